#!/usr/bin/env bash
# polydyn view without a browser: the page file, and bad input (docs/commands.md): exit status 2,
# `FILE:LINE:COL: message` for a malformed CSV, nothing written.
#
# usage: test_view_input.sh POLYDYN_BINARY PROJECT_SOURCE_DIR
set -u
PD=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SRC=$(cd "$2" && pwd)
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_view.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$(dirname "${BASH_SOURCE[0]}")/../lib.sh"  # check, run_pd, no_partial
run_pd() { "$PD" "$@" >"$SCRATCH/out" 2>"$SCRATCH/err"; rc=$?; }  # this script's own (fixed files)
nothing_left() { ! compgen -G "$SCRATCH/page.html*" >/dev/null; }

RUN=$SCRATCH/demo
"$PD" run "$SRC/cases/examples/demo.scene" --out "$RUN" --tend 0.3 >/dev/null 2>&1 || { echo "cannot run the demo"; exit 1; }

# --- a good page -------------------------------------------------------------------------------
if [ -f "$SRC/viewer/dist/viewer.js" ]; then
  run_pd view "$RUN" -o "$SCRATCH/good.html"
  check "view of a run directory exits 0" '[ $rc -eq 0 ]'
  check "the page has one replay element" '[ "$(grep -c "<section class=\"pd-replay\"" "$SCRATCH/good.html")" -eq 1 ]'
  check "the page inlines the bundle once" '[ "$(grep -c "^<script>$" "$SCRATCH/good.html")" -eq 1 ]'
  check "the page loads nothing from elsewhere" '! grep -qiE "<script[^>]+src=|<link[^>]+href=" "$SCRATCH/good.html"'
  run_pd view "$RUN"
  check "the default page is DIR.html" '[ $rc -eq 0 ] && [ -s "$RUN.html" ]'
  run_pd view "$RUN" -o "$SCRATCH/no/such/dir/page.html"
  check "an unwritable -o exits 2" '[ $rc -eq 2 ] && grep -q "page.html: cannot write" "$SCRATCH/err"'
else
  echo "SKIP: the viewer bundle is not built (scripts/setup); page checks skipped"
fi
POLYDYN_VIEWER_DIR=$SCRATCH/nowhere "$PD" view "$RUN" -o "$SCRATCH/page.html" >/dev/null 2>"$SCRATCH/err"
rc=$?
check "a missing bundle exits 1" '[ $rc -eq 1 ]'
check "a missing bundle is named" 'grep -q "viewer.js" "$SCRATCH/err"'
check "a missing bundle leaves no page" nothing_left

# --- arguments -----------------------------------------------------------------------------------
run_pd view
check "no run directory exits 2" '[ $rc -eq 2 ] && grep -q "^polydyn view: no run directory" "$SCRATCH/err"'
run_pd view "$RUN" --frobnicate
check "an unknown option exits 2" '[ $rc -eq 2 ] && grep -q -- "--frobnicate" "$SCRATCH/err"'
run_pd view "$RUN" --fps 30
check "--fps without --movie exits 2" '[ $rc -eq 2 ]'
run_pd view "$RUN" --movie "$SCRATCH/m.mp4" --speed 1000
check "--speed above 100 exits 2" '[ $rc -eq 2 ] && [ ! -e "$SCRATCH/m.mp4" ]'
run_pd view --help
check "view --help exits 0" '[ $rc -eq 0 ] && grep -q "^usage: polydyn view" "$SCRATCH/out"'

# --- bad run directories -------------------------------------------------------------------------
run_pd view "$SCRATCH/missing" -o "$SCRATCH/page.html"
check "a missing run directory exits 2" '[ $rc -eq 2 ] && grep -q "missing/summary.json: cannot read" "$SCRATCH/err"'
check "a missing run directory leaves no page" nothing_left

bad() {  # bad NAME: a copy of the run directory to spoil
  rm -rf "$SCRATCH/$1"
  cp -r "$RUN" "$SCRATCH/$1"
  echo "$SCRATCH/$1"
}
B=$(bad number)
sed -i '3s/^\([^,]*,[^,]*,\)[^,]*/\1abc/' "$B/trajectory.csv"
col=$(( $(sed -n 3p "$B/trajectory.csv" | cut -d, -f1,2 | wc -c) + 1 ))
run_pd view "$B" -o "$SCRATCH/page.html"
check "a non-number in trajectory.csv exits 2" '[ $rc -eq 2 ]'
check "a non-number is reported at FILE:3:COL" 'grep -q "^$B/trajectory.csv:3:$col: not a finite number" "$SCRATCH/err"'
check "a malformed CSV leaves no page" nothing_left

B=$(bad short)
sed -i '4s/,[^,]*$//' "$B/trajectory.csv"
run_pd view "$B" -o "$SCRATCH/page.html"
check "a short trajectory row is reported at its line" '[ $rc -eq 2 ] && grep -q "^$B/trajectory.csv:4:[0-9]*: expected 15 fields" "$SCRATCH/err"'

B=$(bad order)
sed -i '2{h;d};3{G}' "$B/trajectory.csv"
run_pd view "$B" -o "$SCRATCH/page.html"
check "bodies out of scene order are reported" '[ $rc -eq 2 ] && grep -q "^$B/trajectory.csv:2:[0-9]*: expected body" "$SCRATCH/err"'

B=$(bad contact)
if [ "$(wc -l <"$B/contacts.csv")" -gt 1 ]; then
  sed -i '2s/,VF,/,XX,/; 2s/,EE,/,XX,/' "$B/contacts.csv"
  run_pd view "$B" -o "$SCRATCH/page.html"
  check "a bad contact kind is reported at contacts.csv:2" '[ $rc -eq 2 ] && grep -q "^$B/contacts.csv:2:[0-9]*: kind must be VF or EE" "$SCRATCH/err"'
fi

B=$(bad json)
printf '{"engine": "x", "bodies": [' >"$B/summary.json"
run_pd view "$B" -o "$SCRATCH/page.html"
check "a truncated summary.json exits 2" '[ $rc -eq 2 ] && grep -q "^$B/summary.json:1:[0-9]*: not valid JSON" "$SCRATCH/err"'

OTHER=$SCRATCH/other
printf 'cube a red 1 1 1\nloc 0 0 1\ntend 0.1\n' >"$SCRATCH/other.scene"
"$PD" run "$SCRATCH/other.scene" --out "$OTHER" >/dev/null 2>&1
run_pd view "$RUN" "$OTHER" -o "$SCRATCH/page.html"
check "runs of different scenes are refused" '[ $rc -eq 2 ] && grep -q "not the same scene" "$SCRATCH/err"'
check "refused runs leave no page" nothing_left

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
