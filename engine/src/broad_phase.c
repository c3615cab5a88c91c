// polydyn — broad phase by sweep and prune (conventions and cost in broad_phase.h).
//
// Design
// - The 2n endpoints along the sweep axis (the box minimum, and the box maximum plus the margin) are
//   kept in one array in a total order: by value, then minima before maxima (so that touching boxes
//   overlap), then by body. A total order makes the sorted array — and so the sweep — a function of
//   the current boxes only, whatever the history.
// - Each update refreshes the endpoint values in place and re-sorts by insertion sort, which moves
//   each endpoint only past the endpoints it crossed since the last step. A move budget bounds the
//   damage when motion is not coherent: past it, the (still permuted) array is merge-sorted instead.
// - The sweep walks the endpoints once with an "active" list of the boxes open at the current
//   position; a new box is tested on the other two axes against every active box. The active list
//   keeps those two intervals in contiguous arrays, and the four comparisons are combined without
//   branches, since most of these tests fail. Pairs are then heap-sorted in the caller's buffer (in
//   place, no allocation) into (a, b) order.
#include "broad_phase.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "polydyn/error.h"

// Insertion-sort budget per endpoint before the merge sort takes over. Coherent motion moves an
// endpoint past a handful of neighbours per step; a body that crosses many others (a teleport, the
// first step) would cost up to n moves each, so past ~8 moves per endpoint on average a merge sort
// (~log2(2n) passes, ~15 for 10⁴ bodies) is cheaper or comparable.
#define INSERTION_MOVES_PER_ENDPOINT 8

typedef struct endpoint {
  double value;  // box lo on the sweep axis, or box hi + margin
  int tag;       // body * 2 + (1 for a maximum, 0 for a minimum)
} endpoint;

struct pdBroadPhase {
  int n;
  double margin;
  bool* fixed;        // (n)
  pdAabb* boxes;      // (n) the last update's boxes
  endpoint* ends;     // (2n) sorted along `axis`
  endpoint* scratch;  // (2n) merge-sort buffer
  // The sweep's open boxes, as a structure of arrays (contiguous reads in the inner loop): the other
  // two axes' intervals (hi including the margin), the body, and each body's position in them.
  double *lo1, *hi1, *lo2, *hi2;  // (n)
  int* activeBody;                // (n)
  int* activePos;                 // (n) indexed by body
  int axis;                       // -1 before the first update
  pdBroadPhaseStats stats;
};

pdBroadPhase* pd_broad_phase_create(int bodyCount, const bool* fixed, double margin) {
  PD_ASSERT(bodyCount >= 0 && bodyCount <= INT_MAX / 2 - 1);
  PD_ASSERT(margin >= 0.0 && isfinite(margin));
  pdBroadPhase* bp = calloc(1, sizeof *bp);
  if (!bp) return NULL;
  size_t n = (size_t)bodyCount, m = n > 0 ? n : 1;
  bp->n = bodyCount;
  bp->margin = margin;
  bp->fixed = calloc(m, sizeof *bp->fixed);
  bp->boxes = calloc(m, sizeof *bp->boxes);
  bp->ends = calloc(2 * m, sizeof *bp->ends);
  bp->scratch = calloc(2 * m, sizeof *bp->scratch);
  bp->lo1 = calloc(m, sizeof *bp->lo1);
  bp->hi1 = calloc(m, sizeof *bp->hi1);
  bp->lo2 = calloc(m, sizeof *bp->lo2);
  bp->hi2 = calloc(m, sizeof *bp->hi2);
  bp->activeBody = calloc(m, sizeof *bp->activeBody);
  bp->activePos = calloc(m, sizeof *bp->activePos);
  if (!bp->fixed || !bp->boxes || !bp->ends || !bp->scratch || !bp->lo1 || !bp->hi1 || !bp->lo2 || !bp->hi2 ||
      !bp->activeBody || !bp->activePos) {
    pd_broad_phase_free(bp);
    return NULL;
  }
  if (fixed) memcpy(bp->fixed, fixed, n * sizeof *fixed);
  for (int i = 0; i < bodyCount; ++i) {
    bp->ends[2 * i] = (endpoint){0.0, 2 * i};
    bp->ends[2 * i + 1] = (endpoint){0.0, 2 * i + 1};
  }
  bp->axis = -1;
  bp->stats.axis = -1;
  return bp;
}

