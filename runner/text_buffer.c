// polydyn runner — a growing text buffer (text_buffer.h).
#include "pdrun/text_buffer.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

void pd_text_appendf(pdTextBuffer* t, const char* fmt, ...) {
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(t->data ? t->data + t->length : NULL, t->data ? t->capacity - t->length : 0, fmt, ap);
    va_end(ap);
    if (n < 0) abort();
    if (t->data && t->length + (size_t)n < t->capacity) {
      t->length += (size_t)n;
      return;
    }
    t->capacity = 2 * (t->capacity + (size_t)n) + 256;
    t->data = realloc(t->data, t->capacity);
    if (!t->data) abort();
  }
}
