// Stacks of bodies of very different masses come to rest, and a heavy body's impact on a light one keeps the
// requested restitution (docs/contact-model.md, "Stacks"): the modal dampers sized for the slow mode a pair takes
// part in (engine/src/stack_modes.c), and that mode's damping ratio as pd_state_stack_modes finds it.
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_eigen.h>

#include "contact_list.h"
#include "material.h"
#include "model_contact.h"
#include "polydyn/model.h"
#include "polydyn/state.h"
#include "scene_run.h"
#include "stack_modes.h"

// Settled: every body slower than this after SETTLE_TIME (the requirement).
#define SETTLED_SPEED 1e-3  // m/s
#define SETTLE_TIME 1.0     // s
// The restitution of the heavy body's first impact within this of the requested one.
#define RESTITUTION_TOL 0.01
// The stack's bounce (the slowest mode along the normals: the block on both interfaces in series) gets the
// requested damping ratio: within this (the pad's mass couples it to the pad's own mode; measured below 0.004).
#define BOUNCE_ZETA_TOL 0.02
// ζ for the default restitution 0.5 (eq. (15)).
#define DEFAULT_ZETA 0.2553
#define PI 3.14159265358979323846

static double speed(pdBodyState b) { return sqrt(b.v.x * b.v.x + b.v.y * b.v.y + b.v.z * b.v.z); }

#define BLOCK_MASS 8.0                   // kg: a 0.2 m cube of water
#define PAD_VOLUME (0.3 * 0.3 * 0.02)    // m³

// A block on a pad on a floor as a newcomer writes it: default materials, the pad's density set for the mass
// ratio; `pad` and `block` add lines to those objects (the block's default: set down on the pad at rest).
static pdModel* block_on_pad(double ratio, const char* settings, const char* pad, const char* block) {
  char text[1024];
  snprintf(text, sizeof text,
           "%s\n"
           "cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\n"
           "cube pad blue 0.3 0.3 0.02\nspgrav %.17g\nloc 0 0 0.01\n%s\n"
           "cube block red 0.2 0.2 0.2\n%s\n",
           settings, BLOCK_MASS / ratio / PAD_VOLUME / 1000.0, pad, block[0] ? block : "loc 0 0 0.12");
  return compile_text(text);
}

static void test_stacks_of_any_mass_ratio_settle(void** state) {
  (void)state;
  const double ratios[] = {1.0, 10.0, 100.0, 1000.0};
  for (int i = 0; i < 4; ++i) {
    pdModel* m = block_on_pad(ratios[i], "tend 1\nsample 100", "", "");
    pdState* s = NULL;
    record* r = run(m, &s);
    double fastest = 0.0, lastFast = 0.0;
    for (int k = 0; k < r->count; ++k)
      for (int b = 0; b < m->movingCount; ++b)
        if (speed(r->body[b][k]) > SETTLED_SPEED) lastFast = r->t[k];
    for (int b = 0; b < m->movingCount; ++b) fastest = fmax(fastest, speed(r->body[b][r->count - 1]));
    print_message("mass ratio %6g: faster than %g m/s until %.3f s, %.2e m/s at %.1f s, overlap %.3f delta_max\n",
                  ratios[i], SETTLED_SPEED, lastFast, fastest, r->t[r->count - 1], deepest_overlap(m, s, NULL, NULL));
    assert_true(r->t[r->count - 1] >= SETTLE_TIME);
    assert_true(fastest < SETTLED_SPEED);
    free(r);
    pd_state_free(s);
    pd_model_free(m);
  }
}

// The factor on the springs of the contacts between bodies a and b (all alike, asserted) for the load they carry.
static double spring_scale(const pdModel* m, const pdState* s, const char* a, const char* b) {
  int ia = body_index(m, a), ib = body_index(m, b), found = 0;
  double scale = 0.0;
  for (int i = 0; i < pd_state_contact_count(s); ++i) {
    pdContactReport c = pd_state_contact(s, i);
    if (!((c.bodyA == ia && c.bodyB == ib) || (c.bodyA == ib && c.bodyB == ia))) continue;
    assert_true(found == 0 || c.springScale == scale);
    scale = c.springScale;
    ++found;
  }
  assert_true(found > 0);
  return scale;
}

