// Material parameters in a compiled model (paper §3.2, §3.3; docs/DESIGN.md §6.4, §4.1): the pair's k_n from
// eq. (11) with the scene's vmax and deflection at the pair's reduced mass and the smaller body's size (a
// floor's size does not matter; δ_max at most a quarter of the thinner body's width), the default restitution
// and modal dampers, explicit constants winning, pair constants (symmetry, μ = √(μ₁μ₂), e = √(e₁e₂), tabulated
// or computed on the fly), the §3.3.1 and §3.3.2 adjustments as listed data, material classes, the shortest
// contact period, and the refusals of compile: an unreachable restitution and bodies interpenetrating at t = 0. Bodies
// whose objects define the same shape and density are built once: the numbers of each as if built alone.
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

// A body's side as the material module sees it, rebuilt from what the model reports.
static pdMaterialSide side_of(const pdModel* m, int body) {
  const pdBody* b = &m->bodies[body];
  pdBodyContactInfo info = pd_model_body_contact_info(m, body);
  return (pdMaterialSide){.mu = b->used.mu, .restitution = b->used.restitution,
                          .kn = b->used.kn > 0.0 ? b->used.kn : 0.0, .kt = b->used.kt > 0.0 ? b->used.kt : 0.0,
                          .cn = b->used.cn, .ct = b->used.ct, .mass = b->fixed ? 0.0 : info.mass,
                          .mMin = b->fixed ? 0.0 : info.mMin, .size = b->size};
}

// The material module's constants for bodies i, j of m, adjustments into list (may be NULL).
static pdContactParams direct_pair(const pdModel* m, int i, int j, pdAdjustmentList* list) {
  pdMaterialSide si = side_of(m, i), sj = side_of(m, j);
  double e, zeta;
  assert_true(pd_pair_damping_ratio(&si, &sj, &e, &zeta));
  pdMaterialSettings set = {.vmax = m->settings.vmax, .deflection = m->settings.deflection, .dtmin = m->settings.dtmin};
  pdContactParams p;
  pd_contact_params_pair(&si, &sj, zeta, &set, i, j, &p, list);
  return p;
}

// Field by field (the struct has padding after its flags): bit-identical values, same flags.
static bool same_params(const pdContactParams* a, const pdContactParams* b) {
  const double x[] = {a->k1n, a->k2n, a->k1t, a->k2t, a->c1n, a->c2n, a->c1t, a->c2t, a->mu, a->zetaN, a->zetaT,
                      a->massPair, a->massMin};
  const double y[] = {b->k1n, b->k2n, b->k1t, b->k2t, b->c1n, b->c2n, b->c1t, b->c2t, b->mu, b->zetaN, b->zetaT,
                      b->massPair, b->massMin};
  return memcmp(x, y, sizeof x) == 0 && a->proportionalN == b->proportionalN &&
         a->proportionalT == b->proportionalT && a->modalN == b->modalN && a->modalT == b->modalT;
}

static double series(double a, double b) { return a * b / (a + b); }

// ---------------------------------------------------------------- pair constants

