// polydyn gedanken — group F: gyroscopic motion (catalogue §2 F1, F2).
#include <stdlib.h>

#include "gedanken_internal.h"

// ---------------------------------------------------------------------------------------------------------
// F1: a fast top on its tip. A 16-sided top (a cone of half-angle 32° under a 1 cm disc, 0.26 kg) stands on
// its tip vertex (one vertex–face contact, μ = 1: no slip, no drilling friction), tilted θ = 20° from the
// vertical, spinning at ω₃ about its axis. Started in steady precession, it precesses at the slow root of
// the heavy symmetric top's steady-precession equation
//   I₁' Ω² cos θ − I₃ ω₃ Ω + m g l = 0   (I₁' = I₁ + m l² about the tip, l = tip to centre of mass),
// Ω ≈ m g l/(I₃ ω₃) for a fast top.

#define F1_TILT 20.0  // degrees from the vertical
#define F1_TEND 1.0

enum { F1_RING = 16 };

static void f1_hull(pdGkText* out) {
  pd_gk_text_printf(out, "hull top red 0 0 -0.05");
  const double rings[2][2] = {{0.02, 0.05}, {0.03, 0.05}};  // z, radius
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < F1_RING; ++k) {
      double a = 2.0 * M_PI * k / F1_RING;
      pd_gk_text_printf(out, "  %.17g %.17g %g", rings[r][1] * cos(a), rings[r][1] * sin(a), rings[r][0]);
    }
  pd_gk_text_printf(out, "\n");
}

typedef struct topProperties {
  double mass, i1, i3;  // kg, kg·m² about the centre of mass (transverse, axial)
  pdVec3 tip;           // the tip vertex in the body frame (origin at the centre of mass), m
} topProperties;

static topProperties top_properties(const pdModel* model, int body) {
  const pdBody* b = &model->bodies[body];
  topProperties p = {b->mass, b->inertia.m[0][0], b->inertia.m[2][2], b->shape.vertices[0]};
  for (int i = 1; i < b->shape.vertexCount; ++i)
    if (b->shape.vertices[i].z < p.tip.z) p.tip = b->shape.vertices[i];
  return p;
}

// The slow root Ω of the steady-precession equation.
static double f1_precession(const topProperties* p, double spin, double g) {
  double th = F1_TILT * M_PI / 180.0, l = pd_v3_norm(p->tip);
  double a = (p->i1 + p->mass * l * l) * cos(th), b = p->i3 * spin, c = p->mass * g * l;
  return 2.0 * c / (b + sqrt(b * b - 4.0 * a * c));  // (b − √(b² − 4ac))/(2a) without the cancellation
}

static void f1_scene(double spin, pdGkText* out) {
  // the top's mass properties come from the model of the top alone (the scene places it by them)
  pdGkText probe = {0};
  pd_gk_text_printf(&probe, "gravity 0 0 0\n");
  f1_hull(&probe);
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer("f1_probe.scene", probe.data, probe.length, &err);
  PD_ASSERT(scene != NULL);
  pdModel* model = pd_model_compile(scene, &err);
  PD_ASSERT(model != NULL);
  topProperties p = top_properties(model, 0);
  pd_model_free(model);
  pd_scene_free(scene);
  pd_gk_text_free(&probe);

  double th = F1_TILT * M_PI / 180.0, omega = f1_precession(&p, spin, GK_G);
  pdQuat q = pd_quat_from_axis_angle(pd_v3(0.0, 1.0, 0.0), th);
  pdVec3 axis = pd_v3(sin(th), 0.0, cos(th));
  // the tip at the origin (on the floor), the centre above it along the turned body offset
  pdVec3 centre = pd_quat_rotate(q, pd_v3_scale(p.tip, -1.0));
  // ω = Ω ẑ + s â with ω·â = ω₃; the centre moves as ω × (centre − tip)
  pdVec3 w = pd_v3_add(pd_v3(0.0, 0.0, omega), pd_v3_scale(axis, spin - omega * cos(th)));
  pdVec3 v = pd_v3_cross(w, centre);
  pdQuat qc = {q.w, -q.x, -q.y, -q.z};
  pdVec3 wBody = pd_quat_rotate(qc, w);
  double rate = pd_v3_norm(wBody);
  pd_gk_text_printf(out, "tend %g\nsample 200\ntol 1e-8\nvmax 1\n", F1_TEND);
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "mu 1\nrestitution 0.5\n");
  f1_hull(out);
  pd_gk_text_printf(out, "loc %.17g %.17g %.17g  %g 0 1 0\nvel %.17g %.17g %.17g  %.17g %.17g %.17g %.17g\nmu 1\n"
                         "restitution 0.5\n",
                    centre.x, centre.y, centre.z, F1_TILT, v.x, v.y, v.z, rate * 180.0 / M_PI, wBody.x / rate,
                    wBody.y / rate, wBody.z / rate);
}

