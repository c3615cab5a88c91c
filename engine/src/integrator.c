// polydyn — the steppers and the loop that runs one system through them (paper §2 and Fig. 8; docs/DESIGN.md §5).
// pd_advance (advance.c) runs it for the whole scene with islands off; islands.c runs it for each island. It calls
// neither of them.
//
// Design note. pd_step_until walks from state->t to tEnd in steps of classic fourth-order Runge–Kutta.
// The adaptive stepper estimates the local error by step doubling: one step of h and two of h/2
// from the same start; their difference is 15/16 of the full step's error, so
//   err_i = (y_half,i − y_full,i) / 15
// estimates the error of the two-half-step result, which is the one accepted (plain fourth order:
// no Richardson extrapolation, so the estimate describes the value we keep). The error norm is the
// max over components of |err_i| / weight_i, where weight_i is the component's characteristic scale
// (state.c: body size for positions, vmax for velocities, vmax/size for angular velocities, 1 for
// quaternion components). A step is accepted when norm <= tol, or when h is already at dtmin (then
// a warning is counted). The next step is h · clamp(0.9 (tol/norm)^(1/5), 0.2, 5), within
// [dtmin, dtmax], and at most the contacts' stability bound (contact_set.h, pd_contact_set_limit_step).
// The embedded stepper (pd_stepperRK43Embedded) keeps one RK4 step and estimates its error with RK4's
// third-order partner, h (k4 − f(t + h, y1))/6: 5 evaluations per step instead of 11, but twice the
// steps for the same stability bound (a single RK4 step must now be stable), and the contact events are
// analysed once per accepted step — so it wins on impacts and free flight and loses on resting and sliding
// contacts (docs/integration.md); step doubling, not this pair, is the default's explicit part. Both run through
// adaptive_step, which takes the trial, the order of its estimate (the controller's exponents) and the bound's share.
// The Dormand–Prince pair (pd_stepperDopri54, trial_dopri) keeps a fifth-order result with an O(h⁵) estimate, as step
// doubling does, at 7 evaluations per step; its stability region holds little of the imaginary axis, so its bound
// depends on the contacts' damping (pd_contact_set_dopri_fraction) and is below step doubling's two half steps'.
// The implicit stepper (pd_stepperImplicit, switching_step) runs step doubling until the contacts' stability bound
// holds it well below what its error control wants (resting contact), then ROS34PW2, a linearly implicit method
// with no stability bound (trial_implicit; its matrices in implicit.c), until step doubling could take about its
// steps again: one system (island) at a time, decided from its own numbers.
//
// Output samples fall exactly on t = k / sampleRate (samples.h), but they do not cut the error-controlled steppers'
// steps, nor does tEnd: the step that passes such a time keeps its interpolant (dense_output.h), the state is
// presented there for the observer, and at tEnd it is left presented while the integration's own state waits at its
// step's end for the next call. So the samples and the call's slices do not change the steps. The fixed stepper
// (a reference for the work-precision sweeps) still cuts its step to end on each sample and on tEnd. An island (no
// observer) keeps its own samples too: they are where its steps aim while it lags behind the scene.
//
// Numerical trouble: a trial step that produces a non-finite number is rejected and retried four
// times smaller (warning counted). At dtmin the run stops with state->failed set; the state keeps
// its last finite value, so nothing non-finite ever reaches the observer.
//
// Memory: every vector lives in state->work, allocated by pd_state_create.
#include <float.h>
#include <math.h>
#include <string.h>

#include "clock.h"
#include "contact_set.h"
#include "dense_output.h"
#include "dynamics.h"
#include "help_desk.h"
#include "implicit.h"
#include "integrator.h"
#include "polydyn/state.h"
#include "samples.h"
#include "state_layout.h"

// Reading the clock (clock_gettime through the vDSO) is not free next to a small island's derivative: three reads
// in every evaluation were 14 % of cases/bench/pile_100's run, whose islands of a few boxes make an evaluation
// cheap. One evaluation in this many is timed and counted this many times, so the
// forces and derivative stages are estimates; a prime, so that the timed ones fall on each of the step
// doubling's 11 (10 or 7 on a retry) evaluations in turn. The count depends on the state alone: no output changes.
// 31 rather than 13: at 13 the reads were still ~1 % of cases/sweep/pile_10's run.
#define PD_DERIVATIVE_TIMING_STRIDE 31

static void derivative(const pdModel* model, pdState* s, double t, const double* y, double* dydt) {
  bool timed = s->count.derivatives % PD_DERIVATIVE_TIMING_STRIDE == 0;
  pd_state_derivative_sampled(model, s, t, y, dydt, timed ? PD_DERIVATIVE_TIMING_STRIDE : 0.0);
  ++s->count.derivatives;
}

// Seconds spent inside derivative evaluations so far (subtracted from the integration stage).
static double derivative_seconds(const pdState* s) {
  return s->stageSeconds[pd_stageForces] + s->stageSeconds[pd_stageDerivative];
}

// The integration stage of a trial step: the lap's time less the derivative evaluations' inside it
// (tDerivative: derivative_seconds at the trial's start). The derivative stages are sampled estimates
// (derivative()): a trial's share may come out below zero, the sum over a run does not.
static void integrate_lap(pdState* s, pdStopwatch* watch, double tDerivative) {
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageIntegrate]);
  s->stageSeconds[pd_stageIntegrate] -= derivative_seconds(s) - tDerivative;
}

