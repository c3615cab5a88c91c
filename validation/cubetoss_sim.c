// polydyn validation — one cube toss: its scene, its run in an engine, its errors against the record, the
// record as a run directory, statistics and parameter fragments (conventions in cubetoss.h).
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pdrun/batch.h"
#include "pdval/cubetoss.h"
#include "polydyn/output.h"
#include "polydyn/scene.h"
#include "pdrun/stats.h"
#include "pdutil/clock.h"
#include "pdutil/json.h"
#include "pdrun/text_buffer.h"

// Default stiffness of each side, N/m: eq. (11) for the cube, m vmax²/δ_max² with δ_max = 0.01 × side
// (the engine's default deflection): 0.37 × 2.5² / (0.01 × 0.1048)² = 2.105e6, rounded.
#define TOSS_DEFAULT_KN 2.1e6
// The data's authors' friction coefficient for their own model (data README).
#define TOSS_DEFAULT_MU 0.18
#define TOSS_DEFAULT_TOL 1e-6

static const double kPi = 3.14159265358979323846;

pdTossParams pd_toss_default_params(void) {
  return (pdTossParams){.mu = TOSS_DEFAULT_MU,
                        .restitution = PD_TOSS_DEFAULT_RESTITUTION,
                        .kn = TOSS_DEFAULT_KN,
                        .tol = TOSS_DEFAULT_TOL,
                        .inertia = PD_TOSS_CUBE_INERTIA};
}

// Planar drops without fitting (cubetoss.h): the soft engine's stiffness by eq. (11) for the block,
// m vmax²/(0.01 side)² = 1 × 3² / (6e-4)² = 2.5e7 N/m; μ and e in the middle of what the data's literature fits.
#define DROP_DEFAULT_KN 2.5e7
#define DROP_DEFAULT_MU 0.2
#define DROP_DEFAULT_RESTITUTION 0.5

pdTossParams pd_toss_experiment_params(const pdTossExperiment* experiment) {
  if (!experiment->planar) return pd_toss_default_params();
  return (pdTossParams){.mu = DROP_DEFAULT_MU,
                        .restitution = DROP_DEFAULT_RESTITUTION,
                        .kn = DROP_DEFAULT_KN,
                        .tol = TOSS_DEFAULT_TOL,
                        .inertia = 0.0};
}

const char* pd_toss_status_name(pdTossStatus status) {
  switch (status) {
    case pd_tossOk: return "ok";
    case pd_tossFailed: return "failed";
    case pd_tossRefused: return "refused";
    case pd_tossNotBuilt: return "not built";
  }
  return "?";
}

// ---------------------------------------------------------------- the scene

static void append_material(pdTextBuffer* b, const pdTossParams* p) {
  pd_text_appendf(b, "mu %.17g\nrestitution %.17g\nkn %.17g\n", p->mu, p->restitution, p->kn);
}

