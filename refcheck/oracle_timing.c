// polydyn refcheck — the oracle's timing (`polydyn oracle --random N --seed S --timing`): our SAT and
// libccd's queries on the same random pairs, each timed over whole batches (pdref/oracle.h).
//
// Design
// - The pairs are drawn once (pd_oracle_random_pair, the oracle's generator), posed (rotation matrices and
//   libccd's scaled bodies) once, and sorted into groups by size (pdOracleTimingGroup). Nothing is set up,
//   allocated or freed inside a timed loop but what the timed function does itself (libccd's EPA allocates
//   its polytope).
// - A batch is one mode over one group's pairs, timed as a whole with the process's CPU clock (the machine
//   is shared: wall time would count the others). Every repeat goes round all modes and groups in turn, so
//   that a slow spell of the machine is spread over all of them; a mode's figure for all pairs is, per
//   repeat, the sum over the groups, and every figure quoted is the median over the repeats.
// - An untimed pass first warms the caches, fills the SAT caches of `ours_cached`, records the verdicts
//   (GJK's picks the overlapping pairs of the `_overlap` modes) and checks that our modes agree with each
//   other: the same verdict in all three searches, and, on overlapping pairs, the same depth to the bit (every
//   axis is evaluated there whatever the mode); the verdict mode separating only what they separate, and
//   calling touching only pairs they call apart by at most PD_ORACLE_VERDICT_BAND_MAX of its margins. It also hashes
//   every result field of our three modes but the work counter, so that two builds can be shown to give the same
//   results to the bit.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "interference.h"
#include "oracle_ccd.h"
#include "polydyn/error.h"
#include "pdref/oracle.h"
#include "pdrun/stats.h"

const char* const pdOracleTimingModeNames[pd_oracleTimingModeCount] = {
    "ours_first",  "ours_cached", "ours_min_depth",     "ccd_gjk",
    "ccd_gjk_epa", "ccd_mpr",     "ours_first_overlap", "ccd_gjk_epa_overlap", "ours_verdict", "ours_verdict_overlap",
};

// column heads of the printed table
static const char* const modeLabels[pd_oracleTimingModeCount] = {
    "first", "cached", "min_depth", "gjk", "gjk+epa", "mpr", "first(ov)", "gjk+epa(ov)", "verdict", "verdict(ov)",
};

const char* const pdOracleTimingGroupNames[pd_oracleTimingGroupCount] = {
    "cube-cube", "small", "medium", "large", "all",
};

typedef struct timedPair {
  pdOraclePair pair;
  pdMat3 RA, RB;
  ccdBody A, B;  // libccd's view; their `calls` point at `calls` below
  long calls;
  pdSatCache cache;  // ours_cached: the feature of the untimed pass's result
  bool gjk;          // GJK's verdict (the untimed pass)
  int group;
} timedPair;

static int group_of(const pdOraclePair* p) {
  if (strncmp(p->a.spec, "cube ", 5) == 0 && strncmp(p->b.spec, "cube ", 5) == 0) return pd_oracleTimingCubeCube;
  int v = p->a.poly.vertexCount > p->b.poly.vertexCount ? p->a.poly.vertexCount : p->b.poly.vertexCount;
  return v <= 32 ? pd_oracleTimingSmall : v <= 162 ? pd_oracleTimingMedium : pd_oracleTimingLarge;
}

