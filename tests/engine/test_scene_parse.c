// Scene parser: values, defaults and masks of every command and setting, the lexer's line
// handling, and every kind of error with its exact line and column. Error cases are parsed both
// from a buffer and from a file, which must agree.
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "polydyn/error.h"
#include "polydyn/scene.h"

#define PI 3.14159265358979323846

static char tmpDir[] = "/tmp/pd_scene_parse_XXXXXX";

static int make_tmp_dir(void** state) {
  (void)state;
  return mkdtemp(tmpDir) ? 0 : -1;
}

static int remove_tmp_dir(void** state) {
  (void)state;
  DIR* d = opendir(tmpDir);
  if (d) {
    struct dirent* e;
    char path[1024];
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
      snprintf(path, sizeof path, "%s/%s", tmpDir, e->d_name);
      if (rmdir(path) != 0) unlink(path);
    }
    closedir(d);
  }
  return rmdir(tmpDir);
}

static const char* tmp_path(char* buf, size_t size, const char* name) {
  snprintf(buf, size, "%s/%s", tmpDir, name);
  return buf;
}

static void write_file(const char* path, const char* bytes, size_t len) {
  FILE* f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(bytes, 1, len, f), len);
  assert_int_equal(fclose(f), 0);
}

// The process's CPU time, not the wall clock: the parse-time bounds guard against work that grows faster than the file,
// and a loaded machine stretches wall time, not CPU time.
static double seconds_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static pdScene* parse_text(const char* text) {
  pdError err;
  pdScene* sc = pd_scene_parse_buffer("t.scene", text, strlen(text), &err);
  if (!sc) fprintf(stderr, "unexpected error: %d:%d: %s\n", err.line, err.col, err.message);
  assert_non_null(sc);
  return sc;
}

// The text must be refused at line:col with a message containing `part`, from a buffer and from a file.
static void expect_error_len(const char* text, size_t len, int line, int col, const char* part) {
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* sc = pd_scene_parse_buffer("t.scene", text, len, &err);
  if (sc || err.line != line || err.col != col || !strstr(err.message, part)) {
    fprintf(stderr, "expected %d:%d: ...%s...\n     got %d:%d: %s\n", line, col, part, err.line, err.col,
            err.message);
  }
  assert_null(sc);
  assert_string_equal(err.file, "t.scene");
  assert_int_equal(err.line, line);
  assert_int_equal(err.col, col);
  assert_non_null(strstr(err.message, part));
  assert_null(strchr(err.message, '\n'));

  char path[1024];
  tmp_path(path, sizeof path, "error.scene");
  write_file(path, text, len);
  pdError ferr;
  memset(&ferr, 0, sizeof ferr);
  assert_null(pd_scene_parse_file(path, &ferr));
  assert_string_equal(ferr.file, path);
  assert_int_equal(ferr.line, err.line);
  assert_int_equal(ferr.col, err.col);
  assert_string_equal(ferr.message, err.message);
  unlink(path);
}

static void expect_error(const char* text, int line, int col, const char* part) {
  expect_error_len(text, strlen(text), line, col, part);
}

// ---------------------------------------------------------------------------------------------
// values

static void check_default_settings(const pdSceneSettings* s) {
  assert_true(s->gravity[0] == 0 && s->gravity[1] == 0 && s->gravity[2] == PD_DEFAULT_GRAVITY_Z);
  assert_true(s->tend == PD_DEFAULT_TEND);
  assert_true(s->tol == PD_DEFAULT_TOL);
  assert_true(s->dt == PD_DEFAULT_DT);
  assert_true(s->dtmin == PD_DEFAULT_DTMIN);
  assert_true(s->dtmax == PD_DEFAULT_DTMAX);
  assert_true(s->sample == PD_DEFAULT_SAMPLE);
  assert_true(s->vmax == 0);
  assert_true(s->deflection == PD_DEFAULT_DEFLECTION);
  assert_true(s->sleep == PD_DEFAULT_SLEEP);
  assert_int_equal(s->setMask, 0);
  for (int i = 0; i < 10; ++i) assert_int_equal(s->where[i].line, 0);
}

static void test_empty_scene_is_valid_with_default_settings(void** state) {
  (void)state;
  pdError err;
  pdScene* sc = pd_scene_parse_buffer("empty", NULL, 0, &err);
  assert_non_null(sc);
  assert_int_equal(sc->objectCount, 0);
  assert_null(sc->objects);
  assert_string_equal(sc->path, "empty");
  check_default_settings(&sc->settings);
  pd_scene_free(sc);

  sc = parse_text("# nothing but comments\n\n   \t\n# and blank lines\n");
  assert_int_equal(sc->objectCount, 0);
  check_default_settings(&sc->settings);
  pd_scene_free(sc);

  char path[1024];
  write_file(tmp_path(path, sizeof path, "empty.scene"), "", 0);
  sc = pd_scene_parse_file(path, &err);
  assert_non_null(sc);
  assert_int_equal(sc->objectCount, 0);
  assert_string_equal(sc->path, path);
  pd_scene_free(sc);
  unlink(path);
}

static void test_settings_are_parsed_with_mask_and_location(void** state) {
  (void)state;
  pdScene* sc = parse_text(
      "gravity 1 -2 3.5\n"
      "tend 2.5\n"
      "tol 1e-8\n"
      "dt 1e-4\n"
      "dtmin 1e-7\n"
      "dtmax 1e-3\n"
      "sample 1000\n"
      "vmax 5\n"
      "  deflection 0.02\n"
      "sleep off\n");
  const pdSceneSettings* s = &sc->settings;
  assert_true(s->gravity[0] == 1 && s->gravity[1] == -2 && s->gravity[2] == 3.5);
  assert_true(s->tend == 2.5);
  assert_true(s->tol == 1e-8);
  assert_true(s->dt == 1e-4);
  assert_true(s->dtmin == 1e-7);
  assert_true(s->dtmax == 1e-3);
  assert_true(s->sample == 1000);
  assert_true(s->vmax == 5);
  assert_true(s->deflection == 0.02);
  assert_false(s->sleep);
  assert_int_equal(s->setMask, PD_SET_GRAVITY | PD_SET_TEND | PD_SET_TOL | PD_SET_DT | PD_SET_DTMIN | PD_SET_DTMAX |
                                   PD_SET_SAMPLE | PD_SET_VMAX | PD_SET_DEFLECTION | PD_SET_SLEEP);
  for (int i = 0; i < 10; ++i) assert_int_equal(s->where[i].line, i + 1);
  assert_int_equal(s->where[8].col, 3);
  assert_int_equal(sc->objectCount, 0);
  pd_scene_free(sc);
}

