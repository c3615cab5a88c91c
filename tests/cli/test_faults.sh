#!/usr/bin/env bash
# Faults: every command that writes an output directory — run, compare, sweep, gedanken,
# cubetoss, soak, report — against an interrupt at random moments (SIGINT and SIGTERM), a full disk (a file-size
# limit: `ulimit -f`, which a polydyn process turns into failed writes, not SIGXFSZ) and an output directory that
# cannot be created. Whatever happens: never a half-written result that looks complete (a directory at the
# output's name is always a complete one), never a lost earlier result (it stays byte for byte, unless the
# command completed and replaced it with a complete one), never a temporary directory left behind, and an exit
# status that says what happened (0 done, 1 could not write, 2 bad input, 130 interrupted).
#
# usage: test_faults.sh POLYDYN_BINARY SOURCE_DIR [SEED [MOMENTS]]   (MOMENTS per signal, default 3)
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 POLYDYN_BINARY SOURCE_DIR [SEED [MOMENTS]]" >&2
  exit 2
fi
PD=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SRC=$(cd "$2" && pwd)
SEED=${3:-1}
MOMENTS=${4:-3}
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/pd_test_faults.XXXXXX") || exit 1
trap 'rm -rf "$SCRATCH"' EXIT
. "$SRC/tests/lib.sh"  # check, no_partial

python3 "$SRC/tests/reports/make_tosses.py" "$SCRATCH/tosses.csv" 4 || exit 1
"$PD" gedanken --only c2_momentum --engines soft --out "$SCRATCH/for-report" >/dev/null 2>&1 || exit 1

# Each command as NAME|ARGS (OUT is replaced by the output directory); long enough (0.3-3 s in the dev build)
# for an interrupt to land in the middle of the work as well as before and after it.
COMMANDS=(
  "run|run $SRC/cases/sweep/pile_10.scene --tend 0.4 --out OUT"
  "compare|compare $SRC/cases/sweep/bounce.scene --out OUT"
  "sweep|sweep $SRC/cases/sweep/bounce.scene --engines soft --repeats 1 --out OUT"
  "gedanken|gedanken --only g1_stack_drift,c2_momentum --engines soft --out OUT"
  "cubetoss|cubetoss --data $SCRATCH/tosses.csv --engines soft --out OUT"
  "soak|soak --seed 1 --scenes 12 --engines soft --jobs 1 --out OUT"
  "report|report $SCRATCH/for-report -o OUT/report.html --no-viewer"
)

# sha256 of every file under DIR (relative names), wall times and other measured times removed from nothing:
# the earlier result must stay byte for byte, so the listing is compared whole.
listing() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha256sum); }
names() { (cd "$1" && find . -type f | sort); }

# Delays of the interrupts, s: from the seed, spread over [0.1, 1.5) so that some land early, some mid-run,
# some after the end (not before 0.1 s: a process still loading its libraries has not caught signals yet, and
# one killed by SIGINT then exits 130 without a word).
delays() {
  python3 -c 'import random, sys
r = random.Random(int(sys.argv[1]) * 1000 + int(sys.argv[2]))
print(" ".join("%.3f" % (0.1 + 1.4 * r.random() ** 2) for _ in range(int(sys.argv[3]))))' "$SEED" "$1" "$MOMENTS"
}

index=0
for entry in "${COMMANDS[@]}"; do
  cmd=${entry%%|*}
  args=${entry#*|}
  index=$((index + 1))
  out=$SCRATCH/$cmd/out
  mkdir -p "$SCRATCH/$cmd"
  # the report writes a page, not a directory: its "earlier result" is the page's folder
  if [ "$cmd" = report ]; then mkdir -p "$out"; fi
  # shellcheck disable=SC2086  # the arguments are words by design
  "$PD" ${args//OUT/$out} >/dev/null 2>"$SCRATCH/$cmd/err"
  rc=$?
  check "$cmd: the earlier result is written (exit 0)" '[ $rc -eq 0 ]'
  earlier=$(listing "$out")
  files=$(names "$out")

  # --- interrupts at random moments
  for sig in INT TERM; do
    for delay in $(delays "$index"); do
      # shellcheck disable=SC2086
      "$PD" ${args//OUT/$out} >/dev/null 2>"$SCRATCH/$cmd/err" &
      pid=$!
      sleep "$delay"
      kill -"$sig" "$pid" 2>/dev/null
      wait "$pid"
      rc=$?
      what="$cmd: SIG$sig after $delay s (exit $rc)"
      # 143: a SIGTERM that came before the command caught it (while it read its arguments): nothing started
      check "$what: exit 0 (done before the signal), 130 (interrupted) or 143 (SIGTERM before it started)" \
        '[ $rc -eq 0 ] || [ $rc -eq 130 ] || { [ $rc -eq 143 ] && [ $sig = TERM ]; }'
      if [ $rc -eq 130 ] || [ $rc -eq 143 ]; then
        check "$what: the earlier result is intact" '[ "$(listing "$out")" = "$earlier" ]'
        [ $rc -eq 143 ] || check "$what: says it was interrupted" 'grep -q "interrupted" "$SCRATCH/$cmd/err"'
      else
        check "$what: a complete result in place (the same files)" '[ "$(names "$out")" = "$files" ]'
        earlier=$(listing "$out")
      fi
      check "$what: no temporary directory left" 'no_partial "$out" && ! compgen -G "$out/*.tmp-*" >/dev/null'
    done
  done

  # --- a full disk: a file-size limit of 0 (every write fails; directories can still be made)
  # (stderr goes through a pipe: the limit would stop its writes to a file too)
  (
    ulimit -f 0
    # shellcheck disable=SC2086
    exec "$PD" ${args//OUT/$out} 2>&1 >/dev/null
  ) | cat >"$SCRATCH/$cmd/err"
  rc=${PIPESTATUS[0]}
  check "$cmd: disk full: exit 1 (not a signal)" '[ $rc -eq 1 ]'
  check "$cmd: disk full: says what it could not write" '[ -s "$SCRATCH/$cmd/err" ]'
  check "$cmd: disk full: the earlier result is intact" '[ "$(listing "$out")" = "$earlier" ]'
  check "$cmd: disk full: no temporary directory left" 'no_partial "$out" && ! compgen -G "$out/*.tmp-*" >/dev/null'

  # --- an output directory that cannot be made (under /proc, whoever runs the test)
  bad=/proc/polydyn-test-$$/out
  # shellcheck disable=SC2086
  "$PD" ${args//OUT/$bad} >/dev/null 2>"$SCRATCH/$cmd/err"
  rc=$?
  check "$cmd: unwritable output: exit 1 or 2 with a message" '{ [ $rc -eq 1 ] || [ $rc -eq 2 ]; } && [ -s "$SCRATCH/$cmd/err" ]'
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
