// polydyn gedanken — group B: friction (catalogue §2 B1, B2, B4, B6, and the friction cone of DESIGN §5).
#include <stdlib.h>

#include "gedanken_internal.h"

// A body has stopped when its speed first falls below this fraction of its launch speed (0.1 % of the
// stop time early for a constant deceleration): the tangential springs then take over and ring down.
#define STOP_SPEED_FRACTION 1e-3

static double pair_mu(const pdModel* model, const char* a, const char* b) {
  return pd_model_pair_contact(model, gk_body(model, a), gk_body(model, b)).mu;
}

static double gravity(const pdModel* model) { return pd_v3_norm(model->settings.gravity); }

// ---------------------------------------------------------------------------------------------------------
// B1: a 0.1 m cube released at rest on a fixed slab tilted θ about y, μ = 0.5 on both. Above the friction
// angle (35°) it slides with a = g (sin θ − μ cos θ); below it (20°) it stays.

static void incline_scene(double thetaDeg, double tend, pdGkText* out) {
  double th = thetaDeg * M_PI / 180.0;
  // slab centred at the origin, 0.2 m thick: its top face passes through 0.1 n, n = (sin θ, 0, cos θ)
  double cx = 0.15 * sin(th), cz = 0.15 * cos(th);
  pd_gk_text_printf(out,
                    "tend %g\nsample 100\ntol 1e-9\nvmax 1\n"
                    "cube slab grey 2 1 0.2\nfixed\nloc 0 0 0  %.17g 0 1 0\nmu 0.5\nrestitution 0.5\n"
                    "cube box red 0.1 0.1 0.1\nloc %.17g 0 %.17g  %.17g 0 1 0\nmu 0.5\nrestitution 0.5\n",
                    tend, thetaDeg, cx, cz, thetaDeg);
}

static pdVec3 downhill(double thetaDeg) {
  double th = thetaDeg * M_PI / 180.0;
  return pd_v3(cos(th), 0.0, -sin(th));  // the slab's x axis turned by θ about y
}

#define SLIDE_DEG 35.0
#define STICK_DEG 20.0
#define SLIDE_FIT_FROM 0.3  // s: the landing transients of the released block are long gone
#define SLIDE_FIT_TO 1.0

static void b1_slide_scene(double input, pdGkText* out) {
  (void)input;
  incline_scene(SLIDE_DEG, SLIDE_FIT_TO, out);
}

static double b1_slide_predicted(const pdModel* model) {
  double th = SLIDE_DEG * M_PI / 180.0;
  return gravity(model) * (sin(th) - pair_mu(model, "box", "slab") * cos(th));
}

static pdGkExpected b1_slide_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){b1_slide_predicted(model), 0.005};
}

static double downhill_speed(const pdBodyState* b) { return pd_v3_dot(b->v, downhill(SLIDE_DEG)); }

static void b1_slide_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  gk_measure_slope(rec, gk_moving(model, "box"), downhill_speed, SLIDE_FIT_FROM, SLIDE_FIT_TO, "downhill speed", out);
}

static double b1_slide_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = b1_slide_predicted(model) * rec->t[k];
  return gk_series_value(rec, k, gk_moving(model, "box"), downhill_speed);
}

const pdGkExperiment pd_gk_b1_incline_slide = {
    .name = "b1_incline_slide",
    .group = 'B',
    .title = "Block sliding down a 35 deg incline, mu 0.5",
    .quantity = "acceleration",
    .unit = "m/s^2",
    .formula = "a = g (sin theta - mu cos theta), mu the pair's sqrt(mu1 mu2) (catalogue B1, textbook)",
    .toleranceReason = "catalogue B1 [REC]: 0.5 %; the line is fitted over 0.3..1 s, after the release transients",
    .seriesLabel = "downhill speed of the block, m/s",
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = b1_slide_scene,
    .expect = b1_slide_expect,
    .measure = b1_slide_measure,
    .series = b1_slide_series,
};

#define STICK_FROM 1.0  // s: creep is measured once the release transients have settled
#define STICK_TEND 5.0

static void b1_stick_scene(double input, pdGkText* out) {
  (void)input;
  incline_scene(STICK_DEG, STICK_TEND, out);
}

