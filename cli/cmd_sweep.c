// polydyn sweep — work-precision: error against wall time over tolerances and step sizes (docs/DESIGN.md §8,
// reports/FORMATS.md, protocol: shared reference speed-accuracy.md §4.4).
//
// Every point runs the same model (only tol, or the step, changes) with no output files, R times; the
// wall time is the median, the errors (deterministic) are taken from the first run. Each point has two
// errors: `error` against the soft engine at the tightest tolerance (checked against one 10× tighter; both
// are written), and `self_error`, its self-convergence: against its own engine-variant's finest run (the
// soft engine, adaptive or fixed-step: the same tol 1e-12 reference, a finer solution of the very
// equations the fixed-step RK4 integrates; ODE and Bullet, native and matched: their own run at the
// finest step swept, 1/16000 s). `horizon_seconds` is the first sample at which a point's run leaves its
// own finest run by more than SWEEP_HORIZON_THRESHOLD: the horizon of predictability of a chaotic scene.
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdutil/csv.h"
#include "pdutil/json.h"
#include "pdrun/batch.h"
#include "pdref/compare.h"
#include "pdref/refcheck.h"
#include "polydyn/state.h"
#include "pdrun/stats.h"

// The reference tolerance and its check: the sweep's tightest point is 1e-10, the reference two decades
// below it, and its own error is estimated against one a decade tighter still.
#define SWEEP_REFERENCE_TOL 1e-12
#define SWEEP_REFERENCE_CHECK_TOL 1e-13
#define SWEEP_MAX_REPEATS 21
// The horizon of predictability: the first sample time at which a run's pose error against its own finest
// run, max over moving bodies of max(|x - x_ref| / size, rotation angle in rad), exceeds this (no unit: a
// tenth of a body size, or 0.1 rad = 5.7°). Far above what runs that agree leave between them (a resting or
// sliding body: 1e-3 of its size at a loose setting), far below what runs that went separate ways show (a
// tumbling box landing on another face, a pile's box elsewhere: 0.5 and more).
#define SWEEP_HORIZON_THRESHOLD 0.1

static const char* const help =
    "usage: polydyn sweep SCENE --out DIR [--repeats R] [--engines soft,ode,bullet] [--tend T] [--jobs N]\n"
    "                     [--events bounded|exact|held]\n"
    "\n"
    "Work-precision sweep of SCENE: polydyn's default stepper (implicit: step doubling switching to ROS34PW2\n"
    "where the contacts' stability bound holds it), adaptive RK4 (step doubling alone) and its embedded RK4(3)\n"
    "pair at tol 1e-2 ... 1e-10 (decades), its fixed-step RK4 at dt 1e-3 ... 1e-5, ODE and Bullet (native and\n"
    "matched)\n"
    "at steps 1/60 ... 1/16000 s. Errors are the RMS over samples and moving bodies of\n"
    "max(|x - x_ref| / body size, rotation angle in rad):\n"
    "  error        against the soft engine at tol 1e-12 (whose own error, against tol 1e-13, is reported as\n"
    "               the reference's);\n"
    "  self_error   self-convergence: against the engine-variant's own finest run (soft, every stepper: the\n"
    "               same adaptive tol 1e-12 run; ODE and Bullet: their own run at 1/16000 s, whose self_error is\n"
    "               empty, it has no finer run of its own);\n"
    "  horizon      the horizon of predictability: the first sample time at which the run's error against\n"
    "               its own finest run exceeds 0.1 (a tenth of a body size or 0.1 rad) for some body; empty\n"
    "               when it never does.\n"
    "Wall time: median of R runs (default 3), no output files written during the runs; derivatives: the soft\n"
    "engine's derivative evaluations (the cost that does not depend on the machine).\n"
    "Writes DIR/sweep.csv (reports/FORMATS.md) and DIR/reference.json; DIR is replaced atomically.\n"
    "\n"
    "  --events MODE  the soft engine's contact events in every soft run, the reference's too: bounded (default)\n"
    "             or exact, the paper's loop (every onset located; polydyn run --events, docs/events.md)\n"
    "  --jobs N   run N points at a time in worker processes (default 1); under mpirun or srun the points are\n"
    "             split over the ranks (docs/commands.md). Every point's repeats stay in one process, one\n"
    "             after the other, but points running side by side share the machine: the wall times then\n"
    "             measure a loaded machine. Everything but the wall times is the same bytes whatever N.\n"
    "\n"
    "Progress goes to stderr on a terminal. Exit status: 0 ok, 1 the reference run failed or DIR could not be\n"
    "written, 2 bad input, 130 interrupted (SIGINT, SIGTERM: nothing written, an earlier DIR kept).\n";

