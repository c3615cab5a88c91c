// polydyn — the force of one contact and the rates of its springs (paper §3.1).
//
// Design note
// The contact mechanism is massless, so its force balance (eqs. (1), (2)) plus the kinematic relation (4)
// determine the force and the spring rates from the spring deflections and Δu alone: an algebraic map,
// evaluated once per contact per derivative call. The normal and the tangential directions are solved
// one after the other (the tangential one needs F_n for the friction limit). Each direction has four
// damper configurations, chosen by exact zeros, and each is its own branch below with its derivation —
// never a division by a tiny damper. Two families result:
// - "damper-determined" (both dampers > 0, eqs. (5)–(10)): the force depends on Δu through the dampers and
//   the friction law is solved for λ in closed form (eq. (9));
// - "spring-determined" (one or both dampers zero, §3.1.5, §3.1.6): the force is a spring's force, fixed
//   by the state; the friction law then limits the RATE of the force-carrying undamped spring: when that
//   spring is on (or beyond) the cone and would lengthen, the lengthening part of its rate is absorbed by
//   slip of the surface elements (Δw_t parallel to the spring, so Δw_t = −λ F_t with λ >= 0 holds). In
//   the same family a state beyond the cone (F_n fell within a step) reports the force clipped to the
//   cone; the springs themselves are clipped by pd_springs_realign at the end of the step.
// The paper's §3.4 clips the tangential springs to the cone after every step in every branch. In the
// damper-determined family that is not needed (the force is on the cone by eq. (9) however long the springs
// are, and a spring beyond it shortens through Δw_t at the rate (|b_t| − F⁺)/c*) and it is harmful: it moves
// the state by an amount set by where the steps happen to end while F_n falls, an error that does not shrink
// with the tolerance (cases/sweep/eccentric_impact.scene: 4e-4 m apart at tol 1e-8 and 1e-12 with the clip,
// 5e-8 without). pd_springs_realign clips only the spring-determined branches.
// Proportional dampers (c1/k1 = c2/k2 = τ, params->proportionalN/T): the surface elements obey
// (c1 + c2) ẋ + (k1 + k2) x = 0 for x ∝ k1 s1 + k2 s2 (eq. (16)), which starts at 0 and stays there; its
// decay rate 1/τ is the fastest in the model (for small ζ far faster than the contact's own frequency), so
// integrating it would set the step. Those branches drop the term (it is 0 up to roundoff, and
// pd_springs_realign restores it exactly after each step): what remains is one Kelvin–Voigt element.
// Notation: F⁺ = μ max(F_n, 0) is the friction limit; x̂ = x/|x|.
#include "contact_force.h"

#include <math.h>

#include "polydyn/error.h"

// ---------------------------------------------------------------- normal direction

