// polydyn refcheck — trajectories in memory and the comparison metrics (conventions in compare.h).
#include "pdref/compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare_internal.h"
#include "interference.h"
#include "polydyn/error.h"

pdTrajectory* pd_trajectory_create(const pdModel* model) {
  pdTrajectory* tr = calloc(1, sizeof *tr);
  if (!tr) abort();
  tr->movingCount = model->movingCount;
  return tr;
}

void pd_trajectory_free(pdTrajectory* tr) {
  if (!tr) return;
  free(tr->t);
  free(tr->bodies);
  free(tr);
}

bool pd_trajectory_observe(const pdModel* model, const pdState* state, void* user) {
  pdTrajectory* tr = user;
  if (tr->samples == tr->capacity) {
    tr->capacity = tr->capacity ? 2 * tr->capacity : 256;
    tr->t = realloc(tr->t, (size_t)tr->capacity * sizeof *tr->t);
    size_t m = (size_t)(tr->movingCount > 0 ? tr->movingCount : 1);
    tr->bodies = realloc(tr->bodies, (size_t)tr->capacity * m * sizeof *tr->bodies);
    if (!tr->t || !tr->bodies) abort();
  }
  tr->t[tr->samples] = state->t;
  for (int k = 0; k < tr->movingCount; ++k)
    tr->bodies[(size_t)tr->samples * (size_t)tr->movingCount + (size_t)k] =
        pd_state_body(model, state, model->movingBodies[k]);
  ++tr->samples;
  return true;
}

const pdBodyState* pd_trajectory_sample(const pdTrajectory* tr, long s, int k) {
  return &tr->bodies[(size_t)s * (size_t)tr->movingCount + (size_t)k];
}

static pdVec3 lerp3(pdVec3 a, pdVec3 b, double u) { return pd_v3_add(a, pd_v3_scale(pd_v3_sub(b, a), u)); }

static pdQuat slerp(pdQuat a, pdQuat b, double u) {
  double d = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (d < 0.0) b = (pdQuat){-b.w, -b.x, -b.y, -b.z}, d = -d;
  double wa = 1.0 - u, wb = u;
  if (d < 0.9995) {  // otherwise the linear blend is within 1e-7 rad and avoids dividing by sin ≈ 0
    double th = acos(d), s = sin(th);
    wa = sin((1.0 - u) * th) / s;
    wb = sin(u * th) / s;
  }
  return pd_quat_normalize((pdQuat){wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z});
}

pdBodyState pd_trajectory_at(const pdTrajectory* tr, int k, double t) {
  PD_ASSERT(tr->samples > 0 && k >= 0 && k < tr->movingCount);
  if (t <= tr->t[0]) return *pd_trajectory_sample(tr, 0, k);
  if (t >= tr->t[tr->samples - 1]) return *pd_trajectory_sample(tr, tr->samples - 1, k);
  long lo = 0, hi = tr->samples - 1;  // t[lo] <= t < t[hi]
  while (hi - lo > 1) {
    long mid = (lo + hi) / 2;
    if (tr->t[mid] <= t) lo = mid;
    else hi = mid;
  }
  const pdBodyState *a = pd_trajectory_sample(tr, lo, k), *b = pd_trajectory_sample(tr, hi, k);
  double u = (t - tr->t[lo]) / (tr->t[hi] - tr->t[lo]);
  if (u == 0.0) return *a;
  return (pdBodyState){lerp3(a->x, b->x, u), slerp(a->q, b->q, u), lerp3(a->v, b->v, u), lerp3(a->w, b->w, u)};
}

double pd_rotation_angle(pdQuat q, pdQuat ref) {
  double d = fabs(q.w * ref.w + q.x * ref.x + q.y * ref.y + q.z * ref.z);
  return 2.0 * acos(fmin(1.0, d));
}

double pd_trajectory_body_energy(const pdModel* model, const pdTrajectory* tr, long s, int k, double* kinetic) {
  const pdBody* body = &model->bodies[model->movingBodies[k]];
  const pdBodyState* b = pd_trajectory_sample(tr, s, k);
  *kinetic = pd_body_kinetic_energy(body, b->v, b->w, b->q);
  return *kinetic - body->mass * pd_v3_dot(model->settings.gravity, b->x);
}

