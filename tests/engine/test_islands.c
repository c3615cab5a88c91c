// Islands (engine/src/islands.c; docs/integration.md): with pd_islandsOn the moving bodies
// advance between output samples in islands, each with its own steps and contact events.
// - two groups far apart (a resting stack in one corner, a bouncing cube in the other) give, body for body,
//   the same numbers bit for bit as each group run alone with islands on (an island's model holds its own
//   bodies and the fixed ones, in scene order, so the same bodies compute the same numbers whatever else
//   the scene holds), and stay within a stated tolerance of each group alone with islands off (measured: 0,
//   each group being one island throughout);
// - every body in one island from start to end, with the samples as the only sync times: the same numbers
//   bit for bit as islands off; also with a vmax that would cut the samples, when cutting splits no island
//   (a bouncing cube alone, a stack);
// - run to run: the same numbers bit for bit (a pile of ten boxes);
// - merge: two cubes flying at each other start as two islands, become one and bounce with the requested
//   restitution (closed form: exit speed / approach speed = e), within 0.01 as with islands off;
// - free flight: two spinning cubes thrown far apart take, bit for bit, the steps each takes alone with islands
//   off (a free body is not cut at the sync times);
// - split: two cubes that start touching and fly apart start as one island and end as two, their free
//   flight untouched (constant velocities, bit for bit);
// - apart: two cubes turned 45° resting side by side, their boxes overlapping but their faces 0.083 m apart,
//   are two islands at every sample (the separating-axis test), and agree with islands off within
//   GROUP_OFF_TOL_REL;
// - a pile of ten boxes (cases/bench/pile_10.scene): finite numbers, penetration below 3 δ_max, no energy
//   gained beyond the integration error;
// - threads (pdState.threads): a pile of 30 boxes in two layers gives, with 2 and 3 threads, every body's x, q,
//   v, ω at every sample, the contact counts and every counter bit for bit as with 1 thread (each island's
//   computation is its own: the split only decides which thread runs it); and a stack of twenty boxes, one
//   island throughout, likewise, the other threads serving its help desk (some half loops run by them); and a
//   layer of 132 bricks, one island of more bodies than PD_HELP_MIN_BODIES (its per-body loops split too);
// - a free body reached late: on the pile of 1 000 (cases/bench/pile_1000.scene, dropped from rest) to 0.2 s, every
//   box that no contact has touched yet (its x, y and orientation bit for bit as at the start) is on its free fall's
//   parabola at every sample, within FREE_FALL_TOL (a free body that another body's box reached at a sync time
//   inside a sample interval, and that the partition then left alone, once kept that time's numbers to the next);
// - a free body reached in the first sample interval, before any island exists (two blocks thrown at a wall,
//   cases/hard/thrown_at_wall.scene): it joins, and the run agrees with islands off until the first wall impact;
// - a lone body: a scene of one moving body, run across samples in one run of its island's steps, gives every sample
//   and counter bit for bit as the interval loop (which a step observer forces): a cube thrown, bouncing and falling
//   asleep, and a cube at rest under a growing force, asleep and woken again and again; in one call, in slices that
//   end between samples, stopped by the observer and resumed, and on two threads;
// - stage timers (pdState.stageSeconds): on one thread, the stages timed whole (broad phase, interference,
//   contact analysis, observe; laps of one stopwatch or intervals of their own, never overlapping) each ran and
//   add up to no more than the time spent in pd_advance.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "help_desk.h"
#include "islands.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "scene_run.h"

#define RESTITUTION_TOL 0.01       // absolute, on e (as tests/engine/test_onsets.c)
#define PENETRATION_MAX_DELTA 3.0  // of the pair's δ_max (the soak's limit)
#define ENERGY_GAIN_TOL 1e-6       // relative to |E(0)|: integration error only (tol 1e-6 of the scene)
// Islands on against islands off for a group alone: both are adaptive RK4 at the scene's tol (1e-6 of the
// body size per step), with different step sequences (samples cut the steps the same way, islands' error
// norms see fewer components); a resting stack and a bounce then agree to well below 1e-4 of a body size.
#define GROUP_OFF_TOL_REL 1e-4

enum { MAX_BODIES = 32, MAX_SAMPLES = 1001 };
// contact_list.h's PD_HELP_MIN_CONTACTS: loops shorter than this are never split
#define PD_TEST_HELP_MIN_CONTACTS 128

typedef struct trace {
  int count, bodies;
  double t[MAX_SAMPLES];
  pdBodyState body[MAX_SAMPLES][MAX_BODIES];  // by moving-body order
  int islands[MAX_SAMPLES];                   // pd_island_count at the sample
  int contacts[MAX_SAMPLES];                  // pd_state_contact_count at the sample
  double energy[MAX_SAMPLES];
  double penetration;  // deepest contact over all samples, in its pair's δ_max
  bool finite;
} trace;

