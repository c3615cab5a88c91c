// Tunnelling: no step may pass over a collision. The soak checks the overlap of every pair at every accepted step's
// end (docs/reliability.md), which cannot see a corner that dips into another body and out again between two step
// ends: a spinning body falling onto the floor, a fast corner past another body's edge. Here a step observer follows
// each accepted step between its ends, along the cubic Hermite interpolant of every body's centre (x, v at both ends)
// and quaternion (q, q̇ = ½ ω q at both ends) — what the engine's dense output gives for the embedded and implicit
// steppers, error O(h⁴) — at SWEPT_POINTS times inside it, and measures there the overlap of every pair whose
// bounding spheres meet (the separating-axis depth over the pair's δ_max, as the soak does). Each scene of
// cases/hard/ below must stay under PENETRATION_LIMIT δ_max everywhere along its steps, with islands off (one step
// size for the scene, the steps the soak's failures were found with) and on (the default).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "interference.h"
#include "polydyn/model.h"
#include "polydyn/state.h"
#include "scene_run.h"

#define CASES_DIR PD_SOURCE_DIR "/cases/hard/"

// As the soak and the other hard cases (test_hard_cases.c): three design deflections, where the springs are sized for
// one at vmax.
#define PENETRATION_LIMIT 3.0
// Times looked at inside every step (its ends excluded): a dip several δ_max deep lasts a good part of the step that
// passes over it (a corner swinging through the floor), so 16 points see it within a small part of its depth.
#define SWEPT_POINTS 16

enum { MAX_BODIES = 16 };

typedef struct sweptWatch {
  int bodyCount;  // of the stretch's model (an island's with islands on): 0 before a stretch starts
  double t;
  pdBodyState previous[MAX_BODIES];
  long steps;
  double deepest;  // δ_max, over every step's inside and ends
  double deepestT;
  char pair[128];
} sweptWatch;

static pdVec3 hermite3(pdVec3 p0, pdVec3 d0, pdVec3 p1, pdVec3 d1, double h, double s) {
  double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s), h01 = s * s * (3 - 2 * s),
         h11 = s * s * (s - 1);
  return pd_v3_add(pd_v3_add(pd_v3_scale(p0, h00), pd_v3_scale(d0, h10 * h)),
                   pd_v3_add(pd_v3_scale(p1, h01), pd_v3_scale(d1, h11 * h)));
}

// q̇ = ½ (0, ω) q, ω in world axes (vecmath.h: q maps body to world).
static pdQuat quat_rate(pdQuat q, pdVec3 w) {
  pdQuat r = pd_quat_mul((pdQuat){0.0, w.x, w.y, w.z}, q);
  return (pdQuat){0.5 * r.w, 0.5 * r.x, 0.5 * r.y, 0.5 * r.z};
}

static pdBodyState between(pdBodyState a, pdBodyState b, double h, double s) {
  pdBodyState m = a;
  m.x = hermite3(a.x, a.v, b.x, b.v, h, s);
  if (pd_v3_dot((pdVec3){a.q.x, a.q.y, a.q.z}, (pdVec3){b.q.x, b.q.y, b.q.z}) + a.q.w * b.q.w < 0.0)
    b.q = (pdQuat){-b.q.w, -b.q.x, -b.q.y, -b.q.z};  // the same rotation, on a's side
  pdQuat da = quat_rate(a.q, a.w), db = quat_rate(b.q, b.w);
  pdVec3 v = hermite3((pdVec3){a.q.x, a.q.y, a.q.z}, (pdVec3){da.x, da.y, da.z}, (pdVec3){b.q.x, b.q.y, b.q.z},
                      (pdVec3){db.x, db.y, db.z}, h, s);
  pdVec3 w = hermite3((pdVec3){a.q.w, 0, 0}, (pdVec3){da.w, 0, 0}, (pdVec3){b.q.w, 0, 0}, (pdVec3){db.w, 0, 0}, h, s);
  m.q = pd_quat_normalize((pdQuat){w.x, v.x, v.y, v.z});
  return m;
}