static void test_settings_last_one_wins_and_others_keep_defaults(void** state) {
  (void)state;
  pdScene* sc = parse_text("tend 3\ncube a red 1 1 1\ntend 4\n");
  assert_true(sc->settings.tend == 4);
  assert_int_equal(sc->settings.setMask, PD_SET_TEND);
  assert_int_equal(sc->settings.where[1].line, 3);
  assert_true(sc->settings.dt == PD_DEFAULT_DT);
  assert_true(sc->settings.gravity[2] == PD_DEFAULT_GRAVITY_Z);
  pd_scene_free(sc);
}

static void test_primitives_are_parsed_with_kind_sides_scale_and_taper(void** state) {
  (void)state;
  pdScene* sc = parse_text(
      "cube box red 1 2 3\n"
      "prism p 88aaff 6 0.5 0.25 2\n"
      "tprism tp blue 3 1 1 1 0.5\n"
      "sphere s green 2 0.1 0.2 0.3\n"
      "sphere s0 green 0 1 1 1\n"
      "prism p64 x 64 1 1 1\n");
  assert_int_equal(sc->objectCount, 6);
  const pdSceneObject* o = sc->objects;
  assert_string_equal(o[0].name, "box");
  assert_string_equal(o[0].color, "red");
  assert_int_equal(o[0].kind, pd_primCube);
  assert_int_equal(o[0].n, 0);
  assert_true(o[0].scale[0] == 1 && o[0].scale[1] == 2 && o[0].scale[2] == 3);
  assert_true(o[0].taper == 1);
  assert_null(o[0].points);
  assert_int_equal(o[0].where.line, 1);
  assert_int_equal(o[0].where.col, 1);

  assert_int_equal(o[1].kind, pd_primPrism);
  assert_string_equal(o[1].color, "88aaff");
  assert_int_equal(o[1].n, 6);
  assert_true(o[1].scale[0] == 0.5 && o[1].scale[1] == 0.25 && o[1].scale[2] == 2);

  assert_int_equal(o[2].kind, pd_primTprism);
  assert_int_equal(o[2].n, 3);
  assert_true(o[2].taper == 0.5);

  assert_int_equal(o[3].kind, pd_primSphere);
  assert_int_equal(o[3].n, 2);
  assert_true(o[3].scale[2] == 0.3);
  assert_int_equal(o[4].n, 0);
  assert_int_equal(o[5].n, 64);
  assert_int_equal(o[5].where.line, 6);
  pd_scene_free(sc);
}

static void test_object_defaults_when_no_properties_are_given(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 1 1 1\n");
  const pdSceneObject* o = &sc->objects[0];
  assert_false(o->fixed);
  for (int i = 0; i < 3; ++i) {
    assert_true(o->loc[i] == 0);
    assert_true(o->vel[i] == 0);
  }
  assert_true(o->locAngle == 0 && o->spin == 0);
  assert_true(o->locAxis[0] == 0 && o->locAxis[1] == 0 && o->locAxis[2] == 1);
  assert_true(o->spinAxis[0] == 0 && o->spinAxis[1] == 0 && o->spinAxis[2] == 1);
  assert_true(o->spgrav == PD_DEFAULT_SPGRAV);
  assert_true(o->mu == PD_DEFAULT_MU);
  assert_true(o->kn == 0 && o->kt == 0 && o->cn == 0 && o->ct == 0);
  assert_int_equal(o->setMask, 0);
  pd_scene_free(sc);
}

static void test_properties_apply_to_the_last_object_with_mask_bits(void** state) {
  (void)state;
  pdScene* sc = parse_text(
      "cube floor grey 10 10 1\n"
      "fixed\n"
      "mu 0.8\n"
      "cube b red 1 1 1\n"
      "loc 1 2 3\n"
      "vel -1 0 0.5\n"
      "spgrav 2.7\n"
      "mu 0\n"
      "kn 1e5\n"
      "kt 2e5\n"
      "cn 10\n"
      "ct 0\n"
      "restitution 1\n");
  const pdSceneObject* f = &sc->objects[0];
  const pdSceneObject* b = &sc->objects[1];
  assert_true(f->fixed);
  assert_true(f->mu == 0.8);
  assert_int_equal(f->setMask, PD_SET_MU);
  assert_false(b->fixed);
  assert_true(b->loc[0] == 1 && b->loc[1] == 2 && b->loc[2] == 3);
  assert_true(b->vel[0] == -1 && b->vel[1] == 0 && b->vel[2] == 0.5);
  assert_true(b->spgrav == 2.7);
  assert_true(b->mu == 0);
  assert_true(b->kn == 1e5 && b->kt == 2e5 && b->cn == 10 && b->ct == 0);
  assert_true(b->restitution == 1);
  assert_int_equal(b->setMask, PD_SET_LOC | PD_SET_VEL | PD_SET_SPGRAV | PD_SET_MU | PD_SET_KN | PD_SET_KT |
                                   PD_SET_CN | PD_SET_CT | PD_SET_RESTITUTION);
  pd_scene_free(sc);
}