// The stack's modes at rest (pd_state_stack_modes): the slowest vertical one, the block bouncing on both
// interfaces, has the requested damping ratio at every mass ratio.
static void test_stack_bounce_has_the_requested_damping_ratio(void** state) {
  (void)state;
  const double ratios[] = {10.0, 100.0, 1000.0};
  for (int i = 0; i < 3; ++i) {
    pdModel* m = block_on_pad(ratios[i], "tend 0.2\nsample 10", "", "");
    pdState* s = pd_state_create(m, NULL);
    assert_true(pd_advance(m, s, 0.2, NULL, NULL));
    int* stackOf = malloc((size_t)m->bodyCount * sizeof *stackOf);
    assert_non_null(stackOf);
    assert_int_equal(pd_state_stacks(m, s, stackOf), 1);
    pdStackMode modes[24];
    int count = pd_state_stack_modes(m, s, stackOf, 0, modes, 24);
    assert_true(count > 0 && count <= 24);
    // the bounce: the oscillating mode whose frequency is that of the block on both interfaces in series
    // (four corners on each interface), their springs as sized for the load they carry
    pdContactParams pf = pd_model_contact_params(m, body_index(m, "pad"), body_index(m, "floor"));
    pdContactParams bp = pd_model_contact_params(m, body_index(m, "block"), body_index(m, "pad"));
    double k = pd_series(4.0 * pd_series(pf.k1n, pf.k2n) * spring_scale(m, s, "pad", "floor"),
                         4.0 * pd_series(bp.k1n, bp.k2n) * spring_scale(m, s, "block", "pad"));
    double bounce = sqrt(k / m->bodies[body_index(m, "block")].mass), best = INFINITY;
    int j = -1;
    for (int q = 0; q < count; ++q)
      if (!modes[q].real && fabs(modes[q].omega - bounce) < best) best = fabs(modes[q].omega - bounce), j = q;
    assert_true(j >= 0);
    print_message("mass ratio %6g: bounce %.2f Hz (series springs: %.2f Hz), damping ratio %.4f\n", ratios[i],
                  modes[j].omega / (2.0 * PI), bounce / (2.0 * PI), modes[j].zeta);
    assert_true(fabs(modes[j].omega - bounce) < 0.05 * bounce);
    assert_true(fabs(modes[j].zeta - DEFAULT_ZETA) < BOUNCE_ZETA_TOL);
    free(stackOf);
    pd_state_free(s);
    pd_model_free(m);
  }
}

// A heavy block dropped on a light pad that a force holds on the floor, gravity off (so that the impact alone sets
// the speeds): its first impact rebounds with the requested restitution. The speed keeps the springs within
// about 2 δ_max (they are sized for the pad's mass: eq. (11) for the pair).
static void test_heavy_body_on_light_pad_keeps_its_restitution(void** state) {
  (void)state;
  const double ratios[] = {100.0, 1000.0};
  for (int i = 0; i < 2; ++i) {
    double v = sqrt(10.0 / ratios[i]);  // m/s
    char motion[128];
    snprintf(motion, sizeof motion, "loc 0 0 0.17\nvel 0 0 %.17g", -v);
    char pad[64];
    snprintf(pad, sizeof pad, "force 0 0 %.17g", -9.81 * BLOCK_MASS / ratios[i]);
    pdModel* pressed = block_on_pad(ratios[i], "tend 0.8\nsample 20000\nvmax 1\ngravity 0 0 0", pad, motion);
    pdState* s = NULL;
    record* r = run(pressed, &s);
    int block = 1;  // moving-body order: pad, block
    double out = -INFINITY;
    for (int k = 0; k < r->count; ++k) {
      double vz = r->body[block][k].v.z;
      if (vz > 0.0) out = fmax(out, vz);
      if (out > 0.0 && vz < 0.0) break;
    }
    double e = out / v;
    print_message("mass ratio %6g: drop at %.4f m/s, rebound %.5f m/s: e %.4f (requested 0.5)\n", ratios[i], v, out,
                  e);
    assert_true(fabs(e - 0.5) <= RESTITUTION_TOL);
    free(r);
    pd_state_free(s);
    pd_model_free(pressed);
  }
}

// The first listed contact of the pair of bodies a < b in a list sorted by pair, and its end; -1 when none.
static int pair_range(const pdContactSet* set, int a, int b, int* last) {
  int first = -1;
  for (int i = 0; i < set->count; ++i) {
    const pdContactId* id = &set->items[i].id;
    bool same = (id->body1 == a && id->body2 == b) || (id->body1 == b && id->body2 == a);
    if (same && first < 0) first = i;
    if (same) *last = i + 1;
  }
  return first;
}

