// polydyn gedanken — work-precision against the closed form (RESULT_SCHEMAS.md, precision.csv).
//
// The sweep (`polydyn sweep`) measures each engine against runs of its own; here each engine is measured against
// what physics says: every quantitative experiment runs on its precision input at every setting of each engine's
// accuracy knob, and the experiment's own measure gives the error against its closed form (restitution error,
// stop-distance error, acceleration error, ...). One point = one (experiment, engine, variant, setting) with no
// output files: its error from its first run (every run is deterministic), its cost the least of `repeats` timings,
// each the run repeated back to back to a minimum CPU time (pd_gk_time_runs, pd_gk_cost). The timings are the tasks
// of a batch (runner/include/pdrun/batch.h) in rounds: every point's first timing, then every point's second, ...,
// so each point is timed at `repeats` moments of the sweep and one experiment's engines side by side in each. The
// file is written in point order: the same bytes whatever the number of processes, except the timings.
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>

#include "gedanken_internal.h"
#include "pdrun/batch.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "polydyn/scene.h"
#include "pdrun/stats.h"
#include "pdutil/csv.h"

// The knobs, loosest first (the header lists them; docs/validation.md).
// The soft tolerances start above 1e-2 so that an experiment reached at every setting gets a measured crossing,
// not only a bound: several experiments' closed forms are met at 1e-2 already.
static const double softTolerances[] = {1e-1, 3e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
static const double softFixedSteps[] = {1e-3, 3e-4, 1e-4, 3e-5, 1e-5};                              // s
static const double referenceSteps[] = {1.0 / 60, 1.0 / 250, 1.0 / 1000, 1.0 / 4000, 1.0 / 16000};  // s
// Bullet's sequential-impulse solver iterations per step, at the default step (ODE's dWorldStep solves its LCP
// exactly: it has no such knob). The adapter's default is 100.
static const double bulletIterations[] = {5, 10, 20, 50, 100, 200};
enum {
  SOFT_TOL_COUNT = sizeof softTolerances / sizeof softTolerances[0],
  SOFT_FIXED_COUNT = sizeof softFixedSteps / sizeof softFixedSteps[0],
  REFERENCE_STEP_COUNT = sizeof referenceSteps / sizeof referenceSteps[0],
  BULLET_ITERATION_COUNT = sizeof bulletIterations / sizeof bulletIterations[0],
  SOFT_TOL_VARIANTS = 6,
};

int pd_gk_precision_input(const pdGkExperiment* e) { return (e->inputCount - 1) / 2; }

typedef enum gkPointStatus {
  gkPointOk,
  gkPointFailed,
  gkPointNoMeasure,
  gkPointRefused,
  gkPointNotBuilt
} gkPointStatus;
static const char* const pointStatusNames[] = {"ok", "failed", "no_measure", "refused", "not_built"};

typedef struct gkPoint {
  const gkCase* c;
  pdGkEngine engine;
  const char* variant;  // "adaptive", "fixed", "embedded", "implicit", "exact-events", "dopri", "implicit-dopri",
                        // "native", "matched"
  const char* setting;  // "tol", "step", "iterations"; "" for a not_built row
  double value;
  // measured (travels between processes as gkPointResult)
  gkPointStatus status;
  double measured, error;
  pdGkCost cost;  // from its timings (pd_gk_cost), when ok
  long steps;
  long derivatives;                 // soft: derivative evaluations of the last run (0 for the reference engines)
  long limited[pd_limitCount];      // soft: its accepted steps by what set their size (pdStepLimit)
  char note[PD_GK_NOTE_MAX];
} gkPoint;

typedef struct gkPointResult {
  int32_t status;
  int32_t completed;  // the timing's runs all completed
  double measured, error;
  double wall, cpu;   // the timing's, s per run
  int64_t runs;       // the timing's runs
  int64_t steps;
  int64_t derivatives;
  int64_t limited[pd_limitCount];
  char note[PD_GK_NOTE_MAX];
} gkPointResult;

typedef struct gkPrecision {
  const pdGkOptions* options;
  gkPoint* points;
  int count;
} gkPrecision;

static bool interrupted(const gkPrecision* p) { return p->options->interrupt && *p->options->interrupt; }

static void point_note(gkPoint* p, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void point_note(gkPoint* p, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(p->note, sizeof p->note, fmt, ap);
  va_end(ap);
}

typedef struct gkPointObserver {
  pdGkRecord* rec;  // NULL after the point's first run: only the time is wanted then
  const gkPrecision* precision;
  bool soft;
} gkPointObserver;

static bool observe(const pdModel* model, const pdState* state, void* user) {
  gkPointObserver* o = user;
  if (o->rec) {
    if (o->soft)
      pd_gk_record_observe(model, state, o->rec);
    else
      pd_gk_record_observe_ref(model, state, o->rec);
  }
  return !interrupted(o->precision);
}

// The case's scene compiled with the point's setting (the scene's tol or dt replaced; nothing else changes, so
// the contact constants and the expected value are those of the suite's run).
static pdModel* compile_with_setting(const gkPoint* p, pdError* err) {
  pdScene* scene = pd_scene_parse_buffer("scene.scene", p->c->sceneText, strlen(p->c->sceneText), err);
  if (!scene) return NULL;
  if (strcmp(p->variant, "fixed") == 0)
    scene->settings.dt = p->value;
  else
    scene->settings.tol = p->value;
  pdModel* model = pd_model_compile(scene, err);
  pd_scene_free(scene);
  return model;
}

// The error of a measured value against the case's closed form (relative when the experiment says so), as
// results.csv writes it.
static double error_of(const gkCase* c, double measured) {
  const pdGkExperiment* e = c->experiment;
  return e->relative ? fabs(measured / c->expected.value - 1.0) : fabs(measured - c->expected.value);
}

// One point's runs as a timed run (pd_gk_time_runs): the engine's state or world made from the compiled model and run
// to the end, the same span for every engine; the first run of the point also records the samples its error is
// measured on.
typedef struct gkPointRun {
  const gkPrecision* s;
  gkPoint* p;
  pdModel* model;  // soft: compiled with the setting; the reference engines run the suite's model
  pdStateOptions stateOptions;
  const pdRefAdapter* adapter;
  pdRefOptions refOptions;
  pdGkRecord* rec;  // the next run's record: NULL once the first run made it
  bool refused;
} gkPointRun;

static bool run_point(void* user, double* wall, double* cpu) {
  gkPointRun* r = user;
  gkPoint* p = r->p;
  gkPointObserver observer = {r->rec, r->s, p->engine == pd_gkSoft};
  r->rec = NULL;
  if (r->model) {
    // the same span as a reference engine's run (pd_ref_run): the engine's state created, then run to the end
    double t0 = gk_wall_seconds(), c0 = gk_cpu_seconds();
    pdState* state = pd_state_create(r->model, &r->stateOptions);
    bool completed = pd_advance(r->model, state, r->model->settings.tend, observe, &observer);
    *wall = gk_wall_seconds() - t0;
    *cpu = gk_cpu_seconds() - c0;
    p->steps = state->count.accepted;
    p->derivatives = state->count.derivatives;
    memcpy(p->limited, state->count.stepsLimited, sizeof p->limited);
    if (!completed) point_note(p, "the run stopped at t = %.6g s", state->t);
    pd_state_free(state);
    return completed;
  }
  pdRefRunStats stats;
  pdError err = {0};
  bool ran = pd_ref_run(p->c->model, r->adapter, &r->refOptions, NULL, observe, &observer, &stats, &err);
  *wall = stats.wallSeconds;
  *cpu = stats.cpuSeconds;
  p->steps = stats.steps;
  if (!ran && stats.refused) {
    r->refused = true;
    point_note(p, "%s", err.message);
    return false;
  }
  bool completed = ran && stats.completed;
  if (!completed) point_note(p, "%s produced a non-finite state after %ld steps", r->adapter->name, stats.steps);
  return completed;
}

// One timing of a point (pd_gk_time_runs); the first (`first`) also measures its error from its first run.
static pdGkTiming measure_point(const gkPrecision* s, gkPoint* p, bool first) {
  p->measured = p->error = NAN;
  p->steps = 0;
  p->derivatives = 0;
  memset(p->limited, 0, sizeof p->limited);
  p->note[0] = '\0';
  const gkCase* c = p->c;
  pdGkRecord rec;
  if (first) pd_gk_record_init(&rec, c->model->movingCount);
  gkPointRun run = {.s = s, .p = p, .rec = first ? &rec : NULL};
  pdError err = {0};
  if (p->engine == pd_gkSoft) {
    run.model = compile_with_setting(p, &err);
    PD_ASSERT(run.model != NULL);  // the same text compiled in the suite; tol and dt are checked > 0 there
    pdStateOptions options = pd_state_options_default();
    options.stepper = strcmp(p->variant, "fixed") == 0          ? pd_stepperRK4Fixed
                      : strcmp(p->variant, "embedded") == 0     ? pd_stepperRK43Embedded
                      : strcmp(p->variant, "implicit") == 0     ? pd_stepperImplicit
                      : strcmp(p->variant, "exact-events") == 0 ? pd_stepperImplicit
                      : strcmp(p->variant, "dopri") == 0        ? pd_stepperDopri54
                      : strcmp(p->variant, "implicit-dopri") == 0 ? pd_stepperImplicitDopri
                                                                : pd_stepperRK4Adaptive;
    // the reference variant of the contact events: every onset located (docs/events.md)
    if (strcmp(p->variant, "exact-events") == 0) options.onsets = pd_onsetsExact;
    // the span is timed whole, as a reference engine's is: no stage timers (their clock reads are not the run's work)
    options.stageTimers = false;
    run.stateOptions = options;
  } else {
    run.adapter = pd_ref_adapter(pdGkEngineNames[p->engine]);
    PD_ASSERT(run.adapter != NULL);  // points of engines with no adapter are not_built rows, never run
    bool iterations = strcmp(p->setting, "iterations") == 0;
    run.refOptions = (pdRefOptions){.variant = strcmp(p->variant, "matched") == 0 ? pd_refMatched : pd_refNative,
                                    .step = iterations ? PD_REF_DEFAULT_STEP : p->value,
                                    .odeFriction = pd_odeFrictionPyramid,
                                    .iterations = iterations ? (int)p->value : 0};
  }
  pdGkTiming timing = pd_gk_time_runs(run_point, &run, PD_GK_TIMING_MIN_CPU_SECONDS);
  if (run.model) pd_model_free(run.model);
  if (!first) return timing;
  if (run.refused) {
    p->status = gkPointRefused;
  } else if (!timing.completed || !rec.finite || rec.count < 2) {
    p->status = gkPointFailed;
    if (!p->note[0])
      point_note(p, "the run produced %s", rec.count < 2 ? "fewer than 2 samples" : "a non-finite state");
  } else {
    pdGkMeasured m = {.value = NAN};
    c->experiment->measure(c->model, &rec, c->input, &m);
    snprintf(p->note, sizeof p->note, "%s", m.note);
    p->status = isfinite(m.value) ? gkPointOk : gkPointNoMeasure;
    if (p->status == gkPointOk) {
      p->measured = m.value;
      p->error = error_of(c, m.value);
    }
  }
  pd_gk_record_free(&rec);
  return timing;
}

// Task t is timing t / n of point t % n (n runnable points): every point's first timing, then every point's
// second, ..., so a point's timings are spread over the sweep and one experiment's engines are timed side by side
// in each round.
static void point_task(int task, pdBatchBuffer* result, void* user) {
  gkPrecision* s = user;
  gkPoint* p = &s->points[task % s->count];
  bool first = task < s->count;
  pdGkTiming timing = measure_point(s, p, first);
  gkPointResult r;
  memset(&r, 0, sizeof r);  // no uninitialised padding in the bytes
  r.status = (int32_t)p->status;
  r.completed = timing.completed;
  r.measured = p->measured;
  r.error = p->error;
  r.wall = timing.wall;
  r.cpu = timing.cpu;
  r.runs = timing.runs;
  r.steps = p->steps;
  r.derivatives = p->derivatives;
  for (int k = 0; k < pd_limitCount; ++k) r.limited[k] = p->limited[k];
  memcpy(r.note, p->note, sizeof r.note);
  pd_batch_append(result, &r, sizeof r);
}

// The task's timing; for a point's first timing also the point's measured fields.
static pdGkTiming take_point(gkPoint* p, bool first, const pdBatchBuffer* bytes) {
  gkPointResult r;
  size_t at = 0;
  bool whole = pd_batch_read(bytes, &at, &r, sizeof r);
  PD_ASSERT(whole);
  if (first) {
    p->status = (gkPointStatus)r.status;
    p->measured = r.measured;
    p->error = r.error;
    p->steps = (long)r.steps;
    p->derivatives = (long)r.derivatives;
    for (int k = 0; k < pd_limitCount; ++k) p->limited[k] = (long)r.limited[k];
    memcpy(p->note, r.note, sizeof p->note);
  }
  return (pdGkTiming){.wall = r.wall, .cpu = r.cpu, .runs = (long)r.runs, .completed = r.completed != 0};
}

static bool point_progress(int task, int done, int total, void* user) {
  const gkPrecision* s = user;
  if (task >= 0 && s->options->progress) {
    const gkPoint* p = &s->points[task % s->count];
    char engine[96];
    snprintf(engine, sizeof engine, "%s-%s %s=%g (work-precision, timing %d of %d)", pdGkEngineNames[p->engine],
             p->variant, p->setting, p->value, task / s->count + 1, s->options->repeats);
    pdGkProgress progress = {done, total, p->c->experiment->name, engine, p->c->label};
    s->options->progress(&progress, s->options->progressUser);
  }
  return !interrupted(s);
}

// ---------------------------------------------------------------------------------------------------------

// The cost of a point that is not ok: every field empty in precision.csv.
static const pdGkCost noCost = {.wall = NAN, .cpu = NAN, .wallMedian = NAN, .cpuMedian = NAN, .wallMaxOverMin = NAN,
                                .cpuMaxOverMin = NAN};

static void add(gkPrecision* s, const gkCase* c, pdGkEngine engine, const char* variant, const char* setting,
                double value) {
  s->points[s->count++] = (gkPoint){.c = c, .engine = engine, .variant = variant, .setting = setting, .value = value,
                                    .cost = noCost};
}

// The points of one case, in the order precision.csv lists them.
static void add_case_points(gkPrecision* s, const gkCase* c) {
  const pdGkOptions* o = s->options;
  if (o->engines[pd_gkSoft]) {
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "adaptive", "tol", softTolerances[k]);
    for (int k = 0; k < SOFT_FIXED_COUNT; ++k) add(s, c, pd_gkSoft, "fixed", "step", softFixedSteps[k]);
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "embedded", "tol", softTolerances[k]);
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "implicit", "tol", softTolerances[k]);
    // the reference variant of the contact events: the default stepper with every onset located (docs/events.md)
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "exact-events", "tol", softTolerances[k]);
    // the Dormand–Prince 5(4) pair, step doubling's explicit alternative, alone and as the implicit stepper's explicit
    // part (docs/integration.md, "Steppers")
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "dopri", "tol", softTolerances[k]);
    for (int k = 0; k < SOFT_TOL_COUNT; ++k) add(s, c, pd_gkSoft, "implicit-dopri", "tol", softTolerances[k]);
  }
  for (int engine = pd_gkOde; engine < pd_gkEngineCount; ++engine) {
    if (!o->engines[engine]) continue;
    bool built = pd_ref_adapter(pdGkEngineNames[engine]) != NULL;
    for (int v = 0; v < 2; ++v) {
      const char* variant = v ? "matched" : "native";
      if (!built) {  // reported, not skipped: one row per variant says the engine is missing
        add(s, c, (pdGkEngine)engine, variant, "", NAN);
        s->points[s->count - 1].status = gkPointNotBuilt;
        point_note(&s->points[s->count - 1], "this build of polydyn has no %s adapter", pdGkEngineNames[engine]);
        continue;
      }
      for (int k = 0; k < REFERENCE_STEP_COUNT; ++k) add(s, c, (pdGkEngine)engine, variant, "step", referenceSteps[k]);
      if (engine == pd_gkBullet)
        for (int k = 0; k < BULLET_ITERATION_COUNT; ++k)
          add(s, c, (pdGkEngine)engine, variant, "iterations", bulletIterations[k]);
    }
  }
}

