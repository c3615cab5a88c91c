// polydyn gedanken — the suite: every selected experiment on every selected engine, and its output files
// (gedanken/RESULT_SCHEMAS.md: results.csv, experiments.json, series/NAME.csv, runs/NAME/ENGINE-VARIANT[-INPUT]).
//
// Order of work: the scenes are generated and compiled first (compiling touches GSL's global error
// handler), one model per (experiment, input), shared read-only by that case's runs. Every run is then one
// task of a batch (runner/include/pdrun/batch.h: `jobs` worker processes, or MPI ranks): it writes its
// run directory and returns its row and series text, which land in task order, so the files are the same
// bytes whatever the number of processes, except wall times.
#include <errno.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gedanken_internal.h"
#include "pdrun/batch.h"
#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "pdutil/csv.h"
#include "pdutil/files.h"
#include "pdutil/json.h"

enum { SERIES_MAX_ROWS = 500 };  // per run (RESULT_SCHEMAS.md: "at most ~500 rows per run")

// ---------------------------------------------------------------------------------------------------------
// files

static bool make_dir(const char* path, pdError* err) {
  if (pdu_make_dir(path)) return true;
  pd_error_set(err, path, 0, 0, "cannot create the directory: %s", strerror(errno));
  return false;
}

bool pd_gk_out_replaceable(const char* out, pdError* err) {
  struct stat st;
  if (stat(out, &st) != 0) return true;
  char* results = pdu_path_join(out, "results.csv");
  bool ours = S_ISDIR(st.st_mode) && access(results, F_OK) == 0;
  free(results);
  if (!ours) pd_error_set(err, out, 0, 0, "exists and is not a gedanken directory (no results.csv); not replacing it");
  return ours;
}

// ---------------------------------------------------------------------------------------------------------
// cases and jobs

typedef struct gkJob {
  gkCase* c;
  pdGkEngine engine;
  pdRefVariant variant;
  // the row
  pdGkStatus status;
  double measured, error, wallSeconds;
  char runDir[512];      // relative to the output directory; "" when there is none
  char note[PD_GK_NOTE_MAX + 160];
  pdGkText series;       // series rows of this run
  bool done;
} gkJob;

static const char* variant_of(pdGkEngine engine, bool matched) {
  if (engine == pd_gkSoft) return "implicit";  // the soft runs take the default stepper (PD_STEPPER_DEFAULT)
  return matched ? "matched" : "native";
}

static const char* variant_name(const gkJob* job) { return variant_of(job->engine, job->variant == pd_refMatched); }

typedef struct gkSuite {
  const pdGkOptions* options;
  char* root;             // the temporary output directory
  gkCase* cases;
  int caseCount;
  gkJob* jobs;
  int jobCount;
} gkSuite;

static bool interrupted(const gkSuite* s) { return s->options->interrupt && *s->options->interrupt; }

typedef struct gkObserver {
  pdGkRecord* rec;
  pdRunWriter* writer;  // soft runs write through it here; pd_ref_run writes its own samples
  const gkSuite* suite;
} gkObserver;

static bool observe_soft(const pdModel* model, const pdState* state, void* user) {
  gkObserver* o = user;
  pd_gk_record_observe(model, state, o->rec);
  if (!pd_run_observe(model, state, o->writer)) return false;
  return !interrupted(o->suite);
}

static bool observe_ref(const pdModel* model, const pdState* state, void* user) {
  gkObserver* o = user;
  pd_gk_record_observe_ref(model, state, o->rec);
  return !interrupted(o->suite);
}

