// engine/src/contact_set.c: the first derivative of a step after a commit takes every contact's force and spring
// rates from the list's preparation (record(), pd_contact_set_recorded_at) instead of forming them again. Checked at
// the end of a step of scenes with edge–edge contacts (a 45° stack), vertex–face contacts in slip (a cube sliding
// down a ramp) and a wall of aligned bricks: the derivative so taken and the one formed afresh are the same bit for
// bit, and the recorded one was taken (the predicate held before it was forgotten). Where the step's quaternions
// renormalised to other bits (bodies turning: a falling pile), the state differs from the recorded one and every
// contact is formed, as the predicate's state comparison says. The same for the derivative at the state the contact
// events just tracked the list to while the implicit method is active (pd_contact_set_tracked_at: an implicit trial's
// end, whose slope its dense output needs): a cube resting on a ramp and one sliding on the floor.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "clock.h"
#include "contact_set.h"
#include "dense_output.h"
#include "implicit.h"
#include "scene_run.h"

// A state's numbers in another place, or one spring changed in place, are not taken for the recorded state.
static void expect_other_states_not_recorded(const pdModel* model, pdState* s) {
  size_t bytes = (size_t)s->n * sizeof(double);
  double* copy = malloc(bytes);
  assert_non_null(copy);
  memcpy(copy, s->y, bytes);
  assert_false(pd_contact_set_recorded_at(model, s->contacts, copy));
  free(copy);
  double kept = s->y[s->n - 1];
  s->y[s->n - 1] += 1e-9;
  assert_false(pd_contact_set_recorded_at(model, s->contacts, s->y));
  s->y[s->n - 1] = kept;
  assert_true(pd_contact_set_recorded_at(model, s->contacts, s->y));
}

// The scene file (below the source tree) advanced to t with islands off, at the end of its last step.
static void expect_recorded_derivative_is_fresh(const char* scene, double t) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", PD_SOURCE_DIR, scene);
  pdModel* model = compile_file(path);
  pdStateOptions options = pd_state_options_default();
  options.islands = pd_islandsOff;  // one state: its own list and step
  pdState* s = pd_state_create(model, &options);
  assert_true(pd_advance(model, s, t, NULL, NULL));
  pd_dense_resume(s);  // the integration's own state, at the end of its last step (a sample presents another)
  assert_true(pd_state_contact_count(s) > 0);
  assert_true(pd_contact_set_recorded_at(model, s->contacts, s->y));
  expect_other_states_not_recorded(model, s);
  size_t bytes = (size_t)s->n * sizeof(double);
  double* recorded = malloc(bytes);
  double* fresh = malloc(bytes);
  assert_true(recorded && fresh);
  pd_state_derivative(model, s, s->t, s->y, recorded);
  pd_contact_set_forget_recorded(s->contacts);
  assert_false(pd_contact_set_recorded_at(model, s->contacts, s->y));
  pd_state_derivative(model, s, s->t, s->y, fresh);
  assert_memory_equal(recorded, fresh, bytes);
  free(recorded);
  free(fresh);
  pd_state_free(s);
  pd_model_free(model);
}

// The scene advanced to t with islands off and the implicit method active: its list tracked to the state's numbers in
// another place, and the derivative there taken from the tracking, then formed afresh.
static void expect_tracked_derivative_is_fresh(const char* scene, double t) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", PD_SOURCE_DIR, scene);
  pdModel* model = compile_file(path);
  pdStateOptions options = pd_state_options_default();
  options.islands = pd_islandsOff;
  pdState* s = pd_state_create(model, &options);
  assert_true(pd_advance(model, s, t, NULL, NULL));
  pd_dense_resume(s);
  assert_true(pd_state_contact_count(s) > 0);
  assert_true(s->implicit != NULL && pd_implicit_active(s->implicit));
  size_t bytes = (size_t)s->n * sizeof(double);
  double* y1 = malloc(bytes);
  double* tracked = malloc(bytes);
  double* fresh = malloc(bytes);
  assert_true(y1 && tracked && fresh);
  memcpy(y1, s->y, bytes);  // not at the recorded place: only the tracking can be taken
  double hRetry = 0.0;
  pdStopwatch watch = pd_stopwatch_start(s->stageTimers);
  pd_contact_events(model, s, 1e-4, y1, NULL, &hRetry, &watch);
  assert_true(pd_contact_set_tracked_at(model, s->contacts, y1));
  assert_false(pd_contact_set_tracked_at(model, s->contacts, s->y));
  pd_state_derivative(model, s, s->t, y1, tracked);
  pd_contact_set_forget_tracked(s->contacts);
  assert_false(pd_contact_set_tracked_at(model, s->contacts, y1));
  pd_state_derivative(model, s, s->t, y1, fresh);
  assert_memory_equal(tracked, fresh, bytes);
  free(y1);
  free(tracked);
  free(fresh);
  pd_state_free(s);
  pd_model_free(model);
}

static void test_tracked_cube_resting_on_a_ramp(void** state) {
  (void)state;
  expect_tracked_derivative_is_fresh("cases/user/ramp_stick.scene", 0.5);
}

static void test_tracked_cube_sliding_on_the_floor(void** state) {
  (void)state;
  expect_tracked_derivative_is_fresh("cases/user/floor_slide.scene", 0.3);
}

static void test_stack_of_crossed_boxes(void** state) {
  (void)state;
  expect_recorded_derivative_is_fresh("cases/hard/stack_10.scene", 0.05);
}

static void test_cube_sliding_down_a_ramp(void** state) {
  (void)state;
  expect_recorded_derivative_is_fresh("cases/user/ramp_slide.scene", 0.5);
}

static void test_brick_bond(void** state) {
  (void)state;
  expect_recorded_derivative_is_fresh("cases/hard/brick_bond.scene", 0.2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_stack_of_crossed_boxes),
      cmocka_unit_test(test_cube_sliding_down_a_ramp),
      cmocka_unit_test(test_brick_bond),
      cmocka_unit_test(test_tracked_cube_resting_on_a_ramp),
      cmocka_unit_test(test_tracked_cube_sliding_on_the_floor),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
