// Exact mass properties of convex polyhedra against closed forms: boxes, regular prisms, the unit
// corner tetrahedron, frusta, geodesic spheres; invariance under point order, rotation and
// translation; the principal frame; and the body frame produced by pd_model_compile.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "test_random.h"

#include "polydyn/model.h"
#include "polydyn/polyhedron.h"
#include "polydyn/scene.h"
#include "polydyn/vecmath.h"

// Closed forms against a sum of a few hundred tetrahedra: each term is rounded to ~1e-16 and the
// vertices themselves carry one rounding (cos/sin, scales), so agreement to 1e-12 leaves a margin of
// ~1e3 over the expected roundoff while any error in a formula shows up at 1e-3 or worse.
#define REL_TOL 1e-12
// A box's products of inertia cancel by symmetry; the residual is the roundoff of the sum (~1e-16
// of the trace per term, a few dozen terms).
#define BOX_PRODUCT_TOL_REL 1e-15
// Quantities that vanish by symmetry (centroids, products of inertia) for shapes whose vertices come
// from cos/sin: absolute, relative to the size (or to the inertia trace).
#define ZERO_TOL_REL 1e-12
// Geodesic spheres are icosahedrally symmetric, so their inertia is isotropic; the vertices carry
// a rounding each, far below this.
#define SPHERE_ISOTROPY_TOL_REL 1e-9
// Level 3 (1280 faces) approximates the ball: its I/(m r²) must be within 1 % of 2/5.
#define SPHERE_LEVEL3_TOL_REL 0.01

#define PI 3.14159265358979323846

// ---------------------------------------------------------------- helpers

static void expect_rel(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol * fabs(expected)))
    fail_msg("%s: %.17g, expected %.17g (relative error %.3g > %.3g)", what, actual, expected,
             fabs(actual - expected) / fabs(expected), tol);
}

static void expect_abs(double actual, double expected, double tol, const char* what) {
  if (!(fabs(actual - expected) <= tol))
    fail_msg("%s: %.17g, expected %.17g (error %.3g > %.3g)", what, actual, expected, fabs(actual - expected), tol);
}

static double trace3(const pdMat3* a) { return a->m[0][0] + a->m[1][1] + a->m[2][2]; }

static void mass_of(const pdPolyhedron* p, double density, pdMassProperties* mp) {
  pdError why = {0};
  if (!pd_mass_properties(p, density, mp, &why)) fail_msg("pd_mass_properties: %s", why.message);
}


// Points on (every third) and inside the ball of radius 0.5, rejection-sampled from the cube.
static void ball_points(double* pts, int n, uint64_t seed) {
  lcg g = {seed};
  for (int i = 0; i < n; ++i) {
    pdVec3 d;
    double len;
    do {
      d = (pdVec3){lcg_range(&g, -1, 1), lcg_range(&g, -1, 1), lcg_range(&g, -1, 1)};
      len = pd_v3_norm(d);
    } while (len < 0.1 || len > 1.0);
    double r = i % 3 == 0 ? 0.5 : 0.5 * lcg_range(&g, 0.0, 0.999);
    d = pd_v3_scale(d, r / len);
    pts[3 * i] = d.x, pts[3 * i + 1] = d.y, pts[3 * i + 2] = d.z;
  }
}

// A rotation from a random unit quaternion.
static pdMat3 random_rotation(lcg* g) {
  for (;;) {
    pdQuat q = {lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1), lcg_range(g, -1, 1)};
    double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (n > 0.1 && n <= 1.0) return pd_quat_to_mat3(pd_quat_normalize(q));
  }
}

// Polar second moment per unit area of a regular n-gon of circumradius R about its centre: the
// n-gon is n triangles (0, p, q) with |p| = |q| = R and apex angle θ = 2π/n; for such a triangle
// ∫ x xᵀ dA = A/12 (p pᵀ + q qᵀ + (p+q)(p+q)ᵀ), whose trace is A/12 (R² + R² + 2R² + 2R² cos θ)
// = A R²/6 (2 + cos θ) = A R²/6 (1 + 2cos²(π/n)). Check: a square (R = a/√2) gives a²/6. ✓
static double ngon_polar_per_area(int n, double R) { return R * R / 6.0 * (2.0 + cos(2.0 * PI / n)); }
static double ngon_area(int n, double R) { return 0.5 * n * R * R * sin(2.0 * PI / n); }

