// Test helper: compile a scene text, run it through pd_advance and record every output sample (time,
// energy, contact count, states of up to SCENE_RUN_TRACKED moving bodies). Shared by the physics tests.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/state.h"

enum { SCENE_RUN_SAMPLES = 20001, SCENE_RUN_TRACKED = 4 };

typedef struct record {
  int count;
  double t[SCENE_RUN_SAMPLES];
  double energy[SCENE_RUN_SAMPLES];
  int contacts[SCENE_RUN_SAMPLES];
  pdBodyState body[SCENE_RUN_TRACKED][SCENE_RUN_SAMPLES];  // by moving-body order
  bool finite;
} record;

// Parses and compiles `text`; fails the test with the error's position otherwise.
pdModel* compile_text(const char* text);
// The same for the objects of `shapes` (lines of scene text; cube, hull and prism objects), each placed 10 m from the
// last so that the scene passes the overlap check at t = 0: for tests that set the poses themselves.
pdModel* compile_apart(const char* shapes);
// The same for a scene file.
pdModel* compile_file(const char* path);
// Runs the model to its tend; asserts that it got there with finite numbers only. The record is the
// caller's (free); the final state too when stateOut is not NULL (pd_state_free).
record* run(const pdModel* model, pdState** stateOut);
// The same with the given stepper (run: the default, PD_STEPPER_DEFAULT).
record* run_with(const pdModel* model, pdStepper stepper, pdState** stateOut);
// The same with the given onset mode too (run_with: the default, PD_ONSETS_DEFAULT).
record* run_onsets(const pdModel* model, pdStepper stepper, pdOnsets onsets, pdState** stateOut);
// The same with adaptive RK4, the given onset mode and islands on or off.
record* run_onsets_islands(const pdModel* model, pdOnsets onsets, pdIslands islands, pdState** stateOut);
// The deepest overlap of any two bodies at the state (each pair whose bounding spheres meet, not both fixed): the
// separating-axis minimum depth, the shortest translation that parts them, over the pair's δ_max
// (pd_model_pair_delta_max); 0 when none overlap. The pair goes to *a, *b (nullable; -1 when none).
double deepest_overlap(const pdModel* model, const pdState* state, int* a, int* b);
// The largest rise of the energy between any earlier and any later sample, relative to |E(0)|.
double energy_gain(const record* r);
// Index of the body called `name`; fails the test when there is none.
int body_index(const pdModel* m, const char* name);
