// polydyn compare — one scene (or every scene of a directory) in every engine, metrics against a tighter
// soft run (docs/DESIGN.md §8.1). Each scene is one task of a batch (runner/include/pdrun/batch.h).
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "compare_files.h"
#include "pdutil/csv.h"
#include "pdutil/json.h"
#include "pdrun/batch.h"
#include "pdref/compare.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "polydyn/state.h"

// The reference run's tolerance over the scene's: docs/DESIGN.md §8.1 ("our own run at a 100× tighter tolerance").
#define COMPARE_REFERENCE_TOL_SCALE 0.01
// Longest --out path: the run directories' paths below it fit the fixed buffers.
#define COMPARE_PATH_MAX 3000

static const char* const help =
    "usage: polydyn compare SCENE|SCENE_DIR --out DIR [--engines soft,ode,bullet] [--variants native,matched]\n"
    "                             [--step H] [--tend T] [--sample HZ] [--jobs N]\n"
    "\n"
    "Runs SCENE in polydyn's soft engine and in the reference engines (each variant), and a reference run\n"
    "of the soft engine at a 100x tighter tolerance. Writes DIR/metrics.csv (one row per run: pose error\n"
    "against the reference, final and RMS; energy and momentum drift; deepest penetration; restitution of\n"
    "each bounce; cost), DIR/compare.json (every run with its status) and DIR/runs/ENGINE-VARIANT/ (each\n"
    "run directory, for replay). DIR is written under a temporary name and renamed when complete.\n"
    "Beside metrics.csv: series.csv (each body over time in every run: pose error, energy, penetration, contacts,\n"
    "normal force, slip speed), impacts.csv (every impact, matched to the reference's), friction.csv (|F_t|/F_n\n"
    "against slip speed) and divergence.csv (when and where each run first differs by more than 0.1, and whether\n"
    "chaos explains it: the reference is repeated at twice its tolerance, runs/soft-chaos). `polydyn report DIR`\n"
    "shows them (docs/compare-report.md).\n"
    "\n"
    "  --engines LIST   comma-separated: soft, ode, bullet (default: all three)\n"
    "  --variants LIST  of the reference engines: native, matched (default: both)\n"
    "  --step H         the reference engines' step, s (default 1e-3)\n"
    "  --tend T, --sample HZ   override the scene's settings for every run\n"
    "  --jobs N         compare N scenes at a time in worker processes (default 1); under mpirun or srun the\n"
    "                   scenes are split over the ranks (docs/commands.md). Scenes compared side by side\n"
    "                   share the machine: wall_per_sim_second then measures a loaded machine\n"
    "\n"
    "With SCENE_DIR, every SCENE_DIR/NAME.scene (in byte order of the names) is compared into DIR/NAME/\n"
    "(the directory `polydyn compare SCENE_DIR/NAME.scene --out DIR/NAME` writes), and DIR/metrics.csv holds\n"
    "the rows of all of them, in that order. Every scene is read first: one bad scene, nothing written.\n"
    "\n"
    "An engine that is not built, or that cannot represent the scene, is reported and skipped.\n"
    "Exit status: 0 ok, 1 the soft engine's run of a scene failed or DIR could not be written (then nothing is\n"
    "kept), 2 bad input, 130 interrupted (SIGINT, SIGTERM: nothing written, an earlier DIR kept).\n";

typedef struct compareRun {
  char name[32];  // ENGINE-VARIANT
  const char* engine;
  const char* variant;
  bool isReference;
  bool isChaos;  // the reference repeated at a perturbed tolerance: the scene's own divergence
  const char* status;  // ok, failed, refused, not built
  char message[512];
  pdTrajectory* trajectory;
  pdContactLog* contacts;  // the soft engine's contacts per sample
  pdDivergence divergence;
  double wallSeconds;
  long steps;
  pdCompareMetrics metrics;  // when status is ok
  bool writeFailed;          // its run directory could not be written (a full disk): nothing of the scene is kept
} compareRun;

typedef struct softObserver {
  pdRunWriter* writer;
  pdTrajectory* trajectory;
  pdContactLog* contacts;
} softObserver;

static bool observe_soft(const pdModel* model, const pdState* state, void* user) {
  softObserver* o = user;
  return pd_run_observe(model, state, o->writer) && pd_trajectory_observe(model, state, o->trajectory) &&
         pd_contact_log_observe(model, state, o->contacts) && !pd_cli_interrupted;
}

