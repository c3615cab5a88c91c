// polydyn gedanken — group B: friction (catalogue §2 B1–B6, and the friction cone of docs/DESIGN.md §8.3).
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
    .kind = pd_gkLaw,
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
    .kind = pd_gkLaw,
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
    .kind = pd_gkLaw,
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
    .kind = pd_gkLaw,
    .relative = true,
    .fast = false,
    .inputCount = 1,
    .scene = b2_scene,
    .expect = b2_stop_expect,
    .measure = b2_stop_measure,
    .series = b2_stop_series,
};

// Friction cone (docs/DESIGN.md §8.3: stopping distance against push direction): the same block launched at 1 m/s
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
    .kind = pd_gkLaw,
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
// B3: a 0.1 m cube (1 kg) at rest on a level plate, μ = 0.4, pushed at its centre of mass (the CoM height) by
// F = β t along x. It sticks, creeping by the tangential springs' deflection β t/(4 k_t,s), until the push
// reaches μ m g at t* = μ m g/β, then slides with m v̇ = β (t − t*). Two rates, as the catalogue asks (a
// damper-weighted stick test would make the breakaway rate dependent).

// The pushed blocks of B3 and B5 stand on a floor whose springs are as stiff as theirs (1e6 N/m ~ m vmax²/(0.01
// size)²) instead of sized by the floor's own 1.4 m extent (5e3 N/m): B3's creep while sticking, β/(4 k_t,s),
// then stays far below B3_V_LO, and B5's tilt on its springs (~0.02 deg) far below the ~0.4 deg at which the
// 1.5 % margin of the moments about the front edge is used up.
#define STIFF_FLOOR "kn 1e6\nkt 1e6\n"

#define B3_MU 0.4
#define B3_AFTER 0.1  // s of sliding after t*: v reaches β (0.1 s)²/(2m) = 0.02..0.04 m/s, past B3_V_HI
// The onset is read from the slide between these speeds (pd_gk_ramp_slip_onset): far above the creep of
// the sticking springs (β/(4 k_t,s) ~ 4e-6 m/s here), reached 20..70 ms after t*, 1 ms samples.
#define B3_V_LO 2e-3  // m/s
#define B3_V_HI 1e-2  // m/s

static double b3_onset(const pdModel* model, double beta) {
  double m = model->bodies[gk_body(model, "box")].mass;
  return pair_mu(model, "box", "floor") * m * gravity(model) / beta;
}

static void b3_scene(double beta, pdGkText* out) {
  double tStar = B3_MU * 1.0 * GK_G / beta;  // the cube's 1 kg: 0.1 m of water
  pd_gk_text_printf(out, "tend %.17g\nsample 1000\ntol 1e-9\nvmax 1\n", tStar + B3_AFTER);
  gk_text_floor(out, 2.0, 2.0, 0.2, 0.0, "mu 0.4\nrestitution 0.5\n" STIFF_FLOOR);
  pd_gk_text_printf(out, "cube box red 0.1 0.1 0.1\nloc 0 0 0.05\nmu %g\nrestitution 0.5\nforce 0 0 0 ramp %.17g 0 0\n",
                    B3_MU, beta);
}

static pdGkExpected b3_expect(const pdModel* model, double beta) { return (pdGkExpected){b3_onset(model, beta), 0.005}; }

static void b3_measure(const pdModel* model, const pdGkRecord* rec, double beta, pdGkMeasured* out) {
  double* v = gk_column(rec, gk_moving(model, "box"), gk_get_vx);
  double m = model->bodies[gk_body(model, "box")].mass, tStar, slope;
  if (pd_gk_ramp_slip_onset(rec->t, v, rec->count, m, beta, B3_V_LO, B3_V_HI, &tStar, &slope)) {
    out->value = tStar;
    gk_note(out, "zero of the line fitted to sqrt(2 m v/beta) while v rose from %g to %g m/s; slope %.4g (1: "
            "m dv/dt = beta (t - t*))", B3_V_LO, B3_V_HI, slope);
  } else {
    gk_note(out, "did not slide: speed at the end %.3g m/s", v[rec->count - 1]);
  }
  free(v);
}

