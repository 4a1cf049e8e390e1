#!/usr/bin/env bash
# Henann & Kamrin 2016, Section 6.1 / Fig. 2c and 6.2 / Fig. 4c: asymptotically quadratic
# convergence of the (u, g) Newton procedure on the shear column (GEOMETRY = column, default:
# P_wall/(phi rho_s G d) = 6.67, v_wall/sqrt(Gd) = 1e-3) or the annulus row (GEOMETRY = annulus:
# R_i/d = 60, R_i Omega sqrt(rho_s/P_wall) = 1e-3), h/d = 1/3, homogeneous Neumann fluidity
# conditions, case-file solver settings except the Newton tolerance TOL (default 1e-13) and a fresh
# factorisation every iteration. R_u's round-off floor is near 5e-14 at the paper's moduli
# (docs/ngf.md); increments also end on the driver's rule for a full Newton correction below
# 1e-10 of each field, before R_g reaches a floor.
# From newton.csv, the accepted attempt of each of the first ten increments that needed at least
# 3 Newton iterations (the yielding transient; attempts that were cut and repeated are skipped)
# gives the pairs (R^(k), R^(k+1)) of normalised L_inf residuals, and of the full Newton
# corrections c^(k) (L_inf, relative to the field's L_inf; before any line search, which the
# yielding increments do not need), the paper's footnote's measure of the error in the degrees of
# freedom.
# Writes DIR/newton_rate_GEOMETRY.csv (increment, k, R_k_u, R_k1_u, R_k_g, R_k1_g, c_k_u, c_k1_u,
# c_k_g, c_k1_g) and DIR/newton_rate_GEOMETRY.png (top: R^(k+1) against R^(k); bottom: c^(k+1)
# against c^(k); log-log, one colour per increment, dashed quadratic guides). Prints, per field, the least-squares slope of log R^(k+1)
# against log R^(k) over the pairs with 0 < R^(k) < 1e-2, again without the pairs whose R^(k+1) is
# at the round-off floor (R_u < FLOOR_U, default 1e-13; R_g < FLOOR_G, default 1e-12), and the
# median local order log(X^(k+1)/X^(k)) / log(X^(k)/X^(k-1)) within each increment over the
# iterates with X^(k) < 1e-2 and X^(k+1) above the floor (1e-13 for the corrections), for X the
# residual and the correction (the pooled fit mixes increments whose constants differ).
#   scripts/ngf_newton_rate.sh [BUILD_DIR] [OUT_DIR] [TOL] [FLOOR_U] [FLOOR_G] [GEOMETRY]
set -euo pipefail
build=${1:-build} out=${2:-results/henann2016} tol=${3:-1e-13} floor_u=${4:-1e-13} floor_g=${5:-1e-12}
geometry=${6:-column}
case $geometry in
  column) case_file=cases/henann2016/linear_shear_gravity.prm figure="Fig. 2c"
    loading=(--set "Loading/Wall pressure=6.67" --set "Loading/Wall speed=1e-3") ;;
  annulus) case_file=cases/henann2016/annular_shear.prm figure="Fig. 4c"
    loading=(--set "Geometry/Inner radius=60" --set "Loading/Wall speed=1e-3") ;;
  *) echo "ngf_newton_rate.sh: GEOMETRY must be column or annulus, not '$geometry'" >&2; exit 2 ;;
esac
mkdir -p "$out"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
run="$runs/newton_rate"
"$build/apps/granflow" run "$case_file" --quiet --output "$run" "${loading[@]}" --set "Solver/Tolerance=$tol" \
  --set "Solver/Reuse factorization=false" \
  --set "Output/Write vtu=false" --set "Output/Reference=none" >/dev/null
/usr/bin/python3 - "$run/newton.csv" "$out" "$floor_u" "$floor_g" "$tol" "$geometry" "$figure" <<'PY'
import csv, math, statistics, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
out, floors = sys.argv[2], (float(sys.argv[3]), float(sys.argv[4]))
attempts = {}  # increment -> its last (accepted) attempt; a new attempt starts at iteration 0
for r in rows:
    inc, it = int(r["increment"]), int(r["iteration"])
    if it == 0:
        attempts[inc] = []
    attempts[inc].append((float(r["R_u"]), float(r["R_g"]), float(r["correction_u"]), float(r["correction_g"])))
chosen = [inc for inc in sorted(attempts) if len(attempts[inc]) - 1 >= 3][:10]
with open(f"{out}/newton_rate_{sys.argv[6]}.csv", "w") as f:
    f.write("increment,k,R_k_u,R_k1_u,R_k_g,R_k1_g,c_k_u,c_k1_u,c_k_g,c_k1_g\n")
    for inc in chosen:
        a = attempts[inc]
        for k in range(len(a) - 1):
            f.write(f"{inc},{k},{a[k][0]!r},{a[k + 1][0]!r},{a[k][1]!r},{a[k + 1][1]!r},"
                    f"{a[k][2]!r},{a[k + 1][2]!r},{a[k][3]!r},{a[k + 1][3]!r}\n")
