// polydyn — the contact model's material parameters in a compiled model (paper §3.2, §3.3; docs/DESIGN.md §6.4).
//
// material.c holds the rules (per-body sides, per-pair constants from eq. (11) and eq. (15), the §3.3
// checks, the modal dampers). This file applies them to a scene:
// - every body gets its side (pd_material_side); bodies whose side is bit-identical form a material class
//   (found by hashing, O(bodies)); a contact's constants depend only on the classes of its two bodies, so
//   pair constants and the §3.3 checks are done per pair of classes, never per pair of bodies;
// - every adjustment is kept as data and described on request (check output, summary.json).
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "material.h"
#include "model_contact.h"

#define PI 3.14159265358979323846

// Pair constants are tabulated (both orientations) when there are at most this many classes: 128² entries
// of ~120 bytes is 2 MB, small enough to stay in cache for the lookups made when contacts begin. Scenes
// with more distinct materials (bodies of many sizes: the size is part of a side) compute a pair's
// constants on the fly with the same function, so both paths give the same bits.
#define PD_MATERIAL_DENSE_CLASSES 128
// pd_model_contact_period_min visits every pair of classes; past this many classes it is not computed
// (reported as unknown): 4096² pairs already take ~0.3 s at compile time, and the value is only reported.
#define PD_MATERIAL_PERIOD_CLASSES 4096

// At most this many adjustments are listed (check output, summary.json); the rest are counted.
#define PD_MODEL_ADJUSTMENTS_MAX 1000

// memcmp on pdMaterialSide is only a bit comparison if the struct has no padding.
_Static_assert(sizeof(pdMaterialSide) == 10 * sizeof(double), "pdMaterialSide must be 10 doubles, no padding");

struct pdMaterialTable {
  int bodyCount;
  pdBodyContactInfo* info;  // (bodyCount)
  int* classOf;             // (bodyCount) material class of each body
  int classCount;
  pdMaterialSide* classSide;  // (classCount)
  int* classFirst;            // (classCount) first body of each class, scene order
  int* classSize;             // (classCount) bodies in each class
  bool* classMoving;          // (classCount) the class holds a moving body
  pdContactParams* pairs;     // (classCount²) [a * classCount + b]: class a on side 1; NULL when not tabulated
  pdMaterialSettings settings;
  double periodMin;           // s, pd_model_contact_period_min
  pdAdjustment* adj;          // (adjCount)
  int adjCount;
  int adjDropped;
  bool view;  // a view of another table (pd_material_table_view): only info and classOf are its own
};

void pd_material_table_free(struct pdMaterialTable* t) {
  if (!t) return;
  free(t->info);
  free(t->classOf);
  if (t->view) {
    free(t);
    return;
  }
  free(t->classSide);
  free(t->classFirst);
  free(t->classSize);
  free(t->classMoving);
  free(t->pairs);
  free(t->adj);
  free(t);
}

// ---------------------------------------------------------------- material classes

