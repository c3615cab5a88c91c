#!/usr/bin/env bash
# End-to-end tests of `polydyn cubetoss` on planar drops (docs/planar-drops.md): synthetic drops
# (tests/reports/make_drops.py) in every engine with the noise floor beside them — per_toss.csv and
# summary.csv with the bounce columns and the side-length unit, a tiny fit (the noise engine has no
# parameters), the report's planar-drop section; and, when ../shared/data/planar-drops/drops-given.csv is
# there, three real drops in every engine (their bounces found in the record and the runs).
#
# usage: test_planar_drops_cli.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u
if [ $# -ne 2 ]; then
  echo "usage: $0 POLYDYN_BINARY PROJECT_SOURCE_DIR" >&2
  exit 2
fi
PD=$1
SRC=$2
DATA_FULL=$SRC/../shared/data/planar-drops/drops-given.csv
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_planar_drops_cli.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial, skip_without

DATA=$SCRATCH/drops.csv
python3 "$SRC/tests/reports/make_drops.py" "$DATA" 4 || exit 1
OUT=$SCRATCH/run
run_pd "$SCRATCH/stdout" "$SCRATCH/err" cubetoss --data "$DATA" --out "$OUT" --engines soft,ode,bullet,noise
check "synthetic drops: exit 0" '[ $rc -eq 0 ]'
check "per_toss.csv has the bounce columns" \
  '[ "$(head -n 1 "$OUT/per_toss.csv")" = "toss,split,engine,variant,params,status,samples,duration_s,pos_err_end,pos_err_rms,rot_err_end_rad,rot_err_rms_rad,impacts_record,impacts_run,impact1_dt_s,impact1_dv,impact1_dw,impact2_dt_s,impact2_dv,impact2_dw,impact3_dt_s,impact3_dv,impact3_dw,wall_seconds,cpu_seconds,steps,run_dir,message" ]'
# make_drops.py bounces with e = 0.5 from 0.10-0.15 m: the first two bounces lift it 25-37 mm and 6-9 mm
check "the record's bounces are found: at least 2 per drop" \
  '[ "$(awk -F, '"'"'NR > 1 && $3 == "soft" && $13 >= 2'"'"' "$OUT/per_toss.csv" | wc -l)" -eq 4 ]'
check "the noise floor: bounce times one sample (0.004 s) off, velocities equal" \
  '[ "$(awk -F, '"'"'NR > 1 && $3 == "noise" && $15 == "0.004" && $16 == "0"'"'"' "$OUT/per_toss.csv" | wc -l)" -eq 4 ]'
check "summary.csv: positions in side lengths, bounce velocities in m/s" \
  'grep -q "^soft,implicit,default,all,ok,4,4,pos_err_end,side_lengths," "$OUT/summary.csv" && grep -q "^ode,native,default,all,ok,4,4,impact1_dv,m/s," "$OUT/summary.csv"'
check "the noise engine keeps no run directory and no parameter fragment" \
  '[ -d "$OUT/runs/1/soft" ] && [ ! -e "$OUT/runs/1/noise" ] && [ ! -e "$OUT/params-noise.scene" ]'
FIT=$SCRATCH/fit
run_pd "$SCRATCH/stdout" "$SCRATCH/err" cubetoss fit --data "$DATA" --out "$FIT" --engines soft,noise --max-evals 2 --jobs 1
check "fit: exit 0, the noise engine has no parameters" \
  '[ $rc -eq 0 ] && grep -q "^noise,shift1,no parameters," "$FIT/fit.csv" && [ ! -e "$FIT/fitted-noise.scene" ] && [ -e "$FIT/fitted-soft.scene" ]'
check "fit: the trace has the first-bounce term" 'head -n 1 "$FIT/fit_trace.csv" | grep -q ",bounce_dv_mean$" && [ -n "$(sed -n 2p "$FIT/fit_trace.csv" | cut -d, -f12)" ]'
REPORT=$SCRATCH/report
mkdir -p "$REPORT" && cp -r "$OUT" "$REPORT/planar-drops"
run_pd "$SCRATCH/stdout" "$SCRATCH/err" report "$REPORT"
check "the report has the planar-drop section" \
  '[ $rc -eq 0 ] && python3 -c "import json,sys; j=json.load(open(sys.argv[1])); sys.exit(0 if \"planar-drops\" in j[\"sections\"] else 1)" "$REPORT/report.json"'

skip_without "$DATA_FULL" "the planar-drop data (docs/planar-drops.md)"
# ---- three real drops
REAL=$SCRATCH/three.csv
awk -F, 'NR == 1 || $1 == 1 || $1 == 2 || $1 == 3' "$DATA_FULL" >"$REAL"
run_pd "$SCRATCH/stdout" "$SCRATCH/err" cubetoss --data "$REAL" --out "$SCRATCH/real" --engines soft,ode,bullet,noise --no-runs
check "three real drops: exit 0, every engine completed" \
  '[ $rc -eq 0 ] && [ "$(awk -F, '"'"'NR > 1 && $6 == "ok"'"'"' "$SCRATCH/real/per_toss.csv" | wc -l)" -eq 12 ]'
check "three real drops: the first bounce found in the record and in every run" \
  '[ "$(awk -F, '"'"'NR > 1 && $13 >= 1 && $14 >= 1 && $16 != ""'"'"' "$SCRATCH/real/per_toss.csv" | wc -l)" -eq 12 ]'
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
