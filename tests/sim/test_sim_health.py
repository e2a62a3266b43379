"""Engine blow-ups are never recorded as physics: real `spine-mj` commands, as a user runs them."""

import json
import os
import re

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj.cli import main


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def simulate(*args):
    return CliRunner().invoke(main, ["simulate", "paper-single-peak", "--start", "-3,-1", *map(str, args)])


def test_a_spring_the_step_cannot_integrate_is_refused_and_leaves_no_mujoco_log(in_tmp):
    # a 1e12 N/m spring with a 10 ms step blew up into MuJoCo's "Nan, Inf or huge value in
    # QACC"; the step rule's bound (sim.step_rule.MAX_SPRING_OMEGA_DT) refuses it before running
    result = simulate("--stiffness", 1e12, "--timestep", 0.01, "--out", "run")
    assert result.exit_code == 2, result.output
    assert re.search(r"drive spring .* swings 1e\+05 rad in one time step .* at most 6e-08 s", result.output)
    assert len(result.output.strip().splitlines()) == 1
    assert sorted(os.listdir(in_tmp)) == []


def test_a_stiff_spring_gets_a_step_that_integrates_it(in_tmp):
    """K = 30000 on the single peak: the step rule refines the step for the spring."""
    result = simulate("--K", 30000, "--duration", 0.02, "--out", "run")
    assert result.exit_code == 0, result.output
    summary = json.loads((in_tmp / "run" / "summary.json").read_text())
    assert summary["end_reason"] == "completed", summary["end_detail"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        # a speed beyond the largest inertia number, given as a speed rather than an I_e
        (["--speed", 1e6], r"the drive's inertia number I_e \(speed 1e\+06 m/s\) must be <= 10000"),
        # a step so coarse that the contact rests the tip deeper than the tolerance
        (["--timestep", 1], r"rests the tip 0\.392 m deep .* at most 0\.0113 s"),
        # the carriage crossing a quarter of an asperity per step
        (["--timestep", 0.01, "--ie", 1], r"the drive advances 0\.256 L_c in one time step"),
        (["--timestep", 1e-12], r"timestep_s must be at least 1e-09 of the time scale tau"),
    ],
)
def test_a_drive_or_step_the_engine_cannot_resolve_is_refused_before_running(in_tmp, args, message):
    """Before these were refused, a 1 s step at 1e6 m/s sank the tip through the surface and
    a 10 ms step at I_e = 1e4 'self-locked' at the force cap in its first step."""
    result = simulate(*args, "--out", "run")
    assert result.exit_code == 2 and re.search(message, result.output), result.output
    assert len(result.output.strip().splitlines()) == 1
    assert not (in_tmp / "run").exists()


def test_an_absurd_inertia_number_is_refused_before_running(in_tmp):
    result = simulate("--ie", 1e300, "--out", "run")
    assert result.exit_code == 2 and "inertia number I_e must be <= " in result.output
    assert not (in_tmp / "run").exists()
    config = in_tmp / "s.toml"
    config.write_text(
        '[sweep]\nname = "x"\nanalyses = ["engine"]\n[[surfaces]]\npreset = "paper-single-peak"\n'
        '[starts]\nframe = "absolute"\npoints = [[-3.0, -1.0]]\n[drive]\nprotocol = "spring"\n'
        "[grid]\nie = [1e300]\n"
    )
    result = CliRunner().invoke(main, ["sweep", str(config), "--out", "sw", "--quiet"])
    assert result.exit_code == 2 and "grid.ie" in result.output and "<= 10000" in result.output
    assert not (in_tmp / "sw").exists()


def test_a_fall_off_a_cliff_lands_within_the_tolerance_by_the_step_rule():
    """A tip pulled off a 20-radius cliff lands at ~1.2 sqrt(F_p L_c / m), far faster than
    the drive: the step the resting and drive-speed rules give (``fall_height_m`` zeroed)
    lets it sink 0.1-0.3 tip radii on landing, depending on where the last step before
    the floor falls, and stops most runs on penetration, which the detail calls a
    landing. With the fall in the rule (sim.scales.fall_height) every run lands within
    the impact depth the rule aims at (5 % of the radius; measured up to 5.8 %)."""
    import dataclasses

    import numpy as np

    from spine_mj import sim
    from spine_mj.surfaces import GridSurface

    x, y = np.linspace(-1e-3, 1e-3, 96), np.linspace(-0.5e-3, 0.5e-3, 48)
    cliff_m = 0.4e-3
    mesa = GridSurface(heights=np.tile(np.where(x < 0, cliff_m, 0.0), (y.size, 1)), x=x, y=y, unit="m")
    tip = sim.TipParams(tip_radius_m=20e-6, mu_s=0.5)
    scales = sim.Scales.for_surface(mesa, tip=tip)
    dx = x[1] - x[0]
    assert scales.fall_height_m == pytest.approx(
        (cliff_m - 0.5 * dx) * cliff_m**2 / (cliff_m**2 + dx**2), rel=1e-6
    )
    speed = scales.speed_for(1e-2)
    starts = [(-x0, 0.0) for x0 in np.linspace(0.05e-3, 0.3e-3, 8)]  # landings at 8 phases of the step
    depth = {}
    for name, sc in (("rule", scales), ("no fall", dataclasses.replace(scales, fall_height_m=0.0))):
        rig = sim.Rig(mesa, tip=tip, engine=sim.default_engine(sc, speed_m_s=speed))
        runs = rig.run_batch(sim.SpringDrive(speed_m_s=speed), starts, refine=False)
        depth[name] = np.array([r.penetration_m.max() for r in runs]) / tip.tip_radius_m
        if name == "rule":
            assert all(r.engine_trouble == "" for r in runs)
        else:
            stopped = [r for r in runs if r.engine_trouble == "penetration"]
            assert len(stopped) >= 3 and all("landing at" in r.end_detail for r in stopped)
    assert depth["rule"].max() < 0.07
    assert depth["no fall"].max() > 0.2


def test_a_penetration_stop_is_run_again_at_a_quarter_of_the_step(monkeypatch):
    """The engine rule made too coarse on purpose (impacts allowed twice the tolerance
    deep): landings on the peak's fast runs then sink too far; run_batch runs each such run
    once more at a quarter of the step, and the result carries the step it ran at."""
    from spine_mj import presets, sim
    from spine_mj.sim import step_rule

    monkeypatch.setattr(step_rule, "_IMPACT_DEPTH_OF_TOLERANCE", 2.0)
    monkeypatch.setattr(step_rule, "_LANDING_SPEED_FACTOR", 1.0)
    surface, tip = presets.make_surface("paper-single-peak"), sim.TipParams(mu_s=1.23)
    scales = sim.Scales.for_surface(surface, tip=tip)
    speed = scales.speed_for(0.1)
    rig = sim.Rig(surface, tip=tip, engine=sim.default_engine(scales, speed_m_s=speed))
    starts = [(-3.0, -1.0), (-3.0, -2.0)]
    drive = sim.SpringDrive(speed_m_s=speed)
    coarse = rig.run_batch(drive, starts, nthread=1, refine=False)
    stopped = [r.engine_trouble == "penetration" for r in coarse]
    assert any(stopped)
    runs = rig.run_batch(drive, starts, nthread=1)
    dt = rig.engine.timestep_s
    for run, was_stopped, before in zip(runs, stopped, coarse):
        assert run.engine.timestep_s == pytest.approx(dt * sim.REFINE_TIMESTEP if was_stopped else dt)
        assert run.engine_trouble == ""
        if not was_stopped:  # a run that was fine is the same run
            np.testing.assert_array_equal(run.position_m, before.position_m)
