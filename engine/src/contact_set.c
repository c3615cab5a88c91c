// polydyn — the contact list of a state: its storage, the contact events between steps and their commit (paper
// Fig. 8, §3.4, §4.2–§4.4; docs/DESIGN.md §5.3). The work they call on is in files of its own: the forces inside the
// derivative (contact_forces.c), the springs sized by the load and the modal dampers (pair_params.c), the stability
// bound (stability_bound.c), the onsets (onsets.c) and the contact search (contact_search.c), all over the structures
// of contact_list.h.
//
// Design note. The loop of Fig. 8 runs as: the stepper proposes a step from (t0, y0) to y1 with the
// contact list C0 fixed; the error control accepts it; pd_contact_events then analyses y1:
//  1. every contact of C0 is tracked to y1 (VF by (18), EE by closest points) and its force evaluated
//     there; a slip/stick change, a reversal of the normal relative velocity (the springs turn from
//     loading to unloading) or of the tangential relative velocity inside the step halves the step until
//     it is shorter than a fraction of the shortest contact period (§3.4);
//  2. the broad phase, the interference test and the contact search give the contacts C1 at y1; a
//     contact of C1 not in C0 that approaches (Δu_n < 0: with its springs at 0 it would push) is new.
//     A new contact found deeper than the onset tolerance began inside the step: the step is retried to end at
//     its onset, or it joins as a virtual contact at t0, or as a pair onset at the step's end (onsets.c).
//  3. on acceptance, contacts of C0 whose feature left the other (vertex projected outside its face, EE
//     closest points off an edge) break geometrically — unless a sliding vertex moved on to another face
//     of the same body, which keeps its springs (face continuity, §4.4.3); contacts whose normal springs
//     would pull (F_n < 0) break by force; the survivors' springs are realigned to the new normal and
//     clipped to the friction cone (§3.4); new contacts join with their springs at 0. The list is
//     re-sorted by id and the springs re-laid in the state vector. record() then forms every contact's
//     geometry (a tracked contact's is tracking's, at the same poses) and force at the new state; the next
//     step's first derivative, at that very state, takes them from there (pd_contact_set_recorded_at).
#include "contact_set.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "contact_list.h"
#include "grow.h"
#include "implicit.h"
#include "material.h"
#include "model_contact.h"
#include "onset_bound.h"
#include "onsets.h"
#include "stack_modes.h"
#include "state_layout.h"

#define PI 3.14159265358979323846

// Steps containing a stick/slip change are halved down to this fraction of the shortest
// contact period: the event is then located to ~5 % of the contact's own time scale. 1 % changed no
// Gedanken result by more than 1e-4 of its tolerance and cost a pile of 10 boxes 27 % more derivative
// evaluations (205 376 against 149 568 for cases/sweep/pile_10.scene): its steps are already ~2.5 % of
// the period (the stability bound), and every halving throws away a whole trial step.
#define PD_REFINE_PERIOD_FRACTION 0.05
// A stop's aimed retry once the stop is predicted within 1.5 floors of the step's start: a step of this many floors,
// under the two whose half would be refined again, holds the stop wherever the prediction's error of up to a floor
// puts it.
#define PD_STOP_HOLD_FLOORS 1.9
// A held mode's change located by a retry (holdModes) is aimed this fraction of the τ since it past its interpolated
// time: the retried step then holds the change (its bound ~ this³ of the first's) rather than stopping short of it
// and meeting it again at the start of the next.
#define PD_MODE_LAND_PAST 0.05
// Retries of one step towards held modes' changes: the interpolated time is not exact, so a retry may meet the change
// again closer; past this many the change is corrected whatever its bound (counted with it).
#define PD_MODE_RETRIES_MAX 4
// The held-change bound's factor over its estimate (held_change): measured, not derived. Cubes landing on a face, an
// edge and a corner (floor 0.1 m, e 0.3-0.95, mu 0 and 0.5, 72 landings, every change corrected, at tol 1e-10
// against --events exact) left exit velocities off by up to 23 times the estimate's sum (a face's four contacts
// releasing together: each correction is formed alone, and the others' releases bend its force's path), and by 0.002
// of it at best; 32 covers every one measured (tests/engine/test_held_modes.c).
#define PD_MODE_BOUND_SAFETY 32.0

void pd_contact_set_reserve_list(pdContactSet* set, int capacity) {
  if (capacity <= set->capacity) return;
  int c = set->capacity > 0 ? set->capacity : 16;
  while (c < capacity) c *= 2;
  set->items = pd_grow(set->items, c, sizeof *set->items);
  set->push = pd_grow(set->push, c, sizeof *set->push);
  set->next = pd_grow(set->next, c, sizeof *set->next);
  set->bodyList = pd_grow(set->bodyList, 2 * c, sizeof *set->bodyList);
  if (set->broad) {  // a view (pd_contact_set_create_view) has no contact events or stability bound
    set->eval = pd_grow(set->eval, c, sizeof *set->eval);
    for (int part = 0; part < 2; ++part)
      set->search[part].previous = pd_grow(set->search[part].previous, c, sizeof *set->search[part].previous);
    set->stability = pd_grow(set->stability, c, sizeof *set->stability);
  } else {
    set->captured = pd_grow(set->captured, c, sizeof *set->captured);
  }
  set->capacity = c;
}

// A set with its per-body arrays; with `search`, also the contact search's (broad phase, pairs, caches, candidates)
// and room for the list a state starts with.
static pdContactSet* create(const pdModel* model, bool search) {
  pdContactSet* set = pd_zeroed(1, sizeof *set);
  int n = model->bodyCount;
  set->bodyCount = n;
  set->force = pd_grow(NULL, model->movingCount, sizeof *set->force);
  set->bodyFirst = pd_grow(NULL, n + 1, sizeof *set->bodyFirst);
  set->invInertiaWorld = pd_grow(NULL, n, sizeof *set->invInertiaWorld);
  for (int i = 0; i < n; ++i) set->invInertiaWorld[i] = pd_mat3_zero();
  set->kinkSum = pd_zeroed((size_t)n, sizeof *set->kinkSum);
  set->stackScratch = NULL;  // made when a pair's modal dampers first need it (stack_mass)
  set->stableStep = set->stableCheap = INFINITY;
  set->dampingMin = 1.0;
  set->stableKnown = true;
  set->travelStep = INFINITY;
  set->bodyRowsK = pd_grow(NULL, n, sizeof *set->bodyRowsK);
  set->bodyBlocks = pd_grow(NULL, n, sizeof *set->bodyBlocks);
  set->bodyRowsRight = pd_grow(NULL, n, sizeof *set->bodyRowsRight);
  set->travel = pd_zeroed((size_t)n, sizeof *set->travel);
  set->torque = pd_grow(NULL, model->movingCount, sizeof *set->torque);
  set->poses = pd_grow(NULL, n, sizeof *set->poses);
  set->poses0 = pd_grow(NULL, n, sizeof *set->poses0);
  set->poses1 = pd_grow(NULL, n, sizeof *set->poses1);
  set->settlePoses = pd_grow(NULL, n, sizeof *set->settlePoses);
  set->boxes = pd_grow(NULL, n, sizeof *set->boxes);
  bool* fixed = pd_grow(NULL, n, sizeof *fixed);
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &model->bodies[i];
    fixed[i] = b->fixed;
    set->poses[i] = set->poses0[i] = set->poses1[i] = set->settlePoses[i] = pose_of(b->x0, b->q0);
    set->boxes[i] = pd_aabb_of(&b->shape, set->poses[i].x, &set->poses[i].R);
  }
  if (!search) {
    free(fixed);
    return set;
  }
  pd_contact_search_create(model, set, fixed);
  free(fixed);
  set->history = pd_history_create();
  pd_contact_set_reserve_list(set, 4 * model->movingCount + 16);
  return set;
}

