// polydyn — material parameters of the contact model (paper §3.2, §3.3, Appendices A and B).
//
// The rules are listed in material.h; the derivations are next to the code below. Nothing here runs
// inside the step: these functions run once when a model is compiled.
#include "material.h"

#include <float.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdio.h>

#include "polydyn/error.h"
#include "polydyn/scene.h"
#include "why.h"

#define PI 3.14159265358979323846

// Brent's bracket on ζ shrinks to this width (absolute, ζ is dimensionless and O(1)–O(10)). The
// catalogue's inverse table is given to 1e-4 and a restitution error of 1e-12 is far below anything a
// simulation can measure; 1e-13 leaves Brent well clear of roundoff (ζ is known to ~1e-16).
#define PD_ZETA_TOL_ABS 1e-13
// Brent converges superlinearly: ~50 iterations reach 1e-13 from [1, 50] even at bisection speed.
#define PD_ZETA_MAX_ITER 200

// ---------------------------------------------------------------- restitution

// h(ζ) = −ln e of a Kelvin–Voigt contact that ends when its force reaches zero (eq. (15), with
// atan(√(1−ζ²)/ζ) = arccos ζ and ln(E_r) = 2 ln e):
//   underdamped ζ < 1: h = 2ζ arccos ζ/√(1 − ζ²), written with θ = arccos ζ as 2ζ θ/sin θ;
//   overdamped  ζ > 1: the same function continued, h = 2ζ arccosh ζ/√(ζ² − 1) = 2ζ θ/sinh θ, θ = arccosh ζ.
// Both forms stay accurate as ζ → 1 (θ → 0, θ/sin θ and θ/sinh θ → 1, h → 2: e → e⁻²). h grows without
// bound (h > 2 arccosh ζ), so every e in (0, 1] has one ζ: an overdamped contact still ends when its
// force vanishes, with the slow mode's small exit speed (e → 1/(4ζ²) for large ζ).
static double neg_log_restitution(double zeta) {
  if (zeta > 1.0) {
    double theta = acosh(zeta);
    return 2.0 * zeta * theta / sinh(theta);
  }
  double theta = acos(zeta);
  return theta > 0.0 ? 2.0 * zeta * theta / sin(theta) : 2.0 * zeta;
}

double pd_restitution_from_damping_ratio(double zeta) {
  PD_ASSERT(zeta >= 0.0 && isfinite(zeta));
  return exp(-neg_log_restitution(zeta));
}

static double zeta_residual(double zeta, void* params) {
  double logE = *(const double*)params;
  return neg_log_restitution(zeta) + logE;
}

