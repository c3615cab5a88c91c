// polydyn — the contact list of a state: contact forces inside the derivative and the contact events
// between steps (paper Fig. 8, §3.4, §4.2–§4.4; DESIGN §3.5).
//
// Design note. The loop of Fig. 8 runs as: the stepper proposes a step from (t0, y0) to y1 with the
// contact list C0 fixed; the error control accepts it; pd_contact_events then analyses y1:
//  1. every contact of C0 is tracked to y1 (VF by (18), EE by closest points) and its force evaluated
//     there; a slip/stick change, a reversal of the normal relative velocity (the springs turn from
//     loading to unloading) or of the tangential relative velocity inside the step halves the step until
//     it is shorter than a fraction of the shortest contact period (§3.4);
//  2. the broad phase, the interference test and the contact search give the contacts C1 at y1; a
//     contact of C1 not in C0 that approaches (Δu_n < 0: with its springs at 0 it would push) is new.
//     A new contact found deeper than the onset tolerance began inside the step: its onset fraction δ is
//     interpolated (App. C) and the step retried to end there (t0 + δ·h); an onset within dt_min of the
//     start makes it a virtual contact, added at t0 with its springs at 0 and the step restarted. With
//     pair onsets (pd_onsetsPair, or pd_onsetsAuto in a system of more than PD_ONSETS_CROWD_BODIES moving bodies:
//     README, "Contact onsets") a contact whose onset lies less than
//     PD_ONSET_PAIR_OMEGA_TAU / ω before the step's end (ω its undamped angular frequency) does not cut the step: the
//     interpolation is applied to the pair alone at commit (start_late_contacts), so one onset does not send every body
//     back.
//  3. on acceptance, contacts of C0 whose feature left the other (vertex projected outside its face, EE
//     closest points off an edge) break geometrically — unless a sliding vertex moved on to another face
//     of the same body, which keeps its springs (face continuity, §4.4.3); contacts whose normal springs
//     would pull (F_n < 0) break by force; the survivors' springs are realigned to the new normal and
//     clipped to the friction cone (§3.4); new contacts join with their springs at 0. The list is
//     re-sorted by id and the springs re-laid in the state vector. record() then forms every contact's
//     geometry (a tracked contact's is tracking's, at the same poses) and force at the new state; the next
//     step's first derivative, at that very state, takes them from there (pd_contact_set_recorded_at).
// Contacts start at zero spring deflection where they are added, so a late start shifts a contact's rest
// point by the depth it was found at but injects no energy; the onset tolerance bounds that shift. A pair
// onset instead starts where its pair alone would be after the τ since the onset (start_late_contacts):
// springs at that deflection x and the two bodies given the impulse of those τ seconds (normal, and the
// friction cone's when they slide), so its energy and phase are its own and its rest point sits d − x ≈
// d (ωτ)²/6 deeper (d the depth reached without it).
// A slip at the rounding of Δu (PD_ONSET_PAIR_SLIP_REL) counts as none: its direction is noise, and friction
// along it broke a flush stack's bitwise symmetry (README, "Contact onsets").
#include "contact_set.h"

#ifdef PD_SELF_CHECKS
#include <gsl/gsl_eigen.h>
#endif

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "broad_phase.h"
#include "clock.h"
#include "contact_history.h"
#include "grow.h"
#include "help_desk.h"
#include "interference.h"
#include "material.h"
#include "model_contact.h"
#include "onset_bound.h"
#include "state_layout.h"

#define PI 3.14159265358979323846

// A new contact found deeper than this fraction of its δ_max at the end of a step is interpolated back
// to its onset: its springs start at 0 where it is added, so a late start moves its rest point by that
// depth; 1e-3 δ_max keeps the shift a thousandth of the design deflection (A3 asks for sinkage to 1 %).
#define PD_ONSET_DEPTH_TOL_REL 1e-3
// Onset retries per step: the interpolation is exact for uniform motion and lands within O(h²) otherwise,
// so one or two retries normally suffice; a bound keeps a pathological case from stalling the run.
#define PD_ONSET_RETRIES_MAX 4
// A pair onset (pd_onsetsPair) is applied to the pair alone when it lies at most this many radians of the
// contact's fastest undamped oscillation (ω = √(k_s/m_min)) before the step's end: its motion since the
// onset is integrated alone (onset_motion), and the rest point it leaves sits ≈ d (ωτ)²/6 deeper. Measured on
// cases/bench/pile_10.scene (0.5 s): 0.5 left 435 onset retries and 16 % more derivative evaluations than
// 1.0 (279), 2.0 took 1 % fewer (122 retries) at 4× the rest-point shift.
#define PD_ONSET_PAIR_OMEGA_TAU 1.0
// ... and when the depth it reached meanwhile is at most this part of its δ_max: the contact's rest point
// then sits at most ~ this × (ωτ)²/6 ≈ 0.042 δ_max deeper than an exactly located onset's. Without it a
// spinning sliver's contacts, found up to 2 δ_max deep (the travel guard's bound), joined with their rest
// points δ_max down (soak seed 1 scene 7: 4.0 δ_max of overlap).
#define PD_ONSET_PAIR_DEPTH_REL 0.25
// A pair onset's slip below this fraction of |Δu| at its point is none: removing the normal part leaves ~1e-16
// |Δu| of rounding whose direction is noise, and friction along it broke a flush stack's symmetry (soak seed 1
// scene 147: README, "Contact onsets"). The friction so dropped is at most 1e-9 m |Δu|.
#define PD_ONSET_PAIR_SLIP_REL 1e-9
// Steps containing a stick/slip change are halved down to this fraction of the shortest
// contact period: the event is then located to ~5 % of the contact's own time scale. 1 % changed no
// Gedanken result by more than 1e-4 of its tolerance and cost a pile of 10 boxes 27 % more derivative
// evaluations (205 376 against 149 568 for cases/sweep/pile_10.scene): its steps are already ~2.5 % of
// the period (the stability bound), and every halving throws away a whole trial step.
#define PD_REFINE_PERIOD_FRACTION 0.05
// Stability bound of the adaptive step (paper §3.3: the contact's time constants set the step it can
// take): (h/2) ω_max ≤ this, ω_max a Gershgorin bound on the contacts' fastest mode (stability_prepare). Classic
// RK4 is stable to |hλ| ≈ 2.8 along both the negative real and the imaginary axis; 2.5 leaves a margin
// for what the bound does not see (contacts coupled through a fixed body's neighbours count none). Without
// the bound the error control walks the step up to the stability edge, where round-off grows until a
// step is rejected: a block at rest then jitters at the tolerance (µm/s) instead of round-off.
#define PD_STABLE_STEP_OMEGA 2.5
// Relative margin on the stability bounds (stability_prepare, stability_tight) against the rounding of their
// sums (~1e-15 relative): where a Gershgorin bound is exact (a single contact), rounding must not take it below
// ω_max².
#define PD_STABLE_MARGIN 1e-9
// Tunnelling guard: over one step, two bodies whose swept boxes overlap may move relative to each other by
// at most this fraction of the thinner one's width. A quarter keeps a vertex that crossed a face within
// the first half of the body, so the face it crossed is still the nearest one and the contact is found
// with the right face; the step is retried shorter (with a little safety) otherwise.
#define PD_TRAVEL_WIDTH_FRACTION 0.25
// ... and by at most this many of the pair's design deflections δ_max: a vertex that sank deeper than its
// distance to the border of the face it crossed finds a side face nearest, and the contact is missed (a
// cube landing with its corners a few mm inside a face's border, at 1 m/s and 10 ms steps). Two δ_max
// keeps the sinking within the deflection the springs are designed for; the onset retry then finds the
// moment of contact. It costs steps only while two bodies' swept boxes overlap.
#define PD_TRAVEL_DEFLECTIONS 2.0
#define PD_TRAVEL_RETRY_SAFETY 0.9

typedef struct contactSlot {
  pdContactId id;
  pdContactParams params;  // modal dampers set per contact when its pair's contacts change (set_modal_dampers)
  double deltaMax;   // m: the springs' error weight, the smaller δ_max of the two bodies
  // at the last accepted state (for realignment, refinement and output)
  pdVec3 normal, point;
  double depth;
  bool geometryCurrent;  // normal, point and depth are the geometry at the poses record() runs at (set by a
                         // commit for a tracked contact: tracking formed it at those poses; record() clears it)
  pdContactForce force;
  pdSprings springs;  // used only while the list is rebuilt
  double onsetAge;    // s: a pair onset's time since the interpolated onset, until start_late_contacts (else 0)
  pdVec3 onsetImpulse;  // N·s, on body 1: start_late_contacts' scratch
  double modalMass;     // kg: the mass per contact of its pair's joint motion along n (set_modal_dampers; 0: none)
  int modalCount;       // contacts its pair had when set_modal_dampers last set its dampers (0: not yet)
} contactSlot;

// A pair's search certificate (contact_analysis.h, "search certificates") and when to issue its next, kept beside
// its interference cache from one search to the next.
typedef struct pairCertificate {
  pdSearchCertificate cert;  // margin 0: none
  int contacts;              // the pair's contacts of C0 it exempts
  bool used;                 // a search was skipped on it
  int wait;                  // quiet searches to let pass before the next is issued
  int backoff;               // the wait after the next one that saves no search
} pairCertificate;
// The longest wait between certificates of a pair whose certificates save no search (it doubles each time from 1).
#define CERT_BACKOFF_MAX 64

// What pd_contact_set_present changes in a captured slot besides its force (dense output's view).
typedef struct capturedGeometry {
  pdVec3 normal, point;
  double depth;
} capturedGeometry;

// Analysis of one contact of C0 at the end of a trial step.
typedef struct contactEval {
  bool tracked;       // still geometrically valid
  bool transferred;   // its vertex moved on to another face (a candidate carries its springs)
  pdContactGeom geom;
  pdContactForce force;
  pdVec3 du;            // relative velocity at the contact point, m/s
  double modeBound;     // a stick–slip change left inside the step: its error bound (onset_bound.h), else 0
} contactEval;

// One contact's share of a derivative evaluation (pd_contact_forces), kept until the per-body sums.
typedef struct contactPush {
  pdVec3 point;  // where the force acts, world
  pdVec3 force;  // on body 1, N
  bool pulls;    // its normal springs would pull: no force
} contactPush;

// One part of the contact search (search_range): the contacts found for its pairs, pair after pair.
typedef struct searchPart {
  pdContactGeom* found;
  int foundCount, foundCapacity;
  pdContactId* previous;  // (capacity) scratch: the ids of one pair's contacts of C0
} searchPart;

// A contact of C1 that is not in C0.
typedef struct candidate {
  pdContactGeom geom;
  double onset;       // δ ∈ [0, 1]
  bool approaching;   // Δu_n < 0 at the end of the step
  double onsetAge;    // s since the interpolated onset when it joins as a pair onset (pd_onsetsPair), else 0
  int inherit;        // index in C0 of the contact whose springs it carries (face continuity), or -1
  double onsetBound;  // the error bound of joining it as a pair onset (onset_bound.h), when it does (else 0)
} candidate;

// Contact i's share in the stiffness of the undamped contact modes. With K_i^½ = √k_t I + (√k_n − √k_t) n nᵀ
// (series constants; k_t = 0 without friction or while sliding) and, for each moving body B of the contact,
// r = p_i − x_B, the contacts' relative velocities are J q̇ (J_iB = σ [I, −[r]ₓ], σ = +1 on body1, −1 on body2)
// and ω_max² is the largest eigenvalue both of M = K^½ J 𝕄⁻¹ Jᵀ K^½ (contact space, blocks
//   M_ij = Σ_B σ_i σ_j (K_i^½ K_j^½ / m_B + (K_i^½ [r_i]ₓᵀ)(W_B [r_j]ₓ K_j^½)),   W_B = R I⁻¹ Rᵀ)
// and of S = 𝕄^-½ Jᵀ K J 𝕄^-½ (body space: 6 × 6 blocks per body and per touching pair), which share their
// nonzero eigenvalues.
typedef struct stabilityTerms {
  pdMat3 k;             // K_i^½
  pdMat3 left[2], right[2];  // K^½ [r]ₓᵀ and W [r]ₓ K^½ per body (body1, body2)
  pdVec3 arm[2];             // r = p_i − x_B per body (body1, body2)
  double overdamp;           // ζ + √(ζ² − 1) for the most over-damped direction (1 when ζ ≤ 1)
} stabilityTerms;

