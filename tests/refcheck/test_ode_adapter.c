// The ODE adapter (refcheck/ode_adapter.c) against closed forms and its own documented behaviour:
// - the pose ODE reports at t = 0 is the scene's (the ODE body frame is the model's body frame);
// - a cube resting on a floor in the matched variant sinks by m g/(4 k_s) (4 vertex contacts, k_s the
//   pair's per-contact k_n), through 4 contacts on a floor plane;
// - a cube sliding to rest stops at v²/(2 μ g): ODE's pyramid along a pyramid axis, the aligned friction in
//   any direction, both variants; the pyramid along its diagonal stops short at v²/(2 √2 μ g) (the trap);
// - a cube on an incline steeper than the friction angle slides at g (sin θ − μ cos θ) with the aligned
//   friction whatever the slope's direction; ODE's pyramid holds it when the slope runs along the pyramid's
//   diagonal (the trap, again);
// - native: a cube dropped flat bounces with the requested e;
// - a floor plane that stops being exact (a body slides off the slab's face) becomes the slab's convex;
// - two runs give identical bytes, and two worlds stepped in turn give what each gives alone;
// - every scene in cases/ (examples, hard) finishes with finite numbers or is refused with a message.
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "polydyn/model.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "test_files.h"

#define G 9.81  // m/s², the scene default

// Tolerances: resting sinkage and stopping distance within 1 %.
#define SINKAGE_REL_TOL 0.01
#define STOPPING_DISTANCE_REL_TOL 0.01
// Speed below which the sliding cube counts as stopped, m/s: far below the 2 m/s it starts with.
#define STOPPED_SPEED 1e-6
// ODE's pyramid along its diagonal: each of the two rows is bounded by μN, so the cube decelerates at
// √2 μ g. The discrete step shortens the slide a little more (the last step); 2 % covers it.
#define PYRAMID_DIAGONAL_REL_TOL 0.02
// Native bounce with hard contact: the row's target speed is e times the approach speed at the step's
// start, exact up to the push-out of the penetration (ERP 0.2 of at most one step's travel, well below
// e v); a flat landing spreads it over 4 contacts that the Dantzig solver treats exactly. 0.5 % of e.
#define BOUNCE_REL_TOL 0.005
// Incline: the distance slid in 1 s against ½ a t², a = g (sin θ − μ cos θ); the cube starts touching and
// falls freely for its first step (1 ms), far below 1 % of the second it slides.
#define INCLINE_REL_TOL 0.01
// A cube held by the pyramid on the incline moves only by the first step's free fall and the settling into
// contact: micrometres, against the 0.33 m it would slide.
#define INCLINE_HELD_DISTANCE 1e-4  // m
// q at t = 0: ODE normalises the quaternion it is given; a unit quaternion changes by rounding only.
#define INITIAL_POSE_TOL 1e-15

// ---------------------------------------------------------------------------------------------
// helpers

static pdModel* compile_text(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("ode.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %d:%d: %s", err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) fail_msg("compile: %d:%d: %s", err.line, err.col, err.message);
  return model;
}

static pdModel* compile_file(const char* path) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_file(path, &err);
  if (!scene) fail_msg("parse %s: %d:%d: %s", path, err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) fail_msg("compile %s: %d:%d: %s", path, err.line, err.col, err.message);
  return model;
}

static int body_index(const pdModel* m, const char* name) {
  for (int i = 0; i < m->bodyCount; ++i)
    if (!strcmp(m->bodies[i].name, name)) return i;
  fail_msg("no body %s", name);
  return -1;
}

static const pdRefAdapter* ode(void) {
  const pdRefAdapter* a = pd_ref_adapter("ode");
  assert_non_null(a);
  return a;
}

static pdRefWorld* create(const pdModel* m, pdRefVariant variant, pdOdeFriction friction) {
  pdRefOptions o = {.variant = variant, .step = PD_REF_DEFAULT_STEP, .odeFriction = friction};
  pdError err;
  memset(&err, 0, sizeof err);
  pdRefWorld* w = ode()->create(m, &o, &err);
  if (!w) fail_msg("create: %s", err.message);
  return w;
}

// Steps to t (whole steps of PD_REF_DEFAULT_STEP).
static void advance(pdRefWorld* w, double t) {
  long steps = lround(t / PD_REF_DEFAULT_STEP);
  for (long k = 0; k < steps; ++k) assert_true(ode()->step(w, PD_REF_DEFAULT_STEP));
}

