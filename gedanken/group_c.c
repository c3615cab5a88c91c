// polydyn gedanken — group C: impacts (catalogue §2 C1–C6).
#include <stdlib.h>

#include "gedanken_internal.h"

// ---------------------------------------------------------------------------------------------------------
// C1: a 0.1 m cube (restitution 0.5) dropped flat from 0.5 m above the floor bounces on its 4 corners at
// once: each bounce returns e² of the height above the contact-onset height. With the default modal
// dampers (material.h) the 4 corners together reach the pair's e; with explicit per-contact dampers it
// would be e(2ζ₁) (A2). The first bounce is measured (3.1 m/s): later, slower bounces feel gravity during
// the contact (catalogue C1 pitfall), which lowers e.

#define C1_DROP 0.5  // m above the contact-onset height

static void c1_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend 0.9\nsample 2000\ntol 1e-9\nvmax 3.2\n");
  gk_text_floor(out, 0.14, 0.14, 0.02, 0.0, "mu 0\nrestitution 0.5\n");  // mean extent 0.1 m, as the cube
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 %g\nmu 0\nrestitution 0.5\n", 0.05 + C1_DROP);
}

static pdGkExpected c1_expect(const pdModel* model, double input) {
  (void)input;
  int box = gk_body(model, "box");
  pdPairContact p = pd_model_pair_contact(model, box, gk_body(model, "floor"));
  if (p.modalN) return (pdGkExpected){p.restitution, 0.01};
  double zeta = p.cn / (2.0 * sqrt(p.kn * model->bodies[box].mass));
  return (pdGkExpected){pd_gk_restitution_of_damping(2.0 * zeta), 0.01};
}

enum { C1_APEXES = 3 };

static void c1_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  double* z = gk_column(rec, j, gk_get_z);
  double* vz = gk_column(rec, j, gk_get_vz);
  double apex[C1_APEXES];
  int count = pd_gk_apexes(z, vz, rec->count, -model->settings.gravity.z, apex, C1_APEXES);
  double onset = 0.05;
  if (count >= 1) {
    out->value = sqrt((apex[0] - onset) / C1_DROP);
    size_t used = (size_t)snprintf(out->note, sizeof out->note, "bounce heights above the onset height, m:");
    for (int i = 0; i < count && used < sizeof out->note; ++i)
      used += (size_t)snprintf(out->note + used, sizeof out->note - used, " %.5g", apex[i] - onset);
  } else {
    gk_note(out, "no bounce");
  }
  free(z);
  free(vz);
}

static double c1_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_z);
}

const pdGkExperiment pd_gk_c1_bounce_apex = {
    .name = "c1_bounce_apex",
    .group = 'C',
    .title = "Cube bouncing flat under gravity: restitution from the first apex",
    .quantity = "restitution",
    .unit = "",
    .formula = "sqrt(h1/h0) = the pair's e: the default modal dampers give the 4 corner contacts together the "
               "requested e (with explicit per-contact dampers: e(2 zeta_1), catalogue C1 with A2's correction); "
               "heights above the contact-onset height",
    .toleranceReason = "catalogue C1 [REC]: within 1 % of the m_eff-corrected prediction; gravity during the "
                       "~1 ms contact lowers e by ~g t_c/v = 0.3 % at 3.1 m/s",
    .seriesLabel = "height of the cube's centre, m",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = c1_scene,
    .expect = c1_expect,
    .measure = c1_measure,
    .series = c1_series,
};

// ---------------------------------------------------------------------------------------------------------
// C2: two equal cubes meet head on at ±1 m/s, one turned 45° about the line of impact and both slightly off
// it (generic features, no coincident ones), gravity off, frictionless. Contact forces are equal and
// opposite: total momentum stays at its start value to round-off.

static void c2_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out,
                    "gravity 0 0 0\ntend 0.5\nsample 100\ntol 1e-9\nvmax 2\n"
                    "cube a red 0.1 0.1 0.1\nloc -0.2 0 0\nvel 1 0 0\nmu 0\nrestitution 0.5\n"
                    "cube b blue 0.1 0.1 0.1\nloc 0.2 0.01 0.005  45 1 0 0\nvel -1 0 0\nmu 0\nrestitution 0.5\n");
}

