// polydyn — applied loads: the scene's `force` on a body, as a function of time, and its torque.
#include "polydyn/model.h"

pdVec3 pd_body_applied_force(const pdBody* b, double t) {
  if (!b->hasForce) return (pdVec3){0.0, 0.0, 0.0};
  return pd_v3_add(b->force0, pd_v3_scale(b->forceRate, t));
}

pdVec3 pd_body_applied_torque(const pdBody* b, const pdMat3* r, pdVec3 force) {
  if (!b->hasForce) return (pdVec3){0.0, 0.0, 0.0};
  return pd_v3_cross(pd_mat3_mulv(r, b->forcePoint), force);
}

bool pd_model_has_applied_force(const pdModel* model) {
  for (int i = 0; i < model->bodyCount; ++i)
    if (model->bodies[i].hasForce) return true;
  return false;
}
