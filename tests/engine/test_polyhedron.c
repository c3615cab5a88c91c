// Polyhedra: the scene primitives (counts, structure, extents), convex hulls of point sets
// (merging, dropped points, order independence, refusal of degenerate input) and translation.
// Every structural property is checked here independently of pd_polyhedron_validate, which is
// also required to accept every primitive.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "test_random.h"

#include "polydyn/polyhedron.h"
#include "polydyn/vecmath.h"

// Face normals are normalised by one division; a unit length off by more than a few ulps is a bug.
#define NORMAL_UNIT_TOL 1e-12
// Convexity and planarity, relative to the polyhedron's size: every vertex comes from coordinates
// rounded once (cos/sin, a scale), so a plane fitted through a face deviates by ~1e-16·size;
// 1e-12 leaves four orders of margin and is still far below PD_PLANARITY_TOL_REL (1e-9).
#define PLANE_TOL_REL 1e-12
// Geodesic sphere vertices are normalised and scaled by ½: a handful of roundings of ~1.1e-16.
#define SPHERE_RADIUS_TOL 1e-15
// Prism vertices are 0.5·cos/sin (each correctly rounded to ~1 ulp) times the scale.
#define PRISM_RADIUS_TOL_REL 1e-15

#define PI 3.14159265358979323846

// ---------------------------------------------------------------- helpers


// Uniform direction by rejection from the cube [-1, 1]³.
static pdVec3 lcg_direction(lcg* g) {
  for (;;) {
    pdVec3 d = {lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1)};
    double n = pd_v3_norm(d);
    if (n > 0.1 && n <= 1.0) return pd_v3_scale(d, 1.0 / n);
  }
}

static pdVec3 vertex_average(const pdPolyhedron* p) {
  pdVec3 c = {0, 0, 0};
  for (int v = 0; v < p->vertexCount; ++v) c = pd_v3_add(c, p->vertices[v]);
  return pd_v3_scale(c, 1.0 / p->vertexCount);
}

// The header's size: largest vertex distance from the vertex average.
static double size_of(const pdPolyhedron* p) {
  pdVec3 c = vertex_average(p);
  double r = 0.0;
  for (int v = 0; v < p->vertexCount; ++v) r = fmax(r, pd_v3_norm(pd_v3_sub(p->vertices[v], c)));
  return r;
}

static pdVec3 face_centroid(const pdPolyhedron* p, int f) {
  const pdFace* face = &p->faces[f];
  pdVec3 c = {0, 0, 0};
  for (int i = 0; i < face->count; ++i) c = pd_v3_add(c, p->vertices[p->faceVertices[face->first + i]]);
  return pd_v3_scale(c, 1.0 / face->count);
}

// 1 when face f walks a → b as consecutive vertices, -1 when it walks b → a, 0 otherwise.
static int face_walks(const pdPolyhedron* p, int f, int a, int b) {
  const pdFace* face = &p->faces[f];
  const int* idx = p->faceVertices + face->first;
  for (int i = 0; i < face->count; ++i) {
    int x = idx[i], y = idx[(i + 1) % face->count];
    if (x == a && y == b) return 1;
    if (x == b && y == a) return -1;
  }
  return 0;
}