// The deepest overlap over the pair's δ_max of any two bodies at the poses, as deepest_overlap (scene_run.h).
static double deepest_at(const pdModel* model, const pdBodyState* poses, int* da, int* db) {
  double deepest = 0.0;
  for (int i = 0; i < model->bodyCount; ++i)
    for (int j = i + 1; j < model->bodyCount; ++j) {
      if (model->bodies[i].fixed && model->bodies[j].fixed) continue;
      if (pd_v3_norm(pd_v3_sub(poses[i].x, poses[j].x)) > model->bodies[i].radius + model->bodies[j].radius) continue;
      pdMat3 ri = pd_quat_to_mat3(poses[i].q), rj = pd_quat_to_mat3(poses[j].q);
      pdSatResult sat;
      if (!pd_interference(&model->bodies[i].shape, poses[i].x, &ri, &model->bodies[j].shape, poses[j].x, &rj,
                           PD_SAT_MIN_DEPTH, NULL, &sat))
        continue;
      double ratio = sat.depth / pd_model_pair_delta_max(model, i, j);
      if (ratio > deepest) deepest = ratio, *da = i, *db = j;
    }
  return deepest;
}

static void observe_step(const pdModel* model, const pdState* state, bool start, void* user) {
  sweptWatch* w = user;
  assert_true(model->bodyCount <= MAX_BODIES);
  pdBodyState now[MAX_BODIES];
  for (int i = 0; i < model->bodyCount; ++i) now[i] = pd_state_body(model, state, i);
  double h = state->t - w->t;
  if (!start && w->bodyCount == model->bodyCount && h != 0.0) {
    ++w->steps;
    pdBodyState mid[MAX_BODIES];
    for (int k = 1; k <= SWEPT_POINTS + 1; ++k) {
      double s = (double)k / (SWEPT_POINTS + 1);
      for (int i = 0; i < model->bodyCount; ++i) mid[i] = between(w->previous[i], now[i], h, s);
      int a = -1, b = -1;
      double depth = deepest_at(model, k <= SWEPT_POINTS ? mid : now, &a, &b);
      if (depth > w->deepest) {
        w->deepest = depth, w->deepestT = w->t + s * h;
        snprintf(w->pair, sizeof w->pair, "%s and %s", model->bodies[a].name, model->bodies[b].name);
      }
    }
  }
  w->bodyCount = model->bodyCount;
  w->t = state->t;
  memcpy(w->previous, now, sizeof now[0] * (size_t)model->bodyCount);
}

static void run_swept(const char* file, pdIslands islands) {
  char path[1024];
  snprintf(path, sizeof path, "%s%s", CASES_DIR, file);
  pdModel* m = compile_file(path);
  sweptWatch w = {0};
  pdStateOptions o = pd_state_options_default();
  o.islands = islands;
  o.stepObserver = observe_step;
  o.stepUser = &w;
  pdState* s = pd_state_create(m, &o);
  bool completed = pd_advance(m, s, m->settings.tend, NULL, NULL);
  print_message("%-34s islands %-3s  steps %6ld acc %5ld rej  derivs %7ld  deepest along the steps %.3g δ_max "
                "(%s, t %.6g)\n",
                file, islands == pd_islandsOn ? "on" : "off", s->count.accepted, s->count.rejected,
                s->count.derivatives, w.deepest, w.deepest > 0.0 ? w.pair : "none", w.deepestT);
  assert_true(completed && !s->failed && s->t == m->settings.tend);
  assert_true(w.steps > 0);
  if (!(w.deepest < PENETRATION_LIMIT))
    fail_msg("%s, islands %s: %s overlap %.3g δ_max at t = %.6g inside a step (limit %g)", file,
             islands == pd_islandsOn ? "on" : "off", w.pair, w.deepest, w.deepestT, PENETRATION_LIMIT);
  pd_state_free(s);
  pd_model_free(m);
}

static void test_swept(void** state) {
  const char* file = *state;
  run_swept(file, pd_islandsOff);
  run_swept(file, pd_islandsOn);
}

// Each the smallest scene of a kind of collision a step can pass over, found by the soak.
static const char* const sweptCases[] = {
    "spinning_baton.scene",      // a body turning through its collision with the floor
    "baton_past_block.scene",    // ... through a corner of a free body
    "vertex_past_edge_plate.scene",  // a spinning plate among free bodies whose corner met another with no contact
    "slide_off_slab_spinning.scene",  // a fast cube whose steps only its move into a fixed slab's top face held, off its edge
    "fast_cube_thin_slab.scene",      // a cube at 20 m/s onto a fixed 2 cm slab: the move into its top face is all
};

int main(void) {
  enum { N = sizeof sweptCases / sizeof sweptCases[0] };
  struct CMUnitTest tests[N];
  for (int i = 0; i < N; ++i) {
    tests[i] = (struct CMUnitTest)cmocka_unit_test_prestate(test_swept, (void*)sweptCases[i]);
    tests[i].name = sweptCases[i];
  }
  return cmocka_run_group_tests(tests, NULL, NULL);
}
