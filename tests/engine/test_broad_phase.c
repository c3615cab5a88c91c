// Broad phase (incremental sweep and prune on three axes): the pair set equals the brute-force O(n²)
// set through coherent and incoherent motion, with fixed bodies and margins; crossings of minima and
// maxima on every axis; a teleported body; identical boxes and touching reached by motion (ties); the
// set growing inside an update; the full-sort fallback and its choice of sweep axis; closed-box
// touching; capacity overflow; the deterministic (a, b) order whatever the history; exact boxes of
// rotated polyhedra.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "test_random.h"

#include "broad_phase.h"
#include "interference.h"
#include "polydyn/polyhedron.h"
#include "polydyn/vecmath.h"

#define PI 3.14159265358979323846

// ---------------------------------------------------------------- helpers

// The reference: every pair a < b, not both fixed, by the header's closed test with the margin.
static int brute_pairs(int n, const pdAabb* boxes, const bool* fixed, double margin, pdPair* out, int capacity) {
  int count = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      if (fixed && fixed[a] && fixed[b]) continue;
      bool overlap = true;
      for (int k = 0; k < 3 && overlap; ++k)
        overlap = boxes[a].lo[k] <= boxes[b].hi[k] + margin && boxes[b].lo[k] <= boxes[a].hi[k] + margin;
      if (!overlap) continue;
      if (count < capacity) out[count] = (pdPair){a, b};
      ++count;
    }
  return count;
}

static void check_sorted(const pdPair* p, int count, int n) {
  for (int i = 0; i < count; ++i) {
    if (!(p[i].a >= 0 && p[i].a < p[i].b && p[i].b < n)) fail_msg("pair %d is (%d, %d)", i, p[i].a, p[i].b);
    if (i > 0 && !(p[i - 1].a < p[i].a || (p[i - 1].a == p[i].a && p[i - 1].b < p[i].b)))
      fail_msg("pairs %d (%d, %d) and %d (%d, %d) out of order", i - 1, p[i - 1].a, p[i - 1].b, i, p[i].a, p[i].b);
  }
}

// Sweep-and-prune pairs into a buffer grown until they fit (the caller's protocol), checked sorted.
static int sap_pairs(pdBroadPhase* bp, int n, pdPair** buf, int* capacity) {
  int count = pd_broad_phase_pairs(bp, *buf, *capacity);
  if (count > *capacity) {
    *capacity = 2 * count;
    *buf = realloc(*buf, (size_t)*capacity * sizeof **buf);
    assert_non_null(*buf);
    assert_int_equal(pd_broad_phase_pairs(bp, *buf, *capacity), count);
  }
  check_sorted(*buf, count, n);
  return count;
}

static void assert_same_pairs(const pdPair* got, int gotCount, const pdPair* want, int wantCount, const char* label) {
  if (gotCount != wantCount) fail_msg("%s: %d pairs, brute force has %d", label, gotCount, wantCount);
  for (int i = 0; i < gotCount; ++i)
    if (got[i].a != want[i].a || got[i].b != want[i].b)
      fail_msg("%s: pair %d is (%d, %d), brute force has (%d, %d)", label, i, got[i].a, got[i].b, want[i].a, want[i].b);
}

typedef struct mover {
  double c[3], h[3];  // centre, half extents
  double v[3];        // velocity per step
} mover;

static pdAabb box_of(const mover* m) {
  pdAabb b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = m->c[k] - m->h[k];
    b.hi[k] = m->c[k] + m->h[k];
  }
  return b;
}

// Speeds are per step, in box sizes (~0.5): a body crosses a box in ~10–20 steps, fast for a
// simulation step but still coherent (each endpoint passes a few others per step).
#define SPEED 0.03
#define ACCEL 0.005

static void random_movers(lcg* g, mover* m, int n, double side) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      m[i].c[k] = lcg_range(g, 0.0, side);
      m[i].h[k] = lcg_range(g, 0.05, 0.5);
      m[i].v[k] = lcg_range(g, -SPEED, SPEED);
    }
}

// The method under test: the sweep-and-prune tests run as written; the grid variants below set this and
// re-run the tests that check results (not sweep-and-prune internals) against brute force.
static pdBroadPhaseMethod testMethod = pd_broadPhaseSweep;
static pdBroadPhase* create_bp(int n, const bool* fixed, double margin) {
  return pd_broad_phase_create_with(n, fixed, margin, testMethod);
}

// One coherent step: drift, small random accelerations, half extents breathing (a rotating body's box).
static void move(lcg* g, mover* m, int n, const bool* fixed) {
  for (int i = 0; i < n; ++i) {
    if (fixed && fixed[i]) continue;
    for (int k = 0; k < 3; ++k) {
      m[i].v[k] = fmin(2 * SPEED, fmax(-2 * SPEED, m[i].v[k] + lcg_range(g, -ACCEL, ACCEL)));
      m[i].c[k] += m[i].v[k];
      m[i].h[k] = fmin(0.6, fmax(0.02, m[i].h[k] + lcg_range(g, -ACCEL, ACCEL)));
    }
  }
}

