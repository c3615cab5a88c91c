// polydyn gedanken — run the catalogue of Gedanken experiments on every engine (gedanken/RESULT_SCHEMAS.md).
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdrun/batch.h"
#include "pdgk/gedanken.h"

#define PD_GK_TEXT_OF(x) #x
#define PD_GK_TEXT(x) PD_GK_TEXT_OF(x)

static const char* const help =
    "usage: polydyn gedanken --out DIR [--only NAME[,NAME...]] [--engines ENGINE[,ENGINE...]] [--fast]\n"
    "                        [--jobs N] [--tolerance-scale F] [--precision [--repeats R]]\n"
    "       polydyn gedanken --list [--fast]\n"
    "\n"
    "Runs the Gedanken experiments (closed-form mechanics: restitution, sinkage, friction, impacts, rolling,\n"
    "Painleve's rod, a top, stacks) on each engine and compares every measured value with its expected value\n"
    "and tolerance. Writes DIR/results.csv, DIR/experiments.json, DIR/series/NAME.csv and every run's\n"
    "directory DIR/runs/NAME/ENGINE-VARIANT[-INPUT]/ (with the generated scene as scene.scene). DIR is written\n"
    "under a temporary name and renamed when complete; an existing DIR is replaced only if it is a previous\n"
    "gedanken directory.\n"
    "\n"
    "  --out DIR            output directory\n"
    "  --list               list the experiments (name, group, title, inputs) and exit\n"
    "  --only NAMES         only these experiments (comma-separated names from --list)\n"
    "  --engines ENGINES    soft, ode, bullet (default: all three); ode and bullet run in their native and\n"
    "                       matched variants; an engine this build has no adapter for gives NOT_BUILT rows\n"
    "  --fast               only the fast subset that CI runs\n"
    "  --jobs N             runs in N worker processes (default 2; 1 per rank under mpirun or srun, where the\n"
    "                       runs are split over the ranks: docs/commands.md); the files are the same bytes\n"
    "                       whatever N, except the measured wall times\n"
    "  --tolerance-scale F  multiply every tolerance by F > 0 (default 1: the catalogue's); only to check that\n"
    "                       failures are reported, the verdicts are then not the catalogue's\n"
    "  --precision          also work-precision against the closed form: every quantitative experiment, on its\n"
    "                       middle input, at soft tol 1e-1 ... 1e-10 and fixed-step RK4 dt 1e-3 ... 1e-5 s, ODE\n"
    "                       and Bullet (native, matched) at steps 1/60 ... 1/16000 s, Bullet also at 5 ... 200\n"
    "                       solver iterations; writes DIR/precision.csv\n"
    "                       (error against the closed form and cost per point)\n"
    "  --repeats R          with --precision: timings per point (default 4, at most 21), each the run repeated\n"
    "                       back to back to " PD_GK_TEXT(PD_GK_TIMING_MIN_CPU_SECONDS) " s of CPU time; the cost is the least\n"
    "                       (precision.csv also has their median and spread); the error is the first run's:\n"
    "                       every run is deterministic\n"
    "\n"
    "Progress goes to stderr when it is a terminal. Exit status: 0 every soft-engine experiment passed (other\n"
    "engines may fail some: see results.csv), 1 a soft-engine experiment failed or the results could not be\n"
    "written, 2 bad input, 130 interrupted (nothing written).\n";

// The speed-accuracy protocol's "minimum of at least 4 runs" (docs/validation.md, "The cost of a point").
enum { MAX_ONLY = 64, MAX_REPEATS = 21, DEFAULT_REPEATS = 4 };

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}

static void progress(const pdGkProgress* p, void* user) {
  (void)user;
  fprintf(stderr, "\r\033[Kpolydyn gedanken: %d/%d %s %s%s%s", p->done, p->total, p->experiment, p->engine,
          p->input[0] ? " " : "", p->input);
}

static void list(bool fast) {
  for (int i = 0; i < pd_gk_experiment_count(); ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    if (fast && !e->fast) continue;
    printf("%-24s %c  %s%s", e->name, e->group, e->title, e->fast ? "  [fast]" : "");
    if (e->inputName) {
      printf("  (%s:", e->inputName);
      for (int k = 0; k < e->inputCount; ++k) printf(" %g", e->inputs[k]);
      putchar(')');
    }
    putchar('\n');
  }
}

// Splits a comma-separated list in place into `items` (at most max); false on an empty item or too many.
static int split(char* text, char** items, int max) {
  int count = 0;
  for (char* item = text;; ++count) {
    char* comma = strchr(item, ',');
    if (comma) *comma = '\0';
    if (item[0] == '\0' || count == max) return -1;
    items[count] = item;
    if (!comma) return count + 1;
    item = comma + 1;
  }
}

// --only: once, a comma-separated list kept as written (split once the other options are read).
static bool accept_only(const char* cmd, const char* v, void* target) {
  char** onlyText = target;
  if (*onlyText) {
    pd_cli_usage_error(cmd, "--only once, with a comma-separated list");
    return false;
  }
  *onlyText = (char*)v;  // a string of argv: split in place
  return true;
}

// --engines: once, a comma-separated list of the engines to run (split in place in argv).
typedef struct enginesChoice {
  bool given;
  bool* engines;  // (pd_gkEngineCount) pdGkOptions.engines
} enginesChoice;

