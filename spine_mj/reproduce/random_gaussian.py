"""Fig. 5: random Gaussian surfaces, convex against concave."""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    random_gaussian_figure,
)
from spine_mj.reproduce._common import Progress, _finite_or_str, _settings
from spine_mj.surfaces import GaussianSurface, random_gaussians
from spine_mj.theory.engagement import ENGAGED, SLIP, kappa
from spine_mj.theory.streamline import ideal_trajectories, streamlines
from spine_mj.theory.streamline_types import StreamlineParams

# --------------------------------------------------------------------------- Fig. 5


def _random_surface(gen: dict, seed: int):
    """One random Gaussian surface from the preset's generator table ``gen``.

    Besides :func:`~spine_mj.surfaces.random_gaussians`' own parameters, ``k_range``
    (when set) applies the single peak's normalization of Figs. 3-4 to every peak: the
    amplitude is ``k / (2 pi sigma_x sigma_y)`` with ``k`` uniform on ``k_range`` (equal
    ends: one fixed ``k``), replacing ``amplitude_range``. Centres and widths are drawn as
    without it, so one seed gives the same layout either way.
    """
    gen = dict(gen)
    k_range = gen.pop("k_range", None)
    surf = random_gaussians(**gen, rng=seed)
    if k_range is None:
        return surf
    k_lo, k_hi = (float(v) for v in k_range)
    if not (0 <= k_lo <= k_hi and k_hi > 0):
        raise SpineInputError(f"k_range must satisfy 0 <= lo <= hi, hi > 0, got {k_range!r}")
    k = np.random.default_rng([seed, 7]).uniform(k_lo, k_hi, surf.amplitude.size)
    amp = np.sign(surf.amplitude) * k / (2 * np.pi * surf.sigma_x * surf.sigma_y)
    return GaussianSurface(
        amplitude=amp,
        center_x=surf.center_x,
        center_y=surf.center_y,
        sigma_x=surf.sigma_x,
        sigma_y=surf.sigma_y,
        bounds=surf.bounds,
        unit=surf.unit,
        metadata=dict(surf.metadata, k_range=[k_lo, k_hi]),
    )


def _max_kappa(res, convention: str) -> np.ndarray:
    """Max kappa per trajectory under ``convention``: ``"inf"`` (self-locked = inf, the
    kernel's value) or ``"finite"`` (largest kappa over the engaged points only: the
    self-lock step is excluded, so a self-locked path scores the last engaged kappa before
    the self-lock boundary). NaN (slip points only) is returned as NaN in both."""
    if convention == "inf":
        return res.max_kappa
    vals = np.where(res.region == ENGAGED, res.kappa, -np.inf)
    out = np.maximum.reduceat(vals, res.offsets[:-1])
    return np.where(np.isneginf(out), np.nan, out)


def random_gaussian(
    *,
    quick: bool = False,
    progress: Progress = None,
    mu: float | None = None,
    n_runs: int | None = None,
    starts: str | None = None,
    kappa_cap: float | None = None,
    max_kappa: str | None = None,
    dl: float | None = None,
    x0_offset: float | None = None,
    seed: int | None = None,
    **params,
):
    """Fig. 5: medians of the maximum kappa along ideal and streamline trajectories on
    random convex and concave Gaussian surfaces.

    ``starts`` (preset ``[reproduce] starts``): ``"surfaces"`` runs one surface per run
    (seeds ``seed, seed + 1, ...``) with one start ``x0_offset`` inside the left edge on
    ``y = y0``; ``"edge"`` runs ``n_runs`` starts spread evenly along the left edge of one
    surface. Conventions for the medians (``max_kappa``, preset ``[reproduce] max_kappa``):
    ``"inf"``, a self-locked trajectory has max kappa = inf (ranked highest, so the median is
    finite while fewer than half self-lock) or ``kappa_cap`` when one is set; ``"finite"``,
    the self-lock step is excluded and the max is taken over the engaged points (it then
    depends on ``dl``, since kappa diverges at the self-lock boundary). A trajectory that met
    only slip points counts as 0. The self-lock counts and the number of starts in the slip
    region are reported beside the medians. Extra keyword arguments replace the presets'
    generator parameters (both surfaces); ``k_range`` there selects the single-peak
    normalization (:func:`_random_surface`). ``seed`` replaces the presets' first seed.
    """
    numbers = {
        "paper": {
            "convex_median_ideal": 3.18,
            "convex_median_streamline": 2.87,
            "concave_median_ideal": 3.22,
            "concave_median_streamline": 11.34,
            "bypass_change": -0.097,
            "trap_change": 2.522,
        }
    }
    scatter = {}
    options = dict(
        mu=mu,
        n_runs=n_runs,
        starts=starts,
        kappa_cap=kappa_cap,
        max_kappa=max_kappa,
        dl=dl,
        x0_offset=x0_offset,
        seed=seed,
        quick=quick,
    )
    for k, (name, preset) in enumerate(
        (("convex", "paper-random-convex"), ("concave", "paper-random-concave"))
    ):
        family, scatter[name] = _random_family(preset, params, **options)
        numbers.update({f"{name}_{key}": value for key, value in family.items()})
        if progress:
            progress(k + 1, 2)
    for key, name in (("bypass_change", "convex"), ("trap_change", "concave")):
        mi, ms = numbers[f"{name}_median_ideal"], numbers[f"{name}_median_streamline"]
        numbers[key] = (ms - mi) / mi if math.isfinite(ms) and math.isfinite(mi) and mi > 0 else None
        for k in (f"{name}_median_ideal", f"{name}_median_streamline"):
            numbers[k] = _finite_or_str(numbers[k])

    return numbers, random_gaussian_figure(scatter, numbers)