// ---------------------------------------------------------------- boxes

static void test_box_volume_mass_and_inertia_match_closed_forms(void** state) {
  (void)state;
  const double boxes[][3] = {{0.1, 0.2, 0.3}, {2, 3, 5}, {1, 1, 1}};
  const double densities[] = {1000.0, 7850.0};
  for (size_t k = 0; k < sizeof boxes / sizeof boxes[0]; ++k)
    for (size_t d = 0; d < sizeof densities / sizeof densities[0]; ++d) {
      double a = boxes[k][0], b = boxes[k][1], c = boxes[k][2], rho = densities[d];
      pdPolyhedron p;
      pdError why = {0};
      assert_true(pd_polyhedron_cube(&p, boxes[k], &why));
      pdMassProperties mp;
      mass_of(&p, rho, &mp);
      double m = rho * a * b * c;
      expect_rel(mp.volume, a * b * c, REL_TOL, "box volume");
      expect_rel(mp.mass, m, REL_TOL, "box mass");
      expect_rel(mp.inertia.m[0][0], m / 12.0 * (b * b + c * c), REL_TOL, "box Ixx");
      expect_rel(mp.inertia.m[1][1], m / 12.0 * (a * a + c * c), REL_TOL, "box Iyy");
      expect_rel(mp.inertia.m[2][2], m / 12.0 * (a * a + b * b), REL_TOL, "box Izz");
      double tr = trace3(&mp.inertia);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (i != j) expect_abs(mp.inertia.m[i][j], 0.0, BOX_PRODUCT_TOL_REL * tr, "box product of inertia");
      double size = fmax(a, fmax(b, c));
      expect_abs(mp.centroid.x, 0.0, ZERO_TOL_REL * size, "box centroid x");
      expect_abs(mp.centroid.y, 0.0, ZERO_TOL_REL * size, "box centroid y");
      expect_abs(mp.centroid.z, 0.0, ZERO_TOL_REL * size, "box centroid z");
      pd_polyhedron_free(&p);
    }
}

// ---------------------------------------------------------------- regular prisms

static void test_regular_prism_area_and_inertia_match_closed_forms(void** state) {
  (void)state;
  const int sides[] = {3, 6, 64};
  const double R = 0.7, h = 1.3, rho = 2700.0;
  for (size_t k = 0; k < sizeof sides / sizeof sides[0]; ++k) {
    int n = sides[k];
    pdPolyhedron p;
    pdError why = {0};
    // the primitive is inscribed in the circle of diameter 1, so an xy scale of 2R gives radius R
    assert_true(pd_polyhedron_prism(&p, n, (const double[3]){2 * R, 2 * R, h}, 1.0, &why));
    pdMassProperties mp;
    mass_of(&p, rho, &mp);
    double A = ngon_area(n, R), m = rho * A * h, J = ngon_polar_per_area(n, R);
    expect_rel(mp.volume, A * h, REL_TOL, "prism volume");
    expect_rel(mp.mass, m, REL_TOL, "prism mass");
    expect_rel(mp.inertia.m[2][2], m * R * R / 6.0 * (2.0 + cos(2.0 * PI / n)), REL_TOL, "prism Izz");
    expect_rel(mp.inertia.m[2][2], m * J, REL_TOL, "prism Izz = m J");
    expect_rel(mp.inertia.m[0][0], m * (J / 2.0 + h * h / 12.0), REL_TOL, "prism Ixx");
    expect_rel(mp.inertia.m[1][1], m * (J / 2.0 + h * h / 12.0), REL_TOL, "prism Iyy");
    double tr = trace3(&mp.inertia);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j) expect_abs(mp.inertia.m[i][j], 0.0, ZERO_TOL_REL * tr, "prism product of inertia");
    // the centroid of a regular polygon is its centre, at mid-height
    expect_abs(mp.centroid.x, 0.0, ZERO_TOL_REL * R, "prism centroid x");
    expect_abs(mp.centroid.y, 0.0, ZERO_TOL_REL * R, "prism centroid y");
    expect_abs(mp.centroid.z, 0.0, ZERO_TOL_REL * h, "prism centroid z");
    pd_polyhedron_free(&p);
  }
}

