// Corrected onsets and their error bound (docs/events.md; engine/src/onset_bound.h):
// - drops whose onsets are forced to be corrected (pd_onsetsPair), a cube landing on a face, on a corner and on an
//   edge, e 0.3, 0.5 and 0.8, at 1, 0.1 and 0.02 m/s and heights that put the onset anywhere in a step (ωτ up to
//   0.8), at tol 1e-10: the velocity after the bounce is the located run's (pd_onsetsExact) to 0.005 of the approach
//   speed (a restitution within 0.005), and within the bound the engine computed for the run's worst corrected onset
//   (PD_ONSET_BOUND_C (ωτ)³ v_n / vmax in the error norm's units, so the bound times vmax is the velocity it
//   allows): the bound is measured, not assumed;
// - the bound over a range of impacts (normal, corner, edge-on, grazing while sliding and while sticking, fast,
//   slow, stiff, soft), the same comparison in the error norm's units of every velocity and turn rate;
// - the default (pd_onsetsBounded) at tol 1e-6 on the landings at 1 m/s: no corrected onset's bound exceeds the
//   tolerance's share (the others were located, their steps cut on the accepted trial's interpolant) and the exit
//   velocity is the exact run's to 0.005 of the approach speed; a loose pile of 12 boxes (slow re-landings) corrects some of its onsets, each within the tolerance's
//   share, gains no energy, and counts its breaks and its body-seconds asleep (within bodies × tend).
// - oblique drops at 0.3 m/s (a face, a corner and an edge landing with the block sliding at 0.3, 1 and 3 times its
//   approach speed, μ 0.3 and 0.8), their onsets forced to be corrected at tol 1e-10: the normal and the tangential
//   exit velocities are the located run's within the bound the engine computed for the run's corrected onsets (their
//   sum, times vmax, plus the comparison's scatter); with the default events at the default tolerance some of those
//   sliding onsets are corrected (the corner landings') and the exit velocity is the located run's to 0.005 of the
//   approach speed (a restitution and a tangential exit within 0.005);
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

// The impacts the bound is checked over: a 0.1 m cube landing at `speed` (m/s) with a tangential velocity of `slide`
// times that (grazing), with the scene's `deflection` (stiff: a small δ_max, a high frequency; soft: a large one).
typedef struct impact {
  const char* name;
  const char* turn;
  double speed, slide, deflection, mu;
  double spin;  // rad/s about y: a body turning as it lands (its point's effective mass changes over τ)
  const char* size;  // the block's extents
} impact;

static const impact IMPACTS[] = {
    {"normal face", "0 0 0 1", 1.0, 0.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"normal corner", "54.7356 0.7071068 -0.7071068 0", 1.0, 0.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"edge-on", "45 1 0 0", 1.0, 0.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"grazing corner, sliding", "54.7356 0.7071068 -0.7071068 0", 0.3, 4.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"grazing edge, sticking", "45 1 0 0", 0.05, 0.3, 0.01, 1.0, 0.0, "0.1 0.1 0.1"},
    {"grazing face, sliding", "0 0 0 1", 0.2, 8.0, 0.01, 0.5, 0.0, "0.1 0.1 0.1"},
    {"fast edge", "45 1 0 0", 3.0, 0.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"slow edge", "45 1 0 0", 0.02, 0.0, 0.01, 0.3, 0.0, "0.1 0.1 0.1"},
    {"stiff corner", "54.7356 0.7071068 -0.7071068 0", 1.0, 0.5, 0.001, 0.3, 0.0, "0.1 0.1 0.1"},
    {"soft edge", "45 1 0 0", 1.0, 0.5, 0.05, 0.3, 0.0, "0.1 0.1 0.1"},
    {"spinning bar, edge", "30 0 1 0", 1.0, 0.0, 0.01, 0.5, 4.0, "0.6 0.1 0.1"},
};
#define PI 3.14159265358979323846
#define IMPACT_DROPS 16
// What two runs of one drop at FORCED_TOL differ by without any correction: each accepted step may leave 1e-10 of
// error, a drop takes ~10² of them (measured: a slow edge landing at 0.02 m/s, corrected onsets bounded by ~2e-9,
// came out 1.6e-9 apart). Below it the comparison measures the steps, not the correction.
#define COMPARISON_NOISE 1e-8

