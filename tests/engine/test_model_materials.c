// Material parameters in a compiled model (paper §3.2, §3.3; DESIGN §3.4, §4.1): k_n from eq. (11) with
// the scene's vmax and deflection, dampers from a restitution (Fig. 5 series rule), explicit constants
// winning, the fixed-body rule, pair constants (symmetry, μ = √(μ₁μ₂), tabulated or computed on the fly),
// the §3.3.1 and §3.3.2 adjustments as listed data, material classes, the shortest contact period, and
// the refusals of compile: an unreachable restitution and bodies interpenetrating at t = 0.
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
#include "model_contact.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"

// Closed forms evaluated with a few roundings each on a mass from the divergence theorem (~1e-15
// relative): 1e-12 leaves a wide margin and still catches any wrong factor.
#define FORMULA_TOL_REL 1e-12
// The catalogue's inverse table gives ζ(0.5) = 0.2553 to 4 decimals.
#define ZETA_TABLE_TOL 1e-4

#define PI 3.14159265358979323846

static void expect_rel(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol * fabs(expected)))
    fail_msg("%s: %.17g, expected %.17g (relative error %.3g > %.3g)", what, actual, expected,
             fabs(actual - expected) / fabs(expected), tol);
}

static pdModel* compile(const char* text) {
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer("m.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %d:%d: %s", err.line, err.col, err.message);
  pdModel* m = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!m) fail_msg("compile: %d:%d: %s", err.line, err.col, err.message);
  return m;
}

// The scene must parse and then be refused by compile at line:col with a message containing `part`.
static void expect_refused(const char* text, int line, int col, const char* part) {
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer("m.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %d:%d: %s", err.line, err.col, err.message);
  pdModel* m = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  print_message("refused: %s:%d:%d: %s\n", err.file, err.line, err.col, err.message);
  if (m || err.line != line || err.col != col || !strstr(err.message, part))
    fail_msg("expected %d:%d: ...%s..., got %s at %d:%d: %s", line, col, part, m ? "a model" : "refusal", err.line,
             err.col, err.message);
  assert_string_equal(err.file, "m.scene");
}

static pdMaterialUsed used_of(const pdModel* m, int body) {
  const pdBody* b = &m->bodies[body];
  pdBodyContactInfo info = pd_model_body_contact_info(m, body);
  return (pdMaterialUsed){.kn = b->used.kn, .kt = b->used.kt, .cn = b->used.cn, .ct = b->used.ct, .mu = b->used.mu,
                          .mass = info.mass, .mMin = info.mMin, .zeta = info.zeta};
}

static bool same_params(const pdContactParams* a, const pdContactParams* b) { return memcmp(a, b, sizeof *a) == 0; }

// ---------------------------------------------------------------- per-body constants

static void test_stiffness_of_a_moving_cube_follows_eq_11(void** state) {
  (void)state;
  // cube of side 0.1 m, water: m = 1 kg, size 0.1 m; δ_max = 0.02 × 0.1 = 2 mm; k_n = m vmax²/δ_max²
  pdModel* m = compile("vmax 3\ndeflection 0.02\ncube box red 0.1 0.1 0.1\n");
  const pdBody* b = &m->bodies[0];
  double delta = 0.02 * b->size;
  expect_rel(b->used.kn, b->mass * 3.0 * 3.0 / (delta * delta), FORMULA_TOL_REL, "k_n = m vmax²/δ²");
  expect_rel(b->used.kn, 2.25e6, FORMULA_TOL_REL, "k_n of 1 kg at 3 m/s over 2 mm");
  assert_true(b->used.kt == b->used.kn);  // k_t = k_n when unset
  assert_true(b->used.cn == 0.0 && b->used.ct == 0.0);  // no restitution, no damper asked: none
  assert_true(b->requested.kn == -1.0 && b->requested.cn == -1.0 && b->requested.restitution == -1.0);
  pdBodyContactInfo info = pd_model_body_contact_info(m, 0);
  assert_true(info.mass == b->mass && info.zeta == -1.0);
  expect_rel(info.mMin, 2.0 * b->mass / 11.0, FORMULA_TOL_REL, "cube m_min = 2m/11 (App. B, exact)");
  expect_rel(info.tauKn, 2.0 * PI * sqrt(info.mMin / b->used.kn), FORMULA_TOL_REL, "τ_kn");
  assert_true(isinf(info.tauCn) && isinf(info.tauCt));
  assert_int_equal(pd_model_adjustment_count(m), 0);
  pd_model_free(m);
}

