// polydyn (internal) — dense output: the state between step ends (integrator.c, islands.c; docs/integration.md).
//
// The error-controlled steppers do not cut their steps at output samples or at pd_advance's tEnd. The step that
// passes such a time keeps what it needs to give the state anywhere inside it (captured before its commit, in its
// contact list's layout), and the state is presented there: the bodies' and springs' numbers interpolated, the
// step's contact list with each contact's geometry and force at that time, its springs realigned to that normal as
// a commit would (when first read: pd_contact_set_settle; an observer reading the bodies alone skips it). While a state is presented, state->t, y, n and contacts are the presented ones and the
// integration's own state (at the step's end, later than state->t) is put aside; pd_advance puts it back before it
// steps on, so presenting never changes what the integration computes.
//
// Interpolants, on θ = (t − t0)/h of the step [t0, t0 + h]:
// - step doubling: the quartic through y0 with slope f(y0), the first half step's result y½ with slope f(y½), and
//   the kept result y1: every number it uses is the step's own (no evaluation), error O(h⁵) like the half steps';
// - the embedded pair and the implicit method: the cubic Hermite interpolant of y0, f(y0), y1, f(y1) (the embedded
//   pair has f(y1) already; the implicit method evaluates it once per step that needs it), error O(h⁴);
// - Dormand–Prince 5(4): its fourth-order continuous extension (Hairer, Nørsett & Wanner I, II.6; their DOPRI5's
//   CONTD5) y0 + θ (Δ + (1 − θ)(h f0 − Δ + θ (2Δ − h f0 − h f1 + (1 − θ) d))), Δ = y1 − y0, d = h Σ d_i k_i: the
//   cubic Hermite interpolant plus θ²(1 − θ)² d, error O(h⁵), from the step's own stages (no evaluation).
// Quaternions are normalised after interpolation.
#pragma once

#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/state.h"

typedef struct pdDense pdDense;

pdDense* pd_dense_create(void);
// Frees the record; the state must not be presented (pd_dense_resume first).
void pd_dense_free(pdDense* d);

// The earliest time the coming step must be able to present (a sample or tEnd); a step whose end passes it is
// captured.
void pd_dense_expect(pdDense* d, double t);
// Does an accepted step of h from state->t pass the expected time?
bool pd_dense_wanted(const pdDense* d, double t0, double h);
// The accepted step of h from (state->t, state->y), before its commit: step doubling's nodes (f0 = f(y0), yHalf,
// fHalf = f(yHalf), y1), or the cubic's (f1 = f(y1), yHalf and fHalf NULL). Copies them and the step's contact
// list. May grow the record (the first steps of a state, or a longer state vector).
void pd_dense_capture(const pdModel* model, pdState* s, double h, const double* f0, const double* yHalf,
                      const double* fHalf, const double* y1, const double* f1);
// The accepted Dormand–Prince step of h from (state->t, state->y), before its commit: f0 = k1, y1, f1 = k7 = f(y1)
// and d = h Σ d_i k_i, its continuous extension's last term (integrator.c, DOPRI_D). As pd_dense_capture.
void pd_dense_capture_dopri(const pdModel* model, pdState* s, double h, const double* f0, const double* y1,
                            const double* f1, const double* d);
// Where the implicit method evaluates f(y1) for its capture (state->n numbers; pd_dense_capture takes it as is).
double* pd_dense_slope_scratch(pdDense* d, int n);

// Presents the state at t, inside the last captured step (t0 < t < t0 + h, asserted). A state already presented
// is presented anew.
void pd_dense_present(const pdModel* model, pdState* s, double t);
// The energy of the springs the contact history kept over the presented step (J), 0 when not presenting: the
// presented contact list has no history of its own (pd_state_energy).
double pd_dense_presented_kept_energy(const pdDense* d);
// Puts the integration's own state back; returns whether the state was presented.
bool pd_dense_resume(pdState* s);
// Forgets the captured step (the state is set up anew: islands.c's island_load, pd_state_reset).
void pd_dense_discard(pdState* s);

// Step doubling's quartic (above) at θ of the step of h from y0, f0 = f(y0), through yHalf, fHalf = f(yHalf) and y1,
// into out (n numbers; quaternions left as interpolated). Also where a located onset's step is cut (integrator.c).
void pd_dense_quartic(int n, double h, double theta, const double* y0, const double* f0, const double* yHalf,
                      const double* fHalf, const double* y1, double* out);
