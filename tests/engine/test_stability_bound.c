// The contacts' stability bound (README, Integration; engine/src/contact_set.c): the exact Gershgorin bound,
// O(contacts × contacts per body), is formed only for a step that the cheap O(contacts) bound does not settle
// (the step the error control wants is longer than the cheap bound allows), and summary.json's `stability_exact`
// counts those steps. Two scenes with a 0.1 m cube on a fixed floor, islands off (one contact set for the run,
// whose work counter the tests read):
// - resting: the error control wants long steps and the bound sets them, so most steps need the exact bound;
// - dropped tilted with restitution 0.8: in flight there is no contact and during the bounces the error control
//   keeps the steps short, so few steps need it.
// In both the exact bound is formed at most once per step that needs it, and under PD_SELF_CHECKS (the sanitizer
// build) for every contact list. Until ced591b it was formed for every contact list in every build (the check
// was under #ifndef NDEBUG, which no build defines): these tests would have failed.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "contact_set.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "scene_run.h"

static pdModel* cube_on_floor(const char* placement) {
  char text[512];
  snprintf(text, sizeof text,
           "tend 0.3\nsample 100\n"
           "cube floor grey 1 1 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\n"
           "cube block red 0.1 0.1 0.1\n%s\nmu 0.5\n",
           placement);
  return compile_text(text);
}

// Runs m with islands off; returns the final state and the exact bounds formed in *formed.
static pdState* run_counting(const pdModel* m, long* formed) {
  pdState* s = NULL;
  free(run_onsets_islands(m, pd_onsetsExact, pd_islandsOff, &s));
  *formed = pd_contact_set_exact_formed(s->contacts);
  print_message("%ld accepted steps, %ld needed the exact bound, formed %ld times\n", s->count.accepted,
                s->count.stabilityExact, *formed);
  assert_true(s->count.stabilityExact <= s->count.accepted);
  return s;
}

// At most once per step that needs it; under the self-checks, for every contact list (every step here).
static void check_formed(const pdState* s, long formed) {
#ifdef PD_SELF_CHECKS
  (void)s;
  assert_true(formed > 0);
#else
  assert_true(formed <= s->count.stabilityExact);
#endif
}

static void test_a_resting_cube_needs_the_exact_bound_on_most_steps(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 0.05");
  long formed;
  pdState* s = run_counting(m, &formed);
  assert_true(pd_state_contact_count(s) == 4);
  assert_true(s->count.stabilityExact > s->count.accepted / 2);
#ifdef PD_SELF_CHECKS
  assert_true(formed >= s->count.accepted);
#endif
  check_formed(s, formed);
  pd_state_free(s);
  pd_model_free(m);
}

static void test_a_bouncing_cube_needs_it_on_few_steps(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 0.1  20 1 1 0\nrestitution 0.8");
  long formed;
  pdState* s = run_counting(m, &formed);
  assert_true(s->count.contactsMade > 0);
  assert_true(s->count.stabilityExact < s->count.accepted / 2);
  check_formed(s, formed);
  pd_state_free(s);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_resting_cube_needs_the_exact_bound_on_most_steps),
      cmocka_unit_test(test_a_bouncing_cube_needs_it_on_few_steps),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
