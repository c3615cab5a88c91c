// Contact analysis (engine/src/contact_analysis.c): VF and EE contacts, face continuity, tracking
// and geometric breaking, onset interpolation (paper §4.4, App. C).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "contact_analysis.h"
#include "onsets.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "scene_run.h"

// Geometry here is exact up to a few roundoffs of lengths of order 0.1 m.
#define GEOM_TOL 1e-12
// Penetration used in the scenes: a soft-contact-sized overlap (about 1e-3 of the body size).
#define DEPTH 1e-4
#define SIDE 0.1
#define PI 3.14159265358979323846

// The scenes name the bodies only; every test sets the poses itself (compile_apart places them 10 m apart so that
// the scene passes the overlap check of pd_model_compile).
static pdModel* compile(const char* shapes) { return compile_apart(shapes); }

static pdPose pose(double x, double y, double z, double angleDeg, pdVec3 axis) {
  pdQuat q = angleDeg != 0.0 ? pd_quat_from_axis_angle(axis, angleDeg * PI / 180.0) : pd_quat_identity();
  return (pdPose){{x, y, z}, pd_quat_to_mat3(q)};
}

static void expect_near(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol)) fail_msg("%s: got %.17g, expected %.17g (tol %g)", what, actual, expected, tol);
}

enum { CAPACITY = 64 };

// body 0: a fixed floor slab with its top face at z = 0; body 1: a cube of side 0.1
static const char* const cubeOnFloor =
    "cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\n"
    "cube box red 0.1 0.1 0.1\n";

static void test_cube_resting_on_floor_gives_four_vf_contacts_with_the_floor_normal(void** state) {
  (void)state;
  pdModel* m = compile(cubeOnFloor);
  pdPose floor = pose(0, 0, -0.05, 0, pd_v3(0, 0, 1));
  pdPose box = pose(0.2, -0.1, SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &floor, 1, &box, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 4);
  for (int i = 0; i < n; ++i) {
    assert_int_equal(c[i].id.kind, pd_contactVF);
    assert_int_equal(c[i].id.body1, 1);  // the cube's vertex
    assert_int_equal(c[i].id.body2, 0);  // in the floor's face
    expect_near(c[i].depth, DEPTH, GEOM_TOL, "depth");
    expect_near(c[i].normal.z, 1.0, GEOM_TOL, "normal z");
    expect_near(c[i].point.z, -DEPTH, GEOM_TOL, "point z");
    expect_near(fabs(c[i].point.x - 0.2), SIDE / 2, GEOM_TOL, "corner x");
    if (i > 0) assert_true(pd_contact_id_compare(&c[i - 1].id, &c[i].id) < 0);
  }
  // the same pair asked the other way round gives the same contacts
  pdContactGeom d[CAPACITY];
  assert_int_equal(pd_contacts_find(m, 1, &box, 0, &floor, NULL, NULL, NULL, 0, d, CAPACITY), 4);
  for (int i = 0; i < 4; ++i) assert_int_equal(pd_contact_id_compare(&c[i].id, &d[i].id), 0);
  pd_model_free(m);
}

static void test_separated_or_just_touching_bodies_have_no_contact(void** state) {
  (void)state;
  pdModel* m = compile(cubeOnFloor);
  pdPose floor = pose(0, 0, -0.05, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  pdPose above = pose(0, 0, SIDE / 2 + 1e-9, 0, pd_v3(0, 0, 1));
  assert_int_equal(pd_contacts_find(m, 0, &floor, 1, &above, NULL, NULL, NULL, 0, c, CAPACITY), 0);
  pdPose touching = pose(0, 0, SIDE / 2, 0, pd_v3(0, 0, 1));
  assert_int_equal(pd_contacts_find(m, 0, &floor, 1, &touching, NULL, NULL, NULL, 0, c, CAPACITY), 0);
  pd_model_free(m);
}

// Two equal cubes, b resting DEPTH deep on a's top face, turned by turnDeg about the vertical: their
// contacts into c, the count returned.
static const char* const twoCubes = "cube a red 0.1 0.1 0.1\ncube b blue 0.1 0.1 0.1\n";
static int cube_on_cube(const pdModel* m, double turnDeg, pdPose* a, pdPose* b, pdContactGeom* c) {
  *a = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  *b = pose(0, 0, SIDE - DEPTH, turnDeg, pd_v3(0, 0, 1));
  return pd_contacts_find(m, 0, a, 1, b, NULL, NULL, NULL, 0, c, CAPACITY);
}

static void test_equal_cubes_face_on_face_count_each_corner_once(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  pdPose a, b;
  pdContactGeom c[CAPACITY];
  int n = cube_on_cube(m, 0, &a, &b, c);
  // each corner is a vertex of both cubes: four physical touches, not eight; edges are parallel
  assert_int_equal(n, 4);
  for (int i = 0; i < n; ++i) {
    assert_int_equal(c[i].id.kind, pd_contactVF);
    assert_int_equal(c[i].id.body1, 0);
    assert_true(isfinite(c[i].depth) && isfinite(c[i].normal.x) && isfinite(c[i].point.z));
    expect_near(c[i].depth, DEPTH, GEOM_TOL, "depth");
  }
  pd_model_free(m);
}

// Cube b rests DEPTH deep on cube a, shifted half a side along x: their y faces are flush (in one plane).
// The overlap is a rectangle whose four corners lie on those shared planes: two of b's bottom vertices
// over a's top face and two of a's top vertices under b's bottom face. Each presses on the face it
// crossed (top or bottom), at the full depth — not "touching" a side face it slides along.
static void test_flush_side_faces_give_the_overlap_corners_on_the_faces_crossed(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  pdPose a = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  pdPose b = pose(SIDE / 2, 0, SIDE - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 4);
  int aVertices = 0;
  for (int i = 0; i < n; ++i) {
    assert_int_equal(c[i].id.kind, pd_contactVF);
    expect_near(c[i].depth, DEPTH, GEOM_TOL, "depth");
    expect_near(fabs(c[i].normal.z), 1.0, GEOM_TOL, "normal along z (the face crossed, not a flush side face)");
    expect_near(fabs(c[i].point.y), SIDE / 2, GEOM_TOL, "corner on the flush planes");
    aVertices += c[i].id.body1 == 0;
    // a's vertex (x = s/2) in b's bottom face; b's vertex (x = 0) on a's top face
    expect_near(c[i].point.x, c[i].id.body1 == 0 ? SIDE / 2 : 0.0, GEOM_TOL, "corner x");
  }
  assert_int_equal(aVertices, 2);
  // a body lying on another's face from outside only touches, flush or not: lift b to touching
  b = pose(SIDE / 2, 0, SIDE, 0, pd_v3(0, 0, 1));
  assert_int_equal(pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY), 0);
  pd_model_free(m);
}

