// polydyn — convex polyhedra and their exact mass properties.
//
// Conventions
// - Faces are convex polygons listed counter-clockwise when seen from outside the body, so the
//   right-hand rule gives the outward normal. Every face normal is a unit vector.
// - Face plane: n · x = offset, with n the outward unit normal; a point x is inside the body when
//   n · x <= offset for every face.
// - Edge e joins vertices v[0] → v[1]; face f[0] sees the edge in that direction in its own CCW
//   order (v[0] then v[1]) and face f[1] sees it reversed. Every edge has exactly two faces.
// - A polyhedron is valid when it is convex, closed (V − E + F = 2), every edge is shared by exactly
//   two faces, faces are planar to PD_PLANARITY_TOL_REL and adjacent faces are not coplanar (coplanar
//   facets are merged into one face when the polyhedron is built).
#pragma once

#include <stdbool.h>

#include "polydyn/api.h"
#include "polydyn/error.h"
#include "polydyn/vecmath.h"

PD_EXTERN_C_BEGIN

typedef struct pdEdge {
  int v[2];  // vertex indices
  int f[2];  // face indices: f[0] walks v[0]→v[1], f[1] walks v[1]→v[0]
} pdEdge;

typedef struct pdFace {
  int first;      // index of its first vertex in pdPolyhedron.faceVertices
  int count;      // number of vertices (>= 3)
  pdVec3 normal;  // outward unit normal
  double offset;  // plane: normal · x = offset, m
} pdFace;

struct pdSatIndex;  // the separating-axis test's search structures (engine/src/interference.c)

typedef struct pdPolyhedron {
  int vertexCount, edgeCount, faceCount;
  pdVec3* vertices;   // (vertexCount) m
  pdEdge* edges;      // (edgeCount)
  pdFace* faces;      // (faceCount)
  int* faceVertices;  // (sum of face counts) vertex indices, CCW seen from outside
  // Derived by the constructors below for the interference test (edge records and the ball inside for its
  // culling bounds; for polyhedra with many features, vertex adjacency and the edges' Gauss-map arcs sorted
  // too), and again by pd_polyhedron_translate; NULL on a polyhedron filled in by hand, which the test then
  // searches exhaustively. Owned: pd_polyhedron_free releases it.
  struct pdSatIndex* satIndex;
} pdPolyhedron;

// Geometric tolerances, relative to the polyhedron's size (largest vertex distance from the
// vertex average), with the reason for each.
// Coplanar facets: qhull pre-merges facets within this distance of a neighbour's plane, and the
// validation checks planarity to it; a dihedral angle this close to 180° carries no contact
// information, and points this close together become one vertex.
#define PD_PLANARITY_TOL_REL 1e-9

// Builds the convex hull of `count` points (xyz triples) with qhull. Returns false and fills
// `err` (a short phrase, e.g. "the points are coplanar") when the hull is degenerate (fewer than 4
// non-coplanar points) or qhull fails. Interior points are dropped; coplanar facets are merged.
// On success `out` holds arrays the caller frees with pd_polyhedron_free; on failure it holds none.
// `err` may be NULL; it gets a message only (file "", line and column 0: the caller knows where the shape came
// from), as for every function below with an `err`.
PD_API bool pd_polyhedron_hull(pdPolyhedron* out, const double* points, int count, pdError* err);

// The scene primitives of docs/scene-language.md, already scaled by (sx, sy, sz), in the primitive's own frame
// (origin at its geometric centre, before the shift to the centre of mass):
// - cube: the unit cube [-½, ½]³;
// - prism: regular n-gon inscribed in the circle of diameter 1 in the xy plane (vertex 0 on +x),
//   z from -½ to ½;
// - tprism: as prism, with the top (z = ½) polygon scaled by `taper`;
// - sphere: geodesic polyhedron of diameter 1: an icosahedron subdivided `level` times (each
//   triangle into four), new vertices pushed onto the sphere.
// Return false with `err` only on a degenerate result (cannot happen for valid arguments).
PD_API bool pd_polyhedron_cube(pdPolyhedron* out, const double scale[3], pdError* err);
PD_API bool pd_polyhedron_prism(pdPolyhedron* out, int sides, const double scale[3], double taper, pdError* err);
PD_API bool pd_polyhedron_sphere(pdPolyhedron* out, int level, const double scale[3], pdError* err);

// Checks every invariant listed at the top of this header. Returns false and fills `err` with the
// first violation found.
PD_API bool pd_polyhedron_validate(const pdPolyhedron* p, pdError* err);

// Moves every vertex and plane by `shift` (x → x + shift).
PD_API void pd_polyhedron_translate(pdPolyhedron* p, pdVec3 shift);

// A copy of p into *out, arrays and all (the same numbers, bit for bit), that the caller frees with
// pd_polyhedron_free.
PD_API void pd_polyhedron_copy(pdPolyhedron* out, const pdPolyhedron* p);

// Frees the arrays of *p (not p itself) and zeroes it.
PD_API void pd_polyhedron_free(pdPolyhedron* p);

// Exact mass properties of a uniform-density convex polyhedron (divergence theorem, evaluated as a
// sum of tetrahedra from the vertex average so that results do not depend on the frame's origin).
typedef struct pdMassProperties {
  double volume;         // m³
  double mass;           // kg
  pdVec3 centroid;       // centre of mass in the polyhedron's frame, m
  pdMat3 inertia;        // inertia tensor about the centre of mass, polyhedron axes, kg·m²
  double principal[3];   // principal moments, ascending, kg·m²
  pdMat3 principalAxes;  // columns are the principal axes (right-handed rotation), polyhedron axes
} pdMassProperties;

// `density` in kg/m³ (> 0). Returns false with `err` if the volume is not positive or the inertia
// is not positive definite.
PD_API bool pd_mass_properties(const pdPolyhedron* p, double density, pdMassProperties* out, pdError* err);

PD_EXTERN_C_END
