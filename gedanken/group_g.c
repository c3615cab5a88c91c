// polydyn gedanken — group G: several bodies (catalogue §2 G1–G3).
#include <stdlib.h>

#include "gedanken_internal.h"

// ---------------------------------------------------------------------------------------------------------
// G1: four 0.1 m cubes stacked on a fixed floor, alternately turned 45° about z (no coincident features:
// 4 corner contacts on the floor, 8 edge crossings at each cube–cube interface), set down at rest.

#define G1_FROM 1.0  // s: settled after the first second (dampers of e = 0.5)

static void g1_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend 2\nsample 100\ntol 1e-7\nvmax 1\n");
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "restitution 0.5\n");
  for (int i = 0; i < 4; ++i)
    pd_gk_text_printf(out, "cube c%d red 0.1 0.1 0.1\nloc 0 0 %g%s\nrestitution 0.5\n", i + 1, 0.05 + 0.1 * i,
                      i % 2 ? "  45 0 0 1" : "");
}

static pdGkExpected g1_drift_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){0.0, 1e-9};
}

// a note on the contact count over the settled window (soft engine: it must not change)
static void g1_contacts_note(const pdGkRecord* rec, int first, char* buf, size_t size) {
  int lo = rec->contacts[first], hi = lo;
  for (int k = first; k < rec->count; ++k) lo = rec->contacts[k] < lo ? rec->contacts[k] : lo, hi = rec->contacts[k] > hi ? rec->contacts[k] : hi;
  if (lo < 0)
    snprintf(buf, size, "contacts not reported");
  else if (lo == hi)
    snprintf(buf, size, "contacts steady at %d", lo);
  else
    snprintf(buf, size, "contacts changed between %d and %d", lo, hi);
}

static void g1_drift_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  double worst = 0.0;
  int first = 0;
  while (first < rec->count && rec->t[first] < G1_FROM) ++first;
  for (int j = 0; j < rec->bodies; ++j) {
    pdVec3* x = gk_positions(rec, j);
    double drift;
    if (pd_gk_drift_speed(rec->t, x, rec->count, G1_FROM, &drift)) worst = fmax(worst, drift);
    else worst = NAN;
    free(x);
  }
  if (isnan(worst) || first >= rec->count) {
    gk_note(out, "the run ended before %g s", G1_FROM);
    return;
  }
  (void)model;
  out->value = worst;
  char contacts[64];
  g1_contacts_note(rec, first, contacts, sizeof contacts);
  gk_note(out, "largest drift of the 4 cubes over %g..%g s; %s", G1_FROM, rec->t[rec->count - 1], contacts);
}

static double g1_top_z(const pdModel* model, const pdGkRecord* rec, int k) {
  return gk_series_value(rec, k, gk_moving(model, "c4"), gk_get_z);
}

static double g1_drift_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return g1_top_z(model, rec, k);
}

const pdGkExperiment pd_gk_g1_stack_drift = {
    .name = "g1_stack_drift",
    .group = 'G',
    .title = "Stack of 4 cubes at rest: no drift",
    .quantity = "drift_speed",
    .unit = "m/s",
    .formula = "0: a stack at rest stays (catalogue G1); measured: largest |x(2 s) - x(1 s)|/1 s over the cubes",
    .toleranceReason = "catalogue G1 [REC]: drift < 1e-9 m/s; contact count constant",
    .seriesLabel = "height of the top cube's centre, m",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = true,
    .inputCount = 1,
    .scene = g1_scene,
    .expect = g1_drift_expect,
    .measure = g1_drift_measure,
    .series = g1_drift_series,
};

// The top cube sinks by the floor's 4 corner springs under 4 m g plus each interface's 8 edge springs
// under the weight above it (3, 2, 1 m g): 4 m g/(4 k_f) + 6 m g/(8 k_c).
static double g1_sinkage_predicted(const pdModel* model) {
  int c1 = gk_body(model, "c1");
  double mg = model->bodies[c1].mass * pd_v3_norm(model->settings.gravity);
  double kf = pd_model_pair_contact(model, c1, gk_body(model, "floor")).kn;
  double kc = pd_model_pair_contact(model, c1, gk_body(model, "c2")).kn;
  return 4.0 * mg / (4.0 * kf) + 6.0 * mg / (8.0 * kc);
}

static pdGkExpected g1_sinkage_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){g1_sinkage_predicted(model), 0.01};
}

