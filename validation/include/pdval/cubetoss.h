// polydyn validation — validation against real cube tosses (docs/DESIGN.md §8.4, `polydyn cubetoss`).
//
// The data (shared/data/cube-toss/README.md): tosses of a wooden cube onto a flat board, tracked by camera
// at 148 Hz, from the ContactNets data set (Pfrommer, Halm & Posa, CoRL 2020), also used by Acosta, Yang &
// Posa (RA-L 2022) to judge Drake, MuJoCo and Bullet. One CSV file, header exactly
//   toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz
// rows of one toss consecutive, t = k/148 s from 0 (printed to 1 µs), x the cube's centre (m, board frame,
// z up), q body → board (unit, w first), v (m/s), ω (rad/s, board frame).
//
// The scene of one toss (pd_toss_scene): the cube (side PD_TOSS_CUBE_SIDE, mass PD_TOSS_CUBE_MASS through
// its density) at the toss's first sample, and the board as a fixed 2 m × 2 m × 0.1 m box whose top face
// is at PD_TOSS_BOARD_TOP. Both bodies get the same μ, e and k_n (pdTossParams), so the pair has μ and e
// themselves and the series stiffness k_n/2. The simulation runs to the toss's last sample and is sampled
// at 148 Hz, so simulated and recorded samples share their times exactly.
//
// Inertia: the scene language has no inertia command; a uniform cube of this mass has 6.77e-4 kg·m², the
// data's authors used 8.1e-4 kg·m² (the real block's). pd_toss_model sets the compiled model's inertia to
// pdTossParams.inertia (isotropic: about every axis) before any state exists, so every engine sees it
// (refcheck adapters read the model's inertia). The contact model's minimum effective mass, which only
// sizes the §3.3.1 time-constant checks and the refinement step, stays the uniform cube's (a shorter
// period, so a smaller, safer refinement step).
//
// Errors of a run against the record, per sample k: position |x_sim − x_rec| / PD_TOSS_CUBE_SIDE (cube
// widths) and rotation angle of q_rec⁻¹ q_sim (rad, in [0, π], not reduced by the cube's symmetries: the
// real cube's faces are told apart by their tags). "end": at the last sample; "rms": root mean square over
// all samples of the toss.
//
// Split (deterministic): a toss's position in the file, counted from 0, decides: even → training, odd →
// test.
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pdref/compare.h"
#include "polydyn/error.h"
#include "polydyn/model.h"
#include "pdref/refcheck.h"
#include "polydyn/state.h"

// ---------------------------------------------------------------- the experiment (data README)

#define PD_TOSS_RATE 148.0          // Hz: camera rate, and our sample rate
#define PD_TOSS_CUBE_SIDE 0.1048    // m
#define PD_TOSS_CUBE_MASS 0.37      // kg
#define PD_TOSS_CUBE_INERTIA 8.1e-4 // kg·m² about every axis: the data's authors' value (uniform: 6.77e-4)
// Height of the board's top face, m: the data's resting height 0.0512 m minus the half-width 0.0524 m
// (the median of the 456 tosses' last samples is 0.05125 m: the same to 0.05 mm).
#define PD_TOSS_BOARD_TOP (-0.0012)
#define PD_TOSS_BOARD_WIDTH 2.0     // m, square: the tosses stay within 0.65 m of the origin
#define PD_TOSS_BOARD_THICKNESS 0.1 // m
// Characteristic speed of the scene, m/s (`vmax`: scales the error control's velocities and sizes the
// default stiffness): the fastest impact in the data is 2.0 m/s vertically (first samples' height and
// vz) with up to ~1.4 m/s horizontally.
#define PD_TOSS_VMAX 2.5
// The t column is printed to 1 µs: a row whose t is farther than this from k/148 is refused, s.
#define PD_TOSS_TIME_TOL 1e-6
// A recorded quaternion whose norm is farther than this from 1 is refused (they are printed to 9 digits
// and are within 1e-9); accepted ones are normalised.
#define PD_TOSS_QUAT_NORM_TOL 1e-6
// Smallest restitution a toss scene requests: the engine's own (PD_RESTITUTION_MIN, polydyn/model.h).
#define PD_TOSS_RESTITUTION_MIN PD_RESTITUTION_MIN
// The default restitution: the data's authors' fit for their own model (Pfrommer et al. 2020).
#define PD_TOSS_DEFAULT_RESTITUTION 0.125