bool pd_damping_ratio_from_restitution(double e, double* zeta, char* why, int whySize) {
  if (!(e >= 0.0 && e <= 1.0)) {
    pd_why(why, whySize, "restitution %g is outside [0, 1]", e);
    return false;
  }
  if (e < PD_RESTITUTION_MIN) {
    pd_why(why, whySize,
           "restitution %g is below %g, the smallest the contact model takes: a spring-damper contact always "
           "returns some energy (e = 0 needs an infinite damper), and below %g the damper (damping ratio above "
           "%.2f) makes the contact's fast mode, and so the integration step, about %.0fx shorter than the "
           "spring alone needs",
           e, PD_RESTITUTION_MIN, PD_RESTITUTION_MIN, PD_DAMPING_RATIO_MAX, 2.0 * PD_DAMPING_RATIO_MAX);
    return false;
  }
  if (e == 1.0) {
    *zeta = 0.0;
    return true;
  }
  double logE = log(e);
  if (zeta_residual(1.0, &logE) == 0.0) {  // e == e⁻² to roundoff: critical damping
    *zeta = 1.0;
    return true;
  }
  // h is increasing, h(0) = 0, h(1) = 2 and h(ζ) > 2 arccosh ζ: [0, 1] brackets the root for e > e⁻² and
  // [1, cosh(−ln e / 2)] for e < e⁻².
  double lo = 0.0, hi = 1.0;
  if (zeta_residual(1.0, &logE) < 0.0) {
    lo = 1.0;
    hi = cosh(-0.5 * logE);
  }
  gsl_function f = {.function = zeta_residual, .params = &logE};
  gsl_root_fsolver* solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  if (!solver) {
    pd_why(why, whySize, "out of memory in the restitution solver");
    return false;
  }
  gsl_error_handler_t* previous = gsl_set_error_handler_off();
  int status = gsl_root_fsolver_set(solver, &f, lo, hi);
  for (int iter = 0; status == GSL_SUCCESS && iter < PD_ZETA_MAX_ITER; ++iter) {
    status = gsl_root_fsolver_iterate(solver);
    if (status != GSL_SUCCESS) break;
    status = gsl_root_test_interval(gsl_root_fsolver_x_lower(solver), gsl_root_fsolver_x_upper(solver),
                                    PD_ZETA_TOL_ABS, 0.0);
    if (status == GSL_SUCCESS) break;
    if (status == GSL_CONTINUE) status = GSL_SUCCESS;
  }
  double root = gsl_root_fsolver_root(solver);
  bool converged = status == GSL_SUCCESS && gsl_root_test_interval(gsl_root_fsolver_x_lower(solver),
                                                                   gsl_root_fsolver_x_upper(solver),
                                                                   PD_ZETA_TOL_ABS, 0.0) == GSL_SUCCESS;
  gsl_set_error_handler(previous);
  gsl_root_fsolver_free(solver);
  if (!converged) {
    pd_why(why, whySize, "the damping ratio for restitution %g did not converge (%s)", e, gsl_strerror(status));
    return false;
  }
  *zeta = root;
  return true;
}

// ---------------------------------------------------------------- effective mass

static bool invert3(const pdMat3* a, pdMat3* inv) {
  const double(*m)[3] = a->m;
  double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  if (!(fabs(det) > 0.0) || !isfinite(det)) return false;
  double d = 1.0 / det;
  inv->m[0][0] = c00 * d;
  inv->m[1][0] = c01 * d;
  inv->m[2][0] = c02 * d;
  inv->m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * d;
  inv->m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * d;
  inv->m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * d;
  inv->m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * d;
  inv->m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * d;
  inv->m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * d;
  return true;
}

// App. A: a force f n at r gives a_c · n = f (1/m + (r × n)ᵀ J⁻¹ (r × n)) (eq. (19) projected on n, with
// (J⁻¹(r × f)) × r · n = (r × n) · J⁻¹ (r × f)), so 1/m_eff = nᵀ M n (eq. (20)).
double pd_effective_mass(double mass, const pdMat3* invInertia, pdVec3 r, pdVec3 n) {
  PD_ASSERT(mass > 0.0);
  pdVec3 rn = pd_v3_cross(r, n);
  return 1.0 / (1.0 / mass + pd_v3_dot(rn, pd_mat3_mulv(invInertia, rn)));
}

