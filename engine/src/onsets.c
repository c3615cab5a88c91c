// polydyn — contact onsets (paper App. C): when a contact found at the end of a step began inside it, and what is done
// about it.
//
// Design note. A new contact found deeper than PD_ONSET_DEPTH_TOL_REL of its δ_max began inside the step: its onset
// fraction δ is interpolated (pd_contact_onset: VF by the quadratic (24)–(25), EE by (26)) and the step retried to end
// there (t0 + δ·h, at most PD_ONSET_RETRIES_MAX times a step); an onset within dt_min of the start makes it a virtual
// contact, added at t0 with its springs at 0 (contact_set.c). With pair onsets (pd_onsetsPair, or pd_onsetsAuto in a
// system of more than PD_ONSETS_CROWD_BODIES moving bodies: docs/contact-model.md) a contact whose onset lies less
// than PD_ONSET_PAIR_OMEGA_TAU / ω before the step's end (ω its undamped angular frequency) does not cut the step:
// the interpolation is applied to the pair alone at commit (pd_onsets_start_late), so one onset does not send every
// body back. With bounded onsets (pd_onsetsBounded, the default) such a contact joins so only where the error bound of
// that correction (onset_bound.h) is within the tolerance's share, in a system of any size; the others are located
// (docs/events.md).
// Contacts start at zero spring deflection where they are added, so a late start shifts a contact's rest point by the
// depth it was found at but injects no energy; the onset tolerance bounds that shift. A pair onset instead starts
// where its pair alone would be after the τ since the onset: springs at that deflection x and the two bodies given
// the impulse of those τ seconds (normal, and the friction cone's when they slide), so its energy and phase are its
// own and its rest point sits d − x ≈ d (ωτ)²/6 deeper (d the depth reached without it).
// A slip at the rounding of Δu (PD_ONSET_PAIR_SLIP_REL) counts as none: its direction is noise, and friction along
// it broke a flush stack's bitwise symmetry (docs/contact-model.md).
#include "onsets.h"

#include <math.h>

#include "contact_list.h"
#include "material.h"
#include "model_contact.h"
#include "onset_bound.h"

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
// scene 147: docs/contact-model.md). The friction so dropped is at most 1e-9 m |Δu|.
#define PD_ONSET_PAIR_SLIP_REL 1e-9

static pdVec3 to_world(const pdPose* p, pdVec3 local) { return pd_v3_add(p->x, pd_mat3_mulv(&p->R, local)); }

// Smallest root of a t² + b t + c = 0 in [0, 1], or -1.
static double first_root_in_unit(double a, double b, double c) {
  double roots[2];
  int count = 0;
  if (fabs(a) <= 1e-12 * (fabs(b) + fabs(c))) {
    if (b != 0.0) roots[count++] = -c / b;
  } else {
    double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      // numerically stable pair
      double qr = -0.5 * (b + copysign(sqrt(disc), b));
      roots[count++] = qr / a;
      if (qr != 0.0) roots[count++] = c / qr;
    }
  }
  double best = -1.0;
  for (int i = 0; i < count; ++i)
    if (roots[i] >= 0.0 && roots[i] <= 1.0 && (best < 0.0 || roots[i] < best)) best = roots[i];
  return best;
}

