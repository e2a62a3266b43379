"""Compiled (numba) fold and landing searches of :mod:`spine_mj.theory.compliant` on the tip's
facets (:class:`spine_mj.surfaces.BallOnFacets`); imported on first use.

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

__all__ = ["fold_on_facets", "landing_on_facets"]

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
