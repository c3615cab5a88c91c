// Material parameters (paper §3.2, §3.3, App. A, B): ζ(e) from eq. (15) against the catalogue's inverse
// table, the overdamped branch below e⁻² and the refusal of e < 0.01, a body's side (defaults), the pair's stiffness from eq. (11) at the pair's
// reduced mass and the smaller body's size, the pair's dampers (modal and proportional by default, the
// explicit forms when given), effective masses (point mass, slender bar, cube minimum) and the pair's
// time-constant adjustments of §3.3.1 and §3.3.2, recorded as data.
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

// Below e⁻² the damper is overdamped (ζ > 1): ζ(e) inverts the continued eq. (15) (checked against a
// direct integration of m ẍ + c ẋ + k x = 0 until the force k x + c ẋ reaches zero, the model's end of
// contact); below PD_RESTITUTION_MIN the request is refused.
static double kelvin_voigt_exit_speed(double zeta) {
  // m = k = 1, entering at speed 1; RK4 at 1e-4 of the period: error ~1e-13
  double x = 0.0, v = 1.0, c = 2.0 * zeta, h = 1e-4 * 2.0 * 3.14159265358979323846;
  for (int i = 0; i < 10000000; ++i) {
    double k1x = v, k1v = -(x + c * v);
    double k2x = v + 0.5 * h * k1v, k2v = -((x + 0.5 * h * k1x) + c * (v + 0.5 * h * k1v));
    double k3x = v + 0.5 * h * k2v, k3v = -((x + 0.5 * h * k2x) + c * (v + 0.5 * h * k2v));
    double k4x = v + h * k3v, k4v = -((x + h * k3x) + c * (v + h * k3v));
    double xn = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x), vn = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (xn + c * vn <= 0.0) {  // the force crosses zero in this step: interpolate linearly
      double f0 = x + c * v, f1 = xn + c * vn, s = f0 / (f0 - f1);
      return -(v + s * (vn - v));
    }
    x = xn, v = vn;
  }
  return NAN;
}

static void test_overdamped_restitution_and_the_refusal_below_the_minimum(void** state) {
  (void)state;
  double zeta = -1;
  char why[512] = "";
  const double es[] = {0.13, 0.1, 0.05, 0.01};
  double previous = 1.0;
  for (size_t i = 0; i < sizeof es / sizeof *es; ++i) {
    if (!pd_damping_ratio_from_restitution(es[i], &zeta, why, sizeof why)) fail_msg("%s", why);
    assert_true(zeta > previous);  // overdamped, and more so for less restitution
    previous = zeta;
    expect_near(pd_restitution_from_damping_ratio(zeta), es[i], ROUND_TRIP_TOL, "e(ζ(e))");
    double direct = kelvin_voigt_exit_speed(zeta);
    print_message("e %.2f: ζ = %.6f, direct integration e = %.8f\n", es[i], zeta, direct);
    expect_near(direct, es[i], 1e-6, "e of the integrated Kelvin–Voigt contact");
  }
  assert_false(pd_damping_ratio_from_restitution(0.005, &zeta, why, sizeof why));
  print_message("refusal: %s\n", why);
  assert_non_null(strstr(why, "below 0.01"));
  assert_false(pd_damping_ratio_from_restitution(0.0, &zeta, why, sizeof why));
  assert_false(pd_damping_ratio_from_restitution(1.2, &zeta, why, sizeof why));
  assert_false(pd_damping_ratio_from_restitution(NAN, &zeta, why, sizeof why));
  assert_true(pd_damping_ratio_from_restitution(1.0, &zeta, why, sizeof why));
  expect_near(zeta, 0.0, 0.0, "ζ(1)");
  assert_true(pd_damping_ratio_from_restitution(exp(-2.0), &zeta, why, sizeof why));
  expect_near(zeta, 1.0, 1e-6, "ζ(e^-2)");
  // the two branches meet at ζ = 1
  expect_near(pd_restitution_from_damping_ratio(1.0 + 1e-9), exp(-2.0), 1e-8, "e(1+) = e^-2");
  expect_near(pd_restitution_from_damping_ratio(1.0 - 1e-9), exp(-2.0), 1e-8, "e(1-) = e^-2");
  // through the side function, too: the message reaches the caller
  pdMaterialBody body = {.mass = 1, .mMin = 1, .size = 1};
  pdMaterialRequest req = {.mu = 0.5, .restitution = 0.005, .setMask = PD_SET_RESTITUTION};
  pdMaterialSide side;
  why[0] = 0;
  assert_false(pd_material_side(&body, &req, &side, why, sizeof why));
  assert_non_null(strstr(why, "below 0.01"));
}

