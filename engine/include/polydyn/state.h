// polydyn — the mutable state of a simulation, and stepping it.
//
// State vector layout (paper §2): per moving body, in scene order, 13 numbers
//   v (3, world, m/s), ω (3, world, rad/s), x (3, centre of mass, world, m), q (4, w x y z, body → world).
// One model can drive many states (sweeps, threads): the model is never written to.
//
// Memory: pd_state_create allocates everything the step needs; pd_advance allocates nothing.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/vecmath.h"

enum { PD_BODY_STATE_SIZE = 13 };

// Named, timed stages of a step (seconds accumulate in pdState.stageSeconds).
typedef enum pdStage {
  pd_stageDerivative,  // state derivative: Newton–Euler, quaternion kinematics
  pd_stageIntegrate,   // Runge–Kutta combination, error estimate, step control
  pd_stageObserve,     // calls to the observer (output)
  pd_stageCount
} pdStage;
extern const char* const pdStageNames[pd_stageCount];

// Counted warnings: numerical trouble that was recovered from.
typedef enum pdWarning {
  pd_warnStepAtMinimum,  // a step at dtmin still exceeded the tolerance and was accepted anyway
  pd_warnNonFinite,      // a trial step produced a non-finite number and was retried smaller
  pd_warnCount
} pdWarning;
extern const char* const pdWarningNames[pd_warnCount];

// Which stepper advances the state. Adaptive RK4 is the paper's; the fixed one is for sweeps.
typedef enum pdStepper {
  pd_stepperRK4Adaptive,  // classic RK4 with step doubling: error = |two half steps − one full step|/15
  pd_stepperRK4Fixed,     // classic RK4 with the step fixed at settings.dt (no error control)
} pdStepper;

typedef struct pdCounters {
  long accepted;     // accepted steps
  long rejected;     // rejected trial steps
  long derivatives;  // evaluations of the state derivative
  long samples;      // output samples delivered to the observer
} pdCounters;

typedef struct pdState {
  double t;          // s
  double h;          // next step to try, s
  pdStepper stepper;
  int n;             // length of y
  double* y;         // (n) the state vector
  double* weight;    // (n) error weight of each component (its characteristic scale)
  double* work;      // scratch for the stepper (owned)
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

pdState* pd_state_create(const pdModel* model);
// Back to t = 0 with the model's initial conditions; counters and timers cleared.
void pd_state_reset(const pdModel* model, pdState* state);
void pd_state_free(pdState* state);

pdBodyState pd_state_body(const pdModel* model, const pdState* state, int bodyIndex);

// Kinetic + gravitational potential energy of all moving bodies, J (potential zero at the origin).
double pd_state_energy(const pdModel* model, const pdState* state);

// Called at every output sample, with state->t exactly k / sampleRate. Returning false asks
// pd_advance to stop after this sample (state->stopped is set).
typedef bool pdObserverFcn(const pdModel* model, const pdState* state, void* user);

// Advances the state to tEnd (clamped to settings.tend is the caller's choice), calling `observer`
// (nullable) at every output sample t = k / sampleRate <= tEnd, including t = 0 when the state is
// there. Returns false if the run had to stop (state->failed; the state stays finite) or the
// observer asked to stop (state->stopped).
bool pd_advance(const pdModel* model, pdState* state, double tEnd, pdObserverFcn* observer, void* user);

// The state derivative dy/dt at (t, y). Exposed for tests and alternative steppers.
void pd_state_derivative(const pdModel* model, double t, const double* y, double* dydt);
