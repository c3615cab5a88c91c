// Tangential history kept through micro-separations (engine/src/contact_history.h, docs/events.md):
// - a corner contact of a cube on a floor that broke by force leaves its tangential springs; lifted by less than
//   PD_HISTORY_GAP_REL δ_max and back on the same features, a new contact takes them (unchanged: the normal did not
//   turn) with its normal springs at 0; lifted beyond the gap, or off its face, they are forgotten; a contact on other
//   features never takes them; one left by a contact whose springs were raised for its pair's load is taken back at
//   that stiffness, and counts that stiffness's energy while kept;
// - the traces of twelve corners of three boxes resting on a floor, left, taken and aged in a fixed pseudo-random order
//   (some of those kept from earlier commits taken, so forgotten, as others are left): at every commit each kept trace
//   is found again, by pd_history_take and by pd_history_vertex_trace, and none that is not kept;
// - a column of three boxes dropped with 2 mm gaps onto a 20° incline (μ 0.5 sticks: tan 20° = 0.36) chatters while it
//   lands, keeps the history of some contacts (counted), and then does not creep: the top box moves along the box
//   below by less than CREEP_DISTANCE from 0.5 s to 2 s;
// - the same column with its top box landing 2 cm late while sliding down the slope at 0.3 m/s, islands off so that
//   nothing sleeps: the default events correct some of its onsets (with the friction those corrections carry,
//   docs/events.md), and the top box then does not creep along the box below from 1 s to 2 s.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "contact_analysis.h"
#include "contact_history.h"
#include "model_contact.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "scene_run.h"

#define DEPTH 1e-4           // m: the corners' depth when the contacts are found
#define SPRING_TOL 1e-15     // m: springs carried over unchanged (no turn of the normal)
#define CREEP_DISTANCE 1e-9  // m over 1.5 s: 0.7 nm/s, far below any slip (the stick test's 1e-6 m/s)
#define PI 3.14159265358979323846
#define SLID_MIN 0.005       // m: the late top box lands sliding (0.3 m/s for a few ms at least), not in place

enum { CAPACITY = 16 };

static pdPose at_height(const pdModel* m, int body, double z) {
  (void)m;
  (void)body;
  return (pdPose){{0.0, 0.0, z}, pd_quat_to_mat3(pd_quat_identity())};
}

// A 10 cm cube DEPTH into a 1 m floor's top face (z = 0): the model, the two bodies' poses, its four corner contacts and
// the pair's δ_max.
typedef struct boxOnFloor {
  pdModel* m;
  int floor, box;
  pdPose poses[2];
  pdContactGeom c[CAPACITY];
  double deltaMax;
} boxOnFloor;

static void box_on_floor(boxOnFloor* b) {
  b->m = compile_apart("cube floor grey 1 1 0.1\nfixed\ncube box red 0.1 0.1 0.1\n");
  b->floor = body_index(b->m, "floor"), b->box = body_index(b->m, "box");
  b->poses[b->floor] = at_height(b->m, b->floor, -0.05);  // top face at z = 0
  b->poses[b->box] = at_height(b->m, b->box, 0.05 - DEPTH);
  int n = pd_contacts_find(b->m, b->box, &b->poses[b->box], b->floor, &b->poses[b->floor], NULL, NULL, NULL, 0, b->c,
                           CAPACITY);
  assert_int_equal(n, 4);
  b->deltaMax = pd_model_pair_delta_max(b->m, b->box, b->floor);
}