// ---------------------------------------------------------------- a body's side, a pair's constants

static const pdMaterialSettings SETTINGS = {.vmax = 3.0, .deflection = 0.01, .dtmin = 1e-9};
static const pdMaterialBody BODY = {.index = 7, .mass = 2.0, .mMin = 0.5, .size = 0.5};
static const pdMaterialBody FLOOR = {.index = 8, .fixed = true, .mass = 1e5, .mMin = 1e4, .size = 10.0};

static pdMaterialSide side_of(const pdMaterialBody* b, const pdMaterialRequest* req) {
  pdMaterialSide side;
  char why[256] = "";
  if (!pd_material_side(b, req, &side, why, sizeof why)) fail_msg("pd_material_side: %s", why);
  return side;
}

static pdContactParams pair_of(const pdMaterialSide* s1, const pdMaterialSide* s2, const pdMaterialSettings* set,
                               pdAdjustmentList* adj) {
  double e, zeta;
  assert_true(pd_pair_damping_ratio(s1, s2, &e, &zeta));
  pdContactParams p;
  pd_contact_params_pair(s1, s2, zeta, set, 3, 4, &p, adj);
  return p;
}

static double series(double a, double b) { return a * b / (a + b); }

static void test_side_defaults(void** state) {
  (void)state;
  pdMaterialRequest req = {.mu = 0.4};
  pdMaterialSide s = side_of(&BODY, &req);
  assert_true(s.mu == 0.4 && s.restitution == PD_DEFAULT_RESTITUTION);
  assert_true(s.kn == 0.0 && s.kt == 0.0 && s.cn == -1.0 && s.ct == -1.0);  // derived per pair
  assert_true(s.mass == 2.0 && s.mMin == 0.5 && s.size == 0.5);
  pdMaterialSide f = side_of(&FLOOR, &req);
  assert_true(f.mass == 0.0 && f.mMin == 0.0 && f.size == 10.0);  // a fixed body: infinite mass
  req = (pdMaterialRequest){.mu = 0.4, .kn = 1e6, .cn = 5.0, .restitution = 0.8,
                            .setMask = PD_SET_KN | PD_SET_CN | PD_SET_RESTITUTION};
  s = side_of(&BODY, &req);
  assert_true(s.kn == 1e6 && s.kt == 0.0 && s.cn == 5.0 && s.ct == -1.0 && s.restitution == 0.8);
}

static void test_pair_stiffness_from_eq_11(void** state) {
  (void)state;
  // Against a fixed floor of ANY size: m_pair = 2 kg, δ_max = 0.01 × 0.5 m (the smaller body), so the series
  // stiffness stores ½ m v² = 9 J at 5 mm: k_s = 2 · 9/2.5e-5 = 720000 N/m, each side 2 k_s.
  pdMaterialRequest req = {.mu = 0.4};
  pdMaterialSide body = side_of(&BODY, &req), floor = side_of(&FLOOR, &req);
  pdContactParams p = pair_of(&body, &floor, &SETTINGS, NULL);
  expect_rel(series(p.k1n, p.k2n), 720000.0, FORMULA_TOL_REL, "k_s");
  assert_true(p.k1n == p.k2n && p.k1t == p.k1n && p.k2t == p.k2n);
  assert_true(p.massPair == 2.0 && p.massMin == 0.5);
  pdMaterialBody small = FLOOR;
  small.size = 1.0;
  pdMaterialSide floor1 = side_of(&small, &req);
  pdContactParams q = pair_of(&body, &floor1, &SETTINGS, NULL);
  assert_true(q.k1n == p.k1n && q.k2n == p.k2n);
  // two moving bodies (2 kg, 5 kg): m_pair = 10/7 kg, δ from the smaller (0.4 m), m_min in series
  pdMaterialBody other = {.index = 9, .mass = 5.0, .mMin = 1.2, .size = 0.4};
  pdMaterialSide o = side_of(&other, &req);
  p = pair_of(&body, &o, &SETTINGS, NULL);
  expect_rel(series(p.k1n, p.k2n), (10.0 / 7.0) * 9.0 / (0.004 * 0.004), FORMULA_TOL_REL, "k_s of two moving");
  expect_rel(p.massPair, 10.0 / 7.0, FORMULA_TOL_REL, "m_pair");
  expect_rel(p.massMin, series(0.5, 1.2), FORMULA_TOL_REL, "m_min in series");
  // the pair does not depend on the order
  pdContactParams r = pair_of(&o, &body, &SETTINGS, NULL);
  assert_true(r.k1n == p.k2n && r.k2n == p.k1n && r.massPair == p.massPair);
  // explicit stiffnesses are kept; kt follows the side's kn
  req = (pdMaterialRequest){.mu = 0.4, .kn = 3e5, .setMask = PD_SET_KN};
  pdMaterialSide stiff = side_of(&BODY, &req);
  p = pair_of(&stiff, &floor, &SETTINGS, NULL);
  assert_true(p.k1n == 3e5 && p.k1t == 3e5);
  expect_rel(p.k2n, 1440000.0, FORMULA_TOL_REL, "derived side 2 k_s");
}

