// pdutil — UTF-8 validation (pdutil/utf8.h).
#include "pdutil/utf8.h"

size_t pdu_utf8_sequence(const unsigned char* s) {
  unsigned char c = s[0];
  if (c < 0x80) return 1;
  size_t n;
  unsigned char lo = 0x80, hi = 0xbf;  // the second byte's range (RFC 3629, section 4)
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
  } else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    if (c == 0xe0) lo = 0xa0;  // no overlong forms
    if (c == 0xed) hi = 0x9f;  // no surrogates
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    if (c == 0xf0) lo = 0x90;  // no overlong forms
    if (c == 0xf4) hi = 0x8f;  // nothing above U+10FFFF
  } else {
    return 0;
  }
  if (s[1] < lo || s[1] > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if (s[k] < 0x80 || s[k] > 0xbf) return 0;
  return n;
}

size_t pdu_utf8_valid_length(const char* s, size_t n) {
  const unsigned char* p = (const unsigned char*)s;
  size_t at = 0;
  while (at < n) {
    // a sequence must end within n: copy the tail so the check never reads past it
    unsigned char tail[4] = {0, 0, 0, 0};
    const unsigned char* q = p + at;
    if (n - at < 4) {
      for (size_t k = 0; k < n - at; ++k) tail[k] = p[at + k];
      q = tail;
    }
    size_t len = pdu_utf8_sequence(q);
    if (len == 0 || len > n - at) return at;
    at += len;
  }
  return n;
}
