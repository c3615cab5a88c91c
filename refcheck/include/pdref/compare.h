// polydyn refcheck — comparing runs of one scene: trajectories in memory and the metrics of
// `polydyn compare` (docs/DESIGN.md §8.1).
//
// Conventions
// - A trajectory holds, per output sample, each moving body's pose and velocity in the model's body frame
//   (pd_state_body), in scene order; every engine's run fills one through its observer.
// - Errors are against a reference trajectory of the same model, taken at the run's sample times (the
//   reference interpolated linearly in x, v, ω and by slerp in q when its samples fall elsewhere).
// - Position error: |x − x_ref| / body size (model body `size`, its mean bounding-box extent); rotation
//   error: the angle of q_ref⁻¹ q, rad, in [0, π]. "final" at the last common sample, "rms" over all
//   samples and moving bodies.
// - Energy: kinetic plus gravitational potential of the moving bodies (springs excluded: the reference
//   engines have none). Drift = (E_end − E_start) / E_scale with E_scale = the largest kinetic energy
//   seen plus |E_start| (never 0 for a scene that moves), so a dissipative scene has drift < 0.
// - Momentum drift (scenes with no fixed body only): |P_end − P_start − M g t_end| / (M · v_scale),
//   v_scale = the largest body speed seen: what the contacts between moving bodies did not conserve.
// - Penetration: the separating-axis minimum depth (engine/src/interference.h) of every pair of bodies at
//   every sample, the deepest over the run, divided by the smaller body's size.
// - Restitution per impact: from apex heights along −g, e = √((z_after − z_contact)/(z_before − z_contact))
//   for each bounce of a moving body (a local minimum of its height between two apexes, rising by more
//   than PD_COMPARE_BOUNCE_MIN_RISE of its size): exact for a free bounce under gravity whatever the
//   sample rate, meaningless for rolling or sliding (then there is no bounce to list).
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/state.h"

// A bounce must lift the body by this fraction of its size to count: resting contact jitters far less
// (springs deflect ~1e-3 of the size), a real bounce lifts it visibly.
#define PD_COMPARE_BOUNCE_MIN_RISE 0.01

typedef struct pdTrajectory {
  int movingCount;
  long samples, capacity;
  double* t;            // (samples)
  pdBodyState* bodies;  // (samples × movingCount), sample-major
} pdTrajectory;

pdTrajectory* pd_trajectory_create(const pdModel* model);
void pd_trajectory_free(pdTrajectory* trajectory);
// Observer (pdObserverFcn) appending the state's moving bodies; `user` is the pdTrajectory. Aborts when
// memory runs out (as every other allocation of the CLI).
bool pd_trajectory_observe(const pdModel* model, const pdState* state, void* user);
// Moving body `movingIndex` at time t (clamped to the trajectory's span), interpolated.
pdBodyState pd_trajectory_at(const pdTrajectory* trajectory, int movingIndex, double t);

typedef struct pdCompareMetrics {
  double posErrFinal, posErrRms;  // no unit (position / body size)
  double rotErrFinal, rotErrRms;  // rad
  double energyDriftRel;          // no unit, < 0 when energy was lost
  double momentumDriftRel;        // no unit; NAN when the scene has a fixed body
  double maxPenetrationOverSize;  // no unit; <= 0 when nothing ever overlapped (the closest gap, negated)
  int impacts;                    // bounces found
  double restitution[16];         // e of the first min(impacts, 16) bounces, in time order
  int impactBody[16];             // their body (model index)
} pdCompareMetrics;

// Metrics of `run` against `reference` (nullable: then the error fields are NAN).
pdCompareMetrics pd_compare_metrics(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference);
