"""Figs. 7E and 9: fractal surfaces, self-lock against the Hurst index."""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    fractal_hurst_figure,
)
from spine_mj.reproduce._common import Progress, _nan_none, _settings
from spine_mj.surfaces import fractal_fbm
from spine_mj.theory.convexity import CONCAVE, CONVEX, SADDLE, hessian_class, sectional_class
from spine_mj.theory.streamline import ideal_trajectories, streamlines
from spine_mj.theory.streamline_types import StreamlineParams
from spine_mj.workers import check_workers

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
