// polydyn — errors of bad input: a location and a one-line message in fixed buffers.
#include "polydyn/error.h"
#include "why.h"

#include <stdarg.h>
#include <string.h>

// Copies at most size - 1 bytes of src and terminates; src may alias dst (memmove).
static void copy_truncated(char* dst, size_t size, const char* src) {
  size_t n = strlen(src);
  if (n >= size) n = size - 1;
  memmove(dst, src, n);
  dst[n] = '\0';
}

void pd_error_set(pdError* err, const char* file, int line, int col, const char* fmt, ...) {
  if (!err || !fmt) return;
  // format into a local buffer first: the arguments may point into err itself
  char message[PD_ERROR_MESSAGE_MAX];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  if (n < 0) {
    copy_truncated(message, sizeof message, "(unprintable error message)");
  } else if ((size_t)n >= sizeof message) {
    memcpy(message + sizeof message - 4, "...", 4);  // mark the cut
  }
  // one line: a stray control byte would break `FILE:LINE:COL: message` consumers
  for (char* c = message; *c; ++c) {
    if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = ' ';
  }
  copy_truncated(err->file, sizeof err->file, file ? file : "");
  copy_truncated(err->message, sizeof err->message, message);
  err->line = line > 0 ? line : 0;
  err->col = col > 0 ? col : 0;
}

void pd_error_print(const pdError* err, FILE* out) {
  PD_ASSERT(err != NULL && out != NULL);
  const char* sep = err->file[0] ? ":" : "";
  if (err->line <= 0) {
    if (err->file[0]) {
      fprintf(out, "%s: %s\n", err->file, err->message);
    } else {
      fprintf(out, "%s\n", err->message);
    }
  } else if (err->col <= 0) {
    fprintf(out, "%s%s%d: %s\n", err->file, sep, err->line, err->message);
  } else {
    fprintf(out, "%s%s%d:%d: %s\n", err->file, sep, err->line, err->col, err->message);
  }
}

void pd_why(char* why, int whySize, const char* fmt, ...) {
  if (!why || whySize <= 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(why, (size_t)whySize, fmt, ap);
  va_end(ap);
}

static void assert_default(const char* expression, const char* file, int line) {
  fprintf(stderr, "%s:%d: polydyn API misuse: assertion `%s` failed\n", file, line, expression);
  abort();
}

static pdAssertFcn* assertFcn = assert_default;

void pd_set_assert_fcn(pdAssertFcn* fcn) { assertFcn = fcn ? fcn : assert_default; }

void pd_assert_failed(const char* expression, const char* file, int line) {
  assertFcn(expression, file, line);
  abort();
}
