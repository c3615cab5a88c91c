// polydyn — interference of two convex polyhedra by the separating-axis test (conventions in
// interference.h).
//
// Design
// - The paper (§4.3) looks for a separating plane through an edge of A or of B. Its modern form is the
//   separating-axis test over the face normals of the Minkowski difference A ⊖ B: A and B are disjoint
//   exactly when the origin lies outside A ⊖ B, i.e. when one of its face planes separates, and the
//   plane nearest the origin gives the penetration depth when they overlap. The faces of A ⊖ B come
//   from the faces of A, the faces of B, and the edge pairs whose Gauss-map arcs cross (Gregorius,
//   "The Separating Axis Test between convex polyhedra", GDC 2013): edge e of A spans the arc between
//   its two face normals on the unit sphere, edge f of B the arc between its two normals negated; the
//   pair is a Minkowski face when the two arcs intersect. Pairs whose arcs do not cross have a cross
//   product that is not a face normal of A ⊖ B, so it can add no separating direction that the faces
//   do not already give, and cannot lower the depth of an overlapping pair (see the property test
//   against the brute-force SAT over all edge pairs in tests/engine/test_interference.c).
// - Everything is computed in A's frame: B's pose relative to A (R = R_Aᵀ R_B, t = R_Aᵀ (x_B − x_A))
//   is formed once per call, and B's geometry is transformed on the fly: a face of A needs Rᵀ n once
//   and then dot products with B's body-frame vertices; an edge of B is transformed once and then
//   paired with every edge of A (outer loop over B's edges). No scratch memory at all.
// - For a Minkowski-face edge pair the two edges are the supporting features along the axis, so the
//   overlap is u·(p_A − p_B) with one vertex of each edge: O(1), no support search.
// - The cache holds the feature of the last result. In PD_SAT_FIRST_SEPARATING mode it is evaluated
//   first with the very same helper (bit for bit) as in the full search, and only if it is still a
//   candidate axis; so a cached separating axis proves exactly what the full search would find, and the
//   verdict never depends on the cache. Support searches are linear scans over the vertices (the
//   polyhedra here have at most a few hundred vertices; hill climbing would need adjacency lists).
#include "interference.h"

#include <math.h>

#include "polydyn/error.h"

typedef struct relPose {
  pdMat3 R;  // B's body axes in A's frame
  pdVec3 t;  // B's origin in A's frame
} relPose;

// An edge of B with its two face normals, in A's frame.
typedef struct edgeData {
  pdVec3 n0, n1;  // normals of faces f[0] and f[1]
  pdVec3 e;       // v[1] − v[0]
  pdVec3 p;       // v[0]
  double len;     // |e|
} edgeData;

// Edge i of B, in A's frame.
static edgeData edge_of_B(const pdPolyhedron* B, int i, const relPose* f) {
  const pdEdge* edge = &B->edges[i];
  pdVec3 p = B->vertices[edge->v[0]], e = pd_v3_sub(B->vertices[edge->v[1]], p);
  edgeData d;
  d.n0 = pd_mat3_mulv(&f->R, B->faces[edge->f[0]].normal);
  d.n1 = pd_mat3_mulv(&f->R, B->faces[edge->f[1]].normal);
  d.p = pd_v3_add(f->t, pd_mat3_mulv(&f->R, p));
  d.e = pd_mat3_mulv(&f->R, e);
  d.len = pd_v3_norm(e);
  return d;
}

// min over the vertices of P of u·p (finite input: a plain comparison rather than a call to fmin)
static double min_projection(const pdPolyhedron* P, pdVec3 u) {
  double lo = INFINITY;
  for (int v = 0; v < P->vertexCount; ++v) {
    double d = pd_v3_dot(u, P->vertices[v]);
    lo = d < lo ? d : lo;
  }
  return lo;
}

