// polydyn — contact analysis: VF and EE contacts of two convex polyhedra (paper §4.4, App. C).
//
// Design note. Soft contacts are shallow (penetration of the order of δ_max, about 1 % of a body's
// size), so every contact is a pair of features that have just crossed:
// - VF: a vertex of one body strictly inside the other. Its face is the one it keeps from the
//   previous contact state (face continuity, §4.4.3); a new one takes, among the faces whose polygon
//   contains the vertex's projection, the one it penetrates least (the one it just crossed).
// - EE: an edge of each body whose Gauss-map arcs cross (the pair spans a face of the Minkowski
//   difference, so the plane through both edges supports both bodies), whose infinite lines have
//   their closest points strictly inside both edges, and which have crossed (depth > 0). Parallel
//   edges never form an EE contact: their overlap is carried by the VF contacts at their ends.
// - Degenerate coincidences (a vertex of each body at the same point, e.g. equal cubes face on face)
//   give two VF contacts at one place; the one whose vertex belongs to the higher-numbered body is
//   dropped so the pair does not count double.
// All geometry is done in the frame of the first body given, so a pair's result does not depend on
// where it sits in the world.
#include "contact_analysis.h"
#include "contact_features.h"

#include <math.h>
#include <stddef.h>

#include "interference.h"

// Edge pairs whose direction cross product is below this (sine of the angle) are parallel: their
// closest points are not unique and the VF contacts at the edge ends carry the contact.
#define PARALLEL_SINE_TOL 1e-9
// A vertex is its body's support point along a direction while no edge from it goes lower by more than this sine
// (rounding of an edge lying in the plane, as a box's bottom edges on the face it rests on).
#define ARC_TOUCH_TOL_VF 1e-9

static pdVec3 to_world(const pdPose* p, pdVec3 local) { return pd_v3_add(p->x, pd_mat3_mulv(&p->R, local)); }
static pdVec3 to_local(const pdPose* p, pdVec3 world) { return pd_mat3_tmulv(&p->R, pd_v3_sub(world, p->x)); }
int pd_contact_id_compare(const pdContactId* a, const pdContactId* b) {
  int alo = a->body1 < a->body2 ? a->body1 : a->body2, ahi = a->body1 < a->body2 ? a->body2 : a->body1;
  int blo = b->body1 < b->body2 ? b->body1 : b->body2, bhi = b->body1 < b->body2 ? b->body2 : b->body1;
  if (alo != blo) return alo < blo ? -1 : 1;
  if (ahi != bhi) return ahi < bhi ? -1 : 1;
  if (a->kind != b->kind) return a->kind < b->kind ? -1 : 1;
  if (a->body1 != b->body1) return a->body1 < b->body1 ? -1 : 1;
  if (a->feat1 != b->feat1) return a->feat1 < b->feat1 ? -1 : 1;
  if (a->feat2 != b->feat2) return a->feat2 < b->feat2 ? -1 : 1;
  return 0;
}

// Is the projection of q (body frame) onto face f's plane inside the face polygon?
static bool projects_inside(const pdPolyhedron* s, int f, pdVec3 q, double tol) {
  const pdFace* face = &s->faces[f];
  const int* idx = s->faceVertices + face->first;
  for (int i = 0; i < face->count; ++i) {
    pdVec3 a = s->vertices[idx[i]], b = s->vertices[idx[(i + 1) % face->count]];
    pdVec3 e = pd_v3_sub(b, a);
    // inward side of edge a→b in a CCW polygon seen from outside is n × e; distance scaled by |e|
    double side = pd_v3_dot(pd_v3_cross(face->normal, e), pd_v3_sub(q, a));
    if (side < -tol * pd_v3_norm(e)) return false;
  }
  return true;
}


// Is q (body frame) inside the body or on its boundary?
static bool inside_body(const pdPolyhedron* s, pdVec3 q, double tol) {
  for (int f = 0; f < s->faceCount; ++f)
    if (face_depth(s, f, q) < -tol) return false;
  return true;
}


// Does body sv, placed in sf's frame by rotation rel and offset off, cross face f's plane of sf by more
// than tol, i.e. lie partly outside it?
static bool crosses_face_plane(const pdPolyhedron* sv, const pdMat3* rel, pdVec3 off, const pdPolyhedron* sf, int f,
                               double tol) {
  for (int i = 0; i < sv->vertexCount; ++i)
    if (face_depth(sf, f, pd_v3_add(off, pd_mat3_mulv(rel, sv->vertices[i]))) < -tol) return true;
  return false;
}

// The face plane of sf a vertex crossed on its way from q0 (step start) to q (now), both in sf's frame:
// one it was on or outside of at the start and is inside of now. Of several (a vertex entering near an
// edge, or one that started on two planes: a corner set down flush), the one it moved into most, which is
// the one it presses on. -1 when it was inside every plane already (a contact found again).
static int face_crossed(const pdPolyhedron* sf, pdVec3 q0, pdVec3 q, double tol) {
  int face = -1;
  double most = 0.0;
  for (int f = 0; f < sf->faceCount; ++f) {
    double d0 = face_depth(sf, f, q0), d = face_depth(sf, f, q);
    if (!(d0 <= tol && d > tol)) continue;
    if (d - d0 > most) most = d - d0, face = f;
  }
  return face;
}

// The face a vertex keeps from the previous contact state, or -1.
static int previous_face(const pdContactId* previous, int count, int vertexBody, int vertex, int faceBody) {
  for (int i = 0; i < count; ++i) {
    const pdContactId* c = &previous[i];
    if (c->kind == pd_contactVF && c->body1 == vertexBody && c->feat1 == vertex && c->body2 == faceBody) return c->feat2;
  }
  return -1;
}

// The face of jf an edge-edge contact of `previous` hands vertex `vertex` of vertexBody over to, or -1: where the
// contact's edge on vertexBody ends at that vertex and the vertex (q, jf's frame) lies within `reach` of its edge e_F
// on jf, the deeper of e_F's two faces below which q lies and over whose polygon it projects (§4.4's EE → VF, design
// note "hand-overs"). Edge e_F's crossing with an edge ending at v has passed v, which now lies in the wedge of e_F's
// faces, the pair's depth d from e_F: its depth below each face is d times the cosine between that face's normal
// and the pair's normal, so the deeper face is the one nearer the predecessor's normal, and the force goes on along
// it. The nearest face (the other side of the wedge, which v crossed in this step) turns the normal by up to the
// wedge's angle and reads a fraction of the depth. A vertex farther from e_F than a new edge pair may be deep did
// not come from that crossing, and takes its face by the rules below.
// Distance from q to the segment a–b, m.
static double segment_distance(pdVec3 a, pdVec3 b, pdVec3 q) {
  pdVec3 u = pd_v3_sub(b, a);
  double s = pd_v3_dot(pd_v3_sub(q, a), u) / pd_v3_dot(u, u);
  s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
  return pd_v3_norm(pd_v3_sub(q, pd_v3_muladd(a, s, u)));
}

// The edge of faceBody in edge pair c when c is an edge pair of vertexBody and faceBody whose edge on vertexBody (shape
// sv) ends at `vertex`, else -1.
static int edge_pair_edge_at_vertex(const pdContactId* c, const pdPolyhedron* sv, int vertexBody, int vertex,
                                    int faceBody) {
  if (c->kind != pd_contactEE) return -1;
  int edgeV, edgeF;
  if (c->body1 == vertexBody && c->body2 == faceBody) edgeV = c->feat1, edgeF = c->feat2;
  else if (c->body2 == vertexBody && c->body1 == faceBody) edgeV = c->feat2, edgeF = c->feat1;
  else return -1;
  return sv->edges[edgeV].v[0] == vertex || sv->edges[edgeV].v[1] == vertex ? edgeF : -1;
}

// Of the two faces of sf's edge edgeF, the one q lies deeper below than *deepest and over whose polygon it projects
// (updating *deepest), else `face`: an edge pair's successor on the vertex its crossing passed.
static int deeper_face_of_edge(const pdPolyhedron* sf, int edgeF, pdVec3 q, double over, double* deepest, int face) {
  for (int k = 0; k < 2; ++k) {
    int f = sf->edges[edgeF].f[k];
    double d = face_depth(sf, f, q);
    if (d > *deepest && projects_inside(sf, f, q, over)) *deepest = d, face = f;
  }
  return face;
}

static int face_after_edge_pair(const pdModel* m, const pdContactId* previous, int count, int vertexBody, int vertex,
                                int faceBody, pdVec3 q, double tol, double over, double reach) {
  const pdPolyhedron* sv = &m->bodies[vertexBody].shape;
  const pdPolyhedron* sf = &m->bodies[faceBody].shape;
  int face = -1;
  double deepest = tol;
  for (int i = 0; i < count; ++i) {
    int edgeF = edge_pair_edge_at_vertex(&previous[i], sv, vertexBody, vertex, faceBody);
    if (edgeF < 0) continue;
    const pdEdge* e = &sf->edges[edgeF];
    if (segment_distance(sf->vertices[e->v[0]], sf->vertices[e->v[1]], q) > reach) continue;
    face = deeper_face_of_edge(sf, edgeF, q, over, &deepest, face);
  }
  return face;
}

