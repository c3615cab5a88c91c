// polydyn — the stability bound of the explicit steppers (paper §3.3–§3.4: the contacts' time constants set the step
// an explicit method can take).
//
// A Gershgorin bound on the contacts' fastest undamped mode ω_max, in two parts — a cheap one formed for every new
// list, a tight one only when the step the stepper wants exceeds the cheap one's (pd_contact_set_limit_step) — and the
// step (h/2) ω_max ≤ PD_STABLE_STEP_OMEGA that follows from it; and the fixed stepper's bound for one contact of the
// stiffest pair (pd_model_fixed_step_max), which nothing enforces: polydyn run warns of it. A pair's springs and
// dampers, which the bound reads, are set in pair_params.c.
#ifdef PD_SELF_CHECKS
#include <gsl/gsl_eigen.h>
#endif

#include <math.h>
#include <string.h>

#include "contact_list.h"
#include "material.h"
#include "model_contact.h"

// Stability bound of the adaptive step (paper §3.3: the contact's time constants set the step it can
// take): (h/2) ω_max ≤ PD_STABLE_STEP_OMEGA (polydyn/model.h), ω_max a Gershgorin bound on the contacts' fastest
// mode (pd_stability_prepare). The margin below RK4's |hλ| ≈ 2.8 covers what the bound does not see (contacts coupled
// through a fixed body's neighbours count none). Without the bound the error control walks the step up to the
// stability edge, where round-off grows until a step is rejected: a block at rest then jitters at the tolerance
// (µm/s) instead of round-off.
// Stability bound of a Dormand–Prince 5(4) step (pd_contact_set_dopri_fraction). Its kept fifth-order result has the
// stability function R(z) = Σ_{k≤5} z^k/k! + z⁶/600 (the seventh stage has weight 0). A contact mode of frequency ω
// and damping ratio ζ ≤ 1 has λ = ω(−ζ ± i√(1 − ζ²)), so the step is stable for hω ≤ r(ζ), the distance from 0 to
// where the ray at that angle leaves |R| ≤ 1. Unlike RK4's, R's region barely holds the imaginary axis (|R(iy)| > 1
// from y = 0.997): an undamped mode is stable only to hω ≈ 1, a damped one far further. Each entry is a damping
// ratio ζ₀ and min r(ζ) over ζ ∈ [ζ₀, 1] (bisection on |R| = 1 along 1 001 rays); a list's least damped contact picks
// the last entry at or below its ζ, and the step is 0.95 r (the margin 2.5 leaves below RK4's own 2.62). The joint
// modes of several contacts are damped at least as much as the least damped of them (docs/integration.md).
// Overdamped modes enter through ω's overdamp factor (step_of), as RK4's do: along the negative real axis r = 3.307.
static const double PD_DOPRI_STABLE_RADIUS[][2] = {
    {0.0, 0.9972},  {0.01, 1.8721}, {0.02, 2.0791}, {0.03, 2.2153}, {0.04, 2.3187}, {0.05, 2.4026},
    {0.075, 2.5623}, {0.1, 2.6814}, {0.15, 2.8608}, {0.2, 3.0007}, {0.25, 3.1179}, {0.3, 3.2160},
    {0.35, 3.2811}, {0.8, 3.2848}, {0.85, 3.3050}, {0.9, 3.3066}};
#define PD_DOPRI_STABLE_MARGIN 0.95
// Relative margin on the stability bounds (pd_stability_prepare, stability_tight) against the rounding of their
// sums (~1e-15 relative): where a Gershgorin bound is exact (a single contact), rounding must not take it below
// ω_max².
#define PD_STABLE_MARGIN 1e-9

// ---------------------------------------------------------------- stability bound

// a [r]ₓ: pd_mat3_mul with the cross-product matrix [r]ₓ, its products with the zeros left out (the other terms added in the same
// order, so the same numbers up to the sign of a zero sum; the stability bound takes absolute values). a [r]ₓᵀ is
// a [−r]ₓ.
static pdMat3 mul_cross(const pdMat3* a, pdVec3 r) {
  pdMat3 m;
  for (int i = 0; i < 3; ++i) {
    const double* ai = a->m[i];
    m.m[i][0] = ai[1] * r.z + ai[2] * -r.y;
    m.m[i][1] = ai[0] * -r.z + ai[2] * r.x;
    m.m[i][2] = ai[0] * r.y + ai[1] * -r.x;
  }
  return m;
}