static pdGkExpected c2_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){0.0, 1e-9};
}

// |p(k) − p(0)| / (m |v_a(0)|)
static double momentum_error(const pdModel* model, const pdGkRecord* rec, int k) {
  pdVec3 p0 = {0}, p = {0};
  for (int j = 0; j < rec->bodies; ++j) {
    double m = model->bodies[model->movingBodies[j]].mass;
    p0 = pd_v3_muladd(p0, m, pd_gk_body(rec, 0, j).v);
    p = pd_v3_muladd(p, m, pd_gk_body(rec, k, j).v);
  }
  double scale = model->bodies[model->movingBodies[0]].mass * pd_v3_norm(pd_gk_body(rec, 0, 0).v);
  return pd_v3_norm(pd_v3_sub(p, p0)) / scale;
}

static void c2_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int last = rec->count - 1;
  double va = pd_gk_body(rec, last, gk_moving(model, "a")).v.x, vb = pd_gk_body(rec, last, gk_moving(model, "b")).v.x;
  if (va > 0.5) {  // they never met
    gk_note(out, "no collision (a still at %.3g m/s)", va);
    return;
  }
  out->value = momentum_error(model, rec, last);
  gk_note(out, "after: va %.6g vb %.6g m/s", va, vb);
}

static double c2_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = 0.0;
  return momentum_error(model, rec, k);
}

const pdGkExperiment pd_gk_c2_momentum = {
    .name = "c2_momentum",
    .group = 'C',
    .title = "Head-on collision of two equal cubes: momentum",
    .quantity = "momentum_error",
    .unit = "",
    .formula = "0: contact forces are equal and opposite (catalogue C2); measured |p_end - p_0|/(m v0)",
    .toleranceReason = "catalogue C2: round-off level; 1e-9 of one cube's momentum",
    .seriesLabel = "momentum error relative to m v0",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = true,
    .inputCount = 1,
    .scene = c2_scene,
    .expect = c2_expect,
    .measure = c2_measure,
    .series = c2_series,
};

// ---------------------------------------------------------------------------------------------------------
// C3: a slender bar (1 × 0.02 × 0.02 m, 1 kg) falls flat at 2 m/s onto the apex of a fixed tetrahedron
// under one end (lever arm r = 0.49 m), gravity off, frictionless, both sides k = 1e6 N/m, c = 350 N·s/m.
// One contact with effective mass m_eff = 1/(1/m + r²/I): a Kelvin–Voigt element of ζ_eff =
// c_s/(2√(k_s m_eff)), e_eff = e(ζ_eff), impulse P = (1 + e_eff) m_eff v, so ω' = P r/I.

#define C3_ARM 0.49   // m: the apex 1 cm inside the bar's end
#define C3_SPEED 2.0  // m/s

static void c3_scene(double input, pdGkText* out) {
  (void)input;
  const double r = C3_ARM;
  // loc of the tetrahedron: its centroid, the mean of its vertices; the apex ends up at (r, 0, 0)
  pd_gk_text_printf(out,
                    "gravity 0 0 0\ntend 0.1\nsample 1000\ntol 1e-10\nvmax 2\n"
                    "hull pin grey %g -0.05 -0.1  %g 0.05 -0.1  %g 0 -0.1  %g 0 0\nfixed\nloc %g 0 -0.075\nmu 0\n"
                    "kn 1e6\ncn 350\n"
                    "cube bar red 1 0.02 0.02\nloc 0 0 0.02\nvel 0 0 -%g\nspgrav 2.5\nmu 0\nkn 1e6\ncn 350\n",
                    r - 0.05, r - 0.05, r + 0.05, r, r - 0.0125, C3_SPEED);
}