// A moving body's block of the body-space bound (stability_tight): 𝕄^-½ (1/√m and W^½ = R P diag(I_k^-½) (R P)ᵀ
// at the list's poses, P the principal axes), the diagonal block S_BB being summed, and the absolute row sums.
typedef struct bodySpaceBlock {
  double invSqrtMass;
  pdMat3 invSqrtInertia;
  double diagonal[6][6];
  double rows[6];
} bodySpaceBlock;

struct pdContactSet {
  pdContactHistory* history;  // tangential springs of contacts broken by force, for a return (contact_history.h)
  int count, capacity;
  contactSlot* items;      // (capacity) sorted by id
  contactEval* eval;       // (capacity) per contact of C0, filled by pd_contact_events
  contactSlot* next;       // (capacity) scratch for rebuilding the list
  int candidateCount, candidateCapacity;
  candidate* candidates;
  searchPart search[2];  // the contact search's two halves of the pairs (help_desk.h's parts)
  int searchSplit;       // the first pair of part 1 (the pair count when the search was not split)
  int bodyCount;
  pdPose* poses;           // (bodyCount) of the last derivative evaluation
  pdPose* poses0;          // (bodyCount) at the start of the analysed step
  pdPose* poses1;          // (bodyCount) at its end
  pdAabb* boxes;           // (bodyCount)
  pdBroadPhase* broad;
  pdPair* pairs;
  int pairCapacity;
  pdPairSatCache *cache, *cacheNext;
  pairCertificate *certs, *certsNext;  // (cacheCapacity) beside cache, cacheNext
  bool* touching;  // (cacheCapacity) did pair p of the contact search interfere
  bool* certified;                        // (cacheCapacity) was pair p's search skipped on its certificate
  int *pairPrevious, *pairPreviousCount;  // (cacheCapacity) pair p's contacts of C0: items[first .. first + count)
  int *pairFound, *pairFoundCount;        // (cacheCapacity) its contacts found: its part's found[first .. + count)
  int cacheCount, cacheCapacity;
  pdVec3 *force, *torque;  // (movingCount) contact force and moment on each moving body, world
  double* travel;          // (bodyCount) how far each body's points moved over the analysed step, m (fixed: 0)
  int onsetRetries;        // onset retries of the step under way
  // stability bound (stability_prepare, stability_tight), sized with the list
  stabilityTerms* stability;  // (capacity)
  int* bodyFirst;          // (bodyCount + 1) contacts of body k: bodyList[bodyFirst[k] … bodyFirst[k + 1])
  int* bodyList;           // (2 capacity)
  bool bodyListValid;      // bodyFirst/bodyList list the current contacts (stability_prepare; install clears it)
  double stableStep;       // s: the largest stable step for the current list, once stableKnown (INFINITY: no contacts)
  double stableCheap;      // s: the step of the cheap bound alone, never above stableStep (stability_prepare)
  double cheapOmega2;      // the cheap bound's ω_max², its rounding margin included
  bool stableKnown;        // stableStep computed for the current list (it is computed only when needed)
  long tightFormed;        // tight bounds formed for a step's limit (pd_contact_set_tight_formed)
  bodySpaceBlock* bodyBlocks;  // (bodyCount) stability_tight's
  const pdPose* stablePoses;   // the poses of the list's stability_prepare (unchanged until the step's limit)
  double overdamp;         // the largest over-damping factor of the list's contacts (stabilityTerms)
  pdVec3* bodyRowsK;       // (bodyCount) per row p: Σ_q |(K_j^½)_pq| summed over the contacts j of each body
  pdVec3* bodyRowsRight;   // (bodyCount) the same for W [r_j]ₓ K_j^½ (j's end on that body)
  pdMat3* invInertiaWorld; // (bodyCount) R I⁻¹ Rᵀ at the poses of the list's last preparation (fixed: 0)
  contactPush* push;       // (capacity) per contact, of the last derivative evaluation
  // the state record() formed every contact's force at (its slots' force, point and rates), while recordedValid:
  // a derivative at the very same numbers takes them from there (pd_contact_forces)
  double* recordedY;
  const double* recordedFrom;  // where that state was (only a derivative at those numbers there is compared)
  int recordedCapacity;
  bool recordedValid;          // cleared by a list installed or cleared
  int capturedCount;           // a dense output's view (dense_output.h): the captured list's length, its slots in items
  capturedGeometry* captured;  // (capacity) a view's: each captured slot's normal, point and depth, which a
                               // presentation overwrites in items and the next one restores
  pdHelpDesk* help;        // where the per-contact and per-pair loops post half their work, or NULL (help_desk.h)
};

static pdPose pose_of(pdVec3 x, pdQuat q) { return (pdPose){x, pd_quat_to_mat3(pd_quat_normalize(q))}; }

static void reserve_list(pdContactSet* set, int capacity) {
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

// The contact search's per-pair lists, to cacheCapacity.
static void grow_pair_lists(pdContactSet* set) {
  set->certified = pd_grow(set->certified, set->cacheCapacity, sizeof *set->certified);
  set->certs = pd_grow(set->certs, set->cacheCapacity, sizeof *set->certs);
  set->certsNext = pd_grow(set->certsNext, set->cacheCapacity, sizeof *set->certsNext);
  set->pairPrevious = pd_grow(set->pairPrevious, set->cacheCapacity, sizeof *set->pairPrevious);
  set->pairPreviousCount = pd_grow(set->pairPreviousCount, set->cacheCapacity, sizeof *set->pairPreviousCount);
  set->pairFound = pd_grow(set->pairFound, set->cacheCapacity, sizeof *set->pairFound);
  set->pairFoundCount = pd_grow(set->pairFoundCount, set->cacheCapacity, sizeof *set->pairFoundCount);
}

// A set with its per-body arrays; with `search`, also the contact search's (broad phase, pairs, caches, candidates)
// and room for the list a state starts with.
static pdContactSet* create(const pdModel* model, bool search) {
  pdContactSet* set = calloc(1, sizeof *set);
  PD_ASSERT(set != NULL);
  int n = model->bodyCount;
  set->bodyCount = n;
  set->force = pd_grow(NULL, model->movingCount, sizeof *set->force);
  set->bodyFirst = pd_grow(NULL, n + 1, sizeof *set->bodyFirst);
  set->invInertiaWorld = pd_grow(NULL, n, sizeof *set->invInertiaWorld);
  for (int i = 0; i < n; ++i) set->invInertiaWorld[i] = pd_mat3_zero();
  set->stableStep = set->stableCheap = INFINITY;
  set->stableKnown = true;
  set->bodyRowsK = pd_grow(NULL, n, sizeof *set->bodyRowsK);
  set->bodyBlocks = pd_grow(NULL, n, sizeof *set->bodyBlocks);
  set->bodyRowsRight = pd_grow(NULL, n, sizeof *set->bodyRowsRight);
  set->travel = calloc((size_t)(n > 0 ? n : 1), sizeof *set->travel);
  PD_ASSERT(set->travel != NULL);
  set->torque = pd_grow(NULL, model->movingCount, sizeof *set->torque);
  set->poses = pd_grow(NULL, n, sizeof *set->poses);
  set->poses0 = pd_grow(NULL, n, sizeof *set->poses0);
  set->poses1 = pd_grow(NULL, n, sizeof *set->poses1);
  set->boxes = pd_grow(NULL, n, sizeof *set->boxes);
  bool* fixed = pd_grow(NULL, n, sizeof *fixed);
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &model->bodies[i];
    fixed[i] = b->fixed;
    set->poses[i] = set->poses0[i] = set->poses1[i] = pose_of(b->x0, b->q0);
    set->boxes[i] = pd_aabb_of(&b->shape, set->poses[i].x, &set->poses[i].R);
  }
  if (!search) {
    free(fixed);
    return set;
  }
  set->broad = pd_broad_phase_create(n, fixed, 0.0);
  PD_ASSERT(set->broad != NULL);
  set->history = pd_history_create();
  free(fixed);
  reserve_list(set, 4 * model->movingCount + 16);
  set->candidateCapacity = 64;
  set->candidates = pd_grow(NULL, set->candidateCapacity, sizeof *set->candidates);
  for (int part = 0; part < 2; ++part) {
    set->search[part].foundCapacity = 64;
    set->search[part].found = pd_grow(NULL, set->search[part].foundCapacity, sizeof *set->search[part].found);
  }
  set->pairCapacity = 2 * n + 16;
  set->pairs = pd_grow(NULL, set->pairCapacity, sizeof *set->pairs);
  set->cacheCapacity = set->pairCapacity;
  set->cache = pd_grow(NULL, set->cacheCapacity, sizeof *set->cache);
  set->cacheNext = pd_grow(NULL, set->cacheCapacity, sizeof *set->cacheNext);
  set->touching = pd_grow(NULL, set->cacheCapacity, sizeof *set->touching);
  grow_pair_lists(set);
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
  free(set->candidates);
  for (int part = 0; part < 2; ++part) {
    free(set->search[part].previous);
    free(set->search[part].found);
  }
  free(set->force);
  free(set->stability);
  free(set->bodyFirst);
  free(set->bodyList);
  free(set->bodyRowsK);
  free(set->bodyBlocks);
  free(set->bodyRowsRight);
  free(set->invInertiaWorld);
  free(set->travel);
  free(set->torque);
  free(set->poses);
  free(set->poses0);
  free(set->poses1);
  free(set->boxes);
  pd_broad_phase_free(set->broad);
  free(set->pairs);
  free(set->cache);
  free(set->cacheNext);
  free(set->touching);
  free(set->pairPrevious);
  free(set->pairPreviousCount);
  free(set->pairFound);
  free(set->pairFoundCount);
  free(set->certs);
  free(set->certified);
  free(set->certsNext);
  free(set);
}

void pd_contact_set_clear(pdContactSet* set) {
  if (set->history) pd_history_clear(set->history);
  set->count = 0;
  set->bodyListValid = false;
  set->recordedValid = false;
  set->stableStep = set->stableCheap = INFINITY;
  set->stableKnown = true;
  set->candidateCount = 0;
  set->cacheCount = 0;
  set->onsetRetries = 0;
}

int pd_contact_set_count(const pdContactSet* set) { return set->count; }

const pdPose* pd_contact_set_poses(const pdContactSet* set) { return set->poses; }
const pdVec3* pd_contact_set_force(const pdContactSet* set) { return set->force; }
const pdVec3* pd_contact_set_torque(const pdContactSet* set) { return set->torque; }

static int spring_base(const pdModel* model) { return PD_BODY_STATE_SIZE * model->movingCount; }

static pdSprings springs_load(const double* y) {
  return (pdSprings){y[0], y[1], {y[2], y[3], y[4]}, {y[5], y[6], y[7]}};
}

static void springs_store(double* y, const pdSprings* s) {
  y[0] = s->s1n, y[1] = s->s2n;
  y[2] = s->s1t.x, y[3] = s->s1t.y, y[4] = s->s1t.z;
  y[5] = s->s2t.x, y[6] = s->s2t.y, y[7] = s->s2t.z;
}

// Body b's point velocity at lever arm r from its centre, at state y (0 for a fixed body).
static pdVec3 velocity_at(const pdModel* model, const double* y, int b, pdVec3 r) {
  const pdBody* body = &model->bodies[b];
  if (body->fixed) return (pdVec3){0, 0, 0};
  const double* yb = y + PD_BODY_STATE_SIZE * body->stateIndex;
  return pd_v3_add(pd_layout_v(yb), pd_v3_cross(pd_layout_w(yb), r));
}

// Velocity of body i's material point at world point p.
static inline pdVec3 point_velocity(const pdModel* model, const double* y, const pdPose* poses, int i, pdVec3 p) {
  return velocity_at(model, y, i, pd_v3_sub(p, poses[i].x));
}

// Δu = u1 − u2 of contact id's bodies at world point p (contact_force.h).
static inline pdVec3 relative_velocity(const pdModel* model, const double* y, const pdPose* poses,
                                       const pdContactId* id, pdVec3 p) {
  return pd_v3_sub(point_velocity(model, y, poses, id->body1, p), point_velocity(model, y, poses, id->body2, p));
}

