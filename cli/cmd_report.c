// polydyn report — one self-contained HTML report of a gedanken / sweep / compare directory.
//
// The report is made by a Node.js script, reports/generator/report.mjs (it inlines Apache ECharts
// from its node_modules, installed by `npm ci --prefix reports/generator`). This command checks its
// arguments, finds the script and runs it with posix_spawnp — an argument vector, no shell, so any
// file name is passed as it is. The script reads and checks every input (a malformed file is
// `polydyn report: FILE:LINE: message` and exit status 2, before anything is written) and writes
// the page, report.json, report-*.csv and the replays' folder report-replays/, each under a temporary
// name renamed when complete.
//
// Where the script is: $PD_REPORT_GENERATOR when set, else PD_SOURCE_DIR/reports/generator/report.mjs
// (PD_SOURCE_DIR is the source tree this binary was built from, a compile definition). Which node:
// $PD_NODE when set, else `node` on the PATH.
#include <errno.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"

extern char** environ;

#ifndef PD_SOURCE_DIR
#error "PD_SOURCE_DIR (the source tree, where reports/generator/report.mjs is) must be defined"
#endif

static const char* const help =
    "usage: polydyn report DIR [-o FILE] [--viewer FILE | --no-viewer]\n"
    "\n"
    "Writes one self-contained HTML report of DIR (what polydyn gedanken, sweep, compare and cubetoss\n"
    "wrote there: no network needed to view it), with the numbers it shows as JSON and CSV beside it.\n"
    "Each section appears when its inputs are in DIR:\n"
    "  results.csv, experiments.json  verdict, PASS/FAIL matrix, restitution table, friction cone,\n"
    "                                 cost, one block per experiment\n"
    "  series/EXPERIMENT.csv          each experiment's quantity over time against the analytic line\n"
    "  runs/*/*/summary.json          the parameters every engine actually used\n"
    "  sweep.csv                      work-precision diagrams, cost to reach error 1e-3\n"
    "  metrics.csv                    comparison metrics of polydyn compare\n"
    "  cubetoss/summary.csv           cube tosses against reality (per_toss.csv, fit.csv and the typical\n"
    "                                 toss's run directories beside it); DIR may itself be a directory\n"
    "                                 of polydyn cubetoss\n"
    "\n"
    "  -o FILE         the page (default DIR/report.html); FILE.json (FILE without .html) and\n"
    "                  FILE-TABLE.csv are written beside it\n"
    "  --viewer FILE   inline this replay bundle once and add a 3-D replay of each run (default:\n"
    "                  viewer/dist/viewer.js of the source tree, when it exists); each replay's data\n"
    "                  is a file of FILE-replays/ (FILE without .html), loaded when its block is\n"
    "                  opened: keep that folder beside the page\n"
    "  --no-viewer     no replays\n"
    "\n"
    "Needs Node.js and `npm ci --prefix reports/generator` (scripts/setup does it). Exit status:\n"
    "0 written, 1 failure, 2 bad input (`FILE:LINE: message`, nothing written), 130 interrupted.\n";

// the generator script: $PD_REPORT_GENERATOR or the one in the source tree
static const char* generator_path(void) {
  const char* env = getenv("PD_REPORT_GENERATOR");
  if (env && *env) return env;
  return PD_SOURCE_DIR "/reports/generator/report.mjs";
}

// The generator's process while it runs, and the interrupt received (forwarded to it).
static volatile pid_t child = 0;
static volatile sig_atomic_t forwarded = 0;
static void forward_signal(int sig) {
  forwarded = sig;
  if (child > 0) kill(child, sig);
}