// A new contact takes the face whose plane its vertex crossed during the step, not the nearest plane:
// b's corner, sinking DEPTH into a's top face over the step, also ends 1e-7 m inside a's side plane
// x = s/2 (it was 2e-7 inside at the start), closer than the top. Without the step's start the nearest
// face wins.
static void test_new_vf_contact_takes_the_face_crossed_during_the_step(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  double slide = 1e-7;
  pdPose a = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  pdPose b0 = pose(SIDE - 2 * slide, SIDE / 2, SIDE + DEPTH, 0, pd_v3(0, 0, 1));  // above the top face
  pdPose b = pose(SIDE - slide, SIDE / 2, SIDE - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, &a, &b0, NULL, 0, c, CAPACITY);
  int found = 0;
  for (int i = 0; i < n; ++i) {
    if (c[i].id.kind != pd_contactVF || c[i].id.body1 != 1) continue;
    ++found;
    expect_near(c[i].normal.z, 1.0, GEOM_TOL, "b's corner presses on a's top face");
    expect_near(c[i].depth, DEPTH, GEOM_TOL, "at the depth below the top face");
  }
  assert_int_equal(found, 1);
  n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  for (int i = 0; i < n; ++i)
    if (c[i].id.kind == pd_contactVF && c[i].id.body1 == 1) expect_near(c[i].depth, slide, GEOM_TOL, "nearest face");
  pd_model_free(m);
}

// Cube a turned 45° about x has a top edge along x at height s/√2; cube b turned 45° about y has a
// bottom edge along y. Crossed, they touch at one point: one EE contact.
static void test_crossed_edges_give_one_ee_contact_with_the_crossing_depth(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  double h = SIDE / sqrt(2.0);
  pdPose a = pose(0, 0, 0, 45, pd_v3(1, 0, 0));
  pdPose b = pose(0, 0, 2 * h - DEPTH, 45, pd_v3(0, 1, 0));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 1);
  assert_int_equal(c[0].id.kind, pd_contactEE);
  assert_int_equal(c[0].id.body1, 0);
  assert_int_equal(c[0].id.body2, 1);
  expect_near(c[0].depth, DEPTH, GEOM_TOL, "depth");
  // normal from body 2 (the upper cube) into body 1 (the lower): straight down
  expect_near(c[0].normal.z, -1.0, GEOM_TOL, "normal z");
  expect_near(c[0].point.x, 0.0, GEOM_TOL, "point x");
  expect_near(c[0].point.y, 0.0, GEOM_TOL, "point y");
  expect_near(c[0].point.z, h - DEPTH / 2, GEOM_TOL, "point z");
  pd_model_free(m);
}

