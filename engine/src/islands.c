// polydyn — islands (pd_islandsOn; docs/DESIGN.md §5.4; docs/integration.md); their partition: island_partition.c.
//
// Design note. With islands off, one state vector carries every moving body and contact: one step size,
// one error norm (a max over all of y), and every contact onset anywhere cuts every body's step. With
// islands on, pd_advance goes from sync time to sync time: the output samples, each sample interval cut into
// equal parts (sync_parts: a body at the scene's vmax moves at most PD_ISLAND_SYNC_SIZE_FRACTION of the
// smallest moving body's size over one; a function of the model and the interval only) where that splits an
// island (cuts_split_islands: the partition over the first part has more islands than over the whole sample
// interval); otherwise the samples are the sync times, and one island of every body is islands off, bit for bit.
// Over each sync interval [T, T'] the moving bodies are partitioned into islands and each island advances
// alone from T to T', in a pdState of its own over a model of its own, with its own step size, error norm,
// contact events, onset retries and stability bound: the unchanged steppers of integrator.c (pd_step_until).
//
// - An island's model holds its moving bodies and every fixed body, in scene order (bodies copied, their
//   polyhedra and names shared, the material table a view with the classes remapped:
//   pd_material_table_view). Fixed bodies carry no state, so every island may touch them without joining
//   islands together. The order is scene order, so a contact's id sorts the same in the island and in
//   the scene, and an island of the same bodies in another scene (same fixed bodies first, same sync times)
//   computes the same numbers bit for bit.
// - Partition at T (union-find over the moving bodies; each island named by its lowest body): two bodies
//   join when they share an active contact, or when their grown boxes overlap and the separating-axis test
//   at T finds no axis along which their gap exceeds all they can close (may_meet). Gravity moves every body
//   alike, so the boxes live in the frame that falls with it: body k's box at T, swept along v_k Δ and grown
//   by its bound (travel_bound: slack + |ω| r Δ + ½ |F/m| Δ² for an applied force, and for a body touching
//   anything at T or whose box may reach a fixed body's, 2 |v| Δ + |g| Δ² for a reversal of its velocity
//   and support against gravity). Two bodies falling side by side thus stay apart. Islands are listed by
//   their lowest body, so nothing depends on the order in which they are processed: each island reads only
//   the scene's state at T and its own state, and writes only its own bodies' entries.
// - Free bodies: at the start T0 of each sample interval the partition is formed once over the whole interval
//   (find_free). A body alone there, touching nothing and with no fixed body in reach, is free: with no
//   contact it cannot leave its ballistic path (its spin bounded by its rotational energy, √(2 E_rot/I_min)),
//   so its island is not cut at the sync times: it goes to the sample in free-flight steps of its own, its box
//   over the sample interval standing for it in every sync partition. When another body's box over a sync
//   interval reaches that box, the free body is brought to that sync time alone and joins the others from
//   there; a free body found outside its box (never expected) is counted (islandStrays), not recovered.
// - A lone moving body is one island over any interval: its sample interval is not cut, and find_free's partition
//   (the same one island, the same box: a free body's box over a sync interval is its box over the sample
//   interval) stands for the interval's. The one island of every moving body (a lone body, a stack joined by its
//   contacts) is written out, not sorted. A scene of one moving body, awake, goes further: its island's steps run
//   across the samples in one pd_step_until, each sample presented from its dense output as with islands off, and
//   at each sample the interval loop's work for it is done there, bit for bit (lone_run, below): per sample the
//   gather, the sleep test, the counters and, for a body touching nothing, its travel from its path. Asleep, it
//   goes from sample to sample counting its time asleep until its force changes (lone_sleep_on).
// - Persistence: an island whose bodies are the same as the last interval's keeps its state (its contact
//   list, caches, step size) and simply goes on; a new island is set up from the scene's state at T (its
//   bodies' numbers and contacts copied, the contacts' springs, forces and modal dampers as they were:
//   pd_contact_set_scatter) with the smallest step its bodies' islands last wanted.
// - Safety: after every step an island takes, each of its bodies' distance from its ballistic path
//   (|x − x0 − v0 τ − ½ g τ²| + radius × rotation angle since T) is compared with its bound. Every point of
//   the body then lies, in the falling frame, in its box at T moved by v0 τ and grown by that distance. A
//   body that strayed farther could have met a body of another island unseen. After all islands reached T',
//   the bound of every such body becomes twice its distance, the partition is formed again, and every island
//   whose bodies changed is set up again from the state at T (still intact: the scene's state is written
//   only at T') and redone (counted: islandRedos); islands whose bodies did not change keep their result.
//   This repeats until no body strayed from its box, so at the end no two islands' swept boxes overlap
//   while every body stayed in its own: no contact between islands can have been missed. (Between two step
//   ends a body's path may leave the box by its curvature, |a − g| h²/8 at most, inside the slack.)
// - At T' the islands' bodies and contacts are gathered into the scene's state (pd_contact_set_gather:
//   sorted by id), the counters summed in island order, and the observer sees the whole scene at samples.
// With the samples as the only sync times, one island of every body computes what islands off computes.
// - Threads (pdState.threads): the islands an interval advances (and the free bodies brought to the sample)
//   are listed, then run on the set's pool of threads, each island whole on one thread. The islands are
//   ordered by size (bodies + contacts, largest first, ties in job order) and each thread takes the next one
//   from a shared counter when it is free: which thread runs an island depends on timing, what the island
//   computes does not. A split fixed in advance from the sizes left the busier thread 8-11 % of the island work
//   on the pile of 1 000 (cases/bench/pile_1000.scene) after the other had finished, because size
//   predicts an island's cost poorly (a falling island is cheap, a colliding one dear); taken in turn, the
//   last island is all that is left over. While they run, a thread writes only its islands' states, their
//   jobOk entries and its bodies' entries of travel/ctravel; everything else (partition, rebuild,
//   activations, the redo decision, the gather, the counters in island order) stays on the calling thread. An
//   island computes the same numbers on any thread, so every thread count gives the same results bit for bit.
// - Help inside an island (help_desk.h): a thread left without an island while others still run serves the pool's
//   help desk; an island whose loops over contacts, pairs, bodies or state components are long enough
//   (PD_HELP_MIN_CONTACTS, PD_HELP_MIN_PAIRS, PD_HELP_MIN_BODIES, PD_HELP_MIN_COMPONENTS) posts their second
//   half there. A batch of one island wakes the workers only from PD_ISLAND_HELP_WEIGHT on. Each index is
//   computed alike on either thread and combined in index order by the island's own, so this too leaves every
//   result the same bit for bit.
// - Sleeping (settings.sleep; sleep.h, docs/sleeping.md): at the end of an interval an island whose bodies all touch
//   something and stayed below the speed and acceleration thresholds for its settle time falls asleep: it is kept
//   with its state as it is and never advanced, so the gather hands the scene the same frozen numbers at every
//   sample. Its bodies take part in every partition with their boxes where they lie (not swept, bound 0) and stay
//   one island (join_sleepers); a sleeping island that the partition joins with a moving body or another sleeping
//   island wakes (wake_reached) and the partition is formed again, as for a free body activated; so does one whose
//   applied force changed (wake_pushed). A woken island is freed and its bodies set up anew from the scene's
//   numbers, which are the frozen ones. Every decision is taken on the calling thread from numbers no thread count
//   changes.
//
// Memory: islands are set up, grown and freed only at sync times; a step allocates nothing. The pool's
// threads are created with the set (or when pdState.threads changes) and joined when it is freed.
#include "islands.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "broad_phase.h"
#include "clock.h"
#include "contact_set.h"
#include "grow.h"
#include "integrator.h"
#include "interference.h"
#include "island_partition.h"
#include "island_set.h"
#include "model_contact.h"
#include "pool.h"
#include "samples.h"
#include "sleep.h"
#include "state_layout.h"