static void test_stiffness_of_a_cube_on_a_floor_follows_eq_11_for_the_pair(void** state) {
  (void)state;
  // a 1 kg cube of 0.1 m on a fixed floor: m_pair = 1 kg, δ_max = 0.02 × 0.1 m = 2 mm (the smaller body),
  // k_s = m_pair vmax²/δ_max² = 2.25e6 N/m whatever the floor's size
  for (int big = 0; big < 2; ++big) {
    pdModel* m = compile(big ? "vmax 3\ndeflection 0.02\ncube floor grey 100 100 1\nfixed\nloc 0 0 -0.5\n"
                               "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0.5\n"
                             : "vmax 3\ndeflection 0.02\ncube floor grey 0.2 0.2 0.1\nfixed\nloc 0 0 -0.05\n"
                               "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0.5\n");
    const pdBody* b = &m->bodies[1];
    pdPairContact p = pd_model_pair_contact(m, 1, 0);
    expect_rel(b->mass, 1.0, FORMULA_TOL_REL, "mass");
    expect_rel(p.kn, 2.25e6, FORMULA_TOL_REL, "k_s of 1 kg at 3 m/s over 2 mm");
    assert_true(p.kt == p.kn && p.massPair == b->mass);
    expect_rel(p.deltaMax, 0.002, FORMULA_TOL_REL, "δ_max of the smaller body");
    // the default restitution, modal dampers, ζ_t the default
    assert_true(p.restitution == PD_DEFAULT_RESTITUTION && strcmp(p.restitutionSource, "default") == 0);
    assert_true(p.modalN && p.modalT && p.zetaT == PD_TANGENTIAL_DAMPING_RATIO);
    assert_true(fabs(p.zetaN - 0.2553) <= ZETA_TABLE_TOL);
    expect_rel(p.cn, 2.0 * p.zetaN * sqrt(p.kn * p.massPair), FORMULA_TOL_REL, "c_n at m_pair");
    expect_rel(p.ct, 2.0 * PD_TANGENTIAL_DAMPING_RATIO * sqrt(p.kt * p.massPair), FORMULA_TOL_REL,
               "c_t at the default ζ_t");
    // per body: what the scene left to the pair is reported as derived (-1)
    assert_true(b->used.kn == -1.0 && b->used.cn == -1.0 && b->used.restitution == PD_DEFAULT_RESTITUTION);
    assert_true(b->requested.kn == -1.0 && b->requested.cn == -1.0 && b->requested.restitution == -1.0);
    pdBodyContactInfo info = pd_model_body_contact_info(m, 1);
    assert_true(info.mass == b->mass && isinf(pd_model_body_contact_info(m, 0).mass));
    expect_rel(info.mMin, 2.0 * b->mass / 11.0, FORMULA_TOL_REL, "cube m_min = 2m/11 (App. B, exact)");
    expect_rel(p.massMin, info.mMin, FORMULA_TOL_REL, "pair m_min (the floor adds nothing)");
    assert_int_equal(pd_model_adjustment_count(m), 0);
    pd_model_free(m);
  }
}

static void test_delta_max_is_at_most_a_quarter_of_the_thinner_width(void** state) {
  (void)state;
  // a 100:1 plate and a cube of its size: δ_max = 0.01 × 0.67 m (the plate's average dimension) would
  // exceed the plate's 1 cm thickness within 1.5 deflections (soak, seed 3: vertices came out on the far
  // side); it is a quarter of the thickness, and the springs are sized for it
  pdModel* m = compile("vmax 2\ncube plate grey 1 1 0.01\ncube box red 1 1 1\nloc 0 0 1\n");
  const pdBody *plate = &m->bodies[0], *box = &m->bodies[1];
  expect_rel(plate->width, 0.01, FORMULA_TOL_REL, "the plate's thinnest width");
  expect_rel(box->width, 1.0, FORMULA_TOL_REL, "the cube's width");
  pdPairContact p = pd_model_pair_contact(m, 0, 1);
  expect_rel(p.deltaMax, 0.25 * 0.01, FORMULA_TOL_REL, "δ_max: a quarter of the plate's thickness");
  expect_rel(pd_model_pair_delta_max(m, 1, 0), p.deltaMax, FORMULA_TOL_REL, "the same either way round");
  expect_rel(p.kn, p.massPair * 4.0 / (p.deltaMax * p.deltaMax), FORMULA_TOL_REL, "k_s = m_pair vmax²/δ_max²");
  pd_model_free(m);
  // a 20:1 sliver at the default deflection: its 5 cm are more than 4 δ_max, δ_max stays 0.01 × its size
  m = compile("vmax 2\ncube sliver grey 1 1 0.05\ncube box red 1 1 1\nloc 0 0 1\n");
  expect_rel(pd_model_pair_contact(m, 0, 1).deltaMax, 0.01 * m->bodies[0].size, FORMULA_TOL_REL,
             "δ_max of the smaller body");
  pd_model_free(m);
}

