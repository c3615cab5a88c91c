// The contacts' stability bound (docs/integration.md; engine/src/contact_set.c): the smaller of a cheap Gershgorin
// bound of the contact-space matrix and a tight one of the body-space matrix. The tight bound is formed only for
// a step that the cheap one does not settle (the step the error control wants is longer than the cheap bound
// allows), and summary.json's `stability_tight` counts those steps. Two scenes with a 0.1 m cube on a fixed floor,
// islands off (one contact set for the run, whose work counter the tests read):
// - resting: the error control wants long steps and the bound sets them, so most steps need the tight bound;
// - dropped tilted with restitution 0.8: in flight there is no contact and during the bounces the error control
//   keeps the steps short, so few steps need it.
// In both the tight bound is formed at most once per step that needs it. The sanitizer build's self-check (PD_SELF_CHECKS) compares both bounds
// with the largest eigenvalue of the contact-space matrix on every list of up to 32 contacts, in every test.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "contact_set.h"
#include "dense_output.h"
#include "material.h"
#include "model_contact.h"
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

// Runs m with islands off; returns the final state and the tight bounds formed in *formed.
static pdState* run_counting(const pdModel* m, long* formed) {
  pdState* s = NULL;
  free(run_onsets_islands(m, pd_onsetsExact, pd_islandsOff, &s));
  // the integration's own state and contact list, not the one presented at tend (dense_output.h)
  pd_dense_resume(s);
  *formed = pd_contact_set_tight_formed(s->contacts);
  print_message("%ld accepted steps, %ld needed the tight bound, formed %ld times\n", s->count.accepted,
                s->count.stabilityTight, *formed);
  assert_true(s->count.stabilityTight <= s->count.accepted);
  return s;
}

// At most once per step that needs it (once per contact list at most).
static void check_formed(const pdState* s, long formed) { assert_true(formed <= s->count.stabilityTight); }

static void test_a_resting_cube_needs_the_tight_bound_on_most_steps(void** state) {
  (void)state;
  pdModel* m = cube_on_floor("loc 0 0 0.05");
  long formed;
  pdState* s = run_counting(m, &formed);
  assert_true(pd_state_contact_count(s) == 4);
  assert_true(s->count.stabilityTight > s->count.accepted / 2);
  assert_true(formed > 0);
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
  assert_true(s->count.stabilityTight < s->count.accepted / 2);
  check_formed(s, formed);
  pd_state_free(s);
  pd_model_free(m);
}

// A frictionless 0.1 m cube (1 kg) resting on a face: its four corner contacts have stiffness only along the
// vertical, so its modes are the bounce, ω² = 4 k/m, and the rocking about either horizontal axis,
// ω² = 4 k (a/2)² / I = 6 k/m with I = m a²/6; k the pair's series normal stiffness. The body-space bound is exact
// here (its off-diagonal terms cancel by symmetry), where the contact-space Gershgorin bound gave 8 k/m
// (docs/integration.md): the step it allows is 2 × 2.5 / ω_max for the rocking mode, to the bound's margin.
#define CUBE_ROCKING_REL_TOL 1e-6  // the corners' lever arms are a/2 to the static deflection (~1e-5 of a)

static void test_the_tight_bound_of_a_cube_resting_on_a_face_is_its_rocking_mode(void** state) {
  (void)state;
  pdModel* m = compile_text(
      "tend 0.05\nsample 100\n"
      "cube floor grey 1 1 0.2\nfixed\nloc 0 0 -0.1\nmu 0\n"
      "cube block red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0\n");
  long formed;
  pdState* s = run_counting(m, &formed);
  assert_int_equal(pd_state_contact_count(s), 4);
  int block = body_index(m, "block"), floor = body_index(m, "floor");
  pdContactParams p = pd_model_contact_params(m, block, floor);
  double k = pd_series(p.k1n, p.k2n), mass = m->bodies[block].mass;
  bool needed;
  double step = pd_contact_set_limit_step(m, s->contacts, INFINITY, 1.0, &needed);
  double omega2 = pow(2.0 * 2.5 / step, 2.0), rocking2 = 6.0 * k / mass;
  print_message("k %.6g N/m, m %.6g kg: bound omega^2 %.9g, rocking 6 k/m %.9g (ratio %.9f)\n", k, mass, omega2,
                rocking2, omega2 / rocking2);
  assert_true(needed);
  assert_true(omega2 >= rocking2 * (1.0 - CUBE_ROCKING_REL_TOL));
  assert_true(omega2 <= rocking2 * (1.0 + CUBE_ROCKING_REL_TOL));
  pd_state_free(s);
  pd_model_free(m);
}

// The messages quote the bound as text; it must be the number the engine applies.
static void test_the_bound_quoted_in_messages_is_the_one_applied(void** state) {
  (void)state;
  assert_true(strtod(PD_STABLE_STEP_OMEGA_TEXT, NULL) == PD_STABLE_STEP_OMEGA);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_resting_cube_needs_the_tight_bound_on_most_steps),
      cmocka_unit_test(test_a_bouncing_cube_needs_it_on_few_steps),
      cmocka_unit_test(test_the_tight_bound_of_a_cube_resting_on_a_face_is_its_rocking_mode),
      cmocka_unit_test(test_the_bound_quoted_in_messages_is_the_one_applied),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
