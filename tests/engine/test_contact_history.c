// Tangential history kept through micro-separations (engine/src/contact_history.h, docs/events.md):
// - a corner contact of a cube on a floor that broke by force leaves its tangential springs; lifted by less than
//   PD_HISTORY_GAP_REL δ_max and back on the same features, a new contact takes them (unchanged: the normal did not
//   turn) with its normal springs at 0; lifted beyond the gap, or off its face, they are forgotten; a contact on other
//   features never takes them;
// - a column of three boxes dropped with 2 mm gaps onto a 20° incline (μ 0.5 sticks: tan 20° = 0.36) chatters while it
//   lands, keeps the history of some contacts (counted), and then does not creep: the top box moves along the box
//   below by less than CREEP_DISTANCE from 0.5 s to 2 s.
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

enum { CAPACITY = 16 };

static pdPose at_height(const pdModel* m, int body, double z) {
  (void)m;
  (void)body;
  return (pdPose){{0.0, 0.0, z}, pd_quat_to_mat3(pd_quat_identity())};
}

static void test_a_broken_corner_returning_within_the_gap_keeps_its_tangential_springs(void** state) {
  (void)state;
  pdModel* m = compile_apart("cube floor grey 1 1 0.1\nfixed\ncube box red 0.1 0.1 0.1\n");
  int floor = body_index(m, "floor"), box = body_index(m, "box");
  double deltaMax = pd_model_pair_delta_max(m, box, floor);
  pdPose poses[2];
  poses[floor] = at_height(m, floor, -0.05);  // top face at z = 0
  poses[box] = at_height(m, box, 0.05 - DEPTH);
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, box, &poses[box], floor, &poses[floor], NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 4);
  pdContactParams params = pd_model_contact_params(m, c[0].id.body1, c[0].id.body2);
  // springs as a contact leaves them: the two sides balanced (k1t s1t + k2t s2t = 0), in the floor's plane
  pdVec3 s1t = {2e-6, -1e-6, 0.0};
  pdSprings left = {-1e-5, 1e-5, s1t, pd_v3_scale(s1t, -params.k1t / params.k2t)};

  // lifted by a few hundredths of δ_max, then back: the same corner takes the springs, once
  double lifts[] = {0.05, 0.5};  // of δ_max: within the gap, beyond it
  for (int k = 0; k < 2; ++k) {
    pdContactHistory* h = pd_history_create();
    pd_history_leave(h, &c[0].id, &left, c[0].normal, deltaMax);
    poses[box] = at_height(m, box, 0.05 + lifts[k] * deltaMax);
    pd_history_age(m, h, poses);
    pdSprings got = {0};
    bool kept = pd_history_take(h, &c[0].id, c[0].normal, &params, &got);
    print_message("corner lifted %.2f delta_max (gap tolerance %.2f): history %s\n", lifts[k], PD_HISTORY_GAP_REL,
                  kept ? "kept" : "forgotten");
    if (lifts[k] <= PD_HISTORY_GAP_REL) {
      assert_true(kept);
      assert_true(got.s1n == 0.0 && got.s2n == 0.0);
      assert_true(pd_v3_norm(pd_v3_sub(got.s1t, left.s1t)) <= SPRING_TOL);
      assert_true(pd_v3_norm(pd_v3_sub(got.s2t, left.s2t)) <= SPRING_TOL);
      pdSprings again = {0};
      assert_false(pd_history_take(h, &c[0].id, c[0].normal, &params, &again));  // taken once
    } else {
      assert_false(kept);
    }
    pd_history_free(h);
  }

  // another corner (other features) does not take them; nor does the same one after its vertex left the face
  pdContactHistory* h = pd_history_create();
  pd_history_leave(h, &c[0].id, &left, c[0].normal, deltaMax);
  poses[box] = at_height(m, box, 0.05);
  pd_history_age(m, h, poses);
  pdSprings got = {0};
  assert_false(pd_history_take(h, &c[1].id, c[1].normal, &params, &got));
  poses[box].x = (pdVec3){2.0, 0.0, 0.05};  // beside the 1 m floor: the vertex is off its face
  pd_history_age(m, h, poses);
  assert_int_equal(pd_history_count(h), 0);
  pd_history_free(h);
  pd_model_free(m);
}

// The column on the incline, as polydyn run would take it (default events, islands on).
static void test_a_chattering_column_on_an_incline_does_not_creep(void** state) {
  (void)state;
  double th = 20.0 * PI / 180.0, gap = 0.002;
  pdVec3 n = {sin(th), 0.0, cos(th)}, down = {cos(th), 0.0, -sin(th)};
  char text[2048];
  int len = snprintf(text, sizeof text,
                     "tend 2\nsample 200\ncube slab grey 2 1 0.2\nfixed\nloc 0 0 0  20 0 1 0\nmu 0.5\nrestitution 0.5\n");
  const char* names[] = {"b0", "b1", "top"};
  for (int i = 0; i < 3; ++i) {
    double d = 0.1 + gap + 0.05 + i * (0.1 + gap);
    len += snprintf(text + len, sizeof text - (size_t)len,
                    "cube %s red 0.2 0.15 0.1\nloc %.17g 0 %.17g  20 0 1 0\nmu 0.5\nrestitution 0.5\n", names[i],
                    d * n.x, d * n.z);
  }
  pdModel* m = compile_text(text);
  pdState* s = NULL;
  record* r = run(m, &s);
  int from = 100, to = r->count - 1;  // samples at 0.5 s and 2 s
  assert_true(fabs(r->t[from] - 0.5) < 1e-12 && fabs(r->t[to] - 2.0) < 1e-12);
  // moving bodies in scene order: b0, b1, top
  pdVec3 rel0 = pd_v3_sub(r->body[2][from].x, r->body[1][from].x);
  pdVec3 rel1 = pd_v3_sub(r->body[2][to].x, r->body[1][to].x);
  double creep = fabs(pd_v3_dot(pd_v3_sub(rel1, rel0), down));
  double slab = fabs(pd_v3_dot(pd_v3_sub(r->body[0][to].x, r->body[0][from].x), down));
  print_message("column on a 20 deg incline: %ld contacts kept their history, top box along the box below %.2e m, "
                "lowest box along the slab %.2e m over 0.5..2 s\n",
                s->count.historyKept, creep, slab);
  assert_true(s->count.historyKept > 0);
  assert_true(creep < CREEP_DISTANCE);
  assert_true(slab < CREEP_DISTANCE);
  pd_state_free(s);
  free(r);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_broken_corner_returning_within_the_gap_keeps_its_tangential_springs),
      cmocka_unit_test(test_a_chattering_column_on_an_incline_does_not_creep),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
