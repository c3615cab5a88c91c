// polydyn (internal) — interference of two convex polyhedra (paper §4.3, docs/DESIGN.md §6.1): the
// separating-axis test over the faces of their Minkowski difference, with a per-pair cache of the
// last separating feature (temporal coherence, §7).
//
// Conventions
// - Poses map body frames to the world: x_world = x + R · x_body (R a rotation matrix).
// - Every axis u is a unit vector pointing from A to B. The overlap of A and B along u is
//       overlap(u) = max_{p in A} u·p − min_{q in B} u·q      (m),
//   the length by which B's projection would have to move along +u to stop overlapping A's.
// - Candidate axes: each face normal of A (u = n_A); each face normal of B reversed (u = −n_B); and,
//   for each edge pair (one edge of A, one of B) that forms a face of the Minkowski difference (their
//   Gauss-map arcs cross), u = ±(e_A × e_B) / |e_A × e_B|, the sign making u an outward normal of A
//   at its edge. These are exactly the face normals of the Minkowski difference A ⊖ B.
// - depth = min over candidate axes of overlap(u), in m. depth > 0 means overlap: the bodies
//   interpenetrate, and depth is the penetration depth (the shortest translation of B that separates
//   them). depth < 0 means separated, and −depth is the gap along the best candidate axis (a lower
//   bound on their distance). depth == 0 (exact touching) counts as interfering: bodies are closed.
// - The verdict has no tolerance: separated ⇔ some candidate axis has overlap < 0 as computed.
//   Edge pairs whose directions are parallel to PD_SAT_PARALLEL_TOL are skipped (see below).
#pragma once

#include <stdbool.h>

#include "polydyn/polyhedron.h"
#include "polydyn/vecmath.h"

// Edge pairs with |e_A × e_B| < PD_SAT_PARALLEL_TOL · |e_A| · |e_B| (the sine of their angle, no unit)
// are not candidate axes. Parallel edges never form a Minkowski face (their arcs lie on one great
// circle; the face axes at the arcs' ends bound the overlap there), and near-parallel ones form a
// sliver face whose normal the cross product gives only to ~1e-16/sin(angle): at sin < 1e-8 that
// error (× the edge length) would exceed the sliver's own effect on the depth (~sin × edge length).
#define PD_SAT_PARALLEL_TOL 1e-8

// The feature that defines an axis.
typedef enum pdSatFeature {
  PD_SAT_NONE = 0,    // no axis (empty cache)
  PD_SAT_FACE_A = 1,  // face `a` of A: u = n_A
  PD_SAT_FACE_B = 2,  // face `b` of B: u = −n_B
  PD_SAT_EDGES = 3,   // edge `a` of A and edge `b` of B: u ∝ e_A × e_B
  PD_SAT_APART = 4,   // in a cache only (PD_SAT_VERDICT): the direction along which GJK last proved them apart
} pdSatFeature;

// Per-pair cache (zero-initialised = empty): the feature of the last call's result axis. A stale or
// foreign entry (indices out of range, or no longer a candidate axis) is ignored. Never changes the
// verdict; changes the reported depth of a separated pair only in PD_SAT_FIRST_SEPARATING mode.
typedef struct pdSatCache {
  pdSatFeature kind;
  int a, b;        // face or edge index in A (FACE_A, EDGES), face or edge index in B (FACE_B, EDGES); else -1
  pdVec3 apart;    // PD_SAT_APART: that direction in A's body frame (GJK's d, pointing from B − A's points to
                   // the origin); read only by PD_SAT_VERDICT, ignored by the other modes
} pdSatCache;

// The cached feature of one pair of bodies (a < b), kept from one query to the next in a list sorted by (a, b)
// (contact_search.c, islands.c's partition).
typedef struct pdPairSatCache {
  int a, b;
  pdSatCache sat;
} pdPairSatCache;

// The cached feature of pair (a, b) in list[0 .. count), sorted by (a, b), an empty cache when the pair is not
// listed. The pairs are asked in ascending order: the search goes on from *cursor, which it advances (a merge).
static inline pdSatCache pd_pair_sat_cache_find(const pdPairSatCache* list, int count, int* cursor, int a, int b) {
  int i = *cursor;
  while (i < count && (list[i].a < a || (list[i].a == a && list[i].b < b))) ++i;
  *cursor = i;
  if (i < count && list[i].a == a && list[i].b == b) return list[i].sat;
  return (pdSatCache){PD_SAT_NONE, -1, -1, {0, 0, 0}};
}

