// A vertex inside an edge's wedge (engine/src/contact_analysis.c, "a vertex pressed into both faces of a right-angled
// edge"; docs/contact-model.md, "A corner or an edge inside an edge's wedge").
// - Right-angled edge: a corner held on a box's top face by continuity and pressed across the side face's plane gets
//   a second VF contact on the side face; the two contacts' depth-weighted normals sum to w, the vector from the
//   vertex to its foot on the edge's line (the vertex–edge element's depth |w| along n = w/|w|), to rounding.
// - Continuity: the second contact starts where the vertex crosses the side plane, at a depth no larger than the
//   vertex moved past it; moving the vertex on through the wedge in small steps, Σ d_i n_i changes by no more than the
//   vertex moved (the elastic force k Σ d_i n_i is Lipschitz with constant k along the path), across the onset.
// - A vertex found anew (not held on the top face) gets one face by the paper's rules only.
// - Obtuse edge: a vertex inside an octagonal prism's lateral edge, with w on the edge's Gauss arc, projects inside
//   both faces and its contact reads w·n_F on the face it takes, at least cos 45° |w|; no second contact.
// - Acute edge: a corner held on a wedge's top face and moved through the lower face's plane into the wedge stays one
//   contact, on the top face, its depth continuous and at least the vertex's own overlap (no second face: the design
//   note in engine/src/contact_analysis.c says why).
// - Search certificates: a corner held on the side face, inside the top face's plane by less than the flush tolerance
//   (no contact on the top face yet), is certified for no more than its way to that tolerance.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "contact_analysis.h"
#include "contact_features.h"
#include "polydyn/model.h"
#include "scene_run.h"

enum { CAPACITY = 64 };

// Rounding of the sums below, relative to the box's size (~1e-16 per operation on 0.1 m).
#define GEOMETRY_TOL_REL 1e-12

// A 0.1 m cube (body 0, faces: +z top, ±x, ±y sides) and a tetrahedron (body 1) whose apex, vertex 0, points down.
static const char* const BOX_AND_TETRAHEDRON =
    "cube a red 0.1 0.1 0.1\n"
    "hull b blue 0 0 0  0.03 0.01 0.02  -0.01 0.03 0.02  -0.015 -0.02 0.02\n";

// Face of s with outward normal nearest u.
static int face_along(const pdPolyhedron* s, pdVec3 u) {
  int best = 0;
  for (int f = 1; f < s->faceCount; ++f)
    if (pd_v3_dot(s->faces[f].normal, u) > pd_v3_dot(s->faces[best].normal, u)) best = f;
  return best;
}

// The tetrahedron's apex: its vertex lowest along −z in its own frame.
static int apex_index(const pdModel* m) {
  const pdPolyhedron* s = &m->bodies[1].shape;
  int low = 0;
  for (int i = 1; i < s->vertexCount; ++i)
    if (s->vertices[i].z < s->vertices[low].z) low = i;
  return low;
}

// The tetrahedron turned by R with its apex at world point p.
static pdPose apex_at_turned(const pdModel* m, pdVec3 p, pdMat3 R) {
  pdVec3 apex = pd_mat3_mulv(&R, m->bodies[1].shape.vertices[apex_index(m)]);
  return (pdPose){pd_v3_sub(p, apex), R};
}
static pdPose apex_at(const pdModel* m, pdVec3 p) { return apex_at_turned(m, p, pd_mat3_identity()); }

static int apex = 0;  // set by each test (apex_index)

// Σ d n over the VF contacts of the apex in `found`; their number to *count.
static pdVec3 apex_depth_sum(const pdContactGeom* found, int n, int* count) {
  pdVec3 sum = {0, 0, 0};
  *count = 0;
  for (int i = 0; i < n; ++i) {
    if (found[i].id.kind != pd_contactVF || found[i].id.body1 != 1 || found[i].id.feat1 != apex) continue;
    sum = pd_v3_muladd(sum, found[i].depth, found[i].normal);
    ++*count;
  }
  return sum;
}

