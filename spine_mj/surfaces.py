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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from spine_mj._version import __version__
from spine_mj.errors import SpineInputError, check_positive

__all__ = [
    "GRIT_PARTICLE_DIAMETER_M",
    "LENGTH_UNITS_M",
    "BSplineGrid",
    "BallOnFacets",
    "GaussianSurface",
    "GridSurface",
    "HField",
    "Surface",
    "TriangulatedSurface",
    "fractal_fbm",
    "from_hfield",
    "length_unit",
    "random_gaussians",
    "sandpaper",
    "single_gaussian",
    "to_hfield",
]

#: Mean particle sizes of the sandpapers in the paper's experiment (§3.3), metres.
GRIT_PARTICLE_DIAMETER_M = {"P36": 538e-6, "P60": 269e-6, "P600": 25.8e-6}

#: Metres per unit of the length units a surface may carry, one ASCII spelling each
#: (:func:`length_unit` maps the others onto them); ``unit == "1"`` is dimensionless.
LENGTH_UNITS_M = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "pm": 1e-12}
#: Other spellings of those units: the micro sign (SurfaceTopography's "µm") and Greek mu.
_UNIT_SPELLINGS = {"\u00b5m": "um", "\u03bcm": "um"}

_MIN_POINTS_PER_SIDE = 4
#: Most points a generated or resampled grid may have (512 MiB per float64 array).
MAX_GRID_POINTS = 2**26
#: Most Gaussians of a random surface: every height costs one exponential per Gaussian.
MAX_PEAKS = 100_000
_CHUNK = 1 << 15
_NONPERIODIC_PAD = 8  # cells of odd reflection before the spline filter, see GridSurface


def length_unit(unit: str) -> str | None:
    """The spelling of :data:`LENGTH_UNITS_M` for the length unit ``unit`` ("µm" -> "um"),
    or None when ``unit`` is not one of them (dimensionless "1", "A", "km", ...)."""
    unit = _UNIT_SPELLINGS.get(unit, unit) if isinstance(unit, str) else None
    return unit if unit in LENGTH_UNITS_M else None


def _rng_and_seed(rng: int | np.random.Generator | None) -> tuple[np.random.Generator, Any]:
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        return np.random.default_rng(), None
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0:
        return np.random.default_rng(int(rng)), int(rng)
    raise SpineInputError(f"rng must be a non-negative int seed or a numpy Generator, got {rng!r}")


def _flag(name: str, value) -> bool:
    """``value`` as a bool: True, False, their numpy forms, 1 or 0; not 3 or "no"."""
    if isinstance(value, str) or value not in (True, False):
        raise SpineInputError(f"{name} must be true or false, got {value!r}")
    return bool(value)