// Scratch vectors inside state->work, and what `half` holds.
typedef struct stepperWork {
  double *k1, *ktmp, *ytmp, *acc, *full, *half, *k1half, *trial;
  double halfStep;  // s: `half` is the RK4 step of this size from the step's start (k1 and y as now); 0: none
  bool linearised;  // the implicit stepper's W is formed at the step's start (trials from there share it)
} stepperWork;

// The scratch of a step from the state as it is now (nothing in it yet).
static stepperWork work_of(pdState* s) {
  double* w = s->work;
  size_t n = (size_t)s->capacity;
  return (stepperWork){w, w + n, w + 2 * n, w + 3 * n, w + 4 * n, w + 5 * n, w + 6 * n, w + 7 * n, 0.0, false};
}

// RK4's vector updates, elementwise (so a split loop computes the same numbers: help_desk.h): stage 0 starts the
// sum and the first midpoint; stages 1 and 2 add a slope and form the next point (half and whole step); stage 3
// forms the result.
typedef struct rk4Loop {
  stepperWork* w;
  const double *y, *k1;
  double h;
  double* out;
  int stage;
} rk4Loop;

static void rk4_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const rk4Loop* job = ctx;
  stepperWork* w = job->w;
  const double* y = job->y;
  double h = job->h;
  switch (job->stage) {
    case 0:
      for (int i = begin; i < end; ++i) {
        w->acc[i] = job->k1[i];
        w->ytmp[i] = y[i] + 0.5 * h * job->k1[i];
      }
      break;
    case 1:
    case 2: {
      double step = job->stage == 1 ? 0.5 * h : h;
      for (int i = begin; i < end; ++i) {
        w->acc[i] += 2.0 * w->ktmp[i];
        w->ytmp[i] = y[i] + step * w->ktmp[i];
      }
      break;
    }
    default:
      for (int i = begin; i < end; ++i) job->out[i] = y[i] + (h / 6.0) * (w->acc[i] + w->ktmp[i]);
  }
}

// State components below which RK4's vector updates are not split (help_desk.h): ~1 ns each, against a handover of
// about a microsecond.
#define PD_HELP_MIN_COMPONENTS 4096

// One classic RK4 step of size h from (t, y) whose derivative k1 is known; result in `out`.
static void rk4(const pdModel* model, pdState* s, stepperWork* w, double t, const double* y, const double* k1,
                double h, double* out) {
  pdHelpDesk* desk = pd_contact_set_help_desk(s->contacts);
  rk4Loop job = {w, y, k1, h, out, 0};
  pd_help_for(desk, s->n, PD_HELP_MIN_COMPONENTS, rk4_range, &job);
  derivative(model, s, t + 0.5 * h, w->ytmp, w->ktmp);
  job.stage = 1;
  pd_help_for(desk, s->n, PD_HELP_MIN_COMPONENTS, rk4_range, &job);
  derivative(model, s, t + 0.5 * h, w->ytmp, w->ktmp);
  job.stage = 2;
  pd_help_for(desk, s->n, PD_HELP_MIN_COMPONENTS, rk4_range, &job);
  derivative(model, s, t + h, w->ytmp, w->ktmp);
  job.stage = 3;
  pd_help_for(desk, s->n, PD_HELP_MIN_COMPONENTS, rk4_range, &job);
}

static bool all_finite(const double* y, int n) {
  for (int i = 0; i < n; ++i)
    if (!isfinite(y[i])) return false;
  return true;
}

static void renormalise_quaternions(const pdModel* model, double* y) {
  for (int k = 0; k < model->movingCount; ++k) {
    double* q = y + PD_BODY_STATE_SIZE * k + PD_Y_Q;
    double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i) q[i] /= norm;
  }
}

// Step-size controller bounds: never grow more than 5× or shrink below 1/5 per accepted step
// (smooth step sequences), 0.9 safety so the next step is likely accepted.
#define STEP_SAFETY 0.9
#define STEP_GROW_MAX 5.0
#define STEP_SHRINK_MIN 0.2
#define STEP_REJECT_SHRINK_MIN 0.1
#define NONFINITE_SHRINK 0.25
// A step ending this many units of rounding short of a sample time is taken as landing on it.
#define TIME_SNAP_ULPS 16.0

// One trial step of h from (s->t, s->y) whose derivative k1 is in w->k1: the result goes to w->trial and the
// function returns the error norm (max over components of |error estimate| / weight).
typedef double trialFcn(const pdModel* model, pdState* s, stepperWork* w, double h);

// fmax(norm, x) for norm >= 0 not NaN, as the error norms below use it (a NaN component is skipped: the
// non-finite check of the stepper catches it), without a libm call per state component.
static inline double max_skipping_nan(double norm, double x) { return x > norm ? x : norm; }

