// polydyn refcheck — the ODE adapter: a compiled pdModel run in ODE 0.16.2 (Debian libode-dev, double).
//
// What is built (shared/reference/reference-engines.md §1, §5):
// - every moving body: a dBody with our mass and full inertia tensor about the centre of mass
//   (dMassSetParameters, cg = 0) and a dCreateConvex geom with our vertices, faces and planes in our body
//   frame, so the ODE body frame is ours (origin at the centre of mass, object axes) and poses need no
//   conversion;
// - every fixed body: a static geom (no dBody) at its pose — a static convex, or a dCreatePlane through
//   one of its faces while that is exact (below, "Planes");
// - per contact: μ = √(μ₁μ₂) as a coefficient (dContactApprox1, never ODE's default force bound), and
//   per variant: native = hard contact (world ERP/CFM) with dContactBounce at the pair's e; matched =
//   dContactSoftERP|SoftCFM from the pair's per-contact k_n, c_n and the step (implicit spring-damper:
//   erp = h k/(h k + c), cfm = 1/(h k + c)), no bounce. ODE has no tangential spring: k_t, c_t are unused.
// - stepping: dWorldStep (Dantzig LCP, exact; faster than QuickStep for few bodies, reference §1.8).
//
// Planes. ODE's convex–convex and convex–box colliders go through libccd's MPR and return one contact per
// pair (a resting cube then carries its weight on one point and drifts); convex–plane returns one contact
// per vertex below the plane, which is the vertex–face contact set of our own model. So a fixed body starts
// as the plane of its face f that looks most nearly up (largest component against gravity, > 0; no plane
// without gravity), and the plane is kept only while it is exact: at every step, before collision, each
// moving body that comes within the slack (PD_ODE_PLANE_SLACK_REL) of the plane must have every vertex
// inside the vertical prism over f and above the depth D to which that prism stays inside the fixed body
// (for a box: its thickness). While that holds the body can touch nothing of the fixed body but f, and the
// plane gives exactly the contacts f would; the first time it fails (also at t = 0), the fixed body
// becomes a static convex for the rest of the run, and the time is written to the settings JSON. The test
// is conservative: a body overhanging the rim of f while it touches f switches it too.
//
// Traps handled (reference §1.6): zero-normal contacts of the libccd path are dropped and counted;
// every array ODE keeps a pointer to (convex planes, points, polygons) lives in the world; the centre of
// mass is at the body origin (dBodySetMass aborts otherwise); dMassCheck runs before dBodySetMass (ODE
// aborts on invalid mass); the friction pyramid is ODE's by default, or aligned with the slip
// (--ode-friction aligned); dInitODE2 runs once per process; every world has its own dWorld, dSpace and
// contact group, so worlds are independent (one world per thread at a time: ODE messages are routed to the
// world being stepped on the calling thread).
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ode/ode.h>
#include <ode/version.h>

#include "pdref/refcheck.h"
#include "pdutil/json.h"

// World constraint parameters of the native variant, stated rather than inherited: ODE's defaults.
#define PD_ODE_WORLD_ERP 0.2
#define PD_ODE_WORLD_CFM 1e-10
// Contacts per dCollide call: convex–plane gives one per vertex below the plane, so at least the largest
// vertex count of any body (a face of a 64-gon prism has 64); libccd pairs give one.
#define PD_ODE_MIN_CONTACTS 16
#define PD_ODE_MAX_CONTACTS 0xffff  // dCollide takes the count in the low 16 bits of its flags
// libccd returns a zero normal (and depth 0) for exactly touching pairs; a unit normal has |n|² = 1, so
// anything below a quarter is that degenerate case, never a real contact (reference §1.5).
#define PD_ODE_ZERO_NORMAL_SQ 0.25
// Aligned friction: fdir1 follows the slip when the tangential relative speed exceeds this; below it the
// contact sticks or nearly does and the direction of the box hardly matters, so ODE's pyramid is kept.
// 1e-6 m/s is far below any speed a stop or a slide measures and far above rounding of speeds of order 1.
#define PD_ODE_ALIGNED_SLIP_MIN 1e-6  // m/s
// Native bounce threshold: an approach slower than this does not bounce. It is at least the speed gravity
// adds in PD_ODE_BOUNCE_VEL_STEPS steps, so a body resting on a face (which falls g·h into the face every
// step) does not bounce on every step, and at least PD_ODE_BOUNCE_VEL_MIN.
#define PD_ODE_BOUNCE_VEL_STEPS 2.0
#define PD_ODE_BOUNCE_VEL_MIN 1e-3  // m/s
// Plane exactness test slack, relative to the scene's length scale: vertex heights are computed from a
// rotation and a translation of order the scene size, so 1e-9 of it is far above their rounding and far
// below any contact depth. It makes the test err on the side of switching to the convex.
#define PD_ODE_PLANE_SLACK_REL 1e-9

typedef struct odeGeom {
  int body;  // model body index
} odeGeom;

// A fixed body represented by a plane through its face `face` while that is exact.
typedef struct odePlane {
  int body;           // model body index
  int face;           // the face the plane extends
  dGeomID geom;       // the dPlane, or NULL once switched to the convex
  pdVec3 n;           // outward unit normal, world
  double d;           // plane n·x = d, m
  double depth;       // D: the prism over the face stays inside the body down to this depth, m
  int edgeCount;      // the face's edges
  pdVec3* sideNormal; // (edgeCount) outward normals of the prism's side planes, world
  double* sideOffset; // (edgeCount) side plane offsets, m
  double switchedAt;  // s: time it became a static convex, or -1
  int switchedBody;   // model index of the moving body that made it switch, or -1
} odePlane;

