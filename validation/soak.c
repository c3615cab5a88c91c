// polydyn refcheck — the random-scene soak: scene generation and the invariants (pdval/soak.h).
#include "pdval/soak.h"

#include <errno.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "interference.h"
#include "polydyn/model.h"
#include "pdref/refcheck.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"
#include "pdrun/text_buffer.h"
#include "pdutil/clock.h"

const char* const pdSoakKindNames[pd_soakKindCount] = {"drop", "stack", "throw", "free", "overlap"};
const char* const pdSoakStatusNames[pd_soakStatusCount] = {"ok", "refused", "over-budget", "failed", "not-built"};

#define PI 3.14159265358979323846

// ---------------------------------------------------------------- scene text

static double uniform(gsl_rng* r, double lo, double hi) { return lo + (hi - lo) * gsl_rng_uniform(r); }
static double log_uniform(gsl_rng* r, double lo, double hi) { return lo * pow(hi / lo, gsl_rng_uniform(r)); }
static bool chance(gsl_rng* r, double p) { return gsl_rng_uniform(r) < p; }

// A uniformly distributed unit vector.
static void unit_vector(gsl_rng* r, double u[3]) {
  double z = uniform(r, -1.0, 1.0), phi = uniform(r, 0.0, 2.0 * PI), s = sqrt(1.0 - z * z);
  u[0] = s * cos(phi), u[1] = s * sin(phi), u[2] = z;
}

// A plate's thickness over its larger width: thick enough for side faces of several δ_max (δ_max is at most a
// quarter of the thinner body's width, docs/contact-model.md), thin enough to rest, slide and be hit on its rim.
static double plate_ratio(gsl_rng* r) { return log_uniform(r, 3.0, 30.0); }