// ---------------------------------------------------------------- the experiments

// Real planar drops (shared/data/planar-drops/README.md): a square block of side 0.06 m dropped in a vertical
// plane onto a flat surface, tracked at 250 Hz (Fazeli et al., ICRA 2017, ISRR 2017; data from the
// repository DAIRLab/ImpactModeling, BSD 3-Clause). One CSV file, header exactly
//   drop,t,x,z,th,vx,vz,vth
// rows of one drop consecutive, t = k/250 s from 0, (x, z) the centre (m, z up), th the angle in the plane
// (rad, counter-clockwise seen from −y: x turns towards z), v (m/s), vth (rad/s). The same machinery runs
// them: each drop is read as a pose in 3-D (x, 0, z), q = rotation by th about −y, ω = (0, −vth, 0); the
// block is a 0.06 m cube held in the x–z plane (scene `planar`), mass 1 kg and the uniform block's inertia
// m s²/6 about y, as the data's repository takes them (the data give neither; a uniform block's motion does
// not depend on its mass). The surface's top is at PD_DROP_BOARD_TOP.
#define PD_DROP_RATE 250.0         // Hz
#define PD_DROP_SIDE 0.06          // m
#define PD_DROP_MASS 1.0           // kg
// Height of the surface, m: the median over the drops of the lowest corner's height at the last sample
// (at rest on a face): 0.52 mm, with the resting centre's median height 0.0315 m = 0.0005 + 0.03.
#define PD_DROP_BOARD_TOP 0.0005
// Characteristic speed, m/s: impacts arrive at about 2.5 m/s; the fastest first sample is 5.0 m/s (noise).
#define PD_DROP_VMAX 3.0

// Bounces (planar experiments): an impact starts when the block's lowest point comes within
// PD_DROP_CONTACT_BAND of the surface and ends when it rises above PD_DROP_LIFT_BAND; the impact's time is the
// first sample after which the lowest point rises (the first local minimum of its height in the band). The post-impact velocity is the central difference of
// the samples 1 and 3 after it (centre velocity and angular velocity: the same estimate for record and run,
// as the record's own velocities are noisy). Bands: the tracking noise of the lowest corner is about 1 mm.
#define PD_DROP_CONTACT_BAND 0.003  // m
#define PD_DROP_LIFT_BAND 0.006     // m
enum { PD_TOSS_IMPACTS = 3 };       // bounces compared

// What differs between the data sets; everything else (the scene's board, the errors, the fit) is shared.
typedef struct pdTossExperiment {
  const char* name;      // "cube tosses", "planar drops"
  const char* header;    // the CSV's header line
  double rate;           // Hz: the record's and our sample rate
  double size[3];        // m: the block's box sx sy sz
  double side;           // m: position errors are in these lengths
  double mass;           // kg
  double boardTop;       // m: height of the surface
  double vmax;           // m/s: the scenes' vmax
  bool planar;           // the block moves in the x–z plane (scene `planar`); bounces are compared
  const char* lengthUnit;  // "cube_widths", "side_lengths"
} pdTossExperiment;

extern const pdTossExperiment pd_cube_tosses, pd_planar_drops;

// ---------------------------------------------------------------- the data

typedef struct pdToss {
  const pdTossExperiment* experiment;
  long id;               // the toss column
  int sampleCount;       // >= 2
  long line;             // line of its first row in the file (1-based)
  pdBodyState* samples;  // (sampleCount) at t = k / PD_TOSS_RATE; q normalised
} pdToss;

typedef struct pdTossSet {
  const pdTossExperiment* experiment;  // chosen by the file's header
  char* path;      // as given (owned)
  int count;
  pdToss* tosses;  // (count) in file order (owned)
} pdTossSet;

// Reads a cube-toss or a planar-drop CSV (layouts above; the header says which). Returns NULL and fills err with `FILE:LINE:COL: message` on a
// file that cannot be read, a wrong header, a field that is not a finite number, a toss whose rows are
// not consecutive, a t that is not k/148, a quaternion that is not unit, or a toss of fewer than 2 rows.
pdTossSet* pd_toss_read(const char* path, pdError* err);
// The same from `size` bytes in memory (need not be NUL-terminated); `name` (nullable: "<buffer>") stands for
// the file in messages and in the set's path. pd_toss_read runs this code on the file's lines.
pdTossSet* pd_toss_parse_buffer(const char* name, const char* data, size_t size, pdError* err);
void pd_toss_set_free(pdTossSet* set);

