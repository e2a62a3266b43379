"""The drive limits a surface sets before any run: the stiffness ``K*`` below which a
spring drive stick-slips at vanishing speed, and the inertia number ``I_e*`` above which the
quasistatic picture breaks (docs/physics.md §8).

Both come from the rigid streamlines (paper Eq. 4) traced from a grid of starts over the
surface, pure numpy on the analytic side:

* ``K* = l_s max(-dH/dx)`` along the paths, ``H`` the hold force per unit preload
  (:func:`spine_mj.theory.compliant.hold_force`, kappa where engaged): below it the
  carriage position that holds the tip, ``X = x + (W / k) H``, falls somewhere along a
  path, a fold of the compliant-drive streamline (:mod:`spine_mj.theory.compliant`). On a
  corrugation this is the Prandtl-Tomlinson ``K* = l_s max(-d kappa / dx)``. It is the
  first fold anywhere, a sufficient condition; the comparison's criterion sees a fold only
  through what its jump does to the path's trace and outcome (a jump along the path leaves
  the trace where it was). ``K_path``
  (:func:`~spine_mj.theory.path_stiffness.path_stiffness`), given the starts of a
  measurement, is the stiffness where the compliant-drive paths (the spring drive's
  ``I_e -> 0`` limit) meet that criterion against the rigid ones: the boundary a measurement
  with that criterion sees, ``<= K*`` on the same paths (no fold: the two paths coincide)
  where the carriage is endless. A run's carriage is not: without a duration it stops
  :func:`~spine_mj.theory.path_stiffness.spring_run_travel` past its start (``1.1`` times
  the distance to the domain's +x edge plus the spring's stretch at ``(1 + mu) F_p``), and
  a tip that must stop where the spring has to be stretched further (a lock that is
  decided at ``kappa_cap F_p``, a tip lagging the carriage by ``H l_s / K`` on its way to
  the edge) ends short of the rigid path's end: given the domain's edge, ``K_path`` is
  measured with the runs' travel.
* ``I_e*`` the lowest of three thresholds. *Lift-off*: a tip carried at horizontal speed
  ``v`` over a profile ``z(h)`` (h: horizontal arc length along the path) needs the
  vertical acceleration ``z'' v^2``; preload and gravity give at most ``F_p / m``, so it
  leaves the surface where ``-z'' v^2 > F_p / m``: ``I_e > 1 / (L_c max(-z''))``.
  On a surface dilated by the tip's radius ``R`` the crest is at most the section of a
  ball of radius ``R`` (:func:`ball_crest_bound`); a sampled dilation's interpolant rings
  past it near creases (measured on sandpaper P36: ``L_c max(-z'')`` 2.5e4 from the
  interpolant where ``L_c / R`` is 18), so ``-z''`` is read as the smaller of the two.
  *Trap skipping*: a path that self-locks does so on a wall the drive cannot climb; a tip
  arriving at the carriage speed climbs it anyway if its kinetic energy covers the work
  to the wall's end (where the region stops being self-locked, along +x): against the
  preload ``W dz``, against friction ``mu (W dx + F dz)`` (the normal load on a slope of
  ``dz / dx`` pushed by ``F``), less the drive's ``F dx``, with ``F`` the hold force the
  path had on arrival: ``I_e > 2 D / L_c``, ``D = dz + mu dx + f (mu dz - dx)``,
  ``f = F / W``, the shallowest trap first.
  *Lag*: where the quasistatic path turns, a sliding tip carries its momentum on until
  friction (``mu F_p`` at most) has taken its kinetic energy: over ``m v^2 / (2 mu F_p) =
  I_e L_c / (2 mu)``. The path lags the streamline by that much; it stays within a path
  tolerance ``t L_c`` while ``I_e < 2 mu t``.
* For a spring drive of stiffness ``K`` two more (:func:`spring_ie_limits`): the tip set
  sliding from rest swings about its quasistatic place by ``L_c sqrt(I_e / K_c)`` and its
  drive force by ``sqrt(I_e K_c) F_p`` (the spring-block, ``K_c = K L_c / l_s``): within
  the path tolerance while ``I_e < t^2 K_c``, within :data:`SWING_BOUND_FP` while
  ``I_e < 1 / K_c``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from spine_mj import roughness
from spine_mj.errors import SpineInputError
from spine_mj.surfaces import Surface
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import streamline as sl
from spine_mj.theory.compliant import hold_force
from spine_mj.theory.engagement import DEFAULT_KAPPA_CAP, SELF_LOCK
from spine_mj.theory.path_stiffness import max_fall, path_stiffness
from spine_mj.theory.streamline_types import StreamlineParams
from spine_mj.theory.targets import FRECHET_TARGET

__all__ = [
    "CORNER_MARGIN",
    "SWING_BOUND_FP",
    "Corner",
    "DriveLimits",
    "ball_crest_bound",
    "crest_curvature",
    "drive_limits",
    "quasistatic_corner",
    "spring_ie_limits",
    "trap_depths",
]

#: The largest spring-block force swing ``V sqrt(k m)`` (in F_p) with which a spring drive
#: is still quasistatic: a dynamic excess as large as the preload itself, the scale of every
#: quasistatic force of the problem (it unloads the tip on a 45 degree downslope, where the
#: normal load is ``(W + F dz/dx) / sqrt(1 + |grad z|^2)``; docs/physics.md §8).
SWING_BOUND_FP = 1.0

#: How far inside its limits a corner lies in ``I_e`` and in ``K`` (:func:`quasistatic_corner`):
#: the lag (``I_e L_c / (2 mu)``) and the compliant offset (``1 / K``) are first order and
#: reach the Frechet target 0.1 L_c at the limits; a tenth of the way they are 0.01 L_c, what
#: the Frechet distance resolves (``validate.theory_orders.FRECHET_FLOOR_LC``). At a threshold
#: (lift-off, a trap skipped) the tip has a tenth of the kinetic energy that crosses it.
CORNER_MARGIN = 10.0


@dataclass(frozen=True)
class DriveLimits:
    """Predicted drive limits of a surface (dimensionless unless a unit is named).

    Attributes
    ----------
    k_star : float
        ``K*``: stick-slip at vanishing speed below it (0: no fold anywhere).
    ie_star : float
        ``min(ie_lift, ie_trap)``: the quasistatic picture breaks above it.
    ie_lift, ie_trap : float
        The lift-off and trap-skipping thresholds (inf: no crest, no trap).
    ie_lag : float
        Where the tip's lag behind a turn of the path, ``I_e L_c / (2 mu)``, reaches the
        path tolerance: ``2 mu tolerance / L_c``.
    limit : str
        Which of the three sets ``ie_star``: ``"lift-off"``, ``"trap"`` or ``"lag"``.
    mu : float
    slope_length, char_length : float
        ``l_s`` and ``L_c`` (surface length unit).
    max_fall : float
        ``max(-dH/dx)`` along the paths (1 / length).
    max_crest_curvature : float
        ``max(-z'')`` along the paths (1 / length).
    min_trap_depth : float
        The shallowest trap's ``D`` (length; inf without traps).
    n_paths, n_traps : int
    k_path : float
        ``K_path``: the smallest stiffness at which the compliant-drive paths from
        ``path_starts`` meet the comparison's criterion against the rigid ones
        (:func:`~spine_mj.theory.path_stiffness.path_stiffness`; NaN: not computed, no ``path_starts``).
    k_star_path_starts : float
        The fold ``K*`` on the paths from ``path_starts`` (NaN: not computed).
    k_path_endless : float
        ``K_path`` with an endless carriage (equal to ``k_path`` without ``carriage_edge``):
        what the folds alone make the criterion see.
    k_path_left_out : int
        Path starts left out of ``k_path``: they miss at every stiffness probed
        (:func:`~spine_mj.theory.path_stiffness.path_stiffness`).
    """

    k_star: float
    ie_star: float
    ie_lift: float
    ie_trap: float
    ie_lag: float
    limit: str
    mu: float
    slope_length: float
    char_length: float
    max_fall: float
    max_crest_curvature: float
    min_trap_depth: float
    n_paths: int
    n_traps: int
    k_path: float = math.nan
    k_star_path_starts: float = math.nan
    k_path_endless: float = math.nan
    k_path_left_out: int = 0

    def as_dict(self) -> dict:
        return asdict(self)

    def sentence(self) -> str:
        """``"quasistatic needs K > ... and I_e < ..."``."""
        return (
            f"quasistatic needs K > {self.k_star:.3g}"
            + (
                f" (the paths from the starts given: {self.k_path:.3g})"
                if not math.isnan(self.k_path)
                else ""
            )
            + f" and I_e < {self.ie_star:.3g} "
            f"(set by {self.limit}; lift-off {self.ie_lift:.3g}, trap {self.ie_trap:.3g}, "
            f"lag {self.ie_lag:.3g})"
        )


@dataclass(frozen=True)
class Corner:
    """The quasistatic corner of a surface (:func:`quasistatic_corner`): the inertia number
    ``ie``, the stiffness number ``k`` (``K = k l_s / F_p``), the force swing ``swing_fp``
    ``sqrt(I_e K L_c / l_s)`` [F_p] there, what sets ``I_e`` (``ie_bound``: ``"I_e*"``,
    ``"swing-path"`` or ``"swing-force"``), what ``K`` is the margin times (``k_bound``:
    ``"K_path"`` or ``"K*"``), and ``reason``, one sentence."""

    ie: float
    k: float
    swing_fp: float
    ie_bound: str
    k_bound: str
    reason: str

    def as_dict(self) -> dict:
        """``validation.json``'s ``corner``: ``ie``, ``K`` and the rest by field name."""
        return {"ie": self.ie, "K": self.k, **{k: v for k, v in asdict(self).items() if k not in ("ie", "k")}}


