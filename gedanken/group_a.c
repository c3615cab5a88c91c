// polydyn gedanken — group A: contact-model calibration (catalogue §2 A1–A4).
#include <stdlib.h>

#include "gedanken_internal.h"

// Free flight is exact for the integrators (constant velocity, or constant acceleration with gravity), so
// the impact detector's threshold only has to sit above round-off: 1e-6 of the 1 m/s impact speed.
#define IMPACT_THRESHOLD 1e-6  // m/s
#define IMPACT_SETTLE 3        // free intervals in a row that end an impact

// ζ of one contact between `moving` and `fixed` for a mass m: the pair's series constants (model.h).
static double pair_zeta(const pdModel* model, int moving, int fixed, double mass) {
  pdPairContact p = pd_model_pair_contact(model, moving, fixed);
  return p.cn / (2.0 * sqrt(p.kn * mass));
}

// Restitution of the first impact of moving body `name` along z, gravity off.
static void measure_first_impact(const pdModel* model, const pdGkRecord* rec, const char* name, pdGkMeasured* out) {
  int j = gk_moving(model, name);
  double* vz = gk_column(rec, j, gk_get_vz);
  pdGkImpact impact;
  if (pd_gk_first_impact(rec->t, vz, rec->count, model->settings.gravity.z, IMPACT_THRESHOLD, IMPACT_SETTLE, &impact)) {
    out->value = impact.restitution;
    gk_note(out, "impact %.4g..%.4g s: v in %.6g m/s out %.6g m/s", impact.tStart, impact.tEnd, impact.vIn, impact.vOut);
  } else {
    gk_note(out, "no complete impact in the run");
  }
  free(vz);
}

// ---------------------------------------------------------------------------------------------------------
// A1: a regular octahedron falls vertex first (its vertex straight below the centre of mass: m_eff = m) at
// 1 m/s, gravity off, frictionless, onto a fixed cube of the same material: one vertex–face contact, a
// single Kelvin–Voigt element that ends when its force is zero, so e = eq. (15) of its damping ratio.

static void a1_scene(double e, pdGkText* out) {
  pd_gk_text_printf(out,
                    "gravity 0 0 0\ntend 0.3\nsample 200\ntol 1e-9\nvmax 1\n"
                    "cube plate grey 0.2 0.2 0.2\nfixed\nloc 0 0 -0.1\nmu 0\nrestitution %.17g\n"
                    "hull oct red 0.1 0 0  -0.1 0 0  0 0.1 0  0 -0.1 0  0 0 0.1  0 0 -0.1\n"
                    "loc 0 0 0.15\nvel 0 0 -1\nmu 0\nrestitution %.17g\n",
                    e, e);
}

static double a1_predicted(const pdModel* model) {
  int oct = gk_body(model, "oct");
  return pd_gk_restitution_of_damping(pair_zeta(model, oct, gk_body(model, "plate"), model->bodies[oct].mass));
}

static pdGkExpected a1_expect(const pdModel* model, double e) {
  (void)e;
  return (pdGkExpected){a1_predicted(model), 0.005};
}

static void a1_measure(const pdModel* model, const pdGkRecord* rec, double e, pdGkMeasured* out) {
  measure_first_impact(model, rec, "oct", out);
  pdPairContact p = pd_model_pair_contact(model, gk_body(model, "oct"), gk_body(model, "plate"));
  size_t n = strlen(out->note);
  snprintf(out->note + n, sizeof out->note - n, "; requested %g, pair e %g (%s)", e, p.restitution,
           p.restitutionSource);
}

static double a1_series(const pdModel* model, const pdGkRecord* rec, int k, double e, double* analytic) {
  (void)e;
  // the vertex is 0.05 m above the plate and falls at 1 m/s: contact from t = 0.05 s
  *analytic = rec->t[k] < 0.05 ? -1.0 : a1_predicted(model);
  return gk_series_value(rec, k, gk_moving(model, "oct"), gk_get_vz);
}

const pdGkExperiment pd_gk_a1_restitution = {
    .name = "a1_restitution",
    .group = 'A',
    .title = "Restitution of one vertex contact against eq. (15)",
    .quantity = "restitution",
    .unit = "",
    .formula = "e(zeta) = exp(-2 zeta arccos(zeta)/sqrt(1-zeta^2)), zeta = c/(2 sqrt(k m)) with the pair's series "
               "k and c (paper eq. (15); catalogue A1); equals the requested e for one contact of one material",
    .toleranceReason = "catalogue A1 [REC]: |e - e(zeta)| <= 0.005 with gravity off",
    .seriesLabel = "vertical velocity of the octahedron, m/s",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = true,
    .inputName = "e",
    .inputCount = 5,
    .inputs = {0.2, 0.3, 0.5, 0.8, 0.95},
    .scene = a1_scene,
    .expect = a1_expect,
    .measure = a1_measure,
    .series = a1_series,
};

