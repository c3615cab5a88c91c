// polydyn — broad phase by incremental sweep and prune on three axes (conventions and cost in
// broad_phase.h).
//
// Design
// - Each axis keeps its 2n endpoints (the box minimum, and the box maximum plus the margin) in one
//   array in a total order: by value, then minima before maxima, then by body. Along an axis, a
//   minimum precedes another body's maximum iff lo <= hi + margin: the header's closed test is read
//   off the order, touching boxes included, and the sorted arrays depend on the current boxes only.
// - `boxes` holds, per axis, the values the axis's array is currently sorted by: an update overwrites
//   an axis's column only once that axis is sorted. So at any moment, a test of `boxes` on an axis
//   says what that axis's order says, and "overlapping on all three axes by `boxes`" is a well-defined
//   state that the pair set tracks exactly.
// - Each axis is re-sorted by insertion sort, which swaps neighbours only; a swap flips one "minimum
//   precedes maximum" relation for one pair along that axis. A minimum passing another body's maximum
//   leftwards starts the pair's overlap along the axis; a maximum passing a minimum ends it (the two
//   relations of a pair cannot both fail, since each body's minimum precedes its maximum, so the event
//   alone says which). The pair enters or leaves the set iff it overlaps on the other two axes by
//   `boxes`. Minimum/minimum and maximum/maximum swaps change nothing. (Baraff 1992; I-COLLIDE, Cohen
//   et al. 1995.) Those events are buffered and applied after a batch of swaps: the other two axes do
//   not move while one axis is sorted, so the result is the same, the hot loop has no unpredictable
//   branch, and the events' scattered reads of `boxes` overlap in the memory system.
// - Incoherent motion (the first update, teleports) would make insertion sort quadratic: past a swap
//   budget the remaining axes are re-sorted (qsort) and the set is rebuilt by one single-axis sweep along
//   the axis with the fewest overlapping pairs (counted in O(n) per axis on the sorted arrays).
// - The set: open addressing with linear probing keyed by (a, b), at most half full, deletion by
//   backward shift (no tombstones, so probes stay short); the slots point into a dense list of keys,
//   so that pd_broad_phase_pairs costs k log k (copy and sort the list), not a scan of the
//   table. The sorted copy is kept until the set changes.
#include "broad_phase.h"

#include "broad_grid.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "interference.h"
#include "polydyn/error.h"

// Insertion-sort budget per endpoint and axis before a full sort (qsort) takes over. Coherent motion moves
// an endpoint past a few neighbours per update. The fallback costs ~log2(2n) comparisons per endpoint
// and axis (~15 for 10⁴ bodies) plus a rebuild sweep; past 32 swaps per endpoint the insertion sort
// is no cheaper, and the work thrown away before giving up stays comparable to the fallback's.
#define INSERTION_SWAPS_PER_ENDPOINT 32

// Swap events buffered before they are applied to the set: enough to amortise the flush, small enough
// to stay in the L1 cache (8 KB).
#define EVENT_BATCH 1024

// The pair set is at most half full (linear probing stays short) and never below this many slots.
#define SET_MIN_SLOTS 64
// Slot limit: keeps list indices and pair counts within int (2^29 pairs is far beyond any memory).
#define SET_MAX_SLOTS ((size_t)1 << 30)

#define EMPTY_KEY UINT64_MAX  // (a, b) with a < b never packs to all ones
#define KEY_HI_SHIFT 31
#define KEY_HI_BIT (1u << KEY_HI_SHIFT)
#define KEY_BODY_MASK 0x7fffffffu

typedef struct endpoint {
  double value;  // box lo on this axis, or box hi + margin
  uint32_t key;  // body, with KEY_HI_BIT for a maximum: as an integer, minima before maxima, then body
} endpoint;

// A swap of a minimum and a maximum recorded during an axis's insertion sort: the endpoint moving left
// and the one it passed.
typedef struct swapEvent {
  uint32_t moving, passed;
} swapEvent;

