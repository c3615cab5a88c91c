// polydyn — broad phase by a uniform hashed grid (conventions and cost in broad_grid.h).
//
// Design
// - The cell edge is GRID_CELL_PER_BOX times the median largest extent of the boxes (with the margin),
//   recomputed at every update, so a box covers 1–8 cells typically and a cell holds a few boxes at any
//   packing the bodies can reach without interpenetrating.
// - A box spanning more than GRID_MAX_SPAN cells along an axis (a floor, a wall, a long bar) does not go
//   into the grid: it is tested against every other box. Scenes have few of those.
// - The grid is a hash table rebuilt each update by counting sort: every (box, cell) entry goes to the
//   bucket of its cell's hash; boxes in the same cell (same integer coordinates, not just the same
//   bucket) are tested pairwise. A pair of overlapping boxes shares every cell of their intersection;
//   it is reported only by the cell holding the intersection's lowest corner, so exactly once.
// - The pairs are sorted at the end, so the result does not depend on the hash or the order of entries.
#include "broad_grid.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "polydyn/error.h"

// Cell edge over the median box's largest extent: 2 keeps a typical box in at most 2 cells per axis
// (≤ 8 cells) while a cell still holds only the boxes near it.
#define GRID_CELL_PER_BOX 2.0
// Boxes spanning more cells than this along an axis are tested directly (see the design note): beyond
// 4 cells per axis (64 entries) a box costs more in the grid than a pass over the others in most scenes.
#define GRID_MAX_SPAN 4
// A cell's three integer coordinates pack into one 64-bit key, 21 bits each (offset by 2^20), so a box
// further than 2^20 cells from the origin along an axis is treated as large: ±10⁶ cells is ±800 km for
// the 0.8 m cells of 0.4 m bodies, still ±1 km for millimetre ones.
#define GRID_COORD_BITS 21
#define GRID_COORD_OFFSET (1 << (GRID_COORD_BITS - 1))
#define GRID_MAX_COORD ((double)GRID_COORD_OFFSET - 1.0)

typedef struct entry {
  uint64_t key;  // packed cell coordinates
  int body;
} entry;

static inline uint64_t pack_cell(int64_t x, int64_t y, int64_t z) {
  return (uint64_t)(x + GRID_COORD_OFFSET) << (2 * GRID_COORD_BITS) |
         (uint64_t)(y + GRID_COORD_OFFSET) << GRID_COORD_BITS | (uint64_t)(z + GRID_COORD_OFFSET);
}

struct pdBroadGrid {
  int n;
  double margin;
  bool* fixed;       // (n)
  pdAabb* boxes;     // (n) this update's boxes, hi grown by the margin
  double* scratch;   // (n) extents, for the median
  int* large;        // (n) bodies not in the grid
  bool* isLarge;     // (n)
  int64_t (*cells)[3];   // (n) lowest cell of each box in the grid
  unsigned char (*span)[3];  // (n) cells it covers along each axis
  entry* entries;    // (entryCap)
  entry* binned;     // (entryCap) entries ordered by bucket
  uint32_t* bucketOf;   // (entryCap) bucket of each entry
  int* bucketStart;  // (bucketCount + 1)
  size_t entryCap, bucketCount;
  pdPair* pairs;     // (pairCap)
  size_t pairCount, pairCap;
  pdBroadGridStats stats;
};

pdBroadGrid* pd_broad_grid_create(int bodyCount, const bool* fixed, double margin) {
  PD_ASSERT(bodyCount >= 0 && margin >= 0.0);
  pdBroadGrid* g = calloc(1, sizeof *g);
  if (!g) return NULL;
  size_t n = (size_t)(bodyCount > 0 ? bodyCount : 1);
  g->n = bodyCount;
  g->margin = margin;
  g->fixed = calloc(n, sizeof *g->fixed);
  g->boxes = malloc(n * sizeof *g->boxes);
  g->scratch = malloc(n * sizeof *g->scratch);
  g->large = malloc(n * sizeof *g->large);
  g->isLarge = malloc(n * sizeof *g->isLarge);
  g->cells = malloc(n * sizeof *g->cells);
  g->span = malloc(n * sizeof *g->span);
  if (!g->fixed || !g->boxes || !g->scratch || !g->large || !g->isLarge || !g->cells || !g->span) {
    pd_broad_grid_free(g);
    return NULL;
  }
  if (fixed) memcpy(g->fixed, fixed, (size_t)bodyCount * sizeof *fixed);
  return g;
}