// Sync times: a sample interval is cut into equal parts so that a body at the characteristic speed vmax travels
// at most this fraction of the smallest moving body's size over one part, at most PD_ISLAND_SYNC_PARTS_MAX parts.
// The bounds grow with the interval: with short ones, bodies that fall or bounce near each other stay in
// islands of their own; each cut also cuts every island's step. With boxes only (no separating-axis test in the
// partition), on cases/bench/pile_1000.scene (0.5 s): the samples alone (10 ms) took 3.3× as long as 0.05 (11
// parts), 0.02 (16 parts) 0.93× of it. With the separating-axis test the islands stay small with fewer cuts:
// 0.05 against 0.02 (CPU time, side by side) cases/sweep/pile_10.scene 0.90x,
// cases/bench/pile_1000.scene 0.96x, pile_100, the bin of 100 and the demo 1.00x; 0.1 the same on pile_10,
// 0.2 1.01x (the samples alone: pile_1000 10x slower, its largest island 751 boxes).
#define PD_ISLAND_SYNC_SIZE_FRACTION 0.05
#define PD_ISLAND_SYNC_PARTS_MAX 16
// A body that moved farther than its bound gets this many times the distance it moved as its new bound.
#define PD_ISLAND_REDO_GROWTH 2.0
// An island's weight in the order the threads take the islands in: its moving bodies plus its contacts, a
// contact counted as this many bodies (a contact's force and events cost about what a body's motion costs: a
// rough guess; the heaviest go first, so that the last ones taken are small).
#define PD_ISLAND_CONTACT_WEIGHT 1
// A batch of one island wakes the other threads to serve its help desk (help_desk.h) from this weight on (bodies +
// contacts): below it the per-contact loops are too short to split (PD_HELP_MIN_CONTACTS in contact_list.h).
#define PD_ISLAND_HELP_WEIGHT 128

// the set and its islands: island_set.h

// ---------------------------------------------------------------- one island

static void island_free(island* is) {
  if (!is) return;
  pd_state_release(is->state);
  pd_material_table_free(is->model.materials);
  free(is->model.bodies);
  free(is->model.movingBodies);
  free(is->toScene);
  free(is->bodies);
  free(is);
}

// The model of members[0 .. count) (moving-body indices, ascending) and every fixed body, scene order.
static island* island_create(const pdModel* model, struct pdIslandSet* set, const int* members, int count) {
  island* is = pd_zeroed(1, sizeof *is);
  is->bodyCount = count;
  is->bodies = pd_grow(NULL, (size_t)count, sizeof *is->bodies);
  memcpy(is->bodies, members, (size_t)count * sizeof *members);
  int n = count + set->fixedCount;
  is->toScene = pd_grow(NULL, (size_t)n, sizeof *is->toScene);
  // merge the two ascending lists of scene indices
  for (int m = 0, f = 0, l = 0; l < n; ++l) {
    int moving = m < count ? model->movingBodies[members[m]] : model->bodyCount;
    int fixed = f < set->fixedCount ? set->fixedBodies[f] : model->bodyCount;
    if (moving < fixed) {
      is->toScene[l] = moving;
      ++m;
    } else {
      is->toScene[l] = fixed;
      ++f;
    }
  }
  pdModel* sub = &is->model;
  *sub = *model;  // settings, scene path, length scale
  sub->bodyCount = n;
  sub->movingCount = count;
  sub->bodies = pd_grow(NULL, (size_t)n, sizeof *sub->bodies);
  sub->movingBodies = pd_grow(NULL, (size_t)count, sizeof *sub->movingBodies);
  for (int l = 0, k = 0; l < n; ++l) {
    sub->bodies[l] = model->bodies[is->toScene[l]];
    if (sub->bodies[l].fixed) continue;
    sub->bodies[l].stateIndex = k;
    sub->movingBodies[k++] = l;
  }
  sub->materials = pd_material_table_view(model->materials, is->toScene, n);
  is->state = pd_state_create(sub, NULL);  // island_load sets its stepper and onsets
  pd_contact_set_help(is->state->contacts, &set->pool.desk);
  return is;
}

// Sets island `is` up from the scene's state s at T: its bodies' numbers, the scene's contacts listed in
// contacts[0 .. count) (scene contact indices), the stepper, onset mode and the smallest step its bodies last
// wanted.
static void island_load(const pdModel* model, const pdState* s, struct pdIslandSet* set, island* is,
                        const int* contacts, int count) {
  pdState* sub = is->state;
  sub->stepper = s->stepper;
  sub->onsets = s->onsets;
  sub->searchCertificates = s->searchCertificates;
  sub->stageTimers = s->stageTimers;
  sub->stepObserver = s->stepObserver;
  sub->stepUser = s->stepUser;
  sub->t = s->t;
  sub->nextSample = s->nextSample;
  double h = INFINITY;
  for (int j = 0; j < is->bodyCount; ++j) {
    int k = is->bodies[j];
    memcpy(sub->y + PD_BODY_STATE_SIZE * j, s->y + PD_BODY_STATE_SIZE * k, PD_BODY_STATE_SIZE * sizeof *s->y);
    h = fmin(h, set->h[k]);
  }
  sub->h = h;
  sub->hLimit = pd_limitError;  // a first step: the error control rejects it down or grows it
  for (int l = 0; l < is->model.bodyCount; ++l) set->toSub[is->toScene[l]] = l;
  pd_contact_set_scatter(model, s, contacts, count, &is->model, sub, set->toSub);
  for (int l = 0; l < is->model.bodyCount; ++l) set->toSub[is->toScene[l]] = -1;
}

// The step hook of an island's pd_step_until: each body's travel since T (centre displacement plus
// radius × rotation angle), the largest so far kept.
typedef struct travelProbe {
  const island* is;
  double t0;              // s: when the paths start (T; a free body: T0 of the sample interval)
  const pdVec3 *x0, *v0;  // (movingCount) centre of mass and velocity at t0
  const pdQuat* q0;       // (movingCount) orientation at t0
  double* travel;         // (movingCount) the largest distance from the path so far, m
  pdSleepSet* sleep;      // nullable: the bodies' speed peaks (sleep.h)
} travelProbe;

// Island body j's distance from the probe's path at time t, its numbers y: centre displacement plus radius ×
// rotation angle.
static double path_distance(const pdModel* sub, const travelProbe* probe, int j, double t, const double* y) {
  double tau = t - probe->t0;
  int k = probe->is->bodies[j];
  pdQuat q = pd_layout_q(y), q0 = probe->q0[k];
  double dot = fabs(q.w * q0.w + q.x * q0.x + q.y * q0.y + q.z * q0.z);
  double norms =
      sqrt((q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) * (q0.w * q0.w + q0.x * q0.x + q0.y * q0.y + q0.z * q0.z));
  double angle = 2.0 * acos(fmin(1.0, dot / norms));
  const pdBody* b = &sub->bodies[sub->movingBodies[j]];
  pdVec3 ballistic = pd_v3_add(
      probe->x0[k], pd_v3_add(pd_v3_scale(probe->v0[k], tau), pd_v3_scale(sub->settings.gravity, 0.5 * tau * tau)));
  return pd_v3_norm(pd_v3_sub(pd_layout_x(y), ballistic)) + b->radius * angle;
}

// Island body j's numbers y at time t: its travel from the path and its speed peak.
static void measure_body(const pdModel* sub, const travelProbe* probe, int j, double t, const double* y) {
  int k = probe->is->bodies[j];
  probe->travel[k] = fmax(probe->travel[k], path_distance(sub, probe, j, t, y));
  if (probe->sleep) pd_sleep_step_end(probe->sleep, &sub->bodies[sub->movingBodies[j]], k, y);
}

static void measure_travel(const pdModel* sub, const pdState* state, void* user) {
  const travelProbe* probe = user;
  for (int j = 0; j < probe->is->bodyCount; ++j)
    measure_body(sub, probe, j, state->t, state->y + PD_BODY_STATE_SIZE * j);
}