static void test_a_broken_corner_returning_within_the_gap_keeps_its_tangential_springs(void** state) {
  (void)state;
  boxOnFloor b;
  box_on_floor(&b);
  pdContactParams params = pd_model_contact_params(b.m, b.c[0].id.body1, b.c[0].id.body2);
  // springs as a contact leaves them: the two sides balanced (k1t s1t + k2t s2t = 0), in the floor's plane
  pdVec3 s1t = {2e-6, -1e-6, 0.0};
  pdSprings left = {-1e-5, 1e-5, s1t, pd_v3_scale(s1t, -params.k1t / params.k2t)};

  // lifted by a few hundredths of δ_max, then back: the same corner takes the springs, once
  double lifts[] = {0.05, 0.5};  // of δ_max: within the gap, beyond it
  for (int k = 0; k < 2; ++k) {
    pdContactHistory* h = pd_history_create();
    pd_history_leave(h, &b.c[0].id, &left, b.c[0].normal, b.deltaMax, 1.0);
    b.poses[b.box] = at_height(b.m, b.box, 0.05 + lifts[k] * b.deltaMax);
    pd_history_age(b.m, h, b.poses);
    pdSprings got = {0};
    double scale = 1.0;
    bool kept = pd_history_take(h, &b.c[0].id, b.c[0].normal, &params, &scale, &got);
    print_message("corner lifted %.2f delta_max (gap tolerance %.2f): history %s\n", lifts[k], PD_HISTORY_GAP_REL,
                  kept ? "kept" : "forgotten");
    if (lifts[k] <= PD_HISTORY_GAP_REL) {
      assert_true(kept);
      assert_true(got.s1n == 0.0 && got.s2n == 0.0);
      assert_true(pd_v3_norm(pd_v3_sub(got.s1t, left.s1t)) <= SPRING_TOL);
      assert_true(pd_v3_norm(pd_v3_sub(got.s2t, left.s2t)) <= SPRING_TOL);
      pdSprings again = {0};
      assert_false(pd_history_take(h, &b.c[0].id, b.c[0].normal, &params, &scale, &again));  // taken once
    } else {
      assert_false(kept);
    }
    pd_history_free(h);
  }

  // another corner (other features) does not take them; nor does the same one after its vertex left the face
  pdContactHistory* h = pd_history_create();
  pd_history_leave(h, &b.c[0].id, &left, b.c[0].normal, b.deltaMax, 1.0);
  b.poses[b.box] = at_height(b.m, b.box, 0.05);
  pd_history_age(b.m, h, b.poses);
  pdSprings got = {0};
  double scale = 1.0;
  assert_false(pd_history_take(h, &b.c[1].id, b.c[1].normal, &params, &scale, &got));
  b.poses[b.box].x = (pdVec3){2.0, 0.0, 0.05};  // beside the 1 m floor: the vertex is off its face
  pd_history_age(b.m, h, b.poses);
  assert_int_equal(pd_history_count(h), 0);
  pd_history_free(h);
  pd_model_free(b.m);
}

// A contact whose springs were raised for its pair's load (docs/contact-model.md, "Springs sized by the load") leaves
// deflections at that stiffness: the contact that takes them back gets the springs they were kept at, so its friction
// force is the one the contact broke with (at eq. (11)'s springs it was that divided by the factor), and the energy
// the trace counts meanwhile is that of the raised springs, which the contact then holds.
static void test_a_trace_of_raised_springs_is_taken_back_at_their_stiffness(void** state) {
  (void)state;
  boxOnFloor b;
  box_on_floor(&b);
  const double raised = 40.0;  // the contact's factor when it broke
  pdContactParams own = pd_model_contact_params(b.m, b.c[0].id.body1, b.c[0].id.body2);
  pdVec3 s1t = {2e-7, -1e-7, 0.0};
  pdSprings left = {-1e-6, 1e-6, s1t, pd_v3_scale(s1t, -own.k1t / own.k2t)};
  double energies[2];
  double scales[2] = {1.0, raised};
  for (int k = 0; k < 2; ++k) {
    pdContactHistory* h = pd_history_create();
    pd_history_leave(h, &b.c[0].id, &left, b.c[0].normal, b.deltaMax, scales[k]);
    b.poses[b.box] = at_height(b.m, b.box, 0.05);
    pd_history_age(b.m, h, b.poses);
    energies[k] = pd_history_spring_energy(b.m, h);
    pdContactParams params = own;
    double scale = 1.0;
    pdSprings got = {0};
    assert_true(pd_history_take(h, &b.c[0].id, b.c[0].normal, &params, &scale, &got));
    assert_true(scale == scales[k]);
    assert_true(params.k1t == scales[k] * own.k1t && params.k2t == scales[k] * own.k2t);
    assert_true(params.k1n == scales[k] * own.k1n && params.k2n == scales[k] * own.k2n);
    // the same deflections, so the force they left with: k1t s1t at the stiffness they were kept at
    assert_true(pd_v3_norm(pd_v3_sub(got.s1t, left.s1t)) <= SPRING_TOL);
    pd_history_free(h);
  }
  print_message("trace energy at factor 1 %.6g J, at factor %.0f %.6g J\n", energies[0], raised, energies[1]);
  assert_true(energies[0] > 0.0);
  assert_true(fabs(energies[1] - raised * energies[0]) <= 1e-12 * energies[1]);
  pd_model_free(b.m);
}

