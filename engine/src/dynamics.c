// polydyn — the state derivative (paper §2): Newton–Euler with the gyroscopic term, quaternion
// kinematics, gravity, the scene's applied forces, and the contact forces with their spring rates
// (contact_forces.c).

#include "dynamics.h"

#include <math.h>
#include <pthread.h>

#include "clock.h"
#include "contact_set.h"
#include "help_desk.h"
#include "polydyn/state.h"
#include "state_layout.h"

// What one clock read adds to a timed interval, s: a property of the machine, measured once per process.
static double clockRead;
static pthread_once_t clockReadOnce = PTHREAD_ONCE_INIT;
static void measure_clock_read(void) { clockRead = pd_clock_read_seconds(); }

typedef struct bodiesLoop {
  const pdModel* model;
  double t;
  const double* y;
  double* dydt;
  const pdPose* poses;
  const pdVec3 *contactForce, *contactTorque;
} bodiesLoop;

// Moving bodies [begin, end) of a derivative evaluation: their rates into dydt.
static void bodies_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const bodiesLoop* job = ctx;
  const pdModel* model = job->model;
  const pdVec3 g = model->settings.gravity;
  for (int k = begin; k < end; ++k) {
    const pdBody* b = &model->bodies[model->movingBodies[k]];
    const double* yb = job->y + PD_BODY_STATE_SIZE * k;
    double* d = job->dydt + PD_BODY_STATE_SIZE * k;
    pdVec3 v = pd_layout_v(yb), w = pd_layout_w(yb);
    pdQuat q = pd_layout_q(yb);
    // inside a Runge–Kutta stage q drifts off unit length; the rotation uses its direction only
    const pdMat3* r = &job->poses[model->movingBodies[k]].R;

    pdVec3 force = pd_v3_add(pd_v3_scale(g, b->mass), job->contactForce[k]);  // N, world
    pdVec3 torque = job->contactTorque[k];                                    // N·m about the centre of mass, world
    if (b->hasForce) {
      // the scene's F(t) at the stage time t, at its body-frame point: it turns with the body
      pdVec3 applied = pd_body_applied_force(b, job->t);
      force = pd_v3_add(force, applied);
      torque = pd_v3_add(torque, pd_body_applied_torque(b, r, applied));
    }

    // Euler's equations in the body frame: I ω̇ = τ − ω × I ω
    pdVec3 wb = pd_mat3_tmulv(r, w);
    pdVec3 tb = pd_mat3_tmulv(r, torque);
    pdVec3 gyro = pd_v3_cross(wb, pd_mat3_mulv(&b->inertia, wb));
    pdVec3 alphaB = pd_mat3_mulv(&b->invInertia, pd_v3_sub(tb, gyro));
    pdVec3 alpha = pd_mat3_mulv(r, alphaB);
    pdVec3 a = pd_v3_scale(force, b->invMass);
    if (b->planar) {
      // the plane's reaction cancels what would leave it (model.h: exact for a principal y axis)
      a.y = 0.0;
      alpha.x = alpha.z = 0.0;
    }

    // q̇ = ½ (0, ω) ⊗ q with ω in the world frame
    pdQuat dq = pd_quat_mul((pdQuat){0.0, w.x, w.y, w.z}, q);
    pd_layout_store(d, a, alpha, v, (pdQuat){0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z});
  }
}

void pd_state_derivative(const pdModel* model, pdState* state, double t, const double* y, double* dydt) {
  pd_contact_set_settle(state->contacts, state->y);  // a presented state's springs, realigned
  pd_state_derivative_sampled(model, state, t, y, dydt, 1.0);
}

void pd_state_derivative_sampled(const pdModel* model, pdState* state, double t, const double* y, double* dydt,
                                 double timedScale) {
  bool timed = timedScale > 0.0 && state->stageTimers;
  if (timed) pthread_once(&clockReadOnce, measure_clock_read);
  double t0 = timed ? pd_clock_seconds() : 0.0;
  pdContactSet* set = state->contacts;
  pd_contact_forces(model, set, y, dydt);
  const pdPose* poses = pd_contact_set_poses(set);
  const pdVec3* contactForce = pd_contact_set_force(set);
  const pdVec3* contactTorque = pd_contact_set_torque(set);
  double t1 = timed ? pd_clock_seconds() : 0.0;
  // a timed interval holds about one clock read, which the scale would multiply too
  if (timed) state->stageSeconds[pd_stageForces] += timedScale * fmax(0.0, t1 - t0 - clockRead);

  bodiesLoop job = {model, t, y, dydt, poses, contactForce, contactTorque};
  pd_help_for(pd_contact_set_help_desk(set), model->movingCount, PD_HELP_MIN_BODIES, bodies_range, &job);
  if (timed) state->stageSeconds[pd_stageDerivative] += timedScale * fmax(0.0, pd_clock_seconds() - t1 - clockRead);
}
