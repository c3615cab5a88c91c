// The gedanken measures on synthetic series with known answers: the line fit, the first impact with and
// without gravity, apex heights, the first fall (stop time), the largest rise (energy gain), the drift
// speed, angle unwrapping, eq. (15)'s restitution of a damping ratio against the catalogue's table, the
// impulse ratio of an oblique impact (C5), the energy a cube's landing takes (D3) and a rate read within a
// band of another series (F2's precession).
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "pdgk/gedanken.h"

#define ROUND_OFF 1e-12  // synthetic series are exact: only floating-point rounding separates the answers

enum { N = 401 };

static void test_line_fit_recovers_the_slope_inside_the_window_only(void** state) {
  (void)state;
  double t[N], y[N];
  for (int k = 0; k < N; ++k) {
    t[k] = 0.01 * k;
    // a line of slope 3 inside [1, 3], something else outside it
    y[k] = t[k] >= 1.0 && t[k] <= 3.0 ? 3.0 * t[k] + 2.0 : 100.0 * sin(t[k]);
  }
  double slope, intercept;
  assert_true(pd_gk_fit_line(t, y, N, 1.0, 3.0, &slope, &intercept));
  assert_true(fabs(slope - 3.0) < ROUND_OFF * 100);
  assert_true(fabs(intercept - 2.0) < ROUND_OFF * 100);
  assert_false(pd_gk_fit_line(t, y, N, 10.0, 11.0, &slope, NULL));  // no sample in the window
  assert_false(pd_gk_fit_line(t, y, 1, 0.0, 1.0, &slope, NULL));     // one sample
}

// Free flight v = vIn + g (t − tm) before the contact, v = vOut + g (t − tm) after it, and an arbitrary
// profile during [tm − 2 ms, tm + 2 ms]: the impact's velocities carried to tm are exactly vIn and vOut.
// tm sits half-way between samples (1 ms apart), so the impact's mid time is tm.
static void synthetic_impact(double* t, double* v, double g, double vIn, double vOut, double tm) {
  for (int k = 0; k < N; ++k) {
    t[k] = 0.001 * k;
    if (t[k] < tm - 0.002)
      v[k] = vIn + g * (t[k] - tm);
    else if (t[k] > tm + 0.002)
      v[k] = vOut + g * (t[k] - tm);
    else
      v[k] = vIn + (vOut - vIn) * (t[k] - tm + 0.002) / 0.004 + 0.3 * sin(1000.0 * t[k]);
  }
}

static void test_first_impact_restitution_without_gravity(void** state) {
  (void)state;
  double t[N], v[N];
  synthetic_impact(t, v, 0.0, -1.0, 0.5, 0.1005);
  pdGkImpact impact;
  assert_true(pd_gk_first_impact(t, v, N, 0.0, 1e-9, 3, &impact));
  assert_true(fabs(impact.restitution - 0.5) < ROUND_OFF);
  assert_true(impact.tStart < 0.0985 && impact.tEnd > 0.1025);
}

static void test_first_impact_restitution_under_gravity(void** state) {
  (void)state;
  double t[N], v[N];
  synthetic_impact(t, v, -9.81, -3.0, 0.9, 0.2005);
  pdGkImpact impact;
  assert_true(pd_gk_first_impact(t, v, N, -9.81, 1e-9, 3, &impact));
  // both velocities carried to the impact's mid time: e = 0.9/3 whatever the samples' phase
  assert_true(fabs(impact.restitution - 0.3) < 1e-9);
  assert_true(fabs(impact.vIn + 3.0) < 1e-9 && fabs(impact.vOut - 0.9) < 1e-9);
}

static void test_first_impact_needs_an_impact(void** state) {
  (void)state;
  double t[N], v[N];
  for (int k = 0; k < N; ++k) t[k] = 0.001 * k, v[k] = -9.81 * t[k];  // free fall throughout
  pdGkImpact impact;
  assert_false(pd_gk_first_impact(t, v, N, -9.81, 1e-9, 3, &impact));
  // an impact that has not ended when the series does
  for (int k = 200; k < N; ++k) v[k] = 5.0 * sin(50.0 * t[k]);
  assert_false(pd_gk_first_impact(t, v, N, -9.81, 1e-9, 3, &impact));
}

