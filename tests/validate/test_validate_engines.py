"""The closed forms in both engines (spine_mj.validate.engines, its wedges in
spine_mj.validate.wedges): the references, and the
cheap checks run in MuJoCo and Bullet."""

import math

import numpy as np
import pytest

from spine_mj import sim
from spine_mj.choices import COMPARED_ENGINES
from spine_mj.validate import engines as study
from spine_mj.validate import wedges
from spine_mj.validate.report.engines import section


def test_dai_threshold_is_the_friction_angle_rule():
    # self-lock iff the contact normal's elevation phi, sin(phi) = r / (R + r), is at most
    # the friction angle: R / r >= 1 / sin(arctan mu) - 1 (sqrt(5) - 1 for mu = 0.5)
    assert wedges.dai_threshold(0.5) == pytest.approx(math.sqrt(5) - 1)
    for mu in (0.3, 0.5, 1.0):
        ratio = wedges.dai_threshold(mu)
        assert math.asin(1 / (1 + ratio)) == pytest.approx(math.atan(mu))


def test_groove_is_a_v_rising_along_x():
    g = wedges.groove(20.0, 30.0, n=41)
    x, y = g.x, g.y
    assert g.heights[20, 20] == pytest.approx(0.0)
    np.testing.assert_allclose(g.heights[20], math.tan(math.radians(20)) * x, atol=1e-15)
    np.testing.assert_allclose(g.heights[:, 20], math.tan(math.radians(30)) * np.abs(y), atol=1e-15)


def test_dai_start_is_the_first_touch_of_the_faceted_sphere():
    tip = 1e-3
    surf = wedges.dai_surface(2e-3, tip)
    ball = sim.build_rig(surf, mu=0.5, tip_radius_m=tip, ie=1.0).contact_surface()
    x0, _ = wedges.dai_start(ball, 2e-3, tip)
    before = ball.height(np.array([x0 - 1e-3 * tip]), np.zeros(1))[0]
    at = ball.height(np.array([x0]), np.zeros(1))[0]
    assert before <= 1e-6 * tip < at


@pytest.mark.parametrize("engine", COMPARED_ENGINES)
def test_the_wedge_holds_more_than_one_contact_in_both_engines(engine):
    if engine == "bullet":
        pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    (row,) = study._groove_rows(engine)
    single = math.tan(math.radians(20) + math.atan(study.MU))
    assert row["ok"], row
    assert row["measured"] > 1.05 * single  # the wedge, not the single-contact rule


def test_flank_tilt_is_the_groove_planes_angle():
    """tan(alpha') = tan(alpha) cos(theta): the wedge's closed form then equals the force
    balance of two flank normals with friction along the groove's line."""
    t, a, mu = math.tan(math.radians(20)), math.tan(math.radians(30)), study.MU
    c, s = math.hypot(1, t), math.sqrt(1 + t * t + a * a)
    balance = (t * c + mu * s) / (c - mu * t * s)
    wedge = math.tan(math.radians(20) + math.atan(mu / math.cos(wedges.flank_tilt(20.0, 30.0))))
    assert wedge == pytest.approx(balance, rel=1e-12)
    assert wedges.flank_tilt(0.0, 30.0) == pytest.approx(math.radians(30))


def test_bullet_over_holds_dais_interlock_at_097_by_its_internal_edge_normals():
    """Measured cause of Bullet's self-lock at 0.97 x the threshold (closed form and facets:
    release at 10.37): the internal-edge adjustment of contact normals at the floor-sphere
    kink; without it the same run breaks away within 5 % of the facets' rule."""
    pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    (default,) = study._dai_rows("bullet", (0.97,))
    (edges_off,) = study._dai_rows("bullet", (0.97,), internal_edges=False)
    assert default["measured"] == "self-lock" and default["facets"] != "self-lock"
    assert edges_off["measured"] == pytest.approx(default["facets"], rel=0.05)


