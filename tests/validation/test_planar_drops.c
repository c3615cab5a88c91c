// Tests of the planar drops in the cube-toss machinery (validation/cubetoss*.c, pd_planar_drops) on synthetic
// drops, so they need no data: a drop in free flight whose record is the closed-form parabola and uniform
// turn, the bounces of a closed-form bouncing record, the noise floor's run, bad drop files, and the fit's
// held-out split (shared with the cube tosses).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pdval/cubetoss.h"

static const double kG = 9.81;

// The soft engine integrates free flight to its tolerance (1e-6, relative to the scene's scales): the
// position to well below a micrometre over 0.2 s, side lengths.
#define SOFT_FLIGHT_TOL 1e-5
// ODE and Bullet integrate by semi-implicit Euler with h = 1e-3 s: the height lags by g h t / 2 at time t
// (5e-4 m at 0.1 s, 0.008 side lengths over these flights); their turn is exact.
#define RIGID_FLIGHT_TOL 0.02
// Central differences are exact for a parabola: the post-bounce velocity to round-off, m/s.
#define BOUNCE_VELOCITY_TOL 1e-9

// ---------------------------------------------------------------- a drop in free flight, in closed form

enum { FLIGHT_SAMPLES = 40 };  // 0.156 s: the block stays above 0.2 m
static const double fx0 = -0.3, fz0 = 0.35, fth0 = 0.4, fvx = 0.6, fvz = 0.2, fvth = -7.0;

// The drops CSV of `drops` such flights (ids 1, 2, ...; each one a little faster).
static char* flight_csv(int drops) {
  size_t size = 200 + (size_t)drops * FLIGHT_SAMPLES * 160;
  char* text = malloc(size);
  assert_non_null(text);
  size_t n = (size_t)snprintf(text, size, "drop,t,x,z,th,vx,vz,vth\n");
  for (int d = 1; d <= drops; ++d)
    for (int k = 0; k < FLIGHT_SAMPLES; ++k) {
      double t = k / PD_DROP_RATE, vx = fvx + 0.1 * d;
      n += (size_t)snprintf(text + n, size - n, "%d,%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", d, t, fx0 + vx * t,
                            fz0 + fvz * t - 0.5 * kG * t * t, fth0 + fvth * t, vx, fvz - kG * t, fvth);
    }
  return text;
}

