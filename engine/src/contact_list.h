// polydyn (internal) — the contact list's structures and the helpers the contact files share: contact_set.c (the list,
// its events and commit), contact_forces.c (forces in the derivative, linearisation), pair_params.c (the springs sized
// by the load, modal dampers), stability_bound.c (the stable step), stack_modes.c (the modes of stacks), onsets.c (late
// onsets), contact_search.c (broad phase, travel, certificates, search) and state_contacts.c (the state's contact
// read-out). Nothing outside these files includes it: everyone else sees pdContactSet through contact_set.h alone.
#pragma once

#include <stdbool.h>

#include "contact_history.h"
#include "broad_phase.h"
#include "clock.h"
#include "contact_analysis.h"
#include "contact_force.h"
#include "contact_set.h"
#include "help_desk.h"
#include "interference.h"
#include "polydyn/state.h"
#include "state_layout.h"

typedef struct contactSlot {
  pdContactId id;
  pdContactParams params;  // modal dampers set per contact when its pair's contacts change (pd_modal_dampers)
  double deltaMax;   // m: the springs' error weight, the smaller δ_max of the two bodies
  // at the last accepted state (for realignment, refinement and output)
  pdVec3 normal, point;
  double depth;
  bool geometryCurrent;  // normal, point and depth are the geometry at the poses record() runs at (set by a
                         // commit for a tracked contact: tracking formed it at those poses; record() clears it)
  pdContactForce force;
  pdSprings springs;  // used only while the list is rebuilt
  double onsetAge;    // s: a pair onset's time since the interpolated onset, until pd_onsets_start_late (else 0)
  pdVec3 onsetImpulse;  // N·s, on body 1: pd_onsets_start_late' scratch
  double modalMass;     // kg: the mass per contact of its pair's joint motion along n (pd_modal_dampers; 0: none)
  int modalCount;       // contacts its pair had when pd_modal_dampers last set its dampers (0: not yet)
  int modalBodyContacts[2];  // contacts of body1, body2 (moving) then: a neighbour's change re-sizes its dampers
  double stackScale[2];      // ζ of its modal dampers at the pair's own mass over the requested (n, P_t; >= 1)
  double loadScale;          // its springs over eq. (11)'s for the pair alone (>= 1; pd_modal_dampers, "load")
  // its modes at the step's start (record()), held over the step when the set holds modes (pd_contact_force_held)
  bool heldPush, heldSlip;
  // presented at a sample and not evaluated there yet (pd_contact_set_settle): its springs in y as interpolated, its
  // normal, point and depth as captured at the step's start, its force and held modes not those of the sample
  bool unevaluated;
  // an implicit trial's stage found it out of the slip it started the step in: stuck, or slipping against it
  // (slipReversals; cleared at each trial's start)
  bool crossed;
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
  pdVec3 du;         // relative velocity at the contact point, m/s
  double modeBound;  // a stick–slip change left inside the step: its error bound (onset_bound.h), else 0
  bool slipChanged;  // stick ↔ slip inside the step, under bounded events (kink then holds its slopes)
  double kink[3];    // a stick–slip change inside the step: its kink's slopes (onset_bound.h) on body1, body2, springs
  // a held mode that the force law left inside the step (holdModes), corrected at the commit: the impulse on body 1
  // (N·s) and the change of its springs (m) that take out what the held law applied since the change
  bool modeCorrected;
  pdVec3 modeImpulse;
  pdSprings modeSprings;
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
  bool released;      // a vertex's contact on the face a release by force left it in (contact_search.c): no onset
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
  double* reachScratch;    // contact_search.c's reaching_fraction: two bodies' vertex moves and bounding planes
  int reachVertexMax, reachFaceMax;  // the most vertices and faces of a body (faces: at least 6)
  double travelStep;       // s: the step the tunnelling guard lets the next one take (INFINITY: any)
  int onsetRetries;        // onset retries of the step under way
  int modeRetries;         // trials of the step under way cut to a held mode's change (holdModes)
  bool holdModes;          // the derivative holds each contact's modes of the step's start (pd_contact_set_hold_modes)
  bool correctHeld;        // every held change corrected, none located (pd_contact_set_correct_held)
  bool slipReversals;      // a stage leaving the start's slip is a change to refine (pd_contact_set_slip_reversals)
  const double* startSlope;  // f(y) at the step's start while slipReversals is on: the stop's prediction reads it
  // stability bound (pd_stability_prepare, stability_tight), sized with the list
  stabilityTerms* stability;  // (capacity)
  int* bodyFirst;          // (bodyCount + 1) contacts of body k: bodyList[bodyFirst[k] … bodyFirst[k + 1])
  int* bodyList;           // (2 capacity)
  bool bodyListValid;      // bodyFirst/bodyList list the current contacts (pd_stability_prepare; install clears it)
  double stableStep;       // s: the largest stable step for the current list, once stableKnown (INFINITY: no contacts)
  double stableCheap;      // s: the step of the cheap bound alone, never above stableStep (pd_stability_prepare)
  double cheapOmega2;      // the cheap bound's ω_max², its rounding margin included
  bool stableKnown;        // stableStep computed for the current list (it is computed only when needed)
  long tightFormed;        // tight bounds formed for a step's limit (pd_contact_set_tight_formed)
  bodySpaceBlock* bodyBlocks;  // (bodyCount) stability_tight's
  const pdPose* stablePoses;   // the poses of the list's pd_stability_prepare (unchanged until the step's limit)
  double overdamp;         // the largest over-damping factor of the list's contacts (stabilityTerms)
  double stackTau;         // s: the largest c/k along n of contacts whose dampers a stack sized (0: none; step_of)
  double dampingMin;       // the smallest damping ratio of the list's modes (ζ_n; ζ_t where a contact sticks), ≤ 1
  pdVec3* bodyRowsK;       // (bodyCount) per row p: Σ_q |(K_j^½)_pq| summed over the contacts j of each body
  pdVec3* bodyRowsRight;   // (bodyCount) the same for W [r_j]ₓ K_j^½ (j's end on that body)
  pdMat3* invInertiaWorld; // (bodyCount) R I⁻¹ Rᵀ at the poses of the list's last preparation (fixed: 0)
  // slots presented and not evaluated yet (contactSlot.unevaluated), of this model, and the poses their evaluation
  // forms (bodyCount; fixed bodies' set once)
  int unevaluated;
  const pdModel* unevaluatedModel;
  pdPose* settlePoses;
  // a presented view's invInertiaWorld is due at its poses (formed with its contacts, when first read: the
  // linearisation settles the state before it reads them)
  bool inertiasPending;
  double* kinkSum;         // (bodyCount) scratch of pd_contact_events: the step's stick–slip kinks' slopes per body
  struct pdStackScratch* stackScratch;  // the modal dampers' local mode analyses (stack_modes.h); NULL until first needed
  contactPush* push;       // (capacity) per contact, of the last derivative evaluation
  // the state record() formed every contact's force at (its slots' force, point and rates), while recordedValid:
  // a derivative at the very same numbers takes them from there (pd_contact_forces)
  double* recordedY;
  const double* recordedFrom;  // where that state was (only a derivative at those numbers there is compared)
  int recordedCapacity;
  bool recordedValid;          // cleared by a list installed or cleared
  // the state pd_contact_events last tracked C0 to (set->eval: each contact's geometry, Δu and force there, the law
  // free), while trackedValid: a derivative at the very same numbers there (the implicit trial's end, for its dense
  // output) takes its vertex–face contacts' from there (pd_contact_forces)
  double* trackedY;
  const double* trackedFrom;
  int trackedCapacity;
  bool trackedValid;           // cleared with recordedValid (a list installed, cleared or gathered)
  int capturedCount;           // a dense output's view (dense_output.h): the captured list's length, its slots in items
  // A view's capture, unique in the process (0: none, or not a view); and, in a scene's list gathered from one island's
  // view, the capture it was last gathered from slot by slot (0: none since its list was last installed otherwise):
  // pd_contact_set_gather then renews only what a presentation and an evaluation change.
  unsigned long captureSerial, gatheredSerial;
  // pd_contact_set_settle's calls that evaluated slots; in a scene's list, the view's count when last gathered from it
  unsigned long evaluations, gatheredEvaluations;
  capturedGeometry* captured;  // (capacity) a view's: each captured slot's normal, point and depth, which a
                               // presentation overwrites in items and the next one restores
  pdHelpDesk* help;        // where the per-contact and per-pair loops post half their work, or NULL (help_desk.h)
};

