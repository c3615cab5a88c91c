// polydyn (internal) — the error a corrected onset may add, and whether the step may spend it (docs/events.md).
//
// Design note. A contact that began τ seconds before a step's end, found there at depth d approaching at v_n, can
// join at the step's end as its pair would be after τ (onsets.c, pd_onsets_start_late: the contacts of the pair that
// began in the step followed together from their onsets under the two bodies' masses and inertias at the step end's
// poses, each contact's springs at the deflection and stretch reached, the bodies given the impulses taken). That
// follows the normal impulse's slip at an off-centre point, the tangential impulse's push along the normal and the
// pair's joint motion; what it misses is the rest of the system over τ: the bodies' turning under the impulse (their
// arms and inertias held at the step end's), the other forces on the bodies (applied loads, other contacts), and the
// interpolated onset time. These terms bound it, all in the units of the stepper's error norm (state.c's weights), so
// they compare with tol:
//   velocity: |δe| v_n / vmax, with |δe| <= PD_ONSET_BOUND_C (ωτ)³, the restitution error of a corrected onset
//             (C measured: tests/engine/test_events.c, the drops whose onsets are forced to be corrected), and μ times
//             it for the cone's radius;
//   position: (d − x) / L <= d (ωτ)² / (6 L), how much deeper the contact's rest point sits than a located onset's,
//             L the smaller moving body's size;
//   applied:  added to the velocity term: the motion starts from the velocities found at the step's end, which the
//             applied loads changed over τ by at most a (τ − t) since the onset's time t (a their largest relative
//             acceleration at the point); the force laws are Lipschitz, so the impulses are off by at most the
//             dampers' and springs' response to that drift, times how far an impulse moves the state (onsets.c,
//             correction_bound), and the springs by a τ²/2 over δ_max (the spring term);
//   turning:  added to the velocity term: PD_ONSET_TURNING_C Ω² r τ ωτ, and the onset time App. C's chord misplaces on
//             a turning body, (ω² τ + c/m) Ω² r τ (h − τ)/2 (onsets.c, correction_bound),
// with ω = √(k_s / m_min) the pair's fastest undamped frequency. An onset is corrected only where the largest of the
// three is at most PD_ONSET_TOL_SHARE × tol, and ωτ and d stay within the ranges the correction holds in (contact_set.c,
// PD_ONSET_PAIR_OMEGA_TAU, PD_ONSET_PAIR_DEPTH_REL); others are located, as the paper does with every one.
#pragma once

#include <stdbool.h>

// Restitution error of a corrected onset over (ωτ)³. The correction integrates the pair's normal element exactly over
// τ; what it leaves out (the bodies turning under that impulse, so the point's effective mass drifting, and the onset
// time's interpolation) enters the velocity at third order in ωτ. Measured on single bodies (tests/engine/test_events.c:
// a cube landing on a face, a corner and an edge, e 0.3–0.8, at 0.02–3 m/s, stiff and soft, ωτ up to 0.82, at tol
// 1e-10): at most 1.1e-4 (ωτ)³, so 0.004 keeps a factor of ~36 for what no test isolates (a crowd's other contacts
// over τ). The 1-D spring–dashpot figure of the cruder impulse (c v_n + ½ k δ₀) τ is 0.08.
#define PD_ONSET_BOUND_C 0.04
// The turning term's coefficient (onsets.c, correction_bound): a body turning at Ω as it lands changes its point's
// approach by Ω² r τ over the τ the correction stands in for; calibrated on a bar 0.6 m long landing on its edge while
// turning at 4 rad/s (tests/engine/test_events.c).
#define PD_ONSET_TURNING_C 10.0
// The share of tol one corrected onset may spend: the size of one accepted step's own local error. An onset joined
// within it changes the result no more than one more step would; beyond it the onset is located (a retried step).
#define PD_ONSET_TOL_SHARE 1.0

// The error bound of joining, corrected, an onset of a contact whose pair's fastest frequency is omega (1/s), that
// began tau seconds before the step's end, found at depth (m) approaching at approach (m/s, > 0), in a scene whose
// velocity scale is vmax (m/s) and whose smaller moving body of the pair is size (m) across, with `friction` (m/s) the
// friction and turning terms and `spring` the spring term (error norm units): the largest of the velocity term,
// friction / vmax added to it, the position term and the spring term (dimensionless, the
// error norm's units).
double pd_onset_error_bound(double omega, double tau, double depth, double approach, double vmax, double size,
                            double friction, double spring);

// Whether an onset of that bound may be corrected at tolerance tol (else it is located).
static inline bool pd_onset_bound_allows(double bound, double tol) { return bound <= PD_ONSET_TOL_SHARE * tol; }

// The part of the tolerance's share a located onset's retried step aims to leave its correction: half, so that the
// contact found at the retried step's end, its onset a little off the estimate, is still corrected.
#define PD_ONSET_AIM_SHARE 0.5

// A stick–slip change left inside a step (docs/events.md). The contact force is continuous there but its rate jumps,
// by at most [Ḟ] = k_t |Δu_t| + μ k_n |Δu_n| (the spring rates of stick against those of the cone; series constants),
// so the acceleration has a kink of slope [a'] <= [Ḟ] / m_min. RK4 integrates the velocity across it like Simpson's
// rule across a kinked integrand, whose error is at most [a'] h²/24 (the kink at the middle); with step doubling the
// kink lies in one half step, h/2. Twice that, for the spring rates the bodies' turning adds:
//   bound = 2 [a'] (h/2)² / 24 / vmax = (ω_t² |Δu_t| + μ ω_n² |Δu_n|) h² / (48 vmax),  ω² = k / m_min,
// in the error norm's units; the change is left inside the step where the bound is within PD_ONSET_TOL_SHARE × tol,
// else the step is halved towards it as the paper does (contact_set.c, refine_step).
double pd_transition_error_bound(double omegaT2, double omegaN2, double mu, double slide, double approach, double h,
                                 double vmax);
