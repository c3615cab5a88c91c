#!/usr/bin/env bash
# End-to-end tests of `polydyn report`: it writes the page, report.json and the CSV tables; it is
# deterministic; sections appear only when their inputs exist; every malformed input is refused with
# `polydyn report: FILE:LINE: message`, exit status 2 and nothing written; bad arguments exit 2;
# a missing node exits 1.
# usage: test_report_cli.sh POLYDYN SOURCE_DIR
set -uo pipefail
polydyn=$1
src=$2
fixture=$src/tests/reports/fixtures/gedanken
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PD_REPORT_GENERATOR=$src/reports/generator/report.mjs
pass=0
fail=0

ok() { echo "ok - $1"; pass=$((pass + 1)); }
bad() { echo "FAIL - $1"; fail=$((fail + 1)); }

# a fresh copy of the fixture
fresh() { rm -rf "$work/d"; cp -r "$fixture" "$work/d"; }

# expect_bad NAME EXPECTED_STDERR_PREFIX: runs polydyn report on $work/d, wants exit 2, stderr starting
# with the prefix, and no report file written
expect_bad() {
  local name=$1 want=$2
  "$polydyn" report "$work/d" --no-viewer >"$work/out" 2>"$work/err"
  local rc=$?
  local msg
  msg=$(cat "$work/err")
  if [[ $rc -eq 2 && $msg == "polydyn report: $want"* && $(wc -l <"$work/err") -eq 1 ]] &&
    ! compgen -G "$work/d/report*" >/dev/null; then
    ok "$name: exit 2, '$msg'"
  else
    bad "$name: rc=$rc, stderr '$msg', expected '$want…'; files: $(ls "$work/d" | tr '\n' ' ')"
  fi
}

# --- the fixture: every output, no temporary left, deterministic
fresh
if "$polydyn" report "$work/d" --no-viewer 2>"$work/err"; then ok "the fixture report is written (exit 0)"; else bad "report on the fixture failed: $(cat "$work/err")"; fi
want="report-cost.csv report-friction-cone.csv report-matrix.csv report-parameters.csv report-restitution.csv report-summary.csv report-verdict.csv report-work-precision.csv report.html report.json"
got=$(cd "$work/d" && ls -d report* | tr '\n' ' ' | sed 's/ $//')
[[ $got == "$want" ]] && ok "page, report.json and 8 CSV tables, no temporary file" || bad "outputs: '$got'"
cp "$work/d/report.html" "$work/first.html"
cp "$work/d/report.json" "$work/first.json"
"$polydyn" report "$work/d" --no-viewer 2>/dev/null
cmp -s "$work/first.html" "$work/d/report.html" && cmp -s "$work/first.json" "$work/d/report.json" &&
  ok "two runs give identical bytes (page and JSON)" || bad "the report differs between two runs"

# -o: page elsewhere, its JSON and CSV beside it
mkdir "$work/o"
"$polydyn" report "$fixture" -o "$work/o/gk.html" --no-viewer 2>/dev/null
[[ -s $work/o/gk.html && -s $work/o/gk.json && -s $work/o/gk-matrix.csv ]] && ok "-o FILE writes FILE, FILE.json and FILE-matrix.csv" ||
  bad "-o: $(ls "$work/o")"
[[ -z $(find "$fixture" -name 'report*' -o -name '*.tmp-*') ]] && ok "-o leaves the input directory untouched" || bad "files written into the fixture"

# --- replays: the viewer bundle once in the page, each run's data in its own file of FILE-replays/
fake=$src/tests/reports/fixtures/fake-viewer.js
"$polydyn" report "$fixture" -o "$work/o/v.html" --viewer "$fake" 2>/dev/null
runs=$(grep -o '<details class="replay" data-run="[^"]*" data-replay="[^"]*"' "$work/o/v.html" | wc -l)
files=$(find "$work/o/v-replays" -name '*.js' | wc -l)
[[ $runs -eq 2 && $files -eq 2 && $(grep -c 'id="pd-viewer-bundle"' "$work/o/v.html") -eq 1 ]] &&
  ok "-o v.html with a viewer: 2 replay blocks, their 2 data files in v-replays/, the bundle once" || bad "replays: $runs blocks, $files files"
