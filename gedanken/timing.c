// polydyn gedanken — the cost of a work-precision point (pdgk/gedanken.h, "The cost of a work-precision point").
//
// A point's run is often a fraction of a millisecond, which one reading of a clock cannot cost: the first run of a
// scene pays for a cold cache, and on a shared machine any run may share its core. So a timing repeats the run
// back to back until its spans add up to a minimum CPU time, and a point's cost is the least of its timings
// (speed-accuracy protocol: the minimum of several runs, with the median and spread beside it).
#include <math.h>
#include <stdlib.h>

#include "pdgk/gedanken.h"
#include "pdrun/stats.h"
#include "polydyn/error.h"

pdGkTiming pd_gk_time_runs(pdGkTimedRunFcn* run, void* user, double minCpuSeconds) {
  PD_ASSERT(run != NULL && minCpuSeconds > 0.0);
  double wall = 0.0, cpu = 0.0;
  pdGkTiming t = {.completed = true};
  while (t.runs < PD_GK_TIMING_MAX_RUNS && cpu < minCpuSeconds) {
    double w = 0.0, c = 0.0;
    t.completed = run(user, &w, &c);
    ++t.runs;
    wall += w;
    cpu += c;
    if (!t.completed) break;
  }
  t.wall = wall / (double)t.runs;
  t.cpu = cpu / (double)t.runs;
  return t;
}

pdGkCost pd_gk_cost(const pdGkTiming* timings, int count) {
  PD_ASSERT(timings != NULL && count >= 1);
  pdGkCost c = {.wall = INFINITY, .cpu = INFINITY};
  double wallMax = 0.0, cpuMax = 0.0;
  double* walls = malloc((size_t)count * sizeof *walls);
  double* cpus = malloc((size_t)count * sizeof *cpus);
  PD_ASSERT(walls != NULL && cpus != NULL);
  for (int k = 0; k < count; ++k) {
    const pdGkTiming* t = &timings[k];
    walls[k] = t->wall;
    cpus[k] = t->cpu;
    if (t->wall < c.wall) c.wall = t->wall;
    if (t->cpu < c.cpu) {
      c.cpu = t->cpu;
      c.runs = t->runs;
    }
    wallMax = fmax(wallMax, t->wall);
    cpuMax = fmax(cpuMax, t->cpu);
  }
  c.wallMedian = pd_median_in_place(walls, count);
  c.cpuMedian = pd_median_in_place(cpus, count);
  c.wallMaxOverMin = wallMax / c.wall;
  c.cpuMaxOverMin = cpuMax / c.cpu;
  free(walls);
  free(cpus);
  return c;
}
