// polydyn refcheck — the random-scene soak (docs/reliability.md; `polydyn soak`).
//
// A campaign is a seed and a count: scene i of campaign S is a function of (S, i) alone, written as
// scene-language text, so a failing scene is replayed with `polydyn run` on its file. The scenes are
// what nobody tuned for: 1 to 30 bodies of random convex shapes (boxes down to 100:1 plates, prisms,
// frusta, geodesic spheres, random hulls including slivers), scene scales from 1 cm to 10 m, densities
// over two orders, μ 0 … 1.5, restitution 0.1 … 1 or the default, sometimes vmax, deflection and tol set.
// Kinds: bodies dropped onto a floor; stacks set down touching (often flush); bodies thrown at up to
// 50 m/s at a floor and a wall; bodies colliding without gravity or fixed bodies; two bodies placed
// interpenetrating, which the scene compiler must refuse.
//
// Each scene runs in a child process per engine (a crash is a result, not the end of the campaign),
// with the invariants checked at every output sample (pdSoakResult). A run that exceeds its wall-time
// budget is stopped and reported as over budget: a cost finding, not a failure of the invariants.
#pragma once

#include <stdbool.h>
#include <stddef.h>

#include "polydyn/state.h"

typedef enum pdSoakKind {
  pd_soakDrop,     // onto a fixed floor, from a loose grid, turned and moving
  pd_soakStack,    // set down touching on a floor, sometimes flush (equal widths, aligned)
  pd_soakThrow,    // at a floor and a wall, 5 … 50 m/s
  pd_soakFree,     // no gravity, no fixed body: colliding towards the middle (momentum must hold)
  pd_soakOverlap,  // two boxes interpenetrating by 5 … 30 % of the smaller: must be refused
  pd_soakKindCount
} pdSoakKind;

extern const char* const pdSoakKindNames[pd_soakKindCount];

typedef struct pdSoakScene {
  pdSoakKind kind;
  int objects;            // bodies in the scene, fixed ones included
  bool dissipative;       // every body's restitution below 1: the energy may not rise
  char* text;             // the scene file (malloc'd; pd_soak_scene_free)
} pdSoakScene;

// Scene `index` of campaign `seed`: the same text for the same (seed, index) on every machine (GSL's
// MT19937 seeded from both, numbers written with %.17g).
pdSoakScene pd_soak_scene(unsigned long seed, long index);
void pd_soak_scene_free(pdSoakScene* scene);

// Invariant limits (docs/reliability.md, says why each is what it is).
// Deepest overlap of any two bodies over the pair's δ_max (pd_model_pair_delta_max), soft engine.
#define PD_SOAK_PENETRATION_LIMIT 3.0
// Largest rise of the energy above its start in a dissipative scene, relative to the start (potential
// energy counted from the floor's top at z = 0, so E(0) > 0 is what the scene can release): the adaptive
// stepper keeps each step's error below tol of the state's scales, and 1e-3 allows a thousand such
// errors adding up in one direction at the default tol 1e-6.
#define PD_SOAK_ENERGY_GAIN_REL 1e-3
// Largest change of the total linear momentum, relative to Σ m|v(0)|, in a scene without gravity or fixed
// bodies: every contact force acts equally and oppositely on its two bodies and Runge–Kutta keeps linear
// invariants, so only rounding remains.
#define PD_SOAK_MOMENTUM_REL 1e-9

typedef enum pdSoakStatus {
  pd_soakOk,          // ran to tend, every invariant held
  pd_soakRefused,     // the scene was refused (as it must be for overlap scenes) or the engine cannot run it
  pd_soakOverBudget,  // stopped at the wall-time budget (not an invariant failure)
  pd_soakFailed,      // an invariant broke, the run stopped early, or the process crashed
  pd_soakNotBuilt,    // the engine is not in this build
  pd_soakStatusCount
} pdSoakStatus;

extern const char* const pdSoakStatusNames[pd_soakStatusCount];

typedef struct pdSoakResult {
  pdSoakStatus status;
  char message[240];
  double wallSeconds;
  double simulated;          // s reached
  long steps;                // soft: accepted steps; reference engines: their steps
  double penetration;        // deepest overlap / δ_max of the pair over all samples (all engines: shown)
  double energyGain;         // max (E(t) − E(0)) / E(0), kinetic + gravitational (+ springs: soft)
  double momentumError;      // max |P(t) − P(0)| / Σ m|v(0)| (free scenes), else 0
} pdSoakResult;

// Whether `engine` is the soft engine: "soft" (islands as the engine's default) or "soft-islands-off"
// (--islands off); *islands gets its island mode.
bool pd_soak_engine_is_soft(const char* engine, pdIslands* islands);

// Runs the scene in `engine` ("soft", "soft-islands-off", "ode", "bullet") in a child process with the wall-time budget
// and checks the invariants; the soft engine joins contact onsets as `onsets` says (docs/contact-model.md). The
// result is filled in every case.
void pd_soak_run(const pdSoakScene* scene, const char* engine, pdOnsets onsets, double budgetSeconds,
                 pdSoakResult* out);