// A fixed pseudo-random sequence (a linear congruential generator): the same draws on every machine.
static unsigned next_draw(unsigned* seed) {
  *seed = *seed * 1664525u + 1013904223u;
  return *seed >> 16;
}

static void test_every_kept_trace_is_found_as_others_come_and_go(void** state) {
  (void)state;
  pdModel* m = compile_apart("cube floor grey 4 4 0.1\nfixed\ncube a red 0.1 0.1 0.1\ncube b red 0.1 0.1 0.1\n"
                             "cube c red 0.1 0.1 0.1\n");
  int floor = body_index(m, "floor"), boxes[3] = {body_index(m, "a"), body_index(m, "b"), body_index(m, "c")};
  pdPose poses[4];
  poses[floor] = at_height(m, floor, -0.05);  // top face at z = 0
  enum { CORNERS = 12 };
  pdContactGeom c[CORNERS];
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    poses[boxes[k]] = at_height(m, boxes[k], 0.05 - DEPTH);
    poses[boxes[k]].x.x = k - 1.0;
    int found = pd_contacts_find(m, boxes[k], &poses[boxes[k]], floor, &poses[floor], NULL, NULL, NULL, 0, c + n,
                                 CORNERS - n);
    assert_int_equal(found, 4);
    n += found;
  }
  pdContactParams params = pd_model_contact_params(m, boxes[0], floor);
  pdSprings left = {0.0, 0.0, {1e-6, 0.0, 0.0}, {-1e-6 * params.k1t / params.k2t, 0.0, 0.0}};
  pdContactHistory* h = pd_history_create();
  bool kept[CORNERS] = {false};  // kept from an earlier commit: what pd_history_take may find
  unsigned seed = 42;
  long takes = 0, lookups = 0;
  for (int commit = 0; commit < 400; ++commit) {
    // as a commit goes (contact_set.c): contacts that break leave their traces, new contacts take older ones, then
    // the history ages
    bool leaves[CORNERS] = {false}, takes_now[CORNERS] = {false};
    for (int i = 0; i < n; ++i)
      if (!kept[i] && next_draw(&seed) % 3 == 0) {
        pd_history_leave(h, &c[i].id, &left, c[i].normal, pd_model_pair_delta_max(m, c[i].id.body1, c[i].id.body2),
                         1.0);
        leaves[i] = true;
      }
    for (int i = 0; i < n; ++i) {
      pdContactId other;
      int face = c[i].id.feat2, otherFace = (face + 1) % 6;
      bool byVertex = pd_history_vertex_trace(h, c[i].id.body1, c[i].id.feat1, c[i].id.body2, otherFace, &other);
      assert_int_equal(byVertex, kept[i]);
      if (byVertex) assert_int_equal(pd_contact_id_compare(&other, &c[i].id), 0);
      assert_false(pd_history_vertex_trace(h, c[i].id.body1, c[i].id.feat1, c[i].id.body2, face, &other));
      ++lookups;
    }
    for (int i = 0; i < n; ++i) {
      if (kept[i] && next_draw(&seed) % 2 != 0) continue;
      pdSprings got = {0};
      double scale = 1.0;
      bool found = pd_history_take(h, &c[i].id, c[i].normal, &params, &scale, &got);
      if (found != kept[i])
        print_message("commit %d, corner %d: trace %s but %s\n", commit, i, kept[i] ? "kept" : "not kept",
                      found ? "found" : "not found");
      assert_int_equal(found, kept[i]);
      takes_now[i] = found;
      takes += found;
    }
    pd_history_age(m, h, poses);
    int count = 0;
    for (int i = 0; i < n; ++i) {
      kept[i] = (kept[i] && !takes_now[i]) || leaves[i];
      count += kept[i];
    }
    assert_int_equal(pd_history_count(h), count);
  }
  print_message("12 corners over 400 commits: %ld traces taken, %ld vertex lookups, each as kept\n", takes, lookups);
  pd_history_free(h);
  pd_model_free(m);
}