static void g1_sinkage_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  out->value = 0.35 - g1_top_z(model, rec, rec->count - 1);
  double bottom = 0.05 - gk_series_value(rec, rec->count - 1, gk_moving(model, "c1"), gk_get_z);
  gk_note(out, "bottom cube sinks %.4g m (floor springs alone: %.4g m)", bottom,
          model->bodies[gk_body(model, "c1")].mass * pd_v3_norm(model->settings.gravity) /
              pd_model_pair_contact(model, gk_body(model, "c1"), gk_body(model, "floor")).kn);
}

static double g1_sinkage_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = g1_sinkage_predicted(model);
  return 0.35 - g1_top_z(model, rec, k);
}

const pdGkExperiment pd_gk_g1_stack_sinkage = {
    .name = "g1_stack_sinkage",
    .group = 'G',
    .title = "Stack of 4 cubes at rest: sinkage of the top cube",
    .quantity = "sinkage",
    .unit = "m",
    .formula = "4 m g/(4 k_f) + (3 + 2 + 1) m g/(8 k_c): interface j from the top carries j m g on its springs "
               "(catalogue G1; 4 corner contacts on the floor, 8 edge crossings between cubes turned 45 deg)",
    .toleranceReason = "1 %: settled after 2 s (dampers of e = 0.5); the springs' static deflection is exact",
    .seriesLabel = "sinkage of the top cube, m",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: a rigid contact does not sink",
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = g1_scene,
    .expect = g1_sinkage_expect,
    .measure = g1_sinkage_measure,
    .series = g1_sinkage_series,
};

// ---------------------------------------------------------------------------------------------------------
// G2: a single domino (0.04 × 0.05 × 0.1 m) set rotating about its front bottom edge at ω₀. It topples
// when ½ I_edge ω₀² ≥ m g (√((h/2)² + (t/2)²) − h/2) (I_edge = m (h² + t²)/3), i.e. ω₀ ≥ ω_c =
// √(6 g (d − h/2)/(h² + t²)); below it falls back. Inputs: ω₀/ω_c. The outcome is read from the final tilt:
// 90° lying on its face, 0° standing.

#define G2_T 0.04  // m, thickness (along the push, x)
#define G2_W 0.05  // m, width (y)
#define G2_H 0.1   // m, height (z)

static double g2_critical_spin(void) {
  double d = hypot(G2_H / 2.0, G2_T / 2.0);
  return sqrt(6.0 * GK_G * (d - G2_H / 2.0) / (G2_H * G2_H + G2_T * G2_T));
}

static void g2_scene(double ratio, pdGkText* out) {
  double w = ratio * g2_critical_spin();
  // v = ω ŷ × (centre − edge), edge at (t/2, ·, 0), centre at (0, ·, h/2)
  pd_gk_text_printf(out, "tend 1.5\nsample 200\ntol 1e-8\nvmax 1\ndeflection 0.002\n");
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "mu 0.8\nrestitution 0.3\n");
  pd_gk_text_printf(out, "cube domino red %g %g %g\nloc 0 0 %g\nvel %.17g 0 %.17g  %.17g 0 1 0\nmu 0.8\nrestitution 0.3\n",
                    G2_T, G2_W, G2_H, G2_H / 2.0, w * G2_H / 2.0, w * G2_T / 2.0, w * 180.0 / M_PI);
}

static pdGkExpected g2_expect(const pdModel* model, double ratio) {
  (void)model;
  return (pdGkExpected){ratio >= 1.0 ? 90.0 : 0.0, 5.0};
}


static void g2_measure(const pdModel* model, const pdGkRecord* rec, double ratio, pdGkMeasured* out) {
  pdBodyState last = pd_gk_body(rec, rec->count - 1, gk_moving(model, "domino"));
  out->value = gk_get_tilt_deg(&last);
  gk_note(out, "w0 = %.4g rad/s (w_c = %.4g rad/s); speed at the end %.3g m/s", ratio * g2_critical_spin(),
          g2_critical_spin(), pd_v3_norm(last.v));
}

static double g2_series(const pdModel* model, const pdGkRecord* rec, int k, double ratio, double* analytic) {
  (void)ratio;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "domino"), gk_get_tilt_deg);
}

const pdGkExperiment pd_gk_g2_domino = {
    .name = "g2_domino",
    .group = 'G',
    .title = "Domino toppling: the outcome flips at the critical spin",
    .quantity = "final_tilt",
    .unit = "deg",
    .formula = "90 (toppled) when 1/2 I_edge w0^2 >= m g (sqrt((h/2)^2 + (t/2)^2) - h/2), else 0 (catalogue G2)",
    .toleranceReason = "5 deg: the outcome is a resting pose (on its face or its base), exact up to the sinkage",
    .seriesLabel = "tilt of the domino from upright, deg",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = false,
    .inputName = "omega_ratio",
    .inputCount = 2,
    .inputs = {0.8, 1.25},
    .scene = g2_scene,
    .expect = g2_expect,
    .measure = g2_measure,
    .series = g2_series,
};

