// Search certificates (engine/src/contact_analysis.c, "search certificates"; contact_set.c skips a certified pair's
// interference test and contact search).
// - What a certificate proves: at any poses within its motion margin (pd_search_motion) of the ones it was issued at,
//   pd_contacts_find reports no contact outside the exempt list. Checked on random pairs of boxes, prisms and hulls
//   of mixed sizes in random poses near contact and on flush stacks (aligned, 45°, slightly tilted), each moved
//   many times by random motions up to its margin (and by the search's real start and end poses: the face a new
//   vertex takes depends on both).
// - That it is not empty where it is meant to work: a box resting turned 45° on another (the crossed edges of a
//   stack) is certified for millimetres of motion, far more than a resting stack moves in a step.
// - That skipping certified searches changes nothing: scenes that come to rest (a 45° stack, a tumbling box on a
//   floor, a small pile) give the same samples bit for bit with certificates on and off, islands on and off, and
//   the certificates do skip searches.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "contact_analysis.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "scene_run.h"

#define PI 3.14159265358979323846
enum { CAPACITY = 256, MOVES = 60 };

// A deterministic generator (xorshift64*): the same pairs on every run.
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void) {
  rng ^= rng >> 12, rng ^= rng << 25, rng ^= rng >> 27;
  return (double)((rng * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}
static pdVec3 unit_vector(void) {
  for (;;) {
    pdVec3 v = {2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0};
    double n = pd_v3_norm(v);
    if (n > 0.1 && n <= 1.0) return pd_v3_scale(v, 1.0 / n);
  }
}
static pdMat3 rotation(pdVec3 axis, double angle) { return pd_quat_to_mat3(pd_quat_from_axis_angle(axis, angle)); }

static bool listed(const pdContactId* ids, int count, const pdContactId* id) {
  for (int i = 0; i < count; ++i)
    if (pd_contact_id_compare(&ids[i], id) == 0) return true;
  return false;
}

typedef struct tally {
  int configurations, certified, moves;
} tally;

// Pair (0, 1) at poses a, b: the contacts found there are the exempt list (the pair's C0); if certified, every
// motion within the margin must find nothing else.
static void check_pair(const pdModel* m, pdPose a, pdPose b, tally* t) {
  pdContactGeom found[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, found, CAPACITY);
  assert_true(n <= CAPACITY);
  pdContactId exempt[CAPACITY];
  for (int i = 0; i < n; ++i) exempt[i] = found[i].id;
  ++t->configurations;
  pdSearchCertificate cert = pd_contacts_certify(m, 0, &a, 1, &b, exempt, n);
  assert_true(cert.margin >= 0.0);
  assert_true(pd_search_motion(&cert, &a, &b) == 0.0);
  if (cert.margin == 0.0) return;
  ++t->certified;
  for (int k = 0; k < MOVES; ++k) {
    // a random motion of either body or both: a turn and a shift, scaled to reach up to the whole margin
    double reach = uniform() < 0.5 ? 1.0 : uniform();
    pdPose a2 = a, b2 = b;
    for (int side = 0; side < 2; ++side) {
      if (side == 0 && uniform() < 0.5) continue;
      pdPose* p = side == 0 ? &a2 : &b2;
      double turn = reach * cert.margin / cert.reach * uniform();
      pdMat3 r = rotation(unit_vector(), turn);
      p->R = pd_mat3_mul(&r, &p->R);
      p->x = pd_v3_add(p->x, pd_v3_scale(unit_vector(), reach * cert.margin * uniform()));
    }
    if (!(pd_search_motion(&cert, &a2, &b2) < cert.margin)) continue;
    ++t->moves;
    pdContactGeom again[CAPACITY];
    int n2 = pd_contacts_find(m, 0, &a2, 1, &b2, &a, &b, exempt, n, again, CAPACITY);
    assert_true(n2 <= CAPACITY);
    for (int i = 0; i < n2; ++i)
      if (!listed(exempt, n, &again[i].id))
        fail_msg("configuration %d, move %d (motion %.3g of margin %.3g): new contact %s %d/%d feat %d/%d depth %.3g",
                 t->configurations, k, pd_search_motion(&cert, &a2, &b2), cert.margin,
                 again[i].id.kind == pd_contactVF ? "VF" : "EE", again[i].id.body1, again[i].id.body2,
                 again[i].id.feat1, again[i].id.feat2, again[i].depth);
  }
}

// B dropped onto A along -d from afar until the search first finds a contact (bisection on the distance), then
// pressed in by `press` (m): a pose near first contact, as a step's end meets it.
static pdPose near_contact(const pdModel* m, pdPose a, pdMat3 rb, pdVec3 d, double press) {
  double lo = 0.0, hi = 2.0 * (m->bodies[0].size + m->bodies[1].size) + 1.0;
  pdContactGeom c[CAPACITY];
  for (int i = 0; i < 60; ++i) {
    double mid = 0.5 * (lo + hi);
    pdPose b = {pd_v3_add(a.x, pd_v3_scale(d, mid)), rb};
    if (pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, c, CAPACITY) > 0)
      lo = mid;
    else
      hi = mid;
  }
  return (pdPose){pd_v3_add(a.x, pd_v3_scale(d, hi - press)), rb};
}

static const char* const shapes[] = {
    "cube a red 0.2 0.15 0.1\ncube b blue 0.2 0.15 0.1\n",
    "cube a red 1 1 0.2\ncube b blue 0.1 0.1 0.1\n",
    "cube a red 0.05 0.3 0.02\ncube b blue 0.12 0.1 0.08\n",
    "prism a red 5 0.1 0.1 0.15\ncube b blue 0.1 0.1 0.1\n",
    ("hull a red 0 0 0  0.1 0 0  0 0.12 0  0 0 0.09  0.08 0.07 0.06  -0.02 0.05 0.04\n"
     "hull b blue 0 0 0  0.05 0.01 0  0.01 0.06 0.01  0.02 0.01 0.07  0.04 0.04 0.04\n"),
    "prism a red 6 0.08 0.08 0.05\nprism b blue 3 0.1 0.1 0.2\n",
};

static void test_no_new_contact_within_a_certificates_margin(void** state) {
  (void)state;
  tally t = {0, 0, 0};
  for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; ++s) {
    pdModel* m = compile_apart(shapes[s]);
    double deltaMax = pd_model_pair_delta_max(m, 0, 1);
    for (int c = 0; c < 150; ++c) {
      pdPose a = {{0, 0, 0}, rotation(unit_vector(), 2.0 * PI * uniform())};
      pdMat3 rb = rotation(unit_vector(), 2.0 * PI * uniform());
      // pressed in from nothing to 10 δ_max: new, shallow and deep contacts (edge pairs beyond 3 δ_max are
      // contacts only as deep as the bodies' penetration)
      double press = (c % 2 ? 3.0 : 10.0) * deltaMax * uniform() * uniform();
      check_pair(m, a, near_contact(m, a, rb, unit_vector(), press), &t);
    }
    pd_model_free(m);
  }
  // flush stacks: a box set on another aligned or turned 45°, tilted by 0 to 1e-3 rad, pressed 0 to 1.5 δ_max
  pdModel* m = compile_apart(shapes[0]);
  double deltaMax = pd_model_pair_delta_max(m, 0, 1);
  for (int c = 0; c < 200; ++c) {
    pdPose a = {{0, 0, 0}, pd_mat3_identity()};
    double turn = (c % 3 == 0 ? 0.25 * PI : c % 3 == 1 ? 0.0 : 2.0 * PI * uniform());
    pdMat3 upright = rotation(pd_v3(0, 0, 1), turn);
    pdMat3 tilt = rotation(unit_vector(), c % 4 == 0 ? 0.0 : 1e-3 * uniform() * uniform());
    pdMat3 rb = pd_mat3_mul(&tilt, &upright);
    pdVec3 shift = {0.02 * (uniform() - 0.5), 0.02 * (uniform() - 0.5), 0.1 - 1.5 * deltaMax * uniform()};
    check_pair(m, a, (pdPose){shift, rb}, &t);
  }
  pd_model_free(m);
  print_message("%d configurations, %d certified, %d motions checked\n", t.configurations, t.certified, t.moves);
  // the check is not empty: most configurations near contact are certified, and each is moved many times
  assert_true(t.certified >= t.configurations / 3);
  assert_true(t.moves >= 20 * t.certified);
}

