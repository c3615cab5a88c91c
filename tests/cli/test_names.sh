#!/usr/bin/env bash
# Names as the scene language allows them (any word of valid UTF-8: docs/names-and-files.md) through every file
# that carries them. A scene of bodies with random names — quotes, commas, semicolons, colons, markup, non-ASCII,
# one of 4 000 bytes, and the name that once made `polydyn compare` write a metrics.csv `polydyn report` refused —
# run, compared, swept (under a file name of the same kind), viewed and reported, and cube tosses read from such
# a file name: every command succeeds and the
# project's readers (names_check.mjs: the report generator's and the viewer's) give each name back byte for byte.
# A name that is not UTF-8 is refused as FILE:LINE:COL with exit status 2.
# Usage: test_names.sh POLYDYN SOURCE_DIR [SEED]
set -uo pipefail
PD=$1 src=$2 seed=${3:-$RANDOM}
. "$src/tests/lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "seed $seed"

# the scene: a fixed floor and eight falling cubes; the names are random words of the allowed kind
python3 - "$seed" "$tmp" <<'PY'
import json, random, sys
seed, tmp = int(sys.argv[1]), sys.argv[2]
rng = random.Random(seed)
pieces = ['"', ',', ';', ':', '<', '>', '/', '=', "'", '\\', '&', 'é', '—', '中', '😀', 'a', 'Z', '0', '_', '-']
names = ['<img/src=x/onerror=document.title="PWNED">', 'x' * 2000 + '"é,' * 500]
while len(names) < 8:
    n = ''.join(rng.choice(pieces) for _ in range(rng.randint(1, 24)))
    if n not in names and not n.endswith('\\'):  # a trailing backslash continues the line
        names.append(n)
rng.shuffle(names)
lines = ['tend 0.8', 'sample 50', 'tol 1e-6', 'cube floor grey 20 20 0.2', 'fixed', 'loc 0 0 -0.1']
for i, n in enumerate(names):
    lines += [f'cube {n} red 0.3 0.3 0.3', f'loc {(i % 4) * 1.0 - 1.5} {(i // 4) * 1.0} {0.3 + 0.1 * i}',
              'restitution 0.6']
open(f'{tmp}/scene.scene', 'w', encoding='utf-8').write('\n'.join(lines) + '\n')
json.dump(names, open(f'{tmp}/names.json', 'w', encoding='utf-8'), ensure_ascii=False)
PY
odd="$tmp/a \"scene\", 1;é.scene"  # the scene's path is text in sweep.csv and reference.json too
cp "$tmp/scene.scene" "$odd"

run_pd "$tmp/o" "$tmp/e" run "$tmp/scene.scene" --out "$tmp/run"
check "run succeeds" '[ $rc -eq 0 ]'
run_pd "$tmp/o" "$tmp/e" compare "$tmp/scene.scene" --engines soft --out "$tmp/compare"
check "compare succeeds" '[ $rc -eq 0 ]'
check "compare's table: a dash, never nan, for what does not apply" '! grep -qw nan "$tmp/o" && grep -q "—" "$tmp/o"'
run_pd "$tmp/o" "$tmp/e" report "$tmp/compare" --out "$tmp/compare.html"
check "report reads compare's metrics.csv" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'
run_pd "$tmp/o" "$tmp/e" sweep "$odd" --engines soft --tend 0.05 --out "$tmp/sweep"
check "sweep succeeds" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'
run_pd "$tmp/o" "$tmp/e" report "$tmp/sweep" --out "$tmp/sweep.html"
check "report reads sweep.csv" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'
run_pd "$tmp/o" "$tmp/e" view "$tmp/run" -o "$tmp/view.html"
check "view reads the run (C reader)" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'
check "every name read back by the report's and the viewer's readers" \
  'node "$src/tests/cli/names_check.mjs" "$tmp/names.json" "$tmp/run" "$tmp/compare" "$tmp/sweep" "$odd"'

# cube tosses from a data file at a path of the same kind: the path is text in each record's summary.json
tosses="$tmp/to,ss \"é\" 1;2.csv"
python3 "$src/tests/reports/make_tosses.py" "$tosses" 2 >/dev/null
run_pd "$tmp/o" "$tmp/e" cubetoss --data "$tosses" --engines soft --out "$tmp/toss"
check "cubetoss succeeds" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'
check "the record's summary.json gives the data path back" \
  'python3 -c "import json,sys; s=json.load(open(sys.argv[1], encoding=\"utf-8\")); sys.exit(s[\"engine_settings\"][\"source\"] != sys.argv[2])" "$tmp/toss/runs/1/record/summary.json" "$tosses"'
run_pd "$tmp/o" "$tmp/e" report "$tmp/toss" --out "$tmp/toss.html"
check "report reads per_toss.csv and summary.csv" '[ $rc -eq 0 ] || { cat "$tmp/e"; false; }'

# a name that is not UTF-8: FILE:LINE:COL at its first bad byte, exit 2, nothing written
printf 'cube ok red 1 1 1\ncube ab\xff\xfe red 1 1 1\n' >"$tmp/bad.scene"
run_pd "$tmp/o" "$tmp/e" run "$tmp/bad.scene" --out "$tmp/bad"
check "a name that is not UTF-8 is refused (exit 2)" '[ $rc -eq 2 ] && [ ! -e "$tmp/bad" ]'
check "... at FILE:LINE:COL of its first bad byte" 'grep -q "bad.scene:2:8: the name is not valid UTF-8 (byte 0xFF)" "$tmp/e"'
printf 'cube ok r\xc3\x28d 1 1 1\n' >"$tmp/bad.scene"
run_pd "$tmp/o" "$tmp/e" check "$tmp/bad.scene"
check "a colour that is not UTF-8 is refused at its byte" '[ $rc -eq 2 ] && grep -q "bad.scene:1:10: the colour is not valid UTF-8" "$tmp/e"'

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
