// Free rigid-body dynamics and the integration loop: ballistic flight, torque-free rotation
// (conservation, the intermediate-axis flip, free precession of a symmetric body), exact sample
// times, step limits and evaluation counts, the fixed-step stepper, unit quaternions, determinism
// and one model driving several states. Every expected value comes from a closed form.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define WATER_DENSITY 1000.0  // kg/m³, spgrav 1

// Ballistic flight: RK4 integrates a quadratic in t exactly, so what remains is round-off of a few
// hundred steps on coordinates of order 1 m and 10 m/s (~1e-13); 1e-9 leaves room without hiding
// a wrong formula (a missing ½ or a lost step would be off by more than 1e-3).
#define PARABOLA_POSITION_TOL 1e-9  // m
#define PARABOLA_VELOCITY_TOL 1e-9  // m/s

// Torque-free rotation over 20 s at 2 rev/s (~250 rad turned): RK4 is not symplectic, so energy and
// |L| drift with the local errors. Measured worst drift over the three axes: 2e-8 at tol 1e-9, 3e-9
// at 1e-10, 5e-10 at 1e-11. tol 1e-11 keeps a 20x margin under the 1e-8 requirement and costs
// ~6000 steps (a few ms).
#define TORQUE_FREE_TOL "1e-11"
#define CONSERVATION_REL_TOL 1e-8
// Near a stable (smallest or largest) principal axis, 1° off, ω stays in a narrow cone; 10° is far
// outside what the polhode reaches and far inside the 180° of a flip.
#define STABLE_CONE_DEG 10.0

// Free precession: the rates are fitted by least squares over 2 s of samples; integration errors
// (tol 1e-11) perturb the angles by ~1e-9 rad, far below 1e-6 relative of a rate of ~7 rad/s.
#define PRECESSION_REL_TOL 1e-6

// Renormalisation after every accepted step leaves |q| = 1 up to the rounding of one division.
#define UNIT_QUATERNION_TOL 1e-12

// ---------------------------------------------------------------------------------------------
// helpers

static pdModel* compile_text(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("free.scene", text, strlen(text), &err);
  if (!scene) fprintf(stderr, "parse error: %d:%d: %s\n", err.line, err.col, err.message);
  assert_non_null(scene);
  pdModel* model = pd_model_compile(scene, &err);
  if (!model) fprintf(stderr, "compile error: %d:%d: %s\n", err.line, err.col, err.message);
  pd_scene_free(scene);
  assert_non_null(model);
  return model;
}

static pdVec3 body_frame_omega(const pdBodyState* bs) {
  pdMat3 r = pd_quat_to_mat3(bs->q);
  return pd_mat3_tmulv(&r, bs->w);
}

// World angular momentum about the centre of mass: L = R I Rᵀ ω.
static pdVec3 world_angular_momentum(const pdBody* body, const pdBodyState* bs) {
  pdMat3 r = pd_quat_to_mat3(bs->q);
  pdVec3 lb = pd_mat3_mulv(&body->inertia, pd_mat3_tmulv(&r, bs->w));
  return pd_mat3_mulv(&r, lb);
}

static double quat_norm(pdQuat q) { return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z); }

// Least-squares slope of y over t.
static double fit_slope(const double* t, const double* y, int n) {
  double mt = 0.0, my = 0.0;
  for (int i = 0; i < n; ++i) mt += t[i], my += y[i];
  mt /= n, my /= n;
  double stt = 0.0, sty = 0.0;
  for (int i = 0; i < n; ++i) stt += (t[i] - mt) * (t[i] - mt), sty += (t[i] - mt) * (y[i] - my);
  return sty / stt;
}

// Adds the multiple of 2π that keeps `angle` within π of `previous`.
static double unwrap(double previous, double angle) {
  while (angle - previous > PI) angle -= 2.0 * PI;
  while (angle - previous < -PI) angle += 2.0 * PI;
  return angle;
}

// Box of edges a, b, c (the cube primitive scaled a b c): mass and principal moments about x, y, z.
static void box_inertia(double a, double b, double c, double* mass, double moments[3]) {
  *mass = WATER_DENSITY * a * b * c;
  moments[0] = *mass * (b * b + c * c) / 12.0;
  moments[1] = *mass * (a * a + c * c) / 12.0;
  moments[2] = *mass * (a * a + b * b) / 12.0;
}

// Records every sample of a run: t and a copy of the whole state vector.
typedef struct recording {
  int n;           // state length
  int count;       // samples recorded
  int capacity;
  double* t;       // (capacity)
  double* y;       // (capacity × n)
} recording;

static recording recording_make(int n, int capacity) {
  recording r = {n, 0, capacity, calloc((size_t)capacity, sizeof(double)),
                 calloc((size_t)capacity * (size_t)(n > 0 ? n : 1), sizeof(double))};
  assert_non_null(r.t);
  assert_non_null(r.y);
  return r;
}

static void recording_free(recording* r) {
  free(r->t);
  free(r->y);
}

static bool record_observer(const pdModel* model, const pdState* state, void* user) {
  (void)model;
  recording* r = user;
  assert_true(r->count < r->capacity);
  r->t[r->count] = state->t;
  memcpy(r->y + (size_t)r->count * (size_t)r->n, state->y, (size_t)r->n * sizeof(double));
  ++r->count;
  return true;
}

