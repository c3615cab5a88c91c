// polydyn (internal) — the islands' partition: which moving bodies may meet over a sync interval (union-find
// over contacts, grown boxes and the separating-axis test; design note at the top of islands.c).
#pragma once

#include <stdbool.h>

#include "island_set.h"
#include "polydyn/model.h"
#include "polydyn/state.h"

// The partition of the moving bodies at the scene's state s (T) with the bounds set->bound over the interval
// dt: islandOf, members, first, partCount; and contactOf, the island of each contact of s. In the frame that
// falls with gravity, body k's points stay within its box at T swept along v0 dt and grown by its bound.
// With fine set (a sync interval), a free body keeps its box over the sample interval (cbox) and joins nothing:
// a free body whose box another body's reaches is listed in set->activate instead, and the number of those is
// returned (the partition is then incomplete: activate them and form it again). Without (the sample interval
// as a whole), every body takes part.
int pd_island_partition(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt, bool fine);

// How far body k's points can stray over the interval from where its ballistic motion (its velocity at T and
// gravity, which every body shares) takes them, m (design note): an applied force's share, its spin's
// (r |ω| Δ), and the slack; a body touching anything at T, or whose box may reach a fixed body's, may also
// reverse its velocity and be held against gravity (2 |v| Δ + |g| Δ²).
// yb: its 13 numbers at T; r: its rotation matrix at T (of its normalised orientation); box: its box at T; touchingOut: in (touching at T) and out (or its box may reach a fixed
// body's). t: T, s; dt: the interval, s.
double pd_island_travel_bound(const pdModel* model, const struct pdIslandSet* set, int k, const double* yb,
                              const pdMat3* r, const pdAabb* box, bool* touchingOut, double t, double dt);

// The slack of body b's bound, m: pd_island_travel_bound never returns less (its other terms are not negative).
double pd_island_slack(const pdModel* model, const pdBody* b);