typedef enum pdSatMode {
  // Stop at the first separating axis, trying the cached feature first: the fast verdict for a
  // simulation step. When separated, depth < 0 is that axis's overlap (not necessarily the minimum).
  PD_SAT_FIRST_SEPARATING = 0,
  // Evaluate every candidate axis: depth is the minimum whether separated or not. The cache is not used
  // to shorten the search (it is still updated), so the result does not depend on it.
  PD_SAT_MIN_DEPTH = 1,
  // The verdict alone, what the contact search asks: touching or not. After the cached feature, a GJK search
  // over the Minkowski difference looks for one of two certificates (interference.c, "Certificates"): a hull of
  // difference points holding a ball of radius m = PD_GJK_MARGIN_REL × the pair's size about the origin
  // (overlap), or a direction along which the bodies are apart by more than m (separation). Where GJK finds
  // neither, the pair is within about m of touching and is called touching, with depth 0 (where GJK's own
  // bookkeeping goes wrong, rarely, the PD_SAT_FIRST_SEPARATING search decides instead). So "separated" is
  // always PD_SAT_FIRST_SEPARATING's verdict too, and so is "touching" except for pairs apart by about m at
  // most. The result has kind PD_SAT_NONE and a = b = -1 (unless the cached feature separates or the search
  // decides: then it is PD_SAT_FIRST_SEPARATING's result); its depth is a lower bound on the penetration
  // (certified overlap), 0 (within the margin), or the gap along its axis, negated (separation); its axis is
  // zero when touching.
  // The cache is left as it was when touching and holds the separating direction (PD_SAT_APART) after a
  // certified separation, tried first next time (as a cached feature is). Polyhedra without a pdSatIndex (filled
  // in by hand) get the PD_SAT_FIRST_SEPARATING search instead.
  PD_SAT_VERDICT = 2,
} pdSatMode;

// The verdict mode's margin, relative to the pair's coordinate size (interference.c, cull_bounds: the body
// centres' distances from their origins, their circumradii and the distance between the origins, summed): 10
// times the largest error of a candidate axis's overlap as computed (~1e-8 of the size: the sliver edge pairs,
// PD_SAT_PARALLEL_TOL), so that a certified overlap is the separating-axis search's too; and about the widest
// gap that may be called touching, far below any deflection of the contact model (δ_max ~1e-3 of the size).
#define PD_GJK_MARGIN_REL 1e-7

typedef struct pdSatResult {
  bool separated;          // depth < 0
  double depth;            // m, see the conventions above
  pdVec3 axis;             // world, unit, from A to B: the axis achieving `depth`
  pdSatFeature kind;       // the feature defining `axis`
  int a, b;                // its indices (as in pdSatCache)
  int minkowskiEdgePairs;  // edge pairs that passed the Gauss-map test and were evaluated (work counter; pairs
                           // the culling bounds skip are not counted)
} pdSatResult;

// The test's structures, built once with the polyhedron (polyhedron.c, and again when it is translated) so
// that the test allocates nothing. For every polyhedron: its edges as records and the ball inside it, for
// the culling bounds (interference.c), which change no result. For polyhedra with many features, search
// structures too: vertex adjacency, so that each face axis finds the other body's
// support by walking downhill from the previous one, and every edge's Gauss-map arc enclosed in a
// spherical cap, the arcs sorted along the body's z axis, so that an edge of B meets only the edges of A
// whose caps share its z band. Neither changes a result: a downhill walk on a convex polyhedron ends at
// the minimum, and arcs whose caps' z bands are apart (by PD_SAT_CAP_MARGIN) cannot cross. Polyhedra
// with fewer than PD_SAT_INDEX_MIN_EDGES edges get no search structures (a cube is searched faster
// exhaustively).
#define PD_SAT_INDEX_MIN_EDGES 48
void pd_sat_index_build(pdPolyhedron* p);
// An edge is acute when its faces' outward normals are more than 90° apart by more than this cosine (a box's right
// angles, rounded, are not).
#define PD_ACUTE_EDGE_COS 1e-9
// Does p have an edge whose faces meet at less than 90°? (Kept with the index; formed here for a polyhedron without.)
// Where it has none, the contact search meets only the paper's contacts (contact_analysis.c, "a vertex beyond an
// acute edge").
bool pd_polyhedron_has_acute_edge(const pdPolyhedron* p);
// Are p's vertices the 8 corners of a box aligned with its body frame (kept with the index; false without one)?
// Sets *lo and *hi, the box's corners, then. pd_aabb_of takes its bounds from two corners instead of 8 vertices.
bool pd_polyhedron_cuboid(const pdPolyhedron* p, pdVec3* lo, pdVec3* hi);
void pd_sat_index_free(struct pdSatIndex* index);

// Do A (at xA, RA) and B (at xB, RB) interfere? Fills *out and returns !out->separated. Equal-depth
// ties go to the first axis in the order: faces of A, faces of B, edge pairs (B's edges outer, A's inner),
// by index; so in PD_SAT_MIN_DEPTH mode the result is a function of the poses alone. `cache` may be
// NULL; when given it is read first (PD_SAT_FIRST_SEPARATING) and overwritten with the result's feature.
// No allocation; cost O(F_A·V_B + F_B·V_A + E_A·E_B) at worst, much less with the search structures.
bool pd_interference(const pdPolyhedron* A, pdVec3 xA, const pdMat3* RA, const pdPolyhedron* B, pdVec3 xB,
                     const pdMat3* RB, pdSatMode mode, pdSatCache* cache, pdSatResult* out);
