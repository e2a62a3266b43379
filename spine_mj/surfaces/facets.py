"""Engine geometry: the piecewise-linear surface MuJoCo's hfield collides with
(:class:`TriangulatedSurface`) and the surface a ball tip's centre rides on over those
facets (:class:`BallOnFacets`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.surfaces.types import GridSurface, Surface


@dataclass(frozen=True, eq=False)
class TriangulatedSurface(Surface):
    """The piecewise-linear surface MuJoCo's hfield collides with.

    Each grid cell ``[x_i, x_i+1] x [y_j, y_j+1]`` is split into two triangles along the
    diagonal from its ``(x_min, y_min)`` corner to its ``(x_max, y_max)`` corner, as in
    MuJoCo's hfield (``tests/sim/test_sim_model.py`` checks the facet normals against MuJoCo's
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

    This is the exact form of ``spine_mj.surfaces.dilation.dilate(facets, radius)``, which samples
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
        Evaluate with the compiled kernel (:mod:`spine_mj.surfaces._contact_kernel`, the default) or
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
            from spine_mj.surfaces._contact_kernel import ball_on_facets

            f, fx, fy = ball_on_facets(
                np.ascontiguousarray(x, dtype=float),
                np.ascontiguousarray(y, dtype=float),
                *self.kernel_args(),
            )
        else:
            parts = [self._contact(x[s : s + 1024], y[s : s + 1024]) for s in range(0, x.size, 1024)]
            f, fx, fy = (np.concatenate([p[k] for p in parts]) for k in range(3))
        return (f,) if order == 0 else (f, fx, fy)

    def kernel_args(self) -> tuple:
        """``(heights, x0, y0, dx, dy, radius)``: the grid as the compiled kernels take it
        (:func:`spine_mj.surfaces._contact_kernel.ball_on_facets` and the callers of ``ball_at``)."""
        fac = self.facets
        ny, nx = fac.heights.shape
        dx = (fac.x[-1] - fac.x[0]) / (nx - 1)
        dy = (fac.y[-1] - fac.y[0]) / (ny - 1)
        heights = np.ascontiguousarray(fac.heights, dtype=float)
        return heights, float(fac.x[0]), float(fac.y[0]), float(dx), float(dy), float(self.radius)

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
