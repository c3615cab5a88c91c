// polydyn cubetoss — real cube tosses in every engine, and fitting each engine's free parameters to them
// (docs/DESIGN.md §8.4; the library part is validation/include/pdval/cubetoss.h).
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdutil/csv.h"
#include "pdrun/batch.h"
#include "pdval/cubetoss.h"
#include "polydyn/output.h"

// Longest --out path: the run directories' paths below it fit the fixed buffers.
#define CUBETOSS_PATH_MAX 3000
enum { ENGINES_MAX = 4, PARAM_FILES_MAX = 8 };
// Fit defaults: evaluations of the objective (each one run of every training toss) and the simplex size
// (scaled units: log10 μ, e, log10 k_n) below which a further step cannot matter against the noise of
// the objective across tosses.
#define FIT_DEFAULT_MAX_EVALUATIONS 100
#define FIT_DEFAULT_SIZE_TOL 0.01
#define DEFAULT_JOBS 2  // the machine's two cores (DESIGN: the tosses are independent)

static const char* const help =
    "usage: polydyn cubetoss --data FILE.csv --out DIR [--engines soft,ode,bullet] [--tosses LIST]\n"
    "                        [--params [ENGINE=]FILE]... [--label WORD] [--variant native|matched] [--step H]\n"
    "                        [--tol T] [--inertia I|uniform] [--jobs N] [--no-runs]\n"
    "       polydyn cubetoss fit --data FILE.csv --out DIR [--engines ...] [--tosses LIST] [--train-every K]\n"
    "                        [--max-evals N] [--size-tol S] [--params [ENGINE=]FILE]... [--variant ...] [--step H]\n"
    "                        [--tol T] [--inertia I|uniform] [--jobs N]\n"
    "\n"
    "Simulates real cube tosses (CSV `toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz` at 148 Hz, e.g.\n"
    "shared/data/cube-toss/tosses-train.csv from the ContactNets data set) from each toss's first sample to its\n"
    "last, sampled at 148 Hz, and compares them with the record: position error in cube widths and rotation\n"
    "angle error, at the end and RMS over the toss. The same for real planar drops (CSV `drop,t,x,z,th,vx,vz,vth`\n"
    "at 250 Hz, e.g. shared/data/planar-drops/drops-given.csv; the header decides), the block held in the x-z\n"
    "plane, errors in side lengths, plus the first three bounces (docs/planar-drops.md). Writes DIR/per_toss.csv\n"
    "(one row per toss and engine),\n"
    "DIR/summary.csv (mean, median and 90th percentile per engine, for all, training and test tosses), the\n"
    "parameter fragments used (DIR/params-ENGINE.scene) and, unless --no-runs, DIR/runs/TOSS/record/ (the\n"
    "record as a run directory) beside DIR/runs/TOSS/ENGINE[-VARIANT]/, for replay.\n"
    "\n"
    "`fit` fits each engine's free parameters (mu, restitution, kn; kn not for the native reference engines)\n"
    "on the training tosses (even positions in the file) with GSL's Nelder-Mead simplex, minimising the mean\n"
    "end position error (cube widths) + the mean end rotation error (rad), and runs the test tosses (odd\n"
    "positions) with the starting and the fitted parameters. Writes DIR/fitted-ENGINE.scene (read by\n"
    "--params), DIR/fit.csv, DIR/fit_trace.csv (every evaluation), DIR/per_toss.csv and DIR/summary.csv.\n"
    "\n"
    "  --engines LIST   soft, ode, bullet, noise (default: soft,ode,bullet; one without an adapter is reported,\n"
    "                   skipped; noise: the record one sample late, the floor of the errors)\n"
    "  --tosses LIST    all (default), train, test, or toss ids and ranges: 1-20,35\n"
    "  --params [ENGINE=]FILE  mu/restitution/kn lines over the defaults (mu 0.18, restitution 0.125,\n"
    "                   kn 2.1e6 N/m on the cube and the board), for ENGINE or every engine; repeatable\n"
    "  --label WORD     the params column of the CSVs (default: default, or params with --params)\n"
    "  --variant V      of ode and bullet: native (default: their own contact) or matched (our k, c)\n"
    "  --step H         the reference engines' step, s (default 1e-3)\n"
    "  --tol T          the soft engine's integration tolerance (default 1e-6)\n"
    "  --inertia I      the cube's moment of inertia, kg m^2 (default 8.1e-4, the data's), or uniform\n"
    "  --jobs N         worker processes (default 2; 1 per rank under mpirun or srun, where the tosses\n"
    "                   are split over the ranks: docs/commands.md)\n"
    "  --no-runs        keep no run directories (only the CSVs)\n"
    "  --train-every K  fit on every K-th training toss (default 1: all)\n"
    "  --max-evals N    objective evaluations per engine (default 100); --size-tol S simplex size (0.01)\n"
    "\n"
    "DIR is written under a temporary name and renamed when complete. Progress on stderr when a terminal.\n"
    "Exit status: 0 ok, 1 a soft-engine run failed (or the work could not finish), 2 bad input, 130\n"
    "interrupted (nothing written).\n";

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}

// ---------------------------------------------------------------- options

typedef struct engineSpec {
  const char* name;     // soft, ode, bullet
  char label[24];       // soft, ode-native, ...: run directories, messages
  const char* variant;  // implicit (the soft engine's default stepper), native, matched
  pdTossEngine engine;
  pdTossParams params;
  const char* paramsFile;  // nullable
  bool built;
} engineSpec;