static void test_two_moving_bodies_use_the_reduced_mass(void** state) {
  (void)state;
  pdModel* m = compile("vmax 2\n"
                       "cube light red 0.1 0.1 0.1\nloc 0 0 0.05\nrestitution 0.3\n"
                       "cube heavy blue 0.2 0.2 0.2\nloc 1 0 0.1\nspgrav 3\nrestitution 0.8\n");
  const pdBody *light = &m->bodies[0], *heavy = &m->bodies[1];
  expect_rel(heavy->mass, 24.0, FORMULA_TOL_REL, "heavy mass");
  pdPairContact p = pd_model_pair_contact(m, 0, 1);
  double mPair = series(light->mass, heavy->mass), delta = m->settings.deflection * light->size;
  expect_rel(p.massPair, mPair, FORMULA_TOL_REL, "m_pair");
  expect_rel(p.kn, mPair * 4.0 / (delta * delta), FORMULA_TOL_REL, "k_s = m_pair vmax²/δ²");
  expect_rel(p.restitution, sqrt(0.3 * 0.8), FORMULA_TOL_REL, "e = √(e₁e₂)");
  assert_string_equal(p.restitutionSource, "requested");
  expect_rel(p.massMin,
             series(pd_model_body_contact_info(m, 0).mMin, pd_model_body_contact_info(m, 1).mMin),
             FORMULA_TOL_REL, "m_min in series");
  pd_model_free(m);
  m = compile("cube a red 0.1 0.1 0.1\nrestitution 0.3\ncube b red 0.1 0.1 0.1\nloc 1 0 0\n");
  assert_string_equal(pd_model_pair_contact(m, 0, 1).restitutionSource, "one side requested, one default");
  expect_rel(pd_model_pair_contact(m, 0, 1).restitution, sqrt(0.3 * 0.5), FORMULA_TOL_REL, "e with the default");
  pd_model_free(m);
}

static void test_explicit_constants_win(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube box red 0.1 0.1 0.1\nrestitution 0.5\ncn 7\nkt 1e5\n"
                       "cube bare red 0.1 0.1 0.1\nloc 1 0 0\ncn 0\nrestitution 0.5\n"
                       "cube other red 0.1 0.1 0.1\nloc 2 0 0\n");
  const pdBody* b = &m->bodies[0];
  assert_true(b->used.cn == 7.0 && b->requested.cn == 7.0);  // an explicit cn wins over the restitution
  assert_true(b->used.kt == 1e5 && b->requested.kt == 1e5);
  pdContactParams p = pd_model_contact_params(m, 0, 2);
  assert_true(p.c1n == 7.0 && p.k1t == 1e5 && !p.modalN && p.modalT);
  pdPairContact pc = pd_model_pair_contact(m, 0, 2);
  assert_string_equal(pc.restitutionSource, "predicted by eq. (15) from the explicit dampers");
  // cn 0 is a request too: no normal damper on that side, whatever the restitution
  p = pd_model_contact_params(m, 1, 2);
  assert_true(p.c1n == 0.0 && !p.modalN && p.c1t > 0.0);
  pd_model_free(m);
}

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
    expect_rel(p.mu, sqrt(m->bodies[i].used.mu * m->bodies[j].used.mu), 1e-15, "μ = √(μ₁μ₂)");
    // the same as the material module's function on the two bodies
    pdContactParams direct = direct_pair(m, i, j, NULL);
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
      pdContactParams direct = direct_pair(m, i, j, NULL);
      pdContactParams p = pd_model_contact_params(m, i, j), q = pd_model_contact_params(m, j, i);
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

