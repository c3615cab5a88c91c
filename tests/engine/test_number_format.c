// engine/src/number_format.h: pd_format_g17 writes exactly what snprintf("%.17g") writes, for doubles of
// every magnitude (random bit patterns: subnormals to 1e308), unit-range values, values over 40 decades,
// binary fractions of 15–16-digit integers (where the exact ties of the 18th digit live) and the edge
// cases by name. Any difference is a failure: the outputs promise "%.17g".
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "number_format.h"

#define DRAWS 500000  // per distribution; ~1 s in all (RelWithDebInfo)

static uint64_t seed = 88172645463325252ull;
static uint64_t next_random(void) {  // xorshift64: fixed seed, the same draws on every machine
  seed ^= seed << 13;
  seed ^= seed >> 7;
  seed ^= seed << 17;
  return seed;
}
static double unit_random(void) { return (double)(next_random() >> 11) / 9007199254740992.0; }

static long differences = 0, ties = 0;

static void check(double x) {
  char expected[64], got[PD_G17_MAX];
  snprintf(expected, sizeof expected, "%.17g", x);
  int n = pd_format_g17(x, got);
  if (n != (int)strlen(got) || strcmp(expected, got) != 0) {
    if (differences < 10) print_message("%%.17g of %a: printf %s, pd_format_g17 %s\n", x, expected, got);
    ++differences;
  }
}

static void test_named_values(void** state) {
  (void)state;
  const double named[] = {0.0, -0.0, 1.0, -1.0, 0.1, 1e-4, 9.9999999999999995e-5, 1e-5, 1e16, 1e17, 1e-300,
                          1.7976931348623157e308, 2.2250738585072014e-308, 4.9406564584124654e-324, 123456789012345.125,
                          -36026628580696.5625, 999999999999999.9375, 0.30000000000000004, 1.0 / 3.0, 9.81};
  for (size_t i = 0; i < sizeof named / sizeof *named; ++i) check(named[i]);
  assert_int_equal(differences, 0);
}

static void test_random_doubles(void** state) {
  (void)state;
  for (long i = 0; i < DRAWS; ++i) {
    uint64_t bits = next_random();
    double x;
    memcpy(&x, &bits, sizeof x);
    if (isfinite(x)) check(x);
    check(2.0 * unit_random() - 1.0);
    check((unit_random() - 0.5) * pow(10.0, (double)(int)(next_random() % 41) - 20.0));
    // k/2^j for 16-digit k: the 18-digit exact values, half of them ties at the 17th digit
    double tie = (double)(int64_t)(next_random() % 9000000000000000ull) / (double)(1 << (next_random() % 4));
    char exact[64];
    snprintf(exact, sizeof exact, "%.40g", tie);
    if (strlen(exact) >= 18 && exact[17] == '5') ++ties;
    check(tie);
  }
  print_message("%d draws, %ld of them with an 18th significant digit 5; %ld differences from printf\n", 4 * DRAWS,
                ties, differences);
  assert_true(ties > 1000);  // the tie rule was exercised
  assert_int_equal(differences, 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_named_values),
      cmocka_unit_test(test_random_doubles),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