typedef struct options {
  bool fit;
  const char* data;
  const char* out;
  const char* engines;
  const char* tosses;
  const char* label;
  pdRefVariant variant;
  double step;
  double tol;
  double inertia;
  bool inertiaGiven;
  int jobs;
  bool runs;
  int trainEvery;
  int maxEvals;
  double sizeTol;
  const char* paramEngine[PARAM_FILES_MAX];  // "" = every engine
  const char* paramFile[PARAM_FILES_MAX];
  int paramCount;
} options;

static bool positive_int(const char* text, int* value) {
  char* end = NULL;
  errno = 0;
  long v = strtol(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || v < 1 || v > 1000000) return false;
  *value = (int)v;
  return true;
}

static const char* const engineOrder[ENGINES_MAX] = {"soft", "ode", "bullet", "noise"};

static bool known_engine(const char* name, size_t len) {
  for (int i = 0; i < ENGINES_MAX; ++i) {
    const char* const* known = engineOrder;
    if (strlen(known[i]) == len && strncmp(name, known[i], len) == 0) return true;
  }
  return false;
}

// --engines: a comma-separated list of soft, ode, bullet and noise.
static bool accept_engines(const char* cmd, const char* v, void* target) {
  for (const char* p = v; p;) {
    const char* comma = strchr(p, ',');
    size_t len = comma ? (size_t)(comma - p) : strlen(p);
    if (!known_engine(p, len)) {
      pd_cli_usage_error(cmd, "--engines: unknown engine '%.*s' (soft, ode, bullet, noise)", (int)(len < 40 ? len : 40),
                         p);
      return false;
    }
    p = comma ? comma + 1 : NULL;
  }
  *(const char**)target = v;
  return true;
}

// --params [ENGINE=]FILE: up to PARAM_FILES_MAX of them.
static bool accept_params(const char* cmd, const char* v, void* target) {
  options* o = target;
  if (o->paramCount == PARAM_FILES_MAX) {
    pd_cli_usage_error(cmd, "at most %d --params", PARAM_FILES_MAX);
    return false;
  }
  const char* eq = strchr(v, '=');
  const char* engine = "";
  if (eq && known_engine(v, (size_t)(eq - v))) {
    engine = v;
    v = eq + 1;
  }
  if (!v[0]) {
    pd_cli_usage_error(cmd, "--params needs a file name");
    return false;
  }
  o->paramEngine[o->paramCount] = engine;
  o->paramFile[o->paramCount++] = v;
  return true;
}

static bool accept_label(const char* cmd, const char* v, void* target) {
  if (!v[0] || strpbrk(v, ",\"\n\r ")) {
    pd_cli_usage_error(cmd, "--label needs one word (no comma, quote, space)");
    return false;
  }
  *(const char**)target = v;
  return true;
}

static bool accept_inertia(const char* cmd, const char* v, void* target) {
  if (strcmp(v, "uniform") == 0) {
    *(double*)target = 0.0;
    return true;
  }
  if (pd_cli_positive(v, target)) return true;
  pd_cli_usage_error(cmd, "--inertia needs a number > 0 (kg m^2) or uniform");
  return false;
}

static bool accept_no_runs(const char* cmd, const char* v, void* target) {
  (void)cmd, (void)v;
  *(bool*)target = false;
  return true;
}

static bool accept_train_every(const char* cmd, const char* v, void* target) {
  if (positive_int(v, target)) return true;
  pd_cli_usage_error(cmd, "--train-every needs an integer >= 1");
  return false;
}

static bool accept_max_evals(const char* cmd, const char* v, void* target) {
  if (positive_int(v, target)) return true;
  pd_cli_usage_error(cmd, "--max-evals needs an integer >= 1");
  return false;
}

static const char* const variantWords[] = {"native", "matched", NULL};
static const int variantValues[] = {pd_refNative, pd_refMatched};

// Parses argv into o; returns -1 to go on, else an exit status (help printed, or a usage error).
static int parse_options(int argc, char** argv, options* o) {
  const char* cmd = o->fit ? "cubetoss fit" : "cubetoss";
  const char* fitOnly = o->fit ? NULL : "%s is for polydyn cubetoss fit";
  int variant = o->variant;
  char jobsMessage[64];
  snprintf(jobsMessage, sizeof jobsMessage, "--jobs needs an integer in 1..%d", PD_CLI_MAX_JOBS);
  const pdCliOption table[] = {
      {.name = "--no-runs", .kind = pd_optFlag, .target = &o->runs, .accept = accept_no_runs,
       .refuse = o->fit ? "--no-runs is for polydyn cubetoss (fit keeps no runs)" : NULL},
      {.name = "--data", .kind = pd_optText, .target = &o->data, .message = "--data needs a file name", .min = 1},
      {.name = "--out", .kind = pd_optText, .target = &o->out, .message = "--out needs a file name", .min = 1},
      {.name = "--engines", .kind = pd_optAccept, .target = &o->engines, .accept = accept_engines},
      {.name = "--tosses", .kind = pd_optText, .target = &o->tosses, .message = "--tosses needs a list", .min = 1},
      {.name = "--params", .kind = pd_optAccept, .target = o, .accept = accept_params},
      {.name = "--label", .kind = pd_optAccept, .target = &o->label, .accept = accept_label},
      {.name = "--variant", .kind = pd_optChoice, .target = &variant, .message = "--variant must be native or matched",
       .words = variantWords, .values = variantValues},
      {.name = "--step", .kind = pd_optPositive, .target = &o->step, .message = "--step needs a number > 0"},
      {.name = "--tol", .kind = pd_optAccept, .target = &o->tol, .accept = pd_cli_accept_tol},
      {.name = "--inertia", .kind = pd_optAccept, .target = &o->inertia, .accept = accept_inertia,
       .given = &o->inertiaGiven},
      {.name = "--jobs", .kind = pd_optJobs, .target = &o->jobs, .message = jobsMessage},
      {.name = "--train-every", .kind = pd_optAccept, .target = &o->trainEvery, .accept = accept_train_every,
       .refuse = fitOnly},
      {.name = "--max-evals", .kind = pd_optAccept, .target = &o->maxEvals, .accept = accept_max_evals,
       .refuse = fitOnly},
      {.name = "--size-tol", .kind = pd_optPositive, .target = &o->sizeTol, .message = "--size-tol needs a number > 0",
       .refuse = fitOnly},
  };
  // no positional argument ("fit" is taken before): anything starting with '-' is an unknown option
  pdCliPositionals none = {.tooMany = "unexpected argument '%s'", .loneDashIsOption = true};
  int parsed = pd_cli_parse_options(cmd, argc, argv, table, sizeof table / sizeof table[0], &none, help);
  if (parsed >= 0) return parsed;
  o->variant = (pdRefVariant)variant;
  if (!o->data) return pd_cli_usage_error(cmd, "--data FILE.csv is required");
  if (!o->out) return pd_cli_usage_error(cmd, "--out DIR is required");
  if (strlen(o->out) > CUBETOSS_PATH_MAX) return pd_cli_usage_error(cmd, "--out: path longer than %d bytes", CUBETOSS_PATH_MAX);
  for (int k = 0; k < o->paramCount; ++k) {
    if (!o->paramEngine[k][0]) continue;
    size_t len = (size_t)(strchr(o->paramEngine[k], '=') - o->paramEngine[k]);
    char name[16];
    snprintf(name, sizeof name, "%.*s", (int)len, o->paramEngine[k]);
    if (!pd_cli_list_has(o->engines, name)) return pd_cli_usage_error(cmd, "--params %s=...: %s is not among --engines", name, name);
  }
  return -1;
}

