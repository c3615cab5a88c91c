// polydyn refcheck — running a compiled polydyn model in a reference engine (ODE, Bullet).
//
// Both adapters take the compiled pdModel as it is: the same vertices and faces, mass and inertia about
// the centre of mass, the same μ and e per pair (pd_model_pair_contact), gravity and initial state, and
// report each moving body's pose in the model's body frame (origin at the centre of mass, object axes),
// so the run directory they produce is byte-compatible with the soft engine's (docs/outputs.md).
//
// Variants (docs/DESIGN.md §8.1):
//   native   the engine's own hard contact with its restitution ("bounce") and Coulomb friction;
//   matched  the engine's soft contact set to our per-contact k and c (ODE: ERP/CFM for the step;
//            Bullet: contact stiffness and damping), restitution then comes from the damping alone.
// Every setting that changes the answer goes into summary.json under "engine_settings".
//
// A scene feature an engine cannot represent makes create() fail with a message; nothing is approximated
// silently.
#pragma once

#include <stdbool.h>
#include <stdio.h>

#include "polydyn/error.h"
#include "polydyn/model.h"
#include "polydyn/output.h"
#include "polydyn/state.h"

typedef enum pdRefVariant { pd_refNative, pd_refMatched } pdRefVariant;
typedef enum pdOdeFriction {
  pd_odeFrictionPyramid,  // ODE's Approx1 box in the dPlaneSpace frame (√2·μ along the diagonal)
  pd_odeFrictionAligned,  // fdir1 along the slip velocity: isotropic Coulomb to first order
} pdOdeFriction;

// Applied forces (scene `force`). Both engines integrate by semi-implicit Euler: a force held constant over a
// step of h changes the velocity by h·F/m. Each adapter applies F at mid-step, F(t + h/2) with t the step's
// start, at the body's force point (world-oriented R·p from the centre of mass for Bullet, body frame for
// ODE): the step's impulse ∫F dt is then exact for the linear F(t) = F0 + t·Ḟ of the scene language, where the
// step's start would lag it by h·Ḟ/2. pd_ref_run records this in engine_settings.
#define PD_REF_APPLIED_FORCE_SAMPLING                                                                           \
  "F(t + h/2) once per step, held over the step: exact impulse for the linear F(t) of the scene (semi-implicit " \
  "Euler)"

// Default step of the reference engines, s: 1 kHz, the rate both engines' documentation treats as
// accurate for contact; sweeps set other steps explicitly.
#define PD_REF_DEFAULT_STEP 1e-3

typedef struct pdRefOptions {
  pdRefVariant variant;
  double step;                // s, > 0
  pdOdeFriction odeFriction;  // ODE only
  int iterations;             // Bullet: sequential-impulse iterations per step, 0 for the adapter's (100); ODE's
                              // dWorldStep solves its LCP exactly and has none
  // Nullable: called at every output sample with the contacts of the step that ended there (their forces that
  // step's average, their mode from the slip speed: PD_REF_SLIP_SPEED), after pd_ref_run's observer.
  void (*contactObserver)(const pdModel* model, const pdState* state, const pdContactReport* contacts, int count,
                          void* user);
  void* contactUser;
} pdRefOptions;

// A reference engine's contact slides when its points move apart along the surface faster than this, m/s
// (neither engine reports a mode): a millimetre per second, far above a resting contact's creep at 1 ms steps.
#define PD_REF_SLIP_SPEED 1e-3

// Velocity of the material point at p (world, m) of body `body` (model index; a fixed body: zero), m/s.
pdVec3 pd_ref_point_velocity(const pdModel* model, const pdState* state, int body, pdVec3 p);

typedef struct pdRefWorld pdRefWorld;

// One reference engine. The driver (pd_ref_run) calls create once, then step repeatedly, body at every
// output sample, settings_json once, destroy once.
typedef struct pdRefAdapter {
  const char* name;     // "ode", "bullet"
  const char* version;  // of the library, as it reports itself where it can
  // Builds the engine's world from the model. Returns NULL and fills err (naming the body and what the
  // engine cannot represent) on a scene the engine cannot run as written.
  pdRefWorld* (*create)(const pdModel* model, const pdRefOptions* options, pdError* err);
  // Advances by h seconds (one engine step). Returns false when the engine produced a non-finite state.
  bool (*step)(pdRefWorld* world, double h);
  // Pose and velocity of moving body `movingIndex` (0 .. model->movingCount-1) in the model's body frame.
  pdBodyState (*body)(const pdRefWorld* world, int movingIndex);
  // Contacts the engine used in its last step (for the counts in the summary).
  int (*contact_count)(const pdRefWorld* world);
  // Those contacts with their forces averaged over the step (bodies, point, unit normal from B into A, fn and ft
  // on A; features and mode unset), the first min(count, capacity) in out; returns the count.
  int (*contacts)(const pdRefWorld* world, pdContactReport* out, int capacity);
  // One JSON object (no trailing newline) of every setting that changes the answer.
  void (*settings_json)(const pdRefWorld* world, FILE* out);
  void (*destroy)(pdRefWorld* world);
} pdRefAdapter;

// The adapter called `name` ("ode", "bullet"), or NULL when there is none.
const pdRefAdapter* pd_ref_adapter(const char* name);

typedef struct pdRefRunStats {
  long steps;
  long contactSteps;     // steps with at least one contact
  long maxContacts;      // most contacts in one step
  double wallSeconds;    // the engine's world created from the model, then stepped and sampled to the end
  double cpuSeconds;     // the same span in the calling thread's CPU time (what a loaded machine does not inflate)
  bool completed;        // reached tend with finite numbers
  bool refused;          // create() refused the scene (a feature the engine cannot represent)
} pdRefRunStats;

// Runs `model` to its tend in `adapter` and writes the run directory through `writer` (trajectory.csv
// at t = k/sample for every k; when the step does not divide the sample interval it is shortened to the
// next divisor of it, and when it is longer than the sample interval every step is a sample — both
// recorded in the summary). Finishes the writer (pd_run_finish) — also when the engine produced a
// non-finite state (then the summary says completed false and stats->completed is false). Aborts the
// writer, fills err and returns false when create fails, the observer asks to stop (nothing is
// written), or the directory cannot be written. `observer` (nullable) sees every sample too. `writer` may
// be NULL (sweeps: the samples go to the observer only).
bool pd_ref_run(const pdModel* model, const pdRefAdapter* adapter, const pdRefOptions* options,
                pdRunWriter* writer, pdObserverFcn* observer, void* user, pdRefRunStats* stats, pdError* err);
