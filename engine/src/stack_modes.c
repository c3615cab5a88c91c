// polydyn — the contact modes of stacks (paper §3.3: the time constants of the contacts as the bodies see them).
//
// Design note. A pair's modal dampers are sized for a mode: c = 2ζ√(k_s m_c) gives the requested damping ratio ζ
// to the mode whose frequency is ω = √(k_s/m_c). For two bodies alone that is their joint motion (m_c from the pair,
// pair_params.c). In a stack the slow mode is another one: an 80 kg block on a 0.2 kg pad on a floor bounces on
// both interfaces in series at √(k/2/80), while each pair alone would size its dampers for the pad (ζ 0.01 left for
// the block). Only where the masses differ (PD_STACK_MASS_RATIO) and the slow mode is far slower than the pair's own
// (pair_params.c, PD_STACK_SLOW_FROM): among bodies of one mass the pair's own dampers are kept. Dampers proportional to the springs with one c/k = 2ζ/ω along a chain in series are one Kelvin–Voigt
// element, so the chain's mode at ω gets exactly ζ; hence each pair's dampers are sized for the slowest mode of its
// local system in which its springs hold a real share of the strain energy (min(1, s/PD_STACK_SHARE) weighs it: a
// light body resting on a heavy one holds ~(m/M)² of the heavy one's bounce and keeps its own, faster mode). The
// local system: the pair's moving bodies and their neighbours in contact (one ring, every contact touching them,
// bodies beyond held fixed); its undamped modes by GSL's symmetric eigensolver on 𝕄^-½ K 𝕄^-½ (≤ 72 × 72).
// Most pairs' answer is only "no mode slow enough" (a light body on a heavy one keeps its own dampers), which needs
// no eigenvectors: when the caller says how fast is fast enough, the eigenvalues alone (GSL's values-only solver, the
// same tridiagonalisation and QR steps, values bit for bit those of the solver with vectors) bound every mode's term,
// the few modes below the mark by an approximate eigenvector (inverse iteration) and its residual's angle bound; the
// vectors are computed, as before, only where that bound cannot show the slow frequency to be fast enough.
#include <gsl/gsl_complex_math.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "material.h"
#include "stack_modes.h"

// The share of a mode's strain energy at which a pair's springs count fully as taking part in it. In a chain of two
// equal interfaces in series (a heavy body on a light one on a floor) each holds 1/2 of the slow mode; a light body
// resting on a heavy one holds ~(m/M)² of the heavy one's bounce, so it keeps its own mode. A lower share (1/4, 1/3)
// also counts the slow modes of a ring of equal boxes fully: cases/hard/stack_10.scene then took 5 840 derivative
// evaluations to its 0.3 s, with 1/2 3 530 (2 543 with each pair's own dampers).
#define PD_STACK_SHARE 0.5
// A local system whose masses differ by at most this factor is not analysed: among bodies of one mass a pair's own
// mode and the slow modes around it are within the factor of PD_STACK_SLOW_FROM (pair_params.c), so the
// analysis would change nothing.
#define PD_STACK_MASS_RATIO 2.0
// Modes below this fraction of the largest eigenvalue are the local system's free motions (a body sliding
// without tangential springs): no strain, no damping to size.
#define PD_STACK_FREE_MODE 1e-12
// The same for the roots of the damped modes (pd_state_stack_modes: |λ|, not λ = ω²); a free motion's root is 0
// to the eigensolver's rounding, ~1e-16 of the largest.
#define PD_STACK_FREE_MODE_ROOT 1e-9
// The bound that spares the eigenvectors (fast_enough) answers "fast enough" only with this relative margin on Ω,
// far above the rounding that separates its estimates from the computed modes' (~1e-13 here), so that the answer is
// the one the eigenvectors would give.
#define PD_STACK_BOUND_MARGIN 1e-6
// The error allowed on a computed eigenvalue, relative to the largest: GSL's tridiagonalisation and QR are backward
// stable to ~n ε (~1.6e-14 at 72 rows); the residual bound's gaps are taken this much narrower.
#define PD_STACK_EIGEN_ERROR 1e-13
// An approximate eigenvector whose angle bound to the true one exceeds this is not used (the bound falls back to
// the eigenvectors): its energy bound would be loose by 3 sin θ of the pair's springs' trace.
#define PD_STACK_ANGLE_MAX 1e-3
// Inverse iteration steps at most for one slow mode; at a shift within rounding of a simple eigenvalue one step
// leaves a residual at rounding level, a second one what a poor start vector left.
#define PD_STACK_INVERSE_STEPS 3