// The contacts a step carries to the next: those found (n), and `held` if the search left it to tracking. Their number.
static int carried(const pdContactGeom* found, int n, pdContactId held, pdContactId* previous) {
  int count = 0;
  bool heldFound = false;
  for (int i = 0; i < n; ++i) {
    previous[count++] = found[i].id;
    heldFound = heldFound || pd_contact_id_compare(&found[i].id, &held) == 0;
  }
  if (!heldFound) previous[count++] = held;
  return count;
}

static void test_a_held_corner_at_a_right_edge_reads_the_vertex_edge_depth(void** state) {
  (void)state;
  pdModel* m = compile_apart(BOX_AND_TETRAHEDRON);
  const pdPolyhedron* box = &m->bodies[0].shape;
  int top = face_along(box, pd_v3(0, 0, 1)), side = face_along(box, pd_v3(1, 0, 0));
  double deltaMax = pd_model_pair_delta_max(m, 0, 1), tol = GEOMETRY_TOL_REL * 0.1;
  pdPose a = {{0, 0, 0}, pd_mat3_identity()};
  // held on the top face (its contact of the last commit), 1 δ_max deep, first 0.05 δ_max outside the side plane: as
  // close as tracking keeps a contact whose vertex is outside the body (TRACK_INSIDE_TOL_REL)
  apex = apex_index(m);
  pdContactId held = {1, 0, pd_contactVF, apex, top};
  pdVec3 start = {0.05 + 0.05 * deltaMax, 0.0, 0.05 - deltaMax};
  pdContactGeom found[CAPACITY];
  int count = 0;
  // moved in -x through the side plane, then on into the wedge, 0.01 δ_max per step, the previous step's contacts held
  pdContactId previous[CAPACITY + 1];  // the found ones and the held one
  int previousCount = 1;
  previous[0] = held;
  pdVec3 lastSum = {0, 0, 0};
  double lastX = start.x;
  int both = 0;
  bool onset = false;
  for (int k = 1; k <= 300; ++k) {
    pdVec3 p = {start.x - 0.01 * k * deltaMax, 0.0, start.z};
    pdPose b = apex_at(m, p), bPrev = apex_at(m, (pdVec3){lastX, 0.0, start.z});
    int n = pd_contacts_find(m, 0, &a, 1, &b, &a, &bPrev, previous, previousCount, found, CAPACITY);
    assert_true(n <= CAPACITY);
    pdVec3 sum = apex_depth_sum(found, n, &count);
    double inside = 0.05 - p.x;  // depth below the side face
    if (inside > tol) {
      // pressed into both faces: a contact on each, Σ d n = w (vertex to its foot on the edge's line)
      assert_int_equal(count, 2);
      pdVec3 w = {0.05 - p.x, 0.0, 0.05 - p.z};
      assert_true(pd_v3_norm(pd_v3_sub(sum, w)) <= tol);
      for (int i = 0; i < n; ++i)
        if (found[i].id.kind == pd_contactVF && found[i].id.feat1 == apex && found[i].id.feat2 == side && !onset) {
          // onset: no deeper than the vertex moved past the plane in this step
          assert_true(found[i].depth <= 0.01 * deltaMax + tol);
          onset = true;
        }
      ++both;
    }
    // outside the body the search finds no contact of the vertex, and tracking carries the top face's at its depth
    if (count == 0) sum = pd_v3_scale(box->faces[top].normal, 0.05 - p.z);
    // continuity: the elastic force's direction × depth moves no more than the vertex
    if (k > 1) assert_true(pd_v3_norm(pd_v3_sub(sum, lastSum)) <= 0.01 * deltaMax * (1.0 + 1e-9) + tol);
    lastSum = sum, lastX = p.x;
    // the step's contacts, and the top face's, which tracking keeps while the vertex is outside by less than its
    // tolerance
    previousCount = carried(found, n, held, previous);
  }
  assert_true(onset);
  assert_true(both > 200);
  // found anew at the last pose (no previous contact): one face, by the paper's rules
  pdPose b = apex_at(m, (pdVec3){start.x - 3.0 * deltaMax, 0.0, start.z});
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, found, CAPACITY);
  apex_depth_sum(found, n, &count);
  assert_int_equal(count, 1);
  pd_model_free(m);
}

