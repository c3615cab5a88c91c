// Material parameters (paper §3.2, §3.3, App. A, B): ζ(e) from eq. (15) against the catalogue's inverse
// table, the refusal of e < e⁻², stiffness from eq. (11), dampers from restitution (Fig. 5 series rule),
// the tangential-damper rules, the fixed-body rule, effective masses (point mass, slender bar, cube
// minimum) and the time-constant adjustments of §3.3.1 and §3.3.2, recorded as data.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "test_random.h"

#include "material.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

// The catalogue's inverse table is printed to 4 decimals: a correct ζ is within 0.5e-4 of it.
#define ZETA_TABLE_TOL 1e-4
// ζ is solved to 1e-13 absolute; e(ζ) then carries ~1e-13 of error: 1e-12 leaves a margin.
#define ROUND_TRIP_TOL 1e-12
// Closed forms evaluated with a few roundings each (sqrt, products of O(1) numbers).
#define FORMULA_TOL_REL 1e-14
// Effective masses from a numerically integrated inertia (~1e-15 relative) and a 3×3 eigen-solve.
#define MASS_TOL_REL 1e-12

#define PI 3.14159265358979323846

static void expect_near(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol))
    fail_msg("%s: %.17g, expected %.17g (error %.3g > %.3g)", what, actual, expected, fabs(actual - expected), tol);
}

static void expect_rel(double actual, double expected, double tol, const char* what) {
  expect_near(actual, expected, tol * fabs(expected), what);
}

// ---------------------------------------------------------------- restitution

static void test_damping_ratio_matches_catalogue_inverse_table(void** state) {
  (void)state;
  const double table[][2] = {{0.9, 0.0343}, {0.8, 0.0744}, {0.5, 0.2553}, {0.3, 0.4972}, {0.15, 0.9246}};
  for (int i = 0; i < 5; ++i) {
    double zeta = -1;
    char why[256] = "";
    if (!pd_damping_ratio_from_restitution(table[i][0], &zeta, why, sizeof why)) fail_msg("%s", why);
    print_message("e = %.2f: ζ = %.6f (catalogue %.4f)\n", table[i][0], zeta, table[i][1]);
    expect_near(zeta, table[i][1], ZETA_TABLE_TOL, "ζ(e)");
  }
}

static void test_damping_ratio_round_trips_through_eq_15(void** state) {
  (void)state;
  for (double e = 0.14; e < 1.0; e += 0.01) {
    double zeta = -1;
    char why[256] = "";
    if (!pd_damping_ratio_from_restitution(e, &zeta, why, sizeof why)) fail_msg("%s", why);
    assert_true(zeta > 0.0 && zeta < 1.0);
    expect_near(pd_restitution_from_damping_ratio(zeta), e, ROUND_TRIP_TOL, "e(ζ(e))");
  }
  // the forward map at the catalogue's A1 points (table to 3 decimals) and its limits
  expect_near(pd_restitution_from_damping_ratio(0.1), 0.744, 5e-4, "e(0.1)");
  expect_near(pd_restitution_from_damping_ratio(0.5), 0.298, 5e-4, "e(0.5)");
  expect_near(pd_restitution_from_damping_ratio(0.0), 1.0, 0.0, "e(0)");
  expect_near(pd_restitution_from_damping_ratio(1.0), exp(-2.0), FORMULA_TOL_REL, "e(1) = e^-2");
}

