"""Figures drawn from surfaces and results (matplotlib, headless Agg backend), in one house style.

Every figure is drawn inside :func:`house_style` (the figure functions here are wrapped by
:func:`styled`; :func:`save_figure` saves inside it too): axis labels with units,
colour bars on maps, perceptual colour maps (:data:`SEQUENTIAL_CMAP`, and
:data:`DIVERGING_CMAP` where the sign of a height matters), one colour per drive protocol
(:func:`protocol_color`) and numbers in titles rounded to 3 significant digits
(:func:`sig`). Lengths of scans in metres are drawn in um or mm (:func:`length_unit`).

Functions return a :class:`matplotlib.figure.Figure`; saving happens in the caller
(:func:`save_figure` writes atomically).
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
from pathlib import Path

import matplotlib
import matplotlib.colors as mcolors
import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from spine_mj.atomic import atomic_output
from spine_mj.surfaces import GridSurface, Surface

__all__ = [
    "DIVERGING_CMAP",
    "PROTOCOL_COLORS",
    "SEQUENTIAL_CMAP",
    "height_mappable",
    "house_style",
    "length_unit",
    "new_figure",
    "path_overlay_figure",
    "protocol_color",
    "save_figure",
    "shared_height_norm",
    "sig",
    "sim_run_figure",
    "styled",
    "surface_preview",
]

#: Colour map of heights and other one-signed quantities (perceptually uniform).
SEQUENTIAL_CMAP = "cividis"
#: Colour map of quantities whose sign matters (peaks against valleys), centred on 0.
DIVERGING_CMAP = "RdBu_r"
#: Okabe-Ito colours, distinguishable with colour-blindness; the series cycle of every axis.
SERIES_COLORS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
#: One colour per drive protocol, the same in every panel and every report.
PROTOCOL_COLORS = {"spring": "#0072B2", "ramp": "#D55E00", "static": "#009E73"}
#: Colours of the paths compared in overlays.
PATH_COLORS = {"streamline": "#000000", "facets": "#56B4E9", "mujoco": "#D55E00"}
#: Colour of target / threshold lines (always labelled in a legend).
THRESHOLD_COLOR = "#7a0177"

_HOUSE_RC = {
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "legend.fontsize": 8,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.prop_cycle": matplotlib.cycler(color=list(SERIES_COLORS)),
    "image.cmap": SEQUENTIAL_CMAP,
    "axes.formatter.limits": (-3, 4),
    "axes.formatter.use_mathtext": True,
    "savefig.facecolor": "white",
    "figure.facecolor": "white",
}


@contextlib.contextmanager
def house_style():
    """Context in which figures are drawn and saved in the house style (rcParams)."""
    with matplotlib.rc_context(_HOUSE_RC):
        yield


def styled(func):
    """Decorator: draw the figure of ``func`` inside :func:`house_style`."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with house_style():
            return func(*args, **kwargs)

    return wrapper


def sig(value, digits: int = 3) -> str:
    """``value`` rounded to ``digits`` significant digits for titles and labels.

    ``3.6068453317776017`` -> ``"3.61"``, ``1e-4`` -> ``"0.0001"``, ``123456.0`` ->
    ``"1.23e+05"``, integers as they are, None -> ``"-"``, NaN -> ``"nan"``.
    """
    if value is None:
        return "-"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    v = float(value)
    if not math.isfinite(v):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return f"{v:.{digits}g}"


def protocol_color(protocol: str) -> str:
    """The colour of a drive protocol (spring, ramp, static) in every figure."""
    return PROTOCOL_COLORS.get(str(protocol).split()[0], "#555555")


def length_unit(span_m: float) -> tuple[float, str]:
    """Factor and name of the unit to draw a length span given in metres: um below 1 mm,
    mm below 1 m, else m (so ticks read 400 um, not 0.0004)."""
    span = abs(float(span_m))
    if span < 1e-3:
        return 1e6, "um"
    if span < 1.0:
        return 1e3, "mm"
    return 1.0, "m"


def new_figure(**kwargs):
    """A figure not tied to any GUI (safe in threads, workers and headless machines)."""

    return Figure(**kwargs)