// The bodies' penetration depth at their poses (the separating-axis test's minimum overlap over the faces of their
// Minkowski difference, 0 when apart), m.
static double penetration_depth(const pdPolyhedron* sa, const pdPose* pa, const pdPolyhedron* sb, const pdPose* pb) {
  pdSatCache cache = {PD_SAT_NONE, -1, -1, {0, 0, 0}};
  pdSatResult r;
  pd_interference(sa, pa->x, &pa->R, sb, pb->x, &pb->R, PD_SAT_MIN_DEPTH, &cache, &r);
  return r.depth > 0.0 ? r.depth : 0.0;
}

// Edge pruning before the Gauss-map test: an edge whose two ends lie outside one face plane of the other
// body, by more than the pair's δ_max plus PRUNE_OUTSIDE_TOLS boundary tolerances, lies wholly outside that
// body by more than find_ee's inside test allows (one tolerance, or for a sharp edge's pair up to the depth,
// at most δ_max): its pairs are skipped unseen. The margin of one more tolerance (1e-12 × size) covers the
// rounding of the closest points (~1e-16 × size), so pruning never changes a result. (A margin of tolerances
// alone, from before the sharp-edge rule, pruned such pairs: seed 3, scene 1779 of the soak, two compact
// bodies met edge on edge 0.05 of an edge from a corner and sank 15 δ_max with no contact.) Masks hold the
// first 64 faces (a bit per face); vertices beyond PRUNE_VERTICES_MAX are not pruned (correct, only slower).
// find_vf forms the masks: it places each vertex of one body in the other's frame and measures it against the other's
// face planes anyway (its placement through the world rounds otherwise than one through the relative pose, by
// ~1e-16 × size: within the margin's tolerance too).
#define PRUNE_OUTSIDE_TOLS 2.0
#define PRUNE_VERTICES_MAX 512
typedef unsigned long long faceMask;

// ---------------------------------------------------------------- a vertex beyond an acute edge
//
// Design note. The paper's VF contact is a vertex inside the other body. At an acute edge of the other body (faces
// meeting at less than 90°: a wedge, a sliver's rim, a frustum's or a triangular prism's edge) a vertex pressed into
// one face F lies outside the other face once it is within depth × cot(angle) of the edge: no longer inside the
// body, yet still pressed into F, its projection still on F's polygon. No EE pair replaces it either: the edges at
// the vertex cross the acute edge with their closest points at the vertex itself, not inside the edges. The
// vertex and F then still span a face of the Minkowski difference (the vertex is its body's support point along
// −n_F) and the overlap along n_F is exactly the vertex's depth below F: the separating-axis test's own measure of
// that configuration. So such a vertex is a VF contact on F while it is over F's polygon, below F's plane, its
// body's support point along −n_F, and outside the other body by no more than its depth and δ_max (and at most 3 δ_max
// deep beyond the bodies' penetration P, as a new EE contact, find_ee); its depth and normal are
// those of a VF contact on F, so they go on unchanged as the vertex crosses the other face's plane. At a right or
// obtuse edge no such vertex exists (outside the other face, its projection is off F), so boxes and regular
// prisms meet only the paper's contacts.

// Is vertex i of sv (placed in sf's frame by rel, off; at q there) its body's support point along −n (sf's frame)
// within the arcs' touch tolerance: none of its neighbours lies lower along n?
static bool support_along(const pdPolyhedron* sv, int i, const pdMat3* rel, pdVec3 q, pdVec3 n) {
  pdVec3 nv = pd_mat3_tmulv(rel, n);  // n in sv's frame
  for (int e = 0; e < sv->edgeCount; ++e) {
    const pdEdge* edge = &sv->edges[e];
    if (edge->v[0] != i && edge->v[1] != i) continue;
    pdVec3 w = pd_v3_sub(sv->vertices[edge->v[0] == i ? edge->v[1] : edge->v[0]], sv->vertices[i]);
    if (pd_v3_dot(nv, w) < -ARC_TOUCH_TOL_VF * pd_v3_norm(w)) return false;
  }
  (void)q;
  return true;
}


// How far q lies outside the farthest face plane of s, m (<= 0: inside all of them).
static double outside_by(const pdPolyhedron* s, pdVec3 q) {
  double most = -INFINITY;
  for (int f = 0; f < s->faceCount; ++f) most = fmax(most, -face_depth(s, f, q));
  return most;
}

// A vertex pressed through a thin body. A VF contact's element on face F is compressed by the vertex's depth below F;
// a vertex driven deeper than the body is thick (a heavy corner pressing a thin plate onto a third body: the plate's
// springs are sized for the plate's own mass, eq. (11), not for the load the third body puts through it) comes out
// through the far side. It then lies outside the body only across faces turned away from F (outward normals more than
// 90° apart), over F's polygon and below F: the element is still compressed by that depth, and a contact tracked
// there (it came in through F: face continuity, §4.4.3) goes on with the paper's geometry and force law while its
// vertex is its body's support point along −n_F, as beyond an acute edge. Breaking it released the compressed element
// at once and left the two bodies overlapping by more than the plate's width with no contact: a 100:1 blade between a
// prism's corner and a third body went 25 δ_max deep, a 38:1 sliver between a plate's corner and the floor 30 δ_max
// (docs/contact-model.md, "A vertex pressed through a thin body"). A vertex found outside a body is no new contact by
// this rule alone, since a vertex resting against the far face from outside lies there too; the search makes one only
// at the end of an edge already in an edge pair with the body (design note below).
static bool through_far_side(const pdPolyhedron* s, int f, pdVec3 q, double tol, double depth) {
  if (!(depth > 0.0)) return false;
  pdVec3 nf = s->faces[f].normal;
  bool out = false;
  for (int g = 0; g < s->faceCount; ++g) {
    if (!(face_depth(s, g, q) < -tol)) continue;
    if (!(pd_v3_dot(s->faces[g].normal, nf) < 0.0)) return false;
    out = true;
  }
  return out;
}

// The face a vertex of sv outside sf (q in sf's frame) presses on beyond an acute edge (design note above), or -1:
// the previous contact's face (while the vertex is below it and over it), else the shallowest that qualifies. *penetration: the bodies'
// penetration depth, formed here when first needed (NAN until then).
static int face_beyond_acute_edge(const pdModel* m, int iv, const pdPose* pv, int jf, const pdPose* pf, int i,
                                                            pdVec3 q, const pdMat3* rel, const pdContactId* previousIds,
                                                            int previousCount, double tol, double over,
                                                            double* penetration) {
  const pdPolyhedron* sv = &m->bodies[iv].shape;
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  double deltaMax = pd_model_pair_delta_max(m, iv, jf);
  double outside = outside_by(sf, q);
  if (outside > deltaMax) return -1;
  // face continuity (§4.4.3), as for a vertex inside: a vertex in contact keeps its face, or is no new contact here
  int previous = previous_face(previousIds, previousCount, iv, i, jf);
  if (previous >= 0) {
    double d = face_depth(sf, previous, q);
    return d > tol && d >= outside && projects_inside(sf, previous, q, over) ? previous : -1;
  }
  int face = -1;
  double best = INFINITY;
  for (int f = 0; f < sf->faceCount; ++f) {
    double d = face_depth(sf, f, q);
    if (!(d > tol) || !(d >= outside) || !projects_inside(sf, f, q, over)) continue;
    if (!(d < best)) continue;
    if (d > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax) {
      if (isnan(*penetration)) *penetration = penetration_depth(sv, pv, sf, pf);
      if (d > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax + *penetration) continue;
    }
    if (!support_along(sv, i, rel, q, sf->faces[f].normal)) continue;
    best = d, face = f;
  }
  return face;
}

// What find_vf learns of a pair only when a vertex outside the other body needs it.
typedef struct beyondAcute {
  bool acute;          // does the face body have an acute edge
  double penetration;  // the bodies' penetration depth, m (NAN: not yet formed)
} beyondAcute;

// The VF contact of vertex i of body iv (at p, world; q in jf's frame), outside body jf (which has an acute edge), beyond
// an acute edge, appended
// to out (find_vf's), or nothing: n or n + 1. Out of find_vf's loop over the vertices, which it would slow for every
// pair.
__attribute__((noinline)) static int vf_beyond_acute_edge(const pdModel* m, int iv, const pdPose* pv, int jf,
                                                          const pdPose* pf, int i, pdVec3 p, pdVec3 q,
                                                          const pdContactId* previous, int previousCount,
                                                          beyondAcute* b, pdContactGeom* out, int capacity, int n) {
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  double tol = BOUNDARY_TOL_REL * m->bodies[jf].size;
  double flushTol = FLUSH_TOL_DEFLECTIONS * pd_model_pair_delta_max(m, iv, jf);
  pdMat3 rel;
  pdVec3 off;
  pose_in_frame_of(pf, pv, &rel, &off);
  int face = face_beyond_acute_edge(m, iv, pv, jf, pf, i, q, &rel, previous, previousCount, tol, fmax(tol, flushTol),
                                    &b->penetration);
  if (face < 0) return n;
  if (n < capacity)
    out[n] = (pdContactGeom){{iv, jf, pd_contactVF, i, face}, p, pd_mat3_mulv(&pf->R, sf->faces[face].normal),
                             face_depth(sf, face, q)};
  return n + 1;
}

