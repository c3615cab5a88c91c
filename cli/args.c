// polydyn — the command line's arguments: usage errors and the values the subcommands share (cli.h: numbers,
// --jobs, --onsets, --events, lists, help), the parse-only flag and the wall clock of progress displays.
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "pdrun/batch.h"
#include "pdutil/clock.h"

bool pd_cli_parse_only = false;

int pd_cli_usage_error(const char* subcommand, const char* fmt, ...) {
  if (!pd_batch_is_root()) return PD_EXIT_BAD_INPUT;
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "polydyn %s: ", subcommand);
  vfprintf(stderr, fmt, ap);
  fputs(" (see 'polydyn ", stderr);
  fputs(subcommand, stderr);
  fputs(" --help')\n", stderr);
  va_end(ap);
  return PD_EXIT_BAD_INPUT;
}

bool pd_cli_positive(const char* text, double* value) {
  char* end = NULL;
  errno = 0;
  double v = strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v) || !(v > 0.0)) return false;
  *value = v;
  return true;
}

double pd_cli_wall_seconds(void) { return pd_wall_seconds(); }

bool pd_cli_list_has(const char* list, const char* word) {
  size_t n = strlen(word);
  for (const char* p = list; p && *p;) {
    const char* comma = strchr(p, ',');
    size_t len = comma ? (size_t)(comma - p) : strlen(p);
    if (len == n && strncmp(p, word, n) == 0) return true;
    p = comma ? comma + 1 : NULL;
  }
  return false;
}

bool pd_cli_jobs(const char* text, int* jobs) {
  char* end = NULL;
  errno = 0;
  long n = strtol(text, &end, 10);
  if (end == text || *end != '\0' || errno || n < 1 || n > PD_CLI_MAX_JOBS) return false;
  *jobs = (int)n;
  return true;
}

bool pd_cli_onsets(const char* text, pdOnsets* onsets) {
  if (strcmp(text, "pair") == 0)
    *onsets = pd_onsetsPair;
  else if (strcmp(text, "exact") == 0)
    *onsets = pd_onsetsExact;
  else if (strcmp(text, "auto") == 0)
    *onsets = pd_onsetsAuto;
  else if (strcmp(text, "bounded") == 0)
    *onsets = pd_onsetsBounded;
  else
    return false;
  return true;
}

bool pd_cli_accept_tol(const char* cmd, const char* value, void* tol) {
  if (pd_cli_positive(value, tol) && *(double*)tol < 1.0) return true;
  pd_cli_usage_error(cmd, "--tol needs a number in (0, 1)");
  return false;
}

bool pd_cli_accept_onsets(const char* cmd, const char* value, void* onsets) {
  if (pd_cli_onsets(value, onsets)) return true;
  pd_cli_usage_error(cmd, "--onsets must be pair, exact, auto or bounded");
  return false;
}

bool pd_cli_events(const char* text, pdOnsets* onsets) {
  if (strcmp(text, "exact") == 0)
    *onsets = pd_onsetsExact;
  else if (strcmp(text, "bounded") == 0)
    *onsets = pd_onsetsBounded;
  else if (strcmp(text, "held") == 0)
    *onsets = pd_onsetsHeld;
  else
    return false;
  return true;
}

int pd_cli_default_jobs(int given, int serialDefault) {
  if (given > 0) return given;
  return pd_batch_ranks() > 1 ? 1 : serialDefault;
}

bool pd_cli_is_help(const char* arg) { return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0; }