pdContactSet* pd_contact_set_create(const pdModel* model) { return create(model, true); }

pdContactSet* pd_contact_set_create_view(const pdModel* model) { return create(model, false); }

void pd_contact_set_free(pdContactSet* set) {
  if (!set) return;
  pd_history_free(set->history);
  free(set->items);
  free(set->eval);
  free(set->push);
  free(set->next);
  free(set->captured);
  free(set->recordedY);
  free(set->trackedY);
  for (int part = 0; part < 2; ++part) free(set->search[part].previous);
  free(set->force);
  free(set->stability);
  free(set->bodyFirst);
  free(set->bodyList);
  free(set->bodyRowsK);
  free(set->bodyBlocks);
  free(set->bodyRowsRight);
  free(set->invInertiaWorld);
  free(set->kinkSum);
  pd_stack_scratch_free(set->stackScratch);
  free(set->travel);
  free(set->torque);
  free(set->poses);
  free(set->poses0);
  free(set->poses1);
  free(set->settlePoses);
  free(set->boxes);
  if (set->broad) pd_contact_search_free(set);
  free(set);
}

void pd_contact_set_clear(pdContactSet* set) {
  if (set->history) pd_history_clear(set->history);
  set->count = 0;
  set->gatheredSerial = 0;
  set->unevaluated = 0;
  set->bodyListValid = false;
  set->recordedValid = set->trackedValid = false;
  set->stableStep = set->stableCheap = INFINITY;
  set->dampingMin = 1.0;
  set->stableKnown = true;
  set->candidateCount = 0;
  set->cacheCount = 0;
  set->onsetRetries = 0;
  set->travelStep = INFINITY;
  set->modeRetries = 0;
}

double pd_contact_set_travel_step(const pdContactSet* set) { return set->travelStep; }

int pd_contact_set_count(const pdContactSet* set) { return set->count; }

void pd_contact_set_hold_modes(pdContactSet* set, bool hold) { set->holdModes = hold; }

void pd_contact_set_correct_held(pdContactSet* set, bool all) { set->correctHeld = all; }

void pd_contact_set_slip_reversals(pdContactSet* set, const double* startSlope) {
  set->slipReversals = startSlope != NULL;
  set->startSlope = startSlope;
}

void pd_contact_set_clear_crossings(pdContactSet* set) {
  for (int i = 0; i < set->count; ++i) set->items[i].crossed = false;
}

void pd_contact_set_help(pdContactSet* set, pdHelpDesk* desk) { set->help = desk; }
pdHelpDesk* pd_contact_set_help_desk(const pdContactSet* set) { return set->help; }

static int compare_slots(const void* a, const void* b) {
  return pd_contact_id_compare(&((const contactSlot*)a)->id, &((const contactSlot*)b)->id);
}

// Makes next[0..count) (springs inside the slots) the contact list: sorts it, lays out the springs after
// the bodies' numbers (already in state->y) in state->y, sets their weights and state->n. May grow the
// state's vectors: the stepper's scratch is dropped then, so nothing may still point into it. `ordered`: the
// caller knows next[] sorted (one island's list, its bodies renumbered in the same order).
static void install(const pdModel* model, pdState* s, int count, bool ordered) {
  pdContactSet* set = s->contacts;
  // a list that changed in no contact comes in sorted (ids are unique, so any sort gives the one order): checked
  // first, since qsort moves slots of ~0.5 kB through a scratch copy (7 % of cases/hard/stack_10.scene's work)
  bool sorted = true;
  if (!ordered)
    for (int i = 1; i < count && sorted; ++i) sorted = compare_slots(&set->next[i - 1], &set->next[i]) < 0;
  if (!sorted) qsort(set->next, (size_t)count, sizeof *set->next, compare_slots);
  pd_state_reserve_contacts(model, s, count);
  int base = spring_base(model);
  for (int i = 0; i < count; ++i) {
    contactSlot* c = &set->next[i];
    springs_store(s->y + base + PD_CONTACT_STATE_SIZE * i, &c->springs);
    for (int j = 0; j < PD_CONTACT_STATE_SIZE; ++j) s->weight[base + PD_CONTACT_STATE_SIZE * i + j] = c->deltaMax;
  }
  contactSlot* old = set->items;
  set->items = set->next;
  set->next = old;
  set->count = count;
  set->gatheredSerial = 0;  // a gather from a view sets it after
  set->unevaluated = 0;  // a gather counts the unevaluated slots it moved (pd_contact_set_gather)
  set->bodyListValid = false;
  set->recordedValid = set->trackedValid = false;
  s->n = base + PD_CONTACT_STATE_SIZE * count;
}

// The shortest period of a contact, 2π√(m_min/k_s) over n and P_t (m_min: the pair's minimum effective
// mass), times PD_REFINE_PERIOD_FRACTION: how finely a reversal in this contact is located.
static double refine_step(const pdModel* model, const pdContactParams* p) {
  double k = fmax(pd_series(p->k1n, p->k2n), p->mu > 0.0 ? pd_series(p->k1t, p->k2t) : 0.0);
  double period = k > 0.0 ? 2.0 * PI * sqrt(p->massMin / k) : INFINITY;
  return fmax(model->settings.dtmin, isfinite(period) ? PD_REFINE_PERIOD_FRACTION * period : 0.0);
}

// A slot for a new contact between the bodies of g.id, springs at 0.
static contactSlot new_slot(const pdModel* model, const pdContactGeom* g) {
  contactSlot c;
  memset(&c, 0, sizeof c);
  c.id = g->id;
  c.params = pd_model_contact_params(model, g->id.body1, g->id.body2);
  c.loadScale = 1.0;
  c.deltaMax = pd_model_pair_delta_max(model, g->id.body1, g->id.body2);
  c.normal = g->normal;
  c.point = g->point;
  c.depth = g->depth;
  return c;
}

// Records geometry and force of every listed contact at state y for output, realignment and refinement.
// poses must be those of y.
static void record_geometry(contactSlot* c, const pdContactGeom* g) {
  c->normal = g->normal;
  c->point = g->point;
  c->depth = g->depth;
}

// The modes a step from here holds (pd_contact_force_held): those the force law gives at the step's start.
static void hold_modes(contactSlot* c) {
  c->heldPush = !pd_contact_force_pulls(&c->force);
  c->heldSlip = c->force.slip;
}

static void record_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    contactSlot* c = &job->set->items[i];
    pdSprings sp = loop_springs(job, i);
    if (c->geometryCurrent) {
      // the same geometry as evaluate() would form again (a pair onset's impulses change velocities, not poses)
      c->geometryCurrent = false;
      pdVec3 du = relative_velocity(job->model, job->y, job->poses1, &c->id, c->point);
      pd_contact_force(&c->params, &sp, c->normal, du, &c->force);
      hold_modes(c);
      continue;
    }
    pdContactGeom g;
    pdVec3 du;  // unused here
    evaluate(job->model, c, job->y, job->poses1, &frame, &sp, &g, NULL, &du, &c->force);
    record_geometry(c, &g);
    hold_modes(c);
  }
}