static void test_restitution_gives_the_series_damper(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube box red 0.1 0.1 0.1\nrestitution 0.5\n");
  const pdBody* b = &m->bodies[0];
  pdBodyContactInfo info = pd_model_body_contact_info(m, 0);
  print_message("e = 0.5: ζ = %.6f, k_n = %.6g N/m, c_n = %.6g N·s/m\n", info.zeta, b->used.kn, b->used.cn);
  assert_true(fabs(info.zeta - 0.2553) <= ZETA_TABLE_TOL);
  // Fig. 5: per-body c = 2ζ√(2 k m); c_t from the restitution too (the default rule)
  expect_rel(b->used.cn, 2.0 * info.zeta * sqrt(2.0 * b->used.kn * b->mass), FORMULA_TOL_REL, "c_n = 2ζ√(2km)");
  expect_rel(b->used.ct, 2.0 * info.zeta * sqrt(2.0 * b->used.kt * b->mass), FORMULA_TOL_REL, "c_t = 2ζ√(2 k_t m)");
  assert_true(b->used.restitution == 0.5 && b->requested.restitution == 0.5);
  expect_rel(info.tauCn, 2.0 * info.mMin / b->used.cn, FORMULA_TOL_REL, "τ_cn = 2 m_min/c_n");
  pd_model_free(m);
}

static void test_explicit_constants_win(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube box red 0.1 0.1 0.1\nrestitution 0.5\ncn 7\nkt 1e5\n"
                       "cube bare red 0.1 0.1 0.1\nloc 1 0 0\ncn 0\nrestitution 0.5\n");
  const pdBody* b = &m->bodies[0];
  pdBodyContactInfo info = pd_model_body_contact_info(m, 0);
  assert_true(b->used.cn == 7.0 && b->requested.cn == 7.0);  // an explicit cn wins over the restitution
  assert_true(b->used.kt == 1e5 && b->requested.kt == 1e5);
  // c_t still from the restitution, with the explicit k_t
  expect_rel(b->used.ct, 2.0 * info.zeta * sqrt(2.0 * 1e5 * b->mass), FORMULA_TOL_REL, "c_t from e with kt 1e5");
  // cn 0 is a request too: no normal damper, whatever the restitution
  assert_true(m->bodies[1].used.cn == 0.0 && m->bodies[1].requested.cn == 0.0 && m->bodies[1].used.ct > 0.0);
  pd_model_free(m);
}

static void test_fixed_floor_is_sized_with_the_heaviest_moving_mass(void** state) {
  (void)state;
  pdModel* m = compile("vmax 2\n"
                       "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\n"
                       "cube light red 0.1 0.1 0.1\nloc 0 0 0.05\n"
                       "cube heavy blue 0.2 0.2 0.2\nloc 1 0 0.1\nspgrav 3\n");
  const pdBody *floor = &m->bodies[0], *light = &m->bodies[1], *heavy = &m->bodies[2];
  pdBodyContactInfo fi = pd_model_body_contact_info(m, 0);
  pdBodyContactInfo li = pd_model_body_contact_info(m, 1);
  expect_rel(heavy->mass, 24.0, FORMULA_TOL_REL, "heavy mass");
  assert_true(fi.mass == heavy->mass);  // the heaviest moving body's mass sizes the floor
  assert_true(fi.mMin == li.mMin);      // and the lightest moving mMin checks it (§3.3.1)
  double delta = m->settings.deflection * floor->size;
  expect_rel(floor->used.kn, heavy->mass * 2.0 * 2.0 / (delta * delta), FORMULA_TOL_REL, "floor k_n");
  assert_true(light->used.kn != heavy->used.kn);
  pd_model_free(m);
}

// ---------------------------------------------------------------- pair constants

