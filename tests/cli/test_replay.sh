#!/usr/bin/env bash
# bench/replay_cone_problem as a user runs it on a dumped problem: one clear error and exit 2 for a
# bad command line before any work, an "error" entry (exit 3) for a method the problem does not
# suit while the others still run, and the measurements so far on Ctrl-C (exit 130).
set -u
: "${GRANFLOW:?path of the granflow binary}" "${REPLAY:?path of replay_cone_problem}" \
  "${SOURCE_DIR:?source directory}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
. "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

# Two small problems: the Bagnold layer (mu = 0.5, Bi = 0) and the Bingham channel (mu = 0, Bi > 0).
check dump-bagnold 0 "Results in" "$GRANFLOW" run "$SOURCE_DIR/cases/daviet2016/bagnold.prm" \
  --quiet --output bagnold --set "Solver/Dump cone problem=$work/bagnold.bin"
check dump-bingham 0 "Results in" "$GRANFLOW" run "$SOURCE_DIR/cases/daviet2016/bingham_poiseuille.prm" \
  --quiet --output bingham --set "Solver/Dump cone problem=$work/bingham.bin"
# and a Newtonian channel (mu = Bi = 0), which only the fixed point solves
check dump-newtonian 0 "Results in" "$GRANFLOW" run "$SOURCE_DIR/cases/daviet2016/bingham_poiseuille.prm" \
  --quiet --output newtonian --set "Rheology/Bi=0" --set "Geometry/Mesh size=0.2" \
  --set "Solver/Dump cone problem=$work/newtonian.bin"

check no-arguments 2 "no problem file (usage: replay_cone_problem PROBLEM.bin" "$REPLAY"
check help 0 "GRANFLOW_REPLAY_MAX_SECONDS limits each solve" "$REPLAY" --help
check bad-tolerance 2 "tolerance '1e-6x' is not a positive number" "$REPLAY" bagnold.bin 1e-6x
check negative-tolerance 2 "tolerance '-1' is not a positive number" "$REPLAY" bagnold.bin -1
check bad-method 2 "unknown method 'sgp': expected pg, apgd, spg, ip or fp-ip" "$REPLAY" bagnold.bin 1e-6 spg sgp
check missing-file 2 "cannot read cone problem 'nope.bin'" "$REPLAY" nope.bin
echo "not a dump" >junk.bin
check not-a-dump 2 "is not a granflow cone problem dump" "$REPLAY" junk.bin
# The residual scales, one per point, close a dump: a count that does not match is refused.
/usr/bin/python3 - bagnold.bin scales.bin <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
# The last vector is the scales: its length n (uint64) stands before its n doubles.
n = next(n for n in range(1, len(data) // 8) if struct.unpack('<Q', data[-8 * (n + 1):-8 * n])[0] == n)
open(sys.argv[2], 'wb').write(data[:-8 * (n + 1)] + struct.pack('<Qd', 1, 1.0))
PY
check scales-do-not-match 2 "has 1 residual scales for" "$REPLAY" scales.bin
check bad-max-seconds 2 "GRANFLOW_REPLAY_MAX_SECONDS='soon' is not a number of seconds" \
  env GRANFLOW_REPLAY_MAX_SECONDS=soon "$REPLAY" bagnold.bin

check bad-units 2 "GRANFLOW_REPLAY_UNITS='stress': expected paper or run" \
  env GRANFLOW_REPLAY_UNITS=stress "$REPLAY" bagnold.bin
# The paper's residual (Daviet (35): gamma with its point's weight), as Table 2 measures it.
check replay-paper-units 0 '"residual_units": "paper"' env GRANFLOW_REPLAY_UNITS=paper "$REPLAY" \
  bagnold.bin 1e-6 ip
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
assert r[0]["converged"] and r[0]["residual"] <= 1e-6, r' out.txt; then
  pass "replay in the paper's units converges"
else fail "replay in the paper's units converges"; cat out.txt; fi

check replay 0 '"converged": true' "$REPLAY" bagnold.bin 1e-6 spg ip
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
assert [e["method"] for e in r] == ["fixed point", "interior point"], r
assert all(e["converged"] and e["residual"] <= 1e-6 for e in r), r' out.txt; then
  pass "replay measures both methods"
else fail "replay measures both methods"; cat out.txt; fi

# The interior point solves the Bingham channel (mu = 0, Bi > 0: its split form alone)...
check replay-bingham-interior-point 0 '"converged": true' "$REPLAY" bingham.bin 1e-5 ip
# ... and refuses mu = Bi = 0; the fixed point after it still runs, and both are printed.
check unsuited-method 3 "ip: the interior-point method needs mu > 0 or Bi > 0" \
  "$REPLAY" newtonian.bin 1e-6 ip spg
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
assert "error" in r[0] and r[1]["converged"], r' out.txt; then
  pass "unsuited method leaves the others' results"
else fail "unsuited method leaves the others' results"; cat out.txt; fi

# The fixed point with interior-point steps (Table 2's interior-point row): it converges on the
# Bagnold layer (18 steps, about 7 s), and refuses mu = Bi = 0 as the interior point does.
check replay-fixed-point-ip-steps 0 '"inner_solver": "ip"' "$REPLAY" bagnold.bin 1e-5 fp-ip
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))[0]
assert r["method"] == "fixed point" and r["converged"] and r["residual"] <= 1e-5, r
assert r["inner_iterations"] > r["fixed_point_iterations"] > 1, r' out.txt; then
  pass "fixed point with interior-point steps converges"
else fail "fixed point with interior-point steps converges"; cat out.txt; fi
check fixed-point-ip-steps-unsuited 3 "fp-ip: the fixed point's interior-point steps need mu > 0 and Bi = 0" \
  "$REPLAY" newtonian.bin 1e-6 fp-ip