// FNV-1a over bytes.
static uint64_t hash_bytes(uint64_t h, const void* data, size_t n) {
  const unsigned char* p = data;
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

static uint64_t hash_result(uint64_t h, const pdSatResult* r) {
  unsigned char sep = r->separated;
  int ints[3] = {(int)r->kind, r->a, r->b};
  h = hash_bytes(h, &sep, 1);
  h = hash_bytes(h, &r->depth, sizeof r->depth);
  h = hash_bytes(h, &r->axis, sizeof r->axis);
  return hash_bytes(h, ints, sizeof ints);
}

// The bodies' radii about their origins plus the origins' distances from the world's, m: at least a third of
// the size that PD_SAT_VERDICT's margin is relative to (interference.c, cull_bounds).
static double pair_scale(const pdOraclePair* p) {
  const pdOracleBody* body[2] = {&p->bodyA, &p->bodyB};
  double scale = 0.0;
  for (int k = 0; k < 2; ++k) {
    double r = 0.0;
    for (int v = 0; v < body[k]->shape->vertexCount; ++v) r = fmax(r, pd_v3_norm(body[k]->shape->vertices[v]));
    scale += r + pd_v3_norm(body[k]->x);
  }
  return scale;
}

static bool ours(timedPair* t, pdSatMode mode, pdSatCache* cache, pdSatResult* r) {
  const pdOracleBody *a = &t->pair.bodyA, *b = &t->pair.bodyB;
  return pd_interference(a->shape, a->x, &t->RA, b->shape, b->x, &t->RB, mode, cache, r);
}

// One batch: `mode` over pairs[idx[0..n)]. Returns a sum of the answers (so nothing is optimised away).
static double run_batch(timedPair* pairs, const int* idx, int n, int mode, const ccd_t* ccd) {
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    timedPair* t = &pairs[idx[k]];
    pdSatResult r;
    ccd_real_t depth = 0.0;
    ccd_vec3_t dir, pos;
    t->calls = 0;
    switch (mode) {
      case pd_oracleTimingFirst:
      case pd_oracleTimingFirstOverlap:
        sum += ours(t, PD_SAT_FIRST_SEPARATING, NULL, &r);
        break;
      case pd_oracleTimingCached: {
        pdSatCache c = t->cache;  // the same warm cache every repeat
        sum += ours(t, PD_SAT_FIRST_SEPARATING, &c, &r);
        break;
      }
      case pd_oracleTimingMinDepth:
        sum += ours(t, PD_SAT_MIN_DEPTH, NULL, &r);
        break;
      case pd_oracleTimingVerdict:
      case pd_oracleTimingVerdictOverlap:
        sum += ours(t, PD_SAT_VERDICT, NULL, &r);
        break;
      case pd_oracleTimingGjk:
        sum += ccdGJKIntersect(&t->A, &t->B, ccd);
        break;
      case pd_oracleTimingGjkEpa:
      case pd_oracleTimingGjkEpaOverlap:
        sum += ccdGJKPenetration(&t->A, &t->B, ccd, &depth, &dir, &pos) + depth;
        break;
      case pd_oracleTimingMpr:
        sum += ccdMPRIntersect(&t->A, &t->B, ccd);
        break;
    }
  }
  return sum;
}

static bool overlap_mode(int mode) {
  return mode == pd_oracleTimingFirstOverlap || mode == pd_oracleTimingGjkEpaOverlap ||
         mode == pd_oracleTimingVerdictOverlap;
}