# each block names a file that holds that run's summary.json and trajectory.csv (numbers shortened to the
# values the viewer keeps), and is smaller than the run's files
python3 - "$work/o/v.html" "$work/o/v-replays" "$fixture" "$src/tests/reports" <<'EOF' && ok "each replay file holds its run's trajectory.csv and summary.json, in fewer bytes" || bad "replay files"
import json, os, re, sys
page, folder, fixture, here = sys.argv[1:]
sys.path.insert(0, here)
from replay_files import read_replay, same_trajectory
blocks = re.findall(r'<details class="replay" data-run="([^"]*)" data-replay="([^"]*)"', open(page, encoding="utf-8").read())
for run, name in blocks:
    files = read_replay(folder, name)
    assert files["run"] == run, (files["run"], run)
    full = open(os.path.join(fixture, run, "trajectory.csv"), encoding="utf-8").read()
    assert same_trajectory(files["trajectory"], full) and len(files["trajectory"]) < len(full), run
    assert files["summary"] == json.load(open(os.path.join(fixture, run, "summary.json"), encoding="utf-8")), run
EOF
cp -r "$work/o/v-replays" "$work/first-replays"
echo stale >"$work/o/v-replays/stale.js"
"$polydyn" report "$fixture" -o "$work/o/v.html" --viewer "$fake" 2>/dev/null
diff -r "$work/first-replays" "$work/o/v-replays" >/dev/null && [[ -z $(find "$work/o" -name '*.tmp-*' -o -name '*.old-*') ]] &&
  ok "a second run replaces the replay folder with identical bytes (no stale file, no temporary)" || bad "the replay folder differs between two runs"
"$polydyn" report "$fixture" -o "$work/o/v.html" --no-viewer 2>/dev/null
[[ ! -e $work/o/v-replays ]] && ! grep -q 'data-replays=' "$work/o/v.html" && ok "a page without replays removes its replay folder" ||
  bad "--no-viewer left $work/o/v-replays"

# --- sections are pluggable: a directory with only sweep.csv gets the sweep's sections only
mkdir "$work/s"
cp "$fixture/sweep.csv" "$work/s/"
"$polydyn" report "$work/s" --no-viewer 2>/dev/null
sections=$(python3 -c 'import json,sys; print(",".join(json.load(open(sys.argv[1]))["sections"]))' "$work/s/report.json")
[[ $sections == "verdict,work-precision,cost" ]] && ok "only sweep.csv: sections verdict, work-precision, cost" || bad "sweep-only sections: $sections"
grep -q 'PASS/FAIL matrix' "$work/s/report.html" && bad "the sweep-only page has a matrix" || ok "the sweep-only page has no matrix"

# a sweep.csv written before the self-convergence columns (the first twelve only) still loads: the cost
# is then read on the error against the reference, and the page says the columns are missing
mkdir "$work/old"
cut -d, -f1-12 "$fixture/sweep.csv" >"$work/old/sweep.csv"
if "$polydyn" report "$work/old" --no-viewer 2>"$work/err" &&
  python3 - "$work/old/report.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["sections"] == ["verdict", "work-precision", "cost"], j["sections"]
