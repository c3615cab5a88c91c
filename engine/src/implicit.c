// polydyn — the linear systems of the implicit stepper (implicit.h; docs/integration.md).
//
// Design note. The state is [bodies | springs]: per moving body v, ω (rows 0–5 of its 13), x, q; per contact its
// 8 springs. W couples only v, ω and the springs. Contact c between bodies 1 and 2 (σ = +1, −1), lever arms r_k,
// relative velocity Δu = K_1 V_1 − K_2 V_2 with V = (v, ω) and K_k = [I, −[r_k]×] (3 × 6); its force F acts
// on body k as σ_k L_k F with L_k = [I/m_k; I_k⁻¹ [r_k]×] (6 × 3, I_k the world inertia). Linearised
// (pd_contact_set_linearise): δF = Du δΔu + Ds δs, δṡ = Gu δΔu + Gs δs. Then M u = r, M = I/hg − W, is
//   spring rows of c:  B_c u_c − Gu Δ(u_b) = r_c,                 B_c = I/hg − Gs (8 × 8, c's own)
//   body rows of k:    u_k/hg − Σ_c σ_k L_k (Du Δ(u_b) + Ds u_c) = r_k
//   x, q rows:         u/hg = r.
// Eliminating each contact's springs, u_c = B_c⁻¹ (r_c + Gu Δ(u_b)), leaves the bodies' system
//   S u_b = r_b + Σ_c σ_k L_k Ds B_c⁻¹ r_c,   S = I/hg − Σ_c Σ_{k,l} σ_k σ_l L_k E_c K_l,   E_c = Du + Ds B_c⁻¹ Gu,
// 6 rows per moving body, dense, factorised by GSL's LU (partial pivoting); the springs follow by substitution.
// Nothing here depends on the order of the contacts but the sums' rounding, which follows the list's order.
#include "implicit.h"

#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_set.h"
#include "grow.h"
#include "polydyn/error.h"
#include "state_layout.h"

enum { SPRINGS = PD_CONTACT_STATE_SIZE, BODY_ROWS = 6 };

// One contact's share of M, kept between factorisation and solves.
typedef struct contactBlock {
  double Binv[SPRINGS][SPRINGS];  // B_c⁻¹
  double DsB[3][SPRINGS];         // Ds B_c⁻¹
  double BGu[SPRINGS][3];         // B_c⁻¹ Gu
  int row1, row2;                 // first row of body 1 and body 2 in S (-1: fixed)
} contactBlock;

struct pdImplicit {
  bool active;       // stepping implicitly (integrator.c, switching_step)
  int held;          // explicit steps in a row held by the stability bound
  double boundStep;  // s: the bound's step at the switch, until an implicit step is accepted (0: not on probation)
  double backoff;    // bound steps to wait after the next failed probation (0: none failed since the last that paid)
  double retryAt;    // s: no switch before this time
  int contactCapacity, rowCapacity;
  pdContactLinear* linear;
  contactBlock* blocks;
  double* S;              // rows × rows, row-major; LU factors after pd_implicit_factor
  double* rb;             // the bodies' right-hand side
  gsl_permutation* perm;  // of `rows` elements
  int rows;
  double hg;
};

pdImplicit* pd_implicit_create(void) {
  pdImplicit* im = pd_zeroed(1, sizeof *im);
  im->retryAt = -INFINITY;
  return im;
}

void pd_implicit_free(pdImplicit* im) {
  if (!im) return;
  free(im->linear);
  free(im->blocks);
  free(im->S);
  free(im->rb);
  if (im->perm) gsl_permutation_free(im->perm);
  free(im);
}

bool pd_implicit_active(const pdImplicit* im) { return im->active; }

bool pd_implicit_note_explicit(pdImplicit* im, bool held, double boundStep, double t) {
  im->held = held ? im->held + 1 : 0;
  if (im->held >= PD_IMPLICIT_SWITCH_STEPS && t >= im->retryAt) {
    im->active = true, im->held = 0, im->boundStep = boundStep;
  }
  return im->active;
}

double pd_implicit_probation_bound_step(const pdImplicit* im) { return im->boundStep; }