static uint64_t hash_side(const pdMaterialSide* u) {
  // FNV-1a over the bytes: classes are defined by bit identity
  const unsigned char* p = (const unsigned char*)u;
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < sizeof *u; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// Classes numbered in order of their first body, so the numbering is a function of the scene.
static void group_classes(struct pdMaterialTable* t, const pdMaterialSide* sides, const pdModel* m) {
  size_t slots = 16;
  while (slots < 2 * (size_t)t->bodyCount) slots *= 2;
  int* slot = pd_zeroed(slots, sizeof *slot);  // class + 1, 0 = empty
  t->classOf = pd_zeroed((size_t)t->bodyCount, sizeof *t->classOf);
  t->classSide = pd_zeroed((size_t)t->bodyCount, sizeof *t->classSide);
  t->classFirst = pd_zeroed((size_t)t->bodyCount, sizeof *t->classFirst);
  t->classSize = pd_zeroed((size_t)t->bodyCount, sizeof *t->classSize);
  t->classMoving = pd_zeroed((size_t)t->bodyCount, sizeof *t->classMoving);
  for (int i = 0; i < t->bodyCount; ++i) {
    size_t s = (size_t)hash_side(&sides[i]) & (slots - 1);
    while (slot[s] != 0 && memcmp(&t->classSide[slot[s] - 1], &sides[i], sizeof sides[i]) != 0) s = (s + 1) & (slots - 1);
    if (slot[s] == 0) {
      int c = t->classCount++;
      slot[s] = c + 1;
      t->classSide[c] = sides[i];
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
// least one of the two moving (fixed bodies never meet: docs/DESIGN.md §5).
static bool classes_can_touch(const struct pdMaterialTable* t, int a, int b) {
  if (a == b) return t->classMoving[a] && t->classSize[a] >= 2;
  return t->classMoving[a] || t->classMoving[b];
}

// A pair of classes always has a moving side to size it: a class holds either moving or fixed bodies only
// (mass is part of the side), and two fixed classes never touch.
static bool classes_have_mass(const struct pdMaterialTable* t, int a, int b) {
  return t->classSide[a].mass > 0.0 || t->classSide[b].mass > 0.0;
}

// The constants of a contact between classes a (side 1) and b (side 2), computed with the lower class
// on side 1 so that the tabulated and the on-the-fly paths, and both orientations, agree to the bit.
static pdContactParams class_pair(const struct pdMaterialTable* t, int a, int b, int body1, int body2,
                                  pdAdjustmentList* adj) {
  int lo = a < b ? a : b, hi = a < b ? b : a;
  double e, zeta;
  bool solved = pd_pair_damping_ratio(&t->classSide[lo], &t->classSide[hi], &e, &zeta);
  PD_ASSERT(solved);  // each side's e was solved when the model was built: their mean is in range
  pdContactParams p;
  pd_contact_params_pair(&t->classSide[lo], &t->classSide[hi], zeta, &t->settings, a <= b ? body1 : body2,
                         a <= b ? body2 : body1, &p, adj);
  return a <= b ? p : pd_contact_params_swapped(&p);
}

// ---------------------------------------------------------------- adjustments and time constants

static void list_adjustment(struct pdMaterialTable* t, const pdAdjustment* a) {
  if (t->adjCount >= PD_MODEL_ADJUSTMENTS_MAX) {
    t->adjDropped++;
    return;
  }
  t->adj[t->adjCount++] = *a;
}

static bool same_content(const pdAdjustment* x, const pdAdjustment* y) {
  return x->rule == y->rule && x->param == y->param && x->from == y->from && x->to == y->to &&
         x->tau == y->tau && x->dtmin == y->dtmin;
}

// Every pair of classes that can touch, in (a, b) order, a <= b: its adjustments (named by the first body
// of each class) and its shortest period 2π√(m_min/k_s) along n and in P_t.
static void visit_pairs(struct pdMaterialTable* t) {
  int n = t->classCount;
  bool periods = n <= PD_MATERIAL_PERIOD_CLASSES;
  double best = INFINITY;
  for (int a = 0; a < n; ++a)
    for (int b = a; b < n; ++b) {
      if (!classes_can_touch(t, a, b) || !classes_have_mass(t, a, b)) continue;
      pdAdjustment items[8];
      pdAdjustmentList local = {.items = items, .capacity = 8};
      pdContactParams p = class_pair(t, a, b, t->classFirst[a], t->classFirst[b], &local);
      PD_ASSERT(local.dropped == 0);
      for (int r = 0; r < local.count; ++r) {
        // within one class both sides' records are the same change: list it once
        if (a == b && r > 0 && same_content(&items[r], &items[r - 1])) continue;
        list_adjustment(t, &items[r]);
      }
      if (!periods) continue;
      double kn = pd_series(p.k1n, p.k2n), kt = pd_series(p.k1t, p.k2t);
      if (kn > 0.0) best = fmin(best, p.massMin / kn);
      if (p.mu > 0.0 && kt > 0.0) best = fmin(best, p.massMin / kt);
    }
  t->periodMin = periods ? 2.0 * PI * sqrt(best) : NAN;
}

// ---------------------------------------------------------------- compile

// A restitution below PD_RESTITUTION_MIN is refused at the object's line (material.h says why), not
// silently clamped. The parser accepts [0, 1]; this is the contact model's own limit.
static bool check_restitutions(const pdScene* scene, pdError* err) {
  for (int i = 0; i < scene->objectCount; ++i) {
    const pdSceneObject* o = &scene->objects[i];
    if ((o->setMask & PD_SET_RESTITUTION) && o->restitution < PD_RESTITUTION_MIN) {
      // scene.h keeps no per-property location: the object's line it is
      pd_error_set(err, scene->path, o->where.line, o->where.col,
                   "object '%s': restitution %.10g is below %g, the smallest the contact model takes (e = 0 "
                   "needs an infinite damper; below %g the overdamped contact forces steps ~10x shorter)",
                   o->name, o->restitution, PD_RESTITUTION_MIN, PD_RESTITUTION_MIN);
      return false;
    }
  }
  return true;
}

bool pd_model_build_materials(pdModel* m, const pdScene* scene, pdError* err) {
  PD_ASSERT(m->materials == NULL && scene->objectCount == m->bodyCount);
  if (!check_restitutions(scene, err)) return false;
  const int n = m->bodyCount;
  pdMaterialSide* sides = pd_zeroed((size_t)n, sizeof *sides);
  const unsigned requestBits = PD_SET_KN | PD_SET_KT | PD_SET_CN | PD_SET_CT | PD_SET_RESTITUTION;
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &m->bodies[i];
    const pdSceneObject* o = &scene->objects[i];
    double mMin = 0.0;
    if (!b->fixed) {
      // a pile of equal boxes forms its minimum effective mass once: a shape twin has the same mass and vertices
      const int twin = b->shapeTwin;
      mMin = twin >= 0 && !m->bodies[twin].fixed
                 ? sides[twin].mMin
                 : pd_min_effective_mass(b->mass, &b->inertia, b->shape.vertices, b->shape.vertexCount);
    }
    pdMaterialBody body = {
        .index = i,
        .fixed = b->fixed,
        .mass = b->mass,
        .mMin = mMin,
        .size = b->size,
        .width = b->width,
    };
    pdMaterialRequest req = {.mu = o->mu, .kn = o->kn, .kt = o->kt, .cn = o->cn, .ct = o->ct,
                             .restitution = o->restitution, .setMask = o->setMask & requestBits};
    char why[PD_ERROR_MESSAGE_MAX] = "";
    if (!pd_material_side(&body, &req, &sides[i], why, sizeof why)) {
      pd_error_set(err, scene->path, o->where.line, o->where.col, "object '%s': %s", o->name, why);
      free(sides);
      return false;
    }
  }
  struct pdMaterialTable* t = pd_zeroed(1, sizeof *t);
  m->materials = t;
  t->bodyCount = n;
  t->settings = (pdMaterialSettings){.vmax = m->settings.vmax, .deflection = m->settings.deflection,
                                     .dtmin = m->settings.dtmin};
  t->info = pd_zeroed((size_t)n, sizeof *t->info);
  for (int i = 0; i < n; ++i) {
    const pdMaterialSide* u = &sides[i];
    pdBody* b = &m->bodies[i];
    double zeta = 0.0;
    char why[PD_ERROR_MESSAGE_MAX];
    bool solved = pd_damping_ratio_from_restitution(u->restitution, &zeta, why, sizeof why);
    PD_ASSERT(solved);  // pd_material_side solved it already
    // per body only what the body itself decides; the springs and dampers are the pair's (pd_model_pair_contact)
    b->used = (pdMaterial){.mu = u->mu, .kn = u->kn > 0.0 ? u->kn : -1.0, .kt = u->kt > 0.0 ? u->kt : -1.0,
                           .cn = u->cn, .ct = u->ct, .restitution = u->restitution};
    t->info[i] = (pdBodyContactInfo){.mass = b->fixed ? INFINITY : u->mass, .mMin = b->fixed ? INFINITY : u->mMin,
                                     .zeta = zeta};
  }
  group_classes(t, sides, m);
  t->adj = pd_zeroed(PD_MODEL_ADJUSTMENTS_MAX, sizeof *t->adj);
  visit_pairs(t);
  if (t->classCount <= PD_MATERIAL_DENSE_CLASSES) {
    size_t c = (size_t)t->classCount;
    t->pairs = pd_zeroed(c * c, sizeof *t->pairs);
    for (int a = 0; a < t->classCount; ++a)
      for (int b = a; b < t->classCount; ++b) {
        if (!classes_have_mass(t, a, b)) continue;  // two fixed classes: never asked for
        pdContactParams p = class_pair(t, a, b, -1, -1, NULL);
        t->pairs[(size_t)a * c + (size_t)b] = p;
        t->pairs[(size_t)b * c + (size_t)a] = pd_contact_params_swapped(&p);
      }
  }
  free(sides);
  return true;
}

// ---------------------------------------------------------------- views

struct pdMaterialTable* pd_material_table_view(const struct pdMaterialTable* t, const int* bodies, int count) {
  struct pdMaterialTable* v = pd_zeroed(1, sizeof *v);
  *v = *t;  // classes, pair constants and adjustments shared: bodies keep their class
  v->view = true;
  v->bodyCount = count;
  v->info = pd_zeroed((size_t)(count > 0 ? count : 1), sizeof *v->info);
  v->classOf = pd_zeroed((size_t)(count > 0 ? count : 1), sizeof *v->classOf);
  for (int i = 0; i < count; ++i) {
    PD_ASSERT(bodies[i] >= 0 && bodies[i] < t->bodyCount);
    v->info[i] = t->info[bodies[i]];
    v->classOf[i] = t->classOf[bodies[i]];
  }
  return v;
}

// ---------------------------------------------------------------- queries

pdContactParams pd_model_contact_params(const pdModel* model, int body1, int body2) {
  const struct pdMaterialTable* t = model->materials;
  PD_ASSERT(t != NULL && body1 >= 0 && body1 < t->bodyCount && body2 >= 0 && body2 < t->bodyCount &&
            body1 != body2);
  PD_ASSERT(!(model->bodies[body1].fixed && model->bodies[body2].fixed));
  int a = t->classOf[body1], b = t->classOf[body2];
  pdContactParams p =
      t->pairs ? t->pairs[(size_t)a * (size_t)t->classCount + (size_t)b] : class_pair(t, a, b, -1, -1, NULL);
  PD_ASSERT(pd_contact_params_valid(&p));  // what pd_contact_force requires (checked there in self-check builds only)
  return p;
}

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

int pd_model_contact_class_pairs(const pdModel* model, int* bodyA, int* bodyB, int capacity) {
  const struct pdMaterialTable* t = model->materials;
  PD_ASSERT(t != NULL && capacity >= 0 && (capacity == 0 || (bodyA && bodyB)));
  int count = 0;
  for (int a = 0; a < t->classCount; ++a)
    for (int b = a; b < t->classCount; ++b) {
      if (!classes_can_touch(t, a, b) || !classes_have_mass(t, a, b)) continue;
      if (count < capacity) {
        int first = t->classFirst[a], second = t->classFirst[b];
        if (a == b) {  // a second body of the same class
          for (int i = first + 1; i < t->bodyCount; ++i)
            if (t->classOf[i] == a) {
              second = i;
              break;
            }
        }
        // the moving body first, as a reader names a contact ("cube on floor")
        bool swap = model->bodies[first].fixed;
        bodyA[count] = swap ? second : first;
        bodyB[count] = swap ? first : second;
      }
      ++count;
    }
  return count;
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
  const pdAdjustment* a = &t->adj[i];
  int len = pd_adjustment_describe(a, model->bodies[a->body].name, model->bodies[a->partner].name, buf, size);
  if (len < 0) return len;
  // what else the line stands for: every body of each class
  char more[200] = "";
  int ca = t->classOf[a->body], cb = t->classOf[a->partner];
  if (ca == cb && t->classSize[ca] > 1)
    snprintf(more, sizeof more, " (every contact among the %d bodies of %s's material)", t->classSize[ca],
             model->bodies[a->body].name);
  else if (ca != cb && (t->classSize[ca] > 1 || t->classSize[cb] > 1))
    snprintf(more, sizeof more, " (every contact between the %d bod%s of %s's material and the %d of %s's)",
             t->classSize[ca], t->classSize[ca] == 1 ? "y" : "ies", model->bodies[a->body].name, t->classSize[cb],
             model->bodies[a->partner].name);
  int done = len < size ? len : (size > 0 ? size - 1 : 0);
  int extra = snprintf(buf ? buf + done : NULL, (size_t)(size - done), "%s", more);
  return len + extra;
}

double pd_model_pair_delta_max(const pdModel* model, int a, int b) {
  const pdBody *A = &model->bodies[a], *B = &model->bodies[b];
  return pd_delta_max(model->settings.deflection, A->size, A->width, B->size, B->width);
}

pdPairContact pd_model_pair_contact(const pdModel* model, int a, int b) {
  pdContactParams p = pd_model_contact_params(model, a, b);
  double kn = pd_series(p.k1n, p.k2n), kt = pd_series(p.k1t, p.k2t);
  pdPairContact pair = {.mu = p.mu,
                        .kn = kn,
                        .kt = kt,
                        .cn = pd_series(p.c1n, p.c2n),
                        .ct = pd_series(p.c1t, p.c2t),
                        .restitution = sqrt(model->bodies[a].used.restitution * model->bodies[b].used.restitution),
                        .zetaN = p.zetaN,
                        .zetaT = p.zetaT,
                        .modalN = p.modalN,
                        .modalT = p.modalT,
                        .massPair = p.massPair,
                        .massMin = p.massMin,
                        .period = kn > 0.0 ? 2.0 * PI * sqrt(p.massPair / kn) : INFINITY,
                        .deltaMax = pd_model_pair_delta_max(model, a, b)};
  bool ra = model->bodies[a].requested.restitution >= 0.0, rb = model->bodies[b].requested.restitution >= 0.0;
  pair.restitutionSource = ra && rb ? "requested" : (ra || rb ? "one side requested, one default" : "default");
  if (!p.modalN) {
    // explicit dampers: what eq. (15) predicts for one contact carrying the pair's reduced mass
    double zeta = kn > 0.0 ? pair.cn / (2.0 * sqrt(kn * p.massPair)) : 0.0;
    pair.restitution = pd_restitution_from_damping_ratio(zeta);
    pair.zetaN = zeta;
    pair.restitutionSource = "predicted by eq. (15) from the explicit dampers";
  }
  return pair;
}
