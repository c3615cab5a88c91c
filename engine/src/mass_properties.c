// polydyn — exact mass properties of a uniform convex polyhedron.
//
// The divergence theorem turns the volume integrals of 1, x and x xᵀ into sums over the faces. We
// evaluate it as a sum of tetrahedra (r, a, b, c) with r the vertex average and (a, b, c) the fan
// triangles of each face: for a tetrahedron with corners 0, a, b, c,
//   ∫ dV = det/6,  ∫ x dV = det/24 (a + b + c),  ∫ x xᵀ dV = det/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c,
// with det = a · (b × c). Taking r near the centre keeps every term small, so the result does not
// depend on where the caller's origin is (to roundoff), and faces wound CCW give positive det.
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "polydyn/polyhedron.h"


static void add_outer(double m[3][3], pdVec3 a, double s) {
  const double v[3] = {a.x, a.y, a.z};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] += s * v[i] * v[j];
}

// Symmetric eigen-decomposition with GSL: ascending moments, right-handed axes as columns.
static bool principal_axes(const pdMat3* inertia, double moments[3], pdMat3* axes) {
  double a[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[3 * i + j] = 0.5 * (inertia->m[i][j] + inertia->m[j][i]);
  gsl_matrix_view A = gsl_matrix_view_array(a, 3, 3);
  gsl_vector* eval = gsl_vector_alloc(3);
  gsl_matrix* evec = gsl_matrix_alloc(3, 3);
  gsl_eigen_symmv_workspace* w = gsl_eigen_symmv_alloc(3);
  int status = gsl_eigen_symmv(&A.matrix, eval, evec, w);
  gsl_eigen_symmv_free(w);
  if (status == GSL_SUCCESS) {
    gsl_eigen_symmv_sort(eval, evec, GSL_EIGEN_SORT_VAL_ASC);
    for (int k = 0; k < 3; ++k) {
      moments[k] = gsl_vector_get(eval, k);
      // sign convention: the largest component of each axis is positive, then the third axis is
      // made the cross product of the first two so the axes form a rotation
      int big = 0;
      for (int i = 1; i < 3; ++i)
        if (fabs(gsl_matrix_get(evec, i, k)) > fabs(gsl_matrix_get(evec, big, k))) big = i;
      double sign = gsl_matrix_get(evec, big, k) < 0.0 ? -1.0 : 1.0;
      for (int i = 0; i < 3; ++i) axes->m[i][k] = sign * gsl_matrix_get(evec, i, k);
    }
    pdVec3 e0 = {axes->m[0][0], axes->m[1][0], axes->m[2][0]};
    pdVec3 e1 = {axes->m[0][1], axes->m[1][1], axes->m[2][1]};
    pdVec3 e2 = pd_v3_cross(e0, e1);
    axes->m[0][2] = e2.x, axes->m[1][2] = e2.y, axes->m[2][2] = e2.z;
  }
  gsl_vector_free(eval);
  gsl_matrix_free(evec);
  return status == GSL_SUCCESS;
}

bool pd_mass_properties(const pdPolyhedron* p, double density, pdMassProperties* out, pdError* why) {
  PD_ASSERT(density > 0.0 && p->vertexCount > 0);
  memset(out, 0, sizeof *out);
  pdVec3 r = {0, 0, 0};
  for (int v = 0; v < p->vertexCount; ++v) r = pd_v3_add(r, p->vertices[v]);
  r = pd_v3_scale(r, 1.0 / p->vertexCount);

  double volume6 = 0.0;         // 6 ∫ dV
  pdVec3 first24 = {0, 0, 0};   // 24 ∫ (x - r) dV
  double second[3][3] = {{0}};  // 120 ∫ (x - r)(x - r)ᵀ dV
  for (int f = 0; f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    const int* idx = p->faceVertices + face->first;
    pdVec3 a = pd_v3_sub(p->vertices[idx[0]], r);
    for (int i = 1; i + 1 < face->count; ++i) {
      pdVec3 b = pd_v3_sub(p->vertices[idx[i]], r), c = pd_v3_sub(p->vertices[idx[i + 1]], r);
      double det = pd_v3_dot(a, pd_v3_cross(b, c));
      pdVec3 s = pd_v3_add(a, pd_v3_add(b, c));
      volume6 += det;
      first24 = pd_v3_muladd(first24, det, s);
      add_outer(second, a, det);
      add_outer(second, b, det);
      add_outer(second, c, det);
      add_outer(second, s, det);
    }
  }
  double volume = volume6 / 6.0;
  if (!(volume > 0.0) || !isfinite(volume)) {
    pd_error_set(why, NULL, 0, 0, "volume is not positive (%g m^3)", volume);
    return false;
  }
  pdVec3 offset = pd_v3_scale(first24, 1.0 / (24.0 * volume));  // centroid - r
  // covariance about the centroid: ∫ (x-c)(x-c)ᵀ dV = ∫ (x-r)(x-r)ᵀ dV − V (c-r)(c-r)ᵀ
  double cov[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      cov[i][j] = second[i][j] / 120.0 - volume * pd_v3_get(offset, i) * pd_v3_get(offset, j);
  double trace = cov[0][0] + cov[1][1] + cov[2][2];
  out->volume = volume;
  out->mass = density * volume;
  out->centroid = pd_v3_add(r, offset);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out->inertia.m[i][j] = density * ((i == j ? trace : 0.0) - cov[i][j]);
  // exact symmetry (the two triangles of the sum are computed identically, but make it explicit)
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) out->inertia.m[j][i] = out->inertia.m[i][j];

  gsl_error_handler_t* previous = gsl_set_error_handler_off();
  bool ok = principal_axes(&out->inertia, out->principal, &out->principalAxes);
  gsl_set_error_handler(previous);
  if (!ok || !(out->principal[0] > 0.0)) {
    pd_error_set(why, NULL, 0, 0, "inertia tensor is not positive definite");
    return false;
  }
  return true;
}
