"""Compiled (numba) kernels behind :mod:`spine_mj.streamline`; imported on first use.

``run_trajectories`` steps many starts one after the other on one core. ``kind`` 0
evaluates a Gaussian sum (``g`` rows: amplitude, centre x, centre y, 1/sigma_x,
1/sigma_y), ``kind`` 1 a cubic B-spline grid (``coef`` and ``sp`` = offset, x0, dx, nx,
y0, dy, ny, periodic). The physics mirrors :func:`spine_mj.engagement.kappa` and
:func:`spine_mj.engagement.slip_direction`; ``tests/test_streamline.py`` checks this
kernel against the pure-numpy reference in :mod:`spine_mj.streamline`.
"""

import math

import numpy as np
from numba import njit

__all__ = ["run_trajectories"]

# no "nnan"/"ninf": the kernel relies on NaN and inf semantics
_FM = {"contract", "arcp", "nsz", "reassoc"}
_GAUSS_CUTOFF = 64.0  # skip Gaussians beyond 8 sigma (relative contribution < 1e-13)


@njit(cache=True, fastmath=_FM)
def gauss_eval(g, x, y):
    f = 0.0
    fx = 0.0
    fy = 0.0
    for m in range(g.shape[1]):
        isx = g[3, m]
        isy = g[4, m]
        u = (x - g[1, m]) * isx
        v = (y - g[2, m]) * isy
        r2 = u * u + v * v
        if r2 > _GAUSS_CUTOFF:
            continue
        e = g[0, m] * math.exp(-0.5 * r2)
        f += e
        fx -= e * u * isx
        fy -= e * v * isy
    return f, fx, fy


@njit(cache=True, fastmath=_FM)
def bspl(t):
    s = 1.0 - t
    t2 = t * t
    t3 = t2 * t
    return (s * s * s / 6.0, (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0, t3 / 6.0,
            -0.5 * s * s, 1.5 * t2 - 2.0 * t, -1.5 * t2 + t + 0.5, 0.5 * t2)


@njit(cache=True, fastmath=_FM)
def cell(c, c0, d, n, periodic):
    u = (c - c0) / d
    if periodic:
        u = u - math.floor(u / n) * n
        i = int(math.floor(u))
        if i > n - 1:
            i = n - 1
    else:
        i = int(math.floor(u))
        if i < 0:
            i = 0
        if i > n - 2:
            i = n - 2
    return i, u - i


@njit(cache=True, fastmath=_FM)
def grid_eval(coef, sp, x, y):
    off = int(sp[0])
    periodic = sp[7] != 0.0
    i, tx = cell(x, sp[1], sp[2], int(sp[3]), periodic)
    j, ty = cell(y, sp[4], sp[5], int(sp[6]), periodic)
    wx = bspl(tx)
    wy = bspl(ty)
    f = 0.0
    fx = 0.0
    fy = 0.0
    for b in range(4):
        row = j - 1 + b + off
        r0 = 0.0
        r1 = 0.0
        for a in range(4):
            c = coef[row, i - 1 + a + off]
            r0 += wx[a] * c
            r1 += wx[4 + a] * c
        f += wy[b] * r0
        fx += wy[b] * r1
        fy += wy[4 + b] * r0
    return f, fx / sp[2], fy / sp[5]


@njit(cache=True, fastmath=_FM)
def kappa_point(fx, fy, mu, tol):
    m2 = mu * mu
    a = 1.0 + fy * fy - m2 * fx * fx
    if a < tol and fx > 0.0:
        return math.inf, 2
    b = -2.0 * (1.0 + m2) * fx
    c = fx * fx + fy * fy - m2
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.nan, 0
    sq = math.sqrt(disc)
    q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
    best = math.nan
    if q != 0.0:
        if abs(a) >= tol:
            r1 = q / a
            if r1 > 0.0 and 1.0 + r1 * fx > 0.0:
                best = r1
        r2 = c / q
        if r2 > 0.0 and 1.0 + r2 * fx > 0.0 and not (r2 <= best):
            best = r2
    if best == best:
        return best, 1
    return math.nan, 0


@njit(cache=True, fastmath=_FM)
def run_trajectories(kind, g, coef, sp, bounds, xs, ys, ideal, mu, dl, tol, max_steps, stall_window,
        stall_dist, store):
    n = xs.size
    outcome = np.zeros(n, np.int8)
    n_steps = np.zeros(n, np.int64)
    max_k = np.full(n, np.nan)
    ex = np.empty(n)
    ey = np.empty(n)
    ez = np.empty(n)
    offsets = np.zeros(n + 1, np.int64)
    cap = 1024 if store else 1
    bx = np.empty(cap)
    by = np.empty(cap)
    bz = np.empty(cap)
    bk = np.empty(cap)
    br = np.empty(cap, np.int8)
    pos = 0
    xmin, xmax, ymin, ymax = bounds[0], bounds[1], bounds[2], bounds[3]
    for i in range(n):
        x = xs[i]
        y = ys[i]
        cx = x
        cy = y
        step = 0
        until_check = stall_window
        mk = math.nan
        while True:
            if kind == 0:
                f, fx, fy = gauss_eval(g, x, y)
            else:
                f, fx, fy = grid_eval(coef, sp, x, y)
            k, reg = kappa_point(fx, fy, mu, tol)
            if store:
                if pos >= cap:
                    cap *= 2
                    nbx = np.empty(cap)
                    nbx[:pos] = bx[:pos]
                    bx = nbx
                    nby = np.empty(cap)
                    nby[:pos] = by[:pos]
                    by = nby
                    nbz = np.empty(cap)
                    nbz[:pos] = bz[:pos]
                    bz = nbz
                    nbk = np.empty(cap)
                    nbk[:pos] = bk[:pos]
                    bk = nbk
                    nbr = np.empty(cap, np.int8)
                    nbr[:pos] = br[:pos]
                    br = nbr
                bx[pos] = x
                by[pos] = y
                bz[pos] = f
                bk[pos] = k
                br[pos] = reg
                pos += 1
            if not (k <= mk):
                if k == k:
                    mk = k
            if reg == 2:
                outcome[i] = 1
                break
            if step >= max_steps:
                outcome[i] = 4
                break
            if ideal:
                vx = 1.0 / math.sqrt(1.0 + fx * fx)
                vy = 0.0
            else:
                kk = k if reg == 1 else 0.0
                rn = (kk * fx + 1.0) / (1.0 + fx * fx + fy * fy)
                tx = kk - rn * fx
                ty = -rn * fy
                tz = -1.0 + rn
                tn2 = tx * tx + ty * ty + tz * tz
                if not (tn2 > 0.0):
                    outcome[i] = 3
                    break
                inv = 1.0 / math.sqrt(tn2)
                vx = tx * inv
                vy = ty * inv
            xn = x + dl * vx
            yn = y + dl * vy
            if not (xn >= xmin and xn <= xmax and yn >= ymin and yn <= ymax):
                outcome[i] = 2
                break
            x = xn
            y = yn
            step += 1
            until_check -= 1
            if until_check == 0:
                until_check = stall_window
                dxs = x - cx
                dys = y - cy
                if dxs * dxs + dys * dys < stall_dist * stall_dist:
                    outcome[i] = 3
                    break
                cx = x
                cy = y
        n_steps[i] = step
        max_k[i] = mk
        ex[i] = x
        ey[i] = y
        ez[i] = f
        offsets[i + 1] = pos
    return (outcome, n_steps, max_k, ex, ey, ez, offsets, bx[:pos], by[:pos], bz[:pos],
            bk[:pos], br[:pos])

