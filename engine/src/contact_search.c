// polydyn — the contact search at the end of a trial step (paper §4.2–§4.4): the broad phase over the step, the
// tunnelling guard (travel), the interference test of every listed pair, its search certificates (contact_analysis.h)
// and the contact search of the touching ones, which yields the candidates: the contacts of C1 that C0 lacks.
//
// The per-pair loops are split with a help desk when long enough (help_desk.h); each pair's numbers are the same on
// any thread, and the candidates are merged in pair order. The arrays grow here between steps, never inside a
// derivative.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_list.h"
#include "grow.h"
#include "model_contact.h"
#include "onsets.h"
#include "state_layout.h"
#include "contact_features.h"

// Tunnelling guard: over one step, two bodies whose swept boxes overlap may move relative to each other by
// at most this fraction of the thinner one's width. A quarter keeps a vertex that crossed a face within
// the first half of the body, so the face it crossed is still the nearest one and the contact is found
// with the right face; the step is retried shorter (with a little safety) otherwise.
#define PD_TRAVEL_WIDTH_FRACTION 0.25
// ... and by at most this many of the pair's design deflections δ_max: a vertex that sank deeper than its
// distance to the border of the face it crossed finds a side face nearest, and the contact is missed (a
// cube landing with its corners a few mm inside a face's border, at 1 m/s and 10 ms steps). Two δ_max
// keeps the sinking within the deflection the springs are designed for; the onset retry then finds the
// moment of contact. It costs steps only while two bodies' swept boxes overlap.
#define PD_TRAVEL_DEFLECTIONS 2.0
#define PD_TRAVEL_RETRY_SAFETY 0.9
// How far past the step just taken the guard looks for the next one (travelStep): the error control grows a step by at
// most 5×; twice is enough to keep a step the guard holds from being tried too long and retried, every step.
#define PD_TRAVEL_ROOM_MAX 2.0
// Numbers per vertex in reaching_fraction's scratch: its point at the step's start (3), its chord over the step (3)
// and the chord's length, and how far the arc it follows may stray from that chord.
#define PD_REACH_VERTEX_SIZE 8

// The contact search's per-pair lists, to cacheCapacity.
static void grow_pair_lists(pdContactSet* set) {
  set->certified = pd_grow(set->certified, set->cacheCapacity, sizeof *set->certified);
  set->certs = pd_grow(set->certs, set->cacheCapacity, sizeof *set->certs);
  set->certsNext = pd_grow(set->certsNext, set->cacheCapacity, sizeof *set->certsNext);
  set->pairPrevious = pd_grow(set->pairPrevious, set->cacheCapacity, sizeof *set->pairPrevious);
  set->pairPreviousCount = pd_grow(set->pairPreviousCount, set->cacheCapacity, sizeof *set->pairPreviousCount);
  set->pairFound = pd_grow(set->pairFound, set->cacheCapacity, sizeof *set->pairFound);
  set->pairFoundCount = pd_grow(set->pairFoundCount, set->cacheCapacity, sizeof *set->pairFoundCount);
}

void pd_contact_search_create(const pdModel* model, pdContactSet* set, const bool* fixed) {
  int n = model->bodyCount;
  set->broad = pd_broad_phase_create(n, fixed, 0.0);
  PD_ASSERT(set->broad != NULL);
  set->candidateCapacity = 64;
  set->candidates = pd_grow(NULL, set->candidateCapacity, sizeof *set->candidates);
  for (int part = 0; part < 2; ++part) {
    set->search[part].foundCapacity = 64;
    set->search[part].found = pd_grow(NULL, set->search[part].foundCapacity, sizeof *set->search[part].found);
  }
  set->pairCapacity = 2 * n + 16;
  set->pairs = pd_grow(NULL, set->pairCapacity, sizeof *set->pairs);
  set->cacheCapacity = set->pairCapacity;
  set->cache = pd_grow(NULL, set->cacheCapacity, sizeof *set->cache);
  set->cacheNext = pd_grow(NULL, set->cacheCapacity, sizeof *set->cacheNext);
  set->touching = pd_grow(NULL, set->cacheCapacity, sizeof *set->touching);
  grow_pair_lists(set);
  // reaching_fraction's scratch: two bodies' vertex moves and their bounding planes (a box's 6 or a fixed body's faces),
  // and two numbers a vertex for plane_reach
  set->reachVertexMax = 1, set->reachFaceMax = 6;
  for (int i = 0; i < n; ++i) {
    const pdPolyhedron* shape = &model->bodies[i].shape;
    if (shape->vertexCount > set->reachVertexMax) set->reachVertexMax = shape->vertexCount;
    if (shape->faceCount > set->reachFaceMax) set->reachFaceMax = shape->faceCount;
  }
  set->reachScratch = pd_grow(NULL, 2 * (PD_REACH_VERTEX_SIZE * set->reachVertexMax + 4 * set->reachFaceMax) +
                                        2 * set->reachVertexMax,
                              sizeof *set->reachScratch);
}

void pd_contact_search_free(pdContactSet* set) {
  free(set->candidates);
  for (int part = 0; part < 2; ++part) free(set->search[part].found);
  pd_broad_phase_free(set->broad);
  free(set->pairs);
  free(set->cache);
  free(set->cacheNext);
  free(set->touching);
  free(set->reachScratch);
  free(set->pairPrevious);
  free(set->pairPreviousCount);
  free(set->pairFound);
  free(set->pairFoundCount);
  free(set->certs);
  free(set->certified);
  free(set->certsNext);
}

