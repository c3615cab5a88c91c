// Interference (separating-axis test with Gauss-map pruning): against the brute-force SAT over every
// face normal and every edge-pair cross product, and against the faces of the Minkowski difference
// built by qhull, on 20 000 random pairs posed near touching; closed cases (face–face, crossed edges,
// vertex on face) with known depths; the cache never changing a verdict (nor, in PD_SAT_MIN_DEPTH mode,
// anything); the edge convention the Gauss-map test relies on.
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

#include "test_random.h"

#include "interference.h"
#include "polydyn/polyhedron.h"
#include "polydyn/vecmath.h"

#define PI 3.14159265358979323846

// Pruned and brute-force SAT evaluate the same axes with different arithmetic (A's frame and one edge
// vertex each, against world coordinates and full support scans): a few roundings of ~1e-16 × the
// pair's scale (radii plus distance from the origin). 1e-12 leaves three orders of margin.
#define DEPTH_TOL_REL 1e-12
// The Minkowski-difference reference comes from qhull, which merges facets coplanar to within
// PD_PLANARITY_TOL_REL (1e-9) × size and refits planes through the merged vertices. (The pruned SAT also
// skips edge pairs parallel to PD_SAT_PARALLEL_TOL, 1e-8 rad, whose sliver faces could move the depth by
// ~1e-8 × edge length; random rotations bring two edges that close with probability ~1e-16 per pair.)
#define HULL_TOL_REL 1e-9
// Closed cases: exact geometry with coordinates of order 1 (or 100 when moved away from the origin).
#define CLOSED_TOL 1e-12

// ---------------------------------------------------------------- shapes and poses

enum { SHAPE_KINDS = 5, POOL = 100 };

typedef struct shape {
  pdPolyhedron p;
  double radius;  // largest vertex distance from the body origin (the vertex average)
  char label[48];
} shape;

static pdVec3 vertex_average(const pdPolyhedron* p) {
  pdVec3 c = {0, 0, 0};
  for (int v = 0; v < p->vertexCount; ++v) c = pd_v3_add(c, p->vertices[v]);
  return pd_v3_scale(c, 1.0 / p->vertexCount);
}

// Shape `kind`: 0 cube, 1 prism (3..12 sides), 2 tapered prism, 3 geodesic sphere (level 0..2),
// 4 hull of 6..30 random points; random scales; origin moved to the vertex average.
static void make_shape(lcg* g, int kind, int index, shape* s) {
  pdError why = {0};
  double scale[3] = {lcg_range(g, 0.3, 2.0), lcg_range(g, 0.3, 2.0), lcg_range(g, 0.3, 2.0)};
  bool ok = false;
  int sides = 3 + (int)(lcg_uniform(g) * 10);
  switch (kind) {
    case 0:
      ok = pd_polyhedron_cube(&s->p, scale, &why);
      snprintf(s->label, sizeof s->label, "cube");
      break;
    case 1:
      ok = pd_polyhedron_prism(&s->p, sides, scale, 1.0, &why);
      snprintf(s->label, sizeof s->label, "prism %d", sides);
      break;
    case 2: {
      double taper = lcg_range(g, 0.1, 0.95);
      ok = pd_polyhedron_prism(&s->p, sides, scale, taper, &why);
      snprintf(s->label, sizeof s->label, "tprism %d taper %.2f", sides, taper);
      break;
    }
    case 3: {
      // levels 0, 1, 0, 1, 2: fewer of the 162-vertex level-2 spheres, whose brute-force SAT (480² edge
      // pairs × 324 vertices for two of them) would otherwise take most of the test's time
      static const int levels[5] = {0, 1, 0, 1, 2};
      int level = levels[index % 5];
      ok = pd_polyhedron_sphere(&s->p, level, scale, &why);
      snprintf(s->label, sizeof s->label, "sphere level %d", level);
      break;
    }
    default: {
      int count = 6 + (int)(lcg_uniform(g) * 25);
      double pts[3 * 30];
      for (int i = 0; i < count; ++i)
        for (int k = 0; k < 3; ++k) pts[3 * i + k] = scale[k] * lcg_range(g, -0.5, 0.5);
      ok = pd_polyhedron_hull(&s->p, pts, count, &why);
      snprintf(s->label, sizeof s->label, "hull of %d points", count);
      break;
    }
  }
  if (!ok) fail_msg("shape %d (%s): %s", index, s->label, why.message);
  pd_polyhedron_translate(&s->p, pd_v3_scale(vertex_average(&s->p), -1.0));
  s->radius = 0.0;
  for (int v = 0; v < s->p.vertexCount; ++v) s->radius = fmax(s->radius, pd_v3_norm(s->p.vertices[v]));
}

static shape* make_pool(uint64_t seed) {
  lcg g = {seed};
  shape* pool = calloc(POOL, sizeof *pool);
  assert_non_null(pool);
  for (int i = 0; i < POOL; ++i) make_shape(&g, i % SHAPE_KINDS, i / SHAPE_KINDS, &pool[i]);
  return pool;
}

static void free_pool(shape* pool) {
  for (int i = 0; i < POOL; ++i) pd_polyhedron_free(&pool[i].p);
  free(pool);
}

static pdVec3 lcg_direction(lcg* g) {
  for (;;) {
    pdVec3 d = {lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1)};
    double n = pd_v3_norm(d);
    if (n > 0.1 && n <= 1.0) return pd_v3_scale(d, 1.0 / n);
  }
}

// Uniform random rotation (a uniform point of the 4-ball's shell, by rejection).
static pdMat3 lcg_rotation(lcg* g) {
  for (;;) {
    pdQuat q = {lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1)};
    double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (n > 0.1 && n <= 1.0) return pd_quat_to_mat3(pd_quat_normalize(q));
  }
}

