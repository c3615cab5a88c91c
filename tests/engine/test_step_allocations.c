// A step never allocates once warmed up (polydyn/state.h, "Memory"): pd_create and the steps that grow the contact list
// may allocate; once the contacts of a settling scene stop changing, pd_advance makes no allocation at all. Counted by
// the engine's own allocation counter (pd_alloc_count, builds with PD_COUNT_ALLOCS): every malloc, calloc and realloc
// of engine/src goes through it, so an allocation put anywhere in a step makes these tests fail.
//
// Scenes: a box settling on a floor (resting contact: four vertex–face contacts, the implicit stepper's matrices in
// use) and a small pile (boxes on the floor and on each other, islands), each under the default stepper and islands
// and under step doubling with islands off. Each is advanced past its settling (warm-up), then on; over the second
// stretch the count must not move. Sleep is off: a resting island that sleeps takes no steps at all.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "polydyn/api.h"
#include "scene_run.h"

static const char boxOnFloor[] =
    "tend 3\n"
    "sample 100\n"
    "sleep off\n"
    "cube floor grey 2 2 0.2\n"
    "fixed\n"
    "loc 0 0 -0.1\n"
    "cube box red 0.2 0.15 0.1\n"
    "loc 0 0 0.12 5 1 1 0\n"
    "restitution 0.3\n";

// Three boxes dropped onto each other and a fourth beside them.
static const char smallPile[] =
    "tend 3\n"
    "sample 100\n"
    "sleep off\n"
    "cube floor grey 2 2 0.2\n"
    "fixed\n"
    "loc 0 0 -0.1\n"
    "restitution 0.3\n"
    "cube b0 tan 0.2 0.15 0.1\n"
    "loc 0 0 0.06 3 0 0 1\n"
    "restitution 0.3\n"
    "cube b1 tan 0.2 0.15 0.1\n"
    "loc 0.02 0.01 0.17 20 0 0 1\n"
    "restitution 0.3\n"
    "cube b2 tan 0.2 0.15 0.1\n"
    "loc -0.01 0.02 0.28 40 0 0 1\n"
    "restitution 0.3\n"
    "cube b3 tan 0.2 0.15 0.1\n"
    "loc 0.4 0 0.08 10 1 0 0\n"
    "restitution 0.3\n";

static void expect_no_allocation_after_warm_up(const char* label, const char* text, pdStepper stepper,
                                               pdIslands islands, double warmUp, double tEnd) {
  pdModel* model = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  options.islands = islands;
  pdState* s = pd_state_create(model, &options);
  long before = pd_alloc_count();
  assert_true(pd_advance(model, s, warmUp, NULL, NULL));
  long warmed = pd_alloc_count();
  int contacts = pd_state_contact_count(s);
  long steps = s->count.accepted;
  double slice = 0.1;
  for (double t = warmUp + slice; t <= tEnd + 1e-9; t += slice) {
    assert_true(pd_advance(model, s, t, NULL, NULL));  // in slices: each call starts the sample loop anew
  }
  long after = pd_alloc_count();
  print_message("%s: %ld allocations up to %g s (%d contacts), then %ld over %ld steps to %g s (%d contacts)\n", label,
                warmed - before, warmUp, contacts, after - warmed, s->count.accepted - steps, tEnd,
                pd_state_contact_count(s));
  assert_true(warmed > before);  // the counter counts: creating the list, the stepper's matrices
  assert_true(pd_state_contact_count(s) > 0);
  assert_true(s->count.accepted > steps);
  assert_int_equal(after, warmed);
  pd_state_free(s);
  pd_model_free(model);
}

static void test_a_box_resting_on_a_floor_steps_without_allocating(void** unused) {
  (void)unused;
  expect_no_allocation_after_warm_up("box, default", boxOnFloor, PD_STEPPER_DEFAULT, PD_ISLANDS_DEFAULT, 1.0, 3.0);
  expect_no_allocation_after_warm_up("box, rk4 islands off", boxOnFloor, pd_stepperRK4Adaptive, pd_islandsOff, 1.0, 3.0);
}

static void test_a_settled_pile_steps_without_allocating(void** unused) {
  (void)unused;
  expect_no_allocation_after_warm_up("pile, default", smallPile, PD_STEPPER_DEFAULT, PD_ISLANDS_DEFAULT, 1.0, 3.0);
  expect_no_allocation_after_warm_up("pile, rk4 islands off", smallPile, pd_stepperRK4Adaptive, pd_islandsOff, 1.0, 3.0);
}

int main(void) {
  assert_true(pd_alloc_count() >= 0);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_box_resting_on_a_floor_steps_without_allocating),
      cmocka_unit_test(test_a_settled_pile_steps_without_allocating),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