// n random boxes in a cube of `side`, `moves` coherent moves; SAP must equal brute force at every step.
static void run_against_brute_force(int n, double side, int moves, double fixedFraction, double margin, uint64_t seed,
                                    long long* pairsChecked, long long* fixedFixedExcluded) {
  lcg g = {seed};
  mover* m = malloc((size_t)n * sizeof *m);
  pdAabb* boxes = malloc((size_t)n * sizeof *boxes);
  bool* fixed = calloc((size_t)n, sizeof *fixed);
  assert_true(m && boxes && fixed);
  random_movers(&g, m, n, side);
  for (int i = 0; i < n; ++i) fixed[i] = lcg_uniform(&g) < fixedFraction;
  int wantCap = 1 << 16, capacity = 16;
  pdPair* want = malloc((size_t)wantCap * sizeof *want);
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  pdBroadPhase* bp = create_bp(n, fixed, margin);
  assert_true(want && got && bp);
  for (int step = 0; step <= moves; ++step) {
    if (step > 0) move(&g, m, n, fixed);
    for (int i = 0; i < n; ++i) boxes[i] = box_of(&m[i]);
    pd_broad_phase_update(bp, boxes);
    int gotCount = sap_pairs(bp, n, &got, &capacity);
    int wantCount = brute_pairs(n, boxes, fixed, margin, want, wantCap);
    assert_true(wantCount <= wantCap);
    char label[64];
    snprintf(label, sizeof label, "n %d, step %d", n, step);
    assert_same_pairs(got, gotCount, want, wantCount, label);
    for (int i = 0; i < gotCount; ++i) assert_false(fixed[got[i].a] && fixed[got[i].b]);
    *pairsChecked += gotCount;
    *fixedFixedExcluded += brute_pairs(n, boxes, NULL, margin, NULL, 0) - wantCount;
    // coherent motion: after the first update, insertion sort alone
    if (step > 0 && testMethod == pd_broadPhaseSweep) assert_false(pd_broad_phase_stats(bp).fullSort);
    if (testMethod == pd_broadPhaseGrid) assert_true(pd_broad_phase_stats(bp).grid);
  }
  pd_broad_phase_free(bp);
  free(want);
  free(got);
  free(m);
  free(boxes);
  free(fixed);
}

// ---------------------------------------------------------------- tests

static void test_pairs_equal_brute_force_for_2000_random_boxes_over_50_coherent_moves(void** state) {
  (void)state;
  long long checked = 0, excluded = 0;
  run_against_brute_force(2000, 10.0, 50, 0.0, 0.0, 0x5a9e11ull, &checked, &excluded);
  print_message("%s = brute force over 51 updates of 2000 boxes: %lld pairs checked\n", testMethod == pd_broadPhaseGrid ? "grid" : "SAP", checked);
  assert_int_equal(excluded, 0);
  assert_true(checked > 51 * 2000);  // a meaningful number of overlaps (~1.3 per body)
}

static void test_pairs_equal_brute_force_with_fixed_bodies_and_no_fixed_fixed_pair(void** state) {
  (void)state;
  long long checked = 0, excluded = 0;
  // a dense cloud where many fixed bodies overlap each other: none of those pairs may appear
  run_against_brute_force(2000, 9.0, 50, 0.3, 0.0, 0xf1c5edull, &checked, &excluded);
  print_message("with 30%% fixed bodies: %lld pairs checked, %lld overlapping fixed-fixed pairs left out\n", checked,
                excluded);
  assert_true(checked > 51 * 2000 && excluded > 51 * 100);
}

static void test_pairs_equal_brute_force_with_a_margin(void** state) {
  (void)state;
  long long checked = 0, excluded = 0;
  run_against_brute_force(800, 8.0, 20, 0.2, 0.15, 0x3a6f1ull, &checked, &excluded);
  assert_true(checked > 21 * 400 && excluded > 0);
}

static void test_boxes_touching_exactly_count_as_overlapping(void** state) {
  (void)state;
  // body 0: the unit cube; 1: touches its +x face; 2: touches its +y face from the other side along x
  // (edge contact); 3: touches its +z face only at the corner (1, 1, 1); 4: one ulp beyond +x.
  pdAabb boxes[5] = {
      {{0, 0, 0}, {1, 1, 1}},
      {{1, 0.2, 0.2}, {2, 0.8, 0.8}},
      {{-1, 1, 0.5}, {0, 2, 0.7}},
      {{1, 1, 1}, {3, 3, 3}},
      {{nextafter(1.0, 2.0), 0, 0}, {1.5, 1, 1}},
  };
  pdBroadPhase* bp = create_bp(5, NULL, 0.0);
  pd_broad_phase_update(bp, boxes);
  pdPair out[16];
  int count = pd_broad_phase_pairs(bp, out, 16);
  pdPair want[16];
  int wantCount = brute_pairs(5, boxes, NULL, 0.0, want, 16);
  assert_same_pairs(out, count, want, wantCount, "touching");
  // by hand: (0,1) face, (0,2) edge, (0,3) corner; (0,4) apart by one ulp; (1,4) overlap;
  // (3,4) touch on y and z while overlapping on x.
  const pdPair expect[] = {{0, 1}, {0, 2}, {0, 3}, {1, 4}, {3, 4}};
  assert_same_pairs(out, count, expect, 5, "touching, by hand");
  pd_broad_phase_free(bp);

  // a row of unit boxes touching end to end along x, y, z: the first update's sweep runs along the row,
  // the axis with the fewest overlapping pairs
  for (int axis = 0; axis < 3; ++axis) {
    pdAabb row[4];
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) {
        row[i].lo[k] = k == axis ? (double)i : 0.0;
        row[i].hi[k] = k == axis ? (double)(i + 1) : 1.0;
      }
    bp = create_bp(4, NULL, 0.0);
    pd_broad_phase_update(bp, row);
    if (testMethod == pd_broadPhaseSweep) assert_int_equal(pd_broad_phase_stats(bp).sweepAxis, axis);
    count = pd_broad_phase_pairs(bp, out, 16);
    const pdPair chain[] = {{0, 1}, {1, 2}, {2, 3}};
    assert_same_pairs(out, count, chain, 3, "row");
    pd_broad_phase_free(bp);
  }

  // with a margin: gap == margin overlaps, a gap one ulp wider does not (per the header's formula)
  double margin = 0.25;
  pdAabb gap[3] = {{{0, 0, 0}, {1, 1, 1}}, {{1.25, 0, 0}, {2, 1, 1}}, {{0, 0, nextafter(1.25, 2.0)}, {1, 1, 2}}};
  bp = create_bp(3, NULL, margin);
  pd_broad_phase_update(bp, gap);
  count = pd_broad_phase_pairs(bp, out, 16);
  const pdPair withMargin[] = {{0, 1}};  // (0,2) is one ulp too far apart along z, (1,2) 0.25 + ulp
  assert_same_pairs(out, count, withMargin, 1, "margin");
  pd_broad_phase_free(bp);
}