// A board resting on the floor carrying three cubes, run 0.05 s with islands off (one list holds every contact),
// its contacts' bodies listed; *poses the bodies' poses at the end (the caller frees them, the state and *m).
static pdState* board_with_three_cubes(pdModel** m, pdPose** poses) {
  *m = compile_text(
      "tend 0.05\nsample 100\nsleep off\n"
      "cube floor grey 3 1 0.2\nfixed\nloc 0 0 -0.1\n"
      "cube board blue 0.6 0.6 0.03\nloc 0 0 0.015\n"
      "cube c0 red 0.1 0.1 0.1\nloc -0.12 0 0.08\n"
      "cube c1 red 0.1 0.1 0.1\nloc 0 0 0.08\n"
      "cube c2 red 0.1 0.1 0.1\nloc 0.12 0 0.08\n");
  pdStateOptions options = pd_state_options_default();
  options.islands = pd_islandsOff;
  pdState* s = pd_state_create(*m, &options);
  assert_true(pd_advance(*m, s, (*m)->settings.tend, NULL, NULL));
  pd_contact_set_list_bodies(*m, s->contacts);
  *poses = malloc((size_t)(*m)->bodyCount * sizeof **poses);
  assert_non_null(*poses);
  for (int k = 0; k < (*m)->bodyCount; ++k) {
    pdBodyState b = pd_state_body(*m, s, k);
    (*poses)[k] = pose_of(b.x, b.q);
  }
  return s;
}

// A decomposition read again (stack_modes.c, a matrix equal bit for bit to the last one decomposed) gives the slow
// frequency a fresh scratch computes, bit for bit. A board resting on the floor carries three cubes: the board–floor
// pair's local system and that of the board with its lowest cube list the same bodies in the same order, so the
// second reads the first's decomposition; the board with its second cube lists them in another order and decomposes
// its own.
static void test_stack_frequency_read_again_equals_recomputed(void** state) {
  (void)state;
  pdModel* m = NULL;
  pdPose* poses = NULL;
  pdState* s = board_with_three_cubes(&m, &poses);
  pdContactSet* set = s->contacts;
  int floorEnd = 0, firstEnd = 0, secondEnd = 0;
  int floorPair = pair_range(set, 0, 1, &floorEnd), firstCube = pair_range(set, 1, 2, &firstEnd),
      secondCube = pair_range(set, 1, 3, &secondEnd);
  assert_true(floorPair >= 0 && firstCube >= 0 && secondCube >= 0);

  pdStackScratch* shared = pd_stack_scratch_create();
  double floorOmega = 0.0, firstOmega = 0.0, secondOmega = 0.0;
  assert_true(pd_stack_pair_frequency(m, set, poses, floorPair, floorEnd, 0.0, shared, &floorOmega));
  assert_int_equal(pd_stack_scratch_reuses(shared), 0);
  assert_true(pd_stack_pair_frequency(m, set, poses, firstCube, firstEnd, 0.0, shared, &firstOmega));
  assert_int_equal(pd_stack_scratch_reuses(shared), 1);
  assert_true(pd_stack_pair_frequency(m, set, poses, secondCube, secondEnd, 0.0, shared, &secondOmega));
  assert_int_equal(pd_stack_scratch_reuses(shared), 1);

  const int firsts[2] = {firstCube, secondCube}, lasts[2] = {firstEnd, secondEnd};
  const double kept[2] = {firstOmega, secondOmega};
  for (int p = 0; p < 2; ++p) {
    pdStackScratch* fresh = pd_stack_scratch_create();
    double omega = 0.0;
    assert_true(pd_stack_pair_frequency(m, set, poses, firsts[p], lasts[p], 0.0, fresh, &omega));
    assert_int_equal(pd_stack_scratch_reuses(fresh), 0);
    print_message("pair %d: omega %.17g rad/s, recomputed %.17g\n", p, kept[p], omega);
    assert_memory_equal(&kept[p], &omega, sizeof omega);
    pd_stack_scratch_free(fresh);
  }
  pd_stack_scratch_free(shared);
  free(poses);
  pd_state_free(s);
  pd_model_free(m);
}

