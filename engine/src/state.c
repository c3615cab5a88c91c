// polydyn — the mutable state: creation, reset, growth, read-out (bodies, contacts, energy).
#include "polydyn/state.h"

#include <stdlib.h>
#include <string.h>

#include "contact_set_internal.h"
#include "grow.h"
#include "dense_output.h"
#include "implicit.h"
#include "islands.h"
#include "state_layout.h"

const char* const pdStageNames[pd_stageCount] = {"broad_phase", "interference", "contact_analysis", "forces",
                                                 "derivative",  "integrate",    "observe"};
const char* const pdWarningNames[pd_warnCount] = {"step_at_minimum", "non_finite_step", "late_onset"};

pdState* pd_state_create(const pdModel* model) {
  pdState* s = calloc(1, sizeof *s);
  PD_ASSERT(s != NULL);
  s->contacts = pd_contact_set_create(model);
  pd_state_reserve_contacts(model, s, 4 * model->movingCount + 16);
  pd_state_reset(model, s);
  return s;
}

void pd_state_reset(const pdModel* model, pdState* s) {
  const pdSettings* set = &model->settings;
  pd_dense_discard(s);  // first: a presented state's y and contacts are the presentation's
  s->t = 0.0;
  s->h = set->dt;
  s->n = PD_BODY_STATE_SIZE * model->movingCount;
  pd_contact_set_clear(s->contacts);
  s->stepper = PD_STEPPER_DEFAULT;
  s->onsets = PD_ONSETS_DEFAULT;
  s->islands = PD_ISLANDS_DEFAULT;
  s->threads = 1;
  s->searchCertificates = true;
  pd_island_set_free(s->islandSet);
  s->islandSet = NULL;
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

void pd_state_free(pdState* s) {
  if (!s) return;
  pd_dense_resume(s);
  pd_dense_free(s->dense);
  free(s->y);
  free(s->weight);
  free(s->work);
  pd_contact_set_free(s->contacts);
  pd_island_set_free(s->islandSet);
  pd_implicit_free(s->implicit);
  free(s);
}

void pd_state_reserve_contacts(const pdModel* model, pdState* s, int contacts) {
  pd_contact_set_reserve_list(s->contacts, contacts);
  int needed = spring_base(model) + PD_CONTACT_STATE_SIZE * contacts;
  if (needed <= s->capacity) return;
  int c = s->capacity > 0 ? s->capacity : 1;
  while (c < needed) c *= 2;
  s->y = pd_grow(s->y, c, sizeof *s->y);
  s->weight = pd_grow(s->weight, c, sizeof *s->weight);
  // the stepper's vectors hold no data between steps: reallocate rather than copy
  free(s->work);
  s->work = calloc((size_t)c * PD_STEPPER_WORK_VECTORS, sizeof *s->work);
  PD_ASSERT(s->work != NULL);
  s->capacity = c;
}

int pd_state_contact_count(const pdState* s) { return s->contacts ? s->contacts->count : 0; }

pdContactReport pd_state_contact(const pdState* s, int i) {
  PD_ASSERT(s->contacts != NULL && i >= 0 && i < s->contacts->count);
  const contactSlot* c = &s->contacts->items[i];
  pdContactReport r;
  r.bodyA = c->id.body1;
  r.bodyB = c->id.body2;
  r.edgeEdge = c->id.kind == pd_contactEE;
  r.featureA = c->id.feat1;
  r.featureB = c->id.feat2;
  r.point = c->point;
  r.normal = c->normal;
  r.depth = c->depth;
  bool pulls = pd_contact_force_pulls(&c->force);
  r.fn = pulls ? 0.0 : c->force.fn;
  r.ft = pulls ? (pdVec3){0, 0, 0} : c->force.ft;
  r.slip = c->force.slip;
  return r;
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
  return e + pd_contact_spring_energy(s->contacts, s->y, PD_BODY_STATE_SIZE * model->movingCount);
}

const char* pd_stepper_name(pdStepper stepper) {
  switch (stepper) {
    case pd_stepperRK4Fixed:
      return "rk4-fixed";
    case pd_stepperRK43Embedded:
      return "rk43-embedded";
    case pd_stepperImplicit:
      return "ros34pw2";
    case pd_stepperRK4Adaptive:
      break;
  }
  return "rk4-adaptive";
}

const char* pd_onsets_name(pdOnsets onsets) {
  return onsets == pd_onsetsExact ? "exact" : onsets == pd_onsetsPair ? "pair" : "auto";
}

const char* pd_islands_name(pdIslands islands) { return islands == pd_islandsOn ? "on" : "off"; }