static bool observe_reference(const pdModel* model, const pdState* state, void* user) {
  return pd_trajectory_observe(model, state, user) && !pd_cli_interrupted;
}

static bool batch_progress(int task, int done, int total, void* user) {
  (void)task, (void)done, (void)total, (void)user;
  return !pd_cli_interrupted;
}

// Every word of `list` is one of `allowed` (NULL-terminated); false names the first stranger in *bad.
static bool list_valid(const char* list, const char* const* allowed, char* bad, size_t badSize) {
  bad[0] = '\0';  // an empty list is refused with an empty name: the message must not read an unset buffer
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
    r->writeFailed = true;
    snprintf(r->message, sizeof r->message, "%s", err.message);
    pd_model_free(model);
    return;
  }
  pdState* state = pd_state_create(model, NULL);
  r->trajectory = pd_trajectory_create(model);
  r->contacts = pd_contact_log_create(model);
  softObserver o = {writer, r->trajectory, r->contacts};
  double e0 = pd_state_energy(model, state), t0 = pd_cli_wall_seconds();
  bool completed = pd_advance(model, state, model->settings.tend, observe_soft, &o);
  pd_run_drain(writer);  // the samples printed by the writer thread count too (engine/src/output.c)
  r->wallSeconds = pd_cli_wall_seconds() - t0;
  r->steps = state->count.accepted;
  pdRunInfo info = {.engine = "polydyn-soft", .energyStart = e0, .energyEnd = pd_state_energy(model, state),
                    .wallSeconds = r->wallSeconds, .completed = completed};
  if (!pd_run_finish(writer, model, state, &info, &err)) {
    r->status = "failed";
    r->writeFailed = true;
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
    r->writeFailed = true;
    snprintf(r->message, sizeof r->message, "%s", err.message);
    return;
  }
  r->trajectory = pd_trajectory_create(model);
  r->contacts = pd_contact_log_create(model);
  pdRefOptions o = *options;
  o.contactObserver = pd_contact_log_add;
  o.contactUser = r->contacts;
  pdRefRunStats stats;
  bool ok = pd_ref_run(model, adapter, &o, writer, observe_reference, r->trajectory, &stats, &err);
  r->wallSeconds = stats.wallSeconds;
  r->steps = stats.steps;
  if (!ok) {
    r->status = stats.refused ? "refused" : "failed";
    r->writeFailed = !stats.refused;  // its observer never stops the run: the directory could not be written
    snprintf(r->message, sizeof r->message, "%s", err.message);
  } else if (!stats.completed) {
    r->status = "failed";
    snprintf(r->message, sizeof r->message, "non-finite state after %ld steps", stats.steps);
  } else {
    r->status = "ok";
  }
}

static const char* const metricsHeader =
    "scene,engine,variant,reference,pos_err_final,pos_err_rms,rot_err_final_rad,rot_err_rms_rad,"
    "energy_drift_rel,momentum_drift_rel,max_penetration_over_size,wall_per_sim_second,steps,"
    "restitution_impacts\n";

// The rows of metrics.csv (schema: reports/FORMATS.md), one per run that completed.
static void write_metric_rows(FILE* out, const char* scene, const pdModel* model, const compareRun* runs, int count,
                              const char* refName) {
  double simulated = model->settings.tend;
  for (int i = 0; i < count; ++i) {
    const compareRun* r = &runs[i];
    if (strcmp(r->status, "ok") != 0 || r->isChaos) continue;
    const pdCompareMetrics m = r->metrics;
    pdu_csv_quoted(out, scene);  // quoted in every row, as it always was
    const char* const texts[] = {r->engine, r->variant, r->isReference ? "self" : refName};
    for (size_t k = 0; k < sizeof texts / sizeof texts[0]; ++k) {
      fputc(',', out);
      pdu_csv_text(out, texts[k]);
    }
    fputc(',', out);
    const double values[] = {m.posErrFinal, m.posErrRms, m.rotErrFinal, m.rotErrRms, m.energyDriftRel,
                             m.momentumDriftRel, m.maxPenetrationOverSize, r->wallSeconds / simulated};
    for (size_t k = 0; k < sizeof values / sizeof values[0]; ++k) {
      pdu_csv_number(out, values[k], 6);
      fputc(',', out);
    }
    fprintf(out, "%ld,", r->steps);
    // "NAME:e;NAME:e": one field, quoted as a whole when a body's name needs it
    char* impacts = NULL;
    size_t impactsSize = 0;
    FILE* text = open_memstream(&impacts, &impactsSize);
    if (!text) abort();
    for (int k = 0; k < m.impacts && k < 16; ++k)
      fprintf(text, "%s%s:%.4f", k ? ";" : "", model->bodies[m.impactBody[k]].name, m.restitution[k]);
    if (fclose(text) != 0) abort();
    pdu_csv_text(out, impacts);
    free(impacts);
    fputc('\n', out);
  }
}

