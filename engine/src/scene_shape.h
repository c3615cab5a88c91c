// polydyn (internal) — the polyhedron of one scene object (a primitive or a hull, in its own frame), as
// pd_model_compile builds it for each body (model.c); the interference oracle builds its shapes with it too.
#pragma once

#include <stdbool.h>

#include "polydyn/error.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"

// Builds o's polyhedron into *shape; false with why filled when the object cannot be built.
bool pd_scene_object_shape(const pdSceneObject* o, pdPolyhedron* shape, pdError* why);