static bool record_trace(const pdModel* model, const pdState* s, void* user) {
  trace* r = user;
  if (r->count == MAX_SAMPLES) return false;
  int k = r->count++;
  r->t[k] = s->t;
  r->bodies = model->movingCount < MAX_BODIES ? model->movingCount : MAX_BODIES;
  for (int j = 0; j < r->bodies; ++j) {
    pdBodyState b = pd_state_body(model, s, model->movingBodies[j]);
    r->body[k][j] = b;
    r->finite = r->finite && pd_v3_isfinite(b.x) && pd_v3_isfinite(b.v) && pd_v3_isfinite(b.w) && isfinite(b.q.w);
  }
  r->islands[k] = pd_island_count(s);
  r->contacts[k] = pd_state_contact_count(s);
  r->energy[k] = pd_state_energy(model, s);
  for (int c = 0; c < pd_state_contact_count(s); ++c) {
    pdContactReport rep = pd_state_contact(s, c);
    r->penetration = fmax(r->penetration, rep.depth / pd_model_pair_delta_max(model, rep.bodyA, rep.bodyB));
  }
  return true;
}

// Runs `model` to its tend with the given island mode and threads; the final state to *stateOut when not NULL.
static trace* run_threads(const pdModel* model, pdIslands islands, int threads, pdState** stateOut) {
  trace* r = calloc(1, sizeof *r);
  assert_non_null(r);
  r->finite = true;
  pdStateOptions options = pd_state_options_default();
  options.islands = islands;
  options.threads = threads;
  pdState* s = pd_state_create(model, &options);
  bool done = pd_advance(model, s, model->settings.tend, record_trace, r);
  assert_true(done);
  assert_false(s->failed);
  if (stateOut)
    *stateOut = s;
  else
    pd_state_free(s);
  return r;
}

// The same on one thread.
static trace* run_islands(const pdModel* model, pdIslands islands, pdState** stateOut) {
  return run_threads(model, islands, 1, stateOut);
}

static bool same_body(const pdBodyState* a, const pdBodyState* b) { return memcmp(a, b, sizeof *a) == 0; }

static double max_abs(double a, double b, double c) { return fmax(fabs(a), fmax(fabs(b), fabs(c))); }

// ---------------------------------------------------------------- two groups far apart

#define SETTINGS "tend 0.6\nsample 100\nvmax 4\n"
#define FLOOR "cube floor grey 6 6 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.5\n"
// a stack of two 0.2 m boxes in one corner, 1 mm gaps, settling
#define STACK                                                           \
  "cube s1 tan 0.2 0.2 0.2\nloc -2 -2 0.101\nmu 0.5\nrestitution 0.5\n" \
  "cube s2 tan 0.2 0.2 0.2\nloc -2 -2 0.302\nmu 0.5\nrestitution 0.5\n"
// a tilted 0.2 m cube dropped from 0.5 m in the other corner, bouncing (e 0.8); the same size as the stack's,
// so that the sync times (a function of vmax and the smallest moving body) are the same in all three scenes
#define BOUNCER "cube b red 0.2 0.2 0.2\nloc 2 2 0.5 20 1 1 0\nmu 0.5\nrestitution 0.8\n"

static void test_far_groups_compute_as_if_alone(void** state) {
  (void)state;
  pdModel* both = compile_text(SETTINGS FLOOR STACK BOUNCER);
  pdModel* stack = compile_text(SETTINGS FLOOR STACK);
  pdModel* bouncer = compile_text(SETTINGS FLOOR BOUNCER);
  trace* on = run_islands(both, pd_islandsOn, NULL);
  trace* stackOn = run_islands(stack, pd_islandsOn, NULL);
  trace* bouncerOn = run_islands(bouncer, pd_islandsOn, NULL);
  trace* stackOff = run_islands(stack, pd_islandsOff, NULL);
  trace* bouncerOff = run_islands(bouncer, pd_islandsOff, NULL);
  assert_int_equal(on->count, stackOn->count);
  assert_int_equal(on->count, bouncerOn->count);
  assert_int_equal(on->count, stackOff->count);
  double worstOff = 0.0;
  bool bounced = false;
  for (int k = 0; k < on->count; ++k) {
    assert_true(on->islands[k] >= 2 || k == 0);  // the groups never join
    for (int j = 0; j < 2; ++j) {
      if (!same_body(&on->body[k][j], &stackOn->body[k][j]))
        fail_msg("sample %d, stack body %d: not the same bits as the stack alone", k, j);
      const pdBodyState *a = &on->body[k][j], *b = &stackOff->body[k][j];
      worstOff = fmax(worstOff, max_abs(a->x.x - b->x.x, a->x.y - b->x.y, a->x.z - b->x.z) / 0.2);
    }
    if (!same_body(&on->body[k][2], &bouncerOn->body[k][0]))
      fail_msg("sample %d, bouncer: not the same bits as the bouncer alone", k);
    const pdBodyState *a = &on->body[k][2], *b = &bouncerOff->body[k][0];
    worstOff = fmax(worstOff, max_abs(a->x.x - b->x.x, a->x.y - b->x.y, a->x.z - b->x.z) / 0.2);
    bounced = bounced || on->body[k][2].v.z > 0.5;
  }
  assert_true(bounced);  // the case is what it says: the cube bounced while the stack settled
  print_message("groups: %d samples bit for bit as alone; against islands off alone: %.3g of a body size\n", on->count,
                worstOff);
  assert_true(worstOff < GROUP_OFF_TOL_REL);
  free(on), free(stackOn), free(bouncerOn), free(stackOff), free(bouncerOff);
  pd_model_free(both), pd_model_free(stack), pd_model_free(bouncer);
}

// ---------------------------------------------------------------- one island = islands off

