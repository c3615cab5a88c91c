// polydyn refcheck — the Bullet adapter (pd_bullet_adapter): a compiled pdModel run in Bullet through the
// C++ shim (bullet_shim.h).
//
// Frames. Bullet takes a diagonal inertia only, so each body lives in Bullet in its principal frame: origin
// at the centre of mass, axes the columns P of pdBody.principalAxes (a rotation; x_body = P x_principal).
// The hull's vertices are given as Pᵀ x_body; with q_P the quaternion of P, Bullet's orientation is
// q_bullet = q ⊗ q_P and ours is read back as q = q_bullet ⊗ q_P⁻¹. Positions (centre of mass) and
// velocities (world frame) need no conversion.
//
// Material. Every contact point gets its pair's values from pd_model_pair_contact — μ, and e (native) or
// k_n, c_n (matched) — through Bullet's per-contact material callback, exact for every pair; Bullet's own
// combination rules (products of the bodies' friction and restitution, series stiffness, summed damping)
// are not used, so no per-body factorisation is needed.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bullet_shim.h"
#include "pdref/refcheck.h"
#include "pdutil/json.h"

#define PI 3.14159265358979323846

// Bullet limits a body's rotation in one step to a quarter turn (btTransformUtil::integrateTransform,
// ANGULAR_MOTION_THRESHOLD = ½·π/2 rad): a faster initial spin would be silently slowed, so it is refused.
#define BULLET_ANGULAR_MOTION_PER_STEP_MAX (0.25 * PI)

// Pairs listed one by one in the settings (the scene's first ones, in body order); the rest are counted.
enum { LISTED_PAIRS_MAX = 64 };

// Solver settings of each variant (bullet_shim.h; every one is written into the summary).
// Both: 100 solver iterations instead of 10, so a flat landing's four contact points converge to the same
// impulse (with 10, a 0.1 m cube dropped flat from 0.5 m leaves with a spurious 0.07 rad/s spin and tumbles
// on its second bounce). Contact points act only once the hulls overlap (processing threshold 0: Bullet's
// speculative points at a positive distance brake a body before it touches, reference-engines.md §2.5).
// The hull–hull normal comes from GJK/EPA (Bullet's default), not from its separating-axis test: in Bullet
// 3.24 that test adds an edge–edge contact at the edges' witness points when an edge pair's axis ties with
// the face normal to round-off, far from the real contact (measured: an elastic octahedron landing vertex
// first on a cube rebounds with e = 1.22 and spins). The GJK path has its own flaw, smaller: its EPA point
// joins the manifold and can displace a corner of a flat face contact (docs/validation.md, Bullet).
// native: Bullet's rigid contact with Newton restitution (above Bullet's default approach speed of
// 0.2 m/s); every penetration is recovered by the split impulse (threshold 0 instead of −0.04 m), so the
// push-out never adds to the bounce velocity (with −0.04: e 0.545 for 0.5).
static const btsSolverSettings nativeSettings = {
    .iterations = 100,
    .splitImpulse = true,
    .splitImpulsePenetrationThreshold = 0.0,
    .erp2 = 0.2,
    .restitutionVelocityThreshold = 0.2,
    .warmstartingFactor = 0.85,
    .contactProcessingThreshold = 0.0,
    .satConvex = false,
};
// matched: each contact point is a spring-damper (erp = h k/(h k + c), cfm = 1/(h k + c)); its position
// term must act through the velocity, as the spring does, so the split impulse is off.
static const btsSolverSettings matchedSettings = {
    .iterations = 100,
    .splitImpulse = false,
    .splitImpulsePenetrationThreshold = 0.0,
    .erp2 = 0.2,
    .restitutionVelocityThreshold = 0.2,
    .warmstartingFactor = 0.85,
    .contactProcessingThreshold = 0.0,
    .satConvex = false,
};

struct pdRefWorld {
  const pdModel* model;
  pdRefVariant variant;
  btsSolverSettings solver;
  btsWorld* bullet;
  int fixedCount;           // Bullet numbers the fixed bodies first
  pdQuat* principal;        // (movingCount) q_P of each moving body
  pdQuat* last;             // (movingCount) last orientation reported: the next keeps its sign
  long steps;               // steps taken: the step starts at t = steps·h
  int bodiesAdded;          // Bullet's index of the next body added
  int planarBodies;         // bodies held in the x–z plane (bts_hold_in_xz_plane)
  double lastStep;          // s, of the last step: the contacts' impulses over it are their forces
};