// ---------------------------------------------------------------------------------------------------------
// G3: SimBenchmark's "rolling" test (leggedrobotics/SimBenchmark, catalogue G3) with polyhedral loads: a
// 0.6 × 0.6 × 0.03 m board (10.8 kg) carrying 25 cubes of 1 kg (0.1 m, 5 × 5, 2 cm apart) is pushed along x by
// 150 N at its centre of mass over a level floor, μ 0.2 board–floor and 0.4 cube–board (μ² = 0.2 × 0.8: the
// product rule of √(μ₁μ₂)). The cubes need μ >= a/g = 0.23 to ride along, so they stick and the whole load
// slides as one body: a = (F − μ_g (M + n m) g)/(M + n m) (catalogue G3, cubes instead of rolling balls).

#define G3_PUSH 150.0   // N
#define G3_FROM 0.1     // s: after the tangential springs have loaded
#define G3_TEND 0.6
#define G3_CUBES 5      // per side

static void g3_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend %g\nsample 500\ntol 1e-7\nvmax 1.5\n", G3_TEND);
  gk_text_floor(out, 3.0, 1.0, 0.2, 1.0, "mu 0.2\nrestitution 0.5\n");
  pd_gk_text_printf(out, "cube board blue 0.6 0.6 0.03\nloc 0 0 0.015\nmu 0.2\nrestitution 0.5\nforce %g 0 0\n",
                    G3_PUSH);
  for (int i = 0; i < G3_CUBES; ++i)
    for (int k = 0; k < G3_CUBES; ++k)
      pd_gk_text_printf(out, "cube c%d%d red 0.1 0.1 0.1\nloc %g %g 0.08\nmu 0.8\nrestitution 0.5\n", i, k,
                        0.12 * (i - 2), 0.12 * (k - 2));
}

// the load's total mass and the board–floor pair's μ
static double g3_predicted(const pdModel* model) {
  double mass = 0.0;
  for (int i = 0; i < model->bodyCount; ++i)
    if (model->bodies[i].stateIndex >= 0) mass += model->bodies[i].mass;
  double mu = pd_model_pair_contact(model, gk_body(model, "board"), gk_body(model, "floor")).mu;
  return (G3_PUSH - mu * mass * pd_v3_norm(model->settings.gravity)) / mass;
}

static pdGkExpected g3_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){g3_predicted(model), 0.01};
}

static void g3_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int board = gk_moving(model, "board");
  if (!gk_measure_slope(rec, board, gk_get_vx, G3_FROM, G3_TEND, "board's speed", out)) return;
  // how far the cubes moved on the board (0 when they stick)
  pdBodyState b0 = pd_gk_body(rec, 0, board), b1 = pd_gk_body(rec, rec->count - 1, board);
  double slip = 0.0;
  for (int j = 0; j < rec->bodies; ++j) {
    if (j == board) continue;
    pdBodyState c0 = pd_gk_body(rec, 0, j), c1 = pd_gk_body(rec, rec->count - 1, j);
    slip = fmax(slip, pd_v3_norm(pd_v3_sub(pd_v3_sub(c1.x, c0.x), pd_v3_sub(b1.x, b0.x))));
  }
  size_t n = strlen(out->note);
  snprintf(out->note + n, sizeof out->note - n, "; largest slip of a cube on the board %.3g m", slip);
}

static double g3_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = g3_predicted(model) * rec->t[k];
  return gk_series_value(rec, k, gk_moving(model, "board"), gk_get_vx);
}

const pdGkExperiment pd_gk_g3_pushed_load = {
    .name = "g3_pushed_load",
    .group = 'G',
    .title = "Board carrying 25 cubes pushed by 150 N over a floor, mu 0.2 (SimBenchmark rolling)",
    .quantity = "acceleration",
    .unit = "m/s^2",
    .formula = "a = (F - mu_g (M + n m) g)/(M + n m): the cubes stick (mu 0.4 >= a/g) and the load slides as one "
               "body (catalogue G3: SimBenchmark's rolling test with cubes that stick instead of rolling balls)",
    .toleranceReason = "1 % [REC] (catalogue B4's 0.5 % for two bodies, relaxed for 26 bodies and 104 corner "
                       "contacts): fitted over 0.1..0.6 s, after the tangential springs have loaded",
    .seriesLabel = "speed of the board, m/s",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = g3_scene,
    .expect = g3_expect,
    .measure = g3_measure,
    .series = g3_series,
};