// RMS over samples and bodies of max(position error / size, rotation angle) against the reference; with
// horizon (nullable), the first sample time at which that error exceeds SWEEP_HORIZON_THRESHOLD for some
// body, NAN when it never does.
static double pose_error(const pdModel* model, const pdTrajectory* run, const pdTrajectory* ref, double* horizon) {
  double sum = 0.0;
  long count = 0;
  if (horizon) *horizon = NAN;
  for (long s = 0; s < run->samples; ++s) {
    double worst = 0.0;
    for (int k = 0; k < run->movingCount; ++k) {
      const pdBodyState* b = &run->bodies[(size_t)s * (size_t)run->movingCount + (size_t)k];
      pdBodyState r = pd_trajectory_at(ref, k, run->t[s]);
      double pos = pd_v3_norm(pd_v3_sub(b->x, r.x)) / model->bodies[model->movingBodies[k]].size;
      double d = fabs(b->q.w * r.q.w + b->q.x * r.q.x + b->q.y * r.q.y + b->q.z * r.q.z);
      double rot = 2.0 * acos(fmin(1.0, d));
      double e = fmax(pos, rot);
      sum += e * e;
      ++count;
      worst = fmax(worst, e);
    }
    if (horizon && isnan(*horizon) && worst > SWEEP_HORIZON_THRESHOLD) *horizon = run->t[s];
  }
  return count ? sqrt(sum / (double)count) : 0.0;
}

// One point of the sweep: what it runs (the same list on every rank) and what it measured.
typedef struct point {
  const char* engine;
  const char* variant;
  const char* setting;  // tol | step
  double value;
  int self;             // index in the kept runs of its own finest run (0: the soft reference)
  bool finest;          // it is that run (an ODE or Bullet variant's finest step): no self_error, no horizon
  // measured: travels between processes as these bytes (pointMeasure)
  bool completed;
  double error;         // against the soft reference; NAN when the run did not complete
  double selfError;     // against its own finest run; NAN when not measured (not completed, the finest itself)
  double horizon;       // s; NAN when never (or not measured)
  double wall;          // median over repeats, s
  long steps;
  long derivatives;  // derivative evaluations of the soft engine's last run; -1 for ODE and Bullet
} point;

typedef struct pointMeasure {
  int32_t completed;
  int32_t unused;
  double error, selfError, horizon, wall;
  int64_t steps, derivatives;
} pointMeasure;

// Every run's observer: records the trajectory when one is given; stops the run at its next sample once the
// sweep is interrupted (pd_cli_catch_interrupts).
static bool observe(const pdModel* model, const pdState* state, void* trajectory) {
  if (pd_cli_interrupted) return false;
  return !trajectory || pd_trajectory_observe(model, state, trajectory);
}

// The soft engine's contact events in every soft run of this sweep (--events; set before any run, workers included).
static pdOnsets sweepOnsets = PD_ONSETS_DEFAULT;

// One soft run: trajectory (when wanted), wall time, steps, derivative evaluations (when wanted), completed.
static bool soft_run(const pdModel* model, pdStepper stepper, pdTrajectory* trajectory, double* wall, long* steps,
                     long* derivatives) {
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  options.onsets = sweepOnsets;
  double t0 = pd_cli_wall_seconds();  // the span of a reference engine's run (pd_ref_run): created, then run
  pdState* state = pd_state_create(model, &options);
  bool ok = pd_advance(model, state, model->settings.tend, observe, trajectory);
  *wall = pd_cli_wall_seconds() - t0;
  *steps = state->count.accepted;
  if (derivatives) *derivatives = state->count.derivatives;
  pd_state_free(state);
  return ok;
}