static void test_force_with_ramp_and_point_in_either_order(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 1 1 1\nforce 1 -2 3\n"
                           "cube b red 1 1 1\nforce 0 0 0 at 0.5 0 -0.25 ramp 4 0 -1\n"
                           "cube c red 1 1 1\nforce 0 1e3 0 ramp 0x1p-2 0 0\n"
                           "cube d red 1 1 1\n");
  const pdSceneObject *a = &sc->objects[0], *b = &sc->objects[1], *c = &sc->objects[2], *d = &sc->objects[3];
  assert_int_equal(a->setMask, PD_SET_FORCE);
  assert_true(a->force[0] == 1 && a->force[1] == -2 && a->force[2] == 3);
  assert_true(a->forceRate[0] == 0 && a->forceRate[1] == 0 && a->forceRate[2] == 0);
  assert_true(a->forcePoint[0] == 0 && a->forcePoint[1] == 0 && a->forcePoint[2] == 0);
  assert_int_equal(a->forceWhere.line, 2);
  assert_int_equal(a->forceWhere.col, 1);
  assert_true(b->forceRate[0] == 4 && b->forceRate[1] == 0 && b->forceRate[2] == -1);
  assert_true(b->forcePoint[0] == 0.5 && b->forcePoint[1] == 0 && b->forcePoint[2] == -0.25);
  assert_true(c->force[1] == 1e3 && c->forceRate[0] == 0.25);
  assert_int_equal(d->setMask, 0);
  assert_int_equal(d->forceWhere.line, 0);
  pd_scene_free(sc);
}

static void test_error_force_arity_keywords_values_and_fixed_bodies(void** state) {
  (void)state;
  expect_error("force 1 2 3\n", 1, 1, "property 'force' before any object");
  expect_error("cube a red 1 1 1\nforce 1 2\n", 2, 1, "'force' expects 3 arguments (fx fy fz [ramp rx ry rz] [at x y z]), got 2");
  expect_error("cube a red 1 1 1\nforce 1 2 3 ramp 1 2\n", 2, 13, "'ramp' expects 3 numbers (rx ry rz), got 2");
  expect_error("cube a red 1 1 1\nforce 1 2 3 at\n", 2, 13, "'at' expects 3 numbers (x y z), got 0");
  expect_error("cube a red 1 1 1\nforce 1 2 3 push 1 2 3\n", 2, 13, "expected 'ramp' or 'at' after the force, got 'push'");
  expect_error("cube a red 1 1 1\nforce 1 2 3 at 0 0 0 at 1 1 1\n", 2, 22, "'at' given twice");
  expect_error("cube a red 1 1 1\nforce 1 2 3 ramp 0 0 0 at 0 0 0 9\n", 2, 33,
               "too many arguments: 'force' expects at most 11");
  expect_error("cube a red 1 1 1\nforce 1 nan 3\n", 2, 9, "not a finite number: 'nan' (for force)");
  expect_error("cube a red 1 1 1\nforce 1 2 3 ramp 1e999 0 0\n", 2, 18, "not a finite number: '1e999' (for force ramp)");
  expect_error("cube a red 1 1 1\nforce 1 2 3 at 0 x 0\n", 2, 18, "not a number: 'x' (for force point)");
  expect_error("cube a red 1 1 1\nforce 1 2 3 at 0 0 2e6\n", 2, 20, "force point must be within +-1e6 m");
  expect_error("cube a red 1 1 1\nfixed\nforce 1 2 3\n", 3, 1, "'force' on the fixed body 'a'");
  expect_error("cube a red 1 1 1\nforce 1 2 3\nfixed\n", 3, 1, "'fixed' on body 'a', which has a force (line 2)");
  expect_error("cube a red 1 1 1\nforce 1 2 3\nforce 0 0 1\n", 3, 1,
               "body 'a' already has a force (line 2): at most one force per body");
}

static void test_loc_angle_in_degrees_is_stored_in_radians(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 1 1 1\nloc 0 0 0.5 90 1 0 0\ncube b red 1 1 1\nloc 1 1 1 -45 0 2 0\n");
  const pdSceneObject* a = &sc->objects[0];
  assert_true(fabs(a->locAngle - PI / 2) < 1e-15);
  assert_true(a->locAxis[0] == 1 && a->locAxis[1] == 0 && a->locAxis[2] == 0);
  assert_true(a->loc[2] == 0.5);
  assert_true(fabs(sc->objects[1].locAngle + PI / 4) < 1e-15);
  assert_true(sc->objects[1].locAxis[1] == 2);
  pd_scene_free(sc);
}

static void test_vel_spin_in_degrees_per_second_is_stored_in_radians_per_second(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 1 1 1\nvel 1 2 3 360 0 1 0\n");
  const pdSceneObject* a = &sc->objects[0];
  assert_true(fabs(a->spin - 2 * PI) < 1e-14);
  assert_true(a->spinAxis[0] == 0 && a->spinAxis[1] == 1 && a->spinAxis[2] == 0);
  assert_true(a->vel[0] == 1 && a->vel[2] == 3);
  assert_int_equal(a->setMask, PD_SET_VEL);
  pd_scene_free(sc);
}

static void test_zero_angle_allows_zero_axis_and_short_form_resets_rotation(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 1 1 1\nloc 0 0 0 0 0 0 0\ncube b red 1 1 1\nloc 0 0 0 30 1 0 0\nloc 5 0 0\n");
  assert_true(sc->objects[0].locAngle == 0);
  assert_true(sc->objects[0].locAxis[2] == 1);  // a zero axis keeps the default
  assert_true(sc->objects[1].locAngle == 0);
  assert_true(sc->objects[1].locAxis[0] == 0 && sc->objects[1].locAxis[2] == 1);
  assert_true(sc->objects[1].loc[0] == 5);
  pd_scene_free(sc);
}

