// polydyn gedanken — measures computed from sampled series (see gedanken.h), and the sample record.
#include <gsl/gsl_fit.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pdgk/gedanken.h"

// ---------------------------------------------------------------------------------------------------------
// record

void pd_gk_record_init(pdGkRecord* rec, int bodies) {
  PD_ASSERT(rec && bodies >= 1);
  memset(rec, 0, sizeof *rec);
  rec->bodies = bodies;
  rec->finite = true;
}

void pd_gk_record_free(pdGkRecord* rec) {
  free(rec->t);
  free(rec->energy);
  free(rec->contacts);
  free(rec->body);
  memset(rec, 0, sizeof *rec);
}

static void record_grow(pdGkRecord* rec) {
  int capacity = rec->capacity ? 2 * rec->capacity : 1024;
  rec->t = realloc(rec->t, (size_t)capacity * sizeof *rec->t);
  rec->energy = realloc(rec->energy, (size_t)capacity * sizeof *rec->energy);
  rec->contacts = realloc(rec->contacts, (size_t)capacity * sizeof *rec->contacts);
  rec->body = realloc(rec->body, (size_t)capacity * (size_t)rec->bodies * sizeof *rec->body);
  PD_ASSERT(rec->t && rec->energy && rec->contacts && rec->body);
  rec->capacity = capacity;
}

static bool body_finite(const pdBodyState* b) {
  return pd_v3_isfinite(b->x) && pd_v3_isfinite(b->v) && pd_v3_isfinite(b->w) && isfinite(b->q.w) &&
         isfinite(b->q.x) && isfinite(b->q.y) && isfinite(b->q.z);
}

static bool record(const pdModel* model, const pdState* state, pdGkRecord* rec, bool contactsKnown) {
  PD_ASSERT(model->movingCount == rec->bodies);
  if (rec->count == rec->capacity) record_grow(rec);
  int k = rec->count++;
  rec->t[k] = state->t;
  rec->energy[k] = pd_state_energy(model, state);
  rec->contacts[k] = contactsKnown ? pd_state_contact_count(state) : -1;
  rec->finite = rec->finite && isfinite(rec->energy[k]);
  for (int j = 0; j < rec->bodies; ++j) {
    pdBodyState b = pd_state_body(model, state, model->movingBodies[j]);
    rec->body[k * rec->bodies + j] = b;
    rec->finite = rec->finite && body_finite(&b);
  }
  return true;
}

bool pd_gk_record_observe(const pdModel* model, const pdState* state, void* user) {
  return record(model, state, user, true);
}

bool pd_gk_record_observe_ref(const pdModel* model, const pdState* state, void* user) {
  return record(model, state, user, false);
}

// ---------------------------------------------------------------------------------------------------------
// measures

