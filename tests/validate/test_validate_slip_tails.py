"""Tail fits: the maximum-likelihood exponent of a known power law, and the size rule."""

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
