#!/usr/bin/env bash
# Browser smoke test: the fixture report (with a stand-in viewer bundle for the replay hook) and a
# sweep-only report load in headless Debian Chromium with no console error and no network request,
# every chart draws, and both embedded replays mount.
# usage: test_report_browser.sh POLYDYN SOURCE_DIR
set -euo pipefail
polydyn=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PD_REPORT_GENERATOR=$src/reports/generator/report.mjs
fixtures=$src/tests/reports/fixtures
"$polydyn" report "$fixtures/gedanken" -o "$work/full.html" --viewer "$fixtures/fake-viewer.js" 2>/dev/null
replays=$(grep -o '<details class="replay"' "$work/full.html" | wc -l)
if [[ $replays -ne 2 ]]; then echo "FAIL - the fixture report embeds $replays replays, expected 2"; exit 1; fi
echo "ok - the fixture report embeds 2 replays and the viewer bundle once ($(grep -c 'id="pd-viewer-bundle"' "$work/full.html"))"
mkdir "$work/s"
cp "$fixtures/gedanken/sweep.csv" "$work/s/"
"$polydyn" report "$work/s" --no-viewer 2>/dev/null
node "$src/tests/reports/browser_check.mjs" "$work/full.html" "$work/s/report.html"