static double row_abs_sum(const pdMat3* m, int row) {
  return fabs(m->m[row][0]) + fabs(m->m[row][1]) + fabs(m->m[row][2]);
}

static double overdamp_factor(double zeta) { return zeta > 1.0 ? zeta + sqrt(zeta * zeta - 1.0) : 1.0; }

// The absolute row sums of m.
static pdVec3 row_abs_sums(const pdMat3* m) {
  return (pdVec3){row_abs_sum(m, 0), row_abs_sum(m, 1), row_abs_sum(m, 2)};
}

// rows[r] += scale Σ_p |a_rp| w_p: bounds row r's absolute sum of a·b summed over all b whose rows sum to w.
static void add_weighted_rows(const pdMat3* a, pdVec3 w, double scale, double rows[3]) {
  for (int r = 0; r < 3; ++r)
    rows[r] += scale * (fabs(a->m[r][0]) * w.x + fabs(a->m[r][1]) * w.y + fabs(a->m[r][2]) * w.z);
}

// A stack's dampers are sized for a mode slower than the pair's own (stack_modes.c), so c/k = τ is larger, and a
// mode at ω has the damping ratio τω/2 (dampers proportional to the springs): at the bound's ω_max it may be
// overdamped, with a real root ω(ζ + √(ζ² − 1)) up to τω². stackTau: the largest such τ of the list (0: none).
static double step_of(double omega2, double overdamp, double stackTau) {
  double omega = sqrt(omega2);
  omega *= fmax(overdamp, overdamp_factor(0.5 * stackTau * omega));
  // the stepper keeps the result of two half steps (integrator.c): they are the ones that must be stable
  return omega > 0.0 ? 2.0 * PD_STABLE_STEP_OMEGA / omega : INFINITY;
}

// The stability bound in two parts, both Gershgorin bounds on ω_max² (never below it; docs/integration.md).
// pd_stability_prepare (after every new list, O(contacts)) forms each contact's terms and a cheap bound of the
// contact-space matrix M above: by |Σ_j (A B_j)_rq| ≤ Σ_p |A_rp| |(B_j)_pq|, row r of contact i's Gershgorin sum
// is at most Σ over its moving ends B of Σ_p |(K_i^½)_rp| w_p / m_B + Σ_p |(K_i^½ [r_i]ₓᵀ)_rp| u_p, where w_p
// and u_p are the row-p absolute sums of K_j^½ and of W_B [r_j]ₓ K_j^½ summed over B's contacts j. Only when the
// step the stepper wants exceeds the cheap bound's (pd_contact_set_limit_step) is the tight one formed
// (stability_tight): the Gershgorin bound of the body-space matrix S, also O(contacts), and the bound is the
// smaller of the two. On a stack of boxes S's rows are far tighter than M's (a box's 16 contacts couple with each
// other in M, its 6 coordinates in S): on cases/bench/stack_20.scene ω_max² came out at 0.55–0.71 of M's exact
// Gershgorin bound (which was O(contacts × contacts per body); the true ω_max² 0.46–0.62 of it), so its steps
// are 1.2–1.35× longer. S's bound alone can be looser than M's (a box on an edge or a corner, its rows summing
// translation and rotation: up to 1.75× M's exact bound on cases/sweep/pile_10.scene), hence the minimum.

// Accumulates Gᵀ H into out (6 × 6) for G, H = [T | R] (3 × 6 each, given as their two 3 × 3 halves).
static void add_gram(const pdMat3* gT, const pdMat3* gR, const pdMat3* hT, const pdMat3* hR, double out[6][6]) {
  // G and H as 3 × 6 rows first: the loop over b then runs along contiguous rows, which the compiler vectorises
  // (each entry the same sum in the same order)
  double g[3][6], h[3][6];
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) {
      g[k][c] = gT->m[k][c], g[k][c + 3] = gR->m[k][c];
      h[k][c] = hT->m[k][c], h[k][c + 3] = hR->m[k][c];
    }
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) out[a][b] += g[0][a] * h[0][b] + g[1][a] * h[1][b] + g[2][a] * h[2][b];
}

