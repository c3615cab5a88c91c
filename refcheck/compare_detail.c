// polydyn refcheck — per-body series, first divergence against chaos, impacts and contact tallies of
// `polydyn compare` (conventions in compare_detail.h).
#include "pdref/compare_detail.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare_internal.h"
#include "polydyn/error.h"
#include "pdref/refcheck.h"

pdBodySample* pd_compare_body_samples(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference,
                                      const long* sampleIndex, long count) {
  int m = run->movingCount;
  pdBodySample* out = calloc((size_t)(count > 0 ? count : 1) * (size_t)(m > 0 ? m : 1), sizeof *out);
  if (!out) abort();
  for (long i = 0; i < count; ++i) {
    long s = sampleIndex[i];
    PD_ASSERT(s >= 0 && s < run->samples);
    for (int k = 0; k < m; ++k) {
      pdBodySample* o = &out[(size_t)i * (size_t)m + (size_t)k];
      o->posErr = o->rotErr = NAN;
      if (reference && reference->samples > 0) {
        pdBodyState r = pd_trajectory_at(reference, k, run->t[s]);
        o->posErr = pd_pose_error(model, k, pd_trajectory_sample(run, s, k), &r, &o->rotErr);
      }
      double kinetic;
      o->energy = pd_trajectory_body_energy(model, run, s, k, &kinetic);
      int body = model->movingBodies[k];
      o->penetration = -INFINITY;
      for (int j = 0; j < model->bodyCount; ++j)
        if (j != body) o->penetration = fmax(o->penetration, pd_pair_penetration(model, run, s, body, j, NULL));
      if (!isfinite(o->penetration)) o->penetration = NAN;  // a scene of one body
    }
  }
  return out;
}

// The largest error over the bodies of trajectory `a` against `b` at time t, a's state taken at its sample s.
static double error_at(const pdModel* model, const pdTrajectory* a, long s, const pdTrajectory* b, int* body,
                       bool* rotation) {
  double worst = -1.0;
  for (int k = 0; k < a->movingCount; ++k) {
    pdBodyState r = pd_trajectory_at(b, k, a->t[s]);
    double re, pe = pd_pose_error(model, k, pd_trajectory_sample(a, s, k), &r, &re);
    if (fmax(pe, re) > worst) {
      worst = fmax(pe, re);
      if (body) *body = k;
      if (rotation) *rotation = re > pe;
    }
  }
  return fmax(worst, 0.0);
}

double pd_compare_sample_error(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference, long s,
                               int* body, bool* rotation) {
  PD_ASSERT(s >= 0 && s < run->samples && reference && reference->samples > 0);
  *body = 0;
  *rotation = false;
  return error_at(model, run, s, reference, body, rotation);
}

// The chaos run's error against the reference at time t (both interpolated there).
static double chaos_error(const pdModel* model, const pdTrajectory* chaos, const pdTrajectory* reference, double t) {
  double worst = 0.0;
  for (int k = 0; k < chaos->movingCount; ++k) {
    pdBodyState c = pd_trajectory_at(chaos, k, t), r = pd_trajectory_at(reference, k, t);
    double re, pe = pd_pose_error(model, k, &c, &r, &re);
    worst = fmax(worst, fmax(pe, re));
  }
  return worst;
}

pdDivergence pd_compare_divergence(const pdModel* model, const pdTrajectory* run, const pdTrajectory* reference,
                                   const pdTrajectory* chaos, double threshold) {
  PD_ASSERT(model && run && reference && threshold > 0.0);
  pdDivergence d = {.t = NAN, .error = NAN, .beyondChaos = NAN};
  if (reference->samples == 0) return d;
  bool chaosKnown = chaos && chaos->samples > 0;
  for (long s = 0; s < run->samples; ++s) {
    int body = 0;
    bool rotation = false;
    double e = error_at(model, run, s, reference, &body, &rotation);
    if (e <= threshold) continue;
    if (!d.diverged) d = (pdDivergence){true, run->t[s], body, rotation, e, NAN};
    if (!chaosKnown) break;
    if (e > PD_COMPARE_CHAOS_FACTOR * chaos_error(model, chaos, reference, run->t[s])) {
      d.beyondChaos = run->t[s];
      break;
    }
  }
  return d;
}