static void test_capacity_overflow_returns_the_needed_count_and_writes_at_most_capacity(void** state) {
  (void)state;
  enum { N = 40 };
  pdAabb boxes[N];
  lcg g = {77};
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < 3; ++k) {
      boxes[i].lo[k] = lcg_range(&g, 0, 1);
      boxes[i].hi[k] = boxes[i].lo[k] + 1.0;  // all overlap: 780 pairs
    }
  pdBroadPhase* bp = create_bp(N, NULL, 0.0);
  pd_broad_phase_update(bp, boxes);
  assert_int_equal(pd_broad_phase_pairs(bp, NULL, 0), N * (N - 1) / 2);
  enum { CAP = 100, GUARD = 8 };
  pdPair buf[CAP + GUARD];
  for (int i = 0; i < CAP + GUARD; ++i) buf[i] = (pdPair){-7, -7};
  assert_int_equal(pd_broad_phase_pairs(bp, buf, CAP), N * (N - 1) / 2);
  for (int i = CAP; i < CAP + GUARD; ++i) assert_true(buf[i].a == -7 && buf[i].b == -7);
  check_sorted(buf, CAP, N);
  // grown to the needed count: the full set (the result depends only on the last update)
  pdPair full[N * (N - 1) / 2], want[N * (N - 1) / 2];
  assert_int_equal(pd_broad_phase_pairs(bp, full, N * (N - 1) / 2), N * (N - 1) / 2);
  int wantCount = brute_pairs(N, boxes, NULL, 0.0, want, N * (N - 1) / 2);
  assert_same_pairs(full, N * (N - 1) / 2, want, wantCount, "after growing");
  pd_broad_phase_free(bp);
}

static void test_order_is_sorted_and_independent_of_history(void** state) {
  (void)state;
  enum { N = 600, STEPS = 30 };
  lcg g = {2024};
  mover m[N];
  random_movers(&g, m, N, 6.0);
  pdAabb boxes[N], jumbled[N];
  pdBroadPhase* coherent = create_bp(N, NULL, 0.0);
  for (int s = 0; s < STEPS; ++s) {
    move(&g, m, N, NULL);
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    pd_broad_phase_update(coherent, boxes);
  }
  // another instance: first fed unrelated boxes (teleports), then the same final boxes
  pdBroadPhase* other = create_bp(N, NULL, 0.0);
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < 3; ++k) {
      jumbled[i].lo[k] = lcg_range(&g, -50, 50);
      jumbled[i].hi[k] = jumbled[i].lo[k] + 1;
    }
  pd_broad_phase_update(other, jumbled);
  pd_broad_phase_update(other, boxes);
  int cap = N * 20;
  pdPair* a = malloc((size_t)cap * sizeof *a);
  pdPair* b = malloc((size_t)cap * sizeof *b);
  int na = pd_broad_phase_pairs(coherent, a, cap), nb = pd_broad_phase_pairs(other, b, cap);
  print_message("%d pairs after %d steps\n", na, STEPS);
  assert_true(na <= cap && na > N / 2);
  assert_int_equal(na, nb);
  assert_memory_equal(a, b, (size_t)na * sizeof *a);
  check_sorted(a, na, N);
  // calling again without an update gives the same bytes
  assert_int_equal(pd_broad_phase_pairs(coherent, b, cap), na);
  assert_memory_equal(a, b, (size_t)na * sizeof *a);
  free(a);
  free(b);
  pd_broad_phase_free(coherent);
  pd_broad_phase_free(other);
}

static void test_teleports_and_reshaping_fall_back_to_a_full_sort_and_stay_exact(void** state) {
  (void)state;
  enum { N = 500 };
  lcg g = {99};
  mover m[N];
  pdAabb boxes[N];
  pdPair want[N * 8], *got = malloc(16 * sizeof *got);
  int capacity = 16;
  random_movers(&g, m, N, 8.0);
  for (int i = 0; i < N; ++i) m[i].c[0] *= 3.0;  // spread along x
  pdBroadPhase* bp = create_bp(N, NULL, 0.0);
  for (int step = 0; step < 40; ++step) {
    if (step == 10)  // every body teleports: insertion sort would be quadratic
      for (int i = 0; i < N; ++i) m[i].c[0] = lcg_range(&g, 0, 24);
    if (step == 20)  // the cloud becomes a column along z: many crossings on x and z at once
      for (int i = 0; i < N; ++i) {
        m[i].c[0] /= 6.0;
        m[i].c[2] *= 5.0;
      }
    move(&g, m, N, NULL);
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    pd_broad_phase_update(bp, boxes);
    pdBroadPhaseStats st = pd_broad_phase_stats(bp);
    if (step == 0 || step == 10) assert_true(st.fullSort);
    if (step != 0 && step != 10 && step != 20) assert_false(st.fullSort);  // coherent again after each
    int count = sap_pairs(bp, N, &got, &capacity);
    int wantCount = brute_pairs(N, boxes, NULL, 0.0, want, N * 8);
    assert_true(wantCount <= N * 8);
    assert_same_pairs(got, count, want, wantCount, "teleport/reshaping");
  }
  long long fullSorts = pd_broad_phase_stats(bp).fullSorts;
  assert_true(fullSorts == 2 || fullSorts == 3);
  free(got);
  pd_broad_phase_free(bp);
}