// Overlap along u = n_A (face i of A).
static double face_A_overlap(const pdPolyhedron* A, int i, const pdPolyhedron* B, const relPose* f) {
  pdVec3 n = A->faces[i].normal, m = pd_mat3_tmulv(&f->R, n);  // n in B's frame
  double lo = min_projection(B, m);
  return A->faces[i].offset - (pd_v3_dot(n, f->t) + lo);
}

// Overlap along u = −n_B (face i of B); *axis receives u in A's frame.
static double face_B_overlap(const pdPolyhedron* A, const pdPolyhedron* B, int i, const relPose* f, pdVec3* axis) {
  pdVec3 n = pd_mat3_mulv(&f->R, B->faces[i].normal);  // n_B in A's frame
  double offset = B->faces[i].offset + pd_v3_dot(n, f->t);
  double lo = min_projection(A, n);
  *axis = pd_v3_scale(n, -1.0);
  return offset - lo;
}

// Strict sign tests (a zero is neither sign) without branches: the first one rejects about half of all
// edge pairs at random, a branch the processor cannot predict. Products of these dot products cannot
// underflow for edges longer than ~1e-150 m.
static inline bool opposite_signs(double x, double y) { return x * y < 0.0; }
static inline bool same_signs(double x, double y) { return x * y > 0.0; }

// Edge pair (edge i of A, edge b of B in A's frame): false when it is not a candidate axis (its
// Gauss-map arcs do not cross, or the edges are parallel to PD_SAT_PARALLEL_TOL); else its overlap and
// axis. A's edge data are read only as far as the test needs them: this is the innermost loop.
static inline bool edge_pair_overlap(const pdPolyhedron* A, int i, const edgeData* b, double* overlap, pdVec3* axis) {
  // Arcs: A's from n0_A to n1_A; B's, negated, from c = −n0_B to d = −n1_B. With the edge convention of
  // polyhedron.h (face f[0] walks v[0]→v[1]) n_f0 × n_f1 points along +e, so the arc planes' normals
  // are n1_A × n0_A ∝ −e_A and d × c ∝ −e_B. Gregorius's test, with those substituted:
  //   c·(b×a) and d·(b×a) of opposite signs (B's arc crosses A's great circle),
  //   a·(d×c) and b·(d×c) of opposite signs (A's arc crosses B's great circle),
  //   c·(b×a) and b·(d×c) of the same sign (the crossings are the same point, not antipodes).
  const pdEdge* edge = &A->edges[i];
  pdVec3 pA = A->vertices[edge->v[0]], eA = pd_v3_sub(A->vertices[edge->v[1]], pA);
  double cba = pd_v3_dot(b->n0, eA);  // (−n0_B)·(−e_A)
  double dba = pd_v3_dot(b->n1, eA);  // (−n1_B)·(−e_A)
  if (!opposite_signs(cba, dba)) return false;
  pdVec3 n0 = A->faces[edge->f[0]].normal, n1 = A->faces[edge->f[1]].normal;
  double adc = -pd_v3_dot(n0, b->e);  // n0_A·(−e_B)
  double bdc = -pd_v3_dot(n1, b->e);  // n1_A·(−e_B)
  if (!opposite_signs(adc, bdc) || !same_signs(cba, bdc)) return false;
  pdVec3 u = pd_v3_cross(eA, b->e);
  double len = pd_v3_norm(u);
  if (!(len >= PD_SAT_PARALLEL_TOL * pd_v3_norm(eA) * b->len)) return false;
  // The arcs cross at ±u: on A's arc u·(n0_A + n1_A) > 0, on B's negated arc u·(n0_B + n1_B) < 0.
  pdVec3 s = pd_v3_sub(pd_v3_add(n0, n1), pd_v3_add(b->n0, b->n1));
  u = pd_v3_scale(u, (pd_v3_dot(u, s) < 0.0 ? -1.0 : 1.0) / len);
  *axis = u;
  *overlap = pd_v3_dot(u, pd_v3_sub(pA, b->p));  // both edges support their body along ±u
  return true;
}

typedef struct best {
  double depth;
  pdVec3 axis;  // A's frame
  pdSatFeature kind;
  int a, b;
} best;

