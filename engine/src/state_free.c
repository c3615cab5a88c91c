// polydyn — pd_state_reset and pd_state_free (state.h). A state with islands on owns an island set whose islands
// hold states of their own, which islands.c makes and releases with state.c's pd_state_create and pd_state_release;
// freeing the set here, above islands.c, keeps the calls going down: state_free.c -> islands.c -> state.c.
#include "polydyn/state.h"

#include "islands.h"
#include "state_layout.h"

void pd_state_reset(const pdModel* model, pdState* s) {
  pd_island_set_free(s->islandSet);
  s->islandSet = NULL;
  pd_state_reset_own(model, s);
}

void pd_state_free(pdState* s) {
  if (!s) return;
  pd_island_set_free(s->islandSet);
  s->islandSet = NULL;
  pd_state_release(s);
}
