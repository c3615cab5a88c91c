// polydyn — the feature geometry that the contact search (contact_analysis.c) and its search certificates
// (contact_certificate.c) share: the tolerances both must agree on, since a certificate proves what the search
// would find, and the small helpers both use. Private to engine/src.
#ifndef POLYDYN_CONTACT_FEATURES_H
#define POLYDYN_CONTACT_FEATURES_H

#include <math.h>

#include "contact_analysis.h"
#include "polydyn/model.h"
#include "polydyn/vecmath.h"

// Relative tolerance (× body size) of "on the boundary": a point this close outside a face plane or
// a face polygon counts as on it, so roundoff neither breaks a vertex sliding exactly along an edge
// nor loses a corner resting exactly on a corner.
#define BOUNDARY_TOL_REL 1e-12

// Tolerance of "flush", as a fraction of the pair's δ_max (pd_model_pair_delta_max): a face plane
// of one body that the other body does not cross by more than this is a plane both bodies share (bricks
// side by side, a box on a box of the same width): a vertex lying on it has crossed another face, not
// that one, and edges crossing inside it have no depth. A contact on such a plane would carry at most
// this fraction of the deflection an impact at vmax makes; the bodies rock by 1e-6 rad and more while
// they settle (1e-7 m on a 0.1 m brick), which a roundoff-sized tolerance would not absorb.
#define FLUSH_TOL_DEFLECTIONS 1e-3

// Deepest a new EE contact may be beyond the bodies' own penetration, in the pair's δ_max: contacts are found as
// they start (onsets are interpolated to 10⁻³ δ_max), so a deeper one is not where the bodies just met unless they
// interpenetrate that deeply (find_ee: the pair's depth against their penetration depth).
#define EE_NEW_DEPTH_MAX_DEFLECTIONS 3.0

// Gauss-map arcs within this sine of meeting touch (the arcs test in contact_analysis.c says why).
#define ARC_TOUCH_TOL 1e-9
// An edge pair is a contact while its Gauss-map arcs meet within this angle (rad), for the search (find_ee) and for
// tracking alike, so that tracking keeps what the search finds and the search finds what tracking would keep. Arcs
// that only just miss are an edge lying nearly along a face of the other body (the pair's normal within about this
// angle of the face's), pressed into it along a segment whose two ends, where it crosses the face's edges, both carry
// the touch; the Minkowski-face test alone admits one end at a time, whichever the face's rocking tips deeper. So an
// edge lying along a thin body's rim face was held at one end at a time, each end found anew at the depth the two
// shared with its springs at zero (soak campaign 49, scene 439: 6.2 δ_max; docs/contact-model.md, "An edge along a
// face"). 1e-2 for both leaves that scene at 4.2 δ_max, 3e-2 at 3.6 (the plate then pressed between two cubes),
// 5e-2 and 1e-1 no lower. Bodies resting face on face rock by far less, so their edge crossings, whose arcs only
// touch, persist; an edge pair that slid past a corner (arcs apart by the angle between faces) breaks.
#define EE_ARC_SLACK 3e-2
// Absolute rounding margin of a triple product of unit vectors: ~100 ulps of 1.
#define ARC_TRIPLE_ROUNDING 1e-14

// A tracked contact keeps its features while its vertex (VF) or each edge's closest point (EE) lies inside the other body, to this
// fraction of that body's δ_max (deflection × size): a crossing that ends with the springs still loaded
// (elastic contacts end where they began, up to the onset interpolation's error) stays; an edge pair whose
// lines pass each other outside the bodies (it slid past a corner) does not press anywhere and breaks.
#define TRACK_INSIDE_TOL_REL 0.1

// Body b's pose in body a's frame: rotation R_aᵀ R_b, offset R_aᵀ (x_b − x_a).
static inline void pose_in_frame_of(const pdPose* a, const pdPose* b, pdMat3* rel, pdVec3* off) {
  pdMat3 RaT = pd_mat3_transpose(&a->R);
  *rel = pd_mat3_mul(&RaT, &b->R);
  *off = pd_mat3_mulv(&RaT, pd_v3_sub(b->x, a->x));
}

// Depth of point q (body frame) below face f's plane (> 0 inside the half-space).
static inline double face_depth(const pdPolyhedron* s, int f, pdVec3 q) { return s->faces[f].offset - pd_v3_dot(s->faces[f].normal, q); }

// Do faces f and g of s meet at an edge outward normals more than 90° apart: an acute edge, in whose wedge a vertex
// near one face may move into the other?
static inline bool faces_meet_at_acute_edge(const pdPolyhedron* s, int f, int g) {
  if (!(pd_v3_dot(s->faces[f].normal, s->faces[g].normal) < 0.0)) return false;
  for (int e = 0; e < s->edgeCount; ++e)
    if ((s->edges[e].f[0] == f && s->edges[e].f[1] == g) || (s->edges[e].f[0] == g && s->edges[e].f[1] == f)) return true;
  return false;
}

// Whether ids[0 .. count) list vertex `vertex` of vertexBody as a VF contact on face `face` of faceBody.
static inline bool vf_listed_on(const pdContactId* ids, int count, int vertexBody, int vertex, int faceBody, int face) {
  for (int k = 0; k < count; ++k)
    if (ids[k].kind == pd_contactVF && ids[k].body1 == vertexBody && ids[k].feat1 == vertex &&
        ids[k].body2 == faceBody && ids[k].feat2 == face)
      return true;
  return false;
}

// Outward normals of two faces whose cosine is within this of 0 meet at a right angle: a vertex pressed into both is
// held by a VF contact on each, whose elastic forces sum to the vertex–edge element's (contact_analysis.c,
// vf_across_right_edge). Box and prism normals are built to ~1e-16; this admits hulls given to ~6 digits.
#define RIGHT_ANGLE_COS_TOL 1e-6

// The face across edge e of s from face F when e borders F and the two meet at a right angle (normals perpendicular
// within RIGHT_ANGLE_COS_TOL), else -1.
static inline int face_across_right_edge(const pdPolyhedron* s, int e, int F) {
  const pdEdge* edge = &s->edges[e];
  if (edge->f[0] != F && edge->f[1] != F) return -1;
  int f = edge->f[0] == F ? edge->f[1] : edge->f[0];
  return fabs(pd_v3_dot(s->faces[F].normal, s->faces[f].normal)) <= RIGHT_ANGLE_COS_TOL ? f : -1;
}

// An arc (a, b) of the Gauss map with its great circle's normal b × a and that normal's squared length: the
// search tests every edge of one body against every edge of the other, so each arc's are formed once.
typedef struct gaussArc {
  pdVec3 a, b, bxa;
  double norm2;
} gaussArc;
static inline gaussArc gauss_arc(pdVec3 a, pdVec3 b) {
  pdVec3 bxa = pd_v3_cross(b, a);
  return (gaussArc){a, b, bxa, pd_v3_dot(bxa, bxa)};
}

// The least overlap of A and B along the face normals of both, m: an upper bound of their penetration depth (those
// normals are among the separating-axis test's axes). B's pose in A's frame rel, off.
double pd_least_face_overlap(const pdPolyhedron* sa, const pdPolyhedron* sb, const pdMat3* rel, pdVec3 off);

#endif
