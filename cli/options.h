// polydyn CLI — one option table per command, one parser for all (cli/options.c).
//
// A command lists its options as a table of pdCliOption rows: the option's name, what kind of value it takes,
// where the value goes and the usage error for a bad one. pd_cli_parse_options walks argv against the table with
// the rules every command shares: -h and --help print the command's help; an option takes the next argument as its
// value ("--tend needs a value" when there is none) unless it is a flag; an argument starting with '-' that names no
// option is refused ("unknown option '-x'"); any other argument is positional. Errors go through pd_cli_usage_error
// (exit 2).
#pragma once

#include <stdbool.h>

typedef enum pdCliOptionKind {
  pd_optFlag,      // bool target, set true; takes no value (with accept: accept(cmd, NULL, target) instead)
  pd_optText,      // const char* target: the value itself; refused when shorter than min or longer than max (> 0)
  pd_optPositive,  // double target: a finite number > 0 (pd_cli_positive)
  pd_optWhole,     // long target: a whole number (strtol, base 10, nothing after it) in min..max
  pd_optJobs,      // int target: a whole number 1..PD_CLI_MAX_JOBS (pd_cli_jobs), at most max when max > 0
  pd_optChoice,    // int target: values[i] for the value words[i] (words: NULL-terminated)
  pd_optAccept,    // any target: accept(cmd, value, target) takes the value or reports its own usage error
} pdCliOptionKind;

typedef struct pdCliOption {
  const char* name;  // "--tend"
  pdCliOptionKind kind;
  void* target;         // where the value goes: const char**, double*, long*, int* or the accept function's own
  const char* message;  // the usage error for a bad value; a "%s" in it stands for the value (not pd_optAccept)
  const char* const* words;  // pd_optChoice
  const int* values;         // pd_optChoice
  long min, max;             // pd_optWhole: the range; pd_optText: its length's (max 0: any); pd_optJobs: at most
  // pd_optAccept: true when the value was taken; false after it printed the usage error (pd_cli_usage_error)
  bool (*accept)(const char* cmd, const char* value, void* target);
  bool* given;  // nullable: set when the option appears
  // nullable: the option is refused here (after its value is read) with this message, "%s" its name: an option
  // of another mode of the command
  const char* refuse;
} pdCliOption;

typedef struct pdCliPositionals {
  const char** values;  // (max) the positional arguments in order
  int max, count;
  // the usage error for one too many, formatted with the first positional and the extra one (max > 0) or with the
  // extra one alone (max == 0)
  const char* tooMany;
  const char* unknownOption;  // nullable: the usage error for an unknown option, "%s" it (default "unknown option")
  bool loneDashIsOption;      // "-" alone is an (unknown) option, not a positional argument
} pdCliPositionals;

// Parses argv[1 .. argc) of subcommand `cmd` (usage errors say `polydyn CMD: ...`). Returns -1 when every argument
// was taken, PD_EXIT_OK after printing `help` for -h/--help, or PD_EXIT_BAD_INPUT after a usage error.
int pd_cli_parse_options(const char* cmd, int argc, char** argv, const pdCliOption* table, int count,
                         pdCliPositionals* positionals, const char* help);
