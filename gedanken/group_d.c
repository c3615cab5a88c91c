// polydyn gedanken — group D: rolling, pivoting and polyhedral wheels (catalogue §2 D1–D3).
#include <stdlib.h>

#include "gedanken_internal.h"

// The rotation of a prism (regular n-gon, axis z) that puts its axis along world y and one face flat on a
// slope turned `slopeDeg` about y (0: a level floor); appends " θ u v w".
static void prism_on_slope_rotation(pdGkText* out, int n, double slopeDeg) {
  // the prism's axis z onto world −y: 90° about x; its vertices then lie in the x–z plane at angles
  // 2πk/n from +x towards +z, face centres half-way between. Turning by d about y moves an angle φ to φ − d:
  // bring the face centre at π/n to the slope's downward normal, at angle −π/2 − slope.
  double slope = slopeDeg * M_PI / 180.0;
  double d = M_PI / n + M_PI / 2.0 + slope;
  pdQuat q = pd_quat_mul(pd_quat_from_axis_angle(pd_v3(0.0, 1.0, 0.0), d),
                         pd_quat_from_axis_angle(pd_v3(1.0, 0.0, 0.0), M_PI / 2.0));
  gk_text_rotation(out, q);
}

// Circumradius (largest distance of a vertex from the body z axis) and inertia about that axis over m R².
static double prism_inertia_ratio(const pdModel* model, int body, double* radius) {
  const pdBody* b = &model->bodies[body];
  double r = 0.0;
  for (int i = 0; i < b->shape.vertexCount; ++i) r = fmax(r, hypot(b->shape.vertices[i].x, b->shape.vertices[i].y));
  *radius = r;
  return b->inertia.m[2][2] / (b->mass * r * r);
}

// ---------------------------------------------------------------------------------------------------------
// D1: a 12-gon prism (R = 0.1 m) rolls down a 5° slope vertex to vertex. Each vertex impact takes a fixed
// fraction of the spin and each step gains the same potential energy, so the wheel settles to a terminal
// mean speed (a rimless wheel: McGeer 1990). The rigid prediction assumes inelastic, no-slip impacts; the
// soft contacts are made stiff (deflection 0.002) and critically damped (e = 0.14, ζ ≈ 0.97) to approach it.

#define D1_SIDES 12
#define D1_SLOPE 5.0     // degrees
#define D1_SPIN0 6.0     // rad/s at the start: close to the terminal cycle, so it settles fast
#define D1_FIT_FROM 2.0  // s
#define D1_TEND 5.0

// The catalogue's rigid prediction (reference/scripts/ngon_prism_incline.py): steady pre-impact rate from
// the energy balance, then the step time by quadrature of the pivoting motion; mean speed = step / time.
static double rimless_wheel_speed(int n, double slopeDeg, double radius, double g) {
  double a = M_PI / n, gam = slopeDeg * M_PI / 180.0;
  double kc = (2.0 + cos(2.0 * a)) / 6.0, kp = kc + 1.0;  // I_c/(m R²) of the n-gon, and about a vertex
  double rho = (kc + cos(2.0 * a)) / kp;                   // ω after / ω before a vertex impact
  double gain = 2.0 * g * radius * sin(a) * sin(gam);      // energy per step per unit mass
  double wEnd2 = 2.0 * gain / (kp * radius * radius * (1.0 - rho * rho)), wStart2 = rho * rho * wEnd2;
  double th0 = gam - a, th1 = gam + a, time = 0.0;
  enum { STEPS = 20000 };  // midpoint rule: far below the 3 % tolerance
  for (int i = 0; i < STEPS; ++i) {
    double th = th0 + (th1 - th0) * (i + 0.5) / STEPS;
    double w2 = wStart2 + 2.0 * g * (cos(th0) - cos(th)) / (kp * radius);
    time += (th1 - th0) / STEPS / sqrt(w2);
  }
  return 2.0 * radius * sin(a) / time;
}

static pdVec3 d1_downhill(void) {
  double g = D1_SLOPE * M_PI / 180.0;
  return pd_v3(cos(g), 0.0, -sin(g));
}

