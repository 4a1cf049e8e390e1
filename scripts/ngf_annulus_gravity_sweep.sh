#!/usr/bin/env bash
# Henann & Kamrin 2016, Section 6.3 (Figs. 5b, 6): annular shear flow with gravity, R_i = 60 d,
# R_o - R_i = 20 d, H = 15 d, 60 x 45 generalized-axisymmetric quads (h/d = 1/3), 4 degrees of
# inner-wall rotation (wall displacement 4.19 d).
#  - rate sweep R_i Omega / sqrt(G d) = 1e-5 ... 1 (inset of Fig. 5b):
#    OUT/annulus_gravity_rate.csv, OUT/annulus_gravity_rate.png (W/d against the rate, log x);
#  - surface profiles v / v_wall at Z = H against (r - R_i)/d for the rates 1e-4, 1e-2, 1 (main
#    plot of Fig. 5b): OUT/annulus_gravity_surface.csv (one column per rate, shared nodes),
#    OUT/annulus_gravity_surface.png (linear axes and log y);
#  - (R, Z) fields at R_i Omega / sqrt(G d) = 1e-3 (rate-independent row of Fig. 6):
#    OUT/annulus_gravity_fields_rate1e-3.png plus one PNG per
#    field, OUT/annulus_gravity_field_{v_over_v_wall,p_over_phi_rho_s_G_H,mu}.png.
# Columns of the rate CSV: W_over_d = distance from the inner wall at which v/v_wall = 1/e on the
# surface, increments and newton_iterations_per_increment from summary.json, time_s = total run
# time, converged = summary.json 'converged', steady, mu_wall_change_last_tenth and
# velocity_change_last_tenth = summary.json's steady_state (relative change of mu_wall and largest
# change of v / v_wall over the last tenth of the run), note = solver settings that differ from the
# case.
# A run that fails or whose mu_wall is NaN is repeated once with 'Solver/Increment growth=1.2'.
#   scripts/ngf_annulus_gravity_sweep.sh [BUILD_DIR] [OUT_DIR]
# (BUILD_DIR as for the other scripts; the granflow binary itself is also accepted.)
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016}
if [ -d "$build" ]; then granflow=$build/apps/granflow; else granflow=$build; fi
case_file=cases/henann2016/annular_shear_gravity.prm
field_rate=1e-3
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT

# run NAME [--set ...]: one run into a temporary directory.
run() {
  local name=$1; shift
  "$granflow" run "$case_file" --quiet --output "$runs/$name" "$@" >/dev/null
}

finite() { [ -f "$1/summary.json" ] && /usr/bin/python3 -c "import json,math,sys; m=json.load(open(sys.argv[1]))['mu_wall']; sys.exit(0 if m is not None and math.isfinite(m) else 1)" "$1/summary.json"; }

# row RUN_DIR RATE NOTE: the CSV row of one run.
row() {
  /usr/bin/python3 - "$1/summary.json" "$1/history.csv" "$2" "$3" <<'PY'
import csv, json, math, sys
s = json.load(open(sys.argv[1]))
f = lambda x: "nan" if x is None else repr(float(x))
n, st = s["newton"], s["steady_state"]
print(f"{sys.argv[3]},{f(s['shear_band_width_over_d'])},{f(s['mu_wall'])},{n['iterations_per_increment']},"
      f"{n['increments']},{s['timings']['total_s']},{str(s['converged']).lower()},{str(st['steady']).lower()},"
      f"{f(st.get('mu_wall_relative_change'))},{f(st.get('velocity_change_over_v_wall'))},{sys.argv[4]}")
PY
}

rate_csv="$out/annulus_gravity_rate.csv"
echo "rate,W_over_d,mu_wall,newton_iterations_per_increment,increments,time_s,converged,steady,mu_wall_change_last_tenth,velocity_change_last_tenth,note" >"$rate_csv"
for r in 1e-5 1e-4 1e-3 1e-2 1e-1 1; do
  vtu=false
  [ "$r" = "$field_rate" ] && vtu=true
  note=default
  if ! run "rate_$r" --set "Loading/Wall speed=$r" --set "Output/Write vtu=$vtu" 2>/dev/null || ! finite "$runs/rate_$r"; then
    note="default settings failed or diverged to NaN; rerun with Solver/Increment growth=1.2"
    rm -rf "${runs:?}/rate_$r"
    run "rate_$r" --set "Loading/Wall speed=$r" --set "Output/Write vtu=$vtu" --set "Solver/Increment growth=1.2"
  fi
  row "$runs/rate_$r" "$r" "$note" >>"$rate_csv"
done

surface_csv="$out/annulus_gravity_surface.csv"
/usr/bin/python3 - "$surface_csv" "$runs" 1e-4 1e-2 1 <<'PY'
import csv, sys
out, runs, rates = sys.argv[1], sys.argv[2], sys.argv[3:]
x, cols = None, []
for r in rates:
    rows = list(csv.DictReader(open(f"{runs}/rate_{r}/profiles/velocity.csv")))
    xr = [float(p["r_minus_R_i_over_d"]) for p in rows]
    if x is None:
        x = xr
    elif len(xr) != len(x) or max(abs(a - b) for a, b in zip(x, xr)) > 1e-9:
        sys.exit(f"surface profiles of rate {r} and {rates[0]} have different node positions")
    cols.append([p["v_over_v_wall"] for p in rows])
with open(out, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["r_minus_R_i_over_d"] + [f"v_over_v_wall_rate_{r}" for r in rates])
    for i, xi in enumerate(x):
        w.writerow([repr(xi)] + [c[i] for c in cols])