// Fills out->fn, out->rate.s1n, out->rate.s2n. du_n = Δu·n.
static void normal_force(const pdContactParams* p, double s1, double s2, double du_n, pdContactForce* out) {
  const double k1 = p->k1n, k2 = p->k2n, c1 = p->c1n, c2 = p->c2n;
  if (c1 > 0.0 && c2 > 0.0 && p->proportionalN) {
    // One Kelvin–Voigt element (see the design note): with k1 s1 + k2 s2 = 0 the damped branch below gives
    //   ṡ1 = c2 Δu_n/(c1 + c2) = k2 Δu_n/(k1 + k2), ṡ2 = −k1 Δu_n/(k1 + k2), F_n = −k1 s1 − c_s Δu_n.
    const double k = k1 + k2;
    out->fn = -k1 * s1 - (c1 * c2 / (c1 + c2)) * du_n;
    out->rate.s1n = k2 * du_n / k;
    out->rate.s2n = -k1 * du_n / k;
  } else if (c1 > 0.0 && c2 > 0.0) {
    // Both damped (§3.1.4). From (1) and (4) with ṡ2 = ṡ1 − Δu_n:
    //   −k1 s1 − c1 ṡ1 = k2 s2 + c2 (ṡ1 − Δu_n)  ⇒  ṡ1 = (c2 Δu_n − k1 s1 − k2 s2)/(c1 + c2),
    //   ṡ2 = ṡ1 − Δu_n = (−c1 Δu_n − k1 s1 − k2 s2)/(c1 + c2),
    //   F_n = −k1 s1 − c1 ṡ1 = −b_n, b_n = (c2 k1 s1 − c1 k2 s2 + c1 c2 Δu_n)/(c1 + c2)   (eqs. (5), (6)).
    const double c = c1 + c2, spring = k1 * s1 + k2 * s2;
    out->fn = -(c2 * k1 * s1 - c1 * k2 * s2 + c1 * c2 * du_n) / c;
    out->rate.s1n = (c2 * du_n - spring) / c;
    out->rate.s2n = (-c1 * du_n - spring) / c;
  } else if (c1 == 0.0 && c2 == 0.0) {
    // No damping (§3.1.5): the springs are in series, F_n = −k1 s1 = k2 s2 at all times, so
    // k1 ṡ1 = −k2 ṡ2, and with ṡ1 − ṡ2 = Δu_n:
    //   ṡ1 = k2 Δu_n/(k1 + k2), ṡ2 = −k1 Δu_n/(k1 + k2), F_n = −k1 s1.
    // These rates keep k1 s1 + k2 s2 constant (0 from the onset), so both sides of (1) stay equal.
    PD_ASSERT(k1 + k2 > 0.0);
    const double k = k1 + k2;
    out->fn = -k1 * s1;
    out->rate.s1n = k2 * du_n / k;
    out->rate.s2n = -k1 * du_n / k;
  } else if (c1 == 0.0) {
    // c1n = 0 < c2n (§3.1.6): spring 1 alone carries F_n = −k1 s1; the damped side balances it:
    //   −k1 s1 = k2 s2 + c2 ṡ2  ⇒  ṡ2 = −(k1 s1 + k2 s2)/c2,  ṡ1 = Δu_n + ṡ2.
    // (the limit c1 → 0 of the damped branch: b_n → k1 s1.)
    const double relax = -(k1 * s1 + k2 * s2) / c2;
    out->fn = -k1 * s1;
    out->rate.s1n = du_n + relax;
    out->rate.s2n = relax;
  } else {
    // c2n = 0 < c1n (§3.1.6, the mirror case): spring 2 alone carries F_n = k2 s2:
    //   −k1 s1 − c1 ṡ1 = k2 s2  ⇒  ṡ1 = −(k1 s1 + k2 s2)/c1,  ṡ2 = ṡ1 − Δu_n.
    // (the limit c2 → 0 of the damped branch: b_n → −k2 s2.)
    const double relax = -(k1 * s1 + k2 * s2) / c1;
    out->fn = k2 * s2;
    out->rate.s1n = relax;
    out->rate.s2n = relax - du_n;
  }
}

// ---------------------------------------------------------------- tangential direction

// The tangential branch: decided by the force law (free), or held in stick or slip (pd_contact_force_held).
typedef enum contactMode { modeFree, modeStick, modeSlip } contactMode;

static pdVec3 in_plane(pdVec3 v, pdVec3 n) { return pd_v3_muladd(v, -pd_v3_dot(v, n), n); }

// Both tangential dampers > 0: the damper-determined branch (tangential_damped), whose force is on the cone by
// eq. (9) whatever the springs' length; otherwise one of the spring-determined ones (design note).
static bool tangential_damper_determined(const pdContactParams* p) { return p->c1t > 0.0 && p->c2t > 0.0; }

