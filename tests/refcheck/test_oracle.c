// The libccd oracle (refcheck/oracle*.c): known pairs (unit cubes apart and overlapping, vertex on face,
// crossed edges, exact touching) where our SAT, GJK, EPA and MPR must all give the closed form; 2000
// fixed-seed random pairs near touching with no verdict disagreement outside the touching band and EPA
// depths equal to ours; shape specs rebuilding the model's polyhedra bit for bit; the seeded generator;
// the CSV round trip.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "polydyn/model.h"
#include "pdref/oracle.h"
#include "polydyn/vecmath.h"

#define PI 3.14159265358979323846

// Closed cases: unit cubes with coordinates of order 1; both methods work in doubles (libccd in
// coordinates divided by the pair's scale), a few roundings of 1e-16 each.
#define CLOSED_TOL 1e-12
// Random pairs: EPA's depth (at PD_ORACLE_EPA_TOL) against ours, relative to the smaller body's size.
// Measured max 1.4e-14 on 3000 pairs (docs/validation.md); 1e-12 leaves a factor 70.
#define RANDOM_DEPTH_TOL_REL 1e-12

static pdOracleShape shape(const char* spec) {
  pdOracleShape s;
  char why[256] = "";
  if (!pd_oracle_shape_parse(spec, &s, why, sizeof why)) fail_msg("shape '%s': %s", spec, why);
  return s;
}

static pdQuat axis_angle(double x, double y, double z, double angle) {
  return pd_quat_from_axis_angle(pd_v3(x, y, z), angle);
}

// All four methods on one pair: the verdict, and the depth when it overlaps.
static pdOracleResult expect(const pdOracleShape* a, pdVec3 xa, pdQuat qa, const pdOracleShape* b, pdVec3 xb, pdQuat qb,
                             bool overlap, double depth, const char* label) {
  pdOracleBody A = {&a->poly, xa, qa}, B = {&b->poly, xb, qb};
  pdOracleResult r;
  pd_oracle_check(&A, &B, &r);
  if (r.ours != overlap || r.gjk != overlap || r.mpr != overlap)
    fail_msg("%s: verdicts ours %d, GJK %d, MPR %d; expected %d", label, r.ours, r.gjk, r.mpr, overlap);
  assert_int_equal(r.kind, overlap ? pd_oracleAgreeOverlap : pd_oracleAgreeSeparate);
  assert_false(r.stalled);
  if (overlap) {
    assert_true(r.hasEpa && r.hasMprDepth);
    if (fabs(r.ourDepth - depth) > CLOSED_TOL || fabs(r.epaDepth - depth) > CLOSED_TOL ||
        fabs(r.mprDepth - depth) > CLOSED_TOL)
      fail_msg("%s: depth ours %.17g, EPA %.17g, MPR %.17g; expected %.17g", label, r.ourDepth, r.epaDepth, r.mprDepth,
               depth);
  } else {
    // our SAT's gap along the best face of the Minkowski difference: here the true gap
    if (fabs(r.ourDepth + depth) > CLOSED_TOL) fail_msg("%s: our depth %.17g, expected %.17g", label, r.ourDepth, -depth);
    assert_false(r.hasEpa);
  }
  return r;
}

static void test_unit_cubes_apart_and_overlapping_give_the_closed_form_depth(void** state) {
  (void)state;
  pdOracleShape cube = shape("cube 1 1 1");
  pdQuat I = pd_quat_identity();
  static const double depths[] = {0.3, 1e-2, 1e-4, 1e-6};
  char label[64];
  for (int i = 0; i < 4; ++i) {
    double d = depths[i];
    // face to face along x, B shifted sideways so that no edge coincides
    snprintf(label, sizeof label, "faces, overlap %g", d);
    expect(&cube, pd_v3(0, 0, 0), I, &cube, pd_v3(1.0 - d, 0.2, -0.1), I, true, d, label);
    snprintf(label, sizeof label, "faces, gap %g", d);
    expect(&cube, pd_v3(0, 0, 0), I, &cube, pd_v3(1.0 + d, 0.2, -0.1), I, false, d, label);
    // the same pair far from the origin and turned as a whole: libccd works about the pair's midpoint
    pdQuat G = axis_angle(1, 2, 3, 0.7);
    pdVec3 shift = pd_v3(100, -50, 20);
    snprintf(label, sizeof label, "faces, turned and moved, overlap %g", d);
    expect(&cube, shift, G, &cube, pd_v3_add(shift, pd_quat_rotate(G, pd_v3(1.0 - d, 0.2, -0.1))), G, true, d, label);
  }
  pd_oracle_shape_free(&cube);
}

