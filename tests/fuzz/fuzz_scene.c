// libFuzzer target for the scene parser: any bytes must give either a scene that keeps the
// language's invariants or one well-formed error, with no crash, leak or undefined behaviour.
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_checks.h"
#include "polydyn/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static void check_scene(const pdScene* sc) {
  const pdSceneSettings* s = &sc->settings;
  if (!(s->tend > 0 && s->tol > 0 && s->tol < 1 && s->dtmin <= s->dt && s->dt <= s->dtmax)) __builtin_trap();
  if (!(s->sample > 0 && s->tend * s->sample <= 1e8 && s->deflection > 0 && s->deflection < 1)) __builtin_trap();
  for (int i = 0; i < sc->objectCount; ++i) {
    const pdSceneObject* o = &sc->objects[i];
    if (!o->name || !o->color || o->where.line < 1 || o->where.col < 1) __builtin_trap();
    for (int j = 0; j < i; ++j) {
      if (strcmp(sc->objects[j].name, o->name) == 0) __builtin_trap();
    }
    for (int k = 0; k < 3; ++k) {
      if (!(o->scale[k] > 0 && o->scale[k] <= 1e6) || !isfinite(o->loc[k]) || !isfinite(o->vel[k])) __builtin_trap();
    }
    if (o->kind == pd_primHull) {
      if (o->pointCount < 4 || o->pointCount > PD_HULL_MAX_POINTS || !o->points) __builtin_trap();
      for (int k = 0; k < 3 * o->pointCount; ++k) {
        if (!isfinite(o->points[k])) __builtin_trap();
      }
    } else if (o->points || o->pointCount != 0) {
      __builtin_trap();
    }
    if (!(o->taper > 0 && o->taper <= 1 && o->spgrav > 0 && o->mu >= 0 && o->mu <= 10)) __builtin_trap();
    if (!(o->restitution >= 0 && o->restitution <= 1 && o->cn >= 0 && o->ct >= 0)) __builtin_trap();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pdError err;
  pdScene* sc = pd_scene_parse_buffer("fuzz.scene", (const char*)data, size, &err);
  if (sc) {
    check_scene(sc);
  } else {
    fuzz_check_error(&err, 0);
  }
  pd_scene_free(sc);
  return 0;
}