bool pd_oracle_timing(long n, uint64_t seed, int repeats, pdOracleTiming* out) {
  PD_ASSERT(n > 0 && repeats > 0 && out != NULL);
  memset(out, 0, sizeof *out);
  out->pairCount = n;
  out->repeats = repeats;
  timedPair* pairs = calloc((size_t)n, sizeof *pairs);
  int* idx[2][pd_oracleTimingGroupCount];  // [overlap only][group]
  for (int s = 0; s < 2; ++s)
    for (int g = 0; g < pd_oracleTimingGroupCount; ++g) idx[s][g] = malloc((size_t)n * sizeof(int));
  double* seconds = calloc((size_t)repeats * pd_oracleTimingModeCount * pd_oracleTimingGroupCount, sizeof(double));
  PD_ASSERT(pairs != NULL && seconds != NULL);
  int count[2][pd_oracleTimingGroupCount] = {{0}};

  // draw, pose and group the pairs
  pdOracleRng g;
  pd_oracle_rng_seed(&g, seed);
  ccd_t ccd;
  pd_oracle_ccd_init(&ccd);
  for (long i = 0; i < n; ++i) {
    timedPair* t = &pairs[i];
    pd_oracle_random_pair(&g, &t->pair);
    const pdOracleBody *a = &t->pair.bodyA, *b = &t->pair.bodyB;
    t->RA = pd_quat_to_mat3(a->q);
    t->RB = pd_quat_to_mat3(b->q);
    shapeMeasures ma = pd_oracle_measure(a->shape), mb = pd_oracle_measure(b->shape);
    pd_oracle_ccd_pair(a, b, &t->RA, &t->RB, &ma, &mb, &t->calls, &t->A, &t->B);
    t->group = group_of(&t->pair);
    out->groups[t->group].meanVertices += 0.5 * (a->shape->vertexCount + b->shape->vertexCount);
    out->groups[t->group].meanEdges += 0.5 * (a->shape->edgeCount + b->shape->edgeCount);
  }

  // the untimed pass: verdicts, caches, agreement of our modes, the result hash
  bool agree = true;
  uint64_t hash = 1469598103934665603ull;
  for (long i = 0; i < n; ++i) {
    timedPair* t = &pairs[i];
    pdSatResult first, cached, min, verdict;
    pdSatCache c = {PD_SAT_NONE, -1, -1, {0, 0, 0}};
    bool hit = ours(t, PD_SAT_FIRST_SEPARATING, NULL, &first);
    ours(t, PD_SAT_FIRST_SEPARATING, &c, &cached);  // fills the cache (the same result as `first`)
    t->cache = c;
    ours(t, PD_SAT_FIRST_SEPARATING, &c, &cached);  // from the warm cache
    ours(t, PD_SAT_MIN_DEPTH, NULL, &min);
    ours(t, PD_SAT_VERDICT, NULL, &verdict);
    if (first.separated != min.separated || cached.separated != min.separated ||
        (!min.separated && (first.depth != min.depth || cached.depth != min.depth)))
      agree = false;
    // the verdict mode separates only what the search separates, and may call touching a pair the search calls
    // apart by up to about its margin (interference.h, PD_SAT_VERDICT)
    if (verdict.separated && !first.separated) agree = false;
    if (!verdict.separated && first.separated) {
      double band = -min.depth / (PD_GJK_MARGIN_REL * pair_scale(&t->pair));
      ++out->verdictWithinMargin;
      out->verdictBandMax = fmax(out->verdictBandMax, band);
      if (!(band <= PD_ORACLE_VERDICT_BAND_MAX)) agree = false;
    }
    hash = hash_result(hash_result(hash_result(hash, &first), &cached), &min);
    out->oursOverlap += hit;
    t->calls = 0;
    t->gjk = ccdGJKIntersect(&t->A, &t->B, &ccd) != 0;
    out->ccdStalled += t->calls > PD_ORACLE_SUPPORT_CAP;
    out->gjkOverlap += t->gjk;
    for (int s = 0; s < 2; ++s) {
      if (s == 1 && !t->gjk) continue;
      idx[s][t->group][count[s][t->group]++] = (int)i;
      idx[s][pd_oracleTimingAll][count[s][pd_oracleTimingAll]++] = (int)i;
    }
  }
  out->resultHash = hash;
  for (int m = 0; m < pd_oracleTimingModeCount; ++m)
    for (int k = 0; k < pd_oracleTimingGroupCount; ++k)
      run_batch(pairs, idx[overlap_mode(m)][k], count[overlap_mode(m)][k], m, &ccd);

  // the timed repeats: round-robin over modes and groups (not "all": it is the sum of the groups)
  double checksum = 0.0;
  for (int r = 0; r < repeats; ++r)
    for (int m = 0; m < pd_oracleTimingModeCount; ++m)
      for (int k = 0; k < pd_oracleTimingAll; ++k) {
        int s = overlap_mode(m);
        double t0 = pd_oracle_cpu_seconds();
        checksum += run_batch(pairs, idx[s][k], count[s][k], m, &ccd);
        double dt = pd_oracle_cpu_seconds() - t0;
        seconds[((size_t)r * pd_oracleTimingModeCount + m) * pd_oracleTimingGroupCount + k] = dt;
        seconds[((size_t)r * pd_oracleTimingModeCount + m) * pd_oracleTimingGroupCount + pd_oracleTimingAll] += dt;
      }
  out->checksum = checksum;

  // medians per pair, µs
  double* v = malloc((size_t)repeats * sizeof *v);
  PD_ASSERT(v != NULL);
  for (int k = 0; k < pd_oracleTimingGroupCount; ++k) {
    pdOracleTimingGroup* grp = &out->groups[k];
    grp->pairs = count[0][k];
    grp->overlapping = count[1][k];
    if (k != pd_oracleTimingAll && grp->pairs > 0) {
      grp->meanVertices /= grp->pairs;
      grp->meanEdges /= grp->pairs;
    }
    for (int m = 0; m < pd_oracleTimingModeCount; ++m) {
      int pairsInBatch = count[overlap_mode(m)][k];
      if (pairsInBatch == 0) continue;
      for (int r = 0; r < repeats; ++r)
        v[r] = 1e6 * seconds[((size_t)r * pd_oracleTimingModeCount + m) * pd_oracleTimingGroupCount + k] / pairsInBatch;
      grp->usPerPair[m] = pd_median_in_place(v, repeats);  // sorts v: its ends are the extremes
      grp->usMin[m] = v[0];
      grp->usMax[m] = v[repeats - 1];
    }
  }
  // the means over all pairs
  pdOracleTimingGroup* all = &out->groups[pd_oracleTimingAll];
  for (int k = 0; k < pd_oracleTimingAll; ++k) {
    all->meanVertices += out->groups[k].meanVertices * out->groups[k].pairs / (double)n;
    all->meanEdges += out->groups[k].meanEdges * out->groups[k].pairs / (double)n;
  }
  free(v);
  free(seconds);
  for (int s = 0; s < 2; ++s)
    for (int k = 0; k < pd_oracleTimingGroupCount; ++k) free(idx[s][k]);
  for (long i = 0; i < n; ++i) pd_oracle_pair_free(&pairs[i].pair);
  free(pairs);
  out->oursAgree = agree;
  return agree;
}