// The local analysis answers "fast enough" from the eigenvalues alone (stack_modes.c, fast_enough) only where the
// eigenvectors' answer is the same: for each pair of the board and three cubes, at marks around its Ω, a false
// answer means Ω >= the mark, a true one gives Ω bit for bit as without a mark; the cubes' pairs, whose slow mode is
// their own, far above the board's bounce, are answered from the values at half their Ω.
static void test_stack_frequency_fast_enough_only_when_it_is(void** state) {
  (void)state;
  pdModel* m = NULL;
  pdPose* poses = NULL;
  pdState* s = board_with_three_cubes(&m, &poses);
  pdContactSet* set = s->contacts;
  const int others[4] = {0, 2, 3, 4};
  const double marks[6] = {0.5, 0.9, 0.999, 1.001, 1.1, 2.0};
  for (int p = 0; p < 4; ++p) {
    int last = 0, first = pair_range(set, others[p], 1, &last);
    assert_true(first >= 0);
    pdStackScratch* scratch = pd_stack_scratch_create();
    double exact = 0.0;
    assert_true(pd_stack_pair_frequency(m, set, poses, first, last, 0.0, scratch, &exact));
    pd_stack_scratch_free(scratch);
    for (int k = 0; k < 6; ++k) {
      double fast = marks[k] * exact, omega = 0.0;
      scratch = pd_stack_scratch_create();  // fresh: its values from the values-only solver
      bool analysed = pd_stack_pair_frequency(m, set, poses, first, last, fast, scratch, &omega);
      pd_stack_scratch_free(scratch);
      print_message("pair %d: Omega %.6g rad/s, mark %.6g: %s\n", p, exact, fast, analysed ? "analysed" : "fast enough");
      if (analysed) assert_memory_equal(&omega, &exact, sizeof omega);
      else assert_true(exact >= fast);
      if (p > 0 && k == 0) assert_false(analysed);
    }
  }
  free(poses);
  pd_state_free(s);
  pd_model_free(m);
}

// fast_enough reads the values-only solver's eigenvalues as those of the solver with vectors (the free modes are
// the same): GSL computes both by the same tridiagonalisation and QR steps, and they agree bit for bit on a
// 72-row matrix of the local systems' kind (a sum of 40 rank-one springs k h hᵀ: 32 free modes).
static void test_values_only_solver_agrees_with_vectors(void** state) {
  (void)state;
  enum { N = 72, SPRINGS_COUNT = 40 };
  static double a[N * N], b[N * N], vectors[N * N], withVectors[N], valuesOnly[N];
  unsigned seed = 12345u;
  for (int c = 0; c < SPRINGS_COUNT; ++c) {
    double h[N] = {0};
    int body = c % 12;
    for (int r = 0; r < 6; ++r) {
      seed = seed * 1103515245u + 12345u;
      h[6 * body + r] = (double)(seed >> 8) / 16777216.0 - 0.5;
    }
    double k = 1e6 * (1.0 + (double)(c % 5));
    for (int r = 0; r < N; ++r)
      for (int q = 0; q < N; ++q) a[r * N + q] += k * h[r] * h[q];
  }
  memcpy(b, a, sizeof a);
  gsl_eigen_symmv_workspace* wv = gsl_eigen_symmv_alloc(N);
  gsl_eigen_symm_workspace* w = gsl_eigen_symm_alloc(N);
  gsl_matrix_view av = gsl_matrix_view_array(a, N, N), bv = gsl_matrix_view_array(b, N, N);
  gsl_matrix_view v = gsl_matrix_view_array(vectors, N, N);
  gsl_vector_view l1 = gsl_vector_view_array(withVectors, N), l2 = gsl_vector_view_array(valuesOnly, N);
  assert_int_equal(gsl_eigen_symmv(&av.matrix, &l1.vector, &v.matrix, wv), 0);
  assert_int_equal(gsl_eigen_symm(&bv.matrix, &l2.vector, w), 0);
  assert_memory_equal(withVectors, valuesOnly, sizeof withVectors);
  gsl_eigen_symm_free(w);
  gsl_eigen_symmv_free(wv);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_stacks_of_any_mass_ratio_settle),
      cmocka_unit_test(test_stack_bounce_has_the_requested_damping_ratio),
      cmocka_unit_test(test_heavy_body_on_light_pad_keeps_its_restitution),
      cmocka_unit_test(test_stack_frequency_read_again_equals_recomputed),
      cmocka_unit_test(test_stack_frequency_fast_enough_only_when_it_is),
      cmocka_unit_test(test_values_only_solver_agrees_with_vectors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
