// polydyn check — parse and compile a scene, print what the engine derived from it.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "options.h"

static const char* const help =
    "usage: polydyn check SCENE\n"
    "\n"
    "Parses and compiles SCENE without simulating it, and prints every body's mass, centre of mass,\n"
    "inertia (full tensor and principal moments), polyhedron counts (V, E, F), the settings in force\n"
    "with where each came from, and the contact model's material parameters (paper §3.2, §3.3): per\n"
    "body the material as requested and as used (mu, kn, kt, cn, ct), the mass that sized it, the\n"
    "minimum effective mass and the time constants; then the number of material classes and every\n"
    "time-constant adjustment made to fit dtmin (or \"adjustments: none\"); then the stacks (moving\n"
    "bodies joined by contacts after 0.1 s of the run, or at tend if sooner; scenes of at most 64\n"
    "moving bodies) with the pairs whose springs are raised for the load pressing them and the\n"
    "frequency and damping ratio of each of their contact modes.\n"
    "Refuses (exit 2) what `polydyn run` refuses, including a restitution below 0.01 and bodies that\n"
    "overlap at t = 0. Exit status: 0 ok, 2 bad input.\n";

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
  printf("  %-11s %s", "sleep", set->sleep ? "on" : "off");
  print_origin(s, PD_SET_SLEEP);
  // dt is the fixed stepper's step, which nothing holds within the stability bound (docs/integration.md)
  double bound = pd_model_fixed_step_max(m);
  if (isnan(bound))
    printf("  fixed step  bound not computed (too many material classes)\n");
  else if (isinf(bound))
    printf("  fixed step  no bound (no contact can form)\n");
  else
    printf("  fixed step  at most %.6g s (RK4 stable at the stiffest contact: omega h <= " PD_STABLE_STEP_OMEGA_TEXT "); dt %s\n", bound,
           set->dt > bound ? "exceeds it" : "is within it");
}

// Material as the scene asked for it: only what the file set (mu always has a value).
static void print_requested(const pdMaterial* r) {
  printf("    material asked  mu %.6g", r->mu);
  const struct {
    const char* name;
    double value;
    const char* unit;
  } rows[] = {{"kn", r->kn, "N/m"}, {"kt", r->kt, "N/m"}, {"cn", r->cn, "N s/m"}, {"ct", r->ct, "N s/m"},
              {"restitution", r->restitution, ""}};
  for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i)
    if (rows[i].value >= 0.0)
      printf(", %s %.6g%s%s", rows[i].name, rows[i].value, *rows[i].unit ? " " : "", rows[i].unit);
  printf("\n");
}

static void print_contact_material(const pdModel* m, int i) {
  const pdBody* b = &m->bodies[i];
  pdBodyContactInfo info = pd_model_body_contact_info(m, i);
  print_requested(&b->requested);
  printf("    material used   mu %.6g, restitution %.6g%s (damping ratio %.4f, %s)", b->used.mu,
         b->used.restitution, b->requested.restitution >= 0.0 ? "" : " (default)", info.zeta,
         info.zeta > 1.0 ? "overdamped: eq. 15 continued" : "eq. 15");
  const struct {
    const char* name;
    double value;
  } given[] = {{"kn", b->used.kn}, {"kt", b->used.kt}, {"cn", b->used.cn}, {"ct", b->used.ct}};
  for (size_t k = 0; k < sizeof given / sizeof given[0]; ++k)
    if (given[k].value >= 0.0) printf(", %s %.6g (given)", given[k].name, given[k].value);
  printf("; springs and dampers: per pair, below\n");
  if (!b->fixed) printf("    min eff. mass   %.10g kg (App. B, exact)\n", info.mMin);
}

// At most this many pairs of material classes are printed.
#define PD_CHECK_CONTACT_PAIRS_MAX 50

