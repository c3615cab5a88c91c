// polydyn — dense output (dense_output.h).
#include "dense_output.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_history.h"
#include "contact_list.h"
#include "contact_set.h"
#include "grow.h"
#include "polydyn/error.h"
#include "state_layout.h"

enum { NODE_Y0, NODE_F0, NODE_YHALF, NODE_FHALF, NODE_Y1, NODE_F1, NODE_COUNT };

struct pdDense {
  double tExpected;  // s
  // the captured step [t0, t0 + h], in its contact list's layout (n numbers)
  bool captured;
  bool quartic;  // step doubling's nodes; else the cubic's
  bool dopri;    // Dormand–Prince's: the cubic's nodes and its extension's term d in NODE_YHALF
  double t0, h;
  int n, capacity;
  double* node[NODE_COUNT];  // (capacity) each
  // The interpolant's terms, up to 4 per number (keep_terms), kept by a step that passes many samples (a body in flight
  // sampled at 2 kHz, some 40 a step; a slide at 1 kHz, some 25): each sample then costs only the polynomial's
  // evaluation, the same operations on the same numbers.
  bool kept;
  double* terms[4];  // (capacity) each
  // the presentation
  pdContactSet* view;  // the captured contact list, presented (NULL until the first capture)
  double keptEnergy;   // J: the springs the history keeps for broken contacts over the step (the view has none)
  double* yView;       // (capacity)
  bool presenting;
  double tOwn;  // the integration's own time, state vector, its length and contact list, put aside
  double* yOwn;
  int nOwn;
  pdContactSet* contactsOwn;
};

pdDense* pd_dense_create(void) {
  pdDense* d = pd_zeroed(1, sizeof *d);
  d->tExpected = INFINITY;
  return d;
}

void pd_dense_free(pdDense* d) {
  if (!d) return;
  PD_ASSERT(!d->presenting);
  for (int k = 0; k < NODE_COUNT; ++k) free(d->node[k]);
  for (int k = 0; k < 4; ++k) free(d->terms[k]);
  free(d->yView);
  pd_contact_set_free(d->view);
  free(d);
}

static void reserve(pdDense* d, int n) {
  if (n <= d->capacity) return;
  int c = d->capacity > 0 ? d->capacity : n;
  while (c < n) c *= 2;
  for (int k = 0; k < NODE_COUNT; ++k) d->node[k] = pd_grow(d->node[k], (size_t)c, sizeof(double));
  for (int k = 0; k < 4; ++k) d->terms[k] = pd_grow(d->terms[k], (size_t)c, sizeof(double));
  d->yView = pd_grow(d->yView, (size_t)c, sizeof(double));
  d->capacity = c;
}

void pd_dense_expect(pdDense* d, double t) { d->tExpected = t; }

bool pd_dense_wanted(const pdDense* d, double t0, double h) { return t0 + h > d->tExpected; }

double* pd_dense_slope_scratch(pdDense* d, int n) {
  reserve(d, n);
  return d->node[NODE_F1];
}

// What every capture keeps: y0, f0, y1 and the step's contact list.
static pdDense* capture_ends(const pdModel* model, pdState* s, double h, const double* f0, const double* y1) {
  pdDense* d = s->dense;
  PD_ASSERT(d != NULL && !d->presenting);
  int n = s->n;
  reserve(d, n);
  size_t bytes = (size_t)n * sizeof(double);
  memcpy(d->node[NODE_Y0], s->y, bytes);
  memcpy(d->node[NODE_F0], f0, bytes);
  memcpy(d->node[NODE_Y1], y1, bytes);
  if (!d->view) d->view = pd_contact_set_create_view(model);
  pd_contact_set_capture(s->contacts, d->view);
  // the history changes only at commits: what it keeps at the step's start it keeps until its end
  d->keptEnergy = s->contacts->history ? pd_history_spring_energy(model, s->contacts->history) : 0.0;
  d->t0 = s->t;
  d->h = h;
  d->n = n;
  d->captured = true;
  d->kept = false;
  return d;
}

void pd_dense_capture(const pdModel* model, pdState* s, double h, const double* f0, const double* yHalf,
                      const double* fHalf, const double* y1, const double* f1) {
  pdDense* d = capture_ends(model, s, h, f0, y1);
  size_t bytes = (size_t)d->n * sizeof(double);
  d->quartic = yHalf != NULL;
  d->dopri = false;
  if (yHalf) {
    memcpy(d->node[NODE_YHALF], yHalf, bytes);
    memcpy(d->node[NODE_FHALF], fHalf, bytes);
  } else if (f1 != d->node[NODE_F1]) {  // the implicit method's f(y1) is already there (pd_dense_slope_scratch)
    memcpy(d->node[NODE_F1], f1, bytes);
  }
}

