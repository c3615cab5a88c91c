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
//   paired with every edge of A (outer loop over B's edges). No scratch memory but bit sets on the stack.
// - Every polyhedron built by the constructors carries a pdSatIndex (built with it, and again by
//   pd_polyhedron_translate) with what the culling bounds need: the vertex average with the inradius and
//   circumradius about it; and, with many edges, each edge as one record (its vector, face normals, length
//   and first vertex, computed exactly as the loop would from the polyhedron, so the same bits; a small
//   polyhedron's arrays are read directly: fewer cache lines). The culling bounds (cull_bounds)
//   are lower bounds of the overlap along whole families of axes — a face's, an edge's arc's — from the
//   ball of the inradius inside each body: an axis whose bound exceeds the best depth so far (by a margin
//   above rounding) cannot be the result, nor tie with it, so it is skipped, and only the axes the result
//   could come from are evaluated. Since the best depth only decreases, the skipped axes stay beaten, and
//   the first separating axis in PD_SAT_FIRST_SEPARATING mode is the same one. Faces are culled only
//   against a body searched by linear scan (a downhill walk starts where the previous face's ended, so
//   skipping a face could change where a walk stops among supports that tie to rounding); edges are
//   culled on both bodies, once per call, into bit sets that the edge-pair loops go through in index
//   order. So verdicts, depths, axes and features are unchanged to the bit; only the work counter
//   minkowskiEdgePairs counts fewer pairs. Polyhedra filled in by hand (no pdSatIndex) are searched
//   without culling.
// - For a Minkowski-face edge pair the two edges are the supporting features along the axis, so the
//   overlap is u·(p_A − p_B) with one vertex of each edge: O(1), no support search.
// - Polyhedra with many features carry search structures too (in their pdSatIndex): the
//   support along a face axis is found by walking downhill over the vertex graph from the previous face's
//   support (a local minimum of a linear function on a convex polyhedron is the minimum), and the edge
//   pairs are narrowed to those whose Gauss-map arcs can cross: each arc lies in a spherical cap, A's
//   caps are sorted by the low end of their z band (A's frame, which is A's body frame here), and an edge
//   of B meets only the edges of A whose bands overlap its own. The candidates are visited in the same
//   order as the exhaustive loop (a bit set over A's edges), so results and ties are unchanged.
// - The cache holds the feature of the last result. In PD_SAT_FIRST_SEPARATING mode it is evaluated
//   first with the very same helper (bit for bit) as in the full search, and only if it is still a
//   candidate axis; so a cached separating axis proves exactly what the full search would find, and the
//   verdict never depends on the cache. Support searches are linear scans over the vertices (the
//   polyhedra without search structures have at most a few dozen vertices).
// - Certificates (PD_SAT_VERDICT). Proving an overlap by the separating-axis test takes every candidate axis;
//   GJK (Gilbert, Johnson and Keerthi) proves it with a few support points of the Minkowski difference
//   M = B − A, and proves a separation with one direction. libccd's GJK (the oracle's) answers with its own
//   tolerance and returns neither proof, so the verdict mode runs a GJK of its own as a search for proofs
//   that are then checked on their own terms, with a margin m = PD_GJK_MARGIN_REL × the pair's coordinate
//   size (the size of the culling bounds): (1) difference points whose hull (GJK's tetrahedron, fattened as
//   EPA does when it is thin) holds the ball of radius m about the origin: then M holds it, the overlap along
//   every axis is at least m, and every candidate axis as computed (off by at most ~1e-8 of the size, for the
//   sliver edge pairs) overlaps; (2) a direction d whose support point s of M has s·d < −m |d|: the bodies are
//   apart by more than m along d, so M lies beyond one of its own face planes (one of the candidate axes) and
//   the separating-axis search would find a separating axis. GJK's own bookkeeping (which sub-simplex is kept,
//   the next direction) only steers the search for a proof. Where it stops without one — no progress past its
//   simplex, the origin on the simplex, or the fattened hull's nearest face on M's boundary — the pair is called
//   touching: GJK stops making progress only within ~m of M's boundary (at a gap of more than 1.001 m its
//   support point already certifies the separation), so such a pair touches or is apart by about m at most.
//   Where its bookkeeping goes wrong (the tetrahedron holds the origin but the hull puts it more than m outside,
//   a non-finite direction, PD_GJK_ITERATIONS_MAX iterations) the PD_SAT_FIRST_SEPARATING search decides. "Separated" is thus always the
//   separating-axis search's verdict too (a proof, or the cached axis evaluated by the search's own helper),
//   and "touching" may include pairs apart by up to ~m (1e-7 of the size): the contact search then runs the
//   contact analysis on them, whose own depth tests (1e-12 of the size) find no contact where nothing
//   penetrates. The separating-axis search would decide those pairs exactly, but they are about a fifth of the oracle's random pairs (drawn log-uniformly near touching) and took three quarters of
//   the mode's time there, and in a simulation they are the rare steps that end within 1e-7 of the size of an
//   onset. GJK's support points come from vertex scans (support_vertex).
#include "interference.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "grow.h"
#include "polydyn/error.h"

// A z band is widened by this (no unit: z of unit vectors) on each side. Arcs that really cross share a
// point, so their bands overlap in exact arithmetic; the margin covers rounding (~1e-15) and the arcs the
// sign tests of edge_pair_overlap might call crossing when they miss by a rounding error, so no pair the
// exhaustive loop would evaluate is dropped.
#define PD_SAT_CAP_MARGIN 1e-9
// Adjacent faces whose normals sum to less than this (nearly opposite: a zero-thickness edge) get a cap
// over the whole sphere.
#define PD_SAT_CAP_DEGENERATE 1e-6
// B's arc is dropped before the full Gauss-map test when both its normals lie on one side of A's edge's
// great circle by more than this times |e_A| (no unit: normals are unit): the full test computes the same
// signs in A's frame, where rounding may differ by ~1e-16 |e_A|, so no pair it would accept is dropped.
#define PD_SAT_STRADDLE_MARGIN 1e-12
// The culling bounds' margin and knife edges: see cull_bounds.
#define PD_SAT_CULL_MARGIN 1e-5
#define PD_SAT_CULL_KNIFE 1e-3
// Edges of A a bit set covers (64 per word, on the stack); past it the exhaustive loop runs.
#define PD_SAT_BITSET_WORDS 1024

