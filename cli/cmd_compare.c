// polydyn compare — one scene in every engine, metrics against a tighter soft run (DESIGN §5).
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "polydyn/compare.h"
#include "polydyn/output.h"
#include "polydyn/refcheck.h"
#include "polydyn/state.h"

// The reference run's tolerance over the scene's: DESIGN §5 ("our own run at a 100× tighter tolerance").
#define COMPARE_REFERENCE_TOL_SCALE 0.01
// Longest --out path: the run directories' paths below it fit the fixed buffers.
#define COMPARE_PATH_MAX 3000

static const char* const help =
    "usage: polydyn compare SCENE --out DIR [--engines soft,ode,bullet] [--variants native,matched]\n"
    "                             [--step H] [--tend T] [--sample HZ]\n"
    "\n"
    "Runs SCENE in polydyn's soft engine and in the reference engines (each variant), and a reference run\n"
    "of the soft engine at a 100x tighter tolerance. Writes DIR/metrics.csv (one row per run: pose error\n"
    "against the reference, final and RMS; energy and momentum drift; deepest penetration; restitution of\n"
    "each bounce; cost), DIR/compare.json (every run with its status) and DIR/runs/ENGINE-VARIANT/ (each\n"
    "run directory, for replay). DIR is written under a temporary name and renamed when complete.\n"
    "\n"
    "  --engines LIST   comma-separated: soft, ode, bullet (default: all three)\n"
    "  --variants LIST  of the reference engines: native, matched (default: both)\n"
    "  --step H         the reference engines' step, s (default 1e-3)\n"
    "  --tend T, --sample HZ   override the scene's settings for every run\n"
    "\n"
    "An engine that is not built, or that cannot represent the scene, is reported and skipped.\n"
    "Exit status: 0 ok, 1 the soft engine's run failed, 2 bad input.\n";

typedef struct compareRun {
  char name[32];  // ENGINE-VARIANT
  const char* engine;
  const char* variant;
  bool isReference;
  const char* status;  // ok, failed, refused, not built
  char message[512];
  pdTrajectory* trajectory;
  double wallSeconds;
  long steps;
  pdCompareMetrics metrics;  // when status is ok
} compareRun;

typedef struct softObserver {
  pdRunWriter* writer;
  pdTrajectory* trajectory;
} softObserver;

static bool observe_soft(const pdModel* model, const pdState* state, void* user) {
  softObserver* o = user;
  return pd_run_observe(model, state, o->writer) && pd_trajectory_observe(model, state, o->trajectory);
}

// Every word of `list` is one of `allowed` (NULL-terminated); false names the first stranger in *bad.
static bool list_valid(const char* list, const char* const* allowed, char* bad, size_t badSize) {
  for (const char* p = list; p && *p;) {
    const char* comma = strchr(p, ',');
    size_t len = comma ? (size_t)(comma - p) : strlen(p);
    bool ok = false;
    for (int i = 0; allowed[i]; ++i) ok = ok || (strlen(allowed[i]) == len && strncmp(p, allowed[i], len) == 0);
    if (!ok) {
      snprintf(bad, badSize, "%.*s", (int)len, p);
      return false;
    }
    p = comma ? comma + 1 : NULL;
  }
  return list[0] != '\0';
}

static void run_soft(const char* scene, const pdCliOverrides* overrides, const char* dir, compareRun* r) {
  pdModel* model = pd_cli_load_model(scene, overrides, NULL);
  if (!model) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "the scene did not load");
    return;
  }
  pdError err = {0};
  pdRunWriter* writer = pd_run_open(dir, &err);
  if (!writer) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "%s", err.message);
    pd_model_free(model);
    return;
  }
  pdState* state = pd_state_create(model);
  r->trajectory = pd_trajectory_create(model);
  softObserver o = {writer, r->trajectory};
  double e0 = pd_state_energy(model, state), t0 = pd_cli_wall_seconds();
  bool completed = pd_advance(model, state, model->settings.tend, observe_soft, &o);
  r->wallSeconds = pd_cli_wall_seconds() - t0;
  r->steps = state->count.accepted;
  pdRunInfo info = {.engine = "polydyn-soft", .energyStart = e0, .energyEnd = pd_state_energy(model, state),
                    .wallSeconds = r->wallSeconds, .completed = completed};
  if (!pd_run_finish(writer, model, state, &info, &err)) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "%s", err.message);
  } else {
    r->status = completed ? "ok" : "failed";
    if (!completed) snprintf(r->message, sizeof r->message, "stopped at t = %.6g s", state->t);
  }
  pd_state_free(state);
  pd_model_free(model);
}

