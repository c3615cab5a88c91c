// pd_bench_broad_phase — cost of the broad phase per step: n small boxes scattered at constant density
// (1 body per m³: a cube of side n^(1/3) m) moving coherently, timed over U updates (update + pairs) for
// incremental sweep and prune and, up to --brute-max bodies, for the brute-force O(n²) test. R repeats
// per size; the CSV on stdout has one row per repeat and a `median` row per size and method (median
// time; pairs and work counters averaged over all repeats); a summary with the fitted exponents
// (least-squares slope of log time, and of log swaps, against log n) goes to stderr.
// The repeats go round-robin over the sizes and methods (each with its own world), so that a slow spell
// of a shared machine is spread over all sizes. Checks, outside the timing: at the end of every repeat
// the incremental pairs equal those of a fresh broad phase given the same boxes (its first update is a
// full sort and rebuild sweep, a separate code path), and, up to --brute-max, those of brute force.
//
// usage: pd_bench_broad_phase [--bodies 100,300,1000,3000,10000] [--repeats 7] [--updates 100]
//                             [--brute-max 3000] [--seed 12345]
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_common.h"
#include "broad_phase.h"

enum { MAX_SIZES = 16, MAX_REPEATS = 101 };

static const char* const usage =
    "usage: pd_bench_broad_phase [--bodies N,N,...] [--repeats R] [--updates U] [--brute-max M] [--seed S]\n"
    "\n"
    "Times the broad phase (update + pairs) per step for N boxes (half extents 0.05-0.25 m) moving\n"
    "coherently (<= 0.02 m per step, reflected at the walls) in a cube of side N^(1/3) m, over U updates,\n"
    "R times per N; brute force too for N <= M. Prints CSV (a median row per N and method) and, on\n"
    "stderr, the fitted exponents of time and of insertion-sort swaps against N.\n"
    "Defaults: --bodies 100,300,1000,3000,10000 --repeats 7 --updates 100 --brute-max 3000 --seed 12345\n";

// Knuth's MMIX LCG (the tests' generator): fixed and portable.
typedef struct lcg {
  uint64_t s;
} lcg;

static double lcg_range(lcg* g, double lo, double hi) {
  g->s = g->s * 6364136223846793005ULL + 1442695040888963407ULL;
  return lo + (hi - lo) * ((double)(g->s >> 11) * (1.0 / 9007199254740992.0));
}

typedef struct mover {
  double c[3], h[3], v[3];
} mover;

typedef struct world {
  int n;
  double side;
  mover* m;
  pdAabb* boxes;
  lcg g;
} world;

static void world_init(world* w, int n, uint64_t seed) {
  w->n = n;
  w->side = cbrt((double)n);
  w->g = (lcg){seed ^ (uint64_t)n};
  w->m = malloc((size_t)n * sizeof *w->m);
  w->boxes = malloc((size_t)n * sizeof *w->boxes);
  if (!w->m || !w->boxes) abort();
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      w->m[i].c[k] = lcg_range(&w->g, 0.0, w->side);
      w->m[i].h[k] = lcg_range(&w->g, 0.05, 0.25);
      w->m[i].v[k] = lcg_range(&w->g, -0.01, 0.01);
    }
}

// One coherent step: drift with small accelerations (speed capped at 0.02 m/step), reflection at the
// walls (so the density stays constant), half extents breathing like a rotating body's box.
static void world_step(world* w) {
  for (int i = 0; i < w->n; ++i) {
    mover* m = &w->m[i];
    for (int k = 0; k < 3; ++k) {
      m->v[k] = fmin(0.02, fmax(-0.02, m->v[k] + lcg_range(&w->g, -0.002, 0.002)));
      m->c[k] += m->v[k];
      if (m->c[k] < 0.0 || m->c[k] > w->side) {
        m->v[k] = -m->v[k];
        m->c[k] = fmin(w->side, fmax(0.0, m->c[k]));
      }
      m->h[k] = fmin(0.25, fmax(0.05, m->h[k] + lcg_range(&w->g, -0.002, 0.002)));
      w->boxes[i].lo[k] = m->c[k] - m->h[k];
      w->boxes[i].hi[k] = m->c[k] + m->h[k];
    }
  }
}

static int brute_pairs(int n, const pdAabb* b, pdPair* out, int capacity) {
  int count = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (b[i].lo[0] <= b[j].hi[0] && b[j].lo[0] <= b[i].hi[0] && b[i].lo[1] <= b[j].hi[1] &&
          b[j].lo[1] <= b[i].hi[1] && b[i].lo[2] <= b[j].hi[2] && b[j].lo[2] <= b[i].hi[2]) {
        if (count < capacity) out[count] = (pdPair){i, j};
        ++count;
      }
    }
  return count;
}

