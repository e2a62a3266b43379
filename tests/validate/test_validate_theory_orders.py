"""Convergence to the theory: fitted orders on known power laws, the K ladder from K*, the
measured K boundary and the factor-2 verdicts on the predicted limits."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from spine_mj.validate.predicted_limits import family_k_axis, k_ladder
from spine_mj.validate.stiffness_map import agreement_map
from spine_mj.validate.theory_orders import (
    FRECHET_FLOOR_LC,
    bracket_ratio,
    fit_order,
    gap_series,
    k_boundary,
    k_path_term,
    k_readings,
    order_rows,
    outside_factor,
    prediction_check,
    within_factor,
)


def test_fit_order_recovers_an_exact_power_law_with_a_tight_interval():
    x = np.array([1e-6, 1e-5, 1e-4, 1e-3])
    fit = fit_order(x, 3.0 * x**1.0)
    assert fit["order"] == pytest.approx(1.0)
    assert fit["ci_low"] == pytest.approx(1.0, abs=1e-6) and fit["ci_high"] == pytest.approx(1.0, abs=1e-6)
    assert fit["n"] == 4


def test_fit_order_interval_holds_the_true_order_of_a_noisy_law():
    rng = np.random.default_rng(3)
    x = np.geomspace(1e-4, 1.0, 9)
    fit = fit_order(x, 0.5 * x**0.5 * np.exp(rng.normal(0, 0.05, x.size)))
    assert fit["ci_low"] < 0.5 < fit["ci_high"]
    assert fit["ci_high"] - fit["ci_low"] < 0.2


def test_fit_order_leaves_out_what_the_metric_does_not_resolve():
    x = np.array([1e-4, 1e-3, 1e-2, 1e-1])
    gap = np.array([0.01, 0.01, 0.05, 0.5])  # the first two at the Frechet's floor
    fit = fit_order(x, gap, floor=2 * FRECHET_FLOOR_LC)
    assert fit["n"] == 2 and fit["order"] == pytest.approx(1.0)
    assert math.isnan(fit["ci_low"])  # two points: a slope, no interval
    assert fit_order(x, np.zeros(4))["n"] == 0 and math.isnan(fit_order(x, np.zeros(4))["order"])


def test_the_k_ladder_is_set_from_k_star_in_two_digits():
    assert k_ladder(104.78, (0.1, 0.3, 1.0, 3.0, 10.0)) == [10.0, 31.0, 100.0, 310.0, 1000.0]
    assert k_ladder(104.78, ()) == [] and k_ladder(float("nan"), (1.0,)) == []
    assert k_ladder(104.78, (1.0, 10.0), round_up=True) == [110.0, 1100.0]
    assert k_ladder(70.4, (10.0,), round_up=True) == [710.0] and k_ladder(2.0, (10.0,), round_up=True) == [
        20.0
    ]


def test_a_familys_k_axis_brackets_k_path_and_reaches_ten_fold_k_stars():
    """The ladder is set on K_path (the boundary the criterion sees, judged within a factor
    of 2) and carries the fold K* and 10 K*; without a finite K_path, the fold's ladder."""
    axis = family_k_axis({"k_path": 0.29, "k_star": 67.4}, (0.3, 0.5, 1.0, 2.0, 3.0))
    assert axis == [0.087, 0.14, 0.29, 0.58, 0.87, 67.0, 680.0]
    assert family_k_axis({"k_star": 104.78}, (1.0, 10.0)) == [100.0, 1000.0, 1100.0]
    for k_star in (19.4, 70.4, 104.78, 2.0):  # the stiffest K is at least 10 K*
        assert max(family_k_axis({"k_path": 1.0, "k_star": k_star}, (1.0,))) / k_star >= 10
    assert family_k_axis({"k_path": 29.0, "k_star": 105.0}, ()) == []


def _cells(ks, ies, passes, agreement=None, frechet=None):
    out = {}
    for i, k in enumerate(ks):
        out[f"{k:g}"] = {
            "ie": list(ies),
            "passes": list(passes[i]),
            "agreement": list(agreement[i]) if agreement else [1.0] * len(ies),
            "median_frechet": list(frechet[i]) if frechet else [0.01] * len(ies),
            "ie_star": {"kind": "bracketed", "value": 0.05, "low": 0.01, "high": 0.1},
        }
    return out


