// polydyn — the mutable state of a simulation, and stepping it.
//
// State vector layout (paper §2): per moving body, in scene order, 13 numbers
//   v (3, world, m/s), ω (3, world, rad/s), x (3, centre of mass, world, m), q (4, w x y z, body → world),
// then per active contact, in contact-id order (paper §4.4), its 8 spring deflections (m):
//   s1n, s2n (along the contact normal), s1t (3), s2t (3) (world vectors in the tangent plane).
// The contact list changes only between steps; the vector's length n changes with it.
//
// Contact conventions (engine/src/contact_analysis.h, contact_force.h): body A (body 1) carries the vertex
// of a vertex–face (VF) contact or the first edge of an edge–edge (EE) contact; the normal points from
// body B into body A; the force reported is the one B applies to A; penetration depth > 0 when overlapping.
// One model can drive many states (sweeps, threads): the model is never written to.
//
// Reading a state: t, count, warnings, failed and stopped directly; poses with pd_state_body, contacts with
// pd_state_contact_count and pd_state_contact (not from y, whose layout is internal to the stepper). The
// caller's settings (stepper, onsets, islands, threads, search certificates, first step) go in a pdStateOptions at
// pd_state_create; the state's fields are written by pd_state_create, pd_state_reset and pd_advance only, and a
// caller reads them. With pd_islandsOn, y, n and the contact list are those of the whole scene at every output sample
// (in the observer and after pd_advance returns); between samples each island advances in a state of its own.
//
// Memory: pd_state_create allocates the vectors; the first steps of a stepper create its own (the dense output, the
// implicit stepper's matrices), and between two steps pd_advance grows the state's vectors (doubling) when the
// contact list outgrows them. Once warmed up, a step never allocates (pd_alloc_count, polydyn/api.h, counts it in
// builds with PD_COUNT_ALLOCS: tests/engine/test_step_allocations.c).
#pragma once

#include <stdbool.h>

#include "polydyn/api.h"
#include "polydyn/model.h"
#include "polydyn/vecmath.h"

PD_EXTERN_C_BEGIN

enum { PD_BODY_STATE_SIZE = 13 };

// Named, timed stages of a step (seconds accumulate in pdState.stageSeconds).
typedef enum pdStage {
  pd_stageBroadPhase,       // boxes of the moving bodies, sweep and prune
  pd_stageInterference,     // separating-axis test of each box-overlapping pair
  pd_stageContactAnalysis,  // VF/EE contacts of interfering pairs, tracking, onsets, breaks, contact list, travel limit
  pd_stageForces,           // contact forces and spring rates inside the state derivative
  pd_stageDerivative,       // the rest of the state derivative: Newton–Euler, quaternion kinematics
  pd_stageIntegrate,        // Runge–Kutta combination, error estimate, step control
  pd_stageObserve,          // calls to the observer (output)
  pd_stageCount
} pdStage;
// Names of the stages (e.g. "broad_phase"), as summary.json writes them.
PD_API extern const char* const pdStageNames[pd_stageCount];

// Counted warnings: numerical trouble that was recovered from.
typedef enum pdWarning {
  pd_warnStepAtMinimum,  // a step at dtmin still exceeded the tolerance and was accepted anyway
  pd_warnNonFinite,      // a trial step produced a non-finite number and was retried smaller
  pd_warnLateOnset,      // a contact onset could not be located within the retries: the contact was
                         // added deeper than the onset tolerance (its springs start at 0 there)
  pd_warnCount
} pdWarning;
// Names of the warnings (e.g. "step_at_minimum"), as summary.json writes them.
PD_API extern const char* const pdWarningNames[pd_warnCount];