// An edge as the edge-pair test reads it, in one record (one cache line and a half instead of four
// scattered loads); the same operations as from the polyhedron, so the same bits.
typedef struct satEdge {
  pdVec3 e;       // v[1] − v[0]
  pdVec3 n0, n1;  // normals of faces f[0] and f[1]
  double len;     // |e|
  pdVec3 p;       // v[0]
} satEdge;

static inline satEdge edge_record(const pdPolyhedron* P, int i) {
  const pdEdge* edge = &P->edges[i];
  satEdge r;
  r.e = pd_v3_sub(P->vertices[edge->v[1]], P->vertices[edge->v[0]]);
  r.n0 = P->faces[edge->f[0]].normal;
  r.n1 = P->faces[edge->f[1]].normal;
  r.len = pd_v3_norm(r.e);
  r.p = P->vertices[edge->v[0]];
  return r;
}

// Bit i of a bit set.
static inline bool bit_is_set(const uint64_t* bits, int i) { return bits[i >> 6] >> (i & 63) & 1; }

struct pdSatIndex {
  // Every polyhedron (positions: pd_polyhedron_translate builds the index again):
  pdVec3 centre;        // the vertex average (strictly inside), m
  double inradius;      // distance from it to the nearest face plane, m
  double circumradius;  // to the farthest vertex, m
  bool acuteEdge;       // two faces meet at less than 90° (pd_polyhedron_has_acute_edge)
  bool cuboid;          // the vertices are the 8 corners of the body-frame box [lo, hi] (pd_polyhedron_cuboid)
  pdVec3 lo, hi;        // that box, m (set when cuboid)
  // Polyhedra with PD_SAT_INDEX_MIN_EDGES edges or more, else NULL (small ones: edge_record on the fly):
  satEdge* edge;        // (E)
  int* neighbourFirst;  // (V + 1) vertex v's neighbours are neighbours[neighbourFirst[v] .. neighbourFirst[v+1])
  int* neighbours;      // (2E)
  int* byZ;             // (E) edge indices sorted by the low end of their arc's z band (arc_band, body frame)
  double* zLo;          // (E) in byZ order
  double* zHi;          // (E) in byZ order
  double zSpanMax;      // the widest band
};

// Edge i of P as a record: the stored one when P keeps records, else formed in *scratch.
static inline const satEdge* edge_at(const pdPolyhedron* P, int i, satEdge* scratch) {
  if (P->satIndex && P->satIndex->edge) return &P->satIndex->edge[i];
  *scratch = edge_record(P, i);
  return scratch;
}

// The band [lo, hi] of u·axis (axis a unit vector) over the Gauss-map arc from unit n0 to unit n1 (not
// antipodal), widened by PD_SAT_CAP_MARGIN: the arc lies in the cap of centre c = (n0 + n1)/|n0 + n1| and
// half-angle r (cos r = c·n0), whose polar angle about the axis spans [θc − r, θc + r], clipped to
// [0, π] where the cap holds a pole. Nearly antipodal normals get the whole range.
static void arc_band(pdVec3 n0, pdVec3 n1, pdVec3 axis, double* lo, double* hi) {
  pdVec3 sum = pd_v3_add(n0, n1);
  double len = pd_v3_norm(sum);
  if (len < PD_SAT_CAP_DEGENERATE) {
    *lo = -1.0 - PD_SAT_CAP_MARGIN;
    *hi = 1.0 + PD_SAT_CAP_MARGIN;
    return;
  }
  pdVec3 c = pd_v3_scale(sum, 1.0 / len);
  double cz = pd_v3_dot(c, axis), cosR = fmin(1.0, pd_v3_dot(c, n0));
  double sinR = sqrt(fmax(0.0, 1.0 - cosR * cosR)), s = sqrt(fmax(0.0, 1.0 - cz * cz));
  *hi = (cz >= cosR ? 1.0 : cz * cosR + s * sinR) + PD_SAT_CAP_MARGIN;
  *lo = (-cz >= cosR ? -1.0 : cz * cosR - s * sinR) - PD_SAT_CAP_MARGIN;
}

static const double* sortKeys;  // qsort has no context argument: set just around the call (build time only)
static int compare_z(const void* a, const void* b) {
  double x = sortKeys[*(const int*)a], y = sortKeys[*(const int*)b];
  if (x != y) return x < y ? -1 : 1;
  return *(const int*)a - *(const int*)b;
}

// Do two faces of p meet at an edge at less than 90°: their outward normals more than 90° apart by more than
// PD_ACUTE_EDGE_COS?
static bool acute_edge(const pdPolyhedron* p) {
  for (int e = 0; e < p->edgeCount; ++e)
    if (pd_v3_dot(p->faces[p->edges[e].f[0]].normal, p->faces[p->edges[e].f[1]].normal) < -PD_ACUTE_EDGE_COS) return true;
  return false;
}

bool pd_polyhedron_has_acute_edge(const pdPolyhedron* p) { return p->satIndex ? p->satIndex->acuteEdge : acute_edge(p); }