// ---------------------------------------------------------------- an edge pair's vertex through the far side
//
// Design note. An edge of one body pressed across a thin body's rim (a plate's edge lying along a lens-shaped sliver's
// face, through the sliver where it is under 2 δ_max thick) is held by its edge pairs with the rim's edges, and its end
// vertex, once that is its body's lowest point along a face F at the other edge, by a VF contact on F. Tracked, that
// contact goes on through the far side (through_far_side); but when the edge rocks, the support point passes between
// the edge's two ends and the contact breaks, and a vertex outside the body is no new contact: with both ends outside
// and the edge pair parting (its Gauss arcs apart), nothing held the two while their overlap grew from 2.4 to 8.5 δ_max
// (soak campaign 63, scene 4858). So the search makes the vertex at the end of an edge in one of the pair's edge pairs a
// VF contact on a face F of the other edge when tracking would keep it there: below F and over its polygon, outside
// the body only across faces turned away from F, its body's support point along −n_F, and no deeper than a new edge
// pair may be (3 δ_max beyond the bodies' penetration). Its geometry and force law are any VF contact's (point the
// vertex, eq. (18a); normal n_F, eq. (18b); depth below F's plane): the overlap along n_F is that depth, as the
// separating-axis test reads it, and it continues the edge pair's normal where the pair's arcs part at n_F. A vertex
// resting against the far face from outside is not its body's lowest point along −n_F, and its edge is in no edge pair
// with F's edges pressed into the body.

// The VF contact of vertex i of body iv (at p, world; q in jf's frame) outside body jf at the end of an edge in one of
// the pair's edge pairs (design note above), appended to out, or nothing: n or n + 1. Out of find_vf's loop over the
// vertices, which calls it only for a pair that held an edge pair.
__attribute__((noinline)) static int vf_through_after_edge_pair(const pdModel* m, int iv, const pdPose* pv, int jf,
                                                                const pdPose* pf, int i, pdVec3 p, pdVec3 q,
                                                                const pdContactId* previous, int previousCount,
                                                                double* penetration, pdContactGeom* out, int capacity,
                                                                int n) {
  const pdPolyhedron* sv = &m->bodies[iv].shape;
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  double tol = BOUNDARY_TOL_REL * m->bodies[jf].size;
  double deltaMax = pd_model_pair_delta_max(m, iv, jf);
  double over = fmax(tol, FLUSH_TOL_DEFLECTIONS * deltaMax);
  // as tracking measures a vertex outside the body (pd_contact_track_framed), so that what is found here is kept there
  double trackOutside = TRACK_INSIDE_TOL_REL * m->settings.deflection * m->bodies[jf].size;
  pdMat3 rel;
  pdVec3 off;
  pose_in_frame_of(pf, pv, &rel, &off);
  int face = -1;
  double deepest = tol;
  for (int k = 0; k < previousCount; ++k) {
    int edgeF = edge_pair_edge_at_vertex(&previous[k], sv, iv, i, jf);
    if (edgeF < 0) continue;
    for (int s = 0; s < 2; ++s) {
      int f = sf->edges[edgeF].f[s];
      double d = face_depth(sf, f, q);
      if (!(d > deepest) || !projects_inside(sf, f, q, over) || !through_far_side(sf, f, q, trackOutside, d)) continue;
      if (!support_along(sv, i, &rel, q, sf->faces[f].normal)) continue;
      if (d > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax) {
        if (isnan(*penetration)) *penetration = penetration_depth(sv, pv, sf, pf);
        if (d > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax + *penetration) continue;
      }
      deepest = d, face = f;
    }
  }
  if (face < 0) return n;
  if (n < capacity)
    out[n] = (pdContactGeom){{iv, jf, pd_contactVF, i, face}, p, pd_mat3_mulv(&pf->R, sf->faces[face].normal), deepest};
  return n + 1;
}

// ---------------------------------------------------------------- a vertex pressed into both faces of a right-angled edge
//
// Design note. A vertex v of one body inside the other, in the wedge of an edge e whose faces F and f meet at a right
// angle (outward normals n_F ⟂ n_f), keeps F by face continuity (§4.4.3) for as long as it is over F's polygon, which
// inside the body it always is at a right angle; its contact reads only its depth d_F below F. When the other body
// turns so that f sweeps into v (a spinning plate whose side face holds a corner of a bar while its broad face rolls
// onto it), the overlap along n_f grows while the contact reads and resists none of it: soak campaign 68, scene 2429,
// 8.35 δ_max along n_f under a contact 1.0 δ_max deep on F (docs/contact-model.md, "A corner or an edge inside an
// edge's wedge"). The pair of features that touches there is v and e, whose vertex–edge element has depth |w| along
// n = w/|w| (w from v to its foot on e's line). At a right angle w = d_F n_F + d_f n_f exactly, so a VF contact on F
// and one on f, each with the paper's geometry and force law (eqs. (18a), (18b), §3.1), carry elastic forces
// k d_F n_F + k d_f n_f = k |w| n: the vertex–edge element's. So the vertex held on F becomes a VF contact on f as well
// once it crosses f's plane (its onset, as any VF contact's by App. C: it starts at depth 0, or at the flush tolerance,
// 10⁻³ δ_max, beyond which a plane counts as crossed, so the force is continuous to the onsets' own precision),
// while it is over f's polygon, and keeps it while tracking does. F's contact goes on as it was (its springs kept), so
// no hand-over is needed at either end of e's Gauss arc: there the element is the one face's contact, the other's
// depth 0. A vertex not held on F (found now, or handed over from an edge pair: its face carries the pair's force on)
// gets its face by the rules above alone: made beside such a hand-over, f's contact started at 150 N, 90° from the
// pair's normal, and a sliver's corner went 3.49 δ_max into a cube (cases/hard/sliver_corner_past_cube_edge.scene;
// 0.49 without). At obtuse edges (normals less than 90° apart) no rule is needed: a vertex inside with n on e's arc
// projects inside both faces and its contact reads at least the bodies' overlap. At acute ones F alone carries it: its
// depth d_F is at least the vertex's own overlap min(d_F, d_f); the element, |w| ≥ d_F / sin θ there, would jump where
// the vertex crosses f's plane; and f's contact would push it along −n_F with |cos θ| of its force: at a sliver's rim
// (cos θ → −1) the two sum to about k (d_F − d_f) n_F, which drives a vertex deeper below f than below F on through the
// body and out through f (measured: docs/contact-model.md, "Acute edges").

// The VF contacts of vertex i of body iv (at p, world; q in jf's frame), inside body jf and held on `face` by face
// continuity, on the faces across right-angled edges of that face (design note above), appended to out, or nothing:
// n to n + 2. `over`: find_vf's flush tolerance. Out of find_vf's loop over the vertices, which calls it only for a
// held vertex.
__attribute__((noinline)) static int vf_across_right_edge(const pdModel* m, int iv, int jf, const pdPose* pf,
                                                          const pdPose* pf0, const pdPose* pv0, int i, int face,
                                                          pdVec3 p, pdVec3 q, const pdContactId* previous,
                                                          int previousCount, double over, pdContactGeom* out,
                                                          int capacity, int n) {
  const pdPolyhedron* sv = &m->bodies[iv].shape;
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  bool start = false;  // q0, the vertex at the step's start (jf's frame), formed when first needed
  pdVec3 q0 = q;
  for (int e = 0; e < sf->edgeCount; ++e) {
    int f = face_across_right_edge(sf, e, face);
    if (f < 0) continue;
    // beyond the flush tolerance, as find_vf's planes: a corner on a plane both bodies share (a brick flush over the
    // side of the brick below, rocked by rounding) does not press into it
    double d = face_depth(sf, f, q);
    if (!(d > over)) continue;
    // new only where the vertex crossed f's plane in the step (its onset)
    if (!vf_listed_on(previous, previousCount, iv, i, jf, f)) {
      if (!pv0) continue;
      if (!start) q0 = to_local(pf0, to_world(pv0, sv->vertices[i])), start = true;
      if (!(face_depth(sf, f, q0) <= over)) continue;
    }
    if (!projects_inside(sf, f, q, over)) continue;
    if (n < capacity)
      out[n] = (pdContactGeom){{iv, jf, pd_contactVF, i, f}, p, pd_mat3_mulv(&pf->R, sf->faces[f].normal), d};
    ++n;
  }
  return n;
}

// ---------------------------------------------------------------- an edge pair begun and handed over within one step
//
// Design note. An edge pair whose crossing slides off its edge's end hands over to the VF contact of the vertex there,
// on the deeper of the other edge's two faces (face_after_edge_pair: the face nearer the pair's normal, which carries
// its force on). A long step (an island alone takes its own) can carry such a pair from before its onset to past that
// vertex: the search then sees the vertex alone, found anew, and gives it the face whose plane it crossed in the step,
// at an acute rim edge the cap it grazed rather than the side face the crossing pressed into (soak campaign 70, scene
// 3505: a frustum's corner 5e-4 δ_max below a plate's cap and 0.78 δ_max inside its side face, the bodies' overlap along
// that face's normal; the cap's contact, at 90° to the approach, released at 2.4 δ_max, while steps a third as long saw
// the pair and handed it over to the side face). So a vertex found anew takes the face that hand-over gives when an edge
// a at it and an edge e of the other body form a pair that began and passed it within the step: at the step's end the
// pair's Gauss arcs meet, it has crossed along a × e by more than the flush tolerance (flush faces' edges meet at their
// shared corners with a depth of rounding: 1e-10 m in a brick wall), its lines' closest points lie inside e and beyond
// the vertex on a, and the vertex is within a new pair's depth (3 δ_max) of e; at the step's start those closest points
// lay on a and the lines had not crossed. A pair crossed at the start was a contact then, or refused by the search's
// rules, and hands over as such or not at all. The contact is a VF contact (eqs. (18a), (18b), §3.1) and starts as a
// new one (App. C: its onset found from the step).