// The arrays ODE keeps pointers to (dCreateConvex copies nothing), one set per body.
typedef struct odeConvexData {
  dReal* planes;         // 4 per face: unit outward normal, offset ≥ 0
  dReal* points;         // 3 per vertex
  unsigned* polygons;    // per face: vertex count, then the indices, CCW seen from outside
} odeConvexData;

// A contact joint of the last step with the force ODE applied through it (dJointFeedback).
typedef struct odeContactForce {
  dJointFeedback feedback;
  int bodyA, bodyB;  // model indices of the joint's first and second geom
  pdVec3 point, normal;
} odeContactForce;

struct pdRefWorld {
  const pdModel* model;
  pdRefOptions options;
  dWorldID world;
  dSpaceID space;
  dJointGroupID contactGroup;
  int planarBodies;  // bodies held in the x–z plane (hold_in_plane)
  odeGeom* geoms;            // (bodyCount) dGeomGetData of each body's geom points here
  odeConvexData* convex;     // (bodyCount)
  dBodyID* bodies;           // (movingCount)
  dGeomID* fixedConvex;      // (bodyCount) static convex of a fixed body, NULL while it is a plane
  odePlane* planes;          // (planeCount)
  int planeCount;
  dContact* contactBuffer;   // (maxContacts)
  int maxContacts;
  double h;                  // step of the current / last step, s
  long steps;
  int contactCount;          // contact joints of the last step
  odeContactForce* forces;   // (forceCapacity) the first contacts of the last step, their joints' feedback
  int forceCapacity;         // grown after a step that had more contacts: never during one (ODE keeps pointers)
  long zeroNormalDropped;    // libccd zero-normal contacts dropped
  long nonFiniteDropped;     // contacts with a non-finite normal or depth dropped
  long alignedContacts;      // aligned friction: contacts with fdir1 along the slip
  long pyramidFallbacks;     // aligned friction: contacts slower than PD_ODE_ALIGNED_SLIP_MIN (pyramid kept)
  long odeMessages;          // dMessage calls while this world ran (e.g. LCP warnings)
  char firstMessage[256];
  double planeSlack;         // m
};

// ---------------------------------------------------------------- process-wide ODE state

static pthread_once_t odeOnce = PTHREAD_ONCE_INIT;
// The world being created or stepped on this thread: ODE's message handler is process-global.
static _Thread_local pdRefWorld* currentWorld = NULL;

static void on_ode_message(int num, const char* msg, va_list ap) {
  pdRefWorld* w = currentWorld;
  if (!w) {
    fprintf(stderr, "ODE message %d: ", num);
    vfprintf(stderr, msg, ap);
    fputc('\n', stderr);
    return;
  }
  if (w->odeMessages++ == 0) {
    int n = snprintf(w->firstMessage, sizeof w->firstMessage, "%d: ", num);
    if (n > 0 && (size_t)n < sizeof w->firstMessage)
      vsnprintf(w->firstMessage + n, sizeof w->firstMessage - (size_t)n, msg, ap);
  }
}

static void close_ode(void) { dCloseODE(); }

static void init_ode(void) {
  if (!dInitODE2(0)) {
    fputs("polydyn: ODE failed to initialise (dInitODE2)\n", stderr);
    abort();
  }
  dSetMessageHandler(on_ode_message);
  atexit(close_ode);
}

// ---------------------------------------------------------------- geometry helpers

static pdVec3 world_point(pdVec3 x, const pdMat3* r, pdVec3 p) { return pd_v3_add(x, pd_mat3_mulv(r, p)); }

static void fill_convex(const pdPolyhedron* s, odeConvexData* c) {
  int indexCount = 0;
  for (int f = 0; f < s->faceCount; ++f) indexCount += 1 + s->faces[f].count;
  c->planes = malloc(sizeof(dReal) * 4 * (size_t)s->faceCount);
  c->points = malloc(sizeof(dReal) * 3 * (size_t)s->vertexCount);
  c->polygons = malloc(sizeof(unsigned) * (size_t)indexCount);
  if (!c->planes || !c->points || !c->polygons) abort();
  for (int v = 0; v < s->vertexCount; ++v) {
    c->points[3 * v + 0] = s->vertices[v].x;
    c->points[3 * v + 1] = s->vertices[v].y;
    c->points[3 * v + 2] = s->vertices[v].z;
  }
  unsigned* p = c->polygons;
  for (int f = 0; f < s->faceCount; ++f) {
    const pdFace* face = &s->faces[f];
    // ODE needs the geom origin (our centre of mass) strictly inside: true for a valid body
    PD_ASSERT(face->offset > 0.0);
    c->planes[4 * f + 0] = face->normal.x;
    c->planes[4 * f + 1] = face->normal.y;
    c->planes[4 * f + 2] = face->normal.z;
    c->planes[4 * f + 3] = face->offset;
    *p++ = (unsigned)face->count;
    for (int k = 0; k < face->count; ++k) *p++ = (unsigned)s->faceVertices[face->first + k];
  }
}