// The poses of moving bodies [begin, end) at y.
static void poses_of_range(const pdModel* model, const double* y, pdPose* poses, int begin, int end) {
  for (int k = begin; k < end; ++k) {
    const double* yb = y + PD_BODY_STATE_SIZE * k;
    poses[model->movingBodies[k]] = pose_of(pd_layout_x(yb), pd_layout_q(yb));
  }
}

static void poses_from(const pdModel* model, const double* y, pdPose* poses) {
  poses_of_range(model, y, poses, 0, model->movingCount);
}

// Geometry and relative velocity of one contact at state y (poses of y given).
// frame: the loop's pair frame (pdPairFrame), shared by a pair's contacts (consecutive in the sorted list).
static void contact_motion(const pdModel* model, const contactSlot* c, const double* y, const pdPose* poses,
                           pdPairFrame* frame, pdContactGeom* geom, bool* tracked, pdVec3* du) {
  int b1 = c->id.body1, b2 = c->id.body2;
  if (tracked)
    *tracked = pd_contact_track_framed(model, &c->id, &poses[b1], &poses[b2], frame, geom);
  else
    pd_contact_geometry_framed(model, &c->id, &poses[b1], &poses[b2], frame, geom);
  if (geom->normal.x == 0.0 && geom->normal.y == 0.0 && geom->normal.z == 0.0) {
    // EE edges turned parallel inside a step: keep the last accepted geometry until the step's end drops it
    geom->normal = c->normal;
    geom->point = c->point;
    geom->depth = c->depth;
  }
  *du = relative_velocity(model, y, poses, &c->id, geom->point);
}

// Geometry, relative velocity and force of one contact at state y (contact_motion, then the force law).
static void evaluate(const pdModel* model, const contactSlot* c, const double* y, const pdPose* poses,
                     pdPairFrame* frame, const pdSprings* springs, pdContactGeom* geom, bool* tracked, pdVec3* du,
                     pdContactForce* f) {
  contact_motion(model, c, y, poses, frame, geom, tracked, du);
  pd_contact_force(&c->params, springs, geom->normal, *du, f);
}

void pd_contact_set_help(pdContactSet* set, pdHelpDesk* desk) { set->help = desk; }
pdHelpDesk* pd_contact_set_help_desk(const pdContactSet* set) { return set->help; }

// Contacts (or pairs) below which a loop is not split (help_desk.h): a handover costs about a microsecond, one
// contact's force ~0.1 us, one pair's interference test ~1 us.
#define PD_HELP_MIN_CONTACTS 128
#define PD_HELP_MIN_PAIRS 32

// What a loop over contacts or pairs reads (pd_help_for's ctx); each loop uses the fields it names.
typedef struct contactLoop {
  const pdModel* model;
  pdContactSet* set;
  const double* y;                // the state the loop evaluates
  double* dydt;                   // forces: where the spring rates go
  const pdPose *poses0, *poses1;  // the contact search: the poses at the step's start and end
  bool certificates;              // the contact search: pdState.searchCertificates
} contactLoop;

// Contacts [begin, end) of a derivative evaluation: their spring rates into dydt, their pushes into set->push.
static void forces_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    pdSprings s = springs_load(job->y + base + PD_CONTACT_STATE_SIZE * i);
    pdContactGeom g;
    pdVec3 du;
    pdContactForce f;
    evaluate(job->model, &set->items[i], job->y, set->poses, &frame, &s, &g, NULL, &du, &f);
    springs_store(job->dydt + base + PD_CONTACT_STATE_SIZE * i, &f.rate);
    set->push[i] = (contactPush){g.point, f.force, pd_contact_force_pulls(&f)};
  }
}

// Moving bodies [begin, end): their poses at job->y (set->poses).
static void poses_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  poses_of_range(job->model, job->y, job->set->poses, begin, end);
}

// Each moving body's contacts in contact order, as 2 i + (0 on body1, 1 on body2): bodyFirst/bodyList. Read by the
// tight stability bound (has_block) and by the force sums (sums_range), built by stability_prepare or, for a list
// installed without it, by the first derivative evaluation (the arrays are sized with the list: nothing is
// allocated).
static void list_bodies(const pdModel* model, pdContactSet* set) {
  int bodies = model->bodyCount;
  for (int k = 0; k <= bodies; ++k) set->bodyFirst[k] = 0;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    if (!model->bodies[c->id.body1].fixed) ++set->bodyFirst[c->id.body1 + 1];
    if (!model->bodies[c->id.body2].fixed) ++set->bodyFirst[c->id.body2 + 1];
  }
  for (int k = 0; k < bodies; ++k) set->bodyFirst[k + 1] += set->bodyFirst[k];
  // fill (bodyFirst[k] advances to bodyFirst[k + 1] and is shifted back after)
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    if (!model->bodies[c->id.body1].fixed) set->bodyList[set->bodyFirst[c->id.body1]++] = 2 * i;
    if (!model->bodies[c->id.body2].fixed) set->bodyList[set->bodyFirst[c->id.body2]++] = 2 * i + 1;
  }
  for (int k = bodies; k > 0; --k) set->bodyFirst[k] = set->bodyFirst[k - 1];
  set->bodyFirst[0] = 0;
  set->bodyListValid = true;
}

// Moving bodies [begin, end): the sums of their contacts' pushes, body by body over its contacts in contact order
// (bodyList), so each body's force and torque are the very sums of the loop over all contacts.
static void sums_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  const pdContactSet* set = job->set;
  for (int k = begin; k < end; ++k) {
    int body = job->model->movingBodies[k];
    pdVec3 force = {0, 0, 0}, torque = {0, 0, 0}, x = set->poses[body].x;
    for (int l = set->bodyFirst[body]; l < set->bodyFirst[body + 1]; ++l) {
      const contactPush* p = &set->push[set->bodyList[l] / 2];
      if (p->pulls) continue;
      pdVec3 moment = pd_v3_cross(pd_v3_sub(p->point, x), p->force);
      if (set->bodyList[l] % 2 == 0) {
        force = pd_v3_add(force, p->force);
        torque = pd_v3_add(torque, moment);
      } else {
        force = pd_v3_sub(force, p->force);
        torque = pd_v3_sub(torque, moment);
      }
    }
    set->force[k] = force;
    set->torque[k] = torque;
  }
}

// Contacts [begin, end) as record() formed them at this very state (pd_contact_forces): the same numbers as
// forces_range, which would form the same geometry, relative velocity and force from the same numbers again.
static void recorded_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  for (int i = begin; i < end; ++i) {
    const contactSlot* c = &set->items[i];
    springs_store(job->dydt + base + PD_CONTACT_STATE_SIZE * i, &c->force.rate);
    set->push[i] = (contactPush){c->point, c->force.force, pd_contact_force_pulls(&c->force)};
  }
}

bool pd_contact_set_recorded_at(const pdModel* model, const pdContactSet* set, const double* y) {
  // a step's stages evaluate in the stepper's scratch: only the place the recorded state was is compared (the list
  // is the recorded one while recordedValid, so is the state's length)
  if (!set->recordedValid || y != set->recordedFrom) return false;
  int n = spring_base(model) + PD_CONTACT_STATE_SIZE * set->count;
  return memcmp(y, set->recordedY, (size_t)n * sizeof *y) == 0;
}

void pd_contact_set_forget_recorded(pdContactSet* set) { set->recordedValid = false; }

void pd_contact_forces(const pdModel* model, pdContactSet* set, const double* y, double* dydt) {
  contactLoop job = {.model = model, .set = set, .y = y, .dydt = dydt};
  pd_help_for(set->help, model->movingCount, PD_HELP_MIN_BODIES, poses_range, &job);
  // the first derivative of a step after a commit is at the state record() has just evaluated (bit for bit)
  bool recorded = pd_contact_set_recorded_at(model, set, y);
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS, recorded ? recorded_range : forces_range, &job);
  if (!set->bodyListValid) list_bodies(model, set);  // a list installed without stability_prepare (a gather)
  pd_help_for(set->help, model->movingCount, PD_HELP_MIN_BODIES, sums_range, &job);
}

// Forward-difference steps of the linearisation: this fraction of a spring's deflection or δ_max, and of a relative
// velocity component or vmax, whichever is larger (~√ε: the truncation and rounding errors balance). The matrix need
// not be exact (a W-method keeps its order with any), only close enough to keep the stiff modes stable.
#define PD_LINEARISE_STEP_REL 1.5e-8

// F and ṡ of a contact as one vector: F (3), then the rates (8); F is 0 when it pulls (sums_range applies none).
static void force_and_rates(const pdContactParams* p, const double s[PD_CONTACT_STATE_SIZE], pdVec3 n, pdVec3 du,
                            double out[3 + PD_CONTACT_STATE_SIZE]) {
  pdSprings sp = springs_load(s);
  pdContactForce f;
  pd_contact_force(p, &sp, n, du, &f);
  pdVec3 force = pd_contact_force_pulls(&f) ? (pdVec3){0, 0, 0} : f.force;
  out[0] = force.x, out[1] = force.y, out[2] = force.z;
  springs_store(out + 3, &f.rate);
}

// Body b's centre at state y (a fixed body's where it stands).
static pdVec3 centre_at(const pdModel* model, const double* y, int b) {
  const pdBody* body = &model->bodies[b];
  return body->fixed ? body->x0 : pd_layout_x(y + PD_BODY_STATE_SIZE * body->stateIndex);
}

void pd_contact_set_linearise(const pdModel* model, pdContactSet* set, const double* y, pdContactLinear* out) {
  int base = spring_base(model);
  double vmax = model->settings.vmax;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    int b1 = c->id.body1, b2 = c->id.body2;
    pdContactLinear* l = &out[i];
    l->body1 = b1, l->body2 = b2;
    // the contact's point and normal as record() left them at the list's preparation, at y
    l->r1 = pd_v3_sub(c->point, centre_at(model, y, b1));
    l->r2 = pd_v3_sub(c->point, centre_at(model, y, b2));
    l->invInertia1 = set->invInertiaWorld[b1];
    l->invInertia2 = set->invInertiaWorld[b2];
    pdVec3 du = pd_v3_sub(velocity_at(model, y, b1, l->r1), velocity_at(model, y, b2, l->r2));
    double s[PD_CONTACT_STATE_SIZE], f0[3 + PD_CONTACT_STATE_SIZE], f1[3 + PD_CONTACT_STATE_SIZE];
    for (int j = 0; j < PD_CONTACT_STATE_SIZE; ++j) s[j] = y[base + PD_CONTACT_STATE_SIZE * i + j];
    force_and_rates(&c->params, s, c->normal, du, f0);
    for (int j = 0; j < PD_CONTACT_STATE_SIZE; ++j) {
      double keep = s[j];
      s[j] += PD_LINEARISE_STEP_REL * fmax(fabs(keep), c->deltaMax);
      double step = s[j] - keep;
      force_and_rates(&c->params, s, c->normal, du, f1);
      s[j] = keep;
      for (int r = 0; r < 3; ++r) l->Ds[r][j] = (f1[r] - f0[r]) / step;
      for (int r = 0; r < PD_CONTACT_STATE_SIZE; ++r) l->Gs[r][j] = (f1[3 + r] - f0[3 + r]) / step;
    }
    double u[3] = {du.x, du.y, du.z};
    for (int j = 0; j < 3; ++j) {
      double keep = u[j];
      u[j] += PD_LINEARISE_STEP_REL * fmax(fabs(keep), vmax);
      double step = u[j] - keep;
      force_and_rates(&c->params, s, c->normal, (pdVec3){u[0], u[1], u[2]}, f1);
      u[j] = keep;
      for (int r = 0; r < 3; ++r) l->Du[r][j] = (f1[r] - f0[r]) / step;
      for (int r = 0; r < PD_CONTACT_STATE_SIZE; ++r) l->Gu[r][j] = (f1[3 + r] - f0[3 + r]) / step;
    }
  }
}