static pdGkExpected b1_stick_expect(const pdModel* model, double input) {
  (void)model, (void)input;
  return (pdGkExpected){0.0, 1e-7};
}

static void b1_stick_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  pdVec3* x = gk_positions(rec, j);
  double creep;
  if (pd_gk_drift_speed(rec->t, x, rec->count, STICK_FROM, &creep)) {
    out->value = creep;
    double moved = pd_v3_dot(pd_v3_sub(x[rec->count - 1], x[0]), downhill(STICK_DEG));
    gk_note(out, "moved %.3g m downhill in all; creep over %g..%g s", moved, STICK_FROM, rec->t[rec->count - 1]);
  } else {
    gk_note(out, "the run ended before %g s", STICK_FROM);
  }
  free(x);
}

static double stick_displacement(const pdBodyState* b) {
  double th = STICK_DEG * M_PI / 180.0;
  pdVec3 start = pd_v3(0.15 * sin(th), 0.0, 0.15 * cos(th));
  return pd_v3_dot(pd_v3_sub(b->x, start), downhill(STICK_DEG));
}

static double b1_stick_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "box"), stick_displacement);
}

const pdGkExperiment pd_gk_b1_incline_stick = {
    .name = "b1_incline_stick",
    .group = 'B',
    .title = "Block at rest on a 20 deg incline, mu 0.5: no creep",
    .quantity = "creep_speed",
    .unit = "m/s",
    .formula = "0: sticks while tan(theta) <= mu (catalogue B1); the tangential springs hold it without creep",
    .toleranceReason = "catalogue B1 [REC]: drift < 1e-7 m/s, measured as displacement over 1..5 s / 4 s",
    .seriesLabel = "downhill displacement of the block from its release point, m",
    .relative = false,
    .fast = false,
    .inputCount = 1,
    .scene = b1_stick_scene,
    .expect = b1_stick_expect,
    .measure = b1_stick_measure,
    .series = b1_stick_series,
};

// ---------------------------------------------------------------------------------------------------------
// B2: a 0.1 m cube launched along a level plate with no spin slides to rest after d = v²/(2μg) and
// t = v/(μg). The block also moves on by the tangential springs' static deflection while they load at the
// stop (μ m g/(4 k_t,s) at most), which the distance's tolerance allows for.

#define SLIDE_MU 0.4

static void slide_scene(double v0, double pushDeg, double tend, double sample, pdGkText* out) {
  double phi = pushDeg * M_PI / 180.0;
  pd_gk_text_printf(out, "tend %g\nsample %g\ntol 1e-9\nvmax %g\n", tend, sample, v0);
  gk_text_floor(out, 2.0, 2.0, 0.2, 0.0, "mu 0.4\nrestitution 0.5\n");
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nvel %.17g %.17g 0\nmu %g\nrestitution 0.5\n",
                    v0 * cos(phi), v0 * sin(phi), SLIDE_MU);
}

static double slide_distance(const pdModel* model) {
  double v0 = pd_v3_norm(model->bodies[gk_body(model, "box")].v0);
  return v0 * v0 / (2.0 * pair_mu(model, "box", "floor") * gravity(model));
}

// 0.5 % of the distance (catalogue B2) + the largest static deflection of the 4 tangential springs
static pdGkExpected slide_distance_expect(const pdModel* model, double input) {
  (void)input;
  int box = gk_body(model, "box");
  pdPairContact p = pd_model_pair_contact(model, box, gk_body(model, "floor"));
  double d = slide_distance(model);
  double deflection = p.mu * model->bodies[box].mass * gravity(model) / (4.0 * p.kt);
  return (pdGkExpected){d, 0.005 * d + deflection};
}

static void slide_distance_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  int j = gk_moving(model, "box");
  pdBodyState first = pd_gk_body(rec, 0, j), last = pd_gk_body(rec, rec->count - 1, j);
  pdVec3 moved = pd_v3_sub(last.x, first.x);
  double speed = pd_v3_norm(last.v), v0 = pd_v3_norm(first.v);
  if (speed > STOP_SPEED_FRACTION * v0) {
    gk_note(out, "still moving at the end (%.3g m/s)", speed);
    return;
  }
  out->value = hypot(moved.x, moved.y);
  // the direction it went against the push (friction-cone isotropy: 0)
  double turn = (atan2(moved.y, moved.x) - atan2(first.v.y, first.v.x)) * 180.0 / M_PI;
  gk_note(out, "final speed %.3g m/s; direction %.4g deg off the push", speed, turn);
}