char* pd_toss_scene(const pdToss* toss, const pdTossParams* p) {
  PD_ASSERT(toss && p && toss->sampleCount >= 2);
  const pdTossExperiment* ex = toss->experiment;
  const pdBodyState* s0 = &toss->samples[0];
  pdTextBuffer b = {0};
  pd_text_appendf(&b, "# polydyn cubetoss: %s, %s %ld from its first sample (generated)\n", ex->name,
                  ex->planar ? "drop" : "toss", toss->id);
  pd_text_appendf(&b, "tend %.17g\nsample %.17g\ntol %.17g\nvmax %.17g\n", (double)(toss->sampleCount - 1) / ex->rate,
                  ex->rate, p->tol, ex->vmax);
  pd_text_appendf(&b, "cube board grey %.17g %.17g %.17g\nfixed\nloc 0 0 %.17g\n", PD_TOSS_BOARD_WIDTH,
                  PD_TOSS_BOARD_WIDTH, PD_TOSS_BOARD_THICKNESS, ex->boardTop - 0.5 * PD_TOSS_BOARD_THICKNESS);
  append_material(&b, p);
  const double* size = ex->size;
  pd_text_appendf(&b, "cube cube red %.17g %.17g %.17g\nspgrav %.17g\n%s", size[0], size[1], size[2],
                  ex->mass / (size[0] * size[1] * size[2]) / 1000.0, ex->planar ? "planar\n" : "");
  // orientation as an angle about a world axis: q = (cos θ/2, sin θ/2 u), θ ∈ [0, 2π] keeps q's sign
  pdVec3 qv = {s0->q.x, s0->q.y, s0->q.z};
  double qvNorm = pd_v3_norm(qv);
  pd_text_appendf(&b, "loc %.17g %.17g %.17g", s0->x.x, s0->x.y, s0->x.z);
  if (qvNorm > 0.0) {
    double angle = 2.0 * atan2(qvNorm, s0->q.w);
    pd_text_appendf(&b, " %.17g %.17g %.17g %.17g", angle * 180.0 / kPi, qv.x / qvNorm, qv.y / qvNorm, qv.z / qvNorm);
  }
  // angular velocity: `vel` takes a spin about an axis of the object's own frame, so ω_body = Rᵀ ω
  pd_text_appendf(&b, "\nvel %.17g %.17g %.17g", s0->v.x, s0->v.y, s0->v.z);
  double spin = pd_v3_norm(s0->w);
  if (spin > 0.0) {
    pdMat3 r = pd_quat_to_mat3(s0->q);
    pdVec3 axis = pd_v3_scale(pd_mat3_tmulv(&r, s0->w), 1.0 / spin);
    pd_text_appendf(&b, " %.17g %.17g %.17g %.17g", spin * 180.0 / kPi, axis.x, axis.y, axis.z);
  }
  pd_text_appendf(&b, "\n");
  append_material(&b, p);
  return b.data;
}

pdModel* pd_toss_model(const pdToss* toss, const pdTossParams* p, pdError* err) {
  PD_ASSERT(p->inertia >= 0.0);
  char* text = pd_toss_scene(toss, p);
  char name[64];
  snprintf(name, sizeof name, "toss %ld", toss->id);
  pdScene* scene = pd_scene_parse_buffer(name, text, strlen(text), err);
  free(text);
  if (!scene) return NULL;
  pdModel* model = pd_model_compile(scene, err);
  pd_scene_free(scene);
  if (!model) return NULL;
  PD_ASSERT(model->bodyCount == 2 && model->movingCount == 1 && !model->bodies[PD_TOSS_CUBE_BODY].fixed);
  if (p->inertia > 0.0) {
    // isotropic: the same moment about every axis, so any frame is principal
    pdBody* cube = &model->bodies[PD_TOSS_CUBE_BODY];
    double inv = 1.0 / p->inertia;
    cube->inertia = (pdMat3){{{p->inertia, 0, 0}, {0, p->inertia, 0}, {0, 0, p->inertia}}};
    cube->invInertia = (pdMat3){{{inv, 0, 0}, {0, inv, 0}, {0, 0, inv}}};
    for (int i = 0; i < 3; ++i) cube->principal[i] = p->inertia;
    cube->principalAxes = pd_mat3_identity();
  }
  return model;
}

// ---------------------------------------------------------------- running one toss

typedef struct softObserver {
  pdRunWriter* writer;  // nullable
  pdTrajectory* trajectory;
} softObserver;

static bool observe_soft(const pdModel* model, const pdState* state, void* user) {
  softObserver* o = user;
  if (o->writer && !pd_run_observe(model, state, o->writer)) return false;
  return pd_trajectory_observe(model, state, o->trajectory);
}