// A soft point R times; its errors against the soft reference, which is also its own finest run.
static void measure_soft(const char* scene, const pdCliOverrides* base, int repeats, const pdTrajectory* ref, point* p) {
  pdCliOverrides o = *base;
  bool fixed = strcmp(p->variant, "fixed") == 0;
  if (fixed) o.dt = p->value;
  else o.tol = p->value;
  pdModel* model = pd_cli_load_model(scene, &o, NULL);
  p->completed = false;
  p->error = p->selfError = p->horizon = p->wall = NAN;
  p->steps = p->derivatives = 0;
  if (!model) return;
  double walls[SWEEP_MAX_REPEATS];
  pdTrajectory* tr = pd_trajectory_create(model);
  pdStepper stepper = fixed                                 ? pd_stepperRK4Fixed
                      : strcmp(p->variant, "embedded") == 0 ? pd_stepperRK43Embedded
                      : strcmp(p->variant, "implicit") == 0 ? pd_stepperImplicit
                                                            : pd_stepperRK4Adaptive;
  for (int r = 0; r < repeats; ++r) {
    p->completed = soft_run(model, stepper, r == 0 ? tr : NULL, &walls[r], &p->steps, &p->derivatives);
    if (!p->completed) break;
  }
  if (p->completed) {
    p->error = p->selfError = pose_error(model, tr, ref, &p->horizon);
    p->wall = pd_median_in_place(walls, repeats);
  }
  pd_trajectory_free(tr);
  pd_model_free(model);
}

// An ODE or Bullet point R times, the first run's trajectory into tr (made empty); completed, wall, steps.
static void run_reference_engine(const pdModel* model, int repeats, point* p, pdTrajectory* tr) {
  const pdRefAdapter* adapter = pd_ref_adapter(p->engine);
  PD_ASSERT(adapter != NULL);
  p->completed = false;
  p->error = p->selfError = p->horizon = p->wall = NAN;
  p->steps = 0;
  p->derivatives = -1;
  double walls[SWEEP_MAX_REPEATS];
  pdRefOptions o = {.variant = strcmp(p->variant, "matched") == 0 ? pd_refMatched : pd_refNative,
                    .step = p->value,
                    .odeFriction = pd_odeFrictionPyramid};
  for (int r = 0; r < repeats; ++r) {
    pdRefRunStats stats;
    pdError err = {0};
    bool ok = pd_ref_run(model, adapter, &o, NULL, observe, r == 0 ? tr : NULL, &stats, &err);
    p->completed = ok && stats.completed;
    p->steps = stats.steps;
    walls[r] = stats.wallSeconds;
    if (!p->completed) break;
  }
  if (p->completed) p->wall = pd_median_in_place(walls, repeats);
}

// ---------------------------------------------------------------- the runs as batch tasks

// A run whose trajectory every rank gets, a task of the first batch: the soft reference (kept run 0) or
// its check (1), both with point NULL, or the finest point of an ODE or Bullet variant, measured as every
// point (R repeats) and kept as its variant's own reference for the coarser points of the second batch.
typedef struct keptRun {
  const pdModel* model;
  point* point;  // NULL: a soft run at model's tolerance
  pdTrajectory* trajectory;
  bool completed;
  double wall;
  long steps;
} keptRun;

typedef struct keptRuns {
  keptRun* runs;
  int repeats;
  bool progress;  // show it (stderr is a terminal)
} keptRuns;

typedef struct keptHeader {
  int32_t completed, movingCount;
  int64_t samples, steps;
  double wall;
} keptHeader;

static void kept_task(int task, pdBatchBuffer* result, void* user) {
  const keptRuns* all = user;
  const keptRun* r = &all->runs[task];
  pdTrajectory* tr = pd_trajectory_create(r->model);
  double wall;
  long steps;
  bool completed;
  if (r->point) {
    point p = *r->point;
    run_reference_engine(r->model, all->repeats, &p, tr);
    completed = p.completed;
    wall = p.wall;
    steps = p.steps;
  } else {
    completed = soft_run(r->model, pd_stepperRK4Adaptive, tr, &wall, &steps, NULL);
  }
  keptHeader h = {completed, tr->movingCount, tr->samples, steps, wall};
  pd_batch_append(result, &h, sizeof h);
  pd_batch_append(result, tr->t, (size_t)tr->samples * sizeof *tr->t);
  pd_batch_append(result, tr->bodies, (size_t)tr->samples * (size_t)tr->movingCount * sizeof *tr->bodies);
  pd_trajectory_free(tr);
}