typedef struct pose {
  pdVec3 x;
  pdMat3 R;
} pose;

static bool interferes(const shape* a, const pose* pa, const shape* b, const pose* pb) {
  pdSatResult r;
  return pd_interference(&a->p, pa->x, &pa->R, &b->p, pb->x, &pb->R, PD_SAT_FIRST_SEPARATING, NULL, &r);
}

// B's position along direction w from A at which the two touch. Newton's method on the minimum depth
// as a function of the distance s, min over the Minkowski faces of (o_f − s·u_f·w), which is concave
// and piecewise linear: started where the bodies are apart it steps monotonically onto the root, in a
// few iterations (each step zeroes the best separating axis, which separates all the way there, so it
// never overshoots). A probe just short of it and a bisection on the verdict finish.
static double touching_distance(const shape* a, const pose* pa, const shape* b, pose* pb, pdVec3 w) {
  double lo = 0.0, hi = 1.01 * (a->radius + b->radius);  // overlapping at lo (both contain their origin)
  double s = hi;
  pdSatCache cache = {PD_SAT_NONE, -1, -1, {0, 0, 0}};
  for (int i = 0; i < 40; ++i) {
    pb->x = pd_v3_muladd(pa->x, s, w);
    pdSatResult r;
    pd_interference(&a->p, pa->x, &pa->R, &b->p, pb->x, &pb->R, PD_SAT_MIN_DEPTH, &cache, &r);
    if (!r.separated) {
      lo = fmax(lo, s);
      break;
    }
    hi = fmin(hi, s);
    double slope = pd_v3_dot(r.axis, w);  // d(overlap along the axis)/ds = −slope
    if (slope < 1e-3 || -r.depth < 1e-14 * hi) break;
    s += r.depth / slope;
  }
  // to 1e-13 relative, far below the smallest offset from touching (1e-10 × radii)
  double probe = hi * (1.0 - 1e-13);  // Newton approaches from the far side
  pb->x = pd_v3_muladd(pa->x, probe, w);
  if (probe > lo && interferes(a, pa, b, pb)) lo = probe;
  for (int i = 0; i < 80 && hi - lo > 1.01e-13 * hi; ++i) {
    double mid = 0.5 * (lo + hi);
    pb->x = pd_v3_muladd(pa->x, mid, w);
    if (interferes(a, pa, b, pb))
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

// A random pose pair: A anywhere in [-1, 1]³, B along a random direction, either at a random
// distance (a quarter of the pairs) or within ±(radii)·10^U(-10, -1) of touching.
static void random_poses(lcg* g, const shape* a, pose* pa, const shape* b, pose* pb) {
  pa->x = pd_v3(lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1));
  pa->R = lcg_rotation(g);
  pb->R = lcg_rotation(g);
  pdVec3 w = lcg_direction(g);
  double sum = a->radius + b->radius, s;
  if (lcg_uniform(g) < 0.25) {
    s = sum * lcg_range(g, 0.2, 1.05);
  } else {
    double t = touching_distance(a, pa, b, pb, w);
    double delta = sum * pow(10.0, lcg_range(g, -10.0, -1.0));
    s = lcg_uniform(g) < 0.5 ? t - delta : t + delta;
  }
  pb->x = pd_v3_muladd(pa->x, s, w);
}

// ---------------------------------------------------------------- references

typedef struct worldShape {
  int vertexCount;
  pdVec3* v;  // world vertices
} worldShape;

static worldShape world_of(const shape* s, const pose* p) {
  worldShape w = {s->p.vertexCount, malloc((size_t)s->p.vertexCount * sizeof(pdVec3))};
  assert_non_null(w.v);
  for (int i = 0; i < w.vertexCount; ++i) w.v[i] = pd_v3_add(p->x, pd_mat3_mulv(&p->R, s->p.vertices[i]));
  return w;
}

// min and max of u·v over the vertices (two interleaved chains: this is the brute force's inner loop)
static void project(const worldShape* w, pdVec3 u, double* lo, double* hi) {
  double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
  int i = 0;
  for (; i + 1 < w->vertexCount; i += 2) {
    double d0 = pd_v3_dot(u, w->v[i]), d1 = pd_v3_dot(u, w->v[i + 1]);
    lo0 = d0 < lo0 ? d0 : lo0;
    hi0 = d0 > hi0 ? d0 : hi0;
    lo1 = d1 < lo1 ? d1 : lo1;
    hi1 = d1 > hi1 ? d1 : hi1;
  }
  if (i < w->vertexCount) {
    double d = pd_v3_dot(u, w->v[i]);
    lo0 = d < lo0 ? d : lo0;
    hi0 = d > hi0 ? d : hi0;
  }
  *lo = lo0 < lo1 ? lo0 : lo1;
  *hi = hi0 > hi1 ? hi0 : hi1;
}

// overlap along u from A to B (the header's definition), by projecting world vertices
static double overlap_along(const worldShape* A, const worldShape* B, pdVec3 u) {
  double aLo, aHi, bLo, bHi;
  project(A, u, &aLo, &aHi);
  project(B, u, &bLo, &bHi);
  return aHi - bLo;
}

// Unoriented axis: the smaller overlap of its two orientations.
static double axis_depth(const worldShape* A, const worldShape* B, pdVec3 u) {
  double aLo, aHi, bLo, bHi;
  project(A, u, &aLo, &aHi);
  project(B, u, &bLo, &bHi);
  return fmin(aHi - bLo, bHi - aLo);
}

// The brute-force SAT: every face normal of A and of B, every edge-pair cross product (no Gauss-map
// pruning; parallel pairs skipped by the same rule, as they have no direction), both orientations.
static double brute_sat(const shape* a, const pose* pa, const shape* b, const pose* pb) {
  worldShape A = world_of(a, pa), B = world_of(b, pb);
  double depth = INFINITY;
  for (int f = 0; f < a->p.faceCount; ++f)
    depth = fmin(depth, axis_depth(&A, &B, pd_mat3_mulv(&pa->R, a->p.faces[f].normal)));
  for (int f = 0; f < b->p.faceCount; ++f)
    depth = fmin(depth, axis_depth(&A, &B, pd_mat3_mulv(&pb->R, b->p.faces[f].normal)));
  for (int i = 0; i < a->p.edgeCount; ++i) {
    pdVec3 ea = pd_v3_sub(A.v[a->p.edges[i].v[1]], A.v[a->p.edges[i].v[0]]);
    for (int j = 0; j < b->p.edgeCount; ++j) {
      pdVec3 eb = pd_v3_sub(B.v[b->p.edges[j].v[1]], B.v[b->p.edges[j].v[0]]);
      pdVec3 u = pd_v3_cross(ea, eb);
      double len = pd_v3_norm(u);
      if (!(len >= PD_SAT_PARALLEL_TOL * pd_v3_norm(ea) * pd_v3_norm(eb))) continue;
      depth = fmin(depth, axis_depth(&A, &B, pd_v3_scale(u, 1.0 / len)));
    }
  }
  free(A.v);
  free(B.v);
  return depth;
}

// The faces of the Minkowski difference B ⊖ A = {b − a}, built by qhull from all vertex differences: a
// face with outward normal n and offset o gives overlap o along u = −n, so depth = min o (both when
// separated and when overlapping). Returns false when the pair is too large for this reference.
static bool minkowski_depth(const shape* a, const pose* pa, const shape* b, const pose* pb, double* depth) {
  int n = a->p.vertexCount * b->p.vertexCount;
  if (n > 4000) return false;
  worldShape A = world_of(a, pa), B = world_of(b, pb);
  double* pts = malloc((size_t)n * 3 * sizeof *pts);
  assert_non_null(pts);
  int k = 0;
  for (int i = 0; i < A.vertexCount; ++i)
    for (int j = 0; j < B.vertexCount; ++j) {
      pdVec3 d = pd_v3_sub(B.v[j], A.v[i]);
      pts[k++] = d.x;
      pts[k++] = d.y;
      pts[k++] = d.z;
    }
  pdPolyhedron D;
  pdError why = {0};
  if (!pd_polyhedron_hull(&D, pts, n, &why)) fail_msg("Minkowski hull: %s", why.message);
  *depth = INFINITY;
  for (int f = 0; f < D.faceCount; ++f) *depth = fmin(*depth, D.faces[f].offset);
  pd_polyhedron_free(&D);
  free(pts);
  free(A.v);
  free(B.v);
  return true;
}

static double pair_scale(const shape* a, const pose* pa, const shape* b, const pose* pb) {
  return a->radius + b->radius + pd_v3_norm(pa->x) + pd_v3_norm(pb->x);
}

static pdSatResult sat(const shape* a, const pose* pa, const shape* b, const pose* pb, pdSatMode mode,
                       pdSatCache* cache) {
  pdSatResult r;
  bool hit = pd_interference(&a->p, pa->x, &pa->R, &b->p, pb->x, &pb->R, mode, cache, &r);
  assert_true(hit == !r.separated);
  assert_true(r.separated == (r.depth < 0.0));
  assert_true(isfinite(r.depth));
  assert_true(fabs(pd_v3_norm(r.axis) - 1.0) < 1e-12);
  return r;
}

// The reported axis really has the reported overlap, oriented from A to B.
static void check_axis(const shape* a, const pose* pa, const shape* b, const pose* pb, const pdSatResult* r, double tol,
                       double* maxDiff) {
  worldShape A = world_of(a, pa), B = world_of(b, pb);
  double d = overlap_along(&A, &B, r->axis);
  *maxDiff = fmax(*maxDiff, fabs(d - r->depth));
  if (fabs(d - r->depth) > tol)
    fail_msg("%s / %s: axis (%g %g %g) kind %d has overlap %.17g, reported %.17g", a->label, b->label, r->axis.x,
             r->axis.y, r->axis.z, r->kind, d, r->depth);
  free(A.v);
  free(B.v);
}

static bool same_result(const pdSatResult* x, const pdSatResult* y) {
  return x->separated == y->separated && x->depth == y->depth && x->axis.x == y->axis.x && x->axis.y == y->axis.y &&
         x->axis.z == y->axis.z && x->kind == y->kind && x->a == y->a && x->b == y->b;
}

// ---------------------------------------------------------------- tests

static void test_edge_faces_follow_the_convention_the_gauss_map_test_uses(void** state) {
  (void)state;
  // interference.c assumes n_f0 × n_f1 points along e = v1 − v0 for every edge
  shape* pool = make_pool(0xed9eull);
  for (int s = 0; s < POOL; ++s) {
    const pdPolyhedron* p = &pool[s].p;
    for (int e = 0; e < p->edgeCount; ++e) {
      const pdEdge* edge = &p->edges[e];
      pdVec3 c = pd_v3_cross(p->faces[edge->f[0]].normal, p->faces[edge->f[1]].normal);
      pdVec3 d = pd_v3_sub(p->vertices[edge->v[1]], p->vertices[edge->v[0]]);
      if (!(pd_v3_dot(c, d) > 0.0)) fail_msg("%s: edge %d: n_f0 x n_f1 is against v1 - v0", pool[s].label, e);
    }
  }
  free_pool(pool);
}

static void test_pruned_sat_equals_brute_force_on_20000_random_pairs_near_touching(void** state) {
  (void)state;
  enum { PAIRS = 20000 };
  shape* pool = make_pool(0x5a7ull);
  lcg g = {0x1e9a11ull};
  long overlapping = 0, separated = 0, bruteSeparatesMore = 0, hullChecked = 0, nearZero = 0;
  long long minkowski = 0, edgePairs = 0;
  double maxOverlapDiff = 0.0, maxSeparatedExcess = 0.0, maxHullDiff = 0.0, maxAxisDiff = 0.0;
  for (int n = 0; n < PAIRS; ++n) {
    const shape* a = &pool[(int)(lcg_uniform(&g) * POOL)];
    const shape* b = &pool[(int)(lcg_uniform(&g) * POOL)];
    pose pa, pb;
    random_poses(&g, a, &pa, b, &pb);
    double scale = pair_scale(a, &pa, b, &pb), tol = DEPTH_TOL_REL * scale;
    pdSatResult r = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, NULL);
    pdSatResult fast = sat(a, &pa, b, &pb, PD_SAT_FIRST_SEPARATING, NULL);
    double brute = brute_sat(a, &pa, b, &pb);
    if (fabs(brute) <= tol) ++nearZero;
    if ((brute < 0.0) != r.separated || fast.separated != r.separated)
      fail_msg("pair %d (%s / %s): pruned %s (depth %.17g), brute %s (depth %.17g), first-separating %s", n, a->label,
               b->label, r.separated ? "separated" : "overlapping", r.depth, brute < 0.0 ? "separated" : "overlapping",
               brute, fast.separated ? "separated" : "overlapping");
    if (!r.separated) {
      ++overlapping;
      maxOverlapDiff = fmax(maxOverlapDiff, fabs(r.depth - brute));
      if (fabs(r.depth - brute) > tol)
        fail_msg("pair %d (%s / %s): overlapping, depth %.17g vs brute %.17g", n, a->label, b->label, r.depth, brute);
      assert_true(same_result(&r, &fast));  // overlapping: every axis evaluated in both modes
    } else {
      ++separated;
      // brute force has more axes: its best separation can only be larger (more negative depth)
      if (brute > r.depth + tol)
        fail_msg("pair %d (%s / %s): separated, depth %.17g, brute %.17g", n, a->label, b->label, r.depth, brute);
      maxSeparatedExcess = fmax(maxSeparatedExcess, r.depth - brute);
      if (r.depth - brute > tol) ++bruteSeparatesMore;
      assert_true(fast.depth >= r.depth);  // the first separating axis, not necessarily the best
    }
    check_axis(a, &pa, b, &pb, &r, tol, &maxAxisDiff);
    check_axis(a, &pa, b, &pb, &fast, tol, &maxAxisDiff);
    // the faces of the Minkowski difference: the same minimum, separated or not (every 8th pair)
    double hull;
    if (n % 8 == 0 && minkowski_depth(a, &pa, b, &pb, &hull)) {
      ++hullChecked;
      maxHullDiff = fmax(maxHullDiff, fabs(r.depth - hull) / scale);
      if (fabs(r.depth - hull) > HULL_TOL_REL * scale)
        fail_msg("pair %d (%s / %s): depth %.17g, Minkowski hull %.17g", n, a->label, b->label, r.depth, hull);
    }
    minkowski += r.minkowskiEdgePairs;
    edgePairs += (long long)a->p.edgeCount * b->p.edgeCount;
  }
  print_message(
      "%d pairs: %ld overlapping, %ld separated, verdict disagreements 0 (%ld with |depth| <= 1e-12 x scale)\n", PAIRS,
      overlapping, separated, nearZero);
  print_message(
      "overlapping: max |depth - brute| = %.3g m; separated: brute found a larger separation on %ld "
      "(max %.3g m, non-Minkowski axes)\n",
      maxOverlapDiff, bruteSeparatesMore, maxSeparatedExcess);
  print_message(
      "reported axes re-projected: max |overlap - depth| = %.3g m; Minkowski hull on %ld pairs: max "
      "|depth - hull| / scale = %.3g\n",
      maxAxisDiff, hullChecked, maxHullDiff);
  print_message("Gauss-map test kept %lld of %lld edge pairs (%.2f%%)\n", minkowski, edgePairs,
                100.0 * (double)minkowski / (double)edgePairs);
  assert_true(overlapping > PAIRS / 4 && separated > PAIRS / 4);
  assert_true(minkowski * 10 < edgePairs);  // the pruning is worth having: far fewer edge axes than pairs
  free_pool(pool);
}

