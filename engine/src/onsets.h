// polydyn (internal) — contact onsets (paper App. C; design note at the top of onsets.c): a contact found at the end
// of a step located back to where it began, and the pair onsets that join at the step's end instead.
#pragma once

#include <stdbool.h>

#include "contact_analysis.h"
#include "contact_set.h"

// Onset of a contact found at the end of a step (App. C): the fraction δ ∈ [0, 1] of the step at
// which the features first touched, given the poses of body 1 and body 2 at the start and the end
// of the step. VF by the quadratic (24)–(25) with linearly interpolated vertex, face point and normal;
// EE by the linear interpolation (26) of the edge-line distances in body 2's frame. Returns 0 when
// the features were already touching at the start (a virtual contact, §4.4.3).
double pd_contact_onset(const pdModel* model, const pdContactId* id, const pdPose* body1Start,
                        const pdPose* body1End, const pdPose* body2Start, const pdPose* body2End);

// The earliest onset fraction δ among the candidates of the last contact search (contact_list.h) that
// approach, carry no springs over and went deeper than their onset tolerance; 2 when there is none. With pairOnsets a
// candidate close enough to the step's end (of size h, at time t1) to join there as a pair onset gets its onset age
// instead.
double pd_onsets_earliest(const pdModel* model, pdContactSet* set, double h, pdOnsets onsets, const double* y1,
                          double t1);
// Whether the step under way may still be retried for an onset (the retries per step are bounded).
bool pd_onsets_may_retry(const pdContactSet* set);
// Pair onsets of a list just installed at state y (poses those of y; world inverse inertias and modal dampers set):
// each contact with an onset age τ > 0 is put where it would be after τ on its own, its springs and its bodies'
// velocities changed so. Returns the number of such contacts.
int pd_onsets_start_late(const pdModel* model, pdContactSet* set, double* y, const pdPose* poses);
