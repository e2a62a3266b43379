"""Compiled (numba) kernel behind :class:`spine_mj.surfaces.BallOnFacets`; imported on first use.

``ball_on_facets`` does, point by point, what ``BallOnFacets._contact_reference`` does with
arrays: for every vertex, edge (along +x, +y and the diagonal) and triangle of the window
of grid nodes a ball of radius ``r`` centred above ``(x, y)`` can reach, the height its
centre rests at on that feature; the highest wins (the first of equal heights, in the
reference's order: vertices, the three edge kinds, lower then upper triangles, each by row
then column; an edge or triangle whose highest node lies more than ``r`` below the best so
far is skipped, which changes nothing). Its value is the centre height less ``r`` and the
slopes of the contact normal. The streamline traces a few points per call, where the array version's per-call
overhead (about 1 ms) was most of the facet reference's cost. ``tests/surfaces/test_surfaces.py``
checks the two against each other.
"""

import math

import numpy as np
from numba import njit

__all__ = ["ball_at", "ball_on_facets"]


@njit(cache=True)
def _node(h, i, j, x0, y0, dx, dy):
    """Position and height of node ``(i, j)``; ``ok`` False outside the grid."""
    ny, nx = h.shape
    ok = (i >= 0) and (i < nx) and (j >= 0) and (j < ny)
    ic = min(max(i, 0), nx - 1)
    jc = min(max(j, 0), ny - 1)
    return x0 + ic * dx, y0 + jc * dy, h[jc, ic], ok


@njit(cache=True)
def _below(bound, best):
    """Whether a feature whose centre height cannot exceed ``bound`` (its highest node plus
    the radius) is beaten by ``best`` already, with a margin far above the rounding of the
    feature's own height: skipping it changes no result, since a tie never wins."""
    return bound + 1e-9 * (abs(bound) + 1.0) < best


@njit(cache=True)
def ball_on_facets(x, y, h, x0, y0, dx, dy, r):
    """``(f, fx, fy)`` at points ``x``, ``y`` (1-d) of a ball of radius ``r`` on the
    triangulated grid ``h`` (rows y, columns x; origin ``x0, y0``, spacing ``dx, dy``)."""
    n = x.size
    f = np.empty(n)
    fx = np.empty(n)
    fy = np.empty(n)
    for p in range(n):
        f[p], fx[p], fy[p] = ball_at(x[p], y[p], h, x0, y0, dx, dy, r)
    return f, fx, fy


@njit(cache=True)
def ball_at(cx, cy, h, x0, y0, dx, dy, r):
    """``(f, fx, fy)`` of :func:`ball_on_facets` at the one point ``(cx, cy)`` (for compiled
    callers that step along a path, :mod:`spine_mj.theory._compliant_kernel`)."""
    mx = int(math.ceil(2 * r / dx)) + 2
    my = int(math.ceil(2 * r / dy)) + 2
    r2 = r * r
    ib = int(math.floor((cx - r - x0) / dx))
    jb = int(math.floor((cy - r - y0) / dy))
    best = -np.inf
    qx, qy, qz = 0.0, 0.0, 0.0
    for j in range(jb, jb + my):  # vertices: the sphere around each
        for i in range(ib, ib + mx):
            ax, ay, az, aok = _node(h, i, j, x0, y0, dx, dy)
            d2 = (cx - ax) ** 2 + (cy - ay) ** 2
            if aok and d2 <= r2 and not _below(az + r, best):
                z = az + math.sqrt(r2 - d2)
                if z > best:
                    best, qx, qy, qz = z, ax, ay, az
    for si, sj in ((1, 0), (0, 1), (1, 1)):  # edges: the cylinder around each
        for j in range(jb, jb + my):
            for i in range(ib, ib + mx):
                ax, ay, az, aok = _node(h, i, j, x0, y0, dx, dy)
                bx, by, bz, bok = _node(h, i + si, j + sj, x0, y0, dx, dy)
                if not (aok and bok) or _below(max(az, bz) + r, best):
                    continue
                ex, ey, ez = bx - ax, by - ay, bz - az
                ll = ex * ex + ey * ey + ez * ez
                wd = (cx - ax) * ex + (cy - ay) * ey
                alpha = (ex * ex + ey * ey) / ll
                beta = wd * ez / ll
                gamma = (cx - ax) ** 2 + (cy - ay) ** 2 - wd * wd / ll - r2
                disc = beta * beta - alpha * gamma
                if not (disc >= 0):
                    continue
                e = (beta + math.sqrt(disc)) / alpha
                t = (wd + e * ez) / ll
                if math.isfinite(e) and t >= 0 and t <= 1:
                    z = az + e
                    if z > best:
                        best, qx, qy, qz = z, ax + t * ex, ay + t * ey, az + t * ez
    for lower in (True, False):  # faces: the plane lifted along its normal
        for j in range(jb, jb + my):
            for i in range(ib, ib + mx):
                ax, ay, az, aok = _node(h, i, j, x0, y0, dx, dy)
                _, _, h11, ok11 = _node(h, i + 1, j + 1, x0, y0, dx, dy)
                _, _, h10, ok10 = _node(h, i + 1, j, x0, y0, dx, dy)
                _, _, h01, ok01 = _node(h, i, j + 1, x0, y0, dx, dy)
                if not (aok and ok11 and (ok10 if lower else ok01)):
                    continue
                if _below(max(az, h11, h10 if lower else h01) + r, best):
                    continue
                gx = ((h10 - az) if lower else (h11 - h01)) / dx
                gy = ((h11 - h10) if lower else (h01 - az)) / dy
                norm = math.sqrt(1.0 + gx * gx + gy * gy)
                px, py = cx + r * gx / norm, cy + r * gy / norm
                s, t = (px - ax) / dx, (py - ay) / dy
                inside = (t >= 0 and t <= s and s <= 1) if lower else (s >= 0 and s <= t and t <= 1)
                if inside:
                    pz = az + gx * (px - ax) + gy * (py - ay)
                    z = pz + r / norm
                    if z > best:
                        best, qx, qy, qz = z, px, py, pz
    nzc = best - qz
    return best - r, -(cx - qx) / nzc, -(cy - qy) / nzc