static void test_pair_dampers_are_modal_and_proportional_by_default(void** state) {
  (void)state;
  // e = √(e₁e₂) = √(0.3 · 0.8); ζ_n from eq. (15); ζ_t the default; both sides one c/k
  pdMaterialRequest r1 = {.mu = 0.5, .restitution = 0.3, .setMask = PD_SET_RESTITUTION};
  pdMaterialRequest r2 = {.mu = 0.5, .restitution = 0.8, .setMask = PD_SET_RESTITUTION};
  pdMaterialSide s1 = side_of(&BODY, &r1), s2 = side_of(&FLOOR, &r2);
  double e, zeta, zetaExpected;
  assert_true(pd_pair_damping_ratio(&s1, &s2, &e, &zeta));
  expect_rel(e, sqrt(0.24), FORMULA_TOL_REL, "pair e");
  assert_true(pd_damping_ratio_from_restitution(sqrt(0.24), &zetaExpected, NULL, 0));
  expect_near(zeta, zetaExpected, 0.0, "pair ζ");
  pdContactParams p = pair_of(&s1, &s2, &SETTINGS, NULL);
  assert_true(p.modalN && p.modalT && p.proportionalN && p.proportionalT);
  assert_true(p.zetaN == zeta && p.zetaT == PD_TANGENTIAL_DAMPING_RATIO);
  double ks = series(p.k1n, p.k2n);
  // one contact carrying the pair's mass until the contact set says more
  expect_rel(series(p.c1n, p.c2n), 2.0 * zeta * sqrt(ks * 2.0), 1e-13, "c_s at m_pair");
  expect_rel(p.c1n / p.k1n, p.c2n / p.k2n, FORMULA_TOL_REL, "one c/k");
  expect_rel(series(p.c1t, p.c2t), 2.0 * PD_TANGENTIAL_DAMPING_RATIO * sqrt(series(p.k1t, p.k2t) * 2.0), 1e-13,
             "c_t at the default ζ_t");
  // four contacts of a face: m_c = m/4 each, ζ per contact as requested
  double scale[2];
  pd_contact_modal_damping(&p, 0.5, 0.5, 0.0, 0.0, scale);
  expect_rel(series(p.c1n, p.c2n), 2.0 * zeta * sqrt(ks * 0.5), 1e-13, "c_s at m/4");
  expect_rel(scale[0], 1.0, 0.0, "no stack: the requested ζ");
  // a mass above m_pair is clamped to it
  pd_contact_modal_damping(&p, 50.0, INFINITY, 0.0, 0.0, scale);
  expect_rel(series(p.c1n, p.c2n), 2.0 * zeta * sqrt(ks * 2.0), 1e-13, "clamped to m_pair");
  // a stack's slow mode (stack_modes.h) sizes it above m_pair, and says by how much ζ grows at the pair's own mass
  pd_contact_modal_damping(&p, 0.5, 0.5, 8.0, 0.0, scale);
  expect_rel(series(p.c1n, p.c2n), 2.0 * zeta * sqrt(ks * 8.0), 1e-13, "the stack's mass");
  expect_rel(scale[0], 4.0, 1e-15, "ζ 4 times at m/4");
  // restitution 1 on both: no normal damper
  pdMaterialRequest elastic = {.mu = 0.5, .restitution = 1.0, .setMask = PD_SET_RESTITUTION};
  s1 = side_of(&BODY, &elastic);
  s2 = side_of(&FLOOR, &elastic);
  p = pair_of(&s1, &s2, &SETTINGS, NULL);
  assert_true(p.c1n == 0.0 && p.c2n == 0.0 && p.c1t > 0.0);
}

