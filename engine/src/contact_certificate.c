// polydyn — search certificates: when a pair's contact search may be skipped (paper §4.4 made cheap for resting
// pairs).
//
// Design note. A pair at rest (a stack, a pile settled) is searched after every step although its contacts do
// not change: the interference test and pd_contacts_find cost a resting stack of 10 a fifth of its work. A
// certificate, issued by a search that found nothing new, proves that the search would find nothing new either
// at any poses within a motion `margin` of the ones it was issued at, so the caller may skip both. It rests on
// conditions every contact the search reports must meet (find_vf, find_ee), each with its distance to failing:
// - VF, vertex v of one body in the other: not outside any face plane of the other by more than max(tol,
//   flushTol) (a face it is farther outside of is never a shared plane, and outside it, it is rejected), or, when the
//   other body has an acute edge, by more than δ_max (a vertex beyond an acute edge). Margin: how far v is outside
//   its farthest face plane, less that tolerance. A vertex in the exempt list keeps its face while it is over the
//   face's polygon (find_vf's face continuity): margin, how far its projection is inside the polygon.
// - EE, edges ea of A and eb of B: each edge's closest point within max(tol, δ_max) + P of inside the other body
//   (the slack find_ee allows; P, the bodies' penetration depth, for a pair deeper than δ_max), so neither
//   edge may lie wholly beyond one face plane of the other body by more. A motion m moves the edge by at most m
//   and raises P by at most m (below), so the margin is half of how far beyond that both ends of an edge lie
//   (per edge).
// - EE: the Gauss arcs meet (find_ee's first test). Margin: the sine by which both ends of one arc lie on one
//   side of the other's great circle, beyond the slack find_ee allows (EE_ARC_SLACK); a rotation of B by ‖ΔR‖
//   moves its normals by at most that much.
// - EE: the closest points lie inside both edges and at most 3 δ_max plus the bodies' penetration depth P apart
//   (EE_NEW_DEPTH_MAX_DEFLECTIONS; for lines whose sine is at least CERT_SINE_MIN the computed closest points are
//   the true ones to ~1e-12 of the size, so the depth is their distance), so the segments are that close. A
//   motion m moves the segments by at most m and raises P by at most m (a separating translation of B grown by
//   m separates B moved by m), so the margin is half the segments' distance less 3 δ_max and P, while the sine
//   stays above CERT_SINE_MIN.
// A feature pair in the exempt list (the pair's contacts of C0) needs none: the search reports it as a contact
// the list already has. A feature pair meeting none of the conditions (an inside vertex not in the list, two
// flush parallel edges) leaves no certificate (margin 0).
// The motion measure (pd_search_motion) bounds how far any point of B moves in A's frame and any point of A in
// B's frame, and, divided by `reach`, how far any direction of B turns in A's frame; every margin is a
// distance one of these may travel before its condition can fail (a sine margin times `reach`). Each margin
// keeps CERT_GUARD_REL of the bodies' sizes and distances from the origin back for the rounding of the search's
// own arithmetic (~1e-16 of those).

#include <math.h>
#include <stddef.h>

#include "contact_analysis.h"
#include "contact_features.h"
#include "interference.h"

// The certificates' tolerances (the design note above says what each guards).
#define CERT_SINE_MIN 1e-2
#define CERT_GUARD_REL 1e-9
// The arcs test's rounding allowance on the sine, beyond ARC_TRIPLE_ROUNDING (both are ~1e-14; generous).
#define CERT_ARC_ROUNDING 1e-12
// The penetration depth's error as the separating-axis test computes it (it skips edge pairs nearer parallel than
// PD_SAT_PARALLEL_TOL, whose sliver faces weigh ~that sine × an edge), relative to the bodies' sizes; generous.
#define CERT_PENETRATION_ROUNDING_REL 1e-7

// Largest distance of a vertex from the body's origin, m.
static double vertex_reach(const pdPolyhedron* s) {
  double r2 = 0.0;
  for (int i = 0; i < s->vertexCount; ++i) {
    double d2 = pd_v3_dot(s->vertices[i], s->vertices[i]);
    r2 = d2 > r2 ? d2 : r2;
  }
  return sqrt(r2);
}

