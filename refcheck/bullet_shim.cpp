// polydyn refcheck — the extern "C" shim over Bullet (see bullet_shim.h). Kept small: a world, hull bodies,
// one step, read-back, a contact count. Traps of Debian's Bullet 3.24 that it handles
// (shared/reference/reference-engines.md §2): margin 0 with recalcLocalAabb, polyhedral features (from the
// model's exact faces) for a 4-point hull–hull manifold, exact principal inertia (never
// calculateLocalInertia), gravity set, stepSimulation(h, 0), deactivation off, the pair material set per
// contact point.
#include "bullet_shim.h"

#include <BulletCollision/CollisionShapes/btConvexPolyhedron.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <mutex>
#include <vector>

struct btsWorld {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld dynamics{&dispatcher, &broadphase, &solver, &configuration};
  std::vector<std::unique_ptr<btConvexHullShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  btsMaterialFcn* material;
  void* user;
  btsSolverSettings settings;  // as created (the processing threshold is given to every body)
};

// Every contact point Bullet adds or refreshes (btManifoldResult::addContactPoint) gets its pair's material
// here, replacing Bullet's combination rules. The world is found through the body's user pointer, so one
// process-wide callback serves every world.
static bool contact_added(btManifoldPoint& cp, const btCollisionObjectWrapper* wrapA, int, int,
                          const btCollisionObjectWrapper* wrapB, int, int) {
  const btCollisionObject* a = wrapA->getCollisionObject();
  const btCollisionObject* b = wrapB->getCollisionObject();
  btsWorld* world = static_cast<btsWorld*>(a->getUserPointer());
  btsContactMaterial m = {};
  world->material(world->user, a->getUserIndex(), b->getUserIndex(), &m);
  cp.m_combinedFriction = m.friction;
  cp.m_combinedRestitution = m.restitution;
  cp.m_combinedRollingFriction = 0;
  cp.m_combinedSpinningFriction = 0;
  if (m.soft) {
    cp.m_combinedContactStiffness1 = m.stiffness;
    cp.m_combinedContactDamping1 = m.damping;
    cp.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
  } else {
    cp.m_contactPointFlags &= ~BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
  }
  return true;
}

extern "C" btsWorld* bts_world_create(const double gravity[3], const btsSolverSettings* s, btsMaterialFcn* material,
                                      void* user) {
  static std::once_flag once;
  std::call_once(once, [] { gContactAddedCallback = contact_added; });
  btsWorld* w = new btsWorld;
  w->material = material;
  w->user = user;
  w->dynamics.setGravity(btVector3(gravity[0], gravity[1], gravity[2]));  // Bullet's default is (0, -10, 0)
  btContactSolverInfo& info = w->dynamics.getSolverInfo();
  info.m_numIterations = s->iterations;
  info.m_splitImpulse = s->splitImpulse ? 1 : 0;
  info.m_splitImpulsePenetrationThreshold = s->splitImpulsePenetrationThreshold;
  info.m_erp2 = s->erp2;
  info.m_restitutionVelocityThreshold = s->restitutionVelocityThreshold;
  info.m_warmstartingFactor = s->warmstartingFactor;
  w->dynamics.getDispatchInfo().m_enableSatConvex = s->satConvex;
  w->settings = *s;
  return w;
}

extern "C" void bts_solver_info(const btsWorld* w, btsSolverInfo* out) {
  const btContactSolverInfo& info = w->dynamics.getSolverInfo();
  out->settings = w->settings;
  out->settings.iterations = info.m_numIterations;
  out->settings.splitImpulse = info.m_splitImpulse != 0;
  out->settings.splitImpulsePenetrationThreshold = info.m_splitImpulsePenetrationThreshold;
  out->settings.erp2 = info.m_erp2;
  out->settings.restitutionVelocityThreshold = info.m_restitutionVelocityThreshold;
  out->settings.warmstartingFactor = info.m_warmstartingFactor;
  out->settings.satConvex = w->dynamics.getDispatchInfo().m_enableSatConvex;
  out->splitImpulseTurnErp = info.m_splitImpulseTurnErp;
  out->sor = info.m_sor;
  out->globalCfm = info.m_globalCfm;
  out->linearSlop = info.m_linearSlop;
  out->solverMode = info.m_solverMode;
  out->frictionDirections = (info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS) ? 2 : 1;
  out->contactBreakingThreshold = gContactBreakingThreshold;
}