// Step doubling: one step of h and two of h/2; err = (y_half − y_full)/15 estimates the error of the two
// half steps, which are kept. 11 derivative evaluations (k1 included; 10 on a retry, 7 on a retry at half
// the step).
static double trial_doubling(const pdModel* model, pdState* s, stepperWork* w, double h) {
  // a retry at half the last trial's step from the same start (a stick–slip refinement halves it) has that
  // trial's first half step as its full step: the same numbers, 3 derivative evaluations fewer
  if (h == w->halfStep)
    memcpy(w->full, w->half, (size_t)s->n * sizeof *w->full);
  else
    rk4(model, s, w, s->t, s->y, w->k1, h, w->full);
  rk4(model, s, w, s->t, s->y, w->k1, 0.5 * h, w->half);
  w->halfStep = 0.5 * h;
  derivative(model, s, s->t + 0.5 * h, w->half, w->k1half);
  rk4(model, s, w, s->t + 0.5 * h, w->half, w->k1half, 0.5 * h, w->trial);
  double norm = 0.0;
  for (int i = 0; i < s->n; ++i) norm = max_skipping_nan(norm, fabs(w->trial[i] - w->full[i]) / (15.0 * s->weight[i]));
  return norm;
}

// Classic RK4 with its embedded third-order partner: with k5 = f(t + h, y1), the weights
// (1/6, 1/3, 1/3, 0, 1/6) over (k1, k2, k3, k4, k5) satisfy the four third-order conditions, so
// y1 − ŷ1 = h (k4 − k5)/6 estimates the third-order solution's error, an upper bound of the kept
// fourth-order one's (local extrapolation). 5 derivative evaluations; k5 cannot be reused as the next
// step's k1 because committing the step realigns springs and may change the contact list.
static double trial_embedded(const pdModel* model, pdState* s, stepperWork* w, double h) {
  rk4(model, s, w, s->t, s->y, w->k1, h, w->trial);  // leaves k4 in w->ktmp
  derivative(model, s, s->t + h, w->trial, w->k1half);
  double norm = 0.0;
  for (int i = 0; i < s->n; ++i)
    norm = max_skipping_nan(norm, fabs(h * (w->ktmp[i] - w->k1half[i])) / (6.0 * s->weight[i]));
  return norm;
}

// Dormand–Prince 5(4) (J. R. Dormand & P. J. Prince, "A family of embedded Runge–Kutta formulae", J. Comput. Appl.
// Math. 6 (1980) 19–26; the tableau as printed in Hairer, Nørsett & Wanner, Solving ODEs I, 2nd ed., Table II.5.2):
// 7 stages, the fifth-order result kept (local extrapolation), error y1 − ŷ1 = h Σ e_i k_i with ŷ1 the embedded
// fourth-order one, O(h⁵) as step doubling's. The seventh stage is f(t + h, y1) (FSAL), but it cannot serve as the
// next step's k1: committing a step realigns the springs and may change the contact list (as for the embedded
// pair), so 7 evaluations per accepted step and 6 per rejected retry. Checked on y' = y²: local error O(h⁶).
static const double DOPRI_C[7] = {0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0};
static const double DOPRI_A[6][5] = {
    {1.0 / 5.0},
    {3.0 / 40.0, 9.0 / 40.0},
    {44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0},
    {19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0},
    {9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0},
    {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, /* 11/84: DOPRI_B[5] */}};
static const double DOPRI_B[6] = {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0};
static const double DOPRI_E[7] = {71.0 / 57600.0,      0.0,           -71.0 / 16695.0, 71.0 / 1920.0,
                                  -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0};
// The fourth-order continuous extension's last coefficients (Hairer, Nørsett & Wanner I, II.6, and their DOPRI5 code,
// CONTD5): with d = h Σ d_i k_i, the interpolant is dense_output.c's (b2 = d2 = 0). Checked on y' = y²: O(h⁵) at θ = ½.
static const double DOPRI_D[7] = {-12715105075.0 / 11282082432.0, 0.0,
                                  87487479700.0 / 32700410799.0,  -10690763975.0 / 1880347072.0,
                                  701980252875.0 / 199316789632.0, -1453857185.0 / 822651844.0,
                                  69997945.0 / 29380423.0};

// The stages' slopes in the scratch: k2's vector takes k7 (k2's weights in y1, the error and the extension are 0).
static void dopri_slopes(stepperWork* w, double* k[7]) {
  double* slopes[7] = {w->k1, w->ktmp, w->acc, w->full, w->half, w->k1half, w->ktmp};
  memcpy(k, slopes, sizeof slopes);
}

// out = y + h Σ_{j<count} a_j k_j, elementwise (so a split loop computes the same numbers: help_desk.h).
typedef struct dopriLoop {
  const double* y;
  double* const* k;
  const double* a;
  int count;
  double h;
  double* out;
} dopriLoop;

static void dopri_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const dopriLoop* job = ctx;
  for (int i = begin; i < end; ++i) {
    double acc = 0.0;
    for (int j = 0; j < job->count; ++j) acc += job->a[j] * job->k[j][i];
    job->out[i] = job->y[i] + job->h * acc;
  }
}