static dGeomID create_convex(pdRefWorld* w, int body) {
  const pdPolyhedron* s = &w->model->bodies[body].shape;
  const odeConvexData* c = &w->convex[body];
  dGeomID g = dCreateConvex(w->space, c->planes, (unsigned)s->faceCount, c->points, (unsigned)s->vertexCount,
                            c->polygons);
  w->geoms[body] = (odeGeom){body};
  dGeomSetData(g, &w->geoms[body]);
  return g;
}

static dGeomID create_static_convex(pdRefWorld* w, int body) {
  const pdBody* b = &w->model->bodies[body];
  dGeomID g = create_convex(w, body);
  dGeomSetPosition(g, b->x0.x, b->x0.y, b->x0.z);
  const dQuaternion q = {b->q0.w, b->q0.x, b->q0.y, b->q0.z};
  dGeomSetQuaternion(g, q);
  return g;
}

// Depth to which the vertical prism over face f (straight down along -n_f) stays inside the body: the
// smallest, over the face's vertices, distance down to the first other face the line leaves through. The
// prism is the hull of the face and its copy D lower, so it is inside the convex body when those vertices
// are. Faces parallel to the line (the sides of a box) never stop it.
static double prism_depth(const pdPolyhedron* s, int f) {
  const pdFace* top = &s->faces[f];
  pdVec3 down = pd_v3_scale(top->normal, -1.0);
  double depth = INFINITY;
  for (int k = 0; k < top->count; ++k) {
    pdVec3 p = s->vertices[s->faceVertices[top->first + k]];
    for (int g = 0; g < s->faceCount; ++g) {
      double approach = pd_v3_dot(s->faces[g].normal, down);
      if (g == f || approach <= PD_PLANARITY_TOL_REL) continue;
      depth = fmin(depth, (s->faces[g].offset - pd_v3_dot(s->faces[g].normal, p)) / approach);
    }
  }
  return depth;
}

// The face of a fixed body that looks most nearly up (against gravity), or -1 when none looks up or there
// is no gravity.
static int upward_face(const pdModel* model, const pdBody* b) {
  double g = pd_v3_norm(model->settings.gravity);
  if (!(g > 0.0)) return -1;
  pdVec3 up = pd_v3_scale(model->settings.gravity, -1.0 / g);
  pdMat3 r = pd_quat_to_mat3(b->q0);
  int best = -1;
  double bestDot = 0.0;
  for (int f = 0; f < b->shape.faceCount; ++f) {
    double c = pd_v3_dot(pd_mat3_mulv(&r, b->shape.faces[f].normal), up);
    if (c > bestDot) {
      bestDot = c;
      best = f;
    }
  }
  return best;
}

static void plane_setup(odePlane* p, const pdBody* b, int body, int face, double depth) {
  pdMat3 r = pd_quat_to_mat3(b->q0);
  const pdFace* f = &b->shape.faces[face];
  p->body = body;
  p->face = face;
  p->geom = NULL;
  p->n = pd_mat3_mulv(&r, f->normal);
  p->d = pd_v3_dot(p->n, b->x0) + f->offset;
  p->depth = depth;
  p->edgeCount = f->count;
  p->sideNormal = malloc(sizeof *p->sideNormal * (size_t)f->count);
  p->sideOffset = malloc(sizeof *p->sideOffset * (size_t)f->count);
  if (!p->sideNormal || !p->sideOffset) abort();
  for (int k = 0; k < f->count; ++k) {
    pdVec3 a = world_point(b->x0, &r, b->shape.vertices[b->shape.faceVertices[f->first + k]]);
    pdVec3 c = world_point(b->x0, &r, b->shape.vertices[b->shape.faceVertices[f->first + (k + 1) % f->count]]);
    // CCW about n seen from outside: (c - a) × n points out of the face across edge a→c
    pdVec3 s = pd_v3_normalize(pd_v3_cross(pd_v3_sub(c, a), p->n));
    p->sideNormal[k] = s;
    p->sideOffset[k] = pd_v3_dot(s, a);
  }
  p->switchedAt = -1.0;
  p->switchedBody = -1;
}

// Is the plane exact for moving body `body` at pose (x, r)? It is when the body does not reach the plane,
// or when every vertex is inside the prism over the face and above the prism's depth D.
static bool plane_exact_for(const pdRefWorld* w, const odePlane* p, int body, pdVec3 x, const pdMat3* r) {
  const pdBody* b = &w->model->bodies[body];
  double slack = w->planeSlack;
  if (pd_v3_dot(p->n, x) - p->d - b->radius > slack) return true;
  const pdPolyhedron* s = &b->shape;
  double lowest = INFINITY;
  for (int v = 0; v < s->vertexCount; ++v) lowest = fmin(lowest, pd_v3_dot(p->n, world_point(x, r, s->vertices[v])) - p->d);
  if (lowest > slack) return true;
  if (lowest < -p->depth + slack) return false;
  for (int v = 0; v < s->vertexCount; ++v) {
    pdVec3 q = world_point(x, r, s->vertices[v]);
    for (int k = 0; k < p->edgeCount; ++k)
      if (pd_v3_dot(p->sideNormal[k], q) - p->sideOffset[k] > -slack) return false;
  }
  return true;
}

static pdMat3 body_rotation(dBodyID b) {
  const dReal* q = dBodyGetQuaternion(b);
  return pd_quat_to_mat3((pdQuat){q[0], q[1], q[2], q[3]});
}