// Checks every structural property independently of pd_polyhedron_validate (which must agree).
static void check_structure(const pdPolyhedron* p, const char* label) {
  pdError why = {0};
  if (!pd_polyhedron_validate(p, &why)) fail_msg("%s: pd_polyhedron_validate: %s", label, why.message);
  if (p->vertexCount - p->edgeCount + p->faceCount != 2)
    fail_msg("%s: V-E+F = %d", label, p->vertexCount - p->edgeCount + p->faceCount);

  // every edge: f[0] walks v[0]→v[1], f[1] walks v[1]→v[0]
  for (int e = 0; e < p->edgeCount; ++e) {
    const pdEdge* edge = &p->edges[e];
    if (edge->f[0] == edge->f[1] || face_walks(p, edge->f[0], edge->v[0], edge->v[1]) != 1 ||
        face_walks(p, edge->f[1], edge->v[0], edge->v[1]) != -1)
      fail_msg("%s: edge %d (%d-%d) is not walked forward by face %d and backward by face %d", label, e, edge->v[0],
               edge->v[1], edge->f[0], edge->f[1]);
  }
  // every side of every face is exactly one edge (so the edge list is complete, without repeats)
  int sides = 0;
  for (int f = 0; f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    sides += face->count;
    for (int i = 0; i < face->count; ++i) {
      int a = p->faceVertices[face->first + i], b = p->faceVertices[face->first + (i + 1) % face->count];
      int found = 0;
      for (int e = 0; e < p->edgeCount; ++e) {
        const pdEdge* edge = &p->edges[e];
        if ((edge->v[0] == a && edge->v[1] == b && edge->f[0] == f) ||
            (edge->v[0] == b && edge->v[1] == a && edge->f[1] == f))
          ++found;
      }
      if (found != 1) fail_msg("%s: side %d-%d of face %d is in %d edges", label, a, b, f, found);
    }
  }
  if (sides != 2 * p->edgeCount) fail_msg("%s: %d face sides for %d edges", label, sides, p->edgeCount);

  pdVec3 centre = vertex_average(p);
  double tol = PLANE_TOL_REL * size_of(p);
  for (int f = 0; f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    const int* idx = p->faceVertices + face->first;
    pdVec3 n = face->normal;
    if (face->count < 3) fail_msg("%s: face %d has %d vertices", label, f, face->count);
    if (fabs(pd_v3_norm(n) - 1.0) > NORMAL_UNIT_TOL)
      fail_msg("%s: face %d normal has length 1%+.3g", label, f, pd_v3_norm(n) - 1.0);
    if (!(pd_v3_dot(n, pd_v3_sub(face_centroid(p, f), centre)) > 0.0))
      fail_msg("%s: face %d normal points inward", label, f);
    for (int i = 0; i < face->count; ++i) {
      pdVec3 a = p->vertices[idx[i]], b = p->vertices[idx[(i + 1) % face->count]],
             c = p->vertices[idx[(i + 2) % face->count]];
      if (!(pd_v3_dot(pd_v3_cross(pd_v3_sub(b, a), pd_v3_sub(c, b)), n) > 0.0))
        fail_msg("%s: face %d turns clockwise (or not at all) at its vertex %d", label, f, idx[(i + 1) % face->count]);
      double off = pd_v3_dot(n, a) - face->offset;
      if (fabs(off) > tol) fail_msg("%s: vertex %d is %.3g off the plane of its face %d", label, idx[i], off, f);
    }
    for (int v = 0; v < p->vertexCount; ++v) {
      double out = pd_v3_dot(n, p->vertices[v]) - face->offset;
      if (out > tol) fail_msg("%s: vertex %d lies %.3g in front of face %d", label, v, out, f);
    }
  }
}

static void check_counts(const pdPolyhedron* p, int v, int e, int f, const char* label) {
  if (p->vertexCount != v || p->edgeCount != e || p->faceCount != f)
    fail_msg("%s: V%d E%d F%d, expected V%d E%d F%d", label, p->vertexCount, p->edgeCount, p->faceCount, v, e, f);
}

static const double unitScale[3] = {1, 1, 1};

static const double cubeScales[][3] = {{1, 1, 1}, {0.1, 0.2, 0.3}, {2, 3, 5}, {0.01, 1, 100}, {1e-3, 1e-3, 1e-3}};
static const int prismSides[] = {3, 4, 5, 6, 7, 12, 64};
static const double prismScales[][3] = {{1, 1, 1}, {2, 3, 0.5}};
static const double tapers[] = {0.5, 1.0};

// ---------------------------------------------------------------- primitives: counts and validity

static void test_cube_is_valid_with_v8_e12_f6_at_several_scales(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof cubeScales / sizeof cubeScales[0]; ++k) {
    pdError why = {0};
    char label[64];
    snprintf(label, sizeof label, "cube %g %g %g", cubeScales[k][0], cubeScales[k][1], cubeScales[k][2]);
    pdPolyhedron p;
    if (!pd_polyhedron_cube(&p, cubeScales[k], &why)) fail_msg("%s: %s", label, why.message);
    check_counts(&p, 8, 12, 6, label);
    check_structure(&p, label);
    pd_polyhedron_free(&p);
  }
}