def save_figure(fig, path: str | os.PathLike, *, dpi: int = 120) -> Path:
    """Save ``fig`` to ``path`` atomically; the format follows the suffix."""
    path = Path(path)
    with house_style(), atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".") or "png")
    return path


def _display_grid(surface: Surface, max_points: int) -> GridSurface:
    if isinstance(surface, GridSurface) and max(surface.shape) <= max_points:
        return surface
    if isinstance(surface, GridSurface):
        sy, sx = (int(np.ceil(n / max_points)) for n in surface.shape)  # a narrow strip keeps its rows
        return GridSurface(surface.heights[::sy, ::sx], surface.x[::sx], surface.y[::sy], unit=surface.unit)
    sides = np.diff(surface.bounds)[::2]  # x and y extents
    return surface.sample(*(max(4, round(max_points * side / sides.max())) for side in sides))


def _axes_units(surface: Surface, grid: GridSurface) -> tuple[float, str, float, str]:
    """(length factor, length unit, height factor, height unit) to draw ``grid``: a surface
    in metres in um or mm (one unit for x and y, one for heights), else its own unit."""
    if surface.unit != "m":
        unit = "" if surface.unit == "1" else surface.unit
        return 1.0, unit, 1.0, unit
    span = max(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0])
    lf, lu = length_unit(span)
    hf, hu = length_unit(float(np.ptp(grid.heights)))
    return lf, lu, hf, hu


def _with_unit(name: str, unit: str) -> str:
    return f"{name} [{unit}]" if unit else f"{name} [surface units]"


def _height_map(fig, ax, grid: GridSurface, units: tuple, *, norm=None, cmap=SEQUENTIAL_CMAP, colorbar=True):
    """Height map of ``grid`` on ``ax`` (labelled axes, colour bar unless ``colorbar`` is
    False); ``norm`` shares one colour scale between panels. Returns the image."""
    lf, lu, hf, hu = units
    extent = (grid.x[0] * lf, grid.x[-1] * lf, grid.y[0] * lf, grid.y[-1] * lf)
    im = ax.imshow(grid.heights * hf, origin="lower", extent=extent, cmap=cmap, norm=norm, aspect="equal")
    if colorbar:
        fig.colorbar(im, ax=ax, label=_with_unit("height", hu))
    ax.set_xlabel(_with_unit("x", lu))
    ax.set_ylabel(_with_unit("y", lu))
    ax.grid(False)
    return im


@styled
def surface_preview(surface: Surface, *, title: str | None = None, max_points: int = 300):
    """Height map (left) and 3-D view (right) of a surface, on one colour scale."""
    grid = _display_grid(surface, max_points)
    units = _axes_units(surface, grid)
    lf, lu, hf, hu = units
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    h = grid.heights * hf
    norm = mcolors.Normalize(float(h.min()), float(h.max()))
    _height_map(fig, fig.add_subplot(1, 2, 1), grid, units, norm=norm)
    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    xx, yy = np.meshgrid(grid.x * lf, grid.y * lf)
    ax3.plot_surface(
        xx,
        yy,
        h,
        cmap=SEQUENTIAL_CMAP,
        norm=norm,
        linewidth=0,
        antialiased=False,
        rcount=min(120, grid.shape[0]),
        ccount=min(120, grid.shape[1]),
    )
    ax3.set_xlabel(_with_unit("x", lu))
    ax3.set_ylabel(_with_unit("y", lu))
    ax3.set_zlabel(_with_unit("z", hu))
    z_span = float(np.ptp(grid.heights)) or 1.0
    xy_span = float(max(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0]))
    ax3.set_box_aspect((1, 1, max(0.15, min(1.0, 3 * z_span / xy_span))))
    name = title or surface.metadata.get("preset") or surface.metadata.get("generator", "surface")
    rms = float(np.std(h))
    fig.suptitle(
        f"{name}: {grid.shape[1]} x {grid.shape[0]} samples shown, rms height {sig(rms)}"
        f"{' ' + hu if hu else ''} (3-D view: heights exaggerated)"
    )
    return fig


