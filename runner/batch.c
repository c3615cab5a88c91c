// polydyn runner — batch runs over worker processes and MPI ranks (batch.h).
//
// Locally, workers are fork()ed children: a counter in a shared anonymous mapping hands out the next task,
// each worker sends (task, size, bytes) back over its own pipe. Over MPI, rank r takes every R-th task
// (no master that does no work, no scheduler of our own), runs its share with its local workers, and the
// shares are gathered (MPI_Gatherv / MPI_Allgatherv) and put back in task order.
// MAP_ANONYMOUS is not in POSIX.1-2008 (it is in Linux, the BSDs and POSIX.1-2024)
#define _DEFAULT_SOURCE

#include <errno.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#ifdef PD_HAVE_MPI
#include <mpi.h>
#endif

#include "pdrun/batch.h"
#include "polydyn/error.h"

// How often the parent asks `progress` whether to go on while no task finishes, ms.
#define BATCH_POLL_MS 200

// ---------------------------------------------------------------- buffers

void pd_batch_append(pdBatchBuffer* b, const void* data, size_t size) {
  if (size == 0) return;
  if (b->size + size > b->capacity) {
    size_t capacity = b->capacity ? b->capacity : 256;
    while (capacity < b->size + size) capacity *= 2;
    unsigned char* grown = realloc(b->data, capacity);
    if (!grown) abort();
    b->data = grown;
    b->capacity = capacity;
  }
  memcpy(b->data + b->size, data, size);
  b->size += size;
}

void pd_batch_buffer_free(pdBatchBuffer* b) {
  free(b->data);
  *b = (pdBatchBuffer){0};
}

bool pd_batch_read(const pdBatchBuffer* b, size_t* offset, void* out, size_t size) {
  if (*offset > b->size || b->size - *offset < size) {
    memset(out, 0, size);
    return false;
  }
  memcpy(out, b->data + *offset, size);
  *offset += size;
  return true;
}

// ---------------------------------------------------------------- MPI ranks

static int worldRank = 0, worldSize = 1;
#ifdef PD_HAVE_MPI
static bool mpiJoined = false;
#endif

#ifndef PD_HAVE_MPI
static long env_long(const char* name) {
  const char* v = getenv(name);
  return v ? strtol(v, NULL, 10) : 0;
}
#endif

static bool launched_by_mpi(void) {
  return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_SIZE") || getenv("PMI_RANK");
}

bool pd_batch_mpi_start(int* argc, char*** argv, char* why, size_t whySize) {
  if (!launched_by_mpi()) return true;
#ifdef PD_HAVE_MPI
  if (MPI_Init(argc, argv) != MPI_SUCCESS) {
    snprintf(why, whySize, "MPI_Init failed");
    return false;
  }
  mpiJoined = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &worldRank);
  MPI_Comm_size(MPI_COMM_WORLD, &worldSize);
  return true;
#else
  (void)argc, (void)argv;
  long size = env_long("OMPI_COMM_WORLD_SIZE") > 1 ? env_long("OMPI_COMM_WORLD_SIZE") : env_long("PMI_SIZE");
  if (size > 1) {
    snprintf(why, whySize, "started by an MPI launcher with %ld processes, but this build of polydyn has no MPI "
             "(configure with -DPD_MPI=ON and libopenmpi-dev installed)", size);
    return false;
  }
  return true;
#endif
}

void pd_batch_mpi_stop(void) {
#ifdef PD_HAVE_MPI
  if (mpiJoined) MPI_Finalize();
  mpiJoined = false;
#endif
}

int pd_batch_rank(void) { return worldRank; }
int pd_batch_ranks(void) { return worldSize; }

void pd_batch_share(void* data, size_t size) {
#ifdef PD_HAVE_MPI
  if (worldSize > 1) {
    PD_ASSERT(size <= INT_MAX);
    MPI_Bcast(data, (int)size, MPI_BYTE, 0, MPI_COMM_WORLD);
  }
#else
  (void)data, (void)size;
#endif
}

// ---------------------------------------------------------------- local workers

typedef struct localRun {
  const int* tasks;  // this rank's tasks
  int count;
  pdBatchTaskFcn* task;
  void* user;
  const pdBatchOptions* options;
  pdBatchBuffer* results;  // indexed by task number
  char* why;
  size_t whySize;
} localRun;

static bool go_on(const localRun* r, int task, int done) {
  const pdBatchOptions* o = r->options;
  if (!o->progress || o->progress(task, done, r->count, o->progressUser)) return true;
  snprintf(r->why, r->whySize, "stopped after %d of %d tasks", done, r->count);
  return false;
}

static bool run_inline(const localRun* r) {
  if (!go_on(r, -1, 0)) return false;
  for (int k = 0; k < r->count; ++k) {
    int t = r->tasks[k];
    r->task(t, &r->results[t], r->user);
    if (!go_on(r, t, k + 1)) return false;
  }
  return true;
}