static void test_prism_is_valid_with_v2n_e3n_fn2(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof prismSides / sizeof prismSides[0]; ++k)
    for (size_t s = 0; s < sizeof prismScales / sizeof prismScales[0]; ++s) {
      int n = prismSides[k];
      pdError why = {0};
    char label[64];
      snprintf(label, sizeof label, "prism n=%d scale %g %g %g", n, prismScales[s][0], prismScales[s][1],
               prismScales[s][2]);
      pdPolyhedron p;
      if (!pd_polyhedron_prism(&p, n, prismScales[s], 1.0, &why)) fail_msg("%s: %s", label, why.message);
      check_counts(&p, 2 * n, 3 * n, n + 2, label);
      check_structure(&p, label);
      pd_polyhedron_free(&p);
    }
}

static void test_tprism_is_valid_with_prism_counts_for_taper_half_and_one(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof prismSides / sizeof prismSides[0]; ++k)
    for (size_t t = 0; t < sizeof tapers / sizeof tapers[0]; ++t)
      for (size_t s = 0; s < sizeof prismScales / sizeof prismScales[0]; ++s) {
        int n = prismSides[k];
        pdError why = {0};
    char label[80];
        snprintf(label, sizeof label, "tprism n=%d taper %g scale %g %g %g", n, tapers[t], prismScales[s][0],
                 prismScales[s][1], prismScales[s][2]);
        pdPolyhedron p;
        if (!pd_polyhedron_prism(&p, n, prismScales[s], tapers[t], &why)) fail_msg("%s: %s", label, why.message);
        check_counts(&p, 2 * n, 3 * n, n + 2, label);
        check_structure(&p, label);
        pd_polyhedron_free(&p);
      }
}

static void test_sphere_levels_0_to_3_are_valid_with_geodesic_counts(void** state) {
  (void)state;
  const double scales[][3] = {{1, 1, 1}, {2, 1, 0.5}};
  for (int level = 0; level <= 3; ++level)
    for (size_t s = 0; s < sizeof scales / sizeof scales[0]; ++s) {
      int four = 1;
      for (int i = 0; i < level; ++i) four *= 4;
      pdError why = {0};
    char label[64];
      snprintf(label, sizeof label, "sphere level %d scale %g %g %g", level, scales[s][0], scales[s][1], scales[s][2]);
      pdPolyhedron p;
      if (!pd_polyhedron_sphere(&p, level, scales[s], &why)) fail_msg("%s: %s", label, why.message);
      check_counts(&p, 10 * four + 2, 30 * four, 20 * four, label);
      check_structure(&p, label);
      pd_polyhedron_free(&p);
    }
}

// ---------------------------------------------------------------- primitives: extents

static void test_cube_spans_exactly_its_scale(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof cubeScales / sizeof cubeScales[0]; ++k) {
    const double* s = cubeScales[k];
    pdPolyhedron p;
    pdError why = {0};
    assert_true(pd_polyhedron_cube(&p, s, &why));
    for (int v = 0; v < p.vertexCount; ++v) {
      // every corner is exactly (±sx/2, ±sy/2, ±sz/2): halving is exact in binary
      assert_true(fabs(p.vertices[v].x) == 0.5 * s[0]);
      assert_true(fabs(p.vertices[v].y) == 0.5 * s[1]);
      assert_true(fabs(p.vertices[v].z) == 0.5 * s[2]);
      for (int w = 0; w < v; ++w)  // the 8 corners are distinct
        assert_false(p.vertices[v].x == p.vertices[w].x && p.vertices[v].y == p.vertices[w].y &&
                     p.vertices[v].z == p.vertices[w].z);
    }
    for (int axis = 0; axis < 3; ++axis) {
      double lo = INFINITY, hi = -INFINITY;
      for (int v = 0; v < p.vertexCount; ++v) {
        lo = fmin(lo, pd_v3_get(p.vertices[v], axis));
        hi = fmax(hi, pd_v3_get(p.vertices[v], axis));
      }
      assert_true(hi - lo == s[axis]);
      assert_true(hi == -lo);
    }
    pd_polyhedron_free(&p);
  }
}