void pd_dense_capture_dopri(const pdModel* model, pdState* s, double h, const double* f0, const double* y1,
                            const double* f1, const double* ext) {
  pdDense* d = capture_ends(model, s, h, f0, y1);
  size_t bytes = (size_t)d->n * sizeof(double);
  d->quartic = false;
  d->dopri = true;
  memcpy(d->node[NODE_F1], f1, bytes);
  memcpy(d->node[NODE_YHALF], ext, bytes);
}

// The quartic's terms for one number: slope h f0 and a, b, c (pd_dense_quartic's p(θ)).
static void quartic_terms(double h, double y0, double f0, double yHalf, double fHalf, double y1, double terms[4]) {
  double slope = h * f0;
  double dHalf = yHalf - y0 - 0.5 * slope, dSlope = h * (fHalf - f0), dEnd = y1 - y0 - slope;
  terms[0] = slope;
  terms[1] = dEnd - 4.0 * dSlope + 16.0 * dHalf;
  terms[2] = -4.0 * dEnd + 12.0 * dSlope - 32.0 * dHalf;
  terms[3] = 4.0 * dEnd - 8.0 * dSlope + 16.0 * dHalf;
}

static inline double quartic_at(double y0, double t0, double t1, double t2, double t3, double theta) {
  return y0 + theta * (t0 + theta * (t1 + theta * (t2 + theta * t3)));
}

void pd_dense_quartic(int n, double h, double theta, const double* y0, const double* f0, const double* yHalf,
                      const double* fHalf, const double* y1, double* out) {
  // p(θ) = y0 + h f0 θ + a θ² + b θ³ + c θ⁴ through p(½) = y½, p'(½) = h f½, p(1) = y1 (derivation: the three
  // conditions solved for a, b, c with D½ = y½ − y0 − h f0/2, Df = h (f½ − f0), D1 = y1 − y0 − h f0)
  for (int i = 0; i < n; ++i) {
    double t[4];
    quartic_terms(h, y0[i], f0[i], yHalf[i], fHalf[i], y1[i], t);
    out[i] = quartic_at(y0[i], t[0], t[1], t[2], t[3], theta);
  }
}

// The cubic Hermite interpolant's terms for one number, h f0, c2 and c3, and its value at θ.
static inline void cubic_terms(double h, double y0, double f0, double y1, double f1, double t[3]) {
  double dy = y1 - y0;
  t[0] = h * f0;
  t[1] = 3.0 * dy - h * (2.0 * f0 + f1);
  t[2] = -2.0 * dy + h * (f0 + f1);
}

static inline double cubic_at(double y0, double t0, double t1, double t2, double theta) {
  return y0 + theta * (t0 + theta * (t1 + theta * t2));
}

// Dormand–Prince's continuous extension's terms for one number, Δ, r3 and r4, and its value at θ (ext: its term d).
static inline void dopri_terms(double h, double y0, double f0, double y1, double f1, double t[3]) {
  double dy = y1 - y0, r3 = h * f0 - dy;
  t[0] = dy;
  t[1] = r3;
  t[2] = dy - h * f1 - r3;
}

static inline double dopri_at(double y0, double t0, double t1, double t2, double ext, double theta) {
  return y0 + theta * (t0 + (1.0 - theta) * (t1 + theta * (t2 + (1.0 - theta) * ext)));
}

// A step that passes at least this many samples from its first presentation keeps its interpolant's terms: forming
// and storing them costs more than evaluating the interpolant directly twice (cases/hard/stack_10.scene, whose steps
// pass one or two samples of 1 000 per second, paid 40 % more for the interpolation when every step kept them).
#define PD_DENSE_KEEP_SAMPLES 4