def _random_family(
    preset: str, params: dict, *, mu, n_runs, starts, kappa_cap, max_kappa, dl, x0_offset, seed, quick
) -> tuple[dict, tuple[np.ndarray, np.ndarray]]:
    """One family of :func:`random_gaussian`: its numbers (keys without the family
    prefix) and the (ideal, streamline) max-kappa scatter."""
    m, rep, pre = _settings(preset, mu)
    runs = int(n_runs if n_runs is not None else rep.get("n_runs", 100))
    mode = str(starts if starts is not None else rep.get("starts", "surfaces"))
    cap = kappa_cap if kappa_cap is not None else rep.get("kappa_cap")
    conv = str(max_kappa if max_kappa is not None else rep.get("max_kappa", "inf"))
    off = float(x0_offset if x0_offset is not None else rep.get("x0_offset", 1e-9))
    if mode not in ("surfaces", "edge"):
        raise SpineInputError(f"starts must be 'surfaces' or 'edge', got {mode!r}")
    if conv not in ("inf", "finite"):
        raise SpineInputError(f"max_kappa must be 'inf' or 'finite', got {conv!r}")
    if quick:
        runs = min(runs, 30)
    step = float(dl if dl is not None else rep.get("dl", 0.015))
    gen = dict(pre.params, **params)
    if "k_range" in rep and "k_range" not in params:
        gen["k_range"] = rep["k_range"]
    if gen.get("k_range") is None:
        gen.pop("k_range", None)
    seed0 = int(seed if seed is not None else (pre.seed or 0))
    params_s = StreamlineParams(mu=m, dl=step)
    seeds = range(seed0, seed0 + runs) if mode == "surfaces" else [seed0]
    store = conv == "finite"
    ideal_max, stream_max, ideal_lock, stream_lock, slip_start = [], [], [], [], 0
    for s in seeds:
        surf = _random_surface(gen, s)
        xmin, _, ymin, ymax = surf.bounds
        if mode == "surfaces":
            pts = np.array([(xmin + off, float(rep.get("y0", 0.0)))])
        else:
            ys = ymin + (ymax - ymin) * (np.arange(runs) + 0.5) / runs
            pts = np.c_[np.full(runs, xmin + off), ys]
        _, fx0, fy0 = surf.evaluate(pts[:, 0], pts[:, 1], order=1)
        slip_start += int((kappa(fx0, fy0, m)[1] == SLIP).sum())
        ri = ideal_trajectories(surf, pts, params_s, store_paths=store)
        rs = streamlines(surf, pts, params_s, store_paths=store)
        ideal_max.append(_max_kappa(ri, conv))
        stream_max.append(_max_kappa(rs, conv))
        ideal_lock.append(ri.self_locked)
        stream_lock.append(rs.self_locked)
    ideal_max, stream_max = np.concatenate(ideal_max), np.concatenate(stream_max)
    ranked = []
    for v in (ideal_max, stream_max):
        v = np.where(np.isnan(v), 0.0, v)
        ranked.append(np.minimum(v, float(cap)) if cap is not None else v)
    family = {
        "mu": m,
        "runs": runs,
        "starts": mode,
        "dl": step,
        "x0_offset": off,
        "max_kappa": conv,
        "kappa_cap": cap,
        "median_ideal": float(np.median(ranked[0])),
        "median_streamline": float(np.median(ranked[1])),
        "self_locked_ideal": int(np.concatenate(ideal_lock).sum()),
        "self_locked_streamline": int(np.concatenate(stream_lock).sum()),
        "starts_in_slip": slip_start,
    }
    return family, (ideal_max, stream_max)