static void add_candidate(pdContactSet* set, const candidate* c) {
  if (set->candidateCount == set->candidateCapacity) {
    set->candidateCapacity *= 2;
    set->candidates = pd_grow(set->candidates, set->candidateCapacity, sizeof *set->candidates);
  }
  set->candidates[set->candidateCount++] = *c;
}

// The rotation angle from pose p0 to pose p1, rad (0 … π).
static double turn_angle(const pdPose* p0, const pdPose* p1) {
  pdMat3 r0t = pd_mat3_transpose(&p0->R);
  pdMat3 d = pd_mat3_mul(&p1->R, &r0t);
  return acos(fmax(-1.0, fmin(1.0, 0.5 * (d.m[0][0] + d.m[1][1] + d.m[2][2] - 1.0))));
}

// How far a moving body's points may stray over a step of h from the chords between their end positions by its turn,
// m (yb0, yb1 its numbers at the step's ends). Turning uniformly by φ about an axis, a point at ρ from it has
// |p''| = ρ φ²/h², and its path strays from its chord by at most λ(1 − λ) h²/2 |p''| ≤ ρ φ²/8 (the interpolation
// error in integral form, in norm): twice that for safety, as vertex_moves' sag, at ρ ≤ r, and at most 2r (a point
// stays on its circle). φ = h |ω|, the larger of the ends', or the angle between the end poses if larger: a spin of more
// than half a turn a step shows a smaller one. The end poses alone miss it: a 0.4 m bar turning 0.5 rad in a step swings
// its end 6 mm beyond both. The velocities' change is left out, as in the guard's move bound: gravity bends a path by
// g h²/8, 0.12 mm over the longest default step, and contact forces act on pairs that are listed already.
// turned: turn_angle(p0, p1).
static double sway(const double* yb0, const double* yb1, double h, double r, double turned) {
  double turn = fmax(h * fmax(pd_v3_norm(pd_layout_w(yb0)), pd_v3_norm(pd_layout_w(yb1))), turned);
  return r * fmin(0.25 * turn * turn, 2.0);
}

// How far body i's points move at most between two poses, m: the centre's displacement plus the largest
// vertex radius times the rotation angle (turned: turn_angle(p0, p1)).
static double travel(const pdBody* b, const pdPose* p0, const pdPose* p1, double turned) {
  return pd_v3_norm(pd_v3_sub(p1->x, p0->x)) + b->radius * turned;
}

// Broad phase over the step: each moving body's box covers its boxes at both ends of the step and how far its points
// may stray from their chords in between (sway), so a pair that met and parted (or tunnelled) inside the step is
// listed too, and the tunnelling guard sees it: a spinning body whose corner swings through the floor between two
// steps' ends. Returns the number of pairs. Measures each moving body's travel over the step too (travel(), for the
// tunnelling guard), from the same turn angle.
int pd_contact_search_broad_phase(const pdModel* model, pdContactSet* set, const double* y0, const double* y1,
                                  double h, const pdPose* poses0, const pdPose* poses1) {
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    const double *yb0 = y0 + PD_BODY_STATE_SIZE * k, *yb1 = y1 + PD_BODY_STATE_SIZE * k;
    double turned = turn_angle(&poses0[i], &poses1[i]);
    set->travel[i] = travel(&model->bodies[i], &poses0[i], &poses1[i], turned);
    double margin = sway(yb0, yb1, h, model->bodies[i].radius, turned);
    pdAabb a = pd_aabb_of(&model->bodies[i].shape, poses0[i].x, &poses0[i].R);
    pdAabb b = pd_aabb_of(&model->bodies[i].shape, poses1[i].x, &poses1[i].R);
    for (int d = 0; d < 3; ++d) a.lo[d] = fmin(a.lo[d], b.lo[d]) - margin, a.hi[d] = fmax(a.hi[d], b.hi[d]) + margin;
    set->boxes[i] = a;
  }
  // grown between steps: the analysis runs after a step, outside the derivative
  int pairCount = pd_broad_phase_pairs_grown(set->broad, set->boxes, &set->pairs, &set->pairCapacity);
  if (pairCount > set->cacheCapacity) {
    set->cacheCapacity = set->pairCapacity;
    set->cache = pd_grow(set->cache, set->cacheCapacity, sizeof *set->cache);
    set->cacheNext = pd_grow(set->cacheNext, set->cacheCapacity, sizeof *set->cacheNext);
    set->touching = pd_grow(set->touching, set->cacheCapacity, sizeof *set->touching);
    grow_pair_lists(set);
  }
  return pairCount;
}