static pdModel* impact_model(const impact* im, double gap, double tol) {
  // the lowest point's depth below the centre: half a face, half a body diagonal, half a face diagonal, or the bar's
  // end turned 30°
  double h = im->spin > 0.0                  ? 0.3 * sin(PI / 6.0) + 0.05 * cos(PI / 6.0)
             : strstr(im->name, "face")      ? 0.05
             : strstr(im->name, "corner")    ? 0.05 * sqrt(3.0)
                                             : 0.05 * sqrt(2.0);
  char text[768];
  snprintf(text, sizeof text,
           "gravity 0 0 0\ntend %.17g\nsample 400\ntol %g\ndeflection %g\nvmax %g\n"
           "cube floor grey 3 3 1\nfixed\nloc 0 0 -0.5\nmu %g\nrestitution 0.5\n"
           "cube block red %s\nloc 0 0 %.17g  %s\nvel %.17g 0 %.17g  %.17g 0 1 0\nmu %g\nrestitution 0.5\n",
           2.0 * gap / im->speed + 0.06, tol, im->deflection, im->speed * (1.0 + im->slide) + 0.3 * im->spin, im->mu,
           im->size, h + gap, im->turn, im->slide * im->speed, -im->speed, im->spin * 180.0 / PI, im->mu);
  return compile_text(text);
}

// The state at sample `at` of a record in the error norm's units (state.c's weights: vmax for velocities, vmax/size for
// angular velocities), against another's.
static double norm_difference(const pdModel* m, const record* a, const record* b, int at) {
  const pdBodyState *x = &a->body[0][at], *y = &b->body[0][at];
  double size = m->bodies[m->movingBodies[0]].size, vmax = m->settings.vmax;
  double dv = pd_v3_norm(pd_v3_sub(x->v, y->v)) / vmax;
  double dw = pd_v3_norm(pd_v3_sub(x->w, y->w)) * size / vmax;
  return fmax(dv, dw);
}

// The first sample after the bounce at which both runs are airborne: there a free flight's velocities differ by what
// they differed at any time of it (the applied forces are the same in both), which compares the two at one time.
static int first_common_flight(const record* a, const record* b) {
  bool touched = false;
  for (int i = 0; i < a->count && i < b->count; ++i) {
    if (a->contacts[i] > 0 || b->contacts[i] > 0) touched = true;
    else if (touched) return i;
  }
  return -1;
}

// An impact's tallies over its drops.
typedef struct tally {
  long corrected;
  double worst, worstRatio;
} tally;

// One drop of model m, its onsets forced to be corrected (pd_onsetsPair), against the same drop with every onset
// located: the state in the error norm's units at the runs' end (both off the floor) or, with atFlight, at the first
// sample both are airborne again, within the sum of the corrected onsets' bounds (plus the comparison's scatter).
static void forced_against_located(pdModel* m, bool atFlight, const char* name, int drop, tally* t) {
  pdState *sp = NULL, *se = NULL;
  record* rp = run_onsets(m, pd_stepperRK4Adaptive, pd_onsetsPair, &sp);
  record* re = run_onsets(m, pd_stepperRK4Adaptive, pd_onsetsExact, &se);
  int at = atFlight ? first_common_flight(rp, re) : rp->count - 1;
  if (at < 0) fail_msg("%s, drop %d: not airborne again by the run's end", name, drop);
  if (!atFlight) {
    assert_int_equal(rp->contacts[at], 0);  // both have left the floor
    assert_int_equal(re->contacts[re->count - 1], 0);
  }
  double error = norm_difference(m, rp, re, at);
  double bound = sp->count.onsetBoundSum;
  t->corrected += sp->count.onsetsInterpolated;
  t->worst = fmax(t->worst, error);
  if (sp->count.onsetsInterpolated > 0) t->worstRatio = fmax(t->worstRatio, error / bound);
  if (sp->count.onsetsInterpolated > 0 && error > bound + COMPARISON_NOISE)
    fail_msg("%s, drop %d: corrected run off the located one's by %.3e, beyond its bounds' sum %.3e", name, drop, error,
             bound);
  free(rp);
  free(re);
  pd_state_free(sp);
  pd_state_free(se);
}