// Both tangential dampers > 0 (§3.1.4). Same algebra as the normal direction with Δu_n replaced by
// Δu_t − Δw_t:
//   F_t = −b_t + c* Δw_t, c* = c1 c2/(c1 + c2), b_t = (c2 k1 s1 − c1 k2 s2 + c1 c2 Δu_t)/(c1 + c2)   (5), (6)
// (the paper's (6) prints "c_2" in the last term; it is c2t). With Δw_t = −λ F_t: F_t = −b_t/(1 + λ c*).
// Stick when |b_t| <= F⁺: λ = 0, Δw_t = 0, F_t = −b_t. Slip otherwise: λ = (|b_t| − F⁺)/(c* F⁺) (9), then
// F_t = −F⁺ b̂_t exactly on the cone and Δw_t = λ b_t/(1 + λ c*) = (|b_t| − F⁺)/c* b̂_t (10); the last form
// stays finite for F⁺ = 0 (λ = ∞: the springs relax through their dampers, F_t = 0).
// Rates: ṡ1 = (c2 (Δu_t − Δw_t) − k1 s1 − k2 s2)/(c1 + c2), ṡ2 = (−c1 (Δu_t − Δw_t) − k1 s1 − k2 s2)/(c1 + c2).
// `forced` (contactMode): the branch the force law decides (free), or stick or slip held whatever |b_t| is. Held slip
// below the cone continues slip's formulas: F_t = −F⁺ b̂_t stays on the cone and Δw_t = (|b_t| − F⁺)/c* b̂_t turns
// against b_t (0 with b_t); held stick is F_t = −b_t beyond the cone. out->coneMargin = F⁺ − |b_t| either way.
static void tangential_damped(const pdContactParams* p, pdVec3 s1, pdVec3 s2, pdVec3 dut, double limit,
                              contactMode forced, pdContactForce* out) {
  const double k1 = p->k1t, k2 = p->k2t, c1 = p->c1t, c2 = p->c2t, c = c1 + c2, cstar = c1 * c2 / c;
  pdVec3 bt = pd_v3_scale(pd_v3_add(pd_v3_sub(pd_v3_scale(s1, c2 * k1), pd_v3_scale(s2, c1 * k2)),
                                    pd_v3_scale(dut, c1 * c2)),
                          1.0 / c);
  double bn = pd_v3_norm(bt);
  pdVec3 dw = {0, 0, 0};
  out->coneMargin = limit - bn;
  bool slip = forced == modeFree ? !(bn <= limit) : forced == modeSlip;
  if (!slip) {
    out->ft = pd_v3_scale(bt, -1.0);
  } else if (bn == 0.0) {  // held slip with no force to follow: none
    out->slip = true;
    out->lambda = 0.0;
    out->ft = dw;
  } else {
    pdVec3 dir = pd_v3_scale(bt, 1.0 / bn);
    out->slip = true;
    out->lambda = limit > 0.0 ? (bn - limit) / (cstar * limit) : INFINITY;
    out->ft = pd_v3_scale(dir, -limit);
    dw = pd_v3_scale(dir, (bn - limit) / cstar);
  }
  out->dw = dw;
  pdVec3 v = pd_v3_sub(dut, dw);
  // proportional dampers: the surface elements' relaxation is 0 (design note), not integrated
  pdVec3 spring = p->proportionalT ? (pdVec3){0, 0, 0} : pd_v3_add(pd_v3_scale(s1, k1), pd_v3_scale(s2, k2));
  out->rate.s1t = pd_v3_scale(pd_v3_sub(pd_v3_scale(v, c2), spring), 1.0 / c);
  out->rate.s2t = pd_v3_scale(pd_v3_add(pd_v3_scale(v, c1), spring), -1.0 / c);
}

// The friction limit of the spring-determined branches. `carrier` is the undamped spring that carries the
// force (force = sign · k · carrier), `stick` its rate if the surface elements stuck. Decides stick/slip,
// sets out->ft, out->slip, and returns `removed`: the part of the carrier's stick rate that slip absorbs
// (0 in stick); the caller turns it into Δw_t and λ for its branch.
//   |F_s| <  F⁺                      : stick, F_t = F_s.
//   |F_s| >= F⁺ and ŝ · stick > 0   : the spring would lengthen beyond the cone: slip, F_t = F⁺ F̂_s, and
//                                     the lengthening part (ŝ · stick) ŝ is removed (rotation is kept).
//   |F_s| >  F⁺ and not lengthening  : the force is clipped to the cone (slip), the springs unload, λ = 0.
//   F⁺ = 0                           : no friction force; the carrier cannot load at all: its whole stick
//                                     rate is removed (slip when that rate or F_s is non-zero).
static pdVec3 cone_limit(pdVec3 force, pdVec3 carrier, pdVec3 stick, double limit, pdContactForce* out) {
  const pdVec3 zero = {0, 0, 0};
  double f = pd_v3_norm(force);
  if (limit <= 0.0) {
    out->ft = zero;
    out->slip = f > 0.0 || pd_v3_dot(stick, stick) > 0.0;
    return stick;
  }
  if (f < limit) {
    out->ft = force;
    return zero;
  }
  out->ft = pd_v3_scale(force, limit / f);
  double len = pd_v3_norm(carrier);
  double grow = len > 0.0 ? pd_v3_dot(carrier, stick) / len : 0.0;  // d|s|/dt under stick, m/s
  if (grow > 0.0) {
    out->slip = true;
    return pd_v3_scale(carrier, grow / len);
  }
  out->slip = f > limit;
  return zero;
}

// λ and Δw_t from the slip velocity of the spring-determined branches: Δw_t = −λ F_t with |F_t| = F⁺ and
// Δw_t ∥ F_t, so λ = |Δw_t|/F⁺ (∞ when F⁺ = 0 and Δw_t ≠ 0).
static void set_slip_velocity(pdVec3 dw, double limit, pdContactForce* out) {
  out->dw = dw;
  double m = pd_v3_norm(dw);
  out->lambda = m == 0.0 ? 0.0 : (limit > 0.0 ? m / limit : INFINITY);
}