// The Dormand–Prince trial (pd_stepperDopri54): y1 into w->trial, the error norm returned; k1 … k7 left in the
// scratch for the dense output (dopri_slopes).
static double trial_dopri(const pdModel* model, pdState* s, stepperWork* w, double h) {
  w->halfStep = 0.0;
  pdHelpDesk* desk = pd_contact_set_help_desk(s->contacts);
  double* k[7];
  dopri_slopes(w, k);
  for (int i = 1; i < 7; ++i) {
    // stage i's point; the last is y1 itself
    double* point = i < 6 ? w->ytmp : w->trial;
    dopriLoop job = {s->y, k, i < 6 ? DOPRI_A[i - 1] : DOPRI_B, i, h, point};
    pd_help_for(desk, s->n, PD_HELP_MIN_COMPONENTS, dopri_range, &job);
    derivative(model, s, s->t + DOPRI_C[i] * h, point, k[i]);
  }
  double norm = 0.0;
  for (int i = 0; i < s->n; ++i) {
    double e = 0.0;
    for (int j = 0; j < 7; ++j) e += DOPRI_E[j] * k[j][i];
    norm = max_skipping_nan(norm, fabs(h * e) / s->weight[i]);
  }
  return norm;
}

// ROS34PW2 (Rang & Angermann, BIT 45 (2005) 761–787): a Rosenbrock-W method of 4 stages, order 3 for any
// matrix W, with an embedded order-2 solution, L-stable and stiffly accurate. In the transformed form (Hairer &
// Wanner II, IV.7), with M = I/(hγ) − W:
//   M u_i = f(t + α_i h, y + Σ_{j<i} a_ij u_j) + Σ_{j<i} (c_ij/h) u_j,   y1 = y + Σ m_i u_i,   error Σ e_i u_i.
// The coefficients are those of the method's tableau (γ, α_ij, γ_ij, b, b̂) transformed (a = αΓ⁻¹,
// c = diag(1/γ) − Γ⁻¹, m = bΓ⁻¹, e = (b − b̂)Γ⁻¹); checked on y' = λy: local error O((hλ)⁴), estimate O((hλ)³),
// R(∞) = 0 (reports/bench/implicit/README.md). α_i are the stage times (the time as a state component whose
// row of W is 0, so no ∂f/∂t term is needed).
static const double ROSW_GAMMA = 0.4358665215084590;
static const double ROSW_ALPHA[4] = {0.0, 0.87173304301691801, 0.73157995778885238, 1.0};
static const double ROSW_A[4][3] = {{0, 0, 0},
                                    {2.0, 0, 0},
                                    {1.4192173174557647, -0.25923221167296973, 0},
                                    {4.1847604823191604, -0.28519201735549593, 2.2942803602790418}};
static const double ROSW_C[4][3] = {{0, 0, 0},
                                    {-4.5885607205580836, 0, 0},
                                    {-4.1847604823191604, 0.28519201735549593, 0},
                                    {-6.3681792001283579, -6.7956209444668367, 2.8700986043310559}};
static const double ROSW_M[4] = {4.1847604823191595, -0.2851920173554956, 2.2942803602790414, 1.0};
static const double ROSW_E[4] = {0.27774994764796723, -1.4032398951759988, 1.7726301276675507, 0.5};

// The implicit stepper's trial (pd_stepperImplicit): one ROS34PW2 step of h, W linearised at the step's start
// (implicit.c) and M factorised for this h. 3 derivative evaluations besides k1, which a retry keeps, with W. A
// singular or non-finite M gives a non-finite norm: the step is retried smaller.
static double trial_implicit(const pdModel* model, pdState* s, stepperWork* w, double h) {
  PD_ASSERT(s->implicit != NULL);  // created by switching_step
  w->halfStep = 0.0;
  int n = s->n;
  if (!w->linearised) pd_implicit_linearise(model, s, s->implicit, s->y);
  w->linearised = true;
  pd_contact_set_clear_crossings(s->contacts);
  if (!pd_implicit_factor(model, s, s->implicit, ROSW_GAMMA * h)) return NAN;
  double* u[4] = {w->acc, w->full, w->half, w->k1half};
  for (int i = 0; i < 4; ++i) {
    const double* f = w->k1;
    if (i > 0) {
      for (int c = 0; c < n; ++c) {
        double acc = s->y[c];
        for (int j = 0; j < i; ++j) acc += ROSW_A[i][j] * u[j][c];
        w->ytmp[c] = acc;
      }
      derivative(model, s, s->t + ROSW_ALPHA[i] * h, w->ytmp, w->ktmp);
      f = w->ktmp;
    }
    for (int c = 0; c < n; ++c) {
      double acc = f[c];
      for (int j = 0; j < i; ++j) acc += (ROSW_C[i][j] / h) * u[j][c];
      w->trial[c] = acc;  // the right-hand side, until the result goes there
    }
    pd_implicit_solve(model, s, s->implicit, w->trial, u[i]);
  }
  double norm = 0.0;
  for (int c = 0; c < n; ++c) {
    double y1 = s->y[c], e = 0.0;
    for (int j = 0; j < 4; ++j) y1 += ROSW_M[j] * u[j][c], e += ROSW_E[j] * u[j][c];
    w->trial[c] = y1;
    norm = max_skipping_nan(norm, fabs(e) / s->weight[c]);
  }
  return norm;
}