typedef enum pdTossSplit { pd_tossTrain, pd_tossTest } pdTossSplit;
// The split of the toss at file position `index` (0-based): even → training, odd → test.
pdTossSplit pd_toss_split(int index);
const char* pd_toss_split_name(pdTossSplit split);  // "train", "test"

// Selects tosses from LIST: "all", "train", "test", or comma-separated toss ids and inclusive id ranges
// ("1-20,35"); a single id must be in the set, a range must hold at least one of its ids. Fills *indices (malloc'd, file order, no repeats; free it) and
// *count; returns false with a message in `why` on a bad list.
bool pd_toss_select(const pdTossSet* set, const char* list, int** indices, int* count, char* why, size_t whySize);

// ---------------------------------------------------------------- the scene

// The free parameters, the same for the cube and the board.
typedef struct pdTossParams {
  double mu;           // base friction coefficient (the pair's μ)
  double restitution;  // requested e, in [PD_TOSS_RESTITUTION_MIN, 1] (derives c_n and c_t, eq. (15))
  double kn;           // normal spring of each side, N/m (k_t = k_n); the pair's is kn/2
  double tol;          // the soft engine's integration tolerance
  double inertia;      // kg·m² about every axis; 0: the uniform-density block's
} pdTossParams;

// The parameters without fitting: μ = 0.18 and e = 0.125 (the data's authors' fit), k_n by the engine's own rule eq. (11) for the cube,
// m vmax²/(0.01 side)² = 2.105e6 N/m (deflection 0.01, the engine default), tol 1e-6, inertia 8.1e-4.
pdTossParams pd_toss_default_params(void);
// The parameters of an experiment without fitting (cube tosses: pd_toss_default_params; planar drops: μ 0.2,
// e 0.5 (the middle of the ranges the data's literature fits), k_n 2.5e7 N/m (eq. (11): m vmax²/(0.01 s)²),
// tol 1e-6, the uniform block's inertia).
pdTossParams pd_toss_experiment_params(const pdTossExperiment* experiment);

// The scene text of toss `toss` (malloc'd, NUL-terminated; free it). Valid input to pd_scene_parse_buffer.
char* pd_toss_scene(const pdToss* toss, const pdTossParams* params);

// Parses and compiles the scene and sets the cube's inertia (see the top of this file). Returns NULL and
// fills err when the scene is refused (e.g. the cube's first pose overlaps the board).
pdModel* pd_toss_model(const pdToss* toss, const pdTossParams* params, pdError* err);

// Index of the cube and of the board among the model's bodies.
enum { PD_TOSS_BOARD_BODY = 0, PD_TOSS_CUBE_BODY = 1 };

// ---------------------------------------------------------------- running and judging one toss

// "noise" is no engine: its run is the record delayed by one sample (the first sample repeated), judged like
// a simulation, so its errors are the floor that the data's own sampling and noise set.
typedef struct pdTossEngine {
  const char* name;   // "soft", "ode", "bullet", "noise"
  pdRefOptions ref;   // ode, bullet: variant, step
} pdTossEngine;

typedef enum pdTossStatus {
  pd_tossOk,        // reached the last sample with finite numbers
  pd_tossFailed,    // the run stopped early or could not write its run directory
  pd_tossRefused,   // the scene or the engine refused the toss
  pd_tossNotBuilt,  // this build has no adapter for the engine
} pdTossStatus;
const char* pd_toss_status_name(pdTossStatus status);  // "ok", "failed", "refused", "not built"

typedef struct pdTossResult {
  pdTossStatus status;
  int samples;                    // samples compared (the record's)
  double posErrEnd, posErrRms;    // cube widths; NAN unless ok
  double rotErrEnd, rotErrRms;    // rad; NAN unless ok
  double wallSeconds;             // the engine's run: its state or world created, then run
  double cpuSeconds;              // CPU time of this process over the same span (a shared machine's wall
                                  // time counts other processes too)
  long steps;                     // accepted steps
  bool runWritten;                // the run directory asked for was written (also for a run that failed)
  char message[640];              // why, unless ok
  // bounces (planar experiments; see PD_DROP_CONTACT_BAND): found in the record and in the run, and per
  // bounce k the errors |t_run − t_rec| (s), |v_run − v_rec| of the centre after it (m/s), |ω_run − ω_rec|
  // (rad/s); NAN where either has no k-th bounce (or no samples after it)
  int impactsRecord, impactsRun;
  double impactDt[PD_TOSS_IMPACTS], impactDv[PD_TOSS_IMPACTS], impactDw[PD_TOSS_IMPACTS];
} pdTossResult;

