// Sleeping (engine/src/sleep.h, engine/src/islands.c; docs/sleeping.md): an island at rest stops being integrated
// until a body may reach it or an applied force changes, and wakes with its frozen state.
// - a box resting on a floor falls asleep within SETTLE_WITHIN_S, and from then on its state is frozen bit for bit
//   (every sample repeats the one it fell asleep at) and within REST_TOL_REL of the run that never sleeps; the
//   body-seconds asleep are the time it slept;
// - a sleeping pile (a stack of two and a box beside it) woken by a light falling box: the pile sleeps before the
//   box reaches it and wakes when it may; every body's position and velocity at every sample match the same run
//   with `sleep off` within WOKEN_POS_TOL_REL and WOKEN_VEL_TOL_REL;
// - a slab touched by a box that slides across it (pushed by a constant force beyond friction) never sleeps
//   while the box slides on it; alone, the same slab falls asleep;
// - an applied force that changes (a ramp) wakes a sleeping box: it falls asleep while friction holds it, wakes,
//   and slides off when the force passes friction, as the run that never sleeps does (WOKEN_*_TOL_REL);
// - a box sliding down an incline under a loose tol (1e-1: a speed threshold of 0.1 m/s) never falls asleep: its
//   steady acceleration would take it past the threshold long before the run ends; its speed at the end is the
//   closed form's within SLIDE_SPEED_TOL_REL;
// - threads: the woken pile gives every body's numbers at every sample and every counter bit for bit on 1, 2 and 3
//   threads;
// - a cube that rings on its edges within the speed threshold after it lands (the Gedanken experiment
//   d3_landing_energy's scene at tol 0.1) falls asleep, the acceleration read over its window of slow intervals (its
//   velocity's drift), and its frozen height is the resting height that tol 1e-7 integrates within
//   RINGING_REST_TOL_REL.
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
#include "polydyn/state.h"
#include "scene_run.h"

// A box placed on the floor at zero deflection rings down in a few of its contact periods (~4 ms) and the implicit
// stepper brings it to ~1e-18 m/s; with the settle time of four periods it sleeps long before this.
#define SETTLE_WITHIN_S 0.2
// Frozen against integrated at rest: the integrated box keeps sinking by what it moves below the speed threshold
// (tol · vmax, ~3e-6 m/s) in the rest of the run: 1e-6 of its size bounds that and the springs' rounding.
#define REST_TOL_REL 1e-6
// The woken pile against the run that never slept. Both are the same integration at tol 1e-6; the woken run starts
// the impact from the frozen state, the other from the state integrated on, which differ by what the bodies moved
// below the speed threshold. Impacts amplify any difference: the run's own error (this scene at tol 1e-6 against
// 1e-7, both with sleep off) is 9.1e-4 of the light box's size and 0.012 of vmax (|Δv| + |Δω| r, during its bounces
// on the stack); sleeping may add no more than about that (measured: 1.5e-4 and 0.011).
#define WOKEN_POS_TOL_REL 1e-3  // of each body's size
#define WOKEN_VEL_TOL_REL 0.02  // of vmax, on |Δv| + |Δω| r

// The ringing cube's frozen height against the rest that tol 1e-7 integrates (measured 1.3e-4 of its size; the run at
// tol 0.1 that never sleeps rocks on and sinks 9.7e-4 below it by the end).
#define RINGING_REST_TOL_REL 2e-4

// The incline's box: the run at tol 1e-1 against g (sin θ − μ cos θ) t; the onset and the implicit steps at that tol
// are within 1e-4 of it (measured), a box frozen early is off by nearly 100 %.
#define SLIDE_SPEED_TOL_REL 0.02

enum { MAX_BODIES = 6, MAX_SAMPLES = 201 };

typedef struct trace {
  int count, bodies;
  double t[MAX_SAMPLES];
  pdBodyState body[MAX_SAMPLES][MAX_BODIES];
  pdCounters counts[MAX_SAMPLES];
} trace;