double pd_contact_onset(const pdModel* model, const pdContactId* id, const pdPose* body1Start,
                        const pdPose* body1End, const pdPose* body2Start, const pdPose* body2End) {
  if (id->kind == pd_contactVF) {
    const pdPolyhedron* s1 = &model->bodies[id->body1].shape;
    const pdPolyhedron* s2 = &model->bodies[id->body2].shape;
    // App. C (23)–(25): vertex v, a point u of the face and its normal n move linearly over the step
    pdVec3 v1 = to_world(body1Start, s1->vertices[id->feat1]), v2 = to_world(body1End, s1->vertices[id->feat1]);
    pdVec3 faceLocal = s2->vertices[s2->faceVertices[s2->faces[id->feat2].first]];
    pdVec3 u1 = to_world(body2Start, faceLocal), u2 = to_world(body2End, faceLocal);
    pdVec3 n1 = pd_mat3_mulv(&body2Start->R, s2->faces[id->feat2].normal);
    pdVec3 n2 = pd_mat3_mulv(&body2End->R, s2->faces[id->feat2].normal);
    pdVec3 dn = pd_v3_sub(n2, n1), rel = pd_v3_sub(pd_v3_sub(v2, v1), pd_v3_sub(u2, u1)), w1 = pd_v3_sub(v1, u1);
    double a = pd_v3_dot(dn, rel), b = pd_v3_dot(dn, w1) + pd_v3_dot(n1, rel), c = pd_v3_dot(n1, w1);
    if (c <= 0.0) return 0.0;  // already on or behind the face plane at the start: virtual contact
    double t = first_root_in_unit(a, b, c);
    if (t >= 0.0) return t;
    // the linear model has no crossing (large rotation over the step): interpolate the distances
    double c2 = pd_v3_dot(n2, pd_v3_sub(v2, u2));
    return c2 < 0.0 ? c / (c - c2) : 1.0;
  }
  // App. C (26): the signed distance between the two edge lines at the start and at the end of the
  // step, each measured in the bodies' relative pose (the same as holding body 2 fixed)
  pdContactGeom end, start;
  if (!pd_contact_edge_lines(model, id, body1End, body2End, &end) ||
      !pd_contact_edge_lines(model, id, body1Start, body2Start, &start))
    return 0.0;  // parallel at one end of the step: no interpolation possible, take the contact as it is
  double d1 = -start.depth, d2 = -end.depth;  // separations
  if (d1 <= 0.0) return 0.0;
  return d2 < 0.0 ? d1 / (d1 - d2) : 1.0;
}

// ---------------------------------------------------------------- onset modes

pdOnsets pd_onsets_effective(pdOnsets onsets, int movingBodies) {
  if (onsets != pd_onsetsAuto) return onsets;
  return movingBodies > PD_ONSETS_CROWD_BODIES ? pd_onsetsPair : pd_onsetsExact;
}

// Can a new contact that began `age` seconds before the step's end join there (pd_onsetsPair)?
static bool joins_as_pair(const pdModel* model, const pdContactGeom* g, double age) {
  int a = g->id.body1, b = g->id.body2;
  if (!(g->depth > 0.0) || g->depth > PD_ONSET_PAIR_DEPTH_REL * pd_model_pair_delta_max(model, a, b)) return false;
  pdContactParams p = pd_model_contact_params(model, a, b);
  double k = pd_series(p.k1n, p.k2n);
  return k > 0.0 && age * sqrt(k / p.massMin) <= PD_ONSET_PAIR_OMEGA_TAU;
}

static void onset_motion(double omega2, double damping, double v0, double tau, double mu, double slipDamp,
                         double slipRate, double* xOut, double* uOut, double* wOut);
static double point_mass_at(const pdModel* model, const pdContactSet* set, const pdPose* poses, const pdContactId* id,
                            pdVec3 point, pdVec3 normal);

// What the error bound (onset_bound.h) of joining new contact g (found at y1, poses in set->poses1) as a corrected
// onset is formed from, apart from its age and depth.
typedef struct onsetTerms {
  double omega;      // 1/s: the pair's fastest undamped frequency, √(k_s / m_min)
  double approach;   // m/s: its approach speed now
  double size;       // m: the smaller moving body's
  double mass;       // kg: the effective mass at the point along the normal (the correction's element)
  double stiffness;  // 1/s²: k_s / mass
  double damping;    // 1/s: c_s / mass
  double mu;
  double slip;       // m/s: the slip speed at the point (0: none)
  double slipDamp;   // m/s²: c_t × slip / mass, the tangential damper's force per unit mass
  double slipRate;   // m/s³: k_t × slip / mass, how fast the tangential springs load
  double lever;      // 1/kg: how far a tangential impulse there may move the state, per kg·m/s (0: no slip)
  double turning;    // m/s²: Ω² r, the bodies' turning's acceleration of the point (Ω their relative rate)
} onsetTerms;

