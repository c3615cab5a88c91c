#!/usr/bin/env bash
# End-to-end tests of `polydyn cubetoss` and `polydyn cubetoss fit` (docs/commands.md, docs/DESIGN.md §8.4): usage
# errors (exit 2, nothing written), bad data at its line and column, the output directory (per_toss.csv and
# summary.csv in their documented schemas, the run directories of the record and the simulation), the
# same bytes with one or two worker processes, --params, and a tiny fit whose fragment --params reads.
# Uses the first tosses of ../shared/data/cube-toss/tosses-train.csv; exits 77 (skip) without it.
#
# usage: test_cubetoss_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u
if [ $# -ne 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR" >&2
  exit 2
fi
PD=$1
DATA_FULL=$2/../shared/data/cube-toss/tosses-train.csv
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_cubetoss_cli.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial, skip_without

# ---- usage errors: exit 2, a message naming the problem, nothing written (no data needed)
BAD=$SCRATCH/bad.csv
printf 'toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n1,0.000000,0,0,0.3,1,0,0,0,0,0,0,0,0,0\n1,0.006757,0,0,oops,1,0,0,0,0,0,0,0,0,0\n' >"$BAD"
"$PD" cubetoss --out "$SCRATCH/x" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "no --data: exit 2, says so" '[ $rc -eq 2 ] && grep -q -- "--data" "$SCRATCH/err"'
"$PD" cubetoss --data "$BAD" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "no --out: exit 2" '[ $rc -eq 2 ] && grep -q -- "--out" "$SCRATCH/err"'
"$PD" cubetoss --data "$BAD" --out "$SCRATCH/x" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "bad data: exit 2 with FILE:LINE:COL" '[ $rc -eq 2 ] && grep -q "^$BAD:3:16: not a finite number" "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
"$PD" cubetoss --data "$SCRATCH/none.csv" --out "$SCRATCH/x" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "missing data file: exit 2" '[ $rc -eq 2 ] && grep -q "none.csv: cannot read" "$SCRATCH/err"'
"$PD" cubetoss --data "$BAD" --out "$SCRATCH/x" --engines soft,havok >/dev/null 2>"$SCRATCH/err"; rc=$?
check "unknown engine: exit 2" '[ $rc -eq 2 ] && grep -q havok "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
for args in "--jobs 0" "--jobs x" "--tol 2" "--step -1" "--variant soft" "--inertia heavy" "--label a,b" "--frobnicate 1" \
            "--max-evals 5" "stray"; do
  # shellcheck disable=SC2086
  "$PD" cubetoss --data "$BAD" --out "$SCRATCH/x" $args >/dev/null 2>"$SCRATCH/err"; rc=$?
  check "bad argument '$args': exit 2" '[ $rc -eq 2 ] && grep -q "^polydyn cubetoss: " "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
done
"$PD" cubetoss fit --data "$BAD" --out "$SCRATCH/x" --no-runs >/dev/null 2>"$SCRATCH/err"; rc=$?
check "fit --no-runs: exit 2" '[ $rc -eq 2 ] && grep -q "^polydyn cubetoss fit: " "$SCRATCH/err"'
# a toss whose first pose is inside the board: refused, reported with the scene's line, no run directory, exit 1
OVERLAP=$SCRATCH/overlap.csv
printf 'toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n1,0.000000,0,0,0.01,1,0,0,0,0,0,0,0,0,0\n1,0.006757,0,0,0.01,1,0,0,0,0,0,0,0,0,0\n' >"$OVERLAP"
"$PD" cubetoss --data "$OVERLAP" --out "$SCRATCH/ov" --engines soft >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a refused toss: exit 1, a row saying refused and why, no run directory named" \
  '[ $rc -eq 1 ] && grep -q "^1,train,soft,implicit,default,refused,2,[0-9.]*,,,,,,,,,toss 1:[0-9]*:1: bodies .board. and .cube. overlap" "$SCRATCH/ov/per_toss.csv" && [ ! -e "$SCRATCH/ov/runs/1/soft" ]'
check "a refused toss: summary says failed, with no numbers" 'grep -q "^soft,implicit,default,all,failed,1,0,pos_err_end,cube_widths,,,$" "$SCRATCH/ov/summary.csv"'
"$PD" cubetoss --help | grep -q "per_toss.csv"; rc=$?; check "--help documents per_toss.csv" '[ $rc -eq 0 ]'
"$PD" help | grep -q "cubetoss"; rc=$?; check "polydyn help lists cubetoss" '[ $rc -eq 0 ]'

skip_without "$DATA_FULL" "the cube-toss data (docs/validation.md, cube tosses)"

# ---- the first 4 tosses of the real data (ids 1, 2, 3, 4: positions 0..3, two training, two test)
DATA=$SCRATCH/four.csv
awk -F, 'NR == 1 || $1 == 1 || $1 == 2 || $1 == 3 || $1 == 4' "$DATA_FULL" >"$DATA"
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/x" --tosses 1,7 >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a toss not in the data: exit 2" '[ $rc -eq 2 ] && grep -q "toss 7 is not in" "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
mkdir "$SCRATCH/precious"
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/precious" --tosses 1 --engines soft >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a directory that is not a cubetoss directory is not replaced" '[ $rc -eq 2 ] && [ -z "$(ls "$SCRATCH/precious")" ]'

OUT=$SCRATCH/ct
"$PD" cubetoss --data "$DATA" --out "$OUT" --tosses 1-3 >"$SCRATCH/stdout" 2>"$SCRATCH/err"; rc=$?
check "cubetoss on 3 tosses: exit 0" '[ $rc -eq 0 ]'
check "per_toss.csv header is the documented schema" \
  '[ "$(head -n 1 "$OUT/per_toss.csv")" = "toss,split,engine,variant,params,status,samples,duration_s,pos_err_end,pos_err_rms,rot_err_end_rad,rot_err_rms_rad,wall_seconds,cpu_seconds,steps,run_dir,message" ]'
check "summary.csv header is the documented schema" \
  '[ "$(head -n 1 "$OUT/summary.csv")" = "engine,variant,params,split,status,tosses,completed,quantity,unit,mean,median,p90" ]'
check "one row per toss and engine, tosses in file order" \
  '[ "$(tail -n +2 "$OUT/per_toss.csv" | cut -d, -f1,3 | tr "\n" " ")" = "1,soft 1,ode 1,bullet 2,soft 2,ode 2,bullet 3,soft 3,ode 3,bullet " ]'
check "soft rows ok with finite errors" \
  '[ "$(awk -F, '"'"'$3 == "soft" && $6 == "ok" && $9 != "" && $10 != "" && $11 != "" && $12 != "" && $9 < 5'"'"' "$OUT/per_toss.csv" | wc -l)" -eq 3 ]'
check "split: positions 0, 2 train, 1 test" '[ "$(awk -F, '"'"'$3 == "soft" {printf "%s ", $2}'"'"' "$OUT/per_toss.csv")" = "train test train " ]'
check "no NaN anywhere" '! grep -qi "nan" "$OUT/per_toss.csv" "$OUT/summary.csv"'
check "summary: soft over all 3 tosses, 6 quantities, and the train and test splits" \
  '[ "$(grep -c "^soft,implicit,default,all,ok,3,3," "$OUT/summary.csv")" -eq 6 ] && grep -q "^soft,implicit,default,test,ok,1,1,pos_err_end,cube_widths," "$OUT/summary.csv"'
if "$PD" cubetoss --data "$DATA" --out "$SCRATCH/probe" --tosses 1 --engines ode --no-runs 2>&1 | grep -q "not built"; then
  check "an engine without adapter: reported as not built" 'grep -q "^1,train,ode,native,default,not built," "$OUT/per_toss.csv" && grep -q "^ode,native,default,all,not built," "$OUT/summary.csv"'
fi
check "run directories: the record and the soft run of each toss" \
  '[ -f "$OUT/runs/2/record/trajectory.csv" ] && [ -f "$OUT/runs/2/record/summary.json" ] && [ -f "$OUT/runs/2/soft/trajectory.csv" ]'
check "the record's summary names engine record" 'grep -q "\"engine\": \"record\"" "$OUT/runs/3/record/summary.json"'
check "record and simulation have the same sample times" \
  '[ "$(cut -d, -f1 "$OUT/runs/3/record/trajectory.csv" | md5sum)" = "$(cut -d, -f1 "$OUT/runs/3/soft/trajectory.csv" | md5sum)" ]'
check "the record's first sample is the data's (x, y, z to the digit)" \
  '[ "$(sed -n 2p "$OUT/runs/1/record/trajectory.csv" | cut -d, -f3-5 | awk -F, "{printf \"%.9f,%.9f,%.9f\", \$1, \$2, \$3}")" = "$(sed -n 2p "$DATA" | cut -d, -f3-5 | awk -F, "{printf \"%.9f,%.9f,%.9f\", \$1, \$2, \$3}")" ]'
check "the parameters used are written" 'grep -q "^mu 0.18$" "$OUT/params-soft.scene"'
check "stdout has the table" 'grep -q "pos end" "$SCRATCH/stdout"'
check "no partial directory left" '[ -z "$(ls -d "$SCRATCH"/ct.partial-* 2>/dev/null)" ]'

# ---- determinism: one worker or two, the same bytes except wall and CPU times
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/one" --tosses all --engines soft --jobs 1 >/dev/null 2>&1
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/two" --tosses all --engines soft --jobs 2 >/dev/null 2>&1
strip() { cut -d, -f1-12,15- "$1"; }
check "per_toss.csv: one worker = two workers (but times)" '[ "$(strip "$SCRATCH/one/per_toss.csv")" = "$(strip "$SCRATCH/two/per_toss.csv")" ]'
check "trajectories: one worker = two workers" 'cmp -s "$SCRATCH/one/runs/4/soft/trajectory.csv" "$SCRATCH/two/runs/4/soft/trajectory.csv"'
check "replaced in place: a second run into the same directory works" \
  '"$PD" cubetoss --data "$DATA" --out "$SCRATCH/one" --tosses 2 --engines soft --no-runs >/dev/null 2>&1 && [ ! -e "$SCRATCH/one/runs" ]'

# ---- --params: a fragment with the default values gives the default run's numbers; other values others
printf '# the defaults, written out\nmu 0.18\nrestitution 0.125\nkn 2.1e6\n' >"$SCRATCH/same.scene"
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/same" --tosses 1-3 --engines soft --params "$SCRATCH/same.scene" --no-runs >/dev/null 2>&1
check "--params with the default values: the same errors" \
  '[ "$(cut -d, -f1-4,6-12 "$SCRATCH/same/per_toss.csv")" = "$(grep -v "^[0-9]*,[a-z]*,\(ode\|bullet\)," "$OUT/per_toss.csv" | cut -d, -f1-4,6-12)" ]'
check "--params labels the rows params" 'grep -q "^1,train,soft,implicit,params,ok," "$SCRATCH/same/per_toss.csv"'
printf 'mu 0.5\n' >"$SCRATCH/mu.scene"
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/mu" --tosses 1 --engines soft --params soft="$SCRATCH/mu.scene" --label mu05 --no-runs >/dev/null 2>&1
check "--params soft=FILE changes the result and the label" \
  'grep -q "^1,train,soft,implicit,mu05,ok," "$SCRATCH/mu/per_toss.csv" && [ "$(sed -n 2p "$SCRATCH/mu/per_toss.csv" | cut -d, -f9)" != "$(sed -n 2p "$OUT/per_toss.csv" | cut -d, -f9)" ]'
printf 'mu 0.5\nspgrav 2\n' >"$SCRATCH/bad.scene"
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/x" --engines soft --params "$SCRATCH/bad.scene" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a bad fragment: exit 2 at its line and column" '[ $rc -eq 2 ] && grep -q "bad.scene:2:1: .spgrav." "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'

# ---- fit: 2 training tosses, 3 evaluations; the fragment it writes is read by --params
FIT=$SCRATCH/fit
"$PD" cubetoss fit --data "$DATA" --out "$FIT" --engines soft --max-evals 3 >"$SCRATCH/stdout" 2>"$SCRATCH/err"; rc=$?
check "fit: exit 0" '[ $rc -eq 0 ]'
check "fit.csv: one row for soft, 2 training and 2 test tosses" \
  '[ "$(tail -n +2 "$FIT/fit.csv" | wc -l)" -eq 1 ] && [ "$(tail -n +2 "$FIT/fit.csv" | cut -d, -f1-4,14-16)" = "soft,implicit,ok,mu;restitution;kn,2,1,2" ]'
check "fit_trace.csv: the start first, then at least one simplex vertex and the final point" \
  '[ "$(tail -n +2 "$FIT/fit_trace.csv" | wc -l)" -ge 5 ] && [ "$(sed -n 2p "$FIT/fit_trace.csv" | cut -d, -f1-6)" = "soft,implicit,1,0.18,0.125,2100000" ]'
check "fit: test tosses only, with the default and the fitted parameters" \
  '[ "$(tail -n +2 "$FIT/per_toss.csv" | cut -d, -f1,2,5 | tr "\n" " ")" = "2,test,default 4,test,default 2,test,fitted 4,test,fitted " ]'
check "fit: the default rows equal cubetoss's own" \
  '[ "$(grep "^2,test,soft,implicit,default" "$FIT/per_toss.csv" | cut -d, -f1-12)" = "$(grep "^2,test,soft" "$SCRATCH/one/per_toss.csv" | cut -d, -f1-12)" ]'
"$PD" cubetoss --data "$DATA" --out "$SCRATCH/fitted" --tosses test --engines soft --params soft="$FIT/fitted-soft.scene" \
  --label fitted --no-runs >/dev/null 2>"$SCRATCH/err"; rc=$?
check "--params reads the fitted fragment, and reproduces fit's test rows" \
  '[ $rc -eq 0 ] && [ "$(grep ",fitted," "$FIT/per_toss.csv" | cut -d, -f1-12)" = "$(tail -n +2 "$SCRATCH/fitted/per_toss.csv" | cut -d, -f1-12)" ]'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