// Fills r->trajectory (made empty), completed, wall and steps from a kept_task's bytes; false when they are
// not whole (a run that did not complete still reads true, with r->completed false).
static bool take_kept(const pdBatchBuffer* bytes, keptRun* r) {
  keptHeader h;
  size_t at = 0;
  if (!pd_batch_read(bytes, &at, &h, sizeof h) || h.movingCount != r->trajectory->movingCount) return false;
  pdTrajectory* tr = r->trajectory;
  size_t bodies = (size_t)h.samples * (size_t)h.movingCount;
  tr->t = malloc((size_t)h.samples * sizeof *tr->t + 1);
  tr->bodies = malloc(bodies * sizeof *tr->bodies + 1);
  if (!tr->t || !tr->bodies) abort();
  tr->samples = tr->capacity = (long)h.samples;
  r->completed = h.completed;
  r->wall = h.wall;
  r->steps = (long)h.steps;
  return pd_batch_read(bytes, &at, tr->t, (size_t)h.samples * sizeof *tr->t) &&
         pd_batch_read(bytes, &at, tr->bodies, bodies * sizeof *tr->bodies);
}

static bool kept_progress(int task, int done, int total, void* user) {
  const keptRuns* all = user;
  if (task >= 0 && all->progress) {
    const point* p = all->runs[task].point;
    if (p)
      fprintf(stderr, "\rpolydyn sweep: reference runs: %s %s %s %.3g (%d/%d)\033[K", p->engine, p->variant, p->setting,
              p->value, done, total);
    else
      fprintf(stderr, "\rpolydyn sweep: reference runs: soft tol %g (%d/%d)\033[K", all->runs[task].model->settings.tol,
              done, total);
  }
  return !pd_cli_interrupted;
}

typedef struct pointRuns {
  const char* scene;
  const pdCliOverrides* base;
  int repeats;
  const pdModel* refModel;
  const keptRun* kept;  // [0]: the soft reference
  point* points;
  const int* todo;      // the second batch's task k is point todo[k]
  bool progress;
} pointRuns;

static void point_task(int task, pdBatchBuffer* result, void* user) {
  const pointRuns* r = user;
  point p = r->points[r->todo[task]];
  const pdTrajectory* ref = r->kept[0].trajectory;
  if (strcmp(p.engine, "soft") == 0) {
    measure_soft(r->scene, r->base, r->repeats, ref, &p);
  } else {
    pdTrajectory* tr = pd_trajectory_create(r->refModel);
    run_reference_engine(r->refModel, r->repeats, &p, tr);
    const keptRun* self = &r->kept[p.self];
    if (p.completed) p.error = pose_error(r->refModel, tr, ref, NULL);
    if (p.completed && self->completed) p.selfError = pose_error(r->refModel, tr, self->trajectory, &p.horizon);
    pd_trajectory_free(tr);
  }
  pointMeasure m = {p.completed, 0, p.error, p.selfError, p.horizon, p.wall, p.steps, p.derivatives};
  pd_batch_append(result, &m, sizeof m);
}

static void take_point(const pdBatchBuffer* bytes, point* p) {
  pointMeasure m;
  size_t at = 0;
  bool whole = pd_batch_read(bytes, &at, &m, sizeof m);
  PD_ASSERT(whole);
  p->completed = m.completed;
  p->error = m.error;
  p->selfError = m.selfError;
  p->horizon = m.horizon;
  p->wall = m.wall;
  p->steps = (long)m.steps;
  p->derivatives = (long)m.derivatives;
}

