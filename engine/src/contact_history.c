// polydyn — tangential history kept through micro-separations (contact_history.h, design note there).
#include "contact_history.h"

#include <float.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "model_contact.h"

typedef struct trace {
  pdContactId id;
  pdSprings springs;
  pdVec3 normal;
  double deltaMax;  // m
  bool taken;
  double fn;  // N: a hand-over trace's normal force when its contact broke
  int age;    // commits a hand-over trace has been kept
  double loadScale;  // the springs' factor over eq. (11)'s (contactSlot.loadScale)
} trace;

// A growable list of traces.
typedef struct traceList {
  trace* items;
  int count, capacity;
} traceList;

struct pdContactHistory {
  trace* items;  // [0, sortedCount) sorted by id (pd_contact_id_compare); then those left since the last age
  trace* scratch;  // as many as items: the merge of those left into the sorted run (pd_history_age)
  int count, capacity, sortedCount;
  traceList handovers;  // contacts broken geometrically with no successor yet (pd_history_leave_handover)
};

pdContactHistory* pd_history_create(void) {
  pdContactHistory* h = calloc(1, sizeof *h);
  PD_ASSERT(h != NULL);
  return h;
}

void pd_history_free(pdContactHistory* h) {
  if (!h) return;
  free(h->items);
  free(h->scratch);
  free(h->handovers.items);
  free(h);
}

void pd_history_clear(pdContactHistory* h) { h->count = h->sortedCount = h->handovers.count = 0; }

int pd_history_count(const pdContactHistory* h) { return h->count; }

void pd_history_leave(pdContactHistory* h, const pdContactId* id, const pdSprings* springs, pdVec3 normal,
                      double deltaMax, double loadScale) {
  if (h->count == h->capacity) {
    h->capacity = h->capacity ? 2 * h->capacity : 16;
    h->items = pd_grow(h->items, (size_t)h->capacity, sizeof *h->items);
    h->scratch = pd_grow(h->scratch, (size_t)h->capacity, sizeof *h->scratch);
  }
  h->items[h->count++] = (trace){*id, *springs, normal, deltaMax, false, 0.0, 0, loadScale};
}

void pd_history_leave_handover(pdContactHistory* h, const pdContactId* id, const pdSprings* springs, pdVec3 normal,
                               double fn, double loadScale) {
  traceList* l = &h->handovers;
  if (l->count == l->capacity) {
    l->capacity = l->capacity ? 2 * l->capacity : 16;
    l->items = pd_grow(l->items, (size_t)l->capacity, sizeof *l->items);
  }
  l->items[l->count++] = (trace){*id, *springs, normal, 0.0, false, fn, 0, loadScale};
}

// The springs of `p` (eq. (11)'s, factor 1) at a trace's factor: its deflections were kept at that stiffness, and at
// eq. (11)'s they would give back that force divided by it.
static void at_trace_scale(const trace* t, pdContactParams* p) {
  double f = t->loadScale;
  p->k1n *= f, p->k2n *= f, p->k1t *= f, p->k2t *= f;
}

bool pd_history_take_handover(const pdModel* model, pdContactHistory* h, const pdContactId* id, pdVec3 normal,
                              pdContactParams* params, double* loadScale, pdSprings* springs) {
  traceList* l = &h->handovers;
  for (int i = 0; i < l->count; ++i) {
    trace* t = &l->items[i];
    if (t->taken || !pd_contact_continues(model, &t->id, id)) continue;
    PD_ASSERT(*loadScale == 1.0);
    at_trace_scale(t, params);
    *loadScale = t->loadScale;
    // as a hand-over within one commit (contact_set.c): the springs turned into the new tangent plane and held within
    // the cone of the predecessor's normal force
    *springs = t->springs;
    pd_springs_realign(springs, t->normal, normal, params->mu, params, t->fn);
    pd_springs_clip_to_cone(springs, params, params->mu * fmax(t->fn, 0.0));
    t->taken = true;
    return true;
  }
  return false;
}

// The energy of the springs a trace will give back: a trace left by force returns its tangential springs only
// (pd_history_take), a hand-over trace all of them as its successor takes them (pd_history_take_handover: realigned,
// which clamps the normal springs out of tension, and held within the cone). A contact that broke with its springs
// stretched in tension (its force pulling at the step's end: the paper's contact ended where its force reached zero)
// gives a successor none of that tension, and the state's energy must not count it: it rose by the tension's energy
// at the commit and fell back when the trace expired (soak campaign 48, scene 1728: 5.1e-3 of E(0)).
static double trace_energy(const pdModel* model, const trace* t, bool normalReturns) {
  pdContactParams p = pd_model_contact_params(model, t->id.body1, t->id.body2);
  at_trace_scale(t, &p);
  pdSprings s = t->springs;
  if (!normalReturns) {
    s.s1n = s.s2n = 0.0;
  } else {
    pd_springs_realign(&s, t->normal, t->normal, p.mu, &p, t->fn);
    pd_springs_clip_to_cone(&s, &p, p.mu * fmax(t->fn, 0.0));
  }
  return pd_springs_energy(&p, &s);
}

double pd_history_spring_energy(const pdModel* model, const pdContactHistory* h) {
  double e = 0.0;
  for (int i = 0; i < h->count; ++i)
    if (!h->items[i].taken) e += trace_energy(model, &h->items[i], false);
  for (int i = 0; i < h->handovers.count; ++i)
    if (!h->handovers.items[i].taken) e += trace_energy(model, &h->handovers.items[i], true);
  return e;
}

static int compare_traces(const trace* a, const trace* b) { return pd_contact_id_compare(&a->id, &b->id); }