// What an accepted step's caller may want to know (switching_step): the step the error control wants next, before
// the stability bound, and whether a contact event (tunnelling guard, onset, stick–slip refinement) cut the step.
typedef struct stepOutcome {
  double wanted;
  bool eventCut;
  bool gaveUp;  // a probation's trial at its floor was rejected (nothing taken, s->h unchanged)
  pdStepLimit wantedLimit;  // what set `wanted`
  pdStepLimit cutLimit;     // with eventCut: the event (pd_limitTravel or pd_limitEvent)
} stepOutcome;

// Dense output (dense_output.h): an accepted step that passes the time the state must next be presented at keeps
// its interpolant, from the trial's own numbers (step doubling: the first half step and its slope; the embedded pair:
// f(y1), its k5; Dormand–Prince: its stages; the implicit method: f(y1), evaluated here). Before the commit, which may change the contact list.
static void capture_step(const pdModel* model, pdState* s, stepperWork* w, trialFcn* trial, double h) {
  if (!s->dense || !pd_dense_wanted(s->dense, s->t, h)) return;
  if (trial == trial_doubling) {
    pd_dense_capture(model, s, h, w->k1, w->half, w->k1half, w->trial, NULL);
  } else if (trial == trial_embedded) {
    pd_dense_capture(model, s, h, w->k1, NULL, NULL, w->trial, w->k1half);
  } else if (trial == trial_dopri) {
    double* k[7];
    dopri_slopes(w, k);
    for (int i = 0; i < s->n; ++i) {
      double d = 0.0;
      for (int j = 0; j < 7; ++j) d += DOPRI_D[j] * k[j][i];
      w->ytmp[i] = h * d;
    }
    pd_dense_capture_dopri(model, s, h, w->k1, w->trial, k[6], w->ytmp);
  } else {
    double* f1 = pd_dense_slope_scratch(s->dense, s->n);
    derivative(model, s, s->t + h, w->trial, f1);
    pd_dense_capture(model, s, h, w->k1, NULL, NULL, w->trial, f1);
  }
}

// A located onset's step (bounded events) is cut on the accepted trial's own interpolant rather than retried: step
// doubling's quartic through its nodes (dense_output.h), whose error inside the step is within the kept result's,
// which the error control held to tol (on y' = λy, hλ from −1 to 1: at most 0.92 of the error at the step's end,
// anywhere inside it). Up to the onset the trial integrated what a retried step would (the new contact has no force
// before it), and past it both leave the contact to the correction at the cut. The paper's loop (exact events) retries, as do held modes (their changes are found from the
// first half step's end, which a cut step does not have) and the other steppers (their interpolant is a cubic).
static bool cuts_on_interpolant(const pdModel* model, const pdState* s, trialFcn* trial) {
  return trial == trial_doubling && pd_onsets_effective(s->onsets, model->movingCount) == pd_onsetsBounded;
}

// The state at hCut of the accepted trial of h into w->full (its full-step result is no longer needed).
static void onset_cut_state(const pdState* s, stepperWork* w, double h, double hCut) {
  pd_dense_quartic(s->n, h, hCut / h, s->y, w->k1, w->half, w->k1half, w->trial, w->full);
}

// The limits of a trial on probation (an implicit switch, implicit.h): the step below which the error control does not
// retry, and the error norm a trial must meet instead of tol.
typedef struct probationLimits {
  double floor;  // s
  double tol;
} probationLimits;