// Each number's terms into d->terms[0 .. 3] (the cubics use three).
static void keep_terms(pdDense* d) {
  const double *y0 = d->node[NODE_Y0], *f0 = d->node[NODE_F0], *y1 = d->node[NODE_Y1], *f1 = d->node[NODE_F1];
  const double *yHalf = d->node[NODE_YHALF], *fHalf = d->node[NODE_FHALF];
  double h = d->h;
  for (int i = 0; i < d->n; ++i) {
    double t[4] = {0.0, 0.0, 0.0, 0.0};
    if (d->quartic)
      quartic_terms(h, y0[i], f0[i], yHalf[i], fHalf[i], y1[i], t);
    else if (d->dopri)
      dopri_terms(h, y0[i], f0[i], y1[i], f1[i], t);
    else
      cubic_terms(h, y0[i], f0[i], y1[i], f1[i], t);
    for (int k = 0; k < 4; ++k) d->terms[k][i] = t[k];
  }
  d->kept = true;
}

// The interpolant at θ into out (d->n numbers); `many`: the step passes PD_DENSE_KEEP_SAMPLES samples from θ on.
static void interpolate(pdDense* d, double theta, double* restrict out, bool many) {
  const double *y0 = d->node[NODE_Y0], *f0 = d->node[NODE_F0], *y1 = d->node[NODE_Y1], *f1 = d->node[NODE_F1];
  const double *yHalf = d->node[NODE_YHALF], *fHalf = d->node[NODE_FHALF];
  double h = d->h;
  if (!d->kept && many) keep_terms(d);
  // restrict: out (the view's vector) overlaps no term, so these loops may take two numbers at a time
  const double *restrict t0 = d->terms[0], *restrict t1 = d->terms[1], *restrict t2 = d->terms[2];
  const double* restrict t3 = d->terms[3];
  if (d->quartic && d->kept) {
    for (int i = 0; i < d->n; ++i) out[i] = quartic_at(y0[i], t0[i], t1[i], t2[i], t3[i], theta);
  } else if (d->quartic) {
    pd_dense_quartic(d->n, h, theta, y0, f0, yHalf, fHalf, y1, out);
  } else if (d->dopri && d->kept) {  // the extension's terms d are in NODE_YHALF
    for (int i = 0; i < d->n; ++i) out[i] = dopri_at(y0[i], t0[i], t1[i], t2[i], yHalf[i], theta);
  } else if (d->dopri) {
    for (int i = 0; i < d->n; ++i) {
      double t[3];
      dopri_terms(h, y0[i], f0[i], y1[i], f1[i], t);
      out[i] = dopri_at(y0[i], t[0], t[1], t[2], yHalf[i], theta);
    }
  } else if (d->kept) {
    for (int i = 0; i < d->n; ++i) out[i] = cubic_at(y0[i], t0[i], t1[i], t2[i], theta);
  } else {
    for (int i = 0; i < d->n; ++i) {
      double t[3];
      cubic_terms(h, y0[i], f0[i], y1[i], f1[i], t);
      out[i] = cubic_at(y0[i], t[0], t[1], t[2], theta);
    }
  }
}

void pd_dense_present(const pdModel* model, pdState* s, double t) {
  pdDense* d = s->dense;
  PD_ASSERT(d != NULL && d->captured && t > d->t0 && t < d->t0 + d->h);
  if (d->presenting) {
    if (s->t == t) return;
    pd_dense_resume(s);
  }
  interpolate(d, (t - d->t0) / d->h, d->yView,
              (d->t0 + d->h - t) * model->settings.sampleRate >= PD_DENSE_KEEP_SAMPLES - 1);
  for (int k = 0; k < model->movingCount; ++k) {
    double* q = d->yView + PD_BODY_STATE_SIZE * k + PD_Y_Q;
    double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i) q[i] /= norm;
  }
  pd_contact_set_present(model, d->view);
  d->tOwn = s->t;
  d->yOwn = s->y;
  d->nOwn = s->n;
  d->contactsOwn = s->contacts;
  s->t = t;
  s->y = d->yView;
  s->n = d->n;
  s->contacts = d->view;
  d->presenting = true;
}

double pd_dense_presented_kept_energy(const pdDense* d) { return d && d->presenting ? d->keptEnergy : 0.0; }

bool pd_dense_resume(pdState* s) {
  pdDense* d = s->dense;
  if (!d || !d->presenting) return false;
  d->yView = s->y;
  s->t = d->tOwn;
  s->y = d->yOwn;
  s->n = d->nOwn;
  s->contacts = d->contactsOwn;
  d->presenting = false;
  return true;
}

void pd_dense_discard(pdState* s) {
  if (!s->dense) return;
  pd_dense_resume(s);
  s->dense->captured = false;
  s->dense->tExpected = INFINITY;
}