// The engines of --engines in the fixed order soft, ode, bullet, noise, with their parameters.
static int make_engines(const options* o, const pdTossExperiment* experiment, engineSpec* specs, char* why,
                        size_t whySize) {
  int n = 0;
  for (int e = 0; e < ENGINES_MAX; ++e) {
    if (!pd_cli_list_has(o->engines, engineOrder[e])) continue;
    engineSpec* s = &specs[n++];
    memset(s, 0, sizeof *s);
    s->name = engineOrder[e];
    bool soft = e == 0, noise = e == 3;
    s->variant = soft ? "implicit" : noise ? "shift1" : o->variant == pd_refMatched ? "matched" : "native";
    snprintf(s->label, sizeof s->label, soft || noise ? "%s" : "%s-%s", s->name, s->variant);
    s->engine = (pdTossEngine){.name = s->name,
                               .ref = {.variant = o->variant, .step = o->step, .odeFriction = pd_odeFrictionPyramid}};
    s->built = soft || noise || pd_ref_adapter(s->name) != NULL;
    s->params = pd_toss_experiment_params(experiment);
    s->params.tol = o->tol;
    if (o->inertiaGiven) s->params.inertia = o->inertia;
    // files for every engine first, then the engine's own, each in the order given
    for (int pass = 0; pass < 2; ++pass)
      for (int k = 0; k < o->paramCount; ++k) {
        const char* pe = o->paramEngine[k];
        bool mine = pe[0] && strncmp(pe, s->name, strlen(s->name)) == 0 && pe[strlen(s->name)] == '=';
        if ((pass == 0 && pe[0]) || (pass == 1 && !mine)) continue;
        pdError err = {0};
        if (!pd_toss_params_read(o->paramFile[k], &s->params, &err)) {
          if (err.line > 0)
            snprintf(why, whySize, "%.300s:%d:%d: %.400s", err.file, err.line, err.col, err.message);
          else
            snprintf(why, whySize, "%.300s: %.400s", err.file, err.message);
          return -1;
        }
        s->paramsFile = o->paramFile[k];
      }
  }
  return n;
}

// ---------------------------------------------------------------- output directory

// ---------------------------------------------------------------- CSVs

// One toss in every engine: the result of one job.
typedef struct tossJobResult {
  pdTossResult engines[ENGINES_MAX];
  bool recordOk;
  char recordMessage[256];
} tossJobResult;

typedef struct runContext {
  const pdTossSet* set;
  const int* tosses;
  const engineSpec* specs;
  int engineCount;
  const char* runsDir;  // nullable: no run directories
  const pdTossParams* overrideParams;  // nullable: every engine runs these (fit's test runs)
} runContext;

static void toss_job(int i, void* out, void* user) {
  const runContext* c = user;
  tossJobResult* r = out;
  const pdToss* toss = &c->set->tosses[c->tosses[i]];
  char dir[4400];
  if (c->runsDir) {
    snprintf(dir, sizeof dir, "%s/%ld", c->runsDir, toss->id);
    mkdir(dir, 0777);
    snprintf(dir, sizeof dir, "%s/%ld/record", c->runsDir, toss->id);
    pdError err = {0};
    r->recordOk = pd_toss_write_record(toss, &c->specs[0].params, dir, c->set->path, &err);
    if (!r->recordOk) snprintf(r->recordMessage, sizeof r->recordMessage, "%.240s", err.message);
  }
  for (int e = 0; e < c->engineCount; ++e) {
    const engineSpec* s = &c->specs[e];
    const pdTossParams* p = c->overrideParams ? &c->overrideParams[e] : &s->params;
    if (c->runsDir) snprintf(dir, sizeof dir, "%s/%ld/%s", c->runsDir, toss->id, s->label);
    pdTrajectory* tr = pd_toss_simulate(toss, p, &s->engine, c->runsDir && s->built ? dir : NULL, &r->engines[e]);
    pd_trajectory_free(tr);
  }
}

typedef struct progressState {
  const char* what;
  bool terminal;
  double start, lastPrint;
  int evaluation;  // fit: evaluations seen (a new one starts at done == 0)
  bool fitting;
} progressState;

