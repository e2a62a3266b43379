"""Tail fits: the maximum-likelihood exponent of a known power law, and the size rule."""

import warnings

import numpy as np
import pytest

from spine_mj.validate.slip_tails import MIN_EVENTS, fit_tail


def test_fit_recovers_the_abbm_exponent_of_a_pareto_sample():
    rng = np.random.default_rng(3)
    x = (1 - rng.random(2000)) ** (-1 / 0.5)  # p(S) ~ S^-3/2 above 1, the ABBM exponent
    fit = fit_tail(x)
    assert fit["fitted"] and fit["ci_low"] < 1.5 < fit["ci_high"]
    assert fit["alpha"] == pytest.approx(1.5, abs=0.1) and fit["loglik_ratio_vs_exponential"] > 0


def test_too_few_events_are_not_fitted():
    assert fit_tail(np.arange(1.0, MIN_EVENTS)) == {"n": MIN_EVENTS - 1, "fitted": False}


def test_the_tail_cutoff_is_found_where_a_uniform_body_meets_a_pareto_tail():
    # uniform on [0.1, 1) below, p(S) ~ S^-2 above 1: the KS rule picks a cutoff near 1
    from spine_mj.validate.slip_tails import xmin_by_ks

    rng = np.random.default_rng(5)
    x = np.concatenate([rng.uniform(0.1, 1.0, 1500), (1 - rng.random(1500)) ** -1.0])
    assert 0.8 <= xmin_by_ks(x) <= 1.3
    fit = fit_tail(x)
    assert fit["ci_low"] < 2.0 < fit["ci_high"]


def test_the_quantile_search_agrees_with_the_packages_search_over_every_value():
    # the package's own xmin search (every distinct value, O(n^2) fits) as the slow reference
    import powerlaw

    rng = np.random.default_rng(11)
    x = np.concatenate([rng.uniform(0.2, 1.0, 150), (1 - rng.random(250)) ** (-1 / 0.7)])
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        ref = powerlaw.Fit(x, verbose=False)
    fit = fit_tail(x)
    assert fit["alpha"] == pytest.approx(float(ref.power_law.alpha), abs=0.15)


def test_a_steep_tail_is_not_pinned_at_the_packages_default_bound_of_3():
    rng = np.random.default_rng(1)
    x = (1 - rng.random(3000)) ** (-1 / 3.0)  # p(S) ~ S^-4
    fit = fit_tail(x)
    assert fit["ci_low"] < 4.0 < fit["ci_high"]