// A ball bouncing with restitution e off z = 0: apex heights h e^(2i), sampled at an arbitrary rate.
static void test_apex_heights_of_a_bouncing_ball(void** state) {
  (void)state;
  enum { M = 5000 };  // 3.6 s: before the bounces pile up at t = 4.06 s
  static double z[M], vz[M];
  const double g = 9.81, e = 0.8, h0 = 1.0, dt = 0.000713;
  double zc = h0, vc = 0.0;
  for (int k = 0; k < M; ++k) {
    z[k] = zc, vz[k] = vc;
    // exact ballistic step, with the bounce inside the step
    double tLeft = dt;
    for (;;) {
      double tHit = (vc + sqrt(vc * vc + 2.0 * g * zc)) / g;  // time to z = 0
      if (tHit > tLeft) {
        zc += vc * tLeft - 0.5 * g * tLeft * tLeft;
        vc -= g * tLeft;
        break;
      }
      vc = -e * (vc - g * tHit);
      zc = 0.0;
      tLeft -= tHit;
    }
  }
  double apex[8];
  int count = pd_gk_apexes(z, vz, M, g, apex, 8);
  assert_int_equal(count, 8);
  for (int i = 0; i < count; ++i) assert_true(fabs(apex[i] - h0 * pow(e, 2.0 * (i + 1))) < 1e-9);
}

static void test_first_fall_is_the_stop_time_of_a_linear_deceleration(void** state) {
  (void)state;
  double t[N], speed[N];
  // v = 2 − 4 t, then a ring-down that crosses the threshold again later
  for (int k = 0; k < N; ++k) {
    t[k] = 0.003 * k;
    speed[k] = t[k] < 0.5 ? 2.0 - 4.0 * t[k] : 0.01 * fabs(sin(60.0 * t[k])) * exp(-(t[k] - 0.5) * 5.0);
  }
  double tStop;
  // the crossing at 0.4875 s lies between samples on the line (0.486 s and 0.489 s)
  assert_true(pd_gk_first_fall(t, speed, N, 0.05, &tStop));
  assert_true(fabs(tStop - (2.0 - 0.05) / 4.0) < ROUND_OFF * 10);
  assert_false(pd_gk_first_fall(t, speed, N, 5.0, &tStop));  // never above
  double rising[3] = {0.0, 1.0, 2.0};
  assert_false(pd_gk_first_fall(t, rising, 3, 0.5, &tStop));  // never falls back
}

static void test_ramp_slip_onset_is_where_the_fitted_slide_starts(void** state) {
  (void)state;
  // m = 2 kg, β = 5 N/s, t* = 1.2 s: a creep of 1e-5 m/s, then v = 1e-5 + β (t − t*)²/(2m); samples 1 ms apart
  enum { M = 1500 };
  static double t[M], v[M];
  for (int k = 0; k < M; ++k) {
    t[k] = 1e-3 * k;
    double after = fmax(0.0, t[k] - 1.2);
    v[k] = 1e-5 + 5.0 * after * after / 4.0;
  }
  double onset, slope;
  assert_true(pd_gk_ramp_slip_onset(t, v, M, 2.0, 5.0, 2e-3, 1e-2, &onset, &slope));
  // the creep shifts √(2 m v/β) by at most 1e-5/(2 v) relative, ~2.5e-3 of the ~0.04 s after t*: ~1e-4 s
  assert_true(fabs(onset - 1.2) < 2e-4);
  assert_true(fabs(slope - 1.0) < 1e-2);
  // a threshold crossing would lag by √(2 m vLo/β) = 0.04 s: the fit does not
  double tCross = 0.0;
  for (int k = 0; k < M; ++k)
    if (v[k] >= 2e-3) {
      tCross = t[k];
      break;
    }
  assert_true(tCross - 1.2 > 0.03);
  assert_false(pd_gk_ramp_slip_onset(t, v, M, 2.0, 5.0, 2e-3, 1.0, &onset, &slope));  // never reaches 1 m/s
}

static void test_largest_rise_of_a_series(void** state) {
  (void)state;
  const double e[] = {10.0, 8.0, 9.0, 7.0, 7.5, 6.0};  // rises: 1 (8 → 9), 0.5 (7 → 7.5)
  assert_true(fabs(pd_gk_largest_rise(e, 6, 10.0) - 0.1) < ROUND_OFF);
  const double falling[] = {3.0, 2.0, 1.0};
  assert_true(pd_gk_largest_rise(falling, 3, 1.0) == 0.0);
}

