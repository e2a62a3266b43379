"""The quasistatic array reference: the array's force-displacement curve is the sum of its spines'.

Under displacement control each spine keeps its own spring to the carriage, so at carriage
position ``X`` the array carries ``S(X) = sum_i F_i(X)``, each ``F_i`` the spine's own
quasistatic force-displacement curve (docs/physics.md, "Load sharing"). Under force control
the carriage moves only forward while the pull rises, so each spine stays on its forward
branch and the carriage sits at the first ``X`` where ``S(X)`` reaches the pull: the array
first lets go at the first fold of ``S`` (where it turns down), jumps forward, and is caught
again where ``S`` climbs back to that pull (re-engagement); it lets go for good at the
largest ``S`` on the reachable route. :func:`force_control_release` says which.

A spine's curve on a 1-D profile ``z = f(x)`` (uniform in y, pulled along x through a
spring ``k``) is the Prandtl-Tomlinson closed form (:func:`profile_spine_curve`): the tip
sits where ``k (X - x) = W kappa``, ``kappa = tan(theta + arctan mu)`` at the contact's
slope, on the forward branch (a fold jumps to the next equilibrium ahead). Pure numpy; no
MuJoCo.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive


def forward_branch(x: np.ndarray, carriage: np.ndarray, query: np.ndarray) -> np.ndarray:
    """Indices into ``x`` of the tip's quasistatic positions at carriage positions ``query``.

    ``carriage[j]`` is the carriage position that holds the tip in equilibrium at ``x[j]``
    (``x`` increasing). Dragged forward, the tip stays at the first equilibrium ahead of it:
    at carriage ``X`` it sits at the first ``x`` whose running maximum of ``carriage``
    reaches ``X`` (a fold, where ``carriage`` turns down, becomes a jump forward).
    """
    reach = np.maximum.accumulate(np.asarray(carriage, dtype=float))
    idx = np.searchsorted(reach, np.asarray(query, dtype=float), side="left")
    return np.clip(idx, 0, len(x) - 1)


def profile_spine_curve(
    carriage: np.ndarray,
    *,
    x0: float,
    slope: Callable[[np.ndarray], np.ndarray],
    mu: float,
    spring_per_preload: float,
    tip_radius: float = 0.0,
    resolution: float | None = None,
) -> np.ndarray:
    """A spine's quasistatic force over preload, ``F / W``, at carriage displacements
    ``carriage`` on a 1-D profile (Prandtl-Tomlinson with Coulomb friction,
    docs/physics.md §6): the spring starts relaxed with the tip resting at ``x0``; the tip
    sticks (force ``k X``) until the force reaches ``W kappa(x0)``, then follows the forward
    branch of ``k (X - x) = W kappa(x)``.

    Parameters
    ----------
    carriage : (m,) array
        Carriage displacement from the start, increasing, >= 0 (the profile's length unit).
    x0 : float
        The tip centre's start.
    slope : callable
        ``f'(x)`` of the profile ``z = f(x)`` (vectorized).
    mu : float
        Friction coefficient.
    spring_per_preload : float
        ``k / W`` [1 / length]: the spring's stiffness over the preload.
    tip_radius : float
        The tip's radius: the contact sits below the centre at ``x = xc - r f' / sqrt(1 +
        f'^2)`` and kappa is that of the contact's slope.
    resolution : float or None
        Sampling step of the contact position (default: ``1e-5`` of the route).

    Returns
    -------
    (m,) array
        The spring's force over ``W`` at each carriage position.
    """
    kk = check_positive("spring_per_preload", spring_per_preload)
    mu = check_positive("mu", mu, allow_zero=True)
    carriage = np.asarray(carriage, dtype=float)
    if carriage.ndim != 1 or carriage.size == 0 or np.any(np.diff(carriage) < 0) or carriage[0] < 0:
        raise SpineInputError("carriage must be a non-empty increasing 1-D array of displacements >= 0")
    xc0 = float(x0)
    for _ in range(50):  # the contact under a centre at x0
        s0 = float(slope(np.array([xc0]))[0])
        xc0 = x0 + tip_radius * s0 / math.sqrt(1 + s0**2)
    span = float(carriage[-1]) + 2 * tip_radius
    h = resolution or max(span, 1e-12) * 1e-5
    xc = xc0 + np.arange(0.0, span + h, h)
    s = slope(xc)
    x_centre = xc - tip_radius * s / np.sqrt(1 + s**2)
    kappa = np.tan(np.minimum(np.arctan(s) + math.atan(mu), math.pi / 2 - 1e-12))
    hold = x_centre - x0 + kappa / kk  # carriage displacement that holds the tip at x_centre
    at = forward_branch(x_centre, hold, carriage)
    return np.where(carriage < hold[0], kk * carriage, kappa[at])


def summed_curve(curves: Sequence[np.ndarray]) -> np.ndarray:
    """The array's curve: the spines' curves (each ``(m,)`` on one carriage grid) summed."""
    stack = np.asarray(curves, dtype=float)
    if stack.ndim != 2:
        raise SpineInputError(f"curves must be N arrays of one length, got shape {stack.shape}")
    return stack.sum(axis=0)


@dataclass(frozen=True)
class Release:
    """What a monotone pull does to an array whose forward curve is ``S(X)``.

    Attributes
    ----------
    first_let_go : float
        The pull at which the carriage first jumps (``S`` at its first fold; the largest
        ``S`` if it never turns down).
    holding : float
        The pull it lets go at for good: the largest ``S`` on the route, if every jump is
        caught by re-engaging spines.
    caught : bool
        Whether a jump is caught again on the route (``holding > first_let_go``): a
        dynamic array may not be, its carriage running on past the catch.
    first_let_go_x, holding_x : float
        Carriage positions of the two.
    """

    first_let_go: float
    holding: float
    caught: bool
    first_let_go_x: float
    holding_x: float


def force_control_release(carriage: np.ndarray, total: np.ndarray, *, rel_tol: float = 1e-6) -> Release:
    """:class:`Release` of a force-controlled array from its forward curve ``total`` at
    carriage positions ``carriage`` (increasing). A drop or a later peak counts when it
    exceeds ``rel_tol`` of the curve's largest magnitude (equal peaks of a periodic
    profile are not a catch)."""
    total = np.asarray(total, dtype=float)
    carriage = np.asarray(carriage, dtype=float)
    if total.shape != carriage.shape or total.ndim != 1 or total.size == 0:
        raise SpineInputError("carriage and total must be 1-D arrays of one length")
    run = np.maximum.accumulate(total)
    scale = max(float(np.abs(total).max()), 1e-300)
    drops = np.flatnonzero(total < run - rel_tol * scale)
    j_best = int(np.argmax(total))
    if drops.size == 0:
        return Release(float(total[j_best]), float(total[j_best]), False, carriage[j_best], carriage[j_best])
    j_first = int(np.argmax(total[: drops[0]])) if drops[0] > 0 else 0
    first = float(total[j_first])
    caught = float(total[j_best]) > first * (1 + rel_tol)
    return Release(first, float(total[j_best]), caught, float(carriage[j_first]), float(carriage[j_best]))


#: Outcomes of a compliant path that hold the spine where it ended (its spring then
#: stretches to the cap): the self-lock region, the force cap, and a stall (a tip wedged in
#: a crease, which a single-contact path cannot leave; docs/physics.md §6, the V-groove).
_HELD = ("SELF_LOCKED", "FORCE_CAP", "STALLED")


def compliant_spine_curves(
    result, carriage: np.ndarray, *, kappa_cap: float
) -> tuple[np.ndarray, np.ndarray]:
    """Each spine's quasistatic force over preload at carriage displacements ``carriage``
    from a :class:`~spine_mj.theory.compliant_types.CompliantResult` (one path per spine, spring relaxed
    at the start).

    The spring stretches with the tip stuck until the first path point (``F = c X``),
    follows the path's carriage and force (a slip, the carriage still, drops the force to
    the landing's), and past the path's end either keeps stretching up to ``kappa_cap``
    (a held spine: self-locked, capped or stalled) or is NaN (it left the domain).

    Returns
    -------
    forces : (N, m) array
    locked : (N,) bool
        Spines that reach ``kappa_cap`` within ``carriage``.
    """
    from spine_mj.theory.streamline_types import Outcome

    carriage = np.asarray(carriage, dtype=float)
    c = float(result.stiffness)
    held_codes = [int(getattr(Outcome, name)) for name in _HELD]
    n = len(result)
    forces = np.full((n, carriage.size), np.nan)
    locked = np.zeros(n, dtype=bool)
    for i in range(n):
        p = result.path(i)
        x0 = float(result.start_x[i])
        car = np.concatenate([[x0], p["carriage"]]) - x0
        frc = np.concatenate([[0.0], p["force"]])
        ok = np.isfinite(car) & np.isfinite(frc)
        car, frc = np.maximum.accumulate(car[ok]), frc[ok]
        j = np.clip(np.searchsorted(car, carriage, side="right") - 1, 0, car.size - 1)
        nxt = np.minimum(j + 1, car.size - 1)
        span = car[nxt] - car[j]
        w = np.where(span > 0, (carriage - car[j]) / np.where(span > 0, span, 1.0), 0.0)
        f = frc[j] + np.clip(w, 0, 1) * (frc[nxt] - frc[j])
        beyond = carriage > car[-1]
        if int(result.outcome[i]) in held_codes:
            f = np.where(beyond, np.minimum(frc[-1] + c * (carriage - car[-1]), kappa_cap), f)
            locked[i] = bool(np.any(f >= kappa_cap * (1 - 1e-9)))
        else:
            f = np.where(beyond, np.nan, f)
        forces[i] = np.minimum(f, kappa_cap)
    return forces, locked