// Copies the state y the list's forces were just formed at into *kept (grown with the list, between steps and
// trials), for a derivative at those very numbers to take them (pd_contact_set_recorded_at, _tracked_at). False,
// nothing kept, for an empty list: not worth a copy and a comparison per derivative.
static bool keep_state(const pdModel* model, const pdContactSet* set, const double* y, double** kept, int* capacity) {
  if (set->count == 0) return false;
  int n = spring_base(model) + PD_CONTACT_STATE_SIZE * set->count;
  if (n > *capacity) {
    *capacity = 2 * n;
    *kept = pd_grow(*kept, (size_t)*capacity, sizeof **kept);
  }
  memcpy(*kept, y, (size_t)n * sizeof *y);
  return true;
}

static void record(const pdModel* model, pdContactSet* set, const double* y, const pdPose* poses) {
  contactLoop job = {.model = model, .set = set, .y = y, .poses1 = poses};
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS, record_range, &job);
  // the next step's first derivative is at this state (after an accepted step: its k1)
  set->recordedValid = keep_state(model, set, y, &set->recordedY, &set->recordedCapacity);
  set->recordedFrom = y;
}

// Each moving body's inverse inertia in the world frame, R I⁻¹ Rᵀ, at `poses`.
static void world_inverse_inertias(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    pdMat3 rt = pd_mat3_transpose(&poses[i].R);
    pdMat3 tmp = pd_mat3_mul(&model->bodies[i].invInertia, &rt);
    set->invInertiaWorld[i] = pd_mat3_mul(&poses[i].R, &tmp);
  }
}

// After a new list is installed at state y (poses those of y): the bodies' world inverse inertias, the
// modal dampers, the pair onsets' springs and impulses (pd_onsets_start_late), each contact's geometry and
// force (record), and the stability bound, in that order (the bound reads which contacts slip). Returns the
// number of pair onsets started.
static int prepare_list(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses) {
  world_inverse_inertias(model, set, poses);
  pd_modal_dampers(model, set, poses, y);
  int started = pd_onsets_start_late(model, set, y, poses);
  record(model, set, y, poses);
  pd_stability_prepare(model, set, poses);
  return started;
}

// Did a contact change mode inside the step (§3.4): stick ↔ slip? That is where the contact force has a
// kink, which the error control would otherwise cross with a step of the wrong order. Reversals of Δu_n or
// of Δu_t within one mode are smooth in this model (linear springs and dampers) and are left to the
// error control (refining them cost pile_10 a third of its derivative evaluations). With slipReversals, a contact
// slipping at both ends with its friction force turned by more than a right angle changed mode too: a slip reverses
// only through stick (|b_t| passes below F⁺ on the way), so the step holds two kinks and a stick it does not end in.
static bool changes_mode(const pdContactSet* set, const contactSlot* c, const pdContactForce* f) {
  if (c->force.slip != f->slip) return true;
  return set->slipReversals && (c->crossed || (f->slip && pd_v3_dot(c->force.ft, f->ft) < 0.0));
}

// Contacts [begin, end) of C0 tracked to y1 and their forces there (set->eval).
static void tracking_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    contactEval* e = &set->eval[i];
    pdSprings sp = loop_springs(job, i);
    evaluate(job->model, &set->items[i], job->y, set->poses1, &frame, &sp, &e->geom, &e->tracked, &e->du, &e->force);
    e->transferred = false;
    e->modeBound = 0.0;
    e->modeCorrected = false;
    e->slipChanged = false;
  }
}

// Keeps the state C0 was just tracked to (set->eval's), for a derivative there (pd_contact_forces).
static void keep_tracked(const pdModel* model, pdContactSet* set, const double* y1) {
  set->trackedValid = keep_state(model, set, y1, &set->trackedY, &set->trackedCapacity);
  set->trackedFrom = y1;
}

// The time since a switching quantity crossed zero inside a step of h, from its values at the start (g0) and the
// end (g1), interpolated linearly; the whole step when they lie on one side (a change and back, or rounding).
static double crossing_age(double g0, double g1, double h) {
  bool crossed = (g0 > 0.0) != (g1 > 0.0);
  return crossed && isfinite(g0) && isfinite(g1) ? h * fabs(g1) / (fabs(g0) + fabs(g1)) : h;
}

// The same with its value gm at the step's middle too: the crossing of the parabola through the three, in the half
// step whose ends it lies between (the chord's there if the parabola has no root in it).
static double crossing_age_mid(double g0, double gm, double g1, double h) {
  bool firstHalf = (g0 > 0.0) != (gm > 0.0);
  double lo = firstHalf ? 0.0 : 0.5, glo = firstHalf ? g0 : gm, ghi = firstHalf ? gm : g1;
  if (!(isfinite(g0) && isfinite(gm) && isfinite(g1)) || (glo > 0.0) == (ghi > 0.0)) return crossing_age(g0, g1, h);
  double root = lo + 0.5 * glo / (glo - ghi);  // the chord's, in units of h
  double a = 2.0 * (g1 - 2.0 * gm + g0), b = g1 - g0 - a, disc = b * b - 4.0 * a * g0;
  if (a != 0.0 && disc >= 0.0) {
    double q = -0.5 * (b + copysign(sqrt(disc), b));
    double r[2] = {q / a, q != 0.0 ? g0 / q : -1.0};
    for (int k = 0; k < 2; ++k)
      if (r[k] >= lo && r[k] <= lo + 0.5) root = r[k];
  }
  return (1.0 - root) * h;
}

// Contact i's normal force and cone margin (the free law) at the state yMid, its bodies' poses formed there into the
// derivative's scratch poses (the next derivative forms every moving body's anew).
static void switching_at(const pdModel* model, pdContactSet* set, int i, const double* yMid, double* fn,
                         double* margin) {
  const contactSlot* c = &set->items[i];
  int bodies[2] = {c->id.body1, c->id.body2};
  for (int side = 0; side < 2; ++side) {
    const pdBody* b = &model->bodies[bodies[side]];
    if (b->fixed) continue;
    const double* yb = yMid + PD_BODY_STATE_SIZE * b->stateIndex;
    set->poses[bodies[side]] = pose_of(pd_layout_x(yb), pd_layout_q(yb));
  }
  pdPairFrame frame;
  frame.p1 = NULL;
  pdContactGeom g;
  pdVec3 du;
  contact_motion(model, c, yMid, set->poses, &frame, &g, NULL, &du);
  pdSprings sp = springs_load(yMid + spring_base(model) + PD_CONTACT_STATE_SIZE * i);
  pdContactForce f;
  pd_contact_force(&c->params, &sp, g.normal, du, &f);
  *fn = f.fn;
  *margin = f.coneMargin;
}

