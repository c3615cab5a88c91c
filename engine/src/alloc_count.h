// polydyn (internal) — counting the engine's allocations (builds with PD_COUNT_ALLOCS).
//
// engine/CMakeLists.txt puts this header in front of every C source of the engine, so each call of malloc, calloc
// and realloc there, pd_grow's and the modules' own growth helpers' included, goes through a counter without a call
// site naming it: a new allocation anywhere in the step is counted wherever it is written. pd_alloc_count
// (polydyn/api.h) reads the count; tests/engine/test_step_allocations.c checks that a warmed-up step adds nothing.
// free is not counted: releasing memory is no allocation, and a step frees nothing either.
#pragma once

#include <stdlib.h>  // first: the standard declarations keep their names

void* pd_counted_malloc(size_t size);
void* pd_counted_calloc(size_t count, size_t size);
void* pd_counted_realloc(void* p, size_t size);

#define malloc(size) pd_counted_malloc(size)
#define calloc(count, size) pd_counted_calloc(count, size)
#define realloc(p, size) pd_counted_realloc(p, size)
