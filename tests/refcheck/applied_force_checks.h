// Checks shared by the ODE and Bullet adapter tests: both apply the scene's `force` the same way (refcheck.h:
// F(t + h/2) held over each step, at the body's force point). Include after cmocka.h, with a compile_text
// helper in the including file.
#pragma once

#include "pdref/refcheck.h"

// A free body in zero gravity under F(t) = F0 + t·Ḟ at its centre of mass, 1000 steps of 1 ms. Semi-implicit
// Euler changes v by h·F(t + h/2)/m per step, the exact impulse of a linear F: v(T) = (F0 T + Ḟ T²/2)/m to the
// round-off of 1000 additions (~1e-13 m/s); sampling F at the step's start would be off by Ḟ T h/(2m) ~ 3e-4
// m/s. x = h Σ vₙ runs ahead of the exact x(T) by h v(T)/2 for a linear v (semi-implicit Euler's first-order
// lag), plus less for the quadratic part: bounded by h |v(T)|.
#define APPLIED_VELOCITY_TOL 1e-9  // m/s
// One step from rest: ω = h I_world⁻¹ (R p × F(h/2)) exactly (no gyroscopic term at ω = 0); round-off of a
// 3×3 product, and for Bullet of the principal-frame conversion (~1e-15 relative).
#define APPLIED_SPIN_REL_TOL 1e-9

static void check_applied_force(const pdRefAdapter* adapter, pdRefVariant variant) {
  const double h = PD_REF_DEFAULT_STEP, T = 1.0;
  pdRefOptions options = {.variant = variant, .step = h, .odeFriction = pd_odeFrictionPyramid};
  pdError err;
  memset(&err, 0, sizeof err);

  // the ramp at the centre of mass: 0.2 × 0.1 × 0.1 m of water, 2 kg
  pdModel* m = compile_text("gravity 0 0 0\ntend 1\ncube b red 0.2 0.1 0.1\nloc 1 0 0\nforce 1 -2 0.5 ramp 0.5 1 0\n");
  const pdBody* b = &m->bodies[0];
  pdRefWorld* w = adapter->create(m, &options, &err);
  if (!w) fail_msg("create: %s", err.message);
  for (int k = 0; k < 1000; ++k) assert_true(adapter->step(w, h));
  pdVec3 f0 = pd_v3(1, -2, 0.5), rate = pd_v3(0.5, 1, 0);
  pdVec3 v = pd_v3_add(pd_v3_scale(f0, T / b->mass), pd_v3_scale(rate, T * T / (2.0 * b->mass)));
  pdVec3 x = pd_v3_add(b->x0, pd_v3_add(pd_v3_scale(f0, T * T / (2.0 * b->mass)), pd_v3_scale(rate, T * T * T / (6.0 * b->mass))));
  pdBodyState s = adapter->body(w, 0);
  double verr = pd_v3_norm(pd_v3_sub(s.v, v)), xerr = pd_v3_norm(pd_v3_sub(s.x, x));
  printf("%s %s: ramp at the centre of mass: |v - v_exact| = %.3g m/s, |x - x_exact| = %.3g m (h|v| = %.3g m)\n",
         adapter->name, variant == pd_refMatched ? "matched" : "native", verr, xerr, h * pd_v3_norm(v));
  assert_true(verr < APPLIED_VELOCITY_TOL);
  assert_true(xerr < h * pd_v3_norm(v));
  assert_true(pd_v3_norm(s.w) < APPLIED_VELOCITY_TOL);  // no torque through the centre of mass
  adapter->destroy(w);
  pd_model_free(m);

  // a force at an offset body point of a turned body: one step from rest
  m = compile_text("gravity 0 0 0\ncube b red 0.3 0.2 0.1\nloc 0 0 0 30 0 0 1\nforce 2 1 -1 ramp 0 3 0 at 0.15 -0.1 0.05\n");
  b = &m->bodies[0];
  w = adapter->create(m, &options, &err);
  if (!w) fail_msg("create: %s", err.message);
  assert_true(adapter->step(w, h));
  pdVec3 f = pd_v3(2, 1 + 3 * 0.5 * h, -1);
  pdMat3 r = pd_quat_to_mat3(b->q0);
  pdVec3 torqueBody = pd_mat3_tmulv(&r, pd_v3_cross(pd_mat3_mulv(&r, b->forcePoint), f));
  pdVec3 spin = pd_v3_scale(pd_mat3_mulv(&r, pd_mat3_mulv(&b->invInertia, torqueBody)), h);
  s = adapter->body(w, 0);
  double werr = pd_v3_norm(pd_v3_sub(s.w, spin)) / pd_v3_norm(spin);
  printf("%s: offset force, first step: |w - h I^-1 (Rp x F)|/|w| = %.3g\n", adapter->name, werr);
  assert_true(werr < APPLIED_SPIN_REL_TOL);
  assert_true(pd_v3_norm(pd_v3_sub(s.v, pd_v3_scale(f, h / b->mass))) < APPLIED_VELOCITY_TOL);
  // engine_settings says how the force was applied
  char* text = NULL;
  size_t size = 0;
  FILE* out = open_memstream(&text, &size);
  assert_non_null(out);
  adapter->settings_json(w, out);
  fclose(out);
  assert_non_null(strstr(text, "\"applied_force_call\""));
  free(text);
  adapter->destroy(w);
  pd_model_free(m);
}