// Are p's vertices the 8 corners of its body-frame box, each coordinate exactly its low or its high value (a cube
// primitive, translated to its centre of mass)? Sets x->lo and x->hi then.
static void find_cuboid(const pdPolyhedron* p, struct pdSatIndex* x) {
  x->cuboid = false;
  if (p->vertexCount != 8) return;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int v = 0; v < 8; ++v) {
    const double c[3] = {p->vertices[v].x, p->vertices[v].y, p->vertices[v].z};
    for (int k = 0; k < 3; ++k) lo[k] = fmin(lo[k], c[k]), hi[k] = fmax(hi[k], c[k]);
  }
  unsigned corners = 0;  // bit (corner index) set for each corner met
  for (int v = 0; v < 8; ++v) {
    const double c[3] = {p->vertices[v].x, p->vertices[v].y, p->vertices[v].z};
    int corner = 0;
    for (int k = 0; k < 3; ++k) {
      if (c[k] != lo[k] && c[k] != hi[k]) return;
      corner |= (c[k] == hi[k]) << k;
    }
    corners |= 1u << corner;
  }
  if (corners != 0xffu || !(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2])) return;
  x->cuboid = true;
  x->lo = (pdVec3){lo[0], lo[1], lo[2]};
  x->hi = (pdVec3){hi[0], hi[1], hi[2]};
}

bool pd_polyhedron_cuboid(const pdPolyhedron* p, pdVec3* lo, pdVec3* hi) {
  if (!p->satIndex || !p->satIndex->cuboid) return false;
  *lo = p->satIndex->lo;
  *hi = p->satIndex->hi;
  return true;
}

void pd_sat_index_build(pdPolyhedron* p) {
  struct pdSatIndex* x = pd_zeroed(1, sizeof *x);
  p->satIndex = x;
  int V = p->vertexCount, E = p->edgeCount, F = p->faceCount;
  pdVec3 c = {0, 0, 0};
  for (int v = 0; v < V; ++v) c = pd_v3_add(c, p->vertices[v]);
  c = pd_v3_scale(c, 1.0 / V);
  x->centre = c;
  x->inradius = INFINITY;
  for (int f = 0; f < F; ++f) x->inradius = fmin(x->inradius, p->faces[f].offset - pd_v3_dot(p->faces[f].normal, c));
  x->inradius = fmax(0.0, x->inradius);
  for (int v = 0; v < V; ++v) x->circumradius = fmax(x->circumradius, pd_v3_norm(pd_v3_sub(p->vertices[v], c)));
  x->acuteEdge = acute_edge(p);
  find_cuboid(p, x);
  if (E < PD_SAT_INDEX_MIN_EDGES) return;
  x->edge = pd_zeroed((size_t)E, sizeof *x->edge);
  for (int e = 0; e < E; ++e) x->edge[e] = edge_record(p, e);
  x->neighbourFirst = pd_zeroed((size_t)V + 1, sizeof *x->neighbourFirst);
  x->neighbours = pd_zeroed(2 * (size_t)E, sizeof *x->neighbours);
  for (int e = 0; e < E; ++e) ++x->neighbourFirst[p->edges[e].v[0] + 1], ++x->neighbourFirst[p->edges[e].v[1] + 1];
  for (int v = 0; v < V; ++v) x->neighbourFirst[v + 1] += x->neighbourFirst[v];
  int* fill = pd_zeroed((size_t)V, sizeof *fill);
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < 2; ++k) {
      int v = p->edges[e].v[k];
      x->neighbours[x->neighbourFirst[v] + fill[v]++] = p->edges[e].v[1 - k];
    }
  free(fill);
  double* lo = pd_zeroed((size_t)E, sizeof *lo);
  double* hi = pd_zeroed((size_t)E, sizeof *hi);
  x->byZ = pd_zeroed((size_t)E, sizeof *x->byZ);
  for (int e = 0; e < E; ++e) {
    arc_band(p->faces[p->edges[e].f[0]].normal, p->faces[p->edges[e].f[1]].normal, (pdVec3){0, 0, 1}, &lo[e], &hi[e]);
    x->byZ[e] = e;
  }
  sortKeys = lo;
  qsort(x->byZ, (size_t)E, sizeof *x->byZ, compare_z);
  sortKeys = NULL;
  x->zLo = pd_zeroed((size_t)E, sizeof *x->zLo);
  x->zHi = pd_zeroed((size_t)E, sizeof *x->zHi);
  for (int k = 0; k < E; ++k) {
    x->zLo[k] = lo[x->byZ[k]];
    x->zHi[k] = hi[x->byZ[k]];
    x->zSpanMax = fmax(x->zSpanMax, x->zHi[k] - x->zLo[k]);
  }
  free(lo);
  free(hi);
}

void pd_sat_index_free(struct pdSatIndex* x) {
  if (!x) return;
  free(x->edge);
  free(x->neighbourFirst);
  free(x->neighbours);
  free(x->byZ);
  free(x->zLo);
  free(x->zHi);
  free(x);
}

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

// Edge i of B, in A's frame (from B's record when it has one).
static edgeData edge_of_B(const pdPolyhedron* B, int i, const relPose* f) {
  satEdge scratch;
  const satEdge* r = edge_at(B, i, &scratch);
  edgeData d;
  d.n0 = pd_mat3_mulv(&f->R, r->n0);
  d.n1 = pd_mat3_mulv(&f->R, r->n1);
  d.p = pd_v3_add(f->t, pd_mat3_mulv(&f->R, r->p));
  d.e = pd_mat3_mulv(&f->R, r->e);
  d.len = r->len;
  return d;
}

// The first vertex of P minimising u·p, by a scan (finite input: a plain comparison rather than fmin). GJK
// uses it for every polyhedron: its directions jump between iterations, and on the oracle's pairs a scan was
// faster than min_projection's downhill walk even over the 642 vertices of a geodesic sphere (1.25 against
// 1.40 times libccd's GJK over all pairs).
static int support_vertex(const pdPolyhedron* P, pdVec3 u) {
  int best = 0;
  double lo = pd_v3_dot(u, P->vertices[0]);
  for (int v = 1; v < P->vertexCount; ++v) {
    double d = pd_v3_dot(u, P->vertices[v]);
    if (d < lo) lo = d, best = v;
  }
  return best;
}