typedef struct slot {
  uint64_t key;  // (a << 32) | b, or EMPTY_KEY
  int index;     // the key's position in `list`
} slot;

struct pdBroadPhase {
  int n;
  double margin;
  bool* fixed;        // (n)
  pdAabb* boxes;      // (n) per axis, the values that axis is sorted by (see the design note)
  endpoint* ends[3];  // (2n) per axis, sorted
  swapEvent* events;  // (EVENT_BATCH)
  // the rebuild sweep's open boxes: their bodies, the other two axes' intervals (hi with the margin;
  // contiguous reads in the inner loop), and each body's place among them
  int *activeBody, *activeAt;     // (n)
  double *lo1, *hi1, *lo2, *hi2;  // (n)
  // the pair set
  slot* slots;                 // (slotCount) a power of two
  size_t slotCount;
  int slotShift;               // 64 - log2(slotCount), for Fibonacci hashing
  uint64_t* list;              // (slotCount / 2) the keys, unordered
  uint64_t* sorted;  // (slotCount / 2) the keys sorted by pd_broad_phase_pairs
  int count;                   // pairs in the set
  bool sortedValid;            // `sorted` holds the current set
  bool valid;       // the set matches the arrays (false before the first update, after a failed one)
  bool growFailed;  // this update could not grow the set
  pdBroadPhaseStats stats;
  pdBroadGrid* grid;  // non-NULL: the grid method does the work (none of the arrays above are used)
};

// ---------------------------------------------------------------- the pair set

static inline uint64_t pack(int a, int b) {
  return a < b ? (uint64_t)a << 32 | (uint32_t)b : (uint64_t)b << 32 | (uint32_t)a;
}

static inline size_t slot_of(const pdBroadPhase* bp, uint64_t key) {
  return (size_t)((key * 0x9E3779B97F4A7C15ull) >> bp->slotShift);  // Fibonacci hashing: the top bits
}

// Allocates a set of `slotCount` slots (a power of two); false when out of memory.
static bool set_alloc(size_t slotCount, slot** slots, uint64_t** list, uint64_t** sorted) {
  *slots = malloc(slotCount * sizeof **slots);
  *list = malloc(slotCount / 2 * sizeof **list);
  *sorted = malloc(slotCount / 2 * sizeof **sorted);
  if (!*slots || !*list || !*sorted) {
    free(*slots);
    free(*list);
    free(*sorted);
    return false;
  }
  for (size_t i = 0; i < slotCount; ++i) (*slots)[i] = (slot){EMPTY_KEY, -1};
  return true;
}

static void set_use(pdBroadPhase* bp, size_t slotCount, slot* slots, uint64_t* list, uint64_t* sorted) {
  bp->slots = slots;
  bp->list = list;
  bp->sorted = sorted;
  bp->slotCount = slotCount;
  int bits = 0;
  while (((size_t)1 << bits) < slotCount) ++bits;
  bp->slotShift = 64 - bits;
  bp->stats.setCapacity = (int)(slotCount / 2);
}

static void set_free(pdBroadPhase* bp) {
  free(bp->slots);
  free(bp->list);
  free(bp->sorted);
}

// Places key (absent) in the table, pointing at list[index].
static void set_place(pdBroadPhase* bp, uint64_t key, int index) {
  size_t mask = bp->slotCount - 1, i = slot_of(bp, key);
  while (bp->slots[i].key != EMPTY_KEY) i = (i + 1) & mask;
  bp->slots[i] = (slot){key, index};
}

static size_t set_find(const pdBroadPhase* bp, uint64_t key) {
  size_t mask = bp->slotCount - 1, i = slot_of(bp, key);
  while (bp->slots[i].key != key) {
    PD_ASSERT(bp->slots[i].key != EMPTY_KEY);  // only what the set's invariant says is there is removed
    i = (i + 1) & mask;
  }
  return i;
}