#define LOCAL_DOFS (6 * PD_STACK_LOCAL_BODIES_MAX)

// A moving body's 𝕄^-½: 1/√m and W^½ = R P diag(I_k^-½) (R P)ᵀ at its pose (P its principal axes).
typedef struct massScale {
  double invSqrtMass;
  pdMat3 invSqrtInertia;
  pdVec3 x;  // its centre of mass, world
} massScale;

struct pdStackScratch {
  gsl_eigen_symmv_workspace* work[PD_STACK_LOCAL_BODIES_MAX + 1];  // by body count, made when first needed
  gsl_eigen_symm_workspace* valuesWork[PD_STACK_LOCAL_BODIES_MAX + 1];  // the values-only solver's, likewise
  int members[PD_STACK_LOCAL_BODIES_MAX];
  int memberCount;  // the pair's own moving bodies first
  massScale scale[PD_STACK_LOCAL_BODIES_MAX];
  double a[LOCAL_DOFS * LOCAL_DOFS], vectors[LOCAL_DOFS * LOCAL_DOFS], values[LOCAL_DOFS];
  // The matrix whose modes `vectors` and `values` hold (decomposedDofs rows; 0: none). When the contacts of a body
  // change, every pair around it is analysed again at the same poses, and two pairs whose local systems list the same
  // bodies in the same order (a body resting on a fixed one and that body with its lowest neighbour) build the same
  // matrix bit for bit: the decomposition is then read again rather than repeated (~6 M instructions at 72 rows).
  double decomposed[LOCAL_DOFS * LOCAL_DOFS];
  int decomposedDofs;
  bool vectorsKept;  // `vectors` hold the decomposition's vectors (false: its values only)
  // The values alone did not answer the last pair that asked (fast_enough): the next goes to the eigenvectors
  // first, and its answer from them says whether the values would have done. The pairs around one body, analysed
  // in turn at one commit, share their local systems' slow mechanisms (a board rocking on two of its contacts).
  bool valuesFailed;
  long reuses;
  // fast_enough's work: a copy of the matrix for the values-only solver, then its shifted LU factors and their row
  // permutation's storage (a gsl_permutation of the local system's rows is made over it where it is used)
  double lu[LOCAL_DOFS * LOCAL_DOFS];
  size_t pivot[LOCAL_DOFS];
  double u[LOCAL_DOFS], au[LOCAL_DOFS];
};

// Not zeroed: ~125 kB that a contact list's first modal dampers would otherwise clear (a tenth of a short drop's whole
// run); the matrices are cleared or written where they are used, the members counted from 0 there.
pdStackScratch* pd_stack_scratch_create(void) {
  pdStackScratch* s = pd_grow(NULL, 1, sizeof *s);
  for (int k = 0; k <= PD_STACK_LOCAL_BODIES_MAX; ++k) s->work[k] = NULL, s->valuesWork[k] = NULL;
  s->memberCount = 0;
  s->decomposedDofs = 0;
  s->vectorsKept = false;
  s->valuesFailed = false;
  s->reuses = 0;
  return s;
}

long pd_stack_scratch_reuses(const pdStackScratch* scratch) { return scratch->reuses; }

void pd_stack_scratch_free(pdStackScratch* scratch) {
  if (!scratch) return;
  for (int k = 0; k <= PD_STACK_LOCAL_BODIES_MAX; ++k) {
    if (scratch->work[k]) gsl_eigen_symmv_free(scratch->work[k]);
    if (scratch->valuesWork[k]) gsl_eigen_symm_free(scratch->valuesWork[k]);
  }
  free(scratch);
}

static int local_index(const pdStackScratch* s, int body) {
  for (int k = 0; k < s->memberCount; ++k)
    if (s->members[k] == body) return k;
  return -1;
}

static void add_member(const pdModel* model, pdStackScratch* s, int body) {
  if (model->bodies[body].fixed || s->memberCount == PD_STACK_LOCAL_BODIES_MAX || local_index(s, body) >= 0) return;
  s->members[s->memberCount++] = body;
}