// Held on the side face 10 δ_max deep (the tetrahedron's edges then leave the cube through the top face far enough from
// its edges that no edge pair keeps the pair from being certified) and below the top face's plane by half the flush
// tolerance, where it is no contact on the top face yet: the certificate reaches no farther than that tolerance.
static void test_a_held_corner_by_a_right_edges_face_is_certified_no_farther_than_its_onset(void** state) {
  (void)state;
  pdModel* m = compile_apart(BOX_AND_TETRAHEDRON);
  const pdPolyhedron* box = &m->bodies[0].shape;
  int side = face_along(box, pd_v3(1, 0, 0)), top = face_along(box, pd_v3(0, 0, 1));
  double deltaMax = pd_model_pair_delta_max(m, 0, 1), flushTol = FLUSH_TOL_DEFLECTIONS * deltaMax;
  pdPose a = {{0, 0, 0}, pd_mat3_identity()};
  apex = apex_index(m);
  pdContactId held = {1, 0, pd_contactVF, apex, side};
  pdPose b = apex_at(m, (pdVec3){0.05 - 10.0 * deltaMax, 0.0, 0.05 - 0.5 * flushTol});
  pdContactGeom found[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, &a, &b, &held, 1, found, CAPACITY);
  assert_int_equal(n, 1);
  assert_true(pd_contact_id_compare(&found[0].id, &held) == 0);
  pdSearchCertificate cert = pd_contacts_certify(m, 0, &a, 1, &b, &held, 1);
  assert_true(cert.margin > 0.0);
  assert_true(cert.margin <= 0.5 * flushTol);
  // and the margin is needed: moved 0.6 of the flush tolerance further down, the search finds the top face's contact
  pdPose b2 = apex_at(m, (pdVec3){0.05 - 10.0 * deltaMax, 0.0, 0.05 - 1.1 * flushTol});
  n = pd_contacts_find(m, 0, &a, 1, &b2, &a, &b, &held, 1, found, CAPACITY);
  bool onTop = false;
  for (int i = 0; i < n; ++i) onTop = onTop || (found[i].id.kind == pd_contactVF && found[i].id.feat2 == top);
  assert_true(onTop);
  pd_model_free(m);
}

