"""Rough surfaces z = f(x, y): analytic Gaussian sums and gridded height maps.

Every surface evaluates height, gradient and Hessian at arbitrary points, vectorized over
any broadcastable ``x`` and ``y`` arrays, and knows its domain (``bounds``) and length
``unit``. Two kinds exist:

* :class:`GaussianSurface`: a sum of elliptical Gaussians with exact derivatives (the
  paper's single peak/valley and random Gaussian surfaces, §3.1-3.2);
* :class:`GridSurface`: heights on a uniform grid, interpolated by a C2 cubic B-spline
  (fractal, sandpaper and measured surfaces, and whatever MuJoCo sees).

Grid convention (shared with MuJoCo's hfield): ``heights[iy, ix]``, row index is y,
column index is x, row 0 at the smallest y.

Generators are pure functions with keyword-only options; randomness enters only through
``rng`` (an int seed or a :class:`numpy.random.Generator`), so a seed reproduces a surface
bit for bit. Units: the paper's Gaussian surfaces are dimensionless (``unit="1"``, lengths
in multiples of the paper's sigma units); sandpaper is in metres and a measured surface in
its instrument's length unit (:data:`LENGTH_UNITS_M`, spelled by :func:`length_unit`).

Modules: :mod:`~spine_mj.surfaces.base` (units, size limits, argument checks),
:mod:`~spine_mj.surfaces.types` (the surface types), :mod:`~spine_mj.surfaces.generators`,
:mod:`~spine_mj.surfaces.sandpaper`, :mod:`~spine_mj.surfaces.tracks` (the ABBM track),
:mod:`~spine_mj.surfaces.hfield` (MuJoCo's height field) and
:mod:`~spine_mj.surfaces.facets` (the facets MuJoCo collides with and the ball tip on them),
:mod:`~spine_mj.surfaces.dilation` (the surface a spherical tip's centre rides on).
Every public name is importable from ``spine_mj.surfaces``.
"""

from spine_mj.surfaces.base import (
    GRIT_PARTICLE_DIAMETER_M,
    LENGTH_UNITS_M,
    MAX_GRID_POINTS,
    MAX_PEAKS,
    check_grid_size,
    check_unit,
    length_unit,
)
from spine_mj.surfaces.dilation import ball_dilation, ball_dilation_reference, dilate
from spine_mj.surfaces.facets import BallOnFacets, TriangulatedSurface
from spine_mj.surfaces.generators import (
    corrugation,
    fractal_fbm,
    inclined_plane,
    random_gaussians,
    single_gaussian,
)
from spine_mj.surfaces.hfield import HField, from_hfield, refine_grid, to_hfield
from spine_mj.surfaces.sandpaper import sandpaper
from spine_mj.surfaces.tracks import abbm_force_intensity, abbm_size_range, abbm_slope_walk, abbm_track
from spine_mj.surfaces.types import BSplineGrid, GaussianSurface, GridSurface, Surface

__all__ = [
    "GRIT_PARTICLE_DIAMETER_M",
    "LENGTH_UNITS_M",
    "MAX_GRID_POINTS",
    "MAX_PEAKS",
    "BSplineGrid",
    "BallOnFacets",
    "GaussianSurface",
    "GridSurface",
    "HField",
    "Surface",
    "TriangulatedSurface",
    "abbm_force_intensity",
    "abbm_size_range",
    "abbm_slope_walk",
    "abbm_track",
    "ball_dilation",
    "ball_dilation_reference",
    "check_grid_size",
    "check_unit",
    "corrugation",
    "dilate",
    "fractal_fbm",
    "from_hfield",
    "inclined_plane",
    "length_unit",
    "random_gaussians",
    "refine_grid",
    "sandpaper",
    "single_gaussian",
    "to_hfield",
]