static bool line_closest(pdVec3 P, pdVec3 u, pdVec3 Q, pdVec3 v, double* s, double* t);
static bool arcs_meet_within_slack(pdVec3 a, pdVec3 b, pdVec3 c, pdVec3 d);

// How far the lines through q along u and through b0 along v have crossed (m, < 0: apart), along their common normal
// turned outward from outward (the sum of the normals of u's edge's faces); *s, *t the closest points' parameters.
// False for parallel lines.
static bool lines_crossed_by(pdVec3 q, pdVec3 u, pdVec3 b0, pdVec3 v, pdVec3 outward, double* s, double* t,
                             double* depth) {
  if (!line_closest(q, u, b0, v, s, t)) return false;
  pdVec3 n = pd_v3_normalize(pd_v3_cross(u, v));
  if (pd_v3_dot(n, outward) < 0.0) n = pd_v3_scale(n, -1.0);
  *depth = pd_v3_dot(n, pd_v3_sub(pd_v3_muladd(q, *s, u), pd_v3_muladd(b0, *t, v)));
  return true;
}

// The face vertex i of body iv (q now, q0 at the step's start, both in jf's frame) takes from an edge pair that began and
// passed it within the step (design note above), or -1. rel, off: iv in jf's frame now; rel0, off0 at the start.
__attribute__((noinline)) static int face_after_passed_edge_pair(const pdModel* m, int iv, int jf, int i, pdVec3 q,
                                                                 pdVec3 q0, const pdMat3* rel, pdVec3 off,
                                                                 const pdMat3* rel0, pdVec3 off0, double tol,
                                                                 double over, double reach) {
  const pdPolyhedron* sv = &m->bodies[iv].shape;
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  int face = -1;
  double deepest = tol;
  for (int j = 0; j < sf->edgeCount; ++j) {
    const pdEdge* e = &sf->edges[j];
    pdVec3 b0 = sf->vertices[e->v[0]], b1 = sf->vertices[e->v[1]], v = pd_v3_sub(b1, b0);
    if (segment_distance(b0, b1, q) > reach) continue;
    for (int k = 0; k < sv->edgeCount; ++k) {
      const pdEdge* a = &sv->edges[k];
      if (a->v[0] != i && a->v[1] != i) continue;
      pdVec3 other = sv->vertices[a->v[0] == i ? a->v[1] : a->v[0]];
      pdVec3 nA0 = pd_mat3_mulv(rel, sv->faces[a->f[0]].normal), nA1 = pd_mat3_mulv(rel, sv->faces[a->f[1]].normal);
      // now: crossed, beyond the vertex on a (s < 0 from the vertex along a), inside e, spanning a Minkowski face
      pdVec3 u = pd_v3_sub(pd_v3_add(off, pd_mat3_mulv(rel, other)), q);
      double s, t, depth;
      if (!lines_crossed_by(q, u, b0, v, pd_v3_add(nA0, nA1), &s, &t, &depth)) continue;
      // crossed beyond the flush tolerance: flush faces' edges meet at their shared corners with a depth of rounding
      if (!(s < 0.0 && t > 0.0 && t < 1.0 && depth > over)) continue;
      pdVec3 c = pd_v3_scale(sf->faces[e->f[0]].normal, -1.0), d = pd_v3_scale(sf->faces[e->f[1]].normal, -1.0);
      if (!arcs_meet_within_slack(nA0, nA1, c, d)) continue;
      // at the step's start: on a, not yet crossed
      pdVec3 u0 = pd_v3_sub(pd_v3_add(off0, pd_mat3_mulv(rel0, other)), q0);
      pdVec3 outward0 = pd_mat3_mulv(rel0, pd_v3_add(sv->faces[a->f[0]].normal, sv->faces[a->f[1]].normal));
      if (!lines_crossed_by(q0, u0, b0, v, outward0, &s, &t, &depth)) continue;
      if (!(s >= 0.0 && s <= 1.0 && depth <= 0.0)) continue;
      face = deeper_face_of_edge(sf, j, q, over, &deepest, face);
    }
  }
  return face;
}

// VF contacts of the vertices of body iv inside body jf, and, with mask, each vertex's faces of jf (of the first 64)
// whose plane it lies outside of by more than the pruning margin (find_ee's edge pruning).
// (Formed twice, for a face body with an acute edge and for one without (find_vf): without, the loop is the paper's
// alone, as fast as it was before vertices beyond acute edges were looked at.)
__attribute__((always_inline)) static inline int find_vf_formed(const pdModel* m, int iv, const pdPose* pv,
                                                                const pdPose* pv0, int jf, const pdPose* pf,
                                                                const pdPose* pf0, const pdContactId* previous,
                                                                int previousCount, pdContactGeom* out, int capacity,
                                                                int n, faceMask* mask, const bool acute) {
  const pdPolyhedron* sv = &m->bodies[iv].shape;
  const pdPolyhedron* sf = &m->bodies[jf].shape;
  double tol = BOUNDARY_TOL_REL * m->bodies[jf].size;
  double deltaMax = pd_model_pair_delta_max(m, iv, jf);
  double flushTol = FLUSH_TOL_DEFLECTIONS * deltaMax;
  beyondAcute beyond = {acute, NAN};
  bool edgePairs = false;  // did the pair hold an edge pair
  for (int k = 0; k < previousCount && !edgePairs; ++k) edgePairs = previous[k].kind == pd_contactEE;
  int maskFaces = mask ? (sf->faceCount < 64 ? sf->faceCount : 64) : 0;
  double maskMargin = deltaMax + PRUNE_OUTSIDE_TOLS * tol;
  pdMat3 rel;  // the vertex body in the face body's frame
  pdVec3 off;
  pose_in_frame_of(pf, pv, &rel, &off);
  for (int i = 0; i < sv->vertexCount; ++i) {
    pdVec3 p = to_world(pv, sv->vertices[i]);
    pdVec3 q = to_local(pf, p);
    // penetration: the distance to the nearest face plane the vertex can have crossed. A face plane
    // the vertex lies on but its own body does not cross is not one: the two bodies share that plane
    // (a corner resting on the corner of an equal cube, a brick on two bricks of its width, a box on a
    // box with one side aligned), the vertex slides along it and presses on the face it did cross. A
    // vertex on a plane its body crosses lies on that face from outside: it only touches, no contact.
    double penetration = INFINITY;
    bool outside = false;
    // A vertex within flushTol outside a shared plane is on it too: a flush stack's corner, rocked by
    // rounding (1e-11 rad moves it 1e-12 m on a 0.1 m box), must stay a VF contact; lost at the boundary
    // tolerance it left its corner to an edge-edge pair that came and went with the rounding's sign.
    double outsideBy = 0.0;  // m: how far outside the face plane that showed it outside (acute only)
    faceMask outsideFaces = 0;
    int f = 0;
    for (; f < sf->faceCount && !outside; ++f) {
      double d = face_depth(sf, f, q);
      if (f < maskFaces && d < -maskMargin) outsideFaces |= 1ull << f;
      if (d <= flushTol && d >= -flushTol && !crosses_face_plane(sv, &rel, off, sf, f, flushTol)) continue;
      outside = d < -tol;
      if (acute) outsideBy = -d;
      if (d < penetration) penetration = d;  // fmin but inline (only compared with tol below)
    }
    if (mask) {  // the faces past the one that showed the vertex outside
      for (; f < maskFaces; ++f)
        if (face_depth(sf, f, q) < -maskMargin) outsideFaces |= 1ull << f;
      mask[i] = outsideFaces;
    }
    if (outside) {
      // the end of an edge in an edge pair, through a thin body's far side (design note above)
      if (edgePairs) {
        int found = vf_through_after_edge_pair(m, iv, pv, jf, pf, i, p, q, previous, previousCount, &beyond.penetration,
                                               out, capacity, n);
        if (found > n) {
          n = found;
          continue;
        }
      }
      // a vertex beyond an acute edge, still pressed into a face (design note above): the vertices outside a body with
      // such an edge by at most δ_max are looked at again
      if (acute && outsideBy <= deltaMax)
        n = vf_beyond_acute_edge(m, iv, pv, jf, pf, i, p, q, previous, previousCount, &beyond, out, capacity, n);
      continue;
    }
    if (!(penetration > tol)) continue;
    int face = previous_face(previous, previousCount, iv, i, jf);
    // face continuity holds while the vertex is over its face, as tracking keeps it (pd_contact_track); one that slid
    // off it onto the next face is found there now, so that its contact hands over in this commit (a successor found
    // only at the next commit leaves the vertex without a contact for a step)
    if (face >= 0 && !projects_inside(sf, face, q, fmax(tol, flushTol))) face = -1;
    bool held = face >= 0;
    // the successor of an edge pair whose crossing passed this vertex: the face that carries its normal on
    if (face < 0) face = face_after_edge_pair(m, previous, previousCount, iv, i, jf, q, tol, fmax(tol, flushTol),
                                             EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax);
    // the successor of an edge pair that began and passed this vertex within the step (design note above)
    if (face < 0 && pv0) {
      pdMat3 rel0;
      pdVec3 off0;
      pose_in_frame_of(pf0, pv0, &rel0, &off0);
      pdVec3 q0 = pd_v3_add(off0, pd_mat3_mulv(&rel0, sv->vertices[i]));
      face = face_after_passed_edge_pair(m, iv, jf, i, q, q0, &rel, off, &rel0, off0, tol, fmax(tol, flushTol),
                                         EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax);
    }
    // a new contact: the face whose plane it crossed during the step. Depth alone misleads where the
    // vertex also lies just inside another plane (a brick's corner a roundoff inside the side plane of
    // the brick below, which it slides along, while it sinks into the top face).
    if (face < 0 && pv0) face = face_crossed(sf, to_local(pf0, to_world(pv0, sv->vertices[i])), q, tol);
    if (face < 0) {
      // no crossing seen: the shallowest face with positive depth whose polygon is over the vertex, within
      // the flush tolerance as in pd_contact_track (a corner out over a shared side plane by 1e-9 m must
      // take the face it rests on, not the far side face its projection falls in)
      double over = fmax(tol, flushTol);
      double best = INFINITY, bestAny = INFINITY;
      int any = 0;
      for (int f = 0; f < sf->faceCount; ++f) {
        double d = face_depth(sf, f, q);
        if (!(d > tol) || (d <= flushTol && !crosses_face_plane(sv, &rel, off, sf, f, flushTol))) continue;
        if (d < bestAny) bestAny = d, any = f;
        if (d < best && projects_inside(sf, f, q, over)) best = d, face = f;
      }
      if (face < 0) face = any;
    }
    if (n < capacity)
      out[n] = (pdContactGeom){{iv, jf, pd_contactVF, i, face}, p, pd_mat3_mulv(&pf->R, sf->faces[face].normal),
                               face_depth(sf, face, q)};
    ++n;
    // held on its face by continuity: pressed into the faces across that face's right-angled edges too
    if (held)
      n = vf_across_right_edge(m, iv, jf, pf, pf0, pv0, i, face, p, q, previous, previousCount, fmax(tol, flushTol), out,
                               capacity, n);
  }
  return n;
}

