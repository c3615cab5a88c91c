// Tests of the cube-toss validation (validation/cubetoss*.c) on synthetic tosses, so they need no data: a
// toss in free flight whose record is the closed-form parabola and torque-free spin, bad CSV files, the
// statistics, toss lists, parameter fragments and the worker processes.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "pdval/cubetoss.h"

static const double kPi = 3.14159265358979323846;
static const double kG = 9.81;

// A scratch directory per test run (removed by the test harness's tmp cleanup is not assumed: removed here).
static char scratch[256];

static int make_scratch(void** state) {
  (void)state;
  snprintf(scratch, sizeof scratch, "%s/pd_test_cubetoss.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
  return mkdtemp(scratch) ? 0 : -1;
}

static int remove_scratch(void** state) {
  (void)state;
  char cmd[400];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", scratch);
  return system(cmd) == 0 ? 0 : -1;
}

static char* scratch_path(const char* name) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", scratch, name);
  return path;
}

static void write_file(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  assert_int_equal(fclose(f), 0);
}

// ---------------------------------------------------------------- a toss in free flight, in closed form

// The cube thrown from 0.6 m up: it stays 0.3 m above the board for `samples` ≤ 40 samples (0.26 s).
static const pdVec3 flightX0 = {0.1, -0.2, 0.6}, flightV0 = {0.8, 0.3, 0.5}, flightW = {3.0, -2.0, 5.0};

static pdBodyState flight_at(double t, pdQuat q0) {
  // isotropic inertia: ω stays constant in the world, q(t) = exp(ω t / 2) ⊗ q0
  double speed = pd_v3_norm(flightW), half = 0.5 * speed * t, s = sin(half) / speed;
  pdQuat turn = {cos(half), s * flightW.x, s * flightW.y, s * flightW.z};
  return (pdBodyState){.x = {flightX0.x + flightV0.x * t, flightX0.y + flightV0.y * t,
                             flightX0.z + flightV0.z * t - 0.5 * kG * t * t},
                       .q = pd_quat_normalize(pd_quat_mul(turn, q0)),
                       .v = {flightV0.x, flightV0.y, flightV0.z - kG * t},
                       .w = flightW};
}

// Writes tosses ids[0..count) of `samples` rows each, all in free flight, as the data's CSV.
static void write_flight_csv(const char* path, const long* ids, int count, int samples) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs("toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n", f);
  for (int i = 0; i < count; ++i) {
    pdQuat q0 = pd_quat_from_axis_angle(pd_v3(1.0, 2.0, -0.5 + i), 0.7 + 0.9 * i);
    if (i == 1) q0 = (pdQuat){-q0.w, -q0.x, -q0.y, -q0.z};  // w < 0: the sign must survive the scene
    for (int k = 0; k < samples; ++k) {
      double t = k / PD_TOSS_RATE;
      pdBodyState b = flight_at(t, q0);
      fprintf(f, "%ld,%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", ids[i], t,
              b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z);
    }
  }
  assert_int_equal(fclose(f), 0);
}

static pdTossSet* flight_set(int count, int samples) {
  static const long ids[] = {3, 4, 9, 12, 13, 20};
  assert_true(count <= 6);
  char* path = scratch_path("flight.csv");
  write_flight_csv(path, ids, count, samples);
  pdError err = {0};
  pdTossSet* set = pd_toss_read(path, &err);
  if (!set) fail_msg("%s:%d:%d: %s", err.file, err.line, err.col, err.message);
  assert_int_equal(set->count, count);
  return set;
}

static const pdTossEngine softEngine = {.name = "soft"};