static void run_reference_engine(const pdModel* model, const pdRefAdapter* adapter, const pdRefOptions* options,
                                 const char* dir, compareRun* r) {
  pdError err = {0};
  pdRunWriter* writer = pd_run_open(dir, &err);
  if (!writer) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "%s", err.message);
    return;
  }
  r->trajectory = pd_trajectory_create(model);
  pdRefRunStats stats;
  bool ok = pd_ref_run(model, adapter, options, writer, pd_trajectory_observe, r->trajectory, &stats, &err);
  r->wallSeconds = stats.wallSeconds;
  r->steps = stats.steps;
  if (!ok) {
    r->status = stats.refused ? "refused" : "failed";
    snprintf(r->message, sizeof r->message, "%s", err.message);
  } else if (!stats.completed) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "non-finite state after %ld steps", stats.steps);
  } else {
    r->status = "ok";
  }
}

static void write_number(FILE* out, double v) {
  if (isfinite(v)) fprintf(out, "%.6g", v);
}

static void write_json_text(FILE* out, const char* s) {
  fputc('"', out);
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\') fputc('\\', out);
    if ((unsigned char)*s < 0x20) fprintf(out, "\\u%04x", *s);
    else fputc(*s, out);
  }
  fputc('"', out);
}

// metrics.csv (schema: reports/FORMATS.md) and compare.json; false on an I/O error.
static bool write_results(const char* dir, const char* scene, const pdModel* model, const compareRun* runs,
                          int count, double tolReference) {
  char path[8192];
  snprintf(path, sizeof path, "%s/metrics.csv", dir);
  FILE* out = fopen(path, "w");
  if (!out) return false;
  fputs("scene,engine,variant,reference,pos_err_final,pos_err_rms,rot_err_final_rad,rot_err_rms_rad,"
        "energy_drift_rel,momentum_drift_rel,max_penetration_over_size,wall_per_sim_second,steps,"
        "restitution_impacts\n",
        out);
  char refName[64];
  snprintf(refName, sizeof refName, "soft tol=%g", tolReference);
  double simulated = model->settings.tend;
  for (int i = 0; i < count; ++i) {
    const compareRun* r = &runs[i];
    if (strcmp(r->status, "ok") != 0) continue;
    const pdCompareMetrics m = r->metrics;
    fprintf(out, "\"%s\",%s,%s,%s,", scene, r->engine, r->variant, r->isReference ? "self" : refName);
    const double values[] = {m.posErrFinal, m.posErrRms, m.rotErrFinal, m.rotErrRms, m.energyDriftRel,
                             m.momentumDriftRel, m.maxPenetrationOverSize, r->wallSeconds / simulated};
    for (size_t k = 0; k < sizeof values / sizeof values[0]; ++k) {
      write_number(out, values[k]);
      fputc(',', out);
    }
    fprintf(out, "%ld,", r->steps);
    for (int k = 0; k < m.impacts && k < 16; ++k)
      fprintf(out, "%s%s:%.4f", k ? ";" : "", model->bodies[m.impactBody[k]].name, m.restitution[k]);
    fputc('\n', out);
  }
  bool ok = !ferror(out);
  ok = fclose(out) == 0 && ok;
  snprintf(path, sizeof path, "%s/compare.json", dir);
  out = fopen(path, "w");
  if (!out) return false;
  fputs("{\n  \"scene\": ", out);
  write_json_text(out, scene);
  fprintf(out, ",\n  \"reference\": \"%s\",\n  \"runs\": [\n", refName);
  for (int i = 0; i < count; ++i) {
    const compareRun* r = &runs[i];
    fprintf(out, "    {\"engine\": \"%s\", \"variant\": \"%s\", \"status\": \"%s\", \"run_dir\": \"runs/%s\", \"message\": ",
            r->engine, r->variant, r->status, r->name);
    write_json_text(out, r->message);
    fprintf(out, "}%s\n", i + 1 < count ? "," : "");
  }
  fputs("  ]\n}\n", out);
  ok = !ferror(out) && ok;
  return fclose(out) == 0 && ok;
}