static pdBodyState recorded_body(const pdModel* model, const recording* r, int sample, int bodyIndex) {
  pdState view;
  memset(&view, 0, sizeof view);
  view.n = r->n;
  view.t = r->t[sample];
  view.y = r->y + (size_t)sample * (size_t)r->n;
  return pd_state_body(model, &view, bodyIndex);
}

static recording run_recorded(const pdModel* model, pdStepper stepper, pdCounters* counters) {
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  pdState* s = pd_state_create(model, &options);
  int capacity = (int)floor(model->settings.tend * model->settings.sampleRate) + 2;
  recording r = recording_make(s->n, capacity);
  assert_true(pd_advance(model, s, model->settings.tend, record_observer, &r));
  assert_false(s->failed);
  assert_true(s->t == model->settings.tend);
  if (counters) *counters = s->count;
  pd_state_free(s);
  return r;
}

// ---------------------------------------------------------------------------------------------
// ballistic flight

static const char* const thrownBox =
    "gravity 0 0 -9.81\n"
    "tend 2\n"
    "tol 1e-8\n"
    "sample 100\n"
    "cube box red 0.1 0.2 0.3\n"
    "loc 0.5 -1 2  40 1 2 3\n"
    "vel 1.5 -0.5 4  720 1 -2 0.5\n";

typedef struct parabolaCheck {
  pdVec3 x0, v0, g;
  double maxPositionError, maxVelocityError;
  int samples;
} parabolaCheck;

static bool parabola_observer(const pdModel* model, const pdState* state, void* user) {
  parabolaCheck* c = user;
  double t = state->t;
  pdBodyState bs = pd_state_body(model, state, 0);
  pdVec3 x = pd_v3_add(pd_v3_add(c->x0, pd_v3_scale(c->v0, t)), pd_v3_scale(c->g, 0.5 * t * t));
  pdVec3 v = pd_v3_add(c->v0, pd_v3_scale(c->g, t));
  c->maxPositionError = fmax(c->maxPositionError, pd_v3_norm(pd_v3_sub(bs.x, x)));
  c->maxVelocityError = fmax(c->maxVelocityError, pd_v3_norm(pd_v3_sub(bs.v, v)));
  ++c->samples;
  return true;
}

static parabolaCheck run_parabola(const char* text, pdStepper stepper, pdCounters* counters) {
  pdModel* model = compile_text(text);
  // the scene's numbers, not the model's: the expectation must not lean on what it checks
  parabolaCheck c = {{0.5, -1, 2}, {1.5, -0.5, 4}, {0, 0, -9.81}, 0.0, 0.0, 0};
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  pdState* s = pd_state_create(model, &options);
  assert_true(pd_advance(model, s, model->settings.tend, parabola_observer, &c));
  if (counters) *counters = s->count;
  pd_state_free(s);
  pd_model_free(model);
  return c;
}

static void test_thrown_spinning_box_centre_of_mass_follows_parabola(void** state) {
  (void)state;
  pdCounters count;
  parabolaCheck c = run_parabola(thrownBox, pd_stepperRK4Adaptive, &count);
  printf("  thrown box: %d samples, %ld steps, max |x - x(t)| = %.3g m, max |v - v(t)| = %.3g m/s\n", c.samples,
         count.accepted, c.maxPositionError, c.maxVelocityError);
  assert_int_equal(c.samples, 201);
  assert_true(c.maxPositionError <= PARABOLA_POSITION_TOL);
  assert_true(c.maxVelocityError <= PARABOLA_VELOCITY_TOL);
}

static void test_fixed_step_rk4_takes_1000_steps_per_second_and_keeps_parabola(void** state) {
  (void)state;
  // with 10 steps per sample, and with one step per sample (dt equal to the sample interval)
  static const int rates[] = {100, 1000};
  for (int i = 0; i < 2; ++i) {
    char text[512];
    snprintf(text, sizeof text,
             "gravity 0 0 -9.81\n"
             "tend 1\n"
             "dt 1e-3\n"
             "sample %d\n"
             "cube box red 0.1 0.2 0.3\n"
             "loc 0.5 -1 2  40 1 2 3\n"
             "vel 1.5 -0.5 4  720 1 -2 0.5\n",
             rates[i]);
    pdCounters count;
    parabolaCheck c = run_parabola(text, pd_stepperRK4Fixed, &count);
    printf("  fixed RK4, sample %d: %ld steps, %ld derivatives, max |x - x(t)| = %.3g m, max |v - v(t)| = %.3g m/s\n",
           rates[i], count.accepted, count.derivatives, c.maxPositionError, c.maxVelocityError);
    assert_int_equal(c.samples, rates[i] + 1);
    assert_int_equal(count.accepted, 1000);
    assert_int_equal(count.rejected, 0);
    assert_int_equal(count.derivatives, 4 * count.accepted);  // classic RK4: four stages, no error estimate
    assert_true(c.maxPositionError <= PARABOLA_POSITION_TOL);
    assert_true(c.maxVelocityError <= PARABOLA_VELOCITY_TOL);
  }
}

// ---------------------------------------------------------------------------------------------
// torque-free rotation of an asymmetric box (0.1 × 0.2 × 0.3: largest moment about x,
// intermediate about y, smallest about z)

