"""The ``array`` analysis: an ``[array]`` table in a sweep gives the command's summary keys."""

import numpy as np
import pytest
from sweep_support import write_config

from spine_mj import sweep
from spine_mj.errors import SpineInputError
from spine_mj.surfaces import inclined_plane

ARRAY = """
[sweep]
name = "arrays"
analyses = ["array"]
[[surfaces]]
preset = "corrugation"
[starts]
frame = "absolute"
points = [[1.0, 0.0], [2.3, 0.0]]
[drive]
ie = 1e-2
duration = 0.02
[array]
layout = ["grid", "staggered"]
rows = 2
cols = 2
spacing = 0.15
spacing_unit = "surface"
"""


def test_array_sweep_records_the_summary_keys_per_layout_and_centre(tmp_path):
    from spine_mj import sim

    out = tmp_path / "out"
    summary = sweep.run_sweep(write_config(tmp_path, ARRAY), out, workers=1)
    assert summary.total_runs == 4
    runs = sweep.load_runs(out)
    assert (runs.status == "ok").all() and (runs.n_spines == 4).all()
    assert set(runs.layout) == {"grid", "staggered"}
    np.testing.assert_allclose(runs.holding_ratio * 4 * 0.01 * 9.81, runs.holding_force_n, rtol=1e-9)
    # the grid case's rows are the ArrayRig's own runs on the case's rig
    from spine_mj.sweep.analyses.engine import case_rig

    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, ARRAY)))
    case = next(c for c in cases if c.params["layout"] == "grid")
    rig = case_rig(case)
    arr = sim.ArrayRig(rig, sim.Layout(rows=2, cols=2, spacing=0.15, spacing_unit="surface"))
    v = rig.scales.speed_for(1e-2)
    direct = arr.run_batch(sim.SpringDrive(speed_m_s=v, duration_s=0.02), [(1.0, 0.0), (2.3, 0.0)], nthread=1)
    grid = runs[runs.layout == "grid"].sort_values("start")
    np.testing.assert_allclose(grid.holding_force_n, [r.holding_force_n for r in direct], rtol=1e-9)


def test_array_key_given_twice_is_refused(tmp_path):
    doc = ARRAY + "[grid]\nrows = 3\n"
    with pytest.raises(SpineInputError, match=r"array\.rows: also given as grid\.rows"):
        sweep.load_config(write_config(tmp_path, doc))


@pytest.mark.parametrize(
    ("table", "match"),
    [
        # over the spine limit: refused by the config, not recorded `failed` run by run
        (
            "rows = 17\ncols = 16",
            r"config \[array\]: an array has at most 256 spines, got rows x cols = 17 x 16",
        ),
        # a seed no layout reads
        (
            'layout = ["grid", "staggered"]\nlayout_seed = 5',
            r"layout_seed = \[5\]: the grid and staggered layout ignores",
        ),
    ],
)
def test_array_layouts_the_command_refuses_are_refused_at_config_time(tmp_path, table, match):
    doc = ARRAY.split("[array]")[0] + "[array]\n" + table + "\n"
    with pytest.raises(SpineInputError, match=match):
        sweep.load_config(write_config(tmp_path, doc))


def test_array_sweep_without_a_pace_runs_at_the_arrays_default_pace(tmp_path):
    # the predicted holding excess of the default pace is 1 % of mu F_p
    doc = ARRAY.replace("ie = 1e-2\n", "").replace('layout = ["grid", "staggered"]', 'layout = "grid"')
    out = tmp_path / "out"
    sweep.run_sweep(write_config(tmp_path, doc), out, workers=1)
    runs = sweep.load_runs(out)
    from spine_mj import presets

    mu = presets.preset_mu("corrugation")
    np.testing.assert_allclose(runs.holding_excess_predicted, 0.01 * mu, rtol=1e-9)


def test_arrays_on_bullet_are_refused_in_one_line(tmp_path):
    """Arrays run in MuJoCo only (one MuJoCo model of N tips and their carriage): engine
    bullet is refused at config time, and an ArrayRig on a Bullet rig the same way."""
    pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    from spine_mj import sim

    doc = ARRAY + '[grid]\nengine = ["mujoco", "bullet"]\n'
    with pytest.raises(SpineInputError, match=r"^engine bullet: spine arrays run in MuJoCo only") as err:
        sweep.load_config(write_config(tmp_path, doc))
    assert "\n" not in str(err.value)
    rig = sim.build_rig(inclined_plane(slope_deg=0.0), engine="bullet", mu=0.5)
    with pytest.raises(SpineInputError, match="spine arrays run in MuJoCo only"):
        sim.ArrayRig(rig, sim.Layout(rows=2, cols=2))