// The planes that bound where a point may end inside body i at the step's end (4 numbers a plane: normal, offset;
// a point p lies beyond one where n·p > offset), into planes; returns their count. A fixed body's own face planes;
// a moving body's swept box's six (set->boxes: it holds the body at the step's end, and at a part of the step).
static int bounding_planes(const pdModel* model, const pdContactSet* set, int i, double* planes) {
  const pdBody* body = &model->bodies[i];
  if (!body->fixed) {
    const pdAabb* box = &set->boxes[i];
    for (int side = 0; side < 6; ++side) {
      double* pl = planes + 4 * side;
      int axis = side / 2;
      pl[0] = pl[1] = pl[2] = 0.0;
      pl[axis] = side % 2 ? 1.0 : -1.0;
      pl[3] = side % 2 ? box->hi[axis] : -box->lo[axis];
    }
    return 6;
  }
  const pdPose* pose = &set->poses1[i];
  for (int f = 0; f < body->shape.faceCount; ++f) {
    pdVec3 n = pd_mat3_mulv(&pose->R, body->shape.faces[f].normal);
    double* pl = planes + 4 * f;
    pl[0] = n.x, pl[1] = n.y, pl[2] = n.z;
    pl[3] = body->shape.faces[f].offset + pd_v3_dot(n, pose->x);
  }
  return body->shape.faceCount;
}

static double beyond(const double* plane, const double* p) {
  return plane[0] * p[0] + plane[1] * p[1] + plane[2] * p[2] - plane[3];
}

// Each vertex of body i at the step's start and how far a fraction λ of the step may move it, into scratch
// (PD_REACH_VERTEX_SIZE numbers a vertex): along the step's screw motion (rotation by φ about u, the centre moving
// uniformly) a point w from the centre of mass is at most λ |c| + ρ φ²/4 from its start, c the chord of the whole step
// and ρ = |u × w| (the arc strays from the chord by at most λ(1 − λ)/2 of its second derivative, ρφ², per
// component). Both terms are convex over the body, and so is the chord's part along a direction, max(0, n·c): c is
// affine in the point; and the arc strays from its chord only across the axis u, so along a direction n by at most
// |n × u| of it. A rolling wheel's rim point on the ground has a short chord where |Δx| + φ ρ, the arc's length, would
// be twice its speed times the step. Returns u, or 0 where it is ill-defined.
static pdVec3 vertex_moves(const pdBody* body, const pdPose* p0, const pdPose* p1, double* scratch) {
  pdMat3 r0t = pd_mat3_transpose(&p0->R);
  pdMat3 d = pd_mat3_mul(&p1->R, &r0t);
  double cosAngle = fmax(-1.0, fmin(1.0, 0.5 * (d.m[0][0] + d.m[1][1] + d.m[2][2] - 1.0)));
  double angle = acos(cosAngle);
  pdVec3 sinAxis = {0.5 * (d.m[2][1] - d.m[1][2]), 0.5 * (d.m[0][2] - d.m[2][0]), 0.5 * (d.m[1][0] - d.m[0][1])};
  double sinAngle = pd_v3_norm(sinAxis);
  // near φ = 0 or π the axis is ill-defined from the skew part: ρ <= |w| holds for any axis
  bool axisKnown = sinAngle > 1e-6;
  for (int v = 0; v < body->shape.vertexCount; ++v) {
    pdVec3 w = pd_mat3_mulv(&p0->R, body->shape.vertices[v]);
    pdVec3 start = pd_v3_add(p0->x, w);
    pdVec3 end = pd_v3_add(p1->x, pd_mat3_mulv(&p1->R, body->shape.vertices[v]));
    pdVec3 chord = pd_v3_sub(end, start);
    double lever = axisKnown ? pd_v3_norm(pd_v3_cross(sinAxis, w)) / sinAngle : pd_v3_norm(w);
    double* at = scratch + PD_REACH_VERTEX_SIZE * v;
    at[0] = start.x, at[1] = start.y, at[2] = start.z;
    at[3] = chord.x, at[4] = chord.y, at[5] = chord.z;
    at[6] = pd_v3_norm(chord);
    at[7] = 0.25 * lever * angle * angle;
  }
  return axisKnown ? pd_v3_scale(sinAxis, 1.0 / sinAngle) : (pdVec3){0.0, 0.0, 0.0};
}

// Where the step's move bounds are evaluated at a fraction λ of the step, they stand for a step λ times as long, the
// motion going on as it went: its chord λ c and its sag λ² times this step's (the turn is λ φ). At λ = 1 they are this
// step's bounds, which the retry checks on every step taken; below and above they predict the step to try.
//
// A vertex's move bound over a fraction lambda of the step (vertex_moves): all of it, or, with `toward` (a plane,
// bounding_planes), only how far it may go past that plane along its inward normal: the chord's part that way and
// `sagAlong` (|n × u|, sole_entry_face) of the sag.
static double vertex_move(const double* at, double lambda, const double* toward, double sagAlong) {
  if (!toward) return lambda * at[6] + at[7];
  double inward = -(toward[0] * at[3] + toward[1] * at[4] + toward[2] * at[5]);
  return lambda * fmax(0.0, inward) + sagAlong * at[7];
}

