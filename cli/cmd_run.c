// polydyn run — simulate a scene and write its run directory (DESIGN §4.2).
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "polydyn/output.h"
#include "polydyn/state.h"

static const char* const help =
    "usage: polydyn run SCENE [--out DIR] [--engine soft] [--tend T] [--sample HZ]\n"
    "                         [--stepper adaptive|fixed]\n"
    "\n"
    "Simulates SCENE and writes DIR/trajectory.csv and DIR/summary.json. DIR is written under a\n"
    "temporary name and renamed when complete; an existing run directory DIR is replaced.\n"
    "\n"
    "  --out DIR        run directory (default: out/NAME, NAME = scene file name without extension)\n"
    "  --engine soft    the engine (only polydyn's own soft-contact engine in this version)\n"
    "  --tend T         simulated seconds, overrides the scene's tend\n"
    "  --sample HZ      output samples per second, overrides the scene's sample\n"
    "  --stepper NAME   adaptive: RK4 with step-doubling error control (default);\n"
    "                   fixed: RK4 with the scene's dt, no error control\n"
    "\n"
    "Progress goes to stderr when it is a terminal. Exit status: 0 ok, 1 the run failed numerically\n"
    "(the run directory is written, marked incomplete), 2 bad input, 130 interrupted (nothing written).\n";

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}

static double wall_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct runObserver {
  pdRunWriter* writer;
  bool progress;
  double lastPrint;
} runObserver;

static bool observe(const pdModel* model, const pdState* state, void* user) {
  runObserver* o = user;
  if (!pd_run_observe(model, state, o->writer)) return false;
  if (o->progress) {
    double now = wall_now();
    if (now - o->lastPrint > 0.5) {
      fprintf(stderr, "\rpolydyn run: t = %.4g / %.4g s", state->t, model->settings.tend);
      o->lastPrint = now;
    }
  }
  return !interrupted;
}

// mkdir -p of the directories above `path`; a real failure shows when the run directory is made
static void make_parents(const char* path) {
  char* p = strdup(path);
  if (!p) abort();
  for (char* slash = strchr(p + 1, '/'); slash; slash = strchr(slash + 1, '/')) {
    *slash = '\0';
    mkdir(p, 0777);
    *slash = '/';
  }
  free(p);
}

// out/NAME for scene path .../NAME.ext
static char* default_out_dir(const char* scene) {
  const char* base = strrchr(scene, '/');
  base = base ? base + 1 : scene;
  size_t n = strlen(base);
  const char* dot = strrchr(base, '.');
  if (dot && dot != base) n = (size_t)(dot - base);
  char* dir = malloc(n + 5);
  if (!dir) abort();
  snprintf(dir, n + 5, "out/%.*s", (int)n, base);
  return dir;
}

int pd_cmd_run(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  pdCliOverrides overrides = {0};
  pdStepper stepper = pd_stepperRK4Adaptive;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    bool hasValue = i + 1 < argc;
    if (pd_cli_is_help(a)) {
      fputs(help, stdout);
      return PD_EXIT_OK;
    } else if (strcmp(a, "--out") == 0 || strcmp(a, "--engine") == 0 || strcmp(a, "--tend") == 0 ||
               strcmp(a, "--sample") == 0 || strcmp(a, "--stepper") == 0) {
      if (!hasValue) return pd_cli_usage_error("run", "%s needs a value", a);
      const char* v = argv[++i];
      if (strcmp(a, "--out") == 0) {
        if (v[0] == '\0') return pd_cli_usage_error("run", "--out needs a directory name");
        out = v;
      } else if (strcmp(a, "--engine") == 0) {
        if (strcmp(v, "soft") != 0)
          return pd_cli_usage_error("run", "--engine '%s' is not available in this version (soft only)", v);
      } else if (strcmp(a, "--tend") == 0) {
        if (!pd_cli_positive(v, &overrides.tend)) return pd_cli_usage_error("run", "--tend needs a number > 0");
      } else if (strcmp(a, "--sample") == 0) {
        if (!pd_cli_positive(v, &overrides.sample)) return pd_cli_usage_error("run", "--sample needs a number > 0");
      } else if (strcmp(v, "adaptive") == 0) {
        stepper = pd_stepperRK4Adaptive;
      } else if (strcmp(v, "fixed") == 0) {
        stepper = pd_stepperRK4Fixed;
      } else {
        return pd_cli_usage_error("run", "--stepper must be adaptive or fixed");
      }
    } else if (a[0] == '-' && a[1] != '\0') {
      return pd_cli_usage_error("run", "unknown option '%s'", a);
    } else if (scene) {
      return pd_cli_usage_error("run", "one scene at a time ('%s' and '%s')", scene, a);
    } else {
      scene = a;
    }
  }
  if (!scene) return pd_cli_usage_error("run", "no scene given");

  pdModel* model = pd_cli_load_model(scene, &overrides, NULL);
  if (!model) return PD_EXIT_BAD_INPUT;

  char* defaultOut = NULL;
  if (!out) {
    defaultOut = default_out_dir(scene);
    out = defaultOut;
  }
  make_parents(out);
  // from here on an interrupt must remove the partial directory, so catch it before making one
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  pdError err = {0};
  pdRunWriter* writer = pd_run_open(out, &err);
  if (!writer) {
    pd_error_print(&err, stderr);
    free(defaultOut);
    pd_model_free(model);
    return PD_EXIT_BAD_INPUT;
  }

  pdState* state = pd_state_create(model);
  state->stepper = stepper;
  runObserver observer = {writer, isatty(STDERR_FILENO) == 1, wall_now()};
  double energyStart = pd_state_energy(model, state);
  double t0 = wall_now();
  bool completed = pd_advance(model, state, model->settings.tend, observe, &observer);
  double wall = wall_now() - t0;
  if (observer.progress) fputs("\r\033[K", stderr);

  int status = PD_EXIT_OK;
  if (interrupted) {
    pd_run_abort(writer);
    fprintf(stderr, "polydyn run: interrupted at t = %.6g s; nothing written\n", state->t);
    status = 130;
  } else {
    pdRunInfo info = {"polydyn-soft", energyStart, pd_state_energy(model, state), wall, completed};
    if (!pd_run_finish(writer, model, state, &info, &err)) {
      pd_error_print(&err, stderr);
      status = PD_EXIT_FAILURE;
    } else if (!completed) {
      fprintf(stderr, "polydyn run: the run stopped at t = %.6g s (%ld non-finite steps); see %s/summary.json\n",
              state->t, state->warnings[pd_warnNonFinite], out);
      status = PD_EXIT_FAILURE;
    }
  }
  pd_state_free(state);
  pd_model_free(model);
  free(defaultOut);
  return status;
}
