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
  free(d->yView);
  pd_contact_set_free(d->view);
  free(d);
}

static void reserve(pdDense* d, int n) {
  if (n <= d->capacity) return;
  int c = d->capacity > 0 ? d->capacity : n;
  while (c < n) c *= 2;
  for (int k = 0; k < NODE_COUNT; ++k) d->node[k] = pd_grow(d->node[k], (size_t)c, sizeof(double));
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

void pd_dense_quartic(int n, double h, double theta, const double* y0, const double* f0, const double* yHalf,
                      const double* fHalf, const double* y1, double* out) {
  // p(θ) = y0 + h f0 θ + a θ² + b θ³ + c θ⁴ through p(½) = y½, p'(½) = h f½, p(1) = y1 (derivation: the three
  // conditions solved for a, b, c with D½ = y½ − y0 − h f0/2, Df = h (f½ − f0), D1 = y1 − y0 − h f0)
  for (int i = 0; i < n; ++i) {
    double slope = h * f0[i];
    double dHalf = yHalf[i] - y0[i] - 0.5 * slope, dSlope = h * (fHalf[i] - f0[i]), dEnd = y1[i] - y0[i] - slope;
    double a = dEnd - 4.0 * dSlope + 16.0 * dHalf;
    double b = -4.0 * dEnd + 12.0 * dSlope - 32.0 * dHalf;
    double c = 4.0 * dEnd - 8.0 * dSlope + 16.0 * dHalf;
    out[i] = y0[i] + theta * (slope + theta * (a + theta * (b + theta * c)));
  }
}

// The interpolant at θ into out (d->n numbers).
static void interpolate(const pdDense* d, double theta, double* out) {
  const double *y0 = d->node[NODE_Y0], *f0 = d->node[NODE_F0], *y1 = d->node[NODE_Y1];
  double h = d->h;
  if (d->quartic) {
    pd_dense_quartic(d->n, h, theta, y0, f0, d->node[NODE_YHALF], d->node[NODE_FHALF], y1, out);
    return;
  }
  const double* f1 = d->node[NODE_F1];
  if (d->dopri) {
    const double* ext = d->node[NODE_YHALF];
    for (int i = 0; i < d->n; ++i) {
      double dy = y1[i] - y0[i], r3 = h * f0[i] - dy, r4 = dy - h * f1[i] - r3;
      out[i] = y0[i] + theta * (dy + (1.0 - theta) * (r3 + theta * (r4 + (1.0 - theta) * ext[i])));
    }
    return;
  }
  for (int i = 0; i < d->n; ++i) {
    double dy = y1[i] - y0[i];
    double c2 = 3.0 * dy - h * (2.0 * f0[i] + f1[i]);
    double c3 = -2.0 * dy + h * (f0[i] + f1[i]);
    out[i] = y0[i] + theta * (h * f0[i] + theta * (c2 + theta * c3));
  }
}

void pd_dense_present(const pdModel* model, pdState* s, double t) {
  pdDense* d = s->dense;
  PD_ASSERT(d != NULL && d->captured && t > d->t0 && t < d->t0 + d->h);
  if (d->presenting) {
    if (s->t == t) return;
    pd_dense_resume(s);
  }
  interpolate(d, (t - d->t0) / d->h, d->yView);
  for (int k = 0; k < model->movingCount; ++k) {
    double* q = d->yView + PD_BODY_STATE_SIZE * k + PD_Y_Q;
    double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i) q[i] /= norm;
  }
  pd_contact_set_present(model, d->view, d->yView);
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
