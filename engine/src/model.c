// polydyn — compiling a scene description into a read-only model.
#include "polydyn/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "polydyn/state.h"

// The characteristic speed never drops below one body length per second: it weights velocity
// errors, and a scene at rest without gravity would otherwise have no velocity scale at all.
#define PD_MIN_SPEED_LENGTHS_PER_SECOND 1.0

static char* copy_string(const char* s) {
  size_t n = strlen(s) + 1;
  char* c = malloc(n);
  PD_ASSERT(c != NULL);
  memcpy(c, s, n);
  return c;
}

static bool build_shape(const pdSceneObject* o, pdPolyhedron* shape, char* why, int whySize) {
  switch (o->kind) {
    case pd_primCube:
      return pd_polyhedron_cube(shape, o->scale, why, whySize);
    case pd_primPrism:
      return pd_polyhedron_prism(shape, o->n, o->scale, 1.0, why, whySize);
    case pd_primTprism:
      return pd_polyhedron_prism(shape, o->n, o->scale, o->taper, why, whySize);
    case pd_primSphere:
      return pd_polyhedron_sphere(shape, o->n, o->scale, why, whySize);
    case pd_primHull:
      return pd_polyhedron_hull(shape, o->points, o->pointCount, why, whySize);
  }
  return false;
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
}

static pdMaterial requested_material(const pdSceneObject* o) {
  return (pdMaterial){
      .mu = o->mu,
      .kn = o->kn,
      .kt = o->kt,
      .cn = o->cn,
      .ct = o->ct,
      .restitution = (o->setMask & PD_SET_RESTITUTION) ? o->restitution : -1.0,
  };
}

// Characteristic speed when the scene gives no vmax: the fastest initial surface speed combined
// with the speed of a fall through the scene's whole extent along gravity.
static double estimate_vmax(const pdModel* m) {
  double g = pd_v3_norm(m->settings.gravity);
  pdVec3 down = g > 0.0 ? pd_v3_scale(m->settings.gravity, 1.0 / g) : (pdVec3){0, 0, -1};
  double lowest = INFINITY, highest = -INFINITY, fastest = 0.0;
  for (int i = 0; i < m->bodyCount; ++i) {
    const pdBody* b = &m->bodies[i];
    double h = -pd_v3_dot(down, b->x0);
    lowest = fmin(lowest, h - b->radius);
    highest = fmax(highest, h + b->radius);
    if (!b->fixed) fastest = fmax(fastest, pd_v3_norm(b->v0) + pd_v3_norm(b->w0) * b->radius);
  }
  double drop = m->bodyCount > 0 ? highest - lowest : 0.0;
  return sqrt(fastest * fastest + 2.0 * g * drop);
}

pdModel* pd_model_compile(const pdScene* scene, pdError* err) {
  if (scene->objectCount == 0) {
    pd_error_set(err, scene->path, 0, 0, "the scene defines no object");
    return NULL;
  }
  pdModel* m = calloc(1, sizeof *m);
  PD_ASSERT(m != NULL);
  m->scenePath = copy_string(scene->path);
  m->bodyCount = scene->objectCount;
  m->bodies = calloc((size_t)m->bodyCount, sizeof *m->bodies);
  m->movingBodies = calloc((size_t)m->bodyCount, sizeof *m->movingBodies);
  PD_ASSERT(m->bodies != NULL && m->movingBodies != NULL);

  for (int i = 0; i < scene->objectCount; ++i) {
    const pdSceneObject* o = &scene->objects[i];
    pdBody* b = &m->bodies[i];
    b->name = copy_string(o->name);
    b->color = copy_string(o->color);
    b->kind = o->kind;
    b->fixed = o->fixed;
    b->where = o->where;
    b->density = 1000.0 * o->spgrav;

    char why[256] = "";
    pdMassProperties mp;
    if (!build_shape(o, &b->shape, why, sizeof why) || !pd_mass_properties(&b->shape, b->density, &mp, why, sizeof why)) {
      pd_error_set(err, scene->path, o->where.line, o->where.col, "object '%s': %s", o->name, why);
      pd_model_free(m);
      return NULL;
    }
    // body frame: origin at the centre of mass, axes of the object's own frame
    pd_polyhedron_translate(&b->shape, pd_v3_scale(mp.centroid, -1.0));
    b->geometricCentre = pd_v3_scale(mp.centroid, -1.0);
    b->volume = mp.volume;
    b->mass = mp.mass;
    b->inertia = mp.inertia;
    memcpy(b->principal, mp.principal, sizeof b->principal);
    b->principalAxes = mp.principalAxes;
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
    b->requested = requested_material(o);
    b->used = b->requested;
  }

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
  };
  if (s->setMask & PD_SET_VMAX) {
    m->settings.vmax = s->vmax;
  } else {
    m->settings.vmax = fmax(estimate_vmax(m), PD_MIN_SPEED_LENGTHS_PER_SECOND * m->lengthScale);
    m->settings.vmaxEstimated = true;
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
