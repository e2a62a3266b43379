"""array_outputs: the designer's files of a real array run say what the run measured."""

import json

import numpy as np
import pandas as pd
import pytest
from sim_rigs import MU, R_TIP

from spine_mj import sim
from spine_mj.errors import SpineInputError
from spine_mj.sim.array import ArrayRig
from spine_mj.sim.array_outputs import ARRAY_OUTPUTS, array_summary, write_array_outputs
from spine_mj.sim.layout import Layout
from spine_mj.surfaces.generators import inclined_plane


@pytest.fixture(scope="module")
def run():
    rig = sim.Rig(
        inclined_plane(slope_deg=10.0, half_width=0.05, n=101), tip=sim.TipParams(tip_radius_m=R_TIP, mu_s=MU)
    )
    arr = ArrayRig(rig, Layout(rows=1, cols=2, spacing=0.01, spacing_unit="surface"))
    speed = rig.scales.speed_for(1e-3)
    return arr.run(sim.SpringDrive(speed_m_s=speed, duration_s=2e-3 / speed), centre=(0.0, 0.0)), arr


def test_files_hold_the_runs_curve_spines_and_summary(tmp_path, run):
    res, arr = run
    paths = write_array_outputs(res, arr, tmp_path / "out")
    assert [p.name for p in paths] == list(ARRAY_OUTPUTS)
    curve = pd.read_csv(paths[0])
    np.testing.assert_allclose(curve["total_force_n"], res.total_force_n, rtol=1e-12)
    np.testing.assert_allclose(curve["carriage_x_m"], res.carriage_x_m, rtol=1e-12)
    spines = pd.read_csv(paths[1])
    scale = arr.rig.length_scale_m
    assert list(spines["spine"]) == [0, 1]
    np.testing.assert_allclose(spines["x0_m"], res.start_xy[:, 0] * scale, rtol=1e-12)
    np.testing.assert_allclose(
        spines["travel_m"], res.position_m[-1, :, 0] - res.start_xy[:, 0] * scale, rtol=1e-9
    )
    summary = json.loads(paths[2].read_text())
    assert summary == json.loads(json.dumps(summary))  # plain JSON, no NaN or Infinity
    assert summary["n_spines"] == 2 and summary["drive"] == "speed"
    assert summary["holding_ratio"] == pytest.approx(
        summary["holding_force_n"] / (2 * summary["preload_per_spine_n"])
    )
    assert summary["holding_force_per_spine_n"] == pytest.approx(res.holding_force_n / 2)
    assert summary["mu_s"] == MU and summary["layout"]["cols"] == 2
    assert paths[3].stat().st_size > 1000


def test_the_summary_is_the_records_of_the_rig_and_the_result(run):
    res, arr = run
    summary = array_summary(res, arr)
    assert summary["engine"] == arr.rig.engine.to_dict()
    assert summary["char_length_m"] == arr.rig.scales.char_length_m
    assert summary["holding_force_n"] == res.holding_force_n


def test_an_unusable_output_leaves_the_folder_as_it_was(tmp_path, run):
    res, arr = run
    out = tmp_path / "out"
    out.mkdir()
    (out / "curve.csv").write_text("old\n")
    (out / "layout.png").mkdir()  # the figure cannot be written: nothing may change
    with pytest.raises(SpineInputError):
        write_array_outputs(res, arr, out)
    assert (out / "curve.csv").read_text() == "old\n"
    assert not (out / "spines.csv").exists() and not (out / "summary.json").exists()