static int find_vf(const pdModel* m, int iv, const pdPose* pv, const pdPose* pv0, int jf, const pdPose* pf,
                   const pdPose* pf0, const pdContactId* previous, int previousCount, pdContactGeom* out, int capacity,
                   int n, faceMask* mask) {
  if (pd_polyhedron_has_acute_edge(&m->bodies[jf].shape))
    return find_vf_formed(m, iv, pv, pv0, jf, pf, pf0, previous, previousCount, out, capacity, n, mask, true);
  return find_vf_formed(m, iv, pv, pv0, jf, pf, pf0, previous, previousCount, out, capacity, n, mask, false);
}

// Closest points of the lines P + s u and Q + t v; false when (nearly) parallel.
static bool line_closest(pdVec3 P, pdVec3 u, pdVec3 Q, pdVec3 v, double* s, double* t) {
  pdVec3 w = pd_v3_sub(P, Q);
  double a = pd_v3_dot(u, u), b = pd_v3_dot(u, v), c = pd_v3_dot(v, v), d = pd_v3_dot(u, w), e = pd_v3_dot(v, w);
  double den = a * c - b * b;
  if (den <= PARALLEL_SINE_TOL * PARALLEL_SINE_TOL * a * c) return false;
  *s = (b * e - c * d) / den;
  *t = (a * e - b * d) / den;
  return true;
}

// Gauss-map test: do the arcs (a, b) and (c, d) on the unit sphere meet? a, b are the face normals
// around an edge of one body; c, d the negated face normals around an edge of the other (D. Gregorius,
// "The Separating Axis Test between Convex Polyhedra", GDC 2013). Closed arcs, within ARC_TOUCH_TOL:
// arcs that only touch — an endpoint shared (two faces parallel and in contact, such as a cube turned
// 45° on another) or lying on the other arc (an edge lying on a face) — meet too, because the crossings
// of the edges bounding those faces are real contact points (the corners of the overlap polygon).
// Strict crossing (the SAT's Minkowski-face test) would miss them. The callers allow a slack beyond that
// (EE_ARC_SLACK, contact_features.h): an edge lying within it of a face is pressed into the face at both of its
// crossings with the face's edges.
// A touching pair is a contact only where those faces press on each other: its depth (the gap of the two
// face planes) must not exceed the bodies' overlap along the faces around the two edges; otherwise the
// faces are far apart across an overlap that is shallow along another axis (see edge_contact_is_shallow).

// Are u and v (triple products of unit vectors, u = c · (b × a), …) of one sign and both beyond
// 2 slack |b × a| + ARC_TRIPLE_ROUNDING in size (norm2 = |b × a|²)?
static bool same_side_beyond(double u, double v, double norm2, double slack) {
  if (!(u * v > 0.0)) return false;  // also false for a NaN, so the sizes below are numbers
  double au = fabs(u), av = fabs(v);
  double m = (au < av ? au : av) - ARC_TRIPLE_ROUNDING;
  return m > 0.0 && m * m > 4.0 * slack * slack * norm2;
}
typedef enum arcMeeting { arcsApart = 0, arcsCross, arcsTouch } arcMeeting;
static arcMeeting arcs_meet_formed(const gaussArc* ab, const gaussArc* cd, double slack) {
  pdVec3 a = ab->a, b = ab->b, c = cd->a, d = cd->b, bxa = ab->bxa, dxc = cd->bxa;
  double cba = pd_v3_dot(c, bxa), dba = pd_v3_dot(d, bxa), adc = pd_v3_dot(a, dxc), bdc = pd_v3_dot(b, dxc);
  // Apart for certain, and cheaply (most edge pairs): both ends of one arc on the same side of the other's
  // great circle, each by a sine beyond twice the slack (plus a margin for the rounding of the triple
  // products: the sine is cba/|b × a|). The arc between them is then on that side too, and so is every point
  // within the slack of it, so the touch test below, whose point lies on that great circle, would find none.
  if (same_side_beyond(cba, dba, ab->norm2, slack) || same_side_beyond(adc, bdc, cd->norm2, slack)) return arcsApart;
  // a crossing by a roundoff (an end of one arc within ARC_TOUCH_TOL of the other's great circle, as
  // when two faces are parallel) is a touch: it gets the touch's depth check, whatever the roundoff's sign
  // (the least of the four at most the tolerance: any of them, which is the same test NaN included, without
  // three libm calls)
  bool nearEnd = fabs(cba) <= ARC_TOUCH_TOL || fabs(dba) <= ARC_TOUCH_TOL || fabs(adc) <= ARC_TOUCH_TOL ||
                 fabs(bdc) <= ARC_TOUCH_TOL;
  if (!nearEnd && cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0) return arcsCross;
  pdVec3 n1 = pd_v3_normalize(pd_v3_cross(a, b)), n2 = pd_v3_normalize(pd_v3_cross(c, d));
  pdVec3 line = pd_v3_cross(n1, n2);
  double len = pd_v3_norm(line);
  if (len <= ARC_TOUCH_TOL) return arcsApart;  // one great circle: parallel edges
  pdVec3 p = pd_v3_scale(line, 1.0 / len);
  for (int sign = 0; sign < 2; ++sign, p = pd_v3_scale(p, -1.0)) {
    // p on arc (a, b) when it lies between a and b along their great circle (arcs are shorter than π);
    // each test is the sine of p's angle past an end of the arc, allowed down to −slack
    bool on1 = pd_v3_dot(pd_v3_cross(a, p), n1) >= -slack && pd_v3_dot(pd_v3_cross(p, b), n1) >= -slack;
    bool on2 = pd_v3_dot(pd_v3_cross(c, p), n2) >= -slack && pd_v3_dot(pd_v3_cross(p, d), n2) >= -slack;
    if (on1 && on2) return arcsTouch;
  }
  return arcsApart;
}
static arcMeeting arcs_meet(pdVec3 a, pdVec3 b, pdVec3 c, pdVec3 d, double slack) {
  gaussArc ab = gauss_arc(a, b), cd = gauss_arc(c, d);
  return arcs_meet_formed(&ab, &cd, slack);
}
static bool arcs_meet_within_slack(pdVec3 a, pdVec3 b, pdVec3 c, pdVec3 d) {
  return arcs_meet(a, b, c, d, EE_ARC_SLACK) != arcsApart;
}

// Overlap of A and B along unit u (A's frame, pointing from A to B), m; B's pose in A's frame (rel, off).
static double overlap_along(const pdPolyhedron* sa, const pdPolyhedron* sb, const pdMat3* rel, pdVec3 off, pdVec3 u) {
  double maxA = -INFINITY, minB = INFINITY;
  // max and min inline: the same value as fmax/fmin for these finite dot products (−0 and +0 included, the first
  // argument kept on a tie), without a libm call per vertex (2 % of cases/hard/stack_10.scene's run)
  for (int i = 0; i < sa->vertexCount; ++i) {
    double d = pd_v3_dot(u, sa->vertices[i]);
    maxA = d > maxA ? d : maxA;
  }
  pdVec3 uB = pd_mat3_tmulv(rel, u);  // u in B's frame
  for (int i = 0; i < sb->vertexCount; ++i) {
    double d = pd_v3_dot(uB, sb->vertices[i]);
    minB = d < minB ? d : minB;
  }
  return maxA - (minB + pd_v3_dot(u, off));
}