static void print_contact_pairs(const pdModel* m) {
  int a[PD_CHECK_CONTACT_PAIRS_MAX], b[PD_CHECK_CONTACT_PAIRS_MAX];
  int total = pd_model_contact_class_pairs(m, a, b, PD_CHECK_CONTACT_PAIRS_MAX);
  printf("contact pairs: %d (one line per pair of material classes that can touch)\n", total);
  for (int i = 0; i < total && i < PD_CHECK_CONTACT_PAIRS_MAX; ++i) {
    pdPairContact p = pd_model_pair_contact(m, a[i], b[i]);
    printf("  %s / %s: mu %.6g, restitution %.6g (%s)\n", m->bodies[a[i]].name, m->bodies[b[i]].name, p.mu,
           p.restitution, p.restitutionSource);
    bool thin = p.deltaMax < m->settings.deflection * fmin(m->bodies[a[i]].size, m->bodies[b[i]].size);
    printf(
        "    springs       kn %.6g N/m, kt %.6g N/m per contact (series of both sides; delta_max %.4g m %s, "
        "m_pair %.6g kg)\n",
        p.kn, p.kt, p.deltaMax, thin ? "= a quarter of the thinner body's width" : "of the smaller body", p.massPair);
    if (p.modalN)
      printf("    normal damper modal: damping ratio %.4f for the mass each contact carries (cn %.6g N s/m for one "
             "contact at m_pair)\n",
             p.zetaN, p.cn);
    else
      printf("    normal damper given: cn %.6g N s/m per contact (damping ratio %.4f at m_pair)\n", p.cn, p.zetaN);
    if (p.modalT)
      printf(
          "    tang. damper  modal: damping ratio %.4f (a face's twist critical; ct %.6g N s/m for one contact "
          "at m_pair)\n",
          p.zetaT, p.ct);
    else
      printf("    tang. damper  given: ct %.6g N s/m per contact\n", p.ct);
    printf("    time scales   period 2 pi sqrt(m_pair/kn) %.4g s, min eff. mass of the pair %.6g kg\n", p.period,
           p.massMin);
  }
  if (total > PD_CHECK_CONTACT_PAIRS_MAX) printf("  ... and %d more pairs\n", total - PD_CHECK_CONTACT_PAIRS_MAX);
}

static void print_adjustments(const pdModel* m) {
  int count = pd_model_adjustment_count(m), dropped = pd_model_adjustments_dropped(m);
  if (count == 0 && dropped == 0) {
    printf("adjustments: none\n");
    return;
  }
  printf("adjustments: %d (time constants below dtmin = %.6g s, paper §3.3)\n", count + dropped, m->settings.dtmin);
  char line[1024];
  for (int i = 0; i < count; ++i) {
    pd_model_adjustment_describe(m, i, line, sizeof line);
    printf("  %s\n", line);
  }
  if (dropped > 0) printf("  ... and %d more not listed (dropped)\n", dropped);
}

// The stacks are those of the state after this long (s), or at tend if sooner: a stack set down at rest forms from
// the floor up, one interface per contact period (a few ms; cases/bench/stack_20.scene's top box is reached after
// about 60 ms).
#define PD_CHECK_STACKS_AFTER 0.1
// Scenes of more moving bodies than this are not run for their stacks (`check` stays quick: a pile of 1000 would
// take seconds).
#define PD_CHECK_STACKS_BODIES_MAX 64
// At most this many roots are printed per stack (the slowest; 12 per body in all).
#define PD_CHECK_STACK_ROOTS_MAX 12

// The stack's pairs whose springs are raised for the load they carry (docs/contact-model.md, "Springs sized by the
// load"), one line each: the factor over eq. (11)'s and the stiffness per contact it gives. Contacts are listed by
// pair, so a pair's contacts are adjacent.
static void print_load_springs(const pdModel* m, const pdState* s, const int* stackOf, int stack) {
  int n = pd_state_contact_count(s);
  for (int i = 0; i < n; ++i) {
    pdContactReport c = pd_state_contact(s, i);
    if (stackOf[c.bodyA] != stack && stackOf[c.bodyB] != stack) continue;
    if (i > 0) {
      pdContactReport p = pd_state_contact(s, i - 1);
      if ((p.bodyA == c.bodyA && p.bodyB == c.bodyB) || (p.bodyA == c.bodyB && p.bodyB == c.bodyA)) continue;
    }
    if (!(c.springScale > 1.0)) continue;
    pdPairContact pair = pd_model_pair_contact(m, c.bodyA, c.bodyB);
    printf("    springs       %s / %s: %.4g times eq. (11)'s for the load pressing them (kn %g N/m per contact, "
           "m_pair %g kg)\n",
           m->bodies[c.bodyA].name, m->bodies[c.bodyB].name, c.springScale, c.springScale * pair.kn, pair.massPair);
  }
}

