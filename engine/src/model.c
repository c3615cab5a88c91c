// polydyn — compiling a scene description into a read-only model.
#include "polydyn/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "broad_phase.h"
#include "grow.h"
#include "interference.h"
#include "model_contact.h"
#include "polydyn/state.h"
#include "scene_shape.h"

// The characteristic speed never drops below one length per second of the largest MOVING body: it weights
// velocity errors, and a scene at rest without gravity would otherwise have no velocity scale at all
// (a fixed floor's size says nothing about how fast anything moves).
#define PD_MIN_SPEED_LENGTHS_PER_SECOND 1.0

// Bodies may touch at t = 0 but not interpenetrate (docs/scene-language.md): a soft contact that starts deep would
// begin with springs at rest and push nothing. Tolerance on the penetration depth, relative to the
// smaller body's size: two bodies placed touching by decimal coordinates overlap by rounding only
// (~1e-16 relative), while 1e-6 leaves room for a scene file written with 6 significant digits.
#define PD_INITIAL_OVERLAP_TOL_REL 1e-6

static char* copy_string(const char* s) {
  size_t n = strlen(s) + 1;
  char* c = pd_grow(NULL, n, 1);
  memcpy(c, s, n);
  return c;
}

bool pd_scene_object_shape(const pdSceneObject* o, pdPolyhedron* shape, pdError* why) {
  switch (o->kind) {
    case pd_primCube:
      return pd_polyhedron_cube(shape, o->scale, why);
    case pd_primPrism:
      return pd_polyhedron_prism(shape, o->n, o->scale, 1.0, why);
    case pd_primTprism:
      return pd_polyhedron_prism(shape, o->n, o->scale, o->taper, why);
    case pd_primSphere:
      return pd_polyhedron_sphere(shape, o->n, o->scale, why);
    case pd_primHull:
      return pd_polyhedron_hull(shape, o->points, o->pointCount, why);
  }
  return false;
}

// Do two objects give the same body shape and density, number for number: the same polyhedron (qhull is
// deterministic) and the same mass properties? A pile of equal boxes builds its hull once.
static bool same_shape_definition(const pdSceneObject* a, const pdSceneObject* b) {
  return a->kind == b->kind && a->n == b->n && memcmp(a->scale, b->scale, sizeof a->scale) == 0 &&
         memcmp(&a->taper, &b->taper, sizeof a->taper) == 0 && memcmp(&a->spgrav, &b->spgrav, sizeof a->spgrav) == 0 &&
         a->pointCount == b->pointCount &&
         (a->pointCount == 0 || memcmp(a->points, b->points, 3 * (size_t)a->pointCount * sizeof *a->points) == 0);
}