static void test_sliding_vertex_keeps_its_face_and_breaks_past_the_face_edge(void** state) {
  (void)state;
  // floor of two fixed prisms would be clearer, but one face suffices: a small cube slides on a
  // fixed cube's top face; past the face's edge the vertex leaves the polygon
  pdModel* m = compile("cube base grey 0.2 0.2 0.2\nfixed\ncube box red 0.1 0.1 0.1\n");
  pdPose base = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  pdPose box = pose(0, 0, 0.1 + SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &base, 1, &box, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 4);
  pdContactId ids[4];
  for (int i = 0; i < 4; ++i) ids[i] = c[i].id;
  int topFace = c[0].id.feat2;

  // the vertex keeps its face while it stays over the face polygon
  pdPose slid = pose(0.04, 0, 0.1 + SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  n = pd_contacts_find(m, 0, &base, 1, &slid, NULL, NULL, ids, 4, c, CAPACITY);
  assert_int_equal(n, 4);
  for (int i = 0; i < 4; ++i) assert_int_equal(c[i].id.feat2, topFace);
  pdContactGeom g;
  for (int i = 0; i < 4; ++i) assert_true(pd_contact_track(m, &ids[i], &slid, &base, &g));

  // moved 0.06 m, the two leading vertices (x = 0.11) are past the face edge at x = 0.1
  pdPose past = pose(0.06, 0, 0.1 + SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  int broken = 0;
  for (int i = 0; i < 4; ++i) broken += !pd_contact_track(m, &ids[i], &past, &base, &g);
  assert_int_equal(broken, 2);
  pd_model_free(m);
}

static void test_vf_onset_interpolates_the_crossing_time(void** state) {
  (void)state;
  pdModel* m = compile(cubeOnFloor);
  pdPose floor = pose(0, 0, -0.05, 0, pd_v3(0, 0, 1));
  double gap = 3e-4;
  pdPose start = pose(0, 0, SIDE / 2 + gap, 0, pd_v3(0, 0, 1));
  pdPose end = pose(0, 0, SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &floor, 1, &end, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 4);
  // straight-line motion: the crossing is at gap / (gap + depth) of the step
  double t = pd_contact_onset(m, &c[0].id, &start, &end, &floor, &floor);
  expect_near(t, gap / (gap + DEPTH), 1e-12, "onset fraction");
  // already penetrating at the start: a virtual contact, onset 0
  assert_true(pd_contact_onset(m, &c[0].id, &end, &end, &floor, &floor) == 0.0);
  pd_model_free(m);
}

// The face body turns during the step: the quadratic (24) puts the vertex on the interpolated face
// plane at the returned time.
static void test_vf_onset_with_a_turning_face_solves_the_quadratic(void** state) {
  (void)state;
  pdModel* m = compile("cube plate grey 0.4 0.4 0.02\ncube box red 0.1 0.1 0.1\n");
  pdPose plateStart = pose(0, 0, -0.01, 0, pd_v3(0, 0, 1));
  pdPose plateEnd = pose(0, 0, -0.01, 3, pd_v3(1, 0, 0));
  pdPose boxStart = pose(0.05, 0.12, 0.05 + 1e-3, 0, pd_v3(0, 0, 1));
  pdPose boxEnd = pose(0.05, 0.12, 0.05 + 2e-4, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &plateEnd, 1, &boxEnd, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_true(n >= 1);
  const pdContactGeom* vf = NULL;
  for (int i = 0; i < n; ++i)
    if (c[i].id.kind == pd_contactVF && c[i].id.body1 == 1) vf = &c[i];
  assert_non_null(vf);
  double t = pd_contact_onset(m, &vf->id, &boxStart, &boxEnd, &plateStart, &plateEnd);
  assert_true(t > 0.0 && t < 1.0);
  // recompute (23) at t: n(t)·(v(t) − u(t)) = 0
  const pdPolyhedron* box = &m->bodies[1].shape;
  const pdPolyhedron* plate = &m->bodies[0].shape;
  pdVec3 vl = box->vertices[vf->id.feat1];
  pdVec3 ul = plate->vertices[plate->faceVertices[plate->faces[vf->id.feat2].first]];
  pdVec3 nl = plate->faces[vf->id.feat2].normal;
  pdVec3 v1 = pd_v3_add(boxStart.x, pd_mat3_mulv(&boxStart.R, vl)), v2 = pd_v3_add(boxEnd.x, pd_mat3_mulv(&boxEnd.R, vl));
  pdVec3 u1 = pd_v3_add(plateStart.x, pd_mat3_mulv(&plateStart.R, ul)), u2 = pd_v3_add(plateEnd.x, pd_mat3_mulv(&plateEnd.R, ul));
  pdVec3 n1 = pd_mat3_mulv(&plateStart.R, nl), n2 = pd_mat3_mulv(&plateEnd.R, nl);
  pdVec3 vt = pd_v3_add(pd_v3_scale(v1, 1 - t), pd_v3_scale(v2, t));
  pdVec3 ut = pd_v3_add(pd_v3_scale(u1, 1 - t), pd_v3_scale(u2, t));
  pdVec3 nt = pd_v3_add(pd_v3_scale(n1, 1 - t), pd_v3_scale(n2, t));
  expect_near(pd_v3_dot(nt, pd_v3_sub(vt, ut)), 0.0, 1e-15, "interpolated distance at onset");
  pd_model_free(m);
}

static void test_ee_onset_interpolates_the_line_distance(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  double h = SIDE / sqrt(2.0), gap = 2e-4;
  pdPose a = pose(0, 0, 0, 45, pd_v3(1, 0, 0));
  pdPose bStart = pose(0, 0, 2 * h + gap, 45, pd_v3(0, 1, 0));
  pdPose bEnd = pose(0, 0, 2 * h - DEPTH, 45, pd_v3(0, 1, 0));
  pdContactGeom c[CAPACITY];
  assert_int_equal(pd_contacts_find(m, 0, &a, 1, &bEnd, NULL, NULL, NULL, 0, c, CAPACITY), 1);
  double t = pd_contact_onset(m, &c[0].id, &a, &a, &bStart, &bEnd);
  expect_near(t, gap / (gap + DEPTH), 1e-12, "onset fraction");
  pd_model_free(m);
}

static void test_vertex_on_vertex_and_parallel_edges_give_finite_contacts(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  // b balanced on a corner over a's top corner: b's body diagonal vertical
  pdQuat tilt = pd_quat_mul(pd_quat_from_axis_angle(pd_v3(1, -1, 0), acos(1.0 / sqrt(3.0))), pd_quat_identity());
  pdPose a = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  pdPose b = {{0.05, 0.05, 0.05 + SIDE * sqrt(3.0) / 2 - DEPTH}, pd_quat_to_mat3(tilt)};
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_true(n >= 1 && n <= CAPACITY);
  for (int i = 0; i < n; ++i)
    assert_true(isfinite(c[i].depth) && pd_v3_isfinite(c[i].normal) && pd_v3_isfinite(c[i].point));
  // edge on edge, parallel: two cubes side by side, one lifted to share an edge line
  pdPose side = pose(SIDE - DEPTH, 0, SIDE - DEPTH, 0, pd_v3(0, 0, 1));
  n = pd_contacts_find(m, 0, &a, 1, &side, NULL, NULL, NULL, 0, c, CAPACITY);
  for (int i = 0; i < n; ++i) {
    assert_int_equal(c[i].id.kind, pd_contactVF);
    assert_true(isfinite(c[i].depth) && pd_v3_isfinite(c[i].normal));
  }
  pd_model_free(m);
}

// A cube turned 45° about the vertical on an equal cube: no vertex of either is inside the other; the
// contact is the octagon where the two square faces overlap, whose 8 corners are crossings of a top edge
// of the lower cube with a bottom edge of the upper one. Their Gauss-map arcs only touch (the two faces
// are parallel), yet each crossing is a contact with the faces' overlap as depth and the vertical normal.
static void test_cube_turned_45_degrees_on_a_cube_gives_eight_edge_crossings(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  pdPose a, b;
  pdContactGeom c[CAPACITY];
  int n = cube_on_cube(m, 45, &a, &b, c);
  assert_int_equal(n, 8);
  double half = SIDE / 2, offset = half * (sqrt(2.0) - 1.0);  // octagon corner: (±half, ±half(√2 − 1))
  for (int i = 0; i < n; ++i) {
    assert_int_equal(c[i].id.kind, pd_contactEE);
    expect_near(c[i].depth, DEPTH, GEOM_TOL, "depth");
    expect_near(c[i].normal.z, -1.0, GEOM_TOL, "normal from b into a");
    double u = fmax(fabs(c[i].point.x), fabs(c[i].point.y)), v = fmin(fabs(c[i].point.x), fabs(c[i].point.y));
    expect_near(u, half, GEOM_TOL, "corner on a's edge");
    expect_near(v, offset, GEOM_TOL, "corner on b's edge");
  }
  // two cubes side by side sharing an edge line: their front faces are parallel too, but 0.1 m apart
  // across an overlap that is only DEPTH deep sideways: no edge crossing there may count as a contact
  pdPose side = pose(SIDE - DEPTH, 0, SIDE - DEPTH, 0, pd_v3(0, 0, 1));
  n = pd_contacts_find(m, 0, &a, 1, &side, NULL, NULL, NULL, 0, c, CAPACITY);
  for (int i = 0; i < n; ++i) assert_true(c[i].depth <= DEPTH * (1 + 1e-9));
  pd_model_free(m);
}

// The derivative uses pd_contact_geometry (no keep/break decision); it must give the numbers
// pd_contact_track gives, bit for bit, for VF and EE contacts, tracked or broken, and for parallel edges.
static void expect_same_geometry(const pdModel* m, const pdContactId* id, const pdPose* p1, const pdPose* p2) {
  pdContactGeom tracked, geometry;
  memset(&tracked, 0, sizeof tracked);
  memset(&geometry, 0, sizeof geometry);
  (void)pd_contact_track(m, id, p1, p2, &tracked);
  pd_contact_geometry(m, id, p1, p2, &geometry);
  assert_memory_equal(&tracked.point, &geometry.point, sizeof tracked.point);
  assert_memory_equal(&tracked.normal, &geometry.normal, sizeof tracked.normal);
  assert_memory_equal(&tracked.depth, &geometry.depth, sizeof tracked.depth);
}

static void test_contact_geometry_is_the_tracked_geometry(void** state) {
  (void)state;
  pdModel* m = compile(twoCubes);
  pdPose a, b;
  pdContactGeom c[CAPACITY];
  int n = cube_on_cube(m, 45, &a, &b, c);
  assert_int_equal(n, 8);
  // at the found poses, turned a little (still tracked), slid far (broken) and turned to parallel edges
  const pdPose moved[] = {b, pose(0.001, 0.002, SIDE - DEPTH, 44, pd_v3(0.1, 0, 1)), pose(0.3, 0, SIDE, 45, pd_v3(0, 0, 1)),
                          pose(0, 0, SIDE - DEPTH, 0, pd_v3(0, 0, 1))};
  for (size_t k = 0; k < sizeof moved / sizeof moved[0]; ++k)
    for (int i = 0; i < n; ++i) expect_same_geometry(m, &c[i].id, &a, &moved[k]);
  pd_model_free(m);
  m = compile(cubeOnFloor);
  pdPose floor = pose(0, 0, -0.05, 0, pd_v3(0, 0, 1));
  pdPose box = pose(0, 0, SIDE / 2 - DEPTH, 10, pd_v3(1, 1, 0));
  n = pd_contacts_find(m, 0, &floor, 1, &box, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_true(n > 0);
  const pdPose boxes[] = {box, pose(0.7, 0, SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1))};  // the second: off the floor's face
  for (size_t k = 0; k < 2; ++k)
    for (int i = 0; i < n; ++i) {
      const pdPose* p1 = c[i].id.body1 == 0 ? &floor : &boxes[k];
      const pdPose* p2 = c[i].id.body1 == 0 ? &boxes[k] : &floor;
      expect_same_geometry(m, &c[i].id, p1, p2);
    }
  pd_model_free(m);
}

// Seed 3, scene 1779 of the soak: a 5-sided prism and a 13-point hull meet edge on edge, 0.05 of an edge from
// the prism's corner. The hull's edge is a sharp one (its closest point lies outside the prism by less than
// the depth), which find_ee keeps; the edge pruning before it, with a margin of roundoff-sized tolerances,
// dropped the pair unseen, and the bodies sank 15 delta_max with no contact. Poses from that run, at the end of
// the step in which the pair first overlapped (by 0.38 delta_max): the contact is found there now.
static const char* const soakScene1779 =
    "prism f0 orange 5 0.044861204207343651 0.042085458341677158 0.034877202772256838\n"
    "hull f9 brown 0.0035315897908884692 0.003900355971729076 -0.012146444327136172 0.0045025524853000284 "
    "-0.0059587271347789506 -0.0099278649313011384 0.0026602131914562387 0.013963857343787913 "
    "-0.00055704713208306938 -0.0042723156915600051 -0.0090207269219572967 -0.0038722543599061178 "
    "-0.0034013480180039792 -0.012493656179138038 -0.0037244663081974342 -0.00069722867723591301 "
    "-0.00020104663901917696 0.0067250998185252554 -0.0018990989852971968 0.0056605704782138047 "
    "0.012678157528397255 -0.00072908942206353845 -0.013775335316915441 0.00072877605499535093 "
    "0.0036116673168147956 0.0020965762755627165 -0.011066682304245117 0.0054435418640811518 "
    "-0.017900165005297942 0.0063788193417485956 -0.0044223025123209855 -0.01359417183030138 "
    "-0.001993431301546114 0.0040872157465124126 -0.00124021632164168 -0.01527599188566796\n";

static void test_sharp_edge_pair_is_not_pruned_before_the_inside_test(void** state) {
  (void)state;
  pdModel* m = compile(soakScene1779);
  pdQuat qa = {-0.34333787861646697, 0.0011060038539183554, -0.71494811668866109, 0.60907065953463579};
  pdQuat qb = {0.66047191899169799, -0.47869626849181929, 0.57739884225903659, -0.035175328191166526};
  pdPose a = {{-0.033340391203570317, 0.054717232503713319, 0.0017847409073762496}, pd_quat_to_mat3(qa)};
  pdPose b = {{-0.033952564060515389, 0.021591205878948878, 0.003015928848528832}, pd_quat_to_mat3(qb)};
  double deltaMax = m->settings.deflection * fmin(m->bodies[0].size, m->bodies[1].size);
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 1);
  assert_int_equal(c[0].id.kind, pd_contactEE);
  assert_int_equal(c[0].id.feat1, 10);
  assert_int_equal(c[0].id.feat2, 8);
  assert_true(c[0].depth > 0.3 * deltaMax && c[0].depth < 0.45 * deltaMax);
  pd_model_free(m);
}

// Soak campaign 43, scene 592: a 4-sided triangular prism's edge crosses a cube's edge 3.95 delta_max deep, the two
// bodies interpenetrating by more than that, the prism's closest point more than 3 delta_max outside the cube as at a
// sharp edge. The search takes such a pair (its points within delta_max + the penetration of inside); tracking allowed
// them 3 delta_max only, so the pair broke at every commit and was found again at the next, with its springs from a
// hand-over trace while it approached and with none when it turned away (14.8 delta_max). Poses from that run.
static const char* const soakScene43_592 =
    "tprism f4 brown 4 0.016190375758028286 0.0049016670562108391 0.010739124391108955 0.92011747919023024\n"
    "loc -10 0 0\n"  // compile_apart places cubes, hulls and prisms only
    "cube f6 grey 0.029093306302204774 0.018918594669769764 0.036012588091981539\n";

static void test_a_deep_edge_pair_the_search_finds_is_tracked(void** state) {
  (void)state;
  pdModel* m = compile(soakScene43_592);
  pdPose a = {{-0.0076696353683780236, -0.0013803532009457645, 0.0074300406585290583},
              {{{-0.024400200201459638, -0.99959160450335083, -0.014874623912744356},
                {-0.33754025209484811, -0.0057676914604886664, 0.94129342500145141},
                {-0.94099479724697477, 0.027988532323676818, -0.33726166934961854}}}};
  pdPose b = {{0.0079226728773246734, -0.0074487440700865435, -0.0038186223368724946},
              {{{0.93378118278783073, -0.19342514731603078, 0.30106380562454171},
                {0.24983504529183803, 0.95472418891340316, -0.16150595421739111},
                {-0.25619358464915798, 0.2260275104703332, 0.93982786279999087}}}};
  double deltaMax = m->settings.deflection * fmin(m->bodies[0].size, m->bodies[1].size);
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY);
  int found = -1;
  for (int i = 0; i < n; ++i)
    if (c[i].id.kind == pd_contactEE && c[i].id.feat1 == 2 && c[i].id.feat2 == 6) found = i;
  assert_true(found >= 0);
  assert_true(c[found].depth > 3.9 * deltaMax && c[found].depth < 4.0 * deltaMax);
  pdContactGeom g;
  assert_true(pd_contact_track(m, &c[found].id, &a, &b, &g));
  expect_near(g.depth, c[found].depth, GEOM_TOL, "tracked depth");
  pd_model_free(m);
}

// An edge lying nearly along a thin plate's rim face, pressed into it, crosses both of the face's long edges: both
// crossings carry the touch. Body 0: a bar (cube a turned 45° about x) whose top edge runs along x at height h;
// body 1: a plate 0.1 × 0.01 × 0.05 m whose bottom face, its rim, is turned 30° about z across that edge (so the
// edge crosses the rim's two long edges at x = ±0.01) and tilted 0.3° about y, pressed down until the edge lies
// `deep` below the rim at its middle: deep ± 5.2e-5 at the two crossings. The Gauss-map arcs of the bar's edge cross
// those of one rim edge only (the tilt turns the pair's normal 0.6° off the rim's), so the Minkowski-face test alone
// gives one crossing at a time, and a rocking rim's other end is found anew at the depth the two share, its springs
// at zero (soak campaign 49, scene 439). Within EE_ARC_SLACK both are found, and tracked.
static void test_edge_along_a_rim_face_gives_both_crossings(void** state) {
  (void)state;
  pdModel* m = compile("cube bar grey 0.3 0.1 0.1\ncube plate orange 0.1 0.01 0.05\n");
  const double deep = 2e-4, tilt = 0.3 * PI / 180.0, turn = 30.0 * PI / 180.0;
  double h = SIDE / sqrt(2.0);
  pdPose bar = pose(0, 0, 0, 45, pd_v3(1, 0, 0));
  pdQuat q = pd_quat_mul(pd_quat_from_axis_angle(pd_v3(0, 1, 0), tilt), pd_quat_from_axis_angle(pd_v3(0, 0, 1), turn));
  pdMat3 R = pd_quat_to_mat3(q);
  // the plate's bottom face centre (0, 0, −0.025 in its frame) at the edge's height less `deep`
  pdVec3 bottom = pd_mat3_mulv(&R, pd_v3(0, 0, -0.025));
  pdPose plate = {pd_v3(-bottom.x, -bottom.y, h - deep - bottom.z), R};
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &bar, 1, &plate, NULL, NULL, NULL, 0, c, CAPACITY);
  int crossings = 0;
  for (int i = 0; i < n; ++i) {
    print_message("contact %d: kind %d features %d/%d depth %.6g at x %.4f\n", i, c[i].id.kind, c[i].id.feat1,
                  c[i].id.feat2, c[i].depth, c[i].point.x);
    if (c[i].id.kind != pd_contactEE) continue;
    ++crossings;
    // the rim's long edges cross the bar's at x = ±0.005 / sin 30°, where the tilt lowers or raises the rim by x tan 0.3°
    assert_true(fabs(fabs(c[i].point.x) - 0.005 / sin(turn)) < 1e-4);
    expect_near(c[i].depth, deep + c[i].point.x * tan(tilt), 2e-6, "crossing depth");
    pdContactGeom g;
    assert_true(pd_contact_track(m, &c[i].id, &bar, &plate, &g));
  }
  assert_int_equal(crossings, 2);
  pd_model_free(m);
}