static void print_stack(const pdModel* m, const pdState* s, const int* stackOf, int stack) {
  int bodies = 0, contacts = 0;
  double lightest = INFINITY, heaviest = 0.0;
  printf("  stack %d:", stack + 1);
  for (int k = 0; k < m->bodyCount; ++k)
    if (stackOf[k] == stack) {
      printf("%s %s", bodies ? "," : "", m->bodies[k].name);
      ++bodies;
      lightest = fmin(lightest, m->bodies[k].mass);
      heaviest = fmax(heaviest, m->bodies[k].mass);
    }
  for (int i = 0, n = pd_state_contact_count(s); i < n; ++i) {
    pdContactReport c = pd_state_contact(s, i);
    contacts += stackOf[c.bodyA] == stack || stackOf[c.bodyB] == stack;
  }
  printf(" (%d bodies, %d contacts, masses %.6g to %.6g kg)\n", bodies, contacts, lightest, heaviest);
  print_load_springs(m, s, stackOf, stack);
  pdStackMode modes[12 * PD_STACK_MODES_BODIES_MAX];
  int count = pd_state_stack_modes(m, s, stackOf, stack, modes, 12 * PD_STACK_MODES_BODIES_MAX);
  if (count < 0) {
    printf("    modes not analysed (more than %d bodies)\n", PD_STACK_MODES_BODIES_MAX);
    return;
  }
  int oscillating = 0, real = 0;
  double slowestDecay = INFINITY, slowestPeriod = 0.0, leastZeta = INFINITY;
  for (int j = 0; j < count; ++j) {
    double decay = modes[j].omega * modes[j].zeta;  // 1/s: −Re λ
    slowestDecay = fmin(slowestDecay, decay);
    if (modes[j].real) {
      ++real;
      continue;
    }
    ++oscillating;
    slowestPeriod = fmax(slowestPeriod, 2.0 * 3.14159265358979323846 / modes[j].omega);
    leastZeta = fmin(leastZeta, modes[j].zeta);
  }
  printf("    modes         %d oscillating, %d overdamped roots; the slowest %d:\n", oscillating, real,
         count < PD_CHECK_STACK_ROOTS_MAX ? count : PD_CHECK_STACK_ROOTS_MAX);
  for (int j = 0; j < count && j < PD_CHECK_STACK_ROOTS_MAX; ++j) {
    if (modes[j].real)
      printf("      overdamped    decay rate %.6g 1/s\n", modes[j].omega);
    else
      printf("      %9.6g Hz  damping ratio %.4f\n", modes[j].omega / (2.0 * 3.14159265358979323846), modes[j].zeta);
  }
  if (oscillating > 0)
    printf("    least damped  damping ratio %.4f; amplitudes fall 1000-fold within %.3g s = %.3g periods of the "
           "slowest mode\n",
           leastZeta, log(1000.0) / slowestDecay, log(1000.0) / slowestDecay / slowestPeriod);
}

// The stacks at the state after PD_CHECK_STACKS_AFTER, with the roots of each.
static void print_stacks(const pdModel* m) {
  if (m->movingCount > PD_CHECK_STACKS_BODIES_MAX) {
    printf("stacks: not analysed (%d moving bodies; at most %d)\n", m->movingCount, PD_CHECK_STACKS_BODIES_MAX);
    return;
  }
  pdState* s = pd_state_create(m, NULL);
  if (!s) return;
  double t = fmin(PD_CHECK_STACKS_AFTER, m->settings.tend);
  if (!pd_advance(m, s, t, NULL, NULL)) {
    printf("stacks: not known (the first %.3g s did not run)\n", t);
    pd_state_free(s);
    return;
  }
  int* stackOf = malloc((size_t)m->bodyCount * sizeof *stackOf);
  if (!stackOf) abort();
  int stacks = pd_state_stacks(m, s, stackOf);
  printf("stacks: %d after %.3g s (moving bodies joined by contacts; their contact modes, paper §3.3)\n", stacks, t);
  for (int k = 0; k < stacks; ++k) print_stack(m, s, stackOf, k);
  free(stackOf);
  pd_state_free(s);
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
}

int pd_cmd_check(int argc, char** argv) {
  const char* scene = NULL;
  pdCliPositionals scenes = {.values = &scene, .max = 1, .tooMany = "one scene at a time"};
  int parsed = pd_cli_parse_options("check", argc, argv, NULL, 0, &scenes, help);
  if (parsed >= 0) return parsed;
  if (!scene) return pd_cli_usage_error("check", "no scene given");
  if (pd_cli_parse_only) return PD_EXIT_OK;
  pdSceneSettings settings;
  pdModel* m = pd_cli_load_model(scene, NULL, &settings);
  if (!m) return PD_EXIT_BAD_INPUT;
  printf("scene: %s\n", m->scenePath);
  print_settings(m, &settings);
  printf("bodies: %d (%d moving, %d fixed)\n", m->bodyCount, m->movingCount, m->bodyCount - m->movingCount);
  for (int i = 0; i < m->bodyCount; ++i) {
    print_body(&m->bodies[i]);
    print_contact_material(m, i);
  }
  printf("material classes: %d (contact constants are derived once per pair of classes)\n",
         pd_model_material_class_count(m));
  print_contact_pairs(m);
  print_adjustments(m);
  print_stacks(m);
  pd_model_free(m);
  return PD_EXIT_OK;
}
