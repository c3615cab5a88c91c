// polydyn runner — a growing text buffer for generated scene files (cube tosses, the soak).
#pragma once

#include <stddef.h>

typedef struct pdTextBuffer {
  char* data;  // NUL-terminated once anything was appended; malloc'd (free with free())
  size_t length, capacity;
} pdTextBuffer;

// Appends printf-formatted text (aborts when memory runs out, as the rest of the CLI).
void pd_text_appendf(pdTextBuffer* t, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
