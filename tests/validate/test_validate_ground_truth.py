"""The ground-truth study at smoke size: each closed form against MuJoCo, and its report."""

import math

import pytest

from spine_mj import sim
from spine_mj.validate.ground_truth import ground_truth, spring_block_ladder
from spine_mj.validate.plans import PLANS
from spine_mj.validate.report.ground_truth import ground_truth_section
from spine_mj.validate.study_runner import StudyRunner


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    out = tmp_path_factory.mktemp("gt")
    return ground_truth(PLANS["smoke"], StudyRunner(out, 1, None, 0.0))


def test_ground_truth_errors_are_small_at_smoke_size(smoke):
    b = smoke.spring_block
    assert (
        abs(b["period_rel_error"]) < 0.03 and abs(b["peak_speed_rel_error"]) < 0.15 and b["slip_events"] == 0
    )
    below, above = sorted(smoke.tomlinson, key=lambda r: r["K"])
    assert above["slip_events"] == 0 and above["max_speed_v"] < 5
    assert below["slip_events"] >= 1 and abs(below["onset_max_rel_error"]) < 0.05
    assert abs(below["slope_length_rel_error"]) < 0.01
    # the rigid reference with the run's m, k, W, V: the K*/4 jump overshoots a wavelength
    assert below["ref_events_per_wave"] < 1 and below["ref_max_jump_waves"] > 1.1
    assert abs(below["ref_onset_max_rel_error"]) < 0.05
    (lift,) = smoke.liftoff
    assert lift["ie_star_predicted"] == pytest.approx(0.55)
    assert len(lift["crest_gap_radii"]) == 2 and math.isfinite(lift["crest_gap_radii"][0])


def test_ground_truth_section_names_each_check(smoke):
    text = ground_truth_section(smoke)
    assert "Spring-block" in text and "Prandtl-Tomlinson" in text and "Lift-off" in text
    assert "reference longest jump" in text
    assert ground_truth_section(None) == ""


def test_the_step_rule_keeps_the_spring_block_period_at_every_stiffness():
    """K = 3 ... 30000 (issue: engine stops at K = 3000): the rig built for the spring
    integrates it at omega dt <= 0.3, so the swing's period is the closed form's within 2 %
    and no run stops (the period's error from the step alone is (omega dt)^2 / 24 < 0.4 %)."""
    rows = spring_block_ladder()
    assert [round(r["stiffness_number_K"]) for r in rows] == [3, 30, 300, 3000, 30000]
    for r in rows:
        assert r["end_reason"] == "completed" and r["slip_events"] == 0, r
        assert r["omega_dt"] <= sim.SPRING_OMEGA_DT * (1 + 1e-9), r
        assert abs(r["period_rel_error"]) < 0.02, r
    stiff = rows[-1]
    assert abs(stiff["peak_speed_rel_error"]) < 0.1, stiff
