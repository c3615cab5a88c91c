// polydyn's subcommands as a library (polydyn_cli): what the polydyn command runs, for a program that runs one in
// its own process (the Python package's compare and cubetoss, tests/fuzz). The commands' shared helpers are the
// library's own (cli/cli.h); this is all a caller needs.
#pragma once

#include <signal.h>
#include <stdbool.h>

// Exit statuses (docs/commands.md).
enum { PD_EXIT_OK = 0, PD_EXIT_FAILURE = 1, PD_EXIT_BAD_INPUT = 2 };

// `polydyn NAME ARGS...`: argv[0] is NAME, argv[1..] its arguments, as on the command line. Each prints its help,
// usage errors and progress as the command does, writes its directory whole or not at all, and returns the exit
// status. The commands that catch SIGINT and SIGTERM (pd_cli_catch_interrupts) install their own handlers: a caller
// with handlers of its own puts them back afterwards.
int pd_cmd_run(int argc, char** argv);
int pd_cmd_check(int argc, char** argv);
int pd_cmd_compare(int argc, char** argv);
int pd_cmd_sweep(int argc, char** argv);
int pd_cmd_report(int argc, char** argv);
int pd_cmd_view(int argc, char** argv);
int pd_cmd_cubetoss(int argc, char** argv);
int pd_cmd_gedanken(int argc, char** argv);
int pd_cmd_oracle(int argc, char** argv);
int pd_cmd_soak(int argc, char** argv);

// `polydyn ARGS...`: argv[1] names the subcommand (cli/commands.c; main() calls it). Returns the exit status.
int pd_cli_dispatch(int argc, char** argv);

// Set by an interrupt (SIGINT, SIGTERM) while a command that catches them runs: the command stops at its next
// check, removes what it had started and returns 130. A caller clears it before it runs a command.
extern volatile sig_atomic_t pd_cli_interrupted;

// Set only by the command-line fuzzer (tests/fuzz/fuzz_cli.c): each subcommand returns PD_EXIT_OK as soon as
// its arguments are accepted, before it opens, reads or writes any file or starts any work. Help and usage
// errors are printed as usual. Never set in the polydyn command.
extern bool pd_cli_parse_only;