double pd_contact_spring_energy(const pdContactSet* set, const double* y, int springBase) {
  double e = 0.0;
  for (int i = 0; i < set->count; ++i) {
    const pdContactParams* p = &set->items[i].params;
    pdSprings s = springs_load(y + springBase + PD_CONTACT_STATE_SIZE * i);
    e += 0.5 * (p->k1n * s.s1n * s.s1n + p->k2n * s.s2n * s.s2n + p->k1t * pd_v3_dot(s.s1t, s.s1t) +
                p->k2t * pd_v3_dot(s.s2t, s.s2t));
  }
  return e;
}

// ---------------------------------------------------------------- growing the state

void pd_state_reserve_contacts(const pdModel* model, pdState* s, int contacts) {
  reserve_list(s->contacts, contacts);
  int needed = spring_base(model) + PD_CONTACT_STATE_SIZE * contacts;
  if (needed <= s->capacity) return;
  int c = s->capacity > 0 ? s->capacity : 1;
  while (c < needed) c *= 2;
  s->y = pd_grow(s->y, c, sizeof *s->y);
  s->weight = pd_grow(s->weight, c, sizeof *s->weight);
  // the stepper's vectors hold no data between steps: reallocate rather than copy
  free(s->work);
  s->work = calloc((size_t)c * PD_STEPPER_WORK_VECTORS, sizeof *s->work);
  PD_ASSERT(s->work != NULL);
  s->capacity = c;
}

static int compare_slots(const void* a, const void* b) {
  return pd_contact_id_compare(&((const contactSlot*)a)->id, &((const contactSlot*)b)->id);
}

// Makes next[0..count) (springs inside the slots) the contact list: sorts it, lays out the springs after
// the bodies' numbers (already in state->y) in state->y, sets their weights and state->n. May grow the
// state's vectors: the stepper's scratch is dropped then, so nothing may still point into it.
static void install(const pdModel* model, pdState* s, int count) {
  pdContactSet* set = s->contacts;
  // a list that changed in no contact comes in sorted (ids are unique, so any sort gives the one order): checked
  // first, since qsort moves slots of ~0.5 kB through a scratch copy (7 % of cases/hard/stack_10.scene's work)
  bool sorted = true;
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
  set->bodyListValid = false;
  set->recordedValid = false;
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
  c.deltaMax = pd_model_pair_delta_max(model, g->id.body1, g->id.body2);
  c.normal = g->normal;
  c.point = g->point;
  c.depth = g->depth;
  return c;
}

// ---------------------------------------------------------------- modal dampers

// Mass per contact of one body pair's joint motion (material.h, "modal"): the pair's contacts i = 1 … n at
// points p_i with normals n_i (from b into a) pushed with equal unit forces. The relative acceleration of
// the contacts along their normals, summed, is 1ᵀA1 = |N|² (1/m_a + 1/m_b) + L_aᵀ J_a⁻¹ L_a + L_bᵀ J_b⁻¹ L_b
// with N = Σ n_i, L = Σ (p_i − x) × n_i (world inverse inertia J⁻¹ = R I⁻¹ Rᵀ), so the common mode carries
// m_c = n/1ᵀA1 per contact: m_eff for one contact, m/4 for a cube landing flat, m/2 on an edge. In P_t the
// same with one tangent t for all: n² (1/m_a + 1/m_b) + tᵀ [Σr]ₓᵀ J⁻¹ [Σr]ₓ t, averaged over two tangents.
static int compare_to_pair(const pdContactId* id, int a, int b);

typedef struct modalSums {
  pdVec3 normal, moment, arm;  // N, L, Σ r about one body's centre of mass
} modalSums;

static pdMat3 cross_matrix(pdVec3 r) { return (pdMat3){{{0, -r.z, r.y}, {r.z, 0, -r.x}, {-r.y, r.x, 0}}}; }

// a [r]ₓ: pd_mat3_mul with cross_matrix(r), its products with the zeros left out (the other terms added in the same
// order, so the same numbers up to the sign of a zero sum; the stability bound takes absolute values). a [r]ₓᵀ is
// a [−r]ₓ.
static pdMat3 mul_cross(const pdMat3* a, pdVec3 r) {
  pdMat3 m;
  for (int i = 0; i < 3; ++i) {
    const double* ai = a->m[i];
    m.m[i][0] = ai[1] * r.z + ai[2] * -r.y;
    m.m[i][1] = ai[0] * -r.z + ai[2] * r.x;
    m.m[i][2] = ai[0] * r.y + ai[1] * -r.x;
  }
  return m;
}

// invWorld: the body's R I⁻¹ Rᵀ (set->invInertiaWorld).
static void add_body_terms(const pdBody* b, const pdMat3* invWorld, const modalSums* s, double* qn, pdMat3* mt) {
  if (b->fixed) return;
  *qn += pd_v3_dot(s->normal, s->normal) * b->invMass + pd_v3_dot(s->moment, pd_mat3_mulv(invWorld, s->moment));
  const pdMat3 rx = cross_matrix(s->arm);
  pdMat3 rxT = pd_mat3_transpose(&rx);
  pdMat3 a = pd_mat3_mul(invWorld, &rx);
  pdMat3 m = pd_mat3_mul(&rxT, &a);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) mt->m[i][j] += m.m[i][j];
}

// The dampers of a pair are set when its contacts change (one made or broken: a new slot has modalCount 0, a
// survivor of a break a count that no longer matches) and then held until they change again, not re-derived
// from the pose after every step: a damper that followed the pose step by step was a staircase in time, whose
// steps made impacts converge only as ~tol^0.24 (the exit velocity of cases/sweep/eccentric_impact.scene's first
// impact 1.1e-5 m/s from tol 1e-12's at tol 1e-8); held, the force is smooth between contact events (1.4e-7).
static void set_modal_dampers(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  for (int first = 0, last; first < set->count; first = last) {
    contactSlot* c0 = &set->items[first];
    int a = c0->id.body1 < c0->id.body2 ? c0->id.body1 : c0->id.body2;
    int b = c0->id.body1 < c0->id.body2 ? c0->id.body2 : c0->id.body1;
    last = first + 1;
    while (last < set->count && compare_to_pair(&set->items[last].id, a, b) == 0) ++last;
    if (!c0->params.modalN && !c0->params.modalT) continue;
    bool unchanged = true;
    for (int i = first; i < last && unchanged; ++i) unchanged = set->items[i].modalCount == last - first;
    if (unchanged) continue;
    modalSums sa = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, sb = sa;
    for (int i = first; i < last; ++i) {
      const contactSlot* c = &set->items[i];
      pdVec3 n = c->id.body1 == a ? c->normal : pd_v3_scale(c->normal, -1.0);
      pdVec3 ra = pd_v3_sub(c->point, poses[a].x), rb = pd_v3_sub(c->point, poses[b].x);
      sa.normal = sb.normal = pd_v3_add(sa.normal, n);
      sa.moment = pd_v3_add(sa.moment, pd_v3_cross(ra, n));
      sb.moment = pd_v3_add(sb.moment, pd_v3_cross(rb, n));
      sa.arm = pd_v3_add(sa.arm, ra);
      sb.arm = pd_v3_add(sb.arm, rb);
    }
    const pdBody *A = &model->bodies[a], *B = &model->bodies[b];
    double count = (double)(last - first), qn = 0.0;
    pdMat3 mt = {{{0}}};
    add_body_terms(A, &set->invInertiaWorld[a], &sa, &qn, &mt);
    add_body_terms(B, &set->invInertiaWorld[b], &sb, &qn, &mt);
    // tangent-plane average: (trace − N̂ᵀ M N̂)/2 plus the translational n²(1/m_a + 1/m_b)
    double nn = pd_v3_norm(sa.normal);
    pdVec3 axis = nn > 0.0 ? pd_v3_scale(sa.normal, 1.0 / nn) : c0->normal;
    double trace = mt.m[0][0] + mt.m[1][1] + mt.m[2][2];
    double qt = count * count * (A->invMass + B->invMass) + 0.5 * (trace - pd_v3_dot(axis, pd_mat3_mulv(&mt, axis)));
    // a degenerate sum (normals cancelling) leaves 1ᵀA1 ~ 0: the clamp to the reduced mass takes over
    double massN = qn > 0.0 ? count / qn : INFINITY, massT = qt > 0.0 ? count / qt : INFINITY;
    for (int i = first; i < last; ++i) {
      pd_contact_modal_damping(&set->items[i].params, massN, massT);
      set->items[i].modalMass = fmin(massN, set->items[i].params.massPair);
      set->items[i].modalCount = last - first;
    }
  }
}

// ---------------------------------------------------------------- stability bound

static double row_abs_sum(const pdMat3* m, int row) {
  return fabs(m->m[row][0]) + fabs(m->m[row][1]) + fabs(m->m[row][2]);
}

static double overdamp_factor(double zeta) { return zeta > 1.0 ? zeta + sqrt(zeta * zeta - 1.0) : 1.0; }

// The absolute row sums of m.
static pdVec3 row_abs_sums(const pdMat3* m) {
  return (pdVec3){row_abs_sum(m, 0), row_abs_sum(m, 1), row_abs_sum(m, 2)};
}

// rows[r] += scale Σ_p |a_rp| w_p: bounds row r's absolute sum of a·b summed over all b whose rows sum to w.
static void add_weighted_rows(const pdMat3* a, pdVec3 w, double scale, double rows[3]) {
  for (int r = 0; r < 3; ++r)
    rows[r] += scale * (fabs(a->m[r][0]) * w.x + fabs(a->m[r][1]) * w.y + fabs(a->m[r][2]) * w.z);
}

static double step_of(double omega2, double overdamp) {
  double omega = sqrt(omega2) * overdamp;
  // the stepper keeps the result of two half steps (integrator.c): they are the ones that must be stable
  return omega > 0.0 ? 2.0 * PD_STABLE_STEP_OMEGA / omega : INFINITY;
}

// The stability bound in two parts, both Gershgorin bounds on ω_max² (never below it; README, Integration).
// stability_prepare (after every new list, O(contacts)) forms each contact's terms and a cheap bound of the
// contact-space matrix M above: by |Σ_j (A B_j)_rq| ≤ Σ_p |A_rp| |(B_j)_pq|, row r of contact i's Gershgorin sum
// is at most Σ over its moving ends B of Σ_p |(K_i^½)_rp| w_p / m_B + Σ_p |(K_i^½ [r_i]ₓᵀ)_rp| u_p, where w_p
// and u_p are the row-p absolute sums of K_j^½ and of W_B [r_j]ₓ K_j^½ summed over B's contacts j. Only when the
// step the stepper wants exceeds the cheap bound's (pd_contact_set_limit_step) is the tight one formed
// (stability_tight): the Gershgorin bound of the body-space matrix S, also O(contacts), and the bound is the
// smaller of the two. On a stack of boxes S's rows are far tighter than M's (a box's 16 contacts couple with each
// other in M, its 6 coordinates in S): on cases/bench/stack_20.scene ω_max² came out at 0.55–0.71 of M's exact
// Gershgorin bound (which was O(contacts × contacts per body); the true ω_max² 0.46–0.62 of it), so its steps
// are 1.2–1.35× longer. S's bound alone can be looser than M's (a box on an edge or a corner, its rows summing
// translation and rotation: up to 1.75× M's exact bound on cases/sweep/pile_10.scene), hence the minimum.

// Accumulates Gᵀ H into out (6 × 6) for G, H = [T | R] (3 × 6 each, given as their two 3 × 3 halves).
static void add_gram(const pdMat3* gT, const pdMat3* gR, const pdMat3* hT, const pdMat3* hR, double out[6][6]) {
  // G and H as 3 × 6 rows first: the loop over b then runs along contiguous rows, which the compiler vectorises
  // (each entry the same sum in the same order)
  double g[3][6], h[3][6];
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) {
      g[k][c] = gT->m[k][c], g[k][c + 3] = gR->m[k][c];
      h[k][c] = hT->m[k][c], h[k][c + 3] = hR->m[k][c];
    }
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) out[a][b] += g[0][a] * h[0][b] + g[1][a] * h[1][b] + g[2][a] * h[2][b];
}

