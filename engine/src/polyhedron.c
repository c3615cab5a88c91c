// polydyn — convex polyhedra: hulls (qhull), scene primitives, validation.
//
// Design note. Every polyhedron, primitive or user hull, is built the same way: a point set goes
// through qhull (reentrant libqhull_r, 'C-n' pre-merging with n = PD_PLANARITY_TOL_REL × size, so
// facets coplanar to within the tolerance pd_polyhedron_validate applies become one face and points
// that close together become one vertex), then we take over. Each face's vertices are put in
// counter-clockwise order around qhull's outward normal, vertices that lie on an edge of the hull
// (collinear in every face around them) are dropped, the face plane is refit through its vertices
// (Newell's normal), edges are paired from the directed face boundaries, and the result is put in a
// canonical order (vertices by input index, faces by their vertex lists) so that the same points
// always give the same polyhedron.
#include "polydyn/polyhedron.h"

#include <libqhull_r/qhull_ra.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "interference.h"


// Turn angles below this (sine) make a face vertex collinear with its neighbours: the vertex lies
// on an edge of the hull and carries no corner.
#define COLLINEAR_SINE_TOL 1e-9

static pdVec3 vertex_average(const pdVec3* v, int n) {
  pdVec3 c = {0, 0, 0};
  for (int i = 0; i < n; ++i) c = pd_v3_add(c, v[i]);
  return pd_v3_scale(c, 1.0 / n);
}

static double size_about(const pdVec3* v, int n, pdVec3 centre) {
  double r = 0.0;
  for (int i = 0; i < n; ++i) r = fmax(r, pd_v3_norm(pd_v3_sub(v[i], centre)));
  return r;
}

// ---------------------------------------------------------------- face ordering and planes

typedef struct angleKey {
  double angle;
  int vertex;
} angleKey;

static int compare_angle(const void* a, const void* b) {
  const angleKey* x = a;
  const angleKey* y = b;
  if (x->angle < y->angle) return -1;
  if (x->angle > y->angle) return 1;
  return x->vertex - y->vertex;
}

// Orders the face's vertices counter-clockwise about `normal`.
static void order_ccw(const pdVec3* verts, int* idx, int count, pdVec3 normal, angleKey* keys) {
  pdVec3 c = {0, 0, 0};
  for (int i = 0; i < count; ++i) c = pd_v3_add(c, verts[idx[i]]);
  c = pd_v3_scale(c, 1.0 / count);
  pdVec3 u = pd_v3_normalize(pd_v3_sub(verts[idx[0]], c));
  pdVec3 w = pd_v3_cross(normal, u);
  for (int i = 0; i < count; ++i) {
    pdVec3 d = pd_v3_sub(verts[idx[i]], c);
    keys[i] = (angleKey){atan2(pd_v3_dot(d, w), pd_v3_dot(d, u)), idx[i]};
  }
  qsort(keys, (size_t)count, sizeof *keys, compare_angle);
  for (int i = 0; i < count; ++i) idx[i] = keys[i].vertex;
}

