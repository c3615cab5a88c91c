// polydyn — the islands' partition over a sync interval (island_partition.h; design note at the top of islands.c).
#include "island_partition.h"

#include <math.h>

#include "broad_phase.h"
#include "contact_set.h"
#include "grow.h"
#include "interference.h"
#include "state_layout.h"

// Slack of the travel bound, in the body's design deflections δ_max (deflection × size), plus a fraction of
// its size: what its velocity at T does not show (its springs' deflection as loads shift, a push from a
// neighbour inside its island, the integration's own error from the ballistic path). A body that moves
// farther makes its island redo the interval (the bound is then grown), so the slack only trades redos
// against islands joined for nothing: the tighter, the smaller the islands. On cases/bench/pile_1000.scene (0.5 s,
// with the separating-axis test), the run time relative to 0.25 δ_max + 0.001 size (largest island 65, 23 redos):
// 2 + 0.01 1.48× (222, no redo), 0.5 + 0.002 1.04× (84, 7 redos), 0.1 + 0 0.96× (48, 119 redos), 0 + 0 0.97× with
// 7414 free bodies straying (never recovered: see the note).
#define PD_ISLAND_SLACK_DEFLECTIONS 0.25
#define PD_ISLAND_SLACK_SIZE 0.001

static int find(int* root, int k) {
  while (root[k] != k) {
    root[k] = root[root[k]];
    k = root[k];
  }
  return k;
}

static void join(int* root, int a, int b) {
  a = find(root, a);
  b = find(root, b);
  if (a < b)
    root[b] = a;
  else if (b < a)
    root[a] = b;
}

static bool boxes_overlap(const pdAabb* a, const pdAabb* b) {
  for (int d = 0; d < 3; ++d)
    if (a->lo[d] > b->hi[d] || b->lo[d] > a->hi[d]) return false;
  return true;
}

double pd_island_slack(const pdModel* model, const pdBody* b) {
  return (PD_ISLAND_SLACK_DEFLECTIONS * model->settings.deflection + PD_ISLAND_SLACK_SIZE) * b->size;
}

double pd_island_travel_bound(const pdModel* model, const struct pdIslandSet* set, int k, const double* yb,
                              const pdMat3* r, const pdAabb* box, bool* touchingOut, double t, double dt) {
  const pdBody* b = &model->bodies[model->movingBodies[k]];
  bool touching = *touchingOut;
  double accel = 0.0;
  if (b->hasForce) accel = (pd_v3_norm(b->force0) + pd_v3_norm(b->forceRate) * (fabs(t) + dt)) * b->invMass;
  double slack = pd_island_slack(model, b);
  // the spin a torque-free body can reach keeps its rotational energy: |ω| <= √(2 E_rot / I_min)
  pdVec3 wb = pd_mat3_tmulv(r, pd_layout_w(yb));
  double twiceEnergy = pd_v3_dot(wb, pd_mat3_mulv(&b->inertia, wb));
  double spinMax = b->principal[0] > 0.0 ? sqrt(fmax(0.0, twiceEnergy) / b->principal[0]) : 0.0;
  double spin = fmax(pd_v3_norm(pd_layout_w(yb)), spinMax) * b->radius * dt;
  double bound = 0.5 * accel * dt * dt + spin + slack;
  double g = pd_v3_norm(model->settings.gravity), v = pd_v3_norm(pd_layout_v(yb));
  if (!touching) {
    // may it reach a fixed body? (its box grown by all it can move, gravity included)
    double reach = v * dt + 0.5 * (g + accel) * dt * dt + spin + slack;
    pdAabb grown = *box;
    for (int d = 0; d < 3; ++d) grown.lo[d] -= reach, grown.hi[d] += reach;
    for (int f = 0; f < set->fixedCount && !touching; ++f)
      touching = boxes_overlap(&grown, &set->boxes[set->fixedBodies[f]]);
  }
  if (touching) bound += 2.0 * v * dt + g * dt * dt;
  *touchingOut = touching;
  return bound;
}