// A 4 mm plate and a tetrahedron above it, its apex down (the two thin-plate cases below).
#define PLATE_AND_TIP "cube plate grey 0.4 0.4 0.004\nhull tip red 0 0 0 0.05 0 0.05 -0.05 0.05 0.05 -0.05 -0.05 0.05\n"

// The vertex of a shape lowest along its own z.
static int lowest_vertex(const pdPolyhedron* shape) {
  int lowest = 0;
  for (int v = 1; v < shape->vertexCount; ++v)
    if (shape->vertices[v].z < shape->vertices[lowest].z) lowest = v;
  return lowest;
}

// A corner pressed through a thin plate (docs/contact-model.md, "A vertex pressed through a thin body"): a
// tetrahedron's apex in contact on the plate's top face keeps that contact when it has come out through the bottom
// face (outside only across a face turned away from its own, over the top face, its body's lowest point), and breaks
// once it is also outside a side face. The search makes no new contact of a vertex there.
static void test_a_vertex_pressed_through_a_thin_plate_keeps_its_face(void** state) {
  (void)state;
  const double half = 0.002;  // the plate's half-thickness, m
  pdModel* m = compile(PLATE_AND_TIP);
  const pdPolyhedron* tip = &m->bodies[1].shape;
  int apex = lowest_vertex(tip);
  double apexZ = tip->vertices[apex].z;  // below the hull's centre of mass, its frame's origin
  pdPose plate = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  pdPose in = pose(0.05, 0, half - DEPTH - apexZ, 0, pd_v3(0, 0, 1));
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &plate, 1, &in, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(n, 1);
  assert_int_equal(c[0].id.kind, pd_contactVF);
  assert_int_equal(c[0].id.feat1, apex);
  pdContactId id = c[0].id;
  expect_near(c[0].normal.z, 1.0, GEOM_TOL, "the top face's normal");
  // through the plate and 1 mm beyond its bottom face (the pair's delta_max is a quarter of its 4 mm width)
  pdPose through = pose(0.05, 0, -half - 1e-3 - apexZ, 0, pd_v3(0, 0, 1));
  pdContactGeom g;
  assert_true(pd_contact_track(m, &id, &through, &plate, &g));
  expect_near(g.depth, 2.0 * half + 1e-3, GEOM_TOL, "depth below the top face");
  expect_near(g.normal.z, 1.0, GEOM_TOL, "the normal stays the top face's");
  assert_int_equal(pd_contacts_find(m, 0, &plate, 1, &through, NULL, NULL, NULL, 0, c, CAPACITY), 0);
  // beyond the plate's side as well (x = 0.2 is its edge): over the top face no more, broken
  pdPose off = pose(0.2 + 1e-3, 0, -half - 1e-3 - apexZ, 0, pd_v3(0, 0, 1));
  assert_false(pd_contact_track(m, &id, &off, &plate, &g));
  pd_model_free(m);
}