// ---------------------------------------------------------------- the corner tetrahedron

// Tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), by direct integration: V = 1/6, ∫x dV = 1/24, so the
// centroid is (1/4, 1/4, 1/4); ∫x² dV = 1/60 and ∫xy dV = 1/120. With m = ρ/6, about the origin
// Ixx = ρ(1/60 + 1/60) = m/5 and Ixy = −ρ/120 = −m/20; the parallel-axis theorem moves them to the
// centroid: Ixx = m/5 − m(1/16 + 1/16) = 3m/40, Ixy = −m/20 + m/16 = m/80. The tensor is
// m(1/16·1 + 1/80·11ᵀ), so the principal moments are m/16 (twice) and m/16 + 3m/80 = m/10 along (1,1,1).
static void test_corner_tetrahedron_hull_matches_closed_forms(void** state) {
  (void)state;
  const double pts[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double rho = 1200.0;
  pdPolyhedron p;
  pdError why = {0};
  if (!pd_polyhedron_hull(&p, pts, 4, &why)) fail_msg("%s", why.message);
  pdMassProperties mp;
  mass_of(&p, rho, &mp);
  double m = rho / 6.0;
  expect_rel(mp.volume, 1.0 / 6.0, REL_TOL, "tetrahedron volume");
  expect_rel(mp.mass, m, REL_TOL, "tetrahedron mass");
  expect_rel(mp.centroid.x, 0.25, REL_TOL, "tetrahedron centroid x");
  expect_rel(mp.centroid.y, 0.25, REL_TOL, "tetrahedron centroid y");
  expect_rel(mp.centroid.z, 0.25, REL_TOL, "tetrahedron centroid z");
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) expect_rel(mp.inertia.m[i][j], i == j ? 3.0 * m / 40.0 : m / 80.0, REL_TOL, "tet I");
  expect_rel(mp.principal[0], m / 16.0, REL_TOL, "tetrahedron principal 0");
  expect_rel(mp.principal[1], m / 16.0, REL_TOL, "tetrahedron principal 1");
  expect_rel(mp.principal[2], m / 10.0, REL_TOL, "tetrahedron principal 2");
  // the largest moment's axis is ±(1,1,1)/√3
  for (int i = 0; i < 3; ++i) expect_rel(fabs(mp.principalAxes.m[i][2]), 1.0 / sqrt(3.0), REL_TOL, "axis (1,1,1)");
  pd_polyhedron_free(&p);
}

// ---------------------------------------------------------------- frusta

// Frustum of height h from z = −h/2 (section area A1) to z = h/2 (area A2 = t²A1): with s the height
// fraction, the section is A1(1 − (1−t)s)²; ∫ds = (1 + t + t²)/3 gives V = h/3 (A1 + A2 + √(A1A2)),
// and ∫s·(1 − (1−t)s)² ds = (1 + 2t + 3t²)/12 gives the centroid height above the base
// h/4 · (1 + 2t + 3t²)/(1 + t + t²), i.e. z_c = h/4 · (1 + 2t + 3t²)/(1 + t + t²) − h/2.
static double frustum_centroid_z(double h, double t) {
  return h / 4.0 * (1.0 + 2.0 * t + 3.0 * t * t) / (1.0 + t + t * t) - h / 2.0;
}