// A box resting turned 45° on an equal box (cases/hard/stack_10.scene's interfaces): eight crossing edge pairs,
// certified for motions of millimetres (the nearest non-contact features are ~4 cm away), against the ~1e-6 m a
// resting stack moves in a step.
static void test_a_resting_45_degree_stack_is_certified_for_millimetres(void** state) {
  (void)state;
  pdModel* m = compile_apart(shapes[0]);
  pdPose a = {{0, 0, 0}, pd_mat3_identity()};
  pdPose b = {{0, 0, 0.1 - 1e-4}, rotation(pd_v3(0, 0, 1), 0.25 * PI)};
  pdContactGeom found[CAPACITY];
  int n = pd_contacts_find(m, 0, &a, 1, &b, NULL, NULL, NULL, 0, found, CAPACITY);
  assert_int_equal(n, 8);
  pdContactId exempt[CAPACITY];
  for (int i = 0; i < n; ++i) exempt[i] = found[i].id;
  pdSearchCertificate cert = pd_contacts_certify(m, 0, &a, 1, &b, exempt, n);
  assert_true(cert.margin > 1e-3);
  // without its contacts exempt there is none: they are contacts the search finds
  assert_true(pd_contacts_certify(m, 0, &a, 1, &b, exempt, n - 1).margin == 0.0);
  pd_model_free(m);
}