bool pd_gk_fit_line(const double* t, const double* y, int n, double t0, double t1, double* slope, double* intercept) {
  int first = 0;
  while (first < n && t[first] < t0) ++first;
  int count = 0;
  while (first + count < n && t[first + count] <= t1) ++count;
  if (count < 2 || !(t[first + count - 1] > t[first])) return false;
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(t + first, 1, y + first, 1, (size_t)count, &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  if (!isfinite(c0) || !isfinite(c1)) return false;
  *slope = c1;
  if (intercept) *intercept = c0;
  return true;
}

static bool free_interval(const double* t, const double* v, int k, double g, double threshold) {
  return fabs((v[k + 1] - v[k]) - g * (t[k + 1] - t[k])) <= threshold;
}

bool pd_gk_first_impact(const double* t, const double* v, int n, double g, double threshold, int settle,
                        pdGkImpact* out) {
  PD_ASSERT(settle >= 1 && threshold >= 0.0);
  int start = -1;
  for (int k = 0; k + 1 < n && start < 0; ++k)
    if (!free_interval(t, v, k, g, threshold)) start = k;
  if (start < 0) return false;
  int end = -1;
  for (int k = start + 1; k + 1 < n && end < 0; ++k) {
    int freeCount = 0;
    while (freeCount < settle && k + freeCount + 1 < n && free_interval(t, v, k + freeCount, g, threshold))
      ++freeCount;
    // settled: `settle` free intervals in a row, or free up to the end of the series
    if (freeCount == settle || (freeCount > 0 && k + freeCount == n - 1)) end = k;
  }
  if (end < 0) return false;
  double tm = 0.5 * (t[start] + t[end]);
  double vIn = v[start] + g * (tm - t[start]);
  double vOut = v[end] + g * (tm - t[end]);
  if (vIn == 0.0) return false;
  *out = (pdGkImpact){.tStart = t[start], .tEnd = t[end], .vIn = vIn, .vOut = vOut, .restitution = -vOut / vIn};
  return true;
}

int pd_gk_apexes(const double* z, const double* vz, int n, double g, double* apex, int max) {
  PD_ASSERT(g > 0.0);
  int count = 0;
  for (int k = 0; k + 1 < n && count < max; ++k)
    if (vz[k] > 0.0 && vz[k + 1] <= 0.0) apex[count++] = z[k] + vz[k] * vz[k] / (2.0 * g);
  return count;
}

bool pd_gk_first_fall(const double* t, const double* y, int n, double level, double* tCross) {
  int k = 0;
  while (k < n && !(y[k] > level)) ++k;
  for (++k; k < n; ++k) {
    if (y[k] <= level) {
      *tCross = t[k - 1] + (y[k - 1] - level) / (y[k - 1] - y[k]) * (t[k] - t[k - 1]);
      return true;
    }
  }
  return false;
}

bool pd_gk_ramp_slip_onset(const double* t, const double* v, int n, double mass, double beta, double vLo, double vHi,
                           double* onset, double* slope) {
  PD_ASSERT(mass > 0.0 && beta > 0.0 && 0.0 < vLo && vLo < vHi);
  int lo = 0;
  while (lo < n && v[lo] < vLo) ++lo;
  int hi = lo;
  while (hi < n && v[hi] < vHi) ++hi;
  if (hi >= n) return false;
  double* root = malloc((size_t)n * sizeof *root);
  PD_ASSERT(root != NULL);
  for (int k = lo; k <= hi; ++k) root[k] = sqrt(2.0 * mass * fmax(v[k], 0.0) / beta);  // s
  double b, c;
  bool ok = pd_gk_fit_line(t + lo, root + lo, hi - lo + 1, t[lo], t[hi], &b, &c) && b > 0.0;
  free(root);
  if (!ok) return false;
  *onset = -c / b;
  *slope = b;
  return true;
}

double pd_gk_largest_rise(const double* y, int n, double scale) {
  PD_ASSERT(scale > 0.0);
  if (n < 1) return 0.0;
  double lowest = y[0], rise = 0.0;
  for (int k = 1; k < n; ++k) {
    rise = fmax(rise, y[k] - lowest);
    lowest = fmin(lowest, y[k]);
  }
  return rise / scale;
}

bool pd_gk_drift_speed(const double* t, const pdVec3* x, int n, double t0, double* speed) {
  int first = 0;
  while (first < n && t[first] < t0) ++first;
  if (first >= n - 1 || !(t[n - 1] > t[first])) return false;
  *speed = pd_v3_norm(pd_v3_sub(x[n - 1], x[first])) / (t[n - 1] - t[first]);
  return true;
}

double pd_gk_impulse_ratio(double vt0, double vt1, double vn0, double vn1) {
  return vn1 == vn0 ? NAN : fabs(vt1 - vt0) / fabs(vn1 - vn0);
}

double pd_gk_absorbed_fraction(double energyBefore, double energyAfter, double kineticBefore) {
  PD_ASSERT(kineticBefore > 0.0);
  return (energyBefore - energyAfter) / kineticBefore;
}

bool pd_gk_mean_rate_in_band(const double* t, const double* angle, const double* band, int n, double lo, double hi,
                             double* rate) {
  double turned = 0.0, time = 0.0;
  for (int k = 0; k + 1 < n; ++k)
    if (band[k] >= lo && band[k] <= hi && band[k + 1] >= lo && band[k + 1] <= hi) {
      turned += angle[k + 1] - angle[k];
      time += t[k + 1] - t[k];
    }
  if (!(time > 0.0)) return false;
  *rate = turned / time;
  return true;
}

void pd_gk_unwrap(double* angle, int n) {
  const double twoPi = 2.0 * M_PI;
  double offset = 0.0;
  for (int k = 1; k < n; ++k) {
    double raw = angle[k] + offset;
    double step = raw - angle[k - 1];
    double turns = round(step / twoPi);
    offset -= turns * twoPi;
    angle[k] = raw - turns * twoPi;
  }
}
