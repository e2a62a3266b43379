"""Closed forms for the dynamics of a tip on a spring (docs/physics.md, "Ground truth").

The answers the MuJoCo rig and every dynamic metric are checked against:

* the spring-block on a flat plane (:func:`spring_block_x`): after breakaway the block
  moves as ``x(t) = V t - (V / w) sin(w t)``, ``w = sqrt(k / m)``: period ``2 pi / w``,
  speed between 0 and 2 V;
* the Prandtl-Tomlinson model with Coulomb friction on a corrugation
  ``z = h sin(2 pi x / lambda)`` (:class:`Corrugation`): the quasistatic tip sits where
  ``k (X - x) = W kappa(x)``, so the motion is smooth iff
  ``K = k l_s / W > K* = l_s max(-dkappa/dx)``; below ``K*`` the tip jumps at the fold,
  where ``1 + (W / k) dkappa/dx`` first reaches 0, with the onset force ``W kappa`` there;
* lift-off over a crest (:func:`liftoff_inertia_number`): a tip carried at speed v leaves
  the surface where ``v^2`` times the path's curvature exceeds the normal acceleration
  ``F_p / m``, i.e. iff ``I_e > 1 / (L_c c)`` with ``c`` the largest convex curvature of
  the path of the tip's centre.

Analytic only: no MuJoCo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive

#: The slope correlation length of a corrugation over its wavelength,
#: ``arccos(1/e) / (2 pi)`` (:func:`spine_mj.roughness.slope_length`'s 1/e rule on a sine).
SLOPE_LENGTH_PER_WAVELENGTH = math.acos(1 / math.e) / (2 * math.pi)


def spring_block_x(t_s, speed_m_s: float, omega_rad_s: float):
    """Position after breakaway of a block pulled at ``speed_m_s`` through a spring on a flat
    plane with one friction coefficient: ``V t - (V / w) sin(w t)`` (t from breakaway)."""
    t = np.asarray(t_s, float)
    return speed_m_s * t - speed_m_s / omega_rad_s * np.sin(omega_rad_s * t)


def spring_block_period_s(stiffness_n_m: float, mass_kg: float) -> float:
    """Period ``2 pi / w`` of the spring-block's speed swing, ``w = sqrt(k / m)``."""
    return 2 * math.pi / math.sqrt(stiffness_n_m / mass_kg)


@dataclass(frozen=True)
class Corrugation:
    """The Prandtl-Tomlinson profile ``z = h sin(2 pi x / lambda)`` with Coulomb friction.

    Attributes
    ----------
    slope_amplitude : float
        ``s = 2 pi h / lambda``, the steepest slope; must stay below ``mu`` (no slip
        region) and ``1 / mu`` (no self-lock).
    mu : float
    wavelength : float
        ``lambda`` [any length unit; lengths below are in the same unit].
    tip_radius : float
        Radius of a spherical tip; the spring pulls its centre, which rides on the profile
        dilated by this radius (0: a point tip, the textbook case).
    """

    slope_amplitude: float
    mu: float
    wavelength: float = 1.0
    tip_radius: float = 0.0

    def __post_init__(self):
        s = check_positive("slope_amplitude", self.slope_amplitude)
        mu = check_positive("mu", self.mu)
        check_positive("wavelength", self.wavelength)
        check_positive("tip_radius", self.tip_radius, allow_zero=True)
        if not s < mu or not s * mu < 1:
            raise SpineInputError(
                f"slope_amplitude must lie below mu and 1/mu (engaged everywhere), got {s!r} with mu {mu!r}"
            )

    def _contact(self, n: int = 20001):
        """Contact points over one wavelength from a crest's steepest rising point (u = 0),
        with kappa and the centre's x there."""
        lam, s, mu = self.wavelength, self.slope_amplitude, self.mu
        u = np.linspace(0.0, 2 * math.pi, n)
        t = s * np.cos(u)  # the slope f'
        kappa = (t + mu) / (1 - mu * t)  # tan(theta + arctan mu)
        x_c = u * lam / (2 * math.pi)
        x = x_c - self.tip_radius * t / np.sqrt(1 + t * t)  # the centre, along the outward normal
        return x_c, x, kappa

    def slope_length(self) -> float:
        """``l_s = 0.190 lambda``."""
        return SLOPE_LENGTH_PER_WAVELENGTH * self.wavelength

    def max_kappa_drop_rate(self) -> float:
        """``max(-dkappa/dx)`` along the centre's x [1 / length]; for a point tip
        ``(1 + mu^2) s (2 pi / lambda) sin u / (1 - mu s cos u)^2`` at its largest."""
        _, x, kappa = self._contact()
        return float(np.max(-np.diff(kappa) / np.diff(x)))

    def critical_stiffness(self, slope_length: float | None = None) -> float:
        """``K* = l_s max(-dkappa/dx)``: the smallest stiffness number of a smooth slide
        (``slope_length`` default :meth:`slope_length`; pass the rig's own to compare)."""
        ls = self.slope_length() if slope_length is None else slope_length
        return ls * self.max_kappa_drop_rate()

    def fold(self, stiffness_number: float, slope_length: float | None = None) -> tuple[float, float]:
        """The fold of the stable branch at ``K = stiffness_number``: (x of the centre in
        one wavelength, from a steepest rising point; kappa there, the onset force over W).
        Raises when ``K >= K*`` (no fold: the slide is smooth)."""
        ls = self.slope_length() if slope_length is None else slope_length
        if stiffness_number >= self.critical_stiffness(ls):
            raise SpineInputError(f"no fold at K = {stiffness_number!r} >= K* (the motion is smooth)")
        _, x, kappa = self._contact()
        carriage = x + ls / stiffness_number * kappa  # X = x + W kappa / k
        i = int(np.flatnonzero(np.diff(carriage) < 0)[0])  # the first place X turns back
        return float(x[i]), float(kappa[i])

    def kappa_range(self) -> tuple[float, float]:
        """Smallest and largest kappa along the profile: ``(mu - s) / (1 + mu s)`` and
        ``(mu + s) / (1 - mu s)``."""
        s, mu = self.slope_amplitude, self.mu
        return (mu - s) / (1 + mu * s), (mu + s) / (1 - mu * s)


def liftoff_inertia_number(path_curvature: float, char_length: float) -> float:
    """The inertia number above which a tip carried over a crest leaves the surface,
    ``1 / (L_c c)``: contact is lost where ``c v^2 > F_p / m`` (small slopes, the normal
    acceleration ``F_p / m``), ``c`` the crest curvature of the tip centre's path, in the
    unit of ``char_length``'s inverse."""
    return 1.0 / (
        check_positive("char_length", char_length) * check_positive("path_curvature", path_curvature)
    )


def gaussian_ridge_path_curvature(height: float, width: float, tip_radius: float = 0.0) -> float:
    """Curvature at the crest of the path of a tip's centre over the ridge
    ``z = A exp(-x^2 / (2 sigma^2))``: the crest's radius of curvature ``sigma^2 / A`` plus
    the tip radius."""
    a, s = check_positive("height", height), check_positive("width", width)
    return 1.0 / (s * s / a + check_positive("tip_radius", tip_radius, allow_zero=True))
