// Dense output (engine/src/dense_output.h; docs/integration.md): the output samples and pd_advance's end do not cut
// the error-controlled steppers' steps; the state is presented at each sample inside the step that passes it.
// - The steps do not depend on the sample rate: a scene with contacts sampled at 50 Hz and at 1 kHz takes the same
//   steps, and its states at the common samples are the same bit for bit (islands off and on; step doubling, the
//   embedded pair, Dormand–Prince and the implicit stepper).
// - A presented state is the trajectory's: free flight under gravity is a parabola, which both interpolants (quartic
//   and cubic) hold exactly, so a spinning cube's centre at every 1 ms sample inside its 10 ms steps is the closed
//   form to rounding.
// - Stopped between samples and resumed (islands off), a run is the run that did not stop, bit for bit.
// - A presented state's contacts carry their forces there: a box resting on a floor, sampled at 1 kHz inside the
//   implicit stepper's 10 ms steps, has its normal forces summing to its weight at every sample.
// - A presented state's contacts are evaluated when first read (pd_contact_set_settle): a run whose observer reads
//   every contact and the energy at every sample (as an eager evaluation would form them) and one that reads them at
//   every 9th sample only give the same contacts, energies and bodies there bit for bit, and the same bodies at every
//   sample, with sliding, sticking and sleeping contacts, islands off and on; a lone body's contacts, gathered into
//   the scene at every sample from its island's presentation, are those of islands off bit for bit.
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
#include "scene_run.h"

// Free flight: the interpolants reproduce a quadratic exactly; what is left is the rounding of the step's numbers
// (positions ~1 m, ~1e-16 relative, summed over a few hundred steps).
#define PARABOLA_TOL 1e-12  // m, and m/s for the velocity
// The resting box: its contacts' springs carry its weight to the integration's error (tol 1e-6 of δ_max scale) and
// the residue of its landing's ringing, damped by 0.6 s.
#define WEIGHT_REL_TOL 1e-6

enum { MAX_SAMPLES = 1201 };

typedef struct trace {
  int count;
  double t[MAX_SAMPLES];
  pdBodyState b[MAX_SAMPLES];
  double normalForce[MAX_SAMPLES];  // the sum of fn over the contacts
} trace;

static bool keep(const pdModel* model, const pdState* state, void* user) {
  trace* tr = user;
  if (tr->count == MAX_SAMPLES) return false;
  int k = tr->count++;
  tr->t[k] = state->t;
  tr->b[k] = pd_state_body(model, state, model->movingBodies[0]);
  double fn = 0.0;
  for (int i = 0; i < pd_state_contact_count(state); ++i) fn += pd_state_contact(state, i).fn;
  tr->normalForce[k] = fn;
  return true;
}

static trace* run_sampled(const char* body, double sampleRate, pdStepper stepper, pdIslands islands, long* steps) {
  char text[1024];
  // sleep off: an island falls asleep at a sync time, and the samples are sync times (docs/sleeping.md)
  snprintf(text, sizeof text, "tend 0.6\nsample %g\nsleep off\n%s", sampleRate, body);
  pdModel* m = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  options.islands = islands;
  pdState* s = pd_state_create(m, &options);
  trace* tr = calloc(1, sizeof *tr);
  assert_non_null(tr);
  assert_true(pd_advance(m, s, m->settings.tend, keep, tr));
  *steps = s->count.accepted;
  pd_state_free(s);
  pd_model_free(m);
  return tr;
}

static bool same_state(const pdBodyState* a, const pdBodyState* b) { return memcmp(a, b, sizeof *a) == 0; }

static const char TUMBLE[] =
    "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\n"
    "cube box red 0.2 0.15 0.1\nloc 0 0 0.12  30 1 1 0\nvel 0.4 0 0  5 0 1 0\nmu 0.5\nrestitution 0.5\n";

