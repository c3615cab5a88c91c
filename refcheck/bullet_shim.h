// polydyn refcheck — a small C interface to Bullet (Debian's libbullet-dev, the float64 build), used only by
// refcheck/bullet_adapter.c. The implementation (bullet_shim.cpp) is the only C++ in polydyn.
//
// Conventions: SI units; quaternions (w, x, y, z) map the body's frame to the world; velocities and angular
// velocities in the world frame. A body's frame here is Bullet's: origin at the centre of mass, axes along
// the principal axes of inertia (Bullet takes a diagonal inertia only), so the caller passes hull vertices
// already expressed in that frame.
//
// Contact material is never combined by Bullet's rules (product of frictions and of restitutions, series
// stiffness, summed damping): every contact point Bullet adds or refreshes asks the caller's material
// function for its pair's values (gContactAddedCallback with CF_CUSTOM_MATERIAL_CALLBACK on every body).
#pragma once

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct btsWorld btsWorld;

// Every solver setting the adapter chooses (the rest are Bullet's defaults, listed by the adapter).
typedef struct btsSolverSettings {
  int iterations;                           // sequential-impulse (PGS) iterations per step
  bool splitImpulse;                        // penetration recovery by a separate position impulse
  double splitImpulsePenetrationThreshold;  // m: penetrations deeper than this are split (0: all)
  double erp2;                              // error reduction of contact penetration per step
  double restitutionVelocityThreshold;      // m/s: no restitution below this approach speed
  double warmstartingFactor;                // fraction of the last step's impulse to start from
  double contactProcessingThreshold;        // m: manifold points farther apart than this are not solved
  bool satConvex;                           // hull–hull normal by the separating-axis test, not GJK/EPA
} btsSolverSettings;

// Material of one contact point between bodies a and b (the caller's body ids).
typedef struct btsContactMaterial {
  double friction;     // Coulomb μ
  double restitution;  // Newton restitution (used above the velocity threshold); 0 for soft contact
  bool soft;           // true: the contact is a spring-damper (stiffness, damping) instead of rigid
  double stiffness;    // N/m per contact point (soft only)
  double damping;      // N·s/m per contact point (soft only)
} btsContactMaterial;

// What Bullet's solver and collision detection use, read back from the world (for the summary).
typedef struct btsSolverInfo {
  btsSolverSettings settings;        // as set
  double splitImpulseTurnErp;        // error reduction of the split impulse's rotation
  double sor;                        // successive over-relaxation factor
  double globalCfm;                  // constraint force mixing of rigid contacts
  double linearSlop;                 // m, penetration allowed before correction
  int solverMode;                    // btSolverMode bits
  int frictionDirections;            // friction rows per contact point (1: along the slip velocity)
  double contactBreakingThreshold;   // gContactBreakingThreshold, scaled by each shape's angular motion disc
} btsSolverInfo;

typedef void btsMaterialFcn(void* user, int bodyA, int bodyB, btsContactMaterial* out);

// A world with gravity (m/s²) and the solver settings. `material` is called for every contact point
// Bullet adds or refreshes, from inside bts_step; `user` is passed back to it.
btsWorld* bts_world_create(const double gravity[3], const btsSolverSettings* settings, btsMaterialFcn* material,
                           void* user);

// A convex polyhedron in a body's (principal) frame, m. Its faces are given, not recomputed: Bullet's own
// initializePolyhedralFeatures rebuilds them through btConvexHullComputer, which moves vertices that are not
// on a coarse grid by up to ~1.5e-4 of the body's size (measured: 1.5e-5 m on a 0.2 m cube turned 10° in its
// frame), and the contact clipping then works on the moved vertices and tilted planes.
typedef struct btsHull {
  int vertexCount;
  const double* vertices;     // (3 vertexCount) xyz
  int faceCount;
  const int* faceSizes;       // (faceCount) vertices of each face
  const int* faceVertices;    // (sum of faceSizes) vertex indices, counter-clockwise seen from outside
  const double* facePlanes;   // (4 faceCount) unit outward normal n and offset d: n · x = d on the face
} btsHull;

// Adds `hull` (copied) as a body with caller id `id`; mass 0 makes it fixed (static). `inertia` are the
// principal moments, kg·m². Bodies are numbered in the order added (0, 1, …) for bts_body_state.
void bts_add_hull(btsWorld* world, int id, const btsHull* hull, double mass, const double inertia[3],
                  const double position[3], const double quaternion[4], const double velocity[3],
                  const double angularVelocity[3]);

// Holds the body added as number `index` in the world x–z plane: linear factor (1, 0, 1), angular factor
// (0, 1, 0) (btRigidBody::setLinearFactor, setAngularFactor: world-frame masks on its velocity changes).
void bts_hold_in_xz_plane(btsWorld* world, int index);

void bts_solver_info(const btsWorld* world, btsSolverInfo* out);

// Adds a force (N, world) at `relPos` (m, world-oriented, from the centre of mass) to the body added as number
// `index`, for the next step only (btRigidBody::applyForce; stepSimulation clears it).
void bts_apply_force(btsWorld* world, int index, const double force[3], const double relPos[3]);

// One step of exactly h seconds (stepSimulation(h, 0)).
void bts_step(btsWorld* world, double h);

// Pose and velocity of the body added as number `index`.
void bts_body_state(const btsWorld* world, int index, double position[3], double quaternion[4], double velocity[3],
                    double angularVelocity[3]);

// Contact points the solver used in the last step (distance within the processing threshold).
int bts_contact_count(const btsWorld* world);

// One of them with the impulses the solver applied through it in the last step of h seconds, as a force.
typedef struct btsContact {
  int a, b;            // the caller's body ids (bts_add_hull's id) of the manifold's first and second body
  double point[3];     // m, world: midway between the two bodies' witness points
  double normal[3];    // unit, world, from b into a
  double fn;           // N, normal force on a
  double ft[3];        // N, friction force on a (both lateral directions)
} btsContact;

// Those contact points, the first min(count, capacity) in out; returns their count.
int bts_contacts(const btsWorld* world, double h, btsContact* out, int capacity);

void bts_world_destroy(btsWorld* world);

// Bullet's version as its headers give it (BT_BULLET_VERSION, e.g. "324") and the precision built against
// ("float64"; linking the other precision's libraries fails, so this is also the library's).
extern const char bts_version_string[];

#ifdef __cplusplus
}
#endif
