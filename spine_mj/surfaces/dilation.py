"""The surface a spherical tip's centre rides on: grey-scale dilation by a ball.

A finite tip of radius R rides with its centre on the surface dilated by a ball of radius
R: :func:`dilate` builds that surface (shifted down by R so that R -> 0 gives the
original), on which the streamline rules apply unchanged. The dilation of a sampled grid,
:func:`ball_dilation`, runs in O(grid) memory whatever the tip's footprint: the ball is cut
into rows, each row's 1-D dilation is the upper envelope of half-circles built in one pass
(:mod:`spine_mj.surfaces._dilation_kernel`). :func:`ball_dilation_reference` is the
brute force over the footprint (``scipy.ndimage.grey_dilation``) it is tested against; its
memory grows with grid points x footprint.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.memory import check_memory
from spine_mj.surfaces.base import check_grid_size
from spine_mj.surfaces.facets import TriangulatedSurface
from spine_mj.surfaces.types import GridSurface, Surface

__all__ = ["ball_dilation", "ball_dilation_reference", "dilate"]

#: A dilation's progress callback: ``(rows of the footprint done, rows in all)``.
Progress = Callable[[int, int], None]
#: :func:`dilate` reports its progress from this many samples x footprint rows (about 2
#: CPU-s; a 2048 x 2048 grid by a tip 21 rows wide: 88 million, 5.6 CPU-s): a quick one
#: stays silent, as a loaded machine would show its bar past the CLI's delay.
PROGRESS_MIN_WORK = 2**25

# arrays of the grid's size ball_dilation holds at once: the input, the result, one row pass
_GRID_ARRAYS = 3


def _spacing_pair(spacing) -> tuple[float, float]:
    dx, dy = (float(s) for s in spacing)
    if not all(math.isfinite(s) and s > 0 for s in (dx, dy)):
        raise SpineInputError(f"spacing must be two finite numbers > 0 (dx, dy), got {spacing!r}")
    return dx, dy


def _check_ball(heights, radius, spacing) -> tuple[np.ndarray, float, float, float]:
    h = np.asarray(heights, dtype=float)
    if h.ndim != 2 or min(h.shape) < 1:
        raise SpineInputError(f"heights must be a 2-D array, got shape {h.shape}")
    if not np.all(np.isfinite(h)):
        raise SpineInputError("heights contain NaN or infinite values")
    radius = float(radius)
    if not (math.isfinite(radius) and radius >= 0):
        raise SpineInputError(f"radius (tip radius) must be finite and >= 0, got {radius!r}")
    return h, radius, *_spacing_pair(spacing)


def _check_footprint(radius: float, dx: float, dy: float) -> None:
    """A tip wider than a grid of MAX_GRID_POINTS samples is refused, as any such grid."""
    check_grid_size(
        2 * radius / dx + 1,
        2 * radius / dy + 1,
        where=f"the tip's footprint (radius {radius:g} on a grid of spacing {dx:g} x {dy:g} surface units)",
    )


def ball_dilation(
    heights, radius: float, *, spacing, periodic: bool = False, progress: Progress | None = None
) -> np.ndarray:
    """Grey-scale dilation of sampled heights by a ball of radius R, shifted down by R.

    ``g[i, j] = max f[i + k, j + m] + sqrt(R^2 - (m dx)^2 - (k dy)^2) - R`` over the samples
    ``(m dx)^2 + (k dy)^2 <= R^2``: the height of a ball's centre resting on the samples,
    less R. Exact (to rounding) for any footprint, in O(grid) memory and O(grid x R / dy)
    time.

    Parameters
    ----------
    heights : array_like, shape (ny, nx)
        ``heights[iy, ix]``, row index y (the grid convention of :mod:`spine_mj.surfaces`).
    radius : float
        R >= 0, in the unit of ``spacing``.
    spacing : (float, float)
        Sample spacing ``(dx, dy)`` > 0.
    periodic : bool
        Wrap around the edges; otherwise beyond an edge the edge values repeat
        (``scipy.ndimage``'s ``mode="nearest"``).
    progress : callable, optional
        Hears ``(done, total)`` after each row of the footprint (a pass over the grid: a
        2048 x 2048 grid by a tip 51 rows wide took 14 CPU-s).

    Returns
    -------
    ndarray, shape (ny, nx)

    Raises
    ------
    SpineInputError
        For a non-finite or negative radius or spacing, non-finite heights, a tip whose
        footprint spans more than :data:`~spine_mj.surfaces.MAX_GRID_POINTS` samples, or a
        grid whose arrays would exceed the memory budget (:mod:`spine_mj.memory`).
    """
    h, radius, dx, dy = _check_ball(heights, radius, spacing)
    if radius == 0:
        return h.copy()
    _check_footprint(radius, dx, dy)
    check_memory(_GRID_ARRAYS * h.nbytes, where=f"dilating a {h.shape[0]} x {h.shape[1]} grid by a tip")
    from spine_mj.surfaces._dilation_kernel import ball_rows, footprint_rows

    h = np.ascontiguousarray(h).view()
    h.flags.writeable = False  # one compiled signature whether the heights were read-only or not
    out = np.full(h.shape, -np.inf)
    n = footprint_rows(radius, dy, h.shape[0], bool(periodic))
    for k in range(n):
        ball_rows(h, radius, dx, dy, bool(periodic), k, k + 1, out)
        if progress is not None:
            progress(k + 1, n)
    out -= radius
    return out


def ball_dilation_reference(heights, radius: float, *, spacing, periodic: bool = False) -> np.ndarray:
    """:func:`ball_dilation` by brute force over the tip's footprint (slow; for tests).

    ``scipy.ndimage.grey_dilation`` with the ball's cap as a non-flat structuring element:
    its memory grows with the grid's points times the footprint's (15 GB for an 801 x 801
    grid and a tip 110 samples wide).

    Parameters
    ----------
    heights : array_like, shape (ny, nx)
        Heights on a uniform grid.
    radius : float
        The ball's radius, in the heights' length unit.
    spacing : tuple of float
        Grid spacing ``(dx, dy)``, in the same unit.
    periodic : bool
        Wrap the grid around at its edges.
    """
    from scipy import ndimage

    h, radius, dx, dy = _check_ball(heights, radius, spacing)
    if radius == 0:
        return h.copy()
    rx, ry = int(math.floor(radius / dx)), int(math.floor(radius / dy))
    u = dx * np.arange(-rx, rx + 1)
    v = dy * np.arange(-ry, ry + 1)
    rho2 = u[None, :] ** 2 + v[:, None] ** 2
    footprint = rho2 <= radius * radius
    cap = np.sqrt(np.clip(radius * radius - rho2, 0, None)) - radius
    return ndimage.grey_dilation(
        h, footprint=footprint, structure=cap, mode="wrap" if periodic else "nearest"
    )


def dilate(
    surface: Surface, radius: float, *, spacing: float | None = None, progress: Progress | None = None
) -> GridSurface:
    """Surface traced by a spherical tip of radius R, shifted down by R (R -> 0: the surface).

    ``g(x, y) = max_{u^2 + v^2 <= R^2} [f(x + u, y + v) + sqrt(R^2 - u^2 - v^2)] - R`` is the
    tip centre's height minus R: grey dilation of the sampled heights with a spherical
    structuring element (:func:`ball_dilation`). The tip touches the surface at the point of
    the cap that attains the maximum; its slope is that of ``g``.

    Parameters
    ----------
    surface : Surface
        Analytic surfaces are sampled on ``bounds`` widened by R (so the edge sees the
        outside); gridded ones at their own spacing unless ``spacing`` is given; surfaces
        defined only inside their bounds (non-periodic grids, MuJoCo's facets as a
        :class:`~spine_mj.surfaces.TriangulatedSurface`) are padded with their edge values.
    radius : float
        Tip radius R >= 0 in the surface's length unit; 0 returns the sampled surface.
    spacing : float, optional
        Sample spacing; defaults to ``min(R / 8, extent / 400)`` for analytic surfaces.
    progress : callable, optional
        Hears ``(done, total)`` through a dilation of :data:`PROGRESS_MIN_WORK` or more
        (:func:`ball_dilation`).

    Returns
    -------
    GridSurface
        Same bounds as ``surface`` (same periodicity for gridded ones).

    Raises
    ------
    SpineInputError
        For a negative or non-finite radius or spacing, a sampled grid over
        :data:`~spine_mj.surfaces.MAX_GRID_POINTS` or over the memory budget.
    """
    radius = float(radius)
    if not (math.isfinite(radius) and radius >= 0):
        raise SpineInputError(f"radius (tip radius) must be finite and >= 0, got {radius!r}")
    if spacing is not None and not (math.isfinite(spacing) and spacing > 0):
        raise SpineInputError(f"spacing must be finite and > 0, got {spacing!r}")
    grid = _dilation_grid(surface, radius, spacing)
    if radius == 0:
        return grid
    dx, dy = grid.spacing
    _check_footprint(radius, dx, dy)
    if grid.heights.size * (radius / dy + 1) < PROGRESS_MIN_WORK:
        progress = None
    if grid.periodic or isinstance(surface, (GridSurface, TriangulatedSurface)):
        heights = ball_dilation(
            grid.heights, radius, spacing=(dx, dy), periodic=grid.periodic, progress=progress
        )
    else:
        # an analytic surface: sample a margin of R outside so the edge sees the true neighbourhood
        rx, ry = int(math.floor(radius / dx)), int(math.floor(radius / dy))
        where = f"dilating by the tip radius {radius:g} with a margin of R (spacing {dx:g} x {dy:g})"
        check_grid_size(grid.x.size + 2 * rx, grid.y.size + 2 * ry, where=where)
        check_memory(8.0 * (grid.x.size + 2 * rx) * (grid.y.size + 2 * ry) * (_GRID_ARRAYS + 1), where=where)
        xw = grid.x[0] + dx * np.arange(-rx, grid.x.size + rx)
        yw = grid.y[0] + dy * np.arange(-ry, grid.y.size + ry)
        wide = surface.height(xw[None, :], yw[:, None])
        heights = ball_dilation(wide, radius, spacing=(dx, dy), progress=progress)
        heights = heights[ry : ry + grid.y.size, rx : rx + grid.x.size]
    meta = dict(surface.metadata, tip_radius=radius)
    return GridSurface(
        heights=heights, x=grid.x, y=grid.y, periodic=grid.periodic, unit=surface.unit, metadata=meta
    )


def _dilation_grid(surface: Surface, radius: float, spacing: float | None) -> GridSurface:
    """The samples :func:`dilate` dilates: a grid's own (or resampled to ``spacing``), an
    analytic surface's on its bounds at ``spacing`` (default ``min(R / 8, extent / 400)``)."""
    if isinstance(surface, GridSurface) and spacing is None:
        return surface
    xmin, xmax, ymin, ymax = surface.bounds
    h = spacing
    if h is None:
        extent = max(xmax - xmin, ymax - ymin)
        h = min(radius / 8, extent / 400) if radius > 0 else extent / 400
    if isinstance(surface, GridSurface) and surface.periodic:
        return surface.resample(h)
    where = f"dilating by the tip radius {radius:g} at spacing {h:g} (surface units)"
    check_grid_size((xmax - xmin) / h + 1, (ymax - ymin) / h + 1, where=where)
    nx = int(math.ceil((xmax - xmin) / h)) + 1
    ny = int(math.ceil((ymax - ymin) / h)) + 1
    x, y = np.linspace(xmin, xmax, nx), np.linspace(ymin, ymax, ny)
    return GridSurface(
        heights=surface.height(x[None, :], y[:, None]),
        x=x,
        y=y,
        unit=surface.unit,
        metadata=dict(surface.metadata),
    )
