// Tests of the planar constraint (scene `planar`, engine/include/polydyn/model.h) in the three engines: the
// soft engine (the derivative and the implicit stepper's linear systems drop what would leave the x–z plane),
// ODE (linear and angular motors) and Bullet (linear and angular factors). A block landing on a corner of a
// board that slopes across the plane stays in its plane to round-off (and, not planar, leaves it), and the
// Gedanken laws of restitution and of the incline hold for a planar body. Also the scene errors.
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
#include "pdref/refcheck.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

#define G 9.81  // m/s², the scene default
#define PI 3.14159265358979323846

// In-plane to round-off: the out-of-plane position (m), velocity (m/s), spin (rad/s) and quaternion
// components of a 0.06 m block moving at ~1 m/s, 10 rad/s. Measured: the soft engine 0 (v_y 2e-24: its implicit stepper's LU solves), Bullet 0; ODE's
// motors are velocity rows of its LCP, solved to ~1e-15.
#define PLANE_POS_TOL 1e-12
#define PLANE_VEL_TOL 1e-12
#define PLANE_SPIN_TOL 1e-9
#define PLANE_QUAT_TOL 1e-12
// Not planar, the same block slides down the cross slope by far more than this, m.
#define LEAVES_PLANE 1e-3
// Restitution of a vertex-first landing: the soft engine's Gedanken tolerance (A1, gedanken/group_a.c), and
// the rigid engines' Newton bounce, exact to the sample's round-off.
#define SOFT_RESTITUTION_TOL 0.005
#define RIGID_RESTITUTION_TOL 1e-6
// Incline acceleration relative to g (sin θ − μ cos θ): the Gedanken B1 tolerance (0.5 %), and 1 % for the rigid
// engines' velocity-level friction (as tests/refcheck/test_ode_adapter.c).
#define SOFT_INCLINE_REL_TOL 0.005
#define RIGID_INCLINE_REL_TOL 0.01

enum { MAX_SAMPLES = 4096 };

typedef struct trace {
  int n;
  double t[MAX_SAMPLES];
  pdBodyState b[MAX_SAMPLES];  // the first moving body
} trace;

static bool observe(const pdModel* model, const pdState* state, void* user) {
  trace* tr = user;
  assert_true(tr->n < MAX_SAMPLES);
  tr->t[tr->n] = state->t;
  tr->b[tr->n++] = pd_state_body(model, state, model->movingBodies[0]);
  return true;
}

static pdModel* compile(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("planar", text, strlen(text), &err);
  if (!scene) fail_msg("%d:%d: %s", err.line, err.col, err.message);
  pdModel* m = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!m) fail_msg("%d:%d: %s", err.line, err.col, err.message);
  return m;
}

// The scene's error, "LINE:COL: message", or "" when it compiles.
static void scene_error(const char* text, char* out, size_t size) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("planar", text, strlen(text), &err);
  pdModel* m = scene ? pd_model_compile(scene, &err) : NULL;
  if (m) snprintf(out, size, "%s", "");
  else snprintf(out, size, "%d:%d: %.400s", err.line, err.col, err.message);
  pd_model_free(m);
  pd_scene_free(scene);
}

// Runs the model in "soft", "soft-pair" (the soft engine joining contact onsets as pairs, with their impulses),
// "ode" or "bullet" (native contact; ODE's friction aligned with the slip when `aligned`); false when this build
// has no such adapter.
static bool run_in(const char* engine, const pdModel* m, bool aligned, trace* tr) {
  tr->n = 0;
  if (strncmp(engine, "soft", 4) == 0) {
    pdStateOptions o = pd_state_options_default();
    if (strcmp(engine, "soft-pair") == 0) o.onsets = pd_onsetsPair;
    pdState* s = pd_state_create(m, &o);
    assert_true(pd_advance(m, s, m->settings.tend, observe, tr));
    pd_state_free(s);
    return true;
  }
  const pdRefAdapter* a = pd_ref_adapter(engine);
  if (!a) return false;
  pdRefOptions o = {.variant = pd_refNative,
                    .step = PD_REF_DEFAULT_STEP,
                    .odeFriction = aligned ? pd_odeFrictionAligned : pd_odeFrictionPyramid};
  pdRefRunStats stats;
  pdError err;
  memset(&err, 0, sizeof err);
  assert_true(pd_ref_run(m, a, &o, NULL, observe, tr, &stats, &err));
  assert_true(stats.completed);
  return true;
}

static const char* const engines[] = {"soft", "ode", "bullet", "soft-pair"};

