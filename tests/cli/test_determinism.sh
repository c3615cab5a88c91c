#!/usr/bin/env bash
# Determinism of the commands' outputs (docs/reliability.md): the same
# command twice gives the same files, byte for byte, except the measured times (same_outputs.py names
# them: wall/CPU time columns, the "timing" line of summary.json, "wall_seconds" of JSON; the "time" lines
# of oracle's summary on stdout). The second run of each pair writes to a differently named directory and
# runs with MALLOC_PERTURB_ set (glibc then fills fresh and freed heap memory with a pattern), so an output
# that depends on where it is written or on uninitialised memory shows up. Covered here:
#   run       demo.scene, a hard case (the 10-box stack), the brick wall (short), the pile of ten boxes (also
#             with --islands on); the pile in ODE and Bullet; demo with the fixed stepper, with the embedded pair and with step doubling alone;
#             the pile of 100 boxes (short) with --islands on, --threads 1 against --threads 2
#   check     the pile
#   oracle    --random, a SCENE, --replay (its CSV and its summary)
#   soak      --jobs 1 against --jobs 2, in the three engines
#   cubetoss  four synthetic tosses (tests/reports/make_tosses.py), --jobs 1 against --jobs 2 (test_batch uses
#             the real data where it is present)
#   view      the replay page of a run
#   report    the report of a small gedanken run (skipped without node)
# gedanken, sweep, compare, cubetoss and cubetoss fit across --jobs 1, --jobs 2 and MPI: test_batch.sh. The
# engine's trajectory against a committed hash: tests/engine/test_determinism.c.
#
# usage: test_determinism.sh POLYDYN_BINARY PROJECT_SOURCE_DIR [quick]
#   quick: fewer and shorter runs (the ASan + UBSan build runs 10-40x slower)
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR [quick]" >&2
  exit 2
fi
PD=$1
SRC=$2
QUICK=${3:-}
HERE=$(dirname "${BASH_SOURCE[0]}")
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_determinism.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$HERE/../lib.sh"  # check
SAME="python3 $HERE/same_outputs.py"

# (check evaluates its condition inside itself: the conditions below name globals, never $1 or $name)

# twice NAME ARGS...: runs `polydyn ARGS... --out DIR` into $SCRATCH/NAME/first and $SCRATCH/NAME/second-run
# (with MALLOC_PERTURB_), stdout and stderr beside them; both must exit 0
twice() {
  T=$1
  shift
  mkdir -p "$SCRATCH/$T"
  "$PD" "$@" --out "$SCRATCH/$T/first" >"$SCRATCH/$T/first.out" 2>"$SCRATCH/$T/first.err"
  rc1=$?
  MALLOC_PERTURB_=165 "$PD" "$@" --out "$SCRATCH/$T/second-run" >"$SCRATCH/$T/second.out" 2>"$SCRATCH/$T/second.err"
  rc2=$?
  check "$T: both runs exit 0" '[ $rc1 -eq 0 ] && [ $rc2 -eq 0 ]' || cat "$SCRATCH/$T/first.err"
}

# same_dirs NAME: the two run directories hold the same files and bytes but the measured times
same_dirs() {
  T=$1
  check "$T: the same files and bytes but the measured times" \
    '$SAME "$SCRATCH/$T/first" "$SCRATCH/$T/second-run" >"$SCRATCH/$T/diff"' || cat "$SCRATCH/$T/diff"
}

# --- run: trajectory.csv and contacts.csv byte for byte, summary.json but its timing line ------------------
TEND_BRICKS=0.3
TEND_PILE=1
if [ "$QUICK" = quick ]; then TEND_PILE=0.3; fi
twice run_demo run "$SRC/cases/examples/demo.scene"
twice run_stack run "$SRC/cases/hard/stack_10.scene"
[ "$QUICK" = quick ] || twice run_bricks run "$SRC/cases/hard/brick_bond.scene" --tend $TEND_BRICKS
twice run_pile run "$SRC/cases/sweep/pile_10.scene" --tend $TEND_PILE
twice run_pile_islands run "$SRC/cases/sweep/pile_10.scene" --tend $TEND_PILE --islands on
twice run_pile_ode run "$SRC/cases/sweep/pile_10.scene" --tend $TEND_PILE --engine ode
twice run_pile_bullet run "$SRC/cases/sweep/pile_10.scene" --tend $TEND_PILE --engine bullet
twice run_demo_fixed run "$SRC/cases/examples/demo.scene" --stepper fixed --tend 1
twice run_demo_embedded run "$SRC/cases/examples/demo.scene" --stepper embedded --tend 1
twice run_demo_adaptive run "$SRC/cases/examples/demo.scene" --stepper adaptive --tend 1
for R in run_demo run_stack run_bricks run_pile run_pile_islands run_pile_ode run_pile_bullet run_demo_fixed run_demo_embedded run_demo_adaptive; do
  [ -d "$SCRATCH/$R" ] || continue
  check "$R: trajectory.csv byte for byte" 'cmp -s "$SCRATCH/$R/first/trajectory.csv" "$SCRATCH/$R/second-run/trajectory.csv"'
  same_dirs $R
