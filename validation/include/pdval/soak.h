// polydyn refcheck — the random-scene soak (docs/reliability.md; `polydyn soak`).
//
// A campaign is a generator, a seed and a count: scene i of campaign S is a function of (generator, S, i)
// alone, written as scene-language text, so a failing scene is replayed with `polydyn run` on its file. The
// scenes are what nobody tuned for: 1 to 30 bodies of random convex shapes (boxes down to 100:1 blades,
// prisms, frusta, geodesic spheres, random hulls including slivers; the second generator also plates, thin
// boxes and prisms 3:1 … 30:1 with side faces), scene scales from 1 cm to 10 m, densities over two orders,
// μ 0 … 1.5, restitution 0.1 … 1 or the default, sometimes deflection and tol set.
// Kinds: bodies dropped onto a floor; stacks set down touching (often flush); bodies thrown at up to
// 50 m/s at a floor and a wall; bodies colliding without gravity or fixed bodies; two bodies placed
// interpenetrating, which the scene compiler must refuse.
//
// Each scene runs in a child process per engine (a crash is a result, not the end of the campaign),
// with the invariants checked at every output sample and, in the soft engine, the overlap and the energy
// also at every accepted step (pdSoakResult). A run that exceeds its wall-time budget is stopped and
// reported as over budget: a cost finding, not a failure of the invariants.
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

// The scene generators. A new generator is a new number: the scenes of the earlier ones stay as they were, so
// committed campaigns and the failures they list replay.
enum {
  PD_SOAK_GENERATOR_BLADES = 1,  // boxes, prisms, frusta, spheres, hulls; thin only as 100:1 blades and slivers
  PD_SOAK_GENERATOR_PLATES = 2,  // as 1, plus plates (thin boxes, prisms and frusta 3:1 … 30:1) in every kind
                                 // that draws shapes, and plates in stacks
  PD_SOAK_GENERATOR_LATEST = PD_SOAK_GENERATOR_PLATES
};

// Scene `index` of campaign `seed` of `generator` (1 .. PD_SOAK_GENERATOR_LATEST, asserted): the same text for
// the same (generator, seed, index) on every machine (GSL's MT19937 seeded from seed and index, numbers written
// with %.17g).
pdSoakScene pd_soak_scene(int generator, unsigned long seed, long index);
void pd_soak_scene_free(pdSoakScene* scene);

// Invariant limits (docs/reliability.md, says why each is what it is).
// Deepest overlap of any two bodies over the pair's δ_max (pd_model_pair_delta_max), soft engine, at every
// accepted step (between the output samples too: an impact can come and go within one sample interval).
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
  double penetration;        // deepest overlap / δ_max of the pair over all samples (all engines: shown) and,
                             // when everyStep, over every accepted step (soft)
  double penetrationSampled; // the same at the output samples only
  double energyGain;         // max (E(t) − E(0)) / E(0), kinetic + gravitational (+ springs: soft); when
                             // everyStep also every stretch's rise within itself (pdSoakRunOptions)
  double momentumError;      // max |P(t) − P(0)| / Σ m|v(0)| at the samples, and of each stretch's change at
                             // the accepted steps (--check steps) (free scenes), else 0
} pdSoakResult;

// Whether `engine` is the soft engine: "soft" (islands as the engine's default) or "soft-islands-off"
// (--islands off); *islands gets its island mode.
bool pd_soak_engine_is_soft(const char* engine, pdIslands* islands);

typedef struct pdSoakRunOptions {
  pdOnsets onsets;       // soft engine: how contact onsets join (docs/contact-model.md)
  double budgetSeconds;  // wall time of one run
  // Soft engine: also check at every accepted step (the engine's step observer, polydyn/state.h): the deepest
  // overlap of the bodies of the system stepped (the scene with islands off, an island with islands on: two
  // islands cannot touch between their sync times, and the samples see the whole scene), and the rise of that
  // system's energy since its stretch began (the whole run with islands off, the island's sync interval with
  // islands on; over E(0) of the scene: a step of a dissipative system never adds energy, and the samples check
  // what the stretches add up to). False: at the output samples only, as campaigns before the step observer.
  bool everyStep;
  // Soft engine: the plain penetration limit, δ_max (0, as a struct left unset has it: PD_SOAK_PENETRATION_LIMIT); a
  // pair that third bodies press together may reach it times √(M / m_pair). A tighter one shows a campaign's margin,
  // and one below any contact's depth fails every run whose bodies touch (tests/cli/test_determinism.sh).
  double penetrationLimit;
} pdSoakRunOptions;

// Runs the scene in `engine` ("soft", "soft-islands-off", "ode", "bullet") in a child process with the wall-time budget
// and checks the invariants as `options` says. The result is filled in every case.
void pd_soak_run(const pdSoakScene* scene, const char* engine, const pdSoakRunOptions* options, pdSoakResult* out);
