// polydyn gedanken — group E: paradoxes and indeterminacy (catalogue §2 E1, E2).
#include <stdlib.h>

#include "gedanken_internal.h"

// ---------------------------------------------------------------------------------------------------------
// E1: Painlevé's rod. A rod (1 × 0.02 × 0.02 m) leans at θ = 63.4° from the floor with its top towards −x;
// its foot slides towards +x at 1 m/s (the foot leads). Rigid theory: the normal force solves
// N [1/m + r_x (r_x + μ r_z)/I] = m g + m ω² r_z (r = foot − centre), whose coefficient is
// 1 + 3 cos θ (cos θ − μ sin θ) for a thin rod: below μ_P = 4/3 the foot decelerates under a finite N
// until the slip stops, at a time the rigid equations give; above it rigid theory has no solution and a
// compliant contact "jams": an impulsive normal force stops the slip at once ("impact without collision").
// μ = 1.0: the slip-stop time against the rigid integration; μ = 1.5: qualitative (the slip stops, finite,
// energy never rises).

#define E1_THETA 63.4         // degrees from the floor: tan θ = 2, where μ_P is smallest
#define E1_FOOT_SPEED 1.0     // m/s
#define E1_ENERGY_GAIN 1e-6   // of E(0) (catalogue C6)

static const pdVec3 e1_foot_body = {-0.01, 0.0, -0.5};  // the lower edge's midpoint, body frame

static double e1_tilt(void) { return -(90.0 - E1_THETA) * M_PI / 180.0; }  // about y: the top towards −x

static void e1_scene(double mu, pdGkText* out) {
  double b = e1_tilt();
  // the lowest corners (x = −0.01 in the body) touch the floor: z' = −x sin b + z cos b
  double centre = -(0.01 * sin(b) - 0.5 * cos(b));
  char material[64];
  snprintf(material, sizeof material, "mu %g\nrestitution 0.5\n", mu);
  pd_gk_text_printf(out, "tend 0.1\nsample 2000\ntol 1e-8\nvmax 2\ndeflection 0.0025\n");
  gk_text_floor(out, 3.0, 1.0, 0.2, 0.5, material);
  pd_gk_text_printf(out, "cube rod red 0.02 0.02 1\nloc 0 0 %.17g  %.17g 0 1 0\nvel %g 0 0\n%s", centre, b * 180.0 / M_PI,
                    E1_FOOT_SPEED, material);
}

// Rigid planar rod sliding on its foot: the coefficient of N in the foot's normal acceleration, per unit N.
static double e1_coefficient(double m, double inertia, double rx, double rz, double mu) {
  return 1.0 / m + rx * (rx + mu * rz) / inertia;
}

// Integrates the rigid equations (RK4) until the foot's slip stops; NAN when the rigid problem has no
// solution (coefficient <= 0) or the foot lifts off first.
static double e1_rigid_slip_time(double m, double inertia, pdVec3 r0, double mu, double g) {
  if (e1_coefficient(m, inertia, r0.x, r0.z, mu) <= 0.0) return NAN;
  // y = (vx, vz, ω, φ); r = R_y(φ) r0; foot slip u = vx + ω r_z
  double y[4] = {E1_FOOT_SPEED, 0.0, 0.0, 0.0}, t = 0.0;
  const double h = 1e-6;  // s: RK4 error far below the 10 % tolerance over ~2e4 steps
  for (int step = 0; step < 1000000; ++step) {
    double k[4][4], yt[4];
    bool lifted = false;
    for (int s = 0; s < 4; ++s) {
      static const double c[4] = {0.0, 0.5, 0.5, 1.0};
      for (int i = 0; i < 4; ++i) yt[i] = y[i] + (s ? c[s] * h * k[s - 1][i] : 0.0);
      double rx = r0.x * cos(yt[3]) + r0.z * sin(yt[3]), rz = -r0.x * sin(yt[3]) + r0.z * cos(yt[3]);
      double n = (g + yt[2] * yt[2] * rz) / e1_coefficient(m, inertia, rx, rz, mu);
      lifted = lifted || n <= 0.0;
      k[s][0] = -mu * n / m;
      k[s][1] = n / m - g;
      k[s][2] = -n * (mu * rz + rx) / inertia;
      k[s][3] = yt[2];
    }
    if (lifted) return NAN;
    double before[4];
    memcpy(before, y, sizeof y);
    for (int i = 0; i < 4; ++i) y[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
    double u0 = before[0] + before[2] * (-r0.x * sin(before[3]) + r0.z * cos(before[3]));
    double u1 = y[0] + y[2] * (-r0.x * sin(y[3]) + r0.z * cos(y[3]));
    if (u1 <= 0.0) return t + h * u0 / (u0 - u1);
    t += h;
  }
  return NAN;
}

static pdVec3 e1_foot_offset(const pdModel* model) {
  return pd_quat_rotate(model->bodies[gk_body(model, "rod")].q0, e1_foot_body);
}

static pdGkExpected e1_expect(const pdModel* model, double mu) {
  const pdBody* rod = &model->bodies[gk_body(model, "rod")];
  double muPair = pd_model_pair_contact(model, gk_body(model, "rod"), gk_body(model, "floor")).mu;
  (void)mu;
  // the rod turns about y only: the world inertia about y is the body's (the body is turned about y)
  double t = e1_rigid_slip_time(rod->mass, rod->inertia.m[1][1], e1_foot_offset(model), muPair,
                                pd_v3_norm(model->settings.gravity));
  return (pdGkExpected){t, 0.10};
}

static double e1_foot_slip(const pdBodyState* b) {
  pdVec3 r = pd_quat_rotate(b->q, e1_foot_body);
  return pd_v3_add(b->v, pd_v3_cross(b->w, r)).x;
}

static void e1_measure(const pdModel* model, const pdGkRecord* rec, double mu, pdGkMeasured* out) {
  (void)mu;
  int j = gk_moving(model, "rod");
  double* slip = gk_column(rec, j, e1_foot_slip);
  double* vz = gk_column(rec, j, gk_get_vz);
  double g = pd_v3_norm(model->settings.gravity), peak = 0.0, tStop, gain = gk_energy_gain(rec);
  // the normal force averaged over each sample interval, from the centre's vertical acceleration
  for (int k = 0; k + 1 < rec->count; ++k) peak = fmax(peak, ((vz[k + 1] - vz[k]) / (rec->t[k + 1] - rec->t[k]) + g) / g);
  if (pd_gk_first_fall(rec->t, slip, rec->count, 0.0, &tStop)) {
    out->value = tStop;
    out->pass = gain <= E1_ENERGY_GAIN;
    gk_note(out, "slip stopped; peak normal force %.3g m g (mean over 0.5 ms); energy gain %.3g", peak, gain);
  } else {
    gk_note(out, "the foot never stopped slipping; peak normal force %.3g m g", peak);
  }
  free(slip);
  free(vz);
}

static double e1_series(const pdModel* model, const pdGkRecord* rec, int k, double mu, double* analytic) {
  (void)mu;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "rod"), e1_foot_slip);
}

