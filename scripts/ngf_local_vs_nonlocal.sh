#!/usr/bin/env bash
# Henann & Kamrin 2016, Section 6.3 / Fig. 7b: the annulus with gravity (quad section, R_i = 60 d,
# R_i Omega / sqrt(G d) = 1e-3) with the nonlocal and the local (g = g_loc) model at h/d = 1/3, 1/2
# and 1. Writes OUT/local_vs_nonlocal.csv (one surface-velocity column per model and mesh, against
# (r - R_i)/d at the nodes every mesh has, i.e. every grain diameter), OUT/local_vs_nonlocal_summary.csv
# (W/d, mu_wall, time per run), OUT/local_vs_nonlocal_differences.csv and OUT/local_vs_nonlocal.png
# (linear and log axes). Prints the largest difference between the meshes for each model, at the
# shared nodes and as FE functions.
#   scripts/ngf_local_vs_nonlocal.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016}
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
for model in nonlocal local; do
  for h in 0.333333333333 0.5 1; do
    "$build/apps/granflow" run cases/henann2016/annular_shear_gravity.prm --quiet --output "$runs/${model}_$h" \
      --set "Solver/Fluidity=$model" --set "Geometry/Element size=$h" --set "Output/Write vtu=false" >/dev/null
  done
done
/usr/bin/python3 - "$runs" "$out" <<'PY'
import csv, json, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
runs, out = sys.argv[1:3]
sizes = ["0.333333333333", "0.5", "1"]
profiles, summary = {}, []
for model in ("nonlocal", "local"):
    for h in sizes:
        rows = list(csv.DictReader(open(f"{runs}/{model}_{h}/profiles/velocity.csv")))
        profiles[(model, h)] = {round(float(r["r_minus_R_i_over_d"]), 6): float(r["v_over_v_wall"]) for r in rows}
        s = json.load(open(f"{runs}/{model}_{h}/summary.json"))
        summary.append((model, float(h), s["shear_band_width_over_d"], s["mu_wall"], s["timings"]["total_s"]))
common = sorted(set.intersection(*(set(p) for p in profiles.values())))
with open(f"{out}/local_vs_nonlocal.csv", "w") as f:
    f.write("r_minus_R_i_over_d," + ",".join(f"v_{m}_h{float(h):.3f}" for m in ("nonlocal", "local") for h in sizes) + "\n")
    for x in common:
        f.write(f"{x}," + ",".join(repr(profiles[(m, h)][x]) for m in ("nonlocal", "local") for h in sizes) + "\n")
with open(f"{out}/local_vs_nonlocal_summary.csv", "w") as f:
    f.write("model,h_over_d,W_over_d,mu_wall,time_s\n")
    for row in summary:
        f.write(",".join(str(v) for v in row) + "\n")
# Two measures of the difference between meshes: at the nodes all meshes share (every d), and as
# FE functions (each profile linear between its own nodes) at the finest mesh's nodes. The first
# hides the local model's mesh dependence, whose flow lies within one element of the wall, so
# nearly all of it falls between the shared nodes.
import numpy as np
def fe_difference(m):
    xs = sorted(profiles[(m, sizes[0])])
    interp = {h: np.interp(xs, sorted(profiles[(m, h)]), [profiles[(m, h)][x] for x in sorted(profiles[(m, h)])]) for h in sizes}
    return max(float(np.max(np.abs(interp[a] - interp[b]))) for a in sizes for b in sizes)
with open(f"{out}/local_vs_nonlocal_differences.csv", "w") as f:
    f.write("model,at_shared_nodes,as_fe_functions\n")
    for m in ("nonlocal", "local"):
        worst = max(abs(profiles[(m, a)][x] - profiles[(m, b)][x]) for x in common for a in sizes for b in sizes)
        fe = fe_difference(m)
        f.write(f"{m},{worst!r},{fe!r}\n")
        print(f"{m}: largest surface-velocity difference between h/d = 1/3, 1/2, 1: {worst:.4f} of the wall "
              f"speed at the shared nodes, {fe:.4f} as FE functions")
for row in summary:
    print(f"{row[0]:8s} h/d = {row[1]:.3f}: W/d = {row[2]:.3f}, mu_wall = {row[3]:.4f}, {row[4]:.1f} s")
fig, axs = plt.subplots(1, 2, figsize=(10, 4))
for m, style in (("nonlocal", "-"), ("local", "--")):
    for h in sizes:
        xs = sorted(profiles[(m, h)])
        for ax in axs:
            ax.plot(xs, [max(profiles[(m, h)][x], 1e-12) for x in xs], style, label=f"{m}, h/d = {float(h):.2f}")
axs[1].set_yscale("log"); axs[1].set_ylim(1e-8, 1.5)
for ax in axs:
    ax.set_xlabel("(r - R_i) / d"); ax.set_ylabel("v / v_wall at z = H"); ax.grid(alpha=0.3); ax.legend(fontsize=7)
fig.suptitle("Henann & Kamrin 2016 Fig. 7b: local and nonlocal, R_i Omega / sqrt(G d) = 1e-3")
fig.tight_layout(); fig.savefig(f"{out}/local_vs_nonlocal.png", dpi=130)
PY
echo "$out/local_vs_nonlocal.csv"
