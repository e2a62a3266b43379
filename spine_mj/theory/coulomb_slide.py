"""Where a tip comes to rest after a fall: a rigid particle sliding under its load, a drive
force and Coulomb friction on a surface ``z = f(x, y)``, until it sticks.

The quasistatic streamline (paper Eq. 4) knows where a tip goes while every point is in
balance; down a flank steeper than the friction angle (the slip region) nothing balances
the load, the tip gains speed, and where it lands depends on its inertia: a streamline that
steps down the slope direction and stops at the first point that holds is not the motion
a tip with mass makes. This reference is that motion, in the same frame as the streamline
(load ``W`` along -z, drive along +x, one friction coefficient as in MuJoCo), so that a
comparison with MuJoCo after a fall is like for like (docs/physics.md §6, inertia).

In contact the particle keeps to the surface; with ``n = (-f_x, -f_y, 1) / g``,
``g = sqrt(1 + |grad f|^2)``, applied force ``A = (F, 0, -W)`` and ``H`` the Hessian, the
constraint gives the normal force (the profile formula of
:mod:`~spine_mj.theory.tomlinson_dynamics` in two dimensions)::

    N = (W + f_x F + m v^T H v) / g        (v the horizontal velocity)

and friction ``mu N`` opposes the sliding velocity. Each step (semi-implicit Euler) adds
the tangential part of ``A`` to the 3-D velocity in the tangent plane, then takes away a
friction impulse ``mu N dt`` along that velocity, clamped at rest: a particle at rest stays
exactly while ``|A_t| <= mu N`` (the stick condition of paper Eq. 1-3), and one that slides
stops where the friction impulse exceeds its momentum. Where ``N < 0``, or the surface a
step ahead lies below a free fall's path (a ledge), it leaves the surface and flies
(gravity and drive only) until it meets the surface again, where the
landing removes the normal velocity (an inelastic, critically damped contact, as the rig's
``solref = (2 dt, 1)``) and friction removes up to ``mu`` times that normal impulse from the
tangential velocity.

A spring of stiffness ``k`` along x from a carriage at ``X`` (staying, or moving along +x
at a constant speed) adds ``k (X - x)`` to the drive, as the rig's spring carriage does
(the spring acts in x only, the particle is free in y and z). A particle at rest then ends
its slide only where ``held(x, y)`` says so (default: wherever it rests; optionally at a
speed of at most ``settled_speed_m_s``); elsewhere the carriage's advance may set it
sliding again.

On a surface without a Hessian (a ball on facets: flat faces, edges rounded over the tip
radius) the curvature term is taken as zero, and where a step brings the particle against
a concave crease the velocity into the new face is lost as at a landing, friction taking
up to ``mu`` times that impulse: the crease's ``m v^T H v`` as one impulse.

Closed forms (tested): on an incline of angle ``theta`` a particle at rest stays iff
``tan(theta) <= mu``; otherwise it accelerates down at ``a (sin(theta) - mu cos(theta))``
(``a = W / m``); one launched down at speed ``v`` with ``tan(theta) < mu`` stops after
``v^2 / (2 a (mu cos(theta) - sin(theta)))``. Released at rest with a spring force
``F_0`` from a carriage that stays, on an incline of angle ``theta`` along x (flat:
``theta = 0``) it slides a harmonic half-period ``pi / omega_e``, ``omega_e^2 = k_e / m``,
``k_e = k cos(theta) (cos(theta) - mu sin(theta))``, and stops ``2 u*`` along the slope,
``u* = (F_0 (cos(theta) - mu sin(theta)) - W (sin(theta) + mu cos(theta))) / k_e``.
Released on flat ground at exactly ``F_0 = mu W`` from a carriage moving at ``v``, it
moves as ``x_0 + v t - (v / omega) sin(omega t)`` (``omega^2 = k / m``) and first rests at
``t = 2 pi / omega``. The error is first order in the step.

Pure numpy, vectorized over particles; the surface is anything with
``evaluate(x, y, order=2) -> (f, f_x, f_y, f_xx, f_xy, f_yy)`` (every
:class:`~spine_mj.surfaces.Surface`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from spine_mj.errors import SpineInputError, check_positive

__all__ = ["SlideOutcome", "SlideParams", "SlideResult", "slide_until_stuck"]


class SlideOutcome(IntEnum):
    """How a slide ended."""

    STUCK = 0  # at rest where friction holds it
    LEFT_DOMAIN = 1  # outside the surface's bounds
    TIMED_OUT = 2  # still moving after ``max_time_s``


@dataclass(frozen=True)
class SlideParams:
    """The particle, its drive and the integration.

    Attributes
    ----------
    mu : float
        Coulomb coefficient (static = kinetic, as MuJoCo's), >= 0.
    load_n : float
        The load ``W`` pressing along -z [N] (the preload F_p), > 0.
    mass_kg : float
        The particle's mass [kg], > 0.
    timestep_s : float
        Integration step [s], > 0.
    max_time_s : float
        Longest slide [s]; a particle still moving then ends ``TIMED_OUT``.
    drive_force_n : float
        A constant drive force along +x [N] (0: gravity alone, a fall), besides the spring.
    spring_n_m : float
        Stiffness ``k`` [N/m] of a spring along x from the carriage to the particle (0: none).
    carriage_speed_m_s : float
        The carriage's speed along +x [m/s] (0: it stays where it is).
    """

    mu: float
    load_n: float
    mass_kg: float
    timestep_s: float
    max_time_s: float
    drive_force_n: float = 0.0
    spring_n_m: float = 0.0
    carriage_speed_m_s: float = 0.0

    def __post_init__(self):
        check_positive("mu", self.mu, allow_zero=True)
        for name in ("load_n", "mass_kg", "timestep_s", "max_time_s"):
            check_positive(name, getattr(self, name))
        for name in ("spring_n_m", "carriage_speed_m_s"):
            check_positive(name, getattr(self, name), allow_zero=True)
        if not math.isfinite(self.drive_force_n):
            raise SpineInputError(f"drive_force_n must be a finite force [N], got {self.drive_force_n!r}")
        if self.max_time_s / self.timestep_s > 1e8:
            raise SpineInputError(
                "max_time_s / timestep_s must be at most 1e8 steps, "
                f"got {self.max_time_s / self.timestep_s:.3g}"
            )


@dataclass(frozen=True)
class SlideResult:
    """Where each particle came to rest, ``(k,)`` arrays in the surface's units.

    Attributes
    ----------
    x, y, z : ndarray
        End position.
    time_s : ndarray
        Time of the ending [s].
    path_length : ndarray
        Length of the 3-D path travelled (flights included).
    outcome : ndarray of int8
        :class:`SlideOutcome` values.
    max_speed_m_s : ndarray
        Largest speed reached.
    airborne_steps : ndarray of int64
        Steps spent off the surface.
    spring_force_n : ndarray
        The spring's pull along +x at the end [N] (0 without a spring).
    paths : list of ndarray or None
        With ``store_paths``: each particle's horizontal path ``(n_i, 2)``, one point a
        step, from its start to its end.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    time_s: np.ndarray
    path_length: np.ndarray
    outcome: np.ndarray
    max_speed_m_s: np.ndarray
    airborne_steps: np.ndarray
    spring_force_n: np.ndarray
    paths: list | None = None


def slide_until_stuck(
    surface,
    starts,
    params: SlideParams,
    *,
    velocity_m_s=None,
    length_scale_m: float = 1.0,
    carriage_x=None,
    held=None,
    settled_speed_m_s: float = 0.0,
    bounds=None,
    store_paths: bool = False,
) -> SlideResult:
    """Slide particles from ``starts`` ``(k, 2)`` (surface units, on the surface) until each
    sticks, leaves the bounds or times out.

    Parameters
    ----------
    surface : Surface
        Anything with ``evaluate(x, y, order)`` (order 2, or 1 where it has no Hessian)
        and ``bounds`` (in its own units).
    starts : array_like, shape (k, 2)
        Start points (x, y).
    params : SlideParams
    velocity_m_s : array_like, shape (k, 2), optional
        Initial horizontal velocity [m/s] (none: at rest); the vertical follows the surface.
    length_scale_m : float
        Metres per surface unit (forces and masses are SI, lengths are scaled once here).
    carriage_x : array_like, shape (k,), optional
        Each spring's carriage at the start (surface units; none: above the start, the
        spring slack).
    held : callable, optional
        ``held(x, y) -> bool (m,)`` (surface units): where a particle at rest ends its
        slide; none: wherever it rests.
    settled_speed_m_s : float
        A particle on the surface at most this fast counts as at rest (0: only at rest).
        With a moving carriage and a spring without damping, a particle may slide on with
        the carriage for good, its speed swinging between 0 and ``2 v`` (it never rests
        where steady sliding is the quasistatic motion): ``2 v`` ends it there.
    bounds : tuple of float, optional
        ``(xmin, xmax, ymin, ymax)``: a particle outside ends ``LEFT_DOMAIN`` (none: the
        surface's bounds).
    store_paths : bool
        Keep each particle's path (:attr:`SlideResult.paths`).

    Returns
    -------
    SlideResult
    """
    p = params
    s = check_positive("length_scale_m", length_scale_m)
    starts, v0 = _checked(starts, velocity_m_s)
    anchor = starts[:, 0].copy() if carriage_x is None else np.asarray(carriage_x, dtype=float).reshape(-1)
    if anchor.shape != (len(starts),) or not np.isfinite(anchor).all():
        raise SpineInputError(f"carriage_x must be {len(starts)} finite positions, got shape {anchor.shape}")
    settled = check_positive("settled_speed_m_s", settled_speed_m_s, allow_zero=True)
    run = _Run(surface, p, s, starts, v0, anchor * s, surface.bounds if bounds is None else bounds)
    steps = [] if store_paths else None
    for step in range(1, int(math.ceil(p.max_time_s / p.timestep_s)) + 1):
        if not run.step(step, held, settled, steps):
            break
    return run.result(None if steps is None else _assemble(starts, steps))


class _Run:
    """The particles' state through a slide (:func:`slide_until_stuck`), SI."""

    def __init__(self, surface, p: SlideParams, s: float, starts, v0, anchor, bounds):
        self.surface, self.p, self.s, self.anchor, self.bounds = surface, p, s, anchor, bounds
        self.hessian = _has_hessian(surface, starts)
        k = len(starts)
        self.q = starts * s  # horizontal position [m]
        self.here = self.ev(self.q)  # the surface under each particle, carried from step to step
        self.z, fx0, fy0 = self.here[:3]
        self.vel = np.column_stack([v0, fx0 * v0[:, 0] + fy0 * v0[:, 1]])  # 3-D velocity [m/s]
        self.active = np.ones(k, bool)
        self.airborne = np.zeros(k, bool)
        self.outcome = np.full(k, SlideOutcome.TIMED_OUT, np.int8)
        self.t_end = np.full(k, p.max_time_s)
        self.length = np.zeros(k)
        self.vmax = np.linalg.norm(self.vel, axis=1)
        self.n_air = np.zeros(k, np.int64)

    def ev(self, q, order=2):
        return _surface_at(self.surface, q, self.s, order, self.hessian)

    def applied(self, i, x, t) -> np.ndarray:
        """The applied force A [N] ``(m, 3)`` on particles ``i`` at ``x`` [m] at time ``t`` [s]."""
        p = self.p
        f = np.zeros((i.size, 3))
        f[:, 0] = p.drive_force_n + p.spring_n_m * (self.anchor[i] + p.carriage_speed_m_s * t - x)
        f[:, 2] = -p.load_n
        return f

    def step(self, step: int, held, settled: float, steps) -> bool:
        """Advance the active particles one step (the ``step``-th); False when none is left."""
        p, s, idx = self.p, self.s, np.flatnonzero(self.active)
        if not idx.size:
            return False
        qa, va, za, air = self.q[idx], self.vel[idx], self.z[idx], self.airborne[idx]
        force = self.applied(idx, qa[:, 0], (step - 1) * p.timestep_s)
        here = [c[idx] for c in self.here]
        new_q, new_z, new_v, flying, f_new = _advance(self.ev, qa, va, za, air, here, force, p)
        for c, c_new in zip(self.here, f_new):
            c[idx] = c_new
        landed = flying & (new_z <= f_new[0])  # a flight that meets the surface lands
        new_z = np.where(~flying | landed, f_new[0], new_z)  # contact keeps to the surface
        on = ~flying | landed
        # without a Hessian a step onto a face tilted into the velocity is a crease's impact
        impact = landed if self.hessian else on
        new_v[on] = _landed_velocity(new_v[on], f_new[1][on], f_new[2][on], impact[on], p.mu)
        self.length[idx] += np.sqrt(np.sum((new_q - qa) ** 2, axis=1) + (new_z - za) ** 2)
        self.q[idx], self.vel[idx], self.z[idx] = new_q, new_v, new_z
        self.airborne[idx] = flying & ~landed
        self.n_air[idx] += flying & ~landed
        sp = np.linalg.norm(new_v, axis=1)
        self.vmax[idx] = np.maximum(self.vmax[idx], sp)
        if steps is not None:
            steps.append((idx, new_q / s))
        xmin, xmax, ymin, ymax = (b * s for b in self.bounds)
        out = ~((new_q[:, 0] >= xmin) & (new_q[:, 0] <= xmax) & (new_q[:, 1] >= ymin) & (new_q[:, 1] <= ymax))
        stuck = ~out & on & (sp <= settled)
        if held is not None and stuck.any():
            stuck[stuck] = np.asarray(held(new_q[stuck, 0] / s, new_q[stuck, 1] / s), dtype=bool)
        for mask, kind in ((out, SlideOutcome.LEFT_DOMAIN), (stuck, SlideOutcome.STUCK)):
            hit = idx[mask]
            self.outcome[hit], self.t_end[hit], self.active[hit] = kind, step * p.timestep_s, False
        return True

    def result(self, paths) -> SlideResult:
        p, s, q = self.p, self.s, self.q
        return SlideResult(
            x=q[:, 0] / s,
            y=q[:, 1] / s,
            z=self.z / s,
            time_s=self.t_end,
            path_length=self.length / s,
            outcome=self.outcome,
            max_speed_m_s=self.vmax,
            airborne_steps=self.n_air,
            spring_force_n=p.spring_n_m * (self.anchor + p.carriage_speed_m_s * self.t_end - q[:, 0]),
            paths=paths,
        )


def _assemble(starts: np.ndarray, steps: list) -> list[np.ndarray]:
    """Each particle's path ``(n_i, 2)``: its start, then its position after each step it took."""
    if not steps:
        return [row[None, :].copy() for row in starts]
    idx = np.concatenate([i for i, _ in steps])
    pts = np.vstack([q for _, q in steps])
    order = np.argsort(idx, kind="stable")
    idx, pts = idx[order], pts[order]
    cuts = np.searchsorted(idx, np.arange(len(starts) + 1))
    return [np.vstack([starts[i], pts[cuts[i] : cuts[i + 1]]]) for i in range(len(starts))]


def _has_hessian(surface, starts: np.ndarray) -> bool:
    """Whether ``surface`` evaluates curvatures (order 2); a ball on facets does not."""
    try:
        surface.evaluate(starts[:1, 0], starts[:1, 1], order=2)
    except SpineInputError:
        return False
    return True


def _surface_at(surface, q: np.ndarray, s: float, order: int, hessian: bool = True):
    """Height [m] (order 0), or height, slopes and curvatures [1/m] (order 2; zero curvatures
    where the surface has no Hessian) at ``q`` [m]."""
    if order == 0:
        return surface.evaluate(q[:, 0] / s, q[:, 1] / s, order=0)[0] * s
    if not hessian:
        f, fx, fy = surface.evaluate(q[:, 0] / s, q[:, 1] / s, order=1)
        zero = np.zeros_like(np.asarray(f, dtype=float))
        return [np.array(c) for c in (f * s, fx, fy, zero, zero, zero)]
    f, fx, fy, fxx, fxy, fyy = surface.evaluate(q[:, 0] / s, q[:, 1] / s, order=2)
    return [np.array(c) for c in (f * s, fx, fy, fxx / s, fxy / s, fyy / s)]


def _contact_velocity(v, n, normal, force, p: SlideParams) -> np.ndarray:
    """One step's velocity in contact: the applied force's tangential part added, then the
    friction impulse ``mu N dt`` taken away along the velocity, clamped at rest."""
    u = v + p.timestep_s * force / p.mass_kg
    u -= np.sum(u * n, axis=1)[:, None] * n  # in the tangent plane
    speed = np.linalg.norm(u, axis=1)
    cut = p.mu * normal * p.timestep_s / p.mass_kg
    keep = np.where(speed > cut, 1 - cut / np.where(speed > 0, speed, 1.0), 0.0)
    return u * keep[:, None]


def _landed_velocity(v, fx, fy, landed, mu: float) -> np.ndarray:
    """Velocities on the surface of slopes ``fx, fy``: in its tangent plane; where the
    particle ``landed`` the normal velocity into the surface is lost and friction takes up
    to ``mu`` times that impulse off the tangential one."""
    n = np.column_stack([-fx, -fy, np.ones_like(fx)])
    n /= np.linalg.norm(n, axis=1)[:, None]
    vn = np.sum(v * n, axis=1)
    ut = v - vn[:, None] * n
    sp = np.linalg.norm(ut, axis=1)
    cut = np.where(landed, mu * np.maximum(-vn, 0.0), 0.0)
    keep = np.where(sp > cut, 1 - cut / np.where(sp > 0, sp, 1.0), 0.0)
    return ut * keep[:, None]


def _advance(ev, qa, va, za, air, here, force, p: SlideParams):
    """One step of particles at ``qa, za`` with velocity ``va`` (``air``: flying) on the
    surface ``here`` under them, under the applied forces ``force`` ``(m, 3)``: new
    position, height and velocity, who flies, and the surface (:func:`_surface_at`) at the
    new position."""
    dt, m = p.timestep_s, p.mass_kg
    _, fx, fy, fxx, fxy, fyy = here
    g = np.sqrt(1 + fx * fx + fy * fy)
    n = np.column_stack([-fx, -fy, np.ones_like(fx)]) / g[:, None]
    vx, vy = va[:, 0], va[:, 1]
    curv = fxx * vx * vx + 2 * fxy * vx * vy + fyy * vy * vy
    normal = (-force[:, 2] + fx * force[:, 0] + m * curv) / g
    # where the surface drops away faster than a free fall from here, the tip leaves it
    # (the discrete N < 0: a step past a ledge narrower than the step)
    free_v = va + dt * force / m
    free_q = qa + dt * free_v[:, :2]
    free_z = za + dt * free_v[:, 2]
    leaves = ~air & ((normal < 0) | (ev(free_q, order=0) < free_z))
    new_v = va.copy()
    new_q, new_z = qa.copy(), za.copy()
    flying = air | leaves
    # flight: gravity and drive only
    new_v[flying], new_q[flying], new_z[flying] = free_v[flying], free_q[flying], free_z[flying]
    # contact: tangential force, then the friction impulse clamped at rest
    on = ~flying
    new_v[on] = _contact_velocity(va[on], n[on], np.maximum(normal[on], 0.0), force[on], p)
    new_q[on] += dt * new_v[on, :2]
    return new_q, new_z, new_v, flying, ev(new_q)


def _checked(starts, velocity_m_s) -> tuple[np.ndarray, np.ndarray]:
    """``starts`` ``(k, 2)`` and the initial velocities ``(k, 2)`` (zero when none), finite."""
    starts = np.asarray(starts, dtype=float)
    if starts.ndim != 2 or starts.shape[1] != 2 or not np.isfinite(starts).all():
        raise SpineInputError(f"starts must be finite (x, y) pairs of shape (k, 2), got shape {starts.shape}")
    k = len(starts)
    v0 = np.zeros((k, 2)) if velocity_m_s is None else np.asarray(velocity_m_s, dtype=float)
    if v0.shape != (k, 2) or not np.isfinite(v0).all():
        raise SpineInputError(f"velocity_m_s must be finite, of shape ({k}, 2), got shape {v0.shape}")
    return starts, v0
