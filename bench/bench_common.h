// polydyn benchmarks — what every benchmark program needs: a monotonic clock, medians, and parsing
// of whole numbers and comma-separated size lists from the command line.
#pragma once

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static inline double bench_wall_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int bench_compare_double(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

// Median of v[0..n) (n <= 1024); v is left untouched.
static inline double bench_median(const double* v, int n) {
  double tmp[1024];
  if (n > 1024) n = 1024;
  memcpy(tmp, v, (size_t)n * sizeof *v);
  qsort(tmp, (size_t)n, sizeof *tmp, bench_compare_double);
  return n % 2 ? tmp[n / 2] : 0.5 * (tmp[n / 2 - 1] + tmp[n / 2]);
}

// A whole number in [lo, hi], the whole string consumed.
static inline bool bench_parse_long(const char* s, long lo, long hi, long* out) {
  char* end = NULL;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (end == s || *end != '\0' || errno || v < lo || v > hi) return false;
  *out = v;
  return true;
}

// "100,300,1000" into sizes[] (at most max entries, each in [lo, hi]); false on any bad entry.
static inline bool bench_parse_sizes(const char* text, int* sizes, int max, long lo, long hi, int* count) {
  char copy[256];
  snprintf(copy, sizeof copy, "%s", text);
  bool ok = true;
  *count = 0;
  for (char* tok = strtok(copy, ","); tok && ok; tok = strtok(NULL, ",")) {
    long n = 0;
    ok = *count < max && bench_parse_long(tok, lo, hi, &n);
    if (ok) sizes[(*count)++] = (int)n;
  }
  return ok && *count > 0;
}