static pdMat3 inverse_spd(const pdMat3* a) {
  // inverse by cofactors; a is symmetric positive definite (checked by the mass properties)
  const double(*m)[3] = a->m;
  pdMat3 c;
  c.m[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  c.m[0][1] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
  c.m[0][2] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  c.m[1][0] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  c.m[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
  c.m[1][2] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
  c.m[2][0] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  c.m[2][1] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
  c.m[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  double det = m[0][0] * c.m[0][0] + m[0][1] * c.m[1][0] + m[0][2] * c.m[2][0];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.m[i][j] /= det;
  return c;
}

static void measure_extents(pdBody* b) {
  pdVec3 lo = b->shape.vertices[0], hi = lo;
  double radius = 0.0;
  for (int v = 0; v < b->shape.vertexCount; ++v) {
    pdVec3 p = b->shape.vertices[v];
    lo = (pdVec3){fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z)};
    hi = (pdVec3){fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z)};
    radius = fmax(radius, pd_v3_norm(p));
  }
  b->size = ((hi.x - lo.x) + (hi.y - lo.y) + (hi.z - lo.z)) / 3.0;
  b->halfExtents = (pdVec3){fmax(-lo.x, hi.x), fmax(-lo.y, hi.y), fmax(-lo.z, hi.z)};
  b->radius = radius;
  // thinnest width: the smallest extent of the vertices along a face normal
  double width = INFINITY;
  for (int f = 0; f < b->shape.faceCount; ++f) {
    double lowest = INFINITY, highest = -INFINITY;
    for (int v = 0; v < b->shape.vertexCount; ++v) {
      double d = pd_v3_dot(b->shape.faces[f].normal, b->shape.vertices[v]);
      lowest = fmin(lowest, d), highest = fmax(highest, d);
    }
    width = fmin(width, highest - lowest);
  }
  b->width = width;
}

// What the file said; -1 for a constant it did not set (cn 0 is a request: no normal damper).
static pdMaterial requested_material(const pdSceneObject* o) {
  return (pdMaterial){
      .mu = o->mu,
      .kn = (o->setMask & PD_SET_KN) ? o->kn : -1.0,
      .kt = (o->setMask & PD_SET_KT) ? o->kt : -1.0,
      .cn = (o->setMask & PD_SET_CN) ? o->cn : -1.0,
      .ct = (o->setMask & PD_SET_CT) ? o->ct : -1.0,
      .restitution = (o->setMask & PD_SET_RESTITUTION) ? o->restitution : -1.0,
  };
}

// Characteristic speed when the scene gives no vmax: the fastest initial surface speed combined with the
// speed of a fall from the highest point of a moving body down to the lowest place it can land on — the
// lowest point of a moving body, or the lowest point of a fixed body's upper surface (its faces that face
// up). A fixed body's own depth does not count: a 1 m thick floor is not a 1 m drop (sizing the springs
// for it made them 60 times too stiff for a cube sliding on such a floor).
static double estimate_vmax(const pdModel* m) {
  double g = pd_v3_norm(m->settings.gravity);
  pdVec3 down = g > 0.0 ? pd_v3_scale(m->settings.gravity, 1.0 / g) : (pdVec3){0, 0, -1};
  double lowest = INFINITY, highest = -INFINITY, fastest = 0.0;
  for (int i = 0; i < m->bodyCount; ++i) {
    const pdBody* b = &m->bodies[i];
    pdMat3 r = pd_quat_to_mat3(b->q0);
    pdVec3 upBody = pd_mat3_tmulv(&r, pd_v3_scale(down, -1.0));  // "up" in the body frame
    double centre = -pd_v3_dot(down, b->x0);
    if (!b->fixed) {
      double lo = INFINITY, hi = -INFINITY;
      for (int v = 0; v < b->shape.vertexCount; ++v) {
        double h = centre + pd_v3_dot(upBody, b->shape.vertices[v]);
        lo = fmin(lo, h), hi = fmax(hi, h);
      }
      lowest = fmin(lowest, lo);
      highest = fmax(highest, hi);
      fastest = fmax(fastest, pd_v3_norm(b->v0) + pd_v3_norm(b->w0) * b->radius);
      continue;
    }
    for (int f = 0; f < b->shape.faceCount; ++f) {
      const pdFace* face = &b->shape.faces[f];
      if (pd_v3_dot(face->normal, upBody) <= 0.0) continue;
      for (int k = 0; k < face->count; ++k) {
        pdVec3 v = b->shape.vertices[b->shape.faceVertices[face->first + k]];
        lowest = fmin(lowest, centre + pd_v3_dot(upBody, v));
      }
    }
  }
  double drop = isfinite(highest) && isfinite(lowest) ? fmax(0.0, highest - lowest) : 0.0;
  return sqrt(fastest * fastest + 2.0 * g * drop);
}

// Refuses the scene when two bodies (at least one moving) interpenetrate at their initial poses by more
// than PD_INITIAL_OVERLAP_TOL_REL of the smaller one's size. Box-overlapping pairs come from the broad
// phase (~n log n for n bodies), each tested with the exact SAT depth. Of several overlapping pairs the
// one whose later body comes first in the file is reported, at that body's object line.
static bool check_initial_overlap(const pdModel* m, pdError* err) {
  const int n = m->bodyCount;
  bool* fixed = calloc((size_t)n, sizeof *fixed);
  pdAabb* boxes = calloc((size_t)n, sizeof *boxes);
  pdMat3* rotation = calloc((size_t)n, sizeof *rotation);
  PD_ASSERT(fixed != NULL && boxes != NULL && rotation != NULL);
  for (int i = 0; i < n; ++i) {
    const pdBody* b = &m->bodies[i];
    fixed[i] = b->fixed;
    rotation[i] = pd_quat_to_mat3(b->q0);
    boxes[i] = pd_aabb_of(&b->shape, b->x0, &rotation[i]);
  }
  pdBroadPhase* bp = pd_broad_phase_create(n, fixed, 0.0);
  PD_ASSERT(bp != NULL);
  bool ok = pd_broad_phase_update(bp, boxes);
  int count = ok ? pd_broad_phase_pairs(bp, NULL, 0) : 0;
  pdPair* pairs = ok ? malloc((size_t)(count > 0 ? count : 1) * sizeof *pairs) : NULL;
  ok = ok && pairs != NULL;
  if (!ok) {
    // memory for the pairs grows with the pairs found: only a scene piling very many bodies into one
    // place gets here
    pd_error_set(err, m->scenePath, 0, 0, "too many pairs of bodies with overlapping boxes at t = 0 to check");
  } else {
    count = pd_broad_phase_pairs(bp, pairs, count);
    int worstA = -1, worstB = -1;
    double worstDepth = 0.0, worstTol = 0.0;
    for (int k = 0; k < count; ++k) {
      int a = pairs[k].a, b = pairs[k].b;
      if (worstB >= 0 && (b > worstB || (b == worstB && a > worstA))) continue;  // a later line is not reported
      const pdBody *A = &m->bodies[a], *B = &m->bodies[b];
      pdSatResult r;
      pd_interference(&A->shape, A->x0, &rotation[a], &B->shape, B->x0, &rotation[b], PD_SAT_MIN_DEPTH, NULL, &r);
      double tol = PD_INITIAL_OVERLAP_TOL_REL * fmin(A->size, B->size);
      if (r.depth > tol) worstA = a, worstB = b, worstDepth = r.depth, worstTol = tol;
    }
    if (worstB >= 0) {
      const pdBody* B = &m->bodies[worstB];
      pd_error_set(err, m->scenePath, B->where.line, B->where.col,
                   "bodies '%s' and '%s' overlap by %.6g m at t = 0 (tolerance %.3g m)", m->bodies[worstA].name,
                   B->name, worstDepth, worstTol);
      ok = false;
    }
  }
  free(pairs);
  pd_broad_phase_free(bp);
  free(fixed);
  free(boxes);
  free(rotation);
  return ok;
}

// A planar body's out-of-plane inertia coupling and initial velocity, relative to its largest principal
// moment and to its speed scale: the scene's numbers are exact in the common cases (a box turned about y) and
// reach this only through round-off of the rotation (about 1e-16); anything larger is a different scene.
#define PLANAR_TOL 1e-12

// Checks a `planar` body (model.h) and makes its initial velocity exactly planar.
static bool make_planar(pdBody* b, const pdSceneObject* o, const char* path, pdError* err) {
  PD_ASSERT(!b->fixed);
  pdMat3 r = pd_quat_to_mat3(b->q0);
  pdVec3 yb = pd_mat3_tmulv(&r, (pdVec3){0, 1, 0});  // world y in body axes
  pdVec3 iy = pd_mat3_mulv(&b->inertia, yb);
  pdVec3 off = pd_v3_sub(iy, pd_v3_scale(yb, pd_v3_dot(yb, iy)));
  if (pd_v3_norm(off) > PLANAR_TOL * b->principal[2]) {
    pd_error_set(err, path, o->planarWhere.line, o->planarWhere.col,
                 "planar body '%s': world y is not a principal axis of its inertia at its initial orientation (turn it "
                 "so that one of its principal axes is along y)", o->name);
    return false;
  }
  double speed = pd_v3_norm(b->v0) + pd_v3_norm(b->w0) * b->radius;
  if (fabs(b->v0.y) > PLANAR_TOL * speed || hypot(b->w0.x, b->w0.z) * b->radius > PLANAR_TOL * speed) {
    pd_error_set(err, path, o->planarWhere.line, o->planarWhere.col,
                 "planar body '%s': its initial velocity leaves the x-z plane (v_y = %g m/s, spin about x, z = %g, %g "
                 "rad/s)", o->name, b->v0.y, b->w0.x, b->w0.z);
    return false;
  }
  b->v0.y = 0.0;
  b->w0.x = b->w0.z = 0.0;
  b->planar = true;
  return true;
}

pdModel* pd_model_compile(const pdScene* scene, pdError* err) {
  if (scene->objectCount == 0) {
    pd_error_set(err, scene->path, 0, 0, "the scene defines no object");
    return NULL;
  }
  pdModel* m = pd_zeroed(1, sizeof *m);
  m->scenePath = copy_string(scene->path);
  m->bodyCount = scene->objectCount;
  m->bodies = pd_zeroed((size_t)m->bodyCount, sizeof *m->bodies);
  m->movingBodies = pd_zeroed((size_t)m->bodyCount, sizeof *m->movingBodies);
  // the objects whose shapes were built (not copied), latest last, and every body's mass properties
  int* built = pd_zeroed((size_t)m->bodyCount, sizeof *built);
  int builtCount = 0;
  pdMassProperties* massProperties = pd_zeroed((size_t)m->bodyCount, sizeof *massProperties);

  for (int i = 0; i < scene->objectCount; ++i) {
    const pdSceneObject* o = &scene->objects[i];
    pdBody* b = &m->bodies[i];
    b->name = copy_string(o->name);
    b->color = copy_string(o->color);
    b->kind = o->kind;
    b->fixed = o->fixed;
    b->where = o->where;
    b->density = 1000.0 * o->spgrav;

    int same = builtCount - 1;
    while (same >= 0 && !same_shape_definition(&scene->objects[built[same]], o)) --same;
    pdMassProperties* mp = &massProperties[i];
    b->shapeTwin = same >= 0 ? built[same] : -1;
    if (same >= 0) {
      pd_polyhedron_copy(&b->shape, &m->bodies[built[same]].shape);
      *mp = massProperties[built[same]];
    } else {
      pdError why = {0};
      if (!pd_scene_object_shape(o, &b->shape, &why) || !pd_mass_properties(&b->shape, b->density, mp, &why)) {
        pd_error_set(err, scene->path, o->where.line, o->where.col, "object '%s': %s", o->name, why.message);
        free(built);
        free(massProperties);
        pd_model_free(m);
        return NULL;
      }
      // body frame: origin at the centre of mass, axes of the object's own frame
      pd_polyhedron_translate(&b->shape, pd_v3_scale(mp->centroid, -1.0));
      built[builtCount++] = i;
    }
    b->geometricCentre = pd_v3_scale(mp->centroid, -1.0);
    b->volume = mp->volume;
    b->mass = mp->mass;
    b->inertia = mp->inertia;
    memcpy(b->principal, mp->principal, sizeof b->principal);
    b->principalAxes = mp->principalAxes;
    if (b->fixed) {
      b->stateIndex = -1;
    } else {
      b->stateIndex = m->movingCount;
      m->movingBodies[m->movingCount++] = i;
      b->invMass = 1.0 / b->mass;
      b->invInertia = inverse_spd(&b->inertia);
    }
    measure_extents(b);
    m->lengthScale = fmax(m->lengthScale, b->size);

    b->x0 = (pdVec3){o->loc[0], o->loc[1], o->loc[2]};
    pdVec3 locAxis = {o->locAxis[0], o->locAxis[1], o->locAxis[2]};
    b->q0 = o->locAngle != 0.0 ? pd_quat_from_axis_angle(locAxis, o->locAngle) : pd_quat_identity();
    if (!b->fixed) {
      b->v0 = (pdVec3){o->vel[0], o->vel[1], o->vel[2]};
      pdVec3 spinAxis = pd_v3_normalize((pdVec3){o->spinAxis[0], o->spinAxis[1], o->spinAxis[2]});
      b->w0 = o->spin != 0.0 ? pd_quat_rotate(b->q0, pd_v3_scale(spinAxis, o->spin)) : (pdVec3){0, 0, 0};
    }
    if ((o->setMask & PD_SET_PLANAR) && !make_planar(b, o, scene->path, err)) {
      free(built);
      free(massProperties);
      pd_model_free(m);
      return NULL;
    }
    b->requested = requested_material(o);
    b->used = b->requested;
    // the parser refuses a force on a fixed body
    PD_ASSERT(!(b->fixed && (o->setMask & PD_SET_FORCE)));
    if (o->setMask & PD_SET_FORCE) {
      b->hasForce = true;
      b->force0 = (pdVec3){o->force[0], o->force[1], o->force[2]};
      b->forceRate = (pdVec3){o->forceRate[0], o->forceRate[1], o->forceRate[2]};
      b->forcePoint = (pdVec3){o->forcePoint[0], o->forcePoint[1], o->forcePoint[2]};
    }
  }

  free(built);
  free(massProperties);

  const pdSceneSettings* s = &scene->settings;
  m->settings = (pdSettings){
      .gravity = {s->gravity[0], s->gravity[1], s->gravity[2]},
      .tend = s->tend,
      .tol = s->tol,
      .dt = s->dt,
      .dtmin = s->dtmin,
      .dtmax = s->dtmax,
      .sampleRate = s->sample,
      .deflection = s->deflection,
      .sleep = s->sleep,
  };
  // a scene without `dtmax` gets the cap of its tolerance, which the scene's last `tol` decides
  if (!(s->setMask & PD_SET_DTMAX)) m->settings.dtmax = pd_default_dtmax(s->tol);
  if (s->setMask & PD_SET_VMAX) {
    m->settings.vmax = s->vmax;
  } else {
    double movingScale = 0.0;
    for (int i = 0; i < m->bodyCount; ++i)
      if (!m->bodies[i].fixed) movingScale = fmax(movingScale, m->bodies[i].size);
    if (movingScale == 0.0) movingScale = m->lengthScale;
    m->settings.vmax = fmax(estimate_vmax(m), PD_MIN_SPEED_LENGTHS_PER_SECOND * movingScale);
    m->settings.vmaxEstimated = true;
  }
  if (!pd_model_build_materials(m, scene, err) || !check_initial_overlap(m, err)) {
    pd_model_free(m);
    return NULL;
  }
  return m;
}

void pd_model_free(pdModel* m) {
  if (!m) return;
  for (int i = 0; i < m->bodyCount; ++i) {
    free((char*)m->bodies[i].name);
    free((char*)m->bodies[i].color);
    pd_polyhedron_free(&m->bodies[i].shape);
  }
  pd_material_table_free(m->materials);
  free(m->bodies);
  free(m->movingBodies);
  free(m->scenePath);
  free(m);
}

double pd_body_kinetic_energy(const pdBody* b, pdVec3 v, pdVec3 w, pdQuat q) {
  pdMat3 r = pd_quat_to_mat3(q);
  pdVec3 wb = pd_mat3_tmulv(&r, w);
  pdVec3 lb = pd_mat3_mulv(&b->inertia, wb);
  return 0.5 * b->mass * pd_v3_dot(v, v) + 0.5 * pd_v3_dot(wb, lb);
}