static void expect_islands_off_bits(const char* text, const char* what) {
  // with islands off nothing sleeps (docs/sleeping.md): sleep off here too, for the same steps
  char scene[2048];
  snprintf(scene, sizeof scene, "sleep off\n%s", text);
  pdModel* m = compile_text(scene);
  trace* on = run_islands(m, pd_islandsOn, NULL);
  trace* off = run_islands(m, pd_islandsOff, NULL);
  assert_int_equal(on->count, off->count);
  for (int k = 1; k < on->count; ++k) {
    assert_int_equal(on->islands[k], 1);  // the bodies never part
    for (int j = 0; j < on->bodies; ++j)
      if (!same_body(&on->body[k][j], &off->body[k][j]))
        fail_msg("%s: sample %d, body %d differs from islands off", what, k, j);
  }
  print_message("%s: %d samples bit for bit as islands off\n", what, on->count);
  free(on), free(off);
  pd_model_free(m);
}

static void test_one_island_is_islands_off_bit_for_bit(void** state) {
  (void)state;
  // vmax 0.3 m/s: a body at vmax moves less than 2 % of the boxes' size in a sample interval, so the sync times
  // are the samples (islands.c, sync_parts), where islands off cuts its steps too
  expect_islands_off_bits("tend 0.6\nsample 100\nvmax 0.3\n" FLOOR STACK, "stack, samples only");
  // vmax 4 m/s would cut each sample interval into 16 parts, but cutting splits no island (one body; a stack whose
  // boxes touch), so the samples stay the only sync times (islands.c, cuts_split_islands)
  expect_islands_off_bits(SETTINGS FLOOR STACK, "stack, vmax 4");
  expect_islands_off_bits(SETTINGS FLOOR BOUNCER, "bouncing cube, vmax 4");
}

// ---------------------------------------------------------------- run to run, and a pile's physics

static pdModel* load_pile(void) { return compile_file(PD_SOURCE_DIR "/cases/bench/pile_10.scene"); }

static void test_the_same_bits_run_after_run(void** state) {
  (void)state;
  pdModel* m = load_pile();
  pdState *s1 = NULL, *s2 = NULL;
  trace* a = run_islands(m, pd_islandsOn, &s1);
  trace* b = run_islands(m, pd_islandsOn, &s2);
  assert_int_equal(a->count, b->count);
  assert_true(memcmp(a->body, b->body, sizeof a->body) == 0);
  assert_true(memcmp(&s1->count, &s2->count, sizeof s1->count) == 0);
  assert_true(s1->count.islandsFormed > 1);
  pd_state_free(s1), pd_state_free(s2);
  free(a), free(b);
  pd_model_free(m);
}

static void test_a_pile_keeps_its_physics(void** state) {
  (void)state;
  pdModel* m = load_pile();
  pdState* s = NULL;
  trace* r = run_islands(m, pd_islandsOn, &s);
  assert_true(r->finite);
  double gain = 0.0, lowest = r->energy[0];
  for (int k = 1; k < r->count; ++k) {
    gain = fmax(gain, (r->energy[k] - lowest) / fabs(r->energy[0]));
    lowest = fmin(lowest, r->energy[k]);
  }
  print_message(
      "pile_10, islands on: %ld islands formed (largest %ld), %ld redos; penetration %.3f delta_max, "
      "energy gain %.3g of |E(0)|\n",
      s->count.islandsFormed, s->count.islandsLargest, s->count.islandRedos, r->penetration, gain);
  assert_true(r->penetration < PENETRATION_MAX_DELTA);
  assert_true(gain <= ENERGY_GAIN_TOL);
  assert_true(s->count.islandsLargest > 1);  // boxes did meet
  assert_int_equal(s->count.islandStrays, 0);
  pd_state_free(s);
  free(r);
  pd_model_free(m);
}

// ---------------------------------------------------------------- free flight

// Two spinning cubes thrown far apart, far above a floor: each is free (alone, touching nothing, out of reach
// of the floor) over every sample interval, so it takes the steps it takes alone with islands off, to the bit,
// whatever the sync times.
#define THROWN_SETTINGS "tend 0.3\nsample 100\nvmax 5\n"
#define FAR_FLOOR "cube floor grey 20 20 0.2\nfixed\nloc 0 0 -10\n"
#define THROWN_A "cube a red 0.1 0.1 0.1\nloc -2 0 1\nvel 1 0 3 400 1 2 3\n"
#define THROWN_B "cube b blue 0.1 0.2 0.05\nloc 2 0 1\nvel -1 0.5 2 300 0 1 1\n"

static void test_free_bodies_take_free_flight_steps(void** state) {
  (void)state;
  pdModel* both = compile_text(THROWN_SETTINGS FAR_FLOOR THROWN_A THROWN_B);
  pdModel* a = compile_text(THROWN_SETTINGS FAR_FLOOR THROWN_A);
  pdModel* b = compile_text(THROWN_SETTINGS FAR_FLOOR THROWN_B);
  pdState *sOn = NULL, *sA = NULL, *sB = NULL;
  trace* on = run_islands(both, pd_islandsOn, &sOn);
  trace* offA = run_islands(a, pd_islandsOff, &sA);
  trace* offB = run_islands(b, pd_islandsOff, &sB);
  for (int k = 0; k < on->count; ++k) {
    if (!same_body(&on->body[k][0], &offA->body[k][0])) fail_msg("sample %d: cube a differs from a alone", k);
    if (!same_body(&on->body[k][1], &offB->body[k][0])) fail_msg("sample %d: cube b differs from b alone", k);
  }
  assert_int_equal(sOn->count.accepted, sA->count.accepted + sB->count.accepted);
  assert_int_equal(sOn->count.islandStrays, 0);
  print_message("two free cubes: %ld + %ld steps alone, %ld with islands on\n", sA->count.accepted, sB->count.accepted,
                sOn->count.accepted);
  pd_state_free(sOn), pd_state_free(sA), pd_state_free(sB);
  free(on), free(offA), free(offB);
  pd_model_free(both), pd_model_free(a), pd_model_free(b);
}