typedef struct torqueFreeCheck {
  int axis;          // the principal axis spun about (0 x, 1 y, 2 z)
  double e0;         // kinetic energy at t = 0
  pdVec3 l0;         // world angular momentum at t = 0
  double maxEnergyDrift, maxMomentumDrift;  // relative
  double maxConeDeg; // largest angle between body ω and the axis (or its opposite)
  int initialSign, signChanges, samples;
  int previousSign;
} torqueFreeCheck;

static bool torque_free_observer(const pdModel* model, const pdState* state, void* user) {
  torqueFreeCheck* c = user;
  const pdBody* body = &model->bodies[0];
  pdBodyState bs = pd_state_body(model, state, 0);
  double e = pd_body_kinetic_energy(body, bs.v, bs.w, bs.q);
  pdVec3 l = world_angular_momentum(body, &bs);
  pdVec3 wb = body_frame_omega(&bs);
  double along = pd_v3_get(wb, c->axis);
  int sign = along > 0.0 ? 1 : -1;
  if (c->samples == 0) {
    c->e0 = e, c->l0 = l, c->initialSign = c->previousSign = sign;
  }
  c->maxEnergyDrift = fmax(c->maxEnergyDrift, fabs(e - c->e0) / c->e0);
  c->maxMomentumDrift = fmax(c->maxMomentumDrift, pd_v3_norm(pd_v3_sub(l, c->l0)) / pd_v3_norm(c->l0));
  if (sign != c->previousSign) ++c->signChanges;
  c->previousSign = sign;
  double cone = acos(fmin(1.0, fabs(along) / pd_v3_norm(wb))) / DEG;
  c->maxConeDeg = fmax(c->maxConeDeg, cone);
  ++c->samples;
  return true;
}

// Spins the box at 2 rev/s about body axis `axis`, tilted 1° towards the next axis, for 20 s.
static torqueFreeCheck run_torque_free(int axis) {
  double spinAxis[3] = {0, 0, 0};
  spinAxis[axis] = cos(1.0 * DEG);
  spinAxis[(axis + 1) % 3] = sin(1.0 * DEG);
  char text[512];
  snprintf(text, sizeof text,
           "gravity 0 0 0\n"
           "tend 20\n"
           "tol " TORQUE_FREE_TOL "\n"
           "sample 100\n"
           "cube box red 0.1 0.2 0.3\n"
           "loc 0 0 0  25 0.3 -1 0.2\n"
           "vel 0 0 0  720 %.17g %.17g %.17g\n",
           spinAxis[0], spinAxis[1], spinAxis[2]);
  pdModel* model = compile_text(text);

  // the model's inertia is the closed form of a box, diagonal in the object's axes
  double mass, moments[3];
  box_inertia(0.1, 0.2, 0.3, &mass, moments);
  assert_true(fabs(model->bodies[0].mass - mass) <= 1e-12 * mass);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      assert_true(fabs(model->bodies[0].inertia.m[i][j] - (i == j ? moments[i] : 0.0)) <= 1e-12 * moments[0]);

  torqueFreeCheck c;
  memset(&c, 0, sizeof c);
  c.axis = axis;
  pdState* s = pd_state_create(model, NULL);
  assert_true(pd_advance(model, s, model->settings.tend, torque_free_observer, &c));
  printf("  axis %c: %ld steps (%ld rejected), energy drift %.3g, |L| drift %.3g, sign changes %d, cone %.3g deg\n",
         "xyz"[axis], s->count.accepted, s->count.rejected, c.maxEnergyDrift, c.maxMomentumDrift, c.signChanges,
         c.maxConeDeg);
  assert_int_equal(c.samples, 2001);
  pd_state_free(s);
  pd_model_free(model);
  return c;
}

static void test_torque_free_box_conserves_energy_and_momentum_and_stays_near_largest_axis(void** state) {
  (void)state;
  torqueFreeCheck c = run_torque_free(0);
  assert_true(c.maxEnergyDrift <= CONSERVATION_REL_TOL);
  assert_true(c.maxMomentumDrift <= CONSERVATION_REL_TOL);
  assert_int_equal(c.signChanges, 0);
  assert_true(c.maxConeDeg < STABLE_CONE_DEG);
}

static void test_torque_free_box_conserves_energy_and_momentum_and_flips_about_intermediate_axis(void** state) {
  (void)state;
  torqueFreeCheck c = run_torque_free(1);
  assert_true(c.maxEnergyDrift <= CONSERVATION_REL_TOL);
  assert_true(c.maxMomentumDrift <= CONSERVATION_REL_TOL);
  assert_true(c.signChanges >= 1);
  assert_true(c.maxConeDeg > 45.0);  // at a flip ω passes (nearly) perpendicular to the axis
}

static void test_torque_free_box_conserves_energy_and_momentum_and_stays_near_smallest_axis(void** state) {
  (void)state;
  torqueFreeCheck c = run_torque_free(2);
  assert_true(c.maxEnergyDrift <= CONSERVATION_REL_TOL);
  assert_true(c.maxMomentumDrift <= CONSERVATION_REL_TOL);
  assert_int_equal(c.signChanges, 0);
  assert_true(c.maxConeDeg < STABLE_CONE_DEG);
}

// ---------------------------------------------------------------------------------------------
// free precession of a symmetric box 0.2 × 0.2 × 0.5 (I1 = I2 about x, y; I3 about z)