def test_the_k_boundary_brackets_the_last_failure_at_the_lowest_ie():
    ies = [1e-4, 1e-2]
    assert k_boundary(_cells([10, 30, 100], ies, [[False, False], [True, False], [True, True]])) == (
        10.0,
        30.0,
    )
    assert k_boundary(_cells([10, 30], ies, [[True, False], [True, False]]))[1] == 10.0
    # the stiffest fails at the lowest I_e too: inertia or spring, the map cannot tell
    assert all(math.isnan(v) for v in k_boundary(_cells([10, 30], ies, [[False, False], [False, True]])))


def test_no_k_is_read_where_the_stiffest_spring_fails_too():
    # the fractal of the full report: every K failed at I_e 1e-4, the stiffest (10 K*)
    # passed at 1e-6, the only K that ran there: a failure at 1e-4 is the tip's inertia
    cells = _cells([29, 100], [1e-4, 1e-2], [[False, False], [False, False]])
    cells["1000"] = dict(_cells([1000], [1e-6, 1e-4], [[True, False]])["1000"])
    assert k_readings(cells) == {"29": None, "100": None, "1000": None}  # no common lowest I_e passes
    assert k_readings(cells, 30.0) == {"29": None, "100": None, "1000": 0}
    low, high = k_boundary(cells, 30.0)
    assert math.isnan(low) and high == 1000.0  # at or below the stiffest: no K boundary above it
    # with the deep I_e at every K, the K boundary is read there
    for k in ("29", "100"):
        cells[k] = {**cells[k], "ie": [1e-6, *cells[k]["ie"]], "passes": [k == "100", False, False]}
    assert k_readings(cells, 30.0) == {"29": 0, "100": 0, "1000": 0}
    assert k_boundary(cells, 30.0) == (29.0, 100.0)


def test_within_a_factor_of_two_needs_the_whole_bracket():
    assert within_factor(100.0, 60.0, 150.0) == "within"
    assert within_factor(100.0, 30.0, 100.0) == "consistent"  # wider than the factor: undecided
    assert within_factor(100.0, 250.0, 300.0) == "outside"
    assert within_factor(100.0, float("nan"), 40.0) == "outside"  # passes already below K* / 2
    assert within_factor(100.0, 150.0, math.inf) == "consistent"
    assert within_factor(float("nan"), 1.0, 2.0) == "-"


def test_gap_series_takes_ie_at_the_stiffest_k_and_1_over_k_above_k_star():
    cells = _cells(
        [10, 100, 1000],
        [1e-4, 1e-2],
        [[False, False], [True, True], [True, True]],
        agreement=[[0.5, 0.4], [0.9, 0.8], [1.0, 0.9]],
        frechet=[[0.5, 0.6], [0.05, 0.2], [0.02, 0.1]],
    )
    cells["1000"]["ie"] = [1e-6, 1e-4, 1e-2]  # a deeper I_e at the stiffest K only
    cells["1000"]["agreement"] = [1.0, 1.0, 0.9]
    cells["1000"]["median_frechet"] = [0.011, 0.02, 0.1]
    s = gap_series(cells, k_star=50.0)
    assert s["ie"]["x"] == [1e-6, 1e-4, 1e-2] and s["ie"]["at"] == 1000.0
    assert s["inverse_k"]["x"] == [0.01, 0.001] and s["inverse_k"]["at"] == 1e-4
    assert s["inverse_k"]["median_frechet"] == [0.05, 0.02]
    rows = order_rows({"fam": cells}, {"fam": {"k_star": 50.0}})
    assert {(r["axis"], r["gap"]) for r in rows} == {
        (a, g) for a in ("ie", "inverse_k") for g in ("agreement_gap", "median_frechet")
    }
    pred = {"k_star": 50.0, "k_path": 300.0, "ie_star": 0.05, "limit": "lag"}
    check = prediction_check({"fam": cells}, {"fam": pred})[0]
    assert (check["k_low"], check["k_high"]) == (10.0, 100.0)
    assert check["k_verdict_fold"] == "consistent" and check["k_verdict"] == "outside"
    assert check["ie_verdict"] == "consistent" and check["ie_at_k"] == 1000.0
    assert check["ie_limit"] == "lag"  # no L_c / l_s: no swing limit