static void test_drift_speed_of_a_uniform_motion(void** state) {
  (void)state;
  double t[N];
  pdVec3 x[N];
  for (int k = 0; k < N; ++k) t[k] = 0.01 * k, x[k] = k < 100 ? pd_v3(5.0, 5.0, 5.0) : pd_v3(3e-9 * t[k], 4e-9 * t[k], 1.0);
  double speed;
  assert_true(pd_gk_drift_speed(t, x, N, 1.0, &speed));
  assert_true(fabs(speed - 5e-9) < 1e-20);
  assert_false(pd_gk_drift_speed(t, x, N, 4.0, &speed));  // one sample left
}

static void test_unwrap_restores_a_steadily_turning_angle(void** state) {
  (void)state;
  double a[N];
  for (int k = 0; k < N; ++k) a[k] = atan2(sin(0.3 * k), cos(0.3 * k));  // 0.3 rad per sample, wrapped
  pd_gk_unwrap(a, N);
  for (int k = 0; k < N; ++k) assert_true(fabs(a[k] - 0.3 * k) < 1e-9);
}

// The catalogue's A1 table (F = 0 rule), its calibration point and the limits of eq. (15).
static void test_restitution_of_damping_matches_the_catalogue_table(void** state) {
  (void)state;
  const double table[][2] = {{0.05, 0.859}, {0.10, 0.744}, {0.20, 0.572}, {0.30, 0.451},
                             {0.50, 0.298}, {0.70, 0.210}, {0.2553, 0.5}, {0.4972, 0.3}};
  for (size_t i = 0; i < sizeof table / sizeof table[0]; ++i)
    assert_true(fabs(pd_gk_restitution_of_damping(table[i][0]) - table[i][1]) < 1e-3);  // 3 digits printed
  assert_true(pd_gk_restitution_of_damping(0.0) == 1.0);
  assert_true(fabs(pd_gk_restitution_of_damping(1.0) - exp(-2.0)) < ROUND_OFF);
  // continuous through critical damping, and still falling beyond it
  assert_true(fabs(pd_gk_restitution_of_damping(1.0 - 1e-6) - exp(-2.0)) < 1e-6);
  assert_true(fabs(pd_gk_restitution_of_damping(1.0 + 1e-6) - exp(-2.0)) < 1e-6);
  assert_true(pd_gk_restitution_of_damping(2.0) < exp(-2.0));
}

// A point mass hits a floor at v_n = −1 m/s, v_t = v_t0, under a half-sine normal force pulse of impulse
// (1 + e) m (m = 1 kg); while it slides the tangential force is μ times the normal one, and a slip that would
// reverse sticks at zero. The impulse so far is P(t) = (1 + e) m (1 − cos(π t/T))/2, taken in 100 steps.
static void sliding_impact(double vt0, double mu, double e, double* vt1, double* vn1) {
  double vt = vt0, vn = -1.0;
  const double pi = acos(-1.0);
  for (int k = 1; k <= 100; ++k) {
    double p0 = (1.0 + e) * (1.0 - cos(pi * (k - 1) / 100.0)) / 2.0;
    double p1 = (1.0 + e) * (1.0 - cos(pi * k / 100.0)) / 2.0;
    vn += p1 - p0;
    vt = fmax(0.0, vt - mu * (p1 - p0));
  }
  *vt1 = vt;
  *vn1 = vn;
}

static void test_impulse_ratio_is_mu_while_the_impact_slides(void** state) {
  (void)state;
  double vt1, vn1;
  sliding_impact(4.0, 0.3, 0.5, &vt1, &vn1);  // slides throughout: Δv_t = 0.45 < 4
  assert_true(fabs(vn1 - 0.5) < ROUND_OFF);
  assert_true(fabs(pd_gk_impulse_ratio(4.0, vt1, -1.0, vn1) - 0.3) < ROUND_OFF);
  // a slow slide stops during the impact: the tangential impulse falls short of μ times the normal one
  sliding_impact(0.2, 0.3, 0.5, &vt1, &vn1);
  assert_true(fabs(pd_gk_impulse_ratio(0.2, vt1, -1.0, vn1) - 0.2 / 1.5) < ROUND_OFF);
  assert_true(isnan(pd_gk_impulse_ratio(1.0, 0.5, -1.0, -1.0)));  // no normal impulse: no ratio
}