// The widest gap PD_SAT_VERDICT may call touching, over PD_GJK_MARGIN_REL × pair_scale: its margin m is
// PD_GJK_MARGIN_REL × a size (the bodies' vertex averages' distances from their origins, their circumradii about
// them, the distance between the origins) of at most 3 × pair_scale (a vertex average lies within `radius` of
// the origin, every vertex within 2 `radius` of it), and GJK certifies every gap above 1.001 m.
#define VERDICT_BAND_MAX 3.01

// Checks PD_SAT_VERDICT's result `v` against the search's (first-separating and min-depth) on one pair: a
// separation is theirs, their overlap is a touching verdict, and a touching pair they call apart is apart by at
// most VERDICT_BAND_MAX × PD_GJK_MARGIN_REL × pair_scale. Returns the gap over PD_GJK_MARGIN_REL × pair_scale
// (0 when the verdicts agree).
static double check_verdict(const shape* a, const pose* pa, const shape* b, const pose* pb, const pdSatResult* v,
                            const pdSatResult* first, const pdSatResult* min, const char* what) {
  assert_true(v->separated == (v->depth < 0.0));
  double unit = PD_GJK_MARGIN_REL * pair_scale(a, pa, b, pb), band = 0.0;
  if (v->separated != first->separated || first->separated != min->separated) {
    band = -min->depth / unit;
    if (v->separated || !(band <= VERDICT_BAND_MAX))
      fail_msg("%s (%s / %s): first-separating %s, min depth %.17g (%.3g margins), verdict %s", what, a->label,
               b->label, first->separated ? "separated" : "overlapping", min->depth, band,
               v->separated ? "separated" : "touching");
  }
  return band;
}

