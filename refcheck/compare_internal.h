// polydyn refcheck — the parts of compare.c that compare_detail.c uses too (conventions in compare.h).
#pragma once

#include "pdref/compare.h"

// Moving body k at sample s.
const pdBodyState* pd_trajectory_sample(const pdTrajectory* trajectory, long s, int k);
// Centre of mass and rotation of body `body` (model index, fixed bodies too) at sample s.
pdVec3 pd_trajectory_body_position(const pdModel* model, const pdTrajectory* run, long s, int body, pdMat3* R);
// Kinetic + gravitational potential energy of moving body k at sample s, J; its kinetic part in *kinetic.
double pd_trajectory_body_energy(const pdModel* model, const pdTrajectory* trajectory, long s, int k, double* kinetic);
// Separating-axis depth of bodies i and j at sample s over the smaller size (negative: apart); the axis
// (unit, world, from i to j) in *axis when not NULL.
double pd_pair_penetration(const pdModel* model, const pdTrajectory* run, long s, int i, int j, pdVec3* axis);
// Angle of q_ref⁻¹ q, rad in [0, π].
double pd_rotation_angle(pdQuat q, pdQuat ref);
// Position error of moving body k over its size, and the rotation angle (rad) in *rotation.
double pd_pose_error(const pdModel* model, int k, const pdBodyState* b, const pdBodyState* ref, double* rotation);
