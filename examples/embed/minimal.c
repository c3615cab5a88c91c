#include <polydyn/scene.h>
#include <polydyn/state.h>
static bool print_sample(const pdModel* model, const pdState* state, void* out) {  // at every output sample
  for (int j = 0; j < pd_state_contact_count(state); j++) {
    pdContactReport c = pd_state_contact(state, j);  // force of body B on A, normal from B into A
    fprintf(out, "%.2f %s on %s: %.3f N\n", state->t, model->bodies[c.bodyB].name, model->bodies[c.bodyA].name, c.fn);
  }
  return true;  // false stops pd_advance
}
int main(int argc, char** argv) {
  pdError err;
  pdScene* scene = pd_scene_parse_file(argc > 1 ? argv[1] : "cases/user/floor_slide.scene", &err);
  pdModel* model = scene ? pd_model_compile(scene, &err) : NULL;  // read-only: bodies, mass, materials
  pd_scene_free(scene);
  if (!model) return pd_error_print(&err, stderr), 2;  // FILE:LINE:COL: why
  pdState* state = pd_state_create(model, NULL);       // default options; all a step needs is allocated here
  bool ok = pd_advance(model, state, model->settings.tend, print_sample, stdout);
  pd_state_free(state), pd_model_free(model);
  return ok ? 0 : 1;
}
