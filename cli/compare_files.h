// polydyn compare — the files beside metrics.csv that say where, when and why the runs differ: series.csv,
// impacts.csv, friction.csv, divergence.csv (formats: reports/FORMATS.md; method: docs/compare-report.md).
#pragma once

#include <stdbool.h>
#include <stdio.h>

#include "pdref/compare_detail.h"

// Samples per run in series.csv at most (every k-th sample, and the last): enough for a plot, small
// enough for a page that carries every body's curves.
#define PD_COMPARE_SERIES_SAMPLES 400
// Contacts per run in friction.csv at most (every k-th of those with a normal force).
#define PD_COMPARE_FRICTION_POINTS 4000

typedef struct pdCompareRunData {
  const char* engine;
  const char* variant;
  const pdTrajectory* trajectory;
  const pdContactLog* contacts;  // NULL when the engine reports none
} pdCompareRunData;

// Writes the four files into `dir` for runs[0 .. count-1] (runs[0] is the reference; `chaos` is the
// index of the chaos run, or −1), and each run's divergence into divergences[count] (runs[0]'s: none).
// False on an I/O error (errno set).
bool pd_compare_write_details(const char* dir, const char* scene, const pdModel* model, const pdCompareRunData* runs,
                              int count, int chaos, pdDivergence* divergences);
