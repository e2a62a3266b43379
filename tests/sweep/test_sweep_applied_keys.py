"""Every key of a sweep is applied to its runs or refused before any run: MuJoCo's solver
options on Bullet cases, the single-spine drive keys on arrays (issue 44)."""

import pandas as pd
import pytest
from sweep_support import write_config

from spine_mj import sweep
from spine_mj.errors import SpineInputError

ENGINES = """
[sweep]
name = "engines"
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
engine = ["mujoco", "bullet"]
hfield_resolution = 41
"""

MUJOCO_ONLY = [
    ('integrator = "euler"', "integrator = ['euler']"),
    ("noslip_iterations = 0", "noslip_iterations = [0]"),
    ("tolerance = 1e-10", "tolerance = [1e-10]"),
    ("timestep_factor = 0.5", "timestep_factor = [0.5]"),
    ("solref_dampratio = 0.7", "solref_dampratio = [0.7]"),
    ('cone = "pyramidal"', "cone = ['pyramidal']"),
    ("impratio = 10", "impratio = [10"),
]


@pytest.mark.parametrize(("line", "named"), MUJOCO_ONLY)
def test_mujoco_solver_options_are_refused_for_bullet_as_simulate_refuses_them(tmp_path, line, named):
    pytest.importorskip("pybullet")
    with pytest.raises(SpineInputError, match="not read by engine bullet") as err:
        sweep.load_config(write_config(tmp_path, ENGINES + line + "\n"))
    assert named in str(err.value)
    # the same key on MuJoCo alone is a setting MuJoCo applies
    alone = ENGINES.replace('engine = ["mujoco", "bullet"]', 'engine = "mujoco"')
    sweep.load_config(write_config(tmp_path, alone + line + "\n"))


def test_a_bullet_row_records_none_for_the_solver_options_it_did_not_apply(tmp_path):
    pytest.importorskip("pybullet")
    out = tmp_path / "out"
    sweep.run_sweep(write_config(tmp_path, ENGINES), out, workers=1)
    runs = sweep.load_runs(out).set_index("engine")
    assert (runs.status == "ok").all()
    for key in ("integrator", "cone", "noslip_iterations", "impratio", "solref_dampratio"):
        assert pd.isna(runs.loc["bullet", key]) and not pd.isna(runs.loc["mujoco", key]), key
    assert runs.loc["mujoco", "integrator"] == "implicitfast"
    # what both engines read stays recorded
    assert runs.loc["bullet", "hfield_resolution"] == 41


ARRAY = """
[sweep]
name = "arrays"
analyses = ["array"]
[[surfaces]]
preset = "corrugation"
[starts]
frame = "absolute"
points = [[1.0, 0.0]]
[array]
rows = 1
cols = 2
spacing = 0.15
spacing_unit = "surface"
"""


@pytest.mark.parametrize(
    ("lines", "named"),
    [
        ('array_drive = "force"\n[drive]\nduration = 0.02', "the force array drive ignores it"),
        ('[drive]\nprotocol = "static"', "not the static protocol"),
        ('[drive]\nprotocol = "ramp"', "not the ramp protocol"),
        ("[drive]\nstart_force = 0.01", "start_force"),
        ("[drive]\nie = 1e-3\nspeed = 0.1", "give one of them"),
    ],
)
def test_array_drive_keys_the_array_does_not_read_are_refused(tmp_path, lines, named):
    with pytest.raises(SpineInputError, match=named):
        sweep.load_config(write_config(tmp_path, ARRAY + lines + "\n"))


def test_the_sweeps_solver_defaults_are_the_step_rules():
    """MuJoCo's solver defaults have one home (``EngineSettings`` and the step rule): a
    sweep's engine keys left out are the settings ``simulate`` runs with no option, and
    their choices are the settings' own."""
    from spine_mj import sim
    from spine_mj.surfaces import inclined_plane
    from spine_mj.sweep.analyses.engine import ENGINE_PARAMS

    rule = sim.default_engine(sim.build_rig(inclined_plane(slope_deg=0.0), mu=0.5, tip_radius_m=1e-3).scales)
    rule_value = {"solref_dampratio": rule.solref[1], "solref_timeconst_s": rule.solref[0]}
    checked = []
    for spec in ENGINE_PARAMS:
        if spec.option is None or spec.default is None:
            continue
        value = rule_value.get(spec.option, getattr(rule, spec.option, None))
        assert getattr(value, "value", value) == spec.default, spec.name
        checked.append(spec.name)
    assert set(checked) == {"integrator", "cone", "impratio", "noslip_iterations", "solref_dampratio"}
    by_name = {s.name: s for s in ENGINE_PARAMS}
    assert by_name["integrator"].choices == tuple(i.value for i in sim.Integrator)
    assert by_name["cone"].choices == tuple(c.value for c in sim.Cone)
