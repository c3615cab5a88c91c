// pd_bench_broad_phase — cost of the broad phase per step: n small boxes scattered at constant density
// (1 body per m³: a cube of side n^(1/3) m) moving coherently, timed over U updates (update + pairs) for
// sweep and prune and, up to --brute-max bodies, for the brute-force O(n²) test. R repeats per size;
// the CSV on stdout has one row per repeat and a `median` row per size and method (median time; pairs
// and axis tests averaged over all repeats); a summary with the fitted exponents (least-squares slope
// of log time against log n) goes to stderr.
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
    "stderr, the fitted exponents of time against N.\n"
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

// Least squares, relative: t ≈ alpha·n + beta·tests, minimising Σ ((alpha·n + beta·tests − t) / t)².
static void cost_model(const double* n, const double* tests, const double* t, int count, double* alpha, double* beta) {
  double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
  for (int i = 0; i < count; ++i) {
    double x1 = n[i] / t[i], x2 = tests[i] / t[i];
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

  printf("method,bodies,repeat,us_per_update,pairs_per_update,axis_tests_per_update,full_sorts\n");
  double xs[2][MAX_SIZES], ys[2][MAX_SIZES], axisTests[MAX_SIZES];
  int fits[2] = {0, 0};
  for (int s = 0; s < sizeCount; ++s) {
    int n = sizes[s];
    bool brute = n <= bruteMax;
    for (int method = 0; method < (brute ? 2 : 1); ++method) {
      const char* name = method == 0 ? "sap" : "brute";
      world w;
      world_init(&w, n, (uint64_t)seed);
      world_step(&w);
      int capacity = 16 * n;
      pdPair* out = malloc((size_t)capacity * sizeof *out);
      pdPair* check = malloc((size_t)capacity * sizeof *check);
      pdBroadPhase* bp = pd_broad_phase_create(n, NULL, 0.0);
      if (!out || !check || !bp) abort();
      pd_broad_phase_update(bp, w.boxes);  // the first (full) sort is not part of the per-step cost
      double times[MAX_REPEATS], allPairs = 0.0, allTests = 0.0;
      for (long r = 0; r < repeats; ++r) {
        double t = 0.0, pairs = 0.0, tests = 0.0;
        long long fullSorts0 = pd_broad_phase_stats(bp).fullSorts;
        for (long u = 0; u < updates; ++u) {
          world_step(&w);
          double t0 = bench_wall_now();
          int count;
          if (method == 0) {
            pd_broad_phase_update(bp, w.boxes);
            count = pd_broad_phase_pairs(bp, out, capacity);
          } else {
            count = brute_pairs(n, w.boxes, out, capacity);
          }
          t += bench_wall_now() - t0;
          if (count > capacity) {
            fprintf(stderr, "pd_bench_broad_phase: %d pairs overflow the buffer of %d\n", count, capacity);
            return 1;
          }
          pairs += count;
          tests += method == 0 ? (double)pd_broad_phase_stats(bp).axisTests : 0.5 * n * (n - 1.0);
          if (method == 1 && u == updates - 1) {  // the two methods agree (checked once per repeat)
            pd_broad_phase_update(bp, w.boxes);
            int sapCount = pd_broad_phase_pairs(bp, check, capacity);
            if (sapCount != count || memcmp(check, out, (size_t)count * sizeof *out) != 0) {
              fprintf(stderr, "pd_bench_broad_phase: SAP and brute force disagree at n = %d\n", n);
              return 1;
            }
          }
        }
        times[r] = 1e6 * t / (double)updates;
        allPairs += pairs;
        allTests += tests;
        printf("%s,%d,%ld,%.6g,%.6g,%.6g,", name, n, r + 1, times[r], pairs / (double)updates, tests / (double)updates);
        if (method == 0) printf("%lld", pd_broad_phase_stats(bp).fullSorts - fullSorts0);  // SAP only
        printf("\n");
        if (r == repeats - 1) {
          double med = bench_median(times, (int)repeats);
          printf("%s,%d,median,%.6g,%.6g,%.6g,\n", name, n, med, allPairs / (double)(updates * repeats),
                 allTests / (double)(updates * repeats));
          if (method == 0) axisTests[fits[0]] = allTests / (double)(updates * repeats);
          xs[method][fits[method]] = n;
          ys[method][fits[method]++] = med;
          fprintf(stderr, "%-5s n = %6d: %10.2f us per update (median of %ld x %ld updates), %.0f pairs, %.0f tests\n",
                  name, n, med, repeats, updates, allPairs / (double)(updates * repeats),
                  allTests / (double)(updates * repeats));
        }
        fflush(stdout);
      }
      pd_broad_phase_free(bp);
      free(out);
      free(check);
      free(w.m);
      free(w.boxes);
    }
  }
  for (int method = 0; method < 2; ++method)
    if (fits[method] >= 2)
      fprintf(stderr, "fitted exponent (log-log slope of time vs n), %s, n = %g..%g: %.3f\n",
              method == 0 ? "sap" : "brute", xs[method][0], xs[method][fits[method] - 1],
              loglog_slope(xs[method], ys[method], fits[method]));
  if (fits[0] >= 2) {
    double alpha, beta;
    cost_model(xs[0], axisTests, ys[0], fits[0], &alpha, &beta);
    fprintf(stderr,
            "sap cost model: time per update ~ %.3g ns x bodies + %.3g ns x axis tests (pairs overlapping "
            "along the sweep axis, each tested on the other two)\n",
            1e3 * alpha, 1e3 * beta);
  }
  return 0;
}