static void test_symmetric_box_precesses_at_euler_and_space_rates(void** state) {
  (void)state;
  // ω in the body frame: θ = 600°/s about (0.3, 0, 1), so ω⊥ along x and ω3 along z
  const double spinDeg = 600.0, axis[3] = {0.3, 0.0, 1.0};
  double axisNorm = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  double w1 = spinDeg * DEG * axis[0] / axisNorm, w3 = spinDeg * DEG * axis[2] / axisNorm;
  double mass, moments[3];
  box_inertia(0.2, 0.2, 0.5, &mass, moments);
  double i1 = moments[0], i3 = moments[2];
  double bodyRate = (i3 - i1) / i1 * w3;                                 // Ω, rad/s
  double spaceRate = sqrt(i1 * i1 * w1 * w1 + i3 * i3 * w3 * w3) / i1;   // |L| / I1, rad/s

  static const char* const text =
      "gravity 0 0 0\n"
      "tend 2\n"
      "tol " TORQUE_FREE_TOL "\n"
      "sample 200\n"
      "cube top red 0.2 0.2 0.5\n"
      "loc 0 0 0  35 1 -0.5 0.25\n"
      "vel 0 0 0  600 0.3 0 1\n";
  pdModel* model = compile_text(text);
  const pdBody* body = &model->bodies[0];
  recording r = run_recorded(model, pd_stepperRK4Adaptive, NULL);
  assert_int_equal(r.count, 401);

  // body frame: the angle of (ω1, ω2) turns at Ω
  double* angle = calloc((size_t)r.count, sizeof(double));
  assert_non_null(angle);
  for (int k = 0; k < r.count; ++k) {
    pdBodyState bs = recorded_body(model, &r, k, 0);
    pdVec3 wb = body_frame_omega(&bs);
    double a = atan2(wb.y, wb.x);
    angle[k] = k ? unwrap(angle[k - 1], a) : a;
  }
  double bodyFit = fit_slope(r.t, angle, r.count);

  // space frame: the symmetry axis R e3 turns about the fixed L at |L| / I1
  pdBodyState first = recorded_body(model, &r, 0, 0);
  pdVec3 n = pd_v3_normalize(world_angular_momentum(body, &first));
  pdVec3 p = pd_v3_normalize(pd_v3_cross(n, fabs(n.x) < 0.9 ? pd_v3(1, 0, 0) : pd_v3(0, 1, 0)));
  pdVec3 q = pd_v3_cross(n, p);
  for (int k = 0; k < r.count; ++k) {
    pdBodyState bs = recorded_body(model, &r, k, 0);
    pdVec3 e3 = pd_quat_rotate(bs.q, pd_v3(0, 0, 1));
    double a = atan2(pd_v3_dot(e3, q), pd_v3_dot(e3, p));
    angle[k] = k ? unwrap(angle[k - 1], a) : a;
  }
  double spaceFit = fit_slope(r.t, angle, r.count);
  printf("  precession: body rate %.12g (expected %.12g, rel err %.3g), space rate %.12g (expected %.12g, rel err "
         "%.3g)\n",
         bodyFit, bodyRate, fabs(bodyFit - bodyRate) / fabs(bodyRate), spaceFit, spaceRate,
         fabs(spaceFit - spaceRate) / spaceRate);
  assert_true(fabs(bodyFit - bodyRate) <= PRECESSION_REL_TOL * fabs(bodyRate));
  assert_true(fabs(spaceFit - spaceRate) <= PRECESSION_REL_TOL * spaceRate);

  free(angle);
  recording_free(&r);
  pd_model_free(model);
}

// ---------------------------------------------------------------------------------------------
// sample times

typedef struct sampleTimes {
  double rate;
  int count;
  bool allExact;
  double lastT;
} sampleTimes;

static bool sample_time_observer(const pdModel* model, const pdState* state, void* user) {
  (void)model;
  sampleTimes* s = user;
  if (state->t != (double)s->count / s->rate) s->allExact = false;  // bit equality, on purpose
  s->lastT = state->t;
  ++s->count;
  return true;
}

static sampleTimes run_sample_times(const char* text) {
  pdModel* model = compile_text(text);
  sampleTimes st = {model->settings.sampleRate, 0, true, -1.0};
  pdState* s = pd_state_create(model, NULL);
  assert_true(pd_advance(model, s, model->settings.tend, sample_time_observer, &st));
  assert_true(s->t == model->settings.tend);
  assert_int_equal(s->count.samples, st.count);
  pd_state_free(s);
  pd_model_free(model);
  return st;
}

static void test_samples_fall_exactly_on_k_over_rate(void** state) {
  (void)state;
  sampleTimes st = run_sample_times(
      "tend 0.5\nsample 1000\n"
      "cube box red 0.1 0.2 0.3\nloc 0 0 1\nvel 1 0 2  300 1 1 0\n");
  assert_true(st.allExact);
  assert_int_equal(st.count, 501);
  assert_true(st.lastT == 0.5);

  // tend between two samples: k/7 for k = 0, 1, 2 and nothing at 0.3
  st = run_sample_times(
      "tend 0.3\nsample 7\n"
      "cube box red 0.1 0.2 0.3\nloc 0 0 1\nvel 1 0 2  300 1 1 0\n");
  assert_true(st.allExact);
  assert_int_equal(st.count, 3);
  assert_true(st.lastT == 2.0 / 7.0);
}