static double travelled(const pdBodyState* b) { return hypot(b->x.x, b->x.y); }

static double slide_distance_series(const pdModel* model, const pdGkRecord* rec, int k, double input,
                                    double* analytic) {
  (void)input;
  double v0 = pd_v3_norm(model->bodies[gk_body(model, "box")].v0);
  double a = pair_mu(model, "box", "floor") * gravity(model);
  double t = fmin(rec->t[k], v0 / a);
  *analytic = v0 * t - 0.5 * a * t * t;
  return gk_series_value(rec, k, gk_moving(model, "box"), travelled);
}

static void b2_scene(double input, pdGkText* out) {
  (void)input;
  slide_scene(2.0, 0.0, 1.0, 1000.0, out);
}

const pdGkExperiment pd_gk_b2_stopping_distance = {
    .name = "b2_stopping_distance",
    .group = 'B',
    .title = "Block sliding to rest from 2 m/s, mu 0.4: distance",
    .quantity = "stopping_distance",
    .unit = "m",
    .formula = "d = v0^2/(2 mu g) (catalogue B2)",
    .toleranceReason = "catalogue B2 [REC]: 0.5 % of d plus the tangential springs' static deflection mu m g/(4 k_t,s)",
    .seriesLabel = "distance travelled, m",
    .relative = false,
    .fast = true,
    .inputCount = 1,
    .scene = b2_scene,
    .expect = slide_distance_expect,
    .measure = slide_distance_measure,
    .series = slide_distance_series,
};

static double b2_stop_predicted(const pdModel* model) {
  double v0 = pd_v3_norm(model->bodies[gk_body(model, "box")].v0);
  return v0 / (pair_mu(model, "box", "floor") * gravity(model));
}

static pdGkExpected b2_stop_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){b2_stop_predicted(model), 0.01};
}

static void b2_stop_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  double* speed = gk_column(rec, gk_moving(model, "box"), gk_get_speed);
  double tStop;
  if (pd_gk_first_fall(rec->t, speed, rec->count, STOP_SPEED_FRACTION * speed[0], &tStop)) {
    out->value = tStop;
    gk_note(out, "the speed first fell below %g of the launch speed", STOP_SPEED_FRACTION);
  } else {
    gk_note(out, "did not stop (speed at the end %.3g m/s)", speed[rec->count - 1]);
  }
  free(speed);
}

static double b2_stop_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  double v0 = pd_v3_norm(model->bodies[gk_body(model, "box")].v0);
  *analytic = fmax(0.0, v0 * (1.0 - rec->t[k] / b2_stop_predicted(model)));
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_speed);
}

const pdGkExperiment pd_gk_b2_stop_time = {
    .name = "b2_stop_time",
    .group = 'B',
    .title = "Block sliding to rest from 2 m/s, mu 0.4: stop time",
    .quantity = "stop_time",
    .unit = "s",
    .formula = "t = v0/(mu g) (catalogue B2)",
    .toleranceReason = "1 %: the stop is read where the speed first falls below 1e-3 v0 (0.1 % early), "
                       "interpolated between samples 1 ms apart",
    .seriesLabel = "speed of the block, m/s",
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = b2_scene,
    .expect = b2_stop_expect,
    .measure = b2_stop_measure,
    .series = b2_stop_series,
};

// Friction cone (DESIGN §5: stopping distance against push direction): the same block launched at 1 m/s
// at an angle to its faces. Coulomb friction is isotropic, so the distance is the same in every direction;
// a pyramid approximation of the cone stops the block later along its diagonals.

static void cone_scene(double pushDeg, pdGkText* out) { slide_scene(1.0, pushDeg, 0.5, 100.0, out); }

