// polydyn — contact forces inside the state derivative (paper §3.1: every listed contact's force law at the state's
// poses and velocities, summed per body), and their linearisation for the implicit stepper (implicit.c).
//
// A derivative evaluation is three loops, each split with a help desk when long enough (help_desk.h): the moving
// bodies' poses, every contact's force and spring rates (or, at the very state record() formed them at, those),
// then per body the sum of its contacts' pushes in contact order, so each body's force is the same sum on any
// thread. Nothing here allocates: the arrays are sized with the list (contact_set.c).
#include <math.h>
#include <string.h>

#include "contact_list.h"

const pdPose* pd_contact_set_poses(const pdContactSet* set) { return set->poses; }
const pdVec3* pd_contact_set_force(const pdContactSet* set) { return set->force; }
const pdVec3* pd_contact_set_torque(const pdContactSet* set) { return set->torque; }

// Contacts [begin, end) of a derivative evaluation: their spring rates into dydt, their pushes into set->push.
static void forces_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  pdPairFrame frame;
  frame.p1 = NULL;  // empty (the rest is formed with it)
  for (int i = begin; i < end; ++i) {
    const contactSlot* c = &set->items[i];
    pdSprings s = loop_springs(job, i);
    pdContactGeom g;
    pdVec3 du;
    pdContactForce f;
    bool pulls;
    if (set->holdModes) {  // the modes of the step's start, whatever the law would decide here (docs/events.md)
      contact_motion(job->model, c, job->y, set->poses, &frame, &g, NULL, &du);
      pd_contact_force_held(&c->params, &s, g.normal, du, c->heldPush, c->heldSlip, &f);
      pulls = !c->heldPush;
    } else {
      evaluate(job->model, c, job->y, set->poses, &frame, &s, &g, NULL, &du, &f);
      pulls = pd_contact_force_pulls(&f);
      // an implicit trial's stage out of the slip its step started in (contact_set.h, pd_contact_set_slip_reversals)
      if (set->slipReversals && c->force.slip && !pulls && (!f.slip || pd_v3_dot(f.ft, c->force.ft) < 0.0))
        set->items[i].crossed = true;
    }
    springs_store(job->dydt + base + PD_CONTACT_STATE_SIZE * i, &f.rate);
    set->push[i] = (contactPush){g.point, f.force, pulls};
  }
}

// Moving bodies [begin, end): their poses at job->y (set->poses).
static void poses_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  poses_of_range(job->model, job->y, job->set->poses, begin, end);
}

// Each moving body's contacts in contact order, as 2 i + (0 on body1, 1 on body2): bodyFirst/bodyList. Read by the
// tight stability bound (stability_bound.c) and by the force sums (sums_range), built by pd_stability_prepare or,
// for a list installed without it, by the first derivative evaluation (the arrays are sized with the list: nothing
// is allocated).
void pd_contact_set_list_bodies(const pdModel* model, pdContactSet* set) {
  int bodies = model->bodyCount;
  for (int k = 0; k <= bodies; ++k) set->bodyFirst[k] = 0;
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    if (!model->bodies[c->id.body1].fixed) ++set->bodyFirst[c->id.body1 + 1];
    if (!model->bodies[c->id.body2].fixed) ++set->bodyFirst[c->id.body2 + 1];
  }
  for (int k = 0; k < bodies; ++k) set->bodyFirst[k + 1] += set->bodyFirst[k];
  // fill (bodyFirst[k] advances to bodyFirst[k + 1] and is shifted back after)
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    if (!model->bodies[c->id.body1].fixed) set->bodyList[set->bodyFirst[c->id.body1]++] = 2 * i;
    if (!model->bodies[c->id.body2].fixed) set->bodyList[set->bodyFirst[c->id.body2]++] = 2 * i + 1;
  }
  for (int k = bodies; k > 0; --k) set->bodyFirst[k] = set->bodyFirst[k - 1];
  set->bodyFirst[0] = 0;
  set->bodyListValid = true;
}

// Moving bodies [begin, end): the sums of their contacts' pushes, body by body over its contacts in contact order
// (bodyList), so each body's force and torque are the very sums of the loop over all contacts.
static void sums_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  const pdContactSet* set = job->set;
  for (int k = begin; k < end; ++k) {
    int body = job->model->movingBodies[k];
    pdVec3 force = {0, 0, 0}, torque = {0, 0, 0}, x = set->poses[body].x;
    for (int l = set->bodyFirst[body]; l < set->bodyFirst[body + 1]; ++l) {
      const contactPush* p = &set->push[set->bodyList[l] / 2];
      if (p->pulls) continue;
      pdVec3 moment = pd_v3_cross(pd_v3_sub(p->point, x), p->force);
      if (set->bodyList[l] % 2 == 0) {
        force = pd_v3_add(force, p->force);
        torque = pd_v3_add(torque, moment);
      } else {
        force = pd_v3_sub(force, p->force);
        torque = pd_v3_sub(torque, moment);
      }
    }
    set->force[k] = force;
    set->torque[k] = torque;
  }
}

