// The Bullet adapter (refcheck/bullet_adapter.c) against closed forms and the model it runs: the pose at
// t = 0 is the scene's and the angular momentum of a free, asymmetric body stays put (the principal ↔ body
// frame conversion), a matched cube rests at its spring sinkage m g/(4 k), a sliding cube stops after
// v²/(2μg), a native flat landing bounces with the pair's e, a matched single vertex contact bounces with
// the e of eq. (15), two runs write the same bytes, every scene in cases/ runs or is refused with a message.
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "material.h"
#include "polydyn/model.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "polydyn/scene.h"
#include "test_files.h"

#define G 9.81  // m/s², the scene default

// Tolerances (catalogue A1, A3, B2, and 1 % for resting sinkage and stopping distance).
#define POSE_TOL 1e-12  // initial pose: one rotation matrix ↔ quaternion round trip in Bullet
#define SINKAGE_REL_TOL 0.01
#define STOPPING_DISTANCE_REL_TOL 0.01
#define RESTITUTION_TOL 0.005
// At rest: matched contacts are springs the solver converges on (m/s); a native rigid contact jitters by
// up to one step of gravity, g h, as the split impulse pushes the body out of the floor.
#define MATCHED_REST_SPEED 1e-6

// ---------------------------------------------------------------------------------------------
// helpers

static pdModel* compile_text(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("bullet.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %d:%d: %s", err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) fail_msg("compile: %d:%d: %s", err.line, err.col, err.message);
  return model;
}

static const pdRefAdapter* bullet(void) {
  const pdRefAdapter* a = pd_ref_adapter("bullet");
  assert_non_null(a);
  return a;
}

static pdRefWorld* create(const pdModel* m, pdRefVariant variant, double step) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdRefOptions options = {.variant = variant, .step = step, .odeFriction = pd_odeFrictionPyramid};
  pdRefWorld* w = bullet()->create(m, &options, &err);
  if (!w) fail_msg("create: %d:%d: %s", err.line, err.col, err.message);
  return w;
}

static int body_index(const pdModel* m, const char* name) {
  for (int i = 0; i < m->bodyCount; ++i)
    if (!strcmp(m->bodies[i].name, name)) return i;
  fail_msg("no body %s", name);
  return -1;
}

static const char* variant_name(pdRefVariant v) { return v == pd_refMatched ? "matched" : "native"; }

// World angular momentum about the centre of mass from the model's inertia and the reported pose: L = R I Rᵀ ω.
static pdVec3 angular_momentum(const pdBody* b, pdBodyState s) {
  pdMat3 r = pd_quat_to_mat3(s.q);
  pdVec3 body = pd_mat3_tmulv(&r, s.w);
  pdVec3 l = pd_mat3_mulv(&b->inertia, body);
  return pd_mat3_mulv(&r, l);
}

// ---------------------------------------------------------------------------------------------
// frames: an irregular hull (inertia far from diagonal in its body axes), turned and spinning

static const char* const oddHull =
    "gravity 0 0 0\ntend 1\nsample 1000\n"
    "hull odd red 0 0 0  0.3 0 0  0 0.2 0  0 0 0.1  0.25 0.15 0.12  -0.05 0.1 0.2\n"
    "loc 1 2 3  37 1 2 3\nvel 0.1 0.2 0.3  300 1 0.5 0.2\n";

static void test_initial_pose_is_the_scene_pose(void** state) {
  (void)state;
  pdModel* m = compile_text(oddHull);
  const pdBody* b = &m->bodies[0];
  // the test means something only if the principal frame is far from the body frame
  assert_true(fabs(b->principalAxes.m[0][0]) < 0.99 && fabs(b->principalAxes.m[1][1]) < 0.99);
  for (int v = pd_refNative; v <= pd_refMatched; ++v) {
    pdRefWorld* w = create(m, (pdRefVariant)v, 1e-3);
    pdBodyState s = bullet()->body(w, 0);
    double dq = fmax(fmax(fabs(s.q.w - b->q0.w), fabs(s.q.x - b->q0.x)),
                     fmax(fabs(s.q.y - b->q0.y), fabs(s.q.z - b->q0.z)));
    double dx = pd_v3_norm(pd_v3_sub(s.x, b->x0)), dv = pd_v3_norm(pd_v3_sub(s.v, b->v0)),
           dw = pd_v3_norm(pd_v3_sub(s.w, b->w0));
    print_message("%s: |dx| %.1e m, |dq| %.1e, |dv| %.1e m/s, |dw| %.1e rad/s\n", variant_name((pdRefVariant)v), dx, dq,
                  dv, dw);
    assert_true(dx <= POSE_TOL * pd_v3_norm(b->x0));
    assert_true(dq <= POSE_TOL);
    assert_true(dv <= POSE_TOL * pd_v3_norm(b->v0) && dw <= POSE_TOL * pd_v3_norm(b->w0));
    bullet()->destroy(w);
  }
  pd_model_free(m);
}