static void test_explicit_dampers_keep_the_papers_form(void** state) {
  (void)state;
  pdMaterialRequest given = {.mu = 0.5, .cn = 40.0, .ct = 10.0, .setMask = PD_SET_CN | PD_SET_CT};
  pdMaterialRequest none = {.mu = 0.5};
  pdMaterialSide s1 = side_of(&BODY, &given), s2 = side_of(&FLOOR, &none);
  pdContactParams p = pair_of(&s1, &s2, &SETTINGS, NULL);
  assert_false(p.modalN || p.modalT);
  assert_true(p.c1n == 40.0 && p.c1t == 10.0);
  // the side without dampers gets the c/k of the pair's ζ at m_pair
  double ks = series(p.k1n, p.k2n);
  expect_rel(p.c2n / p.k2n, 2.0 * p.zetaN * sqrt(2.0 / ks), 1e-13, "derived side's c/k");
  assert_false(p.proportionalN);
  // the same c/k on both sides: proportional (one Kelvin–Voigt element)
  pdMaterialRequest a = {.mu = 0.5, .kn = 1e6, .cn = 100.0, .setMask = PD_SET_KN | PD_SET_CN};
  pdMaterialRequest b = {.mu = 0.5, .kn = 3e6, .cn = 300.0, .setMask = PD_SET_KN | PD_SET_CN};
  s1 = side_of(&BODY, &a);
  s2 = side_of(&FLOOR, &b);
  p = pair_of(&s1, &s2, &SETTINGS, NULL);
  assert_true(p.proportionalN && !p.modalN && p.c1n == 100.0 && p.c2n == 300.0);
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
  pdError why = {0};
  assert_true(pd_polyhedron_cube(&bar, scale, &why));
  assert_true(pd_mass_properties(&bar, 1000.0, &mp, &why));
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
  pdError why = {0};
  assert_true(pd_polyhedron_cube(&cube, scale, &why));
  assert_true(pd_mass_properties(&cube, 1000.0, &mp, &why));
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
  pdMaterialSide s = side_of(&BODY, &req), f = side_of(&FLOOR, &req);
  pdContactParams p = pair_of(&s, &f, &SETTINGS, &adj);
  assert_int_equal(adj.count, 0);
  assert_int_equal(adj.dropped, 0);
  assert_true(p.mu == 0.5 && p.k1n > 0.0);
}

static void test_pair_time_constant_lowers_stiffness(void** state) {
  (void)state;
  // k_s = 720000 N/m, m_min = 0.5 kg (the floor adds nothing): 1/ω = √(0.5/720000) = 8.3e-4 s < Δt_min =
  // 0.01 s → both sides scaled by (τ/Δt_min)², so k_s = m_min/Δt_min² = 5000 N/m, in n and in P_t.
  pdAdjustment items[8];
  pdAdjustmentList adj = {.items = items, .capacity = 8};
  pdMaterialSettings set = SETTINGS;
  set.dtmin = 0.01;
  pdMaterialRequest req = {.mu = 0.5};
  pdMaterialSide s = side_of(&BODY, &req), f = side_of(&FLOOR, &req);
  pdContactParams p = pair_of(&s, &f, &set, &adj);
  expect_rel(series(p.k1n, p.k2n), 5000.0, 1e-13, "k_s lowered");
  expect_rel(series(p.k1t, p.k2t), 5000.0, 1e-13, "k_t lowered");
  assert_int_equal(adj.count, 4);
  const pdMaterialParam params[4] = {pd_paramKn, pd_paramKn, pd_paramKt, pd_paramKt};
  for (int i = 0; i < 4; ++i) {
    assert_int_equal(items[i].rule, pd_adjustPairStiffness);
    assert_int_equal(items[i].param, params[i]);
    assert_true(items[i].dtmin == 0.01 && items[i].tau < 0.01);
  }
  assert_int_equal(items[0].body, 3);
  assert_int_equal(items[0].partner, 4);
  assert_int_equal(items[1].body, 4);
  expect_rel(items[0].from, 1440000.0, FORMULA_TOL_REL, "k_n from");
  expect_rel(items[0].tau, sqrt(0.5 / 720000.0), FORMULA_TOL_REL, "τ");
  // modal dampers follow the lowered stiffness: ζ stays as requested
  expect_rel(series(p.c1n, p.c2n), 2.0 * p.zetaN * sqrt(5000.0 * 2.0), 1e-13, "c_s with the lowered k");
}

