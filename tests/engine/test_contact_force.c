// The force law of one contact (paper §3.1): every damper branch of the normal and tangential directions
// against hand-derived values, the friction cone (stick/slip at the boundary, |F_t| = μ F_n in slip,
// λ from eq. (9), slip opposing the motion), eqs. (1), (2), (4) and (7) in every branch, a 1-D impact
// integrated with RK4 against the closed-form restitution (catalogue A1), spring realignment (§3.4,
// catalogue A4), and pd_contact_normal_force giving pd_contact_force's F_n bit for bit.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "test_random.h"

#include "contact_force.h"
#include "material.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

// Hand-derived values are sums of a few products of O(1) numbers: a few ulp each. 1e-12 relative to the
// terms' scale leaves a wide margin over roundoff while any wrong coefficient shows at 1e-2 or worse.
#define HAND_TOL_REL 1e-12
// Balance checks (eqs. (1), (2), (4), (7)) on random contacts: each side is a sum of terms up to ~1e3
// times the result; roundoff is ~1e-16 of the largest term, so 1e-11 of the term scale.
#define BALANCE_TOL_REL 1e-11
// Restitution of the 1-D impact against the closed form (the brief's and catalogue A1's gate is 0.002;
// RK4 with 2e4 steps per period and a linearly interpolated break are ~1e-8 accurate).
#define RESTITUTION_TOL 0.002
// An elastic (undamped) impact returns all energy: RK4 energy drift at ω h = 3e-4 is ~1e-14, the
// interpolated break ~1e-10.
#define ELASTIC_TOL 1e-6
// Realignment keeps |s| and puts s in the new plane: a rotation, a projection and a rescale cost a few ulp.
#define REALIGN_TOL_REL 1e-15
// Comparing the realigned spring with an independently built rotation (quaternion): ~10 roundings.
#define ROTATION_TOL_REL 1e-14

static void expect_near(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol))
    fail_msg("%s: %.17g, expected %.17g (error %.3g > %.3g)", what, actual, expected, fabs(actual - expected), tol);
}

static void expect_vec(pdVec3 a, pdVec3 e, double tol, const char* what) {
  char buf[96];
  snprintf(buf, sizeof buf, "%s.x", what);
  expect_near(a.x, e.x, tol, buf);
  snprintf(buf, sizeof buf, "%s.y", what);
  expect_near(a.y, e.y, tol, buf);
  snprintf(buf, sizeof buf, "%s.z", what);
  expect_near(a.z, e.z, tol, buf);
}

#define PI 3.14159265358979323846

static const pdVec3 ZN = {0, 0, 1};

// ---------------------------------------------------------------- normal direction, by hand
//
// Common data: k1n = 1000, k2n = 3000 N/m; s1n = −0.001, s2n = 0.0004 m (not balanced, so the dampers
// matter); Δu_n = −0.5 m/s (approach). k1 s1 + k2 s2 = −1 + 1.2 = 0.2 N.

static pdContactParams normal_params(double c1, double c2) {
  return (pdContactParams){.k1n = 1000, .k2n = 3000, .c1n = c1, .c2n = c2, .mu = 0.0};
}

static void test_normal_both_damped_matches_eqs_5_6(void** state) {
  (void)state;
  // c1 = 2, c2 = 6, C = 8: ṡ1 = (c2 Δu − 0.2)/C = (−3 − 0.2)/8 = −0.4; ṡ2 = (−c1 Δu − 0.2)/C = (1 − 0.2)/8 = 0.1;
  // b_n = (c2 k1 s1 − c1 k2 s2 + c1 c2 Δu)/C = (−6 − 2.4 − 6)/8 = −1.8, F_n = 1.8.
  pdContactParams p = normal_params(2, 6);
  pdSprings s = {.s1n = -0.001, .s2n = 0.0004};
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0, 0, -0.5), &f);
  expect_near(f.fn, 1.8, HAND_TOL_REL * 6, "F_n");
  expect_near(f.rate.s1n, -0.4, HAND_TOL_REL, "ṡ1n");
  expect_near(f.rate.s2n, 0.1, HAND_TOL_REL, "ṡ2n");
  expect_vec(f.force, pd_v3(0, 0, 1.8), HAND_TOL_REL * 6, "F_c");
  assert_false(pd_contact_force_pulls(&f));
}

static void test_normal_undamped_springs_in_series(void** state) {
  (void)state;
  // §3.1.5, balanced springs −k1 s1 = k2 s2 = 3 N (s1 = −0.003, s2 = 0.001), Δu = −0.4:
  // ṡ1 = k2/(k1+k2) Δu = 0.75 (−0.4) = −0.3, ṡ2 = −k1/(k1+k2) Δu = 0.1, F_n = 3.
  pdContactParams p = normal_params(0, 0);
  pdSprings s = {.s1n = -0.003, .s2n = 0.001};
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0, 0, -0.4), &f);
  expect_near(f.fn, 3.0, HAND_TOL_REL * 3, "F_n");
  expect_near(f.rate.s1n, -0.3, HAND_TOL_REL, "ṡ1n");
  expect_near(f.rate.s2n, 0.1, HAND_TOL_REL, "ṡ2n");
}

