// polydyn refcheck — trajectories in memory and the comparison metrics (conventions in compare.h).
#include "polydyn/compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

static const pdBodyState* sample_body(const pdTrajectory* tr, long s, int k) {
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
  if (t <= tr->t[0]) return *sample_body(tr, 0, k);
  if (t >= tr->t[tr->samples - 1]) return *sample_body(tr, tr->samples - 1, k);
  long lo = 0, hi = tr->samples - 1;  // t[lo] <= t < t[hi]
  while (hi - lo > 1) {
    long mid = (lo + hi) / 2;
    if (tr->t[mid] <= t) lo = mid;
    else hi = mid;
  }
  const pdBodyState *a = sample_body(tr, lo, k), *b = sample_body(tr, hi, k);
  double u = (t - tr->t[lo]) / (tr->t[hi] - tr->t[lo]);
  if (u == 0.0) return *a;
  return (pdBodyState){lerp3(a->x, b->x, u), slerp(a->q, b->q, u), lerp3(a->v, b->v, u), lerp3(a->w, b->w, u)};
}

// Angle of q_ref⁻¹ q, rad in [0, π].
static double rotation_angle(pdQuat q, pdQuat ref) {
  double d = fabs(q.w * ref.w + q.x * ref.x + q.y * ref.y + q.z * ref.z);
  return 2.0 * acos(fmin(1.0, d));
}

static double energy_at(const pdModel* model, const pdTrajectory* tr, long s, double* kineticOut) {
  double e = 0.0, kinetic = 0.0;
  pdVec3 g = model->settings.gravity;
  for (int k = 0; k < tr->movingCount; ++k) {
    const pdBody* body = &model->bodies[model->movingBodies[k]];
    const pdBodyState* b = sample_body(tr, s, k);
    double ke = pd_body_kinetic_energy(body, b->v, b->w, b->q);
    kinetic += ke;
    e += ke - body->mass * pd_v3_dot(g, b->x);
  }
  *kineticOut = kinetic;
  return e;
}

static void errors(const pdModel* model, const pdTrajectory* run, const pdTrajectory* ref, pdCompareMetrics* m) {
  double pos2 = 0.0, rot2 = 0.0;
  long count = 0;
  for (long s = 0; s < run->samples; ++s) {
    double posMax = 0.0, rotMax = 0.0;
    for (int k = 0; k < run->movingCount; ++k) {
      const pdBody* body = &model->bodies[model->movingBodies[k]];
      const pdBodyState* b = sample_body(run, s, k);
      pdBodyState r = pd_trajectory_at(ref, k, run->t[s]);
      double pe = pd_v3_norm(pd_v3_sub(b->x, r.x)) / body->size, re = rotation_angle(b->q, r.q);
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
    for (int k = 0; k < run->movingCount; ++k) vmax = fmax(vmax, pd_v3_norm(sample_body(run, s, k)->v));
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
    p0 = pd_v3_muladd(p0, body->mass, sample_body(run, 0, k)->v);
    p1 = pd_v3_muladd(p1, body->mass, sample_body(run, run->samples - 1, k)->v);
  }
  double elapsed = run->t[run->samples - 1] - run->t[0];
  pdVec3 lost = pd_v3_sub(pd_v3_sub(p1, p0), pd_v3_scale(model->settings.gravity, mass * elapsed));
  m->momentumDriftRel = vmax > 0.0 ? pd_v3_norm(lost) / (mass * vmax) : 0.0;
}

static pdVec3 body_position(const pdModel* model, const pdTrajectory* run, long s, int body, pdMat3* R) {
  const pdBody* b = &model->bodies[body];
  if (b->fixed) {
    *R = pd_quat_to_mat3(b->q0);
    return b->x0;
  }
  const pdBodyState* st = sample_body(run, s, b->stateIndex);
  *R = pd_quat_to_mat3(st->q);
  return st->x;
}

static void penetration(const pdModel* model, const pdTrajectory* run, pdCompareMetrics* m) {
  double deepest = -INFINITY;
  for (long s = 0; s < run->samples; ++s)
    for (int i = 0; i < model->bodyCount; ++i)
      for (int j = i + 1; j < model->bodyCount; ++j) {
        const pdBody *a = &model->bodies[i], *b = &model->bodies[j];
        if (a->fixed && b->fixed) continue;
        pdMat3 Ra, Rb;
        pdVec3 xa = body_position(model, run, s, i, &Ra), xb = body_position(model, run, s, j, &Rb);
        double gap = pd_v3_norm(pd_v3_sub(xa, xb)) - a->radius - b->radius;
        double size = fmin(a->size, b->size);
        if (gap > 0.0) {  // bounding spheres apart: the SAT would say separated by at least this
          deepest = fmax(deepest, -gap / size);
          continue;
        }
        pdSatResult r;
        pd_interference(&a->shape, xa, &Ra, &b->shape, xb, &Rb, PD_SAT_MIN_DEPTH, NULL, &r);
        deepest = fmax(deepest, r.depth / size);
      }
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
    double apex = pd_v3_dot(up, sample_body(run, 0, k)->x), low = apex, lowT = run->t[0];
    bool falling = pd_v3_dot(up, sample_body(run, 0, k)->v) <= 0.0;
    for (long s = 1; s < run->samples; ++s) {
      double z = pd_v3_dot(up, sample_body(run, s, k)->x);
      if (falling) {
        if (z <= low) {
          low = z;
          lowT = run->t[s];
        } else if (z - low > minRise) {  // rising clearly again: a bounce at `low`
          // follow the rise to its apex
          double next = z;
          long r = s;
          while (r + 1 < run->samples && pd_v3_dot(up, sample_body(run, r + 1, k)->x) >= next)
            next = pd_v3_dot(up, sample_body(run, ++r, k)->x);
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
