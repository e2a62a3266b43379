"""Compiled (numba) loop of :mod:`spine_mj.theory.compliant`, with its fold and landing
searches; imported on first use.

``run_compliant`` is ``compliant._run`` start by start (its lanes are independent), on a
Gaussian sum, a gridded spline (the evaluations of :mod:`spine_mj.theory._kernels`) or a ball
on facets (:func:`spine_mj.surfaces._contact_kernel.ball_at`). The numpy loop spends about
0.3 ms of interpreter per iteration; a tip creeping along a crease of a grit's facets takes
~1e5 iterations (measured: 145 of the 198 CPU seconds of comparing two P600 starts).
``tests/theory/test_theory_compliant.py`` checks it against the numpy loop (on facets, bit
for bit).

The compliant reference locates each jump's fold by a golden-section search of ``X(s)``
and its landing by bisection, 60 and 52 surface evaluations of a handful of lanes each.
With numpy that is a few microseconds of arithmetic under a hundred of call overhead: on
the quick plan's sandpaper the searches were 350 of the demo's 825 CPU seconds. Here each
lane runs its whole search in compiled code, the same steps in the same order as
``compliant._fold_along`` and ``compliant._landing_along`` (the numpy reference, which
``tests/theory/test_theory_compliant.py`` checks this against) with the hold of
:func:`spine_mj.theory.compliant.hold_force` written out for one point.
"""

import math

import numpy as np
from numba import njit

from spine_mj.surfaces._contact_kernel import ball_at
from spine_mj.theory._kernels import gauss_eval, grid_eval

__all__ = ["fold_on_facets", "landing_on_facets", "run_compliant"]

#: The golden ratio's conjugate, as ``compliant._fold_along`` forms it.
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@njit(cache=True)
def _hold(fx, fy, mu, tol):
    """:func:`spine_mj.theory.compliant.hold_force` at one point: ``+inf`` self-locked, NaN where
    nothing holds (the same operations in the same order)."""
    m2 = mu * mu
    a = 1.0 + fy * fy - m2 * fx * fx
    b = -2.0 * (1.0 + m2) * fx
    c = fx * fx + fy * fy - m2
    if a < tol and fx > 0:
        return np.inf
    disc = b * b - 4.0 * a * c
    root = math.sqrt(disc) if disc >= 0 else np.nan
    q = -0.5 * (b + (1.0 if b >= 0 else -1.0) * root)
    r1 = q / a if (abs(a) >= tol and q != 0) else np.nan
    r2 = c / q if q != 0 else np.nan
    h1 = r1 if 1.0 + r1 * fx > 0 else np.nan
    h2 = r2 if 1.0 + r2 * fx > 0 else np.nan
    if math.isnan(h1):
        return h2
    if math.isnan(h2):
        return h1
    return max(h1, h2)


@njit(cache=True)
def _hold_along(px, py, vx, vy, s, mu, tol, h, x0, y0, dx, dy, r):
    _, fx, fy = ball_at(px + s * vx, py + s * vy, h, x0, y0, dx, dy, r)
    return _hold(fx, fy, mu, tol)


@njit(cache=True)
def _carriage(px, py, vx, vy, s, c, mu, tol, h, x0, y0, dx, dy, r):
    hx = _hold_along(px, py, vx, vy, s, mu, tol, h, x0, y0, dx, dy, r)
    return px + s * vx + hx / c if math.isfinite(hx) else -np.inf


