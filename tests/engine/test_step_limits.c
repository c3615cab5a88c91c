// What set each accepted step's size (pdCounters.stepsLimited, summary.json's `steps_limited_by`;
// docs/integration.md, "What sets the steps"): every accepted step of an error-controlled stepper is counted under
// exactly one limit, and the limit named is the one the scene is known to be held by. A 0.1 m cube and a fixed floor:
// - falling free from rest for 0.3 s (no contact): the error control grows the step to the scene's dtmax, which then
//   sets it (the parabola has no fifth derivative); no contact limit may appear;
// - resting on the floor, step doubling alone (islands off: it does not fall asleep): the error control wants long steps and the contacts' stability bound
//   (about 2.8/ω) sets them;
// - sliding at 4 m/s on a nearly frictionless free slab lying on the floor: the tunnelling guard lets a pair of moving
//   bodies touching move at most 2 δ_max per step (0.5 ms at that speed), shorter than the stability bound allows;
// - sliding so on the fixed floor itself: the floor's top face is its only way in, and once the two touch the guard
//   bounds only the move into it (contact_search.c, entry_holds), which sliding does not make: the guard sets none
//   of its steps but the first.
// And the largest step of a scene that sets no dtmax follows its tolerance (pd_default_dtmax): the same free fall at
// tol 1e-2 takes the longer cap, lands where the parabola does, and a scene's own dtmax is kept.
#include <setjmp.h>
#include <stdbool.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <math.h>
#include <stdlib.h>

#include <cmocka.h>

#include "polydyn/model.h"
#include "polydyn/state.h"
#include "scene_run.h"

// `settings`: extra setting lines ("" for none)
static pdModel* cube_on_floor_with(const char* settings, const char* placement) {
  char text[512];
  snprintf(text, sizeof text,
           "tend 0.3\nsample 100\n%s"
           "cube floor grey 4 1 0.2\nfixed\nloc 1.5 0 -0.1\nmu 0.01\n"
           "cube block red 0.1 0.1 0.1\n%s\nmu 0.01\n",
           settings, placement);
  return compile_text(text);
}

static pdModel* cube_on_floor(const char* placement) { return cube_on_floor_with("", placement); }

// The same cube on a free 2 cm slab (3 m by 1 m, of the same material) that lies on the fixed floor.
static pdModel* cube_on_slab(const char* placement) {
  char text[512];
  snprintf(text, sizeof text,
           "tend 0.3\nsample 100\n"
           "cube floor grey 4 1 0.2\nfixed\nloc 1.5 0 -0.1\nmu 0.01\n"
           "cube slab grey 3 1 0.02\nloc 1 0 0.01\nmu 0.01\n"
           "cube block red 0.1 0.1 0.1\n%s\nmu 0.01\n",
           placement);
  return compile_text(text);
}

// Runs m with the default stepper, or step doubling alone with islands off (no island falls asleep: `explicitOnly`);
// checks that every accepted step is counted once and returns the final state.
static pdState* run_limits(const pdModel* m, bool explicitOnly) {
  pdState* s = NULL;
  free(explicitOnly ? run_onsets_islands(m, PD_ONSETS_DEFAULT, pd_islandsOff, &s) : run(m, &s));
  long sum = 0;
  for (int k = 0; k < pd_limitCount; ++k) {
    print_message("%-9s %ld\n", pd_step_limit_name((pdStepLimit)k), s->count.stepsLimited[k]);
    sum += s->count.stepsLimited[k];
  }
  print_message("accepted  %ld\n", s->count.accepted);
  assert_int_equal(sum, s->count.accepted);
  return s;
}

// Runs m (run_limits) and checks that `limit` set more than half of its steps; returns
// the final state (the caller frees it).
static pdState* held_by(pdModel* m, bool explicitOnly, pdStepLimit limit) {
  pdState* s = run_limits(m, explicitOnly);
  assert_true(s->count.stepsLimited[limit] > s->count.accepted / 2);
  return s;
}

static void test_a_free_fall_is_held_by_the_largest_step(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 2");
  pdState* s = held_by(m, false, pd_limitLargest);
  assert_int_equal(s->count.stepsLimited[pd_limitStability], 0);
  // only the steps before its contacts are made: a pair's sole entry face is used once the pair touches
  assert_true(s->count.stepsLimited[pd_limitTravel] <= 2);
  pd_state_free(s);
  pd_model_free(m);
}

