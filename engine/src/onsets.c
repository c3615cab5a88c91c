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
// where its pair would be after the τ since the onset: the pair's contacts that began in the step followed together from
// their onsets under the two bodies' masses and inertias (onset_group_motion), each contact's springs at the deflection
// and stretch reached and the bodies given the impulses they took, so its energy and phase are its own and its rest
// point sits d − x ≈ d (ωτ)²/6 deeper (d the depth reached without it).
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
// onset is followed with its pair's (onset_group_motion), and the rest point it leaves sits ≈ d (ωτ)²/6 deeper. Measured on
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
static bool joins_as_pair(const pdModel* model, const pdContactSet* set, const pdContactGeom* g, double age) {
  int a = g->id.body1, b = g->id.body2;
  if (!(g->depth > 0.0) || g->depth > PD_ONSET_PAIR_DEPTH_REL * pd_model_pair_delta_max(model, a, b)) return false;
  pdContactParams p = pd_onset_params(model, set, &g->id);
  double k = pd_series(p.k1n, p.k2n);
  return k > 0.0 && age * sqrt(k / p.massMin) <= PD_ONSET_PAIR_OMEGA_TAU;
}

// What the error bound (onset_bound.h) of joining new contact g (found at y1, poses in set->poses1) as a corrected
// onset is formed from, apart from its age and depth.
typedef struct onsetTerms {
  double omega;         // 1/s: the pair's fastest undamped frequency, √(k_s / m_min)
  double approach;      // m/s: its approach speed now
  double size;          // m: the smaller moving body's
  double mu;
  double dampingRate;   // 1/s: c_n / m_min, the normal damper's (series) over the pair's smaller mass
  double kn, cn, kt, ct;  // N/m, N·s/m: the model's series springs and dampers (the modal dampers never exceed them)
  pdVec3 normal;
  double deltaMax;      // m: the pair's δ_max, the error norm's weight of a contact spring
  double pointMass;     // kg: the point's effective mass along the normal (INFINITY: neither body moves)
  double lever;         // 1/kg: how far an impulse there may move the state, per kg·m/s
  double turning;       // m/s²: Ω² r, the bodies' turning's acceleration of the point (Ω their relative rate)
  pdVec3 applied;       // m/s²: the applied loads' relative acceleration of the point at the step's end (applied_at)
  pdVec3 appliedRate;   // m/s³: its rate (a ramped force)
} onsetTerms;

// A body's inverse inertia in the world frame at `pose`, R I⁻¹ Rᵀ: computed here, since the set's copy is the last
// installed list's (a step's start, and zero before the first), and an onset's bound is formed at the step's end.
static pdMat3 inverse_inertia_at(const pdBody* body, const pdPose* pose) {
  pdMat3 rt = pd_mat3_transpose(&pose->R), tmp = pd_mat3_mul(&body->invInertia, &rt);
  return pd_mat3_mul(&pose->R, &tmp);
}
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
  pdContactParams p = pd_onset_params(model, set, &g->id);
  pdVec3 du = relative_velocity(model, y1, set->poses1, &g->id, g->point);
  onsetTerms t = {.omega = sqrt(pd_series(p.k1n, p.k2n) / p.massMin), .approach = -pd_v3_dot(du, g->normal),
                  .size = INFINITY, .mu = p.mu, .dampingRate = pd_series(p.c1n, p.c2n) / p.massMin,
                  .normal = g->normal, .deltaMax = pd_model_pair_delta_max(model, a, b), .kn = pd_series(p.k1n, p.k2n),
                  .cn = pd_series(p.c1n, p.c2n), .kt = pd_series(p.k1t, p.k2t), .ct = pd_series(p.c1t, p.c2t)};
  pdVec3 spin = {0.0, 0.0, 0.0};
  double reach = 0.0, inverseMass = 0.0;
  for (int side = 0; side < 2; ++side) {
    const pdBody* body = &model->bodies[side == 0 ? a : b];
    if (body->fixed) continue;
    t.size = fmin(t.size, body->size);
    pdVec3 w = pd_layout_w(y1 + PD_BODY_STATE_SIZE * body->stateIndex);
    spin = side == 0 ? pd_v3_add(spin, w) : pd_v3_sub(spin, w);
    pdVec3 arm = pd_v3_sub(g->point, set->poses1[side == 0 ? a : b].x);
    reach = fmax(reach, pd_v3_norm(arm));
    // the point's inverse mass along the normal, and `lever`: a tangential impulse J at the point moves it by at most
    // |J| λ_max(K) <= |J| tr K (K its inverse mass matrix there, 1/m + [r]ᵀ I⁻¹ [r], tr <= 3/m + |r|² tr I⁻¹) and turns
    // the body by at most |J| |r| tr I⁻¹, which the error norm weighs by size / vmax
    pdVec3 rn = pd_v3_cross(arm, g->normal);
    pdMat3 invInertia = inverse_inertia_at(body, &set->poses1[side == 0 ? a : b]);
    inverseMass += body->invMass + pd_v3_dot(rn, pd_mat3_mulv(&invInertia, rn));
    double r = pd_v3_norm(arm), trInv = body->invInertia.m[0][0] + body->invInertia.m[1][1] + body->invInertia.m[2][2];
    t.lever += fmax(3.0 * body->invMass + r * r * trInv, r * trInv * body->size);
  }
  t.turning = pd_v3_dot(spin, spin) * reach;
  t.pointMass = inverseMass > 0.0 ? 1.0 / inverseMass : INFINITY;
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

