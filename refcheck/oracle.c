// polydyn refcheck — the interference oracle: one pair checked by our SAT and by libccd, and the
// statistics over many pairs (conventions and tolerances in pdref/oracle.h).
//
// Design
// - libccd sees each body through a support function over its vertices (a linear scan, as our SAT
//   does), in coordinates moved to the midpoint of the two centres and divided by the pair's scale
//   r_A + r_B. libccd compares squared distances with DBL_EPSILON and EPA's tolerance with products
//   of distances, all absolute: in these coordinates they mean the same for a 1 cm pair as for a 10 m
//   one, and the touching band can be stated relative to the scale.
// - The four libccd queries (GJK and MPR booleans, EPA depth when GJK overlaps, MPR depth when MPR
//   overlaps) each run with a fresh support-call budget; see PD_ORACLE_SUPPORT_CAP.
#include "pdref/oracle.h"

#include <ccd/ccd.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "interference.h"
#include "oracle_ccd.h"
#include "polydyn/error.h"
#include "pdrun/stats.h"
#include "pdutil/clock.h"

const char* const pdOracleKindNames[pd_oracleKindCount] = {
    "agree_overlap", "agree_separate", "we_overlap", "we_separate", "touching", "mpr_differs", "depth", "ccd_stalled",
};

double pd_oracle_cpu_seconds(void) { return pd_process_cpu_seconds(); }

void pd_oracle_ccd_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const ccdBody* b = obj;
  pdVec3 p = b->centre;
  // past the budget answer the centre: every libccd loop then finds no progress and stops
  if (++*b->calls <= PD_ORACLE_SUPPORT_CAP) {
    // Rs is R / scale: the direction's length does not matter
    pdVec3 d = pd_mat3_tmulv(&b->Rs, (pdVec3){dir->v[0], dir->v[1], dir->v[2]});
    const pdVec3* v = b->shape->vertices;
    int best = 0;
    double hi = pd_v3_dot(d, v[0]);
    for (int i = 1; i < b->shape->vertexCount; ++i) {
      double h = pd_v3_dot(d, v[i]);
      if (h > hi) {
        hi = h;
        best = i;
      }
    }
    p = pd_v3_add(b->origin, pd_mat3_mulv(&b->Rs, v[best]));
  }
  out->v[0] = p.x;
  out->v[1] = p.y;
  out->v[2] = p.z;
}

void pd_oracle_ccd_centre(const void* obj, ccd_vec3_t* out) {
  const ccdBody* b = obj;
  out->v[0] = b->centre.x;
  out->v[1] = b->centre.y;
  out->v[2] = b->centre.z;
}

shapeMeasures pd_oracle_measure(const pdPolyhedron* p) {
  shapeMeasures m = {{0, 0, 0}, 0.0, 0.0};
  pdVec3 lo = p->vertices[0], hi = p->vertices[0];
  for (int i = 0; i < p->vertexCount; ++i) {
    pdVec3 v = p->vertices[i];
    m.average = pd_v3_add(m.average, v);
    lo = (pdVec3){fmin(lo.x, v.x), fmin(lo.y, v.y), fmin(lo.z, v.z)};
    hi = (pdVec3){fmax(hi.x, v.x), fmax(hi.y, v.y), fmax(hi.z, v.z)};
  }
  m.average = pd_v3_scale(m.average, 1.0 / p->vertexCount);
  for (int i = 0; i < p->vertexCount; ++i) m.radius = fmax(m.radius, pd_v3_norm(pd_v3_sub(p->vertices[i], m.average)));
  m.size = ((hi.x - lo.x) + (hi.y - lo.y) + (hi.z - lo.z)) / 3.0;
  return m;
}

static ccdBody ccd_body(const pdOracleBody* b, const pdMat3* R, const shapeMeasures* m, pdVec3 origin, double scale,
                        long* calls) {
  ccdBody c;
  c.shape = b->shape;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.Rs.m[i][j] = R->m[i][j] / scale;
  c.origin = pd_v3_scale(pd_v3_sub(b->x, origin), 1.0 / scale);
  c.centre = pd_v3_add(c.origin, pd_mat3_mulv(&c.Rs, m->average));
  c.calls = calls;
  return c;
}

