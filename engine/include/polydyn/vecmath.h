// polydyn — small 3-D vector, quaternion and 3×3 matrix helpers (double precision).
//
// Conventions
// - pdVec3 is a column vector; pdMat3 is row-major, m[r][c].
// - A unit quaternion q = (w, x, y, z) maps body coordinates to world coordinates:
//   x_world = R(q) · x_body.
// - Angles in these helpers are radians; the scene language uses degrees and converts on input.
// - The helpers build their results in named locals, not compound literals: the header is C11 and C++ alike.
#pragma once

#include <math.h>
#include <stdbool.h>

#include "polydyn/api.h"

PD_EXTERN_C_BEGIN

typedef struct pdVec3 {
  double x, y, z;
} pdVec3;

typedef struct pdQuat {
  double w, x, y, z;
} pdQuat;

typedef struct pdMat3 {
  double m[3][3];
} pdMat3;

static inline pdVec3 pd_v3(double x, double y, double z) {
  pdVec3 r = {x, y, z};
  return r;
}
static inline pdVec3 pd_v3_add(pdVec3 a, pdVec3 b) {
  pdVec3 r = {a.x + b.x, a.y + b.y, a.z + b.z};
  return r;
}
static inline pdVec3 pd_v3_sub(pdVec3 a, pdVec3 b) {
  pdVec3 r = {a.x - b.x, a.y - b.y, a.z - b.z};
  return r;
}
static inline pdVec3 pd_v3_scale(pdVec3 a, double s) {
  pdVec3 r = {a.x * s, a.y * s, a.z * s};
  return r;
}
static inline pdVec3 pd_v3_muladd(pdVec3 a, double s, pdVec3 b) {
  pdVec3 r = {a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
  return r;
}
static inline double pd_v3_dot(pdVec3 a, pdVec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline pdVec3 pd_v3_cross(pdVec3 a, pdVec3 b) {
  pdVec3 r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return r;
}
static inline double pd_v3_norm(pdVec3 a) { return sqrt(pd_v3_dot(a, a)); }
static inline pdVec3 pd_v3_normalize(pdVec3 a) {
  double n = pd_v3_norm(a);
  return n > 0.0 ? pd_v3_scale(a, 1.0 / n) : a;
}
static inline bool pd_v3_isfinite(pdVec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline double pd_v3_get(pdVec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

static inline pdQuat pd_quat_identity(void) {
  pdQuat r = {1.0, 0.0, 0.0, 0.0};
  return r;
}
static inline pdQuat pd_quat_mul(pdQuat a, pdQuat b) {
  pdQuat r = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
              a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  return r;
}
static inline pdQuat pd_quat_normalize(pdQuat q) {
  double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  pdQuat r = {q.w / n, q.x / n, q.y / n, q.z / n};
  return r;
}
// Rotation by `angle` radians about `axis` (need not be unit; must be non-zero when angle != 0).
static inline pdQuat pd_quat_from_axis_angle(pdVec3 axis, double angle) {
  pdVec3 u = pd_v3_normalize(axis);
  double s = sin(0.5 * angle);
  pdQuat r = {cos(0.5 * angle), u.x * s, u.y * s, u.z * s};
  return r;
}

static inline pdMat3 pd_mat3_zero(void) {
  pdMat3 r = {{{0}}};
  return r;
}
static inline pdMat3 pd_mat3_identity(void) {
  pdMat3 r = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  return r;
}
static inline pdVec3 pd_mat3_mulv(const pdMat3* a, pdVec3 v) {
  pdVec3 r = {a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
              a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
              a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z};
  return r;
}
// Aᵀ·v
static inline pdVec3 pd_mat3_tmulv(const pdMat3* a, pdVec3 v) {
  pdVec3 r = {a->m[0][0] * v.x + a->m[1][0] * v.y + a->m[2][0] * v.z,
              a->m[0][1] * v.x + a->m[1][1] * v.y + a->m[2][1] * v.z,
              a->m[0][2] * v.x + a->m[1][2] * v.y + a->m[2][2] * v.z};
  return r;
}
static inline pdMat3 pd_mat3_mul(const pdMat3* a, const pdMat3* b) {
  pdMat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
  return r;
}
static inline pdMat3 pd_mat3_transpose(const pdMat3* a) {
  pdMat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a->m[j][i];
  return r;
}

// Rotation matrix of a unit quaternion (body → world).
static inline pdMat3 pd_quat_to_mat3(pdQuat q) {
  double ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z, wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  pdMat3 r = {{{ww + xx - yy - zz, 2 * (xy - wz), 2 * (xz + wy)},
               {2 * (xy + wz), ww - xx + yy - zz, 2 * (yz - wx)},
               {2 * (xz - wy), 2 * (yz + wx), ww - xx - yy + zz}}};
  return r;
}
static inline pdVec3 pd_quat_rotate(pdQuat q, pdVec3 v) {
  pdMat3 r = pd_quat_to_mat3(q);
  return pd_mat3_mulv(&r, v);
}
// Quaternion of a proper rotation matrix (Shepperd's method; sign chosen so w >= 0).
PD_API pdQuat pd_quat_from_mat3(const pdMat3* r);

PD_EXTERN_C_END