// ---- impacts ----

// The velocity change of moving body k over the interval [s, s+1] that gravity does not explain, m/s.
static double speed_change(const pdModel* model, const pdTrajectory* run, long s, int k) {
  double dt = run->t[s + 1] - run->t[s];
  pdVec3 dv = pd_v3_sub(pd_trajectory_sample(run, s + 1, k)->v, pd_trajectory_sample(run, s, k)->v);
  return pd_v3_norm(pd_v3_sub(dv, pd_v3_scale(model->settings.gravity, dt)));
}

// The smallest τ >= 0 with gap + speed τ + accel τ²/2 = 0, at most `longest`; `longest` when there is none
// in between.
static double time_to_close(double gap, double speed, double accel, double longest) {
  if (gap <= 0.0) return 0.0;
  double tau = longest;
  if (accel == 0.0) {
    if (speed < 0.0) tau = -gap / speed;
  } else {
    double disc = speed * speed - 2.0 * accel * gap;
    if (disc >= 0.0) {
      double r = sqrt(disc), lo = (-speed - r) / accel, hi = (-speed + r) / accel;
      if (lo > hi) tau = lo, lo = hi, hi = tau;
      tau = lo >= 0.0 ? lo : hi >= 0.0 ? hi : longest;
    }
  }
  return fmin(tau, longest);
}

// Where the pair touches at sample s: the centroid of the smaller body's vertices within
// PD_IMPACT_FEATURE_SPAN of its size of its support towards the other (the vertex, edge or face that lands).
static pdVec3 touch_point(const pdModel* model, const pdTrajectory* run, long s, int bodyA, int bodyB, pdVec3 n) {
  bool smallerA = model->bodies[bodyA].size <= model->bodies[bodyB].size;
  int body = smallerA ? bodyA : bodyB;
  pdVec3 towards = smallerA ? pd_v3_scale(n, -1.0) : n;  // n points from B into A
  const pdBody* b = &model->bodies[body];
  pdMat3 R;
  pdVec3 x = pd_trajectory_body_position(model, run, s, body, &R);
  double most = -INFINITY;
  for (int i = 0; i < b->shape.vertexCount; ++i)
    most = fmax(most, pd_v3_dot(pd_mat3_mulv(&R, b->shape.vertices[i]), towards));
  pdVec3 sum = {0, 0, 0};
  int count = 0;
  for (int i = 0; i < b->shape.vertexCount; ++i) {
    pdVec3 r = pd_mat3_mulv(&R, b->shape.vertices[i]);
    if (pd_v3_dot(r, towards) >= most - PD_IMPACT_FEATURE_SPAN * b->size) sum = pd_v3_add(sum, r), ++count;
  }
  return pd_v3_add(x, pd_v3_scale(sum, 1.0 / count));
}

// Velocity of body (model index)'s material point at p, sample s (a fixed body: zero), and its acceleration in
// free flight.
static pdVec3 velocity_of(const pdModel* model, const pdTrajectory* run, long s, int body, pdVec3 p, pdVec3* accel) {
  const pdBody* b = &model->bodies[body];
  *accel = b->fixed ? (pdVec3){0, 0, 0} : model->settings.gravity;
  if (b->fixed) return (pdVec3){0, 0, 0};
  const pdBodyState* st = pd_trajectory_sample(run, s, b->stateIndex);
  return pd_v3_add(st->v, pd_v3_cross(st->w, pd_v3_sub(p, st->x)));
}