print(f"increments with >= 3 Newton iterations (first ten): {chosen}")
print("iterations per chosen increment:", [len(attempts[i]) - 1 for i in chosen])
def slope(pairs):
    if len(pairs) < 2:
        return float("nan"), len(pairs)
    x = [math.log10(p[0]) for p in pairs]; y = [math.log10(p[1]) for p in pairs]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x), len(pairs)
fig, axs = plt.subplots(2, 2, figsize=(11, 9.5))
colors = plt.cm.tab10.colors
def local_orders(column, floor):
    orders = []
    for inc in chosen:
        a = [r[column] for r in attempts[inc] if not math.isnan(r[column])]
        orders += [math.log(a[k + 1] / a[k]) / math.log(a[k] / a[k - 1]) for k in range(1, len(a) - 1)
                   if a[k] < 1e-2 and a[k + 1] >= floor and a[k - 1] > 0 and a[k] != a[k - 1]]
    return orders
# top row: the residuals R (Fig. 2c / 4c); bottom row: the full Newton corrections c (the error in
# the degrees of freedom of the paper's footnote), each against its previous value
for j, name in enumerate(("u", "g")):
    for row, (column, symbol, floor) in enumerate(((j, "R", floors[j]), (j + 2, "c", 1e-13))):
        ax = axs[row][j]
        all_pairs = []
        for c, inc in enumerate(chosen):
            a = [r[column] for r in attempts[inc]]
            pairs = [(a[k], a[k + 1]) for k in range(len(a) - 1) if a[k] > 0 and a[k + 1] > 0]
            all_pairs += pairs
            ax.loglog([p[0] for p in pairs], [p[1] for p in pairs], "o", color=colors[c % 10], ms=5,
                      label=f"increment {inc}")
        local = local_orders(column, floor)
        ax.axhline(floor, color="gray", ls=":", lw=1)
        xs = [p[0] for p in all_pairs]
        lo, hi = min(xs), max(xs)
        for c0 in (1e-2, 1, 1e2):
            ax.loglog([lo, hi], [c0 * lo ** 2, c0 * hi ** 2], "k--", lw=0.8)
        ax.set_ylim(min(p[1] for p in all_pairs) / 3, max(p[1] for p in all_pairs) * 3)
        ax.set_xlabel(f"{symbol}_{name}^(k)"); ax.set_ylabel(f"{symbol}_{name}^(k+1)")
        ax.grid(alpha=0.3, which="both")
        med = statistics.median(local) if local else float("nan")
        if row == 0:
            s_all = slope([p for p in all_pairs if p[0] < 1e-2])
            s_flo = slope([p for p in all_pairs if p[0] < 1e-2 and p[1] >= floor])
            ax.set_title(f"residual R_{name}: fit slope {s_all[0]:.2f} (R^(k) < 1e-2), {s_flo[0]:.2f} (also "
                         f"R^(k+1) >= {floor:g})\nmedian local order {med:.2f}; dotted: FLOOR\n(the fit and the "
                         f"orders exclude R^(k+1) below it)", fontsize=9)
            print(f"R_{name}: slope of log R^(k+1) vs log R^(k), R^(k) < 1e-2: {s_all[0]:.3f} over {s_all[1]} pairs; "
                  f"excluding R^(k+1) < {floor:g}: {s_flo[0]:.3f} over {s_flo[1]} pairs; "
                  f"local orders within increments: median {med:.2f} of {len(local)} {[round(x, 2) for x in local]}")
        else:
            ax.set_title(f"Newton correction of {name} (L_inf, relative to the field):\nmedian local order "
                         f"{med:.2f}; dotted: 1e-13 (orders exclude c^(k+1) below it)", fontsize=9)
            print(f"  correction of {name}: local orders within increments: median {med:.2f} of {len(local)} "
                  f"{[round(x, 2) for x in local]}")
axs[0][0].legend(fontsize=7)
fig.suptitle(f"Henann & Kamrin 2016 {sys.argv[7]}: Newton residuals (tolerance {sys.argv[5]});\n"
             f"dashed: quadratic R^(k+1) = c R^(k)^2, c = 1e-2, 1, 1e2", fontsize=10)
fig.tight_layout(); fig.savefig(f"{out}/newton_rate_{sys.argv[6]}.png", dpi=130)
PY
echo "$out/newton_rate_$geometry.csv"
