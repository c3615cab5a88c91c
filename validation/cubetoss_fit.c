// polydyn validation — fitting an engine's free parameters to the training tosses with GSL's Nelder–Mead
// simplex (objective, bounds and steps in cubetoss.h); the held-out split, several engines in turn and their
// fit.csv, for both data sets (cube tosses, planar drops).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multimin.h>

#include "pdval/cubetoss.h"

// The box of the scaled coordinates and the simplex's first steps (cubetoss.h).
enum { FIT_DIM_MAX = 3 };
static const double boxLo[FIT_DIM_MAX] = {-2.0, PD_TOSS_RESTITUTION_MIN, 4.0};
static const double boxHi[FIT_DIM_MAX] = {0.17609125905568124 /* log10 1.5 */, 1.0, 8.0};
static const double startStep[FIT_DIM_MAX] = {0.15, 0.15, 0.5};
// Penalty per unit of scaled distance outside the box: larger than any gain the objective could show
// over such a distance near the box, so the simplex turns back.
#define FIT_PENALTY_PER_UNIT 1.0
// Fitted values are kept to this many significant digits: the objective's noise across tosses is far
// larger than what further digits change, and the fragment stays readable.
#define FIT_DIGITS 4

typedef struct fitContext {
  const pdTossFitOptions* o;
  int dim;
  pdTossResult* results;  // (tossCount)
  pdTossParams params;    // of the current evaluation
  int evaluations;
  bool stopped;
  char why[256];
  // the last evaluation's terms, and the first evaluation's objective (GSL evaluates the start first)
  double posMean, rotMean, bounceMean;  // bounceMean: NAN unless planar
  double startObjective;
  int failed;
} fitContext;

static void fit_job(int i, void* result, void* user) {
  fitContext* c = user;
  const pdToss* toss = &c->o->set->tosses[c->o->tosses[i]];
  pdTrajectory* tr = pd_toss_simulate(toss, &c->params, &c->o->engine, NULL, result);
  pd_trajectory_free(tr);
}

static double round_digits(double v) {
  char buf[40];
  snprintf(buf, sizeof buf, "%.*g", FIT_DIGITS, v);
  return strtod(buf, NULL);
}

// Parameters at scaled point u (clamped into the box); *outside = distance from the box.
static pdTossParams params_at(const fitContext* c, const double* u, double* outside) {
  double v[FIT_DIM_MAX] = {0}, d2 = 0.0;
  for (int i = 0; i < c->dim; ++i) {
    v[i] = fmin(fmax(u[i], boxLo[i]), boxHi[i]);
    d2 += (u[i] - v[i]) * (u[i] - v[i]);
  }
  if (outside) *outside = sqrt(d2);
  pdTossParams p = c->o->start;
  p.mu = pow(10.0, v[0]);
  p.restitution = v[1];
  if (c->dim > 2) p.kn = pow(10.0, v[2]);
  return p;
}

// Runs every training toss at c->params: J = mean end position error + mean end rotation error (rad).
static double evaluate(fitContext* c) {
  const pdTossFitOptions* o = c->o;
  ++c->evaluations;
  if (!pd_toss_parallel(o->tossCount, o->workers, sizeof *c->results, c->results, fit_job, c, o->progress,
                        o->progressUser, c->why, sizeof c->why)) {
    c->stopped = true;
    return HUGE_VAL;
  }
  double pos = 0.0, rot = 0.0, bounce = 0.0;
  c->failed = 0;
  for (int i = 0; i < o->tossCount; ++i) {
    const pdTossResult* r = &c->results[i];
    bool ok = r->status == pd_tossOk;
    c->failed += !ok;
    pos += ok ? r->posErrEnd : PD_TOSS_FAIL_POS_ERR;
    rot += ok ? r->rotErrEnd : PD_TOSS_FAIL_ROT_ERR;
    bounce += ok && isfinite(r->impactDv[0]) ? r->impactDv[0] : PD_TOSS_FAIL_BOUNCE_ERR;
  }
  c->posMean = pos / o->tossCount;
  c->rotMean = rot / o->tossCount;
  bool planar = o->set->experiment->planar;
  c->bounceMean = planar ? bounce / o->tossCount : NAN;
  return c->posMean + c->rotMean + (planar ? c->bounceMean / PD_TOSS_BOUNCE_SCALE : 0.0);
}