// Whether the axis of `sat` keeps two bodies apart over dt: its gap wider than they can close along it.
static bool kept_apart(const pdSatResult* sat, pdVec3 relativeVelocity, double dt, double bounds) {
  return sat->separated && -sat->depth > fmax(0.0, pd_v3_dot(sat->axis, relativeVelocity)) * dt + bounds;
}

// Whether moving bodies a and b, whose grown boxes overlap, may meet over the interval dt: unless the separating
// axis test at T finds an axis u (from a to b) with a gap wider than all they can close along it. Each point of
// body k stays, in the frame that falls with gravity, within bound_k of where v0_k τ takes it (design note), so
// along u the gap shrinks by at most max(0, u·(v0_a − v0_b)) dt + bound_a + bound_b. Boxes of turned bodies
// overlap long before the bodies do: in a settling pile, the box test alone joins bodies lying side by side
// into islands of hundreds. The pair's separating feature from the last partition (cache) is tried first (the
// same bodies, moved a little since); only when its axis does not keep them apart are all axes searched for the
// widest gap. Either answer is safe, and the cache is a function of the pair's own past: still deterministic.
static bool may_meet(const struct pdIslandSet* set, const pdBody* a, const pdBody* b, double dt, pdSatCache* cache) {
  int ka = a->stateIndex, kb = b->stateIndex;
  const pdMat3 *ra = &set->r0[ka], *rb = &set->r0[kb];
  double bounds = set->bound[ka] + set->bound[kb];
  pdVec3 dv = pd_v3_sub(set->v0[ka], set->v0[kb]);
  pdSatResult sat;
  if (cache->kind != PD_SAT_NONE) {
    pd_interference(&a->shape, set->x0[ka], ra, &b->shape, set->x0[kb], rb, PD_SAT_FIRST_SEPARATING, cache, &sat);
    if (kept_apart(&sat, dv, dt, bounds)) return false;
  }
  pd_interference(&a->shape, set->x0[ka], ra, &b->shape, set->x0[kb], rb, PD_SAT_MIN_DEPTH, cache, &sat);
  return !kept_apart(&sat, dv, dt, bounds);
}

// Counting sort: items 0 .. n) grouped by group[i] (0 .. groups), ascending within each group, into
// out[first[j] .. first[j + 1]).
static void group_by(const int* group, int n, int groups, int* first, int* out) {
  for (int j = 0; j <= groups; ++j) first[j] = 0;
  for (int i = 0; i < n; ++i) ++first[group[i] + 1];
  for (int j = 0; j < groups; ++j) first[j + 1] += first[j];
  for (int i = 0; i < n; ++i) out[first[group[i]]++] = i;
  for (int j = groups; j > 0; --j) first[j] = first[j - 1];
  first[0] = 0;
}

// The bodies of each sleeping island stay one island: frozen, they move together (not at all), and a part of one
// woken alone would leave the rest frozen against moving bodies.
static void join_sleepers(struct pdIslandSet* set) {
  if (!set->sleep) return;
  for (int j = 0; j < set->islandCount; ++j) {
    const island* is = set->islands[j];
    if (!is || !is->asleep) continue;
    for (int m = 1; m < is->bodyCount; ++m) join(set->root, is->bodies[0], is->bodies[m]);
  }
}

