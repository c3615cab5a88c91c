// Tests of the comparison metrics (refcheck/compare.c): each metric on a trajectory whose answer is known
// in closed form, and the soft engine's own bounce measured by the apex method; the first divergence, the
// chaos verdict, impacts and their matching (refcheck/compare_detail.c) on trajectories built to have them.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pdref/compare.h"
#include "pdref/compare_detail.h"
#include "polydyn/scene.h"

static pdModel* compile_text(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("compare.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %d:%d: %s", err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) fail_msg("compile: %d:%d: %s", err.line, err.col, err.message);
  return model;
}

// One free cube of side 0.2 (size 0.2 m), no floor.
static const char* const freeCube =
    "tend 1\nsample 100\ncube c red 0.2 0.2 0.2\nloc 0 0 1\n";

// Appends a sample of the one moving body.
static void push(pdTrajectory* tr, double t, pdBodyState b) {
  if (tr->samples == tr->capacity) {
    tr->capacity = tr->capacity ? 2 * tr->capacity : 64;
    tr->t = realloc(tr->t, (size_t)tr->capacity * sizeof *tr->t);
    tr->bodies = realloc(tr->bodies, (size_t)tr->capacity * sizeof *tr->bodies);
    assert_non_null(tr->t);
    assert_non_null(tr->bodies);
  }
  tr->t[tr->samples] = t;
  tr->bodies[tr->samples++] = b;
}

// Ballistic flight from z0 with vz0 under g = 9.81 down: exact samples.
static pdBodyState flight(double z0, double vz0, double t, double angle) {
  const double g = 9.81;
  return (pdBodyState){{0, 0, z0 + vz0 * t - 0.5 * g * t * t},
                       pd_quat_from_axis_angle(pd_v3(0, 0, 1), angle),
                       {0, 0, vz0 - g * t},
                       {0, 0, 0}};
}

static void test_identical_runs_have_zero_error_and_free_flight_conserves_energy(void** state) {
  (void)state;
  pdModel* model = compile_text(freeCube);
  pdTrajectory *run = pd_trajectory_create(model), *ref = pd_trajectory_create(model);
  for (int k = 0; k <= 100; ++k) {
    push(run, 0.01 * k, flight(1.0, 2.0, 0.01 * k, 0.0));
    push(ref, 0.01 * k, flight(1.0, 2.0, 0.01 * k, 0.0));
  }
  pdCompareMetrics m = pd_compare_metrics(model, run, ref);
  assert_true(m.posErrFinal == 0.0 && m.posErrRms == 0.0 && m.rotErrFinal == 0.0 && m.rotErrRms == 0.0);
  // exact parabola: kinetic + potential constant to rounding (1e-12 of the energy scale)
  assert_true(fabs(m.energyDriftRel) < 1e-12);
  // no fixed body: momentum changes by exactly the gravity impulse
  assert_true(isfinite(m.momentumDriftRel) && m.momentumDriftRel < 1e-12);
  assert_int_equal(m.impacts, 0);
  pd_trajectory_free(run);
  pd_trajectory_free(ref);
  pd_model_free(model);
}

static void test_offset_and_turned_run_has_the_known_pose_errors(void** state) {
  (void)state;
  pdModel* model = compile_text(freeCube);
  pdTrajectory *run = pd_trajectory_create(model), *ref = pd_trajectory_create(model);
  // the run is 0.01 m higher (0.05 of the 0.2 m size) and turned 0.3 rad about z at every sample
  for (int k = 0; k <= 100; ++k) {
    pdBodyState b = flight(1.01, 0.0, 0.01 * k, 0.3);
    push(run, 0.01 * k, b);
    push(ref, 0.01 * k, flight(1.0, 0.0, 0.01 * k, 0.0));
  }
  pdCompareMetrics m = pd_compare_metrics(model, run, ref);
  assert_true(fabs(m.posErrFinal - 0.05) < 1e-12 && fabs(m.posErrRms - 0.05) < 1e-12);
  assert_true(fabs(m.rotErrFinal - 0.3) < 1e-12 && fabs(m.rotErrRms - 0.3) < 1e-12);
  pd_trajectory_free(run);
  pd_trajectory_free(ref);
  pd_model_free(model);
}

