// polydyn — sleeping bodies' records and thresholds (sleep.h; the decisions are in islands.c).
#include "sleep.h"

#include <math.h>
#include <stdlib.h>

#include "contact_set.h"
#include "grow.h"
#include "model_contact.h"
#include "polydyn/error.h"
#include "state_layout.h"

#define PI 3.14159265358979323846

pdSleepSet* pd_sleep_create(const pdModel* model) {
  pdSleepSet* set = calloc(1, sizeof *set);
  PD_ASSERT(set != NULL);
  int m = model->movingCount > 0 ? model->movingCount : 1;
  set->movingCount = model->movingCount;
  set->speedMax = PD_SLEEP_SPEED_TOL * model->settings.tol * model->settings.vmax;
  set->speedPeak = pd_grow(NULL, (size_t)m, sizeof *set->speedPeak);
  set->v0 = pd_grow(NULL, (size_t)m, sizeof *set->v0);
  set->w0 = pd_grow(NULL, (size_t)m, sizeof *set->w0);
  set->quietSince = pd_grow(NULL, (size_t)m, sizeof *set->quietSince);
  set->slowSince = pd_grow(NULL, (size_t)m, sizeof *set->slowSince);
  set->vSlow = pd_grow(NULL, (size_t)m, sizeof *set->vSlow);
  set->wSlow = pd_grow(NULL, (size_t)m, sizeof *set->wSlow);
  set->asleep = pd_grow(NULL, (size_t)m, sizeof *set->asleep);
  set->asleepSince = pd_grow(NULL, (size_t)m, sizeof *set->asleepSince);
  set->horizon = pd_grow(NULL, (size_t)m, sizeof *set->horizon);
  set->inContact = pd_grow(NULL, (size_t)m, sizeof *set->inContact);
  for (int k = 0; k < model->movingCount; ++k) {
    set->speedPeak[k] = 0.0;
    pd_sleep_restless(set, k);
    set->asleep[k] = false;
  }
  return set;
}

void pd_sleep_free(pdSleepSet* set) {
  if (!set) return;
  free(set->speedPeak);
  free(set->v0);
  free(set->w0);
  free(set->quietSince);
  free(set->slowSince);
  free(set->vSlow);
  free(set->wSlow);
  free(set->asleep);
  free(set->asleepSince);
  free(set->horizon);
  free(set->inContact);
  free(set);
}

double pd_sleep_speed(const pdBody* body, const double* yb) {
  return pd_v3_norm(pd_layout_v(yb)) + pd_v3_norm(pd_layout_w(yb)) * body->radius;
}

void pd_sleep_interval_start(pdSleepSet* set, const pdBody* body, int k, const double* yb) {
  set->speedPeak[k] = pd_sleep_speed(body, yb);
  set->v0[k] = pd_layout_v(yb);
  set->w0[k] = pd_layout_w(yb);
}

double pd_sleep_settle_time(const pdModel* sub, const pdState* state) {
  double period = 0.0;
  for (int c = 0; c < pd_state_contact_count(state); ++c) {
    int b1, b2;
    pd_contact_set_bodies(state->contacts, c, &b1, &b2);
    pdContactParams p = pd_model_contact_params(sub, b1, b2);
    double kn = p.k1n * p.k2n / (p.k1n + p.k2n), kt = p.k1t * p.k2t / (p.k1t + p.k2t);
    double k = p.mu > 0.0 && kt > 0.0 ? fmin(kn, kt) : kn;
    if (k > 0.0 && isfinite(p.massPair)) period = fmax(period, 2.0 * PI * sqrt(p.massPair / k));
  }
  return period > 0.0 ? PD_SLEEP_SETTLE_PERIODS * period : INFINITY;
}

bool pd_sleep_slow(const pdSleepSet* set, const pdBody* body, int k, const double* yb) {
  return fmax(set->speedPeak[k], pd_sleep_speed(body, yb)) < set->speedMax;
}

// The mean acceleration of a body's fastest surface point over dt, from its velocity's change dv and its angular
// velocity's change dw (the speed's measure, pd_sleep_speed, of the change over its length).
static double mean_acceleration(const pdBody* body, pdVec3 dv, pdVec3 dw, double dt) {
  return dt > 0.0 ? (pd_v3_norm(dv) + pd_v3_norm(dw) * body->radius) / dt : 0.0;
}

bool pd_sleep_quiet(pdSleepSet* set, const pdBody* body, int k, const double* yb, double t0, double t1,
                    double horizon) {
  pdVec3 dv = pd_v3_sub(pd_layout_v(yb), set->v0[k]), dw = pd_v3_sub(pd_layout_w(yb), set->w0[k]);
  double accel = mean_acceleration(body, dv, dw, t1 - t0);
  bool slow = isfinite(horizon) && pd_sleep_slow(set, body, k, yb);
  bool quiet = slow && accel * horizon < set->speedMax;
  if (!quiet)
    set->quietSince[k] = NAN;
  else if (isnan(set->quietSince[k]))
    set->quietSince[k] = t0;
  if (!slow) {
    set->slowSince[k] = NAN;
  } else if (isnan(set->slowSince[k])) {
    set->slowSince[k] = t0;
    set->vSlow[k] = set->v0[k];
    set->wSlow[k] = set->w0[k];
  }
  return quiet;
}

bool pd_sleep_still(const pdSleepSet* set, const pdBody* body, int k, const double* yb, double t, double horizon) {
  pdVec3 dv = pd_v3_sub(pd_layout_v(yb), set->vSlow[k]), dw = pd_v3_sub(pd_layout_w(yb), set->wSlow[k]);
  return mean_acceleration(body, dv, dw, t - set->slowSince[k]) * horizon < set->speedMax;
}

void pd_sleep_restless(pdSleepSet* set, int k) { set->quietSince[k] = set->slowSince[k] = NAN; }

void pd_sleep_fall_asleep(pdSleepSet* set, int k, double t, double horizon) {
  set->asleep[k] = true;
  set->asleepSince[k] = t;
  set->horizon[k] = horizon;
}

bool pd_sleep_force_changed(const pdSleepSet* set, const pdBody* body, int k, double t) {
  if (!body->hasForce) return false;
  double change = pd_v3_norm(body->forceRate) * fabs(t - set->asleepSince[k]);
  double surface = change * body->invMass;
  if (body->principal[0] > 0.0) surface += change * pd_v3_norm(body->forcePoint) * body->radius / body->principal[0];
  return surface * set->horizon[k] >= set->speedMax;
}
