// polydyn run — simulate a scene and write its run directory (docs/outputs.md).
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdutil/files.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "polydyn/state.h"

// The help in two literals (each within the 4095 characters C requires a compiler to take), joined in pd_cmd_run.
static const char helpHead[] =
    "usage: polydyn run SCENE [--out DIR] [--engine soft|ode|bullet] [--tend T] [--sample HZ] [--tol E]\n"
    "                         [--stepper implicit|adaptive|fixed|embedded|dopri]\n"
    "                         [--variant native|matched]\n"
    "                         [--events bounded|exact|held] [--onsets pair|exact|auto|bounded] [--islands on|off]\n"
    "                         [--sleep on|off] [--threads N] [--step H] [--ode-friction pyramid|aligned]\n"
    "\n"
    "Simulates SCENE and writes DIR/trajectory.csv and DIR/summary.json. DIR is written under a\n"
    "temporary name and renamed when complete; an existing run directory DIR is replaced.\n"
    "\n"
    "  --out DIR        run directory (default: out/NAME, NAME = scene file name without extension)\n"
    "  --engine NAME    soft: polydyn's soft-contact engine (default); ode, bullet: the same model in\n"
    "                   a reference engine (docs/validation.md)\n"
    "  --tend T         simulated seconds, overrides the scene's tend\n"
    "  --sample HZ      output samples per second, overrides the scene's sample\n"
    "  --tol E          soft engine: the integration tolerance, 0 < E < 1, overrides the scene's tol\n"
    "                   (its largest step and event shares follow it; docs/integration.md)\n"
    "  --stepper NAME   implicit (default): RK4 with step-doubling error control, switching island by\n"
    "                   island to a linearly implicit method (ROS34PW2) where the contacts' stability\n"
    "                   bound holds RK4 to a fraction of the steps its error allows: resting and\n"
    "                   sliding contact, islands of up to 32 bodies (docs/integration.md);\n"
    "                   adaptive: RK4 with step-doubling error control alone (the paper's);\n"
    "                   fixed: RK4 with the scene's dt (or --step), no error control; warns on\n"
    "                   stderr when the step exceeds RK4's stability bound for the scene's stiffest\n"
    "                   contact, omega h <= " PD_STABLE_STEP_OMEGA_TEXT " (docs/integration.md), and runs anyway;\n"
    "                   embedded: RK4 with its embedded third-order error estimate; dopri: DOPRI5(4);\n"
    "                   implicit-dopri: implicit with DOPRI5(4) for step doubling\n"
    ;
static const char helpTail[] =
    "  --events MODE    soft engine: bounded (default) corrects a contact onset inside a step where its\n"
    "                   error bound is within the tolerance's share and locates the others; exact locates\n"
    "                   every onset, the paper's loop (docs/events.md; the same as --onsets bounded|exact);\n"
    "                   held as bounded with each contact's modes held within a step (docs/events.md)\n"
    "  --onsets MODE    soft engine, a contact that began inside a step: exact cuts the whole step back\n"
    "                   to its onset; pair joins it at the step's end, run for that pair alone since its\n"
    "                   onset, when it began within 1/omega and is shallow; auto pair in an island of more\n"
    "                   than 16 moving bodies, exact in smaller ones; bounded (default) as --events bounded\n"
    "                   (docs/events.md)\n"
    "  --islands on|off soft engine: on (default) splits the bodies between output samples into islands\n"
    "                   (bodies in contact or whose boxes may meet before the next sample), each with its\n"
    "                   own steps and contact events; off advances all bodies with one step size\n"
    "                   (docs/integration.md)\n"
    "  --sleep on|off   soft engine with islands on: on (the scene's `sleep`, default on) stops integrating\n"
    "                   an island whose bodies stayed at rest for a few periods of its slowest contact\n"
    "                   until a moving body may reach it or an applied force changes; off integrates every\n"
    "                   island to the end (docs/sleeping.md)\n"
    "  --threads N      soft engine with islands on: advance the islands on N threads, 1..64 (default 1),\n"
    "                   a thread without an island helping a big one with its loops over contacts;\n"
    "                   every contact's numbers are the same on any thread, so the outputs are\n"
    "                   bit-identical for every N\n"
    "  --variant NAME   ode, bullet: native (the engine's own hard contact, default) or matched (its\n"
    "                   soft contact set to polydyn's k and c)\n"
    "  --step H         the fixed step, s: ode, bullet (default 1e-3); soft with --stepper fixed\n"
    "                   (default: the scene's dt)\n"
    "  --ode-friction F ode: pyramid (ODE's Approx1 box, default) or aligned (fdir1 along the slip)\n"
    "\n"
    "Progress goes to stderr when it is a terminal. Exit status: 0 ok, 1 the run failed numerically\n"
    "(the run directory is written, marked incomplete), 2 bad input, 130 interrupted (nothing written).\n";

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}


