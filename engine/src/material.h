// polydyn (internal) — material parameters of the contact model (paper §3.2, §3.3, Appendices A and B).
//
// Constants belong to a PAIR of bodies, not to one body: what a contact feels is the pair's stiffness,
// damping and friction, and a spring sized by one body alone (a 10 m floor against a 0.1 m cube) makes
// the softer side decide everything. What this module decides (each rule derived in material.c):
// - Per body (pd_material_side): μ; the restitution e (requested, or PD_DEFAULT_RESTITUTION); explicit
//   kn, kt, cn, ct when the scene gives them; mass, minimum effective mass and size.
// - Per pair (pd_contact_params_pair):
//   μ = √(μ₁μ₂); e = √(e₁e₂); ζ_n from eq. (15) for that e; ζ_t = PD_TANGENTIAL_DAMPING_RATIO (1/√3).
//   Stiffness (eq. (11) for the pair): the relative kinetic energy ½ m_pair v_max² is stored at
//   δ_max = deflection × the SMALLER body's size, m_pair = m₁m₂/(m₁+m₂) (a fixed body: infinite mass), so
//   the series stiffness is k_s = m_pair v_max²/δ_max², and each side without an explicit kn gets 2 k_s
//   (equal sides: the surface elements sit in the middle). kt = kn of the same side unless set. Where all four are
//   derived (loadSized), a pair pressed by a heavier body towards a third has them raised for that load while the
//   simulation runs (pair_params.c, load_scale).
//   Damping: when neither side gives cn (ct), the pair's dampers are "modal": each contact gets
//   c_s = 2ζ√(k_s m_c), with m_c the mass per contact of the pair's joint motion along the normals (in the
//   tangent plane), set from the pair's active contacts whenever they change (pair_params.c) — so the
//   requested e holds for one vertex, an edge (2 contacts) or a face (4) alike. Both sides get the same
//   c/k (c_i = (c_s/k_s) k_i): two Kelvin–Voigt elements with one c/k ARE one Kelvin–Voigt element, which
//   is what makes eq. (15) exact for any two bodies; the contact force then takes its "proportional"
//   branch, with no surface-element mode to integrate. When a side gives cn (ct), the paper's explicit
//   forms hold for that pair: the given sides keep their values, the others get the c/k of the pair's ζ
//   at m_pair, and the §3.3.2 surface-element check applies.
// - Time constants (§3.3), per pair: 1/ω = √(m_min/k_s) with m_min the pair's minimum effective mass (App.
//   B, both bodies in series) must not be below Δt_min (this bounds both the period 2π/ω and the decay
//   1/(ζω) for ζ <= 1): otherwise both sides' stiffnesses are scaled down. Explicit dampers: 2 m_min/c_s
//   >= Δt_min. Non-proportional explicit dampers: (c₁+c₂)/(k₁+k₂) >= Δt_min, else the normal dampers are
//   dropped or the tangential stiffnesses lowered (§3.3.2). Every change is recorded as data.
// - Minimum effective mass (App. B): computed exactly, 1/m_min = max over vertices of λ_max(M(r)) with
//   M(r) = I/m + [r]ₓᵀ J⁻¹ [r]ₓ (nᵀ M(r) n is convex in r, so the maximum is at a vertex). Cube: 2m/11.
#pragma once

#include <stdbool.h>

#include "contact_force.h"
#include "polydyn/model.h"
#include "polydyn/vecmath.h"

// Two springs (or dampers) in series: ab/(a + b); 0 when either is 0 (no element).
static inline double pd_series(double a, double b) { return (a > 0.0 && b > 0.0) ? a * b / (a + b) : 0.0; }

// ---------------------------------------------------------------- restitution (eqs. (12)–(15))

// PD_RESTITUTION_MIN (polydyn/model.h) is reached at ζ = 4.807: the contact's fast mode,
// ω(ζ + √(ζ² − 1)) ≈ 2ζω, then bounds the step about ten times below what the spring alone needs
// (stability_bound.c).
#define PD_DAMPING_RATIO_MAX 4.807  // ζ at PD_RESTITUTION_MIN; for the refusal message