assert not any(s["self_convergence"] for s in j["work-precision"])
assert all(c["to_target"] == c["to_target_reference"] for s in j["work-precision"] for c in s["curves"])
assert all(p["self_error"] is None and p["horizon_seconds"] is None for s in j["work-precision"] for c in s["curves"] for p in c["points"])
ode = j["cost"]["rows"][[r["ev"] for r in j["cost"]["rows"]].index("ode native")]
assert ode["to_target"]["cases/gedanken/slide.scene"]["kind"] == "never", ode
PY
then
  grep -q 'no self-convergence columns' "$work/old/report.html" && ! grep -q 'class="horizon"' "$work/old/report.html" &&
    ok "an old sweep.csv (12 columns) loads: the error against the reference, no horizon table" ||
    bad "the old sweep.csv page does not say it has no self-convergence columns"
else
  bad "an old sweep.csv (12 columns) does not load: $(cat "$work/err")"
fi
# an old sweep concatenated after a new one: each part read with its own header
{ cat "$fixture/sweep.csv"; cut -d, -f1-12 "$fixture/sweep.csv" | sed 's#cases/gedanken/#old/#'; } >"$work/old/sweep.csv"
"$polydyn" report "$work/old" --no-viewer 2>"$work/err" &&
  [[ $(python3 -c 'import json,sys; print(sum(s["self_convergence"] for s in json.load(open(sys.argv[1]))["work-precision"]))' "$work/old/report.json") == 2 ]] &&
  ok "a new and an old sweep concatenated: each part read with its header" || bad "a mixed sweep.csv: $(cat "$work/err")"

# a compare directory (metrics.csv only) gets the comparison table only
"$polydyn" report "$src/tests/reports/fixtures/compare" -o "$work/o/cmp.html" --no-viewer 2>/dev/null
sections=$(python3 -c 'import json,sys; print(",".join(json.load(open(sys.argv[1]))["sections"]))' "$work/o/cmp.json")
[[ $sections == "compare" ]] && ok "only metrics.csv: section compare" || bad "compare-only sections: $sections"
mkdir "$work/e"
cp "$fixture/experiments.json" "$work/e/"
[[ $("$polydyn" report "$work/e" --no-viewer 2>"$work/err"; echo $?) == 2 ]] && grep -q "nothing to report" "$work/err" &&
  ok "experiments.json alone (no results, no series): nothing to report, exit 2" || bad "experiments.json alone: $(cat "$work/err")"

