"""Engine blow-ups are never recorded as physics: real `spine-mj` commands, as a user runs them."""

import json
import os

import pytest
from click.testing import CliRunner

from spine_mj.cli import main


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def simulate(*args):
    return CliRunner().invoke(main, ["simulate", "paper-single-peak", "--start", "-3,-1", *map(str, args)])


@pytest.mark.parametrize(
    ("args", "detail"),
    [
        # a 1 s step at 1e6 m/s: the tip is flung through the surface
        (["--timestep", 1, "--speed", 1e6], "below the surface"),
        # a 1e12 N/m spring with a 10 ms step: MuJoCo's "Nan, Inf or huge value in QACC"
        (["--stiffness", 1e12, "--timestep", 0.01], "MuJoCo warning"),
    ],
)
def test_engine_blow_ups_end_as_engine_trouble_and_leave_no_mujoco_log(in_tmp, args, detail):
    result = simulate(*args, "--out", "run")
    assert result.exit_code == 0, result.output
    summary = json.loads((in_tmp / "run" / "summary.json").read_text())
    assert summary["end_reason"] == "engine_trouble"
    assert detail in summary["end_detail"]
    assert not (in_tmp / "MUJOCO_LOG.TXT").exists()
    assert sorted(os.listdir(in_tmp)) == ["run"]


def test_an_absurd_inertia_number_is_refused_before_running(in_tmp):
    result = simulate("--ie", 1e300, "--out", "run")
    assert result.exit_code == 2 and "inertia number I_e must be <= " in result.output
    assert not (in_tmp / "run").exists()
    config = in_tmp / "s.toml"
    config.write_text(
        '[sweep]\nname = "x"\nanalyses = ["mujoco"]\n[[surfaces]]\npreset = "paper-single-peak"\n'
        '[starts]\nframe = "absolute"\npoints = [[-3.0, -1.0]]\n[drive]\nprotocol = "spring"\n'
        "[grid]\nie = [1e300]\n"
    )
    result = CliRunner().invoke(main, ["sweep", str(config), "--out", "sw", "--quiet"])
    assert result.exit_code == 2 and "grid.ie" in result.output and "<= 10000" in result.output
    assert not (in_tmp / "sw").exists()