// One body's shape line; returns the radius of a sphere about its centre that holds it (for spacing). The
// generator's shapes (PD_SOAK_GENERATOR_*): the first draws five kinds, the second a sixth, plates.
static double shape_line(gsl_rng* r, int generator, pdTextBuffer* t, const char* name, double size) {
  static const char* const colors[] = {"red", "blue", "green", "orange", "tan", "grey", "brown", "purple"};
  const char* color = colors[gsl_rng_uniform_int(r, sizeof colors / sizeof colors[0])];
  int choice = (int)gsl_rng_uniform_int(r, generator >= PD_SOAK_GENERATOR_PLATES ? 6 : 5);
  double sx = size * log_uniform(r, 0.5, 2.0), sy = size * log_uniform(r, 0.5, 2.0), sz = size * log_uniform(r, 0.5, 2.0);
  if (choice == 0 && chance(r, 0.15)) sz = fmax(sx, sy) / 100.0;  // a 100:1 blade
  switch (choice) {
    case 0:
      pd_text_appendf(t, "cube %s %s %.17g %.17g %.17g\n", name, color, sx, sy, sz);
      return 0.5 * sqrt(sx * sx + sy * sy + sz * sz);
    case 1:
      pd_text_appendf(t, "prism %s %s %d %.17g %.17g %.17g\n", name, color, 3 + (int)gsl_rng_uniform_int(r, 6), sx, sy,
                      sz);
      return 0.5 * sqrt(sx * sx + sy * sy + sz * sz);
    case 2:
      pd_text_appendf(t, "tprism %s %s %d %.17g %.17g %.17g %.17g\n", name, color, 3 + (int)gsl_rng_uniform_int(r, 6),
                      sx, sy, sz, uniform(r, 0.3, 1.0));
      return 0.5 * sqrt(sx * sx + sy * sy + sz * sz);
    case 3:
      pd_text_appendf(t, "sphere %s %s %d %.17g %.17g %.17g\n", name, color, (int)gsl_rng_uniform_int(r, 2), sx, sy,
                      sz);
      return 0.5 * fmax(sx, fmax(sy, sz));
    case 5: {
      // a plate: a thin box, a thin regular prism, or a thin frustum (its side faces bevelled)
      sz = fmax(sx, sy) / plate_ratio(r);
      int shape = (int)gsl_rng_uniform_int(r, 5), sides = 3 + (int)gsl_rng_uniform_int(r, 6);
      if (shape < 2)
        pd_text_appendf(t, "cube %s %s %.17g %.17g %.17g\n", name, color, sx, sy, sz);
      else if (shape < 4)
        pd_text_appendf(t, "prism %s %s %d %.17g %.17g %.17g\n", name, color, sides, sx, sy, sz);
      else
        pd_text_appendf(t, "tprism %s %s %d %.17g %.17g %.17g %.17g\n", name, color, sides, sx, sy, sz,
                        uniform(r, 0.6, 0.95));
      return 0.5 * sqrt(sx * sx + sy * sy + sz * sz);
    }
    default: {
      // a hull of 6 … 12 random points in a box, sometimes squashed to a sliver (20:1)
      int n = 6 + (int)gsl_rng_uniform_int(r, 7);
      double squash = chance(r, 0.2) ? 0.05 : 1.0, far = 0.0;
      pd_text_appendf(t, "hull %s %s", name, color);
      for (int i = 0; i < n; ++i) {
        double p[3] = {uniform(r, -0.5, 0.5) * sx, uniform(r, -0.5, 0.5) * sy, uniform(r, -0.5, 0.5) * sz * squash};
        far = fmax(far, sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
        pd_text_appendf(t, " %.17g %.17g %.17g", p[0], p[1], p[2]);
      }
      pd_text_appendf(t, "\n");
      return 2.0 * far;  // the centre of mass lies inside the hull: its distance to any point is < 2 far
    }
  }
}

// The material lines of a body; *elastic set when it asks for restitution 1.
static void material_lines(gsl_rng* r, pdTextBuffer* t, bool* elastic) {
  if (chance(r, 0.85)) pd_text_appendf(t, "mu %.17g\n", chance(r, 0.15) ? 0.0 : uniform(r, 0.05, 1.5));
  if (chance(r, 0.7)) {
    double e = chance(r, 0.1) ? 1.0 : uniform(r, 0.1, 0.95);
    if (e >= 1.0) *elastic = true;
    pd_text_appendf(t, "restitution %.17g\n", e);
  }
  pd_text_appendf(t, "spgrav %.17g\n", log_uniform(r, 0.3, 10.0));
}

static void turn(gsl_rng* r, double* angle, double axis[3]) {
  *angle = uniform(r, 0.0, 180.0);
  unit_vector(r, axis);
}

// Settings lines shared by every kind: sometimes vmax, deflection and tol are set.
static void settings_lines(gsl_rng* r, pdTextBuffer* t, double tend) {
  pd_text_appendf(t, "tend %.17g\nsample 100\n", tend);
  if (chance(r, 0.2)) pd_text_appendf(t, "tol %.17g\n", log_uniform(r, 1e-7, 1e-5));
  if (chance(r, 0.2)) pd_text_appendf(t, "deflection %.17g\n", log_uniform(r, 0.005, 0.05));
}

// A fixed floor whose top face is the plane z = 0, `half` wide each way.
static void floor_lines(pdTextBuffer* t, double half) {
  pd_text_appendf(t, "cube floor grey %.17g %.17g %.17g\nfixed\nloc 0 0 %.17g\nmu 0.5\n", 2 * half, 2 * half,
                  0.1 * half, -0.05 * half);
}

static int drop_scene(gsl_rng* r, int generator, pdTextBuffer* t, double L, bool* elastic) {
  int n = 1 + (int)gsl_rng_uniform_int(r, 30);
  settings_lines(r, t, 0.5);
  // pitch from the largest body: every body's sphere fits in its cell
  double sizes[30], radii[30];
  pdTextBuffer bodies = {0};
  double pitch = 0.0;
  for (int i = 0; i < n; ++i) {
    sizes[i] = L * log_uniform(r, 0.3, 3.0);
    char name[16];
    snprintf(name, sizeof name, "b%d", i);
    radii[i] = shape_line(r, generator, &bodies, name, sizes[i]);
    pitch = fmax(pitch, 2.2 * radii[i]);
    // placeholder: the loc line is written below, once the pitch is known
    pd_text_appendf(&bodies, "@LOC%d\n", i);
    material_lines(r, &bodies, elastic);
  }
  int side = (int)ceil(sqrt((double)n));
  floor_lines(t, fmax(10.0 * pitch * side, 20.0 * L));
  // replace each placeholder by its loc and vel lines
  const char* p = bodies.data;
  for (int i = 0; i < n; ++i) {
    char mark[16];
    snprintf(mark, sizeof mark, "@LOC%d\n", i);
    const char* at = strstr(p, mark);
    pd_text_appendf(t, "%.*s", (int)(at - p), p);
    int layer = i / (side * side), row = (i / side) % side, col = i % side;
    double x = (col - 0.5 * (side - 1)) * pitch, y = (row - 0.5 * (side - 1)) * pitch;
    double z = 0.5 * pitch + layer * pitch + uniform(r, 0.0, 2.0 * L), angle, axis[3], dir[3], spin[3];
    turn(r, &angle, axis);
    pd_text_appendf(t, "loc %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", x, y, z, angle, axis[0], axis[1], axis[2]);
    double speed = uniform(r, 0.0, 3.0), omega = uniform(r, 0.0, 360.0);
    unit_vector(r, dir);
    unit_vector(r, spin);
    pd_text_appendf(t, "vel %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", speed * dir[0], speed * dir[1],
                    speed * dir[2], omega, spin[0], spin[1], spin[2]);
    p = at + strlen(mark);
  }
  pd_text_appendf(t, "%s", p);
  free(bodies.data);
  return n + 1;
}

static int stack_scene(gsl_rng* r, int generator, pdTextBuffer* t, double L, bool* elastic) {
  int n = 2 + (int)gsl_rng_uniform_int(r, 7);
  settings_lines(r, t, 0.5);
  floor_lines(t, 20.0 * L);
  bool flush = chance(r, 0.4);  // equal widths, aligned: every side face flush with the one below
  double w = L * log_uniform(r, 0.5, 2.0), d = L * log_uniform(r, 0.5, 2.0), z = 0.0;
  for (int i = 0; i < n; ++i) {
    double h = L * log_uniform(r, 0.3, 1.5);
    double sx = flush ? w : L * log_uniform(r, 0.5, 2.0), sy = flush ? d : L * log_uniform(r, 0.5, 2.0);
    if (generator >= PD_SOAK_GENERATOR_PLATES && chance(r, 0.3)) h = fmax(sx, sy) / plate_ratio(r);  // a plate
    pd_text_appendf(t, "cube s%d tan %.17g %.17g %.17g\n", i, sx, sy, h);
    double angle = flush ? 0.0 : uniform(r, 0.0, 90.0);
    pd_text_appendf(t, "loc 0 0 %.17g %.17g 0 0 1\n", z + 0.5 * h, angle);
    material_lines(r, t, elastic);
    z += h;
  }
  return n + 1;
}

static int throw_scene(gsl_rng* r, int generator, pdTextBuffer* t, double L, bool* elastic) {
  int n = 1 + (int)gsl_rng_uniform_int(r, 10);
  settings_lines(r, t, 0.3);
  floor_lines(t, 40.0 * L);
  double wallX = 8.0 * L;
  pd_text_appendf(t, "cube wall grey %.17g %.17g %.17g\nfixed\nloc %.17g 0 %.17g\nmu 0.5\n", L, 40.0 * L, 20.0 * L,
                  wallX + 0.5 * L, 10.0 * L);
  for (int i = 0; i < n; ++i) {
    char name[16];
    snprintf(name, sizeof name, "t%d", i);
    double size = L * log_uniform(r, 0.3, 2.0);
    double radius = shape_line(r, generator, t, name, size), angle, axis[3], spin[3];
    turn(r, &angle, axis);
    // a column along y, spaced by the largest possible sphere: thrown towards +x and down
    double y = (i - 0.5 * (n - 1)) * 3.0 * (2.0 * L), z = fmax(radius * 1.05, uniform(r, 1.0, 4.0) * L);
    pd_text_appendf(t, "loc %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", uniform(r, -4.0, 0.0) * L, y, z, angle,
                    axis[0], axis[1], axis[2]);
    double speed = uniform(r, 5.0, 50.0), down = uniform(r, 0.0, 0.6);
    unit_vector(r, spin);
    pd_text_appendf(t, "vel %.17g 0 %.17g %.17g %.17g %.17g %.17g\n", speed * sqrt(1.0 - down * down), -speed * down,
                    uniform(r, 0.0, 720.0), spin[0], spin[1], spin[2]);
    material_lines(r, t, elastic);
  }
  return n + 2;
}

static int free_scene(gsl_rng* r, int generator, pdTextBuffer* t, double L, bool* elastic) {
  int n = 2 + (int)gsl_rng_uniform_int(r, 9);
  settings_lines(r, t, 0.5);
  pd_text_appendf(t, "gravity 0 0 0\n");
  // on a ring of radius R in the xy plane, each aimed at the middle with a little scatter
  double R = 3.0 * L * n;
  for (int i = 0; i < n; ++i) {
    char name[16];
    snprintf(name, sizeof name, "f%d", i);
    shape_line(r, generator, t, name, L * log_uniform(r, 0.5, 2.0));
    double a = 2.0 * PI * i / n, x = R * cos(a), y = R * sin(a), z = uniform(r, -0.3, 0.3) * L, angle, axis[3], spin[3];
    turn(r, &angle, axis);
    pd_text_appendf(t, "loc %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", x, y, z, angle, axis[0], axis[1], axis[2]);
    // reaches the middle in about a quarter second, at most 50 m/s
    double speed = fmin(R / 0.25, 50.0) * uniform(r, 0.8, 1.2);
    double sx = -x / R + uniform(r, -0.1, 0.1), sy = -y / R + uniform(r, -0.1, 0.1), norm = hypot(sx, sy);
    unit_vector(r, spin);
    pd_text_appendf(t, "vel %.17g %.17g 0 %.17g %.17g %.17g %.17g\n", speed * sx / norm, speed * sy / norm,
                    uniform(r, 0.0, 360.0), spin[0], spin[1], spin[2]);
    material_lines(r, t, elastic);
  }
  return n;
}

static int overlap_scene(gsl_rng* r, pdTextBuffer* t, double L, bool* elastic) {
  settings_lines(r, t, 0.2);
  floor_lines(t, 20.0 * L);
  double a[3] = {L * log_uniform(r, 0.5, 2.0), L * log_uniform(r, 0.5, 2.0), L * log_uniform(r, 0.5, 2.0)};
  double b[3] = {L * log_uniform(r, 0.5, 2.0), L * log_uniform(r, 0.5, 2.0), L * log_uniform(r, 0.5, 2.0)};
  double height = 2.0 * fmax(fmax(a[1], a[2]), fmax(b[1], b[2]));
  // aligned along x (turned about x only, which keeps their x extents): overlapping by a fraction of the smaller
  double overlap = uniform(r, 0.05, 0.3) * fmin(a[0], b[0]);
  pd_text_appendf(t, "cube p grey %.17g %.17g %.17g\nloc 0 0 %.17g %.17g 1 0 0\n", a[0], a[1], a[2], height,
                  uniform(r, 0, 90));
  material_lines(r, t, elastic);
  pd_text_appendf(t, "cube q grey %.17g %.17g %.17g\nloc %.17g 0 %.17g %.17g 1 0 0\n", b[0], b[1], b[2],
                  0.5 * (a[0] + b[0]) - overlap, height, uniform(r, 0, 90));
  material_lines(r, t, elastic);
  return 3;
}

pdSoakScene pd_soak_scene(int generator, unsigned long seed, long index) {
  PD_ASSERT(generator >= PD_SOAK_GENERATOR_BLADES && generator <= PD_SOAK_GENERATOR_LATEST);
  gsl_rng* r = gsl_rng_alloc(gsl_rng_mt19937);
  if (!r) abort();
  // one stream per scene: a scene's text never depends on the scenes before it
  gsl_rng_set(r, (seed * 2654435761ul + (unsigned long)index * 40503ul + 1ul) & 0xfffffffful);
  pdSoakScene s = {.kind = (pdSoakKind)gsl_rng_uniform_int(r, pd_soakKindCount)};
  double L = log_uniform(r, 0.01, 10.0);  // the scene's length scale: three orders of magnitude
  pdTextBuffer t = {0};
  // the first generator's header as it always was (its scenes replay byte for byte)
  if (generator == PD_SOAK_GENERATOR_BLADES)
    pd_text_appendf(&t, "# polydyn soak: seed %lu, scene %ld (%s), length scale %.3g m\n", seed, index,
                    pdSoakKindNames[s.kind], L);
  else
    pd_text_appendf(&t, "# polydyn soak: generator %d, seed %lu, scene %ld (%s), length scale %.3g m\n", generator,
                    seed, index, pdSoakKindNames[s.kind], L);
  bool elastic = false;
  switch (s.kind) {
    case pd_soakDrop: s.objects = drop_scene(r, generator, &t, L, &elastic); break;
    case pd_soakStack: s.objects = stack_scene(r, generator, &t, L, &elastic); break;
    case pd_soakThrow: s.objects = throw_scene(r, generator, &t, L, &elastic); break;
    case pd_soakFree: s.objects = free_scene(r, generator, &t, L, &elastic); break;
    default: s.objects = overlap_scene(r, &t, L, &elastic); break;
  }
  s.dissipative = !elastic;
  s.text = t.data;
  gsl_rng_free(r);
  return s;
}

void pd_soak_scene_free(pdSoakScene* scene) {
  free(scene->text);
  scene->text = NULL;
}

// ---------------------------------------------------------------- invariants

typedef struct watch {
  const pdSoakScene* scene;
  double budget, wall0;
  bool started, overBudget, nonFinite;
  double e0, momentumScale;
  pdVec3 p0;
  double stretchE0;  // the energy of the system stepped where its stretch began (observe_step)
  pdVec3 stretchP0;  // and its momentum
  pdSoakResult* out;
  char broke[240];  // the first invariant that broke (soft), empty while all hold
  bool soft;          // the soft engine: overlaps judged against the pair's limit (pair_limit)
  double limit;       // the plain penetration limit, δ_max (pdSoakRunOptions.penetrationLimit)
  double worst;       // max over samples (and steps) of a pair's overlap over its limit; above 1: failed
  double worstDepth, worstLimit;  // that pair's overlap and limit, δ_max
  char worstPair[160];            // that pair and the time
} watch;

static pdVec3 momentum(const pdModel* m, const pdState* s, double* scale) {
  pdVec3 p = {0, 0, 0};
  double sum = 0.0;
  for (int k = 0; k < m->movingCount; ++k) {
    int i = m->movingBodies[k];
    pdBodyState b = pd_state_body(m, s, i);
    p = pd_v3_muladd(p, m->bodies[i].mass, b.v);
    sum += m->bodies[i].mass * pd_v3_norm(b.v);
  }
  if (scale) *scale = sum;
  return p;
}

// A fixed body pressing on one of a pair stands in for this many times the pressed body's mass: immovable for the
// limit (the mass moving with the pressed body then grows as 1 / sin²θ, or without bound while held, below).
#define PRESSING_FIXED_MASS_FACTOR 1e6

// The mass that moves with body b of a pair when b moves at unit speed along `into` (towards the pair's other
// body), given pushes[k], the net contact force of each third body k on b, and whether the pair's contact holds b
// from sliding across (it sticks): pair_limit's derivation. Infinite for a fixed b.
static double mass_moving_with(const pdModel* m, int b, pdVec3 into, const pdVec3* pushes, bool held) {
  if (m->bodies[b].fixed) return INFINITY;
  double mb = m->bodies[b].mass, along = mb, a[3][3] = {{mb, 0, 0}, {0, mb, 0}, {0, 0, mb}};
  for (int k = 0; k < m->bodyCount; ++k) {
    double f = pd_v3_norm(pushes[k]), c = f > 0.0 ? pd_v3_dot(pushes[k], into) / f : 0.0;
    if (!(c > 0.0)) continue;  // not pressing b towards the other body
    pdVec3 u = pd_v3_scale(pushes[k], 1.0 / f);
    double mk = m->bodies[k].fixed ? PRESSING_FIXED_MASS_FACTOR * mb : m->bodies[k].mass;
    along += mk * c * c;
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) a[r][q] += mk * pd_v3_get(u, r) * pd_v3_get(u, q);
  }
  if (held) return along;
  // 1 / (into · A⁻¹ into) by Cramer's rule: A is symmetric positive definite (mb 1 plus positive semidefinite terms)
  pdVec3 r0 = pd_v3(a[0][0], a[0][1], a[0][2]), r1 = pd_v3(a[1][0], a[1][1], a[1][2]),
         r2 = pd_v3(a[2][0], a[2][1], a[2][2]);
  double det = pd_v3_dot(r0, pd_v3_cross(r1, r2));
  pdVec3 x = pd_v3(pd_v3_dot(into, pd_v3_cross(r1, r2)), pd_v3_dot(r0, pd_v3_cross(into, r2)),
                   pd_v3_dot(r0, pd_v3_cross(r1, into)));
  return det / pd_v3_dot(into, x);
}