static void test_free_flight_toss_matches_its_closed_form_record(void** state) {
  (void)state;
  pdTossSet* set = flight_set(2, 40);
  pdTossParams p = pd_toss_default_params();
  p.tol = 1e-10;  // the integration error must be far below the tolerances asserted here
  for (int i = 0; i < set->count; ++i) {
    const pdToss* toss = &set->tosses[i];
    pdTossResult r;
    pdTrajectory* tr = pd_toss_simulate(toss, &p, &softEngine, NULL, &r);
    assert_non_null(tr);
    assert_int_equal(r.status, pd_tossOk);
    assert_int_equal(tr->samples, toss->sampleCount);
    // the first sample is the record's (scene text at %.17g, angle-axis and spin conversions): 1e-12
    const pdBodyState *s0 = &tr->bodies[0], *r0 = &toss->samples[0];
    assert_true(pd_v3_norm(pd_v3_sub(s0->x, r0->x)) < 1e-12);
    assert_true(pd_v3_norm(pd_v3_sub(s0->v, r0->v)) < 1e-12);
    assert_true(pd_v3_norm(pd_v3_sub(s0->w, r0->w)) < 1e-12);
    double dq = fabs(s0->q.w - r0->q.w) + fabs(s0->q.x - r0->q.x) + fabs(s0->q.y - r0->q.y) + fabs(s0->q.z - r0->q.z);
    assert_true(dq < 1e-12);
    // free flight with isotropic inertia 8.1e-4 is the parabola and the steady spin: errors at the
    // integrator's level (tol 1e-10), not the contact model's
    printf("free flight toss %ld: pos err end %.3g widths, rot err end %.3g rad\n", toss->id, r.posErrEnd, r.rotErrEnd);
    assert_true(r.posErrEnd < 1e-8 && r.posErrRms < 1e-8);
    assert_true(r.rotErrEnd < 1e-8 && r.rotErrRms < 1e-8);
    pd_trajectory_free(tr);
  }
  pd_toss_set_free(set);
}

static void test_toss_model_has_the_cubes_mass_inertia_and_the_board_top(void** state) {
  (void)state;
  pdTossSet* set = flight_set(1, 10);
  pdTossParams p = pd_toss_default_params();
  pdError err = {0};
  pdModel* m = pd_toss_model(&set->tosses[0], &p, &err);
  assert_non_null(m);
  const pdBody *cube = &m->bodies[PD_TOSS_CUBE_BODY], *board = &m->bodies[PD_TOSS_BOARD_BODY];
  assert_true(fabs(cube->mass - PD_TOSS_CUBE_MASS) < 1e-12 * PD_TOSS_CUBE_MASS);
  for (int i = 0; i < 3; ++i) {
    assert_true(cube->principal[i] == PD_TOSS_CUBE_INERTIA);
    assert_true(fabs(cube->invInertia.m[i][i] * PD_TOSS_CUBE_INERTIA - 1.0) < 1e-15);
  }
  assert_true(fabs(board->x0.z + 0.5 * PD_TOSS_BOARD_THICKNESS - PD_TOSS_BOARD_TOP) < 1e-15);
  assert_true(board->fixed && !cube->fixed);
  assert_true(m->settings.sampleRate == PD_TOSS_RATE);
  assert_true(m->settings.tend == 9.0 / PD_TOSS_RATE);
  // the pair: μ and e as asked, series stiffness kn/2; nothing adjusted by the §3.3 checks
  pdPairContact pair = pd_model_pair_contact(m, PD_TOSS_CUBE_BODY, PD_TOSS_BOARD_BODY);
  assert_true(fabs(pair.mu - p.mu) < 1e-15);
  assert_true(fabs(pair.restitution - p.restitution) < 1e-15);
  assert_true(fabs(pair.kn - 0.5 * p.kn) < 1e-9 * p.kn);
  assert_int_equal(pd_model_adjustment_count(m), 0);
  pd_model_free(m);
  // uniform: the compiled cube's own inertia, m s²/6
  p.inertia = 0.0;
  m = pd_toss_model(&set->tosses[0], &p, &err);
  assert_non_null(m);
  double uniform = PD_TOSS_CUBE_MASS * PD_TOSS_CUBE_SIDE * PD_TOSS_CUBE_SIDE / 6.0;
  assert_true(fabs(m->bodies[PD_TOSS_CUBE_BODY].principal[0] - uniform) < 1e-12 * uniform);
  pd_model_free(m);
  pd_toss_set_free(set);
}

// Reads the first data row of DIR/trajectory.csv into v[0..15) (t, then 13 numbers after the body name).
static int read_rows(const char* dir, double rows[][14], int maxRows) {
  char path[600];
  snprintf(path, sizeof path, "%s/trajectory.csv", dir);
  FILE* f = fopen(path, "r");
  assert_non_null(f);
  char line[2048];
  assert_non_null(fgets(line, sizeof line, f));
  assert_string_equal(line, "t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n");
  int n = 0;
  while (n < maxRows && fgets(line, sizeof line, f)) {
    char* p = line;
    rows[n][0] = strtod(p, &p);
    assert_true(strncmp(p, ",cube,", 6) == 0);
    p += 5;
    for (int c = 1; c < 14; ++c) {
      assert_true(*p == ',');
      rows[n][c] = strtod(p + 1, &p);
    }
    ++n;
  }
  fclose(f);
  return n;
}

