"""The surface types: the :class:`Surface` interface, analytic :class:`GaussianSurface` sums
and gridded :class:`GridSurface` height maps (C2 cubic B-spline, :class:`BSplineGrid`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.memory import BLOCK_BYTES
from spine_mj.surfaces.base import (
    _CHUNK,
    _MIN_POINTS_PER_SIDE,
    _NONPERIODIC_PAD,
    MAX_PEAKS,
    _bounds,
    _broadcast_points,
    _flag,
    _grid_count,
    check_grid_size,
)

# float64 temporaries of one Gaussian's factors that GaussianSurface's evaluation holds at once
_FACTOR_ARRAYS = 8


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

    def _points_per_chunk(self) -> int:
        """How many points :meth:`_evaluate` takes at once (its temporaries bounded)."""
        return _CHUNK

    def _eval_shaped(self, x, y, order: int) -> tuple[np.ndarray, ...]:
        xf, yf, shape = _broadcast_points(x, y)
        step = self._points_per_chunk()
        parts = [
            self._evaluate(xf[s : s + step], yf[s : s + step], order) for s in range(0, xf.size, step)
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

    At most :data:`~spine_mj.surfaces.MAX_PEAKS` Gaussians, whether generated or read from
    a file. Evaluation works in blocks of points x Gaussians within
    :data:`spine_mj.memory.BLOCK_BYTES`.
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
        if n > MAX_PEAKS:
            raise SpineInputError(f"a Gaussian surface holds at most {MAX_PEAKS} Gaussians, got {n}")
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
        dilating a surface of 100 Gaussians on a 3201^2 grid: 47 s pointwise. The
        Gaussians go in blocks whose (block, nx + ny) factors fit in BLOCK_BYTES."""
        step = max(1, BLOCK_BYTES // (8 * _FACTOR_ARRAYS * (x.size + y.size)))
        out = None
        for lo in range(0, self.n_gaussians, step):
            part = self._on_grid_block(x, y, order, slice(lo, lo + step))
            out = part if out is None else [a + b for a, b in zip(out, part, strict=True)]
        return tuple(out)

    def _on_grid_block(self, x, y, order, k: slice) -> list[np.ndarray]:
        """:meth:`_on_grid` of the Gaussians ``k`` only."""
        cx, cy, sx, sy = (
            self.center_x[k, None],
            self.center_y[k, None],
            self.sigma_x[k, None],
            self.sigma_y[k, None],
        )
        dx = (x[None, :] - cx) / sx  # (K, nx)
        dy = (y[None, :] - cy) / sy  # (K, ny)
        ex, ey = np.exp(-0.5 * dx * dx), np.exp(-0.5 * dy * dy)
        ay = self.amplitude[k, None] * ey
        out = [ay.T @ ex]
        if order >= 1:
            gx, gy = -dx / sx, -dy / sy
            out += [ay.T @ (ex * gx), (ay * gy).T @ ex]
        if order >= 2:
            out += [
                ay.T @ (ex * (gx * gx - 1.0 / sx**2)),
                (ay * gy).T @ (ex * gx),
                (ay * (gy * gy - 1.0 / sy**2)).T @ ex,
            ]
        return out

    def _points_per_chunk(self) -> int:
        return max(1, min(_CHUNK, BLOCK_BYTES // (8 * _FACTOR_ARRAYS * self.n_gaussians)))

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

    Attributes
    ----------
    coef : ndarray, 2-D
        The spline's coefficients, indexed as above.
    offset : int
        Index shift of the coefficients (padding of the non-periodic grid).
    x0, dx, y0, dy : float
        The grid's first coordinate and spacing along x and y.
    nx, ny : int
        Grid points along x and y.
    periodic : bool
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
    curvature (h the spacing; ``tests/surfaces/test_surfaces.py`` measures the orders). A
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
        heights = np.array(self.heights, dtype=float, order="C")  # the kernels take C order
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
        from scipy import ndimage  # on demand: a grid's spline; scipy.ndimage takes ~0.3 s to import

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