static void pair_material(void* user, int a, int b, btsContactMaterial* out) {
  const pdRefWorld* w = user;
  pdPairContact p = pd_model_pair_contact(w->model, a, b);
  out->friction = p.mu;
  if (w->variant == pd_refMatched) {
    out->restitution = 0.0;  // the damper alone decides the bounce
    out->soft = true;
    out->stiffness = p.kn;
    out->damping = p.cn;
  } else {
    out->restitution = p.restitution;
    out->soft = false;
  }
}

// Body b's polyhedron in its principal frame: vertices Pᵀ x, face normals Pᵀ n (offsets unchanged: the
// rotation is about the centre of mass). Free with free_hull.
static btsHull principal_hull(const pdBody* b) {
  const pdPolyhedron* p = &b->shape;
  int indexCount = 0;
  for (int f = 0; f < p->faceCount; ++f) indexCount += p->faces[f].count;
  double* vertices = malloc(sizeof(double) * 3 * (size_t)p->vertexCount);
  double* planes = malloc(sizeof(double) * 4 * (size_t)p->faceCount);
  int* sizes = malloc(sizeof(int) * (size_t)p->faceCount);
  int* indices = malloc(sizeof(int) * (size_t)indexCount);
  if (!vertices || !planes || !sizes || !indices) abort();
  for (int i = 0; i < p->vertexCount; ++i) {
    pdVec3 x = pd_mat3_tmulv(&b->principalAxes, p->vertices[i]);
    vertices[3 * i] = x.x, vertices[3 * i + 1] = x.y, vertices[3 * i + 2] = x.z;
  }
  for (int f = 0, at = 0; f < p->faceCount; ++f) {
    const pdFace* face = &p->faces[f];
    pdVec3 n = pd_mat3_tmulv(&b->principalAxes, face->normal);
    planes[4 * f] = n.x, planes[4 * f + 1] = n.y, planes[4 * f + 2] = n.z, planes[4 * f + 3] = face->offset;
    sizes[f] = face->count;
    for (int k = 0; k < face->count; ++k) indices[at++] = p->faceVertices[face->first + k];
  }
  return (btsHull){.vertexCount = p->vertexCount, .vertices = vertices, .faceCount = p->faceCount, .faceSizes = sizes,
                   .faceVertices = indices, .facePlanes = planes};
}

static void free_hull(btsHull* h) {
  free((void*)h->vertices);
  free((void*)h->facePlanes);
  free((void*)h->faceSizes);
  free((void*)h->faceVertices);
}

static double mat3_det(const pdMat3* m) {
  pdVec3 c0 = {m->m[0][0], m->m[1][0], m->m[2][0]}, c1 = {m->m[0][1], m->m[1][1], m->m[2][1]},
         c2 = {m->m[0][2], m->m[1][2], m->m[2][2]};
  return pd_v3_dot(c0, pd_v3_cross(c1, c2));
}

static pdQuat quat_conjugate(pdQuat q) { return (pdQuat){q.w, -q.x, -q.y, -q.z}; }

// A feature Bullet cannot run as written: fills err at the body's line.
static bool representable(const pdModel* model, const pdRefOptions* options, pdError* err) {
  for (int i = 0; i < model->bodyCount; ++i) {
    const pdBody* b = &model->bodies[i];
    double spin = pd_v3_norm(b->w0);
    if (!b->fixed && spin * options->step > BULLET_ANGULAR_MOTION_PER_STEP_MAX) {
      pd_error_set(err, model->scenePath, b->where.line, b->where.col,
                   "bullet: body '%s' spins at %.6g rad/s, but Bullet turns a body by at most pi/4 rad per step "
                   "(%.6g rad/s at step %g s) and would slow it silently; use --step %.3g or less",
                   b->name, spin, BULLET_ANGULAR_MOTION_PER_STEP_MAX / options->step, options->step,
                   BULLET_ANGULAR_MOTION_PER_STEP_MAX / spin);
      return false;
    }
  }
  return true;
}