static void test_the_samples_do_not_change_the_steps(void** state) {
  (void)state;
  const pdStepper steppers[] = {pd_stepperRK4Adaptive, pd_stepperRK43Embedded, pd_stepperImplicit, pd_stepperDopri54};
  const pdIslands islands[] = {pd_islandsOff, pd_islandsOn};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 2; ++j) {
      long coarseSteps, fineSteps;
      trace* coarse = run_sampled(TUMBLE, 50, steppers[i], islands[j], &coarseSteps);
      trace* fine = run_sampled(TUMBLE, 1000, steppers[i], islands[j], &fineSteps);
      assert_int_equal(coarse->count, 31);
      assert_int_equal(fine->count, 601);
      int differ = 0;
      for (int k = 0; k < coarse->count; ++k) {
        assert_true(coarse->t[k] == fine->t[20 * k]);
        differ += !same_state(&coarse->b[k], &fine->b[20 * k]);
      }
      print_message("%s, islands %s: %ld steps at 50 Hz, %ld at 1 kHz; %d of the 31 common samples differ\n",
                    pd_stepper_name(steppers[i]), islands[j] == pd_islandsOn ? "on" : "off", coarseSteps, fineSteps,
                    differ);
      assert_int_equal(coarseSteps, fineSteps);
      assert_int_equal(differ, 0);
      free(coarse);
      free(fine);
    }
}

static void test_a_presented_free_flight_is_the_parabola(void** state) {
  (void)state;
  const pdStepper steppers[] = {pd_stepperRK4Adaptive, pd_stepperRK43Embedded, pd_stepperImplicit, pd_stepperDopri54};
  const pdVec3 x0 = {0.1, -0.2, 1.0}, v0 = {0.5, 0.3, 2.0};
  for (int i = 0; i < 4; ++i) {
    long steps;
    trace* tr = run_sampled("cube box red 0.2 0.15 0.1\nloc 0.1 -0.2 1  30 1 1 0\nvel 0.5 0.3 2  3 0 1 1\n", 1000,
                            steppers[i], pd_islandsOn, &steps);
    double worstX = 0.0, worstV = 0.0;
    for (int k = 0; k < tr->count; ++k) {
      double t = tr->t[k];
      pdVec3 x = {x0.x + v0.x * t, x0.y + v0.y * t, x0.z + v0.z * t - 0.5 * 9.81 * t * t};
      pdVec3 v = {v0.x, v0.y, v0.z - 9.81 * t};
      worstX = fmax(worstX, pd_v3_norm(pd_v3_sub(tr->b[k].x, x)));
      worstV = fmax(worstV, pd_v3_norm(pd_v3_sub(tr->b[k].v, v)));
    }
    print_message("%s: %ld steps for 600 samples; centre off the parabola by at most %.2e m, velocity %.2e m/s\n",
                  pd_stepper_name(steppers[i]), steps, worstX, worstV);
    assert_true(steps < tr->count / 2);  // the samples lie inside the steps, not at their ends
    assert_true(worstX <= PARABOLA_TOL);
    assert_true(worstV <= PARABOLA_TOL);
    free(tr);
  }
}

static void test_a_presented_resting_box_carries_its_weight(void** state) {
  (void)state;
  long steps;
  trace* tr = run_sampled(
      "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\ncube box red 0.2 0.15 0.1\nloc 0 0 0.05\nmu 0.5\n", 1000,
      pd_stepperImplicit, pd_islandsOn, &steps);
  double weight = 1000.0 * 0.2 * 0.15 * 0.1 * 9.81, worst = 0.0;
  for (int k = 300; k < tr->count; ++k) worst = fmax(worst, fabs(tr->normalForce[k] / weight - 1.0));
  print_message(
      "box at rest: %ld steps for 600 samples; sum of the normal forces off its weight %.4g N by at most "
      "%.2e of it over [0.3, 0.6] s\n",
      steps, weight, worst);
  assert_true(steps < tr->count / 4);
  assert_true(worst <= WEIGHT_REL_TOL);
  free(tr);
}