static void test_pair_constants_are_symmetric_with_mu_the_geometric_mean(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.8\nrestitution 0.7\n"
                       "cube a red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0.3\nrestitution 0.5\n"
                       "sphere b blue 1 0.2 0.2 0.2\nloc 1 0 0.1\nmu 0.45\n");
  const int pairs[][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    int i = pairs[k][0], j = pairs[k][1];
    pdContactParams p = pd_model_contact_params(m, i, j), q = pd_model_contact_params(m, j, i);
    pdContactParams qs = pd_contact_params_swapped(&q);
    assert_true(same_params(&p, &qs));  // bit-identical under swap
    // the side labels follow the arguments: k1n is body i's
    assert_true(p.k1n == m->bodies[i].used.kn && p.k2n == m->bodies[j].used.kn);
    expect_rel(p.mu, sqrt(m->bodies[i].used.mu * m->bodies[j].used.mu), 1e-15, "μ = √(μ₁μ₂)");
    // the same as the material module's function on the two bodies
    pdMaterialUsed ui = used_of(m, i), uj = used_of(m, j);
    pdContactParams direct;
    pd_contact_params_pair(&ui, &uj, i, j, m->settings.dtmin, &direct, NULL);
    assert_true(same_params(&p, &direct));
  }
  expect_rel(pd_model_contact_params(m, 0, 1).mu, sqrt(0.24), 1e-15, "μ(floor, a)");
  pd_model_free(m);
}

// More distinct materials than the table holds: pairs computed on the fly give the same bits.
static void test_many_distinct_materials_give_the_same_pair_constants(void** state) {
  (void)state;
  enum { BODIES = 150 };
  size_t size = 64 * BODIES + 64;
  char* text = malloc(size);
  assert_non_null(text);
  int len = snprintf(text, size, "vmax 3\n");
  for (int i = 0; i < BODIES; ++i)
    len += snprintf(text + len, size - (size_t)len, "cube c%d red %.4f 0.1 0.1\nloc %d 0 0\nrestitution 0.6\n", i,
                    0.05 + 0.001 * i, i);
  pdModel* m = compile(text);
  free(text);
  assert_int_equal(pd_model_material_class_count(m), BODIES);
  for (int i = 0; i < BODIES; i += 7)
    for (int j = i + 1; j < BODIES; j += 11) {
      pdMaterialUsed ui = used_of(m, i), uj = used_of(m, j);
      pdContactParams direct, p = pd_model_contact_params(m, i, j), q = pd_model_contact_params(m, j, i);
      pd_contact_params_pair(&ui, &uj, i, j, m->settings.dtmin, &direct, NULL);
      pdContactParams qs = pd_contact_params_swapped(&q);
      assert_true(same_params(&p, &direct) && same_params(&qs, &direct));
    }
  pd_model_free(m);
}

// ---------------------------------------------------------------- adjustments (§3.3)

static bool listed(const pdModel* m, const char* part) {
  char line[1024];
  for (int i = 0; i < pd_model_adjustment_count(m); ++i) {
    pd_model_adjustment_describe(m, i, line, sizeof line);
    if (strstr(line, part)) return true;
  }
  return false;
}

static void print_adjustments(const pdModel* m) {
  char line[1024];
  for (int i = 0; i < pd_model_adjustment_count(m); ++i) {
    pd_model_adjustment_describe(m, i, line, sizeof line);
    print_message("  %s\n", line);
  }
}

static void test_dtmin_above_a_body_time_constant_lowers_it_by_the_rule(void** state) {
  (void)state;
  // vmax 10, deflection 0.01, a 1 kg cube of 0.1 m: k_n = 1e8 N/m, τ = 2π√((2/11)/1e8) ≈ 2.7e-4 s; with
  // dtmin 1e-3 s, §3.3.1 lowers k to m_min (2π/dtmin)².
  pdModel* m = compile("vmax 10\ndtmin 1e-3\ndt 1e-3\ncube box red 0.1 0.1 0.1\n");
  const pdBody* b = &m->bodies[0];
  pdBodyContactInfo info = pd_model_body_contact_info(m, 0);
  print_adjustments(m);
  assert_int_equal(pd_model_adjustment_count(m), 2);  // kn and kt
  assert_int_equal(pd_model_adjustments_dropped(m), 0);
  assert_true(listed(m, "box: kn 1e+08 -> ") && listed(m, "box: kt ") && listed(m, "§3.3.1"));
  double rule = info.mMin * (2.0 * PI / 1e-3) * (2.0 * PI / 1e-3);
  expect_rel(b->used.kn, rule, FORMULA_TOL_REL, "k_n = m_min (2π/dtmin)²");
  expect_rel(info.tauKn, 1e-3, FORMULA_TOL_REL, "τ_kn = dtmin after the adjustment");
  pd_model_free(m);
}