def quasistatic_corner(
    *,
    ie_star: float,
    k_path: float,
    lc_over_ls: float,
    k_star: float = math.nan,
    path_tolerance: float = FRECHET_TARGET,
    margin: float = CORNER_MARGIN,
    ie_limit: str = "",
    k_floor: float = 0.0,
) -> Corner:
    """The corner ``(I_e, K)`` at which a spring drive on a surface is quasistatic, from its
    own predicted limits (:func:`drive_limits`; for a family, its surfaces' lowest
    ``ie_star`` and highest ``k_path`` and ``lc_over_ls``; docs/physics.md §8).

    ``K = margin K_path`` (``margin K*`` where ``k_path`` is NaN), rounded up to two digits:
    the compliant offset, first order in ``1 / K``, is a ``margin``-th of the path tolerance
    ``t`` it reaches at ``K_path``. ``I_e`` the lowest of ``I_e* / margin`` (the lag is
    first order in ``I_e``), ``(t / margin)^2 K_c`` (the position swing ``L_c sqrt(I_e /
    K_c)`` a ``margin``-th of ``t L_c``) and ``SWING_BOUND_FP^2 / K_c`` (the force swing,
    :func:`spring_ie_limits`), ``K_c = K L_c / l_s``, rounded down to one digit.
    ``ie_limit`` names what set ``ie_star`` in the reason; ``K`` is at least ``k_floor`` (the
    softest spring the engine runs cleanly: a path criterion met at any K gives no scale).

    Raises
    ------
    SpineInputError
        A limit that is not a positive number (``ie_star`` may be inf: no limit from the
        geometry), neither a ``k_path`` nor a ``k_star`` > 0, or ``margin <= 1``.
    """
    checks = (
        ("ie_star", ie_star, True),
        ("lc_over_ls", lc_over_ls, False),
        ("path_tolerance", path_tolerance, False),
    )
    for name, v, inf_ok in checks:
        if not (isinstance(v, (int, float)) and v > 0 and (math.isfinite(v) or (inf_ok and v == math.inf))):
            raise SpineInputError(f"{name} must be a positive number, got {v!r}")
    if not (isinstance(margin, (int, float)) and math.isfinite(margin) and margin > 1):
        raise SpineInputError(f"margin must be a finite number > 1, got {margin!r}")
    usable = [(float(v), n) for v, n in ((k_path, "K_path"), (k_star, "K*")) if math.isfinite(v) and v > 0]
    if not usable:
        raise SpineInputError(f"the corner needs K_path or a positive K*, got {k_path!r} and {k_star!r}")
    k_ref, k_bound = usable[0]
    scale = 10.0 ** (math.floor(math.log10(margin * k_ref)) - 1)
    k = max(float(f"{math.ceil(margin * k_ref / scale * (1 - 1e-12)) * scale:.2g}"), float(k_floor))
    k_bound = k_bound if k > k_floor else "floor"
    bounds = {
        "I_e*": ie_star / margin,
        **spring_ie_limits(k, lc_over_ls, path_tolerance=path_tolerance / margin),
    }
    ie_bound = min(bounds, key=bounds.get)
    scale = 10.0 ** math.floor(math.log10(bounds[ie_bound]))
    ie = float(f"{math.floor(bounds[ie_bound] / scale * (1 + 1e-12)) * scale:.1g}")
    swing_fp = math.sqrt(ie * k * lc_over_ls)
    why = {
        "I_e*": f"I_e* {ie_star:.3g}{f' ({ie_limit})' if ie_limit else ''} / {margin:g}",
        "swing-path": f"the spring's position swing at {path_tolerance / margin:.3g} L_c",
        "swing-force": f"the spring's force swing at {SWING_BOUND_FP:g} F_p",
    }[ie_bound]
    reason = f"I_e {ie:.3g}, K {k:.3g}: K = {margin:g} {k_bound} ({k_ref:.3g}), I_e set by {why}"
    return Corner(ie, k, swing_fp, ie_bound, k_bound, f"{reason}; swing {swing_fp:.2g} F_p")