static void test_prism_circumradius_is_half_scale_with_vertex_0_on_plus_x(void** state) {
  (void)state;
  const double s = 1.7, h = 0.6;  // uniform xy scale s, height h
  const double scale[3] = {s, s, h};
  for (size_t k = 0; k < sizeof prismSides / sizeof prismSides[0]; ++k)
    for (size_t t = 0; t < sizeof tapers / sizeof tapers[0]; ++t) {
      int n = prismSides[k];
      double taper = tapers[t];
      pdPolyhedron p;
      pdError why = {0};
      assert_true(pd_polyhedron_prism(&p, n, scale, taper, &why));
      assert_int_equal(p.vertexCount, 2 * n);
      // vertex 0 is the first bottom corner, on +x
      assert_true(p.vertices[0].x == 0.5 * s && p.vertices[0].y == 0.0 && p.vertices[0].z == -0.5 * h);
      int bottom = 0, top = 0;
      for (int v = 0; v < p.vertexCount; ++v) {
        pdVec3 x = p.vertices[v];
        double r = hypot(x.x, x.y);
        if (x.z == -0.5 * h) {
          ++bottom;
          if (fabs(r - 0.5 * s) > PRISM_RADIUS_TOL_REL * s) fail_msg("n=%d bottom vertex %d at radius %.17g", n, v, r);
        } else if (x.z == 0.5 * h) {
          ++top;
          if (fabs(r - 0.5 * s * taper) > PRISM_RADIUS_TOL_REL * s)
            fail_msg("n=%d taper %g top vertex %d at radius %.17g", n, taper, v, r);
        } else {
          fail_msg("n=%d vertex %d at z=%.17g, not ±h/2", n, v, x.z);
        }
      }
      assert_int_equal(bottom, n);
      assert_int_equal(top, n);
      pd_polyhedron_free(&p);
    }
}

static void test_sphere_vertices_lie_at_radius_half(void** state) {
  (void)state;
  for (int level = 0; level <= 3; ++level) {
    pdPolyhedron p;
    pdError why = {0};
    assert_true(pd_polyhedron_sphere(&p, level, unitScale, &why));
    for (int v = 0; v < p.vertexCount; ++v) {
      double r = pd_v3_norm(p.vertices[v]);
      if (fabs(r - 0.5) > SPHERE_RADIUS_TOL) fail_msg("level %d vertex %d at radius 0.5%+.3g", level, v, r - 0.5);
    }
    pd_polyhedron_free(&p);
  }
}

// ---------------------------------------------------------------- hulls

static bool same_point(pdVec3 a, const double* b) { return a.x == b[0] && a.y == b[1] && a.z == b[2]; }

