#!/usr/bin/env bash
# Henann & Kamrin 2016, Section 6.1 / Fig. 1 insets: linear shear flow with gravity on the shear
# column (h/d = 1/3, depth 20 d, wall displacement d), FE against the finite-difference solution
# of (90).
#  - rate sweep at P_wall/(phi rho_s G d) = 6.67, v_wall/sqrt(Gd) = 1e-5 ... 1 (insets of Fig. 1b, 1c):
#    DIR/linear_shear_rate.csv, DIR/linear_shear_rate.png (W/d and mu_wall against v_wall, log x);
#  - pressure sweep at v_wall/sqrt(Gd) = 1e-3, P_wall/(phi rho_s G d) = 3.33 ... 100 (inset of Fig. 1d):
#    DIR/linear_shear_pressure.csv, DIR/linear_shear_pressure.png (W/d against phi rho_s G d / P_wall);
#  - steady-state check of the two slowest wall speeds, rerun to a wall displacement of 2 d:
#    DIR/linear_shear_steady_check.csv.
# Columns: *_fd are the FD reference, max_velocity_difference = max |v_FE - v_FD| / v_wall over the
# nodes, mu_wall_drift_last_0p1d = relative change of mu_wall over the last 0.1 d of wall
# displacement (history.csv, final increment excluded since it is shorter than the others),
# finite = false when the run ended with NaN fields, note = solver settings that differ from the case.
# A run that fails or whose mu_wall is NaN is repeated once with 'Solver/Increment growth=1.2' (note column says so).
#   scripts/ngf_linear_shear_sweep.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016}
granflow="$build/apps/granflow"
case_file=cases/henann2016/linear_shear_gravity.prm
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT

# run NAME [--set ...]: one FE run with the FD reference into a temporary directory.
run() {
  local name=$1; shift
  "$granflow" run "$case_file" --quiet --output "$runs/$name" \
    --set "Output/Write vtu=false" --set "Output/Reference=finite difference" "$@" >/dev/null
}

# row RUN_DIR LEADING_VALUE NOTE: the CSV row of one run (prints 'nan' for a NaN mu_wall).
row() {
  /usr/bin/python3 - "$1/summary.json" "$1/history.csv" "$2" "$3" <<'PY'
import csv, json, math, sys
s = json.load(open(sys.argv[1]))
r = s["reference"]
f = lambda x: "nan" if x is None else repr(float(x))
hist = [(float(h["wall_displacement_over_d"]), float(h["mu_wall"])) for h in csv.DictReader(open(sys.argv[2]))]
hist = hist[:-1]  # the final increment is cut short to land on the wall displacement
d_end, mu_end = hist[-1]
mu_before = min(hist, key=lambda p: abs(p[0] - (d_end - 0.1)))[1]
drift = (mu_end - mu_before) / mu_end if math.isfinite(mu_end) and math.isfinite(mu_before) else float("nan")
finite = s["mu_wall"] is not None and math.isfinite(s["mu_wall"])
print(f"{sys.argv[3]},{f(s['shear_band_width_over_d'])},{f(r['shear_band_width_over_d'])},{f(s['mu_wall'])},"
      f"{f(r['mu_wall'])},{f(r['max_velocity_difference_over_v_wall']) if finite else 'nan'},"
      f"{s['newton']['iterations_per_increment']},{s['timings']['total_s']},{drift!r},"
      f"{str(finite).lower()},{sys.argv[4]}")
PY
}

finite() { [ -f "$1/summary.json" ] && /usr/bin/python3 -c "import json,math,sys; m=json.load(open(sys.argv[1]))['mu_wall']; sys.exit(0 if m is not None and math.isfinite(m) else 1)" "$1/summary.json"; }

tail_cols="newton_iterations_per_increment,time_s,mu_wall_drift_last_0p1d,finite,note"
rate_csv="$out/linear_shear_rate.csv"
echo "v_wall_over_sqrt_Gd,W_over_d,W_over_d_fd,mu_wall,mu_wall_fd,max_velocity_difference,$tail_cols" >"$rate_csv"
for v in 1e-5 3e-5 1e-4 3e-4 1e-3 3e-3 1e-2 3e-2 0.1 0.3 1; do
  note=default
  if ! run "rate_v$v" --set "Loading/Wall speed=$v" --set "Loading/Wall pressure=6.67" 2>/dev/null || ! finite "$runs/rate_v$v"; then
    note="default settings failed or diverged to NaN; rerun with Solver/Increment growth=1.2"
    run "rate_v$v" --set "Loading/Wall speed=$v" --set "Loading/Wall pressure=6.67" --set "Solver/Increment growth=1.2"
  fi
  row "$runs/rate_v$v" "$v" "$note" >>"$rate_csv"
