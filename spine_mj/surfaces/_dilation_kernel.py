"""Compiled (numba) kernel behind :mod:`spine_mj.surfaces.dilation`; imported on first use.

Grey-scale dilation by a ball of radius R on a grid of spacing (dx, dy), split by rows of
the footprint: the ball's row at offset ``v = k dy`` is a half-disc of radius
``r_k = sqrt(R^2 - v^2)``, so

    g(x, y) = max_k D_{r_k}[f](x, y + k dy),    D_r[f](x) = max_{|u| <= r} f(x + u) + sqrt(r^2 - u^2)

and each 1-D dilation ``D_r`` of a grid line is the upper envelope of the half-circles of
radius ``r`` centred on its samples. Two translates of the same concave half-circle cross
at most once (the left one above on the left), so the envelope is built in one pass with a
stack of candidates and their switch points (Felzenszwalb and Huttenlocher's lower-envelope
scheme), O(line) time and memory. Total: O(grid x rows of the footprint) time, three grid
arrays of memory, whatever the footprint's area.
"""

import math

import numpy as np
from numba import njit

__all__ = ["ball_rows", "footprint_rows"]


@njit(cache=True)
def _switch(xa, fa, xb, fb, r):
    """Abscissa from which the half-circle centred at (xb, fb) is at least the one at
    (xa, fa), xa < xb, both of radius r (outside its base a half-circle is -inf)."""
    d = xb - xa
    e = fb - fa
    if d > 2.0 * r:  # bases disjoint: anywhere in the gap between them
        return 0.5 * (xa + xb)
    l2 = d * d + e * e
    q = r * r - 0.25 * l2
    if q >= 0.0:
        t = math.sqrt(q)
        ln = math.sqrt(l2)
        if 2.0 * t * d >= abs(e) * ln:  # the circles' upper crossing lies on both halves
            x = 0.5 * (xa + xb) - t * e / ln
            return min(max(x, xb - r), xa + r)
    # no crossing over the common base: the higher one dominates all of it
    return xb - r if e > 0.0 else xa + r


@njit(cache=True)
def _line(f, n, dx, r, out, v, z):
    """``out[i] = max_j f[j] + sqrt(r^2 - ((i - j) dx)^2)`` over ``|i - j| dx <= r``, for
    the first ``n`` entries of ``f``; ``v``, ``z`` are work arrays of n and n + 1."""
    k = 0
    v[0] = 0
    z[0] = -np.inf
    z[1] = np.inf
    for q in range(1, n):
        s = _switch(v[k] * dx, f[v[k]], q * dx, f[q], r)
        while s <= z[k]:
            k -= 1
            s = _switch(v[k] * dx, f[v[k]], q * dx, f[q], r)
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = np.inf
    k = 0
    r2 = r * r
    for i in range(n):
        x = i * dx
        while z[k + 1] <= x:
            k += 1
        u = (i - v[k]) * dx
        out[i] = f[v[k]] + math.sqrt(max(r2 - u * u, 0.0))


def footprint_rows(radius, dy, ny, wrap):
    """The footprint's rows ``k = 0 .. n - 1`` (each ``+-k dy``) that :func:`ball_rows` visits."""
    kmax = int(math.floor(radius / dy))
    return (min(kmax, ny // 2) if wrap else min(kmax, ny - 1)) + 1


@njit(cache=True)
def ball_rows(heights, radius, dx, dy, wrap, k0, k1, out):
    """``out = max(out, max_{k0 <= |k| < k1} D_{r_k}[f](x, y + k dy))``: the footprint's
    rows ``k0 .. k1 - 1`` of ``max_{u^2 + v^2 <= R^2} f(x + u, y + v) + sqrt(R^2 - u^2 -
    v^2)`` at every sample, accumulated into ``out``; beyond the edges the grid wraps
    (``wrap``) or repeats its edge values (the nearest copy of a sample always dominates
    the farther ones, so only in-range samples, or one period's, are visited)."""
    ny, nx = heights.shape
    pmax = min(int(math.floor(radius / dx)), nx // 2) if wrap else 0
    m = nx + 2 * pmax
    line = np.empty(m)
    res = np.empty(m)
    v = np.empty(m, dtype=np.int64)
    z = np.empty(m + 1)
    rows = np.empty((ny, nx))
    for k in range(k0, k1):
        r = math.sqrt(max(radius * radius - (k * dy) ** 2, 0.0))
        for s in range(ny):
            for i in range(m):
                line[i] = heights[s, (i - pmax) % nx]
            _line(line, m, dx, r, res, v, z)
            for i in range(nx):
                rows[s, i] = res[i + pmax]
        for t in range(ny):
            for sign in (1, -1):
                if sign < 0 and k == 0:
                    break
                s = t + sign * k
                if wrap:
                    s %= ny
                elif s < 0 or s >= ny:
                    continue
                for i in range(nx):
                    if rows[s, i] > out[t, i]:
                        out[t, i] = rows[s, i]