def crest_curvature(x, y, z) -> np.ndarray:
    """``-d^2 z / dh^2`` at the inner points of one path (shape ``(n - 2,)``), ``h`` its
    horizontal arc length (three-point formula on uneven steps); NaN at repeated points."""
    x, y, z = (np.asarray(a, float) for a in (x, y, z))
    h = np.hypot(np.diff(x), np.diff(y))
    h1, h2 = h[:-1], h[1:]
    ok = (h1 > 0) & (h2 > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        d2 = 2.0 * (h1 * z[2:] - (h1 + h2) * z[1:-1] + h2 * z[:-2]) / (h1 * h2 * (h1 + h2))
    return np.where(ok, -d2, np.nan)


def ball_crest_bound(x, y, z, fx, fy, tip_radius: float) -> np.ndarray:
    """The sharpest crest ``-z''`` (along the horizontal arc length) that a surface dilated
    by a ball of radius ``R`` can have at the inner points of one path (shape ``(n - 2,)``;
    inf for ``R = 0``).

    The tip centre's surface is an upper envelope of balls, so at every point a ball of
    radius ``R`` lies below it and touches it (:func:`spine_mj.surfaces.dilate`). The
    path's vertical plane cuts that ball in a circle of radius ``rho = R sqrt(1 - q^2)``,
    ``q`` the unit normal's component across the path (from the gradient ``fx, fy``); the
    section lies above the circle, so it bends down no faster: ``-z'' <= (1 + s^2)^(3/2) /
    rho``, ``s`` the slope along the path (the chord of its neighbours: a sampled
    dilation's interpolant rings, in slope and in curvature, near the creases where two
    balls meet; the chord of the path's own heights rings least).
    """
    x, y, z, fx, fy = (np.asarray(a, float) for a in (x, y, z, fx, fy))
    if not tip_radius > 0:
        return np.full(max(x.size - 2, 0), np.inf)
    ex, ey = x[2:] - x[:-2], y[2:] - y[:-2]
    norm = np.hypot(ex, ey)
    ok = norm > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        ex, ey = ex / norm, ey / norm
        along = (z[2:] - z[:-2]) / np.where(ok, norm, 1.0)
    gx, gy = fx[1:-1], fy[1:-1]
    across = (gy * ex - gx * ey) / np.sqrt(1.0 + gx**2 + gy**2)
    rho = tip_radius * np.sqrt(np.clip(1.0 - across**2, 0.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ok, (1.0 + along**2) ** 1.5 / rho, np.nan)


def trap_depths(surface: Surface, x, y, f_arrival, mu: float, *, step: float, kappa_cap: float) -> np.ndarray:
    """``D = dz + mu dx + f (mu dz - dx)`` of traps at ``(x, y)`` (shape ``(m,)``): the
    work per unit preload that takes a tip arriving with drive ``f W`` along +x to the end
    of the self-locked wall (held: self-locked, or a hold force above ``kappa_cap``),
    marched in steps ``step``; ``inf`` where the wall reaches the domain's edge."""
    x = np.asarray(x, float).copy()
    y = np.asarray(y, float)
    f = np.asarray(f_arrival, float)
    x0 = x.copy()
    z0 = surface.height(x, y)
    xmax = surface.bounds[1]
    held = np.ones(x.size, bool)
    while held.any():
        x = np.where(held, x + step, x)
        beyond = held & (x > xmax)
        x = np.where(beyond, xmax, x)
        _, fx, fy = surface.evaluate(x, y, order=1)
        hold, region = hold_force(fx, fy, mu)
        still = (region == SELF_LOCK) | (hold > kappa_cap)
        held &= still & ~beyond
        if beyond.any():
            held[beyond] = False
            x[beyond] = np.inf
    dz = surface.height(np.where(np.isfinite(x), x, x0), y) - z0
    dx = x - x0
    return np.where(np.isfinite(x), dz + mu * dx + f * (mu * dz - dx), np.inf)


def spring_ie_limits(
    stiffness_number: float,
    lc_over_ls: float,
    *,
    path_tolerance: float = FRECHET_TARGET,
    force_bound: float = SWING_BOUND_FP,
) -> dict[str, float]:
    """The inertia numbers at which a spring drive of stiffness ``K`` stops being
    quasistatic through its own swing (docs/physics.md §8). A tip set sliding from rest
    behind a carriage at ``V`` swings about its quasistatic place with the spring-block's
    amplitudes: ``V / w = L_c sqrt(I_e / K_c)`` in position and ``V sqrt(k m) =
    sqrt(I_e K_c) F_p`` in force (``K_c = K L_c / l_s``, :func:`spine_mj.sim.holding.spring_swing`).

    Returns
    -------
    dict
        ``"swing-path"``: where the position swing reaches the path tolerance ``t L_c``,
        ``t^2 K_c``; ``"swing-force"``: where the force swing reaches ``force_bound`` F_p,
        ``force_bound^2 / K_c`` (inf for both without a finite positive ``K_c``).
    """
    kc = float(stiffness_number) * float(lc_over_ls)
    if not (math.isfinite(kc) and kc > 0):
        return {"swing-path": math.inf, "swing-force": math.inf}
    return {"swing-path": path_tolerance**2 * kc, "swing-force": force_bound**2 / kc}


def _path_statistics(
    surface: Surface, res, mu: float, kappa_cap: float, tip_radius: float = 0.0
) -> tuple[float, np.ndarray]:
    """Over the paths of ``res``: the sharpest crest ``max(-z'')`` (at most
    :func:`ball_crest_bound` on a surface dilated by ``tip_radius``), and per path the last
    finite hold force (a trap's arrival drive)."""
    curv, arrival = [np.array([])], np.full(len(res), np.nan)
    for i in range(len(res)):
        p = res.path(i)
        _, fx, fy = surface.evaluate(p["x"], p["y"], order=1)
        hold, _ = hold_force(fx, fy, mu)
        finite = hold[np.isfinite(hold) & (hold <= kappa_cap)]
        arrival[i] = finite[-1] if finite.size else 0.0
        bound = ball_crest_bound(p["x"], p["y"], p["z"], fx, fy, tip_radius)
        curv.append(np.minimum(crest_curvature(p["x"], p["y"], p["z"]), bound))
    return float(np.nanmax(np.concatenate(curv), initial=0.0)), arrival


def _path_stiffnesses(traced, path_starts, params, l_s: float, l_c: float, carriage_edge):
    """``(k_path, k_fold, k_path_endless, left_out)`` of :func:`drive_limits` (NaN and 0
    without starts)."""
    if path_starts is None:
        return math.nan, math.nan, math.nan, 0
    endless, k_fold, left_out = path_stiffness(traced, path_starts, params, slope_length=l_s, char_length=l_c)
    if carriage_edge is None:
        return endless, k_fold, endless, left_out
    k_path, _, left_out = path_stiffness(
        traced, path_starts, params, slope_length=l_s, char_length=l_c, carriage_edge=carriage_edge
    )
    return k_path, k_fold, endless, left_out


def _grid_starts(surface: Surface, n: int, margin: float) -> np.ndarray:
    xmin, xmax, ymin, ymax = surface.bounds
    mx, my = margin * (xmax - xmin), margin * (ymax - ymin)
    xs = np.linspace(xmin + mx, xmax - mx, n)
    ys = np.linspace(ymin + my, ymax - my, n)
    return np.array([(a, b) for b in ys for a in xs])


def _lengths(surface: Surface, n_starts) -> tuple[float, float]:
    """``(l_s, L_c)`` of :func:`drive_limits`' ``surface``, its arguments checked first."""
    if not isinstance(surface, Surface):
        raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
    if isinstance(n_starts, bool) or not isinstance(n_starts, (int, np.integer)) or n_starts < 1:
        raise SpineInputError(f"n_starts must be an integer >= 1, got {n_starts!r}")
    return float(roughness.stiffness_length(surface)), float(roughness.characteristic_length(surface))


def _traced(surface: Surface, tip_radius: float, progress) -> Surface:
    """The surface the tip's centre rides (``surface`` dilated by ``tip_radius``; 0: itself)."""
    return dilate(surface, tip_radius, progress=progress) if tip_radius > 0 else surface


def drive_limits(
    surface: Surface,
    mu: float,
    *,
    starts=None,
    n_starts: int = 8,
    dl: float | None = None,
    tip_radius: float = 0.0,
    kappa_cap: float = DEFAULT_KAPPA_CAP,
    path_tolerance: float = FRECHET_TARGET,
    path_starts=None,
    carriage_edge: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> DriveLimits:
    """Predict ``K*`` and ``I_e*`` of ``surface`` from its quasistatic paths (module doc).

    Parameters
    ----------
    surface : Surface
    mu : float
    starts : array_like, shape (n, 2), optional
        Path starts; default an ``n_starts x n_starts`` grid over the domain (5 % margin).
    dl : float, optional
        Streamline step (default ``l_s / 40``, at most an eighth of the narrower side).
    tip_radius : float
        Trace on the surface dilated by a ball of this radius (the MuJoCo tip's centre).
    kappa_cap : float
        Hold forces above it count as held.
    path_tolerance : float
        How far (in ``L_c``) a path may lag the streamline, for ``ie_lag`` (the Frechet target).
    path_starts, carriage_edge : array_like (m, 2), float, optional
        A measurement's starts and its runs' +x edge: ``K_path`` (:mod:`~spine_mj.theory.path_stiffness`).
    progress : callable, optional
        Hears a big dilation by the tip row by row (:func:`~spine_mj.surfaces.dilate`).

    Returns
    -------
    DriveLimits
    """
    l_s, l_c = _lengths(surface, n_starts)
    traced = _traced(surface, tip_radius, progress)
    pts = _grid_starts(traced, int(n_starts), 0.05) if starts is None else starts
    dl = min(l_s / 40, min(np.diff(traced.bounds)[::2]) / 8) if dl is None else dl  # 1/8 of a strip's width
    params = StreamlineParams(mu=mu, dl=dl, kappa_cap=kappa_cap)
    res = sl.streamlines(traced, pts, params, store_paths=True)
    fall = max_fall(traced, res, mu, kappa_cap)
    max_curv, arrival = _path_statistics(traced, res, mu, kappa_cap, tip_radius)
    trapped = res.self_locked
    xy = (res.end_x[trapped], res.end_y[trapped])
    depth = trap_depths(traced, *xy, arrival[trapped], mu, step=params.dl / 4, kappa_cap=kappa_cap)
    min_depth = float(depth.min()) if depth.size else math.inf
    ie_lift = 1.0 / (l_c * max_curv) if max_curv > 0 else math.inf
    ie_trap = 2.0 * max(min_depth, 0.0) / l_c
    ie_lag = 2.0 * float(mu) * float(path_tolerance)
    limits = {"lift-off": ie_lift, "trap": ie_trap, "lag": ie_lag}
    limit = min(limits, key=limits.get)
    k_path, k_fold_starts, k_endless, left_out = _path_stiffnesses(
        traced, path_starts, params, l_s, l_c, carriage_edge
    )
    return DriveLimits(
        k_star=l_s * max(0.0, fall),
        ie_star=limits[limit],
        ie_lift=ie_lift,
        ie_trap=ie_trap,
        ie_lag=ie_lag,
        limit=limit,
        mu=float(mu),
        slope_length=l_s,
        char_length=l_c,
        max_fall=fall,
        max_crest_curvature=max_curv,
        min_trap_depth=min_depth,
        n_paths=len(res),
        n_traps=int(trapped.sum()),
        k_path=k_path,
        k_star_path_starts=k_fold_starts,
        k_path_endless=k_endless,
        k_path_left_out=left_out,
    )
