// Determinism, as Box2D tests it (test/test_determinism.c there: a golden hash of a falling scene): the
// pile of ten boxes (cases/sweep/pile_10.scene, the first PILE_TEND s: they fall, collide and start to
// settle) hashed at every output sample — FNV-1a 64 over the bytes of t, every moving body's x, q, v, w
// (13 doubles, in memory as this machine lays them out) and the number of active contacts, then the
// counts of accepted and rejected steps at the end — must equal EXPECTED_HASH. The same run again in this
// process after pd_state_reset, and two states of the same model advanced in alternating slices of a few
// samples each, give that hash too: the engine keeps no state outside pdState, and a run stopped at an
// output sample and resumed is the run that did not stop.
//
// EXPECTED_HASH holds for x86-64 (IEEE double in SSE2 registers, little-endian), FMA contraction off
// (-ffp-contract=off, top-level CMakeLists.txt) and glibc's libm. It was measured the same under gcc 12.2
// at -O2 (dev), -O0 with ASan + UBSan (asan) and -O3 (release-tests), and clang 14 at -Os (clang), all at
// the commit that set it. It changes whenever the engine's numbers change on purpose (the contact model,
// the step control, the order of a sum...): then `build/tests/engine/test_determinism` (or
// `ctest --preset dev -R test_determinism --output-on-failure`) prints the new value — check that the
// change was meant, put the value below and say so in the commit message. A change of this hash with no
// change of the engine is a bug (a compiler flag, uninitialised memory, an order that depends on addresses).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

#define EXPECTED_HASH UINT64_C(0x2a376fc9461a5ae0)
#define PILE PD_SOURCE_DIR "/cases/sweep/pile_10.scene"
#define PILE_TEND 0.5  // s: the boxes land at about 0.2 s
// Samples per alternating slice. A slice ends on a sample time k / sampleRate computed as pd_advance computes
// it: an end a rounding away from it (3 × 0.05 = 0.15000000000000002) would add a 3e-17 s step.
#define SLICE_SAMPLES 5

// FNV-1a, 64 bits (http://www.isthe.com/chongo/tech/comp/fnv/)
static uint64_t fnv1a(uint64_t hash, const void* data, size_t size) {
  const unsigned char* p = data;
  for (size_t i = 0; i < size; ++i) {
    hash ^= p[i];
    hash *= UINT64_C(0x100000001b3);
  }
  return hash;
}

static const uint64_t fnvOffset = UINT64_C(0xcbf29ce484222325);

typedef struct trace {
  uint64_t hash;
  long samples;
} trace;

static bool hash_sample(const pdModel* model, const pdState* state, void* user) {
  trace* tr = user;
  tr->hash = fnv1a(tr->hash, &state->t, sizeof state->t);
  for (int i = 0; i < model->bodyCount; ++i) {
    if (model->bodies[i].fixed) continue;
    pdBodyState b = pd_state_body(model, state, i);
    const double v[13] = {b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
    tr->hash = fnv1a(tr->hash, v, sizeof v);
  }
  int contacts = pd_state_contact_count(state);
  tr->hash = fnv1a(tr->hash, &contacts, sizeof contacts);
  ++tr->samples;
  return true;
}

static uint64_t finish(trace* tr, const pdState* state) {
  tr->hash = fnv1a(tr->hash, &state->count.accepted, sizeof state->count.accepted);
  tr->hash = fnv1a(tr->hash, &state->count.rejected, sizeof state->count.rejected);
  return tr->hash;
}

static pdModel* load_pile(void) {
  pdError err = {0};
  pdScene* scene = pd_scene_parse_file(PILE, &err);
  pdModel* model = scene ? pd_model_compile(scene, &err) : NULL;
  pd_scene_free(scene);
  if (!model) fail_msg("%s:%d:%d: %s", err.file, err.line, err.col, err.message);
  return model;
}

// One whole run to PILE_TEND; its hash.
static uint64_t run_once(const pdModel* model, pdState* state) {
  trace tr = {fnvOffset, 0};
  assert_true(pd_advance(model, state, PILE_TEND, hash_sample, &tr));
  assert_int_equal(tr.samples, (long)(PILE_TEND * model->settings.sampleRate + 0.5) + 1);
  return finish(&tr, state);
}

static void test_the_pile_hashes_to_the_committed_value(void** state) {
  (void)state;
  pdModel* model = load_pile();
  pdState* s = pd_state_create(model, NULL);
  uint64_t hash = run_once(model, s);
  print_message("pile_10 to t = %g s: trajectory hash 0x%016llx (expected 0x%016llx), %ld steps, %ld rejected\n",
                PILE_TEND, (unsigned long long)hash, (unsigned long long)EXPECTED_HASH, s->count.accepted,
                s->count.rejected);
  if (hash != EXPECTED_HASH)
    fail_msg("trajectory hash 0x%016llx, expected 0x%016llx: if the engine's numbers changed on purpose, set "
             "EXPECTED_HASH in tests/engine/test_determinism.c (see the top of that file)",
             (unsigned long long)hash, (unsigned long long)EXPECTED_HASH);
  // again, after a reset of the same state
  pd_state_reset(model, s);
  assert_true(run_once(model, s) == hash);
  pd_state_free(s);
  pd_model_free(model);
}

static void test_two_states_of_one_model_in_alternating_slices_give_the_same_hash(void** state) {
  (void)state;
  pdModel* model = load_pile();
  pdState* alone = pd_state_create(model, NULL);
  uint64_t hash = run_once(model, alone);
  pd_state_free(alone);

  pdState* s[2] = {pd_state_create(model, NULL), pd_state_create(model, NULL)};
  trace tr[2] = {{fnvOffset, 0}, {fnvOffset, 0}};
  long samples = (long)(PILE_TEND * model->settings.sampleRate + 0.5);
  for (long k = SLICE_SAMPLES; k < samples + SLICE_SAMPLES; k += SLICE_SAMPLES) {
    double end = k < samples ? (double)k / model->settings.sampleRate : PILE_TEND;
    for (int i = 0; i < 2; ++i) assert_true(pd_advance(model, s[i], end, hash_sample, &tr[i]));
  }
  for (int i = 0; i < 2; ++i) {
    assert_int_equal(tr[i].samples, (long)(PILE_TEND * model->settings.sampleRate + 0.5) + 1);
    if (finish(&tr[i], s[i]) != hash)
      fail_msg("state %d in slices of %d samples: hash 0x%016llx, one whole run 0x%016llx", i, SLICE_SAMPLES,
               (unsigned long long)tr[i].hash, (unsigned long long)hash);
    pd_state_free(s[i]);
  }
  pd_model_free(model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_the_pile_hashes_to_the_committed_value),
      cmocka_unit_test(test_two_states_of_one_model_in_alternating_slices_give_the_same_hash),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