// Takes one accepted step of at most `hMax` from state->t with error control. Returns the step taken (0 on
// failure). `order` is the order of the error estimate's leading term in h (5 for step doubling, 4 for the
// embedded pair, 3 for ROS34PW2); `stableFraction` the part of the contacts' stability bound (a bound for half
// steps) the whole trial step may use (INFINITY: none; NAN: Dormand–Prince's, from the committed list); `probation` (nullable): a trial must meet its tol, a rejection
// below its floor retries at the floor once, and a trial at the floor rejected returns 0 with outcome->gaveUp set and
// nothing taken; `outcome` (nullable) receives the accepted step's outcome.
static double adaptive_step(const pdModel* model, pdState* s, double hMax, trialFcn* trial, double order,
                            double stableFraction, const probationLimits* probation, stepOutcome* outcome) {
  const pdSettings* set = &model->settings;
  stepperWork w = work_of(s);
  // held events hold each contact's modes over the step (contact_set.h); the others let the law decide
  pd_contact_set_hold_modes(s->contacts, s->onsets == pd_onsetsHeld);
  pd_contact_set_slip_reversals(s->contacts, trial == trial_implicit ? w.k1 : NULL);
  derivative(model, s, s->t, s->y, w.k1);
  bool eventCut = false;
  pdStepLimit cutLimit = pd_limitEvent;  // what cut the step, when eventCut
  for (;;) {
    // a step cut short to land on a time (one_step's `land`) says nothing about a longer one: s->h keeps the wanted
    // size
    bool cut = hMax < s->h;
    double h = cut ? hMax : s->h;
    pdStepLimit limit = !cut ? s->hLimit : eventCut ? cutLimit : pd_limitLanding;
    bool atMinimum = h <= set->dtmin;
    // the trial, then the contact events and the commit, timed as consecutive laps
    pdStopwatch watch = pd_stopwatch_start(s->stageTimers);
    double tDerivative = derivative_seconds(s);

    double norm = trial(model, s, &w, h);
    bool finite = isfinite(norm) && all_finite(w.trial, s->n);
    integrate_lap(s, &watch, tDerivative);

    if (!finite) {
      ++s->warnings[pd_warnNonFinite];
      ++s->count.rejected;
      if (atMinimum) {
        s->failed = true;
        return 0.0;
      }
      s->h = fmax(set->dtmin, NONFINITE_SHRINK * h);
      s->hLimit = pd_limitError;
      continue;
    }
    double tolTrial = probation ? probation->tol : set->tol;
    if (norm > tolTrial && !atMinimum) {
      ++s->count.rejected;
      double shrink = fmax(STEP_REJECT_SHRINK_MIN, STEP_SAFETY * pow(tolTrial / norm, 1.0 / (order - 1.0)));
      if (probation && shrink * h < probation->floor) {
        // a trial at the floor itself was rejected: give up; else the next trial is the floor
        if (h <= probation->floor) {
          if (outcome) *outcome = (stepOutcome){s->h, eventCut, true, s->hLimit, cutLimit};
          return 0.0;
        }
        shrink = probation->floor / h;
      }
      s->h = fmax(set->dtmin, shrink * h);
      s->hLimit = pd_limitError;
      continue;
    }
    // contact events (Fig. 8): a new contact's onset or a reversal inside the step may shorten it; a
    // virtual contact restarts it with the contact list grown
    double hRetry = h;
    const double* yMid = trial == trial_doubling ? w.half : NULL;  // the first half step's end
    long travelRetries = s->count.travelRetries, onsetRetries = s->count.eventRetries;
    pdEventVerdict verdict = pd_contact_events(model, s, h, w.trial, yMid, &hRetry, &watch);
    // the step's end and length as accepted: the trial's, or a located onset's cut on the trial's interpolant
    const double* yEnd = w.trial;
    double hTaken = h;
    if (verdict == pd_eventRetry && s->count.eventRetries > onsetRetries && cuts_on_interpolant(model, s, trial)) {
      // an onset to locate: the trial up to it is the retried step's, as accurate (onset_cut_state); a retried trial
      // is needed only if the contact events at the cut ask for one again
      double hCut = hRetry;
      onset_cut_state(s, &w, h, hCut);
      verdict = pd_contact_events(model, s, hCut, w.full, NULL, &hRetry, &watch);
      if (verdict == pd_eventAccept) {
        ++s->count.onsetCuts;
        yEnd = w.full;
        hTaken = hCut;
        cut = eventCut = true;
        cutLimit = limit = pd_limitEvent;
      }
    }
    if (verdict == pd_eventRetry) {
      hMax = hRetry;
      eventCut = true;
      cutLimit = s->count.travelRetries > travelRetries ? pd_limitTravel : pd_limitEvent;
      continue;
    }
    if (verdict == pd_eventRestart) {
      w = work_of(s);
      derivative(model, s, s->t, s->y, w.k1);
      continue;
    }
    if (norm > set->tol) ++s->warnings[pd_warnStepAtMinimum];
    capture_step(model, s, &w, trial, h);  // the whole trial's: a cut step presents its samples from the same curve
    pd_contact_events_commit(model, s, yEnd, &watch);
    h = hTaken;
    renormalise_quaternions(model, s->y);
    ++s->count.accepted;
    ++s->count.stepsLimited[limit];
    if (!cut) {
      double grow = norm > 0.0 ? STEP_SAFETY * pow(set->tol / norm, 1.0 / order) : STEP_GROW_MAX;
      grow = fmin(STEP_GROW_MAX, fmax(STEP_SHRINK_MIN, grow));
      s->h = fmin(set->dtmax, fmax(set->dtmin, grow * h));
      s->hLimit = grow * h >= set->dtmax ? pd_limitLargest : pd_limitError;
    } else if (eventCut) {
      // a step a contact event cut short grows from what it took, as any step does: tried again at the size the
      // event cut, the next step would meet the same contact (an onset whose interpolation came early, a tunnelling
      // guard) and be cut again, one whole trial lost each time
      if (STEP_GROW_MAX * h < s->h) s->hLimit = cutLimit;
      s->h = fmin(s->h, STEP_GROW_MAX * h);
    }
    // the tunnelling guard's step for the motion as it goes on: a longer trial would only be cut back to it
    double travelStep = pd_contact_set_travel_step(s->contacts);
    if (travelStep < s->h) s->hLimit = pd_limitTravel;
    s->h = fmax(set->dtmin, fmin(s->h, travelStep));
    if (outcome) *outcome = (stepOutcome){s->h, eventCut, false, s->hLimit, cutLimit};
    // the contacts' stability bound (§3.3): the error control alone would walk the step to the edge (an implicit
    // trial has none: stableFraction INFINITY)
    if (stableFraction != INFINITY) {
      bool tightNeeded;
      double fraction = isnan(stableFraction) ? pd_contact_set_dopri_fraction(s->contacts) : stableFraction;
      double stable = pd_contact_set_limit_step(model, s->contacts, s->h, fraction, &tightNeeded);
      if (stable < s->h) s->hLimit = pd_limitStability;
      s->h = fmax(set->dtmin, stable);
      s->count.stabilityTight += tightNeeded;
    }
    return h;
  }
}