static int body_contacts(const pdContactSet* set, int body) { return set->bodyFirst[body + 1] - set->bodyFirst[body]; }

// The pair's moving bodies, then their neighbours in contact in body order (up to the cap). False when the pair's
// bodies touch nothing but each other.
static bool gather_members(const pdModel* model, const pdContactSet* set, int a, int b, int pairContacts,
                           pdStackScratch* s) {
  s->memberCount = 0;
  add_member(model, s, a);
  add_member(model, s, b);
  int own = s->memberCount;
  bool alone = true;
  for (int m = 0; m < own; ++m) alone = alone && body_contacts(set, s->members[m]) == pairContacts;
  if (alone) return false;
  // neighbours in body order: repeatedly the lowest body index not yet taken
  for (int last = -1;;) {
    int next = -1;
    for (int m = 0; m < own; ++m) {
      int k = s->members[m];
      for (int l = set->bodyFirst[k]; l < set->bodyFirst[k + 1]; ++l) {
        const pdContactId* id = &set->items[set->bodyList[l] / 2].id;
        int other = id->body1 == k ? id->body2 : id->body1;
        if (other > last && (next < 0 || other < next) && !model->bodies[other].fixed && local_index(s, other) < 0)
          next = other;
      }
    }
    if (next < 0 || s->memberCount == PD_STACK_LOCAL_BODIES_MAX) break;
    add_member(model, s, next);
    last = next;
  }
  return true;
}

static massScale mass_scale(const pdBody* body, const pdPose* pose) {
  massScale m = {.invSqrtMass = sqrt(body->invMass), .x = pose->x};
  pdMat3 q = pd_mat3_mul(&pose->R, &body->principalAxes);
  pdMat3 qd = q;
  for (int c = 0; c < 3; ++c) {
    double f = 1.0 / sqrt(body->principal[c]);
    for (int r = 0; r < 3; ++r) qd.m[r][c] *= f;
  }
  pdMat3 qt = pd_mat3_transpose(&q);
  m.invSqrtInertia = pd_mat3_mul(&qd, &qt);
  return m;
}

// One end of a direction d of contact c in mass-scaled coordinates: h = 𝕄^-½ g, g = σ [d, r × d] (σ = ±1, the
// relative displacement along d is g · q). Returns the member index, or -1 for a fixed or outside end.
typedef struct scaledEnd {
  int member;
  double h[6];
} scaledEnd;

static scaledEnd scaled_end(int member, const massScale* scale, double sigma, pdVec3 point, pdVec3 d) {
  scaledEnd e = {member, {0}};
  if (member < 0) return e;
  const massScale* m = &scale[member];
  pdVec3 lin = pd_v3_scale(d, sigma * m->invSqrtMass);
  pdVec3 ang = pd_v3_scale(pd_mat3_mulv(&m->invSqrtInertia, pd_v3_cross(pd_v3_sub(point, m->x), d)), sigma);
  double h[6] = {lin.x, lin.y, lin.z, ang.x, ang.y, ang.z};
  memcpy(e.h, h, sizeof h);
  return e;
}

// The tangent plane of normal n as the columns of I − n nᵀ: their outer products sum to the projector.
static void tangent_directions(pdVec3 n, pdVec3 dirs[3]) {
  double nv[3] = {n.x, n.y, n.z};
  for (int col = 0; col < 3; ++col)
    dirs[col] = (pdVec3){(col == 0) - nv[0] * nv[col], (col == 1) - nv[1] * nv[col], (col == 2) - nv[2] * nv[col]};
}

// A += k h hᵀ over both ends' blocks.
static void add_contact(double* a, int n, double k, const scaledEnd ends[2]) {
  for (int e = 0; e < 2; ++e) {
    if (ends[e].member < 0) continue;
    for (int f = 0; f < 2; ++f) {
      if (ends[f].member < 0) continue;
      for (int r = 0; r < 6; ++r)
        for (int q = 0; q < 6; ++q)
          a[(6 * ends[e].member + r) * n + 6 * ends[f].member + q] += k * ends[e].h[r] * ends[f].h[q];
    }
  }
}