// Doubles the set, keeping the list. False (the set untouched) when memory runs out.
static bool set_grow(pdBroadPhase* bp) {
  if (bp->slotCount >= SET_MAX_SLOTS) return false;
  size_t slotCount = 2 * bp->slotCount;
  slot* slots;
  uint64_t *list, *sorted;
  if (!set_alloc(slotCount, &slots, &list, &sorted)) return false;
  memcpy(list, bp->list, (size_t)bp->count * sizeof *list);
  set_free(bp);
  set_use(bp, slotCount, slots, list, sorted);
  for (int i = 0; i < bp->count; ++i) set_place(bp, bp->list[i], i);
  bp->sortedValid = false;
  bp->stats.setGrowths++;
  return true;
}

static void set_insert(pdBroadPhase* bp, uint64_t key) {
  if ((size_t)bp->count + 1 > bp->slotCount / 2 && !set_grow(bp)) {
    bp->growFailed = true;  // the set is now incomplete: the update reports it, the next one rebuilds
    return;
  }
  set_place(bp, key, bp->count);
  bp->list[bp->count++] = key;
  bp->sortedValid = false;
}

static void set_remove(pdBroadPhase* bp, uint64_t key) {
  size_t mask = bp->slotCount - 1, hole = set_find(bp, key);
  int index = bp->slots[hole].index, last = --bp->count;
  if (index != last) {  // the list's last key fills the gap
    uint64_t moved = bp->list[last];
    bp->list[index] = moved;
    bp->slots[set_find(bp, moved)].index = index;
  }
  // backward-shift deletion: pull back each later key of the probe run whose home allows the hole
  for (size_t j = (hole + 1) & mask; bp->slots[j].key != EMPTY_KEY; j = (j + 1) & mask) {
    size_t home = slot_of(bp, bp->slots[j].key);
    if (((j - home) & mask) >= ((j - hole) & mask)) {
      bp->slots[hole] = bp->slots[j];
      hole = j;
    }
  }
  bp->slots[hole] = (slot){EMPTY_KEY, -1};
  bp->sortedValid = false;
}

static void set_clear(pdBroadPhase* bp) {
  for (size_t i = 0; i < bp->slotCount; ++i) bp->slots[i] = (slot){EMPTY_KEY, -1};
  bp->count = 0;
  bp->sortedValid = false;
}

// ---------------------------------------------------------------- creation

pdBroadPhase* pd_broad_phase_create(int bodyCount, const bool* fixed, double margin) {
  return pd_broad_phase_create_with(bodyCount, fixed, margin, pd_broadPhaseAuto);
}

pdBroadPhase* pd_broad_phase_create_with(int bodyCount, const bool* fixed, double margin,
                                         pdBroadPhaseMethod method) {
  PD_ASSERT(bodyCount >= 0 && bodyCount <= INT_MAX / 2 - 1);
  PD_ASSERT(margin >= 0.0 && isfinite(margin));
  if (method == pd_broadPhaseAuto)
    method = bodyCount >= PD_BROAD_PHASE_GRID_MIN_BODIES ? pd_broadPhaseGrid : pd_broadPhaseSweep;
  pdBroadPhase* bp = calloc(1, sizeof *bp);
  if (!bp) return NULL;
  if (method == pd_broadPhaseGrid) {
    bp->n = bodyCount;
    bp->margin = margin;
    bp->grid = pd_broad_grid_create(bodyCount, fixed, margin);
    bp->stats.sweepAxis = -1;
    bp->stats.grid = true;
    if (!bp->grid) {
      free(bp);
      return NULL;
    }
    return bp;
  }
  size_t n = (size_t)bodyCount, m = n > 0 ? n : 1;
  bp->n = bodyCount;
  bp->margin = margin;
  bp->fixed = calloc(m, sizeof *bp->fixed);
  bp->boxes = calloc(m, sizeof *bp->boxes);
  bool ok = bp->fixed && bp->boxes;
  for (int k = 0; k < 3; ++k) ok = (bp->ends[k] = calloc(2 * m, sizeof *bp->ends[k])) && ok;
  bp->events = malloc(EVENT_BATCH * sizeof *bp->events);
  bp->activeBody = calloc(m, sizeof *bp->activeBody);
  bp->activeAt = calloc(m, sizeof *bp->activeAt);
  bp->lo1 = calloc(m, sizeof *bp->lo1);
  bp->hi1 = calloc(m, sizeof *bp->hi1);
  bp->lo2 = calloc(m, sizeof *bp->lo2);
  bp->hi2 = calloc(m, sizeof *bp->hi2);
  ok = ok && bp->events && bp->activeBody && bp->activeAt && bp->lo1 && bp->hi1 && bp->lo2 &&
       bp->hi2;
  // slots: a power of two, at least twice the reserved pairs
  size_t slotCount = SET_MIN_SLOTS;
  while (slotCount < SET_MAX_SLOTS && slotCount / 2 < (size_t)PD_BROAD_PHASE_PAIRS_PER_BODY * n) slotCount *= 2;
  slot* slots;
  uint64_t *list, *sorted;
  if (!ok || !set_alloc(slotCount, &slots, &list, &sorted)) {
    pd_broad_phase_free(bp);
    return NULL;
  }
  set_use(bp, slotCount, slots, list, sorted);
  if (fixed) memcpy(bp->fixed, fixed, n * sizeof *fixed);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < bodyCount; ++i) {
      bp->ends[k][2 * i] = (endpoint){0.0, (uint32_t)i};
      bp->ends[k][2 * i + 1] = (endpoint){0.0, (uint32_t)i | KEY_HI_BIT};
    }
  bp->stats.sweepAxis = -1;
  return bp;
}

