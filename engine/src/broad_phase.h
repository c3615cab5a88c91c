// polydyn (internal) — broad phase: which body pairs have overlapping axis-aligned boxes
// (sweep and prune, DESIGN §3.2 and §3.6).
//
// Conventions
// - A box is closed: [lo, hi] on each world axis. Two boxes overlap when, on every axis,
//   a.lo <= b.hi + margin and b.lo <= a.hi + margin; boxes that touch exactly (gap 0) overlap.
//   The margin (m, >= 0) is fixed at creation; 0 gives the plain closed-box test.
// - Pairs are (a, b) with a < b, never both fixed, listed sorted by (a, b) — a deterministic order
//   that does not depend on the history of updates.
// - Sweep axis: the world axis along which the box centres have the largest variance, chosen at the
//   first update and switched (with a full re-sort) only when another axis's variance exceeds the
//   current one's by the factor PD_BROAD_PHASE_AXIS_SWITCH; ties go to the lowest axis (x first).
//   The choice changes the cost, never the result.
//
// Cost: endpoints along the sweep axis stay sorted between updates and are re-sorted by insertion
// sort, ~n when motion is coherent; a merge sort (n log n) takes over on the first update, on an
// axis switch, or when insertion sort exceeds its move budget (incoherent motion). The sweep then
// costs ~n + (pairs overlapping along the sweep axis), each such pair tested on the other two axes.
//
// Memory: pd_broad_phase_create allocates everything; update and pairs never allocate.
#pragma once

#include <stdbool.h>

#include "polydyn/polyhedron.h"
#include "polydyn/vecmath.h"

// An axis-aligned box in world coordinates, m: lo[k] <= hi[k] on each axis k (0 = x, 1 = y, 2 = z).
typedef struct pdAabb {
  double lo[3], hi[3];
} pdAabb;

// A candidate pair of body indices, a < b.
typedef struct pdPair {
  int a, b;
} pdPair;

// Hysteresis of the sweep-axis choice: switch only when another axis's centre variance is this many
// times larger, so that bodies milling about in a roughly isotropic cloud do not re-sort every step.
#define PD_BROAD_PHASE_AXIS_SWITCH 2.0

// Work counters of the last update and pairs call (for benchmarks and warnings; they change no result).
typedef struct pdBroadPhaseStats {
  int axis;             // current sweep axis (0 = x, 1 = y, 2 = z; -1 before the first update)
  long long sortMoves;  // endpoint moves by insertion sort in the last update
  bool fullSort;        // the last update used the merge sort
  long long fullSorts;  // merge sorts since creation
  long long axisTests;  // pairs overlapping along the sweep axis in the last pairs call (tested on the others)
} pdBroadPhaseStats;

typedef struct pdBroadPhase pdBroadPhase;

// `fixed` (bodyCount flags, or NULL when no body is fixed) is copied. bodyCount >= 0, margin >= 0 (m).
// Returns NULL only when memory runs out.
pdBroadPhase* pd_broad_phase_create(int bodyCount, const bool* fixed, double margin);
void pd_broad_phase_free(pdBroadPhase* bp);

// Takes this step's boxes (bodyCount of them, finite, lo <= hi; fixed bodies included, their boxes
// unchanged) and re-sorts the endpoints. The boxes are copied. No allocation.
void pd_broad_phase_update(pdBroadPhase* bp, const pdAabb* boxes);

// Writes the overlapping pairs of the last update into out[0 .. min(count, capacity)) sorted by (a, b),
// and returns count, the number of overlapping pairs. When count > capacity only `capacity` of them
// (an unspecified subset, still sorted) are written: grow the buffer to at least count and call again
// (the result depends only on the last update). No allocation. out may be NULL when capacity is 0.
int pd_broad_phase_pairs(pdBroadPhase* bp, pdPair* out, int capacity);

pdBroadPhaseStats pd_broad_phase_stats(const pdBroadPhase* bp);

// The exact box of a polyhedron (body frame) at pose (x, R): world = x + R·p for every vertex p,
// min and max per axis of those computed world points.
pdAabb pd_aabb_of(const pdPolyhedron* p, pdVec3 x, const pdMat3* R);