static void test_restitution_below_e_minus_2_is_refused(void** state) {
  (void)state;
  double zeta = -1;
  char why[256] = "";
  assert_false(pd_damping_ratio_from_restitution(0.1, &zeta, why, sizeof why));
  print_message("refusal: %s\n", why);
  assert_non_null(strstr(why, "unreachable"));
  assert_non_null(strstr(why, "0.1353"));
  assert_false(pd_damping_ratio_from_restitution(1.2, &zeta, why, sizeof why));
  assert_false(pd_damping_ratio_from_restitution(NAN, &zeta, why, sizeof why));
  assert_true(pd_damping_ratio_from_restitution(1.0, &zeta, why, sizeof why));
  expect_near(zeta, 0.0, 0.0, "ζ(1)");
  assert_true(pd_damping_ratio_from_restitution(exp(-2.0), &zeta, why, sizeof why));
  expect_near(zeta, 1.0, 1e-6, "ζ(e^-2)");
  // through the body function, too: the message reaches the caller
  pdMaterialBody body = {.mass = 1, .mMin = 1, .size = 1};
  pdMaterialRequest req = {.mu = 0.5, .restitution = 0.1, .setMask = PD_SET_RESTITUTION};
  pdMaterialSettings set = {.vmax = 1, .deflection = 0.01, .dtmin = 1e-9};
  pdMaterialUsed used;
  why[0] = 0;
  assert_false(pd_material_body(&body, &req, &set, &used, NULL, why, sizeof why));
  assert_non_null(strstr(why, "unreachable"));
}

// ---------------------------------------------------------------- per-body parameters

static const pdMaterialSettings SETTINGS = {.vmax = 3.0, .deflection = 0.01, .dtmin = 1e-9,
                                            .ctRule = pd_ctFromRestitution};
static const pdMaterialBody BODY = {.index = 7, .mass = 2.0, .mMin = 0.5, .size = 0.5};

static pdMaterialUsed body_used(const pdMaterialBody* b, const pdMaterialRequest* req, const pdMaterialSettings* s,
                                pdAdjustmentList* adj) {
  pdMaterialUsed used;
  char why[256] = "";
  if (!pd_material_body(b, req, s, &used, adj, why, sizeof why)) fail_msg("pd_material_body: %s", why);
  return used;
}

static void test_stiffness_from_eq_11(void** state) {
  (void)state;
  // δ_max = 0.01 × 0.5 = 0.005 m, E_max = ½ 2 · 3² = 9 J: k_n = 2 E_max/δ_max² = 18/2.5e-5 = 720000 N/m.
  pdMaterialRequest req = {.mu = 0.4};
  pdMaterialUsed u = body_used(&BODY, &req, &SETTINGS, NULL);
  expect_rel(u.kn, 720000.0, FORMULA_TOL_REL, "k_n");
  expect_rel(u.kt, 720000.0, FORMULA_TOL_REL, "k_t = k_n");
  assert_true(u.cn == 0.0 && u.ct == 0.0 && u.zeta == -1.0 && u.mu == 0.4);
  assert_true(u.mass == 2.0 && u.mMin == 0.5);
  // an explicit kt is kept
  req.kt = 5e5;
  req.setMask = PD_SET_KT;
  u = body_used(&BODY, &req, &SETTINGS, NULL);
  assert_true(u.kt == 5e5);
  expect_rel(u.kn, 720000.0, FORMULA_TOL_REL, "k_n unchanged by an explicit kt");
}

static void test_dampers_from_restitution_use_the_series_rule(void** state) {
  (void)state;
  // Fig. 5: c = 2ζ√(2 k m) per body, for c_n (k_n) and, by default, for c_t (k_t).
  pdMaterialRequest req = {.mu = 0.5, .restitution = 0.5, .setMask = PD_SET_RESTITUTION};
  pdMaterialUsed u = body_used(&BODY, &req, &SETTINGS, NULL);
  double zeta = -1;
  assert_true(pd_damping_ratio_from_restitution(0.5, &zeta, NULL, 0));
  expect_near(u.zeta, zeta, 0.0, "ζ");
  expect_rel(u.cn, 2.0 * zeta * sqrt(2.0 * 720000.0 * 2.0), FORMULA_TOL_REL, "c_n");
  expect_rel(u.ct, 2.0 * zeta * sqrt(2.0 * 720000.0 * 2.0), FORMULA_TOL_REL, "c_t (15)");
  // the series experiment gives back ζ: (c/2)/(2√((k/2) m))
  expect_rel((u.cn / 2.0) / (2.0 * sqrt(u.kn / 2.0 * 2.0)), zeta, FORMULA_TOL_REL, "ζ of the series system");
  // critical rule: c_t = √(4 m k_t)
  pdMaterialSettings crit = SETTINGS;
  crit.ctRule = pd_ctCritical;
  u = body_used(&BODY, &req, &crit, NULL);
  expect_rel(u.ct, sqrt(4.0 * 2.0 * 720000.0), FORMULA_TOL_REL, "c_t critical");
  // explicit values win
  req.cn = 10.0;
  req.ct = 3.0;
  req.setMask |= PD_SET_CN | PD_SET_CT;
  u = body_used(&BODY, &req, &crit, NULL);
  assert_true(u.cn == 10.0 && u.ct == 3.0);
}

