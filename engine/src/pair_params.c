// polydyn — a pair's springs and dampers, set when its contacts change (paper §3.2 eq. (11), §3.3).
//
// Springs sized by the load: eq. (11) sizes a pair's springs for its own reduced mass; a pair that a heavier body
// presses towards a third carries that body's load, so its springs are raised for it (load_scale) and their
// deflections scaled down with them, so the force goes on (rescale_springs). Modal dampers: a pair's dampers are sized
// for the mass its contacts move together (material.h, "modal"), and in a stack for the slow mode the pair takes part
// in (stack_modes.h). Both are set when the pair's contacts or its bodies' other contacts change, springs first, and
// held until they change again (docs/contact-model.md).
#include <math.h>

#include "contact_list.h"
#include "material.h"
#include "model_contact.h"
#include "stack_modes.h"

// Mass per contact of one body pair's joint motion (material.h, "modal"): the pair's contacts i = 1 … n at
// points p_i with normals n_i (from b into a) pushed with equal unit forces. The relative acceleration of
// the contacts along their normals, summed, is 1ᵀA1 = |N|² (1/m_a + 1/m_b) + L_aᵀ J_a⁻¹ L_a + L_bᵀ J_b⁻¹ L_b
// with N = Σ n_i, L = Σ (p_i − x) × n_i (world inverse inertia J⁻¹ = R I⁻¹ Rᵀ), so the common mode carries
// m_c = n/1ᵀA1 per contact: m_eff for one contact, m/4 for a cube landing flat, m/2 on an edge. In P_t the
// same with one tangent t for all: n² (1/m_a + 1/m_b) + tᵀ [Σr]ₓᵀ J⁻¹ [Σr]ₓ t, averaged over two tangents.
typedef struct modalSums {
  pdVec3 normal, moment, arm;  // N, L, Σ r about one body's centre of mass
} modalSums;

static pdMat3 cross_matrix(pdVec3 r) { return (pdMat3){{{0, -r.z, r.y}, {r.z, 0, -r.x}, {-r.y, r.x, 0}}}; }

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
static bool own_contacts_unchanged(const pdContactSet* set, int first, int last) {
  for (int i = first; i < last; ++i)
    if (set->items[i].modalCount != last - first) return false;
  return true;
}

// In a stack (stack_modes.c) a pair's dampers are also set anew when a contact of one of its moving bodies with another
// body is made or broken (its count of contacts changed): that changes the modes its dampers are sized for.
static bool neighbours_unchanged(const pdModel* model, const pdContactSet* set, int first, int last) {
  for (int i = first; i < last; ++i) {
    const contactSlot* c = &set->items[i];
    int ends[2] = {c->id.body1, c->id.body2};
    for (int e = 0; e < 2; ++e)
      if (!model->bodies[ends[e]].fixed &&
          c->modalBodyContacts[e] != set->bodyFirst[ends[e] + 1] - set->bodyFirst[ends[e]])
        return false;
  }
  return true;
}

static void note_body_contacts(contactSlot* c, const pdContactSet* set) {
  c->modalBodyContacts[0] = set->bodyFirst[c->id.body1 + 1] - set->bodyFirst[c->id.body1];
  c->modalBodyContacts[1] = set->bodyFirst[c->id.body2 + 1] - set->bodyFirst[c->id.body2];
}

// A stack's mass per contact enters where its slow mode is far slower than the pair's own: from (ω_own/Ω)² =
// PD_STACK_SLOW_FROM in proportion to the logarithm, fully from PD_STACK_SLOW_FULL. Among boxes of one mass
// (ω_own/Ω)² is 5 in cases/hard/stack_10.scene and up to 8.5 in cases/hard/brick_bond.scene, and the heavier dampers
// there only cost steps (1.4 and 1.7 times the derivative evaluations, the overdamped part of the stability bound);
// a heavy body on a pad of a tenth of its mass gives 20 (√(M/m) slower, times the two interfaces in series), where
// the pair's own dampers leave its bounce at ζ 0.08.
#define PD_STACK_SLOW_FROM 10.0
#define PD_STACK_SLOW_FULL 20.0