// Edge-edge geometry in body A's frame: B's edge given in A's frame. Fills depth, point (A frame) and
// the normal from B into A (A frame). Returns false for parallel edges, and, when `interior`, unless
// the closest points of the two lines lie strictly inside both edges.
typedef struct edgeGeom {
  double s, t;  // closest points' parameters along A's edge (a0 → a1) and B's (b0 → b1)
  double depth;
  pdVec3 point;
  pdVec3 normal;
} edgeGeom;

static bool edge_pair_geometry(const pdPolyhedron* sa, int ea, pdVec3 b0, pdVec3 b1, bool interior, edgeGeom* g) {
  const pdEdge* e = &sa->edges[ea];
  pdVec3 a0 = sa->vertices[e->v[0]], a1 = sa->vertices[e->v[1]];
  pdVec3 u = pd_v3_sub(a1, a0), v = pd_v3_sub(b1, b0);
  double s, t;
  if (!line_closest(a0, u, b0, v, &s, &t)) return false;
  if (interior && !(s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0)) return false;
  pdVec3 pa = pd_v3_muladd(a0, s, u), pb = pd_v3_muladd(b0, t, v);
  g->s = s, g->t = t;
  // outward from A: the side of A's two face normals at this edge
  pdVec3 n = pd_v3_normalize(pd_v3_cross(u, v));
  pdVec3 outward = pd_v3_add(sa->faces[e->f[0]].normal, sa->faces[e->f[1]].normal);
  if (pd_v3_dot(n, outward) < 0.0) n = pd_v3_scale(n, -1.0);
  g->depth = pd_v3_dot(n, pd_v3_sub(pa, pb));
  g->point = pd_v3_scale(pd_v3_add(pa, pb), 0.5);
  g->normal = pd_v3_scale(n, -1.0);
  return true;
}

// Does B's edge b0–b1 (A's frame) lie in the plane of a face of A around A's edge ea, a plane that B does
// not cross (B's rotation rel and offset off in A's frame): a plane both bodies share (FLUSH_TOL_DEFLECTIONS)?
static bool in_shared_plane(const pdPolyhedron* sa, const pdEdge* ea, pdVec3 b0, pdVec3 b1, const pdPolyhedron* sb,
                            const pdMat3* rel, pdVec3 off, double flushTol) {
  for (int k = 0; k < 2; ++k) {
    int f = ea->f[k];
    if (fabs(face_depth(sa, f, b0)) > flushTol || fabs(face_depth(sa, f, b1)) > flushTol) continue;
    if (!crosses_face_plane(sb, rel, off, sa, f, flushTol)) return true;
  }
  return false;
}

// An edge pair whose crossing lies within this many of the pair's δ_max (m along the edge) of an end of
// either edge, where that end's vertex is already in VF contact with the other body, is no new contact:
// that vertex carries the contact at that point. A flush stack's corners are such crossings: an upper
// box's bottom edge meets the perpendicular top edge below exactly at the shared corner (their arcs only
// touch), so the pair duplicates the corner's VF contact (twice its stiffness) and its closest points
// wander off the edges' ends by rounding: in soak seed 1 scene 147 with one box set 1e-12 m aside such
// pairs broke under 0.06-1.9 N, up to 3 of a box pair's 4 corners in one step, and the stack sank 54
// δ_max. The moment left out is at most this distance times the force; FLUSH_TOL_DEFLECTIONS' size for
// the same reason (rocking of 1e-6 rad moves a corner's crossing by ~1e-7 m on a 0.1 m box).
#define EE_AT_VF_VERTEX_DEFLECTIONS 1e-3

// Is edge e's end within `reach` (m) of parameter s (edge length len) a vertex of body `body` in VF contact
// with body `other` among found[0..count)?
static bool end_in_vf_contact(const pdContactGeom* found, int count, int body, int other, const pdEdge* e, double s,
                              double len, double reach) {
  int v = s * len <= reach ? e->v[0] : (1.0 - s) * len <= reach ? e->v[1] : -1;
  if (v < 0) return false;
  for (int k = 0; k < count; ++k) {
    const pdContactId* id = &found[k].id;
    if (id->kind == pd_contactVF && id->body1 == body && id->body2 == other && id->feat1 == v) return true;
  }
  return false;
}

// find_ee's per-search caches, on the stack: A's Gauss arcs of its first this many edges, the overlaps along the
// first this many faces of each body (a bit of a faceMask per entry).
#define FIND_EE_CACHED 64

// Overlaps of A and B along face normals, by body (0: A's normals, 1: B's reversed) and face, each formed once when
// first asked for (the faces past FIND_EE_CACHED are formed each time, as the same numbers).
typedef struct faceOverlaps {
  double value[2][FIND_EE_CACHED];
  faceMask formed[2];
} faceOverlaps;

// The overlap of A and B along face f of body `side` (A's normal, or B's reversed; B's pose in A's frame rel, off),
// m; cache nullable.
static double face_overlap(const pdPolyhedron* sa, const pdPolyhedron* sb, const pdMat3* rel, pdVec3 off, int side,
                           int f, faceOverlaps* cache) {
  bool cached = cache && f < FIND_EE_CACHED;
  if (cached && (cache->formed[side] >> f & 1u)) return cache->value[side][f];
  pdVec3 axis = side == 0 ? sa->faces[f].normal : pd_v3_scale(pd_mat3_mulv(rel, sb->faces[f].normal), -1.0);
  double overlap = overlap_along(sa, sb, rel, off, axis);
  if (cached) cache->value[side][f] = overlap, cache->formed[side] |= 1ull << f;
  return overlap;
}

// The least overlap of A and B along the face normals of both, m: an upper bound of their penetration depth (those
// normals are among the separating-axis test's axes). cache nullable.
static double least_face_overlap(const pdPolyhedron* sa, const pdPolyhedron* sb, const pdMat3* rel, pdVec3 off,
                                 faceOverlaps* cache) {
  double least = INFINITY;
  for (int f = 0; f < sa->faceCount; ++f) least = fmin(least, face_overlap(sa, sb, rel, off, 0, f, cache));
  for (int f = 0; f < sb->faceCount; ++f) least = fmin(least, face_overlap(sa, sb, rel, off, 1, f, cache));
  return least;
}