static void test_fixed_body_uses_heaviest_moving_mass(void** state) {
  (void)state;
  pdMaterialBody bodies[3] = {{.index = 0, .mass = 2.0, .mMin = 0.5, .size = 0.5},
                              {.index = 1, .mass = 5.0, .mMin = 1.2, .size = 0.4},
                              {.index = 2, .fixed = true, .mass = 1e4, .mMin = 3e3, .size = 2.0}};
  pdMaterialRequest reqs[3] = {
      {.mu = 0.5}, {.mu = 0.5}, {.mu = 0.5, .restitution = 0.8, .setMask = PD_SET_RESTITUTION}};
  pdMaterialUsed used[3];
  char why[256] = "";
  int failed = -1;
  assert_true(pd_material_bodies(bodies, reqs, 3, &SETTINGS, used, NULL, &failed, why, sizeof why));
  // the floor: mass 5 (heaviest mover), size 2 → δ = 0.02, k_n = 5 · 9/4e-4; m_min = 0.5 (lightest mover)
  expect_rel(used[2].kn, 5.0 * 9.0 / (0.02 * 0.02), FORMULA_TOL_REL, "fixed k_n");
  assert_true(used[2].mass == 5.0 && used[2].mMin == 0.5);
  expect_rel(used[2].cn, 2.0 * used[2].zeta * sqrt(2.0 * used[2].kn * 5.0), FORMULA_TOL_REL, "fixed c_n");
  // moving bodies keep their own
  assert_true(used[1].mass == 5.0 && used[1].mMin == 1.2);
  // a scene of fixed bodies only: they keep their own masses
  double m = 0, mm = 0;
  assert_false(pd_material_fixed_reference(&bodies[2], 1, &m, &mm));
}

// ---------------------------------------------------------------- effective mass

static void test_effective_mass_of_a_point_mass_is_its_mass(void** state) {
  (void)state;
  pdMat3 zero = pd_mat3_zero();
  expect_near(pd_effective_mass(3.0, &zero, pd_v3(0.3, -0.2, 0.5), pd_v3(0, 0.6, 0.8)), 3.0, 0.0, "J⁻¹ = 0");
  // a body with a huge inertia: (r × n)² / 1e30 is lost below 1e-12 of 1/m
  pdMat3 inv = pd_mat3_identity();
  for (int i = 0; i < 3; ++i) inv.m[i][i] = 1e-30;
  expect_rel(pd_effective_mass(3.0, &inv, pd_v3(0.3, -0.2, 0.5), pd_v3(0, 0.6, 0.8)), 3.0, MASS_TOL_REL, "I huge");
}

