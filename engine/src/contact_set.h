// polydyn (internal) — the contact list of a state and the work around it: contact forces inside the
// state derivative, and the contact events between steps (paper Fig. 8, §3.4, §4.2–§4.4).
//
// The contact list holds the active contacts sorted by id (pd_contact_id_compare); contact i's 8 spring
// numbers sit at y[springBase + 8 i] (state_layout.h). Everything here is sized at creation and grown only
// between steps (pd_contact_set_reserve); nothing allocates inside a derivative evaluation.
#pragma once

#include <stdbool.h>

#include "clock.h"
#include "contact_analysis.h"
#include "contact_force.h"
#include "polydyn/state.h"

enum { PD_CONTACT_STATE_SIZE = 8 };

typedef struct pdContactSet pdContactSet;

pdContactSet* pd_contact_set_create(const pdModel* model);
void pd_contact_set_free(pdContactSet* set);
// Empties the list and clears the contact search's caches (state reset).
void pd_contact_set_clear(pdContactSet* set);
// The help desk the set's per-contact and per-pair loops post half their work at (help_desk.h), or NULL: the
// islands' pool gives every island's set its own pool's desk. Results do not depend on it.
struct pdHelpDesk;
void pd_contact_set_help(pdContactSet* set, struct pdHelpDesk* desk);
struct pdHelpDesk* pd_contact_set_help_desk(const pdContactSet* set);
int pd_contact_set_count(const pdContactSet* set);
// Whether the derivative holds every contact's modes of the step's start over the step (its normal force applied
// or not, its stick or slip: pd_contact_force_held), the changes the force law finds at the step's end corrected
// there or located by a retry (pd_contact_events; docs/events.md, "Modes within a step"). Set by the stepper
// before a step; off, the force law decides at every evaluation (the paper's loop).
void pd_contact_set_hold_modes(pdContactSet* set, bool hold);
// With `all`, every held mode's change is corrected whatever its bound, none located (tests measure the bound
// against the located run's answer); off (the default), the bound decides.
void pd_contact_set_correct_held(pdContactSet* set, bool all);
// Whether a contact that slipped at a step's start and that a stage found stuck or slipping against that friction
// (`crossed`), or that slips at both ends with its friction turned against itself, changed mode inside the step
// (pd_contact_events), refined whatever the kink bound. Set by the stepper before a step: on for the implicit
// method's trials, whose W holds the start's slip and whose stages overshoot a stop (docs/events.md, "A stop inside
// an implicit step").
// `startSlope`, f(y) at the step's start (NULL: off), aims the refinement's retry at the stop it predicts
// (pd_contact_events); it must stay valid over the step.
void pd_contact_set_slip_reversals(pdContactSet* set, const double* startSlope);
// Forgets which contacts a trial's stages found out of their slip (slipReversals): before each trial.
void pd_contact_set_clear_crossings(pdContactSet* set);

// Inside the derivative: poses of every body from y (fixed bodies keep theirs), then for every contact
// its force and moment on both bodies (summed per moving body, world: pd_contact_set_force/_torque) and
// its spring rates (written into dydt's contact part). A normal force that would pull is not applied
// (normal springs are never in tension); the contact is dropped after the step.
void pd_contact_forces(const pdModel* model, pdContactSet* set, const double* y, double* dydt);
// Whether a derivative at y takes every contact's force and spring rates from the list's preparation: record() formed
// them at a state of the very same numbers in the same place (the first derivative of a step after a commit, at
// state->y), so pd_contact_forces copies them instead of forming the same numbers again. Any list installed or
// cleared forgets them.
bool pd_contact_set_recorded_at(const pdModel* model, const pdContactSet* set, const double* y);
// Forgets them now: the next derivative forms every contact (tests compare the two).
void pd_contact_set_forget_recorded(pdContactSet* set);
// Whether a derivative at y takes its vertex–face contacts' force and spring rates from the contact events' tracking:
// pd_contact_events tracked the list to a state of the very same numbers in the same place while the implicit method
// was active (the implicit trial's end, whose derivative its dense output needs), and modes are not held. Any list
// installed, cleared or gathered forgets it; so does the next pd_contact_events.
bool pd_contact_set_tracked_at(const pdModel* model, const pdContactSet* set, const double* y);
// Forgets it now (tests compare the two).
void pd_contact_set_forget_tracked(pdContactSet* set);
// Results of the last pd_contact_forces call: poses indexed by body; force and torque (N, N·m, about the
// centre of mass) indexed by moving body (stateIndex).
const pdPose* pd_contact_set_poses(const pdContactSet* set);
const pdVec3* pd_contact_set_force(const pdContactSet* set);
const pdVec3* pd_contact_set_torque(const pdContactSet* set);

