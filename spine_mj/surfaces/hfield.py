"""The one conversion between a surface and MuJoCo's height field (:class:`HField`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spine_mj.errors import check_positive
from spine_mj.surfaces.types import GridSurface, Surface

#: Samples a side of an analytic surface's hfield when none are asked for.
DEFAULT_HFIELD_SIDE = 201


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
    resampling: where they refine its own samples (``(n - 1) f + 1`` a side, the same whole
    ``f`` on both) its interpolant is evaluated between them (:func:`refine_grid`: every
    sample kept), else it is resampled over its bounds; an analytic surface is sampled on
    ``nrow x ncol`` points over its bounds (default 201 x 201). ``base_z`` (the solid's
    thickness below the lowest point) defaults to a tenth of the larger horizontal radius.

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
    factor = _nesting_factor(surface, nrow, ncol)
    if isinstance(surface, GridSurface) and nrow is None and ncol is None:
        grid = surface
    elif factor:
        grid = refine_grid(surface, factor)
    else:
        ncol = DEFAULT_HFIELD_SIDE if ncol is None else ncol
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


def hfield_half_extents(surface: Surface, *, nrow: int | None = None, ncol: int | None = None) -> tuple:
    """``(radius_x, radius_y)`` of :func:`to_hfield`'s hfield with the same arguments (its
    ``size[:2]``), without sampling: a grid's first to last sample where it keeps or refines
    them, else the bounds. What the rig's sizing reads before any hfield is made."""
    if isinstance(surface, GridSurface) and (nrow is ncol is None or _nesting_factor(surface, nrow, ncol)):
        return 0.5 * float(surface.x[-1] - surface.x[0]), 0.5 * float(surface.y[-1] - surface.y[0])
    xmin, xmax, ymin, ymax = surface.bounds
    return 0.5 * float(xmax - xmin), 0.5 * float(ymax - ymin)


def refine_grid(surface: GridSurface, factor: int) -> GridSurface:
    """``surface`` at ``factor`` times the samples a side, every old sample kept: its C2
    spline (which passes through every sample) evaluated on ``(n - 1) factor + 1`` points
    spanning its first to its last sample. How a gridded surface's hfield is refined: only
    the facets change, not the surface.

    Parameters
    ----------
    surface : GridSurface
        The grid.
    factor : int
        >= 1.

    Returns
    -------
    GridSurface
        Not periodic (a periodic grid's last sample is one spacing short of its period).
    """
    if not isinstance(surface, GridSurface):
        raise TypeError(f"surface must be a GridSurface, got {type(surface).__name__}")
    if isinstance(factor, bool) or int(factor) != factor or factor < 1:
        raise ValueError(f"factor must be an integer >= 1, got {factor!r}")
    f = int(factor)
    x = np.linspace(surface.x[0], surface.x[-1], (surface.x.size - 1) * f + 1)
    y = np.linspace(surface.y[0], surface.y[-1], (surface.y.size - 1) * f + 1)
    heights = surface.height(x[None, :], y[:, None])
    # the old samples exactly as they were (the spline reproduces them to rounding)
    heights[::f, ::f] = surface.heights
    meta = dict(surface.metadata, refined_from=surface.metadata.get("generator", "grid"), refinement=f)
    return GridSurface(heights=heights, x=x, y=y, periodic=False, unit=surface.unit, metadata=meta)


def _nesting_factor(surface: Surface, nrow: int | None, ncol: int | None) -> int:
    """The whole factor ``f`` > 1 by which ``nrow x ncol`` refines a grid's own samples
    (``(n - 1) f + 1`` a side); 0 where it does not (or ``surface`` is no grid)."""
    if not isinstance(surface, GridSurface) or nrow is None or ncol is None:
        return 0
    ny, nx = surface.heights.shape
    fx, rx = divmod(int(ncol) - 1, nx - 1)
    fy, ry = divmod(int(nrow) - 1, ny - 1)
    return fx if rx == ry == 0 and fx == fy and fx > 1 else 0


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