// Island `is` starts an interval: its bodies' travel and speed peaks restart (a free body's island, coarse, keeps
// what it measured since T0). Returns the probe its step ends are measured with.
static travelProbe start_probe(struct pdIslandSet* set, island* is, bool coarse) {
  if (!coarse)
    for (int j = 0; j < is->bodyCount; ++j) {
      set->travel[is->bodies[j]] = 0.0;
      if (set->sleep)
        pd_sleep_interval_start(set->sleep, &is->model.bodies[is->model.movingBodies[j]], is->bodies[j],
                                is->state->y + PD_BODY_STATE_SIZE * j);
    }
  is->advanced = true;
  return coarse ? (travelProbe){is, set->ct0, set->cx0, set->cv0, set->cq0, set->ctravel, NULL}
                : (travelProbe){is, set->t0, set->x0, set->v0, set->q0, set->travel, set->sleep};
}

// Advances island `is` to tNext; false if it failed. A free body's island (coarse) measures against its path
// over the whole sample interval, and keeps what it measured since T0.
static bool island_advance(struct pdIslandSet* set, island* is, double tNext, bool land, bool coarse) {
  travelProbe probe = start_probe(set, is, coarse);
  return pd_step_until(&is->model, is->state, tNext, land, NULL, NULL, false, measure_travel, &probe);
}

// ---------------------------------------------------------------- the pool's jobs

// Runs job i of the batch (pdPoolJobFcn).
static void run_job(void* ctx, int i) {
  struct pdIslandSet* set = ctx;
  set->jobOk[i] = island_advance(set, set->jobs[i], set->jobTime, set->jobLand, set->jobCoarse[i]);
}

// Adds island `is` (to the batch's time) to the batch.
static void add_job(struct pdIslandSet* set, island* is, bool coarse) {
  set->jobs[set->jobCount] = is;
  set->jobCoarse[set->jobCount] = coarse;
  set->jobOk[set->jobCount] = false;
  ++set->jobCount;
}

// Runs the batch to tNext: the jobs ordered heaviest first, the workers woken, the caller taking jobs too,
// then a wait for the rest. False if an island failed; every job runs either way, so the islands' states do
// not depend on the thread count.
static bool run_batch(struct pdIslandSet* set, double tNext, bool land) {
  if (set->jobCount == 0) return true;  // (the free bodies' batch of an interval with none)
  set->jobTime = tNext;
  set->jobLand = land;
  for (int i = 0; i < set->jobCount; ++i) {
    const island* is = set->jobs[i];
    set->order[i] = (pdPoolOrder){is->bodyCount + PD_ISLAND_CONTACT_WEIGHT * (long)pd_state_contact_count(is->state), i};
  }
  pd_pool_run(&set->pool, set->order, set->jobCount, PD_ISLAND_HELP_WEIGHT, run_job, set);
  bool ok = true;
  for (int i = 0; i < set->jobCount; ++i) ok = ok && set->jobOk[i];
  set->jobCount = 0;
  return ok;
}

// ---------------------------------------------------------------- counters

static void add_counters(pdCounters* to, const pdCounters* c) {
  to->accepted += c->accepted;
  to->rejected += c->rejected;
  to->derivatives += c->derivatives;
  to->eventRetries += c->eventRetries;
  to->onsetCuts += c->onsetCuts;
  to->onsetsInterpolated += c->onsetsInterpolated;
  to->travelRetries += c->travelRetries;
  to->refinements += c->refinements;
  to->stabilityTight += c->stabilityTight;
  to->implicitSteps += c->implicitSteps;
  for (int k = 0; k < pd_limitCount; ++k) to->stepsLimited[k] += c->stepsLimited[k];
  to->searchesSkipped += c->searchesSkipped;
  to->contactsMade += c->contactsMade;
  to->contactsVirtual += c->contactsVirtual;
  to->contactsTransferred += c->contactsTransferred;
  to->breaksForce += c->breaksForce;
  to->breaksGeometry += c->breaksGeometry;
  to->onsetBoundMax = fmax(to->onsetBoundMax, c->onsetBoundMax);
  to->onsetBoundSum += c->onsetBoundSum;
  to->transitionsUnlocated += c->transitionsUnlocated;
  to->transitionBoundMax = fmax(to->transitionBoundMax, c->transitionBoundMax);
  to->transitionBoundSum += c->transitionBoundSum;
  to->releasesCorrected += c->releasesCorrected;
  to->releaseBoundMax = fmax(to->releaseBoundMax, c->releaseBoundMax);
  to->releaseBoundSum += c->releaseBoundSum;
  to->historyKept += c->historyKept;
}

static void retire(struct pdIslandSet* set, island* is) {
  add_counters(&set->retired, &is->state->count);
  for (int w = 0; w < pd_warnCount; ++w) set->retiredWarnings[w] += is->state->warnings[w];
  for (int g = 0; g < pd_stageCount; ++g) set->retiredStages[g] += is->state->stageSeconds[g];
  island_free(is);
}

// The scene state's counters, warnings and stage seconds: the freed islands' plus the live ones', in island
// order (integers: the order does not matter; seconds are not reproducible anyway).
static void compose_set_counters(const struct pdIslandSet* set, pdState* s);

static void compose_counters(struct pdIslandSet* set, pdState* s) {
  long samples = s->count.samples;
  s->count = set->retired;
  memcpy(s->warnings, set->retiredWarnings, sizeof s->warnings);
  memcpy(s->stageSeconds, set->retiredStages, sizeof s->stageSeconds);
  for (int i = 0; i < set->islandCount; ++i) {
    const pdState* sub = set->islands[i]->state;
    add_counters(&s->count, &sub->count);
    for (int w = 0; w < pd_warnCount; ++w) s->warnings[w] += sub->warnings[w];
    for (int g = 0; g < pd_stageCount; ++g) s->stageSeconds[g] += sub->stageSeconds[g];
  }
  s->stageSeconds[pd_stageObserve] += set->observeSeconds;
  s->count.samples = samples;
  compose_set_counters(set, s);
  set->stagesBehind = false;
}

// The scene state's counters of the set's own (islands formed, intervals, sleeping ...): all that changes in the
// scene's counters while no island steps.
static void compose_set_counters(const struct pdIslandSet* set, pdState* s) {
  s->count.islandsFormed = set->formed;
  s->count.islandsLargest = set->largest;
  s->count.islandIntervals = set->intervals;
  s->count.islandRedos = set->redos;
  s->count.islandStrays = set->strays;
  if (set->sleep) {
    s->count.islandsSlept = set->sleep->sleeps;
    s->count.islandsWoken = set->sleep->wakes;
    s->count.bodySecondsAsleep = set->sleep->bodySeconds;
  }
}

// ---------------------------------------------------------------- the set

int pd_island_count(const pdState* s) { return s->islandSet ? s->islandSet->islandCount : 0; }

long pd_island_help_served(const pdState* s) {
  return s->islandSet ? atomic_load(&s->islandSet->pool.desk.served) : 0;
}

void pd_island_set_free(struct pdIslandSet* set) {
  if (!set) return;
  pd_pool_destroy(&set->pool);
  pd_sleep_free(set->sleep);
  free(set->jobs);
  free(set->jobCoarse);
  free(set->jobOk);
  free(set->order);
  for (int i = 0; i < set->islandCount; ++i) island_free(set->islands[i]);
  free(set->fixedBodies);
  free(set->root);
  free(set->islandOf);
  free(set->islandOld);
  free(set->members);
  free(set->first);
  free(set->bound);
  free(set->travel);
  free(set->h);
  free(set->x0);
  free(set->v0);
  free(set->box0);
  free(set->touching);
  free(set->free);
  free(set->cx0);
  free(set->cv0);
  free(set->cq0);
  free(set->cbound);
  free(set->ctravel);
  free(set->cbox);
  free(set->activate);
  free(set->q0);
  free(set->r0);
  free(set->boxes);
  pd_broad_phase_free(set->broad);
  free(set->pairs);
  free(set->sat);
  free(set->satNext);
  free(set->toSub);
  free(set->contactOf);
  free(set->contacts);
  free(set->contactFirst);
  free(set->islands);
  free(set->next);
  free(set->subModels);
  free(set->subStates);
  free(set->subMaps);
  free(set);
}

