"""Convergence to the theory, from the (I_e, K) map: the gap between MuJoCo and the
streamline against I_e and against 1/K with its fitted order beside the order the theory
predicts, and the predicted drive limits against the measured ones.

The gap is ``1 - agreement`` (outcome agreement) and the median Frechet distance (in L_c),
each cell's over its runs (:func:`spine_mj.validate.stiffness_map.agreement_map`). Two
series per family (docs/physics.md §10):

- against I_e at the family's stiffest K (the spring's offset smallest there): the tip's
  lag behind a turn is ``I_e L_c / (2 mu)``, first order in I_e;
- against 1/K at the lowest I_e every K ran at, over K >= K* (below K* the compliant path
  folds and jumps: no power law): the compliant offset of the path from the rigid
  streamline is ``kappa F_p / k``, i.e. ``kappa l_s / K``, first order in 1/K.

The order is the least-squares slope of log gap against log x with its t interval
(:func:`fit_order`), over the points the metric resolves: a median Frechet above twice its
resolution (:data:`FRECHET_FLOOR_LC`), an agreement gap above zero.

The predicted drive limits against the measured ones (:func:`prediction_check`) compare
like with like (docs/physics.md §8): the K boundary is read only in cells below both
spring-swing limits of their K (:func:`spine_mj.theory.drive_limits.spring_ie_limits`: the
swing within the path tolerance, its force within F_p), each K at its lowest such I_e, and
set beside ``K_path``, the boundary the same criterion draws between the compliant-drive
and the rigid paths; the I_e* at the stiffest K is set beside the lowest of the geometry's
thresholds and that K's swing limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy import stats

from spine_mj.theory.drive_limits import spring_ie_limits
from spine_mj.theory.path_stiffness import PATH_STIFFNESS_RESOLUTION
from spine_mj.validate.intervals import CONFIDENCE

__all__ = [
    "FRECHET_FLOOR_LC",
    "PREDICTED_ORDERS",
    "PREDICTION_FACTOR",
    "bracket_ratio",
    "common_lowest_ie",
    "fit_order",
    "gap_series",
    "k_boundary",
    "k_path_term",
    "k_readings",
    "order_rows",
    "outside_factor",
    "prediction_check",
    "within_factor",
]

#: Orders the theory predicts (docs/physics.md §10): axis -> order of the gap.
PREDICTED_ORDERS = {"ie": 1.0, "inverse_k": 1.0}

#: The median Frechet distance's resolution in L_c: :func:`spine_mj.theory.agreement.path_frechet`
#: resamples both paths at L_c / 50, and the discrete distance resolves half a sample (the
#: corner's medians sit at 0.010 on every family where the paths coincide).
FRECHET_FLOOR_LC = 0.01

#: How far a predicted limit may lie from the measured one (the issue's factor of 2).
PREDICTION_FACTOR = 2.0


def fit_order(x: Sequence[float], gap: Sequence[float], *, floor: float = 0.0) -> dict:
    """The order of ``gap`` in ``x``: the least-squares slope of ``log gap`` against
    ``log x`` over the points with ``x > 0`` and ``gap > floor``, with its 95 % t interval.

    Returns
    -------
    dict
        ``order``, ``ci_low``, ``ci_high``, ``n`` (points fitted), ``x_fitted`` and
        ``gap_fitted`` (those points); NaN order with fewer than two points, NaN interval
        with fewer than three.
    """
    x = np.asarray(x, dtype=float)
    g = np.asarray(gap, dtype=float)
    keep = np.isfinite(x) & np.isfinite(g) & (x > 0) & (g > floor) & (g > 0)
    lx, lg = np.log(x[keep]), np.log(g[keep])
    out = {
        "order": math.nan,
        "ci_low": math.nan,
        "ci_high": math.nan,
        "n": int(keep.sum()),
        "x_fitted": x[keep].tolist(),
        "gap_fitted": g[keep].tolist(),
    }
    if lx.size < 2 or np.ptp(lx) == 0:
        return out
    fit = stats.linregress(lx, lg)
    out["order"] = float(fit.slope)
    if lx.size >= 3:
        t = stats.t.ppf(0.5 + CONFIDENCE / 2, lx.size - 2)
        out["ci_low"] = float(fit.slope - t * fit.stderr)
        out["ci_high"] = float(fit.slope + t * fit.stderr)
    return out


def common_lowest_ie(cells: dict) -> float:
    """The lowest I_e every K cell has (a deeper one of the stiffest K left out)."""
    return max(min(c["ie"]) for c in cells.values())


def gap_series(cells: dict, k_star: float) -> dict:
    """A family's two gap series from its map ``cells`` (K (str) -> cell): ``ie`` at the
    stiffest K and ``inverse_k`` (x = 1/K) at the lowest common I_e over K >= ``k_star``;
    each ``{"x", "agreement_gap", "median_frechet", "at"}`` (``at``: the fixed K or I_e)."""
    ks = sorted(cells, key=float)
    top = cells[ks[-1]]
    low = common_lowest_ie(cells)
    above = [k for k in ks if not (math.isfinite(k_star) and float(k) < k_star)]
    idx = [cells[k]["ie"].index(low) for k in above]
    return {
        "ie": {
            "x": list(top["ie"]),
            "agreement_gap": [1.0 - a for a in top["agreement"]],
            "median_frechet": list(top["median_frechet"]),
            "at": float(ks[-1]),
        },
        "inverse_k": {
            "x": [1.0 / float(k) for k in above],
            "agreement_gap": [1.0 - cells[k]["agreement"][i] for k, i in zip(above, idx)],
            "median_frechet": [cells[k]["median_frechet"][i] for k, i in zip(above, idx)],
            "at": low,
        },
    }


def order_rows(agreement: dict, predicted: dict) -> list[dict]:
    """Per family, axis (``ie``, ``inverse_k``) and gap (``agreement_gap``,
    ``median_frechet``): the fitted order (:func:`fit_order`), the predicted one
    (:data:`PREDICTED_ORDERS`), and ``consistent``: the interval holds it (None without an
    interval)."""
    rows = []
    for fam, cells in agreement.items():
        k_star = float(predicted.get(fam, {}).get("k_star", math.nan))
        for axis, series in gap_series(cells, k_star).items():
            for gap in ("agreement_gap", "median_frechet"):
                floor = 2 * FRECHET_FLOOR_LC if gap == "median_frechet" else 0.0
                fit = fit_order(series["x"], series[gap], floor=floor)
                lo, hi = fit["ci_low"], fit["ci_high"]
                p = PREDICTED_ORDERS[axis]
                rows.append(
                    {
                        "family": fam,
                        "axis": axis,
                        "gap": gap,
                        "at": series["at"],
                        "predicted": p,
                        **fit,
                        "consistent": bool(lo <= p <= hi)
                        if math.isfinite(lo) and math.isfinite(hi)
                        else None,
                        "all_x": series["x"],
                        "all_gap": series[gap],
                    }
                )
    return rows


def k_readings(cells: dict, lc_over_ls: float = math.nan) -> dict:
    """Where each K of a family's map is read for the K boundary: K (str) -> the index of
    its lowest I_e below both its spring-swing limits
    (:func:`spine_mj.theory.drive_limits.spring_ie_limits`) and at or below the highest of
    those I_e at which the stiffest K so read passes, None where it has none; without a
    finite ``lc_over_ls``, every K at the lowest I_e all of them ran at, as long as the
    stiffest passes there.

    A K fails for its spring only where a stiffer one passes at the same pace: at an I_e
    where the stiffest spring fails too, the tip's inertia fails them all (measured on the
    fractal: every K from 2.9 to 1000 failed at I_e 1e-4, K 14 to 100 passed at 1e-6), and
    no K is read there."""
    if not (math.isfinite(lc_over_ls) and lc_over_ls > 0):
        low = common_lowest_ie(cells)
        quiet = {k: [cells[k]["ie"].index(low)] for k in cells}
    else:
        quiet = {}
        for k, c in cells.items():
            top = min(spring_ie_limits(float(k), lc_over_ls).values())
            quiet[k] = [i for i, ie in enumerate(c["ie"]) if ie <= top]
    read = [k for k in cells if quiet[k]]
    if not read:
        return dict.fromkeys(cells)
    stiffest = cells[max(read, key=float)]
    passing = [stiffest["ie"][i] for i in quiet[max(read, key=float)] if stiffest["passes"][i]]
    ceiling = max(passing, default=-math.inf)
    out = {}
    for k, c in cells.items():
        ok = [i for i in quiet[k] if c["ie"][i] <= ceiling]
        out[k] = min(ok, key=lambda i: c["ie"][i]) if ok else None
    return out


def k_boundary(cells: dict, lc_over_ls: float = math.nan) -> tuple[float, float]:
    """The measured K boundary of a family's map over the K read (:func:`k_readings`):
    ``(low, high)``, the largest K that fails the criterion and the next K read, which
    passes (``(nan, K_min)`` when the smallest passes, ``(nan, nan)`` when no K is read: the
    stiffest fails wherever its swing is small)."""
    read = k_readings(cells, lc_over_ls)
    ks = sorted((k for k, i in read.items() if i is not None), key=float)
    if not ks:
        return math.nan, math.nan
    passes = [bool(cells[k]["passes"][read[k]]) for k in ks]
    fails = [i for i, p in enumerate(passes) if not p]
    if not fails:
        return math.nan, float(ks[0])
    last = max(fails)
    if last + 1 >= len(ks):
        return float(ks[-1]), math.inf
    return float(ks[last]), float(ks[last + 1])


def within_factor(predicted: float, low: float, high: float, factor: float = PREDICTION_FACTOR) -> str:
    """How a predicted limit compares with a measured bracket ``[low, high]`` (NaN low: at or
    below ``high``; infinite high: above ``low``): ``within`` where the whole bracket lies
    within ``factor`` of it, ``consistent`` where they overlap (the bracket is wider than
    the factor allows to decide), ``outside`` otherwise, ``-`` without a prediction."""
    if not (math.isfinite(predicted) and predicted > 0):
        return "-"
    a, b = predicted / factor, predicted * factor
    lo = low if math.isfinite(low) else 0.0
    if a <= lo and high <= b:
        return "within"
    if lo <= b and high >= a:
        return "consistent"
    return "outside"


def outside_factor(predicted: float, low: float, high: float) -> float:
    """How far a predicted limit lies outside a measured bracket ``[low, high]`` (NaN low: 0,
    infinite high: unbounded), as a factor: 1 inside it, else the nearer end over the
    prediction or the prediction over it; NaN without a positive prediction."""
    if not (math.isfinite(predicted) and predicted > 0):
        return math.nan
    lo = low if math.isfinite(low) else 0.0
    if predicted < lo:
        return lo / predicted
    if predicted > high:
        return predicted / high
    return 1.0


def k_path_term(k_path: float, k_endless: float) -> str:
    """What sets a family's ``K_path``: ``"carriage travel"`` where it lies above the
    endless carriage's by more than the search's resolution (the runs stop short of a hold),
    ``"folds"`` otherwise, ``"-"`` without both."""
    if not (math.isfinite(k_path) and math.isfinite(k_endless)):
        return "-"
    return "carriage travel" if k_path > k_endless * PATH_STIFFNESS_RESOLUTION else "folds"


def bracket_ratio(low: float, high: float) -> float:
    """``high / low`` of a measured bracket (inf where either end is open): where it exceeds
    :data:`PREDICTION_FACTOR` squared no prediction can be *within* the factor of all of it."""
    return high / low if math.isfinite(low) and low > 0 and math.isfinite(high) else math.inf


def prediction_check(agreement: dict, predicted: dict) -> list[dict]:
    """Per family: the predicted K boundary against the measured one, and the predicted I_e*
    at the stiffest K against the measured one there, each with :func:`within_factor`.

    The K boundary is read where the spring's swing is small and the stiffest K passes
    (:func:`k_boundary` with the family's ``lc_over_ls``; ``k_read_ie``: K -> the I_e read,
    None: not read) and set beside ``K_path`` (``k_verdict``: the prediction, with the
    carriage travel of the map's runs), beside the fold ``K*`` (``k_verdict_fold``) and
    beside ``K_path`` with an endless carriage (``k_verdict_endless``; ``k_path_set_by``:
    :func:`k_path_term`), each with
    :func:`outside_factor` (``k_factor``...) and the bracket's own width
    (:func:`bracket_ratio`: above 4 a factor of 2 cannot be decided). The
    I_e* predicted at the stiffest K is the lowest of the geometry's (lift-off, trap, lag)
    and that K's swing limits (:func:`~spine_mj.theory.drive_limits.spring_ie_limits`);
    ``ie_limit`` names it."""
    rows = []
    for fam, cells in agreement.items():
        pred = predicted.get(fam, {})
        k_fold = float(pred.get("k_star", math.nan))
        k_path = float(pred.get("k_path", math.nan))
        k_endless = float(pred.get("k_path_endless", math.nan))
        ratio = float(pred.get("lc_over_ls", math.nan))
        k_lo, k_hi = k_boundary(cells, ratio)
        read = k_readings(cells, ratio)
        k_top = max(cells, key=float)
        ie_geometry = float(pred.get("ie_star", math.nan))
        limits = {pred.get("limit", ""): ie_geometry, **spring_ie_limits(float(k_top), ratio)}
        limit = min(limits, key=lambda n: limits[n] if math.isfinite(limits[n]) else math.inf)
        ie_pred = limits[limit]
        top = cells[k_top]["ie_star"]
        kind = top.get("kind")
        if kind == "bracketed":
            ie_lo, ie_hi = float(top["low"]), float(top["high"])
        elif kind == "above":  # holds over the whole grid: I_e* above its top
            ie_lo, ie_hi = float(top.get("low", math.nan)), math.inf
        elif kind == "below":  # fails at the lowest I_e already
            ie_lo, ie_hi = math.nan, float(top.get("high", math.nan))
        else:
            ie_lo, ie_hi = math.nan, math.nan
        measured = math.isfinite(k_lo) or math.isfinite(k_hi)
        rows.append(
            {
                "family": fam,
                "k_star_predicted": k_fold,
                "k_path_predicted": k_path,
                "lc_over_ls": ratio,
                "k_read_ie": {k: (cells[k]["ie"][i] if i is not None else None) for k, i in read.items()},
                "k_low": k_lo,
                "k_high": k_hi,
                "k_path_endless": k_endless,
                "k_path_set_by": k_path_term(k_path, k_endless),
                "k_bracket_ratio": bracket_ratio(k_lo, k_hi),
                "k_verdict": within_factor(k_path, k_lo, k_hi) if measured else "not measured",
                "k_factor": outside_factor(k_path, k_lo, k_hi) if measured else math.nan,
                "k_verdict_fold": within_factor(k_fold, k_lo, k_hi) if measured else "not measured",
                "k_factor_fold": outside_factor(k_fold, k_lo, k_hi) if measured else math.nan,
                "k_verdict_endless": within_factor(k_endless, k_lo, k_hi) if measured else "not measured",
                "ie_star_predicted": ie_pred,
                "ie_star_geometry": ie_geometry,
                "ie_swing_path": limits["swing-path"],
                "ie_swing_force": limits["swing-force"],
                "ie_limit": limit,
                "ie_low": ie_lo,
                "ie_high": ie_hi,
                "ie_at_k": float(k_top),
                "ie_bracket_ratio": bracket_ratio(ie_lo, ie_hi),
                "ie_verdict": within_factor(ie_pred, ie_lo, ie_hi)
                if math.isfinite(ie_lo) or math.isfinite(ie_hi)
                else "not measured",
                "ie_factor": outside_factor(ie_pred, ie_lo, ie_hi),
            }
        )
    return rows