void pd_broad_phase_free(pdBroadPhase* bp) {
  if (!bp) return;
  pd_broad_grid_free(bp->grid);
  free(bp->fixed);
  free(bp->boxes);
  for (int k = 0; k < 3; ++k) free(bp->ends[k]);
  free(bp->events);
  free(bp->activeBody);
  free(bp->activeAt);
  free(bp->lo1);
  free(bp->hi1);
  free(bp->lo2);
  free(bp->hi2);
  set_free(bp);
  free(bp);
}

// ---------------------------------------------------------------- sorting

// The total order of endpoints: value, then minima before maxima, then body.
static inline bool endpoint_less(endpoint a, endpoint b) {
  return a.value < b.value || (a.value == b.value && a.key < b.key);
}

static inline double endpoint_value(const pdAabb* boxes, double margin, uint32_t key, int axis) {
  const pdAabb* b = &boxes[key & KEY_BODY_MASK];
  // both, then an indexed select: a branch on the kind would be a coin flip (mispredicted half the time)
  const double v[2] = {b->lo[axis], b->hi[axis] + margin};
  return v[key >> KEY_HI_SHIFT];
}

static int compare_endpoints(const void* pa, const void* pb) {
  endpoint a = *(const endpoint*)pa, b = *(const endpoint*)pb;
  return endpoint_less(a, b) ? -1 : endpoint_less(b, a) ? 1 : 0;
}

// Applies the buffered swaps of `axis`, in order. A minimum passing a maximum leftwards begins that
// pair's overlap along the axis, a maximum passing a minimum ends it; the pair enters or leaves the set
// iff it overlaps on the other two axes (whose arrays and values do not change while `axis` is sorted).
static void apply_events(pdBroadPhase* bp, int axis, int count) {
  if (!bp->valid || bp->growFailed) return;  // the set is rebuilt at the end of this update anyway
  int k1 = axis == 0 ? 1 : 0, k2 = axis == 2 ? 1 : 2;
  double margin = bp->margin;
  for (int i = 0; i < count; ++i) {
    uint32_t moving = bp->events[i].moving, passed = bp->events[i].passed;
    int a = (int)(moving & KEY_BODY_MASK), b = (int)(passed & KEY_BODY_MASK);
    const pdAabb *ba = &bp->boxes[a], *bb = &bp->boxes[b];
    // non-short-circuit &: one well-predicted branch (few events change the set) instead of four
    bool both = (ba->lo[k1] <= bb->hi[k1] + margin) & (bb->lo[k1] <= ba->hi[k1] + margin) &
                (ba->lo[k2] <= bb->hi[k2] + margin) & (bb->lo[k2] <= ba->hi[k2] + margin);
    if (!both || (bp->fixed[a] && bp->fixed[b])) continue;
    bp->stats.pairChanges++;
    if (moving & KEY_HI_BIT)
      set_remove(bp, pack(a, b));
    else
      set_insert(bp, pack(a, b));
    if (bp->growFailed) return;
  }
}