// The adapter's settings JSON as a string (caller frees).
static char* settings(const pdRefWorld* w) {
  char* text = NULL;
  size_t size = 0;
  FILE* f = open_memstream(&text, &size);
  assert_non_null(f);
  ode()->settings_json(w, f);
  fclose(f);
  // a copy: gcc -O3 takes pointers into the stream buffer for pointers into this frame (a false
  // -Wdangling-pointer in the callers)
  char* copy = strdup(text);
  free(text);
  assert_non_null(copy);
  return copy;
}

static const char* variant_name(pdRefVariant v) { return v == pd_refMatched ? "matched" : "native"; }
static const char* friction_name(pdOdeFriction f) { return f == pd_odeFrictionAligned ? "aligned" : "pyramid"; }

// ---------------------------------------------------------------------------------------------
// the pose at t = 0

static bool first_sample(const pdModel* model, const pdState* state, void* user) {
  pdBodyState* out = user;
  if (state->t == 0.0)
    for (int i = 0; i < model->movingCount; ++i) out[i] = pd_state_body(model, state, model->movingBodies[i]);
  return true;
}

static char* temp_dir(void) {
  char* dir = strdup("/tmp/polydyn-ode-test-XXXXXX");
  assert_non_null(dir);
  assert_non_null(mkdtemp(dir));
  return dir;
}

static void remove_run(const char* dir) {
  char path[1100];
  const char* files[] = {"trajectory.csv", "contacts.csv", "summary.json"};
  for (int i = 0; i < 3; ++i) {
    int n = snprintf(path, sizeof path, "%s/%s", dir, files[i]);
    assert_true(n > 0 && (size_t)n < sizeof path);
    unlink(path);
  }
  rmdir(dir);
}

// Runs the model through the driver into DIR (a run directory); returns the driver's result.
static bool run_to_dir(const pdModel* m, const pdRefOptions* o, const char* dir, pdObserverFcn* observer, void* user,
                       pdRefRunStats* stats, pdError* err) {
  pdRunWriter* writer = pd_run_open(dir, err);
  assert_non_null(writer);
  return pd_ref_run(m, ode(), o, writer, observer, user, stats, err);
}