// Both tangential dampers zero (§3.1.5): springs in series, F_t = −k1 s1 = k2 s2, and in stick
//   ṡ1 = k2 Δu_t/(k1 + k2), ṡ2 = −k1 Δu_t/(k1 + k2)   (as in the normal direction; Δw_t = 0).
// In slip the paper only says |s_it| <= F⁺/k_it: the springs do not grow further along their direction.
// Precisely: with Δw_t in the rates, ṡ1 = k2 (Δu_t − Δw_t)/(k1 + k2); cone_limit removes r = (ŝ1 · ṡ1) ŝ1
// from ṡ1, i.e. Δw_t = r (k1 + k2)/k2 = (ŝ1 · Δu_t) ŝ1. Since F̂_t = −ŝ1, Δw_t = −λ F_t with
// λ = (ŝ1 · Δu_t)/F⁺ >= 0. ṡ2 = −(k1/k2) ṡ1 keeps the springs balanced.
static void tangential_undamped(const pdContactParams* p, pdVec3 s1, pdVec3 dut, double limit, pdContactForce* out) {
  const double k1 = p->k1t, k2 = p->k2t, k = k1 + k2;
  pdVec3 force = pd_v3_scale(s1, -k1);
  pdVec3 stick1 = pd_v3_scale(dut, k2 / k);
  pdVec3 removed = cone_limit(force, s1, stick1, limit, out);
  // removed = k2/(k1+k2) Δw_t (parallel to ŝ1, or all of stick1 when F⁺ = 0)
  pdVec3 dw = pd_v3_dot(removed, removed) > 0.0 ? pd_v3_scale(removed, k / k2) : (pdVec3){0, 0, 0};
  set_slip_velocity(dw, limit, out);
  pdVec3 v = pd_v3_sub(dut, dw);
  out->rate.s1t = pd_v3_scale(v, k2 / k);
  out->rate.s2t = pd_v3_scale(v, -k1 / k);
}

// c1t = 0 < c2t (§3.1.6, the paper's own example): spring 1 carries F_t = −k1 s1 = k2 s2 + c2 ṡ2, so
//   ṡ2 = −(k1 s1 + k2 s2)/c2 (independent of slip),  ṡ1 = ṡ2 + Δu_t − Δw_t.
// Stick: Δw_t = 0. Slip: cone_limit removes r = (ŝ1 · ṡ1,stick) ŝ1 from ṡ1, i.e. Δw_t = r; with
// F̂_t = −ŝ1, λ = (ŝ1 · ṡ1,stick)/F⁺ >= 0.
static void tangential_mixed1(const pdContactParams* p, pdVec3 s1, pdVec3 s2, pdVec3 dut, double limit,
                              pdContactForce* out) {
  const double k1 = p->k1t, k2 = p->k2t, c2 = p->c2t;
  pdVec3 relax = pd_v3_scale(pd_v3_add(pd_v3_scale(s1, k1), pd_v3_scale(s2, k2)), -1.0 / c2);
  pdVec3 stick1 = pd_v3_add(relax, dut);
  pdVec3 dw = cone_limit(pd_v3_scale(s1, -k1), s1, stick1, limit, out);
  set_slip_velocity(dw, limit, out);
  out->rate.s1t = pd_v3_sub(stick1, dw);
  out->rate.s2t = relax;
}

// c2t = 0 < c1t (§3.1.6, mirror case derived here): spring 2 carries F_t = k2 s2 = −k1 s1 − c1 ṡ1, so
//   ṡ1 = −(k1 s1 + k2 s2)/c1 (independent of slip),  ṡ2 = ṡ1 − Δu_t + Δw_t.
// Stick: Δw_t = 0. Slip: cone_limit removes r = (ŝ2 · ṡ2,stick) ŝ2 from ṡ2, i.e. Δw_t = −r; with
// F̂_t = ŝ2, Δw_t = −λ F_t gives λ = (ŝ2 · ṡ2,stick)/F⁺ >= 0.
static void tangential_mixed2(const pdContactParams* p, pdVec3 s1, pdVec3 s2, pdVec3 dut, double limit,
                              pdContactForce* out) {
  const double k1 = p->k1t, k2 = p->k2t, c1 = p->c1t;
  pdVec3 relax = pd_v3_scale(pd_v3_add(pd_v3_scale(s1, k1), pd_v3_scale(s2, k2)), -1.0 / c1);
  pdVec3 stick2 = pd_v3_sub(relax, dut);
  pdVec3 removed = cone_limit(pd_v3_scale(s2, k2), s2, stick2, limit, out);
  pdVec3 dw = pd_v3_scale(removed, -1.0);
  set_slip_velocity(dw, limit, out);
  out->rate.s1t = relax;
  out->rate.s2t = pd_v3_sub(stick2, removed);
}