// An edge pressed through a thin plate's rim (docs/contact-model.md, "An edge pair's vertex through the far side"): a
// tetrahedron in an edge pair with the plate's top edge, its apex through the plate 1 mm beyond the bottom face, below
// the top face and over it, its body's lowest point. The apex presses on the top face as a vertex tracked there would
// (through_far_side): the search finds it there, its normal and depth the top face's; with no edge pair at the apex it
// finds no contact of that vertex, as above.
static void test_an_edge_pairs_end_through_a_thin_plate_is_found_on_the_face(void** state) {
  (void)state;
  const double half = 0.002;  // the plate's half-thickness, m
  pdModel* m = compile(PLATE_AND_TIP);
  const pdPolyhedron* plateShape = &m->bodies[0].shape;
  const pdPolyhedron* tip = &m->bodies[1].shape;
  int apex = lowest_vertex(tip);
  int top = -1, rim = -1, tipEdge = -1;
  for (int f = 0; f < plateShape->faceCount; ++f)
    if (plateShape->faces[f].normal.z > 0.5) top = f;
  for (int e = 0; e < plateShape->edgeCount && rim < 0; ++e) {  // the top face's edge along x = 0.2
    pdVec3 a = plateShape->vertices[plateShape->edges[e].v[0]], b = plateShape->vertices[plateShape->edges[e].v[1]];
    if (a.x > 0.19 && b.x > 0.19 && a.z > 0.0 && b.z > 0.0) rim = e;
  }
  for (int e = 0; e < tip->edgeCount && tipEdge < 0; ++e)
    if (tip->edges[e].v[0] == apex || tip->edges[e].v[1] == apex) tipEdge = e;
  assert_true(top >= 0 && rim >= 0 && tipEdge >= 0);
  double apexZ = tip->vertices[apex].z;
  pdPose plate = pose(0, 0, 0, 0, pd_v3(0, 0, 1));
  // 1 cm in from the rim's side face (the tetrahedron's edges pass over the rim), through the plate and 1 mm beyond its
  // bottom face
  pdVec3 apexAt = tip->vertices[apex];  // in the hull's frame, about its centre of mass
  pdPose through = pose(0.2 - 1e-2 - apexAt.x, -apexAt.y, -half - 1e-3 - apexZ, 0, pd_v3(0, 0, 1));
  pdContactId edgePair = {0, 1, pd_contactEE, rim, tipEdge};
  pdContactGeom c[CAPACITY];
  int n = pd_contacts_find(m, 0, &plate, 1, &through, NULL, NULL, &edgePair, 1, c, CAPACITY);
  assert_true(n <= CAPACITY);
  int found = -1;
  for (int k = 0; k < n; ++k)
    if (c[k].id.kind == pd_contactVF && c[k].id.body1 == 1 && c[k].id.feat1 == apex) found = k;
  assert_true(found >= 0);
  assert_int_equal(c[found].id.feat2, top);
  expect_near(c[found].depth, 2.0 * half + 1e-3, GEOM_TOL, "depth below the top face");
  expect_near(c[found].normal.z, 1.0, GEOM_TOL, "the top face's normal");
  // tracked there as a vertex pressed through the plate
  pdContactGeom g;
  assert_true(pd_contact_track(m, &c[found].id, &through, &plate, &g));
  // no edge pair at the apex: no contact of it
  n = pd_contacts_find(m, 0, &plate, 1, &through, NULL, NULL, NULL, 0, c, CAPACITY);
  for (int k = 0; k < n && k < CAPACITY; ++k)
    assert_false(c[k].id.kind == pd_contactVF && c[k].id.body1 == 1 && c[k].id.feat1 == apex);
  pd_model_free(m);
}