void pd_broad_phase_free(pdBroadPhase* bp) {
  if (!bp) return;
  free(bp->fixed);
  free(bp->boxes);
  free(bp->ends);
  free(bp->scratch);
  free(bp->lo1);
  free(bp->hi1);
  free(bp->lo2);
  free(bp->hi2);
  free(bp->activeBody);
  free(bp->activePos);
  free(bp);
}

// The total order of endpoints: value, then minima before maxima, then body.
static inline bool endpoint_less(endpoint a, endpoint b) {
  if (a.value != b.value) return a.value < b.value;
  int ka = a.tag & 1, kb = b.tag & 1;
  if (ka != kb) return ka < kb;
  return a.tag < b.tag;
}

static void merge_sort(endpoint* a, endpoint* tmp, int count) {
  endpoint *src = a, *dst = tmp;
  for (int width = 1; width < count; width *= 2) {
    for (int lo = 0; lo < count; lo += 2 * width) {
      int mid = lo + width < count ? lo + width : count;
      int hi = lo + 2 * width < count ? lo + 2 * width : count;
      int i = lo, j = mid, k = lo;
      while (i < mid && j < hi) dst[k++] = endpoint_less(src[j], src[i]) ? src[j++] : src[i++];
      while (i < mid) dst[k++] = src[i++];
      while (j < hi) dst[k++] = src[j++];
    }
    endpoint* t = src;
    src = dst;
    dst = t;
  }
  if (src != a) memcpy(a, src, (size_t)count * sizeof *a);
}

// Insertion sort that gives up (leaving a permutation) once it has made more than `budget` moves.
static bool insertion_sort(endpoint* a, int count, long long budget, long long* moves) {
  long long done = 0;
  for (int i = 1; i < count; ++i) {
    endpoint x = a[i];
    int j = i;
    while (j > 0 && endpoint_less(x, a[j - 1])) {
      a[j] = a[j - 1];
      --j;
    }
    a[j] = x;
    done += i - j;
    if (done > budget) {
      *moves = done;
      return false;
    }
  }
  *moves = done;
  return true;
}

// Sweep axis with the largest variance of box centres (ties to the lowest axis), with hysteresis.
static int choose_axis(const pdBroadPhase* bp) {
  if (bp->n == 0) return bp->axis >= 0 ? bp->axis : 0;
  double mean[3] = {0, 0, 0}, var[3] = {0, 0, 0};
  for (int i = 0; i < bp->n; ++i)
    for (int k = 0; k < 3; ++k) mean[k] += 0.5 * (bp->boxes[i].lo[k] + bp->boxes[i].hi[k]);
  for (int k = 0; k < 3; ++k) mean[k] /= bp->n;
  for (int i = 0; i < bp->n; ++i)
    for (int k = 0; k < 3; ++k) {
      double d = 0.5 * (bp->boxes[i].lo[k] + bp->boxes[i].hi[k]) - mean[k];
      var[k] += d * d;
    }
  int best = 0;
  for (int k = 1; k < 3; ++k)
    if (var[k] > var[best]) best = k;
  if (bp->axis < 0) return best;
  return var[best] > PD_BROAD_PHASE_AXIS_SWITCH * var[bp->axis] ? best : bp->axis;
}

void pd_broad_phase_update(pdBroadPhase* bp, const pdAabb* boxes) {
  PD_ASSERT(bp != NULL && (boxes != NULL || bp->n == 0));
  for (int i = 0; i < bp->n; ++i) {
    const pdAabb* b = &boxes[i];
    for (int k = 0; k < 3; ++k) PD_ASSERT(isfinite(b->lo[k]) && isfinite(b->hi[k]) && b->lo[k] <= b->hi[k]);
  }
  if (bp->n > 0) memcpy(bp->boxes, boxes, (size_t)bp->n * sizeof *boxes);

  int axis = choose_axis(bp);
  bool sorted = axis == bp->axis;  // the endpoints are in the order of the last update's values
  bp->axis = axis;
  int count = 2 * bp->n;
  for (int i = 0; i < count; ++i) {
    endpoint* e = &bp->ends[i];
    const pdAabb* b = &bp->boxes[e->tag >> 1];
    e->value = (e->tag & 1) ? b->hi[axis] + bp->margin : b->lo[axis];
  }
  long long moves = 0;
  bool full = !sorted || !insertion_sort(bp->ends, count, (long long)INSERTION_MOVES_PER_ENDPOINT * count, &moves);
  if (full) {
    merge_sort(bp->ends, bp->scratch, count);
    bp->stats.fullSorts++;
  }
  bp->stats.axis = axis;
  bp->stats.sortMoves = moves;
  bp->stats.fullSort = full;
}