void pd_implicit_paid(pdImplicit* im) { im->boundStep = 0.0, im->backoff = 0.0; }

void pd_implicit_deactivate(pdImplicit* im, bool gaveUp, double t) {
  if (gaveUp) {
    im->backoff = im->backoff > 0.0 ? fmin(2.0 * im->backoff, PD_IMPLICIT_BACKOFF_MAX) : PD_IMPLICIT_BACKOFF_FIRST;
    im->retryAt = t + im->backoff * im->boundStep;
  }
  im->active = false, im->held = 0, im->boundStep = 0.0;
}

void pd_implicit_reserve(pdImplicit* im, int movingCount, int contacts) {
  int rows = BODY_ROWS * movingCount;
  if (contacts < 1) contacts = 1;
  if (contacts > im->contactCapacity) {
    im->linear = pd_grow(im->linear, (size_t)contacts, sizeof *im->linear);
    im->blocks = pd_grow(im->blocks, (size_t)contacts, sizeof *im->blocks);
    im->contactCapacity = contacts;
  }
  if (rows > im->rowCapacity) {
    im->S = pd_grow(im->S, (size_t)rows * (size_t)rows, sizeof *im->S);
    im->rb = pd_grow(im->rb, (size_t)rows, sizeof *im->rb);
    im->rowCapacity = rows;
  }
  if (!im->perm || im->perm->size != (size_t)rows) {  // an island's rows change only when its bodies do
    if (im->perm) gsl_permutation_free(im->perm);
    im->perm = gsl_permutation_alloc((size_t)rows);
    PD_ASSERT(im->perm != NULL);
  }
}

// Inverts the 8 × 8 matrix a (destroyed) into inv by Gauss–Jordan with partial pivoting; false when singular.
// Once column col is eliminated, a's columns up to col are never read again (the pivots and factors come from
// the columns after it, the answer is inv): only the columns after col are updated, the same inv for half the work.
static bool invert_springs(double a[SPRINGS][SPRINGS], double inv[SPRINGS][SPRINGS]) {
  for (int i = 0; i < SPRINGS; ++i)
    for (int j = 0; j < SPRINGS; ++j) inv[i][j] = i == j ? 1.0 : 0.0;
  for (int col = 0; col < SPRINGS; ++col) {
    int pivot = col;
    for (int i = col + 1; i < SPRINGS; ++i)
      if (fabs(a[i][col]) > fabs(a[pivot][col])) pivot = i;
    if (!(fabs(a[pivot][col]) > 0.0) || !isfinite(a[pivot][col])) return false;
    if (pivot != col) {
      for (int j = col; j < SPRINGS; ++j) {
        double t = a[col][j];
        a[col][j] = a[pivot][j], a[pivot][j] = t;
      }
      for (int j = 0; j < SPRINGS; ++j) {
        double t = inv[col][j];
        inv[col][j] = inv[pivot][j], inv[pivot][j] = t;
      }
    }
    double d = 1.0 / a[col][col];
    for (int j = col + 1; j < SPRINGS; ++j) a[col][j] *= d;
    for (int j = 0; j < SPRINGS; ++j) inv[col][j] *= d;
    for (int i = 0; i < SPRINGS; ++i) {
      if (i == col || a[i][col] == 0.0) continue;
      double f = a[i][col];
      for (int j = col + 1; j < SPRINGS; ++j) a[i][j] -= f * a[col][j];
      for (int j = 0; j < SPRINGS; ++j) inv[i][j] -= f * inv[col][j];
    }
  }
  return true;
}

// The first row of body b in S, or -1 for a fixed body.
static int body_row(const pdModel* model, int b) {
  const pdBody* body = &model->bodies[b];
  return body->fixed ? -1 : BODY_ROWS * body->stateIndex;
}

// K V: the velocity at lever arm r of a body moving with V = (v, ω).
static pdVec3 point_velocity_of(const double* V, pdVec3 r) {
  pdVec3 v = {V[0], V[1], V[2]}, w = {V[3], V[4], V[5]};
  return pd_v3_add(v, pd_v3_cross(w, r));
}

