// polydyn check — parse and compile a scene, print what the engine derived from it.
#include <stdio.h>
#include <string.h>

#include "cli.h"

static const char* const help =
    "usage: polydyn check SCENE\n"
    "\n"
    "Parses and compiles SCENE without simulating it, and prints every body's mass, centre of mass,\n"
    "inertia (full tensor and principal moments), polyhedron counts (V, E, F) and the settings in\n"
    "force with where each came from. Exit status: 0 ok, 2 bad input.\n";

// -0 prints as "-0"; adding +0 makes it 0, which is what a reader expects to see
static double shown(double x) { return x + 0.0; }

static const char* primitive_word(pdPrimitiveKind k) {
  static const char* const words[] = {"cube", "prism", "tprism", "sphere", "hull"};
  return words[k];
}

static void print_origin(const pdSceneSettings* s, unsigned bit) {
  int index = 0;
  while ((1u << index) != bit) ++index;
  if (s->setMask & bit)
    printf("  (line %d)\n", s->where[index].line);
  else
    printf("  (default)\n");
}

static void print_settings(const pdModel* m, const pdSceneSettings* s) {
  const pdSettings* set = &m->settings;
  printf("settings:\n");
  printf("  gravity     %.10g %.10g %.10g m/s^2", set->gravity.x, set->gravity.y, set->gravity.z);
  print_origin(s, PD_SET_GRAVITY);
  const struct {
    const char* name;
    double value;
    const char* unit;
    unsigned bit;
  } rows[] = {
      {"tend", set->tend, "s", PD_SET_TEND},           {"tol", set->tol, "", PD_SET_TOL},
      {"dt", set->dt, "s", PD_SET_DT},                 {"dtmin", set->dtmin, "s", PD_SET_DTMIN},
      {"dtmax", set->dtmax, "s", PD_SET_DTMAX},        {"sample", set->sampleRate, "1/s", PD_SET_SAMPLE},
      {"deflection", set->deflection, "", PD_SET_DEFLECTION},
  };
  for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
    printf("  %-11s %.10g %s", rows[i].name, rows[i].value, rows[i].unit);
    print_origin(s, rows[i].bit);
  }
  printf("  %-11s %.10g m/s", "vmax", set->vmax);
  if (set->vmaxEstimated)
    printf("  (estimated: initial speeds and a fall through the scene's height)\n");
  else
    print_origin(s, PD_SET_VMAX);
}

static void print_body(const pdBody* b) {
  printf("  %s: %s, colour %s, %s (line %d)\n", b->name, primitive_word(b->kind), b->color,
         b->fixed ? "fixed" : "moving", b->where.line);
  printf("    polyhedron      V=%d E=%d F=%d (V-E+F=%d)\n", b->shape.vertexCount, b->shape.edgeCount,
         b->shape.faceCount, b->shape.vertexCount - b->shape.edgeCount + b->shape.faceCount);
  printf("    mass            %.10g kg (volume %.10g m^3, density %.10g kg/m^3)\n", b->mass, b->volume, b->density);
  printf("    centre of mass  %.10g %.10g %.10g m (world)\n", b->x0.x, b->x0.y, b->x0.z);
  printf("    geometric centre in the body frame  %.10g %.10g %.10g m\n", shown(b->geometricCentre.x),
         shown(b->geometricCentre.y), shown(b->geometricCentre.z));
  printf("    principal inertias  %.10g %.10g %.10g kg m^2\n", b->principal[0], b->principal[1], b->principal[2]);
  for (int k = 0; k < 3; ++k)
    printf("      axis %d (body)  %.6f %.6f %.6f\n", k + 1, shown(b->principalAxes.m[0][k]),
           shown(b->principalAxes.m[1][k]), shown(b->principalAxes.m[2][k]));
  printf("    inertia tensor (body axes, about the centre of mass), kg m^2:\n");
  for (int i = 0; i < 3; ++i)
    printf("      %14.8g %14.8g %14.8g\n", shown(b->inertia.m[i][0]), shown(b->inertia.m[i][1]),
           shown(b->inertia.m[i][2]));
  printf("    size            %.10g m (mean bounding-box extent)\n", b->size);
  printf("    material        mu %.6g", b->used.mu);
  if (b->requested.restitution >= 0.0) printf(", restitution %.6g", b->requested.restitution);
  printf(" (spring and damper constants are derived by the contact model)\n");
}

int pd_cmd_check(int argc, char** argv) {
  const char* scene = NULL;
  for (int i = 1; i < argc; ++i) {
    if (pd_cli_is_help(argv[i])) {
      fputs(help, stdout);
      return PD_EXIT_OK;
    } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
      return pd_cli_usage_error("check", "unknown option '%s'", argv[i]);
    } else if (scene) {
      return pd_cli_usage_error("check", "one scene at a time");
    } else {
      scene = argv[i];
    }
  }
  if (!scene) return pd_cli_usage_error("check", "no scene given");
  pdSceneSettings settings;
  pdModel* m = pd_cli_load_model(scene, NULL, &settings);
  if (!m) return PD_EXIT_BAD_INPUT;
  printf("scene: %s\n", m->scenePath);
  print_settings(m, &settings);
  printf("bodies: %d (%d moving, %d fixed)\n", m->bodyCount, m->movingCount, m->bodyCount - m->movingCount);
  for (int i = 0; i < m->bodyCount; ++i) print_body(&m->bodies[i]);
  pd_model_free(m);
  return PD_EXIT_OK;
}