static bool show_progress(int done, int total, void* user) {
  progressState* p = user;
  if (p->fitting && done == 0) ++p->evaluation;
  if (p->terminal) {
    double now = pd_cli_wall_seconds();
    if (now - p->lastPrint > 0.2 || done == total) {
      p->lastPrint = now;
      if (p->fitting)
        fprintf(stderr, "\rpolydyn cubetoss fit: %s, evaluation %d, toss %d/%d, %.0f s\033[K", p->what, p->evaluation,
                done, total, now - p->start);
      else
        fprintf(stderr, "\rpolydyn cubetoss: %s %d/%d tosses, %.0f s\033[K", p->what, done, total, now - p->start);
    }
  }
  return !interrupted;
}

// Planar experiments add their bounces after the pose errors (pdTossResult).
static void per_toss_header(FILE* out, const pdTossExperiment* ex) {
  fputs("toss,split,engine,variant,params,status,samples,duration_s,pos_err_end,pos_err_rms,rot_err_end_rad,"
        "rot_err_rms_rad,",
        out);
  if (ex->planar) {
    fputs("impacts_record,impacts_run,", out);
    for (int k = 1; k <= PD_TOSS_IMPACTS; ++k) fprintf(out, "impact%d_dt_s,impact%d_dv,impact%d_dw,", k, k, k);
  }
  fputs("wall_seconds,cpu_seconds,steps,run_dir,message\n", out);
}

static void per_toss_row(FILE* out, const pdToss* toss, int index, const engineSpec* s, const char* label,
                         const pdTossResult* r, bool runs) {
  fprintf(out, "%ld", toss->id);
  const char* const texts[] = {pd_toss_split_name(pd_toss_split(index)), s->name, s->variant, label,
                               pd_toss_status_name(r->status)};
  for (int k = 0; k < 5; ++k) {
    fputc(',', out);
    pdu_csv_text(out, texts[k]);
  }
  fprintf(out, ",%d,%.9g,", r->samples, (double)(toss->sampleCount - 1) / toss->experiment->rate);
  const double values[] = {r->posErrEnd, r->posErrRms, r->rotErrEnd, r->rotErrRms};
  for (int k = 0; k < 4; ++k) {
    pdu_csv_number(out, values[k], 9);
    fputc(',', out);
  }
  if (toss->experiment->planar) {
    if (r->status == pd_tossOk) fprintf(out, "%d,%d,", r->impactsRecord, r->impactsRun);
    else fputs(",,", out);
    for (int k = 0; k < PD_TOSS_IMPACTS; ++k) {
      const double impact[3] = {r->impactDt[k], r->impactDv[k], r->impactDw[k]};
      for (int j = 0; j < 3; ++j) {
        pdu_csv_number(out, impact[j], 9);
        fputc(',', out);
      }
    }
  }
  if (r->status == pd_tossOk || r->status == pd_tossFailed) {
    fprintf(out, "%.6g,%.6g,%ld,", r->wallSeconds, r->cpuSeconds, r->steps);
  } else {
    fputs(",,,", out);
  }
  if (runs && r->runWritten) fprintf(out, "runs/%ld/%s", toss->id, s->label);
  fputc(',', out);
  pdu_csv_text(out, r->message);
  fputc('\n', out);
}

static void summary_header(FILE* out) {
  fputs("engine,variant,params,split,status,tosses,completed,quantity,unit,mean,median,p90\n", out);
}

// The first POSE_QUANTITIES for every experiment, the bounces' for planar ones only.
enum { POSE_QUANTITIES = 6, QUANTITIES = POSE_QUANTITIES + 3 * PD_TOSS_IMPACTS };
static const char* const quantityNames[QUANTITIES] = {
    "pos_err_end", "pos_err_rms", "rot_err_end", "rot_err_rms", "wall_seconds", "cpu_seconds",
    "impact1_dt",  "impact1_dv",  "impact1_dw",  "impact2_dt",  "impact2_dv",   "impact2_dw",
    "impact3_dt",  "impact3_dv",  "impact3_dw"};
static const char* const quantityUnits[QUANTITIES] = {"", "", "rad", "rad", "s", "s", "s", "m/s", "rad/s",
                                                      "s", "m/s", "rad/s", "s", "m/s", "rad/s"};

static int quantity_count(const pdTossExperiment* ex) { return ex->planar ? QUANTITIES : POSE_QUANTITIES; }
static const char* quantity_unit(const pdTossExperiment* ex, int q) { return q < 2 ? ex->lengthUnit : quantityUnits[q]; }

static double quantity(const pdTossResult* r, int q) {
  if (q >= POSE_QUANTITIES) {
    int k = (q - POSE_QUANTITIES) / 3, j = (q - POSE_QUANTITIES) % 3;
    return j == 0 ? r->impactDt[k] : j == 1 ? r->impactDv[k] : r->impactDw[k];
  }
  const double v[POSE_QUANTITIES] = {r->posErrEnd, r->posErrRms, r->rotErrEnd, r->rotErrRms,
                                     r->status == pd_tossOk ? r->wallSeconds : NAN,
                                     r->status == pd_tossOk ? r->cpuSeconds : NAN};
  return v[q];
}

// Statistics of one engine over the tosses of one split ("all", "train", "test"); results[i] belongs to
// toss position indices[i]. Writes nothing when the split has no toss.
typedef struct splitStats {
  int tosses, completed;
  pdTossStats q[QUANTITIES];
} splitStats;