// Brute-force counts, per axis, of the pairs overlapping along that axis alone (margin included).
static void axis_overlap_counts(int n, const pdAabb* boxes, double margin, long long counts[3]) {
  for (int k = 0; k < 3; ++k) counts[k] = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int k = 0; k < 3; ++k)
        counts[k] += boxes[a].lo[k] <= boxes[b].hi[k] + margin && boxes[b].lo[k] <= boxes[a].hi[k] + margin;
}

// Update, then the pairs (grown buffer) against brute force; returns the count.
static int update_and_check(pdBroadPhase* bp, int n, const pdAabb* boxes, const bool* fixed, double margin,
                            pdPair** got, int* capacity, const char* label) {
  assert_true(pd_broad_phase_update(bp, boxes));
  int count = sap_pairs(bp, n, got, capacity);
  pdPair* want = malloc(((size_t)count + 1) * sizeof *want);
  assert_non_null(want);
  int wantCount = brute_pairs(n, boxes, fixed, margin, want, count + 1);
  assert_same_pairs(*got, count, want, wantCount, label);
  assert_int_equal(pd_broad_phase_stats(bp).pairs, count);
  free(want);
  return count;
}

static void test_pairs_equal_brute_force_over_200_updates_with_crossings_on_every_axis(void** state) {
  (void)state;
  enum { N = 400, STEPS = 200 };
  const double side = 6.0, margin = 0.05;
  lcg g = {0xc0ffee};
  mover m[N];
  pdAabb boxes[N], before[N];
  bool fixed[N];
  random_movers(&g, m, N, side);
  for (int i = 0; i < N; ++i) fixed[i] = i % 5 == 0;  // fixed bodies stay put; the others cross them
  int capacity = 16;
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  pdBroadPhase* bp = create_bp(N, fixed, margin);
  assert_true(got && bp);
  long long changed[3] = {0, 0, 0}, events = 0, pairChanges = 0, checked = 0;
  for (int step = 0; step <= STEPS; ++step) {
    if (step > 0) {
      move(&g, m, N, fixed);
      for (int i = 0; i < N; ++i)  // reflected at the walls: the density, and the crossings, keep up
        for (int k = 0; k < 3; ++k)
          if (m[i].c[k] < 0.0 || m[i].c[k] > side) m[i].v[k] = -m[i].v[k];
    }
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    char label[64];
    snprintf(label, sizeof label, "coherent, step %d", step);
    checked += update_and_check(bp, N, boxes, fixed, margin, &got, &capacity, label);
    pdBroadPhaseStats st = pd_broad_phase_stats(bp);
    if (step > 0) {
      assert_false(st.fullSort);
      events += st.overlapEvents;
      pairChanges += st.pairChanges;
      // the pairs whose overlap along each axis changed since the last update: crossings on that axis
      for (int a = 0; a < N; ++a)
        for (int b = a + 1; b < N; ++b)
          for (int k = 0; k < 3; ++k) {
            bool now = boxes[a].lo[k] <= boxes[b].hi[k] + margin && boxes[b].lo[k] <= boxes[a].hi[k] + margin;
            bool then = before[a].lo[k] <= before[b].hi[k] + margin && before[b].lo[k] <= before[a].hi[k] + margin;
            changed[k] += now != then;
          }
    }
    memcpy(before, boxes, sizeof boxes);
  }
  print_message("%d updates of %d boxes: %lld pairs checked; axis-overlap changes x %lld, y %lld, z %lld; "
                "%lld min/max swaps, %lld set changes\n",
                STEPS, N, checked, changed[0], changed[1], changed[2], events, pairChanges);
  for (int k = 0; k < 3; ++k) assert_true(changed[k] > 20 * STEPS);
  assert_true(events >= changed[0] + changed[1] + changed[2]);  // each change is at least one event
  assert_true(pairChanges > 2 * STEPS && checked > (long long)STEPS * N / 2);
  free(got);
  pd_broad_phase_free(bp);
}

