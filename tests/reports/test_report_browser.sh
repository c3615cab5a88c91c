#!/usr/bin/env bash
# Browser smoke test: the fixture report with cube-toss results (and a stand-in viewer bundle for the
# replay hook) and a sweep-only report load in headless Debian Chromium with no console error and no network request,
# every chart draws, and every replay loads its data from full-replays/ when opened and draws it (one of them the cube
# toss's record with each engine's run); the page copied without that folder says, in each replay, that the data is missing.
# usage: test_report_browser.sh POLYDYN SOURCE_DIR
set -euo pipefail
polydyn=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PD_REPORT_GENERATOR=$src/reports/generator/report.mjs
fixtures=$src/tests/reports/fixtures
# the Gedanken fixture with cube-toss results beside it (synthetic tosses, polydyn cubetoss)
cp -r "$fixtures/gedanken" "$work/g"
python3 "$src/tests/reports/make_tosses.py" "$work/tosses.csv" 4
"$polydyn" cubetoss --data "$work/tosses.csv" --out "$work/g/cubetoss" --tosses all >/dev/null 2>&1
"$polydyn" report "$work/g" -o "$work/full.html" --viewer "$fixtures/fake-viewer.js" 2>/dev/null
replays=$(grep -o '<details class="replay"' "$work/full.html" | wc -l)
if [[ $replays -ne 3 ]]; then echo "FAIL - the fixture report embeds $replays replays, expected 3 (2 runs, 1 cube toss)"; exit 1; fi
echo "ok - the fixture report embeds 3 replays (one of a cube toss) and the viewer bundle once ($(grep -c 'id="pd-viewer-bundle"' "$work/full.html"))"
mkdir "$work/s"
cp "$fixtures/gedanken/sweep.csv" "$work/s/"
"$polydyn" report "$work/s" --no-viewer 2>/dev/null
# the same page without its replay folder (full-replays/)
mkdir "$work/alone"
cp "$work/full.html" "$work/alone/"
node "$src/tests/reports/browser_check.mjs" "$work/full.html" "$work/s/report.html" --missing-replays "$work/alone/full.html"