static double f1_predicted(const pdModel* model, double spin) {
  topProperties p = top_properties(model, gk_body(model, "top"));
  return f1_precession(&p, spin, pd_v3_norm(model->settings.gravity));
}

static pdGkExpected f1_expect(const pdModel* model, double spin) {
  return (pdGkExpected){f1_predicted(model, spin), 0.02};
}

// azimuth of the top's axis (body z in the world) about the vertical
static double azimuth(const pdBodyState* b) {
  pdVec3 a = pd_quat_rotate(b->q, pd_v3(0.0, 0.0, 1.0));
  return atan2(a.y, a.x);
}


static void f1_measure(const pdModel* model, const pdGkRecord* rec, double spin, pdGkMeasured* out) {
  int j = gk_moving(model, "top");
  double* phi = gk_column(rec, j, azimuth);
  double* tilt = gk_column(rec, j, gk_get_tilt_deg);
  pd_gk_unwrap(phi, rec->count);
  double rate, lo = INFINITY, hi = -INFINITY;
  for (int k = 0; k < rec->count; ++k) lo = fmin(lo, tilt[k]), hi = fmax(hi, tilt[k]);
  if (pd_gk_fit_line(rec->t, phi, rec->count, 0.0, rec->t[rec->count - 1], &rate, NULL)) {
    out->value = rate;
    topProperties p = top_properties(model, gk_body(model, "top"));
    gk_note(out, "tilt %.4g..%.4g deg; fast-top approximation m g l/(I3 w3) = %.6g rad/s", lo, hi,
            p.mass * pd_v3_norm(model->settings.gravity) * pd_v3_norm(p.tip) / (p.i3 * spin));
  } else {
    gk_note(out, "too few samples");
  }
  free(phi);
  free(tilt);
}

static double f1_series(const pdModel* model, const pdGkRecord* rec, int k, double spin, double* analytic) {
  // unwrapped azimuth: precession is slow (≈ 1 rad/s), so sample to sample it never jumps by π
  double phi = gk_series_value(rec, k, gk_moving(model, "top"), azimuth);
  double predicted = f1_predicted(model, spin) * rec->t[k];
  *analytic = predicted;
  return phi + 2.0 * M_PI * round((predicted - phi) / (2.0 * M_PI));
}

const pdGkExperiment pd_gk_f1_top_precession = {
    .name = "f1_top_precession",
    .group = 'F',
    .title = "Fast top on its tip precesses at the steady-precession rate",
    .quantity = "precession_rate",
    .unit = "rad/s",
    .formula = "slow root of I1' W^2 cos(theta) - I3 w3 W + m g l = 0 (heavy symmetric top, steady precession; "
               "W = m g l/(I3 w3) for a fast top: catalogue F1)",
    .toleranceReason = "catalogue F1 [REC]: 2 % for w3 >= 10 sqrt(m g l I1)/I3; started in steady precession, "
                       "the nutation the settling tip spring adds averages out of the fitted rate",
    .seriesLabel = "azimuth of the top's axis, rad",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputName = "spin",
    .inputCount = 2,
    .inputs = {600, 1200},
    .scene = f1_scene,
    .expect = f1_expect,
    .measure = f1_measure,
    .series = f1_series,
};

// ---------------------------------------------------------------------------------------------------------
// F2: Euler's disk. A 24-gon disc (circumradius 0.05 m, 1 cm thick) stands on its rim tilted 10° from
// upright, spinning at 25 rad/s about the vertical, on a floor with μ 0.5. It falls over rolling on its rim
// and settles flat; the catalogue has no reliable closed form with dissipation (F2: qualitative). What every
// engine must show (Moffatt 2000; Euler's disk's finite-time singularity): as the disc's angle α to the floor
// falls, the precession of its rim — the turning rate of its axis' heading — speeds up (Ω² ∝ 1/α for a
// rolling disc at small α, while the spin about its axis dies), and it ends lying flat at rest. Measured: the
// mean heading rate while α is 2..6° over the rate while α is 40..50°; the check: that ratio > 2, the disc
// flat (α < 1°) and still (speed < 1e-3 m/s) at the end. The energy gain is reported (C6 judges it).