const pdGkExperiment pd_gk_e1_painleve = {
    .name = "e1_painleve",
    .group = 'E',
    .title = "Painleve's rod: slip stops under a finite force (mu 1.0) or jams (mu 1.5)",
    .quantity = "slip_time",
    .unit = "s",
    .formula = "mu < mu_P = 4/3: the slip-stop time of the rigid rod sliding on its foot, integrated from "
               "N [1/m + r_x (r_x + mu r_z)/I] = m (g + w^2 r_z) (catalogue E1); mu > mu_P: qualitative, rigid "
               "theory has no solution: the slip must stop (jam), finite, energy non-increasing",
    .toleranceReason = "10 %: the soft contact needs about one contact period (~2 ms at deflection 0.0025) to "
                       "take up the load the rigid rod feels at once; E1's qualitative check otherwise",
    .seriesLabel = "slip velocity of the rod's foot, m/s",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = true,
    .inputName = "mu",
    .inputCount = 2,
    .inputs = {1.0, 1.5},
    .scene = e1_scene,
    .expect = e1_expect,
    .measure = e1_measure,
    .series = e1_series,
};

// ---------------------------------------------------------------------------------------------------------
// E2: a statically indeterminate support. A cube on its 4 corners is pushed sideways below breakaway (the
// push: gravity tilted by α, tan α = 0.2 < μ = 0.5). Rigid theory cannot split the corner loads; the soft
// contacts give one answer: the tangential springs share the push, the normal springs carry the pitch
// moment F h, and the cube tilts by φ = F h/(k_n a² − m g_z h) (k_n per corner, a the side, h = a/2 the
// centre's height; the m g_z h term is the tilted weight's own moment).

#define E2_PUSH 0.2  // tan α: the side load over the weight

static void e2_scene(double input, pdGkText* out) {
  (void)input;
  double alpha = atan(E2_PUSH);
  pd_gk_text_printf(out, "gravity %.17g 0 %.17g\ntend 1\nsample 100\ntol 1e-9\nvmax 1\n", GK_G * sin(alpha),
                    -GK_G * cos(alpha));
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "mu 0.5\nrestitution 0.5\n");
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nmu 0.5\nrestitution 0.5\n");
}

static double e2_predicted(const pdModel* model) {
  int box = gk_body(model, "box");
  double m = model->bodies[box].mass, a = 0.1, h = 0.05;
  double kn = pd_model_pair_contact(model, box, gk_body(model, "floor")).kn;
  return h * m * model->settings.gravity.x / (kn * a * a + h * m * model->settings.gravity.z);
}

static pdGkExpected e2_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){e2_predicted(model), 0.01};
}

static double pitch(const pdBodyState* b) { return 2.0 * atan2(b->q.y, b->q.w); }

static void e2_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  pdBodyState last = pd_gk_body(rec, rec->count - 1, gk_moving(model, "box"));
  out->value = pitch(&last);
  gk_note(out, "moved %.3g m sideways; speed at the end %.3g m/s", last.x.x, pd_v3_norm(last.v));
}

static double e2_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = e2_predicted(model);
  return gk_series_value(rec, k, gk_moving(model, "box"), pitch);
}

const pdGkExperiment pd_gk_e2_side_load_pitch = {
    .name = "e2_side_load_pitch",
    .group = 'E',
    .title = "Cube on 4 corners under a side load: the unique compliant split tilts it",
    .quantity = "pitch",
    .unit = "rad",
    .formula = "phi = F h/(k_n a^2 - m g_z h): normal loads follow the pitch moment F h (catalogue E2, derived "
               "from the static balance of 4 corner springs)",
    .toleranceReason = "1 %: second-order terms in phi (~5e-4 rad) are far smaller; the dampers settle it in 0.1 s",
    .seriesLabel = "pitch of the cube about y, rad",
    .kind = pd_gkModelPrediction,
    .appliesTo = PD_GK_SOFT | PD_GK_ODE_MATCHED | PD_GK_BULLET_MATCHED,
    .notApplicableReason = "ODE and Bullet native: a rigid contact does not deflect, so it does not pitch under the "
                           "side load (the rigid split is indeterminate)",
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = e2_scene,
    .expect = e2_expect,
    .measure = e2_measure,
    .series = e2_series,
};