typedef enum pdEventVerdict {
  pd_eventAccept,   // take the step: call pd_contact_events_commit
  pd_eventRetry,    // take a shorter step from the same start (*hRetry), the contact list unchanged
  pd_eventRestart,  // contacts were added at the start of the step (virtual contacts): y0 was re-laid
                    // (state->n changed), re-evaluate the derivative at the start and try again
} pdEventVerdict;

// After a trial step from (t0, y0 = state->y) to y1 (length state->n) of size h that the error control
// accepted (yMid, nullable: the trial's own state at t0 + h/2, which places a held mode's change more closely): analyses the contacts at y1 (broad phase, interference, contact search, tracking) and decides
// whether a contact onset or a reversal inside the step asks for a shorter step (Retry), whether
// contacts must be added at the start (Restart: state->y and state->n are updated), or whether the step
// stands (Accept). Onset retries are bounded per step, refinements by the refinement step. May grow the
// state's vectors (Restart only: pointers into the stepper's scratch are then stale). Its stages are timed as
// laps of `watch`, running since the caller's last lap.
pdEventVerdict pd_contact_events(const pdModel* model, pdState* state, double h, const double* y1, const double* yMid,
                                 double* hRetry, pdStopwatch* watch);
// Accepts the step analysed by the last pd_contact_events: copies y1 into state->y with the new contact
// list (breaks, transfers, new contacts with springs at 0), realigns the springs of continuing contacts
// (§3.4) and records each contact's force for output. Grows the state's vectors if needed. Timed as one lap
// of `watch` (contact analysis), which must have run since pd_contact_events' last.
void pd_contact_events_commit(const pdModel* model, pdState* state, const double* y1, pdStopwatch* watch);

// min(h, fraction × the largest step the adaptive stepper may take with the committed contact list), that
// step satisfying (step/2) ω_max ≤ 2.5 for the fastest contact mode, ω_max bounded by the smaller of two
// Gershgorin bounds (stability_bound.c; INFINITY without contacts): fraction 1 for step doubling (its half steps
// are the ones kept), ½ for a single RK4 step. The tight bound is formed only when the cheap one
// does not let h through; *tightNeeded says whether it was needed.
double pd_contact_set_limit_step(const pdModel* model, pdContactSet* set, double h, double fraction, bool* tightNeeded);

// The fraction of that step (pd_contact_set_limit_step's `fraction`) within which one Dormand–Prince 5(4) step is
// stable for the committed list: its stability region's radius along the rays of modes damped at least as much as
// the list's least damped contact (stability_bound.c, PD_DOPRI_STABLE_RADIUS), against step doubling's 2 × 2.5.
double pd_contact_set_dopri_fraction(const pdContactSet* set);

// The step the tunnelling guard (contact_search.c) lets the step after the last analysed one take if the bodies'
// motion goes on, s (INFINITY: no pair near its travel limit). The adaptive steppers start their next trial from at
// most this, rather than from what their error control wants, each time to be cut back by the guard.
double pd_contact_set_travel_step(const pdContactSet* set);

// How many times the tight stability bound was formed for this set (work counter for the tests: at most once per
// contact list whose step the cheap bound does not settle).
long pd_contact_set_tight_formed(const pdContactSet* set);

// ---------------------------------------------------------------- islands (islands.c)
// An island's state runs over a model of some of the scene's bodies (its moving bodies and every fixed body,
// in scene order, so a contact's id orders the same in both); contacts move between the scene's state and
// the islands' states at output samples only.