// In a stack, along n: the mass per contact k_s/Ω² of the slow mode the pair takes part in (stack_modes.h), weighed
// as above against the pair's own mass per contact `own`; 0: the pair's own dampers.
static double stack_mass(const pdModel* model, pdContactSet* set, const pdPose* poses, int first, int last,
                         double own) {
  const pdContactParams* p = &set->items[first].params;
  double omega;
  if (!p->modalN) return 0.0;
  // ~125 kB: a list that never needs it (a dense output's view, an island of one falling body) makes none; made
  // at the first contacts a list has, as its GSL workspaces are (stack_modes.c)
  if (!set->stackScratch) set->stackScratch = pd_stack_scratch_create();
  // the weight below is 0 for any Ω from √(k_s / (PD_STACK_SLOW_FROM own)) up: the analysis may stop there
  double fast = sqrt(pd_series(p->k1n, p->k2n) / (PD_STACK_SLOW_FROM * own));
  if (!isfinite(fast)) fast = 0.0;
  if (!pd_stack_pair_frequency(model, set, poses, first, last, fast, set->stackScratch, &omega)) return 0.0;
  double mass = pd_series(p->k1n, p->k2n) / (omega * omega);
  double weight = log(mass / own / PD_STACK_SLOW_FROM) / log(PD_STACK_SLOW_FULL / PD_STACK_SLOW_FROM);
  return weight > 0.0 ? fmin(1.0, weight) * mass : 0.0;
}

// The mass per contact of pair [first, last)'s joint motion along n and in P_t (the sums above).
static void pair_masses(const pdModel* model, const pdContactSet* set, const pdPose* poses, int first, int last,
                        double* massN, double* massT) {
  const contactSlot* c0 = &set->items[first];
  int a = c0->id.body1 < c0->id.body2 ? c0->id.body1 : c0->id.body2;
  int b = c0->id.body1 < c0->id.body2 ? c0->id.body2 : c0->id.body1;
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
  *massN = qn > 0.0 ? count / qn : INFINITY;
  *massT = qt > 0.0 ? count / qt : INFINITY;
}

// Springs sized by the load (docs/contact-model.md, "Springs sized by the load"). Eq. (11) stores ½ m v_max² at δ_max
// with m = m_pair, the pair's reduced mass; a light body pressed by a heavy one against a third body must stop the
// heavy one's motion on its springs. So each side of a pair counts, besides its own body, the bodies pressing it
// towards the other side: a neighbour in contact whose normal is within PD_LOAD_PRESS_COS of the pair's (pushing
// the side on along it), a fixed one counting as infinitely heavy; the pair's load is the two sides in series, and
// its springs are eq. (11)'s times load/m_pair where that exceeds PD_LOAD_SCALE_FROM. A light body resting on a heavy
// one, or bodies of like masses, keep eq. (11)'s springs: the load is then the pair's own within that factor, and a
// factor near 1 would only move every such scene's bytes.
#define PD_LOAD_SCALE_FROM 2.0
// cos 60°: a neighbour pressing at 60° from the pair's normal sends half its force along it.
#define PD_LOAD_PRESS_COS 0.5
// At most this factor (docs/contact-model.md, "Springs sized by the load"): the light body's own mode is √f times faster,
// and its steps as much shorter; beyond 100 (a body 100 times its own mass pressing it) a 1 mg chip under a 49 g
// prism took the implicit stepper to its minimum step (soak campaign 62, scene 6037, islands off).
#define PD_LOAD_SCALE_MAX 100.0

// The mass behind `side` of pair (side, other) whose normal `n` points into `side` (from `other`): its own, or the
// heaviest neighbour pressing it towards `other` (INFINITY: a fixed one, or `side` fixed).
static double mass_behind(const pdModel* model, const pdContactSet* set, int side, int other, pdVec3 n) {
  if (model->bodies[side].fixed) return INFINITY;
  double mass = model->bodies[side].mass;
  for (int l = set->bodyFirst[side]; l < set->bodyFirst[side + 1]; ++l) {
    const contactSlot* c = &set->items[set->bodyList[l] / 2];
    int k = c->id.body1 == side ? c->id.body2 : c->id.body1;
    if (k == other) continue;
    pdVec3 push = c->id.body1 == side ? c->normal : pd_v3_scale(c->normal, -1.0);  // its force on `side`, along
    if (!(pd_v3_dot(push, n) <= -PD_LOAD_PRESS_COS)) continue;
    mass = fmax(mass, model->bodies[k].fixed ? INFINITY : model->bodies[k].mass);
  }
  return mass;
}