// The overlap pair (i, j) may reach, in δ_max. Eq. (11) sizes the pair's springs, k_s = m_pair vmax² / δ_max², so
// that the pair's bodies alone, closing at vmax, stop at δ_max: PD_SOAK_PENETRATION_LIMIT is that with the margin
// for the scene's vmax estimate (hard cases). Third bodies pressing on the pair make its springs stop more mass: they
// store the kinetic energy of the closing motion along the pair's normal n of all that moves with either side,
// ½ M v² with M = M_i M_j / (M_i + M_j), and deflect by δ_max √(M / m_pair) v / vmax. So the limit is
// plain √(M / m_pair), plain being PD_SOAK_PENETRATION_LIMIT unless the run sets its own, with M_i (M_j alike) the
// mass moving with i when i closes on j along −n at unit speed:
// - a third body k presses on i with F_k, the net force of its contacts on i (springs and friction). A contact
//   transmits force along F_k only, so k has to follow i along u_k = F_k / |F_k| alone (it slides freely across it),
//   and only if F_k presses i towards j (cos θ_k = −u_k · n > 0): a body pulling away or pressing sideways stores
//   nothing in the pair's springs;
// - while the pair's contact sticks, i moves along −n (relative to j) and k follows at cos θ_k: M_i = m_i +
//   Σ_k m_k cos²θ_k, the pushing force projected on the pair's normal;
// - while it slides, i may also slide out sideways, and by Kelvin's theorem (an impulsive motion under constraints
//   has the least kinetic energy they allow) M_i is the least of wᵀ A w over i's velocities w with −w · n = 1,
//   A = m_i 1 + Σ_k m_k u_k u_kᵀ: 1 / (nᵀ A⁻¹ n). One pusher gives m_i + m_k cos²θ m_i / (m_i + m_k sin²θ): m_i +
//   m_k pressing along the normal, m_i pressing sideways, m_i / sin²θ for an immovable one (i squeezed out).
// Bodies are taken as points (leaving their turning out can only raise the least energy: a generous bound), and
// only the direct pushers count (a pusher's own pushers are not followed: a strict bound). The limit grows only
// while the pair's own contacts carry the overlap (their largest normal force at least k_n times the overlap beyond
// the plain limit), and n and stick are that contact's: an overlap that no contact resists, or one a contact reads
// at a fraction of its depth, is a fault of the contact search whatever the load.
static double pair_limit(const pdModel* m, const pdState* s, int i, int j, double depthOverDelta, double plain) {
  if (!(depthOverDelta > plain)) return plain;
  pdPairContact pair = pd_model_pair_contact(m, i, j);
  double pushed = 0.0;
  pdVec3 outOfJ = {0, 0, 0};  // the carrying contact's normal, from j into i
  bool held = false;          // and whether it sticks
  int n = pd_state_contact_count(s);
  pdVec3* onI = calloc((size_t)m->bodyCount * 2, sizeof *onI);  // each third body's net force on i, then on j
  if (!onI) abort();
  pdVec3* onJ = onI + m->bodyCount;
  for (int c = 0; c < n; ++c) {
    pdContactReport r = pd_state_contact(s, c);
    pdVec3 onA = pd_v3_muladd(r.ft, r.fn, r.normal);
    if ((r.bodyA == i && r.bodyB == j) || (r.bodyA == j && r.bodyB == i)) {
      if (r.fn > pushed) pushed = r.fn, outOfJ = r.bodyA == i ? r.normal : pd_v3_scale(r.normal, -1.0), held = !r.slip;
      continue;
    }
    for (int side = 0; side < 2; ++side) {
      int on = side ? r.bodyB : r.bodyA, k = side ? r.bodyA : r.bodyB;
      pdVec3 force = side ? pd_v3_scale(onA, -1.0) : onA;
      if (on == i) onI[k] = pd_v3_add(onI[k], force);
      if (on == j) onJ[k] = pd_v3_add(onJ[k], force);
    }
  }
  double beyond = (depthOverDelta - plain) * pair.deltaMax;
  double limit = plain;
  if (pushed > 0.0 && pushed >= pair.kn * beyond) {
    double mi = mass_moving_with(m, i, pd_v3_scale(outOfJ, -1.0), onI, held);
    double mj = mass_moving_with(m, j, outOfJ, onJ, held);
    double moving = isinf(mi) ? mj : isinf(mj) ? mi : mi * mj / (mi + mj);
    if (moving > pair.massPair) limit *= sqrt(moving / pair.massPair);
  }
  free(onI);
  return limit;
}