static void test_vertex_on_face_and_crossed_edges_give_the_closed_form_depth(void** state) {
  (void)state;
  pdOracleShape cube = shape("cube 1 1 1");
  pdQuat I = pd_quat_identity();
  // vertex on face: B's corner (½, ½, ½) turned to point straight down, pressed d into A's top face
  pdQuat down = axis_angle(-1, 1, 0, acos(-1.0 / sqrt(3.0)));
  assert_true(pd_v3_norm(pd_v3_sub(pd_quat_rotate(down, pd_v3(0.5, 0.5, 0.5)), pd_v3(0, 0, -sqrt(3.0) / 2))) < 1e-15);
  // crossed edges: A turned 45° about x (top edge along x at z = √2/2), B 45° about y (bottom edge
  // along y at z = −√2/2), B above A: the edges cross at depth d along z
  pdQuat ax = axis_angle(1, 0, 0, PI / 4), ay = axis_angle(0, 1, 0, PI / 4);
  char label[64];
  for (int s = -1; s <= 1; s += 2) {
    for (double d = 1e-2; d > 1e-6; d /= 100) {
      snprintf(label, sizeof label, "vertex on face, %s %g", s > 0 ? "overlap" : "gap", d);
      expect(&cube, pd_v3(0, 0, 0), I, &cube, pd_v3(0.1, 0.05, 0.5 + sqrt(3.0) / 2 - s * d), down, s > 0, d, label);
      snprintf(label, sizeof label, "crossed edges, %s %g", s > 0 ? "overlap" : "gap", d);
      expect(&cube, pd_v3(0, 0, 0), ax, &cube, pd_v3(0, 0, sqrt(2.0) - s * d), ay, s > 0, d, label);
    }
  }
  pd_oracle_shape_free(&cube);
}

