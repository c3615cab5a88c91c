// polydyn (internal) — the linear systems of the implicit stepper (pd_stepperImplicit, integrator.c).
//
// The stepper needs M = I/(hγ) − W solved for several right-hand sides per step, W an approximation of the
// Jacobian ∂f/∂y of the state derivative. W holds only the stiff part: how the contacts' springs and the moving
// bodies' velocities drive one another (each contact linearised by pd_contact_set_linearise). The rows and
// columns of positions and orientations, gravity, applied forces and the gyroscopic term are left out (0): a
// W-method keeps its order with any W, and those couplings are slow beside the springs'.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/state.h"

// Moving bodies above which a system (an island, or the scene with islands off) is not stepped implicitly:
// M's body part is a dense 6N × 6N matrix, factorised in O(N³) (~0.3 ms at 16 bodies, 8× that at 32), more than
// the steps it saves on a larger system. Larger systems take step doubling (docs/integration.md). 32 rather than
// 16: with the switch's probation, stacks of 20-30 boxes took 0.72-0.83× the wall time of a bound at 16, and the
// soak's random scenes (smaller islands) and the piles the same steps.
#define PD_IMPLICIT_BODIES_MAX 32

// The implicit stepper switches between step doubling and the implicit method system by system (integrator.c,
// switching_step): to the implicit method after this many accepted steps in a row whose step the stability bound
// held to at most 1/PD_IMPLICIT_HELD_RATIO of what the error control wanted (resting contact), back to step
// doubling as soon as the bound would allow 1/PD_IMPLICIT_HELD_RATIO of the implicit method's step (an implicit
// trial costs about two explicit ones on a small system).
#define PD_IMPLICIT_SWITCH_STEPS 3
#define PD_IMPLICIT_HELD_RATIO 2.0
// A switch is on probation until its first implicit step is accepted. Its error control may reject the first trial
// down to the probation floor, PD_IMPLICIT_HELD_RATIO times the step the bound held step doubling to, and no
// further: a trial at the floor rejected means that the implicit method's order-2 estimate, not the bound, limits
// its step (a stack still ringing after its landing). The system then gives up, takes the step by step doubling,
// and tries again no earlier than a back-off later: PD_IMPLICIT_BACKOFF_FIRST bound steps after the first failure,
// doubling after each failure in a row up to PD_IMPLICIT_BACKOFF_MAX bound steps (at most one wasted pair of trials
// in so many steps), and none after a switch that paid. Without it a ringing stack of 5-9 boxes switched every
// fourth step and had its implicit trials rejected: up to 2× step doubling's steps (soak seeds 28 and 29).
// A probation's trial passes only when its error norm is at most this fraction of tol, where the error control's next
// step, 0.9 (tol/norm)^(1/3) times this one, is at least 1.34 times it. A trial that only just meets tol leaves the
// implicit method about at the floor, no cheaper than step doubling, and spends the whole tolerance in one step: a
// stack that spent it so (soak seed 30, scene 1797, 0.84 tol) had its modes stirred to tol where step doubling's
// steps at the bound had left them at ~1e-3 of it, and step doubling then took 1.5× its steps and 1.8× its
// evaluations to resolve them. 0.09 (a next step of twice this one) cost up to 8 % more evaluations on the cost
// scenes (tests/engine/test_implicit.c; docs/integration.md).
#define PD_IMPLICIT_PROBATION_ERROR 0.3
#define PD_IMPLICIT_BACKOFF_FIRST 8.0
#define PD_IMPLICIT_BACKOFF_MAX 256.0
// After an implicit step that a contact event cut, the next may be at most this many times as long (the event,
// typically the tunnelling guard of a sliding body, would cut a longer one again, each retry a wasted trial).
#define PD_IMPLICIT_GROWTH_AFTER_CUT 1.0

typedef struct pdImplicit pdImplicit;

// An empty workspace, sized by pd_implicit_reserve before its first step and again, between steps, whenever the state
// can hold more contacts (pd_state_reserve_contacts): a step allocates nothing (pd_implicit_linearise asserts it).
pdImplicit* pd_implicit_create(void);
// Room for a system of `movingCount` bodies and up to `contacts` contacts (grows only).
void pd_implicit_reserve(pdImplicit* im, int movingCount, int contacts);
void pd_implicit_free(pdImplicit* im);

// Whether the system steps implicitly now, and the switch's bookkeeping (PD_IMPLICIT_SWITCH_STEPS).
bool pd_implicit_active(const pdImplicit* im);
// After an explicit step accepted at time t: `held` says whether the stability bound held it (see above), `boundStep`
// (s) the step it held it to. Returns true when the system switches to the implicit method, on probation.
bool pd_implicit_note_explicit(pdImplicit* im, bool held, double boundStep, double t);
// On probation, the step (s) the bound held step doubling to at the switch; 0 once an implicit step was accepted.
double pd_implicit_probation_bound_step(const pdImplicit* im);
// The first implicit step after a switch was accepted: no back-off before the next switch.
void pd_implicit_paid(pdImplicit* im);
// Back to step doubling at time t; `gaveUp` after a probation that failed (the back-off above).
void pd_implicit_deactivate(pdImplicit* im, bool gaveUp, double t);

// Linearises the contacts of `state` at state y, the state its contact list was last prepared at (a step's start;
// pd_contact_set_linearise), into W's blocks: once per step, whatever the trials from there.
void pd_implicit_linearise(const pdModel* model, pdState* state, pdImplicit* im, const double* y);

// Forms M = I/hg − W from the last linearisation and factorises it. Returns false when M is singular or not finite
// (the caller rejects the step and retries a smaller one).
bool pd_implicit_factor(const pdModel* model, const pdState* state, pdImplicit* im, double hg);

// u = M⁻¹ r over the state's n components, M as last factorised (r and u must not overlap).
void pd_implicit_solve(const pdModel* model, const pdState* state, pdImplicit* im, const double* r, double* u);

// w = W x over the state's n components, W as last factorised (the tests compare it with finite differences of
// the derivative).
void pd_implicit_apply_w(const pdModel* model, const pdState* state, const pdImplicit* im, const double* x, double* w);