// Δu of a contact for body-row vector x (fixed bodies: 0).
static pdVec3 relative_velocity(const double* x, int row1, int row2, pdVec3 r1, pdVec3 r2) {
  pdVec3 du = {0, 0, 0};
  if (row1 >= 0) du = point_velocity_of(x + row1, r1);
  if (row2 >= 0) du = pd_v3_sub(du, point_velocity_of(x + row2, r2));
  return du;
}

// out[row ..] += sign L F for a moving body of inverse mass invMass and world inverse inertia invInertia: F/m to the
// velocity rows, I⁻¹ (r × F) to the angular ones.
static void add_push(double invMass, const pdMat3* invInertia, int row, pdVec3 r, pdVec3 F, double sign, double* out) {
  pdVec3 a = pd_v3_scale(F, invMass * sign);
  pdVec3 alpha = pd_v3_scale(pd_mat3_mulv(invInertia, pd_v3_cross(r, F)), sign);
  out[row] += a.x, out[row + 1] += a.y, out[row + 2] += a.z;
  out[row + 3] += alpha.x, out[row + 4] += alpha.y, out[row + 5] += alpha.z;
}

static pdVec3 mul3(const double m[3][3], pdVec3 x) {
  return (pdVec3){m[0][0] * x.x + m[0][1] * x.y + m[0][2] * x.z, m[1][0] * x.x + m[1][1] * x.y + m[1][2] * x.z,
                  m[2][0] * x.x + m[2][1] * x.y + m[2][2] * x.z};
}

void pd_implicit_linearise(const pdModel* model, pdState* state, pdImplicit* im, const double* y) {
  PD_ASSERT(model->movingCount >= 1 && model->movingCount <= PD_IMPLICIT_BODIES_MAX);
  int contacts = pd_state_contact_count(state);
  int rows = BODY_ROWS * model->movingCount;
  // sized between steps (pd_implicit_reserve): a trial step does not allocate
  PD_ASSERT(contacts <= im->contactCapacity && rows <= im->rowCapacity && im->perm && im->perm->size == (size_t)rows);
  im->rows = rows;
  pd_contact_set_settle(state->contacts, state->y);  // a presented state's modes (the linearisation reads them)
  pd_contact_set_linearise(model, state->contacts, y, im->linear);
}

// Contact l's push σ_k L_k F on its end k (0: body 1, 1: body 2) into out.
// A planar body's push keeps to its plane, as its derivative does (dynamics.c), so that its stages never
// leave it either.
static void push_end(const pdModel* model, const pdContactLinear* l, int k, int row, pdVec3 F, double* out) {
  const pdBody* body = &model->bodies[k == 0 ? l->body1 : l->body2];
  double kept[BODY_ROWS] = {0};
  add_push(body->invMass, k == 0 ? &l->invInertia1 : &l->invInertia2, 0, k == 0 ? l->r1 : l->r2, F,
           k == 0 ? 1.0 : -1.0, kept);
  if (body->planar) kept[1] = kept[3] = kept[5] = 0.0;
  for (int i = 0; i < BODY_ROWS; ++i) out[row + i] += kept[i];
}

// Whether a contact's springs drive their own rates (Gs ≠ 0, as in slip, where the friction limit follows the
// normal springs). Where none does (Gs = 0 exactly, as in stick with the default proportional dampers) B_c⁻¹ is
// hg I and needs no inversion.
static bool springs_self_coupled(const pdContactLinear* l) {
  for (int i = 0; i < SPRINGS; ++i)
    for (int j = 0; j < SPRINGS; ++j)
      if (l->Gs[i][j] != 0.0) return true;
  return false;
}

