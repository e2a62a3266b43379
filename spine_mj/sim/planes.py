"""Inclined planes: the surfaces with a closed-form answer, for checking the rig."""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.surfaces import GridSurface


def inclined_plane(
    *, slope_deg: float, azimuth_deg: float = 0.0, half_width: float = 0.02, n: int = 41, unit: str = "m"
) -> GridSurface:
    """A plane ``z = tan(slope) (x cos(az) + y sin(az))`` on a square grid.

    ``azimuth_deg = 0`` makes the plane rise in +x (the closed form's theta > 0), where
    ``kappa = tan(theta + arctan mu)`` (docs/physics.md §1) is the static probe's target.

    Parameters
    ----------
    slope_deg : float
        Inclination theta [deg].
    azimuth_deg : float
        Direction of steepest rise from +x [deg].
    half_width : float
        Half the side of the square domain, centred on 0.
    n : int
        Grid points a side.
    unit : str
        Length unit of the coordinates and heights.

    Returns
    -------
    GridSurface
    """
    slope = float(slope_deg)
    if not (math.isfinite(slope) and -89.0 <= slope <= 89.0):
        raise SpineInputError(f"slope_deg must lie in [-89, 89], got {slope_deg!r}")
    half_width = check_positive("half_width", half_width)
    t = math.tan(math.radians(slope))
    az = math.radians(float(azimuth_deg))
    x = np.linspace(-half_width, half_width, int(n))
    h = t * (math.cos(az) * x[None, :] + math.sin(az) * x[:, None])
    return GridSurface(
        heights=h,
        x=x,
        y=x.copy(),
        unit=unit,
        metadata={"generator": "inclined_plane", "slope_deg": slope, "azimuth_deg": float(azimuth_deg)},
    )