// The implicit stepper (pd_stepperImplicit): step doubling while its step is set by the error control, ROS34PW2 while
// the contacts' stability bound would hold step doubling far below what its error control wants — resting contact,
// where the implicit method's steps are limited by its own error estimate alone (reports/bench/implicit: 3× fewer
// steps on a resting pile). The switch (implicit.h, PD_IMPLICIT_SWITCH_STEPS) looks only at the state's own
// numbers, so it is the same on every run. Systems of more than PD_IMPLICIT_BODIES_MAX moving bodies stay explicit.
// `explicitTrial`: step doubling (pd_stepperImplicit) or Dormand–Prince (pd_stepperImplicitDopri), with its bound.
static double explicit_step(const pdModel* model, pdState* s, double hMax, trialFcn* explicitTrial, stepOutcome* out) {
  return adaptive_step(model, s, hMax, explicitTrial, 5.0, explicitTrial == trial_dopri ? NAN : 1.0, NULL, out);
}

static double switching_step(const pdModel* model, pdState* s, double hMax, trialFcn* explicitTrial) {
  if (model->movingCount > PD_IMPLICIT_BODIES_MAX) return explicit_step(model, s, hMax, explicitTrial, NULL);
  if (!s->implicit) {
    s->implicit = pd_implicit_create();
    pd_implicit_reserve(s->implicit, model->movingCount, pd_state_contact_room(model, s));
  }
  pdImplicit* im = s->implicit;
  stepOutcome out = {0.0, false, false, pd_limitError, pd_limitEvent};
  if (!pd_implicit_active(im)) {
    double taken = explicit_step(model, s, hMax, explicitTrial, &out);
    // s->h is now the bound's step: on a switch the implicit method starts from the step the error control wanted
    bool held = !out.eventCut && out.wanted >= PD_IMPLICIT_HELD_RATIO * s->h;
    if (taken > 0.0 && pd_implicit_note_explicit(im, held, s->h, s->t)) {
      s->h = out.wanted;
      s->hLimit = out.wantedLimit;
    }
    return taken;
  }
  // on probation (implicit.h): the implicit step must reach PD_IMPLICIT_HELD_RATIO × the step the bound held step
  // doubling to, with room to grow (PD_IMPLICIT_PROBATION_ERROR)
  double boundStep = pd_implicit_probation_bound_step(im);
  probationLimits limits = {PD_IMPLICIT_HELD_RATIO * boundStep, PD_IMPLICIT_PROBATION_ERROR * model->settings.tol};
  bool onProbation = boundStep > 0.0;
  // a step a landing cuts below the floor (a sync time inside a sample interval: islands.c) would prove nothing: step
  // doubling takes it, from the bound's step, and the probation waits for the next
  if (onProbation && hMax < limits.floor) {
    double wanted = s->h;
    pdStepLimit wantedLimit = s->hLimit;
    s->h = boundStep;
    s->hLimit = pd_limitStability;
    double taken = explicit_step(model, s, hMax, explicitTrial, NULL);
    if (taken > 0.0 && wanted > s->h) {
      s->h = wanted;
      s->hLimit = wantedLimit;
    }
    return taken;
  }
  double taken = adaptive_step(model, s, hMax, trial_implicit, 3.0, INFINITY, onProbation ? &limits : NULL, &out);
  if (out.gaveUp) {
    // on probation and not paying: step doubling takes this step, from the bound's step it was held to
    s->h = boundStep;
    s->hLimit = pd_limitStability;
    pd_implicit_deactivate(im, true, s->t);
    return explicit_step(model, s, hMax, explicitTrial, NULL);
  }
  if (taken > 0.0) {
    if (onProbation) pd_implicit_paid(im);
    s->count.implicitSteps += 1;
    // a step an event cut (a body sliding fast at its tunnelling guard) is the step the next one will meet too:
    // the implicit trial is dear, so it grows from there rather than from what its error control wants
    if (out.eventCut && PD_IMPLICIT_GROWTH_AFTER_CUT * taken < s->h) {
      s->h = PD_IMPLICIT_GROWTH_AFTER_CUT * taken;
      s->hLimit = out.cutLimit;
    }
    // back to step doubling when its bound would allow 1/PD_IMPLICIT_HELD_RATIO of the implicit step: an implicit
    // trial costs about two explicit ones on a small system
    double worth = (out.eventCut ? fmin(out.wanted, taken) : out.wanted) / PD_IMPLICIT_HELD_RATIO;
    bool tightNeeded;
    double fraction = explicitTrial == trial_dopri ? pd_contact_set_dopri_fraction(s->contacts) : 1.0;
    if (pd_contact_set_limit_step(model, s->contacts, worth, fraction, &tightNeeded) >= worth) {
      pd_implicit_deactivate(im, false, s->t);
      s->count.stabilityTight += tightNeeded;
    }
  }
  return taken;
}