// metrics.csv and compare.json; false on an I/O error.
static bool write_results(const char* dir, const char* scene, const pdModel* model, const compareRun* runs,
                          int count, const char* refName) {
  char path[8192];
  snprintf(path, sizeof path, "%s/metrics.csv", dir);
  FILE* out = fopen(path, "w");
  if (!out) return false;
  fputs(metricsHeader, out);
  write_metric_rows(out, scene, model, runs, count, refName);
  bool ok = !ferror(out);
  ok = fclose(out) == 0 && ok;
  snprintf(path, sizeof path, "%s/compare.json", dir);
  out = fopen(path, "w");
  if (!out) return false;
  fputs("{\n  \"scene\": ", out);
  pdu_json_string(out, scene);
  fputs(",\n  \"reference\": ", out);
  pdu_json_string(out, refName);
  fputs(",\n  \"runs\": [\n", out);
  for (int i = 0; i < count; ++i) {
    const compareRun* r = &runs[i];
    const char* const keys[] = {"engine", "variant", "status"};
    const char* const values[] = {r->engine, r->variant, r->status};
    for (int k = 0; k < 3; ++k) {
      fprintf(out, "%s\"%s\": ", k ? ", " : "    {", keys[k]);
      pdu_json_string(out, values[k]);
    }
    fprintf(out, ", \"run_dir\": \"runs/%s\", \"message\": ", r->name);
    pdu_json_string(out, r->message);
    fprintf(out, "}%s\n", i + 1 < count ? "," : "");
  }
  fputs("  ]\n}\n", out);
  ok = !ferror(out) && ok;
  return fclose(out) == 0 && ok;
}

// The table a person reads first (stdout).
static void write_table(FILE* out, const pdModel* model, const compareRun* runs, int count) {
  fprintf(out, "%-16s %-8s %12s %12s %12s %14s %12s %12s\n", "run", "status", "pos err end", "rot err end", "energy drift",
          "wall/sim s", "diverges s", "beyond chaos");
  for (int i = 0; i < count; ++i) {
    const compareRun* r = &runs[i];
    if (strcmp(r->status, "ok") != 0) {
      fprintf(out, "%-16s %-8s\n", r->name, r->status);
      continue;
    }
    const pdCompareMetrics m = r->metrics;
    const pdDivergence d = r->divergence;
    fprintf(out, "%-16s %-8s", r->name, r->status);
    pd_cli_table_number(out, 13, "%.3g", m.posErrFinal);  // the reference row has no error: "—"
    pd_cli_table_number(out, 13, "%.3g", m.rotErrFinal);
    pd_cli_table_number(out, 13, "%.3g", m.energyDriftRel);
    pd_cli_table_number(out, 15, "%.3g", r->wallSeconds / model->settings.tend);
    pd_cli_table_number(out, 13, "%.3g", d.diverged ? d.t : NAN);  // never diverged: "—"
    pd_cli_table_number(out, 13, "%.3g", !r->isChaos && d.diverged ? d.beyondChaos : NAN);
    fputc('\n', out);
  }
}

typedef struct compareSettings {
  const char* engines;
  const char* variants;
  pdCliOverrides overrides;
  pdRefOptions refOptions;
  bool progress;
} compareSettings;

// What one scene's task returns: its status, then its metrics rows and its table (texts with their sizes).
typedef struct sceneHeader {
  int32_t status;
  int32_t written;  // its metrics.csv and compare.json are complete
  uint64_t rowsSize, tableSize;
} sceneHeader;