// Contact i's G = K^½ J_iB 𝕄_B^-½ on its end e (body B): T = σ K^½ / √m_B, R = −σ K^½ [r]ₓ W_B^½.
static void contact_gram_factor(const stabilityTerms* t, int e, const bodySpaceBlock* b, pdMat3* T, pdMat3* R) {
  double sigma = e == 0 ? 1.0 : -1.0;
  pdMat3 krx = mul_cross(&t->k, t->arm[e]);
  pdMat3 krxw = pd_mat3_mul(&krx, &b->invSqrtInertia);
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) {
      T->m[r][q] = sigma * b->invSqrtMass * t->k.m[r][q];
      R->m[r][q] = -sigma * krxw.m[r][q];
    }
}

// Does moving body k have contacts in the list (a block of S)?
static bool has_block(const pdModel* model, const pdContactSet* set, int k) {
  return !model->bodies[k].fixed && set->bodyFirst[k] < set->bodyFirst[k + 1];
}

// Each block's 𝕄^-½ at `poses`, its sums cleared.
static void body_space_scales(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  for (int k = 0; k < model->bodyCount; ++k) {
    if (!has_block(model, set, k)) continue;
    const pdBody* body = &model->bodies[k];
    bodySpaceBlock* b = &set->bodyBlocks[k];
    b->invSqrtMass = sqrt(body->invMass);
    pdMat3 q = pd_mat3_mul(&poses[k].R, &body->principalAxes);  // principal axes in the world
    pdMat3 qd = q;
    for (int c = 0; c < 3; ++c) {
      double s = 1.0 / sqrt(body->principal[c]);
      for (int r = 0; r < 3; ++r) qd.m[r][c] *= s;
    }
    pdMat3 qt = pd_mat3_transpose(&q);
    b->invSqrtInertia = pd_mat3_mul(&qd, &qt);
    memset(b->diagonal, 0, sizeof b->diagonal);
    memset(b->rows, 0, sizeof b->rows);
  }
}

// The tight bound: the largest absolute row sum of S, over the blocks of every moving body with contacts and of
// every touching pair (the list is sorted by pair, so a pair's contacts are one run). ω_max², no margin.
static double stability_tight(const pdModel* model, pdContactSet* set) {
  body_space_scales(model, set, set->stablePoses);
  for (int first = 0, last; first < set->count; first = last) {
    const pdContactId* id0 = &set->items[first].id;
    int lo = id0->body1 < id0->body2 ? id0->body1 : id0->body2, hi = id0->body1 < id0->body2 ? id0->body2 : id0->body1;
    last = first + 1;
    while (last < set->count && compare_to_pair(&set->items[last].id, lo, hi) == 0) ++last;
    bool both = !model->bodies[lo].fixed && !model->bodies[hi].fixed;
    double pair[6][6] = {{0}};  // S_lo,hi
    for (int i = first; i < last; ++i) {
      const stabilityTerms* t = &set->stability[i];
      const pdContactId* id = &set->items[i].id;
      pdMat3 T[2], R[2];
      int ends[2] = {id->body1, id->body2};
      for (int e = 0; e < 2; ++e) {
        if (model->bodies[ends[e]].fixed) continue;
        bodySpaceBlock* b = &set->bodyBlocks[ends[e]];
        contact_gram_factor(t, e, b, &T[e], &R[e]);
        add_gram(&T[e], &R[e], &T[e], &R[e], b->diagonal);
      }
      if (both) {
        int eLo = id->body1 == lo ? 0 : 1;
        add_gram(&T[eLo], &R[eLo], &T[1 - eLo], &R[1 - eLo], pair);
      }
    }
    if (!both) continue;
    // S_hi,lo = S_lo,hiᵀ: lo's rows take the pair block's row sums, hi's its column sums
    bodySpaceBlock *bLo = &set->bodyBlocks[lo], *bHi = &set->bodyBlocks[hi];
    for (int a = 0; a < 6; ++a)
      for (int q = 0; q < 6; ++q) {
        bLo->rows[a] += fabs(pair[a][q]);
        bHi->rows[q] += fabs(pair[a][q]);
      }
  }
  double omega2 = 0.0;
  for (int k = 0; k < model->bodyCount; ++k) {
    if (!has_block(model, set, k)) continue;
    const bodySpaceBlock* b = &set->bodyBlocks[k];
    for (int a = 0; a < 6; ++a) {
      double row = b->rows[a];
      for (int q = 0; q < 6; ++q) row += fabs(b->diagonal[a][q]);
      omega2 = fmax(omega2, row);
    }
  }
  return omega2;
}

#ifdef PD_SELF_CHECKS
// Lists of at most this many contacts are checked (a dense eigenproblem of 3 × this size per list).
#define PD_STABILITY_CHECK_CONTACTS_MAX 32
// The self-check of the sanitizer and Debug builds: both bounds against ω_max², the largest eigenvalue (GSL) of
// the contact-space matrix M assembled from its own formula (the terms left and right), not from S.
static void stability_self_check(const pdModel* model, pdContactSet* set) {
  int c = set->count, n = 3 * c;
  if (c > PD_STABILITY_CHECK_CONTACTS_MAX) return;
  gsl_matrix* m = gsl_matrix_calloc((size_t)n, (size_t)n);
  PD_ASSERT(m != NULL);
  for (int i = 0; i < c; ++i)
    for (int j = 0; j < c; ++j) {
      const pdContactId *a = &set->items[i].id, *b = &set->items[j].id;
      const stabilityTerms *ti = &set->stability[i], *tj = &set->stability[j];
      int endsA[2] = {a->body1, a->body2}, endsB[2] = {b->body1, b->body2};
      for (int ea = 0; ea < 2; ++ea)
        for (int eb = 0; eb < 2; ++eb) {
          const pdBody* body = &model->bodies[endsA[ea]];
          if (endsA[ea] != endsB[eb] || body->fixed) continue;
          double sign = (ea == eb) ? 1.0 : -1.0;
          pdMat3 kk = pd_mat3_mul(&ti->k, &tj->k), rot = pd_mat3_mul(&ti->left[ea], &tj->right[eb]);
          for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q) {
              double v = sign * (kk.m[r][q] * body->invMass + rot.m[r][q]);
              *gsl_matrix_ptr(m, (size_t)(3 * i + r), (size_t)(3 * j + q)) += 0.5 * v;
              *gsl_matrix_ptr(m, (size_t)(3 * j + q), (size_t)(3 * i + r)) += 0.5 * v;
            }
        }
    }
  gsl_vector* eigenvalues = gsl_vector_alloc((size_t)n);
  gsl_eigen_symm_workspace* w = gsl_eigen_symm_alloc((size_t)n);
  PD_ASSERT(eigenvalues != NULL && w != NULL);
  gsl_eigen_symm(m, eigenvalues, w);
  double omega2 = gsl_vector_max(eigenvalues);
  gsl_eigen_symm_free(w);
  gsl_vector_free(eigenvalues);
  gsl_matrix_free(m);
  // the eigenvalue is exact to ~1e-15 of the largest entry; the bounds carry PD_STABLE_MARGIN
  double tight2 = stability_tight(model, set) * (1.0 + PD_STABLE_MARGIN);
  PD_ASSERT(set->cheapOmega2 >= omega2 * (1.0 - 1e-12));
  PD_ASSERT(tight2 >= omega2 * (1.0 - 1e-12));
}
#endif

static void stability_prepare(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  set->stableKnown = false;
  if (set->count == 0) {
    set->stableStep = set->stableCheap = INFINITY;
    set->cheapOmega2 = 0.0;
    set->stableKnown = true;
    return;
  }
  list_bodies(model, set);
  set->stablePoses = poses;
  int bodies = model->bodyCount;
  for (int k = 0; k < bodies; ++k) set->bodyRowsK[k] = set->bodyRowsRight[k] = (pdVec3){0, 0, 0};
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    const pdContactParams* p = &c->params;
    stabilityTerms* t = &set->stability[i];
    // a sliding contact's tangential spring is held at the friction limit: no tangential mode
    bool sticks = p->mu > 0.0 && !c->force.slip;
    double sn = sqrt(pd_series(p->k1n, p->k2n)), st = sticks ? sqrt(pd_series(p->k1t, p->k2t)) : 0.0;
    pdVec3 n = c->normal;
    double nv[3] = {n.x, n.y, n.z};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) t->k.m[r][q] = (r == q ? st : 0.0) + (sn - st) * nv[r] * nv[q];
    double zn = isfinite(p->zetaN) ? p->zetaN : 0.0, zt = p->mu > 0.0 && isfinite(p->zetaT) ? p->zetaT : 0.0;
    t->overdamp = fmax(overdamp_factor(zn), overdamp_factor(zt));
    int ends[2] = {c->id.body1, c->id.body2};
    for (int e = 0; e < 2; ++e) {
      const pdBody* b = &model->bodies[ends[e]];
      if (b->fixed) continue;
      t->arm[e] = pd_v3_sub(c->point, poses[ends[e]].x);
      t->left[e] = mul_cross(&t->k, pd_v3_scale(t->arm[e], -1.0));
      pdMat3 wrx = mul_cross(&set->invInertiaWorld[ends[e]], t->arm[e]);
      t->right[e] = pd_mat3_mul(&wrx, &t->k);
      set->bodyRowsK[ends[e]] = pd_v3_add(set->bodyRowsK[ends[e]], row_abs_sums(&t->k));
      set->bodyRowsRight[ends[e]] = pd_v3_add(set->bodyRowsRight[ends[e]], row_abs_sums(&t->right[e]));
    }
  }
  // the cheap bound
  double cheap2 = 0.0;
  set->overdamp = 1.0;
  for (int i = 0; i < set->count; ++i) {
    const stabilityTerms* ti = &set->stability[i];
    set->overdamp = fmax(set->overdamp, ti->overdamp);
    double rows[3] = {0, 0, 0};
    int ends[2] = {set->items[i].id.body1, set->items[i].id.body2};
    for (int e = 0; e < 2; ++e) {
      const pdBody* b = &model->bodies[ends[e]];
      if (b->fixed) continue;
      add_weighted_rows(&ti->k, set->bodyRowsK[ends[e]], b->invMass, rows);
      add_weighted_rows(&ti->left[e], set->bodyRowsRight[ends[e]], 1.0, rows);
    }
    cheap2 = fmax(cheap2, fmax(rows[0], fmax(rows[1], rows[2])));
  }
  set->cheapOmega2 = cheap2 * (1.0 + PD_STABLE_MARGIN);
  set->stableCheap = step_of(set->cheapOmega2, set->overdamp);
#ifdef PD_SELF_CHECKS
  stability_self_check(model, set);
#endif
}

long pd_contact_set_tight_formed(const pdContactSet* set) { return set->tightFormed; }

double pd_contact_set_limit_step(const pdModel* model, pdContactSet* set, double h, double fraction,
                                 bool* tightNeeded) {
  *tightNeeded = fraction * set->stableCheap < h;
  if (!*tightNeeded) return h;  // the bound, never below the cheap one's step, cannot bind
  if (!set->stableKnown) {
    ++set->tightFormed;
    double tight2 = stability_tight(model, set) * (1.0 + PD_STABLE_MARGIN);
    set->stableStep = step_of(fmin(set->cheapOmega2, tight2), set->overdamp);
    set->stableKnown = true;
  }
  return fmin(h, fraction * set->stableStep);
}

// Records geometry and force of every listed contact at state y for output, realignment and refinement.
// poses must be those of y.
static void record_geometry(contactSlot* c, const pdContactGeom* g) {
  c->normal = g->normal;
  c->point = g->point;
  c->depth = g->depth;
}

static void record_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  int base = spring_base(job->model);
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    contactSlot* c = &job->set->items[i];
    pdSprings sp = springs_load(job->y + base + PD_CONTACT_STATE_SIZE * i);
    if (c->geometryCurrent) {
      // the same geometry as evaluate() would form again (a pair onset's impulses change velocities, not poses)
      c->geometryCurrent = false;
      pdVec3 du = relative_velocity(job->model, job->y, job->poses1, &c->id, c->point);
      pd_contact_force(&c->params, &sp, c->normal, du, &c->force);
      continue;
    }
    pdContactGeom g;
    pdVec3 du;  // unused here
    evaluate(job->model, c, job->y, job->poses1, &frame, &sp, &g, NULL, &du, &c->force);
    record_geometry(c, &g);
  }
}