static void test_hull_over_continuation_lines(void** state) {
  (void)state;
  pdScene* sc = parse_text(
      "hull h white \\\n"
      "  0 0 0 \\\n"
      "  1 0 0 \\   # a comment after the backslash\n"
      "\t0 1 0\\\n"
      "  0 0 1.5   # last point\n"
      "fixed\n");
  assert_int_equal(sc->objectCount, 1);
  const pdSceneObject* h = &sc->objects[0];
  assert_int_equal(h->kind, pd_primHull);
  assert_int_equal(h->pointCount, 4);
  assert_non_null(h->points);
  static const double expected[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1.5};
  for (int i = 0; i < 12; ++i) assert_true(h->points[i] == expected[i]);
  assert_true(h->scale[0] == 1 && h->scale[1] == 1 && h->scale[2] == 1);
  assert_true(h->fixed);
  pd_scene_free(sc);
}

static void test_continuation_joins_any_command_and_keeps_inner_backslashes(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube \\\n a\\b \\\n red 1 \\\n\\\n 2 3\ntend \\\n 7\n");
  assert_int_equal(sc->objectCount, 1);
  assert_string_equal(sc->objects[0].name, "a\\b");
  assert_true(sc->objects[0].scale[2] == 3);
  assert_true(sc->settings.tend == 7);
  assert_int_equal(sc->settings.where[1].line, 6);
  pd_scene_free(sc);
}

static void test_comments_after_arguments_and_anywhere(void** state) {
  (void)state;
  pdScene* sc = parse_text("# header\ncube a red 1 2 3 # a comment\ntend 2#glued comment\n   # indented\n");
  assert_int_equal(sc->objectCount, 1);
  assert_true(sc->objects[0].scale[2] == 3);
  assert_true(sc->settings.tend == 2);
  pd_scene_free(sc);
  // '#' starts a comment even at the start of a would-be colour
  expect_error("cube a #88aaff 1 1 1\n", 1, 1, "'cube' expects 5 arguments (NAME COLOR sx sy sz), got 1");
}

static void test_crlf_line_ends(void** state) {
  (void)state;
  pdScene* sc = parse_text("tend 2\r\ncube a red 1 2 3\r\n\r\nhull h w 0 0 0 1 0 0 \\\r\n 0 1 0 0 0 1\r\nfixed\r\n");
  assert_int_equal(sc->objectCount, 2);
  assert_true(sc->settings.tend == 2);
  assert_true(sc->objects[0].scale[2] == 3);
  assert_int_equal(sc->objects[1].pointCount, 4);
  assert_int_equal(sc->objects[1].where.line, 4);
  assert_true(sc->objects[1].fixed);
  pd_scene_free(sc);
  // an error on a CRLF line still points at the right column
  expect_error("tend 2\r\ncube a red 1 -2 3\r\n", 2, 14, "size must be > 0, got -2");
}

static void test_tabs_blank_lines_no_final_newline_and_bom(void** state) {
  (void)state;
  pdScene* sc = parse_text("\xEF\xBB\xBF\n\n\tcube\ta\tred\t1\t1\t1\f\v\n\n   sphere b blue 1 1 1 1");
  assert_int_equal(sc->objectCount, 2);
  assert_int_equal(sc->objects[0].where.line, 3);
  assert_int_equal(sc->objects[0].where.col, 2);
  assert_int_equal(sc->objects[1].where.line, 5);
  assert_int_equal(sc->objects[1].where.col, 4);
  pd_scene_free(sc);
}

static void test_hex_float_and_signed_numbers_are_accepted(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube a red 0x1p-1 +2 .5e1\n");
  assert_true(sc->objects[0].scale[0] == 0.5 && sc->objects[0].scale[1] == 2 && sc->objects[0].scale[2] == 5);
  pd_scene_free(sc);
}

static void test_success_leaves_error_untouched(void** state) {
  (void)state;
  pdError err;
  memset(&err, 0x5a, sizeof err);
  pdError copy = err;
  pdScene* sc = pd_scene_parse_buffer("x", "cube a b 1 1 1\n", 15, &err);
  assert_non_null(sc);
  assert_memory_equal(&err, &copy, sizeof err);
  pd_scene_free(sc);
  // a NULL error is allowed on both paths
  assert_null(pd_scene_parse_buffer("x", "bogus\n", 6, NULL));
}

// Field by field: structs with padding cannot be compared with memcmp.
static void assert_same_object(const pdSceneObject* a, const pdSceneObject* b) {
  assert_string_equal(a->name, b->name);
  assert_string_equal(a->color, b->color);
  assert_int_equal(a->kind, b->kind);
  assert_int_equal(a->n, b->n);
  assert_memory_equal(a->scale, b->scale, sizeof a->scale);
  assert_true(a->taper == b->taper);
  assert_int_equal(a->pointCount, b->pointCount);
  if (a->pointCount) assert_memory_equal(a->points, b->points, (size_t)a->pointCount * 3 * sizeof(double));
  assert_int_equal(a->fixed, b->fixed);
  assert_memory_equal(a->loc, b->loc, sizeof a->loc);
  assert_true(a->locAngle == b->locAngle);
  assert_memory_equal(a->locAxis, b->locAxis, sizeof a->locAxis);
  assert_memory_equal(a->vel, b->vel, sizeof a->vel);
  assert_true(a->spin == b->spin);
  assert_memory_equal(a->spinAxis, b->spinAxis, sizeof a->spinAxis);
  double pa[7] = {a->spgrav, a->mu, a->kn, a->kt, a->cn, a->ct, a->restitution};
  double pb[7] = {b->spgrav, b->mu, b->kn, b->kt, b->cn, b->ct, b->restitution};
  assert_memory_equal(pa, pb, sizeof pa);
  assert_int_equal(a->setMask, b->setMask);
  assert_int_equal(a->where.line, b->where.line);
  assert_int_equal(a->where.col, b->where.col);
}

static void assert_same_settings(const pdSceneSettings* a, const pdSceneSettings* b) {
  double va[11] = {a->gravity[0], a->gravity[1], a->gravity[2], a->tend, a->tol, a->dt, a->dtmin, a->dtmax,
                   a->sample, a->vmax, a->deflection};
  double vb[11] = {b->gravity[0], b->gravity[1], b->gravity[2], b->tend, b->tol, b->dt, b->dtmin, b->dtmax,
                   b->sample, b->vmax, b->deflection};
  assert_memory_equal(va, vb, sizeof va);
  assert_int_equal(a->setMask, b->setMask);
  assert_memory_equal(a->where, b->where, sizeof a->where);
}

