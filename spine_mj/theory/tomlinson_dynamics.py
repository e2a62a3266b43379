"""A reference integrator of the Prandtl-Tomlinson dynamics with Coulomb friction.

A point mass ``m`` constrained to a profile ``z = f(x)`` (the path of the tip's centre),
pulled along x by a spring ``k (X - x)`` whose carriage moves at ``X = X0 + V t``, pressed
by a load ``W`` along -z, with one Coulomb coefficient ``mu`` (static = kinetic, as in
MuJoCo). Independent of the MuJoCo rig: it checks what inertia alone does on a corrugation
(docs/physics.md, "Ground truth").

While sliding (``sigma = -mu sign(x')``) the normal force and the motion follow from the
constraint (``g = sqrt(1 + f'^2)``, ``F = k (X - x)``)::

    N   = (W + f' F + m f'' x'^2) / g
    m x'' = F + N (sigma - f') / g

A stuck tip stays while ``W kappa_b(x) <= F <= W kappa(x)``,
``kappa = (f' + mu) / (1 - mu f')`` (forward) and ``kappa_b = (f' - mu) / (1 + mu f')``
(backward); since ``F`` grows at ``k V`` while stuck, the release time is exact. Slides are
integrated by :func:`scipy.integrate.solve_ivp` (DOP853) up to ``x' = 0`` or ``N = 0``
(lift-off, which ends the run). The trajectory is sampled on a uniform grid so that
:mod:`spine_mj.theory.motion` classifies it exactly as it does a MuJoCo run.

Analytic side: numpy and scipy only, no MuJoCo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.theory.motion import SlipEvent, motion_states, slip_events


@dataclass(frozen=True)
class SineProfile:
    """``z = h sin(2 pi x / lambda)`` with ``h = slope_amplitude lambda / (2 pi)`` (0: flat)."""

    slope_amplitude: float
    wavelength: float = 1.0

    def derivatives(self, x):
        """``(f', f'')`` at ``x``."""
        q = 2 * math.pi / self.wavelength
        return self.slope_amplitude * np.cos(q * x), -self.slope_amplitude * q * np.sin(q * x)


@dataclass(frozen=True)
class PTParams:
    """The rig of :func:`integrate` (SI or any consistent units).

    Attributes
    ----------
    mass_kg, stiffness_n_m, load_n, speed_m_s, mu : float
        ``m``, ``k``, ``W``, carriage speed ``V``, Coulomb coefficient.
    """

    mass_kg: float
    stiffness_n_m: float
    load_n: float
    speed_m_s: float
    mu: float

    def __post_init__(self):
        for name in ("mass_kg", "stiffness_n_m", "load_n", "speed_m_s", "mu"):
            check_positive(name, getattr(self, name))

    @property
    def omega_rad_s(self) -> float:
        return math.sqrt(self.stiffness_n_m / self.mass_kg)


@dataclass(frozen=True)
class PTRun:
    """Result of :func:`integrate`: samples every ``dt`` (time, tip x, x-speed, carriage X,
    spring force ``k (X - x)``, normal force), the slip events of :mod:`spine_mj.theory.motion`
    and whether the tip lifted off (the run then ends there)."""

    time_s: np.ndarray
    x_m: np.ndarray
    speed_m_s: np.ndarray
    carriage_m: np.ndarray
    force_n: np.ndarray
    normal_n: np.ndarray
    events: list[SlipEvent]
    lifted_off: bool


def _rhs(p: PTParams, profile, sigma: float, x0_carriage: float):
    def f(t, y):
        x, v = y
        fp, fpp = profile.derivatives(x)
        g = math.sqrt(1 + fp * fp)
        force = p.stiffness_n_m * (x0_carriage + p.speed_m_s * t - x)
        normal = (p.load_n + fp * force + p.mass_kg * fpp * v * v) / g
        return [v, (force + normal * (sigma - fp) / g) / p.mass_kg]

    return f


def _normal(p: PTParams, profile, t, x, v, carriage0):
    fp, fpp = profile.derivatives(x)
    force = p.stiffness_n_m * (carriage0 + p.speed_m_s * t - x)
    return force, (p.load_n + fp * force + p.mass_kg * fpp * v * v) / np.sqrt(1 + fp * fp)


def _cone(p: PTParams, profile, x: float) -> tuple[float, float]:
    """Spring forces at which a tip stuck at ``x`` slips backward and forward."""
    fp, _ = profile.derivatives(x)
    mu = p.mu
    if not mu * fp < 1:
        raise SpineInputError(f"mu * slope must stay below 1 (self-lock), got {mu * fp!r}")
    return p.load_n * (fp - mu) / (1 + mu * fp), p.load_n * (fp + mu) / (1 - mu * fp)


def integrate(p: PTParams, profile, x0: float, duration_s: float, dt_s: float, rtol: float = 1e-9) -> PTRun:
    """Run the carriage from ``x0`` (spring relaxed, tip at rest) for ``duration_s``,
    sampled every ``dt_s``; see the module docstring for the equations."""
    check_positive("duration_s", duration_s)
    check_positive("dt_s", dt_s)
    k, V = p.stiffness_n_m, p.speed_m_s
    grid = np.arange(0.0, duration_s + 0.5 * dt_s, dt_s)
    xs, vs = np.full(grid.size, np.nan), np.zeros(grid.size)
    t, x, v, lifted = 0.0, float(x0), 0.0, False
    max_step = 0.05 * 2 * math.pi / p.omega_rad_s
    while t < duration_s and not lifted:
        if v == 0.0:
            lo, hi = _cone(p, profile, x)
            force = k * (x0 + V * t - x)
            if force < lo:
                sigma = p.mu  # slides backward
            else:
                t_go = max(t, (hi / k + x - x0) / V) if force <= hi else t
                m = (grid >= t) & (grid < t_go)
                xs[m], vs[m] = x, 0.0
                t, sigma = t_go, -p.mu
                if t >= duration_s:
                    break
        else:
            sigma = -p.mu * math.copysign(1.0, v)

        def stop(tt, y, s=sigma):
            return y[1] if s < 0 else -y[1]

        def lift(tt, y):
            return _normal(p, profile, tt, y[0], y[1], x0)[1]

        stop.terminal, stop.direction = True, -1
        lift.terminal, lift.direction = True, -1
        sol = solve_ivp(
            _rhs(p, profile, sigma, x0),
            (t, duration_s),
            [x, v if v else -sigma * 1e-12 * V],
            method="DOP853",
            events=(stop, lift),
            dense_output=True,
            rtol=rtol,
            atol=1e-12 * max(abs(x0), 1.0),
            max_step=max_step,
        )
        m = (grid >= t) & (grid <= sol.t[-1])
        xs[m], vs[m] = sol.sol(grid[m])
        stalled = sol.t[-1] <= t  # a slide stopped where it began, at the cone's edge
        t, x = float(sol.t[-1]), float(sol.y[0, -1])
        lifted = sol.t_events[1].size > 0
        v = 0.0 if sol.t_events[0].size else float(sol.y[1, -1])
        if stalled and v == 0.0:  # stay stuck one sample: the spring loads past the edge
            m = (grid >= t) & (grid < t + dt_s)
            xs[m], vs[m], t = x, 0.0, t + dt_s
    keep = np.isfinite(xs)
    return _sampled(p, profile, grid[keep], xs[keep], vs[keep], x0, lifted)


def _sampled(p, profile, t, x, v, x0, lifted) -> PTRun:
    force, normal = _normal(p, profile, t, x, v, x0)
    vel = np.zeros((t.size, 3))
    vel[:, 0] = v
    states = motion_states(vel, p.speed_m_s)
    return PTRun(
        time_s=t,
        x_m=x,
        speed_m_s=v,
        carriage_m=x0 + p.speed_m_s * t,
        force_n=force,
        normal_n=normal,
        events=slip_events(states, t, x, force, v),
        lifted_off=lifted,
    )
