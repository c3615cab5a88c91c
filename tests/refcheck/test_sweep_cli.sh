#!/usr/bin/env bash
# End-to-end tests of `polydyn sweep`: usage errors, sweep.csv in its documented schema (reports/FORMATS.md),
# and the work-precision fact the sweep exists to show: the soft engine's error falls as its tolerance
# tightens (tol 1e-5 against 1e-9 on a sliding block: at least 100× smaller), for the default stepper and
# the embedded pair alike, each soft row with its derivative evaluations (ODE's empty). Looser tolerances do not
# count: there the step is held by the contacts' stability bound (engine/src/contact_set.c), not by the
# error control, and the error stays at its 1e-5 level. Self-convergence (the last three columns): on a
# tumbling cube (chaotic) with ODE, the self_reference of each row, the finest ODE step's empty self_error
# and horizon, a finite self_error for every other completed row (equal to error for the soft engine), every
# horizon empty or within [0, tend] and at least one there, and the same bytes with --jobs 2 (but wall times).
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
check "sweep.csv header is the documented schema (the self-convergence columns last)" \
  '[ "$(head -n 1 "$OUT/sweep.csv")" = "scene,engine,variant,setting,value,error,error_kind,wall_seconds,wall_per_sim_second,steps,repeats,reference,self_error,self_reference,horizon_seconds,derivatives" ]'
check "9 tolerances, 5 fixed steps, 9 tolerances of the embedded pair" \
  '[ "$(grep -c ",soft,adaptive,tol," "$OUT/sweep.csv")" -eq 9 ] && [ "$(grep -c ",soft,fixed,step," "$OUT/sweep.csv")" -eq 5 ] && [ "$(grep -c ",soft,embedded,tol," "$OUT/sweep.csv")" -eq 9 ]'
awk -F, 'NR > 1 && $2 == "soft" && $16 !~ /^[1-9][0-9]*$/ { bad = 1 } END { exit bad }' "$OUT/sweep.csv"; rc=$?
check "every soft row counts its derivative evaluations" '[ $rc -eq 0 ]'
check "reference.json states the reference's own error" 'grep -q "error_against_check" "$OUT/reference.json"'
for v in implicit adaptive embedded; do
  awk -F, -v v=$v '$3 == v && $5 == "1e-05" { a = $6 } $3 == v && $5 == "1e-09" { b = $6 } END { exit !(a > 0 && b >= 0 && b * 100 < a) }' "$OUT/sweep.csv"; rc=$?
  check "$v: error at tol 1e-9 is at least 100x below that at tol 1e-5" '[ $rc -eq 0 ]'
done

# self-convergence and the horizon of predictability on a chaotic scene, serially and with --jobs 2
CUBE=$SRC/cases/sweep/tumbling_cube.scene
"$PD" sweep "$CUBE" --out "$SCRATCH/cube" --engines soft,ode --repeats 1 --tend 0.8 >"$SCRATCH/cube.out" 2>"$SCRATCH/err"; rc=$?
check "tumbling cube sweep: exit 0" '[ $rc -eq 0 ]'
"$PD" sweep "$CUBE" --out "$SCRATCH/cube2" --engines soft,ode --repeats 1 --tend 0.8 --jobs 2 >/dev/null 2>"$SCRATCH/err"; rc=$?
check "tumbling cube sweep --jobs 2: exit 0" '[ $rc -eq 0 ]'
check "--jobs 2: the same bytes but the wall times (self_error, self_reference, horizon_seconds included)" \
  'python3 "$SRC/tests/cli/same_outputs.py" "$SCRATCH/cube" "$SCRATCH/cube2"'
python3 - "$SCRATCH/cube/sweep.csv" 0.8 >"$SCRATCH/selfcheck" 2>&1 <<'PY'; rc=$?
import csv, math, sys
rows, tend, bad = list(csv.DictReader(open(sys.argv[1]))), float(sys.argv[2]), []
finest = {"ode native step=6.25e-05", "ode matched step=6.25e-05"}
for r in rows:
    name = f'{r["engine"]} {r["variant"]} {r["setting"]}={r["value"]}'
    want = "soft tol=1e-12" if r["engine"] == "soft" else f'{r["engine"]} {r["variant"]} step=6.25e-05'
    if r["self_reference"] != want: bad.append(f"{name}: self_reference {r['self_reference']!r}, expected {want!r}")
    if name in finest:
        if r["self_error"] or r["horizon_seconds"]: bad.append(f"{name}: the finest step has a self_error or a horizon")
        continue
    if r["error"]:  # completed
        try:
            e = float(r["self_error"])
        except ValueError:
            e = math.nan
        if not (math.isfinite(e) and e >= 0): bad.append(f"{name}: self_error {r['self_error']!r} is not a finite number")
        if r["engine"] == "soft" and r["self_error"] != r["error"]: bad.append(f"{name}: soft self_error differs from error")
    if r["horizon_seconds"] and not 0 <= float(r["horizon_seconds"]) <= tend: bad.append(f"{name}: horizon {r['horizon_seconds']} outside [0, tend]")
if len(rows) != 42: bad.append(f"{len(rows)} rows, expected 42 (32 soft, 10 ode)")
bad += [f"{r['engine']} {r['variant']} {r['value']}: derivatives {r['derivatives']!r}" for r in rows
        if r["error"] and (r["derivatives"] == "") != (r["engine"] != "soft")]
if not any(r["horizon_seconds"] for r in rows): bad.append("no point has a horizon on the tumbling cube")
if not any(r["engine"] == "ode" and r["horizon_seconds"] for r in rows): bad.append("no ode point has a horizon on the tumbling cube")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
check "self_error, self_reference and horizon_seconds as documented (reports/FORMATS.md)" '[ $rc -eq 0 ]' || cat "$SCRATCH/selfcheck"
check "reference.json states the reference's own horizon against its check" \
  'grep -q "\"horizon_threshold\": 0.1, \"horizon_against_check_seconds\": " "$SCRATCH/cube/reference.json"'
echo "test_sweep_cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