// Deepest overlap of any two bodies over the pair's δ_max. With w->soft, each pair's overlap is also judged against
// its limit (pair_limit): the worst in w->worst, named (with `where`) in w->worstPair.
static double deepest_overlap(const pdModel* m, const pdState* s, watch* w, const char* where) {
  double deepest = 0.0;
  for (int i = 0; i < m->bodyCount; ++i)
    for (int j = i + 1; j < m->bodyCount; ++j) {
      const pdBody *a = &m->bodies[i], *b = &m->bodies[j];
      if (a->fixed && b->fixed) continue;
      pdBodyState sa = pd_state_body(m, s, i), sb = pd_state_body(m, s, j);
      if (pd_v3_norm(pd_v3_sub(sa.x, sb.x)) > a->radius + b->radius) continue;
      pdMat3 ra = pd_quat_to_mat3(sa.q), rb = pd_quat_to_mat3(sb.q);
      pdSatResult sat;
      if (!pd_interference(&a->shape, sa.x, &ra, &b->shape, sb.x, &rb, PD_SAT_MIN_DEPTH, NULL, &sat)) continue;
      double ratio = sat.depth / pd_model_pair_delta_max(m, i, j);
      deepest = fmax(deepest, ratio);
      if (!w->soft || !(ratio > w->limit)) continue;
      double limit = pair_limit(m, s, i, j, ratio, w->limit);
      if (ratio / limit > w->worst) {
        w->worst = ratio / limit, w->worstDepth = ratio, w->worstLimit = limit;
        snprintf(w->worstPair, sizeof w->worstPair, "%.40s and %.40s at t = %.6g s%s", a->name, b->name, s->t, where);
      }
    }
  return deepest;
}