static onsetTerms onset_terms(const pdModel* model, const pdContactSet* set, const double* y1, const pdContactGeom* g) {
  int a = g->id.body1, b = g->id.body2;
  pdContactParams p = pd_model_contact_params(model, a, b);
  pdVec3 du = relative_velocity(model, y1, set->poses1, &g->id, g->point);
  onsetTerms t = {.omega = sqrt(pd_series(p.k1n, p.k2n) / p.massMin), .approach = -pd_v3_dot(du, g->normal),
                  .size = INFINITY, .mu = p.mu};
  t.mass = point_mass_at(model, set, set->poses1, &g->id, g->point, g->normal);
  t.slip = pd_v3_norm(pd_v3_sub(du, pd_v3_scale(g->normal, -t.approach)));
  if (!(p.mu > 0.0) || t.slip <= PD_ONSET_PAIR_SLIP_REL * pd_v3_norm(du)) t.slip = 0.0;
  if (isfinite(t.mass)) {
    t.stiffness = pd_series(p.k1n, p.k2n) / t.mass;
    t.damping = pd_series(p.c1n, p.c2n) / t.mass;
    t.slipDamp = pd_series(p.c1t, p.c2t) * t.slip / t.mass;
    t.slipRate = pd_series(p.k1t, p.k2t) * t.slip / t.mass;
  }
  pdVec3 spin = {0.0, 0.0, 0.0};
  double reach = 0.0;
  for (int side = 0; side < 2; ++side) {
    const pdBody* body = &model->bodies[side == 0 ? a : b];
    if (body->fixed) continue;
    t.size = fmin(t.size, body->size);
    pdVec3 w = pd_layout_w(y1 + PD_BODY_STATE_SIZE * body->stateIndex);
    spin = side == 0 ? pd_v3_add(spin, w) : pd_v3_sub(spin, w);
    reach = fmax(reach, pd_v3_norm(pd_v3_sub(g->point, set->poses1[side == 0 ? a : b].x)));
    // a tangential impulse J at the point moves it by at most |J| λ_max(K) <= |J| tr K (K its inverse mass matrix
    // there, 1/m + [r]ᵀ I⁻¹ [r], tr <= 3/m + |r|² tr I⁻¹) and turns the body by at most |J| |r| tr I⁻¹, which the
    // error norm weighs by size / vmax
    double r = pd_v3_norm(pd_v3_sub(g->point, set->poses1[side == 0 ? a : b].x));
    double trInv = body->invInertia.m[0][0] + body->invInertia.m[1][1] + body->invInertia.m[2][2];
    t.lever += fmax(3.0 * body->invMass + r * r * trInv, r * trInv * body->size);
  }
  t.turning = pd_v3_dot(spin, spin) * reach;
  return t;
}

// The bound of joining the contact `age` seconds after its onset at `depth`. Its friction term: the tangential
// impulse the correction gives (onset_motion's, as if the slip stayed what it is now) is off by what the slip's own
// change over the age makes of it, at most ωτ of it (PD_ONSET_FRICTION_C), times what such an impulse moves. Its
// turning term: the correction starts the element at the approach speed found at the step's end, which the bodies'
// turning changed over the age by up to Ω² r τ without the contact; the element's response to that is at most ωτ of
// it (PD_ONSET_TURNING_C).
static double correction_bound(const pdModel* model, const onsetTerms* t, double age, double depth) {
  double frictionVelocity = PD_ONSET_TURNING_C * t->turning * age * t->omega * age;
  if (t->slip > 0.0 && isfinite(t->mass) && t->approach > 0.0) {
    double x, u, w;
    onset_motion(t->stiffness, t->damping, t->approach, age, t->mu, t->slipDamp, t->slipRate, &x, &u, &w);
    frictionVelocity += PD_ONSET_FRICTION_C * t->omega * age * t->lever * t->mass * fmin(w, t->slip);
  }
  return pd_onset_error_bound(t->omega, age, depth, t->approach, model->settings.vmax, t->size, frictionVelocity);
}

// Bisections of the age a retried step aims at (retry_target): to ~1e-3 of the range, far finer than its share.
#define PD_ONSET_AIM_BISECTIONS 10

// The step fraction a retry aims at for a candidate that has to be located (its onset at fraction c->onset of h).
// Exact events: the onset itself (the paper). Bounded events: past it by the largest age whose correction's bound
// (the depth then taken as approach × age) is PD_ONSET_AIM_SHARE of the tolerance's share, within the pair-onset
// ranges, so that the retried step ends with the contact shallow and joins it corrected. Aimed at the onset itself, a
// retry whose onset estimate comes early (a vertex swinging down on a rolling body) ends before the contact, and the
// next full step finds it again a little later: a rimless wheel took thousands of such steps, each closer to the same
// onset.
static double retry_target(const pdModel* model, const pdContactSet* set, const double* y1, const candidate* c,
                           double h, pdOnsets onsets) {
  if (onsets != pd_onsetsBounded) return c->onset;
  onsetTerms t = onset_terms(model, set, y1, &c->geom);
  if (!(t.approach > 0.0) || !(t.omega > 0.0)) return c->onset;
  double deltaMax = pd_model_pair_delta_max(model, c->geom.id.body1, c->geom.id.body2);
  double spend = PD_ONSET_AIM_SHARE * PD_ONSET_TOL_SHARE * model->settings.tol;
  double lo = 0.0, hi = fmin(PD_ONSET_PAIR_OMEGA_TAU / t.omega, PD_ONSET_PAIR_DEPTH_REL * deltaMax / t.approach);
  if (correction_bound(model, &t, hi, t.approach * hi) <= spend) {
    lo = hi;
  } else {
    for (int k = 0; k < PD_ONSET_AIM_BISECTIONS; ++k) {
      double age = 0.5 * (lo + hi);
      if (correction_bound(model, &t, age, t.approach * age) <= spend)
        lo = age;
      else
        hi = age;
    }
  }
  double target = c->onset + lo / h;
  return target < 1.0 ? target : c->onset;
}

