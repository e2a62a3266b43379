"""The (I_e, K) map's pure pieces: per-run rows to the agreement grid and I_e*(K), the energy
and slip tables, the start subset, and the CCDF of slip sizes."""

import numpy as np
import pandas as pd
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.validate.plans import PLANS, paper_starts, relative_starts
from spine_mj.validate.stick_slip import complementary_cdf, slip_statistics
from spine_mj.validate.stiffness_map import agreement_map, energy_rows, slip_rows, subset_starts

IE = [1e-3, 1e-2, 1e-1, 1.0]


def _runs(fail_from: dict, *, family="fractal", n_starts=4, frechet=0.01) -> pd.DataFrame:
    """Rows of a map where, per K, every start agrees below the I_e index ``fail_from[K]``
    and none from there on (None: all agree)."""
    rows = []
    for k, j_fail in fail_from.items():
        for j, ie in enumerate(IE):
            for s in range(n_starts):
                ok = j_fail is None or j < j_fail
                rows.append(
                    {
                        "family": family,
                        "surface": "paper-fractal#1",
                        "K": k,
                        "ie": ie,
                        "start": s,
                        "agree": ok,
                        "agree_lock": True,
                        "frechet": frechet,
                        "engine_trouble": s == 0 and j == 0,
                        "mj_locked": False,
                    }
                )
    return pd.DataFrame(rows)


def test_agreement_map_brackets_ie_star_per_stiffness():
    m = agreement_map(_runs({1.0: 1, 10.0: 3, 100.0: None, 0.5: 0}), n_boot=50)["fractal"]
    assert set(m) == {"0.5", "1", "10", "100"}
    # K = 1 fails from 1e-2 on: I_e* in (1e-3, 1e-2); agreement 1 -> 0 crosses 0.95 at 5 %
    s1 = m["1"]["ie_star"]
    assert s1["kind"] == "bracketed" and (s1["low"], s1["high"]) == (1e-3, 1e-2)
    assert s1["value"] == pytest.approx(10 ** (-3 + 0.05), rel=1e-9)
    # every start fails at the same I_e: every resample brackets the same I_e*
    assert s1["ci_low"] == pytest.approx(s1["value"]) and s1["ci_high"] == pytest.approx(s1["value"])
    s10 = m["10"]["ie_star"]
    assert (s10["low"], s10["high"]) == (1e-1, 1.0)
    assert m["100"]["ie_star"]["kind"] == "above" and m["100"]["ie_star"]["low"] == 1.0
    assert m["0.5"]["ie_star"]["kind"] == "below" and m["0.5"]["ie_star"]["high"] == 1e-3
    assert m["1"]["agreement"] == [1.0, 0.0, 0.0, 0.0]
    assert m["1"]["passes"] == [True, False, False, False]
    # n_ok / n beside every average: the first start has engine trouble at the lowest I_e
    assert m["1"]["n"] == [4, 4, 4, 4] and m["1"]["n_ok"] == [3, 4, 4, 4]


def test_agreement_map_fails_a_cell_on_median_frechet_alone():
    m = agreement_map(_runs({3.0: None}, frechet=0.2), n_boot=10)["fractal"]["3"]
    assert m["agreement"] == [1.0] * 4 and m["passes"] == [False] * 4
    assert m["ie_star"]["kind"] == "below"


def test_a_deep_cell_that_passes_brackets_an_ie_star_the_grid_reads_below():
    # the grid fails at every I_e; a deeper sweep of 2 of the 4 starts (numbered anew) at
    # I_e 1e-6 agrees: I_e* lies between 1e-6 and the grid's lowest, 1e-3
    runs = _runs({1000.0: 0})
    runs["start_x"], runs["start_y"] = 0.05, 0.2 + 0.1 * runs["start"]
    deep = runs[(runs["ie"] == IE[0]) & runs["start"].isin([1, 3])].copy()
    deep["start"], deep["ie"], deep["agree"], deep["engine_trouble"] = [0, 1], 1e-6, True, False
    both = pd.concat([runs, deep], ignore_index=True)
    star = agreement_map(runs, n_boot=10)["fractal"]["1000"]["ie_star"]
    assert star["kind"] == "below" and star["high"] == IE[0]
    m = agreement_map(both, n_boot=10)["fractal"]["1000"]
    assert m["ie"][0] == 1e-6 and m["passes"][0] and m["n"][0] == 2
    star = m["ie_star"]
    assert star["kind"] == "bracketed" and (star["low"], star["high"]) == (1e-6, IE[0])
    assert 1e-6 < star["value"] < IE[0] and star["starts"] == 2
    # a deep cell that fails too leaves it below the deepest I_e
    both.loc[both["ie"] == 1e-6, "agree"] = False
    star = agreement_map(both, n_boot=10)["fractal"]["1000"]["ie_star"]
    assert star["kind"] == "below" and star["high"] == 1e-6


