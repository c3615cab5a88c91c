// polydyn — the compiled model: read-only after pd_model_compile.
//
// Frames
// - Each body's frame has its origin at the centre of mass and the axes of the object's own frame
//   (the primitive's axes as the scene file describes them, before `loc` rotates them). It is not
//   the principal frame: the inertia tensor is kept in full, the principal moments and axes beside it.
// - A body's pose maps that frame to the world: x_world = x + R(q) · x_body.
#pragma once

#include <stdbool.h>

#include "polydyn/api.h"
#include "polydyn/error.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

PD_EXTERN_C_BEGIN

// The smallest restitution a scene may request (pd_model_compile refuses less, at the object's line).
// Below e⁻² ≈ 0.135 the contact's normal damper is overdamped, which the model reproduces exactly; e = 0
// would need an infinite damper, and below 0.01 (damping ratio 4.8) the damper's fast mode would force
// integration steps about ten times shorter than the spring's.
#define PD_RESTITUTION_MIN 0.01

// Material of a body: as requested by the scene, and as finally used (docs/contact-model.md). In `requested`, a
// value the scene did not set is -1 (mu always has a value: its default).
// In `used`, restitution is the requested e or the default (0.5); kn, kt, cn, ct are the values the scene
// gave, or -1 where the contact model derives them for each pair of bodies (pd_model_pair_contact): springs
// and dampers belong to a pair, not to one body.
typedef struct pdMaterial {
  double mu;           // base friction coefficient (pair value: √(μ₁μ₂))
  double kn, kt;       // spring constants, N/m
  double cn, ct;       // damper constants, N·s/m
  double restitution;  // e (pair value: √(e₁e₂)); in `requested`, -1 when not requested
} pdMaterial;

typedef struct pdBody {
  const char* name;       // owned by the model
  const char* color;      // owned by the model
  pdPrimitiveKind kind;
  bool fixed;             // immovable: carries no state
  int stateIndex;         // index among moving bodies (-1 for fixed bodies)
  pdPolyhedron shape;     // body frame (origin at the centre of mass, object axes)
  int shapeTwin;          // an earlier body of the same shape definition and density (the same polyhedron and
                          // mass properties, number for number, built once), or -1
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
  double width;           // thinnest width: the smallest extent across one of its face planes, m
  pdVec3 halfExtents;     // body-frame bounding-box half extents about the centre of mass, m (max |coord|)
  double radius;          // largest vertex distance from the centre of mass, m
  pdVec3 x0;              // initial centre of mass, world, m
  pdQuat q0;              // initial orientation (body → world)
  pdVec3 v0;              // initial linear velocity, world, m/s
  pdVec3 w0;              // initial angular velocity, world, rad/s
  pdMaterial requested;   // what the scene said (mu's default filled in; -1 for what it did not set)
  pdMaterial used;        // what the engine uses (per body; pair constants: engine/src/model_contact.h)
  // Applied load (scene `force`): F(t) = force0 + t·forceRate in the world frame, acting at forcePoint (body
  // frame, from the centre of mass). Never on a fixed body; all zero when hasForce is false.
  bool hasForce;
  pdVec3 force0;          // N, world
  pdVec3 forceRate;       // N/s, world
  pdVec3 forcePoint;      // m, body frame
  // Planar motion (scene `planar`): the centre of mass moves in the world x–z plane and the body turns about
  // the world y axis only, three degrees of freedom. Contacts and their forces stay three-dimensional; the
  // derivative drops the force's y component and the torque's x and z components (the constraint's reaction,
  // which does no work), so v_y, ω_x and ω_z stay zero (to the round-off of the implicit stepper's solves).
  // The reduced motion is exact because the compiled model requires a principal axis of inertia along world y
  // and an initial velocity in the plane (pd_model_compile).
  bool planar;
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
  bool sleep;            // islands at rest stop being integrated until reached (pd_islandsOn; docs/sleeping.md)
} pdSettings;

typedef struct pdModel {
  char* scenePath;
  pdSettings settings;
  int bodyCount;         // all bodies, scene order
  pdBody* bodies;        // (bodyCount)
  int movingCount;       // bodies that carry state
  int* movingBodies;     // (movingCount) body index of each moving body, scene order
  double lengthScale;    // m: the largest body size, used where a scene-wide length is needed
  struct pdMaterialTable* materials;  // contact parameters per body and per material-class pair (internal)
} pdModel;

// Compiles a parsed scene into a model: builds and validates every polyhedron, computes exact mass
// properties, shifts each body's frame to its centre of mass, sets initial states and settings, derives
// the contact model's material parameters (paper §3.2, §3.3) and checks that no two bodies overlap.
// Returns NULL and fills err (at the object's line) on a degenerate polyhedron, an empty scene, an
// unreachable restitution (below PD_RESTITUTION_MIN) or bodies interpenetrating at t = 0 (docs/scene-language.md).
// The model copies what it needs: the scene may be freed right after. The caller owns the model
// (pd_model_free); it is read-only from then on (any number of states and threads may share it).
PD_API pdModel* pd_model_compile(const pdScene* scene, pdError* err);

// Frees the model and everything it holds; NULL is allowed. Free its states first.
PD_API void pd_model_free(pdModel* model);

// Kinetic energy of one moving body with velocity v (m/s, world), angular velocity w (rad/s, world) and
// orientation q (body → world): ½ m v² + ½ wᵀ R I Rᵀ w, J.
PD_API double pd_body_kinetic_energy(const pdBody* body, pdVec3 v, pdVec3 w, pdQuat q);

// ---------------------------------------------------------------- applied loads (engine/src/applied_force.c)

