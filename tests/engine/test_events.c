// Corrected onsets and their error bound (docs/events.md; engine/src/onset_bound.h):
// - drops whose onsets are forced to be corrected (pd_onsetsPair), a cube landing on a face, on a corner and on an
//   edge, e 0.3, 0.5 and 0.8, at 1, 0.1 and 0.02 m/s and heights that put the onset anywhere in a step (ωτ up to
//   0.8), at tol 1e-10: the velocity after the bounce is the located run's (pd_onsetsExact) to 0.005 of the approach
//   speed (a restitution within 0.005), and within the bound the engine computed for the run's worst corrected onset
//   (PD_ONSET_BOUND_C (ωτ)³ v_n / vmax in the error norm's units, so the bound times vmax is the velocity it
//   allows): the bound is measured, not assumed;
// - the default (pd_onsetsBounded) at tol 1e-6 on the landings at 1 m/s: no corrected onset's bound exceeds the
//   tolerance's share (the others were located) and the exit velocity is the exact run's to 0.005 of the approach
//   speed; a loose pile of 12 boxes (slow re-landings) corrects some of its onsets, each within the tolerance's
//   share, gains no energy, and counts its breaks and its body-seconds asleep (within bodies × tend).
// Every case asserts first that what it checks happened (corrected onsets in the forced runs and in the pile).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "onset_bound.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "scene_run.h"

#define RESTITUTION_TOL 0.005   // of the approach speed: what the forced corrections must keep
#define ENERGY_GAIN_TOL 1e-9    // relative to |E(0)|: integration error only, no energy from the onsets
#define DROPS 24
// The forced drops run at a tolerance far below the correction's error so that what is compared is the correction,
// not the steps (at the default 1e-6 both runs scatter by ~1e-5 of v_n over a landing's ~20 steps); the bounded ones
// at the default.
#define FORCED_TOL 1e-10
#define DEFAULT_TOL 1e-6

typedef struct landing {
  const char* name;
  const char* turn;  // the block's orientation, "angle ux uy uz"
} landing;

static const landing LANDINGS[] = {
    {"face", "0 0 0 1"},
    {"corner", "54.7356 0.7071068 -0.7071068 0"},  // a body diagonal along z: one vertex down
    {"edge", "45 1 0 0"},                           // an edge down
};
static const double RESTITUTIONS[] = {0.3, 0.5, 0.8};
static const double SPEEDS[] = {1.0, 0.1, 0.02};  // m/s: slower landings join later in their step (deeper ωτ)

// A 0.1 m cube, lowest point `gap` above a 1 m fixed floor, falling at `speed` with gravity off (mu 0.3), at `tol`,
// run until it has bounced off.
static pdModel* landing_model(const landing* l, double e, double gap, double speed, double tol) {
  // the lowest point of the turned cube lies h below its centre: half the face, the half body diagonal, or half the
  // face diagonal
  double h = strcmp(l->name, "face") == 0 ? 0.05 : strcmp(l->name, "corner") == 0 ? 0.05 * sqrt(3.0) : 0.05 * sqrt(2.0);
  char text[640];
  snprintf(text, sizeof text,
           "gravity 0 0 0\ntend %.17g\nsample 200\ntol %g\n"
           "cube floor grey 1 1 1\nfixed\nloc 0 0 -0.5\nmu 0.3\nrestitution %g\n"
           "cube block red 0.1 0.1 0.1\nloc 0 0 %.17g  %s\nvel 0 0 %.17g\nmu 0.3\nrestitution %g\n",
           2.0 * gap / speed + 0.05, tol, e, h + gap, l->turn, -speed, e);
  return compile_text(text);
}

// Its centre's velocity after the bounce (the last sample); the run's state into *out (caller frees).
static pdVec3 final_velocity(const pdModel* m, pdOnsets onsets, pdState** out) {
  record* r = run_onsets(m, pd_stepperRK4Adaptive, onsets, out);
  assert_int_equal(r->contacts[r->count - 1], 0);  // it has left the floor
  pdVec3 v = r->body[0][r->count - 1].v;
  free(r);
  return v;
}

