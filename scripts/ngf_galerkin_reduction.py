#!/usr/bin/env python3
"""Henann & Kamrin 2016, Section 6.1 / Fig. 7b: why the nonlocal FE profile at h = d is off.

An independent steady 1D reduction of the paper's Galerkin discretization of the shear column
(P_wall/(phi rho_s G d) = 6.67, v_wall/sqrt(G d) = 1e-3, homogeneous Neumann fluidity conditions):
linear elements, 2-point Gauss, and at steady state, at each Gauss point, plastic = total shear rate,
g_q mu_q = gammadot_e (20) (the element's shear rate is constant, g varies linearly); equilibrium in
weak form makes the Gauss average of tau = mu p the same in every element; the fluidity residual is
(34)_2 with g_loc (22) and xi (24) at the Gauss points; the wall speed fixes the sum of the element
shear rates. Solved by scipy's root + Newton polish. Also a finite-difference solution of (90) on a
0.01 d grid, and the FE code's own runs (BUILD_DIR/apps/granflow) at h/d = 1, 2/3, 1/3, 1/9.

If the reduction reproduces the FE's coarse-mesh deviation from FD, that deviation is a property
of the paper's discretization and not of our implementation. Side experiment at h = d: the
fluidity reaction term integrated with nodal (trapezoidal) quadrature, with three choices of mu
at the nodes, to show how sensitive the coarse-mesh answer is to that choice; and ('gbar') the
flow rule evaluated with the element-mean fluidity, so that mu does not split between an
element's Gauss points (docs/ngf.md).

Writes OUT_DIR/galerkin_reduction_column.csv and prints the table (with mu_wall - mu_s relative to
the FD solution's). P_WALL (default 6.67) is
P_wall/(phi rho_s G d), for the FD solution, the reduction and the FE runs alike.
  /usr/bin/python3 scripts/ngf_galerkin_reduction.py [BUILD_DIR] [OUT_DIR] [P_WALL]
Dimensionless units: z~ = z/d, g~ = g sqrt(d/G), p~ = p/(rho_s G d), v~ = v/sqrt(G d), so that
g_loc~ = sqrt(p~) (mu - mu_s)/(b mu), xi~ = A/sqrt|mu - mu_s|, gammadot~ = g~ mu.
"""
import json, os, subprocess, sys, tempfile
import numpy as np
from scipy.optimize import brentq, root
from scipy.sparse import diags
from scipy.sparse.linalg import spsolve

MU_S, B, A = 0.3819, 0.9377, 0.48
PHI = 0.62
D = 20.0
P_WALL = float(sys.argv[3]) if len(sys.argv) > 3 else 6.67  # P_wall / (phi rho_s G d)
PW = P_WALL * PHI        # P_wall / (rho_s G d)
VW = 1e-3                # v_wall / sqrt(G d)
XI_CAP = 1000.0


def p_of(z):
    return PW + PHI * z


def gloc(mu, p):
    mu = np.asarray(mu, float)
    out = np.zeros_like(mu)
    m = mu > MU_S
    out[m] = np.sqrt(p[m] if np.ndim(p) else p) * (mu[m] - MU_S) / (B * mu[m])
    return out


def inv_xi2(mu):
    dm = np.abs(np.asarray(mu, float) - MU_S)
    xi = np.minimum(A / np.sqrt(np.maximum(dm, 1e-300)), XI_CAP)
    return 1.0 / xi**2


# ----------------------------------------------------------------- FD of (90)
def fd_solve_mu(mu_wall, dz=0.01):
    n = int(round(D / dz))
    z = np.linspace(0, D, n + 1)
    p = p_of(z)
    mu = mu_wall * PW / p
    k = inv_xi2(mu)
    gl = gloc(mu, p)
    # g'' - k g = -k gl ; Neumann via ghost points (second order)
    main = -2.0 / dz**2 - k
    up = np.full(n, 1.0 / dz**2)
    lo = np.full(n, 1.0 / dz**2)
    up[0] = 2.0 / dz**2
    lo[-1] = 2.0 / dz**2
    M = diags([lo, main, up], [-1, 0, 1], format='csc')
    g = spsolve(M, -k * gl)
    gd = g * mu
    # v(z) = int_z^D gd  (trapezoid)
    seg = 0.5 * (gd[1:] + gd[:-1]) * dz
    v = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])
    return z, g, v, mu


def fd_solve():
    f = lambda m: fd_solve_mu(m)[2][0] - VW
    mw = brentq(f, MU_S + 1e-6, 0.45, xtol=1e-14)
    z, g, v, mu = fd_solve_mu(mw)
    return dict(mu_wall=mw, z=z, g=g, v=v / VW)


# ------------------------------------------------------ Galerkin 1D reduction
GP = np.array([-1.0, 1.0]) / np.sqrt(3.0)   # in [-1,1]