// The cached feature's overlap, when it is still a candidate axis.
static bool cached_overlap(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, const pdSatCache* c,
                           best* out) {
  out->kind = c->kind;
  out->a = c->a;
  out->b = c->b;
  switch (c->kind) {
    case PD_SAT_FACE_A:
      if (c->a < 0 || c->a >= A->faceCount) return false;
      out->depth = face_A_overlap(A, c->a, B, f);
      out->axis = A->faces[c->a].normal;
      return true;
    case PD_SAT_FACE_B:
      if (c->b < 0 || c->b >= B->faceCount) return false;
      out->depth = face_B_overlap(A, B, c->b, f, &out->axis);
      return true;
    case PD_SAT_EDGES: {
      if (c->a < 0 || c->a >= A->edgeCount || c->b < 0 || c->b >= B->edgeCount) return false;
      edgeData eb = edge_of_B(B, c->b, f);
      return edge_pair_overlap(A, c->a, &eb, &out->depth, &out->axis);
    }
    case PD_SAT_NONE:
      return false;
  }
  return false;
}

bool pd_interference(const pdPolyhedron* A, pdVec3 xA, const pdMat3* RA, const pdPolyhedron* B, pdVec3 xB,
                     const pdMat3* RB, pdSatMode mode, pdSatCache* cache, pdSatResult* out) {
  PD_ASSERT(A != NULL && B != NULL && RA != NULL && RB != NULL && out != NULL);
  PD_ASSERT(A->faceCount > 0 && B->faceCount > 0);
  PD_ASSERT(pd_v3_isfinite(xA) && pd_v3_isfinite(xB));
  for (int r = 0; r < 3; ++r)
    PD_ASSERT(isfinite(RA->m[r][0] + RA->m[r][1] + RA->m[r][2]) && isfinite(RB->m[r][0] + RB->m[r][1] + RB->m[r][2]));
  pdMat3 RAt = pd_mat3_transpose(RA);
  relPose f = {pd_mat3_mul(&RAt, RB), pd_mat3_mulv(&RAt, pd_v3_sub(xB, xA))};
  bool early = mode == PD_SAT_FIRST_SEPARATING;
  best b = {INFINITY, {0, 0, 0}, PD_SAT_NONE, -1, -1};
  int minkowski = 0;

  if (early && cache && cached_overlap(A, B, &f, cache, &b) && b.depth < 0.0) goto done;
  b = (best){INFINITY, {0, 0, 0}, PD_SAT_NONE, -1, -1};

  for (int i = 0; i < A->faceCount; ++i) {
    double d = face_A_overlap(A, i, B, &f);
    if (d < b.depth) {
      b = (best){d, A->faces[i].normal, PD_SAT_FACE_A, i, -1};
      if (early && d < 0.0) goto done;
    }
  }
  for (int i = 0; i < B->faceCount; ++i) {
    pdVec3 axis;
    double d = face_B_overlap(A, B, i, &f, &axis);
    if (d < b.depth) {
      b = (best){d, axis, PD_SAT_FACE_B, -1, i};
      if (early && d < 0.0) goto done;
    }
  }
  for (int j = 0; j < B->edgeCount; ++j) {
    edgeData eb = edge_of_B(B, j, &f);
    for (int i = 0; i < A->edgeCount; ++i) {
      double d;
      pdVec3 axis;
      if (!edge_pair_overlap(A, i, &eb, &d, &axis)) continue;
      ++minkowski;
      if (d < b.depth) {
        b = (best){d, axis, PD_SAT_EDGES, i, j};
        if (early && d < 0.0) goto done;
      }
    }
  }

done:
  out->separated = b.depth < 0.0;
  out->depth = b.depth;
  out->axis = pd_mat3_mulv(RA, b.axis);
  out->kind = b.kind;
  out->a = b.a;
  out->b = b.b;
  out->minkowskiEdgePairs = minkowski;
  if (cache) *cache = (pdSatCache){b.kind, b.a, b.b};
  return !out->separated;
}