static bool finite_state(const pdModel* m, const pdState* s) {
  for (int k = 0; k < m->movingCount; ++k) {
    pdBodyState b = pd_state_body(m, s, m->movingBodies[k]);
    if (!pd_v3_isfinite(b.x) || !pd_v3_isfinite(b.v) || !pd_v3_isfinite(b.w) || !isfinite(b.q.w) || !isfinite(b.q.x) ||
        !isfinite(b.q.y) || !isfinite(b.q.z))
      return false;
  }
  return true;
}

static bool observe(const pdModel* m, const pdState* s, void* user) {
  watch* w = user;
  pdSoakResult* o = w->out;
  o->simulated = s->t;
  if (!finite_state(m, s) || !isfinite(pd_state_energy(m, s))) {
    w->nonFinite = true;
    return false;
  }
  double e = pd_state_energy(m, s);
  if (!w->started) {
    w->started = true;
    w->e0 = e;
    w->p0 = momentum(m, s, &w->momentumScale);
  }
  if (w->e0 > 0.0) o->energyGain = fmax(o->energyGain, (e - w->e0) / w->e0);
  double depth = deepest_overlap(m, s, w, "");
  o->penetrationSampled = fmax(o->penetrationSampled, depth);
  o->penetration = fmax(o->penetration, depth);
  if (w->scene->kind == pd_soakFree && w->momentumScale > 0.0)
    o->momentumError =
        fmax(o->momentumError, pd_v3_norm(pd_v3_sub(momentum(m, s, NULL), w->p0)) / w->momentumScale);
  if (pd_wall_seconds() - w->wall0 > w->budget) {
    w->overBudget = true;
    return false;
  }
  return true;
}

