// polydyn — the contact search at the end of a trial step (paper §4.2–§4.4): the broad phase over the step, the
// tunnelling guard (travel), the interference test of every listed pair, its search certificates (contact_analysis.h)
// and the contact search of the touching ones, which yields the candidates: the contacts of C1 that C0 lacks.
//
// The per-pair loops are split with a help desk when long enough (help_desk.h); each pair's numbers are the same on
// any thread, and the candidates are merged in pair order. The arrays grow here between steps, never inside a
// derivative.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_list.h"
#include "grow.h"
#include "model_contact.h"
#include "onsets.h"

// Tunnelling guard: over one step, two bodies whose swept boxes overlap may move relative to each other by
// at most this fraction of the thinner one's width. A quarter keeps a vertex that crossed a face within
// the first half of the body, so the face it crossed is still the nearest one and the contact is found
// with the right face; the step is retried shorter (with a little safety) otherwise.
#define PD_TRAVEL_WIDTH_FRACTION 0.25
// ... and by at most this many of the pair's design deflections δ_max: a vertex that sank deeper than its
// distance to the border of the face it crossed finds a side face nearest, and the contact is missed (a
// cube landing with its corners a few mm inside a face's border, at 1 m/s and 10 ms steps). Two δ_max
// keeps the sinking within the deflection the springs are designed for; the onset retry then finds the
// moment of contact. It costs steps only while two bodies' swept boxes overlap.
#define PD_TRAVEL_DEFLECTIONS 2.0
#define PD_TRAVEL_RETRY_SAFETY 0.9

// The contact search's per-pair lists, to cacheCapacity.
static void grow_pair_lists(pdContactSet* set) {
  set->certified = pd_grow(set->certified, set->cacheCapacity, sizeof *set->certified);
  set->certs = pd_grow(set->certs, set->cacheCapacity, sizeof *set->certs);
  set->certsNext = pd_grow(set->certsNext, set->cacheCapacity, sizeof *set->certsNext);
  set->pairPrevious = pd_grow(set->pairPrevious, set->cacheCapacity, sizeof *set->pairPrevious);
  set->pairPreviousCount = pd_grow(set->pairPreviousCount, set->cacheCapacity, sizeof *set->pairPreviousCount);
  set->pairFound = pd_grow(set->pairFound, set->cacheCapacity, sizeof *set->pairFound);
  set->pairFoundCount = pd_grow(set->pairFoundCount, set->cacheCapacity, sizeof *set->pairFoundCount);
}

void pd_contact_search_create(const pdModel* model, pdContactSet* set, const bool* fixed) {
  int n = model->bodyCount;
  set->broad = pd_broad_phase_create(n, fixed, 0.0);
  PD_ASSERT(set->broad != NULL);
  set->candidateCapacity = 64;
  set->candidates = pd_grow(NULL, set->candidateCapacity, sizeof *set->candidates);
  for (int part = 0; part < 2; ++part) {
    set->search[part].foundCapacity = 64;
    set->search[part].found = pd_grow(NULL, set->search[part].foundCapacity, sizeof *set->search[part].found);
  }
  set->pairCapacity = 2 * n + 16;
  set->pairs = pd_grow(NULL, set->pairCapacity, sizeof *set->pairs);
  set->cacheCapacity = set->pairCapacity;
  set->cache = pd_grow(NULL, set->cacheCapacity, sizeof *set->cache);
  set->cacheNext = pd_grow(NULL, set->cacheCapacity, sizeof *set->cacheNext);
  set->touching = pd_grow(NULL, set->cacheCapacity, sizeof *set->touching);
  grow_pair_lists(set);
}

void pd_contact_search_free(pdContactSet* set) {
  free(set->candidates);
  for (int part = 0; part < 2; ++part) free(set->search[part].found);
  pd_broad_phase_free(set->broad);
  free(set->pairs);
  free(set->cache);
  free(set->cacheNext);
  free(set->touching);
  free(set->pairPrevious);
  free(set->pairPreviousCount);
  free(set->pairFound);
  free(set->pairFoundCount);
  free(set->certs);
  free(set->certified);
  free(set->certsNext);
}

static void add_candidate(pdContactSet* set, const candidate* c) {
  if (set->candidateCount == set->candidateCapacity) {
    set->candidateCapacity *= 2;
    set->candidates = pd_grow(set->candidates, set->candidateCapacity, sizeof *set->candidates);
  }
  set->candidates[set->candidateCount++] = *c;
}

