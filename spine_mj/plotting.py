"""Figures drawn from surfaces and results (matplotlib, headless Agg backend).

Functions return a :class:`matplotlib.figure.Figure`; saving happens in the caller
(:func:`save_figure` writes atomically).
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib.colors as mcolors
import numpy as np
from matplotlib.figure import Figure

from spine_mj.errors import atomic_output
from spine_mj.surfaces import GridSurface, Surface

__all__ = ["new_figure", "save_figure", "sim_run_figure", "surface_preview"]


def new_figure(**kwargs):
    """A figure not tied to any GUI (safe in threads, workers and headless machines)."""

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
        return GridSurface(
            heights=surface.heights[::step, ::step],
            x=surface.x[::step],
            y=surface.y[::step],
            unit=surface.unit,
        )
    return surface.sample(max_points)


def _height_map(fig, ax, grid: GridSurface, unit: str):
    """Height map of ``grid`` on ``ax`` with a colour bar; returns ``ax``."""
    extent = (grid.x[0], grid.x[-1], grid.y[0], grid.y[-1])
    im = ax.imshow(grid.heights, origin="lower", extent=extent, cmap="terrain", aspect="equal")
    fig.colorbar(im, ax=ax, label=f"height{unit}")
    return ax


def surface_preview(surface: Surface, *, title: str | None = None, max_points: int = 300):
    """Height map (left) and 3-D view (right) of a surface."""
    grid = _display_grid(surface, max_points)
    unit = "" if surface.unit == "1" else f" [{surface.unit}]"
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    ax = _height_map(fig, fig.add_subplot(1, 2, 1), grid, unit)
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")
    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    xx, yy = np.meshgrid(grid.x, grid.y)
    ax3.plot_surface(
        xx,
        yy,
        grid.heights,
        cmap="terrain",
        linewidth=0,
        antialiased=False,
        rcount=min(120, grid.shape[0]),
        ccount=min(120, grid.shape[1]),
    )
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
    ax = _height_map(fig, fig.add_subplot(1, 2, 1), grid, unit)
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
        ax2.plot(
            result.time_s[onsets],
            result.drive_force_n[onsets] / fp,
            "v",
            color="crimson",
            ms=4,
            label="slip onset",
        )
        ax2.legend(loc="upper left", fontsize=8)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("drive force / F_p")
    fig.suptitle(
        f"{type(result.drive).__name__}, I_e = {result.inertia_number:.3g}, end: {result.end_reason.value}"
    )
    return fig


# --------------------------------------------------------------------------- engagement theory


def _kappa_colors(ax, x, y, k, region, *, kmax=10.0):
    """kappa as colour (slip blank), self-lock in dark red; returns the image."""

    shown = np.where(region == 1, np.minimum(k, kmax), np.nan)
    extent = (x[0], x[-1], y[0], y[-1])
    im = ax.imshow(shown, origin="lower", extent=extent, cmap="jet", vmin=0, vmax=kmax)
    lock = np.where(region == 2, 1.0, np.nan)
    ax.imshow(lock, origin="lower", extent=extent, cmap=mcolors.ListedColormap(["#5a0000"]), vmin=0, vmax=1)
    return im


def kappa_map_figure(maps: dict, mu: float):
    """Fig. 2B: kappa maps; ``maps[name] = (xs, heights, kappa, region)``."""
    fig = new_figure(figsize=(11, 4.8), layout="constrained")
    for i, (name, (xs, h, k, region)) in enumerate(maps.items()):
        ax = fig.add_subplot(1, len(maps), i + 1)
        im = _kappa_colors(ax, xs, xs, k, region)
        ax.contour(xs, xs, h, colors="k", linewidths=0.4, levels=8)
        ax.set_title(f"{name}: kappa (slip blank, self-lock dark red)")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        fig.colorbar(im, ax=ax, label="kappa (clipped at 10)")
    fig.suptitle(f"Engagement ratio kappa, mu_s = {mu:g}")
    return fig


def single_peak_figure(runs: dict, numbers: dict):
    """Figs. 3-4: streamlines over the surface and kappa along streamline vs ideal."""
    fig = new_figure(figsize=(12, 8), layout="constrained")
    for row, (name, (surf, s5, i5)) in enumerate(runs.items()):
        ax = fig.add_subplot(2, 2, 2 * row + 1)
        xs = np.linspace(-5, 5, 201)
        ax.contourf(xs, xs, surf.height(xs[None, :], xs[:, None]), levels=20, cmap="terrain")
        for i in range(len(s5)):
            p, q = s5.path(i), i5.path(i)
            ax.plot(q["x"], q["y"], color="0.5", lw=0.8, ls="--")
            ax.plot(p["x"], p["y"], lw=1.5)
            ax.plot(p["x"][0], p["y"][0], "o", mfc="none", color="k")
            ax.plot(p["x"][-1], p["y"][-1], "x", color="k")
        ax.set_title(
            f"{name}: streamlines (solid), ideal (dashed); "
            f"ratio {numbers[f'{name}_ratio'] or float('nan'):.3f}"
        )
        ax.set_aspect("equal")
        ax2 = fig.add_subplot(2, 2, 2 * row + 2)
        for i in range(len(s5)):
            p, q = s5.path(i), i5.path(i)
            line = ax2.plot(p["x"], np.minimum(p["kappa"], 20), lw=1.2, label=f"y0 = {s5.start_y[i]:g}")[0]
            ax2.plot(q["x"], np.minimum(q["kappa"], 20), color=line.get_color(), ls="--", lw=0.8)
            for path in (p, q):
                if path["region"][-1] == 2:
                    ax2.plot(path["x"][-1], 20, "^", color=line.get_color())
        ax2.set_ylim(0, 21)
        ax2.set_xlabel("x")
        ax2.set_ylabel("kappa (self-lock: triangle)")
        ax2.legend(fontsize=7)
    fig.suptitle(f"Single Gaussian peak / valley, mu_s = {numbers['mu']:g}")
    return fig


def random_gaussian_figure(scatter: dict, numbers: dict):
    """Fig. 5 B(III)/C(III): max kappa per run, ideal vs streamline (inf drawn at the top)."""
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    for i, (name, (ideal, stream)) in enumerate(scatter.items()):
        ax = fig.add_subplot(1, 2, i + 1)
        top = 30.0
        for j, (vals, label, color) in enumerate(
            ((ideal, "ideal", "0.5"), (stream, "streamline", "C0" if i == 0 else "C3"))
        ):
            shown = np.where(np.isfinite(vals), np.minimum(vals, top), top)
            xj = j + 0.15 * np.random.default_rng(j).uniform(-1, 1, vals.size)
            ax.plot(xj, shown, "o", ms=3, color=color, label=label)
            med = np.median(vals)
            ax.hlines(min(med, top), j - 0.3, j + 0.3, color="k")
        ax.set_xticks([0, 1], ["ideal", "streamline"])
        ax.set_ylabel("max kappa (self-lock at top)")
        ax.set_title(
            f"{name}: medians {numbers[f'{name}_median_ideal']} -> {numbers[f'{name}_median_streamline']}"
        )
    return fig


def fractal_hurst_figure(table: list):
    """Fig. 9B-C: self-lock rate and concavity shares against H (mean +- sd of groups)."""
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    h = [row["hurst"] for row in table]

    def series(key):
        m = np.array([np.nan if row[f"{key}_mean"] is None else row[f"{key}_mean"] for row in table])
        s = np.array([np.nan if row[f"{key}_sd"] is None else row[f"{key}_sd"] for row in table])
        return 100 * m, 100 * s

    panels = (
        (
            "Fig. 9B: sectional method",
            "%",
            (
                ("rate", "self-lock rate"),
                ("sect_concave", "concave (sectional)"),
                ("sect_convex", "convex (sectional)"),
            ),
        ),
        (
            "Fig. 9C: Hessian method",
            "% of self-locks",
            (("hess_concave", "concave"), ("hess_saddle", "saddle"), ("hess_convex", "convex")),
        ),
    )
    for col, (title, ylabel, curves) in enumerate(panels, start=1):
        ax = fig.add_subplot(1, 2, col)
        for key, label in curves:
            m, s = series(key)
            ax.errorbar(h, m, yerr=s, marker="o", capsize=3, label=label)
        ax.set(xlabel="Hurst index H", ylabel=ylabel, title=title)
        ax.legend()
    return fig


def streamline_figure(surface, stream, ideal, *, title: str = ""):
    """3-D view of streamlines (solid) and ideal paths (dashed) over the surface, and kappa
    along each path."""
    grid = _display_grid(surface, 150)
    fig = new_figure(figsize=(12, 5), layout="constrained")
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    xx, yy = np.meshgrid(grid.x, grid.y)
    ax3.plot_surface(
        xx,
        yy,
        grid.heights,
        cmap="terrain",
        alpha=0.6,
        linewidth=0,
        rcount=min(80, grid.shape[0]),
        ccount=min(80, grid.shape[1]),
    )
    ax = fig.add_subplot(1, 2, 2)
    for i in range(len(stream)):
        p, q = stream.path(i), ideal.path(i)
        line = ax3.plot(p["x"], p["y"], p["z"], lw=2)[0]
        c = line.get_color()
        ax3.plot(q["x"], q["y"], q["z"], lw=1, ls="--", color=c)
        ax3.scatter([p["x"][0]], [p["y"][0]], [p["z"][0]], color=c, marker="o")
        ax3.scatter([p["x"][-1]], [p["y"][-1]], [p["z"][-1]], color=c, marker="x")
        ax.plot(
            p["x"],
            np.minimum(p["kappa"], 20),
            color=c,
            label=f"({stream.start_x[i]:g}, {stream.start_y[i]:g})",
        )
        ax.plot(q["x"], np.minimum(q["kappa"], 20), color=c, ls="--", lw=0.8)
        if p["region"][-1] == 2:
            ax.plot(p["x"][-1], 20, "^", color=c)
    ax3.set_xlabel("x")
    ax3.set_ylabel("y")
    ax3.set_zlabel("z")
    ax.set_ylim(0, 21)
    ax.set_xlabel("x")
    ax.set_ylabel("kappa (clipped at 20; triangle = self-lock)")
    ax.legend(fontsize=7)
    fig.suptitle(title or "Streamlines (solid) and ideal trajectories (dashed)")
    return fig


def roughness_figure(rough, *, title: str = ""):
    """Radially averaged PSD on log axes with the fitted Hurst slope, and the numbers."""
    fig = new_figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    unit = "" if rough.unit == "1" else f" [{rough.unit}]"
    ax.loglog(rough.q, rough.psd, "o-", ms=3, lw=1, color="#1f4e79", label="radial PSD")
    if np.isfinite(rough.hurst):
        q = np.geomspace(*rough.fit_range, 20)
        fit = rough.psd_prefactor * q ** (-(2 * rough.hurst + 2))
        ax.loglog(q, fit, "--", color="#c55a11", lw=2, label=f"fit: C ~ q^-(2H+2), H = {rough.hurst:.2f}")
    ax.set_xlabel(f"wavevector q = 2π/λ [rad{'' if rough.unit == '1' else ' / ' + rough.unit}]")
    ax.set_ylabel(f"PSD C(q){'' if rough.unit == '1' else f' [{rough.unit}^4]'}")
    ax.set_title(
        title
        or f"rms height {rough.rms_height:.3g}{unit}, rms slope {rough.rms_slope:.3g}, "
        f"L_c {rough.char_length:.3g}, l_s {rough.slope_correlation_length:.3g}",
        fontsize=9,
    )
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    return fig