static void d1_scene(double input, pdGkText* out) {
  (void)input;
  const double r = 0.1, apothem = r * cos(M_PI / D1_SIDES), side = 2.0 * r * sin(M_PI / D1_SIDES);
  double g = D1_SLOPE * M_PI / 180.0;
  pdVec3 n = pd_v3(sin(g), 0.0, cos(g)), down = d1_downhill();
  // slab 6 m long centred at the origin (top face through 0.1 n); the wheel starts 2.5 m uphill
  pdVec3 c = pd_v3_add(pd_v3_scale(n, 0.1 + apothem), pd_v3_scale(down, -2.5));
  // pivoting about the front vertex of its face: v = ω ŷ × (c − pivot) = ω (apothem down + side/2 n)
  pdVec3 v = pd_v3_add(pd_v3_scale(down, D1_SPIN0 * apothem), pd_v3_scale(n, D1_SPIN0 * side / 2.0));
  pd_gk_text_printf(out,
                    "tend %g\nsample 200\ntol 1e-7\nvmax 1\ndeflection 0.002\n"
                    "cube slab grey 6 0.5 0.2\nfixed\nloc 0 0 0  %g 0 1 0\nmu 0.6\nrestitution 0.14\n"
                    "prism wheel red %d 0.2 0.2 0.1\nloc %.17g 0 %.17g",
                    D1_TEND, D1_SLOPE, D1_SIDES, c.x, c.z);
  prism_on_slope_rotation(out, D1_SIDES, D1_SLOPE);
  // ω about world +y is about the prism's own −z
  pd_gk_text_printf(out, "\nvel %.17g 0 %.17g  %.17g 0 0 -1\nmu 0.6\nrestitution 0.14\n", v.x, v.z,
                    D1_SPIN0 * 180.0 / M_PI);
}

static pdGkExpected d1_expect(const pdModel* model, double input) {
  (void)input;
  double r;
  prism_inertia_ratio(model, gk_body(model, "wheel"), &r);
  return (pdGkExpected){rimless_wheel_speed(D1_SIDES, D1_SLOPE, r, pd_v3_norm(model->settings.gravity)), 0.03};
}

static double d1_position(const pdBodyState* b) { return pd_v3_dot(b->x, d1_downhill()); }

static void d1_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  gk_measure_slope(rec, gk_moving(model, "wheel"), d1_position, D1_FIT_FROM, D1_TEND, "downhill position", out);
}

static double d1_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "wheel"), gk_get_speed);
}

const pdGkExperiment pd_gk_d1_rimless_wheel = {
    .name = "d1_rimless_wheel",
    .group = 'D',
    .title = "12-gon prism rolling down a 5 deg slope reaches a terminal speed",
    .quantity = "mean_speed",
    .unit = "m/s",
    .formula = "rigid rimless wheel: rho = (k_c + cos 2a)/(k_c + 1) per vertex impact, energy 2 g R sin a sin gamma "
               "per step, step time by quadrature; mean speed = 2 R sin a / T (catalogue D1, "
               "reference/scripts/ngon_prism_incline.py; McGeer 1990)",
    .toleranceReason = "catalogue D1 [REC]: steady mean speed within 3 %; the soft impacts are not plastic "
                       "(e >= 0.135): stiff, near-critical contacts approach the rigid value from below",
    .seriesLabel = "speed of the wheel's centre, m/s",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = d1_scene,
    .expect = d1_expect,
    .measure = d1_measure,
    .series = d1_series,
};

// ---------------------------------------------------------------------------------------------------------
// D2: a 64-gon prism (the finest the scene language has) lying on a face is launched at 1 m/s without spin
// on a level floor, μ = 0.5. Friction at the contact has no moment about the contact line, so the angular
// momentum about it is kept while it slips: m h v + I ω = m h v₀, and rolling (v = ω h, h ≈ R) starts at
// v_f = v₀/(1 + I/(m R²)), 2/3 of v₀ for a solid cylinder.

#define D2_SPEED 1.0
#define D2_SIDES 64
#define D2_ROLL_SLIP 0.01  // rolling: slip speed below 1 % of v0

static void d2_scene(double input, pdGkText* out) {
  (void)input;
  const double apothem = 0.1 * cos(M_PI / D2_SIDES);
  pd_gk_text_printf(out, "tend 0.3\nsample 1000\ntol 1e-8\nvmax 1\ndeflection 0.003\n");
  gk_text_floor(out, 2.0, 0.5, 0.2, 0.5, "mu 0.5\nrestitution 0.3\n");
  pd_gk_text_printf(out, "prism wheel red %d 0.2 0.2 0.1\nloc 0 0 %.17g", D2_SIDES, apothem);
  prism_on_slope_rotation(out, D2_SIDES, 0.0);
  pd_gk_text_printf(out, "\nvel %g 0 0\nmu 0.5\nrestitution 0.3\n", D2_SPEED);
}