// A body spinning about no principal axis in zero gravity (smooth, no contacts), sampled at 1 kHz inside the
// Dormand–Prince pair's steps of ~13 ms, against the same run at tol 1e-12: its continuous extension is of fourth
// order, error O(h⁵) like the step's estimate, so the presented angular velocity stays within a small multiple of tol
// (relative to |ω|) between the step ends too. With the extension's last term left out (the cubic Hermite
// interpolant of the same ends and slopes) the samples are off by 2.9e-6 of |ω|.
#define DOPRI_SAMPLE_TOL_FACTOR 10.0

static void test_dopri_presents_a_spinning_box_between_its_steps_to_the_tolerance(void** state) {
  (void)state;
  static const char spin[] = "gravity 0 0 0\ndtmax 1\ncube box red 0.1 0.2 0.3\nvel 0 0 0  720 1 3 0.2\n";
  char text[512];
  snprintf(text, sizeof text, "tol 1e-12\n%s", spin);
  long refSteps, steps;
  trace* ref = run_sampled(text, 1000, pd_stepperDopri54, pd_islandsOff, &refSteps);
  snprintf(text, sizeof text, "tol 1e-7\n%s", spin);
  trace* tr = run_sampled(text, 1000, pd_stepperDopri54, pd_islandsOff, &steps);
  assert_int_equal(tr->count, ref->count);
  double worst = 0.0;
  for (int k = 0; k < tr->count; ++k)
    worst = fmax(worst, pd_v3_norm(pd_v3_sub(tr->b[k].w, ref->b[k].w)) / pd_v3_norm(ref->b[k].w));
  print_message("dopri54 at tol 1e-7: %ld steps for %d samples; presented ω off the tol 1e-12 run's by at most %.2e of "
                "|ω|\n",
                steps, tr->count, worst);
  assert_true(steps < tr->count / 10);
  assert_true(worst <= DOPRI_SAMPLE_TOL_FACTOR * 1e-7);
  free(tr);
  free(ref);
}

// Stopped at times between the samples and resumed: with islands off the same steps and numbers as one call, since no
// tEnd cuts a step (with islands on a tEnd also ends a sync interval, so only sample times keep that: state.h).
static void test_a_run_stopped_between_samples_is_the_run_that_did_not_stop(void** state) {
  (void)state;
  const pdStepper steppers[] = {pd_stepperRK4Adaptive, pd_stepperRK43Embedded, pd_stepperImplicit, pd_stepperDopri54};
  char text[1024];
  snprintf(text, sizeof text, "tend 0.6\nsample 100\n%s", TUMBLE);
  pdModel* m = compile_text(text);
  for (int i = 0; i < 4; ++i) {
    pdStateOptions options = pd_state_options_default();
    options.stepper = steppers[i];
    options.islands = pd_islandsOff;
    pdState *whole = pd_state_create(m, &options), *sliced = pd_state_create(m, &options);
    trace *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
    assert_true(a != NULL && b != NULL);
    assert_true(pd_advance(m, whole, m->settings.tend, keep, a));
    for (double t = 0.0137; t < m->settings.tend; t += 0.0291) assert_true(pd_advance(m, sliced, t, keep, b));
    assert_true(pd_advance(m, sliced, m->settings.tend, keep, b));
    assert_int_equal(a->count, b->count);
    int differ = 0;
    for (int k = 0; k < a->count; ++k) differ += a->t[k] != b->t[k] || !same_state(&a->b[k], &b->b[k]);
    print_message("%s, islands off, stopped 21 times between samples: %ld and %ld steps, %d of %d samples differ\n",
                  pd_stepper_name(steppers[i]), whole->count.accepted, sliced->count.accepted, differ, a->count);
    assert_int_equal(whole->count.accepted, sliced->count.accepted);
    assert_int_equal(differ, 0);
    free(a);
    free(b);
    pd_state_free(whole);
    pd_state_free(sliced);
  }
  pd_model_free(m);
}

enum { READ_BODIES = 3, READ_CONTACTS = 16, READ_SAMPLES = 801 };

