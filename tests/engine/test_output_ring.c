// engine/src/output.c: the files a run directory gets through the writer thread's ring (pd_run_observe) and its
// cache of the numbers' texts hold the very bytes that pd_write_trajectory_rows and pd_write_contact_rows print for
// the same samples (formed afresh), with their headers first: for samples smaller than a block, so that the ring keeps
// its 64 blocks and wraps round several times (the stack of 10: 8.75 KiB a sample, one to a 16 KiB block, 301
// samples), and for samples larger than a block from the first sample on, so that the ring has fewer blocks, each
// grown to a sample, and wraps round too (300 cubes resting on a floor: ~31 KiB at the first sample, ~150 KiB with
// their contacts).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "polydyn/output.h"
#include "scene_run.h"
#include "test_files.h"

// The same samples printed directly (the reference) and handed to the ring.
typedef struct bothWriters {
  pdRunWriter* run;
  FILE* trajectory;
  FILE* contacts;
  int samples;
} bothWriters;

static bool observe_both(const pdModel* model, const pdState* state, void* user) {
  bothWriters* w = user;
  pd_write_trajectory_rows(w->trajectory, model, state);
  pd_write_contact_rows(w->contacts, model, state);
  ++w->samples;
  return pd_run_observe(model, state, w->run);
}

static void expect_same_file(const char* dir, const char* name, const char* expected, size_t expectedSize) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  size_t size;
  char* text = test_read_file(path, &size);
  if (size != expectedSize || memcmp(text, expected, size) != 0)
    fail_msg("%s: %zu bytes through the ring, %zu printed directly, or other bytes", name, size, expectedSize);
  free(text);
}

// Runs `model` to its tend into a run directory through the ring and into memory directly; compares the files.
static void expect_ring_writes_rows(const pdModel* model, int minSamples) {
  char dir[] = "/tmp/pd-ring-XXXXXX";
  assert_non_null(mkdtemp(dir));
  char out[600];
  snprintf(out, sizeof out, "%s/run", dir);
  pdError err = {0};
  bothWriters w = {pd_run_open(out, &err), NULL, NULL, 0};
  assert_non_null(w.run);
  char *trajectory = NULL, *contacts = NULL;
  size_t trajectorySize = 0, contactsSize = 0;
  w.trajectory = open_memstream(&trajectory, &trajectorySize);
  w.contacts = open_memstream(&contacts, &contactsSize);
  assert_true(w.trajectory != NULL && w.contacts != NULL);
  pd_write_trajectory_header(w.trajectory);
  pd_write_contacts_header(w.contacts);

  pdState* state = pd_state_create(model, NULL);
  double energyStart = pd_state_energy(model, state);
  bool completed = pd_advance(model, state, model->settings.tend, observe_both, &w);
  assert_true(completed);
  assert_true(w.samples >= minSamples);
  pdRunInfo info = {.engine = "polydyn-soft",
                    .energyStart = energyStart,
                    .energyEnd = pd_state_energy(model, state),
                    .wallSeconds = 0.0,
                    .completed = completed};
  assert_true(pd_run_finish(w.run, model, state, &info, &err));
  fclose(w.trajectory);
  fclose(w.contacts);
  expect_same_file(out, "trajectory.csv", trajectory, trajectorySize);
  expect_same_file(out, "contacts.csv", contacts, contactsSize);
  print_message("%d samples, %zu + %zu bytes\n", w.samples, trajectorySize, contactsSize);
  free(trajectory);
  free(contacts);
  pd_state_free(state);

  char command[700];
  snprintf(command, sizeof command, "rm -rf '%s'", dir);
  assert_int_equal(system(command), 0);
}

static void test_small_samples_wrap_the_ring(void** s) {
  (void)s;
  pdModel* model = compile_file(PD_SOURCE_DIR "/cases/hard/stack_10.scene");
  expect_ring_writes_rows(model, 301);
  pd_model_free(model);
}

static void test_samples_larger_than_a_block(void** s) {
  (void)s;
  // 300 cubes of 5 cm resting on a floor, 4 VF contacts each after the first step: ~1 200 contact rows a sample
  size_t capacity = 64 * 1024, used = 0;
  char* text = malloc(capacity);
  assert_non_null(text);
  used += (size_t)snprintf(text + used, capacity - used,
                           "tend 0.08\nsample 1000\ncube floor grey 4 4 0.1\nfixed\nloc 0 0 -0.05\n");
  for (int i = 0; i < 300; ++i)
    used += (size_t)snprintf(text + used, capacity - used, "cube c%d tan 0.05 0.05 0.05\nloc %.3f %.3f 0.025\n", i,
                             -1.5 + 0.15 * (i % 20), -1.5 + 0.15 * (i / 20));
  assert_true(used < capacity);
  pdModel* model = compile_text(text);
  free(text);
  expect_ring_writes_rows(model, 81);
  pd_model_free(model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_small_samples_wrap_the_ring),
      cmocka_unit_test(test_samples_larger_than_a_block),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