// ---------------------------------------------------------------- public

// The force law with the tangential branch `forced` (held, or free) and, with `pushing`, the friction limit μ F_n
// continued below F_n = 0 (a contact held pushing: no kink where the normal force crosses zero).
static void contact_force(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du, contactMode forced,
                          bool pushing, pdContactForce* out) {
#ifdef PD_SELF_CHECKS
  // checked where constants are formed (pd_model_contact_params, pd_contact_modal_damping); here, once per contact
  // per evaluation, 2 % of cases/hard/stack_10.scene's instructions: in the sanitizer and Debug builds only
  PD_ASSERT(pd_contact_params_valid(p));
#endif
  // each field written once: normal_force writes fn and the normal rates, every tangential branch ft, dw and the
  // tangential rates, and slip and λ where it slips (a compound literal of the whole struct first compiled to
  // `rep stos`, 10 % of this function: perf)
  out->slip = false;
  out->lambda = 0.0;
  out->coneMargin = INFINITY;
  double du_n = pd_v3_dot(du, n);
  normal_force(p, s->s1n, s->s2n, du_n, out);

  if (p->mu > 0.0 && p->k1t + p->k2t > 0.0) {
    // fn > 0 ? fn : 0 equals fmax(fn, 0) for every fn (NaN and −0 included), without fmax's libm call
    double limit = p->mu * (pushing || out->fn > 0.0 ? out->fn : 0.0);
    pdVec3 dut = in_plane(du, n), s1 = in_plane(s->s1t, n), s2 = in_plane(s->s2t, n);
    if (tangential_damper_determined(p))
      tangential_damped(p, s1, s2, dut, limit, forced, out);
    else if (p->c1t == 0.0 && p->c2t == 0.0)
      tangential_undamped(p, s1, dut, limit, out);
    else if (p->c1t == 0.0)
      tangential_mixed1(p, s1, s2, dut, limit, out);
    else
      tangential_mixed2(p, s1, s2, dut, limit, out);
  } else {
    const pdVec3 zero = {0, 0, 0};
    out->ft = out->dw = zero;
    out->rate.s1t = out->rate.s2t = zero;
  }
  out->force = pd_v3_muladd(out->ft, out->fn, n);
}

void pd_contact_force(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du, pdContactForce* out) {
  contact_force(p, s, n, du, modeFree, false, out);
}

void pd_contact_force_held(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du, bool pushing, bool slip,
                           pdContactForce* out) {
  contact_force(p, s, n, du, slip ? modeSlip : modeStick, pushing, out);
}

bool pd_contact_slip_held(const pdContactParams* p) {
  return p->mu > 0.0 && p->k1t + p->k2t > 0.0 && tangential_damper_determined(p);
}

double pd_contact_normal_force(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du) {
  pdContactForce out;
  normal_force(p, s->s1n, s->s2n, pd_v3_dot(du, n), &out);
  return out.fn;
}

// The smallest rotation taking unit a to unit b, applied to x (Rodrigues with v = a × b, c = a · b):
//   R x = c x + v × x + (v · x)/(1 + c) v.
// When a and b are (nearly) opposite the axis is undefined; any axis u ⊥ a then gives a half turn,
// R x = 2 (u · x) u − x. Below this 1 + c the Rodrigues factor 1/(1 + c) would amplify roundoff in v
// beyond 1e-8 relative; a normal that flips by ~180° within one accepted step is a degenerate event
// anyway (the springs are reoriented, not lost).
#define PD_REALIGN_ANTIPARALLEL_TOL 1e-8

// The rotation, formed once for both tangential springs of a contact (the same numbers as forming it for each).
typedef struct minRotation {
  bool halfTurn;       // a and b (nearly) opposite: the half turn about `axis`
  double c, onePlusC;  // a · b and 1 + a · b
  pdVec3 v;            // a × b (not half turn)
  pdVec3 axis;         // unit, ⊥ a (half turn)
} minRotation;