static double project(const scaledEnd ends[2], const double* vectors, int n, int mode) {
  double sum = 0.0;
  for (int e = 0; e < 2; ++e)
    if (ends[e].member >= 0)
      for (int r = 0; r < 6; ++r) sum += ends[e].h[r] * vectors[(6 * ends[e].member + r) * n + mode];
  return sum;
}

static void contact_ends(const pdStackScratch* s, const contactSlot* c, pdVec3 d, scaledEnd ends[2]) {
  ends[0] = scaled_end(local_index(s, c->id.body1), s->scale, 1.0, c->point, d);
  ends[1] = scaled_end(local_index(s, c->id.body2), s->scale, -1.0, c->point, d);
}

// Σ k |h|² over the pair's contacts: the trace of its springs' share of the matrix, which bounds that share's norm.
static double pair_trace(const pdContactSet* set, int first, int last, const pdStackScratch* s) {
  double trace = 0.0;
  for (int i = first; i < last; ++i) {
    const contactSlot* c = &set->items[i];
    scaledEnd ends[2];
    contact_ends(s, c, c->normal, ends);
    double sum = 0.0;
    for (int e = 0; e < 2; ++e)
      if (ends[e].member >= 0)
        for (int r = 0; r < 6; ++r) sum += ends[e].h[r] * ends[e].h[r];
    trace += pd_series(c->params.k1n, c->params.k2n) * sum;
  }
  return trace;
}

// Factorises a − shift I (n rows, from s->decomposed) into s->lu and *perm by GSL's LU with partial pivoting. False
// at an exactly zero pivot (a shift at an eigenvalue can make the matrix singular in floating point): GSL 2.7 divides
// the column by it (the factors below it NaN, the status still success), later versions stop there (the factors
// incomplete), so no pivot can be patched; the eigenvectors decide instead, the same answer. gsl_linalg_LU_svx, which
// refuses a zero diagonal through GSL's error handler (abort by default), only ever sees a nonsingular factor.
static bool factor_shifted(pdStackScratch* s, int n, double shift, gsl_permutation* perm) {
  double* t = s->lu;
  memcpy(t, s->decomposed, sizeof(double) * (size_t)(n * n));
  for (int i = 0; i < n; ++i) t[i * n + i] -= shift;
  gsl_matrix_view lu = gsl_matrix_view_array(t, (size_t)n, (size_t)n);
  int signum;
  if (gsl_linalg_LU_decomp(&lu.matrix, perm, &signum) != GSL_SUCCESS) return false;
  for (int i = 0; i < n; ++i)
    if (!(fabs(t[i * n + i]) > 0.0) || !isfinite(t[i * n + i])) return false;
  return true;
}