// Switches to the static convex every plane that is no longer exact for some moving body.
static void check_planes(pdRefWorld* w) {
  const pdModel* model = w->model;
  for (int i = 0; i < w->planeCount; ++i) {
    odePlane* p = &w->planes[i];
    if (!p->geom) continue;
    for (int m = 0; m < model->movingCount; ++m) {
      int body = model->movingBodies[m];
      const dReal* x = dBodyGetPosition(w->bodies[m]);
      pdMat3 r = body_rotation(w->bodies[m]);
      if (plane_exact_for(w, p, body, (pdVec3){x[0], x[1], x[2]}, &r)) continue;
      dGeomDestroy(p->geom);
      p->geom = NULL;
      w->fixedConvex[p->body] = create_static_convex(w, p->body);
      p->switchedAt = (double)w->steps * w->h;
      p->switchedBody = body;
      break;
    }
  }
}

// ---------------------------------------------------------------- contacts

static double bounce_velocity(const pdRefWorld* w) {
  return fmax(PD_ODE_BOUNCE_VEL_MIN, PD_ODE_BOUNCE_VEL_STEPS * pd_v3_norm(w->model->settings.gravity) * w->h);
}

// Sets fdir1 along the slip of body 1 relative to body 2 at the contact point; false when slower than
// PD_ODE_ALIGNED_SLIP_MIN (then ODE's own pyramid frame is kept).
static bool align_friction(dContact* c, dBodyID b1, dBodyID b2) {
  const dReal* p = c->geom.pos;
  dVector3 v1 = {0, 0, 0, 0}, v2 = {0, 0, 0, 0};
  if (b1) dBodyGetPointVel(b1, p[0], p[1], p[2], v1);
  if (b2) dBodyGetPointVel(b2, p[0], p[1], p[2], v2);
  pdVec3 n = {c->geom.normal[0], c->geom.normal[1], c->geom.normal[2]};
  pdVec3 u = {v1[0] - v2[0], v1[1] - v2[1], v1[2] - v2[2]};
  pdVec3 t = pd_v3_muladd(u, -pd_v3_dot(u, n), n);
  double speed = pd_v3_norm(t);
  if (!(speed > PD_ODE_ALIGNED_SLIP_MIN)) return false;
  c->fdir1[0] = t.x / speed;
  c->fdir1[1] = t.y / speed;
  c->fdir1[2] = t.z / speed;
  c->fdir1[3] = 0;
  return true;
}

static void near_callback(void* data, dGeomID g1, dGeomID g2) {
  pdRefWorld* w = data;
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (!b1 && !b2) return;  // two fixed bodies never touch
  const odeGeom* o1 = dGeomGetData(g1);
  const odeGeom* o2 = dGeomGetData(g2);
  int n = dCollide(g1, g2, w->maxContacts, &w->contactBuffer[0].geom, sizeof(dContact));
  if (n <= 0) return;
  pdPairContact pair = pd_model_pair_contact(w->model, o1->body, o2->body);
  double h = w->h;
  for (int i = 0; i < n; ++i) {
    dContact* c = &w->contactBuffer[i];
    const dReal* nn = c->geom.normal;
    double n2 = nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2];
    if (!isfinite(n2) || !isfinite(c->geom.depth)) {
      ++w->nonFiniteDropped;
      continue;
    }
    if (n2 < PD_ODE_ZERO_NORMAL_SQ) {
      ++w->zeroNormalDropped;
      continue;
    }
    dSurfaceParameters* s = &c->surface;
    memset(s, 0, sizeof *s);
    s->mode = dContactApprox1;
    s->mu = pair.mu;
    if (w->options.variant == pd_refMatched) {
      s->mode |= dContactSoftERP | dContactSoftCFM;
      s->soft_erp = h * pair.kn / (h * pair.kn + pair.cn);
      s->soft_cfm = 1.0 / (h * pair.kn + pair.cn);
    } else {
      s->mode |= dContactBounce;
      s->bounce = pair.restitution;
      s->bounce_vel = bounce_velocity(w);
    }
    if (w->options.odeFriction == pd_odeFrictionAligned && pair.mu > 0.0) {
      if (align_friction(c, b1, b2)) {
        s->mode |= dContactFDir1;
        ++w->alignedContacts;
      } else {
        ++w->pyramidFallbacks;
      }
    }
    dJointID j = dJointCreateContact(w->world, w->contactGroup, c);
    dJointAttach(j, b1, b2);
    if (w->contactCount < w->forceCapacity) {
      odeContactForce* f = &w->forces[w->contactCount];
      dJointSetFeedback(j, &f->feedback);
      f->bodyA = o1->body;
      f->bodyB = o2->body;
      f->point = (pdVec3){c->geom.pos[0], c->geom.pos[1], c->geom.pos[2]};
      f->normal = (pdVec3){nn[0], nn[1], nn[2]};
    }
    ++w->contactCount;
  }
}

// ---------------------------------------------------------------- adapter

static void ode_destroy(pdRefWorld* w) {
  if (!w) return;
  pdRefWorld* previous = currentWorld;
  currentWorld = w;
  if (w->contactGroup) dJointGroupDestroy(w->contactGroup);
  if (w->space) dSpaceDestroy(w->space);  // destroys the geoms it holds
  if (w->world) dWorldDestroy(w->world);  // destroys the bodies
  currentWorld = previous;
  if (w->convex)
    for (int i = 0; i < w->model->bodyCount; ++i) {
      free(w->convex[i].planes);
      free(w->convex[i].points);
      free(w->convex[i].polygons);
    }
  for (int i = 0; i < w->planeCount; ++i) {
    free(w->planes[i].sideNormal);
    free(w->planes[i].sideOffset);
  }
  free(w->planes);
  free(w->convex);
  free(w->geoms);
  free(w->bodies);
  free(w->fixedConvex);
  free(w->contactBuffer);
  free(w->forces);
  free(w);
}