static void test_file_and_buffer_parse_to_the_same_scene(void** state) {
  (void)state;
  const char* text =
      "gravity 0 0 -9.81\ntend 2\nsample 50\n"
      "cube floor grey 10 10 0.5\nfixed\nloc 0 0 -0.25\n"
      "tprism t red 5 1 1 1 0.3 # frustum\nloc 0 0 2 30 1 1 0\nvel 0 0 -1 90 0 0 1\nrestitution 0.5\n"
      "hull h blue 0 0 0 1 0 0 \\\n 0 1 0 0 0 1\nmu 0.2\nkn 1e6\n";
  char path[1024];
  write_file(tmp_path(path, sizeof path, "same.scene"), text, strlen(text));
  pdError err;
  pdScene* a = pd_scene_parse_buffer(path, text, strlen(text), &err);
  pdScene* b = pd_scene_parse_file(path, &err);
  assert_non_null(a);
  assert_non_null(b);
  assert_string_equal(a->path, b->path);
  assert_same_settings(&a->settings, &b->settings);
  assert_int_equal(a->settings.setMask, PD_SET_GRAVITY | PD_SET_TEND | PD_SET_SAMPLE);
  assert_int_equal(a->objectCount, 3);
  assert_int_equal(b->objectCount, 3);
  for (int i = 0; i < a->objectCount; ++i) assert_same_object(&a->objects[i], &b->objects[i]);
  pd_scene_free(a);
  pd_scene_free(b);
  unlink(path);
}

static void test_hull_with_10000_points_on_one_line(void** state) {
  (void)state;
  enum { N = 10000 };
  size_t cap = 64 + (size_t)N * 3 * 16;
  char* text = malloc(cap);
  assert_non_null(text);
  size_t len = (size_t)snprintf(text, cap, "hull big white");
  for (int i = 0; i < N; ++i) {
    len += (size_t)snprintf(text + len, cap - len, " %d.25 %d -%d", i % 1000, i / 1000, i % 7);
  }
  text[len++] = '\n';
  char path[1024];
  write_file(tmp_path(path, sizeof path, "hull.scene"), text, len);
  free(text);
  pdError err;
  pdScene* sc = pd_scene_parse_file(path, &err);
  assert_non_null(sc);
  assert_int_equal(sc->objectCount, 1);
  assert_int_equal(sc->objects[0].pointCount, N);
  assert_true(sc->objects[0].points[3 * 1234 + 0] == 234.25);
  assert_true(sc->objects[0].points[3 * 1234 + 1] == 1);
  assert_true(sc->objects[0].points[3 * 1234 + 2] == -(1234 % 7));
  pd_scene_free(sc);
  unlink(path);
}

// ---------------------------------------------------------------------------------------------
// errors

static void test_error_unknown_command(void** state) {
  (void)state;
  expect_error("tend 1\n  cbe a red 1 1 1\n", 2, 3, "unknown command 'cbe'");
  expect_error("Cube a red 1 1 1\n", 1, 1, "unknown command 'Cube'");  // keywords are case sensitive
}

static void test_error_too_few_arguments_points_at_the_command(void** state) {
  (void)state;
  expect_error("\n cube a red 1 1\n", 2, 2, "'cube' expects 5 arguments (NAME COLOR sx sy sz), got 4");
  expect_error("tend\n", 1, 1, "'tend' expects 1 argument (T), got 0");
  expect_error("cube a red 1 1 1\nloc 1 2 3 4 5\n", 2, 1, "'loc' expects 3 or 7 arguments");
  expect_error("hull h\n", 1, 1, "'hull' expects NAME COLOR");
}

static void test_error_too_many_arguments_points_at_the_first_extra(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1 9 8\n", 1, 18, "too many arguments: 'cube' expects 5");
  expect_error("cube a red 1 1 1\nfixed now\n", 2, 7, "too many arguments: 'fixed' takes none");
  expect_error("cube a red 1 1 1\nvel 1 2 3 4 5 6 7 8\n", 2, 19, "too many arguments: 'vel' expects at most 7");
}

static void test_error_not_a_number(void** state) {
  (void)state;
  expect_error("cube a red 1 1x 1\n", 1, 14, "not a number: '1x'");
  expect_error("gravity 0 0 -9,81\n", 1, 13, "not a number: '-9,81'");
  expect_error("cube a red 1 1 1\nmu --1\n", 2, 4, "not a number");
}

static void test_error_nan_inf_and_overflow_are_not_finite(void** state) {
  (void)state;
  expect_error("cube a red nan 1 1\n", 1, 12, "not a finite number: 'nan'");
  expect_error("cube a red 1 -INF 1\n", 1, 14, "not a finite number: '-INF'");
  expect_error("cube a red 1 1 infinity\n", 1, 16, "not a finite number: 'infinity'");
  expect_error("tend 1e999\n", 1, 6, "not a finite number: '1e999'");
  expect_error("cube a red 1 1 1\nloc 0 0 NaN\n", 2, 9, "not a finite number");
}

static void test_error_size_not_positive_or_over_sanity_bound(void** state) {
  (void)state;
  expect_error("cube a red 1 -1 1\n", 1, 14, "size must be > 0, got -1");
  expect_error("sphere a red 1 1 1 0\n", 1, 20, "size must be > 0, got 0");
  expect_error("cube a red 1 1 2e6\n", 1, 16, "at most 1e6 m");
  expect_error("hull h w 0 0 0 1 0 0 0 1 0 0 0 -3e6\n", 1, 32, "sanity bound");
}

static void test_error_density_not_positive(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1\nspgrav 0\n", 2, 8, "spgrav must be > 0, got 0");
  expect_error("cube a red 1 1 1\nspgrav -2.5\n", 2, 8, "spgrav must be > 0, got -2.5");
}

