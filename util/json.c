// pdutil — the JSON string writer (pdutil/json.h).
#include "pdutil/json.h"

#include "pdutil/utf8.h"

void pdu_json_string(FILE* out, const char* s) {
  fputc('"', out);
  for (const unsigned char* p = (const unsigned char*)s; *p;) {
    if (*p == '"' || *p == '\\') {
      fputc('\\', out);
      fputc(*p++, out);
    } else if (*p < 0x20) {
      fprintf(out, "\\u%04x", *p++);
    } else {
      size_t n = pdu_utf8_sequence(p);
      if (n == 0) {
        fputs("\\ufffd", out);
        ++p;
      } else {
        fwrite(p, 1, n, out);
        p += n;
      }
    }
  }
  fputc('"', out);
}