static bool write_all(int fd, const void* data, size_t size) {
  const unsigned char* p = data;
  while (size > 0) {
    ssize_t n = write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= (size_t)n;
  }
  return true;
}

// Reads exactly size bytes; returns size, 0 at end of file before the first byte, -1 otherwise.
static ssize_t read_all(int fd, void* data, size_t size) {
  unsigned char* p = data;
  size_t got = 0;
  while (got < size) {
    ssize_t n = read(fd, p + got, size - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return got == 0 && n == 0 ? 0 : -1;
    got += (size_t)n;
  }
  return (ssize_t)got;
}

// What a worker sends per task, before the result's bytes.
typedef struct taskHeader {
  int32_t position;  // in this rank's task list
  uint32_t unused;
  uint64_t size;
} taskHeader;

static _Noreturn void worker_main(const localRun* r, atomic_int* next, int fd) {
  // an interrupt ends a worker at once (the parent cleans up), never through its parent's handler
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  for (int k; (k = atomic_fetch_add(next, 1)) < r->count;) {
    pdBatchBuffer result = {0};
    r->task(r->tasks[k], &result, r->user);
    taskHeader h = {.position = k, .size = result.size};
    bool sent = write_all(fd, &h, sizeof h) && write_all(fd, result.data, result.size);
    pd_batch_buffer_free(&result);
    if (!sent) _exit(1);
  }
  fflush(NULL);
  _exit(0);
}

// Reads one message from a worker's pipe into the results; 1 a task arrived, 0 the pipe closed, -1 broken.
static int receive(const localRun* r, int fd, int* task) {
  taskHeader h;
  ssize_t got = read_all(fd, &h, sizeof h);
  if (got <= 0) return (int)got;
  if (h.position < 0 || h.position >= r->count || h.size > SIZE_MAX / 2) return -1;
  *task = r->tasks[h.position];
  pdBatchBuffer* out = &r->results[*task];
  pd_batch_buffer_free(out);
  out->data = malloc(h.size ? (size_t)h.size : 1);
  if (!out->data) abort();
  out->size = out->capacity = (size_t)h.size;
  return read_all(fd, out->data, out->size) == (ssize_t)out->size ? 1 : -1;
}

static bool run_workers(const localRun* r, int workers) {
  atomic_int* next = mmap(NULL, sizeof *next, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (next == MAP_FAILED) {
    snprintf(r->why, r->whySize, "cannot map shared memory for the workers: %s", strerror(errno));
    return false;
  }
  atomic_init(next, 0);
  pid_t* pids = calloc((size_t)workers, sizeof *pids);
  struct pollfd* fds = calloc((size_t)workers, sizeof *fds);
  if (!pids || !fds) abort();
  fflush(NULL);  // nothing buffered may be written twice
  bool ok = go_on(r, -1, 0);
  int started = 0;
  for (; ok && started < workers; ++started) {
    int pipeEnds[2];
    if (pipe(pipeEnds) != 0) {
      snprintf(r->why, r->whySize, "cannot make a pipe for a worker: %s", strerror(errno));
      ok = false;
      break;
    }
    pid_t pid = fork();
    if (pid == 0) {
      close(pipeEnds[0]);
      for (int w = 0; w < started; ++w) close(fds[w].fd);
      worker_main(r, next, pipeEnds[1]);
    }
    close(pipeEnds[1]);
    if (pid < 0) {
      close(pipeEnds[0]);
      snprintf(r->why, r->whySize, "cannot start a worker process: %s", strerror(errno));
      ok = false;
      break;
    }
    pids[started] = pid;
    fds[started] = (struct pollfd){.fd = pipeEnds[0], .events = POLLIN};
  }

  // collect: results as they come, progress after each, until every pipe has closed
  int open = started, done = 0;
  while (ok && open > 0) {
    int ready = poll(fds, (nfds_t)started, BATCH_POLL_MS);
    if (ready < 0 && errno != EINTR) {
      snprintf(r->why, r->whySize, "cannot watch the workers: %s", strerror(errno));
      ok = false;
    } else if (ready <= 0) {
      ok = go_on(r, -1, done);
    }
    for (int w = 0; ok && ready > 0 && w < started; ++w) {
      if (fds[w].fd < 0 || !(fds[w].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      int task = -1, got = receive(r, fds[w].fd, &task);
      if (got == 1) {
        ok = go_on(r, task, ++done);
        continue;
      }
      close(fds[w].fd);
      fds[w].fd = -1;
      --open;
      if (got < 0) {
        snprintf(r->why, r->whySize, "a worker process sent a broken result");
        ok = false;
      }
    }
  }
  for (int w = 0; w < started; ++w) {
    if (!ok) kill(pids[w], SIGTERM);
    if (fds[w].fd >= 0) close(fds[w].fd);
  }
  for (int w = 0; w < started; ++w) {
    int status;
    while (waitpid(pids[w], &status, 0) < 0 && errno == EINTR) {
    }
    if (ok && (!WIFEXITED(status) || WEXITSTATUS(status) != 0)) {
      if (WIFSIGNALED(status)) snprintf(r->why, r->whySize, "a worker process died (signal %d)", WTERMSIG(status));
      else snprintf(r->why, r->whySize, "a worker process failed");
      ok = false;
    }
  }
  if (ok && done != r->count) {
    snprintf(r->why, r->whySize, "the workers finished %d of %d tasks", done, r->count);
    ok = false;
  }
  free(fds);
  free(pids);
  munmap(next, sizeof *next);
  return ok;
}

// ---------------------------------------------------------------- gathering over ranks

#ifdef PD_HAVE_MPI
// Puts every rank's results in place (on rank 0, or everywhere); collective. `ok` is this rank's outcome.
static bool gather(int count, pdBatchBuffer* results, bool ok, bool everywhere, char* why, size_t whySize) {
  // this rank's share, packed: (uint64 size, bytes) per task, in task order
  pdBatchBuffer packed = {0};
  for (int t = worldRank; ok && t < count; t += worldSize) {
    uint64_t size = results[t].size;
    pd_batch_append(&packed, &size, sizeof size);
    pd_batch_append(&packed, results[t].data, results[t].size);
  }
  int* sizes = calloc((size_t)worldSize, sizeof *sizes);
  int* offsets = calloc((size_t)worldSize, sizeof *offsets);
  if (!sizes || !offsets) abort();
  int mine = ok && packed.size <= INT_MAX ? (int)packed.size : -1;
  MPI_Allgather(&mine, 1, MPI_INT, sizes, 1, MPI_INT, MPI_COMM_WORLD);
  long long total = 0;
  bool allOk = true;
  for (int r = 0; r < worldSize; ++r) {
    allOk = allOk && sizes[r] >= 0;
    offsets[r] = (int)(total < INT_MAX ? total : 0);
    total += sizes[r] > 0 ? sizes[r] : 0;
  }
  if (allOk && total > INT_MAX) {
    snprintf(why, whySize, "the results of the ranks (%lld bytes) exceed what one gather carries (2 GiB)", total);
    allOk = false;
  } else if (ok && !allOk) {
    snprintf(why, whySize, "another MPI rank failed (see its messages)");
  }
  bool root = worldRank == 0;
  unsigned char* all = NULL;
  if (allOk) {
    all = malloc(total > 0 ? (size_t)total : 1);
    if (!all) abort();
    if (everywhere)
      MPI_Allgatherv(packed.data, mine, MPI_BYTE, all, sizes, offsets, MPI_BYTE, MPI_COMM_WORLD);
    else
      MPI_Gatherv(packed.data, mine, MPI_BYTE, all, sizes, offsets, MPI_BYTE, 0, MPI_COMM_WORLD);
  }
  pd_batch_buffer_free(&packed);
  if (allOk && (everywhere || root)) {
    for (int r = 0; r < worldSize; ++r) {
      if (r == worldRank) continue;
      pdBatchBuffer share = {all + offsets[r], (size_t)sizes[r], (size_t)sizes[r]};
      size_t at = 0;
      for (int t = r; t < count; t += worldSize) {
        uint64_t size = 0;
        pd_batch_read(&share, &at, &size, sizeof size);
        PD_ASSERT(size <= share.size - at);
        pd_batch_buffer_free(&results[t]);
        pd_batch_append(&results[t], share.data + at, (size_t)size);
        at += (size_t)size;
      }
    }
  } else {
    for (int t = 0; t < count; ++t) pd_batch_buffer_free(&results[t]);
  }
  free(all);
  free(sizes);
  free(offsets);
  return allOk;
}
#endif

bool pd_batch_run(int count, pdBatchTaskFcn* task, void* user, const pdBatchOptions* options, pdBatchBuffer* results,
                  char* why, size_t whySize) {
  PD_ASSERT(count >= 0 && task && options && options->workers >= 1 && (results || count == 0));
  for (int t = 0; t < count; ++t) results[t] = (pdBatchBuffer){0};
  int* mine = malloc(((size_t)count + 1) * sizeof *mine);
  if (!mine) abort();
  int n = 0;
  for (int t = worldRank; t < count; t += worldSize) mine[n++] = t;
  localRun r = {mine, n, task, user, options, results, why, whySize};
  int workers = options->workers < n ? options->workers : n;
  bool ok = workers <= 1 ? run_inline(&r) : run_workers(&r, workers);
  free(mine);
#ifdef PD_HAVE_MPI
  if (worldSize > 1) return gather(count, results, ok, options->everywhere, why, whySize);
#endif
  if (!ok)
    for (int t = 0; t < count; ++t) pd_batch_buffer_free(&results[t]);
  return ok;
}
