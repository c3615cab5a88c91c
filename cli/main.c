// polydyn — the command line: main() (the dispatch and the subcommands are in the polydyn_cli library).
#include <signal.h>
#include <stdio.h>

#include "cli.h"
#include "pdrun/batch.h"

// Under mpirun or srun every rank runs the same command: the batch commands split their tasks over the
// ranks (runner/include/pdrun/batch.h) and rank 0 alone prints and writes the results.
int main(int argc, char** argv) {
  char why[512];
  if (!pd_batch_mpi_start(&argc, &argv, why, sizeof why)) {
    fprintf(stderr, "polydyn: %s\n", why);
    return PD_EXIT_BAD_INPUT;
  }
  if (!pd_batch_is_root() && !freopen("/dev/null", "w", stdout)) return PD_EXIT_FAILURE;
  // A file-size limit (ulimit -f) must end in a failed write that the command reports and cleans up after,
  // like a full disk, not in SIGXFSZ killing the process with a temporary directory left behind.
  signal(SIGXFSZ, SIG_IGN);
  int status = pd_cli_dispatch(argc, argv);
  pd_batch_mpi_stop();
  return status;
}