// Edge-edge contacts of A and B; maskA, maskB (find_vf's, both or neither): A's vertices outside B's face planes and B's
// outside A's, by more than the pruning margin.
static int find_ee(const pdModel* model, int ia, const pdPose* pa, int ib, const pdPose* pb, const faceMask* maskA,
                   const faceMask* maskB, pdContactGeom* out, int capacity, int n) {
  const pdPolyhedron* sa = &model->bodies[ia].shape;
  const pdPolyhedron* sb = &model->bodies[ib].shape;
  pdMat3 rel;  // B in A's frame
  pdVec3 off;
  pose_in_frame_of(pa, pb, &rel, &off);
  double tolA = BOUNDARY_TOL_REL * model->bodies[ia].size, tolB = BOUNDARY_TOL_REL * model->bodies[ib].size;
  double deltaMax = pd_model_pair_delta_max(model, ia, ib);
  double flushTol = FLUSH_TOL_DEFLECTIONS * deltaMax;
  double vertexReach = EE_AT_VF_VERTEX_DEFLECTIONS * deltaMax;
  int vfCount = n < capacity ? n : capacity;                      // this pair's VF contacts, found before its EE ones
  bool prune = maskA != NULL;
  // A's arcs (its edges' face normals, fixed in A's frame), each formed once for all of B's edges when first
  // needed (most pairs are pruned), and the overlap along a face normal by face (A's, then B's reversed): touching
  // arcs (a 45° stack's flush faces) test the same four faces for most of their edge pairs. A bit per entry says
  // it is formed (the first 64 edges and faces; the others are formed where used, as the same numbers).
  gaussArc arcsA[FIND_EE_CACHED];
  faceMask arcFormed = 0;
  faceOverlaps overlaps;
  overlaps.formed[0] = overlaps.formed[1] = 0;
  double penetration = NAN;  // the bodies' penetration depth, once a pair needs it
  double faceOverlap = NAN;  // the least overlap along a face normal of either body, once a pair needs it
  for (int j = 0; j < sb->edgeCount; ++j) {
    const pdEdge* eb = &sb->edges[j];
    if (prune && (maskB[eb->v[0]] & maskB[eb->v[1]])) continue;
    pdVec3 b0 = pd_v3_add(off, pd_mat3_mulv(&rel, sb->vertices[eb->v[0]]));
    pdVec3 b1 = pd_v3_add(off, pd_mat3_mulv(&rel, sb->vertices[eb->v[1]]));
    pdVec3 c = pd_v3_scale(pd_mat3_mulv(&rel, sb->faces[eb->f[0]].normal), -1.0);
    pdVec3 d = pd_v3_scale(pd_mat3_mulv(&rel, sb->faces[eb->f[1]].normal), -1.0);
    gaussArc arcB;
    bool arcBFormed = false;
    for (int i = 0; i < sa->edgeCount; ++i) {
      const pdEdge* ea = &sa->edges[i];
      if (prune && (maskA[ea->v[0]] & maskA[ea->v[1]])) continue;
      gaussArc arcA;
      if (i < FIND_EE_CACHED && (arcFormed >> i & 1u)) {
        arcA = arcsA[i];
      } else {
        arcA = gauss_arc(sa->faces[ea->f[0]].normal, sa->faces[ea->f[1]].normal);
        if (i < FIND_EE_CACHED) arcsA[i] = arcA, arcFormed |= 1ull << i;
      }
      if (!arcBFormed) arcB = gauss_arc(c, d), arcBFormed = true;
      arcMeeting meet = arcs_meet_formed(&arcA, &arcB, EE_ARC_SLACK);
      if (meet == arcsApart) continue;
      edgeGeom g;
      if (!edge_pair_geometry(sa, i, b0, b1, true, &g) || !(g.depth > 0.0)) continue;
      if (meet == arcsTouch) {
        // the faces around the two edges, as axes from A to B: A's normals, B's reversed (c, d)
        const int faces[4] = {ea->f[0], ea->f[1], eb->f[0], eb->f[1]};
        double shallowest = INFINITY;
        for (int k = 0; k < 4; ++k)
          shallowest = fmin(shallowest, face_overlap(sa, sb, &rel, off, k / 2, faces[k], &overlaps));
        if (g.depth > shallowest + tolA + tolB) continue;
      }
      // edges crossing inside a plane both bodies share (the flush sides of a brick on a brick of its
      // width, one tilted a little on the other): the normal, their cross product, lies in the faces
      // that press and the depth along it is nil; the VF contacts at the overlap's corners carry it
      if (in_shared_plane(sa, ea, b0, b1, sb, &rel, off, flushTol)) continue;
      // a new edge pair deeper than the allowance beyond the bodies' own penetration is not where they just met:
      // its lines pass each other a body's width away (two flush boxes rocking a little on each other cross
      // their antipodal edges, lying on the shared planes, inside within any tolerance: a width against a
      // penetration of a fraction of δ_max; cases/sweep/pile_10.scene refuses 1 663 such pairs, all 30 δ_max
      // deep or more). An edge crossing that deepened while its features changed over is as deep as the bodies
      // interpenetrate, and is kept (soak seed 32, scene 592: the corner of a box spinning at 560 rad/s cut an
      // edge, the Minkowski face turning over every 40-100 µs; each successor pair, refused beyond 3 δ_max, left
      // the pair without contact and it sank 83 δ_max). The penetration is formed once per search, when needed.
      if (g.depth > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax) {
        // the least overlap along the bodies' face normals bounds the penetration from above and refuses most
        // such pairs without the whole separating-axis test
        if (isnan(faceOverlap)) faceOverlap = least_face_overlap(sa, sb, &rel, off, &overlaps);
        if (g.depth > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax + faceOverlap) continue;
        if (isnan(penetration)) penetration = penetration_depth(sa, pa, sb, pb);
        if (g.depth > EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax + penetration) continue;
      }
      // a crossing at a vertex in VF contact (a flush stack's corner): that vertex carries it
      if (end_in_vf_contact(out, vfCount, ia, ib, ea, g.s,
                            pd_v3_norm(pd_v3_sub(sa->vertices[ea->v[1]], sa->vertices[ea->v[0]])), vertexReach) ||
          end_in_vf_contact(out, vfCount, ib, ia, eb, g.t, pd_v3_norm(pd_v3_sub(b1, b0)), vertexReach))
        continue;
      // a crossing, not an antipodal Minkowski face: each edge's closest point is inside the other body.
      // A thin body's sharp edge (a sliver, a plate's rim) is a wedge of a few degrees: the other edge's
      // point, the depth away along the pair's normal, leaves it through a face at once although the edge
      // is pressed into the other body. Such a pair is kept when its points are within the depth (at
      // most the pair's δ_max) of inside and the depth is no more than the bodies' overlap along the
      // normal: a bogus pair whose lines pass a body's width apart reads a depth of that width, its
      // points that far outside.
      pdVec3 onA = pd_v3_sub(g.point, pd_v3_scale(g.normal, 0.5 * g.depth));  // on A's edge
      pdVec3 onB = pd_v3_add(g.point, pd_v3_scale(g.normal, 0.5 * g.depth));  // on B's edge
      pdVec3 onAinB = pd_mat3_tmulv(&rel, pd_v3_sub(onA, off));
      if (!inside_body(sa, onB, tolA) || !inside_body(sb, onAinB, tolB)) {
        // Where the bodies interpenetrate by P, a pair deeper than δ_max may have its points up to δ_max + P outside
        // (still within its depth): one slack for every depth, so that acceptance does not jump where the depth
        // crosses the new-pair allowance. With δ_max alone below 3 δ_max and δ_max + P above it, an edge pair 1.3 and
        // 2.7 δ_max deep was refused until no pair of features was left (soak campaign 43, scene 6651: 3.2 δ_max
        // between samples), another was found only at 3.0 δ_max; a 1 cm hull entering a body 58 δ_max deep (seed 32,
        // scene 733) and a hand-over's successor on the same edge at 2.5 δ_max (seed 3, scene 8454) were refused at
        // δ_max. P is formed only for a pair whose points the δ_max slack leaves outside.
        double slack = fmin(g.depth, deltaMax);
        if (!inside_body(sa, onB, slack) || !inside_body(sb, onAinB, slack)) {
          if (!(g.depth > deltaMax)) continue;
          if (isnan(penetration)) penetration = penetration_depth(sa, pa, sb, pb);
          slack = fmin(g.depth, deltaMax + penetration);
          if (!inside_body(sa, onB, slack) || !inside_body(sb, onAinB, slack)) continue;
        }
        pdVec3 u = pd_v3_scale(g.normal, -1.0);  // from A to B
        double overlap = fmin(overlap_along(sa, sb, &rel, off, u), overlap_along(sa, sb, &rel, off, g.normal));
        if (g.depth > overlap + tolA + tolB) continue;
      }
      if (n < capacity)
        out[n] = (pdContactGeom){{ia, ib, pd_contactEE, i, j}, to_world(pa, g.point), pd_mat3_mulv(&pa->R, g.normal),
                                 g.depth};
      ++n;
    }
  }
  return n;
}

// The vertices of contact id's feature on body `body` (a vertex: 1, an edge: 2; a face, or not its body: 0).
static int feature_vertices(const pdModel* model, const pdContactId* id, int body, int v[2]) {
  const pdPolyhedron* s = &model->bodies[body].shape;
  if (id->body1 == body) {
    if (id->kind == pd_contactVF) return v[0] = id->feat1, 1;
    v[0] = s->edges[id->feat1].v[0], v[1] = s->edges[id->feat1].v[1];
    return 2;
  }
  if (id->body2 == body && id->kind == pd_contactEE) {
    v[0] = s->edges[id->feat2].v[0], v[1] = s->edges[id->feat2].v[1];
    return 2;
  }
  return 0;
}

bool pd_contact_continues(const pdModel* model, const pdContactId* a, const pdContactId* b) {
  bool samePair = (a->body1 == b->body1 && a->body2 == b->body2) || (a->body1 == b->body2 && a->body2 == b->body1);
  if (!samePair) return false;
  int bodies[2] = {a->body1, a->body2};
  for (int k = 0; k < 2; ++k) {
    int va[2], vb[2];
    int na = feature_vertices(model, a, bodies[k], va), nb = feature_vertices(model, b, bodies[k], vb);
    for (int i = 0; i < na; ++i)
      for (int j = 0; j < nb; ++j)
        if (va[i] == vb[j]) return true;
  }
  return false;
}

// Drops VF contacts whose vertex belongs to the higher-numbered body when a VF contact of the other
// direction sits at the same place (within twice the larger depth): one physical touch, counted once.
static int drop_coincident(pdContactGeom* c, int count, int lowBody) {
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    bool drop = false;
    if (c[i].id.kind == pd_contactVF && c[i].id.body1 != lowBody) {
      for (int j = 0; j < count && !drop; ++j) {
        if (c[j].id.kind != pd_contactVF || c[j].id.body1 != lowBody) continue;
        double reach = 2.0 * fmax(c[i].depth, c[j].depth);
        drop = pd_v3_norm(pd_v3_sub(c[i].point, c[j].point)) <= reach;
      }
    }
    if (!drop) c[kept++] = c[i];
  }
  return kept;
}

int pd_contacts_find(const pdModel* model, int ia, const pdPose* pa, int ib, const pdPose* pb, const pdPose* pa0,
                     const pdPose* pb0, const pdContactId* previous, int previousCount, pdContactGeom* out,
                     int capacity) {
  PD_ASSERT(ia != ib && ia >= 0 && ib >= 0 && ia < model->bodyCount && ib < model->bodyCount);
  PD_ASSERT((pa0 == NULL) == (pb0 == NULL));
  if (ia > ib) {
    const pdPose* tp = pa;
    pa = pb, pb = tp;
    tp = pa0, pa0 = pb0, pb0 = tp;
    int ti = ia;
    ia = ib, ib = ti;
  }
  // A's vertices against B's faces, and B's against A's (find_ee's pruning)
  faceMask maskA[PRUNE_VERTICES_MAX], maskB[PRUNE_VERTICES_MAX];
  bool prune = model->bodies[ia].shape.vertexCount <= PRUNE_VERTICES_MAX &&
               model->bodies[ib].shape.vertexCount <= PRUNE_VERTICES_MAX;
  int n = 0;
  n = find_vf(model, ia, pa, pa0, ib, pb, pb0, previous, previousCount, out, capacity, n, prune ? maskA : NULL);
  n = find_vf(model, ib, pb, pb0, ia, pa, pa0, previous, previousCount, out, capacity, n, prune ? maskB : NULL);
  n = find_ee(model, ia, pa, ib, pb, prune ? maskA : NULL, prune ? maskB : NULL, out, capacity, n);
  if (n > capacity) return n;
  n = drop_coincident(out, n, ia);
  // the contact state is kept sorted by id (§4.4): sort this pair's contacts (few: insertion sort)
  for (int i = 1; i < n; ++i) {
    pdContactGeom key = out[i];
    int j = i - 1;
    while (j >= 0 && pd_contact_id_compare(&out[j].id, &key.id) > 0) {
      out[j + 1] = out[j];
      --j;
    }
    out[j + 1] = key;
  }
  return n;
}