static bool write_precision(const gkPrecision* s, const char* root, pdError* err) {
  size_t n = strlen(root) + 32;
  char* path = malloc(n);
  PD_ASSERT(path != NULL);
  snprintf(path, n, "%s/precision.csv", root);
  FILE* out = fopen(path, "w");
  free(path);
  if (!out) {
    pd_error_set(err, s->options->out, 0, 0, "cannot write precision.csv: %s", strerror(errno));
    return false;
  }
  fputs(
      "experiment,kind,engine,variant,setting,value,input,quantity,unit,measured,expected,error,relative,tolerance,"
      "judged,status,wall_seconds,wall_per_sim_second,steps,repeats,cpu_seconds,cpu_per_sim_second,derivatives,"
      "steps_error,steps_largest,steps_stability,steps_travel,steps_event,steps_landing,note,"
      "cpu_seconds_median,cpu_max_over_min,wall_seconds_median,wall_max_over_min,runs_per_timing\n",
      out);
  for (int i = 0; i < s->count; ++i) {
    const gkPoint* p = &s->points[i];
    const gkCase* c = p->c;
    const pdGkExperiment* e = c->experiment;
    pdu_csv_text(out, e->name);
    fprintf(out, ",%s,%s,%s,%s,", pdGkKindNames[e->kind], pdGkEngineNames[p->engine], p->variant, p->setting);
    if (isfinite(p->value)) fprintf(out, "%.6g", p->value);  // the setting as it is named (1/60 s: 0.0166667)
    fputc(',', out);
    const char* const texts[] = {c->label, e->quantity, e->unit};
    for (int k = 0; k < 3; ++k) {
      pdu_csv_text(out, texts[k]);
      fputc(',', out);
    }
    pdu_csv_number(out, p->measured, 17);
    fputc(',', out);
    pdu_csv_number(out, c->expected.value, 17);
    fputc(',', out);
    pdu_csv_number(out, p->error, 17);
    fprintf(out, ",%s,", e->relative ? "true" : "false");
    pdu_csv_number(out, c->expected.tolerance, 17);
    bool judged = pd_gk_applies(e, p->engine, strcmp(p->variant, "matched") == 0);
    fprintf(out, ",%s,%s,", judged ? "true" : "false", pointStatusNames[p->status]);
    // the cost: the least of the point's timings (pd_gk_cost); empty unless ok
    const pdGkCost* cost = &p->cost;
    pdu_csv_number(out, cost->wall, 17);
    fputc(',', out);
    pdu_csv_number(out, cost->wall / c->model->settings.tend, 17);
    fprintf(out, ",%ld,%d,", p->steps, s->options->repeats);
    pdu_csv_number(out, cost->cpu, 17);
    fputc(',', out);
    pdu_csv_number(out, cost->cpu / c->model->settings.tend, 17);
    fputc(',', out);
    // what polydyn's steps were spent on (docs/integration.md); the reference engines': empty
    bool counted = p->engine == pd_gkSoft && p->status == gkPointOk;
    if (counted) fprintf(out, "%ld", p->derivatives);
    fputc(',', out);
    for (int k = 0; k < pd_limitCount; ++k) {
      if (counted && strcmp(p->variant, "fixed") != 0) fprintf(out, "%ld", p->limited[k]);
      fputc(',', out);
    }
    pdu_csv_text(out, p->note);
    // appended after note, so the columns before keep their places: the timings' median and spread
    const double spread[] = {cost->cpuMedian, cost->cpuMaxOverMin, cost->wallMedian, cost->wallMaxOverMin};
    for (int k = 0; k < 4; ++k) {
      fputc(',', out);
      pdu_csv_number(out, spread[k], 17);
    }
    fputc(',', out);
    if (p->status == gkPointOk) fprintf(out, "%ld", cost->runs);
    fputc('\n', out);
  }
  bool ok = !ferror(out);
  ok = fclose(out) == 0 && ok;
  if (!ok) pd_error_set(err, s->options->out, 0, 0, "cannot write precision.csv");
  return ok;
}