// How far q lies outside the farthest face plane of s, m (negative: inside all of them), or a distance of at least
// `enough` once one plane is that far (the caller needs no more).
static double outside_farthest(const pdPolyhedron* s, pdVec3 q, double enough) {
  double most = -INFINITY;
  for (int f = 0; f < s->faceCount && most < enough; ++f) {
    double d = -face_depth(s, f, q);
    most = d > most ? d : most;  // inline max: the depths are finite, and libm's fmax is a call
  }
  return most;
}

// How far both ends q0, q1 of an edge lie beyond one face plane of s, the farthest such plane, m, or a distance of
// at least `enough` once one plane is that far.
static double edge_beyond_one_plane(const pdPolyhedron* s, pdVec3 q0, pdVec3 q1, double enough) {
  double most = -INFINITY;
  for (int f = 0; f < s->faceCount && most < enough; ++f) {
    double d0 = -face_depth(s, f, q0), d1 = -face_depth(s, f, q1), both = d0 < d1 ? d0 : d1;
    most = both > most ? both : most;
  }
  return most;
}

// The sine by which arcs (ab) and (cd) lie apart beyond arcs_meet's slack (both ends of one on one side of the
// other's great circle), or -INFINITY.
static double arcs_apart_margin(const gaussArc* ab, const gaussArc* cd, double slack) {
  double best = -INFINITY;
  const gaussArc* arcs[2][2] = {{ab, cd}, {cd, ab}};
  for (int k = 0; k < 2; ++k) {
    const gaussArc *circle = arcs[k][0], *ends = arcs[k][1];
    double u = pd_v3_dot(ends->a, circle->bxa), v = pd_v3_dot(ends->b, circle->bxa);
    if (!(u * v > 0.0) || !(circle->norm2 > 0.0)) continue;
    double sine = (fmin(fabs(u), fabs(v)) - ARC_TRIPLE_ROUNDING) / sqrt(circle->norm2);
    best = fmax(best, sine - 2.0 * slack - CERT_ARC_ROUNDING);
  }
  return best;
}