static double energy_at(const pdModel* model, const pdTrajectory* tr, long s, double* kineticOut) {
  double e = 0.0, kinetic = 0.0;
  for (int k = 0; k < tr->movingCount; ++k) {
    double ke;
    e += pd_trajectory_body_energy(model, tr, s, k, &ke);
    kinetic += ke;
  }
  *kineticOut = kinetic;
  return e;
}

double pd_pose_error(const pdModel* model, int k, const pdBodyState* b, const pdBodyState* ref, double* rotation) {
  *rotation = pd_rotation_angle(b->q, ref->q);
  return pd_v3_norm(pd_v3_sub(b->x, ref->x)) / model->bodies[model->movingBodies[k]].size;
}

static void errors(const pdModel* model, const pdTrajectory* run, const pdTrajectory* ref, pdCompareMetrics* m) {
  double pos2 = 0.0, rot2 = 0.0;
  long count = 0;
  for (long s = 0; s < run->samples; ++s) {
    double posMax = 0.0, rotMax = 0.0;
    for (int k = 0; k < run->movingCount; ++k) {
      pdBodyState r = pd_trajectory_at(ref, k, run->t[s]);
      double re, pe = pd_pose_error(model, k, pd_trajectory_sample(run, s, k), &r, &re);
      pos2 += pe * pe;
      rot2 += re * re;
      ++count;
      posMax = fmax(posMax, pe);
      rotMax = fmax(rotMax, re);
    }
    if (s == run->samples - 1) {
      m->posErrFinal = posMax;
      m->rotErrFinal = rotMax;
    }
  }
  m->posErrRms = count ? sqrt(pos2 / (double)count) : 0.0;
  m->rotErrRms = count ? sqrt(rot2 / (double)count) : 0.0;
}

static void drifts(const pdModel* model, const pdTrajectory* run, pdCompareMetrics* m) {
  double kinetic, kineticMax = 0.0;
  double e0 = energy_at(model, run, 0, &kinetic), e1 = e0;
  kineticMax = kinetic;
  double vmax = 0.0;
  for (long s = 0; s < run->samples; ++s) {
    e1 = energy_at(model, run, s, &kinetic);
    kineticMax = fmax(kineticMax, kinetic);
    for (int k = 0; k < run->movingCount; ++k) vmax = fmax(vmax, pd_v3_norm(pd_trajectory_sample(run, s, k)->v));
  }
  double scale = kineticMax + fabs(e0);
  m->energyDriftRel = scale > 0.0 ? (e1 - e0) / scale : 0.0;
  m->momentumDriftRel = NAN;
  if (model->movingCount < model->bodyCount || run->samples < 1) return;
  pdVec3 p0 = {0, 0, 0}, p1 = {0, 0, 0};
  double mass = 0.0;
  for (int k = 0; k < run->movingCount; ++k) {
    const pdBody* body = &model->bodies[model->movingBodies[k]];
    mass += body->mass;
    p0 = pd_v3_muladd(p0, body->mass, pd_trajectory_sample(run, 0, k)->v);
    p1 = pd_v3_muladd(p1, body->mass, pd_trajectory_sample(run, run->samples - 1, k)->v);
  }
  double elapsed = run->t[run->samples - 1] - run->t[0];
  pdVec3 lost = pd_v3_sub(pd_v3_sub(p1, p0), pd_v3_scale(model->settings.gravity, mass * elapsed));
  m->momentumDriftRel = vmax > 0.0 ? pd_v3_norm(lost) / (mass * vmax) : 0.0;
}

pdVec3 pd_trajectory_body_position(const pdModel* model, const pdTrajectory* run, long s, int body, pdMat3* R) {
  const pdBody* b = &model->bodies[body];
  if (b->fixed) {
    *R = pd_quat_to_mat3(b->q0);
    return b->x0;
  }
  const pdBodyState* st = pd_trajectory_sample(run, s, b->stateIndex);
  *R = pd_quat_to_mat3(st->q);
  return st->x;
}