def test_the_k_boundary_is_read_where_the_spring_swing_is_small():
    # K_c = K L_c / l_s = 100 K: the swing's force reaches F_p at I_e = 1 / K_c, its
    # amplitude the path tolerance (0.1 L_c) at I_e = 0.01 K_c
    cells = _cells(
        [1, 10, 100], [1e-5, 1e-3, 1e-2], [[False, False, False], [True, True, False], [True, True, False]]
    )
    cells["100"]["ie"] = [1e-3, 1e-2]  # the stiffest K ran only where its swing is F_p and more
    cells["100"]["passes"] = [False, False]
    assert k_readings(cells, 100.0) == {"1": 0, "10": 0, "100": None}
    assert k_boundary(cells, 100.0) == (1.0, 10.0)  # the stiffest K failed for its swing: not read
    # read at the lowest common I_e, where the stiffest fails too: nothing read
    assert all(math.isnan(v) for v in k_boundary(cells))
    assert all(math.isnan(v) for v in k_boundary({"100": cells["100"]}, 100.0))
    pred = {"k_star": 50.0, "k_path": 2.0, "ie_star": 0.25, "limit": "lag", "lc_over_ls": 100.0}
    check = prediction_check({"fam": cells}, {"fam": pred})[0]
    assert check["k_verdict"] == "consistent" and check["k_verdict_fold"] == "outside"
    assert check["k_read_ie"] == {"1": 1e-5, "10": 1e-5, "100": None}
    # at K = 100 the force swing (I_e 1e-4) is below the lag's 0.25 and the path swing's 100
    assert check["ie_limit"] == "swing-force" and check["ie_star_predicted"] == pytest.approx(1e-4)
    assert check["ie_swing_path"] == pytest.approx(100.0)


def test_the_ie_star_bootstrap_leaves_out_a_deeper_ie_run_from_fewer_starts():
    rows = []
    for ie, starts in ((1e-6, 2), (1e-4, 4), (1e-2, 4), (1.0, 4)):
        for s in range(starts):
            rows.append(
                {
                    "family": "f",
                    "K": 100.0,
                    "ie": ie,
                    "surface": "a",
                    "start": s,
                    "agree": ie < 0.5,
                    "frechet": 0.01 if ie < 0.5 else 1.0,
                    "engine_trouble": False,
                }
            )
    cell = agreement_map(pd.DataFrame(rows), n_boot=20)["f"]["100"]
    assert cell["ie"] == [1e-6, 1e-4, 1e-2, 1.0] and cell["n"] == [2, 4, 4, 4]
    assert cell["ie_star"]["kind"] == "bracketed"
    assert (cell["ie_star"]["low"], cell["ie_star"]["high"]) == (1e-2, 1.0)


def test_the_factor_outside_is_the_nearer_end_over_the_prediction():
    assert outside_factor(100.0, 60.0, 150.0) == 1.0
    assert outside_factor(0.3, 0.9, 70.0) == pytest.approx(3.0)
    assert outside_factor(29.0, 100.0, 1000.0) == pytest.approx(100 / 29)
    assert outside_factor(0.2, 0.01, 0.1) == pytest.approx(2.0)
    assert outside_factor(5.0, float("nan"), 10.0) == 1.0 and outside_factor(5.0, 1.0, math.inf) == 1.0
    assert math.isnan(outside_factor(float("nan"), 1.0, 2.0))
    assert bracket_ratio(0.9, 70.0) == pytest.approx(70 / 0.9)
    assert bracket_ratio(float("nan"), 10.0) == math.inf and bracket_ratio(1.0, math.inf) == math.inf


def test_k_path_is_set_by_the_travel_only_where_it_exceeds_the_endless_carriages():
    assert k_path_term(8.7, 0.32) == "carriage travel"  # the single peak/valley's map
    assert k_path_term(20.2, 20.2) == "folds" and k_path_term(1.1, 1.0) == "folds"
    assert k_path_term(float("nan"), 1.0) == "-"
    check = prediction_check(
        {"fam": _cells([5, 10], [1e-4], [[False], [True]])},
        {"fam": {"k_star": 70.0, "k_path": 8.7, "k_path_endless": 0.32, "ie_star": 0.2, "limit": "lag"}},
    )[0]
    assert check["k_path_set_by"] == "carriage travel" and check["k_verdict"] == "within"
    assert check["k_verdict_endless"] == "outside" and check["k_bracket_ratio"] == 2.0