static bool record_trace(const pdModel* model, const pdState* s, void* user) {
  trace* r = user;
  if (r->count == MAX_SAMPLES) return false;
  int k = r->count++;
  r->t[k] = s->t;
  r->bodies = model->movingCount < MAX_BODIES ? model->movingCount : MAX_BODIES;
  for (int j = 0; j < r->bodies; ++j) r->body[k][j] = pd_state_body(model, s, model->movingBodies[j]);
  r->counts[k] = s->count;
  return true;
}

// Runs `text` with the defaults (islands on, the implicit stepper) on `threads` threads.
static trace* run_trace(const char* text, int threads, pdModel** modelOut) {
  pdModel* model = compile_text(text);
  pdStateOptions options = pd_state_options_default();
  options.threads = threads;
  pdState* s = pd_state_create(model, &options);
  trace* r = calloc(1, sizeof *r);
  assert_non_null(r);
  assert_true(pd_advance(model, s, model->settings.tend, record_trace, r));
  pd_state_free(s);
  if (modelOut)
    *modelOut = model;
  else
    pd_model_free(model);
  return r;
}

// The same scene run with `sleep on` and with `sleep off` (a setting line put first), on one thread.
typedef struct pair {
  pdModel* model;  // the sleeping run's (the same bodies and settings as the other's)
  trace *slept, *awake;
} pair;

static trace* run_with_sleep(const char* text, bool on, pdModel** modelOut) {
  size_t n = strlen(text) + 16;
  char* scene = malloc(n);
  assert_non_null(scene);
  snprintf(scene, n, "sleep %s\n%s", on ? "on" : "off", text);
  trace* r = run_trace(scene, 1, modelOut);
  free(scene);
  return r;
}

static pair run_pair(const char* text) {
  pair p = {NULL, NULL, NULL};
  p.slept = run_with_sleep(text, true, &p.model);
  p.awake = run_with_sleep(text, false, NULL);
  return p;
}

static void free_pair(pair* p) {
  free(p->slept);
  free(p->awake);
  pd_model_free(p->model);
}

// Every body at every sample of a and b within the tolerances (positions of each body's size, velocities of vmax).
static void assert_close(const pdModel* model, const trace* a, const trace* b, double posTol, double velTol) {
  assert_int_equal(a->count, b->count);
  double worstX = 0.0, worstV = 0.0;
  for (int k = 0; k < a->count; ++k)
    for (int j = 0; j < a->bodies; ++j) {
      const pdBody* body = &model->bodies[model->movingBodies[j]];
      const pdBodyState *p = &a->body[k][j], *q = &b->body[k][j];
      double dx = pd_v3_norm(pd_v3_sub(p->x, q->x)) / body->size;
      double dv = (pd_v3_norm(pd_v3_sub(p->v, q->v)) + pd_v3_norm(pd_v3_sub(p->w, q->w)) * body->radius) /
                  model->settings.vmax;
      worstX = fmax(worstX, dx);
      worstV = fmax(worstV, dv);
    }
  print_message("worst position difference %.3g of size, velocity %.3g of vmax\n", worstX, worstV);
  assert_true(worstX <= posTol);
  assert_true(worstV <= velTol);
}

static bool same_body_state(const pdBodyState* a, const pdBodyState* b) {
  return memcmp(&a->x, &b->x, sizeof a->x) == 0 && memcmp(&a->q, &b->q, sizeof a->q) == 0 &&
         memcmp(&a->v, &b->v, sizeof a->v) == 0 && memcmp(&a->w, &b->w, sizeof a->w) == 0;
}

// ---------------------------------------------------------------- a box at rest

static const char* const restingBox =
    "tend 1\nsample 100\n"
    "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\n"
    "cube box tan 0.2 0.15 0.1\nloc 0.1 -0.2 0.05 20 0 0 1\n";

