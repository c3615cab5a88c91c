// polydyn soak — the random-scene soak (validation/include/pdval/soak.h; docs/reliability.md). Each scene
// is one task of a batch (runner/include/pdrun/batch.h); its runs go through child processes.
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "options.h"
#include "pdutil/csv.h"
#include "pdutil/files.h"
#include "pdrun/batch.h"
#include "pdval/soak.h"

static const char* const help =
    "usage: polydyn soak --out DIR [--scenes N] [--seed S] [--first I] [--generator G]\n"
    "                    [--engines soft,soft-islands-off,ode,bullet] [--budget SECONDS] [--jobs N]\n"
    "                    [--onsets pair|exact|auto|bounded] [--check steps|samples] [--penetration-limit D]\n"
    "\n"
    "Generates N random scenes (campaign S of generator G: scene i is the same text on every machine) and\n"
    "runs each in every engine, in a child process per run, checking at every output sample: no NaN or Inf;\n"
    "for the soft engine also penetration below 3 delta_max of the pair (a pair that third bodies press\n"
    "together along its normal: 3 delta_max sqrt(M / m_pair), M the mass moving with it, while its contacts\n"
    "carry it, docs/reliability.md), no energy gained beyond 1e-3 of E(0) in a dissipative scene, the\n"
    "momentum kept in a scene without gravity or fixed bodies; and that the run reaches its end. The soft\n"
    "engine's penetration, energy and momentum are also checked at every accepted step.\n"
    "Scenes of two overlapping boxes must be refused. A run over its wall-time budget is\n"
    "stopped and counted as over budget (a cost finding, not a failure).\n"
    "Writes DIR/summary.csv (one row per scene and engine), DIR/failures/SCENE-ENGINE.scene (every failed\n"
    "run's scene, replayable with `polydyn run`) and DIR/over-budget/SCENE-ENGINE.scene; prints the counts.\n"
    "DIR is written under a temporary name and renamed when complete.\n"
    "\n"
    "  --scenes N       how many scenes (default 100)\n"
    "  --seed S         the campaign (default 1)\n"
    "  --first I        start at scene I (default 0): scenes I .. I+N-1\n"
    "  --generator G    the scene generator: 1 (boxes, prisms, frusta, spheres, hulls, 100:1 blades), 2 (also\n"
    "                   plates 3:1 .. 30:1, loose and in stacks; the default)\n"
    "  --engines LIST   soft, soft-islands-off (the soft engine with --islands off), ode, bullet (default soft)\n"
    "  --budget SECONDS wall-time budget of one run (default 20)\n"
    "  --jobs N         scenes in N worker processes (default 1; under mpirun or srun split over the ranks)\n"
    "  --onsets MODE    soft engine: how a contact that began inside a step joins, pair, exact or auto (default:\n"
    "                   the engine's, as polydyn run --onsets; docs/contact-model.md)\n"
    "  --check WHEN     soft engine: penetration, energy and momentum at every accepted step and every sample\n"
    "                   (steps, the default) or at the output samples only (samples)\n"
    "  --penetration-limit D  soft engine: the plain penetration limit, delta_max (default 3; a pressed pair's\n"
    "                   D sqrt(M / m_pair)): a tighter one shows a campaign's margin\n"
    "\n"
    "Exit status: 0 no failure, 1 a run failed (or the results could not be written), 2 bad input,\n"
    "130 interrupted (nothing written).\n";

enum { ENGINES_MAX = 4 };
static const char* const engineNames[ENGINES_MAX] = {"soft", "soft-islands-off", "ode", "bullet"};

typedef struct soakJob {
  int generator;
  unsigned long seed;
  long first;
  const char* engines[ENGINES_MAX];
  int engineCount;
  pdSoakRunOptions run;
} soakJob;

static void soak_task(int task, pdBatchBuffer* result, void* user) {
  const soakJob* job = user;
  pdSoakScene scene = pd_soak_scene(job->generator, job->seed, job->first + task);
  for (int e = 0; e < job->engineCount; ++e) {
    pdSoakResult r;
    pd_soak_run(&scene, job->engines[e], &job->run, &r);
    pd_batch_append(result, &r, sizeof r);
  }
  pd_soak_scene_free(&scene);
}

