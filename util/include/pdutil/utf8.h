// pdutil — UTF-8 (RFC 3629): what the JSON writer passes through and what the scene language accepts in
// a name or a colour.
#pragma once

#include <stddef.h>

// The length (1..4) of the valid UTF-8 sequence that starts at s, or 0 when s does not start one (a
// stray continuation byte, an overlong form, a surrogate, a code point above U+10FFFF, a sequence cut
// short). s must be NUL-terminated or hold at least 4 bytes from s on.
size_t pdu_utf8_sequence(const unsigned char* s);

// The length of the longest valid UTF-8 prefix of s[0..n): n when the whole of it is valid.
size_t pdu_utf8_valid_length(const char* s, size_t n);
