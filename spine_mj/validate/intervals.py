"""Intervals on the validation's headline numbers, and the rule that says a target is met.

MuJoCo differs in the last bits between CPUs, and chaotic paths near watersheds amplify
that into whole flipped runs: a headline number is a sample, and no verdict may hinge on one
run. Rates (agreements, lock rates) get a Wilson interval (:func:`wilson`); medians and other
statistics of per-run values a percentile bootstrap over runs (:func:`bootstrap`). A target
is met when the point estimate meets it and the interval's far bound lies within
:data:`TARGET_SLACK` of it (:func:`meets_target`): one flipped run cannot decide it, and a
sample too small to say anything does not pass.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy import stats

__all__ = [
    "CONFIDENCE",
    "TARGET_RULE",
    "TARGET_SLACK",
    "bootstrap",
    "meets_target",
    "newcombe_difference",
    "runs_to_meet",
    "wilson",
]

#: Confidence level of every interval on a headline number.
CONFIDENCE = 0.95
#: How far the interval's far bound may lie beyond a target that the point estimate meets:
#: 5 points of a rate; for a statistic of lengths, 5 % of the target.
TARGET_SLACK = 0.05
#: :func:`meets_target` in words, for ``validation.json`` and the report.
TARGET_RULE = (
    "met when the point estimate meets the target and the 95 % interval's far bound lies within "
    "5 points of it (a rate: low >= target - 0.05; a length: high <= 1.05 target)"
)


def wilson(successes: int, n: int, *, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """Wilson score interval of a rate ``successes / n``; (NaN, NaN) when ``n == 0``."""
    k, n = int(successes), int(n)
    if not (0 <= k <= n):
        raise ValueError(f"successes must lie in [0, n = {n}], got {successes!r}")
    if n == 0:
        return math.nan, math.nan
    ci = stats.binomtest(k, n).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def bootstrap(
    values: Sequence[float],
    statistic: Callable[[np.ndarray], float] = np.median,
    *,
    n_resamples: int = 2000,
    confidence: float = CONFIDENCE,
    seed: int = 0,
) -> tuple[float, float]:
    """Percentile bootstrap interval of ``statistic`` over the finite ``values`` (runs).

    A fixed ``seed`` and the values sorted first make the interval a function of the values
    alone, not of the order the runs came in (how a study splits its sweeps into cases).
    (NaN, NaN) with fewer than two finite values; a sample of one repeated value gives that
    value twice.
    """
    v = np.asarray(values, dtype=float)
    v = np.sort(v[np.isfinite(v)])
    if v.size < 2:
        return math.nan, math.nan
    if np.all(v == v[0]):
        return float(v[0]), float(v[0])
    res = stats.bootstrap(
        (v,),
        lambda x: float(statistic(x)),
        n_resamples=n_resamples,
        confidence_level=confidence,
        method="percentile",
        vectorized=False,
        rng=np.random.default_rng(seed),
    )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


def newcombe_difference(a: dict, b: dict) -> dict:
    """``a["rate"] - b["rate"]`` of two rate records (``rate``, ``ci_low``, ``ci_high``: e.g.
    :func:`~spine_mj.validate.fractal_lock.lock_rate`) with Newcombe's hybrid
    score interval (method 10) built from their Wilson intervals."""
    pa, pb = a["rate"], b["rate"]
    d = pa - pb
    lo = d - math.sqrt((pa - a["ci_low"]) ** 2 + (b["ci_high"] - pb) ** 2)
    hi = d + math.sqrt((a["ci_high"] - pa) ** 2 + (pb - b["ci_low"]) ** 2)
    return {"diff": d, "ci_low": lo, "ci_high": hi}


def meets_target(point: float, interval: Sequence[float], target: float, *, higher_is_better: bool) -> bool:
    """Whether ``point`` meets ``target`` with its ``(low, high)`` interval.

    Higher is better (a rate): ``point >= target`` and ``low >= target - TARGET_SLACK``.
    Lower is better (a length): ``point <= target`` and
    ``high <= target * (1 + TARGET_SLACK)``. A NaN anywhere is not met.
    """
    low, high = (float(b) for b in interval)
    if not all(math.isfinite(v) for v in (point, low, high, target)):
        return False
    if higher_is_better:
        return point >= target and low >= target - TARGET_SLACK
    return point <= target and high <= target * (1.0 + TARGET_SLACK)


def runs_to_meet(target: float) -> int:
    """The fewest runs with which a rate can meet ``target`` under :func:`meets_target`: all
    of them agreeing, the Wilson interval's low end reaching ``target - TARGET_SLACK`` (35
    for 0.95: a plan of 30 runs a family cannot meet it, whatever it measures)."""
    n = 1
    while wilson(n, n)[0] < target - TARGET_SLACK:
        n += 1
    return n