typedef struct samples {
  int count;
  pdBodyState b[2000][4];
} samples;

static bool keep(const pdModel* model, const pdState* state, void* user) {
  samples* s = user;
  if (s->count == 2000) return false;
  for (int k = 0; k < model->movingCount && k < 4; ++k)
    s->b[s->count][k] = pd_state_body(model, state, model->movingBodies[k]);
  ++s->count;
  return true;
}

static samples* run_certified(const pdModel* m, bool certificates, pdIslands islands, long* skipped) {
  pdStateOptions options = pd_state_options_default();
  options.islands = islands;
  options.searchCertificates = certificates;
  pdState* s = pd_state_create(m, &options);
  samples* out = calloc(1, sizeof *out);
  assert_non_null(out);
  assert_true(pd_advance(m, s, m->settings.tend, keep, out));
  *skipped = s->count.searchesSkipped;
  pd_state_free(s);
  return out;
}

static const char* const restingScenes[] = {
    // three boxes stacked, each turned 45° on the one below
    "tend 0.3\nsample 200\ntol 1e-7\n"
    "cube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\nrestitution 0.5\n"
    "cube b0 tan 0.2 0.2 0.1\nloc 0 0 0.05\nrestitution 0.5\n"
    "cube b1 tan 0.2 0.2 0.1\nloc 0 0 0.15  45 0 0 1\nrestitution 0.5\n"
    "cube b2 tan 0.2 0.2 0.1\nloc 0 0 0.25\nrestitution 0.5\n",
    // a box tumbling onto a floor and coming to rest
    "tend 0.8\nsample 100\n"
    "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\n"
    "cube box red 0.2 0.15 0.1\nloc 0 0 0.12  30 1 1 0\nvel 0.4 0 0  5 0 1 0\nmu 0.5\nrestitution 0.5\n",
    // four mixed bodies dropped on a floor next to each other
    "tend 0.8\nsample 100\n"
    "cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nmu 0.5\nrestitution 0.3\n"
    "cube p0 tan 0.2 0.15 0.1\nloc -0.15 0 0.1  20 0.3 0.2 1\nmu 0.5\nrestitution 0.3\n"
    "cube p1 tan 0.12 0.12 0.12\nloc 0.1 0.05 0.12  40 1 0.1 0.2\nmu 0.5\nrestitution 0.3\n"
    "prism p2 tan 6 0.06 0.06 0.1\nloc 0 0.25 0.12\nmu 0.5\nrestitution 0.3\n"
    "cube p3 tan 0.1 0.1 0.05\nloc -0.12 0.02 0.3  10 0 1 0\nmu 0.5\nrestitution 0.3\n",
};

static void test_skipping_certified_searches_changes_no_bit(void** state) {
  (void)state;
  for (size_t k = 0; k < sizeof restingScenes / sizeof restingScenes[0]; ++k) {
    pdModel* m = compile_text(restingScenes[k]);
    for (int islands = 0; islands < 2; ++islands) {
      pdIslands mode = islands ? pd_islandsOn : pd_islandsOff;
      long skippedOn = 0, skippedOff = 0;
      samples* on = run_certified(m, true, mode, &skippedOn);
      samples* off = run_certified(m, false, mode, &skippedOff);
      assert_int_equal(on->count, off->count);
      assert_true(on->count > 10);
      assert_memory_equal(on->b, off->b, (size_t)on->count * sizeof on->b[0]);
      assert_int_equal(skippedOff, 0);
      print_message("scene %zu, islands %s: %ld searches skipped\n", k, islands ? "on" : "off", skippedOn);
      assert_true(skippedOn > 0);
      free(on);
      free(off);
    }
    pd_model_free(m);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_no_new_contact_within_a_certificates_margin),
      cmocka_unit_test(test_a_resting_45_degree_stack_is_certified_for_millimetres),
      cmocka_unit_test(test_skipping_certified_searches_changes_no_bit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