// Contact i's G = K^½ J_iB 𝕄_B^-½ on its end e (body B): T = σ K^½ / √m_B, R = −σ K^½ [r]ₓ W_B^½.
static void contact_gram_factor(const stabilityTerms* t, int e, const bodySpaceBlock* b, pdMat3* T, pdMat3* R) {
  double sigma = e == 0 ? 1.0 : -1.0;
  pdMat3 krx = mul_cross(&t->k, t->arm[e]);
  pdMat3 krxw = pd_mat3_mul(&krx, &b->invSqrtInertia);
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) {
      T->m[r][q] = sigma * b->invSqrtMass * t->k.m[r][q];
      R->m[r][q] = -sigma * krxw.m[r][q];
    }
}

// Does moving body k have contacts in the list (a block of S)?
static bool has_block(const pdModel* model, const pdContactSet* set, int k) {
  return !model->bodies[k].fixed && set->bodyFirst[k] < set->bodyFirst[k + 1];
}

// Each block's 𝕄^-½ at `poses`, its sums cleared.
static void body_space_scales(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  for (int k = 0; k < model->bodyCount; ++k) {
    if (!has_block(model, set, k)) continue;
    const pdBody* body = &model->bodies[k];
    bodySpaceBlock* b = &set->bodyBlocks[k];
    b->invSqrtMass = sqrt(body->invMass);
    pdMat3 q = pd_mat3_mul(&poses[k].R, &body->principalAxes);  // principal axes in the world
    pdMat3 qd = q;
    for (int c = 0; c < 3; ++c) {
      double s = 1.0 / sqrt(body->principal[c]);
      for (int r = 0; r < 3; ++r) qd.m[r][c] *= s;
    }
    pdMat3 qt = pd_mat3_transpose(&q);
    b->invSqrtInertia = pd_mat3_mul(&qd, &qt);
    memset(b->diagonal, 0, sizeof b->diagonal);
    memset(b->rows, 0, sizeof b->rows);
  }
}

// The tight bound: the largest absolute row sum of S, over the blocks of every moving body with contacts and of
// every touching pair (the list is sorted by pair, so a pair's contacts are one run). ω_max², no margin.
static double stability_tight(const pdModel* model, pdContactSet* set) {
  body_space_scales(model, set, set->stablePoses);
  for (int first = 0, last; first < set->count; first = last) {
    const pdContactId* id0 = &set->items[first].id;
    int lo = id0->body1 < id0->body2 ? id0->body1 : id0->body2, hi = id0->body1 < id0->body2 ? id0->body2 : id0->body1;
    last = first + 1;
    while (last < set->count && compare_to_pair(&set->items[last].id, lo, hi) == 0) ++last;
    bool both = !model->bodies[lo].fixed && !model->bodies[hi].fixed;
    double pair[6][6] = {{0}};  // S_lo,hi
    for (int i = first; i < last; ++i) {
      const stabilityTerms* t = &set->stability[i];
      const pdContactId* id = &set->items[i].id;
      pdMat3 T[2], R[2];
      int ends[2] = {id->body1, id->body2};
      for (int e = 0; e < 2; ++e) {
        if (model->bodies[ends[e]].fixed) continue;
        bodySpaceBlock* b = &set->bodyBlocks[ends[e]];
        contact_gram_factor(t, e, b, &T[e], &R[e]);
        add_gram(&T[e], &R[e], &T[e], &R[e], b->diagonal);
      }
      if (both) {
        int eLo = id->body1 == lo ? 0 : 1;
        add_gram(&T[eLo], &R[eLo], &T[1 - eLo], &R[1 - eLo], pair);
      }
    }
    if (!both) continue;
    // S_hi,lo = S_lo,hiᵀ: lo's rows take the pair block's row sums, hi's its column sums
    bodySpaceBlock *bLo = &set->bodyBlocks[lo], *bHi = &set->bodyBlocks[hi];
    for (int a = 0; a < 6; ++a)
      for (int q = 0; q < 6; ++q) {
        bLo->rows[a] += fabs(pair[a][q]);
        bHi->rows[q] += fabs(pair[a][q]);
      }
  }
  double omega2 = 0.0;
  for (int k = 0; k < model->bodyCount; ++k) {
    if (!has_block(model, set, k)) continue;
    const bodySpaceBlock* b = &set->bodyBlocks[k];
    for (int a = 0; a < 6; ++a) {
      double row = b->rows[a];
      for (int q = 0; q < 6; ++q) row += fabs(b->diagonal[a][q]);
      omega2 = fmax(omega2, row);
    }
  }
  return omega2;
}