// An upper bound on the strain energy of mode j (eigenvalue values[j], the decomposition's) in the pair's springs,
// Σ k (h · v_j)², from an approximate eigenvector u by inverse iteration: with ρ = uᵀAu and r = Au − ρu, the angle
// between u and v_j is at most |r| / gap (the sin θ theorem; gap: ρ to the nearest other eigenvalue), and
// |v_jᵀ P v_j − uᵀ P u| <= 3 |P| sin θ for the pair's share P (|P| <= its trace). The computed vector the solver
// with vectors would give lies within its own rounding of v_j, allowed for as an eigenvalue error `error`.
// Negative: no bound (a cluster of eigenvalues, a residual too large, or an exactly singular shifted matrix).
static double slow_mode_energy(const pdContactSet* set, int first, int last, pdStackScratch* s, int n, int j,
                               double error, double trace) {
  double mu = s->values[j], gap = INFINITY;
  for (int i = 0; i < n; ++i)
    if (i != j) gap = fmin(gap, fabs(s->values[i] - mu));
  if (!(gap > 4.0 * error)) return -1.0;
  gsl_permutation perm = {.size = (size_t)n, .data = s->pivot};
  if (!factor_shifted(s, n, mu, &perm)) return -1.0;
  gsl_matrix_const_view lu = gsl_matrix_const_view_array(s->lu, (size_t)n, (size_t)n);
  gsl_vector_view uv = gsl_vector_view_array(s->u, (size_t)n);
  double* u = s->u;
  for (int i = 0; i < n; ++i) u[i] = 1.0 + 0.1 * (double)(i % 7) + 0.01 * (double)i;  // not special to any mode
  double sinTheta = INFINITY;
  for (int step = 0; step < PD_STACK_INVERSE_STEPS && !(sinTheta <= PD_STACK_ANGLE_MAX * 1e-6); ++step) {
    gsl_linalg_LU_svx(&lu.matrix, &perm, &uv.vector);
    double norm = 0.0;
    for (int i = 0; i < n; ++i) norm += u[i] * u[i];
    norm = sqrt(norm);
    if (!(norm > 0.0) || !isfinite(norm)) return -1.0;
    for (int i = 0; i < n; ++i) u[i] /= norm;
    double rho = 0.0;
    for (int r = 0; r < n; ++r) {
      double acc = 0.0;
      for (int q = 0; q < n; ++q) acc += s->decomposed[r * n + q] * u[q];
      s->au[r] = acc;
      rho += u[r] * acc;
    }
    double residual = 0.0;
    for (int r = 0; r < n; ++r) residual += (s->au[r] - rho * u[r]) * (s->au[r] - rho * u[r]);
    double away = gap - fabs(rho - mu) - error;
    // the residual's own rounding and the solver's vector's distance from v_j: two eigenvalue errors more
    sinTheta = away > 0.0 ? (sqrt(residual) + 2.0 * error) / away : INFINITY;
  }
  if (!(sinTheta <= PD_STACK_ANGLE_MAX)) return -1.0;
  double energy = 0.0;
  for (int i = first; i < last; ++i) {
    const contactSlot* c = &set->items[i];
    scaledEnd ends[2];
    contact_ends(s, c, c->normal, ends);
    double x = project(ends, u, 1, 0);  // u as a one-column matrix
    energy += pd_series(c->params.k1n, c->params.k2n) * x * x;
  }
  return energy + trace * (3.0 * sinTheta + PD_STACK_EIGEN_ERROR);
}

// Whether every mode's term min(1, s_j / PD_STACK_SHARE) / ω_j is at most 1/fast with PD_STACK_BOUND_MARGIN to
// spare, from the decomposition's eigenvalues: a mode at or above `fast` by its eigenvalue alone (its term is at most
// 1/ω_j), one below it by its energy bound (slow_mode_energy). The free modes are those slow_period skips: the
// values-only solver's eigenvalues are the other's bit for bit (tests/engine/test_stack_damping.c).
static bool fast_enough(const pdContactSet* set, int first, int last, pdStackScratch* s, int n, double fast) {
  double largest = 0.0;
  for (int j = 0; j < n; ++j) largest = fmax(largest, s->values[j]);
  if (!(largest > 0.0)) return false;
  double error = PD_STACK_EIGEN_ERROR * largest;
  double mark = fast * (1.0 + PD_STACK_BOUND_MARGIN);
  double trace = -1.0;  // not yet formed: most matrices have no mode below the mark
  // first the modes no energy bound can clear, before any inverse iteration: the term reaches 1/mark at an energy
  // below the bound's own allowance (a mechanism of the normal springs, ω_j ~ 1e-5 of the largest)
  for (int j = 0; j < n; ++j) {
    double lambda = s->values[j];
    if (!(lambda > PD_STACK_FREE_MODE * largest)) continue;
    double low = lambda - error;  // the smallest the true eigenvalue may be
    if (!(low > 0.0)) return false;
    if (sqrt(low) >= mark) continue;
    if (trace < 0.0) trace = pair_trace(set, first, last, s);
    if (low * sqrt(low) * PD_STACK_SHARE / mark <= 2.0 * PD_STACK_EIGEN_ERROR * trace) return false;
  }
  for (int j = 0; j < n; ++j) {
    double lambda = s->values[j];
    if (!(lambda > PD_STACK_FREE_MODE * largest)) continue;
    double low = lambda - error;
    if (sqrt(low) >= mark) continue;
    double energy = slow_mode_energy(set, first, last, s, n, j, error, trace);
    if (!(energy >= 0.0)) return false;
    if (fmin(1.0, energy / low / PD_STACK_SHARE) / sqrt(low) * mark > 1.0) return false;
  }
  return true;
}