// min over the vertices of P of u·p: a scan (support_vertex), or with P's search structures a steepest-descent
// walk over the vertex graph from *start (the previous axis's support, usually a few edges away), which ends at
// the minimum; *start receives the support.
static double min_projection(const pdPolyhedron* P, pdVec3 u, int* start) {
  const struct pdSatIndex* x = P->satIndex;
  if (x && x->neighbourFirst) {
    int v = *start;
    double lo = pd_v3_dot(u, P->vertices[v]);
    for (;;) {
      int next = -1;
      for (int k = x->neighbourFirst[v]; k < x->neighbourFirst[v + 1]; ++k) {
        double d = pd_v3_dot(u, P->vertices[x->neighbours[k]]);
        if (d < lo) lo = d, next = x->neighbours[k];
      }
      if (next < 0) break;
      v = next;
    }
    *start = v;
    return lo;
  }
  return pd_v3_dot(u, P->vertices[support_vertex(P, u)]);
}

// Overlap along u = n_A (face i of A). *support: see min_projection.
static double face_A_overlap(const pdPolyhedron* A, int i, const pdPolyhedron* B, const relPose* f, int* support) {
  pdVec3 n = A->faces[i].normal, m = pd_mat3_tmulv(&f->R, n);  // n in B's frame
  double lo = min_projection(B, m, support);
  return A->faces[i].offset - (pd_v3_dot(n, f->t) + lo);
}

// Overlap along u = −n_B (face i of B); *axis receives u in A's frame. *support: see min_projection.
static double face_B_overlap(const pdPolyhedron* A, const pdPolyhedron* B, int i, const relPose* f, pdVec3* axis,
                             int* support) {
  pdVec3 n = pd_mat3_mulv(&f->R, B->faces[i].normal);  // n_B in A's frame
  double offset = B->faces[i].offset + pd_v3_dot(n, f->t);
  double lo = min_projection(A, n, support);
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
  satEdge scratch;
  const satEdge* ea = edge_at(A, i, &scratch);
  pdVec3 eA = ea->e;
  double cba = pd_v3_dot(b->n0, eA);  // (−n0_B)·(−e_A)
  double dba = pd_v3_dot(b->n1, eA);  // (−n1_B)·(−e_A)
  if (!opposite_signs(cba, dba)) return false;
  pdVec3 n0 = ea->n0, n1 = ea->n1;
  double adc = -pd_v3_dot(n0, b->e);  // n0_A·(−e_B)
  double bdc = -pd_v3_dot(n1, b->e);  // n1_A·(−e_B)
  if (!opposite_signs(adc, bdc) || !same_signs(cba, bdc)) return false;
  pdVec3 u = pd_v3_cross(eA, b->e);
  double len = pd_v3_norm(u);
  if (!(len >= PD_SAT_PARALLEL_TOL * ea->len * b->len)) return false;
  // The arcs cross at ±u: on A's arc u·(n0_A + n1_A) > 0, on B's negated arc u·(n0_B + n1_B) < 0.
  pdVec3 s = pd_v3_sub(pd_v3_add(n0, n1), pd_v3_add(b->n0, b->n1));
  u = pd_v3_scale(u, (pd_v3_dot(u, s) < 0.0 ? -1.0 : 1.0) / len);
  *axis = u;
  *overlap = pd_v3_dot(u, pd_v3_sub(ea->p, b->p));  // both edges support their body along ±u
  return true;
}

typedef struct best {
  double depth;
  pdVec3 axis;  // A's frame
  pdSatFeature kind;
  int a, b;
} best;

// Edge i of A against edge j of B (eb): when a candidate axis, counts it and keeps it in *b if deeper.
// A tie with an earlier edge pair goes to the lower (j, i), as the exhaustive loop (j outer, i inner)
// visits them, so that the result does not depend on the order of the visits; a tie with a face stays
// with the face. Returns whether *b changed.
static inline bool visit_edge_pair(const pdPolyhedron* A, int i, const edgeData* eb, int j, best* b, int* minkowski) {
  double d;
  pdVec3 axis;
  if (!edge_pair_overlap(A, i, eb, &d, &axis)) return false;
  ++*minkowski;
  bool earlier = d == b->depth && b->kind == PD_SAT_EDGES && (j < b->b || (j == b->b && i < b->a));
  if (!(d < b->depth) && !earlier) return false;
  *b = (best){d, axis, PD_SAT_EDGES, i, j};
  return true;
}

