#!/usr/bin/python3
"""Research prototype, not part of granflow: a primal-dual interior point on the *split* form of
the discrete DP(mu, 0) problem (35) of Daviet & Bertails-Descoubes 2016 (2D, blocks of 3), run on a
cone problem dumped by `granflow run CASE --set "Solver/Dump cone problem=FILE"`. It reproduces
the measurement of docs/solvers.md ("the split form", session 23); the residual is the
Fischer-Burmeister one of the replay in the paper's units (no gamma_scale).

    scripts/dp_split_interior_point.py FILE [--tolerance T] [--max-iterations N] [--delta D]
        [--separate-steps] [--from-velocity] [--probe K ...]

The law of Corollary 1, lambda in K_mu, gamma_hat = gamma + mu |gamma_T| e_N in K_{1/mu},
lambda . gamma_hat = 0, is the same as the two complementarities
    gamma_N >= 0  _|_  lambda_N >= 0                                   (unilateral incompressibility)
    (t, gamma_T) in K  _|_  (mu lambda_N, lambda_T) in K               (maximal dissipation)
with an auxiliary t (t = |gamma_T| wherever lambda != 0): gamma_hat in K_{1/mu} <=> gamma_N >= 0,
and lambda . gamma_hat = lambda_N gamma_N + (mu lambda_N |gamma_T| + lambda_T . gamma_T), a sum
of two terms >= 0. The central path of this form is smooth: no derivative of |gamma_T|.
Each iteration is a Mehrotra predictor-corrector step with Nesterov-Todd scaling of both pairs;
the Newton system is reduced to the velocity, (A + H^T M H) du = r, with M a 3 x 3 block per point
(unsymmetric: the friction cone's radius mu lambda_N is the incompressibility multiplier).
"""
import argparse
import struct
import time
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def read_dump(path):
    f = open(path, 'rb').read()
    pos = [0]

    def u64(n=1):
        v = struct.unpack_from('<%dQ' % n, f, pos[0]); pos[0] += 8 * n; return v

    def vec(dt, size):
        (n,) = u64(); a = np.frombuffer(f, dtype=dt, count=n, offset=pos[0]).copy()
        pos[0] += size * n; return a

    def mat():
        nr, nc = u64(2)
        rs = vec(np.int32, 4); col = vec(np.int32, 4); val = vec(np.float64, 8)
        return sp.csr_matrix((val, col, rs), shape=(nr, nc))

    magic, bs = u64(2)
    if magic != 0x67666c6f77636f6e or bs != 3:
        raise SystemExit(f"{path}: not a granflow cone problem dump of a 2D problem")
    A = mat(); H = mat(); l = vec(np.float64, 8); k = vec(np.float64, 8)
    mu = vec(np.float64, 8); Bi = vec(np.float64, 8)
    gs = vec(np.float64, 8) if pos[0] < len(f) else np.ones_like(mu)
    return A, H, l, k, mu, Bi, gs


def fb_residual(lam, gam, mu):
    """max_i |f_FB| of drucker_prager.cc (x = (mu lam_N, lam_T), y = (gamma_hat_N, mu gamma_T))."""
    L = lam.reshape(-1, 3); G = gam.reshape(-1, 3)
    gT = np.linalg.norm(G[:, 1:], axis=1)
    x = L.copy(); x[:, 0] *= mu
    y = G.copy(); y[:, 0] = G[:, 0] + mu * gT; y[:, 1:] *= mu[:, None]
    xx = (x * x).sum(1); yy = (y * y).sum(1)
    z0 = xx + yy
    zT = 2 * (x[:, :1] * x[:, 1:] + y[:, :1] * y[:, 1:])
    dx = x[:, 0]**2 - (x[:, 1:]**2).sum(1); dy = y[:, 0]**2 - (y[:, 1:]**2).sum(1)
    xTyT = (x[:, 1:] * y[:, 1:]).sum(1)
    det = dx * dx + dy * dy + 2 * np.maximum(0, xx * yy - 4 * x[:, 0] * y[:, 0] * xTyT)
    l2 = z0 + np.linalg.norm(zT, axis=1)
    s2 = np.sqrt(l2); s1 = np.where(l2 > 0, np.sqrt(det / np.where(l2 > 0, l2, 1)), 0)
    ss = np.where(s1 + s2 > 0, s1 + s2, 1)
    f0 = x[:, 0] + y[:, 0] - 0.5 * (s1 + s2)
    fT = x[:, 1:] + y[:, 1:] - zT / ss[:, None]
    return np.sqrt(f0**2 + (fT**2).sum(1)).max()


