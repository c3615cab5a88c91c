// pd_bench_free — cost of free flight: N bodies (random boxes, prisms, frusta and spheres from a
// fixed-seed generator) thrown and spun under gravity, integrated for a simulated second at the
// default tolerance with no output. Each size is run R times on a fresh state; the CSV on stdout has
// one row per run and a `median` row per size.
//
// usage: pd_bench_free [--bodies 1,10,100,1000] [--repeats 5] [--tend 1] [--seed 12345]
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_common.h"
#include "pdrun/text_buffer.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

enum { MAX_SIZES = 16, MAX_REPEATS = 1000 };

static const char* const usage =
    "usage: pd_bench_free [--bodies N,N,...] [--repeats R] [--tend T] [--seed S]\n"
    "\n"
    "Times free flight of N random convex bodies (gravity on, random spins) over T simulated seconds\n"
    "at the default tolerance, without output, R times per N. Prints CSV with a median row per N.\n"
    "Defaults: --bodies 1,10,100,1000 --repeats 5 --tend 1 --seed 12345\n";

// Numerical Recipes' 32-bit LCG: fixed, portable, good enough to vary shapes and speeds.
typedef struct lcg {
  unsigned long state;
} lcg;

static double lcg_uniform(lcg* g, double lo, double hi) {
  g->state = (1664525ul * g->state + 1013904223ul) & 0xFFFFFFFFul;
  return lo + (hi - lo) * ((double)g->state / 4294967296.0);
}

static int lcg_int(lcg* g, int lo, int hi) { return lo + (int)floor(lcg_uniform(g, 0.0, (double)(hi - lo + 1))); }

// A scene of `count` bodies on a cubic grid 1 m apart (no two overlap: every body fits in 0.6 m).
static char* random_scene(int count, double tend, unsigned long seed) {
  lcg g = {seed};
  pdTextBuffer t = {NULL, 0, 0};
  pd_text_appendf(&t, "# pd_bench_free: %d random bodies, seed %lu\ngravity 0 0 -9.81\ntend %.17g\n", count, seed, tend);
  int side = 1;
  while (side * side * side < count) ++side;
  for (int i = 0; i < count; ++i) {
    double sx = lcg_uniform(&g, 0.1, 0.4), sy = lcg_uniform(&g, 0.1, 0.4), sz = lcg_uniform(&g, 0.1, 0.4);
    switch (lcg_int(&g, 0, 3)) {
      case 0: pd_text_appendf(&t, "cube b%d red %.6f %.6f %.6f\n", i, sx, sy, sz); break;
      case 1: pd_text_appendf(&t, "prism b%d blue %d %.6f %.6f %.6f\n", i, lcg_int(&g, 3, 12), sx, sy, sz); break;
      case 2:
        pd_text_appendf(&t, "tprism b%d green %d %.6f %.6f %.6f %.6f\n", i, lcg_int(&g, 3, 12), sx, sy, sz,
                    lcg_uniform(&g, 0.3, 1.0));
        break;
      default: pd_text_appendf(&t, "sphere b%d grey %d %.6f %.6f %.6f\n", i, lcg_int(&g, 0, 2), sx, sy, sz); break;
    }
    pd_text_appendf(&t, "loc %d %d %d  %.6f %.6f %.6f %.6f\n", i % side, (i / side) % side, i / (side * side),
                lcg_uniform(&g, 0.0, 360.0), lcg_uniform(&g, -1, 1), lcg_uniform(&g, -1, 1), lcg_uniform(&g, 0.1, 1));
    pd_text_appendf(&t, "vel %.6f %.6f %.6f  %.6f %.6f %.6f %.6f\n", lcg_uniform(&g, -2, 2), lcg_uniform(&g, -2, 2),
                lcg_uniform(&g, 0, 5), lcg_uniform(&g, 90, 1080), lcg_uniform(&g, -1, 1), lcg_uniform(&g, -1, 1),
                lcg_uniform(&g, 0.1, 1));
    pd_text_appendf(&t, "spgrav %.6f\n", lcg_uniform(&g, 0.5, 8.0));
  }
  return t.data;
}