static void test_dtmin_above_a_pair_time_constant_lowers_its_stiffness(void** state) {
  (void)state;
  // vmax 10, deflection 0.01, a 1 kg cube of 0.1 m on a fixed floor: k_s = 1e8 N/m, 1/ω = √((2/11)/1e8)
  // ≈ 4.3e-5 s; with dtmin 1e-3 s, §3.3.1 lowers k_s to m_min/dtmin² (both sides, n and P_t).
  pdModel* m = compile("vmax 10\ndtmin 1e-3\ndt 1e-3\ncube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\n"
                       "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\n");
  print_adjustments(m);
  assert_int_equal(pd_model_adjustment_count(m), 4);  // kn and kt of both sides
  assert_int_equal(pd_model_adjustments_dropped(m), 0);
  assert_true(listed(m, "box: kn 2e+08 -> ") && listed(m, "box: kt ") && listed(m, "§3.3.1"));
  pdPairContact p = pd_model_pair_contact(m, 1, 0);
  expect_rel(p.kn, pd_model_body_contact_info(m, 1).mMin / 1e-6, FORMULA_TOL_REL, "k_s = m_min/dtmin²");
  pd_model_free(m);
}

static void test_dtmin_above_a_contact_time_constant_adjusts_the_pair(void** state) {
  (void)state;
  // explicit kn 1e4 / 2e4, cn 1, ct 1 on two 1 kg cubes: the pair's 1/ω = √((1/11)/6667) ≈ 3.7e-3 s and
  // 2 m_min/c_s ≈ 0.36 s pass dtmin = 1e-3 s; the sides' c/k differ, and the surface elements' τ =
  // (1 + 1)/(1e4 + 2e4) = 6.7e-5 s does not (§3.3.2): normal dampers off, tangential stiffnesses × τ/dtmin.
  pdModel* m = compile("dtmin 1e-3\ndt 1e-3\n"
                       "cube a red 0.1 0.1 0.1\nkn 1e4\ncn 1\nct 1\n"
                       "cube b red 0.1 0.1 0.1\nloc 1 0 0\nkn 2e4\ncn 1\nct 1\n");
  print_adjustments(m);
  assert_int_equal(pd_model_material_class_count(m), 2);
  assert_true(m->bodies[0].used.cn == 1.0);  // the per-body value is unchanged: the pair is adjusted
  pdContactParams p = pd_model_contact_params(m, 0, 1);
  assert_true(p.c1n == 0.0 && p.c2n == 0.0);
  double tau = 2.0 / 3e4;
  expect_rel(p.k1t, 1e4 * tau / 1e-3, FORMULA_TOL_REL, "k_1t scaled by τ/dtmin");
  expect_rel(p.k2t, 2e4 * tau / 1e-3, FORMULA_TOL_REL, "k_2t scaled by τ/dtmin");
  assert_true(p.c1t == 1.0 && p.c2t == 1.0);
  assert_int_equal(pd_model_adjustment_count(m), 4);
  assert_true(listed(m, "a: cn 1 -> 0") && listed(m, "a: kt 10000 -> 666.6") && listed(m, "§3.3.2"));
  pd_model_free(m);
  // the same c/k on both sides (one material) is one Kelvin–Voigt element: no surface-element mode
  m = compile("dtmin 1e-3\ndt 1e-3\ncube a red 0.1 0.1 0.1\nkn 1e4\ncn 1\nct 1\n"
              "cube b red 0.1 0.1 0.1\nloc 1 0 0\nkn 1e4\ncn 1\nct 1\n");
  assert_int_equal(pd_model_adjustment_count(m), 0);
  assert_true(pd_model_contact_params(m, 0, 1).proportionalN);
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
      if (m->bodies[i].fixed && m->bodies[j].fixed) continue;
      direct_pair(m, i, j, &list);
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
  assert_true(listed(m, "c0: kn ") && listed(m, "(every contact between the 1000 bodies of c0's material"));
  assert_true(pd_model_adjustment_count(m) <= 12);
  assert_int_equal(pd_model_adjustments_dropped(m), 0);
  pd_model_free(m);
}