static minRotation min_rotation(pdVec3 a, pdVec3 b) {
  minRotation m;
  m.c = pd_v3_dot(a, b);
  m.onePlusC = 1.0 + m.c;
  m.halfTurn = !(m.onePlusC > PD_REALIGN_ANTIPARALLEL_TOL);
  if (!m.halfTurn) {
    m.v = pd_v3_cross(a, b);
    return m;
  }
  // a half turn about an axis ⊥ a: cross a with the coordinate axis it is least aligned with
  pdVec3 e = fabs(a.x) <= fabs(a.y) && fabs(a.x) <= fabs(a.z) ? pd_v3(1, 0, 0)
             : (fabs(a.y) <= fabs(a.z) ? pd_v3(0, 1, 0) : pd_v3(0, 0, 1));
  m.axis = pd_v3_normalize(pd_v3_cross(a, e));
  return m;
}

static pdVec3 rotate_min(const minRotation* m, pdVec3 x) {
  if (!m->halfTurn) {
    pdVec3 r = pd_v3_add(pd_v3_scale(x, m->c), pd_v3_cross(m->v, x));
    return pd_v3_muladd(r, pd_v3_dot(m->v, x) / m->onePlusC, m->v);
  }
  return pd_v3_sub(pd_v3_scale(m->axis, 2.0 * pd_v3_dot(m->axis, x)), x);
}

// Rotates s into the plane ⊥ nNew keeping |s|: rotate, drop the residual normal part (from roundoff or a
// spring that was not exactly in the old plane), restore the length.
static pdVec3 realign_one(pdVec3 s, const minRotation* m, pdVec3 nNew) {
  double len = pd_v3_norm(s);
  if (len == 0.0) return s;
  pdVec3 r = in_plane(rotate_min(m, s), nNew);
  double rl = pd_v3_norm(r);
  return rl > 0.0 ? pd_v3_scale(r, len / rl) : (pdVec3){0, 0, 0};
}

static pdVec3 clip_to_cone(pdVec3 s, double k, double limit) {
  if (k <= 0.0) return s;
  double f = k * pd_v3_norm(s);
  return f > limit ? pd_v3_scale(s, limit / f) : s;
}

// Puts a proportional pair of springs back on k1 s1 + k2 s2 = 0, keeping the total deflection s2 − s1.
static void rebalance(double k1, double k2, double* s1, double* s2) {
  double d = *s2 - *s1, k = k1 + k2;
  *s1 = -d * k2 / k;
  *s2 = d * k1 / k;
}

double pd_springs_energy(const pdContactParams* p, const pdSprings* s) {
  return 0.5 * (p->k1n * s->s1n * s->s1n + p->k2n * s->s2n * s->s2n + p->k1t * pd_v3_dot(s->s1t, s->s1t) +
                p->k2t * pd_v3_dot(s->s2t, s->s2t));
}

void pd_springs_realign(pdSprings* s, pdVec3 nOld, pdVec3 nNew, double mu, const pdContactParams* p, double fn) {
  PD_ASSERT(mu >= 0.0);
  minRotation m = min_rotation(nOld, nNew);
  s->s1t = realign_one(s->s1t, &m, nNew);
  s->s2t = realign_one(s->s2t, &m, nNew);
  if (p->proportionalN && p->k1n + p->k2n > 0.0) rebalance(p->k1n, p->k2n, &s->s1n, &s->s2n);
  if (p->proportionalT && p->k1t + p->k2t > 0.0) {
    rebalance(p->k1t, p->k2t, &s->s1t.x, &s->s2t.x);
    rebalance(p->k1t, p->k2t, &s->s1t.y, &s->s2t.y);
    rebalance(p->k1t, p->k2t, &s->s1t.z, &s->s2t.z);
  }
  if (!tangential_damper_determined(p)) {  // spring-determined: the spring's force is the contact's (design note)
    double limit = mu * fmax(fn, 0.0);
    s->s1t = clip_to_cone(s->s1t, p->k1t, limit);
    s->s2t = clip_to_cone(s->s2t, p->k2t, limit);
  }
  s->s1n = fmin(s->s1n, 0.0);
  s->s2n = fmax(s->s2n, 0.0);
}

void pd_springs_clip_to_cone(pdSprings* s, const pdContactParams* p, double limit) {
  s->s1t = clip_to_cone(s->s1t, p->k1t, limit);
  s->s2t = clip_to_cone(s->s2t, p->k2t, limit);
}