def galerkin_residual(x, N, h, quad='gauss', gscale=1e3):
    g = x[:N + 1] / gscale
    tau = x[-1] * PW * 0.4     # tau_wall/(rho_s G d), x[-1] ~ mu_wall/0.4
    zn = np.linspace(0, D, N + 1)
    zc = 0.5 * (zn[1:] + zn[:-1])
    # Gauss points
    zq = zc[:, None] + 0.5 * h * GP[None, :]             # (N,2)
    Nq = np.stack([0.5 * (1 - GP), 0.5 * (1 + GP)], 1)  # N_a(xi_q): rows q, cols a
    gq = np.maximum(g[:-1, None] * Nq[None, :, 0] + g[1:, None] * Nq[None, :, 1], 1e-300)
    pq = p_of(zq)
    # per element: mu_q = gd/g_q, (mu_1 p_1 + mu_2 p_2)/2 = tau  -> gd
    gflow = np.repeat(gq.mean(1)[:, None], 2, 1) if quad == 'gbar' else gq
    gd = 2 * tau / (pq[:, 0] / gflow[:, 0] + pq[:, 1] / gflow[:, 1])
    muq = gd[:, None] / gflow
    R = np.zeros(N + 1)
    # stiffness g' N'
    dg = (g[1:] - g[:-1]) / h
    R[:-1] += -dg
    R[1:] += dg
    if quad in ('gauss', 'gbar'):
        f = (gq - gloc(muq, pq)) * inv_xi2(muq)             # (N,2)
        for a, sl in ((0, slice(0, N)), (1, slice(1, N + 1))):
            R[sl] += (0.5 * h) * (f * Nq[None, :, a]).sum(1)
    else:
        # nodal (trapezoidal) quadrature of N^A (g - g_loc)/xi^2; mu at element nodes
        if quad == 'trap_extrap':   # linear extrapolation of Gauss-point mu to nodes
            s = np.sqrt(3.0)
            mun = np.stack([0.5 * (1 + s) * muq[:, 0] + 0.5 * (1 - s) * muq[:, 1],
                            0.5 * (1 - s) * muq[:, 0] + 0.5 * (1 + s) * muq[:, 1]], 1)
        elif quad == 'trap_const':  # element-constant mu (Gauss average)
            mun = np.repeat(muq.mean(1)[:, None], 2, 1)
        elif quad == 'trap_tauover_p':  # mu at node = tau_e/p(node) with tau_e = tau
            mun = tau / p_of(np.stack([zn[:-1], zn[1:]], 1))
        pn = p_of(np.stack([zn[:-1], zn[1:]], 1))
        gn = np.stack([g[:-1], g[1:]], 1)
        f = (gn - gloc(mun, pn)) * inv_xi2(mun)
        R[:-1] += 0.5 * h * f[:, 0]
        R[1:] += 0.5 * h * f[:, 1]
    speed = gd.sum() * h - VW
    return np.concatenate([R * gscale, [speed * gscale]]), dict(g=g, gd=gd, tau=tau, muq=muq, zq=zq)


def galerkin_solve(hd, x0fun, quad='gauss'):
    N = int(round(D / hd))
    h = D / N
    zn = np.linspace(0, D, N + 1)
    x0 = x0fun(zn)
    fun = lambda x: galerkin_residual(x, N, h, quad)[0]
    sol = root(fun, x0, method='hybr', options=dict(xtol=1e-14, maxfev=200000))
    x = sol.x
    # polish with Newton (numerical Jacobian)
    for it in range(30):
        r = fun(x)
        if np.max(np.abs(r)) < 1e-13:
            break
        J = np.empty((len(x), len(x)))
        for j in range(len(x)):
            dx = 1e-7 * max(abs(x[j]), 1e-6)
            xp = x.copy(); xp[j] += dx
            J[:, j] = (fun(xp) - r) / dx
        x = x - np.linalg.solve(J, r)
    r, info = galerkin_residual(x, N, h, quad)
    v = np.concatenate([np.cumsum((info['gd'] * h)[::-1])[::-1], [0.0]]) / VW
    return dict(z=zn, g=info['g'], v=v, mu_wall=info['tau'] / PW, res=np.max(np.abs(r)),
                x=x, h=h)


def width(z, v):
    t = np.exp(-1.0)
    i = np.nonzero(v < t)[0][0]
    return z[i - 1] + (t - v[i - 1]) * (z[i] - z[i - 1]) / (v[i] - v[i - 1])