int pd_cmd_report(int argc, char** argv) {
  const char* dir = NULL;
  const char* out = NULL;
  const char* viewer = NULL;
  bool noViewer = false;
  const pdCliOption table[] = {
      {.name = "-o", .kind = pd_optText, .target = &out},
      {.name = "--out", .kind = pd_optText, .target = &out},
      {.name = "--viewer", .kind = pd_optText, .target = &viewer},
      {.name = "--no-viewer", .kind = pd_optFlag, .target = &noViewer},
  };
  pdCliPositionals dirs = {.values = &dir, .max = 1, .tooMany = "one directory expected, got '%s' and '%s'"};
  int parsed = pd_cli_parse_options("report", argc, argv, table, sizeof table / sizeof table[0], &dirs, help);
  if (parsed >= 0) return parsed;
  if (!dir) return pd_cli_usage_error("report", "DIR is missing");
  if (viewer && noViewer) return pd_cli_usage_error("report", "--viewer and --no-viewer exclude each other");
  if (pd_cli_parse_only) return PD_EXIT_OK;

  // the directory: checked here too, so that a typo does not wait for node to start
  struct stat st;
  if (stat(dir, &st) != 0) {
    fprintf(stderr, "polydyn report: %s: no such directory\n", dir);
    return PD_EXIT_BAD_INPUT;
  }
  if (!S_ISDIR(st.st_mode)) {
    fprintf(stderr, "polydyn report: %s: not a directory\n", dir);
    return PD_EXIT_BAD_INPUT;
  }

  const char* script = generator_path();
  if (access(script, R_OK) != 0) {
    fprintf(stderr,
            "polydyn report: the report generator %s is not there (%s); set PD_REPORT_GENERATOR to "
            "reports/generator/report.mjs of a polydyn source tree\n",
            script, strerror(errno));
    return PD_EXIT_FAILURE;
  }
  const char* node = getenv("PD_NODE");
  if (!node || !*node) node = "node";

  // node SCRIPT DIR [-o FILE] [--viewer FILE | --no-viewer]
  char* args[9];
  int n = 0;
  args[n++] = (char*)node;
  args[n++] = (char*)script;
  args[n++] = (char*)dir;
  if (out) {
    args[n++] = "-o";
    args[n++] = (char*)out;
  }
  if (viewer) {
    args[n++] = "--viewer";
    args[n++] = (char*)viewer;
  } else if (noViewer) {
    args[n++] = "--no-viewer";
  }
  args[n] = NULL;

  // like system(), but an interrupt sent to this process alone (kill PID) reaches the child too: the child
  // gets SIGINT/SIGTERM, cleans up its temporary files and exits 130; this process waits for it instead of
  // dying first and leaving it writing
  struct sigaction forward = {0}, ignore = {0}, oldInt, oldTerm, oldQuit;
  forward.sa_handler = forward_signal;
  sigemptyset(&forward.sa_mask);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGINT, &forward, &oldInt);
  sigaction(SIGTERM, &forward, &oldTerm);
  sigaction(SIGQUIT, &ignore, &oldQuit);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGQUIT);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);

  pid_t pid;
  int rc = posix_spawnp(&pid, node, NULL, &attr, args, environ);
  posix_spawnattr_destroy(&attr);
  int status = 0;
  if (rc == 0) {
    child = pid;
    if (forwarded) kill(pid, forwarded);  // a signal that came while spawning
    while (waitpid(pid, &status, 0) < 0) {
      if (errno != EINTR) {
        rc = errno;
        break;
      }
    }
  }
  child = 0;
  sigaction(SIGINT, &oldInt, NULL);
  sigaction(SIGTERM, &oldTerm, NULL);
  sigaction(SIGQUIT, &oldQuit, NULL);

  if (rc != 0) {
    fprintf(stderr, "polydyn report: cannot run %s (%s): the report needs Node.js 20 or later (scripts/install-deps)\n",
            node, strerror(rc));
    return PD_EXIT_FAILURE;
  }
  bool stopped = WIFSIGNALED(status) && (WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM);
  if (stopped || (WIFEXITED(status) && WEXITSTATUS(status) == 130)) {
    fprintf(stderr, "polydyn report: interrupted; nothing written\n");
    return 130;
  }
  if (!WIFEXITED(status)) return PD_EXIT_FAILURE;
  int code = WEXITSTATUS(status);
  // the generator's own statuses pass through; anything else (node itself failing) is a failure
  if (code == PD_EXIT_OK || code == PD_EXIT_FAILURE || code == PD_EXIT_BAD_INPUT || code == 130) return code;
  fprintf(stderr, "polydyn report: %s exited with status %d\n", node, code);
  return PD_EXIT_FAILURE;
}