// ---------------------------------------------------------------- merge and split

// Two 0.1 m cubes, gravity off, μ 0, e 0.5, face to face along x at ±x0 with speeds ±v.
static pdModel* two_cubes(double x0, double v, double tend) {
  char text[1024];
  snprintf(text, sizeof text,
           "gravity 0 0 0\ntend %.17g\nsample 100\nvmax 2\n"
           "cube a red 0.1 0.1 0.1\nloc %.17g 0 0\nvel %.17g 0 0\nmu 0\nrestitution 0.5\n"
           "cube b blue 0.1 0.1 0.1\nloc %.17g 0 0\nvel %.17g 0 0\nmu 0\nrestitution 0.5\n",
           tend, -x0, v, x0, -v);
  return compile_text(text);
}

static void test_islands_merge_and_bounce_with_the_requested_e(void** state) {
  (void)state;
  pdModel* m = two_cubes(0.3, 1.0, 0.5);  // they meet at t = 0.2 s
  double e[2];
  for (int mode = 0; mode < 2; ++mode) {
    trace* r = run_islands(m, mode ? pd_islandsOn : pd_islandsOff, NULL);
    int last = r->count - 1;
    e[mode] = (r->body[last][1].v.x - r->body[last][0].v.x) / 2.0;
    if (mode) {
      assert_int_equal(r->islands[1], 2);  // apart at first
      bool merged = false;
      for (int k = 0; k < r->count; ++k) merged = merged || r->islands[k] == 1;
      assert_true(merged);
      assert_int_equal(r->islands[last], 2);  // apart again
    }
    free(r);
  }
  print_message("two cubes meeting at 2 m/s: e = %.5f islands off, %.5f islands on (requested 0.5)\n", e[0], e[1]);
  assert_true(fabs(e[0] - 0.5) <= RESTITUTION_TOL);
  assert_true(fabs(e[1] - 0.5) <= RESTITUTION_TOL);
  pd_model_free(m);
}

static void test_an_island_splits_when_its_bodies_part(void** state) {
  (void)state;
  pdModel* m = two_cubes(0.05, -0.5, 0.3);  // touching faces at x = 0, flying apart at 1 m/s
  pdState* s = NULL;
  trace* r = run_islands(m, pd_islandsOn, &s);
  // one island at first (their boxes touch), then one each: three formed, the largest of two
  assert_int_equal(s->count.islandsFormed, 3);
  assert_int_equal(s->count.islandsLargest, 2);
  assert_int_equal(r->islands[r->count - 1], 2);
  pd_state_free(s);
  for (int k = 0; k < r->count; ++k) {
    assert_true(r->body[k][0].v.x == -0.5 && r->body[k][1].v.x == 0.5);  // no contact ever pushed
    assert_true(fabs(r->body[k][0].x.x - (-0.05 - 0.5 * r->t[k])) < 1e-12);
  }
  free(r);
  pd_model_free(m);
}

// Two cubes turned 45° about z resting side by side on the floor: their boxes overlap (centres 0.2 m apart in x
// and y, box half-widths 0.141 m) but their facing faces are 0.083 m apart, far more than they can close over a
// sample interval at rest. The separating-axis test keeps them in islands of their own from start to end; the
// box test alone made them one.
static void test_turned_bodies_apart_whose_boxes_overlap_are_two_islands(void** state) {
  (void)state;
  pdModel* m = compile_text("tend 0.3\nsample 100\n" FLOOR
                            "cube a red 0.2 0.2 0.2\nloc -0.1 -0.1 0.1 45 0 0 1\nmu 0.5\nrestitution 0.5\n"
                            "cube b blue 0.2 0.2 0.2\nloc 0.1 0.1 0.1 45 0 0 1\nmu 0.5\nrestitution 0.5\n");
  pdState* s = NULL;
  trace* on = run_islands(m, pd_islandsOn, &s);
  trace* off = run_islands(m, pd_islandsOff, NULL);
  assert_int_equal(s->count.islandsLargest, 1);
  for (int k = 1; k < on->count; ++k) assert_int_equal(on->islands[k], 2);  // (none at t = 0: none formed yet)
  pd_state_free(s);
  // each cube alone against both in one step sequence: resting, they agree to the integration tolerance
  double worst = 0.0;
  for (int k = 0; k < on->count; ++k)
    for (int j = 0; j < 2; ++j) {
      pdVec3 a = on->body[k][j].x, b = off->body[k][j].x;
      worst = fmax(worst, max_abs(a.x - b.x, a.y - b.y, a.z - b.z) / 0.2);
    }
  print_message(
      "turned cubes side by side: two islands at every sample; position difference to islands off %.2e "
      "of the size\n",
      worst);
  assert_true(worst <= GROUP_OFF_TOL_REL);
  free(on);
  free(off);
  pd_model_free(m);
}

