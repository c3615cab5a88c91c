// polydyn (internal) — the islands' set: the live islands and the partition's working arrays, shared by the
// interval loop (islands.c) and the partition (island_partition.c). Design note at the top of islands.c.
#pragma once

#include <stdbool.h>

#include "broad_phase.h"
#include "interference.h"
#include "pool.h"
#include "polydyn/model.h"
#include "polydyn/state.h"
#include "sleep.h"

typedef struct island {
  int bodyCount;   // moving bodies
  int* bodies;     // (bodyCount) their moving-body indices k (scene body model->movingBodies[k]), ascending
  pdModel model;   // its moving bodies and every fixed body, scene order
  int* toScene;    // (model.bodyCount) scene body index of each of its bodies
  pdState* state;  // at T, or at T' once advanced
  bool advanced;   // advanced over the interval under way
  bool asleep;     // frozen (sleeping, below): never advanced; its state kept as it was when it fell asleep
} island;

struct pdIslandSet {
  int movingCount, bodyCount, fixedCount;
  int* fixedBodies;  // (fixedCount) scene indices of the fixed bodies, ascending
  int* root;         // (movingCount) union-find over moving-body indices; a root is its set's lowest index
  int* islandOf;     // (movingCount) island of each moving body in the partition under way
  int* islandOld;    // (movingCount) index in `islands` of the island holding the body (-1: none)
  int* members;      // (movingCount) moving bodies grouped by island, ascending within each
  int* first;        // (movingCount + 1) island j's members: members[first[j] .. first[j + 1])
  int partCount;     // islands in the partition under way
  double* bound;     // (movingCount) m: how far the body's points may move over the interval
  double* travel;    // (movingCount) m: how far they moved at most, measured at the island's step ends
  double* h;         // (movingCount) s: the next step its island wanted at the last sync
  pdVec3* x0;        // (movingCount) centre of mass at T, m
  pdVec3* v0;        // (movingCount) its velocity at T, m/s
  pdQuat* q0;        // (movingCount) orientation at T
  pdMat3* r0;        // (movingCount) its rotation matrix (normalised)
  pdAabb* box0;      // (movingCount) box at T
  bool* touching;    // (movingCount) in a contact at T, or its box may reach a fixed body's
  // x0 … touching of every body not free are set_start's at startsT over startsDt (find_free's or
  // cuts_split_islands', which an interval of that length from there need not form again), while startsFormed
  bool startsFormed;
  double startsT, startsDt;  // s
  // the sample interval [T0, Ts] as a whole (free bodies: see the design note)
  double ct0;         // s: T0
  bool* free;         // (movingCount) alone and ballistic over the whole sample interval
  pdVec3 *cx0, *cv0;  // (movingCount) centre of mass and velocity at T0
  pdQuat* cq0;        // (movingCount) orientation at T0
  double* cbound;     // (movingCount) m: the bound over the sample interval
  double* ctravel;    // (movingCount) m: how far a free body strayed from its ballistic path since T0
  pdAabb* cbox;       // (movingCount) its box over the sample interval (swept and grown)
  int* activate;      // (movingCount) free bodies a fine box reached (partition)
  long strays;        // free bodies that strayed from their box (never expected: counted, not recovered)
  double t0;         // s: T
  double sizeMin;    // m: the smallest moving body's size
  pdAabb* boxes;     // (bodyCount) grown boxes (fixed bodies: their own)
  pdBroadPhase* broad;
  pdPair* pairs;
  int pairCapacity;
  // may_meet's separating feature of each pair it tested at the last partition, sorted by (a, b) (a hint)
  pdPairSatCache *sat, *satNext;  // (pairCapacity)
  int satCount;
  int* toSub;        // (bodyCount) scratch: scene body → island body (-1 elsewhere)
  int* contactOf;    // (contactCapacity) island of each of the scene's contacts at T
  int* contacts;     // (contactCapacity) the scene's contacts grouped by island, ascending within each
  int* contactFirst;  // (movingCount + 1) island j's contacts: contacts[contactFirst[j] .. contactFirst[j + 1])
  int contactCapacity;
  island** islands;  // (islandCapacity) the live islands, listed by their lowest body
  island** next;     // (islandCapacity) scratch: the list being formed
  int islandCount, islandCapacity;
  const pdModel** subModels;  // (islandCapacity) scratch for the gather
  const pdState** subStates;
  const int** subMaps;
  // work of islands freed so far (summed in with the live ones' at every sync)
  pdCounters retired;
  long retiredWarnings[pd_warnCount];
  double retiredStages[pd_stageCount];
  double observeSeconds;  // the scene's observer calls
  bool stagesBehind;      // the scene's stage seconds not composed since a lone sleeper's interval (islands.c)
  long formed, largest, intervals, redos;
  pdPool pool;  // the caller and pdState.threads − 1 workers (design note, "Threads"; pool.h)
  // the batch: jobCount islands, all to jobTime
  int jobCount;
  double jobTime;
  bool jobLand;          // cut the islands' last steps to end on jobTime (a sync time inside a sample interval)
  island** jobs;         // (islandCapacity)
  bool* jobCoarse;       // (islandCapacity) a free body's island (island_advance's coarse)
  bool* jobOk;           // (islandCapacity) written by the job's thread
  pdPoolOrder* order;    // (islandCapacity) the jobs by weight: the order the pool takes them in
  pdSleepSet* sleep;     // the bodies' sleep records (NULL when settings.sleep is off)
};