const pdGkExperiment pd_gk_b2_friction_cone = {
    .name = "b2_friction_cone",
    .group = 'B',
    .title = "Stopping distance against the push direction (friction-cone isotropy)",
    .quantity = "stopping_distance",
    .unit = "m",
    .formula = "d = v0^2/(2 mu g) in every direction: the Coulomb cone is isotropic (catalogue B2; DESIGN 5)",
    .toleranceReason = "catalogue B2 [REC]: 0.5 % of d plus the tangential springs' static deflection mu m g/(4 k_t,s)",
    .seriesLabel = "distance travelled, m",
    .relative = false,
    .fast = true,
    .inputName = "push_deg",
    .inputCount = 7,
    .inputs = {0, 15, 30, 45, 60, 75, 90},
    .scene = cone_scene,
    .expect = slide_distance_expect,
    .measure = slide_distance_measure,
    .series = slide_distance_series,
};

// ---------------------------------------------------------------------------------------------------------
// B4: a 1 kg block (0.1 m cube) rests on a 4.5 kg sled (0.3 × 0.3 × 0.05 m) launched at 1 m/s over a
// frictionless floor; μ = 0.4 between block and sled. The block slides on the sled and is dragged at
// a₁ = μ g until both move together at m₂ v₀/(m₁ + m₂), after t* = v₀/(μ g (1 + m₁/m₂)).

static void b4_scene(double input, pdGkText* out) {
  (void)input;
  pd_gk_text_printf(out, "tend 0.4\nsample 1000\ntol 1e-9\nvmax 1\n");
  gk_text_floor(out, 2.0, 1.0, 0.2, 0.5, "mu 0\nrestitution 0.5\n");
  pd_gk_text_printf(out,
                    "cube sled blue 0.3 0.3 0.05\nloc 0 0 0.025\nvel 1 0 0\nmu 0.4\nrestitution 0.5\n"
                    "cube block red 0.1 0.1 0.1\nloc 0.08 0 0.1\nmu 0.4\nrestitution 0.5\n");
}

static double b4_predicted(const pdModel* model) { return pair_mu(model, "block", "sled") * gravity(model); }

static pdGkExpected b4_expect(const pdModel* model, double input) {
  (void)input;
  return (pdGkExpected){b4_predicted(model), 0.005};
}

// the time both move together, and their common speed
static double b4_common(const pdModel* model, double* tStar) {
  double m1 = model->bodies[gk_body(model, "block")].mass, m2 = model->bodies[gk_body(model, "sled")].mass;
  double v0 = model->bodies[gk_body(model, "sled")].v0.x;
  *tStar = v0 / (b4_predicted(model) * (1.0 + m1 / m2));
  return m2 * v0 / (m1 + m2);
}

static void b4_measure(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out) {
  (void)input;
  double tStar;
  double common = b4_common(model, &tStar);
  // the slip phase without its first 20 ms (the block's springs load) and its last fifth
  double from = 0.02, to = 0.8 * tStar;
  int j = gk_moving(model, "block");
  if (gk_measure_slope(rec, j, gk_get_vx, from, to, "block's speed", out)) {
    size_t n = strlen(out->note);
    snprintf(out->note + n, sizeof out->note - n, "; common speed at the end %.6g m/s (momentum: %.6g m/s)",
             pd_gk_body(rec, rec->count - 1, j).v.x, common);
  }
}

static double b4_series(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic) {
  (void)input;
  double tStar;
  double common = b4_common(model, &tStar);
  *analytic = fmin(b4_predicted(model) * rec->t[k], common);
  return gk_series_value(rec, k, gk_moving(model, "block"), gk_get_vx);
}

const pdGkExperiment pd_gk_b4_block_on_block = {
    .name = "b4_block_on_block",
    .group = 'B',
    .title = "Block dragged by a sled on a frictionless floor (both bodies move at the contact)",
    .quantity = "acceleration",
    .unit = "m/s^2",
    .formula = "a1 = mu g while the block slips on the sled (catalogue B4, with the push replaced by the sled's "
               "initial speed)",
    .toleranceReason = "catalogue B4 [REC]: 0.5 %",
    .seriesLabel = "speed of the block, m/s",
    .relative = true,
    .fast = true,
    .inputCount = 1,
    .scene = b4_scene,
    .expect = b4_expect,
    .measure = b4_measure,
    .series = b4_series,
};