// A planar body (model.h): ODE's plane-2D joint holds the x–y plane (z = 0) only, and ours is the x–z plane
// under z-up gravity, so two motors do it instead, each an unbounded velocity constraint against the world
// frame with zero target and zero CFM: a linear motor along world y and an angular motor (user mode) about
// world x and z. Velocity-level, so the pose leaves the plane only by round-off.
static void hold_in_plane(pdRefWorld* w, dBodyID body) {
  dJointID lin = dJointCreateLMotor(w->world, 0);
  dJointAttach(lin, body, 0);
  dJointSetLMotorNumAxes(lin, 1);
  dJointSetLMotorAxis(lin, 0, 0, 0.0, 1.0, 0.0);  // rel 0: the world frame
  dJointSetLMotorParam(lin, dParamVel, 0.0);
  dJointSetLMotorParam(lin, dParamFMax, dInfinity);
  dJointSetLMotorParam(lin, dParamCFM, 0.0);
  dJointID ang = dJointCreateAMotor(w->world, 0);
  dJointAttach(ang, body, 0);
  dJointSetAMotorMode(ang, dAMotorUser);
  dJointSetAMotorNumAxes(ang, 2);
  dJointSetAMotorAxis(ang, 0, 0, 1.0, 0.0, 0.0);
  dJointSetAMotorAxis(ang, 1, 0, 0.0, 0.0, 1.0);
  static const int vel[2] = {dParamVel, dParamVel2}, fmax[2] = {dParamFMax, dParamFMax2}, cfm[2] = {dParamCFM, dParamCFM2};
  for (int k = 0; k < 2; ++k) {
    dJointSetAMotorParam(ang, vel[k], 0.0);
    dJointSetAMotorParam(ang, fmax[k], dInfinity);
    dJointSetAMotorParam(ang, cfm[k], 0.0);
  }
  ++w->planarBodies;
}

static pdRefWorld* ode_create(const pdModel* model, const pdRefOptions* options, pdError* err) {
  PD_ASSERT(model && options && options->step > 0.0);
  pthread_once(&odeOnce, init_ode);
  if (!dAllocateODEDataForThread(dAllocateMaskAll)) abort();  // fails only when out of memory
  size_t n = (size_t)model->bodyCount;
  pdRefWorld* w = calloc(1, sizeof *w);
  if (!w) abort();
  w->model = model;
  w->options = *options;
  w->h = options->step;
  w->planeSlack = PD_ODE_PLANE_SLACK_REL * model->lengthScale;
  w->geoms = calloc(n, sizeof *w->geoms);
  w->convex = calloc(n, sizeof *w->convex);
  w->bodies = calloc((size_t)model->movingCount + 1, sizeof *w->bodies);
  w->fixedConvex = calloc(n, sizeof *w->fixedConvex);
  w->planes = calloc(n, sizeof *w->planes);
  if (!w->geoms || !w->convex || !w->bodies || !w->fixedConvex || !w->planes) abort();
  pdRefWorld* previous = currentWorld;
  currentWorld = w;

  w->world = dWorldCreate();
  pdVec3 g = model->settings.gravity;
  dWorldSetGravity(w->world, g.x, g.y, g.z);
  dWorldSetERP(w->world, PD_ODE_WORLD_ERP);
  dWorldSetCFM(w->world, PD_ODE_WORLD_CFM);
  dWorldSetContactSurfaceLayer(w->world, 0.0);
  dWorldSetContactMaxCorrectingVel(w->world, dInfinity);
  dWorldSetAutoDisableFlag(w->world, 0);
  dWorldSetDamping(w->world, 0.0, 0.0);
  // dSimpleSpace: every pair's boxes tested, in insertion order. Debian's dHashSpace (default levels, and
  // levels -10..10) never reported a 0.05 m cube overlapping the top of a 0.5 m one (mass_ratio.scene: the
  // pebble fell into the block unseen); the simple space did.
  w->space = dSimpleSpaceCreate(0);
  w->contactGroup = dJointGroupCreate(0);

  int maxVertices = 0;
  for (int i = 0; i < model->bodyCount; ++i) {
    const pdBody* b = &model->bodies[i];
    if (b->shape.vertexCount > maxVertices) maxVertices = b->shape.vertexCount;
    fill_convex(&b->shape, &w->convex[i]);
  }
  w->maxContacts = maxVertices < PD_ODE_MIN_CONTACTS ? PD_ODE_MIN_CONTACTS : maxVertices;
  if (w->maxContacts > PD_ODE_MAX_CONTACTS) w->maxContacts = PD_ODE_MAX_CONTACTS;
  w->contactBuffer = calloc((size_t)w->maxContacts, sizeof *w->contactBuffer);
  w->forceCapacity = 8 * model->bodyCount;  // a box resting on a face: 4 to 8 contacts; grown after a step with more
  w->forces = calloc((size_t)w->forceCapacity, sizeof *w->forces);
  if (!w->contactBuffer || !w->forces) abort();

  for (int m = 0; m < model->movingCount; ++m) {
    int i = model->movingBodies[m];
    const pdBody* b = &model->bodies[i];
    const pdMat3* I = &b->inertia;
    dMass mass;
    dMassSetZero(&mass);
    dMassSetParameters(&mass, b->mass, 0, 0, 0, I->m[0][0], I->m[1][1], I->m[2][2], I->m[0][1], I->m[0][2], I->m[1][2]);
    if (!dMassCheck(&mass)) {  // dBodySetMass would abort the process
      pd_error_set(err, model->scenePath, b->where.line, b->where.col,
                   "object '%s': ODE refuses its mass properties (dMassCheck: %s)", b->name,
                   w->odeMessages ? w->firstMessage : "invalid mass or inertia");
      currentWorld = previous;
      ode_destroy(w);
      return NULL;
    }
    dBodyID body = dBodyCreate(w->world);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, b->x0.x, b->x0.y, b->x0.z);
    const dQuaternion q = {b->q0.w, b->q0.x, b->q0.y, b->q0.z};
    dBodySetQuaternion(body, q);
    dBodySetLinearVel(body, b->v0.x, b->v0.y, b->v0.z);
    dBodySetAngularVel(body, b->w0.x, b->w0.y, b->w0.z);
    dBodySetGyroscopicMode(body, 1);
    dBodySetFiniteRotationMode(body, 0);
    dGeomSetBody(create_convex(w, i), body);
    if (b->planar) hold_in_plane(w, body);
    w->bodies[m] = body;
  }

  // fixed bodies: a plane through the upward face when the prism under it has depth and the plane is
  // exact for every moving body at t = 0; otherwise a static convex
  for (int i = 0; i < model->bodyCount; ++i) {
    const pdBody* b = &model->bodies[i];
    if (!b->fixed) continue;
    int face = upward_face(model, b);
    double depth = face >= 0 ? prism_depth(&b->shape, face) : 0.0;
    if (face >= 0 && depth > w->planeSlack) {
      odePlane* p = &w->planes[w->planeCount];
      plane_setup(p, b, i, face, depth);
      bool exact = true;
      for (int m = 0; m < model->movingCount && exact; ++m) {
        const pdBody* mb = &model->bodies[model->movingBodies[m]];
        pdMat3 r = pd_quat_to_mat3(mb->q0);
        exact = plane_exact_for(w, p, model->movingBodies[m], mb->x0, &r);
      }
      if (exact) {
        p->geom = dCreatePlane(w->space, p->n.x, p->n.y, p->n.z, p->d);
        w->geoms[i] = (odeGeom){i};
        dGeomSetData(p->geom, &w->geoms[i]);
        ++w->planeCount;
        continue;
      }
      free(p->sideNormal);
      free(p->sideOffset);
      memset(p, 0, sizeof *p);
    }
    w->fixedConvex[i] = create_static_convex(w, i);
  }
  currentWorld = previous;
  return w;
}