static void test_effective_mass_of_a_slender_bar_hit_at_its_end(void** state) {
  (void)state;
  // Box L × t × t (L = 1, t = 0.05), hit at the end r = (L/2, 0, 0) along n = z: r × n = (0, −L/2, 0),
  // 1/m_eff = 1/m + (L/2)²/I_yy with I_yy = m (L² + t²)/12, so m_eff = m (L² + t²)/(4 L² + t²) (0.25047 m).
  // The thin-rod limit (I_yy = m L²/12) is catalogue A2's m/4.
  const double L = 1.0, t = 0.05, scale[3] = {L, t, t};
  pdPolyhedron bar;
  pdMassProperties mp;
  char why[256] = "";
  assert_true(pd_polyhedron_cube(&bar, scale, why, sizeof why));
  assert_true(pd_mass_properties(&bar, 1000.0, &mp, why, sizeof why));
  pdMat3 inv = pd_mat3_zero();
  for (int i = 0; i < 3; ++i) inv.m[i][i] = 1.0 / mp.inertia.m[i][i];
  const double m = mp.mass;
  double meff = pd_effective_mass(m, &inv, pd_v3(L / 2, 0, 0), pd_v3(0, 0, 1));
  print_message("bar: m_eff/m = %.12f (box), thin rod 0.25\n", meff / m);
  expect_rel(meff, m * (L * L + t * t) / (4 * L * L + t * t), MASS_TOL_REL, "box bar end");
  pdMat3 rod = pd_mat3_zero();
  rod.m[0][0] = 1.0;  // unused: r × n has no x component
  rod.m[1][1] = rod.m[2][2] = 12.0 / (m * L * L);
  expect_rel(pd_effective_mass(m, &rod, pd_v3(L / 2, 0, 0), pd_v3(0, 0, 1)), m / 4.0, MASS_TOL_REL, "thin rod m/4");
  // along its axis, or at its centre, the bar feels its whole mass
  expect_rel(pd_effective_mass(m, &inv, pd_v3(L / 2, 0, 0), pd_v3(1, 0, 0)), m, MASS_TOL_REL, "axial");
  expect_rel(pd_effective_mass(m, &inv, pd_v3(0, 0, 0), pd_v3(0, 0, 1)), m, MASS_TOL_REL, "centre");
  pd_polyhedron_free(&bar);
}

static void test_minimum_effective_mass_of_a_cube(void** state) {
  (void)state;
  // Cube of side a: J = m a²/6 · I. At a vertex r (|r|² = 3a²/4), M = I/m + (6/(m a²)) (|r|² I − r rᵀ) has
  // eigenvalues 1/m (along r) and 1/m + 4.5/m (⊥ r): m_min = m/5.5 = 2m/11.
  // Eq. (22) (n along a principal axis): 1/m + (r_y² + r_z²)·6/(m a²) = 4/m: m/4.
  const double a = 0.4, scale[3] = {a, a, a};
  pdPolyhedron cube;
  pdMassProperties mp;
  char why[256] = "";
  assert_true(pd_polyhedron_cube(&cube, scale, why, sizeof why));
  assert_true(pd_mass_properties(&cube, 1000.0, &mp, why, sizeof why));
  const double m = mp.mass;
  double exact = pd_min_effective_mass(m, &mp.inertia, cube.vertices, cube.vertexCount);
  // A cube's inertia is isotropic: every basis is principal and eq. (22) depends on the one chosen (GSL's
  // is arbitrary). The paper's reading is the face axes.
  const pdMat3 faceAxes = pd_mat3_identity();
  double approx = pd_min_effective_mass_principal(m, mp.principal, &faceAxes, cube.vertices, cube.vertexCount);
  print_message("cube: m_min/m = %.12f (exact), %.12f (eq. 22)\n", exact / m, approx / m);
  expect_rel(exact, 2.0 * m / 11.0, MASS_TOL_REL, "m_min exact");
  expect_rel(approx, m / 4.0, MASS_TOL_REL, "m_min eq. (22)");
  // no point of the body, in no direction, feels less than m_min
  pdMat3 inv = pd_mat3_zero();
  for (int i = 0; i < 3; ++i) inv.m[i][i] = 1.0 / mp.inertia.m[i][i];
  lcg g = {7};
  for (int trial = 0; trial < 20000; ++trial) {
    pdVec3 r = {lcg_range(&g, -a / 2, a / 2), lcg_range(&g, -a / 2, a / 2), lcg_range(&g, -a / 2, a / 2)};
    pdVec3 n = pd_v3_normalize(pd_v3(lcg_range(&g, -1, 1), lcg_range(&g, -1, 1), lcg_range(&g, -1, 1)));
    assert_true(pd_effective_mass(m, &inv, r, n) >= exact * (1.0 - MASS_TOL_REL));
  }
  pd_polyhedron_free(&cube);
}