static void test_dtmin_above_a_contact_time_constant_adjusts_the_pair(void** state) {
  (void)state;
  // explicit kn 1e4, cn 1, ct 1 on two 1 kg cubes: per body τ = 2π√((2/11)/1e4) ≈ 0.027 s and
  // 2 m_min/c ≈ 0.36 s pass dtmin = 1e-3 s; the pair's τ = (1 + 1)/(1e4 + 1e4) = 1e-4 s does not (§3.3.2):
  // normal dampers off, tangential stiffnesses scaled by τ/dtmin = 0.1.
  pdModel* m = compile("dtmin 1e-3\ndt 1e-3\n"
                       "cube a red 0.1 0.1 0.1\nkn 1e4\ncn 1\nct 1\n"
                       "cube b red 0.1 0.1 0.1\nloc 1 0 0\nkn 1e4\ncn 1\nct 1\n");
  print_adjustments(m);
  assert_int_equal(pd_model_material_class_count(m), 1);
  assert_true(m->bodies[0].used.cn == 1.0);  // the per-body value is unchanged: the pair is adjusted
  pdContactParams p = pd_model_contact_params(m, 0, 1);
  assert_true(p.c1n == 0.0 && p.c2n == 0.0);
  double tau = (1.0 + 1.0) / (m->bodies[0].used.kt + m->bodies[1].used.kt);
  expect_rel(p.k1t, m->bodies[0].used.kt * tau / 1e-3, FORMULA_TOL_REL, "k_1t scaled by τ/dtmin");
  expect_rel(p.k2t, 1e3, FORMULA_TOL_REL, "k_2t = 0.1 × 1e4");
  assert_true(p.c1t == 1.0 && p.c2t == 1.0);
  // one line per change within the class (its two sides are the same change)
  assert_int_equal(pd_model_adjustment_count(m), 2);
  assert_true(listed(m, "a: cn 1 -> 0") && listed(m, "a: kt 10000 -> 1000") && listed(m, "§3.3.2"));
  assert_true(listed(m, "every contact among the 2 bodies of a's material"));
  pd_model_free(m);
}

// Compiles BODIES cubes, each its own material class (kn, cn, ct varied), on a fixed floor, and compares
// the listed §3.3.2 adjustments (plus the dropped count) with the material module's function on every
// body pair. Returns how many were listed and dropped.
static void pair_adjustments_against_brute_force(const char* dtmin, double cnBase, int* listedOut, int* droppedOut) {
  enum { BODIES = 30 };
  size_t size = 128 * BODIES + 128;
  char* text = malloc(size);
  assert_non_null(text);
  int len = snprintf(text, size, "dtmin %s\ndt 1e-3\ncube floor grey 30 1 0.1\nfixed\nloc 0 0 -0.05\n", dtmin);
  for (int i = 0; i < BODIES; ++i)
    len += snprintf(text + len, size - (size_t)len, "cube c%d red 0.1 0.1 0.1\nloc %d 0 0.05\nkn %g\ncn %g\nct %g\n", i,
                    i - BODIES / 2, 1e4 * (1 + i % 7), cnBase * (1.0 + 0.5 * (i % 5)), 0.5 + 0.7 * (i % 3));
  pdModel* m = compile(text);
  free(text);
  assert_int_equal(pd_model_material_class_count(m), BODIES + 1);
  int expected = 0;
  for (int i = 0; i < m->bodyCount; ++i)
    for (int j = i + 1; j < m->bodyCount; ++j) {
      pdAdjustment items[4];
      pdAdjustmentList list = {.items = items, .capacity = 4};
      pdMaterialUsed ui = used_of(m, i), uj = used_of(m, j);
      pdContactParams p;
      pd_contact_params_pair(&ui, &uj, i, j, m->settings.dtmin, &p, &list);
      expected += list.count;
    }
  int got = 0;
  char line[1024];
  for (int i = 0; i < pd_model_adjustment_count(m); ++i) {
    pd_model_adjustment_describe(m, i, line, sizeof line);
    if (strstr(line, "§3.3.1")) fail_msg("unexpected: %s", line);
    got += strstr(line, "§3.3.2") != NULL;
  }
  int dropped = pd_model_adjustments_dropped(m);
  print_message("dtmin %s: %d §3.3.2 adjustments listed (%d dropped), %d by brute force\n", dtmin, got, dropped,
                expected);
  assert_true(expected > 20 && expected < 2 * BODIES * (BODIES + 1));  // the scene has both kinds of pairs
  assert_int_equal(got + dropped, expected);
  pd_model_free(m);
  *listedOut = got;
  *droppedOut = dropped;
}