// ---------------------------------------------------------------------------------------------
// a block lands on a corner of a board sloping across the plane

// The board is turned 15° about x, so its top slopes along y and the block's lower edge (along y) meets it
// with one corner first; the contact force then has a y component and a torque about x and z.
static void corner_drop_scene(bool planar, char* text, size_t size) {
  snprintf(text, size,
           "tend 0.6\nsample 500\n"
           "cube board grey 1 1 0.1\nfixed\nloc 0 0 -0.05 15 1 0 0\nmu 0.5\nrestitution 0.5\n"
           "cube block red 0.06 0.06 0.06\nloc 0.02 0.01 0.12 30 0 1 0\nvel 0.3 0 -1 500 0 1 0\n%smu 0.5\n"
           "restitution 0.5\n",
           planar ? "planar\n" : "");
}

static void test_corner_drop_stays_in_its_plane_in_every_engine(void** state) {
  (void)state;
  char text[1024];
  corner_drop_scene(true, text, sizeof text);
  pdModel* m = compile(text);
  trace* tr = malloc(sizeof *tr);
  assert_non_null(tr);
  for (int e = 0; e < 4; ++e) {
    if (!run_in(engines[e], m, false, tr)) {
      print_message("%s: not built\n", engines[e]);
      continue;
    }
    double y0 = tr->b[0].x.y, dy = 0, vy = 0, spin = 0, quat = 0, lowest = INFINITY;
    for (int k = 0; k < tr->n; ++k) {
      const pdBodyState* b = &tr->b[k];
      dy = fmax(dy, fabs(b->x.y - y0));
      vy = fmax(vy, fabs(b->v.y));
      spin = fmax(spin, hypot(b->w.x, b->w.z));
      quat = fmax(quat, hypot(b->q.x, b->q.z));
      lowest = fmin(lowest, b->x.z);
    }
    const pdBodyState* end = &tr->b[tr->n - 1];
    print_message("%s: %d samples, |dy| %.2g m, |vy| %.2g m/s, |w_xz| %.2g rad/s, |q_xz| %.2g; end x %.4f z %.4f, "
                  "turned %.1f deg\n",
                  engines[e], tr->n, dy, vy, spin, quat, end->x.x, end->x.z,
                  2.0 * atan2(end->q.y, end->q.w) * 180.0 / PI);
    assert_true(lowest < 0.06);  // it did land
    assert_true(dy <= PLANE_POS_TOL && vy <= PLANE_VEL_TOL && spin <= PLANE_SPIN_TOL && quat <= PLANE_QUAT_TOL);
  }
  pd_model_free(m);

  // the same block, not planar, leaves the plane: the test above can fail
  corner_drop_scene(false, text, sizeof text);
  m = compile(text);
  run_in("soft", m, false, tr);
  double dy = fabs(tr->b[tr->n - 1].x.y - tr->b[0].x.y);
  print_message("not planar (soft): |dy| %.3g m\n", dy);
  assert_true(dy > LEAVES_PLANE);
  pd_model_free(m);
  free(tr);
}

// ---------------------------------------------------------------------------------------------
// Gedanken A1 (restitution of one vertex contact) with a planar body

static void test_vertex_landing_bounces_with_the_requested_restitution(void** state) {
  (void)state;
  trace* tr = malloc(sizeof *tr);
  assert_non_null(tr);
  const double requested[] = {0.3, 0.8};
  for (int i = 0; i < 2; ++i) {
    char text[1024];
    // gravity off, frictionless: an octahedron falls vertex first at 1 m/s onto a fixed plate (catalogue A1);
    // its inertia is isotropic, so y is a principal axis
    snprintf(text, sizeof text,
             "gravity 0 0 0\ntend 0.3\nsample 200\ntol 1e-9\nvmax 1\n"
             "cube plate grey 0.2 0.2 0.2\nfixed\nloc 0 0 -0.1\nmu 0\nrestitution %g\n"
             "hull oct red 0.1 0 0  -0.1 0 0  0 0.1 0  0 -0.1 0  0 0 0.1  0 0 -0.1\n"
             "loc 0 0 0.15\nvel 0 0 -1\nplanar\nmu 0\nrestitution %g\n",
             requested[i], requested[i]);
    pdModel* m = compile(text);
    double e = pd_model_pair_contact(m, 0, 1).restitution;
    for (int k = 0; k < 3; ++k) {
      if (!run_in(engines[k], m, false, tr)) continue;
      double measured = tr->b[tr->n - 1].v.z;  // the landing speed is 1 m/s
      print_message("%s: requested e %.3f, measured %.6f\n", engines[k], e, measured);
      assert_true(fabs(measured - e) <= (k == 0 ? SOFT_RESTITUTION_TOL : RIGID_RESTITUTION_TOL));
    }
    pd_model_free(m);
  }
  free(tr);
}