static void test_record_run_directory_round_trips_the_data(void** state) {
  (void)state;
  pdTossSet* set = flight_set(2, 12);
  const pdToss* toss = &set->tosses[1];
  pdTossParams p = pd_toss_default_params();
  pdError err = {0};
  char* dir = scratch_path("record");
  assert_true(pd_toss_write_record(toss, &p, dir, set->path, &err));
  double rows[20][14];
  assert_int_equal(read_rows(dir, rows, 20), toss->sampleCount);
  for (int k = 0; k < toss->sampleCount; ++k) {
    const pdBodyState* b = &toss->samples[k];
    const double want[14] = {k / PD_TOSS_RATE, b->x.x, b->x.y, b->x.z, b->q.w, b->q.x, b->q.y,
                             b->q.z, b->v.x, b->v.y, b->v.z, b->w.x, b->w.y, b->w.z};
    for (int c = 0; c < 14; ++c) assert_true(rows[k][c] == want[c]);  // %.17g: exact
  }
  // summary.json names the engine "record"
  char path[600];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  FILE* f = fopen(path, "r");
  assert_non_null(f);
  char text[8192];
  size_t n = fread(text, 1, sizeof text - 1, f);
  text[n] = '\0';
  fclose(f);
  assert_non_null(strstr(text, "\"engine\": \"record\""));
  pd_toss_set_free(set);
}

static void test_judge_measures_a_known_offset_and_turn(void** state) {
  (void)state;
  pdTossSet* set = flight_set(1, 10);
  const pdToss* toss = &set->tosses[0];
  pdTossParams p = pd_toss_default_params();
  pdError err = {0};
  pdModel* m = pd_toss_model(toss, &p, &err);
  assert_non_null(m);
  pdTrajectory* tr = pd_trajectory_create(m);
  pdState* st = pd_state_create(m, NULL);
  pdQuat quarter = pd_quat_from_axis_angle(pd_v3(0, 0, 1), 0.5 * kPi);
  for (int k = 0; k < toss->sampleCount; ++k) {
    // the record moved by one cube width along x, and turned by a quarter turn about z from sample 5 on
    pdBodyState b = toss->samples[k];
    b.x.x += PD_TOSS_CUBE_SIDE;
    if (k >= 5) b.q = pd_quat_mul(b.q, quarter);
    const double y[13] = {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z, b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z};
    memcpy(st->y, y, sizeof y);
    st->t = k / PD_TOSS_RATE;
    pd_trajectory_observe(m, st, tr);
  }
  pdTossResult r = {0};
  pd_toss_judge(toss, tr, &r);
  assert_int_equal(r.status, pd_tossOk);
  assert_true(fabs(r.posErrEnd - 1.0) < 1e-12 && fabs(r.posErrRms - 1.0) < 1e-12);
  assert_true(fabs(r.rotErrEnd - 0.5 * kPi) < 1e-12);
  assert_true(fabs(r.rotErrRms - 0.5 * kPi * sqrt(5.0 / 10.0)) < 1e-12);  // 5 of 10 samples turned
  // a run with fewer samples than the record is a failed run, with no error numbers
  tr->samples = 4;
  pd_toss_judge(toss, tr, &r);
  assert_int_equal(r.status, pd_tossFailed);
  assert_true(isnan(r.posErrEnd) && isnan(r.rotErrRms));
  pd_state_free(st);
  pd_trajectory_free(tr);
  pd_model_free(m);
  pd_toss_set_free(set);
}

// ---------------------------------------------------------------- bad data