// displacement along the push: β t/(4 k_t,s) while it sticks, then that plus β (t − t*)³/(6 m)
static double b3_series(const pdModel* model, const pdGkRecord* rec, int k, double beta, double* analytic) {
  int box = gk_body(model, "box");
  double kt = pd_model_pair_contact(model, box, gk_body(model, "floor")).kt, m = model->bodies[box].mass;
  double t = rec->t[k], tStar = b3_onset(model, beta), after = fmax(0.0, t - tStar);
  *analytic = beta * fmin(t, tStar) / (4.0 * kt) + beta * after * after * after / (6.0 * m);
  return gk_series_value(rec, k, gk_moving(model, "box"), gk_get_x);
}

const pdGkExperiment pd_gk_b3_ramp_onset = {
    .name = "b3_ramp_onset",
    .group = 'B',
    .title = "Cube pushed by a ramp force beta t at its centre of mass, mu 0.4: slip onset",
    .quantity = "onset_time",
    .unit = "s",
    .formula = "t* = mu m g/beta: gross slip when the push reaches the Coulomb bound, one mu for stick and slip "
               "(catalogue B3)",
    .toleranceReason = "catalogue B3 [REC]: 0.5 %; t* is where the fitted slide extrapolates to zero speed, free of "
                       "any threshold's lag",
    .seriesLabel = "displacement of the cube along the push, m",
    .kind = pd_gkLaw,
    .relative = true,
    .fast = true,
    .inputName = "beta",
    .inputCount = 2,
    .inputs = {4, 8},
    .scene = b3_scene,
    .expect = b3_expect,
    .measure = b3_measure,
    .series = b3_series,
};

// ---------------------------------------------------------------------------------------------------------
// B5: a block w = 0.1 m along the push, 0.1 m across, h = 0.2 m tall (2 kg, CoM at h_c = 0.1 m) on a level
// plate, pushed along x by a constant force at the middle of its rear face, H = 0.12 m above the plate.
// Statics: it slides if μ < w/(2H) and tips over its front edge if μ > w/(2H); the tip force is m g w/(2H).
// Inputs: μ/(w/(2H)) = 0.98 and 1.02 (catalogue: ±2 %). The push is 1 % above the tip force. With μ 2 % above
// the threshold it stays below μ m g: the block tips and does not slide. With μ 2 % below it exceeds μ m g and
// stays below m g (w/2 − μ h_c)/(H − h_c), the push that tips a block sliding on friction μ m g (10 % above the
// tip force here: pushing close to the CoM height makes that margin hc/(H − hc) = 5 times the 2 %), so the
// block slides and does not tip; pushing at the top (H = h) would leave 1 %, which a soft contact's rocking
// under the suddenly applied push overshoots. The regime is whichever shows first: a tilt of B5_TIP_DEG or a
// slide of the front bottom edge by B5_SLIDE_M.

#define B5_W 0.1          // m, along the push (x)
#define B5_D 0.1          // m, across (y)
#define B5_H 0.2          // m, height (z)
#define B5_PUSH_H 0.12    // m, height of the push above the plate
#define B5_PUSH_OVER 1.01 // push / tip force
#define B5_TIP_DEG 5.0    // deg: far above the springs' static tilt (~1e-2 deg), and past it the push's lever
                          // grows while gravity's shrinks, so the block goes on over
#define B5_SLIDE_M 0.01   // m: far above the tangential springs' deflection (~1e-4 m)

static double b5_threshold(void) { return B5_W / (2.0 * B5_PUSH_H); }