// ---------------------------------------------------------------- time constants (§3.3)

static void test_small_dtmin_records_no_adjustment(void** state) {
  (void)state;
  pdAdjustment items[8];
  pdAdjustmentList adj = {.items = items, .capacity = 8};
  pdMaterialRequest req = {.mu = 0.5, .restitution = 0.5, .setMask = PD_SET_RESTITUTION};
  pdMaterialUsed u = body_used(&BODY, &req, &SETTINGS, &adj);
  pdContactParams p;
  pd_contact_params_pair(&u, &u, 0, 1, SETTINGS.dtmin, &p, &adj);
  assert_int_equal(adj.count, 0);
  assert_int_equal(adj.dropped, 0);
  assert_true(p.c1n == u.cn && p.c2n == u.cn && p.k1t == u.kt && p.mu == 0.5);
}

static void test_body_time_constants_lower_stiffness_and_damping(void** state) {
  (void)state;
  // m_min = 0.5, k_n = k_t = 720000: τ = 2π√(0.5/720000) = 5.24e-3 s < Δt_min = 0.01 s →
  // k = m_min (2π/Δt_min)² = 0.5 · (200π)² for both. Then c from e = 0.5 with that k exceeds
  // 2 m_min/Δt_min = 100 N·s/m (τ = 2 m_min/c < Δt_min) → c_n = c_t = 100.
  pdAdjustment items[8];
  pdAdjustmentList adj = {.items = items, .capacity = 8};
  pdMaterialSettings set = SETTINGS;
  set.dtmin = 0.01;
  pdMaterialRequest req = {.mu = 0.5, .restitution = 0.5, .setMask = PD_SET_RESTITUTION};
  pdMaterialUsed u = body_used(&BODY, &req, &set, &adj);
  const double kLow = 0.5 * (200.0 * PI) * (200.0 * PI);
  expect_rel(u.kn, kLow, FORMULA_TOL_REL, "k_n lowered");
  expect_rel(u.kt, kLow, FORMULA_TOL_REL, "k_t lowered");
  expect_rel(u.cn, 100.0, FORMULA_TOL_REL, "c_n lowered");
  expect_rel(u.ct, 100.0, FORMULA_TOL_REL, "c_t lowered");
  assert_int_equal(adj.count, 4);
  const pdMaterialParam params[4] = {pd_paramKn, pd_paramKt, pd_paramCn, pd_paramCt};
  for (int i = 0; i < 4; ++i) {
    assert_int_equal(items[i].body, 7);
    assert_int_equal(items[i].partner, -1);
    assert_int_equal(items[i].param, params[i]);
    assert_true(items[i].dtmin == 0.01 && items[i].tau < 0.01);
  }
  assert_int_equal(items[0].rule, pd_adjustBodyPeriod);
  expect_rel(items[0].from, 720000.0, FORMULA_TOL_REL, "k_n from");
  expect_rel(items[0].tau, 2.0 * PI * sqrt(0.5 / 720000.0), FORMULA_TOL_REL, "k_n τ");
  assert_int_equal(items[2].rule, pd_adjustBodyDecay);
  expect_rel(items[2].from, 2.0 * u.zeta * sqrt(2.0 * kLow * 2.0), FORMULA_TOL_REL, "c_n from (with lowered k)");
  assert_true(items[2].to == u.cn);
}