// The step observer (polydyn/state.h): the overlap, the energy and (free scenes) the momentum of the system stepped
// (the scene, or one island over a sync interval) at every accepted step; its bodies' names and δ_max are the
// scene's. The energy and momentum are compared with the stretch's start (the samples compare the scene's with t = 0).
static void observe_step(const pdModel* m, const pdState* s, bool start, void* user) {
  watch* w = user;
  pdSoakResult* o = w->out;
  if (!finite_state(m, s) || !isfinite(pd_state_energy(m, s))) {
    w->nonFinite = true;
    return;
  }
  double e = pd_state_energy(m, s);
  bool free = w->scene->kind == pd_soakFree;
  if (start) {
    w->stretchE0 = e;
    if (free) w->stretchP0 = momentum(m, s, NULL);
    return;
  }
  if (w->e0 > 0.0) o->energyGain = fmax(o->energyGain, (e - w->stretchE0) / w->e0);
  // an island touches no other within its sync interval: its own momentum holds over the stretch
  if (free && w->momentumScale > 0.0)
    o->momentumError =
        fmax(o->momentumError, pd_v3_norm(pd_v3_sub(momentum(m, s, NULL), w->stretchP0)) / w->momentumScale);
  o->penetration = fmax(o->penetration, deepest_overlap(m, s, w, " (an accepted step)"));
}