static void test_reference_sampled_elsewhere_is_interpolated(void** state) {
  (void)state;
  pdModel* model = compile_text(freeCube);
  pdTrajectory *run = pd_trajectory_create(model), *ref = pd_trajectory_create(model);
  // uniform motion and rotation: linear x and slerp q are exact between the reference's samples
  for (int k = 0; k <= 10; ++k) {
    double t = 0.1 * k;
    push(ref, t, (pdBodyState){{t, 0, 1}, pd_quat_from_axis_angle(pd_v3(0, 0, 1), 2.0 * t), {1, 0, 0}, {0, 0, 2}});
  }
  for (int k = 0; k <= 100; ++k) {
    double t = 0.01 * k;
    push(run, t, (pdBodyState){{t, 0, 1}, pd_quat_from_axis_angle(pd_v3(0, 0, 1), 2.0 * t), {1, 0, 0}, {0, 0, 2}});
  }
  pdCompareMetrics m = pd_compare_metrics(model, run, ref);
  assert_true(m.posErrRms < 1e-14 && m.rotErrRms < 1e-7);
  pd_trajectory_free(run);
  pd_trajectory_free(ref);
  pd_model_free(model);
}

// A synthetic bounce: fall from 1 m above the contact height, leave with e times the impact speed.
static void test_bounce_restitution_from_apex_heights(void** state) {
  (void)state;
  pdModel* model = compile_text(freeCube);
  pdTrajectory* run = pd_trajectory_create(model);
  const double g = 9.81, e = 0.6, contact = 0.1, drop = 1.0;
  double tImpact = sqrt(2 * drop / g), vIn = g * tImpact;
  for (int k = 0; k <= 150; ++k) {
    double t = 0.01 * k;
    if (t <= tImpact) push(run, t, flight(contact + drop, 0.0, t, 0.0));
    else push(run, t, flight(contact, e * vIn, t - tImpact, 0.0));
  }
  pdCompareMetrics m = pd_compare_metrics(model, run, NULL);
  assert_int_equal(m.impacts, 1);
  // the apex after is sampled at 100 Hz (≤ g·dt²/8 = 1.2e-4 m low) and the contact height up to ~v·dt
  // too high: e within 0.02
  print_message("apex method: e = %.4f (exact %.2f)\n", m.restitution[0], e);
  assert_true(fabs(m.restitution[0] - e) < 0.02);
  assert_true(isnan(m.posErrFinal));
  pd_trajectory_free(run);
  pd_model_free(model);
}

static bool observe(const pdModel* model, const pdState* state, void* user) {
  return pd_trajectory_observe(model, state, user);
}

// The soft engine's cube dropped flat from 0.5 m on a floor, e = 0.5 requested: the apex method sees a
// bounce, and a cube landing flat on four corners bounces less than one contact would (catalogue A2):
// e below the requested 0.5, and above 0.
static void test_soft_cube_bounce_is_found_and_below_the_single_contact_value(void** state) {
  (void)state;
  pdModel* model = compile_text(
      "tend 1\nsample 400\ntol 1e-8\n"
      "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nrestitution 0.5\n"
      "cube c red 0.2 0.2 0.2\nloc 0 0 0.6\nrestitution 0.5\n");
  pdState* st = pd_state_create(model, NULL);
  pdTrajectory* run = pd_trajectory_create(model);
  assert_true(pd_advance(model, st, model->settings.tend, observe, run));
  pdCompareMetrics m = pd_compare_metrics(model, run, NULL);
  assert_true(m.impacts >= 1);
  print_message("soft cube on 4 corners: e = %.4f, deepest penetration %.3g of the size\n", m.restitution[0],
                m.maxPenetrationOverSize);
  assert_true(m.restitution[0] > 0.05 && m.restitution[0] < 0.5);
  assert_true(isnan(m.momentumDriftRel));  // a fixed floor takes momentum
  assert_true(m.maxPenetrationOverSize > 0.0 && m.maxPenetrationOverSize < 0.05);
  assert_true(m.energyDriftRel < 0.0);
  pd_trajectory_free(run);
  pd_state_free(st);
  pd_model_free(model);
}

