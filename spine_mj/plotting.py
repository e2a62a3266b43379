"""Figures drawn from surfaces and results (matplotlib, headless Agg backend).

Functions return a :class:`matplotlib.figure.Figure`; saving happens in the caller
(:func:`save_figure` writes atomically).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from spine_mj.errors import atomic_output
from spine_mj.surfaces import GridSurface, Surface

__all__ = ["new_figure", "save_figure", "sim_run_figure", "surface_preview"]


def new_figure(**kwargs):
    """A figure not tied to any GUI (safe in threads, workers and headless machines)."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def save_figure(fig, path: str | os.PathLike, *, dpi: int = 120) -> Path:
    """Save ``fig`` to ``path`` atomically; the format follows the suffix."""
    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".") or "png")
    return path


def _display_grid(surface: Surface, max_points: int) -> GridSurface:
    if isinstance(surface, GridSurface) and max(surface.shape) <= max_points:
        return surface
    if isinstance(surface, GridSurface):
        step = int(np.ceil(max(surface.shape) / max_points))
        return GridSurface(heights=surface.heights[::step, ::step], x=surface.x[::step],
                           y=surface.y[::step], unit=surface.unit)
    return surface.sample(max_points)


def surface_preview(surface: Surface, *, title: str | None = None, max_points: int = 300):
    """Height map (left) and 3-D view (right) of a surface."""
    grid = _display_grid(surface, max_points)
    unit = "" if surface.unit == "1" else f" [{surface.unit}]"
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    ax = fig.add_subplot(1, 2, 1)
    extent = (grid.x[0], grid.x[-1], grid.y[0], grid.y[-1])
    im = ax.imshow(grid.heights, origin="lower", extent=extent, cmap="terrain", aspect="equal")
    fig.colorbar(im, ax=ax, label=f"height{unit}")
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")
    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    xx, yy = np.meshgrid(grid.x, grid.y)
    ax3.plot_surface(xx, yy, grid.heights, cmap="terrain", linewidth=0, antialiased=False,
                     rcount=min(120, grid.shape[0]), ccount=min(120, grid.shape[1]))
    ax3.set_xlabel("x")
    ax3.set_ylabel("y")
    ax3.set_zlabel("z")
    h = grid.heights
    z_span = float(h.max() - h.min()) or 1.0
    xy_span = float(max(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0]))
    ax3.set_box_aspect((1, 1, max(0.15, min(1.0, 3 * z_span / xy_span))))
    name = title or surface.metadata.get("preset") or surface.metadata.get("generator", "surface")
    rms = float(np.std(h))
    fig.suptitle(f"{name}: {grid.shape[1]} x {grid.shape[0]} shown, rms height {rms:.3g}{unit}")
    return fig


def sim_run_figure(result, surface: Surface, *, length_scale_m: float, max_points: int = 300):
    """A MuJoCo run (:class:`spine_mj.sim.RunResult`): path over the surface's height map
    (left, surface units) and drive force / F_p against time (right), slip onsets marked."""
    grid = _display_grid(surface, max_points)
    unit = "" if surface.unit == "1" else f" [{surface.unit}]"
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    ax = fig.add_subplot(1, 2, 1)
    extent = (grid.x[0], grid.x[-1], grid.y[0], grid.y[-1])
    im = ax.imshow(grid.heights, origin="lower", extent=extent, cmap="terrain", aspect="equal")
    fig.colorbar(im, ax=ax, label=f"height{unit}")
    path = result.position_m / length_scale_m
    ax.plot(path[:, 0], path[:, 1], color="crimson", lw=1.5, label="tip")
    ax.plot(path[0, 0], path[0, 1], "o", color="white", mec="k", label="start")
    ax.plot(path[-1, 0], path[-1, 1], "x", color="k", label=result.end_reason.value)
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")
    ax.legend(loc="upper left", fontsize=8)
    ax2 = fig.add_subplot(1, 2, 2)
    fp = result.scales.preload_n
    ax2.plot(result.time_s, result.drive_force_n / fp, color="navy", lw=1)
    onsets = [e.index for e in result.events if e.kind == "slip_onset"]
    if onsets:
        ax2.plot(result.time_s[onsets], result.drive_force_n[onsets] / fp, "v", color="crimson",
                 ms=4, label="slip onset")
        ax2.legend(loc="upper left", fontsize=8)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("drive force / F_p")
    fig.suptitle(f"{type(result.drive).__name__}, I_e = {result.inertia_number:.3g}, "
                 f"end: {result.end_reason.value}")
    return fig


# --------------------------------------------------------------------------- engagement theory