bool gk_precision_run(const pdGkOptions* options, const gkCase* cases, int caseCount, const char* root, pdError* err) {
  PD_ASSERT(options->repeats >= 1);
  // add_case_points: six soft variants over the tolerances (adaptive, embedded, implicit, exact-events, dopri,
  // implicit-dopri), one over the fixed steps; each reference engine native and matched over the steps, Bullet also over its iterations
  int perCase = SOFT_TOL_VARIANTS * SOFT_TOL_COUNT + SOFT_FIXED_COUNT +
                2 * (pd_gkEngineCount - 1) * REFERENCE_STEP_COUNT + 2 * BULLET_ITERATION_COUNT;
  gkPrecision s = {.options = options, .points = calloc((size_t)caseCount * (size_t)perCase + 1, sizeof(gkPoint))};
  PD_ASSERT(s.points != NULL);
  for (int i = 0; i < caseCount; ++i) {
    const gkCase* c = &cases[i];
    const pdGkExperiment* e = c->experiment;
    if (e->qualitative || !isfinite(c->expected.value)) continue;  // no closed form: nothing to measure against
    if (c->input != e->inputs[pd_gk_precision_input(e)]) continue;
    add_case_points(&s, c);
  }
  // not_built rows are not tasks: a task per point that runs; the others keep their status
  int* run = malloc(((size_t)s.count + 1) * sizeof *run);
  PD_ASSERT(run != NULL);
  int tasks = 0;
  for (int i = 0; i < s.count; ++i)
    if (s.points[i].status != gkPointNotBuilt) run[tasks++] = i;
  gkPoint* all = s.points;
  gkPoint* runnable = calloc((size_t)tasks + 1, sizeof *runnable);
  PD_ASSERT(runnable != NULL);
  for (int k = 0; k < tasks; ++k) runnable[k] = all[run[k]];
  s.points = runnable;
  int total = s.count;
  s.count = tasks;  // the tasks see the runnable points only
  // a task per timing: `repeats` rounds over the runnable points (point_task)
  int repeats = options->repeats;
  size_t timingCount = (size_t)tasks * (size_t)repeats;
  PD_ASSERT(timingCount <= INT32_MAX);
  pdBatchBuffer* results = calloc(timingCount + 1, sizeof *results);
  pdGkTiming* timings = calloc((size_t)repeats, sizeof *timings);
  PD_ASSERT(results != NULL && timings != NULL);
  pdBatchOptions batch = {.workers = options->jobs, .everywhere = true, .progress = point_progress, .progressUser = &s};
  char why[256] = "";
  bool ok = pd_batch_run((int)timingCount, point_task, &s, &batch, results, why, sizeof why);
  for (int k = 0; ok && k < tasks; ++k) {
    gkPoint* p = &all[run[k]];
    for (int r = 0; r < repeats; ++r) timings[r] = take_point(p, r == 0, &results[(size_t)r * (size_t)tasks + (size_t)k]);
    if (p->status == gkPointOk) p->cost = pd_gk_cost(timings, repeats);
  }
  for (size_t t = 0; t < timingCount; ++t) pd_batch_buffer_free(&results[t]);
  free(timings);
  free(results);
  free(runnable);
  free(run);
  s.points = all;
  s.count = total;
  if (interrupted(&s)) {
    pd_error_set(err, options->out, 0, 0, "interrupted; nothing written");
    ok = false;
  } else if (!ok) {
    pd_error_set(err, options->out, 0, 0, "%s", why);
  }
  if (ok && pd_batch_is_root()) ok = write_precision(&s, root, err);
  free(s.points);
  return ok;
}