@styled
def sim_run_figure(result, surface: Surface, *, length_scale_m: float, max_points: int = 300):
    """A MuJoCo run (:class:`spine_mj.sim.RunResult`): path over the surface's height map
    (left) and drive force / F_p against time (right), slip onsets marked."""
    grid = _display_grid(surface, max_points)
    units = _axes_units(surface, grid)
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    ax = fig.add_subplot(1, 2, 1)
    _height_map(fig, ax, grid, units)
    path = result.position_m / length_scale_m * units[0]
    ax.plot(path[:, 0], path[:, 1], color=PATH_COLORS["mujoco"], lw=1.5, label="tip path (MuJoCo)")
    ax.plot(path[0, 0], path[0, 1], "o", color="white", mec="k", label="start")
    ax.plot(path[-1, 0], path[-1, 1], "x", color="k", label=f"end: {result.end_reason.value}")
    ax.legend(loc="upper left")
    ax2 = fig.add_subplot(1, 2, 2)
    fp = result.scales.preload_n
    ax2.plot(result.time_s, result.drive_force_n / fp, color=PROTOCOL_COLORS["spring"], lw=1, label="drive")
    onsets = [e.onset for e in result.slip_events]  # slips relative to the drive (theory.motion)
    if onsets:
        ax2.plot(
            result.time_s[onsets],
            result.drive_force_n[onsets] / fp,
            "v",
            color=PATH_COLORS["mujoco"],
            ms=4,
            label="slip onset",
        )
    ax2.legend(loc="upper left")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("drive force / F_p [1]")
    fig.suptitle(
        f"{type(result.drive).__name__}, I_e = {sig(result.inertia_number)}, end: {result.end_reason.value}"
    )
    return fig


# --------------------------------------------------------------------------- engagement theory

#: Colours of the regions drawn over a kappa map.
SLIP_COLOR = "#d9d9d9"
LOCK_COLOR = "#5a0000"


def _kappa_colors(ax, x, y, k, region, *, kmax=10.0):
    """kappa in the engaged region as colour, slip in light grey, self-lock in dark red;
    returns the image of kappa."""
    extent = (x[0], x[-1], y[0], y[-1])
    slip = np.where(region == 0, 1.0, np.nan)
    ax.imshow(slip, origin="lower", extent=extent, cmap=mcolors.ListedColormap([SLIP_COLOR]), vmin=0, vmax=1)
    shown = np.where(region == 1, np.minimum(k, kmax), np.nan)
    im = ax.imshow(shown, origin="lower", extent=extent, cmap="viridis", vmin=0, vmax=kmax)
    lock = np.where(region == 2, 1.0, np.nan)
    ax.imshow(lock, origin="lower", extent=extent, cmap=mcolors.ListedColormap([LOCK_COLOR]), vmin=0, vmax=1)
    ax.grid(False)
    return im


