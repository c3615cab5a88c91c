// polydyn — the compiled model: read-only after pd_model_compile.
//
// Frames
// - Each body's frame has its origin at the centre of mass and the axes of the object's own frame
//   (the primitive's axes as the scene file describes them, before `loc` rotates them). It is not
//   the principal frame: the inertia tensor is kept in full, the principal moments and axes beside it.
// - A body's pose maps that frame to the world: x_world = x + R(q) · x_body.
#pragma once

#include <stdbool.h>

#include "polydyn/error.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

// Material of a body: as requested by the scene, and as finally used.
typedef struct pdMaterial {
  double mu;           // base friction coefficient (pair value: √(μ₁μ₂))
  double kn, kt;       // spring constants, N/m (0 until the contact model derives them)
  double cn, ct;       // damper constants, N·s/m
  double restitution;  // requested e, or -1 when not requested
} pdMaterial;

typedef struct pdBody {
  const char* name;       // owned by the model
  const char* color;      // owned by the model
  pdPrimitiveKind kind;
  bool fixed;             // immovable: carries no state
  int stateIndex;         // index among moving bodies (-1 for fixed bodies)
  pdPolyhedron shape;     // body frame (origin at the centre of mass, object axes)
  pdVec3 geometricCentre; // the primitive's own origin, in the body frame, m
  double density;         // kg/m³
  double volume;          // m³
  double mass;            // kg
  double invMass;         // 1/kg (0 for fixed bodies)
  pdMat3 inertia;         // about the centre of mass, body axes, kg·m²
  pdMat3 invInertia;      // its inverse (zero for fixed bodies)
  double principal[3];    // principal moments, ascending, kg·m²
  pdMat3 principalAxes;   // columns: principal axes in body axes
  double size;            // average dimension: mean of the body-frame bounding-box extents, m
  pdVec3 halfExtents;     // body-frame bounding-box half extents about the centre of mass, m (max |coord|)
  double radius;          // largest vertex distance from the centre of mass, m
  pdVec3 x0;              // initial centre of mass, world, m
  pdQuat q0;              // initial orientation (body → world)
  pdVec3 v0;              // initial linear velocity, world, m/s
  pdVec3 w0;              // initial angular velocity, world, rad/s
  pdMaterial requested;   // what the scene said (defaults filled in)
  pdMaterial used;        // what the engine uses
  pdSourceLoc where;      // the object command in the scene file
} pdBody;

typedef struct pdSettings {
  pdVec3 gravity;        // m/s²
  double tend;           // s
  double tol;            // integration tolerance (weighted max-norm of the local error)
  double dt, dtmin, dtmax;  // s
  double sampleRate;     // output samples per second
  double vmax;           // m/s: characteristic speed (requested, or estimated: see velocityScaleSource)
  bool vmaxEstimated;    // true when vmax was estimated from the scene
  double deflection;     // δ_max as a fraction of a body's average dimension
} pdSettings;

typedef struct pdModel {
  char* scenePath;
  pdSettings settings;
  int bodyCount;         // all bodies, scene order
  pdBody* bodies;        // (bodyCount)
  int movingCount;       // bodies that carry state
  int* movingBodies;     // (movingCount) body index of each moving body, scene order
  double lengthScale;    // m: the largest body size, used where a scene-wide length is needed
} pdModel;

// Compiles a parsed scene into a model: builds and validates every polyhedron, computes exact mass
// properties, shifts each body's frame to its centre of mass, sets initial states and settings.
// Returns NULL and fills err (at the object's line) on a degenerate polyhedron or an empty scene.
pdModel* pd_model_compile(const pdScene* scene, pdError* err);

void pd_model_free(pdModel* model);

// Total mechanical energy contributions of one moving body in a given state (J).
double pd_body_kinetic_energy(const pdBody* body, pdVec3 v, pdVec3 w, pdQuat q);
