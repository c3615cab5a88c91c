// polydyn — contact onsets (paper App. C): when a contact found at the end of a step began inside it, and what is done
// about it.
//
// Design note. A new contact found deeper than onset_depth_tol (tol × δ_max: the depth whose omission the tolerance's
// share allows) began inside the step: its onset fraction δ is interpolated (pd_contact_onset: VF by the quadratic
// (24)–(25), EE by (26)) and the step retried to end there (t0 + δ·h, at most PD_ONSET_RETRIES_MAX times a step); an
// onset within dt_min of the start makes it a virtual contact, added at t0 with its springs at 0 (contact_set.c). With
// pair onsets (pd_onsetsPair, or pd_onsetsAuto in a system of more than PD_ONSETS_CROWD_BODIES moving bodies:
// docs/contact-model.md) a contact whose onset lies less than PD_ONSET_PAIR_OMEGA_TAU / ω before the step's end (ω its
// undamped angular frequency) does not cut the step: the interpolation is applied to the pair alone at commit
// (pd_onsets_start_late), so one onset does not send every body back. With bounded onsets (pd_onsetsBounded, the
// default) such a contact joins so only where the error bound of that correction (onset_bound.h) is within the
// tolerance's share, in a system of any size; the others are located (docs/events.md).
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

// A new contact found deeper than onset_depth_tol at the end of a step is located (the step retried to its onset); a
// shallower one that is not corrected joins with its springs at 0, its rest point shifted by the depth d it was found
// at. That omission is onset_bound.h's spring term with the whole deflection missed, d / δ_max in the error norm, so
// d <= PD_ONSET_TOL_SHARE × tol × δ_max keeps it within the share of the tolerance a corrected onset may spend and the
// result converges with tol. The velocity it misses, ω d (ωτ/2 + 2ζ) from the spring and the damper over τ, is then
// at most tol (ωτ/2 + 2ζ) over the velocity scale, since δ_max ω is about v_max (eq. (11)). A depth fixed at 1e-3
// δ_max left the sweep's bounce 1e-5 of its size from the converged run at every tol (tests/engine/test_onsets.c).
// Capped at PD_ONSET_DEPTH_TOL_REL δ_max for loose tolerances: a thousandth of the design deflection (A3 asks for
// sinkage to 1 %).
#define PD_ONSET_DEPTH_TOL_REL 1e-3
static double onset_depth_tol(const pdModel* model, const pdContactId* id) {
  double share = fmin(PD_ONSET_DEPTH_TOL_REL, PD_ONSET_TOL_SHARE * model->settings.tol);
  return share * pd_model_pair_delta_max(model, id->body1, id->body2);  // m
}
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

// The pair's motion over the τ since an onset, alone (onset_motion): a Kelvin–Voigt element along the normal and one
// along the slip, coupled by the cone.
typedef struct onsetElement {
  double omega2;        // 1/s²: k_n / m, the normal element's (m its mass along the normal)
  double damping;       // 1/s: c_n / m
  double mass;          // kg: m
  double mu;
  double kt, ct;        // N/m, N·s/m: the tangential spring and damper (series)
  double slipInvMass;   // 1/kg: ŝᵀKŝ, the slip's change per unit tangential impulse along it (K the point's)
  double slip;          // m/s: the slip speed at the onset (0: none)
  double driftPerJt;    // 1/kg: |(I − n nᵀ − ŝ ŝᵀ) K ŝ|, the slip's turn off ŝ per unit tangential impulse
  double driftPerJn;    // 1/kg: |(I − n nᵀ) K n|, the slip the normal impulse makes, per unit of it
  double approachPerJt; // 1/kg: |nᵀ K ŝ|, the approach the tangential impulse changes, per unit of it
} onsetElement;

typedef struct onsetMotion {
  double x, u;          // m, m/s: the normal deflection and approach speed at τ
  double jn, jt;        // N·s: the normal and tangential impulses over τ (jt against the slip)
  double spring;        // m: the tangential spring's stretch since the onset (∫ slip in stick)
  double cone;          // N: μ F_n at τ
  double drift1;        // m: ∫₀^τ D(t) dt, D the slip's change that the element leaves out (onset_bound.h)
  double drift2;        // m·s: ∫₀^τ ∫₀^t D
  double approach1;     // m: ∫₀^τ D_n(t) dt, D_n the approach's change that the element leaves out
  double approach2;     // m·s: ∫₀^τ ∫₀^t D_n
} onsetMotion;