static double d2_predicted(const pdModel* model) {
  double r;
  double k = prism_inertia_ratio(model, gk_body(model, "wheel"), &r);
  return D2_SPEED / (1.0 + k);
}

static pdGkExpected d2_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){d2_predicted(model), 0.03};
}

// slip of the lowest point on the floor (z = 0): v_x − ω_y h, h the centre's height
static double d2_slip(const pdBodyState* b) { return fabs(b->v.x - b->w.y * b->x.z); }

static void d2_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "wheel");
  double* slip = gk_column(rec, j, d2_slip);
  double* v = gk_column(rec, j, gk_get_vx);
  double tRoll;
  if (pd_gk_first_fall(rec->t, slip, rec->count, D2_ROLL_SLIP * D2_SPEED, &tRoll)) {
    int k = 1;
    while (rec->t[k] < tRoll) ++k;
    double f = (tRoll - rec->t[k - 1]) / (rec->t[k] - rec->t[k - 1]);
    out->value = v[k - 1] + f * (v[k] - v[k - 1]);
    gk_note(out, "rolling from %.4g s (rigid: %.4g s)", tRoll,
            D2_SPEED / (3.0 * pd_model_pair_contact(model, gk_body(model, "wheel"), gk_body(model, "floor")).mu *
                        pd_v3_norm(model->settings.gravity)));
  } else {
    gk_note(out, "never rolled without slip");
  }
  free(slip);
  free(v);
}

static double d2_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  double mu = pd_model_pair_contact(model, gk_body(model, "wheel"), gk_body(model, "floor")).mu;
  *analytic = fmax(D2_SPEED - mu * pd_v3_norm(model->settings.gravity) * rec->t[k], d2_predicted(model));
  return gk_series_value(rec, k, gk_moving(model, "wheel"), gk_get_vx);
}

const pdGkExperiment pd_gk_d2_slide_to_roll = {
    .name = "d2_slide_to_roll",
    .group = 'D',
    .title = "64-gon prism launched sliding starts to roll at v0/(1 + I/(m R^2))",
    .quantity = "rolling_speed",
    .unit = "m/s",
    .formula = "v_f = v0/(1 + I_c/(m R^2)) with the prism's own I_c and circumradius R: angular momentum about the "
               "contact line is kept while it slips (catalogue D2; 2 v0/3 for a solid cylinder)",
    .toleranceReason = "catalogue D2: 'within a few %' for N >= 40: the ~2 vertex transfers during the slip phase "
                       "lose a little angular momentum (polyhedral caveat); 3 %",
    .seriesLabel = "speed of the prism's centre, m/s",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = d2_scene,
    .expect = d2_expect,
    .measure = d2_measure,
    .series = d2_series,
};

// ---------------------------------------------------------------------------------------------------------
// D3: a cube pivoting over its bottom edge at 10 rad/s goes over, lands on its next face and settles. The
// rigid, perfectly plastic, no-slip edge impact gives ω⁺ = ω⁻/4; a soft contact is never perfectly plastic
// (e >= 0.01), and how much the landing edge bounces depends on its effective mass and on the
// old edge still touching during the landing. So the check is qualitative: it goes over, the
// landing takes most of the spin (ω⁺/ω⁻ < 1/2), and the cube settles (drift < 1e-9 m/s over the last
// second, energy never rises by more than 1e-6 E0). The measured ratio is reported.

#define D3_SETTLED_DRIFT 1e-9  // m/s (catalogue G1's drift bound)
#define D3_ENERGY_GAIN 1e-6    // of E(0) (catalogue C6)

static void d3_scene(double input, pdGkText* out) {
  (void)input;
  // rolling about its bottom edge at x = +0.05 with ω = 10 rad/s about +y (v = ω × (c − edge)): enough to
  // lift the centre of mass over the edge (needs ω > 7.8 rad/s)
  pd_gk_text_printf(out, "tend 3\nsample 2000\ntol 1e-8\nvmax 1\n");
  gk_text_floor(out, 2.0, 1.0, 0.2, 0.5, "mu 0.8\nrestitution 0.3\n");
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nvel 0.5 0 0.5  572.95779513082323 0 1 0\n"
                         "mu 0.8\nrestitution 0.3\n");
}

static pdGkExpected d3_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){NAN, 0.0};
}