// Refreshes the values of `axis` from `boxes` and insertion-sorts them, keeping the set in step with
// every swap; then makes `boxes`' column of `axis` the one in effect. Gives up (the array a permutation
// of fresh values) past `budget` swaps.
static bool sort_axis(pdBroadPhase* bp, const pdAabb* boxes, int axis, long long budget) {
  endpoint* e = bp->ends[axis];
  swapEvent* events = bp->events;
  double margin = bp->margin;
  int count = 2 * bp->n, pending = 0;
  long long swaps = 0, kindSwaps = 0;
  // fresh values first, in a loop of independent loads, rather than one load per step of the sort's
  // loop where a mispredicted branch would wait for it
  for (int i = 0; i < count; ++i) e[i].value = endpoint_value(boxes, margin, e[i].key, axis);
  for (int i = 1; i < count; ++i) {
    endpoint x = e[i];
    int j = i;
    if (endpoint_less(x, e[j - 1])) {
      do {
        endpoint y = e[j - 1];
        e[j] = y;
        // recorded unconditionally, kept only for a minimum/maximum swap: no unpredictable branch
        events[pending] = (swapEvent){x.key, y.key};
        pending += (int)((x.key ^ y.key) >> KEY_HI_SHIFT);
        if (pending == EVENT_BATCH) {
          apply_events(bp, axis, pending);
          kindSwaps += pending;
          pending = 0;
        }
        --j;
      } while (j > 0 && endpoint_less(x, e[j - 1]));
      swaps += i - j;
    }
    e[j] = x;
    if (swaps > budget) {
      bp->stats.swaps += swaps;
      return false;
    }
  }
  apply_events(bp, axis, pending);
  bp->stats.swaps += swaps;
  bp->stats.overlapEvents += kindSwaps + pending;
  for (int b = 0; b < bp->n; ++b) {
    bp->boxes[b].lo[axis] = boxes[b].lo[axis];
    bp->boxes[b].hi[axis] = boxes[b].hi[axis];
  }
  return true;
}

// ---------------------------------------------------------------- rebuild

// Pairs overlapping along a sorted axis: each counted when the later of the two boxes opens.
static long long axis_overlaps(const endpoint* e, int count) {
  long long pairs = 0, open = 0;
  for (int i = 0; i < count; ++i) {
    if (e[i].key & KEY_HI_BIT) {
      --open;
    } else {
      pairs += open;
      ++open;
    }
  }
  return pairs;
}

