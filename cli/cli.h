// polydyn CLI — shared helpers of the subcommands.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/scene.h"

// Exit statuses (DESIGN §4.3).
enum { PD_EXIT_OK = 0, PD_EXIT_FAILURE = 1, PD_EXIT_BAD_INPUT = 2 };

int pd_cmd_run(int argc, char** argv);
int pd_cmd_check(int argc, char** argv);
int pd_cmd_compare(int argc, char** argv);
int pd_cmd_sweep(int argc, char** argv);
int pd_cmd_report(int argc, char** argv);
int pd_cmd_view(int argc, char** argv);
int pd_cmd_cubetoss(int argc, char** argv);
int pd_cmd_gedanken(int argc, char** argv);
int pd_cmd_oracle(int argc, char** argv);

// Reports a bad command-line argument as `polydyn SUBCOMMAND: message` on stderr; returns 2.
int pd_cli_usage_error(const char* subcommand, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

// mkdir -p of the directories above `path`; out/NAME for scene path .../NAME.ext (free with free()).
void pd_cli_make_parents(const char* path);
char* pd_cli_default_out_dir(const char* scene);

// Parses a finite number > 0 from an option value; false when it is not one.
bool pd_cli_positive(const char* text, double* value);

// True when argv[i] is -h or --help.
bool pd_cli_is_help(const char* arg);

// Overrides of scene settings given on the command line (0 = not given).
typedef struct pdCliOverrides {
  double tend;
  double sample;
  double tolScale;  // > 0: multiplies the scene's tol (compare's tighter reference run)
  double tol;       // > 0: replaces the scene's tol (sweeps)
  double dt;        // > 0: replaces the scene's dt, the fixed stepper's step (sweeps)
} pdCliOverrides;

// Parses and compiles a scene, applying the overrides. On bad input prints `FILE:LINE:COL: message`
// to stderr and returns NULL (the caller exits with status 2). `settings` (nullable) receives the
// scene's settings as written, with where each was set.
pdModel* pd_cli_load_model(const char* path, const pdCliOverrides* overrides, pdSceneSettings* settings);