#ifdef PD_SELF_CHECKS
// Lists of at most this many contacts are checked (a dense eigenproblem of 3 × this size per list).
#define PD_STABILITY_CHECK_CONTACTS_MAX 32
// The self-check of the sanitizer and Debug builds: both bounds against ω_max², the largest eigenvalue (GSL) of
// the contact-space matrix M assembled from its own formula (the terms left and right), not from S.
static void stability_self_check(const pdModel* model, pdContactSet* set) {
  int c = set->count, n = 3 * c;
  if (c > PD_STABILITY_CHECK_CONTACTS_MAX) return;
  gsl_matrix* m = gsl_matrix_calloc((size_t)n, (size_t)n);
  PD_ASSERT(m != NULL);
  for (int i = 0; i < c; ++i)
    for (int j = 0; j < c; ++j) {
      const pdContactId *a = &set->items[i].id, *b = &set->items[j].id;
      const stabilityTerms *ti = &set->stability[i], *tj = &set->stability[j];
      int endsA[2] = {a->body1, a->body2}, endsB[2] = {b->body1, b->body2};
      for (int ea = 0; ea < 2; ++ea)
        for (int eb = 0; eb < 2; ++eb) {
          const pdBody* body = &model->bodies[endsA[ea]];
          if (endsA[ea] != endsB[eb] || body->fixed) continue;
          double sign = (ea == eb) ? 1.0 : -1.0;
          pdMat3 kk = pd_mat3_mul(&ti->k, &tj->k), rot = pd_mat3_mul(&ti->left[ea], &tj->right[eb]);
          for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q) {
              double v = sign * (kk.m[r][q] * body->invMass + rot.m[r][q]);
              *gsl_matrix_ptr(m, (size_t)(3 * i + r), (size_t)(3 * j + q)) += 0.5 * v;
              *gsl_matrix_ptr(m, (size_t)(3 * j + q), (size_t)(3 * i + r)) += 0.5 * v;
            }
        }
    }
  gsl_vector* eigenvalues = gsl_vector_alloc((size_t)n);
  gsl_eigen_symm_workspace* w = gsl_eigen_symm_alloc((size_t)n);
  PD_ASSERT(eigenvalues != NULL && w != NULL);
  gsl_eigen_symm(m, eigenvalues, w);
  double omega2 = gsl_vector_max(eigenvalues);
  gsl_eigen_symm_free(w);
  gsl_vector_free(eigenvalues);
  gsl_matrix_free(m);
  // the eigenvalue is exact to ~1e-15 of the largest entry; the bounds carry PD_STABLE_MARGIN
  double tight2 = stability_tight(model, set) * (1.0 + PD_STABLE_MARGIN);
  PD_ASSERT(set->cheapOmega2 >= omega2 * (1.0 - 1e-12));
  PD_ASSERT(tight2 >= omega2 * (1.0 - 1e-12));
}
#endif

