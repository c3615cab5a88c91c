// polydyn — the contact model's material parameters in a compiled model (paper §3.2, §3.3; DESIGN §3.4).
//
// material.c holds the rules (eq. (11) stiffness, restitution → damping, the fixed-body rule, exact
// minimum effective mass, the §3.3.1 and §3.3.2 adjustments). This file applies them to a scene:
// - every body gets its per-body constants (body->used) through pd_material_bodies;
// - bodies whose pdMaterialUsed is bit-identical form a material class (found by hashing, O(bodies));
//   a contact's constants depend only on the classes of its two bodies, so pair constants and the
//   §3.3.2 checks are done per pair of classes, never per pair of bodies;
// - every adjustment is kept as data and described on request (check output, summary.json).
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "material.h"
#include "model_contact.h"

#define PI 3.14159265358979323846

// Pair constants are tabulated (both orientations) when there are at most this many classes: 128² entries
// of 72 bytes is 1.2 MB, small enough to stay in cache for the lookups inside the step. Scenes with more
// distinct materials (random benchmark scenes give every body its own class) compute a pair's constants
// on the fly with the same function, so both paths give the same bits.
#define PD_MATERIAL_DENSE_CLASSES 128

// At most this many adjustments are listed (check output, summary.json); the rest are counted. Identical
// §3.3.1 adjustments of many bodies are already merged into one line, so reaching it takes a scene with
// that many distinct adjusted materials.
#define PD_MODEL_ADJUSTMENTS_MAX 1000

// memcmp on pdMaterialUsed is only a bit comparison if the struct has no padding.
_Static_assert(sizeof(pdMaterialUsed) == 8 * sizeof(double), "pdMaterialUsed must be 8 doubles, no padding");

typedef struct listedAdjustment {
  pdAdjustment a;
  int alike;  // §3.3.1: further bodies with the identical adjustment (not listed separately)
} listedAdjustment;

struct pdMaterialTable {
  int bodyCount;
  pdBodyContactInfo* info;  // (bodyCount)
  int* classOf;             // (bodyCount) material class of each body
  int classCount;
  pdMaterialUsed* classUsed;  // (classCount)
  int* classFirst;            // (classCount) first body of each class, scene order
  int* classSize;             // (classCount) bodies in each class
  bool* classMoving;          // (classCount) the class holds a moving body
  pdContactParams* pairs;     // (classCount²) [a * classCount + b]: class a on side 1; NULL when not tabulated
  double dtmin;               // s, of the §3.3.2 checks
  double periodMin;           // s, pd_model_contact_period_min
  listedAdjustment* adj;      // (adjCount)
  int adjCount;
  int adjDropped;
};

void pd_material_table_free(struct pdMaterialTable* t) {
  if (!t) return;
  free(t->info);
  free(t->classOf);
  free(t->classUsed);
  free(t->classFirst);
  free(t->classSize);
  free(t->classMoving);
  free(t->pairs);
  free(t->adj);
  free(t);
}

static void* alloc_array(size_t count, size_t size) {
  void* p = calloc(count > 0 ? count : 1, size);
  PD_ASSERT(p != NULL);
  return p;
}

// ---------------------------------------------------------------- material classes