// Relative velocity of bodyA to bodyB at their touching point at sample s, and their relative acceleration in
// free flight.
static pdVec3 relative_velocity(const pdModel* model, const pdTrajectory* run, long s, int bodyA, int bodyB, pdVec3 n,
                                pdVec3* accel) {
  pdVec3 p = touch_point(model, run, s, bodyA, bodyB, n), ga, gb;
  pdVec3 v = pd_v3_sub(velocity_of(model, run, s, bodyA, p, &ga), velocity_of(model, run, s, bodyB, p, &gb));
  *accel = pd_v3_sub(ga, gb);
  return v;
}

static double gap_at(const pdModel* model, const pdTrajectory* run, long s, int bodyA, int bodyB) {
  double size = fmin(model->bodies[bodyA].size, model->bodies[bodyB].size);
  return -pd_pair_penetration(model, run, s, bodyA, bodyB, NULL) * size;
}

typedef struct impactList {
  pdImpact* items;
  int count, capacity;
} impactList;

static void push_impact(impactList* list, pdImpact impact) {
  if (list->count == list->capacity) {
    list->capacity = list->capacity ? 2 * list->capacity : 32;
    list->items = realloc(list->items, (size_t)list->capacity * sizeof *list->items);
    if (!list->items) abort();
  }
  list->items[list->count++] = impact;
}

// One impact of moving body k over samples [first, last + 1], its largest change over [peak, peak + 1].
static void add_impact(const pdModel* model, const pdTrajectory* run, int k, long first, long last, long peak,
                       impactList* list) {
  int body = model->movingBodies[k];
  // the partner: of the bodies touching it, the one that came at it fastest (a domino resting on the floor is
  // hit by its neighbour, not by the floor); the deepest when none approached
  int partner = -1, fastest = -1;
  double deepest = -INFINITY, fastestSpeed = 0.0;
  pdVec3 axis = {0, 0, 1}, fastestAxis = axis;
  for (int j = 0; j < model->bodyCount; ++j) {
    if (j == body) continue;
    pdVec3 a;
    double p = pd_pair_penetration(model, run, peak + 1, body, j, &a);
    if (p > deepest) deepest = p, partner = j, axis = a;
    if (p < -PD_IMPACT_TOUCH) continue;
    int lo = body < j ? body : j, hi = body < j ? j : body;
    pdVec3 n = body == lo ? pd_v3_scale(a, -1.0) : a, accel;
    double approach = -pd_v3_dot(relative_velocity(model, run, first, lo, hi, n, &accel), n);
    if (approach > fastestSpeed) fastestSpeed = approach, fastest = j, fastestAxis = a;
  }
  if (fastest >= 0) partner = fastest, axis = fastestAxis;
  if (partner < 0) return;  // a body alone: nothing to hit (an applied force changed its speed)
  int bodyA = body < partner ? body : partner, bodyB = body < partner ? partner : body;
  // the axis runs from `body` to `partner`; the normal from bodyB into bodyA
  pdVec3 n = body == bodyA ? pd_v3_scale(axis, -1.0) : axis;
  // free flight up to the contact and from the separation: the speeds the impact met and left behind
  pdVec3 accel;
  pdVec3 v0 = relative_velocity(model, run, first, bodyA, bodyB, n, &accel);
  pdVec3 v1 = relative_velocity(model, run, last + 1, bodyA, bodyB, n, &accel);
  double an = pd_v3_dot(accel, n), span = run->t[last + 1] - run->t[first];
  double toContact = time_to_close(gap_at(model, run, first, bodyA, bodyB), pd_v3_dot(v0, n), an, span);
  double gapAfter = gap_at(model, run, last + 1, bodyA, bodyB);
  double sinceSeparation = time_to_close(gapAfter, -pd_v3_dot(v1, n), an, span - toContact);
  pdVec3 before = pd_v3_add(v0, pd_v3_scale(accel, toContact));
  pdVec3 after = pd_v3_sub(v1, pd_v3_scale(accel, sinceSeparation));
  double t = run->t[first] + toContact;
  double vnBefore = pd_v3_dot(before, n), vnAfter = pd_v3_dot(after, n);
  pdVec3 change = pd_v3_sub(after, before);
  pdVec3 tangential = pd_v3_sub(change, pd_v3_scale(n, pd_v3_dot(change, n)));
  // the same impact found already from its other body (both moving): once
  for (int i = list->count - 1; i >= 0 && list->items[i].t >= run->t[first] - 1e-12; --i)
    if (list->items[i].bodyA == bodyA && list->items[i].bodyB == bodyB) return;
  push_impact(list, (pdImpact){.t = t,
                               .bodyA = bodyA,
                               .bodyB = bodyB,
                               .vnBefore = vnBefore,
                               .vnAfter = vnAfter,
                               .restitution = -vnBefore > PD_IMPACT_MIN_APPROACH_SHARE * pd_v3_norm(change)
                                                  ? -vnAfter / vnBefore
                                                  : NAN,
                               .restitutionRequested = pd_model_pair_contact(model, bodyA, bodyB).restitution,
                               .tangentialChange = pd_v3_norm(tangential),
                               .match = -1});
}

