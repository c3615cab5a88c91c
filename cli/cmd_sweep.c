// polydyn sweep — work-precision: error against wall time over tolerances and step sizes (DESIGN §5,
// reports/FORMATS.md, protocol: shared reference speed-accuracy.md §4.4).
//
// Every point runs the same model (only tol, or the step, changes) with no output files, R times; the
// wall time is the median, the error (deterministic) is taken from the first. The reference is the soft
// engine at the tightest tolerance, checked against one 10× tighter; both are written.
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
#include "polydyn/batch.h"
#include "polydyn/compare.h"
#include "polydyn/refcheck.h"
#include "polydyn/state.h"

// The reference tolerance and its check: the sweep's tightest point is 1e-10, the reference two decades
// below it, and its own error is estimated against one a decade tighter still.
#define SWEEP_REFERENCE_TOL 1e-12
#define SWEEP_REFERENCE_CHECK_TOL 1e-13
#define SWEEP_MAX_REPEATS 21

static const char* const help =
    "usage: polydyn sweep SCENE --out DIR [--repeats R] [--engines soft,ode,bullet] [--tend T] [--jobs N]\n"
    "\n"
    "Work-precision sweep of SCENE: polydyn's adaptive RK4 at tol 1e-2 ... 1e-10 (decades) and its fixed-step\n"
    "RK4 at dt 1e-3 ... 1e-5, ODE and Bullet (native and matched) at steps 1/60 ... 1/16000 s. The error of\n"
    "each point is the RMS over samples and moving bodies of max(|x - x_ref| / body size, rotation angle in\n"
    "rad) against the soft engine at tol 1e-12 (whose own error, against tol 1e-13, is reported as the\n"
    "reference's). Wall time: median of R runs (default 3), no output files written during the runs.\n"
    "Writes DIR/sweep.csv (reports/FORMATS.md) and DIR/reference.json; DIR is replaced atomically.\n"
    "\n"
    "  --jobs N   run N points at a time in worker processes (default 1); under mpirun or srun the points are\n"
    "             split over the ranks (README, Batch runs). Every point's repeats stay in one process, one\n"
    "             after the other, but points running side by side share the machine: the wall times then\n"
    "             measure a loaded machine. Everything but the wall times is the same bytes whatever N.\n"
    "\n"
    "Progress goes to stderr on a terminal. Exit status: 0 ok, 1 the reference run failed, 2 bad input.\n";

