#!/usr/bin/env bash
# Henann & Kamrin 2016, Fig. 2a-b (Section 6.1) and Fig. 4a-b (Section 6.2): mesh convergence
#  - GEOMETRY = column (default): the shear column at P_wall/(phi rho_s G d) = 6.67,
#    v_wall/sqrt(Gd) = 1e-3 (wall displacement d); fluidity Dirichlet boundary 'wall';
#  - GEOMETRY = annulus: the annulus row at R_i/d = 60, R_i Omega sqrt(rho_s/P_wall) = 1e-3 (4
#    degrees); fluidity Dirichlet boundary 'inner wall'. u is the circumferential displacement
#    r theta (u_r is not in the velocity profile and is left out).
# h/d = 1, 2/3, 5/9, 1/3, 2/9, 1/9 (and 1/18, 1/45 for (b), whose wall boundary layer the coarse
# meshes do not resolve: the paper too uses "the finer range of mesh resolutions" there), against
# an FE "exact" solution on a fine mesh:
#  (a) homogeneous Neumann fluidity condition everywhere, reference h/d = 1/90;
#  (b) g = 0 at the driven wall, reference h/d = 1/REF_B (paper: 1/900, the default).
# A reference run that fails or ends with a NaN mu_wall is repeated once with
# 'Solver/Increment growth=1.2' (printed).
# Relative errors by the paper's (91): trapezoid-weighted discrete L2 norm over the FE nodes of
# u_FE - u_ref and g_FE - g_ref, the reference nodes matched by position, divided by the
# trapezoid norm of the reference over its own nodes.
# Writes DIR/convergence_GEOMETRY_neumann.csv, DIR/convergence_GEOMETRY_dirichlet.csv (h_over_d,
# error_u, error_g, mu_wall, mu_wall_reference, h_reference_over_d, order_u, order_g = observed
# orders against the next coarser mesh, time_s) and DIR/convergence_GEOMETRY.png (errors against
# h/d, log-log, slope-1 guide; mu_wall against d/h with the reference as a dashed line). Prints
# the observed orders.
#   scripts/ngf_convergence.sh [BUILD_DIR] [OUT_DIR] [REF_B] [GEOMETRY]
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016} ref_b=${3:-900} geometry=${4:-column}
granflow="$build/apps/granflow"
case $geometry in
  column)
    case_file=cases/henann2016/linear_shear_gravity.prm wall="wall"
    loading=(--set "Loading/Wall pressure=6.67" --set "Loading/Wall speed=1e-3")
    title="Fig. 2a-b: P_wall / phi rho_s G d = 6.67, v_wall / sqrt(G d) = 1e-3" ;;
  annulus)
    case_file=cases/henann2016/annular_shear.prm wall="inner wall"
    loading=(--set "Geometry/Inner radius=60" --set "Loading/Wall speed=1e-3")
    title="Fig. 4a-b: R_i / d = 60, R_i Omega sqrt(rho_s / P_wall) = 1e-3" ;;
  *) echo "ngf_convergence.sh: GEOMETRY must be column or annulus, not '$geometry'" >&2; exit 2 ;;
esac
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
base_sizes="1 0.666666666667 0.555555555556 0.333333333333 0.222222222222 0.111111111111"

# run NAME ELEMENT_SIZE [--set ...]
run() {
  local name=$1 h=$2; shift 2
  "$granflow" run "$case_file" --quiet --output "$runs/$name" --set "Geometry/Element size=$h" \
    "${loading[@]}" --set "Output/Write vtu=false" --set "Output/Reference=none" "$@" >/dev/null
}

for bc in neumann dirichlet; do
  if [ "$bc" = neumann ]; then
    extra=(); ref_n=90; sizes=$base_sizes
  else
    extra=(--set "Fluidity boundary conditions/Dirichlet=$wall: 0"); ref_n=$ref_b
    sizes="$base_sizes 0.0555555555556 0.0222222222222"
  fi
  ref_h=$(/usr/bin/python3 -c "print(f'{1 / $ref_n:.14f}')")
  if ! run "conv_${bc}_ref" "$ref_h" "${extra[@]}" 2>/dev/null || ! /usr/bin/python3 -c \
      "import json,math,sys; m=json.load(open(sys.argv[1]))['mu_wall']; sys.exit(0 if m is not None and math.isfinite(m) else 1)" \
      "$runs/conv_${bc}_ref/summary.json" 2>/dev/null; then
    echo "$bc reference h/d = 1/$ref_n failed with the case's solver settings; rerun with Solver/Increment growth=1.2"
    run "conv_${bc}_ref" "$ref_h" "${extra[@]}" --set "Solver/Increment growth=1.2"
  fi
  for h in $sizes; do run "conv_${bc}_h$h" "$h" "${extra[@]}"; done
  /usr/bin/python3 - "$runs" "$bc" $sizes >"$out/convergence_${geometry}_$bc.csv" <<'PY'
