// polydyn — scene description: what a scene file said, before anything is derived from it.
//
// The scene language (docs/scene-language.md, paper §5.1) is line oriented: `#` starts a comment, one command
// per line, a trailing backslash continues the line, keywords are case sensitive. Object commands
// start an object, property commands apply to the last object, settings may appear anywhere.
// Units: m, kg, s; angles in degrees (converted to radians here, at parse time).
//
// A scene is accepted or refused as a whole: the parser stops at the first error and reports it as
// `FILE:LINE:COL: message` in a pdError. The parser never asserts or aborts on file content.
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "polydyn/api.h"
#include "polydyn/error.h"

PD_EXTERN_C_BEGIN

typedef enum pdPrimitiveKind {
  pd_primCube,    // cube NAME COLOR sx sy sz
  pd_primPrism,   // prism NAME COLOR n sx sy sz          (3 <= n <= PD_PRISM_MAX_SIDES)
  pd_primTprism,  // tprism NAME COLOR n sx sy sz taper   (0 < taper <= 1)
  pd_primSphere,  // sphere NAME COLOR level sx sy sz     (0 <= level <= PD_SPHERE_MAX_LEVEL)
  pd_primHull,    // hull NAME COLOR x y z x y z ...      (at least 4 points)
} pdPrimitiveKind;

enum {
  PD_PRISM_MAX_SIDES = 64,
  PD_SPHERE_MAX_LEVEL = 3,
  PD_HULL_MAX_POINTS = 100000,
};

// Bits of pdSceneObject.setMask / pdSceneSettings.setMask: which values the file gave explicitly.
enum {
  PD_SET_MU = 1u << 0,
  PD_SET_KN = 1u << 1,
  PD_SET_KT = 1u << 2,
  PD_SET_CN = 1u << 3,
  PD_SET_CT = 1u << 4,
  PD_SET_RESTITUTION = 1u << 5,
  PD_SET_SPGRAV = 1u << 6,
  PD_SET_LOC = 1u << 7,
  PD_SET_VEL = 1u << 8,
  PD_SET_FORCE = 1u << 9,
  PD_SET_PLANAR = 1u << 10,
};
enum {
  PD_SET_GRAVITY = 1u << 0,
  PD_SET_TEND = 1u << 1,
  PD_SET_TOL = 1u << 2,
  PD_SET_DT = 1u << 3,
  PD_SET_DTMIN = 1u << 4,
  PD_SET_DTMAX = 1u << 5,
  PD_SET_SAMPLE = 1u << 6,
  PD_SET_VMAX = 1u << 7,
  PD_SET_DEFLECTION = 1u << 8,
  PD_SET_SLEEP = 1u << 9,
};

// Where a command stood in its file (1-based line and column of its first character).
typedef struct pdSourceLoc {
  int line;
  int col;
} pdSourceLoc;

typedef struct pdSceneObject {
  char* name;             // unique within the scene (owned)
  char* color;            // free-form colour word, e.g. "red" or "88aaff" (no `#`: it starts a comment) (owned)
  pdPrimitiveKind kind;
  int n;                  // prism/tprism: sides; sphere: level; else 0
  double scale[3];        // sx sy sz (> 0); hull: 1 1 1
  double taper;           // tprism: top scale factor in (0, 1]; else 1
  double* points;         // hull: pointCount × 3 coordinates in the object's own frame (owned); else NULL
  int pointCount;
  bool fixed;             // `fixed`: immovable, carries no state
  double loc[3];          // `loc`: centre of mass in the world, m (default 0 0 0)
  double locAngle;        // `loc`: rotation angle, rad (default 0)
  double locAxis[3];      // `loc`: rotation axis in the world, not normalised (default 0 0 1)
  double vel[3];          // `vel`: linear velocity, m/s (default 0 0 0)
  double spin;            // `vel`: angular speed, rad/s (default 0)
  double spinAxis[3];     // `vel`: spin axis in the object's own frame, not normalised (default 0 0 1)
  double spgrav;          // specific gravity: density = spgrav × 1000 kg/m³ (default 1)
  double mu;              // base friction coefficient (default PD_DEFAULT_MU)
  double kn, kt;          // spring constants, N/m (0 = derive, issue: contact model)
  double cn, ct;          // damper constants, N·s/m (0 = none unless derived from restitution)
  double restitution;     // requested coefficient of restitution in [0, 1] (valid when PD_SET_RESTITUTION)
  // `force`: an applied force F(t) = force + t·forceRate (world frame) at the point forcePoint (object axes,
  // relative to the centre of mass); valid when PD_SET_FORCE, else zero
  double force[3];        // N
  double forceRate[3];    // N/s
  double forcePoint[3];   // m
  pdSourceLoc forceWhere; // the `force` command (line 0 when none)
  pdSourceLoc planarWhere; // the `planar` command (valid when PD_SET_PLANAR)
  unsigned setMask;       // PD_SET_* bits: which properties the file set
  pdSourceLoc where;      // the object command
} pdSceneObject;