// PD_SAT_VERDICT (GJK's certificates; touching where GJK finds none) on pairs within 1e-10 to 1e-1 of touching,
// with and without a warm cache (check_verdict): a certified overlap's depth is a lower bound on the penetration
// (PD_SAT_MIN_DEPTH's depth); a certified separation's axis really has the reported negative overlap; the
// certificates settle most pairs; and the pairs called touching while the search calls them apart lie within
// the margin.
static void test_verdict_mode_separates_only_what_the_search_separates(void** state) {
  (void)state;
  enum { PAIRS = 20000 };
  shape* pool = make_pool(0x5a7ull);
  lcg g = {0xfe11c7ull};
  long certifiedOverlap = 0, certifiedSeparation = 0, withinMargin = 0, apartWithinMargin = 0, searched = 0;
  double maxAxisDiff = 0.0, widestBand = 0.0;
  for (int n = 0; n < PAIRS; ++n) {
    const shape* a = &pool[(int)(lcg_uniform(&g) * POOL)];
    const shape* b = &pool[(int)(lcg_uniform(&g) * POOL)];
    pose pa, pb;
    random_poses(&g, a, &pa, b, &pb);
    double tol = DEPTH_TOL_REL * pair_scale(a, &pa, b, &pb);
    pdSatCache cache = {PD_SAT_NONE, -1, -1, {0, 0, 0}};
    pdSatResult first = sat(a, &pa, b, &pb, PD_SAT_FIRST_SEPARATING, &cache);
    pdSatResult min = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, NULL);
    pdSatResult v, warm;
    bool hit = pd_interference(&a->p, pa.x, &pa.R, &b->p, pb.x, &pb.R, PD_SAT_VERDICT, NULL, &v);
    pd_interference(&a->p, pa.x, &pa.R, &b->p, pb.x, &pb.R, PD_SAT_VERDICT, &cache, &warm);
    assert_true(hit == !v.separated);
    double band = check_verdict(a, &pa, b, &pb, &v, &first, &min, "cold");
    widestBand = fmax(widestBand, fmax(band, check_verdict(a, &pa, b, &pb, &warm, &first, &min, "from a warm cache")));
    apartWithinMargin += band > 0.0;
    if (v.kind != PD_SAT_NONE) {
      ++searched;  // GJK went wrong (gjkUndecided): the search's own result
    } else if (v.separated) {
      ++certifiedSeparation;
      assert_true(fabs(pd_v3_norm(v.axis) - 1.0) < 1e-12);
      check_axis(a, &pa, b, &pb, &v, tol, &maxAxisDiff);
    } else if (v.depth > 0.0) {
      ++certifiedOverlap;
      if (!(v.depth <= min.depth + tol))
        fail_msg("pair %d (%s / %s): certified depth %.17g, penetration %.17g", n, a->label, b->label, v.depth,
                 min.depth);
    } else {
      ++withinMargin;
      assert_true(v.depth == 0.0);
    }
  }
  print_message(
      "%d pairs: overlap certified %ld, separation certified %ld, touching within the margin %ld (of which the "
      "search calls %ld apart, by at most %.3g x PD_GJK_MARGIN_REL x the pair's scale), left to the search %ld\n",
      PAIRS, certifiedOverlap, certifiedSeparation, withinMargin, apartWithinMargin, widestBand, searched);
  assert_true(certifiedOverlap > PAIRS / 5 && certifiedSeparation > PAIRS / 5);
  assert_true(searched < PAIRS / 100);  // else the mode would be GJK plus the search
  free_pool(pool);
}