static struct pdIslandSet* set_create(const pdModel* model, const pdState* s) {
  struct pdIslandSet* set = pd_zeroed(1, sizeof *set);
  int m = model->movingCount, n = model->bodyCount;
  set->movingCount = m;
  set->bodyCount = n;
  set->fixedBodies = pd_grow(NULL, (size_t)n, sizeof *set->fixedBodies);
  bool* fixed = pd_grow(NULL, (size_t)n, sizeof *fixed);
  set->boxes = pd_grow(NULL, (size_t)n, sizeof *set->boxes);
  set->toSub = pd_grow(NULL, (size_t)n, sizeof *set->toSub);
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &model->bodies[i];
    fixed[i] = b->fixed;
    if (b->fixed) set->fixedBodies[set->fixedCount++] = i;
    pdMat3 r = pd_quat_to_mat3(pd_quat_normalize(b->q0));
    set->boxes[i] = pd_aabb_of(&b->shape, b->x0, &r);
    set->toSub[i] = -1;
  }
  set->broad = pd_broad_phase_create(n, fixed, 0.0);
  PD_ASSERT(set->broad != NULL);
  free(fixed);
  set->pairCapacity = 4 * m + 16;
  set->pairs = pd_grow(NULL, (size_t)set->pairCapacity, sizeof *set->pairs);
  set->sat = pd_grow(NULL, (size_t)set->pairCapacity, sizeof *set->sat);
  set->satNext = pd_grow(NULL, (size_t)set->pairCapacity, sizeof *set->satNext);
  set->root = pd_grow(NULL, (size_t)m, sizeof *set->root);
  set->islandOf = pd_grow(NULL, (size_t)m, sizeof *set->islandOf);
  set->islandOld = pd_grow(NULL, (size_t)m, sizeof *set->islandOld);
  set->members = pd_grow(NULL, (size_t)m, sizeof *set->members);
  set->first = pd_grow(NULL, (size_t)m + 1, sizeof *set->first);
  set->contactFirst = pd_grow(NULL, (size_t)m + 1, sizeof *set->contactFirst);
  set->contactCapacity = 4 * m + 16;  // grown in partition when the list outgrows it
  set->contactOf = pd_grow(NULL, (size_t)set->contactCapacity, sizeof *set->contactOf);
  set->contacts = pd_grow(NULL, (size_t)set->contactCapacity, sizeof *set->contacts);
  set->bound = pd_grow(NULL, (size_t)m, sizeof *set->bound);
  set->travel = pd_grow(NULL, (size_t)m, sizeof *set->travel);
  set->h = pd_grow(NULL, (size_t)m, sizeof *set->h);
  set->x0 = pd_grow(NULL, (size_t)m, sizeof *set->x0);
  set->v0 = pd_grow(NULL, (size_t)m, sizeof *set->v0);
  set->box0 = pd_grow(NULL, (size_t)m, sizeof *set->box0);
  set->touching = pd_grow(NULL, (size_t)m, sizeof *set->touching);
  set->free = pd_zeroed((size_t)m, sizeof *set->free);
  set->cx0 = pd_grow(NULL, (size_t)m, sizeof *set->cx0);
  set->cv0 = pd_grow(NULL, (size_t)m, sizeof *set->cv0);
  set->cq0 = pd_grow(NULL, (size_t)m, sizeof *set->cq0);
  set->cbound = pd_grow(NULL, (size_t)m, sizeof *set->cbound);
  set->ctravel = pd_grow(NULL, (size_t)m, sizeof *set->ctravel);
  set->cbox = pd_grow(NULL, (size_t)m, sizeof *set->cbox);
  set->activate = pd_grow(NULL, (size_t)m, sizeof *set->activate);
  set->q0 = pd_grow(NULL, (size_t)m, sizeof *set->q0);
  set->r0 = pd_grow(NULL, (size_t)m, sizeof *set->r0);
  set->sizeMin = INFINITY;
  for (int k = 0; k < m; ++k) {
    set->sizeMin = fmin(set->sizeMin, model->bodies[model->movingBodies[k]].size);
    set->islandOld[k] = -1;
    set->h[k] = s->h;
  }
  set->islandCapacity = m > 0 ? m : 1;
  set->islands = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->islands);
  set->next = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->next);
  set->subModels = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->subModels);
  set->subStates = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->subStates);
  set->subMaps = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->subMaps);
  set->jobs = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->jobs);
  set->jobCoarse = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->jobCoarse);
  set->jobOk = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->jobOk);
  set->order = pd_grow(NULL, (size_t)set->islandCapacity, sizeof *set->order);
  if (model->settings.sleep) set->sleep = pd_sleep_create(model);
  pd_pool_init(&set->pool, s->threads);
  return set;
}

// Makes the live islands those of the partition: an island whose bodies did not change is kept as it is
// (advanced or not); the others are freed and new ones set up from the scene's state at T. Returns the
// number of islands set up.
static int rebuild(const pdModel* model, const pdState* s, struct pdIslandSet* set) {
  int built = 0;
  for (int j = 0; j < set->partCount; ++j) {
    const int* members = set->members + set->first[j];
    int count = set->first[j + 1] - set->first[j];
    int old = set->islandOld[members[0]];
    bool same = old >= 0 && set->islands[old] != NULL && set->islands[old]->bodyCount == count;
    for (int m = 1; m < count && same; ++m) same = set->islandOld[members[m]] == old;
    if (same) {
      set->next[j] = set->islands[old];
      set->islands[old] = NULL;
      continue;
    }
    island* is = island_create(model, set, members, count);
    island_load(model, s, set, is, set->contacts + set->contactFirst[j],
                set->contactFirst[j + 1] - set->contactFirst[j]);
    set->next[j] = is;
    ++built;
    ++set->formed;
    if (count > set->largest) set->largest = count;
  }
  for (int i = 0; i < set->islandCount; ++i)
    if (set->islands[i]) retire(set, set->islands[i]);
  island** t = set->islands;
  set->islands = set->next;
  set->next = t;
  set->islandCount = set->partCount;
  for (int j = 0; j < set->islandCount; ++j)
    for (int m = 0; m < set->islands[j]->bodyCount; ++m) set->islandOld[set->islands[j]->bodies[m]] = j;
  return built;
}

// ---------------------------------------------------------------- one interval

// Body k's numbers at the scene's state s (its time T): start pose, box and bound over dt (fine: set->x0 …).
static void set_start(const pdModel* model, const pdState* s, struct pdIslandSet* set, int k, double dt) {
  const pdBody* b = &model->bodies[model->movingBodies[k]];
  const double* yb = s->y + PD_BODY_STATE_SIZE * k;
  set->x0[k] = pd_layout_x(yb);
  set->v0[k] = pd_layout_v(yb);
  set->q0[k] = pd_layout_q(yb);
  set->r0[k] = pd_quat_to_mat3(pd_quat_normalize(set->q0[k]));
  set->box0[k] = pd_aabb_of(&b->shape, set->x0[k], &set->r0[k]);
  set->travel[k] = 0.0;
  if (set->sleep && set->sleep->asleep[k]) {
    // frozen: its box stays where it is, whatever its (frozen) velocity says
    set->v0[k] = (pdVec3){0.0, 0.0, 0.0};
    set->bound[k] = 0.0;
    return;
  }
  set->bound[k] =
      pd_island_travel_bound(model, set, k, yb, &set->r0[k], &set->box0[k], &set->touching[k], s->t, dt);
}

// Marks in set->touching the moving bodies of the scene's contacts.
static void mark_touching(const pdModel* model, const pdState* s, struct pdIslandSet* set) {
  for (int k = 0; k < set->movingCount; ++k) set->touching[k] = false;
  for (int c = 0; c < pd_state_contact_count(s); ++c) {
    int b1, b2;
    pd_contact_set_bodies(s->contacts, c, &b1, &b2);
    if (!model->bodies[b1].fixed) set->touching[model->bodies[b1].stateIndex] = true;
    if (!model->bodies[b2].fixed) set->touching[model->bodies[b2].stateIndex] = true;
  }
}

// ---------------------------------------------------------------- sleeping (sleep.h)

