// polydyn (internal) — broad phase: which body pairs have overlapping axis-aligned boxes
// (incremental sweep and prune on all three axes, DESIGN §3.2 and §3.6; Baraff 1992, Cohen et al. 1995).
//
// Conventions
// - A box is closed: [lo, hi] on each world axis. Two boxes overlap when, on every axis,
//   a.lo <= b.hi + margin and b.lo <= a.hi + margin; boxes that touch exactly (gap 0) overlap.
//   The margin (m, >= 0) is fixed at creation; 0 gives the plain closed-box test.
// - Pairs are (a, b) with a < b, never both fixed, listed sorted by (a, b) — a deterministic order
//   that does not depend on the history of updates.
//
// Cost: the endpoints of the boxes along each of the three axes stay sorted between updates, and a
// persistent set holds the pairs overlapping on all three. An update re-sorts each axis by insertion
// sort, ~n + s for s swaps of neighbouring endpoints (coherent motion: few per endpoint), and touches
// the set only when a swap starts or ends a pair's overlap along one axis. A full sort (qsort) of the three
// axes (n log n) and a rebuild of the set by one sweep (~n + pairs overlapping along the sweep axis)
// take over on the first update and when insertion sort exceeds its swap budget (incoherent motion).
// pd_broad_phase_pairs sorts the set, k log k for k pairs, and only when it changed.
// Caveat: s ~ n × (endpoints per metre along an axis) × (distance moved per update, relative to the
// others). For bodies scattered at constant density in a cube, that density grows as n^(2/3), so s
// grows as n^(5/3) × speed and dominates large clouds (reports/bench/broad_phase.md); only a spatial
// subdivision keeps it ~n: from PD_BROAD_PHASE_GRID_MIN_BODIES bodies on, the broad phase is a hashed
// uniform grid rebuilt at every update (broad_grid.h), ~n + k log k whatever the motion.
//
// Memory: pd_broad_phase_create allocates everything, the pair set sized for
// PD_BROAD_PHASE_PAIRS_PER_BODY pairs per body. An update that needs more doubles the set (counted in
// the stats); nothing else allocates after creation, and pd_broad_phase_pairs never does.
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

// Pairs per body the pair set holds without growing (at most half its slots in use). A resting pile
// gives each body a handful of neighbours; scattered bodies far fewer. Denser scenes double the set.
#define PD_BROAD_PHASE_PAIRS_PER_BODY 4

// Work counters (for benchmarks and warnings; they change no result). The "last update" ones are reset
// by each pd_broad_phase_update.
typedef struct pdBroadPhaseStats {
  long long swaps;          // swaps of neighbouring endpoints by insertion sort in the last update, 3 axes
  long long overlapEvents;  // of those, a minimum passing another body's maximum: that pair's overlap
                            // along one axis begins or ends, and the other two axes are checked
  long long pairChanges;    // of those events, the ones that added a pair to the set or removed one
  bool fullSort;            // the last update fully sorted (some of) the axes and rebuilt the set
  long long fullSorts;      // such updates since creation
  int sweepAxis;            // axis of the last rebuild sweep, the one with the fewest overlapping pairs
                            // (0 = x, 1 = y, 2 = z; -1 before the first update)
  long long sweepTests;     // pairs overlapping along sweepAxis in that sweep (each tested on the others)
  int pairs;                // pairs in the set: overlapping on all three axes, not both fixed
  int setCapacity;          // pairs the set holds before it must grow
  int setGrowths;           // times an update doubled the set since creation
  // the grid method (stats.grid): its last update
  bool grid;                // the grid method is in use (the counters above stay 0)
  double cell;              // m: edge of a grid cell
  long long cellEntries;    // (box, cell) entries
  int largeBoxes;           // boxes too large for the grid, tested against every box
  long long boxTests;       // box–box overlap tests
} pdBroadPhaseStats;

// Which method finds the pairs. Auto: sweep and prune below PD_BROAD_PHASE_GRID_MIN_BODIES bodies, the
// grid from there on (reports/bench/broad_phase.md measures both; the crossover sets the constant).
typedef enum pdBroadPhaseMethod { pd_broadPhaseAuto, pd_broadPhaseSweep, pd_broadPhaseGrid } pdBroadPhaseMethod;
#define PD_BROAD_PHASE_GRID_MIN_BODIES 1000

typedef struct pdBroadPhase pdBroadPhase;

// `fixed` (bodyCount flags, or NULL when no body is fixed) is copied. bodyCount >= 0, margin >= 0 (m).
// Returns NULL only when memory runs out.
pdBroadPhase* pd_broad_phase_create(int bodyCount, const bool* fixed, double margin);  // method auto
pdBroadPhase* pd_broad_phase_create_with(int bodyCount, const bool* fixed, double margin,
                                         pdBroadPhaseMethod method);
void pd_broad_phase_free(pdBroadPhase* bp);

// Takes this step's boxes (bodyCount of them, finite, lo <= hi; fixed bodies included, their boxes
// unchanged), re-sorts the endpoints and updates the pair set. The boxes are copied. Allocates only to
// grow the pair set. Returns false only when that allocation fails: the pairs are then unknown
// (pd_broad_phase_pairs must not be called) until an update returns true (it rebuilds the set).
bool pd_broad_phase_update(pdBroadPhase* bp, const pdAabb* boxes);

// Writes the overlapping pairs of the last update into out[0 .. min(count, capacity)) sorted by (a, b),
// and returns count, the number of overlapping pairs. When count > capacity only `capacity` of them
// (an unspecified subset, still sorted) are written: grow the buffer to at least count and call again
// (the result depends only on the last update). No allocation. out may be NULL when capacity is 0.
int pd_broad_phase_pairs(pdBroadPhase* bp, pdPair* out, int capacity);

// pd_broad_phase_update with these boxes, then pd_broad_phase_pairs into *pairs (capacity *capacity), which is grown
// to twice the count and filled again when the pairs do not fit: the caller grows its own per-pair arrays when
// *capacity changed. For the callers that run it between steps (the contact search, the islands' partition): it
// allocates, and memory that is not there is fatal (PD_ASSERT), like every other allocation of the engine's loop.
int pd_broad_phase_pairs_grown(pdBroadPhase* bp, const pdAabb* boxes, pdPair** pairs, int* capacity);

pdBroadPhaseStats pd_broad_phase_stats(const pdBroadPhase* bp);

// The exact box of a polyhedron (body frame) at pose (x, R): world = x + R·p for every vertex p,
// min and max per axis of those computed world points.
pdAabb pd_aabb_of(const pdPolyhedron* p, pdVec3 x, const pdMat3* R);