// ζ for a requested restitution e ∈ [PD_RESTITUTION_MIN, 1]: in [0, 1) for e > e⁻², above 1 (overdamped)
// below it. Returns false and fills `why` for e outside that range or when the root finder fails.
bool pd_damping_ratio_from_restitution(double e, double* zeta, char* why, int whySize);

// The forward map of eq. (15): e = exp(−2ζ arccos ζ/√(1−ζ²)) for ζ ∈ [0, 1] (e⁻² at ζ = 1), continued
// for ζ > 1 as exp(−2ζ arccosh ζ/√(ζ²−1)) (overdamped; the contact ends when its force reaches zero).
double pd_restitution_from_damping_ratio(double zeta);

// The restitution a body without `restitution` has: a hard, moderately lossy material (wood, plastic,
// stone on stone are 0.3–0.7); never 1, which would leave contacts ringing forever.
#define PD_DEFAULT_RESTITUTION 0.5
// The tangential dampers' damping ratio, for the mass each contact carries in the pair's joint sliding (modal
// dampers: m/4 per contact on a face). On the same springs a body resting on a face also twists about the
// normal, and for the corners of any rectangular face m r²/I_n = 3, so the twist's damping ratio is √3 ζ_t.
// With ζ_t = 1 the twist was overdamped (ζ 1.73): its fast real root, 3.1 times its frequency, lay beyond the
// stability bound (which takes ζ <= 1 per contact at its Gershgorin ω_max), so steps at the bound grew the
// twist's error until rejected: cases/hard/stack_10.scene took 6 557 derivative evaluations, a box sliding to
// rest on a floor had 23 % of its steps rejected. 1/√3 makes the twist critically damped and sliding 0.577 (a
// sticking contact's ringing falls to 1.2 % within one period): the stack 3 595 evaluations (one step per 1 ms
// sample), the box 0.2 % of its steps rejected.
#define PD_TANGENTIAL_DAMPING_RATIO 0.57735026918962576

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

// ---------------------------------------------------------------- adjustments (§3.3), all per pair

typedef enum pdMaterialParam { pd_paramKn, pd_paramKt, pd_paramCn, pd_paramCt } pdMaterialParam;

typedef enum pdAdjustmentRule {
  pd_adjustPairStiffness,      // §3.3.1: 1/ω = √(m_min/k_s) < Δt_min → both sides' k scaled down
  pd_adjustPairDecay,          // §3.3.1: 2 m_min/c_s < Δt_min (explicit dampers) → both sides' c scaled down
  pd_adjustContactNormal,      // §3.3.2: τ = (c1n + c2n)/(k1n + k2n) < Δt_min → normal dampers set to 0
  pd_adjustContactTangential,  // §3.3.2: τ = (c1t + c2t)/(k1t + k2t) < Δt_min → k_t scaled by τ/Δt_min
} pdAdjustmentRule;

