// polydyn (internal) — output samples: their times and the observer's call, one definition for pd_advance with islands
// off (advance.c) and on (islands.c).
#pragma once

#include "clock.h"
#include "polydyn/state.h"

// The time of output sample k, s: k / sampleRate, never accumulated, so sample stamps never drift.
static inline double pd_sample_time(const pdModel* model, long k) { return (double)k / model->settings.sampleRate; }

// The observer (nullable) at the state as it is now; the sample counted and the next one due. An observer that
// returns false stops the run (state->stopped). Returns the seconds the call took, also added to the observe stage.
static inline double pd_observe(const pdModel* model, pdState* s, pdObserverFcn* observer, void* user) {
  double t0 = pd_clock_seconds();
  if (observer && !observer(model, s, user)) s->stopped = true;
  ++s->count.samples;
  ++s->nextSample;
  double seconds = pd_clock_seconds() - t0;
  s->stageSeconds[pd_stageObserve] += seconds;
  return seconds;
}