// The largest move bound (vertex_move, all of it or toward `plane` alone) over the points of a body (its vertices in
// `moves`) that may get beyond `plane` over a fraction lambda of the step: the vertices whose bound exceeds their
// distance outside it (inside ones all count), and where an edge crosses from such a vertex to one that cannot.
// Between vertices the bound is taken as their barycentric mix, which is at least the convex bound's value there.
// Once the largest so far reaches `stopAbove` the rest is not looked at: the result is then at least stopAbove and at
// most the bound (reaching_move keeps the smaller of it and a best at most stopAbove, or only compares it).
static double plane_reach(const pdPolyhedron* shape, const double* moves, const double* plane, double lambda,
                          bool alongNormal, double sagAlong, double stopAbove, double* scratch) {
  const double* toward = alongNormal ? plane : NULL;
  double most = 0.0;
  // each vertex's move bound and by how much it exceeds its distance outside the plane, for its edges below
  double *move = scratch, *over = scratch + shape->vertexCount;
  for (int v = 0; v < shape->vertexCount; ++v) {
    const double* at = moves + PD_REACH_VERTEX_SIZE * v;
    move[v] = vertex_move(at, lambda, toward, sagAlong);
    over[v] = move[v] - beyond(plane, at);
    // the larger inline, not fmax's libm call (1.8 M calls on cases/bench/pile_300.scene's first 0.2 s): the moves are
    // finite and at least +0, so the same value
    if (over[v] > 0.0 && move[v] > most) {
      most = move[v];
      if (most >= stopAbove) return most;
    }
  }
  for (int e = 0; e < shape->edgeCount && most < stopAbove; ++e) {
    int u = shape->edges[e].v[0], w = shape->edges[e].v[1];
    double fu = over[u], fw = over[w];
    if ((fu > 0.0) == (fw > 0.0)) continue;  // in or out as a whole: its vertices tell
    double t = fu / (fu - fw);                 // where it crosses out
    double crossing = (1.0 - t) * move[u] + t * move[w];
    if (crossing > most) most = crossing;
  }
  return most;
}

// The largest move, over a fraction lambda of the step, of the points of a body (its vertices in `moves`:
// vertex_moves) that may end it inside the other body (bounded by `planes`: bounding_planes), m: what the tunnelling
// guard needs to bound, where travel() bounds every point's. A rigid body's move bound above is convex over it, so a
// point's is at most the barycentric mix of its polyhedron's vertices'; and a point p can end inside the other body only
// if λ d(p) > g(p) for every plane, g its signed distance beyond the plane (1-Lipschitz and affine). For one plane the
// set where λ d − g > 0 is a convex part of the body whose corners are vertices and crossings on edges, so the largest
// move over it is at one of those; each plane gives a bound, the smallest is kept. A spinning or rolling body's far
// points move fast but cannot reach the other body: only the ones that can count (a top spinning on its tip, a wheel
// on its rim).
//
// Where only whether it is within `enough` (> 0) matters (one moving body against a fixed one), the first plane whose
// bound is within it answers, and a plane's search stops once above it; with `enough` 0, the bound itself.
static double reaching_move(const pdPolyhedron* shape, const double* moves, const double* planes, int planeCount,
                            double lambda, double enough, double* scratch) {
  double best = INFINITY;
  // past this a plane's bound is out: past the best so far, and, with `enough`, past it
  double out = enough > 0.0 ? nextafter(enough, INFINITY) : INFINITY;
  for (int k = 0; k < planeCount && best > enough; ++k)
    best = fmin(best, plane_reach(shape, moves, planes + 4 * k, lambda, false, 1.0, fmin(best, out), scratch));
  return best;
}

// One moving body's side of a pair in the guard's measure: its vertices' moves (vertex_moves) and turn axis, the
// other body's bounding planes, and, where the other body is fixed, the candidate for its face that is the moving
// body's only way in (entry_face) with the part of the sag that can point along that face's normal, and the fractions
// at which that face is known to hold (entryHolds) and to fail (entryFails).
typedef struct reachSide {
  const pdPolyhedron* shape;
  const double* moves;
  pdVec3 axis;
  const double* planes;
  int planeCount;
  int entryFace;  // -1: none
  double sagAlong;
  double entryHolds, entryFails;
  double* scratch;  // plane_reach's
} reachSide;

// The candidate for a fixed body's sole entry face (entry_holds) for a moving body: the plane that the moving body's
// most inside vertex is least inside (its nearest face), into side->entryFace, with side->sagAlong: |n × u| for its
// normal n and the turn's axis u (1 where the axis is ill-defined: no turn, or half a turn).
static void entry_face(reachSide* side) {
  side->entryFace = -1, side->sagAlong = 1.0, side->entryHolds = 0.0, side->entryFails = INFINITY;
  double deepest = INFINITY;
  for (int v = 0; v < side->shape->vertexCount; ++v) {
    const double* at = side->moves + PD_REACH_VERTEX_SIZE * v;
    int nearest = 0;
    double outside = -INFINITY;
    for (int k = 0; k < side->planeCount; ++k) {
      double g = beyond(side->planes + 4 * k, at);
      if (g > outside) outside = g, nearest = k;
    }
    if (outside < deepest) deepest = outside, side->entryFace = nearest;
  }
  if (side->entryFace < 0 || pd_v3_norm(side->axis) == 0.0) return;
  const double* n = side->planes + 4 * side->entryFace;
  side->sagAlong = fmin(1.0, pd_v3_norm(pd_v3_cross((pdVec3){n[0], n[1], n[2]}, side->axis)));
}