// An octagonal prism (body 0; its lateral edges obtuse: normals 45° apart) and the tetrahedron's apex inside the wedge of
// the lateral edge at +x, +y, on the edge's Gauss arc: the apex projects inside both faces, takes one by the paper's
// rules, and reads w·n_F there, at least cos 22.5° |w| in the middle of the arc; no second contact (the edge is not
// right-angled).
static void test_a_vertex_in_an_obtuse_edges_sector_is_read_by_one_face(void** state) {
  (void)state;
  pdModel* m = compile_apart("prism a red 8 0.1 0.1 0.1\n"
                             "hull b blue 0 0 0  0.03 0.01 0.02  -0.01 0.03 0.02  -0.015 -0.02 0.02\n");
  apex = apex_index(m);
  const pdPolyhedron* prism = &m->bodies[0].shape;
  double deltaMax = pd_model_pair_delta_max(m, 0, 1), tol = GEOMETRY_TOL_REL * 0.1;
  pdPose a = {{0, 0, 0}, pd_mat3_identity()};
  // a lateral edge with both faces' normals horizontal and 45° apart
  int edge = -1;
  for (int e = 0; e < prism->edgeCount && edge < 0; ++e) {
    pdVec3 n1 = prism->faces[prism->edges[e].f[0]].normal, n2 = prism->faces[prism->edges[e].f[1]].normal;
    if (fabs(n1.z) < 1e-9 && fabs(n2.z) < 1e-9 && pd_v3_dot(n1, n2) > 0.5) edge = e;
  }
  assert_true(edge >= 0);
  const pdEdge* e = &prism->edges[edge];
  pdVec3 n1 = prism->faces[e->f[0]].normal, n2 = prism->faces[e->f[1]].normal;
  pdVec3 v0 = prism->vertices[e->v[0]], v1 = prism->vertices[e->v[1]];
  pdVec3 mid = pd_v3_scale(pd_v3_add(v0, v1), 0.5);
  for (int k = 0; k <= 10; ++k) {
    double t = k / 10.0;
    pdVec3 n = pd_v3_add(pd_v3_scale(n1, 1.0 - t), pd_v3_scale(n2, t));
    n = pd_v3_scale(n, 1.0 / pd_v3_norm(n));
    double depth = 2.0 * deltaMax;
    // the apex |w| = 2 δ_max inside along −n from the edge's middle, the tetrahedron turned so that it points along −n
    // (its own +z, the base's side, along n: out of the prism)
    pdVec3 p = pd_v3_muladd(mid, -depth, n);
    pdVec3 axis = pd_v3_cross(pd_v3(0, 0, 1), n);
    pdMat3 R = pd_quat_to_mat3(pd_quat_from_axis_angle(pd_v3_scale(axis, 1.0 / pd_v3_norm(axis)), acos(n.z)));
    pdPose b = apex_at_turned(m, p, R);
    pdContactGeom found[CAPACITY];
    int count = 0, n_found = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, found, CAPACITY);
    apex_depth_sum(found, n_found, &count);
    assert_int_equal(count, 1);
    for (int i = 0; i < n_found; ++i) {
      if (found[i].id.kind != pd_contactVF || found[i].id.body1 != 1 || found[i].id.feat1 != apex) continue;
      int f = found[i].id.feat2;
      assert_true(f == e->f[0] || f == e->f[1]);
      // its depth is w's component along the face's normal, at least cos 45° of |w| on the whole arc
      assert_true(fabs(found[i].depth - depth * pd_v3_dot(n, prism->faces[f].normal)) <= tol);
      assert_true(found[i].depth >= depth * sqrt(0.5) - tol);
    }
  }
  pd_model_free(m);
}

