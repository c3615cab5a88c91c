// polydyn — the command line: the dispatch to the subcommands and the helpers they share (cli.h). main()
// is in main.c, so that the command-line fuzzer (tests/fuzz/fuzz_cli.c) can call pd_cli_dispatch.
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "polydyn/batch.h"

static const char* const usage =
    "usage: polydyn COMMAND [ARGS]\n"
    "\n"
    "Rigid convex polyhedra in frictional contact (Goyal, Pinson & Sinden 1994).\n"
    "\n"
    "commands:\n"
    "  run SCENE [--out DIR] [--tend T] [--sample HZ] [--stepper implicit|adaptive|fixed|embedded]\n"
    "                 simulate a scene, write trajectory.csv and summary.json into DIR\n"
    "  check SCENE    parse and compile a scene; print masses, inertias, polyhedra, settings\n"
    "  compare SCENE --out DIR [--engines soft,ode,bullet]\n"
    "                 run a scene in every engine, write DIR/metrics.csv against a tighter soft run\n"
    "  sweep SCENE --out DIR [--repeats R]\n"
    "                 work-precision: error against wall time over tolerances and step sizes\n"
    "  report DIR [-o FILE]\n"
    "                 one self-contained HTML report (+ JSON, CSV) of a gedanken/sweep/compare DIR\n"
    "  view DIR...    self-contained HTML replay of run directories (or --movie OUT.mp4)\n"
    "  cubetoss [fit] --data FILE.csv --out DIR [--engines soft,ode,bullet]\n"
    "                 real cube tosses in every engine against the record; fit each engine's parameters\n"
    "  oracle (SCENE | --random N --seed S | --replay FILE)  interference test vs libccd\n"
    "  soak --out DIR [--scenes N] [--seed S]             random scenes, invariants checked\n"
    "  help           this text\n"
    "  --version      print the version\n"
    "\n"
    "Every command takes --help. Exit status: 0 ok, 1 failure, 2 bad input.\n";

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

double pd_cli_wall_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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

int pd_cli_dispatch(int argc, char** argv) {
  if (argc < 2) {
    fputs(usage, stderr);
    return PD_EXIT_BAD_INPUT;
  }
  const char* cmd = argv[1];
  if (strcmp(cmd, "run") == 0) return pd_cmd_run(argc - 1, argv + 1);
  if (strcmp(cmd, "check") == 0) return pd_cmd_check(argc - 1, argv + 1);
  if (strcmp(cmd, "compare") == 0) return pd_cmd_compare(argc - 1, argv + 1);
  if (strcmp(cmd, "sweep") == 0) return pd_cmd_sweep(argc - 1, argv + 1);
  if (strcmp(cmd, "report") == 0) return pd_cmd_report(argc - 1, argv + 1);
  if (strcmp(cmd, "view") == 0) return pd_cmd_view(argc - 1, argv + 1);
  if (strcmp(cmd, "cubetoss") == 0) return pd_cmd_cubetoss(argc - 1, argv + 1);
  if (strcmp(cmd, "gedanken") == 0) return pd_cmd_gedanken(argc - 1, argv + 1);
  if (strcmp(cmd, "oracle") == 0) return pd_cmd_oracle(argc - 1, argv + 1);
  if (strcmp(cmd, "soak") == 0) return pd_cmd_soak(argc - 1, argv + 1);
  if (strcmp(cmd, "help") == 0 || pd_cli_is_help(cmd)) {
    fputs(usage, stdout);
    return PD_EXIT_OK;
  }
  if (strcmp(cmd, "--version") == 0) {
    printf("polydyn %s\n", PD_VERSION);
    return PD_EXIT_OK;
  }
  fprintf(stderr, "polydyn: unknown command '%s'\n\n%s", cmd, usage);
  return PD_EXIT_BAD_INPUT;
}
