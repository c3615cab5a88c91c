// polydyn (internal) — the contact modes of stacks: the slow frequency that sizes a pair's modal dampers when its
// bodies rest on, or carry, other bodies (stack_modes.c, docs/contact-model.md "Stacks"), and the damped modes that
// `polydyn check` reports (polydyn/modes.h).
#pragma once

#include <stdbool.h>

#include "contact_list.h"

typedef struct pdStackScratch pdStackScratch;

// A pair's local system holds at most this many moving bodies: the pair's and its bodies' neighbours in contact,
// in body order; the bodies beyond count as fixed. A brick inside a wall has 6 to 8 neighbours.
#define PD_STACK_LOCAL_BODIES_MAX 12

pdStackScratch* pd_stack_scratch_create(void);
void pd_stack_scratch_free(pdStackScratch* scratch);
// How many times pd_stack_pair_frequency read a decomposition again for a matrix equal bit for bit to the last one
// it decomposed with this scratch (stack_modes.c).
long pd_stack_scratch_reuses(const pdStackScratch* scratch);

// The slow frequency Ω (rad/s) that pair [first, last) of the list takes part in along the normals, from the
// undamped normal modes of its local system (the pair's moving bodies and their neighbours in contact, every contact
// touching them; bodies outside it fixed): 1/Ω = max over modes j of min(1, s_j / PD_STACK_SHARE) / ω_j, s_j the
// share of mode j's strain energy in the pair's springs. Returns false (*omega unset) for a pair whose bodies touch
// nothing else, whose local system's masses are within PD_STACK_MASS_RATIO of each other, or which has no normal
// stiffness: its dampers are the pair's own. The body lists (bodyFirst, bodyList) must be current.
// fast (rad/s; 0: none) is the frequency from which the caller's answer no longer depends on Ω: false also when Ω
// is shown to be at least fast (with a margin of 1e-6 of it) from the eigenvalues alone, the eigenvectors
// uncomputed; where it is not shown, Ω as without it, bit for bit.
// The modes of stack `stack` (pd_state_stack_modes, state.h; engine/src/state_stack_modes.c) from the contact list
// and every body's state.
int pd_stack_modes(const pdModel* model, const pdContactSet* set, const pdBodyState* bodies, const int* stackOf,
                   int stack, pdStackMode* modes, int capacity);

bool pd_stack_pair_frequency(const pdModel* model, const pdContactSet* set, const pdPose* poses, int first,
                             int last, double fast, pdStackScratch* scratch, double* omega);