// Its inertia, with the section at height fraction s scaled by λ = 1 − (1−t)s (area A1λ², polar moment
// per area J1λ², J1 from ngon_polar_per_area): ∫λ⁴ ds = (1 + t + t² + t³ + t⁴)/5, so
// Izz = ρ A1 J1 h (1 + t + t² + t³ + t⁴)/5; in-plane the section is isotropic (J/2 about x and y), and
// ∫ A (u − u_c)² du = A1 h³ ∫ s²λ² ds − V u_c² = A1 h³ (1/3 − k/2 + k²/5) − V u_c² with k = 1 − t and
// u_c the centroid height above the base, so Ixx = Iyy = ρ [A1 J1 h (1 + t + t² + t³ + t⁴)/10 + that].
// The centroid is below the vertex average here, so this checks the parallel-axis step.
static void frustum_inertia(double A1, double J1, double h, double t, double rho, double* ixx, double* izz) {
  double k = 1.0 - t, quartic = (1.0 + t + t * t + t * t * t + t * t * t * t);
  double V = A1 * h * (1.0 + t + t * t) / 3.0, uc = frustum_centroid_z(h, t) + h / 2.0;
  *izz = rho * A1 * J1 * h * quartic / 5.0;
  *ixx = rho * (A1 * J1 * h * quartic / 10.0 + A1 * h * h * h * (1.0 / 3.0 - k / 2.0 + k * k / 5.0) - V * uc * uc);
}

static void test_frustum_volume_centroid_and_inertia_match_closed_forms(void** state) {
  (void)state;
  const int sides[] = {4, 64};
  const double tapers[] = {0.25, 0.5, 0.8, 1.0};
  const double sx = 1.1, h = 0.9;
  for (size_t k = 0; k < sizeof sides / sizeof sides[0]; ++k)
    for (size_t i = 0; i < sizeof tapers / sizeof tapers[0]; ++i) {
      int n = sides[k];
      double t = tapers[i], R = 0.5 * sx;
      pdPolyhedron p;
      pdError why = {0};
      assert_true(pd_polyhedron_prism(&p, n, (const double[3]){sx, sx, h}, t, &why));
      pdMassProperties mp;
      mass_of(&p, 1000.0, &mp);
      double A1 = ngon_area(n, R), A2 = ngon_area(n, t * R);
      if (n == 4) expect_rel(A1, sx * sx / 2.0, REL_TOL, "square of circumradius sx/2 has area sx²/2");
      expect_rel(mp.volume, h / 3.0 * (A1 + A2 + sqrt(A1 * A2)), REL_TOL, "frustum volume");
      double zc = frustum_centroid_z(h, t);
      if (t == 1.0) expect_abs(mp.centroid.z, 0.0, ZERO_TOL_REL * h, "prism centroid z");
      else expect_rel(mp.centroid.z, zc, REL_TOL, "frustum centroid z");
      expect_abs(mp.centroid.x, 0.0, ZERO_TOL_REL * sx, "frustum centroid x");
      expect_abs(mp.centroid.y, 0.0, ZERO_TOL_REL * sx, "frustum centroid y");
      double ixx, izz, rho = 1000.0;
      frustum_inertia(A1, ngon_polar_per_area(n, R), h, t, rho, &ixx, &izz);
      expect_rel(mp.inertia.m[0][0], ixx, REL_TOL, "frustum Ixx");
      expect_rel(mp.inertia.m[1][1], ixx, REL_TOL, "frustum Iyy");
      expect_rel(mp.inertia.m[2][2], izz, REL_TOL, "frustum Izz");
      double tr = trace3(&mp.inertia);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (a != b) expect_abs(mp.inertia.m[a][b], 0.0, ZERO_TOL_REL * tr, "frustum product of inertia");
      pd_polyhedron_free(&p);
    }
}

// ---------------------------------------------------------------- geodesic spheres

