// polydyn (internal) — islands: groups of moving bodies that advance alone between output samples
// (pd_islandsOn; design note at the top of islands.c).
#pragma once

#include <stdbool.h>

#include "polydyn/state.h"

// Called by pd_advance_hooked after every step it takes (accepted or a jump to the next sample), with the
// state at its new time.
typedef void pdStepHookFcn(const pdModel* model, const pdState* state, void* user);

// pd_advance without the islands' dispatch, calling `hook` (nullable) with `hookUser` after each step that ends by
// tEnd, and once more with the state presented at tEnd when the last step passed it (integrator.c). With landOnEnd the
// last step is cut to end on tEnd unless the state is already past it (dense output, dense_output.h). pd_advance is
// pd_advance_hooked with no hook, landOnEnd false, when islands are off.
bool pd_advance_hooked(const pdModel* model, pdState* state, double tEnd, bool landOnEnd, pdObserverFcn* observer,
                       void* user, pdStepHookFcn* hook, void* hookUser);

// pd_advance with state->islands == pd_islandsOn (contract of pd_advance, state.h).
bool pd_islands_advance(const pdModel* model, pdState* state, double tEnd, pdObserverFcn* observer, void* user);

// The number of islands of the state's last interval (0 before the first, or with islands off).
int pd_island_count(const pdState* state);

// Half loops of an island run by another thread of the pool so far (help_desk.h; 0 with islands off or one
// thread): how much help the islands got. Depends on timing; no result does.
long pd_island_help_served(const pdState* state);

// Frees the islands' states (state reset and free); NULL is allowed.
void pd_island_set_free(struct pdIslandSet* set);