typedef struct runObserver {
  pdRunWriter* writer;
  bool progress;
  double lastPrint;
} runObserver;

// Progress on a terminal and the interrupt flag; used alone by the reference engines, whose driver
// writes the samples itself.
static bool observe_progress(const pdModel* model, const pdState* state, void* user) {
  runObserver* o = user;
  if (o->progress) {
    double now = pd_cli_wall_seconds();
    if (now - o->lastPrint > 0.5) {
      fprintf(stderr, "\rpolydyn run: t = %.4g / %.4g s", state->t, model->settings.tend);
      o->lastPrint = now;
    }
  }
  return !interrupted;
}

static bool observe(const pdModel* model, const pdState* state, void* user) {
  runObserver* o = user;
  if (!pd_run_observe(model, state, o->writer)) return false;
  return observe_progress(model, state, user);
}


// --engine: soft, or a reference engine this build has an adapter for.
static bool accept_engine(const char* cmd, const char* v, void* target) {
  if (strcmp(v, "soft") != 0 && strcmp(v, "ode") != 0 && strcmp(v, "bullet") != 0) {
    pd_cli_usage_error(cmd, "--engine must be soft, ode or bullet, not '%s'", v);
    return false;
  }
  if (strcmp(v, "soft") != 0 && !pd_ref_adapter(v)) {
    pd_cli_usage_error(cmd, "--engine %s: this build of polydyn has no %s adapter", v, v);
    return false;
  }
  *(const char**)target = v;
  return true;
}

static bool accept_events(const char* cmd, const char* v, void* target) {
  if (pd_cli_events(v, target)) return true;
  pd_cli_usage_error(cmd, "--events must be bounded, exact or held");
  return false;
}

// The fixed stepper has no error control to shorten a step that is unstable for the stiffest contact: such a run
// may still finish (contacts that never come together), so it runs, but the user is told the bound.
static void warn_fixed_step(const pdModel* model) {
  double bound = pd_model_fixed_step_max(model);
  if (!(model->settings.dt > bound)) return;  // within the bound, nothing can touch, or the bound is unknown (NAN)
  fprintf(stderr,
          "polydyn run: warning: the fixed step %.6g s exceeds RK4's stability bound %.6g s for the scene's stiffest "
          "contact (omega h <= " PD_STABLE_STEP_OMEGA_TEXT "); the run may stop with non-finite steps: use --step H with H <= %.6g s "
          "(docs/integration.md)\n",
          model->settings.dt, bound, bound);
}

static const char* const onOff[] = {"on", "off", NULL};
static const char* const stepperWords[] = {"adaptive", "fixed", "embedded", "implicit", "dopri", "implicit-dopri", NULL};
static const int stepperValues[] = {pd_stepperRK4Adaptive, pd_stepperRK4Fixed, pd_stepperRK43Embedded,
                                    pd_stepperImplicit, pd_stepperDopri54, pd_stepperImplicitDopri};
