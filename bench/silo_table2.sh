#!/usr/bin/env bash
# Daviet 6.4, Table 2: the creeping half-silo (P2-P1d, mu = 0.5, Re = 1, Bi = 0) on 4 uniformly
# refined meshes; for each mesh and method (Cadoux fixed point with the inner solvers pg, apgd,
# spg; ip, the interior point: its split form, then its whole form where that stalls; fp-ip, the
# fixed point with interior-point steps, Table 2's interior-point row with Anderson), the wall
# time to reach a Fischer-Burmeister residual (infinity norm) <= 1e-6, the fixed-point iterations
# and the time per iteration, beside the paper's SPG times (13, 69, 144, 1098 s). Release build.
# Each solve is limited to MAX_SECONDS (default 300): a solver that has not converged by then is
# reported with the residual it reached.
# The residual is the paper's, that of (35): lambda against gamma = R^{+T} B u, the strain rate
# times its point's weight (UNITS=paper, the default). UNITS=run measures it as `granflow run`
# does, against the viscous stress of the strain rate (units of stress), which is stricter on
# these meshes: 1e-6 is then reached on none but the coarsest.
# METHODS (default "pg apgd spg ip fp-ip") chooses the methods, METHODS=ip the interior point
# alone.
# table2_summary.csv (printed too) gives per mesh the best time to the issue's 1e-6 and to
# So-bogus's residual at 1e-6 and 1e-8 (our 1e-3 and 1e-4), and the paper's time over it.
#   bench/silo_table2.sh [BUILD_DIR] [OUT_DIR] [LEVELS] [MAX_SECONDS] [UNITS]
set -euo pipefail
build=${1:-build} out=${2:-results/bench_silo_table2} levels=${3:-4}
export GRANFLOW_REPLAY_MAX_SECONDS=${4:-300}
export GRANFLOW_REPLAY_UNITS=${5:-paper}
# The fixed point's stagnation rule (session 35) is off here, as in the measurements of
# docs/dp.md: a solve goes on to MAX_SECONDS, the best residual it reaches in that time is what
# the table reports. A GRANFLOW_REPLAY_TUNE of the caller that sets either of its tunables
# (fixed_point.stagnation_min_iterations, fixed_point.stagnation_ratio) keeps it on.
tune=${GRANFLOW_REPLAY_TUNE:-}
case "$tune" in
  *fixed_point.stagnation_*) ;;
  *) tune="fixed_point.stagnation_min_iterations=0${tune:+, $tune}" ;;
esac
export GRANFLOW_REPLAY_TUNE=$tune
mkdir -p "$out"
paper=(13 69 144 1098)
echo "[" >"$out/table2.json"
for r in $(seq 0 $((levels - 1))); do
  run="$out/mesh$r"
  # Assemble and dump the cone problem (the run's own solve is capped: the replay measures).
  "$build/apps/granflow" run cases/daviet2016/silo_creeping.prm --quiet --output "$run" \
    --set "Geometry/Global refinements=$r" --set "Solver/Dump cone problem=cone_problem.bin" \
    --set "Solver/Max outer iterations=1" --set "Output/Write vtu=false" >/dev/null 2>&1 || true
  vertices=$(/usr/bin/python3 -c "import json;print(json.load(open('$run/summary.json'))['mesh']['vertices'])")
  # shellcheck disable=SC2086 # METHODS is a list of words
  result=$("$build/bench/replay_cone_problem" "$run/cone_problem.bin" 1e-6 ${METHODS:-pg apgd spg ip fp-ip})
  [ "$r" -gt 0 ] && echo "," >>"$out/table2.json"
  printf '{"mesh": %d, "vertices": %s, "paper_spg_time_s": %s, "solvers": %s}\n' \
    "$r" "$vertices" "${paper[$r]}" "$result" >>"$out/table2.json"
  rm -f "$run/cone_problem.bin"
done
echo "]" >>"$out/table2.json"
# Beside the issue's measure (max_i |FB_i| <= 1e-6), the same times in So-bogus's measure, the
# library of the paper's solvers: max_i |FB_i|^2 (SOCLaw::eval is the squared norm, and its
# infinity norm takes the largest), so its 1e-6 and 1e-8 are our 1e-3 and 1e-4. The paper does
# not state Table 2's tolerance (docs/dp.md, "Table 2's tolerance").
/usr/bin/python3 - "$out/table2.json" "$out/table2_summary.csv" <<'PY'
import csv, json, sys
meshes = json.load(open(sys.argv[1]))
levels = [("1e-06", "FB_inf<=1e-6"), ("0.001", "sobogus<=1e-6 (FB_inf<=1e-3)"),
          ("0.0001", "sobogus<=1e-8 (FB_inf<=1e-4)")]
rows = []
for m in meshes:
    for key, label in levels:
        times = [(s["time_to_residual_s"].get(key), s["method"], s["inner_solver"])
                 for s in m["solvers"] if "time_to_residual_s" in s]
        reached = [t for t in times if t[0] is not None]
        best = min(reached) if reached else None
        rows.append({"mesh": m["mesh"], "vertices": m["vertices"], "residual": label,
                     "paper_spg_time_s": m["paper_spg_time_s"],
                     "best_time_s": "" if best is None else "%.3g" % best[0],
                     "best_method": "" if best is None else (best[1] + " " + best[2]).strip(),
                     "paper_over_best": "" if best is None else
                                        "%.3g" % (m["paper_spg_time_s"] / best[0])})
with open(sys.argv[2], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
print("%4s %8s  %-30s %8s %10s  %-18s %s" % ("mesh", "vertices", "residual", "paper_s",
                                                "best_s", "method", "paper/best"))
for r in rows:
    print("%4s %8s  %-30s %8s %10s  %-18s %s" % (r["mesh"], r["vertices"], r["residual"],
          r["paper_spg_time_s"], r["best_time_s"] or "never", r["best_method"],
          r["paper_over_best"]))
PY
echo "$out/table2.json"