// Every §3.3.2 change of every pair of classes is listed, whichever pairs the compile step's screen
// skips; past the list's capacity (1000) the rest are counted as dropped, never lost.
static void test_every_pair_adjustment_is_listed_or_counted(void** state) {
  (void)state;
  int listed, dropped;
  // pair τ = (c_a + c_b)/(k_a + k_b) from ~7e-6 to 1.5e-4 s around dtmin = 3e-5 s; every per-body time
  // constant is above 1e-2 s, so §3.3.1 changes nothing
  pair_adjustments_against_brute_force("3e-5", 1.0, &listed, &dropped);
  assert_int_equal(dropped, 0);
  // dtmin 1e-4 s: nearly every pair is adjusted, more than the list holds
  pair_adjustments_against_brute_force("1e-4", 1.0, &listed, &dropped);
  assert_int_equal(listed, 1000);
  assert_true(dropped > 0);
}

// ---------------------------------------------------------------- classes, period

static char* grid_of_cubes(int side, const char* settings) {
  size_t size = 96 * (size_t)side * side * side + 256;
  char* text = malloc(size);
  assert_non_null(text);
  int len = snprintf(text, size, "%scube floor grey 4 4 0.2\nfixed\nloc 0 0 -0.1\n", settings);
  for (int i = 0; i < side * side * side; ++i)
    len += snprintf(text + len, size - (size_t)len, "cube c%d red 0.1 0.1 0.1\nloc %.1f %.1f %.2f\nrestitution 0.5\n",
                    i, 0.2 * (i % side), 0.2 * (i / side % side), 0.05 + 0.2 * (i / (side * side)));
  return text;
}

static void test_identical_bodies_share_one_material_class(void** state) {
  (void)state;
  char* text = grid_of_cubes(10, "vmax 5\n");
  pdModel* m = compile(text);
  free(text);
  assert_int_equal(m->bodyCount, 1001);
  assert_int_equal(pd_model_material_class_count(m), 2);  // 1000 cubes + the floor
  pd_model_free(m);
  // with dtmin above their time constants, 1000 identical §3.3.1 adjustments are listed once each kind
  text = grid_of_cubes(10, "vmax 5\ndtmin 1e-3\ndt 1e-3\n");
  m = compile(text);
  free(text);
  print_adjustments(m);
  assert_true(listed(m, "c0: kn ") && listed(m, "(and 999 more bodies adjusted alike)"));
  assert_true(pd_model_adjustment_count(m) <= 12);
  assert_int_equal(pd_model_adjustments_dropped(m), 0);
  pd_model_free(m);
}

static void test_shortest_contact_period_matches_the_pairs(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\n"
                       "cube wall grey 0.2 2 1\nfixed\nloc 1.5 0 0.5\n"
                       "cube a red 0.1 0.1 0.1\nloc 0 0 0.05\nkt 1e9\n"
                       "sphere b blue 1 0.2 0.2 0.2\nloc 0.5 0 0.1\nspgrav 5\n"
                       "tprism c green 5 0.3 0.3 0.3 0.6\nloc -0.5 0 0.15\nkn 1e5\n");
  // brute force over body pairs with at least one moving body
  double best = INFINITY;
  for (int i = 0; i < m->bodyCount; ++i)
    for (int j = i + 1; j < m->bodyCount; ++j) {
      if (m->bodies[i].fixed && m->bodies[j].fixed) continue;
      double mMin = fmin(pd_model_body_contact_info(m, i).mMin, pd_model_body_contact_info(m, j).mMin);
      double kn = m->bodies[i].used.kn * m->bodies[j].used.kn / (m->bodies[i].used.kn + m->bodies[j].used.kn);
      double kt = m->bodies[i].used.kt * m->bodies[j].used.kt / (m->bodies[i].used.kt + m->bodies[j].used.kt);
      best = fmin(best, 2.0 * PI * sqrt(mMin / kn));
      best = fmin(best, 2.0 * PI * sqrt(mMin / kt));
    }
  print_message("shortest contact period %.6g s (brute force %.6g s)\n", pd_model_contact_period_min(m), best);
  expect_rel(pd_model_contact_period_min(m), best, FORMULA_TOL_REL, "period_min");
  pd_model_free(m);
  // a lone body touches nothing
  m = compile("cube box red 0.1 0.1 0.1\n");
  assert_true(isinf(pd_model_contact_period_min(m)));
  pd_model_free(m);
}