// Which stepper advances the state. Adaptive RK4 is the paper's; the implicit one (step doubling that switches to
// ROS34PW2 where the contacts' stability bound holds it) is the default; the fixed one is for sweeps.
typedef enum pdStepper {
  pd_stepperRK4Adaptive,   // classic RK4 with step doubling: error = |two half steps − one full step|/15
  pd_stepperRK4Fixed,      // classic RK4 with the step fixed at settings.dt (no error control; stable only within
                           // pd_model_fixed_step_max)
  pd_stepperRK43Embedded,  // classic RK4 with its embedded third-order partner: error = h |k4 − f(t+h, y1)|/6
  pd_stepperImplicit,      // step doubling, switching system by system to ROS34PW2 (a linearly implicit method of
                           // order 3 with an order-2 estimate and no stability bound) where the contacts' stability
                           // bound holds step doubling: resting contact. Systems of more than 32 moving bodies
                           // (PD_IMPLICIT_BODIES_MAX) keep step doubling (docs/integration.md)
  pd_stepperDopri54,       // Dormand–Prince 5(4): 7 stages, the fifth-order result kept, error = |y1 − ŷ1| of the
                           // embedded fourth-order one, dense output by its fourth-order continuous extension; its own
                           // stability bound (docs/integration.md, "Steppers")
  pd_stepperImplicitDopri,  // as pd_stepperImplicit with Dormand–Prince 5(4) in step doubling's place, for measurement
} pdStepper;

// The stepper of pd_state_options_default() and the one `polydyn run` uses unless told: it takes step doubling's
// steps wherever the error control sets them, and longer ones where resting and sliding contacts' stability bound
// would hold step doubling to a fraction of them (docs/integration.md).
#define PD_STEPPER_DEFAULT pd_stepperImplicit

// The stepper's name in summary.json: "rk4-adaptive", "rk4-fixed", "rk43-embedded", "ros34pw2", "dopri54" or
// "ros34pw2-dopri54".
PD_API const char* pd_stepper_name(pdStepper stepper);

// How a contact that began inside a step joins the list (paper App. C; docs/contact-model.md).
typedef enum pdOnsets {
  pd_onsetsExact,  // every onset found deeper than 1e-3 δ_max cuts the whole step back to it
  pd_onsetsPair,   // a contact that began less than 1/ω before the step's end (ω of its pair) and is at most
                   // ¼ δ_max deep joins there as if its pair had run alone since the onset (springs at that
                   // deflection, the pair's impulse given to its two bodies); the step stands, so an onset in
                   // one corner of a pile does not send every body back. Others as pd_onsetsExact.
  pd_onsetsAuto,  // pd_onsetsPair in a system of more than PD_ONSETS_CROWD_BODIES moving bodies (an island, or
                  // the scene with islands off), pd_onsetsExact in smaller ones: a retry costs a crowd's whole
                  // step, and a small system keeps the exact onsets' error control
  pd_onsetsBounded,  // default: in every system, a contact that pd_onsetsPair would join at the step's end joins there
                     // when the error bound of that correction (onset_bound.h: restitution from ωτ, in the error
                     // norm's units) is within the share of the tolerance an onset may spend; others as
                     // pd_onsetsExact. So the step follows the tolerance: slow onsets are corrected, fast impacts
                     // located (docs/events.md)
  pd_onsetsHeld,     // as pd_onsetsBounded, and each contact's modes at a step's start (its normal force applied or
                     // not, its stick or slip) held for the whole step, a change the force law finds at the step's
                     // end corrected there or located by a retry (docs/events.md, "Modes within a step"). Measured:
                     // no cheaper than pd_onsetsBounded, and an impact chain's result converges with tol less
                     // well, hence not the default
} pdOnsets;

// More moving bodies than this in one system make pd_onsetsAuto join onsets as pairs. On
// cases/bench/pile_1000.scene over 1 s (its settling pile is one island of ~900 boxes from 0.6 s) exact onsets took
// 2.4× the time of auto, pair 1.06×; the piles of 10 and 100 and the bin of 100 polyhedra never form islands of more than
// 8 bodies, nor does any sweep scene or Gedanken experiment but G3 (a board with 25 cubes): they keep exact onsets.
#define PD_ONSETS_CROWD_BODIES 16

// The mode pd_onsetsAuto stands for in a system of `movingBodies` moving bodies (other modes: themselves).
PD_API pdOnsets pd_onsets_effective(pdOnsets onsets, int movingBodies);

// The onset mode of pd_state_options_default() and of the commands' --onsets; `--events exact` is pd_onsetsExact
// (the paper's loop: every onset located), `--events bounded` this default.
#define PD_ONSETS_DEFAULT pd_onsetsBounded

// The onset mode's name in summary.json: "pair", "exact", "auto", "bounded" or "held".
PD_API const char* pd_onsets_name(pdOnsets onsets);