static void expect_refused(const char* name, const char* text, int line, int col, const char* needle) {
  char* path = scratch_path(name);
  write_file(path, text);
  pdError err = {0};
  pdTossSet* set = pd_toss_read(path, &err);
  if (set) fail_msg("%s: accepted", name);
  if (err.line != line || err.col != col || !strstr(err.message, needle))
    fail_msg("%s: got %d:%d: %s; expected %d:%d: ...%s...", name, err.line, err.col, err.message, line, col, needle);
  // the same bytes from memory: the same answer
  pdError fromBuffer = {0};
  assert_null(pd_toss_parse_buffer(path, text, strlen(text), &fromBuffer));
  assert_string_equal(fromBuffer.file, err.file);
  assert_int_equal(fromBuffer.line, err.line);
  assert_int_equal(fromBuffer.col, err.col);
  assert_string_equal(fromBuffer.message, err.message);
}

#define HEADER "toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n"
#define ROW0 "1,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n"
#define ROW1 "1,0.006757,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n"

static void test_bad_csv_is_refused_at_its_line_and_column(void** state) {
  (void)state;
  expect_refused("header.csv", "toss,t,x\n" ROW0, 1, 1, "header");
  expect_refused("nan.csv", HEADER ROW0 "1,0.006757,0,0,nan,1,0,0,0,0,0,0,0,0,0\n", 3, 16, "finite");
  expect_refused("word.csv", HEADER ROW0 "1,0.006757,0,zero,0.3,1,0,0,0,0,0,0,0,0,0\n", 3, 14, "number");
  expect_refused("fields.csv", HEADER ROW0 "1,0.006757,0,0,0.3,1,0,0,0,0,0,0,0,0\n", 3, 1, "14 fields");
  expect_refused("time.csv", HEADER ROW0 "1,0.007000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n", 3, 3, "expected 0.00675");
  expect_refused("quat.csv", HEADER ROW0 "1,0.006757,0,0,0.3,1,0.1,0,0,0,0,0,0,0,0\n", 3, 20, "norm");
  expect_refused("again.csv", HEADER ROW0 ROW1 "2,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n" "2,0.006757,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n" ROW0,
                 6, 1, "consecutive");
  expect_refused("single.csv", HEADER ROW0 ROW1 "2,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n", 4, 1, "one row");
  expect_refused("id.csv", HEADER "x1,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n", 2, 1, "integer");
  expect_refused("empty.csv", "", 0, 0, "empty");
  expect_refused("none.csv", HEADER, 2, 1, "no tosses");
  pdError err = {0};
  assert_null(pd_toss_read(scratch_path("does-not-exist.csv"), &err));
  assert_non_null(strstr(err.message, "cannot read"));
  // CRLF line ends and a trailing blank line are fine
  write_file(scratch_path("crlf.csv"), "toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\r\n1,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\r\n"
                                       "1,0.006757,0,0,0.3,1,0,0,0,0,0,0,0,0,0\r\n\r\n");
  pdTossSet* set = pd_toss_read(scratch_path("crlf.csv"), &err);
  assert_non_null(set);
  assert_int_equal(set->count, 1);
  assert_int_equal(set->tosses[0].sampleCount, 2);
  pd_toss_set_free(set);
  // from memory, without a final newline and not NUL-terminated: the same set
  const char text[] = HEADER ROW0 "1,0.006757,0,0,0.3,1,0,0,0,0,0,0,0,0,0";
  set = pd_toss_parse_buffer(NULL, text, sizeof text - 1, &err);
  assert_non_null(set);
  assert_string_equal(set->path, "<buffer>");
  assert_int_equal(set->count, 1);
  assert_int_equal(set->tosses[0].sampleCount, 2);
  assert_int_equal(set->tosses[0].line, 2);
  pd_toss_set_free(set);
  const char cut[] = HEADER ROW0 ROW1;  // a buffer ending inside the header is refused by the header
  assert_null(pd_toss_parse_buffer("cut.csv", cut, 20, &err));
  assert_true(err.line == 1 && err.col == 1);
}

// ---------------------------------------------------------------- statistics, lists, fragments