// ---------------------------------------------------------------- threads

enum { PILE_BOXES = 30, PILE_ROW = 5, PILE_LAYER = 15 };  // 30 boxes: two layers of 3 rows of 5
#define PILE_PITCH 0.3        // m between neighbours in a layer (the boxes are 0.2 m long: apart at first)
#define PILE_LAYER_RISE 0.35  // m between the layers: the upper one lands on the lower one
enum { PILE_TEXT = 8192 };

// A pile of 30 boxes dropped in two layers onto a floor, each turned its own way: islands form, merge and
// split, and some boxes fly free at first.
static pdModel* pile_30(void) {
  char text[PILE_TEXT];
  int used = snprintf(text, sizeof text, "tend 0.3\nsample 100\n" FLOOR);
  for (int k = 0; k < PILE_BOXES; ++k) {
    int layer = k / PILE_LAYER, row = k % PILE_LAYER / PILE_ROW, col = k % PILE_ROW;
    double x = PILE_PITCH * (col - 2) + 0.07 * layer, y = PILE_PITCH * (row - 1) + 0.05 * layer;
    double z = 0.15 + PILE_LAYER_RISE * layer, angle = (13 + 37 * k) % 90;
    used += snprintf(text + used, sizeof text - (size_t)used,
                     "cube b%d tan 0.2 0.15 0.1\nloc %.4f %.4f %.4f %.1f 1 %.1f 0.5\nmu 0.5\nrestitution 0.5\n", k, x,
                     y, z, angle, 0.3 * (k % 3));
    assert_true(used < PILE_TEXT);
  }
  return compile_text(text);
}

// Runs m on 2 and 3 threads and checks every sample, counter, warning and the final state (contact springs
// included) against the one-thread run (a, one); returns the half loops the islands got help with on 2 threads.
static long same_bits_on_more_threads(const pdModel* m, const trace* a, const pdState* one) {
  long helped = 0;
  for (int threads = 2; threads <= 3; ++threads) {
    pdState* s = NULL;
    trace* b = run_threads(m, pd_islandsOn, threads, &s);
    if (threads == 2) helped = pd_island_help_served(s);
    assert_int_equal(a->count, b->count);
    assert_true(memcmp(a->t, b->t, sizeof a->t) == 0);
    assert_true(memcmp(a->body, b->body, sizeof a->body) == 0);
    assert_true(memcmp(a->contacts, b->contacts, sizeof a->contacts) == 0);
    assert_true(memcmp(a->islands, b->islands, sizeof a->islands) == 0);
    assert_true(memcmp(&one->count, &s->count, sizeof one->count) == 0);  // steps, retries, islands: all integers
    assert_true(memcmp(one->warnings, s->warnings, sizeof one->warnings) == 0);
    assert_int_equal(one->n, s->n);
    assert_true(memcmp(one->y, s->y, (size_t)one->n * sizeof *one->y) == 0);  // contact springs included
    pd_state_free(s);
    free(b);
  }
  return helped;
}

static void test_threads_give_the_same_bits(void** state) {
  (void)state;
  pdModel* m = pile_30();
  assert_int_equal(m->movingCount, PILE_BOXES);
  pdState* one = NULL;
  trace* a = run_threads(m, pd_islandsOn, 1, &one);
  print_message("pile_30, islands on: %ld islands formed (largest %ld), %ld intervals, %ld redos, %ld steps\n",
                one->count.islandsFormed, one->count.islandsLargest, one->count.islandIntervals, one->count.islandRedos,
                one->count.accepted);
  assert_true(one->count.islandsFormed > PILE_BOXES);  // islands formed and changed: the threads had work
  assert_true(one->count.islandsLargest > 1);
  same_bits_on_more_threads(m, a, one);
  pd_state_free(one);
  free(a);
  pd_model_free(m);
}

enum { STACK_BOXES = 20 };

// Twenty boxes stacked, each turned its own way, settling: one island from start to end, with over a hundred
// contacts.
static pdModel* stack_20(void) {
  char text[PILE_TEXT];
  int used = snprintf(text, sizeof text, "tend 0.1\nsample 200\n" FLOOR);
  for (int k = 0; k < STACK_BOXES; ++k) {
    used += snprintf(text + used, sizeof text - (size_t)used,
                     "cube s%d tan 0.2 0.2 0.1\nloc 0 0 %.4f %d 0 0 1\nmu 0.5\nrestitution 0.5\n", k,
                     0.0505 + 0.1005 * k, 17 * k % 90);
    assert_true(used < PILE_TEXT);
  }
  return compile_text(text);
}

// One island alone in every interval: the other threads, with no island of their own, serve its help desk (half
// its loops over contacts and pairs: help_desk.h), and the results stay the same bit for bit.
static void test_one_island_helped_by_other_threads_gives_the_same_bits(void** state) {
  (void)state;
  pdModel* m = stack_20();
  pdState* one = NULL;
  trace* a = run_threads(m, pd_islandsOn, 1, &one);
  print_message("stack_20: largest island %ld, %d contacts at the end, %ld derivative evaluations\n",
                one->count.islandsLargest, a->contacts[a->count - 1], one->count.derivatives);
  assert_int_equal(one->count.islandsLargest, STACK_BOXES);
  assert_true(a->contacts[a->count - 1] >= PD_TEST_HELP_MIN_CONTACTS);  // loops long enough to be split
  assert_int_equal(pd_island_help_served(one), 0);
  long helped = same_bits_on_more_threads(m, a, one);
  print_message("stack_20 on 2 threads: %ld half loops run by the other thread\n", helped);
  assert_true(helped > 0);
  pd_state_free(one);
  free(a);
  pd_model_free(m);
}