// Contacts [begin, end) as record() formed them at this very state (pd_contact_forces): the same numbers as
// forces_range, which would form the same geometry, relative velocity and force from the same numbers again.
static void recorded_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  for (int i = begin; i < end; ++i) {
    const contactSlot* c = &set->items[i];
    springs_store(job->dydt + base + PD_CONTACT_STATE_SIZE * i, &c->force.rate);
    set->push[i] = (contactPush){c->point, c->force.force, pd_contact_force_pulls(&c->force)};
  }
}

// Contacts [begin, end) at the state pd_contact_events just tracked them to (pd_contact_set_tracked_at): a vertex–face contact's
// geometry is formed alike tracked or not (contact_motion), and its relative velocity and force (the law free) from the
// same numbers, so its rates and push are set->eval's; the others as forces_range forms them.
static void tracked_range(void* ctx, int part, int begin, int end) {
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  int base = spring_base(job->model);
  for (int i = begin; i < end; ++i) {
    if (set->items[i].id.kind != pd_contactVF) {
      forces_range(ctx, part, i, i + 1);
      continue;
    }
    const contactEval* e = &set->eval[i];
    springs_store(job->dydt + base + PD_CONTACT_STATE_SIZE * i, &e->force.rate);
    set->push[i] = (contactPush){e->geom.point, e->force.force, pd_contact_force_pulls(&e->force)};
  }
}

bool pd_contact_set_recorded_at(const pdModel* model, const pdContactSet* set, const double* y) {
  // a step's stages evaluate in the stepper's scratch: only the place the recorded state was is compared (the list
  // is the recorded one while recordedValid, so is the state's length)
  if (!set->recordedValid || y != set->recordedFrom) return false;
  int n = spring_base(model) + PD_CONTACT_STATE_SIZE * set->count;
  return memcmp(y, set->recordedY, (size_t)n * sizeof *y) == 0;
}

void pd_contact_set_forget_recorded(pdContactSet* set) { set->recordedValid = false; }

bool pd_contact_set_tracked_at(const pdModel* model, const pdContactSet* set, const double* y) {
  if (!set->trackedValid || y != set->trackedFrom || set->holdModes) return false;
  int n = spring_base(model) + PD_CONTACT_STATE_SIZE * set->count;
  return memcmp(y, set->trackedY, (size_t)n * sizeof *y) == 0;
}

void pd_contact_set_forget_tracked(pdContactSet* set) { set->trackedValid = false; }

void pd_contact_forces(const pdModel* model, pdContactSet* set, const double* y, double* dydt) {
  contactLoop job = {.model = model, .set = set, .y = y, .dydt = dydt};
  pd_help_for(set->help, model->movingCount, PD_HELP_MIN_BODIES, poses_range, &job);
  // the first derivative of a step after a commit is at the state record() has just evaluated (bit for bit)
  bool recorded = pd_contact_set_recorded_at(model, set, y);
  // an implicit trial's end (its dense output's slope) is at the state its contact events just tracked the list to
  bool tracked = !recorded && pd_contact_set_tracked_at(model, set, y);
  pd_help_for(set->help, set->count, PD_HELP_MIN_CONTACTS,
              recorded ? recorded_range : tracked ? tracked_range : forces_range, &job);
  // a list installed without pd_stability_prepare (a gather)
  if (!set->bodyListValid) pd_contact_set_list_bodies(model, set);
  pd_help_for(set->help, model->movingCount, PD_HELP_MIN_BODIES, sums_range, &job);
}

// Forward-difference steps of the linearisation: this fraction of a spring's deflection or δ_max, and of a relative
// velocity component or vmax, whichever is larger (~√ε: the truncation and rounding errors balance). The matrix need

#define PD_LINEARISE_STEP_REL 1.5e-8

// F and ṡ of a contact as one vector: F (3), then the rates (8); F is 0 when it pulls (sums_range applies none).
// `held`: the contact's modes of the step's start (the set holds modes), as the derivative takes them.
static void force_and_rates(const contactSlot* c, bool held, const double s[PD_CONTACT_STATE_SIZE], pdVec3 n,
                            pdVec3 du, double out[3 + PD_CONTACT_STATE_SIZE]) {
  pdSprings sp = springs_load(s);
  pdContactForce f;
  bool pulls;
  if (held) {
    pd_contact_force_held(&c->params, &sp, n, du, c->heldPush, c->heldSlip, &f);
    pulls = !c->heldPush;
  } else {
    pd_contact_force(&c->params, &sp, n, du, &f);
    pulls = pd_contact_force_pulls(&f);
  }
  pdVec3 force = pulls ? (pdVec3){0, 0, 0} : f.force;
  out[0] = force.x, out[1] = force.y, out[2] = force.z;
  springs_store(out + 3, &f.rate);
}