// Body i of a and body j of b: the same polyhedron, mass properties, extents and minimum effective mass, bit for bit.
static void expect_same_body(const pdModel* a, int i, const pdModel* b, int j) {
  const pdBody *x = &a->bodies[i], *y = &b->bodies[j];
  const pdPolyhedron *p = &x->shape, *q = &y->shape;
  assert_int_equal(p->vertexCount, q->vertexCount);
  assert_int_equal(p->edgeCount, q->edgeCount);
  assert_int_equal(p->faceCount, q->faceCount);
  assert_memory_equal(p->vertices, q->vertices, (size_t)p->vertexCount * sizeof *p->vertices);
  assert_memory_equal(p->edges, q->edges, (size_t)p->edgeCount * sizeof *p->edges);
  assert_memory_equal(p->faces, q->faces, (size_t)p->faceCount * sizeof *p->faces);
  int sides = 0;
  for (int f = 0; f < p->faceCount; ++f) sides += p->faces[f].count;
  assert_memory_equal(p->faceVertices, q->faceVertices, (size_t)sides * sizeof *p->faceVertices);
  const double numbers[][2] = {{x->mass, y->mass}, {x->volume, y->volume}, {x->size, y->size}, {x->width, y->width},
                               {x->radius, y->radius}, {x->principal[0], y->principal[0]},
                               {x->principal[2], y->principal[2]},
                               {pd_model_body_contact_info(a, i).mMin, pd_model_body_contact_info(b, j).mMin}};
  for (size_t k = 0; k < sizeof numbers / sizeof numbers[0]; ++k)
    if (memcmp(&numbers[k][0], &numbers[k][1], sizeof(double)) != 0)
      fail_msg("number %zu: %.17g against %.17g built alone", k, numbers[k][0], numbers[k][1]);
  assert_memory_equal(&x->inertia, &y->inertia, sizeof x->inertia);
  assert_memory_equal(&x->principalAxes, &y->principalAxes, sizeof x->principalAxes);
  assert_memory_equal(&x->geometricCentre, &y->geometricCentre, sizeof x->geometricCentre);
}

static void test_equal_shapes_are_built_once_as_each_alone(void** state) {
  (void)state;
  // a and b are equal (turned apart); c is denser; d is 1e-16 m taller (a different double); e is a hull of a's
  // corners (another kind: built on its own)
  const char* box = "cube %s tan 0.2 0.15 %s\n";
  const char* lines[][3] = {{"a", "0.1", ""}, {"b", "0.1", ""}, {"c", "0.1", "spgrav 2\n"},
                            {"d", "0.1000000000000001", ""}};
  char text[2048] = "cube floor grey 3 3 0.1\nfixed\nloc 0 0 -0.05\n";
  for (int k = 0; k < 4; ++k) {
    size_t at = strlen(text);
    snprintf(text + at, sizeof text - at, box, lines[k][0], lines[k][1]);
    at = strlen(text);
    snprintf(text + at, sizeof text - at, "loc %g 0 0.2  %d 1 2 3\n%s", -0.9 + 0.4 * k, 40 * k, lines[k][2]);
  }
  strcat(text, "hull e tan -0.1 -0.075 -0.05 0.1 -0.075 -0.05 -0.1 0.075 -0.05 0.1 0.075 -0.05 "
               "-0.1 -0.075 0.05 0.1 -0.075 0.05 -0.1 0.075 0.05 0.1 0.075 0.05\nloc 0.9 0 0.2\n");
  pdModel* pile = compile(text);
  assert_int_equal(pile->bodyCount, 6);
  for (int k = 0; k < 5; ++k) {
    char alone[512];
    if (k < 4) {
      snprintf(alone, sizeof alone, box, lines[k][0], lines[k][1]);
      strcat(alone, lines[k][2]);
    } else {
      snprintf(alone, sizeof alone, "hull e tan -0.1 -0.075 -0.05 0.1 -0.075 -0.05 -0.1 0.075 -0.05 0.1 0.075 -0.05 "
                                    "-0.1 -0.075 0.05 0.1 -0.075 0.05 -0.1 0.075 0.05 0.1 0.075 0.05\n");
    }
    pdModel* m = compile(alone);
    expect_same_body(pile, 1 + k, m, 0);
    pd_model_free(m);
  }
  // copies, not one array twice (each body's shape is its own to free)
  assert_ptr_not_equal(pile->bodies[1].shape.vertices, pile->bodies[2].shape.vertices);
  // what differs is seen: twice the density, a taller box
  assert_true(pile->bodies[3].mass > 1.9 * pile->bodies[1].mass);
  assert_true(memcmp(pile->bodies[4].shape.vertices, pile->bodies[1].shape.vertices,
                     8 * sizeof *pile->bodies[1].shape.vertices) != 0);
  pd_model_free(pile);
}