done
check "run_pile: the soft run's trajectory has every sample (the comparison is not of empty files)" \
  '[ "$(wc -l <"$SCRATCH/run_pile/first/trajectory.csv")" -gt 100 ]'

# --- run --islands on: --threads 1 against --threads 2 (an island computes the same numbers on any thread) ---------
TEND_THREADS=0.5
# quick (ASan): 0.2 s, the first window in which two boxes share an island since islands are split by the
# separating-axis test (at 0.15 s every island still holds one box)
if [ "$QUICK" = quick ]; then TEND_THREADS=0.2; fi
T=run_pile_threads
mkdir -p "$SCRATCH/$T"
"$PD" run "$SRC/cases/bench/pile_100.scene" --tend $TEND_THREADS --islands on --threads 1 \
  --out "$SCRATCH/$T/first" >"$SCRATCH/$T/first.out" 2>"$SCRATCH/$T/first.err"
rc1=$?
MALLOC_PERTURB_=165 "$PD" run "$SRC/cases/bench/pile_100.scene" --tend $TEND_THREADS --islands on --threads 2 \
  --out "$SCRATCH/$T/second-run" >"$SCRATCH/$T/second.out" 2>"$SCRATCH/$T/second.err"
rc2=$?
check "$T: both runs exit 0" '[ $rc1 -eq 0 ] && [ $rc2 -eq 0 ]' || cat "$SCRATCH/$T/first.err" "$SCRATCH/$T/second.err"
check "$T: trajectory.csv byte for byte" 'cmp -s "$SCRATCH/$T/first/trajectory.csv" "$SCRATCH/$T/second-run/trajectory.csv"'
check "$T: contacts.csv byte for byte" 'cmp -s "$SCRATCH/$T/first/contacts.csv" "$SCRATCH/$T/second-run/contacts.csv"'
same_dirs $T
check "$T: the boxes met (islands of more than one body: the comparison covers contacts)" \
  'grep -q "\"largest_island\": [2-9]" "$SCRATCH/$T/first/summary.json"'

# --- check ------------------------------------------------------------------------------------------------
"$PD" check "$SRC/cases/sweep/pile_10.scene" >"$SCRATCH/check1.out" 2>&1
MALLOC_PERTURB_=165 "$PD" check "$SRC/cases/sweep/pile_10.scene" >"$SCRATCH/check2.out" 2>&1
check "check: the same report twice" 'cmp -s "$SCRATCH/check1.out" "$SCRATCH/check2.out" && [ -s "$SCRATCH/check1.out" ]'

# --- oracle: the CSV byte for byte, the summary but its "time" lines ---------------------------------------
no_time() { grep -v '^time' "$1"; }
oracle_twice() {
  T=$1
  shift
  "$PD" oracle "$@" --out "$SCRATCH/$T-1.csv" >"$SCRATCH/$T-1.out" 2>&1
  rc1=$?
  MALLOC_PERTURB_=165 "$PD" oracle "$@" --out "$SCRATCH/$T-2.csv" >"$SCRATCH/$T-2.out" 2>&1
  rc2=$?
  check "$T: both exit 0" '[ $rc1 -eq 0 ] && [ $rc2 -eq 0 ]' || cat "$SCRATCH/$T-1.out"
  check "$T: the same CSV twice" 'cmp -s "$SCRATCH/$T-1.csv" "$SCRATCH/$T-2.csv"'
  # the summary names the CSV it wrote
  check "$T: the same summary twice but its time lines" \
    '[ "$(no_time "$SCRATCH/$T-1.out" | sed "s/$T-1/X/")" = "$(no_time "$SCRATCH/$T-2.out" | sed "s/$T-2/X/")" ]'
}
oracle_twice oracle_random --random 500 --seed 15
check "oracle_random: some pairs listed (the comparison is not of empty files)" \
  '[ "$(wc -l <"$SCRATCH/oracle_random-1.csv")" -gt 2 ]'
oracle_twice oracle_scene "$SRC/cases/hard/cubes_face_on_face.scene" --tend 0.1
oracle_twice oracle_replay --replay "$SCRATCH/oracle_random-1.csv"