// A wedge (body 0, a hull: a horizontal top face F and a lower face f that rises to meet it at 45°, their outward
// normals 135° apart) and the tetrahedron's apex held on F, 1 δ_max below it, first 0.05 δ_max outside f's plane (a
// vertex beyond an acute edge, kept on F), then moved through f's plane into the wedge in steps of 0.01 δ_max while it
// sinks 0.005 δ_max per step: it stays one VF contact, on F (face continuity), its depth F's depth, continuous, and at
// least the vertex's own penetration, min(d_F, d_f); no contact on f is added as at a right-angled edge, since there
// f's force k d_f n_f would push the vertex along −n_F with |cos θ| of itself, against F's (the vertex–edge element, which
// reads |w| ≥ d_F / sin θ inside the wedge, would jump at f's plane). Found anew at the last pose, one face.
static void test_a_held_corner_at_an_acute_edge_keeps_its_face(void** state) {
  (void)state;
  pdModel* m = compile_apart("hull a grey 0 -0.05 0  0 0.05 0  -0.1 -0.05 0  -0.1 0.05 0  -0.1 -0.05 -0.1  -0.1 0.05 -0.1\n"
                             "hull b blue 0 0 0  0.03 0.01 0.02  -0.01 0.03 0.02  -0.015 -0.02 0.02\n");
  const pdPolyhedron* wedge = &m->bodies[0].shape;
  int top = face_along(wedge, pd_v3(0, 0, 1)), low = face_along(wedge, pd_v3(1, 0, -1));
  double cosTheta = pd_v3_dot(wedge->faces[top].normal, wedge->faces[low].normal);
  assert_true(fabs(cosTheta + sqrt(0.5)) <= 1e-9);
  double deltaMax = pd_model_pair_delta_max(m, 0, 1), tol = GEOMETRY_TOL_REL * 0.1;
  pdPose a = {{0, 0, 0}, pd_mat3_identity()};
  apex = apex_index(m);
  pdContactId held = {1, 0, pd_contactVF, apex, top};
  // the acute edge's line in the wedge's frame (y = 0): on F's plane, z = zTop, and on f's, nf·q = f's offset
  double zTop = wedge->faces[top].offset;
  pdVec3 nf = wedge->faces[low].normal;
  double xEdge = (wedge->faces[low].offset - nf.z * zTop) / nf.x;
  // 1 δ_max below F and outside f's plane by 0.05 δ_max: (x − xEdge) nf.x + (z − zTop) nf.z = 0.05 δ_max
  pdVec3 start = {0.0, 0.0, zTop - deltaMax};
  start.x = xEdge + (0.05 * deltaMax - (start.z - zTop) * nf.z) / nf.x;
  assert_true(fabs(face_depth(wedge, low, start) + 0.05 * deltaMax) <= tol);
  pdContactGeom found[CAPACITY];
  pdContactId previous[CAPACITY + 1];  // the found ones and the held one
  int previousCount = 1;
  previous[0] = held;
  pdVec3 last = start;
  double lastDepth = zTop - start.z;
  int inside = 0;
  for (int k = 1; k <= 300; ++k) {
    pdVec3 p = {start.x - 0.01 * k * deltaMax, 0.0, start.z - 0.005 * k * deltaMax};
    pdPose b = apex_at(m, p), bPrev = apex_at(m, last);
    int n = pd_contacts_find(m, 0, &a, 1, &b, &a, &bPrev, previous, previousCount, found, CAPACITY);
    assert_true(n <= CAPACITY);
    int count = 0;
    apex_depth_sum(found, n, &count);
    double dF = face_depth(wedge, top, p), df = face_depth(wedge, low, p);
    if (df > 0.0) ++inside;
    if (count > 0) {
      assert_int_equal(count, 1);
      for (int i = 0; i < n; ++i) {
        if (found[i].id.kind != pd_contactVF || found[i].id.body1 != 1 || found[i].id.feat1 != apex) continue;
        assert_true(pd_contact_id_compare(&found[i].id, &held) == 0);
        assert_true(fabs(found[i].depth - dF) <= tol);
        assert_true(found[i].depth >= fmin(dF, df) - tol);
        // continuous: it moves no more than the vertex does along n_F
        assert_true(fabs(found[i].depth - lastDepth) <= 0.005 * deltaMax + tol);
        lastDepth = found[i].depth;
      }
    } else {
      // outside f's plane the search may leave it to tracking, which keeps F's contact at its depth
      assert_true(df <= 0.0);
    }
    last = p;
    previousCount = carried(found, n, held, previous);
  }
  assert_true(inside > 250);
  pdPose b = apex_at(m, last);
  int count = 0, n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, found, CAPACITY);
  apex_depth_sum(found, n, &count);
  assert_int_equal(count, 1);
  pd_model_free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_a_held_corner_at_a_right_edge_reads_the_vertex_edge_depth),
      cmocka_unit_test(test_a_held_corner_by_a_right_edges_face_is_certified_no_farther_than_its_onset),
      cmocka_unit_test(test_a_vertex_in_an_obtuse_edges_sector_is_read_by_one_face),
      cmocka_unit_test(test_a_held_corner_at_an_acute_edge_keeps_its_face),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
