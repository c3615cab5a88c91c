// polydyn refcheck — the oracle's shapes: specs written as scene object commands, the seeded random
// generator, and random pairs posed near touching (pdref/oracle.h).
//
// Design
// - A spec is parsed by the scene parser itself (as a one-object scene), so a spec means exactly what the
//   same words mean in a scene file, and a bad spec gets the parser's message. The polyhedron is then put
//   in the body frame the model uses (origin at the centre of mass, object axes: pd_model_compile does
//   the same three steps), so the poses of trajectory.csv apply to it unchanged and a scene body rebuilt
//   from its spec is the model's polyhedron bit for bit.
// - Random dimensions are written with 6 significant digits and read back, so the spec in the CSV is
//   short and rebuilds the very shape that was checked.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interference.h"
#include "pdref/oracle.h"
#include "scene_shape.h"

// ---------------------------------------------------------------- specs

static const char* const kindWords[] = {"cube", "prism", "tprism", "sphere", "hull"};

bool pd_oracle_shape_parse(const char* spec, pdOracleShape* out, char* why, int whySize) {
  PD_ASSERT(spec != NULL && out != NULL);
  memset(out, 0, sizeof *out);
  if (strpbrk(spec, "\n\r#\\")) {
    snprintf(why, (size_t)whySize, "a shape is one line without '#' or '\\'");
    return false;
  }
  // the kind word, then NAME and COLOR inserted for the scene parser
  size_t skip = strspn(spec, " \t"), len = strcspn(spec + skip, " \t");
  bool known = false;
  for (size_t i = 0; i < sizeof kindWords / sizeof *kindWords; ++i)
    known = known || (strlen(kindWords[i]) == len && strncmp(spec + skip, kindWords[i], len) == 0);
  if (!known) {
    snprintf(why, (size_t)whySize, "unknown shape '%.*s' (cube, prism, tprism, sphere or hull)", (int)(len < 40 ? len : 40),
             spec + skip);
    return false;
  }
  size_t n = strlen(spec) + 8;
  char* text = malloc(n);
  PD_ASSERT(text != NULL);
  snprintf(text, n, "%.*s _ _%s\n", (int)len, spec + skip, spec + skip + len);
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer("shape", text, strlen(text), &err);
  free(text);
  if (!scene) {
    snprintf(why, (size_t)whySize, "%s", err.message);
    return false;
  }
  PD_ASSERT(scene->objectCount == 1);
  // body frame as in pd_model_compile: the centre of mass does not depend on the density
  pdMassProperties mp;
  pdError shapeErr = {0};
  bool ok = pd_scene_object_shape(&scene->objects[0], &out->poly, &shapeErr);
  if (ok && !pd_mass_properties(&out->poly, 1000.0, &mp, &shapeErr)) {
    pd_polyhedron_free(&out->poly);
    ok = false;
  }
  if (!ok) snprintf(why, (size_t)whySize, "%s", shapeErr.message);
  pd_scene_free(scene);
  if (!ok) return false;
  pd_polyhedron_translate(&out->poly, pd_v3_scale(mp.centroid, -1.0));
  n = strlen(spec) + 1;
  out->spec = malloc(n);
  PD_ASSERT(out->spec != NULL);
  memcpy(out->spec, spec, n);
  return true;
}

void pd_oracle_shape_free(pdOracleShape* s) {
  pd_polyhedron_free(&s->poly);
  free(s->spec);
  memset(s, 0, sizeof *s);
}

// A growing string (specs of hulls can be long).
typedef struct text {
  char* s;
  size_t len, cap;
} text;

static void text_put(text* t, const char* s) {
  size_t n = strlen(s);
  if (t->len + n + 1 > t->cap) {
    t->cap = 2 * (t->len + n + 1);
    t->s = realloc(t->s, t->cap);
    PD_ASSERT(t->s != NULL);
  }
  memcpy(t->s + t->len, s, n + 1);
  t->len += n;
}

// Appends " " and v formatted with fmt (e.g. "%.17g").
static void text_num(text* t, const char* fmt, double v) {
  char buf[40] = " ";
  snprintf(buf + 1, sizeof buf - 1, fmt, v);
  text_put(t, buf);
}