// ---------------------------------------------------------------------------------------------
// Gedanken B1 (a block slides down an incline at g (sin θ − μ cos θ)) with a planar body

static void test_planar_block_slides_down_an_incline_at_the_coulomb_rate(void** state) {
  (void)state;
  const double thetaDeg = 35.0, mu = 0.5, from = 0.3, to = 1.0;  // s: after the landing transients (B1)
  double th = thetaDeg * PI / 180.0;
  char text[1024];
  // the slab turned θ about y (its slope in the x–z plane), the box resting on it (gedanken/group_b.c)
  snprintf(text, sizeof text,
           "tend %g\nsample 100\ntol 1e-9\nvmax 1\n"
           "cube slab grey 2 1 0.2\nfixed\nloc 0 0 0  %.17g 0 1 0\nmu %g\nrestitution 0.5\n"
           "cube box red 0.1 0.1 0.1\nloc %.17g 0 %.17g  %.17g 0 1 0\nplanar\nmu %g\nrestitution 0.5\n",
           to, thetaDeg, mu, 0.15 * sin(th), 0.15 * cos(th), thetaDeg, mu);
  pdModel* m = compile(text);
  double expected = G * (sin(th) - mu * cos(th));
  const pdVec3 downhill = {cos(th), 0.0, -sin(th)};
  trace* tr = malloc(sizeof *tr);
  assert_non_null(tr);
  for (int e = 0; e < 3; ++e) {
    if (!run_in(engines[e], m, true, tr)) continue;
    int a = (int)lround(from * 100.0), b = tr->n - 1;
    double slope = (pd_v3_dot(tr->b[b].v, downhill) - pd_v3_dot(tr->b[a].v, downhill)) / (tr->t[b] - tr->t[a]);
    print_message("%s: downhill acceleration %.5f m/s^2, expected %.5f (%+.3f %%)\n", engines[e], slope, expected,
                  100.0 * (slope / expected - 1.0));
    assert_true(fabs(slope / expected - 1.0) <= (e == 0 ? SOFT_INCLINE_REL_TOL : RIGID_INCLINE_REL_TOL));
  }
  free(tr);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// bad input: FILE:LINE:COL for every misuse

static void test_misuse_is_refused_at_its_line(void** state) {
  (void)state;
  static const struct {
    const char* text;
    const char* expected;  // the start of "LINE:COL: message"
  } cases[] = {
      {"cube a red 1 1 1\nfixed\nplanar\n", "3:1: 'planar' on the fixed body"},
      {"cube a red 1 1 1\nplanar\nfixed\n", "3:1: 'fixed' on body 'a', which is planar (line 2)"},
      {"cube a red 1 1 1\nplanar\nplanar\n", "3:1: body 'a' is already planar (line 2)"},
      {"cube a red 1 1 1\nplanar 1\n", "2:"},
      {"planar\n", "1:1:"},
      {"cube a red 1 1 1\nvel 0 0.5 0\nplanar\n", "3:1: planar body 'a': its initial velocity leaves the x-z plane"},
      {"cube a red 1 1 1\nvel 0 0 0 10 1 0 0\nplanar\n", "3:1: planar body 'a': its initial velocity leaves"},
      {"cube a red 1 2 3\nloc 0 0 0 30 1 0 0\nplanar\n", "3:1: planar body 'a': world y is not a principal axis"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char got[1024];
    scene_error(cases[i].text, got, sizeof got);
    if (strncmp(got, cases[i].expected, strlen(cases[i].expected)) != 0)
      fail_msg("case %zu: got '%s', expected '%s...'", i, got, cases[i].expected);
  }
  // accepted: a box turned about y, spinning about y (its principal axes stay principal)
  char got[1024];
  scene_error("cube a red 1 2 3\nloc 0 0 0 30 0 1 0\nvel 1 0 2 45 0 1 0\nplanar\n", got, sizeof got);
  assert_string_equal(got, "");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_corner_drop_stays_in_its_plane_in_every_engine),
      cmocka_unit_test(test_vertex_landing_bounces_with_the_requested_restitution),
      cmocka_unit_test(test_planar_block_slides_down_an_incline_at_the_coulomb_rate),
      cmocka_unit_test(test_misuse_is_refused_at_its_line),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
