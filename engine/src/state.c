// polydyn — the mutable state: options, creation, reset and release of its own parts, read-out of bodies and
// energy. Its contacts' read-out and room: state_contacts.c; the public reset and free, which also free the
// islands' states: state_free.c.
#include "polydyn/state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_list.h"
#include "contact_set.h"
#include "grow.h"
#include "dense_output.h"
#include "implicit.h"
#include "state_layout.h"

const char* const pdStageNames[pd_stageCount] = {"broad_phase", "interference", "contact_analysis", "forces",
                                                 "derivative",  "integrate",    "observe"};
const char* const pdWarningNames[pd_warnCount] = {"step_at_minimum", "non_finite_step", "late_onset"};

enum { OPTIONS_VALID = 0x5044534f };  // "PDSO": pdStateOptions.valid of options made by pd_state_options_default

pdStateOptions pd_state_options_default(void) {
  pdStateOptions o = {0};
  o.stepper = PD_STEPPER_DEFAULT;
  o.onsets = PD_ONSETS_DEFAULT;
  o.islands = PD_ISLANDS_DEFAULT;
  o.threads = 1;
  o.searchCertificates = true;
  o.stageTimers = true;
  o.h = 0.0;
  o.valid = OPTIONS_VALID;
  return o;
}

pdState* pd_state_create(const pdModel* model, const pdStateOptions* options) {
  pdStateOptions o = options ? *options : pd_state_options_default();
  PD_ASSERT(o.valid == OPTIONS_VALID);  // made by pd_state_options_default
  PD_ASSERT(o.stepper >= pd_stepperRK4Adaptive && o.stepper <= pd_stepperImplicitDopri);
  PD_ASSERT(o.onsets >= pd_onsetsExact && o.onsets <= pd_onsetsHeld);
  PD_ASSERT(o.islands == pd_islandsOff || o.islands == pd_islandsOn);
  PD_ASSERT(o.threads >= 1 && o.threads <= PD_THREADS_MAX);
  PD_ASSERT(o.h >= 0.0 && o.h < INFINITY);
  pdState* s = pd_zeroed(1, sizeof *s);
  s->options = o;
  s->contacts = pd_contact_set_create(model);
  pd_state_reserve_contacts(model, s, 4 * model->movingCount + 16);
  pd_state_reset_own(model, s);
  return s;
}

void pd_state_reset_own(const pdModel* model, pdState* s) {
  const pdSettings* set = &model->settings;
  pd_dense_discard(s);  // first: a presented state's y and contacts are the presentation's
  s->t = 0.0;
  s->h = s->options.h > 0.0 ? s->options.h : set->dt;
  s->hLimit = pd_limitError;
  s->n = PD_BODY_STATE_SIZE * model->movingCount;
  pd_contact_set_clear(s->contacts);
  s->stepper = s->options.stepper;
  s->onsets = s->options.onsets;
  s->islands = s->options.islands;
  s->threads = s->options.threads;
  s->searchCertificates = s->options.searchCertificates;
  s->stageTimers = s->options.stageTimers;
  s->stepObserver = s->options.stepObserver;
  s->stepUser = s->options.stepUser;
  pd_implicit_free(s->implicit);  // its switch (active, on probation, backing off) is the last run's
  s->implicit = NULL;
  s->nextSample = 0;
  s->failed = false;
  s->stopped = false;
  memset(&s->count, 0, sizeof s->count);
  memset(s->warnings, 0, sizeof s->warnings);
  memset(s->stageSeconds, 0, sizeof s->stageSeconds);
  for (int k = 0; k < model->movingCount; ++k) {
    const pdBody* b = &model->bodies[model->movingBodies[k]];
    double* y = s->y + PD_BODY_STATE_SIZE * k;
    double* w = s->weight + PD_BODY_STATE_SIZE * k;
    pd_layout_store(y, b->v0, b->w0, b->x0, b->q0);
    // error weights: velocities over the characteristic speed, angular velocities over that speed
    // per body size, positions over the body size, quaternion components are already O(1)
    double L = b->size, V = set->vmax;
    for (int i = 0; i < 3; ++i) {
      w[PD_Y_V + i] = V;
      w[PD_Y_W + i] = V / L;
      w[PD_Y_X + i] = L;
    }
    for (int i = 0; i < 4; ++i) w[PD_Y_Q + i] = 1.0;
  }
}

void pd_state_release(pdState* s) {
  PD_ASSERT(s->islandSet == NULL);  // pd_state_free frees it first
  pd_dense_resume(s);
  pd_dense_free(s->dense);
  free(s->y);
  free(s->weight);
  free(s->work);
  pd_contact_set_free(s->contacts);
  pd_implicit_free(s->implicit);
  free(s);
}

pdBodyState pd_state_body(const pdModel* model, const pdState* s, int bodyIndex) {
  PD_ASSERT(bodyIndex >= 0 && bodyIndex < model->bodyCount);
  const pdBody* b = &model->bodies[bodyIndex];
  if (b->fixed) return (pdBodyState){b->x0, b->q0, {0, 0, 0}, {0, 0, 0}};
  const double* y = s->y + PD_BODY_STATE_SIZE * b->stateIndex;
  return (pdBodyState){pd_layout_x(y), pd_layout_q(y), pd_layout_v(y), pd_layout_w(y)};
}

double pd_state_energy(const pdModel* model, const pdState* s) {
  double e = 0.0;
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    const pdBody* b = &model->bodies[i];
    pdBodyState bs = pd_state_body(model, s, i);
    e += pd_body_kinetic_energy(b, bs.v, bs.w, bs.q) - b->mass * pd_v3_dot(model->settings.gravity, bs.x);
  }
  pd_contact_set_settle(s->contacts, s->y);  // a presented state's springs, realigned
  e += pd_contact_spring_energy(s->contacts, s->y, PD_BODY_STATE_SIZE * model->movingCount);
  // the springs that broken contacts keep for a return (contact_history.h) are energy the state still holds
  // (a presented state's contact list is the dense output's view, without a history: the step's, kept aside)
  if (s->contacts && s->contacts->history) e += pd_history_spring_energy(model, s->contacts->history);
  else e += pd_dense_presented_kept_energy(s->dense);
  return e;
}

const char* pd_stepper_name(pdStepper stepper) {
  switch (stepper) {
    case pd_stepperRK4Fixed:
      return "rk4-fixed";
    case pd_stepperRK43Embedded:
      return "rk43-embedded";
    case pd_stepperImplicit:
      return "ros34pw2";
    case pd_stepperDopri54:
      return "dopri54";
    case pd_stepperImplicitDopri:
      return "ros34pw2-dopri54";
    case pd_stepperRK4Adaptive:
      break;
  }
  return "rk4-adaptive";
}

const char* pd_onsets_name(pdOnsets onsets) {
  switch (onsets) {
    case pd_onsetsExact:
      return "exact";
    case pd_onsetsPair:
      return "pair";
    case pd_onsetsBounded:
      return "bounded";
    case pd_onsetsHeld:
      return "held";
    case pd_onsetsAuto:
      break;
  }
  return "auto";
}

const char* pd_islands_name(pdIslands islands) { return islands == pd_islandsOn ? "on" : "off"; }

const char* pd_step_limit_name(pdStepLimit limit) {
  static const char* const names[pd_limitCount] = {"error", "largest", "stability", "travel", "event", "landing"};
  PD_ASSERT(limit >= 0 && limit < pd_limitCount);
  return names[limit];
}