done

pressure_csv="$out/linear_shear_pressure.csv"
echo "P_wall_over_phi_rho_s_G_d,phi_rho_s_G_d_over_P_wall,W_over_d,W_over_d_fd,mu_wall,mu_wall_fd,max_velocity_difference,$tail_cols" >"$pressure_csv"
for p in 3.33 6.67 12.5 25 50 100; do
  note=default
  if ! run "pressure_P$p" --set "Loading/Wall speed=1e-3" --set "Loading/Wall pressure=$p" 2>/dev/null || ! finite "$runs/pressure_P$p"; then
    note="default settings failed or diverged to NaN; rerun with Solver/Increment growth=1.2"
    run "pressure_P$p" --set "Loading/Wall speed=1e-3" --set "Loading/Wall pressure=$p" --set "Solver/Increment growth=1.2"
  fi
  inv=$(/usr/bin/python3 -c "print(repr(1 / $p))")
  echo "$p,$(row "$runs/pressure_P$p" "$inv" "$note")" >>"$pressure_csv"
done

# Steady state at the slowest speeds: the same runs to a wall displacement of 2 d.
steady_csv="$out/linear_shear_steady_check.csv"
echo "v_wall_over_sqrt_Gd,wall_displacement_over_d,W_over_d,W_over_d_fd,mu_wall,mu_wall_fd,max_velocity_difference,$tail_cols" >"$steady_csv"
for v in 1e-5 3e-5; do
  for D in 1 2; do
    extra=()
    if grep -q "^$v,.*Increment growth=1.2" "$rate_csv"; then extra=(--set "Solver/Increment growth=1.2"); fi
    run "steady_v${v}_D$D" --set "Loading/Wall speed=$v" --set "Loading/Wall pressure=6.67" \
      --set "Loading/Wall displacement=$D" "${extra[@]}"
    echo "$v,$D,$(row "$runs/steady_v${v}_D$D" "" "${extra[*]:-default}" | cut -d, -f2-)" >>"$steady_csv"
  done
done

/usr/bin/python3 - "$rate_csv" "$pressure_csv" "$out" <<'PY'
import csv, math, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
col = lambda rows, k: [float(r[k]) for r in rows]
rate = [r for r in csv.DictReader(open(sys.argv[1]))]
pres = [r for r in csv.DictReader(open(sys.argv[2]))]
def insets(rows, x_key, x_label, title, name, mu_s_line):
    """W/d and mu_wall against x, FE markers over the FD line."""
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.2))
    x = col(rows, x_key)
    for ax, fe, fd, label in ((axs[0], "W_over_d", "W_over_d_fd", "W/d"), (axs[1], "mu_wall", "mu_wall_fd", "mu_wall")):
        ax.semilogx(x, col(rows, fd), "k-", label="FD (90)")
        ax.semilogx(x, col(rows, fe), "o", mfc="none", label="FE, h/d = 1/3")
        ax.set_xlabel(x_label); ax.set_ylabel(label); ax.grid(alpha=0.3, which="both"); ax.legend()
    if mu_s_line:
        axs[1].axhline(0.3819, color="gray", ls=":", lw=1)
    fig.suptitle(title)
    fig.tight_layout(); fig.savefig(f"{sys.argv[3]}/{name}.png", dpi=130)
insets(rate, "v_wall_over_sqrt_Gd", "v_wall / sqrt(G d)",
       "Henann & Kamrin 2016 Fig. 1b, 1c insets: P_wall / phi rho_s G d = 6.67", "linear_shear_rate", True)
insets(pres, "phi_rho_s_G_d_over_P_wall", "phi rho_s G d / P_wall",
       "Henann & Kamrin 2016 Fig. 1d inset: v_wall / sqrt(G d) = 1e-3", "linear_shear_pressure", False)
PY
echo "$rate_csv"
echo "$pressure_csv"
echo "$steady_csv"
