"""Quasistatic references for stick-slip on a landscape: the slips of a tip driven
infinitely slowly through a spring over a profile uniform in y (docs/physics.md §12).

The tip's centre at ``u`` needs the force ``F(u) = W tan(theta(u) + arctan mu)`` to slide
forward (Coulomb friction, §1); the spring pulls with ``k (X - u)``. Write
``g(u) = F(u) + k u`` and the drive's level ``L = k X``. The tip holds while ``L <= g``
just ahead of it and follows the rising branch of ``g``; where ``g`` turns down (a fold)
it slips at fixed ``X`` (the drive is infinitely slow), and

* the **overdamped** reference (:func:`overdamped_slips`) stops it at the first stable
  point, the first ``q`` with ``g(q) >= L`` (no passing: the tip never skips a stable
  point);
* the **inertial** reference (:func:`inertial_slips`) stops it where its kinetic energy,
  the work ``int_p^q (L - g) du`` of spring, landscape and friction, returns to zero: a
  tip with mass overshoots stable points.

Where a slip stops does not depend on the mobility or the mass; its duration and peak
speed do (``eta du/dt = L - g`` overdamped, ``m v^2 / 2 = E`` inertial). Exact for the
piecewise-linear interpolant of ``F`` on the landscape's grid (refine the grid to approach
a smooth profile). The inertial balance neglects the vertical kinetic energy (a factor
``1 + f'^2``) and the change of the normal force with the acceleration: small slopes.

Pure numpy with a compiled walk (:mod:`spine_mj.theory._avalanche_kernel`); lengths,
forces and times in any consistent units, forces in units of the load ``W``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.theory._avalanche_kernel import slip_walk

__all__ = [
    "Landscape",
    "Slips",
    "abbm_cutoff",
    "inertial_slips",
    "overdamped_slips",
    "pulse_shapes",
    "quasistatic_path",
]


@dataclass(frozen=True)
class Landscape:
    """A landscape on a uniform grid of the tip centre's positions.

    Attributes
    ----------
    start, spacing : float
        ``u_0`` and ``du`` of the grid.
    force : ndarray
        ``F(u_i) / W``: ``tan(theta + arctan mu)``, the forward threshold.
    backward : ndarray
        ``tan(theta - arctan mu)``: below this spring force a resting tip slides back.
    height : ndarray
        The centre's height at ``u_i`` [length]: ``W`` times its rise is the work against
        the load.
    """

    start: float
    spacing: float
    force: np.ndarray
    backward: np.ndarray
    height: np.ndarray

    @classmethod
    def from_profile(cls, x, slope, height, mu: float, tip_radius: float = 0.0) -> Landscape:
        """The landscape of a profile ``z(x)`` with slopes ``f'(x)`` on a uniform grid
        ``x``, for Coulomb friction ``mu`` and a ball tip of ``tip_radius``: the centre
        rides at ``x - r sin theta``, ``z + r cos theta`` (the contact's normal), resampled
        onto a uniform grid of the same count (linear interpolation). The centre's x must
        rise along the profile (the radius below every concave radius of curvature)."""
        x, s, z = (np.asarray(a, float).ravel() for a in (x, slope, height))
        mu = check_positive("mu", mu)
        r = check_positive("tip_radius", tip_radius, allow_zero=True)
        if not (x.size == s.size == z.size and x.size >= 4):
            raise SpineInputError(
                f"x, slope and height must be of one size >= 4, got {x.size}, {s.size}, {z.size}"
            )
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(s)) and np.all(np.isfinite(z))):
            raise SpineInputError("x, slope and height must be finite")
        if not np.all(np.diff(x) > 0):
            raise SpineInputError("x must be strictly increasing")
        if not np.all(s * mu < 1):
            raise SpineInputError(f"the profile self-locks: a slope reaches 1 / mu = {1 / mu:.3g}")
        norm = np.sqrt(1 + s * s)
        xc, zc = x - r * s / norm, z + r / norm
        if not np.all(np.diff(xc) > 0):
            raise SpineInputError(
                f"tip_radius {r!r} exceeds a concave radius of curvature: the centre's x turns back"
            )
        force = (s + mu) / (1 - mu * s)
        back = (s - mu) / (1 + mu * s)
        u = np.linspace(xc[0], xc[-1], xc.size)
        return cls(
            start=float(u[0]),
            spacing=float(u[1] - u[0]),
            force=np.interp(u, xc, force),
            backward=np.interp(u, xc, back),
            height=np.interp(u, xc, zc),
        )

    @property
    def positions(self) -> np.ndarray:
        """The grid ``u_i``."""
        return self.start + self.spacing * np.arange(self.force.size)


@dataclass(frozen=True)
class Slips:
    """The slips of one quasistatic run, one entry each, in order.

    Attributes
    ----------
    start_u, size : ndarray
        Where the slip starts and how far the tip moves [length].
    start_carriage : ndarray
        The carriage position ``X`` at the slip (``L / k``) [length]; the start time is
        ``(X - X_0) / V`` for a drive at speed V.
    force_drop : ndarray
        ``k S / W``: the spring force's drop (the carriage stands still during a slip).
    duration, peak_speed : ndarray
        Time spent faster than the threshold speed, and the largest speed.
    dissipated : ndarray
        Work of the spring minus the work against the load, ``W`` times the rise [W length]:
        what friction (and, overdamped, the viscous mobility) dissipates.
    slides_back : int
        Stops where the spring's push exceeds the backward threshold (inertial only): the
        tip would slide back, which these references do not follow (0 on the tracks tested).
    """

    start_u: np.ndarray
    size: np.ndarray
    start_carriage: np.ndarray
    force_drop: np.ndarray
    duration: np.ndarray
    peak_speed: np.ndarray
    dissipated: np.ndarray
    slides_back: int = 0


def _slips(landscape: Landscape, stiffness: float, inertial: bool, coef: float, slow: float) -> Slips:
    k = check_positive("stiffness", stiffness)
    u = landscape.positions
    g = landscape.force + k * (u - landscape.start)
    max_events = g.size // 2 + 2
    p, q, level, dur, peak, n = slip_walk(g, landscape.spacing, inertial, coef, slow, max_events)
    p, q, level = p[:n], q[:n], level[:n]
    size = q - p
    lift = np.interp(q, u - landscape.start, landscape.height) - np.interp(
        p, u - landscape.start, landscape.height
    )
    work = level * size - 0.5 * k * (q * q - p * p)  # int_p^q k (X - u) du, X = L / k
    spring_at_stop = level - k * q  # k (X - q)
    back = np.interp(q, u - landscape.start, landscape.backward)
    slides_back = int(np.sum(spring_at_stop < back)) if inertial else 0
    return Slips(
        start_u=p + landscape.start,
        size=size,
        start_carriage=level / k + landscape.start,
        force_drop=k * size,
        duration=dur[:n].copy(),
        peak_speed=peak[:n].copy(),
        dissipated=work - lift,
        slides_back=slides_back,
    )


def overdamped_slips(
    landscape: Landscape, stiffness: float, *, mobility: float = 1.0, slow: float = 0.0
) -> Slips:
    """Every slip of an overdamped tip (``du/dt = mobility (k (X - u) - F(u))``) driven
    quasistatically along the whole landscape: each stops at the first stable point.

    Parameters
    ----------
    landscape : Landscape
    stiffness : float
        ``k / W`` [1 / length].
    mobility : float
        ``1 / eta`` [length / (W time)]: sets durations and speeds only.
    slow : float
        Speeds at or below this do not count towards a slip's duration (the drive's speed,
        as the MuJoCo slip detector counts time ahead of the carriage; 0 counts all, and a
        slip that starts at a fold then lasts logarithmically long in the grid spacing).
    """
    return _slips(landscape, stiffness, False, check_positive("mobility", mobility), _slow(slow))


def inertial_slips(landscape: Landscape, stiffness: float, *, mass: float = 1.0, slow: float = 0.0) -> Slips:
    """Every slip of a tip of ``mass`` [W time^2 / length] driven quasistatically along the
    whole landscape: each stops where its kinetic energy is spent (see the module's
    docstring); ``slow`` as in :func:`overdamped_slips`."""
    return _slips(landscape, stiffness, True, 2.0 / check_positive("mass", mass), _slow(slow))


def _slow(slow: float) -> float:
    return check_positive("slow", slow, allow_zero=True)


def quasistatic_path(landscape: Landscape, stiffness: float, slips: Slips, carriage) -> np.ndarray:
    """Where the tip of a reference run (``slips``, from :func:`overdamped_slips` or
    :func:`inertial_slips` at ``stiffness``) rests at each carriage position: between
    slips it holds where the last slip left it until the spring reaches the landscape's
    threshold, then follows the rising stretch of ``g`` up to the next fold; a slip moves
    it at one carriage position (the position of a slip's start gives where it stopped).

    Parameters
    ----------
    landscape : Landscape
    stiffness : float
        ``k / W`` [1 / length], the one ``slips`` was computed at.
    slips : Slips
    carriage : (n,) array
        Non-decreasing carriage positions ``X`` [length], from ``landscape.start`` on and
        not past the last slip's.

    Returns
    -------
    (n,) array
        The tip's ``u``; the spring's force is ``k (X - u)`` [W].
    """
    k = check_positive("stiffness", stiffness)
    x = np.asarray(carriage, float)
    if x.ndim != 1 or not np.all(np.diff(x) >= 0):
        raise SpineInputError("carriage must be a non-decreasing 1-D array")
    u = landscape.positions - landscape.start
    g = landscape.force + k * u
    level = k * (x - landscape.start)
    slip_level = k * (slips.start_carriage - landscape.start)
    rest = np.concatenate([[0.0], slips.start_u - landscape.start + slips.size])
    ends = np.concatenate([slips.start_u - landscape.start, [u[-1]]])
    which = np.searchsorted(slip_level, level, side="right")
    out = np.empty_like(x)
    for i in np.unique(which):
        sel = which == i
        a, b = np.searchsorted(u, rest[i], side="right"), np.searchsorted(u, ends[i], side="right")
        uu = np.concatenate([[rest[i]], u[a:b]])
        gg = np.maximum.accumulate(np.concatenate([[np.interp(rest[i], u, g)], g[a:b]]))
        out[sel] = np.maximum(rest[i], np.interp(level[sel], gg, uu))
    return out + landscape.start


def pulse_shapes(
    landscape: Landscape,
    stiffness: float,
    slips: Slips,
    *,
    inertial: bool,
    slow: float = 0.0,
    points: int = 41,
    min_segments: int = 8,
) -> tuple[np.ndarray, np.ndarray]:
    """Each slip's speed against time, both normalized: ``v / (S / T)`` (over its mean
    speed) at ``points`` times ``t / T`` from 0 to 1 (T the time spent faster than
    ``slow``; the first and last samples are the first and last pieces' speeds), from the landscape
    between its start and stop: overdamped ``v ~ L - g(u)``, inertial
    ``v ~ sqrt(int_p^u (L - g))`` (the mobility and the mass scale v and t and drop out
    of the shape; they only set what ``slow`` cuts). Midpoint speeds of the grid's pieces.

    Parameters
    ----------
    landscape, stiffness, slips
        As for :func:`quasistatic_path` (``slips`` of the reference named by ``inertial``).
    inertial : bool
    slow : float
        Speeds at or below this (in the units ``L - g`` or ``sqrt(2 E)`` of a unit
        mobility or mass) do not count: 0 counts all.
    points : int
        Samples of the normalized time axis, >= 2.
    min_segments : int
        Slips over fewer grid pieces are left out (their shape is the grid's).

    Returns
    -------
    (shapes, durations) : ((m, points) array, (m,) array)
        One row per slip kept, and its duration in the same units.
    """
    k = check_positive("stiffness", stiffness)
    if int(points) < 2:
        raise SpineInputError(f"points must be at least 2, got {points!r}")
    u = landscape.positions - landscape.start
    g = landscape.force + k * u
    grid = np.linspace(0.0, 1.0, int(points))
    shapes, durations = [], []
    for p, size, x in zip(slips.start_u - landscape.start, slips.size, slips.start_carriage):
        level = k * (x - landscape.start)
        a, b = np.searchsorted(u, p, side="right"), np.searchsorted(u, p + size, side="left")
        if b - a < min_segments:
            continue
        uu = np.concatenate([[p], u[a:b], [p + size]])
        gg = np.concatenate([[np.interp(p, u, g)], g[a:b], [np.interp(p + size, u, g)]])
        drive = level - gg
        if inertial:
            energy = np.concatenate([[0.0], np.cumsum(0.5 * (drive[1:] + drive[:-1]) * np.diff(uu))])
            v = np.sqrt(np.maximum(0.5 * (energy[1:] + energy[:-1]), 0.0) * 2.0)
        else:
            v = np.maximum(0.5 * (drive[1:] + drive[:-1]), 0.0)
        fast = v > slow
        if fast.sum() < 2:
            continue
        dt = np.diff(uu)[fast] / v[fast]
        t = np.cumsum(dt) - 0.5 * dt
        span = float(dt.sum())
        shapes.append(np.interp(grid * span, t, v[fast]) / (size / span))
        durations.append(span)
    if not shapes:
        return np.zeros((0, grid.size)), np.zeros(0)
    return np.array(shapes), np.array(durations)


def abbm_cutoff(force_intensity: float, stiffness: float) -> float:
    """``S_m = sigma / k^2``: the ABBM cutoff of slip sizes, ``P(S) ~ S^-3/2
    exp(-S / (4 S_m))``, for a force walk ``<(F(u) - F(u'))^2> = 2 sigma |u - u'|``."""
    return check_positive("force_intensity", force_intensity) / check_positive("stiffness", stiffness) ** 2