// Torque free, the world angular momentum is constant; computed from the model's full inertia tensor and
// the reported orientation it stays constant only if Bullet's principal frame and moments match the model's
// (a wrong frame gives an O(1) error at any step). What is left is Bullet's first-order integration error:
// below ω h over 1 s and ten times smaller at a ten times smaller step.
static double angular_momentum_drift(const pdModel* m, double h) {
  const pdBody* b = &m->bodies[0];
  pdRefWorld* w = create(m, pd_refNative, h);
  pdVec3 l0 = angular_momentum(b, bullet()->body(w, 0));
  double worst = 0.0;
  for (int k = 0, steps = (int)(1.0 / h + 0.5); k < steps; ++k) {
    assert_true(bullet()->step(w, h));
    pdVec3 l = angular_momentum(b, bullet()->body(w, 0));
    worst = fmax(worst, pd_v3_norm(pd_v3_sub(l, l0)) / pd_v3_norm(l0));
  }
  pdBodyState s = bullet()->body(w, 0);
  pdVec3 expected = pd_v3_add(b->x0, b->v0);  // 1 s of uniform motion
  assert_true(pd_v3_norm(pd_v3_sub(s.x, expected)) < 1e-9);
  bullet()->destroy(w);
  return worst;
}

static void test_free_body_keeps_its_angular_momentum(void** state) {
  (void)state;
  pdModel* m = compile_text(oddHull);
  double spin = pd_v3_norm(m->bodies[0].w0);
  double coarse = angular_momentum_drift(m, 1e-3), fine = angular_momentum_drift(m, 1e-4);
  print_message("|L| drift over 1 s: %.2e at h = 1 ms, %.2e at 0.1 ms (ratio %.3f); omega h = %.2e\n", coarse, fine,
                fine / coarse, spin * 1e-3);
  assert_true(coarse <= spin * 1e-3);
  assert_true(fine / coarse > 0.08 && fine / coarse < 0.12);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// A3: a 0.2 m cube set down on a floor, matched: four contact springs k_s (the pair's per-contact kn)
// carry m g, so its centre rests 0.5·side − m g/(4 k_s) above the floor.

static void test_matched_cube_rests_at_the_spring_sinkage(void** state) {
  (void)state;
  pdModel* m = compile_text("cube floor grey 1 1 0.2\nfixed\nloc 0 0 -0.1\nrestitution 0.5\n"
                            "cube box red 0.2 0.2 0.2\nloc 0 0 0.1\nrestitution 0.5\n");
  int box = body_index(m, "box");
  pdPairContact pair = pd_model_pair_contact(m, body_index(m, "floor"), box);
  double expected = m->bodies[box].mass * G / (4.0 * pair.kn);
  pdRefWorld* w = create(m, pd_refMatched, 1e-3);
  for (int k = 0; k < 2000; ++k) assert_true(bullet()->step(w, 1e-3));
  pdBodyState s = bullet()->body(w, 0);
  double sinkage = 0.1 - s.x.z, speed = pd_v3_norm(s.v);
  int contacts = bullet()->contact_count(w);
  print_message("A3 matched: sinkage %.6e m, m g/(4 k) %.6e m, rel. error %.2e; %d contacts; speed %.1e m/s\n", sinkage,
                expected, sinkage / expected - 1.0, contacts, speed);
  assert_true(fabs(sinkage / expected - 1.0) <= SINKAGE_REL_TOL);
  assert_int_equal(contacts, 4);
  assert_true(speed < MATCHED_REST_SPEED);
  bullet()->destroy(w);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// B2: a 0.1 m cube launched at 2 m/s along a floor with μ = 0.4 stops after v²/(2μg), in both variants
// (Bullet's friction is rigid Coulomb in both).

static void test_sliding_cube_stops_at_the_coulomb_distance(void** state) {
  (void)state;
  pdModel* m = compile_text("cube floor grey 4 1 0.2\nfixed\nloc 1 0 -0.1\nmu 0.4\nrestitution 0.5\n"
                            "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nvel 2 0 0\nmu 0.4\nrestitution 0.5\n");
  double coulomb = 2.0 * 2.0 / (2.0 * 0.4 * G);
  assert_true(fabs(pd_model_pair_contact(m, 0, 1).mu - 0.4) < 1e-15);
  for (int v = pd_refNative; v <= pd_refMatched; ++v) {
    pdRefWorld* w = create(m, (pdRefVariant)v, 1e-3);
    for (int k = 0; k < 1000; ++k) assert_true(bullet()->step(w, 1e-3));
    pdBodyState s = bullet()->body(w, 0);
    double d = s.x.x, speed = pd_v3_norm(s.v);
    print_message("B2 %s: distance %.6f m, Coulomb %.6f m, rel. error %.2e; final speed %.1e m/s\n",
                  variant_name((pdRefVariant)v), d, coulomb, d / coulomb - 1.0, speed);
    assert_true(fabs(d / coulomb - 1.0) <= STOPPING_DISTANCE_REL_TOL);
    assert_true(speed < (v == pd_refMatched ? MATCHED_REST_SPEED : G * 1e-3));
    bullet()->destroy(w);
  }
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// A1, native: a 0.1 m cube dropped flat from 0.5 m; the first impact reverses the approach speed times the
// pair's e (Newton restitution, exact for a flat landing once the solver has converged). Sampled every
// step: the velocity after the impact step over the velocity before it (the impact takes one step; the
// penetration is then removed by the split impulse, which adds no velocity).

// The velocity before the first step that slows the fall over the velocity after that step (rigid impact,
// native) or after the last step in contact (soft contact, matched: it lasts many steps; gravity off).
static double first_impact_restitution(const pdModel* m, pdRefVariant variant, double h, double tend) {
  pdRefWorld* w = create(m, variant, h);
  double before = 0.0, after = 0.0;
  int steps = (int)(tend / h + 0.5);
  for (int k = 0; k < steps && after == 0.0; ++k) {
    double v = bullet()->body(w, 0).v.z;
    assert_true(bullet()->step(w, h));
    double next = bullet()->body(w, 0).v.z;
    if (before == 0.0 && v < 0.0 && next > v) before = v;
    if (before != 0.0 && (variant == pd_refNative || bullet()->contact_count(w) == 0)) after = next;
  }
  bullet()->destroy(w);
  assert_true(before < 0.0 && after > 0.0);
  return after / -before;
}

static void test_native_flat_landing_bounces_with_the_pair_restitution(void** state) {
  (void)state;
  const double requested[] = {0.3, 0.5, 0.8};
  for (int i = 0; i < 3; ++i) {
    char text[512];
    snprintf(text, sizeof text,
             "cube floor grey 1 1 0.2\nfixed\nloc 0 0 -0.1\nrestitution %g\n"
             "cube box red 0.1 0.1 0.1\nloc 0 0 0.55\nrestitution %g\n",
             requested[i], requested[i]);
    pdModel* m = compile_text(text);
    double pairE = pd_model_pair_contact(m, 0, 1).restitution;
    assert_true(fabs(pairE - requested[i]) < 1e-12);
    double e = first_impact_restitution(m, pd_refNative, 1e-3, 0.5);
    print_message("A1 native flat cube, e requested %.2f: measured %.6f\n", requested[i], e);
    assert_true(fabs(e - pairE) <= RESTITUTION_TOL);
    pd_model_free(m);
  }
}

// A1, matched: a regular octahedron falls vertex first at 1 m/s onto a fixed cube, gravity off,
// frictionless: one contact spring-damper; with a step small against the contact time Bullet's implicit
// spring-damper bounces with e = exp(−2ζ arccos ζ/√(1−ζ²)), ζ = c/(2√(k m)) of the pair. The vertex starts
// 0.12345678 mm above the face so that it does not reach it exactly at the end of a step: at an exact touch
// Bullet's GJK/EPA returns an arbitrary normal and the point made with it stays in the manifold (docs/validation.md, Bullet).

static void test_matched_single_contact_bounces_with_eq_15(void** state) {
  (void)state;
  pdModel* m = compile_text("gravity 0 0 0\ncube plate grey 0.2 0.2 0.2\nfixed\nloc 0 0 -0.1\nmu 0\nrestitution 0.5\n"
                            "hull oct red 0.1 0 0  -0.1 0 0  0 0.1 0  0 -0.1 0  0 0 0.1  0 0 -0.1\n"
                            "loc 0 0 0.10012345678\nvel 0 0 -1\nmu 0\nrestitution 0.5\n");
  int oct = body_index(m, "oct");
  pdPairContact pair = pd_model_pair_contact(m, body_index(m, "plate"), oct);
  double zeta = pair.cn / (2.0 * sqrt(pair.kn * m->bodies[oct].mass));
  double predicted = pd_restitution_from_damping_ratio(zeta);
  double e = first_impact_restitution(m, pd_refMatched, 1e-5, 0.05);
  print_message("A1 matched vertex contact, h = 1e-5 s: zeta %.5f, predicted e %.6f, measured %.6f\n", zeta,
                predicted, e);
  assert_true(fabs(e - predicted) <= RESTITUTION_TOL);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// whole runs through the driver: determinism, every scene of cases/, refusals

static pdModel* compile_file(const char* path) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_file(path, &err);
  if (!scene) fail_msg("%s:%d:%d: %s", path, err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) fail_msg("%s:%d:%d: %s", path, err.line, err.col, err.message);
  return model;
}

// Every sample's bodies are finite (the driver stops at a non-finite state; this checks what it wrote).
static bool all_finite(const pdModel* model, const pdState* state, void* user) {
  bool* finite = user;
  for (int i = 0; i < model->movingCount; ++i) {
    pdBodyState b = pd_state_body(model, state, model->movingBodies[i]);
    *finite = *finite && pd_v3_isfinite(b.x) && pd_v3_isfinite(b.v) && pd_v3_isfinite(b.w) && isfinite(b.q.w) &&
              isfinite(b.q.x) && isfinite(b.q.y) && isfinite(b.q.z);
  }
  return true;
}

// Runs `model` through pd_ref_run into directory `dir` (replaced if it is a run directory).
static bool run_to(const pdModel* model, pdRefVariant variant, const char* dir, pdRefRunStats* stats, pdError* err,
                   bool* finite) {
  pdRunWriter* writer = pd_run_open(dir, err);
  if (!writer) fail_msg("%s: %s", dir, err->message);
  pdRefOptions options = {.variant = variant, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
  *finite = true;
  return pd_ref_run(model, bullet(), &options, writer, all_finite, finite, stats, err);
}

// summary.json up to its timing object, the only part two identical runs may differ in
static size_t before_timing(const char* summary, size_t size) {
  const char* t = strstr(summary, "\"timing\"");
  return t ? (size_t)(t - summary) : size;
}

static void test_two_runs_write_the_same_bytes(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/examples/demo.scene");
  for (int v = pd_refNative; v <= pd_refMatched; ++v) {
    char* traj[2];
    char* summary[2];
    size_t trajSize[2], summarySize[2];
    for (int r = 0; r < 2; ++r) {
      char dir[64], path[96];
      snprintf(dir, sizeof dir, "bullet_determinism_%s_%d", variant_name((pdRefVariant)v), r);
      pdRefRunStats stats;
      pdError err;
      memset(&err, 0, sizeof err);
      bool finite;
      assert_true(run_to(m, (pdRefVariant)v, dir, &stats, &err, &finite));
      assert_true(stats.completed && finite);
      snprintf(path, sizeof path, "%s/trajectory.csv", dir);
      traj[r] = test_read_file(path, &trajSize[r]);
      snprintf(path, sizeof path, "%s/summary.json", dir);
      summary[r] = test_read_file(path, &summarySize[r]);
    }
    size_t s0 = before_timing(summary[0], summarySize[0]), s1 = before_timing(summary[1], summarySize[1]);
    print_message("%s: trajectory.csv %zu bytes, summary.json %zu bytes before timing\n", variant_name((pdRefVariant)v),
                  trajSize[0], s0);
    assert_true(trajSize[0] == trajSize[1] && memcmp(traj[0], traj[1], trajSize[0]) == 0);
    assert_true(s0 == s1 && memcmp(summary[0], summary[1], s0) == 0);
    for (int r = 0; r < 2; ++r) free(traj[r]), free(summary[r]);
  }
  pd_model_free(m);
}

static void run_every_scene_in(const char* folder) {
  char dirPath[512];
  snprintf(dirPath, sizeof dirPath, "%s/cases/%s", PD_SOURCE_DIR, folder);
  DIR* dir = opendir(dirPath);
  assert_non_null(dir);
  int scenes = 0;
  for (struct dirent* e; (e = readdir(dir));) {
    size_t n = strlen(e->d_name);
    if (n < 7 || strcmp(e->d_name + n - 6, ".scene") != 0) continue;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dirPath, e->d_name);
    pdModel* m = compile_file(path);
    for (int v = pd_refNative; v <= pd_refMatched; ++v) {
      pdRefRunStats stats;
      pdError err;
      memset(&err, 0, sizeof err);
      bool finite;
      bool ok = run_to(m, (pdRefVariant)v, "bullet_case", &stats, &err, &finite);
      print_message("%s/%s %s: %s, %ld steps, at most %ld contacts, %.3f s wall%s%s\n", folder, e->d_name,
                    variant_name((pdRefVariant)v),
                    stats.completed ? "completed" : (stats.refused ? "refused" : "FAILED"),
                    stats.steps, stats.maxContacts, stats.wallSeconds, stats.refused ? ": " : "",
                    stats.refused ? err.message : "");
      if (stats.refused) {
        assert_false(ok);
        assert_true(strlen(err.message) > 0);
      } else {
        assert_true(ok && stats.completed && finite);
      }
    }
    pd_model_free(m);
    ++scenes;
  }
  closedir(dir);
  assert_true(scenes > 0);
}

static void test_every_example_and_hard_case_runs_or_is_refused(void** state) {
  (void)state;
  run_every_scene_in("examples");
  run_every_scene_in("hard");
}

// Bullet turns a body by at most π/4 per step: a faster initial spin is refused at the body's line, and
// the driver writes nothing.
static void test_spin_too_fast_for_the_step_is_refused(void** state) {
  (void)state;
  pdModel* m = compile_text("gravity 0 0 0\n"
                            "cube box red 0.1 0.1 0.1\nvel 0 0 0  50000 0 0 1\n");  // 873 rad/s > (π/4)/1 ms
  pdError err;
  memset(&err, 0, sizeof err);
  pdRefOptions options = {.variant = pd_refNative, .step = 1e-3, .odeFriction = pd_odeFrictionPyramid};
  assert_null(bullet()->create(m, &options, &err));
  print_message("refused: %s:%d:%d: %s\n", err.file, err.line, err.col, err.message);
  assert_int_equal(err.line, 2);
  assert_non_null(strstr(err.message, "'box'"));
  pdRefRunStats stats;
  bool finite;
  memset(&err, 0, sizeof err);
  assert_false(run_to(m, pd_refNative, "bullet_refused", &stats, &err, &finite));
  assert_true(stats.refused);
  assert_null(opendir("bullet_refused"));
  options.step = 1e-4;  // 87 mrad per step: fine
  pdRefWorld* w = bullet()->create(m, &options, &err);
  assert_non_null(w);
  bullet()->destroy(w);
  pd_model_free(m);
}

// ---------------------------------------------------------------------------------------------
// applied force (scene `force`)

#include "applied_force_checks.h"

static void test_applied_force_gives_the_exact_impulse_and_torque(void** state) {
  (void)state;
  check_applied_force(bullet(), pd_refNative);
  check_applied_force(bullet(), pd_refMatched);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_applied_force_gives_the_exact_impulse_and_torque),
      cmocka_unit_test(test_initial_pose_is_the_scene_pose),
      cmocka_unit_test(test_free_body_keeps_its_angular_momentum),
      cmocka_unit_test(test_matched_cube_rests_at_the_spring_sinkage),
      cmocka_unit_test(test_sliding_cube_stops_at_the_coulomb_distance),
      cmocka_unit_test(test_native_flat_landing_bounces_with_the_pair_restitution),
      cmocka_unit_test(test_matched_single_contact_bounces_with_eq_15),
      cmocka_unit_test(test_two_runs_write_the_same_bytes),
      cmocka_unit_test(test_every_example_and_hard_case_runs_or_is_refused),
      cmocka_unit_test(test_spin_too_fast_for_the_step_is_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