// The applied force on `body` at time t: force0 + t·forceRate, N, world frame (zero without a force).
PD_API pdVec3 pd_body_applied_force(const pdBody* body, double t);
// The torque about the centre of mass of the applied force `force` (N, world) acting at the body's
// forcePoint, with `r` the body's rotation (body → world): (r · forcePoint) × force, N·m, world frame.
PD_API pdVec3 pd_body_applied_torque(const pdBody* body, const pdMat3* r, pdVec3 force);
// True when at least one body carries an applied force. Its work is not part of the state's energy
// (pd_state_energy), so an energy balance of such a run does not close.
PD_API bool pd_model_has_applied_force(const pdModel* model);

// ---------------------------------------------------------------- contact material (paper §3.2, §3.3)

// What the contact model derived for one body, beside body->used.
typedef struct pdBodyContactInfo {
  double mass;  // kg (INFINITY for a fixed body)
  double mMin;  // kg: minimum effective mass over the surface and all directions (App. B); INFINITY if fixed
  double zeta;  // damping ratio of the body's own restitution (eq. (15)); a pair uses that of √(e₁e₂)
} pdBodyContactInfo;

// The derived contact quantities of body `body` (0 <= body < model->bodyCount; asserts otherwise).
PD_API pdBodyContactInfo pd_model_body_contact_info(const pdModel* model, int body);

// Bodies whose side of a contact (material as used, mass, minimum effective mass, size) is identical
// share a material class; contact-pair constants are derived once per pair of classes.
PD_API int pd_model_material_class_count(const pdModel* model);
// The pairs of classes that can touch (one body moving), each named by two bodies (a moving one first):
// writes up to `capacity` into bodyA[], bodyB[] and returns how many there are.
PD_API int pd_model_contact_class_pairs(const pdModel* model, int* bodyA, int* bodyB, int capacity);

// RK4's stable step at one undamped contact mode of frequency ω: ω h ≤ PD_STABLE_STEP_OMEGA. Classic RK4 is stable
// to |hλ| ≈ 2.8 along both the negative real and the imaginary axis; 2.5 leaves a margin for what the bound does not
// see. PD_STABLE_STEP_OMEGA_TEXT is the same number as text, for messages.
#define PD_STABLE_STEP_OMEGA 2.5
#define PD_STABLE_STEP_OMEGA_TEXT "2.5"

// The longest step of the fixed RK4 stepper (pd_stepperRK4Fixed) within the stability bound of the scene's stiffest
// contact (docs/integration.md, "the stability bound"): ω h ≤ PD_STABLE_STEP_OMEGA, the bound the adaptive steppers keep, with
// ω = 2π / the shortest contact period over the pairs of material classes that can touch (one contact, undamped;
// summary.json's contact_period_min), s. Several contacts acting together can need a shorter step. INFINITY when
// nothing can touch, NAN when the period is not computed (too many material classes).
PD_API double pd_model_fixed_step_max(const pdModel* model);

// The time-constant adjustments of §3.3.1 and §3.3.2 made at compile time, per pair of material classes
// (naming the first body of each class). Adjustments past the list's capacity are not listed but counted
// (pd_model_adjustments_dropped).
PD_API int pd_model_adjustment_count(const pdModel* model);
PD_API int pd_model_adjustments_dropped(const pdModel* model);
// One line describing adjustment i (0 <= i < count) into buf (UTF-8, no newline, truncated to size - 1
// bytes); returns snprintf's count (the length it needed).
PD_API int pd_model_adjustment_describe(const pdModel* model, int i, char* buf, int size);

// ---------------------------------------------------------------- one pair, as a reference engine sees it
// A reference engine (refcheck: ODE, Bullet) takes one spring, one damper, one μ and one e per contact.
// Our contact has each side's spring ∥ damper in series (paper Fig. 3); the single equivalent element is
// k = k1 k2/(k1 + k2) and c = c1 c2/(c1 + c2), exact when both sides have the same c/k (always, unless the
// scene gives dampers explicitly). Derived ("modal") dampers are set per contact from the mass each
// contact carries in the pair's joint motion; the c here is the one for a single contact carrying the
// pair's reduced mass.
typedef struct pdPairContact {
  double mu;           // √(μ₁μ₂)
  double kn, kt;       // N/m, per contact (one vertex–face or edge–edge contact)
  double cn, ct;       // N·s/m, per contact at one contact with the pair's reduced mass; 0 without damper
  double restitution;  // the pair's e: √(e₁e₂) (each e requested or the default); with explicit dampers,
                       // e of eq. (15) for one contact at the pair's reduced mass
  const char* restitutionSource;  // "requested", "one side requested, one default", "default" or
                                  // "predicted by eq. (15) from the explicit dampers"
  double zetaN, zetaT;  // damping ratios along n and in P_t
  bool modalN, modalT;  // dampers derived per contact (true unless the scene gives cn / ct)
  double massPair;      // kg: reduced mass m₁m₂/(m₁+m₂) (a fixed body: the other's mass)
  double massMin;       // kg: the pair's minimum effective mass (App. B, both bodies in series)
  double period;        // s: 2π√(m_pair/k_n), one contact at the reduced mass
  double deltaMax;      // m: δ_max = deflection × the smaller body's size, at most ¼ of the thinner body's width
                        // (pd_model_pair_delta_max)
} pdPairContact;

// δ_max of bodies a and b, m: deflection × the smaller body's size, at most a quarter of the thinner body's
// width (docs/contact-model.md: a deeper deflection passes through a thin plate). The deflection
// the pair's springs are sized for, and the scale of the contact search's tolerances.
PD_API double pd_model_pair_delta_max(const pdModel* model, int a, int b);

// The pair constants of bodies a and b (model body indices, a != b, not both fixed), as used.
PD_API pdPairContact pd_model_pair_contact(const pdModel* model, int a, int b);

PD_EXTERN_C_END
