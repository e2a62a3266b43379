"""The I_e boundary study: both drives' sweeps run as one batch, each read back as its own."""

from __future__ import annotations

import dataclasses
import time

from spine_mj.validate.boundary import boundary
from spine_mj.validate.plans import PLANS, FamilySpec, paper_starts
from spine_mj.validate.study_runner import StudyRunner


def test_spring_and_ramp_sweeps_each_give_their_drives_curve(tmp_path):
    fam = FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0, -4.0]))
    plan = dataclasses.replace(
        PLANS["smoke"],
        families=(fam,),
        protocols=("spring", "ramp"),
        ie_values=(1e-2, 1.0),
        ramp_max_steps=2000,
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