bool pd_implicit_factor(const pdModel* model, const pdState* state, pdImplicit* im, double hg) {
  PD_ASSERT(hg > 0.0 && im->rows == BODY_ROWS * model->movingCount);
  int contacts = pd_state_contact_count(state);
  int rows = im->rows;
  im->hg = hg;
  double* S = im->S;
  for (int i = 0; i < rows * rows; ++i) S[i] = 0.0;
  for (int i = 0; i < rows; ++i) S[i * rows + i] = 1.0 / hg;
  for (int c = 0; c < contacts; ++c) {
    const pdContactLinear* l = &im->linear[c];
    contactBlock* blk = &im->blocks[c];
    blk->row1 = body_row(model, l->body1);
    blk->row2 = body_row(model, l->body2);
    if (springs_self_coupled(l)) {
      double B[SPRINGS][SPRINGS];
      for (int i = 0; i < SPRINGS; ++i)
        for (int j = 0; j < SPRINGS; ++j) B[i][j] = (i == j ? 1.0 / hg : 0.0) - l->Gs[i][j];
      if (!invert_springs(B, blk->Binv)) return false;
    } else {
      for (int i = 0; i < SPRINGS; ++i)
        for (int j = 0; j < SPRINGS; ++j) blk->Binv[i][j] = i == j ? hg : 0.0;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < SPRINGS; ++j) {
        double acc = 0.0;
        for (int m = 0; m < SPRINGS; ++m) acc += l->Ds[i][m] * blk->Binv[m][j];
        blk->DsB[i][j] = acc;
      }
    for (int i = 0; i < SPRINGS; ++i)
      for (int j = 0; j < 3; ++j) {
        double acc = 0.0;
        for (int m = 0; m < SPRINGS; ++m) acc += blk->Binv[i][m] * l->Gu[m][j];
        blk->BGu[i][j] = acc;
      }
    double E[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double acc = l->Du[i][j];
        for (int m = 0; m < SPRINGS; ++m) acc += l->Ds[i][m] * blk->BGu[m][j];
        E[i][j] = acc;
      }
    // S −= σ_k σ_l L_k E K_l, column by column of K_l (a unit velocity or spin of body l): its point velocity
    // through E is a force, pushed on body k
    const int rowOf[2] = {blk->row1, blk->row2};
    const pdVec3 leverOf[2] = {l->r1, l->r2};
    const double sign[2] = {1.0, -1.0};
    for (int ll = 0; ll < 2; ++ll) {
      if (rowOf[ll] < 0) continue;
      for (int j = 0; j < BODY_ROWS; ++j) {
        double unit[BODY_ROWS] = {0};
        unit[j] = 1.0;
        pdVec3 F = mul3((const double(*)[3])E, point_velocity_of(unit, leverOf[ll]));
        for (int kk = 0; kk < 2; ++kk) {
          if (rowOf[kk] < 0) continue;
          double col[BODY_ROWS] = {0};  // σ_k L_k F
          push_end(model, l, kk, 0, F, col);
          double s = -sign[ll];
          for (int i = 0; i < BODY_ROWS; ++i) S[(rowOf[kk] + i) * rows + rowOf[ll] + j] += s * col[i];
        }
      }
    }
  }
  if (rows == 0) return true;
  for (int i = 0; i < rows * rows; ++i)
    if (!isfinite(S[i])) return false;
  gsl_matrix_view mv = gsl_matrix_view_array(S, (size_t)rows, (size_t)rows);
  int signum;
  gsl_linalg_LU_decomp(&mv.matrix, im->perm, &signum);
  for (int i = 0; i < rows; ++i)
    if (!(fabs(S[i * rows + i]) > 0.0)) return false;
  return true;
}