static shape unit_cube(void) {
  shape s;
  pdError why = {0};
  assert_true(pd_polyhedron_cube(&s.p, (const double[3]){1, 1, 1}, &why));
  s.radius = sqrt(3.0) / 2;
  snprintf(s.label, sizeof s.label, "unit cube");
  return s;
}

// The closed cases again with the whole scene rotated by G and moved by `shift` (frame invariance).
static void move_scene(pose* p, const pdMat3* G, pdVec3 shift) {
  p->x = pd_v3_add(shift, pd_mat3_mulv(G, p->x));
  p->R = pd_mat3_mul(G, &p->R);
}

// kind 0: any feature (in a rotated frame, rounding decides between features that give the same axis,
// e.g. a face normal and the cross product of two edges lying in that face).
static void expect(const shape* a, const pose* pa, const shape* b, const pose* pb, bool separated, double depth,
                   pdSatFeature kind, pdVec3 axis, const char* label) {
  for (int mode = 0; mode < 2; ++mode) {
    pdSatResult r = sat(a, pa, b, pb, (pdSatMode)mode, NULL);
    if (r.separated != separated || fabs(r.depth - depth) > CLOSED_TOL)
      fail_msg("%s (mode %d): %s depth %.17g, expected %s %.17g", label, mode,
               r.separated ? "separated" : "overlapping", r.depth, separated ? "separated" : "overlapping", depth);
    if ((kind != PD_SAT_NONE && r.kind != kind) || pd_v3_norm(pd_v3_sub(r.axis, axis)) > 1e-12)
      fail_msg("%s (mode %d): axis (%.17g %.17g %.17g) kind %d, expected (%g %g %g) kind %d", label, mode, r.axis.x,
               r.axis.y, r.axis.z, r.kind, axis.x, axis.y, axis.z, kind);
    double brute = brute_sat(a, pa, b, pb);
    if (separated ? brute > depth + CLOSED_TOL : fabs(brute - depth) > CLOSED_TOL)
      fail_msg("%s: brute force depth %.17g, expected %.17g", label, brute, depth);
  }
}

