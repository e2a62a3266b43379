"""Ensembles of starts: the stencil, and ill-conditioned starts found on each side."""

from __future__ import annotations

import numpy as np
import pytest

from spine_mj.validate.ensembles import ensemble_starts, ensemble_verdicts, member_offsets
from spine_mj.validate.intervals import wilson


def test_the_stencil_is_the_start_and_a_circle_around_it():
    off = member_offsets(5)
    assert off.shape == (5, 2) and np.all(off[0] == 0)
    assert np.allclose(np.hypot(off[1:, 0], off[1:, 1]), 1.0)
    assert np.allclose(off[1:].sum(axis=0), 0.0, atol=1e-12)  # evenly spaced
    assert member_offsets(1).tolist() == [[0.0, 0.0]]
    with pytest.raises(ValueError, match="members must be"):
        member_offsets(0)


def test_every_start_becomes_its_ensemble_in_a_row():
    table = {"frame": "relative", "x": [0.0], "y": [0.2, 0.5]}
    out = ensemble_starts(table, 3, (1e-3, 2e-3))
    pts = np.array(out["points"])
    assert out["frame"] == "relative" and pts.shape == (6, 2)
    assert pts[0].tolist() == [0.0, 0.2] and pts[3].tolist() == [0.0, 0.5]
    assert np.all(pts >= 0)  # clipped into the relative frame (x = 0 is its edge)
    assert np.allclose(pts[1], [1e-3, 0.2])
    absolute = ensemble_starts({"frame": "absolute", "points": [(-3.0, -2.0)]}, 3, (0.01, 0.01))
    assert np.allclose(np.array(absolute["points"])[2], [-3.01, -2.0])


def _group(mj_held, mj_end, ref_held, ref_end, ok=True):
    return {
        "mj_held": np.array(mj_held),
        "mj_end": np.array(mj_end, float),
        "ref_held": np.array(ref_held),
        "ref_end": np.array(ref_end, float),
        "lc": 1.0,
        "ok": ok,
    }


def test_a_start_whose_members_end_in_different_traps_is_ill_conditioned_on_that_side():
    here, there = [0.0, 0.0], [1.0, 0.0]  # 1 L_c apart: two traps (tolerance 0.25 L_c)
    groups = [
        # agrees, one outcome each side: held in the same trap
        _group([1, 1, 1], [here, here, [0.1, 0]], [1, 1, 1], [here, here, here]),
        # free on both sides (where a free path ends does not matter)
        _group([0, 0, 0], [here, there, here], [0, 0, 0], [there, here, here]),
        # one outcome each side, but not the same: a disagreement on a well-conditioned start
        _group([1, 1, 1], [there] * 3, [1, 1, 1], [here] * 3),
        # MuJoCo splits between two traps: ill-conditioned on MuJoCo's side only
        _group([1, 1, 1], [here, there, here], [1, 1, 1], [here] * 3),
        # the reference splits between held and free
        _group([1, 1, 1], [here] * 3, [1, 0, 1], [here] * 3),
        # an engine stop: not well-conditioned, whatever the outcomes
        _group([1, 1, 1], [here] * 3, [1, 1, 1], [here] * 3, ok=False),
    ]
    v = ensemble_verdicts(groups)
    assert v["starts"] == 6 and v["members"] == 3
    assert v["ill_conditioned_share"] == {"mujoco": pytest.approx(1 / 6), "reference": pytest.approx(1 / 6)}
    assert v["ill_conditioned_starts"] == 2
    assert v["well_conditioned_runs"] == 3 and v["stopped_starts"] == 1
    assert v["agreement_well_conditioned"] == pytest.approx(2 / 3)
    assert v["agreement_ci"] == pytest.approx(list(wilson(2, 3)))
    # pairs that agree: 1, 1, 0, 6/9, 6/9 and 0 for the stopped start
    assert v["distribution_agreement"] == pytest.approx((1 + 1 + 0 + 6 / 9 + 6 / 9 + 0) / 6)


