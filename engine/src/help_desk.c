// polydyn — the help desk (help_desk.h): one posted half loop at a time, handed over by compare-and-swap.
//
// The task lives on the poster's stack: the poster returns only after it ran the half itself (taken back) or
// saw the server's done flag, so the server never touches a task after it is gone. The poster's inputs are
// written before the task is posted (a sequentially consistent exchange) and the server's outputs before its
// done flag (release; the poster reads it with acquire).
#include "help_desk.h"

#include <sched.h>
#include <stddef.h>

#include "polydyn/error.h"

struct pdHelpTask {
  pdRangeFcn* f;
  void* ctx;
  int begin, end;
  atomic_int done;
};

// Spins of a server between yields of its core: a few microseconds of spinning (what a posting thread's
// half loop takes) before the scheduler may give the core to another process.
#define PD_HELP_SPINS_PER_YIELD 4096

static inline void relax(void) {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

void pd_help_desk_init(pdHelpDesk* desk) {
  atomic_init(&desk->posted, NULL);
  atomic_init(&desk->servers, 0);
  atomic_init(&desk->served, 0);
}

void pd_help_for(pdHelpDesk* desk, int n, int minSplit, pdRangeFcn* f, void* ctx) {
  PD_ASSERT(n >= 0 && f != NULL);
  if (!desk || n < minSplit || n < 2 || atomic_load_explicit(&desk->servers, memory_order_relaxed) == 0) {
    f(ctx, 0, 0, n);
    return;
  }
  int mid = n / 2;
  pdHelpTask task = {f, ctx, mid, n, 0};
  atomic_init(&task.done, 0);
  pdHelpTask* none = NULL;
  if (!atomic_compare_exchange_strong(&desk->posted, &none, &task)) {  // another island's half is waiting
    f(ctx, 0, 0, n);
    return;
  }
  f(ctx, 0, 0, mid);
  pdHelpTask* mine = &task;
  if (atomic_compare_exchange_strong(&desk->posted, &mine, NULL)) {  // not taken: run it here
    f(ctx, 1, mid, n);
    return;
  }
  while (!atomic_load_explicit(&task.done, memory_order_acquire)) relax();
}

void pd_help_serve(pdHelpDesk* desk, const atomic_int* pending) {
  atomic_fetch_add(&desk->servers, 1);
  long spins = 0;
  while (atomic_load_explicit(pending, memory_order_acquire) != 0) {
    pdHelpTask* t = atomic_load_explicit(&desk->posted, memory_order_relaxed);
    if (t && atomic_compare_exchange_strong(&desk->posted, &t, NULL)) {
      t->f(t->ctx, 1, t->begin, t->end);
      atomic_fetch_add_explicit(&desk->served, 1, memory_order_relaxed);
      atomic_store_explicit(&t->done, 1, memory_order_release);
      spins = 0;
      continue;
    }
    relax();
    if (++spins % PD_HELP_SPINS_PER_YIELD == 0) sched_yield();
  }
  atomic_fetch_sub(&desk->servers, 1);
}