def main():
    fd = fd_solve()
    fd['W'] = width(fd['z'], fd['v'])
    print(f"FD: mu_wall={fd['mu_wall']:.6f}  W/d={fd['W']:.4f}  g_wall={fd['g'][0]:.6e}")
    vfd = lambda z: np.interp(z, fd['z'], fd['v'])
    gfd = lambda z: np.interp(z, fd['z'], fd['g'])

    def x0_from(zfun_g, mu_wall):
        return lambda zn: np.concatenate([zfun_g(zn) * 1e3, [mu_wall / 0.4]])

    res = {}
    hs = [('1', 1.0), ('2/3', 2 / 3), ('5/9', 5 / 9), ('1/3', 1 / 3), ('2/9', 2 / 9),
          ('1/9', 1 / 9), ('1/27', 1 / 27), ('1/90', 1 / 90)]
    for lab, hd in hs:
        s = galerkin_solve(hd, x0_from(gfd, fd['mu_wall']))
        s['W'] = width(s['z'], s['v'])
        res[lab] = s
    variants = {}
    for q in ('trap_extrap', 'trap_const', 'trap_tauover_p', 'gbar'):
        s = galerkin_solve(1.0, x0_from(gfd, fd['mu_wall']), quad=q)
        s['W'] = width(s['z'], s['v'])
        variants[q] = s

    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    fe = {}
    runs = tempfile.mkdtemp()
    for lab, size in (('1', '1'), ('2/3', '0.666666666667'), ('1/3', '0.333333333333'), ('1/9', '0.111111111111')):
        pth = os.path.join(runs, size)
        subprocess.run([os.path.join(build, "apps", "granflow"), "run", "cases/henann2016/linear_shear_gravity.prm",
                        "--quiet", "--output", pth, "--set", f"Geometry/Element size={size}",
                        "--set", f"Loading/Wall pressure={P_WALL}", "--set", "Loading/Wall speed=1e-3",
                        "--set", "Output/Write vtu=false", "--set", "Output/Reference=none"],
                       check=True, stdout=subprocess.DEVNULL)
        dat = np.genfromtxt(os.path.join(pth, 'profiles/velocity.csv'), delimiter=',', names=True)
        sm = json.load(open(os.path.join(pth, 'summary.json')))
        fe[lab] = dict(z=dat['z_over_d'], v=dat['v_over_v_wall'], g=dat['g_sqrt_d_over_G'],
                       mu_wall=sm['mu_wall'], W=sm['shear_band_width_over_d'])

    out = sys.argv[2] if len(sys.argv) > 2 else "results/henann2016"
    os.makedirs(out, exist_ok=True)
    csv = open(os.path.join(out, "galerkin_reduction_column.csv"), "w")
    csv.write("solver,h_over_d,v_at_1d,v_at_2d,v_at_3d,v_at_4d,max_abs_dv_vs_fd,mu_wall,W_over_d,g_wall_sqrt_d_over_G,"
              "mu_wall_minus_mu_s_relative_difference\n")

    def row(name, s):
        vz = [np.interp(zz, s['z'], s['v']) for zz in (1, 2, 3, 4)]
        dmax = np.max(np.abs(s['v'] - vfd(s['z'])))
        # the rate-dependent part mu_wall - mu_s against the FD solution's (docs/ngf.md)
        drate = (s['mu_wall'] - MU_S) / (fd['mu_wall'] - MU_S) - 1
        solver, _, h = name.partition(" h=")
        csv.write(f"{solver.strip()},{h or 0},{','.join(repr(float(x)) for x in vz)},{dmax!r},{s['mu_wall']!r},"
                  f"{s['W']!r},{s['g'][0]!r},{drate!r}\n")
        return (f"{name:<22s} " + " ".join(f"{x:7.4f}" for x in vz) +
                f"  {dmax:7.4f}  {s['mu_wall']:.5f}  {100 * drate:+6.1f}%  {s['W']:6.4f}  {s['g'][0]:.4e}")

    hdr = f"{'':22s} {'v(1)':>7s} {'v(2)':>7s} {'v(3)':>7s} {'v(4)':>7s}  {'max|dv|':>7s}  mu_wall  d(mu-mu_s)  W/d     g_wall"
    print(hdr)
    print(row('FD (dz=0.01)', dict(z=fd['z'], v=fd['v'], g=fd['g'], mu_wall=fd['mu_wall'], W=fd['W'])))
    for lab, hd in hs:
        if lab in fe:
            print(row(f'FE ours h={lab}', fe[lab]))
        s = res[lab]
        print(row(f'Galerkin1D h={lab}', s) + f"   res={s['res']:.1e}")
    for q, s in variants.items():
        print(row(f'Galerkin1D {q} h=1', s) + f"   res={s['res']:.1e}")
    # FE vs Galerkin1D nodal differences
    print()
    for lab in fe:
        s = res[lab]
        f = fe[lab]
        dv = np.max(np.abs(np.interp(s['z'], f['z'], f['v']) - s['v']))
        dg = np.max(np.abs(np.interp(s['z'], f['z'], f['g']) - s['g'])) / s['g'][0]
        print(f"h={lab}: max|v_FE - v_G1D| = {dv:.2e} (of v_wall), max|g_FE-g_G1D|/g_wall = {dg:.2e}, "
              f"dmu_wall = {f['mu_wall'] - s['mu_wall']:+.2e}")


if __name__ == '__main__':
    main()