enum { LAYER_ROWS = 11, LAYER_COLUMNS = 12, LAYER_BRICKS = LAYER_ROWS * LAYER_COLUMNS, LAYER_TEXT = 32768 };

// A layer of 132 bricks lying flush side by side on the floor, touching it: one island of more moving bodies than
// PD_HELP_MIN_BODIES, whose per-body loops (poses, force sums, Newton–Euler) are split too.
static pdModel* layer_132(void) {
  static char text[LAYER_TEXT];
  int used = snprintf(text, sizeof text, "tend 0.003\nsample 1000\n" FLOOR);
  for (int k = 0; k < LAYER_BRICKS; ++k) {
    int row = k / LAYER_COLUMNS, col = k % LAYER_COLUMNS;
    used += snprintf(text + used, sizeof text - (size_t)used,
                     "cube k%d brown 0.2 0.1 0.1\nloc %.2f %.2f 0.05\nmu 0.6\nrestitution 0.5\n", k, -1.1 + 0.2 * col,
                     -0.5 + 0.1 * row);
    assert_true(used < LAYER_TEXT);
  }
  return compile_text(text);
}

static void test_a_wide_island_helped_body_by_body_gives_the_same_bits(void** state) {
  (void)state;
  pdModel* m = layer_132();
  assert_true(m->movingCount >= PD_HELP_MIN_BODIES);
  pdState* one = NULL;
  trace* a = run_threads(m, pd_islandsOn, 1, &one);
  print_message("layer_132: largest island %ld, %d contacts at the end\n", one->count.islandsLargest,
                a->contacts[a->count - 1]);
  assert_int_equal(one->count.islandsLargest, LAYER_BRICKS);
  long helped = same_bits_on_more_threads(m, a, one);
  print_message("layer_132 on 2 threads: %ld half loops run by the other thread\n", helped);
  assert_true(helped > 0);
  pd_state_free(one);
  free(a);
  pd_model_free(m);
}

// ---------------------------------------------------------------- a free body reached in the first interval

// Two blocks thrown at a wall (cases/hard/thrown_at_wall.scene), both free at the start; one is reached by the
// other's box inside the first sample interval, when no island exists yet. Until the first block meets the wall
// (about 0.13 s) the islands run each body as islands off does (GROUP_OFF_TOL_REL of the smallest block's 0.22 m);
// after it, the spinning block's wall impact makes the two step sequences diverge, so only the run's end is asked
// for (finite numbers).
#define WALL_FIRST_IMPACT_S 0.12
#define WALL_SMALLEST_SIZE_M 0.22

static void test_a_free_body_reached_in_the_first_interval(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/hard/thrown_at_wall.scene");
  trace* on = run_islands(m, pd_islandsOn, NULL);
  trace* off = run_islands(m, pd_islandsOff, NULL);
  assert_int_equal(on->count, off->count);
  assert_true(fabs(on->t[on->count - 1] - m->settings.tend) < 1e-12);
  double worst = 0.0;
  for (int k = 0; k < on->count; ++k)
    for (int j = 0; j < on->bodies; ++j) {
      const pdBodyState *a = &on->body[k][j], *b = &off->body[k][j];
      assert_true(isfinite(a->x.x) && isfinite(a->x.y) && isfinite(a->x.z) && isfinite(a->v.x));
      if (on->t[k] <= WALL_FIRST_IMPACT_S)
        worst = fmax(worst, max_abs(a->x.x - b->x.x, a->x.y - b->x.y, a->x.z - b->x.z) / WALL_SMALLEST_SIZE_M);
    }
  print_message("thrown at a wall: islands on against off to %.2f s: %.3g of a block size\n", WALL_FIRST_IMPACT_S,
                worst);
  assert_true(worst < GROUP_OFF_TOL_REL);
  free(on), free(off);
  pd_model_free(m);
}

// The stages timed whole are disjoint parts of pd_advance's interval: on one thread their sum cannot exceed it
// (forces, derivative and integrate are left out: they are scaled-up samples and the remainders of them).
// ---------------------------------------------------------------- a lone body across samples

// A scene of one moving body goes, awake, through one run of its island's steps with the interval loop's work done
// at each sample, and asleep from sample to sample counting its time asleep (islands.c, "a lone body across
// samples"); a step observer sends it through the interval loop itself (its stretches start at every sample). Both must give the same samples and counters bit for bit: in one call, in
// slices that end between samples, stopped by the observer and resumed, and on two threads.
#define LONE_SLICE_S 0.0137  // s: a call's length that ends between samples (5 ms and 1 ms apart)

static void count_step(const pdModel* model, const pdState* s, bool start, void* user) {
  (void)model, (void)s, (void)start;
  ++*(long*)user;
}

typedef struct stopAt {
  trace* r;
  int at;  // the observer stops after this many samples (then never again)
} stopAt;

static bool record_and_stop(const pdModel* model, const pdState* s, void* user) {
  stopAt* stop = user;
  bool go = record_trace(model, s, stop->r);
  if (stop->r->count != stop->at) return go;
  stop->at = -1;
  return false;
}

