// Hand-overs (engine/src/contact_search.c, engine/src/contact_history.h; docs/contact-model.md, "Hand-overs"): a contact
// whose features change over (a vertex onto the next face, a vertex off a face onto the edge pairs at it, an edge pair
// onto the next edge at a shared vertex) goes on in its successor with its springs, so the force goes on where it was.
// - a 10 cm box slides slowly (0.1-0.2 m/s) down a 20° face over a convex edge onto a 20.5° face of the same fixed
//   body: wherever its contacts change over between two output samples (some end and others begin in one interval:
//   a hand-over), the total friction force on the box changes by at most HANDOVER_JUMP_MAX μ m g. Without hand-overs
//   the front corners' VF contacts ended at the edge with their springs, and the edge pairs that replaced them started
//   at zero: a jump of 0.53 μ m g;
// - a box pushed at 0.95 m/s over a level face and a convex edge onto a 3° face (μ 0.3: it sticks there) comes to
//   rest on contacts that took over from others, and then does not creep: it moves by less than CREEP_DISTANCE from
//   1 s to 3 s (sleeping off).
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

#define PI 3.14159265358979323846
#define G 9.81  // m/s², the scenes' default gravity
// The largest change of the box's total friction force across a hand-over between two 0.2 ms samples, in μ m g. The
// springs go on unchanged (turned by the 0.5° between the faces); what changes is the dampers' share, c_n times the
// change of the approach speed seen along the new normal (the box slides at ~0.2 m/s: 1.7 mm/s over 0.5°, with c_n
// ~250 N·s/m about 0.4 N on each rear corner), measured 0.095 μ m g; the box's own rocking over the edge changes the
// force by up to 0.05 μ m g per sample interval away from any hand-over.
#define HANDOVER_JUMP_MAX 0.15
#define CREEP_DISTANCE 1e-9  // m over 2 s (0.5 nm/s), as the history test's resting column

enum { CONTACTS_MAX = 64 };

// A fixed body with two top faces meeting at a convex edge along y at the origin: a face falling at angle1 towards +x
// up to the edge, then one falling at angle2 (degrees), 1 m long and 0.3 m wide; and a 10 cm box of 1 kg resting on the
// first face with its front face `before` (m) from the edge, moving down the slope at v0 (m/s).
static pdModel* ramp_scene(double angle1, double angle2, double mu, double before, double v0, double tend,
                           double sample) {
  double t1 = tan(angle1 * PI / 180.0), t2 = tan(angle2 * PI / 180.0);
  double px[5] = {-0.5, 0.0, 0.5, 0.5, -0.5}, pz[5] = {0.5 * t1, 0.0, -0.5 * t2, -0.4, -0.4};
  // the profile's centroid: the hull's centre of mass (a prism of it), where `loc` puts it so the points stay as given
  double area = 0.0, cx = 0.0, cz = 0.0;
  for (int i = 0; i < 5; ++i) {
    int j = (i + 1) % 5;
    double c = px[i] * pz[j] - px[j] * pz[i];
    area += c, cx += (px[i] + px[j]) * c, cz += (pz[i] + pz[j]) * c;
  }
  area *= 0.5, cx /= 6.0 * area, cz /= 6.0 * area;
  char points[1024];
  int n = 0;
  for (int i = 0; i < 5; ++i)
    for (int side = -1; side <= 1; side += 2)
      n += snprintf(points + n, sizeof points - (size_t)n, " %.17g %g %.17g", px[i], 0.15 * side, pz[i]);
  double th = angle1 * PI / 180.0, s = before + 0.05, lift = 0.05 + 1e-8;
  char text[4096];
  snprintf(text, sizeof text,
           "tend %g\nsample %g\ntol 1e-7\nvmax 1\nsleep off\n"
           "hull ramp grey%s\nfixed\nloc %.17g 0 %.17g\nmu %g\nrestitution 0.5\n"
           "cube box green 0.1 0.1 0.1\nloc %.17g 0 %.17g %g 0 1 0\nvel %.17g 0 %.17g\nmu %g\nrestitution 0.5\n",
           tend, sample, points, cx, cz, mu, -s * cos(th) + lift * sin(th), s * sin(th) + lift * cos(th), angle1,
           v0 * cos(th), -v0 * sin(th), mu);
  return compile_text(text);
}

typedef struct contactKey {
  int a, b, fa, fb;
  bool ee;
} contactKey;

typedef struct frictionWatch {
  int box;
  double mu, weight;  // μ, m g (N)
  double t0;          // s: hand-overs are looked at from here (after the box has landed)
  int count;
  contactKey keys[CONTACTS_MAX];
  pdVec3 friction;  // N, on the box, at the last sample
  bool started;
  int handovers;     // sample intervals in which some contacts ended and others began
  double jumpMax;    // μ m g
  double jumpT;
} frictionWatch;

