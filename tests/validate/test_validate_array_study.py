"""The array study at smoke size: rows with intervals, the conjecture's differences, the report."""

import copy
import math

import numpy as np
import pytest
from sim_rigs import MU

from spine_mj import sim
from spine_mj.sim.array import ArrayRig
from spine_mj.sim.drives import DEFAULT_STIFFNESS_NUMBER, stiffness_n_m
from spine_mj.sim.holding import spring_swing
from spine_mj.sim.layout import Layout
from spine_mj.surfaces.generators import inclined_plane
from spine_mj.validate.array_study import ARRAY_IE, PACE_RATIO, array_study, extrapolate_to_rest
from spine_mj.validate.fractal_lock import lock_rate
from spine_mj.validate.intervals import newcombe_difference
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
        # the fractal at K = 30, L_c / l_s = 24: a swing of 0.85 F_p per spine at I_e = 1e-3,
        # half that at the slower pace, where the excess is stated
        paces = r["holding_by_pace"]
        assert [b["ie"] for b in paces] == [ARRAY_IE, ARRAY_IE / PACE_RATIO]
        assert paces[0]["excess_predicted"] == pytest.approx(math.sqrt(1e-3 * 30 * 24), rel=0.01)
        assert r["holding_excess_predicted"] == pytest.approx(paces[0]["excess_predicted"] / 2)
        # the extrapolation is paired per placement: its mean is Richardson's step on the means
        slow, fast = paces[1]["holding"], paces[0]["holding"]
        assert r["holding_per_spine"] == pytest.approx(float(extrapolate_to_rest(slow, fast)))
        assert r["holding_extrapolation_step"] == pytest.approx(r["holding_per_spine"] - slow)
        lo, hi = paces[1]["holding_ci"]
        assert r["holding_converged"] is (lo <= r["holding_per_spine"] <= hi)
    assert smoke.convergence["pace"]["rows"] == len(smoke.rows)
    # the step check: the grid layout at the fastest pace, paired per placement
    grid = [r for r in smoke.rows if r["layout"] == "grid"]
    assert all(r["dt_halved"]["ie"] == ARRAY_IE and r["dt_halved"]["runs"] == 3 for r in grid)
    assert smoke.convergence["dt_halved"]["rows"] == len(grid)
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
    assert "## Spine arrays" in text and "**Answer" in text and "![" in text
    assert text.count("(unconverged: ") >= sum(not r["holding_converged"] for r in smoke.rows)
    assert not any(isinstance(v, float) and math.isnan(v) for v in smoke.pooled["staggered"]["diff"].values())


def test_extrapolation_to_rest_is_richardsons_step_of_order_one_in_sqrt_ie():
    # a holding mu + c sqrt(I_e) at two paces PACE_RATIO apart extrapolates to mu exactly
    mu, c, ie = 0.5, 0.3, 1e-3
    fast, slow = mu + c * math.sqrt(ie), mu + c * math.sqrt(ie / PACE_RATIO)
    assert float(extrapolate_to_rest(slow, fast)) == pytest.approx(mu, rel=1e-12)
    np.testing.assert_allclose(extrapolate_to_rest([slow, 2 * slow], [fast, 2 * fast]), [mu, 2 * mu])


def test_extrapolation_removes_the_spring_block_swing_from_an_arrays_peak_on_a_plane():
    # on a flat plane the peak lies the swing sqrt(I_e K L_c / l_s) per spine above mu F_p
    # (spine_mj.sim.holding, within 10 %: the engine's contact damps it a little); two paces
    # PACE_RATIO apart extrapolate to mu within that 10 % of the slower pace's swing (measured:
    # peaks 0.663 and 0.579, swings 0.173 and 0.087, extrapolated 0.494)
    surf = inclined_plane(slope_deg=0.0, half_width=0.05, n=101)
    layout = Layout(rows=2, cols=2, spacing=0.01, spacing_unit="surface")
    peaks, swings = [], []
    for ie in (ARRAY_IE, ARRAY_IE / PACE_RATIO):
        rig = sim.build_rig(surf, mu=MU, ie=ie)
        sc = rig.scales
        v = sc.speed_for(ie)
        k = stiffness_n_m(sim.SpringDrive(speed_m_s=v), sc)
        drive = sim.SpringDrive(speed_m_s=v, duration_s=2 * MU * sc.preload_n / k / v)
        peaks.append(ArrayRig(rig, layout).run(drive, centre=(0.0, 0.0)).peak_ratio)
        swings.append(spring_swing(ie, DEFAULT_STIFFNESS_NUMBER, sc.char_length_m / sc.slope_length_m))
    assert swings[0] == pytest.approx(2 * swings[1])
    for peak, swing in zip(peaks, swings):
        assert peak - MU == pytest.approx(swing, rel=0.1)
    assert abs(float(extrapolate_to_rest(peaks[1], peaks[0])) - MU) < 0.1 * swings[1]


def test_report_shows_the_observed_order_only_with_three_paces(smoke):
    assert "observed order" not in array_section(smoke)
    three = copy.deepcopy(smoke)
    three.plan["ie"] = [ARRAY_IE / PACE_RATIO**i for i in range(3)]
    for r in three.rows:
        r["holding_observed_order"] = 1.0
    assert "observed order" in array_section(three)


def test_the_median_relative_error_leaves_out_placements_whose_reference_holds_nothing():
    from spine_mj.validate.array_study import _median_rel_error

    assert _median_rel_error([1.1, 0.3, 0.9], [1.0, 0.0, 1.0]) == pytest.approx(0.1)
    assert np.isnan(_median_rel_error([0.2], [0.0])) and np.isnan(_median_rel_error([], []))


def test_a_resumed_study_reads_each_surfaces_rows_back_as_the_first_run_computed_them(
    smoke, tmp_path, monkeypatch
):
    import spine_mj.validate.array_study as study
    from spine_mj.jsonio import to_jsonable
    from spine_mj.validate.study_runner import StudyRunner

    first = array_study(PLANS["smoke"], StudyRunner(tmp_path, 1, None, 0.0))
    assert sorted(p.name for p in (tmp_path / "stored").iterdir()) == [
        f"arrays-{k}.json" for k in sorted(study.ARRAY_PLANS["smoke"].surfaces)
    ]

    def recomputed(*args):
        raise AssertionError("a stored surface was computed again")

    monkeypatch.setattr(study, "_surface_rows", recomputed)
    resumed = array_study(PLANS["smoke"], StudyRunner(tmp_path, 1, None, 0.0))
    assert to_jsonable(resumed.validation_keys()) == to_jsonable(first.validation_keys())
    assert to_jsonable(first.validation_keys()) == to_jsonable(smoke.validation_keys())
