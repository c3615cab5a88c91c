// Contact onsets (docs/contact-model.md): a contact that began inside a step either
// cuts the whole step back to its onset (pd_onsetsExact) or, when it began within 1/ω of the step's end
// and is still shallow, joins there with the motion its pair alone would have had since the onset
// (pd_onsetsPair, selectable). The pair mode must give the same closed forms as the exact one:
// - restitution of a cube landing face-first, at 24 heights (so that the onset falls anywhere in a step),
//   within 0.01 of the requested e in both modes;
// - the rest height of a cube dropped onto a floor: half its size less its static deflection m g/(4 k_s),
//   within 0.05 δ_max (a pair onset's rest point sits ~d (ωτ)²/6 ≤ 0.042 δ_max deeper while it lasts)
//   in the pair mode and 0.01 δ_max in the exact one (both measured 5.5e-3 δ_max: the cube bounces
//   and re-lands a few times, each landing located to 1e-3 δ_max), from 24 heights 2.8 mm apart: since the samples
//   stopped cutting the steps, 2 of them land with pair onsets (8 in all; 9.1e-3 and 8.2e-3 δ_max);
// - a column of boxes dropped onto a floor: no energy gained at any sample, and fewer onset retries than
//   the exact mode (the point of the pair mode), summed over three such columns (their bounces are chaotic).
// - auto (the default): exact onsets in a system of at most PD_ONSETS_CROWD_BODIES moving bodies, pair onsets in
//   a larger one, bit for bit (islands off), and pair onsets inside an island of more (islands on), no energy
//   gained.
// Every case asserts first that pair onsets did happen, so the test cannot pass on the exact path alone.
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
#include "polydyn/vecmath.h"
#include "scene_run.h"

#define RESTITUTION_TOL 0.01       // absolute, on e: a hundredth of the range of e
#define REST_PAIR_TOL_DELTA 0.05   // of δ_max: a pair onset's rest-point shift (contact_set.c) with margin
#define REST_EXACT_TOL_DELTA 0.01  // of δ_max: several landings, each located to the onset tolerance 1e-3 δ_max
#define ENERGY_GAIN_TOL 1e-9       // relative to |E(0)|: integration error only, no energy from the onsets
#define DROPS 24

// bounce_at's cube, m: distances are measured in its size.
#define BOUNCE_SIZE 0.2
// How much closer to the converged run each factor 100 of tol must bring the bounce: RK4's local error falls with
// tol, so its distance should too; measured 17–37, 5 leaves room for rounding near the reference's own error.
#define BOUNCE_CONVERGENCE_FACTOR 5.0
// Body sizes the bounce at tol 1e-12 must come within of the run at tol 1e-13: measured 1.4e-9; a fixed onset depth
// threshold of 1e-3 δ_max left 1.5e-5.
#define BOUNCE_CONVERGED 1e-7

static const pdOnsets MODES[] = {pd_onsetsPair, pd_onsetsExact};

// A 0.1 m cube `gap` above a 1 m fixed floor, landing face-first at 1 m/s with gravity off, e 0.5, mu 0:
// its exit speed over the approach speed. *interpolated gets the number of pair onsets.
static double face_landing_restitution(double gap, pdOnsets onsets, long* interpolated) {
  char text[512];
  snprintf(text, sizeof text,
           "gravity 0 0 0\ntend 0.15\n"
           "cube floor grey 1 1 1\nfixed\nloc 0 0 -0.5\nmu 0\nrestitution 0.5\n"
           "cube block red 0.1 0.1 0.1\nloc 0 0 %.17g\nvel 0 0 -1\nmu 0\nrestitution 0.5\n",
           0.05 + gap);
  pdModel* m = compile_text(text);
  pdState* s = NULL;
  record* r = run_onsets(m, pd_stepperRK4Adaptive, onsets, &s);
  assert_int_equal(r->contacts[r->count - 1], 0);
  double e = r->body[0][r->count - 1].v.z;
  *interpolated = s->count.onsetsInterpolated;
  pd_state_free(s);
  free(r);
  pd_model_free(m);
  return e;
}

