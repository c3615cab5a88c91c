// polydyn (internal) — a second thread's hands inside one island (docs/DESIGN.md §5.4; docs/integration.md).
//
// With pdState.threads > 1 the islands of a sync interval are taken in turn by the pool's threads
// (islands.c). A thread left without an island while another still runs serves the help desk instead of
// sleeping: the running island's long loops (over its contacts: forces, tracking, recording; over its pairs:
// interference and contact search; over its bodies: poses, force sums, Newton–Euler; over its state: RK4's updates)
// post their second half there, and the server runs it while the island's own thread runs the first. Every index is
// computed by the same function from the same inputs whichever thread runs it, each writes only its own index's
// outputs, and whatever combines them (merges, maxima) runs afterwards on the island's thread in index order: results
// are the same bit for bit with or without help, on any number of threads.
#pragma once

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

#include "polydyn/error.h"

// f(ctx, part, begin, end) runs the indices [begin, end) of a loop: part 0 the first half (or the whole loop),
// part 1 the second half. A loop that collects outputs of varying size keeps them per part.
typedef void pdRangeFcn(void* ctx, int part, int begin, int end);

typedef struct pdHelpTask pdHelpTask;

typedef struct pdHelpDesk {
  _Atomic(pdHelpTask*) posted;  // a half loop waiting for a server, or NULL
  atomic_int servers;           // threads serving now
  atomic_int sleepers;          // of them, asleep on `wake` (nothing posted for a while)
  atomic_int holdOff;           // loops to run without posting (help_desk.c)
  atomic_int votes, against;    // helped loops in the current window, and those whose help cost time
  atomic_long served;           // half loops a server ran (how much help was given; no result depends on it)
  pthread_mutex_t lock;         // guards the sleep on `wake`
  pthread_cond_t wake;          // a post, or the end of the servers' batch
} pdHelpDesk;

void pd_help_desk_init(pdHelpDesk* desk);
void pd_help_desk_destroy(pdHelpDesk* desk);

// Wakes every sleeping server: call it when *pending (pd_help_serve's) drops to 0.
void pd_help_wake_all(pdHelpDesk* desk);

// Moving bodies below which a per-body loop is not split (forces' sums, poses and the dynamics of a derivative
// evaluation: ~50 ns per body against a handover of about a microsecond).
#define PD_HELP_MIN_BODIES 128

// pd_help_for's loop that may be split: a desk, at least minSplit and 2 indices.
void pd_help_for_split(pdHelpDesk* desk, int n, int minSplit, pdRangeFcn* f, void* ctx);

// Runs f over [0, n): f(ctx, 0, 0, n), or f(ctx, 0, 0, n/2) and f(ctx, 1, n/2, n). With a desk, at least minSplit
// indices and a server waiting, the second half is posted and the first run here; the second half is taken back and run
// here too when no server took it by then. Inline: a loop too short to split (every loop of a small island, several
// per derivative evaluation) is a direct call of f at the loop's site.
static inline void pd_help_for(pdHelpDesk* desk, int n, int minSplit, pdRangeFcn* f, void* ctx) {
  PD_ASSERT(n >= 0 && f != NULL);
  if (!desk || n < minSplit || n < 2) {
    f(ctx, 0, 0, n);
    return;
  }
  pd_help_for_split(desk, n, minSplit, f, ctx);
}

// Serves the desk (runs what is posted) while *pending is nonzero. Spins: a server has nothing else to do.
void pd_help_serve(pdHelpDesk* desk, const atomic_int* pending);