// The set from scratch (the three axes sorted by the values in `boxes`): one sweep along the axis with
// the fewest overlapping pairs, each tested on the other two.
static void rebuild(pdBroadPhase* bp) {
  set_clear(bp);
  int count = 2 * bp->n, axis = 0;
  long long fewest = axis_overlaps(bp->ends[0], count);
  for (int k = 1; k < 3; ++k) {
    long long c = axis_overlaps(bp->ends[k], count);
    if (c < fewest) {
      fewest = c;
      axis = k;
    }
  }
  int k1 = axis == 0 ? 1 : 0, k2 = axis == 2 ? 1 : 2;
  double margin = bp->margin;
  double *lo1 = bp->lo1, *hi1 = bp->hi1, *lo2 = bp->lo2, *hi2 = bp->hi2;
  int active = 0;
  for (int i = 0; i < count && !bp->growFailed; ++i) {
    uint32_t key = bp->ends[axis][i].key;
    int body = (int)(key & KEY_BODY_MASK);
    if (key & KEY_HI_BIT) {  // the box closes: swap-remove it from the active list
      int at = bp->activeAt[body], last = --active;
      lo1[at] = lo1[last];
      hi1[at] = hi1[last];
      lo2[at] = lo2[last];
      hi2[at] = hi2[last];
      bp->activeBody[at] = bp->activeBody[last];
      bp->activeAt[bp->activeBody[at]] = at;
      continue;
    }
    const pdAabb* b = &bp->boxes[body];
    double mlo1 = b->lo[k1], mhi1 = b->hi[k1] + margin, mlo2 = b->lo[k2], mhi2 = b->hi[k2] + margin;
    for (int j = 0; j < active; ++j) {
      // non-short-circuit &: one well-predicted branch (most of these tests fail) instead of four
      if (!((mlo1 <= hi1[j]) & (lo1[j] <= mhi1) & (mlo2 <= hi2[j]) & (lo2[j] <= mhi2))) continue;
      int other = bp->activeBody[j];
      if (bp->fixed[body] && bp->fixed[other]) continue;
      set_insert(bp, pack(body, other));
    }
    lo1[active] = mlo1;
    hi1[active] = mhi1;
    lo2[active] = mlo2;
    hi2[active] = mhi2;
    bp->activeBody[active] = body;
    bp->activeAt[body] = active++;
  }
  bp->stats.sweepAxis = axis;
  bp->stats.sweepTests = fewest;
}

// ---------------------------------------------------------------- the API

bool pd_broad_phase_update(pdBroadPhase* bp, const pdAabb* boxes) {
  PD_ASSERT(bp != NULL && (boxes != NULL || bp->n == 0));
  for (int i = 0; i < bp->n; ++i) {
    const pdAabb* b = &boxes[i];
    for (int k = 0; k < 3; ++k) PD_ASSERT(isfinite(b->lo[k]) && isfinite(b->hi[k]) && b->lo[k] <= b->hi[k]);
  }
  if (bp->grid) {
    bp->valid = pd_broad_grid_update(bp->grid, boxes);
    pdBroadGridStats g = pd_broad_grid_stats(bp->grid);
    int count = 0;
    pd_broad_grid_pairs(bp->grid, &count);
    bp->stats.pairs = bp->valid ? count : 0;
    bp->stats.cell = g.cell;
    bp->stats.cellEntries = g.entries;
    bp->stats.largeBoxes = g.large;
    bp->stats.boxTests = g.tests;
    bp->stats.sweepAxis = 0;  // "updated at least once"
    return bp->valid;
  }
  bp->stats.swaps = 0;
  bp->stats.overlapEvents = 0;
  bp->stats.pairChanges = 0;
  bp->growFailed = false;
  int count = 2 * bp->n;
  long long budget = (long long)INSERTION_SWAPS_PER_ENDPOINT * count;
  // Axes from `unsorted` on are fully sorted: all three on the first update (no order to keep), else
  // from the first axis whose insertion sort runs over its budget (sort_axis refreshed its values).
  int unsorted = bp->stats.sweepAxis < 0 ? 0 : 3;
  for (int k = 0; k < unsorted; ++k)
    if (!sort_axis(bp, boxes, k, budget)) unsorted = k;
  bool full = unsorted < 3;
  for (int k = unsorted; k < 3; ++k) {
    endpoint* e = bp->ends[k];
    if (k > unsorted || bp->stats.sweepAxis < 0)
      for (int i = 0; i < count; ++i) e[i].value = endpoint_value(boxes, bp->margin, e[i].key, k);
    qsort(e, (size_t)count, sizeof *e, compare_endpoints);  // a total order: the result is unique
  }
  if (full) {
    if (bp->n > 0) memcpy(bp->boxes, boxes, (size_t)bp->n * sizeof *boxes);
    bp->stats.fullSorts++;
  }
  if (full || !bp->valid || bp->growFailed) {  // every axis is sorted by `boxes`: rebuild from them
    bp->growFailed = false;
    rebuild(bp);
  }
  bp->stats.fullSort = full;
  bp->valid = !bp->growFailed;
  bp->stats.pairs = bp->count;
  return bp->valid;
}