void pd_toss_fit_trace_header(FILE* out) {
  fputs("engine,variant,evaluation,mu,restitution,kn,objective,pos_err_end_mean,rot_err_end_mean_rad,failed,penalty,"
        "bounce_dv_mean\n",
        out);
}

static void trace_row(const fitContext* c, double j, double penalty) {
  FILE* out = c->o->trace;
  if (!out) return;
  const pdTossParams* p = &c->params;
  const char* variant = strcmp(c->o->engine.name, "soft") == 0      ? "implicit"
                        : c->o->engine.ref.variant == pd_refMatched ? "matched"
                                                                    : "native";
  fprintf(out, "%s,%s,%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d,%.6g,", c->o->engine.name, variant, c->evaluations,
          p->mu, p->restitution, p->kn, j, c->posMean, c->rotMean, c->failed, penalty);
  if (isfinite(c->bounceMean)) fprintf(out, "%.10g", c->bounceMean);
  fputc('\n', out);
  fflush(out);
}

static double objective(const gsl_vector* x, void* user) {
  fitContext* c = user;
  if (c->stopped) return HUGE_VAL;
  double u[FIT_DIM_MAX], outside;
  for (int i = 0; i < c->dim; ++i) u[i] = gsl_vector_get(x, (size_t)i);
  c->params = params_at(c, u, &outside);
  double j = evaluate(c);
  if (c->stopped) return HUGE_VAL;
  double penalty = FIT_PENALTY_PER_UNIT * outside;
  if (c->evaluations == 1) c->startObjective = j + penalty;
  trace_row(c, j, penalty);
  return j + penalty;
}

bool pd_toss_fit(const pdTossFitOptions* o, pdTossFitResult* result, char* why, size_t whySize) {
  PD_ASSERT(o && result && o->set && o->tosses && o->tossCount > 0 && o->maxEvaluations > 0 && o->sizeTol > 0.0 &&
            o->workers >= 1 && o->start.mu > 0.0 && o->start.kn > 0.0);
  fitContext c = {.o = o, .dim = o->fitStiffness ? 3 : 2};
  c.results = calloc((size_t)o->tossCount, sizeof *c.results);
  if (!c.results) abort();
  memset(result, 0, sizeof *result);

  gsl_multimin_function f = {.f = objective, .n = (size_t)c.dim, .params = &c};
  gsl_vector* x = gsl_vector_alloc((size_t)c.dim);
  gsl_vector* step = gsl_vector_alloc((size_t)c.dim);
  const double start[FIT_DIM_MAX] = {log10(o->start.mu), o->start.restitution, log10(o->start.kn)};
  for (int i = 0; i < c.dim; ++i) {
    gsl_vector_set(x, (size_t)i, fmin(fmax(start[i], boxLo[i]), boxHi[i]));
    gsl_vector_set(step, (size_t)i, startStep[i]);
  }
  // a stopped evaluation returns +inf, which the simplex reports as GSL_EBADFUNC: a status here, not an abort
  gsl_error_handler_t* previousHandler = gsl_set_error_handler_off();
  gsl_multimin_fminimizer* s = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, (size_t)c.dim);
  PD_ASSERT(s != NULL);
  int status = gsl_multimin_fminimizer_set(s, &f, x, step);
  bool converged = false;
  while (status == GSL_SUCCESS && !c.stopped && c.evaluations < o->maxEvaluations) {
    status = gsl_multimin_fminimizer_iterate(s);
    if (status != GSL_SUCCESS || c.stopped) break;
    if (gsl_multimin_test_size(gsl_multimin_fminimizer_size(s), o->sizeTol) == GSL_SUCCESS) {
      converged = true;
      break;
    }
  }
  bool ok = !c.stopped;
  if (ok) {
    // the best vertex, rounded, evaluated once more: the objective reported is the one of the values written
    double u[FIT_DIM_MAX];
    for (int i = 0; i < c.dim; ++i) u[i] = gsl_vector_get(gsl_multimin_fminimizer_x(s), (size_t)i);
    pdTossParams p = params_at(&c, u, NULL);
    p.mu = round_digits(p.mu);
    p.restitution = fmax(round_digits(p.restitution), PD_TOSS_RESTITUTION_MIN);
    p.kn = round_digits(p.kn);
    c.params = p;
    double j = evaluate(&c);
    ok = !c.stopped;
    if (ok) {
      trace_row(&c, j, 0.0);
      *result = (pdTossFitResult){.params = p, .startObjective = c.startObjective, .objective = j, .posErrEndMean = c.posMean, .rotErrEndMean = c.rotMean, .bounceDvMean = c.bounceMean,
                                  .failed = c.failed, .evaluations = c.evaluations, .converged = converged};
    }
  }
  if (!ok) snprintf(why, whySize, "%s", c.why);
  gsl_multimin_fminimizer_free(s);
  gsl_set_error_handler(previousHandler);
  gsl_vector_free(x);
  gsl_vector_free(step);
  free(c.results);
  return ok;
}