@njit(cache=True)
def fold_on_facets(px, py, vx, vy, step, c, mu, tol, iterations, h, x0, y0, dx, dy, r):
    """Per lane, ``s`` in ``[0, step]`` maximizing ``X(s) = x(s) + H(s) / c`` and ``X``
    there: ``compliant._fold_along`` (golden section, ``iterations`` steps) on the ball's
    facets (``h, x0, y0, dx, dy, r`` as for :func:`spine_mj.surfaces._contact_kernel.ball_on_facets`)."""
    n = px.size
    s_out = np.empty(n)
    x_out = np.empty(n)
    for k in range(n):
        a, b = 0.0, step[k]
        s1, s2 = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
        args = (px[k], py[k], vx[k], vy[k])
        x1 = _carriage(*args, s1, c, mu, tol, h, x0, y0, dx, dy, r)
        x2 = _carriage(*args, s2, c, mu, tol, h, x0, y0, dx, dy, r)
        for _ in range(iterations):
            if x1 >= x2:  # the maximum lies in [a, s2]
                b = s2
                s_new = b - _GOLDEN * (b - a)
                x_new = _carriage(*args, s_new, c, mu, tol, h, x0, y0, dx, dy, r)
                s2, x2, s1, x1 = s1, x1, s_new, x_new
            else:
                a = s1
                s_new = a + _GOLDEN * (b - a)
                x_new = _carriage(*args, s_new, c, mu, tol, h, x0, y0, dx, dy, r)
                s2, x2, s1, x1 = s_new, x_new, s2, x2
        s = s1 if x1 >= x2 else s2
        at0 = _carriage(*args, 0.0, c, mu, tol, h, x0, y0, dx, dy, r)
        best = max(x1, x2)
        s_out[k] = 0.0 if at0 >= best else s
        x_out[k] = max(at0, best)
    return s_out, x_out


@njit(cache=True)
def landing_on_facets(px, py, vx, vy, step, carriage, c, mu, tol, bisections, h, x0, y0, dx, dy, r):
    """Per lane, the smallest ``s`` in ``(0, step]`` where ``c (X - x(s)) <= H(s)``:
    ``compliant._landing_along`` (``bisections`` halvings) on the ball's facets."""
    n = px.size
    out = np.empty(n)
    for k in range(n):
        lo, hi = 0.0, step[k]
        for _ in range(bisections):
            mid = 0.5 * (lo + hi)
            hx = _hold_along(px[k], py[k], vx[k], vy[k], mid, mu, tol, h, x0, y0, dx, dy, r)
            if not (c * (carriage[k] - (px[k] + mid * vx[k])) <= hx):
                lo = mid
            else:
                hi = mid
        out[k] = hi
    return out


@njit(cache=True)
def _at(surf, x, y):
    """``(f, fx, fy)`` at one point of the surface ``surf`` = ``(kind, g, coef, sp, h, x0, y0,
    dx, dy, r)``: kind 0 a Gaussian sum (``g``), 1 a cubic B-spline grid (``coef``, ``sp``),
    as in :mod:`spine_mj.theory._kernels`; 2 a ball of radius ``r`` on facets (``h`` ...)."""
    kind, g, coef, sp, h, x0, y0, dx, dy, r = surf
    if kind == 0:
        return gauss_eval(g, x, y)
    if kind == 1:
        return grid_eval(coef, sp, x, y)
    return ball_at(x, y, h, x0, y0, dx, dy, r)


@njit(cache=True)
def _hold_on(surf, px, py, vx, vy, s, mu, tol):
    _, fx, fy = _at(surf, px + s * vx, py + s * vy)
    return _hold(fx, fy, mu, tol)


@njit(cache=True)
def _carriage_on(surf, px, py, vx, vy, s, c, mu, tol):
    hx = _hold_on(surf, px, py, vx, vy, s, mu, tol)
    return px + s * vx + hx / c if math.isfinite(hx) else -np.inf


@njit(cache=True)
def _fold_one(surf, px, py, vx, vy, step, c, mu, tol, iterations):
    """``compliant._fold_along`` for one lane on ``surf``: ``(s, X(s))``."""
    a, b = 0.0, step
    s1, s2 = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    x1 = _carriage_on(surf, px, py, vx, vy, s1, c, mu, tol)
    x2 = _carriage_on(surf, px, py, vx, vy, s2, c, mu, tol)
    for _ in range(iterations):
        if x1 >= x2:  # the maximum lies in [a, s2]
            b = s2
            s_new = b - _GOLDEN * (b - a)
            x_new = _carriage_on(surf, px, py, vx, vy, s_new, c, mu, tol)
            s2, x2, s1, x1 = s1, x1, s_new, x_new
        else:
            a = s1
            s_new = a + _GOLDEN * (b - a)
            x_new = _carriage_on(surf, px, py, vx, vy, s_new, c, mu, tol)
            s2, x2, s1, x1 = s_new, x_new, s2, x2
    s = s1 if x1 >= x2 else s2
    at0 = _carriage_on(surf, px, py, vx, vy, 0.0, c, mu, tol)
    best = max(x1, x2)
    return (0.0 if at0 >= best else s), max(at0, best)