PY

/usr/bin/python3 - "$rate_csv" "$surface_csv" "$out" "$field_rate" "$runs" <<'PY'
import csv, sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import meshio
rate_csv, surface_csv, out, field_rate, runs = sys.argv[1:6]

# Inset of Fig. 5b: W/d against R_i Omega / sqrt(G d).
rows = list(csv.DictReader(open(rate_csv)))
fig, ax = plt.subplots(figsize=(5.5, 4.2))
ax.semilogx([float(r["rate"]) for r in rows], [float(r["W_over_d"]) for r in rows], "o-", mfc="none",
            label="FE, GAX, h/d = 1/3")
ax.set_xlabel("R_i Omega / sqrt(G d)"); ax.set_ylabel("W / d"); ax.set_ylim(bottom=0)
ax.grid(alpha=0.3, which="both"); ax.legend()
ax.set_title("Henann & Kamrin 2016 Fig. 5b inset: R_i/d = 60", fontsize=10)
fig.tight_layout(); fig.savefig(f"{out}/annulus_gravity_rate.png", dpi=130)

# Main plot of Fig. 5b: surface profiles, linear and log y.
surf = list(csv.DictReader(open(surface_csv)))
x = [float(r["r_minus_R_i_over_d"]) for r in surf]
names = [k for k in surf[0] if k.startswith("v_over_v_wall_rate_")]
fig, axs = plt.subplots(1, 2, figsize=(10, 4.2))
for name in names:
    v = [float(r[name]) for r in surf]
    label = "R_i Omega / sqrt(G d) = " + name.rsplit("_", 1)[1]
    axs[0].plot(x, v, "o-", ms=2.5, mfc="none", label=label)
    pos = [(xi, vi) for xi, vi in zip(x, v) if vi > 0]  # v = 0 on the fixed outer wall
    axs[1].semilogy(*zip(*pos), "o-", ms=2.5, mfc="none", label=label)
for ax in axs:
    ax.set_xlabel("(r - R_i) / d"); ax.set_ylabel("v / v_wall at z = H"); ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
axs[0].set_ylim(0, 1.02); axs[1].set_ylim(top=1.5)
fig.suptitle("Henann & Kamrin 2016 Fig. 5b: surface velocity, R_i/d = 60")
fig.tight_layout(); fig.savefig(f"{out}/annulus_gravity_surface.png", dpi=130)

# Fig. 6 (rate-independent row): fields in the (r, z) plane at the field rate.
mesh = meshio.read(f"{runs}/rate_{field_rate}/solution-0000.vtu")
quads = np.vstack([c.data for c in mesh.cells if c.type == "quad"])
tris = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
d = 1e-3  # grain diameter [m] of the case file; mesh coordinates are in metres
pts = mesh.points[:, :2] / d
tri = mtri.Triangulation(pts[:, 0], pts[:, 1], tris)
fields = [("v_over_v_wall", "v / (R_i Omega)"), ("p_over_phi_rho_s_G_H", "p / (phi rho_s G H)"), ("mu", "mu")]

def draw(ax, field, label):
    # Fields written per quad (cell data, or point data that is constant on each quad because the
    # VTU duplicates the nodes of every cell, as for mu and p) are drawn flat, one colour per quad;
    # continuous point fields are contoured.
    if field in mesh.point_data:
        vals = np.asarray(mesh.point_data[field], dtype=float)
        per_quad = vals[quads]
        cellwise = np.ptp(per_quad, axis=1).max() <= 1e-12 * max(np.abs(vals).max(), 1e-300)
        cd = per_quad[:, 0]
    else:
        cd = np.concatenate([np.asarray(a, dtype=float) for c, a in zip(mesh.cells, mesh.cell_data[field])
                             if c.type == "quad"])
        vals, cellwise = cd, True
    if cellwise:
        m = ax.tripcolor(tri, facecolors=np.concatenate([cd, cd]), cmap="jet")
    else:
        m = ax.tricontourf(tri, vals, levels=20, cmap="jet")
    ax.set_xlim(pts[:, 0].min(), pts[:, 0].max()); ax.set_ylim(pts[:, 1].min(), pts[:, 1].max())
    ax.set_aspect("equal"); ax.set_xlabel("r / d"); ax.set_ylabel("z / d")
    kind = "per element" if cellwise else "nodal"
    ax.set_title(f"{label} ({kind}; min {np.nanmin(vals):.3g}, max {np.nanmax(vals):.3g})", fontsize=9)
    return m

fig_all, axs = plt.subplots(3, 1, figsize=(6.5, 9))
for ax, (field, label) in zip(axs, fields):
    fig_all.colorbar(draw(ax, field, label), ax=ax, shrink=0.9)
    fig, a = plt.subplots(figsize=(7, 3.6))
    fig.colorbar(draw(a, field, label), ax=a, shrink=0.9)
    fig.suptitle(f"Henann & Kamrin 2016 Fig. 6: R_i Omega / sqrt(G d) = {field_rate}", fontsize=10)
    fig.tight_layout(); fig.savefig(f"{out}/annulus_gravity_field_{field}.png", dpi=130)
    plt.close(fig)
fig_all.suptitle(f"Henann & Kamrin 2016 Fig. 6: R_i Omega / sqrt(G d) = {field_rate}, R_i/d = 60")
fig_all.tight_layout(); fig_all.savefig(f"{out}/annulus_gravity_fields_rate{field_rate}.png", dpi=130)
PY
echo "$rate_csv"
echo "$surface_csv"
ls "$out"/annulus_gravity_*.png
