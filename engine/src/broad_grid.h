// polydyn (internal) — broad phase by a uniform hashed grid, rebuilt at every update: the method for
// large scenes (broad_phase.h chooses it; same conventions: closed boxes, margin, pairs (a, b) with
// a < b, never both fixed, sorted by (a, b)).
//
// Cost per update ~ n + e + k log k for n boxes, e cell entries (a few per box when the cell is twice the
// typical box) and k pairs: linear in n at constant density, whatever the motion, where incremental sweep
// and prune grows as n^(5/3) for a cloud of bodies (broad_phase.h "Caveat").
#pragma once

#include <stdbool.h>

#include "broad_phase.h"

typedef struct pdBroadGrid pdBroadGrid;

// Work counters of the last update.
typedef struct pdBroadGridStats {
  double cell;      // m: edge of a grid cell
  long long entries;  // (box, cell) entries in the hash grid
  int large;        // boxes too large for the grid, tested against every box
  long long tests;  // box–box overlap tests
} pdBroadGridStats;

// `fixed` (bodyCount flags or NULL) is copied. Returns NULL when memory runs out.
pdBroadGrid* pd_broad_grid_create(int bodyCount, const bool* fixed, double margin);
void pd_broad_grid_free(pdBroadGrid* grid);

// Bins this update's boxes and finds every overlapping pair, sorted. Allocates only to grow its arrays
// (a larger scene or denser packing than before); returns false when that fails (pairs unknown).
bool pd_broad_grid_update(pdBroadGrid* grid, const pdAabb* boxes);

// The pairs of the last successful update: *count of them, sorted by (a, b); valid until the next update.
const pdPair* pd_broad_grid_pairs(const pdBroadGrid* grid, int* count);

pdBroadGridStats pd_broad_grid_stats(const pdBroadGrid* grid);