static void box_at_rest_sleeps_frozen(void** unused) {
  (void)unused;
  pair p = run_pair(restingBox);
  const pdModel* model = p.model;
  const trace *slept = p.slept, *awake = p.awake;
  int first = -1;
  for (int k = 0; k < slept->count && first < 0; ++k)
    if (slept->counts[k].islandsSlept > 0) first = k;
  assert_true(first >= 0);
  print_message("asleep at t = %g s\n", slept->t[first]);
  assert_true(slept->t[first] <= SETTLE_WITHIN_S);
  // frozen: every later sample repeats the one it fell asleep at, never woken
  for (int k = first; k < slept->count; ++k) {
    assert_true(same_body_state(&slept->body[k][0], &slept->body[first][0]));
    assert_int_equal(slept->counts[k].islandsWoken, 0);
  }
  // the accepted steps stop: none after the sample it fell asleep at
  assert_int_equal(slept->counts[slept->count - 1].accepted, slept->counts[first].accepted);
  assert_true(awake->counts[awake->count - 1].accepted > awake->counts[first].accepted);
  // body-seconds asleep: the one body from the time it fell asleep (at or before that sample) to the end
  double asleep = slept->counts[slept->count - 1].bodySecondsAsleep;
  double tEnd = slept->t[slept->count - 1];
  assert_true(asleep >= tEnd - slept->t[first] - 1e-12 && asleep <= tEnd - slept->t[first - 1] + 1e-12);
  assert_true(awake->counts[awake->count - 1].bodySecondsAsleep == 0.0);
  assert_int_equal(awake->counts[awake->count - 1].islandsSlept, 0);
  assert_close(model, slept, awake, REST_TOL_REL, REST_TOL_REL);
  free_pair(&p);
}

// ---------------------------------------------------------------- a sleeping pile woken by a falling box

static const char* const wokenPile =
    "tend 1\nsample 100\n"
    "cube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n"
    "cube b0 tan 0.2 0.2 0.2\nloc 0 0 0.1\n"
    "cube b1 tan 0.2 0.2 0.2\nloc 0.01 0 0.3\n"
    "cube b2 tan 0.2 0.2 0.2\nloc 0.3 0 0.1\n"
    "cube drop red 0.1 0.1 0.1\nloc 0.03 0.01 0.55 5 0 0 1\nspgrav 0.2\n";

static void woken_pile_matches_never_slept(void** unused) {
  (void)unused;
  pair p = run_pair(wokenPile);
  const pdModel* model = p.model;
  const trace *slept = p.slept, *awake = p.awake;
  // the pile slept before the box came near, and woke
  int impact = -1;  // the first sample at which the stack's top box moves faster than it rests
  for (int k = 1; k < awake->count && impact < 0; ++k)
    if (pd_v3_norm(awake->body[k][1].v) > 1e-3) impact = k;
  assert_true(impact > 0);
  assert_true(slept->counts[impact - 1].bodySecondsAsleep > 0.0);
  const pdCounters* end = &slept->counts[slept->count - 1];
  assert_true(end->islandsSlept >= 2);
  assert_true(end->islandsWoken >= 1);
  assert_close(model, slept, awake, WOKEN_POS_TOL_REL, WOKEN_VEL_TOL_REL);
  free_pair(&p);
}

static void woken_pile_same_on_threads(void** unused) {
  (void)unused;
  trace* one = run_trace(wokenPile, 1, NULL);
  assert_true(one->counts[one->count - 1].islandsWoken >= 1);  // sleep is on by default
  for (int threads = 2; threads <= 3; ++threads) {
    trace* many = run_trace(wokenPile, threads, NULL);
    assert_int_equal(many->count, one->count);
    for (int k = 0; k < one->count; ++k) {
      for (int j = 0; j < one->bodies; ++j) assert_true(same_body_state(&many->body[k][j], &one->body[k][j]));
      const pdCounters *a = &one->counts[k], *b = &many->counts[k];
      assert_int_equal(a->accepted, b->accepted);
      assert_int_equal(a->derivatives, b->derivatives);
      assert_int_equal(a->islandsSlept, b->islandsSlept);
      assert_int_equal(a->islandsWoken, b->islandsWoken);
      assert_true(a->bodySecondsAsleep == b->bodySecondsAsleep);
    }
    free(many);
  }
  free(one);
}