// ---------------------------------------------------------------------------------------------------------
// B6: a thin square plate (0.2 × 0.2 × 0.004 m) on a level plate, 4 corner contacts, μ = 0.3, launched at
// 1 m/s with a spin ω₀ about the vertical: translation and spin stop together, later than without spin.

static const struct {
  double w0, tStop;
} b6_reference[] = {
    {3.0, 0.3473},   // catalogue B6: reference/scripts/plate_slide_spin.py, 4 Coulomb point loads
    {10.0, 0.4150},
};

static void b6_scene(double w0, pdGkText* out) {
  pd_gk_text_printf(out, "tend 0.6\nsample 1000\ntol 1e-8\nvmax 1\n");
  gk_text_floor(out, 2.0, 2.0, 0.2, 0.5, "mu 0.3\nrestitution 0.5\n");
  pd_gk_text_printf(out, "cube plate red 0.2 0.2 0.004\nloc 0 0 0.002\nvel 1 0 0  %.17g 0 0 1\nmu 0.3\nrestitution 0.5\n",
                    w0 * 180.0 / M_PI);
}

static pdGkExpected b6_expect(const pdModel* model, double w0) {
  if (w0 == 0.0) {  // pure slide: closed form
    double v0 = model->bodies[gk_body(model, "plate")].v0.x;
    return (pdGkExpected){v0 / (pair_mu(model, "plate", "floor") * gravity(model)), 0.01};
  }
  for (size_t i = 0; i < sizeof b6_reference / sizeof b6_reference[0]; ++i)
    if (b6_reference[i].w0 == w0) return (pdGkExpected){b6_reference[i].tStop, 0.01};
  PD_ASSERT(!"b6: no reference stop time for this spin");
  return (pdGkExpected){NAN, 0.0};
}

static double spin_rim_speed(const pdBodyState* b) { return fabs(b->w.z) * 0.1 * M_SQRT2; }

static void b6_measure(const pdModel* model, const pdGkRecord* rec, double w0, pdGkMeasured* out) {
  (void)w0;
  int j = gk_moving(model, "plate");
  double* speed = gk_column(rec, j, gk_get_horizontal_speed);
  double* rim = gk_column(rec, j, spin_rim_speed);
  double threshold = STOP_SPEED_FRACTION * speed[0], tStop, tSpin;
  if (pd_gk_first_fall(rec->t, speed, rec->count, threshold, &tStop)) {
    out->value = tStop;
    pdBodyState last = pd_gk_body(rec, rec->count - 1, j);
    if (pd_gk_first_fall(rec->t, rim, rec->count, threshold, &tSpin))
      gk_note(out, "spin stopped at %.4g s; distance %.4g m", tSpin, hypot(last.x.x, last.x.y));
    else
      gk_note(out, "distance %.4g m", hypot(last.x.x, last.x.y));
  } else {
    gk_note(out, "did not stop (speed at the end %.3g m/s)", speed[rec->count - 1]);
  }
  free(speed);
  free(rim);
}

static double b6_series(const pdModel* model, const pdGkRecord* rec, int k, double w0, double* analytic) {
  *analytic = NAN;
  if (w0 == 0.0) *analytic = fmax(0.0, 1.0 - pair_mu(model, "plate", "floor") * gravity(model) * rec->t[k]);
  return gk_series_value(rec, k, gk_moving(model, "plate"), gk_get_horizontal_speed);
}

const pdGkExperiment pd_gk_b6_slide_spin = {
    .name = "b6_slide_spin",
    .group = 'B',
    .title = "Thin square plate sliding and spinning to rest, mu 0.3",
    .quantity = "stop_time",
    .unit = "s",
    .formula = "w0 = 0: t = v0/(mu g); w0 = 3, 10 rad/s: 0.3473 s, 0.4150 s from the ODE of 4 Coulomb point "
               "loads (catalogue B6, reference/scripts/plate_slide_spin.py; Goyal, Ruina & Papadopoulos 1991)",
    .toleranceReason = "catalogue B6 [REC]: 1 %",
    .seriesLabel = "speed of the plate, m/s",
    .relative = true,
    .fast = false,
    .inputName = "w0",
    .inputCount = 3,
    .inputs = {0, 3, 10},
    .scene = b6_scene,
    .expect = b6_expect,
    .measure = b6_measure,
    .series = b6_series,
};