// Squared distance between segments p0 + s u and q0 + t v (s, t in [0, 1]) (Ericson, Real-Time Collision Detection,
// 5.1.9; u, v not zero).
static double segment_distance2(pdVec3 p0, pdVec3 u, pdVec3 q0, pdVec3 v) {
  pdVec3 r = pd_v3_sub(p0, q0);
  double a = pd_v3_dot(u, u), e = pd_v3_dot(v, v), f = pd_v3_dot(v, r), c = pd_v3_dot(u, r), b = pd_v3_dot(u, v);
  double denom = a * e - b * b;
  double s = denom > 0.0 ? fmin(fmax((b * f - c * e) / denom, 0.0), 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = fmin(fmax(-c / a, 0.0), 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = fmin(fmax((b - c) / a, 0.0), 1.0);
  }
  pdVec3 d = pd_v3_sub(pd_v3_muladd(p0, s, u), pd_v3_muladd(q0, t, v));
  return pd_v3_dot(d, d);
}

// The exempt contact of this kind on body1's feature feat1 (and, for EE, feat2), or -1.
static int exempt_index(const pdContactId* exempt, int count, pdContactKind kind, int body1, int feat1, int feat2) {
  for (int i = 0; i < count; ++i) {
    const pdContactId* c = &exempt[i];
    if (c->kind == kind && c->body1 == body1 && c->feat1 == feat1 && (kind == pd_contactVF || c->feat2 == feat2))
      return i;
  }
  return -1;
}
static bool exempt_listed(const pdContactId* exempt, int count, pdContactKind kind, int body1, int feat1, int feat2) {
  return exempt_index(exempt, count, kind, body1, feat1, feat2) >= 0;
}

// How far q's projection onto face f's plane may move before it leaves the polygon by more than `over`, m.
static double over_face_margin(const pdPolyhedron* s, int f, pdVec3 q, double over) {
  const pdFace* face = &s->faces[f];
  const int* idx = s->faceVertices + face->first;
  double least = INFINITY;
  for (int i = 0; i < face->count; ++i) {
    pdVec3 a = s->vertices[idx[i]], b = s->vertices[idx[(i + 1) % face->count]];
    pdVec3 e = pd_v3_sub(b, a);
    double side = pd_v3_dot(pd_v3_cross(face->normal, e), pd_v3_sub(q, a)) / pd_v3_norm(e);
    least = fmin(least, side + over);
  }
  return least;
}

// For vertex i of sv (q, sf's frame) at the end of an edge in a listed edge pair, how far it may move before it could
// press through sf's far side on a face F around the pair's edge on sf (find_vf, vf_through_after_edge_pair), m
// (INFINITY: no such pair). That needs it below F, outside no face turned less than 90° from F by more than tracking's
// tolerance `outside`, and outside one turned away from F by more than it: not while any of these is further away than
// the margin. `tolerance` covers the search's tolerance and the rounding.
static double edge_pair_end_margin(const pdPolyhedron* sv, int iv, int i, pdVec3 q, const pdPolyhedron* sf,
                                   double tolerance, double outside, const pdContactId* exempt, int exemptCount) {
  double least = INFINITY;
  for (int k = 0; k < exemptCount; ++k) {
    const pdContactId* c = &exempt[k];
    if (c->kind != pd_contactEE) continue;
    int edgeV = c->body1 == iv ? c->feat1 : c->body2 == iv ? c->feat2 : -1;
    if (edgeV < 0 || (sv->edges[edgeV].v[0] != i && sv->edges[edgeV].v[1] != i)) continue;
    const pdEdge* e = &sf->edges[c->body1 == iv ? c->feat2 : c->feat1];
    for (int s = 0; s < 2; ++s) {
      int f = e->f[s];
      pdVec3 nf = sf->faces[f].normal;
      double above = -face_depth(sf, f, q) - tolerance;  // above F's plane
      double inside = INFINITY;                           // from leaving a face turned away from F
      for (int g = 0; g < sf->faceCount; ++g) {
        double d = face_depth(sf, g, q);
        if (pd_v3_dot(sf->faces[g].normal, nf) < 0.0) inside = fmin(inside, d - tolerance);
        else if (g != f) above = fmax(above, -d - outside - tolerance);
      }
      least = fmin(least, fmax(above, inside));
    }
  }
  return least;
}

// For vertex i of sv (q, sf's frame) listed on face F of body jf, how far it may move before it could cross the plane
// of a face f across a right-angled edge of F that it is not listed on (its depth below f passing `threshold`,
// find_vf's flush tolerance), where find_vf makes it a contact on f as well (vf_across_right_edge,
// contact_analysis.c), m (INFINITY: no such face). `guard`: the rounding kept back.
static double right_edge_face_margin(const pdPolyhedron* sf, int iv, int i, int jf, int F, pdVec3 q, double threshold,
                                     double guard, const pdContactId* exempt, int exemptCount) {
  double least = INFINITY;
  for (int e = 0; e < sf->edgeCount; ++e) {
    int f = face_across_right_edge(sf, e, F);
    if (f < 0) continue;
    if (!vf_listed_on(exempt, exemptCount, iv, i, jf, f))
      least = fmin(least, fabs(face_depth(sf, f, q) - threshold) - guard);
  }
  return least;
}

// The least margin of the vertices of sv (given in sf's frame by rel, off) against sf, vertices listed as VF
// contacts of body iv in `exempt` left out; stops at `bound` (no lower margin needed).
static double vertices_margin(const pdPolyhedron* sv, int iv, const pdMat3* rel, pdVec3 off, const pdPolyhedron* sf,
                              double tolerance, double over, double outside, double guard, const pdContactId* exempt,
                              int exemptCount, double bound) {
  double least = bound;
  for (int i = 0; i < sv->vertexCount && least > 0.0; ++i) {
    pdVec3 q = pd_v3_add(off, pd_mat3_mulv(rel, sv->vertices[i]));
    int listed = exempt_index(exempt, exemptCount, pd_contactVF, iv, i, 0);
    if (listed >= 0) {
      // a vertex in contact keeps its face while it is over it (find_vf), and takes another once it is not
      double margin = over_face_margin(sf, exempt[listed].feat2, q, over);
      least = margin < least ? margin : least;
      least = fmin(least, right_edge_face_margin(sf, iv, i, exempt[listed].body2, exempt[listed].feat2, q, over + guard,
                                                 guard, exempt, exemptCount));
      continue;
    }
    double margin = outside_farthest(sf, q, least + tolerance) - tolerance;
    least = margin < least ? margin : least;
    // the end of an edge in a listed edge pair may become a contact on a face of the other edge it lies below, through
    // the body's far side (find_vf): it is not while above both faces' planes by more than the search's tolerance
    least = fmin(least, edge_pair_end_margin(sv, iv, i, q, sf, tolerance, outside, exempt, exemptCount));
  }
  return least;
}

pdSearchCertificate pd_contacts_certify(const pdModel* model, int ia, const pdPose* pa, int ib, const pdPose* pb,
                                        const pdContactId* exempt, int exemptCount) {
  PD_ASSERT(ia < ib);
  const pdPolyhedron* sa = &model->bodies[ia].shape;
  const pdPolyhedron* sb = &model->bodies[ib].shape;
  pdSearchCertificate cert;
  pose_in_frame_of(pa, pb, &cert.rel, &cert.off);
  double reachA = vertex_reach(sa), reachB = vertex_reach(sb);
  cert.reach = fmax(reachB, reachA + pd_v3_norm(cert.off));
  cert.margin = 0.0;
  pdMat3 relT = pd_mat3_transpose(&cert.rel);
  pdVec3 offA = pd_v3_scale(pd_mat3_mulv(&relT, cert.off), -1.0);  // A in B's frame
  double sizeA = model->bodies[ia].size, sizeB = model->bodies[ib].size;
  double guard = CERT_GUARD_REL * (sizeA + sizeB + pd_v3_norm(pa->x) + pd_v3_norm(pb->x));
  double deltaMax = pd_model_pair_delta_max(model, ia, ib);
  double flushTol = FLUSH_TOL_DEFLECTIONS * deltaMax;
  double tolA = BOUNDARY_TOL_REL * sizeA, tolB = BOUNDARY_TOL_REL * sizeB;
  // VF: B's vertices against A (A's frame), A's against B (B's frame); against a body with an acute edge a vertex
  // outside it by up to δ_max may be a contact too (a vertex beyond an acute edge, find_vf)
  double onA = pd_polyhedron_has_acute_edge(sa) ? fmax(deltaMax, tolA) : fmax(tolA, flushTol);
  double onB = pd_polyhedron_has_acute_edge(sb) ? fmax(deltaMax, tolB) : fmax(tolB, flushTol);
  double overA = fmax(tolA, flushTol) - guard, overB = fmax(tolB, flushTol) - guard;  // find_vf's "over its face"
  // tracking's tolerance for a vertex outside a body (find_vf's vertex through the far side at an edge pair's end)
  double outsideA = TRACK_INSIDE_TOL_REL * model->settings.deflection * sizeA;
  double outsideB = TRACK_INSIDE_TOL_REL * model->settings.deflection * sizeB;
  double least =
      vertices_margin(sb, ib, &cert.rel, cert.off, sa, onA + guard, overA, outsideA, guard, exempt, exemptCount, INFINITY);
  least = vertices_margin(sa, ia, &relT, offA, sb, onB + guard, overB, outsideB, guard, exempt, exemptCount, least);
  if (!(least > 0.0)) return cert;
  // EE: per edge, how far it lies beyond one face plane of the other body (then any pair with it is certified)
  enum { EDGES_MAX = 64 };
  if (sa->edgeCount > EDGES_MAX || sb->edgeCount > EDGES_MAX) return cert;  // (no certificate: searched each step)
  double beyondA[EDGES_MAX], beyondB[EDGES_MAX];
  pdVec3 b0[EDGES_MAX], b1[EDGES_MAX];
  gaussArc arcB[EDGES_MAX];
  // P bounded from above by the least overlap along a face normal (one of the separating-axis test's axes; P as
  // that test computes it is the true one or up to PD_SAT_PARALLEL_TOL × an edge above it)
  double overlap = pd_least_face_overlap(sa, sb, &cert.rel, cert.off);
  double penetration = (overlap > 0.0 ? overlap : 0.0) + CERT_PENETRATION_ROUNDING_REL * (sizeA + sizeB);
  for (int j = 0; j < sb->edgeCount; ++j) {
    const pdEdge* e = &sb->edges[j];
    b0[j] = pd_v3_add(cert.off, pd_mat3_mulv(&cert.rel, sb->vertices[e->v[0]]));
    b1[j] = pd_v3_add(cert.off, pd_mat3_mulv(&cert.rel, sb->vertices[e->v[1]]));
    // half of how far beyond δ_max + P (a margin found at least `least` is as good as its full value: no edge pair
    // needs more)
    double thresholdA = fmax(deltaMax, tolA) + penetration + guard;
    beyondB[j] = 0.5 * (edge_beyond_one_plane(sa, b0[j], b1[j], 2.0 * least + thresholdA) - thresholdA);
    arcB[j] = gauss_arc(pd_v3_scale(pd_mat3_mulv(&cert.rel, sb->faces[e->f[0]].normal), -1.0),
                        pd_v3_scale(pd_mat3_mulv(&cert.rel, sb->faces[e->f[1]].normal), -1.0));
  }
  for (int i = 0; i < sa->edgeCount; ++i) {
    const pdEdge* e = &sa->edges[i];
    pdVec3 a0 = pd_v3_add(offA, pd_mat3_mulv(&relT, sa->vertices[e->v[0]]));
    pdVec3 a1 = pd_v3_add(offA, pd_mat3_mulv(&relT, sa->vertices[e->v[1]]));
    double thresholdB = fmax(deltaMax, tolB) + penetration + guard;
    beyondA[i] = 0.5 * (edge_beyond_one_plane(sb, a0, a1, 2.0 * least + thresholdB) - thresholdB);
  }
  double apart = EE_NEW_DEPTH_MAX_DEFLECTIONS * deltaMax + penetration + guard;
  for (int i = 0; i < sa->edgeCount && least > 0.0; ++i) {
    const pdEdge* ea = &sa->edges[i];
    pdVec3 a0 = sa->vertices[ea->v[0]], u = pd_v3_sub(sa->vertices[ea->v[1]], a0);
    gaussArc arcA = gauss_arc(sa->faces[ea->f[0]].normal, sa->faces[ea->f[1]].normal);
    for (int j = 0; j < sb->edgeCount && least > 0.0; ++j) {
      // each pair needs one condition whose margin is at least the least so far (cheapest first)
      double margin = fmax(beyondA[i], beyondB[j]);
      if (margin >= least || exempt_listed(exempt, exemptCount, pd_contactEE, ia, i, j)) continue;
      margin = fmax(margin, arcs_apart_margin(&arcA, &arcB[j], EE_ARC_SLACK) * cert.reach);
      if (margin >= least) continue;
      pdVec3 v = pd_v3_sub(b1[j], b0[j]);
      double sine = pd_v3_norm(pd_v3_cross(u, v)) / sqrt(pd_v3_dot(u, u) * pd_v3_dot(v, v));
      if (sine > CERT_SINE_MIN) {
        double gap = 0.5 * (sqrt(segment_distance2(a0, u, b0[j], v)) - apart);
        margin = fmax(margin, fmin(gap, (sine - CERT_SINE_MIN) * cert.reach));
      }
      least = fmin(least, margin);
    }
  }
  cert.margin = least > 0.0 ? least : 0.0;
  return cert;
}

double pd_search_motion(const pdSearchCertificate* cert, const pdPose* pa, const pdPose* pb) {
  pdMat3 rel;
  pdVec3 off;
  pose_in_frame_of(pa, pb, &rel, &off);
  double turn2 = 0.0;  // ‖Δrel‖_F², a bound on ‖Δrel‖₂²
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) turn2 += (rel.m[r][c] - cert->rel.m[r][c]) * (rel.m[r][c] - cert->rel.m[r][c]);
  return pd_v3_norm(pd_v3_sub(off, cert->off)) + sqrt(turn2) * cert->reach;
}