static uint64_t hash_used(const pdMaterialUsed* u) {
  // FNV-1a over the bytes: classes are defined by bit identity
  const unsigned char* p = (const unsigned char*)u;
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < sizeof *u; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// Classes numbered in order of their first body, so the numbering is a function of the scene.
static void group_classes(struct pdMaterialTable* t, const pdMaterialUsed* used, const pdModel* m) {
  size_t slots = 16;
  while (slots < 2 * (size_t)t->bodyCount) slots *= 2;
  int* slot = alloc_array(slots, sizeof *slot);  // class + 1, 0 = empty
  t->classOf = alloc_array((size_t)t->bodyCount, sizeof *t->classOf);
  t->classUsed = alloc_array((size_t)t->bodyCount, sizeof *t->classUsed);
  t->classFirst = alloc_array((size_t)t->bodyCount, sizeof *t->classFirst);
  t->classSize = alloc_array((size_t)t->bodyCount, sizeof *t->classSize);
  t->classMoving = alloc_array((size_t)t->bodyCount, sizeof *t->classMoving);
  for (int i = 0; i < t->bodyCount; ++i) {
    size_t s = (size_t)hash_used(&used[i]) & (slots - 1);
    while (slot[s] != 0 && memcmp(&t->classUsed[slot[s] - 1], &used[i], sizeof used[i]) != 0) s = (s + 1) & (slots - 1);
    if (slot[s] == 0) {
      int c = t->classCount++;
      slot[s] = c + 1;
      t->classUsed[c] = used[i];
      t->classFirst[c] = i;
    }
    int c = slot[s] - 1;
    t->classOf[i] = c;
    t->classSize[c]++;
    if (!m->bodies[i].fixed) t->classMoving[c] = true;
  }
  free(slot);
}

// A pair of classes can touch when some body of one can meet some other body of the other with at
// least one of the two moving (fixed bodies never meet: DESIGN §3.6).
static bool classes_can_touch(const struct pdMaterialTable* t, int a, int b) {
  if (a == b) return t->classMoving[a] && t->classSize[a] >= 2;
  return t->classMoving[a] || t->classMoving[b];
}

// The constants of a contact between classes a (side 1) and b (side 2), computed with the lower class
// on side 1 so that the tabulated and the on-the-fly paths, and both orientations, agree to the bit.
static pdContactParams class_pair(const struct pdMaterialTable* t, int a, int b) {
  int lo = a < b ? a : b, hi = a < b ? b : a;
  pdContactParams p;
  pd_contact_params_pair(&t->classUsed[lo], &t->classUsed[hi], -1, -1, t->dtmin, &p, NULL);
  return a <= b ? p : pd_contact_params_swapped(&p);
}

// ---------------------------------------------------------------- adjustments

static void list_adjustment(struct pdMaterialTable* t, const pdAdjustment* a, int alike) {
  if (t->adjCount >= PD_MODEL_ADJUSTMENTS_MAX) {
    t->adjDropped += 1 + alike;
    return;
  }
  t->adj[t->adjCount++] = (listedAdjustment){*a, alike};
}

static int compare_doubles(double x, double y) { return (x > y) - (x < y); }

static bool same_content(const pdAdjustment* x, const pdAdjustment* y) {
  return x->rule == y->rule && x->param == y->param && x->from == y->from && x->to == y->to &&
         x->tau == y->tau && x->dtmin == y->dtmin;
}

typedef struct indexedRecord {
  pdAdjustment a;
  int index;  // position in the raw list (body order)
} indexedRecord;

// By content, then by position: the first of a run of identical records is the earliest body's.
static int compare_records(const void* pa, const void* pb) {
  const indexedRecord *x = pa, *y = pb;
  int c = (x->a.rule > y->a.rule) - (x->a.rule < y->a.rule);
  if (!c) c = (x->a.param > y->a.param) - (x->a.param < y->a.param);
  if (!c) c = compare_doubles(x->a.from, y->a.from);
  if (!c) c = compare_doubles(x->a.to, y->a.to);
  if (!c) c = compare_doubles(x->a.tau, y->a.tau);
  if (!c) c = compare_doubles(x->a.dtmin, y->a.dtmin);
  return c ? c : (x->index > y->index) - (x->index < y->index);
}

// §3.3.1 records in body order, identical ones merged into the first (1000 identical cubes adjusted
// alike give one line, not 1000).
static void list_body_adjustments(struct pdMaterialTable* t, const pdAdjustmentList* raw) {
  int n = raw->count;
  indexedRecord* sorted = alloc_array((size_t)n, sizeof *sorted);
  int* alike = alloc_array((size_t)n, sizeof *alike);
  for (int i = 0; i < n; ++i) sorted[i] = (indexedRecord){raw->items[i], i}, alike[i] = -1;
  qsort(sorted, (size_t)n, sizeof *sorted, compare_records);
  for (int i = 0; i < n;) {
    int j = i + 1;
    while (j < n && same_content(&sorted[i].a, &sorted[j].a)) ++j;
    alike[sorted[i].index] = j - i - 1;
    i = j;
  }
  for (int i = 0; i < n; ++i)
    if (alike[i] >= 0) list_adjustment(t, &raw->items[i], alike[i]);
  free(sorted);
  free(alike);
}

static void list_pair(struct pdMaterialTable* t, int a, int b) {
  if (!classes_can_touch(t, a, b)) return;
  pdAdjustment items[4];
  pdAdjustmentList local = {.items = items, .capacity = 4};
  pdContactParams p;
  pd_contact_params_pair(&t->classUsed[a], &t->classUsed[b], t->classFirst[a], t->classFirst[b], t->dtmin, &p,
                         &local);
  PD_ASSERT(local.dropped == 0);
  for (int r = 0; r < local.count; ++r) {
    // within one class both sides' records are the same change: list it once
    if (a == b && r > 0 && same_content(&items[r], &items[r - 1])) continue;
    list_adjustment(t, &items[r], 0);
  }
}

// §3.3.2 can change a pair only if (c_a + c_b) < dtmin (k_a + k_b) along n or in P_t. With
// s = c − dtmin (1 + PD_PAIR_SCREEN_REL) k per class and direction, a class whose s plus the smallest s
// of all classes is >= 0 in both directions has no pair that the check could change: it is screened out,
// and only pairs of two remaining classes (one of them damped) are visited. The relative margin makes the
// screen safe against roundoff: near a tie every term is at most ~dtmin (k_a + k_b), so rounding moves
// the sums by ~1e-16 of that, far below the 1e-9 margin. Typical scenes (dtmin far below every contact
// time constant) screen out every damped class: O(classes), not O(classes²).
#define PD_PAIR_SCREEN_REL 1e-9

static double screen_value(double c, double k, double dtmin) { return c - dtmin * (1.0 + PD_PAIR_SCREEN_REL) * k; }

// §3.3.2 for every pair of classes that can touch and that the check could change, in (a, b) order, a <= b.
static void list_pair_adjustments(struct pdMaterialTable* t) {
  int n = t->classCount;
  double minN = INFINITY, minT = INFINITY;
  for (int c = 0; c < n; ++c) {
    const pdMaterialUsed* u = &t->classUsed[c];
    minN = fmin(minN, screen_value(u->cn, u->kn, t->dtmin));
    minT = fmin(minT, screen_value(u->ct, u->kt, t->dtmin));
  }
  bool* candidate = alloc_array((size_t)n, sizeof *candidate);
  int* dampedCandidates = alloc_array((size_t)n, sizeof *dampedCandidates);  // ascending
  int dampedCount = 0;
  for (int c = 0; c < n; ++c) {
    const pdMaterialUsed* u = &t->classUsed[c];
    candidate[c] = screen_value(u->cn, u->kn, t->dtmin) + minN < 0.0 ||
                   screen_value(u->ct, u->kt, t->dtmin) + minT < 0.0;
    if (candidate[c] && (u->cn > 0.0 || u->ct > 0.0)) dampedCandidates[dampedCount++] = c;
  }
  // a pair is checked only when c_a + c_b > 0: one of its classes is damped
  for (int a = 0, first = 0; a < n; ++a) {
    if (!candidate[a]) continue;
    while (first < dampedCount && dampedCandidates[first] < a) ++first;  // dampedCandidates[first ..] >= a
    if (first < dampedCount && dampedCandidates[first] == a) {
      for (int b = a; b < n; ++b)
        if (candidate[b]) list_pair(t, a, b);
    } else {
      for (int j = first; j < dampedCount; ++j) list_pair(t, a, dampedCandidates[j]);
    }
  }
  free(candidate);
  free(dampedCandidates);
}

// ---------------------------------------------------------------- shortest contact period

typedef struct classKey {
  double mMin;
  int c;
} classKey;

static int compare_keys(const void* pa, const void* pb) {
  const classKey *x = pa, *y = pb;
  int c = compare_doubles(x->mMin, y->mMin);
  return c ? c : (x->c > y->c) - (x->c < y->c);
}

// min over pairs that can touch of min(mMin_a, mMin_b) (1/k_a + 1/k_b) = mMinPair/kSeries, in
// O(classes log classes): with classes sorted by mMin, a pair's smaller mMin is its earlier class's, and
// for a given earlier class the best partner is the later class of largest k (among moving classes when
// the earlier class is fixed only). Pairs with a k = 0 side carry no spring: skipped.
static double period_sq_min(const struct pdMaterialTable* t, bool tangential) {
  int n = t->classCount;
  classKey* keys = alloc_array((size_t)n, sizeof *keys);
  double* sufAll = alloc_array((size_t)n + 1, sizeof *sufAll);
  double* sufMoving = alloc_array((size_t)n + 1, sizeof *sufMoving);
  int count = 0;
  for (int c = 0; c < n; ++c) {
    double k = tangential ? t->classUsed[c].kt : t->classUsed[c].kn;
    if (k > 0.0) keys[count++] = (classKey){t->classUsed[c].mMin, c};
  }
  qsort(keys, (size_t)count, sizeof *keys, compare_keys);
  sufAll[count] = sufMoving[count] = 0.0;
  for (int i = count - 1; i >= 0; --i) {
    int c = keys[i].c;
    double k = tangential ? t->classUsed[c].kt : t->classUsed[c].kn;
    sufAll[i] = fmax(sufAll[i + 1], k);
    sufMoving[i] = t->classMoving[c] ? fmax(sufMoving[i + 1], k) : sufMoving[i + 1];
  }
  double best = INFINITY;
  for (int i = 0; i < count; ++i) {
    int c = keys[i].c;
    double k = tangential ? t->classUsed[c].kt : t->classUsed[c].kn, m = keys[i].mMin;
    double partner = t->classMoving[c] ? sufAll[i + 1] : sufMoving[i + 1];
    if (partner > 0.0) best = fmin(best, m * (1.0 / k + 1.0 / partner));
    if (classes_can_touch(t, c, c)) best = fmin(best, m * (2.0 / k));
  }
  free(keys);
  free(sufAll);
  free(sufMoving);
  return best;
}

// ---------------------------------------------------------------- compile

// Below e⁻² no positive stiffness reproduces the restitution (ζ → 1 in eq. (15)): the scene is refused,
// not silently clamped. The parser accepts [0, 1]; this is the contact model's own limit.
static bool check_restitutions(const pdScene* scene, pdError* err) {
  for (int i = 0; i < scene->objectCount; ++i) {
    const pdSceneObject* o = &scene->objects[i];
    if ((o->setMask & PD_SET_RESTITUTION) && o->restitution < PD_RESTITUTION_MIN) {
      // scene.h keeps no per-property location: the object's line it is
      pd_error_set(err, scene->path, o->where.line, o->where.col,
                   "object '%s': restitution %.10g is below e^-2 = %.10g, the smallest the contact model can "
                   "reach (paper §3.2.2, eq. 15: critical damping)",
                   o->name, o->restitution, PD_RESTITUTION_MIN);
      return false;
    }
  }
  return true;
}

bool pd_model_build_materials(pdModel* m, const pdScene* scene, pdError* err) {
  PD_ASSERT(m->materials == NULL && scene->objectCount == m->bodyCount);
  if (!check_restitutions(scene, err)) return false;
  const int n = m->bodyCount;
  pdMaterialBody* bodies = alloc_array((size_t)n, sizeof *bodies);
  pdMaterialRequest* reqs = alloc_array((size_t)n, sizeof *reqs);
  pdMaterialUsed* used = alloc_array((size_t)n, sizeof *used);
  const unsigned requestBits = PD_SET_KN | PD_SET_KT | PD_SET_CN | PD_SET_CT | PD_SET_RESTITUTION;
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &m->bodies[i];
    const pdSceneObject* o = &scene->objects[i];
    bodies[i] = (pdMaterialBody){
        .index = i,
        .fixed = b->fixed,
        .mass = b->mass,
        .mMin = pd_min_effective_mass(b->mass, &b->inertia, b->shape.vertices, b->shape.vertexCount),
        .size = b->size,
    };
    reqs[i] = (pdMaterialRequest){.mu = o->mu, .kn = o->kn, .kt = o->kt, .cn = o->cn, .ct = o->ct,
                                  .restitution = o->restitution, .setMask = o->setMask & requestBits};
  }
  const pdMaterialSettings settings = {.vmax = m->settings.vmax, .deflection = m->settings.deflection,
                                       .dtmin = m->settings.dtmin, .ctRule = pd_ctFromRestitution};
  // §3.3.1 changes at most kn, kt, cn and ct of each body: 4 records per body always fit
  pdAdjustmentList raw = {.items = alloc_array(4 * (size_t)n, sizeof(pdAdjustment)), .capacity = 4 * n};
  int failed = -1;
  char why[PD_ERROR_MESSAGE_MAX] = "";
  bool ok = pd_material_bodies(bodies, reqs, n, &settings, used, &raw, &failed, why, sizeof why);
  if (!ok) {
    const pdSceneObject* o = &scene->objects[failed >= 0 && failed < n ? failed : 0];
    pd_error_set(err, scene->path, o->where.line, o->where.col, "object '%s': %s", o->name, why);
  } else {
    PD_ASSERT(raw.dropped == 0);
    struct pdMaterialTable* t = calloc(1, sizeof *t);
    PD_ASSERT(t != NULL);
    m->materials = t;
    t->bodyCount = n;
    t->dtmin = settings.dtmin;
    t->info = alloc_array((size_t)n, sizeof *t->info);
    for (int i = 0; i < n; ++i) {
      const pdMaterialUsed* u = &used[i];
      pdBody* b = &m->bodies[i];
      b->used = (pdMaterial){.mu = u->mu, .kn = u->kn, .kt = u->kt, .cn = u->cn, .ct = u->ct,
                             .restitution = b->requested.restitution};
      t->info[i] = (pdBodyContactInfo){
          .mass = u->mass,
          .mMin = u->mMin,
          .zeta = u->zeta,
          .tauKn = 2.0 * PI * sqrt(u->mMin / u->kn),
          .tauKt = 2.0 * PI * sqrt(u->mMin / u->kt),
          .tauCn = u->cn > 0.0 ? 2.0 * u->mMin / u->cn : INFINITY,
          .tauCt = u->ct > 0.0 ? 2.0 * u->mMin / u->ct : INFINITY,
      };
    }
    group_classes(t, used, m);
    t->adj = alloc_array(PD_MODEL_ADJUSTMENTS_MAX, sizeof *t->adj);
    list_body_adjustments(t, &raw);
    list_pair_adjustments(t);
    if (t->classCount <= PD_MATERIAL_DENSE_CLASSES) {
      size_t c = (size_t)t->classCount;
      t->pairs = alloc_array(c * c, sizeof *t->pairs);
      for (int a = 0; a < t->classCount; ++a)
        for (int b = a; b < t->classCount; ++b) {
          pdContactParams p = class_pair(t, a, b);
          t->pairs[(size_t)a * c + (size_t)b] = p;
          t->pairs[(size_t)b * c + (size_t)a] = pd_contact_params_swapped(&p);
        }
    }
    t->periodMin = 2.0 * PI * sqrt(fmin(period_sq_min(t, false), period_sq_min(t, true)));
  }
  free(raw.items);
  free(bodies);
  free(reqs);
  free(used);
  return ok;
}

