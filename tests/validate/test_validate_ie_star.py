"""I_e*: the estimator, its bootstrap, the criteria and the departure rule."""

import math

import numpy as np
import pytest

from spine_mj import validate
from spine_mj.errors import SpineInputError

IE = np.array([1e-4, 1e-3, 1e-2, 1e-1, 1.0])


def test_ie_star_interpolates_the_agreement_crossing_in_log_ie():
    # agreement 1.0 at 1e-2, 0.9 at 1e-1: 0.95 is crossed half-way in log10, at 10**-1.5
    est = validate.estimate_ie_star(IE, [1.0, 1.0, 1.0, 0.9, 0.5])
    assert est.kind == "bracketed"
    assert (est.low, est.high) == (1e-2, 1e-1)
    assert est.value == pytest.approx(10**-1.5, rel=1e-9)


def test_ie_star_takes_the_earlier_of_agreement_and_frechet_crossings():
    # Frechet 0.04 -> 0.19 crosses 0.1 at 40 % of the decade; agreement 1 -> 0.85 at 1/3
    est = validate.estimate_ie_star(IE, [1, 1, 1, 0.85, 0.5], [0.01, 0.02, 0.04, 0.19, 1.0])
    assert est.value == pytest.approx(10 ** (-2 + 1 / 3), rel=1e-9)
    est = validate.estimate_ie_star(IE, [1, 1, 1, 1, 0.5], [0.01, 0.02, 0.04, 0.19, 1.0])
    assert est.value == pytest.approx(10 ** (-2 + 0.4), rel=1e-9)
    assert (est.low, est.high) == (1e-2, 1e-1)


def test_ie_star_reports_when_the_grid_does_not_bracket_it():
    above = validate.estimate_ie_star(IE, np.ones(5), np.full(5, 0.01))
    assert above.kind == "above" and above.low == 1.0 and math.isnan(above.value)
    below = validate.estimate_ie_star(IE, [0.5, 1, 1, 1, 1])
    assert below.kind == "below" and below.high == 1e-4 and math.isnan(below.value)


@pytest.mark.parametrize(
    "ie, ag, match",
    [
        ([1e-3, 1e-4], [1, 1], "strictly increasing"),
        ([1e-3], [1], "same length >= 2"),
        ([1e-3, 1e-2], [1, 1, 1], "same length >= 2"),
    ],
)
def test_ie_star_rejects_bad_grids(ie, ag, match):
    with pytest.raises(SpineInputError, match=match):
        validate.estimate_ie_star(ie, ag)


def test_bootstrap_of_identical_starts_collapses_on_the_estimate():
    ag = np.repeat(np.array([1.0, 1.0, 1.0, 0.0, 0.0])[:, None], 6, axis=1)
    fr = np.full_like(ag, 0.01)
    lo, hi = validate.bootstrap_ie_star(IE, ag, fr, n_boot=50, rng=0)
    # every resample sees agreement 1 -> 0 between 1e-2 and 1e-1: crossing at 5 % of the decade
    assert lo == pytest.approx(hi) == pytest.approx(10 ** (-2 + 0.05))
    # starts that disagree at 1e-1 for some resamples widen the interval
    ag[3, :3] = 1.0
    lo, hi = validate.bootstrap_ie_star(IE, ag, fr, n_boot=200, rng=0)
    assert 1e-2 < lo < hi <= 1e-1


def test_one_outlying_start_moves_the_mean_criterion_but_not_the_median():
    # 10 starts, all agree in outcome; one start deviates by 5 L_c at every I_e (a marginal
    # start), the others by 0.02 L_c until 1e-1
    ag = np.ones((5, 10))
    ag[3:, :] = 0.0
    fr = np.full((5, 10), 0.02)
    fr[:, 0] = 5.0
    by = validate.ie_star_by_criterion(IE, ag, fr, n_boot=100, rng=1)
    assert set(by) == set(validate.IE_STAR_CRITERIA) | {"departure"}
    assert by["mean_frechet"]["kind"] == "below"  # mean 0.52 L_c at every I_e
    for key in ("median_frechet", "outcome"):
        assert by[key]["kind"] == "bracketed"
        assert (by[key]["low"], by[key]["high"]) == (1e-2, 1e-1)
        assert 1e-2 <= by[key]["ci_low"] <= by[key]["ci_high"] <= 1e-1
    assert "median" in by["median_frechet"]["criterion"]


def test_bootstrap_rejects_an_unknown_statistic():
    with pytest.raises(SpineInputError, match="stat must be"):
        validate.bootstrap_ie_star(IE, np.ones((5, 2)), np.ones((5, 2)), n_boot=2, rng=0, stat="max")


def test_departure_ie_star_finds_the_break_below_an_imperfect_plateau():
    """Agreement stuck at 90 % (one start always disagrees) fails the absolute 95 % rule at
    every I_e; the departure criterion still brackets the drop between 1e-2 and 1e-1."""
    ie = np.logspace(-4, 0, 5)
    runs = np.ones((5, 10))
    runs[:, 0] = 0  # an I_e-independent disagreement
    runs[3:, 1:6] = 0  # inertia breaks agreement from I_e = 0.1 on
    absolute = validate.estimate_ie_star(ie, runs.mean(axis=1))
    assert absolute.kind == "below"
    dep = validate.departure_ie_star(ie, runs, n_boot=50)
    assert dep.kind == "bracketed" and (dep.low, dep.high) == pytest.approx((1e-2, 1e-1))
    assert 1e-2 <= dep.value <= 1e-1
    flat = validate.departure_ie_star(ie, np.ones((5, 10)), n_boot=0)
    assert flat.kind == "above"


def test_a_single_criterion_is_the_one_ie_star_by_criterion_reports():
    from spine_mj.validate.ie_star import criterion_ie_star, grid_point

    rng = np.random.default_rng(3)
    ag = (rng.random((5, 8)) < np.array([1.0, 1.0, 0.97, 0.6, 0.1])[:, None]).astype(float)
    fr = rng.uniform(0.0, 0.2, (5, 8)) * np.array([0.1, 0.2, 0.5, 1.0, 3.0])[:, None]
    by = validate.ie_star_by_criterion(IE, ag, fr, n_boot=20, rng=0)
    for key in validate.IE_STAR_CRITERIA:
        star = criterion_ie_star(IE, ag, fr, key)
        assert star.kind == by[key]["kind"] and star.low == by[key]["low"]
        assert grid_point(star) == pytest.approx(
            by[key]["value"]
            if star.kind == "bracketed"
            else (star.low if star.kind == "above" else star.high)
        )
    with pytest.raises(SpineInputError, match="criterion must be one of"):
        criterion_ie_star(IE, ag, fr, "nope")


def test_a_95_percent_interval_holds_the_68_percent_one():
    ag = np.ones((5, 12))
    ag[3, :5] = 0.0  # five of twelve starts fail at 1e-1
    ag[4, :] = 0.0
    fr = np.full_like(ag, 0.01)
    lo68, hi68 = validate.bootstrap_ie_star(IE, ag, fr, n_boot=300, rng=0)
    lo95, hi95 = validate.bootstrap_ie_star(IE, ag, fr, n_boot=300, rng=0, confidence=0.95)
    assert lo95 <= lo68 < hi68 <= hi95
    assert lo95 < lo68 or hi68 < hi95