static int compare_doubles(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

static double median(double* v, int n) {
  qsort(v, (size_t)n, sizeof *v, compare_doubles);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// RMS over samples and bodies of max(position error / size, rotation angle) against the reference.
static double pose_error(const pdModel* model, const pdTrajectory* run, const pdTrajectory* ref) {
  double sum = 0.0;
  long count = 0;
  for (long s = 0; s < run->samples; ++s)
    for (int k = 0; k < run->movingCount; ++k) {
      const pdBodyState* b = &run->bodies[(size_t)s * (size_t)run->movingCount + (size_t)k];
      pdBodyState r = pd_trajectory_at(ref, k, run->t[s]);
      double pos = pd_v3_norm(pd_v3_sub(b->x, r.x)) / model->bodies[model->movingBodies[k]].size;
      double d = fabs(b->q.w * r.q.w + b->q.x * r.q.x + b->q.y * r.q.y + b->q.z * r.q.z);
      double rot = 2.0 * acos(fmin(1.0, d));
      double e = fmax(pos, rot);
      sum += e * e;
      ++count;
    }
  return count ? sqrt(sum / (double)count) : 0.0;
}

// One point of the sweep: what it runs (the same list on every rank) and what it measured.
typedef struct point {
  const char* engine;
  const char* variant;
  const char* setting;  // tol | step
  double value;
  // measured: travels between processes as these bytes (pointMeasure)
  bool completed;
  double error;         // NAN when the run did not complete
  double wall;          // median over repeats, s
  long steps;
} point;

typedef struct pointMeasure {
  int32_t completed;
  int32_t unused;
  double error, wall;
  int64_t steps;
} pointMeasure;

// One soft run: trajectory (when wanted), wall time, steps, completed.
static bool soft_run(const pdModel* model, pdStepper stepper, pdTrajectory* trajectory, double* wall, long* steps) {
  pdState* state = pd_state_create(model);
  state->stepper = stepper;
  double t0 = pd_cli_wall_seconds();
  bool ok = pd_advance(model, state, model->settings.tend, trajectory ? pd_trajectory_observe : NULL, trajectory);
  *wall = pd_cli_wall_seconds() - t0;
  *steps = state->count.accepted;
  pd_state_free(state);
  return ok;
}

static void measure_soft(const char* scene, const pdCliOverrides* base, int repeats, const pdTrajectory* ref, point* p) {
  pdCliOverrides o = *base;
  bool fixed = strcmp(p->variant, "fixed") == 0;
  if (fixed) o.dt = p->value;
  else o.tol = p->value;
  pdModel* model = pd_cli_load_model(scene, &o, NULL);
  p->completed = false;
  p->error = p->wall = NAN;
  p->steps = 0;
  if (!model) return;
  double walls[SWEEP_MAX_REPEATS];
  pdTrajectory* tr = pd_trajectory_create(model);
  for (int r = 0; r < repeats; ++r) {
    p->completed = soft_run(model, fixed ? pd_stepperRK4Fixed : pd_stepperRK4Adaptive, r == 0 ? tr : NULL,
                            &walls[r], &p->steps);
    if (!p->completed) break;
  }
  if (p->completed) {
    p->error = pose_error(model, tr, ref);
    p->wall = median(walls, repeats);
  }
  pd_trajectory_free(tr);
  pd_model_free(model);
}

static void measure_reference_engine(const pdModel* model, int repeats, const pdTrajectory* ref, point* p) {
  const pdRefAdapter* adapter = pd_ref_adapter(p->engine);
  PD_ASSERT(adapter != NULL);
  p->completed = false;
  p->error = p->wall = NAN;
  p->steps = 0;
  double walls[SWEEP_MAX_REPEATS];
  pdTrajectory* tr = pd_trajectory_create(model);
  pdRefOptions o = {strcmp(p->variant, "matched") == 0 ? pd_refMatched : pd_refNative, p->value, pd_odeFrictionPyramid};
  for (int r = 0; r < repeats; ++r) {
    pdRefRunStats stats;
    pdError err = {0};
    bool ok = pd_ref_run(model, adapter, &o, NULL, r == 0 ? pd_trajectory_observe : NULL, r == 0 ? tr : NULL,
                         &stats, &err);
    p->completed = ok && stats.completed;
    p->steps = stats.steps;
    walls[r] = stats.wallSeconds;
    if (!p->completed) break;
  }
  if (p->completed) {
    p->error = pose_error(model, tr, ref);
    p->wall = median(walls, repeats);
  }
  pd_trajectory_free(tr);
}

// ---------------------------------------------------------------- the runs as batch tasks

// The reference or its check: a soft run at a tight tolerance whose trajectory every rank gets.
typedef struct referenceRun {
  const pdModel* model;
  pdTrajectory* trajectory;
  double wall;
  long steps;
} referenceRun;

typedef struct referenceHeader {
  int32_t completed, movingCount;
  int64_t samples, steps;
  double wall;
} referenceHeader;

static void reference_task(int task, pdBatchBuffer* result, void* user) {
  const referenceRun* r = &((const referenceRun*)user)[task];
  pdTrajectory* tr = pd_trajectory_create(r->model);
  double wall;
  long steps;
  bool completed = soft_run(r->model, pd_stepperRK4Adaptive, tr, &wall, &steps);
  referenceHeader h = {completed, tr->movingCount, tr->samples, steps, wall};
  pd_batch_append(result, &h, sizeof h);
  pd_batch_append(result, tr->t, (size_t)tr->samples * sizeof *tr->t);
  pd_batch_append(result, tr->bodies, (size_t)tr->samples * (size_t)tr->movingCount * sizeof *tr->bodies);
  pd_trajectory_free(tr);
}

// Fills r->trajectory (made empty), wall and steps from a reference_task's bytes; false when the run failed.
static bool take_reference(const pdBatchBuffer* bytes, referenceRun* r) {
  referenceHeader h;
  size_t at = 0;
  if (!pd_batch_read(bytes, &at, &h, sizeof h) || !h.completed || h.movingCount != r->trajectory->movingCount)
    return false;
  pdTrajectory* tr = r->trajectory;
  size_t bodies = (size_t)h.samples * (size_t)h.movingCount;
  tr->t = malloc((size_t)h.samples * sizeof *tr->t + 1);
  tr->bodies = malloc(bodies * sizeof *tr->bodies + 1);
  if (!tr->t || !tr->bodies) abort();
  tr->samples = tr->capacity = (long)h.samples;
  r->wall = h.wall;
  r->steps = (long)h.steps;
  return pd_batch_read(bytes, &at, tr->t, (size_t)h.samples * sizeof *tr->t) &&
         pd_batch_read(bytes, &at, tr->bodies, bodies * sizeof *tr->bodies);
}

typedef struct pointRuns {
  const char* scene;
  const pdCliOverrides* base;
  int repeats;
  const pdModel* refModel;
  const pdTrajectory* ref;
  point* points;
  bool progress;
} pointRuns;

static void point_task(int task, pdBatchBuffer* result, void* user) {
  const pointRuns* r = user;
  point p = r->points[task];
  if (strcmp(p.engine, "soft") == 0) measure_soft(r->scene, r->base, r->repeats, r->ref, &p);
  else measure_reference_engine(r->refModel, r->repeats, r->ref, &p);
  pointMeasure m = {p.completed, 0, p.error, p.wall, p.steps};
  pd_batch_append(result, &m, sizeof m);
}

static void take_point(const pdBatchBuffer* bytes, point* p) {
  pointMeasure m;
  size_t at = 0;
  bool whole = pd_batch_read(bytes, &at, &m, sizeof m);
  PD_ASSERT(whole);
  p->completed = m.completed;
  p->error = m.error;
  p->wall = m.wall;
  p->steps = (long)m.steps;
}

static bool point_progress(int task, int done, int total, void* user) {
  const pointRuns* r = user;
  if (task >= 0) {
    const point* p = &r->points[task];
    fprintf(stderr, "\rpolydyn sweep: %s %s %s %.3g (%d/%d)\033[K", p->engine, p->variant, p->setting, p->value,
            done, total);
  }
  return true;
}

int pd_cmd_sweep(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  const char* engines = "soft,ode,bullet";
  long repeats = 3;
  int jobs = 0;
  pdCliOverrides base = {0};
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (pd_cli_is_help(a)) {
      fputs(help, stdout);
      return PD_EXIT_OK;
    } else if (strcmp(a, "--out") == 0 || strcmp(a, "--repeats") == 0 || strcmp(a, "--engines") == 0 ||
               strcmp(a, "--tend") == 0 || strcmp(a, "--jobs") == 0) {
      if (i + 1 >= argc) return pd_cli_usage_error("sweep", "%s needs a value", a);
      const char* v = argv[++i];
      if (strcmp(a, "--out") == 0) {
        if (!v[0] || strlen(v) > 3000) return pd_cli_usage_error("sweep", "--out needs a directory name (< 3000 bytes)");
        out = v;
      } else if (strcmp(a, "--repeats") == 0) {
        char* end = NULL;
        repeats = strtol(v, &end, 10);
        if (!end || *end || repeats < 1 || repeats > SWEEP_MAX_REPEATS)
          return pd_cli_usage_error("sweep", "--repeats needs a whole number 1..%d", SWEEP_MAX_REPEATS);
      } else if (strcmp(a, "--engines") == 0) {
        for (const char* q = v; *q;) {
          const char* comma = strchr(q, ',');
          size_t len = comma ? (size_t)(comma - q) : strlen(q);
          if (!((len == 4 && !strncmp(q, "soft", 4)) || (len == 3 && !strncmp(q, "ode", 3)) ||
                (len == 6 && !strncmp(q, "bullet", 6))))
            return pd_cli_usage_error("sweep", "--engines: unknown engine '%.*s' (soft, ode, bullet)", (int)len, q);
          q = comma ? comma + 1 : q + len;
        }
        engines = v;
      } else if (strcmp(a, "--jobs") == 0) {
        if (!pd_cli_jobs(v, &jobs)) return pd_cli_usage_error("sweep", "--jobs needs a whole number 1..%d", PD_CLI_MAX_JOBS);
      } else if (!pd_cli_positive(v, &base.tend)) {
        return pd_cli_usage_error("sweep", "--tend needs a number > 0");
      }
    } else if (a[0] == '-' && a[1] != '\0') {
      return pd_cli_usage_error("sweep", "unknown option '%s'", a);
    } else if (scene) {
      return pd_cli_usage_error("sweep", "one scene at a time ('%s' and '%s')", scene, a);
    } else {
      scene = a;
    }
  }
  if (!scene) return pd_cli_usage_error("sweep", "no scene given");
  if (!out) return pd_cli_usage_error("sweep", "--out DIR is required");
  if (pd_cli_parse_only) return PD_EXIT_OK;
  bool progress = isatty(STDERR_FILENO) == 1;

  jobs = pd_cli_default_jobs(jobs, 1);  // one at a time unless asked: the wall times are the measurement

  // the reference and its check: two tasks, their trajectories on every rank (every point needs the reference)
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
  if (progress) fprintf(stderr, "\rpolydyn sweep: reference (tol %g) and its check (tol %g)\033[K", SWEEP_REFERENCE_TOL,
                        SWEEP_REFERENCE_CHECK_TOL);
  referenceRun references[2] = {{.model = refModel}, {.model = checkModel}};
  pdBatchBuffer referenceBytes[2];
  char why[256] = "";
  pdBatchOptions batch = {.workers = jobs, .everywhere = true};
  bool refOk = pd_batch_run(2, reference_task, references, &batch, referenceBytes, why, sizeof why);
  for (int k = 0; k < 2; ++k) {
    references[k].trajectory = pd_trajectory_create(references[k].model);
    refOk = refOk && take_reference(&referenceBytes[k], &references[k]);
    pd_batch_buffer_free(&referenceBytes[k]);
  }
  pdTrajectory* ref = references[0].trajectory;
  pdTrajectory* check = references[1].trajectory;
  if (!refOk) {
    if (progress) fputs("\r\033[K", stderr);
    if (why[0]) fprintf(stderr, "polydyn sweep: %s\n", why);
    fprintf(stderr, "polydyn sweep: the reference run (soft at tol %g) did not complete\n", SWEEP_REFERENCE_TOL);
    pd_trajectory_free(ref);
    pd_trajectory_free(check);
    pd_model_free(refModel);
    pd_model_free(checkModel);
    return PD_EXIT_FAILURE;
  }
  double refError = pose_error(refModel, ref, check);
  double refWall = references[0].wall;
  long refSteps = references[0].steps;

  // the points: one task each, in the order of sweep.csv
  enum { MAX_POINTS = 64 };
  point points[MAX_POINTS];
  int count = 0;
  static const double tols[] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  static const double fixedSteps[] = {1e-3, 3e-4, 1e-4, 3e-5, 1e-5};
  static const double refSteps_[] = {1.0 / 60, 1.0 / 250, 1.0 / 1000, 1.0 / 4000, 1.0 / 16000};
  if (pd_cli_list_has(engines, "soft")) {
    for (size_t i = 0; i < sizeof tols / sizeof tols[0]; ++i) points[count++] = (point){.engine = "soft", .variant = "adaptive", .setting = "tol", .value = tols[i]};
    for (size_t i = 0; i < sizeof fixedSteps / sizeof fixedSteps[0]; ++i)
      points[count++] = (point){.engine = "soft", .variant = "fixed", .setting = "step", .value = fixedSteps[i]};
  }
  static const char* const refNames[] = {"ode", "bullet"};
  for (int e = 0; e < 2; ++e) {
    if (!pd_cli_list_has(engines, refNames[e])) continue;
    if (!pd_ref_adapter(refNames[e])) {
      if (pd_batch_is_root()) fprintf(stderr, "polydyn sweep: this build has no %s adapter; skipped\n", refNames[e]);
      continue;
    }
    for (int v = 0; v < 2; ++v)
      for (size_t i = 0; i < sizeof refSteps_ / sizeof refSteps_[0]; ++i)
        points[count++] = (point){.engine = refNames[e], .variant = v ? "matched" : "native", .setting = "step", .value = refSteps_[i]};
  }
  pointRuns runs = {scene, &base, (int)repeats, refModel, ref, points, progress};
  pdBatchBuffer* measured = calloc((size_t)count + 1, sizeof *measured);
  if (!measured) abort();
  batch = (pdBatchOptions){.workers = jobs, .progress = progress ? point_progress : NULL, .progressUser = &runs};
  bool pointsOk = pd_batch_run(count, point_task, &runs, &batch, measured, why, sizeof why);
  for (int i = 0; i < count; ++i) {
    if (pointsOk && pd_batch_is_root()) take_point(&measured[i], &points[i]);
    pd_batch_buffer_free(&measured[i]);
  }
  free(measured);
  if (progress) fputs("\r\033[K", stderr);
  // DIR under a temporary name, made only now (an interrupted sweep leaves nothing); MPI: rank 0 writes
  char tmp[4096];
  bool opened = pointsOk && pd_cli_out_open("sweep", out, "sweep.csv", tmp, sizeof tmp);
  if (!opened || !pd_batch_is_root()) {
    if (!pointsOk) fprintf(stderr, "polydyn sweep: %s\n", why);
    pd_trajectory_free(ref);
    pd_trajectory_free(check);
    pd_model_free(refModel);
    pd_model_free(checkModel);
    return !pointsOk ? PD_EXIT_FAILURE : opened ? PD_EXIT_OK : PD_EXIT_BAD_INPUT;
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
      fputs("scene,engine,variant,setting,value,error,error_kind,wall_seconds,wall_per_sim_second,steps,repeats,reference\n", f);
      for (int i = 0; i < count; ++i) {
        const point* p = &points[i];
        fprintf(f, "\"%s\",%s,%s,%s,%.6g,", scene, p->engine, p->variant, p->setting, p->value);
        if (p->completed) fprintf(f, "%.6g", p->error);
        fprintf(f, ",rms_pose,");
        if (p->completed) fprintf(f, "%.6g,%.6g", p->wall, p->wall / tend);
        else fputc(',', f);
        fprintf(f, ",%ld,%ld,%s\n", p->steps, repeats, refName);
      }
      ok = !ferror(f);
      ok = fclose(f) == 0 && ok;
    }
    snprintf(path, sizeof path, "%s/reference.json", tmp);
    f = ok ? fopen(path, "w") : NULL;
    if (f) {
      fprintf(f,
              "{\"scene\": \"%s\", \"engine\": \"soft\", \"tol\": %g, \"steps\": %ld, \"wall_seconds\": %.6g,\n"
              " \"check_tol\": %g, \"error_against_check\": %.6g,\n"
              " \"error_kind\": \"rms over samples and moving bodies of max(|x - x_ref| / size, rotation angle rad)\"}\n",
              scene, SWEEP_REFERENCE_TOL, refSteps, refWall, SWEEP_REFERENCE_CHECK_TOL, refError);
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
      printf("%-8s %-9s %-5s %10s %12s %12s\n", "engine", "variant", "set", "value", "error", "wall/sim s");
      for (int i = 0; i < count; ++i) {
        const point* p = &points[i];
        if (p->completed)
          printf("%-8s %-9s %-5s %10.3g %12.3g %12.3g\n", p->engine, p->variant, p->setting, p->value, p->error,
                 p->wall / tend);
        else
          printf("%-8s %-9s %-5s %10.3g %12s\n", p->engine, p->variant, p->setting, p->value, "failed");
      }
      printf("reference: soft at tol %g (its error against tol %g: %.3g); %s/sweep.csv\n", SWEEP_REFERENCE_TOL,
             SWEEP_REFERENCE_CHECK_TOL, refError, out);
    }
  }
  pd_trajectory_free(ref);
  pd_trajectory_free(check);
  pd_model_free(refModel);
  pd_model_free(checkModel);
  return status;
}