// ---------------------------------------------------------------- queries

pdContactParams pd_model_contact_params(const pdModel* model, int body1, int body2) {
  const struct pdMaterialTable* t = model->materials;
  PD_ASSERT(t != NULL && body1 >= 0 && body1 < t->bodyCount && body2 >= 0 && body2 < t->bodyCount &&
            body1 != body2);
  PD_ASSERT(!(model->bodies[body1].fixed && model->bodies[body2].fixed));
  int a = t->classOf[body1], b = t->classOf[body2];
  if (t->pairs) return t->pairs[(size_t)a * (size_t)t->classCount + (size_t)b];
  return class_pair(t, a, b);
}

// The tangential part uses each class's k_t before the §3.3.2 pair scaling, which only ever lowers k_t
// (lengthens a period): the value is exact for the normal springs and never above the true minimum.
double pd_model_contact_period_min(const pdModel* model) {
  PD_ASSERT(model->materials != NULL);
  return model->materials->periodMin;
}

pdBodyContactInfo pd_model_body_contact_info(const pdModel* model, int body) {
  PD_ASSERT(model->materials != NULL && body >= 0 && body < model->materials->bodyCount);
  return model->materials->info[body];
}

int pd_model_material_class_count(const pdModel* model) {
  PD_ASSERT(model->materials != NULL);
  return model->materials->classCount;
}