@njit(cache=True)
def _landing_one(surf, px, py, vx, vy, step, carriage, c, mu, tol, bisections):
    """``compliant._landing_along`` for one lane on ``surf``."""
    lo, hi = 0.0, step
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        hx = _hold_on(surf, px, py, vx, vy, mid, mu, tol)
        if not (c * (carriage - (px + mid * vx)) <= hx):
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def _direction(fx, fy, force):
    """``compliant._direction`` at one point."""
    s2 = 1.0 + fx * fx + fy * fy
    rn = (force * fx + 1.0) / s2
    tx, ty, tz = force - rn * fx, -rn * fy, -1.0 + rn
    inv = 1.0 / math.sqrt(tx * tx + ty * ty + tz * tz)
    if not math.isfinite(inv):
        inv = np.nan
    return tx * inv, ty * inv


@njit(cache=True)
def _region(fx, hold, fy, mu, tol):
    """``compliant.hold_force``'s region at one point (2 self-lock, 1 engaged, 0 slip)."""
    m2 = mu * mu
    a = 1.0 + fy * fy - m2 * fx * fx
    if a < tol and fx > 0:
        return 2
    return 1 if hold > 0 else 0


@njit(cache=True)
def _grow_rows(a, used, cap):
    b = np.empty((cap,) + a.shape[1:], a.dtype)  # noqa: RUF005 (numba types no starred tuple)
    b[:used] = a[:used]
    return b