static void test_absorbed_fraction_from_total_energies(void** state) {
  (void)state;
  // 2 J of kinetic energy at a landing 3 J above the zero of potential energy, 0.5 J of it left after: 3/4 taken
  assert_true(fabs(pd_gk_absorbed_fraction(5.0, 3.5, 2.0) - 0.75) < ROUND_OFF);
  assert_true(fabs(pd_gk_absorbed_fraction(5.0, 5.0, 2.0)) < ROUND_OFF);  // elastic: nothing taken
}

static void test_cube_landing_takes_fifteen_sixteenths_when_plastic(void** state) {
  (void)state;
  double spin;
  // plastic: ω⁺/ω⁻ = (2 + 7 cos(2π/N))/(8 + cos(2π/N)) for an N-gon (catalogue D1), 1/4 for the cube; the
  // energy about the new edge, whose inertia equals the old one's, is then (1/4)² of what it was
  assert_true(fabs(pd_gk_cube_landing_absorbed(0.0, &spin) - 15.0 / 16.0) < ROUND_OFF);
  double n = 4.0, c = cos(2.0 * acos(-1.0) / n);
  assert_true(fabs(spin - (2.0 + 7.0 * c) / (8.0 + c)) < ROUND_OFF);
  // elastic normal and no slip: neither impulse does work, nothing is taken
  assert_true(fabs(pd_gk_cube_landing_absorbed(1.0, &spin)) < ROUND_OFF);
  // between, the kinetic energy left is (1 + 15 e²)/16 of it (derived by hand from the same impulse balance)
  for (double e = 0.1; e < 1.0; e += 0.2)
    assert_true(fabs(pd_gk_cube_landing_absorbed(e, NULL) - 15.0 / 16.0 * (1.0 - e * e)) < ROUND_OFF);
}

static void test_mean_rate_in_band_reads_each_band_alone(void** state) {
  (void)state;
  // a heading turning at 20 rad/s while a tilt falls from 50 to 40, then at 100 rad/s while it falls from 6 to 2
  double t[N], heading[N], tilt[N];
  for (int k = 0; k < N; ++k) {
    t[k] = 0.001 * k;
    bool early = k <= 200;
    tilt[k] = early ? 50.0 - 10.0 * k / 200.0 : 6.0 - 4.0 * (k - 201) / 199.0;
    heading[k] = early ? 20.0 * t[k] : 20.0 * 0.2 + 100.0 * (t[k] - 0.2);
  }
  double rate;
  assert_true(pd_gk_mean_rate_in_band(t, heading, tilt, N, 40.0, 50.0, &rate));
  assert_true(fabs(rate - 20.0) < ROUND_OFF * 1e3);
  assert_true(pd_gk_mean_rate_in_band(t, heading, tilt, N, 2.0, 6.0, &rate));
  assert_true(fabs(rate - 100.0) < ROUND_OFF * 1e3);
  assert_false(pd_gk_mean_rate_in_band(t, heading, tilt, N, 10.0, 30.0, &rate));  // never in that band
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_line_fit_recovers_the_slope_inside_the_window_only),
      cmocka_unit_test(test_first_impact_restitution_without_gravity),
      cmocka_unit_test(test_first_impact_restitution_under_gravity),
      cmocka_unit_test(test_first_impact_needs_an_impact),
      cmocka_unit_test(test_apex_heights_of_a_bouncing_ball),
      cmocka_unit_test(test_first_fall_is_the_stop_time_of_a_linear_deceleration),
      cmocka_unit_test(test_ramp_slip_onset_is_where_the_fitted_slide_starts),
      cmocka_unit_test(test_largest_rise_of_a_series),
      cmocka_unit_test(test_drift_speed_of_a_uniform_motion),
      cmocka_unit_test(test_unwrap_restores_a_steadily_turning_angle),
      cmocka_unit_test(test_restitution_of_damping_matches_the_catalogue_table),
      cmocka_unit_test(test_impulse_ratio_is_mu_while_the_impact_slides),
      cmocka_unit_test(test_absorbed_fraction_from_total_energies),
      cmocka_unit_test(test_cube_landing_takes_fifteen_sixteenths_when_plastic),
      cmocka_unit_test(test_mean_rate_in_band_reads_each_band_alone),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