static bool point_progress(int task, int done, int total, void* user) {
  const pointRuns* r = user;
  if (task >= 0 && r->progress) {
    const point* p = &r->points[r->todo[task]];
    fprintf(stderr, "\rpolydyn sweep: %s %s %s %.3g (%d/%d)\033[K", p->engine, p->variant, p->setting, p->value,
            done, total);
  }
  return !pd_cli_interrupted;
}

// "ENGINE VARIANT SETTING=VALUE" of the run a point's self_error is measured against.
static void self_reference_name(const keptRun* kept, const point* p, char* name, size_t size) {
  const point* f = kept[p->self].point;
  if (f) snprintf(name, size, "%s %s %s=%.6g", f->engine, f->variant, f->setting, f->value);
  else snprintf(name, size, "soft tol=%g", SWEEP_REFERENCE_TOL);
}

// --engines: a comma-separated list of soft, ode and bullet.
static bool accept_engines(const char* cmd, const char* v, void* target) {
  for (const char* q = v; *q;) {
    const char* comma = strchr(q, ',');
    size_t len = comma ? (size_t)(comma - q) : strlen(q);
    if (!((len == 4 && !strncmp(q, "soft", 4)) || (len == 3 && !strncmp(q, "ode", 3)) ||
          (len == 6 && !strncmp(q, "bullet", 6)))) {
      pd_cli_usage_error(cmd, "--engines: unknown engine '%.*s' (soft, ode, bullet)", (int)len, q);
      return false;
    }
    q = comma ? comma + 1 : q + len;
  }
  *(const char**)target = v;
  return true;
}

static bool accept_events(const char* cmd, const char* v, void* target) {
  if (pd_cli_events(v, target)) return true;
  pd_cli_usage_error(cmd, "--events must be bounded, exact or held");
  return false;
}