// Packed pair keys: their unsigned order is the (a, b) order.
static int compare_keys(const void* pa, const void* pb) {
  uint64_t a = *(const uint64_t*)pa, b = *(const uint64_t*)pb;
  return (a > b) - (a < b);
}

int pd_broad_phase_pairs(pdBroadPhase* bp, pdPair* out, int capacity) {
  PD_ASSERT(bp != NULL && capacity >= 0 && (out != NULL || capacity == 0));
  PD_ASSERT(bp->valid || bp->stats.sweepAxis < 0);  // not after a failed update
  if (!bp->valid) return 0;                         // no update yet: no boxes
  if (bp->grid) {
    int count = 0;
    const pdPair* pairs = pd_broad_grid_pairs(bp->grid, &count);
    int written = count < capacity ? count : capacity;
    if (written > 0) memcpy(out, pairs, (size_t)written * sizeof *out);  // out may be NULL when capacity is 0
    return count;
  }
  int count = bp->count;
  if (!bp->sortedValid) {
    memcpy(bp->sorted, bp->list, (size_t)count * sizeof *bp->sorted);
    qsort(bp->sorted, (size_t)count, sizeof *bp->sorted, compare_keys);
    bp->sortedValid = true;
  }
  int written = count < capacity ? count : capacity;
  for (int i = 0; i < written; ++i) out[i] = (pdPair){(int)(bp->sorted[i] >> 32), (int)(uint32_t)bp->sorted[i]};
  return count;
}

int pd_broad_phase_pairs_grown(pdBroadPhase* bp, const pdAabb* boxes, pdPair** pairs, int* capacity) {
  bool updated = pd_broad_phase_update(bp, boxes);
  PD_ASSERT(updated);  // false only when memory runs out
  int count = pd_broad_phase_pairs(bp, *pairs, *capacity);
  if (count > *capacity) {
    *capacity = 2 * count;
    *pairs = pd_grow(*pairs, (size_t)*capacity, sizeof **pairs);
    pd_broad_phase_pairs(bp, *pairs, *capacity);
  }
  return count;
}

pdBroadPhaseStats pd_broad_phase_stats(const pdBroadPhase* bp) {
  PD_ASSERT(bp != NULL);
  return bp->stats;
}

// A cuboid's box: along world axis k the highest vertex takes, for each body axis j, the high corner where R_kj ≥ 0 and
// the low one where R_kj < 0. Rounding is monotone, so that vertex's x + R v, formed as pd_mat3_mulv forms it, is the
// largest the vertex loop below would form: the same bounds, bit for bit, from 2 points instead of 8. False (the loop
// decides) when a bound is not a number.
static bool cuboid_box(pdVec3 lo, pdVec3 hi, pdVec3 x, const pdMat3* R, pdAabb* box) {
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z}, xs[3] = {x.x, x.y, x.z};
  for (int k = 0; k < 3; ++k) {
    const double* r = R->m[k];
    double up[3], down[3];
    for (int j = 0; j < 3; ++j) {
      bool rising = r[j] >= 0.0;
      up[j] = rising ? h[j] : l[j];
      down[j] = rising ? l[j] : h[j];
    }
    box->hi[k] = xs[k] + (r[0] * up[0] + r[1] * up[1] + r[2] * up[2]);
    box->lo[k] = xs[k] + (r[0] * down[0] + r[1] * down[1] + r[2] * down[2]);
    if (!(box->lo[k] <= box->hi[k])) return false;
  }
  return true;
}

pdAabb pd_aabb_of(const pdPolyhedron* p, pdVec3 x, const pdMat3* R) {
  PD_ASSERT(p != NULL && R != NULL && p->vertexCount > 0);
  pdVec3 lo, hi;
  pdAabb fast;
  if (pd_polyhedron_cuboid(p, &lo, &hi) && cuboid_box(lo, hi, x, R, &fast)) return fast;
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