// M(r) = I/m + [r]ₓᵀ J⁻¹ [r]ₓ, where [r]ₓ n = r × n. Its largest eigenvalue is the largest 1/m_eff at r.
double pd_min_effective_mass(double mass, const pdMat3* inertia, const pdVec3* vertices, int count) {
  PD_ASSERT(mass > 0.0 && count > 0);
  pdMat3 inv;
  bool invertible = invert3(inertia, &inv);
  PD_ASSERT(invertible);
  gsl_eigen_symm_workspace* w = gsl_eigen_symm_alloc(3);
  PD_ASSERT(w != NULL);
  double worst = 1.0 / mass;
  for (int v = 0; v < count; ++v) {
    pdVec3 r = vertices[v];
    const pdMat3 rx = {{{0, -r.z, r.y}, {r.z, 0, -r.x}, {-r.y, r.x, 0}}};
    pdMat3 rxT = pd_mat3_transpose(&rx);
    pdMat3 t = pd_mat3_mul(&inv, &rx);
    pdMat3 mm = pd_mat3_mul(&rxT, &t);
    double a[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a[3 * i + j] = 0.5 * (mm.m[i][j] + mm.m[j][i]) + (i == j ? 1.0 / mass : 0.0);
    gsl_matrix_view A = gsl_matrix_view_array(a, 3, 3);
    double ev[3];
    gsl_vector_view E = gsl_vector_view_array(ev, 3);
    int status = gsl_eigen_symm(&A.matrix, &E.vector, w);
    PD_ASSERT(status == GSL_SUCCESS);
    for (int k = 0; k < 3; ++k) worst = fmax(worst, ev[k]);
  }
  gsl_eigen_symm_free(w);
  return 1.0 / worst;
}

// Eq. (21) in the principal frame (r' = Aᵀ r), with n one of the principal axes.
double pd_min_effective_mass_principal(double mass, const double principal[3], const pdMat3* axes,
                                       const pdVec3* vertices, int count) {
  PD_ASSERT(mass > 0.0 && count > 0 && principal[0] > 0.0 && principal[1] > 0.0 && principal[2] > 0.0);
  double worst = 1.0 / mass;
  for (int v = 0; v < count; ++v) {
    pdVec3 r = pd_mat3_tmulv(axes, vertices[v]);
    for (int k = 0; k < 3; ++k) {
      pdVec3 n = {k == 0, k == 1, k == 2};
      pdVec3 rn = pd_v3_cross(r, n);
      double inv = 1.0 / mass + rn.x * rn.x / principal[0] + rn.y * rn.y / principal[1] + rn.z * rn.z / principal[2];
      worst = fmax(worst, inv);
    }
  }
  return 1.0 / worst;
}

// ---------------------------------------------------------------- adjustments

const char* pd_material_param_name(pdMaterialParam param) {
  switch (param) {
    case pd_paramKn: return "kn";
    case pd_paramKt: return "kt";
    case pd_paramCn: return "cn";
    case pd_paramCt: return "ct";
  }
  return "?";
}

static void record(pdAdjustmentList* adj, pdAdjustmentRule rule, int body, int partner, pdMaterialParam param,
                   double from, double to, double tau, double dtmin) {
  if (!adj) return;
  if (adj->count >= adj->capacity) {
    adj->dropped++;
    return;
  }
  adj->items[adj->count++] = (pdAdjustment){.rule = rule, .body = body, .partner = partner, .param = param,
                                            .from = from, .to = to, .tau = tau, .dtmin = dtmin};
}

int pd_adjustment_describe(const pdAdjustment* a, const char* bodyName, const char* partnerName, char* buf,
                           int size) {
  char nb[32], np[32];
  if (!bodyName) {
    snprintf(nb, sizeof nb, "body %d", a->body);
    bodyName = nb;
  }
  if (!partnerName) {
    snprintf(np, sizeof np, "body %d", a->partner);
    partnerName = np;
  }
  const char* unit = (a->param == pd_paramKn || a->param == pd_paramKt) ? "N/m" : "N·s/m";
  const char* name = pd_material_param_name(a->param);
  // the paper's section, the time scale that fell below dt_min, and what the change means when it is not obvious
  const char *section = NULL, *scale = NULL, *consequence = "";
  switch (a->rule) {
    case pd_adjustPairStiffness: section = "§3.3.1", scale = "1/ω = √(m_min/k_s)"; break;
    case pd_adjustPairDecay: section = "§3.3.1", scale = "τ = 2 m_min/c_s"; break;
    case pd_adjustContactNormal:
      section = "§3.3.2", scale = "τ = (c1n+c2n)/(k1n+k2n)", consequence = ": normal dampers off, the impact becomes elastic";
      break;
    case pd_adjustContactTangential: section = "§3.3.2", scale = "τ = (c1t+c2t)/(k1t+k2t)"; break;
  }
  if (section)
    return snprintf(buf, (size_t)size, "%s: %s %.6g -> %.6g %s in contacts with %s (%s: %s = %.3g s < dt_min = %.3g s%s)",
                    bodyName, name, a->from, a->to, unit, partnerName, section, scale, a->tau, a->dtmin, consequence);
  return snprintf(buf, (size_t)size, "%s: %s %.6g -> %.6g", bodyName, name, a->from, a->to);
}

// ---------------------------------------------------------------- sides and pairs

bool pd_material_side(const pdMaterialBody* body, const pdMaterialRequest* req, pdMaterialSide* out, char* why,
                      int whySize) {
  const unsigned set = req->setMask;
  if (!(body->size > 0.0 && isfinite(body->size)) || !(body->width >= 0.0 && isfinite(body->width)) ||
      (!body->fixed && !(body->mass > 0.0 && isfinite(body->mass) && body->mMin > 0.0 && isfinite(body->mMin)))) {
    pd_why(why, whySize, "invalid body (mass %g kg, minimum effective mass %g kg, size %g m)", body->mass,
           body->mMin, body->size);
    return false;
  }
  if (((set & PD_SET_KN) && !(req->kn > 0.0 && isfinite(req->kn))) ||
      ((set & PD_SET_KT) && !(req->kt > 0.0 && isfinite(req->kt))) ||
      ((set & PD_SET_CN) && !(req->cn >= 0.0 && isfinite(req->cn))) ||
      ((set & PD_SET_CT) && !(req->ct >= 0.0 && isfinite(req->ct))) || !(req->mu >= 0.0 && isfinite(req->mu))) {
    pd_why(why, whySize, "invalid material request (kn %g, kt %g, cn %g, ct %g, mu %g)", req->kn, req->kt, req->cn,
           req->ct, req->mu);
    return false;
  }
  double e = (set & PD_SET_RESTITUTION) ? req->restitution : PD_DEFAULT_RESTITUTION;
  double zeta;
  if (!pd_damping_ratio_from_restitution(e, &zeta, why, whySize)) return false;
  *out = (pdMaterialSide){
      .mu = req->mu,
      .restitution = e,
      .kn = (set & PD_SET_KN) ? req->kn : 0.0,
      .kt = (set & PD_SET_KT) ? req->kt : 0.0,
      .cn = (set & PD_SET_CN) ? req->cn : -1.0,
      .ct = (set & PD_SET_CT) ? req->ct : -1.0,
      .mass = body->fixed ? 0.0 : body->mass,
      .mMin = body->fixed ? 0.0 : body->mMin,
      .size = body->size,
      .width = body->width,
  };
  return true;
}

double pd_delta_max(double deflection, double size1, double width1, double size2, double width2) {
  double delta = deflection * fmin(size1, size2);
  if (width1 > 0.0) delta = fmin(delta, PD_DELTA_MAX_WIDTH_FRACTION * width1);
  if (width2 > 0.0) delta = fmin(delta, PD_DELTA_MAX_WIDTH_FRACTION * width2);
  return delta;
}

// Two masses in series (the pair's relative motion); 0 stands for an infinite (fixed) mass.
static double reduced_mass(double m1, double m2) {
  if (m1 <= 0.0) return m2;
  if (m2 <= 0.0) return m1;
  return m1 * m2 / (m1 + m2);
}

bool pd_pair_damping_ratio(const pdMaterialSide* s1, const pdMaterialSide* s2, double* e, double* zeta) {
  *e = sqrt(s1->restitution * s2->restitution);
  // both factors are >= PD_RESTITUTION_MIN, so is their geometric mean (up to the last bit: clamp)
  char why[PD_ERROR_MESSAGE_MAX];
  return pd_damping_ratio_from_restitution(fmax(*e, PD_RESTITUTION_MIN), zeta, why, sizeof why);
}

// The damper of side i when the pair's dampers are derived: the pair's c/k times the side's k.
static void derived_dampers(double ratio, double k1, double k2, double* c1, double* c2) {
  *c1 = ratio * k1;
  *c2 = ratio * k2;
}

// c_s/k_s of a Kelvin–Voigt pair reaching damping ratio zeta for mass m: 2ζ√(k_s m)/k_s = 2ζ√(m/k_s).
static double damping_over_stiffness(double zeta, double kSeries, double mass) {
  return kSeries > 0.0 ? 2.0 * zeta * sqrt(mass / kSeries) : 0.0;
}

void pd_contact_modal_damping(pdContactParams* p, double massN, double massT, double stackN, double stackT,
                              double scale[2]) {
  scale[0] = scale[1] = 1.0;
  if (p->modalN) {
    double own = fmin(massN, p->massPair), m = fmax(own, stackN);
    scale[0] = sqrt(m / own);
    derived_dampers(damping_over_stiffness(p->zetaN, pd_series(p->k1n, p->k2n), m), p->k1n, p->k2n, &p->c1n, &p->c2n);
  }
  if (p->modalT) {
    double own = fmin(massT, p->massPair), m = fmax(own, stackT);
    scale[1] = sqrt(m / own);
    derived_dampers(damping_over_stiffness(p->zetaT, pd_series(p->k1t, p->k2t), m), p->k1t, p->k2t, &p->c1t, &p->c2t);
  }
  PD_ASSERT(pd_contact_params_valid(p));  // a mass that is not a number >= 0 gives NaN or negative dampers
}

// §3.3.1 for the pair: 1/ω = √(m_min/k_s) >= Δt_min, which bounds the period 2π/ω and, for ζ <= 1, the
// decay time 1/(ζω) too. Scales both sides of one direction by the factor that makes it equal.
static void check_pair_stiffness(double* k1, double* k2, double mMin, pdMaterialParam param, int body1, int body2,
                                 double dtmin, pdAdjustmentList* adj) {
  double ks = pd_series(*k1, *k2);
  if (!(ks > 0.0) || !(dtmin > 0.0)) return;
  double tau = sqrt(mMin / ks);
  if (tau >= dtmin) return;
  double f = (tau / dtmin) * (tau / dtmin);
  record(adj, pd_adjustPairStiffness, body1, body2, param, *k1, f * *k1, tau, dtmin);
  record(adj, pd_adjustPairStiffness, body2, body1, param, *k2, f * *k2, tau, dtmin);
  *k1 *= f;
  *k2 *= f;
}

// §3.3.1 for explicit dampers: the decay time 2 m_min/c_s must not be below Δt_min.
static void check_pair_decay(double* c1, double* c2, double mMin, pdMaterialParam param, int body1, int body2,
                             double dtmin, pdAdjustmentList* adj) {
  double cs = pd_series(*c1, *c2);
  if (!(cs > 0.0) || !(dtmin > 0.0)) return;
  double tau = 2.0 * mMin / cs;
  if (tau >= dtmin) return;
  double f = tau / dtmin;
  record(adj, pd_adjustPairDecay, body1, body2, param, *c1, f * *c1, tau, dtmin);
  record(adj, pd_adjustPairDecay, body2, body1, param, *c2, f * *c2, tau, dtmin);
  *c1 *= f;
  *c2 *= f;
}

// §3.3.2: the massless surface elements obey (c1 + c2) ẋ + (k1 + k2) x = 0 (eq. (16)), τ = (c1+c2)/(k1+k2)
// (eq. (17)). Only where the sides' c/k differ: proportional dampers have no surface-element mode.
// Δt_min > τ along n: both normal dampers become 0 (the paper's rule; the contact then takes the zero-
// damping branch). In P_t: both tangential stiffnesses are scaled by f = τ/Δt_min, which makes τ = Δt_min.
static void check_surface_elements(pdContactParams* out, int body1, int body2, double dtmin, pdAdjustmentList* adj) {
  double cn = out->c1n + out->c2n, kn = out->k1n + out->k2n;
  if (!out->proportionalN && cn > 0.0 && kn > 0.0 && dtmin > cn / kn) {
    double tau = cn / kn;
    if (out->c1n > 0.0) record(adj, pd_adjustContactNormal, body1, body2, pd_paramCn, out->c1n, 0.0, tau, dtmin);
    if (out->c2n > 0.0) record(adj, pd_adjustContactNormal, body2, body1, pd_paramCn, out->c2n, 0.0, tau, dtmin);
    out->c1n = out->c2n = 0.0;
  }
  double ct = out->c1t + out->c2t, kt = out->k1t + out->k2t;
  if (!out->proportionalT && out->mu > 0.0 && ct > 0.0 && kt > 0.0 && dtmin > ct / kt) {
    double tau = ct / kt, f = tau / dtmin;
    record(adj, pd_adjustContactTangential, body1, body2, pd_paramKt, out->k1t, f * out->k1t, tau, dtmin);
    record(adj, pd_adjustContactTangential, body2, body1, pd_paramKt, out->k2t, f * out->k2t, tau, dtmin);
    out->k1t *= f;
    out->k2t *= f;
  }
}

// One direction's dampers: modal when neither side gives one (set per contact later; here for one contact
// at m_pair), else the explicit values with the derived c/k for a side that gives none.
static void dampers(double given1, double given2, double k1, double k2, double zeta, double massPair, double* c1,
                    double* c2, bool* modal, bool* proportional) {
  double ratio = damping_over_stiffness(zeta, pd_series(k1, k2), massPair);
  derived_dampers(ratio, k1, k2, c1, c2);
  *modal = given1 < 0.0 && given2 < 0.0;
  if (given1 >= 0.0) *c1 = given1;
  if (given2 >= 0.0) *c2 = given2;
  // derived on both sides by construction; explicit on both sides when the exact products agree (one
  // material on both sides); one explicit and one derived side in general not
  *proportional = *modal || (given1 >= 0.0 && given2 >= 0.0 && given1 * k2 == given2 * k1);
}

void pd_contact_params_pair(const pdMaterialSide* s1, const pdMaterialSide* s2, double zetaN,
                            const pdMaterialSettings* set, int body1, int body2, pdContactParams* out,
                            pdAdjustmentList* adj) {
  PD_ASSERT(s1->mass > 0.0 || s2->mass > 0.0);
  const double massPair = reduced_mass(s1->mass, s2->mass), massMin = reduced_mass(s1->mMin, s2->mMin);
  // eq. (11) for the pair: ½ m_pair v_max² = ½ k_s δ_max², δ_max of the smaller body (bounded by the thinner
  // one's width); each side 2 k_s
  const double delta = pd_delta_max(set->deflection, s1->size, s1->width, s2->size, s2->width);
  const double kSide = 2.0 * massPair * set->vmax * set->vmax / (delta * delta);
  *out = (pdContactParams){.mu = sqrt(s1->mu * s2->mu), .zetaN = zetaN, .zetaT = PD_TANGENTIAL_DAMPING_RATIO,
                           .massPair = massPair, .massMin = massMin};
  out->k1n = s1->kn > 0.0 ? s1->kn : kSide;
  out->k2n = s2->kn > 0.0 ? s2->kn : kSide;
  out->k1t = s1->kt > 0.0 ? s1->kt : out->k1n;
  out->k2t = s2->kt > 0.0 ? s2->kt : out->k2n;
  out->loadSized = !(s1->kn > 0.0 || s2->kn > 0.0 || s1->kt > 0.0 || s2->kt > 0.0);
  check_pair_stiffness(&out->k1n, &out->k2n, massMin, pd_paramKn, body1, body2, set->dtmin, adj);
  check_pair_stiffness(&out->k1t, &out->k2t, massMin, pd_paramKt, body1, body2, set->dtmin, adj);
  dampers(s1->cn, s2->cn, out->k1n, out->k2n, out->zetaN, massPair, &out->c1n, &out->c2n, &out->modalN,
          &out->proportionalN);
  dampers(s1->ct, s2->ct, out->k1t, out->k2t, out->zetaT, massPair, &out->c1t, &out->c2t, &out->modalT,
          &out->proportionalT);
  if (!out->modalN) check_pair_decay(&out->c1n, &out->c2n, massMin, pd_paramCn, body1, body2, set->dtmin, adj);
  if (!out->modalT) check_pair_decay(&out->c1t, &out->c2t, massMin, pd_paramCt, body1, body2, set->dtmin, adj);
  check_surface_elements(out, body1, body2, set->dtmin, adj);
}
