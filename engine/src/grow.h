// polydyn (internal) — growing an array: realloc to at least one element (realloc of 0 bytes may return NULL), and
// memory that is not there is fatal, as every other allocation of the engine treats it (PD_ASSERT).
#pragma once

#include <stdlib.h>

#include "polydyn/error.h"

static inline void* pd_grow(void* p, size_t count, size_t size) {
  void* q = realloc(p, (count > 0 ? count : 1) * size);
  PD_ASSERT(q != NULL);
  return q;
}
