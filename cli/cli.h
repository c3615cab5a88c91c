// polydyn CLI — shared helpers of the subcommands.
#pragma once

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

#include "pdcli/commands.h"  // the commands, their exit statuses, the interrupt and parse-only flags

// Reports a bad command-line argument as `polydyn SUBCOMMAND: message` on stderr (on MPI rank 0 only:
// every rank sees the same arguments); returns 2.
int pd_cli_usage_error(const char* subcommand, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

// Terminal tables (cli/table.c): one right-aligned cell of `width` columns, a space included, `format`
// (one double, e.g. "%.3g") for a finite value and "—" for a value that does not apply (NaN, ±inf).
void pd_cli_table_number(FILE* out, int width, const char* format, double value);

// Output directories (cli/out_dir.c; parents: pdu_make_parents, util/): out/NAME for scene path .../NAME.ext
// (free with free()); rm -r of a directory this command made (rank 0 only).
char* pd_cli_default_out_dir(const char* scene);
void pd_cli_remove_tree(const char* path);
// A whole output directory is written as OUT.partial-PID (tmp) and renamed to OUT when complete.
// pd_cli_out_open refuses (message, false) an existing OUT without `marker` in it — not a directory of
// this command — and makes tmp. pd_cli_out_close moves tmp into place, replacing a previous OUT; on
// failure it prints why, removes tmp and returns false.
// Under MPI (runner/include/pdrun/batch.h) both are collective: rank 0 makes, moves and removes the
// directories, every rank gets tmp's name (or false), and the others' pd_cli_out_close does nothing.
bool pd_cli_out_open(const char* cmd, const char* out, const char* marker, char* tmp, size_t tmpSize);
bool pd_cli_out_close(const char* cmd, const char* tmp, const char* out);

// Interrupts (SIGINT, SIGTERM) of the commands that catch them with pd_cli_catch_interrupts: the flag is set
// and the command stops at its next check, removes what it had started and exits 130 ("interrupted; nothing
// written"). pd_cli_out_close holds them back while it swaps the directories, so an interrupt never lands
// between the two renames.
void pd_cli_catch_interrupts(void);  // sets pd_cli_interrupted (pdcli/commands.h)

// --jobs N of the batch commands (docs/commands.md): a whole number 1..PD_CLI_MAX_JOBS; false when not.
#define PD_CLI_MAX_JOBS 64
bool pd_cli_jobs(const char* text, int* jobs);
// The worker processes of this process: `given` when --jobs was given (> 0), else `serialDefault`, or 1
// under MPI (the ranks already fill the cores).
int pd_cli_default_jobs(int given, int serialDefault);

// Seconds of CLOCK_MONOTONIC (wall time of runs and progress displays).
double pd_cli_wall_seconds(void);
// True when the comma-separated `list` contains `word` as one of its items.
bool pd_cli_list_has(const char* list, const char* word);

// Parses a finite number > 0 from an option value; false when it is not one.
bool pd_cli_positive(const char* text, double* value);
// --tol's value as an option table's accept function (options.h): a number in (0, 1), the scene's own range for tol
// (docs/scene-language.md); a usage error for anything else.
bool pd_cli_accept_tol(const char* cmd, const char* value, void* tol);

// Parses --onsets' value, "pair", "exact", "auto" or "bounded"; false when it is none of them.
bool pd_cli_onsets(const char* text, pdOnsets* onsets);
// The same as an option table's accept function (options.h): a usage error for a value it does not know.
bool pd_cli_accept_onsets(const char* cmd, const char* value, void* onsets);
// Parses --events' value: "exact" (the paper's loop, every onset located: pd_onsetsExact), "bounded" (the default,
// pd_onsetsBounded: an onset is corrected where its error bound allows, docs/events.md) or "held" (pd_onsetsHeld:
// bounded, with contact modes held within a step); false otherwise.
bool pd_cli_events(const char* text, pdOnsets* onsets);

// True when argv[i] is -h or --help.
bool pd_cli_is_help(const char* arg);

// Overrides of scene settings given on the command line (0 = not given).
typedef struct pdCliOverrides {
  double tend;
  double sample;
  double tolScale;  // > 0: multiplies the scene's tol (compare's tighter reference run)
  double tol;       // > 0: replaces the scene's tol (sweeps)
  double dt;        // > 0: replaces the scene's dt, the fixed stepper's step (sweeps)
  int sleep;        // > 0: sleep on, < 0: sleep off, 0: the scene's setting
} pdCliOverrides;

// Parses and compiles a scene, applying the overrides. On bad input prints `FILE:LINE:COL: message`
// to stderr and returns NULL (the caller exits with status 2). `settings` (nullable) receives the
// scene's settings as written, with where each was set.
pdModel* pd_cli_load_model(const char* path, const pdCliOverrides* overrides, pdSceneSettings* settings);