typedef struct pdAdjustment {
  pdAdjustmentRule rule;
  int body;               // the body whose side changed (caller's index)
  int partner;            // the other body of the pair
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
// "ball: cn 12.5 -> 0 N·s/m in contacts with floor (§3.3.2: τ = (c1n+c2n)/(k1n+k2n) = 1e-09 s < dt_min = 1e-08 s)".
// Names may be NULL (then "body N"). Returns snprintf's count.
int pd_adjustment_describe(const pdAdjustment* a, const char* bodyName, const char* partnerName, char* buf,
                           int size);

// ---------------------------------------------------------------- per-body sides, per-pair constants

// δ_max of a pair, m (docs/contact-model.md): `deflection` times the smaller body's size (paper
// §3.2), but at most PD_DELTA_MAX_WIDTH_FRACTION of the thinner body's width (a width of 0 is not known and
// does not bound it). A deflection comparable to a body's thickness passes through it: a vertex pressed into a
// plate thinner than δ_max comes out on the far side, its contact breaks (it left the body, or the rim face it
// pressed on) and no other contact replaces it. Seed 3 of the soak: plates 0.4–1.6 δ_max thick crossed by up to
// 85 δ_max. At a quarter of the width, the 3 δ_max a contact may reach (the soak's limit) stay inside the body.
#define PD_DELTA_MAX_WIDTH_FRACTION 0.25
double pd_delta_max(double deflection, double size1, double width1, double size2, double width2);

typedef struct pdMaterialSettings {
  double vmax;        // m/s, > 0: the relative speed that sizes k (eq. (11))
  double deflection;  // δ_max as a fraction of the smaller body's size, in (0, 1) (pd_delta_max)
  double dtmin;       // s, >= 0
} pdMaterialSettings;

// What the scene asked for. setMask holds scene.h's PD_SET_KN, PD_SET_KT, PD_SET_CN, PD_SET_CT and
// PD_SET_RESTITUTION bits; a value counts only when its bit is set.
typedef struct pdMaterialRequest {
  double mu;
  double kn, kt;        // N/m, > 0 when set
  double cn, ct;        // N·s/m, >= 0 when set
  double restitution;   // in [PD_RESTITUTION_MIN, 1] when set
  unsigned setMask;
} pdMaterialRequest;

typedef struct pdMaterialBody {
  int index;    // caller's body index, used in adjustment records
  bool fixed;   // infinite mass: the pair's masses are the other body's
  double mass;  // kg, > 0 (ignored for a fixed body)
  double mMin;  // kg, minimum effective mass (pd_min_effective_mass), > 0 (ignored for a fixed body)
  double size;  // m, average dimension, > 0
  double width;  // m, thinnest width (across a face plane), > 0; 0: not given (δ_max from the size alone)
} pdMaterialBody;

// What one body brings to each of its contacts. Bodies with bit-identical sides share a material class.
typedef struct pdMaterialSide {
  double mu;
  double restitution;  // requested, or PD_DEFAULT_RESTITUTION
  double kn, kt;       // N/m as the scene gave them; 0 = derived for each pair
  double cn, ct;       // N·s/m as the scene gave them; -1 = derived for each pair
  double mass;         // kg; 0 for a fixed body (infinite mass)
  double mMin;         // kg, minimum effective mass; 0 for a fixed body
  double size;         // m
  double width;        // m, thinnest width; 0: not given
} pdMaterialSide;

// One body's side. Returns false and fills `why` for an unreachable restitution (below PD_RESTITUTION_MIN) or invalid
// inputs.
bool pd_material_side(const pdMaterialBody* body, const pdMaterialRequest* req, pdMaterialSide* out, char* why,
                      int whySize);

// The pair's restitution √(e₁e₂) and its damping ratio ζ_n (eq. (15)); false only if the root finder fails.
bool pd_pair_damping_ratio(const pdMaterialSide* s1, const pdMaterialSide* s2, double* e, double* zeta);

// Contact parameters of a pair, body 1 = s1 (index body1), body 2 = s2 (index body2), by the rules above,
// with the pair's ζ_n given (pd_pair_damping_ratio). Modal dampers are set for one contact carrying the
// pair's reduced mass (m_c = m_pair) until pd_contact_modal_damping sets them per contact. Adjustments are
// appended to adj (may be NULL). The result does not depend on which body is 1 except for the side
// labels: compute a pair once and use pd_contact_params_swapped for contacts whose roles are reversed.
void pd_contact_params_pair(const pdMaterialSide* s1, const pdMaterialSide* s2, double zetaN,
                            const pdMaterialSettings* set, int body1, int body2, pdContactParams* out,
                            pdAdjustmentList* adj);

// Sets the modal dampers of one contact (the directions whose p->modalN, p->modalT are set) for the mass
// per contact of the pair's joint motion along n (massN) and in the tangent plane (massT), kg: c_s =
// 2ζ√(k_s m_c), each side c_i = (c_s/k_s) k_i. Masses above the pair's reduced mass are clamped to it. In a stack
// the mass is at least stackN (stackT), k_s/Ω² of the slow mode the pair takes part in (stack_modes.h; 0: none).
// Returns in scale[0] (n) and scale[1] (P_t) how many times ζ the dampers give at the pair's own mass (>= 1).
void pd_contact_modal_damping(pdContactParams* p, double massN, double massT, double stackN, double stackT,
                              double scale[2]);

static inline pdContactParams pd_contact_params_swapped(const pdContactParams* p) {
  pdContactParams q = *p;
  q.k1n = p->k2n, q.k2n = p->k1n, q.k1t = p->k2t, q.k2t = p->k1t;
  q.c1n = p->c2n, q.c2n = p->c1n, q.c1t = p->c2t, q.c2t = p->c1t;
  return q;
}