static pdRefWorld* bullet_create(const pdModel* model, const pdRefOptions* options, pdError* err) {
  PD_ASSERT(model && options && options->step > 0.0);
  if (!representable(model, options, err)) return NULL;
  pdRefWorld* w = calloc(1, sizeof *w);
  if (!w) abort();
  w->model = model;
  w->variant = options->variant;
  w->solver = options->variant == pd_refMatched ? matchedSettings : nativeSettings;
  if (options->iterations > 0) w->solver.iterations = options->iterations;  // work-precision over the solver
  w->principal = calloc((size_t)model->movingCount + 1, sizeof *w->principal);
  w->last = calloc((size_t)model->movingCount + 1, sizeof *w->last);
  if (!w->principal || !w->last) abort();
  const double gravity[3] = {model->settings.gravity.x, model->settings.gravity.y, model->settings.gravity.z};
  w->bullet = bts_world_create(gravity, &w->solver, pair_material, w);

  // Fixed bodies first: Bullet's hull–hull clipping takes the first-added body's face as the reference
  // face, and a vertex landing on a fixed face is placed right only when that face is the reference (see
  // docs/validation.md (Bullet): with the order reversed, an octahedron dropped vertex first gets its contact point off the
  // vertex and spins). Then the moving bodies in scene order: Bullet body fixedCount + moving index.
  w->fixedCount = model->bodyCount - model->movingCount;
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 0; i < model->bodyCount; ++i) {
      const pdBody* b = &model->bodies[i];
      if (b->fixed != (pass == 0)) continue;
      PD_ASSERT(mat3_det(&b->principalAxes) > 0.0);
      pdQuat qP = pd_quat_from_mat3(&b->principalAxes);
      pdQuat q = pd_quat_mul(b->q0, qP);
      btsHull hull = principal_hull(b);
      const double x[3] = {b->x0.x, b->x0.y, b->x0.z}, quat[4] = {q.w, q.x, q.y, q.z};
      const double v[3] = {b->v0.x, b->v0.y, b->v0.z}, omega[3] = {b->w0.x, b->w0.y, b->w0.z};
      const double none[3] = {0.0, 0.0, 0.0};
      bts_add_hull(w->bullet, i, &hull, b->fixed ? 0.0 : b->mass, b->fixed ? none : b->principal, x, quat, v, omega);
      free_hull(&hull);
      if (b->planar) {
        bts_hold_in_xz_plane(w->bullet, w->bodiesAdded);
        ++w->planarBodies;
      }
      ++w->bodiesAdded;
      if (!b->fixed) {
        w->principal[b->stateIndex] = qP;
        w->last[b->stateIndex] = b->q0;
      }
    }
  }
  return w;
}

// The scene's applied forces for the step from t = steps·h: F at mid-step (refcheck.h), at the force point
// turned into the world (R p from the centre of mass, as btRigidBody::applyForce takes it). Bullet clears
// its force accumulators at the end of every stepSimulation.
static void apply_forces(pdRefWorld* w, double h) {
  double tMid = ((double)w->steps + 0.5) * h;  // s
  for (int i = 0; i < w->model->movingCount; ++i) {
    const pdBody* body = &w->model->bodies[w->model->movingBodies[i]];
    if (!body->hasForce) continue;
    double x[3], q[4], v[3], omega[3];
    bts_body_state(w->bullet, w->fixedCount + i, x, q, v, omega);
    // Bullet's orientation is of the principal frame; R p is the same vector either way: rotate the
    // principal-frame point by q_bullet
    pdQuat qb = {q[0], q[1], q[2], q[3]};
    pdVec3 r = pd_quat_rotate(qb, pd_quat_rotate(quat_conjugate(w->principal[i]), body->forcePoint));
    pdVec3 f = pd_body_applied_force(body, tMid);
    const double force[3] = {f.x, f.y, f.z}, at[3] = {r.x, r.y, r.z};
    bts_apply_force(w->bullet, w->fixedCount + i, force, at);
  }
}

