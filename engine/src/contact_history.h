// polydyn (internal) — tangential history kept through micro-separations (docs/events.md).
//
// Design note. A contact whose normal springs would pull is dropped at the step's end (a break ends its history).
// In a pile, resting contacts chatter: a corner lifts by a fraction of its rest depth and lands again a few steps
// later on the same features, and with its tangential springs started at zero each time, what held the body in stick
// is lost at every landing, and the pile creeps. So a contact that breaks by force leaves its tangential springs
// behind (a "trace", keyed by its id: the same two features), as long as its features stay tracked and within
// PD_HISTORY_GAP_REL × δ_max of touching; a contact on the same features that starts again meanwhile takes them,
// realigned to its normal. A trace whose features part farther, or leave each other (a vertex off its face), is
// forgotten. A contact whose features part (broken geometrically) with no successor in that commit leaves a hand-over
// trace, taken by a successor on continuing features within a few commits. Traces are kept per contact set: an island set up anew starts without them (as before this history).
#pragma once

#include <stdbool.h>

#include "contact_analysis.h"
#include "contact_force.h"

// A trace is kept while its features are apart by at most this fraction of the pair's δ_max. A resting contact's
// rest depth is of the order of 0.1–0.3 δ_max (m g over the springs of a face's corners), and a micro-separation
// lifts a corner by a small part of it; a gap of a tenth of δ_max is then still that resting contact, while a body
// that bounces off goes beyond it within a step or two.
#define PD_HISTORY_GAP_REL 0.1

// A contact broken geometrically with no successor in that commit leaves its springs for this many commits: a successor
// on features that continue it (pd_contact_continues) found meanwhile takes them, as a hand-over in one commit does.
// A corner of a box spinning at 560 rad/s across an edge turns its edge pairs over every 40–100 µs, and the successor
// pair is found a step or two after its predecessor broke (soak seed 32, scene 592).
#define PD_HANDOVER_COMMITS 4

typedef struct pdContactHistory pdContactHistory;

pdContactHistory* pd_history_create(void);
void pd_history_free(pdContactHistory* h);
void pd_history_clear(pdContactHistory* h);
int pd_history_count(const pdContactHistory* h);

// Contact `id` of the list broke by force with these springs, its normal `normal`, the pair's δ_max deltaMax (m) and
// its springs' factor over eq. (11)'s loadScale (contactSlot.loadScale: the springs' deflections are at that factor).
void pd_history_leave(pdContactHistory* h, const pdContactId* id, const pdSprings* springs, pdVec3 normal,
                      double deltaMax, double loadScale);
// Contact `id` of the list broke geometrically (its features parted) with these springs, its normal and normal force fn
// (N) and springs' factor loadScale, and no contact took over from it: kept PD_HANDOVER_COMMITS commits for a successor.
void pd_history_leave_handover(pdContactHistory* h, const pdContactId* id, const pdSprings* springs, pdVec3 normal,
                               double fn, double loadScale);
// A new contact `id` with normal `normal` that continues a hand-over trace (pd_contact_continues): its springs, normal
// and tangential, turned to `normal` and the tangential ones held within the cone of the trace's normal force, into
// *springs, with the stiffness they had: *params' springs and *loadScale (the new contact's, eq. (11)'s and 1) raised
// to the trace's factor; the trace is forgotten; true. Else false.
bool pd_history_take_handover(const pdModel* model, pdContactHistory* h, const pdContactId* id, pdVec3 normal,
                              pdContactParams* params, double* loadScale, pdSprings* springs);
// The energy the kept traces will bring back, J: ½ k s² of the tangential springs of each trace left by force (its
// normal springs start at zero on return) and of every spring of each hand-over trace. A contact that breaks with
// springs kept moves their energy here rather than losing it, so a state's energy (pd_state_energy) does not jump up
// when a successor takes them (realigned, or held within a cone: never more).
double pd_history_spring_energy(const pdModel* model, const pdContactHistory* h);
// After a commit, at the bodies' new poses (indexed by model body): forgets every trace whose features no longer
// track or are apart by more than the gap tolerance, and every trace left before this call and taken since.
void pd_history_age(const pdModel* model, pdContactHistory* h, const pdPose* poses);
// The factor over eq. (11)'s of the springs a new contact `id` would take back from a trace left by force on the same
// features (pd_history_take), 1 when none is kept.
double pd_history_load_scale(const pdContactHistory* h, const pdContactId* id);
// The id of the trace left by force by vertex `vertex` of body vertexBody on a face of faceBody other than `face`, into
// *id: true when one is kept (not taken), else false.
bool pd_history_vertex_trace(const pdContactHistory* h, int vertexBody, int vertex, int faceBody, int face,
                             pdContactId* id);
// A new contact `id` with normal `normal`: when a trace of the same features is kept, writes its tangential springs,
// realigned from the trace's normal to `normal` (pd_springs_realign), into *springs, raises *params' springs and
// *loadScale (the new contact's, eq. (11)'s and 1) to the trace's factor, forgets the trace and returns true; else
// false.
bool pd_history_take(pdContactHistory* h, const pdContactId* id, pdVec3 normal, pdContactParams* params,
                     double* loadScale, pdSprings* springs);