static inline pdPose pose_of(pdVec3 x, pdQuat q) { return (pdPose){x, pd_quat_to_mat3(pd_quat_normalize(q))}; }

static inline int spring_base(const pdModel* model) { return PD_BODY_STATE_SIZE * model->movingCount; }

static inline pdSprings springs_load(const double* y) {
  return (pdSprings){y[0], y[1], {y[2], y[3], y[4]}, {y[5], y[6], y[7]}};
}

static inline void springs_add(pdSprings* s, const pdSprings* d) {
  s->s1n += d->s1n, s->s2n += d->s2n;
  s->s1t = pd_v3_add(s->s1t, d->s1t), s->s2t = pd_v3_add(s->s2t, d->s2t);
}

static inline void springs_store(double* y, const pdSprings* s) {
  y[0] = s->s1n, y[1] = s->s2n;
  y[2] = s->s1t.x, y[3] = s->s1t.y, y[4] = s->s1t.z;
  y[5] = s->s2t.x, y[6] = s->s2t.y, y[7] = s->s2t.z;
}

// Body b's point velocity at lever arm r from its centre, at state y (0 for a fixed body).
static inline pdVec3 velocity_at(const pdModel* model, const double* y, int b, pdVec3 r) {
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
static inline void poses_of_range(const pdModel* model, const double* y, pdPose* poses, int begin, int end) {
  for (int k = begin; k < end; ++k) {
    const double* yb = y + PD_BODY_STATE_SIZE * k;
    poses[model->movingBodies[k]] = pose_of(pd_layout_x(yb), pd_layout_q(yb));
  }
}

static inline void poses_from(const pdModel* model, const double* y, pdPose* poses) {
  poses_of_range(model, y, poses, 0, model->movingCount);
}

// Geometry and relative velocity of one contact at state y (poses of y given).
// frame: the loop's pair frame (pdPairFrame), shared by a pair's contacts (consecutive in the sorted list).
static inline void contact_motion(const pdModel* model, const contactSlot* c, const double* y, const pdPose* poses,
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
static inline void evaluate(const pdModel* model, const contactSlot* c, const double* y, const pdPose* poses,
                            pdPairFrame* frame, const pdSprings* springs, pdContactGeom* geom, bool* tracked,
                            pdVec3* du, pdContactForce* f) {
  contact_motion(model, c, y, poses, frame, geom, tracked, du);
  pd_contact_force(&c->params, springs, geom->normal, *du, f);
}

// A contact's unordered body pair against the pair (a, b), a < b: −1 before it, 0 the same, 1 after.
static inline int compare_to_pair(const pdContactId* id, int a, int b) {
  int lo = id->body1 < id->body2 ? id->body1 : id->body2, hi = id->body1 < id->body2 ? id->body2 : id->body1;
  if (lo != a) return lo < a ? -1 : 1;
  return hi < b ? -1 : hi > b;
}

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


// Contact i's springs in the state the loop evaluates (job->y).
static inline pdSprings loop_springs(const contactLoop* job, int i) {
  return springs_load(job->y + spring_base(job->model) + PD_CONTACT_STATE_SIZE * i);
}

// ---------------------------------------------------------------- between the files

// onsets.c: gives body 1 of contact c the impulse j (N·s) at `point` and body 2 −j (fixed bodies take none; a
// planar body its in-plane part), in y, with lever arms from `poses` and the list's world inverse inertias.
void pd_contact_impulse(const pdModel* model, const pdContactSet* set, double* y, const pdPose* poses,
                        const pdContactId* id, pdVec3 point, pdVec3 j);

// contact_set.c: grows the list's per-contact arrays to hold `capacity` contacts (between steps).
void pd_contact_set_reserve_list(pdContactSet* set, int capacity);

// contact_forces.c: each moving body's contacts in contact order, as 2 i + (0 on body1, 1 on body2): bodyFirst and
// bodyList, read by the force sums and the tight stability bound.
void pd_contact_set_list_bodies(const pdModel* model, pdContactSet* set);

// pair_params.c: the springs sized by the load and the modal dampers of every pair whose contacts changed (poses:
// the list's, world inverse inertias set; y: the state whose springs are re-scaled with their stiffness), and the
// stability bound's terms and cheap bound for a new list.
void pd_modal_dampers(const pdModel* model, pdContactSet* set, const pdPose* poses, double* y);
// pair_params.c: the constants a new contact `id` found in a step would have at the step's commit as far as the step
// knows them: the model's (eq. (11)'s), with the springs at the factor of its pair's listed contacts (which never falls
// while they last) or of the trace it would take back (pd_history_load_scale), and modal dampers raised with them
// (√ of it). Read by the onsets' join test and error bound (onsets.c).
pdContactParams pd_onset_params(const pdModel* model, const pdContactSet* set, const pdContactId* id);
void pd_stability_prepare(const pdModel* model, pdContactSet* set, const pdPose* poses);

// contact_search.c: the contact search's arrays (broad phase, pairs, caches, certificates, candidates) of a set
// with contact events, and their release.
void pd_contact_search_create(const pdModel* model, pdContactSet* set, const bool* fixed);
void pd_contact_search_free(pdContactSet* set);
// Broad phase over the step of h from y0 (poses0) to y1 (poses1): every moving body's box covers both ends and how far
// its turn may carry its points off their chords in between; the pairs in set->pairs; returns their number.
int pd_contact_search_broad_phase(const pdModel* model, pdContactSet* set, const double* y0, const double* y1,
                                  double h, const pdPose* poses0, const pdPose* poses1);
// Tunnelling guard over the step of h just analysed: whether a listed pair moved too far relative to each other, and
// then the shorter step to retry (*hRetry). The bodies' travel is the broad phase's, called just before on that step.
bool pd_contact_search_travel_retry(const pdModel* model, pdContactSet* set, int pairCount, double h,
                                    double* hRetry);
// The contact search at y1 over the pairs of the broad phase: the candidates (contacts of C1 not in C0), each with
// its onset fraction. Times the interference as a lap of `watch`.
void pd_contact_search(const pdModel* model, pdState* s, const double* y1, int pairCount, const pdPose* poses0,
                       const pdPose* poses1, pdStopwatch* watch);