// Is the candidate face F (entry_face) of a fixed body (its planes) the only way into it for every point of a moving
// body over a fraction lambda of the step? It is when every vertex v, for every other face j, ends the fraction
// farther inside j's plane than it can be past F's:
//     −g_j(v) − (λ|c_v| + s_v) > −g_F(v) + (λ max(0, −n_F·c_v) + |n_F × u| s_v)
// (g signed distances beyond the planes at the start, c the chord, s the sag, u the turn's axis: vertex_moves). Each
// side is a convex bound and an affine part, so it holds over the whole body once it holds at the vertices. Then, all
// through the fraction, a point of the body that is inside the fixed one is deeper behind every other face than
// behind F: F is the face it is found against, and it cannot pass through and out of another; how deep it is behind F
// grows by at most its move along F's inward normal. That, not its whole move, is what the guard bounds for it: a
// block sliding on the floor, or a top spinning on its tip, moves its touching points along the face, not into it, and
// such a move can neither sink them nor carry them through. The bounds grow with λ, so the condition holds up to some
// fraction and fails above it: each answer is kept for the bisection's later fractions.
static bool entry_holds(reachSide* side, double lambda) {
  if (side->entryFace < 0 || lambda >= side->entryFails) return false;
  if (lambda <= side->entryHolds) return true;
  const double* entry = side->planes + 4 * side->entryFace;
  for (int v = 0; v < side->shape->vertexCount; ++v) {
    const double* at = side->moves + PD_REACH_VERTEX_SIZE * v;
    double behindEntry = -beyond(entry, at) + vertex_move(at, lambda, entry, side->sagAlong);
    double move = vertex_move(at, lambda, NULL, 1.0);
    for (int k = 0; k < side->planeCount; ++k)
      if (k != side->entryFace && -beyond(side->planes + 4 * k, at) - move <= behindEntry) {
        side->entryFails = lambda;
        return false;
      }
  }
  side->entryHolds = lambda;
  return true;
}

// One moving body's share of a pair's reaching move over a fraction lambda of the step, as far as the guard's test
// against `allowed` needs it: reaching_move, or, where the other body is fixed and its entry face holds at lambda
// (entry_holds), the smaller of that and the largest move into the face of the points that may get past it (both
// bound the same points; the face's, which needs one plane where reaching_move takes every plane, is tried first and
// is enough when within `allowed`). Each grows with lambda, and the face holds up to some fraction: the result, as
// compared with `allowed`, grows with lambda too (reaching_fraction bisects it).
static double side_reach(reachSide* side, double lambda, double allowed, double enough) {
  double inward = INFINITY;
  if (entry_holds(side, lambda)) {
    inward = plane_reach(side->shape, side->moves, side->planes + 4 * side->entryFace, lambda, true,
                         side->sagAlong, INFINITY, side->scratch);
    if (inward <= allowed) return inward;
  }
  return fmin(inward, reaching_move(side->shape, side->moves, side->planes, side->planeCount, lambda, enough,
                                    side->scratch));
}

// Bisections of the step fraction a pair's reaching travel allows: the fraction is then known to ~1e-3 of the
// step, far finer than the retry's safety (PD_TRAVEL_RETRY_SAFETY).
#define PD_TRAVEL_BISECTIONS 10

// The largest fraction of the step, between `floor` (known to hold) and `most`, over which pair (a, b)'s reaching
// travel (side_reach of each moving body against the other, summed) stays within `allowed`; `most` when all of it
// does. `touching`: the pair has contacts at the step's start. Fractions above 1 extrapolate the step's motion: what
// the next step may take if the motion goes on.
static double reaching_fraction(const pdModel* model, pdContactSet* set, int a, int b, bool touching, double allowed,
                                double floor, double most) {
  const pdBody *ba = &model->bodies[a], *bb = &model->bodies[b];
  double* movesA = set->reachScratch;
  double* movesB = movesA + PD_REACH_VERTEX_SIZE * set->reachVertexMax;
  double* planesA = movesB + PD_REACH_VERTEX_SIZE * set->reachVertexMax;  // bounding body a: for b's points
  double* planesB = planesA + 4 * set->reachFaceMax;
  double* planeScratch = planesB + 4 * set->reachFaceMax;
  reachSide sides[2];
  int sideCount = 0;
  if (!ba->fixed) {
    pdVec3 axis = vertex_moves(ba, &set->poses0[a], &set->poses1[a], movesA);
    int count = bounding_planes(model, set, b, planesB);
    sides[sideCount++] = (reachSide){&ba->shape, movesA, axis, planesB, count, -1, 1.0, 0.0, 0.0, planeScratch};
  }
  if (!bb->fixed) {
    pdVec3 axis = vertex_moves(bb, &set->poses0[b], &set->poses1[b], movesB);
    int count = bounding_planes(model, set, a, planesA);
    sides[sideCount++] = (reachSide){&bb->shape, movesB, axis, planesA, count, -1, 1.0, 0.0, 0.0, planeScratch};
  }
  // a moving body touching a fixed one may have a sole entry face, where only its points' moves into it count. Not
  // before it touches: a landing's steps stay held by its whole move, and with them how long before a step's end its
  // onset may be, which the correction of an onset found inside a step is bounded for (onset_bound.h)
  if (sideCount == 1 && touching) entry_face(&sides[0]);
  // alone, a side's bound only needs comparing with `allowed`; two are summed
  double enough = sideCount == 1 ? allowed : 0.0;
  double lo = floor, hi = most;
  for (int k = -1; k < PD_TRAVEL_BISECTIONS; ++k) {
    double lambda = k < 0 ? most : 0.5 * (lo + hi);
    double moved = 0.0;
    for (int k2 = 0; k2 < sideCount; ++k2) moved += side_reach(&sides[k2], lambda, allowed, enough);
    if (moved <= allowed) {
      if (k < 0) return most;
      lo = lambda;
    } else {
      hi = lambda;
    }
  }
  return lo;
}