static void b5_scene(double ratio, pdGkText* out) {
  double m = 1000.0 * B5_W * B5_D * B5_H;  // kg, spgrav 1
  double push = B5_PUSH_OVER * m * GK_G * b5_threshold(), mu = ratio * b5_threshold();
  pd_gk_text_printf(out, "tend 1.5\nsample 200\ntol 1e-8\nvmax 1\n");
  // the floor's μ is the block's, so the pair's √(μ₁μ₂) is μ
  gk_text_floor(out, 2.0, 2.0, 0.2, 0.0, "");
  pd_gk_text_printf(out, "mu %.17g\nrestitution 0.5\n" STIFF_FLOOR, mu);
  pd_gk_text_printf(out,
                    "cube block red %g %g %g\nloc 0 0 %g\nmu %.17g\nrestitution 0.5\nforce %.17g 0 0 at %g 0 %.17g\n",
                    B5_W, B5_D, B5_H, B5_H / 2.0, mu, push, -B5_W / 2.0, B5_PUSH_H - B5_H / 2.0);
}

static pdGkExpected b5_expect(const pdModel* model, double ratio) {
  (void)model, (void)ratio;
  return (pdGkExpected){NAN, 0.0};
}

// x of the middle of the front bottom edge, the edge it would tip over
static double front_edge_x(const pdBodyState* b) {
  return pd_v3_add(b->x, pd_quat_rotate(b->q, pd_v3(B5_W / 2.0, 0.0, -B5_H / 2.0))).x;
}

static void b5_measure(const pdModel* model, const pdGkRecord* rec, double ratio, pdGkMeasured* out) {
  (void)ratio;
  int j = gk_moving(model, "block");
  double pairMu = pair_mu(model, "block", "floor");
  bool tipsExpected = pairMu > b5_threshold();
  double* tilt = gk_column(rec, j, gk_get_tilt_deg);
  double* edge = gk_column(rec, j, front_edge_x);
  int tip = 0, slide = 0;
  while (tip < rec->count && tilt[tip] < B5_TIP_DEG) ++tip;
  while (slide < rec->count && edge[slide] - edge[0] < B5_SLIDE_M) ++slide;
  if (tip == rec->count && slide == rec->count) {
    gk_note(out, "neither tipped (%.3g deg) nor slid (%.3g m) by the end", tilt[rec->count - 1],
            edge[rec->count - 1] - edge[0]);
  } else {
    bool tips = tip < slide;
    out->value = tips ? 1.0 : 0.0;
    out->pass = tips == tipsExpected;
    int at = tips ? tip : slide;
    gk_note(out, "%s at %.3g s (expected: %s; mu %.4g against w/(2H) = %.4g); at %.3g s: tilt %.3g deg, edge moved %.3g m",
            tips ? "tips" : "slides", rec->t[at], tipsExpected ? "tips" : "slides", pairMu, b5_threshold(), rec->t[at],
            tilt[at], edge[at] - edge[0]);
  }
  free(tilt);
  free(edge);
}

static double b5_series(const pdModel* model, const pdGkRecord* rec, int k, double ratio, double* analytic) {
  (void)ratio;
  *analytic = NAN;
  return gk_series_value(rec, k, gk_moving(model, "block"), gk_get_tilt_deg);
}

const pdGkExperiment pd_gk_b5_tip_or_slide = {
    .name = "b5_tip_or_slide",
    .group = 'B',
    .title = "Block pushed just past the tip force: slides or tips across mu = w/(2H) (qualitative)",
    .quantity = "tips",
    .unit = "",
    .formula = "slides (0) if mu < w/(2H), tips (1) if mu > w/(2H) (w = 0.1 m, H = 0.12 m); tip force m g w/(2H) "
               "(catalogue B5)",
    .toleranceReason = "catalogue B5 [REC]: the regime is classified right 2 % either side of the threshold",
    .seriesLabel = "tilt of the block from upright, deg",
    .qualitative = true,
    .kind = pd_gkLaw,
    .relative = false,
    .fast = true,
    .inputName = "mu_ratio",
    .inputCount = 2,
    .inputs = {0.98, 1.02},
    .scene = b5_scene,
    .expect = b5_expect,
    .measure = b5_measure,
    .series = b5_series,
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
    .kind = pd_gkLaw,
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
    .kind = pd_gkLaw,
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