def _pair(name: str, value) -> tuple[float, float]:
    """``value`` as two finite floats, or a :class:`SpineInputError` naming ``name``."""
    try:
        a, b = (float(v) for v in value)
    except (TypeError, ValueError):
        raise SpineInputError(f"{name} must be a pair of numbers, got {value!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise SpineInputError(f"{name} must be finite, got {value!r}")
    return a, b


def _range(name: str, value, *, positive: bool = True) -> tuple[float, float]:
    """``value`` as a finite pair ``(low, high)`` with low <= high (and low > 0 if ``positive``)."""
    lo, hi = _pair(name, value)
    if not lo <= hi:
        raise SpineInputError(f"{name} must be a pair (low, high) with low <= high, got {value!r}")
    if positive and lo <= 0:
        raise SpineInputError(f"{name} must be > 0, got {value!r}")
    return lo, hi


def _bounds(value) -> tuple[float, float, float, float]:
    try:
        xmin, xmax, ymin, ymax = (float(v) for v in value)
    except (TypeError, ValueError):
        raise SpineInputError(f"bounds must be (xmin, xmax, ymin, ymax), got {value!r}") from None
    if not all(math.isfinite(v) for v in (xmin, xmax, ymin, ymax, xmax - xmin, ymax - ymin)):
        raise SpineInputError(f"bounds and their extents must be finite, got {value!r}")
    if not (xmin < xmax and ymin < ymax):
        raise SpineInputError(f"bounds must satisfy xmin < xmax and ymin < ymax, got {value!r}")
    return xmin, xmax, ymin, ymax


def _broadcast_points(x, y) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    return x.ravel(), y.ravel(), x.shape


class Surface:
    """Common interface of all surfaces (see the module docstring).

    Subclasses provide ``bounds``, ``unit``, ``metadata`` and ``_evaluate(x, y, order)``
    returning a tuple of flat arrays: ``(f,)``, ``(f, fx, fy)`` or
    ``(f, fx, fy, fxx, fxy, fyy)`` for ``order`` 0, 1, 2.
    """

    bounds: tuple[float, float, float, float]
    unit: str
    metadata: dict

    def _evaluate(self, x: np.ndarray, y: np.ndarray, order: int) -> tuple[np.ndarray, ...]:
        raise NotImplementedError

    def _eval_shaped(self, x, y, order: int) -> tuple[np.ndarray, ...]:
        xf, yf, shape = _broadcast_points(x, y)
        parts = [
            self._evaluate(xf[s : s + _CHUNK], yf[s : s + _CHUNK], order) for s in range(0, xf.size, _CHUNK)
        ] or [self._evaluate(xf, yf, order)]
        return tuple(np.concatenate([p[k] for p in parts]).reshape(shape) for k in range(len(parts[0])))

    def height(self, x, y) -> np.ndarray:
        """Height f(x, y), broadcast over ``x`` and ``y``."""
        return self._eval_shaped(x, y, 0)[0]

    def gradient(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Slopes ``(f_x, f_y)`` at the points."""
        return self._eval_shaped(x, y, 1)[1:3]

    def hessian(self, x, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Second derivatives ``(f_xx, f_xy, f_yy)`` (paper Eq. 7)."""
        return self._eval_shaped(x, y, 2)[3:6]

    def evaluate(self, x, y, *, order: int = 2) -> tuple[np.ndarray, ...]:
        """Height and derivatives up to ``order`` in one pass (cheaper than three calls)."""
        if order not in (0, 1, 2):
            raise SpineInputError(f"order must be 0, 1 or 2, got {order!r}")
        return self._eval_shaped(x, y, order)

    def contains(self, x, y) -> np.ndarray:
        """True where (x, y) lies inside ``bounds`` (edges included)."""
        xmin, xmax, ymin, ymax = self.bounds
        x, y = np.asarray(x), np.asarray(y)
        return (x >= xmin) & (x <= xmax) & (y >= ymin) & (y <= ymax)

    def sample(self, nx: int, ny: int | None = None) -> GridSurface:
        """Sample on a uniform ``ny x nx`` grid spanning ``bounds`` (edges included)."""
        nx = _grid_count("nx", nx)
        ny = nx if ny is None else _grid_count("ny", ny)
        check_grid_size(nx, ny, where="sampling a surface")
        xmin, xmax, ymin, ymax = self.bounds
        x = np.linspace(xmin, xmax, int(nx))
        y = np.linspace(ymin, ymax, int(ny))
        heights = self.height(x[None, :], y[:, None])
        meta = dict(self.metadata, sampled_from=self.metadata.get("generator", type(self).__name__))
        return GridSurface(heights=heights, x=x, y=y, periodic=False, unit=self.unit, metadata=meta)


@dataclass(frozen=True, eq=False)
class GaussianSurface(Surface):
    """Sum of elliptical Gaussians, with exact derivatives.

    ``f(x, y) = sum_i a_i exp(-(x - mx_i)^2 / (2 sx_i^2) - (y - my_i)^2 / (2 sy_i^2))``

    Attributes
    ----------
    amplitude, center_x, center_y, sigma_x, sigma_y : ndarray, shape (n,)
        Signed peak height a_i (negative for a valley), centres and widths.
    bounds : (xmin, xmax, ymin, ymax)
        The domain streamlines run in; the formula itself is defined everywhere.
    """

    amplitude: np.ndarray
    center_x: np.ndarray
    center_y: np.ndarray
    sigma_x: np.ndarray
    sigma_y: np.ndarray
    bounds: tuple[float, float, float, float]
    unit: str = "1"
    metadata: dict = field(default_factory=dict)

    def __post_init__(self):
        arrays = {}
        for name in ("amplitude", "center_x", "center_y", "sigma_x", "sigma_y"):
            arr = np.atleast_1d(np.asarray(getattr(self, name), dtype=float)).copy()
            if arr.ndim != 1:
                raise SpineInputError(f"{name} must be 1-D, got shape {arr.shape}")
            if not np.all(np.isfinite(arr)):
                raise SpineInputError(f"{name} must be finite, got non-finite values")
            arr.flags.writeable = False
            arrays[name] = arr
        n = arrays["amplitude"].size
        if n == 0 or any(a.size != n for a in arrays.values()):
            raise SpineInputError(
                "amplitude, center_x, center_y, sigma_x, sigma_y must have the same length "
                f"n >= 1, got {[a.size for a in arrays.values()]}"
            )
        for name in ("sigma_x", "sigma_y"):
            if np.any(arrays[name] <= 0):
                raise SpineInputError(f"{name} must be > 0, got min {arrays[name].min():g}")
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "bounds", _bounds(self.bounds))

    @property
    def n_gaussians(self) -> int:
        return self.amplitude.size

    def _eval_shaped(self, x, y, order: int) -> tuple[np.ndarray, ...]:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if x.ndim == 2 and y.ndim == 2 and x.shape[0] == 1 and y.shape[1] == 1:
            return self._on_grid(x[0], y[:, 0], order)
        return super()._eval_shaped(x, y, order)

    def _on_grid(self, x, y, order):
        """Values on the tensor grid ``x (nx,)`` by ``y (ny,)``, shape ``(ny, nx)``: each
        Gaussian is a product of one factor in x and one in y, so every sum is a matrix
        product (K Gaussians: K (nx + ny) exponentials instead of K nx ny). Sampling and
        dilating a surface of 100 Gaussians on a 3201^2 grid: 47 s pointwise."""
        dx = (x[None, :] - self.center_x[:, None]) / self.sigma_x[:, None]  # (K, nx)
        dy = (y[None, :] - self.center_y[:, None]) / self.sigma_y[:, None]  # (K, ny)
        ex, ey = np.exp(-0.5 * dx * dx), np.exp(-0.5 * dy * dy)
        ay = self.amplitude[:, None] * ey
        out = [ay.T @ ex]
        if order >= 1:
            gx, gy = -dx / self.sigma_x[:, None], -dy / self.sigma_y[:, None]
            out += [ay.T @ (ex * gx), (ay * gy).T @ ex]
        if order >= 2:
            out += [
                ay.T @ (ex * (gx * gx - 1.0 / self.sigma_x[:, None] ** 2)),
                (ay * gy).T @ (ex * gx),
                (ay * (gy * gy - 1.0 / self.sigma_y[:, None] ** 2)).T @ ex,
            ]
        return tuple(out)

    def _evaluate(self, x, y, order):
        dx = (x[:, None] - self.center_x) / self.sigma_x
        dy = (y[:, None] - self.center_y) / self.sigma_y
        g = self.amplitude * np.exp(-0.5 * (dx * dx + dy * dy))
        out = [g.sum(axis=1)]
        if order >= 1:
            gx = -dx / self.sigma_x
            gy = -dy / self.sigma_y
            out += [(g * gx).sum(axis=1), (g * gy).sum(axis=1)]
        if order >= 2:
            out += [
                (g * (gx * gx - 1.0 / self.sigma_x**2)).sum(axis=1),
                (g * gx * gy).sum(axis=1),
                (g * (gy * gy - 1.0 / self.sigma_y**2)).sum(axis=1),
            ]
        return tuple(out)


@dataclass(frozen=True)
class BSplineGrid:
    """Coefficients of a uniform cubic B-spline, for fast evaluators (numba kernels).

    The value at (x, y) is ``sum_{b,a} By_b(t_y) Bx_a(t_x) coef[j - 1 + b + offset,
    i - 1 + a + offset]`` with ``u = (x - x0) / dx``, ``i = floor(u)``, ``t_x = u - i``
    (likewise in y) and the standard cubic B-spline basis. For periodic grids ``u`` is
    taken modulo ``nx`` first; otherwise ``i`` is clipped to ``[0, nx - 2]``.
    """

    coef: np.ndarray
    offset: int
    x0: float
    dx: float
    nx: int
    y0: float
    dy: float
    ny: int
    periodic: bool


def _bspline_weights(t: np.ndarray, order: int) -> list[np.ndarray]:
    """Cubic B-spline basis (and derivatives w.r.t. t) as ``(P, 4)`` arrays."""
    s = 1.0 - t
    t2 = t * t
    t3 = t2 * t
    w = [np.stack([s**3 / 6, (3 * t3 - 6 * t2 + 4) / 6, (-3 * t3 + 3 * t2 + 3 * t + 1) / 6, t3 / 6], axis=1)]
    if order >= 1:
        w.append(np.stack([-0.5 * s * s, 1.5 * t2 - 2 * t, -1.5 * t2 + t + 0.5, 0.5 * t2], axis=1))
    if order >= 2:
        w.append(np.stack([s, 3 * t - 2, 1 - 3 * t, t], axis=1))
    return w


@dataclass(frozen=True, eq=False)
class GridSurface(Surface):
    """Heights on a uniform grid, interpolated by a C2 cubic B-spline.

    Attributes
    ----------
    heights : ndarray, shape (ny, nx)
        ``heights[iy, ix] = f(x[ix], y[iy])``; finite, at least 4 points a side.
    x, y : ndarray, shapes (nx,), (ny,)
        Strictly increasing, uniformly spaced coordinates.
    periodic : bool
        If True the surface repeats with periods ``nx * dx`` and ``ny * dy`` (the grid
        holds one period, without the repeated end point).

    Notes
    -----
    The interpolant passes through every sample and is twice continuously differentiable.
    Its error for a smooth surface is O(h^4) in height, O(h^3) in slope and O(h^2) in
    curvature (h the spacing; ``tests/test_surfaces.py`` measures the orders). A
    non-periodic grid is extended by 8 cells of odd reflection, ``f(-k) = 2 f(0) - f(k)``,
    before the spline is fitted: slopes stay continuous across the edge and the implied
    curvature there is zero, so within about two cells of an edge the curvature error is
    O(f''). Points outside a non-periodic grid evaluate to NaN.
    """

    heights: np.ndarray
    x: np.ndarray
    y: np.ndarray
    periodic: bool = False
    unit: str = "1"
    metadata: dict = field(default_factory=dict)
    spline: BSplineGrid = field(init=False, repr=False)
    bounds: tuple[float, float, float, float] = field(init=False)

    def __post_init__(self):
        if np.iscomplexobj(self.heights):  # a cast would drop the imaginary part with a warning
            raise SpineInputError("heights must be real numbers, got complex values")
        heights = np.array(self.heights, dtype=float)
        if heights.ndim != 2:
            raise SpineInputError(f"heights must be a 2-D array (ny, nx), got shape {heights.shape}")
        ny, nx = heights.shape
        if nx < _MIN_POINTS_PER_SIDE or ny < _MIN_POINTS_PER_SIDE:
            raise SpineInputError(
                f"heights must have at least {_MIN_POINTS_PER_SIDE} points a side, got {ny} x {nx}"
            )
        n_bad = int(np.count_nonzero(~np.isfinite(heights)))
        if n_bad:
            raise SpineInputError(
                f"heights contain {n_bad} NaN or infinite values of {heights.size}; "
                "fill them first (e.g. `--fill harmonic` on import)"
            )
        coords = {}
        for name, n in (("x", nx), ("y", ny)):
            c = np.array(getattr(self, name), dtype=float)
            if c.shape != (n,):
                raise SpineInputError(f"{name} must have shape ({n},) to match heights, got {c.shape}")
            if not np.all(np.isfinite(c)):
                raise SpineInputError(f"{name} coordinates must be finite")
            d = np.diff(c)
            if np.any(d <= 0):
                raise SpineInputError(f"{name} coordinates must be strictly increasing")
            if not (np.isfinite(1.0 / d.min()) and np.isfinite(c[-1] - c[0])):
                raise SpineInputError(
                    f"{name} spacing {d.min():.3g} and extent {c[-1] - c[0]:.3g} must be finite and normal "
                    "floating-point numbers"
                )
            if np.ptp(d) > 1e-6 * abs(d.mean()):
                raise SpineInputError(
                    f"{name} coordinates must be uniformly spaced (spacing varies by "
                    f"{np.ptp(d):.3g} around {d.mean():.3g}); resample the data first"
                )
            c.flags.writeable = False
            coords[name] = c
        heights.flags.writeable = False
        x, y = coords["x"], coords["y"]
        dx, dy = (x[-1] - x[0]) / (nx - 1), (y[-1] - y[0]) / (ny - 1)
        periodic = _flag("periodic", self.periodic)
        if periodic:
            coef = np.pad(ndimage.spline_filter(heights, order=3, mode="grid-wrap"), 2, mode="wrap")
            offset = 2
            bounds = (x[0], x[0] + nx * dx, y[0], y[0] + ny * dy)
        else:
            padded = np.pad(heights, _NONPERIODIC_PAD, mode="reflect", reflect_type="odd")
            coef = ndimage.spline_filter(padded, order=3, mode="mirror")
            offset = _NONPERIODIC_PAD
            bounds = (x[0], x[-1], y[0], y[-1])
        coef.flags.writeable = False
        object.__setattr__(self, "heights", heights)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "periodic", periodic)
        object.__setattr__(self, "bounds", tuple(float(b) for b in bounds))
        object.__setattr__(
            self,
            "spline",
            BSplineGrid(
                coef=coef,
                offset=offset,
                x0=float(x[0]),
                dx=float(dx),
                nx=nx,
                y0=float(y[0]),
                dy=float(dy),
                ny=ny,
                periodic=periodic,
            ),
        )

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``."""
        return self.heights.shape

    @property
    def spacing(self) -> tuple[float, float]:
        """Grid spacing ``(dx, dy)``."""
        return self.spline.dx, self.spline.dy

    def _cell(self, coord, origin, step, n):
        u = (coord - origin) / step
        if self.periodic:
            u = np.mod(u, n)
            i = np.minimum(np.floor(u).astype(np.intp), n - 1)
            inside = np.ones(u.shape, dtype=bool)
        else:
            inside = (u >= -1e-9) & (u <= n - 1 + 1e-9)
            i = np.clip(np.floor(u), 0, n - 2).astype(np.intp)
        return i, u - i, inside

    def _evaluate(self, x, y, order):
        sp = self.spline
        i, tx, in_x = self._cell(x, sp.x0, sp.dx, sp.nx)
        j, ty, in_y = self._cell(y, sp.y0, sp.dy, sp.ny)
        ar = np.arange(4)
        rows = (j - 1 + sp.offset)[:, None] + ar
        cols = (i - 1 + sp.offset)[:, None] + ar
        block = sp.coef[rows[:, :, None], cols[:, None, :]]  # (P, 4 rows, 4 cols)
        wx = _bspline_weights(tx, order)
        wy = _bspline_weights(ty, order)

        def comb(by, bx, scale):
            return np.einsum("pb,pba,pa->p", by, block, bx) * scale

        out = [comb(wy[0], wx[0], 1.0)]
        if order >= 1:
            out += [comb(wy[0], wx[1], 1 / sp.dx), comb(wy[1], wx[0], 1 / sp.dy)]
        if order >= 2:
            out += [
                comb(wy[0], wx[2], 1 / sp.dx**2),
                comb(wy[1], wx[1], 1 / (sp.dx * sp.dy)),
                comb(wy[2], wx[0], 1 / sp.dy**2),
            ]
        outside = ~(in_x & in_y)
        if outside.any():
            for arr in out:
                arr[outside] = np.nan
        return tuple(out)

    def resample(self, spacing: float | tuple[float, float]) -> GridSurface:
        """Resample onto a new uniform spacing (same units) with the C2 interpolant.

        The new grid starts at the same corner and covers as much of the old domain as
        whole steps allow.
        """
        sx, sy = (spacing, spacing) if np.isscalar(spacing) else spacing
        sx, sy = check_positive("spacing x", sx), check_positive("spacing y", sy)
        xmin, xmax, ymin, ymax = self.bounds
        # counts as floats, before rounding: an inf or 1e300-point grid is refused, not converted
        check_grid_size(
            (xmax - xmin) / sx + 1, (ymax - ymin) / sy + 1, where=f"resampling to spacing {sx:g} x {sy:g}"
        )
        if self.periodic:
            nx, ny = max(1, round((xmax - xmin) / sx)), max(1, round((ymax - ymin) / sy))
            sx, sy = (xmax - xmin) / nx, (ymax - ymin) / ny
        else:
            nx = int(math.floor((xmax - xmin) / sx * (1 + 1e-12))) + 1
            ny = int(math.floor((ymax - ymin) / sy * (1 + 1e-12))) + 1
        x, y = xmin + sx * np.arange(nx), ymin + sy * np.arange(ny)
        if nx < _MIN_POINTS_PER_SIDE or ny < _MIN_POINTS_PER_SIDE:
            raise SpineInputError(
                f"spacing {spacing!r} leaves only {ny} x {nx} points; at least 4 a side are needed"
            )
        heights = self.height(x[None, :], y[:, None])
        meta = dict(self.metadata, resampled_spacing=[float(sx), float(sy)])
        return GridSurface(heights=heights, x=x, y=y, periodic=self.periodic, unit=self.unit, metadata=meta)


# --------------------------------------------------------------------------- generators


def _meta(generator: str, seed, **params) -> dict:
    clean = {k: (list(v) if isinstance(v, tuple) else v) for k, v in params.items()}
    return {"generator": generator, "seed": seed, "params": clean, "spine_mj_version": __version__}


def single_gaussian(
    *,
    sign: int = 1,
    k: float = 10 * math.pi,
    sigma_x: float = 1.5,
    sigma_y: float = 1.5,
    center: tuple[float, float] = (0.0, 0.0),
    bounds: tuple[float, float, float, float] = (-5.0, 5.0, -5.0, 5.0),
) -> GaussianSurface:
    """The paper's single Gaussian peak (``sign=+1``) or valley (``sign=-1``), §3.1.

    ``f = sign * k / (2 pi sx sy) * exp(-(x-mx)^2/(2 sx^2) - (y-my)^2/(2 sy^2))``; with the
    paper's ``k = 10 pi`` and ``sx = sy = 1.5`` the amplitude is 2.22 and the steepest
    slope 0.90 (docs/physics.md §3). Dimensionless.
    """
    if sign not in (1, -1):
        raise SpineInputError(f"sign must be +1 (peak) or -1 (valley), got {sign!r}")
    k = check_positive("k", k)
    sx, sy = check_positive("sigma_x", sigma_x), check_positive("sigma_y", sigma_y)
    mx, my = _pair("center", center)
    amplitude = sign * k / (2 * math.pi * sx * sy)
    return GaussianSurface(
        amplitude=[amplitude],
        center_x=[mx],
        center_y=[my],
        sigma_x=[sx],
        sigma_y=[sy],
        bounds=_bounds(bounds),
        unit="1",
        metadata=_meta(
            "single_gaussian",
            None,
            sign=sign,
            k=k,
            sigma_x=sx,
            sigma_y=sy,
            center=(mx, my),
            bounds=tuple(bounds),
        ),
    )


def random_gaussians(
    *,
    n_peaks: int = 100,
    sign: int = 1,
    bounds: tuple[float, float, float, float] = (-10.0, 10.0, -10.0, 10.0),
    sigma_range: tuple[float, float] = (0.5, 1.5),
    amplitude_range: tuple[float, float] = (0.5, 1.5),
    anisotropic: bool = False,
    overlap: bool = True,
    min_separation: float = 2.0,
    rng: int | np.random.Generator | None = None,
) -> GaussianSurface:
    """Random Gaussian surface of §3.2: ``n_peaks`` Gaussians scattered over ``bounds``.

    Distributions (the paper gives none; the defaults are calibrated in ``analysis/``):

    * centres: uniform over ``bounds``;
    * widths: ``sigma`` uniform on ``sigma_range``; ``sigma_x = sigma_y`` unless
      ``anisotropic``, when both are drawn independently;
    * heights: amplitude ``|a|`` uniform on ``amplitude_range``, sign ``sign`` (+1 convex
      peaks, -1 concave valleys);
    * ``overlap=False`` rejects centres closer than ``min_separation * (sigma_i + sigma_j)``
      (drawn in sequence), and fails clearly when they cannot all be placed.

    The draws happen in a fixed order (centres, widths, amplitudes), so one seed gives the
    same surface on every machine.
    """
    if isinstance(n_peaks, bool) or int(n_peaks) != n_peaks or not 0 < n_peaks <= MAX_PEAKS:
        raise SpineInputError(f"n_peaks must be an integer in 1..{MAX_PEAKS}, got {n_peaks!r}")
    n_peaks = int(n_peaks)
    if sign not in (1, -1):
        raise SpineInputError(f"sign must be +1 (convex peaks) or -1 (concave valleys), got {sign!r}")
    anisotropic, overlap = _flag("anisotropic", anisotropic), _flag("overlap", overlap)
    xmin, xmax, ymin, ymax = _bounds(bounds)
    s_lo, s_hi = _range("sigma_range (widths)", sigma_range)
    a_lo, a_hi = _range("amplitude_range (heights)", amplitude_range)
    min_separation = float(min_separation)
    if not overlap and not (min_separation > 0):
        raise SpineInputError(f"min_separation must be > 0, got {min_separation!r}")
    gen, seed = _rng_and_seed(rng)

    sigma_x = gen.uniform(s_lo, s_hi, n_peaks)
    sigma_y = gen.uniform(s_lo, s_hi, n_peaks) if anisotropic else sigma_x.copy()
    amplitude = sign * gen.uniform(a_lo, a_hi, n_peaks)
    if overlap:
        cx = gen.uniform(xmin, xmax, n_peaks)
        cy = gen.uniform(ymin, ymax, n_peaks)
    else:
        radius = 0.5 * (sigma_x + sigma_y)
        cx, cy = np.empty(n_peaks), np.empty(n_peaks)
        for i in range(n_peaks):
            for _ in range(10_000):
                px, py = gen.uniform(xmin, xmax), gen.uniform(ymin, ymax)
                d = np.hypot(cx[:i] - px, cy[:i] - py)
                if np.all(d >= min_separation * (radius[:i] + radius[i])):
                    cx[i], cy[i] = px, py
                    break
            else:
                raise SpineInputError(
                    f"overlap=False: could not place peak {i + 1} of {n_peaks} with "
                    f"min_separation={min_separation}; lower n_peaks, the widths or "
                    "min_separation, or allow overlap"
                )
    return GaussianSurface(
        amplitude=amplitude,
        center_x=cx,
        center_y=cy,
        sigma_x=sigma_x,
        sigma_y=sigma_y,
        bounds=(xmin, xmax, ymin, ymax),
        unit="1",
        metadata=_meta(
            "random_gaussians",
            seed,
            n_peaks=n_peaks,
            sign=sign,
            bounds=(xmin, xmax, ymin, ymax),
            sigma_range=(s_lo, s_hi),
            amplitude_range=(a_lo, a_hi),
            anisotropic=bool(anisotropic),
            overlap=bool(overlap),
            min_separation=min_separation,
        ),
    )


def _spectral_rms_slope(heights: np.ndarray, dx: float, dy: float) -> float:
    """``sqrt(<|grad f|^2>)`` of a periodic grid by Parseval: ``sum q^2 |F(q)|^2 / N^2``."""
    ny, nx = heights.shape
    power = np.abs(np.fft.fft2(heights)) ** 2 / heights.size**2
    q2 = (2 * np.pi) ** 2 * (np.fft.fftfreq(nx, dx)[None, :] ** 2 + np.fft.fftfreq(ny, dy)[:, None] ** 2)
    return float(np.sqrt(np.sum(q2 * power)))


def fractal_fbm(
    *,
    nx: int = 256,
    ny: int | None = None,
    size: float | tuple[float, float] = 20.0,
    hurst: float = 0.8,
    rms_height: float | None = None,
    rms_slope: float | None = None,
    periodic: bool = True,
    long_cutoff: float | None = None,
    short_cutoff: float | None = None,
    unit: str = "1",
    rng: int | np.random.Generator | None = None,
) -> GridSurface:
    """Fractal (fBm) surface by spectral synthesis, paper Eq. 5 and Fig. 7A-C.

    White Gaussian noise is Fourier transformed (a complex Gaussian field with Hermitian
    symmetry), filtered by ``A(f) = sqrt(P(f)) = |f|^-(H+1)`` so that the 2-D PSD is
    ``P(f) ~ |f|^-(2H+2)``, and transformed back. ``f`` is spatial frequency in cycles per
    unit length. Below ``1/long_cutoff`` the filter is flat (roll-off); above
    ``1/short_cutoff`` it is zero. The mean height is removed.

    Parameters
    ----------
    nx, ny
        Grid points per side (``ny`` defaults to ``nx``); spacing is ``size / n``.
    size
        Physical side lengths ``(Lx, Ly)`` or one value for both; the grid is centred at 0.
    hurst
        Hurst index H, 0 < H < 1.
    rms_height, rms_slope
        Normalization: exactly one may be given (neither gives ``rms_height=1``). RMS slope
        is ``sqrt(<|grad f|^2>)``, evaluated spectrally on a periodic surface and by
        central differences on a non-periodic one.
    periodic
        If False, a surface twice as large is synthesized and one quadrant kept, so the
        result does not wrap around.
    """
    periodic = _flag("periodic", periodic)
    nx = _grid_count("nx", nx)
    ny = nx if ny is None else _grid_count("ny", ny)
    check_grid_size((1 if periodic else 2) * nx, (1 if periodic else 2) * ny, where="fractal_fbm")
    lx, ly = (size, size) if np.isscalar(size) else _pair("size", size)
    lx, ly = check_positive("size x", lx), check_positive("size y", ly)
    hurst = float(hurst)
    if not (0.0 < hurst < 1.0):
        raise SpineInputError(f"hurst must lie in the open interval (0, 1), got {hurst!r}")
    if rms_height is not None and rms_slope is not None:
        raise SpineInputError("give rms_height or rms_slope, not both")
    if rms_slope is not None:
        rms_slope = check_positive("rms_slope", rms_slope)
    else:
        rms_height = 1.0 if rms_height is None else check_positive("rms_height", rms_height)
    if long_cutoff is not None:
        long_cutoff = check_positive("long_cutoff", long_cutoff)
    if short_cutoff is not None:
        short_cutoff = check_positive("short_cutoff", short_cutoff)
    gen, seed = _rng_and_seed(rng)

    dx, dy = lx / nx, ly / ny
    fac = 1 if periodic else 2
    mx, my = fac * nx, fac * ny
    fx = np.fft.fftfreq(mx, dx)[None, :]
    fy = np.fft.fftfreq(my, dy)[:, None]
    freq = np.hypot(fx, fy)
    if long_cutoff is not None:
        freq = np.maximum(freq, 1.0 / long_cutoff)
    with np.errstate(divide="ignore"):
        amp = np.where(freq > 0, freq ** -(hurst + 1.0), 0.0)
    if short_cutoff is not None:
        amp[np.hypot(fx, fy) > 1.0 / short_cutoff] = 0.0
    amp[0, 0] = 0.0
    noise = gen.standard_normal((my, mx))
    heights = np.fft.ifft2(np.fft.fft2(noise) * amp).real[:ny, :nx]
    heights -= heights.mean()
    if rms_slope is not None:
        if periodic:
            current = _spectral_rms_slope(heights, dx, dy)
        else:
            gy, gx = np.gradient(heights, dy, dx)
            current = float(np.sqrt(np.mean(gx * gx + gy * gy)))
        heights *= rms_slope / current
    else:
        heights *= rms_height / heights.std()
    if not np.isfinite(heights).all():
        raise SpineInputError(
            f"fractal_fbm: size {lx:g} x {ly:g} with rms_height {rms_height} and rms_slope {rms_slope} "
            "gives heights beyond floating-point range; use sizes and RMS values nearer 1"
        )
    x = -lx / 2 + dx * np.arange(nx)
    y = -ly / 2 + dy * np.arange(ny)
    return GridSurface(
        heights=heights,
        x=x,
        y=y,
        periodic=bool(periodic),
        unit=unit,
        metadata=_meta(
            "fractal_fbm",
            seed,
            nx=nx,
            ny=ny,
            size=(lx, ly),
            hurst=hurst,
            rms_height=rms_height,
            rms_slope=rms_slope,
            periodic=bool(periodic),
            long_cutoff=long_cutoff,
            short_cutoff=short_cutoff,
            unit=unit,
        ),
    )


def _grid_count(name: str, n) -> int:
    """``n`` as a number of grid points a side: an integer in [4, MAX_GRID_POINTS]."""
    ok = isinstance(n, (int, np.integer, float, np.floating)) and not isinstance(n, (bool, np.bool_))
    if not ok or not math.isfinite(n) or int(n) != n or n < _MIN_POINTS_PER_SIDE:
        raise SpineInputError(f"{name} must be an integer >= {_MIN_POINTS_PER_SIDE}, got {n!r}")
    return int(n)


def check_grid_size(nx: int, ny: int, *, where: str) -> None:
    """Refuse a grid of more than :data:`MAX_GRID_POINTS` points before allocating it.

    Raises
    ------
    SpineInputError
        Naming ``where``, the grid's shape, the limit and the memory one height array
        of that shape would take.
    """
    points = float(nx) * float(ny)  # counts may come as floats, before rounding: inf is refused too
    if not points <= MAX_GRID_POINTS:
        gib = points * 8 / 2**30
        raise SpineInputError(
            f"{where}: a {_count(ny)} x {_count(nx)} grid has {points:.3g} points, more than the limit "
            f"{MAX_GRID_POINTS:.3g} ({gib:.3g} GiB per height array); use fewer points or a coarser spacing"
        )


def _count(n) -> str:
    """A point count for a message: whole numbers as integers, others as floats."""
    n = float(n)
    return str(int(n)) if math.isfinite(n) and n == int(n) and abs(n) < 1e15 else f"{n:.4g}"


def _particle_envelope(n, spacing, diam, px, py, embed) -> np.ndarray:
    """Upper envelope ``(n, n)`` of the base z = 0 and spheres of diameters ``diam`` at
    ``(px, py)``, each sunk by ``embed`` times its diameter, on a periodic grid."""
    heights = np.zeros((n, n))
    grid = np.arange(n)
    for d, cx, cy, e in zip(diam, px, py, embed):
        r = d / 2
        zc = r - e * d
        half = int(math.ceil(r / spacing)) + 1
        ix0, iy0 = int(round(cx / spacing)), int(round(cy / spacing))
        ix = np.arange(ix0 - half, ix0 + half + 1)
        iy = np.arange(iy0 - half, iy0 + half + 1)
        ddx = ix * spacing - cx
        ddy = iy * spacing - cy
        rho2 = ddy[:, None] ** 2 + ddx[None, :] ** 2
        cap = zc + np.sqrt(np.clip(r * r - rho2, 0, None))
        cap[rho2 >= r * r] = 0.0
        rows, cols = grid[np.mod(iy, n)], grid[np.mod(ix, n)]
        block = heights[np.ix_(rows, cols)]
        heights[np.ix_(rows, cols)] = np.maximum(block, cap)
    return heights


def sandpaper(
    *,
    grit: str | None = None,
    particle_diameter_m: float | None = None,
    size_m: float = 4e-3,
    tip_radius_m: float = 25e-6,
    spacing_m: float | None = None,
    coverage: float = 0.6,
    size_cv: float = 0.25,
    embed_range: tuple[float, float] = (0.3, 0.6),
    rng: int | np.random.Generator | None = None,
) -> GridSurface:
    """Sandpaper analog: partly embedded spherical grit particles on a flat base (§3.3).

    Particles are placed uniformly at random (overlaps allowed) on a square periodic
    patch; diameters are log-normal with mean ``particle_diameter_m`` and coefficient of
    variation ``size_cv``; each sphere is sunk into the base by a fraction of its diameter
    drawn uniformly from ``embed_range``. The height is the upper envelope of the exposed
    caps and the base (z = 0). Their number fills ``coverage`` of the base area with
    particle cross-sections (counting overlaps).

    The default spacing, ``min(tip_radius_m / 5, particle_diameter_m / 10)``, resolves both
    a tip of radius ``tip_radius_m`` and the particles (P600's 25.8 um grains included).

    Parameters
    ----------
    grit
        One of ``P36``, ``P60``, ``P600`` (mean particle size from the paper), or None
        when ``particle_diameter_m`` is given.
    size_m
        Side of the square patch, metres.
    """
    if grit is not None:
        if grit not in GRIT_PARTICLE_DIAMETER_M:
            raise SpineInputError(f"grit must be one of {sorted(GRIT_PARTICLE_DIAMETER_M)}, got {grit!r}")
        if particle_diameter_m is None:
            particle_diameter_m = GRIT_PARTICLE_DIAMETER_M[grit]
    if particle_diameter_m is None:
        raise SpineInputError("give grit (P36, P60, P600) or particle_diameter_m")
    d_mean = check_positive("particle_diameter_m", particle_diameter_m)
    size_m = check_positive("size_m", size_m)
    tip_radius_m = check_positive("tip_radius_m", tip_radius_m)
    spacing_m = (
        min(tip_radius_m / 5, d_mean / 10) if spacing_m is None else check_positive("spacing_m", spacing_m)
    )
    coverage = check_positive("coverage", coverage)
    size_cv = float(size_cv)
    if not (0 <= size_cv < 2):
        raise SpineInputError(f"size_cv must be in [0, 2), got {size_cv!r}")
    e_lo, e_hi = _range("embed_range", embed_range, positive=False)
    if not (0 <= e_lo and e_hi < 1):
        raise SpineInputError(f"embed_range must lie within [0, 1), got {embed_range!r}")
    check_grid_size(
        size_m / spacing_m, size_m / spacing_m, where="sandpaper (size_m / spacing_m points a side)"
    )
    n = math.ceil(size_m / spacing_m - 1e-9)
    if n < _MIN_POINTS_PER_SIDE:
        raise SpineInputError(f"size_m / spacing_m gives {n} points; need at least 4")
    if size_m < 2 * d_mean:
        raise SpineInputError(
            f"size_m ({size_m:g}) must be at least twice the particle diameter ({d_mean:g})"
        )
    gen, seed = _rng_and_seed(rng)
    spacing = size_m / n
    mean_area = math.pi * (d_mean / 2) ** 2 * (1 + size_cv**2)
    n_particles = max(1, round(coverage * size_m**2 / mean_area))

    sig_ln = math.sqrt(math.log1p(size_cv**2))
    diam = d_mean * np.exp(gen.normal(-0.5 * sig_ln**2, sig_ln, n_particles))
    px = gen.uniform(0, size_m, n_particles)
    py = gen.uniform(0, size_m, n_particles)
    embed = gen.uniform(e_lo, e_hi, n_particles)

    heights = _particle_envelope(n, spacing, diam, px, py, embed)
    coords = spacing * np.arange(n) - size_m / 2
    return GridSurface(
        heights=heights,
        x=coords,
        y=coords.copy(),
        periodic=True,
        unit="m",
        metadata=_meta(
            "sandpaper",
            seed,
            grit=grit,
            particle_diameter_m=d_mean,
            size_m=size_m,
            tip_radius_m=tip_radius_m,
            spacing_m=spacing,
            coverage=coverage,
            size_cv=size_cv,
            embed_range=(e_lo, e_hi),
            n_particles=n_particles,
        ),
    )


# --------------------------------------------------------------------------- MuJoCo hfield


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
    """Inverse of :func:`to_hfield`: the gridded surface MuJoCo's samples describe."""
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


# --------------------------------------------------------------------------- engine geometry


@dataclass(frozen=True, eq=False)
class TriangulatedSurface(Surface):
    """The piecewise-linear surface MuJoCo's hfield collides with.

    Each grid cell ``[x_i, x_i+1] x [y_j, y_j+1]`` is split into two triangles along the
    diagonal from its ``(x_min, y_min)`` corner to its ``(x_max, y_max)`` corner, as in
    MuJoCo's hfield (``tests/test_sim.py`` checks the facet normals against MuJoCo's
    contacts). Height and gradient are exact per facet; the Hessian is zero. On a cell
    edge or diagonal the facet with the smaller index wins (lower triangle, then the cell
    with the smaller i, j). Points outside the grid evaluate to NaN.

    Build it from the samples MuJoCo sees: ``TriangulatedSurface.from_grid(from_hfield(hf))``
    or ``from_grid(surface.sample(n))``.

    Attributes
    ----------
    heights : ndarray, shape (ny, nx)
    x, y : ndarray, shapes (nx,), (ny,)
        Uniform, strictly increasing.
    """

    heights: np.ndarray
    x: np.ndarray
    y: np.ndarray
    unit: str = "1"
    metadata: dict = field(default_factory=dict)
    bounds: tuple[float, float, float, float] = field(init=False)

    def __post_init__(self):
        grid = GridSurface(heights=self.heights, x=self.x, y=self.y, unit=self.unit)
        object.__setattr__(self, "heights", grid.heights)
        object.__setattr__(self, "x", grid.x)
        object.__setattr__(self, "y", grid.y)
        object.__setattr__(self, "bounds", grid.bounds)

    @classmethod
    def from_grid(cls, grid: GridSurface) -> TriangulatedSurface:
        """The triangulation of a grid surface's own samples (non-periodic)."""
        return cls(
            heights=grid.heights,
            x=grid.x,
            y=grid.y,
            unit=grid.unit,
            metadata=dict(grid.metadata, triangulated=True),
        )

    def _evaluate(self, x, y, order):
        ny, nx = self.heights.shape
        dx = (self.x[-1] - self.x[0]) / (nx - 1)
        dy = (self.y[-1] - self.y[0]) / (ny - 1)
        u = (x - self.x[0]) / dx
        v = (y - self.y[0]) / dy
        inside = (u >= -1e-9) & (u <= nx - 1 + 1e-9) & (v >= -1e-9) & (v <= ny - 1 + 1e-9)
        i = np.clip(np.floor(u), 0, nx - 2).astype(np.intp)
        j = np.clip(np.floor(v), 0, ny - 2).astype(np.intp)
        s, t = u - i, v - j
        h = self.heights
        h00, h10, h01, h11 = h[j, i], h[j, i + 1], h[j + 1, i], h[j + 1, i + 1]
        lower = s >= t
        fs = np.where(lower, h10 - h00, h11 - h01)
        ft = np.where(lower, h11 - h10, h01 - h00)
        out = [h00 + s * fs + t * ft]
        if order >= 1:
            out += [fs / dx, ft / dy]
        if order >= 2:
            zero = np.zeros_like(out[0])
            out += [zero, zero.copy(), zero.copy()]
        if not inside.all():
            for arr in out:
                arr[~inside] = np.nan
        return tuple(out)


@dataclass(frozen=True, eq=False)
class BallOnFacets(Surface):
    """The surface a ball of radius ``radius`` rides on over ``facets``: the height of its
    centre, less the radius, and the slopes of its contact, exactly.

    At ``(x, y)`` the ball rests on the highest point of contact with any facet, edge or
    vertex of the triangulation (the one MuJoCo's hfield collides with): a facet seen
    through its face lifts the centre to the facet's plane plus ``radius`` along its normal,
    an edge to the cylinder around it, a vertex to the sphere around it. The slopes are those
    of the contact normal ``n = (centre - contact) / radius``: ``(-n_x / n_z, -n_y / n_z)``,
    what the engine's contact reports, with no interpolation between samples. Where two
    contacts tie (a concave crease) the slope is that of one of them.

    This is the exact form of ``spine_mj.streamline.dilate(facets, radius)``, which samples
    the same height on a grid and interpolates it by a spline: at steep kinks (grit walls)
    the spline overshoots, and the sampled dilation sits up to slope x spacing low
    (docs/physics.md §4). Points whose ball reaches beyond the facets see only the facets
    inside. The Hessian is not defined (order 2 raises).

    Attributes
    ----------
    facets : TriangulatedSurface
    radius : float
        Ball radius in the surface's length unit, > 0.
    compiled : bool
        Evaluate with the compiled kernel (:mod:`spine_mj._contact_kernel`, the default) or
        with the numpy reference it is tested against (same numbers; about 1 ms per call).
    """

    facets: TriangulatedSurface
    radius: float
    compiled: bool = True
    unit: str = field(init=False)
    metadata: dict = field(init=False)
    bounds: tuple[float, float, float, float] = field(init=False)

    def __post_init__(self):
        if not isinstance(self.facets, TriangulatedSurface):
            raise SpineInputError(f"facets must be a TriangulatedSurface, got {type(self.facets).__name__}")
        object.__setattr__(self, "radius", check_positive("radius (tip radius)", self.radius))
        object.__setattr__(self, "unit", self.facets.unit)
        object.__setattr__(self, "bounds", self.facets.bounds)
        meta = dict(self.facets.metadata, dilated_by=self.radius, generator="BallOnFacets")
        object.__setattr__(self, "metadata", meta)

    def _evaluate(self, x, y, order):
        if order > 1:
            raise SpineInputError("BallOnFacets has no Hessian (order 2): its facets are flat")
        if self.compiled:
            from spine_mj._contact_kernel import ball_on_facets

            fac = self.facets
            ny, nx = fac.heights.shape
            dx = (fac.x[-1] - fac.x[0]) / (nx - 1)
            dy = (fac.y[-1] - fac.y[0]) / (ny - 1)
            f, fx, fy = ball_on_facets(
                np.ascontiguousarray(x, dtype=float),
                np.ascontiguousarray(y, dtype=float),
                np.ascontiguousarray(fac.heights, dtype=float),
                float(fac.x[0]),
                float(fac.y[0]),
                float(dx),
                float(dy),
                float(self.radius),
            )
        else:
            parts = [self._contact(x[s : s + 1024], y[s : s + 1024]) for s in range(0, x.size, 1024)]
            f, fx, fy = (np.concatenate([p[k] for p in parts]) for k in range(3))
        return (f,) if order == 0 else (f, fx, fy)

    def _contact(self, x, y):
        """Centre height less the radius and the contact's slopes at points ``x``, ``y``
        (the numpy reference of the compiled kernel)."""
        fac, r = self.facets, self.radius
        h = fac.heights
        ny, nx = h.shape
        x0, y0 = fac.x[0], fac.y[0]
        dx = (fac.x[-1] - x0) / (nx - 1)
        dy = (fac.y[-1] - y0) / (ny - 1)
        mx, my = int(math.ceil(2 * r / dx)) + 2, int(math.ceil(2 * r / dy)) + 2
        i0 = np.floor((x - r - x0) / dx).astype(np.intp)[:, None] + np.arange(mx)[None, :]
        j0 = np.floor((y - r - y0) / dy).astype(np.intp)[:, None] + np.arange(my)[None, :]
        # nodes of the window (k, my, mx): every node, edge and cell the ball can reach
        ii = np.broadcast_to(i0[:, None, :], (x.size, my, mx))
        jj = np.broadcast_to(j0[:, :, None], (x.size, my, mx))
        cx, cy = x[:, None, None], y[:, None, None]
        best = np.full(x.size, -np.inf)
        contact = np.zeros((x.size, 3))

        def node(i, j):
            ok = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
            ic, jc = np.clip(i, 0, nx - 1), np.clip(j, 0, ny - 1)
            return x0 + ic * dx, y0 + jc * dy, h[jc, ic], ok

        def keep(z, px, py, pz, ok):
            z = np.where(ok, z, -np.inf).reshape(x.size, -1)
            k = np.argmax(z, axis=1)
            top = z[np.arange(x.size), k]
            better = top > best
            best[better] = top[better]
            for c, p in enumerate((px, py, pz)):
                p = np.broadcast_to(p, ok.shape).reshape(x.size, -1)
                contact[better, c] = p[np.arange(x.size), k][better]

        ax, ay, az, aok = node(ii, jj)
        ahead = {step: node(ii + step[0], jj + step[1]) for step in ((1, 0), (0, 1), (1, 1))}
        with np.errstate(invalid="ignore"):
            d2 = (cx - ax) ** 2 + (cy - ay) ** 2  # vertices: the sphere around each
            keep(az + np.sqrt(r * r - d2), ax, ay, az, aok & (d2 <= r * r))
            for bx, by, bz, bok in ahead.values():  # edges: the cylinder around each
                ex, ey, ez = bx - ax, by - ay, bz - az
                ll = ex * ex + ey * ey + ez * ez
                wd = (cx - ax) * ex + (cy - ay) * ey
                alpha = (ex * ex + ey * ey) / ll
                beta = wd * ez / ll
                gamma = (cx - ax) ** 2 + (cy - ay) ** 2 - wd * wd / ll - r * r
                e = (beta + np.sqrt(beta * beta - alpha * gamma)) / alpha
                t = (wd + e * ez) / ll
                ok = aok & bok & (t >= 0) & (t <= 1) & np.isfinite(e)
                keep(az + e, ax + t * ex, ay + t * ey, az + t * ez, ok)
            _, _, bz, bok = ahead[(1, 1)]
            _, _, h10, ok10 = ahead[(1, 0)]
            _, _, h01, ok01 = ahead[(0, 1)]
            for lower in (True, False):  # faces: the plane lifted along its normal
                gx = np.where(lower, h10 - az, bz - h01) / dx
                gy = np.where(lower, bz - h10, h01 - az) / dy
                norm = np.sqrt(1.0 + gx * gx + gy * gy)
                px, py = cx + r * gx / norm, cy + r * gy / norm  # the foot of the contact
                s, t = (px - ax) / dx, (py - ay) / dy
                inside = (t >= 0) & (t <= s) & (s <= 1) if lower else (s >= 0) & (s <= t) & (t <= 1)
                pz = az + gx * (px - ax) + gy * (py - ay)
                keep(pz + r / norm, px, py, pz, aok & bok & (ok10 if lower else ok01) & inside)
        nxc, nyc, nzc = cx[:, 0, 0] - contact[:, 0], cy[:, 0, 0] - contact[:, 1], best - contact[:, 2]
        return best - r, -nxc / nzc, -nyc / nzc
