// polydyn refcheck — running independent jobs (tosses) in worker processes (cubetoss.h).
//
// Workers are fork()ed children sharing one anonymous mapping: a counter hands out the next job, each job
// writes its result into its own slot, a second counter tells the parent how many are done. A job's
// result depends only on the job, so the results are the same whichever worker ran it and however the
// two were scheduled. Processes rather than threads: the reference engines' libraries keep global state.
// MAP_ANONYMOUS is not in POSIX.1-2008 (it is in Linux, the BSDs and POSIX.1-2024)
#define _DEFAULT_SOURCE

#include <errno.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "polydyn/cubetoss.h"

// The parent looks at the workers this often, s: progress on a terminal needs no more.
#define POOL_POLL_SECONDS 0.02

typedef struct poolShared {
  atomic_int next;  // the next job to hand out
  atomic_int done;  // jobs finished
} poolShared;

static void sleep_seconds(double s) {
  struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

static bool run_inline(int count, size_t resultSize, unsigned char* results, pdTossJobFcn* job, void* user,
                       pdTossProgressFcn* progress, void* progressUser, char* why, size_t whySize) {
  if (progress && !progress(0, count, progressUser)) {
    snprintf(why, whySize, "stopped");
    return false;
  }
  for (int i = 0; i < count; ++i) {
    memset(results + (size_t)i * resultSize, 0, resultSize);
    job(i, results + (size_t)i * resultSize, user);
    if (progress && !progress(i + 1, count, progressUser)) {
      snprintf(why, whySize, "stopped after %d of %d", i + 1, count);
      return false;
    }
  }
  return true;
}

bool pd_toss_parallel(int count, int workers, size_t resultSize, void* results, pdTossJobFcn* job, void* user,
                      pdTossProgressFcn* progress, void* progressUser, char* why, size_t whySize) {
  PD_ASSERT(count >= 0 && workers >= 1 && resultSize > 0 && (results || count == 0) && job);
  if (workers > count) workers = count;
  if (workers <= 1) return run_inline(count, resultSize, results, job, user, progress, progressUser, why, whySize);

  // the shared mapping: counters, then the result slots
  size_t header = (sizeof(poolShared) + 63) / 64 * 64;
  size_t bytes = header + (size_t)count * resultSize;
  void* map = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (map == MAP_FAILED) {
    snprintf(why, whySize, "cannot map shared memory for the workers: %s", strerror(errno));
    return false;
  }
  poolShared* shared = map;
  unsigned char* slots = (unsigned char*)map + header;
  atomic_init(&shared->next, 0);
  atomic_init(&shared->done, 0);

  pid_t* pids = calloc((size_t)workers, sizeof *pids);
  if (!pids) abort();
  fflush(NULL);  // nothing buffered may be written twice
  bool ok = true;
  int started = 0;
  for (; started < workers; ++started) {
    pid_t pid = fork();
    if (pid < 0) {
      snprintf(why, whySize, "cannot start a worker process: %s", strerror(errno));
      ok = false;
      break;
    }
    if (pid == 0) {
      // a worker: an interrupt ends it at once (the parent cleans up), never its parent's handler
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      for (int i; (i = atomic_fetch_add(&shared->next, 1)) < count;) {
        unsigned char* slot = slots + (size_t)i * resultSize;
        memset(slot, 0, resultSize);
        job(i, slot, user);
        atomic_fetch_add(&shared->done, 1);
      }
      fflush(NULL);
      _exit(0);
    }
    pids[started] = pid;
  }

  // watch the workers: progress as jobs finish, stop them all when asked or when one dies
  int live = started, lastDone = -1;
  bool stopping = !ok;
  while (live > 0) {
    for (int w = 0; w < started; ++w) {
      if (pids[w] <= 0) continue;
      int status;
      pid_t got = waitpid(pids[w], &status, WNOHANG);
      if (got == 0 || (got < 0 && errno == EINTR)) continue;
      pids[w] = -1;
      --live;
      if (got < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        if (ok) {
          if (got > 0 && WIFSIGNALED(status))
            snprintf(why, whySize, "a worker process died (signal %d)", WTERMSIG(status));
          else
            snprintf(why, whySize, "a worker process failed");
        }
        ok = false;
        stopping = true;
      }
    }
    int done = atomic_load(&shared->done);
    if (!stopping && progress && done != lastDone) {
      lastDone = done;
      if (!progress(done, count, progressUser)) {
        snprintf(why, whySize, "stopped after %d of %d", done, count);
        ok = false;
        stopping = true;
      }
    }
    if (stopping)
      for (int w = 0; w < started; ++w)
        if (pids[w] > 0) kill(pids[w], SIGTERM);
    if (live > 0) sleep_seconds(POOL_POLL_SECONDS);
  }
  if (ok && atomic_load(&shared->done) != count) {
    snprintf(why, whySize, "the workers finished %d of %d jobs", atomic_load(&shared->done), count);
    ok = false;
  }
  if (ok && progress && lastDone != count && !progress(count, count, progressUser)) {
    snprintf(why, whySize, "stopped after %d of %d", count, count);
    ok = false;
  }
  if (ok) memcpy(results, slots, (size_t)count * resultSize);
  free(pids);
  munmap(map, bytes);
  return ok;
}