static void test_normal_mixed_c1_zero(void** state) {
  (void)state;
  // c1n = 0 < c2n = 6: F_n = −k1 s1 = 1; ṡ2 = −(k1 s1 + k2 s2)/c2 = −0.2/6 = −1/30; ṡ1 = Δu + ṡ2 = −0.5 − 1/30.
  // Check of (1): k2 s2 + c2 ṡ2 = 1.2 − 0.2 = 1.
  pdContactParams p = normal_params(0, 6);
  pdSprings s = {.s1n = -0.001, .s2n = 0.0004};
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0, 0, -0.5), &f);
  expect_near(f.fn, 1.0, HAND_TOL_REL * 3, "F_n");
  expect_near(f.rate.s2n, -1.0 / 30.0, HAND_TOL_REL, "ṡ2n");
  expect_near(f.rate.s1n, -0.5 - 1.0 / 30.0, HAND_TOL_REL, "ṡ1n");
}

static void test_normal_mixed_c2_zero(void** state) {
  (void)state;
  // c2n = 0 < c1n = 2: F_n = k2 s2 = 1.2; ṡ1 = −(k1 s1 + k2 s2)/c1 = −0.1; ṡ2 = ṡ1 − Δu = 0.4.
  // Check of (1): −k1 s1 − c1 ṡ1 = 1 + 0.2 = 1.2.
  pdContactParams p = normal_params(2, 0);
  pdSprings s = {.s1n = -0.001, .s2n = 0.0004};
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0, 0, -0.5), &f);
  expect_near(f.fn, 1.2, HAND_TOL_REL * 3, "F_n");
  expect_near(f.rate.s1n, -0.1, HAND_TOL_REL, "ṡ1n");
  expect_near(f.rate.s2n, 0.4, HAND_TOL_REL, "ṡ2n");
}

static void test_normal_tension_pulls_and_carries_no_friction(void** state) {
  (void)state;
  // s1n > 0 is tension of spring 1: F_n = −k1 s1 = −1 < 0 (undamped): the dynamics-side break. With no
  // normal push there is no friction even with μ > 0 and a loaded tangential spring.
  pdContactParams p = {.k1n = 1000, .k2n = 1000, .k1t = 1000, .k2t = 1000, .mu = 0.5};
  pdSprings s = {.s1n = 0.001, .s2n = -0.001, .s1t = {0.001, 0, 0}, .s2t = {-0.001, 0, 0}};
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.1, 0, 0.1), &f);
  assert_true(f.fn < 0.0);
  assert_true(pd_contact_force_pulls(&f));
  expect_vec(f.ft, pd_v3(0, 0, 0), 0.0, "F_t");
  // the undamped carrier cannot load without a normal push: its rate is all slip
  expect_vec(f.rate.s1t, pd_v3(0, 0, 0), 0.0, "ṡ1t");
  expect_vec(f.rate.s2t, pd_v3(0, 0, 0), 0.0, "ṡ2t");
}

// ---------------------------------------------------------------- tangential direction, by hand
//
// Normal part for all tangential cases: undamped, k1n = k2n = 1024, s1n = −2/1024, s2n = 2/1024, so
// F_n = 2 N exactly (powers of two), and μ sets the friction limit F⁺ = 2μ exactly for μ = 0.5 (1 N).

static pdContactParams tangential_params(double k1t, double k2t, double c1t, double c2t, double mu) {
  return (pdContactParams){.k1n = 1024, .k2n = 1024, .k1t = k1t, .k2t = k2t, .c1t = c1t, .c2t = c2t, .mu = mu};
}

static pdSprings springs_t(pdVec3 s1t, pdVec3 s2t) {
  return (pdSprings){.s1n = -2.0 / 1024.0, .s2n = 2.0 / 1024.0, .s1t = s1t, .s2t = s2t};
}

static void test_tangential_damped_stick_matches_eqs_5_6(void** state) {
  (void)state;
  // k1t = 1000, k2t = 3000, c1t = 2, c2t = 6 (C = 8); s1t = (0.001, 0, 0), s2t = (0, −0.0002, 0);
  // Δu = (0.2, 0.1, −0.5) → Δu_t = (0.2, 0.1, 0).
  // b_t = (c2 k1 s1 − c1 k2 s2 + c1 c2 Δu_t)/C = ((6,0) + (0,1.2) + (2.4,1.2))/8 = (1.05, 0.3);
  // |b_t| = 1.092 < μ F_n = 20: stick, F_t = −b_t = (−1.05, −0.3).
  // k1 s1 + k2 s2 = (1, −0.6): ṡ1 = (c2 Δu_t − (1, −0.6))/8 = (0.025, 0.15),
  // ṡ2 = (−c1 Δu_t − (1, −0.6))/8 = (−0.175, 0.05).
  pdContactParams p = tangential_params(1000, 3000, 2, 6, 10);
  pdSprings s = springs_t(pd_v3(0.001, 0, 0), pd_v3(0, -0.0002, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.2, 0.1, -0.5), &f);
  assert_false(f.slip);
  assert_true(f.lambda == 0.0);
  expect_vec(f.ft, pd_v3(-1.05, -0.3, 0), HAND_TOL_REL * 6, "F_t");
  expect_vec(f.rate.s1t, pd_v3(0.025, 0.15, 0), HAND_TOL_REL, "ṡ1t");
  expect_vec(f.rate.s2t, pd_v3(-0.175, 0.05, 0), HAND_TOL_REL, "ṡ2t");
  expect_vec(f.dw, pd_v3(0, 0, 0), 0.0, "Δw_t");
}