# Ctrl-C during a solve that cannot finish soon: the solve ends at its next iteration, the methods
# after it are skipped, and what was measured is printed.
# (The time limit is a backstop: a SIGINT that came before the handler was installed would be
# ignored, as background jobs of a script start with SIGINT ignored.)
GRANFLOW_REPLAY_MAX_SECONDS=60 "$REPLAY" bagnold.bin 1e-15 pg spg >int.json 2>int.err &
pid=$!
sleep 2
kill -INT $pid
wait $pid
got=$?
if [ "$got" -eq 130 ] && /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
assert len(r) == 1 and r[0]["interrupted"] and not r[0]["converged"], r' int.json; then
  pass "ctrl-c prints the measurements so far"
else fail "ctrl-c prints the measurements so far" "exit $got"; cat int.json int.err; fi

# The solvers' tunables, set without recompiling: each interior-point step counted short, the
# split form stalls after one, then the whole form after one, each says why, and the JSON records
# the setting (the fixed point that would follow turned off).
check tune 0 '"interior_point.short_steps": 1.0' env \
  GRANFLOW_REPLAY_TUNE="interior_point.short_step=2, interior_point.short_steps=1, interior_point.fixed_point_after_stall=0" \
  "$REPLAY" bagnold.bin 1e-6 ip
if grep -q '"stall_reason": "split form: 1 successive steps were shorter than 2 .*; then whole form: 1 successive steps were shorter than 2 [^;]*",' out.txt &&
  grep -q '"fixed_point_iterations": 2,' out.txt && grep -q '"stalled": true,' out.txt &&
  grep -q '"timed_out": false,' out.txt && grep -q '"time_per_fixed_point_step_s": null' out.txt &&
  grep -q '"interior_point_iterations": 2,' out.txt; then pass "tunables reach the solver"
else fail "tunables reach the solver"; cat out.txt; fi
# By default Cadoux's fixed point with interior-point steps follows the two stalled forms, its
# steps counted as iterations after theirs.
check tune-chain 0 '"interior_point.short_steps": 1.0' env \
  GRANFLOW_REPLAY_TUNE="interior_point.short_step=2, interior_point.short_steps=1" \
  "$REPLAY" bagnold.bin 1e-6 ip
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))[0]
assert r["stall_reason"].startswith("split form: 1 successive") and "; then whole form: 1 successive" in r["stall_reason"] and "; then fixed point: " in r["stall_reason"], r
assert r["fixed_point_iterations"] > 2 and r["fixed_point_steps"] == r["fixed_point_iterations"] - 2 and r["stalled"], r
# each kind of iteration its own time per iteration
assert r["interior_point_iterations"] == 2 and "time_per_fixed_point_iteration_s" not in r, r
assert r["time_per_interior_point_iteration_s"] > 0 and r["time_per_fixed_point_step_s"] > 0, r' out.txt; then pass "the fixed point follows the stalled forms"
else fail "the fixed point follows the stalled forms"; cat out.txt; fi
# Plain Algorithm 1 (no Anderson extrapolation; an options-level tunable) and the outer
# iterations after which each residual decade was first reached. With Anderson (the default) the
# fixed point reaches 1e-4 here (14 iterations, 1.5 s), its last iteration the one that reached
# the decade; plain, it stalls near 1e-3, so in 20 iterations it does not. (An iteration limit,
# not a time limit, so that how far it gets does not depend on the machine's speed.)
check replay-iterations-to-residual 0 '"converged": true' "$REPLAY" bagnold.bin 1e-4 spg
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))[0]
n = r["iterations_to_residual"]
assert n["0.0001"] == r["fixed_point_iterations"] and 0 < n["0.01"] <= n["0.001"] <= n["0.0001"], r
assert n["1e-05"] is None, r' out.txt; then
  pass "iterations to each residual decade"
else fail "iterations to each residual decade"; cat out.txt; fi
check tune-plain-fixed-point 0 '"fixed_point.anderson_depth": 0.0' \
  env GRANFLOW_REPLAY_TUNE="fixed_point.anderson_depth=0, fixed_point.max_outer_iterations=20" \
  "$REPLAY" bagnold.bin 1e-4 spg
if /usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))[0]
n = r["iterations_to_residual"]
assert not r["converged"] and 1e-4 < r["residual"] < 1e-2 and n["0.0001"] is None, r
assert r["fixed_point_iterations"] == 20 and not r["timed_out"] and not r["stalled"], r
assert r["tunables"]["fixed_point.max_outer_iterations"] == 20, r' out.txt; then
  pass "the plain fixed point stalls where Anderson's converges"
else fail "the plain fixed point stalls where Anderson's converges"; cat out.txt; fi
check tune-no-inner-iterations 2 "GRANFLOW_REPLAY_TUNE: fixed_point.max_inner_iterations='0': expected a whole number >= 1" \
  env GRANFLOW_REPLAY_TUNE="fixed_point.max_inner_iterations=0" "$REPLAY" bagnold.bin
check tune-unknown 2 "GRANFLOW_REPLAY_TUNE: 'interior_point.short_stepz=2' is not name=value with a known name" \
  env GRANFLOW_REPLAY_TUNE="interior_point.short_stepz=2" "$REPLAY" bagnold.bin
check tune-not-whole 2 "GRANFLOW_REPLAY_TUNE: fixed_point.spg_memory='2.5': expected a whole number" \
  env GRANFLOW_REPLAY_TUNE="fixed_point.spg_memory=2.5" "$REPLAY" bagnold.bin

summary
