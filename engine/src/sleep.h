// polydyn (internal) — sleeping: islands at rest stop being integrated (settings.sleep; docs/sleeping.md).
//
// What an island must show to fall asleep, and what wakes it, per moving body k (scene moving-body index).
// islands.c owns the islands and decides; this module keeps each body's record and the thresholds:
// - speed: |v| + |ω| r (r the body's radius: the fastest surface point), peak over every step end of the
//   interval under way and its start, below PD_SLEEP_SPEED of the velocity scale the error control uses;
// - acceleration: the same measure of the change of v and ω over a sync interval, divided by its length,
//   below the speed threshold over the horizon: the time left to the scene's end, at least the island's settle
//   time (a body that accelerated faster would leave the speed threshold before the end);
// - contact: every body of the island touches something (a body in free flight is never at rest);
// - both held since quietSince for the island's settle time: PD_SLEEP_SETTLE_PERIODS of the slowest period
//   of its contacts (pd_sleep_settle_time);
// - or, the speed alone held since slowSince for the settle time, the acceleration over that whole window (the
//   change of v and ω since slowSince over its length) below the same threshold (pd_sleep_still): a body ringing
//   within the speed threshold (the tolerance's own noise) fails the acceleration over each interval though its
//   velocity goes nowhere, and over the window it reads its drift; a steady acceleration reads the same either way.
// A sleeping body wakes when the applied force on it has changed since it fell asleep by what would give it
// the acceleration threshold (pd_sleep_force_changed); islands.c wakes it too when a body outside its island
// may reach it (the islands' partition).
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/state.h"

// The speed threshold as a fraction of settings.vmax: the error control's velocity scale, so that a body slower
// than tol · vmax moves less than one step's tolerated velocity error allows (state.h, the error norm). Bodies
// at rest in a pile come to 1e-17 m/s (cases/bench/pile_100.scene, 2 s: 100 of 100 below 1e-12 from 1.6 s):
// resting contact is far below it, and the frozen state differs from the integrated one by less than the
// tolerance asks of one step.
#define PD_SLEEP_SPEED_TOL 1.0
// Settle time, in periods of the island's slowest contact: long enough for a contact's own ringing to show in the
// speed peaks at several step ends (a body is checked at every step end, and the implicit stepper's steps at
// rest are up to dtmax long).
#define PD_SLEEP_SETTLE_PERIODS 4.0

typedef struct pdSleepSet {
  int movingCount;
  double speedMax;      // m/s: the speed threshold, PD_SLEEP_SPEED_TOL · tol · vmax
  double* speedPeak;    // (movingCount) m/s: the largest speed at the interval's start and step ends so far
  pdVec3 *v0, *w0;      // (movingCount) velocity and angular velocity at the interval's start
  double* quietSince;   // (movingCount) s: start of the quiet intervals leading here (NAN: the last was not quiet)
  double* slowSince;    // (movingCount) s: start of the slow intervals leading here (NAN: the last was not slow)
  pdVec3 *vSlow, *wSlow;  // (movingCount) velocity and angular velocity at slowSince
  bool* asleep;         // (movingCount)
  double* asleepSince;  // (movingCount) s: when it fell asleep
  double* horizon;      // (movingCount) s: the horizon of its acceleration threshold when it fell asleep
  bool* inContact;      // (movingCount) scratch: the body has a contact
  long sleeps, wakes;   // islands that fell asleep, islands woken
  double bodySeconds;   // body-seconds spent asleep
} pdSleepSet;

pdSleepSet* pd_sleep_create(const pdModel* model);
void pd_sleep_free(pdSleepSet* set);

// Body k's speed measure |v| + |ω| r from its 13 numbers.
double pd_sleep_speed(const pdBody* body, const double* yb);

// Body k starts an interval (or its redo) with the numbers yb: the peak restarts there.
void pd_sleep_interval_start(pdSleepSet* set, const pdBody* body, int k, const double* yb);

// Body k's numbers yb at a step end (or presented at the interval's end): the peak grows. Touches only k's entries
// (called from the thread that runs k's island).
static inline void pd_sleep_step_end(pdSleepSet* set, const pdBody* body, int k, const double* yb) {
  double speed = pd_sleep_speed(body, yb);
  if (speed > set->speedPeak[k]) set->speedPeak[k] = speed;
}

// The island's settle time, s: PD_SLEEP_SETTLE_PERIODS periods of its slowest contact (2π √(m / k) with m the
// pair's reduced mass and k the softer of the series normal and tangential springs). INFINITY without a contact.
double pd_sleep_settle_time(const pdModel* sub, const pdState* state);

// Whether body k, with its numbers yb at the end of the interval, stayed below the speed threshold over it (the cheap
// half of pd_sleep_quiet).
bool pd_sleep_slow(const pdSleepSet* set, const pdBody* body, int k, const double* yb);

// At the end of the interval [t0, t1] with body k's numbers yb there: whether the body was quiet over it (speed
// peak below the speed threshold, mean acceleration below it over `horizon`), and quietSince updated
// (set to t0 when the body turns quiet, NAN when it is not); slowSince likewise for the speed alone, with the
// velocities there.
bool pd_sleep_quiet(pdSleepSet* set, const pdBody* body, int k, const double* yb, double t0, double t1,
                    double horizon);

// Whether body k, its numbers yb at t, has kept its mean acceleration since slowSince below the speed threshold over
// `horizon` (the window's test, once the speed alone has held for a settle time).
bool pd_sleep_still(const pdSleepSet* set, const pdBody* body, int k, const double* yb, double t, double horizon);

// Body k's quiet and slow times start again (it moved, lost its contacts, or woke).
void pd_sleep_restless(pdSleepSet* set, int k);

// Body k falls asleep at t, its acceleration threshold that of `horizon` (pd_sleep_quiet).
void pd_sleep_fall_asleep(pdSleepSet* set, int k, double t, double horizon);

// Whether the applied force on sleeping body k at t differs from the one it fell asleep under by more than would
// give its surface the acceleration threshold it fell asleep under (speedMax / horizon).
bool pd_sleep_force_changed(const pdSleepSet* set, const pdBody* body, int k, double t);
