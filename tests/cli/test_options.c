// Tests of the commands' option parser (cli/options.c): values reach their targets, and every refusal is a usage
// error with the command's name and the message the table gives (exit status 2), as docs/commands.md promises.
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "cli.h"
#include "options.h"

// What the parse wrote to stderr (usage errors), read back from a temporary file.
static char errText[1024];

typedef struct parsed {
  const char* out;
  double tend;
  long repeats;
  int jobs;
  int mode;
  bool quiet, given;
  const char* list;
  const char* scenes[2];
  int sceneCount;
} parsed;

static bool accept_list(const char* cmd, const char* v, void* target) {
  if (strchr(v, ' ')) {
    pd_cli_usage_error(cmd, "--list takes no spaces");
    return false;
  }
  *(const char**)target = v;
  return true;
}

static const char* const modeWords[] = {"slow", "fast", NULL};
static const int modeValues[] = {10, 20};

// Parses argv (NULL-terminated, argv[0] the command) with a table of every kind; returns the status.
static int parse(parsed* p, const char* refuse, const char** argv) {
  *p = (parsed){.repeats = 3, .mode = 10};
  const pdCliOption table[] = {
      {.name = "--out", .kind = pd_optText, .target = &p->out, .message = "--out needs a directory name", .min = 1,
       .max = 8},
      {.name = "--tend", .kind = pd_optPositive, .target = &p->tend, .message = "--tend needs a number > 0"},
      {.name = "--repeats", .kind = pd_optWhole, .target = &p->repeats, .message = "--repeats: 1..5, not '%s'",
       .min = 1, .max = 5},
      {.name = "--jobs", .kind = pd_optJobs, .target = &p->jobs, .message = "--jobs: 1..4", .max = 4},
      {.name = "--mode", .kind = pd_optChoice, .target = &p->mode, .message = "--mode must be slow or fast, not '%s'",
       .words = modeWords, .values = modeValues, .given = &p->given},
      {.name = "--quiet", .kind = pd_optFlag, .target = &p->quiet, .refuse = refuse},
      {.name = "--list", .kind = pd_optAccept, .target = &p->list, .accept = accept_list},
  };
  pdCliPositionals scenes = {.values = p->scenes, .max = 2, .tooMany = "two scenes at most ('%s' and then '%s')"};
  int argc = 0;
  while (argv[argc]) ++argc;
  FILE* capture = tmpfile();
  assert_non_null(capture);
  fflush(stderr);
  int saved = dup(STDERR_FILENO);
  assert_true(saved >= 0 && dup2(fileno(capture), STDERR_FILENO) >= 0);
  int status = pd_cli_parse_options("demo", argc, (char**)argv, table, sizeof table / sizeof table[0], &scenes,
                                    "usage: polydyn demo\n");
  fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  rewind(capture);
  size_t n = fread(errText, 1, sizeof errText - 1, capture);
  errText[n] = '\0';
  fclose(capture);
  p->sceneCount = scenes.count;
  return status;
}

static void values_reach_their_targets(void** state) {
  (void)state;
  parsed p;
  const char* argv[] = {"demo", "a.scene", "--out", "dir", "--tend", "2.5", "--repeats", "5", "--jobs", "4",
                        "--mode", "fast", "--quiet", "--list", "x,y", "b.scene", NULL};
  assert_int_equal(parse(&p, NULL, argv), -1);
  assert_string_equal(p.out, "dir");
  assert_true(p.tend == 2.5);
  assert_int_equal(p.repeats, 5);
  assert_int_equal(p.jobs, 4);
  assert_int_equal(p.mode, 20);
  assert_true(p.given && p.quiet);
  assert_string_equal(p.list, "x,y");
  assert_int_equal(p.sceneCount, 2);
  assert_string_equal(p.scenes[0], "a.scene");
  assert_string_equal(p.scenes[1], "b.scene");
  assert_string_equal(errText, "");
  // nothing given: the defaults stay
  const char* none[] = {"demo", NULL};
  assert_int_equal(parse(&p, NULL, none), -1);
  assert_int_equal(p.repeats, 3);
  assert_int_equal(p.mode, 10);
  assert_false(p.given || p.quiet);
  assert_int_equal(p.sceneCount, 0);
}

// Each refusal: the status and the whole line on stderr.
static void expect_refused(const char** argv, const char* refuse, const char* message) {
  parsed p;
  assert_int_equal(parse(&p, refuse, argv), PD_EXIT_BAD_INPUT);
  char line[512];
  snprintf(line, sizeof line, "polydyn demo: %s (see 'polydyn demo --help')\n", message);
  assert_string_equal(errText, line);
}

static void bad_arguments_are_usage_errors(void** state) {
  (void)state;
  expect_refused((const char*[]){"demo", "--tend", NULL}, NULL, "--tend needs a value");
  expect_refused((const char*[]){"demo", "--tend", "--help", NULL}, NULL, "--tend needs a number > 0");
  expect_refused((const char*[]){"demo", "--tend", "-1", NULL}, NULL, "--tend needs a number > 0");
  expect_refused((const char*[]){"demo", "--out", "", NULL}, NULL, "--out needs a directory name");
  expect_refused((const char*[]){"demo", "--out", "123456789", NULL}, NULL, "--out needs a directory name");
  expect_refused((const char*[]){"demo", "--repeats", "6", NULL}, NULL, "--repeats: 1..5, not '6'");
  expect_refused((const char*[]){"demo", "--repeats", "2x", NULL}, NULL, "--repeats: 1..5, not '2x'");
  expect_refused((const char*[]){"demo", "--jobs", "5", NULL}, NULL, "--jobs: 1..4");
  expect_refused((const char*[]){"demo", "--mode", "medium", NULL}, NULL, "--mode must be slow or fast, not 'medium'");
  expect_refused((const char*[]){"demo", "--list", "a b", NULL}, NULL, "--list takes no spaces");
  expect_refused((const char*[]){"demo", "--loud", NULL}, NULL, "unknown option '--loud'");
  expect_refused((const char*[]){"demo", "a", "b", "c", NULL}, NULL, "two scenes at most ('a' and then 'c')");
  expect_refused((const char*[]){"demo", "--quiet", NULL}, "%s is for another mode", "--quiet is for another mode");
}

static void help_is_printed_and_stops_the_parse(void** state) {
  (void)state;
  parsed p;
  assert_int_equal(parse(&p, NULL, (const char*[]){"demo", "--tend", "1", "-h", "--bogus", NULL}), PD_EXIT_OK);
  assert_int_equal(parse(&p, NULL, (const char*[]){"demo", "--help", NULL}), PD_EXIT_OK);
  assert_string_equal(errText, "");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(values_reach_their_targets),
      cmocka_unit_test(bad_arguments_are_usage_errors),
      cmocka_unit_test(help_is_printed_and_stops_the_parse),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