// The slopes of the kink that contact i's stick–slip change inside a step of h leaves (onset_bound.h), in the error
// norm's units, into e->kink: on body1, body2 (0 for a fixed body) and the contact's springs. The rate jump ġ is the
// cone's margin's, from its values at the step's start, the first half step's end and the end (the larger of the half
// steps' chords and the parabola's slope at its crossing); without the middle, or off the damper-determined branch
// (no finite margin), the rate the springs and the cone can reach, k_t |Δu_t| + μ k_n |Δu_n|.
static void transition_kink(const pdModel* model, pdContactSet* set, int i, const double* yMid, double h) {
  const contactSlot* c = &set->items[i];
  contactEval* e = &set->eval[i];
  const pdContactParams* p = &c->params;
  double g0 = c->force.coneMargin, g1 = e->force.coneMargin, gm = NAN, fnMid;
  if (yMid && isfinite(g0) && isfinite(g1)) switching_at(model, set, i, yMid, &fnMid, &gm);
  double rate;
  if (isfinite(gm)) {
    double theta = 1.0 - crossing_age_mid(g0, gm, g1, h) / h;
    double a = 2.0 * (g1 - 2.0 * gm + g0), b = g1 - g0 - a;
    rate = fmax(fmax(fabs(gm - g0), fabs(g1 - gm)) / (0.5 * h), fabs(b + 2.0 * a * theta) / h);
  } else {
    double approach = pd_v3_dot(e->du, e->geom.normal);
    double slide = pd_v3_norm(pd_v3_sub(e->du, pd_v3_scale(e->geom.normal, approach)));
    rate = pd_series(p->k1t, p->k2t) * slide + p->mu * pd_series(p->k1n, p->k2n) * fabs(approach);
  }
  double ftNorm = pd_v3_norm(e->force.ft);
  pdVec3 along = ftNorm > 0.0 ? pd_v3_scale(e->force.ft, 1.0 / ftNorm) : (pdVec3){0.0, 0.0, 0.0};
  int bodies[2] = {c->id.body1, c->id.body2};
  for (int side = 0; side < 2; ++side) {
    const pdBody* body = &model->bodies[bodies[side]];
    e->kink[side] = 0.0;
    if (body->fixed) continue;
    pdVec3 arm = pd_v3_sub(e->geom.point, set->poses1[bodies[side]].x);
    const pdMat3* w = &set->invInertiaWorld[bodies[side]];
    double turning;
    if (ftNorm > 0.0) {
      turning = pd_v3_norm(pd_mat3_mulv(w, pd_v3_cross(arm, along)));
    } else {  // no direction to follow: |W (r × t̂)| ≤ ‖W‖_F |r| for every t̂
      double frobenius = 0.0;
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) frobenius += w->m[r][k] * w->m[r][k];
      turning = sqrt(frobenius) * pd_v3_norm(arm);
    }
    e->kink[side] = rate * fmax(body->invMass, turning * body->size) / model->settings.vmax;
  }
  double damper = pd_series(p->c1t, p->c2t);
  e->kink[2] = damper > 0.0 ? rate / (damper * c->deltaMax) : 0.0;
}

// The step's stick–slip kinks' slopes summed per moving body into set->kinkSum (in the contacts' order), over the
// contacts whose change is inside the step (slipChanged): one pass, whatever the number of changes.
static void sum_kinks(const pdModel* model, pdContactSet* set) {
  for (int j = 0; j < set->count; ++j)
    if (set->eval[j].slipChanged) set->kinkSum[set->items[j].id.body1] = set->kinkSum[set->items[j].id.body2] = 0.0;
  for (int j = 0; j < set->count; ++j) {
    if (!set->eval[j].slipChanged) continue;
    const pdContactId* id = &set->items[j].id;
    if (!model->bodies[id->body1].fixed) set->kinkSum[id->body1] += set->eval[j].kink[0];
    if (!model->bodies[id->body2].fixed) set->kinkSum[id->body2] += set->eval[j].kink[1];
  }
}

// The error bound of contact i's change inside a step of h: its kink's slopes summed with those of the step's other
// changes on the same bodies (sum_kinks), the largest.
static double transition_bound(const pdModel* model, const pdContactSet* set, int i, double h) {
  const pdContactId* id = &set->items[i].id;
  double sum1 = model->bodies[id->body1].fixed ? 0.0 : set->kinkSum[id->body1];
  double sum2 = model->bodies[id->body2].fixed ? 0.0 : set->kinkSum[id->body2];
  return pd_transition_error_bound(fmax(fmax(sum1, sum2), set->eval[i].kink[2]), h);
}

// Whether the force law at the step's end left a mode contact c held over the step (holdModes): the normal force's
// sign, or stick and slip where they are held (pd_contact_slip_held) and the contact pushed throughout.
static bool held_mode_changed(const contactSlot* c, const contactEval* e) {
  bool pushEnd = !pd_contact_force_pulls(&e->force);
  if (pushEnd != c->heldPush) return true;
  return pushEnd && pd_contact_slip_held(&c->params) && e->force.slip != c->heldSlip;
}

// A held mode the force law left inside a step of h (docs/events.md, "Modes within a step"). Since the change the
// held law applied a force and spring rates the free law would not; their difference grows from 0 there, about
// linearly, so over the τ since it the held law gave half the end's difference times τ too much: e->modeImpulse and
// e->modeSprings take that out at the commit. Sets them and *tau, and returns the error bound (onset_bound.h's units)
// of what the correction leaves: the difference's curvature over τ and the error of τ itself (interpolated, at the
// contact's frequency ω), and the bodies' positions, which the correction does not move.
static double held_change(const pdModel* model, pdContactSet* set, int i, const pdSprings* springs, const double* yMid,
                          double h, double* tauOut) {
  const contactSlot* c = &set->items[i];
  contactEval* e = &set->eval[i];
  const pdContactParams* p = &c->params;
  pdContactForce held;
  pd_contact_force_held(p, springs, e->geom.normal, e->du, c->heldPush, c->heldSlip, &held);
  bool pushEnd = !pd_contact_force_pulls(&e->force);
  const pdVec3 zero = {0, 0, 0};
  pdVec3 dF = pd_v3_sub(c->heldPush ? held.force : zero, pushEnd ? e->force.force : zero);
  // the change's time: where F_n (pushing or not) or the cone's margin (stick or slip) crossed zero; the earlier
  double tau = 0.0, fnMid = NAN, marginMid = NAN;
  if (yMid) switching_at(model, set, i, yMid, &fnMid, &marginMid);
  if (pushEnd != c->heldPush)
    tau = yMid ? crossing_age_mid(c->force.fn, fnMid, e->force.fn, h) : crossing_age(c->force.fn, e->force.fn, h);
  if (pushEnd && c->heldPush && e->force.slip != c->heldSlip)
    tau = fmax(tau, yMid ? crossing_age_mid(c->force.coneMargin, marginMid, e->force.coneMargin, h)
                         : crossing_age(c->force.coneMargin, e->force.coneMargin, h));
  *tauOut = tau;
  e->modeImpulse = pd_v3_scale(dF, -0.5 * tau);
  const pdSprings* a = &held.rate;
  const pdSprings* b = &e->force.rate;
  double half = -0.5 * tau;
  e->modeSprings = (pdSprings){half * (a->s1n - b->s1n), half * (a->s2n - b->s2n),
                               pd_v3_scale(pd_v3_sub(a->s1t, b->s1t), half), pd_v3_scale(pd_v3_sub(a->s2t, b->s2t), half)};
  if (!(tau > 0.0)) return 0.0;
  // the correction's relative error: the difference's curvature over τ (~ωτ/6, taken as ωτ), and τ's error, from the
  // interpolant's error near the step's end: ~(ωh)²/12 of τ from the parabola, ~ωh/2 from the chord
  double omega = sqrt(fmax(pd_series(p->k1n, p->k2n), pd_series(p->k1t, p->k2t)) / p->massMin);
  double spread = omega * tau + (yMid ? omega * omega * h * h / 12.0 : 0.5 * omega * h);
  double impulse = pd_v3_norm(e->modeImpulse);
  const pdSprings* d = &e->modeSprings;
  double spring = fmax(fmax(fabs(d->s1n), fabs(d->s2n)), fmax(pd_v3_norm(d->s1t), pd_v3_norm(d->s2t)));
  double size = INFINITY;
  if (!model->bodies[c->id.body1].fixed) size = model->bodies[c->id.body1].size;
  if (!model->bodies[c->id.body2].fixed) size = fmin(size, model->bodies[c->id.body2].size);
  double velocity = impulse * spread / (p->massMin * model->settings.vmax);
  double position = impulse * tau / (3.0 * p->massMin * size);
  return PD_MODE_BOUND_SAFETY * fmax(fmax(velocity, spring * spread / c->deltaMax), position);
}