// An impact up to this many times vmax keeps eq. (11)'s springs for its speed (they take it within about as many
// δ_max); a faster one gets springs that take it within that many: the factor (v_n / (PD_LOAD_SPEED_FROM vmax))².
// Speeds beyond vmax come from bodies struck by heavier ones: a 30 kg plate between a 10 t prism and a 12 t ball
// closing in met the ball at 3.4 vmax, each bounce off the prism faster (soak campaign 68, scene 4373: 3.52 δ_max).
#define PD_LOAD_SPEED_FROM 2.0

// The fastest approach (m/s, >= 0) of pair [first, last)'s contacts made at this list (none yet listed before: their
// normal springs start at zero and no dampers were set for them) at y, poses those of y.
static double onset_speed(const pdModel* model, const pdContactSet* set, const pdPose* poses, const double* y,
                          int first, int last) {
  double fastest = 0.0;
  for (int i = first; i < last; ++i) {
    const contactSlot* c = &set->items[i];
    if (c->modalCount != 0) continue;
    pdSprings sp = springs_load(y + spring_base(model) + PD_CONTACT_STATE_SIZE * i);
    if (sp.s1n != 0.0 || sp.s2n != 0.0) continue;
    fastest = fmax(fastest, -pd_v3_dot(relative_velocity(model, y, poses, &c->id, c->point), c->normal));
  }
  return fastest;
}

// The factor on pair [first, last)'s springs for the load it carries and the speed its new contacts meet at (1:
// eq. (11)'s). §3.3.1 bounds it: 1/ω = √(m_min/k_s) stays at or above Δt_min.
static double load_scale(const pdModel* model, const pdContactSet* set, const pdPose* poses, const double* y,
                         int first, int last) {
  const contactSlot* c0 = &set->items[first];
  const pdContactParams* p = &c0->params;
  if (!p->loadSized) return 1.0;
  pdVec3 n = {0, 0, 0};  // the pair's normal, into c0's body1 (a contact of the pair may name the bodies the other way)
  for (int i = first; i < last; ++i) {
    const contactSlot* c = &set->items[i];
    n = pd_v3_add(n, c->id.body1 == c0->id.body1 ? c->normal : pd_v3_scale(c->normal, -1.0));
  }
  double nn = pd_v3_norm(n);
  if (!(nn > 0.0)) return 1.0;
  n = pd_v3_scale(n, 1.0 / nn);
  double m1 = mass_behind(model, set, c0->id.body1, c0->id.body2, n);
  double m2 = mass_behind(model, set, c0->id.body2, c0->id.body1, pd_v3_scale(n, -1.0));
  // a side backed by a fixed body moves nothing with it: the other side's load is the pair's; both backed (a body
  // wedged between two fixed ones) bring no moving mass beyond the pair's own
  double load = isinf(m1) ? m2 : isinf(m2) ? m1 : m1 * m2 / (m1 + m2);
  if (isinf(load)) load = p->massPair;
  double speed = onset_speed(model, set, poses, y, first, last) / (PD_LOAD_SPEED_FROM * model->settings.vmax);
  double f = load / p->massPair * fmax(1.0, speed * speed);
  if (!(f > PD_LOAD_SCALE_FROM)) return 1.0;
  double ks = pd_series(p->k1n, p->k2n) / c0->loadScale, dtmin = model->settings.dtmin;
  double bound = ks > 0.0 && dtmin > 0.0 ? p->massMin / (ks * dtmin * dtmin) : INFINITY;
  return fmax(1.0, fmin(fmin(f, PD_LOAD_SCALE_MAX), bound));
}

// Contact i's springs at `scale` (>= its present factor) times eq. (11)'s: the deflections shrink by the factor they
// grow by, so the force goes on where it was and the springs' energy falls by it (kept at the deflection, the force
// would jump and the energy grow). The dampers are set anew after (modalCount 0).
static void rescale_springs(const pdModel* model, contactSlot* c, double* y, int i, double scale) {
  double f = scale / c->loadScale;
  PD_ASSERT(f >= 1.0);
  pdContactParams* p = &c->params;
  p->k1n *= f, p->k2n *= f, p->k1t *= f, p->k2t *= f;
  double* at = y + spring_base(model) + PD_CONTACT_STATE_SIZE * i;
  pdSprings sp = springs_load(at);
  sp.s1n /= f, sp.s2n /= f;
  sp.s1t = pd_v3_scale(sp.s1t, 1.0 / f), sp.s2t = pd_v3_scale(sp.s2t, 1.0 / f);
  springs_store(at, &sp);
  c->loadScale = scale;
  c->modalCount = 0;
}