static volatile sig_atomic_t interrupted = 0;
static void on_signal(int sig) {
  (void)sig;
  interrupted = 1;
}
static bool keep_going(int task, int done, int total, void* user) {
  (void)task, (void)user;
  if (isatty(2)) fprintf(stderr, "\r\033[Kpolydyn soak: %d/%d", done, total);
  return !interrupted;
}

// The scene file of a run that did not pass: the scene, headed by what happened.
static bool write_scene_file(const char* dir, const char* sub, long index, const char* engine, pdOnsets onsets,
                             const pdSoakScene* scene, const pdSoakResult* r) {
  char path[8192];
  snprintf(path, sizeof path, "%s/%s", dir, sub);
  if (!pdu_make_dir(path)) return false;
  snprintf(path, sizeof path, "%s/%s/%06ld-%s.scene", dir, sub, index, engine);
  FILE* f = fopen(path, "w");
  if (!f) return false;
  pdIslands islands;
  bool soft = pd_soak_engine_is_soft(engine, &islands), whole = islands == pd_islandsOff;
  fprintf(f, "# %s: %s\n# replay: polydyn run %06ld-%s.scene --engine %s%s%s%s\n%s", pdSoakStatusNames[r->status],
          r->message, index, engine, soft ? "soft" : engine, whole ? " --islands off" : "", soft ? " --onsets " : "",
          soft ? pd_onsets_name(onsets) : "", scene->text);
  bool ok = !ferror(f);
  return fclose(f) == 0 && ok;
}

// --seed: a whole number 0 .. 2^32 - 1 (the generator's seed is 32 bits).
static bool accept_seed(const char* cmd, const char* v, void* target) {
  char* end = NULL;
  errno = 0;
  unsigned long long s = strtoull(v, &end, 10);
  if (end == v || *end || errno || v[0] == '-' || s > 0xffffffffull) {
    pd_cli_usage_error(cmd, "--seed needs a whole number from 0 to 4294967295");
    return false;
  }
  *(unsigned long*)target = (unsigned long)s;
  return true;
}

// --penetration-limit: delta_max > 0, at most 1000 (an overlap of many delta_max is a failure whatever the load).
static bool accept_penetration_limit(const char* cmd, const char* v, void* target) {
  if (pd_cli_positive(v, target) && *(double*)target <= 1000.0) return true;
  pd_cli_usage_error(cmd, "--penetration-limit needs delta_max > 0 (at most 1000)");
  return false;
}

// --budget: seconds > 0, at most a day (a run that needs more is a finding of its own).
static bool accept_budget(const char* cmd, const char* v, void* target) {
  if (pd_cli_positive(v, target) && *(double*)target <= 86400) return true;
  pd_cli_usage_error(cmd, "--budget needs seconds > 0 (at most a day)");
  return false;
}

