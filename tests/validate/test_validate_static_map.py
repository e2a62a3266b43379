"""The static map's solution verification: its hfield x 2 refines the plane's hfield and
keeps the tip (a plane of twice the samples would halve the default tip with it)."""

import dataclasses
import time

import pytest

from spine_mj import sweep
from spine_mj.validate.plans import HFIELD_DOUBLED, PLANS, RECOMMENDED
from spine_mj.validate.static_map import static_map
from spine_mj.validate.study_runner import StudyRunner


def test_the_hfield_doubled_probe_runs_on_the_same_plane_and_tip_with_its_hfield_refined(tmp_path):
    plan = dataclasses.replace(
        PLANS["smoke"], slopes_deg=(20.0,), azimuths_deg=(0.0,), static_engines=(RECOMMENDED, HFIELD_DOUBLED)
    )
    res = static_map(plan, StudyRunner(tmp_path, 1, None, time.perf_counter()))
    stores = sorted((tmp_path / "sweeps" / "static").iterdir())
    assert len(stores) == 2
    runs = {s.name: sweep.load_runs(s).iloc[0] for s in stores}
    base = next(r for n, r in runs.items() if n.endswith("default"))
    fine = next(r for n, r in runs.items() if "hfield_factor" in n)
    assert (base["hfield_refinement"], fine["hfield_refinement"]) == (1, 2)
    assert fine["tip_radius_m"] == base["tip_radius_m"]  # the tip kept
    # a plane's refined facets are the same plane: the breakaway does not move
    by = {r["engine"]: r for r in res.rows}
    assert by[HFIELD_DOUBLED[0]]["kappa_mj"] == pytest.approx(by[RECOMMENDED[0]]["kappa_mj"], rel=1e-3)
    assert set(res.convergence) == {"hfield_doubled"}