# --- soak: --jobs 1 against --jobs 2; failing scenes' replay files too: campaign 70's scenes 3504 (a stack) and 3505 (a
# pile-up of eight bodies in the air) judged against a penetration limit of 1e-6 delta_max, which every run whose bodies
# touch fails by construction (a loaded contact is that deep many times over: 0.002 and 0.70 delta_max) ---------
SOAK_SCENES=40
[ "$QUICK" = quick ] && SOAK_SCENES=3
soak_twice() {
  T=$1
  want=$2
  shift 2
  mkdir -p "$SCRATCH/$T"
  "$PD" soak "$@" --jobs 1 --out "$SCRATCH/$T/first" >"$SCRATCH/$T/first.out" 2>&1
  rc1=$?
  MALLOC_PERTURB_=165 "$PD" soak "$@" --jobs 2 --out "$SCRATCH/$T/second-run" >"$SCRATCH/$T/second.out" 2>&1
  rc2=$?
  check "$T --jobs 1 and --jobs 2: both exit $want" '[ $rc1 -eq $want ] && [ $rc2 -eq $want ]' || cat "$SCRATCH/$T/first.out"
  same_dirs $T
  check "$T: the same report on stdout" 'cmp -s "$SCRATCH/$T/first.out" "$SCRATCH/$T/second.out"'
}
soak_twice soak 0 --seed 4 --scenes $SOAK_SCENES --engines soft,ode,bullet
soak_twice soak_failure 1 --seed 70 --first 3504 --scenes 2 --penetration-limit 1e-6
check "soak_failure: the failing scenes' replay files are there" \
  '[ -s "$SCRATCH/soak_failure/first/failures/003504-soft.scene" ] && [ -s "$SCRATCH/soak_failure/first/failures/003505-soft.scene" ]'

# --- cubetoss: synthetic tosses, --jobs 1 against --jobs 2 -------------------------------------------------
python3 "$SRC/tests/reports/make_tosses.py" "$SCRATCH/tosses.csv" 4 || exit 1
mkdir -p "$SCRATCH/cubetoss"
"$PD" cubetoss --data "$SCRATCH/tosses.csv" --engines soft,ode --jobs 1 --out "$SCRATCH/cubetoss/first" \
  >"$SCRATCH/cubetoss1.out" 2>&1
rc1=$?
MALLOC_PERTURB_=165 "$PD" cubetoss --data "$SCRATCH/tosses.csv" --engines soft,ode --jobs 2 \
  --out "$SCRATCH/cubetoss/second-run" >"$SCRATCH/cubetoss2.out" 2>&1
rc2=$?
check "cubetoss --jobs 1 and --jobs 2: both exit 0" '[ $rc1 -eq 0 ] && [ $rc2 -eq 0 ]' || cat "$SCRATCH/cubetoss1.out"
same_dirs cubetoss

# --- view: the page of a run ---------------------------------------------------------------------------------
if [ -r "$SRC/viewer/dist/viewer.js" ]; then
  "$PD" view "$SCRATCH/run_stack/first" -o "$SCRATCH/view1.html" >/dev/null 2>&1
  MALLOC_PERTURB_=165 "$PD" view "$SCRATCH/run_stack/first" -o "$SCRATCH/view2.html" >/dev/null 2>&1
  check "view: the same page twice" 'cmp -s "$SCRATCH/view1.html" "$SCRATCH/view2.html" && [ -s "$SCRATCH/view1.html" ]'
else
  echo "note: no viewer bundle (viewer/scripts/setup): view not tested"
fi

# --- report: the same files when written under the same name ------------------------------------------------
if command -v node >/dev/null && [ -d "$SRC/reports/generator/node_modules" ]; then
  "$PD" gedanken --only a1_restitution,c2_momentum --engines soft --out "$SCRATCH/gedanken" >/dev/null 2>&1
  mkdir -p "$SCRATCH/report/first" "$SCRATCH/report/second-run"
  "$PD" report "$SCRATCH/gedanken" -o "$SCRATCH/report/first/report.html" >/dev/null 2>&1
  rc1=$?
  "$PD" report "$SCRATCH/gedanken" -o "$SCRATCH/report/second-run/report.html" >/dev/null 2>&1
  rc2=$?
  check "report: both exit 0" '[ $rc1 -eq 0 ] && [ $rc2 -eq 0 ]'
  same_dirs report
else
  echo "note: no node or no npm packages in reports/generator (npm ci): report not tested"
fi

echo "test_determinism: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