// The scene's applied forces for the step from t = steps·h: F at mid-step (refcheck.h), at the body-frame
// point (ODE's body frame is ours, origin at the centre of mass). ODE clears the accumulators after each step.
static void add_applied_forces(pdRefWorld* w, double h) {
  double tMid = ((double)w->steps + 0.5) * h;  // s
  for (int m = 0; m < w->model->movingCount; ++m) {
    const pdBody* body = &w->model->bodies[w->model->movingBodies[m]];
    if (!body->hasForce) continue;
    pdVec3 f = pd_body_applied_force(body, tMid), p = body->forcePoint;
    dBodyAddForceAtRelPos(w->bodies[m], f.x, f.y, f.z, p.x, p.y, p.z);
  }
}

static bool ode_step(pdRefWorld* w, double h) {
  PD_ASSERT(w && h > 0.0);
  pdRefWorld* previous = currentWorld;
  currentWorld = w;
  w->h = h;
  w->contactCount = 0;
  check_planes(w);
  dSpaceCollide(w->space, w, near_callback);
  add_applied_forces(w, h);
  int ok = dWorldStep(w->world, h);
  dJointGroupEmpty(w->contactGroup);
  if (w->contactCount > w->forceCapacity) {  // room for the next step's: the feedback must not move during one
    w->forceCapacity = 2 * w->contactCount;
    w->forces = realloc(w->forces, (size_t)w->forceCapacity * sizeof *w->forces);
    if (!w->forces) abort();
  }
  ++w->steps;
  currentWorld = previous;
  if (!ok) return false;
  for (int m = 0; m < w->model->movingCount; ++m) {
    dBodyID b = w->bodies[m];
    const dReal* a[4] = {dBodyGetPosition(b), dBodyGetLinearVel(b), dBodyGetAngularVel(b), dBodyGetQuaternion(b)};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < (k == 3 ? 4 : 3); ++j)
        if (!isfinite(a[k][j])) return false;
  }
  return true;
}

static pdBodyState ode_body(const pdRefWorld* w, int movingIndex) {
  PD_ASSERT(w && movingIndex >= 0 && movingIndex < w->model->movingCount);
  dBodyID b = w->bodies[movingIndex];
  const dReal* x = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  const dReal* v = dBodyGetLinearVel(b);
  const dReal* om = dBodyGetAngularVel(b);
  return (pdBodyState){.x = {x[0], x[1], x[2]},
                       .q = {q[0], q[1], q[2], q[3]},
                       .v = {v[0], v[1], v[2]},
                       .w = {om[0], om[1], om[2]}};
}

