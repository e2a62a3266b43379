"""analysis/stickslip_engines.py's ``--dampratio``: the contact's damping ratio lowered at
the variant's own contact stiffness and step (issue 42 item 5's cells at damping 0.5)."""

from pathlib import Path

import pytest

from spine_mj import presets
from spine_mj.errors import SpineInputError
from spine_mj.sim.step_rule import rest_depth_m

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def script(analysis_script):
    return analysis_script("stickslip_engines")


@pytest.fixture(scope="module")
def strip(script):
    surf = presets.make_surface("abbm-short")
    return script.crop(surf, 100.0, 130.0)


def test_the_damping_falls_at_the_same_stiffness(script):
    tc, r0 = 3e-4, 1.0
    got = script.at_dampratio((tc, r0), 0.5)
    assert got["solref_dampratio"] == 0.5
    # MuJoCo: stiffness ~ 1 / (tc r)^2 (kept), damping ~ 1 / tc (halved)
    assert got["solref_timeconst_s"] * got["solref_dampratio"] == pytest.approx(tc * r0, rel=1e-12)
    assert tc / got["solref_timeconst_s"] == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("bad", [0.0, -0.5, float("nan")])
def test_a_bad_ratio_is_refused_by_name(script, bad):
    with pytest.raises(SpineInputError, match="dampratio"):
        script.at_dampratio((3e-4, 1.0), bad)


def test_the_dt2_rig_at_half_damping(script, strip):
    rule = script._variant("mujoco", "dt2", 1e-5, 2.0, strip)
    low = script._variant("mujoco", "dt2", 1e-5, 2.0, strip, 0.5)
    dt = rule.engine.timestep_s
    assert low.engine.timestep_s == dt
    assert rule.engine.solref == pytest.approx((2 * dt, 1.0), rel=1e-12)
    assert low.engine.solref == pytest.approx((4 * dt, 0.5), rel=1e-12)
    # the resting depth, set by the contact's stiffness, is the rule's
    assert rest_depth_m(low.engine, low.scales) == pytest.approx(
        rest_depth_m(rule.engine, rule.scales), rel=1e-12
    )
    # the model's contact geoms carry it: each of the rule's (2 dt, 1) rows is (4 dt, 0.5)
    contact = (rule.model.geom_solref[:, 1] == 1.0) & (low.model.geom_solref[:, 1] == 0.5)
    assert contact.any()
    assert low.model.geom_solref[contact, 0] == pytest.approx(2 * rule.model.geom_solref[contact, 0])


@pytest.mark.parametrize("text", ["0", "-1", "soft"])
def test_the_option_is_one_error_line(script, capsys, text):
    with pytest.raises(SystemExit) as exit_:
        script.main(["--dampratio", text])
    err = capsys.readouterr().err.strip().splitlines()
    assert exit_.value.code == 2
    assert f"--dampratio expects a positive number, got {text!r}" in err[-1]