int pd_model_adjustment_count(const pdModel* model) {
  PD_ASSERT(model->materials != NULL);
  return model->materials->adjCount;
}

int pd_model_adjustments_dropped(const pdModel* model) {
  PD_ASSERT(model->materials != NULL);
  return model->materials->adjDropped;
}

int pd_model_adjustment_describe(const pdModel* model, int i, char* buf, int size) {
  const struct pdMaterialTable* t = model->materials;
  PD_ASSERT(t != NULL && i >= 0 && i < t->adjCount && (buf != NULL || size == 0) && size >= 0);
  const listedAdjustment* l = &t->adj[i];
  const pdAdjustment* a = &l->a;
  const char* partner = a->partner >= 0 ? model->bodies[a->partner].name : NULL;
  int len = pd_adjustment_describe(a, model->bodies[a->body].name, partner, buf, size);
  if (len < 0) return len;
  // what else the line stands for: identical §3.3.1 changes of other bodies; every body of each class
  char more[200] = "";
  if (a->partner < 0) {
    if (l->alike > 0)
      snprintf(more, sizeof more, " (and %d more bod%s adjusted alike)", l->alike, l->alike == 1 ? "y" : "ies");
  } else {
    int ca = t->classOf[a->body], cb = t->classOf[a->partner];
    if (ca == cb && t->classSize[ca] > 1)
      snprintf(more, sizeof more, " (every contact among the %d bodies of %s's material)", t->classSize[ca],
               model->bodies[a->body].name);
    else if (ca != cb && (t->classSize[ca] > 1 || t->classSize[cb] > 1))
      snprintf(more, sizeof more, " (every contact between the %d bod%s of %s's material and the %d of %s's)",
               t->classSize[ca], t->classSize[ca] == 1 ? "y" : "ies", model->bodies[a->body].name,
               t->classSize[cb], partner);
  }
  int done = len < size ? len : (size > 0 ? size - 1 : 0);
  int extra = snprintf(buf ? buf + done : NULL, (size_t)(size - done), "%s", more);
  return len + extra;
}