// The landing: the first sample interval in which ω_y falls by more than a quarter of its value; ω⁻ just
// before, ω⁺ at the first later sample whose change per interval is back below 2 % of ω⁻.
static bool d3_ratio(const double* w, int n, double* ratio) {
  for (int k = 0; k + 1 < n; ++k) {
    if (w[k] > 0.0 && w[k] - w[k + 1] > 0.25 * w[k]) {
      for (int j = k + 1; j + 1 < n; ++j)
        if (fabs(w[j + 1] - w[j]) < 0.02 * w[k]) {
          *ratio = w[j] / w[k];
          return true;
        }
      return false;
    }
  }
  return false;
}

static void d3_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  double* w = gk_column(rec, j, gk_get_wy);
  pdVec3* x = gk_positions(rec, j);
  double ratio, drift, gain = gk_energy_gain(rec);
  bool over = x[rec->count - 1].x > 0.05;
  if (!d3_ratio(w, rec->count, &ratio)) {
    gk_note(out, "%s; no landing found", over ? "went over the edge" : "did NOT go over the edge");
  } else if (!pd_gk_drift_speed(rec->t, x, rec->count, rec->t[rec->count - 1] - 1.0, &drift) || !(gain >= 0.0)) {
    gk_note(out, "the run is too short to judge the settling");
  } else {
    out->value = ratio;
    out->pass = over && ratio < 0.5 && drift < D3_SETTLED_DRIFT && gain <= D3_ENERGY_GAIN;
    gk_note(out, "%s; w+/w- %.4g (rigid plastic: 0.25); drift over the last second %.3g m/s; energy gain %.3g",
            over ? "went over the edge" : "did NOT go over the edge", ratio, drift, gain);
  }
  free(w);
  free(x);
}

static double d3_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_wy);
}

const pdGkExperiment pd_gk_d3_tumbling_cube = {
    .name = "d3_tumbling_cube",
    .group = 'D',
    .title = "Cube tumbling over an edge lands and settles (qualitative)",
    .quantity = "omega_ratio",
    .unit = "",
    .formula = "qualitative: goes over the edge, w+/w- < 1/2, settles (drift < 1e-9 m/s, energy gain <= 1e-6 E0); "
               "rigid plastic theory gives w+/w- = 1/4 (catalogue D3), never reached by a soft contact (e > 0)",
    .toleranceReason = "catalogue G1/C6 bounds for the settled state; the ratio has no soft-contact closed form",
    .seriesLabel = "spin of the cube about y, rad/s",
    .qualitative = true,
    .kind = pd_gkLaw,
    .relative = false,
    .fast = false,
    .inputCount = 1,
    .scene = d3_scene,
    .expect = d3_expect,
    .measure = d3_measure,
    .series = d3_series,
};

// ---------------------------------------------------------------------------------------------------------
// D3, quantitative: the energy a plastic-like landing takes. The same cube tumbles over its edge with
// e = 0.01 (an overdamped soft contact, ζ 4.8: eq. (15) continued), overdamped tangential dampers and μ = 2
// (the landing edge sticks: rigid theory needs |P_t|/P_n = 0.6; the soft landing's force ratio peaks
// higher). Rigid impact theory for the landing edge — no slip, normal velocity reversed with the landing's
// e — gives the fraction of the kinetic energy taken: 15/16 (1 − e²) for a cube
// (pd_gk_cube_landing_absorbed). The model gives the landing the pair's e (its default modal dampers reach
// the requested e whatever the contact's effective mass). Measured from the total energy (kinetic +
// gravitational + springs), which nothing else changes across the landing: (E before − E after)/(E before −
// m g a/2), the kinetic energy at the instant the face reaches the floor with its centre a/2 above it.

#define D3_K 2e6   // N/m per body: the pair's springs are 1e6 N/m in series
#define D3_CT 2e4  // N·s/m per body: the pair's 1e4 gives ζ_t = 1e4/(2 √(1e6 × 1 kg)) = 5, overdamped

static void d3_landing_scene(double e, pdGkText* out) {
  // the tangential dampers overdamped too (the default is ζ_t = 1/√3): a tangential spring that gives
  // back what it stored would spin the cube up after the landing, which rigid theory's plastic landing does not
  // have (with the default dampers the soft cube leaves its landing spinning at ~1/3 of ω⁻ instead of 1/4)
  char material[160];
  snprintf(material, sizeof material, "mu 2\nrestitution %g\nkn %g\nkt %g\nct %g\n", e, D3_K, D3_K, D3_CT);
  pd_gk_text_printf(out, "tend 0.6\nsample 4000\ntol 1e-9\nvmax 1\n");
  gk_text_floor(out, 2.0, 1.0, 0.2, 0.5, material);
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nvel 0.5 0 0.5  572.95779513082323 0 1 0\n%s",
                    material);
}