// The column on the incline: three boxes with 2 mm gaps, the top one `lift` higher still and sliding down the slope at
// `slide` (m/s); into *r and *s by polydyn run's default events, islands as given. Returns the top box's move along the
// box below, and *slab the lowest box's along the slab, between samples `from` and the last.
static double column_creep(double lift, double slide, pdIslands islands, int from, double* slab, long* kept,
                           long* corrected, double* slid) {
  double th = 20.0 * PI / 180.0, gap = 0.002;
  pdVec3 n = {sin(th), 0.0, cos(th)}, down = {cos(th), 0.0, -sin(th)};
  char text[2048];
  int len = snprintf(text, sizeof text,
                     "tend 2\nsample 200\ncube slab grey 2 1 0.2\nfixed\nloc 0 0 0  20 0 1 0\nmu 0.5\nrestitution 0.5\n");
  for (int i = 0; i < 3; ++i) {
    double d = 0.1 + gap + 0.05 + i * (0.1 + gap) + (i == 2 ? lift : 0.0), v = i == 2 ? slide : 0.0;
    len += snprintf(text + len, sizeof text - (size_t)len,
                    "cube b%d red 0.2 0.15 0.1\nloc %.17g 0 %.17g  20 0 1 0\nvel %.17g 0 %.17g\nmu 0.5\nrestitution 0.5\n",
                    i, d * n.x, d * n.z, v * down.x, v * down.z);
  }
  pdModel* m = compile_text(text);
  pdState* s = NULL;
  record* r = run_onsets_islands(m, pd_onsetsBounded, islands, &s);
  int to = r->count - 1;
  assert_true(fabs(r->t[from] - 0.005 * from) < 1e-12 && fabs(r->t[to] - 2.0) < 1e-12);
  assert_true(r->contacts[to] > 0);
  // moving bodies in scene order: b0, b1, b2 (the top)
  pdVec3 rel0 = pd_v3_sub(r->body[2][from].x, r->body[1][from].x);
  pdVec3 rel1 = pd_v3_sub(r->body[2][to].x, r->body[1][to].x);
  double creep = fabs(pd_v3_dot(pd_v3_sub(rel1, rel0), down));
  *slab = fabs(pd_v3_dot(pd_v3_sub(r->body[0][to].x, r->body[0][from].x), down));
  *slid = pd_v3_dot(pd_v3_sub(rel0, pd_v3_sub(r->body[2][0].x, r->body[1][0].x)), down);  // from the start
  *kept = s->count.historyKept;
  *corrected = s->count.onsetsInterpolated;
  if (islands == pd_islandsOff) assert_true(s->count.bodySecondsAsleep == 0.0);
  pd_state_free(s);
  free(r);
  pd_model_free(m);
  return creep;
}

// The column on the incline, as polydyn run would take it (default events, islands on).
static void test_a_chattering_column_on_an_incline_does_not_creep(void** state) {
  (void)state;
  double slab, slid;
  long kept, corrected;
  double creep = column_creep(0.0, 0.0, pd_islandsOn, 100, &slab, &kept, &corrected, &slid);
  print_message("column on a 20 deg incline: %ld contacts kept their history, top box along the box below %.2e m, "
                "lowest box along the slab %.2e m over 0.5..2 s\n",
                kept, creep, slab);
  assert_true(kept > 0);
  assert_true(creep < CREEP_DISTANCE);
  assert_true(slab < CREEP_DISTANCE);
}

// The top box landing late while sliding, nothing asleep.
static void test_a_box_landing_sliding_on_the_column_does_not_creep(void** state) {
  (void)state;
  double slab, slid;
  long kept, corrected;
  double creep = column_creep(0.02, 0.3, pd_islandsOff, 200, &slab, &kept, &corrected, &slid);
  print_message("top box landing sliding on the column, islands off: %ld onsets corrected, slid %.3f m down the box "
                "below by 1 s, then %.2e m, lowest box along the slab %.2e m over 1..2 s\n",
                corrected, slid, creep, slab);
  assert_true(corrected > 0);
  assert_true(slid > SLID_MIN);
  assert_true(creep < CREEP_DISTANCE);
  assert_true(slab < CREEP_DISTANCE);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_broken_corner_returning_within_the_gap_keeps_its_tangential_springs),
      cmocka_unit_test(test_a_trace_of_raised_springs_is_taken_back_at_their_stiffness),
      cmocka_unit_test(test_every_kept_trace_is_found_as_others_come_and_go),
      cmocka_unit_test(test_a_chattering_column_on_an_incline_does_not_creep),
      cmocka_unit_test(test_a_box_landing_sliding_on_the_column_does_not_creep),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
