#!/usr/bin/env bash
# The report of a compared multi-body scene (polydyn compare; polydyn report with the real viewer bundle) in
# headless Chromium (compare_browser.mjs: the first screen's sentences and first-divergence table, every chart,
# the body select, the link into the 3-D replay of every run, which draws), keeping a screenshot of the first
# screen (SCREENSHOT); and a directory of compared scenes: one row per scene linking to that scene's page.
# usage: test_compare_report.sh POLYDYN SOURCE_DIR SCREENSHOT.png
set -euo pipefail
polydyn=$1
src=$2
shot=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PD_REPORT_GENERATOR=$src/reports/generator/report.mjs
bundle=$src/viewer/dist/viewer.js
if [[ ! -f $bundle ]]; then echo "FAIL - no viewer bundle at $bundle (viewer/scripts/setup builds it)"; exit 1; fi
# three boxes dropped on each other and a floor: impacts between bodies, contacts, a pile's divergence
mkdir "$work/scenes"
cat >"$work/scenes/three.scene" <<'SC'
tend 0.6
sample 100
cube floor grey 1 1 0.1
fixed
loc 0 0 -0.05
mu 0.5
restitution 0.5
cube a red 0.1 0.1 0.1
loc 0 0 0.1  20 1 1 0
mu 0.5
restitution 0.5
cube b blue 0.1 0.08 0.06
loc 0.02 0.01 0.25  35 0 1 1
mu 0.5
restitution 0.5
cube c green 0.12 0.06 0.05
loc -0.01 0.02 0.4  50 1 0 1
mu 0.5
restitution 0.5
SC
"$polydyn" compare "$work/scenes/three.scene" --out "$work/three" >/dev/null 2>&1
"$polydyn" report "$work/three" --viewer "$bundle" 2>/dev/null
node "$src/tests/reports/compare_browser.mjs" "$work/three/report.html" --screenshot "$shot"
# a directory of scenes: the overview's rows link to the page of each scene, which is written too
sed 's/^tend 0.6/tend 0.3/' "$work/scenes/three.scene" >"$work/scenes/short.scene"
"$polydyn" compare "$work/scenes" --out "$work/many" --engines soft >/dev/null 2>&1
"$polydyn" report "$work/many" --no-viewer 2>/dev/null
for name in short three; do
  grep -q "<a href=\"$name/report.html\">$name</a>" "$work/many/report.html" || { echo "FAIL - the overview has no row linking to $name/report.html"; exit 1; }
  grep -q 'id="differ"' "$work/many/$name/report.html" || { echo "FAIL - $name/report.html has no where-when-why section"; exit 1; }
done
echo "ok - a directory of compared scenes: one row per scene linking to its page (short, three), each page written"
