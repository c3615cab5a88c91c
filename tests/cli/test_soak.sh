#!/usr/bin/env bash
# The random-scene soak (docs/reliability.md; cli/cmd_soak.c, validation/soak.c).
# - CI's campaign: the latest generator (plates too), seed 1, scenes 0..SCENES-1 (40; 12 in the ASan + UBSan
#   build, 10-40 times slower, whose runs get a budget of 300 s instead of 20), in the soft engine (checked at
#   every accepted step), ODE and Bullet: every run ok, or refused where it must be (the overlap scenes), no
#   failure, no run over its budget; summary.csv has a row per scene and engine; the same command again gives
#   the same rows but the measured times (scene i of campaign S is a function of the generator, S and i alone,
#   and the runs are deterministic); the larger campaigns are committed (reports/reliability/README.md);
# - regressions the soak found and that are fixed (docs/reliability.md), scenes of the first generator (the one
#   that found them, --generator 1): seed 2 scene 2945 (a stack of eight
#   flush boxes sank 29 delta_max), seed 1 scene 147 with --onsets pair (seven flush boxes fell apart), seed 1 scenes 4, 7, 19 (inside the campaign: a sliver's sharp rim pressed
#   into a box found no edge-edge contact), seed 3 scene 1779 (such a sharp edge's pair was pruned before the
#   contact search looked at it: two bodies sank 15 delta_max with no contact), seed 3 scenes 1931, 2429, 2707,
#   8264 and seed 4 scene 325 (plates 0.4-0.9 delta_max thick, whose springs let vertices through them);
# - a run stopped at its budget writes its scene under over-budget/, and that file replays with polydyn run;
# - bad arguments: exit 2 with a message, nothing written.
#
# usage: test_soak.sh POLYDYN_BINARY [SCENES [BUDGET]]   (BUDGET: seconds per run, polydyn soak --budget)
set -u
PD=$1
SCENES=${2:-40}
BUDGET=${3:-20}
HERE=$(dirname "${BASH_SOURCE[0]}")
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_soak.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$HERE/../lib.sh"

run_pd "$SCRATCH/ci.out" "$SCRATCH/ci.err" soak --seed 1 --scenes "$SCENES" --engines soft,ode,bullet --jobs 2 --budget "$BUDGET" --out "$SCRATCH/ci"
check "generator 2, seed 1, scenes 0..$((SCENES - 1)): exit 0" '[ $rc -eq 0 ]' || cat "$SCRATCH/ci.out" "$SCRATCH/ci.err"
check "a row per scene and engine" '[ "$(tail -n +2 "$SCRATCH/ci/summary.csv" | wc -l)" -eq $((3 * SCENES)) ]'
check "no failure" '! grep -q ",failed," "$SCRATCH/ci/summary.csv" && [ ! -e "$SCRATCH/ci/failures" ]'
check "no run over its budget" '! grep -q ",over-budget," "$SCRATCH/ci/summary.csv"'
check "only overlap scenes refused" '! grep ",refused," "$SCRATCH/ci/summary.csv" | grep -vq ",overlap,"'
check "every overlap scene refused" '! grep ",overlap," "$SCRATCH/ci/summary.csv" | grep -vq ",refused,"'
check "the counts are printed" 'grep -q "^soft  *[0-9]" "$SCRATCH/ci.out"'
check "generator 2, checked at every step" 'grep -q "generator 2, seed 1, .* checked at every step" "$SCRATCH/ci.out"'
# the same scenes again (a slice, serially): the same rows but wall_seconds (column 8)
LAST=$((SCENES - 1))
SLICE=$((SCENES / 2))
run_pd "$SCRATCH/again.out" "$SCRATCH/again.err" soak --seed 1 --first "$SLICE" --scenes $((SCENES - SLICE)) --budget "$BUDGET" --out "$SCRATCH/again"
check "a slice again: exit 0" '[ $rc -eq 0 ]'
check "the same rows but the measured times" \
  'diff <(awk -F, -v lo="$SLICE" -v hi="$LAST" "NR > 1 && \$2 >= lo && \$2 <= hi && \$6 == \"soft\"" "$SCRATCH/ci/summary.csv" | cut -d, -f1-7,9-) \
        <(tail -n +2 "$SCRATCH/again/summary.csv" | cut -d, -f1-7,9-)'

run_pd "$SCRATCH/stack.out" "$SCRATCH/stack.err" soak --generator 1 --seed 2 --first 2945 --scenes 1 --budget "$BUDGET" --out "$SCRATCH/stack"
check "regression: seed 2 scene 2945 (flush stack) passes" '[ $rc -eq 0 ] && grep -q "^2,2945,stack,.*,soft,ok," "$SCRATCH/stack/summary.csv"'

# seven flush boxes at rest, which pair onsets toppled by friction along a slip of rounding (contact_set.c)
run_pd "$SCRATCH/flush.out" "$SCRATCH/flush.err" soak --generator 1 --seed 1 --first 147 --scenes 1 --onsets pair --budget "$BUDGET" --out "$SCRATCH/flush"
check "regression: seed 1 scene 147 (flush stack) passes with pair onsets" '[ $rc -eq 0 ] && grep -q "^1,147,stack,.*,soft,ok," "$SCRATCH/flush/summary.csv"'