// Broad phase over the step: each moving body's box covers its boxes at both ends of the step, so a pair
// that met and parted (or tunnelled) inside the step is listed too. Returns the number of pairs.
int pd_contact_search_broad_phase(const pdModel* model, pdContactSet* set, const pdPose* poses0,
                                  const pdPose* poses1) {
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    pdAabb a = pd_aabb_of(&model->bodies[i].shape, poses0[i].x, &poses0[i].R);
    pdAabb b = pd_aabb_of(&model->bodies[i].shape, poses1[i].x, &poses1[i].R);
    for (int d = 0; d < 3; ++d) a.lo[d] = fmin(a.lo[d], b.lo[d]), a.hi[d] = fmax(a.hi[d], b.hi[d]);
    set->boxes[i] = a;
  }
  // grown between steps: the analysis runs after a step, outside the derivative
  int pairCount = pd_broad_phase_pairs_grown(set->broad, set->boxes, &set->pairs, &set->pairCapacity);
  if (pairCount > set->cacheCapacity) {
    set->cacheCapacity = set->pairCapacity;
    set->cache = pd_grow(set->cache, set->cacheCapacity, sizeof *set->cache);
    set->cacheNext = pd_grow(set->cacheNext, set->cacheCapacity, sizeof *set->cacheNext);
    set->touching = pd_grow(set->touching, set->cacheCapacity, sizeof *set->touching);
    grow_pair_lists(set);
  }
  return pairCount;
}

// How far body i's points move at most between two poses, m: the centre's displacement plus the largest
// vertex radius times the rotation angle.
static double travel(const pdBody* b, const pdPose* p0, const pdPose* p1) {
  pdMat3 r0t = pd_mat3_transpose(&p0->R);
  pdMat3 d = pd_mat3_mul(&p1->R, &r0t);  // the rotation over the step
  double cosAngle = fmax(-1.0, fmin(1.0, 0.5 * (d.m[0][0] + d.m[1][1] + d.m[2][2] - 1.0)));
  return pd_v3_norm(pd_v3_sub(p1->x, p0->x)) + b->radius * acos(cosAngle);
}

// The longest step (as a fraction of the step just taken) that keeps every listed pair's relative travel
// within PD_TRAVEL_WIDTH_FRACTION of the thinner body's width; 1 when the step is short enough.
static double travel_limit(const pdModel* model, pdContactSet* set, int pairCount) {
  for (int k = 0; k < model->movingCount; ++k) {
    int i = model->movingBodies[k];
    set->travel[i] = travel(&model->bodies[i], &set->poses0[i], &set->poses1[i]);
  }
  double limit = 1.0;
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    double moved = set->travel[a] + set->travel[b];
    double allowed = fmin(PD_TRAVEL_WIDTH_FRACTION * fmin(model->bodies[a].width, model->bodies[b].width),
                          PD_TRAVEL_DEFLECTIONS * pd_model_pair_delta_max(model, a, b));
    if (moved > allowed) limit = fmin(limit, allowed / moved);
  }
  return limit;
}

bool pd_contact_search_travel_retry(const pdModel* model, pdContactSet* set, int pairCount, double h,
                                    double* hRetry) {
  double limit = travel_limit(model, set, pairCount);
  if (!(limit < 1.0 && limit * h > model->settings.dtmin)) return false;
  *hRetry = fmax(model->settings.dtmin, PD_TRAVEL_RETRY_SAFETY * limit * h);
  return true;
}

// A certificate that saved no search, or none issued: the pair waits longer before the next try (a pair in motion, or
// one whose features no certificate covers, would pay for one after every step). The wait doubles from 1.
static void back_off(pairCertificate* c) {
  c->backoff = c->backoff < CERT_BACKOFF_MAX ? 2 * c->backoff + 1 : CERT_BACKOFF_MAX;
  c->wait = c->backoff;
}

// Are all of pair p's contacts of C0 still tracked at the step's end?
static bool all_tracked(const pdContactSet* set, int p) {
  for (int k = set->pairPrevious[p]; k < set->pairPrevious[p] + set->pairPreviousCount[p]; ++k)
    if (!set->eval[k].tracked) return false;
  return true;
}