static bool bullet_step(pdRefWorld* w, double h) {
  apply_forces(w, h);
  w->lastStep = h;
  bts_step(w->bullet, h);
  ++w->steps;
  for (int i = 0; i < w->model->movingCount; ++i) {
    double x[3], q[4], v[3], omega[3];
    bts_body_state(w->bullet, w->fixedCount + i, x, q, v, omega);
    for (int k = 0; k < 3; ++k)
      if (!isfinite(x[k]) || !isfinite(v[k]) || !isfinite(omega[k]) || !isfinite(q[k + 1])) return false;
    if (!isfinite(q[0])) return false;
  }
  return true;
}

static pdBodyState bullet_body(const pdRefWorld* w, int movingIndex) {
  PD_ASSERT(movingIndex >= 0 && movingIndex < w->model->movingCount);
  double x[3], q[4], v[3], omega[3];
  bts_body_state(w->bullet, w->fixedCount + movingIndex, x, q, v, omega);
  pdQuat ours = pd_quat_mul((pdQuat){q[0], q[1], q[2], q[3]}, quat_conjugate(w->principal[movingIndex]));
  // q and −q are the same rotation; Bullet keeps a matrix and may return either, so keep the trajectory's sign
  pdQuat prev = w->last[movingIndex];
  if (ours.w * prev.w + ours.x * prev.x + ours.y * prev.y + ours.z * prev.z < 0.0)
    ours = (pdQuat){-ours.w, -ours.x, -ours.y, -ours.z};
  w->last[movingIndex] = ours;
  return (pdBodyState){
      .x = {x[0], x[1], x[2]}, .q = ours, .v = {v[0], v[1], v[2]}, .w = {omega[0], omega[1], omega[2]}};
}

static int bullet_contact_count(const pdRefWorld* w) { return bts_contact_count(w->bullet); }

static int bullet_contacts(const pdRefWorld* w, pdContactReport* out, int capacity) {
  btsContact* points = capacity > 0 ? calloc((size_t)capacity, sizeof *points) : NULL;
  if (capacity > 0 && !points) abort();
  int count = bts_contacts(w->bullet, w->lastStep, points, capacity);
  for (int i = 0; i < count && i < capacity; ++i) {
    const btsContact* c = &points[i];
    pdVec3 n = {c->normal[0], c->normal[1], c->normal[2]}, ft = {c->ft[0], c->ft[1], c->ft[2]};
    out[i] = (pdContactReport){.bodyA = c->a, .bodyB = c->b, .featureA = -1, .featureB = -1,
                               .point = {c->point[0], c->point[1], c->point[2]}, .normal = n, .fn = c->fn,
                               .ft = pd_v3_sub(ft, pd_v3_scale(n, pd_v3_dot(ft, n)))};
  }
  free(points);
  return count;
}

// Every pair that can touch (not both fixed), with the values its contacts get.
static void write_pairs(const pdRefWorld* w, FILE* out) {
  const pdModel* m = w->model;
  long total = 0;
  fputs("\"pairs\": [", out);
  for (int a = 0; a < m->bodyCount; ++a) {
    for (int b = a + 1; b < m->bodyCount; ++b) {
      if (m->bodies[a].fixed && m->bodies[b].fixed) continue;
      if (total++ >= LISTED_PAIRS_MAX) continue;
      pdPairContact p = pd_model_pair_contact(m, a, b);
      fputs(total > 1 ? ", {\"a\": " : "{\"a\": ", out);
      pdu_json_string(out, m->bodies[a].name);
      fputs(", \"b\": ", out);
      pdu_json_string(out, m->bodies[b].name);
      fprintf(out, ", \"mu\": %.17g", p.mu);
      if (w->variant == pd_refMatched)
        fprintf(out, ", \"stiffness\": %.17g, \"damping\": %.17g}", p.kn, p.cn);
      else
        fprintf(out, ", \"restitution\": %.17g, \"restitution_source\": \"%s\"}", p.restitution, p.restitutionSource);
    }
  }
  fprintf(out, "], \"pairs_total\": %ld, \"pairs_listed\": %ld", total,
          total < LISTED_PAIRS_MAX ? total : (long)LISTED_PAIRS_MAX);
}

