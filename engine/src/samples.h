// polydyn (internal) — output samples: their times and the observer's call, one definition for pd_advance with islands
// off (advance.c) and on (islands.c).
#pragma once

#include <stdbool.h>

#include "clock.h"
#include "polydyn/state.h"

// The time of output sample k, s: k / sampleRate, never accumulated, so sample stamps never drift.
static inline double pd_sample_time(const pdModel* model, long k) { return (double)k / model->settings.sampleRate; }

// The observer (nullable) at the state as it is now; the sample counted and the next one due. An observer that
// returns false stops the run (state->stopped). Returns the seconds the call took, also added to the observe stage,
// when `timed` and there is an observer: a clock read costs about what a lone body's presentation does (tens of
// nanoseconds), so a call whose time nobody keeps (no observer; an island's, which the scene times itself) reads
// none.
static inline double pd_observe(const pdModel* model, pdState* s, pdObserverFcn* observer, void* user, bool timed) {
  timed = timed && observer && s->stageTimers;
  double t0 = timed ? pd_clock_seconds() : 0.0;
  if (observer && !observer(model, s, user)) s->stopped = true;
  ++s->count.samples;
  ++s->nextSample;
  if (!timed) return 0.0;
  double seconds = pd_clock_seconds() - t0;
  s->stageSeconds[pd_stageObserve] += seconds;
  return seconds;
}