static void test_hull_of_box_with_face_edge_and_interior_points_is_the_box(void** state) {
  (void)state;
  const double hx = 0.5, hy = 1.25, hz = 0.75;  // half extents (exact binary fractions)
  enum { maxPoints = 200 };
  double pts[3 * maxPoints];
  int n = 0;
  lcg g = {12345};
  // interior points and edge midpoints first, so the corners are not the lowest input indices
  for (int i = 0; i < 20; ++i, ++n) {
    pts[3 * n] = lcg_range(&g, -hx, hx) * 0.99, pts[3 * n + 1] = lcg_range(&g, -hy, hy) * 0.99;
    pts[3 * n + 2] = lcg_range(&g, -hz, hz) * 0.99;
  }
  for (int i = 0; i < 8; ++i)  // the 12 edges join corners i < j differing in one bit: midpoint and a third
    for (int bit = 1; bit < 8; bit <<= 1) {
      int j = i | bit;
      if (j == i) continue;
      for (int k = 0; k < 2; ++k, ++n) {
        double along = k == 0 ? 0.5 : 1.0 / 3.0;
        double a[3] = {(i & 1) ? hx : -hx, (i & 2) ? hy : -hy, (i & 4) ? hz : -hz};
        double b[3] = {(j & 1) ? hx : -hx, (j & 2) ? hy : -hy, (j & 4) ? hz : -hz};
        for (int c = 0; c < 3; ++c) pts[3 * n + c] = a[c] + along * (b[c] - a[c]);
      }
    }
  for (int face = 0; face < 6; ++face)  // face centres and 3 random points on each face
    for (int k = 0; k < 4; ++k, ++n) {
      double* q = pts + 3 * n;
      double u = k == 0 ? 0.0 : lcg_range(&g, -1, 1), w = k == 0 ? 0.0 : lcg_range(&g, -1, 1);
      double sign = (face & 1) ? 1.0 : -1.0;
      if (face / 2 == 0) q[0] = sign * hx, q[1] = u * hy, q[2] = w * hz;
      if (face / 2 == 1) q[0] = u * hx, q[1] = sign * hy, q[2] = w * hz;
      if (face / 2 == 2) q[0] = u * hx, q[1] = w * hy, q[2] = sign * hz;
    }
  int firstCorner = n;
  for (int i = 0; i < 8; ++i, ++n) {
    pts[3 * n] = (i & 1) ? hx : -hx, pts[3 * n + 1] = (i & 2) ? hy : -hy, pts[3 * n + 2] = (i & 4) ? hz : -hz;
  }
  assert_true(n <= maxPoints);

  pdPolyhedron p;
  pdError why = {0};
  if (!pd_polyhedron_hull(&p, pts, n, &why)) fail_msg("hull: %s", why.message);
  check_counts(&p, 8, 12, 6, "box hull");
  check_structure(&p, "box hull");
  for (int v = 0; v < p.vertexCount; ++v) {  // the vertices are the 8 corners, nothing else
    bool corner = false;
    for (int i = firstCorner; i < n; ++i) corner = corner || same_point(p.vertices[v], pts + 3 * i);
    if (!corner) fail_msg("vertex %d (%g %g %g) is not a corner", v, p.vertices[v].x, p.vertices[v].y, p.vertices[v].z);
  }
  for (int f = 0; f < p.faceCount; ++f) assert_int_equal(p.faces[f].count, 4);
  pd_polyhedron_free(&p);
}

enum { ballPoints = 300 };

// Points on (the first third) and strictly inside the sphere of radius 0.5 about `centre`.
static void ball_points(double* pts, int n, uint64_t seed) {
  lcg g = {seed};
  for (int i = 0; i < n; ++i) {
    double r = i % 3 == 0 ? 0.5 : 0.5 * lcg_range(&g, 0.0, 0.999);
    pdVec3 d = pd_v3_scale(lcg_direction(&g), r);
    pts[3 * i] = d.x, pts[3 * i + 1] = d.y, pts[3 * i + 2] = d.z;
  }
}

static void test_hull_of_random_ball_points_is_valid_and_contains_them(void** state) {
  (void)state;
  double* pts = malloc(sizeof(double) * 3 * ballPoints);
  assert_non_null(pts);
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    ball_points(pts, ballPoints, seed);
    pdPolyhedron p;
    pdError why = {0};
    char label[32];
    snprintf(label, sizeof label, "ball seed %d", (int)seed);
    if (!pd_polyhedron_hull(&p, pts, ballPoints, &why)) fail_msg("%s: %s", label, why.message);
    check_structure(&p, label);
    double tol = PLANE_TOL_REL * size_of(&p);
    for (int i = 0; i < ballPoints; ++i)
      for (int f = 0; f < p.faceCount; ++f) {
        pdVec3 x = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]};
        double out = pd_v3_dot(p.faces[f].normal, x) - p.faces[f].offset;
        if (out > tol) fail_msg("%s: input point %d lies %.3g outside face %d", label, i, out, f);
      }
    // every vertex is an input point, and every point on the sphere (a third of them) is a vertex
    int onSphere = 0;
    for (int v = 0; v < p.vertexCount; ++v) {
      bool input = false;
      for (int i = 0; i < ballPoints && !input; ++i) input = same_point(p.vertices[v], pts + 3 * i);
      assert_true(input);
    }
    for (int i = 0; i < ballPoints; i += 3) {
      for (int v = 0; v < p.vertexCount; ++v)
        if (same_point(p.vertices[v], pts + 3 * i)) {
          ++onSphere;
          break;
        }
    }
    assert_int_equal(onSphere, (ballPoints + 2) / 3);
    pd_polyhedron_free(&p);
  }
  free(pts);
}