void pd_implicit_solve(const pdModel* model, const pdState* state, pdImplicit* im, const double* r, double* u) {
  int contacts = pd_state_contact_count(state);
  int base = PD_BODY_STATE_SIZE * model->movingCount;
  double hg = im->hg;
  // positions and orientations: u = hg r; the bodies' right-hand side with the springs' share
  for (int k = 0; k < model->movingCount; ++k) {
    const double* rk = r + PD_BODY_STATE_SIZE * k;
    double* uk = u + PD_BODY_STATE_SIZE * k;
    for (int i = PD_Y_X; i < PD_BODY_STATE_SIZE; ++i) uk[i] = hg * rk[i];
    for (int i = 0; i < BODY_ROWS; ++i) im->rb[BODY_ROWS * k + i] = rk[i];
  }
  for (int c = 0; c < contacts; ++c) {
    const contactBlock* blk = &im->blocks[c];
    const pdContactLinear* l = &im->linear[c];
    const double* rc = r + base + SPRINGS * c;
    double f[3];
    for (int i = 0; i < 3; ++i) {
      double acc = 0.0;
      for (int m = 0; m < SPRINGS; ++m) acc += blk->DsB[i][m] * rc[m];
      f[i] = acc;
    }
    pdVec3 F = {f[0], f[1], f[2]};
    if (blk->row1 >= 0) push_end(model, l, 0, blk->row1, F, im->rb);
    if (blk->row2 >= 0) push_end(model, l, 1, blk->row2, F, im->rb);
  }
  if (im->rows > 0) {
    gsl_matrix_view mv = gsl_matrix_view_array(im->S, (size_t)im->rows, (size_t)im->rows);
    gsl_vector_view bv = gsl_vector_view_array(im->rb, (size_t)im->rows);
    gsl_linalg_LU_svx(&mv.matrix, im->perm, &bv.vector);
  }
  for (int k = 0; k < model->movingCount; ++k)
    for (int i = 0; i < BODY_ROWS; ++i) u[PD_BODY_STATE_SIZE * k + i] = im->rb[BODY_ROWS * k + i];
  // the springs by substitution: u_c = B⁻¹ r_c + B⁻¹ Gu Δ(u_b)
  for (int c = 0; c < contacts; ++c) {
    const contactBlock* blk = &im->blocks[c];
    const pdContactLinear* l = &im->linear[c];
    const double* rc = r + base + SPRINGS * c;
    pdVec3 du = relative_velocity(im->rb, blk->row1, blk->row2, l->r1, l->r2);
    for (int i = 0; i < SPRINGS; ++i) {
      double acc = blk->BGu[i][0] * du.x + blk->BGu[i][1] * du.y + blk->BGu[i][2] * du.z;
      for (int m = 0; m < SPRINGS; ++m) acc += blk->Binv[i][m] * rc[m];
      u[base + SPRINGS * c + i] = acc;
    }
  }
}

void pd_implicit_apply_w(const pdModel* model, const pdState* state, const pdImplicit* im, const double* x, double* w) {
  int contacts = pd_state_contact_count(state);
  int base = PD_BODY_STATE_SIZE * model->movingCount;
  double* body = pd_zeroed((size_t)im->rows, sizeof *body);
  double* vel = pd_zeroed((size_t)im->rows, sizeof *vel);
  for (int k = 0; k < model->movingCount; ++k)
    for (int i = 0; i < BODY_ROWS; ++i) vel[BODY_ROWS * k + i] = x[PD_BODY_STATE_SIZE * k + i];
  for (int c = 0; c < contacts; ++c) {
    const contactBlock* blk = &im->blocks[c];
    const pdContactLinear* l = &im->linear[c];
    const double* xc = x + base + SPRINGS * c;
    pdVec3 du = relative_velocity(vel, blk->row1, blk->row2, l->r1, l->r2);
    pdVec3 F = mul3(l->Du, du);
    double f[3] = {F.x, F.y, F.z};
    for (int i = 0; i < 3; ++i)
      for (int m = 0; m < SPRINGS; ++m) f[i] += l->Ds[i][m] * xc[m];
    F = (pdVec3){f[0], f[1], f[2]};
    if (blk->row1 >= 0) push_end(model, l, 0, blk->row1, F, body);
    if (blk->row2 >= 0) push_end(model, l, 1, blk->row2, F, body);
    for (int i = 0; i < SPRINGS; ++i) {
      double acc = l->Gu[i][0] * du.x + l->Gu[i][1] * du.y + l->Gu[i][2] * du.z;
      for (int m = 0; m < SPRINGS; ++m) acc += l->Gs[i][m] * xc[m];
      w[base + SPRINGS * c + i] = acc;
    }
  }
  for (int k = 0; k < model->movingCount; ++k) {
    double* wk = w + PD_BODY_STATE_SIZE * k;
    for (int i = 0; i < BODY_ROWS; ++i) wk[i] = body[BODY_ROWS * k + i];
    for (int i = BODY_ROWS; i < PD_BODY_STATE_SIZE; ++i) wk[i] = 0.0;
  }
  free(body);
  free(vel);
}