def test_agreement_map_counts_missing_agreement_as_disagreeing():
    runs = _runs({1.0: None})
    runs["agree"] = runs["agree"].astype(object)
    runs.loc[(runs["ie"] == 1.0) & (runs["start"] < 2), "agree"] = None
    m = agreement_map(runs, n_boot=10)["fractal"]["1"]
    assert m["agreement"][-1] == 0.5 and m["ie_star"]["high"] == 1.0


def test_energy_rows_normalize_release_and_work_per_lc_at_the_lowest_ie():
    runs = _runs({1.0: None, 10.0: None}, n_starts=2)
    runs["engine_trouble"] = False
    # K = 1 releases 0.5 F_p L_c over 2 L_c per run; the streamline's work is 1 F_p L_c per L_c
    runs["release_fplc"] = np.where(runs["K"] == 1.0, 0.5, 0.05)
    runs["advance_lc"] = 2.0
    runs["qs_work_fplc"] = 3.0
    runs["qs_advance_lc"] = 3.0
    runs["slip_events"] = np.where(runs["K"] == 1.0, 4.0, 0.0)
    rows = energy_rows(runs)
    assert [r["K"] for r in rows] == [1.0, 10.0] and all(r["ie"] == 1e-3 for r in rows)
    assert rows[0]["release_per_lc"] == pytest.approx(0.25)
    assert rows[0]["qs_work_per_lc"] == pytest.approx(1.0)
    assert rows[0]["release_over_work"] == pytest.approx(0.25)
    assert rows[1]["release_over_work"] == pytest.approx(0.025)
    assert rows[0]["slip_events_per_lc"] == pytest.approx(2.0) and rows[1]["slip_events_per_lc"] == 0
    assert (rows[0]["n_ok"], rows[0]["n"]) == (2, 2)


def test_slip_rows_count_skipped_traps_and_keep_slip_numbers_to_rough_families():
    runs = pd.concat(
        [_runs({1.0: None}, n_starts=2), _runs({1.0: None}, family="single_peak_valley", n_starts=2)]
    )
    runs["engine_trouble"] = False
    runs["advance_lc"] = 1.0
    runs["slip_events"] = np.where(runs["family"] == "fractal", 3.0, 100.0)
    runs["slip_time_fraction"] = 0.25
    # at I_e = 1: two streamline traps (lock agreed), one of which MuJoCo skips (disagreed)
    last = runs["ie"] == 1.0
    runs.loc[last & (runs["start"] == 0), ["agree_lock", "mj_locked"]] = [True, True]
    runs.loc[last & (runs["start"] == 1) & (runs["family"] == "fractal"), ["agree_lock", "mj_locked"]] = [
        False,
        False,
    ]
    rows = {r["ie"]: r for r in slip_rows(runs)}
    assert rows[1.0]["traps"] == 3 and rows[1.0]["skipped"] == 1
    assert rows[1.0]["trap_skip_rate"] == pytest.approx(1 / 3)
    assert np.isnan(rows[1e-3]["trap_skip_rate"])
    assert rows[1e-3]["slip_events_per_lc"] == pytest.approx(3.0)  # the peak/valley's 100 left out
    assert (rows[1e-3]["n_ok"], rows[1e-3]["n"]) == (2, 2)
    # a run the engine lost (unlocked, against a streamline trap) is not a skipped trap
    runs.loc[last & (runs["start"] == 1) & (runs["family"] == "fractal"), "engine_trouble"] = True
    rows = {r["ie"]: r for r in slip_rows(runs)}
    assert (rows[1.0]["traps"], rows[1.0]["skipped"]) == (2, 0) and rows[1.0]["n_ok"] == 1


def test_subset_starts_keeps_ends_and_the_frame():
    fam = PLANS["quick"].families[0]
    sub = subset_starts(fam, 2)
    assert sub.starts_table()["y"] == [-0.5, -4.0] and sub.starts_table()["x"] == [-3.0]
    assert subset_starts(fam, 10) == fam
    rel = subset_starts(type(fam)("f", ("paper-fractal",), (1,), relative_starts(5)), 3).starts_table()
    assert rel["frame"] == "relative" and rel["y"] == [0.2, 0.5, 0.8]
    assert dict(paper_starts([1.0]))["y"] == (1.0,)
    with pytest.raises(SpineInputError, match="starts"):
        subset_starts(fam, 0)


def test_complementary_cdf_of_known_samples():
    x, p = complementary_cdf([3.0, 1.0, 2.0, 2.0, np.nan])
    np.testing.assert_array_equal(x, [1.0, 2.0, 2.0, 3.0])
    # P(X >= x): all 4 at 1, the 3 from the first 2 on, 1 at 3
    np.testing.assert_allclose(p, [1.0, 0.75, 0.75, 0.25])
    x, p = complementary_cdf([])
    assert x.size == 0 and p.size == 0