// Newell's normal of a polygon: robust for nearly degenerate and non-triangular faces.
static pdVec3 newell_normal(const pdVec3* verts, const int* idx, int count) {
  pdVec3 n = {0, 0, 0};
  for (int i = 0; i < count; ++i) {
    pdVec3 a = verts[idx[i]], b = verts[idx[(i + 1) % count]];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return pd_v3_normalize(n);
}

static bool is_collinear(pdVec3 prev, pdVec3 p, pdVec3 next) {
  pdVec3 a = pd_v3_sub(p, prev), b = pd_v3_sub(next, p);
  return pd_v3_norm(pd_v3_cross(a, b)) <= COLLINEAR_SINE_TOL * pd_v3_norm(a) * pd_v3_norm(b);
}

// ---------------------------------------------------------------- edges from directed boundaries

typedef struct halfEdge {
  int a, b, face;
} halfEdge;

static int compare_half_edge(const void* x, const void* y) {
  const halfEdge* p = x;
  const halfEdge* q = y;
  int plo = p->a < p->b ? p->a : p->b, phi = p->a < p->b ? p->b : p->a;
  int qlo = q->a < q->b ? q->a : q->b, qhi = q->a < q->b ? q->b : q->a;
  if (plo != qlo) return plo - qlo;
  if (phi != qhi) return phi - qhi;
  return (p->a < p->b ? 0 : 1) - (q->a < q->b ? 0 : 1);  // forward (a < b) first
}

// Pairs directed face boundaries into edges. Returns false (with why) unless every undirected edge
// is walked exactly once in each direction. When `edges` is NULL only counts and checks.
static bool pair_edges(const pdPolyhedron* p, pdEdge* edges, int* edgeCount, pdError* why) {
  int total = 0;
  for (int f = 0; f < p->faceCount; ++f) total += p->faces[f].count;
  halfEdge* h = pd_zeroed((size_t)total, sizeof *h);
  int k = 0;
  for (int f = 0; f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    for (int i = 0; i < face->count; ++i)
      h[k++] = (halfEdge){p->faceVertices[face->first + i], p->faceVertices[face->first + (i + 1) % face->count], f};
  }
  qsort(h, (size_t)total, sizeof *h, compare_half_edge);
  bool ok = true;
  int e = 0;
  for (int i = 0; i < total;) {
    // a group of half-edges over the same two vertices
    int j = i + 1;
    while (j < total && (h[j].a == h[i].a || h[j].a == h[i].b) && (h[j].b == h[i].a || h[j].b == h[i].b)) ++j;
    const halfEdge* fwd = &h[i];
    if (j - i != 2 || fwd->a == fwd->b || !(fwd->a < fwd->b && h[i + 1].a == fwd->b)) {
      pd_error_set(why, NULL, 0, 0, "edge %d-%d is not shared by exactly two faces walking it in opposite directions", fwd->a,
          fwd->b);
      ok = false;
      break;
    }
    if (edges) edges[e] = (pdEdge){{fwd->a, fwd->b}, {fwd->face, h[i + 1].face}};
    ++e;
    i = j;
  }
  free(h);
  if (edgeCount) *edgeCount = e;
  return ok;
}

// ---------------------------------------------------------------- canonical assembly

typedef struct rawFace {
  int* idx;
  int count;
  pdVec3 normal;
} rawFace;

static int compare_raw_face(const void* x, const void* y) {
  const rawFace* a = x;
  const rawFace* b = y;
  int n = a->count < b->count ? a->count : b->count;
  for (int i = 0; i < n; ++i)
    if (a->idx[i] != b->idx[i]) return a->idx[i] - b->idx[i];
  return a->count - b->count;
}

// Takes the faces (vertex index lists into `verts`, any order within a face, outward normal hint),
// orders, cleans and assembles the polyhedron. Takes ownership of nothing.
static bool assemble(pdPolyhedron* out, const pdVec3* verts, int vertCount, rawFace* faces, int faceCount, pdError* why) {
  memset(out, 0, sizeof *out);
  int maxCount = 3;
  for (int f = 0; f < faceCount; ++f) maxCount = faces[f].count > maxCount ? faces[f].count : maxCount;
  angleKey* keys = pd_zeroed((size_t)maxCount, sizeof *keys);
  for (int f = 0; f < faceCount; ++f) order_ccw(verts, faces[f].idx, faces[f].count, faces[f].normal, keys);
  free(keys);

  // drop vertices that are collinear in every face that holds them (they lie on a hull edge)
  int* uses = pd_zeroed((size_t)vertCount, sizeof *uses);
  int* straight = pd_zeroed((size_t)vertCount, sizeof *straight);
  for (int f = 0; f < faceCount; ++f) {
    int n = faces[f].count;
    for (int i = 0; i < n; ++i) {
      int v = faces[f].idx[i];
      ++uses[v];
      if (is_collinear(verts[faces[f].idx[(i + n - 1) % n]], verts[v], verts[faces[f].idx[(i + 1) % n]])) ++straight[v];
    }
  }
  for (int f = 0; f < faceCount; ++f) {
    int k = 0;
    for (int i = 0; i < faces[f].count; ++i) {
      int v = faces[f].idx[i];
      if (!(uses[v] > 0 && straight[v] == uses[v])) faces[f].idx[k++] = v;
    }
    faces[f].count = k;
  }

  // compact the vertex numbering to the vertices still used, keeping their order
  int* remap = pd_zeroed((size_t)vertCount, sizeof *remap);
  int used = 0;
  for (int v = 0; v < vertCount; ++v) remap[v] = (uses[v] > 0 && straight[v] < uses[v]) ? used++ : -1;
  out->vertexCount = used;
  out->vertices = pd_zeroed((size_t)used, sizeof *out->vertices);
  for (int v = 0; v < vertCount; ++v)
    if (remap[v] >= 0) out->vertices[remap[v]] = verts[v];

  // canonical face lists: renumbered, rotated to start at the smallest index, faces sorted
  int total = 0;
  for (int f = 0; f < faceCount; ++f) {
    int n = faces[f].count, lo = 0;
    for (int i = 0; i < n; ++i) faces[f].idx[i] = remap[faces[f].idx[i]];
    for (int i = 1; i < n; ++i)
      if (faces[f].idx[i] < faces[f].idx[lo]) lo = i;
    int* rotated = pd_zeroed((size_t)n, sizeof *rotated);
    for (int i = 0; i < n; ++i) rotated[i] = faces[f].idx[(lo + i) % n];
    memcpy(faces[f].idx, rotated, (size_t)n * sizeof *rotated);
    free(rotated);
    total += n;
  }
  qsort(faces, (size_t)faceCount, sizeof *faces, compare_raw_face);
  free(uses);
  free(straight);
  free(remap);

  out->faceCount = faceCount;
  out->faces = pd_zeroed((size_t)faceCount, sizeof *out->faces);
  out->faceVertices = pd_zeroed((size_t)total, sizeof *out->faceVertices);
  int at = 0;
  for (int f = 0; f < faceCount; ++f) {
    if (faces[f].count < 3) {
      pd_error_set(why, NULL, 0, 0, "a face has fewer than 3 corners (degenerate hull)");
      pd_polyhedron_free(out);
      return false;
    }
    memcpy(out->faceVertices + at, faces[f].idx, (size_t)faces[f].count * sizeof(int));
    pdFace* face = &out->faces[f];
    face->first = at;
    face->count = faces[f].count;
    face->normal = newell_normal(out->vertices, out->faceVertices + at, face->count);
    double d = 0.0;
    for (int i = 0; i < face->count; ++i) d += pd_v3_dot(face->normal, out->vertices[out->faceVertices[at + i]]);
    face->offset = d / face->count;
    at += face->count;
  }

  int edgeCount = 0;
  if (!pair_edges(out, NULL, &edgeCount, why)) {
    pd_polyhedron_free(out);
    return false;
  }
  out->edgeCount = edgeCount;
  out->edges = pd_zeroed((size_t)edgeCount, sizeof *out->edges);
  pair_edges(out, out->edges, NULL, NULL);
  if (!pd_polyhedron_validate(out, why)) {
    pd_polyhedron_free(out);
    return false;
  }
  pd_sat_index_build(out);
  return true;
}

// ---------------------------------------------------------------- qhull

// Largest distance of a point from the points' average (finite points).
static double points_size(const double* points, int count) {
  double c[3] = {0, 0, 0}, r = 0.0;
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) c[k] += points[3 * i + k] / count;
  for (int i = 0; i < count; ++i)
    r = fmax(r, pd_v3_norm((pdVec3){points[3 * i] - c[0], points[3 * i + 1] - c[1], points[3 * i + 2] - c[2]}));
  return r;
}