int pd_cmd_compare(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  const char* engines = "soft,ode,bullet";
  const char* variants = "native,matched";
  pdCliOverrides overrides = {0};
  pdRefOptions refOptions = {pd_refNative, PD_REF_DEFAULT_STEP, pd_odeFrictionPyramid};
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (pd_cli_is_help(a)) {
      fputs(help, stdout);
      return PD_EXIT_OK;
    } else if (strcmp(a, "--out") == 0 || strcmp(a, "--engines") == 0 || strcmp(a, "--variants") == 0 ||
               strcmp(a, "--step") == 0 || strcmp(a, "--tend") == 0 || strcmp(a, "--sample") == 0) {
      if (i + 1 >= argc) return pd_cli_usage_error("compare", "%s needs a value", a);
      const char* v = argv[++i];
      char bad[64];
      if (strcmp(a, "--out") == 0) {
        if (!v[0]) return pd_cli_usage_error("compare", "--out needs a directory name");
        out = v;
      } else if (strcmp(a, "--engines") == 0) {
        static const char* const known[] = {"soft", "ode", "bullet", NULL};
        if (!list_valid(v, known, bad, sizeof bad))
          return pd_cli_usage_error("compare", "--engines: unknown engine '%s' (soft, ode, bullet)", bad);
        engines = v;
      } else if (strcmp(a, "--variants") == 0) {
        static const char* const known[] = {"native", "matched", NULL};
        if (!list_valid(v, known, bad, sizeof bad))
          return pd_cli_usage_error("compare", "--variants: unknown variant '%s' (native, matched)", bad);
        variants = v;
      } else if (strcmp(a, "--step") == 0) {
        if (!pd_cli_positive(v, &refOptions.step)) return pd_cli_usage_error("compare", "--step needs a number > 0");
      } else if (strcmp(a, "--tend") == 0) {
        if (!pd_cli_positive(v, &overrides.tend)) return pd_cli_usage_error("compare", "--tend needs a number > 0");
      } else if (!pd_cli_positive(v, &overrides.sample)) {
        return pd_cli_usage_error("compare", "--sample needs a number > 0");
      }
    } else if (a[0] == '-' && a[1] != '\0') {
      return pd_cli_usage_error("compare", "unknown option '%s'", a);
    } else if (scene) {
      return pd_cli_usage_error("compare", "one scene at a time ('%s' and '%s')", scene, a);
    } else {
      scene = a;
    }
  }
  if (!scene) return pd_cli_usage_error("compare", "no scene given");
  if (!out) return pd_cli_usage_error("compare", "--out DIR is required");
  if (strlen(out) > COMPARE_PATH_MAX) return pd_cli_usage_error("compare", "--out: path longer than %d bytes", COMPARE_PATH_MAX);

  pdModel* model = pd_cli_load_model(scene, &overrides, NULL);
  if (!model) return PD_EXIT_BAD_INPUT;
  char tmp[4096];
  if (!pd_cli_out_open("compare", out, "metrics.csv", tmp, sizeof tmp)) {
    pd_model_free(model);
    return PD_EXIT_BAD_INPUT;
  }
  char runsDir[4200];
  snprintf(runsDir, sizeof runsDir, "%s/runs", tmp);
  if (mkdir(runsDir, 0777) != 0) {
    fprintf(stderr, "polydyn compare: cannot create %s: %s\n", runsDir, strerror(errno));
    pd_cli_remove_tree(tmp);
    pd_model_free(model);
    return PD_EXIT_FAILURE;
  }
  bool progress = isatty(STDERR_FILENO) == 1;

  compareRun runs[8];
  int count = 0;
  pdCliOverrides tighter = overrides;
  tighter.tolScale = COMPARE_REFERENCE_TOL_SCALE;
  double tolReference = model->settings.tol * COMPARE_REFERENCE_TOL_SCALE;
  // the reference first: every other run is measured against it
  runs[count] = (compareRun){.engine = "soft", .variant = "reference", .isReference = true, .status = "failed"};
  snprintf(runs[count].name, sizeof runs[count].name, "soft-reference");
  ++count;
  if (pd_cli_list_has(engines, "soft")) {
    runs[count] = (compareRun){.engine = "soft", .variant = "adaptive", .status = "failed"};
    snprintf(runs[count].name, sizeof runs[count].name, "soft-adaptive");
    ++count;
  }
  static const char* const refEngines[] = {"ode", "bullet"};
  static const char* const refVariants[] = {"native", "matched"};
  for (int e = 0; e < 2; ++e)
    for (int v = 0; v < 2; ++v)
      if (pd_cli_list_has(engines, refEngines[e]) && pd_cli_list_has(variants, refVariants[v])) {
        runs[count] = (compareRun){.engine = refEngines[e], .variant = refVariants[v], .status = "failed"};
        snprintf(runs[count].name, sizeof runs[count].name, "%s-%s", refEngines[e], refVariants[v]);
        ++count;
      }

  for (int i = 0; i < count; ++i) {
    compareRun* r = &runs[i];
    char dir[4300];
    snprintf(dir, sizeof dir, "%s/%s", runsDir, r->name);
    if (progress) fprintf(stderr, "\rpolydyn compare: %s (%d/%d)\033[K", r->name, i + 1, count);
    if (strcmp(r->engine, "soft") == 0) {
      run_soft(scene, r->isReference ? &tighter : &overrides, dir, r);
      continue;
    }
    const pdRefAdapter* adapter = pd_ref_adapter(r->engine);
    if (!adapter) {
      r->status = "not built";
      snprintf(r->message, sizeof r->message, "this build of polydyn has no %s adapter", r->engine);
      continue;
    }
    pdRefOptions o = refOptions;
    o.variant = strcmp(r->variant, "matched") == 0 ? pd_refMatched : pd_refNative;
    run_reference_engine(model, adapter, &o, dir, r);
  }
  if (progress) fputs("\r\033[K", stderr);

  int status = PD_EXIT_OK;
  for (int i = 0; i < count; ++i) {
    compareRun* r = &runs[i];
    if (strcmp(r->status, "ok") != 0) {
      fprintf(stderr, "polydyn compare: %s %s: %s\n", r->name, r->status, r->message);
      if (strcmp(r->engine, "soft") == 0) status = PD_EXIT_FAILURE;
    }
  }
  const compareRun* reference = strcmp(runs[0].status, "ok") == 0 ? &runs[0] : NULL;
  for (int i = 0; i < count; ++i)
    if (strcmp(runs[i].status, "ok") == 0)
      runs[i].metrics = pd_compare_metrics(model, runs[i].trajectory,
                                           reference && reference != &runs[i] ? reference->trajectory : NULL);
  bool written = write_results(tmp, scene, model, runs, count, tolReference);
  if (!written) {
    fprintf(stderr, "polydyn compare: cannot write %s: %s\n", tmp, strerror(errno));
    pd_cli_remove_tree(tmp);
  }
  written = written && pd_cli_out_close("compare", tmp, out);
  if (!written) {
    status = PD_EXIT_FAILURE;
  } else {
    // the table on stdout: what a person reads first
    printf("%-16s %-8s %12s %12s %12s %14s\n", "run", "status", "pos err end", "rot err end", "energy drift",
           "wall/sim s");
    for (int i = 0; i < count; ++i) {
      compareRun* r = &runs[i];
      if (strcmp(r->status, "ok") != 0) {
        printf("%-16s %-8s\n", r->name, r->status);
        continue;
      }
      const pdCompareMetrics m = r->metrics;
      printf("%-16s %-8s %12.3g %12.3g %12.3g %14.3g\n", r->name, r->status, m.posErrFinal, m.rotErrFinal,
             m.energyDriftRel, r->wallSeconds / model->settings.tend);
    }
    printf("metrics: %s/metrics.csv (reference: soft at tol %g)\n", out, tolReference);
  }
  for (int i = 0; i < count; ++i) pd_trajectory_free(runs[i].trajectory);
  pd_model_free(model);
  return status;
}
