// polydyn CLI — loading a scene into a model, with command-line overrides.
#include <stdio.h>

#include "cli.h"

pdModel* pd_cli_load_model(const char* path, const pdCliOverrides* overrides, pdSceneSettings* settings) {
  pdError err = {0};
  pdScene* scene = pd_scene_parse_file(path, &err);
  if (!scene) {
    pd_error_print(&err, stderr);
    return NULL;
  }
  if (overrides && overrides->tend > 0.0) scene->settings.tend = overrides->tend;
  if (overrides && overrides->sample > 0.0) scene->settings.sample = overrides->sample;
  if (overrides && overrides->tol > 0.0) scene->settings.tol = overrides->tol;
  if (overrides && overrides->tolScale > 0.0) scene->settings.tol *= overrides->tolScale;
  // dtmin is left alone: it sizes the §3.3 material adjustments, and a sweep must compare one model
  if (overrides && overrides->dt > 0.0) scene->settings.dt = overrides->dt;
  if (overrides && overrides->sleep != 0) scene->settings.sleep = overrides->sleep > 0;
  if (scene->settings.tend * scene->settings.sample > 1e8) {
    pd_error_set(&err, path, 0, 0, "too many output samples (tend × sample > 1e8)");
    pd_error_print(&err, stderr);
    pd_scene_free(scene);
    return NULL;
  }
  if (settings) *settings = scene->settings;
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);
  if (!model) pd_error_print(&err, stderr);
  return model;
}