static splitStats split_stats(const pdTossResult* const* results, const int* indices, int count, const char* split) {
  splitStats s = {0};
  double* v = malloc((size_t)(count > 0 ? count : 1) * sizeof *v);
  if (!v) abort();
  for (int q = 0; q < QUANTITIES; ++q) {
    int n = 0;
    s.tosses = s.completed = 0;
    for (int i = 0; i < count; ++i) {
      if (strcmp(split, "all") != 0 && strcmp(pd_toss_split_name(pd_toss_split(indices[i])), split) != 0) continue;
      ++s.tosses;
      s.completed += results[i]->status == pd_tossOk;
      v[n++] = quantity(results[i], q);
    }
    s.q[q] = pd_toss_stats(v, n);
  }
  free(v);
  return s;
}

static const char* summary_status(const engineSpec* spec, const splitStats* s) {
  if (!spec->built) return "not built";
  if (s->completed == s->tosses) return "ok";
  return s->completed == 0 ? "failed" : "partial";
}

static void summary_rows(FILE* out, const pdTossExperiment* ex, const engineSpec* spec, const char* label,
                         const pdTossResult* const* results, const int* indices, int count) {
  static const char* const splits[] = {"all", "train", "test"};
  for (int k = 0; k < 3; ++k) {
    splitStats s = split_stats(results, indices, count, splits[k]);
    if (s.tosses == 0) continue;
    for (int q = 0; q < quantity_count(ex); ++q) {
      const char* const texts[] = {spec->name, spec->variant, label, splits[k], summary_status(spec, &s)};
      for (int t = 0; t < 5; ++t) {
        pdu_csv_text(out, texts[t]);
        fputc(',', out);
      }
      fprintf(out, "%d,%d,", s.tosses, s.completed);
      pdu_csv_text(out, quantityNames[q]);
      fputc(',', out);
      pdu_csv_text(out, quantity_unit(ex, q));
      fputc(',', out);
      pdu_csv_number(out, s.q[q].mean, 9);
      fputc(',', out);
      pdu_csv_number(out, s.q[q].median, 9);
      fputc(',', out);
      pdu_csv_number(out, s.q[q].p90, 9);
      fputc('\n', out);
    }
  }
}

// The table a person reads first: per engine and split, median and 90th percentile of the end errors.
static void print_table(const engineSpec* spec, const char* label, const pdTossResult* const* results,
                        const int* indices, int count, bool header) {
  if (header)
    printf("%-15s %-8s %-6s %9s  %-19s  %-19s  %-19s %10s %10s\n", "engine", "params", "split", "completed",
           "pos end (widths)", "rot end (deg)", "pos rms (widths)", "wall/toss", "cpu/toss");
  static const char* const splits[] = {"all", "train", "test"};
  const double deg = 180.0 / 3.14159265358979323846;
  char name[40];
  snprintf(name, sizeof name, "%s%s%s", spec->name, strcmp(spec->name, "soft") ? "-" : "",
           strcmp(spec->name, "soft") ? spec->variant : "");
  for (int k = 0; k < 3; ++k) {
    splitStats s = split_stats(results, indices, count, splits[k]);
    if (s.tosses == 0) continue;
    if (!spec->built) {
      printf("%-15s %-8s %-6s %9s\n", name, label, splits[k], "not built");
      return;
    }
    char completed[24];
    snprintf(completed, sizeof completed, "%d/%d", s.completed, s.tosses);
    if (s.completed == 0) {  // no numbers to show (and never a NaN)
      printf("%-15s %-8s %-6s %9s  none completed\n", name, label, splits[k], completed);
      continue;
    }
    printf("%-15s %-8s %-6s %9s  med %5.3f p90 %5.3f  med %5.1f p90 %5.1f  med %5.3f p90 %5.3f %8.3f s %8.3f s\n",
           name, label, splits[k], completed, s.q[0].median, s.q[0].p90, s.q[2].median * deg, s.q[2].p90 * deg,
           s.q[1].median, s.q[1].p90, s.q[4].mean, s.q[5].mean);
    if (s.q[POSE_QUANTITIES + 1].n > 0)  // planar experiments: the first bounce
      printf("%-15s %-8s %-6s %9s  first bounce: %d/%d found, time med %.4f s, velocity med %.3f m/s, spin med %.2f rad/s\n",
             "", "", "", "", s.q[POSE_QUANTITIES + 1].n, s.tosses, s.q[POSE_QUANTITIES].median,
             s.q[POSE_QUANTITIES + 1].median, s.q[POSE_QUANTITIES + 2].median);
  }
}

// The results of one parameter set over a list of tosses (a cubetoss run has one, fit two).
typedef struct resultGroup {
  const char* label;              // the params column
  const tossJobResult* results;   // (count) one per toss, in toss order
  const int* indices;             // (count) set indices of the tosses
  int count;
  bool runs;                      // run directories were kept
} resultGroup;

// One engine's results of a group as a column of pointers (malloc'd; free it).
static const pdTossResult** engine_column(const resultGroup* g, int e) {
  const pdTossResult** column = malloc((size_t)(g->count > 0 ? g->count : 1) * sizeof *column);
  if (!column) abort();
  for (int i = 0; i < g->count; ++i) column[i] = &g->results[i].engines[e];
  return column;
}