// Whether the moving bodies advance as one system or as islands (engine/src/islands.c; docs/integration.md).
typedef enum pdIslands {
  pd_islandsOff,  // one state vector, one step size, every onset cuts every body's step
  pd_islandsOn,   // default: between output samples, bodies joined by a contact or whose boxes, grown by how far they
                  // can travel before the next sample, overlap form an island; each island takes its own
                  // steps, error norm and contact events. Output at the common sample times.
} pdIslands;

// The most threads pdState.threads may ask for (a sanity bound: the islands of an interval, and an island's long
// loops over contacts, are the only work split, and more threads than cores only adds switching).
#define PD_THREADS_MAX 64

// The island mode of pd_state_options_default() and of the commands' --islands.
#define PD_ISLANDS_DEFAULT pd_islandsOn

// The island mode's name in summary.json: "on" or "off".
PD_API const char* pd_islands_name(pdIslands islands);

// What set the size of an accepted step of an error-controlled stepper (pdCounters.stepsLimited; docs/integration.md,
// "What sets the steps"): what a run's step count is spent on.
typedef enum pdStepLimit {
  pd_limitError,      // the error control: its growth from the step before, or its shrink after a rejected trial
  pd_limitLargest,    // the scene's largest step, dtmax
  pd_limitStability,  // the contacts' stability bound (step doubling's steps; §3.3)
  pd_limitTravel,     // the tunnelling guard: the step it allows the motion as it goes on, or a trial it cut back
  pd_limitEvent,      // another contact event cut the step: an onset located, a stick–slip change refined
  pd_limitLanding,    // cut to end on a time: a sync time between islands, the end of a call, a probation's floor
  pd_limitCount
} pdStepLimit;

// The limit's name in summary.json ("error", "largest", "stability", "travel", "event", "landing").
PD_API const char* pd_step_limit_name(pdStepLimit limit);

typedef struct pdCounters {
  long accepted;     // accepted steps
  long rejected;     // rejected trial steps
  long derivatives;  // evaluations of the state derivative
  long samples;      // output samples delivered to the observer
  long eventRetries;      // trial steps cut short to land on a contact onset (App. C)
  long onsetCuts;         // of those, the steps ended on the accepted trial's interpolant, no trial retaken
  long onsetsInterpolated;  // contacts that joined at a step's end from an onset inside it (pd_onsetsPair)
  long travelRetries;     // trial steps cut short because two bodies that may meet moved too far (tunnelling)
  long refinements;       // trial steps halved around a reversal or a stick/slip change (§3.4)
  long stabilityTight;    // accepted steps whose limit needed the tight stability bound: the cheap bound allowed
                          // less than the step the error control wanted (docs/integration.md)
  long implicitSteps;     // accepted steps taken by the implicit method (pd_stepperImplicit; 0 with other steppers)
  long stepsLimited[pd_limitCount];  // accepted steps by what set their size (pdStepLimit; the fixed stepper's: none)
  long searchesSkipped;   // pair searches (interference and contact search) a search certificate made needless
  long contactsMade;      // contacts added at the end of a step (found, approaching)
  long contactsVirtual;   // contacts added at the start of a step (onset within the first dt_min)
  long contactsTransferred;  // hand-overs: a contact whose features changed over (a vertex onto the next face, §4.4.3;
                             // EE → VF, VF → EE, EE → EE at a shared vertex) going on in its successor, springs kept
  long breaksForce;       // contacts dropped because the normal springs would pull
  long breaksGeometry;    // contacts dropped because a feature left the other (vertex off its face, EE off an edge)
  // What the step did not locate (docs/events.md): each corrected onset's error bound (onset_bound.h), in the units
  // of the error norm (so comparable with tol), their largest and their sum
  double onsetBoundMax;
  double onsetBoundSum;
  long transitionsUnlocated;   // stick–slip changes left inside their step (bounded events), each with its bound:
  double transitionBoundMax;   // the largest
  double transitionBoundSum;   // and their sum, error-norm units as above
  long releasesCorrected;      // normal forces that reached zero inside a step whose modes were held (docs/events.md):
  double releaseBoundMax;      // the tension applied since taken out at the step's end, never located; each one's
  double releaseBoundSum;      // error bound, largest and summed, error-norm units
  long historyKept;  // contacts that started on the features of one broken by force within the gap tolerance, with
                     // its tangential springs (engine/src/contact_history.h)
  // pd_islandsOn only (0 otherwise); the counts above are then summed over the islands
  long islandsFormed;    // islands set up (at the start, and each time the bodies of an island changed)
  long islandsLargest;   // moving bodies in the largest island formed
  long islandIntervals;  // sync intervals advanced (island by island; islands.c, design note)
  long islandRedos;      // islands whose interval was redone because a body moved farther than its grown box
  long islandStrays;     // free bodies found outside their box over a sample interval (none expected: a free body
                         // has no contact to leave its ballistic path by; counted, not recovered)
  // pd_islandsOn with settings.sleep (0 otherwise): islands at rest stop being integrated (docs/sleeping.md)
  long islandsSlept;         // islands that fell asleep
  long islandsWoken;         // sleeping islands woken (a body may reach them, or an applied force changed)
  double bodySecondsAsleep;  // s: the sum over moving bodies of the time each spent asleep
} pdCounters;

