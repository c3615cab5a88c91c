// polydyn gedanken (internal) — what the experiment files share: scene snippets, series extraction, notes.
#pragma once

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "pdgk/gedanken.h"

#define GK_G 9.81  // m/s², the scene default; scenes that change gravity say so

// The experiments, one const definition each (group_a.c … group_g.c); the table is catalogue.c.
extern const pdGkExperiment pd_gk_a1_restitution, pd_gk_a2_restitution_contacts, pd_gk_a3_sinkage,
    pd_gk_a4_elastic_apex;
extern const pdGkExperiment pd_gk_b1_incline_slide, pd_gk_b1_incline_stick, pd_gk_b2_stopping_distance,
    pd_gk_b2_stop_time, pd_gk_b2_friction_cone, pd_gk_b3_ramp_onset, pd_gk_b4_block_on_block, pd_gk_b5_tip_or_slide,
    pd_gk_b6_slide_spin;
extern const pdGkExperiment pd_gk_c1_bounce_apex, pd_gk_c2_momentum, pd_gk_c3_eccentric_bar,
    pd_gk_c4_velocity_exchange, pd_gk_c5_oblique_impact, pd_gk_c6_energy_gain;
extern const pdGkExperiment pd_gk_d1_rimless_wheel, pd_gk_d2_slide_to_roll, pd_gk_d3_tumbling_cube,
    pd_gk_d3_landing_energy;
extern const pdGkExperiment pd_gk_e1_painleve, pd_gk_e2_side_load_pitch;
extern const pdGkExperiment pd_gk_f1_top_precession, pd_gk_f2_euler_disk;
extern const pdGkExperiment pd_gk_g1_stack_drift, pd_gk_g1_stack_sinkage, pd_gk_g2_domino, pd_gk_g3_pushed_load;

// Index of the body called `name` in the model / among the moving bodies (asserts it exists: the scenes
// are generated here, so a missing name is a bug).
int gk_body(const pdModel* model, const char* name);
int gk_moving(const pdModel* model, const char* name);

// " θ u v w" of `loc` / `vel` (degrees, axis) for the rotation q.
void gk_text_rotation(pdGkText* out, pdQuat q);

// A fixed floor slab whose top face is the plane z = 0, `sx` × `sy` × `sz` m centred at (cx, 0, −sz/2), with
// the material lines `material` (e.g. "mu 0.4\nrestitution 0.5\n"). A fixed body's springs are sized by its
// own size (its mean extent) and the heaviest moving mass: a floor of the same mean extent as the body on
// it has the same k and c, so the pair is one Kelvin–Voigt element (catalogue A1 pitfall: otherwise third
// order).
void gk_text_floor(pdGkText* out, double sx, double sy, double sz, double cx, const char* material);

// Per-sample values of moving body j through `get`, into a new array (free it).
typedef double gkGetter(const pdBodyState* b);
double* gk_column(const pdGkRecord* rec, int j, gkGetter* get);
double gk_get_x(const pdBodyState* b);
double gk_get_z(const pdBodyState* b);
double gk_get_vx(const pdBodyState* b);
double gk_get_vz(const pdBodyState* b);
double gk_get_wy(const pdBodyState* b);
double gk_get_speed(const pdBodyState* b);            // |v|
double gk_get_horizontal_speed(const pdBodyState* b);  // |(vx, vy)|
double gk_get_tilt_deg(const pdBodyState* b);          // angle of the body z axis from the world z axis, deg

// Positions of moving body j (new array; free it).
pdVec3* gk_positions(const pdGkRecord* rec, int j);

// The slope of a line fitted to moving body j's `get` over from <= t <= to (an acceleration from a speed, a
// mean speed from a position) into out->value, with a note naming `what` was fitted. False (and a note)
// when the window holds fewer than two samples.
bool gk_measure_slope(const pdGkRecord* rec, int j, gkGetter* get, double from, double to, const char* what,
                      pdGkMeasured* out);

// Sets out->note (printf style).
void gk_note(pdGkMeasured* out, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

// The time of sample k and the value of a body component there: the plain series most experiments plot.
static inline double gk_series_value(const pdGkRecord* rec, int k, int j, gkGetter* get) {
  pdBodyState b = pd_gk_body(rec, k, j);
  return get(&b);
}

// The largest relative energy rise of the run (energy gain; the scale is E(0), positive in scenes whose floor
// top is z = 0 and whose bodies start above it).
double gk_energy_gain(const pdGkRecord* rec);

// Kinetic energy of `body` (model index) in state b: translation and rotation (inertia in the body frame).
double gk_kinetic_energy(const pdModel* model, int body, const pdBodyState* b);

// Effective mass of `body` (model index) for a push along world direction n at world point p, at the
// body's initial pose (paper eqs. (19)–(20)).
double gk_effective_mass(const pdModel* model, int body, pdVec3 p, pdVec3 n);

// Monotonic wall clock, s (for the measured wall times).
double gk_wall_seconds(void);
// The calling thread's CPU time, s: a run's cost that other processes on the machine do not inflate.
double gk_cpu_seconds(void);


// ---------------------------------------------------------------------------------------------------------
// The suite's cases, shared with the work-precision runs (precision.c)

// One (experiment, input) of a suite run: its generated scene, compiled once and shared read-only by its runs.
typedef struct gkCase {
  const pdGkExperiment* experiment;
  double input;
  char label[64];         // "e=0.5" or ""
  char* sceneText;        // the generated scene (owned)
  pdModel* model;         // compiled from it (owned)
  pdGkExpected expected;  // tolerance already scaled
} gkCase;

// The work-precision runs of `options->precision` (gedanken/RESULT_SCHEMAS.md, precision.csv): for each
// selected quantitative experiment, its precision input (pd_gk_precision_input) on every selected engine over
// its accuracy knob. Runs as a batch like the suite's runs and writes root/precision.csv. False with err when
// the batch failed or the file could not be written (interruption: false, err names it).
bool gk_precision_run(const pdGkOptions* options, const gkCase* cases, int caseCount, const char* root, pdError* err);