// DIR/per_toss.csv (group, toss, engine order) and DIR/summary.csv; false (path says which) on an I/O error.
static bool write_result_csvs(const char* dir, const pdTossSet* set, const engineSpec* specs, int engineCount,
                              const resultGroup* groups, int groupCount, char* path, size_t pathSize) {
  snprintf(path, pathSize, "%s/per_toss.csv", dir);
  FILE* out = fopen(path, "w");
  if (!out) return false;
  per_toss_header(out, set->experiment);
  for (int k = 0; k < groupCount; ++k) {
    const resultGroup* g = &groups[k];
    for (int i = 0; i < g->count; ++i)
      for (int e = 0; e < engineCount; ++e)
        per_toss_row(out, &set->tosses[g->indices[i]], g->indices[i], &specs[e], g->label, &g->results[i].engines[e],
                     g->runs);
  }
  bool written = !ferror(out);
  if (fclose(out) != 0 || !written) return false;
  snprintf(path, pathSize, "%s/summary.csv", dir);
  out = fopen(path, "w");
  if (!out) return false;
  summary_header(out);
  for (int k = 0; k < groupCount; ++k)
    for (int e = 0; e < engineCount; ++e) {
      const pdTossResult** column = engine_column(&groups[k], e);
      summary_rows(out, set->experiment, &specs[e], groups[k].label, column, groups[k].indices, groups[k].count);
      free(column);
    }
  written = !ferror(out);
  return fclose(out) == 0 && written;
}

static void print_tables(const engineSpec* specs, int engineCount, const resultGroup* groups, int groupCount) {
  for (int k = 0; k < groupCount; ++k)
    for (int e = 0; e < engineCount; ++e) {
      const pdTossResult** column = engine_column(&groups[k], e);
      print_table(&specs[e], groups[k].label, column, groups[k].indices, groups[k].count, k == 0 && e == 0);
      free(column);
    }
}

static bool write_params_file(const char* path, const pdTossParams* p, const char* comment) {
  FILE* out = fopen(path, "w");
  if (!out) return false;
  pd_toss_params_write(out, p, comment);
  bool ok = !ferror(out);
  return fclose(out) == 0 && ok;
}

static void catch_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

// ---------------------------------------------------------------- polydyn cubetoss

static int finish_interrupted(const char* cmd, const char* tmp) {
  if (isatty(STDERR_FILENO) == 1) fputs("\r\033[K", stderr);
  fprintf(stderr, "polydyn %s: interrupted; nothing written\n", cmd);
  pd_cli_remove_tree(tmp);
  return 130;
}

// The noise floor has no parameters to fit.
static bool fittable(const engineSpec* s) { return s->built && strcmp(s->name, "noise") != 0; }

static int run_tosses(const options* o, const pdTossSet* set, const int* indices, int count, engineSpec* specs,
                      int engineCount) {
  char tmp[4200], runsDir[4300];
  if (!pd_cli_out_open("cubetoss", o->out, "per_toss.csv", tmp, sizeof tmp)) return PD_EXIT_BAD_INPUT;
  snprintf(runsDir, sizeof runsDir, "%s/runs", tmp);
  // every rank makes it (MPI: all see the same directory), so every rank knows whether it is there
  if (o->runs && mkdir(runsDir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "polydyn cubetoss: cannot create %s: %s\n", runsDir, strerror(errno));
    pd_cli_remove_tree(tmp);
    return PD_EXIT_FAILURE;
  }
  for (int e = 0; e < engineCount && pd_batch_is_root(); ++e)
    if (!specs[e].built)
      fprintf(stderr, "polydyn cubetoss: %s: this build of polydyn has no %s adapter; reported as not built\n",
              specs[e].label, specs[e].name);

  tossJobResult* results = calloc((size_t)count, sizeof *results);
  if (!results) abort();
  runContext ctx = {set, indices, specs, engineCount, o->runs ? runsDir : NULL, NULL};
  progressState progress = {.what = "", .terminal = isatty(STDERR_FILENO) == 1, .start = pd_cli_wall_seconds()};
  char what[128] = "";
  for (int e = 0; e < engineCount; ++e)
    if (specs[e].built) snprintf(what + strlen(what), sizeof what - strlen(what), "%s%s", what[0] ? "," : "", specs[e].label);
  progress.what = what;
  char why[256] = "";
  bool ok = pd_toss_parallel(count, o->jobs, sizeof *results, results, toss_job, &ctx, show_progress, &progress, why,
                             sizeof why);
  if (progress.terminal) fputs("\r\033[K", stderr);
  if (ok && !pd_batch_is_root()) {  // MPI: rank 0 writes and reports
    free(results);
    return PD_EXIT_OK;
  }
  if (!ok) {
    free(results);
    if (interrupted) return finish_interrupted("cubetoss", tmp);
    fprintf(stderr, "polydyn cubetoss: %s\n", why);
    pd_cli_remove_tree(tmp);
    return PD_EXIT_FAILURE;
  }

  // per_toss.csv in toss order, summary.csv, the parameter fragments used
  int status = PD_EXIT_OK;
  char path[4400];
  resultGroup group = {o->label, results, indices, count, o->runs};
  bool written = write_result_csvs(tmp, set, specs, engineCount, &group, 1, path, sizeof path);
  for (int e = 0; e < engineCount && written; ++e) {
    if (!fittable(&specs[e]) && specs[e].built) continue;  // the noise floor has no parameters
    snprintf(path, sizeof path, "%s/params-%s.scene", tmp, specs[e].name);
    char comment[1024], inertia[64] = "that of a uniform cube";
    if (specs[e].params.inertia > 0.0) snprintf(inertia, sizeof inertia, "%g kg m^2", specs[e].params.inertia);
    snprintf(comment, sizeof comment,
             "polydyn cubetoss: parameters of the %s engine in this run (%.300s),\n"
             "on the cube and the board; the cube's inertia %s about every axis, tol %g",
             specs[e].label, specs[e].paramsFile ? specs[e].paramsFile : "defaults", inertia, specs[e].params.tol);
    written = write_params_file(path, &specs[e].params, comment);
  }
  for (int i = 0; i < count; ++i) {
    if (o->runs && !results[i].recordOk) {
      fprintf(stderr, "polydyn cubetoss: toss %ld: the record's run directory: %s\n", set->tosses[indices[i]].id,
              results[i].recordMessage);
      status = PD_EXIT_FAILURE;
    }
    for (int e = 0; e < engineCount; ++e) {
      const pdTossResult* r = &results[i].engines[e];
      if (r->status == pd_tossOk || r->status == pd_tossNotBuilt) continue;
      fprintf(stderr, "polydyn cubetoss: toss %ld, %s: %s: %s\n", set->tosses[indices[i]].id, specs[e].label,
              pd_toss_status_name(r->status), r->message);
      if (e == 0 && strcmp(specs[e].name, "soft") == 0) status = PD_EXIT_FAILURE;
    }
  }
  if (!written) {
    fprintf(stderr, "polydyn cubetoss: cannot write %s: %s\n", path, strerror(errno));
    pd_cli_remove_tree(tmp);
    status = PD_EXIT_FAILURE;
  } else if (!pd_cli_out_close("cubetoss", tmp, o->out)) {
    status = PD_EXIT_FAILURE;
  } else {
    print_tables(specs, engineCount, &group, 1);
    printf("per toss: %s/per_toss.csv; statistics: %s/summary.csv\n", o->out, o->out);
  }
  free(results);
  return status;
}