static void fail(pdTossResult* r, pdTossStatus status, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
static void fail(pdTossResult* r, pdTossStatus status, const char* fmt, ...) {
  r->status = status;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(r->message, sizeof r->message, fmt, ap);
  va_end(ap);
}

// `FILE:LINE:COL: message` into buf (the file name cut to 150 bytes, the message to 400: they fit)
static void error_text(const pdError* err, char* buf, size_t size) {
  if (err->line > 0)
    snprintf(buf, size, "%.150s:%d:%d: %.400s", err->file, err->line, err->col, err->message);
  else
    snprintf(buf, size, "%.150s%s%.400s", err->file, err->file[0] ? ": " : "", err->message);
}

static void clear_errors(pdTossResult* r) {
  r->posErrEnd = r->posErrRms = r->rotErrEnd = r->rotErrRms = NAN;
  r->impactsRecord = r->impactsRun = 0;
  for (int k = 0; k < PD_TOSS_IMPACTS; ++k) r->impactDt[k] = r->impactDv[k] = r->impactDw[k] = NAN;
}

// The moving block's state vector from a recorded sample (the first 13 numbers: state.h).
static void set_block_state(pdState* state, const pdBodyState* b) {
  const double y[PD_BODY_STATE_SIZE] = {b->v.x, b->v.y, b->v.z, b->w.x, b->w.y, b->w.z, b->x.x,
                                        b->x.y, b->x.z, b->q.w, b->q.x, b->q.y, b->q.z};
  memcpy(state->y, y, sizeof y);
}

// The "noise" engine's run (cubetoss.h): the record one sample late, at the record's sample times.
static pdTrajectory* delayed_record(const pdModel* model, const pdToss* toss) {
  pdTrajectory* tr = pd_trajectory_create(model);
  pdState* state = pd_state_create(model, NULL);
  for (int k = 0; k < toss->sampleCount; ++k) {
    set_block_state(state, &toss->samples[k > 0 ? k - 1 : 0]);
    state->t = (double)k / toss->experiment->rate;
    pd_trajectory_observe(model, state, tr);
  }
  pd_state_free(state);
  return tr;
}

pdTrajectory* pd_toss_simulate(const pdToss* toss, const pdTossParams* params, const pdTossEngine* engine,
                               const char* runDir, pdTossResult* r) {
  PD_ASSERT(toss && params && engine && engine->name && r);
  memset(r, 0, sizeof *r);
  clear_errors(r);
  r->samples = toss->sampleCount;
  bool soft = strcmp(engine->name, "soft") == 0, noise = strcmp(engine->name, "noise") == 0;
  const pdRefAdapter* adapter = soft || noise ? NULL : pd_ref_adapter(engine->name);
  if (!soft && !noise && !adapter) {
    fail(r, pd_tossNotBuilt, "this build of polydyn has no %s adapter", engine->name);
    return NULL;
  }
  pdError err = {0};
  char text[sizeof r->message];
  pdModel* model = pd_toss_model(toss, params, &err);
  if (!model) {
    error_text(&err, text, sizeof text);
    fail(r, pd_tossRefused, "%s", text);
    return NULL;
  }
  if (noise) {
    pdTrajectory* delayed = delayed_record(model, toss);
    pd_model_free(model);
    pd_toss_judge(toss, delayed, r);
    if (r->status == pd_tossOk) return delayed;
    clear_errors(r);
    pd_trajectory_free(delayed);
    return NULL;
  }
  pdRunWriter* writer = NULL;
  if (runDir && !(writer = pd_run_open(runDir, &err))) {
    error_text(&err, text, sizeof text);
    fail(r, pd_tossFailed, "%s", text);
    pd_model_free(model);
    return NULL;
  }
  pdTrajectory* trajectory = pd_trajectory_create(model);
  bool ok;
  double cpu0 = pd_process_cpu_seconds();
  if (soft) {
    double t0 = pd_wall_seconds();  // the span of a reference engine's run (pd_ref_run): created, then run
    pdState* state = pd_state_create(model, NULL);
    softObserver o = {writer, trajectory};
    double e0 = pd_state_energy(model, state);
    bool completed = pd_advance(model, state, model->settings.tend, observe_soft, &o);
    if (writer) pd_run_drain(writer);  // the samples printed by the writer thread count too (engine/src/output.c)
    r->wallSeconds = pd_wall_seconds() - t0;
    r->cpuSeconds = pd_process_cpu_seconds() - cpu0;
    r->steps = state->count.accepted;
    pdRunInfo info = {.engine = "polydyn-soft", .energyStart = e0, .energyEnd = pd_state_energy(model, state),
                      .wallSeconds = r->wallSeconds, .completed = completed};
    ok = completed;
    if (!completed) fail(r, pd_tossFailed, "the soft engine stopped at t = %.6g s", state->t);
    if (writer && !pd_run_finish(writer, model, state, &info, &err)) {
      error_text(&err, text, sizeof text);
      fail(r, pd_tossFailed, "%s", text);
      ok = false;
    } else {
      r->runWritten = writer != NULL;
    }
    pd_state_free(state);
  } else {
    pdRefRunStats stats;
    ok = pd_ref_run(model, adapter, &engine->ref, writer, pd_trajectory_observe, trajectory, &stats, &err);
    r->cpuSeconds = pd_process_cpu_seconds() - cpu0;
    r->wallSeconds = stats.wallSeconds;
    r->steps = stats.steps;
    r->runWritten = ok && writer != NULL;  // pd_ref_run finishes the writer unless it returns false
    if (!ok) {
      error_text(&err, text, sizeof text);
      fail(r, stats.refused ? pd_tossRefused : pd_tossFailed, "%s", text);
    } else if (!stats.completed) {
      fail(r, pd_tossFailed, "%s: non-finite state after %ld steps", engine->name, stats.steps);
      ok = false;
    }
  }
  pd_model_free(model);
  if (ok) pd_toss_judge(toss, trajectory, r);
  if (r->status != pd_tossOk) {
    clear_errors(r);
    pd_trajectory_free(trajectory);
    return NULL;
  }
  return trajectory;
}

// Angle of q_ref⁻¹ q, rad in [0, π]; atan2 of the vector part keeps small angles exact.
static double rotation_angle(pdQuat q, pdQuat ref) {
  pdQuat d = pd_quat_mul((pdQuat){ref.w, -ref.x, -ref.y, -ref.z}, q);
  return 2.0 * atan2(sqrt(d.x * d.x + d.y * d.y + d.z * d.z), fabs(d.w));
}

// Height of the block's lowest point above the surface, m: the box's half sizes along world z.
static double lowest_height(const pdTossExperiment* ex, const pdBodyState* b) {
  pdMat3 r = pd_quat_to_mat3(b->q);
  double below = 0.0;
  for (int j = 0; j < 3; ++j) below += 0.5 * ex->size[j] * fabs(r.m[2][j]);
  return b->x.z - below - ex->boardTop;
}

// Rotation vector of q1 q0⁻¹ (world frame), rad.
static pdVec3 rotation_between(pdQuat q0, pdQuat q1) {
  pdQuat d = pd_quat_mul(q1, (pdQuat){q0.w, -q0.x, -q0.y, -q0.z});
  if (d.w < 0.0) d = (pdQuat){-d.w, -d.x, -d.y, -d.z};
  pdVec3 u = {d.x, d.y, d.z};
  double s = pd_v3_norm(u);
  return s > 0.0 ? pd_v3_scale(u, 2.0 * atan2(s, d.w) / s) : (pdVec3){0, 0, 0};
}

int pd_toss_impacts(const pdTossExperiment* ex, const pdBodyState* samples, int n, pdTossImpact impacts[PD_TOSS_IMPACTS]) {
  int found = 0;
  for (int k = 0; k < n && found < PD_TOSS_IMPACTS;) {
    if (lowest_height(ex, &samples[k]) >= PD_DROP_CONTACT_BAND) {
      ++k;
      continue;
    }
    // within the band: the impact is the first sample after which the lowest point rises (not the lowest of the
    // whole contact, which at rest is wherever the tracking noise dips), and the contact lasts until the
    // block lifts above the lift band (or the record ends)
    int best = k;
    while (best + 1 < n && lowest_height(ex, &samples[best + 1]) < lowest_height(ex, &samples[best])) ++best;
    int j = best + 1;
    while (j < n && lowest_height(ex, &samples[j]) <= PD_DROP_LIFT_BAND) ++j;
    pdTossImpact* im = &impacts[found++];
    im->sample = best;
    im->t = (double)best / ex->rate;
    im->v = im->w = (pdVec3){NAN, NAN, NAN};
    if (best + 3 < n) {
      double scale = 0.5 * ex->rate;
      im->v = pd_v3_scale(pd_v3_sub(samples[best + 3].x, samples[best + 1].x), scale);
      im->w = pd_v3_scale(rotation_between(samples[best + 1].q, samples[best + 3].q), scale);
    }
    if (j >= n) break;  // never lifted again: at rest or rocking
    k = j;
  }
  return found;
}

// The bounces of the run against the record's (pdTossResult).
static void judge_impacts(const pdToss* toss, const pdTrajectory* run, pdTossResult* r) {
  pdTossImpact rec[PD_TOSS_IMPACTS], sim[PD_TOSS_IMPACTS];
  r->impactsRecord = pd_toss_impacts(toss->experiment, toss->samples, toss->sampleCount, rec);
  r->impactsRun = pd_toss_impacts(toss->experiment, run->bodies, toss->sampleCount, sim);
  for (int k = 0; k < PD_TOSS_IMPACTS; ++k) {
    bool both = k < r->impactsRecord && k < r->impactsRun;
    r->impactDt[k] = both ? fabs(sim[k].t - rec[k].t) : NAN;
    r->impactDv[k] = both ? pd_v3_norm(pd_v3_sub(sim[k].v, rec[k].v)) : NAN;
    r->impactDw[k] = both ? pd_v3_norm(pd_v3_sub(sim[k].w, rec[k].w)) : NAN;
  }
}

// Sample times of a run may differ from k/148 by round-off only (both are computed as k/rate), s.
#define TOSS_SAMPLE_TIME_TOL 1e-9

void pd_toss_judge(const pdToss* toss, const pdTrajectory* run, pdTossResult* r) {
  PD_ASSERT(toss && run && r && run->movingCount == 1);
  const pdTossExperiment* ex = toss->experiment;
  clear_errors(r);
  r->samples = toss->sampleCount;
  if (run->samples < toss->sampleCount) {
    fail(r, pd_tossFailed, "the run has %ld samples, the record %d", run->samples, toss->sampleCount);
    return;
  }
  double pos2 = 0.0, rot2 = 0.0, pos = 0.0, rot = 0.0;
  for (int k = 0; k < toss->sampleCount; ++k) {
    if (fabs(run->t[k] - (double)k / ex->rate) > TOSS_SAMPLE_TIME_TOL) {
      fail(r, pd_tossFailed, "sample %d of the run is at t = %.9g s, not %.9g s", k, run->t[k], (double)k / ex->rate);
      return;
    }
    const pdBodyState *sim = &run->bodies[k], *rec = &toss->samples[k];
    pos = pd_v3_norm(pd_v3_sub(sim->x, rec->x)) / ex->side;
    rot = rotation_angle(sim->q, rec->q);
    if (!isfinite(pos) || !isfinite(rot)) {
      fail(r, pd_tossFailed, "non-finite pose at sample %d", k);
      return;
    }
    pos2 += pos * pos;
    rot2 += rot * rot;
  }
  r->status = pd_tossOk;
  r->message[0] = '\0';
  r->posErrEnd = pos;
  r->rotErrEnd = rot;
  r->posErrRms = sqrt(pos2 / toss->sampleCount);
  r->rotErrRms = sqrt(rot2 / toss->sampleCount);
  if (ex->planar) judge_impacts(toss, run, r);
}

// ---------------------------------------------------------------- the record as a run directory

bool pd_toss_write_record(const pdToss* toss, const pdTossParams* params, const char* dir, const char* dataPath,
                          pdError* err) {
  pdModel* model = pd_toss_model(toss, params, err);
  if (!model) return false;
  pdRunWriter* writer = pd_run_open(dir, err);
  if (!writer) {
    pd_model_free(model);
    return false;
  }
  pdState* state = pd_state_create(model, NULL);
  double energyStart = 0.0;
  bool ok = true;
  for (int k = 0; k < toss->sampleCount && ok; ++k) {
    set_block_state(state, &toss->samples[k]);  // the block is the only moving body
    state->t = (double)k / toss->experiment->rate;
    ++state->count.samples;
    if (k == 0) energyStart = pd_state_energy(model, state);
    ok = pd_run_observe(model, state, writer);
  }
  char* settings = NULL;
  size_t settingsSize = 0;
  FILE* mem = open_memstream(&settings, &settingsSize);
  if (!mem) abort();
  fputs("{\"source\": ", mem);
  pdu_json_string(mem, dataPath ? dataPath : "");
  fprintf(mem, ", \"toss\": %ld, \"first_line\": %ld, \"rate_hz\": %.17g, \"quaternions\": \"normalised on reading\"}",
          toss->id, toss->line, toss->experiment->rate);
  fclose(mem);
  pdRunInfo info = {.engine = "record",
                    .energyStart = energyStart,
                    .energyEnd = pd_state_energy(model, state),
                    .completed = true,
                    .stepper = "record",
                    .engineSettingsJson = settings};
  if (ok) {
    ok = pd_run_finish(writer, model, state, &info, err);
  } else {
    pd_error_set(err, dir, 0, 0, "cannot write trajectory.csv");
    pd_run_abort(writer);
  }
  free(settings);
  pd_state_free(state);
  pd_model_free(model);
  return ok;
}

// ---------------------------------------------------------------- statistics

// Type-7 percentile of sorted x[0..n), p in [0, 1].
static double percentile(const double* x, int n, double p) {
  double h = p * (double)(n - 1);
  int lo = (int)floor(h);
  if (lo >= n - 1) return x[n - 1];
  return x[lo] + (h - (double)lo) * (x[lo + 1] - x[lo]);
}

pdTossStats pd_toss_stats(const double* v, int count) {
  PD_ASSERT(count >= 0 && (v || count == 0));
  double* x = malloc((size_t)(count > 0 ? count : 1) * sizeof *x);
  if (!x) abort();
  int n = 0;
  double sum = 0.0;
  for (int i = 0; i < count; ++i)
    if (isfinite(v[i])) {
      x[n++] = v[i];
      sum += v[i];
    }
  pdTossStats s = {n, NAN, NAN, NAN};
  if (n > 0) {
    pd_sort_doubles(x, (size_t)n);
    s.mean = sum / n;
    s.median = percentile(x, n, 0.5);
    s.p90 = percentile(x, n, 0.9);
  }
  free(x);
  return s;
}

// ---------------------------------------------------------------- parameter fragments

// A fragment is at most this long: three numbers and comments.
#define TOSS_FRAGMENT_MAX_BYTES 65536
#define TOSS_FRAGMENT_PREFIX "cube fragment none 1 1 1\n"

static const char* const fragmentKeys[] = {"mu", "restitution", "kn"};
enum { FRAGMENT_KEYS = 3 };

bool pd_toss_params_read(const char* path, pdTossParams* params, pdError* err) {
  FILE* in = fopen(path, "rb");
  if (!in) {
    pd_error_set(err, path, 0, 0, "cannot read: %s", strerror(errno));
    return false;
  }
  const size_t prefixLen = strlen(TOSS_FRAGMENT_PREFIX);
  char* text = malloc(prefixLen + TOSS_FRAGMENT_MAX_BYTES + 2);
  if (!text) abort();
  memcpy(text, TOSS_FRAGMENT_PREFIX, prefixLen);
  size_t n = fread(text + prefixLen, 1, TOSS_FRAGMENT_MAX_BYTES + 1, in);
  bool readError = ferror(in);
  fclose(in);
  if (readError || n > TOSS_FRAGMENT_MAX_BYTES) {
    pd_error_set(err, path, 0, 0, readError ? "read error" : "longer than %d bytes: not a parameter fragment",
                 TOSS_FRAGMENT_MAX_BYTES);
    free(text);
    return false;
  }
  text[prefixLen + n] = '\0';
  // which commands appear, line by line (the scene parser checks values, ranges and arity after this)
  int keyLine[FRAGMENT_KEYS] = {0}, keyCol[FRAGMENT_KEYS] = {0};
  int line = 1;
  for (const char* p = text + prefixLen; *p; ++line) {
    const char* end = strchr(p, '\n');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    size_t i = 0;
    while (i < len && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r')) ++i;
    if (i < len && p[i] != '#') {
      size_t w = i;
      while (w < len && p[w] != ' ' && p[w] != '\t' && p[w] != '\r' && p[w] != '#') ++w;
      int key = -1;
      for (int k = 0; k < FRAGMENT_KEYS; ++k)
        if (strlen(fragmentKeys[k]) == w - i && strncmp(p + i, fragmentKeys[k], w - i) == 0) key = k;
      if (key < 0) {
        pd_error_set(err, path, line, (int)i + 1,
                     "'%.*s': a cubetoss parameter fragment holds only mu, restitution and kn lines (and comments)",
                     (int)(w - i < 40 ? w - i : 40), p + i);
        free(text);
        return false;
      }
      keyLine[key] = line;
      keyCol[key] = (int)i + 1;
    }
    p = end ? end + 1 : p + len;
  }
  pdScene* scene = pd_scene_parse_buffer(path, text, prefixLen + n, err);
  free(text);
  if (!scene) {
    if (err && err->line > 0) --err->line;  // the prefix line is ours
    return false;
  }
  const pdSceneObject* o = &scene->objects[0];
  bool ok = true;
  if (keyLine[1] && o->restitution < PD_TOSS_RESTITUTION_MIN) {
    pd_error_set(err, path, keyLine[1], keyCol[1], "restitution %.10g is below %g, the contact model's smallest",
                 o->restitution, PD_TOSS_RESTITUTION_MIN);
    ok = false;
  } else if (!keyLine[0] && !keyLine[1] && !keyLine[2]) {
    pd_error_set(err, path, 0, 0, "sets none of mu, restitution, kn");
    ok = false;
  }
  if (ok) {
    if (keyLine[0]) params->mu = o->mu;
    if (keyLine[1]) params->restitution = o->restitution;
    if (keyLine[2]) params->kn = o->kn;
  }
  pd_scene_free(scene);
  return ok;
}

// The shortest %.Ng that reads back as the same double.
static void write_exact(FILE* out, double v) {
  char buf[40];
  for (int precision = 1; precision <= 17; ++precision) {
    snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (strtod(buf, NULL) == v) break;
  }
  fputs(buf, out);
}

void pd_toss_params_write(FILE* out, const pdTossParams* p, const char* comment) {
  for (const char* c = comment; c && *c;) {
    const char* end = strchr(c, '\n');
    int len = end ? (int)(end - c) : (int)strlen(c);
    fprintf(out, "# %.*s\n", len, c);
    c = end ? end + 1 : c + len;
  }
  const double values[FRAGMENT_KEYS] = {p->mu, p->restitution, p->kn};
  for (int k = 0; k < FRAGMENT_KEYS; ++k) {
    fprintf(out, "%s ", fragmentKeys[k]);
    write_exact(out, values[k]);
    fputc('\n', out);
  }
}

// ---------------------------------------------------------------- parallel runs (batch.h)

typedef struct tossBatch {
  size_t resultSize;
  pdTossJobFcn* job;
  void* user;
  pdTossProgressFcn* progress;
  void* progressUser;
} tossBatch;

static void toss_task(int task, pdBatchBuffer* result, void* user) {
  const tossBatch* b = user;
  unsigned char* slot = calloc(1, b->resultSize);
  if (!slot) abort();
  b->job(task, slot, b->user);
  pd_batch_append(result, slot, b->resultSize);
  free(slot);
}

static bool toss_progress(int task, int done, int total, void* user) {
  (void)task;
  const tossBatch* b = user;
  return b->progress(done, total, b->progressUser);
}

bool pd_toss_parallel(int count, int workers, size_t resultSize, void* results, pdTossJobFcn* job, void* user,
                      pdTossProgressFcn* progress, void* progressUser, char* why, size_t whySize) {
  PD_ASSERT(count >= 0 && workers >= 1 && resultSize > 0 && (results || count == 0) && job);
  tossBatch b = {resultSize, job, user, progress, progressUser};
  // every rank gets every result: the fit's simplex steps on all ranks alike
  pdBatchOptions options = {.workers = workers, .everywhere = true, .progress = progress ? toss_progress : NULL,
                            .progressUser = &b};
  pdBatchBuffer* buffers = calloc((size_t)count + 1, sizeof *buffers);
  if (!buffers) abort();
  bool ok = pd_batch_run(count, toss_task, &b, &options, buffers, why, whySize);
  for (int i = 0; i < count; ++i) {
    if (ok) {
      PD_ASSERT(buffers[i].size == resultSize);
      memcpy((unsigned char*)results + (size_t)i * resultSize, buffers[i].data, resultSize);
    }
    pd_batch_buffer_free(&buffers[i]);
  }
  free(buffers);
  return ok;
}