static bool same_key(const contactKey* x, const contactKey* y) {
  return x->a == y->a && x->b == y->b && x->fa == y->fa && x->fb == y->fb && x->ee == y->ee;
}

static bool listed(const contactKey* keys, int count, const contactKey* k) {
  for (int i = 0; i < count; ++i)
    if (same_key(&keys[i], k)) return true;
  return false;
}

static bool watch_friction(const pdModel* model, const pdState* state, void* user) {
  (void)model;
  frictionWatch* w = user;
  int count = pd_state_contact_count(state);
  assert_true(count <= CONTACTS_MAX);
  contactKey keys[CONTACTS_MAX];
  pdVec3 friction = {0, 0, 0};
  for (int i = 0; i < count; ++i) {
    pdContactReport c = pd_state_contact(state, i);
    keys[i] = (contactKey){c.bodyA, c.bodyB, c.featureA, c.featureB, c.edgeEdge};
    double sign = c.bodyA == w->box ? 1.0 : c.bodyB == w->box ? -1.0 : 0.0;
    friction = pd_v3_add(friction, pd_v3_scale(c.ft, sign));
  }
  if (w->started && state->t > w->t0) {
    int ended = 0, begun = 0;
    for (int i = 0; i < w->count; ++i) ended += !listed(keys, count, &w->keys[i]);
    for (int i = 0; i < count; ++i) begun += !listed(w->keys, w->count, &keys[i]);
    if (ended > 0 && begun > 0) {
      ++w->handovers;
      double jump = pd_v3_norm(pd_v3_sub(friction, w->friction)) / (w->mu * w->weight);
      if (jump > w->jumpMax) w->jumpMax = jump, w->jumpT = state->t;
    }
  }
  memcpy(w->keys, keys, sizeof keys);
  w->count = count;
  w->friction = friction;
  w->started = true;
  return true;
}

static void test_a_box_sliding_over_an_edge_keeps_a_continuous_friction_force(void** state) {
  (void)state;
  pdModel* m = ramp_scene(20.0, 20.5, 0.35, 0.02, 0.0, 1.6, 5000.0);
  int box = body_index(m, "box");
  frictionWatch w = {.box = box, .mu = 0.35, .weight = m->bodies[box].mass * G, .t0 = 0.2};
  pdState* s = pd_state_create(m, NULL);
  assert_true(pd_advance(m, s, m->settings.tend, watch_friction, &w));
  pdBodyState b = pd_state_body(m, s, box);
  print_message("box at x = %.4g m (the edge at 0), %d hand-over intervals, %ld contacts handed over; largest friction "
                "change across one: %.3g μ m g at t = %.5g s\n",
                b.x.x, w.handovers, s->count.contactsTransferred, w.jumpMax, w.jumpT);
  assert_true(b.x.x > 0.1);  // it went over the edge
  assert_true(w.handovers >= 2 && s->count.contactsTransferred >= 2);
  assert_true(w.jumpMax <= HANDOVER_JUMP_MAX);
  pd_state_free(s);
  pd_model_free(m);
}

typedef struct positions {
  double t[2];
  pdVec3 x[2];
  int box;
} positions;

static bool watch_rest(const pdModel* model, const pdState* state, void* user) {
  positions* p = user;
  for (int k = 0; k < 2; ++k)
    if (fabs(state->t - p->t[k]) < 1e-9) p->x[k] = pd_state_body(model, state, p->box).x;
  return true;
}

static void test_a_box_at_rest_after_a_handover_does_not_creep(void** state) {
  (void)state;
  pdModel* m = ramp_scene(0.0, 3.0, 0.3, 0.03, 0.95, 3.0, 1000.0);
  positions p = {{1.0, 3.0}, {{0, 0, 0}, {0, 0, 0}}, body_index(m, "box")};
  pdState* s = pd_state_create(m, NULL);
  assert_true(pd_advance(m, s, m->settings.tend, watch_rest, &p));
  double creep = pd_v3_norm(pd_v3_sub(p.x[1], p.x[0]));
  print_message("box at rest at x = %.4g m (the edge at 0) after %ld hand-overs; moved %.3g m from 1 s to 3 s\n",
                p.x[1].x, s->count.contactsTransferred, creep);
  assert_true(p.x[1].x > 0.05);  // wholly on the 3° face
  assert_true(s->count.contactsTransferred >= 1);
  assert_true(creep < CREEP_DISTANCE);
  pd_state_free(s);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_box_sliding_over_an_edge_keeps_a_continuous_friction_force),
      cmocka_unit_test(test_a_box_at_rest_after_a_handover_does_not_creep),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
