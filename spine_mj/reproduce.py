"""Reproductions of the paper's figures: numbers (a JSON-ready dict) plus a figure.

``REPRODUCTIONS`` maps a name to a function ``f(*, quick=False, progress=None, **over)``
returning ``(numbers, figure)``. Parameters the paper leaves open (mu_s, random-field
widths and heights, fractal size and normalization) come from the ``[engagement]`` and
``[reproduce]`` tables of the ``paper-*`` presets (calibrated in
``analysis/calibration.py``); keyword overrides replace them. ``progress(done, total)`` is
called as work completes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    fractal_hurst_figure,
    kappa_map_figure,
    random_gaussian_figure,
    single_peak_figure,
)
from spine_mj.presets import load_preset, resolve_mu
from spine_mj.surfaces import GaussianSurface, fractal_fbm, random_gaussians, single_gaussian
from spine_mj.theory.convexity import CONCAVE, CONVEX, SADDLE, hessian_class, sectional_class
from spine_mj.theory.engagement import ENGAGED, REGION_NAMES, SLIP, kappa, kappa_grid
from spine_mj.theory.streamline import Outcome, StreamlineParams, ideal_trajectories, streamlines
from spine_mj.workers import check_workers

__all__ = [
    "REPRODUCTIONS",
    "fig9_rms_height",
    "fig9_seeds",
    "fractal_hurst",
    "kappa_map",
    "random_gaussian",
    "raw_rms_height",
    "run",
    "single_peak",
]

Progress = Callable[[int, int], None] | None
FIVE_Y0 = (-0.5, -1.0, -2.0, -3.0, -4.0)


def _settings(preset: str, mu: float | None) -> tuple[float, dict, object]:
    """mu_s (``mu``, else the preset's calibrated one: :func:`~spine_mj.presets.resolve_mu`),
    the preset's ``[reproduce]`` table and the preset itself."""
    p = load_preset(preset)
    return resolve_mu(p, mu), dict(p.extras.get("reproduce", {})), p


def _outcome_name(code: int) -> str:
    return Outcome(int(code)).name.lower()


def _finite_or_str(v: float):
    return float(v) if math.isfinite(v) else ("inf" if v > 0 else "nan")


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
    maps = {}
    for name, sign in (("convex", 1), ("concave", -1)):
        xs, _, heights, k, region = kappa_grid(single_gaussian(sign=sign), mu, n)
        maps[name] = (xs, heights, k, region)
        for code, label in REGION_NAMES.items():
            numbers[f"{name}_{label}_fraction"] = float(np.mean(region == code))
    if progress:
        progress(1, 1)

    return numbers, kappa_map_figure(maps, mu)


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


# --------------------------------------------------------------------------- Figs. 7E, 9


def raw_rms_height(hurst: float, nx: int, size: float) -> float:
    """Expected RMS height of the paper's unnormalized synthesis: white noise filtered by
    ``A(f) = |f|^-(H+1)`` (f in cycles per unit length) on an ``nx x nx`` periodic grid of
    side ``size``: ``sqrt(mean_k A(f_k)^2)`` (the DC term excluded). ``size = nx`` gives
    frequencies in cycles per pixel (all ``|f| <= 0.5`` per axis)."""
    f = np.fft.fftfreq(nx, size / nx)
    freq = np.hypot(f[None, :], f[:, None])
    amp2 = np.zeros_like(freq)
    amp2[freq > 0] = freq[freq > 0] ** (-2.0 * (hurst + 1.0))
    return float(math.sqrt(amp2.mean()))


def fig9_rms_height(hurst: float, nx: int, size: float, frequency_unit: str, scale: float) -> float:
    """RMS height of a Fig. 9 surface at ``hurst``: ``scale`` times :func:`raw_rms_height`
    with frequencies in cycles per pixel (``frequency_unit = "pixel"``) or per unit length
    (``"length"``). One rule, shared by :func:`fractal_hurst` and the validation's
    fractal study, so both draw the same surfaces."""
    spectral_size = nx if frequency_unit == "pixel" else size
    return scale * raw_rms_height(hurst, nx, spectral_size)


def fig9_seeds(hurst_index: int, n: int) -> np.ndarray:
    """Seeds of the ``n`` surfaces at the ``hurst_index``-th H of a Fig. 9 run (distinct
    per surface and per H)."""
    return 1_000_000 * (hurst_index + 1) + np.arange(n)


def _fractal_chunk(args):
    hurst, seeds, gen, mu, dl, scale, lock_point, trajectory = args
    params = StreamlineParams(mu=mu, dl=dl)
    rms = fig9_rms_height(hurst, gen["nx"], gen["size"], gen["frequency_unit"], scale)
    trace = ideal_trajectories if trajectory == "ideal" else streamlines
    before = lock_point == "before"
    locked, sect, hess = [], [], []
    for seed in seeds:
        surf = fractal_fbm(
            nx=gen["nx"], size=gen["size"], hurst=hurst, rms_height=rms, periodic=True, rng=int(seed)
        )
        xmin, _, ymin, ymax = surf.bounds
        r = trace(surf, [(xmin, 0.5 * (ymin + ymax))], params, store_paths=before)
        ok = bool(r.self_locked[0])
        locked.append(ok)
        if ok:
            px, py = r.end_x, r.end_y
            if before and r.n_steps[0] > 0:
                j = r.offsets[1] - 2
                px, py = r.x[j : j + 1], r.y[j : j + 1]
            _, fx, fy, fxx, fxy, fyy = surf.evaluate(px, py, order=2)
            sect.append(int(sectional_class(fx, fy, fxx, fxy, fyy)[0]))
            hess.append(int(hessian_class(fxx, fxy, fyy)[0]))
        else:
            sect.append(-1)
            hess.append(-1)
    return hurst, np.array(locked), np.array(sect), np.array(hess)


#: Most fractal surfaces per H value of :func:`fractal_hurst` (the default is 300; this is
#: about an hour's work on two workers).
MAX_SURFACES_PER_HURST = 20_000


def fractal_hurst(
    *,
    quick: bool = False,
    progress: Progress = None,
    mu: float | None = None,
    surfaces: int | None = None,
    workers: int = 2,
    hursts=None,
    **over,
):
    """Figs. 7E and 9: self-lock rate and concave / convex (sectional, Eq. 6) and concave /
    saddle / convex (Hessian, Eqs. 8-10) shares of self-lock points against H.

    For each H, ``surfaces`` fractal surfaces (default 300, 30 when ``quick``; in 3 groups)
    get one streamline each from the middle of the left edge; shares are among self-locked
    streamlines of a group; mean and sd over the groups. The height scale follows the
    paper's unnormalized synthesis (:func:`raw_rms_height`) times ``scale`` from the
    preset: a fixed spectral prefactor, so roughness grows with H when frequencies are in
    cycles per pixel (``frequency_unit = "pixel"``) and barely changes with ``"length"``.

    ``lock_point`` (preset ``[reproduce] lock_point``): ``"lock"`` classifies the first
    self-lock point the trajectory reaches, ``"before"`` the engaged point one step
    earlier. ``trajectory``: ``"streamline"`` (the paper's Fig. 9) or ``"ideal"`` (the
    same statistics for ideal trajectories, for comparison).
    """
    mu, rep, pre = _settings("paper-fractal", mu)
    hursts = list(
        hursts if hursts is not None else rep.get("hursts", [0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95])
    )
    default = int(rep.get("surfaces", 300))
    n = int(surfaces) if surfaces is not None else (min(default, 30) if quick else default)
    groups = int(rep.get("groups", 3))
    if n < groups:
        raise SpineInputError(f"surfaces must be >= groups ({groups}), got {n}")
    if n > MAX_SURFACES_PER_HURST:
        raise SpineInputError(
            f"--surfaces: at most {MAX_SURFACES_PER_HURST} per H ({len(hursts)} H values; the "
            f"default {default} takes about a minute on 2 workers), got {n}"
        )
    check_workers(workers)
    gen = {
        "nx": int(over.get("nx", rep.get("nx", pre.params["nx"]))),
        "size": float(over.get("size", pre.params["size"])),
        "frequency_unit": str(over.get("frequency_unit", rep.get("frequency_unit", "length"))),
    }
    if gen["frequency_unit"] not in ("pixel", "length"):
        raise SpineInputError(f"frequency_unit must be 'pixel' or 'length', got {gen['frequency_unit']!r}")
    scale = float(over.get("scale", rep["scale"]))
    dl = float(over.get("dl", rep.get("dl", 0.02)))
    lock_point = str(over.get("lock_point", rep.get("lock_point", "lock")))
    trajectory = str(over.get("trajectory", rep.get("trajectory", "streamline")))
    if lock_point not in ("lock", "before") or trajectory not in ("streamline", "ideal"):
        raise SpineInputError(
            f"lock_point must be 'lock' or 'before' and trajectory "
            f"'streamline' or 'ideal', got {lock_point!r}, {trajectory!r}"
        )
    chunks = []
    for h_i, h in enumerate(hursts):
        seeds = fig9_seeds(h_i, n)
        for part in np.array_split(seeds, max(1, workers * 2)):
            chunks.append((h, part, gen, mu, dl, scale, lock_point, trajectory))
    results: dict[float, list] = {h: [] for h in hursts}
    for res in _run_chunks(chunks, workers, progress):
        results[res[0]].append(res[1:])
    table = [_hurst_row(h, results[h], n, groups) for h in hursts]
    numbers = {
        "mu": mu,
        "nx": gen["nx"],
        "size": gen["size"],
        "scale": scale,
        "dl": dl,
        "frequency_unit": gen["frequency_unit"],
        "lock_point": lock_point,
        "trajectory": trajectory,
        "groups": groups,
        "surfaces_per_hurst": n,
        "by_hurst": table,
    }

    return numbers, fractal_hurst_figure(table)


def _run_chunks(chunks: list, workers: int, progress: Progress):
    """:func:`_fractal_chunk` over ``chunks``, on ``workers`` processes when > 1."""
    if workers > 1:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            for done, res in enumerate(pool.map(_fractal_chunk, chunks)):
                yield res
                if progress:
                    progress(done + 1, len(chunks))
    else:
        for done, c in enumerate(chunks):
            yield _fractal_chunk(c)
            if progress:
                progress(done + 1, len(chunks))


def _hurst_row(hurst: float, parts: list, n: int, groups: int) -> dict:
    """Self-lock rate and convexity shares at one H: mean and sd over ``groups`` groups."""
    locked = np.concatenate([r[0] for r in parts])
    sect = np.concatenate([r[1] for r in parts])
    hess = np.concatenate([r[2] for r in parts])
    classes = {
        "sect_concave": (sect, CONCAVE),
        "sect_convex": (sect, CONVEX),
        "hess_concave": (hess, CONCAVE),
        "hess_saddle": (hess, SADDLE),
        "hess_convex": (hess, CONVEX),
    }
    rows = {"rate": [], **{key: [] for key in classes}}
    for g in np.array_split(np.arange(n), groups):
        lk = locked[g]
        rows["rate"].append(lk.mean())
        m = max(1, lk.sum())
        for key, (labels, cls) in classes.items():
            rows[key].append((labels[g] == cls).sum() / m if lk.any() else np.nan)
    entry = {"hurst": hurst, "self_locked": int(locked.sum()), "surfaces": n}
    for key, vals in rows.items():
        v = np.asarray(vals, dtype=float)
        entry[f"{key}_mean"] = _nan_none(np.nanmean(v) if np.isfinite(v).any() else np.nan)
        entry[f"{key}_sd"] = _nan_none(np.nanstd(v) if np.isfinite(v).sum() > 1 else np.nan)
    return entry


def _nan_none(v):
    v = float(v)
    return v if math.isfinite(v) else None


REPRODUCTIONS = {
    "single-peak": single_peak,
    "random-gaussian": random_gaussian,
    "fractal-hurst": fractal_hurst,
    "kappa-map": kappa_map,
}


def run(name: str, *, quick: bool = False, progress: Progress = None, **options):
    """Run reproduction ``name`` (one of :data:`REPRODUCTIONS`); returns ``(numbers, fig)``."""
    if name not in REPRODUCTIONS:
        raise SpineInputError(f"NAME must be one of {', '.join(REPRODUCTIONS)}, got {name!r}")
    return REPRODUCTIONS[name](quick=quick, progress=progress, **options)
