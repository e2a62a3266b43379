"""I_e*: the inertia number at which MuJoCo stops agreeing with the quasistatic streamline.

:func:`estimate_ie_star` locates the break along an increasing I_e grid (bracketing
interval plus a log-linear interpolation inside it), :func:`bootstrap_ie_star` and
:func:`departure_ie_star` add an interval from resampling the starts, and
:func:`ie_star_by_criterion` applies every criterion of :data:`IE_STAR_CRITERIA`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import stats

from spine_mj.errors import SpineInputError
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET

__all__ = [
    "DEPARTURE",
    "IE_STAR_CRITERIA",
    "IeStar",
    "bootstrap_ie_star",
    "criterion_ie_star",
    "departure_ie_star",
    "estimate_ie_star",
    "grid_point",
    "ie_star_by_criterion",
    "passes_criterion",
    "quiet_nan_warnings",
]


@dataclass(frozen=True)
class IeStar:
    """Where agreement breaks along an I_e grid.

    Attributes
    ----------
    value : float
        Estimated I_e* (log-linear interpolation of the failing metric to its threshold
        between the bracketing grid values); NaN when agreement holds over the whole grid
        (``above``) or fails already at its lowest value (``below``).
    low, high : float
        Bracketing interval: the last grid value that passes and the first that fails.
    kind : {"bracketed", "above", "below"}
        ``above``: agreement holds at every grid value, I_e* > ``low`` = the largest;
        ``below``: fails at the smallest, I_e* < ``high``.
    ci_low, ci_high : float
        16th and 84th percentiles of the bootstrap over starts (NaN when not computed).
    """

    value: float
    low: float
    high: float
    kind: str
    ci_low: float = float("nan")
    ci_high: float = float("nan")

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def passes_criterion(
    agree: float, frechet: float, *, agree_min: float = OUTCOME_TARGET, frechet_max: float = FRECHET_TARGET
) -> bool:
    """Whether agreement holds at one I_e: ``agree >= agree_min`` and a finite ``frechet``
    (if any) ``<= frechet_max``; a NaN agreement fails."""
    return (
        bool(agree >= agree_min and (not np.isfinite(frechet) or frechet <= frechet_max))
        if np.isfinite(agree)
        else False
    )


def estimate_ie_star(
    ie, agreement, frechet=None, *, agree_min: float = OUTCOME_TARGET, frechet_max: float = FRECHET_TARGET
) -> IeStar:
    """The I_e at which agreement first breaks along an increasing grid.

    Agreement passes at a grid value when ``agreement >= agree_min`` and (if given)
    ``frechet <= frechet_max``. The first failing value above a passing one brackets I_e*;
    inside the bracket, the metric that fails is interpolated linearly in ``log10 I_e`` to
    its threshold (both failing: the smaller crossing).

    Parameters
    ----------
    ie : array_like, shape (n,)
        Strictly increasing, > 0.
    agreement : array_like, shape (n,)
        Outcome agreement (fraction in [0, 1]) at each I_e.
    frechet : array_like, shape (n,), optional
        Mean Frechet deviation / L_c at each I_e.
    agree_min : float
        The agreement target (default :data:`~spine_mj.theory.agreement.OUTCOME_TARGET`, 0.95).
    frechet_max : float
        The Frechet target / L_c (default :data:`~spine_mj.theory.agreement.FRECHET_TARGET`, 0.1).

    Returns
    -------
    IeStar

    Raises
    ------
    SpineInputError
        Shapes differ, fewer than 2 values, or ``ie`` not strictly increasing and positive.

    Examples
    --------
    Agreement holds up to ``I_e = 0.01`` and fails at 0.1, where the Frechet distance
    (0.12 L_c) passes its target of 0.1: I_e* lies in that bracket, where the path metric
    crosses its threshold (interpolated in ``log10 I_e``).

    >>> star = estimate_ie_star([1e-3, 1e-2, 1e-1, 1.0], [1.0, 1.0, 0.97, 0.6], [0.01, 0.03, 0.12, 0.5])
    >>> star.kind, star.low, star.high
    ('bracketed', 0.01, 0.1)
    >>> 0.01 < star.value < 0.1
    True
    """
    ie = np.asarray(ie, dtype=float)
    ag = np.asarray(agreement, dtype=float)
    fr = np.full_like(ie, np.nan) if frechet is None else np.asarray(frechet, dtype=float)
    if ie.ndim != 1 or ie.size < 2 or ag.shape != ie.shape or fr.shape != ie.shape:
        raise SpineInputError(
            f"ie, agreement and frechet must be 1-D of the same length >= 2, "
            f"got {ie.shape}, {ag.shape}, {fr.shape}"
        )
    if not (np.all(ie > 0) and np.all(np.diff(ie) > 0)):
        raise SpineInputError(f"ie must be positive and strictly increasing, got {ie.tolist()}")
    ok = np.array(
        [passes_criterion(a, f, agree_min=agree_min, frechet_max=frechet_max) for a, f in zip(ag, fr)]
    )
    if not ok[0]:
        return IeStar(float("nan"), float("nan"), float(ie[0]), "below")
    bad = np.flatnonzero(~ok)
    if bad.size == 0:
        return IeStar(float("nan"), float(ie[-1]), float("nan"), "above")
    j = int(bad[0])
    i = j - 1
    li, lj = math.log10(ie[i]), math.log10(ie[j])
    cands = []
    if ag[j] < agree_min and ag[i] != ag[j]:
        t = (ag[i] - agree_min) / (ag[i] - ag[j])
        cands.append(li + np.clip(t, 0, 1) * (lj - li))
    if np.isfinite(fr[j]) and fr[j] > frechet_max and np.isfinite(fr[i]) and fr[j] != fr[i]:
        t = (frechet_max - fr[i]) / (fr[j] - fr[i])
        cands.append(li + np.clip(t, 0, 1) * (lj - li))
    value = 10 ** min(cands) if cands else math.sqrt(ie[i] * ie[j])
    return IeStar(float(value), float(ie[i]), float(ie[j]), "bracketed")


def bootstrap_ie_star(
    ie,
    agree_matrix,
    frechet_matrix,
    *,
    n_boot: int,
    rng,
    agree_min: float = OUTCOME_TARGET,
    frechet_max: float = FRECHET_TARGET,
    stat: str | None = "mean",
    confidence: float = 0.68,
) -> tuple[float, float]:
    """16th / 84th percentiles of I_e* when the starts are resampled with replacement (the
    ``confidence`` interval's ends: 0.68 by default).

    ``agree_matrix`` and ``frechet_matrix`` have shape ``(n_ie, n_starts)``; ``stat``
    (``"mean"``, ``"median"`` or None: agreement only) reduces the Frechet deviations of a
    resample. A resample whose I_e* is not bracketed contributes the edge of the grid it
    points at.

    Parameters
    ----------
    ie : array_like, shape (n_ie,)
        Strictly increasing inertia numbers.
    agree_matrix, frechet_matrix : array_like, shape (n_ie, n_starts)
        Per-run agreement (0 / 1) and Frechet deviation / L_c.
    n_boot : int
        Resamples.
    rng : int or numpy.random.Generator
        The resampling's randomness.
    agree_min, frechet_max : float
        The targets (:func:`estimate_ie_star`).
    stat : {"mean", "median", None}
        How a resample's Frechet deviations are reduced (None: agreement only).
    confidence : float
        Of the percentile interval, in (0, 1) (0.95 for a solution-verification verdict,
        :mod:`spine_mj.validate.convergence`).
    """
    if stat not in ("mean", "median", None):
        raise SpineInputError(f"stat must be 'mean', 'median' or None, got {stat!r}")
    a = np.asarray(agree_matrix, dtype=float)
    f = np.asarray(frechet_matrix, dtype=float)
    n = a.shape[1]
    if n == 0 or n_boot <= 0:
        return float("nan"), float("nan")
    reduce = {"mean": np.nanmean, "median": np.nanmedian}.get(stat)

    def estimate(idx):
        with np.errstate(all="ignore"), quiet_nan_warnings():
            fr = None if reduce is None else reduce(f[:, idx], axis=1)
            return estimate_ie_star(
                ie, a[:, idx].mean(axis=1), fr, agree_min=agree_min, frechet_max=frechet_max
            )

    return _log_interval(estimate, n, n_boot, rng, confidence=confidence)


def grid_point(est: IeStar) -> float:
    """I_e* of an estimate, or the edge of the grid it points at when not bracketed (a
    number for every kind: what an interval and a change of I_e* are taken of)."""
    return est.value if est.kind == "bracketed" else (est.low if est.kind == "above" else est.high)


def _log_interval(
    estimate, n_starts: int, n_boot: int, rng, *, confidence: float = 0.68
) -> tuple[float, float]:
    """The ``confidence`` percentile interval (16th / 84th percentiles by default) of
    ``log10 I_e*`` over resamples of the starts (``scipy.stats.bootstrap``, percentile
    method); ``estimate(indices) -> IeStar``."""
    if n_starts < 2:
        value = grid_point(estimate(np.arange(n_starts)))
        return value, value
    res = stats.bootstrap(
        (np.arange(n_starts),),
        lambda idx: math.log10(grid_point(estimate(idx))),
        n_resamples=n_boot,
        confidence_level=confidence,
        method="percentile",
        vectorized=False,
        rng=np.random.default_rng(rng),
    )
    return float(10**res.confidence_interval.low), float(10**res.confidence_interval.high)


@contextlib.contextmanager
def quiet_nan_warnings():
    """Silence the all-NaN-slice RuntimeWarnings of nanmean / nanmedian."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


#: How far (as a fraction) outcome agreement may fall below its lowest-I_e value before
#: the :func:`departure_ie_star` criterion counts it as broken.
DEPARTURE = 0.1


#: I_e* criteria: label -> (Frechet statistic over starts or None, description).
IE_STAR_CRITERIA = {
    "median_frechet": ("median", "outcome agreement >= 95 % and median Frechet <= 0.1 L_c"),
    "outcome": (None, "outcome agreement >= 95 %"),
    "mean_frechet": (
        "mean",
        "outcome agreement >= 95 % and mean Frechet <= 0.1 L_c (sensitive: one outlying start moves it)",
    ),
}


def ie_star_by_criterion(ie, agree_matrix, frechet_matrix, *, n_boot: int, rng=12345) -> dict:
    """I_e* under each of :data:`IE_STAR_CRITERIA`, with its bootstrap interval over starts.

    Parameters
    ----------
    ie : array_like, shape (n_ie,)
        Strictly increasing inertia numbers.
    agree_matrix, frechet_matrix : array_like, shape (n_ie, n_starts)
        Per-run agreement (0 / 1) and Frechet deviation / L_c.
    n_boot : int
        Resamples of the starts for each interval.
    rng : int or numpy.random.Generator
        The resampling's randomness.

    Returns
    -------
    dict
        label -> :meth:`IeStar.as_dict` plus ``criterion`` (its description).
    """
    a = np.asarray(agree_matrix, dtype=float)
    f = np.asarray(frechet_matrix, dtype=float)
    out = {}
    for label, (stat, text) in IE_STAR_CRITERIA.items():
        star = criterion_ie_star(ie, a, f, label)
        lo, hi = bootstrap_ie_star(ie, a, f, n_boot=n_boot, rng=rng, stat=stat)
        out[label] = {**dataclasses.replace(star, ci_low=lo, ci_high=hi).as_dict(), "criterion": text}
    out["departure"] = {
        **departure_ie_star(ie, a, n_boot=n_boot, rng=rng).as_dict(),
        "criterion": f"outcome agreement within {100 * DEPARTURE:g} points of "
        "its value at the lowest I_e (where the picture breaks "
        "relative to the engine's own low-speed agreement)",
    }
    return out


def criterion_ie_star(ie, agree_matrix, frechet_matrix, criterion: str) -> IeStar:
    """I_e* under one criterion of :data:`IE_STAR_CRITERIA` (no interval).

    Parameters
    ----------
    ie : array_like, shape (n_ie,)
        Strictly increasing inertia numbers.
    agree_matrix, frechet_matrix : array_like, shape (n_ie, n_starts)
        Per-run agreement (0 / 1) and Frechet deviation / L_c.
    criterion : str
        A key of :data:`IE_STAR_CRITERIA`.
    """
    if criterion not in IE_STAR_CRITERIA:
        raise SpineInputError(f"criterion must be one of {sorted(IE_STAR_CRITERIA)}, got {criterion!r}")
    stat = IE_STAR_CRITERIA[criterion][0]
    a = np.asarray(agree_matrix, dtype=float)
    f = np.asarray(frechet_matrix, dtype=float)
    with quiet_nan_warnings():
        fr = None if stat is None else (np.nanmean(f, axis=1) if stat == "mean" else np.nanmedian(f, axis=1))
    return estimate_ie_star(ie, a.mean(axis=1), fr)


def departure_ie_star(ie, agree_matrix, *, n_boot: int, rng=12345) -> IeStar:
    """I_e* where outcome agreement first falls more than :data:`DEPARTURE` below its value
    at the lowest I_e, with a 16-84 % bootstrap interval over starts (the baseline is
    recomputed in every resample).

    The absolute criteria fail at every I_e when a few starts disagree for reasons that do
    not depend on I_e (a marginal start, hfield facets); this one still locates where
    inertia makes agreement break down.

    Parameters
    ----------
    ie : array_like, shape (n_ie,)
        Strictly increasing inertia numbers.
    agree_matrix : array_like, shape (n_ie, n_starts)
        Per-run agreement (0 / 1).
    n_boot : int
        Resamples of the starts.
    rng : int or numpy.random.Generator
        The resampling's randomness.
    """
    a = np.asarray(agree_matrix, dtype=float)

    def estimate(sample):
        m = sample.mean(axis=1)
        return estimate_ie_star(ie, m, None, agree_min=m[0] - DEPARTURE - 1e-12)

    star = estimate(a)
    n = a.shape[1]
    if n == 0 or n_boot <= 0:
        return star
    lo, hi = _log_interval(lambda idx: estimate(a[:, idx]), n, n_boot, rng)
    return dataclasses.replace(star, ci_low=lo, ci_high=hi)
