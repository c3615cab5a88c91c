// polydyn (internal) — where each body's 13 numbers sit in the state vector, and scratch sizes.
#pragma once

#include "polydyn/state.h"
#include "polydyn/vecmath.h"

enum {
  PD_Y_V = 0,  // linear velocity, world
  PD_Y_W = 3,  // angular velocity, world
  PD_Y_X = 6,  // centre of mass, world
  PD_Y_Q = 9,  // orientation quaternion w x y z
};

// Scratch vectors of length n the steppers need (see integrator.c).
enum { PD_STEPPER_WORK_VECTORS = 8 };

static inline pdVec3 pd_layout_v(const double* y) { return (pdVec3){y[PD_Y_V], y[PD_Y_V + 1], y[PD_Y_V + 2]}; }
static inline pdVec3 pd_layout_w(const double* y) { return (pdVec3){y[PD_Y_W], y[PD_Y_W + 1], y[PD_Y_W + 2]}; }
static inline pdVec3 pd_layout_x(const double* y) { return (pdVec3){y[PD_Y_X], y[PD_Y_X + 1], y[PD_Y_X + 2]}; }
static inline pdQuat pd_layout_q(const double* y) {
  return (pdQuat){y[PD_Y_Q], y[PD_Y_Q + 1], y[PD_Y_Q + 2], y[PD_Y_Q + 3]};
}
static inline void pd_layout_store(double* y, pdVec3 v, pdVec3 w, pdVec3 x, pdQuat q) {
  y[PD_Y_V] = v.x, y[PD_Y_V + 1] = v.y, y[PD_Y_V + 2] = v.z;
  y[PD_Y_W] = w.x, y[PD_Y_W + 1] = w.y, y[PD_Y_W + 2] = w.z;
  y[PD_Y_X] = x.x, y[PD_Y_X + 1] = x.y, y[PD_Y_X + 2] = x.z;
  y[PD_Y_Q] = q.w, y[PD_Y_Q + 1] = q.x, y[PD_Y_Q + 2] = q.y, y[PD_Y_Q + 3] = q.z;
}

// Grows the state's y, weight and work, its contact list and the implicit stepper's workspace, to hold `contacts`
// contacts (between steps only: the stepper's scratch in work is dropped, not copied). contact_set.c.
void pd_state_reserve_contacts(const pdModel* model, pdState* state, int contacts);
// How many contacts the state's vectors hold (what pd_state_reserve_contacts has made room for).
int pd_state_contact_room(const pdModel* model, const pdState* state);  // state_contacts.c

// pd_state_reset and pd_state_free but for the island set (state.c): what islands.c uses for its islands' states,
// which never have one (islands run with islands off); the public two (state_free.c) free the set first.
void pd_state_reset_own(const pdModel* model, pdState* state);
void pd_state_release(pdState* state);
