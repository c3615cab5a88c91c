// polydyn (internal) — contact analysis (paper §4.4, App. C): which vertex–face (VF) and edge–edge
// (EE) contacts two interfering convex polyhedra have, where, and when each began.
//
// Conventions
// - Body 1 carries the vertex (VF) or the first edge (EE); body 2 carries the face or the second edge.
// - The contact normal n is a unit vector pointing from body 2 into body 1: the face's outward normal
//   for VF; for EE the edge cross product oriented away from body 2.
// - depth > 0 means the features interpenetrate (the vertex is behind the face plane; the edges
//   have crossed), in m.
// - Poses map body frames to the world: x_world = x + R · x_body.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/vecmath.h"

typedef enum pdContactKind {
  pd_contactVF = 0,
  pd_contactEE = 1,
} pdContactKind;

// The paper's 6-tuple (§4.4): the two bodies, the kinds of their features, the feature indices.
// VF: feat1 is a vertex of body1, feat2 a face of body2. EE: feat1, feat2 are edges, body1 < body2.
typedef struct pdContactId {
  int body1, body2;
  pdContactKind kind;
  int feat1, feat2;
} pdContactId;

typedef struct pdPose {
  pdVec3 x;
  pdMat3 R;
} pdPose;

typedef struct pdContactGeom {
  pdContactId id;
  pdVec3 point;   // world point of application: the vertex (VF); midpoint of the closest points (EE)
  pdVec3 normal;  // unit, from body 2 into body 1
  double depth;   // m, > 0 when interpenetrating
} pdContactGeom;

// Total order of contact ids: by the unordered body pair, then kind, then body1, feat1, feat2.
int pd_contact_id_compare(const pdContactId* a, const pdContactId* b);

// Appends to out[] (at most capacity) the contacts between bodies ia and ib in the given poses, and
// returns how many there are (which may exceed capacity: the caller grows its buffer and retries).
// A vertex already in contact with a face of the other body in `previous` (sorted, nullable) keeps
// that face (face continuity, §4.4.3); a new one takes the face whose plane it crossed between the
// poses pa0, pb0 (the step's start; both NULL: unknown) and pa, pb, else the shallowest face over it.
// Equal-feature duplicates (a vertex of each body at the same point, as when equal cubes meet face to
// face) are reported once.
int pd_contacts_find(const pdModel* model, int ia, const pdPose* pa, int ib, const pdPose* pb, const pdPose* pa0,
                     const pdPose* pb0, const pdContactId* previous, int previousCount, pdContactGeom* out,
                     int capacity);


// Does contact b continue contact a of the same pair (a hand-over): on one of the two bodies, a vertex or edge of each
// that share a vertex, so the touch moved from one feature to the next over their common vertex (a vertex onto the
// next edge or face, an edge crossing onto an edge at its end)?
bool pd_contact_continues(const pdModel* model, const pdContactId* a, const pdContactId* b);

// Geometry of one known contact at the given poses (tracking, §4.4.2): VF by (18), EE by the
// closest points of the two edge lines. Returns false when the contact must break for geometric
// reasons: the vertex projected onto the face plane leaves the face polygon, or an EE closest point
// leaves its edge. `out` is filled either way: when an EE contact breaks it holds the closest points of
// the two edge lines, or, for parallel lines, a zero normal (no geometry exists).
bool pd_contact_track(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                      pdContactGeom* out);

// The geometry pd_contact_track fills, without deciding whether the contact still holds: what the
// derivative needs inside a step (a contact is kept or dropped between steps only). Same numbers,
// bit for bit, as pd_contact_track's `out`.
void pd_contact_geometry(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                         pdContactGeom* out);

// Body 2's pose in body 1's frame (rotation rel, offset off) at the poses p1, p2, which EE geometry is computed in.
// A loop over a list of contacts sorted by id meets each pair's contacts one after another: one frame, with p1
// NULL to start, passed to the _framed forms below for them all is formed once per pair, as the same numbers.
// It is valid while the poses it was formed at (pointers it compares) keep their values: within one loop.
// It also keeps body 2's vertices it has placed in that frame (a crossed pair of boxes has 8 EE contacts on 4 of
// each box's edges: 16 edge ends, 4 vertices), each by its index modulo PD_PAIR_FRAME_VERTICES (a power of two).
enum { PD_PAIR_FRAME_VERTICES = 8 };
typedef struct pdPairFrame {
  const pdPose *p1, *p2;
  pdMat3 rel;
  pdVec3 off;
  int vertexIndex[PD_PAIR_FRAME_VERTICES];  // -1: empty
  pdVec3 vertex[PD_PAIR_FRAME_VERTICES];    // off + rel · (body 2's vertex vertexIndex)
} pdPairFrame;
// pd_contact_track and pd_contact_geometry with a pair frame (nullable), bit for bit the same results.
bool pd_contact_track_framed(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                             pdPairFrame* frame, pdContactGeom* out);
void pd_contact_geometry_framed(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                                pdPairFrame* frame, pdContactGeom* out);
// A certificate of a pair's contact search (contact_certificate.c, its design note): at any poses whose motion
// from the ones it was issued at (pd_search_motion) is below `margin`, pd_contacts_find reports no contact of the
// pair (ia < ib) outside the exempt list it was issued with. margin 0: none.
typedef struct pdSearchCertificate {
  double margin;  // m, of pd_search_motion
  pdMat3 rel;     // B's rotation in A's frame when issued
  pdVec3 off;     // B's origin in A's frame when issued, m
  double reach;   // m: max(R_B, R_A + |off|), R a body's largest vertex distance from its origin
} pdSearchCertificate;
// The certificate of pair ia < ib at poses pa, pb with the contacts `exempt` (the pair's contacts of C0).
pdSearchCertificate pd_contacts_certify(const pdModel* model, int ia, const pdPose* pa, int ib, const pdPose* pb,
                                        const pdContactId* exempt, int exemptCount);
// The motion of the pair from the certificate's poses to pa, pb, m: |Δoff| + ‖Δrel‖_F reach, which bounds how far
// any point of B moves in A's frame and any point of A in B's frame, and (over reach) how far B's directions turn.
double pd_search_motion(const pdSearchCertificate* cert, const pdPose* pa, const pdPose* pb);
// Where the edge lines of EE contact id are closest at poses p1, p2 (its normal and the lines' signed distance as
// depth), whether or not the closest points lie inside the edges; false when the lines are parallel (out unset).
bool pd_contact_edge_lines(const pdModel* model, const pdContactId* id, const pdPose* p1, const pdPose* p2,
                           pdContactGeom* out);
