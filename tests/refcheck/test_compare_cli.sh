#!/usr/bin/env bash
# End-to-end tests of `polydyn compare` (docs/commands.md, docs/DESIGN.md §8.1): usage errors, the compare directory (metrics.csv
# in its documented schema, compare.json, the run directories), atomic replacement, and that the soft run's
# error against its 100× tighter reference is small on a scene with a known smooth answer.
#
# usage: test_compare_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u
if [ $# -ne 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR" >&2
  exit 2
fi
PD=$1
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_compare.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial

# a cube sliding to rest on a floor (μ 0.4, 2 m/s): smooth, so the default tolerance is close to the reference
SCENE=$SCRATCH/slide.scene
cat >"$SCENE" <<'SC'
tend 0.8
sample 100
cube floor grey 3 3 0.2
fixed
loc 0 0 -0.1
mu 0.4
restitution 0.5
cube block red 0.2 0.2 0.2
loc 0 0 0.1
mu 0.4
restitution 0.5
vel 2 0 0
SC

"$PD" compare >/dev/null 2>&1; rc=$?; check "no scene: exit 2" '[ $rc -eq 2 ]'
"$PD" compare "$SCENE" >/dev/null 2>"$SCRATCH/err"; rc=$?; check "no --out: exit 2" '[ $rc -eq 2 ]'
check "no --out: says so" 'grep -q -- "--out" "$SCRATCH/err"'
"$PD" compare "$SCENE" --out "$SCRATCH/x" --engines soft,havok >/dev/null 2>"$SCRATCH/err"; rc=$?
check "unknown engine: exit 2" '[ $rc -eq 2 ] && grep -q havok "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
# an empty list names no engine: refused with a whole message (the refusal once printed an unset buffer)
"$PD" compare "$SCENE" --out "$SCRATCH/x" --engines '' >/dev/null 2>"$SCRATCH/err"; rc=$?
check "empty engine list: exit 2" '[ $rc -eq 2 ] && grep -q "^polydyn compare: --engines: unknown engine '"''"'" "$SCRATCH/err" && [ ! -e "$SCRATCH/x" ]'
mkdir "$SCRATCH/precious"
"$PD" compare "$SCENE" --out "$SCRATCH/precious" --engines soft >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a directory that is not a compare directory is not replaced" '[ $rc -eq 2 ] && [ -d "$SCRATCH/precious" ] && [ ! -e "$SCRATCH/precious/metrics.csv" ]'
"$PD" compare --help | grep -q "metrics.csv"; rc=$?; check "--help documents metrics.csv" '[ $rc -eq 0 ]'

OUT=$SCRATCH/cmp
"$PD" compare "$SCENE" --out "$OUT" --engines soft >"$SCRATCH/stdout" 2>"$SCRATCH/err"; rc=$?
check "compare soft: exit 0" '[ $rc -eq 0 ]'
check "metrics.csv header is the documented schema" \
  '[ "$(head -n 1 "$OUT/metrics.csv")" = "scene,engine,variant,reference,pos_err_final,pos_err_rms,rot_err_final_rad,rot_err_rms_rad,energy_drift_rel,momentum_drift_rel,max_penetration_over_size,wall_per_sim_second,steps,restitution_impacts" ]'
check "two rows: the reference and the soft run" '[ "$(tail -n +2 "$OUT/metrics.csv" | wc -l)" -eq 2 ]'
check "run directories kept for replay" '[ -f "$OUT/runs/soft-implicit/trajectory.csv" ] && [ -f "$OUT/runs/soft-reference/summary.json" ]'
check "compare.json lists the runs" 'grep -q "\"soft-implicit\"\|runs/soft-implicit" "$OUT/compare.json"'
check "no partial directory left" '[ -z "$(ls -d "$SCRATCH"/cmp.partial-* 2>/dev/null)" ]'
# the soft run against the reference: final position error below 1e-4 of the block's size (smooth scene,
# the default tolerance vs 100× tighter), energy lost (sliding friction), the reference's row says "self"
awk -F, 'NR == 3 { ok = ($4 ~ /^soft tol=/) && ($5 + 0 < 1e-4) && ($9 + 0 < 0) } END { exit !ok }' "$OUT/metrics.csv"; rc=$?
check "soft vs reference: error < 1e-4 of the size, energy lost" '[ $rc -eq 0 ]'
awk -F, 'NR == 2 { ok = ($4 == "self") } END { exit !ok }' "$OUT/metrics.csv"; rc=$?; check "reference row marked self" '[ $rc -eq 0 ]'
# an engine that is not built or refuses is reported, not fatal; the soft rows are still written
"$PD" compare "$SCENE" --out "$OUT" --engines soft,ode --variants native >/dev/null 2>"$SCRATCH/err"; rc=$?
check "with ode: exit 0 and the compare directory replaced" '[ $rc -eq 0 ] && [ -f "$OUT/metrics.csv" ] && [ -z "$(ls -d "$SCRATCH"/cmp.old-* 2>/dev/null)" ]'
check "ode's row or its reason is there" 'grep -q "^\"[^\"]*\",ode,native" "$OUT/metrics.csv" || grep -q "ode-native" "$SCRATCH/err"'

# a directory of scenes: DIR/NAME/ per scene, DIR/metrics.csv = the header and every scene's rows in name order
SCENES=$SCRATCH/scenes
mkdir "$SCENES"
cp "$SCENE" "$SCENES/b_slide.scene"
sed 's/^vel 2 0 0/vel 1 0 0/' "$SCENE" >"$SCENES/a_slow.scene"
"$PD" compare "$SCENES" --out "$SCRATCH/many" --engines soft --tend 0.2 >"$SCRATCH/stdout" 2>"$SCRATCH/err"; rc=$?
check "a directory of scenes: exit 0, one sub-directory per scene" \
  '[ $rc -eq 0 ] && [ -f "$SCRATCH/many/a_slow/compare.json" ] && [ -f "$SCRATCH/many/b_slide/runs/soft-implicit/trajectory.csv" ]'
check "a directory of scenes: metrics.csv is the header, then a_slow's rows, then b_slide's" \
  '[ "$(cat "$SCRATCH/many/metrics.csv")" = "$(head -n 1 "$SCRATCH/many/a_slow/metrics.csv"; tail -n +2 "$SCRATCH/many/a_slow/metrics.csv"; tail -n +2 "$SCRATCH/many/b_slide/metrics.csv")" ] && [ "$(wc -l <"$SCRATCH/many/metrics.csv")" -eq 5 ]'
printf 'cube c red 1 1 1\nloc 0 0 zero\n' >"$SCENES/c_bad.scene"
"$PD" compare "$SCENES" --out "$SCRATCH/bad" --engines soft >/dev/null 2>"$SCRATCH/err"; rc=$?
check "one bad scene in the directory: exit 2 at its line, nothing written" \
  '[ $rc -eq 2 ] && grep -q "c_bad.scene:2:" "$SCRATCH/err" && [ ! -e "$SCRATCH/bad" ] && no_partial "$SCRATCH/bad"'
mkdir "$SCRATCH/empty"
"$PD" compare "$SCRATCH/empty" --out "$SCRATCH/none" >/dev/null 2>"$SCRATCH/err"; rc=$?
check "a directory without scenes: exit 2, says so" '[ $rc -eq 2 ] && grep -q "no NAME.scene" "$SCRATCH/err" && [ ! -e "$SCRATCH/none" ]'

# where, when and why (docs/compare-report.md): a cube dropped 0.5 m flat onto a floor (e = 0.5), named with a
# quote and a comma; soft runs only (the reference, its chaos run and the default tolerance)
BOUNCE=$SCRATCH/bounce.scene
printf 'tend 0.7\nsample 100\ncube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\nrestitution 0.5\ncube b"ox,1 red 0.2 0.2 0.2\nloc 0 0 0.6\nrestitution 0.5\n' >"$BOUNCE"
"$PD" compare "$BOUNCE" --out "$SCRATCH/bounce" --engines soft >"$SCRATCH/stdout" 2>"$SCRATCH/err"; rc=$?
check "bounce: exit 0, the four files beside metrics.csv" '[ $rc -eq 0 ] && for f in series impacts friction divergence; do [ -f "$SCRATCH/bounce/$f.csv" ] || exit 1; done'
check "the terminal table prints — where a value does not apply (the reference's own error)" \
  'grep -q "^soft-reference *ok *— *—" "$SCRATCH/stdout"'
python3 - "$SCRATCH/bounce" <<'PY'; rc=$?
import csv, json, math, sys
d = sys.argv[1]
mass = [b["mass"] for b in json.load(open(f"{d}/runs/soft-reference/summary.json"))["bodies"] if b["name"] == 'b"ox,1'][0]
rows = lambda name: list(csv.DictReader(open(f"{d}/{name}.csv", newline="")))
imp = rows("impacts")
assert list(imp[0].keys()) == "scene,engine,variant,impact,body_a,body_b,t,vn_before,vn_after,restitution,restitution_requested,tangential_speed_change,reference_impact".split(","), imp[0].keys()
# the quoted name reads back whole (RFC 4180)
assert all(r["body_a"] == "floor" and r["body_b"] == 'b"ox,1' for r in imp), imp[0]
first = {r["variant"]: r for r in imp if r["impact"] == "0"}
# free fall of 0.5 m: |v_n| = sqrt(2 g h) at contact (the reference within 1e-3 m/s)
assert abs(float(first["reference"]["vn_before"]) + math.sqrt(2 * 9.81 * 0.5)) < 1e-3, first["reference"]
# the soft model's restitution is the requested one (eq. 15: within 1e-2 at this sample rate), matched to the reference's impact
for v in ("reference", "implicit"):
    assert abs(float(first[v]["restitution"]) - 0.5) < 1e-2 and first[v]["restitution_requested"] == "0.5" and first[v]["reference_impact"] == "0", first[v]
# every impact of the soft run found in the reference: bounces alike to 1e-2 s
assert all(r["reference_impact"] != "" for r in imp), [r for r in imp if r["reference_impact"] == ""]
div = {r["variant"]: r for r in rows("divergence")}
assert div["chaos"]["verdict"] == "own_divergence" and div["implicit"]["verdict"] == "agrees" and div["implicit"]["first_t"] == "", div
ser = rows("series")
# every run, every sample (0.7 s at 100 /s: 71), the one moving body; the soft runs report contacts
for v in ("reference", "chaos", "implicit"):
    mine = [r for r in ser if r["variant"] == v]
    assert len(mine) == 71 and all(r["body"] == 'b"ox,1' for r in mine), (v, len(mine))
    assert max(int(r["contacts"]) for r in mine) >= 4, v  # a flat landing: the four bottom corners
    assert max(float(r["normal_force"]) for r in mine) > 2 * mass * 9.81, v  # an impact pushes harder than the weight
PY
check "impacts.csv, divergence.csv and series.csv: documented header, quoted name, e = 0.5 ± 0.01 matched, verdicts" '[ $rc -eq 0 ]'

# every engine's contacts (the soft engine's own, ODE's joint feedback, Bullet's impulses over the step): the
# sliding block's friction is mu times its normal force, and that force its weight, in sum over its contacts
"$PD" compare "$SCENE" --out "$SCRATCH/slide" --tend 0.4 >/dev/null 2>"$SCRATCH/err"; rc=$?
python3 - "$SCRATCH/slide" <<'PY'; rc2=$?
import csv, json, sys
d = sys.argv[1]
mass = [b["mass"] for b in json.load(open(f"{d}/runs/soft-reference/summary.json"))["bodies"] if b["name"] == "block"][0]
runs = {(r["engine"], r["variant"]) for r in csv.DictReader(open(f"{d}/series.csv", newline=""))}
fr = list(csv.DictReader(open(f"{d}/friction.csv", newline="")))
bad = []
for run in sorted(runs):
    for t in ("0.1", "0.2", "0.3"):
        mine = [r for r in fr if (r["engine"], r["variant"]) == run and r["t"] == t]
        fn, ft = sum(float(r["fn"]) for r in mine), sum(float(r["ft"]) for r in mine)
        # friction within 1 % of mu = 0.4 times the normal force (every point slides at 2 - 0.4 g t m/s); the
        # weight within 1 % (Bullet's impulses chatter from step to step: 0.4, 1 and 1.6 times it at these samples)
        weight = run[0] == "bullet" or abs(fn - mass * 9.81) < 0.01 * mass * 9.81
        if not (weight and fn > 0 and abs(ft - 0.4 * fn) < 0.01 * fn and all(r["mode"] == "slip" for r in mine)):
            bad.append((run, t, fn, ft))
if bad or len(runs) < 3:
    print("runs:", sorted(runs), "off:", bad)
    sys.exit(1)
PY
check "every engine's contacts: friction mu times the normal force of a sliding block, which carries its weight" '[ $rc -eq 0 ] && [ $rc2 -eq 0 ]'

echo "test_compare_cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
