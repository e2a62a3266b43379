"""The wedge geometries of the engines study (:mod:`spine_mj.validate.engines`) and their
closed forms: a V-groove rising along x (:func:`groove`, its flanks' tilt in the groove's own
plane :func:`flank_tilt`) and Dai's half-embedded sphere (:func:`dai_surface`, the first touch
of a tip sliding into it :func:`dai_start`, the self-lock threshold :func:`dai_threshold`).
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.surfaces import GridSurface

__all__ = ["dai_start", "dai_surface", "dai_threshold", "flank_tilt", "groove"]


def dai_threshold(mu: float) -> float:
    """The smallest R / r at which a tip pushed into a half-embedded sphere can self-lock."""
    return 1.0 / math.sin(math.atan(mu)) - 1.0


def groove(theta_deg: float, alpha_deg: float, half_width_m: float = 0.02, n: int = 81) -> GridSurface:
    """``z = tan(theta) x + tan(alpha) |y|``: a V-groove along x rising at theta, flanks tilted by alpha."""
    x = np.linspace(-half_width_m, half_width_m, n)
    h = (
        math.tan(math.radians(theta_deg)) * x[None, :]
        + math.tan(math.radians(alpha_deg)) * np.abs(x)[:, None]
    )
    return GridSurface(heights=h, x=x, y=x.copy(), unit="m", metadata={"generator": "groove"})


def flank_tilt(theta_deg: float, alpha_deg: float) -> float:
    """The flanks' tilt [rad] of :func:`groove` in the groove's own inclined plane (the
    closed form's alpha): ``tan(alpha') = tan(alpha) cos(theta)`` (the flank's normal
    ``(-tan theta, -+tan alpha, 1)`` seen across the groove's line ``(1, 0, tan theta)``)."""
    return math.atan(math.tan(math.radians(alpha_deg)) * math.cos(math.radians(theta_deg)))


def dai_surface(sphere_m: float, tip_m: float) -> GridSurface:
    """A half-embedded sphere of radius ``sphere_m`` on a floor, on a grid at a quarter of
    the tip radius ``tip_m`` (the rig's finest)."""
    step = tip_m / 4
    half = 3 * (sphere_m + tip_m)
    x = np.arange(-half, half + step / 2, step)
    xx, yy = np.meshgrid(x, x)
    h = np.sqrt(np.clip(sphere_m**2 - xx**2 - yy**2, 0.0, None))
    return GridSurface(heights=h, x=x, y=x.copy(), unit="m", metadata={"generator": "dai"})


def dai_start(ball, sphere_m: float, tip_m: float) -> tuple[float, float]:
    """Where a tip sliding in +x along the floor first touches the faceted sphere (``ball``:
    the rig's contact surface, metres): the first point, on a 1e-4 tip-radius grid, where
    the ball rises off the floor."""
    x_smooth = -math.sqrt((sphere_m + tip_m) ** 2 - tip_m**2)
    xs = np.linspace(x_smooth - 0.5 * tip_m, x_smooth + 0.5 * tip_m, 10001)
    lifted = np.flatnonzero(ball.height(xs, np.zeros_like(xs)) > 1e-6 * tip_m)
    return float(xs[lifted[0]]), 0.0
