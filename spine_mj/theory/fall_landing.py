"""The fall-landing reference: the quasistatic streamline, with each fall replaced by the
inertial motion of the tip on its spring drive until it lands.

Down a flank steeper than friction (the slip region, paper Fig. 2C) no drive force along +x
holds the tip; the streamline then steps down the tangential part of gravity and resumes
at the first point that holds (docs/physics/streamlines.md), a path with no rate and no
momentum, which does not say where a tip with mass lands. Here, from the first slip point
of the streamline, the tip is a rigid particle of the rig's mass, under its load, Coulomb
friction and the rig's spring (:func:`~spine_mj.theory.coulomb_slide.slide_until_stuck`):
the spring acts along x only, from a carriage that starts where the quasistatic drive held
the tip just before the fall (``x + kappa W / k``, kappa of the last engaged point; 0 from
a start) and moves on at the drive's speed. The tip is free in y and z. The particle is
followed until it rests, or moves no faster than ``2 v`` (a spring without damping on a
moving carriage slides on with it, its speed swinging between 0 and ``2 v``), where a pull
along +x is needed to move it (the engaged or self-lock region,
:func:`~spine_mj.theory.compliant.hold_force` ``>= 0``): from there the
quasistatic streamline is again the path (above the stiffness of its folds, ``K*``, the
compliant drive's path is the rigid one, docs/physics/compliant.md), and it resumes there
until its next fall. A tip at rest in the slip region, held only by a spring that pushes
it back, waits there while the carriage comes up and slides on: a glide down a forward
flank at the carriage's pace.

What it assumes: a rigid tip and surface (MuJoCo's soft contact sinks and creeps), a single
contact but at concave creases, whose impact loses the velocity into the new face with
friction on that impulse (the ball on facets has no curvature), the rig's spring without
damping, and one friction coefficient for stick and slip (as MuJoCo's). Its error is first
order in the step (``timestep_s``, the rig's own by default in a comparison). The streamline
between falls is rate-free: a drive slow enough for the streamline to hold there is what
the corner asks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_count, check_positive
from spine_mj.theory import streamline as sl
from spine_mj.theory.compliant import hold_force
from spine_mj.theory.coulomb_slide import SlideOutcome, SlideParams, slide_until_stuck
from spine_mj.theory.engagement import SLIP
from spine_mj.theory.streamline_types import Outcome, StreamlineParams, StreamlineResult

__all__ = ["FallParams", "landing_streamlines"]


@dataclass(frozen=True)
class FallParams:
    """The tip and its spring drive during a fall (SI).

    Attributes
    ----------
    mass_kg : float
        The tip's mass [kg], > 0.
    load_n : float
        The load ``W`` along -z [N] (the preload F_p), > 0.
    spring_n_m : float
        The drive's spring [N/m], > 0.
    speed_m_s : float
        The carriage's speed [m/s], >= 0.
    length_scale_m : float
        Metres per surface unit.
    timestep_s : float
        The falls' integration step [s].
    max_fall_s : float
        Longest fall [s]; a tip still moving then ends the path (``STEP_CAP``).
    max_falls : int
        Falls a path may take; one more ends it (``STEP_CAP``).
    """

    mass_kg: float
    load_n: float
    spring_n_m: float
    speed_m_s: float
    length_scale_m: float
    timestep_s: float
    max_fall_s: float
    max_falls: int = 64

    def __post_init__(self):
        for name in ("mass_kg", "load_n", "spring_n_m", "length_scale_m", "timestep_s", "max_fall_s"):
            check_positive(name, getattr(self, name))
        check_positive("speed_m_s", self.speed_m_s, allow_zero=True)
        check_count("max_falls", self.max_falls, least=0)
        SlideParams(0.0, self.load_n, self.mass_kg, self.timestep_s, self.max_fall_s)  # the step count


def landing_streamlines(
    surface, starts, params: StreamlineParams, fall: FallParams, *, trace=None
) -> StreamlineResult:
    """Streamlines from ``starts`` whose falls land where the inertial tip does (module
    docstring).

    Parameters
    ----------
    surface : Surface
        The surface the tip's centre rides on; slopes (order 1) are all the falls need.
    starts : array_like, shape (n, 2)
        Start points (surface units).
    params : StreamlineParams
        The streamline's parameters; its ``mu`` is the falls' friction and its domain
        (``edge_margin``) theirs.
    fall : FallParams
    trace : callable, optional
        ``trace(surface, starts, params, store_paths=True) -> StreamlineResult``
        (:func:`spine_mj.theory.streamline.streamlines`, the default, or the ideal
        trajectories).

    Returns
    -------
    StreamlineResult
        The paths, the falls' points in the slip region (kappa NaN), one point a streamline
        step; ``meta`` holds per path ``falls`` (count), ``fall_time_s`` (total),
        ``fall_peak_speed_m_s`` and ``landings`` (each fall's end, where it came to rest or
        left the domain). A landing that the slide holds and the streamline does not (the
        two rules differ by round-off at the slip region's edge) ends the path ``STALLED``.
    """
    if not isinstance(fall, FallParams):
        raise SpineInputError(f"fall must be FallParams, got {type(fall).__name__}")
    trace = sl.streamlines if trace is None else trace
    starts = np.asarray(starts, dtype=float).reshape(-1, 2)
    book = _Paths(len(starts))
    active, points, first = np.arange(len(starts)), starts, True
    while active.size:
        res = trace(surface, points, params, store_paths=True)
        go, at, force = book.split(res, active, first, fall.max_falls)
        first = False
        if not go.size:
            break
        landed = _slide(surface, params, fall, at, force)
        book.land(go, landed, params.dl)
        again = landed.outcome == SlideOutcome.STUCK
        active = go[again]
        points = np.column_stack([landed.x[again], landed.y[again]])
    return book.result(surface, starts, params)


def _slide(surface, params: StreamlineParams, fall: FallParams, at: np.ndarray, kappa: np.ndarray):
    """The falls from ``at`` ``(m, 2)``, the spring holding ``kappa W`` at each start, to
    where each comes to rest where a pull is needed to move it on (module docstring)."""
    mu, s = params.mu, fall.length_scale_m
    slide = SlideParams(
        mu,
        fall.load_n,
        fall.mass_kg,
        fall.timestep_s,
        fall.max_fall_s,
        spring_n_m=fall.spring_n_m,
        carriage_speed_m_s=fall.speed_m_s,
    )

    def held(x, y):
        _, fx, fy = surface.evaluate(x, y, order=1)
        return hold_force(fx, fy, mu)[1] != SLIP

    return slide_until_stuck(
        surface,
        at,
        slide,
        length_scale_m=s,
        carriage_x=at[:, 0] + kappa * fall.load_n / (fall.spring_n_m * s),
        held=held,
        settled_speed_m_s=2 * fall.speed_m_s,
        bounds=params.domain(surface),
        store_paths=True,
    )


class _Paths:
    """The landing reference's paths as they grow: streamline pieces and falls."""

    def __init__(self, n: int):
        self.pieces = [[] for _ in range(n)]  # (x, y, kappa, region) arrays
        self.outcome = np.zeros(n, np.int8)
        self.max_kappa = np.full(n, np.nan)
        self.falls = np.zeros(n, np.int64)
        self.landings = [[] for _ in range(n)]
        self.fall_time = np.zeros(n)
        self.peak = np.zeros(n)

    def split(self, res: StreamlineResult, active: np.ndarray, first: bool, max_falls: int):
        """Keep each streamline of ``res`` (path ``j`` is path ``active[j]``'s next piece) up
        to its first slip point; return the paths that fall there, the points and the
        spring's force there over the load (kappa of the last engaged point; 0 at a start)."""
        self.max_kappa[active] = np.fmax(self.max_kappa[active], res.max_kappa)
        go, at, force = [], [], []
        k0 = 0 if first else 1  # a restart's first point is the landing, already kept
        for j, i in enumerate(active):
            path = res.path(j)
            slip = np.flatnonzero(path["region"] == SLIP)
            f = int(slip[0]) if slip.size else len(path["x"]) - 1
            self.pieces[i].append([path[c][k0 : f + 1] for c in ("x", "y", "kappa", "region")])
            if not slip.size:
                self.outcome[i] = res.outcome[j]
            elif f == 0 and not first:  # a landing held by the slide's rule, not by the streamline's
                self.outcome[i] = Outcome.STALLED
            elif self.falls[i] >= max_falls:
                self.outcome[i] = Outcome.STEP_CAP
            else:
                kap = float(path["kappa"][f - 1]) if f > 0 else 0.0
                go.append(i)
                at.append((path["x"][f], path["y"][f]))
                force.append(kap if math.isfinite(kap) and kap > 0 else 0.0)
        return np.array(go, np.int64), np.array(at).reshape(-1, 2), np.array(force)

    def land(self, go: np.ndarray, landed, dl: float) -> None:
        """Add the falls of paths ``go`` (:class:`~spine_mj.theory.coulomb_slide.SlideResult`),
        one point a streamline step ``dl``."""
        self.falls[go] += 1
        self.fall_time[go] += landed.time_s
        self.peak[go] = np.maximum(self.peak[go], landed.max_speed_m_s)
        for j, i in enumerate(go):
            self.landings[i].append((float(landed.x[j]), float(landed.y[j])))
            p = _thinned(landed.paths[j], dl)[1:]
            self.pieces[i].append([p[:, 0], p[:, 1], np.full(len(p), np.nan), np.full(len(p), SLIP, np.int8)])
            if landed.outcome[j] == SlideOutcome.LEFT_DOMAIN:
                self.outcome[i] = Outcome.LEFT_DOMAIN
            elif landed.outcome[j] == SlideOutcome.TIMED_OUT:
                self.outcome[i] = Outcome.STEP_CAP

    def result(self, surface, starts, params) -> StreamlineResult:
        meta = {
            "falls": self.falls,
            "fall_time_s": self.fall_time,
            "fall_peak_speed_m_s": self.peak,
            "landings": self.landings,
        }
        return _result(surface, starts, params, self.pieces, self.outcome, self.max_kappa, meta)


def _thinned(path: np.ndarray, spacing: float) -> np.ndarray:
    """The points of ``path`` ``(m, 2)`` at least ``spacing`` apart along it, its first and
    last kept."""
    if len(path) < 3:
        return path
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    keep = np.flatnonzero(np.diff(np.floor(arc / spacing), prepend=-1.0) > 0)
    keep = np.union1d(keep, [len(path) - 1])
    return path[keep]


def _result(surface, starts, params, pieces, outcome, max_kappa, meta) -> StreamlineResult:
    """The paths of ``pieces`` (per path, its ``(x, y, kappa, region)`` pieces) as one result."""
    cols = [[np.concatenate([p[c] for p in parts]) for parts in pieces] for c in range(4)]
    counts = np.array([len(x) for x in cols[0]], np.int64)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    x, y, kappa = (np.concatenate(c).astype(float) for c in cols[:3])
    region = np.concatenate(cols[3]).astype(np.int8)
    z = np.asarray(surface.evaluate(x, y, order=0)[0], dtype=float)
    last = offsets[1:] - 1
    locked = (outcome == Outcome.SELF_LOCKED) | (outcome == Outcome.FORCE_CAP)
    return StreamlineResult(
        params=params,
        ideal=False,
        start_x=starts[:, 0].copy(),
        start_y=starts[:, 1].copy(),
        outcome=outcome,
        end_x=x[last],
        end_y=y[last],
        end_z=z[last],
        n_steps=counts - 1,
        max_kappa=np.where(locked & (outcome == Outcome.SELF_LOCKED), np.inf, max_kappa),
        offsets=offsets,
        x=x,
        y=y,
        z=z,
        kappa=kappa,
        region=region,
        meta=meta,
    )