static void test_a_teleported_body_is_tracked_without_a_full_sort(void** state) {
  (void)state;
  enum { N = 1000 };
  lcg g = {4242};
  mover* m = malloc(N * sizeof *m);
  pdAabb* boxes = malloc(N * sizeof *boxes);
  int capacity = 16;
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  assert_true(m && boxes && got);
  random_movers(&g, m, N, 10.0);
  pdBroadPhase* bp = create_bp(N, NULL, 0.0);
  const int body = 417;
  for (int step = 0; step < 24; ++step) {
    move(&g, m, N, NULL);
    if (step == 6)  // far away on every axis: it leaves all its pairs
      for (int k = 0; k < 3; ++k) m[body].c[k] = 1000.0 + k;
    if (step == 12)  // back into the cloud, grown so that it overlaps many others at once
      for (int k = 0; k < 3; ++k) {
        m[body].c[k] = 5.0;
        m[body].h[k] = 1.5;
      }
    if (step == 18)  // to the cloud's far corner, below everything on x
      m[body].c[0] = -3.0;
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    char label[64];
    snprintf(label, sizeof label, "teleport, step %d", step);
    int count = update_and_check(bp, N, boxes, NULL, 0.0, &got, &capacity, label);
    pdBroadPhaseStats st = pd_broad_phase_stats(bp);
    if (step > 0) assert_false(st.fullSort);  // one body's six endpoints: within the swap budget
    int involving = 0;
    for (int i = 0; i < count; ++i) involving += got[i].a == body || got[i].b == body;
    if (step >= 6 && step < 12) assert_int_equal(involving, 0);
    if (step == 12) {
      print_message("the teleported body overlaps %d others after %lld swaps\n", involving, st.swaps);
      assert_true(involving > 20 && st.swaps > N);
    }
  }
  free(got);
  free(m);
  free(boxes);
  pd_broad_phase_free(bp);
}

static void test_identical_boxes_moving_together_and_one_sliding_through_them(void** state) {
  (void)state;
  // every endpoint value is shared by N bodies: the order is decided by (kind, body) alone
  enum { N = 64 };
  const double margin = 0.125;
  pdAabb boxes[N];
  bool fixed[N];
  for (int i = 0; i < N; ++i) fixed[i] = i % 4 == 1;
  int capacity = 16;
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  pdBroadPhase* bp = create_bp(N, fixed, margin);
  assert_true(got && bp);
  int fixedCount = N / 4, all = N * (N - 1) / 2 - fixedCount * (fixedCount - 1) / 2;
  for (int step = 0; step < 8; ++step) {  // all together, by exact steps of 1/4
    for (int i = 0; i < N; ++i)
      for (int k = 0; k < 3; ++k) {
        boxes[i].lo[k] = 0.25 * step + k;
        boxes[i].hi[k] = boxes[i].lo[k] + 1.0;
      }
    assert_int_equal(update_and_check(bp, N, boxes, fixed, margin, &got, &capacity, "identical"), all);
    if (step > 0) assert_int_equal(pd_broad_phase_stats(bp).swaps, 0);  // the order does not change
  }
  // body 10 slides out along each axis in steps of 1/8, through touching-with-margin (gap == margin)
  // and touching-without (gap 0) exactly, then back into the stack
  for (int axis = 0; axis < 3; ++axis) {
    pdAabb home = boxes[10];
    for (int s = 0; s <= 24; ++s) {
      double shift = s <= 12 ? 0.125 * s : 0.125 * (24 - s);  // out to 1.5 (gap 0.5), back to 0
      boxes[10].lo[axis] = home.lo[axis] + shift;
      boxes[10].hi[axis] = home.hi[axis] + shift;
      char label[64];
      snprintf(label, sizeof label, "slide along %d, shift %g", axis, shift);
      int count = update_and_check(bp, N, boxes, fixed, margin, &got, &capacity, label);
      // overlapping (body 10 is not fixed) while the gap shift - 1 <= margin, that is shift <= 1.125
      assert_int_equal(count, shift <= 1.0 + margin ? all : all - (N - 1));
      assert_false(pd_broad_phase_stats(bp).fullSort);
    }
  }
  free(got);
  pd_broad_phase_free(bp);
}

static void test_touching_reached_by_motion_on_a_lattice_is_exact(void** state) {
  (void)state;
  // unit boxes on a lattice of pitch 1.5 moving by multiples of 1/8 (exact in binary): the gaps between
  // neighbours pass exactly through 0 and through the margin, on every axis, many times
  enum { SIDE = 5, N = SIDE * SIDE * SIDE, STEPS = 48 };
  const double margins[2] = {0.0, 0.25};
  for (int mi = 0; mi < 2; ++mi) {
    double margin = margins[mi];
    pdAabb boxes[N];
    double v[N][3];
    lcg g = {31 + (uint64_t)mi};
    for (int i = 0; i < N; ++i)
      for (int k = 0; k < 3; ++k) v[i][k] = 0.125 * (double)((int)(lcg_uniform(&g) * 5) - 2);
    int capacity = 16;
    pdPair* got = malloc((size_t)capacity * sizeof *got);
    pdBroadPhase* bp = create_bp(N, NULL, margin);
    assert_true(got && bp);
    long long exactTouches = 0;
    for (int step = 0; step <= STEPS; ++step) {
      double t = step <= STEPS / 2 ? step : STEPS - step;  // out and back
      for (int i = 0; i < N; ++i) {
        int cell[3] = {i % SIDE, i / SIDE % SIDE, i / (SIDE * SIDE)};
        for (int k = 0; k < 3; ++k) {
          boxes[i].lo[k] = 1.5 * cell[k] + t * v[i][k];
          boxes[i].hi[k] = boxes[i].lo[k] + 1.0;
        }
      }
      char label[64];
      snprintf(label, sizeof label, "lattice, margin %g, step %d", margin, step);
      update_and_check(bp, N, boxes, NULL, margin, &got, &capacity, label);
      if (step > 0 && testMethod == pd_broadPhaseSweep) assert_false(pd_broad_phase_stats(bp).fullSort);
      if (testMethod == pd_broadPhaseGrid) assert_true(pd_broad_phase_stats(bp).grid);
      for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b)
          for (int k = 0; k < 3; ++k) exactTouches += a != b && boxes[a].lo[k] == boxes[b].hi[k] + margin;
    }
    print_message("margin %g: %lld exact touches (gap == margin) along an axis met by motion\n", margin,
                  exactTouches);
    assert_true(exactTouches > 100);
    free(got);
    pd_broad_phase_free(bp);
  }
}

