// polydyn oracle — our interference test against libccd (docs/validation.md): random pairs
// near touching, every pair of a soft run at every output sample, or the rows of an earlier CSV again.
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdutil/files.h"
#include "pdref/oracle.h"
#include "polydyn/state.h"

static const char* const help =
    "usage: polydyn oracle --random N --seed S [--out FILE.csv]\n"
    "       polydyn oracle SCENE [--out FILE.csv] [--tend T] [--sample HZ]\n"
    "       polydyn oracle --replay FILE.csv [--out FILE.csv]\n"
    "       polydyn oracle --random N --seed S --timing [--repeats R] [--out FILE.csv]\n"
    "\n"
    "Checks polydyn's interference test (separating axes, minimum depth) against libccd's GJK, MPR and\n"
    "EPA on the same posed polyhedra, and prints the counts of agreement and disagreement by kind and\n"
    "the depth errors.\n"
    "\n"
    "  --random N     N random pairs (cubes, prisms, tapered prisms, geodesic spheres, hulls) in random\n"
    "                 poses, most of them within a few % of touching\n"
    "  --seed S       the seed of --random (0 .. 2^64-1): the same seed gives the same pairs\n"
    "  SCENE          runs the soft engine and checks every pair of bodies at every output sample\n"
    "  --tend T       SCENE: simulated seconds, overrides the scene's tend\n"
    "  --sample HZ    SCENE: output samples per second, overrides the scene's sample\n"
    "  --replay FILE  checks again every pair listed in a CSV written by this command\n"
    "  --out FILE     the CSV of every pair that is not a plain agreement, with both shapes and poses\n"
    "                 (default for --random: out/random-seed-S-N.oracle.csv; for SCENE:\n"
    "                 out/NAME.oracle.csv); with --replay, every replayed pair, only when asked;\n"
    "                 with --timing, the timing table, only when asked\n"
    "  --timing       with --random: no check; times, on the same pairs, our test as the engine calls it\n"
    "                 (first separating axis, without and with a warm cache), ours with every axis, and\n"
    "                 libccd's GJK, GJK + EPA and MPR (its default tolerances), each over whole batches;\n"
    "                 prints the median us per pair by group of shapes and the ratios to GJK\n"
    "  --repeats R    --timing: timed repeats, 1 to 101 (default 5)\n"
    "\n"
    "libccd's verdict is GJK's (MPR is reported beside it). A verdict mismatch where either depth is\n"
    "within 1e-7 x (r_A + r_B) of touching is counted as touching, not as a failure. Exit status: 0 no\n"
    "disagreement with GJK outside that band, 1 a disagreement outside it (or the soft run failed),\n"
    "2 bad input, 130 interrupted (no CSV written). With --timing: 1 when our modes disagree with each\n"
    "other.\n";

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}