run_pd "$SCRATCH/edge.out" "$SCRATCH/edge.err" soak --generator 1 --seed 3 --first 1779 --scenes 1 --budget "$BUDGET" --out "$SCRATCH/edge"
check "regression: seed 3 scene 1779 (a sharp edge's pair pruned unseen) passes" '[ $rc -eq 0 ] && grep -q "^3,1779,free,.*,soft,ok," "$SCRATCH/edge/summary.csv"'

# plates thinner than the deflection their springs were sized for, crossed by 5.8-18 delta_max at the samples
# (campaigns 3, 4); checked at every step (3/1931's 100:1 blade, spun to 800 rad/s, crossed an edge by 3.4 delta_max
# between samples until edge contacts kept their history through hand-overs)
for sc in 3:1931:free:steps 3:2429:free:steps 3:2707:free:steps 3:8264:free:steps 4:325:free:steps; do
  IFS=: read -r seed scene kind when <<<"$sc"
  run_pd "$SCRATCH/thin.out" "$SCRATCH/thin.err" soak --generator 1 --seed "$seed" --first "$scene" --scenes 1 --check "$when" --budget "$BUDGET" --out "$SCRATCH/thin-$seed-$scene"
  check "regression: seed $seed scene $scene (a plate thinner than delta_max) passes" \
    '[ $rc -eq 0 ] && grep -q "^$seed,$scene,$kind,.*,soft,ok," "$SCRATCH/thin-$seed-$scene/summary.csv"'
done

# an edge lying along a plate's rim face, held at one end at a time (campaign 49, checked at every step:
# cases/hard/cube_edge_along_plate_rim.scene is this scene reduced)
run_pd "$SCRATCH/rim.out" "$SCRATCH/rim.err" soak --seed 49 --first 439 --scenes 1 --budget "$BUDGET" --out "$SCRATCH/rim"
check "regression: seed 49 scene 439 (an edge along a plate's rim face) passes" \
  '[ $rc -eq 0 ] && grep -q "^49,439,free,.*,soft,ok," "$SCRATCH/rim/summary.csv"'

run_pd "$SCRATCH/budget.out" "$SCRATCH/budget.err" soak --generator 1 --seed 1 --first 13 --scenes 1 --budget 0.001 --out "$SCRATCH/budget"
check "over budget: exit 0 (a cost finding, not a failure)" '[ $rc -eq 0 ]'
check "over budget: counted" 'grep -q ",over-budget," "$SCRATCH/budget/summary.csv"'
check "over budget: the scene is written" '[ -f "$SCRATCH/budget/over-budget/000013-soft.scene" ]'
check "over budget: it says why" 'head -1 "$SCRATCH/budget/over-budget/000013-soft.scene" | grep -q "^# over-budget: stopped at t = "'
run_pd "$SCRATCH/replay.out" "$SCRATCH/replay.err" run "$SCRATCH/budget/over-budget/000013-soft.scene" --out "$SCRATCH/replay"
check "over budget: the scene replays with polydyn run" '[ $rc -eq 0 ] && [ -f "$SCRATCH/replay/trajectory.csv" ]'

# a penetration limit below any loaded contact's depth fails a scene whose bodies collide; the default passes it
run_pd "$SCRATCH/limit.out" "$SCRATCH/limit.err" soak --seed 49 --first 439 --scenes 1 --budget "$BUDGET" \
  --penetration-limit 1e-6 --out "$SCRATCH/limit"
check "--penetration-limit 1e-6: seed 49 scene 439 fails (exit 1), judged against that limit" \
  '[ $rc -eq 1 ] && grep -q "^49,439,free,.*,soft,failed," "$SCRATCH/limit/summary.csv" && head -1 "$SCRATCH/limit/failures/000439-soft.scene" | grep -q "(limit 1e-06)"'
check "--penetration-limit: the campaign's header names it" 'grep -q "penetration limit 1e-06 delta_max" "$SCRATCH/limit.out"'

for bad in "--scenes 0" "--scenes x" "--seed -1" "--generator 0" "--generator 3" "--check often" "--engines soft,box" "--engines soft,soft" "--budget 0" "--jobs 0" "--onsets late" "--penetration-limit 0" "--penetration-limit 1001" "--penetration-limit x" "--frobnicate 1"; do
  # shellcheck disable=SC2086
  run_pd "$SCRATCH/bad.out" "$SCRATCH/bad.err" soak $bad --out "$SCRATCH/bad"
  check "bad argument '$bad': exit 2 with a message, nothing written" \
    '[ $rc -eq 2 ] && grep -q "polydyn soak: " "$SCRATCH/bad.err" && [ ! -e "$SCRATCH/bad" ] && no_partial "$SCRATCH/bad"'
done
run_pd "$SCRATCH/bad.out" "$SCRATCH/bad.err" soak --scenes 3
check "no --out: exit 2" '[ $rc -eq 2 ] && grep -q "\-\-out DIR is required" "$SCRATCH/bad.err"'
check_interrupted "$SCRATCH/int.out" "$SCRATCH/int.err" "$SCRATCH/int" soak --seed 1 --scenes 100000 --out "$SCRATCH/int"

echo "test_soak: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