static double series(double a, double b) { return (a > 0.0 && b > 0.0) ? a * b / (a + b) : 0.0; }

pdPairContact pd_model_pair_contact(const pdModel* model, int a, int b) {
  pdContactParams p = pd_model_contact_params(model, a, b);
  pdPairContact pair = {.mu = p.mu,
                        .kn = series(p.k1n, p.k2n),
                        .kt = series(p.k1t, p.k2t),
                        .cn = series(p.c1n, p.c2n),
                        .ct = series(p.c1t, p.c2t)};
  double ea = model->bodies[a].requested.restitution, eb = model->bodies[b].requested.restitution;
  if (ea >= 0.0 && eb >= 0.0) {
    pair.restitution = sqrt(ea * eb);
    pair.restitutionSource = "requested";
  } else if (ea >= 0.0 || eb >= 0.0) {
    pair.restitution = ea >= 0.0 ? ea : eb;
    pair.restitutionSource = "one side requested";
  } else {
    // the lighter moving side decides how much of the damping it feels (eq. (15) with its sizing mass)
    const struct pdMaterialTable* t = model->materials;
    double m = INFINITY;
    if (!model->bodies[a].fixed) m = fmin(m, t->info[a].mass);
    if (!model->bodies[b].fixed) m = fmin(m, t->info[b].mass);
    double zeta = pair.kn > 0.0 ? pair.cn / (2.0 * sqrt(pair.kn * m)) : 0.0;
    pair.restitution = zeta >= 1.0 ? 0.0 : pd_restitution_from_damping_ratio(zeta);
    pair.restitutionSource = "predicted by eq. (15)";
  }
  return pair;
}
