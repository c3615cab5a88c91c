// The catalogue as a whole: at least 20 experiments covering every group A–G, unique names, every field
// an experiment needs (formula with its source, tolerance reason, series label), and for every input a
// generated scene that parses and compiles and an expected value that is finite with a positive tolerance
// (or NAN for a qualitative check, and only then).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pdgk/gedanken.h"
#include "polydyn/scene.h"

#define MIN_EXPERIMENTS 20  // the catalogue's promise: at least 20 experiments

static void test_catalogue_covers_every_group(void** state) {
  (void)state;
  int count = pd_gk_experiment_count(), perGroup[7] = {0}, fast = 0;
  assert_true(count >= MIN_EXPERIMENTS);
  for (int i = 0; i < count; ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    assert_true(e->group >= 'A' && e->group <= 'G');
    ++perGroup[e->group - 'A'];
    fast += e->fast;
    assert_ptr_equal(pd_gk_find(e->name), e);
    for (int j = 0; j < i; ++j) assert_string_not_equal(pd_gk_experiment(j)->name, e->name);
  }
  for (int g = 0; g < 7; ++g) assert_true(perGroup[g] >= 1);
  assert_true(fast >= 1 && fast < count);
  assert_null(pd_gk_find("no_such_experiment"));
}

static void test_every_experiment_is_complete(void** state) {
  (void)state;
  for (int i = 0; i < pd_gk_experiment_count(); ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    print_message("%s\n", e->name);
    assert_true(e->title && e->title[0] && e->quantity && e->quantity[0] && e->unit);
    assert_true(e->formula && strlen(e->formula) > 10);
    assert_true(e->toleranceReason && strlen(e->toleranceReason) > 10);
    assert_true(e->seriesLabel && e->seriesLabel[0]);
    assert_true(e->scene && e->expect && e->measure && e->series);
    assert_true(e->inputCount >= 1 && e->inputCount <= PD_GK_MAX_INPUTS);
    assert_true(e->inputName != NULL || e->inputCount == 1);
    // names are file and directory names (series/NAME.csv, runs/NAME/) and CSV fields
    assert_true(strspn(e->name, "abcdefghijklmnopqrstuvwxyz0123456789_") == strlen(e->name));
    assert_true(e->name[0] == e->group - 'A' + 'a');
    // A law is judged on every variant; a model prediction on the soft engine at least (its
    // own model) and not on every variant, with the reason for the others
    assert_true(e->kind == pd_gkLaw || e->kind == pd_gkModelPrediction);
    if (e->kind == pd_gkLaw) {
      assert_int_equal(e->appliesTo, 0);
      assert_null(e->notApplicableReason);
    } else {
      assert_true((e->appliesTo & PD_GK_SOFT) && (e->appliesTo & ~(unsigned)PD_GK_ALL_VARIANTS) == 0);
      assert_true(e->appliesTo != PD_GK_ALL_VARIANTS);
      assert_true(e->notApplicableReason && strlen(e->notApplicableReason) > 10);
    }
  }
}

// The variants judged: every one for a law; for a model prediction exactly those of appliesTo.
static void test_applicability_follows_the_kind(void** state) {
  (void)state;
  int predictions = 0;
  for (int i = 0; i < pd_gk_experiment_count(); ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    predictions += e->kind == pd_gkModelPrediction;
    int judged = 0;
    for (int engine = 0; engine < pd_gkEngineCount; ++engine)
      for (int matched = 0; matched < 2; ++matched) {
        bool applies = pd_gk_applies(e, (pdGkEngine)engine, matched);
        if (e->kind == pd_gkLaw) assert_true(applies);
        else assert_int_equal(applies, (e->appliesTo & pd_gk_variant_bit((pdGkEngine)engine, matched)) != 0);
        judged += applies && !(engine == pd_gkSoft && matched);
      }
    if (e->kind == pd_gkLaw) assert_int_equal(judged, 5);
  }
  // the examples of docs/validation.md: sinkage is the soft model's, a stop distance and momentum are laws
  assert_int_equal(pd_gk_find("a3_sinkage")->kind, pd_gkModelPrediction);
  assert_false(pd_gk_applies(pd_gk_find("a3_sinkage"), pd_gkOde, false));
  assert_true(pd_gk_applies(pd_gk_find("a3_sinkage"), pd_gkOde, true));
  assert_int_equal(pd_gk_find("b2_stopping_distance")->kind, pd_gkLaw);
  assert_int_equal(pd_gk_find("c2_momentum")->kind, pd_gkLaw);
  assert_true(predictions >= 1 && predictions < pd_gk_experiment_count());
  assert_string_equal(pdGkStatusNames[pd_gkNotApplicable], "NOT_APPLICABLE");
  assert_string_equal(pdGkKindNames[pd_gkModelPrediction], "model_prediction");
}

static void test_every_scene_compiles_with_a_finite_expectation(void** state) {
  (void)state;
  for (int i = 0; i < pd_gk_experiment_count(); ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    int qualitative = 0;
    for (int k = 0; k < e->inputCount; ++k) {
      pdGkText text = {0};
      e->scene(e->inputs[k], &text);
      pdError err = {0};
      pdScene* scene = pd_scene_parse_buffer("scene.scene", text.data, text.length, &err);
      if (!scene) fail_msg("%s input %g: %d:%d: %s", e->name, e->inputs[k], err.line, err.col, err.message);
      pdModel* model = pd_model_compile(scene, &err);
      if (!model) fail_msg("%s input %g: %d:%d: %s", e->name, e->inputs[k], err.line, err.col, err.message);
      // a generated scene never needs an adjustment of §3.3: its expected value uses the constants as given
      assert_int_equal(pd_model_adjustment_count(model), 0);
      pdGkExpected x = e->expect(model, e->inputs[k]);
      if (isnan(x.value)) {
        ++qualitative;
      } else {
        assert_true(isfinite(x.value) && x.tolerance > 0.0);
        assert_true(!e->relative || x.value != 0.0);
      }
      char label[64];
      pd_gk_input_label(e, e->inputs[k], label, sizeof label);
      assert_true(e->inputName ? strchr(label, '=') != NULL : label[0] == '\0');
      pd_model_free(model);
      pd_scene_free(scene);
      pd_gk_text_free(&text);
    }
    // "qualitative" in experiments.json means every input is a qualitative check
    assert_true(e->qualitative == (qualitative == e->inputCount));
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_catalogue_covers_every_group),
      cmocka_unit_test(test_every_experiment_is_complete),
      cmocka_unit_test(test_applicability_follows_the_kind),
      cmocka_unit_test(test_every_scene_compiles_with_a_finite_expectation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
