// Batch runs (runner/include/pdrun/batch.h): results land in task order with the same bytes whatever
// the number of worker processes, including results larger than a pipe holds; a worker that dies and a
// progress callback that says stop fail the batch with a message; a plain process is a world of one.
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "pdrun/batch.h"

enum { TASKS = 9 };

// Task i: i × 37 000 bytes (up to ~300 kB: many times a pipe's 64 kB), each a function of (i, position).
static size_t task_size(int task) { return (size_t)task * 37000; }

static void pattern_task(int task, pdBatchBuffer* result, void* user) {
  (void)user;
  for (size_t k = 0; k < task_size(task); ++k) {
    unsigned char byte = (unsigned char)((size_t)task * 131 + k * 7);
    pd_batch_append(result, &byte, 1);
  }
}

static void run_with(int workers, pdBatchBuffer* results) {
  pdBatchOptions options = {.workers = workers};
  char why[256] = "";
  assert_true(pd_batch_run(TASKS, pattern_task, NULL, &options, results, why, sizeof why));
}

static void test_results_in_task_order_whatever_the_workers(void** state) {
  (void)state;
  pdBatchBuffer one[TASKS], three[TASKS];
  run_with(1, one);
  run_with(3, three);
  for (int i = 0; i < TASKS; ++i) {
    assert_int_equal(one[i].size, task_size(i));
    assert_int_equal(three[i].size, task_size(i));
    if (i > 0) {
      assert_memory_equal(one[i].data, three[i].data, one[i].size);
      assert_int_equal(three[i].data[task_size(i) - 1], (unsigned char)((size_t)i * 131 + (task_size(i) - 1) * 7));
    }
    pd_batch_buffer_free(&one[i]);
    pd_batch_buffer_free(&three[i]);
  }
}

static void dying_task(int task, pdBatchBuffer* result, void* user) {
  (void)user;
  if (task == 4) raise(SIGKILL);
  pd_batch_append(result, &task, sizeof task);
}

static void test_a_worker_that_dies_fails_the_batch(void** state) {
  (void)state;
  pdBatchBuffer results[TASKS];
  pdBatchOptions options = {.workers = 2};
  char why[256] = "";
  assert_false(pd_batch_run(TASKS, dying_task, NULL, &options, results, why, sizeof why));
  assert_non_null(strstr(why, "died"));
  for (int i = 0; i < TASKS; ++i) assert_int_equal(results[i].size, 0);
}

static bool stop_after_two(int task, int done, int total, void* user) {
  (void)task, (void)total, (void)user;
  return done < 2;
}

static void test_progress_can_stop_the_batch(void** state) {
  (void)state;
  for (int workers = 1; workers <= 2; ++workers) {
    pdBatchBuffer results[TASKS];
    pdBatchOptions options = {.workers = workers, .progress = stop_after_two};
    char why[256] = "";
    assert_false(pd_batch_run(TASKS, pattern_task, NULL, &options, results, why, sizeof why));
    assert_non_null(strstr(why, "stopped"));
  }
}

static void test_a_plain_process_is_a_world_of_one(void** state) {
  (void)state;
  assert_int_equal(pd_batch_ranks(), 1);
  assert_int_equal(pd_batch_rank(), 0);
  assert_true(pd_batch_is_root());
  char text[8] = "same";
  pd_batch_share(text, sizeof text);
  assert_string_equal(text, "same");
  pdBatchBuffer b = {0};
  int32_t v = 7, back = 0;
  size_t at = 0;
  pd_batch_append(&b, &v, sizeof v);
  assert_true(pd_batch_read(&b, &at, &back, sizeof back));
  assert_int_equal(back, 7);
  assert_false(pd_batch_read(&b, &at, &back, sizeof back));  // past the end: false, zeroed
  assert_int_equal(back, 0);
  pd_batch_buffer_free(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_results_in_task_order_whatever_the_workers),
      cmocka_unit_test(test_a_worker_that_dies_fails_the_batch),
      cmocka_unit_test(test_progress_can_stop_the_batch),
      cmocka_unit_test(test_a_plain_process_is_a_world_of_one),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