// ---------------------------------------------------------------------------------------------
// step limits and counts

static pdCounters run_counts_with(const char* text, pdStepper stepper) {
  pdModel* model = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  pdState* s = pd_state_create(model, &options);
  assert_true(pd_advance(model, s, model->settings.tend, NULL, NULL));
  assert_true(s->t == model->settings.tend);
  pdCounters c = s->count;
  pd_state_free(s);
  pd_model_free(model);
  return c;
}

static pdCounters run_counts(const char* text) { return run_counts_with(text, pd_stepperRK4Adaptive); }

static void test_dtmax_bounds_the_step(void** state) {
  (void)state;
  pdCounters c = run_counts(
      "tend 1\ntol 1e-3\ndtmax 1e-3\nsample 100\n"
      "cube box red 0.1 0.2 0.3\nvel 1 0 2  300 1 1 0\n");
  printf("  dtmax 1e-3: %ld accepted, %ld rejected\n", c.accepted, c.rejected);
  assert_true(c.accepted >= 1000);
}

static void test_dt_equal_to_dtmin_and_dtmax_takes_exactly_1000_steps(void** state) {
  (void)state;
  // a huge tolerance never rejects; with dt = dtmin = dtmax every step is 1 ms
  pdCounters c = run_counts(
      "tend 1\ntol 0.9\ndt 1e-3\ndtmin 1e-3\ndtmax 1e-3\nsample 100\n"
      "cube box red 0.1 0.2 0.3\nvel 1 0 2  300 1 1 0\n");
  printf("  dt = dtmin = dtmax = 1e-3: %ld accepted, %ld rejected\n", c.accepted, c.rejected);
  assert_int_equal(c.accepted, 1000);
  assert_int_equal(c.rejected, 0);

  // the same with a sample at every step
  c = run_counts(
      "tend 1\ntol 0.9\ndt 1e-3\ndtmin 1e-3\ndtmax 1e-3\nsample 1000\n"
      "cube box red 0.1 0.2 0.3\nvel 1 0 2  300 1 1 0\n");
  printf("  ... with sample 1000: %ld accepted, %ld rejected\n", c.accepted, c.rejected);
  assert_int_equal(c.accepted, 1000);
  assert_int_equal(c.rejected, 0);
}

// A thrown, spinning box at tol 1e-10 from a first step of 0.01 s (far too long: some trials are rejected): every
// accepted step costs `perAccepted` derivative evaluations and every rejected trial `perRejected`.
static void check_evaluations_per_step(pdStepper stepper, long perAccepted, long perRejected) {
  pdCounters c = run_counts_with(
      "gravity 0 0 -9.81\ntend 1\ntol 1e-10\ndt 0.01\nsample 100\n"
      "cube box red 0.1 0.2 0.3\nvel 1 0 2  720 1 3 0.2\n",
      stepper);
  printf("  %s counts: %ld accepted, %ld rejected, %ld derivatives\n", pd_stepper_name(stepper), c.accepted,
         c.rejected, c.derivatives);
  assert_true(c.rejected > 0);
  assert_int_equal(c.derivatives, perAccepted * c.accepted + perRejected * c.rejected);
}

static void test_adaptive_step_costs_11_evaluations_and_a_rejection_10(void** state) {
  (void)state;
  // integrator.c: k1 is evaluated once per accepted step and reused by every trial from that point;
  // a trial is a full step (3 more), two half steps (3 + 1 + 3): 10 evaluations
  check_evaluations_per_step(pd_stepperRK4Adaptive, 11, 10);
}

static void test_embedded_step_costs_5_evaluations_and_a_rejection_4(void** state) {
  (void)state;
  // integrator.c: k1 once per accepted step; a trial is the RK4 step (3 more) and f(t + h, y1) for the
  // error estimate: 4 evaluations
  check_evaluations_per_step(pd_stepperRK43Embedded, 5, 4);
}

static void test_embedded_pair_keeps_the_parabola_and_steps_as_tol_to_the_quarter(void** state) {
  (void)state;
  pdCounters count;
  parabolaCheck c = run_parabola(thrownBox, pd_stepperRK43Embedded, &count);
  printf("  thrown box, embedded RK4(3): %d samples, %ld steps, max |x - x(t)| = %.3g m, max |v - v(t)| = %.3g m/s\n",
         c.samples, count.accepted, c.maxPositionError, c.maxVelocityError);
  assert_int_equal(c.samples, 201);
  assert_true(c.maxPositionError <= PARABOLA_POSITION_TOL);
  assert_true(c.maxVelocityError <= PARABOLA_VELOCITY_TOL);
  // the error estimate is the third-order partner's, O(h⁴): ten times tighter a tolerance takes 10^(1/4) ≈ 1.78×
  // the steps (step doubling's O(h⁵) estimate: 10^(1/5) ≈ 1.58×; a second-order estimate: 10^(1/3) ≈ 2.15×)
  static const char* const spin =
      "gravity 0 0 0\ntend 1\nsample 10\ncube box red 0.1 0.2 0.3\nvel 0 0 0  720 1 3 0.2\n";
  char text[256];
  long steps[2];
  for (int i = 0; i < 2; ++i) {
    snprintf(text, sizeof text, "tol %g\n%s", i == 0 ? 1e-7 : 1e-8, spin);
    steps[i] = run_counts_with(text, pd_stepperRK43Embedded).accepted;
  }
  double ratio = (double)steps[1] / (double)steps[0];
  printf("  spinning box: %ld steps at tol 1e-7, %ld at 1e-8 (ratio %.2f, 10^(1/4) = 1.78)\n", steps[0], steps[1],
         ratio);
  assert_true(ratio > 1.68 && ratio < 1.9);
}