// ---------------------------------------------------------------------------------------------------------
// A2: a 0.1 m cube lands at 1 m/s, gravity off, frictionless, on a vertex (1 contact), an edge (2) or a face
// (4), each time with the contacts straight below the centre of mass (pure translation). The catalogue's
// form: explicit per-contact constants (k_n, c_n) on both bodies, tuned for e = 0.5 at one contact with
// m_eff = m (ζ₁ = 0.2553, eq. (15)). n equal Kelvin–Voigt elements in parallel on the mass m have
// ζ_n = n c/(2√(n k m)) = √n ζ₁. (The default modal dampers would give 0.5 for every n: test_ordinary_scenes.)
#define A2_KN 2e5   // N/m per side: series 1e5 N/m, a contact period of 20 ms on the 1 kg cube
#define A2_CN 323.0 // N·s/m per side: series 161.5 = 2 · 0.2553 · √(1e5 · 1 kg), so c/k equal on both sides

static void a2_scene(double contacts, pdGkText* out) {
  const double a = 0.1, gap = 0.05;
  pdQuat q = pd_quat_identity();
  double height = 0.5 * a;  // centre above the lowest point
  if (contacts == 1.0) {
    // turn the body diagonal (−1,−1,−1) onto −z: about (1,−1,0) by arccos(1/√3)
    q = pd_quat_from_axis_angle(pd_v3(1.0, -1.0, 0.0), acos(1.0 / sqrt(3.0)));
    height = 0.5 * sqrt(3.0) * a;
  } else if (contacts == 2.0) {
    q = pd_quat_from_axis_angle(pd_v3(0.0, 1.0, 0.0), M_PI / 4.0);
    height = 0.5 * sqrt(2.0) * a;
  }
  pd_gk_text_printf(out, "gravity 0 0 0\ntend 0.3\nsample 200\ntol 1e-9\nvmax 1\n");
  char material[96];
  snprintf(material, sizeof material, "mu 0\nkn %g\ncn %g\n", A2_KN, A2_CN);
  gk_text_floor(out, 0.14, 0.14, 0.02, 0.0, material);  // mean extent 0.1 m, as the cube
  pd_gk_text_printf(out, "cube box red %g %g %g\nloc 0 0 %.17g", a, a, a, height + gap);
  gk_text_rotation(out, q);
  pd_gk_text_printf(out, "\nvel 0 0 -1\n%s", material);
}

static double a2_predicted(const pdModel* model, double contacts) {
  int box = gk_body(model, "box");
  double zeta = pair_zeta(model, box, gk_body(model, "floor"), model->bodies[box].mass);
  return pd_gk_restitution_of_damping(sqrt(contacts) * zeta);
}

static pdGkExpected a2_expect(const pdModel* model, double contacts) {
  return (pdGkExpected){a2_predicted(model, contacts), 0.01};
}

static void a2_measure(const pdModel* model, const pdGkRecord* rec, double contacts, pdGkMeasured* out) {
  measure_first_impact(model, rec, "box", out);
  size_t n = strlen(out->note);
  snprintf(out->note + n, sizeof out->note - n, "; explicit k_n, c_n tuned for 0.5 at one contact, %g in parallel", contacts);
}

static double a2_series(const pdModel* model, const pdGkRecord* rec, int k, double contacts, double* analytic) {
  *analytic = rec->t[k] < 0.05 ? -1.0 : a2_predicted(model, contacts);
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_vz);
}

const pdGkExperiment pd_gk_a2_restitution_contacts = {
    .name = "a2_restitution_contacts",
    .group = 'A',
    .title = "Restitution of a cube landing on 1, 2 or 4 contacts at once",
    .quantity = "restitution",
    .unit = "",
    .formula = "e(sqrt(n) zeta_1) with e(zeta) of eq. (15) and zeta_1 the one-contact damping ratio: n parallel "
               "contacts give zeta_n = n c/(2 sqrt(n k m)) (catalogue A2, from paper App. A)",
    .toleranceReason = "catalogue A2 [REC]: within 0.01 of the m_eff- and contact-count-corrected prediction",
    .seriesLabel = "vertical velocity of the cube, m/s",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: a rigid contact bounces with the requested e whatever the number "
                           "of contacts; e(sqrt(n) zeta_1) is the soft model's parallel spring-dampers",
    .relative = false,
    .fast = true,
    .inputName = "contacts",
    .inputCount = 3,
    .inputs = {1, 2, 4},
    .scene = a2_scene,
    .expect = a2_expect,
    .measure = a2_measure,
    .series = a2_series,
};