@njit(cache=True)
def run_compliant(
    surf,
    xs,
    ys,
    carriage_end,
    domain,
    c,
    mu,
    tol,
    dl,
    max_steps,
    stall_window,
    stall_dist,
    max_halvings,
    kappa_cap,
    iterations,
    bisections,
    probe_at,
):
    """:func:`spine_mj.theory.compliant._run` start by start, compiled: the same steps in the
    same order per start (the lanes of the numpy loop are independent). Returns the
    outcomes and largest kappa per start, the points' offsets, their columns ``x, y, z,
    kappa, carriage, force`` (rows of ``pts``) and states, and the fold table (``fstart``;
    ``fold`` columns ``x, y, carriage, onset, land_x, land_y, land_force, jump``), both in
    start order, then along the path."""
    n = xs.size
    h_min = dl / 2.0**max_halvings
    xmin, xmax, ymin, ymax = domain[0], domain[1], domain[2], domain[3]
    cap = 1024
    pts = np.empty((cap, 6))
    states = np.empty(cap, np.int8)
    pos = 0
    fcap = 64
    fold = np.empty((fcap, 8))
    fstart = np.empty(fcap, np.int64)
    nf = 0
    outcome = np.zeros(n, np.int8)
    max_k = np.full(n, np.nan)
    offsets = np.zeros(n + 1, np.int64)
    for i in range(n):
        x, y = xs[i], ys[i]
        px, py, pvx, pvy = x, y, 0.0, 0.0
        h = dl
        has_prev = False
        X = x
        slipping = False
        pending = 0
        row = -1
        jump = 0.0
        steps = 0
        mk = np.nan
        cx, cy = x, y
        arc = 0.0
        until = stall_window
        while True:
            probe = has_prev and not slipping and pending == 0
            hold_q, qx = 0.0, 0.0
            if probe:
                t = h * (1.0 - probe_at)
                qx, qy = px + t * pvx, py + t * pvy
                _, qfx, qfy = _at(surf, qx, qy)
                hold_q = _hold(qfx, qfy, mu, tol)
            z, fx, fy = _at(surf, x, y)
            hold = _hold(fx, fy, mu, tol)
            region = _region(fx, hold, fy, mu, tol)
            kap = np.nan if region == 0 else hold
            force = c * (X - x)
            slip = not (force <= hold)
            if pending == 1:
                slip = True
            elif pending == 2:
                slip = False
            locked = region == 2
            slip = slip and not locked
            drive = force if slip else hold
            falls = probe and not (x + hold / c >= qx + hold_q / c) and math.isfinite(hold)
            vx, vy = _direction(fx, fy, drive)
            finite = math.isfinite(vx) and math.isfinite(vy)
            reversed_ = has_prev and not locked and finite and (vx * pvx + vy * pvy < 0.0)
            fresh = pending == 0
            if reversed_ and h > h_min and fresh:  # reject: halve the step
                h *= 0.5
                x, y = px + h * pvx, py + h * pvy
                continue
            moving = not locked and fresh and has_prev
            if moving and not slipping and (slip or falls):  # locate the fold along the step
                s, xstar = _fold_one(surf, px, py, pvx, pvy, h, c, mu, tol, iterations)
                X = max(X, xstar)
                x, y = px + s * pvx, py + s * pvy
                pending = 1
                continue
            if moving and slipping and not slip:  # locate the landing
                s = _landing_one(surf, px, py, pvx, pvy, h, X, c, mu, tol, bisections)
                x, y = px + s * pvx, py + s * pvy
                pending = 2
                continue
            # accept the point
            arrived_slipping = slipping and has_prev
            if arrived_slipping:
                jump += math.hypot(x - px, y - py)
            landed = arrived_slipping and not slip
            if landed:
                fold[row, 4], fold[row, 5] = x, y
                fold[row, 6] = c * (X - x)
                fold[row, 7] = jump
                row = -1
            if slip and (pending == 1 or not has_prev):
                if nf == fcap:
                    fcap *= 2
                    fold = _grow_rows(fold, nf, fcap)
                    fstart = _grow_rows(fstart, nf, fcap)
                fstart[nf] = i
                fold[nf, 0], fold[nf, 1], fold[nf, 2], fold[nf, 3] = x, y, X, c * (X - x)
                fold[nf, 4:] = np.nan
                row = nf
                nf += 1
                jump = 0.0
            stick = not slip and (not has_prev or landed)
            if not slip and math.isfinite(hold):
                X = max(X, x + min(hold, kappa_cap) / c)
            stopped = X > carriage_end[i]
            if stopped:
                X = carriage_end[i]
            if pos == cap:
                cap *= 2
                pts = _grow_rows(pts, pos, cap)
                states = _grow_rows(states, pos, cap)
            pts[pos, 0], pts[pos, 1], pts[pos, 2], pts[pos, 3] = x, y, z, kap
            pts[pos, 4], pts[pos, 5] = X, c * (X - x)
            states[pos] = 2 if slip else (0 if stick else 1)
            pos += 1
            if not (kap <= mk) and kap == kap:  # fmax
                mk = kap
            pending = 0
            code = 0
            if stopped:
                code = 6
            elif locked:
                code = 1
            elif hold > kappa_cap:
                code = 5
            elif steps >= max_steps:
                code = 4
            elif not finite:
                code = 3
            if code == 0:  # step on
                hn = h if reversed_ else min(2.0 * h, dl)
                xn, yn = x + hn * vx, y + hn * vy
                if not ((xn >= xmin) and (xn <= xmax) and (yn >= ymin) and (yn <= ymax)):
                    code = 2
                else:
                    px, py, pvx, pvy = x, y, vx, vy
                    h = hn
                    x, y = xn, yn
                    slipping = slip
                    has_prev = True
                    steps += 1
                    arc += hn
                    until -= 1
                    if until == 0:
                        need = stall_dist * arc / (stall_window * dl)
                        stuck = math.hypot(x - cx, y - cy) < need
                        cx, cy = x, y
                        arc = 0.0
                        until = stall_window
                        if stuck:
                            code = 3
            if code != 0:
                outcome[i] = code
                if row >= 0:
                    fold[row, 7] = jump
                break
        max_k[i] = mk
        offsets[i + 1] = pos
    return outcome, max_k, offsets, pts[:pos], states[:pos], fstart[:nf], fold[:nf]
