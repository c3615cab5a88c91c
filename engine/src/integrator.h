// polydyn (internal) — the steppers (integrator.c): one system stepped from output sample to output sample, for
// pd_advance with islands off (advance.c) and for each island (islands.c).
#pragma once

#include <stdbool.h>

#include "polydyn/state.h"

// Called by pd_step_until after every step it takes (accepted or a jump to the next sample), with the state at its new
// time.
typedef void pdStepHookFcn(const pdModel* model, const pdState* state, void* user);

// pd_advance's contract (state.h) for one system, whatever state->islands says: observer (nullable) at every output
// sample, and `hook` (nullable) with `hookUser` after each step that ends by tEnd and once more with the state
// presented at tEnd when the last step passed it. With landOnEnd the last step is cut to end on tEnd unless the state
// is already past it (dense output, dense_output.h). `observerTimed`: the observer's calls are timed into the state's
// observe stage (false: an island's observer, which times what it calls itself).
bool pd_step_until(const pdModel* model, pdState* state, double tEnd, bool landOnEnd, pdObserverFcn* observer, void* user,
                   bool observerTimed, pdStepHookFcn* hook, void* hookUser);