static double fixed_step(const pdModel* model, pdState* s, double hMax) {
  stepperWork w = work_of(s);
  pd_contact_set_hold_modes(s->contacts, false);  // its steps are the work-precision sweeps' reference: the law decides
  double h = fmin(model->settings.dt, hMax);
  derivative(model, s, s->t, s->y, w.k1);
  pdStopwatch watch;
  for (;;) {
    watch = pd_stopwatch_start(s->stageTimers);
    double tDerivative = derivative_seconds(s);
    rk4(model, s, &w, s->t, s->y, w.k1, h, w.trial);
    integrate_lap(s, &watch, tDerivative);
    if (!all_finite(w.trial, s->n)) {
      ++s->warnings[pd_warnNonFinite];
      s->failed = true;
      return 0.0;
    }
    double hRetry = h;
    pdEventVerdict verdict = pd_contact_events(model, s, h, w.trial, NULL, &hRetry, &watch);
    if (verdict == pd_eventAccept) break;
    if (verdict == pd_eventRestart) {
      w = work_of(s);
      derivative(model, s, s->t, s->y, w.k1);
    } else {
      h = hRetry;
    }
  }
  pd_contact_events_commit(model, s, w.trial, &watch);
  renormalise_quaternions(model, s->y);
  ++s->count.accepted;
  return h;
}

// One step of the state's stepper from state->t; `target` the next time the state must be at or presented at. The
// fixed stepper ends on it, and so does any stepper when `land`; else the error-controlled ones do not cut their
// steps for it (dense output). Returns the step taken (0 on failure).
static double one_step(const pdModel* model, pdState* s, double target, bool land) {
  if (s->stepper == pd_stepperRK4Fixed) return fixed_step(model, s, target - s->t);
  if (!s->dense) s->dense = pd_dense_create();
  pd_dense_expect(s->dense, target);
  double hMax = land ? target - s->t : INFINITY;
  switch (s->stepper) {
    case pd_stepperRK43Embedded:
      return adaptive_step(model, s, hMax, trial_embedded, 4.0, 0.5, NULL, NULL);
    case pd_stepperImplicit:
      return switching_step(model, s, hMax, trial_doubling);
    case pd_stepperImplicitDopri:
      return switching_step(model, s, hMax, trial_dopri);
    case pd_stepperDopri54:
      return adaptive_step(model, s, hMax, trial_dopri, 5.0, NAN, NULL, NULL);
    case pd_stepperRK4Adaptive:
    default:
      return adaptive_step(model, s, hMax, trial_doubling, 5.0, 1.0, NULL, NULL);
  }
}

// After a step (or at the state presented at tEnd): the caller's hook, then the state's step observer (state.h).
static void step_ended(const pdModel* model, const pdState* s, pdStepHookFcn* hook, void* hookUser) {
  if (hook) hook(model, s, hookUser);
  if (s->stepObserver) s->stepObserver(model, s, false, s->stepUser);
}

bool pd_step_until(const pdModel* model, pdState* s, double tEnd, bool landOnEnd, pdObserverFcn* observer, void* user,
                   bool observerTimed, pdStepHookFcn* hook, void* hookUser) {
  PD_ASSERT(model != NULL && s != NULL && tEnd >= s->t);
  if (s->failed) return false;
  s->stopped = false;
  // skip samples already behind us (a state advanced without an observer, then with one)
  while (pd_sample_time(model, s->nextSample) < s->t) ++s->nextSample;
  if (pd_sample_time(model, s->nextSample) == s->t) pd_observe(model, s, observer, user, observerTimed);
  if (s->stopped) return false;
  if (s->stepObserver) s->stepObserver(model, s, true, s->stepUser);
  // a state presented at the last call's end goes on from the integration's own, later, state; that step's end was
  // never shown to the hook (it lay beyond that call's end)
  if (pd_dense_resume(s) && s->t <= tEnd) step_ended(model, s, hook, hookUser);
  for (;;) {
    // the samples up to the integration's time: the last step's end itself, or presented inside that step (a stop
    // leaves the state at that sample, presented)
    for (double tSample; (tSample = pd_sample_time(model, s->nextSample)) <= s->t && tSample <= tEnd;) {
      if (tSample < s->t && observer) pd_dense_present(model, s, tSample);
      pd_observe(model, s, observer, user, observerTimed);
      if (s->stopped) return false;
      pd_dense_resume(s);
    }
    if (s->t >= tEnd) break;
    double tSample = pd_sample_time(model, s->nextSample);
    double target = fmin(tEnd, tSample);
    double taken = 0.0;
    if (s->n == 0) {
      taken = target - s->t;  // nothing moves: jump to the next sample
    } else {
      taken = one_step(model, s, target, landOnEnd && target == tEnd);
      if (s->failed) return false;
    }
    // a step cut to the target (the fixed stepper's, a landing one's, or nothing moving) lands exactly on it, so sample
    // stamps never drift; so does a step that ends within rounding short of it (a fixed dt equal to the sample
    // interval), else a ~1e-19 s sliver follows; a step that passed it (dense output) keeps its own end
    double next = s->t + taken;
    bool lands =
        next <= target && (taken >= target - s->t || target - next <= TIME_SNAP_ULPS * DBL_EPSILON * fabs(target));
    s->t = lands ? target : next;
    if (taken > 0.0 && s->t <= tEnd) step_ended(model, s, hook, hookUser);
  }
  if (s->t > tEnd) {
    pd_dense_present(model, s, tEnd);
    step_ended(model, s, hook, hookUser);
  }
  return true;
}
