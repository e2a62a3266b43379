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

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