@styled
def kappa_map_figure(maps: dict, mu: float):
    """Fig. 2B: kappa maps; ``maps[name] = (xs, heights, kappa, region)`` (square domain,
    ``xs`` the coordinates of both axes, surface units)."""
    n = len(maps)
    fig = new_figure(figsize=(5.2 * n + 0.6, 4.8), layout="constrained")
    axes = fig.subplots(1, n, squeeze=False)[0]
    for ax, (name, (xs, h, k, region)) in zip(axes, maps.items()):
        im = _kappa_colors(ax, xs, xs, k, region)
        ax.contour(xs, xs, h, colors="k", linewidths=0.4, levels=8)
        ax.set_title(str(name))
        ax.set(xlabel="x [surface units]", ylabel="y [surface units]", aspect="equal")
    fig.colorbar(im, ax=list(axes), label="engagement ratio kappa [1] (engaged; clipped at 10)")
    handles = [
        Patch(color=SLIP_COLOR, label="slip"),
        Patch(color=LOCK_COLOR, label="self-lock"),
        Line2D([], [], color="k", lw=0.4, label="height contours"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=3)
    fig.suptitle(f"Engagement ratio kappa, mu_s = {sig(mu)}")
    return fig


@styled
def single_peak_figure(runs: dict, numbers: dict):
    """Figs. 3-4: streamlines over the surface and kappa along streamline vs ideal."""
    fig = new_figure(figsize=(12, 8), layout="constrained")
    for row, (name, (surf, s5, i5)) in enumerate(runs.items()):
        ax = fig.add_subplot(2, 2, 2 * row + 1)
        xs = np.linspace(-5, 5, 201)
        cs = ax.contourf(xs, xs, surf.height(xs[None, :], xs[:, None]), levels=20, cmap=SEQUENTIAL_CMAP)
        fig.colorbar(cs, ax=ax, label="height [surface units]")
        for i in range(len(s5)):
            p, q = s5.path(i), i5.path(i)
            ax.plot(q["x"], q["y"], color="0.85", lw=0.8, ls="--", label="ideal" if i == 0 else None)
            ax.plot(p["x"], p["y"], lw=1.5, label="streamline" if i == 0 else None)
            ax.plot(p["x"][0], p["y"][0], "o", mfc="none", color="w")
            ax.plot(p["x"][-1], p["y"][-1], "x", color="w")
        ax.set_title(f"{name}: streamlines (solid), ideal (dashed); ratio {sig(numbers[f'{name}_ratio'])}")
        ax.set(aspect="equal", xlabel="x [surface units]", ylabel="y [surface units]")
        ax.legend(loc="upper left")
        ax2 = fig.add_subplot(2, 2, 2 * row + 2)
        for i in range(len(s5)):
            p, q = s5.path(i), i5.path(i)
            line = ax2.plot(p["x"], np.minimum(p["kappa"], 20), lw=1.2, label=f"y0 = {sig(s5.start_y[i])}")[0]
            ax2.plot(q["x"], np.minimum(q["kappa"], 20), color=line.get_color(), ls="--", lw=0.8)
            for path in (p, q):
                if path["region"][-1] == 2:
                    ax2.plot(path["x"][-1], 20, "^", color=line.get_color())
        ax2.set_ylim(0, 21)
        ax2.set_xlabel("x [surface units]")
        ax2.set_ylabel("kappa [1] (clipped at 20; triangle: self-lock)")
        ax2.legend(title="solid: streamline, dashed: ideal")
    fig.suptitle(f"Single Gaussian peak / valley, mu_s = {sig(numbers['mu'])}")
    return fig


@styled
def random_gaussian_figure(scatter: dict, numbers: dict):
    """Fig. 5 B(III)/C(III): max kappa per run, ideal vs streamline (inf drawn at the top)."""
    fig = new_figure(figsize=(11, 4.6), layout="constrained")
    for i, (name, (ideal, stream)) in enumerate(scatter.items()):
        ax = fig.add_subplot(1, 2, i + 1)
        top = 30.0
        for j, (vals, label, color) in enumerate(
            (
                (ideal, "ideal", "0.5"),
                (stream, "streamline", SERIES_COLORS[0] if i == 0 else SERIES_COLORS[1]),
            )
        ):
            shown = np.where(np.isfinite(vals), np.minimum(vals, top), top)
            xj = j + 0.15 * np.random.default_rng(j).uniform(-1, 1, vals.size)
            ax.plot(xj, shown, "o", ms=3, color=color, label=label)
            med = np.median(vals)
            ax.hlines(min(med, top), j - 0.3, j + 0.3, color="k", label="median" if j == 0 else None)
        ax.set_xticks([0, 1], ["ideal", "streamline"])
        ax.set_ylabel("max kappa along the path [1] (self-lock drawn at 30)")
        ax.set_title(
            f"{name}: medians {sig(numbers[f'{name}_median_ideal'])} -> "
            f"{sig(numbers[f'{name}_median_streamline'])}"
        )
        ax.legend()
    return fig


@styled
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
            "share [%]",
            (
                ("rate", "self-lock rate"),
                ("sect_concave", "concave (sectional)"),
                ("sect_convex", "convex (sectional)"),
            ),
        ),
        (
            "Fig. 9C: Hessian method",
            "share of self-locks [%]",
            (("hess_concave", "concave"), ("hess_saddle", "saddle"), ("hess_convex", "convex")),
        ),
    )
    for col, (title, ylabel, curves) in enumerate(panels, start=1):
        ax = fig.add_subplot(1, 2, col)
        for key, label in curves:
            m, s = series(key)
            ax.errorbar(h, m, yerr=s, marker="o", capsize=3, label=label)
        ax.set(xlabel="Hurst index H [1]", ylabel=ylabel, title=f"{title} (mean +- sd)")
        ax.legend()
    return fig