// ---------------------------------------------------------------- touched: no sleep

// A 1.2 m slab resting on the floor, and a box on it pushed along x by a constant force 10 % beyond its friction limit
// (μ m g = 0.5 × 1.5 kg × 9.81 m/s² = 7.36 N; 8.1 N): it slides across the slab, 0.25 m in the second.
static const char* const touchedSlab =
    "tend 1\nsample 100\n"
    "cube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n"
    "cube slab tan 1.2 0.6 0.1\nloc 0 0 0.05\nspgrav 5\n"
    "cube box red 0.15 0.1 0.1\nloc -0.5 0 0.15\nforce 8.1 0 0\n";
static const char* const aloneSlab =
    "tend 1\nsample 100\n"
    "cube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n"
    "cube slab tan 1.2 0.6 0.1\nloc 0 0 0.05\nspgrav 5\n";

static void touched_island_stays_awake(void** unused) {
  (void)unused;
  trace* touched = run_trace(touchedSlab, 1, NULL);
  // the box slides across the slab over the whole run and stays on it
  const pdBodyState* end = &touched->body[touched->count - 1][1];
  assert_true(end->x.x > -0.4 && end->x.x < 0.6 && end->x.z > 0.1);
  assert_true(pd_v3_norm(end->v) > 0.1);
  for (int k = 0; k < touched->count; ++k) {
    assert_int_equal(touched->counts[k].islandsSlept, 0);
    assert_true(touched->counts[k].bodySecondsAsleep == 0.0);
  }
  trace* alone = run_trace(aloneSlab, 1, NULL);
  assert_true(alone->counts[alone->count - 1].islandsSlept == 1);
  free(touched);
  free(alone);
}

// ---------------------------------------------------------------- an applied force wakes

// A box on the floor pushed along x by a ramp from 0 at 4 N/s: friction (μ m g = 0.5 × 1.5 kg × 9.81 m/s²
// = 7.36 N) holds it until t ≈ 1.84 s, then it slides.
static const char* const rampBox =
    "tend 2\nsample 100\n"
    "cube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n"
    "cube box red 0.15 0.1 0.1\nloc 0 0 0.05\nforce 0 0 0 ramp 4 0 0\n";

static void force_change_wakes(void** unused) {
  (void)unused;
  pair p = run_pair(rampBox);
  const pdModel* model = p.model;
  const trace *slept = p.slept, *awake = p.awake;
  const pdCounters* end = &slept->counts[slept->count - 1];
  print_message("slept %ld, woken %ld, %.3g body-seconds asleep\n", end->islandsSlept, end->islandsWoken,
                end->bodySecondsAsleep);
  assert_true(end->islandsSlept >= 1);
  assert_true(end->islandsWoken >= 1);
  assert_true(end->bodySecondsAsleep > 0.0);
  // it slides at the end, as the run that never slept
  assert_true(slept->body[slept->count - 1][0].v.x > 1e-3);
  assert_close(model, slept, awake, WOKEN_POS_TOL_REL, WOKEN_VEL_TOL_REL);
  free_pair(&p);
}

// ---------------------------------------------------------------- an accelerating body: no sleep