static void test_statistics_of_known_numbers(void** state) {
  (void)state;
  // 1..10: mean 5.5, median 5.5, 90th percentile 9.1 (type 7, numpy: percentile(range(1, 11), 90) = 9.1)
  double v[12] = {10, 3, 1, 4, 5, 9, 2, 6, 8, 7, NAN, NAN};
  pdTossStats s = pd_toss_stats(v, 12);
  assert_int_equal(s.n, 10);
  assert_true(fabs(s.mean - 5.5) < 1e-15 && fabs(s.median - 5.5) < 1e-15 && fabs(s.p90 - 9.1) < 1e-14);
  // odd count: the middle value; p90 of 5 values: h = 3.6 between the 4th and 5th
  double w[5] = {0.5, 0.1, 0.3, 0.2, 0.4};
  s = pd_toss_stats(w, 5);
  assert_true(s.median == 0.3 && fabs(s.p90 - 0.46) < 1e-15 && fabs(s.mean - 0.3) < 1e-15);
  s = pd_toss_stats(w, 1);
  assert_true(s.n == 1 && s.mean == 0.5 && s.median == 0.5 && s.p90 == 0.5);
  s = pd_toss_stats(v + 10, 2);
  assert_true(s.n == 0 && isnan(s.mean) && isnan(s.median) && isnan(s.p90));
}

static void test_toss_lists_select_in_file_order(void** state) {
  (void)state;
  pdTossSet* set = flight_set(6, 3);  // ids 3, 4, 9, 12, 13, 20
  int* idx = NULL;
  int n = 0;
  char why[256];
  assert_true(pd_toss_select(set, "train", &idx, &n, why, sizeof why));
  assert_int_equal(n, 3);
  assert_true(idx[0] == 0 && idx[1] == 2 && idx[2] == 4);  // even positions
  free(idx);
  assert_true(pd_toss_select(set, "test", &idx, &n, why, sizeof why));
  assert_true(n == 3 && idx[0] == 1 && idx[2] == 5);
  free(idx);
  assert_true(pd_toss_select(set, "20,4-10,3,4", &idx, &n, why, sizeof why));
  assert_true(n == 4 && idx[0] == 0 && idx[1] == 1 && idx[2] == 2 && idx[3] == 5);
  free(idx);
  assert_false(pd_toss_select(set, "5", &idx, &n, why, sizeof why));
  assert_non_null(strstr(why, "toss 5 is not in"));
  assert_false(pd_toss_select(set, "5-8", &idx, &n, why, sizeof why));
  assert_false(pd_toss_select(set, "9-3", &idx, &n, why, sizeof why));
  assert_false(pd_toss_select(set, "3,,4", &idx, &n, why, sizeof why));
  assert_false(pd_toss_select(set, "three", &idx, &n, why, sizeof why));
  assert_false(pd_toss_select(set, "", &idx, &n, why, sizeof why));
  assert_null(idx);
  pd_toss_set_free(set);
}