static void test_contact_time_constant_zeroes_normal_dampers(void** state) {
  (void)state;
  // τ_n = (100 + 300)/(1e6 + 3e6) = 1e-4 s < Δt_min = 1e-3 s: both normal dampers → 0, two records.
  // τ_t is the same: both tangential stiffnesses × τ/Δt_min = 0.1.
  pdMaterialUsed m1 = {.kn = 1e6, .kt = 1e6, .cn = 100, .ct = 100, .mu = 0.25};
  pdMaterialUsed m2 = {.kn = 3e6, .kt = 3e6, .cn = 300, .ct = 300, .mu = 1.0};
  pdAdjustment items[8];
  pdAdjustmentList adj = {.items = items, .capacity = 8};
  pdContactParams p;
  pd_contact_params_pair(&m1, &m2, 3, 4, 1e-3, &p, &adj);
  expect_rel(p.mu, 0.5, FORMULA_TOL_REL, "μ = √(μ₁μ₂)");
  assert_true(p.c1n == 0.0 && p.c2n == 0.0);
  assert_true(p.c1t == 100.0 && p.c2t == 300.0 && p.k1n == 1e6 && p.k2n == 3e6);
  expect_rel(p.k1t, 1e5, FORMULA_TOL_REL, "k1t lowered");
  expect_rel(p.k2t, 3e5, FORMULA_TOL_REL, "k2t lowered");
  assert_int_equal(adj.count, 4);
  assert_int_equal(items[0].rule, pd_adjustContactNormal);
  assert_int_equal(items[0].body, 3);
  assert_int_equal(items[0].partner, 4);
  assert_int_equal(items[0].param, pd_paramCn);
  assert_true(items[0].from == 100.0 && items[0].to == 0.0);
  expect_rel(items[0].tau, 1e-4, FORMULA_TOL_REL, "τ_n");
  assert_int_equal(items[1].body, 4);
  assert_true(items[1].from == 300.0 && items[1].to == 0.0);
  assert_int_equal(items[2].rule, pd_adjustContactTangential);
  assert_int_equal(items[2].param, pd_paramKt);
  char line[512];
  pd_adjustment_describe(&items[0], "ball", "floor", line, sizeof line);
  print_message("%s\n", line);
  assert_non_null(strstr(line, "ball: cn 100 -> 0"));
  assert_non_null(strstr(line, "floor"));
  assert_non_null(strstr(line, "§3.3.2"));
  // the swapped view of the pair
  pdContactParams q = pd_contact_params_swapped(&p);
  assert_true(q.k1n == p.k2n && q.c1t == p.c2t && q.mu == p.mu);
  // frictionless pairs have no tangential springs to adjust
  m1.mu = 0.0;
  adj.count = 0;
  pd_contact_params_pair(&m1, &m2, 3, 4, 1e-3, &p, &adj);
  assert_int_equal(adj.count, 2);
  assert_true(p.k1t == 1e6);
}

static void test_adjustments_beyond_capacity_are_counted(void** state) {
  (void)state;
  pdMaterialUsed m1 = {.kn = 1e6, .kt = 1e6, .cn = 100, .ct = 100, .mu = 1};
  pdAdjustment items[1];
  pdAdjustmentList adj = {.items = items, .capacity = 1};
  pdContactParams p;
  pd_contact_params_pair(&m1, &m1, 0, 1, 1e-3, &p, &adj);
  assert_int_equal(adj.count, 1);
  assert_int_equal(adj.dropped, 3);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_damping_ratio_matches_catalogue_inverse_table),
      cmocka_unit_test(test_damping_ratio_round_trips_through_eq_15),
      cmocka_unit_test(test_restitution_below_e_minus_2_is_refused),
      cmocka_unit_test(test_stiffness_from_eq_11),
      cmocka_unit_test(test_dampers_from_restitution_use_the_series_rule),
      cmocka_unit_test(test_fixed_body_uses_heaviest_moving_mass),
      cmocka_unit_test(test_effective_mass_of_a_point_mass_is_its_mass),
      cmocka_unit_test(test_effective_mass_of_a_slender_bar_hit_at_its_end),
      cmocka_unit_test(test_minimum_effective_mass_of_a_cube),
      cmocka_unit_test(test_small_dtmin_records_no_adjustment),
      cmocka_unit_test(test_body_time_constants_lower_stiffness_and_damping),
      cmocka_unit_test(test_contact_time_constant_zeroes_normal_dampers),
      cmocka_unit_test(test_adjustments_beyond_capacity_are_counted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
