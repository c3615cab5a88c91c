// The public API's promises about itself (polydyn/api.h, error.h, state.h): the version query reports the build's
// CMake project version, a state keeps the options it was created with, and misuse of the API goes through the assert handler the embedding program installed (a
// program may turn it into its own report or, as here, into a test's longjmp), while the default handler prints
// FILE:LINE and aborts.
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "polydyn/api.h"
#include "polydyn/error.h"
#include "scene_run.h"

static const char oneCube[] =
    "cube floor grey 2 2 0.2\n"
    "fixed\n"
    "loc 0 0 -0.1\n"
    "cube block red 0.1 0.1 0.1\n"
    "loc 0 0 0.2\n";

static void test_the_version_is_the_projects(void** unused) {
  (void)unused;
  assert_string_equal(pd_version(), PD_EXPECTED_VERSION);
  pdVersion v = pd_version_numbers();
  char text[64];
  snprintf(text, sizeof text, "%d.%d.%d", v.major, v.minor, v.patch);
  assert_string_equal(text, pd_version());
}

// What the test's handler saw, and where it jumps back to.
static struct {
  jmp_buf back;
  int calls;
  char expression[128];
  char file[256];
  int line;
} caught;

static void catch_assert(const char* expression, const char* file, int line) {
  caught.calls++;
  snprintf(caught.expression, sizeof caught.expression, "%s", expression);
  snprintf(caught.file, sizeof caught.file, "%s", file);
  caught.line = line;
  longjmp(caught.back, 1);
}

static void test_misuse_calls_the_installed_handler(void** unused) {
  (void)unused;
  pdModel* model = compile_text(oneCube);
  pdState* s = pd_state_create(model, NULL);
  memset(&caught, 0, sizeof caught);
  pd_set_assert_fcn(catch_assert);
  if (setjmp(caught.back) == 0) {
    pd_state_body(model, s, model->bodyCount);  // one past the last body: misuse
    fail_msg("pd_state_body accepted body index %d of %d", model->bodyCount, model->bodyCount);
  }
  pd_set_assert_fcn(NULL);
  assert_int_equal(caught.calls, 1);
  assert_non_null(strstr(caught.expression, "bodyIndex"));
  const char* base = strrchr(caught.file, '/');
  assert_string_equal(base ? base + 1 : caught.file, "state.c");
  assert_true(caught.line > 0);
  // a valid call afterwards works and does not call the handler
  pdBodyState b = pd_state_body(model, s, model->bodyCount - 1);
  assert_true(b.x.z > 0.1);
  assert_int_equal(caught.calls, 1);
  pd_state_free(s);
  pd_model_free(model);
}

// pd_state_create takes the caller's settings from pdStateOptions (NULL: the defaults) and pd_state_reset returns
// to them; options not made by pd_state_options_default (here: zeroed) are misuse.
static void test_a_state_keeps_its_options_across_reset(void** unused) {
  (void)unused;
  pdModel* model = compile_text(oneCube);
  pdStateOptions d = pd_state_options_default();
  assert_int_equal(d.stepper, PD_STEPPER_DEFAULT);
  assert_int_equal(d.onsets, PD_ONSETS_DEFAULT);
  assert_int_equal(d.islands, PD_ISLANDS_DEFAULT);
  assert_int_equal(d.threads, 1);
  assert_true(d.searchCertificates);
  assert_true(d.stageTimers);
  pdState* plain = pd_state_create(model, NULL);
  assert_int_equal(plain->stepper, PD_STEPPER_DEFAULT);
  assert_true(plain->h == model->settings.dt);  // h = 0: the scene's dt
  pd_state_free(plain);

  pdStateOptions o = pd_state_options_default();
  o.stepper = pd_stepperRK43Embedded;
  o.onsets = pd_onsetsPair;
  o.islands = pd_islandsOff;
  o.threads = 3;
  o.searchCertificates = false;
  o.h = 1e-5;
  pdState* s = pd_state_create(model, &o);
  assert_true(pd_advance(model, s, 0.05, NULL, NULL));
  pd_state_reset(model, s);
  assert_true(s->t == 0.0 && s->h == 1e-5);
  assert_int_equal(s->stepper, pd_stepperRK43Embedded);
  assert_int_equal(s->onsets, pd_onsetsPair);
  assert_int_equal(s->islands, pd_islandsOff);
  assert_int_equal(s->threads, 3);
  assert_false(s->searchCertificates);
  pd_state_free(s);

  pdStateOptions zeroed;
  memset(&zeroed, 0, sizeof zeroed);
  memset(&caught, 0, sizeof caught);
  pd_set_assert_fcn(catch_assert);
  if (setjmp(caught.back) == 0) {
    pd_state_free(pd_state_create(model, &zeroed));
    fail_msg("pd_state_create accepted options not made by pd_state_options_default");
  }
  pd_set_assert_fcn(NULL);
  assert_int_equal(caught.calls, 1);
  assert_non_null(strstr(caught.expression, "valid"));
  pd_model_free(model);
}

static void returning_handler(const char* expression, const char* file, int line) {
  (void)expression;
  (void)file;
  (void)line;
}

// Runs pd_state_body with an index out of range in a child process with `handler` installed (NULL: the default);
// checks that the child aborted and returns what it wrote to stderr.
static void misuse_in_child(pdAssertFcn* handler, char* errText, size_t errSize) {
  int pipeFd[2];
  assert_int_equal(pipe(pipeFd), 0);
  fflush(NULL);
  pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) {
    dup2(pipeFd[1], STDERR_FILENO);
    close(pipeFd[0]);
    pdModel* model = compile_text(oneCube);
    pdState* s = pd_state_create(model, NULL);
    pd_set_assert_fcn(handler);
    pd_state_body(model, s, -1);
    _exit(0);  // not reached: the handler aborts, or pd_assert_failed does when it returns
  }
  close(pipeFd[1]);
  size_t n = 0;
  ssize_t got;
  while (n + 1 < errSize && (got = read(pipeFd[0], errText + n, errSize - 1 - n)) > 0) n += (size_t)got;
  errText[n] = '\0';
  close(pipeFd[0]);
  int status = 0;
  assert_int_equal(waitpid(pid, &status, 0), pid);
  assert_true(WIFSIGNALED(status));
  assert_int_equal(WTERMSIG(status), SIGABRT);
}

static void test_the_default_handler_prints_file_and_line_and_aborts(void** unused) {
  (void)unused;
  char err[2048];
  misuse_in_child(NULL, err, sizeof err);
  assert_non_null(strstr(err, "state.c:"));
  assert_non_null(strstr(err, "polydyn API misuse: assertion `"));
  assert_non_null(strstr(err, "bodyIndex"));
}

static void test_a_handler_that_returns_still_aborts(void** unused) {
  (void)unused;
  char err[2048];
  misuse_in_child(returning_handler, err, sizeof err);
  assert_null(strstr(err, "polydyn API misuse"));  // the installed handler, not the default, had the report
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_the_version_is_the_projects),
      cmocka_unit_test(test_misuse_calls_the_installed_handler),
      cmocka_unit_test(test_a_state_keeps_its_options_across_reset),
      cmocka_unit_test(test_the_default_handler_prints_file_and_line_and_aborts),
      cmocka_unit_test(test_a_handler_that_returns_still_aborts),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