def soc_det(x):
    return x[:, 0]**2 - (x[:, 1:]**2).sum(1)


def nt_scaling(x, y):
    """CVXOPT's Nesterov-Todd scaling of SOC pairs: W x = W^-1 y = v. Returns (eta, wb)."""
    dx = np.sqrt(soc_det(x)); dy = np.sqrt(soc_det(y))
    xn = x / dx[:, None]; yn = y / dy[:, None]
    g = np.sqrt(0.5 * (1 + (xn * yn).sum(1)))
    Jx = xn.copy(); Jx[:, 1:] *= -1
    wb = (yn + Jx) / (2 * g[:, None])
    eta = np.sqrt(dy / dx)
    return eta, wb


def W_apply(eta, wb, z, inverse=False):
    w0 = wb[:, 0]; w1 = wb[:, 1:]
    s = -1 if inverse else 1
    w1z1 = (w1 * z[:, 1:]).sum(1)
    r0 = w0 * z[:, 0] + s * w1z1
    r1 = s * w1 * z[:, :1] + z[:, 1:] + w1 * (w1z1 / (1 + w0))[:, None]
    r = np.column_stack([r0, r1])
    return r / eta[:, None] if inverse else r * eta[:, None]


def W_matrix(eta, wb):
    n = wb.shape[0]
    M = np.zeros((n, 3, 3))
    M[:, 0, 0] = wb[:, 0]; M[:, 0, 1:] = wb[:, 1:]; M[:, 1:, 0] = wb[:, 1:]
    M[:, 1:, 1:] = np.eye(2)[None] + wb[:, 1:, None] * wb[:, None, 1:] / (1 + wb[:, 0])[:, None, None]
    return M * eta[:, None, None]


def jordan(a, b):
    return np.column_stack([(a * b).sum(1), a[:, :1] * b[:, 1:] + b[:, :1] * a[:, 1:]])


def arrow_solve(v, r):
    det = soc_det(v)
    z0 = (v[:, 0] * r[:, 0] - (v[:, 1:] * r[:, 1:]).sum(1)) / det
    z1 = (r[:, 1:] - z0[:, None] * v[:, 1:]) / v[:, :1]
    return np.column_stack([z0, z1])


def soc_max_step(x, dx):
    """Largest alpha in [0, inf) with x + alpha dx in K (x interior), per point."""
    a = soc_det(dx); b = 2 * (x[:, 0] * dx[:, 0] - (x[:, 1:] * dx[:, 1:]).sum(1)); c = soc_det(x)
    alpha = np.full(len(x), np.inf)
    # det(x + t dx) = a t^2 + b t + c >= 0 and x0 + t dx0 >= 0
    disc = b * b - 4 * a * c
    with np.errstate(all='ignore'):
        sq = np.sqrt(np.maximum(disc, 0))
        r1 = (-b - sq) / (2 * a); r2 = (-b + sq) / (2 * a)
    for r in (r1, r2):
        ok = np.isfinite(r) & (r > 0) & (disc >= 0)
        alpha = np.where(ok, np.minimum(alpha, r), alpha)
    lin = (np.abs(a) < 1e-300) & (b < 0)
    alpha = np.where(lin, np.minimum(alpha, -c / np.where(lin, b, -1)), alpha)
    neg0 = dx[:, 0] < 0
    alpha = np.where(neg0, np.minimum(alpha, -x[:, 0] / np.where(neg0, dx[:, 0], -1)), alpha)
    return alpha


class Cancellation(RuntimeError):
    pass


def stop_cancellation(e, it, res, t0):
    print(f"stopped: the points' own eliminations of the stress step disagree by {e.args[0]:.1e} "
          f"of its size")
    return it, res, time.time() - t0


def least_singular_value(lu, n, rng, iterations=30, symmetric=False):
    """Least singular value of the factorised matrix K: inverse iteration on K^T K."""
    z = rng.normal(size=n)
    z /= np.linalg.norm(z)
    for _ in range(iterations):
        z = lu.solve(z) if symmetric else lu.solve(lu.solve(z, trans='T'))
        norm = np.linalg.norm(z)
        z /= norm
    return 1 / norm if symmetric else 1 / np.sqrt(norm)