static int impact_order(const void* pa, const void* pb) {
  const pdImpact *a = pa, *b = pb;
  if (a->t != b->t) return a->t < b->t ? -1 : 1;
  if (a->bodyA != b->bodyA) return a->bodyA < b->bodyA ? -1 : 1;
  return (a->bodyB > b->bodyB) - (a->bodyB < b->bodyB);
}

int pd_compare_impacts(const pdModel* model, const pdTrajectory* run, pdImpact** impacts) {
  impactList list = {0};
  double g = pd_v3_norm(model->settings.gravity);
  // intervals of every body in time order, so that an impact seen by both its bodies is found twice close by
  typedef struct span {
    long first, last, peak;
    int k;
  } span;
  span* spans = NULL;
  int spanCount = 0, spanCapacity = 0;
  for (int k = 0; k < run->movingCount; ++k) {
    long first = -1, peak = -1;
    double peakChange = 0.0;
    for (long s = 0; s + 1 < run->samples; ++s) {
      double dt = run->t[s + 1] - run->t[s];
      double change = speed_change(model, run, s, k);
      bool jump = change > fmax(PD_IMPACT_SPEED_CHANGE_OVER_G * g * dt, PD_IMPACT_MIN_SPEED_CHANGE);
      if (jump) {
        if (first < 0) first = s, peak = s, peakChange = change;
        else if (change > peakChange) peak = s, peakChange = change;
      }
      bool ends = first >= 0 && (!jump || s + 2 == run->samples);
      if (!ends) continue;
      if (spanCount == spanCapacity) {
        spanCapacity = spanCapacity ? 2 * spanCapacity : 32;
        spans = realloc(spans, (size_t)spanCapacity * sizeof *spans);
        if (!spans) abort();
      }
      spans[spanCount++] = (span){first, jump ? s : s - 1, peak, k};
      first = -1;
    }
  }
  // by the time of the largest change: the two bodies of one impact come next to each other
  for (int i = 1; i < spanCount; ++i)
    for (int j = i; j > 0 && (spans[j].peak < spans[j - 1].peak ||
                              (spans[j].peak == spans[j - 1].peak && spans[j].k < spans[j - 1].k)); --j) {
      span tmp = spans[j];
      spans[j] = spans[j - 1];
      spans[j - 1] = tmp;
    }
  for (int i = 0; i < spanCount; ++i)
    add_impact(model, run, spans[i].k, spans[i].first, spans[i].last, spans[i].peak, &list);
  free(spans);
  if (list.count > 1) qsort(list.items, (size_t)list.count, sizeof *list.items, impact_order);
  *impacts = list.items;
  return list.count;
}