extern "C" void bts_add_hull(btsWorld* w, int id, const btsHull* hull, double mass, const double inertia[3],
                             const double position[3], const double quaternion[4], const double velocity[3],
                             const double angularVelocity[3]) {
  auto shape = std::make_unique<btConvexHullShape>();
  btConvexPolyhedron polyhedron;  // the polyhedral features (hull–hull contacts by clipping, up to 4 points)
  for (int i = 0; i < hull->vertexCount; ++i) {
    const double* x = hull->vertices + 3 * i;
    shape->addPoint(btVector3(x[0], x[1], x[2]), i == hull->vertexCount - 1);
    polyhedron.m_vertices.push_back(btVector3(x[0], x[1], x[2]));
  }
  shape->setMargin(0);       // the default 0.04 m inflates a hull
  shape->recalcLocalAabb();  // setMargin does not refresh the cached box
  const int* index = hull->faceVertices;
  for (int f = 0; f < hull->faceCount; ++f) {
    btFace face;
    for (int k = 0; k < hull->faceSizes[f]; ++k) face.m_indices.push_back(*index++);
    const double* plane = hull->facePlanes + 4 * f;
    face.m_plane[0] = plane[0], face.m_plane[1] = plane[1], face.m_plane[2] = plane[2];
    face.m_plane[3] = -plane[3];  // Bullet's plane: n · x + m_plane[3] = 0
    polyhedron.m_faces.push_back(face);
  }
  polyhedron.initialize();  // unique edge directions, centre, extents
  shape->setPolyhedralFeatures(polyhedron);

  btTransform start;
  start.setOrigin(btVector3(position[0], position[1], position[2]));
  start.setRotation(btQuaternion(quaternion[1], quaternion[2], quaternion[3], quaternion[0]));
  btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, shape.get(),
                                              btVector3(inertia[0], inertia[1], inertia[2]));
  ci.m_startWorldTransform = start;
  auto body = std::make_unique<btRigidBody>(ci);
  body->setUserPointer(w);
  body->setUserIndex(id);
  body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK);
  body->setContactProcessingThreshold(w->settings.contactProcessingThreshold);
  if (mass > 0) {
    body->setLinearVelocity(btVector3(velocity[0], velocity[1], velocity[2]));
    body->setAngularVelocity(btVector3(angularVelocity[0], angularVelocity[1], angularVelocity[2]));
    body->setActivationState(DISABLE_DEACTIVATION);  // a resting body would otherwise fall asleep
  }
  w->dynamics.addRigidBody(body.get());
  w->shapes.push_back(std::move(shape));
  w->bodies.push_back(std::move(body));
}

extern "C" void bts_hold_in_xz_plane(btsWorld* w, int index) {
  btRigidBody& b = *w->bodies[(size_t)index];
  b.setLinearFactor(btVector3(1, 0, 1));
  b.setAngularFactor(btVector3(0, 1, 0));
}

extern "C" void bts_apply_force(btsWorld* w, int index, const double force[3], const double relPos[3]) {
  w->bodies[(size_t)index]->applyForce(btVector3(force[0], force[1], force[2]), btVector3(relPos[0], relPos[1], relPos[2]));
}

extern "C" void bts_step(btsWorld* w, double h) { w->dynamics.stepSimulation(h, 0); }

extern "C" void bts_body_state(const btsWorld* w, int index, double position[3], double quaternion[4],
                               double velocity[3], double angularVelocity[3]) {
  const btRigidBody& b = *w->bodies[(size_t)index];
  const btTransform& t = b.getCenterOfMassTransform();
  btQuaternion q = t.getRotation();
  const btVector3 &x = t.getOrigin(), &v = b.getLinearVelocity(), &omega = b.getAngularVelocity();
  for (int i = 0; i < 3; ++i) {
    position[i] = x[i];
    velocity[i] = v[i];
    angularVelocity[i] = omega[i];
  }
  quaternion[0] = q.w(), quaternion[1] = q.x(), quaternion[2] = q.y(), quaternion[3] = q.z();
}

extern "C" int bts_contacts(const btsWorld* w, double h, btsContact* out, int capacity) {
  int count = 0;
  for (int m = 0; m < w->dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = w->dispatcher.getManifoldByIndexInternal(m);
    for (int p = 0; p < manifold->getNumContacts(); ++p) {
      const btManifoldPoint& pt = manifold->getContactPoint(p);
      if (pt.getDistance() > manifold->getContactProcessingThreshold()) continue;
      if (count < capacity) {
        btsContact& c = out[count];
        c.a = manifold->getBody0()->getUserIndex();
        c.b = manifold->getBody1()->getUserIndex();
        btVector3 mid = 0.5 * (pt.getPositionWorldOnA() + pt.getPositionWorldOnB());
        btVector3 ft = (pt.m_appliedImpulseLateral1 * pt.m_lateralFrictionDir1 +
                        pt.m_appliedImpulseLateral2 * pt.m_lateralFrictionDir2) / h;
        for (int k = 0; k < 3; ++k) {
          c.point[k] = mid[k];
          c.normal[k] = pt.m_normalWorldOnB[k];  // Bullet's normal on B points towards A
          c.ft[k] = ft[k];
        }
        c.fn = pt.getAppliedImpulse() / h;
      }
      ++count;
    }
  }
  return count;
}

extern "C" int bts_contact_count(const btsWorld* w) {
  int count = 0;
  for (int m = 0; m < w->dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = w->dispatcher.getManifoldByIndexInternal(m);
    for (int p = 0; p < manifold->getNumContacts(); ++p)
      if (manifold->getContactPoint(p).getDistance() <= manifold->getContactProcessingThreshold()) ++count;
  }
  return count;
}

extern "C" void bts_world_destroy(btsWorld* w) {
  if (!w) return;
  for (auto& body : w->bodies) w->dynamics.removeRigidBody(body.get());
  delete w;
}

#ifndef BT_USE_DOUBLE_PRECISION
#error "polydyn's Bullet adapter needs the double-precision build (pkg-config module bullet-float64)"
#endif
#define BTS_STRING(x) BTS_STRING_(x)
#define BTS_STRING_(x) #x
extern "C" const char bts_version_string[] = BTS_STRING(BT_BULLET_VERSION) "-float64";