typedef struct pdTossImpact {
  int sample;     // index of the sample at the impact
  double t;       // s
  pdVec3 v, w;    // after it (NAN when the samples end too soon), m/s and rad/s
} pdTossImpact;

// The first (at most PD_TOSS_IMPACTS) bounces of `n` samples at the experiment's rate; returns how many.
int pd_toss_impacts(const pdTossExperiment* experiment, const pdBodyState* samples, int n,
                    pdTossImpact impacts[PD_TOSS_IMPACTS]);

// Simulates one toss in one engine from its first sample to its last, sampled at 148 Hz, and judges it
// against the record (fills result). With runDir non-NULL writes that run directory too. Returns the
// simulated trajectory (free with pd_trajectory_free) or NULL unless the status is ok.
pdTrajectory* pd_toss_simulate(const pdToss* toss, const pdTossParams* params, const pdTossEngine* engine,
                               const char* runDir, pdTossResult* result);

// Fills the error fields of `result` from `run` (sample k at k/148 s) against the record; a run with
// fewer samples than the record makes the result failed.
void pd_toss_judge(const pdToss* toss, const pdTrajectory* run, pdTossResult* result);

// Writes the record of a toss as a run directory (docs/outputs.md; engine "record" in summary.json), so a
// viewer overlays reality and simulation; `dataPath` (nullable) is named in its engine_settings. Returns false
// and fills err on an I/O error.
bool pd_toss_write_record(const pdToss* toss, const pdTossParams* params, const char* dir, const char* dataPath,
                          pdError* err);

// ---------------------------------------------------------------- statistics

typedef struct pdTossStats {
  int n;       // finite values used
  double mean, median, p90;  // NAN when n == 0
} pdTossStats;

// Mean, median and 90th percentile of the finite values among v[0..count) (NaNs are skipped). Percentiles
// interpolate linearly between order statistics: P(p) = x[⌊h⌋] + (h − ⌊h⌋)(x[⌊h⌋+1] − x[⌊h⌋]) with
// h = p (n − 1), x sorted from 0 (numpy's default, Hyndman & Fan type 7).
pdTossStats pd_toss_stats(const double* v, int count);

// ---------------------------------------------------------------- parameter fragments

// Reads a scene fragment of property lines for one object (`mu`, `restitution`, `kn`, comments) into
// *params, overriding what it sets. Anything else (another property, a setting, an object) is refused.
// Errors are `FILE:LINE:COL: message` in err.
bool pd_toss_params_read(const char* path, pdTossParams* params, pdError* err);
// Writes params as such a fragment (mu, restitution, kn; %.17g); `comment` (nullable, may hold several
// lines) is written first, each line behind "# ".
void pd_toss_params_write(FILE* out, const pdTossParams* params, const char* comment);

// ---------------------------------------------------------------- parallel runs

// One job: fills `result` (resultSize bytes, zeroed before the call) for job `job`.
typedef void pdTossJobFcn(int job, void* result, void* user);
// Called in the calling process as jobs finish (done of total); returning false stops the work.
typedef bool pdTossProgressFcn(int done, int total, void* user);

// Runs jobs 0 .. count-1 as a batch (batch.h): in `workers` processes (fork; jobs handed out one at a
// time, so the results do not depend on which worker ran which job), and under MPI split over the ranks,
// every rank getting every result (collective: every rank calls it alike). Leaves job i's result at
// results + i·resultSize. With one worker (or one job) runs them in this process. Returns false with a
// message in `why` when a worker died or progress asked to stop.
bool pd_toss_parallel(int count, int workers, size_t resultSize, void* results, pdTossJobFcn* job, void* user,
                      pdTossProgressFcn* progress, void* progressUser, char* why, size_t whySize);

// ---------------------------------------------------------------- fitting