static double c3_predicted(const pdModel* model, double* eEff) {
  int bar = gk_body(model, "bar");
  const pdBody* b = &model->bodies[bar];
  double inertia = b->inertia.m[1][1];  // about y: the axis the impact turns the bar about
  double meff = gk_effective_mass(model, bar, pd_v3(C3_ARM, 0.0, 0.01), pd_v3(0.0, 0.0, 1.0));
  pdPairContact p = pd_model_pair_contact(model, gk_body(model, "pin"), bar);
  double e = pd_gk_restitution_of_damping(p.cn / (2.0 * sqrt(p.kn * meff)));
  if (eEff) *eEff = e;
  return (1.0 + e) * meff * C3_SPEED * C3_ARM / inertia;
}

static pdGkExpected c3_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){c3_predicted(model, NULL), 0.01};
}

// ω' turns the bar's far end down: r × P ẑ = −r P ŷ for the impact at +x from below
static double bar_spin(const pdBodyState* b) { return -b->w.y; }

static void c3_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  pdBodyState last = pd_gk_body(rec, rec->count - 1, gk_moving(model, "bar"));
  if (!(last.v.z > -C3_SPEED + 1e-3)) {
    gk_note(out, "no impact");
    return;
  }
  double e;
  c3_predicted(model, &e);
  out->value = bar_spin(&last);
  gk_note(out, "v_cm after %.6g m/s; e_eff %.5g", last.v.z, e);
}

static double c3_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  // the bar's underside is 0.01 m above the apex: contact from t = 0.005 s
  *analytic = rec->t[k] < 0.01 / C3_SPEED ? 0.0 : c3_predicted(model, NULL);
  return gk_series_value(rec, k, gk_moving(model, "bar"), bar_spin);
}

const pdGkExperiment pd_gk_c3_eccentric_bar = {
    .name = "c3_eccentric_bar",
    .group = 'C',
    .title = "Bar hit at one end: spin after the impact from the effective mass",
    .quantity = "angular_velocity",
    .unit = "rad/s",
    .formula = "w' = (1 + e_eff) m_eff v r/I, 1/m_eff = 1/m + r^2/I, e_eff = e(c/(2 sqrt(k m_eff))) "
               "(paper App. A eqs. (19)-(20) and eq. (15); catalogue C3)",
    .toleranceReason = "catalogue C3 [REC]: 1 % for a stiff contact",
    .seriesLabel = "spin of the bar about -y, rad/s",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: a rigid impact applies the requested e at any effective mass; "
                           "e_eff(m_eff) is the soft model's",
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = c3_scene,
    .expect = c3_expect,
    .measure = c3_measure,
    .series = c3_series,
};

// ---------------------------------------------------------------------------------------------------------
// C4: a cube at 1 m/s hits an equal cube at rest, turned 45° about the line of impact (8 edge–edge
// contacts, symmetric: no rotation), gravity off, frictionless, no dampers: an elastic two-body collision
// in one dimension exchanges the velocities.

static void c4_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out,
                    "gravity 0 0 0\ntend 0.4\nsample 100\ntol 1e-9\nvmax 1\n"
                    "cube a red 0.1 0.1 0.1\nloc -0.2 0 0\nvel 1 0 0\nmu 0\nrestitution 1\n"
                    "cube b blue 0.1 0.1 0.1\nloc 0 0 0  45 1 0 0\nmu 0\nrestitution 1\n");
}

static pdGkExpected c4_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){1.0, 1e-3};
}

static double transferred(const pdBodyState* b) { return b->v.x; }  // of the 1 m/s launch speed

static void c4_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int last = rec->count - 1;
  pdBodyState a = pd_gk_body(rec, last, gk_moving(model, "a")), b = pd_gk_body(rec, last, gk_moving(model, "b"));
  out->value = transferred(&b);
  gk_note(out, "a keeps %.3g m/s; spin of b %.3g rad/s", a.v.x, pd_v3_norm(b.w));
}

static double c4_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  // a's face reaches b's at t = 0.1 s
  *analytic = rec->t[k] < 0.1 ? 0.0 : 1.0;
  return gk_series_value(rec, k, gk_moving(model, "b"), transferred);
}

