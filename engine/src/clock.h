// polydyn (internal) — the monotonic clock the step stages are timed with.
#pragma once

#include <stdbool.h>
#include <time.h>

static inline double pd_clock_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// What one clock read adds to an interval timed with two, s: the least difference of consecutive reads out of a
// few (sampled stage timers scale their intervals up, and that read with them: dynamics.c subtracts it).
static inline double pd_clock_read_seconds(void) {
  double least = 1.0;
  for (int i = 0; i < 16; ++i) {
    double a = pd_clock_seconds();
    double b = pd_clock_seconds();
    if (b - a < least) least = b - a;
  }
  return least;
}

// Consecutive stages timed with one clock read per boundary instead of two per stage: each lap adds the time
// since the previous one to a stage's seconds. A stopwatch started off (pdStateOptions.stageTimers false) reads no
// clock and adds nothing.
typedef struct pdStopwatch {
  double last;  // s, the clock at the previous boundary
  bool on;
} pdStopwatch;

static inline pdStopwatch pd_stopwatch_start(bool on) { return (pdStopwatch){on ? pd_clock_seconds() : 0.0, on}; }

static inline void pd_stopwatch_lap(pdStopwatch* w, double* stageSeconds) {
  if (!w->on) return;
  double now = pd_clock_seconds();
  *stageSeconds += now - w->last;
  w->last = now;
}