// Compares one scene into `dir` (which exists): its run directories, metrics.csv and compare.json.
static void compare_scene(const char* scene, const pdModel* model, const compareSettings* c, const char* dir,
                          pdBatchBuffer* result) {
  char runsDir[4500];
  snprintf(runsDir, sizeof runsDir, "%s/runs", dir);
  sceneHeader h = {.status = PD_EXIT_OK, .written = true};
  if (mkdir(runsDir, 0777) != 0) {
    fprintf(stderr, "polydyn compare: cannot create %s: %s\n", runsDir, strerror(errno));
    h = (sceneHeader){.status = PD_EXIT_FAILURE};
    pd_batch_append(result, &h, sizeof h);
    return;
  }
  compareRun runs[8];  // the reference, the chaos run, soft, ODE and Bullet in two variants each
  int count = 0;
  pdCliOverrides tighter = c->overrides;
  tighter.tolScale = COMPARE_REFERENCE_TOL_SCALE;
  double tolReference = model->settings.tol * COMPARE_REFERENCE_TOL_SCALE;
  // the reference first: every other run is measured against it
  runs[count] = (compareRun){.engine = "soft", .variant = "reference", .isReference = true, .status = "failed"};
  snprintf(runs[count].name, sizeof runs[count].name, "soft-reference");
  ++count;
  pdCliOverrides perturbed = tighter;
  perturbed.tolScale = COMPARE_REFERENCE_TOL_SCALE * PD_COMPARE_CHAOS_TOL_SCALE;
  runs[count] = (compareRun){.engine = "soft", .variant = "chaos", .isChaos = true, .status = "failed"};
  snprintf(runs[count].name, sizeof runs[count].name, "soft-chaos");
  ++count;
  if (pd_cli_list_has(c->engines, "soft")) {
    runs[count] = (compareRun){.engine = "soft", .variant = "implicit", .status = "failed"};
    snprintf(runs[count].name, sizeof runs[count].name, "soft-implicit");
    ++count;
  }
  static const char* const refEngines[] = {"ode", "bullet"};
  static const char* const refVariants[] = {"native", "matched"};
  for (int e = 0; e < 2; ++e)
    for (int v = 0; v < 2; ++v)
      if (pd_cli_list_has(c->engines, refEngines[e]) && pd_cli_list_has(c->variants, refVariants[v])) {
        runs[count] = (compareRun){.engine = refEngines[e], .variant = refVariants[v], .status = "failed"};
        snprintf(runs[count].name, sizeof runs[count].name, "%s-%s", refEngines[e], refVariants[v]);
        ++count;
      }

  for (int i = 0; i < count; ++i) {
    compareRun* r = &runs[i];
    char runDir[4600];
    snprintf(runDir, sizeof runDir, "%s/%s", runsDir, r->name);
    if (c->progress) fprintf(stderr, "\rpolydyn compare: %s %s (%d/%d)\033[K", scene, r->name, i + 1, count);
    if (strcmp(r->engine, "soft") == 0) {
      run_soft(scene, r->isReference ? &tighter : r->isChaos ? &perturbed : &c->overrides, runDir, r);
      continue;
    }
    const pdRefAdapter* adapter = pd_ref_adapter(r->engine);
    if (!adapter) {
      r->status = "not built";
      snprintf(r->message, sizeof r->message, "this build of polydyn has no %s adapter", r->engine);
      continue;
    }
    pdRefOptions o = c->refOptions;
    o.variant = strcmp(r->variant, "matched") == 0 ? pd_refMatched : pd_refNative;
    run_reference_engine(model, adapter, &o, runDir, r);
  }
  if (c->progress) fputs("\r\033[K", stderr);

  for (int i = 0; i < count; ++i) {
    compareRun* r = &runs[i];
    if (strcmp(r->status, "ok") != 0) {
      fprintf(stderr, "polydyn compare: %s: %s %s: %s\n", scene, r->name, r->status, r->message);
      if (strcmp(r->engine, "soft") == 0) h.status = PD_EXIT_FAILURE;
    }
    if (r->writeFailed) h.written = false;
  }
  const compareRun* reference = strcmp(runs[0].status, "ok") == 0 ? &runs[0] : NULL;
  for (int i = 0; i < count; ++i)
    if (strcmp(runs[i].status, "ok") == 0)
      runs[i].metrics = pd_compare_metrics(model, runs[i].trajectory,
                                           reference && reference != &runs[i] ? reference->trajectory : NULL);
  char refName[64];
  snprintf(refName, sizeof refName, "soft tol=%g", tolReference);
  bool detailsWritten = true;
  if (reference) {  // series, impacts, friction and divergence: against the reference, the chaos run beside it
    pdCompareRunData data[8];
    pdDivergence divergences[8];
    int index[8], n = 0, chaos = -1;
    for (int i = 0; i < count; ++i) {
      if (strcmp(runs[i].status, "ok") != 0) continue;
      if (runs[i].isChaos) chaos = n;
      index[n] = i;
      data[n++] = (pdCompareRunData){runs[i].engine, runs[i].variant, runs[i].trajectory, runs[i].contacts};
    }
    detailsWritten = pd_compare_write_details(dir, scene, model, data, n, chaos, divergences);
    for (int i = 0; i < n; ++i) runs[index[i]].divergence = divergences[i];
  }
  char* rows = NULL;
  char* table = NULL;
  size_t rowsSize = 0, tableSize = 0;
  FILE* rowsOut = open_memstream(&rows, &rowsSize);
  FILE* tableOut = open_memstream(&table, &tableSize);
  if (!rowsOut || !tableOut) abort();
  if (detailsWritten && write_results(dir, scene, model, runs, count, refName)) {
    write_metric_rows(rowsOut, scene, model, runs, count, refName);
    write_table(tableOut, model, runs, count);
  } else {
    fprintf(stderr, "polydyn compare: cannot write %s: %s\n", dir, strerror(errno));
    h = (sceneHeader){.status = PD_EXIT_FAILURE};
  }
  fclose(rowsOut);
  fclose(tableOut);
  h.rowsSize = rowsSize;
  h.tableSize = tableSize;
  pd_batch_append(result, &h, sizeof h);
  pd_batch_append(result, rows, rowsSize);
  pd_batch_append(result, table, tableSize);
  free(rows);
  free(table);
  for (int i = 0; i < count; ++i) {
    pd_trajectory_free(runs[i].trajectory);
    pd_contact_log_free(runs[i].contacts);
  }
}