const pdGkExperiment pd_gk_c4_velocity_exchange = {
    .name = "c4_velocity_exchange",
    .group = 'C',
    .title = "Elastic collision of equal cubes exchanges their velocities",
    .quantity = "velocity_ratio",
    .unit = "",
    .formula = "v_b'/v0 = 1: equal masses, e = 1, one dimension (catalogue C4)",
    .toleranceReason = "1e-3: energy is conserved to the integration tolerance over the ~20 ms contact",
    .seriesLabel = "velocity of the struck cube over the launch speed",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = true,
    .inputCount = 1,
    .scene = c4_scene,
    .expect = c4_expect,
    .measure = c4_measure,
    .series = c4_series,
};

// ---------------------------------------------------------------------------------------------------------
// C6: a bar (0.4 × 0.05 × 0.05 m) tilted 30° strikes a rough floor moving sideways and spinning, for several
// μ. A passive spring–damper–Coulomb contact cannot create energy (Stronge 1991: Newton's kinematic
// restitution can): the energy, springs included, never rises above an earlier value.

static void c6_scene(double mu, pdGkText* out) {
  const double tilt = 30.0 * M_PI / 180.0;
  double lowest = 0.2 * sin(tilt) + 0.025 * cos(tilt);  // centre above the lowest corner
  pd_gk_text_printf(out, "tend 1\nsample 1000\ntol 1e-8\nvmax 3\n");
  char material[64];
  snprintf(material, sizeof material, "mu %g\nrestitution 0.5\n", mu);
  gk_text_floor(out, 2.0, 2.0, 0.2, 0.3, material);
  pd_gk_text_printf(out, "cube bar red 0.4 0.05 0.05\nloc 0 0 %.17g  30 0 1 0\nvel 1 0 -2  300 0 1 0\n%s",
                    lowest + 0.05, material);
}

static pdGkExpected c6_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){0.0, 1e-6};
}

static void c6_measure(const pdModel* model, const pdGkRecord* rec, double mu, pdGkMeasured* out) {
  (void)model, (void)mu;
  out->value = gk_energy_gain(rec);
  gk_note(out, "energy %.6g J -> %.6g J", rec->energy[0], rec->energy[rec->count - 1]);
}

static double c6_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)model, (void)input;
  *analytic = NAN;
  return rec->energy[k] / rec->energy[0];
}

const pdGkExperiment pd_gk_c6_energy_gain = {
    .name = "c6_energy_gain",
    .group = 'C',
    .title = "No energy gain in a frictional impact (Kane-type test)",
    .quantity = "energy_gain",
    .unit = "",
    .formula = "0: a passive spring-damper-Coulomb contact cannot create energy (catalogue C6; Stronge 1991); "
               "measured: largest rise of E (kinetic + gravitational + springs) over E(0)",
    .toleranceReason = "catalogue C6: violations < 1e-6 E0 (integration error only)",
    .seriesLabel = "energy over its initial value",
    .kind = pd_gkLaw,
    .relative = false,
    .fast = false,
    .inputName = "mu",
    .inputCount = 3,
    .inputs = {0.2, 0.5, 1.0},
    .scene = c6_scene,
    .expect = c6_expect,
    .measure = c6_measure,
    .series = c6_series,
};

// ---------------------------------------------------------------------------------------------------------
// C5: oblique impact (the DEM benchmark family of Chung & Ooi 2011, catalogue C5) in gross slip. A regular
// octahedron (vertex 0.1 m from its centre, m_eff = m along the normal) hits a fixed plate vertex first at
// 1 m/s down and v_t across, gravity off, μ = 0.3, e = 0.5. While the vertex slides, Coulomb's law holds the
// tangential force at μ times the normal force, so the impulses are in that ratio: |Δv_t| = μ |Δv_n| for the
// centre of mass, whatever the contact's stiffness, damping or duration. The vertex keeps sliding when
// v_t > μ (1 + e) v_n (1 + m r²/I) = 2.7 v_n (I = m r²/5): inputs v_t/v_n = 4 and 8. At lower v_t the
// tangential spring would stop the slip and rebound (the tangential restitution of Schwager & Pöschel 2008):
// a prediction of the model, not tested here.