double pd_pair_penetration(const pdModel* model, const pdTrajectory* run, long s, int i, int j, pdVec3* axis) {
  const pdBody *a = &model->bodies[i], *b = &model->bodies[j];
  pdMat3 Ra, Rb;
  pdVec3 xa = pd_trajectory_body_position(model, run, s, i, &Ra), xb = pd_trajectory_body_position(model, run, s, j, &Rb);
  double distance = pd_v3_norm(pd_v3_sub(xb, xa));
  double gap = distance - a->radius - b->radius;
  double size = fmin(a->size, b->size);
  if (gap > 0.0) {  // bounding spheres apart: the SAT would say separated by at least this
    if (axis) *axis = pd_v3_scale(pd_v3_sub(xb, xa), 1.0 / distance);
    return -gap / size;
  }
  pdSatResult r;
  pd_interference(&a->shape, xa, &Ra, &b->shape, xb, &Rb, PD_SAT_MIN_DEPTH, NULL, &r);
  if (axis) *axis = r.axis;
  return r.depth / size;
}

static void penetration(const pdModel* model, const pdTrajectory* run, pdCompareMetrics* m) {
  double deepest = -INFINITY;
  for (long s = 0; s < run->samples; ++s)
    for (int i = 0; i < model->bodyCount; ++i)
      for (int j = i + 1; j < model->bodyCount; ++j)
        if (!model->bodies[i].fixed || !model->bodies[j].fixed)
          deepest = fmax(deepest, pd_pair_penetration(model, run, s, i, j, NULL));
  m->maxPenetrationOverSize = isfinite(deepest) ? deepest : 0.0;
}

// Bounces of each moving body: height minima between apexes (see compare.h).
static void bounces(const pdModel* model, const pdTrajectory* run, pdCompareMetrics* m) {
  pdVec3 g = model->settings.gravity;
  double gn = pd_v3_norm(g);
  if (!(gn > 0.0) || run->samples < 3) return;
  pdVec3 up = pd_v3_scale(g, -1.0 / gn);
  typedef struct bounce {
    double t, e;
    int body;
  } bounce;
  bounce found[64];
  int count = 0;
  for (int k = 0; k < run->movingCount; ++k) {
    int body = model->movingBodies[k];
    double minRise = PD_COMPARE_BOUNCE_MIN_RISE * model->bodies[body].size;
    // walk the height: apex (local max) → contact (local min) → apex
    double apex = pd_v3_dot(up, pd_trajectory_sample(run, 0, k)->x), low = apex, lowT = run->t[0];
    bool falling = pd_v3_dot(up, pd_trajectory_sample(run, 0, k)->v) <= 0.0;
    for (long s = 1; s < run->samples; ++s) {
      double z = pd_v3_dot(up, pd_trajectory_sample(run, s, k)->x);
      if (falling) {
        if (z <= low) {
          low = z;
          lowT = run->t[s];
        } else if (z - low > minRise) {  // rising clearly again: a bounce at `low`
          // follow the rise to its apex
          double next = z;
          long r = s;
          while (r + 1 < run->samples && pd_v3_dot(up, pd_trajectory_sample(run, r + 1, k)->x) >= next)
            next = pd_v3_dot(up, pd_trajectory_sample(run, ++r, k)->x);
          if (apex - low > minRise && count < 64)
            found[count++] = (bounce){lowT, sqrt((next - low) / (apex - low)), body};
          apex = next;
          low = next;
          s = r;
        }
      } else if (z >= apex) {
        apex = z;
        low = z;
      } else {
        falling = true;
        low = z;
        lowT = run->t[s];
      }
    }
  }
  // time order, then body: deterministic
  for (int i = 1; i < count; ++i)
    for (int j = i; j > 0 && (found[j].t < found[j - 1].t || (found[j].t == found[j - 1].t && found[j].body < found[j - 1].body)); --j) {
      bounce tmp = found[j];
      found[j] = found[j - 1];
      found[j - 1] = tmp;
    }
  m->impacts = count;
  for (int i = 0; i < count && i < 16; ++i) {
    m->restitution[i] = found[i].e;
    m->impactBody[i] = found[i].body;
  }
}

pdCompareMetrics pd_compare_metrics(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference) {
  PD_ASSERT(model && run && run->samples > 0 && run->movingCount == model->movingCount);
  pdCompareMetrics m;
  memset(&m, 0, sizeof m);
  m.posErrFinal = m.posErrRms = m.rotErrFinal = m.rotErrRms = NAN;
  if (reference && reference->samples > 0) errors(model, run, reference, &m);
  drifts(model, run, &m);
  penetration(model, run, &m);
  bounces(model, run, &m);
  return m;
}