// Body 2's vertex v in body 1's frame (the frame's, placed once per frame).
static pdVec3 frame_vertex(pdPairFrame* frame, const pdPolyhedron* s2, int v) {
  int slot = v & (PD_PAIR_FRAME_VERTICES - 1);  // v >= 0; a power of two
  if (frame->vertexIndex[slot] != v) {
    frame->vertex[slot] = pd_v3_add(frame->off, pd_mat3_mulv(&frame->rel, s2->vertices[v]));
    frame->vertexIndex[slot] = v;
  }
  return frame->vertex[slot];
}

// EE contact geometry of a known edge pair at the given poses, computed in body 1's frame.
// frame (nullable): body 2's pose in body 1's frame, formed here unless it holds it for these poses already.
static bool edge_contact(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                         pdPairFrame* frame, bool interior, pdContactGeom* out) {
  const pdPolyhedron* s1 = &model->bodies[id->body1].shape;
  const pdPolyhedron* s2 = &model->bodies[id->body2].shape;
  pdPairFrame own;
  if (!frame) frame = &own, own.p1 = NULL;
  if (frame->p1 != p1 || frame->p2 != p2) {
    pose_in_frame_of(p1, p2, &frame->rel, &frame->off);
    frame->p1 = p1, frame->p2 = p2;
    for (int k = 0; k < PD_PAIR_FRAME_VERTICES; ++k) frame->vertexIndex[k] = -1;
  }
  const pdEdge* e2 = &s2->edges[id->feat2];
  pdVec3 b0 = frame_vertex(frame, s2, e2->v[0]), b1 = frame_vertex(frame, s2, e2->v[1]);
  edgeGeom g;
  if (!edge_pair_geometry(s1, id->feat1, b0, b1, interior, &g)) return false;
  out->id = *id;
  out->point = to_world(p1, g.point);
  out->normal = pd_mat3_mulv(&p1->R, g.normal);
  out->depth = g.depth;
  return true;
}

static bool edge_points_inside(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                               const pdContactGeom* g) {
  pdVec3 on1 = pd_v3_muladd(g->point, -0.5 * g->depth, g->normal);  // on body 1's edge
  pdVec3 on2 = pd_v3_muladd(g->point, 0.5 * g->depth, g->normal);   // on body 2's edge
  const pdBody* b1 = &model->bodies[id->body1];
  const pdBody* b2 = &model->bodies[id->body2];
  // as the search accepts a sharp edge's pair (find_ee): the points within the pair's depth of inside,
  // up to the deepest a new pair may be; else a pair found again every step would break at every commit
  double deepest = EE_NEW_DEPTH_MAX_DEFLECTIONS * pd_model_pair_delta_max(model, id->body1, id->body2);
  double sharp = fmin(fmax(g->depth, 0.0), deepest);
  double tol1 = fmax(TRACK_INSIDE_TOL_REL * model->settings.deflection * b1->size, sharp);
  double tol2 = fmax(TRACK_INSIDE_TOL_REL * model->settings.deflection * b2->size, sharp);
  pdVec3 on2in1 = to_local(p1, on2), on1in2 = to_local(p2, on1);
  if (inside_body(&b1->shape, on2in1, tol1) && inside_body(&b2->shape, on1in2, tol2)) return true;
  // and as find_ee accepts a pair deeper than δ_max where the bodies interpenetrate by P: its points within δ_max + P
  // (at most its depth) of inside. Held to less, a deep pair the search finds broke at every commit and was found
  // again at the next, with springs from a hand-over trace while it approached and none once it turned away
  double deltaMax = pd_model_pair_delta_max(model, id->body1, id->body2);
  if (!(g->depth > deltaMax)) return false;
  double slack = fmin(g->depth, deltaMax + penetration_depth(&b1->shape, p1, &b2->shape, p2));
  return inside_body(&b1->shape, on2in1, slack) && inside_body(&b2->shape, on1in2, slack);
}

// Do the Gauss-map arcs of a known edge pair meet at the given poses (see arcs_meet)?
static bool edge_arcs_meet(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2) {
  const pdPolyhedron* s1 = &model->bodies[id->body1].shape;
  const pdPolyhedron* s2 = &model->bodies[id->body2].shape;
  const pdEdge* e1 = &s1->edges[id->feat1];
  const pdEdge* e2 = &s2->edges[id->feat2];
  pdVec3 a = pd_mat3_mulv(&p1->R, s1->faces[e1->f[0]].normal), b = pd_mat3_mulv(&p1->R, s1->faces[e1->f[1]].normal);
  pdVec3 c = pd_v3_scale(pd_mat3_mulv(&p2->R, s2->faces[e2->f[0]].normal), -1.0);
  pdVec3 d = pd_v3_scale(pd_mat3_mulv(&p2->R, s2->faces[e2->f[1]].normal), -1.0);
  return arcs_meet(a, b, c, d, EE_ARC_SLACK) != arcsApart;
}

void pd_contact_geometry(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                         pdContactGeom* out) {
  pd_contact_geometry_framed(model, id, p1, p2, NULL, out);
}

void pd_contact_geometry_framed(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                                pdPairFrame* frame, pdContactGeom* out) {
  out->id = *id;
  if (id->kind == pd_contactVF) {
    const pdPolyhedron* s1 = &model->bodies[id->body1].shape;
    const pdPolyhedron* s2 = &model->bodies[id->body2].shape;
    // (18a) the vertex rides with body 1; (18b) the normal with body 2
    pdVec3 p = to_world(p1, s1->vertices[id->feat1]);
    out->point = p;
    out->normal = pd_mat3_mulv(&p2->R, s2->faces[id->feat2].normal);
    out->depth = face_depth(s2, id->feat2, to_local(p2, p));
    return;
  }
  // where the edge lines are closest; parallel lines have no closest points: normal 0 says so
  if (!edge_contact(model, id, p1, p2, frame, false, out)) {
    out->point = p1->x;
    out->normal = (pdVec3){0, 0, 0};
    out->depth = 0.0;
  }
}

bool pd_contact_track(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                      pdContactGeom* out) {
  return pd_contact_track_framed(model, id, p1, p2, NULL, out);
}

bool pd_contact_track_framed(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                             pdPairFrame* frame, pdContactGeom* out) {
  if (id->kind == pd_contactVF) {
    pd_contact_geometry(model, id, p1, p2, out);
    const pdPolyhedron* s2 = &model->bodies[id->body2].shape;
    pdVec3 q = to_local(p2, out->point);
    // still over its face, and not outside the body across another face (it slid past an edge that is
    // not its face's: near a corner the face plane alone can read deep while the vertex is outside)
    double outside = TRACK_INSIDE_TOL_REL * model->settings.deflection * model->bodies[id->body2].size;
    // over its face polygon within the flush tolerance: a corner resting on a shared side plane wanders
    // across it by roundoff and must not break and be found again on the side face
    double over = fmax(BOUNDARY_TOL_REL * model->bodies[id->body2].size,
                       FLUSH_TOL_DEFLECTIONS * pd_model_pair_delta_max(model, id->body1, id->body2));
    if (!projects_inside(s2, id->feat2, q, over)) return false;
    if (inside_body(s2, q, outside)) return true;
    // a vertex beyond an acute edge (find_vf) stays on its face while it presses on it as there: outside the body by
    // at most its depth and δ_max, its body's support point along −n_F
    // or, pressed through a thin body, outside it across faces turned away from its own (through_far_side)
    double beyond = outside_by(s2, q);
    if (!(beyond <= fmin(out->depth, pd_model_pair_delta_max(model, id->body1, id->body2))) &&
        !through_far_side(s2, id->feat2, q, outside, out->depth))
      return false;
    pdMat3 rel;
    pdVec3 off;
    pose_in_frame_of(p2, p1, &rel, &off);
    return support_along(&model->bodies[id->body1].shape, id->feat1, &rel, q, s2->faces[id->feat2].normal);
  }
  // an edge pair stays a contact while its closest points lie inside both edges and it spans a face of
  // the Minkowski difference (its Gauss-map arcs still meet): past that, other features carry the contact
  // and the lines' distance means nothing
  if (edge_contact(model, id, p1, p2, frame, true, out))
    return edge_arcs_meet(model, id, p1, p2) && edge_points_inside(model, id, p1, p2, out);
  // broken: still report where the edge lines are closest (the caller may integrate on to the end of the
  // step before it drops the contact)
  pd_contact_geometry_framed(model, id, p1, p2, frame, out);
  return false;
}

bool pd_contact_edge_lines(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                           pdContactGeom* out) {
  return edge_contact(model, id, p1, p2, NULL, false, out);
}

double pd_least_face_overlap(const pdPolyhedron* sa, const pdPolyhedron* sb, const pdMat3* rel, pdVec3 off) {
  return least_face_overlap(sa, sb, rel, off, NULL);
}
