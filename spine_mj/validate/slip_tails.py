"""Maximum-likelihood fits of the tails of slip-size and force-drop distributions.

Slip sizes of a particle pulled through a random landscape follow ``S^-3/2`` up to a
cutoff in the ABBM model (docs/physics.md); with short-range correlated slopes there is no
universal exponent. A tail is fitted here by maximum likelihood (the ``powerlaw`` package:
Clauset, Shalizi and Newman's estimator, ``xmin`` chosen by the Kolmogorov-Smirnov
distance over :data:`XMIN_CANDIDATES` quantiles of the series: the package's own search
fits every distinct value, O(n^2), which took hours on the full map's series of 10^4
events), with a 95 % interval on the exponent and a likelihood-ratio test against an
exponential tail, never by a straight line on a log plot. A series with fewer than
:data:`MIN_EVENTS` events is not fitted.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import numpy as np

__all__ = ["MIN_EVENTS", "fit_tail", "xmin_by_ks"]

#: Fewest slip events a series needs for a tail fit.
MIN_EVENTS = 200
#: Candidate lower cutoffs of the tail: this many quantiles of the series.
XMIN_CANDIDATES = 64
#: Fewest events a candidate tail keeps.
MIN_TAIL = 50
#: The exponents a fit may return (the density's ``alpha``).
ALPHA_RANGE = (1.0, 20.0)


def xmin_by_ks(x: np.ndarray) -> float:
    """The lower cutoff of a power-law tail of ``x`` (positive, finite): the candidate whose
    maximum-likelihood power law, ``alpha = 1 + n / sum(ln(x / xmin))``, lies closest to the
    tail's empirical distribution in Kolmogorov-Smirnov distance (Clauset, Shalizi and
    Newman's rule), over :data:`XMIN_CANDIDATES` quantiles keeping at least
    :data:`MIN_TAIL` events."""
    xs = np.sort(np.asarray(x, dtype=float))
    candidates = np.unique(np.quantile(xs[: xs.size - MIN_TAIL + 1], np.linspace(0.0, 1.0, XMIN_CANDIDATES)))
    best, best_d = float(xs[0]), math.inf
    for xmin in candidates:
        tail = xs[xs >= xmin]
        n = tail.size
        logs = np.log(tail / xmin).sum()
        if n < MIN_TAIL or logs <= 0:
            continue
        alpha = 1.0 + n / logs
        model = 1.0 - (tail / xmin) ** (1.0 - alpha)
        d = max(np.abs(np.arange(n) / n - model).max(), np.abs(np.arange(1, n + 1) / n - model).max())
        if d < best_d:
            best, best_d = float(xmin), d
    return best


def fit_tail(samples) -> dict:
    """The power-law tail of the positive finite ``samples``.

    Returns
    -------
    dict
        ``n`` (events), ``fitted``; when fitted also ``alpha`` (the density's exponent,
        ``p(S) ~ S^-alpha``; the CCDF falls as ``S^(1 - alpha)``), ``ci_low``/``ci_high``
        (``alpha -/+ 1.96 sigma``), ``xmin``, ``n_tail``, ``loglik_ratio_vs_exponential``
        and its ``p_vs_exponential`` (positive ratio with small p: the power law fits better).
    """
    x = np.asarray(samples, dtype=float).ravel()
    x = x[np.isfinite(x) & (x > 0)]
    out = {"n": int(x.size), "fitted": False}
    if x.size < MIN_EVENTS or np.unique(x).size < 10:
        return out
    import powerlaw

    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        # the package bounds alpha to [0, 3] by default, which pins steep tails at 3
        fit = powerlaw.Fit(x, xmin=xmin_by_ks(x), parameter_ranges={"alpha": ALPHA_RANGE}, verbose=False)
        pl = fit.power_law
        ratio, p = fit.distribution_compare("power_law", "exponential", normalized_ratio=True)
    alpha, sigma = float(pl.alpha), float(pl.standard_err)
    out.update(
        fitted=math.isfinite(alpha),
        alpha=alpha,
        ci_low=alpha - 1.96 * sigma,
        ci_high=alpha + 1.96 * sigma,
        xmin=float(fit.xmin),
        n_tail=int((x >= fit.xmin).sum()),
        loglik_ratio_vs_exponential=float(ratio),
        p_vs_exponential=float(p),
    )
    return out
