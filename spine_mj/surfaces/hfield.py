"""The one conversion between a surface and MuJoCo's height field (:class:`HField`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spine_mj.errors import check_positive
from spine_mj.surfaces.types import GridSurface, Surface


@dataclass(frozen=True)
class HField:
    """A surface as MuJoCo's height field wants it.

    Attributes
    ----------
    data : ndarray, shape (nrow, ncol), float32
        Heights rescaled to [0, 1]; column index is x, row index is y, row 0 at
        ``y = pos[1] - radius_y`` (the order of MjSpec ``userdata``, not of the XML
        ``elevation`` attribute, which is flipped).
    size : (radius_x, radius_y, elevation_z, base_z)
        All > 0; ``elevation_z = max - min`` of the heights.
    pos : (x, y, z)
        Where to put the hfield geom: the grid centre and the minimum height.
    """

    data: np.ndarray
    size: tuple[float, float, float, float]
    pos: tuple[float, float, float]

    @property
    def nrow(self) -> int:
        return self.data.shape[0]

    @property
    def ncol(self) -> int:
        return self.data.shape[1]


def to_hfield(
    surface: Surface, *, nrow: int | None = None, ncol: int | None = None, base_z: float | None = None
) -> HField:
    """The one conversion from a surface to MuJoCo hfield data (see :class:`HField`).

    A :class:`GridSurface` is used at its own samples unless ``nrow``/``ncol`` ask for a
    resampling; an analytic surface is sampled on ``nrow x ncol`` points over its bounds
    (default 201 x 201). ``base_z`` (the solid's thickness below the lowest point)
    defaults to a tenth of the larger horizontal radius.

    Parameters
    ----------
    surface : Surface
        Any surface.
    nrow, ncol : int, optional
        Samples along y (rows) and x (columns).
    base_z : float, optional
        Thickness of the solid under the lowest point (surface length unit).

    Returns
    -------
    HField
        ``data`` (nrow x ncol in [0, 1], row 0 at the smallest y), ``size`` and ``pos``.
    """
    if isinstance(surface, GridSurface) and nrow is None and ncol is None:
        grid = surface
    else:
        ncol = 201 if ncol is None else ncol
        nrow = ncol if nrow is None else nrow
        grid = surface.sample(ncol, nrow)
    h = grid.heights
    zmin, zmax = float(h.min()), float(h.max())
    rx = 0.5 * float(grid.x[-1] - grid.x[0])
    ry = 0.5 * float(grid.y[-1] - grid.y[0])
    elevation = zmax - zmin
    if elevation <= 1e-12 * max(rx, ry):
        elevation = 1e-9 * max(rx, ry)
    data = ((h - zmin) / elevation).astype(np.float32)
    base = 0.1 * max(rx, ry) if base_z is None else check_positive("base_z", base_z)
    pos = (0.5 * float(grid.x[0] + grid.x[-1]), 0.5 * float(grid.y[0] + grid.y[-1]), zmin)
    return HField(data=data, size=(rx, ry, elevation, base), pos=pos)


def from_hfield(hfield: HField, *, unit: str = "1") -> GridSurface:
    """Inverse of :func:`to_hfield`: the gridded surface MuJoCo's samples describe.

    Parameters
    ----------
    hfield : HField
        MuJoCo's height field data.
    unit : str
        Length unit of the result's coordinates and heights.

    Returns
    -------
    GridSurface
    """
    nrow, ncol = hfield.data.shape
    rx, ry, elevation, _ = hfield.size
    cx, cy, cz = hfield.pos
    x = cx + np.linspace(-rx, rx, ncol)
    y = cy + np.linspace(-ry, ry, nrow)
    return GridSurface(
        heights=cz + hfield.data.astype(float) * elevation,
        x=x,
        y=y,
        periodic=False,
        unit=unit,
        metadata={"generator": "from_hfield"},
    )