typedef enum loneWay { loneOneCall, loneSlices, loneStopped, loneTwoThreads } loneWay;

static trace* run_lone(const pdModel* m, loneWay way, bool loop, pdCounters* count) {
  trace* r = calloc(1, sizeof *r);
  assert_non_null(r);
  r->finite = true;
  long steps = 0;
  pdStateOptions options = pd_state_options_default();
  if (loop) options.stepObserver = count_step, options.stepUser = &steps;
  if (way == loneTwoThreads) options.threads = 2;
  pdState* s = pd_state_create(m, &options);
  double tend = m->settings.tend;
  if (way == loneSlices) {
    for (double t = LONE_SLICE_S; s->t < tend; t += LONE_SLICE_S)
      assert_true(pd_advance(m, s, fmin(t, tend), record_trace, r));
  } else if (way == loneStopped) {
    stopAt stop = {r, 37};
    int calls = 0;
    while (!pd_advance(m, s, tend, record_and_stop, &stop)) {
      assert_false(s->failed);
      ++calls;
    }
    assert_int_equal(calls, 1);
  } else {
    assert_true(pd_advance(m, s, tend, record_trace, r));
  }
  if (loop) assert_true(steps > 0);
  assert_false(s->failed);
  *count = s->count;
  pd_state_free(s);
  return r;
}

static void expect_same_lone(const trace* a, const pdCounters* ca, const trace* b, const pdCounters* cb,
                             const char* what) {
  assert_int_equal(a->count, b->count);
  for (int k = 0; k < a->count; ++k) {
    if (a->t[k] != b->t[k] || !same_body(&a->body[k][0], &b->body[k][0]) || a->contacts[k] != b->contacts[k])
      fail_msg("%s: sample %d (t = %g s) differs", what, k, a->t[k]);
  }
  assert_int_equal(ca->accepted, cb->accepted);
  assert_int_equal(ca->rejected, cb->rejected);
  assert_int_equal(ca->derivatives, cb->derivatives);
  assert_int_equal(ca->samples, cb->samples);
  assert_int_equal(ca->contactsMade, cb->contactsMade);
  assert_int_equal(ca->islandsFormed, cb->islandsFormed);
  assert_int_equal(ca->islandIntervals, cb->islandIntervals);
  assert_int_equal(ca->islandStrays, cb->islandStrays);
  assert_int_equal(ca->islandsSlept, cb->islandsSlept);
  assert_int_equal(ca->islandsWoken, cb->islandsWoken);
  assert_true(ca->bodySecondsAsleep == cb->bodySecondsAsleep);
}

static void expect_lone_as_loop(const char* text, const char* what, long slept, long woken) {
  pdModel* m = compile_text(text);
  assert_int_equal(m->movingCount, 1);
  const loneWay ways[] = {loneOneCall, loneSlices, loneStopped, loneTwoThreads};
  const char* names[] = {"one call", "slices", "stopped and resumed", "two threads"};
  for (int w = 0; w < 4; ++w) {
    pdCounters loopCount, count;
    trace* loop = run_lone(m, ways[w], true, &loopCount);
    trace* r = run_lone(m, ways[w], false, &count);
    assert_true(loop->finite);
    assert_true(loopCount.islandsSlept >= slept && loopCount.islandsWoken >= woken);
    char label[160];
    snprintf(label, sizeof label, "%s, %s", what, names[w]);
    expect_same_lone(r, &count, loop, &loopCount, label);
    print_message("%s: %d samples, %ld intervals, %ld slept, %ld woken: bit for bit as the interval loop\n", label,
                  loop->count, loopCount.islandIntervals, loopCount.islandsSlept, loopCount.islandsWoken);
    free(r), free(loop);
  }
  pd_model_free(m);
}

static void test_a_lone_body_runs_across_samples_as_the_interval_loop(void** state) {
  (void)state;
  // thrown spinning from 0.3 m: free flight (its box out of the floor's reach), bounces, rest, asleep
  expect_lone_as_loop("tend 1.2\nsample 200\ntol 1e-6\nvmax 3\n" FLOOR
                      "cube box red 0.1 0.1 0.1\nloc 0 0 0.3 10 1 1 0\nvel 0.3 0 1 200 0 2 5\n"
                      "mu 0.5\nrestitution 0.5\n",
                      "thrown cube", 1, 0);
  // a cube at rest under a force growing from 0 (b3_ramp_onset's): asleep, woken by the force, asleep again ...
  expect_lone_as_loop("tend 0.6\nsample 1000\ntol 1e-3\nvmax 1\n"
                      "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.4\nrestitution 0.5\nkn 1e6\nkt 1e6\n"
                      "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0.4\nrestitution 0.5\nforce 0 0 0 ramp 4 0 0\n",
                      "pushed cube", 1, 1);
}

// ---------------------------------------------------------------- a free body reached late

// A box falling from rest without spin is integrated to rounding (RK4 and dense output are exact on a parabola); one
// sync interval behind (~1 ms at ~2 m/s) it would be off by millimetres.
#define FREE_FALL_TOL 1e-9