// A run that drifts 0.009 m (0.045 of the size) per 0.1 s from the reference: past 0.1 of the size after 0.222 s.
static void test_first_divergence_and_chaos(void** state) {
  (void)state;
  pdModel* model = compile_text(freeCube);
  pdTrajectory *run = pd_trajectory_create(model), *ref = pd_trajectory_create(model);
  pdTrajectory *calm = pd_trajectory_create(model), *wild = pd_trajectory_create(model);
  for (int k = 0; k <= 100; ++k) {
    double t = 0.01 * k;
    push(ref, t, flight(1.0, 0.0, t, 0.0));
    push(run, t, flight(1.0 + 0.09 * t, 0.0, t, 0.0));
    push(calm, t, flight(1.0 + 1e-9 * t, 0.0, t, 0.0));  // the scene's own divergence: tiny
    push(wild, t, flight(1.0 + 0.5 * t, 0.0, t, 0.0));   // 5.6 times the run's: chaos explains the run
  }
  pdDivergence d = pd_compare_divergence(model, run, ref, calm, PD_COMPARE_DIVERGENCE_THRESHOLD);
  // first sample with 0.09 t / 0.2 > 0.1: t = 0.23, error 0.1035
  assert_true(d.diverged && fabs(d.t - 0.23) < 1e-9 && d.body == 0 && !d.rotation);
  assert_true(fabs(d.error - 0.1035) < 1e-9);
  assert_true(fabs(d.beyondChaos - 0.23) < 1e-9);  // the chaos run is 1e-8 of it: beyond at once
  d = pd_compare_divergence(model, run, ref, wild, PD_COMPARE_DIVERGENCE_THRESHOLD);
  assert_true(d.diverged && fabs(d.t - 0.23) < 1e-9 && isnan(d.beyondChaos));  // never 10x the chaos run
  d = pd_compare_divergence(model, calm, ref, NULL, PD_COMPARE_DIVERGENCE_THRESHOLD);
  assert_false(d.diverged);
  pd_trajectory_free(run);
  pd_trajectory_free(ref);
  pd_trajectory_free(calm);
  pd_trajectory_free(wild);
  pd_model_free(model);
}

// Impacts of the same bodies are matched nearest first within the window, each reference impact once.
static void test_impacts_matched_nearest_first(void** state) {
  (void)state;
  pdImpact ref[3] = {{.t = 0.30, .bodyA = 0, .bodyB = 1}, {.t = 0.34, .bodyA = 0, .bodyB = 1}, {.t = 0.50, .bodyA = 1, .bodyB = 2}};
  pdImpact run[4] = {{.t = 0.33, .bodyA = 0, .bodyB = 1},   // nearer 0.34 (0.01) than 0.30 (0.03)
                     {.t = 0.31, .bodyA = 0, .bodyB = 1},   // then 0.30
                     {.t = 0.50, .bodyA = 0, .bodyB = 2},   // other bodies: none
                     {.t = 0.56, .bodyA = 1, .bodyB = 2}};  // 0.06 s away: outside the window
  pd_compare_match_impacts(run, 4, ref, 3);
  assert_int_equal(run[0].match, 1);
  assert_int_equal(run[1].match, 0);
  assert_int_equal(run[2].match, -1);
  assert_int_equal(run[3].match, -1);
}

// A cube dropped 0.2 m onto a floor leaving with half its speed between two samples: one impact with the floor,
// the contact speed sqrt(2 g h) and e = 0.5, wherever in the interval the contact falls.
static void test_impact_found_from_samples(void** state) {
  (void)state;
  pdModel* model = compile_text("tend 1\nsample 100\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\n"
                                "cube c red 0.2 0.2 0.2\nloc 0 0 0.3\n");
  pdTrajectory* run = pd_trajectory_create(model);
  const double g = 9.81, h = 0.2, tc = sqrt(2.0 * h / g), vc = sqrt(2.0 * g * h);  // contact at z = 0.1
  for (int k = 0; k <= 40; ++k) {
    double t = 0.01 * k;
    if (t <= tc) push(run, t, flight(0.3, 0.0, t, 0.0));
    else push(run, t, flight(0.1, 0.5 * vc, t - tc, 0.0));  // an instant bounce with e = 0.5
  }
  pdImpact* impacts = NULL;
  int n = pd_compare_impacts(model, run, &impacts);
  assert_int_equal(n, 1);
  assert_int_equal(impacts[0].bodyA, 0);  // the floor, scene order
  assert_int_equal(impacts[0].bodyB, 1);
  // relative speed of the floor to the cube along the normal into the floor: approaching at vc, leaving at vc/2
  assert_true(fabs(impacts[0].vnBefore + vc) < 1e-9 && fabs(impacts[0].vnAfter - 0.5 * vc) < 1e-9);
  assert_true(fabs(impacts[0].restitution - 0.5) < 1e-9 && fabs(impacts[0].t - tc) < 1e-9);
  assert_true(impacts[0].tangentialChange < 1e-12);
  free(impacts);
  pd_trajectory_free(run);
  pd_model_free(model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_identical_runs_have_zero_error_and_free_flight_conserves_energy),
      cmocka_unit_test(test_offset_and_turned_run_has_the_known_pose_errors),
      cmocka_unit_test(test_reference_sampled_elsewhere_is_interpolated),
      cmocka_unit_test(test_bounce_restitution_from_apex_heights),
      cmocka_unit_test(test_soft_cube_bounce_is_found_and_below_the_single_contact_value),
      cmocka_unit_test(test_first_divergence_and_chaos),
      cmocka_unit_test(test_impacts_matched_nearest_first),
      cmocka_unit_test(test_impact_found_from_samples),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
