"""The I_e boundary study: both drives' sweeps run as one batch, each read back as its own."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from spine_mj.validate.boundary import boundary
from spine_mj.validate.plans import PLANS, FamilySpec, paper_starts
from spine_mj.validate.study_runner import StudyRunner


def test_spring_and_ramp_sweeps_each_give_their_drives_curve(tmp_path):
    fam = FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0, -4.0]))
    plan = dataclasses.replace(
        PLANS["smoke"],
        families=(fam,),
        boundary=dataclasses.replace(
            PLANS["smoke"].boundary, protocols=("spring", "ramp"), ie_values=(1e-2, 1.0), ramp_max_steps=2000
        ),
    )
    res = boundary(plan, StudyRunner(tmp_path, 2, None, time.perf_counter()))
    assert set(res.curves) == {"spring", "ramp"}
    for proto, curve in res.curves.items():
        d = curve.as_dict()
        assert list(d["ie"]) == [1e-2, 1.0], proto
        assert all(0.0 <= a <= 1.0 for a in d["agreement"]), proto
    sweeps = {p.name for p in (tmp_path / "sweeps" / "boundary").iterdir()}
    assert "spring-paper-single-peak" in sweeps
    assert any(name.startswith("ramp-paper-single-peak-d") for name in sweeps)


def test_the_refined_window_is_the_bracket_and_one_grid_value_either_side():
    from spine_mj.validate.boundary import refinement_window

    ie = [1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0]
    assert refinement_window(ie, {"kind": "bracketed", "low": 1e-2, "high": 1e-1}) == [1e-3, 1e-2, 1e-1, 1.0]
    assert refinement_window(ie, {"kind": "bracketed", "low": 1e-4, "high": 1e-3}) == [1e-4, 1e-3, 1e-2]
    assert refinement_window(ie, {"kind": "above", "low": 10.0}) == [0.1, 1.0, 10.0]
    assert refinement_window(ie, {"kind": "below", "high": 1e-4}) == [1e-4, 1e-3, 1e-2]
    assert refinement_window(ie, {"kind": "not measured", "valid": False}) == []


def test_ie_star_under_a_halved_step_reruns_the_window_at_half_each_paces_own_step(tmp_path):
    from spine_mj import sweep

    fam = FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0, -4.0]))
    plan = dataclasses.replace(
        PLANS["smoke"],
        families=(fam,),
        boundary=dataclasses.replace(
            PLANS["smoke"].boundary, protocols=("spring",), ie_values=(1e-2, 1.0), refinements=("dt_halved",)
        ),
    )
    res = boundary(plan, StudyRunner(tmp_path, 2, None, time.perf_counter()))
    star = res.ie_star["spring"]
    conv = star["convergence"]
    assert conv["ie_refined"] == [1e-2, 1.0]  # a two-value grid is all window
    entry = conv["dt_halved"]
    assert entry["refined"] and entry["runs"] == 4  # 2 I_e x 2 starts
    lo, hi = conv["ci95"]
    assert entry["converged"] == (lo <= entry["refined_value"] <= hi)
    base = sweep.load_runs(tmp_path / "sweeps" / "boundary" / "spring-paper-single-peak")
    for ie in (1e-2, 1.0):
        refined = sweep.load_runs(
            tmp_path / "sweeps" / "boundary-refined" / "dt_halved" / f"spring-paper-single-peak-ie{ie:.3g}"
        )
        mj = refined[refined["analysis"] == "engine"]
        own = base[(base["analysis"] == "engine") & (base["ie"] == ie)]
        assert np.allclose(mj["timestep_s"], own["timestep_s"].iloc[0] / 2)
        assert sorted(mj["start_y"]) == sorted(own["start_y"])