static void test_tangential_damped_slip_lambda_from_eq_9(void** state) {
  (void)state;
  // Same springs and Δu with μ = 0.45: F⁺ = 0.9 < |b_t| = √1.1925: slip. c* = c1 c2/(c1+c2) = 1.5.
  // λ = (|b_t| − F⁺)/(c* F⁺) (9); F_t = −b_t/(1 + λ c*) (10), |F_t| = F⁺; Δw_t = λ b_t/(1 + λ c*) = −λ F_t.
  pdContactParams p = tangential_params(1000, 3000, 2, 6, 0.45);
  pdSprings s = springs_t(pd_v3(0.001, 0, 0), pd_v3(0, -0.0002, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.2, 0.1, -0.5), &f);
  const pdVec3 bt = {1.05, 0.3, 0};
  const double bn = sqrt(1.1925), limit = 0.9, cstar = 1.5;
  const double lambda = (bn - limit) / (cstar * limit);
  assert_true(f.slip);
  expect_near(f.lambda, lambda, HAND_TOL_REL, "λ");
  expect_vec(f.ft, pd_v3_scale(bt, -1.0 / (1.0 + lambda * cstar)), HAND_TOL_REL, "F_t (10)");
  expect_near(pd_v3_norm(f.ft), limit, HAND_TOL_REL, "|F_t| = μ F_n");
  expect_vec(f.dw, pd_v3_scale(bt, lambda / (1.0 + lambda * cstar)), HAND_TOL_REL, "Δw_t (10)");
  expect_vec(f.dw, pd_v3_scale(f.ft, -f.lambda), HAND_TOL_REL, "Δw_t = −λ F_t (7)");
  // rates with Δu_t − Δw_t in place of Δu_t: ṡ1 − ṡ2 = Δu_t − Δw_t (4)
  expect_vec(pd_v3_sub(f.rate.s1t, f.rate.s2t), pd_v3_sub(pd_v3(0.2, 0.1, 0), f.dw), HAND_TOL_REL, "(4)");
}