# --- malformed inputs: FILE:LINE, exit 2, nothing written
fresh; sed -i '5s/,[^,]*$//' "$work/d/results.csv"
expect_bad "a row one field short" "$work/d/results.csv:5: 16 fields expected, 15 found"
fresh; sed -i '3s/,\(PASS\|FAIL\),/,MAYBE,/' "$work/d/results.csv"
expect_bad "an unknown status" "$work/d/results.csv:3: status: expected one of PASS, FAIL, REFUSED, NOT_BUILT, ERROR"
fresh; sed -i '4s/,restitution,1,e=0.3,[^,]*,/,restitution,1,e=0.3,zero point five,/' "$work/d/results.csv"
expect_bad "a measured value that is not a number" "$work/d/results.csv:4: measured: not a number: 'zero point five'"
fresh; sed -i '7s/,A,Restitution/,A,"Restitution/' "$work/d/results.csv"
expect_bad "an unbalanced quote, reported where it opens" "$work/d/results.csv:7: the quoted field that opens here runs to line"
fresh; printf 'x,"never closed\n' >>"$work/d/results.csv"; n=$(wc -l <"$work/d/results.csv")
expect_bad "a quote that never closes" "$work/d/results.csv:$n: quoted field is never closed"
fresh; sed -i '1s/,note$/,notes/' "$work/d/results.csv"
expect_bad "a wrong header" "$work/d/results.csv:1: header must be exactly"
fresh; sed -n '2p' "$work/d/results.csv" >>"$work/d/results.csv"; n=$(wc -l <"$work/d/results.csv")
expect_bad "a duplicate row" "$work/d/results.csv:$n: duplicate row: same experiment, engine, variant and input as line 2"
fresh; sed -i '2s/^A1,A,/A1,AB,/' "$work/d/results.csv"
expect_bad "a group that is not one letter" "$work/d/results.csv:2: group:"
fresh; sed -i '2s#runs/A1/soft-adaptive-e=0.3#../../etc#' "$work/d/results.csv"
expect_bad "a run_dir outside DIR" "$work/d/results.csv:2: run_dir: must be a path inside the report directory"
fresh; sed -i '3s/,tol,0.001,/,tol,-1,/' "$work/d/sweep.csv"
expect_bad "a negative sweep setting" "$work/d/sweep.csv:3: value: must be a finite number > 0"
fresh; sed -i '4s/,step,/,dt,/; 4s/,tol,/,dt,/' "$work/d/sweep.csv"
expect_bad "an unknown sweep setting" "$work/d/sweep.csv:4: setting: expected tol or step"
fresh; sed -i '3s/,[^,]*$/,-0.5/' "$work/d/sweep.csv"
expect_bad "a negative horizon" "$work/d/sweep.csv:3: horizon_seconds: must be empty or a finite number ≥ 0"
fresh; sed -i '3s/,[^,]*,[^,]*,[^,]*$/,x,soft tol=1e-12,/' "$work/d/sweep.csv"
expect_bad "a self_error that is not a number" "$work/d/sweep.csv:3: self_error: not a number: 'x'"
fresh; sed -i '1s/,horizon_seconds$/,horizon/' "$work/d/sweep.csv"
expect_bad "a sweep header neither new nor old" "$work/d/sweep.csv:1: header must be exactly"
fresh; sed -i '10s/^\([^,]*\),/\1x,/' "$work/d/series/A1.csv"
expect_bad "a series time that is not a number" "$work/d/series/A1.csv:10: t: not a number"
fresh; sed -i '3s/"name": "A1",/"name": "A1"/' "$work/d/experiments.json"
expect_bad "experiments.json with a missing comma" "$work/d/experiments.json:4: malformed JSON"
fresh; python3 - "$work/d/experiments.json" <<'PY'
import json, sys
p = sys.argv[1]; d = json.load(open(p)); del d[2]["formula"]; json.dump(d, open(p, "w"), indent=2)
PY
line=$(grep -n '"name": "A3"' "$work/d/experiments.json" | cut -d: -f1)
expect_bad "an experiment without its formula" "$work/d/experiments.json:$((line - 1)): experiment \"A3\": missing \"formula\""
fresh; printf '{\n  "engine": "ode",\n  "engine_settings": {"step": 0.001,,}\n}\n' >"$work/d/runs/A3/ode-native/summary.json"
expect_bad "a malformed summary.json" "$work/d/runs/A3/ode-native/summary.json:3: malformed JSON"
fresh; printf 'a,b\n' >"$work/d/metrics.csv"
expect_bad "metrics.csv with a wrong header" "$work/d/metrics.csv:1: header must be exactly"
# precision.csv (gedanken --precision): a header and two good rows, then one broken thing at a time
precision_csv() {
  {
    echo 'experiment,kind,engine,variant,setting,value,input,quantity,unit,measured,expected,error,relative,tolerance,judged,status,wall_seconds,wall_per_sim_second,steps,repeats,note'
    echo 'A1,law,soft,adaptive,tol,0.01,e=0.5,restitution,,0.51,0.5,0.01,false,0.005,true,ok,0.001,0.001,120,1,'
    echo 'A1,law,ode,native,,,e=0.5,restitution,,,0.5,,false,0.005,true,not_built,,,0,1,this build of polydyn has no ode adapter'
  } >"$work/d/precision.csv"
}
fresh; precision_csv
"$polydyn" report "$work/d" --no-viewer 2>"$work/err" && grep -q '"precision"' "$work/d/report.json" &&
  ok "a good precision.csv gives the precision section" || bad "precision.csv: $(cat "$work/err")"