// 1/Ω along the normals (0: no normal stiffness). With fast > 0, *isFast when the eigenvalues alone show 1/Ω to be
// at most 1/fast (fast_enough; the period is then not computed: 0).
static double slow_period(const pdContactSet* set, int first, int last, pdStackScratch* s, double fast,
                          bool* isFast) {
  int n = 6 * s->memberCount;
  *isFast = false;
  memset(s->a, 0, sizeof(double) * (size_t)(n * n));
  bool any = false;
  for (int m = 0; m < s->memberCount; ++m) {
    int body = s->members[m];
    for (int l = set->bodyFirst[body]; l < set->bodyFirst[body + 1]; ++l) {
      const contactSlot* c = &set->items[set->bodyList[l] / 2];
      int other = local_index(s, c->id.body1 == body ? c->id.body2 : c->id.body1);
      if (other >= 0 && other < m) continue;  // a contact between two members, added at the first
      double k = pd_series(c->params.k1n, c->params.k2n);
      if (!(k > 0.0)) continue;
      scaledEnd ends[2];
      contact_ends(s, c, c->normal, ends);
      add_contact(s->a, n, k, ends);
      any = true;
    }
  }
  if (!any) return 0.0;
  size_t bytes = sizeof(double) * (size_t)(n * n);
  bool same = s->decomposedDofs == n && memcmp(s->a, s->decomposed, bytes) == 0;
  if (same) ++s->reuses;
  if (fast > 0.0 && !s->valuesFailed) {
    if (!same) {
      memcpy(s->decomposed, s->a, bytes);
      s->decomposedDofs = 0;
      gsl_eigen_symm_workspace** w = &s->valuesWork[s->memberCount];
      if (!*w) *w = gsl_eigen_symm_alloc((size_t)n);
      PD_ASSERT(*w != NULL);
      memcpy(s->lu, s->a, bytes);  // the solver overwrites its matrix
      gsl_matrix_view a = gsl_matrix_view_array(s->lu, (size_t)n, (size_t)n);
      gsl_vector_view values = gsl_vector_view_array(s->values, (size_t)n);
      if (gsl_eigen_symm(&a.matrix, &values.vector, *w) == GSL_SUCCESS) {
        s->decomposedDofs = n;
        s->vectorsKept = false;
        same = true;
      }
    }
    if (same && fast_enough(set, first, last, s, n, fast)) {
      *isFast = true;
      return 0.0;
    }
    s->valuesFailed = true;
  }
  if (!same || !s->vectorsKept) {
    memcpy(s->decomposed, s->a, bytes);  // before the solver overwrites a
    s->decomposedDofs = 0;
    gsl_eigen_symmv_workspace** w = &s->work[s->memberCount];
    if (!*w) *w = gsl_eigen_symmv_alloc((size_t)n);
    PD_ASSERT(*w != NULL);
    gsl_matrix_view a = gsl_matrix_view_array(s->a, (size_t)n, (size_t)n);
    gsl_matrix_view v = gsl_matrix_view_array(s->vectors, (size_t)n, (size_t)n);
    gsl_vector_view values = gsl_vector_view_array(s->values, (size_t)n);
    if (gsl_eigen_symmv(&a.matrix, &values.vector, &v.matrix, *w) != GSL_SUCCESS) return 0.0;
    s->decomposedDofs = n;
    s->vectorsKept = true;
    if (fast > 0.0 && s->valuesFailed && fast_enough(set, first, last, s, n, fast)) {
      s->valuesFailed = false;  // the values would have answered: the next pair tries them first
      *isFast = true;
      return 0.0;
    }
  }
  double largest = 0.0;
  for (int j = 0; j < n; ++j) largest = fmax(largest, s->values[j]);
  double period = 0.0;
  for (int j = 0; j < n; ++j) {
    double lambda = s->values[j];
    if (!(lambda > PD_STACK_FREE_MODE * largest)) continue;
    double energy = 0.0;
    for (int i = first; i < last; ++i) {
      const contactSlot* c = &set->items[i];
      scaledEnd ends[2];
      contact_ends(s, c, c->normal, ends);
      double x = project(ends, s->vectors, n, j);
      energy += pd_series(c->params.k1n, c->params.k2n) * x * x;
    }
    period = fmax(period, fmin(1.0, energy / lambda / PD_STACK_SHARE) / sqrt(lambda));
  }
  return period;
}

