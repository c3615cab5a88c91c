#!/usr/bin/env bash
# End-to-end tests of `polydyn oracle` (docs/validation.md): help and usage errors, random
# pairs (summary, CSV format, determinism, no NaN), replay of the listed pairs (same verdicts again), a
# small scene, and bad input (scene, CSV) refused with its location and nothing written.
#
# usage: test_oracle_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u

if [ $# -ne 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR" >&2
  exit 2
fi
PD=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SRC=$(cd "$2" && pwd)
FACE=$SRC/cases/hard/cubes_face_on_face.scene
HEADER='source,index,t,kind,name_a,name_b,shape_a,shape_b,ax,ay,az,aqw,aqx,aqy,aqz,bx,by,bz,bqw,bqx,bqy,bqz,our_verdict,our_depth,gjk_verdict,mpr_verdict,epa_depth,mpr_depth,scale,size,epa_tol'

SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_oracle_cli.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT

. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial


OUT=$SCRATCH/stdout
ERR=$SCRATCH/stderr
no_partial() { ! compgen -G "$1.partial-*" >/dev/null; }
data_rows() { tail -n +2 "$1" | wc -l | tr -d ' '; }
# the number in the summary line "listed: N pairs in FILE"
listed() { sed -n 's/^listed: \([0-9]*\) pairs.*/\1/p' "$1"; }
# replay lines whose kind changed ("line N: ... was KIND, now KIND (...)")
kinds_changed() { grep "^line " "$1" | sed -E 's/.*: was ([a-z_]+), now ([a-z_]+) .*/\1 \2/' | awk '$1 != $2' | wc -l; }

# --- help and usage errors ----------------------------------------------------------------------
run_pd "$OUT" "$ERR" oracle --help
check "oracle --help exits 0" '[ $rc -eq 0 ]'
check "oracle --help prints usage" 'grep -q "^usage: polydyn oracle" "$OUT"'
run_pd "$OUT" "$ERR" --help
check "polydyn --help lists oracle" 'grep -q "^  oracle" "$OUT"'
usage_error() {  # usage_error NAME ARGS...: exit 2 with a `polydyn oracle: ` message
  local name=$1
  shift
  run_pd "$OUT" "$ERR" oracle "$@"
  check "$name exits 2" '[ $rc -eq 2 ]'
  check "$name says polydyn oracle:" 'grep -q "^polydyn oracle: " "$ERR"'
}
usage_error "no arguments"
usage_error "--random without --seed" --random 10
usage_error "--seed without --random" --seed 1
usage_error "--random 0" --random 0 --seed 1
usage_error "--random not a number" --random ten --seed 1
usage_error "--seed negative" --random 10 --seed -1
usage_error "--seed not a number" --random 10 --seed 1.5
usage_error "--random without a value" --random
usage_error "unknown option" --random 10 --seed 1 --frobnicate
check "unknown option is named" 'grep -q -- "--frobnicate" "$ERR"'
usage_error "scene and --random" "$FACE" --random 10 --seed 1
usage_error "--tend with --random" --random 10 --seed 1 --tend 1
usage_error "--sample 0" "$FACE" --sample 0
usage_error "empty --out" --random 10 --seed 1 --out ""

# --- random pairs --------------------------------------------------------------------------------
R1=$SCRATCH/r1.csv
run_pd "$SCRATCH/r1.out" "$ERR" oracle --random 300 --seed 7 --out "$R1"
check "random run exits 0" '[ $rc -eq 0 ]'
check "random run checks 300 pairs" 'grep -q "^pairs checked: 300$" "$SCRATCH/r1.out"'
check "random run reports no disagreement outside the band" 'grep -q "^verdict: ok$" "$SCRATCH/r1.out"'
check "random run prints depth statistics" 'grep -q "^  |EPA - ours|, outside: max" "$SCRATCH/r1.out"'
check "random CSV header is exact" '[ "$(head -n 1 "$R1")" = "$HEADER" ]'
check "random CSV lists what the summary says" '[ "$(data_rows "$R1")" = "$(listed "$SCRATCH/r1.out")" ]'
check "random CSV lists some touching pairs" '[ "$(data_rows "$R1")" -gt 0 ]'
check "random CSV rows have 31 fields" '[ "$(tail -n +2 "$R1" | awk -F, "NF != 31" | wc -l)" -eq 0 ]'
check "random CSV has no agreement rows" '! cut -d, -f4 "$R1" | grep -q "^agree_"'
check "no NaN in the CSV or the summary" '! grep -qi nan "$R1" "$SCRATCH/r1.out"'
check "no leftover partial CSV" 'no_partial "$R1"'

R2=$SCRATCH/r2.csv
run_pd "$SCRATCH/r2.out" "$ERR" oracle --random 300 --seed 7 --out "$R2"
check "same seed: identical CSV bytes" 'cmp -s "$R1" "$R2"'
check "same seed: identical summary apart from times" \
  '[ "$(grep -v "^time" "$SCRATCH/r1.out" | grep -v "^listed")" = "$(grep -v "^time" "$SCRATCH/r2.out" | grep -v "^listed")" ]'
run_pd "$SCRATCH/r3.out" "$ERR" oracle --random 300 --seed 8 --out "$SCRATCH/r3.csv"
check "another seed: other pairs" '! cmp -s "$R1" "$SCRATCH/r3.csv"'
(cd "$SCRATCH" && "$PD" oracle --random 5 --seed 3 >/dev/null 2>&1)
check "default --out is out/random-seed-S-N.oracle.csv" '[ -f "$SCRATCH/out/random-seed-3-5.oracle.csv" ]'

# --- replay ----------------------------------------------------------------------------------------
REP=$SCRATCH/replayed.csv
run_pd "$OUT" "$ERR" oracle --replay "$R1" --out "$REP"
check "replay exits 0" '[ $rc -eq 0 ]'
check "replay checks every listed pair" '[ "$(grep -c "^line " "$OUT")" = "$(data_rows "$R1")" ]'
check "replay finds the same kind for every pair" '[ "$(kinds_changed "$OUT")" -eq 0 ]'
check "replay writes the pairs again" '[ "$(data_rows "$REP")" = "$(data_rows "$R1")" ]'
check "replayed CSV equals the original (bit-exact rebuild)" 'cmp -s "$R1" "$REP"'

# --- a small scene ---------------------------------------------------------------------------------
SC=$SCRATCH/face.csv
run_pd "$OUT" "$ERR" oracle "$FACE" --tend 0.3 --sample 100 --out "$SC"
check "scene run exits 0" '[ $rc -eq 0 ]'
# one pair (fixed base, falling top) at 31 samples
check "scene run checks every pair at every sample" 'grep -q "^pairs checked: 31$" "$OUT"'
check "scene run sees the contact (both overlap)" 'grep -q "^agree: both overlap [1-9]" "$OUT"'
check "scene CSV header is exact" '[ "$(head -n 1 "$SC")" = "$HEADER" ]'
check "no leftover partial scene CSV" 'no_partial "$SC"'

BAD=$SCRATCH/bad
mkdir "$BAD"
printf 'cube a red 1 1\n' >"$BAD/wrong_arity.scene"
run_pd "$OUT" "$ERR" oracle "$BAD/wrong_arity.scene" --out "$BAD/x.csv"
check "bad scene exits 2" '[ $rc -eq 2 ]'
check "bad scene message is FILE:LINE:COL" 'grep -q "^$BAD/wrong_arity.scene:1:[0-9]*: " "$ERR"'
check "bad scene writes no CSV" '[ ! -e "$BAD/x.csv" ] && no_partial "$BAD/x.csv"'

# --- bad CSV files ---------------------------------------------------------------------------------
printf 'a,b,c\n' >"$BAD/header.csv"
run_pd "$OUT" "$ERR" oracle --replay "$BAD/header.csv"
check "replay of a foreign CSV exits 2" '[ $rc -eq 2 ]'
check "foreign CSV message is FILE:1:1" 'grep -q "^$BAD/header.csv:1:1: " "$ERR"'
# the first row of R1 with its 9th field (ax) replaced
{ head -n 1 "$R1"; sed -n 2p "$R1" | awk -F, -v OFS=, '{ $9 = "abc"; print }'; } >"$BAD/number.csv"
run_pd "$OUT" "$ERR" oracle --replay "$BAD/number.csv" --out "$BAD/y.csv"
check "replay of a bad number exits 2" '[ $rc -eq 2 ]'
COL=$(sed -n 2p "$BAD/number.csv" | awk -F, '{ n = 0; for (i = 1; i < 9; ++i) n += length($i) + 1; print n + 1 }')
check "bad number message is FILE:2:COL of the field" 'grep -q "^$BAD/number.csv:2:$COL: " "$ERR"'
check "bad CSV writes nothing" '[ ! -e "$BAD/y.csv" ] && no_partial "$BAD/y.csv"'
{ head -n 1 "$R1"; sed -n 2p "$R1" | awk -F, -v OFS=, '{ $7 = "cube 1 1"; print }'; } >"$BAD/shape.csv"
run_pd "$OUT" "$ERR" oracle --replay "$BAD/shape.csv"
check "replay of a bad shape exits 2" '[ $rc -eq 2 ]'
check "bad shape message names shape_a" 'grep -q "^$BAD/shape.csv:2:[0-9]*: shape_a: " "$ERR"'
run_pd "$OUT" "$ERR" oracle --replay "$BAD/missing.csv"
check "replay of a missing file exits 2" '[ $rc -eq 2 ]'

# --- --timing: usage errors, the table, the CSV, exit 0 when our modes agree -------------------------
usage_error "--timing without --random" --timing
usage_error "--timing with --replay" --replay "$R1" --timing
usage_error "--repeats without --timing" --random 10 --seed 1 --repeats 3
usage_error "--repeats 0" --random 10 --seed 1 --timing --repeats 0
usage_error "--repeats too many" --random 10 --seed 1 --timing --repeats 102
run_pd "$OUT" "$ERR" oracle --random 200 --seed 3 --timing --repeats 1 --out "$SCRATCH/timing/t.csv"
check "--timing exits 0" '[ $rc -eq 0 ]'
check "--timing: our modes agree" 'grep -q "^our modes agree .*: yes; result hash [0-9a-f]\{16\} (first, cached, min_depth)$" "$OUT"'
check "--timing prints the all row" 'grep -q "^all  *200 " "$OUT"'
check "--timing CSV header" '[ "$(head -n 1 "$SCRATCH/timing/t.csv")" = "group,mode,pairs,repeats,us_per_pair_median,us_per_pair_min,us_per_pair_max,ratio_to_gjk" ]'
check "--timing CSV: 10 modes for all pairs" '[ "$(grep -c "^all," "$SCRATCH/timing/t.csv")" -eq 10 ]'
check "--timing CSV: GJK's ratio is 1" 'grep -q "^all,ccd_gjk,200,1,.*,1.0000$" "$SCRATCH/timing/t.csv"'
run_pd "$OUT" "$ERR" oracle --random 200 --seed 3 --timing --repeats 1
H1=$(sed -n "s/.*result hash //p" "$OUT")
run_pd "$OUT" "$ERR" oracle --random 200 --seed 3 --timing --repeats 2
check "--timing: the result hash depends on the pairs only" '[ -n "$H1" ] && [ "$(sed -n "s/.*result hash //p" "$OUT")" = "$H1" ]'

echo "test_oracle_cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
