// polydyn gedanken — helpers the experiment files share, and the closed forms used by several of them.
#include <stdlib.h>
#include <time.h>

#include "gedanken_internal.h"
#include "pdutil/clock.h"

// ---------------------------------------------------------------------------------------------------------
// closed forms

double pd_gk_restitution_of_damping(double zeta) {
  PD_ASSERT(zeta >= 0.0);
  if (zeta == 0.0) return 1.0;
  // both branches are one analytic function of ζ; near ζ = 1 they tend to e⁻² (ratio → 1)
  if (fabs(zeta - 1.0) < 1e-9) return exp(-2.0);
  if (zeta < 1.0) return exp(-2.0 * zeta * acos(zeta) / sqrt(1.0 - zeta * zeta));
  return exp(-2.0 * zeta * acosh(zeta) / sqrt(zeta * zeta - 1.0));
}

double pd_gk_cube_landing_absorbed(double e, double* spinRatio) {
  PD_ASSERT(e >= 0.0 && e <= 1.0);
  // in the plane of the roll, units m = a = ω⁻ = 1: pivot A at the origin, landing edge B at (1, 0), centre C at
  // (1/2, 1/2); before, the cube turns about A: ω ŷ × r = ω (r_z, −r_x)
  const double ic = 1.0 / 6.0;                 // I_c/(m a²)
  double rho[2] = {0.5, -0.5};                 // B − C
  double u[2] = {rho[1], -rho[0]};             // v_B = v_C + ω u
  double vc[2] = {0.5, -0.5};                  // ŷ × (C − A)
  double vb[2] = {vc[0] + u[0], vc[1] + u[1]};  // (0, −1)
  double target[2] = {0.0, -e * vb[1]}, dv[2] = {target[0] - vb[0], target[1] - vb[1]};
  // Δv_B = K P with K = 1/m + u uᵀ/I_c: solve the 2×2 system for the impulse P
  double k00 = 1.0 + u[0] * u[0] / ic, k01 = u[0] * u[1] / ic, k11 = 1.0 + u[1] * u[1] / ic;
  double det = k00 * k11 - k01 * k01;
  double p[2] = {(k11 * dv[0] - k01 * dv[1]) / det, (k00 * dv[1] - k01 * dv[0]) / det};
  double w = 1.0 + (u[0] * p[0] + u[1] * p[1]) / ic;
  double v[2] = {vc[0] + p[0], vc[1] + p[1]};
  double before = 0.5 * (vc[0] * vc[0] + vc[1] * vc[1]) + 0.5 * ic;
  double after = 0.5 * (v[0] * v[0] + v[1] * v[1]) + 0.5 * ic * w * w;
  if (spinRatio) *spinRatio = w;
  return 1.0 - after / before;
}

double gk_kinetic_energy(const pdModel* model, int body, const pdBodyState* b) {
  const pdBody* m = &model->bodies[body];
  pdQuat qc = {b->q.w, -b->q.x, -b->q.y, -b->q.z};
  pdVec3 w = pd_quat_rotate(qc, b->w);  // body frame, where the inertia is kept
  return 0.5 * m->mass * pd_v3_dot(b->v, b->v) + 0.5 * pd_v3_dot(w, pd_mat3_mulv(&m->inertia, w));
}

double gk_effective_mass(const pdModel* model, int body, pdVec3 p, pdVec3 n) {
  const pdBody* b = &model->bodies[body];
  // r × n in the body frame, where the inverse inertia is kept
  pdVec3 r = pd_v3_sub(p, b->x0);
  pdQuat qc = {b->q0.w, -b->q0.x, -b->q0.y, -b->q0.z};
  pdVec3 rn = pd_quat_rotate(qc, pd_v3_cross(r, pd_v3_normalize(n)));
  return 1.0 / (b->invMass + pd_v3_dot(rn, pd_mat3_mulv(&b->invInertia, rn)));
}

// ---------------------------------------------------------------------------------------------------------
// text

void pd_gk_text_printf(pdGkText* text, const char* fmt, ...) {
  for (;;) {
    size_t room = text->capacity - text->length;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(text->data ? text->data + text->length : NULL, text->data ? room : 0, fmt, ap);
    va_end(ap);
    PD_ASSERT(n >= 0);
    if (text->data && (size_t)n < room) {
      text->length += (size_t)n;
      return;
    }
    size_t capacity = text->capacity ? text->capacity : 256;
    while (capacity - text->length <= (size_t)n) capacity *= 2;
    text->data = realloc(text->data, capacity);
    PD_ASSERT(text->data != NULL);
    text->capacity = capacity;
  }
}