static void check_closed_cases(const pdMat3* G, pdVec3 shift, bool exactFrame) {
  shape cube = unit_cube();
  pdSatFeature faceA = exactFrame ? PD_SAT_FACE_A : PD_SAT_NONE, faceB = exactFrame ? PD_SAT_FACE_B : PD_SAT_NONE;
  pdMat3 I = pd_mat3_identity();
  pdVec3 gx = pd_mat3_mulv(G, pd_v3(1, 0, 0)), gz = pd_mat3_mulv(G, pd_v3(0, 0, 1));

  // face to face along x: gap 1e-9 (separated), overlap 1e-6
  pose a = {{0, 0, 0}, I}, b = {{1.0 + 1e-9, 0.2, -0.1}, I};
  move_scene(&a, G, shift);
  move_scene(&b, G, shift);
  expect(&cube, &a, &cube, &b, true, -1e-9, faceA, gx, "faces, gap 1e-9");
  a = (pose){{0, 0, 0}, I};
  b = (pose){{1.0 - 1e-6, 0.2, -0.1}, I};
  move_scene(&a, G, shift);
  move_scene(&b, G, shift);
  expect(&cube, &a, &cube, &b, false, 1e-6, faceA, gx, "faces, overlap 1e-6");

  // crossed edges: A turned 45° about x (top edge along x at z = √2/2), B turned 45° about y (bottom
  // edge along y at z = −√2/2), B above A: the edges cross at depth d along z
  pdMat3 Rx = pd_quat_to_mat3(pd_quat_from_axis_angle(pd_v3(1, 0, 0), PI / 4));
  pdMat3 Ry = pd_quat_to_mat3(pd_quat_from_axis_angle(pd_v3(0, 1, 0), PI / 4));
  for (int s = -1; s <= 1; s += 2) {
    double d = s * 1e-3;
    a = (pose){{0, 0, 0}, Rx};
    b = (pose){{0, 0, sqrt(2.0) - d}, Ry};
    move_scene(&a, G, shift);
    move_scene(&b, G, shift);
    expect(&cube, &a, &cube, &b, d < 0, d, PD_SAT_EDGES, gz,
           d < 0 ? "crossed edges, gap 1e-3" : "crossed edges, depth 1e-3");
  }

  // vertex on face: B's corner (½, ½, ½) turned to point straight down, pressed 1e-4 into A's top face
  pdMat3 Rv = pd_quat_to_mat3(pd_quat_from_axis_angle(pd_v3(-1, 1, 0), acos(-1.0 / sqrt(3.0))));
  pdVec3 corner = pd_mat3_mulv(&Rv, pd_v3(0.5, 0.5, 0.5));
  assert_true(pd_v3_norm(pd_v3_sub(corner, pd_v3(0, 0, -sqrt(3.0) / 2))) < 1e-15);
  double d = 1e-4;
  a = (pose){{0, 0, 0}, I};
  b = (pose){{0.1, 0.05, 0.5 + sqrt(3.0) / 2 - d}, Rv};
  move_scene(&a, G, shift);
  move_scene(&b, G, shift);
  expect(&cube, &a, &cube, &b, false, d, faceA, gz, "vertex on face");
  // the same with the roles swapped: now B's face, and the axis still from A (above) to B (below)
  expect(&cube, &b, &cube, &a, false, d, faceB, pd_v3_scale(gz, -1.0), "vertex on face, swapped");
  pd_polyhedron_free(&cube.p);
}

static void test_closed_cases_face_face_crossed_edges_vertex_face(void** state) {
  (void)state;
  pdMat3 I = pd_mat3_identity();
  check_closed_cases(&I, pd_v3(0, 0, 0), true);
  // rotated and 100 m from the origin: the same depths to 1e-12 (everything is done in A's frame)
  lcg g = {31};
  for (int i = 0; i < 10; ++i) {
    pdMat3 G = lcg_rotation(&g);
    check_closed_cases(&G, pd_v3_scale(lcg_direction(&g), 100.0), false);
  }
}