// Sleeping island j wakes at T (the scene's state s): its state is freed, and its bodies, moving again, are set up
// in a new island from the scene's numbers at T, which are the frozen ones (its contacts' springs included).
static void wake_island(const pdModel* model, const pdState* s, struct pdIslandSet* set, int j, double dt) {
  island* is = set->islands[j];
  for (int m = 0; m < is->bodyCount; ++m) {
    int k = is->bodies[m];
    set->sleep->asleep[k] = false;
    pd_sleep_restless(set->sleep, k);
    set->islandOld[k] = -1;
    set_start(model, s, set, k, dt);
  }
  ++set->sleep->wakes;
  retire(set, is);
  set->islands[j] = NULL;
}

// Sleeping islands on one of whose bodies the applied force changed since it fell asleep wake at T.
static void wake_pushed(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt) {
  for (int j = 0; j < set->islandCount; ++j) {
    const island* is = set->islands[j];
    if (!is || !is->asleep) continue;
    bool pushed = false;
    for (int m = 0; m < is->bodyCount && !pushed; ++m) {
      int k = is->bodies[m];
      pushed = pd_sleep_force_changed(set->sleep, &model->bodies[model->movingBodies[k]], k, s->t);
    }
    if (pushed) wake_island(model, s, set, j, dt);
  }
}

// After a partition: a sleeping island that shares an island of the partition with a moving body (its box, grown by
// all it can move, and the sleeping body's may meet: the broad phase, then the separating-axis test) or with
// another sleeping island wakes. True if one woke (the partition must be formed again).
static bool wake_reached(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt) {
  bool woke = false;
  for (int p = 0; p < set->partCount; ++p) {
    bool mixed = false;
    int owner0 = 0;
    for (int i = set->first[p]; i < set->first[p + 1]; ++i) {
      int k = set->members[i];
      int owner = set->sleep->asleep[k] ? set->islandOld[k] : -1;
      if (i == set->first[p])
        owner0 = owner;
      else if (owner != owner0)
        mixed = true;
    }
    if (!mixed) continue;
    for (int i = set->first[p]; i < set->first[p + 1]; ++i) {
      int k = set->members[i];
      if (set->sleep->asleep[k]) {
        wake_island(model, s, set, set->islandOld[k], dt);
        woke = true;
      }
    }
  }
  return woke;
}

// At the end of the interval [T, tNext], the scene's state gathered: the body-seconds asleep over it, and the
// islands quiet for their settle time fall asleep (sleep.h). A sleeping island keeps its state as it is: the
// scene's numbers at tNext are its own, presented there, and stay so at every later sample until it wakes.
static void fall_asleep(const pdModel* model, const pdState* s, struct pdIslandSet* set, double tNext) {
  pdSleepSet* sleep = set->sleep;
  long asleep = 0;
  for (int k = 0; k < set->movingCount; ++k) asleep += sleep->asleep[k];
  sleep->bodySeconds += (double)asleep * (tNext - set->t0);
  for (int j = 0; j < set->islandCount; ++j) {
    island* is = set->islands[j];
    if (is->asleep || set->free[is->bodies[0]]) continue;  // a free body touches nothing: never at rest
    // nor is an island without a contact, whatever its speed: its settle time is infinite (pd_sleep_settle_time), so
    // pd_sleep_quiet finds none of its bodies quiet (a lone body in flight, tested at every sample)
    if (pd_state_contact_count(is->state) == 0) {
      for (int m = 0; m < is->bodyCount; ++m) pd_sleep_restless(sleep, is->bodies[m]);
      continue;
    }
    // the cheap test first: one body above the speed threshold keeps the island awake, and the quiet time of every
    // body in it starts again (an island comes to rest as a whole)
    bool slow = true;
    for (int m = 0; m < is->bodyCount && slow; ++m) {
      int k = is->bodies[m];
      slow = pd_sleep_slow(sleep, &model->bodies[model->movingBodies[k]], k, s->y + PD_BODY_STATE_SIZE * k);
    }
    if (!slow) {
      for (int m = 0; m < is->bodyCount; ++m) pd_sleep_restless(sleep, is->bodies[m]);
      continue;
    }
    double settle = pd_sleep_settle_time(&is->model, is->state);
    // The acceleration threshold guards the frozen velocity until the scene's end, not one settle time: a body
    // accelerating steadily (a block sliding down an incline under a loose tol) stays below the speed threshold
    // over a settle time and would leave it long before the end.
    double horizon = fmax(settle, model->settings.tend - tNext);
    for (int m = 0; m < is->bodyCount; ++m) sleep->inContact[is->bodies[m]] = false;
    for (int c = 0; c < pd_state_contact_count(is->state); ++c) {
      int b[2];
      pd_contact_set_bodies(is->state->contacts, c, &b[0], &b[1]);
      for (int e = 0; e < 2; ++e)
        if (!is->model.bodies[b[e]].fixed) sleep->inContact[is->bodies[is->model.bodies[b[e]].stateIndex]] = true;
    }
    bool quiet = true, slowAll = true;
    double since = -INFINITY, slowSince = -INFINITY;
    for (int m = 0; m < is->bodyCount; ++m) {
      int k = is->bodies[m];
      const pdBody* b = &model->bodies[model->movingBodies[k]];
      bool bodyQuiet = pd_sleep_quiet(sleep, b, k, s->y + PD_BODY_STATE_SIZE * k, set->t0, tNext, horizon);
      // pd_sleep_quiet has already cleared quietSince for a body that was not quiet
      if (!sleep->inContact[k]) pd_sleep_restless(sleep, k);
      if (!bodyQuiet || !sleep->inContact[k])
        quiet = false;
      else
        since = fmax(since, sleep->quietSince[k]);
      if (isnan(sleep->slowSince[k]))
        slowAll = false;
      else
        slowSince = fmax(slowSince, sleep->slowSince[k]);
    }
    // quiet at every interval for a settle time; else slow for one, its acceleration read over the whole window
    // (sleep.h): a body ringing within the speed threshold, its velocity going nowhere
    bool rests = quiet && tNext - since >= settle;
    if (!rests && slowAll && tNext - slowSince >= settle) {
      rests = true;
      for (int m = 0; m < is->bodyCount; ++m) {
        int k = is->bodies[m];
        if (!pd_sleep_still(sleep, &model->bodies[model->movingBodies[k]], k, s->y + PD_BODY_STATE_SIZE * k, tNext,
                            horizon)) {
          sleep->slowSince[k] = NAN;  // its window starts again
          rests = false;
        }
      }
    }
    if (!rests) continue;
    is->asleep = true;
    ++sleep->sleeps;
    for (int m = 0; m < is->bodyCount; ++m) pd_sleep_fall_asleep(sleep, is->bodies[m], tNext, horizon);
  }
}

// The islands at tNext gathered into the scene's state: bodies, then contacts (sorted by id), and each body's next
// step; then the islands quiet long enough fall asleep. Free bodies' numbers only at the sample (`last`).
static void gather(const pdModel* model, pdState* s, struct pdIslandSet* set, double tNext, bool last) {
  for (int j = 0; j < set->islandCount; ++j) {
    const island* is = set->islands[j];
    if (set->free[is->bodies[0]] && !last) continue;  // still at T0: the scene keeps its numbers from there
    for (int m = 0; m < is->bodyCount; ++m) {
      int k = is->bodies[m];
      memcpy(s->y + PD_BODY_STATE_SIZE * k, is->state->y + PD_BODY_STATE_SIZE * m, PD_BODY_STATE_SIZE * sizeof *s->y);
      set->h[k] = is->state->h;
    }
  }
  for (int j = 0; j < set->islandCount; ++j) {
    const island* is = set->islands[j];
    // a sleeping island's state stays presented as it fell asleep: evaluated once there, not at every gather's read
    if (is->asleep) pd_contact_set_settle(is->state->contacts, is->state->y);
    set->subModels[j] = &is->model;
    set->subStates[j] = is->state;
    set->subMaps[j] = is->toScene;
  }
  pd_contact_set_gather(model, s, set->islandCount, set->subModels, set->subStates, set->subMaps);
  if (set->sleep) fall_asleep(model, s, set, tNext);
}