static void test_dopri_step_costs_7_evaluations_and_a_rejection_6(void** state) {
  (void)state;
  // integrator.c, trial_dopri: k1 once per accepted step; a trial is 6 more stages, the last f(t + h, y1), which the
  // next step cannot reuse (its commit realigns the springs)
  check_evaluations_per_step(pd_stepperDopri54, 7, 6);
}

// A box spinning about no principal axis (Euler's equations, torque-free: smooth, no contacts), run with the
// Dormand–Prince pair at fixed steps (dtmin = dtmax, tol 0.9 loose enough to accept every step) of 10 and 5 ms (ωh
// 0.13 and 0.06) and compared at t = 1 s with a run at tol 1e-13: the kept result is of fifth order, so halving the
// step divides the global error by 2⁵ = 32 (a fourth-order result kept: 16; sixth: 64). The estimated order
// log₂(e_h/e_h/2) within 4.5 … 5.6 (at 20 and 10 ms, not yet asymptotic, it is 5.8).
#define DOPRI_ORDER_MIN 4.5
#define DOPRI_ORDER_MAX 5.6

static const char* const spinningBox = "gravity 0 0 0\ntend 1\nsample 10\ncube box red 0.1 0.2 0.3\nvel 0 0 0  720 1 3 0.2\n";

static pdBodyState spin_run(const char* settings, long* steps) {
  char text[512];
  snprintf(text, sizeof text, "%s%s", settings, spinningBox);
  pdModel* m = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.stepper = pd_stepperDopri54;
  pdState* s = pd_state_create(m, &options);
  assert_true(pd_advance(m, s, m->settings.tend, NULL, NULL));
  pdBodyState b = pd_state_body(m, s, 0);
  *steps = s->count.accepted;
  pd_state_free(s);
  pd_model_free(m);
  return b;
}

static void test_dopri_converges_at_fifth_order(void** state) {
  (void)state;
  long refSteps, steps[2];
  pdBodyState ref = spin_run("tol 1e-13\ndtmax 1\n", &refSteps);
  static const char* const fixedSteps[2] = {"tol 0.9\ndt 0.01\ndtmin 0.01\ndtmax 0.01\n",
                                            "tol 0.9\ndt 0.005\ndtmin 0.005\ndtmax 0.005\n"};
  double err[2];
  for (int i = 0; i < 2; ++i) {
    pdBodyState b = spin_run(fixedSteps[i], &steps[i]);
    double dq = fabs(b.q.w - ref.q.w) + fabs(b.q.x - ref.q.x) + fabs(b.q.y - ref.q.y) + fabs(b.q.z - ref.q.z);
    err[i] = fmax(pd_v3_norm(pd_v3_sub(b.w, ref.w)) / pd_v3_norm(ref.w), dq);
  }
  double order = log2(err[0] / err[1]);
  printf("  spinning box, dopri54: h 0.01 s (%ld steps) error %.3g, h 0.005 s (%ld steps) error %.3g: order %.2f "
         "(reference %ld steps)\n",
         steps[0], err[0], steps[1], err[1], order, refSteps);
  assert_int_equal(steps[0], 100);
  assert_int_equal(steps[1], 200);
  assert_true(order >= DOPRI_ORDER_MIN && order <= DOPRI_ORDER_MAX);
}

// ---------------------------------------------------------------------------------------------
// quaternions, determinism, several states

static void test_quaternion_stays_unit_at_every_sample(void** state) {
  (void)state;
  pdModel* model = compile_text(
      "gravity 0 0 -9.81\ntend 5\ntol 1e-4\nsample 1000\n"
      "cube box red 0.1 0.2 0.3\nloc 0 0 0  70 1 1 1\nvel 0 0 0  1500 0.1 1 0.3\n"
      "sphere ball green 1 0.2 0.2 0.2\nloc 1 0 0\nvel 0 0 0  -900 1 0 0\n");
  static const pdStepper steppers[] = {pd_stepperRK4Adaptive, pd_stepperRK4Fixed, pd_stepperRK43Embedded};
  for (int stepper = 0; stepper < 3; ++stepper) {
    recording r = run_recorded(model, steppers[stepper], NULL);
    double worst = 0.0;
    for (int k = 0; k < r.count; ++k)
      for (int b = 0; b < model->bodyCount; ++b) {
        pdBodyState bs = recorded_body(model, &r, k, b);
        worst = fmax(worst, fabs(quat_norm(bs.q) - 1.0));
      }
    printf("  %s: max ||q| - 1| = %.3g over %d samples\n", pd_stepper_name(steppers[stepper]), worst, r.count);
    assert_true(worst <= UNIT_QUATERNION_TOL);
    recording_free(&r);
  }
  pd_model_free(model);
}