// A set for dense output's presented states (dense_output.h): the per-body arrays only, no contact search, its list
// grown by the captures. Read-out, derivative evaluations and the implicit stepper's linearisation work on it; the
// contact events and the stability bound do not.
pdContactSet* pd_contact_set_create_view(const pdModel* model);
// Dense output (dense_output.h): copies the list of `from` into `view` (another set of the same model), kept there
// until the next capture.
void pd_contact_set_capture(const pdContactSet* from, pdContactSet* view);
// Makes the captured list the list of `view` (the presented state's, in its layout), each contact unevaluated: as
// captured, its springs in the state as interpolated, until pd_contact_set_settle evaluates it (and forms the bodies'
// world inverse inertias at the state's poses).
void pd_contact_set_present(const pdModel* model, pdContactSet* view);
// Evaluates the set's unevaluated contacts (a presentation's, and the slots a gather moved from one) at state y
// (the state whose list it is): each one's springs in y realigned to its normal at y as a commit would (those that
// pull left as they are), then its geometry and force recorded for output, as a presentation did eagerly. Every
// reader of a state's contacts or springs calls it first; nothing to do (one test) when none is unevaluated.
void pd_contact_set_settle(pdContactSet* set, double* y);
// The bodies of contact i of the list (model body indices).
void pd_contact_set_bodies(const pdContactSet* set, int i, int* body1, int* body2);
// Makes contacts[0 .. count) of `from` (a state of `model`, in list order) the contact list of `to` (a state
// of `sub`, whose body numbers are already in to->y): their ids remapped by toSub (model body → sub body, every
// body of these contacts mapped), their springs, forces and dampers as they are in `from`. Grows `to`.
void pd_contact_set_scatter(const pdModel* model, const pdState* from, const int* contacts, int count,
                            const pdModel* sub, pdState* to, const int* toSub);
// Makes the union of the contact lists of from[0 .. parts) (states of subs[p], ids remapped by toModel[p]:
// sub body → model body) the contact list of `to`, a state of `model`, sorted by id; the springs go into to->y
// after the bodies' numbers, which the caller copies. Grows `to`.
void pd_contact_set_gather(const pdModel* model, pdState* to, int parts, const pdModel* const* subs,
                           const pdState* const* from, const int* const* toModel);

// ---------------------------------------------------------------- the implicit stepper (implicit.c)

// One contact linearised at a state (the implicit stepper's matrix W): with Δu its relative velocity and s its 8
// springs (pdSprings' order: s1n, s2n, s1t, s2t), the force F on body 1 (−F on body 2) and the spring rates ṡ
// change as δF = Du δΔu + Ds δs and δṡ = Gu δΔu + Gs δs; r1, r2 are the lever arms p − x of the contact point
// from the bodies' centres (world), invInertia1, 2 the bodies' world inverse inertias (0 for a fixed body). A
// contact whose force pulls applies none: its Du and Ds are 0.
typedef struct pdContactLinear {
  int body1, body2;  // model body indices
  pdVec3 r1, r2;     // m
  pdMat3 invInertia1, invInertia2;  // R I⁻¹ Rᵀ, 1/(kg m²)
  double Du[3][3], Ds[3][PD_CONTACT_STATE_SIZE];
  double Gu[PD_CONTACT_STATE_SIZE][3], Gs[PD_CONTACT_STATE_SIZE][PD_CONTACT_STATE_SIZE];
} pdContactLinear;

// Every listed contact linearised at state y, the state the list was last prepared at (a step's start: its
// geometry, force and the bodies' inertias are the list's own), into out[i] for contact i (out sized for the
// list), by forward differences of pd_contact_force (11 calls a contact).
void pd_contact_set_linearise(const pdModel* model, pdContactSet* set, const double* y, pdContactLinear* out);

// Spring energy ½ Σ k s² of the contacts whose springs are in y (J).
double pd_contact_spring_energy(const pdContactSet* set, const double* y, int springBase);