// A step observer (pdStateOptions.stepObserver; nullable, NULL by default, and then nothing is called and nothing
// costs): called with `start` true with the state where a stretch of integration begins (pd_advance's start with
// islands off; with islands on, an island's start at each sync time, again when the island is redone), then with
// `start` false after every accepted step of that stretch (and once with the state presented at its end when the
// last step passed it). With islands on, `model` and `state` are the island's own (its moving bodies and every
// fixed body, in scene order; pd_state_body and the model's bodies and names as for a scene), and with threads > 1
// the calls of different islands come from their threads at the same time; one island's calls come from one
// thread, in order. It reads the state (const) and must not step it. For checks between output samples (the
// soak: docs/reliability.md); the observer of pd_advance sees the whole scene at the samples only.
struct pdState;
typedef void pdStepObserverFcn(const pdModel* model, const struct pdState* state, bool start, void* user);

// The caller's settings of a state. Start from pd_state_options_default() and change the fields you need:
//   pdStateOptions o = pd_state_options_default();
//   o.islands = pd_islandsOff;
//   pdState* s = pd_state_create(model, &o);
// (a struct not made by pd_state_options_default is refused: pd_state_create asserts on its `valid` field).
typedef struct pdStateOptions {
  pdStepper stepper;  // PD_STEPPER_DEFAULT
  pdOnsets onsets;    // how contacts that began inside a step join: PD_ONSETS_DEFAULT
  pdIslands islands;  // one system or islands: PD_ISLANDS_DEFAULT
  int threads;        // 1 (default) .. PD_THREADS_MAX. With pd_islandsOn, the islands of each interval run on this
                      // many threads (the caller's and threads - 1 of the state's own, created at the first pd_advance
                      // and joined by pd_state_free/reset), a thread without an island helping a running one with
                      // its long loops over contacts; the results are bit-identical for every count. Ignored with
                      // pd_islandsOff (one system: one thread).
  bool searchCertificates;  // true (the default): a pair whose last contact search found nothing new is not
                            // searched again while a certificate proves the search would find nothing new
                            // (contact_analysis.h); false searches every pair after every step. The results are
                            // the same bit for bit; false is for tests and measurements.
  bool stageTimers;  // true (the default): each step's stages and each sample's observer call are timed into
                     // pdState.stageSeconds (summary.json's timing); false reads no clock and leaves them 0, for a
                     // caller that times the run whole (the Gedanken cost, benchmarks): a clock read costs ~30 ns,
                     // and a short run of one body sampled at 2 kHz makes thousands of them. Results are the same
                     // bit for bit.
  double h;           // the first step to try, s (> 0); 0 (the default): the scene's settings.dt
  pdStepObserverFcn* stepObserver;  // nullable (the default): called at every accepted step (pdStepObserverFcn)
  void* stepUser;                   // handed to stepObserver
  int valid;          // set by pd_state_options_default; do not set (catches options never initialised)
} pdStateOptions;

// The default options: the values listed in pdStateOptions.
PD_API pdStateOptions pd_state_options_default(void);