// A free body's island goes on to tNext alone (coarse: against its path over the sample interval); its
// numbers go to the scene's state. False if it failed.
static bool free_advance(pdState* s, struct pdIslandSet* set, int k, double tNext, bool land) {
  island* is = set->islands[set->islandOld[k]];
  PD_ASSERT(is->bodyCount == 1 && is->bodies[0] == k);
  if (is->state->t < tNext) {
    ++set->intervals;
    if (!island_advance(set, is, tNext, land, true)) return false;
  }
  if (set->ctravel[k] > set->cbound[k]) ++set->strays;
  memcpy(s->y + PD_BODY_STATE_SIZE * k, is->state->y, PD_BODY_STATE_SIZE * sizeof *s->y);
  set->h[k] = is->state->h;
  return true;
}

// The islands from s (at T) to tNext, then the scene's state gathered at tNext (free bodies' numbers only at
// the sample, `last`). False if an island failed (s keeps its state at T).
static bool advance_interval(const pdModel* model, pdState* s, struct pdIslandSet* set, double tNext, bool last) {
  double dt = tNext - s->t;
  set->t0 = s->t;
  // a sample interval gone through in one (a stack, a pile at rest) has its starts from find_free: the same numbers
  bool startsKept = set->startsFormed && set->startsT == s->t && set->startsDt == dt;
  if (!startsKept) {
    mark_touching(model, s, set);
    for (int k = 0; k < set->movingCount; ++k)
      if (!set->free[k]) set_start(model, s, set, k, dt);
  }
  set->startsFormed = false;  // the rounds below grow bounds and start activated bodies
  for (int j = 0; j < set->islandCount; ++j) set->islands[j]->advanced = false;
  long wakes = set->sleep ? set->sleep->wakes : 0;
  if (set->sleep) wake_pushed(model, s, set, dt);
  // A lone moving body whose starts are find_free's, none woken since: the partition find_free formed over this
  // interval is the one below would form (one island, its box the same: a free body's fine box is its coarse one).
  bool partitionKept = startsKept && set->movingCount == 1 && (!set->sleep || set->sleep->wakes == wakes);
  for (int round = 0;; ++round) {
    // a free body another body may reach joins the others from here: it is brought to T first; a sleeping island
    // another body may reach wakes here, and the partition is formed again with its bodies moving
    do {
      if (round == 0 && partitionKept) break;
      for (int activations; (activations = pd_island_partition(model, s, set, dt, true)) > 0;)
        for (int i = 0; i < activations; ++i) {
          int k = set->activate[i];
          if (s->t > set->ct0 && !free_advance(s, set, k, s->t, true)) return false;
          set->free[k] = false;
          // brought to T only: the interval is still to go (left marked advanced, an island that stays alone in the
          // partition would keep T's numbers for T'); a body free since the run's start has no island yet
          if (set->islandOld[k] >= 0) set->islands[set->islandOld[k]]->advanced = false;
          set_start(model, s, set, k, dt);
        }
    } while (set->sleep && wake_reached(model, s, set, dt));
    int built = rebuild(model, s, set);
    if (round > 0) set->redos += built;
    for (int j = 0; j < set->islandCount; ++j) {
      island* is = set->islands[j];
      if (is->advanced || is->asleep || set->free[is->bodies[0]]) continue;
      ++set->intervals;
      add_job(set, is, false);
    }
    if (!run_batch(set, tNext, !last)) return false;
    // a body that left its grown box could have met another island's body unseen: grow its bound and
    // form the partition again; islands that change are redone from T
    bool left = false;
    for (int k = 0; k < set->movingCount; ++k)
      if (!set->free[k] && set->travel[k] > set->bound[k]) {
        set->bound[k] = PD_ISLAND_REDO_GROWTH * set->travel[k];
        left = true;
      }
    if (!left) break;
  }
  if (last) {
    // the free bodies to the sample: their islands run as one batch, then their numbers go to the scene
    for (int k = 0; k < set->movingCount; ++k) {
      island* is = set->free[k] ? set->islands[set->islandOld[k]] : NULL;
      if (is && is->state->t < tNext) {
        ++set->intervals;
        add_job(set, is, true);
      }
    }
    if (!run_batch(set, tNext, false)) return false;
    for (int k = 0; k < set->movingCount; ++k)
      if (set->free[k] && !free_advance(s, set, k, tNext, false)) return false;
  }
  gather(model, s, set, tNext, last);
  return true;
}

// At the start T0 of a sample interval of length dt: each body's path and bound over the whole interval, and
// which bodies are free: alone in the partition of that interval (no contact, no box reaching another body's
// or a fixed body's). A free body has no contact to leave its ballistic path by: it goes to the sample in
// steps of its own, not cut at the sync times, unless another body's box over a sync interval reaches its
// box over the sample interval.
static void find_free(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt) {
  set->ct0 = s->t;
  mark_touching(model, s, set);
  for (int k = 0; k < set->movingCount; ++k) {
    set->free[k] = false;
    set_start(model, s, set, k, dt);
    set->cx0[k] = set->x0[k];
    set->cv0[k] = set->v0[k];
    set->cq0[k] = set->q0[k];
    set->cbound[k] = set->bound[k];
    set->ctravel[k] = 0.0;
  }
  set->startsFormed = true, set->startsT = s->t, set->startsDt = dt;
  pd_island_partition(model, s, set, dt, false);
  for (int j = 0; j < set->partCount; ++j) {
    if (set->first[j + 1] - set->first[j] != 1) continue;
    int k = set->members[set->first[j]];
    set->free[k] = !set->touching[k];
    set->cbox[k] = set->boxes[model->movingBodies[k]];
  }
}

// Whether cutting the sample interval at the sync times (each of length dt) would split an island of the
// partition over the whole interval (find_free's, set->partCount islands): the partition over the first sync
// interval, formed at T0, has more islands. If not, the sync times would only cut every island's steps and
// add a partition, a rebuild and a gather each: the islands go to the sample in one interval (a single body,
// a stack, a pile at rest). The partition over the whole interval holds at least as many bodies together as
// any over a part of it (each box grows with the interval), so a part's count is never lower.
static bool cuts_split_islands(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt) {
  int whole = set->partCount;
  mark_touching(model, s, set);
  for (int k = 0; k < set->movingCount; ++k)
    if (!set->free[k]) set_start(model, s, set, k, dt);
  set->startsFormed = true, set->startsT = s->t, set->startsDt = dt;
  int activations = pd_island_partition(model, s, set, dt, true);
  return activations > 0 || set->partCount > whole;
}

// ---------------------------------------------------------------- pd_advance with islands

// Into how many equal parts the interval dt is cut: the fewest that keep a body at the scene's characteristic
// speed vmax from moving more than PD_ISLAND_SYNC_SIZE_FRACTION of the smallest moving body's size over one,
// at most PD_ISLAND_SYNC_PARTS_MAX. A function of dt and the model only: the sync times do not depend on the
// bodies' states, so a group of bodies computes the same numbers whatever moves elsewhere.
static int sync_parts(const pdModel* model, const struct pdIslandSet* set, double dt) {
  double parts = ceil(dt * model->settings.vmax / (PD_ISLAND_SYNC_SIZE_FRACTION * set->sizeMin));
  return parts <= 1.0 ? 1 : (int)fmin(PD_ISLAND_SYNC_PARTS_MAX, parts);
}

static void observe(const pdModel* model, pdState* s, struct pdIslandSet* set, pdObserverFcn* observer, void* user) {
  set->observeSeconds += pd_observe(model, s, observer, user, true);
}

// ---------------------------------------------------------------- a lone body across samples