static void test_a_drop_in_free_flight_matches_its_closed_form(void** state) {
  (void)state;
  char* text = flight_csv(2);
  pdError err;
  memset(&err, 0, sizeof err);
  pdTossSet* set = pd_toss_parse_buffer("flight.csv", text, strlen(text), &err);
  free(text);
  if (!set) fail_msg("%d:%d: %s", err.line, err.col, err.message);
  assert_ptr_equal(set->experiment, &pd_planar_drops);
  assert_int_equal(set->count, 2);
  // the pose in 3-D: (x, 0, z), th a turn about −y (x towards z), ω = (0, −vth, 0)
  const pdBodyState* s0 = &set->tosses[0].samples[0];
  assert_true(s0->x.y == 0.0 && s0->v.y == 0.0 && s0->w.x == 0.0 && s0->w.z == 0.0 && s0->w.y == -fvth);
  pdMat3 r = pd_quat_to_mat3(s0->q);
  assert_true(fabs(r.m[0][0] - cos(fth0)) < 1e-15 && fabs(r.m[2][0] - sin(fth0)) < 1e-15);

  pdTossParams p = pd_toss_experiment_params(set->experiment);
  pdModel* m = pd_toss_model(&set->tosses[0], &p, &err);
  assert_non_null(m);
  const pdBody* block = &m->bodies[PD_TOSS_CUBE_BODY];
  assert_true(block->planar);
  assert_true(fabs(block->mass - PD_DROP_MASS) < 1e-12);
  // the uniform block's inertia about y, m s²/6, as the data's repository takes it
  assert_true(fabs(block->inertia.m[1][1] - PD_DROP_MASS * PD_DROP_SIDE * PD_DROP_SIDE / 6.0) < 1e-15);
  pd_model_free(m);

  static const char* const engines[] = {"soft", "ode", "bullet"};
  for (int e = 0; e < 3; ++e) {
    pdTossEngine engine = {.name = engines[e], .ref = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP}};
    pdTossResult res;
    pdTrajectory* tr = pd_toss_simulate(&set->tosses[1], &p, &engine, NULL, &res);
    if (res.status == pd_tossNotBuilt) continue;
    assert_int_equal(res.status, pd_tossOk);
    print_message("%s: end %.3g side lengths, %.3g rad; %d bounces recorded, %d run\n", engines[e], res.posErrEnd,
                  res.rotErrEnd, res.impactsRecord, res.impactsRun);
    double tol = e == 0 ? SOFT_FLIGHT_TOL : RIGID_FLIGHT_TOL;
    assert_true(res.posErrEnd < tol && res.posErrRms < tol && res.rotErrEnd < tol);
    assert_int_equal(res.impactsRecord, 0);
    assert_int_equal(res.impactsRun, 0);
    assert_true(isnan(res.impactDv[0]));
    pd_trajectory_free(tr);
  }

  // the noise floor: the record one sample late; at the end it is one sample's travel behind
  pdTossEngine noise = {.name = "noise"};
  pdTossResult res;
  pdTrajectory* tr = pd_toss_simulate(&set->tosses[0], &p, &noise, NULL, &res);
  assert_int_equal(res.status, pd_tossOk);
  const pdToss* d = &set->tosses[0];
  double step = pd_v3_norm(pd_v3_sub(d->samples[FLIGHT_SAMPLES - 1].x, d->samples[FLIGHT_SAMPLES - 2].x)) / PD_DROP_SIDE;
  assert_true(fabs(res.posErrEnd - step) < 1e-15);
  assert_true(fabs(res.rotErrEnd - fabs(fvth) / PD_DROP_RATE) < 1e-12);
  pd_trajectory_free(tr);
  pd_toss_set_free(set);
}

// ---------------------------------------------------------------- bounces of a closed-form record

// A block falling flat (th = 0) from its lowest point at h0 above the surface, bouncing with restitution e
// instantly: the lowest point's height is a chain of parabolas.
static void test_bounces_are_found_with_their_times_and_velocities(void** state) {
  (void)state;
  const double h0 = 0.15, e = 0.5, vx = 0.3;
  enum { N = 200 };
  pdBodyState* s = calloc(N, sizeof *s);
  assert_non_null(s);
  enum { BOUNCES = 40 };  // beyond the record's end
  double bounceT[BOUNCES], bounceV[BOUNCES];  // time of each bounce and the upward speed after it
  bounceT[0] = sqrt(2.0 * h0 / kG);
  bounceV[0] = e * kG * bounceT[0];
  for (int b = 1; b < BOUNCES; ++b) {
    bounceT[b] = bounceT[b - 1] + 2.0 * bounceV[b - 1] / kG;
    bounceV[b] = e * bounceV[b - 1];
  }
  for (int k = 0; k < N; ++k) {
    double t = k / PD_DROP_RATE, h, vz;
    if (t < bounceT[0]) {
      h = h0 - 0.5 * kG * t * t, vz = -kG * t;
    } else {
      int b = 0;
      while (b < BOUNCES - 1 && t >= bounceT[b + 1]) ++b;
      double u = t - bounceT[b];
      h = bounceV[b] * u - 0.5 * kG * u * u, vz = bounceV[b] - kG * u;
    }
    s[k] = (pdBodyState){.x = {vx * t, 0.0, PD_DROP_BOARD_TOP + 0.5 * PD_DROP_SIDE + h}, .q = {1, 0, 0, 0},
                         .v = {vx, 0.0, vz}};
  }
  pdTossImpact im[PD_TOSS_IMPACTS];
  int found = pd_toss_impacts(&pd_planar_drops, s, N, im);
  // the third bounce lifts the block 2.3 mm: below the lift band (6 mm), it and what follows are one contact
  double lift[3] = {bounceV[0] * bounceV[0] / (2 * kG), bounceV[1] * bounceV[1] / (2 * kG), bounceV[2] * bounceV[2] / (2 * kG)};
  print_message("bounces at %.4f %.4f %.4f s, lifting %.4f %.4f %.4f m; found %d\n", bounceT[0], bounceT[1], bounceT[2],
                lift[0], lift[1], lift[2], found);
  assert_int_equal(found, 3);
  for (int b = 0; b < found; ++b) {
    print_message("bounce %d: sample %d, t %.4f s, v after (%.6f, %.6f) m/s\n", b + 1, im[b].sample, im[b].t, im[b].v.x, im[b].v.z);
    // the lower of the two samples around the bounce (the later bounces, which never lift the block above the
    // band again, are part of the third's contact)
    assert_true(fabs(im[b].t - bounceT[b]) <= 1.0 / PD_DROP_RATE);
    double u = (im[b].sample + 2) / PD_DROP_RATE - bounceT[b];
    if ((im[b].sample + 1) / PD_DROP_RATE > bounceT[b] && b < 2) {  // samples 1..3 after it are in one flight
      assert_true(fabs(im[b].v.z - (bounceV[b] - kG * u)) < BOUNCE_VELOCITY_TOL);
      assert_true(fabs(im[b].v.x - vx) < BOUNCE_VELOCITY_TOL && fabs(im[b].w.y) < BOUNCE_VELOCITY_TOL);
    }
  }
  free(s);
}