double pd_onsets_earliest(const pdModel* model, pdContactSet* set, double h, pdOnsets onsets, const double* y1) {
  double earliest = 2.0;
  for (int k = 0; k < set->candidateCount; ++k) {
    candidate* c = &set->candidates[k];
    if (!c->approaching || c->inherit >= 0 || c->released) continue;
    double age = (1.0 - c->onset) * h;
    if (onsets != pd_onsetsExact && joins_as_pair(model, &c->geom, age)) {
      onsetTerms t = onset_terms(model, set, y1, &c->geom);
      c->onsetBound = correction_bound(model, &t, age, c->geom.depth);
      if (onsets == pd_onsetsPair || pd_onset_bound_allows(c->onsetBound, model->settings.tol)) {
        c->onsetAge = age;
        continue;
      }
    }
    double tol = PD_ONSET_DEPTH_TOL_REL * pd_model_pair_delta_max(model, c->geom.id.body1, c->geom.id.body2);
    if (c->geom.depth > tol) earliest = fmin(earliest, retry_target(model, set, y1, c, h, onsets));
  }
  return earliest;
}

bool pd_onsets_may_retry(const pdContactSet* set) { return set->onsetRetries < PD_ONSET_RETRIES_MAX; }

// ---------------------------------------------------------------- pair onsets at commit

// The normal motion of one contact over the τ since its onset, alone at the effective mass m, undamped
// frequency² k/m and damping c/m (a Kelvin–Voigt element, force never pulling): from deflection 0 at
// approach speed v0 to its deflection *x and approach speed *u at τ. Linear and short
// (ω τ <= PD_ONSET_PAIR_OMEGA_TAU): a few classic RK4 substeps are exact to ~(ωτ/8)⁵. With it, the friction over τ
// per unit mass, *w (m/s): the tangential spring and damper under the slip, slipDamp + slipRate t (c_t × slip / m and
// k_t × slip / m), within the cone μ F_n / m, the force at each time the smaller of the two. A slow slip's springs
// take a while to reach the cone, which the normal damper makes large at once: the cone's impulse μ J_n alone would
// be first order in τ there, where the springs give second.
#define PD_ONSET_PAIR_SUBSTEPS 8
static void onset_motion(double omega2, double damping, double v0, double tau, double mu, double slipDamp,
                         double slipRate, double* xOut, double* uOut, double* wOut) {
  double x = 0.0, u = v0, w = 0.0, dt = tau / PD_ONSET_PAIR_SUBSTEPS;
  for (int i = 0; i < PD_ONSET_PAIR_SUBSTEPS; ++i) {
    double t = i * dt;
    double a1 = fmax(0.0, omega2 * x + damping * u);
    double x2 = x + 0.5 * dt * u, u2 = u - 0.5 * dt * a1, a2 = fmax(0.0, omega2 * x2 + damping * u2);
    double x3 = x + 0.5 * dt * u2, u3 = u - 0.5 * dt * a2, a3 = fmax(0.0, omega2 * x3 + damping * u3);
    double x4 = x + dt * u3, u4 = u - dt * a3, a4 = fmax(0.0, omega2 * x4 + damping * u4);
    double f1 = fmin(mu * a1, slipDamp + slipRate * t), f2 = fmin(mu * a2, slipDamp + slipRate * (t + 0.5 * dt));
    double f3 = fmin(mu * a3, slipDamp + slipRate * (t + 0.5 * dt)), f4 = fmin(mu * a4, slipDamp + slipRate * (t + dt));
    x += dt / 6.0 * (u + 2.0 * u2 + 2.0 * u3 + u4);
    u -= dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    w += dt / 6.0 * (f1 + 2.0 * f2 + 2.0 * f3 + f4);
  }
  *xOut = x;
  *uOut = u;
  *wOut = w;
}