// The scenes of one command: one file, or every NAME.scene of a directory (in byte order of the names).
typedef struct sceneList {
  bool directory;
  int count;
  char** paths;   // (count)
  char** names;   // (count) NAME, the sub-directory of the output
  pdModel** models;
  const compareSettings* settings;
  const char* tmp;
} sceneList;

static int compare_names(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

static bool is_scene_name(const char* name) {
  size_t n = strlen(name);
  return n > 6 && name[0] != '.' && strcmp(name + n - 6, ".scene") == 0;
}

// Fills the list from `arg`; false (message printed) when the directory cannot be read or has no scene.
static bool list_scenes(const char* arg, sceneList* list) {
  struct stat st;
  list->directory = stat(arg, &st) == 0 && S_ISDIR(st.st_mode);
  if (!list->directory) {
    list->count = 1;
    list->paths = calloc(1, sizeof *list->paths);
    list->names = calloc(1, sizeof *list->names);
    if (!list->paths || !list->names || !(list->paths[0] = strdup(arg)) || !(list->names[0] = strdup(""))) abort();
    return true;
  }
  DIR* d = opendir(arg);
  if (!d) {
    fprintf(stderr, "polydyn compare: %s: cannot read the directory: %s\n", arg, strerror(errno));
    return false;
  }
  int capacity = 0;
  for (struct dirent* e; (e = readdir(d));) {
    if (!is_scene_name(e->d_name)) continue;
    if (list->count == capacity) {
      capacity = capacity ? 2 * capacity : 16;
      list->names = realloc(list->names, (size_t)capacity * sizeof *list->names);
      if (!list->names) abort();
    }
    if (!(list->names[list->count++] = strdup(e->d_name))) abort();
  }
  closedir(d);
  if (list->count == 0) {
    fprintf(stderr, "polydyn compare: %s: no NAME.scene in the directory\n", arg);
    return false;
  }
  qsort(list->names, (size_t)list->count, sizeof *list->names, compare_names);
  list->paths = calloc((size_t)list->count, sizeof *list->paths);
  if (!list->paths) abort();
  for (int i = 0; i < list->count; ++i) {
    size_t n = strlen(arg) + strlen(list->names[i]) + 2;
    list->paths[i] = malloc(n);
    if (!list->paths[i]) abort();
    snprintf(list->paths[i], n, "%s/%s", arg, list->names[i]);
    list->names[i][strlen(list->names[i]) - 6] = '\0';  // NAME.scene -> NAME
  }
  return true;
}

static void free_scenes(sceneList* list) {
  for (int i = 0; i < list->count; ++i) {
    if (list->paths) free(list->paths[i]);
    if (list->names) free(list->names[i]);
    if (list->models && list->models[i]) pd_model_free(list->models[i]);
  }
  free(list->paths);
  free(list->names);
  free(list->models);
}

static void scene_task(int task, pdBatchBuffer* result, void* user) {
  const sceneList* list = user;
  char dir[4400];
  snprintf(dir, sizeof dir, "%s%s%s", list->tmp, list->directory ? "/" : "", list->names[task]);
  if (list->directory && mkdir(dir, 0777) != 0) {
    fprintf(stderr, "polydyn compare: cannot create %s: %s\n", dir, strerror(errno));
    sceneHeader h = {.status = PD_EXIT_FAILURE};
    pd_batch_append(result, &h, sizeof h);
    return;
  }
  compare_scene(list->paths[task], list->models[task], list->settings, dir, result);
}

// Rank 0 after the batch: the aggregated metrics.csv of a directory, the tables; the exit status. False
// when a scene's files or the aggregate could not be written (then nothing is kept).
static bool report_scenes(const sceneList* list, const pdBatchBuffer* results, const char* out, int* status) {
  *status = PD_EXIT_OK;
  for (int i = 0; i < list->count; ++i) {
    sceneHeader h;
    size_t at = 0;
    if (!pd_batch_read(&results[i], &at, &h, sizeof h) || !h.written) return false;
  }
  FILE* metrics = NULL;
  char path[4300];
  if (list->directory) {
    snprintf(path, sizeof path, "%s/metrics.csv", list->tmp);
    metrics = fopen(path, "w");
    if (!metrics) {
      fprintf(stderr, "polydyn compare: cannot write %s: %s\n", path, strerror(errno));
      return false;
    }
    fputs(metricsHeader, metrics);
  }
  for (int i = 0; i < list->count; ++i) {
    sceneHeader h;
    size_t at = 0;
    bool whole = pd_batch_read(&results[i], &at, &h, sizeof h);
    PD_ASSERT(whole && results[i].size - at == h.rowsSize + h.tableSize);
    if (h.status > *status) *status = h.status;
    if (metrics) fwrite(results[i].data + at, 1, (size_t)h.rowsSize, metrics);
    if (list->directory) printf("%s:\n", list->paths[i]);
    fwrite(results[i].data + at + h.rowsSize, 1, (size_t)h.tableSize, stdout);
    printf("metrics: %s%s%s/metrics.csv (reference: soft at tol %g)\n", out, list->directory ? "/" : "", list->names[i],
           list->models[i]->settings.tol * COMPARE_REFERENCE_TOL_SCALE);
  }
  if (metrics) {
    bool ok = !ferror(metrics);
    ok = fclose(metrics) == 0 && ok;
    if (!ok) {
      fprintf(stderr, "polydyn compare: cannot write %s\n", path);
      return false;
    }
    printf("all scenes: %s/metrics.csv\n", out);
  }
  return true;
}

static bool accept_engines(const char* cmd, const char* v, void* target) {
  static const char* const known[] = {"soft", "ode", "bullet", NULL};
  char bad[64];
  if (!list_valid(v, known, bad, sizeof bad)) {
    pd_cli_usage_error(cmd, "--engines: unknown engine '%s' (soft, ode, bullet)", bad);
    return false;
  }
  *(const char**)target = v;
  return true;
}

static bool accept_variants(const char* cmd, const char* v, void* target) {
  static const char* const known[] = {"native", "matched", NULL};
  char bad[64];
  if (!list_valid(v, known, bad, sizeof bad)) {
    pd_cli_usage_error(cmd, "--variants: unknown variant '%s' (native, matched)", bad);
    return false;
  }
  *(const char**)target = v;
  return true;
}

int pd_cmd_compare(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = NULL;
  int jobs = 0;
  compareSettings c = {
      .engines = "soft,ode,bullet",
      .variants = "native,matched",
      .refOptions = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid}};
  char jobsMessage[64];
  snprintf(jobsMessage, sizeof jobsMessage, "--jobs needs a whole number 1..%d", PD_CLI_MAX_JOBS);
  const pdCliOption table[] = {
      {.name = "--out", .kind = pd_optText, .target = &out, .message = "--out needs a directory name", .min = 1},
      {.name = "--engines", .kind = pd_optAccept, .target = &c.engines, .accept = accept_engines},
      {.name = "--variants", .kind = pd_optAccept, .target = &c.variants, .accept = accept_variants},
      {.name = "--step", .kind = pd_optPositive, .target = &c.refOptions.step, .message = "--step needs a number > 0"},
      {.name = "--tend", .kind = pd_optPositive, .target = &c.overrides.tend, .message = "--tend needs a number > 0"},
      {.name = "--sample", .kind = pd_optPositive, .target = &c.overrides.sample,
       .message = "--sample needs a number > 0"},
      {.name = "--jobs", .kind = pd_optJobs, .target = &jobs, .message = jobsMessage},
  };
  pdCliPositionals scenes = {.values = &scene, .max = 1,
                             .tooMany = "one scene or one directory of scenes ('%s' and '%s')"};
  int parsed = pd_cli_parse_options("compare", argc, argv, table, sizeof table / sizeof table[0], &scenes, help);
  if (parsed >= 0) return parsed;
  if (!scene) return pd_cli_usage_error("compare", "no scene given");
  if (!out) return pd_cli_usage_error("compare", "--out DIR is required");
  if (strlen(out) > COMPARE_PATH_MAX) return pd_cli_usage_error("compare", "--out: path longer than %d bytes", COMPARE_PATH_MAX);
  if (pd_cli_parse_only) return PD_EXIT_OK;
  jobs = pd_cli_default_jobs(jobs, 1);  // one at a time unless asked: wall_per_sim_second is a measurement

  // every scene read first: a bad one is refused before anything is written
  sceneList list = {.settings = &c};
  if (!list_scenes(scene, &list)) {
    free_scenes(&list);
    return PD_EXIT_BAD_INPUT;
  }
  list.models = calloc((size_t)list.count, sizeof *list.models);
  if (!list.models) abort();
  for (int i = 0; i < list.count; ++i)
    if (!(list.models[i] = pd_cli_load_model(list.paths[i], &c.overrides, NULL))) {
      free_scenes(&list);
      return PD_EXIT_BAD_INPUT;
    }
  char tmp[4096];
  pd_cli_catch_interrupts();  // from here on an interrupt must remove the temporary directory
  if (!pd_cli_out_open("compare", out, "metrics.csv", tmp, sizeof tmp)) {
    free_scenes(&list);
    return PD_EXIT_BAD_INPUT;
  }
  list.tmp = tmp;
  // progress of a scene's runs when they run here, one after the other
  c.progress = isatty(STDERR_FILENO) == 1 && jobs == 1 && pd_batch_ranks() == 1;

  pdBatchBuffer* results = calloc((size_t)list.count, sizeof *results);
  if (!results) abort();
  pdBatchOptions batch = {.workers = jobs, .progress = batch_progress};
  char why[256] = "";
  int status = PD_EXIT_OK;
  bool ran = pd_batch_run(list.count, scene_task, &list, &batch, results, why, sizeof why);
  if (pd_cli_interrupted) {
    if (pd_batch_is_root()) fprintf(stderr, "polydyn compare: interrupted; nothing written\n");
    pd_cli_remove_tree(tmp);
    status = 130;
  } else if (!ran) {
    fprintf(stderr, "polydyn compare: %s\n", why);
    pd_cli_remove_tree(tmp);
    status = PD_EXIT_FAILURE;
  } else if (pd_batch_is_root()) {  // MPI: rank 0 writes and reports
    // a scene whose soft run failed is kept (exit 1, as one scene); a write error keeps nothing
    if (!report_scenes(&list, results, out, &status)) {
      pd_cli_remove_tree(tmp);
      status = PD_EXIT_FAILURE;
    } else if (!pd_cli_out_close("compare", tmp, out)) {
      status = PD_EXIT_FAILURE;
    }
  }
  for (int i = 0; i < list.count; ++i) pd_batch_buffer_free(&results[i]);
  free(results);
  free_scenes(&list);
  return status;
}
