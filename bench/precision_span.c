// pd_bench_span — the span `polydyn gedanken --precision` times for a soft point, repeated: the scene compiled with
// the point's tol (outside the span), then pd_state_create and pd_advance with the sample record as the observer
// (gedanken/precision.c's measure_point; the implicit stepper, the report's `soft implicit`). The record is kept on
// the first repeat only, as there; --no-record leaves it out of every repeat (the runs the report's least timing falls
// on). The span is the function measured_span, so an instruction count can be taken over exactly it:
//   valgrind --tool=callgrind --toggle-collect=measured_span pd_bench_span SCENE --tol T --repeats 1 --no-record
// A Gedanken experiment's scene: `polydyn gedanken --only NAME --engines soft --out DIR` writes it to
// DIR/runs/NAME/soft-implicit*/scene.scene. CSV on stdout: steps, derivatives, each repeat's thread CPU seconds.
//
// usage: pd_bench_span SCENE --tol T [--repeats R] [--no-record]
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "pdgk/gedanken.h"
#include "pdutil/clock.h"
#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

enum { MAX_REPEATS = 1000 };

static const char* const usage =
    "usage: pd_bench_span SCENE --tol T [--repeats R] [--no-record]\n"
    "\n"
    "Repeats the span polydyn gedanken --precision times for a soft point (the implicit stepper): the state made\n"
    "and advanced to the scene's tend with the sample record as observer (kept on the first repeat only, or on\n"
    "none with --no-record). Prints CSV: repeat, steps, derivatives, cpu_seconds. Defaults: --repeats 5\n";

static bool record_sample(const pdModel* model, const pdState* state, void* user) {
  if (user) pd_gk_record_observe(model, state, user);
  return true;
}

// Not inlined, and external: the span an instruction count toggles on by name (the header's command).
pdState* measured_span(const pdModel* model, pdGkRecord* rec);
__attribute__((noinline)) pdState* measured_span(const pdModel* model, pdGkRecord* rec) {
  pdStateOptions options = pd_state_options_default();
  options.stepper = pd_stepperImplicit;
  options.stageTimers = false;  // as gedanken/precision.c times a point
  pdState* state = pd_state_create(model, &options);
  pd_advance(model, state, model->settings.tend, record_sample, rec);
  return state;
}

int main(int argc, char** argv) {
  const char* path = NULL;
  double tol = 0.0;
  long repeats = 5;
  bool record = true;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) {
      char* end = NULL;
      tol = strtod(argv[++i], &end);
      if (*end != '\0' || !(tol > 0.0)) tol = -1.0;
    } else if (strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      if (!bench_parse_long(argv[++i], 1, MAX_REPEATS, &repeats)) repeats = 0;
    } else if (strcmp(argv[i], "--no-record") == 0) {
      record = false;
    } else if (argv[i][0] != '-' && !path) {
      path = argv[i];
    } else {
      path = NULL;
      break;
    }
  }
  if (!path || !(tol > 0.0) || repeats < 1) {
    fputs(usage, stderr);
    return 2;
  }
  pdError err = {0};
  pdScene* scene = pd_scene_parse_file(path, &err);
  if (!scene) {
    pd_error_print(&err, stderr);
    return 2;
  }
  scene->settings.tol = tol;
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) {
    pd_error_print(&err, stderr);
    return 2;
  }
  printf("repeat,steps,derivatives,cpu_seconds\n");
  double cpu[MAX_REPEATS];
  for (int r = 0; r < repeats; ++r) {
    pdGkRecord rec;
    pd_gk_record_init(&rec, model->movingCount);
    double c0 = pd_thread_cpu_seconds();
    pdState* state = measured_span(model, record && r == 0 ? &rec : NULL);
    cpu[r] = pd_thread_cpu_seconds() - c0;
    printf("%d,%ld,%ld,%.9f\n", r, state->count.accepted, state->count.derivatives, cpu[r]);
    pd_state_free(state);
    pd_gk_record_free(&rec);
  }
  printf("median,,,%.9f\n", bench_median(cpu, (int)repeats));
  pd_model_free(model);
  return 0;
}
