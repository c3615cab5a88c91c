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

// Brent's bracket on ζ ∈ [0, 1] shrinks to this width (absolute, ζ is dimensionless and O(1)). The
// catalogue's inverse table is given to 1e-4 and a restitution error of 1e-12 is far below anything a
// simulation can measure; 1e-13 leaves Brent well clear of roundoff (ζ is known to ~1e-16).
#define PD_ZETA_TOL_ABS 1e-13
// Brent converges superlinearly: ~40 iterations reach 1e-13 from [0, 1] even at bisection speed.
#define PD_ZETA_MAX_ITER 200

// ---------------------------------------------------------------- restitution

// h(ζ) = 2ζ arccos ζ/√(1 − ζ²) = −ln e: eq. (15) with atan(√(1−ζ²)/ζ) = arccos ζ for ζ ∈ (0, 1] and
// ln(E_r) = 2 ln e. Written with θ = arccos ζ as 2ζ θ/sin θ, which stays accurate as ζ → 1 (θ → 0,
// θ/sin θ → 1, h → 2: e → e⁻²).
static double neg_log_restitution(double zeta) {
  double theta = acos(zeta);
  return theta > 0.0 ? 2.0 * zeta * theta / sin(theta) : 2.0 * zeta;
}

double pd_restitution_from_damping_ratio(double zeta) {
  PD_ASSERT(zeta >= 0.0 && zeta <= 1.0);
  return exp(-neg_log_restitution(zeta));
}

static double zeta_residual(double zeta, void* params) {
  double logE = *(const double*)params;
  return neg_log_restitution(zeta) + logE;
}

