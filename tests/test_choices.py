"""The names a user chooses among (engines, protocols, plans) and the engine registry: one
entry per engine drives the CLI, the sweep and build_rig alike."""

import json
import subprocess
import sys

import pandas as pd
import pytest
from click.testing import CliRunner
from sweep_support import write_config

from spine_mj import choices, sim, sweep
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.sim.step_rule import mujoco_settings
from spine_mj.surfaces import inclined_plane


def rk4_settings(scales, *, speed_m_s=None, stiffness_n_m=None, **options):
    """A third engine's settings: MuJoCo's step rule, always integrated with RK4."""
    return mujoco_settings(
        scales, speed_m_s=speed_m_s, stiffness_n_m=stiffness_n_m, integrator="rk4", **options
    )


@pytest.fixture
def third_engine(monkeypatch):
    """A third engine registered here alone (MuJoCo's rig, RK4 settings, the step its only
    option): no module of the package names it."""
    entry = choices.Engine(
        "mujoco-rk4",
        "MuJoCo integrated with RK4",
        rig=sim.Rig,
        settings=rk4_settings,
        options=("timestep_s",),
    )
    monkeypatch.setitem(choices.ENGINES, entry.name, entry)
    return entry


def test_the_name_lists_match_what_they_name():
    from spine_mj.validate.plans import PLANS

    assert choices.PLAN_NAMES == tuple(PLANS)
    assert set(choices.COMPARED_ENGINES) <= set(choices.ENGINES)
    assert choices.DEFAULT_ENGINE in choices.ENGINES
    assert choices.ENGINES["mujoco"].rig_class() is sim.Rig
    # MuJoCo's options are exactly the fields of its overrides record
    assert set(choices.ENGINES["mujoco"].options) == set(sim.EngineOverrides.__dataclass_fields__)
    surf = inclined_plane(slope_deg=10.0)
    for protocol in choices.PROTOCOLS:
        sim.build_drive(sim.build_rig(surf, mu=0.5, tip_radius_m=1e-3).scales, protocol)


def test_the_names_module_loads_nothing_heavy():
    heavy = "('numpy', 'mujoco', 'spine_mj.sim')"
    code = f"import sys, spine_mj.choices; print(sorted(m for m in {heavy} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_an_unknown_engine_and_an_option_it_does_not_read_are_refused(third_engine):
    surf = inclined_plane(slope_deg=10.0)
    with pytest.raises(SpineInputError, match=r"engine must be one of mujoco, .*mujoco-rk4, got 'ode'"):
        sim.build_rig(surf, engine="ode", mu=0.5)
    with pytest.raises(SpineInputError, match="impratio: not read by engine mujoco-rk4"):
        sim.build_rig(surf, engine="mujoco-rk4", mu=0.5, impratio=10.0)


def test_a_third_engine_runs_simulate(third_engine, tmp_path):
    out = tmp_path / "run"
    res = CliRunner().invoke(
        main,
        [
            *("simulate", "paper-single-peak", "--start", "-3,-1", "--resolution", "41"),
            *("--duration", "0.01", "--engine", "mujoco-rk4", "--out", str(out)),
        ],
    )
    assert res.exit_code == 0, res.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["engine"]["integrator"] == "rk4"
    # the same inputs in MuJoCo give the same rig but for the integrator
    base = sim.build_rig(inclined_plane(slope_deg=0.0), mu=0.5, tip_radius_m=1e-3)
    rk4 = sim.build_rig(inclined_plane(slope_deg=0.0), engine="mujoco-rk4", mu=0.5, tip_radius_m=1e-3)
    assert rk4.engine.timestep_s == base.engine.timestep_s
    assert (rk4.engine.integrator.value, base.engine.integrator.value) == ("rk4", "implicitfast")
    # its rig is MuJoCo's model, so --render draws it (refused only for want of the video
    # extra, a name not an engine's) and a replay plays it on its own settings
    from spine_mj.sim.model import has_mujoco_model
    from spine_mj.sim.run_folder import load_run

    assert has_mujoco_model("mujoco-rk4") and has_mujoco_model("mujoco")
    assert not has_mujoco_model("bullet")
    rig, _ = load_run(out)
    assert rig.engine.integrator.value == "rk4"


SWEEP = """
[sweep]
name = "third-engine"
analyses = ["engine"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
frame = "absolute"
points = [[-3.0, -1.0]]
[drive]
ie = 1e-3
duration = 0.01
[grid]
engine = ["mujoco", "mujoco-rk4"]
hfield_resolution = 41
"""


def test_a_third_engine_runs_a_sweep_case(third_engine, tmp_path):
    with pytest.raises(SpineInputError, match=r"impratio = \[10.0\]: not read by engine mujoco-rk4"):
        sweep.load_config(write_config(tmp_path, SWEEP + "impratio = 10\n"))
    out = tmp_path / "out"
    config = write_config(tmp_path, SWEEP)
    sweep.run_sweep(config, out, workers=1)
    runs = sweep.load_runs(out).set_index("engine")
    assert (runs.status == "ok").all()
    assert runs.loc["mujoco", "integrator"] == "implicitfast"
    # the integrator key is not an option of the third engine: its row records none applied
    assert pd.isna(runs.loc["mujoco-rk4", "integrator"])
    assert runs.loc["mujoco-rk4", "hfield_resolution"] == 41
    # on MuJoCo's rig class, its cases are checked before any run as MuJoCo's are: planned,
    # nothing compiled
    from spine_mj.sim.build import RigPlan
    from spine_mj.sweep.analyses.engine import case_plan

    plans = {c.params["engine"]: case_plan(c) for c in sweep.expand_cases(sweep.load_config(config))}
    assert all(isinstance(p, RigPlan) for p in plans.values()) and set(plans) == {"mujoco", "mujoco-rk4"}