static int ode_contact_count(const pdRefWorld* w) { return w->contactCount; }

// The last step's contacts with their forces; those past the feedback's room (a step with more contacts than any
// before it) are not reported.
static int ode_contacts(const pdRefWorld* w, pdContactReport* out, int capacity) {
  int count = w->contactCount < w->forceCapacity ? w->contactCount : w->forceCapacity;
  for (int i = 0; i < count && i < capacity; ++i) {
    const odeContactForce* f = &w->forces[i];
    // the force on the first geom's body; on a fixed first geom, minus the force on the second
    bool firstMoves = !w->model->bodies[f->bodyA].fixed;
    const dReal* F = firstMoves ? f->feedback.f1 : f->feedback.f2;
    pdVec3 force = {F[0], F[1], F[2]};
    if (!firstMoves) force = pd_v3_scale(force, -1.0);
    // the normal from B into A: the way the contact pushes A
    pdVec3 n = pd_v3_dot(force, f->normal) >= 0.0 ? f->normal : pd_v3_scale(f->normal, -1.0);
    double fn = pd_v3_dot(force, n);
    out[i] = (pdContactReport){.bodyA = f->bodyA, .bodyB = f->bodyB, .featureA = -1, .featureB = -1, .point = f->point,
                               .normal = n, .fn = fn, .ft = pd_v3_sub(force, pd_v3_scale(n, fn))};
  }
  return count;
}

// ---------------------------------------------------------------- settings JSON

static bool same_pair(const pdPairContact* a, const pdPairContact* b) {
  return a->mu == b->mu && a->kn == b->kn && a->cn == b->cn && a->kt == b->kt && a->ct == b->ct &&
         a->restitution == b->restitution && strcmp(a->restitutionSource, b->restitutionSource) == 0;
}

enum { PAIR_CLASSES_LISTED = 64 };

// Every pair that can touch (not both fixed), grouped by identical constants: μ and e as ODE uses them,
// and for matched the soft ERP/CFM at the step used.
static void write_pairs(const pdRefWorld* w, FILE* out) {
  const pdModel* model = w->model;
  pdPairContact classes[PAIR_CLASSES_LISTED];
  int firstA[PAIR_CLASSES_LISTED], firstB[PAIR_CLASSES_LISTED];
  long count[PAIR_CLASSES_LISTED];
  int classCount = 0;
  long unlisted = 0;
  for (int a = 0; a < model->bodyCount; ++a)
    for (int b = a + 1; b < model->bodyCount; ++b) {
      if (model->bodies[a].fixed && model->bodies[b].fixed) continue;
      pdPairContact p = pd_model_pair_contact(model, a, b);
      int k = 0;
      while (k < classCount && !same_pair(&classes[k], &p)) ++k;
      if (k == classCount) {
        if (classCount == PAIR_CLASSES_LISTED) {
          ++unlisted;
          continue;
        }
        classes[k] = p;
        firstA[k] = a;
        firstB[k] = b;
        count[k] = 0;
        ++classCount;
      }
      ++count[k];
    }
  fputs("\"pairs\": [", out);
  for (int k = 0; k < classCount; ++k) {
    const pdPairContact* p = &classes[k];
    fputs(k ? ", {\"example\": [" : "{\"example\": [", out);
    pdu_json_string(out, model->bodies[firstA[k]].name);
    fputs(", ", out);
    pdu_json_string(out, model->bodies[firstB[k]].name);
    fprintf(out, "], \"pair_count\": %ld, \"mu\": %.17g, \"restitution\": %.17g, \"restitution_source\": ", count[k],
            p->mu, p->restitution);
    pdu_json_string(out, p->restitutionSource);
    fprintf(out, ", \"kn\": %.17g, \"cn\": %.17g", p->kn, p->cn);
    if (w->options.variant == pd_refMatched)
      fprintf(out, ", \"soft_erp\": %.17g, \"soft_cfm\": %.17g", w->h * p->kn / (w->h * p->kn + p->cn),
              1.0 / (w->h * p->kn + p->cn));
    else
      fprintf(out, ", \"bounce\": %.17g", p->restitution);
    fputc('}', out);
  }
  fprintf(out, "], \"pair_classes_not_listed\": %ld", unlisted);
}

static void write_fixed_bodies(const pdRefWorld* w, FILE* out) {
  const pdModel* model = w->model;
  fputs("\"fixed_bodies\": [", out);
  bool first = true;
  for (int i = 0; i < model->bodyCount; ++i) {
    if (!model->bodies[i].fixed) continue;
    fputs(first ? "{\"body\": " : ", {\"body\": ", out);
    first = false;
    pdu_json_string(out, model->bodies[i].name);
    const odePlane* p = NULL;
    for (int k = 0; k < w->planeCount; ++k)
      if (w->planes[k].body == i) p = &w->planes[k];
    if (!p) {
      fputs(", \"geom\": \"static convex (dCreateConvex)\"}", out);
      continue;
    }
    fprintf(out,
            ", \"geom\": \"%s\", \"plane_face\": %d, \"plane\": [%.17g, %.17g, %.17g, %.17g], \"prism_depth\": %.17g",
            p->geom ? "plane (dCreatePlane), exact for the whole run"
                    : "plane (dCreatePlane) until it stopped being exact, then static convex (dCreateConvex)",
            p->face, p->n.x, p->n.y, p->n.z, p->d, p->depth);
    if (p->geom) {
      fputs(", \"switched_to_convex_at\": null}", out);
    } else {
      fprintf(out, ", \"switched_to_convex_at\": %.17g, \"switched_by\": ", p->switchedAt);
      pdu_json_string(out, model->bodies[p->switchedBody].name);
      fputc('}', out);
    }
  }
  fputc(']', out);
}