// ---------------------------------------------------------------------------------------------------------
// A3: a cube set down exactly on a fixed plate settles on its 4 bottom corners, each carrying m g/4 on the
// pair's series spring: the sinkage is m g/(4 k_s).

static void a3_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend 2\nsample 100\ntol 1e-9\nvmax 1\n");
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "restitution 0.5\n");
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nrestitution 0.5\n");
}

static double a3_predicted(const pdModel* model) {
  int box = gk_body(model, "box");
  pdPairContact p = pd_model_pair_contact(model, box, gk_body(model, "floor"));
  return model->bodies[box].mass * -model->settings.gravity.z / (4.0 * p.kn);
}

static pdGkExpected a3_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){a3_predicted(model), 1e-3};
}

static void a3_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  pdBodyState last = pd_gk_body(rec, rec->count - 1, j);
  out->value = 0.05 - last.x.z;
  int contacts = rec->contacts[rec->count - 1];
  if (contacts >= 0)
    gk_note(out, "lateral drift %.3g m; contacts at the end %d", hypot(last.x.x, last.x.y), contacts);
  else
    gk_note(out, "lateral drift %.3g m", hypot(last.x.x, last.x.y));
}

static double a3_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = a3_predicted(model);
  return 0.05 - gk_series_value(rec, k, gk_moving(model, "box"), gk_get_z);
}

const pdGkExperiment pd_gk_a3_sinkage = {
    .name = "a3_sinkage",
    .group = 'A',
    .title = "Static sinkage of a cube resting on 4 corners",
    .quantity = "sinkage",
    .unit = "m",
    .formula = "delta = m g/(4 k_s), k_s the pair's series normal stiffness per contact (catalogue A3)",
    .toleranceReason = "catalogue A3 [REC]: 0.1 % once settled (2 s: the dampers of e = 0.5 settle it in ~0.1 s)",
    .seriesLabel = "sinkage of the cube's centre below its initial height, m",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: a rigid contact does not sink",
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = a3_scene,
    .expect = a3_expect,
    .measure = a3_measure,
    .series = a3_series,
};

// ---------------------------------------------------------------------------------------------------------
// A4: an undamped, frictionless cube dropped flat from 0.5 m bounces back to the same apex (energy is
// conserved by the springs alone). Apex i (after bounce i + 1) may differ from the drop height by at most
// 0.1 % per bounce.

enum { A4_MIN_BOUNCES = 10, A4_MAX_APEXES = 64 };

static void a4_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend 6.5\nsample 1000\ntol 1e-9\n");
  // restitution 1: no dampers (the default is 0.5)
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "mu 0\nrestitution 1\n");
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.55\nmu 0\nrestitution 1\n");
}

static pdGkExpected a4_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){0.0, 1e-3};
}

static void a4_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  double* z = gk_column(rec, j, gk_get_z);
  double* vz = gk_column(rec, j, gk_get_vz);
  double apex[A4_MAX_APEXES];
  int count = pd_gk_apexes(z, vz, rec->count, -model->settings.gravity.z, apex, A4_MAX_APEXES);
  double h0 = z[0], worst = 0.0;
  for (int i = 0; i < count; ++i) worst = fmax(worst, fabs(apex[i] - h0) / h0 / (i + 1));
  if (count >= A4_MIN_BOUNCES) {
    out->value = worst;
    gk_note(out, "%d bounces; apex %.9g m -> %.9g m", count, h0, apex[count - 1]);
  } else {
    gk_note(out, "only %d bounces (at least %d needed)", count, A4_MIN_BOUNCES);
  }
  free(z);
  free(vz);
}

static double a4_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_z);
}

const pdGkExperiment pd_gk_a4_elastic_apex = {
    .name = "a4_elastic_apex",
    .group = 'A',
    .title = "Elastic bouncing keeps its apex (no damping, no friction)",
    .quantity = "apex_drift_per_bounce",
    .unit = "",
    .formula = "apex_i = h_0: energy conserved with c = 0 (catalogue A4); measured max |apex_i - h_0|/(h_0 i)",
    .toleranceReason = "catalogue A4 [REC]: apex drift < 0.1 % per bounce over 10 bounces",
    .seriesLabel = "height of the cube's centre, m",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: the bounce is Newton's restitution with e = 1 requested, not an "
                           "undamped spring (a centred impact's e is judged in a1_restitution)",
    .relative = false,
    .fast = false,
    .inputCount = 1,
    .scene = a4_scene,
    .expect = a4_expect,
    .measure = a4_measure,
    .series = a4_series,
};