static inline bool pair_less(pdPair x, pdPair y) { return x.a < y.a || (x.a == y.a && x.b < y.b); }

static void sift_down(pdPair* h, int root, int count) {
  for (;;) {
    int child = 2 * root + 1;
    if (child >= count) return;
    if (child + 1 < count && pair_less(h[child], h[child + 1])) ++child;
    if (!pair_less(h[root], h[child])) return;
    pdPair t = h[root];
    h[root] = h[child];
    h[child] = t;
    root = child;
  }
}

// In place, no allocation, O(p log p); the pairs are distinct so the order is unique.
static void heap_sort_pairs(pdPair* p, int count) {
  for (int i = count / 2 - 1; i >= 0; --i) sift_down(p, i, count);
  for (int end = count - 1; end > 0; --end) {
    pdPair t = p[0];
    p[0] = p[end];
    p[end] = t;
    sift_down(p, 0, end);
  }
}

int pd_broad_phase_pairs(pdBroadPhase* bp, pdPair* out, int capacity) {
  PD_ASSERT(bp != NULL && capacity >= 0 && (out != NULL || capacity == 0));
  if (bp->axis < 0) return 0;  // no update yet: no boxes
  int k1 = (bp->axis + 1) % 3, k2 = (bp->axis + 2) % 3;
  double margin = bp->margin;
  long long count = 0, tests = 0;
  int activeCount = 0, ends = 2 * bp->n;
  double *lo1 = bp->lo1, *hi1 = bp->hi1, *lo2 = bp->lo2, *hi2 = bp->hi2;
  for (int i = 0; i < ends; ++i) {
    int tag = bp->ends[i].tag, body = tag >> 1;
    if (tag & 1) {  // the box closes: swap-remove it from the active list
      int pos = bp->activePos[body], last = --activeCount;
      lo1[pos] = lo1[last];
      hi1[pos] = hi1[last];
      lo2[pos] = lo2[last];
      hi2[pos] = hi2[last];
      bp->activeBody[pos] = bp->activeBody[last];
      bp->activePos[bp->activeBody[pos]] = pos;
      continue;
    }
    const pdAabb* b = &bp->boxes[body];
    double mlo1 = b->lo[k1], mhi1 = b->hi[k1] + margin, mlo2 = b->lo[k2], mhi2 = b->hi[k2] + margin;
    tests += activeCount;
    for (int j = 0; j < activeCount; ++j) {
      // non-short-circuit &: one well-predicted branch (most of these tests fail) instead of four
      if (!((mlo1 <= hi1[j]) & (lo1[j] <= mhi1) & (mlo2 <= hi2[j]) & (lo2[j] <= mhi2))) continue;
      int other = bp->activeBody[j];
      if (bp->fixed[body] && bp->fixed[other]) continue;
      if (count < capacity) out[count] = body < other ? (pdPair){body, other} : (pdPair){other, body};
      ++count;
    }
    lo1[activeCount] = mlo1;
    hi1[activeCount] = mhi1;
    lo2[activeCount] = mlo2;
    hi2[activeCount] = mhi2;
    bp->activeBody[activeCount] = body;
    bp->activePos[body] = activeCount++;
  }
  PD_ASSERT(count <= INT_MAX);
  bp->stats.axisTests = tests;
  heap_sort_pairs(out, count < capacity ? (int)count : capacity);
  return (int)count;
}

pdBroadPhaseStats pd_broad_phase_stats(const pdBroadPhase* bp) {
  PD_ASSERT(bp != NULL);
  return bp->stats;
}

pdAabb pd_aabb_of(const pdPolyhedron* p, pdVec3 x, const pdMat3* R) {
  PD_ASSERT(p != NULL && R != NULL && p->vertexCount > 0);
  pdAabb box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (int v = 0; v < p->vertexCount; ++v) {
    pdVec3 w = pd_v3_add(x, pd_mat3_mulv(R, p->vertices[v]));
    double c[3] = {w.x, w.y, w.z};
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = c[k] < box.lo[k] ? c[k] : box.lo[k];
      box.hi[k] = c[k] > box.hi[k] ? c[k] : box.hi[k];
    }
  }
  return box;
}
