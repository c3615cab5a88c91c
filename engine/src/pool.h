// polydyn (internal) — the islands' thread pool (islands.c, design note, "Threads"): the caller and threadCount − 1
// workers run a batch of jobs, each job whole on one thread, taken heaviest first from a shared counter when a thread
// is free; a thread left without a job serves the pool's help desk (help_desk.h) until every job of the batch is
// done. Which thread runs a job depends on timing; what a job computes must not.
#pragma once

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

#include "help_desk.h"

// Runs job `job` of the batch (ctx as given to pd_pool_run).
typedef void pdPoolJobFcn(void* ctx, int job);

// A job's weight, by which the threads take the jobs (the heaviest first, so that the last ones taken are small).
typedef struct pdPoolOrder {
  long weight;
  int job;
} pdPoolOrder;

typedef struct pdPool {
  int threadCount;
  pthread_t* workers;  // (threadCount - 1)
  pthread_mutex_t lock;
  pthread_cond_t wake;  // a new batch (generation) or quit
  pthread_cond_t done;  // pending reached 0
  long generation;      // batches handed out so far
  int pending;          // workers still running the batch
  bool quit;
  // the batch under way
  int jobCount;
  const pdPoolOrder* order;  // (jobCount) the order the jobs are taken in
  pdPoolJobFcn* run;
  void* ctx;
  atomic_int nextJob;   // the next entry of `order` to take
  atomic_int jobsLeft;  // jobs of the batch not finished yet
  pdHelpDesk desk;      // where a running job posts half loops for a thread without a job
} pdPool;

// Sets the desk up and starts `threads` threads in all: the caller and threads − 1 workers waiting for batches.
void pd_pool_init(pdPool* pool, int threads);
// Joins the workers and tears the desk down.
void pd_pool_destroy(pdPool* pool);
// Stops the workers and starts `threads` in all, when that is another count.
void pd_pool_resize(pdPool* pool, int threads);
// Runs jobs order[0 .. count).job, `order` sorted here heaviest first (equal weights in job order: a total order, so
// the order does not depend on qsort) when there are threads to share them. The workers are woken for two jobs or
// more, or for one of at least helpWeight (they then serve its help desk); the caller takes jobs too. Returns when
// every job has finished.
void pd_pool_run(pdPool* pool, pdPoolOrder* order, int count, long helpWeight, pdPoolJobFcn* run, void* ctx);