// The bound of joining the contact `age` seconds after its onset at `depth`, its onset interpolated over a step of
// `step` seconds (onset_bound.h). The correction follows the pair's bodies under every contact of the pair that began in
// the step, at the step end's poses (onset_group_motion), so the slip a normal impulse makes, the push a tangential
// impulse gives along the normal and the pair's joint motion are its own. What it leaves: the bodies' masses and arms
// turning under the impulse (the velocity term, PD_ONSET_BOUND_C (ωτ)³, and μ times it for the cone's radius, μ F_n,
// which the normal impulse's error moves; the turning term, PD_ONSET_TURNING_C Ω² r τ ωτ), the rest point the normal
// deflection leaves (the position term), what the other forces on the bodies changed over the age (the applied term),
// and the onset time.
// The applied term: the motion starts from the relative velocity found at the step's end, which the applied loads
// (gravity, a scene's force and its torque) changed over the age without the contact; followed from the onset, the
// point's relative velocity differs from the motion's at time t since it by at most a (τ − t), a the loads' largest
// relative acceleration there (applied_over): ∫ a (τ − t) dt = a τ²/2 and ∫∫ = a τ³/3. Each force law is Lipschitz in its
// velocity (the damper by c, the spring by k on its integral, the cone's projection and the clamp by 1), so the normal
// impulse is off by at most c_n a_n τ²/2 + k_n a_n τ³/3, the tangential one by c_t a_t τ²/2 + k_t a_t τ³/3 (at most both
// cones' impulses, 2 μ J_n, J_n <= k_n v_n τ²/2 + c_n v_n τ) and by μ times the normal one's error; those impulses move
// the state by at most `lever` each; the springs are off by at most a τ²/2, over δ_max. The loads are followed by
// none of it: a body resting on others has them balanced by contacts the motion does not see.
// The onset time: App. C's interpolation moves the point along the chord of its step,
// which a turn's arc strays from by λ(1 − λ) Ω² r h²/2 at the fraction λ of the step (sway in contact_search.c), at the
// onset (λ = 1 − τ/h) by Ω² r τ (h − τ)/2, so the age is off by that over v_n, and the element, whose force per unit mass
// is at most (ω² τ + c/m) v_n, ends off by (ω² τ + c/m) Ω² r τ (h − τ)/2 in the velocity.
static double correction_bound(const pdModel* model, const onsetTerms* t, double age, double depth, double step) {
  double wt = t->omega * age, velocity = PD_ONSET_TURNING_C * t->turning * age * wt;
  velocity += 0.5 * (t->omega * t->omega * age + t->dampingRate) * t->turning * age * fmax(step - age, 0.0);
  if (t->mu > 0.0 && t->approach > 0.0) velocity += t->mu * PD_ONSET_BOUND_C * wt * wt * wt * t->approach;
  double spring = 0.0;
  if (isfinite(t->pointMass) && t->approach > 0.0) {
    double an, at, age2 = 0.5 * age * age, age3 = age * age * age / 3.0;
    applied_over(t, age, &an, &at);
    double normal = t->cn * an * age2 + t->kn * an * age3;  // N·s
    double cones = 2.0 * t->mu * (t->kn * t->approach * age2 + t->cn * t->approach * age);
    double tangential = t->mu > 0.0 ? fmin(t->ct * at * age2 + t->kt * at * age3, cones) : 0.0;
    velocity += t->lever * (tangential + (1.0 + t->mu) * normal);
    spring = fmax(an, t->mu > 0.0 ? at : 0.0) * age2 / t->deltaMax;
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
  // the retried step ends `age` past the onset, at c->onset h + age
  if (correction_bound(model, &t, hi, t.approach * hi, c->onset * h + hi) <= spend) {
    lo = hi;
  } else {
    for (int k = 0; k < PD_ONSET_AIM_BISECTIONS; ++k) {
      double age = 0.5 * (lo + hi);
      if (correction_bound(model, &t, age, t.approach * age, c->onset * h + age) <= spend)
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
    if (onsets != pd_onsetsExact && joins_as_pair(model, set, &c->geom, age)) {
      onsetTerms t = onset_terms(model, set, y1, t1, &c->geom);
      c->onsetBound = correction_bound(model, &t, age, c->geom.depth, h);
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

// The contacts of one pair whose onsets are followed together (onset_group_motion): a face on a face has its corners
// and edge crossings, 8 between two boxes; a pair with more is followed in groups of this many.
#define PD_ONSET_GROUP_MAX 16
// Substeps of classic RK4 between two onsets of a group: the motion is linear and short (ω τ <= PD_ONSET_PAIR_OMEGA_TAU),
// so they are exact to ~(ωτ/8)⁵ away from the cone's and the clamp's kinks; every onset falls on a substep's start, so
// that no substep straddles the jump of a damper's force.
#define PD_ONSET_PAIR_SUBSTEPS 8
// More substeps where the group's dampers relax faster (group_damping_rate): at most this rate times a substep, well
// inside classic RK4's stable 2.8 on the real axis, and as accurate per substep as 8 are for ωτ = 1.
#define PD_ONSET_SUBSTEP_DAMPING 1.0

typedef struct onsetPoint {
  int side;                   // +1: the contact's body 1 is the group's body A; −1: its body 2 is
  pdVec3 normal, arm[2];      // the contact's normal; its point less the centre of body A and of body B
  double kn, cn, kt, ct, mu;  // series constants (the modal dampers the contact has)
  double start;               // s: its onset, after the group's earliest
  pdVec3 free;                // m/s: Δu at the step's end (body 1's less body 2's), without the group's impulses
} onsetPoint;

typedef struct onsetGroup {
  int count;
  double tau;                 // s: the earliest onset's age
  double invMass[2];          // 1/kg: body A's, body B's (0: fixed)
  pdMat3 invInertia[2];       // world frame (zero: fixed)
  bool planar[2];
  onsetPoint points[PD_ONSET_GROUP_MAX];
} onsetGroup;

// State: body A's and body B's velocity changes (Δv, Δω each), then per contact its normal deflection, tangential
// stretch and impulse on its body 1.
enum { G_BODIES = 12, G_X = 0, G_Q = 1, G_J = 4, G_POINT = 7, G_STATE = G_BODIES + G_POINT * PD_ONSET_GROUP_MAX };
static pdVec3 group_vec(const double* s) { return (pdVec3){s[0], s[1], s[2]}; }
static void group_store(double* s, pdVec3 v) { s[0] = v.x, s[1] = v.y, s[2] = v.z; }

// Δu of contact p at time `time` since the group's earliest onset, state s.
static pdVec3 group_du(const onsetPoint* p, const double* s) {
  pdVec3 a = pd_v3_add(group_vec(s), pd_v3_cross(group_vec(s + 3), p->arm[0]));
  pdVec3 b = pd_v3_add(group_vec(s + 6), pd_v3_cross(group_vec(s + 9), p->arm[1]));
  return pd_v3_add(p->free, pd_v3_scale(pd_v3_sub(a, b), p->side));
}

// Contact p's force on its body 1 at deflection x, stretch q and relative velocity du, by the contact law: along the
// normal a Kelvin–Voigt element that never pulls; across it the spring and damper in stick, on the cone μ F_n in slip
// with the stretch relaxing towards it through the damper, k_t q + c_t q̇ = μ F_n along the trial force
// (contact_force.h). *stretchRate gets q̇, *cone μ F_n.
static pdVec3 group_force(const onsetPoint* p, double x, pdVec3 q, pdVec3 du, pdVec3* stretchRate, double* cone) {
  double fn = fmax(0.0, p->kn * x - p->cn * pd_v3_dot(du, p->normal));  // N
  pdVec3 slip = pd_v3_sub(du, pd_v3_scale(p->normal, pd_v3_dot(du, p->normal)));
  pdVec3 trial = pd_v3_add(pd_v3_scale(q, p->kt), pd_v3_scale(slip, p->ct)), ft = trial;
  double size = pd_v3_norm(trial);
  *cone = p->mu * fn;
  *stretchRate = slip;
  if (size > *cone) {
    ft = size > 0.0 ? pd_v3_scale(trial, *cone / size) : (pdVec3){0.0, 0.0, 0.0};
    if (p->ct > 0.0) *stretchRate = pd_v3_scale(pd_v3_sub(ft, pd_v3_scale(q, p->kt)), 1.0 / p->ct);
  }
  return pd_v3_sub(pd_v3_scale(p->normal, fn), ft);
}

// The state's components the bodies and contacts [0, active) take: the rest of a group's state stays as it is.
static int group_size(int active) { return G_BODIES + G_POINT * active; }

// The rate of state s, the contacts [0, active) begun (they are sorted by their onsets): the system is autonomous.
// Only the group_size(active) components that move are written.
static void group_rate(const onsetGroup* g, int active, const double* s, double* r) {
  for (int j = 0; j < group_size(active); ++j) r[j] = 0.0;
  for (int i = 0; i < active; ++i) {
    const onsetPoint* p = &g->points[i];
    const double* sp = s + G_BODIES + G_POINT * i;
    double* rp = r + G_BODIES + G_POINT * i;
    pdVec3 du = group_du(p, s), stretchRate;
    double cone;
    pdVec3 force = group_force(p, sp[G_X], group_vec(sp + G_Q), du, &stretchRate, &cone);
    rp[G_X] = -pd_v3_dot(du, p->normal);
    group_store(rp + G_Q, stretchRate);
    group_store(rp + G_J, force);
    pdVec3 onA = pd_v3_scale(force, p->side);  // on body A; body B takes its opposite
    for (int b = 0; b < 2; ++b) {
      pdVec3 f = b == 0 ? onA : pd_v3_scale(onA, -1.0);
      pdVec3 dv = pd_v3_scale(f, g->invMass[b]), dw = pd_mat3_mulv(&g->invInertia[b], pd_v3_cross(p->arm[b], f));
      if (g->planar[b]) dv.y = 0.0, dw.x = dw.z = 0.0;  // the plane takes the out-of-plane part (model.h)
      group_store(r + 6 * b, pd_v3_add(group_vec(r + 6 * b), dv));
      group_store(r + 6 * b + 3, pd_v3_add(group_vec(r + 6 * b + 3), dw));
    }
  }
}

// A bound on the rate (1/s) at which the group's normal dampers relax its points' approach: Σ c_n w_n over its contacts,
// w_n the point's inverse mass along its normal (both bodies, turning included). The join test bounds the springs'
// frequency (ωτ <= PD_ONSET_PAIR_OMEGA_TAU), not the dampers': a light body's pair in a stack has them sized for the
// stack's slow mode, overdamped by √(M/m) for its own, and a 1.1 mg blade under a 49 g prism had c_n w_n τ = 35 over a
// pair onset, which classic RK4 in 8 substeps (stable to a real rate of 2.8 per substep) took to 10^23 J (soak campaign
// 62, scene 6037: the integration failed at its minimum step).
static double group_damping_rate(const onsetGroup* g) {
  double rate = 0.0;
  for (int i = 0; i < g->count; ++i) {
    const onsetPoint* p = &g->points[i];
    double w = 0.0;
    for (int b = 0; b < 2; ++b) {
      pdVec3 rn = pd_v3_cross(p->arm[b], p->normal);
      w += g->invMass[b] + pd_v3_dot(rn, pd_mat3_mulv(&g->invInertia[b], rn));
    }
    rate += p->cn * w;
  }
  return rate;
}

// The motion of a group of contacts of one pair over the τ since the earliest's onset (points sorted by onset): the
// changes of the two bodies' velocities from the step's end's, under every begun contact's force through the bodies'
// masses and inertias at the step end's poses. So the slip a normal impulse makes at an off-centre point, the push a
// tangential impulse gives along the normal and the pair's contacts beginning together are followed, not bounded
// (onset_bound.h); the other forces on the bodies over τ are bounded (correction_bound). s holds the state at the
// earliest onset (the velocity changes and deflections 0, the stretches those the contacts join with) and gets the
// state at the step's end.
static void onset_group_motion(const onsetGroup* g, double s[G_STATE]) {
  double k[4][G_STATE], tmp[G_STATE];
  double time = 0.0, rate = group_damping_rate(g);
  for (int active = 1; active <= g->count; ++active) {
    double end = active < g->count ? g->points[active].start : g->tau;
    if (!(end > time)) continue;  // onsets together: begun at once
    int substeps = PD_ONSET_PAIR_SUBSTEPS;
    if ((end - time) * rate > PD_ONSET_PAIR_SUBSTEPS * PD_ONSET_SUBSTEP_DAMPING)
      substeps = (int)ceil((end - time) * rate / PD_ONSET_SUBSTEP_DAMPING);
    double dt = (end - time) / substeps;
    // the contacts not begun yet have no rate: their components are not stepped but for the one change adding a
    // zero rate makes (a −0 becomes +0)
    int n = group_size(active);
    for (int j = n; j < group_size(g->count); ++j) s[j] += 0.0;
    for (int i = 0; i < substeps; ++i) {
      group_rate(g, active, s, k[0]);
      for (int j = 0; j < n; ++j) tmp[j] = s[j] + 0.5 * dt * k[0][j];
      group_rate(g, active, tmp, k[1]);
      for (int j = 0; j < n; ++j) tmp[j] = s[j] + 0.5 * dt * k[1][j];
      group_rate(g, active, tmp, k[2]);
      for (int j = 0; j < n; ++j) tmp[j] = s[j] + dt * k[2][j];
      group_rate(g, active, tmp, k[3]);
      for (int j = 0; j < n; ++j) s[j] += dt / 6.0 * (k[0][j] + 2.0 * k[1][j] + 2.0 * k[2][j] + k[3][j]);
    }
    time = end;
  }
}

// Whether contacts a and b are between the same two bodies.
static bool same_pair(const pdContactId* a, const pdContactId* b) {
  return (a->body1 == b->body1 && a->body2 == b->body2) || (a->body1 == b->body2 && a->body2 == b->body1);
}

// Follows the pair onsets members[0 .. count) of set (all of one pair, at most PD_ONSET_GROUP_MAX) at state y from their
// onsets to the step's end together (onset_group_motion), and puts each where it gets to: its normal springs at the
// deflection reached (at most its depth), split as series springs share a static load (k1 s1 + k2 s2 = 0), its
// tangential ones at the stretch reached, held within the cone, and its onsetImpulse the impulse it gave.
static void start_group(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses, const int* members,
                        int count) {
  int base = spring_base(model);
  onsetGroup g = {.count = count};
  const pdContactId* first = &set->items[members[0]].id;
  int bodies[2] = {first->body1, first->body2};
  for (int b = 0; b < 2; ++b) {
    const pdBody* body = &model->bodies[bodies[b]];
    g.invMass[b] = body->fixed ? 0.0 : body->invMass;
    g.invInertia[b] = body->fixed ? pd_mat3_zero() : set->invInertiaWorld[bodies[b]];
    g.planar[b] = body->planar;
  }
  // by onset, the earliest first (insertion: a group is small); the order of equal onsets is the list's
  int order[PD_ONSET_GROUP_MAX] = {0};
  for (int i = 0; i < count; ++i) {
    int j = i;
    while (j > 0 && set->items[members[order[j - 1]]].onsetAge < set->items[members[i]].onsetAge) {
      order[j] = order[j - 1];
      --j;
    }
    order[j] = i;
  }
  g.tau = set->items[members[order[0]]].onsetAge;
  double s[G_STATE] = {0.0};
  for (int i = 0; i < count; ++i) {
    const contactSlot* c = &set->items[members[order[i]]];
    const pdContactParams* p = &c->params;
    onsetPoint* q = &g.points[i];
    q->side = c->id.body1 == bodies[0] ? 1 : -1;
    q->normal = c->normal;
    for (int b = 0; b < 2; ++b) q->arm[b] = pd_v3_sub(c->point, poses[bodies[b]].x);
    q->kn = pd_series(p->k1n, p->k2n), q->cn = pd_series(p->c1n, p->c2n);
    q->kt = pd_series(p->k1t, p->k2t), q->ct = pd_series(p->c1t, p->c2t), q->mu = p->mu;
    if (!(q->mu > 0.0) || !(q->kt > 0.0)) q->kt = q->ct = q->mu = 0.0;  // no friction
    q->start = g.tau - c->onsetAge;
    q->free = relative_velocity(model, y, poses, &c->id, c->point);
    // a slip at the rounding of Δu is none: its direction is noise, and friction along it broke a flush stack's symmetry
    pdVec3 slip = pd_v3_sub(q->free, pd_v3_scale(q->normal, pd_v3_dot(q->free, q->normal)));
    if (pd_v3_norm(slip) <= PD_ONSET_PAIR_SLIP_REL * pd_v3_norm(q->free)) q->free = pd_v3_sub(q->free, slip);
    // the tangential springs it joins with (a kept history, else 0) are where its stretch starts: F_t = −k1t s1t
    pdSprings sp = springs_load(y + base + PD_CONTACT_STATE_SIZE * members[order[i]]);
    pdVec3 s0 = q->kt > 0.0 ? pd_v3_scale(sp.s1t, p->k1t / q->kt) : (pdVec3){0.0, 0.0, 0.0};
    group_store(s + G_BODIES + G_POINT * i + G_Q, pd_v3_sub(s0, pd_v3_scale(q->normal, pd_v3_dot(s0, q->normal))));
  }
  onset_group_motion(&g, s);
  for (int i = 0; i < count; ++i) {
    contactSlot* c = &set->items[members[order[i]]];
    const pdContactParams* p = &c->params;
    const onsetPoint* q = &g.points[i];
    const double* sp = s + G_BODIES + G_POINT * i;
    double* springs = y + base + PD_CONTACT_STATE_SIZE * members[order[i]];
    pdSprings out = springs_load(springs);
    double x = fmin(fmax(sp[G_X], 0.0), fmax(c->depth, 0.0));
    out.s1n = -q->kn * x / p->k1n;
    out.s2n = q->kn * x / p->k2n;
    c->onsetImpulse = group_vec(sp + G_J);
    if (q->kt > 0.0) {  // the spring's force k_t q, held within the cone at the step's end: F_t = −k1t s1t = k2t s2t
      pdVec3 du = group_du(q, s), stretchRate;
      double cone;
      pdVec3 stretch = group_vec(sp + G_Q);
      stretch = pd_v3_sub(stretch, pd_v3_scale(q->normal, pd_v3_dot(stretch, q->normal)));
      (void)group_force(q, sp[G_X], stretch, du, &stretchRate, &cone);
      double force = q->kt * pd_v3_norm(stretch);
      if (force > cone) stretch = pd_v3_scale(stretch, cone / force);
      out.s1t = pd_v3_scale(stretch, q->kt / p->k1t);
      out.s2t = pd_v3_scale(stretch, -q->kt / p->k2t);
    }
    springs_store(springs, &out);
  }
}

// Pair onsets of a list just installed at state y (poses those of y; world inverse inertias and modal dampers set):
// the contacts with an onset age τ > 0 are followed from their onsets, each pair's together (start_group), and put
// where they get to, their bodies given the impulses they gave. Their energy and phase are then their own; a rest point
// sits deeper by the depth d reached without the contact, less the deflection x (≈ d (ωτ)²/6). All impulses are formed
// before any is applied, so the list's order does not matter. Returns the number of such contacts.
int pd_onsets_start_late(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses) {
  int started = 0, members[PD_ONSET_GROUP_MAX];
  for (int i = 0; i < set->count;) {
    int end = i + 1;  // the pair's contacts: the list holds them together (sorted by the unordered pair first)
    while (end < set->count && same_pair(&set->items[i].id, &set->items[end].id)) ++end;
    int count = 0;
    for (int j = i; j < end; ++j) {
      if (set->items[j].onsetAge <= 0.0) continue;
      members[count++] = j;
      ++started;
      if (count == PD_ONSET_GROUP_MAX) {
        start_group(model, set, y, poses, members, count);
        count = 0;
      }
    }
    if (count > 0) start_group(model, set, y, poses, members, count);
    i = end;
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