bool pd_stack_pair_frequency(const pdModel* model, const pdContactSet* set, const pdPose* poses, int first, int last,
                             double fast, pdStackScratch* scratch, double* omega) {
  PD_ASSERT(set->bodyListValid);
  const pdContactId* id = &set->items[first].id;
  int a = id->body1 < id->body2 ? id->body1 : id->body2, b = id->body1 < id->body2 ? id->body2 : id->body1;
  if (!gather_members(model, set, a, b, last - first, scratch)) return false;
  double lightest = INFINITY, heaviest = 0.0;
  for (int m = 0; m < scratch->memberCount; ++m) {
    lightest = fmin(lightest, model->bodies[scratch->members[m]].mass);
    heaviest = fmax(heaviest, model->bodies[scratch->members[m]].mass);
  }
  if (!(heaviest > PD_STACK_MASS_RATIO * lightest)) return false;
  // A mode slower than the whole local system's mass on the pair's springs, each in series with one spring per
  // body, is a mechanism of the normal springs alone (a box rocking about a line of two contacts, which gravity and
  // the tangential springs hold), not a bounce: Ω² >= count k_s / (members · Σ m).
  const pdContactParams* p = &set->items[first].params;
  double total = 0.0;
  for (int m = 0; m < scratch->memberCount; ++m) total += model->bodies[scratch->members[m]].mass;
  double slowest = (last - first) * pd_series(p->k1n, p->k2n) / (scratch->memberCount * total);
  if (fast > 0.0 && sqrt(slowest) >= fast * (1.0 + PD_STACK_BOUND_MARGIN)) return false;  // fast enough unanalysed
  for (int m = 0; m < scratch->memberCount; ++m)
    scratch->scale[m] = mass_scale(&model->bodies[scratch->members[m]], &poses[scratch->members[m]]);
  bool isFast;
  double period = slow_period(set, first, last, scratch, fast, &isFast);
  if (isFast || !(period > 0.0)) return false;
  *omega = fmax(1.0 / period, sqrt(slowest));
  return true;
}

// ---------------------------------------------------------------- the damped modes of a state's stacks

static int find_root(int* parent, int k) {
  while (parent[k] != k) k = parent[k] = parent[parent[k]];
  return k;
}

int pd_state_stacks(const pdModel* model, const pdState* state, int* stackOf) {
  PD_ASSERT(model != NULL && state != NULL && stackOf != NULL);
  const pdContactSet* set = state->contacts;
  int n = model->bodyCount;
  int* parent = pd_grow(NULL, (size_t)n, sizeof *parent);
  bool* touched = pd_zeroed((size_t)n, sizeof *touched);
  for (int k = 0; k < n; ++k) parent[k] = k;
  for (int i = 0; i < set->count; ++i) {
    int a = set->items[i].id.body1, b = set->items[i].id.body2;
    touched[a] = touched[b] = true;
    if (model->bodies[a].fixed || model->bodies[b].fixed) continue;
    int ra = find_root(parent, a), rb = find_root(parent, b);
    if (ra < rb) parent[rb] = ra;
    if (rb < ra) parent[ra] = rb;  // the root is the lowest body index
  }
  int count = 0;
  for (int k = 0; k < n; ++k) {
    stackOf[k] = -1;
    if (model->bodies[k].fixed || !touched[k]) continue;
    int root = find_root(parent, k);
    stackOf[k] = root == k ? count++ : stackOf[root];
  }
  free(parent);
  free(touched);
  return count;
}

// Both ends' rows of one direction of a contact in the stack's mass-scaled coordinates, added to out as k h hᵀ.
static void add_scaled(const int* local, const massScale* scale, const contactSlot* c, pdVec3 d, double k, double* out,
                       int dim) {
  scaledEnd ends[2] = {scaled_end(local[c->id.body1], scale, 1.0, c->point, d),
                       scaled_end(local[c->id.body2], scale, -1.0, c->point, d)};
  add_contact(out, dim, k, ends);
}

static int compare_modes(const void* a, const void* b) {
  const pdStackMode *x = a, *y = b;
  if (x->omega != y->omega) return x->omega < y->omega ? -1 : 1;
  return (x->zeta > y->zeta) - (x->zeta < y->zeta);
}