static void test_error_prism_sides_out_of_range_or_fractional(void** state) {
  (void)state;
  expect_error("prism p red 2 1 1 1\n", 1, 13, "prism sides must be an integer in 3..64, got 2");
  expect_error("prism p red 65 1 1 1\n", 1, 13, "prism sides must be an integer in 3..64, got 65");
  expect_error("tprism p red 3.5 1 1 1 1\n", 1, 14, "prism sides must be an integer in 3..64, got 3.5");
  expect_error("prism p red six 1 1 1\n", 1, 13, "prism sides must be an integer in 3..64, got six");
}

static void test_error_taper_out_of_range(void** state) {
  (void)state;
  expect_error("tprism t red 4 1 1 1 0\n", 1, 22, "taper must be in (0, 1], got 0");
  expect_error("tprism t red 4 1 1 1 1.5\n", 1, 22, "taper must be in (0, 1], got 1.5");
}

static void test_error_sphere_level_out_of_range(void** state) {
  (void)state;
  expect_error("sphere s red 4 1 1 1\n", 1, 14, "sphere level must be an integer in 0..3, got 4");
  expect_error("sphere s red -1 1 1 1\n", 1, 14, "sphere level must be an integer in 0..3");
}

static void test_error_property_ranges(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1\nrestitution 1.2\n", 2, 13, "restitution must be in [0, 1], got 1.2");
  expect_error("cube a red 1 1 1\nrestitution -0.1\n", 2, 13, "restitution must be in [0, 1]");
  expect_error("cube a red 1 1 1\nmu 11\n", 2, 4, "mu must be in [0, 10], got 11");
  expect_error("cube a red 1 1 1\nkn 0\n", 2, 4, "kn must be > 0, got 0");
  expect_error("cube a red 1 1 1\nkt -1\n", 2, 4, "kt must be > 0");
  expect_error("cube a red 1 1 1\ncn -1\n", 2, 4, "cn must be >= 0, got -1");
  expect_error("cube a red 1 1 1\nct -0.5\n", 2, 4, "ct must be >= 0");
}

static void test_error_setting_ranges(void** state) {
  (void)state;
  expect_error("tend 0\n", 1, 6, "tend must be > 0, got 0");
  expect_error("tol 1\n", 1, 5, "tol must be in (0, 1), got 1");
  expect_error("tol 0\n", 1, 5, "tol must be in (0, 1)");
  expect_error("dt -1e-3\n", 1, 4, "dt must be > 0");
  expect_error("dtmin 0\n", 1, 7, "dtmin must be > 0");
  expect_error("dtmax 0\n", 1, 7, "dtmax must be > 0");
  expect_error("sample 0\n", 1, 8, "sample must be > 0");
  expect_error("vmax 0\n", 1, 6, "vmax must be > 0");
  expect_error("deflection 1\n", 1, 12, "deflection must be in (0, 1), got 1");
  expect_error("sleep 0\n", 1, 7, "sleep must be on or off, got '0'");
  expect_error("sleep on off\n", 1, 10, "too many arguments: 'sleep' expects 1 (on|off)");
}

static void test_error_zero_rotation_axis_with_nonzero_angle(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1\nloc 0 0 0 45 0 0 0\n", 2, 14, "axis must be non-zero");
  expect_error("cube a red 1 1 1\nvel 0 0 0 10 0 0 0\n", 2, 14, "axis must be non-zero");
}

static void test_error_property_before_any_object(void** state) {
  (void)state;
  expect_error("tend 1\n  loc 0 0 1\ncube a red 1 1 1\n", 2, 3, "property 'loc' before any object");
  expect_error("fixed\n", 1, 1, "property 'fixed' before any object");
}

static void test_error_duplicate_name_reports_the_first_definition(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1\n\nsphere b red 1 1 1 1\nprism a blue 3 1 1 1\n", 4, 7,
               "duplicate name 'a' (first defined at line 1)");
  expect_error("cube a red 1 1 1\nhull a w 0 0 0 1 0 0 0 1 0 0 0 1\n", 2, 6, "duplicate name 'a'");
}

// The rule for names (docs/names-and-files.md): any word of valid UTF-8. A word may hold what CSV and JSON
// must quote or escape; a name or colour that is not UTF-8 is refused at its first bad byte.
static void test_names_are_any_word_of_valid_utf8(void** state) {
  (void)state;
  pdScene* sc = parse_text("cube <img/src=x/onerror=document.title=\"PWNED\"> red 1 1 1\n"
                           "cube a,b;c:d'e t\xc3\xaate 1 1 1\n"
                           "hull \xe7\xae\xb1\xf0\x9f\x98\x80 \xe2\x80\x94 0 0 0 1 0 0 0 1 0 0 0 1\n");
  assert_int_equal(sc->objectCount, 3);
  assert_string_equal(sc->objects[0].name, "<img/src=x/onerror=document.title=\"PWNED\">");
  assert_string_equal(sc->objects[1].name, "a,b;c:d'e");
  assert_string_equal(sc->objects[1].color, "t\xc3\xaate");
  assert_string_equal(sc->objects[2].name, "\xe7\xae\xb1\xf0\x9f\x98\x80");
  pd_scene_free(sc);
  expect_error("cube ab\xff red 1 1 1\n", 1, 8, "the name is not valid UTF-8 (byte 0xFF)");
  expect_error("cube ok red 1 1 1\nsphere \xc3( red 1 1 1 1\n", 2, 8, "the name is not valid UTF-8 (byte 0xC3)");
  expect_error("cube a \xed\xa0\x80 1 1 1\n", 1, 8, "the colour is not valid UTF-8 (byte 0xED)");  // a surrogate
  expect_error("cube a r\xc0\xaf 1 1 1\n", 1, 9, "the colour is not valid UTF-8 (byte 0xC0)");    // overlong '/'
  expect_error("hull \xf4\x90\x80\x80 w 0 0 0 1 0 0 0 1 0 0 0 1\n", 1, 6, "the name is not valid UTF-8");
}