// Defaults of the scene language, documented in docs/scene-language.md.
#define PD_DEFAULT_GRAVITY_Z (-9.81)  // m/s²
#define PD_DEFAULT_TEND 1.0           // s
#define PD_DEFAULT_TOL 1e-6           // weighted max-norm of the local error estimate, dimensionless
#define PD_DEFAULT_DT 1e-3            // s, first step proposed
#define PD_DEFAULT_DTMIN 1e-9         // s
#define PD_DEFAULT_DTMAX 1e-2         // s, at tol PD_DEFAULT_TOL and tighter; looser: pd_default_dtmax
// the longest derived dtmax, s: the longest cap measured on the Gedanken work-precision ladder (tol 1e-1)
#define PD_DTMAX_DERIVED_CEILING 0.1
#define PD_DEFAULT_SAMPLE 100.0       // output samples per second
#define PD_DEFAULT_DEFLECTION 0.01    // δ_max as a fraction of a body's average dimension
#define PD_DEFAULT_SLEEP true         // islands at rest stop being integrated (docs/sleeping.md)
#define PD_DEFAULT_MU 0.5             // base friction coefficient
#define PD_DEFAULT_SPGRAV 1.0         // water

typedef struct pdSceneSettings {
  double gravity[3];   // m/s²
  double tend;         // s, > 0
  double tol;          // > 0
  double dt;           // s, > 0
  double dtmin;        // s, > 0
  double dtmax;        // s, > 0
  double sample;       // Hz, > 0
  double vmax;         // m/s, > 0 when PD_SET_VMAX, else 0 (estimated from the scene)
  double deflection;   // (0, 1)
  bool sleep;          // `sleep on|off`
  unsigned setMask;    // PD_SET_* setting bits
  pdSourceLoc where[10];  // where each setting was last given, indexed by bit number (line 0 = default)
} pdSceneSettings;

typedef struct pdScene {
  char* path;                // the file name used in messages (owned)
  pdSceneSettings settings;
  pdSceneObject* objects;    // objectCount objects in file order (owned)
  int objectCount;
} pdScene;

// Parses a scene file. On success returns a scene (free with pd_scene_free) and leaves err
// untouched; on failure returns NULL and fills err with the first problem found (bad syntax,
// unknown command, arity, non-number, non-finite, out of range, property before any object,
// duplicate name, a file that cannot be opened or is not text, a token or file over the limits).
// Memory use is bounded by the scene's content, not by the length of junk lines.
PD_API pdScene* pd_scene_parse_file(const char* path, pdError* err);

// Parses a scene held in memory: `length` bytes of `text` (no terminating NUL needed); `name` is used in
// messages. Same contract as pd_scene_parse_file.
PD_API pdScene* pd_scene_parse_buffer(const char* name, const char* text, size_t length, pdError* err);

// Frees the scene and everything it holds; NULL is allowed.
PD_API void pd_scene_free(pdScene* scene);

// The largest step of a scene that sets no `dtmax`, s, for its tolerance `tol` (> 0): PD_DEFAULT_DTMAX at
// PD_DEFAULT_TOL and tighter; looser, PD_DEFAULT_DTMAX (tol / PD_DEFAULT_TOL)^(1/5), the step at which a local
// error of the steppers' order (step doubling's h⁵) that reaches PD_DEFAULT_TOL at PD_DEFAULT_DTMAX reaches tol,
// at most PD_DTMAX_DERIVED_CEILING. The cap follows the tolerance as the error control's steps do (docs/events.md,
// "The largest step"); pd_model_compile applies it.
PD_API double pd_default_dtmax(double tol);

PD_EXTERN_C_END
