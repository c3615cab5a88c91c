// polydyn fuzz targets — what every refused input must give, shared by the targets (fuzz_NAME.c).
#pragma once

#include <stddef.h>
#include <string.h>

#include "polydyn/error.h"

// A refusal is one printable line of message with its position: line and column >= `first` (0 where a message
// may be about the whole input, 1 where every refusal names a line). Anything else traps.
static inline void fuzz_check_error(const pdError* err, int first) {
  size_t n = strnlen(err->message, sizeof err->message);
  if (n == 0 || n == sizeof err->message || err->line < first || err->col < first) __builtin_trap();
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = (unsigned char)err->message[i];
    if (c < 0x20 || c == 0x7f) __builtin_trap();  // one printable line
  }
}