@styled
def streamline_figure(surface, stream, ideal, *, title: str = ""):
    """3-D view of streamlines (solid) and ideal paths (dashed) over the surface, and kappa
    along each path."""
    grid = _display_grid(surface, 150)
    unit = _with_unit("", "" if surface.unit == "1" else surface.unit).strip()
    fig = new_figure(figsize=(12, 5), layout="constrained")
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    xx, yy = np.meshgrid(grid.x, grid.y)
    ax3.plot_surface(
        xx,
        yy,
        grid.heights,
        cmap=SEQUENTIAL_CMAP,
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
            label=f"({sig(stream.start_x[i])}, {sig(stream.start_y[i])})",
        )
        ax.plot(q["x"], np.minimum(q["kappa"], 20), color=c, ls="--", lw=0.8)
        if p["region"][-1] == 2:
            ax.plot(p["x"][-1], 20, "^", color=c)
    ax3.set_xlabel(f"x {unit}")
    ax3.set_ylabel(f"y {unit}")
    ax3.set_zlabel(f"z {unit}")
    ax.set_ylim(0, 21)
    ax.set_xlabel(f"x {unit}")
    ax.set_ylabel("kappa [1] (clipped at 20; triangle = self-lock)")
    ax.legend(title="start (x0, y0)")
    fig.suptitle(title or "Streamlines (solid) and ideal trajectories (dashed)")
    return fig


@styled
def roughness_figure(rough, *, title: str = ""):
    """Radially averaged PSD on log axes with the fitted Hurst slope, and the numbers."""
    fig = new_figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    unit = "" if rough.unit == "1" else f" {rough.unit}"
    ax.loglog(rough.q, rough.psd, "o-", ms=3, lw=1, color=SERIES_COLORS[0], label="radial PSD")
    if np.isfinite(rough.hurst):
        q = np.geomspace(*rough.fit_range, 20)
        fit = rough.psd_prefactor * q ** (-(2 * rough.hurst + 2))
        ax.loglog(
            q, fit, "--", color=SERIES_COLORS[1], lw=2, label=f"fit: C ~ q^-(2H+2), H = {sig(rough.hurst)}"
        )
    ax.set_xlabel(f"wavevector q = 2π/λ [rad{'' if rough.unit == '1' else ' / ' + rough.unit}]")
    ax.set_ylabel(f"PSD C(q) [{'surface units^4' if rough.unit == '1' else rough.unit + '^4'}]")
    ax.set_title(
        title
        or f"rms height {sig(rough.rms_height)}{unit}, rms slope {sig(rough.rms_slope)}, "
        f"L_c {sig(rough.char_length)}{unit}, l_s {sig(rough.slope_correlation_length)}{unit}",
        fontsize=9,
    )
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    return fig


# --------------------------------------------------------------------------- path overlays