void pd_gk_text_free(pdGkText* text) {
  free(text->data);
  memset(text, 0, sizeof *text);
}

void gk_text_rotation(pdGkText* out, pdQuat q) {
  if (q.w < 0.0) q = (pdQuat){-q.w, -q.x, -q.y, -q.z};
  double s = sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  if (s == 0.0) {
    pd_gk_text_printf(out, " 0 0 0 1");
    return;
  }
  double angle = 2.0 * atan2(s, q.w) * 180.0 / M_PI;
  pd_gk_text_printf(out, " %.17g %.17g %.17g %.17g", angle, q.x / s, q.y / s, q.z / s);
}

void gk_text_floor(pdGkText* out, double sx, double sy, double sz, double cx, const char* material) {
  pd_gk_text_printf(out, "cube floor grey %.17g %.17g %.17g\nfixed\nloc %.17g 0 %.17g\n%s", sx, sy, sz, cx, -0.5 * sz,
                    material);
}

// ---------------------------------------------------------------------------------------------------------
// model and record helpers

int gk_body(const pdModel* model, const char* name) {
  for (int i = 0; i < model->bodyCount; ++i)
    if (strcmp(model->bodies[i].name, name) == 0) return i;
  PD_ASSERT(!"no body of that name in a generated scene");
  return -1;
}

int gk_moving(const pdModel* model, const char* name) {
  int i = gk_body(model, name);
  PD_ASSERT(model->bodies[i].stateIndex >= 0);
  return model->bodies[i].stateIndex;
}

double* gk_column(const pdGkRecord* rec, int j, gkGetter* get) {
  double* out = malloc((size_t)(rec->count > 0 ? rec->count : 1) * sizeof *out);
  PD_ASSERT(out != NULL);
  for (int k = 0; k < rec->count; ++k) out[k] = gk_series_value(rec, k, j, get);
  return out;
}

pdVec3* gk_positions(const pdGkRecord* rec, int j) {
  pdVec3* out = malloc((size_t)(rec->count > 0 ? rec->count : 1) * sizeof *out);
  PD_ASSERT(out != NULL);
  for (int k = 0; k < rec->count; ++k) out[k] = pd_gk_body(rec, k, j).x;
  return out;
}

double gk_get_z(const pdBodyState* b) { return b->x.z; }
double gk_get_x(const pdBodyState* b) { return b->x.x; }
double gk_get_vx(const pdBodyState* b) { return b->v.x; }
double gk_get_vz(const pdBodyState* b) { return b->v.z; }
double gk_get_wy(const pdBodyState* b) { return b->w.y; }
double gk_get_speed(const pdBodyState* b) { return pd_v3_norm(b->v); }
double gk_get_horizontal_speed(const pdBodyState* b) { return hypot(b->v.x, b->v.y); }
double gk_get_tilt_deg(const pdBodyState* b) {
  double c = pd_quat_rotate(b->q, pd_v3(0.0, 0.0, 1.0)).z;
  return acos(fmax(-1.0, fmin(1.0, c))) * 180.0 / M_PI;
}

bool gk_measure_slope(const pdGkRecord* rec, int j, gkGetter* get, double from, double to, const char* what,
                      pdGkMeasured* out) {
  double* y = gk_column(rec, j, get);
  double slope;
  bool ok = pd_gk_fit_line(rec->t, y, rec->count, from, to, &slope, NULL);
  if (ok) {
    out->value = slope;
    gk_note(out, "line fitted to the %s over %.3g..%.3g s", what, from, to);
  } else {
    gk_note(out, "too few samples in %.3g..%.3g s", from, to);
  }
  free(y);
  return ok;
}

void gk_note(pdGkMeasured* out, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(out->note, sizeof out->note, fmt, ap);
  va_end(ap);
}

double gk_energy_gain(const pdGkRecord* rec) {
  if (rec->count < 1 || !(rec->energy[0] > 0.0)) return NAN;
  return pd_gk_largest_rise(rec->energy, rec->count, rec->energy[0]);
}

double gk_wall_seconds(void) { return pd_wall_seconds(); }

double gk_cpu_seconds(void) { return pd_thread_cpu_seconds(); }
