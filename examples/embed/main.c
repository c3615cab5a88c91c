// polydyn embedded in a program: load a scene, compile it, step it, read poses and contact forces.
//
//   embed [SCENE] [SECONDS]
//
// SCENE is a scene file (README "Scene files"); without it, the built-in scene below (a tilted 0.1 m cube
// dropped onto a fixed floor). SECONDS is how long to run (default: the scene's tend). Uses the public API
// of <polydyn/...> only. Prints, at every output sample of the scene (its `sample` rate):
//   pose    T BODY x y z qw qx qy qz vx vy vz   each moving body: centre of mass (m), orientation, velocity (m/s)
//   contact T A B KIND px py pz nx ny nz fn ftx fty ftz MODE
//                                               each active contact: point (m), normal from B into A,
//                                               force B applies to A: fn (N, >= 0) along n, ft (N) tangential
//   load    T BODY Fx Fy Fz                     each moving body: the sum of its contact forces (N, world)
// Exit status 0, or 2 with `FILE:LINE:COL: message` on a bad scene or argument.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <polydyn/model.h>
#include <polydyn/scene.h>
#include <polydyn/state.h>

static const char builtInScene[] =
    "# a 0.1 m cube (1000 kg/m3: 1 kg), tilted 10 degrees, dropped from 0.2 m onto a fixed floor\n"
    "tend 3\n"
    "sample 10\n"
    "cube floor grey 2 2 0.2\n"
    "fixed\n"
    "loc 0 0 -0.1\n"
    "cube block red 0.1 0.1 0.1\n"
    "loc 0 0 0.2 10 1 0 0\n"
    "restitution 0.5\n";

// The contact force on `body` from one contact: the report gives the force B applies to A.
static pdVec3 force_on(const pdContactReport* c, int body) {
  pdVec3 onA = pd_v3_add(pd_v3_scale(c->normal, c->fn), c->ft);
  if (c->bodyA == body) return onA;
  if (c->bodyB == body) return pd_v3_scale(onA, -1.0);
  return pd_v3(0, 0, 0);
}

// Observer: called by pd_advance at every output sample. Reads the state only; returns true to go on.
static bool print_sample(const pdModel* model, const pdState* state, void* user) {
  FILE* out = user;
  double t = state->t;
  int contactCount = pd_state_contact_count(state);
  for (int k = 0; k < model->movingCount; k++) {
    int i = model->movingBodies[k];
    pdBodyState b = pd_state_body(model, state, i);
    fprintf(out, "pose %.3f %s %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", t, model->bodies[i].name,
            b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z);
  }
  for (int j = 0; j < contactCount; j++) {
    pdContactReport c = pd_state_contact(state, j);
    fprintf(out, "contact %.3f %s %s %s %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %s\n", t,
            model->bodies[c.bodyA].name, model->bodies[c.bodyB].name, c.edgeEdge ? "EE" : "VF", c.point.x,
            c.point.y, c.point.z, c.normal.x, c.normal.y, c.normal.z, c.fn, c.ft.x, c.ft.y, c.ft.z,
            c.slip ? "slip" : "stick");
  }
  for (int k = 0; k < model->movingCount; k++) {
    int i = model->movingBodies[k];
    pdVec3 total = pd_v3(0, 0, 0);
    for (int j = 0; j < contactCount; j++) {
      pdContactReport c = pd_state_contact(state, j);
      total = pd_v3_add(total, force_on(&c, i));
    }
    fprintf(out, "load %.3f %s %.9f %.9f %.9f\n", t, model->bodies[i].name, total.x, total.y, total.z);
  }
  return true;
}

int main(int argc, char** argv) {
  if (argc > 3) {
    fprintf(stderr, "usage: %s [SCENE] [SECONDS]\n", argv[0]);
    return 2;
  }
  double seconds = -1;
  if (argc == 3) {
    char* end;
    seconds = strtod(argv[2], &end);
    if (end == argv[2] || *end != '\0' || !(seconds > 0)) {
      fprintf(stderr, "%s: SECONDS must be a number > 0, not '%s'\n", argv[0], argv[2]);
      return 2;
    }
  }
  pdError err;
  pdScene* scene = argc >= 2 ? pd_scene_parse_file(argv[1], &err)
                             : pd_scene_parse_buffer("built-in", builtInScene, strlen(builtInScene), &err);
  if (scene == NULL) {
    pd_error_print(&err, stderr);
    return 2;
  }
  pdModel* model = pd_model_compile(scene, &err);
  pd_scene_free(scene);  // the model keeps what it needs
  if (model == NULL) {
    pd_error_print(&err, stderr);
    return 2;
  }
  // the caller's settings: the defaults (implicit stepper, islands, one thread); set fields to choose others
  pdStateOptions options = pd_state_options_default();
  pdState* state = pd_state_create(model, &options);
  if (seconds < 0) seconds = model->settings.tend;
  bool completed = pd_advance(model, state, seconds, print_sample, stdout);
  // a run that could not go on says why in its warning counters (state.h)
  for (int w = 0; w < pd_warnCount; w++) {
    if (state->warnings[w] > 0) fprintf(stderr, "warning: %s x %ld\n", pdWarningNames[w], state->warnings[w]);
  }
  int status = completed ? 0 : 1;
  pd_state_free(state);
  pd_model_free(model);
  return status;
}