typedef struct result {
  double wall, sim;
  long derivatives, accepted, rejected;
} result;

static void print_row(int bodies, const char* repeat, const result* r) {
  printf("%d,%s,%.6g,%.6g,%.6g,%ld,%.6g,%.6g,%ld,%ld\n", bodies, repeat, r->wall, r->sim, r->wall / r->sim,
         r->derivatives, (double)r->derivatives / r->wall, (double)r->derivatives * bodies / r->wall, r->accepted,
         r->rejected);
}




int main(int argc, char** argv) {
  int sizes[MAX_SIZES] = {1, 10, 100, 1000};
  int sizeCount = 4;
  long repeats = 5, seed = 12345;
  double tend = 1.0;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(usage, stdout);
      return 0;
    }
    if (i + 1 >= argc) {
      fprintf(stderr, "pd_bench_free: %s needs a value\n%s", a, usage);
      return 2;
    }
    const char* v = argv[++i];
    bool ok = true;
    if (strcmp(a, "--bodies") == 0) {
      ok = bench_parse_sizes(v, sizes, MAX_SIZES, 1, 100000, &sizeCount);
    } else if (strcmp(a, "--repeats") == 0) {
      ok = bench_parse_long(v, 1, MAX_REPEATS, &repeats);
    } else if (strcmp(a, "--seed") == 0) {
      ok = bench_parse_long(v, 0, 0xFFFFFFFFl, &seed);
    } else if (strcmp(a, "--tend") == 0) {
      char* end = NULL;
      tend = strtod(v, &end);
      ok = end != v && *end == '\0' && isfinite(tend) && tend > 0.0;
    } else {
      ok = false;
    }
    if (!ok) {
      fprintf(stderr, "pd_bench_free: bad option %s %s\n%s", a, v, usage);
      return 2;
    }
  }

  printf("bodies,repeat,wall_s,sim_s,wall_per_sim_s,derivative_evals,derivs_per_s,body_derivs_per_s,accepted,"
         "rejected\n");
  static double walls[MAX_REPEATS];
  for (int s = 0; s < sizeCount; ++s) {
    char* sceneText = random_scene(sizes[s], tend, (unsigned long)seed);
    pdError err;
    memset(&err, 0, sizeof err);
    pdScene* scene = pd_scene_parse_buffer("pd_bench_free", sceneText, strlen(sceneText), &err);
    pdModel* model = scene ? pd_model_compile(scene, &err) : NULL;
    pd_scene_free(scene);
    free(sceneText);
    if (!model) {
      fprintf(stderr, "pd_bench_free: generated scene refused: %d:%d: %s\n", err.line, err.col, err.message);
      return 1;
    }
    pdState* state = pd_state_create(model, NULL);
    result r = {0};
    for (long k = 0; k < repeats; ++k) {
      pd_state_reset(model, state);
      double t0 = bench_wall_now();
      bool ok = pd_advance(model, state, model->settings.tend, NULL, NULL);
      r.wall = bench_wall_now() - t0;
      if (!ok) {
        fprintf(stderr, "pd_bench_free: the run failed at t = %g s\n", state->t);
        return 1;
      }
      r.sim = state->t;
      r.derivatives = state->count.derivatives;
      r.accepted = state->count.accepted;
      r.rejected = state->count.rejected;
      walls[k] = r.wall;
      char repeat[32];
      snprintf(repeat, sizeof repeat, "%ld", k + 1);
      print_row(sizes[s], repeat, &r);
    }
    // the runs are deterministic: counts are the same every time, only the wall time varies
    r.wall = bench_median(walls, (int)repeats);
    print_row(sizes[s], "median", &r);
    fflush(stdout);
    pd_state_free(state);
    pd_model_free(model);
  }
  return 0;
}