// Does pair p's certificate, issued with c->contacts of its contacts of C0, hold at the poses pa, pb: the same
// contacts listed (the list only loses contacts between searches, at commits: the same count is the same list),
// each still tracked, and the pair within the certificate's motion?
static bool certificate_holds(const pdContactSet* set, int p, const pairCertificate* c, const pdPose* pa,
                              const pdPose* pb) {
  return c->contacts == set->pairPreviousCount[p] && all_tracked(set, p) &&
         pd_search_motion(&c->cert, pa, pb) < c->cert.margin;
}

// Pairs [begin, end) of the contact search: touching[p] and the pair's new cache entry, or certified[p] when its
// certificate holds.
static void interference_range(void* ctx, int part, int begin, int end) {
  (void)part;
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose* poses1 = job->poses1;
  int cached = 0;  // the cache's cursor (sorted like the pairs); from its start in every range
  for (int p = begin; p < end; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    pdPairSatCache entry = {a, b, pd_pair_sat_cache_find(set->cache, set->cacheCount, &cached, a, b)};
    bool listed = cached < set->cacheCount && set->cache[cached].a == a && set->cache[cached].b == b;
    pairCertificate cert = listed ? set->certs[cached] : (pairCertificate){.cert.margin = 0.0};
    set->certified[p] = false;
    if (job->certificates && cert.cert.margin > 0.0) {
      if (certificate_holds(set, p, &cert, &poses1[a], &poses1[b])) {
        // nothing new to find (contact_analysis.h): the pair keeps its cache and certificate, and is not searched
        cert.used = true;
        set->certified[p] = true;
        set->touching[p] = false;
        set->cacheNext[p] = set->cache[cached];
        set->certsNext[p] = cert;
        continue;
      }
      if (cert.used)
        cert.backoff = 0;
      else
        back_off(&cert);
      cert.cert.margin = 0.0;
      cert.used = false;
    }
    set->certsNext[p] = cert;
    pdSatResult sat;
    const pdBody *A = &job->model->bodies[a], *B = &job->model->bodies[b];
    set->touching[p] = pd_interference(&A->shape, poses1[a].x, &poses1[a].R, &B->shape, poses1[b].x, &poses1[b].R,
                                       PD_SAT_VERDICT, &entry.sat, &sat);
    set->cacheNext[p] = entry;
  }
}

// Did pair p's search find nothing its contacts of C0 (`previous`, sorted like found[0 .. n)) do not have, with
// each of them tracked?
static bool quiet(const pdContactSet* set, int p, const pdContactGeom* found, int n, const pdContactId* previous) {
  if (!all_tracked(set, p)) return false;
  int count = set->pairPreviousCount[p], j = 0;
  for (int f = 0; f < n; ++f) {
    while (j < count && pd_contact_id_compare(&previous[j], &found[f].id) < 0) ++j;
    if (j == count || pd_contact_id_compare(&previous[j], &found[f].id) != 0) return false;
  }
  return true;
}

// The contacts of the touching pairs [begin, end) into the part's found[], pair after pair (pairFound,
// pairFoundCount). A part's buffer grows here, on whichever thread runs it (between steps, not in the derivative).
static void find_range(void* ctx, int part, int begin, int end) {
  const contactLoop* job = ctx;
  pdContactSet* set = job->set;
  const pdPose *poses0 = job->poses0, *poses1 = job->poses1;
  searchPart* sp = &set->search[part];
  if (part == 1) set->searchSplit = begin;
  sp->foundCount = 0;
  for (int p = begin; p < end; ++p) {
    set->pairFound[p] = sp->foundCount;
    set->pairFoundCount[p] = 0;
    if (set->certified[p]) continue;
    int a = set->pairs[p].a, b = set->pairs[p].b, first = set->pairPrevious[p], count = set->pairPreviousCount[p];
    for (int k = 0; k < count; ++k) sp->previous[k] = set->items[first + k].id;
    int n = 0;
    if (set->touching[p]) {
      while ((n = pd_contacts_find(job->model, a, &poses1[a], b, &poses1[b], &poses0[a], &poses0[b], sp->previous,
                                   count, sp->found + sp->foundCount, sp->foundCapacity - sp->foundCount)) >
             sp->foundCapacity - sp->foundCount) {
        sp->foundCapacity = 2 * (sp->foundCount + n);
        sp->found = pd_grow(sp->found, sp->foundCapacity, sizeof *sp->found);
      }
    }
    // a pair in contact that found nothing new with all its contacts tracked is certified for the next steps (a pair
    // apart has only its interference test to skip, itself about as dear as a certificate)
    pairCertificate* cert = &set->certsNext[p];
    if (job->certificates && count > 0 && quiet(set, p, sp->found + sp->foundCount, n, sp->previous)) {
      if (cert->wait > 0) {
        --cert->wait;
      } else {
        cert->cert = pd_contacts_certify(job->model, a, &poses1[a], b, &poses1[b], sp->previous, count);
        cert->contacts = count;
        cert->used = false;
        if (!(cert->cert.margin > 0.0)) back_off(cert);  // none to be had here (flush parallel edges): not every step
      }
    }
    set->pairFoundCount[p] = n;
    sp->foundCount += n;
  }
}

