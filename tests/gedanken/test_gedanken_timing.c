// The cost of a work-precision point (pdgk/gedanken.h): a timing repeats the run back to back until the runs have
// spent the minimum CPU time and gives the cost per run; a point's cost is the least of its timings, with their
// median and spread. Runs here are scripted (their times are given), so every answer is known exactly.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "pdgk/gedanken.h"

#define ROUND_OFF 1e-12  // the scripted times are exact: only floating-point rounding separates the answers

typedef struct scriptedRun {
  double wall, cpu;  // each run's, s
  long failsAt;      // the run (1-based) that does not complete; 0: none
  long calls;
} scriptedRun;

static bool scripted(void* user, double* wall, double* cpu) {
  scriptedRun* r = user;
  ++r->calls;
  *wall = r->wall;
  *cpu = r->cpu;
  return r->calls != r->failsAt;
}

static void test_a_short_run_is_repeated_until_the_minimum_cpu_time(void** state) {
  (void)state;
  // 3 ms of CPU a run: 6 runs make 18 ms, the 7th reaches 21 ms >= 20 ms
  scriptedRun r = {.wall = 0.005, .cpu = 0.003};
  pdGkTiming t = pd_gk_time_runs(scripted, &r, PD_GK_TIMING_MIN_CPU_SECONDS);
  assert_true(t.completed);
  assert_int_equal(t.runs, 7);
  assert_int_equal(r.calls, 7);
  assert_true(fabs(t.cpu - 0.003) <= ROUND_OFF);
  assert_true(fabs(t.wall - 0.005) <= ROUND_OFF);
  assert_true((double)t.runs * t.cpu >= PD_GK_TIMING_MIN_CPU_SECONDS);
  assert_true((double)(t.runs - 1) * t.cpu < PD_GK_TIMING_MIN_CPU_SECONDS);  // not one run more than needed
}

static void test_a_long_run_is_timed_once(void** state) {
  (void)state;
  scriptedRun r = {.wall = 0.2, .cpu = 0.15};
  pdGkTiming t = pd_gk_time_runs(scripted, &r, PD_GK_TIMING_MIN_CPU_SECONDS);
  assert_true(t.completed);
  assert_int_equal(t.runs, 1);
  assert_true(fabs(t.cpu - 0.15) <= ROUND_OFF);
}

static void test_a_run_that_fails_ends_the_timing(void** state) {
  (void)state;
  scriptedRun r = {.wall = 0.001, .cpu = 0.001, .failsAt = 3};
  pdGkTiming t = pd_gk_time_runs(scripted, &r, PD_GK_TIMING_MIN_CPU_SECONDS);
  assert_false(t.completed);
  assert_int_equal(t.runs, 3);
  assert_int_equal(r.calls, 3);
}

static void test_a_clock_that_does_not_advance_stops_at_the_most_runs(void** state) {
  (void)state;
  scriptedRun r = {.wall = 0.0, .cpu = 0.0};
  pdGkTiming t = pd_gk_time_runs(scripted, &r, PD_GK_TIMING_MIN_CPU_SECONDS);
  assert_true(t.completed);
  assert_int_equal(t.runs, PD_GK_TIMING_MAX_RUNS);
}

static void test_the_cost_is_the_least_timing_with_median_and_spread(void** state) {
  (void)state;
  // CPU and wall least in different timings: each is its own minimum; the runs are those of the least CPU time
  const pdGkTiming timings[] = {
      {.wall = 0.0050, .cpu = 0.0040, .runs = 5, .completed = true},
      {.wall = 0.0040, .cpu = 0.0030, .runs = 7, .completed = true},
      {.wall = 0.0030, .cpu = 0.0036, .runs = 6, .completed = true},
      {.wall = 0.0090, .cpu = 0.0060, .runs = 4, .completed = true},
  };
  pdGkCost c = pd_gk_cost(timings, 4);
  assert_true(fabs(c.cpu - 0.0030) <= ROUND_OFF);
  assert_true(fabs(c.wall - 0.0030) <= ROUND_OFF);
  assert_int_equal(c.runs, 7);
  assert_true(fabs(c.cpuMedian - 0.5 * (0.0036 + 0.0040)) <= ROUND_OFF);
  assert_true(fabs(c.wallMedian - 0.5 * (0.0040 + 0.0050)) <= ROUND_OFF);
  assert_true(fabs(c.cpuMaxOverMin - 2.0) <= ROUND_OFF);
  assert_true(fabs(c.wallMaxOverMin - 3.0) <= ROUND_OFF);
}

static void test_one_timing_is_its_own_median_with_spread_one(void** state) {
  (void)state;
  const pdGkTiming one = {.wall = 0.002, .cpu = 0.0015, .runs = 14, .completed = true};
  pdGkCost c = pd_gk_cost(&one, 1);
  assert_true(c.cpu == c.cpuMedian && c.wall == c.wallMedian);
  assert_true(c.cpuMaxOverMin == 1.0 && c.wallMaxOverMin == 1.0);
  assert_int_equal(c.runs, 14);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_short_run_is_repeated_until_the_minimum_cpu_time),
      cmocka_unit_test(test_a_long_run_is_timed_once),
      cmocka_unit_test(test_a_run_that_fails_ends_the_timing),
      cmocka_unit_test(test_a_clock_that_does_not_advance_stops_at_the_most_runs),
      cmocka_unit_test(test_the_cost_is_the_least_timing_with_median_and_spread),
      cmocka_unit_test(test_one_timing_is_its_own_median_with_spread_one),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