static void test_contact_time_constant_zeroes_normal_dampers(void** state) {
  (void)state;
  // explicit, non-proportional: τ_n = (100 + 600)/(1e6 + 3e6) = 1.75e-4 s < Δt_min = 1e-3 s: both normal
  // dampers → 0, two records. τ_t the same: both tangential stiffnesses × τ/Δt_min = 0.175.
  pdMaterialBody heavy = {.index = 3, .mass = 100.0, .mMin = 50.0, .size = 1.0};
  pdMaterialRequest a = {.mu = 0.25, .kn = 1e6, .kt = 1e6, .cn = 100, .ct = 100,
                         .setMask = PD_SET_KN | PD_SET_KT | PD_SET_CN | PD_SET_CT};
  pdMaterialRequest b = {.mu = 1.0, .kn = 3e6, .kt = 3e6, .cn = 600, .ct = 600,
                         .setMask = PD_SET_KN | PD_SET_KT | PD_SET_CN | PD_SET_CT};
  pdMaterialSide m1 = side_of(&heavy, &a), m2 = side_of(&FLOOR, &b);
  pdAdjustment items[8];
  pdAdjustmentList adj = {.items = items, .capacity = 8};
  pdMaterialSettings set = SETTINGS;
  set.dtmin = 1e-3;
  pdContactParams p = pair_of(&m1, &m2, &set, &adj);
  expect_rel(p.mu, 0.5, FORMULA_TOL_REL, "μ = √(μ₁μ₂)");
  assert_true(p.c1n == 0.0 && p.c2n == 0.0);
  assert_true(p.c1t == 100.0 && p.c2t == 600.0 && p.k1n == 1e6 && p.k2n == 3e6);
  expect_rel(p.k1t, 1.75e5, 1e-13, "k1t lowered");
  expect_rel(p.k2t, 5.25e5, 1e-13, "k2t lowered");
  assert_int_equal(adj.count, 4);
  assert_int_equal(items[0].rule, pd_adjustContactNormal);
  assert_int_equal(items[0].body, 3);
  assert_int_equal(items[0].partner, 4);
  assert_int_equal(items[0].param, pd_paramCn);
  assert_true(items[0].from == 100.0 && items[0].to == 0.0);
  expect_rel(items[0].tau, 1.75e-4, FORMULA_TOL_REL, "τ_n");
  assert_int_equal(items[1].body, 4);
  assert_true(items[1].from == 600.0 && items[1].to == 0.0);
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
  assert_true(q.k1n == p.k2n && q.c1t == p.c2t && q.mu == p.mu && q.modalN == p.modalN);
  // frictionless pairs have no tangential springs to adjust
  a.mu = 0.0;
  m1 = side_of(&heavy, &a);
  adj.count = 0;
  p = pair_of(&m1, &m2, &set, &adj);
  assert_int_equal(adj.count, 2);
  assert_true(p.k1t == 1e6);
}

static void test_adjustments_beyond_capacity_are_counted(void** state) {
  (void)state;
  pdMaterialRequest req = {.mu = 0.5};
  pdMaterialSide s = side_of(&BODY, &req), f = side_of(&FLOOR, &req);
  pdAdjustment items[1];
  pdAdjustmentList adj = {.items = items, .capacity = 1};
  pdMaterialSettings set = SETTINGS;
  set.dtmin = 0.01;
  pair_of(&s, &f, &set, &adj);
  assert_int_equal(adj.count, 1);
  assert_int_equal(adj.dropped, 3);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_damping_ratio_matches_catalogue_inverse_table),
      cmocka_unit_test(test_damping_ratio_round_trips_through_eq_15),
      cmocka_unit_test(test_overdamped_restitution_and_the_refusal_below_the_minimum),
      cmocka_unit_test(test_side_defaults),
      cmocka_unit_test(test_pair_stiffness_from_eq_11),
      cmocka_unit_test(test_pair_dampers_are_modal_and_proportional_by_default),
      cmocka_unit_test(test_explicit_dampers_keep_the_papers_form),
      cmocka_unit_test(test_effective_mass_of_a_point_mass_is_its_mass),
      cmocka_unit_test(test_effective_mass_of_a_slender_bar_hit_at_its_end),
      cmocka_unit_test(test_minimum_effective_mass_of_a_cube),
      cmocka_unit_test(test_small_dtmin_records_no_adjustment),
      cmocka_unit_test(test_pair_time_constant_lowers_stiffness),
      cmocka_unit_test(test_contact_time_constant_zeroes_normal_dampers),
      cmocka_unit_test(test_adjustments_beyond_capacity_are_counted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
