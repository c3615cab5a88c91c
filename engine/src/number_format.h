// polydyn — numbers in the outputs: exactly the text of printf's "%.17g", several times faster.
//
// Every number polydyn writes (trajectory.csv, contacts.csv, summary.json) is printed with 17 significant
// digits, so it reads back to the same double. glibc's printf forms it by multi-precision arithmetic,
// which made writing the samples up to 40 % of a run (reports/bench/cost.md, the 10-box stack at 1000
// samples/s). pd_format_g17 calls the C++ library's std::to_chars in general format with
// precision 17, which the standard defines as printf's %.17g text in the "C" locale (libstdc++ 11 and
// later implement it with Ryu printf: exact, in about a third of printf's time on the stack's numbers and
// half that of the double-conversion library's digits). tests/engine/test_number_format.c
// compares it with snprintf on millions of doubles, ties included.
#pragma once

#ifdef __cplusplus
extern "C" {
#endif

// The longest text: "-1.2345678901234567e-308" is 24 characters and the terminating NUL.
#define PD_G17_MAX 32

// Writes finite x as printf("%.17g", x) would into out (at least PD_G17_MAX bytes, NUL-terminated) and
// returns the length. x must be finite (asserted by the caller's contract: the engine never writes
// a non-finite number).
int pd_format_g17(double x, char* out);

#ifdef __cplusplus
}
#endif
