"""Metrics comparing a dynamic (MuJoCo) trajectory with the quasistatic streamline.

All lengths come back normalized by the characteristic asperity length ``L_c`` passed in,
so numbers from surfaces of different scale are comparable (the validation targets are
stated in units of ``L_c``).

* :func:`frechet_distance`: discrete Frechet distance between two polylines (the
  shortest "leash" when both walk forward along their paths);
* :func:`mean_lateral_deviation`: mean distance from points of one path (equally spaced in
  arc length) to the other polyline, in the x-y plane;
* :func:`outcome_agreement`: both self-lock or neither, end points within a tolerance,
  same trap;
* :func:`kappa_agreement`: quasistatic max kappa against the dynamic peak drive force / W;
* :func:`capture_rate`: the fraction of runs that end self-locked (trapped);
* :func:`miss_reason`: why a run and its reference disagree, from the reference restarted
  along the run's path;
* :func:`slide_fraction` and :func:`peak_speed`: how much of a path gravity alone moves
  (where the quasistatic model has no drive, hence no rate) and how fast the engine's tip
  actually went: the evidence that a path is quasistatic at all, whatever the drive speed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from spine_mj.errors import SpineInputError
from spine_mj.memory import BLOCK_BYTES
from spine_mj.theory.engagement import SLIP

#: The most points :func:`resample_by_arclength` returns (2^16, 1 MiB of x-y): at the
#: default spacing L_c / 50 a path over 1300 L_c long, hundreds of times any run across a
#: surface; a longer one (a diverged run) is sampled more coarsely rather than without bound.
MAX_RESAMPLED_POINTS = 2**16
# bytes of float64 temporaries per (point, segment) pair in _point_segment_distance
_PAIR_BYTES = 8 * 8

#: The kinds :func:`miss_reason` tells apart, in the order reports list them, and what each
#: means (the report prints these).
MISS_REASONS = {
    "separatrix": "the reference restarted from a point of MuJoCo's path within one hfield "
    "spacing of its own path ends where MuJoCo ended: the reference's outcome flips closer "
    "to its path than the engine's tip can follow it (the two sides agree on the flow; the "
    "start is ill-conditioned)",
    "diverged": "the first such point is farther: MuJoCo left the reference's path by the "
    "offset before the outcomes parted (inertia, a hop)",
    "engine_held": "no restart ends as MuJoCo did, and MuJoCo held where the reference, "
    "restarted at MuJoCo's end, moves on (a lock the reference does not see)",
    "engine_passed": "MuJoCo ended free where every restart of the reference holds",
    "reference_stalled": "the reference made no progress even at its shortest step: it "
    "decided nothing (no restart is traced)",
}

__all__ = [
    "MAX_RESAMPLED_POINTS",
    "MISS_REASONS",
    "capture_rate",
    "frechet_distance",
    "frechet_distance_reference",
    "kappa_agreement",
    "mean_lateral_deviation",
    "miss_reason",
    "outcome_agreement",
    "path_frechet",
    "peak_speed",
    "resample_by_arclength",
    "slide_fraction",
]


def _path(name: str, path) -> np.ndarray:
    arr = np.asarray(path, dtype=float)
    if arr.ndim != 2 or arr.shape[1] not in (2, 3) or arr.shape[0] < 1:
        raise SpineInputError(f"{name} must have shape (n, 2) or (n, 3) with n >= 1, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SpineInputError(f"{name} contains NaN or infinite coordinates")
    return arr


def _length_scale(length_scale) -> float:
    value = float(length_scale)
    if not (math.isfinite(value) and value > 0):
        raise SpineInputError(f"length_scale (L_c) must be a finite number > 0, got {length_scale!r}")
    return value


@njit(cache=True)
def _frechet_kernel(p, q):
    n, m = p.shape[0], q.shape[0]
    prev = np.empty(m)
    cur = np.empty(m)
    for i in range(n):
        for j in range(m):
            d = 0.0
            for k in range(p.shape[1]):
                diff = p[i, k] - q[j, k]
                d += diff * diff
            d = math.sqrt(d)
            if i == 0 and j == 0:
                best = d
            elif i == 0:
                best = max(cur[j - 1], d)
            elif j == 0:
                best = max(prev[0], d)
            else:
                best = max(min(prev[j], prev[j - 1], cur[j - 1]), d)
            cur[j] = best
        prev, cur = cur, prev
    return prev[m - 1]


def frechet_distance(path_a, path_b, *, length_scale: float = 1.0) -> float:
    """Discrete Frechet distance between two polylines, divided by ``length_scale``.

    Parameters
    ----------
    path_a, path_b : array_like, shapes (n, d), (m, d), d = 2 or 3
        Vertices in walking order. Both must have the same ``d``.
    length_scale
        ``L_c``; the result is in units of it.

    Notes
    -----
    O(n m) time, O(m) memory (a compiled dynamic programme, Eiter and Mannila 1994). For
    long paths, :func:`resample_by_arclength` both first: the discrete distance then
    approaches the continuous one as the spacing shrinks.
    """
    a, b = _path("path_a", path_a), _path("path_b", path_b)
    if a.shape[1] != b.shape[1]:
        raise SpineInputError(
            f"path_a and path_b must have the same dimension, got {a.shape[1]} and {b.shape[1]}"
        )
    return float(_frechet_kernel(np.ascontiguousarray(a), np.ascontiguousarray(b))) / _length_scale(
        length_scale
    )


def frechet_distance_reference(path_a, path_b) -> float:
    """Plain recursive definition of the discrete Frechet distance (slow; for tests)."""
    a, b = _path("path_a", path_a), _path("path_b", path_b)
    memo = np.full((len(a), len(b)), -1.0)

    def c(i, j):
        if memo[i, j] < 0:
            d = float(np.linalg.norm(a[i] - b[j]))
            if i == 0 and j == 0:
                memo[i, j] = d
            elif i == 0:
                memo[i, j] = max(c(0, j - 1), d)
            elif j == 0:
                memo[i, j] = max(c(i - 1, 0), d)
            else:
                memo[i, j] = max(min(c(i - 1, j), c(i - 1, j - 1), c(i, j - 1)), d)
        return memo[i, j]

    return c(len(a) - 1, len(b) - 1)


def resample_by_arclength(path, spacing: float) -> np.ndarray:
    """Points equally spaced by ``spacing`` in arc length along a polyline (ends kept).

    At most :data:`MAX_RESAMPLED_POINTS`: a path longer than that many spacings is
    resampled at its arc length / (``MAX_RESAMPLED_POINTS`` - 1) instead, so memory and the
    comparisons' time stay bounded whatever the path's length (a diverged run's path that
    flies off to 1e6 L_c and back would otherwise need 5e7 samples at L_c / 50).
    """
    p = _path("path", path)
    spacing = _length_scale(spacing)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] == 0:
        return p[:1].copy()
    n = int(min(MAX_RESAMPLED_POINTS, max(2, math.ceil(s[-1] / spacing) + 1)))
    target = np.linspace(0.0, s[-1], n)
    keep = np.concatenate([[True], seg > 0])
    return np.column_stack([np.interp(target, s[keep], p[keep, k]) for k in range(p.shape[1])])


def path_frechet(path, reference, *, length_scale: float, spacing: float | None = None) -> float:
    """Frechet distance between two recorded paths over ``L_c``, both resampled first.

    The one path-deviation rule of the project: both polylines are resampled to equal
    arc-length steps (``spacing``, default ``L_c / 50``) so that the discrete distance
    approximates the continuous one whatever the recording density, then
    :func:`frechet_distance` is taken in units of ``length_scale``.
    """
    a, b = _path("path", path), _path("reference", reference)
    lc = _length_scale(length_scale)
    step = lc / 50 if spacing is None else spacing
    return frechet_distance(resample_by_arclength(b, step), resample_by_arclength(a, step), length_scale=lc)


def _point_segment_distance(points, seg_start, seg_end):
    """Distance from each point (P, 2) to the nearest of the segments (S, 2) -> (P,).

    Blocks of points x segments whose temporaries take at most
    :data:`spine_mj.memory.BLOCK_BYTES`, so memory is O(P + S) whatever their product."""
    d = seg_end - seg_start
    len2 = np.einsum("sk,sk->s", d, d)
    inv = np.divide(1.0, len2, out=np.zeros_like(len2), where=len2 > 0)
    best = np.full(points.shape[0], np.inf)
    pairs = max(1, BLOCK_BYTES // _PAIR_BYTES)
    pstep = max(1, min(points.shape[0], pairs))
    sstep = max(1, pairs // pstep)
    for plo in range(0, points.shape[0], pstep):
        pts = points[plo : plo + pstep]
        for lo in range(0, seg_start.shape[0], sstep):
            a, dd, il2 = seg_start[lo : lo + sstep], d[lo : lo + sstep], inv[lo : lo + sstep]
            rel = pts[:, None, :] - a[None, :, :]
            t = np.clip(np.einsum("psk,sk->ps", rel, dd) * il2, 0.0, 1.0)
            rel -= t[..., None] * dd[None]
            dist = np.sqrt(np.einsum("psk,psk->ps", rel, rel))
            np.minimum(best[plo : plo + pstep], dist.min(axis=1), out=best[plo : plo + pstep])
    return best


def mean_lateral_deviation(
    path, reference, *, length_scale: float = 1.0, spacing: float | None = None
) -> float:
    """Mean x-y distance from ``path`` to the ``reference`` polyline, over ``L_c``.

    ``path`` is resampled to equal arc-length steps (``spacing``, default L_c / 50) so
    that the mean weighs the path by length, not by how densely it was recorded; each
    sample's distance to the nearest point of the reference polyline (segments, not only
    vertices) is averaged.

    Parameters
    ----------
    path, reference : array_like, shapes (n, d), (m, d), d = 2 or 3
        Vertices in walking order (only x and y are used), in one length unit.
    length_scale : float
        ``L_c`` in that unit; the result is in units of it.
    spacing : float, optional
        Resampling step of ``path`` in that unit (default ``length_scale / 50``).

    Returns
    -------
    float
        The mean distance over ``length_scale``.
    """
    lc = _length_scale(length_scale)
    p = _path("path", path)[:, :2]
    ref = _path("reference", reference)[:, :2]
    samples = resample_by_arclength(p, lc / 50 if spacing is None else spacing)
    if ref.shape[0] == 1:
        dist = np.linalg.norm(samples - ref[0], axis=1)
    else:
        dist = _point_segment_distance(samples, ref[:-1], ref[1:])
    return float(dist.mean() / lc)


def outcome_agreement(
    locked_a, end_a, locked_b, end_b, *, length_scale: float = 1.0, end_tolerance: float = 0.25
) -> dict[str, np.ndarray]:
    """Agreement of run outcomes, vectorized over runs.

    Parameters
    ----------
    locked_a, locked_b : array_like of bool, shape (n,)
        Whether each run of A (e.g. quasistatic) and B (e.g. MuJoCo) ended self-locked.
    end_a, end_b : array_like, shape (n, 2) or (n, 3)
        End points (x, y[, z]); only x and y are compared.
    length_scale : float
        ``L_c`` in the end points' unit.
    end_tolerance : float
        End points closer than ``end_tolerance * L_c`` in x-y count as the same place.

    Returns
    -------
    dict of bool arrays, shape (n,)
        ``lock``: both self-locked or neither. ``end``: end points within tolerance.
        ``same_trap``: both self-locked and in the same place. ``agree``: ``lock`` and,
        where both locked, ``same_trap`` (the outcome a user cares about: held or not, and
        where).
    """
    lc = _length_scale(length_scale)
    la = np.asarray(locked_a, dtype=bool)
    lb = np.asarray(locked_b, dtype=bool)
    ea = np.asarray(end_a, dtype=float).reshape(la.size, -1)[:, :2]
    eb = np.asarray(end_b, dtype=float).reshape(lb.size, -1)[:, :2]
    if not (la.shape == lb.shape and ea.shape[0] == la.size and eb.shape[0] == lb.size):
        raise SpineInputError(
            f"locked_a, end_a, locked_b, end_b must describe the same n runs, got "
            f"{la.shape}, {ea.shape}, {lb.shape}, {eb.shape}"
        )
    if not (end_tolerance > 0):
        raise SpineInputError(f"end_tolerance must be > 0, got {end_tolerance!r}")
    lock = la == lb
    end = np.linalg.norm(ea - eb, axis=1) <= end_tolerance * lc
    same_trap = la & lb & end
    agree = lock & (~la | same_trap)
    return {"lock": lock, "end": end, "same_trap": same_trap, "agree": agree}


def miss_reason(
    checkpoints, reference, reaches, mj_locked: bool, *, length_scale: float, separatrix_offset: float
) -> tuple[str, float]:
    """Why a run disagrees with its reference, read from the reference restarted at
    checkpoints along the run's own path (the first at its start, the last at its end).

    Parameters
    ----------
    checkpoints : array_like, shape (k, 2)
        Points of the run's path, in order.
    reference : array_like, shape (n, 2)
        The reference path of the run's start.
    reaches : array_like of bool, shape (k,)
        Whether the reference restarted at each checkpoint ends as the run did
        (:func:`outcome_agreement`).
    mj_locked : bool
        Whether the run ended held.
    length_scale
        L_c, in the unit of the paths.
    separatrix_offset
        Distance from the reference (over L_c) up to which the run cannot follow it: a facet.

    Returns
    -------
    reason : str
        A key of :data:`MISS_REASONS`, which says what each means: ``separatrix`` where the
        first checkpoint whose restart ends as the run did lies within
        ``separatrix_offset`` of the reference, ``diverged`` where it lies farther,
        ``engine_held`` / ``engine_passed`` where no restart ends as the run did and the
        run ended held / free. (``reference_stalled`` is the caller's to tell: a stalled
        reference has no outcome to read restarts against.)
    offset : float
        Distance over L_c from the reference of the first checkpoint that reaches the run's
        outcome; NaN for the engine_* reasons.
    """
    lc = _length_scale(length_scale)
    pts = _path("checkpoints", checkpoints)[:, :2]
    ref = _path("reference", reference)[:, :2]
    hit = np.asarray(reaches, dtype=bool).ravel()
    if hit.shape != (pts.shape[0],):
        raise SpineInputError(f"reaches must have one flag per checkpoint ({pts.shape[0]}), got {hit.shape}")
    if not (separatrix_offset >= 0):
        raise SpineInputError(f"separatrix_offset must be >= 0, got {separatrix_offset!r}")
    first = np.flatnonzero(hit)
    if first.size == 0:
        return ("engine_held" if mj_locked else "engine_passed"), math.nan
    point = pts[first[:1]]
    if ref.shape[0] == 1:
        offset = float(np.linalg.norm(point[0] - ref[0]) / lc)
    else:
        offset = float(_point_segment_distance(point, ref[:-1], ref[1:])[0] / lc)
    return ("separatrix" if offset <= separatrix_offset else "diverged"), offset


def kappa_agreement(
    max_kappa_quasistatic, peak_force_over_weight, *, kappa_cap: float
) -> dict[str, np.ndarray]:
    """Quasistatic max kappa against the dynamic peak drive force / W, per run.

    A self-locked quasistatic run has max kappa = inf and a dynamic one stops at the cap
    ``kappa_cap`` (force reaching ``kappa_cap * W`` without motion), so both are clipped to
    the cap before comparing.

    Parameters
    ----------
    max_kappa_quasistatic : array_like, shape (n,)
        Largest kappa along each streamline (paper Eqs. 1-3; inf where it self-locked).
    peak_force_over_weight : array_like, shape (n,)
        Largest drive force of each dynamic run over the preload W (dimensionless).
    kappa_cap : float
        The force cap over W that both sides are clipped to.

    Returns
    -------
    dict of arrays, shape (n,)
        ``ratio``: dynamic / quasistatic (clipped values); ``both_capped``: both at the cap.
    """
    if not (kappa_cap > 0 and math.isfinite(kappa_cap)):
        raise SpineInputError(f"kappa_cap must be a finite number > 0, got {kappa_cap!r}")
    qs = np.minimum(np.asarray(max_kappa_quasistatic, dtype=float), kappa_cap)
    dyn = np.minimum(np.asarray(peak_force_over_weight, dtype=float), kappa_cap)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(qs > 0, dyn / qs, np.nan)
    return {"ratio": ratio, "both_capped": (qs >= kappa_cap) & (dyn >= kappa_cap)}


def capture_rate(locked) -> float:
    """Fraction of runs that ended self-locked; NaN for no runs.

    Parameters
    ----------
    locked : array_like of bool, shape (n,)
        Whether each run ended self-locked.

    Returns
    -------
    float
        ``locked.mean()``, in [0, 1]; NaN when ``n = 0``.
    """
    arr = np.asarray(locked, dtype=bool)
    return float(arr.mean()) if arr.size else float("nan")


def slide_fraction(path, region) -> float:
    """Share of a streamline's arc length traced in the slip region (``region`` per point,
    :data:`spine_mj.theory.engagement.SLIP`; a segment counts by its first point), where gravity
    alone slides the tip (docs/physics.md §2).

    There the quasistatic model has no drive force and no rate: the engine's tip falls at
    the speed gravity gives it, not at the drive's, so a path with slides is not
    quasistatic at any drive speed (:func:`peak_speed` measures how fast it went). NaN for
    a path of fewer than two points or of zero length.
    """
    p = _path("path", path)
    reg = np.asarray(region).reshape(-1)
    if reg.size != p.shape[0]:
        raise SpineInputError(f"region must have one entry per path point ({p.shape[0]}), got {reg.size}")
    seg = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1)
    total = float(seg.sum())
    if not total > 0:
        return float("nan")
    return float(seg[reg[:-1] == SLIP].sum() / total)


def peak_speed(velocity) -> float:
    """The largest speed ``|v|`` of velocity rows ``(n, 3)`` (NaN for none). Through
    :meth:`spine_mj.sim.Scales.inertia_number` it gives the inertia number the tip itself
    reached, ``m v_max^2 / (F_p L_c)``, to set against the drive's and against I_e*."""
    v = np.asarray(velocity, dtype=float).reshape(-1, 3)
    return float(np.sqrt((v * v).sum(axis=1)).max()) if v.shape[0] else float("nan")
