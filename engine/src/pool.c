// polydyn — the islands' thread pool (pool.h). The workers sleep on `wake` between batches; a batch is published
// under the lock with a new generation, each worker takes jobs from the shared counter, then serves the help desk
// until no job of the batch is left running, and the caller waits on `done` for the last worker.
#include "pool.h"

#include <stdlib.h>

#include "grow.h"
#include "polydyn/error.h"

static int compare_jobs(const void* a, const void* b) {
  const pdPoolOrder *x = a, *y = b;
  if (x->weight != y->weight) return x->weight > y->weight ? -1 : 1;
  return (x->job > y->job) - (x->job < y->job);
}

// Takes the batch's jobs in order, one at a time, until none is left; then, with other threads, serves the help desk
// until every job is finished (the jobs still running post half their loops there).
static void run_jobs(pdPool* pool) {
  for (int n; (n = atomic_fetch_add(&pool->nextJob, 1)) < pool->jobCount;) {
    pool->run(pool->ctx, pool->order[n].job);
    if (atomic_fetch_sub(&pool->jobsLeft, 1) == 1 && pool->threadCount > 1) pd_help_wake_all(&pool->desk);
  }
  if (pool->threadCount > 1) pd_help_serve(&pool->desk, &pool->jobsLeft);
}

static void* worker_main(void* user) {
  pdPool* pool = user;
  long seen = 0;
  pthread_mutex_lock(&pool->lock);
  for (;;) {
    while (!pool->quit && pool->generation == seen) pthread_cond_wait(&pool->wake, &pool->lock);
    if (pool->quit) break;
    seen = pool->generation;
    pthread_mutex_unlock(&pool->lock);
    run_jobs(pool);
    pthread_mutex_lock(&pool->lock);
    if (--pool->pending == 0) pthread_cond_signal(&pool->done);
  }
  pthread_mutex_unlock(&pool->lock);
  return NULL;
}

static void pool_stop(pdPool* pool) {
  if (pool->threadCount > 1) {
    pthread_mutex_lock(&pool->lock);
    pool->quit = true;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->lock);
    for (int w = 0; w < pool->threadCount - 1; ++w) pthread_join(pool->workers[w], NULL);
    pthread_cond_destroy(&pool->wake);
    pthread_cond_destroy(&pool->done);
    pthread_mutex_destroy(&pool->lock);
  }
  free(pool->workers);
  pool->workers = NULL;
  pool->threadCount = 0;
}

static void pool_start(pdPool* pool, int threads) {
  pool->threadCount = threads;
  pool->quit = false;
  pool->generation = 0;
  pool->pending = 0;
  if (threads == 1) return;
  pool->workers = pd_grow(NULL, (size_t)threads - 1, sizeof *pool->workers);
  PD_ASSERT(pthread_mutex_init(&pool->lock, NULL) == 0 && pthread_cond_init(&pool->wake, NULL) == 0 &&
            pthread_cond_init(&pool->done, NULL) == 0);
  for (int w = 0; w < threads - 1; ++w) {
    PD_ASSERT(pthread_create(&pool->workers[w], NULL, worker_main, pool) == 0);
  }
}

void pd_pool_init(pdPool* pool, int threads) {
  pd_help_desk_init(&pool->desk);
  pool_start(pool, threads);
}

void pd_pool_destroy(pdPool* pool) {
  pool_stop(pool);
  pd_help_desk_destroy(&pool->desk);
}

void pd_pool_resize(pdPool* pool, int threads) {
  if (pool->threadCount == threads) return;
  pool_stop(pool);
  pool_start(pool, threads);
}

void pd_pool_run(pdPool* pool, pdPoolOrder* order, int count, long helpWeight, pdPoolJobFcn* run, void* ctx) {
  if (pool->threadCount > 1) qsort(order, (size_t)count, sizeof *order, compare_jobs);
  pool->order = order;
  pool->jobCount = count;
  pool->run = run;
  pool->ctx = ctx;
  atomic_store(&pool->nextJob, 0);
  atomic_store(&pool->jobsLeft, count);
  // one job alone gets the other threads' help when it is heavy enough to split its loops
  bool parallel = pool->threadCount > 1 && (count > 1 || (count == 1 && order[0].weight >= helpWeight));
  if (parallel) {
    pthread_mutex_lock(&pool->lock);
    pool->pending = pool->threadCount - 1;
    ++pool->generation;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->lock);
  }
  run_jobs(pool);
  if (parallel) {
    pthread_mutex_lock(&pool->lock);
    while (pool->pending > 0) pthread_cond_wait(&pool->done, &pool->lock);
    pthread_mutex_unlock(&pool->lock);
  }
}
