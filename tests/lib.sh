# Shared helpers of the end-to-end test scripts (sourced, not run):
#   check NAME CONDITION...   evaluates the condition (a shell command) and counts the result
#   run_pd OUT ERR ARGS...    runs $PD with stdout/stderr to files; the exit status goes to $rc
#   no_partial DIR            no DIR.partial-* or DIR.old-* left behind
#   skip_without FILE WHAT    ends the script as skipped (77) when FILE is not there
#   check_interrupted OUT ERR DIR ARGS...
#                             runs $PD ARGS in the background, sends SIGINT after 0.5 s, and checks the
#                             documented answer: exit 130, "interrupted" on stderr, no DIR and no partial one
# The script prints "$passed passed, $failed failed" and exits non-zero when a check failed.
passed=0
failed=0
check() {
  local name=$1
  shift
  if eval "$@"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL: $name  [$*]"
  fi
}
run_pd() {
  local out=$1 err=$2
  shift 2
  "$PD" "$@" >"$out" 2>"$err"
  rc=$?
}
# skip_without FILE WHAT: without the readable FILE, says so (naming WHAT) and ends the script: exit 77 (CTest's
# skip) when every check so far passed, else 1.
skip_without() {
  [ -r "$1" ] && return 0
  echo "SKIP: $2 is not at $1 (not part of the project); $passed checks passed"
  [ $failed -eq 0 ] || exit 1
  exit 77
}
no_partial() { ! compgen -G "$1.partial-*" >/dev/null && ! compgen -G "$1.old-*" >/dev/null; }
check_interrupted() {
  local out=$1 err=$2 dir=$3
  shift 3
  "$PD" "$@" >"$out" 2>"$err" &
  local pid=$!
  sleep 0.5
  kill -INT "$pid"
  wait "$pid"
  rc=$?
  check "SIGINT exits 130" '[ $rc -eq 130 ]'
  check "SIGINT says nothing was written" 'grep -q "interrupted" "$err"'
  check "SIGINT leaves no directory" '[ ! -e "$dir" ] && no_partial "$dir"'
}