static void test_the_largest_step_follows_a_loose_tolerance(void** state) {
  (void)state;
  // the cap itself: the fixed default at the default tolerance and tighter, h ∝ tol^(1/5) looser, with a ceiling
  assert_true(pd_default_dtmax(PD_DEFAULT_TOL) == PD_DEFAULT_DTMAX);
  assert_true(pd_default_dtmax(1e-9) == PD_DEFAULT_DTMAX);
  assert_float_equal(pd_default_dtmax(1e-1), PD_DTMAX_DERIVED_CEILING, 1e-15);
  assert_true(pd_default_dtmax(10.0) == PD_DTMAX_DERIVED_CEILING);
  double loose = PD_DEFAULT_DTMAX * pow(1e4, 0.2);  // tol 1e-2: 0.063 s
  assert_float_equal(pd_default_dtmax(1e-2), loose, 1e-15);

  pdModel* tight = cube_on_floor("loc 0 0 2");
  pdModel* m = cube_on_floor_with("tol 1e-2\n", "loc 0 0 2");
  pdModel* own = cube_on_floor_with("tol 1e-2\ndtmax 0.01\n", "loc 0 0 2");
  assert_true(tight->settings.dtmax == PD_DEFAULT_DTMAX);
  assert_float_equal(m->settings.dtmax, loose, 1e-15);
  assert_true(own->settings.dtmax == 0.01);
  pdState* sTight = held_by(tight, false, pd_limitLargest);
  pdState* s = held_by(m, false, pd_limitLargest);
  // 0.3 s at 0.063 s a step after the first steps grow from dt (1e-3, at most 5× a step): 8 steps, against 32
  print_message("accepted: %ld at tol 1e-2, %ld at tol 1e-6\n", s->count.accepted, sTight->count.accepted);
  assert_true(s->count.accepted <= 10);
  assert_true(sTight->count.accepted >= 30);
  // a free fall has no error for the estimate to see: the long steps land where the parabola does (to rounding)
  pdBodyState block = pd_state_body(m, s, 1);
  double fall = 0.5 * 9.81 * 0.3 * 0.3;
  assert_float_equal(block.x.z, 2.0 - fall, 1e-12);
  assert_float_equal(block.v.z, -9.81 * 0.3, 1e-12);
  pd_state_free(sTight);
  pd_state_free(s);
  pd_model_free(tight);
  pd_model_free(m);
  pd_model_free(own);
}

static void test_a_resting_cube_is_held_by_the_stability_bound(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 0.05");
  pd_state_free(held_by(m, true, pd_limitStability));
  pd_model_free(m);
}

static void test_a_cube_sliding_fast_on_a_free_slab_is_held_by_the_tunnelling_guard(void** state) {
  (void)state;
  pdModel* m = cube_on_slab("loc 0 0 0.07\nvel 4 0 0");
  pd_state_free(held_by(m, false, pd_limitTravel));
  pd_model_free(m);
}

static void test_a_cube_sliding_fast_on_the_fixed_floor_is_not_held_by_the_tunnelling_guard(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 0.05\nvel 4 0 0");
  pdState* s = run_limits(m, false);
  // only the steps before its contacts are made: a pair's sole entry face is used once the pair touches
  assert_true(s->count.stepsLimited[pd_limitTravel] <= 2);
  pdBodyState block = pd_state_body(m, s, 1);
  assert_true(block.v.x > 3.9);  // sliding on across the floor, on it
  assert_true(block.x.z > 0.04);
  pd_state_free(s);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_free_fall_is_held_by_the_largest_step),
      cmocka_unit_test(test_the_largest_step_follows_a_loose_tolerance),
      cmocka_unit_test(test_a_resting_cube_is_held_by_the_stability_bound),
      cmocka_unit_test(test_a_cube_sliding_fast_on_a_free_slab_is_held_by_the_tunnelling_guard),
      cmocka_unit_test(test_a_cube_sliding_fast_on_the_fixed_floor_is_not_held_by_the_tunnelling_guard),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