fresh; precision_csv; sed -i '2s/,ok,/,fine,/' "$work/d/precision.csv"
expect_bad "an unknown precision status" "$work/d/precision.csv:2: status: expected one of ok, failed, no_measure, refused, not_built"
fresh; precision_csv; sed -i '2s/,0.01,false,/,,false,/' "$work/d/precision.csv"
expect_bad "an ok precision point without its error" "$work/d/precision.csv:2: an ok point needs its error"
fresh; precision_csv; sed -i '2s/,true,ok,/,yes,ok,/' "$work/d/precision.csv"
expect_bad "judged neither true nor false" "$work/d/precision.csv:2: judged: expected true or false"
fresh; precision_csv; sed -i '2s/,tol,0.01,/,tol,0,/' "$work/d/precision.csv"
expect_bad "a precision setting of 0" "$work/d/precision.csv:2: value: must be a finite number > 0"
fresh; printf '\x00\x01binary' >"$work/d/sweep.csv"
expect_bad "a binary sweep.csv" "$work/d/sweep.csv: not a text file"

# a bad input leaves an existing report as it was
fresh; echo old >"$work/d/report.html"; sed -i '5s/,[^,]*$//' "$work/d/results.csv"
"$polydyn" report "$work/d" --no-viewer 2>/dev/null
[[ $? -eq 2 && $(cat "$work/d/report.html") == old && ! -e $work/d/report.json ]] && ok "a bad input leaves the previous report untouched" ||
  bad "the previous report was changed"

# --- arguments and directories
run_rc() { "$polydyn" report "$@" >/dev/null 2>"$work/err"; echo $?; }
[[ $(run_rc) == 2 ]] && ok "no DIR: exit 2" || bad "no DIR"
[[ $(run_rc "$fixture" --bogus) == 2 ]] && grep -q "unknown option '--bogus'" "$work/err" && ok "unknown option: exit 2" || bad "unknown option"
[[ $(run_rc "$fixture" -o) == 2 ]] && ok "-o without a value: exit 2" || bad "-o without a value"
[[ $(run_rc "$work/nowhere") == 2 ]] && grep -q "^polydyn report: $work/nowhere: no such directory$" "$work/err" && ok "missing DIR: exit 2" || bad "missing DIR: $(cat "$work/err")"
[[ $(run_rc "$fixture/results.csv") == 2 ]] && grep -q "not a directory" "$work/err" && ok "a file as DIR: exit 2" || bad "a file as DIR"
mkdir "$work/empty"
[[ $(run_rc "$work/empty") == 2 ]] && grep -q "nothing to report" "$work/err" && ok "a directory without inputs: exit 2" || bad "empty DIR: $(cat "$work/err")"
[[ $(run_rc "$fixture" -o "$work/no/such/dir/r.html") == 2 ]] && grep -q "does not exist" "$work/err" && ok "-o into a missing directory: exit 2" || bad "-o missing dir: $(cat "$work/err")"
[[ $(run_rc "$fixture" --viewer "$work/none.js" -o "$work/o/v.html") == 2 ]] && grep -q "cannot read the viewer bundle" "$work/err" && ok "a missing --viewer bundle: exit 2" || bad "--viewer missing: $(cat "$work/err")"
[[ $(PD_NODE=/nonexistent/node run_rc "$fixture" -o "$work/o/n.html") == 1 ]] && grep -q "cannot run /nonexistent/node" "$work/err" && ok "no node: exit 1 with a message" || bad "no node: $(cat "$work/err")"
[[ $(PD_REPORT_GENERATOR=/nonexistent/report.mjs run_rc "$fixture") == 1 ]] && grep -q "report generator /nonexistent/report.mjs is not there" "$work/err" && ok "no generator: exit 1" || bad "no generator: $(cat "$work/err")"
"$polydyn" report --help | grep -q '^usage: polydyn report DIR' && ok "--help" || bad "--help"

echo "$pass passed, $fail failed"
[[ $fail -eq 0 ]]
