"""Energy accounting of a MuJoCo run: where the drive's work goes, and what a spring releases.

Why a soft spring breaks the quasistatic picture, in numbers: a spring of stiffness ``k``
holding a force ``F`` stores ``F^2 / (2 k)``. When the tip breaks away, the force drops
and the stored energy goes into the tip's motion whatever the carriage speed, so a run at
``I_e -> 0`` still jumps when that release is large against the work the quasistatic
drive does along the path (``W_qs = F_p integral kappa dx``, paper Eq. 1). The drive
stiffness number ``K = k l_s / F_p`` (``l_s``: :func:`spine_mj.roughness.slope_correlation_length`)
measures the same thing: a release ``F^2 / (2k) = (F / F_p)^2 F_p l_s / (2 K)`` is a small
part of the work over one slope correlation length only when ``K`` is large.

:func:`energy_budget` splits a spring run's energy: the carriage's work
``W_c = integral F v_c dt`` goes into the spring (``d(F^2 / 2k)``) and onto the tip
(``W_drive = integral F v_x dt``); of the latter, ``dKE + F_p dz`` stays with the tip and the
rest is dissipated by the contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spine_mj.errors import check_positive

__all__ = ["EnergyBudget", "elastic_release_j", "energy_budget", "quasistatic_work_j"]


def _integral(y: np.ndarray, t: np.ndarray) -> float:
    """Trapezoid rule, NaN samples counted as 0."""
    y = np.nan_to_num(np.asarray(y, dtype=float))
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t))) if t.size > 1 else 0.0


@dataclass(frozen=True)
class EnergyBudget:
    """Work and energy of a run's drive phase [J].

    Attributes
    ----------
    drive_work_j : float
        Work of the drive force on the tip, ``integral F_drive v_x dt``.
    carriage_work_j, spring_energy_change_j : float
        Spring drive only (else NaN): the carriage's work ``integral F v_c dt`` and the
        change of the stored energy ``F^2 / (2 k)``.
    kinetic_change_j, potential_change_j : float
        ``dKE`` and ``F_p dz`` (gravity and the constant preload).
    contact_dissipation_j : float
        ``W_drive - dKE - F_p dz``: what friction (and the soft contact) took.
    elastic_release_j : float
        Spring energy released during slip events, ``sum (F_onset^2 - F_stop^2) / (2 k)``
        (0 for force drives).
    """

    drive_work_j: float
    carriage_work_j: float
    spring_energy_change_j: float
    kinetic_change_j: float
    potential_change_j: float
    elastic_release_j: float

    @property
    def contact_dissipation_j(self) -> float:
        return self.drive_work_j - self.kinetic_change_j - self.potential_change_j

    @property
    def spring_residual_j(self) -> float:
        """``W_c - d(F^2/2k) - W_drive``: zero up to integration error for a spring drive."""
        return self.carriage_work_j - self.spring_energy_change_j - self.drive_work_j


def elastic_release_j(drive_force_n, stiffness_n_m: float, spans) -> float:
    """Spring energy released over the slip events of a run [J].

    ``spans``: ``(onset, stop)`` rows of each slip (:class:`spine_mj.theory.motion.SlipEvent`'s
    ``onset`` and ``stop``); each releases ``(F_onset^2 - F_stop^2) / (2 k)``, an increase
    of the stored energy counting 0.
    """
    k = check_positive("stiffness_n_m", stiffness_n_m)
    force = np.asarray(drive_force_n, dtype=float)
    return float(sum(max(0.0, (force[i] ** 2 - force[j] ** 2) / (2 * k)) for i, j in spans))


def quasistatic_work_j(kappa_along_path, x_m, preload_n: float) -> float:
    """Work of a quasistatic drive along a path, ``F_p integral kappa dx`` [J] (paper Eq. 1:
    the drive force at every point is ``kappa W``); self-locked or slip points count 0."""
    k = np.asarray(kappa_along_path, dtype=float)
    k = np.where(np.isfinite(k), k, 0.0)
    return check_positive("preload_n", preload_n) * _integral(k, np.asarray(x_m, dtype=float))


def energy_budget(result, *, stiffness_n_m: float | None = None) -> EnergyBudget:
    """The :class:`EnergyBudget` of a :class:`spine_mj.sim.RunResult` after its settle phase.

    ``stiffness_n_m`` is the spring drive's (None for the force drives: the spring terms
    are NaN and nothing is released).
    """
    i0 = result.drive_start_index
    t = result.time_s[i0:]
    v = result.velocity_m_s[i0:]
    force = result.drive_force_n[i0:]
    speed2 = np.einsum("ij,ij->i", v, v)
    kinetic = 0.5 * result.tip.mass_kg * (speed2[-1] - speed2[0]) if t.size else 0.0
    dz = result.position_m[-1, 2] - result.position_m[i0, 2] if t.size else 0.0
    carriage = spring = float("nan")
    release = 0.0
    if stiffness_n_m is not None:
        k = check_positive("stiffness_n_m", stiffness_n_m)
        carriage = _integral(force * np.gradient(result.carriage_x_m[i0:], t), t) if t.size > 1 else 0.0
        spring = float((force[-1] ** 2 - force[0] ** 2) / (2 * k)) if t.size else 0.0
        spans = [(e.onset, e.stop) for e in result.slip_events if e.onset >= i0]
        release = elastic_release_j(result.drive_force_n, k, spans)
    return EnergyBudget(
        drive_work_j=_integral(force * v[:, 0], t),
        carriage_work_j=carriage,
        spring_energy_change_j=spring,
        kinetic_change_j=float(kinetic),
        potential_change_j=float(result.tip.preload_total_n * dz),
        elastic_release_j=release,
    )