// Soak campaign 70, scene 3505 (cases/hard/prism_vertex_at_plate_rim_long_step.scene): the poses at the start and the
// end of the 62 us step in which the frustum f1's edge 11 crossed the plate f6's acute rim edge 9 (cap face 1, side
// face 6) from before the pair's onset to past the edge's end, vertex 7 (as the engine before reached them). Found
// anew, vertex 7 takes the face the pair's hand-over gives, the side face (0.78 delta_max deep, the deeper of the rim
// edge's two faces), not the cap whose plane it crossed (5e-4 delta_max); without the step's start, or with the step
// starting where it ends (the pair's crossing already past the vertex), it takes the cap as before.
static pdPose pose_q(double x, double y, double z, double qw, double qx, double qy, double qz) {
  pdQuat q = {qw, qx, qy, qz};
  return (pdPose){{x, y, z}, pd_quat_to_mat3(q)};
}
static int vertex_contact_face(const pdContactGeom* c, int n, int body, int vertex, double* depth) {
  for (int k = 0; k < n && k < CAPACITY; ++k)
    if (c[k].id.kind == pd_contactVF && c[k].id.body1 == body && c[k].id.feat1 == vertex) {
      *depth = c[k].depth;
      return c[k].id.feat2;
    }
  return -1;
}
static void test_a_vertex_an_edge_pair_passed_within_the_step_takes_the_pairs_face(void** state) {
  (void)state;
  pdModel* m = compile_file(PD_SOURCE_DIR "/cases/hard/prism_vertex_at_plate_rim_long_step.scene");
  const int frustum = 0, plate = 1, vertex = 7, cap = 1, side = 6;
  double deltaMax = pd_model_pair_delta_max(m, frustum, plate);
  pdPose f0 = pose_q(0.097890679906785599, -0.057264619827454379, -0.0062303098908068743, 0.39008598464570715,
                     -0.047183019979544397, -0.55101476769474123, 0.73619930249281651);
  pdPose p0 = pose_q(0.092063965627048217, -0.087973608263498981, 0.0068526819592374544, 0.34577015118209425,
                     0.80290589471426643, -0.31730021735949243, -0.36756727118748472);
  pdPose f1 = pose_q(0.097748604310665801, -0.057455862810404212, -0.0062279001018962143, 0.38950057804361993,
                     -0.048014988947847614, -0.55084413563846224, 0.73658305626231968);
  pdPose p1 = pose_q(0.092087431408150719, -0.087746886721731698, 0.0068526819592374544, 0.34574551788961161,
                     0.80286632545909908, -0.31741309519769256, -0.36757941631716662);
  pdContactGeom c[CAPACITY];
  double depth = 0.0;
  // the step as the engine took it: the side face, at the bodies' overlap along its normal
  int n = pd_contacts_find(m, frustum, &f1, plate, &p1, &f0, &p0, NULL, 0, c, CAPACITY);
  assert_int_equal(vertex_contact_face(c, n, frustum, vertex, &depth), side);
  expect_near(depth / deltaMax, 0.778, 1e-3, "depth below the side face / delta_max");
  // no step seen, or a step with no motion (the pair's crossing past the vertex at its start too): the cap, the face
  // crossed or the shallowest
  n = pd_contacts_find(m, frustum, &f1, plate, &p1, NULL, NULL, NULL, 0, c, CAPACITY);
  assert_int_equal(vertex_contact_face(c, n, frustum, vertex, &depth), cap);
  assert_true(depth < 1e-3 * deltaMax);
  n = pd_contacts_find(m, frustum, &f1, plate, &p1, &f1, &p1, NULL, 0, c, CAPACITY);
  assert_int_equal(vertex_contact_face(c, n, frustum, vertex, &depth), cap);
  pd_model_free(m);
}