static void test_tangential_damped_stick_slip_boundary(void** state) {
  (void)state;
  // k1t = k2t = 1000, c1t = c2t = 2 (c* = 1), springs at rest, Δu_t = (1, 0, 0): b_t = c1 c2/(c1+c2) Δu_t = (1, 0, 0),
  // |b_t| = 1 = F⁺ exactly at μ = 0.5: stick (|b_t| <= μ|b_n|). One ulp less μ: slip with a tiny λ.
  pdContactParams p = tangential_params(1000, 1000, 2, 2, 0.5);
  pdSprings s = springs_t(pd_v3(0, 0, 0), pd_v3(0, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(1, 0, 0), &f);
  assert_false(f.slip);
  assert_true(f.lambda == 0.0);
  expect_vec(f.ft, pd_v3(-1, 0, 0), 0.0, "F_t at the boundary");
  p.mu = nextafter(0.5, 0.0);
  pd_contact_force(&p, &s, ZN, pd_v3(1, 0, 0), &f);
  assert_true(f.slip);
  assert_true(f.lambda > 0.0 && f.lambda < 1e-15);
  expect_near(pd_v3_norm(f.ft), 2.0 * p.mu, 0.0, "|F_t| = μ F_n just past the boundary");
}

static void test_tangential_damped_slip_opposes_motion(void** state) {
  (void)state;
  // Springs at rest, fast sliding along an arbitrary tangential direction: F_t = −F⁺ Δû_t exactly in
  // direction and on the cone, whatever the normal's orientation.
  pdVec3 n = pd_v3_normalize(pd_v3(0.3, -0.4, 0.866));
  pdVec3 dut = pd_v3_cross(n, pd_v3(0.2, 0.7, -0.1));  // ⊥ n
  pdContactParams p = tangential_params(1000, 1000, 5, 7, 0.3);
  pdSprings s = springs_t(pd_v3(0, 0, 0), pd_v3(0, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, n, pd_v3_muladd(dut, -0.1, n), &f);
  assert_true(f.slip);
  expect_vec(f.ft, pd_v3_scale(pd_v3_normalize(dut), -0.6), HAND_TOL_REL, "F_t = −μ F_n Δû_t");
}

static void test_tangential_undamped_stick(void** state) {
  (void)state;
  // §3.1.5, k1t = k2t = 1024, balanced s1t = (−1/1024, 0, 0), s2t = (1/1024, 0, 0): F_t = −k1 s1 = (1, 0, 0);
  // μ = 10: stick. ṡ1 = k2/(k1+k2) Δu_t = 0.5 (−0.3, 0.2) = (−0.15, 0.1), ṡ2 = −0.5 Δu_t = (0.15, −0.1).
  pdContactParams p = tangential_params(1024, 1024, 0, 0, 10);
  pdSprings s = springs_t(pd_v3(-1.0 / 1024, 0, 0), pd_v3(1.0 / 1024, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(-0.3, 0.2, 0), &f);
  assert_false(f.slip);
  expect_vec(f.ft, pd_v3(1, 0, 0), 0.0, "F_t");
  expect_vec(f.rate.s1t, pd_v3(-0.15, 0.1, 0), HAND_TOL_REL, "ṡ1t");
  expect_vec(f.rate.s2t, pd_v3(0.15, -0.1, 0), HAND_TOL_REL, "ṡ2t");
}

static void test_tangential_undamped_slip_on_the_cone(void** state) {
  (void)state;
  // Same springs, μ = 0.5: |F_t| = 1 = F⁺, on the cone. Δu_t = (−0.3, 0.2): ŝ1 = (−1, 0, 0), ŝ1 · Δu_t = 0.3 > 0:
  // the springs would lengthen → slip. Δw_t = (ŝ1 · Δu_t) ŝ1 = (−0.3, 0, 0), λ = 0.3/F⁺ = 0.3, F_t stays
  // (1, 0, 0) (= −Δŵ_t: friction opposes the slip), ṡ1 = 0.5 (Δu_t − Δw_t) = (0, 0.1), ṡ2 = (0, −0.1): the
  // springs only turn.
  pdContactParams p = tangential_params(1024, 1024, 0, 0, 0.5);
  pdSprings s = springs_t(pd_v3(-1.0 / 1024, 0, 0), pd_v3(1.0 / 1024, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(-0.3, 0.2, 0), &f);
  assert_true(f.slip);
  expect_near(f.lambda, 0.3, HAND_TOL_REL, "λ");
  expect_vec(f.ft, pd_v3(1, 0, 0), 0.0, "F_t");
  expect_near(pd_v3_norm(f.ft), 0.5 * f.fn, 0.0, "|F_t| = μ F_n");
  expect_vec(f.dw, pd_v3(-0.3, 0, 0), HAND_TOL_REL, "Δw_t");
  expect_vec(f.rate.s1t, pd_v3(0, 0.1, 0), HAND_TOL_REL, "ṡ1t");
  expect_vec(f.rate.s2t, pd_v3(0, -0.1, 0), HAND_TOL_REL, "ṡ2t");
  // unloading from the cone (Δu_t = (+0.3, 0)) is stick: the springs shorten freely
  pd_contact_force(&p, &s, ZN, pd_v3(0.3, 0, 0), &f);
  assert_false(f.slip);
  expect_vec(f.rate.s1t, pd_v3(0.15, 0, 0), HAND_TOL_REL, "ṡ1t unloading");
  // beyond the cone (μ = 0.45, F⁺ = 0.9): the force is clipped to the cone
  p.mu = 0.45;
  pd_contact_force(&p, &s, ZN, pd_v3(-0.3, 0.2, 0), &f);
  assert_true(f.slip);
  expect_vec(f.ft, pd_v3(0.9, 0, 0), HAND_TOL_REL, "F_t clipped");
}

static void test_tangential_mixed_c1_zero(void** state) {
  (void)state;
  // §3.1.6, c1t = 0 < c2t = 6: k1t = 1024, k2t = 3000, s1t = (−1/1024, 0, 0) (F_t = −k1 s1 = (1, 0, 0)),
  // s2t = (0.0002, 0, 0) (k2 s2 = 0.6). ṡ2 = −(k1 s1 + k2 s2)/c2 = −(−1 + 0.6)/6 = (1/15, 0, 0).
  // Stick (μ = 10), Δu_t = (0.1, 0.2): ṡ1 = ṡ2 + Δu_t = (1/6, 0.2). Eq. (2): k2 s2 + c2 ṡ2 = 0.6 + 0.4 = 1.
  pdContactParams p = tangential_params(1024, 3000, 0, 6, 10);
  pdSprings s = springs_t(pd_v3(-1.0 / 1024, 0, 0), pd_v3(0.0002, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.1, 0.2, 0), &f);
  assert_false(f.slip);
  expect_vec(f.ft, pd_v3(1, 0, 0), 0.0, "F_t stick");
  expect_vec(f.rate.s2t, pd_v3(1.0 / 15, 0, 0), HAND_TOL_REL, "ṡ2t stick");
  expect_vec(f.rate.s1t, pd_v3(1.0 / 6, 0.2, 0), HAND_TOL_REL, "ṡ1t stick");
  // Slip on the cone (μ = 0.5, F⁺ = 1), Δu_t = (−0.3, 0.2): ṡ1,stick = (1/15 − 0.3, 0.2) = (−7/30, 0.2);
  // ŝ1 · ṡ1,stick = 7/30 > 0 (lengthening) → Δw_t = (ŝ1 · ṡ1,stick) ŝ1 = (−7/30, 0, 0), λ = (7/30)/F⁺,
  // ṡ1 = (0, 0.2), ṡ2 unchanged (1/15, 0).
  p.mu = 0.5;
  pd_contact_force(&p, &s, ZN, pd_v3(-0.3, 0.2, 0), &f);
  assert_true(f.slip);
  expect_near(f.lambda, 7.0 / 30.0, HAND_TOL_REL, "λ");
  expect_vec(f.dw, pd_v3(-7.0 / 30.0, 0, 0), HAND_TOL_REL, "Δw_t");
  expect_vec(f.rate.s1t, pd_v3(0, 0.2, 0), HAND_TOL_REL, "ṡ1t slip");
  expect_vec(f.rate.s2t, pd_v3(1.0 / 15, 0, 0), HAND_TOL_REL, "ṡ2t slip");
  expect_near(pd_v3_norm(f.ft), 0.5 * f.fn, 0.0, "|F_t| = μ F_n");
}

static void test_tangential_mixed_c2_zero(void** state) {
  (void)state;
  // Mirror case c2t = 0 < c1t = 6: k1t = 3000, k2t = 1024, s2t = (1/1024, 0, 0) (F_t = k2 s2 = (1, 0, 0)),
  // s1t = (−0.0002, 0, 0) (k1 s1 = −0.6). ṡ1 = −(k1 s1 + k2 s2)/c1 = (−1/15, 0, 0); ṡ2 = ṡ1 − Δu_t + Δw_t.
  // Stick (μ = 10), Δu_t = (0.1, 0.2): ṡ2 = (−1/15 − 0.1, −0.2) = (−1/6, −0.2). Eq. (2): −k1 s1 − c1 ṡ1 = 0.6 + 0.4.
  pdContactParams p = tangential_params(3000, 1024, 6, 0, 10);
  pdSprings s = springs_t(pd_v3(-0.0002, 0, 0), pd_v3(1.0 / 1024, 0, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.1, 0.2, 0), &f);
  assert_false(f.slip);
  expect_vec(f.ft, pd_v3(1, 0, 0), 0.0, "F_t stick");
  expect_vec(f.rate.s1t, pd_v3(-1.0 / 15, 0, 0), HAND_TOL_REL, "ṡ1t stick");
  expect_vec(f.rate.s2t, pd_v3(-1.0 / 6, -0.2, 0), HAND_TOL_REL, "ṡ2t stick");
  // Slip (μ = 0.5), Δu_t = (−0.3, 0.2): ṡ2,stick = (−1/15 + 0.3, −0.2) = (7/30, −0.2); ŝ2 = (1, 0, 0) lengthens
  // at 7/30 → Δw_t = −(7/30, 0, 0) = −λ F_t with λ = 7/30; ṡ2 = (0, −0.2), ṡ1 unchanged.
  p.mu = 0.5;
  pd_contact_force(&p, &s, ZN, pd_v3(-0.3, 0.2, 0), &f);
  assert_true(f.slip);
  expect_near(f.lambda, 7.0 / 30.0, HAND_TOL_REL, "λ");
  expect_vec(f.dw, pd_v3(-7.0 / 30.0, 0, 0), HAND_TOL_REL, "Δw_t");
  expect_vec(f.rate.s2t, pd_v3(0, -0.2, 0), HAND_TOL_REL, "ṡ2t slip");
  expect_vec(f.rate.s1t, pd_v3(-1.0 / 15, 0, 0), HAND_TOL_REL, "ṡ1t slip");
}

static void test_frictionless_contact_has_no_tangential_output(void** state) {
  (void)state;
  pdContactParams p = tangential_params(1000, 3000, 2, 6, 0.0);
  pdSprings s = springs_t(pd_v3(0.001, 0, 0), pd_v3(0, -0.0002, 0));
  pdContactForce f;
  pd_contact_force(&p, &s, ZN, pd_v3(0.2, 0.1, -0.5), &f);
  expect_near(f.fn, 2.0, 0.0, "F_n");
  expect_vec(f.ft, pd_v3(0, 0, 0), 0.0, "F_t");
  expect_vec(f.rate.s1t, pd_v3(0, 0, 0), 0.0, "ṡ1t");
  expect_vec(f.rate.s2t, pd_v3(0, 0, 0), 0.0, "ṡ2t");
  expect_vec(f.force, pd_v3(0, 0, 2.0), 0.0, "F_c");
  assert_false(f.slip);
}

// ---------------------------------------------------------------- balance in every branch (random)

static double pick_damper(lcg* g, int zero) { return zero ? 0.0 : lcg_range(g, 0.5, 20.0); }

static pdVec3 random_unit(lcg* g) {
  for (;;) {
    pdVec3 v = {lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1)};
    double r = pd_v3_norm(v);
    if (r > 0.1 && r <= 1.0) return pd_v3_scale(v, 1.0 / r);
  }
}

static pdVec3 random_in_plane(lcg* g, pdVec3 n, double scale) {
  pdVec3 v = pd_v3_scale(random_unit(g), scale);
  return pd_v3_muladd(v, -pd_v3_dot(v, n), n);
}

// For 16 damper configurations × many random states: eq. (1) both sides equal F_n; eq. (4) along n; the
// friction law (7): |F_t| <= μ F_n⁺, Δw_t = −λ F_t, λ >= 0; eq. (4) in P_t with Δw_t; rates in P_t; and
// eq. (2) both sides equal F_t whenever the force is not clipped (damper-determined branch: always;
// spring-determined branches: on or inside the cone).
static void test_balance_equations_hold_in_every_branch(void** state) {
  (void)state;
  lcg g = {20240611};
  for (int config = 0; config < 16; ++config) {
    for (int trial = 0; trial < 200; ++trial) {
      pdContactParams p = {.k1n = lcg_range(&g, 1e2, 1e4), .k2n = lcg_range(&g, 1e2, 1e4),
                           .k1t = lcg_range(&g, 1e2, 1e4), .k2t = lcg_range(&g, 1e2, 1e4),
                           .c1n = pick_damper(&g, config & 1), .c2n = pick_damper(&g, config & 2),
                           .c1t = pick_damper(&g, config & 4), .c2t = pick_damper(&g, config & 8),
                           .mu = lcg_range(&g, 0.05, 1.0)};
      pdVec3 n = random_unit(&g);
      pdSprings s;
      s.s1n = -lcg_range(&g, 0, 1e-3);
      s.s2n = (p.c1n == 0 && p.c2n == 0) ? -p.k1n * s.s1n / p.k2n : lcg_range(&g, 0, 1e-3);
      s.s1t = random_in_plane(&g, n, 1e-3);
      s.s2t = (p.c1t == 0 && p.c2t == 0) ? pd_v3_scale(s.s1t, -p.k1t / p.k2t) : random_in_plane(&g, n, 1e-3);
      pdVec3 du = pd_v3_scale(random_unit(&g), lcg_range(&g, 0, 2));
      pdContactForce f;
      pd_contact_force(&p, &s, n, du, &f);

      double scale = p.k1n * 1e-3 + p.k2n * 1e-3 + 20 * 2 + 20 * 2;  // size of the terms of (1), N
      expect_near(-p.k1n * s.s1n - p.c1n * f.rate.s1n, f.fn, BALANCE_TOL_REL * scale, "(1) left");
      expect_near(p.k2n * s.s2n + p.c2n * f.rate.s2n, f.fn, BALANCE_TOL_REL * scale, "(1) right");
      expect_near(f.rate.s1n - f.rate.s2n, pd_v3_dot(du, n), BALANCE_TOL_REL * 4, "(4) along n");

      double limit = p.mu * fmax(f.fn, 0.0);
      double tscale = p.k1t * 1e-3 + p.k2t * 1e-3 + 20 * 4;
      assert_true(pd_v3_norm(f.ft) <= limit * (1 + BALANCE_TOL_REL) + BALANCE_TOL_REL * tscale);
      assert_true(f.lambda >= 0.0);
      expect_near(fabs(pd_v3_dot(f.ft, n)), 0.0, BALANCE_TOL_REL * tscale, "F_t in P_t");
      expect_near(fabs(pd_v3_dot(f.rate.s1t, n)), 0.0, BALANCE_TOL_REL * 4, "ṡ1t in P_t");
      expect_near(fabs(pd_v3_dot(f.rate.s2t, n)), 0.0, BALANCE_TOL_REL * 4, "ṡ2t in P_t");
      if (isfinite(f.lambda))
        expect_vec(f.dw, pd_v3_scale(f.ft, -f.lambda), BALANCE_TOL_REL * 4, "Δw_t = −λ F_t");
      pdVec3 dut = pd_v3_muladd(du, -pd_v3_dot(du, n), n);
      expect_vec(pd_v3_sub(f.rate.s1t, f.rate.s2t), pd_v3_sub(dut, f.dw), BALANCE_TOL_REL * 4, "(4) in P_t");

      bool damperDetermined = p.c1t > 0 && p.c2t > 0;
      pdVec3 fs = p.c1t == 0 ? pd_v3_scale(s.s1t, -p.k1t) : pd_v3_scale(s.s2t, p.k2t);
      if (damperDetermined || pd_v3_norm(fs) <= limit) {
        pdVec3 left = pd_v3_sub(pd_v3_scale(s.s1t, -p.k1t), pd_v3_scale(f.rate.s1t, p.c1t));
        pdVec3 right = pd_v3_add(pd_v3_scale(s.s2t, p.k2t), pd_v3_scale(f.rate.s2t, p.c2t));
        expect_vec(left, f.ft, BALANCE_TOL_REL * tscale, "(2) left");
        expect_vec(right, f.ft, BALANCE_TOL_REL * tscale, "(2) right");
      }
      if (f.slip && limit > 0) expect_near(pd_v3_norm(f.ft), limit, BALANCE_TOL_REL * tscale, "|F_t| in slip");
    }
  }
}

// ---------------------------------------------------------------- 1-D impact (catalogue A1)

// A point mass m moving along n = z with speed v_b onto the contact mechanism (body 2 fixed), gravity
// off. State y = [x, v, s1n, s2n]; ẋ = v, v̇ = F_n/m, ṡ from pd_contact_force with Δu = v n. Classical RK4
// with a fixed step; the contact breaks when F_n becomes negative: the rebound speed is interpolated
// linearly in F_n between the last two steps. Returns e = v_after/v_b.
static void impact_rhs(const pdContactParams* p, double m, const double y[4], double dy[4]) {
  pdSprings s = {.s1n = y[2], .s2n = y[3]};
  pdContactForce f;
  pd_contact_force(p, &s, ZN, pd_v3(0, 0, y[1]), &f);
  dy[0] = y[1];
  dy[1] = f.fn / m;
  dy[2] = f.rate.s1n;
  dy[3] = f.rate.s2n;
}

static double normal_force_of(const pdContactParams* p, const double y[4]) {
  pdSprings s = {.s1n = y[2], .s2n = y[3]};
  pdContactForce f;
  pd_contact_force(p, &s, ZN, pd_v3(0, 0, y[1]), &f);
  return f.fn;
}

static double simulate_restitution(const pdContactParams* p, double m, double vb) {
  // the system stiffness seen by the mass is at least the series value; the step resolves its period
  double kSeries = p->k1n * p->k2n / (p->k1n + p->k2n);
  double h = 2.0 * PI * sqrt(m / kSeries) / 20000.0;
  double y[4] = {0, -vb, 0, 0};
  double fPrev = normal_force_of(p, y);
  for (int step = 0; step < 1000000; ++step) {
    double k1[4], k2[4], k3[4], k4[4], t[4], yn[4];
    impact_rhs(p, m, y, k1);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + 0.5 * h * k1[i];
    impact_rhs(p, m, t, k2);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + 0.5 * h * k2[i];
    impact_rhs(p, m, t, k3);
    for (int i = 0; i < 4; ++i) t[i] = y[i] + h * k3[i];
    impact_rhs(p, m, t, k4);
    for (int i = 0; i < 4; ++i) yn[i] = y[i] + h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    double f = normal_force_of(p, yn);
    if (f < 0.0 && step > 0) {
      double a = fPrev / (fPrev - f);
      return (y[1] + a * (yn[1] - y[1])) / vb;
    }
    memcpy(y, yn, sizeof y);
    fPrev = f;
  }
  fail_msg("the contact never broke");
  return 0.0;
}

// Catalogue A1's closed form, written here independently of material.c.
static double restitution_formula(double zeta) {
  return zeta == 0.0 ? 1.0 : exp(-2.0 * zeta * acos(zeta) / sqrt(1.0 - zeta * zeta));
}

static void test_impact_restitution_matches_closed_form(void** state) {
  (void)state;
  // Two identical bodies: per body k and c; in series the mass sees k/2 and c/2, so
  // ζ = (c/2)/(2√((k/2) m)) ⇒ c = 4ζ√(k m/2).
  const double m = 2.0, k = 1e5, vb = 1.5;
  const double zetas[] = {0.1, 0.3, 0.7};
  for (int i = 0; i < 3; ++i) {
    double c = 4.0 * zetas[i] * sqrt(k * m / 2.0);
    pdContactParams p = {.k1n = k, .k2n = k, .c1n = c, .c2n = c};
    double e = simulate_restitution(&p, m, vb);
    print_message("ζ = %.1f: e measured %.9f, formula %.9f (difference %.1e)\n", zetas[i], e,
                  restitution_formula(zetas[i]), e - restitution_formula(zetas[i]));
    expect_near(e, restitution_formula(zetas[i]), RESTITUTION_TOL, "restitution");
  }
}

static void test_impact_without_damping_is_elastic(void** state) {
  (void)state;
  pdContactParams p = {.k1n = 1e5, .k2n = 3e5};
  double e = simulate_restitution(&p, 2.0, 1.5);
  print_message("undamped: e measured %.15f (difference %.1e)\n", e, e - 1.0);
  expect_near(e, 1.0, ELASTIC_TOL, "restitution");
}

static void test_impact_with_material_damper_reproduces_requested_restitution(void** state) {
  (void)state;
  // The material module's pair constants for a requested e (the Fig. 5 experiment), between a 2 kg body and a
  // fixed floor 10× its size: one Kelvin–Voigt element at the pair's mass whatever the two sides' k.
  // The last case asks for different e on the two sides: the pair's e is √(e₁e₂).
  const double e1[] = {0.3, 0.5, 0.8, 0.3}, e2[] = {0.3, 0.5, 0.8, 0.8};
  const pdMaterialSettings set = {.vmax = 2.0, .deflection = 0.01, .dtmin = 1e-12};
  const pdMaterialBody body = {.index = 0, .mass = 2.0, .mMin = 2.0, .size = 0.5};
  const pdMaterialBody floor = {.index = 1, .fixed = true, .mass = 1.0, .mMin = 1.0, .size = 5.0};
  for (int i = 0; i < 4; ++i) {
    pdMaterialRequest r1 = {.mu = 0.5, .restitution = e1[i], .setMask = PD_SET_RESTITUTION};
    pdMaterialRequest r2 = {.mu = 0.5, .restitution = e2[i], .setMask = PD_SET_RESTITUTION};
    pdMaterialSide s1, s2;
    char why[256] = "";
    if (!pd_material_side(&body, &r1, &s1, why, sizeof why) || !pd_material_side(&floor, &r2, &s2, why, sizeof why))
      fail_msg("pd_material_side: %s", why);
    double e, zeta;
    assert_true(pd_pair_damping_ratio(&s1, &s2, &e, &zeta));
    pdContactParams p;
    pd_contact_params_pair(&s1, &s2, zeta, &set, 0, 1, &p, NULL);
    double measured = simulate_restitution(&p, body.mass, set.vmax);
    print_message("e = √(%.1f · %.1f) = %.6f: measured %.9f (ζ = %.6f, k_n = %.6g + %.6g N/m)\n", e1[i], e2[i], e,
                  measured, zeta, p.k1n, p.k2n);
    expect_near(measured, sqrt(e1[i] * e2[i]), RESTITUTION_TOL, "restitution");
  }
}

// ---------------------------------------------------------------- realignment (§3.4, catalogue A4)

static void test_realign_keeps_length_and_moves_springs_into_new_plane(void** state) {
  (void)state;
  // n tilts by 10° about (1, 1, 0)/√2: the springs turn with it (the same rotation) and keep their length.
  pdVec3 axis = pd_v3_normalize(pd_v3(1, 1, 0));
  pdQuat q = pd_quat_from_axis_angle(axis, 10.0 * PI / 180.0);
  pdVec3 nOld = ZN, nNew = pd_quat_rotate(q, nOld);
  pdSprings s = {.s1n = -1e-3, .s2n = 1e-3, .s1t = {3e-4, -1e-4, 0}, .s2t = {-2e-4, 5e-4, 0}};
  pdSprings before = s;
  pdContactParams p = {.k1t = 1000, .k2t = 1000, .mu = 0.5};
  pd_springs_realign(&s, nOld, nNew, 0.5, &p, 10.0);  // cone 5 N: no clipping
  const pdVec3* after[2] = {&s.s1t, &s.s2t};
  const pdVec3* orig[2] = {&before.s1t, &before.s2t};
  for (int i = 0; i < 2; ++i) {
    double len = pd_v3_norm(*orig[i]);
    expect_near(pd_v3_norm(*after[i]), len, REALIGN_TOL_REL * len, "|s_t| kept");
    expect_near(pd_v3_dot(*after[i], nNew), 0.0, REALIGN_TOL_REL * len, "s_t · n_new");
    expect_vec(*after[i], pd_quat_rotate(q, *orig[i]), ROTATION_TOL_REL * len, "s_t turned with n");
  }
  assert_true(s.s1n == before.s1n && s.s2n == before.s2n);
}

static void test_realign_with_unchanged_normal_changes_nothing(void** state) {
  (void)state;
  pdSprings s = {.s1n = -1e-3, .s2n = 1e-3, .s1t = {3e-4, -1e-4, 0}, .s2t = {-2e-4, 5e-4, 0}};
  pdSprings before = s;
  pdContactParams p = {.k1t = 1000, .k2t = 1000, .mu = 0.5};
  pd_springs_realign(&s, ZN, ZN, 0.5, &p, 10.0);
  assert_memory_equal(&s, &before, sizeof s);
}

static void test_realign_clips_to_cone_and_clamps_tension(void** state) {
  (void)state;
  // k1t = 1000, |s1t| = 3e-3 → 3 N > μ F_n = 0.5 · 2 = 1 N: shortened to 1e-3 along itself.
  // k2t = 1000, |s2t| = 5e-4 → 0.5 N: inside the cone, unchanged. Tension (s1n > 0, s2n < 0) is clamped to 0.
  pdSprings s = {.s1n = 1e-4, .s2n = -1e-4, .s1t = {3e-3, 0, 0}, .s2t = {0, 5e-4, 0}};
  pdContactParams p = {.k1t = 1000, .k2t = 1000, .mu = 0.5};
  pd_springs_realign(&s, ZN, ZN, 0.5, &p, 2.0);
  expect_vec(s.s1t, pd_v3(1e-3, 0, 0), 1e-18, "s1t clipped");
  expect_vec(s.s2t, pd_v3(0, 5e-4, 0), 0.0, "s2t kept");
  assert_true(s.s1n == 0.0 && s.s2n == 0.0);
  // no normal push: no tangential spring survives
  pd_springs_realign(&s, ZN, ZN, 0.5, &p, -1.0);
  expect_vec(s.s1t, pd_v3(0, 0, 0), 0.0, "s1t without push");
  expect_vec(s.s2t, pd_v3(0, 0, 0), 0.0, "s2t without push");
}

static void test_realign_survives_a_flipped_normal(void** state) {
  (void)state;
  pdSprings s = {.s1t = {3e-4, -1e-4, 0}, .s2t = {-2e-4, 5e-4, 0}};
  pdContactParams p = {.k1t = 1000, .k2t = 1000, .mu = 0.5};
  double len = pd_v3_norm(s.s1t);
  pdVec3 nNew = {0, 0, -1};
  pd_springs_realign(&s, ZN, nNew, 0.5, &p, 10.0);
  expect_near(pd_v3_norm(s.s1t), len, REALIGN_TOL_REL * len, "|s1t| kept");
  expect_near(pd_v3_dot(s.s1t, nNew), 0.0, REALIGN_TOL_REL * len, "s1t · n_new");
}

// F_n alone, as pd_contact_force forms it, in each normal branch (both dampers, proportional or not, none, one).
static void test_normal_force_alone(void** s) {
  (void)s;
  const double dampers[5][2] = {{3.0, 5.0}, {3.0, 5.0}, {0.0, 0.0}, {0.0, 5.0}, {3.0, 0.0}};
  for (int b = 0; b < 5; ++b)
    for (int k = 0; k < 100; ++k) {
      pdContactParams p = {.k1n = 2e5,
                           .k2n = 3e5,
                           .k1t = 1e5,
                           .k2t = 2e5,
                           .c1n = dampers[b][0],
                           .c2n = dampers[b][1],
                           .c1t = 1.0,
                           .c2t = 2.0,
                           .mu = 0.4,
                           .proportionalN = b == 0};
      pdSprings sp = {-1e-5 * (k % 7), 2e-5 * (k % 5), {1e-6 * k, 0, 0}, {0, -1e-6, 0}};
      pdVec3 n = pd_v3_normalize(pd_v3(0.1 * (k % 3), 0.2, 1.0));
      pdVec3 du = pd_v3(0.01 * (k % 11) - 0.05, 0.02, 0.03 * (k % 13) - 0.2);
      pdContactForce f;
      pd_contact_force(&p, &sp, n, du, &f);
      double fn = pd_contact_normal_force(&p, &sp, n, du);
      assert_memory_equal(&fn, &f.fn, sizeof fn);
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_normal_both_damped_matches_eqs_5_6),
      cmocka_unit_test(test_normal_undamped_springs_in_series),
      cmocka_unit_test(test_normal_mixed_c1_zero),
      cmocka_unit_test(test_normal_mixed_c2_zero),
      cmocka_unit_test(test_normal_tension_pulls_and_carries_no_friction),
      cmocka_unit_test(test_tangential_damped_stick_matches_eqs_5_6),
      cmocka_unit_test(test_tangential_damped_slip_lambda_from_eq_9),
      cmocka_unit_test(test_tangential_damped_stick_slip_boundary),
      cmocka_unit_test(test_tangential_damped_slip_opposes_motion),
      cmocka_unit_test(test_tangential_undamped_stick),
      cmocka_unit_test(test_tangential_undamped_slip_on_the_cone),
      cmocka_unit_test(test_tangential_mixed_c1_zero),
      cmocka_unit_test(test_tangential_mixed_c2_zero),
      cmocka_unit_test(test_frictionless_contact_has_no_tangential_output),
      cmocka_unit_test(test_balance_equations_hold_in_every_branch),
      cmocka_unit_test(test_impact_restitution_matches_closed_form),
      cmocka_unit_test(test_impact_without_damping_is_elastic),
      cmocka_unit_test(test_impact_with_material_damper_reproduces_requested_restitution),
      cmocka_unit_test(test_realign_keeps_length_and_moves_springs_into_new_plane),
      cmocka_unit_test(test_realign_with_unchanged_normal_changes_nothing),
      cmocka_unit_test(test_realign_clips_to_cone_and_clamps_tension),
      cmocka_unit_test(test_realign_survives_a_flipped_normal),
      cmocka_unit_test(test_normal_force_alone),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