static int compare_vec3(const void* a, const void* b) {
  const pdVec3* x = a;
  const pdVec3* y = b;
  for (int k = 0; k < 3; ++k) {
    double u = pd_v3_get(*x, k), w = pd_v3_get(*y, k);
    if (u < w) return -1;
    if (u > w) return 1;
  }
  return 0;
}

static void test_hull_of_permuted_points_has_the_same_vertex_set(void** state) {
  (void)state;
  double* pts = malloc(sizeof(double) * 3 * ballPoints);
  double* shuffled = malloc(sizeof(double) * 3 * ballPoints);
  assert_non_null(pts);
  assert_non_null(shuffled);
  ball_points(pts, ballPoints, 77);
  memcpy(shuffled, pts, sizeof(double) * 3 * ballPoints);
  lcg g = {99};
  for (int i = ballPoints - 1; i > 0; --i) {  // Fisher–Yates
    int j = (int)(lcg_uniform(&g) * (i + 1));
    for (int k = 0; k < 3; ++k) {
      double t = shuffled[3 * i + k];
      shuffled[3 * i + k] = shuffled[3 * j + k];
      shuffled[3 * j + k] = t;
    }
  }
  pdPolyhedron a, b;
  pdError why = {0};
  if (!pd_polyhedron_hull(&a, pts, ballPoints, &why)) fail_msg("%s", why.message);
  if (!pd_polyhedron_hull(&b, shuffled, ballPoints, &why)) fail_msg("%s", why.message);
  check_counts(&b, a.vertexCount, a.edgeCount, a.faceCount, "permuted hull");
  qsort(a.vertices, (size_t)a.vertexCount, sizeof *a.vertices, compare_vec3);
  qsort(b.vertices, (size_t)b.vertexCount, sizeof *b.vertices, compare_vec3);
  for (int v = 0; v < a.vertexCount; ++v) assert_int_equal(compare_vec3(&a.vertices[v], &b.vertices[v]), 0);
  pd_polyhedron_free(&a);
  pd_polyhedron_free(&b);
  free(pts);
  free(shuffled);
}

static void expect_refused(const double* pts, int n, const char* label) {
  pdPolyhedron p;
  memset(&p, 0xff, sizeof p);  // garbage in: the function must not rely on it
  pdError why = {0};
  if (pd_polyhedron_hull(&p, pts, n, &why)) {
    pd_polyhedron_free(&p);
    fail_msg("%s: a degenerate hull was accepted", label);
  }
  if (why.message[0] == '\0') fail_msg("%s: refused without a reason", label);
  assert_null(p.vertices);  // nothing left allocated or dangling
  assert_null(p.edges);
  assert_null(p.faces);
  assert_null(p.faceVertices);
  pd_polyhedron_free(&p);  // freeing a refused hull is harmless
}