static void test_exact_touching_is_never_a_failure_and_gives_no_nan(void** state) {
  (void)state;
  pdOracleShape cube = shape("cube 1 1 1");
  pdQuat I = pd_quat_identity();
  // libccd's worst cases (reference-engines.md §3.2): stacked exactly, and faces exactly touching
  static const pdVec3 poses[] = {{1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {1e-9, 0.0, 1.0}, {1.0, 0.2, -0.1}};
  for (int i = 0; i < 4; ++i) {
    pdOracleBody A = {&cube.poly, pd_v3(0, 0, 0), I}, B = {&cube.poly, poses[i], I};
    pdOracleResult r;
    pd_oracle_check(&A, &B, &r);
    print_message("touching %d: ours %d (%g), GJK %d, MPR %d, EPA %s %g -> %s\n", i, r.ours, r.ourDepth, r.gjk, r.mpr,
                  r.hasEpa ? "depth" : "none", r.epaDepth, pdOracleKindNames[r.kind]);
    assert_true(r.ours);  // closed bodies: touching interferes
    assert_true(r.touching);
    assert_true(r.kind == pd_oracleAgreeOverlap || r.kind == pd_oracleTouching);
    assert_true(isfinite(r.ourDepth) && isfinite(r.epaDepth) && isfinite(r.mprDepth));
  }
  pd_oracle_shape_free(&cube);
}

// cases/hard/mass_ratio.scene: the 0.5 × 0.5 × 0.2 m block resting on the fixed 1.5 × 1.5 × 0.1 m floor,
// face on face, at a pose of the soft run (tilted by ~1e-7). MPR goes straight down the centre line onto
// the floor's top face: its depth is exact there, and ours must equal it.
static pdOracleResult block_on_floor(pdVec3 x, pdQuat q) {
  pdOracleShape floor = shape("cube 1.5 1.5 0.10000000000000001");
  pdOracleShape block = shape("cube 0.5 0.5 0.20000000000000001");
  pdOracleBody A = {&floor.poly, {0, 0, -0.050000000000000003}, {1, 0, 0, 0}}, B = {&block.poly, x, q};
  pdOracleResult r;
  pd_oracle_check(&A, &B, &r);
  print_message("ours %.17g, MPR %.17g, EPA %.17g (tol %g, bound %.3g m) -> %s\n", r.ourDepth, r.mprDepth, r.epaDepth,
                r.epaTol, r.epaBound, pdOracleKindNames[r.kind]);
  assert_true(r.ours && r.gjk && r.mpr && r.hasMprDepth && !r.stalled);
  assert_true(fabs(r.mprDepth - r.ourDepth) <= CLOSED_TOL);
  assert_true(r.ourDepth > 1e-4 && r.ourDepth < 2e-4);
  pd_oracle_shape_free(&floor);
  pd_oracle_shape_free(&block);
  return r;
}

static void test_a_block_resting_on_a_slab_gets_an_epa_depth_within_its_bound(void** state) {
  (void)state;
  // t = 0.14 s: libccd's EPA cycles on this pair at the tightest tolerance, the oracle retries looser
  pdOracleResult r = block_on_floor((pdVec3){2.2999227383557647e-08, -1.9755720129624577e-08, 0.099866104313912657},
                                    (pdQuat){0.99999999999999389, 2.5295599845141236e-08, 1.0609642471246841e-07,
                                             -1.3037715786162735e-08});
  assert_int_equal(r.kind, pd_oracleAgreeOverlap);
  assert_true(r.hasEpa && fabs(r.epaDepth - r.ourDepth) <= r.epaBound);
}

static void test_resting_block_depth_equals_mprs_when_epa_takes_its_touching_shortcut(void** state) {
  (void)state;
  // t = 0.152 s, 1.34e-4 m deep: libccd's GJK ends with the origin within DBL_EPSILON (squared) of a
  // simplex face, and EPA then reports that face's distance, ~4e-9 m
  pdOracleResult r = block_on_floor((pdVec3){-7.1233592156859987e-09, 2.6378821116571543e-08, 0.09986604738503238},
                                    (pdQuat){0.99999999999999867, -5.070507188534073e-08, 1.5371519245006506e-08,
                                             4.7885366486010021e-09});
  // EPA either agrees within its bound, or the pair is listed as a depth outlier (never a verdict failure)
  assert_true(fabs(r.epaDepth - r.ourDepth) <= r.epaBound ? r.kind == pd_oracleAgreeOverlap : r.kind == pd_oracleDepth);
}

static void test_2000_random_pairs_near_touching_agree_outside_the_band(void** state) {
  (void)state;
  enum { PAIRS = 2000 };
  pdOracleRng g;
  pd_oracle_rng_seed(&g, 20260101);
  pdOracleStats s;
  pd_oracle_stats_init(&s);
  double maxDepthErr = 0.0;
  for (int i = 0; i < PAIRS; ++i) {
    pdOraclePair p;
    pd_oracle_random_pair(&g, &p);
    pdOracleResult r;
    pd_oracle_check(&p.bodyA, &p.bodyB, &r);
    pd_oracle_stats_add(&s, &r);
    if (r.kind == pd_oracleWeOverlap || r.kind == pd_oracleWeSeparate || r.kind == pd_oracleStalled ||
        r.kind == pd_oracleDepth)
      fail_msg("pair %d (%s | %s): %s, ours %.17g, EPA %.17g, scale %g", i, p.a.spec, p.b.spec, pdOracleKindNames[r.kind],
               r.ourDepth, r.epaDepth, r.scale);
    if (r.ours && r.gjk && !r.touching && r.epaTol == PD_ORACLE_EPA_TOL) {
      double e = fabs(r.epaDepth - r.ourDepth) / r.size;
      maxDepthErr = fmax(maxDepthErr, e);
      if (e > RANDOM_DEPTH_TOL_REL)
        fail_msg("pair %d (%s | %s): depth ours %.17g, EPA %.17g (size %g)", i, p.a.spec, p.b.spec, r.ourDepth,
                 r.epaDepth, r.size);
    }
    // a mismatch inside the band is one of libccd's touching calls, within √DBL_EPSILON ≈ 1.5e-8 of the
    // scale (measured at most 1.9e-8 on 100 000 pairs): below 3e-8
    if (r.kind == pd_oracleTouching) assert_true(fabs(r.ourDepth) < 3e-8 * r.scale || r.epaDepth < 3e-8 * r.scale);
    pd_oracle_pair_free(&p);
  }
  long both = s.kinds[pd_oracleAgreeOverlap] + s.kinds[pd_oracleDepth], apart = s.kinds[pd_oracleAgreeSeparate];
  print_message("%d pairs: both overlap %ld, both separate %ld, in the band %ld (mismatched %ld); max |EPA - ours| / "
                "size %.3g outside the band\n",
                PAIRS, both, apart, s.inBand, s.kinds[pd_oracleTouching], maxDepthErr);
  assert_int_equal(pd_oracle_stats_failures(&s), 0);
  // the pairs really are near touching, and on both sides of it
  assert_true(both > PAIRS / 4 && apart > PAIRS / 4 && s.inBand < PAIRS / 3);
  pd_oracle_stats_free(&s);
}

static void test_seeded_generator_repeats_and_seeds_differ(void** state) {
  (void)state;
  pdOracleRng g1, g2, g3;
  pd_oracle_rng_seed(&g1, 42);
  pd_oracle_rng_seed(&g2, 42);
  pd_oracle_rng_seed(&g3, 43);
  int differ = 0;
  for (int i = 0; i < 20; ++i) {
    pdOraclePair p1, p2, p3;
    pd_oracle_random_pair(&g1, &p1);
    pd_oracle_random_pair(&g2, &p2);
    pd_oracle_random_pair(&g3, &p3);
    assert_string_equal(p1.a.spec, p2.a.spec);
    assert_string_equal(p1.b.spec, p2.b.spec);
    assert_memory_equal(&p1.bodyB.x, &p2.bodyB.x, sizeof p1.bodyB.x);
    assert_memory_equal(&p1.bodyB.q, &p2.bodyB.q, sizeof p1.bodyB.q);
    differ += strcmp(p1.a.spec, p3.a.spec) != 0;
    pd_oracle_pair_free(&p1);
    pd_oracle_pair_free(&p2);
    pd_oracle_pair_free(&p3);
  }
  assert_true(differ >= 15);
  // xoshiro256** is uniform: the mean of 1e5 draws is ½ to 5 standard errors (0.0009)
  double sum = 0.0;
  for (int i = 0; i < 100000; ++i) sum += pd_oracle_rng_uniform(&g1);
  assert_true(fabs(sum / 100000 - 0.5) < 0.005);
}

static const char* const specScene =
    "cube c red 0.2 0.3 0.4\n"
    "prism p red 7 0.3 0.3 0.5\n"
    "tprism t red 8 0.3 0.2 0.3 0.4\n"
    "sphere s red 2 0.3 0.25 0.2\n"
    "hull h red 0 0 0  1 0 0  0 1 0  0 0 1  0.3 0.3 0.3\n";

static void test_specs_rebuild_the_models_polyhedra_bit_for_bit(void** state) {
  (void)state;
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer("specs", specScene, strlen(specScene), &err);
  assert_non_null(scene);
  // bodies far apart, so that the model compiles
  for (int i = 0; i < scene->objectCount; ++i) scene->objects[i].loc[0] = 5.0 * i;
  pdModel* model = pd_model_compile(scene, &err);
  if (!model) fail_msg("%s", err.message);
  for (int i = 0; i < model->bodyCount; ++i) {
    char* spec = pd_oracle_object_spec(&scene->objects[i]);
    pdOracleShape s = shape(spec);
    const pdPolyhedron *p = &s.poly, *q = &model->bodies[i].shape;
    print_message("%s\n", spec);
    assert_int_equal(p->vertexCount, q->vertexCount);
    assert_int_equal(p->faceCount, q->faceCount);
    assert_memory_equal(p->vertices, q->vertices, (size_t)p->vertexCount * sizeof *p->vertices);
    pd_oracle_shape_free(&s);
    free(spec);
  }
  pd_model_free(model);
  pd_scene_free(scene);
}

static void test_bad_specs_are_refused_with_a_reason(void** state) {
  (void)state;
  static const char* const bad[] = {
      "cube 1 1",                                  // arity
      "ball 1 1 1",                                // unknown
      "cube 1 1 -1",                               // out of range
      "cube 1 1 1 # comment",                      // not one plain line
      "tend 5",                                    // a setting, not a shape
      "hull 0 0 0  1 0 0  0 1 0  1 1 0",           // coplanar: degenerate
      "sphere 4 1 1 1",                            // level out of range
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
    pdOracleShape s;
    char why[256] = "";
    assert_false(pd_oracle_shape_parse(bad[i], &s, why, sizeof why));
    print_message("'%s': %s\n", bad[i], why);
    assert_true(strlen(why) > 0);
  }
}

static void test_csv_rows_read_back_exactly_with_quoted_names(void** state) {
  (void)state;
  pdOracleRow row = {.source = "scenes/a,b.scene",
                     .index = 17,
                     .t = 0.1 + 0.2,
                     .nameA = "box \"one\"",
                     .nameB = "floor",
                     .specA = "cube 0.1 0.2 0.3",
                     .specB = "hull 0 0 0 1 0 0 0 1 0 0 0 1",
                     .xa = {1.0 / 3.0, -2e-300, 7},
                     .xb = {PI, 0, -0.0},
                     .qa = pd_quat_normalize((pdQuat){1, 2, 3, 4}),
                     .qb = pd_quat_identity()};
  row.r = (pdOracleResult){.scale = 1.5, .size = 0.2, .ours = true, .ourDepth = 1e-9, .gjk = false, .mpr = true,
                           .hasEpa = false, .hasMprDepth = true, .mprDepth = 2e-9, .kind = pd_oracleTouching};
  char* text = NULL;
  size_t size = 0;
  FILE* f = open_memstream(&text, &size);
  assert_non_null(f);
  pd_oracle_csv_write(f, &row);
  fclose(f);
  text[strcspn(text, "\n")] = '\0';
  print_message("%s\n", text);
  pdOracleRow back;
  int col = 0;
  char why[256];
  if (!pd_oracle_csv_read(text, &back, &col, why, sizeof why)) fail_msg("column %d: %s", col, why);
  assert_string_equal(back.source, row.source);
  assert_string_equal(back.nameA, row.nameA);
  assert_string_equal(back.specB, row.specB);
  assert_int_equal(back.index, 17);
  assert_memory_equal(&back.t, &row.t, sizeof row.t);
  assert_memory_equal(&back.xa, &row.xa, sizeof row.xa);
  assert_memory_equal(&back.qa, &row.qa, sizeof row.qa);
  assert_memory_equal(&back.xb, &row.xb, sizeof row.xb);
  assert_int_equal(back.r.kind, pd_oracleTouching);
  assert_true(back.r.ours && !back.r.gjk && back.r.mpr && !back.r.hasEpa && back.r.hasMprDepth);
  free(text);

  // a bad pose value is refused at its column
  char bad[] = "random,0,0,touching,A,B,cube 1 1 1,cube 1 1 1,0,0,0,1,0,0,0,x,0,0,1,0,0,0,"
               "overlap,0,overlap,overlap,0,0,1,1,1e-15";
  int xCol = (int)(strstr(bad, ",x,") - bad) + 2;  // before the read splits the line in place
  assert_false(pd_oracle_csv_read(bad, &back, &col, why, sizeof why));
  print_message("column %d: %s\n", col, why);
  assert_int_equal(col, xCol);
}

// pdOracleReplayFcn: counts the rows and keeps the last line
static bool count_row(const pdOracleRow* row, const pdOracleShape* a, const pdOracleShape* b, long line, void* user) {
  long* seen = user;
  assert_non_null(row->source);
  assert_true(a->poly.vertexCount >= 4 && b->poly.vertexCount >= 4);
  seen[0] += 1;
  seen[1] = line;
  return true;
}

static void test_a_replay_file_is_read_whole_and_refused_at_its_first_bad_line(void** state) {
  (void)state;
  char* text = NULL;
  size_t size = 0;
  FILE* f = open_memstream(&text, &size);
  assert_non_null(f);
  pd_oracle_csv_header(f);
  pdOracleRow row = {.source = "random", .nameA = "A", .nameB = "B", .specA = "cube 1 1 1", .specB = "prism 5 1 1 1",
                     .xb = {0.9, 0, 0}, .qa = pd_quat_identity(), .qb = pd_quat_identity()};
  pd_oracle_csv_write(f, &row);
  fputs("\r\n", f);  // a blank line (CRLF) is skipped
  pd_oracle_csv_write(f, &row);
  fclose(f);
  pdError err = {0};
  long seen[2] = {0, 0};
  if (!pd_oracle_replay_buffer("r.csv", text, size, count_row, seen, &err)) fail_msg("%s", err.message);
  assert_int_equal(seen[0], 2);
  assert_int_equal(seen[1], 4);
  assert_true(pd_oracle_replay_buffer(NULL, text, size, NULL, NULL, &err));  // checking only
  // a NUL byte: at its line and column; a bad shape: at its field; another header, or none: at 1:1
  size_t second = size - 1;  // where the last row starts
  while (second > 0 && text[second - 1] != '\n') --second;
  text[second + 3] = '\0';
  assert_false(pd_oracle_replay_buffer("r.csv", text, size, NULL, NULL, &err));
  assert_string_equal(err.file, "r.csv");
  assert_int_equal(err.line, 4);
  assert_int_equal(err.col, 4);
  text[second + 3] = 'd';
  char* shape = strstr(text + second, "prism 5");
  shape[6] = '2';  // a prism of 2 sides
  assert_false(pd_oracle_replay_buffer("r.csv", text, size, NULL, NULL, &err));
  print_message("%s:%d:%d: %s\n", err.file, err.line, err.col, err.message);
  assert_int_equal(err.line, 4);
  assert_int_equal(err.col, (int)(shape - (text + second)) + 1);
  assert_non_null(strstr(err.message, "shape_b"));
  text[0] = 'S';
  assert_false(pd_oracle_replay_buffer("r.csv", text, size, NULL, NULL, &err));
  assert_true(err.line == 1 && err.col == 1);
  assert_false(pd_oracle_replay_buffer("r.csv", "", 0, NULL, NULL, &err));
  assert_true(err.line == 1 && err.col == 1);
  free(text);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_unit_cubes_apart_and_overlapping_give_the_closed_form_depth),
      cmocka_unit_test(test_vertex_on_face_and_crossed_edges_give_the_closed_form_depth),
      cmocka_unit_test(test_exact_touching_is_never_a_failure_and_gives_no_nan),
      cmocka_unit_test(test_a_block_resting_on_a_slab_gets_an_epa_depth_within_its_bound),
      cmocka_unit_test(test_resting_block_depth_equals_mprs_when_epa_takes_its_touching_shortcut),
      cmocka_unit_test(test_2000_random_pairs_near_touching_agree_outside_the_band),
      cmocka_unit_test(test_seeded_generator_repeats_and_seeds_differ),
      cmocka_unit_test(test_specs_rebuild_the_models_polyhedra_bit_for_bit),
      cmocka_unit_test(test_bad_specs_are_refused_with_a_reason),
      cmocka_unit_test(test_csv_rows_read_back_exactly_with_quoted_names),
      cmocka_unit_test(test_a_replay_file_is_read_whole_and_refused_at_its_first_bad_line),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
