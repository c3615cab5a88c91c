// polydyn (internal) — the monotonic clock the step stages are timed with.
#pragma once

#include <time.h>

static inline double pd_clock_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