static void test_hull_refuses_degenerate_point_sets_with_a_reason(void** state) {
  (void)state;
  const double coplanar4[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const double coplanarMany[] = {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1, 0.5, 0.5, 1, 0.2, 0.7, 1, 0.9, 0.1, 1};
  const double tilted4[] = {0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1, 0};  // on the plane x = z
  const double three[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const double collinear[] = {0, 0, 0, 1, 2, 3, 2, 4, 6, -1, -2, -3, 0.5, 1, 1.5};
  const double identical[] = {0.3, -0.2, 0.1, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1};
  const double withNan[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN, 1, 1, 1};
  const double withInf[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, INFINITY, 1, 1};
  expect_refused(coplanar4, 4, "4 coplanar points");
  expect_refused(coplanarMany, 7, "7 coplanar points");
  expect_refused(tilted4, 4, "4 points on a tilted plane");
  expect_refused(three, 3, "3 points");
  expect_refused(collinear, 5, "collinear points");
  expect_refused(identical, 5, "identical points");
  expect_refused(withNan, 5, "a NaN coordinate");
  expect_refused(withInf, 5, "an infinite coordinate");
  expect_refused(NULL, 0, "no points");
}

// Points within the planarity tolerance of the box (1e-12 of its size: far below
// PD_PLANARITY_TOL_REL, far above roundoff) belong to it: a corner doubled at that distance is one
// vertex, a point that far out of a face is on the face, and the result is the box again.
#define NEAR_BOX_OFFSET_REL 1e-12

static void test_hull_merges_points_within_tolerance_into_the_box(void** state) {
  (void)state;
  const double h = 0.5, size = sqrt(3.0) * h;  // unit box: the header's size is its half-diagonal
  const double d = NEAR_BOX_OFFSET_REL * size;
  enum { variants = 3 };
  for (int variant = 0; variant < variants; ++variant) {
    double pts[3 * 20];
    int n = 0;
    for (int i = 0; i < 8; ++i, ++n)
      pts[3 * n] = (i & 1) ? h : -h, pts[3 * n + 1] = (i & 2) ? h : -h, pts[3 * n + 2] = (i & 4) ? h : -h;
    if (variant == 0 || variant == 2)  // every corner doubled, pushed out by d·(1, -0.7, 0.3)
      for (int i = 0; i < 8; ++i, ++n)
        pts[3 * n] = pts[3 * i] + d, pts[3 * n + 1] = pts[3 * i + 1] - 0.7 * d,
        pts[3 * n + 2] = pts[3 * i + 2] + 0.3 * d;
    if (variant == 1 || variant == 2)  // a point d outside the top face, away from its centre
      pts[3 * n] = 0.1, pts[3 * n + 1] = 0.2, pts[3 * n + 2] = h + d, ++n;
    pdPolyhedron p;
    pdError why = {0};
    char label[32];
    snprintf(label, sizeof label, "near box variant %d", variant);
    if (!pd_polyhedron_hull(&p, pts, n, &why)) fail_msg("%s: refused: %s", label, why.message);
    check_counts(&p, 8, 12, 6, label);
    check_structure(&p, label);
    pd_polyhedron_free(&p);
  }
}

// pd_polyhedron_validate refuses each kind of damage to a valid polyhedron.
static void test_validate_refuses_damaged_polyhedra(void** state) {
  (void)state;
  enum { kinds = 9 };
  const char* names[kinds] = {"edge faces swapped", "edge vertices swapped", "face wound clockwise",
                              "normal flipped",     "vertex pushed out",     "edge count off",
                              "edge repeated",      "edge repeated reversed", "plane moved outward"};
  for (int kind = 0; kind < kinds; ++kind) {
    pdPolyhedron p;
    pdError why = {0};
    assert_true(pd_polyhedron_prism(&p, 5, (const double[3]){1, 1, 1}, 0.5, &why));
    assert_true(pd_polyhedron_validate(&p, &why));
    switch (kind) {
      case 0: {
        int t = p.edges[3].f[0];
        p.edges[3].f[0] = p.edges[3].f[1];
        p.edges[3].f[1] = t;
        break;
      }
      case 1: {
        int t = p.edges[3].v[0];
        p.edges[3].v[0] = p.edges[3].v[1];
        p.edges[3].v[1] = t;
        break;
      }
      case 2: {
        int* idx = p.faceVertices + p.faces[1].first;
        for (int i = 0, j = p.faces[1].count - 1; i < j; ++i, --j) {
          int t = idx[i];
          idx[i] = idx[j];
          idx[j] = t;
        }
        break;
      }
      case 3:
        p.faces[2].normal = pd_v3_scale(p.faces[2].normal, -1.0);
        p.faces[2].offset = -p.faces[2].offset;
        break;
      case 4:
        p.vertices[0] = pd_v3_scale(p.vertices[0], 1.01);
        break;
      case 5:
        p.edgeCount -= 1;
        break;
      case 6:
        p.edges[4] = p.edges[3];
        break;
      case 7:  // the same edge written the other way round is still the same edge
        p.edges[4] = (pdEdge){{p.edges[3].v[1], p.edges[3].v[0]}, {p.edges[3].f[1], p.edges[3].f[0]}};
        break;
      case 8:  // still convex (every vertex behind it), but no longer through its face's vertices
        p.faces[2].offset += 1e-6;
        break;
    }
    why.message[0] = '\0';
    if (pd_polyhedron_validate(&p, &why)) fail_msg("%s: accepted", names[kind]);
    if (why.message[0] == '\0') fail_msg("%s: refused without a reason", names[kind]);
    pd_polyhedron_free(&p);
  }
}

// ---------------------------------------------------------------- translation

static void test_translate_moves_vertices_and_keeps_planes_consistent(void** state) {
  (void)state;
  const pdVec3 shifts[] = {{10, -20, 30}, {-0.125, 0.3, 1e-3}, {1e3, 1e3, -1e3}};
  for (size_t s = 0; s < sizeof shifts / sizeof shifts[0]; ++s) {
    pdPolyhedron p, q;
    pdError why = {0};
    assert_true(pd_polyhedron_prism(&p, 7, (const double[3]){1.3, 0.9, 2.1}, 0.5, &why));
    assert_true(pd_polyhedron_prism(&q, 7, (const double[3]){1.3, 0.9, 2.1}, 0.5, &why));
    pd_polyhedron_translate(&q, shifts[s]);
    double reach = 0.0;  // the largest coordinate magnitude after the shift: the scale of roundoff
    for (int v = 0; v < q.vertexCount; ++v) {
      pdVec3 expected = pd_v3_add(p.vertices[v], shifts[s]);
      assert_true(q.vertices[v].x == expected.x && q.vertices[v].y == expected.y && q.vertices[v].z == expected.z);
      reach = fmax(reach, pd_v3_norm(q.vertices[v]));
    }
    assert_int_equal(q.faceCount, p.faceCount);
    for (int f = 0; f < q.faceCount; ++f) {
      const pdFace* face = &q.faces[f];
      assert_true(face->normal.x == p.faces[f].normal.x && face->normal.y == p.faces[f].normal.y &&
                  face->normal.z == p.faces[f].normal.z);
      for (int i = 0; i < face->count; ++i) {
        double off = pd_v3_dot(face->normal, q.vertices[q.faceVertices[face->first + i]]) - face->offset;
        if (fabs(off) > PLANE_TOL_REL * reach) fail_msg("shift %zu: face %d vertex off its plane by %.3g", s, f, off);
      }
    }
    if (!pd_polyhedron_validate(&q, &why)) fail_msg("shift %zu: %s", s, why.message);
    pd_polyhedron_free(&p);
    pd_polyhedron_free(&q);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cube_is_valid_with_v8_e12_f6_at_several_scales),
      cmocka_unit_test(test_prism_is_valid_with_v2n_e3n_fn2),
      cmocka_unit_test(test_tprism_is_valid_with_prism_counts_for_taper_half_and_one),
      cmocka_unit_test(test_sphere_levels_0_to_3_are_valid_with_geodesic_counts),
      cmocka_unit_test(test_cube_spans_exactly_its_scale),
      cmocka_unit_test(test_prism_circumradius_is_half_scale_with_vertex_0_on_plus_x),
      cmocka_unit_test(test_sphere_vertices_lie_at_radius_half),
      cmocka_unit_test(test_hull_of_box_with_face_edge_and_interior_points_is_the_box),
      cmocka_unit_test(test_hull_of_random_ball_points_is_valid_and_contains_them),
      cmocka_unit_test(test_hull_of_permuted_points_has_the_same_vertex_set),
      cmocka_unit_test(test_hull_refuses_degenerate_point_sets_with_a_reason),
      cmocka_unit_test(test_hull_merges_points_within_tolerance_into_the_box),
      cmocka_unit_test(test_validate_refuses_damaged_polyhedra),
      cmocka_unit_test(test_translate_moves_vertices_and_keeps_planes_consistent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
