// polydyn (internal) — the force of one contact and the rates of its springs (paper §3.1, eqs. (1)–(10),
// §3.1.5 zero damping, §3.1.6 mixed dampers), and the realignment of its springs after a step (§3.4).
//
// Conventions
// - Body 1 carries the vertex (VF contact) or the first edge (EE contact); body 2 carries the face (or the
//   second edge).
// - n is the unit contact normal pointing from body 2 into body 1 (for VF: the face's outward normal).
//   P_t is the tangent plane, ⊥ n.
// - Δu = u1 − u2 is the relative velocity of the contact point: body 1's material point minus body 2's.
//   Δu_n = Δu · n < 0 is approach; Δu_t = Δu − Δu_n n.
// - F_c is the force body 2 applies to body 1 (body 2 receives −F_c): F_c = F_n n + F_t.
// - The normal springs are scalars along n with eq. (1): F_n = −k1n s1n − c1n ṡ1n = k2n s2n + c2n ṡ2n, so
//   compression (F_n > 0) means s1n < 0 < s2n. ṡ1n − ṡ2n = Δu_n (eq. (4)).
// - The tangential springs s1t, s2t are world-frame 3-vectors lying in P_t, eq. (2):
//   F_t = −k1t s1t − c1t ṡ1t = k2t s2t + c2t ṡ2t, ṡ1t − ṡ2t = Δu_t − Δw_t, with Δw_t = w1 − w2 the slip
//   velocity of the surface elements and the friction law (7): |F_t| ≤ μ F_n⁺, Δw_t = −λ F_t, λ ≥ 0, where
//   F_n⁺ = max(F_n, 0) (no friction without a normal push). Keeping the two tangential springs as plane
//   vectors is the paper's "spring along the slip direction" with its direction kept in the vector.
// - Damper branches are chosen by exact zeros (c == 0.0); the caller decides thresholds (paper §3.4).
// - Friction is modelled only when μ > 0 and there is a tangential spring (k1t + k2t > 0); otherwise
//   F_t = 0 and the tangential rates are 0 (docs/DESIGN.md §6.3: frictionless contacts carry no tangential springs,
//   and the caller may skip their tangential state entirely).
#pragma once

#include <stdbool.h>

#include "polydyn/vecmath.h"

// Spring and damper constants of one contact (body 1 side, body 2 side) and the pair friction coefficient.
// "Proportional" directions have c1/k1 = c2/k2 by construction: the two sides are then one Kelvin–Voigt
// element (k_s = k1k2/(k1+k2), c_s = c1c2/(c1+c2)) and the surface elements stay where k1 s1 + k2 s2 = 0;
// their relaxation, fast and identically zero, is not integrated (contact_force.c).
typedef struct pdContactParams {
  double k1n, k2n, k1t, k2t;  // N/m, >= 0
  double c1n, c2n, c1t, c2t;  // N·s/m, >= 0; an exact 0 selects the zero-damping branch
  double mu;                  // pair friction coefficient √(μ₁μ₂), >= 0
  bool proportionalN, proportionalT;  // c1/k1 = c2/k2 along n, in P_t (set where that holds by construction)
  bool modalN, modalT;        // the dampers are set per contact from the pair's modal mass (material.h)
  bool loadSized;             // all four springs from eq. (11): raised for the load the pair carries (material.h)
  double zetaN, zetaT;        // damping ratios the modal dampers reach
  double massPair;            // kg: the pair's reduced mass (a fixed body counts as infinite)
  double massMin;             // kg: the pair's minimum effective mass (both bodies' m_min in series)
} pdContactParams;

// Every constant a number >= 0 (what pd_contact_force requires).
static inline bool pd_contact_params_valid(const pdContactParams* p) {
  return p->k1n >= 0.0 && p->k2n >= 0.0 && p->k1t >= 0.0 && p->k2t >= 0.0 && p->c1n >= 0.0 && p->c2n >= 0.0 &&
         p->c1t >= 0.0 && p->c2t >= 0.0 && p->mu >= 0.0;
}

// The 8 numbers of a contact in the state vector: spring deflections, m.
typedef struct pdSprings {
  double s1n, s2n;   // along n; compression: s1n <= 0 <= s2n
  pdVec3 s1t, s2t;   // in P_t, world frame
} pdSprings;