double pd_oracle_ccd_pair(const pdOracleBody* a, const pdOracleBody* b, const pdMat3* RA, const pdMat3* RB,
                          const shapeMeasures* ma, const shapeMeasures* mb, long* calls, ccdBody* A, ccdBody* B) {
  double scale = ma->radius + mb->radius;
  pdVec3 ca = pd_v3_add(a->x, pd_mat3_mulv(RA, ma->average)), cb = pd_v3_add(b->x, pd_mat3_mulv(RB, mb->average));
  pdVec3 origin = pd_v3_scale(pd_v3_add(ca, cb), 0.5);
  *A = ccd_body(a, RA, ma, origin, scale, calls);
  *B = ccd_body(b, RB, mb, origin, scale, calls);
  return scale;
}

void pd_oracle_ccd_init(ccd_t* ccd) {
  CCD_INIT(ccd);
  ccd->support1 = pd_oracle_ccd_support;
  ccd->support2 = pd_oracle_ccd_support;
  ccd->center1 = pd_oracle_ccd_centre;
  ccd->center2 = pd_oracle_ccd_centre;
  ccd->max_iterations = PD_ORACLE_GJK_ITERATIONS;
}

typedef int penetrationFcn(const void* o1, const void* o2, const ccd_t* ccd, ccd_real_t* depth, ccd_vec3_t* dir,
                           ccd_vec3_t* pos);

// A libccd depth query (EPA or MPR), in m: false when it fails or its depth is not finite and >= 0
// (exact touching gives depth 0 with a NaN direction, which is never read). Sets *stalled when the
// query ran out of support calls.
static bool ccd_depth(penetrationFcn* query, const ccdBody* A, const ccdBody* B, const ccd_t* ccd, double scale,
                      bool* stalled, double* depth) {
  ccd_real_t d = 0.0;
  ccd_vec3_t dir, pos;
  *A->calls = 0;
  bool ok = query(A, B, ccd, &d, &dir, &pos) == 0 && isfinite(d) && d >= 0.0;
  *stalled = *A->calls > PD_ORACLE_SUPPORT_CAP;
  *depth = ok ? d * scale : 0.0;
  return ok && !*stalled;
}

// EPA at PD_ORACLE_EPA_TOL, retried looser when it cycles (see oracle.h).
static void epa(const ccdBody* A, const ccdBody* B, ccd_t* ccd, pdOracleResult* out) {
  double tol = PD_ORACLE_EPA_TOL;
  for (int attempt = 0; attempt <= PD_ORACLE_EPA_RETRIES; ++attempt, tol *= 100.0) {
    ccd->epa_tolerance = tol;
    bool stalled;
    out->hasEpa = ccd_depth(ccdGJKPenetration, A, B, ccd, out->scale, &stalled, &out->epaDepth);
    if (!stalled) {
      // a depth below the band is EPA calling the pair touching: held to the bound at the band's edge
      double d = fmax(out->epaDepth / out->scale, PD_ORACLE_TOUCH_REL);
      out->epaTol = out->hasEpa ? tol : 0.0;
      out->epaBound = out->hasEpa ? out->scale * fmax(tol / d, sqrt(tol)) : 0.0;
      return;
    }
  }
  out->stalled = true;
  out->epaDepth = 0.0;
}

static pdOracleKind classify(const pdOracleResult* r) {
  if (r->stalled || (r->gjk && !r->hasEpa)) return pd_oracleStalled;
  if (r->ours != r->gjk || r->ours != r->mpr) {
    if (r->touching) return pd_oracleTouching;
    if (r->ours != r->gjk) return r->ours ? pd_oracleWeOverlap : pd_oracleWeSeparate;
    return pd_oracleMprDiffers;
  }
  if (!r->ours) return pd_oracleAgreeSeparate;
  // EPA's depth against ours wherever ours is outside the band (an EPA depth near 0 included)
  if (r->ourDepth >= PD_ORACLE_TOUCH_REL * r->scale && fabs(r->epaDepth - r->ourDepth) > r->epaBound)
    return pd_oracleDepth;
  return pd_oracleAgreeOverlap;
}

