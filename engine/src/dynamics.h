// polydyn — the state derivative with sampled stage timers (dynamics.c; pd_state_derivative is the public form).
#ifndef PD_DYNAMICS_H
#define PD_DYNAMICS_H

#include "polydyn/state.h"

// pd_state_derivative, with its two stage timers (forces, derivative) read only when timedScale > 0, each timed
// evaluation then counted timedScale times; timedScale 0 reads no clock. pd_state_derivative passes 1.
void pd_state_derivative_sampled(const pdModel* model, pdState* state, double t, const double* y, double* dydt,
                                 double timedScale);

#endif
