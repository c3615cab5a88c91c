// polydyn (internal) — material parameters of the contact model (paper §3.2, §3.3, Appendices A and B).
//
// What this module decides (each rule is derived in material.c):
// - Stiffness (eq. (11)): k_n = 2 E_max/δ_max² with E_max = ½ m v_max², δ_max = deflection × size
//   (size = the body's average dimension), i.e. k_n = m v_max²/δ_max². k_t = k_n unless the scene sets kt.
// - Restitution → normal damper: ζ from eq. (15), ln(e²) = −4ζ/√(1−ζ²) · atan(√(1−ζ²)/ζ), solved with GSL's
//   Brent root finder; e = 1 gives ζ = 0; e < e⁻² ≈ 0.1353 is refused (unreachable with k > 0, §3.2.2).
//   The calibration experiment of Fig. 5 (a body of mass m on a plate of the same material) puts the two
//   bodies' springs and dampers in series: half stiffness, half damping. So ζ = (c/2)/(2√((k/2) m)) and
//   the per-body damper is c = 2ζ√(2 k m).
// - Tangential damper (§3.2.2: "either from (15) or critical"): an explicit ct wins; otherwise the rule
//   pd_ctFromRestitution (DEFAULT, DESIGN §4.1: `restitution` derives c_n and c_t) gives c_t = 2ζ√(2 k_t m)
//   when a restitution is requested and 0 when not; pd_ctCritical gives the paper's √(4 m k_t).
//   An explicit cn wins over a requested restitution for c_n.
// - Fixed bodies (infinite mass) are sized as a body of their own size with the mass of the HEAVIEST
//   moving body in the scene (k_n, c_n, c_t), and their §3.3.1 time-constant checks use the SMALLEST
//   minimum effective mass of the moving bodies (the lightest thing that can touch them). With no moving
//   body in the scene, a fixed body uses its own mass and minimum effective mass.
// - Minimum effective mass (App. B): the paper defines m_min as the minimum of eq. (21) over surface points
//   and directions, and approximates it with principal directions (eq. (22)). We compute it exactly:
//   1/m_eff(r, n) = nᵀ M(r) n with M(r) = I/m + [r]ₓᵀ J⁻¹ [r]ₓ, so the worst direction at r is the top
//   eigenvector of M(r); nᵀ M(r) n is convex in r for every n, so its maximum over the (convex) body is
//   attained at a vertex. m_min = 1 / max over vertices of λ_max(M(r)). (Cube: 2m/11; eq. (22): m/4.)
// - Time constants: §3.3.1 per body, τ = 2π√(m_min/k) for k_n, k_t and τ = 2 m_min/c for c_n, c_t; when
//   Δt_min > τ the parameter is lowered to make τ = Δt_min (k = m_min (2π/Δt_min)², c = 2 m_min/Δt_min).
//   Dampers derived from a restitution use the stiffness after its adjustment. §3.3.2 per contact pair,
//   τ = (c1 + c2)/(k1 + k2): along n, Δt_min > τ sets both normal dampers to 0; in P_t it lowers both
//   tangential stiffnesses by the common factor τ/Δt_min (so τ = Δt_min). No check when c1 + c2 = 0.
//   Every change is appended to a pdAdjustmentList as data; nothing is adjusted silently.
#pragma once

#include <stdbool.h>

#include "contact_force.h"
#include "polydyn/vecmath.h"

// ---------------------------------------------------------------- restitution (eqs. (12)–(15))

// e⁻²: the smallest restitution reachable with k > 0 (ζ → 1 in eq. (15)).
#define PD_RESTITUTION_MIN 0.1353352832366127

// ζ for a requested restitution e ∈ [e⁻², 1]. Returns false and fills `why` for e outside that range
// (including e < e⁻², "unreachable with k > 0") or when the root finder fails.
bool pd_damping_ratio_from_restitution(double e, double* zeta, char* why, int whySize);