// When contact i (slipping at the step's start, state y0) stops slipping, s after the start, predicted from its
// relative tangential velocity there and the rate the start's slope gives it (each body's v̇ + ω̇ × r + ω × (ω × r)):
// the time that velocity's component along itself takes to reach zero at that rate; INFINITY where it does not
// decelerate. A block sliding to rest decelerates at μ g: the prediction is then its stop up to the contact's own
// spring, which turns it within a fraction of the contact's period.
static double predicted_stop(const pdModel* model, const pdContactSet* set, int i, const double* y0) {
  const contactSlot* c = &set->items[i];
  pdVec3 u = {0, 0, 0}, a = {0, 0, 0};
  const int bodies[2] = {c->id.body1, c->id.body2};
  for (int k = 0; k < 2; ++k) {
    const pdBody* body = &model->bodies[bodies[k]];
    if (body->fixed) continue;
    const double* yb = y0 + PD_BODY_STATE_SIZE * body->stateIndex;
    pdVec3 r = pd_v3_sub(c->point, pd_layout_x(yb)), w = pd_layout_w(yb);
    pdVec3 uk = velocity_at(model, y0, bodies[k], r);
    // the slope's rows are v̇ and ω̇ where y's are v and ω: the same point velocity of them is v̇ + ω̇ × r
    pdVec3 ak = pd_v3_add(velocity_at(model, set->startSlope, bodies[k], r), pd_v3_cross(w, pd_v3_cross(w, r)));
    double sign = k == 0 ? 1.0 : -1.0;
    u = pd_v3_add(u, pd_v3_scale(uk, sign)), a = pd_v3_add(a, pd_v3_scale(ak, sign));
  }
  pdVec3 n = c->normal;
  pdVec3 ut = pd_v3_sub(u, pd_v3_scale(n, pd_v3_dot(u, n))), at = pd_v3_sub(a, pd_v3_scale(n, pd_v3_dot(a, n)));
  double closing = -pd_v3_dot(ut, at);  // m²/s³
  return closing > 0.0 ? pd_v3_dot(ut, ut) / closing : INFINITY;
}

// The retry of a step of h whose stages passed a stop predicted at stopAt (s after its start), refined to `floor`
// (refine_step): a step ending half a floor before the stop, which slips to its end and is kept, then one of just
// under two floors that holds the stop and is not refined again; halving where the prediction is not inside the step
// (then it was wrong, and halving closes in on the stop as before). Each aimed retry is shorter than the trial it
// retries, so retries from one start end: the prediction, from the start alone, is the same for each, and a step that
// ends before it and still crosses is halved.
static double stop_aimed_retry(double stopAt, double floor, double h) {
  if (!(stopAt < h)) return 0.5 * h;
  if (stopAt > 1.5 * floor) return stopAt - 0.5 * floor;
  return fmin(0.5 * h, PD_STOP_HOLD_FLOORS * floor);
}

pdEventVerdict pd_contact_events(const pdModel* model, pdState* s, double h, const double* y1, const double* yMid,
                                 double* hRetry, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  int base = spring_base(model);
  poses_from(model, s->y, set->poses0);
  poses_from(model, y1, set->poses1);
  // the stages one after the other: broad phase (the poses above included), contact analysis (the travel
  // limit included), interference, contact analysis
  double* analysisSeconds = &s->stageSeconds[pd_stageContactAnalysis];

  // 0. no tunnelling: bodies that may meet must not pass through each other's thinnest width in one step
  int pairCount = pd_contact_search_broad_phase(model, set, s->y, y1, h, set->poses0, set->poses1);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageBroadPhase]);
  if (pd_contact_search_travel_retry(model, set, pairCount, h, hRetry)) {
    ++s->count.travelRetries;
    pd_stopwatch_lap(watch, analysisSeconds);
    return pd_eventRetry;
  }

  // 1. C0 at y1: tracking, forces, reversals
  contactLoop job = {.model = model, .set = set, .y = y1};
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS, tracking_range, &job);
  // only an implicit trial evaluates the derivative at its end after its contact events (its dense output's slope)
  if (s->implicit && pd_implicit_active(s->implicit))
    keep_tracked(model, set, y1);
  else
    set->trackedValid = false;
  double refineStep = 0.0;  // the largest refinement bound among the contacts that changed mode (0: none)
  double locate = h;        // the step that ends just past the earliest held mode's change to locate (h: none)
  pdOnsets mode = pd_onsets_effective(s->onsets, model->movingCount);
  bool bounded = mode == pd_onsetsBounded || mode == pd_onsetsHeld;
  int slipChanges = 0;
  bool stopAimed = set->slipReversals;  // every change refined is a crossed contact's stop (predicted_stop)
  double stopAt = INFINITY;             // s after the step's start: the earliest stop predicted among them
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    contactEval* e = &set->eval[i];
    if (set->holdModes && held_mode_changed(c, e)) {
      // corrected at the commit where its bound allows, or when it cannot be located any closer; else located
      pdSprings sp = loop_springs(&job, i);
      double tau, bound = held_change(model, set, i, &sp, yMid, h, &tau);
      double past = h - (1.0 - PD_MODE_LAND_PAST) * tau;
      if (set->correctHeld || pd_onset_bound_allows(bound, model->settings.tol) ||
          set->modeRetries >= PD_MODE_RETRIES_MAX ||
          past <= model->settings.dtmin || past >= h || s->stepper == pd_stepperRK4Fixed) {
        e->modeCorrected = true;
        e->modeBound = bound;
      } else {
        locate = fmin(locate, past);
      }
      continue;
    }
    if (set->holdModes && pd_contact_slip_held(&c->params)) continue;  // held: a change is the branch above
    if (!changes_mode(set, c, &e->force)) continue;
    // bounded events leave a change inside the step where its bound allows (onset_bound.h; below, once every
    // change's kink is known); others refine it
    if (bounded) {
      transition_kink(model, set, i, yMid, h);
      e->slipChanged = true;
      ++slipChanges;
      continue;
    }
    refineStep = fmax(refineStep, refine_step(model, &c->params));
    stopAimed = false;
  }
  if (slipChanges > 0) sum_kinks(model, set);
  for (int i = 0; slipChanges > 0 && i < set->count; ++i) {
    contactEval* e = &set->eval[i];
    if (!e->slipChanged) continue;
    bool allowed = pd_onset_bound_allows(transition_bound(model, set, i, h), model->settings.tol);
    if (allowed)
      e->modeBound = pd_transition_error_bound(fmax(fmax(e->kink[0], e->kink[1]), e->kink[2]), h);  // its own share
    // an implicit trial's stage that left the start's slip is refined whatever the bound, which is step doubling's:
    // W, linearised in that slip, does not hold the stick it crossed into (docs/events.md, "A stop inside an implicit
    // step"); at the refinement's floor it stays in its step, counted with its bound as any change left there
    bool crossed = set->slipReversals && set->items[i].crossed;
    if (!allowed || crossed) refineStep = fmax(refineStep, refine_step(model, &set->items[i].params));
    if (!allowed && !crossed) stopAimed = false;
    if (crossed && stopAimed) stopAt = fmin(stopAt, predicted_stop(model, set, i, s->y));
  }
  pd_stopwatch_lap(watch, analysisSeconds);
  // only the adaptive stepper refines: the fixed one keeps its step (work-precision sweeps compare steps)
  if (refineStep > 0.0 && s->stepper != pd_stepperRK4Fixed && 0.5 * h >= refineStep) {
    ++s->count.refinements;
    *hRetry = stopAimed ? stop_aimed_retry(stopAt, refineStep, h) : 0.5 * h;
    return pd_eventRetry;
  }
  if (locate < h) {
    ++s->count.refinements;
    ++set->modeRetries;
    *hRetry = locate;
    return pd_eventRetry;
  }

  // 2. the contacts at y1 that C0 does not have
  pd_contact_search(model, s, y1, pairCount, set->poses0, set->poses1, watch);

  // 3. onsets: the earliest new contact that began inside the step and went deeper than its tolerance (a
  // pair onset close enough to the step's end joins there instead)
  double earliest = pd_onsets_earliest(model, set, h, pd_onsets_effective(s->onsets, model->movingCount), y1, s->t + h);
  pdEventVerdict verdict = pd_eventAccept;
  if (earliest <= 1.0 && pd_onsets_may_retry(set)) {
    double hOnset = earliest * h;
    if (hOnset > model->settings.dtmin && hOnset < h) {
      ++s->count.eventRetries;
      ++set->onsetRetries;
      *hRetry = hOnset;
      verdict = pd_eventRetry;
    } else if (hOnset <= model->settings.dtmin) {
      // the onset lies within dt_min of the start: add those contacts at t0 (virtual contacts, §4.4.3)
      // when they approach there; their springs start at 0 at t0
      int count = 0;
      for (int i = 0; i < set->count; ++i) {
        set->next[count] = set->items[i];
        set->next[count].springs = springs_load(s->y + base + PD_CONTACT_STATE_SIZE * i);
        ++count;
      }
      int added = 0;
      for (int k = 0; k < set->candidateCount; ++k) {
        const candidate* c = &set->candidates[k];
        if (!c->approaching || c->inherit >= 0 || c->released || c->onset * h > model->settings.dtmin) continue;
        pdContactGeom g0;
        const pdContactId* id = &c->geom.id;
        pd_contact_track(model, id, &set->poses0[id->body1], &set->poses0[id->body2], &g0);
        pdVec3 du = relative_velocity(model, s->y, set->poses0, id, g0.point);
        if (pd_v3_dot(du, g0.normal) > 0.0) continue;  // separating: with springs at 0 it would pull
        if (count == set->capacity) pd_contact_set_reserve_list(set, count + 1);
        contactSlot* k = &set->next[count++];
        *k = new_slot(model, &g0);
        // a contact back on the same features after a micro-separation keeps its tangential springs here too
        if (set->history && pd_history_take(set->history, id, g0.normal, &k->params, &k->loadScale, &k->springs))
          ++s->count.historyKept;
        ++added;
      }
      if (added > 0) {
        s->count.contactsVirtual += added;
        install(model, s, count, false);
        poses_from(model, s->y, set->poses0);
        prepare_list(model, set, s->y, set->poses0);
        verdict = pd_eventRestart;
      }
    }
  }
  if (verdict == pd_eventAccept && earliest <= 1.0) ++s->warnings[pd_warnLateOnset];
  pd_stopwatch_lap(watch, analysisSeconds);  // the contact search after the interference, and the onsets
  return verdict;
}