// The number of leading entries of the ascending a[0..n) below key (or at most key when inclusive).
static int count_below(const double* a, int n, double key, bool inclusive) {
  int lo = 0, hi = n;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (a[mid] < key || (inclusive && a[mid] == key))
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// The set (one bit per edge, in (edges + 63)/64 words) of the indexed polyhedron's edges whose z bands
// meet [lo, hi]: byZ positions [first, last), zLo from lo − zSpanMax to hi, with zHi >= lo.
static void band_candidates(const struct pdSatIndex* x, int edges, double lo, double hi, uint64_t* bits) {
  int first = count_below(x->zLo, edges, lo - x->zSpanMax, false), last = count_below(x->zLo, edges, hi, true);
  for (int w = 0; w < (edges + 63) / 64; ++w) bits[w] = 0;
  for (int k = first; k < last; ++k)
    if (x->zHi[k] >= lo) bits[x->byZ[k] >> 6] |= (uint64_t)1 << (x->byZ[k] & 63);
}

// The culling bounds (design note). For a unit axis u the overlap is h_A(u) + h_B(−u) (h the support
// function), and a body holds the ball of its inradius r about its vertex average c, so h_A(u) >= u·c_A + r_A
// and likewise for B. A face axis has one of the two terms exactly (its plane). An edge-pair axis lies on
// both edges' arcs, where each edge supports its body, so h_A(u) = u·p_i for a vertex p_i of A's edge i and
// h_B(−u) = −u·p_j for B's edge j, and u lies on A's arc and −u on B's. Hence
//   face i of A:  overlap >= offset_i − n_i·c_B + r_B
//   face j of B:  overlap >= offset_j − n_j·c_A + r_A                  (in B's frame)
//   edge i of A:  overlap >= min over v on i's arc of v·(p_i − c_B) + r_B
//   edge j of B:  overlap >= min over v on j's arc of v·(p_j − c_A) + r_A   (in B's frame; v = −u)
// The minimum of v·w over an arc (less than a half circle, from n0 to n1 about +e) is at an end, or, when
// the arc holds the direction of −w's component across e, minus that component's length.
// An axis whose bound exceeds the best depth so far by the margin cannot be taken (it would need
// overlap < best, or a tie), so it is skipped; the margin covers the rounding of the overlap as computed,
// whose worst case is the edge-pair axis of nearly parallel edges, off by ~1e-16 / PD_SAT_PARALLEL_TOL
// ≈ 1e-8 of a radian, i.e. 1e-8 of the pair's size: PD_SAT_CULL_MARGIN times a bound on every coordinate
// involved leaves a factor 1000. A knife edge (normals nearly opposite, |n_f0 + n_f1| below
// PD_SAT_CULL_KNIFE) is never culled: its axis's sign rests on a small dot product.

typedef struct edgeCull {
  pdVec3 other;  // the other body's vertex average, in this body's frame
  double lift;   // the other body's inradius − the margin
} edgeCull;

typedef struct cullBounds {
  bool on;        // both polyhedra carry a pdSatIndex
  pdVec3 cB;      // B's vertex average, A's frame
  pdVec3 cAinB;   // A's vertex average, B's frame
  double rA, rB;  // inradii
  double margin;  // m
  edgeCull edgesA, edgesB;
} cullBounds;

static void cull_bounds(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, cullBounds* c) {
  const struct pdSatIndex *ia = A->satIndex, *ib = B->satIndex;
  c->on = ia && ib;
  if (!c->on) return;
  pdVec3 cA = ia->centre, cBlocal = ib->centre;
  c->cB = pd_v3_add(f->t, pd_mat3_mulv(&f->R, cBlocal));
  c->cAinB = pd_mat3_tmulv(&f->R, pd_v3_sub(cA, f->t));
  c->rA = ia->inradius;
  c->rB = ib->inradius;
  // every coordinate the overlaps are computed from is at most this large
  double size = pd_v3_norm(cA) + ia->circumradius + pd_v3_norm(cBlocal) + ib->circumradius + pd_v3_norm(f->t);
  c->margin = PD_SAT_CULL_MARGIN * size;
  c->edgesA = (edgeCull){c->cB, ib->inradius - c->margin};
  c->edgesB = (edgeCull){c->cAinB, ia->inradius - c->margin};
}

// The bit set of P's edges whose bound (less the margin) does not exceed `depth`.
static void alive_edges(const pdPolyhedron* P, const edgeCull* c, double depth, uint64_t* bits) {
  for (int w = 0; w < (P->edgeCount + 63) / 64; ++w) bits[w] = 0;
  double limit = depth - c->lift;  // alive when the minimum over the arc is at most this
  for (int e = 0; e < P->edgeCount; ++e) {
    satEdge scratch;
    const satEdge* r = edge_at(P, e, &scratch);
    pdVec3 w = pd_v3_sub(r->p, c->other);
    // an end of the arc low enough settles it; else the inside of the arc, when it holds the minimum
    bool alive = pd_v3_dot(r->n0, w) <= limit || pd_v3_dot(r->n1, w) <= limit;
    if (!alive) {
      pdVec3 sum = pd_v3_add(r->n0, r->n1);
      if (pd_v3_dot(sum, sum) < PD_SAT_CULL_KNIFE * PD_SAT_CULL_KNIFE) {
        alive = true;
      } else if (pd_v3_dot(w, pd_v3_cross(r->e, r->n0)) <= 0.0 && pd_v3_dot(w, pd_v3_cross(r->n1, r->e)) <= 0.0) {
        double along = pd_v3_dot(w, r->e) / r->len;
        alive = -sqrt(fmax(0.0, pd_v3_dot(w, w) - along * along)) <= limit;
      }
    }
    if (alive) bits[e >> 6] |= (uint64_t)1 << (e & 63);
  }
}

// GJK's iterations before the separating-axis search decides. Pairs GJK settles take a handful (a few more for
// the geodesic spheres); past this many it is circling a boundary within rounding of the origin.
#define PD_GJK_ITERATIONS_MAX 40

// The support point of M = B − A (A's frame) along d: B's vertex farthest along d less A's farthest along −d.
static pdVec3 difference_support(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, pdVec3 d) {
  int a = support_vertex(A, d);
  int b = support_vertex(B, pd_v3_scale(pd_mat3_tmulv(&f->R, d), -1.0));
  pdVec3 pb = pd_v3_add(f->t, pd_mat3_mulv(&f->R, B->vertices[b]));
  return pd_v3_sub(pb, A->vertices[a]);
}

static pdVec3 triple(pdVec3 a, pdVec3 b, pdVec3 c) { return pd_v3_cross(pd_v3_cross(a, b), c); }

// The line case of GJK's simplex step: s = {.., A} with A newest; keeps the part nearest the origin.
static int simplex_line(pdVec3* s, pdVec3 B, pdVec3 A, pdVec3* d) {
  pdVec3 AB = pd_v3_sub(B, A), AO = pd_v3_scale(A, -1.0);
  if (pd_v3_dot(AB, AO) > 0.0) {
    s[0] = B, s[1] = A;
    *d = triple(AB, AO, AB);
    return 2;
  }
  s[0] = A;
  *d = AO;
  return 1;
}

// The triangle case: C, B, A (A newest).
static int simplex_triangle(pdVec3* s, pdVec3 C, pdVec3 B, pdVec3 A, pdVec3* d) {
  pdVec3 AB = pd_v3_sub(B, A), AC = pd_v3_sub(C, A), AO = pd_v3_scale(A, -1.0);
  pdVec3 ABC = pd_v3_cross(AB, AC);
  if (pd_v3_dot(pd_v3_cross(ABC, AC), AO) > 0.0) {
    if (pd_v3_dot(AC, AO) > 0.0) {
      s[0] = C, s[1] = A;
      *d = triple(AC, AO, AC);
      return 2;
    }
    return simplex_line(s, B, A, d);
  }
  if (pd_v3_dot(pd_v3_cross(AB, ABC), AO) > 0.0) return simplex_line(s, B, A, d);
  if (pd_v3_dot(ABC, AO) > 0.0) {
    s[0] = C, s[1] = B, s[2] = A;
    *d = ABC;
  } else {
    s[0] = B, s[1] = C, s[2] = A;
    *d = pd_v3_scale(ABC, -1.0);
  }
  return 3;
}

// What GJK's search for a certificate found (gjk_certificate).
enum { gjkApart, gjkOverlap, gjkWithinMargin, gjkUndecided };

// The points GJK may hold: the tetrahedron and the points added to fatten it (enclosed_certificate).
#define PD_GJK_POINTS_MAX 8

// The depth of the origin inside the hull of p[0..n) (the origin inside it), m, and the outward unit normal and
// offset of the face plane nearest to it. Every plane through three of the points with every point on its inner
// side (to within `slack`, the rounding of these small sums) bounds the hull, and every face plane is one of
// them, so the least distance over them is the origin's depth in the hull, less the slack. −INFINITY when no
// such plane exists (a flat set).
static double hull_depth(const pdVec3* p, int n, double slack, pdVec3* normal, double* offset) {
  double depth = INFINITY;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        pdVec3 m = pd_v3_cross(pd_v3_sub(p[j], p[i]), pd_v3_sub(p[k], p[i]));
        double len = pd_v3_norm(m);
        if (!(len > 0.0)) continue;
        m = pd_v3_scale(m, 1.0 / len);
        double o = pd_v3_dot(m, p[i]), hi = -INFINITY, lo = INFINITY;
        for (int l = 0; l < n; ++l) {
          double h = pd_v3_dot(m, p[l]) - o;
          hi = h > hi ? h : hi;
          lo = h < lo ? h : lo;
        }
        if (hi > slack && lo < -slack) continue;  // points on both sides: not a supporting plane
        if (hi > slack) m = pd_v3_scale(m, -1.0), o = -o;  // orient it outward
        double d = o - slack;  // the origin's distance below the plane
        if (d < depth) depth = d, *normal = m, *offset = o;
      }
  return isfinite(depth) ? depth : -INFINITY;
}