// A scene of one moving body, awake, is one island at every sync time, and its sample intervals are never cut
// (sync_parts' cut splits no island). Its island's steps then run to the call's end in one pd_step_until, as with
// islands off: each sample is presented from the step that passed it (dense output), and there, through the
// island's sample observer (lone_sample), the scene gets exactly what the interval loop would have given it at that
// sample: the travel and speed peaks measured on the same states (the step ends in the interval and the state
// presented at its end), the free-body test (find_free's, where its outcome can tell: lone_interval_end), the gather,
// the sleep test and the counters. The island falling asleep or the caller's observer stopping ends the run at that
// sample, with the island presented there as the interval loop leaves it; the interval loop takes over from there.
// The island's own steps, contact search and events are pd_step_until's, as in the interval loop: only the calls
// between samples go (per sample about 2 500 instructions of partition, rebuild, batch and re-entry, against the
// ~1 000 of a sample's presentation and observation that islands off spends too).
typedef struct loneRun {
  const pdModel* model;
  pdState* s;  // the scene's state
  struct pdIslandSet* set;
  island* is;
  pdObserverFcn* observer;  // the caller's, and its user pointer
  void* user;
  double tEnd;       // s: the call's end
  double tInterval;  // s: the end of the sample interval under way (the next sample, or tEnd)
  bool open;         // an interval under way (none once the one ending at tEnd is closed)
  bool untouched;    // the body had no contact at the interval's start (lone_interval_start)
  travelProbe probe;  // the interval's (a body without contact at its start: against its path from there)
  double slack;       // m: the body's (pd_island_slack)
  bool contactsAtEnd;  // the island's contacts at the last interval's end, which the gather gave the scene
  // A distance from the path below half the slack (the body's lowest bound) can change no decision: lone_near_path
  // tells such a state without the norm and the arc cosine. The squared distance and the squared cosine of the
  // angle's half that each leave a quarter of the slack (nearCos2 infinite: never told).
  double nearDistance2, nearCos2;
  // The speed peak (sleep.h) starts at the interval's start from the scene's numbers there (s->y until the gather),
  // when first needed: a step end in the interval, or the sleep test at its end. Its end's speed is the sleep
  // test's own (pd_sleep_slow, on the same numbers gathered), so the sample adds nothing to it.
  bool peakStarted;
  // A step end past tInterval, shown to the hook before the samples it passed are presented: it belongs to the
  // interval it ends in, and is measured when that interval starts.
  bool pending;
  double pendingT;
  double pendingY[PD_BODY_STATE_SIZE];
  long derivatives;       // the island's derivative evaluations when the scene's counters were last composed
} loneRun;

// The thresholds of lone_near_path for the body: its distance (centre displacement + radius × angle) below half its
// slack, a quarter from each part. The angle's is a cosine of its half, a/2 = slack / (8 r), and is used only where
// that half angle is wide enough (at least 1e-6 rad) for the rounding of the cosines compared (~1e-16) to move the
// arc cosine by a small part of it (acos near 1 turns an error e into about √(2e)).
static void lone_near_thresholds(loneRun* run) {
  const pdModel* model = run->model;
  const pdBody* b = &model->bodies[model->movingBodies[0]];
  double slack = run->slack;
  run->nearDistance2 = 0.0625 * slack * slack;
  double half = b->radius > 0.0 ? slack / (8.0 * b->radius) : INFINITY;
  run->nearCos2 = INFINITY;
  if (half >= 1e-6 && half <= 0.5) run->nearCos2 = cos(half) * cos(half);
}

// Whether the lone body's numbers y at t lie so near its path (the interval's probe) that path_distance is below half
// the slack (each part below a quarter: the roundings of the squares compared move it by far less than the other
// half).
static bool lone_near_path(const loneRun* run, double t, const double* y) {
  const travelProbe* probe = &run->probe;
  double tau = t - probe->t0;
  pdVec3 fall = pd_v3_scale(run->model->settings.gravity, 0.5 * tau * tau);
  pdVec3 ballistic = pd_v3_add(probe->x0[0], pd_v3_add(pd_v3_scale(probe->v0[0], tau), fall));
  pdVec3 d = pd_v3_sub(pd_layout_x(y), ballistic);
  if (!(pd_v3_dot(d, d) <= run->nearDistance2)) return false;
  pdQuat q = pd_layout_q(y), q0 = probe->q0[0];
  double dot = q.w * q0.w + q.x * q0.x + q.y * q0.y + q.z * q0.z;
  double norms =
      (q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) * (q0.w * q0.w + q0.x * q0.x + q0.y * q0.y + q0.z * q0.z);
  return dot * dot >= run->nearCos2 * norms;
}

// The speed peak of the interval under way, started (above).
static void lone_start_peak(loneRun* run) {
  const pdModel* sub = &run->is->model;
  pd_sleep_interval_start(run->set->sleep, &sub->bodies[sub->movingBodies[0]], 0, run->s->y);
  run->peakStarted = true;
}

// The lone body's numbers y at time t inside the interval, at a step end (`sample` false) or the interval's end. A
// body with no contact at the interval's start has its travel from its path measured (its stray counted:
// lone_interval_end); a step end grows the speed peak (the sleep test): the body's box, bound and travel serve the
// partition and the redo, which with one moving body form the same one island every time. A travel below half the
// slack is left out of the largest: lone_interval_end compares that with the slack and the bound (never below the
// slack) only, and the largest is the same wherever it exceeds the slack.
static void lone_measure(loneRun* run, double t, const double* y, bool sample) {
  const pdModel* sub = &run->is->model;
  if (run->untouched && !lone_near_path(run, t, y))
    run->set->ctravel[0] = fmax(run->set->ctravel[0], path_distance(sub, &run->probe, 0, t, y));
  if (sample || !run->set->sleep) return;
  if (!run->peakStarted) lone_start_peak(run);
  pd_sleep_step_end(run->set->sleep, &sub->bodies[sub->movingBodies[0]], 0, y);
}

// The sample interval from the scene's time to the next sample (or tEnd) starts, as advance_interval starts it for
// the one island. find_free's test is put off to the interval's end (lone_interval_end): the partition of one moving
// body is that body alone, so it is free when it touches nothing at the start and its box reaches no fixed body.
// A body in contact is not free; a body without is measured as a free one is, against its path from here.
static void lone_interval_start(loneRun* run) {
  pdState* s = run->s;
  struct pdIslandSet* set = run->set;
  double tSample = pd_sample_time(run->model, s->nextSample);
  set->t0 = set->ct0 = s->t;
  set->startsFormed = false;
  set->free[0] = false;
  ++set->intervals;
  run->untouched = !run->contactsAtEnd;
  set->touching[0] = !run->untouched;
  set->travel[0] = 0.0;  // start_probe's, but for the speed peak (lone_start_peak)
  run->is->advanced = true;
  run->peakStarted = false;
  if (run->untouched) {
    const double* y = s->y;
    set->cx0[0] = pd_layout_x(y);
    set->cv0[0] = pd_layout_v(y);
    set->cq0[0] = pd_layout_q(y);
    set->ctravel[0] = 0.0;
    run->probe.t0 = set->ct0;  // the rest is lone_run's: set->cx0, cv0, cq0, ctravel
  }
  run->tInterval = tSample < run->tEnd ? tSample : run->tEnd;
  run->open = true;
  if (run->pending && run->pendingT <= run->tInterval) {
    lone_measure(run, run->pendingT, run->pendingY, false);
    run->pending = false;
  }
}