// The longest step (as a fraction of the step just taken, at most PD_TRAVEL_ROOM_MAX) that keeps every listed pair's
// relative travel within PD_TRAVEL_WIDTH_FRACTION of the thinner body's width and PD_TRAVEL_DEFLECTIONS of its
// δ_max. A pair whose bodies' whole travel (travel()) exceeds it is measured again over the points that may reach the
// other body (reaching_fraction). The bodies' travel is the broad phase's, over the same step.
static double travel_room(const pdModel* model, pdContactSet* set, int pairCount) {
  double room = PD_TRAVEL_ROOM_MAX;
  int listed = 0;  // the contact list's cursor: it is sorted by the unordered body pair, as the pairs are
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) < 0) ++listed;
    bool touching = listed < set->count && compare_to_pair(&set->items[listed].id, a, b) == 0;
    double moved = set->travel[a] + set->travel[b];
    double allowed = fmin(PD_TRAVEL_WIDTH_FRACTION * fmin(model->bodies[a].width, model->bodies[b].width),
                          PD_TRAVEL_DEFLECTIONS * pd_model_pair_delta_max(model, a, b));
    if (room * moved > allowed) room = reaching_fraction(model, set, a, b, touching, allowed, allowed / moved, room);
  }
  return room;
}

bool pd_contact_search_travel_retry(const pdModel* model, pdContactSet* set, int pairCount, double h,
                                    double* hRetry) {
  double room = travel_room(model, set, pairCount);
  // the step the guard lets the next one take if the motion goes on (the stepper starts from at most that)
  set->travelStep = room < PD_TRAVEL_ROOM_MAX ? PD_TRAVEL_RETRY_SAFETY * room * h : INFINITY;
  if (!(room < 1.0 && room * h > model->settings.dtmin)) return false;
  *hRetry = fmax(model->settings.dtmin, PD_TRAVEL_RETRY_SAFETY * room * h);
  return true;
}

// A certificate that saved no search, or none issued: the pair waits longer before the next try (a pair in motion, or
// one whose features no certificate covers, would pay for one after every step). The wait doubles from 1.
static void back_off(pairCertificate* c) {
  c->backoff = c->backoff < CERT_BACKOFF_MAX ? 2 * c->backoff + 1 : CERT_BACKOFF_MAX;
  c->wait = c->backoff;
}

// Are all of pair p's contacts of C0 still tracked at the step's end?
static bool all_tracked(const pdContactSet* set, int p) {
  for (int k = set->pairPrevious[p]; k < set->pairPrevious[p] + set->pairPreviousCount[p]; ++k)
    if (!set->eval[k].tracked) return false;
  return true;
}

// Does pair p's certificate, issued with c->contacts of its contacts of C0, hold at the poses pa, pb: the same
// contacts listed (the list only loses contacts between searches, at commits: the same count is the same list),
// each still tracked, and the pair within the certificate's motion?
static bool certificate_holds(const pdContactSet* set, int p, const pairCertificate* c, const pdPose* pa,
                              const pdPose* pb) {
  return c->contacts == set->pairPreviousCount[p] && all_tracked(set, p) &&
         pd_search_motion(&c->cert, pa, pb) < c->cert.margin;
}

// Pairs [begin, end) of the contact search: touching[p] and the pair's new cache entry, or certified[p] when its
// certificate holds.
static void interference_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose* poses1 = job->poses1;
  int cached = 0;  // the cache's cursor (sorted like the pairs); from its start in every range
  for (int p = begin; p < end; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    pdPairSatCache entry = {a, b, pd_pair_sat_cache_find(set->cache, set->cacheCount, &cached, a, b)};
    bool listed = cached < set->cacheCount && set->cache[cached].a == a && set->cache[cached].b == b;
    pairCertificate cert = listed ? set->certs[cached] : (pairCertificate){.cert.margin = 0.0};
    set->certified[p] = false;
    if (job->certificates && cert.cert.margin > 0.0) {
      if (certificate_holds(set, p, &cert, &poses1[a], &poses1[b])) {
        // nothing new to find (contact_analysis.h): the pair keeps its cache and certificate, and is not searched
        cert.used = true;
        set->certified[p] = true;
        set->touching[p] = false;
        set->cacheNext[p] = set->cache[cached];
        set->certsNext[p] = cert;
        continue;
      }
      if (cert.used)
        cert.backoff = 0;
      else
        back_off(&cert);
      cert.cert.margin = 0.0;
      cert.used = false;
    }
    set->certsNext[p] = cert;
    pdSatResult sat;
    const pdBody *A = &job->model->bodies[a], *B = &job->model->bodies[b];
    set->touching[p] = pd_interference(&A->shape, poses1[a].x, &poses1[a].R, &B->shape, poses1[b].x, &poses1[b].R,
                                       PD_SAT_VERDICT, &entry.sat, &sat);
    set->cacheNext[p] = entry;
  }
}

