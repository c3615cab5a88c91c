// polydyn utilities — the clocks runs and stages are timed with, in seconds.
// Wall time is monotonic (never steps back with the system clock); CPU time is the calling thread's where a
// worker thread times its own run among others, the whole process's where a command times everything it did.
#pragma once

#include <time.h>

static inline double pd_timespec_seconds(struct timespec ts) { return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec; }

static inline double pd_wall_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return pd_timespec_seconds(ts);
}

static inline double pd_thread_cpu_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return pd_timespec_seconds(ts);
}

static inline double pd_process_cpu_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return pd_timespec_seconds(ts);
}