static double d3_landing_restitution(const pdModel* model) {
  return pd_model_pair_contact(model, gk_body(model, "box"), gk_body(model, "floor")).restitution;
}

static pdGkExpected d3_landing_expect(const pdModel* model, double e) {
  (void)e;
  return (pdGkExpected){pd_gk_cube_landing_absorbed(d3_landing_restitution(model), NULL), 0.02};
}

// The landing: the first interval in which ω_y falls by more than a quarter (d3_ratio); `before` the last sample
// at which ω_y still grew (the cube falling over its edge speeds up until its face touches), `after` the first
// later sample from which both ω_y and the energy E change per interval by less than 2 % of ω⁻ and 1e-4 of
// the kinetic energy before: the landing's springs have given back or lost what they took (the overdamped
// contact relaxes over a few ms, its springs holding ~1 % of the energy at the end of the spin's drop).
static bool d3_landing(const double* w, const double* energy, double kinetic, int n, int* before, int* after) {
  int k = 0;
  while (k + 1 < n && !(w[k] > 0.0 && w[k] - w[k + 1] > 0.25 * w[k])) ++k;
  if (k + 1 >= n) return false;
  while (k > 0 && w[k] < w[k - 1]) --k;
  int j = k + 1;
  while (j + 1 < n && !(w[j] < w[k] && fabs(w[j + 1] - w[j]) < 0.02 * w[k] &&
                        fabs(energy[j + 1] - energy[j]) < 1e-4 * kinetic))
    ++j;
  if (j + 1 >= n) return false;
  *before = k;
  *after = j;
  return true;
}

static void d3_landing_measure(const pdModel* model, const pdGkRecord* rec, double e, pdGkMeasured* out) {
  (void)e;
  int box = gk_body(model, "box"), j = gk_moving(model, "box");
  double* w = gk_column(rec, j, gk_get_wy);
  int before, after;
  double landed = model->bodies[box].mass * pd_v3_norm(model->settings.gravity) * model->bodies[box].halfExtents.z;
  // the kinetic energy at the landing: E at the end of the pivoting, less the potential energy of the landed pose
  // (E is constant while it pivots)
  double kinetic = rec->energy[0] - landed;
  if (!(kinetic > 0.0)) {
    gk_note(out, "no kinetic energy left at the landing");
  } else if (!d3_landing(w, rec->energy, kinetic, rec->count, &before, &after)) {
    gk_note(out, "no landing found");
  } else {
    kinetic = rec->energy[before] - landed;
    double spin;
    pd_gk_cube_landing_absorbed(d3_landing_restitution(model), &spin);
    out->value = pd_gk_absorbed_fraction(rec->energy[before], rec->energy[after], kinetic);
    gk_note(out,
            "landing %.4g..%.4g s: kinetic energy before %.5g J; w/w- at its end %.4g (rigid, just after the impact: %.4g)",
            rec->t[before], rec->t[after], kinetic, w[after] / w[before], spin);
  }
  free(w);
}

static double d3_landing_series(const pdModel* model, const pdGkRecord* rec, int k, double e, double* analytic) {
  (void)e;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_wy);
}

const pdGkExperiment pd_gk_d3_landing_energy = {
    .name = "d3_landing_energy",
    .group = 'D',
    .title = "Cube tumbling over an edge: energy taken by a plastic-like landing (e = 0.01)",
    .quantity = "absorbed_fraction",
    .unit = "",
    .formula = "15/16 (1 - e^2) of the kinetic energy: rigid landing on the next edge without slip, normal velocity "
               "reversed with the landing's e (angular momentum about the landing edge; catalogue D3: w+ = w-/4 "
               "when e = 0), e the pair's (the model's modal dampers give every landing the requested e)",
    .toleranceReason = "2 % [REC]: the soft landing lasts a few ms, during which the old edge still carries load "
                       "and gravity turns the cube; measured from the total energy, which only the landing changes",
    .seriesLabel = "spin of the cube about y, rad/s",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputName = "e",
    .inputCount = 1,
    .inputs = {0.01},
    .scene = d3_landing_scene,
    .expect = d3_landing_expect,
    .measure = d3_landing_measure,
    .series = d3_landing_series,
};
