"""Figs. 2B, 3-4: the single peak and valley (kappa map, self-lock start ranges, the
calibration of mu_s)."""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    kappa_map_figure,
    save_figure,
    single_peak_figure,
)
from spine_mj.reproduce._common import FIVE_Y0, Progress, _finite_or_str, _outcome_name, _settings
from spine_mj.surfaces import single_gaussian
from spine_mj.theory.engagement import REGION_NAMES, kappa_grid
from spine_mj.theory.streamline import ideal_trajectories, streamlines
from spine_mj.theory.streamline_types import StreamlineParams

# --------------------------------------------------------------------------- Figs. 3-4


def _five_starts(surf, x0: float, params: StreamlineParams):
    five = [(x0, y) for y in FIVE_Y0]
    return surf, streamlines(surf, five, params), ideal_trajectories(surf, five, params)


def _five_start_table(s5, i5) -> list[dict]:
    return [
        {
            "y0": y,
            "streamline": _outcome_name(s5.outcome[i]),
            "ideal": _outcome_name(i5.outcome[i]),
            "streamline_max_kappa": _finite_or_str(s5.max_kappa[i]),
            "ideal_max_kappa": _finite_or_str(i5.max_kappa[i]),
        }
        for i, y in enumerate(FIVE_Y0)
    ]


def _ratio_error(numbers: dict) -> float:
    """The calibration criterion: the larger relative error of the two primary ratios
    against the paper's (inf when a ratio is undefined)."""
    errors = []
    for key, paper in PAPER_RATIOS.items():
        value = numbers.get(key)
        errors.append(abs(value / paper - 1) if value is not None else math.inf)
    return max(errors)


def calibrate_single_peak_mu(mus=None, *, progress: Progress = None) -> dict:
    """Choose mu_s for the single peak/valley by a stated criterion on the fine scan.

    Criterion: the mu_s (on a 0.005 grid over 1.12-1.40 unless ``mus`` is given) that
    minimizes :func:`_ratio_error`, the larger relative error of the fine-scan convex and
    concave ratios against the paper's 0.833 and 5.667. Also reports whether the concave
    start y0 = -3 self-locks at any mu_s (the paper's figure says it does).

    Returns
    -------
    dict
        ``rows`` (mu, both ratios, the error, the y0 = -3 outcome), ``best_mu``,
        ``best_error``, ``y0_minus_3_locks_anywhere``.
    """
    mus = np.round(np.arange(1.12, 1.4001, 0.005), 3) if mus is None else np.asarray(mus, float)
    rows = []
    for i, mu in enumerate(mus):
        numbers, fig = single_peak(mu=float(mu))
        fig.clf()
        at3 = next(s for s in numbers["concave_starts"] if s["y0"] == -3.0)["streamline"]
        rows.append(
            {
                "mu": float(mu),
                "convex_ratio": numbers["convex_ratio"],
                "concave_ratio": numbers["concave_ratio"],
                "ratio_error": numbers["ratio_error"],
                "concave_y0_minus_3": at3,
            }
        )
        if progress:
            progress(i + 1, len(mus))
    best = min(rows, key=lambda r: r["ratio_error"])
    return {
        "rows": rows,
        "best_mu": best["mu"],
        "best_error": best["ratio_error"],
        "y0_minus_3_locks_anywhere": any(r["concave_y0_minus_3"] == "self_locked" for r in rows),
    }


#: The paper's self-lock start-range ratios (Figs. 3-4): 5/6 and 34/6.
PAPER_RATIOS = {"convex_ratio": 0.833, "concave_ratio": 5.667}
#: Step of the primary start scan in y0 (the quick run's is 0.05).
FINE_Y0_STEP = 0.01


