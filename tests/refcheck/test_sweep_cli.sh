#!/usr/bin/env bash
# End-to-end tests of `polydyn sweep`: usage errors, sweep.csv in its documented schema (reports/FORMATS.md),
# and the work-precision fact the sweep exists to show: the soft engine's error falls as its tolerance
# tightens (tol 1e-5 against 1e-9 on a sliding block: at least 100× smaller). Looser tolerances do not
# count: there the step is held by the contacts' stability bound (engine/src/contact_set.c), not by the
# error control, and the error stays at its 1e-5 level.
#
# usage: test_sweep_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u
PD=$1
SRC=$2
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_sweep.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial
SCENE=$SRC/cases/sweep/slide_to_rest.scene
"$PD" sweep >/dev/null 2>&1; rc=$?; check "no scene: exit 2" '[ $rc -eq 2 ]'
"$PD" sweep "$SCENE" >/dev/null 2>&1; rc=$?; check "no --out: exit 2" '[ $rc -eq 2 ]'
"$PD" sweep "$SCENE" --out "$SCRATCH/x" --repeats 0 >/dev/null 2>&1; rc=$?; check "--repeats 0: exit 2" '[ $rc -eq 2 ] && [ ! -e "$SCRATCH/x" ]'
"$PD" sweep "$SCENE" --out "$SCRATCH/x" --engines soft,physx >/dev/null 2>&1; rc=$?; check "unknown engine: exit 2" '[ $rc -eq 2 ]'

OUT=$SCRATCH/sw
"$PD" sweep "$SCENE" --out "$OUT" --engines soft --repeats 1 --tend 0.3 >/dev/null 2>"$SCRATCH/err"; rc=$?
check "sweep: exit 0" '[ $rc -eq 0 ]'
check "sweep.csv header is the documented schema" \
  '[ "$(head -n 1 "$OUT/sweep.csv")" = "scene,engine,variant,setting,value,error,error_kind,wall_seconds,wall_per_sim_second,steps,repeats,reference" ]'
check "9 tolerances and 5 fixed steps" '[ "$(grep -c ",soft,adaptive,tol," "$OUT/sweep.csv")" -eq 9 ] && [ "$(grep -c ",soft,fixed,step," "$OUT/sweep.csv")" -eq 5 ]'
check "reference.json states the reference's own error" 'grep -q "error_against_check" "$OUT/reference.json"'
awk -F, '$4 == "tol" && $5 == "1e-05" { a = $6 } $4 == "tol" && $5 == "1e-09" { b = $6 } END { exit !(a > 0 && b >= 0 && b * 100 < a) }' "$OUT/sweep.csv"; rc=$?
check "error at tol 1e-9 is at least 100x below that at tol 1e-5" '[ $rc -eq 0 ]'
echo "test_sweep_cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