static void test_shortest_contact_period_matches_the_pairs(void** state) {
  (void)state;
  pdModel* m = compile("vmax 3\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\n"
                       "cube wall grey 0.2 2 1\nfixed\nloc 1.5 0 0.5\n"
                       "cube a red 0.1 0.1 0.1\nloc 0 0 0.05\nkt 1e9\n"
                       "sphere b blue 1 0.2 0.2 0.2\nloc 0.5 0 0.1\nspgrav 5\n"
                       "tprism c green 5 0.3 0.3 0.3 0.6\nloc -0.5 0 0.15\nkn 1e5\n");
  // brute force over body pairs with at least one moving body: 2π√(m_min/k_s) of each pair, n and P_t
  double best = INFINITY;
  for (int i = 0; i < m->bodyCount; ++i)
    for (int j = i + 1; j < m->bodyCount; ++j) {
      if (m->bodies[i].fixed && m->bodies[j].fixed) continue;
      pdPairContact p = pd_model_pair_contact(m, i, j);
      best = fmin(best, 2.0 * PI * sqrt(p.massMin / p.kn));
      best = fmin(best, 2.0 * PI * sqrt(p.massMin / p.kt));
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
  expect_refused("cube a red 0.1 0.1 0.1\ncube b red 0.1 0.1 0.1\nloc 1 0 0\nrestitution 0.005\n", 2, 1,
                 "restitution 0.005 is below 0.01");
  // below e⁻² is overdamped, at the minimum too
  pdModel* m = compile("cube a red 0.1 0.1 0.1\nrestitution 0.01\n");
  assert_true(pd_model_body_contact_info(m, 0).zeta > 4.8);
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
      cmocka_unit_test(test_stiffness_of_a_cube_on_a_floor_follows_eq_11_for_the_pair),
      cmocka_unit_test(test_delta_max_is_at_most_a_quarter_of_the_thinner_width),
      cmocka_unit_test(test_two_moving_bodies_use_the_reduced_mass),
      cmocka_unit_test(test_explicit_constants_win),
      cmocka_unit_test(test_pair_constants_are_symmetric_with_mu_the_geometric_mean),
      cmocka_unit_test(test_many_distinct_materials_give_the_same_pair_constants),
      cmocka_unit_test(test_dtmin_above_a_pair_time_constant_lowers_its_stiffness),
      cmocka_unit_test(test_dtmin_above_a_contact_time_constant_adjusts_the_pair),
      cmocka_unit_test(test_every_pair_adjustment_is_listed_or_counted),
      cmocka_unit_test(test_identical_bodies_share_one_material_class),
      cmocka_unit_test(test_equal_shapes_are_built_once_as_each_alone),
      cmocka_unit_test(test_shortest_contact_period_matches_the_pairs),
      cmocka_unit_test(test_unreachable_restitution_is_refused_at_the_object),
      cmocka_unit_test(test_interpenetrating_cubes_are_refused_at_the_later_body),
      cmocka_unit_test(test_touching_bodies_are_accepted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