// ---------------------------------------------------------------- several engines, the split, fit.csv

void pd_toss_fit_split(const int* indices, int count, int trainEvery, int* train, int* trainCount, int* test,
                       int* testCount) {
  PD_ASSERT(trainEvery >= 1 && (count == 0 || (indices && train && test)));
  int seenTrain = 0;
  *trainCount = *testCount = 0;
  for (int i = 0; i < count; ++i) {
    if (pd_toss_split(indices[i]) == pd_tossTest) test[(*testCount)++] = indices[i];
    else if (seenTrain++ % trainEvery == 0) train[(*trainCount)++] = indices[i];
  }
}

bool pd_toss_fit_engines(const pdTossFitOptions* common, const pdTossFitEngine* engines, int count,
                         void (*started)(const pdTossFitEngine* engine, void* user), void* user,
                         pdTossFitResult* results, pdTossParams* fitted, char* why, size_t whySize) {
  bool ok = true;
  for (int e = 0; e < count; ++e) {
    memset(&results[e], 0, sizeof results[e]);
    fitted[e] = engines[e].start;
  }
  for (int e = 0; e < count && ok; ++e) {
    if (!engines[e].fit) continue;
    if (started) started(&engines[e], user);
    pdTossFitOptions o = *common;
    o.engine = engines[e].engine;
    o.start = engines[e].start;
    o.fitStiffness = engines[e].fitStiffness;
    ok = pd_toss_fit(&o, &results[e], why, whySize);
    if (ok) fitted[e] = results[e].params;
  }
  return ok;
}

void pd_toss_fit_csv(FILE* out, const pdTossFitEngine* engines, int count, const pdTossFitResult* results,
                     int trainCount, int trainEvery, int testCount) {
  fputs("engine,variant,status,fitted,mu,restitution,kn,objective_train,pos_err_end_mean_train,"
        "rot_err_end_mean_train_rad,failed_train,evaluations,converged,train_tosses,train_every,test_tosses,"
        "start_mu,start_restitution,start_kn,start_objective_train,bounce_dv_mean_train\n",
        out);
  for (int e = 0; e < count; ++e) {
    const pdTossFitEngine* g = &engines[e];
    const pdTossFitResult* f = &results[e];
    const pdTossParams* s = &g->start;
    fprintf(out, "%s,%s,%s,%s,", g->engine.name, g->variant, g->fit ? "ok" : g->built ? "no parameters" : "not built",
            !g->fit ? "" : g->fitStiffness ? "mu;restitution;kn" : "mu;restitution");
    if (g->fit)
      fprintf(out, "%.10g,%.10g,%.10g,%.9g,%.9g,%.9g,%d,%d,%s,", f->params.mu, f->params.restitution, f->params.kn,
              f->objective, f->posErrEndMean, f->rotErrEndMean, f->failed, f->evaluations, f->converged ? "true" : "false");
    else
      fputs(",,,,,,,,,", out);
    fprintf(out, "%d,%d,%d,%.10g,%.10g,%.10g,", trainCount, trainEvery, testCount, s->mu, s->restitution, s->kn);
    if (g->fit) fprintf(out, "%.9g", f->startObjective);
    fputc(',', out);
    if (g->fit && isfinite(f->bounceDvMean)) fprintf(out, "%.9g", f->bounceDvMean);
    fputc('\n', out);
  }
}