static void job_note(gkJob* job, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void job_note(gkJob* job, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(job->note, sizeof job->note, fmt, ap);
  va_end(ap);
}

// Verdict of one measured run.
static void judge(gkJob* job, const pdGkRecord* rec) {
  const gkCase* c = job->c;
  const pdGkExperiment* e = c->experiment;
  if (!rec->finite || rec->count < 2) {
    job->status = pd_gkFail;
    job_note(job, "the run produced %s", rec->count < 2 ? "fewer than 2 samples" : "a non-finite state");
    return;
  }
  pdGkMeasured m = {.value = NAN};
  e->measure(c->model, rec, c->input, &m);
  job->measured = isfinite(m.value) ? m.value : NAN;
  const char* prefix = e->relative && isfinite(c->expected.value) ? "relative error; " : "";
  job_note(job, "%s%s", prefix, m.note);
  if (isfinite(c->expected.value) && !isnan(job->measured))
    job->error = e->relative ? fabs(job->measured / c->expected.value - 1.0) : fabs(job->measured - c->expected.value);
  if (!pd_gk_applies(e, job->engine, job->variant == pd_refMatched)) {  // recorded, not judged
    job->status = pd_gkNotApplicable;
    char measured[sizeof job->note];
    snprintf(measured, sizeof measured, "%s", job->note);
    job_note(job, "not applicable: %s; %s", e->notApplicableReason, measured);
    return;
  }
  if (!isfinite(c->expected.value))  // a qualitative check: the measure decides
    job->status = m.pass ? pd_gkPass : pd_gkFail;
  else if (isnan(job->measured))
    job->status = pd_gkFail;
  else
    job->status = job->error <= c->expected.tolerance ? pd_gkPass : pd_gkFail;
}

static void write_series(gkJob* job, const pdGkRecord* rec) {
  const gkCase* c = job->c;
  int stride = (rec->count + SERIES_MAX_ROWS - 1) / SERIES_MAX_ROWS;
  if (stride < 1) stride = 1;
  for (int k = 0; k < rec->count; k += stride) {
    double analytic = NAN;
    double value = c->experiment->series(c->model, rec, k, c->input, &analytic);
    if (!isfinite(value)) continue;
    pd_gk_text_printf(&job->series, "%.17g,%s,%s,%s,%.17g,", rec->t[k], pdGkEngineNames[job->engine],
                      variant_name(job), c->label, value);
    if (isfinite(analytic)) pd_gk_text_printf(&job->series, "%.17g", analytic);
    pd_gk_text_printf(&job->series, "\n");
  }
}

// Writes the generated scene beside the run's files, so `polydyn run DIR/scene.scene` repeats the run.
static bool write_scene_copy(const char* dir, const char* text) {
  char* path = pdu_path_join(dir, "scene.scene");
  FILE* f = fopen(path, "w");
  free(path);
  if (!f) return false;
  fputs(text, f);
  return fclose(f) == 0;
}

static void run_job(gkSuite* s, gkJob* job) {
  const gkCase* c = job->c;
  const pdModel* model = c->model;
  job->measured = job->error = job->wallSeconds = NAN;
  const pdRefAdapter* adapter = NULL;
  if (job->engine != pd_gkSoft) {
    adapter = pd_ref_adapter(pdGkEngineNames[job->engine]);
    if (!adapter) {
      job->status = pd_gkNotBuilt;
      job_note(job, "this build of polydyn has no %s adapter", pdGkEngineNames[job->engine]);
      return;
    }
  }
  char name[160];
  snprintf(name, sizeof name, "%s-%s%s%s", pdGkEngineNames[job->engine], variant_name(job), c->label[0] ? "-" : "",
           c->label);
  snprintf(job->runDir, sizeof job->runDir, "runs/%s/%s", c->experiment->name, name);
  char* dir = pdu_path_join(s->root, job->runDir);
  pdError err = {0};
  pdRunWriter* writer = pd_run_open(dir, &err);
  if (!writer) {
    job->status = pd_gkError;
    job->runDir[0] = '\0';
    job_note(job, "%s", err.message);
    free(dir);
    return;
  }
  pdGkRecord rec;
  pd_gk_record_init(&rec, model->movingCount);
  gkObserver observer = {&rec, writer, s};
  bool written = false, completed = false;
  if (job->engine == pd_gkSoft) {
    double t0 = gk_wall_seconds();  // the span of a reference engine's run (pd_ref_run): created, then run
    pdState* state = pd_state_create(model, NULL);
    double energyStart = pd_state_energy(model, state);
    completed = pd_advance(model, state, model->settings.tend, observe_soft, &observer);
    job->wallSeconds = gk_wall_seconds() - t0;
    if (state->stopped) {
      pd_run_abort(writer);
    } else {
      pdRunInfo info = {.engine = "polydyn-soft", .energyStart = energyStart, .energyEnd = pd_state_energy(model, state),
                        .wallSeconds = job->wallSeconds, .completed = completed};
      written = pd_run_finish(writer, model, state, &info, &err);
      if (!completed) job_note(job, "the run stopped at t = %.6g s", state->t);
    }
    pd_state_free(state);
  } else {
    pdRefOptions options = {.variant = job->variant, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
    pdRefRunStats stats;
    written = pd_ref_run(model, adapter, &options, writer, observe_ref, &observer, &stats, &err);
    job->wallSeconds = stats.wallSeconds;
    completed = stats.completed;
    if (!written && stats.refused) {
      job->status = pd_gkRefused;
      job->runDir[0] = '\0';
      job_note(job, "%s", err.message);
      pd_gk_record_free(&rec);
      free(dir);
      return;
    }
    if (written && !completed) job_note(job, "%s produced a non-finite state after %ld steps", adapter->name, stats.steps);
  }
  if (interrupted(s)) {
    job->status = pd_gkError;
  } else if (!written) {
    job->status = pd_gkError;
    job->runDir[0] = '\0';
    job_note(job, "the run directory could not be written: %s", err.message[0] ? err.message : "a write failed");
  } else {
    bool copied = write_scene_copy(dir, c->sceneText);
    if (!completed) {
      job->status = pd_gkFail;
    } else if (!copied) {
      job->status = pd_gkError;
      job_note(job, "cannot write %s/scene.scene", job->runDir);
    } else {
      judge(job, &rec);
    }
    write_series(job, &rec);
  }
  pd_gk_record_free(&rec);
  free(dir);
}

// A run as one task of the batch: its row and series text travel as bytes (taskRow, then the series).
typedef struct taskRow {
  int32_t status;
  double measured, error, wallSeconds;
  char runDir[sizeof((gkJob*)0)->runDir];
  char note[sizeof((gkJob*)0)->note];
} taskRow;

static void run_task(int task, pdBatchBuffer* result, void* user) {
  gkSuite* s = user;
  gkJob* job = &s->jobs[task];
  run_job(s, job);
  taskRow row;
  memset(&row, 0, sizeof row);  // no uninitialised padding in the bytes
  row.status = (int32_t)job->status;
  row.measured = job->measured;
  row.error = job->error;
  row.wallSeconds = job->wallSeconds;
  memcpy(row.runDir, job->runDir, sizeof row.runDir);
  memcpy(row.note, job->note, sizeof row.note);
  pd_batch_append(result, &row, sizeof row);
  pd_batch_append(result, job->series.data, job->series.length);
}

static void take_result(gkJob* job, const pdBatchBuffer* result) {
  taskRow row;
  size_t at = 0;
  bool whole = pd_batch_read(result, &at, &row, sizeof row);
  PD_ASSERT(whole);
  job->status = (pdGkStatus)row.status;
  job->measured = row.measured;
  job->error = row.error;
  job->wallSeconds = row.wallSeconds;
  memcpy(job->runDir, row.runDir, sizeof row.runDir);
  memcpy(job->note, row.note, sizeof row.note);
  pd_gk_text_free(&job->series);
  if (result->size > at) pd_gk_text_printf(&job->series, "%.*s", (int)(result->size - at), (const char*)result->data + at);
  job->done = true;
}

static bool task_progress(int task, int done, int total, void* user) {
  const gkSuite* s = user;
  if (task >= 0 && s->options->progress) {
    const gkJob* job = &s->jobs[task];
    char engine[32];
    snprintf(engine, sizeof engine, "%s%s%s", pdGkEngineNames[job->engine], job->engine == pd_gkSoft ? "" : "-",
             job->engine == pd_gkSoft ? "" : variant_name(job));
    pdGkProgress p = {done, total, job->c->experiment->name, engine, job->c->label};
    s->options->progress(&p, s->options->progressUser);
  }
  return !interrupted(s);
}

// ---------------------------------------------------------------------------------------------------------
// the output files

static bool write_results(const gkSuite* s, pdError* err) {
  char* path = pdu_path_join(s->root, "results.csv");
  FILE* out = fopen(path, "w");
  free(path);
  if (!out) {
    pd_error_set(err, s->options->out, 0, 0, "cannot write results.csv: %s", strerror(errno));
    return false;
  }
  fputs("experiment,group,title,engine,variant,quantity,unit,input,measured,expected,error,tolerance,status,"
        "wall_seconds,run_dir,note\n",
        out);
  for (int i = 0; i < s->jobCount; ++i) {
    const gkJob* job = &s->jobs[i];
    const pdGkExperiment* e = job->c->experiment;
    bool judged = job->status == pd_gkPass || job->status == pd_gkFail || job->status == pd_gkNotApplicable;
    bool quantitative = isfinite(job->c->expected.value);
    pdu_csv_text(out, e->name);
    fprintf(out, ",%c,", e->group);
    pdu_csv_text(out, e->title);
    fprintf(out, ",%s,%s,", pdGkEngineNames[job->engine], variant_name(job));
    pdu_csv_text(out, e->quantity);
    fputc(',', out);
    pdu_csv_text(out, e->unit);
    fputc(',', out);
    pdu_csv_text(out, job->c->label);
    fputc(',', out);
    if (judged) pdu_csv_number(out, job->measured, 17);
    fputc(',', out);
    if (quantitative) pdu_csv_number(out, job->c->expected.value, 17);
    fputc(',', out);
    if (judged && quantitative) pdu_csv_number(out, job->error, 17);
    fputc(',', out);
    if (quantitative) pdu_csv_number(out, job->c->expected.tolerance, 17);
    fprintf(out, ",%s,", pdGkStatusNames[job->status]);
    pdu_csv_number(out, job->wallSeconds, 17);
    fputc(',', out);
    pdu_csv_text(out, job->runDir);
    fputc(',', out);
    pdu_csv_text(out, job->note);
    fputc('\n', out);
  }
  bool ok = !ferror(out);
  ok = fclose(out) == 0 && ok;
  if (!ok) pd_error_set(err, s->options->out, 0, 0, "cannot write results.csv");
  return ok;
}

static bool write_experiments(const gkSuite* s, pdError* err) {
  char* path = pdu_path_join(s->root, "experiments.json");
  FILE* out = fopen(path, "w");
  free(path);
  if (!out) {
    pd_error_set(err, s->options->out, 0, 0, "cannot write experiments.json: %s", strerror(errno));
    return false;
  }
  fputs("[", out);
  const pdGkExperiment* previous = NULL;
  for (int i = 0; i < s->caseCount; ++i) {
    const pdGkExperiment* e = s->cases[i].experiment;
    if (e == previous) continue;
    fputs(previous ? ",\n " : "\n ", out);
    previous = e;
    const struct {
      const char* key;
      const char* value;
    } fields[] = {{"name", e->name}, {"group", (char[]){e->group, '\0'}}, {"title", e->title},
                  {"quantity", e->quantity}, {"unit", e->unit}, {"formula", e->formula},
                  {"tolerance_reason", e->toleranceReason}};
    fputc('{', out);
    for (size_t f = 0; f < sizeof fields / sizeof fields[0]; ++f) {
      fprintf(out, "%s\"%s\": ", f ? ", " : "", fields[f].key);
      pdu_json_string(out, fields[f].value);
    }
    fprintf(out, ", \"qualitative\": %s, \"kind\": \"%s\", \"applies_to\": [", e->qualitative ? "true" : "false",
            pdGkKindNames[e->kind]);
    for (int engine = 0, n = 0; engine < pd_gkEngineCount; ++engine)
      for (int v = 0; v < (engine == pd_gkSoft ? 1 : 2); ++v)
        if (pd_gk_applies(e, (pdGkEngine)engine, v))
          fprintf(out, "%s\"%s-%s\"", n++ ? ", " : "", pdGkEngineNames[engine], variant_of((pdGkEngine)engine, v));
    fputs("], \"not_applicable_reason\": ", out);
    if (e->kind == pd_gkLaw) fputs("null", out);
    else pdu_json_string(out, e->notApplicableReason);
    fputs(", \"scene\": \"generated\", \"series_label\": ", out);
    pdu_json_string(out, e->seriesLabel);
    fputc('}', out);
  }
  fputs("\n]\n", out);
  bool ok = !ferror(out);
  ok = fclose(out) == 0 && ok;
  if (!ok) pd_error_set(err, s->options->out, 0, 0, "cannot write experiments.json");
  return ok;
}

static bool write_series_files(const gkSuite* s, pdError* err) {
  char* dir = pdu_path_join(s->root, "series");
  bool ok = make_dir(dir, err);
  for (int i = 0; ok && i < s->jobCount;) {
    const pdGkExperiment* e = s->jobs[i].c->experiment;
    char file[160];
    snprintf(file, sizeof file, "%s.csv", e->name);
    char* path = pdu_path_join(dir, file);
    FILE* out = fopen(path, "w");
    free(path);
    if (!out) {
      pd_error_set(err, s->options->out, 0, 0, "cannot write series/%s: %s", file, strerror(errno));
      ok = false;
      break;
    }
    fputs("t,engine,variant,input,value,analytic\n", out);
    for (; i < s->jobCount && s->jobs[i].c->experiment == e; ++i)
      if (s->jobs[i].series.data) fputs(s->jobs[i].series.data, out);
    ok = !ferror(out);
    ok = fclose(out) == 0 && ok;
    if (!ok) pd_error_set(err, s->options->out, 0, 0, "cannot write series/%s", file);
  }
  free(dir);
  return ok;
}

// Moves the finished temporary directory into place, replacing a previous gedanken directory.
static bool install(const gkSuite* s, pdError* err) {
  const char* out = s->options->out;
  char* old = NULL;
  struct stat st;
  bool ok = true;
  if (stat(out, &st) == 0) {
    if (!pd_gk_out_replaceable(out, err)) return false;
    size_t n = strlen(out) + 16;
    old = malloc(n);
    PD_ASSERT(old != NULL);
    snprintf(old, n, "%s.old-XXXXXX", out);
    ok = mkdtemp(old) != NULL && rename(out, old) == 0;
  }
  ok = ok && rename(s->root, out) == 0;
  if (!ok) pd_error_set(err, out, 0, 0, "cannot move the results into place: %s", strerror(errno));
  if (old) {
    if (ok) pdu_remove_tree(old);
    free(old);
  }
  return ok;
}

// ---------------------------------------------------------------------------------------------------------
// the suite

static bool selected(const pdGkOptions* o, const pdGkExperiment* e) {
  if (o->fast && !e->fast) return false;
  if (!o->only) return true;
  for (int i = 0; i < o->onlyCount; ++i)
    if (strcmp(o->only[i], e->name) == 0) return true;
  return false;
}

int pd_gk_selected_count(const pdGkOptions* options) {
  int count = 0;
  for (int i = 0; i < pd_gk_experiment_count(); ++i) count += selected(options, pd_gk_experiment(i));
  return count;
}

static bool build_case(gkCase* c, const pdGkExperiment* e, double input, double toleranceScale, pdError* err) {
  c->experiment = e;
  c->input = input;
  pd_gk_input_label(e, input, c->label, sizeof c->label);
  pdGkText text = {0};
  e->scene(input, &text);
  c->sceneText = text.data;
  pdScene* scene = pd_scene_parse_buffer("scene.scene", text.data, text.length, err);
  if (scene) {
    c->model = pd_model_compile(scene, err);
    pd_scene_free(scene);
  }
  if (!c->model) {
    // a generated scene that does not compile is a bug of the catalogue: say which one
    char message[PD_ERROR_MESSAGE_MAX];
    snprintf(message, sizeof message, "%s", err->message);
    pd_error_set(err, e->name, err->line, err->col, "generated scene %s: %s", c->label, message);
    return false;
  }
  c->expected = e->expect(c->model, input);
  PD_ASSERT(!e->relative || !isfinite(c->expected.value) || c->expected.value != 0.0);
  c->expected.tolerance *= toleranceScale;
  return true;
}

static void free_suite(gkSuite* s) {
  for (int i = 0; i < s->caseCount; ++i) {
    free(s->cases[i].sceneText);
    if (s->cases[i].model) pd_model_free(s->cases[i].model);
  }
  for (int i = 0; i < s->jobCount; ++i) pd_gk_text_free(&s->jobs[i].series);
  free(s->cases);
  free(s->jobs);
  if (s->root) {
    if (pd_batch_is_root()) pdu_remove_tree(s->root);  // nothing when it was installed (renamed away)
    free(s->root);
  }
}

bool pd_gk_run_suite(const pdGkOptions* options, pdGkSummary* summary, pdError* err) {
  PD_ASSERT(options && options->out && summary && options->jobs >= 1 && options->toleranceScale > 0.0);
  PD_ASSERT(!options->precision || options->repeats >= 1);
  memset(summary, 0, sizeof *summary);
  double wall0 = gk_wall_seconds();
  for (int i = 0; i < options->onlyCount; ++i)
    if (!pd_gk_find(options->only[i])) {
      pd_error_set(err, options->only[i], 0, 0, "no such experiment");
      return false;
    }
  if (!pd_gk_out_replaceable(options->out, err)) return false;

  gkSuite s = {.options = options};
  int maxCases = pd_gk_experiment_count() * PD_GK_MAX_INPUTS;
  s.cases = calloc((size_t)maxCases, sizeof *s.cases);
  s.jobs = calloc((size_t)maxCases * 5, sizeof *s.jobs);
  PD_ASSERT(s.cases && s.jobs);
  bool ok = true;
  for (int i = 0; ok && i < pd_gk_experiment_count(); ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    if (!selected(options, e)) continue;
    for (int k = 0; ok && k < e->inputCount; ++k) {
      gkCase* c = &s.cases[s.caseCount++];
      ok = build_case(c, e, e->inputs[k], options->toleranceScale, err);
      for (int engine = 0; ok && engine < pd_gkEngineCount; ++engine) {
        if (!options->engines[engine]) continue;
        for (int v = 0; v < (engine == pd_gkSoft ? 1 : 2); ++v) {
          gkJob* job = &s.jobs[s.jobCount];
          *job = (gkJob){.c = c, .engine = (pdGkEngine)engine, .variant = v ? pd_refMatched : pd_refNative};
          ++s.jobCount;
        }
      }
    }
  }
  if (ok && s.jobCount == 0) {
    pd_error_set(err, options->out, 0, 0, "no experiment selected");
    ok = false;
  }
  // rank 0 makes the temporary directory and its runs/NAME/ directories; every rank learns its name
  enum { ROOT_MAX = 4200 };
  char root[ROOT_MAX] = "";
  if (ok && pd_batch_is_root() && strlen(options->out) + 24 < ROOT_MAX) {
    snprintf(root, sizeof root, "%s.partial-XXXXXX", options->out);
    pdu_make_parents(options->out);  // a real failure shows when the directory is made
    if (!mkdtemp(root)) {
      pd_error_set(err, options->out, 0, 0, "cannot create the output directory: %s", strerror(errno));
      root[0] = '\0';
    } else {
      mode_t mask = umask(0);  // mkdtemp makes the directory private; the results get the usual permissions
      umask(mask);
      chmod(root, 0777 & ~mask);
      s.root = strdup(root);
      PD_ASSERT(s.root != NULL);
      char* runs = pdu_path_join(s.root, "runs");
      bool made = make_dir(runs, err);
      for (int i = 0; made && i < s.caseCount; ++i) {
        if (i > 0 && s.cases[i].experiment == s.cases[i - 1].experiment) continue;
        char* dir = pdu_path_join(runs, s.cases[i].experiment->name);
        made = make_dir(dir, err);
        free(dir);
      }
      free(runs);
      if (!made) root[0] = '\0';
    }
  }
  if (ok) {
    pd_batch_share(root, sizeof root);
    if (!root[0]) {
      if (!err->message[0]) pd_error_set(err, options->out, 0, 0, "rank 0 could not create the output directory");
      ok = false;
    } else if (!s.root) {
      s.root = strdup(root);
      PD_ASSERT(s.root != NULL);
    }
  }
  if (ok) {
    pdBatchBuffer* results = calloc((size_t)s.jobCount, sizeof *results);
    PD_ASSERT(results != NULL);
    pdBatchOptions batch = {.workers = options->jobs, .everywhere = true, .progress = task_progress, .progressUser = &s};
    char why[256] = "";
    ok = pd_batch_run(s.jobCount, run_task, &s, &batch, results, why, sizeof why);
    for (int i = 0; i < s.jobCount; ++i) {
      if (ok) take_result(&s.jobs[i], &results[i]);
      pd_batch_buffer_free(&results[i]);
    }
    free(results);
    if (interrupted(&s)) {
      summary->interrupted = true;
      pd_error_set(err, options->out, 0, 0, "interrupted; nothing written");
    } else if (!ok) {
      pd_error_set(err, options->out, 0, 0, "%s", why);
    }
  }
  // a run directory that could not be written (a full disk, a file-size limit) fails the whole suite: its rows
  // would replace a complete earlier result with ERROR rows that measure the disk, not the engine
  for (int i = 0; ok && !interrupted(&s) && i < s.jobCount; ++i)
    if (s.jobs[i].status == pd_gkError) {
      pd_error_set(err, options->out, 0, 0, "%s %s%s%s: %s; nothing written", s.jobs[i].c->experiment->name,
                   pdGkEngineNames[s.jobs[i].engine], s.jobs[i].c->label[0] ? " " : "", s.jobs[i].c->label,
                   s.jobs[i].note);
      ok = false;
    }
  if (ok && options->precision) {
    ok = gk_precision_run(options, s.cases, s.caseCount, s.root, err);
    summary->interrupted = interrupted(&s);
  }
  // rank 0 writes the files; every rank has every row (the same summary, the same exit status)
  if (pd_batch_is_root())
    ok = ok && write_results(&s, err) && write_experiments(&s, err) && write_series_files(&s, err) && install(&s, err);
  if (ok) {
    free(s.root);
    s.root = NULL;
    summary->rows = s.jobCount;
    for (int i = 0; i < s.jobCount; ++i) {
      const gkJob* job = &s.jobs[i];
      ++summary->count[job->status];
      if (job->engine == pd_gkSoft && (job->status == pd_gkFail || job->status == pd_gkError)) {
        size_t used = strlen(summary->softFailed), room = sizeof summary->softFailed - used;
        int n = snprintf(summary->softFailed + used, room, "%s%s%s%s", summary->softFailures ? ", " : "",
                         job->c->experiment->name, job->c->label[0] ? " " : "", job->c->label);
        if (n < 0 || (size_t)n >= room) strcpy(summary->softFailed + sizeof summary->softFailed - 4, "...");
        ++summary->softFailures;
      }
    }
  }
  summary->wallSeconds = gk_wall_seconds() - wall0;
  free_suite(&s);
  return ok;
}