// What an observer saw at each sample: every moving body and, at the samples it reads them, the contacts and energy.
typedef struct readings {
  int count, every;  // every: the contacts are read at samples k with k % every == 0
  const pdModel* model;
  pdBodyState b[READ_SAMPLES][READ_BODIES];
  int contacts[READ_SAMPLES];
  pdContactReport c[READ_SAMPLES][READ_CONTACTS];
  double energy[READ_SAMPLES];
  int sliding, sticking;  // contacts read slipping and holding
} readings;

static bool read_sample(const pdModel* model, const pdState* state, void* user) {
  readings* r = user;
  if (r->count == READ_SAMPLES) return false;
  int k = r->count++;
  for (int j = 0; j < model->movingCount && j < READ_BODIES; ++j)
    r->b[k][j] = pd_state_body(model, state, model->movingBodies[j]);
  if (k % r->every != 0) return true;
  r->contacts[k] = pd_state_contact_count(state);
  for (int i = 0; i < r->contacts[k] && i < READ_CONTACTS; ++i) {
    r->c[k][i] = pd_state_contact(state, i);
    if (r->c[k][i].fn > 0.0) r->c[k][i].slip ? ++r->sliding : ++r->sticking;
  }
  r->energy[k] = pd_state_energy(model, state);
  return true;
}

static bool same_bits(const void* a, const void* b, size_t n) { return memcmp(a, b, n) == 0; }

// Field by field: the report's padding is not part of it.
static bool same_report(const pdContactReport* a, const pdContactReport* b) {
  return a->bodyA == b->bodyA && a->bodyB == b->bodyB && a->edgeEdge == b->edgeEdge && a->featureA == b->featureA &&
         a->featureB == b->featureB && same_bits(&a->point, &b->point, sizeof a->point) &&
         same_bits(&a->normal, &b->normal, sizeof a->normal) && same_bits(&a->depth, &b->depth, sizeof a->depth) &&
         same_bits(&a->fn, &b->fn, sizeof a->fn) && same_bits(&a->ft, &b->ft, sizeof a->ft) && a->slip == b->slip &&
         same_bits(&a->springScale, &b->springScale, sizeof a->springScale);
}

static readings* run_read(const char* text, pdIslands islands, int every) {
  pdModel* m = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.islands = islands;
  pdState* s = pd_state_create(m, &options);
  readings* r = calloc(1, sizeof *r);
  assert_non_null(r);
  r->every = every;
  assert_true(pd_advance(m, s, m->settings.tend, read_sample, r));
  pd_state_free(s);
  pd_model_free(m);
  return r;
}

static void test_contacts_read_when_needed_are_those_evaluated_at_every_sample(void** state) {
  (void)state;
  // a box sliding and tumbling to rest, and one landing flat beside it that sticks and (sleep on) falls asleep
  static const char SCENE[] =
      "tend 0.8\nsample 1000\nsleep %s\n"
      "cube floor grey 3 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\n"
      "cube box red 0.2 0.15 0.1\nloc 0 0 0.12  30 1 1 0\nvel 0.4 0 0  5 0 1 0\nmu 0.5\nrestitution 0.5\n"
      "cube rest blue 0.2 0.2 0.2\nloc 0.9 0 0.102\nmu 0.5\n";
  for (int variant = 0; variant < 3; ++variant) {
    pdIslands islands = variant == 0 ? pd_islandsOff : pd_islandsOn;
    char text[1024];
    snprintf(text, sizeof text, SCENE, variant == 2 ? "on" : "off");
    readings* every = run_read(text, islands, 1);
    readings* some = run_read(text, islands, 9);
    assert_int_equal(every->count, some->count);
    assert_true(every->sliding > 0 && every->sticking > 0);
    for (int k = 0; k < every->count; ++k) {
      assert_true(same_bits(every->b[k], some->b[k], sizeof every->b[k]));
      if (k % 9 != 0) continue;
      assert_int_equal(every->contacts[k], some->contacts[k]);
      assert_true(same_bits(&every->energy[k], &some->energy[k], sizeof every->energy[k]));
      for (int i = 0; i < every->contacts[k] && i < READ_CONTACTS; ++i)
        assert_true(same_report(&every->c[k][i], &some->c[k][i]));
    }
    free(every);
    free(some);
  }
}

