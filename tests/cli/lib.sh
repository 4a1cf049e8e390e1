# Shared by the command-line test scripts: counts checks and compares a command's exit status and
# output with what a user should see.
failures=0 passes=0 skips=0 skipped=""

# A check done by the caller: pass NAME, or fail NAME [WHY].
pass() { echo "ok   $1"; passes=$((passes + 1)); }
fail() { echo "FAIL $1${2:+: $2}"; failures=$((failures + 1)); }
# A check this machine cannot make: skip NAME WHY (counted and named in the summary line).
skip() { echo "skip $1: $2"; skips=$((skips + 1)); skipped="${skipped:+$skipped, }$1"; }

check() { # name, expected status, expected text in stderr/stdout, command...
  local name=$1 status=$2 text=$3
  shift 3
  # Every error message quotes the --set values it was judged with, so an expected text found in
  # the command line itself would match any error: it must name the reason too.
  if [ "$status" -eq 2 ] && [[ " $* " == *"$text"* ]]; then
    fail "$name" "the expected text '$text' is part of the command; it would match any error"
    return
  fi
  "$@" >out.txt 2>err.txt
  local got=$?
  if [ "$got" -ne "$status" ]; then
    fail "$name" "exit $got, expected $status"; cat err.txt; return
  fi
  if ! grep -qF -- "$text" out.txt err.txt; then
    fail "$name" "output lacks '$text'"; cat out.txt err.txt; return
  fi
  if [ "$status" -eq 2 ] && [ "$(wc -l <err.txt)" -ne 1 ]; then
    fail "$name" "expected one error line, got:"; cat err.txt; return
  fi
  pass "$name"
}

summary() {
  echo "$passes passed, $failures failed${skipped:+, $skips skipped ($skipped)}"
  [ "$failures" -eq 0 ]
}