#define C5_MU 0.3
#define C5_IMPACT_THRESHOLD 1e-6  // m/s: gravity off, so free flight keeps its velocity to round-off

static void c5_scene(double ratio, pdGkText* out) {
  pd_gk_text_printf(out,
                    "gravity 0 0 0\ntend 0.2\nsample 2000\ntol 1e-9\nvmax %.17g\n"
                    "cube plate grey 1 0.3 0.2\nfixed\nloc 0.3 0 -0.1\nmu %g\nrestitution 0.5\n"
                    "hull oct red 0.1 0 0  -0.1 0 0  0 0.1 0  0 -0.1 0  0 0 0.1  0 0 -0.1\n"
                    "loc 0 0 0.12\nvel %.17g 0 -1\nmu %g\nrestitution 0.5\n",
                    hypot(ratio, 1.0), C5_MU, ratio, C5_MU);
}

static pdGkExpected c5_expect(const pdModel* model, double ratio) {
  (void)ratio;
  return (pdGkExpected){pd_model_pair_contact(model, gk_body(model, "oct"), gk_body(model, "plate")).mu, 0.01};
}

static void c5_measure(const pdModel* model, const pdGkRecord* rec, double ratio, pdGkMeasured* out) {
  (void)ratio;
  int j = gk_moving(model, "oct");
  double* vz = gk_column(rec, j, gk_get_vz);
  double* vx = gk_column(rec, j, gk_get_vx);
  pdGkImpact impact;
  if (pd_gk_first_impact(rec->t, vz, rec->count, 0.0, C5_IMPACT_THRESHOLD, 3, &impact)) {
    double dvx = vx[rec->count - 1] - vx[0];
    out->value = pd_gk_impulse_ratio(vx[0], vx[rec->count - 1], impact.vIn, impact.vOut);
    pdBodyState last = pd_gk_body(rec, rec->count - 1, j);
    gk_note(out, "impact %.4g..%.4g s: dv_t %.6g m/s, dv_n %.6g m/s (e %.4g); spin after %.4g rad/s", impact.tStart,
            impact.tEnd, dvx, impact.vOut - impact.vIn, impact.restitution, pd_v3_norm(last.w));
  } else {
    gk_note(out, "no complete impact in the run");
  }
  free(vz);
  free(vx);
}

// v_t against the Coulomb line v_t0 − μ (v_n − v_n0) drawn through the measured normal velocity
static double c5_series(const pdModel* model, const pdGkRecord* rec, int k, double ratio, double* analytic) {
  (void)ratio;
  int j = gk_moving(model, "oct");
  pdBodyState b0 = pd_gk_body(rec, 0, j), b = pd_gk_body(rec, k, j);
  *analytic = b0.v.x - c5_expect(model, ratio).value * (b.v.z - b0.v.z);
  return b.v.x;
}

const pdGkExperiment pd_gk_c5_oblique_impact = {
    .name = "c5_oblique_impact",
    .group = 'C',
    .title = "Oblique vertex impact in gross slip: tangential impulse = mu x normal impulse",
    .quantity = "impulse_ratio",
    .unit = "",
    .formula = "|dv_t|/|dv_n| = mu (Coulomb's law through a sliding impact; catalogue C5, the oblique-impact "
               "benchmarks of Chung & Ooi 2011), measured on the centre of mass over the first impact",
    .toleranceReason = "1 % [REC]: exact for a contact that slides throughout; an engine whose friction is "
                       "regularised or whose slip stops during the impact falls short of mu",
    .seriesLabel = "tangential velocity of the octahedron, m/s (analytic: the Coulomb line through the measured "
                   "normal velocity)",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputName = "vt_over_vn",
    .inputCount = 2,
    .inputs = {4.0, 8.0},
    .scene = c5_scene,
    .expect = c5_expect,
    .measure = c5_measure,
    .series = c5_series,
};
