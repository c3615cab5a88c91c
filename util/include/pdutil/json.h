// pdutil — JSON text (RFC 8259): the one string writer of every JSON file polydyn writes.
#pragma once

#include <stdio.h>

// Writes `s` as a JSON string: in double quotes, with '"' and '\' escaped by a backslash and control
// characters (U+0000..U+001F) as \u00XX (lower-case hex). Valid UTF-8 passes through unchanged (the file
// stays readable); a byte that does not belong to a valid UTF-8 sequence is written as \ufffd, so the
// output is valid JSON whatever the input.
void pdu_json_string(FILE* out, const char* s);