#define F2_TILT 80.0  // degrees: axis from the vertical
#define F2_SPIN 25.0  // rad/s about the vertical
#define F2_RADIUS 0.05
#define F2_THICK 0.01
#define F2_SPEEDUP 2.0

static pdQuat f2_rotation(void) { return pd_quat_from_axis_angle(pd_v3(1.0, 0.0, 0.0), F2_TILT * M_PI / 180.0); }

static void f2_scene(double input, pdGkText* out) {
  (void)input;
  double phi = F2_TILT * M_PI / 180.0;
  // the lowest point of the rim 0.1 mm above the floor; ω about world z in the body's axes
  double z = F2_RADIUS * sin(phi) + 0.5 * F2_THICK * cos(phi) + 1e-4;
  pdQuat q = f2_rotation(), qc = {q.w, -q.x, -q.y, -q.z};
  pdVec3 axis = pd_quat_rotate(qc, pd_v3(0.0, 0.0, 1.0));
  pd_gk_text_printf(out, "tend 3\nsample 2000\ntol 1e-7\nvmax 1\n");
  gk_text_floor(out, 1.0, 1.0, 0.2, 0.0, "mu 0.5\nrestitution 0.3\n");
  pd_gk_text_printf(out, "prism disc red 24 %g %g %g\nloc 0 0 %.17g", 2.0 * F2_RADIUS, 2.0 * F2_RADIUS, F2_THICK, z);
  gk_text_rotation(out, q);
  pd_gk_text_printf(out, "\nvel 0 0 0  %.17g %.17g %.17g %.17g\nmu 0.5\nrestitution 0.3\n", F2_SPIN * 180.0 / M_PI,
                    axis.x, axis.y, axis.z);
}

static pdGkExpected f2_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){NAN, 0.0};
}

// the disc's angle to the floor (its axis from the vertical, folded to 0..90°), and its axis' heading
static double f2_floor_angle(const pdBodyState* b) {
  double t = gk_get_tilt_deg(b);
  return t > 90.0 ? 180.0 - t : t;
}
static double f2_heading(const pdBodyState* b) {
  pdVec3 a = pd_quat_rotate(b->q, pd_v3(0.0, 0.0, 1.0));
  return atan2(a.y, a.x);
}

static void f2_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "disc");
  double* angle = gk_column(rec, j, f2_floor_angle);
  double* heading = gk_column(rec, j, f2_heading);
  pd_gk_unwrap(heading, rec->count);
  double early, late;
  pdBodyState last = pd_gk_body(rec, rec->count - 1, j);
  double speed = pd_v3_norm(last.v), finalAngle = angle[rec->count - 1], gain = gk_energy_gain(rec);
  bool flat = finalAngle < 1.0 && speed < 1e-3;
  if (!pd_gk_mean_rate_in_band(rec->t, heading, angle, rec->count, 40.0, 50.0, &early) ||
      !pd_gk_mean_rate_in_band(rec->t, heading, angle, rec->count, 2.0, 6.0, &late) || early == 0.0) {
    gk_note(out, "the disc never rolled through 40..50 deg and 2..6 deg to the floor; at the end %.3g deg, %.3g m/s",
            finalAngle, speed);
  } else {
    out->value = fabs(late / early);
    out->pass = out->value > F2_SPEEDUP && flat;
    gk_note(out, "heading rate %.4g rad/s at 40..50 deg, %.4g rad/s at 2..6 deg; at the end %.3g deg to the floor, "
            "%.3g m/s; energy gain %.3g E0", early, late, finalAngle, speed, gain);
  }
  free(angle);
  free(heading);
}

static double f2_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "disc"), f2_floor_angle);
}

const pdGkExperiment pd_gk_f2_euler_disk = {
    .name = "f2_euler_disk",
    .group = 'F',
    .title = "Euler's disk: the precession speeds up as the disc falls flat (qualitative)",
    .quantity = "precession_speedup",
    .unit = "",
    .formula = "qualitative: the heading rate of the disc's axis at 2..6 deg to the floor is more than twice that at "
               "40..50 deg (Euler's disk's finite-time singularity; catalogue F2: no closed form with "
               "dissipation), and the disc ends flat (< 1 deg) and still (< 1e-3 m/s)",
    .toleranceReason = "a factor 2: a rolling disc's precession grows as 1/sqrt(angle), about 3x between the two bands",
    .seriesLabel = "angle of the disc to the floor, deg",
    .kind = pd_gkLaw,
    .qualitative = true,
    .relative = false,
    .fast = false,
    .inputCount = 1,
    .scene = f2_scene,
    .expect = f2_expect,
    .measure = f2_measure,
    .series = f2_series,
};