// Interference of the pairs at poses1 (the verdict only, PD_SAT_VERDICT: GJK's certificates, and touching where
// they prove neither, within 1e-7 of the size; cache of the last separating feature or direction per pair, merged
// by the sorted pair order), then the contact search of the touching ones, whose own depth tests find no contact
// where nothing penetrates. Fills candidates. Times the interference
// (a lap of `watch`), not the search after it.
void pd_contact_search(const pdModel* model, pdState* s, const double* y1, int pairCount, const pdPose* poses0,
                       const pdPose* poses1, pdStopwatch* watch) {
  pdContactSet* set = s->contacts;
  // each pair's contacts in C0 (the list is sorted by the unordered body pair first)
  int listed = 0;
  for (int p = 0; p < pairCount; ++p) {
    int a = set->pairs[p].a, b = set->pairs[p].b;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) < 0) ++listed;
    set->pairPrevious[p] = listed;
    while (listed < set->count && compare_to_pair(&set->items[listed].id, a, b) == 0) ++listed;
    set->pairPreviousCount[p] = listed - set->pairPrevious[p];
  }
  // every pair's interference first, timed as a whole (two clock reads per pair were 2 % of a pile's run)
  contactLoop job = {.model = model, .set = set, .poses1 = poses1, .certificates = s->searchCertificates};
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, interference_range, &job);
  pd_stopwatch_lap(watch, &s->stageSeconds[pd_stageInterference]);
  set->candidateCount = 0;
  contactLoop find = {
      .model = model, .set = set, .poses0 = poses0, .poses1 = poses1, .certificates = s->searchCertificates};
  set->searchSplit = pairCount;
  pd_help_for(set->help, pairCount, PD_HELP_MIN_PAIRS, find_range, &find);
  for (int p = 0; p < pairCount; ++p) {
    s->count.searchesSkipped += set->certified[p];
    if (!set->touching[p]) continue;
    int first = set->pairPrevious[p], previousCount = set->pairPreviousCount[p], n = set->pairFoundCount[p];
    const pdContactGeom* found = set->search[p >= set->searchSplit].found + set->pairFound[p];
    // found[] and C0's contacts of this pair are both sorted by id: merge
    int j = first;
    for (int f = 0; f < n; ++f) {
      const pdContactGeom* g = &found[f];
      while (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) < 0) ++j;
      if (j < first + previousCount && pd_contact_id_compare(&set->items[j].id, &g->id) == 0) continue;
      candidate c = {*g, 1.0, false, 0.0, -1, 0.0};
      int b1 = g->id.body1, b2 = g->id.body2;
      pdVec3 du = relative_velocity(model, y1, poses1, &g->id, g->point);
      c.approaching = pd_v3_dot(du, g->normal) < 0.0;
      // face continuity: the vertex of a VF contact of C0 that no longer tracks its face, now on another
      for (int k = first; k < first + previousCount && g->id.kind == pd_contactVF; ++k) {
        const pdContactId* old = &set->items[k].id;
        if (old->kind == pd_contactVF && old->body1 == g->id.body1 && old->feat1 == g->id.feat1 &&
            !set->eval[k].tracked && !set->eval[k].transferred) {
          c.inherit = k;
          set->eval[k].transferred = true;
          break;
        }
      }
      if (c.inherit < 0) c.onset = pd_contact_onset(model, &g->id, &poses0[b1], &poses1[b1], &poses0[b2], &poses1[b2]);
      add_candidate(set, &c);
    }
  }
  // C0 contacts whose pair no longer overlaps were not visited: nothing to do, they break on commit
  // if they no longer track or pull; swap in the new cache
  pdPairSatCache* t = set->cache;
  set->cache = set->cacheNext;
  set->cacheNext = t;
  pairCertificate* c = set->certs;
  set->certs = set->certsNext;
  set->certsNext = c;
  set->cacheCount = pairCount;
}