static onsetMotion onset_motion(const onsetElement* e, double v0, double tau);
static pdVec3 point_response(const pdModel* model, const pdPose* poses, const pdContactId* id, pdVec3 point,
                             pdVec3 impulse);
static void slip_element(const pdModel* model, const pdPose* poses, const pdContactId* id, pdVec3 point, pdVec3 normal,
                         pdVec3 du, onsetElement* e, pdVec3* along);
static pdMat3 inverse_inertia_at(const pdBody* body, const pdPose* pose);

// What the error bound (onset_bound.h) of joining new contact g (found at y1, poses in set->poses1) as a corrected
// onset is formed from, apart from its age and depth.
typedef struct onsetTerms {
  double omega;         // 1/s: the pair's fastest undamped frequency, √(k_s / m_min)
  double approach;      // m/s: its approach speed now
  double size;          // m: the smaller moving body's
  double deltaMax;      // m: the pair's δ_max, the error norm's weight of a contact spring
  pdVec3 normal;        // the contact's
  onsetElement element; // the correction's element at the point's effective mass (its friction: the model's dampers,
                        // which the modal ones never exceed)
  double lever;         // 1/kg: how far a tangential impulse there may move the state, per kg·m/s
  double turning;       // m/s²: Ω² r, the bodies' turning's acceleration of the point (Ω their relative rate)
  pdVec3 applied;       // m/s²: the applied loads' relative acceleration of the point at the step's end (applied_at)
  pdVec3 appliedRate;   // m/s³: its rate (a ramped force)
} onsetTerms;

// The relative acceleration at `point` that the applied loads give the pair's bodies at time t (gravity, the scene's
// force and its torque: dynamics.c's, without the contact forces and the bodies' turning), and its rate, at the
// poses `poses`. A fixed body has none; gravity alone cancels between two moving bodies.
static void applied_at(const pdModel* model, const pdPose* poses, const pdContactId* id, pdVec3 point, double t,
                       pdVec3* acceleration, pdVec3* rate) {
  *acceleration = *rate = (pdVec3){0.0, 0.0, 0.0};
  for (int side = 0; side < 2; ++side) {
    int b = side == 0 ? id->body1 : id->body2;
    const pdBody* body = &model->bodies[b];
    if (body->fixed) continue;
    pdVec3 a = model->settings.gravity, aRate = {0.0, 0.0, 0.0};
    if (body->planar) a.y = 0.0;  // the plane's reaction, as in the derivative
    if (body->hasForce) {
      pdVec3 force = pd_body_applied_force(body, t);
      pdMat3 invInertia = inverse_inertia_at(body, &poses[b]);
      pdVec3 alpha = pd_mat3_mulv(&invInertia, pd_body_applied_torque(body, &poses[b].R, force));
      pdVec3 alphaRate = pd_mat3_mulv(&invInertia, pd_body_applied_torque(body, &poses[b].R, body->forceRate));
      pdVec3 linear = pd_v3_scale(force, body->invMass);
      aRate = pd_v3_scale(body->forceRate, body->invMass);
      if (body->planar) {
        linear.y = aRate.y = 0.0;
        alpha.x = alpha.z = alphaRate.x = alphaRate.z = 0.0;
      }
      pdVec3 r = pd_v3_sub(point, poses[b].x);
      a = pd_v3_add(a, pd_v3_add(linear, pd_v3_cross(alpha, r)));
      aRate = pd_v3_add(aRate, pd_v3_cross(alphaRate, r));
    }
    *acceleration = side == 0 ? pd_v3_add(*acceleration, a) : pd_v3_sub(*acceleration, a);
    *rate = side == 0 ? pd_v3_add(*rate, aRate) : pd_v3_sub(*rate, aRate);
  }
}