// Merges the sorted runs a[0, na) and b[0, nb) into out[0, na + nb) (out overlaps neither).
static void merge_traces(const trace* a, int na, const trace* b, int nb, trace* out) {
  int i = 0, j = 0, k = 0;
  while (i < na && j < nb) out[k++] = compare_traces(&b[j], &a[i]) < 0 ? b[j++] : a[i++];
  while (i < na) out[k++] = a[i++];
  while (j < nb) out[k++] = b[j++];
}

// Sorts t[0, n) by id through scratch[0, n): a bottom-up merge sort, which allocates nothing (qsort may) and, the ids
// being unique among traces, gives the one order there is.
static void sort_traces(trace* t, int n, trace* scratch) {
  trace *from = t, *to = scratch;
  for (int width = 1; width < n; width *= 2) {
    for (int lo = 0; lo < n; lo += 2 * width) {
      int mid = lo + width < n ? lo + width : n, hi = lo + 2 * width < n ? lo + 2 * width : n;
      merge_traces(from + lo, mid - lo, from + mid, hi - mid, to + lo);
    }
    trace* swap = from;
    from = to;
    to = swap;
  }
  if (from != t) memcpy(t, from, (size_t)n * sizeof *t);
}

void pd_history_age(const pdModel* model, pdContactHistory* h, const pdPose* poses) {
  // the kept traces keep their order: those of the sorted run first (still sorted), then those left since
  int kept = 0, keptSorted = 0;
  for (int i = 0; i < h->count; ++i) {
    trace* t = &h->items[i];
    if (t->taken) continue;
    pdContactGeom g;
    if (!pd_contact_track(model, &t->id, &poses[t->id.body1], &poses[t->id.body2], &g)) continue;
    if (-g.depth > PD_HISTORY_GAP_REL * t->deltaMax) continue;
    h->items[kept++] = *t;
    if (i < h->sortedCount) keptSorted = kept;
  }
  // hand-over traces wait a few commits for their successor (it is often found a step or two after its predecessor
  // broke), then go
  int waiting = 0;
  for (int i = 0; i < h->handovers.count; ++i) {
    trace* t = &h->handovers.items[i];
    if (t->taken || ++t->age > PD_HANDOVER_COMMITS) continue;
    h->handovers.items[waiting++] = *t;
  }
  h->handovers.count = waiting;
  // the new ones sorted, then merged into the sorted run (ids are unique among traces: a contact breaks only while
  // listed, and a listed contact has no trace left), whatever their number: pd_history_take's binary search and
  // pd_history_vertex_trace's read the whole run
  int added = kept - keptSorted;
  if (added > 0) {
    trace* run = h->items + keptSorted;
    sort_traces(run, added, h->scratch);
    if (keptSorted > 0 && compare_traces(&h->items[keptSorted - 1], &run[0]) > 0) {
      // from the back, the new ones (few) set aside: each write lands past the sorted run's unread part
      memcpy(h->scratch, run, (size_t)added * sizeof *run);
      int i = keptSorted - 1, j = added - 1, k = kept - 1;
      while (j >= 0)
        h->items[k--] = i >= 0 && compare_traces(&h->items[i], &h->scratch[j]) > 0 ? h->items[i--] : h->scratch[j--];
    }
  }
  h->count = h->sortedCount = kept;
}

// The first trace of the sorted run whose id is not before *id (sortedCount when none).
static int lower_bound(const pdContactHistory* h, const pdContactId* id) {
  int lo = 0, hi = h->sortedCount;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (pd_contact_id_compare(&h->items[mid].id, id) < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

bool pd_history_take(pdContactHistory* h, const pdContactId* id, pdVec3 normal, pdContactParams* params,
                     double* loadScale, pdSprings* springs) {
  // a trace left since the last age broke from a contact of this very list, which a new contact is not
  if (h->sortedCount == 0) return false;
  int i = lower_bound(h, id);
  if (i == h->sortedCount || pd_contact_id_compare(&h->items[i].id, id) != 0) return false;
  trace* t = &h->items[i];
  if (t->taken) return false;
  PD_ASSERT(*loadScale == 1.0);
  at_trace_scale(t, params);
  *loadScale = t->loadScale;
  pdSprings s = t->springs;
  s.s1n = s.s2n = 0.0;  // the normal springs start where the contact does
  // turned to the new normal (and rebalanced where the sides are proportional), not clipped to a cone: the contact
  // has no normal force yet, and the force law keeps its friction within the cone as the normal force grows
  pd_springs_realign(&s, t->normal, normal, params->mu, params, DBL_MAX);
  springs->s1t = s.s1t;
  springs->s2t = s.s2t;
  t->taken = true;
  return true;
}

double pd_history_load_scale(const pdContactHistory* h, const pdContactId* id) {
  int i = lower_bound(h, id);
  if (i == h->sortedCount || pd_contact_id_compare(&h->items[i].id, id) != 0 || h->items[i].taken) return 1.0;
  return h->items[i].loadScale;
}

bool pd_history_vertex_trace(const pdContactHistory* h, int vertexBody, int vertex, int faceBody, int face,
                             pdContactId* id) {
  // the traces of this vertex on faceBody's faces follow one another in the sorted run, by face
  // (pd_contact_id_compare orders by body pair, kind, body1, feat1, then feat2)
  pdContactId first = {vertexBody, faceBody, pd_contactVF, vertex, INT_MIN};
  for (int i = lower_bound(h, &first); i < h->sortedCount; ++i) {
    const trace* t = &h->items[i];
    if (t->id.kind != pd_contactVF || t->id.body1 != vertexBody || t->id.body2 != faceBody || t->id.feat1 != vertex)
      break;
    if (t->taken || t->id.feat2 == face) continue;
    *id = t->id;
    return true;
  }
  return false;
}