int pd_island_partition(const pdModel* model, const pdState* s, struct pdIslandSet* set, double dt, bool fine) {
  int m = set->movingCount, activations = 0;
  for (int k = 0; k < m; ++k) {
    set->root[k] = k;
    if (fine && set->free[k]) {
      set->boxes[model->movingBodies[k]] = set->cbox[k];
      continue;
    }
    pdAabb box = set->box0[k];
    double sweep[3] = {set->v0[k].x * dt, set->v0[k].y * dt, set->v0[k].z * dt};
    for (int d = 0; d < 3; ++d) {
      box.lo[d] += fmin(0.0, sweep[d]) - set->bound[k];
      box.hi[d] += fmax(0.0, sweep[d]) + set->bound[k];
    }
    set->boxes[model->movingBodies[k]] = box;
  }
  // bodies in contact first: a pair already in one island needs no separation test
  int contacts = pd_state_contact_count(s);
  for (int c = 0; c < contacts; ++c) {
    int b1, b2;
    pd_contact_set_bodies(s->contacts, c, &b1, &b2);
    const pdBody *a = &model->bodies[b1], *b = &model->bodies[b2];
    if (!a->fixed && !b->fixed) join(set->root, a->stateIndex, b->stateIndex);
  }
  join_sleepers(set);
  // every moving body in one island by its contacts alone (a stack, a wall): every pair below would be skipped as
  // joined, with no free body to activate (a free body touches nothing), so the broad phase is not asked (its pairs
  // come sorted whatever its history: broad_phase.h)
  bool joined = true;
  for (int k = 1; k < m && joined; ++k) joined = find(set->root, k) == find(set->root, 0);
  int pairCount = 0;
  if (!joined) {
    int capacity = set->pairCapacity;
    pairCount = pd_broad_phase_pairs_grown(set->broad, set->boxes, &set->pairs, &set->pairCapacity);
    if (set->pairCapacity != capacity) {
      set->sat = pd_grow(set->sat, (size_t)set->pairCapacity, sizeof *set->sat);
      set->satNext = pd_grow(set->satNext, (size_t)set->pairCapacity, sizeof *set->satNext);
    }
  }
  int cached = 0, tested = 0;
  for (int p = 0; p < pairCount; ++p) {
    const pdBody *a = &model->bodies[set->pairs[p].a], *b = &model->bodies[set->pairs[p].b];
    if (a->fixed || b->fixed) continue;
    bool freeA = fine && set->free[a->stateIndex], freeB = fine && set->free[b->stateIndex];
    if (freeA && freeB) continue;  // their boxes over the sample interval overlap no other body's (coarse partition)
    if (freeA || freeB) {
      int k = freeA ? a->stateIndex : b->stateIndex;
      bool listed = false;
      for (int i = 0; i < activations && !listed; ++i) listed = set->activate[i] == k;
      if (!listed) set->activate[activations++] = k;
      continue;
    }
    if (find(set->root, a->stateIndex) == find(set->root, b->stateIndex)) continue;
    int ia = set->pairs[p].a, ib = set->pairs[p].b;
    pdPairSatCache* entry = &set->satNext[tested++];
    *entry = (pdPairSatCache){ia, ib, pd_pair_sat_cache_find(set->sat, set->satCount, &cached, ia, ib)};
    if (may_meet(set, a, b, dt, &entry->sat)) join(set->root, a->stateIndex, b->stateIndex);
  }
  pdPairSatCache* t = set->sat;
  set->sat = set->satNext;
  set->satNext = t;
  set->satCount = tested;
  if (activations > 0) return activations;
  if (contacts > set->contactCapacity) {
    set->contactCapacity = 2 * contacts;
    set->contactOf = pd_grow(set->contactOf, (size_t)set->contactCapacity, sizeof *set->contactOf);
    set->contacts = pd_grow(set->contacts, (size_t)set->contactCapacity, sizeof *set->contacts);
  }
  if (joined && m > 0) {
    // one island of every moving body (a lone body, a stack): what the counting sorts below would give, written out
    set->partCount = 1;
    for (int k = 0; k < m; ++k) set->islandOf[k] = 0, set->members[k] = k;
    set->first[0] = 0, set->first[1] = m;
    for (int c = 0; c < contacts; ++c) set->contactOf[c] = 0, set->contacts[c] = c;
    set->contactFirst[0] = 0, set->contactFirst[1] = contacts;
    return 0;
  }
  // islands named by their lowest body, in that order; members grouped by a counting sort
  set->partCount = 0;
  for (int k = 0; k < m; ++k) {
    int r = find(set->root, k);
    set->islandOf[k] = r == k ? set->partCount++ : set->islandOf[r];
  }
  group_by(set->islandOf, m, set->partCount, set->first, set->members);
  for (int c = 0; c < contacts; ++c) {
    int b1, b2;
    pd_contact_set_bodies(s->contacts, c, &b1, &b2);
    int moving = model->bodies[b1].fixed ? b2 : b1;
    set->contactOf[c] = set->islandOf[model->bodies[moving].stateIndex];
  }
  group_by(set->contactOf, contacts, set->partCount, set->contactFirst, set->contacts);
  return 0;
}