typedef struct pdState {
  double t;          // s
  double h;          // next step to try, s
  pdStepLimit hLimit;  // what set h (counted in count.stepsLimited when a step of h is accepted)
  // The options the state was created with (pdStateOptions), as the steppers read them; read-only to the caller.
  pdStepper stepper;
  pdOnsets onsets;
  pdIslands islands;
  bool searchCertificates;
  bool stageTimers;
  int threads;
  pdStepObserverFcn* stepObserver;  // and its user pointer: the options' (an island's: the scene state's)
  void* stepUser;
  pdStateOptions options;  // as given to pd_state_create (pd_state_reset returns to them)
  int n;             // length of y: 13 per moving body + 8 per active contact
  int capacity;      // allocated length of y, weight and each stepper vector (grown only between steps)
  double* y;         // (n) the state vector
  double* weight;    // (n) error weight of each component (its characteristic scale)
  double* work;      // scratch for the stepper (owned)
  struct pdContactSet* contacts;  // the contact list and the contact search's scratch (internal)
  struct pdIslandSet* islandSet;  // the islands' own states between samples (internal; NULL when off)
  struct pdImplicit* implicit;    // the implicit stepper's matrices (internal; NULL until it first steps)
  struct pdDense* dense;          // dense output: the last step that passed a sample or tEnd, and the integration's
                                  // own state while the state is presented between step ends (internal; NULL until
                                  // an error-controlled stepper first steps)
  long nextSample;   // index k of the next output sample, at t = k / sampleRate
  bool failed;       // the run could not continue (see warnings); pd_advance returns false
  bool stopped;      // the observer asked to stop; pd_advance returns false
  pdCounters count;
  long warnings[pd_warnCount];
  double stageSeconds[pd_stageCount];
} pdState;

// Pose and velocity of one body (fixed bodies report their initial pose and zero velocity).
typedef struct pdBodyState {
  pdVec3 x;  // centre of mass, world, m
  pdQuat q;  // body → world
  pdVec3 v;  // m/s
  pdVec3 w;  // rad/s, world
} pdBodyState;

// A new state of `model` at t = 0: the scene's initial poses and velocities, no contacts, the settings of `options`
// (NULL: pd_state_options_default(); asserted valid: threads in 1 .. PD_THREADS_MAX, h >= 0). The caller owns it
// (pd_state_free). `model` must outlive the state and be the model passed with it to every other call.
PD_API pdState* pd_state_create(const pdModel* model, const pdStateOptions* options);
// Back to t = 0 with the model's initial conditions and the options the state was created with; counters,
// warnings and timers cleared.
PD_API void pd_state_reset(const pdModel* model, pdState* state);
// Frees the state and everything it holds; NULL is allowed.
PD_API void pd_state_free(pdState* state);

// Pose and velocity of body `bodyIndex` (a model body index, 0 <= bodyIndex < model->bodyCount, fixed
// bodies included) at the state's time t. Asserts on an index out of range.
PD_API pdBodyState pd_state_body(const pdModel* model, const pdState* state, int bodyIndex);

// Kinetic + gravitational potential energy of all moving bodies plus the energy stored in the contact
// springs (½ k s² each), those that broken contacts keep for their return included, J (gravitational potential zero
// at the origin).
PD_API double pd_state_energy(const pdModel* model, const pdState* state);

// One active contact at the state's time, for output (docs/outputs.md, contacts.csv).
typedef struct pdContactReport {
  int bodyA, bodyB;     // body indices: A carries the vertex (VF) or the first edge (EE)
  bool edgeEdge;        // false: VF, true: EE
  int featureA, featureB;  // VF: vertex of A, face of B; EE: edge of A, edge of B
  pdVec3 point;         // world, m: the vertex (VF) or the midpoint of the edges' closest points (EE)
  pdVec3 normal;        // unit, from B into A
  double depth;         // m, > 0 when overlapping (geometric, not the springs' deflection)
  double fn;            // N, normal force on A (>= 0)
  pdVec3 ft;            // N, friction force on A
  bool slip;            // the friction limit is active
  double springScale;   // its springs over eq. (11)'s for the pair alone, >= 1: raised for the load the pair carries
                        // (docs/contact-model.md, "Springs sized by the load")
} pdContactReport;

// The active contacts at the state's time t (in an observer, or after pd_advance returned): their number,
// and contact i (0 <= i < count, in contact-id order; asserts otherwise) as a copy. Its force is the one the
// springs carry at t; a contact whose normal springs would pull reports no force (it is dropped after the
// step). The sum over contacts of ±(fn·normal + ft) (+ when the body is A, − when it is B) is the total
// contact force on a body (examples/embed/main.c). In a state presented at a sample (pd_advance), the first call
// evaluates all its contacts there and keeps them: state is const to the caller, but two threads must not make
// that first read of one state at once.
PD_API int pd_state_contact_count(const pdState* state);
PD_API pdContactReport pd_state_contact(const pdState* state, int i);