static void test_parameter_fragment_round_trips_and_refuses_other_lines(void** state) {
  (void)state;
  pdTossParams p = pd_toss_default_params();
  p.mu = 0.2137;
  p.restitution = 0.4;
  p.kn = 3.3e6;
  char* path = scratch_path("fitted.scene");
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  pd_toss_params_write(f, &p, "a comment\nof two lines");
  assert_int_equal(fclose(f), 0);
  pdTossParams q = pd_toss_default_params();
  pdError err = {0};
  if (!pd_toss_params_read(path, &q, &err)) fail_msg("%d:%d: %s", err.line, err.col, err.message);
  assert_true(q.mu == p.mu && q.restitution == p.restitution && q.kn == p.kn);
  // only what the fragment sets changes
  write_file(path, "# only friction\n  mu 0.3\n");
  q = pd_toss_default_params();
  assert_true(pd_toss_params_read(path, &q, &err));
  assert_true(q.mu == 0.3 && q.restitution == PD_TOSS_DEFAULT_RESTITUTION && q.kn == pd_toss_default_params().kn);
  // refused, each at its line and column
  struct {
    const char* text;
    int line, col;
    const char* needle;
  } bad[] = {
      {"mu 0.3\n  kt 5\n", 2, 3, "only mu, restitution and kn"},
      {"mu 0.3\ntend 2\n", 2, 1, "only mu"},
      {"mu 0.3\nrestitution 0.005\n", 2, 1, "below 0.01"},
      {"mu 0.3\nkn 0\n", 2, 4, "kn must be > 0"},  // the scene parser's own range check
      {"mu\n", 1, 1, ""},
      {"\nmu zero\n", 2, 4, ""},
      {"# nothing\n", 0, 0, "sets none"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    write_file(path, bad[i].text);
    memset(&err, 0, sizeof err);
    assert_false(pd_toss_params_read(path, &q, &err));
    if (err.line != bad[i].line || err.col != bad[i].col || !strstr(err.message, bad[i].needle))
      fail_msg("fragment %zu: got %d:%d: %s", i, err.line, err.col, err.message);
    assert_string_equal(err.file, path);
  }
}

// ---------------------------------------------------------------- worker processes

typedef struct jobInput {
  const pdTossSet* set;
  pdTossParams params;
} jobInput;

static void flight_job(int i, void* result, void* user) {
  const jobInput* in = user;
  pdTrajectory* tr = pd_toss_simulate(&in->set->tosses[i], &in->params, &softEngine, NULL, result);
  pd_trajectory_free(tr);
}

static bool count_progress(int done, int total, void* user) {
  int* calls = user;
  ++*calls;
  assert_true(done >= 0 && done <= total);
  return true;
}

static bool stop_at_once(int done, int total, void* user) {
  (void)done, (void)total, (void)user;
  return false;
}

static void test_two_workers_give_the_results_of_one(void** state) {
  (void)state;
  pdTossSet* set = flight_set(5, 30);
  jobInput in = {set, pd_toss_default_params()};
  pdTossResult one[5], two[5];
  char why[256];
  int calls = 0;
  assert_true(pd_toss_parallel(5, 1, sizeof(pdTossResult), one, flight_job, &in, count_progress, &calls, why, sizeof why));
  assert_true(calls >= 2);
  assert_true(pd_toss_parallel(5, 2, sizeof(pdTossResult), two, flight_job, &in, NULL, NULL, why, sizeof why));
  for (int i = 0; i < 5; ++i) {
    assert_int_equal(one[i].status, pd_tossOk);
    assert_int_equal(two[i].status, pd_tossOk);
    // bit-identical errors and steps, whichever process ran the toss
    assert_memory_equal(&one[i].posErrEnd, &two[i].posErrEnd, sizeof(double));
    assert_memory_equal(&one[i].rotErrRms, &two[i].rotErrRms, sizeof(double));
    assert_int_equal(one[i].steps, two[i].steps);
  }
  // a progress callback that says stop stops the work, with a message
  assert_false(pd_toss_parallel(5, 2, sizeof(pdTossResult), two, flight_job, &in, stop_at_once, NULL, why, sizeof why));
  assert_non_null(strstr(why, "stopped"));
  pd_toss_set_free(set);
}

static void test_missing_adapter_is_reported_not_built(void** state) {
  (void)state;
  pdTossSet* set = flight_set(1, 5);
  pdTossParams p = pd_toss_default_params();
  const char* const names[] = {"ode", "bullet"};
  for (int i = 0; i < 2; ++i) {
    pdTossEngine e = {
        .name = names[i],
        .ref = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid}};
    pdTossResult r;
    pdTrajectory* tr = pd_toss_simulate(&set->tosses[0], &p, &e, NULL, &r);
    if (pd_ref_adapter(names[i])) {
      // an adapter in this build: the toss in free flight runs to its end
      assert_int_equal(r.status, pd_tossOk);
      assert_non_null(tr);
    } else {
      assert_int_equal(r.status, pd_tossNotBuilt);
      assert_null(tr);
      assert_non_null(strstr(r.message, names[i]));
    }
    pd_trajectory_free(tr);
  }
  pd_toss_set_free(set);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_free_flight_toss_matches_its_closed_form_record),
      cmocka_unit_test(test_toss_model_has_the_cubes_mass_inertia_and_the_board_top),
      cmocka_unit_test(test_record_run_directory_round_trips_the_data),
      cmocka_unit_test(test_judge_measures_a_known_offset_and_turn),
      cmocka_unit_test(test_bad_csv_is_refused_at_its_line_and_column),
      cmocka_unit_test(test_statistics_of_known_numbers),
      cmocka_unit_test(test_toss_lists_select_in_file_order),
      cmocka_unit_test(test_parameter_fragment_round_trips_and_refuses_other_lines),
      cmocka_unit_test(test_two_workers_give_the_results_of_one),
      cmocka_unit_test(test_missing_adapter_is_reported_not_built),
  };
  return cmocka_run_group_tests(tests, make_scratch, remove_scratch);
}
