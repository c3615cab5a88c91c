# Shared helpers of the end-to-end test scripts (sourced, not run):
#   check NAME CONDITION...   evaluates the condition (a shell command) and counts the result
#   run_pd OUT ERR ARGS...    runs $PD with stdout/stderr to files; the exit status goes to $rc
#   no_partial DIR            no DIR.partial-* or DIR.old-* left behind
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