char* pd_oracle_object_spec(const pdSceneObject* o) {
  PD_ASSERT(o != NULL && (int)o->kind >= 0 && (int)o->kind < 5);
  text t = {NULL, 0, 0};
  text_put(&t, kindWords[o->kind]);
  if (o->kind == pd_primHull) {
    for (int i = 0; i < 3 * o->pointCount; ++i) text_num(&t, "%.17g", o->points[i]);
    return t.s;
  }
  if (o->kind != pd_primCube) text_num(&t, "%.0f", (double)o->n);
  for (int k = 0; k < 3; ++k) text_num(&t, "%.17g", o->scale[k]);
  if (o->kind == pd_primTprism) text_num(&t, "%.17g", o->taper);
  return t.s;
}

// ---------------------------------------------------------------- random numbers

// splitmix64 (Steele, Lea & Flood 2014): spreads a seed over the generator's 256 bits
static uint64_t splitmix64(uint64_t* x) {
  uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

void pd_oracle_rng_seed(pdOracleRng* g, uint64_t seed) {
  for (int i = 0; i < 4; ++i) g->s[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

// xoshiro256** (Blackman & Vigna 2018)
uint64_t pd_oracle_rng_next(pdOracleRng* g) {
  uint64_t* s = g->s;
  uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return result;
}

double pd_oracle_rng_uniform(pdOracleRng* g) { return (double)(pd_oracle_rng_next(g) >> 11) * 0x1.0p-53; }

static double range(pdOracleRng* g, double lo, double hi) { return lo + (hi - lo) * pd_oracle_rng_uniform(g); }

// ---------------------------------------------------------------- random shapes and poses

// A length of 0.1 … 2 m, log-uniform.
static double random_length(pdOracleRng* g) { return pow(10.0, range(g, -1.0, log10(2.0))); }

// Appends each value with 6 significant digits.
static void add_numbers(text* t, const double* v, int n) {
  for (int i = 0; i < n; ++i) text_num(t, "%.6g", v[i]);
}

static void random_shape(pdOracleRng* g, pdOracleShape* out) {
  for (;;) {
    text t = {NULL, 0, 0};
    double dims[3] = {random_length(g), random_length(g), random_length(g)};
    int kind = (int)(5.0 * pd_oracle_rng_uniform(g));
    int sides = 3 + (int)(10.0 * pd_oracle_rng_uniform(g));
    double u = pd_oracle_rng_uniform(g);
    switch (kind) {
      case 0:
        text_put(&t, "cube");
        add_numbers(&t, dims, 3);
        break;
      case 1:
        text_put(&t, "prism");
        text_num(&t, "%.0f", sides);
        add_numbers(&t, dims, 3);
        break;
      case 2:
        text_put(&t, "tprism");
        text_num(&t, "%.0f", sides);
        add_numbers(&t, dims, 3);
        text_num(&t, "%.6g", range(g, 0.1, 1.0));
        break;
      case 3:
        // levels 0, 1, 2 equally, level 3 (642 vertices) one time in ten: it dominates the cost
        text_put(&t, "sphere");
        text_num(&t, "%.0f", u < 0.3 ? 0 : u < 0.6 ? 1 : u < 0.9 ? 2 : 3);
        add_numbers(&t, dims, 3);
        break;
      default: {
        int count = 6 + (int)(25.0 * u);
        text_put(&t, "hull");
        for (int i = 0; i < count; ++i) {
          double p[3] = {dims[0] * range(g, -0.5, 0.5), dims[1] * range(g, -0.5, 0.5), dims[2] * range(g, -0.5, 0.5)};
          add_numbers(&t, p, 3);
        }
        break;
      }
    }
    char why[256];
    bool ok = pd_oracle_shape_parse(t.s, out, why, sizeof why);
    free(t.s);
    if (ok) return;
    // a degenerate random hull (all points nearly coplanar): draw again
  }
}

static pdVec3 random_direction(pdOracleRng* g) {
  for (;;) {
    pdVec3 d = {range(g, -1, 1), range(g, -1, 1), range(g, -1, 1)};
    double n = pd_v3_norm(d);
    if (n > 0.1 && n <= 1.0) return pd_v3_scale(d, 1.0 / n);
  }
}

// uniform on the rotations: a uniform point of the 4-ball's shell, by rejection
static pdQuat random_rotation(pdOracleRng* g) {
  for (;;) {
    pdQuat q = {range(g, -1, 1), range(g, -1, 1), range(g, -1, 1), range(g, -1, 1)};
    double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (n > 0.1 && n <= 1.0) return pd_quat_normalize(q);
  }
}

static pdVec3 vertex_average(const pdPolyhedron* p) {
  pdVec3 c = {0, 0, 0};
  for (int i = 0; i < p->vertexCount; ++i) c = pd_v3_add(c, p->vertices[i]);
  return pd_v3_scale(c, 1.0 / p->vertexCount);
}

static double radius_about(const pdPolyhedron* p, pdVec3 c) {
  double r = 0.0;
  for (int i = 0; i < p->vertexCount; ++i) r = fmax(r, pd_v3_norm(pd_v3_sub(p->vertices[i], c)));
  return r;
}

// B's origin when its vertex average sits at `target`.
static pdVec3 origin_for(const pdOracleBody* B, pdVec3 avgB, pdVec3 target) {
  return pd_v3_sub(target, pd_quat_rotate(B->q, avgB));
}

// Our minimum depth with B's vertex average at cA + s·w; *slope = −d(depth)/ds along the best axis.
static double depth_at(const pdOracleBody* A, pdOracleBody* B, pdVec3 avgB, pdVec3 cA, pdVec3 w, double s,
                       double* slope) {
  B->x = origin_for(B, avgB, pd_v3_muladd(cA, s, w));
  pdMat3 RA = pd_quat_to_mat3(A->q), RB = pd_quat_to_mat3(B->q);
  pdSatResult r;
  pd_interference(A->shape, A->x, &RA, B->shape, B->x, &RB, PD_SAT_MIN_DEPTH, NULL, &r);
  *slope = pd_v3_dot(r.axis, w);
  return r.depth;
}

// The distance s along w at which B touches A. The minimum depth is min over the Minkowski faces of
// (o_f − s·u_f·w): concave and piecewise linear in s, so Newton's method from the separated side steps
// monotonically onto the root, each step zeroing the current best axis; a bisection of the bracket
// [overlapping, separated] catches steps that leave it (an axis nearly perpendicular to w).
static double touching_distance(const pdOracleBody* A, pdOracleBody* B, pdVec3 avgB, pdVec3 cA, pdVec3 w, double rsum) {
  double lo = 0.0, hi = 1.01 * rsum, s = hi;  // the centres coincide at 0 (overlap); apart at hi
  for (int i = 0; i < 200; ++i) {
    double slope, d = depth_at(A, B, avgB, cA, w, s, &slope);
    if (fabs(d) <= 1e-15 * rsum) return s;
    if (d >= 0.0)
      lo = s;
    else
      hi = s;
    if (hi - lo <= 1e-15 * rsum) break;
    double next = slope > 1e-3 ? s + d / slope : -1.0;
    s = next > lo && next < hi ? next : 0.5 * (lo + hi);
  }
  return s;
}

void pd_oracle_random_pair(pdOracleRng* g, pdOraclePair* out) {
  PD_ASSERT(g != NULL && out != NULL);
  memset(out, 0, sizeof *out);
  random_shape(g, &out->a);
  random_shape(g, &out->b);
  pdOracleBody* A = &out->bodyA;
  pdOracleBody* B = &out->bodyB;
  A->shape = &out->a.poly;
  B->shape = &out->b.poly;
  A->x = (pdVec3){range(g, -1, 1), range(g, -1, 1), range(g, -1, 1)};
  A->q = random_rotation(g);
  B->q = random_rotation(g);
  pdVec3 w = random_direction(g);
  pdVec3 avgA = vertex_average(A->shape), avgB = vertex_average(B->shape);
  double rsum = radius_about(A->shape, avgA) + radius_about(B->shape, avgB);
  pdVec3 cA = pd_v3_add(A->x, pd_quat_rotate(A->q, avgA));
  double u = pd_oracle_rng_uniform(g), s;
  if (u < 0.10) {
    out->placement = pd_placeFar;
    s = rsum * range(g, 0.2, 1.05);
  } else {
    s = touching_distance(A, B, avgB, cA, w, rsum);
    if (u < 0.15) {
      out->placement = pd_placeTouch;
    } else {
      out->placement = pd_placeNear;
      out->offset = (pd_oracle_rng_uniform(g) < 0.5 ? -1.0 : 1.0) * rsum * pow(10.0, range(g, -8.0, -1.3));
      s += out->offset;
    }
  }
  B->x = origin_for(B, avgB, pd_v3_muladd(cA, s, w));
}

void pd_oracle_pair_free(pdOraclePair* p) {
  pd_oracle_shape_free(&p->a);
  pd_oracle_shape_free(&p->b);
}