bool pd_damping_ratio_from_restitution(double e, double* zeta, char* why, int whySize) {
  const double eMin = exp(-2.0);
  if (!(e >= 0.0 && e <= 1.0)) {
    pd_why(why, whySize, "restitution %g is outside [0, 1]", e);
    return false;
  }
  if (e < eMin) {
    pd_why(why, whySize,
           "restitution %g is unreachable: with a spring (k > 0) the contact model's smallest restitution is "
           "e^-2 = %.4f (critical damping, paper eq. 15)",
           e, eMin);
    return false;
  }
  if (e == 1.0) {
    *zeta = 0.0;
    return true;
  }
  double logE = log(e);
  if (neg_log_restitution(1.0) + logE <= 0.0) {  // e == e⁻² to roundoff: critical damping
    *zeta = 1.0;
    return true;
  }
  // h is increasing from h(0) = 0 to h(1) = 2, so [0, 1] brackets the root for e ∈ (e⁻², 1).
  gsl_function f = {.function = zeta_residual, .params = &logE};
  gsl_root_fsolver* solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  if (!solver) {
    pd_why(why, whySize, "out of memory in the restitution solver");
    return false;
  }
  gsl_error_handler_t* previous = gsl_set_error_handler_off();
  int status = gsl_root_fsolver_set(solver, &f, 0.0, 1.0);
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

// Fig. 5: a body of mass m on a plate of the same material; the two springs (k each) and the two dampers
// (c each) are in series, and equal c/k ratios make the series a single Kelvin–Voigt element with k/2 and
// c/2. Eq. (13) then has ζ = (c/2)/(2 m ω_n), ω_n = √((k/2)/m), i.e. ζ = (c/2)/(2√((k/2) m)), so
// c = 4ζ√(k m/2) = 2ζ√(2 k m).
double pd_body_damper_from_ratio(double zeta, double k, double m) {
  PD_ASSERT(zeta >= 0.0 && k >= 0.0 && m > 0.0);
  return 2.0 * zeta * sqrt(2.0 * k * m);
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
  switch (a->rule) {
    case pd_adjustBodyPeriod:
      return snprintf(buf, (size_t)size, "%s: %s %.6g -> %.6g %s (§3.3.1: τ = 2π√(m_min/k) = %.3g s < dt_min = %.3g s)",
                      bodyName, name, a->from, a->to, unit, a->tau, a->dtmin);
    case pd_adjustBodyDecay:
      return snprintf(buf, (size_t)size, "%s: %s %.6g -> %.6g %s (§3.3.1: τ = 2 m_min/c = %.3g s < dt_min = %.3g s)",
                      bodyName, name, a->from, a->to, unit, a->tau, a->dtmin);
    case pd_adjustContactNormal:
      return snprintf(buf, (size_t)size,
                      "%s: %s %.6g -> %.6g %s in contacts with %s (§3.3.2: τ = (c1n+c2n)/(k1n+k2n) = %.3g s < "
                      "dt_min = %.3g s: normal dampers off, the impact becomes elastic)",
                      bodyName, name, a->from, a->to, unit, partnerName, a->tau, a->dtmin);
    case pd_adjustContactTangential:
      return snprintf(buf, (size_t)size,
                      "%s: %s %.6g -> %.6g %s in contacts with %s (§3.3.2: τ = (c1t+c2t)/(k1t+k2t) = %.3g s < "
                      "dt_min = %.3g s)",
                      bodyName, name, a->from, a->to, unit, partnerName, a->tau, a->dtmin);
  }
  return snprintf(buf, (size_t)size, "%s: %s %.6g -> %.6g", bodyName, name, a->from, a->to);
}

// §3.3.1, stiffness: the undamped period 2π/ω_n = 2π√(m_min/k) must not be below Δt_min; if it is, the
// stiffness that makes it equal is k = m_min (2π/Δt_min)².
static double check_period(double k, const pdMaterialBody* b, double mMin, pdMaterialParam param, double dtmin,
                           pdAdjustmentList* adj) {
  if (!(k > 0.0) || !(dtmin > 0.0)) return k;
  double tau = 2.0 * PI * sqrt(mMin / k);
  if (dtmin <= tau) return k;
  double lowered = mMin * (2.0 * PI / dtmin) * (2.0 * PI / dtmin);
  record(adj, pd_adjustBodyPeriod, b->index, -1, param, k, lowered, tau, dtmin);
  return lowered;
}

// §3.3.1, damping: the decay time 1/(ζ ω_n) = 2 m/c must not be below Δt_min; if it is, c = 2 m_min/Δt_min.
static double check_decay(double c, const pdMaterialBody* b, double mMin, pdMaterialParam param, double dtmin,
                          pdAdjustmentList* adj) {
  if (!(c > 0.0) || !(dtmin > 0.0)) return c;
  double tau = 2.0 * mMin / c;
  if (dtmin <= tau) return c;
  double lowered = 2.0 * mMin / dtmin;
  record(adj, pd_adjustBodyDecay, b->index, -1, param, c, lowered, tau, dtmin);
  return lowered;
}

bool pd_material_body(const pdMaterialBody* body, const pdMaterialRequest* req, const pdMaterialSettings* s,
                      pdMaterialUsed* out, pdAdjustmentList* adj, char* why, int whySize) {
  const unsigned set = req->setMask;
  if (!(body->mass > 0.0 && isfinite(body->mass) && body->mMin > 0.0 &&
        body->size > 0.0 && isfinite(body->size))) {
    pd_why(why, whySize, "invalid body (mass %g kg, minimum effective mass %g kg, size %g m)", body->mass,
           body->mMin, body->size);
    return false;
  }
  if (!(s->vmax > 0.0 && isfinite(s->vmax) && s->deflection > 0.0 && s->deflection < 1.0 && s->dtmin >= 0.0)) {
    pd_why(why, whySize, "invalid material settings (vmax %g m/s, deflection %g, dtmin %g s)", s->vmax,
           s->deflection, s->dtmin);
    return false;
  }
  if (((set & PD_SET_KN) && !(req->kn > 0.0)) || ((set & PD_SET_KT) && !(req->kt > 0.0)) ||
      ((set & PD_SET_CN) && !(req->cn >= 0.0)) || ((set & PD_SET_CT) && !(req->ct >= 0.0)) || !(req->mu >= 0.0)) {
    pd_why(why, whySize, "invalid material request (kn %g, kt %g, cn %g, ct %g, mu %g)", req->kn, req->kt, req->cn,
           req->ct, req->mu);
    return false;
  }
  const double m = body->mass, mMin = body->mMin;
  *out = (pdMaterialUsed){.mu = req->mu, .mass = m, .mMin = mMin, .zeta = -1.0};

  // eq. (11): k_n = 2 E_max/δ_max², E_max = ½ m v_max², δ_max = deflection × size
  double delta = s->deflection * body->size;
  double kn = (set & PD_SET_KN) ? req->kn : m * s->vmax * s->vmax / (delta * delta);
  double kt = (set & PD_SET_KT) ? req->kt : kn;
  out->kn = check_period(kn, body, mMin, pd_paramKn, s->dtmin, adj);
  out->kt = check_period(kt, body, mMin, pd_paramKt, s->dtmin, adj);

  if (set & PD_SET_RESTITUTION) {
    if (!pd_damping_ratio_from_restitution(req->restitution, &out->zeta, why, whySize)) return false;
  }
  const bool fromE = out->zeta >= 0.0;
  double cn = (set & PD_SET_CN) ? req->cn : (fromE ? pd_body_damper_from_ratio(out->zeta, out->kn, m) : 0.0);
  double ct;
  if (set & PD_SET_CT)
    ct = req->ct;
  else if (s->ctRule == pd_ctCritical)
    ct = sqrt(4.0 * m * out->kt);
  else
    ct = fromE ? pd_body_damper_from_ratio(out->zeta, out->kt, m) : 0.0;
  out->cn = check_decay(cn, body, mMin, pd_paramCn, s->dtmin, adj);
  out->ct = check_decay(ct, body, mMin, pd_paramCt, s->dtmin, adj);
  return true;
}

bool pd_material_fixed_reference(const pdMaterialBody* bodies, int count, double* mass, double* mMin) {
  double heaviest = 0.0, lightest = INFINITY;
  bool any = false;
  for (int i = 0; i < count; ++i) {
    if (bodies[i].fixed) continue;
    any = true;
    heaviest = fmax(heaviest, bodies[i].mass);
    lightest = fmin(lightest, bodies[i].mMin);
  }
  if (!any) return false;
  *mass = heaviest;
  *mMin = lightest;
  return true;
}

bool pd_material_bodies(const pdMaterialBody* bodies, const pdMaterialRequest* reqs, int count,
                        const pdMaterialSettings* s, pdMaterialUsed* used, pdAdjustmentList* adj, int* failed,
                        char* why, int whySize) {
  double refMass = 0.0, refMMin = 0.0;
  bool haveRef = pd_material_fixed_reference(bodies, count, &refMass, &refMMin);
  for (int i = 0; i < count; ++i) {
    pdMaterialBody b = bodies[i];
    if (b.fixed && haveRef) b.mass = refMass, b.mMin = refMMin;
    if (!pd_material_body(&b, &reqs[i], s, &used[i], adj, why, whySize)) {
      if (failed) *failed = i;
      return false;
    }
  }
  return true;
}

// §3.3.2: the massless surface elements obey (c1 + c2) ẋ + (k1 + k2) x = 0 (eq. (16)), τ = (c1+c2)/(k1+k2)
// (eq. (17)). Δt_min > τ along n: both normal dampers become 0 (the paper's rule; the contact then takes
// the zero-damping branch). In P_t: both tangential stiffnesses are scaled by f = τ/Δt_min, which makes
// τ = Δt_min. The tangential check is skipped for frictionless pairs (μ = 0: no tangential springs).
void pd_contact_params_pair(const pdMaterialUsed* m1, const pdMaterialUsed* m2, int body1, int body2, double dtmin,
                            pdContactParams* out, pdAdjustmentList* adj) {
  *out = (pdContactParams){.k1n = m1->kn, .k2n = m2->kn, .k1t = m1->kt, .k2t = m2->kt,
                           .c1n = m1->cn, .c2n = m2->cn, .c1t = m1->ct, .c2t = m2->ct,
                           .mu = sqrt(m1->mu * m2->mu)};
  if (!(dtmin > 0.0)) return;
  double cn = out->c1n + out->c2n, kn = out->k1n + out->k2n;
  if (cn > 0.0 && kn > 0.0) {
    double tau = cn / kn;
    if (dtmin > tau) {
      if (out->c1n > 0.0) record(adj, pd_adjustContactNormal, body1, body2, pd_paramCn, out->c1n, 0.0, tau, dtmin);
      if (out->c2n > 0.0) record(adj, pd_adjustContactNormal, body2, body1, pd_paramCn, out->c2n, 0.0, tau, dtmin);
      out->c1n = out->c2n = 0.0;
    }
  }
  double ct = out->c1t + out->c2t, kt = out->k1t + out->k2t;
  if (out->mu > 0.0 && ct > 0.0 && kt > 0.0) {
    double tau = ct / kt;
    if (dtmin > tau) {
      double f = tau / dtmin;
      record(adj, pd_adjustContactTangential, body1, body2, pd_paramKt, out->k1t, f * out->k1t, tau, dtmin);
      record(adj, pd_adjustContactTangential, body2, body1, pd_paramKt, out->k2t, f * out->k2t, tau, dtmin);
      out->k1t *= f;
      out->k2t *= f;
    }
  }
}