static void ode_settings_json(const pdRefWorld* w, FILE* out) {
  bool matched = w->options.variant == pd_refMatched;
  bool aligned = w->options.odeFriction == pd_odeFrictionAligned;
  fputs("{\"library\": \"ODE " dODE_VERSION " (Debian libode-dev, double)\", \"configuration\": ", out);
  pdu_json_string(out, dGetConfiguration());
  fputs(", \"step_method\": \"dWorldStep (Dantzig LCP, exact)\"", out);
  fprintf(out, ", \"world_erp\": %.17g, \"world_cfm\": %.17g, \"contact_surface_layer\": 0, "
               "\"contact_max_correcting_vel\": \"infinity\", \"damping\": 0, \"auto_disable\": false, "
               "\"gyroscopic\": true, \"space\": \"dSimpleSpace (all pairs)\"",
          PD_ODE_WORLD_ERP, PD_ODE_WORLD_CFM);
  fprintf(out, ", \"normal_contact\": \"%s\"",
          matched ? "soft: dContactSoftERP|dContactSoftCFM per pair, erp = h kn/(h kn + cn), cfm = 1/(h kn + cn), "
                    "no bounce (restitution from the damping alone)"
                  : "hard: world ERP and CFM, dContactBounce with bounce = the pair's e above bounce_vel");
  if (!matched)
    fprintf(out, ", \"bounce_vel\": %.17g, \"bounce_vel_rule\": \"max(%g m/s, %g |g| h)\"", bounce_velocity(w),
            PD_ODE_BOUNCE_VEL_MIN, PD_ODE_BOUNCE_VEL_STEPS);
  fputs(", \"tangential_contact\": \"no tangential spring or damper in ODE: the model's kt and ct are not used; "
        "friction is a velocity-level Coulomb bound\"",
        out);
  fprintf(out, ", \"unused_model_parameters\": \"%s\", \"unused_scene_settings\": \"tol, dt, dtmin, dtmax (the soft "
               "engine's step control: ODE takes fixed steps of step_used)\"",
          matched ? "kt, ct (no tangential spring); the requested restitution (e comes from cn and the step)"
                  : "kn, cn, kt, ct (hard contact: ERP/CFM of the world)");
  fprintf(out, ", \"friction\": {\"mode\": \"%s\", \"approximation\": \"dContactApprox1: mu is a coefficient "
               "(bound = mu x normal force per friction row), never ODE's default force bound\", "
               "\"mu_rule\": \"sqrt(mu1 mu2)\", \"frame\": \"%s\"",
          aligned ? "aligned" : "pyramid",
          aligned ? "dContactFDir1 with fdir1 = unit tangential slip velocity when faster than "
                    "aligned_slip_min, else ODE's dPlaneSpace pyramid"
                  : "ODE's dPlaneSpace pyramid: a box of half-width mu N per row, sqrt(2) mu along its diagonal");
  if (aligned)
    fprintf(out, ", \"aligned_slip_min\": %.17g, \"aligned_contacts\": %ld, \"pyramid_fallback_contacts\": %ld",
            PD_ODE_ALIGNED_SLIP_MIN, w->alignedContacts, w->pyramidFallbacks);
  fputc('}', out);
  if (pd_model_has_applied_force(w->model))
    fputs(", \"applied_force_call\": \"dBodyAddForceAtRelPos (world force, body-frame point) before dWorldStep\"", out);
  if (w->planarBodies)
    fprintf(out, ", \"planar_bodies\": %d, \"planar_constraint\": \"dJointCreateLMotor along world y and "
                 "dJointCreateAMotor (user mode) about world x and z: velocity 0, unbounded force, CFM 0 (the "
                 "plane-2D joint holds the x-y plane only)\"", w->planarBodies);
  fprintf(out, ", \"max_contacts_per_collide\": %d", w->maxContacts);
  fputs(", \"colliders\": {\"convex-convex\": \"dCollideConvexConvexCCD (libccd MPR): 1 contact per pair\", "
        "\"convex-plane\": \"dCollideConvexPlane (native): 1 contact per vertex below the plane\"}, ",
        out);
  write_fixed_bodies(w, out);
  fputs(", ", out);
  write_pairs(w, out);
  fprintf(out, ", \"zero_normal_contacts_dropped\": %ld, \"nonfinite_contacts_dropped\": %ld, \"ode_messages\": %ld",
          w->zeroNormalDropped, w->nonFiniteDropped, w->odeMessages);
  if (w->odeMessages) {
    fputs(", \"first_ode_message\": ", out);
    pdu_json_string(out, w->firstMessage);
  }
  fputc('}', out);
}

const pdRefAdapter pd_ode_adapter = {
    .name = "ode",
    .version = dODE_VERSION,
    .create = ode_create,
    .step = ode_step,
    .body = ode_body,
    .contact_count = ode_contact_count,
    .contacts = ode_contacts,
    .settings_json = ode_settings_json,
    .destroy = ode_destroy,
};