// ---------------------------------------------------------------- polydyn cubetoss fit

static void fit_started(const pdTossFitEngine* engine, void* user) {
  progressState* progress = user;
  progress->what = engine->label;
  progress->evaluation = 0;
}

static int fit_tosses(const options* o, const pdTossSet* set, const int* indices, int count, engineSpec* specs,
                      int engineCount) {
  int* train = malloc((size_t)count * sizeof *train);
  int* test = malloc((size_t)count * sizeof *test);
  if (!train || !test) abort();
  int trainCount, testCount;
  pd_toss_fit_split(indices, count, o->trainEvery, train, &trainCount, test, &testCount);
  if (trainCount == 0 || testCount == 0) {
    free(train);
    free(test);
    return pd_cli_usage_error("cubetoss fit", "--tosses %s selects %d training and %d test tosses; both must be > 0",
                              o->tosses, trainCount, testCount);
  }
  char tmp[4200];
  if (!pd_cli_out_open("cubetoss fit", o->out, "fit.csv", tmp, sizeof tmp)) {
    free(train);
    free(test);
    return PD_EXIT_BAD_INPUT;
  }
  char path[4400];
  snprintf(path, sizeof path, "%s/fit_trace.csv", tmp);
  FILE* trace = pd_batch_is_root() ? fopen(path, "w") : NULL;  // MPI: every rank fits, rank 0 writes
  int traceOpen = trace != NULL;
  pd_batch_share(&traceOpen, sizeof traceOpen);
  if (!traceOpen) {
    fprintf(stderr, "polydyn cubetoss fit: cannot write %s: %s\n", path, strerror(errno));
    pd_cli_remove_tree(tmp);
    free(train);
    free(test);
    return PD_EXIT_FAILURE;
  }
  if (trace) pd_toss_fit_trace_header(trace);

  pdTossFitResult fits[ENGINES_MAX];
  pdTossParams fitted[ENGINES_MAX];
  pdTossFitEngine engines[ENGINES_MAX];
  for (int e = 0; e < engineCount; ++e) {
    if (!specs[e].built && pd_batch_is_root()) {
      fprintf(stderr, "polydyn cubetoss fit: %s: this build of polydyn has no %s adapter; not fitted\n", specs[e].label,
              specs[e].name);
    }
    engines[e] = (pdTossFitEngine){.label = specs[e].label,
                                   .variant = specs[e].variant,
                                   .engine = specs[e].engine,
                                   .start = specs[e].params,
                                   .built = specs[e].built,
                                   .fit = fittable(&specs[e]),
                                   .fitStiffness = strcmp(specs[e].name, "soft") == 0 || o->variant == pd_refMatched};
  }
  char why[256] = "";
  progressState progress = {.terminal = isatty(STDERR_FILENO) == 1, .start = pd_cli_wall_seconds(), .fitting = true};
  pdTossFitOptions common = {.set = set,
                             .tosses = train,
                             .tossCount = trainCount,
                             .maxEvaluations = o->maxEvals,
                             .sizeTol = o->sizeTol,
                             .workers = o->jobs,
                             .progress = show_progress,
                             .progressUser = &progress,
                             .trace = trace};
  bool ok = pd_toss_fit_engines(&common, engines, engineCount, fit_started, &progress, fits, fitted, why, sizeof why);
  bool traceOk = !trace || !ferror(trace);
  traceOk = (!trace || fclose(trace) == 0) && traceOk;

  // the test tosses with the starting and with the fitted parameters
  tossJobResult* results[2] = {calloc((size_t)testCount, sizeof(tossJobResult)),
                               calloc((size_t)testCount, sizeof(tossJobResult))};
  if (!results[0] || !results[1]) abort();
  pdTossParams startParams[ENGINES_MAX];
  for (int e = 0; e < engineCount; ++e) startParams[e] = specs[e].params;
  const pdTossParams* sets[2] = {startParams, fitted};
  progress.fitting = false;
  for (int k = 0; k < 2 && ok; ++k) {
    runContext ctx = {set, test, specs, engineCount, NULL, sets[k]};
    progress.what = k == 0 ? "test tosses, starting parameters," : "test tosses, fitted parameters,";
    ok = pd_toss_parallel(testCount, o->jobs, sizeof(tossJobResult), results[k], toss_job, &ctx, show_progress,
                          &progress, why, sizeof why);
  }
  if (progress.terminal) fputs("\r\033[K", stderr);
  if (ok && !pd_batch_is_root()) {  // MPI: rank 0 writes and reports
    free(results[0]);
    free(results[1]);
    free(train);
    free(test);
    return PD_EXIT_OK;
  }
  if (!ok) {
    free(results[0]);
    free(results[1]);
    free(train);
    free(test);
    if (interrupted) return finish_interrupted("cubetoss fit", tmp);
    fprintf(stderr, "polydyn cubetoss fit: %s\n", why);
    pd_cli_remove_tree(tmp);
    return PD_EXIT_FAILURE;
  }

  // fit.csv, the fragments, per_toss.csv and summary.csv of the test tosses
  bool written = traceOk;
  snprintf(path, sizeof path, "%s/fit.csv", tmp);
  FILE* out = written ? fopen(path, "w") : NULL;
  written = out != NULL;
  if (out) {
    pd_toss_fit_csv(out, engines, engineCount, fits, trainCount, o->trainEvery, testCount);
    written = !ferror(out) && written;
    written = fclose(out) == 0 && written;
  }
  for (int e = 0; e < engineCount && written; ++e) {
    if (!fittable(&specs[e])) continue;
    snprintf(path, sizeof path, "%s/fitted-%s.scene", tmp, specs[e].name);
    char comment[2048];
    const pdTossFitResult* f = &fits[e];
    snprintf(comment, sizeof comment,
             "polydyn cubetoss fit: %s engine, fitted on %d training tosses of %.300s (even positions%s)\n"
             "objective (mean end position error in %s + mean end rotation error in rad%s): %.4g at the\n"
             "start, %.4g fitted (%d evaluations, %s); %s\n"
             "put these lines under the cube and the board of a scene, or: polydyn cubetoss --params %s=FILE",
             specs[e].label, trainCount, set->path, o->trainEvery > 1 ? ", every K-th" : "", set->experiment->lengthUnit,
             set->experiment->planar ? " + mean first-bounce velocity error in m/s" : "", f->startObjective,
             f->objective, f->evaluations, f->converged ? "converged" : "stopped at --max-evals",
             strcmp(specs[e].name, "soft") == 0 || o->variant == pd_refMatched ? "mu, restitution, kn fitted"
                                                                               : "mu, restitution fitted; kn as given",
             specs[e].name);
    written = write_params_file(path, &f->params, comment);
  }
  resultGroup groups[2] = {{o->label ? o->label : "default", results[0], test, testCount, false},
                           {"fitted", results[1], test, testCount, false}};
  written = written && write_result_csvs(tmp, set, specs, engineCount, groups, 2, path, sizeof path);
  int status = PD_EXIT_OK;
  if (!written) {
    fprintf(stderr, "polydyn cubetoss fit: cannot write %s: %s\n", path, strerror(errno));
    pd_cli_remove_tree(tmp);
    status = PD_EXIT_FAILURE;
  } else if (!pd_cli_out_close("cubetoss fit", tmp, o->out)) {
    status = PD_EXIT_FAILURE;
  } else {
    for (int e = 0; e < engineCount; ++e) {
      if (!fittable(&specs[e])) continue;
      printf("%s: mu %.4g, restitution %.4g, kn %.4g N/m; objective on %d training tosses %.4g -> %.4g (%d evaluations%s)\n",
             specs[e].label, fits[e].params.mu, fits[e].params.restitution, fits[e].params.kn, trainCount,
             fits[e].startObjective, fits[e].objective, fits[e].evaluations, fits[e].converged ? ", converged" : "");
    }
    print_tables(specs, engineCount, groups, 2);
    printf("fitted parameters: %s/fitted-ENGINE.scene; test tosses: %s/summary.csv\n", o->out, o->out);
  }
  free(results[0]);
  free(results[1]);
  free(train);
  free(test);
  return status;
}