// The contact of C0 (among the pair's items[first .. first + count)) that new contact id takes over from: one that no
// longer tracks and has handed over to none yet; face continuity first (the same vertex on another face), then the
// first whose features id continues. -1: none.
static int handover_predecessor(const pdModel* model, const pdContactSet* set, int first, int count,
                                const pdContactId* id) {
  for (int k = first; k < first + count && id->kind == pd_contactVF; ++k) {
    const pdContactId* old = &set->items[k].id;
    if (old->kind == pd_contactVF && old->body1 == id->body1 && old->feat1 == id->feat1 && !set->eval[k].tracked &&
        !set->eval[k].transferred)
      return k;
  }
  for (int k = first; k < first + count; ++k)
    if (!set->eval[k].tracked && !set->eval[k].transferred && pd_contact_continues(model, &set->items[k].id, id)) return k;
  return -1;
}

// Did pair p's search find nothing its contacts of C0 (`previous`, sorted like found[0 .. n)) do not have, with
// each of them tracked?
static bool quiet(const pdContactSet* set, int p, const pdContactGeom* found, int n, const pdContactId* previous) {
  if (!all_tracked(set, p)) return false;
  int count = set->pairPreviousCount[p], j = 0;
  for (int f = 0; f < n; ++f) {
    while (j < count && pd_contact_id_compare(&previous[j], &found[f].id) < 0) ++j;
    if (j == count || pd_contact_id_compare(&previous[j], &found[f].id) != 0) return false;
  }
  return true;
}

// The contacts of the touching pairs [begin, end) into the part's found[], pair after pair (pairFound,
// pairFoundCount). A part's buffer grows here, on whichever thread runs it (between steps, not in the derivative).
static void find_range(void* ctx, int part, int begin, int end) {
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose *poses0 = job->poses0, *poses1 = job->poses1;
  searchPart* sp = &set->search[part];
  if (part == 1) set->searchSplit = begin;
  sp->foundCount = 0;
  for (int p = begin; p < end; ++p) {
    set->pairFound[p] = sp->foundCount;
    set->pairFoundCount[p] = 0;
    if (set->certified[p]) continue;
    int a = set->pairs[p].a, b = set->pairs[p].b, first = set->pairPrevious[p], count = set->pairPreviousCount[p];
    for (int k = 0; k < count; ++k) sp->previous[k] = set->items[first + k].id;
    int n = 0;
    if (set->touching[p]) {
      while ((n = pd_contacts_find(job->model, a, &poses1[a], b, &poses1[b], &poses0[a], &poses0[b], sp->previous, count,
                                   sp->found + sp->foundCount, sp->foundCapacity - sp->foundCount)) >
             sp->foundCapacity - sp->foundCount) {
        sp->foundCapacity = 2 * (sp->foundCount + n);
        sp->found = pd_grow(sp->found, sp->foundCapacity, sizeof *sp->found);
      }
    }
    // a pair in contact that found nothing new with all its contacts tracked is certified for the next steps (a pair
    // apart has only its interference test to skip, itself about as dear as a certificate)
    pairCertificate* cert = &set->certsNext[p];
    if (job->certificates && count > 0 && quiet(set, p, sp->found + sp->foundCount, n, sp->previous)) {
      if (cert->wait > 0) {
        --cert->wait;
      } else {
        cert->cert = pd_contacts_certify(job->model, a, &poses1[a], b, &poses1[b], sp->previous, count);
        cert->contacts = count;
        cert->used = false;
        if (!(cert->cert.margin > 0.0)) back_off(cert);  // none to be had here (flush parallel edges): not every step
      }
    }
    set->pairFoundCount[p] = n;
    sp->foundCount += n;
  }
}

// A vertex leaving a body through face F recedes from F as fast as it sinks into a face f opposite F (the far side of
// a plate: the two rates are equal for parallel faces, within the lateral motion's share for a lens whose faces meet at
// a few degrees); one sinking into f more than this many times as fast as it recedes from F is not leaving through F.
#define SINKING_NOT_LEAVING 2.0