// ---------------------------------------------------------------- bad drop files

static void test_bad_drop_files_are_refused_at_their_line_and_column(void** state) {
  (void)state;
  static const struct {
    const char* text;
    int line, col;
    const char* message;
  } cases[] = {
      {"drop,t,x,z,th,vx,vz\n", 1, 1, "header is not"},
      {"drop,t,x,z,th,vx,vz,vth\n1,0,0,0.2,0,0,0\n", 2, 1, "7 fields, expected 8"},
      {"drop,t,x,z,th,vx,vz,vth\n1,0,0,0.2,x,0,0,0\n1,0.004,0,0.2,0,0,0,0\n", 2, 11, "not a finite number"},
      {"drop,t,x,z,th,vx,vz,vth\n1,0,0,0.2,0,0,0,0\n1,0.005,0,0.2,0,0,0,0\n", 3, 3, "expected 0.004 s"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    pdError err;
    memset(&err, 0, sizeof err);
    pdTossSet* set = pd_toss_parse_buffer("bad.csv", cases[i].text, strlen(cases[i].text), &err);
    assert_null(set);
    if (err.line != cases[i].line || err.col != cases[i].col || !strstr(err.message, cases[i].message))
      fail_msg("case %zu: %d:%d: %s", i, err.line, err.col, err.message);
  }
}

// ---------------------------------------------------------------- the held-out split of a fit

static void test_the_split_trains_on_even_positions_every_kth_and_tests_on_odd(void** state) {
  (void)state;
  const int indices[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11};  // file positions of a selection
  int train[11], test[11], trainCount, testCount;
  pd_toss_fit_split(indices, 11, 1, train, &trainCount, test, &testCount);
  assert_int_equal(trainCount, 6);
  assert_int_equal(testCount, 5);
  assert_true(train[5] == 10 && test[0] == 1 && test[4] == 11);
  pd_toss_fit_split(indices, 11, 2, train, &trainCount, test, &testCount);
  assert_int_equal(trainCount, 3);  // the 1st, 3rd and 5th of 0, 2, 4, 6, 8, 10
  assert_true(train[0] == 0 && train[1] == 4 && train[2] == 8);
  assert_int_equal(testCount, 5);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_drop_in_free_flight_matches_its_closed_form),
      cmocka_unit_test(test_bounces_are_found_with_their_times_and_velocities),
      cmocka_unit_test(test_bad_drop_files_are_refused_at_their_line_and_column),
      cmocka_unit_test(test_the_split_trains_on_even_positions_every_kth_and_tests_on_odd),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