// The bound (onset_bound.h) is at least the error a corrected onset makes: each impact's drops, their onsets forced to
// be corrected (pd_onsetsPair) at tol 1e-10, against the same drop with every onset located, after the bounce, in the
// error norm's units, within the sum of the run's corrected onsets' bounds (plus the comparison's own scatter). Normal,
// edge-on, fast, slow, stiff and soft landings test its velocity term (PD_ONSET_BOUND_C (ωτ)³), grazing ones, sliding
// and sticking, its friction term.
static void test_onset_bound_holds_over_impacts(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof IMPACTS / sizeof IMPACTS[0]; ++k) {
    const impact* im = &IMPACTS[k];
    tally t = {0};
    for (int i = 0; i < IMPACT_DROPS; ++i) {
      // heights that put the onsets all over a step
      pdModel* m = impact_model(im, 0.004 + 0.00137 * i * fmax(im->speed, 0.1), FORCED_TOL);
      forced_against_located(m, false, im->name, i, &t);
      pd_model_free(m);
    }
    print_message("%s: %ld corrected onsets over %d drops, worst error %.2e (norm units), at most %.2e of its bound\n",
                  im->name, t.corrected, IMPACT_DROPS, t.worst, t.worstRatio);
    assert_true(t.corrected > 0);
  }
}

// Impacts under the applied forces: the bound's applied term (onsets.c, correction_bound). A body falling onto a fixed
// one approaches faster by g τ over the τ a correction stands in for, which the correction, started at the approach
// found at the step's end, leaves out. A 0.1 m cube under gravity starting at `speed` `gap` above the floor (slow and
// moderate landings: 0.1 and 1 m/s), or pushed down by an applied force off its centre (a torque too), gravity off.
typedef struct pushedImpact {
  const char* name;
  const char* turn;
  double speed;        // m/s at the start
  double gravity;      // m/s², downwards
  const char* force;   // the block's `force` line ("" for none)
} pushedImpact;

static const pushedImpact PUSHED_IMPACTS[] = {
    {"face under gravity, slow", "0 0 0 1", 0.1, 9.81, ""},
    {"corner under gravity, slow", "54.7356 0.7071068 -0.7071068 0", 0.1, 9.81, ""},
    {"edge under gravity, slow", "45 1 0 0", 0.1, 9.81, ""},
    {"face under gravity, 1 m/s", "0 0 0 1", 1.0, 9.81, ""},
    {"corner under gravity, 1 m/s", "54.7356 0.7071068 -0.7071068 0", 1.0, 9.81, ""},
    {"edge under gravity, 1 m/s", "45 1 0 0", 1.0, 9.81, ""},
    {"corner pushed off its centre", "54.7356 0.7071068 -0.7071068 0", 0.3, 0.0, "force 2 -3 -40 at 0.03 0 0.02\n"},
};
#define PUSHED_DROPS 16

static pdModel* pushed_model(const pushedImpact* im, double gap, double tol) {
  double h = strstr(im->name, "face") ? 0.05 : strstr(im->name, "corner") ? 0.05 * sqrt(3.0) : 0.05 * sqrt(2.0);
  // the landing's speed and time (a push of 40 N on the 1 kg block is an acceleration of about 40 m/s²), then the
  // contact (a few δ_max / vmax, δ_max = 1 mm; vmax 1 m/s above the landing's, so that its springs hold the weight at a
  // small part of δ_max and a slow landing bounces) and the flight back up, which the comparison needs a sample of
  double a = im->gravity > 0.0 ? im->gravity : 40.0, land = sqrt(im->speed * im->speed + 2.0 * a * gap);
  double vmax = land + 1.0, tend = (land - im->speed) / a + 0.004 / vmax + 0.5 * land / a;
  char text[768];
  snprintf(text, sizeof text,
           "gravity 0 0 %.17g\ntend %.17g\nsample 4000\ntol %g\ndeflection 0.01\nvmax %g\n"
           "cube floor grey 3 3 1\nfixed\nloc 0 0 -0.5\nmu 0.3\nrestitution 0.5\n"
           "cube block red 0.1 0.1 0.1\nloc 0 0 %.17g  %s\nvel 0 0 %.17g\nmu 0.3\nrestitution 0.5\n%s",
           -im->gravity, tend, tol, vmax, h + gap, im->turn, -im->speed, im->force);
  return compile_text(text);
}

