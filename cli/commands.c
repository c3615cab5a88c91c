// polydyn — the command line: the usage text and the dispatch to the subcommands (pdcli/commands.h). main() is in
// main.c, so that the command-line fuzzer (tests/fuzz/fuzz_cli.c) can call pd_cli_dispatch.
#include <stdio.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: polydyn COMMAND [ARGS]\n"
    "\n"
    "Rigid convex polyhedra in frictional contact (Goyal, Pinson & Sinden 1994).\n"
    "\n"
    "commands:\n"
    "  run SCENE [--out DIR] [--tend T] [--sample HZ] [--stepper implicit|adaptive|fixed|embedded|dopri]\n"
    "                 simulate a scene, write trajectory.csv and summary.json into DIR\n"
    "  check SCENE    parse and compile a scene; print masses, inertias, polyhedra, settings\n"
    "  compare SCENE --out DIR [--engines soft,ode,bullet]\n"
    "                 run a scene in every engine, write DIR/metrics.csv against a tighter soft run\n"
    "  sweep SCENE --out DIR [--repeats R]\n"
    "                 work-precision: error against wall time over tolerances and step sizes\n"
    "  report DIR [-o FILE]\n"
    "                 one self-contained HTML report (+ JSON, CSV) of a gedanken/sweep/compare DIR\n"
    "  view DIR...    self-contained HTML replay of run directories (or --movie OUT.mp4)\n"
    "  cubetoss [fit] --data FILE.csv --out DIR [--engines soft,ode,bullet]\n"
    "                 real cube tosses in every engine against the record; fit each engine's parameters\n"
    "  oracle (SCENE | --random N --seed S | --replay FILE)  interference test vs libccd\n"
    "  soak --out DIR [--scenes N] [--seed S]             random scenes, invariants checked\n"
    "  help           this text\n"
    "  --version      print the version\n"
    "\n"
    "Every command takes --help. Exit status: 0 ok, 1 failure, 2 bad input.\n";

int pd_cli_dispatch(int argc, char** argv) {
  if (argc < 2) {
    fputs(usage, stderr);
    return PD_EXIT_BAD_INPUT;
  }
  const char* cmd = argv[1];
  if (strcmp(cmd, "run") == 0) return pd_cmd_run(argc - 1, argv + 1);
  if (strcmp(cmd, "check") == 0) return pd_cmd_check(argc - 1, argv + 1);
  if (strcmp(cmd, "compare") == 0) return pd_cmd_compare(argc - 1, argv + 1);
  if (strcmp(cmd, "sweep") == 0) return pd_cmd_sweep(argc - 1, argv + 1);
  if (strcmp(cmd, "report") == 0) return pd_cmd_report(argc - 1, argv + 1);
  if (strcmp(cmd, "view") == 0) return pd_cmd_view(argc - 1, argv + 1);
  if (strcmp(cmd, "cubetoss") == 0) return pd_cmd_cubetoss(argc - 1, argv + 1);
  if (strcmp(cmd, "gedanken") == 0) return pd_cmd_gedanken(argc - 1, argv + 1);
  if (strcmp(cmd, "oracle") == 0) return pd_cmd_oracle(argc - 1, argv + 1);
  if (strcmp(cmd, "soak") == 0) return pd_cmd_soak(argc - 1, argv + 1);
  if (strcmp(cmd, "help") == 0 || pd_cli_is_help(cmd)) {
    fputs(usage, stdout);
    return PD_EXIT_OK;
  }
  if (strcmp(cmd, "--version") == 0) {
    printf("polydyn %s\n", PD_VERSION);
    return PD_EXIT_OK;
  }
  fprintf(stderr, "polydyn: unknown command '%s'\n\n%s", cmd, usage);
  return PD_EXIT_BAD_INPUT;
}