def single_peak(
    *,
    quick: bool = False,
    progress: Progress = None,
    mu: float | None = None,
    dl: float | None = None,
    y0_step: float | None = None,
    y0_range: tuple[float, float] | None = None,
):
    """Figs. 3-4: five starts on the convex peak and the concave valley, and the self-lock
    start-range ratios (streamline range / ideal range of y0 at x0 = -3).

    The primary ratios (``convex_ratio``, ``concave_ratio``) come from a fine scan of
    starts, y0 every :data:`FINE_Y0_STEP` over -5..5 (cell midpoints): range = number of
    self-locked starts times the step. The paper's 83.3 % and 566.7 % are 5/6 and 34/6,
    ratios of small counts that a coarse count produces; that reading is kept as a
    secondary measurement, ``*_coarse``, on the preset's scan ``y0 = y0_range[0], ... +
    y0_step, ..., y0_range[1]`` (end points included; skipped in a quick run).

    Returns numbers with keys ``mu``, ``convex_ratio``, ``concave_ratio`` (fractions;
    paper 0.833 and 5.667), the ranges, their ``*_coarse`` counterparts, and per-start
    outcomes and max kappa.
    """
    mu, rep, _ = _settings("paper-single-peak", mu)
    dl = float(dl if dl is not None else rep.get("dl", 0.015))
    y0_step = float(y0_step if y0_step is not None else rep.get("y0_step", 0.1))
    lo, hi = (float(v) for v in (y0_range if y0_range is not None else rep.get("y0_range", (-5.0, 0.0))))
    if not (y0_step > 0 and hi > lo):
        raise SpineInputError(f"y0_step must be > 0 and y0_range increasing, got {y0_step}, ({lo}, {hi})")
    x0 = float(rep.get("x0", -3.0))
    params = StreamlineParams(mu=mu, dl=dl)
    fine_step = 0.05 if quick else FINE_Y0_STEP
    y_fine = np.arange(-5 + fine_step / 2, 5.0, fine_step)
    scans = {"": (np.c_[np.full(y_fine.size, x0), y_fine], fine_step)}
    if not quick:
        y_coarse = np.linspace(lo, hi, int(round((hi - lo) / y0_step)) + 1)
        scans["_coarse"] = (np.c_[np.full(y_coarse.size, x0), y_coarse], y0_step)
    numbers = {
        "mu": mu,
        "dl": dl,
        "x0": x0,
        "y0_step": fine_step,
        "y0_step_coarse": y0_step,
        "y0_range_coarse": [lo, hi],
        "paper": dict(PAPER_RATIOS),
    }
    runs = {}
    for k, (name, sign) in enumerate((("convex", 1), ("concave", -1))):
        surf = single_gaussian(sign=sign)
        for label, (pts, step) in scans.items():
            n_ideal = int(ideal_trajectories(surf, pts, params, store_paths=False).self_locked.sum())
            n_stream = int(streamlines(surf, pts, params, store_paths=False).self_locked.sum())
            numbers[f"{name}_ideal_range{label}"] = n_ideal * step
            numbers[f"{name}_streamline_range{label}"] = n_stream * step
            numbers[f"{name}_ratio{label}"] = n_stream / n_ideal if n_ideal > 0 else None
        runs[name] = _five_starts(surf, x0, params)
        numbers[f"{name}_starts"] = _five_start_table(*runs[name][1:])
        if progress:
            progress(k + 1, 2)
    numbers["ratio_error"] = _ratio_error(numbers)
    return numbers, single_peak_figure(runs, numbers)


# --------------------------------------------------------------------------- Fig. 2B


def kappa_map(
    *, quick: bool = False, progress: Progress = None, mu: float | None = None, n: int | None = None
):
    """Fig. 2B: kappa over the single convex peak and concave valley (slip blank, self-lock
    marked). Numbers: area fractions of the regions and the kappa range."""
    mu, _, _ = _settings("paper-single-peak", mu)
    n = int(n if n is not None else (101 if quick else 301))
    numbers = {"mu": mu, "n": n}
    surfs = {"convex": single_gaussian(sign=1), "concave": single_gaussian(sign=-1)}
    maps, fractions = _kappa_maps(surfs, mu, n)
    for name, shares in fractions.items():
        numbers.update({f"{name}_{label}_fraction": share for label, share in shares.items()})
    if progress:
        progress(1, 1)

    return numbers, kappa_map_figure(maps, mu)


def kappa_map_to(path, surface, *, mu: float, resolution: int) -> dict[str, float]:
    """Draw the kappa map of ``surface`` (Fig. 2B's panel: slip blank, self-lock dark red)
    on a ``resolution`` x ``resolution`` grid and save it as the PNG ``path``
    (``spine-mj kappa``).

    Returns
    -------
    dict
        The share of the grid in each region, by name (:data:`REGION_NAMES` order).
    """
    name = surface.metadata.get("preset", "surface")
    maps, fractions = _kappa_maps({name: surface}, mu, resolution)
    save_figure(kappa_map_figure(maps, mu), path)
    return fractions[name]


def _kappa_maps(surfs: dict, mu: float, n: int) -> tuple[dict, dict]:
    """:func:`kappa_grid` of each named surface: the figure's maps ``(xs, heights, kappa,
    region)`` and each map's region shares ``{label: fraction}``."""
    maps, fractions = {}, {}
    for name, surf in surfs.items():
        xs, _, heights, k, region = kappa_grid(surf, mu, n)
        maps[name] = (xs, heights, k, region)
        fractions[name] = {label: float(np.mean(region == code)) for code, label in REGION_NAMES.items()}
    return maps, fractions
