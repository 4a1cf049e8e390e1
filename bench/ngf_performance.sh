#!/usr/bin/env bash
# Henann & Kamrin 2016, issue #3 g: wall time and Newton iterations per increment of the ngf cases
# in a Release build, each run to the paper's end point (wall displacement d for 6.1, 4 degrees
# for 6.2 and 6.3). Targets on a 2-core machine: 6.1 at one parameter set under 2 s, the 60 x 45
# annulus with gravity (6.3) under 60 s, at most 6 Newton iterations per increment on average.
# Writes OUT/ngf_performance.json and prints a table.
#   bench/ngf_performance.sh [BUILD_DIR] [OUT_DIR]
set -uo pipefail
build=${1:-build} out=${2:-results/bench_ngf}
mkdir -p "$out"
cases=(linear_shear_gravity annular_shear annular_shear_gravity annular_shear_gravity_slice)
echo "[" >"$out/ngf_performance.json"
printf '%-24s %10s %11s %14s %10s\n' case time_s increments iter/increment converged
first=1
for c in "${cases[@]}"; do
  run="$out/$c"
  "$build/apps/granflow" run "cases/henann2016/$c.prm" --quiet --output "$run" --set "Output/Write vtu=false" \
    >/dev/null 2>"$run.err"
  status=$?
  line=$(/usr/bin/python3 - "$run/summary.json" "$c" "$status" <<'PY'
import json, sys
path, case, status = sys.argv[1:]
try:
    s = json.load(open(path))
except OSError:
    s = {"newton": {}}
n = s.get("newton", {})
wall = s.get("timings", {}).get("total_s", float("nan"))
print(json.dumps({"case": case, "wall_time_s": wall, "exit_status": int(status),
                  "increments": n.get("increments"), "newton_iterations": n.get("iterations"),
                  "iterations_per_increment": n.get("iterations_per_increment"),
                  "max_iterations": n.get("max_iterations"), "converged": s.get("converged", False),
                  "wall_displacement_over_d": s.get("wall_displacement_over_d")}))
PY
)
  [ $first -eq 0 ] && echo "," >>"$out/ngf_performance.json"
  first=0
  echo "$line" >>"$out/ngf_performance.json"
  /usr/bin/python3 -c "
import json; r = json.loads('''$line''')
print('%-24s %10.2f %11s %14s %10s' % (r['case'], r['wall_time_s'], r['increments'],
      '%.2f' % r['iterations_per_increment'] if r['iterations_per_increment'] else '-', r['converged']))"
done
echo "]" >>"$out/ngf_performance.json"
echo "$out/ngf_performance.json"