static void test_the_set_grows_inside_an_update_as_a_cloud_contracts(void** state) {
  (void)state;
  enum { N = 500 };
  lcg g = {8080};
  mover m[N];
  pdAabb boxes[N];
  random_movers(&g, m, N, 20.0);
  int capacity = 16;
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  pdBroadPhase* bp = create_bp(N, NULL, 0.0);
  assert_true(got && bp);
  int initialCapacity = pd_broad_phase_stats(bp).setCapacity, growthsWhileIncremental = 0, count = 0;
  assert_true(initialCapacity >= PD_BROAD_PHASE_PAIRS_PER_BODY * N);
  for (int step = 0; step < 80; ++step) {
    for (int i = 0; i < N; ++i)  // 3% closer to the centre each step: coherent, ever denser
      for (int k = 0; k < 3; ++k) m[i].c[k] = 10.0 + 0.97 * (m[i].c[k] - 10.0);
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    int growths = pd_broad_phase_stats(bp).setGrowths;
    char label[64];
    snprintf(label, sizeof label, "contracting, step %d", step);
    count = update_and_check(bp, N, boxes, NULL, 0.0, &got, &capacity, label);
    pdBroadPhaseStats st = pd_broad_phase_stats(bp);
    if (!st.fullSort) growthsWhileIncremental += st.setGrowths - growths;
  }
  pdBroadPhaseStats st = pd_broad_phase_stats(bp);
  print_message("%d pairs at the end; set capacity %d -> %d after %d growths (%d in incremental updates), "
                "%lld full sorts\n",
                count, initialCapacity, st.setCapacity, st.setGrowths, growthsWhileIncremental, st.fullSorts);
  assert_true(count > initialCapacity && st.setCapacity >= count && growthsWhileIncremental > 0);
  free(got);
  pd_broad_phase_free(bp);
}

static void test_a_full_sort_sweeps_along_the_axis_with_fewest_overlaps_and_coherent_updates_follow(
    void** state) {
  (void)state;
  enum { N = 600 };
  lcg g = {515};
  mover m[N];
  pdAabb boxes[N];
  random_movers(&g, m, N, 6.0);
  for (int i = 0; i < N; ++i) {  // a slab: long along y, thin along z
    m[i].c[1] *= 4.0;
    m[i].c[2] *= 0.2;
  }
  int capacity = 16;
  pdPair* got = malloc((size_t)capacity * sizeof *got);
  pdBroadPhase* bp = create_bp(N, NULL, 0.0);
  assert_true(got && bp);
  for (int step = 0; step < 40; ++step) {
    move(&g, m, N, NULL);
    if (step == 20)  // everybody jumps: a full sort and a rebuild, then coherent updates again
      for (int i = 0; i < N; ++i) {
        m[i].c[0] = lcg_range(&g, 0.0, 6.0);
        m[i].c[1] = lcg_range(&g, 0.0, 24.0);
      }
    for (int i = 0; i < N; ++i) boxes[i] = box_of(&m[i]);
    update_and_check(bp, N, boxes, NULL, 0.0, &got, &capacity, "slab");
    pdBroadPhaseStats st = pd_broad_phase_stats(bp);
    assert_int_equal(st.fullSort, step == 0 || step == 20);
    if (st.fullSort) {
      long long counts[3];
      axis_overlap_counts(N, boxes, 0.0, counts);
      print_message("step %d: overlapping pairs along x %lld, y %lld, z %lld; swept along %d\n", step, counts[0],
                    counts[1], counts[2], st.sweepAxis);
      assert_int_equal(st.sweepAxis, 1);
      assert_true(st.sweepTests == counts[1] && counts[1] < counts[0] && counts[0] < counts[2]);
    }
  }
  assert_int_equal(pd_broad_phase_stats(bp).fullSorts, 2);
  free(got);
  pd_broad_phase_free(bp);
}

static void test_zero_one_and_coincident_bodies(void** state) {
  (void)state;
  pdBroadPhase* bp = create_bp(0, NULL, 0.0);
  pd_broad_phase_update(bp, NULL);
  assert_int_equal(pd_broad_phase_pairs(bp, NULL, 0), 0);
  pd_broad_phase_free(bp);

  pdAabb one = {{0, 0, 0}, {1, 1, 1}};
  bp = create_bp(1, NULL, 0.0);
  assert_int_equal(pd_broad_phase_pairs(bp, NULL, 0), 0);  // before any update: nothing
  pd_broad_phase_update(bp, &one);
  assert_int_equal(pd_broad_phase_pairs(bp, NULL, 0), 0);
  pd_broad_phase_free(bp);

  // ten identical point boxes: all 45 pairs; with bodies 0..4 fixed, the 10 fixed-fixed pairs go
  enum { N = 10 };
  pdAabb same[N];
  bool fixed[N];
  for (int i = 0; i < N; ++i) {
    same[i] = (pdAabb){{1, 2, 3}, {1, 2, 3}};
    fixed[i] = i < 5;
  }
  pdPair out[64], want[64];
  bp = create_bp(N, NULL, 0.0);
  pd_broad_phase_update(bp, same);
  int count = pd_broad_phase_pairs(bp, out, 64);
  assert_same_pairs(out, count, want, brute_pairs(N, same, NULL, 0.0, want, 64), "identical");
  assert_int_equal(count, 45);
  pd_broad_phase_free(bp);
  bp = create_bp(N, fixed, 0.0);
  pd_broad_phase_update(bp, same);
  count = pd_broad_phase_pairs(bp, out, 64);
  assert_same_pairs(out, count, want, brute_pairs(N, same, fixed, 0.0, want, 64), "identical, half fixed");
  assert_int_equal(count, 35);
  pd_broad_phase_free(bp);
}