int pd_stack_modes(const pdModel* model, const pdContactSet* set, const pdBodyState* bodies, const int* stackOf,
                   int stack, pdStackMode* modes, int capacity) {
  PD_ASSERT(model != NULL && bodies != NULL && stackOf != NULL && capacity >= 0 &&
            (modes != NULL || capacity == 0));
  int n = model->bodyCount, members = 0;
  int* local = pd_grow(NULL, (size_t)n, sizeof *local);
  for (int k = 0; k < n; ++k) local[k] = stackOf[k] == stack && stack >= 0 ? members++ : -1;
  if (members > PD_STACK_MODES_BODIES_MAX || members == 0) {
    free(local);
    return members == 0 ? 0 : -1;
  }
  massScale* scale = pd_grow(NULL, (size_t)members, sizeof *scale);
  for (int k = 0; k < n; ++k)
    if (local[k] >= 0) {
      pdBodyState b = bodies[k];
      pdPose pose = pose_of(b.x, b.q);
      scale[local[k]] = mass_scale(&model->bodies[k], &pose);
    }
  int dim = 6 * members;
  double* k = pd_zeroed((size_t)(dim * dim), sizeof *k);
  double* c = pd_zeroed((size_t)(dim * dim), sizeof *c);
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* slot = &set->items[i];
    if (local[slot->id.body1] < 0 && local[slot->id.body2] < 0) continue;
    const pdContactParams* p = &slot->params;
    add_scaled(local, scale, slot, slot->normal, pd_series(p->k1n, p->k2n), k, dim);
    add_scaled(local, scale, slot, slot->normal, pd_series(p->c1n, p->c2n), c, dim);
    if (!(p->mu > 0.0) || slot->force.slip) continue;
    pdVec3 dirs[3];
    tangent_directions(slot->normal, dirs);
    for (int d = 0; d < 3; ++d) {
      add_scaled(local, scale, slot, dirs[d], pd_series(p->k1t, p->k2t), k, dim);
      add_scaled(local, scale, slot, dirs[d], pd_series(p->c1t, p->c2t), c, dim);
    }
  }
  // first-order form: d/dt (q, q̇) = [[0, I], [−K, −C]] (q, q̇), in mass-scaled coordinates
  int order = 2 * dim;
  gsl_matrix* a = gsl_matrix_calloc((size_t)order, (size_t)order);
  gsl_vector_complex* roots = gsl_vector_complex_alloc((size_t)order);
  gsl_eigen_nonsymm_workspace* w = gsl_eigen_nonsymm_alloc((size_t)order);
  PD_ASSERT(a != NULL && roots != NULL && w != NULL);
  for (int r = 0; r < dim; ++r) {
    gsl_matrix_set(a, (size_t)r, (size_t)(dim + r), 1.0);
    for (int q = 0; q < dim; ++q) {
      gsl_matrix_set(a, (size_t)(dim + r), (size_t)q, -k[r * dim + q]);
      gsl_matrix_set(a, (size_t)(dim + r), (size_t)(dim + q), -c[r * dim + q]);
    }
  }
  int found = 0;
  pdStackMode* all = pd_grow(NULL, (size_t)order, sizeof *all);
  if (gsl_eigen_nonsymm(a, roots, w) == GSL_SUCCESS) {
    double largest = 0.0;
    for (int j = 0; j < order; ++j) largest = fmax(largest, gsl_complex_abs(gsl_vector_complex_get(roots, (size_t)j)));
    for (int j = 0; j < order; ++j) {
      gsl_complex z = gsl_vector_complex_get(roots, (size_t)j);
      double re = GSL_REAL(z), im = GSL_IMAG(z), abs = gsl_complex_abs(z);
      if (im < 0.0 || !(abs > PD_STACK_FREE_MODE_ROOT * largest)) continue;  // a conjugate, or a free motion
      all[found++] = (pdStackMode){.omega = abs, .zeta = im == 0.0 ? 1.0 : -re / abs, .real = im == 0.0};
    }
    qsort(all, (size_t)found, sizeof *all, compare_modes);
    memcpy(modes, all, (size_t)(found < capacity ? found : capacity) * sizeof *all);
  }
  gsl_eigen_nonsymm_free(w);
  gsl_vector_complex_free(roots);
  gsl_matrix_free(a);
  free(all);
  free(k);
  free(c);
  free(scale);
  free(local);
  return found;
}