// A 0.1 m box on a slab tilted by 35°, μ = 0.5 < tan 35°: it slides from rest at g (sin 35° − 0.5 cos 35°)
// = 1.61 m/s². At tol 1e-1 it stays below the speed threshold (0.1 m/s) for its first 0.06 s, longer than its settle
// time: only the horizon of the acceleration threshold (the time left) keeps it awake.
static const char* const inclineBox =
    "tend 1\nsample 100\ntol 1e-1\nvmax 1\n"
    "cube slab grey 2 1 0.2\nfixed\nloc 0 0 0  35 0 1 0\nmu 0.5\n"
    "cube box red 0.1 0.1 0.1\nloc 0.086036465452656904 0 0.12287280664334876  35 0 1 0\nmu 0.5\n";

static void accelerating_box_stays_awake(void** unused) {
  (void)unused;
  trace* r = run_trace(inclineBox, 1, NULL);
  const double theta = 35.0 * 3.14159265358979323846 / 180.0, g = 9.81;
  double expected = g * (sin(theta) - 0.5 * cos(theta)) * r->t[r->count - 1];
  double speed = pd_v3_norm(r->body[r->count - 1][0].v);
  print_message("speed at the end %.6g m/s, closed form %.6g; slept %ld\n", speed, expected,
                r->counts[r->count - 1].islandsSlept);
  assert_int_equal(r->counts[r->count - 1].islandsSlept, 0);
  assert_true(fabs(speed / expected - 1.0) < SLIDE_SPEED_TOL_REL);
  free(r);
}

// ---------------------------------------------------------------- ringing within the tolerance: sleep

// d3_landing_energy's scene (gedanken/group_d.c): a 0.1 m cube of 1 kg thrown spinning onto a floor, μ 2, stiff
// tangential dampers. At tol 0.1 (a speed threshold of 0.1 m/s) it stops by 0.31 s and then rocks on its edges at
// ~2 kHz, two corners lifting and landing, at ~1e-3 of the threshold: each 0.25 ms sample interval sees accelerations
// of m/s², which over the 0.3 s left would pass the threshold, but its velocity goes nowhere. At tol 1e-7 it rests
// on its four corners.
static const char* const ringingCube =
    "tend 0.6\nsample 4000\ntol %g\nvmax 1\n"
    "cube floor grey 2 1 0.2\nfixed\nloc 0.5 0 -0.1\nmu 2\nrestitution 0.01\nkn 2e+06\nkt 2e+06\nct 20000\n"
    "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nvel 0.5 0 0.5  572.95779513082323 0 1 0\nmu 2\nrestitution 0.01\n"
    "kn 2e+06\nkt 2e+06\nct 20000\n";

static void ringing_cube_sleeps(void** unused) {
  (void)unused;
  char text[512];
  double heights[2];
  pdCounters counts[2];
  const double tols[2] = {0.1, 1e-7};
  for (int k = 0; k < 2; ++k) {
    snprintf(text, sizeof text, ringingCube, tols[k]);
    pdModel* model = compile_text(text);
    pdState* s = NULL;
    record* r = run(model, &s);
    heights[k] = r->body[0][r->count - 1].x.z;
    counts[k] = s->count;
    free(r);
    pd_state_free(s);
    pd_model_free(model);
  }
  print_message("tol 0.1: slept %ld, %.3g s asleep, height %.9f m; tol 1e-7: %.9f m\n", counts[0].islandsSlept,
                counts[0].bodySecondsAsleep, heights[0], heights[1]);
  assert_true(counts[0].islandsSlept >= 1);
  assert_true(counts[0].bodySecondsAsleep >= 0.2);  // asleep within 0.1 s of its stop, to the end
  assert_true(fabs(heights[0] - heights[1]) <= RINGING_REST_TOL_REL * 0.1);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(box_at_rest_sleeps_frozen),
      cmocka_unit_test(woken_pile_matches_never_slept),
      cmocka_unit_test(woken_pile_same_on_threads),
      cmocka_unit_test(touched_island_stays_awake),
      cmocka_unit_test(force_change_wakes),
      cmocka_unit_test(accelerating_box_stays_awake),
      cmocka_unit_test(ringing_cube_sleeps),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
