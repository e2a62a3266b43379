"""The array study at smoke size: rows with intervals, the conjecture's differences, the report."""

import math

import pytest

from spine_mj.validate.array_study import array_study, newcombe_difference
from spine_mj.validate.fractal_lock import lock_rate
from spine_mj.validate.plans import PLANS
from spine_mj.validate.report.array_study import array_figure, array_section


def test_newcombe_difference_is_zero_centred_for_equal_rates_and_inside_minus_one_one():
    a = lock_rate([True] * 3 + [False] * 5)
    d = newcombe_difference(a, a)
    assert d["diff"] == 0 and d["ci_low"] == pytest.approx(-d["ci_high"])
    far = newcombe_difference(lock_rate([True] * 20), lock_rate([False] * 20))
    assert far["diff"] == 1 and 0.7 < far["ci_low"] < 1 and far["ci_high"] == pytest.approx(1)


@pytest.fixture(scope="module")
def smoke():
    return array_study(PLANS["smoke"])


def test_smoke_study_has_one_row_per_layout_and_size_with_intervals(smoke):
    kinds = {(r["n_spines"], r["layout"]) for r in smoke.rows}
    assert kinds == {(n, k) for n in (1, 4) for k in ("grid", "staggered", "random")}
    for r in smoke.rows:
        lo, hi = r["holding_ci"]
        assert lo <= r["holding_per_spine"] <= hi
        assert r["p_lock"]["n_ok"] + r["failed_runs"] == r["placements"]
        assert 0 <= r["p_lock"]["ci_low"] <= r["p_lock"]["ci_high"] <= 1
        assert 0 <= r["lock_agreement"] <= 1
        assert r["holding_per_spine_qs"] > 0
        # the fractal at I_e = 1e-3, K = 30, L_c / l_s = 24: a swing of 0.85 F_p per spine
        assert r["holding_excess_predicted"] == pytest.approx(math.sqrt(1e-3 * 30 * 24), rel=0.01)
        assert r["holding_converged"] is False
    one = {r["layout"]: r for r in smoke.rows if r["n_spines"] == 1}
    assert one["grid"]["holding_per_spine"] == one["staggered"]["holding_per_spine"]  # one spine: one layout


def test_smoke_study_answers_the_conjecture_in_the_report(smoke, tmp_path):
    assert {c["layout"] for c in smoke.conjecture} == {"staggered", "random"}
    for c in smoke.conjecture:
        d = c["p_lock_diff"]
        assert d["ci_low"] <= d["diff"] <= d["ci_high"]
    fig = array_figure(smoke, tmp_path / "arrays.png")
    assert fig is not None and fig.stat().st_size > 10_000
    text = array_section(smoke, "figures/arrays.png")
    assert "## Spine arrays" in text and "**Answer" in text and "![" in text and "(unconverged)" in text
    assert not any(isinstance(v, float) and math.isnan(v) for v in smoke.pooled["staggered"]["diff"].values())