static void test_trajectory_starts_at_the_scene_pose(void** state) {
  (void)state;
  pdModel* m = compile_text("tend 0.01\nsample 100\n"
                            "cube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n"
                            "tprism cone blue 5 0.3 0.2 0.4 0.6\nloc 0.3 -0.2 1  37 1 2 3\nvel 1 0 2  90 0.2 1 0.1\n"
                            "cube box red 0.2 0.3 0.4\nloc -1 0 1  -120 0 1 1\n");
  pdBodyState first[2];
  memset(first, 0, sizeof first);
  char* tmp = temp_dir();
  char dir[512];
  snprintf(dir, sizeof dir, "%s/run", tmp);
  pdRefOptions o = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
  pdRefRunStats stats;
  pdError err;
  memset(&err, 0, sizeof err);
  assert_true(run_to_dir(m, &o, dir, first_sample, first, &stats, &err));
  for (int i = 0; i < 2; ++i) {
    const pdBody* b = &m->bodies[m->movingBodies[i]];
    double dq = fmax(fmax(fabs(first[i].q.w - b->q0.w), fabs(first[i].q.x - b->q0.x)),
                     fmax(fabs(first[i].q.y - b->q0.y), fabs(first[i].q.z - b->q0.z)));
    double dx = pd_v3_norm(pd_v3_sub(first[i].x, b->x0));
    double dv = pd_v3_norm(pd_v3_sub(first[i].v, b->v0)) + pd_v3_norm(pd_v3_sub(first[i].w, b->w0));
    print_message("%s: |Δq| %.2e, |Δx| %.2e, |Δv| + |Δω| %.2e at t = 0\n", b->name, dq, dx, dv);
    assert_true(dq <= INITIAL_POSE_TOL && dx == 0.0 && dv == 0.0);
  }
  remove_run(dir);
  rmdir(tmp);
  free(tmp);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// resting: matched sinkage m g/(4 k_s) through the 4 corner contacts on the floor plane

static void test_matched_cube_rests_at_the_static_sinkage(void** state) {
  (void)state;
  const double side = 0.2;
  pdModel* m = compile_text("tend 1\ncube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\nrestitution 0.5\n"
                            "cube box red 0.2 0.2 0.2\nloc 0 0 0.1\nrestitution 0.5\n");
  int box = body_index(m, "box");
  pdPairContact pair = pd_model_pair_contact(m, body_index(m, "floor"), box);
  double sinkage = m->bodies[box].mass * G / (4.0 * pair.kn);
  pdRefWorld* w = create(m, pd_refMatched, pd_odeFrictionPyramid);
  advance(w, 1.0);
  pdBodyState b = ode()->body(w, 0);
  double measured = 0.5 * side - b.x.z;
  print_message("matched rest: z %.12f, sinkage %.6e m, expected m g/(4 k) = %.6e m (k %.6e N/m), error %.3f %%, "
                "%d contacts, |v| %.1e m/s\n",
                b.x.z, measured, sinkage, pair.kn, 100.0 * (measured / sinkage - 1.0), ode()->contact_count(w),
                pd_v3_norm(b.v));
  assert_true(fabs(measured / sinkage - 1.0) <= SINKAGE_REL_TOL);
  assert_int_equal(ode()->contact_count(w), 4);
  char* json = settings(w);
  assert_non_null(strstr(json, "exact for the whole run"));
  free(json);
  ode()->destroy(w);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// sliding to rest: v²/(2 μ g)

static double stopping_distance(pdRefVariant variant, pdOdeFriction friction, double angleDeg) {
  const double v0 = 2.0, a = angleDeg * 3.14159265358979323846 / 180.0;
  char text[1024];
  snprintf(text, sizeof text,
           "tend 1\ncube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.5\n"
           "cube box red 0.2 0.2 0.2\nloc 0 0 0.1\nvel %.17g %.17g 0\nmu 0.5\nrestitution 0.5\n",
           v0 * cos(a), v0 * sin(a));
  pdModel* m = compile_text(text);
  double mu = pd_model_pair_contact(m, 0, 1).mu;
  double expected = v0 * v0 / (2.0 * mu * G);
  pdRefWorld* w = create(m, variant, friction);
  advance(w, 1.0);
  pdBodyState b = ode()->body(w, 0);
  assert_true(pd_v3_norm(b.v) < STOPPED_SPEED);
  double d = hypot(b.x.x, b.x.y);
  print_message("slide %s %s at %g°: %.6f m, v²/(2 μ g) = %.6f m (%+.3f %%), sideways %.2e m\n", variant_name(variant),
                friction_name(friction), angleDeg, d, expected, 100.0 * (d / expected - 1.0),
                fabs(-b.x.x * sin(a) + b.x.y * cos(a)));
  ode()->destroy(w);
  pd_model_free(m);
  return d / expected;
}

static void test_sliding_cube_stops_at_the_coulomb_distance(void** state) {
  (void)state;
  const pdRefVariant variants[] = {pd_refNative, pd_refMatched};
  for (int i = 0; i < 2; ++i) {
    // along a pyramid axis (x is one of dPlaneSpace's for the +z normal) both frictions are Coulomb
    assert_true(fabs(stopping_distance(variants[i], pd_odeFrictionPyramid, 0.0) - 1.0) <= STOPPING_DISTANCE_REL_TOL);
    // aligned is isotropic: any direction
    assert_true(fabs(stopping_distance(variants[i], pd_odeFrictionAligned, 45.0) - 1.0) <= STOPPING_DISTANCE_REL_TOL);
    assert_true(fabs(stopping_distance(variants[i], pd_odeFrictionAligned, 30.0) - 1.0) <= STOPPING_DISTANCE_REL_TOL);
  }
}

// The documented trap: ODE's pyramid along its diagonal bounds the friction force by √2 μ N.
static void test_pyramid_friction_is_stronger_along_its_diagonal(void** state) {
  (void)state;
  const pdRefVariant variants[] = {pd_refNative, pd_refMatched};
  for (int i = 0; i < 2; ++i) {
    double ratio = stopping_distance(variants[i], pd_odeFrictionPyramid, 45.0);
    assert_true(fabs(ratio * sqrt(2.0) - 1.0) <= PYRAMID_DIAGONAL_REL_TOL);
  }
}

// ---------------------------------------------------------------------------------------------
// incline: a fixed floor slab turned by θ about a horizontal axis at azimuth φ, a cube resting on it

static double incline_slide(pdRefVariant variant, pdOdeFriction friction, double phiDeg, double* expected) {
  const double theta = 30.0, mu = 0.5, pi = 3.14159265358979323846;
  pdVec3 axis = {cos(phiDeg * pi / 180.0), sin(phiDeg * pi / 180.0), 0.0};
  pdVec3 centre = pd_quat_rotate(pd_quat_from_axis_angle(axis, theta * pi / 180.0), (pdVec3){0, 0, 0.2});
  char text[1024];
  // vmax 1: the estimate (a fall from the cube's top to the tilted floor's lowest corner, ~4.6 m/s) would
  // size a contact for an impact that never happens; that stiff a k gives ODE's matched soft contact
  // erp ≈ 1 at h = 1 ms, and ODE's solver then lets the sliding cube chatter (a third less distance)
  snprintf(text, sizeof text,
           "tend 1\nvmax 1\ncube floor grey 4 4 0.2\nfixed\nloc 0 0 0  %g %.17g %.17g 0\nmu %g\nrestitution 0.5\n"
           "cube box red 0.2 0.2 0.2\nloc %.17g %.17g %.17g  %g %.17g %.17g 0\nmu %g\nrestitution 0.5\n",
           theta, axis.x, axis.y, mu, centre.x, centre.y, centre.z, theta, axis.x, axis.y, mu);
  pdModel* m = compile_text(text);
  pdRefWorld* w = create(m, variant, friction);
  advance(w, 1.0);
  double d = pd_v3_norm(pd_v3_sub(ode()->body(w, 0).x, centre));
  *expected = 0.5 * G * (sin(theta * pi / 180.0) - mu * cos(theta * pi / 180.0));
  print_message("incline 30° (friction angle %.2f°), tilt axis at azimuth %g°, %s %s: slid %.6f m, ½ a t² = %.6f m\n",
                atan(mu) * 180.0 / pi, phiDeg, variant_name(variant), friction_name(friction), d, *expected);
  ode()->destroy(w);
  pd_model_free(m);
  return d;
}

static void test_incline_slides_at_the_coulomb_rate_with_aligned_friction(void** state) {
  (void)state;
  const pdRefVariant variants[] = {pd_refNative, pd_refMatched};
  for (int i = 0; i < 2; ++i) {
    double expected;
    for (double phi = 20.0; phi <= 45.0; phi += 25.0) {
      double d = incline_slide(variants[i], pd_odeFrictionAligned, phi, &expected);
      assert_true(fabs(d / expected - 1.0) <= INCLINE_REL_TOL);
    }
    // tan 30° = 0.577 lies between μ = 0.5 and √2 μ = 0.707: along its diagonal the pyramid holds the cube
    assert_true(incline_slide(variants[i], pd_odeFrictionPyramid, 45.0, &expected) < INCLINE_HELD_DISTANCE);
  }
}

// ---------------------------------------------------------------------------------------------
// native bounce: a cube dropped flat leaves the floor at e times its landing speed

static void test_native_flat_drop_bounces_with_the_requested_restitution(void** state) {
  (void)state;
  const double requested[] = {0.25, 0.5, 0.9};
  for (int i = 0; i < 3; ++i) {
    char text[1024];
    snprintf(text, sizeof text,
             "tend 1\ncube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\nrestitution %g\n"
             "cube box red 0.2 0.2 0.2\nloc 0 0 0.6\nrestitution %g\n",
             requested[i], requested[i]);
    pdModel* m = compile_text(text);
    double e = pd_model_pair_contact(m, 0, 1).restitution;
    pdRefWorld* w = create(m, pd_refNative, pd_odeFrictionPyramid);
    double before = 0.0, after = 0.0;
    int contacts = 0;
    for (long k = 0; k < 1000; ++k) {
      double vz = ode()->body(w, 0).v.z;
      assert_true(ode()->step(w, PD_REF_DEFAULT_STEP));
      if (ode()->contact_count(w) > 0) {
        before = vz;
        after = ode()->body(w, 0).v.z;
        contacts = ode()->contact_count(w);
        break;
      }
    }
    double measured = -after / before;
    print_message("native flat drop: e %.3f, landing %.6f m/s, leaving %.6f m/s, measured e %.6f (%+.3f %%), %d contacts\n",
                  e, before, after, measured, 100.0 * (measured / e - 1.0), contacts);
    assert_int_equal(contacts, 4);
    assert_true(fabs(measured / e - 1.0) <= BOUNCE_REL_TOL);
    ode()->destroy(w);
    pd_model_free(m);
  }
}

// ---------------------------------------------------------------------------------------------
// a floor plane is exact only while the body stays over the slab's face

static void test_floor_plane_becomes_convex_when_a_body_leaves_its_face(void** state) {
  (void)state;
  // a 1 m slab (top at z = 0); a cube slides off its +x edge at 3 m/s with little friction
  pdModel* m = compile_text("tend 1\ncube slab grey 1 1 0.1\nfixed\nloc 0 0 -0.05\nmu 0.1\n"
                            "cube box red 0.1 0.1 0.1\nloc 0.3 0 0.05\nvel 3 0 0\nmu 0.1\n");
  pdRefWorld* w = create(m, pd_refNative, pd_odeFrictionPyramid);
  char* json = settings(w);
  assert_non_null(strstr(json, "exact for the whole run"));  // a plane at the start
  free(json);
  advance(w, 1.0);
  pdBodyState b = ode()->body(w, 0);
  json = settings(w);
  const char* at = strstr(json, "\"switched_to_convex_at\": ");
  assert_non_null(at);
  double t = strtod(at + strlen("\"switched_to_convex_at\": "), NULL);
  print_message("slab: switched to convex at t = %.3f s; the cube is at x %.3f, z %.3f after 1 s\n", t, b.x.x, b.x.z);
  // the cube's edge reaches the slab's edge after (0.5 − 0.05 − 0.3)/3 = 0.05 s
  assert_true(t > 0.0 && t < 0.1);
  assert_true(b.x.z < -0.5);  // it fell past the slab, which the plane would have held up
  free(json);
  ode()->destroy(w);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// determinism

static void test_two_runs_give_identical_bytes(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/examples/demo.scene");
  const pdRefOptions options[] = {
      {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionAligned},
      {.variant = pd_refMatched, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid}};
  for (int i = 0; i < 2; ++i) {
    char* tmp = temp_dir();
    char dirs[2][512];
    for (int r = 0; r < 2; ++r) {
      snprintf(dirs[r], sizeof dirs[r], "%s/run%d", tmp, r);
      pdRefRunStats stats;
      pdError err;
      memset(&err, 0, sizeof err);
      assert_true(run_to_dir(m, &options[i], dirs[r], NULL, NULL, &stats, &err));
      assert_true(stats.completed);
    }
    const char* files[] = {"trajectory.csv", "summary.json"};
    for (int f = 0; f < 2; ++f) {
      char a[600], b[600];
      snprintf(a, sizeof a, "%s/%s", dirs[0], files[f]);
      snprintf(b, sizeof b, "%s/%s", dirs[1], files[f]);
      size_t na, nb;
      char* ta = test_read_file(a, &na);
      char* tb = test_read_file(b, &nb);
      if (f == 1) {  // summary.json: everything before the timing part
        char* ca = strstr(ta, "\"timing\"");
        char* cb = strstr(tb, "\"timing\"");
        assert_non_null(ca);
        assert_non_null(cb);
        na = (size_t)(ca - ta);
        nb = (size_t)(cb - tb);
      }
      assert_int_equal(na, nb);
      assert_memory_equal(ta, tb, na);
      free(ta);
      free(tb);
    }
    print_message("demo %s %s: two runs, identical trajectory.csv and summary.json (timing aside)\n",
                  variant_name(options[i].variant), friction_name(options[i].odeFriction));
    for (int r = 0; r < 2; ++r) remove_run(dirs[r]);
    rmdir(tmp);
    free(tmp);
  }
  pd_model_free(m);
}

// Each world has its own dWorld, dSpace and contact group: stepping two in turn changes neither.
static void test_two_worlds_stepped_in_turn_match_one_alone(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/examples/demo.scene");
  pdRefWorld* alone = create(m, pd_refMatched, pd_odeFrictionAligned);
  advance(alone, 1.0);
  pdRefWorld* a = create(m, pd_refMatched, pd_odeFrictionAligned);
  pdRefWorld* b = create(m, pd_refNative, pd_odeFrictionPyramid);
  for (int k = 0; k < 1000; ++k) {
    assert_true(ode()->step(a, PD_REF_DEFAULT_STEP));
    assert_true(ode()->step(b, PD_REF_DEFAULT_STEP));
  }
  for (int i = 0; i < m->movingCount; ++i) {
    pdBodyState x = ode()->body(alone, i), y = ode()->body(a, i);
    assert_memory_equal(&x, &y, sizeof x);
  }
  ode()->destroy(b);
  ode()->destroy(a);
  ode()->destroy(alone);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// every scene of cases/

typedef struct drift {
  int movingCount;
  pdBodyState start[64];
  double largestMove;  // m: the largest distance any body's centre moved from its start, at tend
  double lowestZ;      // m: the lowest centre height seen
} drift;

static bool track(const pdModel* model, const pdState* state, void* user) {
  drift* d = user;
  for (int i = 0; i < model->movingCount && i < 64; ++i) {
    pdBodyState b = pd_state_body(model, state, model->movingBodies[i]);
    if (state->t == 0.0) d->start[i] = b;
    d->lowestZ = fmin(d->lowestZ, b.x.z);
    if (state->t >= model->settings.tend * (1.0 - 1e-12))
      d->largestMove = fmax(d->largestMove, pd_v3_norm(pd_v3_sub(b.x, d->start[i].x)));
  }
  return true;
}

static int compare_names(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

static void run_cases_in(const char* folder) {
  DIR* d = opendir(folder);
  assert_non_null(d);
  char* names[256];
  int count = 0;
  for (struct dirent* e = readdir(d); e && count < 256; e = readdir(d)) {
    size_t n = strlen(e->d_name);
    if (n > 6 && !strcmp(e->d_name + n - 6, ".scene")) names[count++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, (size_t)count, sizeof *names, compare_names);
  assert_true(count > 0);
  const pdRefVariant variants[] = {pd_refNative, pd_refMatched};
  for (int i = 0; i < count; ++i) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", folder, names[i]);
    pdModel* m = compile_file(path);
    for (int v = 0; v < 2; ++v) {
      char* tmp = temp_dir();
      char dir[512];
      snprintf(dir, sizeof dir, "%s/run", tmp);
      pdRefOptions o = {.variant = variants[v], .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
      pdRefRunStats stats;
      pdError err;
      memset(&err, 0, sizeof err);
      drift dr = {.movingCount = m->movingCount, .lowestZ = INFINITY};
      bool ok = run_to_dir(m, &o, dir, track, &dr, &stats, &err);
      if (stats.refused) {
        print_message("%-28s %-7s refused: %s\n", names[i], variant_name(variants[v]), err.message);
        assert_true(err.message[0] != '\0');
      } else {
        assert_true(ok);
        print_message("%-28s %-7s %s, %ld steps, wall %.3f s, max contacts %ld, largest move %.4f m, lowest z %.4f m\n",
                      names[i], variant_name(variants[v]), stats.completed ? "completed" : "NOT COMPLETED",
                      stats.steps, stats.wallSeconds, stats.maxContacts, dr.largestMove, dr.lowestZ);
        assert_true(stats.completed);
        remove_run(dir);
      }
      rmdir(tmp);
      free(tmp);
    }
    pd_model_free(m);
    free(names[i]);
  }
}

static void test_every_case_scene_finishes_or_is_refused(void** state) {
  (void)state;
  run_cases_in(PD_SOURCE_DIR "/cases/examples");
  run_cases_in(PD_SOURCE_DIR "/cases/hard");
}

// ---------------------------------------------------------------------------------------------
// applied force (scene `force`)

#include "applied_force_checks.h"

static void test_applied_force_gives_the_exact_impulse_and_torque(void** state) {
  (void)state;
  check_applied_force(ode(), pd_refNative);
  check_applied_force(ode(), pd_refMatched);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_applied_force_gives_the_exact_impulse_and_torque),
      cmocka_unit_test(test_trajectory_starts_at_the_scene_pose),
      cmocka_unit_test(test_matched_cube_rests_at_the_static_sinkage),
      cmocka_unit_test(test_sliding_cube_stops_at_the_coulomb_distance),
      cmocka_unit_test(test_pyramid_friction_is_stronger_along_its_diagonal),
      cmocka_unit_test(test_incline_slides_at_the_coulomb_rate_with_aligned_friction),
      cmocka_unit_test(test_native_flat_drop_bounces_with_the_requested_restitution),
      cmocka_unit_test(test_floor_plane_becomes_convex_when_a_body_leaves_its_face),
      cmocka_unit_test(test_two_runs_give_identical_bytes),
      cmocka_unit_test(test_two_worlds_stepped_in_turn_match_one_alone),
      cmocka_unit_test(test_every_case_scene_finishes_or_is_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