bool pd_polyhedron_hull(pdPolyhedron* out, const double* points, int count, pdError* why) {
  memset(out, 0, sizeof *out);
  if (count < 4) {
    pd_error_set(why, NULL, 0, 0, "a hull needs at least 4 points, got %d", count);
    return false;
  }
  for (int i = 0; i < 3 * count; ++i)
    if (!isfinite(points[i])) {
      pd_error_set(why, NULL, 0, 0, "a hull point is not finite");
      return false;
    }

  // qhull wants a writable array; its messages go to a memory stream we read on failure
  coordT* coords = pd_zeroed((size_t)count * 3, sizeof *coords);
  memcpy(coords, points, (size_t)count * 3 * sizeof(double));
  char* messages = NULL;
  size_t messagesSize = 0;
  FILE* errfile = open_memstream(&messages, &messagesSize);
  PD_ASSERT(errfile != NULL);

  qhT qhStorage;
  qhT* qh = &qhStorage;
  QHULL_LIB_CHECK
  qh_zero(qh, errfile);
  // merge facets whose centrums are within the planarity tolerance of a neighbour's plane ('C-n'):
  // with qhull's default 'C-0' a point 1e-12 off a face survived as a sliver bump or a near-duplicate
  // corner as sliver faces, which validation then refused as coplanar neighbours or kept as micro-edges
  char command[64];
  snprintf(command, sizeof command, "qhull C-%.17g", PD_PLANARITY_TOL_REL * points_size(points, count));
  int exitcode = qh_new_qhull(qh, 3, count, coords, False, command, NULL, errfile);
  bool ok = exitcode == 0;
  if (!ok) {
    fflush(errfile);
    const char* text = messages ? messages : "";
    const char* code = strstr(text, "QH");
    pd_error_set(why, NULL, 0, 0, "degenerate hull: the points are coplanar, collinear or coincident (qhull %.6s)",
        code ? code : "error");
  } else {
    // vertices in input order: mark which input points are hull vertices
    int* vertexOf = pd_zeroed((size_t)count, sizeof *vertexOf);
    for (int i = 0; i < count; ++i) vertexOf[i] = -1;
    vertexT* vertex;
    FORALLvertices vertexOf[qh_pointid(qh, vertex->point)] = 0;
    int vertCount = 0;
    pdVec3* verts = pd_zeroed((size_t)count, sizeof *verts);
    for (int i = 0; i < count; ++i)
      if (vertexOf[i] == 0) {
        vertexOf[i] = vertCount;
        verts[vertCount++] = (pdVec3){points[3 * i], points[3 * i + 1], points[3 * i + 2]};
      }

    int faceCount = 0;
    facetT* facet;
    FORALLfacets++ faceCount;
    rawFace* faces = pd_zeroed((size_t)faceCount, sizeof *faces);
    int f = 0;
    FORALLfacets {
      vertexT** vertexp;
      int n = qh_setsize(qh, facet->vertices);
      faces[f].idx = pd_zeroed((size_t)n, sizeof(int));
      faces[f].count = 0;
      FOREACHvertex_(facet->vertices) faces[f].idx[faces[f].count++] = vertexOf[qh_pointid(qh, vertex->point)];
      faces[f].normal = (pdVec3){facet->normal[0], facet->normal[1], facet->normal[2]};
      ++f;
    }
    ok = assemble(out, verts, vertCount, faces, faceCount, why);
    for (int i = 0; i < faceCount; ++i) free(faces[i].idx);
    free(faces);
    free(verts);
    free(vertexOf);
  }
  int curlong, totlong;
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &curlong, &totlong);
  fclose(errfile);
  free(messages);
  free(coords);
  return ok;
}

