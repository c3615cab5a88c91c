// polydyn — the allocation count (pd_alloc_count) and, in builds with PD_COUNT_ALLOCS, the counting allocators
// (alloc_count.h).
#include <stdatomic.h>
#include <stdlib.h>

#include "polydyn/api.h"

#ifdef PD_COUNT_ALLOCS
#include "alloc_count.h"
// the counters call the real functions
#undef malloc
#undef calloc
#undef realloc

// relaxed: the count orders nothing, and islands allocate (between steps) on several threads
static atomic_long allocations;

static void count_one(void) { atomic_fetch_add_explicit(&allocations, 1, memory_order_relaxed); }

void* pd_counted_malloc(size_t size) {
  count_one();
  return malloc(size);
}

void* pd_counted_calloc(size_t count, size_t size) {
  count_one();
  return calloc(count, size);
}

void* pd_counted_realloc(void* p, size_t size) {
  count_one();
  return realloc(p, size);
}

long pd_alloc_count(void) { return atomic_load_explicit(&allocations, memory_order_relaxed); }
#else
long pd_alloc_count(void) { return -1; }
#endif
