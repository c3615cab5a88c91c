// polydyn — errors of bad input, and the assertion used for misuse of the API.
//
// Three tiers (style-anchors §6.7):
// - misuse of the API by a programmer: PD_ASSERT, fatal;
// - numerical trouble during a run: counted warnings in pdState (see state.h), with a safe recovery;
// - bad input (scene files, CLI arguments): a pdError with `FILE:LINE:COL: message`, never an assert.
#pragma once

#include <stdio.h>
#include <stdlib.h>

#include "polydyn/api.h"

PD_EXTERN_C_BEGIN

enum { PD_ERROR_MESSAGE_MAX = 512 };

typedef struct pdError {
  char file[PD_ERROR_MESSAGE_MAX];     // file name as given by the caller ("" when none)
  int line;                            // 1-based; 0 when the problem has no line (e.g. cannot open)
  int col;                             // 1-based; 0 when unknown
  char message[PD_ERROR_MESSAGE_MAX];  // one line, no trailing newline
} pdError;

// Fills err (if not NULL) with a location (file "" or NULL when none; line, col 0 when unknown) and a
// printf-style message (one line: control characters become spaces; a message too long ends in "...").
PD_API void pd_error_set(pdError* err, const char* file, int line, int col, const char* fmt, ...)
    __attribute__((format(printf, 5, 6)));

// Writes `FILE:LINE:COL: message\n` (or `FILE: message` when the line is unknown) to `out`.
PD_API void pd_error_print(const pdError* err, FILE* out);

// The function PD_ASSERT calls when a check fails: `expression` is the condition's text, `file` and `line` where the
// check is (an engine/src file). A handler must not return: it reports, then aborts, exits or longjmps out (a test
// harness); if it returns, polydyn aborts anyway, since the code after a failed check relies on the condition.
typedef void pdAssertFcn(const char* expression, const char* file, int line);

// Installs the handler of failed checks for the whole process (NULL restores the default, which writes
// `FILE:LINE: polydyn API misuse: assertion `EXPRESSION` failed` to stderr and aborts). Not thread-safe: call it
// before any thread uses polydyn.
PD_API void pd_set_assert_fcn(pdAssertFcn* fcn);

// Calls the installed handler, then aborts should it return (PD_ASSERT's failure path).
PD_API PD_NORETURN void pd_assert_failed(const char* expression, const char* file, int line);

#define PD_ASSERT(cond)                                \
  do {                                                 \
    if (!(cond)) pd_assert_failed(#cond, __FILE__, __LINE__); \
  } while (0)

PD_EXTERN_C_END