static void test_landings_bounce_with_the_requested_e_in_both_modes(void** state) {
  (void)state;
  for (int mode = 0; mode < 2; ++mode) {
    long interpolated = 0;
    double worst = 0.0;
    for (int i = 0; i < DROPS; ++i) {
      long n = 0;
      double e = face_landing_restitution(0.01 + 0.00137 * i, MODES[mode], &n);
      interpolated += n;
      worst = fmax(worst, fabs(e - 0.5));
      if (fabs(e - 0.5) > RESTITUTION_TOL)
        fail_msg("%s onsets, drop %d: e = %.5f, requested 0.5", pd_onsets_name(MODES[mode]), i, e);
    }
    print_message("%s onsets: %d face landings, %ld pair onsets, worst |e - 0.5| %.2e\n", pd_onsets_name(MODES[mode]),
                  DROPS, interpolated, worst);
    if (MODES[mode] == pd_onsetsPair)
      assert_true(interpolated > 0);
    else
      assert_int_equal(interpolated, 0);
  }
}

static void test_a_dropped_cube_rests_at_its_static_deflection(void** state) {
  (void)state;
  for (int mode = 0; mode < 2; ++mode) {
    long interpolated = 0;
    double worst = 0.0, deltaMax = 0.0;
    for (int i = 0; i < DROPS; ++i) {
      char text[512];
      snprintf(text, sizeof text,
               "tend 1.2\n"
               "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.3\n"
               "cube block red 0.1 0.1 0.1\nloc 0 0 %.17g\nmu 0.5\nrestitution 0.3\n",
               0.05 + 0.02 + 0.0113 * i / 4.0);
      pdModel* m = compile_text(text);
      int floor = body_index(m, "floor"), block = body_index(m, "block");
      pdPairContact pair = pd_model_pair_contact(m, block, floor);
      deltaMax = pd_model_pair_delta_max(m, block, floor);
      double rest = 0.05 - m->bodies[block].mass * 9.81 / (4.0 * pair.kn);
      pdState* s = NULL;
      record* r = run_onsets(m, pd_stepperRK4Adaptive, MODES[mode], &s);
      const pdBodyState* end = &r->body[0][r->count - 1];
      assert_true(pd_v3_norm(end->v) < 1e-4);
      assert_int_equal(r->contacts[r->count - 1], 4);
      worst = fmax(worst, fabs(end->x.z - rest) / deltaMax);
      interpolated += s->count.onsetsInterpolated;
      pd_state_free(s);
      free(r);
      pd_model_free(m);
    }
    print_message("%s onsets: %d drops, %ld pair onsets, rest height off m g/(4 k_s) by at most %.2e delta_max\n",
                  pd_onsets_name(MODES[mode]), DROPS, interpolated, worst);
    if (MODES[mode] == pd_onsetsPair) {
      assert_true(interpolated > 0);
      assert_true(worst <= REST_PAIR_TOL_DELTA);
    } else {
      assert_true(worst <= REST_EXACT_TOL_DELTA);
    }
  }
}

// The column's bounces are chaotic (boxes at e = 0.9 landing on one another), so one column's retry counts move by
// ±50 % with any change of the steps: the column is dropped COLUMNS times, its upper boxes raised by 1 mm more each
// time, and the retries summed over the drops. At the commit that made the samples stop cutting the steps the single
// column took 645 retries in the pair mode and 637 in the exact one; the three, 1 372 and 2 312.
#define COLUMNS 3

