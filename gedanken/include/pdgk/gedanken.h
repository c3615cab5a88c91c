// polydyn gedanken — the catalogue of Gedanken experiments (../shared/reference/gedanken-catalogue.md) as
// code, the measures computed from a run, and the suite that runs every experiment on every engine.
//
// An experiment is a scene generated from one varied parameter (its input: e.g. the requested restitution
// or the push direction), a measure computed from the sampled run (restitution of the first impact, an
// acceleration fitted over a window, a stop time, a precession rate, ...), the expected value as a formula
// with its source, and a tolerance with its reason. An experiment with no closed form states a
// qualitative check instead (finite, energy non-increasing, the outcome flips across a threshold): its
// expected value is NAN and the measure decides PASS or FAIL itself.
//
// Every engine delivers the same samples: the pose and velocity of each moving body at t = k / sample
// (docs/outputs.md). The measures use only those, the energy and (soft engine only) the contact count, so one
// measure serves polydyn's engine, ODE and Bullet alike.
//
// Units: SI (m, kg, s, rad); angles in degrees only where an input says so (push_deg).
#pragma once

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>

#include "polydyn/error.h"
#include "polydyn/model.h"
#include "polydyn/state.h"

// ---------------------------------------------------------------------------------------------------------
// The sampled run

// Every output sample of one run, collected through the observer (pd_advance and pd_ref_run both call it
// at each sample). Moving bodies are in model order (model->movingBodies).
typedef struct pdGkRecord {
  int count;            // samples
  int capacity;         // allocated samples
  int bodies;           // moving bodies per sample
  double* t;            // (count) s
  double* energy;       // (count) J: kinetic + gravitational (zero at z = 0) + contact springs (soft only)
  int* contacts;        // (count) active contacts; -1 when the engine does not report them
  pdBodyState* body;    // (count × bodies): sample k, moving body j at [k * bodies + j]
  bool finite;          // every sampled number was finite
} pdGkRecord;

// An empty record for `bodies` moving bodies (bodies >= 1).
void pd_gk_record_init(pdGkRecord* rec, int bodies);
void pd_gk_record_free(pdGkRecord* rec);
// Observer (pdObserverFcn) appending the state's sample to the pdGkRecord `user`. `contactsKnown` is
// decided by the caller: pd_gk_record_observe_ref records -1 contacts (reference engines keep no contacts in
// the state they hand to the observer).
bool pd_gk_record_observe(const pdModel* model, const pdState* state, void* user);
bool pd_gk_record_observe_ref(const pdModel* model, const pdState* state, void* user);
static inline pdBodyState pd_gk_body(const pdGkRecord* rec, int k, int j) { return rec->body[k * rec->bodies + j]; }

// ---------------------------------------------------------------------------------------------------------
// Measures (measures.c). Pure functions of sampled series; each returns false (and leaves its outputs alone)
// when the series does not contain what it looks for.

// Least-squares line y = slope·t + intercept through the samples with t0 <= t <= t1 (at least 2).
bool pd_gk_fit_line(const double* t, const double* y, int n, double t0, double t1, double* slope, double* intercept);

// The first impact in a velocity component v (along the impact normal) under a constant acceleration g
// along it (0 when gravity is off or normal to it). Free flight is a sample interval whose velocity change
// is g·Δt to within `threshold` (m/s); the impact runs from the last free sample before the first
// interval that is not, to the first sample after which `settle` intervals in a row are free again (or the
// series ends free). Velocities before and after are both carried to the impact's mid time with g, so the
// restitution -vOut/vIn does not depend on where the samples fall.
typedef struct pdGkImpact {
  double tStart, tEnd;  // s: last free sample before, first free sample after
  double vIn, vOut;     // m/s, at (tStart + tEnd)/2
  double restitution;   // -vOut / vIn
} pdGkImpact;
bool pd_gk_first_impact(const double* t, const double* v, int n, double g, double threshold, int settle,
                        pdGkImpact* out);

// Apex heights of a bouncing body: at each sample k in flight with vz[k] > 0 >= vz[k+1], z + vz²/(2g) (exact
// between samples in free flight; g > 0 is the magnitude of gravity). Returns how many were written (<= max).
int pd_gk_apexes(const double* z, const double* vz, int n, double g, double* apex, int max);

// The first time y falls to `level` or below after being above it, interpolated linearly between the two
// samples. A stop time is the first fall of the speed to a small threshold: the first arrival, not the
// time it stays below, because a soft contact rings at its springs' frequency after the stop.
bool pd_gk_first_fall(const double* t, const double* y, int n, double level, double* tCross);