void pd_stability_prepare(const pdModel* model, pdContactSet* set, const pdPose* poses) {
  set->stableKnown = false;
  if (set->count == 0) {
    set->stableStep = set->stableCheap = INFINITY;
    set->cheapOmega2 = 0.0;
    set->dampingMin = 1.0;
    set->stableKnown = true;
    return;
  }
  pd_contact_set_list_bodies(model, set);
  set->stablePoses = poses;
  set->stackTau = 0.0;
  set->dampingMin = 1.0;
  int bodies = model->bodyCount;
  for (int k = 0; k < bodies; ++k) set->bodyRowsK[k] = set->bodyRowsRight[k] = (pdVec3){0, 0, 0};
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    const pdContactParams* p = &c->params;
    stabilityTerms* t = &set->stability[i];
    // a sliding contact's tangential spring is held at the friction limit: no tangential mode
    bool sticks = p->mu > 0.0 && !c->force.slip;
    double sn = sqrt(pd_series(p->k1n, p->k2n)), st = sticks ? sqrt(pd_series(p->k1t, p->k2t)) : 0.0;
    pdVec3 n = c->normal;
    double nv[3] = {n.x, n.y, n.z};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) t->k.m[r][q] = (r == q ? st : 0.0) + (sn - st) * nv[r] * nv[q];
    double zn = isfinite(p->zetaN) ? p->zetaN : 0.0, zt = p->mu > 0.0 && isfinite(p->zetaT) ? p->zetaT : 0.0;
    if (p->modalN && c->stackScale[0] > 1.0) {
      double ks = pd_series(p->k1n, p->k2n);
      if (ks > 0.0) set->stackTau = fmax(set->stackTau, pd_series(p->c1n, p->c2n) / ks);
    }
    t->overdamp = fmax(overdamp_factor(zn), overdamp_factor(zt));
    set->dampingMin = fmin(set->dampingMin, sticks ? fmin(zn, zt) : zn);
    int ends[2] = {c->id.body1, c->id.body2};
    for (int e = 0; e < 2; ++e) {
      const pdBody* b = &model->bodies[ends[e]];
      if (b->fixed) continue;
      t->arm[e] = pd_v3_sub(c->point, poses[ends[e]].x);
      t->left[e] = mul_cross(&t->k, pd_v3_scale(t->arm[e], -1.0));
      pdMat3 wrx = mul_cross(&set->invInertiaWorld[ends[e]], t->arm[e]);
      t->right[e] = pd_mat3_mul(&wrx, &t->k);
      set->bodyRowsK[ends[e]] = pd_v3_add(set->bodyRowsK[ends[e]], row_abs_sums(&t->k));
      set->bodyRowsRight[ends[e]] = pd_v3_add(set->bodyRowsRight[ends[e]], row_abs_sums(&t->right[e]));
    }
  }
  // the cheap bound
  double cheap2 = 0.0;
  set->overdamp = 1.0;
  for (int i = 0; i < set->count; ++i) {
    const stabilityTerms* ti = &set->stability[i];
    set->overdamp = fmax(set->overdamp, ti->overdamp);
    double rows[3] = {0, 0, 0};
    int ends[2] = {set->items[i].id.body1, set->items[i].id.body2};
    for (int e = 0; e < 2; ++e) {
      const pdBody* b = &model->bodies[ends[e]];
      if (b->fixed) continue;
      add_weighted_rows(&ti->k, set->bodyRowsK[ends[e]], b->invMass, rows);
      add_weighted_rows(&ti->left[e], set->bodyRowsRight[ends[e]], 1.0, rows);
    }
    cheap2 = fmax(cheap2, fmax(rows[0], fmax(rows[1], rows[2])));
  }
  set->cheapOmega2 = cheap2 * (1.0 + PD_STABLE_MARGIN);
  set->stableCheap = step_of(set->cheapOmega2, set->overdamp, set->stackTau);
#ifdef PD_SELF_CHECKS
  stability_self_check(model, set);
#endif
}

long pd_contact_set_tight_formed(const pdContactSet* set) { return set->tightFormed; }

double pd_contact_set_limit_step(const pdModel* model, pdContactSet* set, double h, double fraction,
                                 bool* tightNeeded) {
  *tightNeeded = fraction * set->stableCheap < h;
  if (!*tightNeeded) return h;  // the bound, never below the cheap one's step, cannot bind
  if (!set->stableKnown) {
    ++set->tightFormed;
    double tight2 = stability_tight(model, set) * (1.0 + PD_STABLE_MARGIN);
    set->stableStep = step_of(fmin(set->cheapOmega2, tight2), set->overdamp, set->stackTau);
    set->stableKnown = true;
  }
  return fmin(h, fraction * set->stableStep);
}

double pd_contact_set_dopri_fraction(const pdContactSet* set) {
  int count = (int)(sizeof PD_DOPRI_STABLE_RADIUS / sizeof PD_DOPRI_STABLE_RADIUS[0]), entry = 0;
  while (entry + 1 < count && PD_DOPRI_STABLE_RADIUS[entry + 1][0] <= set->dampingMin) ++entry;
  return PD_DOPRI_STABLE_MARGIN * PD_DOPRI_STABLE_RADIUS[entry][1] / (2.0 * PD_STABLE_STEP_OMEGA);
}

// ---------------------------------------------------------------- the fixed stepper's bound

double pd_model_fixed_step_max(const pdModel* model) {
  const double twoPi = 6.28318530717958647692;
  return PD_STABLE_STEP_OMEGA * pd_model_contact_period_min(model) / twoPi;
}