static void test_a_falling_column_gains_no_energy_and_retries_less(void** state) {
  (void)state;
  long retries[2] = {0, 0}, interpolated[2] = {0, 0};
  for (int column = 0; column < COLUMNS; ++column) {
    double raise = 1e-3 * column;  // m
    char text[1024];
    snprintf(text, sizeof text,
             "tend 1\n"
             "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.4\nrestitution 0.9\n"
             "cube b0 red 0.2 0.15 0.1\nloc 0 0 0.12  20 0 0 1\nmu 0.4\nrestitution 0.9\n"
             "cube b1 blue 0.2 0.15 0.1\nloc 0.01 0 %.17g  50 0 0 1\nmu 0.4\nrestitution 0.9\n"
             "cube b2 green 0.2 0.15 0.1\nloc 0 0.01 0.5  10 1 0 0\nmu 0.4\nrestitution 0.9\n"
             "cube b3 tan 0.2 0.15 0.1\nloc -0.01 0 %.17g  80 0 0 1\nmu 0.4\nrestitution 0.9\n",
             0.3 + raise, 0.7 + 2.0 * raise);
    pdModel* m = compile_text(text);
    for (int mode = 0; mode < 2; ++mode) {
      pdState* s = NULL;
      record* r = run_onsets(m, pd_stepperRK4Adaptive, MODES[mode], &s);
      double gain = energy_gain(r);
      retries[mode] += s->count.eventRetries;
      interpolated[mode] += s->count.onsetsInterpolated;
      print_message(
          "%s onsets: column of 4 (raised %.0f mm), %ld onset retries, %ld pair onsets, %ld derivative evaluations, "
          "largest energy rise %.2e of |E(0)|\n",
          pd_onsets_name(MODES[mode]), 1e3 * raise, s->count.eventRetries, s->count.onsetsInterpolated,
          s->count.derivatives, gain);
      assert_true(gain <= ENERGY_GAIN_TOL);
      pd_state_free(s);
      free(r);
    }
    pd_model_free(m);
  }
  print_message("%d columns: %ld onset retries in the pair mode, %ld in the exact one\n", COLUMNS, retries[0],
                retries[1]);
  assert_true(interpolated[0] > 0);
  assert_true(retries[0] < retries[1]);
}

// A column of `boxes` 0.2 × 0.2 × 0.1 m boxes, each turned 30° from the one below, 2 mm apart, dropped onto a
// floor: they land one on another and form one island.
static pdModel* column_of(int boxes) {
  enum { COLUMN_TEXT = 8192 };
  char text[COLUMN_TEXT];
  int used =
      snprintf(text, sizeof text, "tend 0.15\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.5\n");
  for (int k = 0; k < boxes; ++k) {
    used += snprintf(text + used, sizeof text - (size_t)used,
                     "cube b%d tan 0.2 0.2 0.1\nloc 0 0 %.4f %d 0 0 1\nmu 0.5\nrestitution 0.5\n", k, 0.052 + 0.102 * k,
                     30 * k % 90);
    assert_true(used < COLUMN_TEXT);
  }
  return compile_text(text);
}

static bool same_record(const record* a, const record* b) {
  if (a->count != b->count) return false;
  for (int k = 0; k < a->count; ++k) {
    if (a->energy[k] != b->energy[k] || a->contacts[k] != b->contacts[k]) return false;
    for (int j = 0; j < SCENE_RUN_TRACKED; ++j)
      if (memcmp(&a->body[j][k], &b->body[j][k], sizeof a->body[j][k]) != 0) return false;
  }
  return true;
}

// pd_onsetsAuto (the default): a system of at most PD_ONSETS_CROWD_BODIES moving bodies takes exact onsets, a
// larger one pair onsets, bit for bit (islands off: the scene is the system). With islands on, a column of
// more than that many boxes becomes one island and joins onsets as pairs there, gaining no energy.
static void test_auto_onsets_are_exact_in_small_systems_and_pairs_in_crowds(void** state) {
  (void)state;
  int sizes[2] = {4, PD_ONSETS_CROWD_BODIES + 2};
  for (int i = 0; i < 2; ++i) {
    pdModel* m = column_of(sizes[i]);
    pdOnsets expected = sizes[i] > PD_ONSETS_CROWD_BODIES ? pd_onsetsPair : pd_onsetsExact;
    assert_int_equal(pd_onsets_effective(pd_onsetsAuto, m->movingCount), expected);
    pdState *sa = NULL, *se = NULL;
    record* a = run_onsets_islands(m, pd_onsetsAuto, pd_islandsOff, &sa);
    record* e = run_onsets_islands(m, expected, pd_islandsOff, &se);
    print_message("column of %d, islands off: auto onsets %s %s's (%ld pair onsets, %ld steps)\n", sizes[i],
                  same_record(a, e) ? "are" : "ARE NOT", pd_onsets_name(expected), sa->count.onsetsInterpolated,
                  sa->count.accepted);
    assert_true(same_record(a, e));
    assert_int_equal(sa->count.accepted, se->count.accepted);
    assert_int_equal(sa->count.derivatives, se->count.derivatives);
    assert_int_equal(sa->count.onsetsInterpolated > 0, expected == pd_onsetsPair);
    pd_state_free(sa);
    pd_state_free(se);
    free(a);
    free(e);
    if (expected == pd_onsetsPair) {
      pdState* s = NULL;
      record* r = run_onsets_islands(m, pd_onsetsAuto, pd_islandsOn, &s);
      print_message("column of %d, islands on: largest island %ld, %ld pair onsets, energy rise %.2e of |E(0)|\n",
                    sizes[i], s->count.islandsLargest, s->count.onsetsInterpolated, energy_gain(r));
      assert_true(s->count.islandsLargest > PD_ONSETS_CROWD_BODIES);
      assert_true(s->count.onsetsInterpolated > 0);
      assert_true(energy_gain(r) <= ENERGY_GAIN_TOL);
      pd_state_free(s);
      free(r);
    }
    pd_model_free(m);
  }
}

