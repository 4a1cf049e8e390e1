# Shared by the command-line test scripts: counts checks and compares a command's exit status and
# output with what a user should see.
failures=0 passes=0

# A check done by the caller: pass NAME, or fail NAME [WHY].
pass() { echo "ok   $1"; passes=$((passes + 1)); }
fail() { echo "FAIL $1${2:+: $2}"; failures=$((failures + 1)); }

check() { # name, expected status, expected text in stderr/stdout, command...
  local name=$1 status=$2 text=$3
  shift 3
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

summary() { echo "$passes passed, $failures failed"; [ "$failures" -eq 0 ]; }