def test_a_start_whose_member_pairs_straddle_the_end_tolerance_is_ill_conditioned_in_its_verdict():
    # each side one outcome (MuJoCo's members 0.2 L_c apart, within the 0.25 L_c tolerance),
    # but the lead lands 0.1 L_c from the reference's lock and its neighbours 0.3: which member
    # is drawn decides the verdict (the full plan's sandpaper P36, y -1.5e-3: 0.193, 0.27, 0.27)
    straddles = _group([1, 1, 1], [[0.0, 0], [0.2, 0], [0.2, 0]], [1, 1, 1], [[-0.1, 0]] * 3)
    agrees = _group([1, 1, 1], [[0.0, 0]] * 3, [1, 1, 1], [[0.05, 0]] * 3)
    misses = _group([1, 1, 1], [[1.0, 0]] * 3, [1, 1, 1], [[0.0, 0]] * 3)
    v = ensemble_verdicts([{**straddles, "key": "a/0"}, {**agrees, "key": "a/1"}, {**misses, "key": "a/2"}])
    assert v["ill_conditioned_share"] == {"mujoco": 0.0, "reference": 0.0}
    assert v["verdict_split_starts"] == 1 and v["ill_conditioned_starts"] == 1
    assert v["ill_conditioned"] == {"a/0": "verdict", "a/1": "", "a/2": ""}
    assert v["well_conditioned"] == {"a/0": False, "a/1": True, "a/2": True}
    # judged on the two whose every member pair gives one verdict, not as a miss
    assert v["well_conditioned_runs"] == 2 and v["agreement_well_conditioned"] == pytest.approx(1 / 2)
    # a split side keeps its own label, whatever the pairs' verdicts
    split = _group([1, 1, 1], [[0, 0], [1, 0], [0, 0]], [1, 1, 1], [[0, 0]] * 3)
    side = ensemble_verdicts([{**split, "key": "b"}])
    assert side["ill_conditioned"] == {"b": "mujoco"} and side["verdict_split_starts"] == 0


def test_one_member_finds_nothing_ill_conditioned():
    v = ensemble_verdicts([_group([1], [[0, 0]], [1], [[5, 0]]), _group([0], [[0, 0]], [0], [[0, 0]])])
    assert v["ill_conditioned_starts"] == 0 and v["well_conditioned_runs"] == 2
    assert v["agreement_well_conditioned"] == 0.5


def test_the_limit_study_runs_each_start_as_an_ensemble_on_both_sides(tmp_path):
    import dataclasses
    import time

    from spine_mj.validate.plans import PLANS, FamilySpec, paper_starts
    from spine_mj.validate.quasistatic_limit import quasistatic_limit
    from spine_mj.validate.study_runner import StudyRunner

    fam = FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0, -4.0]))
    plan = dataclasses.replace(
        PLANS["smoke"], families=(fam,), limit=dataclasses.replace(PLANS["smoke"].limit, ensemble_members=3)
    )
    res = quasistatic_limit(plan, StudyRunner(tmp_path, 1, None, time.perf_counter()))
    f = res.families["single_peak_valley"]
    assert f["runs"] == 2 and f["starts"] == 2 and f["members"] == 3  # runs: the starts themselves
    assert f["well_conditioned_runs"] + f["ill_conditioned_starts"] <= 2
    lo, hi = f["agreement_ci"]
    assert lo <= f["agreement_well_conditioned"] <= hi
    assert set(f["ill_conditioned_share"]) == {"mujoco", "reference"}
    assert [r["start_y"] for r in res.runs] == [-2.0, -4.0]  # each ensemble's own start
    assert all(r["ill_conditioned"] in ("", "mujoco", "reference", "both") for r in res.runs)


def test_a_familys_presets_share_one_sweep_in_cases_of_whole_ensembles():
    """Presets with one grid run as one sweep; each preset's ensemble starts split into
    cases of at most CASE_STARTS whole ensembles, in order, none lost."""
    import dataclasses

    from spine_mj.sweep import expand_cases, parse_config
    from spine_mj.validate.ensembles import ensemble_family
    from spine_mj.validate.plans import PLANS, FamilySpec, paper_starts
    from spine_mj.validate.quasistatic_limit import CASE_STARTS, limit_family_docs

    ys = list(np.linspace(-0.5, -4.0, 2 * CASE_STARTS + 1))
    fam = FamilySpec(
        "single_peak_valley", ("paper-single-peak", "paper-single-valley"), None, paper_starts(ys)
    )
    plan = dataclasses.replace(
        PLANS["smoke"], families=(fam,), limit=dataclasses.replace(PLANS["smoke"].limit, ensemble_members=3)
    )
    ((name, doc),) = limit_family_docs(plan, fam)
    assert name == "single_peak_valley"
    cases = expand_cases(parse_config(doc))
    assert len(cases) == 2 * 3  # per preset: CASE_STARTS, CASE_STARTS and 1 ensemble
    for preset in fam.presets:
        mine = [c for c in cases if c.surface.source == preset]
        points = [tuple(p) for c in mine for p in c.starts.as_dict()["points"]]
        expected = ensemble_family(fam, preset, 3).starts_table()["points"]
        assert points == [tuple(p) for p in expected]
        assert all(len(c.starts.as_dict()["points"]) % 3 == 0 for c in mine)
        assert max(len(c.starts.as_dict()["points"]) for c in mine) == 3 * CASE_STARTS
    assert {c.params["ensemble_members"] for c in cases} == {3}
    # without ensembles every preset keeps its own sweep of the family's starts
    single = dataclasses.replace(plan, limit=dataclasses.replace(plan.limit, ensemble_members=1))
    assert [n for n, _ in limit_family_docs(single, fam)] == list(fam.presets)