static void record(const pdModel* model, pdContactSet* set, const double* y, const pdPose* poses) {
  contactLoop job = {.model = model, .set = set, .y = y, .poses1 = poses};
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS, record_range, &job);
  // the next step's first derivative is at this state (after an accepted step: its k1)
  set->recordedValid = false;
  if (set->count == 0) return;  // nothing to take: not worth a copy and a comparison per derivative
  int n = spring_base(model) + PD_CONTACT_STATE_SIZE * set->count;
  if (n > set->recordedCapacity) {  // grown with the list, after a step
    set->recordedCapacity = 2 * n;
    set->recordedY = pd_grow(set->recordedY, (size_t)set->recordedCapacity, sizeof *set->recordedY);
  }
  memcpy(set->recordedY, y, (size_t)n * sizeof *y);
  set->recordedFrom = y;
  set->recordedValid = true;
}

// The normal motion of one contact over the τ since its onset, alone at the effective mass m, undamped
// frequency² k/m and damping c/m (a Kelvin–Voigt element, force never pulling): from deflection 0 at
// approach speed v0 to its deflection *x and approach speed *u at τ. Linear and short
// (ω τ <= PD_ONSET_PAIR_OMEGA_TAU): a few classic RK4 substeps are exact to ~(ωτ/8)⁵.
#define PD_ONSET_PAIR_SUBSTEPS 8
static void onset_motion(double omega2, double damping, double v0, double tau, double* xOut, double* uOut) {
  double x = 0.0, u = v0, dt = tau / PD_ONSET_PAIR_SUBSTEPS;
  for (int i = 0; i < PD_ONSET_PAIR_SUBSTEPS; ++i) {
    double a1 = -fmax(0.0, omega2 * x + damping * u);
    double x2 = x + 0.5 * dt * u, u2 = u + 0.5 * dt * a1, a2 = -fmax(0.0, omega2 * x2 + damping * u2);
    double x3 = x + 0.5 * dt * u2, u3 = u + 0.5 * dt * a2, a3 = -fmax(0.0, omega2 * x3 + damping * u3);
    double x4 = x + dt * u3, u4 = u + dt * a3, a4 = -fmax(0.0, omega2 * x4 + damping * u4);
    x += dt / 6.0 * (u + 2.0 * u2 + 2.0 * u3 + u4);
    u += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  }
  *xOut = x;
  *uOut = u;
}

// The effective mass of contact c's two bodies along its normal at its point, kg (INFINITY if neither moves).
static double point_mass(const pdModel* model, const pdContactSet* set, const pdPose* poses, const contactSlot* c) {
  double invMass = 0.0;
  for (int side = 0; side < 2; ++side) {
    int b = side == 0 ? c->id.body1 : c->id.body2;
    const pdBody* body = &model->bodies[b];
    if (body->fixed) continue;
    pdVec3 rn = pd_v3_cross(pd_v3_sub(c->point, poses[b].x), c->normal);
    invMass += body->invMass + pd_v3_dot(rn, pd_mat3_mulv(&set->invInertiaWorld[b], rn));
  }
  return invMass > 0.0 ? 1.0 / invMass : INFINITY;
}

// Pair onsets of a list just installed at state y (poses those of y; world inverse inertias and modal dampers
// set): each contact with an onset age τ > 0 is put where it would be after τ on its own (onset_motion, m the
// modal mass per contact or the point's effective mass, from its approach speed now): its normal springs at
// that deflection x, split as series springs share a static load (k1 s1 + k2 s2 = 0), and its two bodies
// given the normal impulse that slows their approach to that speed u. Its energy and phase are then the
// contact's own; its rest point sits deeper by the depth d reached without it, less x (≈ d (ωτ)²/6).
// All impulses are formed before any is applied, so the list's order does not matter. Returns the number
// of such contacts.
static int start_late_contacts(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses) {
  int base = spring_base(model), started = 0;
  for (int i = 0; i < set->count; ++i) {
    contactSlot* c = &set->items[i];
    if (c->onsetAge <= 0.0) continue;
    const pdContactParams* p = &c->params;
    double k = pd_series(p->k1n, p->k2n), damper = pd_series(p->c1n, p->c2n);
    // the approach speed and the slip at the contact point
    pdVec3 n = c->normal;
    pdVec3 du = relative_velocity(model, y, poses, &c->id, c->point);
    double approach = -pd_v3_dot(du, n);
    pdVec3 slip = pd_v3_sub(du, pd_v3_scale(n, -approach));  // tangential relative velocity
    double slipSpeed = pd_v3_norm(slip);
    if (slipSpeed <= PD_ONSET_PAIR_SLIP_REL * pd_v3_norm(du)) slipSpeed = 0.0;  // rounding, not slip
    c->onsetImpulse = (pdVec3){0, 0, 0};
    double mass = c->modalMass > 0.0 && isfinite(c->modalMass) ? c->modalMass : point_mass(model, set, poses, c);
    if (isfinite(mass) && approach > 0.0 && k > 0.0) {
      double x, u;
      onset_motion(k / mass, damper / mass, approach, c->onsetAge, &x, &u);
      x = fmin(fmax(x, 0.0), fmax(c->depth, 0.0));
      pdSprings sp = springs_load(y + base + PD_CONTACT_STATE_SIZE * i);
      sp.s1n = -k * x / p->k1n;
      sp.s2n = k * x / p->k2n;
      double normalImpulse = mass * fmax(0.0, approach - fmax(u, 0.0));  // the pair's contacts together slow it so
      c->onsetImpulse = pd_v3_scale(n, normalImpulse);
      // friction over τ: sliding, the cone's impulse μ J against the slip (at most what stops it), and the
      // tangential springs loaded to the cone (or to the slip since the onset, if less) against it
      double kt = pd_series(p->k1t, p->k2t);
      if (p->mu > 0.0 && kt > 0.0 && slipSpeed > 0.0) {
        pdVec3 along = pd_v3_scale(slip, 1.0 / slipSpeed);
        double frictionImpulse = fmin(p->mu * normalImpulse, mass * slipSpeed);
        c->onsetImpulse = pd_v3_sub(c->onsetImpulse, pd_v3_scale(along, frictionImpulse));
        double ft = fmin(p->mu * k * x, kt * slipSpeed * c->onsetAge);  // |F_t| on body 1, against the slip
        sp.s1t = pd_v3_scale(along, ft / p->k1t);                       // F_t = −k1t s1t = k2t s2t = −ft · along
        sp.s2t = pd_v3_scale(along, -ft / p->k2t);
      }
      springs_store(y + base + PD_CONTACT_STATE_SIZE * i, &sp);
    }
    ++started;
  }
  for (int i = 0; i < set->count && started > 0; ++i) {
    contactSlot* c = &set->items[i];
    if (c->onsetAge <= 0.0) continue;
    for (int side = 0; side < 2; ++side) {
      int b = side == 0 ? c->id.body1 : c->id.body2;
      const pdBody* body = &model->bodies[b];
      if (body->fixed) continue;
      pdVec3 j = side == 0 ? c->onsetImpulse : pd_v3_scale(c->onsetImpulse, -1.0);
      double* yb = y + PD_BODY_STATE_SIZE * body->stateIndex;
      pdVec3 v = pd_v3_add(pd_layout_v(yb), pd_v3_scale(j, body->invMass));
      pdVec3 w = pd_v3_add(pd_layout_w(yb),
                           pd_mat3_mulv(&set->invInertiaWorld[b], pd_v3_cross(pd_v3_sub(c->point, poses[b].x), j)));
      pd_layout_store(yb, v, w, pd_layout_x(yb), pd_layout_q(yb));
    }
    c->onsetAge = 0.0;
  }
  return started;
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
// modal dampers, the pair onsets' springs and impulses (start_late_contacts), each contact's geometry and
// force (record), and the stability bound, in that order (the bound reads which contacts slip). Returns the
// number of pair onsets started.
static int prepare_list(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses) {
  world_inverse_inertias(model, set, poses);
  set_modal_dampers(model, set, poses);
  int started = start_late_contacts(model, set, y, poses);
  record(model, set, y, poses);
  stability_prepare(model, set, poses);
  return started;
}

// ---------------------------------------------------------------- the contact search at y1

static void add_candidate(pdContactSet* set, const candidate* c) {
  if (set->candidateCount == set->candidateCapacity) {
    set->candidateCapacity *= 2;
    set->candidates = pd_grow(set->candidates, set->candidateCapacity, sizeof *set->candidates);
  }
  set->candidates[set->candidateCount++] = *c;
}

// Broad phase over the step: each moving body's box covers its boxes at both ends of the step, so a pair
// that met and parted (or tunnelled) inside the step is listed too. Returns the number of pairs.
static int broad_phase(const pdModel* model, pdState* s, const pdPose* poses0, const pdPose* poses1) {
  pdContactSet* set = s->contacts;
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    pdAabb a = pd_aabb_of(&model->bodies[i].shape, poses0[i].x, &poses0[i].R);
    pdAabb b = pd_aabb_of(&model->bodies[i].shape, poses1[i].x, &poses1[i].R);
    for (int d = 0; d < 3; ++d) a.lo[d] = fmin(a.lo[d], b.lo[d]), a.hi[d] = fmax(a.hi[d], b.hi[d]);
    set->boxes[i] = a;
  }
  bool updated = pd_broad_phase_update(set->broad, set->boxes);
  PD_ASSERT(updated);  // false only when memory runs out, like every other allocation here
  int pairCount = pd_broad_phase_pairs(set->broad, set->pairs, set->pairCapacity);
  if (pairCount > set->pairCapacity) {
    // grown between steps: the analysis runs after a step, outside the derivative
    set->pairCapacity = 2 * pairCount;
    set->pairs = pd_grow(set->pairs, set->pairCapacity, sizeof *set->pairs);
    pd_broad_phase_pairs(set->broad, set->pairs, set->pairCapacity);
  }
  if (pairCount > set->cacheCapacity) {
    set->cacheCapacity = set->pairCapacity;
    set->cache = pd_grow(set->cache, set->cacheCapacity, sizeof *set->cache);
    set->cacheNext = pd_grow(set->cacheNext, set->cacheCapacity, sizeof *set->cacheNext);
    set->touching = pd_grow(set->touching, set->cacheCapacity, sizeof *set->touching);
    grow_pair_lists(set);
  }
  return pairCount;
}

// How far body i's points move at most between two poses, m: the centre's displacement plus the largest
// vertex radius times the rotation angle.
static double travel(const pdBody* b, const pdPose* p0, const pdPose* p1) {
  pdMat3 r0t = pd_mat3_transpose(&p0->R);
  pdMat3 d = pd_mat3_mul(&p1->R, &r0t);  // the rotation over the step
  double cosAngle = fmax(-1.0, fmin(1.0, 0.5 * (d.m[0][0] + d.m[1][1] + d.m[2][2] - 1.0)));
  return pd_v3_norm(pd_v3_sub(p1->x, p0->x)) + b->radius * acos(cosAngle);
}

// The longest step (as a fraction of the step just taken) that keeps every listed pair's relative travel
// within PD_TRAVEL_WIDTH_FRACTION of the thinner body's width; 1 when the step is short enough.
static double travel_limit(const pdModel* model, pdContactSet* set, int pairCount) {
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    set->travel[i] = travel(&model->bodies[i], &set->poses0[i], &set->poses1[i]);
  }
  double limit = 1.0;
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    double moved = set->travel[a] + set->travel[b];
    double allowed = fmin(PD_TRAVEL_WIDTH_FRACTION * fmin(model->bodies[a].width, model->bodies[b].width),
                          PD_TRAVEL_DEFLECTIONS * pd_model_pair_delta_max(model, a, b));
    if (moved > allowed) limit = fmin(limit, allowed / moved);
  }
  return limit;
}

// A contact's unordered body pair against the pair (a, b), a < b: −1 before it, 0 the same, 1 after.
static int compare_to_pair(const pdContactId* id, int a, int b) {
  int lo = id->body1 < id->body2 ? id->body1 : id->body2, hi = id->body1 < id->body2 ? id->body2 : id->body1;
  if (lo != a) return lo < a ? -1 : 1;
  return hi < b ? -1 : hi > b;
}

// A certificate that saved no search, or none issued: the pair waits longer before the next try (a pair in motion, or
// one whose features no certificate covers, would pay for one after every step). The wait doubles from 1.
static void back_off(pairCertificate* c) {
  c->backoff = c->backoff < CERT_BACKOFF_MAX ? 2 * c->backoff + 1 : CERT_BACKOFF_MAX;
  c->wait = c->backoff;
}