static const int islandsValues[] = {pd_islandsOn, pd_islandsOff};
static const int sleepValues[] = {1, -1};  // pdCliOverrides.sleep
static const char* const variantWords[] = {"native", "matched", NULL};
static const int variantValues[] = {pd_refNative, pd_refMatched};
static const char* const frictionWords[] = {"pyramid", "aligned", NULL};
static const int frictionValues[] = {pd_odeFrictionPyramid, pd_odeFrictionAligned};

int pd_cmd_run(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  const char* engine = "soft";
  pdCliOverrides overrides = {0};
  int stepper = PD_STEPPER_DEFAULT;
  pdRefOptions ref = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
  int variant = ref.variant, odeFriction = ref.odeFriction;
  pdOnsets onsets = PD_ONSETS_DEFAULT;
  int islands = PD_ISLANDS_DEFAULT;
  int threads = 1;  // one unless asked: a run's CPU time stays its own, and batch commands fill the cores
  bool refOptionGiven = false, softOptionGiven = false, stepGiven = false;
  char threadsMessage[64];
  snprintf(threadsMessage, sizeof threadsMessage, "--threads needs a whole number 1..%d", PD_THREADS_MAX);
  char help[sizeof helpHead + sizeof helpTail];
  snprintf(help, sizeof help, "%s%s", helpHead, helpTail);
  const pdCliOption table[] = {
      {.name = "--out", .kind = pd_optText, .target = &out, .message = "--out needs a directory name", .min = 1},
      {.name = "--engine", .kind = pd_optAccept, .target = &engine, .accept = accept_engine},
      {.name = "--tend", .kind = pd_optPositive, .target = &overrides.tend, .message = "--tend needs a number > 0"},
      {.name = "--sample", .kind = pd_optPositive, .target = &overrides.sample,
       .message = "--sample needs a number > 0"},
      {.name = "--tol", .kind = pd_optAccept, .target = &overrides.tol, .accept = pd_cli_accept_tol,
       .given = &softOptionGiven},
      {.name = "--stepper", .kind = pd_optChoice, .target = &stepper,
       .message = "--stepper must be adaptive, fixed, embedded, implicit, dopri or implicit-dopri", .words = stepperWords,
       .values = stepperValues, .given = &softOptionGiven},
      {.name = "--onsets", .kind = pd_optAccept, .target = &onsets, .accept = pd_cli_accept_onsets, .given = &softOptionGiven},
      {.name = "--events", .kind = pd_optAccept, .target = &onsets, .accept = accept_events, .given = &softOptionGiven},
      {.name = "--islands", .kind = pd_optChoice, .target = &islands,
       .message = "--islands must be on or off, not '%s'", .words = onOff, .values = islandsValues,
       .given = &softOptionGiven},
      {.name = "--sleep", .kind = pd_optChoice, .target = &overrides.sleep,
       .message = "--sleep must be on or off, not '%s'", .words = onOff, .values = sleepValues,
       .given = &softOptionGiven},
      {.name = "--threads", .kind = pd_optJobs, .target = &threads, .message = threadsMessage, .max = PD_THREADS_MAX,
       .given = &softOptionGiven},
      {.name = "--variant", .kind = pd_optChoice, .target = &variant, .message = "--variant must be native or matched",
       .words = variantWords, .values = variantValues, .given = &refOptionGiven},
      {.name = "--step", .kind = pd_optPositive, .target = &ref.step, .message = "--step needs a number > 0",
       .given = &stepGiven},
      {.name = "--ode-friction", .kind = pd_optChoice, .target = &odeFriction,
       .message = "--ode-friction must be pyramid or aligned", .words = frictionWords, .values = frictionValues,
       .given = &refOptionGiven},
  };
  pdCliPositionals scenes = {.values = &scene, .max = 1, .tooMany = "one scene at a time ('%s' and '%s')"};
  int parsed = pd_cli_parse_options("run", argc, argv, table, sizeof table / sizeof table[0], &scenes, help);
  if (parsed >= 0) return parsed;
  ref.variant = (pdRefVariant)variant;
  ref.odeFriction = (pdOdeFriction)odeFriction;
  if (!scene) return pd_cli_usage_error("run", "no scene given");
  bool soft = strcmp(engine, "soft") == 0;
  if (soft && refOptionGiven)
    return pd_cli_usage_error("run", "--variant and --ode-friction are for --engine ode or bullet");
  if (soft && stepGiven && stepper != pd_stepperRK4Fixed)
    return pd_cli_usage_error("run", "--step is for --stepper fixed or --engine ode or bullet");
  if (soft && stepGiven) overrides.dt = ref.step;
  if (!soft && softOptionGiven)
    return pd_cli_usage_error("run",
                              "--tol, --stepper, --events, --onsets, --islands, --sleep and --threads are for the soft "
                              "engine");
  // islands off is one system on one thread: more threads would be silently idle
  if (threads > 1 && islands != pd_islandsOn) return pd_cli_usage_error("run", "--threads N > 1 needs --islands on");
  if (strcmp(engine, "bullet") == 0 && ref.odeFriction != pd_odeFrictionPyramid)
    return pd_cli_usage_error("run", "--ode-friction is for --engine ode");
  if (pd_cli_parse_only) return PD_EXIT_OK;

  pdModel* model = pd_cli_load_model(scene, &overrides, NULL);
  if (!model) return PD_EXIT_BAD_INPUT;

  char* defaultOut = NULL;
  if (!out) {
    defaultOut = pd_cli_default_out_dir(scene);
    out = defaultOut;
  }
  pdu_make_parents(out);
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

  if (!soft) {
    runObserver observer = {NULL, isatty(STDERR_FILENO) == 1, pd_cli_wall_seconds()};
    pdRefRunStats stats;
    bool ok = pd_ref_run(model, pd_ref_adapter(engine), &ref, writer, observe_progress, &observer, &stats, &err);
    if (observer.progress) fputs("\r\033[K", stderr);
    int status = PD_EXIT_OK;
    if (interrupted) {
      fprintf(stderr, "polydyn run: interrupted; nothing written\n");
      status = 130;
    } else if (!ok) {
      pd_error_print(&err, stderr);
      // a scene the engine cannot represent is bad input for that engine; a write failure is a failure
      status = stats.refused ? PD_EXIT_BAD_INPUT : PD_EXIT_FAILURE;
    } else if (!stats.completed) {
      fprintf(stderr, "polydyn run: %s stopped with a non-finite state after %ld steps; see %s/summary.json\n",
              engine, stats.steps, out);
      status = PD_EXIT_FAILURE;
    }
    pd_model_free(model);
    free(defaultOut);
    return status;
  }

  if (stepper == pd_stepperRK4Fixed) warn_fixed_step(model);
  pdStateOptions options = pd_state_options_default();
  options.stepper = stepper;
  options.onsets = onsets;
  options.islands = islands;
  options.threads = threads;
  pdState* state = pd_state_create(model, &options);
  runObserver observer = {writer, isatty(STDERR_FILENO) == 1, pd_cli_wall_seconds()};
  double energyStart = pd_state_energy(model, state);
  double t0 = pd_cli_wall_seconds();
  bool completed = pd_advance(model, state, model->settings.tend, observe, &observer);
  pd_run_drain(writer);  // the samples printed by the writer thread count too (engine/src/output.c)
  double wall = pd_cli_wall_seconds() - t0;
  if (observer.progress) fputs("\r\033[K", stderr);

  int status = PD_EXIT_OK;
  if (interrupted) {
    pd_run_abort(writer);
    fprintf(stderr, "polydyn run: interrupted at t = %.6g s; nothing written\n", state->t);
    status = 130;
  } else {
    pdRunInfo info = {.engine = "polydyn-soft", .energyStart = energyStart, .energyEnd = pd_state_energy(model, state), .wallSeconds = wall, .completed = completed};
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
