"""Compiled walk of :mod:`spine_mj.theory.avalanches`: the slips of a tip driven
quasistatically through a spring over a piecewise-linear landscape.

``g[i] = F(u_i) + k u_i`` on a uniform grid of spacing ``du``; the drive's level is
``L = k X``. A tip at rest at ``p`` holds while ``g(p) >= L`` ahead; a slip starts where
``g`` turns down (a fold, or a resting point on a falling segment) at ``L = g(p)``. The
overdamped tip stops at the first ``q > p`` with ``g(q) >= L``; the inertial one where
``E(q) = int_p^q (L - g) du`` (kinetic energy) returns to 0. Both exact for the linear
interpolant of ``g`` (the integral of a linear segment is a quadratic, solved by bisection).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_BISECTIONS = 60
#: Midpoint-rule steps per grid segment of a slip's duration and peak speed.
_SUBSTEPS = 4


@njit(cache=True)
def _g_at(g, du, i, t):
    """``g`` at ``t`` (0 <= t <= du) into segment ``i``."""
    return g[i] + (g[i + 1] - g[i]) * (t / du)


@njit(cache=True)
def _energy_root(e0, b, c, lo, hi):
    """The zero of ``e0 + b t - c t^2 / 2`` in ``(lo, hi]`` that the energy first reaches,
    by bisection (the energy is positive at ``lo``, not positive at ``hi``)."""
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if e0 + b * mid - 0.5 * c * mid * mid > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def _speed(inertial, coef, e0, b, c, x):
    """The tip's speed ``x`` into a segment: ``coef (L - g)`` overdamped (``coef = 1 / eta``),
    ``sqrt(coef E)`` inertial (``coef = 2 / m``)."""
    if inertial:
        return math.sqrt(max(coef * (e0 + b * x - 0.5 * c * x * x), 0.0))
    return max(coef * (b - c * x), 0.0)


@njit(cache=True)
def slip_walk(g, du, inertial, coef, slow, max_events):
    """The slips over the whole grid: per slip its start ``p`` and stop ``q`` (distances
    from ``u_0``), its level ``L``, the time the tip spends faster than ``slow`` (midpoint
    rule, :data:`_SUBSTEPS` a segment) and its peak speed; stops at the first slip that
    would run off the grid.

    Returns ``(p, q, level, duration, peak, n)``, the first ``n`` entries filled."""
    n = g.size
    p_out = np.empty(max_events)
    q_out = np.empty(max_events)
    l_out = np.empty(max_events)
    d_out = np.empty(max_events)
    v_out = np.empty(max_events)
    count = 0
    j = 0  # segment holding the tip
    t = 0.0  # the tip's offset into it
    while count < max_events:
        # where does the next slip start? on a falling segment at once, else at the fold
        if j >= n - 1:
            break
        gp = _g_at(g, du, j, t)
        if g[j + 1] >= gp:
            a = j + 1
            while a < n - 1 and g[a + 1] >= g[a]:
                a += 1
            if a >= n - 1:
                break
            j, t, gp = a, 0.0, g[a]
        level = gp
        start = j * du + t
        # run the slip segment by segment from (j, t)
        i, s0, e = j, t, 0.0
        off = -1.0
        duration, peak = 0.0, 0.0
        while i < n - 1:
            g0 = _g_at(g, du, i, s0)
            c = (g[i + 1] - g[i]) / du
            span = du - s0
            b = level - g0
            end = span
            if not inertial:
                if g[i + 1] >= level:  # g0 < level here: the segment crosses the level
                    end = b / c
                    off = s0 + end
            else:
                e_end = e + b * span - 0.5 * c * span * span
                hit = -1.0
                if e_end <= 0.0:
                    hit = _energy_root(e, b, c, 0.0, span)
                elif c < 0.0 and b < 0.0:  # a convex dip below zero inside the segment
                    tv = b / c
                    if tv < span and e + b * tv - 0.5 * c * tv * tv <= 0.0:
                        hit = _energy_root(e, b, c, 0.0, tv)
                if hit >= 0.0:
                    end = hit
                    off = s0 + hit
            h = end / _SUBSTEPS
            for k in range(_SUBSTEPS):
                v = _speed(inertial, coef, e, b, c, (k + 0.5) * h)
                peak = max(peak, v)
                if v > slow:
                    duration += h / v
            if off >= 0.0:
                break
            if inertial:
                e = e_end
            i += 1
            s0 = 0.0
        if off < 0.0:
            break
        p_out[count] = start
        q_out[count] = i * du + off
        l_out[count] = level
        d_out[count] = duration
        v_out[count] = peak
        count += 1
        j, t = i, min(off, du)
        if t >= du:
            j, t = j + 1, 0.0
    return p_out, q_out, l_out, d_out, v_out, count