void pd_oracle_check(const pdOracleBody* a, const pdOracleBody* b, pdOracleResult* out) {
  PD_ASSERT(a != NULL && b != NULL && out != NULL && a->shape != NULL && b->shape != NULL);
  PD_ASSERT(a->shape->vertexCount > 0 && b->shape->vertexCount > 0);
  memset(out, 0, sizeof *out);
  pdMat3 RA = pd_quat_to_mat3(a->q), RB = pd_quat_to_mat3(b->q);
  shapeMeasures ma = pd_oracle_measure(a->shape), mb = pd_oracle_measure(b->shape);
  out->scale = ma.radius + mb.radius;
  out->size = fmin(ma.size, mb.size);

  // ours: every candidate axis, so the depth is the minimum whether separated or not
  double t0 = pd_oracle_cpu_seconds();
  pdSatResult sat;
  out->ours = pd_interference(a->shape, a->x, &RA, b->shape, b->x, &RB, PD_SAT_MIN_DEPTH, NULL, &sat);
  out->ourDepth = sat.depth;
  double t1 = pd_oracle_cpu_seconds();

  // libccd, in coordinates about the midpoint of the centres, divided by the scale
  long calls = 0;
  ccdBody A, B;
  pd_oracle_ccd_pair(a, b, &RA, &RB, &ma, &mb, &calls, &A, &B);
  ccd_t ccd;
  pd_oracle_ccd_init(&ccd);
  ccd.mpr_tolerance = PD_ORACLE_MPR_TOL;

  // each query with a fresh support budget
  calls = 0;
  out->gjk = ccdGJKIntersect(&A, &B, &ccd) != 0;
  bool stalled = calls > PD_ORACLE_SUPPORT_CAP;
  calls = 0;
  out->mpr = ccdMPRIntersect(&A, &B, &ccd) != 0;
  stalled = stalled || calls > PD_ORACLE_SUPPORT_CAP;
  // depths only from usable verdicts; an MPR depth that stalls is only missing (counted in the stats)
  if (out->gjk && !stalled) epa(&A, &B, &ccd, out);
  if (out->mpr && !stalled) {
    bool mprStalled;
    out->hasMprDepth = ccd_depth(ccdMPRPenetration, &A, &B, &ccd, out->scale, &mprStalled, &out->mprDepth);
  }
  out->stalled = out->stalled || stalled;
  double t2 = pd_oracle_cpu_seconds();

  double band = PD_ORACLE_TOUCH_REL * out->scale;
  out->touching = fabs(out->ourDepth) < band || (out->hasEpa && out->epaDepth < band);
  out->kind = classify(out);
  out->secondsOurs = t1 - t0;
  out->secondsCcd = t2 - t1;
}

// ---------------------------------------------------------------- statistics

static void sample_push(pdOracleSample* s, double v) {
  if (s->count == s->capacity) {
    s->capacity = s->capacity ? 2 * s->capacity : 1024;
    s->v = realloc(s->v, (size_t)s->capacity * sizeof *s->v);
    PD_ASSERT(s->v != NULL);
  }
  s->v[s->count++] = v;
}

void pd_oracle_stats_init(pdOracleStats* s) { memset(s, 0, sizeof *s); }

void pd_oracle_stats_free(pdOracleStats* s) {
  free(s->epaError.v);
  free(s->mprError.v);
  free(s->ourDepth.v);
  free(s->epaErrorInBand.v);
  memset(s, 0, sizeof *s);
}

void pd_oracle_stats_add(pdOracleStats* s, const pdOracleResult* r) {
  ++s->pairs;
  ++s->kinds[r->kind];
  if (r->hasEpa && r->epaTol > PD_ORACLE_EPA_TOL) ++s->epaRetried;
  if (r->kind == pd_oracleDepth && r->hasMprDepth && fabs(r->mprDepth - r->ourDepth) <= r->epaBound) ++s->depthMprAgrees;
  if (r->touching) ++s->inBand;
  if (!r->stalled && r->gjk != r->mpr) ++s->gjkMprDiffer;
  s->secondsOurs += r->secondsOurs;
  s->secondsCcd += r->secondsCcd;
  if (!(r->ours && r->gjk && r->hasEpa)) return;
  // split by our depth: an EPA depth near 0 on a pair we find deep is an EPA error, not touching
  if (r->ourDepth < PD_ORACLE_TOUCH_REL * r->scale) {
    sample_push(&s->epaErrorInBand, (r->epaDepth - r->ourDepth) / r->size);
    return;
  }
  sample_push(&s->epaError, (r->epaDepth - r->ourDepth) / r->size);
  sample_push(&s->ourDepth, r->ourDepth / r->size);
  if (r->mpr && r->hasMprDepth)
    sample_push(&s->mprError, (r->mprDepth - r->ourDepth) / r->size);
  else if (r->mpr)
    ++s->mprDepthMissing;
}

