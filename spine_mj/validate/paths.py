"""Paths of the validation: streamlines on the surface the MuJoCo tip traces, path metrics,
and the MuJoCo paths a sweep stored.

The quasistatic streamline runs on the surface dilated by the rig's tip radius
(:func:`tip_radius`), on the smooth surface or on MuJoCo's triangulated hfield
(:func:`triangulated_surface`), which separates the geometry error of the facets from the
dynamics error. Deviations are resampled Frechet distances in units of ``L_c``
(:func:`spine_mj.theory.agreement.path_frechet`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spine_mj import presets, sweep
from spine_mj.errors import SpineInputError
from spine_mj.sim.rig_hfield import grid_keeps_samples
from spine_mj.sim.scales import resolve_tip_radius
from spine_mj.surfaces import TriangulatedSurface, from_hfield, to_hfield
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import agreement
from spine_mj.theory import streamline as sl
from spine_mj.theory.streamline_types import StreamlineParams, StreamlineResult

__all__ = [
    "mujoco_traces",
    "path_metrics",
    "prefix_frechet",
    "stored_paths",
    "streamline_paths",
    "tip_radius",
    "triangulated_surface",
]


def tip_radius(preset: str, seeds, resolution: int) -> float:
    """The rig's default tip radius in surface units (:func:`spine_mj.sim.scales.resolve_tip_radius`),
    so that the quasistatic streamline runs on the surface traced by the same sphere. A grid
    keeps its own samples; ``resolution`` applies to analytic surfaces.

    Parameters
    ----------
    preset : str
        The surface's preset, or a surface file (``example:NAME``: :func:`spine_mj.presets.open_surface`).
    seeds : sequence of int or None
        Its seeds: the first one's surface is measured (None: the preset's seed).
    resolution : int
        Samples a side of an analytic surface's hfield.
    """
    surface = presets.open_surface(preset, **({} if seeds is None else {"seed": seeds[0]}))
    return float(f"{resolve_tip_radius(surface, None, hfield_resolution=resolution):.3g}")


def streamline_paths(surface, starts, mu: float, dl: float, tip: float) -> StreamlineResult:
    """Streamlines (with paths) from ``starts`` on ``surface`` dilated by ``tip``
    (:func:`spine_mj.surfaces.dilation.dilate`: MuJoCo's facets are sampled at ``tip / 8``, finer
    than the hfield, before the dilation).

    Parameters
    ----------
    surface : Surface
        Any surface.
    starts : array_like, shape (n, 2)
        Start points in surface units.
    mu : float
        Static friction coefficient mu_s.
    dl : float
        Streamline step (surface units).
    tip : float
        Tip radius (surface units); 0 traces the surface itself.
    """
    traced = dilate(surface, tip) if tip > 0 else surface
    params = StreamlineParams(mu=mu, dl=dl)
    return sl.streamlines(traced, np.asarray(starts, float), params, store_paths=True)


def triangulated_surface(surface, resolution: int | None) -> TriangulatedSurface:
    """MuJoCo's hfield of ``surface`` as facets (a grid keeps its samples; else
    ``resolution`` per side, or the default when None).

    Parameters
    ----------
    surface : Surface
        Any surface.
    resolution : int or None
        Samples a side of an analytic surface's hfield.
    """
    resolution = grid_keeps_samples(surface, resolution)
    hf = to_hfield(surface) if not resolution else to_hfield(surface, nrow=resolution, ncol=resolution)
    return TriangulatedSurface.from_grid(from_hfield(hf, unit=surface.unit))


def path_metrics(mpath: np.ndarray, qpath: np.ndarray, lc: float) -> tuple[float, float]:
    """Frechet and mean lateral deviation of ``mpath`` from ``qpath`` over ``lc`` (NaN, NaN
    when either has fewer than two points).

    Parameters
    ----------
    mpath, qpath : ndarray, shape (n, 2), (m, 2)
        The MuJoCo path and the streamline (x, y in surface units).
    lc : float
        ``L_c`` in surface units; the results are in units of it.
    """
    if mpath.shape[0] < 2 or qpath.shape[0] < 2:
        return float("nan"), float("nan")
    fr = agreement.path_frechet(mpath, qpath, length_scale=lc)
    return fr, float(agreement.mean_lateral_deviation(mpath, qpath, length_scale=lc))


def prefix_frechet(mpath: np.ndarray, qpath: np.ndarray, lc: float) -> float:
    """Frechet deviation of a MuJoCo path from the streamline cut at the same arc length.

    Parameters
    ----------
    mpath, qpath : ndarray, shape (n, 2), (m, 2)
        The MuJoCo path and the streamline (x, y in surface units).
    lc : float
        ``L_c`` in surface units; the result is in units of it.
    """
    if mpath.shape[0] < 2 or qpath.shape[0] < 2:
        return float("nan")
    arc_m = float(np.linalg.norm(np.diff(mpath, axis=0), axis=1).sum())
    seg = np.linalg.norm(np.diff(qpath, axis=0), axis=1)
    cum = np.r_[0.0, np.cumsum(seg)]
    k = int(np.searchsorted(cum, arc_m))
    if k >= cum.size:
        q = qpath
    else:
        t = (arc_m - cum[k - 1]) / seg[k - 1] if k > 0 and seg[k - 1] > 0 else 0.0
        end = qpath[k - 1] + t * (qpath[k] - qpath[k - 1]) if k > 0 else qpath[0]
        q = np.vstack([qpath[:k], end[None, :]])
    if q.shape[0] < 2:
        q = np.vstack([qpath[0], qpath[0]])
    spacing = max(min(lc / 50, arc_m / 20), 1e-9 * lc)
    return agreement.path_frechet(mpath, q, length_scale=lc, spacing=spacing)


def mujoco_traces(store: Path, case_id: str) -> dict:
    """MuJoCo trajectories of a stored case: start -> DataFrame (``x``, ``y``,
    ``drive_force_n``, ``time_s``, ``motion``) sorted by step; empty without any."""
    try:
        tr = sweep.load_trajectories(
            store, case_id, analysis="engine", columns=["x", "y", "drive_force_n", "time_s", "motion"]
        )
    except SpineInputError:
        return {}
    return {int(s): g.sort_values("step") for s, g in tr.groupby("start")}


def stored_paths(store: Path, case_id: str, analysis: str) -> dict[int, np.ndarray]:
    """Paths of ``analysis`` for a stored case: start -> ``(n, 2)`` x, y; empty without any."""
    try:
        tr = sweep.load_trajectories(store, case_id, analysis=analysis, columns=["x", "y"])
    except SpineInputError:
        return {}
    return {int(s): g.sort_values("step")[["x", "y"]].to_numpy() for s, g in tr.groupby("start")}