@styled
def path_overlay_figure(panels: list[dict], *, length_label: str = "[surface units]"):
    """MuJoCo paths over the quasistatic streamline, one panel per case.

    Parameters
    ----------
    panels : list of dict
        Each with ``title``, ``paths`` (list of ``(streamline_xy, mujoco_xy)`` arrays of
        shape (n, 2)) and optionally ``surface`` (drawn as filled height contours on one
        diverging colour scale shared by all panels, 0 = white) and ``extent`` (x0, x1, y0, y1).
    length_label : str
        Unit of x and y in the axis labels.
    """
    n = len(panels)
    ncols = min(n, 2)
    nrows = -(-n // ncols)
    fig = new_figure(figsize=(5.4 * ncols + 0.8, 4.8 * nrows), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    norm, field = shared_height_norm(panels), None
    for ax, panel in zip(axes, panels):
        if panel.get("surface") is not None and norm is not None:
            x0, x1, y0, y1 = panel.get("extent") or panel["surface"].bounds
            xs, ys = np.linspace(x0, x1, 161), np.linspace(y0, y1, 161)
            h = panel["surface"].height(xs[None, :], ys[:, None])
            levels = np.linspace(norm.vmin, norm.vmax, 17)  # one set of levels: one colour bar for all
            field = ax.contourf(xs, ys, h, levels=levels, cmap=DIVERGING_CMAP, norm=norm)
        for i, (qs, mj) in enumerate(panel["paths"]):
            ax.plot(
                qs[:, 0],
                qs[:, 1],
                color=PATH_COLORS["streamline"],
                lw=1.6,
                label="streamline" if i == 0 else None,
            )
            if len(mj):
                ax.plot(
                    mj[:, 0],
                    mj[:, 1],
                    color=PATH_COLORS["mujoco"],
                    lw=1.0,
                    ls="--",
                    label="MuJoCo" if i == 0 else None,
                )
            ax.plot(qs[0, 0], qs[0, 1], "o", mfc="white", mec="k", ms=5, label="start" if i == 0 else None)
        ax.set(title=panel["title"], xlabel=f"x {length_label}", ylabel=f"y {length_label}")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(loc="upper left")
    for ax in axes[n:]:
        ax.set_visible(False)
    if field is not None:
        fig.colorbar(
            height_mappable(field),
            ax=list(axes[:n]),
            label=f"surface height {length_label} (peaks red, valleys blue)",
        )
    return fig


def height_mappable(field):
    """A colour bar source covering the whole shared scale of ``field`` (a contour set
    keeps only the levels its own data reach)."""
    return ScalarMappable(norm=field.norm, cmap=DIVERGING_CMAP)


def shared_height_norm(panels: list[dict]):
    """One colour scale, symmetric about 0, for the surfaces of all panels (None if none)."""
    top = 0.0
    for panel in panels:
        if panel.get("surface") is not None:
            x0, x1, y0, y1 = panel.get("extent") or panel["surface"].bounds
            xs, ys = np.linspace(x0, x1, 81), np.linspace(y0, y1, 81)
            top = max(top, float(np.abs(panel["surface"].height(xs[None, :], ys[:, None])).max()))
    return mcolors.TwoSlopeNorm(0.0, -top, top) if top > 0 else None


@styled
def array_figure(res, arr):
    """An array run (:class:`~spine_mj.sim.ArrayResult` of ``arr``, an
    :class:`~spine_mj.sim.ArrayRig`): the layout on the surface's height map with each
    spine's path (self-locked spines marked), beside the array's force-displacement curve."""
    rig = arr.rig
    s = rig.length_scale_m
    fig = new_figure(figsize=(12, 4.6), layout="constrained")
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.4, 1]})
    grid = _display_grid(rig.surface, 300)
    units = _axes_units(rig.surface, grid)
    lf = units[0]
    _height_map(fig, ax, grid, units)
    for i in range(res.n_spines):
        p = res.position_m[:, i] / s * lf
        ax.plot(p[:, 0], p[:, 1], lw=0.9, color="white")
    x0, y0 = res.start_xy.T * lf
    ax.scatter(x0, y0, s=12, color="black", zorder=3, label="start")
    end = res.position_m[-1] / s * lf
    if res.locked.any():
        xe, ye = end[res.locked, 0], end[res.locked, 1]
        ax.scatter(xe, ye, s=40, marker="x", color="red", zorder=4, label="self-locked (where it ended)")
    seen = np.concatenate([res.start_xy * lf, res.position_m[:, :, :2].reshape(-1, 2) / s * lf])
    lo, hi = np.nanmin(seen, axis=0), np.nanmax(seen, axis=0)
    pad = 0.15 * max(hi - lo) + 1e-12
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.legend(loc="upper right", fontsize=7)
    lay = arr.layout
    ax.set_title(
        f"{lay.kind.value} {lay.rows} x {lay.cols}, spacing {lay.spacing:g} {lay.spacing_unit.value}"
    )
    fp = rig.scales.preload_n
    ax2.plot(res.carriage_x_m / rig.scales.char_length_m, res.total_force_n / (res.n_spines * fp), lw=1)
    ax2.axhline(res.holding_ratio, color="gray", lw=0.8, ls="--")
    ax2.set_xlabel("carriage displacement [L_c]")
    ax2.set_ylabel("array force / (N F_p)")
    ax2.set_title(f"holding ratio {sig(res.holding_ratio)}, {res.locked_spines} locked ({res.end_reason})")
    return fig