// Stacks: the moving bodies joined by the state's contacts (a fixed body joins none). stackOf (model->bodyCount)
// gets each body's stack, 0 … count − 1 in the order of their lowest body index, or −1 for a fixed body and for a
// moving one without contacts. Returns the number of stacks.
PD_API int pd_state_stacks(const pdModel* model, const pdState* state, int* stackOf);

// One root λ of a stack's linearised contact dynamics det(λ² 𝕄 + λ C + K) = 0 (docs/contact-model.md, "Stacks").
typedef struct pdStackMode {
  double omega;  // rad/s: |λ| (an oscillating mode's natural frequency; a real root's decay rate)
  double zeta;   // −Re λ/|λ|: the damping ratio of an oscillating mode (< 1); 1 for a real root
  bool real;     // a real root: half of an overdamped mode, which does not oscillate
} pdStackMode;

// Stacks of more moving bodies than this are not analysed (the eigenproblem has 12 roots per body).
#define PD_STACK_MODES_BODIES_MAX 16

// The roots of stack `stack` of stackOf (pd_state_stacks), one per complex-conjugate pair, sorted by omega: K and C
// from every contact touching the stack (normal springs and dampers, and the tangential ones of sticking contacts,
// each the series of both sides; fixed bodies hold still), 𝕄 the bodies' masses and world inertias; roots below
// 1e-9 of the largest (free motions: a body sliding without tangential springs) are left out. Writes at most
// `capacity` roots and returns how many there are, or −1 for a stack of more than PD_STACK_MODES_BODIES_MAX bodies.
PD_API int pd_state_stack_modes(const pdModel* model, const pdState* state, const int* stackOf, int stack,
                                pdStackMode* modes, int capacity);

// Called at every output sample, with state->t exactly k / sampleRate. Returning false asks
// pd_advance to stop after this sample (state->stopped is set). The observer reads the state (it is
// const) and may do anything else, but must not call pd_advance or pd_state_reset on this state.
typedef bool pdObserverFcn(const pdModel* model, const pdState* state, void* user);

// Advances the state to tEnd, s (tEnd >= state->t, asserted; clamping to settings.tend is the caller's choice), calling
// `observer` (nullable) with `user` at every output sample t = k / sampleRate <= tEnd, including t = 0 when the state
// is there. Neither the samples nor tEnd cut the error-controlled steppers' steps (dense output, docs/integration.md):
// at a sample inside a step, and at tEnd when the last step passed it, the state is presented there (its bodies and
// springs interpolated within that step; its contacts' springs realigned and forces evaluated there when first read, by
// pd_state_contact, pd_state_energy or the next island set-up, so a sample whose observer reads only the bodies pays
// for the interpolant alone: the numbers are the same either way), and the integration's own state waits at that step's
// end; writing to state->y between calls does not reach it. The fixed stepper ends its steps on every sample and on
// tEnd. Call it again with a later tEnd to go on: the samples continue where they stopped, and a run stopped on a
// sample time (tEnd = k / sampleRate, that very division) and resumed computes the same numbers as one call
// (tests/engine/test_determinism.c); so does one stopped at any other tEnd with islands off (with islands on, tEnd ends
// a sync interval there). Returns true when state->t == tEnd; false if the run had to stop (state->failed, with the
// reason counted in state->warnings; the state stays finite and later calls return false at once) or the observer asked
// to stop (state->stopped; state->t is then that sample's time).
PD_API bool pd_advance(const pdModel* model, pdState* state, double tEnd, pdObserverFcn* observer, void* user);

// The state derivative dy/dt at (t, y), y laid out for the state's current contact list (its length is
// state->n; layout at the top of this header), written to dydt (state->n numbers). Uses the state's
// scratch and stage timers, so it changes what pd_state_contact reports until the next step. Exposed for
// tests and alternative steppers.
PD_API void pd_state_derivative(const pdModel* model, pdState* state, double t, const double* y, double* dydt);

PD_EXTERN_C_END