// Are all of pair p's contacts of C0 still tracked at the step's end?
static bool all_tracked(const pdContactSet* set, int p) {
  for (int k = set->pairPrevious[p]; k < set->pairPrevious[p] + set->pairPreviousCount[p]; ++k)
    if (!set->eval[k].tracked) return false;
  return true;
}

// Does pair p's certificate, issued with c->contacts of its contacts of C0, hold at the poses pa, pb: the same
// contacts listed (the list only loses contacts between searches, at commits: the same count is the same list),
// each still tracked, and the pair within the certificate's motion?
static bool certificate_holds(const pdContactSet* set, int p, const pairCertificate* c, const pdPose* pa,
                              const pdPose* pb) {
  return c->contacts == set->pairPreviousCount[p] && all_tracked(set, p) &&
         pd_search_motion(&c->cert, pa, pb) < c->cert.margin;
}

// Pairs [begin, end) of the contact search: touching[p] and the pair's new cache entry, or certified[p] when its
// certificate holds.
static void interference_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose* poses1 = job->poses1;
  int cached = 0;  // the cache's cursor (sorted like the pairs); from its start in every range
  for (int p = begin; p < end; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    pdPairSatCache entry = {a, b, pd_pair_sat_cache_find(set->cache, set->cacheCount, &cached, a, b)};
    bool listed = cached < set->cacheCount && set->cache[cached].a == a && set->cache[cached].b == b;
    pairCertificate cert = listed ? set->certs[cached] : (pairCertificate){.cert.margin = 0.0};
    set->certified[p] = false;
    if (job->certificates && cert.cert.margin > 0.0) {
      if (certificate_holds(set, p, &cert, &poses1[a], &poses1[b])) {
        // nothing new to find (contact_analysis.h): the pair keeps its cache and certificate, and is not searched
        cert.used = true;
        set->certified[p] = true;
        set->touching[p] = false;
        set->cacheNext[p] = set->cache[cached];
        set->certsNext[p] = cert;
        continue;
      }
      if (cert.used)
        cert.backoff = 0;
      else
        back_off(&cert);
      cert.cert.margin = 0.0;
      cert.used = false;
    }
    set->certsNext[p] = cert;
    pdSatResult sat;
    const pdBody *A = &job->model->bodies[a], *B = &job->model->bodies[b];
    set->touching[p] = pd_interference(&A->shape, poses1[a].x, &poses1[a].R, &B->shape, poses1[b].x, &poses1[b].R,
                                       PD_SAT_VERDICT, &entry.sat, &sat);
    set->cacheNext[p] = entry;
  }
}

// Did pair p's search find nothing its contacts of C0 (`previous`, sorted like found[0 .. n)) do not have, with
// each of them tracked?
static bool quiet(const pdContactSet* set, int p, const pdContactGeom* found, int n, const pdContactId* previous) {
  if (!all_tracked(set, p)) return false;
  int count = set->pairPreviousCount[p], j = 0;
  for (int f = 0; f < n; ++f) {
    while (j < count && pd_contact_id_compare(&previous[j], &found[f].id) < 0) ++j;
    if (j == count || pd_contact_id_compare(&previous[j], &found[f].id) != 0) return false;
  }
  return true;
}

// The contacts of the touching pairs [begin, end) into the part's found[], pair after pair (pairFound,
// pairFoundCount). A part's buffer grows here, on whichever thread runs it (between steps, not in the derivative).
static void find_range(void* ctx, int part, int begin, int end) {
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose *poses0 = job->poses0, *poses1 = job->poses1;
  searchPart* sp = &set->search[part];
  if (part == 1) set->searchSplit = begin;
  sp->foundCount = 0;
  for (int p = begin; p < end; ++p) {
    set->pairFound[p] = sp->foundCount;
    set->pairFoundCount[p] = 0;
    if (set->certified[p]) continue;
    int a = set->pairs[p].a, b = set->pairs[p].b, first = set->pairPrevious[p], count = set->pairPreviousCount[p];
    for (int k = 0; k < count; ++k) sp->previous[k] = set->items[first + k].id;
    int n = 0;
    if (set->touching[p]) {
      while ((n = pd_contacts_find(job->model, a, &poses1[a], b, &poses1[b], &poses0[a], &poses0[b], sp->previous,
                                   count, sp->found + sp->foundCount, sp->foundCapacity - sp->foundCount)) >
             sp->foundCapacity - sp->foundCount) {
        sp->foundCapacity = 2 * (sp->foundCount + n);
        sp->found = pd_grow(sp->found, sp->foundCapacity, sizeof *sp->found);
      }
    }
    // a pair in contact that found nothing new with all its contacts tracked is certified for the next steps (a pair
    // apart has only its interference test to skip, itself about as dear as a certificate)
    pairCertificate* cert = &set->certsNext[p];
    if (job->certificates && count > 0 && quiet(set, p, sp->found + sp->foundCount, n, sp->previous)) {
      if (cert->wait > 0) {
        --cert->wait;
      } else {
        cert->cert = pd_contacts_certify(job->model, a, &poses1[a], b, &poses1[b], sp->previous, count);
        cert->contacts = count;
        cert->used = false;
        if (!(cert->cert.margin > 0.0)) back_off(cert);  // none to be had here (flush parallel edges): not every step
      }
    }
    set->pairFoundCount[p] = n;
    sp->foundCount += n;
  }
}

// Interference of the pairs at poses1 (the verdict only, PD_SAT_VERDICT: GJK's certificates, and touching where
// they prove neither, within 1e-7 of the size; cache of the last separating feature or direction per pair, merged
// by the sorted pair order), then the contact search of the touching ones, whose own depth tests find no contact
// where nothing penetrates. Fills candidates. Times the interference
// (a lap of `watch`), not the search after it.
static void search(const pdModel* model, pdState* s, const double* y1, int pairCount, const pdPose* poses0,
                   const pdPose* poses1, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  // each pair's contacts in C0 (the list is sorted by the unordered body pair first)
  int listed = 0;
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) < 0) ++listed;
    set->pairPrevious[p] = listed;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) == 0) ++listed;
    set->pairPreviousCount[p] = listed - set->pairPrevious[p];
  }
  // every pair's interference first, timed as a whole (two clock reads per pair were 2 % of a pile's run)
  contactLoop job = {.model = model, .set = set, .poses1 = poses1, .certificates = s->searchCertificates};
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, interference_range, &job);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageInterference]);
  set->candidateCount = 0;
  contactLoop find = {
      .model = model, .set = set, .poses0 = poses0, .poses1 = poses1, .certificates = s->searchCertificates};
  set->searchSplit = pairCount;
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, find_range, &find);
  for (int p = 0; p < pairCount; ++p) {
    s->count.searchesSkipped += set->certified[p];
    if (!set->touching[p]) continue;
    int first = set->pairPrevious[p], previousCount = set->pairPreviousCount[p], n = set->pairFoundCount[p];
    const pdContactGeom* found = set->search[p >= set->searchSplit].found + set->pairFound[p];
    // found[] and C0's contacts of this pair are both sorted by id: merge
    int j = first;
    for (int f = 0; f < n; ++f) {
      const pdContactGeom* g = &found[f];
      while (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) < 0) ++j;
      if (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) == 0) continue;
      candidate c = {*g, 1.0, false, 0.0, -1, 0.0};
      int b1 = g->id.body1, b2 = g->id.body2;
      pdVec3 du = relative_velocity(model, y1, poses1, &g->id, g->point);
      c.approaching = pd_v3_dot(du, g->normal) < 0.0;
      // face continuity: the vertex of a VF contact of C0 that no longer tracks its face, now on another
      for (int k = first; k < first + previousCount && g->id.kind == pd_contactVF; ++k) {
        const pdContactId* old = &set->items[k].id;
        if (old->kind == pd_contactVF && old->body1 == g->id.body1 && old->feat1 == g->id.feat1 &&
            !set->eval[k].tracked && !set->eval[k].transferred) {
          c.inherit = k;
          set->eval[k].transferred = true;
          break;
        }
      }
      if (c.inherit < 0) c.onset = pd_contact_onset(model, &g->id, &poses0[b1], &poses1[b1], &poses0[b2], &poses1[b2]);
      add_candidate(set, &c);
    }
  }
  // C0 contacts whose pair no longer overlaps were not visited: nothing to do, they break on commit
  // if they no longer track or pull; swap in the new cache
  pdPairSatCache* t = set->cache;
  set->cache = set->cacheNext;
  set->cacheNext = t;
  pairCertificate* c = set->certs;
  set->certs = set->certsNext;
  set->certsNext = c;
  set->cacheCount = pairCount;
}

// Did a contact change mode inside the step (§3.4): stick ↔ slip? That is where the contact force has a
// kink, which the error control would otherwise cross with a step of the wrong order. Reversals of Δu_n or
// of Δu_t within one mode are smooth in this model (linear springs and dampers) and are left to the
// error control (refining them cost pile_10 a third of its derivative evaluations).
static bool changes_mode(const contactSlot* c, const pdContactForce* f) { return c->force.slip != f->slip; }

// Can a new contact that began `age` seconds before the step's end join there (pd_onsetsPair)?
static bool joins_as_pair(const pdModel* model, const pdContactGeom* g, double age) {
  int a = g->id.body1, b = g->id.body2;
  if (!(g->depth > 0.0) || g->depth > PD_ONSET_PAIR_DEPTH_REL * pd_model_pair_delta_max(model, a, b)) return false;
  pdContactParams p = pd_model_contact_params(model, a, b);
  double k = pd_series(p.k1n, p.k2n);
  return k > 0.0 && age * sqrt(k / p.massMin) <= PD_ONSET_PAIR_OMEGA_TAU;
}

// The error bound (onset_bound.h) of joining new contact g at y1 (poses in set->poses1) as a pair onset `age` seconds
// after its onset.
static double onset_bound(const pdModel* model, const pdState* s, const double* y1, const pdContactGeom* g,
                          double age) {
  int a = g->id.body1, b = g->id.body2;
  pdContactParams p = pd_model_contact_params(model, a, b);
  double approach = -pd_v3_dot(relative_velocity(model, y1, s->contacts->poses1, &g->id, g->point), g->normal);
  double size = INFINITY;
  if (!model->bodies[a].fixed) size = model->bodies[a].size;
  if (!model->bodies[b].fixed) size = fmin(size, model->bodies[b].size);
  return pd_onset_error_bound(sqrt(pd_series(p.k1n, p.k2n) / p.massMin), age, g->depth, approach,
                              model->settings.vmax, size);
}

// The error bound (onset_bound.h) of leaving contact c's stick–slip change (evaluated at the step's end in e) inside
// a step of h.
static double transition_bound(const pdModel* model, const contactSlot* c, const contactEval* e, double h) {
  const pdContactParams* p = &c->params;
  double approach = pd_v3_dot(e->du, e->geom.normal);
  double slide = pd_v3_norm(pd_v3_sub(e->du, pd_v3_scale(e->geom.normal, approach)));
  return pd_transition_error_bound(pd_series(p->k1t, p->k2t) / p->massMin, pd_series(p->k1n, p->k2n) / p->massMin,
                                   p->mu, slide, fabs(approach), h, model->settings.vmax);
}

// Contacts [begin, end) of C0 tracked to y1 and their forces there (set->eval).
static void tracking_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    contactEval* e = &set->eval[i];
    pdSprings sp = springs_load(job->y + base + PD_CONTACT_STATE_SIZE * i);
    evaluate(job->model, &set->items[i], job->y, set->poses1, &frame, &sp, &e->geom, &e->tracked, &e->du, &e->force);
    e->transferred = false;
    e->modeBound = 0.0;
  }
}