// The pairs of a fresh broad phase given `boxes` (a full sort and rebuild sweep) equal `pairs`.
static bool same_as_fresh(int n, const pdAabb* boxes, const pdPair* pairs, int count, pdPair* buf, int capacity) {
  pdBroadPhase* fresh = pd_broad_phase_create_with(n, NULL, 0.0, pd_broadPhaseSweep);
  if (!fresh || !pd_broad_phase_update(fresh, boxes)) abort();
  int freshCount = pd_broad_phase_pairs(fresh, buf, capacity);
  pd_broad_phase_free(fresh);
  return freshCount == count && memcmp(buf, pairs, (size_t)(count < capacity ? count : capacity) * sizeof *buf) == 0;
}

enum { METHOD_SAP, METHOD_BRUTE, METHOD_GRID, METHOD_COUNT };
static const char* const methodNames[METHOD_COUNT] = {"sap", "brute", "grid"};

// One size and method: its world, buffers and broad phase (SAP only), and per repeat the time and the
// sums over its updates.
typedef struct run {
  int n, method;  // METHOD_SAP, METHOD_BRUTE, METHOD_GRID
  world w;
  int capacity;
  pdPair *out, *check;
  pdBroadPhase* bp;
  double times[MAX_REPEATS];    // us per update
  double sum[MAX_REPEATS][4];   // pairs, swaps, min/max swaps, set changes
  long long fullSorts[MAX_REPEATS];
} run;

// Repeat r of run u: `updates` timed steps, then the checks. False (with a message) on a disagreement.
static bool repeat_run(run* u, long r, long updates, long bruteMax) {
  int n = u->n;
  double t = 0.0;
  long long fullSorts0 = u->bp ? pd_broad_phase_stats(u->bp).fullSorts : 0;
  for (long k = 0; k < updates; ++k) {
    world_step(&u->w);
    double t0 = bench_wall_now();
    int count;
    if (u->method != METHOD_BRUTE) {
      if (!pd_broad_phase_update(u->bp, u->w.boxes)) abort();
      count = pd_broad_phase_pairs(u->bp, u->out, u->capacity);
    } else {
      count = brute_pairs(n, u->w.boxes, u->out, u->capacity);
    }
    t += bench_wall_now() - t0;
    if (count > u->capacity) {
      fprintf(stderr, "pd_bench_broad_phase: %d pairs overflow the buffer of %d\n", count, u->capacity);
      return false;
    }
    u->sum[r][0] += count;
    if (u->method == METHOD_SAP) {
      pdBroadPhaseStats st = pd_broad_phase_stats(u->bp);
      u->sum[r][1] += (double)st.swaps;
      u->sum[r][2] += (double)st.overlapEvents;
      u->sum[r][3] += (double)st.pairChanges;
    }
    if (k == updates - 1 && u->method != METHOD_BRUTE) {  // checked once per repeat, outside the timing
      if (!same_as_fresh(n, u->w.boxes, u->out, count, u->check, u->capacity)) {
        fprintf(stderr, "pd_bench_broad_phase: %s and a fresh SAP rebuild disagree at n = %d\n", methodNames[u->method], n);
        return false;
      }
      if (n <= bruteMax) {
        int bruteCount = brute_pairs(n, u->w.boxes, u->check, u->capacity);
        if (bruteCount != count || memcmp(u->check, u->out, (size_t)count * sizeof *u->out) != 0) {
          fprintf(stderr, "pd_bench_broad_phase: %s and brute force disagree at n = %d\n", methodNames[u->method], n);
          return false;
        }
      }
    }
  }
  u->times[r] = 1e6 * t / (double)updates;
  u->fullSorts[r] = u->bp ? pd_broad_phase_stats(u->bp).fullSorts - fullSorts0 : 0;
  return true;
}

// Least-squares slope of log y against log x.
static double loglog_slope(const double* x, const double* y, int n) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    double lx = log(x[i]), ly = log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Least squares, relative: t ≈ alpha·n + beta·swaps, minimising Σ ((alpha·n + beta·swaps − t) / t)².
static void cost_model(const double* n, const double* swaps, const double* t, int count, double* alpha, double* beta) {
  double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
  for (int i = 0; i < count; ++i) {
    double x1 = n[i] / t[i], x2 = swaps[i] / t[i];
    a11 += x1 * x1;
    a12 += x1 * x2;
    a22 += x2 * x2;
    b1 += x1;
    b2 += x2;
  }
  double det = a11 * a22 - a12 * a12;
  *alpha = (b1 * a22 - b2 * a12) / det;
  *beta = (a11 * b2 - a12 * b1) / det;
}