static void test_error_hull_with_3_points(void** state) {
  (void)state;
  expect_error("cube a red 1 1 1\nhull h w 0 0 0 \\\n 1 0 0 0 1 0\n", 2, 1, "hull needs at least 4 points, got 3");
}

static void test_error_hull_with_10_coordinates(void** state) {
  (void)state;
  expect_error("hull h w 0 0 0 1 0 0 0 1 0 0\n", 1, 1, "x y z triples, got 10 numbers");
}

static void test_error_dt_below_dtmin_and_above_dtmax(void** state) {
  (void)state;
  expect_error("dtmin 1e-3\ncube a red 1 1 1\ndt 1e-4\n", 3, 1, "dt 0.0001 is below dtmin 0.001");
  expect_error("dtmin 1e-2\n", 1, 1, "is below dtmin");  // against the default dt
  expect_error("tend 1\n dt 0.5\n", 2, 2, "dt 0.5 is above dtmax 0.01");
  expect_error("dtmax 1e-4\n", 1, 1, "is above dtmax");
}

static void test_error_too_many_output_samples(void** state) {
  (void)state;
  expect_error("tend 1000\nsample 1e6\n", 2, 1, "too many output samples");
  expect_error("sample 1e6\ntend 1000\n", 2, 1, "too many output samples");
  pdScene* sc = parse_text("tend 100\nsample 1e6\n");  // exactly 1e8 is allowed
  pd_scene_free(sc);
}

static void test_error_on_a_continuation_line_has_its_physical_location(void** state) {
  (void)state;
  expect_error("hull h w 0 0 0 \\\n   1 0 0 \\\n  0 zz 0\n", 3, 5, "not a number: 'zz'");
  expect_error("cube a red \\\n 1 1 1 \\\n   extra\n", 3, 4, "too many arguments");
}

static void test_error_message_truncates_and_escapes_user_text(void** state) {
  (void)state;
  char text[200];
  memset(text, 'k', 100);
  memcpy(text + 100, "\n", 2);
  pdError err;
  assert_null(pd_scene_parse_buffer("t", text, strlen(text), &err));
  char expected[128];
  snprintf(expected, sizeof expected, "unknown command '%.40s...'", text);
  assert_string_equal(err.message, expected);

  expect_error("caf\xc3\xa9 1\n", 1, 1, "unknown command 'caf\\xC3\\xA9'");
}

static void test_error_missing_file_and_directory(void** state) {
  (void)state;
  char path[1024];
  pdError err;
  assert_null(pd_scene_parse_file(tmp_path(path, sizeof path, "no-such.scene"), &err));
  assert_int_equal(err.line, 0);
  assert_string_equal(err.file, path);
  assert_non_null(strstr(err.message, "cannot open: No such file or directory"));

  assert_null(pd_scene_parse_file(tmpDir, &err));
  assert_int_equal(err.line, 0);
  assert_non_null(strstr(err.message, "is a directory"));
}

static void test_error_nul_and_control_bytes_are_not_text(void** state) {
  (void)state;
  expect_error_len("tend 1\ncube a\0 red 1 1 1\n", 25, 2, 7, "not a text file (byte 0x00)");
  expect_error("cube a red 1 1 1 # a bell \a in a comment\n", 1, 27, "not a text file (byte 0x07)");
  expect_error("\n\n\x1b[31m\n", 3, 1, "byte 0x1B");
  expect_error("tend 1\x7f\n", 1, 7, "byte 0x7F");
}

static void test_error_token_too_long_on_a_1mb_line(void** state) {
  (void)state;
  size_t len = 1 << 20;
  char* text = malloc(len + 8);
  assert_non_null(text);
  memcpy(text, "cube ", 5);
  memset(text + 5, 'a', len);
  memcpy(text + 5 + len, "\n", 2);
  expect_error_len(text, len + 6, 1, 6, "token too long");
  // exactly the limit is fine as a name
  memcpy(text + 5 + 4096, " red 1 1 1\n", 12);
  pdScene* sc = parse_text(text);
  assert_int_equal(strlen(sc->objects[0].name), 4096);
  pd_scene_free(sc);
  free(text);
}

static void test_error_100mb_junk_file_is_refused_fast_at_line_1(void** state) {
  (void)state;
  char path[1024];
  tmp_path(path, sizeof path, "junk.scene");
  FILE* f = fopen(path, "wb");
  assert_non_null(f);
  enum { BLOCK = 1 << 20 };
  unsigned char* block = malloc(BLOCK);
  assert_non_null(block);
  uint64_t x = 0x9E3779B97F4A7C15u;  // fixed seed: junk bytes, no newline
  for (int b = 0; b < 100; ++b) {
    for (int i = 0; i < BLOCK; ++i) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      unsigned char c = (unsigned char)(x >> 24);
      block[i] = c == '\n' ? 'n' : c;
    }
    if (b == 0) block[0] = 'J';
    assert_int_equal(fwrite(block, 1, BLOCK, f), BLOCK);
  }
  assert_int_equal(fclose(f), 0);
  free(block);

  pdError err;
  double t0 = seconds_now();
  pdScene* sc = pd_scene_parse_file(path, &err);
  double elapsed = seconds_now() - t0;
  assert_null(sc);
  assert_int_equal(err.line, 1);
  assert_true(elapsed < 3.0);
  unlink(path);
}

static void test_10mb_comments_only_file_parses_fast(void** state) {
  (void)state;
  char path[1024];
  tmp_path(path, sizeof path, "comments.scene");
  FILE* f = fopen(path, "wb");
  assert_non_null(f);
  const char* lines = "# a comment line that says nothing much at all, padded to some length ......\n\n   \t\r\n";
  size_t n = strlen(lines), total = 0;
  while (total < 10u << 20) {
    assert_int_equal(fwrite(lines, 1, n, f), n);
    total += n;
  }
  assert_true(fputs("cube last red 1 1 1\n", f) >= 0);
  assert_int_equal(fclose(f), 0);

  pdError err;
  double t0 = seconds_now();
  pdScene* sc = pd_scene_parse_file(path, &err);
  double elapsed = seconds_now() - t0;
  assert_non_null(sc);
  assert_int_equal(sc->objectCount, 1);
  assert_int_equal(sc->objects[0].where.line, (int)(total / n) * 3 + 1);
  assert_true(elapsed < 3.0);
  pd_scene_free(sc);
  unlink(path);
}