// A listed contact takes a broken one's normal springs (handover_to_listed) only while their normals are within this
// cosine (25°): the springs' force then goes on about along the line it had.
#define PD_HANDOVER_LISTED_COS 0.9

// The normal deflection of springs sp, m: how far they are pressed together (s2n − s1n, the depth they carry).
static double normal_deflection(const pdSprings* sp) { return sp->s2n - sp->s1n; }

// Contacts of C0 broken geometrically with no successor among the new contacts (not transferred) may be continued
// by a contact already listed: two edge pairs at one corner, or an edge pair and the vertex's face contact. The
// corner's depth is then carried by the survivor, whose springs may have started at zero when it was found
// already deep; without the broken contact's springs the depth they carried is met by no force, and the pair
// sinks by it. So the survivor among next[0 .. count) whose features continue the broken one's and whose normal
// springs carry less takes the broken one's normal springs (never more energy than the two held). The
// tangential springs stay the survivor's: they are its own sliding history.
static void handover_to_listed(const pdModel* model, pdContactSet* set, const double* y1, int count) {
  int base = spring_base(model);
  for (int i = 0; i < set->count; ++i) {
    const contactEval* e = &set->eval[i];
    if (e->tracked || e->transferred) continue;
    const contactSlot* c = &set->items[i];
    pdSprings left = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
    int best = -1;
    double deflection = normal_deflection(&left);
    for (int k = 0; k < count; ++k) {
      contactSlot* s = &set->next[k];
      // the survivor presses where the broken one did: its normal near the broken one's, and deep enough to take the
      // deflection (more would push it back beyond its own surface)
      double carried = fmin(deflection, s->depth);
      double cosine = pd_v3_dot(s->normal, e->geom.normal) * (s->id.body1 == c->id.body1 ? 1.0 : -1.0);
      if (normal_deflection(&s->springs) >= carried || cosine < PD_HANDOVER_LISTED_COS ||
          !pd_contact_continues(model, &c->id, &s->id))
        continue;
      if (best < 0 || normal_deflection(&s->springs) < normal_deflection(&set->next[best].springs)) best = k;
    }
    if (best < 0) continue;
    double scale = fmin(1.0, set->next[best].depth / deflection);
    set->next[best].springs.s1n = scale * left.s1n;
    set->next[best].springs.s2n = scale * left.s2n;
    set->eval[i].transferred = true;  // no hand-over trace: its normal springs went on
  }
}