// Measured I/(m r²), r = 0.5 (level 0 is the regular icosahedron, whose closed form is
// I = φ²a²m/10 with circumradius r = a·sin 72°, so I/(m r²) = 2φ/(5√5) = 0.289443):
//   level 0: 0.289442719  level 1: 0.365791722  level 2: 0.390944403  level 3: 0.397702987  (2/5 = 0.4)
static void test_geodesic_sphere_inertia_ratio_approaches_two_fifths(void** state) {
  (void)state;
  const double r = 0.5, phi = (1.0 + sqrt(5.0)) / 2.0;
  double previous = 0.0, ratio = 0.0;
  for (int level = 0; level <= 3; ++level) {
    pdPolyhedron p;
    pdError why = {0};
    char label[64];
    assert_true(pd_polyhedron_sphere(&p, level, (const double[3]){1, 1, 1}, &why));
    pdMassProperties mp;
    mass_of(&p, 1000.0, &mp);
    double mean = (mp.principal[0] + mp.principal[1] + mp.principal[2]) / 3.0;
    ratio = mean / (mp.mass * r * r);
    print_message("sphere level %d: I/(m r^2) = %.9f, principal spread %.3g\n", level, ratio,
                  (mp.principal[2] - mp.principal[0]) / mean);
    snprintf(label, sizeof label, "sphere level %d isotropy", level);
    expect_rel(mp.principal[0], mean, SPHERE_ISOTROPY_TOL_REL, label);
    expect_rel(mp.principal[2], mean, SPHERE_ISOTROPY_TOL_REL, label);
    if (level == 0) expect_rel(ratio, 2.0 * phi / (5.0 * sqrt(5.0)), REL_TOL, "icosahedron I/(m r^2)");
    if (!(ratio > previous && ratio < 0.4))
      fail_msg("level %d ratio %.9f does not increase towards 2/5 (previous %.9f)", level, ratio, previous);
    previous = ratio;
    pd_polyhedron_free(&p);
  }
  expect_rel(ratio, 0.4, SPHERE_LEVEL3_TOL_REL, "level 3 I/(m r^2) close to 2/5");
}

// ---------------------------------------------------------------- invariance

enum { invariancePoints = 150 };

static void compare_transformed(const pdMassProperties* a, const pdMassProperties* b, const pdMat3* R, pdVec3 t,
                                double size, const char* label) {
  char what[96];
  snprintf(what, sizeof what, "%s: volume", label);
  expect_rel(b->volume, a->volume, REL_TOL, what);
  snprintf(what, sizeof what, "%s: mass", label);
  expect_rel(b->mass, a->mass, REL_TOL, what);
  for (int k = 0; k < 3; ++k) {
    snprintf(what, sizeof what, "%s: principal moment %d", label, k);
    expect_rel(b->principal[k], a->principal[k], REL_TOL, what);
  }
  pdVec3 c = pd_v3_add(pd_mat3_mulv(R, a->centroid), t);  // centroid' = R c + t
  for (int k = 0; k < 3; ++k) {
    snprintf(what, sizeof what, "%s: centroid %d", label, k);
    expect_abs(pd_v3_get(b->centroid, k), pd_v3_get(c, k), REL_TOL * size, what);
  }
  pdMat3 RT = pd_mat3_transpose(R), tmp = pd_mat3_mul(R, &a->inertia), I = pd_mat3_mul(&tmp, &RT);  // R I Rᵀ
  double tr = trace3(&a->inertia);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      snprintf(what, sizeof what, "%s: inertia %d%d", label, i, j);
      expect_abs(b->inertia.m[i][j], I.m[i][j], REL_TOL * tr, what);
    }
}

