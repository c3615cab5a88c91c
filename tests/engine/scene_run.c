// Test helper: see scene_run.h.
#include "scene_run.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "interference.h"
#include "polydyn/scene.h"

// Compiles a parsed scene (NULL: the parse failed, err says why) and frees it; fails the test with err's position.
static pdModel* compile_parsed(pdScene* scene, pdError* err) {
  if (!scene) fail_msg("parse: %s:%d:%d: %s", err->file, err->line, err->col, err->message);
  pdModel* model = pd_model_compile(scene, err);
  pd_scene_free(scene);
  if (!model) fail_msg("compile: %s:%d:%d: %s", err->file, err->line, err->col, err->message);
  return model;
}

pdModel* compile_text(const char* text) {
  pdError err;
  memset(&err, 0, sizeof err);
  return compile_parsed(pd_scene_parse_buffer("physics.scene", text, strlen(text), &err), &err);
}

pdModel* compile_apart(const char* shapes) {
  char text[8192];
  size_t used = 0;
  int objects = 0;
  for (const char* line = shapes; *line;) {
    const char* end = strchr(line, '\n');
    size_t len = end ? (size_t)(end - line) + 1 : strlen(line);
    used += (size_t)snprintf(text + used, sizeof text - used, "%.*s", (int)len, line);
    if (!strncmp(line, "cube ", 5) || !strncmp(line, "hull ", 5) || !strncmp(line, "prism ", 6))
      used += (size_t)snprintf(text + used, sizeof text - used, "loc %d 0 0\n", 10 * objects++);
    assert_true(used < sizeof text);
    line += len;
  }
  return compile_text(text);
}

pdModel* compile_file(const char* path) {
  pdError err;
  memset(&err, 0, sizeof err);
  return compile_parsed(pd_scene_parse_file(path, &err), &err);
}

static bool record_sample(const pdModel* model, const pdState* state, void* user) {
  record* r = user;
  if (r->count == SCENE_RUN_SAMPLES) return false;
  int k = r->count++;
  r->t[k] = state->t;
  r->energy[k] = pd_state_energy(model, state);
  r->contacts[k] = pd_state_contact_count(state);
  for (int j = 0; j < model->movingCount && j < SCENE_RUN_TRACKED; ++j) {
    pdBodyState b = pd_state_body(model, state, model->movingBodies[j]);
    r->body[j][k] = b;
    r->finite = r->finite && pd_v3_isfinite(b.x) && pd_v3_isfinite(b.v) && pd_v3_isfinite(b.w) && isfinite(b.q.w);
  }
  r->finite = r->finite && isfinite(r->energy[k]);
  return true;
}

record* run(const pdModel* model, pdState** stateOut) { return run_with(model, PD_STEPPER_DEFAULT, stateOut); }

record* run_with(const pdModel* model, pdStepper stepper, pdState** stateOut) {
  return run_onsets(model, stepper, pd_onsetsExact, stateOut);
}

static record* run_state(const pdModel* model, pdStepper stepper, pdOnsets onsets, pdIslands islands,
                         pdState** stateOut) {
  record* r = calloc(1, sizeof *r);
  assert_non_null(r);
  r->finite = true;
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  options.onsets = onsets;
  options.islands = islands;
  pdState* s = pd_state_create(model, &options);
  assert_true(pd_advance(model, s, model->settings.tend, record_sample, r));
  assert_true(r->finite);
  assert_int_equal(s->warnings[pd_warnNonFinite], 0);
  if (stateOut)
    *stateOut = s;
  else
    pd_state_free(s);
  return r;
}

record* run_onsets(const pdModel* model, pdStepper stepper, pdOnsets onsets, pdState** stateOut) {
  return run_state(model, stepper, onsets, PD_ISLANDS_DEFAULT, stateOut);
}

record* run_onsets_islands(const pdModel* model, pdOnsets onsets, pdIslands islands, pdState** stateOut) {
  return run_state(model, pd_stepperRK4Adaptive, onsets, islands, stateOut);
}

double energy_gain(const record* r) {
  double lowest = r->energy[0], gain = 0.0;
  for (int k = 1; k < r->count; ++k) {
    gain = fmax(gain, r->energy[k] - lowest);
    lowest = fmin(lowest, r->energy[k]);
  }
  return gain / fabs(r->energy[0]);
}

int body_index(const pdModel* m, const char* name) {
  for (int i = 0; i < m->bodyCount; ++i)
    if (!strcmp(m->bodies[i].name, name)) return i;
  fail_msg("no body %s", name);
  return -1;
}

double deepest_overlap(const pdModel* model, const pdState* state, int* a, int* b) {
  double deepest = 0.0;
  int da = -1, db = -1;
  for (int i = 0; i < model->bodyCount; ++i)
    for (int j = i + 1; j < model->bodyCount; ++j) {
      if (model->bodies[i].fixed && model->bodies[j].fixed) continue;
      pdBodyState bi = pd_state_body(model, state, i), bj = pd_state_body(model, state, j);
      if (pd_v3_norm(pd_v3_sub(bi.x, bj.x)) > model->bodies[i].radius + model->bodies[j].radius) continue;
      pdMat3 ri = pd_quat_to_mat3(bi.q), rj = pd_quat_to_mat3(bj.q);
      pdSatResult sat;
      if (!pd_interference(&model->bodies[i].shape, bi.x, &ri, &model->bodies[j].shape, bj.x, &rj, PD_SAT_MIN_DEPTH,
                           NULL, &sat))
        continue;
      double ratio = sat.depth / pd_model_pair_delta_max(model, i, j);
      if (ratio > deepest) deepest = ratio, da = i, db = j;
    }
  if (a) *a = da;
  if (b) *b = db;
  return deepest;
}