void pd_contact_events_commit(const pdModel* model, pdState* s, const double* y1, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  int base = spring_base(model);
  pd_contact_set_reserve_list(set, set->count + set->candidateCount);
  int count = 0;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    const contactEval* e = &set->eval[i];
    bool ends = !e->tracked || pd_contact_force_pulls(&e->force);
    if (ends && e->modeCorrected) {  // a held push the force law released inside the step
      ++s->count.releasesCorrected;
      s->count.releaseBoundMax = fmax(s->count.releaseBoundMax, e->modeBound);
      s->count.releaseBoundSum += e->modeBound;
    }
    if (!e->tracked) {
      if (!e->transferred) ++s->count.breaksGeometry;
      continue;  // its springs go on in a listed contact, or into a hand-over trace, below
    }
    if (pd_contact_force_pulls(&e->force)) {
      ++s->count.breaksForce;
      if (set->history) {
        pdSprings left = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
        if (e->modeCorrected) springs_add(&left, &e->modeSprings);
        pd_history_leave(set->history, &c->id, &left, e->geom.normal, c->deltaMax, c->loadScale);
      }
      continue;
    }
    if (e->modeBound > 0.0 || e->modeCorrected) {
      ++s->count.transitionsUnlocated;
      s->count.transitionBoundMax = fmax(s->count.transitionBoundMax, e->modeBound);
      s->count.transitionBoundSum += e->modeBound;
    }
    contactSlot* k = &set->next[count++];
    *k = *c;
    k->springs = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
    if (e->modeCorrected) springs_add(&k->springs, &e->modeSprings);
    pd_springs_realign(&k->springs, c->normal, e->geom.normal, c->params.mu, &c->params, e->force.fn);
    k->normal = e->geom.normal;  // where the contact is now: its pair's modal dampers are set from it
    k->point = e->geom.point;
    k->depth = e->geom.depth;
    k->geometryCurrent = true;  // tracked at y1's poses, which the commit keeps (record_range)
  }
  handover_to_listed(model, set, y1, count);
  for (int i = 0; i < set->count && set->history; ++i) {
    const contactEval* e = &set->eval[i];
    if (e->tracked || e->transferred) continue;
    pdSprings left = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
    pd_history_leave_handover(set->history, &set->items[i].id, &left, e->geom.normal, e->force.fn,
                              set->items[i].loadScale);
  }
  for (int j = 0; j < set->candidateCount; ++j) {
    const candidate* cand = &set->candidates[j];
    if (cand->inherit >= 0) {
      const contactSlot* old = &set->items[cand->inherit];
      contactSlot* k = &set->next[count++];
      *k = new_slot(model, &cand->geom);
      // the successor of a hand-over takes its predecessor's springs: the normal ones as they are, the tangential
      // ones turned into its tangent plane and held within the friction cone of the predecessor's normal force,
      // so the force goes on where it was (and a spring the cone would not carry does not load it with slip); with
      // the stiffness they had (a pair of the same two bodies: the same constants but the load's factor)
      k->params = old->params;
      k->loadScale = old->loadScale;
      double fn = set->eval[cand->inherit].force.fn;
      k->springs = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * cand->inherit);
      pd_springs_realign(&k->springs, old->normal, cand->geom.normal, k->params.mu, &k->params, fn);
      pd_springs_clip_to_cone(&k->springs, &k->params, k->params.mu * fmax(fn, 0.0));
      ++s->count.contactsTransferred;
    } else if (cand->approaching) {
      contactSlot* k = &set->next[count++];
      *k = new_slot(model, &cand->geom);
      k->onsetAge = cand->onsetAge;
      if (set->history &&
          pd_history_take(set->history, &cand->geom.id, cand->geom.normal, &k->params, &k->loadScale, &k->springs))
        ++s->count.historyKept;
      else if (set->history && pd_history_take_handover(model, set->history, &cand->geom.id, cand->geom.normal,
                                                        &k->params, &k->loadScale, &k->springs))
        ++s->count.contactsTransferred;
      if (cand->onsetAge > 0.0) {
        s->count.onsetBoundMax = fmax(s->count.onsetBoundMax, cand->onsetBound);
        s->count.onsetBoundSum += cand->onsetBound;
      }
      ++s->count.contactsMade;
    }
  }
  set->candidateCount = 0;
  set->onsetRetries = 0;
  set->modeRetries = 0;
  // y1 lives in the stepper's scratch, which install may drop: the bodies' numbers go to state->y first, with the
  // held modes' corrections (all formed before any is applied: the list's order does not matter)
  memcpy(s->y, y1, (size_t)base * sizeof *s->y);
  for (int i = 0; i < set->count; ++i)
    if (set->eval[i].modeCorrected)
      pd_contact_impulse(model, set, s->y, set->poses1, &set->items[i].id, set->eval[i].geom.point,
                         set->eval[i].modeImpulse);
  install(model, s, count, false);
  poses_from(model, s->y, set->poses1);
  s->count.onsetsInterpolated += prepare_list(model, set, s->y, set->poses1);
  if (set->history) pd_history_age(model, set->history, set->poses1);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageContactAnalysis]);
}

// ---------------------------------------------------------------- dense output (dense_output.c)

// Captures in the whole process, numbered from 1 (islands capture on any thread).
static atomic_ulong captureSerials;

void pd_contact_set_capture(const pdContactSet* from, pdContactSet* view) {
  view->captureSerial = atomic_fetch_add(&captureSerials, 1) + 1;
  pd_contact_set_reserve_list(view, from->count > 0 ? from->count : 1);  // never NULL: memcpy of nothing still wants a pointer
  memcpy(view->items, from->items, (size_t)from->count * sizeof *view->items);
  for (int i = 0; i < from->count; ++i) {
    const contactSlot* c = &from->items[i];
    view->captured[i] = (capturedGeometry){c->normal, c->point, c->depth};
  }
  view->capturedCount = from->count;
  view->count = 0;  // nothing presented yet
  view->unevaluated = 0;
}

void pd_contact_set_present(const pdModel* model, pdContactSet* view) {
  int count = view->capturedCount;
  view->bodyListValid = false;
  // the inverse inertias are read for the bodies of the view's contacts only (the implicit stepper's linearisation,
  // which settles the state first): formed with the contacts when first read, at the same poses; a view without
  // contacts (a body in flight, presented at every sample) needs none
  if (count == 0) {
    view->count = 0;
    view->unevaluated = 0;
    return;
  }
  // every slot still as the last presentation left it (none evaluated since: a settle evaluates them all)
  bool asPresented = view->count == count && view->unevaluated == count;
  view->count = count;
  view->inertiasPending = true;
  // each contact as captured (a presentation at another time of the same step evaluated it there), evaluated at
  // the sample only when read (pd_contact_set_settle): most samples' observers read the bodies alone
  for (int i = 0; i < count && !asPresented; ++i) {
    contactSlot* c = &view->items[i];
    c->normal = view->captured[i].normal;
    c->point = view->captured[i].point;
    c->depth = view->captured[i].depth;
    c->unevaluated = true;
  }
  view->unevaluated = count;
  view->unevaluatedModel = model;
}

void pd_contact_set_settle(pdContactSet* set, double* y) {
  if (set->unevaluated == 0) return;
  const pdModel* model = set->unevaluatedModel;
  const pdPose* poses = set->settlePoses;
  poses_from(model, y, set->settlePoses);
  if (set->inertiasPending) world_inverse_inertias(model, set, poses);
  set->inertiasPending = false;
  int base = spring_base(model);
  // realigned as a commit realigns the contacts it keeps (one that pulls keeps its springs: a commit drops it),
  // then recorded as record() records: the same geometry and relative velocity, the force of the springs as
  // they are now
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = 0; i < set->count; ++i) {
    contactSlot* c = &set->items[i];
    if (!c->unevaluated) continue;
    double* yc = y + base + PD_CONTACT_STATE_SIZE * i;
    pdSprings sp = springs_load(yc);
    pdContactGeom g;
    pdVec3 du;
    contact_motion(model, c, y, poses, &frame, &g, NULL, &du);
    // the normal force decides (pd_contact_fn_pulls) whether the springs are realigned before the whole force
    double fn = pd_contact_normal_force(&c->params, &sp, g.normal, du);
    if (!pd_contact_fn_pulls(fn)) {
      pd_springs_realign(&sp, c->normal, g.normal, c->params.mu, &c->params, fn);
      springs_store(yc, &sp);
    }
    pd_contact_force(&c->params, &sp, g.normal, du, &c->force);
    record_geometry(c, &g);
    hold_modes(c);
    c->unevaluated = false;
  }
  set->unevaluated = 0;
  ++set->evaluations;
}

// ---------------------------------------------------------------- islands (islands.c)

void pd_contact_set_bodies(const pdContactSet* set, int i, int* body1, int* body2) {
  PD_ASSERT(i >= 0 && i < set->count);
  *body1 = set->items[i].id.body1;
  *body2 = set->items[i].id.body2;
}

