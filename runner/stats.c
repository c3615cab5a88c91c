// polydyn runner — small statistics over arrays of doubles (runner/include/pdrun/stats.h).
#include "pdrun/stats.h"

#include <stdlib.h>

#include "polydyn/error.h"

static int compare_doubles(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

void pd_sort_doubles(double* v, size_t n) {
  if (n > 1) qsort(v, n, sizeof *v, compare_doubles);
}

double pd_median_in_place(double* v, int n) {
  PD_ASSERT(v != NULL && n >= 1);
  pd_sort_doubles(v, (size_t)n);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