static const char* const twoBodies =
    "gravity 0 0 -9.81\ntend 1\ntol 1e-7\nsample 100\n"
    "cube box red 0.1 0.2 0.3\nloc 0 0 1  30 1 0 0\nvel 1 0 2  720 0.2 1 0.1\n"
    "tprism cone blue 8 0.3 0.3 0.3 0.5\nloc 1 0 1\nvel 0 1 3  90 0 0 1\n";

// ---------------------------------------------------------------------------------------------
// applied force (scene `force`)

// A constant force at the centre of mass in zero gravity: x(t) = x0 + F t²/(2m); with a ramp Ḟ added,
// + Ḟ t³/(6m). RK4 integrates polynomials of degree <= 4 in t exactly, so only round-off of a few hundred
// steps on values of order 1 remains (~1e-13); 1e-9 m would still catch a factor 2 or a force evaluated at
// the step's start instead of the stage time (an error h·Ḟ t/(2m) ~ 1e-4 m at dtmax 1e-2 s).
#define APPLIED_POSITION_TOL 1e-9  // m
#define APPLIED_VELOCITY_TOL 1e-9  // m/s

static void check_pushed_free_box(const char* scene, pdVec3 f0, pdVec3 rate) {
  pdModel* model = compile_text(scene);
  const pdBody* b = &model->bodies[0];
  assert_true(b->hasForce);
  pdState* s = pd_state_create(model, NULL);
  assert_true(pd_advance(model, s, model->settings.tend, NULL, NULL));
  double t = s->t, m = b->mass;
  pdBodyState bs = pd_state_body(model, s, 0);
  pdVec3 x = pd_v3_add(pd_v3_add(b->x0, pd_v3_scale(f0, t * t / (2.0 * m))), pd_v3_scale(rate, t * t * t / (6.0 * m)));
  pdVec3 v = pd_v3_add(pd_v3_scale(f0, t / m), pd_v3_scale(rate, t * t / (2.0 * m)));
  assert_true(t == 2.0);  // pd_advance lands exactly on tend
  assert_true(pd_v3_norm(pd_v3_sub(bs.x, x)) < APPLIED_POSITION_TOL);
  assert_true(pd_v3_norm(pd_v3_sub(bs.v, v)) < APPLIED_VELOCITY_TOL);
  assert_true(pd_v3_norm(bs.w) == 0.0);  // a force through the centre of mass exerts no torque
  pd_state_free(s);
  pd_model_free(model);
}

static void test_constant_force_at_centre_of_mass_gives_x_equal_f_t2_over_2m(void** state) {
  (void)state;
  // 0.2 × 0.1 × 0.1 m of water: 2 kg; 3 N gives x(2 s) = 3 m
  check_pushed_free_box("gravity 0 0 0\ntend 2\ncube b red 0.2 0.1 0.1\nloc 1 2 3\nforce 3 -1 0.5\n",
                        pd_v3(3, -1, 0.5), pd_v3(0, 0, 0));
}

static void test_ramp_force_gives_x_equal_rate_t3_over_6m(void** state) {
  (void)state;
  check_pushed_free_box("gravity 0 0 0\ntend 2\ncube b red 0.2 0.1 0.1\nforce 1 0 0 ramp 0.5 2 -1\n",
                        pd_v3(1, 0, 0), pd_v3(0.5, 2, -1));
}

// At t = 0 the derivative is exact arithmetic on the model: ω̇ = I⁻¹ (R p × F) (ω = 0, no gyroscopic term)
// and a = F/m, to the rounding of a 3×3 product (~1e-15 relative).
#define DERIVATIVE_REL_TOL 1e-12

static void test_force_at_an_offset_point_gives_angular_acceleration_inverse_inertia_p_cross_f(void** state) {
  (void)state;
  // turned 30° about z, so the body-frame point turns with the body; F(t) = (2, 1, −1) + t (0, 3, 0) N
  pdModel* model = compile_text("gravity 0 0 0\ncube b red 0.3 0.2 0.1\nloc 0 0 0 30 0 0 1\n"
                                "force 2 1 -1 ramp 0 3 0 at 0.15 -0.1 0.05\n");
  const pdBody* b = &model->bodies[0];
  pdState* s = pd_state_create(model, NULL);
  double* dydt = calloc((size_t)s->n, sizeof *dydt);
  assert_non_null(dydt);
  const double times[] = {0.0, 0.5};
  for (int i = 0; i < 2; ++i) {
    double t = times[i];
    pd_state_derivative(model, s, t, s->y, dydt);
    pdVec3 f = pd_v3_add(pd_v3(2, 1, -1), pd_v3_scale(pd_v3(0, 3, 0), t));
    pdMat3 r = pd_quat_to_mat3(b->q0);
    pdVec3 torqueBody = pd_mat3_tmulv(&r, pd_v3_cross(pd_mat3_mulv(&r, pd_v3(0.15, -0.1, 0.05)), f));
    pdVec3 alpha = pd_mat3_mulv(&r, pd_mat3_mulv(&b->invInertia, torqueBody));
    pdVec3 a = pd_v3_scale(f, 1.0 / b->mass);
    // layout per body: v̇ (3), ω̇ (3), ẋ (3), q̇ (4) (polydyn/state.h)
    pdVec3 gotA = pd_v3(dydt[0], dydt[1], dydt[2]), gotAlpha = pd_v3(dydt[3], dydt[4], dydt[5]);
    assert_true(pd_v3_norm(pd_v3_sub(gotA, a)) <= DERIVATIVE_REL_TOL * pd_v3_norm(a));
    assert_true(pd_v3_norm(pd_v3_sub(gotAlpha, alpha)) <= DERIVATIVE_REL_TOL * pd_v3_norm(alpha));
    assert_true(pd_v3_norm(alpha) > 1.0);  // not a vacuous comparison: the offset point gives a real torque
  }
  free(dydt);
  pd_state_free(s);
  pd_model_free(model);
}