typedef struct pdContactForce {
  double fn;        // F_n, N (>= 0 when the contact pushes; < 0: the normal springs would pull)
  pdVec3 ft;        // F_t, N, in P_t
  pdVec3 force;     // F_c = fn n + ft, applied to body 1 (body 2 gets −force), N
  bool slip;        // the friction limit is active: |F_t| = μ F_n⁺ (see contact_force.c for each branch)
  double coneMargin;  // N: F⁺ − |b_t| of the damper-determined branch, > 0 in stick (INFINITY in the other branches)
  double lambda;    // λ of eq. (7)/(9), s/kg; 0 in stick; INFINITY when slipping with F_n⁺ = 0
  pdVec3 dw;        // Δw_t = −λ F_t, the slip velocity of the surface elements, m/s (0 in stick)
  pdSprings rate;   // ṡ1n, ṡ2n, ṡ1t, ṡ2t, m/s
} pdContactForce;

// Force of one contact and the rates of its springs. n must be a unit vector. Pure, allocation-free.
// The tangential springs are used through their projection on the current P_t (an out-of-plane part
// appears only while n turns inside an integration step; pd_springs_realign removes it), and the
// tangential rates lie in P_t.
void pd_contact_force(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du, pdContactForce* out);

// The force law with its modes held as they were at a step's start (docs/events.md, "Modes within a step"): `pushing`,
// the friction limit μ F_n continued below F_n = 0 (the caller applies the normal force whatever its sign); `slip`,
// the damper-determined tangential branch held in slip (F_t on the cone, also below it) or in stick (F_t = −b_t,
// also beyond it). So the force is one smooth function of the state over the step. The other tangential branches
// (a tangential damper zero) keep the free law. With the modes the free law gives, the same numbers as
// pd_contact_force.
void pd_contact_force_held(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du, bool pushing, bool slip,
                           pdContactForce* out);
// Whether pd_contact_force_held holds this contact's stick or slip (friction, both tangential dampers > 0).
bool pd_contact_slip_held(const pdContactParams* p);

// F_n of pd_contact_force alone (the same number), N: what a caller needs before it realigns the springs.
double pd_contact_normal_force(const pdContactParams* p, const pdSprings* s, pdVec3 n, pdVec3 du);

// The dynamics-side break (paper §4.2, docs/DESIGN.md §6.3): true when the normal force would pull (fn < 0).
static inline bool pd_contact_fn_pulls(double fn) { return fn < 0.0; }
static inline bool pd_contact_force_pulls(const pdContactForce* f) { return pd_contact_fn_pulls(f->fn); }

// After an accepted step (paper §3.4): rotates the tangential springs from the old tangent plane (⊥ nOld)
// into the new one (⊥ nNew) by the smallest rotation taking nOld to nNew, keeping each spring's length
// exactly (a residual out-of-plane part is removed and the length restored); in a proportional direction
// the two sides are put back exactly on k1 s1 + k2 s2 = 0 keeping their difference; then, where a tangential
// damper is zero (the spring-determined branches, whose force is the spring's), clips each tangential spring
// to the friction cone, |k_it s_it| <= mu max(fn, 0) (shortened along itself; a spring with k_it = 0 carries
// no force and is left alone), and clamps the normal springs out of tension (s1n <= 0 <= s2n). With both
// tangential dampers > 0 the springs are not clipped: the force is on the cone by eq. (9) whatever their
// length, and a spring beyond it relaxes through slip on the contact's own time scale (contact_force.c).
// nOld and nNew must be unit vectors; fn is the normal force at the accepted state, N.
void pd_springs_realign(pdSprings* s, pdVec3 nOld, pdVec3 nNew, double mu, const pdContactParams* p, double fn);
// Shortens each tangential spring along itself so that its force stays within `limit` (N): |k_it s_it| <= limit (a
// spring with k_it = 0 carries no force and is left alone). What a successor of a hand-over inherits (contact_set.c).
void pd_springs_clip_to_cone(pdSprings* s, const pdContactParams* p, double limit);
// The energy the springs store, ½ k s² over the four of them, J.
double pd_springs_energy(const pdContactParams* p, const pdSprings* s);