// ---------------------------------------------------------------------------------------------
// pdError

static void test_error_print_formats_with_and_without_line(void** state) {
  (void)state;
  char buf[1024];
  pdError err;
  FILE* out = fmemopen(buf, sizeof buf, "w");
  assert_non_null(out);
  pd_error_set(&err, "a.scene", 3, 7, "unknown command '%s'", "cbe");
  pd_error_print(&err, out);
  pd_error_set(&err, "a.scene", 0, 0, "cannot open: %s", "No such file or directory");
  pd_error_print(&err, out);
  fclose(out);
  assert_string_equal(buf, "a.scene:3:7: unknown command 'cbe'\na.scene: cannot open: No such file or directory\n");
}

static void test_error_set_truncates_long_message_and_file_name(void** state) {
  (void)state;
  char longText[2000];
  memset(longText, 'x', sizeof longText - 1);
  longText[sizeof longText - 1] = '\0';
  pdError err;
  pd_error_set(&err, longText, 1, 1, "%s and more", longText);
  assert_int_equal(strlen(err.file), PD_ERROR_MESSAGE_MAX - 1);
  assert_int_equal(strlen(err.message), PD_ERROR_MESSAGE_MAX - 1);
  assert_string_equal(err.message + PD_ERROR_MESSAGE_MAX - 4, "...");
  pd_error_set(&err, NULL, -5, -1, "line\nbreak");
  assert_string_equal(err.file, "");
  assert_int_equal(err.line, 0);
  assert_string_equal(err.message, "line break");
  pd_error_set(NULL, "x", 1, 1, "ignored");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_empty_scene_is_valid_with_default_settings),
      cmocka_unit_test(test_settings_are_parsed_with_mask_and_location),
      cmocka_unit_test(test_settings_last_one_wins_and_others_keep_defaults),
      cmocka_unit_test(test_primitives_are_parsed_with_kind_sides_scale_and_taper),
      cmocka_unit_test(test_object_defaults_when_no_properties_are_given),
      cmocka_unit_test(test_properties_apply_to_the_last_object_with_mask_bits),
      cmocka_unit_test(test_loc_angle_in_degrees_is_stored_in_radians),
      cmocka_unit_test(test_vel_spin_in_degrees_per_second_is_stored_in_radians_per_second),
      cmocka_unit_test(test_zero_angle_allows_zero_axis_and_short_form_resets_rotation),
      cmocka_unit_test(test_hull_over_continuation_lines),
      cmocka_unit_test(test_continuation_joins_any_command_and_keeps_inner_backslashes),
      cmocka_unit_test(test_comments_after_arguments_and_anywhere),
      cmocka_unit_test(test_crlf_line_ends),
      cmocka_unit_test(test_tabs_blank_lines_no_final_newline_and_bom),
      cmocka_unit_test(test_hex_float_and_signed_numbers_are_accepted),
      cmocka_unit_test(test_success_leaves_error_untouched),
      cmocka_unit_test(test_file_and_buffer_parse_to_the_same_scene),
      cmocka_unit_test(test_hull_with_10000_points_on_one_line),
      cmocka_unit_test(test_error_unknown_command),
      cmocka_unit_test(test_error_too_few_arguments_points_at_the_command),
      cmocka_unit_test(test_error_too_many_arguments_points_at_the_first_extra),
      cmocka_unit_test(test_error_not_a_number),
      cmocka_unit_test(test_error_nan_inf_and_overflow_are_not_finite),
      cmocka_unit_test(test_error_size_not_positive_or_over_sanity_bound),
      cmocka_unit_test(test_error_density_not_positive),
      cmocka_unit_test(test_error_prism_sides_out_of_range_or_fractional),
      cmocka_unit_test(test_error_taper_out_of_range),
      cmocka_unit_test(test_error_sphere_level_out_of_range),
      cmocka_unit_test(test_error_property_ranges),
      cmocka_unit_test(test_error_setting_ranges),
      cmocka_unit_test(test_error_zero_rotation_axis_with_nonzero_angle),
      cmocka_unit_test(test_error_property_before_any_object),
      cmocka_unit_test(test_error_duplicate_name_reports_the_first_definition),
      cmocka_unit_test(test_error_hull_with_3_points),
      cmocka_unit_test(test_error_hull_with_10_coordinates),
      cmocka_unit_test(test_error_dt_below_dtmin_and_above_dtmax),
      cmocka_unit_test(test_error_too_many_output_samples),
      cmocka_unit_test(test_error_on_a_continuation_line_has_its_physical_location),
      cmocka_unit_test(test_error_message_truncates_and_escapes_user_text),
      cmocka_unit_test(test_error_missing_file_and_directory),
      cmocka_unit_test(test_error_nul_and_control_bytes_are_not_text),
      cmocka_unit_test(test_error_token_too_long_on_a_1mb_line),
      cmocka_unit_test(test_error_100mb_junk_file_is_refused_fast_at_line_1),
      cmocka_unit_test(test_10mb_comments_only_file_parses_fast),
      cmocka_unit_test(test_force_with_ramp_and_point_in_either_order),
      cmocka_unit_test(test_error_force_arity_keywords_values_and_fixed_bodies),
      cmocka_unit_test(test_names_are_any_word_of_valid_utf8),
      cmocka_unit_test(test_error_print_formats_with_and_without_line),
      cmocka_unit_test(test_error_set_truncates_long_message_and_file_name),
  };
  return cmocka_run_group_tests(tests, make_tmp_dir, remove_tmp_dir);
}