// The origin lies inside GJK's tetrahedron s[0..4) (as computed). The certificate needs it deeper than the
// margin: while it is not, the nearest face of the hull is pushed out to M's support point along its normal
// (as EPA does), up to PD_GJK_POINTS_MAX points; when that face is M's own (the support does not pass it), the
// origin is within the margin of M's boundary (gjkWithinMargin).
static int enclosed_certificate(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, double margin,
                                pdVec3* s, best* b) {
  double slack = 1e-6 * margin;
  for (int n = 4;; ++n) {
    pdVec3 normal = {0, 0, 0};
    double offset = 0.0, depth = hull_depth(s, n, slack, &normal, &offset);
    if (depth > margin) {
      *b = (best){depth, {0, 0, 0}, PD_SAT_NONE, -1, -1};
      return gjkOverlap;
    }
    if (!(depth > -margin)) return gjkUndecided;  // GJK's bookkeeping and the hull disagree: leave it to the search
    if (n == PD_GJK_POINTS_MAX) return gjkWithinMargin;
    pdVec3 w = difference_support(A, B, f, normal);
    if (!(pd_v3_dot(w, normal) > offset + 1e-3 * margin)) return gjkWithinMargin;  // that face is on M's boundary
    s[n] = w;
  }
}

// The tetrahedron case: D, C, B, A (A newest; the origin lies on A's side of BCD). Returns 4 when the origin
// is inside all four faces (as computed); else the face it lies beyond, as a triangle step.
static int simplex_tetrahedron(pdVec3* s, pdVec3 D, pdVec3 C, pdVec3 B, pdVec3 A, pdVec3* d) {
  pdVec3 AO = pd_v3_scale(A, -1.0);
  const pdVec3 other[3][3] = {{C, B, D}, {D, C, B}, {B, D, C}};  // faces ACB, ADC, ABD and their opposite vertex
  for (int f = 0; f < 3; ++f) {
    pdVec3 P = other[f][0], Q = other[f][1], R = other[f][2];
    pdVec3 n = pd_v3_cross(pd_v3_sub(P, A), pd_v3_sub(Q, A));
    if (pd_v3_dot(n, pd_v3_sub(R, A)) > 0.0) n = pd_v3_scale(n, -1.0);
    if (pd_v3_dot(n, AO) > 0.0) return simplex_triangle(s, P, Q, A, d);
  }
  s[0] = D, s[1] = C, s[2] = B, s[3] = A;
  return 4;
}

