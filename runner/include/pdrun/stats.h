// polydyn runner — small statistics over arrays of doubles, shared by the bench's commands (medians of
// repeated wall times, percentiles of errors).
#pragma once

#include <stddef.h>

// Sorts v[0..n) ascending (NaN must not be present).
void pd_sort_doubles(double* v, size_t n);

// The median of v[0..n) (n >= 1; the mean of the middle two when n is even). Sorts v in place.
double pd_median_in_place(double* v, int n);
