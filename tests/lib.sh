# Shared helpers of the end-to-end test scripts (sourced, not run):
#   check NAME CONDITION...   evaluates the condition (a shell command) and counts the result
#   run_pd OUT ERR ARGS...    runs $PD with stdout/stderr to files; the exit status goes to $rc
#   no_partial DIR            no DIR.partial-* or DIR.old-* left behind
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
