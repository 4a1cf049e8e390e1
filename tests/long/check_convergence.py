#!/usr/bin/python3
"""Checks a paper-scale convergence study written by scripts/ (the `long` tests).

    check_convergence.py bingham CONVERGENCE.csv
        Issue #2 b (Daviet 6.1.2, Fig. 5), from scripts/convergence_bingham.sh: in each series
        (stress element, Bi) the max-norm and H1 errors fall at every halving of h, and the order
        of the last halving is at least 1 (measured: 1.22 to 1.79 and 1.18 to 1.49, docs/dp.md).
        Solves that did not reach their tolerance (the script's time cap) are named.
    check_convergence.py ngf-neumann CONVERGENCE.csv
    check_convergence.py ngf-dirichlet CONVERGENCE.csv
        Issue #3 d (Henann 6.1-6.2, Figs. 2a-b and 4a-b), from scripts/ngf_convergence.sh: the
        relative L2 errors of u and g decrease at least linearly and mu_wall converges. With the
        homogeneous Neumann fluidity condition every refinement's order is at least 1 (measured
        1.29 to 2.77). With g = 0 at the driven wall the coarse meshes do not resolve the wall's
        boundary layer (the paper uses "the finer range of mesh resolutions" there): the
        log-log slope over h/d <= 1/9 is at least 1 (measured 1.05 to 1.19). In both,
        |mu_wall - mu_wall_reference| falls at every refinement of that range and is below 1 %
        of the reference on the finest mesh.
Exits 1 with one line per failed check; prints the measured orders.
"""
import csv
import math
import sys


def order(h0, e0, h1, e1):
    return math.log(e0 / e1) / math.log(h0 / h1)


def check_bingham(rows):
    failures = []
    series = {}
    for r in rows:
        series.setdefault((r["stress_element"], r["Bi"]), []).append(r)
    if len(series) != 4:
        failures.append(f"expected 4 series (P1, P1d at Bi = 0.5, 0.9), found {sorted(series)}")
    for r in rows:  # a solve that stopped at its time cap keeps its best iterate: say so
        if float(r["residual"]) > float(r["tolerance"]):
            print(f"note: {r['stress_element']} Bi = {r['Bi']} h = {r['h']} did not converge "
                  f"(residual {float(r['residual']):.3g} > {r['tolerance']}, {r['time_s']} s)")
    for key, rs in sorted(series.items()):
        rs.sort(key=lambda r: -float(r["h"]))
        if len(rs) < 4:
            failures.append(f"{key}: {len(rs)} meshes, expected at least 4")
            continue
        for norm in ("error_Linf", "error_H1"):
            h = [float(r["h"]) for r in rs]
            e = [float(r[norm]) for r in rs]
            orders = [order(h[k], e[k], h[k + 1], e[k + 1]) for k in range(len(e) - 1)]
            print(f"{key[0]} Bi = {key[1]} {norm}: orders " + ", ".join(f"{p:.2f}" for p in orders))
            if not all(math.isfinite(p) and p > 0 for p in orders):
                failures.append(f"{key} {norm}: the error does not fall at every halving ({e})")
            elif orders[-1] < 1:
                failures.append(f"{key} {norm}: last order {orders[-1]:.2f} < 1")
    return failures


def check_ngf(rows, dirichlet):
    failures = []
    rows.sort(key=lambda r: -float(r["h_over_d"]))
    h = [float(r["h_over_d"]) for r in rows]
    fine = [k for k in range(len(h)) if h[k] <= 1 / 9 + 1e-9] if dirichlet else list(range(len(h)))
    if len(fine) < 3:
        return [f"{len(fine)} meshes in the range checked, expected at least 3"]
    for field in ("error_u", "error_g"):
        e = [float(r[field]) for r in rows]
        if not all(math.isfinite(x) and x > 0 for x in e):
            failures.append(f"{field}: not a positive number on every mesh ({e})")
            continue
        if dirichlet:
            # least-squares slope of log e against log h over the finer range
            x = [math.log(h[k]) for k in fine]
            y = [math.log(e[k]) for k in fine]
            mx, my = sum(x) / len(x), sum(y) / len(y)
            slope = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)
            print(f"{field}: slope {slope:.2f} over h/d <= 1/9")
            if slope < 1:
                failures.append(f"{field}: slope {slope:.2f} < 1 over h/d <= 1/9")
        else:
            orders = [order(h[k], e[k], h[k + 1], e[k + 1]) for k in range(len(e) - 1)]
            print(f"{field}: orders " + ", ".join(f"{p:.2f}" for p in orders))
            if min(orders) < 1:
                failures.append(f"{field}: an order below 1 ({min(orders):.2f})")
    mu = [float(rows[k]["mu_wall"]) for k in fine]
    ref = float(rows[0]["mu_wall_reference"])
    gaps = [abs(m - ref) for m in mu]
    print("|mu_wall - reference|: " + ", ".join(f"{g:.2e}" for g in gaps) + f" (reference {ref:.6f})")
    if not all(math.isfinite(g) for g in gaps) or any(b > a for a, b in zip(gaps, gaps[1:])):
        failures.append(f"mu_wall does not approach the reference at every refinement ({mu}, {ref})")
    if not gaps[-1] <= 0.01 * ref:
        failures.append(f"mu_wall on the finest mesh {mu[-1]} is not within 1 % of {ref}")
    return failures


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("bingham", "ngf-neumann", "ngf-dirichlet"):
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[2])))
    if sys.argv[1] == "bingham":
        failures = check_bingham(rows)
    else:
        failures = check_ngf(rows, sys.argv[1] == "ngf-dirichlet")
    for f in failures:
        print(f"FAIL {sys.argv[2]}: {f}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
