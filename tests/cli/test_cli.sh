#!/usr/bin/env bash
# End-to-end tests of the polydyn command (docs/outputs.md, docs/commands.md): help and usage errors, the run
# directory (format, atomicity, determinism, replacement), bad scenes, overrides, interruption, check.
#
# usage: test_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u

if [ $# -ne 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR" >&2
  exit 2
fi
# absolute paths: some checks run from another working directory
PD=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SRC=$(cd "$2" && pwd)
DEMO=$SRC/cases/examples/demo.scene
HEADER='t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz'

SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_cli.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT

. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial, check_interrupted


# message_at FILE ERRFILE line|file: the message starts with `FILE:LINE:COL: ` (line) or `FILE: ` (file)
message_at() {
  local text rest
  text=$(cat "$2")
  rest=${text#"$1":}
  [ "$rest" != "$text" ] || return 1
  if [ "$3" = line ]; then [[ $rest =~ ^[0-9]+:[0-9]+:\  ]]; else [[ $rest == " "* ]]; fi
}
line_count() { wc -l <"$1" | tr -d ' '; }
# summary_field FILE EXPR: EXPR evaluated in Python with d the summary's JSON
summary_field() {
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
print(eval(sys.argv[2], {"d": d}))' "$1" "$2"
}
# summary.json without its "timing" object (the only part allowed to differ between two runs)
summary_without_timing() {
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
d.pop("timing")
print(json.dumps(d, sort_keys=True))' "$1"
}

OUT=$SCRATCH/stdout
ERR=$SCRATCH/stderr

# --- help and usage errors ----------------------------------------------------------------------
run_pd "$OUT" "$ERR" --help
check "polydyn --help exits 0" '[ $rc -eq 0 ]'
check "polydyn --help prints usage" 'grep -q "^usage: polydyn" "$OUT"'
run_pd "$OUT" "$ERR" run --help
check "run --help exits 0" '[ $rc -eq 0 ]'
check "run --help prints usage" 'grep -q "^usage: polydyn run" "$OUT"'
run_pd "$OUT" "$ERR" check --help
check "check --help exits 0" '[ $rc -eq 0 ]'
check "check --help prints usage" 'grep -q "^usage: polydyn check" "$OUT"'
run_pd "$OUT" "$ERR" frobnicate
check "unknown command exits 2" '[ $rc -eq 2 ]'
check "unknown command is named on stderr" 'grep -q "frobnicate" "$ERR"'
run_pd "$OUT" "$ERR" run "$DEMO" --frobnicate
check "unknown run option exits 2" '[ $rc -eq 2 ]'
check "unknown run option is named on stderr" 'grep -q -- "--frobnicate" "$ERR"'
run_pd "$OUT" "$ERR" check "$DEMO" --frobnicate
check "unknown check option exits 2" '[ $rc -eq 2 ]'
run_pd "$OUT" "$ERR"
check "no command exits 2" '[ $rc -eq 2 ]'

# --- a run of the demo -----------------------------------------------------------------------------
RUN1=$SCRATCH/run1
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN1"
check "demo run exits 0" '[ $rc -eq 0 ]'
check "demo run has trajectory.csv" '[ -f "$RUN1/trajectory.csv" ]'
check "demo run has summary.json" '[ -f "$RUN1/summary.json" ]'
check "trajectory header is exact" '[ "$(head -n 1 "$RUN1/trajectory.csv")" = "$HEADER" ]'
# demo: tend T (a whole number of seconds), sample 100 -> 100 T + 1 samples; 3 moving bodies (the floor is fixed)
DEMO_TEND=$(awk '$1 == "tend" { t = $2 } END { printf "%d", t }' "$DEMO")
DEMO_SAMPLES=$((100 * DEMO_TEND + 1))
check "trajectory has samples x moving bodies rows" '[ "$(line_count "$RUN1/trajectory.csv")" -eq $((1 + DEMO_SAMPLES * 3)) ]'
check "trajectory rows have 15 fields" \
  '[ "$(tail -n +2 "$RUN1/trajectory.csv" | awk -F, "NF != 15" | wc -l)" -eq 0 ]'
check "trajectory lists bodies in scene order" \
  '[ "$(sed -n "2,4p" "$RUN1/trajectory.csv" | cut -d, -f2 | tr "\n" " ")" = "box cone ball " ]'
check "last sample is at t = tend" '[ "$(tail -n 1 "$RUN1/trajectory.csv" | cut -d, -f1)" = "$DEMO_TEND" ]'
check "summary.json is valid JSON" 'python3 -m json.tool "$RUN1/summary.json" >/dev/null'
check "no leftover partial directory" 'no_partial "$RUN1"'

NESTED=$SCRATCH/not/yet/there
run_pd "$OUT" "$ERR" run "$DEMO" --out "$NESTED" --tend 0.1
check "run creates missing parent directories of --out" '[ $rc -eq 0 ] && [ -f "$NESTED/summary.json" ]'
(cd "$SCRATCH" && "$PD" run "$DEMO" --tend 0.1 >/dev/null 2>&1)
check "run without --out writes out/NAME in the working directory" '[ -f "$SCRATCH/out/demo/summary.json" ]'

# --- determinism -------------------------------------------------------------------------------
RUN2=$SCRATCH/run2
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN2"
check "second demo run exits 0" '[ $rc -eq 0 ]'
check "two runs give identical trajectory bytes" 'cmp -s "$RUN1/trajectory.csv" "$RUN2/trajectory.csv"'
check "two runs give identical summaries apart from timing" \
  '[ "$(summary_without_timing "$RUN1/summary.json")" = "$(summary_without_timing "$RUN2/summary.json")" ]'
has_timing() { python3 -c 'import json, sys; sys.exit(0 if "timing" in json.load(open(sys.argv[1])) else 1)' "$1"; }
check "summary has a timing object" 'has_timing "$RUN1/summary.json"'

# --- bad scenes --------------------------------------------------------------------------------
BAD=$SCRATCH/bad
mkdir "$BAD"
printf 'frob 1 2 3\n' >"$BAD/unknown_command.scene"
printf 'cube a red 1 1\n' >"$BAD/wrong_arity.scene"
printf 'cube a red 1 1 1\nloc 0 0\n' >"$BAD/wrong_property_arity.scene"
printf 'cube a red 1 nan 1\n' >"$BAD/nan.scene"
printf 'cube a red 1 1 1\nvel 0 0 inf\n' >"$BAD/infinite.scene"
printf 'tend abc\ncube a red 1 1 1\n' >"$BAD/not_a_number.scene"
printf 'cube a red 1 -1 1\n' >"$BAD/negative_size.scene"
printf 'tol 0\ncube a red 1 1 1\n' >"$BAD/out_of_range.scene"
printf 'loc 0 0 0\ncube a red 1 1 1\n' >"$BAD/property_before_object.scene"
printf 'cube a red 1 1 1\ncube a blue 1 1 1\nloc 3 0 0\n' >"$BAD/duplicate_name.scene"
printf 'hull h red 0 0 0  1 0 0  0 1 0  1 1 0\n' >"$BAD/coplanar_hull.scene"
printf '# nothing here\n' >"$BAD/no_object.scene"
# two cubes of side 0.1 m with centres 0.09 m apart: 1 cm of overlap at t = 0 (docs/DESIGN.md §4.1)
printf 'cube a red 0.1 0.1 0.1\ncube b red 0.1 0.1 0.1\nloc 0.09 0 0\n' >"$BAD/overlapping_bodies.scene"
# below 0.01 the contact model refuses the restitution (its damper would need steps ~10x shorter)
printf 'cube a red 1 1 1\nrestitution 0.005\n' >"$BAD/unreachable_restitution.scene"
head -c 4096 "$PD" >"$BAD/binary.scene"
mkdir "$BAD/directory.scene"

for scene in "$BAD"/*.scene "$BAD/missing.scene"; do
  name=$(basename "$scene" .scene)
  dir=$SCRATCH/out_$name
  run_pd "$OUT" "$ERR" run "$scene" --out "$dir"
  check "$name: exit 2" '[ $rc -eq 2 ]'
  check "$name: exactly one line on stderr" '[ "$(line_count "$ERR")" -eq 1 ]'
  case $name in
    missing | directory | no_object) check "$name: message is FILE: ..." 'message_at "$scene" "$ERR" file' ;;
    *) check "$name: message is FILE:LINE:COL: ..." 'message_at "$scene" "$ERR" line' ;;
  esac
  check "$name: nothing written" '[ ! -e "$dir" ] && no_partial "$dir"'
done

# --- overrides ---------------------------------------------------------------------------------
RUN3=$SCRATCH/run3
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN3" --tend 0.5 --sample 10
check "--tend 0.5 --sample 10 exits 0" '[ $rc -eq 0 ]'
check "--tend 0.5 --sample 10 gives 6 samples per body" \
  '[ "$(tail -n +2 "$RUN3/trajectory.csv" | awk -F, "\$2 == \"box\"" | wc -l)" -eq 6 ]'
check "--tend 0.5 --sample 10 gives 6 x 3 rows" '[ "$(line_count "$RUN3/trajectory.csv")" -eq $((1 + 6 * 3)) ]'
# k / 10 printed with %.17g
TIMES="0 0.10000000000000001 0.20000000000000001 0.29999999999999999 0.40000000000000002 0.5 "
sample_times() { tail -n +2 "$1" | cut -d, -f1 | uniq | tr "\n" " "; }
check "samples at 0, 0.1, ..., 0.5" '[ "$(sample_times "$RUN3/trajectory.csv")" = "$TIMES" ]'
# --tol replaces the scene's tol (the demo's is 1e-8): summary.json says which was in force, and the largest step
# follows it (docs/events.md, "The largest step": 1e-2 s at tol 1e-6 and tighter, longer at a looser one); the
# scene's own tol given again changes no byte
RUN_TOL=$SCRATCH/run_tol
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN_TOL" --tend 0.5 --sample 10 --tol 1e-4
check "--tol 1e-4 exits 0" '[ $rc -eq 0 ]'
check "--tol 1e-4: summary.json's tol is 1e-4 and its dtmax above 1e-2 s" \
  '[ "$(summary_field "$RUN_TOL/summary.json" "d[\"settings\"][\"tol\"] == 1e-4 and d[\"settings\"][\"dtmax\"] > 1e-2")" = True ]'
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN_TOL" --tend 0.5 --sample 10 --tol 1e-8
check "--tol with the scene's own tol gives the same trajectory" \
  '[ $rc -eq 0 ] && cmp -s "$RUN_TOL/trajectory.csv" "$RUN3/trajectory.csv"'
for bad in "--tend abc" "--tend -1" "--tend nan" "--sample 0" "--tend" "--islands maybe" "--islands" \
  "--tol 0" "--tol 1" "--tol abc" "--tol" "--engine ode --tol 1e-4" \
  "--engine ode --islands on" "--islands on --threads 0" "--islands on --threads 65" "--islands on --threads 2x" \
  "--islands on --threads" "--islands off --threads 2" "--engine ode --threads 1" "--sleep maybe" "--sleep" \
  "--engine bullet --sleep off"; do
  dir=$SCRATCH/out_badopt
  # shellcheck disable=SC2086
  run_pd "$OUT" "$ERR" run "$DEMO" --out "$dir" $bad
  check "run $bad exits 2" '[ $rc -eq 2 ]'
  check "run $bad writes nothing" '[ ! -e "$dir" ] && no_partial "$dir"'
done

# --sleep overrides the scene's `sleep` setting; summary.json says which was in force
RUN_SLEEP=$SCRATCH/run_sleep
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN_SLEEP" --tend 0.2 --sleep off
check "--sleep off exits 0" '[ $rc -eq 0 ]'
check "--sleep off: summary.json says sleep off, no body-seconds asleep" \
  'grep -q "\"sleep\": \"off\"" "$RUN_SLEEP/summary.json" && grep -q "\"body_seconds_asleep\": 0}" "$RUN_SLEEP/summary.json"'
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN_SLEEP" --tend 0.2
check "default: summary.json says sleep on" '[ $rc -eq 0 ] && grep -q "\"sleep\": \"on\"" "$RUN_SLEEP/summary.json"'

# --- output directory rules ----------------------------------------------------------------------
KEEP=$SCRATCH/not_a_run
mkdir "$KEEP"
echo "precious" >"$KEEP/notes.txt"
run_pd "$OUT" "$ERR" run "$DEMO" --out "$KEEP"
check "existing non-run directory is refused with 2" '[ $rc -eq 2 ]'
check "refused directory is left untouched" \
  '[ "$(ls -A "$KEEP")" = "notes.txt" ] && [ "$(cat "$KEEP/notes.txt")" = "precious" ]'
check "refused directory: no partial left" 'no_partial "$KEEP"'
echo "x" >"$SCRATCH/a_file"
run_pd "$OUT" "$ERR" run "$DEMO" --out "$SCRATCH/a_file"
check "existing file as --out is refused with 2" '[ $rc -eq 2 ] && [ "$(cat "$SCRATCH/a_file")" = "x" ]'

touch "$RUN3/stale-marker"
run_pd "$OUT" "$ERR" run "$DEMO" --out "$RUN3"
check "existing run directory is replaced (exit 0)" '[ $rc -eq 0 ]'
check "replaced run directory holds the new run" '[ "$(line_count "$RUN3/trajectory.csv")" -eq $((1 + DEMO_SAMPLES * 3)) ]'
check "replaced run directory lost the old contents" '[ ! -e "$RUN3/stale-marker" ]'
check "replaced run directory: no partial or old copy left" 'no_partial "$RUN3"'

# --- interruption --------------------------------------------------------------------------------
# ~15 s of work (1e7 steps of 10 µs), 100 samples per simulated second so SIGINT is seen at once
LONG=$SCRATCH/long.scene
printf 'gravity 0 0 -9.81\ntend 100\ntol 1e-12\ndt 1e-5\ndtmax 1e-5\nsample 100\n%s\n%s\n' \
  'cube box red 0.1 0.2 0.3' 'vel 1 0 2  720 1 2 3' >"$LONG"
INT=$SCRATCH/interrupted
check_interrupted "$OUT" "$ERR" "$INT" run "$LONG" --out "$INT"

# --- check ---------------------------------------------------------------------------------------
run_pd "$OUT" "$ERR" check "$DEMO"
check "check demo exits 0" '[ $rc -eq 0 ]'
check "check prints each body's mass" '[ "$(grep -c "^    mass " "$OUT")" -eq 4 ]'
check "check prints the box's mass (0.2 x 0.3 x 0.4 x 1000 = 24 kg)" 'grep -q "^    mass            24 kg" "$OUT"'
check "check prints V=8 E=12 F=6 for a cube" '[ "$(grep -c "V=8 E=12 F=6" "$OUT")" -eq 2 ]'
check "check names every body" \
  'grep -q "^  floor: " "$OUT" && grep -q "^  box: " "$OUT" && grep -q "^  cone: " "$OUT" && grep -q "^  ball: " "$OUT"'
run_pd "$OUT" "$ERR" check "$BAD/coplanar_hull.scene"
check "check on a bad scene exits 2" '[ $rc -eq 2 ]'

# --- contact material parameters (paper §3.2, §3.3) ------------------------------------------------
run_pd "$OUT" "$ERR" check "$DEMO"
check "check prints the material used by every body" '[ "$(grep -c "^    material used   mu .*, restitution 0.5 (damping ratio 0.2553" "$OUT")" -eq 4 ]'
PAIRS=$(sed -n 's/^contact pairs: \([0-9]*\) .*/\1/p' "$OUT")
check "check prints the springs and dampers of every pair" \
  '[ "${PAIRS:-0}" -ge 3 ] && [ "$(grep -c "^    springs       kn .* per contact" "$OUT")" -eq "$PAIRS" ] && [ "$(grep -c "^    normal damper modal: damping ratio 0.2553" "$OUT")" -eq "$PAIRS" ]'
# a cube resting exactly on a floor (touching is not overlapping), default dtmin: nothing adjusted
REST=$SCRATCH/resting.scene
printf 'cube floor grey 2 2 0.2\nfixed\nloc 0 0 -0.1\ncube box red 0.2 0.2 0.2\nloc 0 0 0.1\nrestitution 0.5\n' >"$REST"
run_pd "$OUT" "$ERR" check "$REST"
check "check accepts a cube resting on a floor" '[ $rc -eq 0 ]'
check "check says when nothing was adjusted" 'grep -q "^adjustments: none$" "$OUT"'
run_pd "$OUT" "$ERR" check "$BAD/overlapping_bodies.scene"
check "check on overlapping bodies exits 2" '[ $rc -eq 2 ]'
check "overlap message names both bodies at the later one's line" \
  'grep -q "overlapping_bodies.scene:2:1: bodies .a. and .b. overlap by 0.01 m at t = 0" "$ERR"'
run_pd "$OUT" "$ERR" check "$BAD/unreachable_restitution.scene"
check "check on restitution 0.1 exits 2" '[ $rc -eq 2 ]'
check "restitution 0.005 is refused for being below 0.01" 'grep -q ":1:1: .*restitution 0.005 is below 0.01" "$ERR"'
# a resting cube and dtmin above its contact time constant: the pair's kn and kt lowered on both sides
# (§3.3.1) and listed; explicit dampers of different c/k on the two sides of a second pair: its surface
# elements are faster than dtmin, so its normal dampers are switched off (§3.3.2)
ADJ=$SCRATCH/adjusted.scene
printf 'dt 1e-3\ndtmin 1e-3\ntend 0.01\nvmax 10\n%s\nfixed\nloc 0 0 -0.1\n%s\nloc 0 0 0.1\nrestitution 0.5\n%b\n' \
  'cube floor grey 2 2 0.2' 'cube box red 0.2 0.2 0.2' \
  'cube a red 0.1 0.1 0.1\nloc 0.5 0 0.05\nkn 1e4\ncn 1\ncube b red 0.1 0.1 0.1\nloc 0.7 0 0.05\nkn 2e4\ncn 1' >"$ADJ"
run_pd "$OUT" "$ERR" check "$ADJ"
check "check on an adjusted scene exits 0" '[ $rc -eq 0 ]'
check "check lists the pair adjustments (§3.3.1) of both sides" \
  '[ "$(grep -c "^  box: k[nt] .* in contacts with floor (§3.3.1: " "$OUT")" -eq 2 ] && [ "$(grep -c "^  floor: k[nt] .* in contacts with box (§3.3.1: " "$OUT")" -eq 2 ]'
check "check lists the surface-element adjustments (§3.3.2)" 'grep -q "^  a: cn 1 -> 0 N·s/m in contacts with b (§3.3.2" "$OUT"'
RUNADJ=$SCRATCH/run_adjusted
run_pd "$OUT" "$ERR" run "$ADJ" --out "$RUNADJ"
check "summary.json lists the adjustments" \
  '[ "$(summary_field "$RUNADJ/summary.json" "sum(\"§3.3\" in a for a in d[\"adjustments\"])")" -ge 5 ]'
check "summary.json has each pair's kn and damping ratio" \
  '[ "$(summary_field "$RUNADJ/summary.json" "all(p[\"kn\"] > 0 and p[\"damping\"][\"n\"] in (\"modal\", \"explicit\") for p in d[\"contact_pairs\"]) and any(abs(p[\"zeta_n\"] - 0.2553) < 1e-4 for p in d[\"contact_pairs\"]) and d[\"contact_pairs_total\"] == len(d[\"contact_pairs\"])")" = True ]'
check "summary.json keeps timing last" '[ "$(summary_field "$RUNADJ/summary.json" "list(d)[-1]")" = timing ]'

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