static void test_aabb_of_is_the_exact_box_of_the_rotated_vertices(void** state) {
  (void)state;
  pdError why = {0};
  pdPolyhedron cube;
  assert_true(pd_polyhedron_cube(&cube, (const double[3]){2, 1, 1}, &why));
  // 45° about z: the 2×1 footprint becomes a 3/√2-wide square
  pdMat3 R = pd_quat_to_mat3(pd_quat_from_axis_angle(pd_v3(0, 0, 1), PI / 4));
  pdAabb b = pd_aabb_of(&cube, pd_v3(10, -5, 1), &R);
  double h = 1.5 / sqrt(2.0);
  assert_true(fabs(b.lo[0] - (10 - h)) < 1e-14 && fabs(b.hi[0] - (10 + h)) < 1e-14);
  assert_true(fabs(b.lo[1] - (-5 - h)) < 1e-14 && fabs(b.hi[1] - (-5 + h)) < 1e-14);
  assert_true(fabs(b.lo[2] - 0.5) < 1e-15 && fabs(b.hi[2] - 1.5) < 1e-15);
  // random poses of a geodesic sphere (every vertex visited) and of cuboids (two corners: pd_polyhedron_cuboid), one off
  // its centre, and the quarter turns whose matrices hold zeros of either sign: equal, bit for bit, to min/max over
  // x + R·p, and attained
  pdPolyhedron s, offset;
  assert_true(pd_polyhedron_sphere(&s, 1, (const double[3]){1, 2, 3}, &why));
  assert_true(pd_polyhedron_cube(&offset, (const double[3]){0.2, 0.15, 0.1}, &why));
  pd_polyhedron_translate(&offset, pd_v3(0.013, -0.0071, 0.3));
  pdVec3 lo, hi;
  assert_true(pd_polyhedron_cuboid(&cube, &lo, &hi) && pd_polyhedron_cuboid(&offset, &lo, &hi));
  assert_false(pd_polyhedron_cuboid(&s, &lo, &hi));
  const pdPolyhedron* shapes[3] = {&s, &cube, &offset};
  lcg g = {5};
  for (int trial = 0; trial < 300; ++trial) {
    pdQuat q = pd_quat_normalize(
        (pdQuat){lcg_range(&g, -1, 1), lcg_range(&g, -1, 1), lcg_range(&g, -1, 1), lcg_range(&g, -1, 1)});
    if (trial % 10 == 0) q = pd_quat_from_axis_angle(trial % 20 ? pd_v3(1, 0, 0) : pd_v3(0, -1, 0), PI / 2 * (trial / 20));
    pdMat3 Rq = pd_quat_to_mat3(q);
    pdVec3 x = pd_v3(lcg_range(&g, -10, 10), lcg_range(&g, -10, 10), lcg_range(&g, -10, 10));
    const pdPolyhedron* p = shapes[trial % 3];
    pdAabb box = pd_aabb_of(p, x, &Rq);
    bool hitLo[3] = {false, false, false}, hitHi[3] = {false, false, false};
    for (int v = 0; v < p->vertexCount; ++v) {
      pdVec3 w = pd_v3_add(x, pd_mat3_mulv(&Rq, p->vertices[v]));
      for (int k = 0; k < 3; ++k) {
        double c = pd_v3_get(w, k);
        assert_true(box.lo[k] <= c && c <= box.hi[k]);
        hitLo[k] = hitLo[k] || c == box.lo[k];
        hitHi[k] = hitHi[k] || c == box.hi[k];
      }
    }
    for (int k = 0; k < 3; ++k) assert_true(hitLo[k] && hitHi[k]);
  }
  pd_polyhedron_free(&offset);
  pd_polyhedron_free(&cube);
  pd_polyhedron_free(&s);
}

// ---------------------------------------------------------------- the grid method

#define GRID_VARIANT(name, test)          \
  static void name(void** state) {        \
    testMethod = pd_broadPhaseGrid;       \
    test(state);                          \
    testMethod = pd_broadPhaseSweep;      \
  }
GRID_VARIANT(test_grid_pairs_equal_brute_force_for_2000_random_boxes_over_50_moves,
             test_pairs_equal_brute_force_for_2000_random_boxes_over_50_coherent_moves)
GRID_VARIANT(test_grid_pairs_equal_brute_force_with_fixed_bodies_and_no_fixed_fixed_pair,
             test_pairs_equal_brute_force_with_fixed_bodies_and_no_fixed_fixed_pair)
GRID_VARIANT(test_grid_pairs_equal_brute_force_with_a_margin, test_pairs_equal_brute_force_with_a_margin)
GRID_VARIANT(test_grid_boxes_touching_exactly_count_as_overlapping, test_boxes_touching_exactly_count_as_overlapping)
GRID_VARIANT(test_grid_capacity_overflow_returns_the_needed_count,
             test_capacity_overflow_returns_the_needed_count_and_writes_at_most_capacity)
GRID_VARIANT(test_grid_zero_one_and_coincident_bodies, test_zero_one_and_coincident_bodies)
GRID_VARIANT(test_grid_touching_reached_by_motion_on_a_lattice_is_exact, test_touching_reached_by_motion_on_a_lattice_is_exact)

