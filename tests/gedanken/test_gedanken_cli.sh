#!/usr/bin/env bash
# End-to-end tests of polydyn gedanken (gedanken/RESULT_SCHEMAS.md): the fast subset passes on the soft
# engine, the output files have the fixed schema, an engine without an adapter gives NOT_BUILT rows and no
# failure, a failing soft experiment exits 1, bad arguments exit 2 with nothing written, the results do not
# depend on the number of worker processes, a previous result directory is replaced, an interrupt leaves nothing.
#
# usage: test_gedanken_cli.sh POLYDYN_BINARY
set -u

if [ $# -ne 1 ]; then
  echo "usage: $0 POLYDYN_BINARY" >&2
  exit 2
fi
PD=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_gedanken.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
OUT=$SCRATCH/stdout
ERR=$SCRATCH/stderr
HEADER='experiment,group,title,engine,variant,quantity,unit,input,measured,expected,error,tolerance,status,wall_seconds,run_dir,note'

. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial, check_interrupted
run_pd() {  # this script's own: its stdout and stderr files are fixed
  "$PD" "$@" >"$OUT" 2>"$ERR"
  rc=$?
}
# csv_query FILE EXPRESSION: evaluates a Python expression over rows = list of dicts of results.csv
csv_query() {
  python3 -c 'import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
print(eval(sys.argv[2], {"rows": rows}))' "$1" "$2"
}

# --- help and list ------------------------------------------------------------------------------------
run_pd gedanken --help
check "--help exits 0" '[ $rc -eq 0 ] && grep -q "^usage: polydyn gedanken" "$OUT"'
run_pd gedanken --list
check "--list exits 0 and lists at least 20 experiments" '[ $rc -eq 0 ] && [ "$(wc -l <"$OUT")" -ge 20 ]'
check "--list covers groups A to G" \
  '[ "$(awk "{print \$2}" "$OUT" | sort -u | tr -d "\n")" = ABCDEFG ]'

# --- the fast subset on the soft engine ---------------------------------------------------------------
FAST=$SCRATCH/fast
run_pd gedanken --fast --engines soft --out "$FAST"
check "fast subset, soft engine: exit 0" '[ $rc -eq 0 ]'
check "results.csv has the fixed header" '[ "$(head -n 1 "$FAST/results.csv")" = "$HEADER" ]'
check "every soft row of the fast subset PASSes" \
  '[ "$(csv_query "$FAST/results.csv" "len(rows) > 0 and all(r[\"status\"] == \"PASS\" for r in rows)")" = True ]'
check "rows are soft/implicit only" \
  '[ "$(csv_query "$FAST/results.csv" "{(r[\"engine\"], r[\"variant\"]) for r in rows}")" = "{('"'"'soft'"'"', '"'"'implicit'"'"')}" ]'
check "every row has 16 fields and no NaN" \
  '[ "$(csv_query "$FAST/results.csv" "all(len(r) == 16 and None not in r and \"nan\" not in \",\".join(r.values()).lower() for r in rows)")" = True ]'
check "quantitative rows carry measured, expected, error and tolerance as numbers" \
  '[ "$(csv_query "$FAST/results.csv" "all(float(r[\"error\"]) <= float(r[\"tolerance\"]) for r in rows if r[\"expected\"])")" = True ]'
check "the friction cone has 7 push directions" \
  '[ "$(csv_query "$FAST/results.csv" "sorted(int(r[\"input\"].split(\"=\")[1]) for r in rows if r[\"experiment\"] == \"b2_friction_cone\")")" = "[0, 15, 30, 45, 60, 75, 90]" ]'
check "restitution rows for several requested e" \
  '[ "$(csv_query "$FAST/results.csv" "len([r for r in rows if r[\"experiment\"] == \"a1_restitution\"])")" -ge 3 ]'
check "every run directory exists with trajectory, summary and scene" \
  '[ "$(csv_query "$FAST/results.csv" "all(all(__import__(\"os\").path.isfile(\"$FAST/\" + r[\"run_dir\"] + \"/\" + f) for f in (\"trajectory.csv\", \"summary.json\", \"scene.scene\")) for r in rows)")" = True ]'
check "experiments.json lists the experiments run, with the schema's fields" \
  '[ "$(python3 -c "import json; d = json.load(open(\"$FAST/experiments.json\")); print(all(set(e) == {\"name\", \"group\", \"title\", \"quantity\", \"unit\", \"formula\", \"tolerance_reason\", \"qualitative\", \"kind\", \"applies_to\", \"not_applicable_reason\", \"scene\", \"series_label\"} for e in d) and len(d))")" = "$(csv_query "$FAST/results.csv" "len({r[\"experiment\"] for r in rows})")" ]'
check "one series file per experiment, with its header and at most 500 rows per run" \
  '[ "$(python3 -c "import csv, glob, collections; fs = glob.glob(\"$FAST/series/*.csv\"); n = [collections.Counter((r[\"engine\"], r[\"variant\"], r[\"input\"]) for r in csv.DictReader(open(f))) for f in fs]; print(len(fs), all(open(f).readline().strip() == \"t,engine,variant,input,value,analytic\" for f in fs), max(max(c.values()) for c in n) <= 500)")" = "$(csv_query "$FAST/results.csv" "len({r[\"experiment\"] for r in rows})") True True" ]'
check "a run directory replays: its scene.scene gives the same trajectory" \
  '"$PD" run "$FAST/runs/c2_momentum/soft-implicit/scene.scene" --out "$SCRATCH/replay" >/dev/null 2>&1 &&
   cmp -s "$SCRATCH/replay/trajectory.csv" "$FAST/runs/c2_momentum/soft-implicit/trajectory.csv"'

# --- the applied-force experiments (catalogue B3, B5) on the soft engine --------------------------------
FORCE=$SCRATCH/force
run_pd gedanken --only b3_ramp_onset,b5_tip_or_slide --engines soft --out "$FORCE"
check "B3 and B5, soft engine: exit 0" '[ $rc -eq 0 ]'
check "B3: the onset at two ramp rates, each within 0.5 % of mu m g/beta" \
  '[ "$(csv_query "$FORCE/results.csv" "[(r[\"input\"], r[\"status\"], float(r[\"error\"]) <= 0.005) for r in rows if r[\"experiment\"] == \"b3_ramp_onset\"]")" = "[('"'"'beta=4'"'"', '"'"'PASS'"'"', True), ('"'"'beta=8'"'"', '"'"'PASS'"'"', True)]" ]'
check "B5: slides (0) 2 % below mu = w/(2H), tips (1) 2 % above" \
  '[ "$(csv_query "$FORCE/results.csv" "[(r[\"input\"], r[\"measured\"], r[\"status\"]) for r in rows if r[\"experiment\"] == \"b5_tip_or_slide\"]")" = "[('"'"'mu_ratio=0.98'"'"', '"'"'0'"'"', '"'"'PASS'"'"'), ('"'"'mu_ratio=1.02'"'"', '"'"'1'"'"', '"'"'PASS'"'"')]" ]'
check "B3: the run directory records the applied force" \
  'grep -q "\"applied_force\": {\"force\": \[0,0,0\], \"rate\": \[4,0,0\]" "$FORCE/runs/b3_ramp_onset/soft-implicit-beta=4/summary.json" &&
   grep -q "\"excludes_applied_work\": true" "$FORCE/runs/b3_ramp_onset/soft-implicit-beta=4/summary.json"'

# --- reference engines: rows for every variant, never a failure of the exit status ---------------------
REF=$SCRATCH/ref
run_pd gedanken --only a3_sinkage --out "$REF"
check "all engines: exit 0 when the soft engine passes" '[ $rc -eq 0 ]'
check "all engines: one soft row and ode/bullet native and matched rows" \
  '[ "$(csv_query "$REF/results.csv" "[(r[\"engine\"], r[\"variant\"]) for r in rows]")" = "[('"'"'soft'"'"', '"'"'implicit'"'"'), ('"'"'ode'"'"', '"'"'native'"'"'), ('"'"'ode'"'"', '"'"'matched'"'"'), ('"'"'bullet'"'"', '"'"'native'"'"'), ('"'"'bullet'"'"', '"'"'matched'"'"')]" ]'
check "all engines: statuses from the schema; a run directory exactly for PASS, FAIL, NOT_APPLICABLE (and some ERRORs)" \
  '[ "$(csv_query "$REF/results.csv" "all(r[\"status\"] in (\"PASS\", \"FAIL\", \"REFUSED\", \"NOT_BUILT\", \"ERROR\", \"NOT_APPLICABLE\") and (r[\"status\"] == \"ERROR\" or (r[\"run_dir\"] != \"\") == (r[\"status\"] in (\"PASS\", \"FAIL\", \"NOT_APPLICABLE\"))) for r in rows)")" = True ]'
# a3_sinkage is a prediction of the soft model: judged on soft and the matched variants; the
# rigid native variants still run and record their sinkage, not judged, with the reason in the note
check "model prediction: native rows NOT_APPLICABLE (or NOT_BUILT) with the reason, matched and soft judged" \
  '[ "$(csv_query "$REF/results.csv" "all((r[\"status\"] == \"NOT_APPLICABLE\" and r[\"measured\"] != \"\" and r[\"note\"].startswith(\"not applicable: \") and \"rigid contact does not sink\" in r[\"note\"]) or r[\"status\"] == \"NOT_BUILT\" if r[\"variant\"] == \"native\" else r[\"status\"] in (\"PASS\", \"FAIL\", \"NOT_BUILT\") for r in rows)")" = True ]'
check "model prediction: experiments.json names the kind, the judged variants and the reason" \
  '[ "$(python3 -c "import json; e = json.load(open(\"$REF/experiments.json\"))[0]; print(e[\"kind\"], e[\"applies_to\"], e[\"not_applicable_reason\"])")" = "model_prediction ['"'"'soft-implicit'"'"', '"'"'ode-matched'"'"', '"'"'bullet-matched'"'"'] ODE and Bullet native: a rigid contact does not sink" ]'
check "a law: every variant judged, no reason" \
  '[ "$(python3 -c "import json; e = [x for x in json.load(open(\"$FAST/experiments.json\")) if x[\"name\"] == \"c2_momentum\"][0]; print(e[\"kind\"], len(e[\"applies_to\"]), e[\"not_applicable_reason\"])")" = "law 5 None" ]'

# --- work-precision against the closed form (--precision) -------------------------------------------
PREC=$SCRATCH/precision
PHEADER='experiment,kind,engine,variant,setting,value,input,quantity,unit,measured,expected,error,relative,tolerance,judged,status,wall_seconds,wall_per_sim_second,steps,repeats,cpu_seconds,cpu_per_sim_second,derivatives,steps_error,steps_largest,steps_stability,steps_travel,steps_event,steps_landing,note,cpu_seconds_median,cpu_max_over_min,wall_seconds_median,wall_max_over_min,runs_per_timing'
run_pd gedanken --only a1_restitution,c3_eccentric_bar --precision --repeats 2 --out "$PREC"
check "--precision: exit 0 and precision.csv with the fixed header" '[ $rc -eq 0 ] && [ "$(head -n 1 "$PREC/precision.csv")" = "$PHEADER" ]'
# what set polydyn's steps: each error-controlled point's accepted steps counted once, under one limit; none for the fixed
# step and the reference engines
check "--precision: soft steps_* sum to the accepted steps, with the derivative evaluations; empty for fixed, ODE and Bullet" \
  '[ "$(csv_query "$PREC/precision.csv" "all((sum(int(r[\"steps_\" + l]) for l in (\"error\", \"largest\", \"stability\", \"travel\", \"event\", \"landing\")) == int(r[\"steps\"]) and int(r[\"derivatives\"]) >= 4 * int(r[\"steps\"])) if r[\"engine\"] == \"soft\" and r[\"variant\"] != \"fixed\" and r[\"status\"] == \"ok\" else all(r[\"steps_\" + l] == \"\" for l in (\"error\", \"event\")) for r in rows)")" = True ]'
# every knob of every engine, loosest first; an engine without an adapter is two not_built rows, never left out
check "--precision: soft at tol 1e-1, 3e-2, 1e-2 ... 1e-10, fixed dt 1e-3 ... 1e-5, embedded, implicit, exact-events, dopri and implicit-dopri tol 1e-1 ... 1e-10, ODE and Bullet at 5 steps per variant, Bullet also at 5 ... 200 iterations (or not_built)" \
  '[ "$(csv_query "$PREC/precision.csv" "all([(r[\"variant\"], r[\"value\"]) for r in rows if r[\"experiment\"] == x and r[\"engine\"] == \"soft\"] == [(\"adaptive\", t) for t in (\"0.1\", \"0.03\")] + [(\"adaptive\", \"%g\" % 10**-k) for k in range(2, 11)] + [(\"fixed\", v) for v in (\"0.001\", \"0.0003\", \"0.0001\", \"3e-05\", \"1e-05\")] + [(\"embedded\", t) for t in (\"0.1\", \"0.03\")] + [(\"embedded\", \"%g\" % 10**-k) for k in range(2, 11)] + [(\"implicit\", t) for t in (\"0.1\", \"0.03\")] + [(\"implicit\", \"%g\" % 10**-k) for k in range(2, 11)] + [(\"exact-events\", t) for t in (\"0.1\", \"0.03\")] + [(\"exact-events\", \"%g\" % 10**-k) for k in range(2, 11)] + [(\"dopri\", t) for t in (\"0.1\", \"0.03\")] + [(\"dopri\", \"%g\" % 10**-k) for k in range(2, 11)] + [(\"implicit-dopri\", t) for t in (\"0.1\", \"0.03\")] + [(\"implicit-dopri\", \"%g\" % 10**-k) for k in range(2, 11)] and all([(r[\"variant\"], r[\"setting\"], r[\"value\"]) for r in rows if r[\"experiment\"] == x and r[\"engine\"] == e] in (sum(([(v, \"step\", s) for s in (\"0.0166667\", \"0.004\", \"0.001\", \"0.00025\", \"6.25e-05\")] + [(v, \"iterations\", n) for n in ((\"5\", \"10\", \"20\", \"50\", \"100\", \"200\") if e == \"bullet\" else ())] for v in (\"native\", \"matched\")), []), [(\"native\", \"\", \"\"), (\"matched\", \"\", \"\")]) for e in (\"ode\", \"bullet\")) for x in (\"a1_restitution\", \"c3_eccentric_bar\"))")" = True ]'
check "--precision: not_built rows say which adapter is missing" \
  '[ "$(csv_query "$PREC/precision.csv" "all(r[\"engine\"] in r[\"note\"] and r[\"setting\"] == \"\" for r in rows if r[\"status\"] == \"not_built\")")" = True ]'
check "--precision: one input per experiment, the middle one (a1: e=0.5 of 0.1 ... 0.95)" \
  '[ "$(csv_query "$PREC/precision.csv" "sorted({(r[\"experiment\"], r[\"input\"]) for r in rows})")" = "[('"'"'a1_restitution'"'"', '"'"'e=0.5'"'"'), ('"'"'c3_eccentric_bar'"'"', '"'"''"'"')]" ]'
check "--precision: the expected value and tolerance are those results.csv judges by" \
  '[ "$(python3 -c "import csv; res = {(r[\"experiment\"], r[\"input\"]): (r[\"expected\"], r[\"tolerance\"]) for r in csv.DictReader(open(\"$PREC/results.csv\"))}; print(all(res[(r[\"experiment\"], r[\"input\"])] == (r[\"expected\"], r[\"tolerance\"]) for r in csv.DictReader(open(\"$PREC/precision.csv\"))))")" = True ]'
check "--precision: every ok point's error is |measured - expected| (relative: |measured/expected - 1|) to 1e-15" \
  '[ "$(csv_query "$PREC/precision.csv" "all(abs(float(r[\"error\"]) - (abs(float(r[\"measured\"]) / float(r[\"expected\"]) - 1) if r[\"relative\"] == \"true\" else abs(float(r[\"measured\"]) - float(r[\"expected\"])))) <= 1e-15 * max(1.0, abs(float(r[\"expected\"]))) for r in rows if r[\"status\"] == \"ok\")")" = True ]'
check "--precision: ok points have a positive wall time and steps; the repeats column says 2" \
  '[ "$(csv_query "$PREC/precision.csv" "all(float(r[\"wall_seconds\"]) > 0 and int(r[\"steps\"]) > 0 for r in rows if r[\"status\"] == \"ok\") and {r[\"repeats\"] for r in rows} == {\"2\"}")" = True ]'
# the cost protocol (gedanken/include/pdgk/gedanken.h, docs/validation.md "The cost of a point"): a timing repeats the
# run until it has spent the minimum CPU time, the cost is the least of the timings, their median and spread beside it
MIN_CPU=$(sed -n 's/^#define PD_GK_TIMING_MIN_CPU_SECONDS \([0-9.e-]*\).*/\1/p' "$(dirname "${BASH_SOURCE[0]}")/../../gedanken/include/pdgk/gedanken.h")
check "--precision: the minimum CPU time of a timing is read from the header ($MIN_CPU s)" '[ -n "$MIN_CPU" ]'
check "--precision: every ok point's cheapest timing ran the run back to back for at least the minimum CPU time (runs_per_timing x cpu_seconds)" \
  '[ "$(csv_query "$PREC/precision.csv" "all(int(r[\"runs_per_timing\"]) >= 1 and int(r[\"runs_per_timing\"]) * float(r[\"cpu_seconds\"]) >= $MIN_CPU * (1 - 1e-12) for r in rows if r[\"status\"] == \"ok\")")" = True ]'
# with 2 timings a and b the median is (a + b) / 2: the cost c is the least of them when median = c (1 + max/min) / 2
check "--precision: the cost is the least of the 2 timings (median = cost x (1 + max/min) / 2, max/min >= 1; CPU and wall time)" \
  '[ "$(csv_query "$PREC/precision.csv" "all(float(r[c + \"_max_over_min\"]) >= 1 and abs(float(r[c + \"_seconds_median\"]) - float(r[c + \"_seconds\"]) * (1 + float(r[c + \"_max_over_min\"])) / 2) <= 1e-12 * float(r[c + \"_seconds_median\"]) for r in rows if r[\"status\"] == \"ok\" for c in (\"cpu\", \"wall\"))")" = True ]'
check "--precision: the timing columns are empty unless ok" \
  '[ "$(csv_query "$PREC/precision.csv" "all(r[c] == \"\" for r in rows if r[\"status\"] != \"ok\" for c in (\"cpu_seconds\", \"cpu_seconds_median\", \"cpu_max_over_min\", \"wall_seconds_median\", \"wall_max_over_min\", \"runs_per_timing\"))")" = True ]'
check "--precision: judged follows the kind (c3, a soft-model prediction: native variants not judged; a1, a law: all judged)" \
  '[ "$(csv_query "$PREC/precision.csv" "all((r[\"judged\"] == \"false\") == (r[\"experiment\"] == \"c3_eccentric_bar\" and r[\"variant\"] == \"native\") for r in rows)")" = True ]'
# eq. (15) is exact for the model: its restitution converges to the requested e as the tolerance tightens, with
# either error-controlled stepper
for V in adaptive embedded dopri; do
  check "--precision: soft $V restitution converges to e = 0.5: within the 0.005 tolerance at tol <= 1e-4, 1e-6 at tol 1e-10" \
    '[ "$(csv_query "$PREC/precision.csv" "all(float(r[\"error\"]) <= 0.005 for r in rows if r[\"experiment\"] == \"a1_restitution\" and r[\"variant\"] == \"$V\" and float(r[\"value\"]) <= 1e-4) and [float(r[\"error\"]) < 1e-6 for r in rows if r[\"experiment\"] == \"a1_restitution\" and r[\"variant\"] == \"$V\" and r[\"value\"] == \"1e-10\"] == [True]")" = True ]'
done
# the timings: every column but those (wall and CPU seconds, their median and spread, runs per timing)
strip_precision_wall() { python3 -c 'import csv, sys
for r in csv.reader(open(sys.argv[1], newline="")): print(r[:16] + r[18:20] + r[22:30])' "$1"; }
run_pd gedanken --only c2_momentum,a1_restitution --engines soft,ode --precision --repeats 1 --jobs 1 --out "$SCRATCH/pdet1"
run_pd gedanken --only c2_momentum,a1_restitution --engines soft,ode --precision --repeats 1 --jobs 2 --out "$SCRATCH/pdet2"
check "--precision: precision.csv identical with 1 and 2 worker processes (but wall times)" \
  '[ -s "$SCRATCH/pdet1/precision.csv" ] && [ "$(strip_precision_wall "$SCRATCH/pdet1/precision.csv")" = "$(strip_precision_wall "$SCRATCH/pdet2/precision.csv")" ]'
check "--precision: with one timing its cost is its median and its spread 1" \
  '[ "$(csv_query "$SCRATCH/pdet1/precision.csv" "all(r[\"cpu_seconds\"] == r[\"cpu_seconds_median\"] and float(r[\"cpu_max_over_min\"]) == 1 and r[\"repeats\"] == \"1\" for r in rows if r[\"status\"] == \"ok\")")" = True ]'
check "--precision: engines not asked for have no rows" \
  '[ "$(csv_query "$SCRATCH/pdet1/precision.csv" "sorted({r[\"engine\"] for r in rows})")" = "['"'"'ode'"'"', '"'"'soft'"'"']" ]'
run_pd gedanken --only c2_momentum --engines soft --out "$SCRATCH/noprec"
check "without --precision there is no precision.csv" '[ $rc -eq 0 ] && [ ! -e "$SCRATCH/noprec/precision.csv" ]'

# --- a failing soft experiment exits 1, and still writes its results -----------------------------------
FAILDIR=$SCRATCH/failing
run_pd gedanken --only a3_sinkage --engines soft --tolerance-scale 1e-12 --out "$FAILDIR"
check "a soft FAIL exits 1" '[ $rc -eq 1 ]'
check "a soft FAIL is named on stderr" 'grep -q "a3_sinkage" "$ERR"'
check "a soft FAIL is written as FAIL" '[ "$(csv_query "$FAILDIR/results.csv" "rows[0][\"status\"]")" = FAIL ]'

# --- determinism: same bytes whatever the number of worker processes, except wall times ------------------------
strip_wall() { python3 -c 'import csv, sys
for r in csv.reader(open(sys.argv[1], newline="")): print(r[:13] + r[14:])' "$1"; }
run_pd gedanken --only a1_restitution,c2_momentum,e1_painleve --engines soft --jobs 1 --out "$SCRATCH/det1"
run_pd gedanken --only a1_restitution,c2_momentum,e1_painleve --engines soft --jobs 3 --out "$SCRATCH/det3"
check "results.csv identical with 1 and 3 worker processes (but wall times)" \
  '[ "$(strip_wall "$SCRATCH/det1/results.csv")" = "$(strip_wall "$SCRATCH/det3/results.csv")" ]'
check "series and trajectories identical with 1 and 3 worker processes" \
  'diff -r -q -x summary.json -x results.csv "$SCRATCH/det1" "$SCRATCH/det3" >/dev/null'

# --- replacing a previous result directory ----------------------------------------------------------------
touch "$SCRATCH/det1/stale-marker"
run_pd gedanken --only c2_momentum --engines soft --out "$SCRATCH/det1"
check "a previous gedanken directory is replaced" \
  '[ $rc -eq 0 ] && [ ! -e "$SCRATCH/det1/stale-marker" ] && [ "$(csv_query "$SCRATCH/det1/results.csv" "len(rows)")" = 1 ] && no_partial "$SCRATCH/det1"'

# --- bad arguments: exit 2, a message, nothing written ----------------------------------------------
BADOUT=$SCRATCH/bad
bad_args() {
  local name=$1
  shift
  run_pd gedanken "$@"
  check "$name exits 2" '[ $rc -eq 2 ]'
  check "$name says why as 'polydyn gedanken: ...'" 'grep -q "^polydyn gedanken: " "$ERR"'
  check "$name writes nothing" '[ ! -e "$BADOUT" ] && no_partial "$BADOUT"'
}
bad_args "no --out" --engines soft
bad_args "an unknown option" --out "$BADOUT" --frobnicate
bad_args "an unknown experiment" --out "$BADOUT" --only a1_restitution,nosuch
bad_args "an empty --only item" --out "$BADOUT" --only a1_restitution,
bad_args "an unknown engine" --out "$BADOUT" --engines soft,physx
bad_args "an empty engine list" --out "$BADOUT" --engines ""
bad_args "--jobs 0" --out "$BADOUT" --jobs 0
bad_args "--jobs not a number" --out "$BADOUT" --jobs two
bad_args "a negative tolerance scale" --out "$BADOUT" --tolerance-scale -1
bad_args "--out without a value" --out
bad_args "an empty selection" --out "$BADOUT" --fast --only a4_elastic_apex
bad_args "--repeats without --precision" --out "$BADOUT" --repeats 2
bad_args "--repeats 0" --out "$BADOUT" --precision --repeats 0
bad_args "--repeats 22" --out "$BADOUT" --precision --repeats 22
mkdir -p "$SCRATCH/precious"
touch "$SCRATCH/precious/keep"
run_pd gedanken --only c2_momentum --engines soft --out "$SCRATCH/precious"
check "an existing non-gedanken directory is refused with exit 2" '[ $rc -eq 2 ] && grep -q "not a gedanken directory" "$ERR"'
check "an existing non-gedanken directory is left alone" '[ -e "$SCRATCH/precious/keep" ] && no_partial "$SCRATCH/precious"'

# --- interruption: exit 130, nothing written ------------------------------------------------------------
# (with --precision: the suite alone of these experiments can end within the half second the check waits)
INT=$SCRATCH/interrupted
check_interrupted "$OUT" "$ERR" "$INT" gedanken --only g1_stack_drift,g1_stack_sinkage,f1_top_precession,d1_rimless_wheel \
  --engines soft --jobs 1 --precision --out "$INT"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
