// polydyn — the help desk (help_desk.h): one posted half loop at a time, handed over by compare-and-swap.
//
// The task lives on the poster's stack: the poster returns only after it ran the half itself (taken back) or
// saw the server's done flag, so the server never touches a task after it is gone. The poster's inputs are
// written before the task is posted (a sequentially consistent exchange) and the server's outputs before its
// done flag (release; the poster reads it with acquire).
//
// Two guards keep help from costing more than it gives (on a 360-brick block, one island, the second thread
// sometimes ran its half 3× slower than the first and the first's own loops 3× slower while it spun, as when both
// virtual CPUs share one physical core: two threads were then slower than one):
// - a server that found nothing to do for PD_HELP_SPIN_SECONDS sleeps on a condition variable; a post wakes it
//   (the poster takes its half back if the server is late) and so does the end of the batch;
// - when most of PD_HELP_VOTES helped loops waited for the server's half longer than their own half took, the
//   posters post nothing for the next PD_HELP_HOLD_OFF_LOOPS loops, then try again.
// Either way every index is computed by the same function from the same inputs: results do not change.
#include "help_desk.h"

#include <stddef.h>

#include "clock.h"
#include "polydyn/error.h"

struct pdHelpTask {
  pdRangeFcn* f;
  void* ctx;
  int begin, end;
  atomic_int done;
};

// A server spins this long (s) without a task before it sleeps: about the gap between two derivative
// evaluations of an island whose loops are split, so that a stream of posts finds it awake.
#define PD_HELP_SPIN_SECONDS 200e-6
// Spins between two clock reads of a server (a read costs ~25 ns, a spin ~20 ns).
#define PD_HELP_SPINS_PER_CHECK 64
// Helped loops per vote, and loops run alone after a vote in which most helped loops waited for the server
// longer than their own half took.
#define PD_HELP_VOTES 32
#define PD_HELP_HOLD_OFF_LOOPS 256

static inline void relax(void) {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

void pd_help_desk_init(pdHelpDesk* desk) {
  atomic_init(&desk->posted, NULL);
  atomic_init(&desk->servers, 0);
  atomic_init(&desk->sleepers, 0);
  atomic_init(&desk->holdOff, 0);
  atomic_init(&desk->votes, 0);
  atomic_init(&desk->against, 0);
  atomic_init(&desk->served, 0);
  PD_ASSERT(pthread_mutex_init(&desk->lock, NULL) == 0 && pthread_cond_init(&desk->wake, NULL) == 0);
}

void pd_help_desk_destroy(pdHelpDesk* desk) {
  pthread_cond_destroy(&desk->wake);
  pthread_mutex_destroy(&desk->lock);
}

void pd_help_wake_all(pdHelpDesk* desk) {
  pthread_mutex_lock(&desk->lock);
  pthread_cond_broadcast(&desk->wake);
  pthread_mutex_unlock(&desk->lock);
}

void pd_help_for_split(pdHelpDesk* desk, int n, int minSplit, pdRangeFcn* f, void* ctx) {
  PD_ASSERT(desk != NULL && n >= minSplit && n >= 2 && f != NULL);
  if (atomic_load_explicit(&desk->servers, memory_order_relaxed) == 0) {
    f(ctx, 0, 0, n);
    return;
  }
  if (atomic_load_explicit(&desk->holdOff, memory_order_relaxed) > 0) {
    atomic_fetch_sub_explicit(&desk->holdOff, 1, memory_order_relaxed);
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
  if (atomic_load(&desk->sleepers) > 0) pd_help_wake_all(desk);
  double t0 = pd_clock_seconds();
  f(ctx, 0, 0, mid);
  double t1 = pd_clock_seconds();
  pdHelpTask* mine = &task;
  if (atomic_compare_exchange_strong(&desk->posted, &mine, NULL)) {  // not taken: run it here
    f(ctx, 1, mid, n);
    return;
  }
  while (!atomic_load_explicit(&task.done, memory_order_acquire)) relax();
  // the vote: did this help save time (the wait shorter than the own half)? A window of votes decides
  bool costly = pd_clock_seconds() - t1 > t1 - t0;
  int votes = atomic_fetch_add_explicit(&desk->votes, 1, memory_order_relaxed) + 1;
  int against = costly ? atomic_fetch_add_explicit(&desk->against, 1, memory_order_relaxed) + 1
                       : atomic_load_explicit(&desk->against, memory_order_relaxed);
  if (votes >= PD_HELP_VOTES) {
    if (2 * against > votes) atomic_store_explicit(&desk->holdOff, PD_HELP_HOLD_OFF_LOOPS, memory_order_relaxed);
    atomic_store_explicit(&desk->votes, 0, memory_order_relaxed);
    atomic_store_explicit(&desk->against, 0, memory_order_relaxed);
  }
}

// Sleeps until a task is posted or nothing is pending. The sleeper count is raised before `posted` is read, and
// a poster reads the count after posting (both sequentially consistent), so one of them sees the other.
static void sleep_until_posted(pdHelpDesk* desk, const atomic_int* pending) {
  pthread_mutex_lock(&desk->lock);
  atomic_fetch_add(&desk->sleepers, 1);
  while (atomic_load(&desk->posted) == NULL && atomic_load(pending) != 0) pthread_cond_wait(&desk->wake, &desk->lock);
  atomic_fetch_sub(&desk->sleepers, 1);
  pthread_mutex_unlock(&desk->lock);
}

void pd_help_serve(pdHelpDesk* desk, const atomic_int* pending) {
  atomic_fetch_add(&desk->servers, 1);
  double idleSince = pd_clock_seconds();
  long spins = 0;
  while (atomic_load_explicit(pending, memory_order_acquire) != 0) {
    pdHelpTask* t = atomic_load_explicit(&desk->posted, memory_order_relaxed);
    if (t && atomic_compare_exchange_strong(&desk->posted, &t, NULL)) {
      t->f(t->ctx, 1, t->begin, t->end);
      atomic_fetch_add_explicit(&desk->served, 1, memory_order_relaxed);
      atomic_store_explicit(&t->done, 1, memory_order_release);
      idleSince = pd_clock_seconds();
      continue;
    }
    relax();
    if (++spins % PD_HELP_SPINS_PER_CHECK == 0 && pd_clock_seconds() - idleSince > PD_HELP_SPIN_SECONDS) {
      sleep_until_posted(desk, pending);
      idleSince = pd_clock_seconds();
    }
  }
  atomic_fetch_sub(&desk->servers, 1);
}
