#!/usr/bin/env bash
# Henann & Kamrin 2016, 6.3: the annulus with gravity (quad section, the case file's 60 x 45 mesh,
# R_i Omega / sqrt(G d) = RATE, default 1e-3) at depths below its free surface, against the
# finite-difference solution of the annular shear reduction (92) at each depth's hydrostatic
# pressure phi rho_s G depth and the same wall speed (exact Couette kinematics, 0.01 d grid; the
# reference the annulus row case computes with Output/Reference = finite difference). In the
# rate-independent limit every depth carries that profile; docs/ngf.md ("The annulus with gravity
# at depth") explains why the check is asymptotic and not depth-resolved.
# Writes OUT/annulus_depth_check.csv (depth / d, P [Pa], the rate R_i Omega sqrt(rho_s / P), the
# largest |v - v_FD| / v_wall, W / d of the FE and of the FD) and prints it, with the summary's
# wall_pressure_over_hydrostatic. About a minute.
#   scripts/ngf_annulus_depth_check.sh [BUILD_DIR] [OUT_DIR] [RATE] [DEPTHS]
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016} rate=${3:-1e-3}
depths=${4:-"0.333333333333, 1, 3, 5, 7.5, 10, 15"}
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
"$build/apps/granflow" run cases/henann2016/annular_shear_gravity.prm --quiet --output "$runs/gravity" \
  --set "Loading/Wall speed=$rate" --set "Output/Profile depths=$depths" --set "Output/Write vtu=false" >/dev/null
/usr/bin/python3 - "$build" "$runs" "$out" "$rate" <<'PY'
import csv, json, math, subprocess, sys
build, runs, out, rate = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
summary = json.load(open(f"{runs}/gravity/summary.json"))
# The material of both case files (the paper's, Section 6): phi, rho_s, G [m/s^2], d [m].
phi, rho_s, G, d = 0.62, 2450.0, 9.81, 1e-3
v_wall = rate * math.sqrt(G * d)
rows = []
for entry in summary["profiles_at_depth"]:
    depth = entry["depth_over_d"]
    if depth <= 0:
        continue  # no pressure at the surface: (92) has no solution there
    P = phi * rho_s * G * depth * d
    row_rate = v_wall / math.sqrt(P / rho_s)  # the annulus row's R_i Omega sqrt(rho_s / P_wall)
    run = f"{runs}/row_{depth}"
    subprocess.run([f"{build}/apps/granflow", "run", "cases/henann2016/annular_shear.prm", "--quiet",
                    "--output", run, "--set", f"Loading/Confining pressure={P!r}",
                    "--set", f"Loading/Wall speed={row_rate!r}", "--set", "Loading/Wall rotation=0.1",
                    "--set", "Output/Write vtu=false"], check=True, capture_output=True)
    ref = list(csv.DictReader(open(f"{run}/profiles/velocity.csv")))
    fe = list(csv.DictReader(open(f"{runs}/gravity/{entry['file']}")))
    assert [r["r_minus_R_i_over_d"] for r in ref] == [r["r_minus_R_i_over_d"] for r in fe]
    worst = max(abs(float(a["v_over_v_wall"]) - float(b["v_over_v_wall_reference"])) for a, b in zip(fe, ref))
    W_fd = json.load(open(f"{run}/summary.json"))["reference"]["shear_band_width_over_d"]
    rows.append((depth, P, row_rate, worst, entry["shear_band_width_over_d"], W_fd))
with open(f"{out}/annulus_depth_check.csv", "w") as f:
    f.write("depth_over_d,P_Pa,R_i_Omega_sqrt_rho_s_over_P,max_velocity_difference_over_v_wall,W_over_d,W_over_d_fd\n")
    for r in rows:
        f.write(",".join(repr(x) for x in r) + "\n")
for depth, P, row_rate, worst, W, W_fd in rows:
    print(f"depth {depth:7.3f} d: P = {P:7.2f} Pa, rate {row_rate:.2e}: |v - v_FD| <= {worst:.4f} v_wall, "
          f"W/d {W:.4f} (FD {W_fd:.4f}, {W / W_fd - 1:+.1%})")
print(f"wall_pressure_over_hydrostatic = {summary['wall_pressure_over_hydrostatic']:.5f}")
PY
echo "$out/annulus_depth_check.csv"
