"""Maximum-likelihood fits of the tails of slip-size and force-drop distributions.

Slip sizes of a particle pulled through a random landscape follow ``S^-3/2`` up to a
cutoff in the ABBM model (docs/physics.md); with short-range correlated slopes there is no
universal exponent. A tail is fitted here by maximum likelihood (the ``powerlaw`` package:
Clauset, Shalizi and Newman's estimator, ``xmin`` chosen by the Kolmogorov-Smirnov
distance), with a 95 % interval on the exponent and a likelihood-ratio test against an
exponential tail, never by a straight line on a log plot. A series with fewer than
:data:`MIN_EVENTS` events is not fitted.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import numpy as np

__all__ = ["MIN_EVENTS", "fit_tail"]

#: Fewest slip events a series needs for a tail fit.
MIN_EVENTS = 200


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
        fit = powerlaw.Fit(x, verbose=False)
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