static onsetTerms onset_terms(const pdModel* model, const pdContactSet* set, const double* y1, double t1,
                              const pdContactGeom* g) {
  int a = g->id.body1, b = g->id.body2;
  pdContactParams p = pd_model_contact_params(model, a, b);
  pdVec3 du = relative_velocity(model, y1, set->poses1, &g->id, g->point);
  onsetTerms t = {.omega = sqrt(pd_series(p.k1n, p.k2n) / p.massMin), .approach = -pd_v3_dot(du, g->normal),
                  .size = INFINITY, .deltaMax = pd_model_pair_delta_max(model, a, b), .normal = g->normal};
  onsetElement* e = &t.element;
  double inverseMass = pd_v3_dot(g->normal, point_response(model, set->poses1, &g->id, g->point, g->normal));
  e->mass = inverseMass > 0.0 ? 1.0 / inverseMass : INFINITY;
  e->mu = p.mu;
  if (isfinite(e->mass)) {
    e->omega2 = pd_series(p.k1n, p.k2n) / e->mass;
    e->damping = pd_series(p.c1n, p.c2n) / e->mass;
    e->kt = pd_series(p.k1t, p.k2t);
    e->ct = pd_series(p.c1t, p.c2t);
    pdVec3 along;
    slip_element(model, set->poses1, &g->id, g->point, g->normal, du, e, &along);
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
  applied_at(model, set->poses1, &g->id, g->point, t1, &t.applied, &t.appliedRate);
  return t;
}

// The largest normal and tangential parts of the applied loads' relative acceleration at the point over the `age`
// before the step's end (linear in time at the step's end's poses: the larger of its two ends), m/s².
static void applied_over(const onsetTerms* t, double age, double* alongNormal, double* tangential) {
  pdVec3 start = pd_v3_sub(t->applied, pd_v3_scale(t->appliedRate, age));
  double n1 = pd_v3_dot(t->applied, t->normal), n0 = pd_v3_dot(start, t->normal);
  *alongNormal = fmax(fabs(n1), fabs(n0));
  *tangential = fmax(pd_v3_norm(pd_v3_sub(t->applied, pd_v3_scale(t->normal, n1))),
                     pd_v3_norm(pd_v3_sub(start, pd_v3_scale(t->normal, n0))));
}

// The bound of joining the contact `age` seconds after its onset at `depth` (onset_bound.h). Its friction terms: the
// correction follows the slip along ŝ under its own friction and the normal element under its own force
// (onset_motion); what it leaves out are the slip's change off that element, D(t) <= driftPerJt J_t(t) +
// driftPerJn J_n(t) (the tangential impulse turning the slip, the normal impulse making slip), and the approach's,
// D_n(t) <= approachPerJt J_t(t) (the tangential impulse pressing or lifting the point). Its applied term: the elements
// start from the approach and the slip found at the step's end, which the applied loads (gravity, a scene's force and
// its torque) changed over the age τ without the contact; followed from the onset, the point's relative velocity
// differs from the elements' at time t since it by what those loads added over [t, τ], at most a (τ − t) with a their
// largest relative acceleration there (applied_over), normal to D_n and tangential to D: their integrals are a τ²/2 and
// a τ³/3. Each force law is Lipschitz in its velocity (the damper by c, the spring by k on its integral, the cone's
// projection by 1, the clamp of F_n by 1), so the tangential impulse is off by at most c_t ∫D + k_t ∫∫D (never more than
// both cones' impulses, 2 μ J_n), the normal impulse by c_n ∫D_n + k_n ∫∫D_n, and the cone's radius, μ F_n, by μ times
// the normal impulse's error: that and the velocity term's (PD_ONSET_BOUND_C). Those impulses move the state by at most
// `lever` each; the tangential springs' stretch is off by at most ∫D and the normal ones' deflection by ∫D_n. Its
// turning term: the correction starts the element at the approach speed found at the step's end, which the bodies'
// turning changed over the age by up to Ω² r τ without the contact; the element's response to that is at most ωτ of it
// (PD_ONSET_TURNING_C).
static double correction_bound(const pdModel* model, const onsetTerms* t, double age, double depth) {
  double wt = t->omega * age, velocity = PD_ONSET_TURNING_C * t->turning * age * wt, spring = 0.0;
  const onsetElement* e = &t->element;
  if (isfinite(e->mass) && t->approach > 0.0) {
    double an, at;
    applied_over(t, age, &an, &at);
    double age2 = 0.5 * age * age, age3 = age * age * age / 3.0;
    double approach1 = an * age2, approach2 = an * age3;  // m, m·s: ∫D_n and ∫∫D_n, the applied loads' part
    double drift1 = at * age2, drift2 = at * age3;        // ∫D and ∫∫D, theirs
    double tangential = 0.0;
    if (e->mu > 0.0) {
      onsetMotion m = onset_motion(e, t->approach, age);
      approach1 += m.approach1, approach2 += m.approach2;
      drift1 += m.drift1, drift2 += m.drift2;
      tangential = fmin(e->ct * drift1 + e->kt * drift2, 2.0 * e->mu * m.jn);
      velocity += e->mu * PD_ONSET_BOUND_C * wt * wt * wt * t->approach;
      spring = drift1 / t->deltaMax;
    }
    double normal = e->mass * (e->omega2 * approach2 + e->damping * approach1);  // N·s
    velocity += t->lever * (tangential + (1.0 + e->mu) * normal);
    spring = fmax(spring, approach1 / t->deltaMax);
  }
  return pd_onset_error_bound(t->omega, age, depth, t->approach, model->settings.vmax, t->size, velocity, spring);
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
static double retry_target(const pdModel* model, const pdContactSet* set, const double* y1, double t1,
                           const candidate* c, double h, pdOnsets onsets) {
  if (onsets != pd_onsetsBounded) return c->onset;
  onsetTerms t = onset_terms(model, set, y1, t1, &c->geom);
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

double pd_onsets_earliest(const pdModel* model, pdContactSet* set, double h, pdOnsets onsets, const double* y1,
                          double t1) {
  double earliest = 2.0;
  for (int k = 0; k < set->candidateCount; ++k) {
    candidate* c = &set->candidates[k];
    if (!c->approaching || c->inherit >= 0 || c->released) continue;
    double age = (1.0 - c->onset) * h;
    if (onsets != pd_onsetsExact && joins_as_pair(model, &c->geom, age)) {
      onsetTerms t = onset_terms(model, set, y1, t1, &c->geom);
      c->onsetBound = correction_bound(model, &t, age, c->geom.depth);
      if (onsets == pd_onsetsPair || pd_onset_bound_allows(c->onsetBound, model->settings.tol)) {
        c->onsetAge = age;
        continue;
      }
    }
    if (c->geom.depth > onset_depth_tol(model, &c->geom.id)) earliest = fmin(earliest, retry_target(model, set, y1, t1, c, h, onsets));
  }
  return earliest;
}

bool pd_onsets_may_retry(const pdContactSet* set) { return set->onsetRetries < PD_ONSET_RETRIES_MAX; }

// ---------------------------------------------------------------- pair onsets at commit

// The motion of one contact over the τ since its onset, alone (onsetElement): along the normal a Kelvin–Voigt element at
// mass m that never pulls, from deflection 0 at approach speed v0; along the slip ŝ a Kelvin–Voigt element (k_t, c_t)
// from stretch 0 at the slip speed, within the cone μ F_n, that slows the slip at ŝᵀKŝ per unit impulse. Linear and
// short (ω τ <= PD_ONSET_PAIR_OMEGA_TAU): a few classic RK4 substeps are exact to ~(ωτ/8)⁵ away from the cone's and
// the clamp's kinks. With the slip's own slowing, the tangential impulse is second order in τ where the slip is slow
// (the springs take a while to reach the cone, which the normal damper makes large at once) and the slip stopping
// within τ is followed, not capped afterwards. Also the integrals of D = driftPerJt J_t + driftPerJn J_n, what the
// element leaves out of the slip (correction_bound).
#define PD_ONSET_PAIR_SUBSTEPS 8
enum { M_X, M_U, M_VT, M_Q, M_JN, M_JT, M_I1, M_I2, M_N1, M_N2, M_STATE };
static void motion_rate(const onsetElement* e, const double s[M_STATE], double r[M_STATE]) {
  double fn = e->mass * fmax(0.0, e->omega2 * s[M_X] + e->damping * s[M_U]);  // N
  // the tangential law (contact_force.h): the spring and damper in stick, on the cone in slip with the spring's stretch
  // relaxing towards it through the damper, k_t q + c_t q̇ = ±μ F_n
  double cone = e->mu * fn, trial = e->kt * s[M_Q] + e->ct * s[M_VT], ft = fmin(cone, fmax(-cone, trial));
  r[M_X] = s[M_U];
  r[M_U] = -fn / e->mass;
  r[M_VT] = -e->slipInvMass * ft;
  r[M_Q] = ft == trial || !(e->ct > 0.0) ? s[M_VT] : (ft - e->kt * s[M_Q]) / e->ct;
  r[M_JN] = fn;
  r[M_JT] = ft;
  r[M_I1] = e->driftPerJt * fabs(s[M_JT]) + e->driftPerJn * s[M_JN];
  r[M_I2] = s[M_I1];
  r[M_N1] = e->approachPerJt * fabs(s[M_JT]);
  r[M_N2] = s[M_N1];
}

static onsetMotion onset_motion(const onsetElement* e, double v0, double tau) {
  double s[M_STATE] = {0.0}, k[4][M_STATE], tmp[M_STATE], dt = tau / PD_ONSET_PAIR_SUBSTEPS;
  s[M_U] = v0;
  s[M_VT] = e->slip;
  for (int i = 0; i < PD_ONSET_PAIR_SUBSTEPS; ++i) {
    motion_rate(e, s, k[0]);
    for (int j = 0; j < M_STATE; ++j) tmp[j] = s[j] + 0.5 * dt * k[0][j];
    motion_rate(e, tmp, k[1]);
    for (int j = 0; j < M_STATE; ++j) tmp[j] = s[j] + 0.5 * dt * k[1][j];
    motion_rate(e, tmp, k[2]);
    for (int j = 0; j < M_STATE; ++j) tmp[j] = s[j] + dt * k[2][j];
    motion_rate(e, tmp, k[3]);
    for (int j = 0; j < M_STATE; ++j) s[j] += dt / 6.0 * (k[0][j] + 2.0 * k[1][j] + 2.0 * k[2][j] + k[3][j]);
  }
  double fn = e->mass * fmax(0.0, e->omega2 * s[M_X] + e->damping * s[M_U]);
  return (onsetMotion){.x = s[M_X], .u = s[M_U], .jn = s[M_JN], .jt = s[M_JT], .spring = s[M_Q], .cone = e->mu * fn,
                       .drift1 = s[M_I1], .drift2 = s[M_I2], .approach1 = s[M_N1], .approach2 = s[M_N2]};
}

// A body's inverse inertia in the world frame at `pose`, R I⁻¹ Rᵀ: computed here, since the set's copy is the last
// installed list's (a step's start, and zero before the first), and an onset's bound is formed at the step's end.
static pdMat3 inverse_inertia_at(const pdBody* body, const pdPose* pose) {
  pdMat3 rt = pd_mat3_transpose(&pose->R), tmp = pd_mat3_mul(&body->invInertia, &rt);
  return pd_mat3_mul(&pose->R, &tmp);
}

// K·j at a contact point: how the relative velocity Δu there changes under impulse j on body 1 (−j on body 2), 1/kg
// times the impulse.
static pdVec3 point_response(const pdModel* model, const pdPose* poses, const pdContactId* id, pdVec3 point,
                             pdVec3 impulse) {
  pdVec3 out = {0.0, 0.0, 0.0};
  for (int side = 0; side < 2; ++side) {
    int b = side == 0 ? id->body1 : id->body2;
    const pdBody* body = &model->bodies[b];
    if (body->fixed) continue;
    pdVec3 r = pd_v3_sub(point, poses[b].x);
    pdMat3 invInertia = inverse_inertia_at(body, &poses[b]);
    pdVec3 turn = pd_mat3_mulv(&invInertia, pd_v3_cross(r, impulse));
    out = pd_v3_add(out, pd_v3_add(pd_v3_scale(impulse, body->invMass), pd_v3_cross(turn, r)));
  }
  return out;
}

// The tangential part of a correction's element at a contact point whose relative velocity is du: the slip, its
// direction *along (any tangent where there is none), and how the impulses change it (K the point's inverse mass).
static void slip_element(const pdModel* model, const pdPose* poses, const pdContactId* id, pdVec3 point, pdVec3 normal,
                         pdVec3 du, onsetElement* e, pdVec3* along) {
  pdVec3 slip = pd_v3_sub(du, pd_v3_scale(normal, pd_v3_dot(du, normal)));
  double speed = pd_v3_norm(slip);
  if (!(e->mu > 0.0) || speed <= PD_ONSET_PAIR_SLIP_REL * pd_v3_norm(du)) speed = 0.0;  // rounding, not slip
  e->slip = speed;
  if (speed > 0.0) {
    *along = pd_v3_scale(slip, 1.0 / speed);
  } else {  // a tangent: the axis least along the normal, crossed with it
    pdVec3 axis = fabs(normal.x) <= fabs(normal.y) && fabs(normal.x) <= fabs(normal.z) ? pd_v3(1, 0, 0)
                  : fabs(normal.y) <= fabs(normal.z)                                    ? pd_v3(0, 1, 0)
                                                                                        : pd_v3(0, 0, 1);
    *along = pd_v3_normalize(pd_v3_cross(normal, axis));
  }
  pdVec3 ks = point_response(model, poses, id, point, *along);
  pdVec3 kn = point_response(model, poses, id, point, normal);
  e->slipInvMass = pd_v3_dot(*along, ks);
  pdVec3 off = pd_v3_sub(ks, pd_v3_add(pd_v3_scale(*along, e->slipInvMass), pd_v3_scale(normal, pd_v3_dot(normal, ks))));
  e->driftPerJt = pd_v3_norm(off);
  e->approachPerJt = fabs(pd_v3_dot(normal, ks));
  e->driftPerJn = pd_v3_norm(pd_v3_sub(kn, pd_v3_scale(normal, pd_v3_dot(normal, kn))));
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
    c->onsetImpulse = (pdVec3){0, 0, 0};
    double mass = c->modalMass > 0.0 && isfinite(c->modalMass) ? c->modalMass : point_mass(model, set, poses, c);
    if (isfinite(mass) && approach > 0.0 && k > 0.0) {
      onsetElement e = {.omega2 = k / mass, .damping = damper / mass, .mass = mass, .mu = p->mu,
                        .kt = pd_series(p->k1t, p->k2t), .ct = pd_series(p->c1t, p->c2t)};
      pdVec3 along;
      slip_element(model, poses, &c->id, c->point, n, du, &e, &along);
      // the pair's contacts that join together slow the slip together, as they do the approach (the modal mass): each
      // contact's element slows it by the ratio of its normal's modal to point inverse mass more, so that several
      // contacts, each stopping the slip alone, do not reverse it
      double pointMass = point_mass(model, set, poses, c);
      if (isfinite(pointMass) && mass < pointMass) e.slipInvMass *= pointMass / mass;
      onsetMotion m = onset_motion(&e, approach, c->onsetAge);
      double x = fmin(fmax(m.x, 0.0), fmax(c->depth, 0.0));
      pdSprings sp = springs_load(y + base + PD_CONTACT_STATE_SIZE * i);
      sp.s1n = -k * x / p->k1n;
      sp.s2n = k * x / p->k2n;
      double normalImpulse = mass * fmax(0.0, approach - fmax(m.u, 0.0));  // the pair's contacts together slow it so
      c->onsetImpulse = pd_v3_scale(n, normalImpulse);
      // friction over τ: sliding, the element's impulse against the slip (within the cone, the slip slowing under it),
      // and the tangential springs loaded by the slip since the onset, capped by the cone
      if (p->mu > 0.0 && e.kt > 0.0 && e.slip > 0.0) {
        c->onsetImpulse = pd_v3_sub(c->onsetImpulse, pd_v3_scale(along, fmax(m.jt, 0.0)));
        double ft = fmin(m.cone, e.kt * fmax(m.spring, 0.0));  // the spring's |F_t| on body 1, against the slip
        sp.s1t = pd_v3_scale(along, ft / p->k1t);                     // F_t = −k1t s1t = k2t s2t = −ft · along
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