int pd_cmd_sweep(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  const char* engines = "soft,ode,bullet";
  long repeats = 3;
  int jobs = 0;
  pdCliOverrides base = {0};
  char repeatsMessage[64], jobsMessage[64];
  snprintf(repeatsMessage, sizeof repeatsMessage, "--repeats needs a whole number 1..%d", SWEEP_MAX_REPEATS);
  snprintf(jobsMessage, sizeof jobsMessage, "--jobs needs a whole number 1..%d", PD_CLI_MAX_JOBS);
  const pdCliOption table[] = {
      {.name = "--out", .kind = pd_optText, .target = &out, .message = "--out needs a directory name (< 3000 bytes)",
       .min = 1, .max = 3000},
      {.name = "--repeats", .kind = pd_optWhole, .target = &repeats, .message = repeatsMessage, .min = 1,
       .max = SWEEP_MAX_REPEATS},
      {.name = "--engines", .kind = pd_optAccept, .target = &engines, .accept = accept_engines},
      {.name = "--tend", .kind = pd_optPositive, .target = &base.tend, .message = "--tend needs a number > 0"},
      {.name = "--jobs", .kind = pd_optJobs, .target = &jobs, .message = jobsMessage},
      {.name = "--events", .kind = pd_optAccept, .target = &sweepOnsets, .accept = accept_events},
  };
  pdCliPositionals scenes = {.values = &scene, .max = 1, .tooMany = "one scene at a time ('%s' and '%s')"};
  int parsed = pd_cli_parse_options("sweep", argc, argv, table, sizeof table / sizeof table[0], &scenes, help);
  if (parsed >= 0) return parsed;
  if (!scene) return pd_cli_usage_error("sweep", "no scene given");
  if (!out) return pd_cli_usage_error("sweep", "--out DIR is required");
  if (pd_cli_parse_only) return PD_EXIT_OK;
  bool progress = isatty(STDERR_FILENO) == 1;

  jobs = pd_cli_default_jobs(jobs, 1);  // one at a time unless asked: the wall times are the measurement

  // the points, in the order of sweep.csv
  enum { MAX_POINTS = 64, MAX_KEPT = 2 + 4 };
  point points[MAX_POINTS];
  int count = 0;
  static const double tols[] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  static const double fixedSteps[] = {1e-3, 3e-4, 1e-4, 3e-5, 1e-5};
  static const double refSteps_[] = {1.0 / 60, 1.0 / 250, 1.0 / 1000, 1.0 / 4000, 1.0 / 16000};
  enum { REF_STEPS = sizeof refSteps_ / sizeof refSteps_[0] };
  if (pd_cli_list_has(engines, "soft")) {
    for (size_t i = 0; i < sizeof tols / sizeof tols[0]; ++i) points[count++] = (point){.engine = "soft", .variant = "adaptive", .setting = "tol", .value = tols[i]};
    for (size_t i = 0; i < sizeof fixedSteps / sizeof fixedSteps[0]; ++i)
      points[count++] = (point){.engine = "soft", .variant = "fixed", .setting = "step", .value = fixedSteps[i]};
    for (size_t i = 0; i < sizeof tols / sizeof tols[0]; ++i)
      points[count++] = (point){.engine = "soft", .variant = "embedded", .setting = "tol", .value = tols[i]};
    for (size_t i = 0; i < sizeof tols / sizeof tols[0]; ++i)
      points[count++] = (point){.engine = "soft", .variant = "implicit", .setting = "tol", .value = tols[i]};
  }
  // the kept runs: the soft reference, its check, and each ODE and Bullet variant's finest step (its own
  // reference: the variant's coarser points are measured against it in the second batch)
  keptRun kept[MAX_KEPT] = {{.model = NULL}};
  int keptCount = 2;
  static const char* const refNames[] = {"ode", "bullet"};
  for (int e = 0; e < 2; ++e) {
    if (!pd_cli_list_has(engines, refNames[e])) continue;
    if (!pd_ref_adapter(refNames[e])) {
      if (pd_batch_is_root()) fprintf(stderr, "polydyn sweep: this build has no %s adapter; skipped\n", refNames[e]);
      continue;
    }
    for (int v = 0; v < 2; ++v) {
      for (int i = 0; i < REF_STEPS; ++i)
        points[count++] = (point){.engine = refNames[e], .variant = v ? "matched" : "native", .setting = "step",
                                  .value = refSteps_[i], .self = keptCount, .finest = i == REF_STEPS - 1};
      kept[keptCount++].point = &points[count - 1];
    }
  }

  // the first batch: the kept runs, their trajectories on every rank (every point needs the reference)
  pdCliOverrides refO = base, checkO = base;
  refO.tol = SWEEP_REFERENCE_TOL;
  checkO.tol = SWEEP_REFERENCE_CHECK_TOL;
  pdModel* refModel = pd_cli_load_model(scene, &refO, NULL);
  if (!refModel) return PD_EXIT_BAD_INPUT;
  pdModel* checkModel = pd_cli_load_model(scene, &checkO, NULL);
  if (!checkModel) {
    pd_model_free(refModel);
    return PD_EXIT_BAD_INPUT;
  }
  for (int k = 0; k < keptCount; ++k) kept[k].model = k == 1 ? checkModel : refModel;
  keptRuns keptAll = {kept, (int)repeats, progress};
  pd_cli_catch_interrupts();
  pdBatchBuffer keptBytes[MAX_KEPT];
  char why[256] = "";
  pdBatchOptions batch = {.workers = jobs, .everywhere = true, .progress = kept_progress, .progressUser = &keptAll};
  bool refOk = pd_batch_run(keptCount, kept_task, &keptAll, &batch, keptBytes, why, sizeof why);
  for (int k = 0; k < keptCount; ++k) {
    kept[k].trajectory = pd_trajectory_create(kept[k].model);
    refOk = refOk && take_kept(&keptBytes[k], &kept[k]);
    pd_batch_buffer_free(&keptBytes[k]);
  }
  pdTrajectory* ref = kept[0].trajectory;
  pdTrajectory* check = kept[1].trajectory;
  refOk = refOk && kept[0].completed && kept[1].completed;
  if (pd_cli_interrupted) refOk = false;
  if (!refOk) {
    if (progress) fputs("\r\033[K", stderr);
    if (pd_cli_interrupted) {
      if (pd_batch_is_root()) fprintf(stderr, "polydyn sweep: interrupted; nothing written\n");
    } else {
      if (why[0]) fprintf(stderr, "polydyn sweep: %s\n", why);
      fprintf(stderr, "polydyn sweep: the reference run (soft at tol %g) did not complete\n", SWEEP_REFERENCE_TOL);
    }
    for (int k = 0; k < keptCount; ++k) pd_trajectory_free(kept[k].trajectory);
    pd_model_free(refModel);
    pd_model_free(checkModel);
    return pd_cli_interrupted ? 130 : PD_EXIT_FAILURE;
  }
  double refHorizon;  // when the reference itself leaves its check: where no point can be judged any more
  double refError = pose_error(refModel, ref, check, &refHorizon);
  double refWall = kept[0].wall;
  long refSteps = kept[0].steps;
  // the finest points measured in the first batch: their error against the soft reference
  for (int k = 2; k < keptCount; ++k) {
    point* p = kept[k].point;
    p->completed = kept[k].completed;
    p->error = p->completed ? pose_error(refModel, kept[k].trajectory, ref, NULL) : NAN;
    p->selfError = p->horizon = NAN;
    p->wall = p->completed ? kept[k].wall : NAN;
    p->steps = kept[k].steps;
    p->derivatives = -1;
  }

  // the second batch: every other point, one task each
  int todo[MAX_POINTS], todoCount = 0;
  for (int i = 0; i < count; ++i)
    if (!points[i].finest) todo[todoCount++] = i;
  pointRuns runs = {scene, &base, (int)repeats, refModel, kept, points, todo, progress};
  pdBatchBuffer* measured = calloc((size_t)todoCount + 1, sizeof *measured);
  if (!measured) abort();
  batch = (pdBatchOptions){.workers = jobs, .progress = point_progress, .progressUser = &runs};
  bool pointsOk = pd_batch_run(todoCount, point_task, &runs, &batch, measured, why, sizeof why);
  for (int k = 0; k < todoCount; ++k) {
    if (pointsOk && pd_batch_is_root()) take_point(&measured[k], &points[todo[k]]);
    pd_batch_buffer_free(&measured[k]);
  }
  free(measured);
  if (progress) fputs("\r\033[K", stderr);
  // DIR under a temporary name, made only now (an interrupted sweep leaves nothing); MPI: rank 0 writes
  char tmp[4096];
  if (pd_cli_interrupted) pointsOk = false;
  bool opened = pointsOk && pd_cli_out_open("sweep", out, "sweep.csv", tmp, sizeof tmp);
  if (!opened || !pd_batch_is_root()) {
    if (pd_cli_interrupted && pd_batch_is_root())
      fprintf(stderr, "polydyn sweep: interrupted; nothing written\n");
    else if (!pointsOk)
      fprintf(stderr, "polydyn sweep: %s\n", why);
    for (int k = 0; k < keptCount; ++k) pd_trajectory_free(kept[k].trajectory);
    pd_model_free(refModel);
    pd_model_free(checkModel);
    return pd_cli_interrupted ? 130 : !pointsOk ? PD_EXIT_FAILURE : opened ? PD_EXIT_OK : PD_EXIT_BAD_INPUT;
  }

  // write DIR's files, then rename
  char path[4400];
  int status = PD_EXIT_OK;
  {
    char refName[128];
    snprintf(refName, sizeof refName, "soft tol=%g", SWEEP_REFERENCE_TOL);
    double tend = refModel->settings.tend;
    snprintf(path, sizeof path, "%s/sweep.csv", tmp);
    FILE* f = fopen(path, "w");
    bool ok = f != NULL;
    if (f) {
      fputs(
          "scene,engine,variant,setting,value,error,error_kind,wall_seconds,wall_per_sim_second,steps,repeats,"
          "reference,self_error,self_reference,horizon_seconds,derivatives\n",
          f);
      for (int i = 0; i < count; ++i) {
        const point* p = &points[i];
        char selfName[128];
        self_reference_name(kept, p, selfName, sizeof selfName);
        pdu_csv_quoted(f, scene);  // quoted in every row, as it always was
        const char* const texts[] = {p->engine, p->variant, p->setting};
        for (int k = 0; k < 3; ++k) {
          fputc(',', f);
          pdu_csv_text(f, texts[k]);
        }
        fprintf(f, ",%.6g,", p->value);
        if (p->completed) fprintf(f, "%.6g", p->error);
        fprintf(f, ",rms_pose,");
        if (p->completed) fprintf(f, "%.6g,%.6g", p->wall, p->wall / tend);
        else fputc(',', f);
        fprintf(f, ",%ld,%ld,", p->steps, repeats);
        pdu_csv_text(f, refName);
        fputc(',', f);
        if (p->completed && !isnan(p->selfError)) fprintf(f, "%.6g", p->selfError);
        fputc(',', f);
        pdu_csv_text(f, selfName);
        fputc(',', f);
        if (p->completed && !isnan(p->horizon)) fprintf(f, "%.6g", p->horizon);
        fputc(',', f);
        if (p->completed && p->derivatives >= 0) fprintf(f, "%ld", p->derivatives);
        fputc('\n', f);
      }
      ok = !ferror(f);
      ok = fclose(f) == 0 && ok;
    }
    snprintf(path, sizeof path, "%s/reference.json", tmp);
    f = ok ? fopen(path, "w") : NULL;
    if (f) {
      char horizonText[32] = "null";
      if (!isnan(refHorizon)) snprintf(horizonText, sizeof horizonText, "%.6g", refHorizon);
      fputs("{\"scene\": ", f);
      pdu_json_string(f, scene);
      fprintf(f,
              ", \"engine\": \"soft\", \"tol\": %g, \"steps\": %ld, \"wall_seconds\": %.6g,\n"
              " \"check_tol\": %g, \"error_against_check\": %.6g,\n"
              " \"error_kind\": \"rms over samples and moving bodies of max(|x - x_ref| / size, rotation angle rad)"
              "\",\n \"horizon_threshold\": %g, \"horizon_against_check_seconds\": %s}\n",
              SWEEP_REFERENCE_TOL, refSteps, refWall, SWEEP_REFERENCE_CHECK_TOL, refError,
              SWEEP_HORIZON_THRESHOLD, horizonText);
      ok = !ferror(f);
      ok = fclose(f) == 0 && ok;
    } else {
      ok = false;
    }
    if (!ok) {
      fprintf(stderr, "polydyn sweep: cannot write %s: %s\n", tmp, strerror(errno));
      pd_cli_remove_tree(tmp);
    }
    if (!ok || !pd_cli_out_close("sweep", tmp, out)) {
      status = PD_EXIT_FAILURE;
    } else {
      printf("%-8s %-9s %-5s %10s %12s %12s %12s %10s\n", "engine", "variant", "set", "value", "error", "self error",
             "wall/sim s", "horizon");
      for (int i = 0; i < count; ++i) {
        const point* p = &points[i];
        char self[32] = "-", horizon[32] = "never";
        if (!isnan(p->selfError)) snprintf(self, sizeof self, "%.3g", p->selfError);
        if (isnan(p->selfError)) snprintf(horizon, sizeof horizon, "-");
        else if (!isnan(p->horizon)) snprintf(horizon, sizeof horizon, "%.3g s", p->horizon);
        if (p->completed)
          printf("%-8s %-9s %-5s %10.3g %12.3g %12s %12.3g %10s\n", p->engine, p->variant, p->setting, p->value,
                 p->error, self, p->wall / tend, horizon);
        else
          printf("%-8s %-9s %-5s %10.3g %12s\n", p->engine, p->variant, p->setting, p->value, "failed");
      }
      printf("reference: soft at tol %g (its error against tol %g: %.3g", SWEEP_REFERENCE_TOL,
             SWEEP_REFERENCE_CHECK_TOL, refError);
      if (!isnan(refHorizon)) printf(", apart by %g from %.3g s", SWEEP_HORIZON_THRESHOLD, refHorizon);
      printf("); self error: against the engine-variant's own finest run; horizon: the first time it is %g apart;"
             " %s/sweep.csv\n", SWEEP_HORIZON_THRESHOLD, out);
    }
  }
  for (int k = 0; k < keptCount; ++k) pd_trajectory_free(kept[k].trajectory);
  pd_model_free(refModel);
  pd_model_free(checkModel);
  return status;
}