// ---------------------------------------------------------------- primitives

bool pd_polyhedron_cube(pdPolyhedron* out, const double scale[3], pdError* why) {
  double pts[8 * 3];
  for (int i = 0; i < 8; ++i) {
    pts[3 * i + 0] = ((i & 1) ? 0.5 : -0.5) * scale[0];
    pts[3 * i + 1] = ((i & 2) ? 0.5 : -0.5) * scale[1];
    pts[3 * i + 2] = ((i & 4) ? 0.5 : -0.5) * scale[2];
  }
  return pd_polyhedron_hull(out, pts, 8, why);
}

bool pd_polyhedron_prism(pdPolyhedron* out, int sides, const double scale[3], double taper, pdError* why) {
  PD_ASSERT(sides >= 3 && taper > 0.0 && taper <= 1.0);
  double* pts = pd_zeroed((size_t)sides * 2 * 3, sizeof *pts);
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < sides; ++i) {
    double a = 2.0 * pi * i / sides;
    double c = 0.5 * cos(a), s = 0.5 * sin(a);
    double* bottom = pts + 3 * i;
    double* top = pts + 3 * (sides + i);
    bottom[0] = c * scale[0], bottom[1] = s * scale[1], bottom[2] = -0.5 * scale[2];
    top[0] = taper * c * scale[0], top[1] = taper * s * scale[1], top[2] = 0.5 * scale[2];
  }
  bool ok = pd_polyhedron_hull(out, pts, 2 * sides, why);
  free(pts);
  return ok;
}

typedef struct sphereBuilder {
  double* pts;
  int count;
} sphereBuilder;

static pdVec3 on_sphere(pdVec3 p) { return pd_v3_scale(pd_v3_normalize(p), 0.5); }

static void subdivide(sphereBuilder* b, pdVec3 a, pdVec3 c, pdVec3 d, int level) {
  if (level == 0) {
    pdVec3 tri[3] = {a, c, d};
    for (int i = 0; i < 3; ++i) {
      b->pts[3 * b->count + 0] = tri[i].x;
      b->pts[3 * b->count + 1] = tri[i].y;
      b->pts[3 * b->count + 2] = tri[i].z;
      ++b->count;
    }
    return;
  }
  // midpoints are sums of the same two vectors from both sides of an edge, so shared vertices are
  // bit-identical and qhull sees them as one point
  pdVec3 ac = on_sphere(pd_v3_add(a, c)), cd = on_sphere(pd_v3_add(c, d)), da = on_sphere(pd_v3_add(d, a));
  subdivide(b, a, ac, da, level - 1);
  subdivide(b, ac, c, cd, level - 1);
  subdivide(b, da, cd, d, level - 1);
  subdivide(b, ac, cd, da, level - 1);
}

