// polydyn runner — batch runs: a list of independent tasks run in local worker processes or split over
// MPI ranks, their results gathered in task order (runner/batch.c).
//
// A task is a function of its index that may write files (under a directory every process sees) and
// returns bytes. Whoever ran a task and in whatever order, task i's bytes land in results[i], so what the
// caller writes from them never depends on the scheduling. Used by polydyn gedanken, sweep, cubetoss and
// compare (docs/commands.md).
#pragma once

#include <stdbool.h>
#include <stddef.h>

// ---------------------------------------------------------------- MPI ranks

// When the process was started by an MPI launcher (mpirun, srun: OMPI_COMM_WORLD_SIZE, PMIX_RANK or
// PMI_SIZE in the environment) and this build has MPI, joins the world (MPI_Init); otherwise it is a world
// of one and MPI is never initialised, so a plain `polydyn` never pays for it. Returns false with a
// message in why when it was started by a launcher but cannot join (a build without MPI under a launcher
// of more than one process: every process would do all the work).
bool pd_batch_mpi_start(int* argc, char*** argv, char* why, size_t whySize);
// MPI_Finalize when pd_batch_mpi_start joined a world.
void pd_batch_mpi_stop(void);
int pd_batch_rank(void);   // 0 in a world of one
int pd_batch_ranks(void);  // 1 in a world of one
static inline bool pd_batch_is_root(void) { return pd_batch_rank() == 0; }
// Copies `size` bytes at data from rank 0 to every rank (a no-op in a world of one).
void pd_batch_share(void* data, size_t size);

// ---------------------------------------------------------------- results

typedef struct pdBatchBuffer {
  unsigned char* data;
  size_t size, capacity;
} pdBatchBuffer;

void pd_batch_append(pdBatchBuffer* buffer, const void* data, size_t size);
void pd_batch_buffer_free(pdBatchBuffer* buffer);
// Reads `size` bytes at *offset into out and advances it; false (out zeroed) past the end.
bool pd_batch_read(const pdBatchBuffer* buffer, size_t* offset, void* out, size_t size);

// ---------------------------------------------------------------- running

// One task: appends its result to `result` (empty at the call).
typedef void pdBatchTaskFcn(int task, pdBatchBuffer* result, void* user);
// Called on the calling process as this rank's tasks finish: `task` the one just finished (-1 before the
// first), done of total of this rank. Returning false stops the work.
typedef bool pdBatchProgressFcn(int task, int done, int total, void* user);

typedef struct pdBatchOptions {
  int workers;      // local worker processes of each rank (1: the tasks run in the calling process)
  bool everywhere;  // results on every rank (false: on rank 0 only, the others get empty buffers)
  pdBatchProgressFcn* progress;  // nullable
  void* progressUser;
} pdBatchOptions;

// Runs tasks 0 .. count-1: rank r of R takes tasks r, r+R, r+2R, ... and hands them out one at a time to
// its `workers` forked processes (processes, not threads: the reference engines' libraries keep global
// state). Fills results[0 .. count) (free each with pd_batch_buffer_free). Every rank must call it with
// the same count (it is collective). Returns false on every rank, with a message in why, when a worker
// died, progress asked to stop, or any rank failed.
bool pd_batch_run(int count, pdBatchTaskFcn* task, void* user, const pdBatchOptions* options, pdBatchBuffer* results,
                  char* why, size_t whySize);