import csv, json, math, sys
runs, bc, sizes = sys.argv[1], sys.argv[2], sys.argv[3:]
def load(run):
    s = json.load(open(f"{runs}/{run}/summary.json"))
    rows = list(csv.DictReader(open(f"{runs}/{run}/profiles/velocity.csv")))
    if "z_over_d" in rows[0]:  # shear column
        z = [float(r["z_over_d"]) for r in rows]
        fields = {k: [float(r[c]) for r in rows] for k, c in (("u", "u_x_over_d"), ("g", "g_sqrt_d_over_G"))}
    else:  # annulus row: u = r theta in grain diameters
        z = [float(r["r_minus_R_i_over_d"]) for r in rows]
        R_i = s["R_i_over_d"]
        fields = {"u": [(R_i + x) * float(r["theta"]) for x, r in zip(z, rows)],
                  "g": [float(r["g_d_sqrt_rho_s_over_P_wall"]) for r in rows]}
    return s, z, fields
def trapezoid(values, h):  # sqrt(sum T_A v_A^2 h), T_A = 1/2 at the two ends
    w = [0.5 if i in (0, len(values) - 1) else 1.0 for i in range(len(values))]
    return math.sqrt(sum(wi * v * v for wi, v in zip(w, values)) * h)
sref, zref, fref = load(f"conv_{bc}_ref")
href = sref["mesh"]["h_over_d"]
key = lambda z: round(z * 1e6)
index = {key(z): i for i, z in enumerate(zref)}
norm = {k: trapezoid(v, href) for k, v in fref.items()}
print("h_over_d,error_u,error_g,mu_wall,mu_wall_reference,h_reference_over_d,order_u,order_g,time_s")
prev = None
for size in sizes:
    s, z, f = load(f"conv_{bc}_h{size}")
    h = s["mesh"]["h_over_d"]
    idx = [index[key(zi)] for zi in z]  # KeyError if a coarse node is not a reference node
    err = {k: trapezoid([f[k][a] - fref[k][i] for a, i in enumerate(idx)], h) / norm[k] for k in f}
    order = {k: math.log(prev[1][k] / err[k]) / math.log(prev[0] / h) if prev else float("nan") for k in err}
    print(f"{h!r},{err['u']!r},{err['g']!r},{s['mu_wall']!r},{sref['mu_wall']!r},{href!r},"
          f"{order['u']:.4f},{order['g']:.4f},{s['timings']['total_s']}")
    prev = (h, err)
print(f"# reference time_s {sref['timings']['total_s']}", file=sys.stderr)
PY
  echo "== $bc (reference h/d = 1/$ref_n)"
  /usr/bin/python3 -c "
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    print(f\"h/d = {float(r['h_over_d']):.4f}: error_u = {float(r['error_u']):.3e} (order {r['order_u']}), error_g = {float(r['error_g']):.3e} (order {r['order_g']}), mu_wall = {float(r['mu_wall']):.6f} (ref {float(r['mu_wall_reference']):.6f})\")
" "$out/convergence_${geometry}_$bc.csv"
done

/usr/bin/python3 - "$out" "$geometry" "$title" <<'PY'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
out, geometry, title = sys.argv[1:4]
fig, axs = plt.subplots(2, 2, figsize=(10, 8))
for j, (bc, panel) in enumerate((("neumann", "(a) Neumann fluidity BC"), ("dirichlet", "(b) g = 0 at the wall"))):
    rows = list(csv.DictReader(open(f"{out}/convergence_{geometry}_{bc}.csv")))
    h = [float(r["h_over_d"]) for r in rows]
    ref_h = float(rows[0]["h_reference_over_d"])
    ax = axs[0][j]
    for k, m in (("error_u", "o"), ("error_g", "s")):
        e = [float(r[k]) for r in rows]
        ax.loglog(h, e, m + "-", label=k.replace("error_", "relative L2 error of "))
    e0 = max(float(rows[0]["error_u"]), float(rows[0]["error_g"]))
    ax.loglog([h[0], h[-1]], [e0 * 1.5, e0 * 1.5 * h[-1] / h[0]], "k--", lw=1, label="slope 1")
    ax.set_xlabel("h/d"); ax.set_ylabel("relative L2 error (91)")
    ax.set_title(f"{panel}, reference h/d = 1/{round(1 / ref_h)}"); ax.grid(alpha=0.3, which="both"); ax.legend(fontsize=8)
    ax = axs[1][j]
    ax.plot([1 / x for x in h], [float(r["mu_wall"]) for r in rows], "o-", label="FE")
    ax.axhline(float(rows[0]["mu_wall_reference"]), color="k", ls="--", lw=1, label="reference mesh")
    ax.set_xlabel("d/h"); ax.set_ylabel("mu_wall"); ax.grid(alpha=0.3); ax.legend(fontsize=8)
fig.suptitle(f"Henann & Kamrin 2016 {title}")
fig.tight_layout(); fig.savefig(f"{out}/convergence_{geometry}.png", dpi=130)
PY
echo "$out/convergence_${geometry}_neumann.csv"
echo "$out/convergence_${geometry}_dirichlet.csv"
