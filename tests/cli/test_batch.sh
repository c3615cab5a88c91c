#!/usr/bin/env bash
# Batch runs (docs/commands.md; runner/include/pdrun/batch.h): one batch command on a small input,
# serially (--jobs 1), in two worker processes (--jobs 2) and split over three MPI ranks
# (mpirun --oversubscribe -np 3), must write the same files with the same bytes, except the measured times
# (same_outputs.py names them: wall/CPU time columns, the timing of summary.json, wall_seconds of JSON).
# COMMAND is gedanken, sweep, cubetoss (4 tosses of ../shared/data/cube-toss/, or 4 synthetic ones without
# the data, and a 3-evaluation fit) or compare (a directory of 4 scenes). MPIEXEC empty: a build without
# MPI; the MPI runs are then skipped (said on stdout), the rest still runs.
#
# usage: test_batch.sh POLYDYN_BINARY PROJECT_SOURCE_DIR COMMAND [MPIEXEC]
set -u
if [ $# -lt 3 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR COMMAND [MPIEXEC]" >&2
  exit 2
fi
PD=$1
SRC=$2
COMMAND=$3
MPIEXEC=${4:-}
HERE=$(dirname "${BASH_SOURCE[0]}")
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_batch.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$HERE/../lib.sh"  # check, no_partial
# CI runs as root: OpenMPI refuses that unless told it is meant
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
# containers often forbid the cross-process memory reads OpenMPI's shared-memory transport tries first
export OMPI_MCA_btl_vader_single_copy_mechanism=none

# the command's arguments but --out DIR; $ARGS is split on purpose
case $COMMAND in
  gedanken) ARGS="gedanken --only a1_restitution,c2_momentum,e1_painleve --engines soft,ode" ;;
  sweep) ARGS="sweep $SRC/cases/sweep/slide_to_rest.scene --engines soft,ode --tend 0.3 --repeats 1" ;;
  compare)
    mkdir "$SCRATCH/scenes"
    cp "$SRC"/cases/user/*.scene "$SCRATCH/scenes/"
    ARGS="compare $SCRATCH/scenes --tend 0.3 --engines soft,ode"
    ;;
  cubetoss | cubetoss-fit)
    DATA_FULL=$SRC/../shared/data/cube-toss/tosses-train.csv
    if [ -r "$DATA_FULL" ]; then
      awk -F, 'NR == 1 || $1 == 1 || $1 == 2 || $1 == 3 || $1 == 4' "$DATA_FULL" >"$SCRATCH/four.csv"
    else
      # a fresh clone (CI) has no ../shared: four synthetic tosses in the same layout
      echo "note: the cube-toss data is not at $DATA_FULL; four synthetic tosses (tests/reports/make_tosses.py)"
      python3 "$SRC/tests/reports/make_tosses.py" "$SCRATCH/four.csv" 4 || exit 1
    fi
    ARGS="cubetoss --data $SCRATCH/four.csv --engines soft,ode"
    [ "$COMMAND" = cubetoss-fit ] && ARGS="cubetoss fit --data $SCRATCH/four.csv --engines soft --max-evals 3"
    ;;
  *)
    echo "test_batch.sh: unknown command '$COMMAND'" >&2
    exit 2
    ;;
esac

# shellcheck disable=SC2086
"$PD" $ARGS --jobs 1 --out "$SCRATCH/serial" >"$SCRATCH/serial.out" 2>"$SCRATCH/serial.err"; rc=$?
check "$COMMAND serial: exit 0" '[ $rc -eq 0 ]'
# shellcheck disable=SC2086
"$PD" $ARGS --jobs 2 --out "$SCRATCH/jobs2" >"$SCRATCH/jobs2.out" 2>"$SCRATCH/jobs2.err"; rc=$?
check "$COMMAND --jobs 2: exit 0" '[ $rc -eq 0 ]'
check "$COMMAND --jobs 2: the serial run's files and bytes but the measured times" \
  'python3 "$HERE/same_outputs.py" "$SCRATCH/serial" "$SCRATCH/jobs2"'
if [ -n "$MPIEXEC" ]; then
  # Under ASan: OpenMPI never frees what MPI_Init allocates, much of it in components it unloads at
  # MPI_Finalize (their frames cannot be suppressed by name), so the leak check is off for these runs only;
  # the serial and --jobs runs above leak-check the same code of polydyn.
  # shellcheck disable=SC2086
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
  "$MPIEXEC" --oversubscribe -np 3 "$PD" $ARGS --out "$SCRATCH/mpi3" >"$SCRATCH/mpi3.out" 2>"$SCRATCH/mpi3.err"; rc=$?
  check "$COMMAND under mpirun -np 3: exit 0" '[ $rc -eq 0 ]' || cat "$SCRATCH/mpi3.err"
  check "$COMMAND under mpirun -np 3: the serial run's files and bytes but the measured times" \
    'python3 "$HERE/same_outputs.py" "$SCRATCH/serial" "$SCRATCH/mpi3"'
  check "$COMMAND under mpirun -np 3: one report on stdout (rank 0's), as the serial run's" \
    '[ "$(wc -l <"$SCRATCH/mpi3.out")" -eq "$(wc -l <"$SCRATCH/serial.out")" ]'
  check "$COMMAND under mpirun: no temporary directory left" 'no_partial "$SCRATCH/mpi3"'
else
  echo "note: this build has no MPI (PD_MPI off): the mpirun runs are not tested"
fi
echo "test_batch $COMMAND: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