// ---------------------------------------------------------------- entry

int pd_cmd_cubetoss(int argc, char** argv) {
  options o = {.engines = "soft,ode,bullet",
               .tosses = "all",
               .variant = pd_refNative,
               .step = PD_REF_DEFAULT_STEP,
               .tol = pd_toss_default_params().tol,
               .runs = true,
               .trainEvery = 1,
               .maxEvals = FIT_DEFAULT_MAX_EVALUATIONS,
               .sizeTol = FIT_DEFAULT_SIZE_TOL};
  if (argc >= 2 && strcmp(argv[1], "fit") == 0) {
    o.fit = true;
    --argc;
    ++argv;
  }
  const char* cmd = o.fit ? "cubetoss fit" : "cubetoss";
  int parsed = parse_options(argc, argv, &o);
  if (parsed >= 0) return parsed;
  o.jobs = pd_cli_default_jobs(o.jobs, DEFAULT_JOBS);
  if (!o.label && !o.fit) o.label = o.paramCount > 0 ? "params" : "default";
  if (pd_cli_parse_only) return PD_EXIT_OK;

  pdError err = {0};
  pdTossSet* set = pd_toss_read(o.data, &err);
  if (!set) {
    pd_error_print(&err, stderr);
    return PD_EXIT_BAD_INPUT;
  }
  int* indices = NULL;
  int count = 0;
  char why[1024];
  if (!pd_toss_select(set, o.tosses, &indices, &count, why, sizeof why)) {
    pd_toss_set_free(set);
    return pd_cli_usage_error(cmd, "--tosses: %s", why);
  }
  engineSpec specs[ENGINES_MAX];
  int engineCount = make_engines(&o, set->experiment, specs, why, sizeof why);
  if (engineCount < 0) {
    fprintf(stderr, "%s\n", why);
    free(indices);
    pd_toss_set_free(set);
    return PD_EXIT_BAD_INPUT;
  }
  catch_signals();
  int status = o.fit ? fit_tosses(&o, set, indices, count, specs, engineCount)
                     : run_tosses(&o, set, indices, count, specs, engineCount);
  free(indices);
  pd_toss_set_free(set);
  return status;
}