static void test_hull_mass_properties_are_invariant_under_order_rotation_and_translation(void** state) {
  (void)state;
  double* pts = malloc(sizeof(double) * 3 * invariancePoints);
  double* other = malloc(sizeof(double) * 3 * invariancePoints);
  assert_non_null(pts);
  assert_non_null(other);
  const double rho = 3100.0, size = 0.5;  // the points lie in the ball of radius 0.5
  const pdVec3 shift = {10, -20, 30};
  lcg g = {2024};
  for (uint64_t seed = 11; seed <= 13; ++seed) {
    ball_points(pts, invariancePoints, seed);
    // stretch the ball so the inertia has three distinct moments and non-zero products
    for (int i = 0; i < invariancePoints; ++i) pts[3 * i] *= 1.7, pts[3 * i + 2] *= 0.6;
    pdPolyhedron p;
    pdError why = {0};
    if (!pd_polyhedron_hull(&p, pts, invariancePoints, &why)) fail_msg("%s", why.message);
    pdMassProperties a;
    mass_of(&p, rho, &a);
    pd_polyhedron_free(&p);

    // the same points in another order (a rotation of the index by 37 and a reversal)
    for (int i = 0; i < invariancePoints; ++i)
      memcpy(other + 3 * i, pts + 3 * ((invariancePoints - 1 - i + 37) % invariancePoints), 3 * sizeof(double));
    if (!pd_polyhedron_hull(&p, other, invariancePoints, &why)) fail_msg("%s", why.message);
    pdMassProperties b;
    mass_of(&p, rho, &b);
    pd_polyhedron_free(&p);
    pdMat3 identity = pd_mat3_identity();
    compare_transformed(&a, &b, &identity, (pdVec3){0, 0, 0}, size, "reordered");

    // the same points in another frame: x' = R x + t
    pdMat3 R = random_rotation(&g);
    for (int i = 0; i < invariancePoints; ++i) {
      pdVec3 x = pd_v3_add(pd_mat3_mulv(&R, (pdVec3){pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}), shift);
      other[3 * i] = x.x, other[3 * i + 1] = x.y, other[3 * i + 2] = x.z;
    }
    if (!pd_polyhedron_hull(&p, other, invariancePoints, &why)) fail_msg("%s", why.message);
    mass_of(&p, rho, &b);
    pd_polyhedron_free(&p);
    compare_transformed(&a, &b, &R, shift, size, "rotated and translated");
  }
  free(pts);
  free(other);
}

// ---------------------------------------------------------------- principal axes

static void check_principal_frame(const pdMassProperties* mp, const char* label) {
  const pdMat3* A = &mp->principalAxes;
  double det = A->m[0][0] * (A->m[1][1] * A->m[2][2] - A->m[1][2] * A->m[2][1]) -
               A->m[0][1] * (A->m[1][0] * A->m[2][2] - A->m[1][2] * A->m[2][0]) +
               A->m[0][2] * (A->m[1][0] * A->m[2][1] - A->m[1][1] * A->m[2][0]);
  char what[96];
  snprintf(what, sizeof what, "%s: det(axes)", label);
  expect_abs(det, 1.0, REL_TOL, what);
  pdMat3 AT = pd_mat3_transpose(A), ATA = pd_mat3_mul(&AT, A), tmp = pd_mat3_mul(&AT, &mp->inertia),
         D = pd_mat3_mul(&tmp, A);
  double tr = trace3(&mp->inertia);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      snprintf(what, sizeof what, "%s: (AᵀA)%d%d", label, i, j);
      expect_abs(ATA.m[i][j], i == j ? 1.0 : 0.0, REL_TOL, what);
      snprintf(what, sizeof what, "%s: (Aᵀ I A)%d%d", label, i, j);
      expect_abs(D.m[i][j], i == j ? mp->principal[i] : 0.0, REL_TOL * tr, what);
    }
  if (!(mp->principal[0] <= mp->principal[1] && mp->principal[1] <= mp->principal[2]))
    fail_msg("%s: principal moments %g %g %g are not ascending", label, mp->principal[0], mp->principal[1],
             mp->principal[2]);
  if (!(mp->principal[0] > 0.0)) fail_msg("%s: principal moments not positive", label);
}