static void bullet_settings_json(const pdRefWorld* w, FILE* out) {
  btsSolverInfo info;
  bts_solver_info(w->bullet, &info);
  const btsSolverSettings* s = &info.settings;
  const pdVec3 g = w->model->settings.gravity;
  fprintf(out,
          "{\"precision\": \"double (bullet-float64)\", \"world\": \"btDiscreteDynamicsWorld, btDbvtBroadphase, "
          "btDefaultCollisionConfiguration\", \"step_call\": \"stepSimulation(h, 0): one internal step of h\", "
          "\"integrator\": \"semi-implicit Euler; gyroscopic term implicit (Bullet default)\", "
          "\"gravity\": [%.17g, %.17g, %.17g], "
          "\"shape\": \"btConvexHullShape of the model's vertices in the principal frame, recalcLocalAabb; "
          "polyhedral features from the model's exact faces (setPolyhedralFeatures, not "
          "initializePolyhedralFeatures): hull-hull contacts by clipping, up to 4 points\", \"margin\": 0, "
          "\"sat_convex\": %s, \"body_order\": \"fixed bodies first (the clipping's reference face), then "
          "moving bodies in scene order\", \"manifold_points_max\": 4, "
          "\"inertia\": \"exact principal moments of the model (not calculateLocalInertia)\", "
          "\"fixed_bodies\": \"static btRigidBody, mass 0\", \"deactivation\": false, \"ccd\": false, "
          "\"linear_damping\": 0, \"angular_damping\": 0, \"angular_motion_per_step_max\": %.17g, "
          "\"solver\": \"btSequentialImpulseConstraintSolver\", \"solver_mode\": %d, \"iterations\": %d, "
          "\"sor\": %.17g, \"erp2\": %.17g, \"global_cfm\": %.17g, \"linear_slop\": %.17g, "
          "\"split_impulse\": %s, \"split_impulse_penetration_threshold\": %.17g, "
          "\"split_impulse_turn_erp\": %.17g, \"restitution_velocity_threshold\": %.17g, "
          "\"warmstarting_factor\": %.17g, \"contact_processing_threshold\": %.17g, "
          "\"contact_breaking_threshold\": \"%.17g x each shape's angular motion disc\", "
          "\"friction\": \"rigid Coulomb, the pair's mu; %d friction row(s) per contact point, along the slip "
          "velocity; tangential springs kt, ct not represented\", "
          "\"material\": \"per contact point from pd_model_pair_contact (gContactAddedCallback, "
          "CF_CUSTOM_MATERIAL_CALLBACK); Bullet's product, series and sum rules unused\", ",
          g.x, g.y, g.z, s->satConvex ? "true" : "false", BULLET_ANGULAR_MOTION_PER_STEP_MAX, info.solverMode,
          s->iterations, info.sor, s->erp2, info.globalCfm, info.linearSlop, s->splitImpulse ? "true" : "false",
          s->splitImpulsePenetrationThreshold, info.splitImpulseTurnErp, s->restitutionVelocityThreshold,
          s->warmstartingFactor, s->contactProcessingThreshold, info.contactBreakingThreshold,
          info.frictionDirections);
  if (w->variant == pd_refMatched)
    fputs("\"normal_contact\": \"spring-damper per contact point: stiffness = pair kn, damping = pair cn, "
          "erp = h k/(h k + c), cfm = 1/(h k + c); restitution 0 (the damping alone gives the bounce)\", ",
          out);
  else
    fputs("\"normal_contact\": \"rigid; Newton restitution = pair e above the velocity threshold\", ", out);
  if (pd_model_has_applied_force(w->model))
    fputs("\"applied_force_call\": \"btRigidBody::applyForce (world force, world-oriented R p from the centre of "
          "mass) before stepSimulation\", ",
          out);
  if (w->planarBodies)
    fprintf(out, "\"planar_bodies\": %d, \"planar_constraint\": \"setLinearFactor(1, 0, 1), setAngularFactor(0, 1, "
                 "0)\", ", w->planarBodies);
  write_pairs(w, out);
  fputc('}', out);
}

static void bullet_destroy(pdRefWorld* w) {
  if (!w) return;
  bts_world_destroy(w->bullet);
  free(w->principal);
  free(w->last);
  free(w);
}

const pdRefAdapter pd_bullet_adapter = {
    .name = "bullet",
    .version = bts_version_string,
    .create = bullet_create,
    .step = bullet_step,
    .body = bullet_body,
    .contact_count = bullet_contact_count,
    .contacts = bullet_contacts,
    .settings_json = bullet_settings_json,
    .destroy = bullet_destroy,
};