def test_section_sets_the_engines_side_by_side():
    res = study.EnginesResult(
        rows=[
            {
                "check": "static kappa",
                "case": "plane 0 deg",
                "closed_form": 0.5,
                "tolerance": "5%",
                "mujoco_measured": 0.5016,
                "mujoco_error": 0.0032,
                "mujoco_ok": True,
                "bullet_measured": 0.4992,
                "bullet_error": -0.0016,
                "bullet_ok": True,
            },
        ],
        engines=("mujoco", "bullet"),
        wall_s={"mujoco": 1.0, "bullet": 2.0},
    )
    text = section(res)
    assert "## Engines side by side: the closed forms" in text
    assert (
        "| static kappa | plane 0 deg | 0.5 | - | 0.5016 | +0.32% | yes | 0.4992 | -0.16% | yes | 5% |"
        in text
    )
    assert section(None) == ""


def test_the_result_round_trips_through_its_json():
    import json

    res = study.EnginesResult(
        rows=[
            {
                "check": "creep of a held tip",
                "case": "20 deg plane",
                "closed_form": 0.0,
                "tolerance": "shown",
                "mujoco_measured": 1e-17,
                "bullet_measured": 2e-8,
            }
        ],
        engines=("mujoco", "bullet"),
        wall_s={"mujoco": 1.0},
        fractal=[
            {
                "hurst": 0.8,
                "engine": e,
                "ie": 1e-4,
                "n": 3,
                "n_ok": 3,
                "locked": 1,
                "failed_runs": 0,
                "rate": 1 / 3,
                "ci_low": 0.06,
                "ci_high": 0.79,
            }
            for e in ("mujoco", "bullet")
        ],
    )
    back = study.EnginesResult.from_dict(json.loads(json.dumps(res.as_dict())))
    assert section(back) == section(res)
    assert "| 0.8 | 0.3333 (0.06-0.79; 1 / 3; 0) | 0.3333 (0.06-0.79; 1 / 3; 0) |" in section(res)


def test_the_validation_report_has_the_section_of_the_studys_result(tmp_path):
    """The engines study is a study of the registry: its result's section is in report.md,
    no file beside it is read."""
    from spine_mj.validate.report.document import write_report

    summary = {"plan": "smoke", "engine_settings": {}, "timings_s": {}}
    assert "Engines side by side" not in write_report(tmp_path, summary, []).read_text()
    res = study.EnginesResult(rows=[], engines=("mujoco", "bullet"), wall_s={"mujoco": 1.0})
    assert section(res) in write_report(tmp_path, summary, [res]).read_text()
    assert res.validation_keys() == {"engines": res.as_dict()}


def test_without_the_bullet_extra_the_validation_says_so_in_one_line(monkeypatch, tmp_path):
    from spine_mj import extras
    from spine_mj.validate.plans import PLANS
    from spine_mj.validate.study_runner import StudyRunner

    monkeypatch.setitem(extras.EXTRAS, "bullet", ("no_such_module_spine_mj",))
    res = study.engines_study(PLANS["smoke"], StudyRunner(tmp_path, 1, None, 0.0))
    assert res.missing == ("bullet",) and res.rows == []
    (title, line) = [t for t in section(res).splitlines() if t]
    assert title == "## Engines side by side: the closed forms"
    assert line.startswith("Bullet is not installed (the [bullet] extra: pip install 'spine-mj[bullet]')")


def test_the_plans_name_only_checks_the_study_has():
    from spine_mj.validate.plans import PLANS

    for plan in PLANS.values():
        assert plan.engines.checks is None or set(plan.engines.checks) <= set(study.CHECKS)
    with pytest.raises(study.SpineInputError, match="engines checks must be among"):
        study.engines_ground_truth(checks=("no such check",), engines=())


def test_the_old_python_m_entry_point_is_one_error_line_naming_the_command():
    # `python -m spine_mj.validate.engines --fractal 6` made the committed reports; it now
    # says where the comparisons went instead of exiting 0 having run nothing
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-m", "spine_mj.validate.engines", "--fractal", "6"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 2 and out.stdout == ""
    (line,) = out.stderr.splitlines()
    assert line.startswith("Error: ") and "--fractal 6" in line and "spine-mj compare-engines" in line