static void test_principal_axes_are_a_rotation_that_diagonalises_inertia(void** state) {
  (void)state;
  lcg g = {5};
  // a 0.1 × 0.2 × 0.3 box in a random orientation: its inertia is full, its moments distinct
  double box[8 * 3];
  pdMat3 R = random_rotation(&g);
  for (int i = 0; i < 8; ++i) {
    pdVec3 x = {(i & 1) ? 0.05 : -0.05, (i & 2) ? 0.1 : -0.1, (i & 4) ? 0.15 : -0.15};
    x = pd_mat3_mulv(&R, x);
    box[3 * i] = x.x, box[3 * i + 1] = x.y, box[3 * i + 2] = x.z;
  }
  double* ball = malloc(sizeof(double) * 3 * invariancePoints);
  assert_non_null(ball);
  ball_points(ball, invariancePoints, 31);
  for (int i = 0; i < invariancePoints; ++i) ball[3 * i + 1] *= 2.5, ball[3 * i + 2] += 0.4 * ball[3 * i];  // shear
  const double tet[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};

  struct {
    const char* label;
    const double* pts;
    int count;
  } hulls[] = {{"rotated box", box, 8}, {"sheared ball", ball, invariancePoints}, {"tetrahedron", tet, 4}};
  for (size_t k = 0; k < sizeof hulls / sizeof hulls[0]; ++k) {
    pdPolyhedron p;
    pdError why = {0};
    if (!pd_polyhedron_hull(&p, hulls[k].pts, hulls[k].count, &why)) fail_msg("%s: %s", hulls[k].label, why.message);
    pdMassProperties mp;
    mass_of(&p, 1000.0, &mp);
    check_principal_frame(&mp, hulls[k].label);
    pd_polyhedron_free(&p);
  }
  // primitives: moments with exact or near ties (cube, sphere, prism) and distinct (tapered box)
  pdPolyhedron p;
  pdError why = {0};
  pdMassProperties mp;
  assert_true(pd_polyhedron_cube(&p, (const double[3]){1, 1, 1}, &why));
  mass_of(&p, 1000.0, &mp);
  check_principal_frame(&mp, "unit cube");
  pd_polyhedron_free(&p);
  assert_true(pd_polyhedron_sphere(&p, 2, (const double[3]){1, 1, 1}, &why));
  mass_of(&p, 1000.0, &mp);
  check_principal_frame(&mp, "sphere level 2");
  pd_polyhedron_free(&p);
  assert_true(pd_polyhedron_prism(&p, 5, (const double[3]){1.5, 0.7, 0.4}, 0.6, &why));
  mass_of(&p, 1000.0, &mp);
  check_principal_frame(&mp, "tapered pentagonal prism");
  pd_polyhedron_free(&p);
  free(ball);
}

// A polyhedron turned inside out (every face walked clockwise) has negative volume: refused.
static void test_inside_out_polyhedron_is_refused(void** state) {
  (void)state;
  pdPolyhedron p;
  pdError why = {0};
  assert_true(pd_polyhedron_cube(&p, (const double[3]){1, 2, 3}, &why));
  for (int f = 0; f < p.faceCount; ++f) {
    int* idx = p.faceVertices + p.faces[f].first;
    for (int i = 0, j = p.faces[f].count - 1; i < j; ++i, --j) {
      int t = idx[i];
      idx[i] = idx[j];
      idx[j] = t;
    }
  }
  pdMassProperties mp;
  why.message[0] = '\0';
  assert_false(pd_mass_properties(&p, 1000.0, &mp, &why));
  assert_non_null(strstr(why.message, "volume"));  // refused for its volume, before any eigen-solving
  pd_polyhedron_free(&p);
}

// ---------------------------------------------------------------- compiled bodies