// ---------------------------------------------------------------- refusals

static void test_unreachable_restitution_is_refused_at_the_object(void** state) {
  (void)state;
  expect_refused("cube a red 0.1 0.1 0.1\ncube b red 0.1 0.1 0.1\nloc 1 0 0\nrestitution 0.1\n", 2, 1,
                 "restitution 0.1 is below e^-2 = 0.1353352832");
  // just above e⁻² is fine
  pdModel* m = compile("cube a red 0.1 0.1 0.1\nrestitution 0.1354\n");
  assert_true(pd_model_body_contact_info(m, 0).zeta > 0.99);
  pd_model_free(m);
}

static void test_interpenetrating_cubes_are_refused_at_the_later_body(void** state) {
  (void)state;
  // two cubes of side 0.1 m whose centres are 0.09 m apart overlap by 1 cm
  expect_refused("# two cubes\ncube a red 0.1 0.1 0.1\n\ncube b blue 0.1 0.1 0.1\nloc 0.09 0 0\n", 4, 1,
                 "bodies 'a' and 'b' overlap by 0.01 m at t = 0 (tolerance 1e-07 m)");
  // of several overlapping pairs, the one whose later body comes first in the file
  expect_refused("cube a red 0.1 0.1 0.1\ncube b red 0.1 0.1 0.1\nloc 1 0 0\ncube c red 0.1 0.1 0.1\nloc 1.05 0 0\n"
                 "cube d red 0.1 0.1 0.1\nloc 0.02 0 0\n",
                 4, 1, "bodies 'b' and 'c' overlap by 0.05 m");
  // a moving cube sunk 1 cm into a fixed floor
  expect_refused("cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\ncube box red 0.1 0.1 0.1\nloc 0 0 0.04\n", 4, 1,
                 "bodies 'floor' and 'box' overlap by 0.01 m");
}

static void test_touching_bodies_are_accepted(void** state) {
  (void)state;
  // a cube resting exactly on a floor; a tilted cube's corner and a neighbour's face within rounding
  pdModel* m = compile("cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\n"
                       "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\n"
                       "cube next red 0.1 0.1 0.1\nloc 0.1 0 0.05\n"
                       "cube turned red 0.1 0.1 0.1\nloc 0.3 0 0.05  90 0 0 1\n"
                       "cube beside red 0.1 0.1 0.1\nloc 0.4 0 0.05  180 0 1 0\n");
  assert_int_equal(m->bodyCount, 5);
  pd_model_free(m);
  // overlapping within the tolerance (1e-9 m < 1e-6 × 0.1 m) is accepted too
  m = compile("cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\ncube box red 0.1 0.1 0.1\nloc 0 0 0.049999999\n");
  pd_model_free(m);
  // fixed bodies are never tested against each other
  m = compile("cube floor grey 1 1 0.1\nfixed\ncube wall grey 0.1 1 1\nfixed\n");
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_stiffness_of_a_moving_cube_follows_eq_11),
      cmocka_unit_test(test_restitution_gives_the_series_damper),
      cmocka_unit_test(test_explicit_constants_win),
      cmocka_unit_test(test_fixed_floor_is_sized_with_the_heaviest_moving_mass),
      cmocka_unit_test(test_pair_constants_are_symmetric_with_mu_the_geometric_mean),
      cmocka_unit_test(test_many_distinct_materials_give_the_same_pair_constants),
      cmocka_unit_test(test_dtmin_above_a_body_time_constant_lowers_it_by_the_rule),
      cmocka_unit_test(test_dtmin_above_a_contact_time_constant_adjusts_the_pair),
      cmocka_unit_test(test_every_pair_adjustment_is_listed_or_counted),
      cmocka_unit_test(test_identical_bodies_share_one_material_class),
      cmocka_unit_test(test_shortest_contact_period_matches_the_pairs),
      cmocka_unit_test(test_unreachable_restitution_is_refused_at_the_object),
      cmocka_unit_test(test_interpenetrating_cubes_are_refused_at_the_later_body),
      cmocka_unit_test(test_touching_bodies_are_accepted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