bool pd_soak_engine_is_soft(const char* engine, pdIslands* islands) {
  *islands = PD_ISLANDS_DEFAULT;
  if (strcmp(engine, "soft-islands-off") == 0) *islands = pd_islandsOff;
  return *islands == pd_islandsOff || strcmp(engine, "soft") == 0;
}

// The run itself (in the child process).
static void run_here(const pdSoakScene* scene, const char* engine, const pdSoakRunOptions* run, pdSoakResult* o) {
  pdError err = {0};
  pdScene* parsed = pd_scene_parse_buffer("soak.scene", scene->text, strlen(scene->text), &err);
  pdModel* m = parsed ? pd_model_compile(parsed, &err) : NULL;
  pd_scene_free(parsed);
  if (!m) {
    // an overlap scene must be refused; any other refusal is a finding
    o->status = scene->kind == pd_soakOverlap ? pd_soakRefused : pd_soakFailed;
    snprintf(o->message, sizeof o->message, "refused: %d:%d: %.180s", err.line, err.col, err.message);
    return;
  }
  if (scene->kind == pd_soakOverlap) {
    o->status = pd_soakFailed;
    snprintf(o->message, sizeof o->message, "two boxes overlapping by 5-30 %% of the smaller were accepted");
    pd_model_free(m);
    return;
  }
  watch w = {.scene = scene,
             .budget = run->budgetSeconds,
             .wall0 = pd_wall_seconds(),
             .out = o,
             .limit = run->penetrationLimit > 0.0 ? run->penetrationLimit : PD_SOAK_PENETRATION_LIMIT};
  bool completed = false;
  pdIslands islands;
  bool soft = pd_soak_engine_is_soft(engine, &islands);
  w.soft = soft;
  if (soft) {
    pdStateOptions options = pd_state_options_default();
    options.islands = islands;
    options.onsets = run->onsets;
    if (run->everyStep) options.stepObserver = observe_step, options.stepUser = &w;
    pdState* s = pd_state_create(m, &options);
    completed = pd_advance(m, s, m->settings.tend, observe, &w);
    completed = completed && !s->failed;
    o->steps = s->count.accepted;
    if (s->failed) snprintf(w.broke, sizeof w.broke, "the integration failed at t = %.6g s (step at its minimum)", s->t);
    pd_state_free(s);
  } else {
    const pdRefAdapter* adapter = pd_ref_adapter(engine);
    if (!adapter) {
      o->status = pd_soakNotBuilt;
      snprintf(o->message, sizeof o->message, "%s is not in this build", engine);
      pd_model_free(m);
      return;
    }
    pdRefOptions options = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP};
    pdRefRunStats stats = {0};
    bool ok = pd_ref_run(m, adapter, &options, NULL, observe, &w, &stats, &err);
    o->steps = stats.steps;
    if (!ok && stats.refused) {
      o->status = pd_soakRefused;
      snprintf(o->message, sizeof o->message, "%.200s", err.message);
      pd_model_free(m);
      return;
    }
    completed = ok && stats.completed;
    if (!completed && !w.overBudget && !w.nonFinite)
      snprintf(w.broke, sizeof w.broke, "%.180s", err.message[0] ? err.message : "the engine produced a non-finite state");
  }
  o->wallSeconds = pd_wall_seconds() - w.wall0;
  if (w.nonFinite) snprintf(w.broke, sizeof w.broke, "a non-finite number at t = %.6g s", o->simulated);
  // the invariants of the soft model (the reference engines' rigid contacts are shown, not judged)
  if (!w.broke[0] && soft && w.worst > 1.0)
    snprintf(w.broke, sizeof w.broke, "penetration %.3g delta_max (limit %.3g): %.150s; %.3g at the samples",
             w.worstDepth, w.worstLimit, w.worstPair, o->penetrationSampled);
  if (!w.broke[0] && soft && scene->dissipative && o->energyGain > PD_SOAK_ENERGY_GAIN_REL)
    snprintf(w.broke, sizeof w.broke, "energy rose %.3g of E(0) in a dissipative scene (limit %g)", o->energyGain,
             PD_SOAK_ENERGY_GAIN_REL);
  if (!w.broke[0] && soft && o->momentumError > PD_SOAK_MOMENTUM_REL)
    snprintf(w.broke, sizeof w.broke, "momentum changed by %.3g of sum m|v| (limit %g)", o->momentumError,
             PD_SOAK_MOMENTUM_REL);
  if (w.broke[0]) {
    o->status = pd_soakFailed;
    snprintf(o->message, sizeof o->message, "%s", w.broke);
  } else if (w.overBudget) {
    o->status = pd_soakOverBudget;
    snprintf(o->message, sizeof o->message, "stopped at t = %.6g s of %.6g s after %.3g s (budget)", o->simulated,
             m->settings.tend, o->wallSeconds);
  } else {
    o->status = completed ? pd_soakOk : pd_soakFailed;
    if (!completed) snprintf(o->message, sizeof o->message, "stopped at t = %.6g s", o->simulated);
  }
  pd_model_free(m);
}