static void test_two_runs_of_one_scene_are_bit_identical(void** state) {
  (void)state;
  pdModel* m1 = compile_text(twoBodies);
  pdModel* m2 = compile_text(twoBodies);
  pdCounters c1, c2;
  recording r1 = run_recorded(m1, pd_stepperRK4Adaptive, &c1);
  recording r2 = run_recorded(m2, pd_stepperRK4Adaptive, &c2);
  assert_int_equal(r1.count, 101);
  assert_int_equal(r1.count, r2.count);
  assert_memory_equal(r1.t, r2.t, (size_t)r1.count * sizeof(double));
  assert_memory_equal(r1.y, r2.y, (size_t)r1.count * (size_t)r1.n * sizeof(double));
  assert_int_equal(c1.accepted, c2.accepted);
  assert_int_equal(c1.rejected, c2.rejected);
  assert_int_equal(c1.derivatives, c2.derivatives);
  recording_free(&r1);
  recording_free(&r2);
  pd_model_free(m1);
  pd_model_free(m2);
}

static void test_one_model_drives_two_interleaved_states_like_one_alone(void** state) {
  (void)state;
  pdModel* model = compile_text(twoBodies);
  pdCounters aloneCount;
  recording alone = run_recorded(model, pd_stepperRK4Adaptive, &aloneCount);

  // two states advanced in turns, in chunks ending on sample times (0.1 s, then 0.05 s steps)
  pdState* a = pd_state_create(model, NULL);
  pdState* b = pd_state_create(model, NULL);
  int capacity = alone.count + 1;
  recording ra = recording_make(a->n, capacity), rb = recording_make(b->n, capacity);
  static const double ends[] = {0.1, 0.15, 0.2, 0.5, 0.55, 0.6, 0.8, 1.0};
  for (size_t i = 0; i < sizeof ends / sizeof ends[0]; ++i) {
    assert_true(pd_advance(model, a, ends[i], record_observer, &ra));
    assert_true(pd_advance(model, b, ends[i], record_observer, &rb));
  }
  assert_int_equal(ra.count, alone.count);
  assert_int_equal(rb.count, alone.count);
  size_t bytes = (size_t)alone.count * (size_t)alone.n * sizeof(double);
  assert_memory_equal(ra.t, alone.t, (size_t)alone.count * sizeof(double));
  assert_memory_equal(ra.y, alone.y, bytes);
  assert_memory_equal(rb.y, alone.y, bytes);
  assert_int_equal(a->count.accepted, aloneCount.accepted);
  assert_int_equal(b->count.derivatives, aloneCount.derivatives);

  recording_free(&ra);
  recording_free(&rb);
  recording_free(&alone);
  pd_state_free(a);
  pd_state_free(b);
  pd_model_free(model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_thrown_spinning_box_centre_of_mass_follows_parabola),
      cmocka_unit_test(test_fixed_step_rk4_takes_1000_steps_per_second_and_keeps_parabola),
      cmocka_unit_test(test_torque_free_box_conserves_energy_and_momentum_and_stays_near_largest_axis),
      cmocka_unit_test(test_torque_free_box_conserves_energy_and_momentum_and_flips_about_intermediate_axis),
      cmocka_unit_test(test_torque_free_box_conserves_energy_and_momentum_and_stays_near_smallest_axis),
      cmocka_unit_test(test_symmetric_box_precesses_at_euler_and_space_rates),
      cmocka_unit_test(test_samples_fall_exactly_on_k_over_rate),
      cmocka_unit_test(test_dtmax_bounds_the_step),
      cmocka_unit_test(test_dt_equal_to_dtmin_and_dtmax_takes_exactly_1000_steps),
      cmocka_unit_test(test_adaptive_step_costs_11_evaluations_and_a_rejection_10),
      cmocka_unit_test(test_embedded_step_costs_5_evaluations_and_a_rejection_4),
      cmocka_unit_test(test_embedded_pair_keeps_the_parabola_and_steps_as_tol_to_the_quarter),
      cmocka_unit_test(test_dopri_step_costs_7_evaluations_and_a_rejection_6),
      cmocka_unit_test(test_dopri_converges_at_fifth_order),
      cmocka_unit_test(test_quaternion_stays_unit_at_every_sample),
      cmocka_unit_test(test_constant_force_at_centre_of_mass_gives_x_equal_f_t2_over_2m),
      cmocka_unit_test(test_ramp_force_gives_x_equal_rate_t3_over_6m),
      cmocka_unit_test(test_force_at_an_offset_point_gives_angular_acceleration_inverse_inertia_p_cross_f),
      cmocka_unit_test(test_two_runs_of_one_scene_are_bit_identical),
      cmocka_unit_test(test_one_model_drives_two_interleaved_states_like_one_alone),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