// The forward map of eq. (15): e = exp(−2ζ arccos ζ/√(1−ζ²)) for ζ ∈ [0, 1] (e⁻² at ζ = 1).
double pd_restitution_from_damping_ratio(double zeta);

// Per-body damper giving damping ratio ζ in the Fig. 5 experiment (two equal bodies in series, mass m):
// c = 2ζ√(2 k m), N·s/m.
double pd_body_damper_from_ratio(double zeta, double k, double m);

// ---------------------------------------------------------------- effective mass (App. A, B)

// Effective mass (eqs. (19)–(20)) of a body along unit direction n at point r from its centre of mass:
// 1/m_eff = 1/m + (r × n)ᵀ I⁻¹ (r × n); r, n and invInertia in one frame (body or world). kg.
double pd_effective_mass(double mass, const pdMat3* invInertia, pdVec3 r, pdVec3 n);

// Exact minimum effective mass over the body's surface and all directions (see above): vertices about the
// centre of mass, inertia about the centre of mass, both in the body frame. kg.
double pd_min_effective_mass(double mass, const pdMat3* inertia, const pdVec3* vertices, int count);

// The paper's approximation (eqs. (21)–(22)): the minimum of eq. (21) over vertices with n restricted to
// the three principal directions. principal[] are the principal moments, axes' columns the principal
// axes (body frame). Never below pd_min_effective_mass. kg. For repeated principal moments (cube, regular
// prisms about their axis) the principal axes are not unique and the result depends on the basis given.
double pd_min_effective_mass_principal(double mass, const double principal[3], const pdMat3* axes,
                                       const pdVec3* vertices, int count);

// ---------------------------------------------------------------- adjustments (§3.3)

typedef enum pdMaterialParam { pd_paramKn, pd_paramKt, pd_paramCn, pd_paramCt } pdMaterialParam;

typedef enum pdAdjustmentRule {
  pd_adjustBodyPeriod,         // §3.3.1: τ = 2π√(m_min/k) < Δt_min → k lowered to m_min (2π/Δt_min)²
  pd_adjustBodyDecay,          // §3.3.1: τ = 2 m_min/c < Δt_min → c lowered to 2 m_min/Δt_min
  pd_adjustContactNormal,      // §3.3.2: τ = (c1n + c2n)/(k1n + k2n) < Δt_min → normal dampers set to 0
  pd_adjustContactTangential,  // §3.3.2: τ = (c1t + c2t)/(k1t + k2t) < Δt_min → k_t scaled by τ/Δt_min
} pdAdjustmentRule;

typedef struct pdAdjustment {
  pdAdjustmentRule rule;
  int body;               // the body whose parameter changed (caller's index)
  int partner;            // the other body of the contact pair (§3.3.2 rules); -1 for §3.3.1 rules
  pdMaterialParam param;  // which parameter
  double from, to;        // its value before and after (N/m or N·s/m)
  double tau;             // the time constant found, s
  double dtmin;           // the Δt_min it was compared with, s
} pdAdjustment;

// Caller-owned storage; records that do not fit are counted in `dropped` (report that number too).
typedef struct pdAdjustmentList {
  pdAdjustment* items;  // (capacity)
  int capacity;
  int count;
  int dropped;
} pdAdjustmentList;

// "kn", "kt", "cn", "ct".
const char* pd_material_param_name(pdMaterialParam param);

// One line for `polydyn check` / summary.json, e.g.
// "ball: cn 12.5 -> 0 N·s/m (§3.3.2 contact with floor: τ = (c1+c2)/(k1+k2) = 1e-09 s < dt_min = 1e-08 s)".
// Names may be NULL (then "body N"). Returns snprintf's count.
int pd_adjustment_describe(const pdAdjustment* a, const char* bodyName, const char* partnerName, char* buf,
                           int size);

// ---------------------------------------------------------------- per-body and per-pair parameters