// A hard limit over the budget (the observer sees only samples: one sample interval may not end).
#define SOAK_HARD_LIMIT_FACTOR 3.0

void pd_soak_run(const pdSoakScene* scene, const char* engine, const pdSoakRunOptions* options, pdSoakResult* out) {
  memset(out, 0, sizeof *out);
  int fds[2];
  if (pipe(fds) != 0) {
    out->status = pd_soakFailed;
    snprintf(out->message, sizeof out->message, "pipe: %s", strerror(errno));
    return;
  }
  fflush(NULL);
  double t0 = pd_wall_seconds();
  pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    out->status = pd_soakFailed;
    snprintf(out->message, sizeof out->message, "fork: %s", strerror(errno));
    return;
  }
  if (pid == 0) {
    close(fds[0]);
    alarm((unsigned)ceil(SOAK_HARD_LIMIT_FACTOR * options->budgetSeconds + 1.0));
    pdSoakResult r;
    memset(&r, 0, sizeof r);
    run_here(scene, engine, options, &r);
    const char* p = (const char*)&r;
    size_t left = sizeof r;
    while (left > 0) {
      ssize_t n = write(fds[1], p, left);
      if (n <= 0) _exit(3);
      p += n, left -= (size_t)n;
    }
    _exit(0);
  }
  close(fds[1]);
  char* p = (char*)out;
  size_t got = 0;
  while (got < sizeof *out) {
    ssize_t n = read(fds[0], p + got, sizeof *out - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += (size_t)n;
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (got == sizeof *out && WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  memset(out, 0, sizeof *out);
  out->wallSeconds = pd_wall_seconds() - t0;
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
    out->status = pd_soakOverBudget;
    snprintf(out->message, sizeof out->message, "killed at the hard limit, %.3g s (no sample within it)",
             out->wallSeconds);
  } else {
    out->status = pd_soakFailed;
    if (WIFSIGNALED(status))
      snprintf(out->message, sizeof out->message, "crashed: signal %d (%s)", WTERMSIG(status), strsignal(WTERMSIG(status)));
    else
      snprintf(out->message, sizeof out->message, "the run's process exited with status %d", WEXITSTATUS(status));
  }
}