static void test_compiled_bodies_have_centroid_at_origin_and_tprism_centre_offset(void** state) {
  (void)state;
  const char* text =
      "gravity 0 0 0\n"
      "cube box red 0.3 0.5 0.7\nloc 0 0 0 30 1 2 3\n"
      "tprism frustum blue 6 1.2 1.2 0.8 0.4\nloc 5 0 0\n"
      "tprism square green 4 1 1 2 0.5\nloc 10 0 0 45 0 1 0\nspgrav 7.8\n"
      "sphere ball white 2 1 1 1\nloc 0 5 0\n"
      "hull tet black 0 0 0 1 0 0 0 1 0 0 0 1\nloc 0 10 0\n"
      "hull lopsided grey 3 3 3 3.5 3 3 3 4 3 3 3 5 3.2 3.2 3.1\nloc 0 -5 0\n";
  pdError err;
  memset(&err, 0, sizeof err);
  pdScene* scene = pd_scene_parse_buffer("compile.scene", text, strlen(text), &err);
  if (!scene) fail_msg("parse: %s:%d:%d: %s", err.file, err.line, err.col, err.message);
  pdModel* model = pd_model_compile(scene, &err);
  if (!model) fail_msg("compile: %s:%d:%d: %s", err.file, err.line, err.col, err.message);
  assert_int_equal(model->bodyCount, 6);
  for (int i = 0; i < model->bodyCount; ++i) {
    const pdBody* b = &model->bodies[i];
    pdError why = {0};
    char what[96];
    if (!pd_polyhedron_validate(&b->shape, &why)) fail_msg("%s: %s", b->name, why.message);
    pdMassProperties mp;
    mass_of(&b->shape, b->density, &mp);
    double size = 0.0;
    for (int v = 0; v < b->shape.vertexCount; ++v) size = fmax(size, pd_v3_norm(b->shape.vertices[v]));
    for (int k = 0; k < 3; ++k) {
      snprintf(what, sizeof what, "%s: body-frame centroid %d", b->name, k);
      expect_abs(pd_v3_get(mp.centroid, k), 0.0, ZERO_TOL_REL * size, what);
    }
    snprintf(what, sizeof what, "%s: mass", b->name);
    expect_rel(b->mass, mp.mass, REL_TOL, what);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        snprintf(what, sizeof what, "%s: inertia %d%d", b->name, r, c);
        expect_abs(b->inertia.m[r][c], mp.inertia.m[r][c], REL_TOL * trace3(&mp.inertia), what);
      }
  }
  // frustum: 6 sides, height 0.8, taper 0.4; square: height 2, taper 0.5. The primitive's origin seen
  // from the centre of mass is minus the centroid offset along z.
  const struct {
    int body;
    double h, t;
  } frusta[] = {{1, 0.8, 0.4}, {2, 2.0, 0.5}};
  for (size_t k = 0; k < sizeof frusta / sizeof frusta[0]; ++k) {
    const pdBody* b = &model->bodies[frusta[k].body];
    double zc = frustum_centroid_z(frusta[k].h, frusta[k].t);
    assert_true(zc < 0.0);  // a narrower top puts the centroid below mid-height: the formula must say so
    expect_rel(b->geometricCentre.z, -zc, REL_TOL, "tprism geometricCentre z");
    expect_abs(b->geometricCentre.x, 0.0, ZERO_TOL_REL * frusta[k].h, "tprism geometricCentre x");
    expect_abs(b->geometricCentre.y, 0.0, ZERO_TOL_REL * frusta[k].h, "tprism geometricCentre y");
  }
  // the lopsided hull: geometricCentre = −centroid of its points' hull (computed here directly)
  {
    const double pts[] = {3, 3, 3, 3.5, 3, 3, 3, 4, 3, 3, 3, 5, 3.2, 3.2, 3.1};
    pdPolyhedron p;
    pdError why = {0};
    assert_true(pd_polyhedron_hull(&p, pts, 5, &why));
    pdMassProperties mp;
    mass_of(&p, 1000.0, &mp);
    const pdBody* b = &model->bodies[5];
    for (int k = 0; k < 3; ++k)
      expect_rel(pd_v3_get(b->geometricCentre, k), -pd_v3_get(mp.centroid, k), REL_TOL, "hull geometricCentre");
    pd_polyhedron_free(&p);
  }
  pd_model_free(model);
  pd_scene_free(scene);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box_volume_mass_and_inertia_match_closed_forms),
      cmocka_unit_test(test_regular_prism_area_and_inertia_match_closed_forms),
      cmocka_unit_test(test_corner_tetrahedron_hull_matches_closed_forms),
      cmocka_unit_test(test_frustum_volume_centroid_and_inertia_match_closed_forms),
      cmocka_unit_test(test_geodesic_sphere_inertia_ratio_approaches_two_fifths),
      cmocka_unit_test(test_hull_mass_properties_are_invariant_under_order_rotation_and_translation),
      cmocka_unit_test(test_principal_axes_are_a_rotation_that_diagonalises_inertia),
      cmocka_unit_test(test_inside_out_polyhedron_is_refused),
      cmocka_unit_test(test_compiled_bodies_have_centroid_at_origin_and_tprism_centre_offset),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