// Failed runs enter the objective with these errors (a lost toss, never better than a real one).
#define PD_TOSS_FAIL_POS_ERR 10.0          // cube widths
#define PD_TOSS_FAIL_ROT_ERR 3.141592653589793  // rad
#define PD_TOSS_FAIL_BOUNCE_ERR PD_DROP_VMAX     // m/s: a first bounce missing in the run or the record
// Planar experiments add the first bounce's velocity error to the objective in units of this speed, m/s: a
// 0.1 m/s error weighs as much as 0.1 side lengths of end position or 0.1 rad of end angle.
#define PD_TOSS_BOUNCE_SCALE 1.0

typedef struct pdTossFitOptions {
  const pdTossSet* set;
  const int* tosses;         // training tosses (set indices)
  int tossCount;
  pdTossEngine engine;
  pdTossParams start;        // where the simplex starts (and tol, inertia: kept)
  bool fitStiffness;         // false: kn stays at start.kn (the native reference engines do not use it)
  int maxEvaluations;        // objective evaluations, each one run of every training toss
  double sizeTol;            // stop when the simplex is this small (GSL's characteristic size, scaled units)
  int workers;
  pdTossProgressFcn* progress;  // nullable: per toss within an evaluation
  void* progressUser;
  FILE* trace;               // nullable: one CSV row per evaluation (see pd_toss_fit_trace_header)
} pdTossFitOptions;

typedef struct pdTossFitResult {
  pdTossParams params;       // the best point, rounded to 4 significant digits
  double startObjective;     // at the start, on the training tosses
  double objective;          // at params, on the training tosses
  double posErrEndMean, rotErrEndMean;  // its terms
  double bounceDvMean;       // planar experiments: the mean first-bounce velocity error, m/s (else NAN)
  int failed;                // training tosses that failed at params
  int evaluations;
  bool converged;            // the simplex reached sizeTol (else maxEvaluations ended it)
} pdTossFitResult;

// Fits μ, e (and k_n) with GSL's Nelder–Mead simplex (nmsimplex2) to minimise
//   J = mean over the training tosses of the end position error (cube widths)
//     + mean over the training tosses of the end rotation error (rad)
//     [+ planar experiments: mean first-bounce velocity error / PD_TOSS_BOUNCE_SCALE].
// Scaled coordinates: log10 μ ∈ [−2, log10 1.5], e ∈ [PD_TOSS_RESTITUTION_MIN, 1], log10 k_n ∈ [4, 8];
// a point outside is evaluated at the nearest point inside plus a penalty of 1 per unit of distance, so
// the simplex stays in the box. Start steps: 0.15 (μ × 1.4), 0.15 (e), 0.5 (k_n × 3.2).
// Returns false with a message in `why` when the work was stopped or a worker died.
bool pd_toss_fit(const pdTossFitOptions* options, pdTossFitResult* result, char* why, size_t whySize);
void pd_toss_fit_trace_header(FILE* out);

// The held-out split of a selection (set indices, file order): training = the selected tosses at even
// positions, every trainEvery-th of them; test = those at odd positions. train and test hold count each.
void pd_toss_fit_split(const int* indices, int count, int trainEvery, int* train, int* trainCount, int* test,
                       int* testCount);

// One engine of a fit over several engines (pd_toss_fit_engines).
typedef struct pdTossFitEngine {
  const char* label;    // soft, ode-native, ...: messages, progress
  const char* variant;  // implicit, native, matched, shift1
  pdTossEngine engine;
  pdTossParams start;
  bool built;           // this build has its adapter
  bool fit;             // fitted (false: not built, or the noise floor, which has no parameters)
  bool fitStiffness;    // k_n too (the soft engine, and the matched variants)
} pdTossFitEngine;

// Fits each engine with fit set (pd_toss_fit with `common`'s set, training tosses, budget, workers, progress and
// trace; its engine, start and fitStiffness are each engine's), in order. results[e] is zero and fitted[e] its
// start for an engine not fitted. `started` (nullable) is called before each fit, with the engine. Returns false
// with a message in `why` when a fit was stopped.
bool pd_toss_fit_engines(const pdTossFitOptions* common, const pdTossFitEngine* engines, int count,
                         void (*started)(const pdTossFitEngine* engine, void* user), void* user,
                         pdTossFitResult* results, pdTossParams* fitted, char* why, size_t whySize);

// fit.csv: its header and one row per engine (status ok, not built or no parameters; what was fitted, the
// fitted values and objective, the split's sizes and the start).
void pd_toss_fit_csv(FILE* out, const pdTossFitEngine* engines, int count, const pdTossFitResult* results,
                     int trainCount, int trainEvery, int testCount);
