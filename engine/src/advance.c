// polydyn — pd_advance: the scene from output sample to output sample (paper Fig. 8; docs/DESIGN.md §5.1).
//
// Design note. pd_advance only dispatches, and it is the one file above both of the engine's loops: with islands on
// the islands advance the scene from sync time to sync time (islands.c), each island through the steppers' loop
// pd_step_until (integrator.c); with islands off that loop runs the whole scene. The calls go down only:
// advance.c -> islands.c -> integrator.c, and advance.c -> integrator.c.
#include "integrator.h"
#include "islands.h"
#include "polydyn/state.h"

bool pd_advance(const pdModel* model, pdState* s, double tEnd, pdObserverFcn* observer, void* user) {
  PD_ASSERT(model != NULL && s != NULL && tEnd >= s->t);
  if (s->islands == pd_islandsOn) return pd_islands_advance(model, s, tEnd, observer, user);
  return pd_step_until(model, s, tEnd, false, observer, user, true, NULL, NULL);
}