static void test_forced_corrections_keep_restitution_within_their_bound(void** state) {
  (void)state;
  for (size_t l = 0; l < sizeof LANDINGS / sizeof LANDINGS[0]; ++l) {
    for (size_t k = 0; k < sizeof RESTITUTIONS / sizeof RESTITUTIONS[0]; ++k) {
      long corrected = 0;
      double worst = 0.0, worstRatio = 0.0;
      for (int i = 0; i < DROPS; ++i) {
        pdModel* m = landing_model(&LANDINGS[l], RESTITUTIONS[k], 0.01 + 0.00137 * i, SPEEDS[i % 3], FORCED_TOL);
        pdState *sp = NULL, *se = NULL;
        pdVec3 vp = final_velocity(m, pd_onsetsPair, &sp);
        pdVec3 ve = final_velocity(m, pd_onsetsExact, &se);
        double speed = SPEEDS[i % 3];
        double dv = pd_v3_norm(pd_v3_sub(vp, ve)) / speed;  // of the approach speed
        double allowed = sp->count.onsetBoundMax * m->settings.vmax / speed;  // the bound's velocity, of it
        corrected += sp->count.onsetsInterpolated;
        worst = fmax(worst, dv);
        if (sp->count.onsetsInterpolated > 0) worstRatio = fmax(worstRatio, dv / allowed);
        if (dv > RESTITUTION_TOL)
          fail_msg("%s landing, e %g, drop %d: corrected exit velocity off the located one's by %.3e v_n",
                   LANDINGS[l].name, RESTITUTIONS[k], i, dv);
        if (sp->count.onsetsInterpolated > 0 && dv > allowed)
          fail_msg("%s landing, e %g, drop %d: off by %.3e v_n, beyond its bound %.3e v_n", LANDINGS[l].name,
                   RESTITUTIONS[k], i, dv, allowed);
        pd_state_free(sp);
        pd_state_free(se);
        pd_model_free(m);
      }
      print_message("%s landings, e %g: %ld corrected onsets over %d drops, worst |dv| %.2e of v_n, at most %.2e of "
                    "its bound\n",
                    LANDINGS[l].name, RESTITUTIONS[k], corrected, DROPS, worst, worstRatio);
      assert_true(corrected > 0);
    }
  }
}

static void test_bounded_events_locate_fast_landings(void** state) {
  (void)state;
  for (size_t l = 0; l < sizeof LANDINGS / sizeof LANDINGS[0]; ++l) {
    long corrected = 0;
    double worst = 0.0;
    for (int i = 0; i < DROPS; ++i) {
      pdModel* m = landing_model(&LANDINGS[l], 0.5, 0.01 + 0.00137 * i, 1.0, DEFAULT_TOL);
      pdState *sb = NULL, *se = NULL;
      pdVec3 vb = final_velocity(m, pd_onsetsBounded, &sb);
      pdVec3 ve = final_velocity(m, pd_onsetsExact, &se);
      corrected += sb->count.onsetsInterpolated;
      assert_true(sb->count.onsetBoundMax <= PD_ONSET_TOL_SHARE * m->settings.tol);
      worst = fmax(worst, pd_v3_norm(pd_v3_sub(vb, ve)));
      pd_state_free(sb);
      pd_state_free(se);
      pd_model_free(m);
    }
    print_message("%s landings at 1 m/s, bounded events: %ld onsets corrected, exit velocity off the located run's by "
                  "at most %.2e m/s\n",
                  LANDINGS[l].name, corrected, worst);
    assert_true(worst <= RESTITUTION_TOL);
  }
}

// 12 boxes dropped onto a floor in a loose column (they land on one another and re-land slowly): the default
// corrects some onsets, each within the tolerance's share, gains no energy, and its counters add up.
static void test_bounded_events_correct_slow_onsets_in_a_pile(void** state) {
  (void)state;
  char text[4096];
  int n = snprintf(text, sizeof text, "tend 1.2\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.5\n");
  for (int i = 0; i < 12; ++i)
    n += snprintf(text + n, sizeof text - (size_t)n,
                  "cube b%d red 0.2 0.15 0.1\nloc %.3f %.3f %.3f  %d 0.3 0.4 0.866\nmu 0.5\nrestitution 0.5\n", i,
                  0.02 * (i % 3), 0.015 * (i % 2), 0.08 + 0.27 * i, 17 * i);
  pdModel* m = compile_text(text);
  pdState* s = NULL;
  record* r = run_onsets_islands(m, pd_onsetsBounded, pd_islandsOn, &s);
  const pdCounters* c = &s->count;
  print_message("pile of 12, bounded events: %ld onsets corrected, %ld contacts made, bound max %.2e (tol %.0e), sum "
                "%.2e, energy rise %.2e of |E(0)|\n",
                c->onsetsInterpolated, c->contactsMade, c->onsetBoundMax, m->settings.tol, c->onsetBoundSum,
                energy_gain(r));
  assert_true(c->onsetsInterpolated > 0);
  assert_true(c->onsetBoundMax > 0.0 && c->onsetBoundMax <= PD_ONSET_TOL_SHARE * m->settings.tol);
  assert_true(c->onsetBoundSum >= c->onsetBoundMax);
  assert_true(c->onsetBoundSum <= (double)c->onsetsInterpolated * c->onsetBoundMax);
  assert_true(energy_gain(r) <= ENERGY_GAIN_TOL);
  assert_true(c->breaksForce + c->breaksGeometry > 0);
  // sleeping (docs/sleeping.md) fills it: at most every moving body asleep for the whole run
  assert_true(c->bodySecondsAsleep >= 0.0 && c->bodySecondsAsleep <= m->movingCount * m->settings.tend);
  pd_state_free(s);
  free(r);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_forced_corrections_keep_restitution_within_their_bound),
      cmocka_unit_test(test_bounded_events_locate_fast_landings),
      cmocka_unit_test(test_bounded_events_correct_slow_onsets_in_a_pile),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