typedef enum pdTangentialDamping {
  pd_ctFromRestitution = 0,  // default: c_t = 2ζ√(2 k_t m) when a restitution is requested, else 0
  pd_ctCritical,             // c_t = √(4 m k_t) (paper §3.2.2)
} pdTangentialDamping;

typedef struct pdMaterialSettings {
  double vmax;        // m/s, > 0: the speed that sizes k_n (eq. (11))
  double deflection;  // δ_max as a fraction of the body's size, in (0, 1)
  double dtmin;       // s, > 0
  pdTangentialDamping ctRule;
} pdMaterialSettings;

// What the scene asked for. setMask holds scene.h's PD_SET_KN, PD_SET_KT, PD_SET_CN, PD_SET_CT and
// PD_SET_RESTITUTION bits; a value counts only when its bit is set.
typedef struct pdMaterialRequest {
  double mu;
  double kn, kt;        // N/m, > 0 when set
  double cn, ct;        // N·s/m, >= 0 when set
  double restitution;   // in [e⁻², 1] when set
  unsigned setMask;
} pdMaterialRequest;

typedef struct pdMaterialBody {
  int index;    // caller's body index, used in adjustment records
  bool fixed;   // pd_material_bodies replaces mass and mMin of fixed bodies by the rule above
  double mass;  // kg, > 0
  double mMin;  // kg, minimum effective mass (pd_min_effective_mass), > 0
  double size;  // m, average dimension, > 0
} pdMaterialBody;

typedef struct pdMaterialUsed {
  double kn, kt;   // N/m
  double cn, ct;   // N·s/m
  double mu;
  double mass;     // kg: the mass that sized k and c (the heaviest moving mass for fixed bodies)
  double mMin;     // kg: the minimum effective mass of the §3.3.1 checks
  double zeta;     // damping ratio from the requested restitution, or -1 when none was requested
} pdMaterialUsed;

// One body's parameters, with body->mass and body->mMin used as given (the fixed-body rule is applied by
// pd_material_bodies). Appends §3.3.1 adjustments to adj (may be NULL only if the caller accepts losing
// them: then nothing is recorded). Returns false and fills `why` for an unreachable restitution or
// invalid inputs.
bool pd_material_body(const pdMaterialBody* body, const pdMaterialRequest* req, const pdMaterialSettings* s,
                      pdMaterialUsed* out, pdAdjustmentList* adj, char* why, int whySize);

// The masses a fixed body is sized and checked with: the heaviest moving mass and the smallest moving
// mMin. Returns false (and leaves the outputs alone) when no body moves.
bool pd_material_fixed_reference(const pdMaterialBody* bodies, int count, double* mass, double* mMin);

// All bodies of a scene: applies the fixed-body rule, then pd_material_body to each. On failure returns
// false with `why` and *failed = the array position of the body refused.
bool pd_material_bodies(const pdMaterialBody* bodies, const pdMaterialRequest* reqs, int count,
                        const pdMaterialSettings* s, pdMaterialUsed* used, pdAdjustmentList* adj, int* failed,
                        char* why, int whySize);

// Contact parameters of a pair, body 1 = m1 (index body1), body 2 = m2 (index body2): μ = √(μ₁μ₂), each
// side's springs and dampers from its own body, then the §3.3.2 checks (adjustments appended to adj).
// The result does not depend on which body is 1 except for the side labels: compute a pair once and use
// pd_contact_params_swapped for contacts whose roles are reversed.
void pd_contact_params_pair(const pdMaterialUsed* m1, const pdMaterialUsed* m2, int body1, int body2, double dtmin,
                            pdContactParams* out, pdAdjustmentList* adj);

static inline pdContactParams pd_contact_params_swapped(const pdContactParams* p) {
  return (pdContactParams){.k1n = p->k2n, .k2n = p->k1n, .k1t = p->k2t, .k2t = p->k1t,
                           .c1n = p->c2n, .c2n = p->c1n, .c1t = p->c2t, .c2t = p->c1t, .mu = p->mu};
}
