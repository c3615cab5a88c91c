// polydyn — the modes of a stack that a state's contacts hold (pd_state_stack_modes, state.h): the read-out that
// `polydyn check` prints, over the mode analysis of engine/src/stack_modes.c.
#include <stdlib.h>

#include "polydyn/state.h"

#include "contact_list.h"
#include "grow.h"
#include "stack_modes.h"

int pd_state_stack_modes(const pdModel* model, const pdState* state, const int* stackOf, int stack,
                         pdStackMode* modes, int capacity) {
  PD_ASSERT(model != NULL && state != NULL && stackOf != NULL && capacity >= 0 && (modes != NULL || capacity == 0));
  pd_contact_set_settle(state->contacts, state->y);  // a presented state's forces and modes
  pdBodyState* bodies = pd_grow(NULL, (size_t)model->bodyCount, sizeof *bodies);
  for (int k = 0; k < model->bodyCount; ++k) bodies[k] = pd_state_body(model, state, k);
  int count = pd_stack_modes(model, state->contacts, bodies, stackOf, stack, modes, capacity);
  free(bodies);
  return count;
}