static bool accept_engines(const char* cmd, const char* v, void* target) {
  enginesChoice* c = target;
  if (c->given) {
    pd_cli_usage_error(cmd, "--engines once, with a comma-separated list");
    return false;
  }
  c->given = true;
  char* names[pd_gkEngineCount * 2];
  int count = split((char*)v, names, pd_gkEngineCount * 2);
  if (count < 0) {
    pd_cli_usage_error(cmd, "--engines needs a list like soft,ode,bullet");
    return false;
  }
  for (int k = 0; k < count; ++k) {
    pdGkEngine e;
    if (!pd_gk_engine_named(names[k], &e)) {
      pd_cli_usage_error(cmd, "unknown engine '%s' (soft, ode or bullet)", names[k]);
      return false;
    }
    c->engines[e] = true;
  }
  return true;
}

int pd_cmd_gedanken(int argc, char** argv) {
  pdGkOptions options = {.toleranceScale = 1.0};
  bool listOnly = false;
  char* onlyText = NULL;
  char* onlyNames[MAX_ONLY];
  enginesChoice engines = {false, options.engines};
  long repeats = 0;
  char jobsMessage[64], repeatsMessage[64];
  snprintf(jobsMessage, sizeof jobsMessage, "--jobs needs a whole number from 1 to %d", PD_CLI_MAX_JOBS);
  snprintf(repeatsMessage, sizeof repeatsMessage, "--repeats needs a whole number from 1 to %d", MAX_REPEATS);
  const pdCliOption table[] = {
      {.name = "--list", .kind = pd_optFlag, .target = &listOnly},
      {.name = "--fast", .kind = pd_optFlag, .target = &options.fast},
      {.name = "--precision", .kind = pd_optFlag, .target = &options.precision},
      {.name = "--out", .kind = pd_optText, .target = &options.out, .message = "--out needs a directory name",
       .min = 1},
      {.name = "--only", .kind = pd_optAccept, .target = &onlyText, .accept = accept_only},
      {.name = "--engines", .kind = pd_optAccept, .target = &engines, .accept = accept_engines},
      {.name = "--jobs", .kind = pd_optJobs, .target = &options.jobs, .message = jobsMessage},
      {.name = "--tolerance-scale", .kind = pd_optPositive, .target = &options.toleranceScale,
       .message = "--tolerance-scale needs a number > 0"},
      {.name = "--repeats", .kind = pd_optWhole, .target = &repeats, .message = repeatsMessage, .min = 1,
       .max = MAX_REPEATS},
  };
  // no positional argument: anything else is refused, whether or not it starts with '-'
  pdCliPositionals none = {.tooMany = "unknown argument '%s'", .unknownOption = "unknown argument '%s'"};
  int parsed = pd_cli_parse_options("gedanken", argc, argv, table, sizeof table / sizeof table[0], &none, help);
  if (parsed >= 0) return parsed;
  options.repeats = (int)repeats;
  bool enginesGiven = engines.given;
  options.jobs = pd_cli_default_jobs(options.jobs, 2);
  if (options.repeats && !options.precision) return pd_cli_usage_error("gedanken", "--repeats goes with --precision");
  if (!options.repeats) options.repeats = DEFAULT_REPEATS;
  if (listOnly) {
    list(options.fast);
    return PD_EXIT_OK;
  }
  if (!options.out) return pd_cli_usage_error("gedanken", "--out DIR is required");
  if (onlyText) {
    int count = split(onlyText, onlyNames, MAX_ONLY);
    if (count < 0) return pd_cli_usage_error("gedanken", "--only needs a comma-separated list of names");
    for (int k = 0; k < count; ++k)
      if (!pd_gk_find(onlyNames[k]))
        return pd_cli_usage_error("gedanken", "no experiment '%s' (see --list)", onlyNames[k]);
    options.only = (const char* const*)onlyNames;
    options.onlyCount = count;
  }
  if (pd_gk_selected_count(&options) == 0)
    return pd_cli_usage_error("gedanken", "no experiment selected (--only names none of the --fast subset)");
  if (!enginesGiven)
    for (int e = 0; e < pd_gkEngineCount; ++e) options.engines[e] = true;
  if (pd_cli_parse_only) return PD_EXIT_OK;
  pdError err = {0};
  if (!pd_gk_out_replaceable(options.out, &err)) {
    fprintf(stderr, "polydyn gedanken: ");
    pd_error_print(&err, stderr);
    return PD_EXIT_BAD_INPUT;
  }

  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  options.interrupt = &interrupted;
  bool terminal = isatty(STDERR_FILENO) == 1;
  if (terminal) options.progress = progress;

  pdGkSummary summary;
  bool ok = pd_gk_run_suite(&options, &summary, &err);
  if (terminal) fputs("\r\033[K", stderr);
  if (summary.interrupted) {
    fprintf(stderr, "polydyn gedanken: interrupted; nothing written\n");
    return 130;
  }
  if (!ok) {
    if (pd_batch_is_root()) {
      fprintf(stderr, "polydyn gedanken: ");
      pd_error_print(&err, stderr);
    }
    return PD_EXIT_FAILURE;
  }
  printf("polydyn gedanken: %d rows in %.1f s:", summary.rows, summary.wallSeconds);
  for (int s = 0; s < pd_gkStatusCount; ++s)
    if (summary.count[s]) printf(" %d %s", summary.count[s], pdGkStatusNames[s]);
  printf("; %s/results.csv\n", options.out);
  if (summary.softFailures > 0) {
    if (pd_batch_is_root())  // MPI: every rank has the rows; rank 0 says it
      fprintf(stderr, "polydyn gedanken: %d soft-engine row%s failed: %s\n", summary.softFailures,
            summary.softFailures > 1 ? "s" : "", summary.softFailed);
    return PD_EXIT_FAILURE;
  }
  return PD_EXIT_OK;
}