static int remap_body(const int* map, int body) {
  int mapped = map[body];
  PD_ASSERT(mapped >= 0);
  return mapped;
}

// Contact i of `from` (a state of `fromModel`) as a slot of another model's list, into *c: its bodies renumbered by
// `map` (fromModel body → the other's), its springs read from from->y. Written in place: a slot is ~0.5 kB, and
// one returned by value was copied twice for every contact at every sample (the islands' gather).
static void remap_slot(contactSlot* c, const pdModel* fromModel, const pdState* from, int i, const int* map) {
  *c = from->contacts->items[i];
  c->id.body1 = remap_body(map, c->id.body1);
  c->id.body2 = remap_body(map, c->id.body2);
  c->springs = springs_load(from->y + spring_base(fromModel) + PD_CONTACT_STATE_SIZE * i);
}

// Installs next[0 .. count) as the list of `to` (a state of `model`), with no candidates or retries pending.
static void install_moved(const pdModel* model, pdState* to, int count, bool ordered) {
  to->contacts->candidateCount = 0;
  to->contacts->onsetRetries = 0;
  to->contacts->modeRetries = 0;
  install(model, to, count, ordered);  // sorted by id: the order the slots came in does not matter
}

// Whether map[0 .. n) ascends: a list sorted by id (pd_contact_id_compare reads the bodies' order and equality
// alone) stays sorted with its bodies renumbered by it.
static bool ascending(const int* map, int n) {
  for (int i = 1; i < n; ++i)
    if (!(map[i - 1] < map[i])) return false;
  return true;
}

void pd_contact_set_scatter(const pdModel* model, const pdState* from, const int* contacts, int count,
                            const pdModel* sub, pdState* to, const int* toSub) {
  pdContactSet* set = to->contacts;
  pd_contact_set_settle(from->contacts, from->y);  // the new island goes on from the springs realigned at T
  if (set->history) pd_history_clear(set->history);  // its traces' ids are another model's
  pd_contact_set_reserve_list(set, count);
  for (int k = 0; k < count; ++k) {
    PD_ASSERT(contacts[k] >= 0 && contacts[k] < from->contacts->count);
    remap_slot(&set->next[k], model, from, contacts[k], toSub);
  }
  install_moved(sub, to, count, false);
  // what prepare_list derives from the bodies' poses; the slots (modal dampers, forces) come as they were
  poses_from(sub, to->y, set->poses1);
  world_inverse_inertias(sub, set, set->poses1);
  pd_stability_prepare(sub, set, set->poses1);
}

// The scene's list as gathered from the same capture of one island's view (pd_contact_set_gather): since that gather,
// the view was presented again (normal, point, depth, unevaluated) and either list may have been evaluated (its
// springs realigned, its force, geometry and held modes recorded); every other field of every slot is the capture's,
// renumbered as it was. Renews those fields and the springs: the slots a full gather would write. Where neither list
// was evaluated since (the scene's slots all still unevaluated, the view's all presented anew and it evaluated nothing
// since), the fields are the capture's in both and only the springs, interpolated at each presentation, are renewed.
static void regather(const pdModel* model, pdState* to, const pdModel* sub, const pdState* from) {
  pdContactSet* set = to->contacts;
  const pdContactSet* view = from->contacts;
  int base = spring_base(model), fromBase = spring_base(sub);
  bool unread = set->unevaluated == set->count && view->unevaluated == set->count &&
                view->evaluations == set->gatheredEvaluations;
  for (int i = 0; i < set->count && unread; ++i) {
    contactSlot* c = &set->items[i];
    c->springs = springs_load(from->y + fromBase + PD_CONTACT_STATE_SIZE * i);
    springs_store(to->y + base + PD_CONTACT_STATE_SIZE * i, &c->springs);
  }
  set->unevaluated = unread ? set->count : 0;
  for (int i = 0; i < set->count && !unread; ++i) {
    contactSlot* c = &set->items[i];
    const contactSlot* v = &view->items[i];
    c->normal = v->normal;
    c->point = v->point;
    c->depth = v->depth;
    c->force = v->force;
    c->heldPush = v->heldPush;
    c->heldSlip = v->heldSlip;
    c->unevaluated = v->unevaluated;
    set->unevaluated += c->unevaluated;
    c->springs = springs_load(from->y + fromBase + PD_CONTACT_STATE_SIZE * i);
    springs_store(to->y + base + PD_CONTACT_STATE_SIZE * i, &c->springs);
  }
  set->candidateCount = 0;
  set->onsetRetries = 0;
  set->modeRetries = 0;
  set->bodyListValid = false;
  set->recordedValid = set->trackedValid = false;
  set->unevaluatedModel = model;
}

void pd_contact_set_gather(const pdModel* model, pdState* to, int parts, const pdModel* const* subs,
                           const pdState* const* from, const int* const* toModel) {
  pdContactSet* set = to->contacts;
  if (set->history) pd_history_clear(set->history);
  int total = 0;
  for (int p = 0; p < parts; ++p) total += from[p]->contacts->count;
  if (total == 0 && set->count == 0) {  // an empty list stays empty (a lone body in flight, gathered every sample)
    PD_ASSERT(to->n == spring_base(model));
    set->bodyListValid = false;
    set->recordedValid = set->trackedValid = false;  // its bodies were just gathered: what was kept is of other numbers
    return;
  }
  // a lone island presenting the same step's list again (a body in contact, gathered at every sample)
  unsigned long serial = parts == 1 ? from[0]->contacts->captureSerial : 0;
  if (serial != 0 && serial == set->gatheredSerial && total == set->count) {
    regather(model, to, subs[0], from[0]);
    set->gatheredEvaluations = from[0]->contacts->evaluations;
    return;
  }
  pd_contact_set_reserve_list(set, total);
  int count = 0;
  for (int p = 0; p < parts; ++p)
    for (int i = 0; i < from[p]->contacts->count; ++i)
      remap_slot(&set->next[count++], subs[p], from[p], i, toModel[p]);
  // one island's list (sorted: installed so) renumbered in ascending order is sorted (a lone body, every sample)
  install_moved(model, to, count, parts == 1 && ascending(toModel[0], subs[0]->bodyCount));
  // an island's contacts presented and not read there come unevaluated, with their springs as interpolated: the
  // scene's state evaluates them when read, at the same numbers (its bodies' are the islands')
  for (int i = 0; i < count; ++i) set->unevaluated += set->items[i].unevaluated;
  set->unevaluatedModel = model;
  set->gatheredSerial = serial;
  set->gatheredEvaluations = parts == 1 ? from[0]->contacts->evaluations : 0;
}

// The state's vectors grow with its contact list: install, above, calls it between steps (state_layout.h).
void pd_state_reserve_contacts(const pdModel* model, pdState* s, int contacts) {
  pd_contact_set_reserve_list(s->contacts, contacts);
  int needed = spring_base(model) + PD_CONTACT_STATE_SIZE * contacts;
  if (needed > s->capacity) {
    int c = s->capacity > 0 ? s->capacity : 1;
    while (c < needed) c *= 2;
    s->y = pd_grow(s->y, c, sizeof *s->y);
    s->weight = pd_grow(s->weight, c, sizeof *s->weight);
    // the stepper's vectors hold no data between steps: reallocate rather than copy
    free(s->work);
    s->work = pd_zeroed((size_t)c * PD_STEPPER_WORK_VECTORS, sizeof *s->work);
    s->capacity = c;
  }
  if (s->implicit) pd_implicit_reserve(s->implicit, model->movingCount, pd_state_contact_room(model, s));
}