pdEventVerdict pd_contact_events(const pdModel* model, pdState* s, double h, const double* y1, double* hRetry,
                                 pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  int base = spring_base(model);
  poses_from(model, s->y, set->poses0);
  poses_from(model, y1, set->poses1);
  // the stages one after the other: broad phase (the poses above included), contact analysis (the travel
  // limit included), interference, contact analysis
  double* analysisSeconds = &s->stageSeconds[pd_stageContactAnalysis];

  // 0. no tunnelling: bodies that may meet must not pass through each other's thinnest width in one step
  int pairCount = broad_phase(model, s, set->poses0, set->poses1);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageBroadPhase]);
  double limit = travel_limit(model, set, pairCount);
  if (limit < 1.0 && limit * h > model->settings.dtmin) {
    ++s->count.travelRetries;
    *hRetry = fmax(model->settings.dtmin, PD_TRAVEL_RETRY_SAFETY * limit * h);
    pd_stopwatch_lap(watch, analysisSeconds);
    return pd_eventRetry;
  }

  // 1. C0 at y1: tracking, forces, reversals
  contactLoop job = {.model = model, .set = set, .y = y1};
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS, tracking_range, &job);
  double refineStep = 0.0;  // the largest refinement bound among the contacts that changed mode (0: none)
  bool bounded = pd_onsets_effective(s->onsets, model->movingCount) == pd_onsetsBounded;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    contactEval* e = &set->eval[i];
    if (!changes_mode(c, &e->force)) continue;
    // bounded events leave a change inside the step where its bound allows (onset_bound.h); others refine it
    if (bounded) {
      double bound = transition_bound(model, c, e, h);
      if (pd_onset_bound_allows(bound, model->settings.tol)) {
        e->modeBound = bound;
        continue;
      }
    }
    refineStep = fmax(refineStep, refine_step(model, &c->params));
  }
  pd_stopwatch_lap(watch, analysisSeconds);
  // only the adaptive stepper refines: the fixed one keeps its step (work-precision sweeps compare steps)
  if (refineStep > 0.0 && s->stepper != pd_stepperRK4Fixed && 0.5 * h >= refineStep) {
    ++s->count.refinements;
    *hRetry = 0.5 * h;
    return pd_eventRetry;
  }

  // 2. the contacts at y1 that C0 does not have
  search(model, s, y1, pairCount, set->poses0, set->poses1, watch);

  // 3. onsets: the earliest new contact that began inside the step and went deeper than its tolerance (a
  // pair onset close enough to the step's end joins there instead)
  double earliest = 2.0;
  pdOnsets onsets = pd_onsets_effective(s->onsets, model->movingCount);
  for (int k = 0; k < set->candidateCount; ++k) {
    candidate* c = &set->candidates[k];
    if (!c->approaching || c->inherit >= 0) continue;
    double age = (1.0 - c->onset) * h;
    if (onsets != pd_onsetsExact && joins_as_pair(model, &c->geom, age)) {
      c->onsetBound = onset_bound(model, s, y1, &c->geom, age);
      if (onsets == pd_onsetsPair || pd_onset_bound_allows(c->onsetBound, model->settings.tol)) {
        c->onsetAge = age;
        continue;
      }
    }
    double tol = PD_ONSET_DEPTH_TOL_REL * pd_model_pair_delta_max(model, c->geom.id.body1, c->geom.id.body2);
    if (c->geom.depth > tol) earliest = fmin(earliest, c->onset);
  }
  pdEventVerdict verdict = pd_eventAccept;
  if (earliest <= 1.0 && set->onsetRetries < PD_ONSET_RETRIES_MAX) {
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
        if (!c->approaching || c->inherit >= 0 || c->onset * h > model->settings.dtmin) continue;
        pdContactGeom g0;
        const pdContactId* id = &c->geom.id;
        pd_contact_track(model, id, &set->poses0[id->body1], &set->poses0[id->body2], &g0);
        pdVec3 du = relative_velocity(model, s->y, set->poses0, id, g0.point);
        if (pd_v3_dot(du, g0.normal) > 0.0) continue;  // separating: with springs at 0 it would pull
        if (count == set->capacity) reserve_list(set, count + 1);
        set->next[count++] = new_slot(model, &g0);
        ++added;
      }
      if (added > 0) {
        s->count.contactsVirtual += added;
        install(model, s, count);
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

void pd_contact_events_commit(const pdModel* model, pdState* s, const double* y1, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  int base = spring_base(model);
  reserve_list(set, set->count + set->candidateCount);
  int count = 0;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    const contactEval* e = &set->eval[i];
    if (!e->tracked) {
      if (!e->transferred) ++s->count.breaksGeometry;
      continue;
    }
    if (pd_contact_force_pulls(&e->force)) {
      ++s->count.breaksForce;
      if (set->history) {
        pdSprings left = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
        pd_history_leave(set->history, &c->id, &left, e->geom.normal, c->deltaMax);
      }
      continue;
    }
    if (e->modeBound > 0.0) {
      ++s->count.transitionsUnlocated;
      s->count.transitionBoundMax = fmax(s->count.transitionBoundMax, e->modeBound);
      s->count.transitionBoundSum += e->modeBound;
    }
    contactSlot* k = &set->next[count++];
    *k = *c;
    k->springs = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * i);
    pd_springs_realign(&k->springs, c->normal, e->geom.normal, c->params.mu, &c->params, e->force.fn);
    k->normal = e->geom.normal;  // where the contact is now: its pair's modal dampers are set from it
    k->point = e->geom.point;
    k->depth = e->geom.depth;
    k->geometryCurrent = true;  // tracked at y1's poses, which the commit keeps (record_range)
  }
  for (int j = 0; j < set->candidateCount; ++j) {
    const candidate* cand = &set->candidates[j];
    if (cand->inherit >= 0) {
      const contactSlot* old = &set->items[cand->inherit];
      contactSlot* k = &set->next[count++];
      *k = new_slot(model, &cand->geom);
      k->springs = springs_load(y1 + base + PD_CONTACT_STATE_SIZE * cand->inherit);
      pd_springs_realign(&k->springs, old->normal, cand->geom.normal, k->params.mu, &k->params,
                         set->eval[cand->inherit].force.fn);
      ++s->count.contactsTransferred;
    } else if (cand->approaching) {
      contactSlot* k = &set->next[count++];
      *k = new_slot(model, &cand->geom);
      k->onsetAge = cand->onsetAge;
      if (set->history && pd_history_take(set->history, &cand->geom.id, cand->geom.normal, &k->params, &k->springs))
        ++s->count.historyKept;
      if (cand->onsetAge > 0.0) {
        s->count.onsetBoundMax = fmax(s->count.onsetBoundMax, cand->onsetBound);
        s->count.onsetBoundSum += cand->onsetBound;
      }
      ++s->count.contactsMade;
    }
  }
  set->candidateCount = 0;
  set->onsetRetries = 0;
  // y1 lives in the stepper's scratch, which install may drop: the bodies' numbers go to state->y first
  memcpy(s->y, y1, (size_t)base * sizeof *s->y);
  install(model, s, count);
  poses_from(model, s->y, set->poses1);
  s->count.onsetsInterpolated += prepare_list(model, set, s->y, set->poses1);
  if (set->history) pd_history_age(model, set->history, set->poses1);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageContactAnalysis]);
}

// ---------------------------------------------------------------- dense output (dense_output.c)

void pd_contact_set_capture(const pdContactSet* from, pdContactSet* view) {
  reserve_list(view, from->count > 0 ? from->count : 1);  // never NULL: memcpy of nothing still wants a pointer
  memcpy(view->items, from->items, (size_t)from->count * sizeof *view->items);
  for (int i = 0; i < from->count; ++i) {
    const contactSlot* c = &from->items[i];
    view->captured[i] = (capturedGeometry){c->normal, c->point, c->depth};
  }
  view->capturedCount = from->count;
  view->count = 0;  // nothing presented yet
}

void pd_contact_set_present(const pdModel* model, pdContactSet* view, double* y) {
  int count = view->capturedCount;
  view->count = count;
  view->bodyListValid = false;
  poses_from(model, y, view->poses1);
  world_inverse_inertias(model, view, view->poses1);  // read by the implicit stepper's linearisation
  int base = spring_base(model);
  // realigned as a commit realigns the contacts it keeps (one that pulls keeps its springs: a commit drops it),
  // then recorded as record() records: the same geometry and relative velocity, the force of the springs as
  // they are now
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = 0; i < count; ++i) {
    contactSlot* c = &view->items[i];
    // as captured: a presentation at another time of the same step overwrote them (the rest it does not change)
    c->normal = view->captured[i].normal;
    c->point = view->captured[i].point;
    c->depth = view->captured[i].depth;
    double* yc = y + base + PD_CONTACT_STATE_SIZE * i;
    pdSprings sp = springs_load(yc);
    pdContactGeom g;
    pdVec3 du;
    contact_motion(model, c, y, view->poses1, &frame, &g, NULL, &du);
    // the normal force decides (pd_contact_fn_pulls) whether the springs are realigned before the whole force
    double fn = pd_contact_normal_force(&c->params, &sp, g.normal, du);
    if (!pd_contact_fn_pulls(fn)) {
      pd_springs_realign(&sp, c->normal, g.normal, c->params.mu, &c->params, fn);
      springs_store(yc, &sp);
    }
    pd_contact_force(&c->params, &sp, g.normal, du, &c->force);
    record_geometry(c, &g);
  }
}

// ---------------------------------------------------------------- read-out

int pd_state_contact_count(const pdState* s) { return s->contacts ? s->contacts->count : 0; }

pdContactReport pd_state_contact(const pdState* s, int i) {
  PD_ASSERT(s->contacts != NULL && i >= 0 && i < s->contacts->count);
  const contactSlot* c = &s->contacts->items[i];
  pdContactReport r;
  r.bodyA = c->id.body1;
  r.bodyB = c->id.body2;
  r.edgeEdge = c->id.kind == pd_contactEE;
  r.featureA = c->id.feat1;
  r.featureB = c->id.feat2;
  r.point = c->point;
  r.normal = c->normal;
  r.depth = c->depth;
  bool pulls = pd_contact_force_pulls(&c->force);
  r.fn = pulls ? 0.0 : c->force.fn;
  r.ft = pulls ? (pdVec3){0, 0, 0} : c->force.ft;
  r.slip = c->force.slip;
  return r;
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

// Contact i of `from` (a state of `fromModel`) as a slot of another model's list: its bodies renumbered by
// `map` (fromModel body → the other's), its springs read from from->y.
static contactSlot remapped_slot(const pdModel* fromModel, const pdState* from, int i, const int* map) {
  contactSlot c = from->contacts->items[i];
  c.id.body1 = remap_body(map, c.id.body1);
  c.id.body2 = remap_body(map, c.id.body2);
  c.springs = springs_load(from->y + spring_base(fromModel) + PD_CONTACT_STATE_SIZE * i);
  return c;
}

// Installs next[0 .. count) as the list of `to` (a state of `model`), with no candidates or retries pending.
static void install_moved(const pdModel* model, pdState* to, int count) {
  to->contacts->candidateCount = 0;
  to->contacts->onsetRetries = 0;
  install(model, to, count);  // sorted by id: the order the slots came in does not matter
}

void pd_contact_set_scatter(const pdModel* model, const pdState* from, const int* contacts, int count,
                            const pdModel* sub, pdState* to, const int* toSub) {
  pdContactSet* set = to->contacts;
  if (set->history) pd_history_clear(set->history);  // its traces' ids are another model's
  reserve_list(set, count);
  for (int k = 0; k < count; ++k) {
    PD_ASSERT(contacts[k] >= 0 && contacts[k] < from->contacts->count);
    set->next[k] = remapped_slot(model, from, contacts[k], toSub);
  }
  install_moved(sub, to, count);
  // what prepare_list derives from the bodies' poses; the slots (modal dampers, forces) come as they were
  poses_from(sub, to->y, set->poses1);
  world_inverse_inertias(sub, set, set->poses1);
  stability_prepare(sub, set, set->poses1);
}

void pd_contact_set_gather(const pdModel* model, pdState* to, int parts, const pdModel* const* subs,
                           const pdState* const* from, const int* const* toModel) {
  pdContactSet* set = to->contacts;
  if (set->history) pd_history_clear(set->history);
  int total = 0;
  for (int p = 0; p < parts; ++p) total += from[p]->contacts->count;
  reserve_list(set, total);
  int count = 0;
  for (int p = 0; p < parts; ++p)
    for (int i = 0; i < from[p]->contacts->count; ++i)
      set->next[count++] = remapped_slot(subs[p], from[p], i, toModel[p]);
  install_moved(model, to, count);
}