// A lone body's island presents the same step's contacts at every sample, and the scene's list gathered from it is
// renewed where a presentation and an evaluation change it (pd_contact_set_gather): with islands on, its contacts read
// at every sample and at every 9th are those of islands off bit for bit, and so are its bodies at every sample,
// sliding, turning and sticking. (Not the energy: with islands off it counts the springs the presented step's contact
// history keeps, which a gather does not carry.) With sleep on (islands only) the body falls asleep, and the runs
// reading at every sample and at every 9th agree.
static void compare_lone(const readings* ref, const readings* r, const char* what) {
  assert_int_equal(ref->count, r->count);
  int read = 0;
  for (int k = 0; k < ref->count; ++k) {
    assert_true(same_bits(ref->b[k], r->b[k], sizeof ref->b[k]));
    if (k % r->every != 0 || k % ref->every != 0) continue;
    assert_int_equal(ref->contacts[k], r->contacts[k]);
    for (int i = 0; i < ref->contacts[k] && i < READ_CONTACTS; ++i, ++read)
      assert_true(same_report(&ref->c[k][i], &r->c[k][i]));
  }
  print_message("%s, contacts read at every %d sample(s): %d contact readings the same\n", what, r->every, read);
}

static void test_a_lone_body_gathered_at_every_sample_is_islands_off(void** state) {
  (void)state;
  static const char FLOOR[] =
      "tend 0.8\nsample 1000\nsleep %s\ncube floor grey 3 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\n%s";
  // a box sliding and turning to rest on the floor
  static const char BOX[] =
      "cube box red 0.2 0.15 0.1\nloc 0 0 0.0505\nvel 0.8 0 0  4 0 0 1\nmu 0.5\nrestitution 0.5\n";
  // a plank tipping off a fixed ridge (a cube on its edge) onto the floor: the ridge's corners on the plank's face,
  // normals that turn with it
  static const char PLANK[] = "cube ridge grey 0.2 0.2 0.2\nfixed\nloc 0.8 0 0.05  45 1 0 0\nmu 0.5\n"
                              "cube plank blue 0.4 0.3 0.02\nloc 0.8 0.04 0.2016\nmu 0.5\nrestitution 0.3\n";
  const char* bodies[2] = {BOX, PLANK};
  char text[1024];
  for (int scene = 0; scene < 2; ++scene) {
    snprintf(text, sizeof text, FLOOR, "off", bodies[scene]);
    readings* off = run_read(text, pd_islandsOff, 1);
    assert_true(off->sliding > 0 && off->sticking > 0);
    for (int every = 1; every <= 9; every += 8) {
      readings* on = run_read(text, pd_islandsOn, every);
      compare_lone(off, on, scene == 0 ? "box, islands on against off" : "plank, islands on against off");
      free(on);
    }
    free(off);
  }
  snprintf(text, sizeof text, FLOOR, "on", BOX);
  readings* all = run_read(text, pd_islandsOn, 1);
  readings* some = run_read(text, pd_islandsOn, 9);
  compare_lone(all, some, "box, sleep on, islands on");
  free(all);
  free(some);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_the_samples_do_not_change_the_steps),
      cmocka_unit_test(test_a_presented_free_flight_is_the_parabola),
      cmocka_unit_test(test_dopri_presents_a_spinning_box_between_its_steps_to_the_tolerance),
      cmocka_unit_test(test_a_presented_resting_box_carries_its_weight),
      cmocka_unit_test(test_a_run_stopped_between_samples_is_the_run_that_did_not_stop),
      cmocka_unit_test(test_contacts_read_when_needed_are_those_evaluated_at_every_sample),
      cmocka_unit_test(test_a_lone_body_gathered_at_every_sample_is_islands_off),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
