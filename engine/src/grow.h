// polydyn (internal) — the engine's allocation helpers: growing an array (pd_grow) and a zeroed one (pd_zeroed), each
// of at least one element (an allocation of 0 bytes may return NULL), and memory that is not there is fatal
// (PD_ASSERT). The broad phase alone reports running out instead (broad_phase.h, broad_grid.h): its pair set is
// rebuilt by the next update.
#pragma once

#include <stdlib.h>

#include "polydyn/error.h"

static inline void* pd_grow(void* p, size_t count, size_t size) {
  void* q = realloc(p, (count > 0 ? count : 1) * size);
  PD_ASSERT(q != NULL);
  return q;
}

static inline void* pd_zeroed(size_t count, size_t size) {
  void* p = calloc(count > 0 ? count : 1, size);
  PD_ASSERT(p != NULL);
  return p;
}