static void test_cache_changes_no_verdict_and_no_min_depth_along_coherent_motion(void** state) {
  (void)state;
  enum { TRAJECTORIES = 250, STEPS = 40 };
  shape* pool = make_pool(0xcac4eull);
  lcg g = {0x7e4a9ull};
  long steps = 0, separatedSteps = 0, cacheReused = 0, withinMargin = 0;
  for (int t = 0; t < TRAJECTORIES; ++t) {
    const shape* a = &pool[(int)(lcg_uniform(&g) * POOL)];
    const shape* b = &pool[(int)(lcg_uniform(&g) * POOL)];
    pose pa, pb;
    random_poses(&g, a, &pa, b, &pb);
    // B drifts through A's neighbourhood and spins; A spins too
    double sum = a->radius + b->radius;
    pdVec3 v = pd_v3_scale(lcg_direction(&g), 0.01 * sum);
    pdMat3 wa = pd_quat_to_mat3(pd_quat_from_axis_angle(lcg_direction(&g), 0.02));
    pdMat3 wb = pd_quat_to_mat3(pd_quat_from_axis_angle(lcg_direction(&g), 0.03));
    pdSatCache warmFast = {PD_SAT_NONE, -1, -1, {0, 0, 0}}, warmMin = {PD_SAT_NONE, -1, -1, {0, 0, 0}};
    pdSatCache warmVerdict = {PD_SAT_NONE, -1, -1, {0, 0, 0}};  // PD_SAT_VERDICT's own: features and directions
    for (int s = 0; s < STEPS; ++s) {
      pb.x = pd_v3_add(pb.x, v);
      pa.R = pd_mat3_mul(&wa, &pa.R);
      pb.R = pd_mat3_mul(&wb, &pb.R);
      pdSatCache before = warmFast;
      pdSatResult cold = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, NULL);
      pdSatResult coldFast = sat(a, &pa, b, &pb, PD_SAT_FIRST_SEPARATING, NULL);
      pdSatResult hotMin = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, &warmMin);
      pdSatResult hot = sat(a, &pa, b, &pb, PD_SAT_FIRST_SEPARATING, &warmFast);
      pdSatResult verdict;
      pd_interference(&a->p, pa.x, &pa.R, &b->p, pb.x, &pb.R, PD_SAT_VERDICT, &warmVerdict, &verdict);
      assert_true(same_result(&cold, &hotMin));  // MIN_DEPTH: identical, bit for bit
      assert_true(hot.separated == cold.separated && coldFast.separated == cold.separated);
      withinMargin += check_verdict(a, &pa, b, &pb, &verdict, &coldFast, &cold, "trajectory step") > 0.0;
      if (!cold.separated) {
        assert_true(same_result(&cold, &hot));  // overlapping: the full search, bit for bit
      } else {
        ++separatedSteps;
        assert_true(hot.depth < 0.0 && hot.depth >= cold.depth);
        double ignored = 0.0;
        check_axis(a, &pa, b, &pb, &hot, DEPTH_TOL_REL * pair_scale(a, &pa, b, &pb), &ignored);
        if (hot.kind == before.kind && hot.a == before.a && hot.b == before.b) ++cacheReused;
      }
      assert_true(warmFast.kind == hot.kind && warmFast.a == hot.a && warmFast.b == hot.b);
      ++steps;
    }
  }
  print_message(
      "%ld steps (%ld separated): verdicts identical with and without the cache, and in verdict mode with its "
      "own but for %ld apart within its margin; the cached axis still separated on %ld (%.1f%%)\n",
      steps, separatedSteps, withinMargin, cacheReused, 100.0 * (double)cacheReused / (double)separatedSteps);
  assert_true(separatedSteps > steps / 4 && cacheReused > separatedSteps / 2);
  free_pool(pool);
}

static void test_stale_or_foreign_cache_entries_are_harmless(void** state) {
  (void)state;
  enum { PAIRS = 1500 };
  shape* pool = make_pool(0x57a1eull);
  lcg g = {0xbadcaull};
  for (int n = 0; n < PAIRS; ++n) {
    const shape* a = &pool[(int)(lcg_uniform(&g) * POOL)];
    const shape* b = &pool[(int)(lcg_uniform(&g) * POOL)];
    const shape* c = &pool[(int)(lcg_uniform(&g) * POOL)];
    pose pa, pb, qa, qb;
    random_poses(&g, a, &pa, b, &pb);
    random_poses(&g, c, &qa, b, &qb);
    pdSatResult cold = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, NULL);
    pdSatCache caches[5];
    // from the same pair at an unrelated pose; from another pair (indices may be out of range);
    // garbage indices; an edge pair that is not a Minkowski face here
    sat(a, &qa, b, &qb, PD_SAT_MIN_DEPTH, &caches[0]);
    sat(c, &qa, b, &qb, PD_SAT_MIN_DEPTH, &caches[1]);
    caches[2] = (pdSatCache){(pdSatFeature)(1 + (int)(lcg_uniform(&g) * 3)), (int)lcg_range(&g, -5, 500),
                             (int)lcg_range(&g, -5, 500), {0, 0, 0}};
    caches[3] = (pdSatCache){PD_SAT_EDGES, (int)(lcg_uniform(&g) * a->p.edgeCount),
                             (int)(lcg_uniform(&g) * b->p.edgeCount), {0, 0, 0}};
    // and a separating direction of GJK's (PD_SAT_VERDICT's cache) from nowhere
    caches[4] = (pdSatCache){PD_SAT_APART, -1, -1, lcg_direction(&g)};
    for (int k = 0; k < 5; ++k) {
      pdSatCache c1 = caches[k], c2 = caches[k], c3 = caches[k];
      pdSatResult hot = sat(a, &pa, b, &pb, PD_SAT_FIRST_SEPARATING, &c1);
      pdSatResult hotMin = sat(a, &pa, b, &pb, PD_SAT_MIN_DEPTH, &c2);
      pdSatResult verdict;
      pd_interference(&a->p, pa.x, &pa.R, &b->p, pb.x, &pb.R, PD_SAT_VERDICT, &c3, &verdict);
      assert_true(hot.separated == cold.separated);
      check_verdict(a, &pa, b, &pb, &verdict, &hot, &cold, "stale cache");
      assert_true(same_result(&hotMin, &cold));
      if (!cold.separated) assert_true(same_result(&hot, &cold));
      double ignored = 0.0;
      check_axis(a, &pa, b, &pb, &hot, DEPTH_TOL_REL * pair_scale(a, &pa, b, &pb), &ignored);
    }
  }
  free_pool(pool);
}