// Each impact's drops, their onsets forced to be corrected at tol 1e-10, against the same drop with every onset located:
// the velocities in the error norm's units, at the first sample both are airborne after the bounce, within the sum of
// the run's corrected onsets' bounds (plus the comparison's scatter). Without the bound's applied term the slow corner
// landing came out at 6.1 times its bound and the pushed corner at 3.8 times.
static void test_onset_bound_holds_under_applied_forces(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof PUSHED_IMPACTS / sizeof PUSHED_IMPACTS[0]; ++k) {
    const pushedImpact* im = &PUSHED_IMPACTS[k];
    tally t = {0};
    for (int i = 0; i < PUSHED_DROPS; ++i) {
      // heights that put the onsets all over a step
      pdModel* m = pushed_model(im, (0.0002 + 0.00137 * i) * im->speed, FORCED_TOL);
      forced_against_located(m, true, im->name, i, &t);
      pd_model_free(m);
    }
    print_message("%s: %ld corrected onsets over %d drops, worst error %.2e (norm units), at most %.2e of its bound\n",
                  im->name, t.corrected, PUSHED_DROPS, t.worst, t.worstRatio);
    assert_true(t.corrected > 0);
  }
}

static void test_bounded_events_locate_fast_landings(void** state) {
  (void)state;
  for (size_t l = 0; l < sizeof LANDINGS / sizeof LANDINGS[0]; ++l) {
    long corrected = 0, cuts = 0;
    double worst = 0.0;
    for (int i = 0; i < DROPS; ++i) {
      pdModel* m = landing_model(&LANDINGS[l], 0.5, 0.01 + 0.00137 * i, 1.0, DEFAULT_TOL);
      pdState *sb = NULL, *se = NULL;
      pdVec3 vb = final_velocity(m, pd_onsetsBounded, &sb);
      pdVec3 ve = final_velocity(m, pd_onsetsExact, &se);
      corrected += sb->count.onsetsInterpolated;
      cuts += sb->count.onsetCuts;
      assert_true(sb->count.onsetBoundMax <= PD_ONSET_TOL_SHARE * m->settings.tol);
      worst = fmax(worst, pd_v3_norm(pd_v3_sub(vb, ve)));
      pd_state_free(sb);
      pd_state_free(se);
      pd_model_free(m);
    }
    print_message("%s landings at 1 m/s, bounded events: %ld onsets corrected, %ld steps cut on the trial's "
                  "interpolant, exit velocity off the located run's by at most %.2e m/s\n",
                  LANDINGS[l].name, corrected, cuts, worst);
    assert_true(cuts > 0);  // the located onsets' steps ended on the interpolant, not on a retried trial
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

// The oblique drops: an impact's landing with the block sliding at `slide` times the approach speed.
static const double SLIDES[] = {0.3, 1.0, 3.0};
static const double FRICTIONS[] = {0.3, 0.8};
static const char* const OBLIQUE_TURNS[][2] = {
    {"face", "0 0 0 1"}, {"corner", "54.7356 0.7071068 -0.7071068 0"}, {"edge", "45 1 0 0"}};
#define OBLIQUE_DROPS 6

static void test_oblique_corrections_keep_restitution_and_slip_within_their_bound(void** state) {
  (void)state;
  long correctedDefault = 0;
  for (size_t l = 0; l < sizeof OBLIQUE_TURNS / sizeof OBLIQUE_TURNS[0]; ++l)
    for (size_t f = 0; f < sizeof FRICTIONS / sizeof FRICTIONS[0]; ++f) {
      long corrected = 0, correctedBounded = 0;
      double worstNormal = 0.0, worstRatio = 0.0, worstBounded = 0.0;
      for (size_t k = 0; k < sizeof SLIDES / sizeof SLIDES[0]; ++k)
        for (int i = 0; i < OBLIQUE_DROPS; ++i) {
          impact im = {OBLIQUE_TURNS[l][0], OBLIQUE_TURNS[l][1], 0.3, SLIDES[k], 0.01, FRICTIONS[f], 0.0,
                       "0.1 0.1 0.1"};
          double gap = 0.004 + 0.00137 * i * im.speed;
          pdModel* m = impact_model(&im, gap, FORCED_TOL);
          pdState *sp = NULL, *se = NULL;
          pdVec3 vp = final_velocity(m, pd_onsetsPair, &sp), ve = final_velocity(m, pd_onsetsExact, &se);
          double normal = fabs(vp.z - ve.z) / im.speed;
          double tangential = hypot(vp.x - ve.x, vp.y - ve.y);
          double allowed = (sp->count.onsetBoundSum + COMPARISON_NOISE) * m->settings.vmax;
          corrected += sp->count.onsetsInterpolated;
          worstNormal = fmax(worstNormal, normal);
          if (sp->count.onsetsInterpolated > 0) worstRatio = fmax(worstRatio, tangential / allowed);
          if (sp->count.onsetsInterpolated > 0 && normal * im.speed > allowed)
            fail_msg("oblique %s landing, mu %g, slide %g, drop %d: normal exit velocity off by %.3e m/s, beyond its "
                     "bound %.3e m/s",
                     im.name, im.mu, im.slide, i, normal * im.speed, allowed);
          if (sp->count.onsetsInterpolated > 0 && tangential > allowed)
            fail_msg("oblique %s landing, mu %g, slide %g, drop %d: tangential exit velocity off by %.3e m/s, beyond "
                     "its bound %.3e m/s",
                     im.name, im.mu, im.slide, i, tangential, allowed);
          pd_state_free(sp);
          pd_state_free(se);
          pd_model_free(m);
          // the default events at the default tolerance, against the same drop with every onset located
          m = impact_model(&im, gap, DEFAULT_TOL);
          pdVec3 vb = final_velocity(m, pd_onsetsBounded, &sp), vx = final_velocity(m, pd_onsetsExact, &se);
          correctedBounded += sp->count.onsetsInterpolated;
          assert_true(sp->count.onsetBoundMax <= PD_ONSET_TOL_SHARE * m->settings.tol);
          double off = pd_v3_norm(pd_v3_sub(vb, vx)) / im.speed;
          worstBounded = fmax(worstBounded, off);
          if (off > RESTITUTION_TOL)
            fail_msg("oblique %s landing, mu %g, slide %g, drop %d, default events: exit velocity off the located "
                     "run's by %.3e v_n",
                     im.name, im.mu, im.slide, i, off);
          pd_state_free(sp);
          pd_state_free(se);
          pd_model_free(m);
        }
      print_message("oblique %s landings, mu %g: %ld corrected onsets (forced), normal exit off by at most %.2e v_n, "
                    "tangential at most %.2e of its bound; default events: %ld corrected, exit off by %.2e v_n\n",
                    OBLIQUE_TURNS[l][0], FRICTIONS[f], corrected, worstNormal, worstRatio, correctedBounded,
                    worstBounded);
      assert_true(corrected > 0);
      assert_true(worstBounded <= RESTITUTION_TOL);
      correctedDefault += correctedBounded;
    }
  assert_true(correctedDefault > 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_forced_corrections_keep_restitution_within_their_bound),
      cmocka_unit_test(test_onset_bound_holds_over_impacts),
      cmocka_unit_test(test_onset_bound_holds_under_applied_forces),
      cmocka_unit_test(test_bounded_events_locate_fast_landings),
      cmocka_unit_test(test_bounded_events_correct_slow_onsets_in_a_pile),
      cmocka_unit_test(test_oblique_corrections_keep_restitution_and_slip_within_their_bound),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