// Onset of gross slip under a ramp force F = β t (catalogue B3), from the speed v along the push (m/s) of a body
// of mass m (kg). Once it slides against Coulomb friction μ m g, m v̇ = β t − μ m g = β (t − t*), so
// √(2 m v/β) = t − t*: a line fitted to √(2 m v/β) against t over the samples from the first with v >= vLo to the
// first with v >= vHi crosses zero at t* (s) with slope 1 (the slope is returned as a check). Reading t* where
// the line crosses zero, not where v crosses a level, removes the lag √(2 m v/β) of any threshold. False when v
// never reaches vHi.
bool pd_gk_ramp_slip_onset(const double* t, const double* v, int n, double mass, double beta, double vLo, double vHi,
                           double* onset, double* slope);

// The largest rise of y between an earlier and a later sample (max over k of y[k] − min_{j<k} y[j]),
// divided by `scale` (> 0): the energy gain of a series that should never increase.
double pd_gk_largest_rise(const double* y, int n, double scale);

// Drift speed of a point over [t0, end]: |x_last − x_first| / (t_last − t_first), m/s. False with fewer than
// two samples in the window.
bool pd_gk_drift_speed(const double* t, const pdVec3* x, int n, double t0, double* speed);

// Ratio of the tangential to the normal velocity change of a body over an impact, |vt1 − vt0| / |vn1 − vn0|
// (catalogue C5): μ for a contact that slides throughout, whatever its stiffness or duration. NAN when the
// normal velocity did not change.
double pd_gk_impulse_ratio(double vt0, double vt1, double vn0, double vn1);

// The fraction of the kinetic energy before a landing that the landing took, (E0 − E1)/kinetic0, from the
// total energies just before (E0) and just after (E1) — gravity does no net work in between then — and the
// kinetic energy before (> 0).
double pd_gk_absorbed_fraction(double energyBefore, double energyAfter, double kineticBefore);

// The mean rate of change of `angle` (rad, unwrapped) over the sample intervals whose two ends both have
// lo <= band <= hi: (Σ Δangle)/(Σ Δt) over those intervals. False when there is none.
bool pd_gk_mean_rate_in_band(const double* t, const double* angle, const double* band, int n, double lo, double hi,
                             double* rate);

// Removes the 2π jumps of an angle series in place, so consecutive samples differ by less than π.
void pd_gk_unwrap(double* angle, int n);

// ---------------------------------------------------------------------------------------------------------
// Closed forms shared by several experiments (formulas.c)

// Restitution of a Kelvin–Voigt contact that ends when its force is zero (paper eq. (15), catalogue A1):
// e = exp(−2ζ arccos ζ / √(1−ζ²)) for ζ < 1, e⁻² at ζ = 1, and its continuation exp(−2ζ acosh ζ / √(ζ²−1))
// for an overdamped contact (ζ > 1). ζ >= 0.
double pd_gk_restitution_of_damping(double zeta);

// A rigid cube pivoting about one bottom edge lands on the next face (catalogue D3): the impulse at the landing
// edge leaves it with no tangential velocity (no slip) and a normal velocity −e times the one before
// (e in [0, 1]). Returns the fraction of the kinetic energy the landing takes, from the impulse balance
// (angular momentum about the landing edge), and ω⁺/ω⁻ in *spinRatio (nullable): 15/16 and 1/4 when
// e = 0 (the plastic landing), 0 when e = 1.
double pd_gk_cube_landing_absorbed(double e, double* spinRatio);

// ---------------------------------------------------------------------------------------------------------
// Experiments

enum { PD_GK_MAX_INPUTS = 8, PD_GK_NOTE_MAX = 320 };

// The expected value of one (experiment, input) from the compiled model: value NAN for a qualitative check;
// tolerance in the quantity's unit, or relative (|measured/expected − 1|) when the experiment says so.
typedef struct pdGkExpected {
  double value;
  double tolerance;
} pdGkExpected;

// What a measure found. value NAN when nothing could be measured (the note says why: the row FAILs).
// `pass` is the verdict of a qualitative check (ignored when an expected value exists). note: one line.
typedef struct pdGkMeasured {
  double value;
  bool pass;
  char note[PD_GK_NOTE_MAX];
} pdGkMeasured;