int main(int argc, char** argv) {
  int sizes[MAX_SIZES] = {100, 300, 1000, 3000, 10000};
  int sizeCount = 5;
  long repeats = 7, updates = 100, bruteMax = 3000, seed = 12345;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(usage, stdout);
      return 0;
    }
    if (i + 1 >= argc) {
      fprintf(stderr, "pd_bench_broad_phase: %s needs a value\n%s", a, usage);
      return 2;
    }
    const char* v = argv[++i];
    bool ok = true;
    if (strcmp(a, "--bodies") == 0) {
      ok = bench_parse_sizes(v, sizes, MAX_SIZES, 2, 1000000, &sizeCount);
    } else if (strcmp(a, "--repeats") == 0) {
      ok = bench_parse_long(v, 1, MAX_REPEATS, &repeats);
    } else if (strcmp(a, "--updates") == 0) {
      ok = bench_parse_long(v, 1, 1000000, &updates);
    } else if (strcmp(a, "--brute-max") == 0) {
      ok = bench_parse_long(v, 0, 1000000, &bruteMax);
    } else if (strcmp(a, "--seed") == 0) {
      ok = bench_parse_long(v, 0, 0x7FFFFFFFl, &seed);
    } else {
      ok = false;
    }
    if (!ok) {
      fprintf(stderr, "pd_bench_broad_phase: bad option %s %s\n%s", a, v, usage);
      return 2;
    }
  }

  // One run per size and method, each with its own world; the repeats go round-robin over the runs so
  // that a slow spell of the (shared) machine hits every size alike rather than one size's block.
  int runCount = 0;
  run* runs = calloc(METHOD_COUNT * MAX_SIZES, sizeof *runs);
  if (!runs) abort();
  for (int s = 0; s < sizeCount; ++s)
    for (int method = 0; method < METHOD_COUNT; ++method) {
      if (method == METHOD_BRUTE && sizes[s] > bruteMax) continue;
      run* u = &runs[runCount++];
      u->n = sizes[s];
      u->method = method;
      world_init(&u->w, u->n, (uint64_t)seed);
      world_step(&u->w);
      u->capacity = 16 * u->n;
      u->out = malloc((size_t)u->capacity * sizeof *u->out);
      u->check = malloc((size_t)u->capacity * sizeof *u->check);
      if (!u->out || !u->check) abort();
      if (method != METHOD_BRUTE) {
        u->bp = pd_broad_phase_create_with(u->n, NULL, 0.0,
                                           method == METHOD_SAP ? pd_broadPhaseSweep : pd_broadPhaseGrid);
        // the first update (a full sort and rebuild sweep) is not part of the per-step cost
        if (!u->bp || !pd_broad_phase_update(u->bp, u->w.boxes)) abort();
      }
    }
  for (long r = 0; r < repeats; ++r)
    for (int i = 0; i < runCount; ++i)
      if (!repeat_run(&runs[i], r, updates, bruteMax)) return 1;

  printf("method,bodies,repeat,us_per_update,pairs_per_update,swaps_per_update,events_per_update,"
         "pair_changes_per_update,full_sorts\n");
  double xs[METHOD_COUNT][MAX_SIZES], ys[METHOD_COUNT][MAX_SIZES], swapsOf[MAX_SIZES];
  int fits[METHOD_COUNT] = {0, 0, 0};
  for (int i = 0; i < runCount; ++i) {
    run* u = &runs[i];
    const char* name = methodNames[u->method];
    double all[4] = {0, 0, 0, 0};  // pairs, swaps, events, pair changes: means over all repeats
    for (long r = 0; r < repeats; ++r) {
      for (int c = 0; c < 4; ++c) all[c] += u->sum[r][c];
      printf("%s,%d,%ld,%.6g,%.6g,", name, u->n, r + 1, u->times[r], u->sum[r][0] / (double)updates);
      if (u->method == METHOD_SAP)  // SAP only
        printf("%.6g,%.6g,%.6g,%lld\n", u->sum[r][1] / (double)updates, u->sum[r][2] / (double)updates,
               u->sum[r][3] / (double)updates, u->fullSorts[r]);
      else
        printf(",,,\n");
    }
    double med = bench_median(u->times, (int)repeats), per = (double)(updates * repeats);
    printf("%s,%d,median,%.6g,%.6g,", name, u->n, med, all[0] / per);
    if (u->method == METHOD_SAP)
      printf("%.6g,%.6g,%.6g,\n", all[1] / per, all[2] / per, all[3] / per);
    else
      printf(",,,\n");
    if (u->method == METHOD_SAP) swapsOf[fits[0]] = all[1] / per;
    xs[u->method][fits[u->method]] = u->n;
    ys[u->method][fits[u->method]++] = med;
    fprintf(stderr, "%-5s n = %6d: %10.2f us per update (median of %ld x %ld updates), %.0f pairs", name, u->n, med,
            repeats, updates, all[0] / per);
    if (u->method == METHOD_SAP) fprintf(stderr, ", %.0f swaps, %.0f overlap events", all[1] / per, all[2] / per);
    fprintf(stderr, "\n");
    pd_broad_phase_free(u->bp);
    free(u->out);
    free(u->check);
    free(u->w.m);
    free(u->w.boxes);
  }
  free(runs);
  for (int method = 0; method < METHOD_COUNT; ++method)
    if (fits[method] >= 2)
      fprintf(stderr, "fitted exponent (log-log slope of time vs n), %s, n = %g..%g: %.3f\n",
              methodNames[method], xs[method][0], xs[method][fits[method] - 1],
              loglog_slope(xs[method], ys[method], fits[method]));
  // the engine's default (pd_broadPhaseAuto): sweep and prune below the threshold, the grid from it on
  if (fits[METHOD_SAP] == fits[METHOD_GRID] && fits[METHOD_SAP] >= 2) {
    double autoTime[MAX_SIZES];
    for (int i = 0; i < fits[METHOD_SAP]; ++i)
      autoTime[i] = xs[METHOD_SAP][i] >= PD_BROAD_PHASE_GRID_MIN_BODIES ? ys[METHOD_GRID][i] : ys[METHOD_SAP][i];
    fprintf(stderr, "fitted exponent (log-log slope of time vs n), auto (grid from %d bodies), n = %g..%g: %.3f\n",
            PD_BROAD_PHASE_GRID_MIN_BODIES, xs[METHOD_SAP][0], xs[METHOD_SAP][fits[METHOD_SAP] - 1],
            loglog_slope(xs[METHOD_SAP], autoTime, fits[METHOD_SAP]));
    fprintf(stderr, "local exponents of grid time (slope between consecutive sizes):");
    for (int i = 1; i < fits[METHOD_GRID]; ++i)
      fprintf(stderr, " %g-%g: %.2f%s", xs[METHOD_GRID][i - 1], xs[METHOD_GRID][i],
              loglog_slope(xs[METHOD_GRID] + i - 1, ys[METHOD_GRID] + i - 1, 2), i + 1 < fits[METHOD_GRID] ? "," : "\n");
  }
  if (fits[0] >= 2) {
    double nlogn[MAX_SIZES];
    for (int i = 0; i < fits[0]; ++i) nlogn[i] = xs[0][i] * log2(xs[0][i]);
    fprintf(stderr, "reference: n log n has a fitted exponent of %.3f over the same sizes\n",
            loglog_slope(xs[0], nlogn, fits[0]));
    fprintf(stderr, "local exponents of sap time (slope between consecutive sizes):");
    for (int i = 1; i < fits[0]; ++i)
      fprintf(stderr, " %g-%g: %.2f%s", xs[0][i - 1], xs[0][i], loglog_slope(xs[0] + i - 1, ys[0] + i - 1, 2),
              i + 1 < fits[0] ? "," : "\n");
    bool anySwapless = false;  // log 0: no slope (tiny n, or no motion)
    for (int i = 0; i < fits[0]; ++i) anySwapless = anySwapless || !(swapsOf[i] > 0.0);
    if (!anySwapless)
      fprintf(stderr, "fitted exponent (log-log slope of insertion-sort swaps vs n), sap, n = %g..%g: %.3f\n",
              xs[0][0], xs[0][fits[0] - 1], loglog_slope(xs[0], swapsOf, fits[0]));
    double alpha, beta;
    cost_model(xs[0], swapsOf, ys[0], fits[0], &alpha, &beta);
    fprintf(stderr,
            "sap cost model: time per update ~ %.3g ns x bodies + %.3g ns x swaps (of neighbouring endpoints, "
            "three axes)\n",
            1e3 * alpha, 1e3 * beta);
  }
  return 0;
}