// Face continuity (§4.4.3) through a release by force: a vertex whose contact on face F was released by its dampers
// while still inside the other body, and that the search finds again on another face of that body, keeps F while the
// history keeps its trace (its features still tracked, within the history's gap: contact_history.h). The search takes
// the face the vertex crossed in the step or else the nearest, and a vertex past a thin plate's mid-plane is nearer
// the far face: a sphere's vertex released 2.75 δ_max below a 100:1 blade's face was found again 1.25 δ_max below the
// opposite face, "approaching" it only because it was on its way back out through F, with springs at zero, and was
// pushed on through the blade (soak campaign 48, scene 4069: 11.4 δ_max). Candidate *c (a new contact at y1) then
// becomes the trace's contact at its tracked geometry when it approaches F (c->released), and is no contact when it
// recedes from F onto a face turned away from F, where its contact ended (false: drop it). Dropped on a face beside F
// too, a vertex that slid from F into that face was not held there (soak campaign 62, scene 265: 0.38 -> 6.5 δ_max).
static bool keep_released_face(const pdModel* model, const pdContactSet* set, const double* y1, const pdPose* poses1,
                               candidate* c) {
  const pdContactId* id = &c->geom.id;
  pdContactId released;
  if (!set->history || id->kind != pd_contactVF ||
      !pd_history_vertex_trace(set->history, id->body1, id->feat1, id->body2, id->feat2, &released))
    return true;
  pdContactGeom kept;
  if (!pd_contact_track(model, &released, &poses1[released.body1], &poses1[released.body2], &kept) ||
      !(kept.depth > 0.0))
    return true;
  kept.id = released;
  pdVec3 du = relative_velocity(model, y1, poses1, &released, kept.point);
  // receding from F it is no contact on a face turned away from F (the far side of a plate, which it approaches only
  // by leaving through F); on a face beside F it may have slid in, and is that face's as found
  if (!(pd_v3_dot(du, kept.normal) < 0.0)) {
    if (!(pd_v3_dot(kept.normal, c->geom.normal) < 0.0)) return true;
    // in the wedge of an acute edge of F and f, a vertex sinking into f much faster than it recedes from F moves
    // along F into the body through f (a corner entered at a thin plate's rim edge rising through its bottom face),
    // not out through F: it is f's contact as found
    double sinking = -pd_v3_dot(du, c->geom.normal), receding = pd_v3_dot(du, kept.normal);
    return sinking > SINKING_NOT_LEAVING * receding &&
           faces_meet_at_acute_edge(&model->bodies[released.body2].shape, released.feat2, c->geom.id.feat2);
  }
  c->geom = kept;
  c->approaching = true;
  c->released = true;
  return true;
}

// Interference of the pairs at poses1 (the verdict only, PD_SAT_VERDICT: GJK's certificates, and touching where
// they prove neither, within 1e-7 of the size; cache of the last separating feature or direction per pair, merged
// by the sorted pair order), then the contact search of the touching ones, whose own depth tests find no contact
// where nothing penetrates. Fills candidates. Times the interference
// (a lap of `watch`), not the search after it.
void pd_contact_search(const pdModel* model, pdState* s, const double* y1, int pairCount, const pdPose* poses0,
                       const pdPose* poses1, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  // each pair's contacts in C0 (the list is sorted by the unordered body pair first)
  int listed = 0;
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) < 0) ++listed;
    set->pairPrevious[p] = listed;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) == 0) ++listed;
    set->pairPreviousCount[p] = listed - set->pairPrevious[p];
  }
  // every pair's interference first, timed as a whole (two clock reads per pair were 2 % of a pile's run)
  contactLoop job = {.model = model, .set = set, .poses1 = poses1, .certificates = s->searchCertificates};
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, interference_range, &job);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageInterference]);
  set->candidateCount = 0;
  contactLoop find = {
      .model = model, .set = set, .poses0 = poses0, .poses1 = poses1, .certificates = s->searchCertificates};
  set->searchSplit = pairCount;
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, find_range, &find);
  for (int p = 0; p < pairCount; ++p) {
    s->count.searchesSkipped += set->certified[p];
    if (!set->touching[p]) continue;
    int first = set->pairPrevious[p], previousCount = set->pairPreviousCount[p], n = set->pairFoundCount[p];
    const pdContactGeom* found = set->search[p >= set->searchSplit].found + set->pairFound[p];
    // found[] and C0's contacts of this pair are both sorted by id: merge
    int j = first;
    for (int f = 0; f < n; ++f) {
      const pdContactGeom* g = &found[f];
      while (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) < 0) ++j;
      if (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) == 0) continue;
      candidate c = {.geom = *g, .onset = 1.0, .approaching = false, .onsetAge = 0.0, .inherit = -1, .onsetBound = 0.0};
      int b1 = g->id.body1, b2 = g->id.body2;
      if (!keep_released_face(model, set, y1, poses1, &c)) continue;
      if (c.released) {  // continues a contact released by force: no onset of its own, its springs from the trace
        add_candidate(set, &c);
        continue;
      }
      pdVec3 du = relative_velocity(model, y1, poses1, &g->id, g->point);
      c.approaching = pd_v3_dot(du, g->normal) < 0.0;
      // a hand-over: the contact of C0 that no longer tracks and whose features this one continues carries on
      // in it (springs and all): first face continuity (the vertex of a VF contact of C0, now on another face),
      // then any feature change over a shared vertex (EE → VF at an edge's end, VF → EE along an edge at the
      // vertex, EE → EE turning over at a vertex or along a shared edge)
      c.inherit = handover_predecessor(model, set, first, previousCount, &g->id);
      if (c.inherit >= 0) set->eval[c.inherit].transferred = true;
      if (c.inherit < 0) c.onset = pd_contact_onset(model, &g->id, &poses0[b1], &poses1[b1], &poses0[b2], &poses1[b2]);
      add_candidate(set, &c);
    }
  }
  // C0 contacts whose pair no longer overlaps were not visited: nothing to do, they break on commit
  // if they no longer track or pull; swap in the new cache
  pdPairSatCache* t = set->cache;
  set->cache = set->cacheNext;
  set->cacheNext = t;
  pairCertificate* c = set->certs;
  set->certs = set->certsNext;
  set->certsNext = c;
  set->cacheCount = pairCount;
}
