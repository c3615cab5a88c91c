// polydyn refcheck — where, when and why runs of one scene differ: what `polydyn compare` writes beside
// metrics.csv (reports/FORMATS.md, docs/compare-report.md).
//
// Conventions (those of compare.h, plus):
// - A run's error at a sample is per moving body: position |x − x_ref| / size and rotation angle (rad); its
//   divergence measure is max over bodies of max(position, rotation), compared with
//   PD_COMPARE_DIVERGENCE_THRESHOLD.
// - Chaos: the reference repeated at a perturbed tolerance (the "chaos run") differs from the reference
//   only by round-off and truncation far below any engine's; its error c(t) against the reference is the
//   scene's own divergence. A run's error e(t) exceeds what chaos explains from the first sample where
//   e(t) > max(threshold, PD_COMPARE_CHAOS_FACTOR · c(t)).
// - Impacts are found in trajectories alone (every engine alike): a moving body whose velocity changes
//   over one sample interval by more than gravity can explain (PD_IMPACT_SPEED_CHANGE_OVER_G · |g| dt, at
//   least PD_IMPACT_MIN_SPEED_CHANGE), consecutive such intervals one impact; its partner, of the bodies
//   within PD_IMPACT_TOUCH of touching it just after its largest change (separating-axis test), the one
//   that came at it fastest, or the deepest when none approached; the normal that test's axis, from body_b into body_a (body_a < body_b in scene order). Normal and
//   tangential speeds are those of the bodies' material points at the touching point (the centroid of the
//   smaller body's vertices that lead towards the other), before at the first sample of the impact and
//   after at the first sample past it, each moved
//   back or on in free flight to the moment of contact and of separation (from the gap the separating-axis
//   test gives at those samples).
// - Contact tallies come from a run's contact reports (the soft engine's pd_state_contact, ODE's and Bullet's
//   through their adapters: refcheck.h): per moving body
//   and sample, the contacts it takes part in, the sum of their normal forces (N) and the largest slip speed
//   of its sliding contacts (m/s; NAN when none slides). Slip speed: |tangential part of the contact
//   point's relative velocity| (body_a's point minus body_b's).
#pragma once

#include <stdbool.h>

#include "pdref/compare.h"
#include "polydyn/model.h"
#include "polydyn/state.h"

// A tenth of a body's size, or 0.1 rad: the pose difference a person sees in a replay; the threshold of
// the sweep's horizon of predictability too.
#define PD_COMPARE_DIVERGENCE_THRESHOLD 0.1
// An engine's error counts as beyond chaos only an order of magnitude above the scene's own divergence:
// once chaos has grown to the size of the differences, two equally good runs differ by as much.
#define PD_COMPARE_CHAOS_FACTOR 10.0
// The chaos run's tolerance over the reference's: a perturbation of the same nature as the reference's
// own error, and as small.
#define PD_COMPARE_CHAOS_TOL_SCALE 2.0
// Resting contact changes a body's velocity by |g| dt per interval, sliding by at most √(1+μ²) |g| dt
// (μ ≤ 1): twice |g| dt is an impact. In a scene without gravity a speed change of 1 mm/s is.
#define PD_IMPACT_SPEED_CHANGE_OVER_G 2.0
#define PD_IMPACT_MIN_SPEED_CHANGE 1e-3
// A restitution is given only where the bodies approached at least at this share of the impact's change of
// relative velocity ((1 + e) times the approach for a collision of the two): a smaller approach means another
// body changed the speed (a pile's neighbours), and −v_after/v_before would be noise over a tiny number.
#define PD_IMPACT_MIN_APPROACH_SHARE 0.1
// Bodies this close (over the smaller size) or overlapping touch, for the choice of an impact's partner: a
// contact's deflection is at most a hundredth of the size (the scene's deflection setting).
#define PD_IMPACT_TOUCH 0.01
// The vertices of the feature that lands lie this close (a share of the body's size) to its support plane.
#define PD_IMPACT_FEATURE_SPAN 1e-3
// Impacts of two runs are the same impact when their bodies agree and their times lie this close, s:
// a few samples at the usual rates, well below the time between a bouncing body's impacts.
#define PD_IMPACT_MATCH_WINDOW 0.05

// Per moving body and sample.
typedef struct pdBodySample {
  double posErr, rotErr;  // against the reference (NAN without one)
  double energy;          // kinetic + gravitational potential, J
  double penetration;     // deepest overlap with any other body over the smaller size (negative: the gap)
} pdBodySample;

// The body samples of `run` at its samples sampleIndex[0 .. count-1] (count × movingCount, sample-major;
// the caller frees it). reference may be NULL.
pdBodySample* pd_compare_body_samples(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference,
                                      const long* sampleIndex, long count);

// The largest error of `run` against `reference` at its sample s: the body (moving index) and whether the
// rotation is the larger part.
double pd_compare_sample_error(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference, long s,
                               int* body, bool* rotation);

typedef struct pdDivergence {
  bool diverged;        // the error exceeded the threshold at some sample
  double t;             // s, the first such sample
  int body;             // moving index of the body with the largest error there
  bool rotation;        // that error is the rotation's
  double error;         // its value
  double beyondChaos;   // s, first sample past what chaos explains (see above); NAN when never
} pdDivergence;

// First divergence of `run` against `reference`; chaos (nullable) gives beyondChaos (NAN without it).
pdDivergence pd_compare_divergence(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference,
                                   const pdTrajectory* chaos, double threshold);

typedef struct pdImpact {
  double t;                       // s
  int bodyA, bodyB;               // model indices, bodyA < bodyB
  double vnBefore, vnAfter;       // m/s, relative normal speed (< 0 approaching)
  double restitution;             // −vnAfter / vnBefore; NAN when they hardly approached (see above)
  double restitutionRequested;    // the pair's e (pd_model_pair_contact)
  double tangentialChange;        // m/s, |change of the relative tangential velocity|
  int match;                      // index of the same impact in the reference's list, −1 when none
} pdImpact;

// Every impact of `run` in time order (then bodies); *impacts is allocated (the caller frees it).
int pd_compare_impacts(const pdModel* model, const pdTrajectory* run, pdImpact** impacts);
// Sets each impact's match to the reference's impact of the same bodies nearest in time within
// PD_IMPACT_MATCH_WINDOW, each reference impact taken once, nearest pairs first.
void pd_compare_match_impacts(pdImpact* impacts, int count, const pdImpact* reference, int referenceCount);

typedef struct pdContactTally {
  int contacts;
  double normalForce;  // N
  double slipSpeed;    // m/s, NAN when none of its contacts slides
} pdContactTally;

typedef struct pdFrictionPoint {
  double t;
  int bodyA, bodyB;  // model indices
  double fn, ft;     // N, |ft|
  double slipSpeed;  // m/s
  bool slip;         // the engine's mode: sliding (true) or sticking
} pdFrictionPoint;

typedef struct pdContactLog {
  int movingCount;
  long samples, capacity;
  pdContactTally* tallies;  // (samples × movingCount), sample-major
  long points, pointCapacity;
  pdFrictionPoint* friction;  // every contact with a normal force at every sample
} pdContactLog;

pdContactLog* pd_contact_log_create(const pdModel* model);
void pd_contact_log_free(pdContactLog* log);
// Observer (pdObserverFcn) appending the state's contacts; `user` is the pdContactLog.
bool pd_contact_log_observe(const pdModel* model, const pdState* state, void* user);
// The same for a reference engine's contacts at a sample (pdRefOptions.contactObserver).
void pd_contact_log_add(const pdModel* model, const pdState* state, const pdContactReport* contacts, int count,
                        void* user);
