// polydyn (internal) — islands: groups of moving bodies that advance alone between output samples
// (pd_islandsOn; design note at the top of islands.c).
#pragma once

#include <stdbool.h>

#include "polydyn/state.h"

// pd_advance with state->islands == pd_islandsOn (contract of pd_advance, state.h): each island stepped by
// pd_step_until (integrator.h).
bool pd_islands_advance(const pdModel* model, pdState* state, double tEnd, pdObserverFcn* observer, void* user);

// The number of islands of the state's last interval (0 before the first, or with islands off).
int pd_island_count(const pdState* state);

// Half loops of an island run by another thread of the pool so far (help_desk.h; 0 with islands off or one
// thread): how much help the islands got. Depends on timing; no result does.
long pd_island_help_served(const pdState* state);

// Frees the islands' states (state reset and free); NULL is allowed.
void pd_island_set_free(struct pdIslandSet* set);