static void test_small_capacity_reports_the_needed_count(void** state) {
  (void)state;
  pdModel* m = compile(cubeOnFloor);
  pdPose floor = pose(0, 0, -0.05, 0, pd_v3(0, 0, 1));
  pdPose box = pose(0, 0, SIDE / 2 - DEPTH, 0, pd_v3(0, 0, 1));
  pdContactGeom c[2];
  assert_int_equal(pd_contacts_find(m, 0, &floor, 1, &box, NULL, NULL, NULL, 0, c, 2), 4);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cube_resting_on_floor_gives_four_vf_contacts_with_the_floor_normal),
      cmocka_unit_test(test_separated_or_just_touching_bodies_have_no_contact),
      cmocka_unit_test(test_equal_cubes_face_on_face_count_each_corner_once),
      cmocka_unit_test(test_flush_side_faces_give_the_overlap_corners_on_the_faces_crossed),
      cmocka_unit_test(test_new_vf_contact_takes_the_face_crossed_during_the_step),
      cmocka_unit_test(test_crossed_edges_give_one_ee_contact_with_the_crossing_depth),
      cmocka_unit_test(test_sliding_vertex_keeps_its_face_and_breaks_past_the_face_edge),
      cmocka_unit_test(test_vf_onset_interpolates_the_crossing_time),
      cmocka_unit_test(test_vf_onset_with_a_turning_face_solves_the_quadratic),
      cmocka_unit_test(test_ee_onset_interpolates_the_line_distance),
      cmocka_unit_test(test_vertex_on_vertex_and_parallel_edges_give_finite_contacts),
      cmocka_unit_test(test_cube_turned_45_degrees_on_a_cube_gives_eight_edge_crossings),
      cmocka_unit_test(test_contact_geometry_is_the_tracked_geometry),
      cmocka_unit_test(test_sharp_edge_pair_is_not_pruned_before_the_inside_test),
      cmocka_unit_test(test_a_deep_edge_pair_the_search_finds_is_tracked),
      cmocka_unit_test(test_edge_along_a_rim_face_gives_both_crossings),
      cmocka_unit_test(test_a_vertex_pressed_through_a_thin_plate_keeps_its_face),
      cmocka_unit_test(test_an_edge_pairs_end_through_a_thin_plate_is_found_on_the_face),
      cmocka_unit_test(test_a_vertex_an_edge_pair_passed_within_the_step_takes_the_pairs_face),
      cmocka_unit_test(test_small_capacity_reports_the_needed_count),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