void pd_oracle_timing_print(const pdOracleTiming* t, FILE* out) {
  fprintf(out, "timing: %ld pairs, %d repeats; CPU time of whole batches, median over the repeats, us per pair\n",
          t->pairCount, t->repeats);
  fprintf(out, "overlapping: ours %ld, GJK %ld; libccd stalled %ld (support-call cap)\n", t->oursOverlap, t->gjkOverlap,
          t->ccdStalled);
  fprintf(out, "our modes agree (verdicts, and depths of overlapping pairs): %s; result hash %016llx (first, cached, min_depth)\n",
          t->oursAgree ? "yes" : "NO", (unsigned long long)t->resultHash);
  fprintf(out,
          "verdict: touching within its margin on %ld pairs that the search calls apart, by at most %.3g x "
          "PD_GJK_MARGIN_REL x the pair's scale (allowed %g)\n",
          t->verdictWithinMargin, t->verdictBandMax, PD_ORACLE_VERDICT_BAND_MAX);
  fprintf(out,
          "groups by the larger body's vertex count V: cube-cube (both cubes), small V <= 32 (other), medium\n"
          "V <= 162, large V > 162 (geodesic spheres of level 3); (ov): only the pairs GJK calls overlapping;\n"
          "first: ours as the engine calls it (first separating axis), cached: the same from a warm cache,\n"
          "min_depth: every axis; verdict: ours as the contact search calls it (GJK's certificates; touching\n"
          "within its margin); gjk, gjk+epa, mpr: libccd's ccdGJKIntersect, ccdGJKPenetration, ccdMPRIntersect\n");
  fprintf(out, "%-16s %6s %6s %6s", "group", "pairs", "mean V", "mean E");
  for (int m = 0; m < pd_oracleTimingModeCount; ++m) fprintf(out, " %11s", modeLabels[m]);
  fputc('\n', out);
  for (int k = 0; k < pd_oracleTimingGroupCount; ++k) {
    const pdOracleTimingGroup* g = &t->groups[k];
    if (g->pairs == 0) continue;
    fprintf(out, "%-16s %6ld %6.1f %6.1f", pdOracleTimingGroupNames[k], g->pairs, g->meanVertices, g->meanEdges);
    for (int m = 0; m < pd_oracleTimingModeCount; ++m) fprintf(out, " %11.3f", g->usPerPair[m]);
    fputc('\n', out);
  }
  fprintf(out, "ratios to GJK alone (ccd_gjk) and, for our first-separating mode, to GJK + EPA:\n");
  fprintf(out, "%-16s %11s %11s %11s %11s %11s %11s %11s\n", "group", "first/gjk", "cached/gjk", "min/gjk", "mpr/gjk",
          "first/g+epa", "(ov)", "verdict/gjk");
  for (int k = 0; k < pd_oracleTimingGroupCount; ++k) {
    const pdOracleTimingGroup* g = &t->groups[k];
    if (g->pairs == 0) continue;
    const double* u = g->usPerPair;
    double gjk = u[pd_oracleTimingGjk];
    double ov =
        u[pd_oracleTimingGjkEpaOverlap] > 0.0 ? u[pd_oracleTimingFirstOverlap] / u[pd_oracleTimingGjkEpaOverlap] : NAN;
    fprintf(out, "%-16s %11.2f %11.2f %11.2f %11.2f %11.2f %11.2f %11.2f\n", pdOracleTimingGroupNames[k],
            u[pd_oracleTimingFirst] / gjk, u[pd_oracleTimingCached] / gjk, u[pd_oracleTimingMinDepth] / gjk,
            u[pd_oracleTimingMpr] / gjk, u[pd_oracleTimingFirst] / u[pd_oracleTimingGjkEpa], ov,
            u[pd_oracleTimingVerdict] / gjk);
  }
}

void pd_oracle_timing_csv(const pdOracleTiming* t, FILE* out) {
  fprintf(out, "group,mode,pairs,repeats,us_per_pair_median,us_per_pair_min,us_per_pair_max,ratio_to_gjk\n");
  for (int k = 0; k < pd_oracleTimingGroupCount; ++k) {
    const pdOracleTimingGroup* g = &t->groups[k];
    if (g->pairs == 0) continue;
    for (int m = 0; m < pd_oracleTimingModeCount; ++m) {
      long pairs = overlap_mode(m) ? g->overlapping : g->pairs;
      if (pairs == 0) continue;
      fprintf(out, "%s,%s,%ld,%d,%.4f,%.4f,%.4f,%.4f\n", pdOracleTimingGroupNames[k], pdOracleTimingModeNames[m], pairs,
              t->repeats, g->usPerPair[m], g->usMin[m], g->usMax[m],
              g->usPerPair[m] / g->usPerPair[pd_oracleTimingGjk]);
    }
  }
}