// GJK's search for a certificate (design note, "Certificates"): gjkOverlap (b->depth a lower bound on the
// depth), gjkApart (b->depth the gap along b->axis, negated), gjkWithinMargin (neither: the origin within ~the
// margin of M's boundary), gjkUndecided (GJK went wrong: the search decides).
// `start`: the first direction (a cached one, PD_SAT_APART), or zero for the one from B's centre to A's.
static int gjk_certificate(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, const cullBounds* cull,
                           pdVec3 start, best* b) {
  double margin = PD_GJK_MARGIN_REL * cull->margin / PD_SAT_CULL_MARGIN;
  pdVec3 d = start;
  if (!(pd_v3_dot(d, d) > 0.0)) d = pd_v3_sub(A->satIndex->centre, cull->cB);  // from inside M to the origin
  if (!(pd_v3_dot(d, d) > 0.0)) d = (pdVec3){1, 0, 0};
  pdVec3 s[PD_GJK_POINTS_MAX];
  int n = 0;
  for (int iteration = 0; iteration < PD_GJK_ITERATIONS_MAX; ++iteration) {
    double dn = pd_v3_norm(d);
    if (!isfinite(dn)) return gjkUndecided;
    if (!(dn > 0.0)) return gjkWithinMargin;  // the origin on the simplex: in M, within rounding of its boundary
    pdVec3 p = difference_support(A, B, f, d);
    double along = pd_v3_dot(p, d) / dn;  // M's extent along d: the overlap along −d
    if (along < -margin) {
      *b = (best){along, pd_v3_scale(d, -1.0 / dn), PD_SAT_NONE, -1, -1};
      return gjkApart;
    }
    // no progress past the simplex along d: the origin lies within ~margin of M's boundary
    double reached = -INFINITY;
    for (int k = 0; k < n; ++k) {
      double r = pd_v3_dot(s[k], d) / dn;
      reached = r > reached ? r : reached;
    }
    if (n > 0 && along <= reached + 1e-3 * margin) return gjkWithinMargin;
    s[n++] = p;
    switch (n) {
      case 1:
        d = pd_v3_scale(p, -1.0);
        break;
      case 2:
        n = simplex_line(s, s[0], s[1], &d);
        break;
      case 3:
        n = simplex_triangle(s, s[0], s[1], s[2], &d);
        break;
      default:
        n = simplex_tetrahedron(s, s[0], s[1], s[2], s[3], &d);
        if (n == 4) return enclosed_certificate(A, B, f, margin, s, b);
    }
  }
  return gjkUndecided;
}

