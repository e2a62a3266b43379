"""The static map's solution verification: its hfield x 2 refines the plane's hfield and
keeps the tip (a plane of twice the samples would halve the default tip with it)."""

import dataclasses
import time

import pytest

from spine_mj import sweep
from spine_mj.validate.plan_sections import StaticPlan
from spine_mj.validate.plans import HFIELD_DOUBLED, PLANS, RECOMMENDED
from spine_mj.validate.static_map import static_map
from spine_mj.validate.study_runner import StudyRunner


def test_the_hfield_doubled_probe_runs_on_the_same_plane_and_tip_with_its_hfield_refined(tmp_path):
    static = StaticPlan(slopes_deg=(20.0,), azimuths_deg=(0.0,), engines=(RECOMMENDED, HFIELD_DOUBLED))
    plan = dataclasses.replace(PLANS["smoke"], static=static)
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


@pytest.mark.parametrize("slope", [0.0, 20.0, 45.0, 60.0])
def test_the_tilt_gain_is_the_closed_form_pole_of_tan_theta_plus_phi(slope):
    """In the drive's section kappa = tan(theta + phi): d ln(kappa) / d theta =
    2 / sin(2 (theta + phi)), which grows without bound toward the self-lock pole."""
    import math

    from spine_mj.validate.static_map import equivalent_tilt_deg, kappa_tilt_gain

    mu = 0.5
    total = math.radians(slope) + math.atan(mu)
    gain = kappa_tilt_gain(slope, 0.0, mu)
    assert gain == pytest.approx(2 / math.sin(2 * total) * math.pi / 180, rel=1e-4)  # central difference
    # a breakaway from a plane tilted 0.05 deg more reads as that tilt on every plane
    ratio = math.tan(total + math.radians(0.05)) / math.tan(total)
    assert equivalent_tilt_deg(ratio, gain) == pytest.approx(0.05, rel=0.02)
    assert math.isnan(kappa_tilt_gain(70.0, 0.0, mu))  # self-locked: no kappa to perturb