long pd_oracle_stats_failures(const pdOracleStats* s) {
  return s->kinds[pd_oracleWeOverlap] + s->kinds[pd_oracleWeSeparate];
}

// max, median and 99th percentile (nearest rank) of |v|, and the signed extremes
static void print_errors(FILE* out, const char* label, const pdOracleSample* s) {
  if (s->count == 0) {
    fprintf(out, "%s: no pairs\n", label);
    return;
  }
  double* a = malloc((size_t)s->count * sizeof *a);
  PD_ASSERT(a != NULL);
  double lo = s->v[0], hi = s->v[0];
  for (long i = 0; i < s->count; ++i) {
    a[i] = fabs(s->v[i]);
    lo = fmin(lo, s->v[i]);
    hi = fmax(hi, s->v[i]);
  }
  pd_sort_doubles(a, (size_t)s->count);
  long p99 = (long)ceil(0.99 * (double)s->count) - 1;
  fprintf(out, "%s: max %.3g, median %.3g, p99 %.3g (signed: %.3g to %.3g; %ld pairs)\n", label, a[s->count - 1],
          a[(s->count - 1) / 2], a[p99], lo, hi, s->count);
  free(a);
}

void pd_oracle_stats_print(const pdOracleStats* s, FILE* out) {
  const long* k = s->kinds;
  fprintf(out, "pairs checked: %ld\n", s->pairs);
  fprintf(out, "agree: both overlap %ld, both separate %ld\n", k[pd_oracleAgreeOverlap] + k[pd_oracleDepth],
          k[pd_oracleAgreeSeparate]);
  fprintf(out, "disagree with libccd's verdict (GJK) outside the touching band (%g x scale):\n", PD_ORACLE_TOUCH_REL);
  fprintf(out, "  we overlap, GJK separates: %ld\n", k[pd_oracleWeOverlap]);
  fprintf(out, "  we separate, GJK overlaps: %ld\n", k[pd_oracleWeSeparate]);
  fprintf(out, "MPR differs from ours and GJK outside the band: %ld (libccd against itself, not failures)\n",
          k[pd_oracleMprDiffers]);
  fprintf(out, "touching band: %ld pairs inside, verdicts differ on %ld (not failures)\n", s->inBand,
          k[pd_oracleTouching]);
  fprintf(out, "GJK and MPR verdicts differ: %ld (any band)\n", s->gjkMprDiffer);
  fprintf(out, "not compared (libccd stalled or EPA gave no depth): %ld\n", k[pd_oracleStalled]);
  fprintf(out, "EPA answered only at a looser tolerance (it cycles at %g): %ld\n", PD_ORACLE_EPA_TOL, s->epaRetried);
  fprintf(out, "depth outliers (|EPA - ours| beyond EPA's own error bound, our depth outside the band): %ld, "
               "MPR's depth agrees with ours on %ld of them\n", k[pd_oracleDepth], s->depthMprAgrees);
  fprintf(out, "depth errors over the pairs ours, GJK and EPA call overlapping, relative to the smaller body's size,\n"
               "with our depth outside or inside the band:\n");
  print_errors(out, "  |EPA - ours|, outside", &s->epaError);
  print_errors(out, "  |EPA - ours|, inside", &s->epaErrorInBand);
  print_errors(out, "  |MPR - ours|, outside (MPR: along its portal, not the minimum)", &s->mprError);
  if (s->mprDepthMissing) fprintf(out, "  (MPR overlapped but gave no depth on %ld of these pairs)\n", s->mprDepthMissing);
  print_errors(out, "  ours, outside", &s->ourDepth);
  double n = s->pairs > 0 ? (double)s->pairs : 1.0;
  fprintf(out, "time (CPU): ours %.3f s (%.1f us/pair), libccd %.3f s (%.1f us/pair)\n", s->secondsOurs,
          1e6 * s->secondsOurs / n, s->secondsCcd, 1e6 * s->secondsCcd / n);
  fprintf(out, "verdict: %s\n", pd_oracle_stats_failures(s) ? "FAIL (disagreements outside the touching band)" : "ok");
}
