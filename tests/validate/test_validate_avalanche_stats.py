"""The event statistics on samples drawn from known distributions: exponents inside their
intervals, the bootstrap keeping a true power law and rejecting an exponential, the
likelihood ratios picking the law that made the data, S_m's closed form, the collapse and
the two-sample tests."""

import math

import numpy as np
import pytest

from spine_mj.validate import avalanche_stats as st


def _power_law(n, alpha, xmin, rng):
    return xmin * (1 - rng.random(n)) ** (-1 / (alpha - 1))


def _truncated(n, tau, lam, xmin, rng):
    """Rejection from the power law: keep with probability exp(-lam (s - xmin))."""
    out = np.empty(0)
    while out.size < n:
        s = _power_law(4 * n, tau, xmin, rng) if tau > 1 else xmin + rng.exponential(1 / lam, 4 * n)
        out = np.concatenate([out, s[rng.random(s.size) < np.exp(-lam * (s - xmin))]])
    return out[:n]


@pytest.mark.parametrize("alpha", [1.5, 2.5])
def test_power_law_fit_recovers_the_exponent_and_the_lower_cutoff(alpha):
    rng = np.random.default_rng(2)
    body = rng.uniform(0.0, 1.0, 1000)  # no power law below 1
    x = np.concatenate([body, _power_law(4000, alpha, 1.0, rng)])
    fit = st.power_law_fit(x)
    assert fit["low"] <= alpha <= fit["high"]
    assert 0.7 < fit["xmin"] < 1.5


def test_truncated_fit_recovers_tau_and_lambda_and_agrees_with_powerlaw():
    import powerlaw

    rng = np.random.default_rng(3)
    x = _truncated(4000, 1.5, 0.02, 1.0, rng)
    fit = st.truncated_fit(x, 1.0)
    assert fit["low"] <= 1.5 <= fit["high"]
    assert fit["high"] - fit["low"] < 0.15
    assert fit["lam"] == pytest.approx(0.02, rel=0.3)
    small = x[:600]
    mine = st.truncated_fit(small, 1.0)
    ref = powerlaw.Fit(small, xmin=1.0, verbose=False).truncated_power_law  # the slow reference
    assert mine["tau"] == pytest.approx(ref.alpha, abs=2e-3)
    assert mine["lam"] == pytest.approx(ref.Lambda, rel=2e-2)


def test_bootstrap_keeps_a_power_law_and_rejects_an_exponential():
    rng = np.random.default_rng(4)
    assert not st.goodness_of_fit(_power_law(1500, 2.0, 1.0, rng), n_bootstrap=40)["rejected"]
    assert st.goodness_of_fit(rng.exponential(1.0, 1500) + 1.0, n_bootstrap=40, xmin=1.0)["rejected"]


def test_likelihood_ratios_favour_the_law_that_made_the_data():
    rng = np.random.default_rng(5)
    pl = st.likelihood_ratios(_power_law(3000, 2.0, 1.0, rng), 1.0)
    assert pl["exponential"]["R"] > 0 and pl["exponential"]["p"] < 0.01
    assert pl["truncated_power_law"]["p"] > 0.01  # no cutoff to find
    tr = st.likelihood_ratios(_truncated(3000, 1.5, 0.05, 1.0, rng), 1.0)
    assert tr["truncated_power_law"]["R"] < 0 and tr["truncated_power_law"]["p"] < 0.01


def test_cutoff_size_is_the_abbm_closed_form():
    # s^-3/2 exp(-s / (4 S_m)): <S^2> / (2 <S>) = S_m (up to sqrt(s_min / S_m) = 2 %)
    rng = np.random.default_rng(6)
    cut = st.cutoff_size(_truncated(20000, 1.5, 1 / 12.0, 1e-3, rng))
    assert cut["low"] <= 3.0 <= cut["high"]


def test_collapse_puts_series_of_different_cutoffs_on_one_curve():
    rng = np.random.default_rng(7)
    series = {sm: _truncated(20000, 1.5, 1 / (4 * sm), 0.01, rng) for sm in (1.0, 10.0)}
    curves = st.collapse(series, 1.5)
    (x1, y1), (x2, y2) = curves[1.0], curves[10.0]
    common = np.geomspace(0.1, 2.0, 5)
    a = np.interp(np.log(common), np.log(x1), np.log(y1))
    b = np.interp(np.log(common), np.log(x2), np.log(y2))
    assert np.abs(a - b).max() < 0.25


def test_two_sample_tests_tell_samples_apart_only_when_they_differ():
    rng = np.random.default_rng(8)
    a, b = _power_law(800, 1.5, 1.0, rng), _power_law(800, 1.5, 1.0, rng)
    assert st.two_sample(a, b)["agree"]
    assert not st.two_sample(a, 1.3 * b)["agree"]


def test_summary_of_too_few_events_is_the_count_alone():
    assert st.summarize_sizes(np.arange(1.0, 20.0)) == {"n_events": 19}
    assert math.isfinite(
        st.summarize_sizes(_power_law(400, 1.5, 1.0, np.random.default_rng(0)), 20)["tau"]["value"]
    )


def test_xmin_floor_keeps_the_fit_above_where_the_law_is_known_to_start():
    """ABBM's slip from a force overshoot a is the first passage of a drifted walk: an
    inverse Gaussian, P(S) ~ S^-3/2 exp(-lam / (2 S)) exp(-lam S / (2 m^2)) (lam ~ a^2 /
    sigma), whose local exponent 3/2 - lam / (2 S) reaches 3/2 only well above lam. With
    its xmin floored at 25 lam the fit finds 3/2 inside its interval and tries no xmin
    below the floor; near lam the law bends."""
    s = np.random.default_rng(6).wald(100.0, 1.0, 200_000)
    floored = st.truncated_fit_by_ks(s, xmin_floor=25.0)
    assert floored["xmin"] >= 25.0
    assert floored["low"] <= 1.5 <= floored["high"]
    assert st.truncated_fit(s, 0.5)["tau"] < 1.45
    assert st.truncated_fit_by_ks(s, xmin_floor=1e9)["xmin"] == st.truncated_fit_by_ks(s)["xmin"]