int pd_cmd_soak(int argc, char** argv) {
  soakJob job = {.generator = PD_SOAK_GENERATOR_LATEST,
                 .seed = 1,
                 .run = {.onsets = PD_ONSETS_DEFAULT,
                         .budgetSeconds = 20.0,
                         .everyStep = true,
                         .penetrationLimit = PD_SOAK_PENETRATION_LIMIT}};
  long scenes = 100;
  long generator = PD_SOAK_GENERATOR_LATEST;
  int everyStep = 1;
  int jobs = 0;
  const char* out = NULL;
  const char* engines = "soft";
  char generatorMessage[64], jobsMessage[64];
  snprintf(generatorMessage, sizeof generatorMessage, "--generator needs %d to %d", PD_SOAK_GENERATOR_BLADES,
           PD_SOAK_GENERATOR_LATEST);
  snprintf(jobsMessage, sizeof jobsMessage, "--jobs needs a whole number from 1 to %d", PD_CLI_MAX_JOBS);
  static const char* const checkWords[] = {"steps", "samples", NULL};
  static const int checkValues[] = {1, 0};
  const pdCliOption table[] = {
      {.name = "--out", .kind = pd_optText, .target = &out, .message = "--out needs a directory name", .min = 1},
      {.name = "--scenes", .kind = pd_optWhole, .target = &scenes, .min = 1, .max = 100000000,
       .message = "--scenes needs a whole number from 1 to 100000000"},
      {.name = "--first", .kind = pd_optWhole, .target = &job.first, .min = 0, .max = 100000000,
       .message = "--first needs a whole number from 0 to 100000000"},
      {.name = "--seed", .kind = pd_optAccept, .target = &job.seed, .accept = accept_seed},
      {.name = "--generator", .kind = pd_optWhole, .target = &generator, .min = PD_SOAK_GENERATOR_BLADES,
       .max = PD_SOAK_GENERATOR_LATEST, .message = generatorMessage},
      {.name = "--check", .kind = pd_optChoice, .target = &everyStep, .words = checkWords, .values = checkValues,
       .message = "--check must be steps or samples"},
      {.name = "--engines", .kind = pd_optText, .target = &engines},
      {.name = "--budget", .kind = pd_optAccept, .target = &job.run.budgetSeconds, .accept = accept_budget},
      {.name = "--onsets", .kind = pd_optAccept, .target = &job.run.onsets, .accept = pd_cli_accept_onsets},
      {.name = "--penetration-limit", .kind = pd_optAccept, .target = &job.run.penetrationLimit,
       .accept = accept_penetration_limit},
      {.name = "--jobs", .kind = pd_optJobs, .target = &jobs, .message = jobsMessage},
  };
  pdCliPositionals none = {.max = 0, .tooMany = "unknown argument '%s'"};
  int parsed = pd_cli_parse_options("soak", argc, argv, table, sizeof table / sizeof table[0], &none, help);
  if (parsed >= 0) return parsed;
  job.generator = (int)generator;
  job.run.everyStep = everyStep != 0;
  if (!out) return pd_cli_usage_error("soak", "--out DIR is required");
  if (job.first + scenes > 2000000000L) return pd_cli_usage_error("soak", "--first + --scenes is too large");
  // the engines, in the order given, each once
  for (const char* p = engines; *p;) {
    const char* comma = strchr(p, ',');
    size_t len = comma ? (size_t)(comma - p) : strlen(p);
    int e = 0;
    while (e < ENGINES_MAX && !(strlen(engineNames[e]) == len && strncmp(p, engineNames[e], len) == 0)) ++e;
    if (e == ENGINES_MAX) return pd_cli_usage_error("soak", "--engines: unknown engine '%.*s'", (int)len, p);
    for (int k = 0; k < job.engineCount; ++k)
      if (job.engines[k] == engineNames[e]) return pd_cli_usage_error("soak", "--engines: %s twice", engineNames[e]);
    job.engines[job.engineCount++] = engineNames[e];
    if (!comma) break;
    p = comma + 1;
    if (!*p) return pd_cli_usage_error("soak", "--engines: an empty name");
  }
  if (job.engineCount == 0) return pd_cli_usage_error("soak", "--engines needs a list like soft,ode,bullet");
  if (pd_cli_parse_only) return PD_EXIT_OK;

  // caught before the temporary directory is made, so that an interrupt always removes it
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  char tmp[4096];
  if (!pd_cli_out_open("soak", out, "summary.csv", tmp, sizeof tmp)) return PD_EXIT_BAD_INPUT;

  pdBatchBuffer* results = calloc((size_t)scenes, sizeof *results);
  if (!results) abort();
  pdBatchOptions options = {.workers = pd_cli_default_jobs(jobs, 1), .progress = keep_going};
  char why[512] = "";
  bool ran = pd_batch_run((int)scenes, soak_task, &job, &options, results, why, sizeof why);
  if (isatty(2)) fputs("\r\033[K", stderr);
  int status = PD_EXIT_OK;
  if (!ran) {
    if (pd_batch_is_root()) fprintf(stderr, "polydyn soak: %s\n", interrupted ? "interrupted; nothing written" : why);
    pd_cli_remove_tree(tmp);
    status = interrupted ? 130 : PD_EXIT_FAILURE;
  } else if (pd_batch_is_root()) {
    long counts[ENGINES_MAX][pd_soakStatusCount] = {{0}};
    long kinds[pd_soakKindCount][pd_soakStatusCount] = {{0}};
    char path[8192];
    snprintf(path, sizeof path, "%s/summary.csv", tmp);
    FILE* csv = fopen(path, "w");
    bool ok = csv != NULL;
    if (ok)
      fputs("seed,scene,kind,objects,dissipative,engine,status,wall_seconds,simulated,steps,penetration_over_delta_max,"
            "energy_gain_rel,momentum_error_rel,penetration_at_samples_over_delta_max,generator,message\n",
            csv);
    for (long s = 0; s < scenes && ok; ++s) {
      long index = job.first + s;
      pdSoakScene scene = pd_soak_scene(job.generator, job.seed, index);
      size_t offset = 0;
      for (int e = 0; e < job.engineCount && ok; ++e) {
        pdSoakResult r;
        if (!pd_batch_read(&results[s], &offset, &r, sizeof r)) {
          ok = false;
          break;
        }
        r.message[sizeof r.message - 1] = '\0';
        int engine = 0;
        while (engineNames[engine] != job.engines[e]) ++engine;
        ++counts[engine][r.status];
        if (e == 0) ++kinds[scene.kind][r.status];
        fprintf(csv, "%lu,%ld,%s,%d,%d,%s,%s,%.4g,%.6g,%ld,%.4g,%.4g,%.4g,%.4g,%d,", job.seed, index,
                pdSoakKindNames[scene.kind], scene.objects, scene.dissipative, job.engines[e],
                pdSoakStatusNames[r.status], r.wallSeconds, r.simulated, r.steps, r.penetration, r.energyGain,
                r.momentumError, r.penetrationSampled, job.generator);
        pdu_csv_quoted(csv, r.message);  // quoted in every row, as it always was
        fputc('\n', csv);
        if (r.status == pd_soakFailed)
          ok = write_scene_file(tmp, "failures", index, job.engines[e], job.run.onsets, &scene, &r);
        if (r.status == pd_soakOverBudget)
          ok = write_scene_file(tmp, "over-budget", index, job.engines[e], job.run.onsets, &scene, &r);
        if (r.status == pd_soakFailed) {
          status = PD_EXIT_FAILURE;
          printf("FAILED scene %ld (%s) in %s: %s\n", index, pdSoakKindNames[scene.kind], job.engines[e], r.message);
        }
      }
      pd_soak_scene_free(&scene);
    }
    if (csv) ok = !ferror(csv) && fclose(csv) == 0 && ok;
    printf("polydyn soak: generator %d, seed %lu, scenes %ld .. %ld, checked at every %s", job.generator, job.seed,
           job.first, job.first + scenes - 1, job.run.everyStep ? "step" : "sample");
    if (job.run.penetrationLimit != PD_SOAK_PENETRATION_LIMIT)
      printf(", penetration limit %.3g delta_max", job.run.penetrationLimit);
    printf("\n");
    printf("%-12s %8s %8s %12s %8s %10s\n", "engine", "ok", "refused", "over-budget", "failed", "not-built");
    for (int e = 0; e < ENGINES_MAX; ++e) {
      bool used = false;
      for (int k = 0; k < job.engineCount; ++k) used = used || job.engines[k] == engineNames[e];
      if (!used) continue;
      printf("%-12s %8ld %8ld %12ld %8ld %10ld\n", engineNames[e], counts[e][pd_soakOk], counts[e][pd_soakRefused],
             counts[e][pd_soakOverBudget], counts[e][pd_soakFailed], counts[e][pd_soakNotBuilt]);
    }
    printf("%s by kind (%s):", job.engines[0], "ok/refused/over-budget/failed");
    for (int k = 0; k < pd_soakKindCount; ++k)
      printf(" %s %ld/%ld/%ld/%ld", pdSoakKindNames[k], kinds[k][pd_soakOk], kinds[k][pd_soakRefused],
             kinds[k][pd_soakOverBudget], kinds[k][pd_soakFailed]);
    putchar('\n');
    if (!ok) {
      fprintf(stderr, "polydyn soak: cannot write the results in %s\n", tmp);
      pd_cli_remove_tree(tmp);
      status = PD_EXIT_FAILURE;
    } else if (!pd_cli_out_close("soak", tmp, out)) {
      status = PD_EXIT_FAILURE;
    }
  }
  for (long s = 0; s < scenes; ++s) pd_batch_buffer_free(&results[s]);
  free(results);
  return status;
}