// force_and_rates of contact c as record() left it (c->force, at the state it recorded).
static void recorded_rates(const contactSlot* c, double out[3 + PD_CONTACT_STATE_SIZE]) {
  pdVec3 force = pd_contact_force_pulls(&c->force) ? (pdVec3){0, 0, 0} : c->force.force;
  out[0] = force.x, out[1] = force.y, out[2] = force.z;
  springs_store(out + 3, &c->force.rate);
}

// Body b's centre at state y (a fixed body's where it stands).
static pdVec3 centre_at(const pdModel* model, const double* y, int b) {
  const pdBody* body = &model->bodies[b];
  return body->fixed ? body->x0 : pd_layout_x(y + PD_BODY_STATE_SIZE * body->stateIndex);
}

void pd_contact_set_linearise(const pdModel* model, pdContactSet* set, const double* y, pdContactLinear* out) {
  int base = spring_base(model);
  double vmax = model->settings.vmax;
  // at the very state record() evaluated (a step's start after a commit), with the law free as there, each contact's
  // unperturbed F and ṡ are its recorded force's: the same normal, Δu and springs (recorded_range reads them so too)
  bool recorded = !set->holdModes && pd_contact_set_recorded_at(model, set, y);
  for (int i = 0; i < set->count; ++i) {
    const contactSlot* c = &set->items[i];
    int b1 = c->id.body1, b2 = c->id.body2;
    pdContactLinear* l = &out[i];
    l->body1 = b1, l->body2 = b2;
    // the contact's point and normal as record() left them at the list's preparation, at y
    l->r1 = pd_v3_sub(c->point, centre_at(model, y, b1));
    l->r2 = pd_v3_sub(c->point, centre_at(model, y, b2));
    l->invInertia1 = set->invInertiaWorld[b1];
    l->invInertia2 = set->invInertiaWorld[b2];
    pdVec3 du = pd_v3_sub(velocity_at(model, y, b1, l->r1), velocity_at(model, y, b2, l->r2));
    double s[PD_CONTACT_STATE_SIZE], f0[3 + PD_CONTACT_STATE_SIZE], f1[3 + PD_CONTACT_STATE_SIZE];
    for (int j = 0; j < PD_CONTACT_STATE_SIZE; ++j) s[j] = y[base + PD_CONTACT_STATE_SIZE * i + j];
    if (recorded)
      recorded_rates(c, f0);
    else
      force_and_rates(c, set->holdModes, s, c->normal, du, f0);
    for (int j = 0; j < PD_CONTACT_STATE_SIZE; ++j) {
      double keep = s[j];
      s[j] += PD_LINEARISE_STEP_REL * fmax(fabs(keep), c->deltaMax);
      double step = s[j] - keep;
      force_and_rates(c, set->holdModes, s, c->normal, du, f1);
      s[j] = keep;
      for (int r = 0; r < 3; ++r) l->Ds[r][j] = (f1[r] - f0[r]) / step;
      for (int r = 0; r < PD_CONTACT_STATE_SIZE; ++r) l->Gs[r][j] = (f1[3 + r] - f0[3 + r]) / step;
    }
    double u[3] = {du.x, du.y, du.z};
    for (int j = 0; j < 3; ++j) {
      double keep = u[j];
      u[j] += PD_LINEARISE_STEP_REL * fmax(fabs(keep), vmax);
      double step = u[j] - keep;
      force_and_rates(c, set->holdModes, s, c->normal, (pdVec3){u[0], u[1], u[2]}, f1);
      u[j] = keep;
      for (int r = 0; r < 3; ++r) l->Du[r][j] = (f1[r] - f0[r]) / step;
      for (int r = 0; r < PD_CONTACT_STATE_SIZE; ++r) l->Gu[r][j] = (f1[3 + r] - f0[3 + r]) / step;
    }
  }
}

double pd_contact_spring_energy(const pdContactSet* set, const double* y, int springBase) {
  double e = 0.0;
  for (int i = 0; i < set->count; ++i) {
    const pdContactParams* p = &set->items[i].params;
    pdSprings s = springs_load(y + springBase + PD_CONTACT_STATE_SIZE * i);
    e += pd_springs_energy(p, &s);
  }
  return e;
}
