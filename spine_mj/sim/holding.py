"""How far an array's measured holding force lies above the quasistatic one, and the pace
that keeps it within a tolerance (docs/physics.md, "Numerical convergence").

A holding force is the quasistatic quantity only when the drive is slow and stiff enough.
Two dynamic excesses have closed forms, per spine in units of the preload ``F_p``:

* **The spring-block overshoot** (displacement control). A spring of stiffness ``k``
  pulled at speed ``V`` from rest against Coulomb friction: once it reaches the breakaway
  force ``F_s`` the tip (mass ``m``) slides as ``x(t) = V t - (V / w) sin(w t)``,
  ``w = sqrt(k / m)``, and the spring force swings to ``F_s + V sqrt(k m)``; in ``F_p``
  units that amplitude is ``sqrt(I_e K L_c / l_s)`` (``K = k l_s / F_p``,
  ``I_e = m V^2 / (F_p L_c)``). The array's holding force under displacement control is
  read where the array lets go (:class:`~spine_mj.sim.array_run.ArrayResult`): at the last
  step before every spine moves faster than :data:`~spine_mj.theory.motion.STUCK_SPEED_FRACTION`
  ``f V``. The tip's speed ``V (1 - cos(w t))`` reaches ``f V`` at ``cos(w t) = 1 - f``,
  where the spring has risen by ``sin(w t) = sqrt(2 f - f^2)`` of the swing: the reading's
  excess is ``sqrt(2 f - f^2) sqrt(I_e K L_c / l_s)`` (0.436 of the swing at ``f = 0.1``).
  On a plane rising at ``theta`` in the drive's direction the tip slides along the plane
  and the swing grows by ``1 / sqrt(cos(theta) (cos(theta) - mu sin(theta)))`` (1.11 at
  15 degrees and ``mu = 0.5``); the flat form is the one stated.
* **The force-rate lag** (force control). A pull rising at ``r`` per spine is read as
  held while the carriage moves slower than the pull's equivalent speed
  ``v_r = L_c r / F_p``. Past breakaway the excess pull ``r t`` accelerates at most the
  carriage and the tips, ``2 m`` per spine, to ``v_r`` in ``t = sqrt(4 m v_r / r) = 2 tau``,
  so the pull read as held lies at most ``2 r tau = 2 sqrt(I_e) F_p`` above breakaway (less
  when only the carriage, ``m`` per spine, has accelerated yet: ``sqrt(2 I_e) F_p``).

:func:`quasistatic_ie` inverts them: the fastest pace whose predicted excess is
:data:`HOLDING_TOLERANCE` of the flat plane's holding ``mu F_p`` (a surface that does not
descend along the drive holds at least that much).
"""

from __future__ import annotations

import math

from spine_mj.errors import check_positive
from spine_mj.sim.drives import DEFAULT_STIFFNESS_NUMBER
from spine_mj.sim.scales import Scales
from spine_mj.theory.motion import STUCK_SPEED_FRACTION

#: The predicted dynamic excess the default pace allows, as a fraction of ``mu F_p``.
HOLDING_TOLERANCE = 0.01
#: The share of the spring-block swing still in the displacement-controlled holding
#: reading, ``sqrt(2 f - f^2)`` with ``f`` the stuck-speed fraction (module docstring).
ONSET_SHARE = math.sqrt(2 * STUCK_SPEED_FRACTION - STUCK_SPEED_FRACTION**2)
#: The force-rate lag's bound, in ``sqrt(I_e) F_p`` (module docstring).
PULL_LAG_FACTOR = 2.0


def spring_swing(ie: float, stiffness_number: float, lc_over_ls: float) -> float:
    """The spring-block swing ``sqrt(I_e K L_c / l_s)`` [F_p]: how far the largest spring
    force of a spring dragged at ``I_e`` from rest lies above breakaway (flat plane)."""
    return math.sqrt(
        check_positive("I_e", ie)
        * check_positive("K", stiffness_number)
        * check_positive("L_c / l_s", lc_over_ls)
    )


def holding_excess(
    ie: float, *, force_control: bool, stiffness_number: float | None = None, lc_over_ls: float | None = None
) -> float:
    """The predicted excess of an array's holding reading over the quasistatic holding,
    per spine [F_p] (module docstring): ``ONSET_SHARE`` of the spring-block swing under
    displacement control, the force-rate lag ``2 sqrt(I_e)`` under force control.

    Parameters
    ----------
    ie : float
        The drive's inertia number (the carriage's speed, or the pull's rate per spine).
    force_control : bool
        A free carriage pulled by a force (True) or a carriage moving at constant speed.
    stiffness_number : float or None
        Each spring's ``K = k l_s / F_p`` (needed under displacement control).
    lc_over_ls : float or None
        The surface's ``L_c / l_s`` (needed under displacement control).

    Returns
    -------
    float
        The excess per spine in units of F_p.
    """
    if force_control:
        return PULL_LAG_FACTOR * math.sqrt(check_positive("I_e", ie))
    return ONSET_SHARE * spring_swing(ie, stiffness_number, lc_over_ls)


def quasistatic_ie(
    *,
    mu: float,
    force_control: bool,
    stiffness_number: float | None = None,
    lc_over_ls: float | None = None,
    tolerance: float = HOLDING_TOLERANCE,
) -> float:
    """The fastest pace (its inertia number) whose predicted holding excess
    (:func:`holding_excess`) is ``tolerance mu F_p`` per spine.

    Displacement control: ``I_e = (tolerance mu / ONSET_SHARE)^2 / (K L_c / l_s)``; force
    control: ``I_e = (tolerance mu / 2)^2``. On a flat plane at ``mu = 0.5``, ``K = 30``,
    ``L_c = l_s``: 4.4e-6 and 6.25e-6.
    """
    share = check_positive("tolerance", tolerance) * check_positive("mu", mu)
    if force_control:
        return (share / PULL_LAG_FACTOR) ** 2
    return (share / ONSET_SHARE) ** 2 / (
        check_positive("K", stiffness_number) * check_positive("L_c / l_s", lc_over_ls)
    )


def array_ie(scales: Scales, *, mu: float, force_control: bool, stiffness_n_m: float | None = None) -> float:
    """The arrays' default pace (:func:`quasistatic_ie` on ``scales``): the inertia number
    of the carriage's speed (displacement control) or of the pull's rate per spine (force
    control) whose predicted holding excess is :data:`HOLDING_TOLERANCE` ``mu F_p``.

    Parameters
    ----------
    scales : Scales
        The rig's scales (``L_c``, ``l_s``, ``F_p``).
    mu : float
        The tip's friction coefficient.
    force_control : bool
        A free carriage pulled by a force (True) or a carriage moving at constant speed.
    stiffness_n_m : float or None
        Each spring's stiffness [N/m] (None: the spring drive's default ``K``).

    Returns
    -------
    float
        The inertia number of the pace.
    """
    k = DEFAULT_STIFFNESS_NUMBER if stiffness_n_m is None else scales.stiffness_number(stiffness_n_m)
    return quasistatic_ie(
        mu=mu,
        force_control=force_control,
        stiffness_number=k,
        lc_over_ls=scales.char_length_m / scales.slope_length_m,
    )


__all__ = [
    "HOLDING_TOLERANCE",
    "ONSET_SHARE",
    "PULL_LAG_FACTOR",
    "array_ie",
    "holding_excess",
    "quasistatic_ie",
    "spring_swing",
]