// A growing text buffer for generated scenes.
typedef struct pdGkText {
  char* data;
  size_t length, capacity;
} pdGkText;
void pd_gk_text_printf(pdGkText* text, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void pd_gk_text_free(pdGkText* text);

// What an experiment tests. A law is physics every engine must obey (Coulomb's stop
// distance, friction-cone isotropy, momentum, a centred impact's restitution): every engine is judged. A model
// prediction is a consequence of the soft contact model itself (static sinkage, the elastic apex drift,
// contact duration): it is judged only for the engine variants in `appliesTo`; the others still run and
// their measurement is recorded, with the status NOT_APPLICABLE and `notApplicableReason` in the note.
typedef enum pdGkKind { pd_gkLaw, pd_gkModelPrediction } pdGkKind;
extern const char* const pdGkKindNames[];  // "law", "model_prediction"

// Engine variants, as bits of pdGkExperiment.appliesTo.
enum {
  PD_GK_SOFT = 1 << 0,
  PD_GK_ODE_NATIVE = 1 << 1,
  PD_GK_ODE_MATCHED = 1 << 2,
  PD_GK_BULLET_NATIVE = 1 << 3,
  PD_GK_BULLET_MATCHED = 1 << 4,
  PD_GK_ALL_VARIANTS = (1 << 5) - 1,
};

typedef struct pdGkExperiment {
  const char* name;             // unique, lower case: catalogue id + what it measures, e.g. "a1_restitution"
  char group;                   // 'A' … 'G' (catalogue §2)
  const char* title;            // one line
  const char* quantity;         // results.csv quantity, e.g. "restitution", "stopping_distance"
  const char* unit;             // "" for dimensionless
  const char* formula;          // the expected value as a formula, with its source
  const char* toleranceReason;  // why the tolerance is what it is
  const char* seriesLabel;      // what series/NAME.csv holds, with its unit
  pdGkKind kind;
  unsigned appliesTo;           // model prediction: the PD_GK_* variants judged (law: every variant, 0 here)
  const char* notApplicableReason;  // model prediction: why the others are not judged (one line)
  bool qualitative;             // every input is a qualitative check (expect gives NAN for each)
  bool relative;                // tolerance and error relative to the expected value
  bool fast;                    // in the CI subset (--fast)
  const char* inputName;        // the varied parameter ("e", "push_deg", ...), NULL when none
  int inputCount;               // 1 … PD_GK_MAX_INPUTS (1 with inputName NULL)
  double inputs[PD_GK_MAX_INPUTS];
  // The scene for one input (appended to `out`).
  void (*scene)(double input, pdGkText* out);
  pdGkExpected (*expect)(const pdModel* model, double input);
  void (*measure)(const pdModel* model, const pdGkRecord* rec, double input, pdGkMeasured* out);
  // The plotted quantity at sample k, and its analytic value (NAN when none).
  double (*series)(const pdModel* model, const pdGkRecord* rec, int k, double input, double* analytic);
} pdGkExperiment;

// Work-precision: each quantitative experiment also runs at every setting of each engine's
// accuracy knob, on one input (the middle one of its inputs, listed first when there are two), and its error
// against the closed form is written with the wall time (out/precision.csv). The knobs, loosest first:
//   soft adaptive: tol 1e-1, 3e-2, then 1e-2 … 1e-10 (decades); soft fixed-step RK4: dt 1e-3, 3e-4, 1e-4, 3e-5, 1e-5 s;
//   ODE and Bullet, native and matched: step 1/60, 1/250, 1/1000, 1/4000, 1/16000 s; Bullet also its solver's
//   iterations 5 … 200 at the 1 ms default step (ODE's dWorldStep solves its LCP exactly: no iterations).
int pd_gk_precision_input(const pdGkExperiment* e);  // index into e->inputs

int pd_gk_experiment_count(void);
const pdGkExperiment* pd_gk_experiment(int index);
const pdGkExperiment* pd_gk_find(const char* name);  // NULL when there is none
// `input` formatted as results.csv writes it: "name=value" (%g), or "" when the experiment has none.
void pd_gk_input_label(const pdGkExperiment* e, double input, char* buf, int size);

// ---------------------------------------------------------------------------------------------------------
// The suite: `polydyn gedanken`

typedef enum pdGkEngine { pd_gkSoft, pd_gkOde, pd_gkBullet, pd_gkEngineCount } pdGkEngine;
extern const char* const pdGkEngineNames[pd_gkEngineCount];  // "soft", "ode", "bullet"
// The engine named `name` (one of pdGkEngineNames); false when none is.
bool pd_gk_engine_named(const char* name, pdGkEngine* engine);

// NOT_APPLICABLE: a model prediction measured on a variant it does not apply to (pdGkKind): not judged.
typedef enum pdGkStatus {
  pd_gkPass,
  pd_gkFail,
  pd_gkRefused,
  pd_gkNotBuilt,
  pd_gkError,
  pd_gkNotApplicable,
  pd_gkStatusCount
} pdGkStatus;
extern const char* const pdGkStatusNames[];  // "PASS", "FAIL", "REFUSED", "NOT_BUILT", "ERROR", "NOT_APPLICABLE"

// The PD_GK_* bit of an engine variant (soft has one variant), and whether experiment e is judged on it.
unsigned pd_gk_variant_bit(pdGkEngine engine, bool matched);
bool pd_gk_applies(const pdGkExperiment* e, pdGkEngine engine, bool matched);

typedef struct pdGkProgress {
  int done, total;
  const char* experiment;
  const char* engine;   // "soft", "ode-native", ...
  const char* input;    // "" when none
} pdGkProgress;
typedef void pdGkProgressFcn(const pdGkProgress* progress, void* user);

typedef struct pdGkOptions {
  const char* out;            // the directory to write (replaced when it is a previous gedanken directory)
  bool engines[pd_gkEngineCount];
  const char* const* only;    // experiment names to run (NULL: all)
  int onlyCount;
  bool fast;                  // only the experiments marked fast
  int jobs;                   // >= 1: worker processes of this process (or MPI rank) for the runs
  double toleranceScale;      // > 0: every tolerance is multiplied by it (1 = the catalogue's); for tests
  bool precision;             // also the work-precision runs: out/precision.csv (pd_gk_precision_input)
  int repeats;                // >= 1 with precision: timings per work-precision point, its cost their minimum
                              // (pd_gk_cost)
  volatile sig_atomic_t* interrupt;  // nullable: non-zero stops the suite (nothing is written)
  pdGkProgressFcn* progress;  // nullable
  void* progressUser;
} pdGkOptions;

typedef struct pdGkSummary {
  int rows;
  int count[pd_gkStatusCount];  // rows per status (index pdGkStatus)
  int softFailures;     // soft rows that are FAIL or ERROR: `polydyn gedanken` exits 1 when > 0
  char softFailed[512]; // those rows as "NAME[ INPUT]" separated by ", " (cut short with "..." when long)
  bool interrupted;     // stopped by options.interrupt; nothing was written
  double wallSeconds;
} pdGkSummary;

// How many experiments the options select (--only and --fast); 0 is bad input for the suite.
int pd_gk_selected_count(const pdGkOptions* options);

// True when `out` does not exist or is a previous gedanken directory (has results.csv), which the suite
// replaces; otherwise false with err ("exists and is not a gedanken directory").
bool pd_gk_out_replaceable(const char* out, pdError* err);

// Runs the selected experiments on the selected engines (soft; ode and bullet in their native and matched
// variants) and writes, under a temporary name renamed into place when complete (docs/outputs.md):
//   out/results.csv, out/experiments.json, out/series/NAME.csv, out/runs/NAME/ENGINE-VARIANT[-INPUT]/.
// An engine with no adapter in this build gives NOT_BUILT rows, a scene an adapter cannot represent REFUSED.
// Returns false and fills err when `out` cannot be written or exists and is not a gedanken directory,
// or when a generated scene does not compile (a bug in the catalogue); nothing is left behind then.
// Returns false with summary->interrupted when interrupted.
bool pd_gk_run_suite(const pdGkOptions* options, pdGkSummary* summary, pdError* err);

// ---------------------------------------------------------------------------------------------------------
// The cost of a work-precision point (gedanken/timing.c; docs/validation.md, "The cost of a point")

// One timing repeats a point's run back to back until the runs' spans have taken at least this much CPU time in
// all, s. A run of a body or two on a floor is a fraction of a millisecond, where one reading is set by the clock, a
// cold cache and the other processes on a shared machine; the costs of consecutive single runs part by several
// times, those of consecutive timings of this length mostly by a tenth or less, and longer timings gain little more (what
// remains is the machine's load changing over seconds, which the least of a point's timings, taken minutes apart,
// answers). Measured: reports/bench/precision-timing/README.md.
#define PD_GK_TIMING_MIN_CPU_SECONDS 0.020
// At most this many runs in one timing: a clock that does not advance must not hang the sweep.
#define PD_GK_TIMING_MAX_RUNS 100000

// One run of the span a point times: sets the run's wall and CPU seconds over that span; false when the run did not
// complete (it failed, was refused or interrupted), which ends the timing.
typedef bool pdGkTimedRunFcn(void* user, double* wallSeconds, double* cpuSeconds);

typedef struct pdGkTiming {
  double wall, cpu;  // the runs' summed spans over their number, s per run
  long runs;         // runs back to back in the timing (>= 1)
  bool completed;    // every run completed
} pdGkTiming;

// Calls run back to back until the summed CPU seconds reach minCpuSeconds (> 0) or PD_GK_TIMING_MAX_RUNS runs, or
// a run does not complete; the timing's cost per run.
pdGkTiming pd_gk_time_runs(pdGkTimedRunFcn* run, void* user, double minCpuSeconds);

// A point's cost from its timings: the least (wall and CPU each its own minimum), what the report reads; their
// median and max/min, the spread.
typedef struct pdGkCost {
  double wall, cpu;                    // minimum over the timings, s per run
  double wallMedian, cpuMedian;        // median over the timings, s per run
  double wallMaxOverMin, cpuMaxOverMin;
  long runs;                           // runs of the timing with the least CPU time
} pdGkCost;
pdGkCost pd_gk_cost(const pdGkTiming* timings, int count);