static void test_a_free_body_reached_late_keeps_falling(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/bench/pile_1000.scene");
  pdState* s = pd_state_create(m, NULL);
  int n = m->movingCount;
  pdBodyState* start = calloc((size_t)n, sizeof *start);
  assert_non_null(start);
  for (int j = 0; j < n; ++j) start[j] = pd_state_body(m, s, m->movingBodies[j]);
  double g = m->settings.gravity.z;
  int untouched = 0;
  for (int k = 1; k <= 20; ++k) {
    double t = 0.01 * k;
    assert_true(pd_advance(m, s, t, NULL, NULL));
    untouched = 0;
    for (int j = 0; j < n; ++j) {
      pdBodyState b = pd_state_body(m, s, m->movingBodies[j]);
      if (b.x.x != start[j].x.x || b.x.y != start[j].x.y || memcmp(&b.q, &start[j].q, sizeof b.q) != 0) continue;
      ++untouched;
      double z = start[j].x.z + 0.5 * g * s->t * s->t;
      if (fabs(b.x.z - z) > FREE_FALL_TOL) fail_msg("body %d at t = %g: z %.12g, its free fall %.12g", j, s->t, b.x.z, z);
    }
  }
  assert_true(untouched > 100);  // most of the upper layers are still falling at 0.2 s
  free(start);
  pd_state_free(s);
  pd_model_free(m);
}

static double wall_seconds(void) {
  struct timespec ts;
  assert_int_equal(timespec_get(&ts, TIME_UTC), TIME_UTC);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void test_whole_stages_add_up_to_at_most_the_run(void** state) {
  (void)state;
  pdModel* m = pile_30();
  trace* r = calloc(1, sizeof *r);
  assert_non_null(r);
  pdState* s = pd_state_create(m, NULL);
  double t0 = wall_seconds();
  assert_true(pd_advance(m, s, m->settings.tend, record_trace, r));
  double wall = wall_seconds() - t0;
  const pdStage whole[] = {pd_stageBroadPhase, pd_stageInterference, pd_stageContactAnalysis, pd_stageObserve};
  double sum = 0.0;
  for (size_t i = 0; i < sizeof whole / sizeof *whole; ++i) {
    print_message("%s %.4f s\n", pdStageNames[whole[i]], s->stageSeconds[whole[i]]);
    assert_true(s->stageSeconds[whole[i]] > 0.0);
    sum += s->stageSeconds[whole[i]];
  }
  print_message("whole stages %.4f s of %.4f s in pd_advance\n", sum, wall);
  assert_true(sum <= wall);
  pd_state_free(s);
  free(r);
  pd_model_free(m);
}

// pdStateOptions.stageTimers false: a caller timing the run whole gets the same run, bit for bit, and no stage time;
// with islands on and off, since each times its own stages and samples.
static void test_a_run_without_stage_timers_is_the_same_run_timing_nothing(void** state) {
  (void)state;
  pdModel* m = pile_30();
  const pdIslands modes[] = {pd_islandsOn, pd_islandsOff};
  for (size_t i = 0; i < sizeof modes / sizeof *modes; ++i) {
    trace* timed = calloc(1, sizeof *timed);
    trace* untimed = calloc(1, sizeof *untimed);
    assert_non_null(timed);
    assert_non_null(untimed);
    pdStateOptions o = pd_state_options_default();
    o.islands = modes[i];
    pdState* a = pd_state_create(m, &o);
    o.stageTimers = false;
    pdState* b = pd_state_create(m, &o);
    assert_true(pd_advance(m, a, m->settings.tend, record_trace, timed));
    assert_true(pd_advance(m, b, m->settings.tend, record_trace, untimed));
    assert_int_equal(timed->count, untimed->count);
    assert_memory_equal(timed->body, untimed->body, sizeof timed->body);
    assert_int_equal(a->n, b->n);
    assert_memory_equal(a->y, b->y, sizeof(double) * (size_t)a->n);
    assert_int_equal(a->count.accepted, b->count.accepted);
    assert_int_equal(a->count.derivatives, b->count.derivatives);
    assert_true(a->stageSeconds[pd_stageObserve] > 0.0);
    for (int g = 0; g < pd_stageCount; ++g) assert_true(b->stageSeconds[g] == 0.0);
    pd_state_free(a);
    pd_state_free(b);
    free(timed);
    free(untimed);
  }
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_far_groups_compute_as_if_alone),
      cmocka_unit_test(test_one_island_is_islands_off_bit_for_bit),
      cmocka_unit_test(test_the_same_bits_run_after_run),
      cmocka_unit_test(test_a_pile_keeps_its_physics),
      cmocka_unit_test(test_free_bodies_take_free_flight_steps),
      cmocka_unit_test(test_islands_merge_and_bounce_with_the_requested_e),
      cmocka_unit_test(test_an_island_splits_when_its_bodies_part),
      cmocka_unit_test(test_turned_bodies_apart_whose_boxes_overlap_are_two_islands),
      cmocka_unit_test(test_threads_give_the_same_bits),
      cmocka_unit_test(test_one_island_helped_by_other_threads_gives_the_same_bits),
      cmocka_unit_test(test_a_wide_island_helped_body_by_body_gives_the_same_bits),
      cmocka_unit_test(test_a_free_body_reached_late_keeps_falling),
      cmocka_unit_test(test_a_free_body_reached_in_the_first_interval),
      cmocka_unit_test(test_whole_stages_add_up_to_at_most_the_run),
      cmocka_unit_test(test_a_run_without_stage_timers_is_the_same_run_timing_nothing),
      cmocka_unit_test(test_a_lone_body_runs_across_samples_as_the_interval_loop),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