// The pair after `first` in the list (sorted by pair): its end.
static int pair_end(const pdContactSet* set, int first) {
  const contactSlot* c0 = &set->items[first];
  int a = c0->id.body1 < c0->id.body2 ? c0->id.body1 : c0->id.body2;
  int b = c0->id.body1 < c0->id.body2 ? c0->id.body2 : c0->id.body1;
  int last = first + 1;
  while (last < set->count && compare_to_pair(&set->items[last].id, a, b) == 0) ++last;
  return last;
}

pdContactParams pd_onset_params(const pdModel* model, const pdContactSet* set, const pdContactId* id) {
  pdContactParams p = pd_model_contact_params(model, id->body1, id->body2);
  if (!p.loadSized) return p;
  int a = id->body1 < id->body2 ? id->body1 : id->body2, b = id->body1 < id->body2 ? id->body2 : id->body1;
  int lo = 0, hi = set->count;  // the pair's first listed contact (the list is sorted by pair)
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (compare_to_pair(&set->items[mid].id, a, b) < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  double f = set->history ? pd_history_load_scale(set->history, id) : 1.0;
  for (int i = lo; i < set->count && compare_to_pair(&set->items[i].id, a, b) == 0; ++i)
    f = fmax(f, set->items[i].loadScale);
  if (f == 1.0) return p;
  p.k1n *= f, p.k2n *= f, p.k1t *= f, p.k2t *= f;
  double root = sqrt(f);
  if (p.modalN) p.c1n *= root, p.c2n *= root;
  if (p.modalT) p.c1t *= root, p.c2t *= root;
  return p;
}

void pd_modal_dampers(const pdModel* model, pdContactSet* set, const pdPose* poses, double* y) {
  if (!set->bodyListValid) pd_contact_set_list_bodies(model, set);
  // the springs first, all from eq. (11)'s (the load does not depend on the order of the pairs), then the dampers
  // for the springs as they act
  for (int first = 0, last; first < set->count; first = last) {
    last = pair_end(set, first);
    const contactSlot* c0 = &set->items[first];
    if (!c0->params.loadSized) continue;
    if (own_contacts_unchanged(set, first, last) && neighbours_unchanged(model, set, first, last)) continue;
    double scale = load_scale(model, set, poses, y, first, last);
    // never softer while the contact lasts: a pair's load comes and goes with every contact made or broken around it
    // (a squeezed prism's contact with one heavy body chattering took its pair with the other from 159 times eq.
    // (11)'s springs to 1 and back), and a softening keeps the deflection, so the force would fall each time round
    for (int i = first; i < last; ++i) scale = fmax(scale, set->items[i].loadScale);
    for (int i = first; i < last; ++i)
      if (set->items[i].loadScale != scale) rescale_springs(model, &set->items[i], y, i, scale);
  }
  for (int first = 0, last; first < set->count; first = last) {
    last = pair_end(set, first);
    contactSlot* c0 = &set->items[first];
    if (!c0->params.modalN && !c0->params.modalT) continue;
    bool own = own_contacts_unchanged(set, first, last);
    if (own && neighbours_unchanged(model, set, first, last)) continue;
    double massN, massT;
    pair_masses(model, set, poses, first, last, &massN, &massT);
    double stackN = stack_mass(model, set, poses, first, last, fmin(massN, c0->params.massPair));
    if (own && stackN == 0.0 && c0->stackScale[0] == 1.0) {  // its own dampers, held: only a neighbour changed
      for (int i = first; i < last; ++i) note_body_contacts(&set->items[i], set);
      continue;
    }
    for (int i = first; i < last; ++i) {
      contactSlot* c = &set->items[i];
      pd_contact_modal_damping(&c->params, massN, massT, stackN, 0.0, c->stackScale);
      c->modalMass = fmin(massN, c->params.massPair);
      c->modalCount = last - first;
      note_body_contacts(c, set);
    }
  }
}