// The interval ends at tNext with the island's state there; the scene's state s is still at its start T0. Whether
// the body was free decides two things only: a stray (its travel beyond its bound) is counted, and the sleep test
// is skipped. So find_free's test runs, from s at T0 as find_free would have run it, only where either can tell:
// a travel beyond the slack (the bound is never below it) or a contact at tNext (a free body has none: it would
// be skipped, not tested). Otherwise the body is taken as not free: its test finds no contact, so it leaves the
// quiet time as a free body's skipped test does (unset since the body's last contact). Then the gather (and the
// sleep test) and the counters; the scene's time is tNext.
static void lone_interval_end(loneRun* run, double tNext) {
  const pdModel* model = run->model;
  pdState* s = run->s;
  struct pdIslandSet* set = run->set;
  island* is = run->is;
  bool contacts = pd_state_contact_count(is->state) > 0;
  if (run->untouched && (contacts || set->ctravel[0] > run->slack)) {
    set_start(model, s, set, 0, tNext - s->t);
    set->cbound[0] = set->bound[0];
    set->free[0] = !set->touching[0];
    if (set->free[0] && set->ctravel[0] > set->cbound[0]) ++set->strays;
  }
  // fall_asleep for the one island, awake: a free body is skipped; a body without a contact is not quiet (its quiet
  // time unset), whatever its speed; the time asleep grows by nothing; else the test, which reads the speed peak,
  // started from the numbers at T0 before the gather overwrites them
  bool sleepTest = set->sleep && !set->free[0] && contacts;
  if (sleepTest && !run->peakStarted) lone_start_peak(run);
  // gather(), for the one island (the gather's lists are lone_run's)
  memcpy(s->y, is->state->y, PD_BODY_STATE_SIZE * sizeof *s->y);
  set->h[0] = is->state->h;
  pd_contact_set_gather(model, s, 1, set->subModels, set->subStates, set->subMaps);
  run->contactsAtEnd = contacts;
  if (sleepTest)
    fall_asleep(model, s, set, tNext);
  else if (set->sleep && !set->free[0])
    pd_sleep_restless(set->sleep, 0);
  // every counter of the island's but the samples (the scene's own) changes with a step tried, which evaluates the
  // derivative: without one, only the set's change (the stage timers wait for the run's end)
  if (is->state->count.derivatives != run->derivatives) {
    compose_counters(set, s);
    run->derivatives = is->state->count.derivatives;
  } else {
    compose_set_counters(set, s);
  }
  s->t = tNext;
  run->open = false;
}

// The island's step hook: a step end inside the interval is measured; one past it waits for its interval.
static void lone_step_end(const pdModel* sub, const pdState* state, void* user) {
  (void)sub;  // the island's: run->is->model
  loneRun* run = user;
  if (!run->open) return;  // the presented end of a call whose last sample closed the interval, measured there
  if (state->t <= run->tInterval) {
    lone_measure(run, state->t, state->y, false);
    return;
  }
  run->pending = true;
  run->pendingT = state->t;
  memcpy(run->pendingY, state->y, sizeof run->pendingY);
}

// The island's sample observer (pdObserverFcn): the interval ends at the sample, the scene is observed, the next
// interval starts. False (the island stops, presented at the sample) when the island fell asleep or the caller's
// observer stopped.
static bool lone_sample(const pdModel* sub, const pdState* state, void* user) {
  (void)sub;  // the island's: run->is->model
  loneRun* run = user;
  PD_ASSERT(run->open && state->t == run->tInterval);
  lone_measure(run, state->t, state->y, true);
  lone_interval_end(run, state->t);
  observe(run->model, run->s, run->set, run->observer, run->user);
  if (run->s->stopped || run->is->asleep) return false;
  if (run->s->t < run->tEnd) lone_interval_start(run);
  return true;
}

// Whether the scene's next sample intervals can go as one run of its lone body's island (above): one moving body,
// awake, no step observer (whose stretches start at every sync time: state.h), and on one thread unless the island is
// too light to be helped (PD_ISLAND_HELP_WEIGHT: a run through the pool could call the caller's observer from a
// worker thread).
static bool lone_runs(const pdState* s, const struct pdIslandSet* set) {
  if (set->movingCount != 1 || set->islandCount != 1 || set->islands[0]->asleep || s->stepObserver) return false;
  const island* is = set->islands[0];
  return s->threads == 1 || is->bodyCount + PD_ISLAND_CONTACT_WEIGHT * (long)pd_state_contact_count(is->state) <
                                PD_ISLAND_HELP_WEIGHT;
}

// A scene of one moving body asleep, its applied force unchanged: the interval loop would keep the island as it is
// and gather the same frozen numbers again; over the interval to target only the time asleep grows, as fall_asleep
// counts it. (A force that changed wakes it there: the interval loop. A step observer keeps the interval loop, as
// for a lone body awake: lone_runs.) No island steps, so of the scene's counters only the set's change: the stage
// seconds (the observer's) are composed once, when the call returns.
static bool lone_sleep_on(const pdModel* model, pdState* s, struct pdIslandSet* set, double target) {
  if (set->movingCount != 1 || set->islandCount != 1 || !set->islands[0]->asleep || s->stepObserver ||
      pd_sleep_force_changed(set->sleep, &model->bodies[model->movingBodies[0]], 0, s->t))
    return false;
  set->t0 = s->t;
  set->startsFormed = false;
  set->sleep->bodySeconds += target - set->t0;
  compose_set_counters(set, s);
  set->stagesBehind = true;
  s->t = target;
  return true;
}

// The lone body's island from the scene's time to tEnd (or to the sample where it falls asleep or the caller
// stops). False if it failed (the scene keeps its state at the last sample).
static bool lone_run(const pdModel* model, pdState* s, struct pdIslandSet* set, double tEnd, pdObserverFcn* observer,
                     void* user) {
  island* is = set->islands[0];
  PD_ASSERT(is->bodyCount == 1 && is->state->t == s->t);
  loneRun run = {.model = model, .s = s, .set = set, .is = is, .observer = observer, .user = user, .tEnd = tEnd,
                 .derivatives = is->state->count.derivatives};
  run.slack = pd_island_slack(model, &model->bodies[model->movingBodies[0]]);
  run.contactsAtEnd = pd_state_contact_count(s) > 0;
  run.probe = (travelProbe){is, s->t, set->cx0, set->cv0, set->cq0, set->ctravel, set->sleep};
  lone_near_thresholds(&run);
  set->subModels[0] = &is->model;
  set->subStates[0] = is->state;
  set->subMaps[0] = is->toScene;
  lone_interval_start(&run);
  // lone_sample untimed: it times the caller's observer into the scene's observe stage itself (observe())
  bool ok = pd_step_until(&is->model, is->state, tEnd, false, lone_sample, &run, false, lone_step_end, &run);
  if (ok && run.open) lone_interval_end(&run, tEnd);  // a call ending between samples: the scene gathered there
  compose_counters(set, s);
  return ok || !is->state->failed;
}

bool pd_islands_advance(const pdModel* model, pdState* s, double tEnd, pdObserverFcn* observer, void* user) {
  PD_ASSERT(model != NULL && s != NULL && tEnd >= s->t);
  if (s->failed) return false;
  s->stopped = false;
  PD_ASSERT(s->threads >= 1 && s->threads <= PD_THREADS_MAX);
  if (!s->islandSet) s->islandSet = set_create(model, s);
  struct pdIslandSet* set = s->islandSet;
  pd_pool_resize(&set->pool, s->threads);
  while (pd_sample_time(model, s->nextSample) < s->t) ++s->nextSample;
  if (pd_sample_time(model, s->nextSample) == s->t) observe(model, s, set, observer, user);
  while (s->t < tEnd && !s->stopped) {
    if (lone_runs(s, set)) {
      if (!lone_run(model, s, set, tEnd, observer, user)) {
        s->failed = true;
        return false;
      }
      continue;
    }
    double tSample = pd_sample_time(model, s->nextSample);
    double target = fmin(tEnd, tSample);
    if (lone_sleep_on(model, s, set, target)) {
      if (s->t == tSample) observe(model, s, set, observer, user);
      continue;
    }
    // the sync times: the interval to the sample cut into equal parts short enough for the fastest body
    double t0 = s->t;
    int parts = sync_parts(model, set, target - t0);
    if (set->movingCount > 0) {
      find_free(model, s, set, target - t0);
      // a lone moving body is one island over any part of the interval: nothing to split
      if (parts > 1 && (set->movingCount == 1 || !cuts_split_islands(model, s, set, (target - t0) / parts))) parts = 1;
    }
    for (int j = 1; j <= parts; ++j) {
      double tSync = j == parts ? target : t0 + (target - t0) * ((double)j / parts);
      bool ok = set->movingCount == 0 || advance_interval(model, s, set, tSync, j == parts);
      compose_counters(set, s);
      if (!ok) {
        s->failed = true;
        return false;
      }
      s->t = tSync;
    }
    if (s->t == tSample) observe(model, s, set, observer, user);
  }
  if (set->stagesBehind) compose_counters(set, s);
  return !s->stopped;
}