// The effective mass of the bodies of contact `id` along `normal` at `point`, kg (INFINITY if neither moves).
static double point_mass_at(const pdModel* model, const pdContactSet* set, const pdPose* poses, const pdContactId* id,
                            pdVec3 point, pdVec3 normal) {
  double invMass = 0.0;
  for (int side = 0; side < 2; ++side) {
    int b = side == 0 ? id->body1 : id->body2;
    const pdBody* body = &model->bodies[b];
    if (body->fixed) continue;
    pdVec3 rn = pd_v3_cross(pd_v3_sub(point, poses[b].x), normal);
    invMass += body->invMass + pd_v3_dot(rn, pd_mat3_mulv(&set->invInertiaWorld[b], rn));
  }
  return invMass > 0.0 ? 1.0 / invMass : INFINITY;
}

// The effective mass of contact c's two bodies along its normal at its point, kg (INFINITY if neither moves).
static double point_mass(const pdModel* model, const pdContactSet* set, const pdPose* poses, const contactSlot* c) {
  return point_mass_at(model, set, poses, &c->id, c->point, c->normal);
}

// Pair onsets of a list just installed at state y (poses those of y; world inverse inertias and modal dampers
// set): each contact with an onset age τ > 0 is put where it would be after τ on its own (onset_motion, m the
// modal mass per contact or the point's effective mass, from its approach speed now): its normal springs at
// that deflection x, split as series springs share a static load (k1 s1 + k2 s2 = 0), and its two bodies
// given the normal impulse that slows their approach to that speed u. Its energy and phase are then the
// contact's own; its rest point sits deeper by the depth d reached without it, less x (≈ d (ωτ)²/6).
// All impulses are formed before any is applied, so the list's order does not matter. Returns the number
// of such contacts.
int pd_onsets_start_late(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses) {
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
      double kt = pd_series(p->k1t, p->k2t), ct = pd_series(p->c1t, p->c2t), x, u, w;
      onset_motion(k / mass, damper / mass, approach, c->onsetAge, p->mu, ct * slipSpeed / mass, kt * slipSpeed / mass,
                   &x, &u, &w);
      x = fmin(fmax(x, 0.0), fmax(c->depth, 0.0));
      pdSprings sp = springs_load(y + base + PD_CONTACT_STATE_SIZE * i);
      sp.s1n = -k * x / p->k1n;
      sp.s2n = k * x / p->k2n;
      double normalImpulse = mass * fmax(0.0, approach - fmax(u, 0.0));  // the pair's contacts together slow it so
      c->onsetImpulse = pd_v3_scale(n, normalImpulse);
      // friction over τ: sliding, the springs' impulse against the slip, within the cone (onset_motion; at most what
      // stops it), and the tangential springs loaded to the cone (or to the slip since the onset, if less) against it
      if (p->mu > 0.0 && kt > 0.0 && slipSpeed > 0.0) {
        pdVec3 along = pd_v3_scale(slip, 1.0 / slipSpeed);
        double frictionImpulse = fmin(mass * w, mass * slipSpeed);
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
    pd_contact_impulse(model, set, y, poses, &c->id, c->point, c->onsetImpulse);
    c->onsetAge = 0.0;
  }
  return started;
}

void pd_contact_impulse(const pdModel* model, const pdContactSet* set, double* y, const pdPose* poses,
                        const pdContactId* id, pdVec3 point, pdVec3 j) {
  for (int side = 0; side < 2; ++side) {
    int b = side == 0 ? id->body1 : id->body2;
    const pdBody* body = &model->bodies[b];
    if (body->fixed) continue;
    pdVec3 jb = side == 0 ? j : pd_v3_scale(j, -1.0);
    double* yb = y + PD_BODY_STATE_SIZE * body->stateIndex;
    pdVec3 v = pd_v3_add(pd_layout_v(yb), pd_v3_scale(jb, body->invMass));
    pdVec3 w = pd_v3_add(pd_layout_w(yb),
                         pd_mat3_mulv(&set->invInertiaWorld[b], pd_v3_cross(pd_v3_sub(point, poses[b].x), jb)));
    if (body->planar) {  // the plane takes the impulse's out-of-plane part, as in the derivative (model.h)
      v.y = pd_layout_v(yb).y;
      w.x = pd_layout_w(yb).x, w.z = pd_layout_w(yb).z;
    }
    pd_layout_store(yb, v, w, pd_layout_x(yb), pd_layout_q(yb));
  }
}