// The search structures (pdSatIndex: downhill supports, Gauss-map arcs banded along z, edge records and the
// culling bounds, which every polyhedron built by a constructor carries) change no result:
// the same pairs with the structures detached (the exhaustive search) give the same depth to the bit, the
// same feature and axis in PD_SAT_MIN_DEPTH mode and the same verdict in PD_SAT_FIRST_SEPARATING mode.
// Shapes with many features (spheres of levels 1 and 2, 16- to 64-gon prisms, hulls of 60 points) against
// each other and against small ones, so that every path (A indexed, B only, both) runs.
static void test_search_structures_change_no_result(void** state) {
  (void)state;
  enum { BIG = 12, PAIRS = 3000 };
  lcg g = {0xb16ull};
  shape pool[BIG + SHAPE_KINDS];
  for (int i = 0; i < BIG; ++i) {
    pdError why = {0};
    double scale[3] = {lcg_range(&g, 0.3, 2.0), lcg_range(&g, 0.3, 2.0), lcg_range(&g, 0.3, 2.0)};
    bool ok;
    if (i % 3 == 0) {
      ok = pd_polyhedron_sphere(&pool[i].p, 1 + i / 3 % 2, scale, &why);
      snprintf(pool[i].label, sizeof pool[i].label, "sphere level %d", 1 + i / 3 % 2);
    } else if (i % 3 == 1) {
      int sides = 16 + 16 * (i / 3 % 4);
      ok = pd_polyhedron_prism(&pool[i].p, sides, scale, lcg_range(&g, 0.3, 1.0), &why);
      snprintf(pool[i].label, sizeof pool[i].label, "tprism %d", sides);
    } else {
      double pts[3 * 60];
      for (int k = 0; k < 3 * 60; ++k) pts[k] = scale[k % 3] * lcg_range(&g, -0.5, 0.5);
      ok = pd_polyhedron_hull(&pool[i].p, pts, 60, &why);
      snprintf(pool[i].label, sizeof pool[i].label, "hull of 60 points");
    }
    if (!ok) fail_msg("%s: %s", pool[i].label, why.message);
    pd_polyhedron_translate(&pool[i].p, pd_v3_scale(vertex_average(&pool[i].p), -1.0));
    pool[i].radius = 0.0;
    for (int v = 0; v < pool[i].p.vertexCount; ++v) pool[i].radius = fmax(pool[i].radius, pd_v3_norm(pool[i].p.vertices[v]));
  }
  for (int k = 0; k < SHAPE_KINDS; ++k) make_shape(&g, k, 0, &pool[BIG + k]);
  int indexed = 0;
  for (int i = 0; i < BIG + SHAPE_KINDS; ++i) indexed += pool[i].p.satIndex != NULL;
  assert_true(indexed >= BIG);  // every big shape carries the structures
  long overlapping = 0;
  for (int n = 0; n < PAIRS; ++n) {
    const shape* a = &pool[(int)(lcg_uniform(&g) * (BIG + SHAPE_KINDS))];
    const shape* b = &pool[(int)(lcg_uniform(&g) * (BIG + SHAPE_KINDS))];
    pose pa, pb;
    random_poses(&g, a, &pa, b, &pb);
    shape plainA = *a, plainB = *b;  // the same polyhedra without their search structures
    plainA.p.satIndex = NULL;
    plainB.p.satIndex = NULL;
    pdSatMode modes[2] = {PD_SAT_MIN_DEPTH, PD_SAT_FIRST_SEPARATING};
    for (int m = 0; m < 2; ++m) {
      pdSatResult fast = sat(a, &pa, b, &pb, modes[m], NULL), plain = sat(&plainA, &pa, &plainB, &pb, modes[m], NULL);
      if (fast.separated != plain.separated)
        fail_msg("pair %d (%s / %s), mode %d: verdicts differ", n, a->label, b->label, m);
      if (m == 0 && (fast.depth != plain.depth || fast.kind != plain.kind || fast.a != plain.a || fast.b != plain.b ||
                     fast.axis.x != plain.axis.x || fast.axis.y != plain.axis.y || fast.axis.z != plain.axis.z))
        fail_msg("pair %d (%s / %s): depth %.17g (feature %d %d %d) against %.17g (feature %d %d %d) exhaustively", n,
                 a->label, b->label, fast.depth, fast.kind, fast.a, fast.b, plain.depth, plain.kind, plain.a, plain.b);
      if (m == 0 && !fast.separated) ++overlapping;
    }
  }
  print_message("%d pairs (%ld overlapping): identical with and without the search structures\n", PAIRS, overlapping);
  assert_true(overlapping > PAIRS / 10);
  for (int i = 0; i < BIG + SHAPE_KINDS; ++i) pd_polyhedron_free(&pool[i].p);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_edge_faces_follow_the_convention_the_gauss_map_test_uses),
      cmocka_unit_test(test_closed_cases_face_face_crossed_edges_vertex_face),
      cmocka_unit_test(test_pruned_sat_equals_brute_force_on_20000_random_pairs_near_touching),
      cmocka_unit_test(test_verdict_mode_separates_only_what_the_search_separates),
      cmocka_unit_test(test_search_structures_change_no_result),
      cmocka_unit_test(test_cache_changes_no_verdict_and_no_min_depth_along_coherent_motion),
      cmocka_unit_test(test_stale_or_foreign_cache_entries_are_harmless),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