void pd_broad_grid_free(pdBroadGrid* g) {
  if (!g) return;
  free(g->fixed);
  free(g->boxes);
  free(g->scratch);
  free(g->large);
  free(g->isLarge);
  free(g->cells);
  free(g->span);
  free(g->entries);
  free(g->binned);
  free(g->bucketOf);
  free(g->bucketStart);
  free(g->pairs);
  free(g);
}

// Grows *p to hold `need` elements of `size` bytes (doubling); false when out of memory.
static bool grow(void** p, size_t* cap, size_t need, size_t size) {
  if (need <= *cap) return true;
  size_t c = *cap ? *cap : 64;
  while (c < need) c *= 2;
  void* q = realloc(*p, c * size);
  if (!q) return false;
  *p = q;
  *cap = c;
  return true;
}

// The k-th smallest of v[0..n) (quickselect; v is reordered). Deterministic: middle pivot.
static double select_kth(double* v, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    double pivot = v[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (v[i] < pivot) ++i;
      while (v[j] > pivot) --j;
      if (i <= j) {
        double t = v[i];
        v[i] = v[j];
        v[j] = t;
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    if (k <= j) hi = j;
    else if (k >= i) lo = i;
    else return v[k];
  }
  return v[k];
}

static inline bool overlap(const pdAabb* a, const pdAabb* b) {
  return a->lo[0] <= b->hi[0] && b->lo[0] <= a->hi[0] && a->lo[1] <= b->hi[1] && b->lo[1] <= a->hi[1] &&
         a->lo[2] <= b->hi[2] && b->lo[2] <= a->hi[2];
}

// Fibonacci hashing of the packed key: the top bits, `shift` = 64 − log2(buckets).
static inline uint32_t cell_bucket(uint64_t key, int shift) {
  return (uint32_t)((key * 0x9E3779B97F4A7C15ull) >> shift);
}

// The three per-entry arrays grow together to hold `count` entries.
static bool grow_entries(pdBroadGrid* g, size_t count) {
  if (count <= g->entryCap) return true;
  size_t cap = g->entryCap ? g->entryCap : 64;
  while (cap < count) cap *= 2;
  entry* e = realloc(g->entries, cap * sizeof *e);
  if (e) g->entries = e;
  entry* b = realloc(g->binned, cap * sizeof *b);
  if (b) g->binned = b;
  uint32_t* k = realloc(g->bucketOf, cap * sizeof *k);
  if (k) g->bucketOf = k;
  if (!e || !b || !k) return false;  // those that grew are kept; entryCap stays the old, safe, size
  g->entryCap = cap;
  return true;
}

static bool add_pair(pdBroadGrid* g, int a, int b) {
  if (!grow((void**)&g->pairs, &g->pairCap, g->pairCount + 1, sizeof *g->pairs)) return false;
  g->pairs[g->pairCount++] = a < b ? (pdPair){a, b} : (pdPair){b, a};
  return true;
}

static int compare_pairs(const void* pa, const void* pb) {
  const pdPair *a = pa, *b = pb;
  if (a->a != b->a) return a->a < b->a ? -1 : 1;
  return (a->b > b->b) - (a->b < b->b);
}

static double median_extent(pdBroadGrid* g) {
  int n = g->n;
  for (int i = 0; i < n; ++i) {
    const pdAabb* b = &g->boxes[i];
    g->scratch[i] = fmax(b->hi[0] - b->lo[0], fmax(b->hi[1] - b->lo[1], b->hi[2] - b->lo[2]));
  }
  return select_kth(g->scratch, (size_t)n, (size_t)n / 2);
}

// Lowest cell and span of box b along each axis; false when the box is too large or too far out.
static bool cell_range(const pdAabb* b, double inverseCell, int64_t lo[3], unsigned char span[3]) {
  for (int k = 0; k < 3; ++k) {
    double l = floor(b->lo[k] * inverseCell), h = floor(b->hi[k] * inverseCell);
    if (!(fabs(l) < GRID_MAX_COORD && fabs(h) < GRID_MAX_COORD) || h - l + 1.0 > GRID_MAX_SPAN) return false;
    lo[k] = (int64_t)l;
    span[k] = (unsigned char)(h - l + 1.0);
  }
  return true;
}

bool pd_broad_grid_update(pdBroadGrid* g, const pdAabb* boxes) {
  int n = g->n;
  g->pairCount = 0;
  g->stats = (pdBroadGridStats){0};
  if (n < 2) return true;
  for (int i = 0; i < n; ++i) {
    g->boxes[i] = boxes[i];
    for (int k = 0; k < 3; ++k) g->boxes[i].hi[k] += g->margin;
  }
  double cell = GRID_CELL_PER_BOX * median_extent(g);
  if (!(cell > 0.0) || !isfinite(cell)) cell = 1.0;  // point boxes: any cell works
  // cells are taken as floor(coordinate / cell) by one multiplication: every test below uses the same
  // product, so a box and the owner test agree on which cell a coordinate falls in
  double inverseCell = 1.0 / cell;
  g->stats.cell = cell;

  // entries: count first, so the arrays grow once
  size_t count = 0;
  int largeCount = 0;
  for (int i = 0; i < n; ++i) {
    g->isLarge[i] = !cell_range(&g->boxes[i], inverseCell, g->cells[i], g->span[i]);
    if (g->isLarge[i]) g->large[largeCount++] = i;
    else count += (size_t)g->span[i][0] * g->span[i][1] * g->span[i][2];
  }
  if (!grow_entries(g, count)) return false;
  size_t buckets = 64;
  int bits = 6;
  while (buckets < count) buckets *= 2, ++bits;
  if (buckets > g->bucketCount) {
    int* b = realloc(g->bucketStart, (buckets + 1) * sizeof *b);
    if (!b) return false;
    g->bucketStart = b;
    g->bucketCount = buckets;
  }
  int shift = 64 - bits;
  memset(g->bucketStart, 0, (buckets + 1) * sizeof *g->bucketStart);
  size_t e = 0;
  for (int i = 0; i < n; ++i) {
    if (g->isLarge[i]) continue;
    const int64_t* c = g->cells[i];
    const unsigned char* sp = g->span[i];
    for (int64_t x = c[0]; x < c[0] + sp[0]; ++x)
      for (int64_t y = c[1]; y < c[1] + sp[1]; ++y)
        for (int64_t z = c[2]; z < c[2] + sp[2]; ++z) {
          uint64_t key = pack_cell(x, y, z);
          uint32_t b = cell_bucket(key, shift);
          g->entries[e] = (entry){key, i};
          g->bucketOf[e++] = b;
          ++g->bucketStart[b + 1];
        }
  }
  // counting sort by bucket: bucketStart[b] becomes the start of bucket b, then each entry is placed
  for (size_t b = 0; b < buckets; ++b) g->bucketStart[b + 1] += g->bucketStart[b];
  for (size_t j = 0; j < count; ++j) g->binned[g->bucketStart[g->bucketOf[j]]++] = g->entries[j];
  // placing advanced each start to its bucket's end: shift back
  for (size_t b = buckets; b > 0; --b) g->bucketStart[b] = g->bucketStart[b - 1];
  g->bucketStart[0] = 0;

  long long tests = 0;
  for (size_t b = 0; b < buckets; ++b) {
    int s = g->bucketStart[b], t = g->bucketStart[b + 1];
    for (int i = s; i + 1 < t; ++i) {
      const entry* ei = &g->binned[i];
      for (int j = i + 1; j < t; ++j) {
        const entry* ej = &g->binned[j];
        if (ei->key != ej->key) continue;  // another cell in the same bucket
        int p = ei->body, q = ej->body;
        if (g->fixed[p] && g->fixed[q]) continue;
        const pdAabb *A = &g->boxes[p], *B = &g->boxes[q];
        ++tests;
        if (!overlap(A, B)) continue;
        // report once: in the cell holding the intersection's lowest corner
        uint64_t owner = pack_cell((int64_t)floor(fmax(A->lo[0], B->lo[0]) * inverseCell),
                                   (int64_t)floor(fmax(A->lo[1], B->lo[1]) * inverseCell),
                                   (int64_t)floor(fmax(A->lo[2], B->lo[2]) * inverseCell));
        if (owner == ei->key && !add_pair(g, p, q)) return false;
      }
    }
  }
  // large boxes against every box (each large–large pair once)
  for (int l = 0; l < largeCount; ++l) {
    int p = g->large[l];
    for (int q = 0; q < n; ++q) {
      if (q == p || (g->isLarge[q] && q < p) || (g->fixed[p] && g->fixed[q])) continue;
      ++tests;
      if (overlap(&g->boxes[p], &g->boxes[q]) && !add_pair(g, p, q)) return false;
    }
  }
  if (g->pairCount > 1) qsort(g->pairs, g->pairCount, sizeof *g->pairs, compare_pairs);  // pairs may be NULL when empty
  g->stats.entries = (long long)count;
  g->stats.large = largeCount;
  g->stats.tests = tests;
  return true;
}

const pdPair* pd_broad_grid_pairs(const pdBroadGrid* g, int* count) {
  *count = (int)g->pairCount;
  return g->pairs;
}

pdBroadGridStats pd_broad_grid_stats(const pdBroadGrid* g) { return g->stats; }