static double clock_now(clockid_t id) {
  struct timespec ts;
  clock_gettime(id, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double wall_now(void) { return clock_now(CLOCK_MONOTONIC); }
// on a shared machine the CPU time says what the work costs
static double cpu_now(void) { return clock_now(CLOCK_PROCESS_CPUTIME_ID); }

// ---------------------------------------------------------------- the CSV, written under a temporary name

typedef struct csvOut {
  char* path;
  char* partial;
  FILE* f;
  long rows;
} csvOut;

static bool csv_open(csvOut* c, const char* path) {
  memset(c, 0, sizeof *c);
  c->path = strdup(path);
  size_t n = strlen(path) + 32;
  c->partial = malloc(n);
  if (!c->path || !c->partial) abort();
  snprintf(c->partial, n, "%s.partial-XXXXXX", path);
  pdu_make_parents(path);
  int fd = mkstemp(c->partial);
  if (fd < 0 || !(c->f = fdopen(fd, "w"))) {
    fprintf(stderr, "polydyn oracle: %s: cannot write: %s\n", path, strerror(errno));
    if (fd >= 0) {
      close(fd);
      unlink(c->partial);
    }
    free(c->path);
    free(c->partial);
    return false;
  }
  pd_oracle_csv_header(c->f);
  return true;
}

static void csv_abort(csvOut* c) {
  if (!c->f) return;
  fclose(c->f);
  unlink(c->partial);
  free(c->path);
  free(c->partial);
  c->f = NULL;
}

static bool csv_finish(csvOut* c) {
  if (!c->f) return true;
  bool ok = !ferror(c->f);
  ok = fclose(c->f) == 0 && ok;
  c->f = NULL;
  if (ok) ok = rename(c->partial, c->path) == 0;
  if (!ok) {
    fprintf(stderr, "polydyn oracle: %s: cannot write: %s\n", c->path, strerror(errno));
    unlink(c->partial);
  }
  free(c->path);
  free(c->partial);
  return ok;
}

// every pair that is not a plain agreement is listed
static void csv_row(csvOut* c, const pdOracleRow* row) {
  if (!c->f || row->r.kind == pd_oracleAgreeOverlap || row->r.kind == pd_oracleAgreeSeparate) return;
  pd_oracle_csv_write(c->f, row);
  ++c->rows;
}

// ---------------------------------------------------------------- progress

typedef struct progress {
  bool on;
  double last;
} progress;

static void progress_show(progress* p, const char* fmt, double done, double total) {
  if (!p->on) return;
  double now = wall_now();
  if (now - p->last < 0.5) return;
  p->last = now;
  fputs("\rpolydyn oracle: ", stderr);
  fprintf(stderr, fmt, done, total);
}

static void progress_end(const progress* p) {
  if (p->on) fputs("\r\033[K", stderr);
}

// ---------------------------------------------------------------- --random

static int run_random(long n, unsigned long long seed, const char* out) {
  char defaultOut[96];
  if (!out) {
    snprintf(defaultOut, sizeof defaultOut, "out/random-seed-%llu-%ld.oracle.csv", seed, n);
    out = defaultOut;
  }
  csvOut csv;
  if (!csv_open(&csv, out)) return PD_EXIT_BAD_INPUT;
  pdOracleRng g;
  pd_oracle_rng_seed(&g, seed);
  pdOracleStats stats;
  pd_oracle_stats_init(&stats);
  long placements[3] = {0, 0, 0};
  progress prog = {isatty(STDERR_FILENO) == 1, wall_now()};
  double t0 = wall_now(), c0 = cpu_now();
  for (long i = 0; i < n && !interrupted; ++i) {
    pdOraclePair p;
    pd_oracle_random_pair(&g, &p);
    pdOracleRow row = {.source = "random", .index = i, .nameA = "A", .nameB = "B", .specA = p.a.spec,
                       .specB = p.b.spec, .xa = p.bodyA.x, .xb = p.bodyB.x, .qa = p.bodyA.q, .qb = p.bodyB.q};
    pd_oracle_check(&p.bodyA, &p.bodyB, &row.r);
    pd_oracle_stats_add(&stats, &row.r);
    ++placements[p.placement];
    csv_row(&csv, &row);
    pd_oracle_pair_free(&p);
    progress_show(&prog, "pair %.0f / %.0f", (double)i, (double)n);
  }
  progress_end(&prog);
  if (interrupted) {
    csv_abort(&csv);
    pd_oracle_stats_free(&stats);
    fprintf(stderr, "polydyn oracle: interrupted; nothing written\n");
    return 130;
  }
  printf("polydyn oracle: %ld random pairs, seed %llu (placed near touching %ld, at touching %ld, anywhere %ld)\n", n,
         seed, placements[pd_placeNear], placements[pd_placeTouch], placements[pd_placeFar]);
  pd_oracle_stats_print(&stats, stdout);
  printf("time: total wall %.2f s, CPU %.2f s (shapes, placement and checks)\n", wall_now() - t0, cpu_now() - c0);
  long rows = csv.rows;
  bool written = csv_finish(&csv);
  if (written) printf("listed: %ld pairs in %s\n", rows, out);
  long failures = pd_oracle_stats_failures(&stats);
  pd_oracle_stats_free(&stats);
  return !written || failures ? PD_EXIT_FAILURE : PD_EXIT_OK;
}

// ---------------------------------------------------------------- --random --timing

static int run_timing(long n, unsigned long long seed, int repeats, const char* out) {
  pdOracleTiming t;
  double c0 = cpu_now();
  bool agree = pd_oracle_timing(n, seed, repeats, &t);
  printf("polydyn oracle: timing, %ld random pairs, seed %llu\n", n, seed);
  pd_oracle_timing_print(&t, stdout);
  printf("time: CPU %.2f s (shapes, placement, an untimed pass and the timed repeats)\n", cpu_now() - c0);
  if (out) {
    pdu_make_parents(out);
    FILE* f = fopen(out, "w");
    if (!f) {
      fprintf(stderr, "polydyn oracle: %s: cannot write: %s\n", out, strerror(errno));
      return PD_EXIT_FAILURE;
    }
    pd_oracle_timing_csv(&t, f);
    if (fclose(f) != 0) {
      fprintf(stderr, "polydyn oracle: %s: cannot write: %s\n", out, strerror(errno));
      return PD_EXIT_FAILURE;
    }
    printf("listed: the timing table in %s\n", out);
  }
  if (!agree) fprintf(stderr, "polydyn oracle: our SAT modes disagree with each other\n");
  return agree ? PD_EXIT_OK : PD_EXIT_FAILURE;
}

// ---------------------------------------------------------------- SCENE

typedef struct sceneCheck {
  const char* path;
  char** specs;  // per body
  pdOracleStats stats;
  csvOut csv;
  long sample;
  progress prog;
} sceneCheck;

static bool observe(const pdModel* model, const pdState* state, void* user) {
  sceneCheck* c = user;
  pdBodyState poses[2];
  for (int i = 0; i < model->bodyCount; ++i) {
    for (int j = i + 1; j < model->bodyCount; ++j) {
      const pdBody *bi = &model->bodies[i], *bj = &model->bodies[j];
      if (bi->fixed && bj->fixed) continue;  // never tested by the engine either
      poses[0] = pd_state_body(model, state, i);
      poses[1] = pd_state_body(model, state, j);
      pdOracleBody a = {&bi->shape, poses[0].x, poses[0].q}, b = {&bj->shape, poses[1].x, poses[1].q};
      pdOracleRow row = {.source = c->path, .index = c->sample, .t = state->t, .nameA = bi->name, .nameB = bj->name,
                         .specA = c->specs[i], .specB = c->specs[j], .xa = a.x, .xb = b.x, .qa = a.q, .qb = b.q};
      pd_oracle_check(&a, &b, &row.r);
      pd_oracle_stats_add(&c->stats, &row.r);
      csv_row(&c->csv, &row);
    }
  }
  ++c->sample;
  progress_show(&c->prog, "t = %.4g / %.4g s", state->t, model->settings.tend);
  return !interrupted;
}

// out/NAME.oracle.csv for scene path .../NAME.ext
static char* default_scene_out(const char* scene) {
  char* dir = pd_cli_default_out_dir(scene);
  size_t size = strlen(dir) + sizeof ".oracle.csv";
  char* path = malloc(size);
  if (!path) abort();
  snprintf(path, size, "%s.oracle.csv", dir);
  free(dir);
  return path;
}

static int run_scene(const char* path, const pdCliOverrides* overrides, const char* out) {
  pdModel* model = pd_cli_load_model(path, overrides, NULL);
  if (!model) return PD_EXIT_BAD_INPUT;
  // the scene again, for the shape of each body as text (the model keeps only the polyhedra)
  pdError err = {0};
  pdScene* scene = pd_scene_parse_file(path, &err);
  if (!scene || scene->objectCount != model->bodyCount) {
    if (scene) pd_error_set(&err, path, 0, 0, "the file changed while it was read");
    pd_error_print(&err, stderr);
    pd_scene_free(scene);
    pd_model_free(model);
    return PD_EXIT_BAD_INPUT;
  }
  sceneCheck c = {path, calloc((size_t)model->bodyCount, sizeof(char*)), {0}, {0}, 0, {isatty(STDERR_FILENO) == 1, wall_now()}};
  if (!c.specs) abort();
  for (int i = 0; i < model->bodyCount; ++i) c.specs[i] = pd_oracle_object_spec(&scene->objects[i]);
  pd_scene_free(scene);
  pd_oracle_stats_init(&c.stats);
  char* defaultOut = out ? NULL : default_scene_out(path);
  if (!out) out = defaultOut;

  int status = PD_EXIT_BAD_INPUT;
  pdState* state = NULL;
  if (!csv_open(&c.csv, out)) goto done;
  state = pd_state_create(model, NULL);
  double t0 = wall_now(), c0 = cpu_now();
  bool completed = pd_advance(model, state, model->settings.tend, observe, &c);
  double wall = wall_now() - t0, cpu = cpu_now() - c0;
  progress_end(&c.prog);
  if (interrupted) {
    csv_abort(&c.csv);
    fprintf(stderr, "polydyn oracle: interrupted at t = %.6g s; nothing written\n", state->t);
    status = 130;
    goto done;
  }
  printf("polydyn oracle: %s, %d bodies, %ld samples to t = %.6g s\n", path, model->bodyCount, c.sample, state->t);
  pd_oracle_stats_print(&c.stats, stdout);
  printf("time: total wall %.2f s, CPU %.2f s (the soft run and the checks)\n", wall, cpu);
  long rows = c.csv.rows;
  bool written = csv_finish(&c.csv);
  if (written) printf("listed: %ld pairs in %s\n", rows, out);
  if (!completed) fprintf(stderr, "polydyn oracle: the soft run stopped at t = %.6g s\n", state->t);
  status = !written || !completed || pd_oracle_stats_failures(&c.stats) ? PD_EXIT_FAILURE : PD_EXIT_OK;

done:
  for (int i = 0; i < model->bodyCount; ++i) free(c.specs[i]);
  free(c.specs);
  free(defaultOut);
  pd_oracle_stats_free(&c.stats);
  pd_state_free(state);
  pd_model_free(model);
  return status;
}

// ---------------------------------------------------------------- --replay

// Reads the whole file (so that a bad row is refused before anything is checked or written).
typedef struct replayRun {
  pdOracleStats* stats;
  csvOut* csv;
} replayRun;

// Checks one listed pair again (pdOracleReplayFcn).
static bool replay_row(const pdOracleRow* listed, const pdOracleShape* sa, const pdOracleShape* sb, long line,
                       void* user) {
  replayRun* run = user;
  pdOracleRow row = *listed;
  pdOracleResult was = row.r;
  pdOracleBody a = {&sa->poly, row.xa, row.qa}, b = {&sb->poly, row.xb, row.qb};
  pd_oracle_check(&a, &b, &row.r);
  pd_oracle_stats_add(run->stats, &row.r);
  if (run->csv->f) {
    pd_oracle_csv_write(run->csv->f, &row);
    ++run->csv->rows;
  }
  printf("line %ld: %s #%ld t=%.6g %s/%s: was %s, now %s (ours %s %.3g m, GJK %s, MPR %s", line, row.source,
         row.index, row.t, row.nameA, row.nameB, pdOracleKindNames[was.kind], pdOracleKindNames[row.r.kind],
         row.r.ours ? "overlap" : "separate", row.r.ourDepth, row.r.gjk ? "overlap" : "separate",
         row.r.mpr ? "overlap" : "separate");
  if (row.r.hasEpa) printf(", EPA %.3g m", row.r.epaDepth);
  if (row.r.hasMprDepth) printf(", MPR depth %.3g m", row.r.mprDepth);
  printf(")\n");
  return !interrupted;
}

static int run_replay(const char* path, const char* out) {
  size_t size = 0;
  char* data = pdu_read_file(path, &size);
  if (!data) {
    fprintf(stderr, "%s: cannot read: %s\n", path, strerror(errno));
    return PD_EXIT_BAD_INPUT;
  }
  pdOracleStats stats;
  pd_oracle_stats_init(&stats);
  csvOut csv = {0};
  pdError err = {0};
  int status = PD_EXIT_BAD_INPUT;
  // every row and shape valid before anything is checked or written
  if (!pd_oracle_replay_buffer(path, data, size, NULL, NULL, &err)) {
    pd_error_print(&err, stderr);
    goto done;
  }
  if (out && !csv_open(&csv, out)) goto done;
  replayRun run = {&stats, &csv};
  pd_oracle_replay_buffer(path, data, size, replay_row, &run, &err);
  if (interrupted) {
    csv_abort(&csv);
    fprintf(stderr, "polydyn oracle: interrupted; nothing written\n");
    status = 130;
    goto done;
  }
  printf("polydyn oracle: replayed %ld pairs from %s\n", stats.pairs, path);
  pd_oracle_stats_print(&stats, stdout);
  bool written = csv_finish(&csv);
  if (out && written) printf("listed: %ld pairs in %s\n", stats.pairs, out);
  status = !written || pd_oracle_stats_failures(&stats) ? PD_EXIT_FAILURE : PD_EXIT_OK;
done:
  free(data);
  pd_oracle_stats_free(&stats);
  return status;
}

// ---------------------------------------------------------------- arguments

// A whole number in [lo, hi] (decimal digits only).
static bool parse_count(const char* text, unsigned long long hi, unsigned long long* value) {
  if (text[0] < '0' || text[0] > '9') return false;
  char* end = NULL;
  errno = 0;
  unsigned long long v = strtoull(text, &end, 10);
  if (*end != '\0' || errno == ERANGE || v > hi) return false;
  *value = v;
  return true;
}

static bool accept_pairs(const char* cmd, const char* v, void* target) {
  if (parse_count(v, 1000000000ull, target) && *(unsigned long long*)target != 0) return true;
  pd_cli_usage_error(cmd, "--random needs a whole number of pairs, 1 to 1e9");
  return false;
}

static bool accept_seed(const char* cmd, const char* v, void* target) {
  if (parse_count(v, ~0ull, target)) return true;
  pd_cli_usage_error(cmd, "--seed needs a whole number, 0 to 2^64-1");
  return false;
}

static bool accept_repeats(const char* cmd, const char* v, void* target) {
  if (parse_count(v, 101, target) && *(unsigned long long*)target != 0) return true;
  pd_cli_usage_error(cmd, "--repeats needs a whole number, 1 to 101");
  return false;
}

int pd_cmd_oracle(int argc, char** argv) {
  const char *scene = NULL, *out = NULL, *replay = NULL;
  unsigned long long count = 0, seed = 0, repeats = 5;
  bool random = false, seedGiven = false, timing = false, repeatsGiven = false;
  pdCliOverrides overrides = {0};
  const pdCliOption table[] = {
      {.name = "--timing", .kind = pd_optFlag, .target = &timing},
      {.name = "--random", .kind = pd_optAccept, .target = &count, .accept = accept_pairs, .given = &random},
      {.name = "--seed", .kind = pd_optAccept, .target = &seed, .accept = accept_seed, .given = &seedGiven},
      {.name = "--out", .kind = pd_optText, .target = &out, .message = "--out needs a file name", .min = 1},
      {.name = "--tend", .kind = pd_optPositive, .target = &overrides.tend, .message = "--tend needs a number > 0"},
      {.name = "--sample", .kind = pd_optPositive, .target = &overrides.sample,
       .message = "--sample needs a number > 0"},
      {.name = "--replay", .kind = pd_optText, .target = &replay, .message = "--replay needs a file name", .min = 1},
      {.name = "--repeats", .kind = pd_optAccept, .target = &repeats, .accept = accept_repeats,
       .given = &repeatsGiven},
  };
  pdCliPositionals scenes = {.values = &scene, .max = 1, .tooMany = "one scene at a time ('%s' and '%s')"};
  int parsed = pd_cli_parse_options("oracle", argc, argv, table, sizeof table / sizeof table[0], &scenes, help);
  if (parsed >= 0) return parsed;
  int modes = (scene != NULL) + random + (replay != NULL);
  if (modes != 1) return pd_cli_usage_error("oracle", "give exactly one of SCENE, --random N or --replay FILE");
  if (random != seedGiven) return pd_cli_usage_error("oracle", "--random and --seed go together");
  if (!scene && (overrides.tend > 0.0 || overrides.sample > 0.0))
    return pd_cli_usage_error("oracle", "--tend and --sample are for a SCENE");
  if (timing && !random) return pd_cli_usage_error("oracle", "--timing goes with --random N --seed S");
  if (repeatsGiven && !timing) return pd_cli_usage_error("oracle", "--repeats is for --timing");
  if (pd_cli_parse_only) return PD_EXIT_OK;

  // an interrupt removes the partial CSV
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  if (timing) return run_timing((long)count, seed, (int)repeats, out);
  if (random) return run_random((long)count, seed, out);
  if (replay) return run_replay(replay, out);
  return run_scene(scene, &overrides, out);
}