bool pd_polyhedron_sphere(pdPolyhedron* out, int level, const double scale[3], pdError* why) {
  PD_ASSERT(level >= 0 && level <= 8);
  const double phi = 1.6180339887498948482;
  const pdVec3 ico[12] = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
                          {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  static const int tris[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                  {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                  {3, 8, 9},   {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  int perFace = 1;
  for (int i = 0; i < level; ++i) perFace *= 4;
  sphereBuilder b = {pd_zeroed((size_t)20 * perFace * 3 * 3, sizeof(double)), 0};
  for (int t = 0; t < 20; ++t)
    subdivide(&b, on_sphere(ico[tris[t][0]]), on_sphere(ico[tris[t][1]]), on_sphere(ico[tris[t][2]]), level);
  for (int i = 0; i < b.count; ++i)
    for (int k = 0; k < 3; ++k) b.pts[3 * i + k] *= scale[k];
  bool ok = pd_polyhedron_hull(out, b.pts, b.count, why);
  free(b.pts);
  return ok;
}

// ---------------------------------------------------------------- validation

// Position in faceVertices of the side of face f that runs a → b, or -1 when it has no such side.
static int side_position(const pdPolyhedron* p, int f, int a, int b) {
  const pdFace* face = &p->faces[f];
  for (int i = 0; i < face->count; ++i)
    if (p->faceVertices[face->first + i] == a && p->faceVertices[face->first + (i + 1) % face->count] == b)
      return face->first + i;
  return -1;
}

bool pd_polyhedron_validate(const pdPolyhedron* p, pdError* why) {
  if (p->vertexCount < 4 || p->faceCount < 4) {
    pd_error_set(why, NULL, 0, 0, "too few vertices or faces (V=%d, F=%d)", p->vertexCount, p->faceCount);
    return false;
  }
  if (p->vertexCount - p->edgeCount + p->faceCount != 2) {
    pd_error_set(why, NULL, 0, 0, "Euler characteristic V-E+F = %d, not 2", p->vertexCount - p->edgeCount + p->faceCount);
    return false;
  }
  pdVec3 centre = vertex_average(p->vertices, p->vertexCount);
  double tol = PD_PLANARITY_TOL_REL * size_about(p->vertices, p->vertexCount, centre);
  int* faceUses = pd_zeroed((size_t)p->vertexCount, sizeof *faceUses);
  bool ok = true;
  for (int f = 0; ok && f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    const int* idx = p->faceVertices + face->first;
    if (face->count < 3 || fabs(pd_v3_norm(face->normal) - 1.0) > 1e-12) {
      pd_error_set(why, NULL, 0, 0, "face %d has %d vertices or a non-unit normal", f, face->count);
      ok = false;
      break;
    }
    for (int i = 0; ok && i < face->count; ++i) {
      if (idx[i] < 0 || idx[i] >= p->vertexCount) {
        pd_error_set(why, NULL, 0, 0, "face %d refers to a vertex out of range", f);
        ok = false;
        break;
      }
      ++faceUses[idx[i]];
      pdVec3 a = p->vertices[idx[i]], b = p->vertices[idx[(i + 1) % face->count]],
             c = p->vertices[idx[(i + 2) % face->count]];
      if (fabs(pd_v3_dot(face->normal, a) - face->offset) > tol) {
        pd_error_set(why, NULL, 0, 0, "face %d is not planar", f);
        ok = false;
      } else if (pd_v3_dot(pd_v3_cross(pd_v3_sub(b, a), pd_v3_sub(c, b)), face->normal) <= 0.0) {
        pd_error_set(why, NULL, 0, 0, "face %d is not convex and counter-clockwise seen from outside", f);
        ok = false;
      }
    }
    // every vertex of the body lies behind every face plane
    for (int v = 0; ok && v < p->vertexCount; ++v)
      if (pd_v3_dot(face->normal, p->vertices[v]) > face->offset + tol) {
        pd_error_set(why, NULL, 0, 0, "not convex: vertex %d lies outside face %d", v, f);
        ok = false;
      }
  }
  for (int v = 0; ok && v < p->vertexCount; ++v)
    if (faceUses[v] < 3) {
      pd_error_set(why, NULL, 0, 0, "vertex %d belongs to %d faces (needs at least 3)", v, faceUses[v]);
      ok = false;
    }
  free(faceUses);
  if (ok) {
    int edgeCount = 0;
    ok = pair_edges(p, NULL, &edgeCount, why);
    if (ok && edgeCount != p->edgeCount) {
      pd_error_set(why, NULL, 0, 0, "edge list has %d edges, faces imply %d", p->edgeCount, edgeCount);
      ok = false;
    }
  }
  if (ok) {
    // the edge list itself: f[0] walks v[0]→v[1], f[1] walks v[1]→v[0], and no side is listed twice
    // (with the count checked above, the list is then exactly the faces' edges)
    int sides = 0;
    for (int f = 0; f < p->faceCount; ++f) sides += p->faces[f].count;
    char* listed = pd_zeroed((size_t)sides, sizeof *listed);
    for (int e = 0; ok && e < p->edgeCount; ++e) {
      const pdEdge* edge = &p->edges[e];
      int fwd = -1, back = -1;
      if (edge->v[0] >= 0 && edge->v[0] < p->vertexCount && edge->v[1] >= 0 && edge->v[1] < p->vertexCount &&
          edge->f[0] >= 0 && edge->f[0] < p->faceCount && edge->f[1] >= 0 && edge->f[1] < p->faceCount) {
        fwd = side_position(p, edge->f[0], edge->v[0], edge->v[1]);
        back = side_position(p, edge->f[1], edge->v[1], edge->v[0]);
      }
      if (fwd < 0 || back < 0 || listed[fwd] || listed[back]) {
        pd_error_set(why, NULL, 0, 0, "edge %d is not walked v0->v1 by its face f0 and v1->v0 by f1, or is listed twice", e);
        ok = false;
      } else {
        listed[fwd] = listed[back] = 1;
      }
    }
    free(listed);
  }
  for (int e = 0; ok && e < p->edgeCount; ++e) {
    const pdEdge* edge = &p->edges[e];
    pdVec3 n0 = p->faces[edge->f[0]].normal, n1 = p->faces[edge->f[1]].normal;
    if (pd_v3_norm(pd_v3_cross(n0, n1)) <= PD_PLANARITY_TOL_REL && pd_v3_dot(n0, n1) > 0.0) {
      pd_error_set(why, NULL, 0, 0, "faces %d and %d are coplanar neighbours", edge->f[0], edge->f[1]);
      ok = false;
    }
  }
  return ok;
}

void pd_polyhedron_translate(pdPolyhedron* p, pdVec3 shift) {
  for (int v = 0; v < p->vertexCount; ++v) p->vertices[v] = pd_v3_add(p->vertices[v], shift);
  for (int f = 0; f < p->faceCount; ++f) p->faces[f].offset += pd_v3_dot(p->faces[f].normal, shift);
  // the interference test's structures hold positions (and edge vectors, rounded from these vertices)
  if (p->satIndex) {
    pd_sat_index_free(p->satIndex);
    pd_sat_index_build(p);
  }
}

void pd_polyhedron_copy(pdPolyhedron* out, const pdPolyhedron* p) {
  int sides = 0;
  for (int f = 0; f < p->faceCount; ++f) sides += p->faces[f].count;
  *out = *p;
  out->vertices = pd_zeroed((size_t)p->vertexCount, sizeof *out->vertices);
  out->edges = pd_zeroed((size_t)p->edgeCount, sizeof *out->edges);
  out->faces = pd_zeroed((size_t)p->faceCount, sizeof *out->faces);
  out->faceVertices = pd_zeroed((size_t)sides, sizeof *out->faceVertices);
  memcpy(out->vertices, p->vertices, (size_t)p->vertexCount * sizeof *out->vertices);
  memcpy(out->edges, p->edges, (size_t)p->edgeCount * sizeof *out->edges);
  memcpy(out->faces, p->faces, (size_t)p->faceCount * sizeof *out->faces);
  memcpy(out->faceVertices, p->faceVertices, (size_t)sides * sizeof *out->faceVertices);
  // the index is formed from the positions alone, so formed again it is the same
  out->satIndex = NULL;
  if (p->satIndex) pd_sat_index_build(out);
}

void pd_polyhedron_free(pdPolyhedron* p) {
  pd_sat_index_free(p->satIndex);
  free(p->vertices);
  free(p->edges);
  free(p->faces);
  free(p->faceVertices);
  memset(p, 0, sizeof *p);
}