// The sweep's bounce (cases/sweep/bounce.scene: a 0.2 m cube dropped flat from 0.5 m, e 0.5) run adaptively at tol:
// its trajectory, for converged_bounce.
static record* bounce_at(double tol) {
  char text[512];
  snprintf(text, sizeof text,
           "tend 1.5\nsample 100\ntol %.17g\n"
           "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nrestitution 0.5\n"
           "cube box red 0.2 0.2 0.2\nloc 0 0 0.6\nrestitution 0.5\n",
           tol);
  pdModel* m = compile_text(text);
  record* r = run_with(m, pd_stepperRK4Adaptive, NULL);
  pd_model_free(m);
  return r;
}

// The largest distance between two runs' cube positions over their common samples, over the cube's 0.2 m size.
static double bounce_distance(const record* a, const record* b) {
  assert_int_equal(a->count, b->count);
  double worst = 0.0;
  for (int i = 0; i < a->count; ++i) {
    pdVec3 d = pd_v3_sub(a->body[0][i].x, b->body[0][i].x);
    worst = fmax(worst, sqrt(pd_v3_dot(d, d)) / BOUNCE_SIZE);
  }
  return worst;
}

// A tighter tolerance must bring the run closer to the converged one: every onset, however shallow it is found,
// follows the tolerance (docs/events.md, "Shallow onsets"). Against a run at tol 1e-13, the distance at tol 1e-8,
// 1e-10 and 1e-12 must fall by at least BOUNCE_CONVERGENCE_FACTOR per factor 100 of tol, and end below
// BOUNCE_CONVERGED; an onset depth threshold fixed at 1e-3 δ_max left it at ~1e-5 body sizes at every tol.
static void test_a_bounce_converges_as_the_tolerance_tightens(void** state) {
  (void)state;
  record* ref = bounce_at(1e-13);
  double tols[] = {1e-8, 1e-10, 1e-12}, err[3];
  for (int i = 0; i < 3; ++i) {
    record* r = bounce_at(tols[i]);
    err[i] = bounce_distance(r, ref);
    printf("tol %g: distance %.3g body sizes\n", tols[i], err[i]);
    free(r);
  }
  free(ref);
  for (int i = 1; i < 3; ++i) assert_true(err[i] <= err[i - 1] / BOUNCE_CONVERGENCE_FACTOR || err[i] <= BOUNCE_CONVERGED);
  assert_true(err[2] <= BOUNCE_CONVERGED);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_landings_bounce_with_the_requested_e_in_both_modes),
      cmocka_unit_test(test_a_dropped_cube_rests_at_its_static_deflection),
      cmocka_unit_test(test_a_falling_column_gains_no_energy_and_retries_less),
      cmocka_unit_test(test_auto_onsets_are_exact_in_small_systems_and_pairs_in_crowds),
      cmocka_unit_test(test_a_bounce_converges_as_the_tolerance_tightens),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