def central_stress(g, mu, tau):
    """The point of the split form's central path whose slacks are gamma itself (gamma_N > 0):
    lambda_N gamma_N = tau and (t, gamma_T) o (mu lambda_N, lambda_T) = tau e in closed form."""
    q = g[:, 0] / mu
    t = 0.5 * (q + np.sqrt(q * q + 4 * (g[:, 1:]**2).sum(1)))
    lam = np.column_stack([tau / g[:, 0], np.zeros((len(g), 2))])
    lam[:, 1:] = -mu[:, None] * lam[:, :1] * g[:, 1:] / t[:, None]
    return t, lam


def solve(path, tol=1e-6, max_it=200, verbose=True, start_scale=1.0, exponent=3, frac=0.99,
          delta=0.0, separate=False, probe=(), from_velocity=False):
    A, H, l, k, mu, Bi, gs = read_dump(path)
    n_p = len(mu)
    HN = H[0::3]; HT = H[np.sort(np.r_[1:H.shape[0]:3, 2:H.shape[0]:3])]
    kN = k[0::3]; kT = k.reshape(-1, 3)[:, 1:]
    t0 = time.time()
    u = np.zeros(A.shape[0])
    lam = np.zeros((n_p, 3)); lam[:, 0] = start_scale
    a = np.ones(n_p)        # slack for gamma_N
    x = np.zeros((n_p, 3)); x[:, 0] = 1.   # (t, sT), sT slack for gamma_T
    if from_velocity:  # a strictly dilating start, gamma_N = 1e-2 (H_N has full row rank)
        u = spla.lsqr(HN, np.full(n_p, 1e-2) - kN, atol=1e-14, btol=1e-14, iter_lim=50000)[0]
        g = (H @ u + k).reshape(-1, 3)
        t, lam = central_stress(g, mu, 1e-2 * start_scale)
        a[:] = g[:, 0]
        x[:] = np.column_stack([t, g[:, 1:]])
    nu = 2 * n_p  # two pairs per point, each of degree 1: a b = x . y = tau on the central path
    Ht = H.T.tocsr()
    Alu = spla.splu(A.tocsc())
    if probe:
        A_least = least_singular_value(Alu, A.shape[0], np.random.default_rng(2), symmetric=True)
    for it in range(max_it + 1):
        # the residual of (35) at lambda: u from the momentum balance, as the replay measures
        gam = H @ Alu.solve(Ht @ lam.ravel() + l) + k
        res = fb_residual(lam.ravel(), gam, mu)
        b = lam[:, 0]
        y = np.column_stack([mu * lam[:, 0], lam[:, 1:]])
        rm = A @ u - Ht @ lam.ravel() - l
        rN = a - (HN @ u + kN)
        rT = x[:, 1:] - (HT @ u).reshape(-1, 2) - kT
        gap = (a * b).sum() + (x * y).sum()
        tau = gap / nu
        if verbose:
            print(f"{it:4d} fb {res:.3e} gap/nu {tau:.3e} |rm| {np.abs(rm).max():.2e} "
                  f"|rN| {np.abs(rN).max():.2e} |rT| {np.abs(rT).max():.2e} t {time.time()-t0:.1f}s",
                  flush=True)
        if res <= tol or it == max_it:
            return it, res, time.time() - t0
        eta, wb = nt_scaling(x, y)
        v = W_apply(eta, wb, x)
        Wm = W_matrix(eta, wb)
        G = np.einsum('nij,njk->nik', Wm, Wm)
        c = b / a
        G00 = G[:, 0, 0]; G0T = G[:, 0, 1:]; GTT = G[:, 1:, 1:]
        S = GTT - G0T[:, :, None] * G0T[:, None, :] / G00[:, None, None]
        # M (3x3 per point, rows/cols N, T1, T2): dlam = -M gamma(du) + f
        Mb = np.zeros((n_p, 3, 3))
        Mb[:, 0, 0] = c
        Mb[:, 1:, 0] = mu[:, None] * c[:, None] * G0T / G00[:, None]
        Mb[:, 1:, 1:] = S
        rows = np.repeat(np.arange(3 * n_p).reshape(-1, 3), 3, axis=1).ravel()
        cols = np.tile(np.arange(3 * n_p).reshape(-1, 3), (1, 3)).ravel()
        # proximal regularisation of the stress: the slack relations gain + delta dlam, so that
        # dlam = -(I + delta M)^-1 M dgamma + (I + delta M)^-1 f
        Pinv = np.linalg.inv(np.eye(3)[None] + delta * Mb)
        Md = np.einsum('nij,njk->nik', Pinv, Mb)
        Mmat = sp.csr_matrix((Md.ravel(), (rows, cols)), shape=(3 * n_p, 3 * n_p))
        K = (A + Ht @ Mmat @ H).tocsc()
        try:
            lu = spla.splu(K, permc_spec='COLAMD')
        except RuntimeError as e:  # SuperLU: "Factor is exactly singular"
            print(f"stopped: the Newton matrix could not be factorised ({e})")
            return it, res, time.time() - t0
        if it in probe:
            least = least_singular_value(lu, K.shape[0], np.random.default_rng(1))
            print(f"      reduced matrix: least singular value {least:.3e}, "
                  f"{least / A_least:.1f} times A's least eigenvalue ({A_least:.3e})")

        def direction(rc1, rc2):
            q = arrow_solve(v, rc2)
            Wq = W_apply(eta, wb, q)
            fN = rc1 / a + c * rN
            fT = (Wq[:, 1:] - G0T / G00[:, None] * (Wq[:, :1] - (mu * rc1 / a + mu * c * rN)[:, None])
                  + np.einsum('nij,nj->ni', S, rT))
            f = np.einsum('nij,nj->ni', Pinv, np.column_stack([fN, fT]))
            du = lu.solve(-rm + Ht @ f.ravel())
            dg = (H @ du).reshape(-1, 3)
            dl = -np.einsum('nij,nj->ni', Md, dg) + f
            da = dg[:, 0] - rN + delta * dl[:, 0]
            dsT = dg[:, 1:] - rT + delta * dl[:, 1:]
            dlamN = rc1 / a - c * da
            dt = (Wq[:, 0] - (G0T * dsT).sum(1) - mu * dlamN) / G00
            dx = np.column_stack([dt, dsT])
            dy = Wq - np.einsum('nij,nj->ni', G, dx)
            dlam = np.column_stack([dlamN, dy[:, 1:]])
            # two eliminations of dlam from the same dgamma (the global solve does not enter):
            # an error in the algebra above would make them differ at O(1); rounding in the
            # points' own 3 x 3 algebra, where W^2 is huge, makes them differ far less
            if not np.allclose(dlam, dl, rtol=1e-3, atol=1e-3 * np.abs(dl).max()):
                raise Cancellation(np.abs(dlam - dl).max() / np.abs(dl).max())
            return du, da, dlam, dx, dy

        def step_len(da, dlam, dx, dy, report=False):
            if report:
                parts = {}
                m = da < 0
                parts['a'] = (-a[m] / da[m]).min() if m.any() else np.inf
                m = dlam[:, 0] < 0
                parts['b'] = (-b[m] / dlam[m, 0]).min() if m.any() else np.inf
                sx = soc_max_step(x, dx); sy = soc_max_step(y, dy)
                parts['x'] = sx.min(); parts['y'] = sy.min()
                which = min(parts, key=parts.get)
                i = {'x': np.argmin(sx), 'y': np.argmin(sy)}.get(which, None)
                if which == 'a': i = np.argmin(np.where(da < 0, -a / np.where(da < 0, da, -1), np.inf))
                if which == 'b': i = np.argmin(np.where(dlam[:, 0] < 0, -b / np.where(dlam[:, 0] < 0, dlam[:, 0], -1), np.inf))
                print(f"      block {which} {parts[which]:.3e} pt {i}: a {a[i]:.2e} lam {lam[i]} x {x[i]} "
                      f"|xT|/x0 {np.linalg.norm(x[i,1:])/x[i,0]:.6f} |lamT|/mu lamN {np.linalg.norm(lam[i,1:])/mu[i]/lam[i,0]:.6f}"
                      f" dx {dx[i]} dlam {dlam[i]} da {da[i]:.2e}")
            al = np.inf
            m = da < 0
            if m.any(): al = min(al, (-a[m] / da[m]).min())
            m = dlam[:, 0] < 0
            if m.any(): al = min(al, (-b[m] / dlam[m, 0]).min())
            al = min(al, soc_max_step(x, dx).min(), soc_max_step(y, dy).min())
            return al

        # predictor
        rc1 = -a * b
        rc2 = -jordan(v, v)
        try:
            du, da, dlam, dx, dy = direction(rc1, rc2)
        except Cancellation as e:
            return stop_cancellation(e, it, res, t0)
        aa = min(1., step_len(da, dlam, dx, dy))
        gap_aff = ((a + aa * da) * (b + aa * dlam[:, 0])).sum() + ((x + aa * dx) * (y + aa * dy)).sum()
        sigma = (gap_aff / gap)**exponent
        # corrector
        Wdx = W_apply(eta, wb, dx); Widy = W_apply(eta, wb, dy, inverse=True)
        rc1 = sigma * tau - a * b - da * dlam[:, 0]
        e = np.zeros((n_p, 3)); e[:, 0] = 1
        rc2 = sigma * tau * e - jordan(v, v) - jordan(Wdx, Widy)
        try:
            du, da, dlam, dx, dy = direction(rc1, rc2)
        except Cancellation as e:
            return stop_cancellation(e, it, res, t0)
        al = min(1., frac * step_len(da, dlam, dx, dy, report=verbose))
        if verbose:
            print(f"      aff {aa:.3f} sigma {sigma:.2e} step {al:.3f}")
        if from_velocity:
            # the velocity's step only, kept where gamma_N > 0 at every point; then the slacks
            # are gamma(u) and the stress is the central path's at the reduced tau
            g = (H @ u + k).reshape(-1, 3)
            dgN = HN @ du
            neg = dgN < 0
            bound = np.min(-g[neg, 0] / dgN[neg]) if neg.any() else np.inf
            al = min(1., frac * bound)
            u += al * du
            g = (H @ u + k).reshape(-1, 3)
            per_pair = gap / (2 * n_p)  # a b = x . y = tau at such a point
            t, lam[:] = central_stress(g, mu, per_pair * (1 - al * (1 - sigma)))
            a[:] = g[:, 0]
            x[:] = np.column_stack([t, g[:, 1:]])
            if verbose:
                print(f"      velocity step {al:.3f} (gamma_N > 0 allows {bound:.3f})")
        elif separate:
            aP = np.inf
            m = da < 0
            if m.any(): aP = min(aP, (-a[m] / da[m]).min())
            aP = min(1., frac * min(aP, soc_max_step(x, dx).min()))
            aD = np.inf
            m = dlam[:, 0] < 0
            if m.any(): aD = min(aD, (-b[m] / dlam[m, 0]).min())
            aD = min(1., frac * min(aD, soc_max_step(y, dy).min()))
            if verbose: print(f"      primal {aP:.3f} dual {aD:.3f}")
            u += aP * du; a += aP * da; x += aP * dx; lam += aD * dlam
        else:
            u += al * du; a += al * da; lam += al * dlam; x += al * dx


if __name__ == '__main__':
    cli = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    cli.add_argument('dump', help='cone problem dumped by granflow run (2D)')
    cli.add_argument('--tolerance', type=float, default=1e-6)
    cli.add_argument('--max-iterations', type=int, default=200)
    cli.add_argument('--delta', type=float, default=0.,
                     help='proximal regularisation of the stress (0: none)')
    cli.add_argument('--separate-steps', action='store_true',
                     help='separate step lengths for (u, gamma_N, t, gamma_T) and lambda')
    cli.add_argument('--from-velocity', action='store_true',
                     help='step the velocity only, from a strictly dilating start, and put the '
                          'slacks and the stress on the central path after each step')
    cli.add_argument('--probe', type=int, nargs='*', default=[],
                     help='iterations at which to estimate the reduced matrix\'s least eigenvalue')
    o = cli.parse_args()
    iterations, residual, seconds = solve(o.dump, tol=o.tolerance, max_it=o.max_iterations,
                                          delta=o.delta, separate=o.separate_steps,
                                          probe=set(o.probe), from_velocity=o.from_velocity)
    print(f"{'converged' if residual <= o.tolerance else 'not converged'}: residual {residual:.3e} "
          f"after {iterations} iterations, {seconds:.1f} s")