void pd_compare_match_impacts(pdImpact* impacts, int count, const pdImpact* reference, int referenceCount) {
  for (int i = 0; i < count; ++i) impacts[i].match = -1;
  bool* taken = calloc((size_t)(referenceCount > 0 ? referenceCount : 1), sizeof *taken);
  if (!taken) abort();
  // nearest pairs first: repeatedly the closest free pair of the same bodies within the window
  for (;;) {
    int bi = -1, bj = -1;
    double best = PD_IMPACT_MATCH_WINDOW;
    for (int i = 0; i < count; ++i) {
      if (impacts[i].match >= 0) continue;
      for (int j = 0; j < referenceCount; ++j) {
        if (taken[j] || reference[j].bodyA != impacts[i].bodyA || reference[j].bodyB != impacts[i].bodyB) continue;
        double dt = fabs(reference[j].t - impacts[i].t);
        if (dt <= best && !(dt == best && bi >= 0)) best = dt, bi = i, bj = j;
      }
    }
    if (bi < 0) break;
    impacts[bi].match = bj;
    taken[bj] = true;
  }
  free(taken);
}

// ---- contact tallies ----

pdContactLog* pd_contact_log_create(const pdModel* model) {
  pdContactLog* log = calloc(1, sizeof *log);
  if (!log) abort();
  log->movingCount = model->movingCount;
  return log;
}

void pd_contact_log_free(pdContactLog* log) {
  if (!log) return;
  free(log->tallies);
  free(log->friction);
  free(log);
}

// The tallies of the next sample, zeroed.
static pdContactTally* next_row(pdContactLog* log) {
  size_t m = (size_t)(log->movingCount > 0 ? log->movingCount : 1);
  if (log->samples == log->capacity) {
    log->capacity = log->capacity ? 2 * log->capacity : 256;
    log->tallies = realloc(log->tallies, (size_t)log->capacity * m * sizeof *log->tallies);
    if (!log->tallies) abort();
  }
  pdContactTally* row = &log->tallies[(size_t)log->samples * m];
  for (size_t k = 0; k < m; ++k) row[k] = (pdContactTally){0, 0.0, NAN};
  return row;
}

static void add_contact(pdContactLog* log, pdContactTally* row, const pdModel* model, const pdState* state,
                        const pdContactReport* c) {
  pdVec3 rel = pd_v3_sub(pd_ref_point_velocity(model, state, c->bodyA, c->point),
                         pd_ref_point_velocity(model, state, c->bodyB, c->point));
  double slip = pd_v3_norm(pd_v3_sub(rel, pd_v3_scale(c->normal, pd_v3_dot(rel, c->normal))));
  const int ends[2] = {c->bodyA, c->bodyB};
  for (int e = 0; e < 2; ++e) {
    int k = model->bodies[ends[e]].stateIndex;
    if (k < 0) continue;
    row[k].contacts += 1;
    row[k].normalForce += c->fn;
    if (c->slip) row[k].slipSpeed = isnan(row[k].slipSpeed) ? slip : fmax(row[k].slipSpeed, slip);
  }
  if (!(c->fn > 0.0)) return;
  if (log->points == log->pointCapacity) {
    log->pointCapacity = log->pointCapacity ? 2 * log->pointCapacity : 1024;
    log->friction = realloc(log->friction, (size_t)log->pointCapacity * sizeof *log->friction);
    if (!log->friction) abort();
  }
  log->friction[log->points++] = (pdFrictionPoint){state->t, c->bodyA, c->bodyB, c->fn, pd_v3_norm(c->ft), slip, c->slip};
}

bool pd_contact_log_observe(const pdModel* model, const pdState* state, void* user) {
  pdContactLog* log = user;
  pdContactTally* row = next_row(log);
  int count = pd_state_contact_count(state);
  for (int i = 0; i < count; ++i) {
    pdContactReport c = pd_state_contact(state, i);
    add_contact(log, row, model, state, &c);
  }
  ++log->samples;
  return true;
}

void pd_contact_log_add(const pdModel* model, const pdState* state, const pdContactReport* contacts, int count,
                        void* user) {
  pdContactLog* log = user;
  pdContactTally* row = next_row(log);
  for (int i = 0; i < count; ++i) add_contact(log, row, model, state, &contacts[i]);
  ++log->samples;
}