// The cached feature's overlap, when it is still a candidate axis.
static bool cached_overlap(const pdPolyhedron* A, const pdPolyhedron* B, const relPose* f, const pdSatCache* c,
                           best* out) {
  out->kind = c->kind;
  out->a = c->a;
  out->b = c->b;
  switch (c->kind) {
    case PD_SAT_FACE_A:
      if (c->a < 0 || c->a >= A->faceCount) return false;
      int support = 0;
      out->depth = face_A_overlap(A, c->a, B, f, &support);
      out->axis = A->faces[c->a].normal;
      return true;
    case PD_SAT_FACE_B: {
      if (c->b < 0 || c->b >= B->faceCount) return false;
      int support = 0;
      out->depth = face_B_overlap(A, B, c->b, f, &out->axis, &support);
      return true;
    }
    case PD_SAT_EDGES: {
      if (c->a < 0 || c->a >= A->edgeCount || c->b < 0 || c->b >= B->edgeCount) return false;
      edgeData eb = edge_of_B(B, c->b, f);
      return edge_pair_overlap(A, c->a, &eb, &out->depth, &out->axis);
    }
    case PD_SAT_NONE:
    case PD_SAT_APART:  // a direction, not a candidate axis (PD_SAT_VERDICT reads it itself)
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
  bool early = mode != PD_SAT_MIN_DEPTH;
  best b = {INFINITY, {0, 0, 0}, PD_SAT_NONE, -1, -1};
  int minkowski = 0;
  bool apart = false;  // a separation certified by GJK (PD_SAT_VERDICT): the cache takes its direction

  if (early && cache && cached_overlap(A, B, &f, cache, &b) && b.depth < 0.0) goto done;
  b = (best){INFINITY, {0, 0, 0}, PD_SAT_NONE, -1, -1};

  cullBounds cull;
  cull_bounds(A, B, &f, &cull);
  if (mode == PD_SAT_VERDICT && cull.on) {
    pdVec3 start = cache && cache->kind == PD_SAT_APART ? cache->apart : (pdVec3){0, 0, 0};
    int verdict = gjk_certificate(A, B, &f, &cull, start, &b);
    apart = verdict == gjkApart;
    if (apart) goto done;
    if (verdict != gjkUndecided) {
      // touching: a certified overlap (b.depth its lower bound), or within the margin of touching (depth 0);
      // the cache keeps what it holds
      double depth = verdict == gjkOverlap ? b.depth : 0.0;
      *out = (pdSatResult){false, depth, {0, 0, 0}, PD_SAT_NONE, -1, -1, 0};
      return true;
    }
    b = (best){INFINITY, {0, 0, 0}, PD_SAT_NONE, -1, -1};
  }
  // a polyhedron searched by a downhill walk keeps every face axis (the walk starts where the last ended)
  bool cullFacesA = cull.on && !B->satIndex->neighbourFirst;
  bool cullFacesB = cull.on && !A->satIndex->neighbourFirst;
  int supportB = 0, supportA = 0;
  for (int i = 0; i < A->faceCount; ++i) {
    if (cullFacesA && A->faces[i].offset - pd_v3_dot(A->faces[i].normal, cull.cB) + cull.rB - cull.margin > b.depth)
      continue;
    double d = face_A_overlap(A, i, B, &f, &supportB);
    if (d < b.depth) {
      b = (best){d, A->faces[i].normal, PD_SAT_FACE_A, i, -1};
      if (early && d < 0.0) goto done;
    }
  }
  for (int i = 0; i < B->faceCount; ++i) {
    if (cullFacesB && B->faces[i].offset - pd_v3_dot(B->faces[i].normal, cull.cAinB) + cull.rA - cull.margin > b.depth)
      continue;
    pdVec3 axis;
    double d = face_B_overlap(A, B, i, &f, &axis, &supportA);
    if (d < b.depth) {
      b = (best){d, axis, PD_SAT_FACE_B, -1, i};
      if (early && d < 0.0) goto done;
    }
  }
  // Edge pairs. With A's search structures: B's edges outer, each meeting the edges of A whose arcs' z
  // bands (A's frame) meet its own negated arc's, in index order. With B's only: A's (few) edges outer,
  // each meeting the edges of B whose bands (along B's z) meet its own negated arc's and whose normals
  // straddle its great circle, tested in B's own frame (no transform) before the full test. Else every
  // pair, B's edges outer. In every case only the edges whose bound (cull_bounds) may beat the best depth
  // so far: since the best only decreases, an edge culled at its value now could never improve it later.
  const struct pdSatIndex *ia = A->satIndex, *ib = B->satIndex;
  uint64_t aliveA[PD_SAT_BITSET_WORDS], aliveB[PD_SAT_BITSET_WORDS];
  bool masks = cull.on && A->edgeCount <= 64 * PD_SAT_BITSET_WORDS && B->edgeCount <= 64 * PD_SAT_BITSET_WORDS;
  if (masks) {
    alive_edges(A, &cull.edgesA, b.depth, aliveA);
    alive_edges(B, &cull.edgesB, b.depth, aliveB);
  }
  if (ia && ia->byZ && A->edgeCount <= 64 * PD_SAT_BITSET_WORDS) {
    uint64_t candidates[PD_SAT_BITSET_WORDS];
    int words = (A->edgeCount + 63) / 64;
    for (int j = 0; j < B->edgeCount; ++j) {
      if (masks && !bit_is_set(aliveB, j)) continue;
      edgeData eb = edge_of_B(B, j, &f);
      double lo, hi;
      arc_band(pd_v3_scale(eb.n0, -1.0), pd_v3_scale(eb.n1, -1.0), (pdVec3){0, 0, 1}, &lo, &hi);
      band_candidates(ia, A->edgeCount, lo, hi, candidates);
      for (int w = 0; w < words; ++w)
        for (uint64_t bits = candidates[w] & (masks ? aliveA[w] : ~(uint64_t)0); bits; bits &= bits - 1)
          if (visit_edge_pair(A, 64 * w + __builtin_ctzll(bits), &eb, j, &b, &minkowski) && early && b.depth < 0.0)
            goto done;
    }
  } else if (ib && ib->byZ && B->edgeCount <= 64 * PD_SAT_BITSET_WORDS) {
    uint64_t candidates[PD_SAT_BITSET_WORDS];
    int words = (B->edgeCount + 63) / 64;
    pdVec3 zB = {f.R.m[0][2], f.R.m[1][2], f.R.m[2][2]};  // B's z axis in A's frame
    for (int i = 0; i < A->edgeCount; ++i) {
      if (masks && !bit_is_set(aliveA, i)) continue;
      const pdEdge* edge = &A->edges[i];
      // A's arc against B's negated arcs = A's negated arc against B's arcs, whose bands B's index holds
      double lo, hi;
      arc_band(pd_v3_scale(A->faces[edge->f[0]].normal, -1.0), pd_v3_scale(A->faces[edge->f[1]].normal, -1.0), zB,
               &lo, &hi);
      band_candidates(ib, B->edgeCount, lo, hi, candidates);
      pdVec3 eA = pd_v3_sub(A->vertices[edge->v[1]], A->vertices[edge->v[0]]);
      pdVec3 eAinB = pd_mat3_tmulv(&f.R, eA);
      double margin = PD_SAT_STRADDLE_MARGIN * pd_v3_norm(eA);
      for (int w = 0; w < words; ++w)
        for (uint64_t bits = candidates[w] & (masks ? aliveB[w] : ~(uint64_t)0); bits; bits &= bits - 1) {
          int j = 64 * w + __builtin_ctzll(bits);
          const pdEdge* e = &B->edges[j];
          double s0 = pd_v3_dot(B->faces[e->f[0]].normal, eAinB), s1 = pd_v3_dot(B->faces[e->f[1]].normal, eAinB);
          if ((s0 > margin && s1 > margin) || (s0 < -margin && s1 < -margin)) continue;
          edgeData eb = edge_of_B(B, j, &f);
          if (visit_edge_pair(A, i, &eb, j, &b, &minkowski) && early && b.depth < 0.0) goto done;
        }
    }
  } else if (masks) {
    int words = (A->edgeCount + 63) / 64;
    for (int j = 0; j < B->edgeCount; ++j) {
      if (!bit_is_set(aliveB, j)) continue;
      edgeData eb = edge_of_B(B, j, &f);
      for (int w = 0; w < words; ++w)
        for (uint64_t bits = aliveA[w]; bits; bits &= bits - 1)
          if (visit_edge_pair(A, 64 * w + __builtin_ctzll(bits), &eb, j, &b, &minkowski) && early && b.depth < 0.0)
            goto done;
    }
  } else {
    for (int j = 0; j < B->edgeCount; ++j) {
      edgeData eb = edge_of_B(B, j, &f);
      for (int i = 0; i < A->edgeCount; ++i)
        if (visit_edge_pair(A, i, &eb, j, &b, &minkowski) && early && b.depth < 0.0) goto done;
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
  if (cache) {
    pdVec3 direction = apart ? pd_v3_scale(b.axis, -1.0) : (pdVec3){0, 0, 0};  // GJK's d (PD_SAT_APART)
    *cache = (pdSatCache){apart ? PD_SAT_APART : b.kind, b.a, b.b, direction};
  }
  return !out->separated;
}
