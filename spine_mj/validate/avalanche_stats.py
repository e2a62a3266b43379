"""Statistics of slip events (docs/physics.md §12): power laws fitted and tested as
Clauset, Shalizi and Newman (SIAM Rev. 51, 661 (2009)) prescribe, never by a line on a log
plot.

* :func:`power_law_fit`: the maximum-likelihood exponent of a pure power law above a lower
  cutoff ``x_min`` chosen by Kolmogorov-Smirnov distance (:func:`~spine_mj.validate.slip_tails.xmin_by_ks`),
  with its standard error ``(alpha - 1) / sqrt(n)``;
* :func:`truncated_fit`: the maximum-likelihood ``(tau, lambda)`` of
  ``p(s) ~ s^-tau exp(-lambda s)`` above ``x_min`` (the ABBM law with
  ``lambda = 1 / (4 S_m)``), with intervals from the observed information;
* :func:`goodness_of_fit`: the parametric bootstrap's p-value of the pure power law (reject
  at p <= 0.1);
* :func:`likelihood_ratios`: the normalized log-likelihood ratios of the power law against
  the lognormal, exponential and truncated power law, with their p-values (the
  ``powerlaw`` package, an install requirement);
* :func:`cutoff_size`: ``S_m = <S^2> / (2 <S>)`` with a bootstrap interval;
* :func:`collapse`: ``s^tau P(s)`` against ``s / S_m`` in log bins, for several series;
* :func:`two_sample`: Kolmogorov-Smirnov and Anderson-Darling tests between two samples.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import numpy as np

from spine_mj.validate.slip_tails import MIN_TAIL, xmin_by_ks

__all__ = [
    "collapse",
    "cutoff_size",
    "goodness_of_fit",
    "likelihood_ratios",
    "power_law_fit",
    "summarize_sizes",
    "truncated_fit",
    "truncated_fit_by_ks",
    "two_sample",
]

#: Two-sided normal quantile of the 95 % intervals.
Z95 = 1.959963984540054
#: Reject a power law when the bootstrap's p-value is at or below this (CSN's rule).
GOF_REJECT_P = 0.1


def _positive(x) -> np.ndarray:
    x = np.asarray(x, float).ravel()
    return np.sort(x[np.isfinite(x) & (x > 0)])


def _alpha(tail: np.ndarray, xmin: float) -> float:
    return 1.0 + tail.size / np.log(tail / xmin).sum()


def _ks(tail: np.ndarray, xmin: float, alpha: float) -> float:
    n = tail.size
    model = 1.0 - (tail / xmin) ** (1.0 - alpha)
    return float(max(np.abs(np.arange(n) / n - model).max(), np.abs(np.arange(1, n + 1) / n - model).max()))


def power_law_fit(x, xmin: float | None = None) -> dict:
    """The pure power law ``p(x) ~ x^-alpha`` above ``xmin`` (default: by KS distance).

    Returns ``alpha``, ``low``, ``high`` (95 %), ``xmin``, ``n_tail`` and ``ks`` (the
    distance between the tail and the fitted law)."""
    xs = _positive(x)
    if xmin is None:
        xmin = xmin_by_ks(xs)
    tail = xs[xs >= xmin]
    alpha = _alpha(tail, xmin)
    se = (alpha - 1.0) / math.sqrt(tail.size)
    return {
        "alpha": float(alpha),
        "low": float(alpha - Z95 * se),
        "high": float(alpha + Z95 * se),
        "xmin": float(xmin),
        "n_tail": int(tail.size),
        "ks": _ks(tail, xmin, alpha),
    }


_LEGENDRE = np.polynomial.legendre.leggauss(200)


def _log_norm(tau: float, lam: float, xmin):
    """``ln int_xmin^inf s^-tau exp(-lam s) ds`` for each ``xmin`` (by ``s = xmin e^t``,
    200-point Gauss-Legendre over the range where the integrand exceeds 1e-17 of its start)."""
    x0 = np.atleast_1d(np.asarray(xmin, float))
    a = x0 * lam
    t_end = np.maximum(np.log(np.maximum(40.0 / a, 1.0)) + 1.0, 1.0)[:, None]
    nodes, weights = _LEGENDRE
    t = 0.5 * t_end * (nodes + 1.0)
    expo = (1.0 - tau) * t - a[:, None] * np.exp(t)
    m = expo.max(axis=1)
    val = 0.5 * t_end[:, 0] * np.sum(weights * np.exp(expo - m[:, None]), axis=1)
    out = (1.0 - tau) * np.log(x0) + m + np.log(val)
    return out if np.ndim(xmin) else float(out[0])


def _truncated_ks(tail: np.ndarray, xmin: float, tau: float, lam: float) -> float:
    n = tail.size
    # the CDF is smooth in ln s: 256 exact points and linear interpolation between them
    knots = np.geomspace(tail[0], tail[-1], 256)
    ccdf = np.exp(_log_norm(tau, lam, knots) - _log_norm(tau, lam, xmin))
    model = 1.0 - np.interp(np.log(tail), np.log(knots), ccdf)
    return float(max(np.abs(np.arange(n) / n - model).max(), np.abs(np.arange(1, n + 1) / n - model).max()))


def _truncated_nll(params, tail: np.ndarray, xmin: float, sum_log: float, total: float) -> float:
    tau, log_lam = params
    lam = math.exp(log_lam)
    return tau * sum_log + lam * total + tail.size * _log_norm(tau, lam, xmin)


def truncated_fit(x, xmin: float) -> dict:
    """The maximum-likelihood ``p(s) ~ s^-tau exp(-lambda s)`` for ``s >= xmin``.

    Returns ``tau``, ``low``, ``high`` (95 %, from the observed information, the inverse
    Hessian of the negative log-likelihood in ``(tau, ln lambda)``), ``lam`` and
    ``loglik``. ``tau`` may lie below 1 (the cutoff normalizes)."""
    from scipy.optimize import minimize

    xs = _positive(x)
    tail = xs[xs >= xmin]
    if tail.size < MIN_TAIL:
        raise ValueError(f"truncated_fit needs at least {MIN_TAIL} values >= xmin, got {tail.size}")
    sum_log, total = float(np.log(tail).sum()), float(tail.sum())
    start = (1.5, math.log(1.0 / tail.mean()))
    args = (tail, xmin, sum_log, total)
    res = minimize(
        _truncated_nll, start, args=args, method="Nelder-Mead", options={"xatol": 1e-7, "fatol": 1e-9}
    )
    tau, log_lam = res.x
    h = np.zeros((2, 2))
    eps = (1e-3, 1e-3)
    f0 = _truncated_nll(res.x, *args)
    for i in range(2):
        for j in range(2):
            ei, ej = np.eye(2)[i] * eps[i], np.eye(2)[j] * eps[j]
            h[i, j] = (
                _truncated_nll(res.x + ei + ej, *args)
                - _truncated_nll(res.x + ei - ej, *args)
                - _truncated_nll(res.x - ei + ej, *args)
                + _truncated_nll(res.x - ei - ej, *args)
            ) / (4 * eps[i] * eps[j])
    try:
        se = math.sqrt(float(np.linalg.inv(h)[0, 0]))
    except (np.linalg.LinAlgError, ValueError):
        se = math.nan
    return {
        "ks": _truncated_ks(tail, xmin, tau, math.exp(log_lam)),
        "tau": float(tau),
        "low": float(tau - Z95 * se),
        "high": float(tau + Z95 * se),
        "lam": float(math.exp(log_lam)),
        "loglik": float(-f0),
        "xmin": float(xmin),
        "n_tail": int(tail.size),
    }


def truncated_fit_by_ks(x, candidates: int = 12, xmin_floor: float = 0.0) -> dict:
    """:func:`truncated_fit` above the ``xmin`` whose fitted law lies closest to the data in
    KS distance, over ``candidates`` quantiles from the smallest value at least
    ``xmin_floor`` to the one that keeps :data:`~spine_mj.validate.slip_tails.MIN_TAIL`
    values (the truncated law's own cutoff rule: a pure power law's would push ``xmin``
    into the exponential tail). ``xmin_floor``: where the law is known to start, below which
    no ``xmin`` is tried (an ABBM track's :func:`~spine_mj.surfaces.abbm_smallest_slip`);
    fewer than ``4 MIN_TAIL`` values above it leave the floor out."""
    xs = _positive(x)
    above = xs[xs >= xmin_floor] if np.count_nonzero(xs >= xmin_floor) >= 4 * MIN_TAIL else xs
    grid = np.unique(np.quantile(above[: above.size - 4 * MIN_TAIL + 1], np.linspace(0.0, 1.0, candidates)))
    fits = [truncated_fit(xs, float(xmin)) for xmin in grid]
    return min(fits, key=lambda f: f["ks"])


def goodness_of_fit(
    x, n_bootstrap: int = 100, rng: int | np.random.Generator = 0, xmin: float | None = None
) -> dict:
    """CSN's parametric bootstrap of the pure power law: synthetic samples of the same size
    (the body resampled below ``xmin``, the fitted power law above it), each refitted with
    its own ``xmin`` (or at the given ``xmin``); ``p`` is the share whose KS distance is at
    least the data's. A free ``xmin`` may retreat into the far tail of any distribution,
    where few points look like a steep power law: the test then judges that tail only.

    Returns ``p``, ``ks``, ``n_bootstrap`` and ``rejected`` (``p <= 0.1``)."""
    gen = np.random.default_rng(rng)
    xs = _positive(x)
    fixed = xmin
    fit = power_law_fit(xs, fixed)
    xmin, alpha = fit["xmin"], fit["alpha"]
    body = xs[xs < xmin]
    p_tail = fit["n_tail"] / xs.size
    worse = 0
    for _ in range(n_bootstrap):
        n_tail = gen.binomial(xs.size, p_tail)
        synth_tail = xmin * (1.0 - gen.random(n_tail)) ** (-1.0 / (alpha - 1.0))
        synth_body = gen.choice(body, xs.size - n_tail) if body.size else np.empty(0)
        synth = np.concatenate([synth_body, synth_tail])
        if power_law_fit(synth, fixed)["ks"] >= fit["ks"]:
            worse += 1
    p = worse / n_bootstrap
    return {"p": p, "ks": fit["ks"], "n_bootstrap": int(n_bootstrap), "rejected": bool(p <= GOF_REJECT_P)}


def likelihood_ratios(x, xmin: float) -> dict:
    """The power law above ``xmin`` against each alternative: ``{name: {"R", "p"}}``,
    ``R`` positive where the power law fits better. Lognormal and exponential (not nested):
    ``R`` the normalized log-likelihood ratio and ``p`` Vuong's two-sided significance, from
    ``powerlaw``. The truncated power law (nested: the power law is its ``lambda = 0``):
    ``R`` the log-likelihood ratio and ``p`` from chi-squared with one degree of freedom
    of ``-2 R`` (CSN's rule for nested models), the truncated fit by :func:`truncated_fit`
    (``powerlaw``'s takes seconds where this takes milliseconds; they agree, tested)."""
    import powerlaw
    from scipy import stats

    xs = _positive(x)
    out = {}
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        fit = powerlaw.Fit(xs, xmin=xmin, parameter_ranges={"alpha": (1.0, 20.0)}, verbose=False)
        for name in ("lognormal", "exponential"):
            r, p = fit.distribution_compare("power_law", name, normalized_ratio=True)
            out[name] = {"R": float(r), "p": float(p)}
    tail = xs[xs >= xmin]
    alpha = _alpha(tail, xmin)
    ll_pl = tail.size * math.log((alpha - 1.0) / xmin) - alpha * float(np.log(tail / xmin).sum())
    r = min(ll_pl - truncated_fit(xs, xmin)["loglik"], 0.0)
    out["truncated_power_law"] = {"R": float(r), "p": float(stats.chi2.sf(-2.0 * r, 1))}
    return out


def cutoff_size(sizes, n_bootstrap: int = 200, rng: int | np.random.Generator = 0) -> dict:
    """``S_m = <S^2> / (2 <S>)`` (``sigma / k^2`` for ABBM) with a 95 % percentile
    bootstrap interval: ``value``, ``low``, ``high``."""
    s = _positive(sizes)
    gen = np.random.default_rng(rng)
    value = float(np.mean(s * s) / (2 * np.mean(s)))
    idx = gen.integers(0, s.size, (n_bootstrap, s.size))
    boot = np.mean(s[idx] ** 2, axis=1) / (2 * np.mean(s[idx], axis=1))
    lo, hi = np.quantile(boot, [0.025, 0.975])
    return {"value": value, "low": float(lo), "high": float(hi)}


def collapse(series: dict, tau: float, bins_per_decade: int = 6) -> dict:
    """``s^tau P(s)`` against ``s / S_m`` for each series (``{label: sizes}``) in log bins:
    ``{label: (s / S_m, s^tau P(s))}``. Where ``P(s) = s^-tau F(s / S_m)`` the curves lie
    on one, ``F``."""
    out = {}
    for label, sizes in series.items():
        s = _positive(sizes)
        sm = float(np.mean(s * s) / (2 * np.mean(s)))
        decades = math.log10(s[-1] / s[0])
        edges = np.logspace(
            math.log10(s[0]), math.log10(s[-1]) + 1e-9, max(int(bins_per_decade * decades), 1) + 1
        )
        counts, _ = np.histogram(s, edges)
        centres = np.sqrt(edges[1:] * edges[:-1])
        density = counts / (np.diff(edges) * s.size)
        keep = counts > 0
        out[label] = (centres[keep] / sm, centres[keep] ** tau * density[keep])
    return out


def two_sample(a, b) -> dict:
    """Kolmogorov-Smirnov and Anderson-Darling two-sample tests: ``ks``, ``ks_p``, ``ad``,
    ``ad_p`` (scipy; the AD p-value is capped to [0.001, 0.25] by its table), and
    ``agree`` (both p-values above 0.05)."""
    from scipy import stats

    a, b = _positive(a), _positive(b)
    ks = stats.ks_2samp(a, b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ad = stats.anderson_ksamp([a, b])
    ad_p = float(getattr(ad, "pvalue", getattr(ad, "significance_level", math.nan)))
    return {
        "ks": float(ks.statistic),
        "ks_p": float(ks.pvalue),
        "ad": float(ad.statistic),
        "ad_p": ad_p,
        "agree": bool(ks.pvalue > 0.05 and ad_p > 0.05),
    }


def summarize_sizes(sizes, n_bootstrap: int = 100, rng: int = 0, xmin_floor: float = 0.0) -> dict:
    """Every statistic of one series of sizes: ``n_events``, ``tau`` (the truncated power
    law's, ``{value, low, high}``, its ``xmin`` at least ``xmin_floor``:
    :func:`truncated_fit_by_ks`), ``alpha`` (the pure power law's), ``cutoff`` (``S_m``),
    ``xmin``, ``gof`` and ``likelihood_ratios``; ``n_events`` alone below
    :data:`~spine_mj.validate.slip_tails.MIN_EVENTS` events."""
    from spine_mj.validate.slip_tails import MIN_EVENTS

    s = _positive(sizes)
    out: dict = {"n_events": int(s.size)}
    if s.size < MIN_EVENTS or np.unique(s).size < 10:
        return out
    pl = power_law_fit(s)
    tr = truncated_fit_by_ks(s, xmin_floor=xmin_floor)
    out.update(
        tau={"value": tr["tau"], "low": tr["low"], "high": tr["high"]},
        alpha={"value": pl["alpha"], "low": pl["low"], "high": pl["high"]},
        cutoff=cutoff_size(s, rng=rng),
        xmin=pl["xmin"],
        n_tail=pl["n_tail"],
        tau_xmin=tr["xmin"],
        tau_n_tail=tr["n_tail"],
        gof=goodness_of_fit(s, n_bootstrap=n_bootstrap, rng=rng),
        likelihood_ratios=likelihood_ratios(s, pl["xmin"]),
    )
    return out