def test_slip_statistics_marks_where_each_drop_is_read():
    t = np.arange(9, dtype=float)
    s = np.array([0, 0, 1, 1, 0, 0, 1, 1, 0], bool)
    f = np.array([0.0, 1.0, 0.5, 0.2, 0.3, 0.8, 0.4, 0.1, 0.2])
    st = slip_statistics(t, t, 0 * t, f, np.where(s, 2, 0))
    np.testing.assert_array_equal(st.onset_indices, [1, 5])
    np.testing.assert_array_equal(st.stop_indices, [3, 7])
    np.testing.assert_allclose(st.force_drops, f[st.onset_indices] - f[st.stop_indices])


def test_slip_transition_brackets_where_slips_stop_along_k():
    from spine_mj.validate.stiffness_map import SLIPS_PER_LC, slip_transitions

    rate = {1.0: 3.0, 3.0: 1.0, 10.0: 0.1 * SLIPS_PER_LC, 30.0: 0.0}
    slip = [{"ie": 1e-4, "K": k, "slip_events_per_lc": r} for k, r in rate.items()]
    slip += [{"ie": 1e-2, "K": k, "slip_events_per_lc": 0.0} for k in rate]
    low, high = slip_transitions(slip)
    assert (low["k_low"], low["k_high"]) == (3.0, 10.0)
    assert low["k_transition"] == pytest.approx(np.sqrt(30.0))
    assert np.isnan(high["k_low"]) and high["k_high"] == 1.0 and np.isnan(high["k_transition"])


def test_measured_k_star_brackets_the_first_passing_stiffness():
    from spine_mj.validate.report.stiffness_map import measured_k_star

    def cells(passes):
        return {k: {"ie": [1e-4, 1e-2], "passes": [p, False]} for k, p in passes.items()}

    assert measured_k_star(cells({"1": False, "3": False, "10": True, "30": True})) == "3-10"
    assert measured_k_star(cells({"1": True, "3": True})) == "< 1"
    assert measured_k_star(cells({"1": False, "3": False})) == "not read"  # the stiffest fails too
    assert measured_k_star(cells({"1": True, "3": False, "10": True})) == "3-10"


def test_family_limits_predict_on_the_maps_surfaces():
    from spine_mj.validate.plans import PLANS
    from spine_mj.validate.predicted_limits import family_limits

    plan = PLANS["smoke"]
    got = family_limits(plan, plan.families[0], n_starts=2)
    assert set(got["presets"]) == {"paper-single-peak"}
    one = got["presets"]["paper-single-peak"]
    assert got["k_star"] == one["k_star"] > 0 and got["ie_star"] == one["ie_star"] > 0
    # the criterion's boundary on the family's own starts lies at or below their fold with
    # an endless carriage; the runs' finite travel can only raise it
    assert 0 <= got["k_path_endless"] == one["k_path_endless"] <= one["k_star_path_starts"]
    assert got["k_path"] == one["k_path"] >= one["k_path_endless"]
    assert got["lc_over_ls"] == pytest.approx(one["char_length"] / one["slope_length"])
    assert one["tip_radius"] > 0 and one["mu"] == pytest.approx(1.23, abs=0.05)


def test_the_report_sets_the_prediction_beside_the_measured_boundary(tmp_path):
    from spine_mj.validate.report.stiffness_map import map_figure, map_sections
    from spine_mj.validate.stiffness_map import StiffnessMapResult

    rigid = agreement_map(_runs({1.0: 0, 10.0: 2, 100.0: 3}), n_boot=20)
    compliant = agreement_map(_runs({1.0: 2, 10.0: 2, 100.0: 3}), n_boot=20)
    km = StiffnessMapResult(
        ie=IE,
        stiffness_numbers=[1.0, 10.0, 100.0],
        families=["fractal"],
        starts_per_preset=4,
        agreement=rigid,
        energy=[],
        slip=[],
        agreement_compliant=compliant,
        predicted={"fractal": {"k_star": 5.0, "ie_star": 0.02, "limit": "trap", "presets": {}}},
    )
    text = map_sections(km)["map"]
    row = next(line for line in text.splitlines() if line.startswith("| fractal | 5 |"))
    # measured K boundary at the lowest I_e: rigid fails at K = 1 only, the compliant
    # reference passes from K = 1; I_e* at the stiffest K from both
    assert "| 1-10 | < 1 | 0.02 | trap | 100 | 0.1-1 | 0.1-1 |" in row
    assert "| fractal | 1 | 0.001 | 0 / 0.01 | 1 / 0.01 |" in text
    assert map_figure(km, tmp_path / "map.png").is_file()
    assert km.validation_keys()["predicted_drive_limits"] == {
        "fractal": {"k_star": 5.0, "ie_star": 0.02, "limit": "trap"}
    }