// Floors, walls and long bars span many cells: they are tested directly, and the pairs still equal brute
// force's, including the small boxes touching them exactly.
static void test_grid_with_boxes_much_larger_than_the_cell_equals_brute_force(void** state) {
  (void)state;
  enum { N = 600, BIG = 6 };
  lcg g = {0xb16b0e5ull};
  pdAabb boxes[N];
  bool fixed[N];
  for (int i = 0; i < N; ++i) {
    fixed[i] = i < BIG / 2;
    for (int k = 0; k < 3; ++k) {
      double c = lcg_range(&g, 0, 8), h = lcg_range(&g, 0.05, 0.3);
      boxes[i].lo[k] = c - h;
      boxes[i].hi[k] = c + h;
    }
  }
  // a floor (z top at exactly 1, touched by box BIG), two walls, three long bars
  boxes[0] = (pdAabb){{-1, -1, 0}, {9, 9, 1}};
  boxes[1] = (pdAabb){{-1, -1, 0}, {0, 9, 9}};
  boxes[2] = (pdAabb){{8, -1, 0}, {9, 9, 9}};
  for (int i = 3; i < BIG; ++i) boxes[i] = (pdAabb){{0, 2.0 * i - 4, 3}, {8, 2.0 * i - 3.8, 3.2}};
  boxes[BIG] = (pdAabb){{4, 4, 1}, {4.2, 4.2, 1.2}};
  pdBroadPhase* bp = pd_broad_phase_create_with(N, fixed, 0.0, pd_broadPhaseGrid);
  assert_true(pd_broad_phase_update(bp, boxes));
  pdBroadPhaseStats st = pd_broad_phase_stats(bp);
  assert_true(st.grid && st.largeBoxes >= BIG);
  static pdPair got[N * 8], want[N * 8];
  int count = pd_broad_phase_pairs(bp, got, N * 8), wantCount = brute_pairs(N, boxes, fixed, 0.0, want, N * 8);
  assert_same_pairs(got, count, want, wantCount, "large boxes");
  bool touching = false;
  for (int i = 0; i < count; ++i) touching = touching || (got[i].a == 0 && got[i].b == BIG);
  assert_true(touching);
  print_message("grid with %d large boxes: %d pairs, cell %.3g m, %lld entries, %lld box tests\n", st.largeBoxes,
                count, st.cell, st.cellEntries, st.boxTests);
  pd_broad_phase_free(bp);
}

static void test_auto_method_uses_the_grid_from_the_threshold_on(void** state) {
  (void)state;
  pdBroadPhase* small = pd_broad_phase_create(PD_BROAD_PHASE_GRID_MIN_BODIES - 1, NULL, 0.0);
  pdBroadPhase* large = pd_broad_phase_create(PD_BROAD_PHASE_GRID_MIN_BODIES, NULL, 0.0);
  assert_false(pd_broad_phase_stats(small).grid);
  assert_true(pd_broad_phase_stats(large).grid);
  pd_broad_phase_free(small);
  pd_broad_phase_free(large);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pairs_equal_brute_force_for_2000_random_boxes_over_50_coherent_moves),
      cmocka_unit_test(test_pairs_equal_brute_force_with_fixed_bodies_and_no_fixed_fixed_pair),
      cmocka_unit_test(test_pairs_equal_brute_force_with_a_margin),
      cmocka_unit_test(test_boxes_touching_exactly_count_as_overlapping),
      cmocka_unit_test(test_capacity_overflow_returns_the_needed_count_and_writes_at_most_capacity),
      cmocka_unit_test(test_order_is_sorted_and_independent_of_history),
      cmocka_unit_test(test_teleports_and_reshaping_fall_back_to_a_full_sort_and_stay_exact),
      cmocka_unit_test(test_pairs_equal_brute_force_over_200_updates_with_crossings_on_every_axis),
      cmocka_unit_test(test_a_teleported_body_is_tracked_without_a_full_sort),
      cmocka_unit_test(test_identical_boxes_moving_together_and_one_sliding_through_them),
      cmocka_unit_test(test_touching_reached_by_motion_on_a_lattice_is_exact),
      cmocka_unit_test(test_the_set_grows_inside_an_update_as_a_cloud_contracts),
      cmocka_unit_test(test_a_full_sort_sweeps_along_the_axis_with_fewest_overlaps_and_coherent_updates_follow),
      cmocka_unit_test(test_zero_one_and_coincident_bodies),
      cmocka_unit_test(test_aabb_of_is_the_exact_box_of_the_rotated_vertices),
      cmocka_unit_test(test_grid_pairs_equal_brute_force_for_2000_random_boxes_over_50_moves),
      cmocka_unit_test(test_grid_pairs_equal_brute_force_with_fixed_bodies_and_no_fixed_fixed_pair),
      cmocka_unit_test(test_grid_pairs_equal_brute_force_with_a_margin),
      cmocka_unit_test(test_grid_boxes_touching_exactly_count_as_overlapping),
      cmocka_unit_test(test_grid_capacity_overflow_returns_the_needed_count),
      cmocka_unit_test(test_grid_zero_one_and_coincident_bodies),
      cmocka_unit_test(test_grid_touching_reached_by_motion_on_a_lattice_is_exact),
      cmocka_unit_test(test_grid_with_boxes_much_larger_than_the_cell_equals_brute_force),
      cmocka_unit_test(test_auto_method_uses_the_grid_from_the_threshold_on),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
