"""The CLI's simulate, sim export and view commands."""

from __future__ import annotations

import mujoco
import pytest


def test_cli_simulate_export_and_view(tmp_path, monkeypatch):
    import pandas as pd
    from click.testing import CliRunner

    from spine_mj.cli import main

    runner = CliRunner()
    res = runner.invoke(
        main,
        [
            "simulate",
            "paper-single-peak",
            "--start",
            "-3,-1",
            "--drive",
            "spring",
            "--speed",
            "0.05",
            "--duration",
            "0.05",
            "--out",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    table = pd.read_parquet(tmp_path / "trajectory.parquet")
    assert len(table) > 100 and (tmp_path / "run.png").stat().st_size > 0
    res = runner.invoke(main, ["sim", "export", "paper-single-peak", "-o", str(tmp_path / "rig.xml")])
    assert res.exit_code == 0 and mujoco.MjModel.from_xml_path(str(tmp_path / "rig.xml")).nhfield == 1
    res = runner.invoke(main, ["simulate", "paper-single-peak", "--start", "-3", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "--start must look like X,Y" in res.output
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    res = runner.invoke(main, ["view", "paper-single-peak"])
    assert res.exit_code != 0 and "no display" in res.output and "Traceback" not in res.output


def test_a_missing_gl_backend_is_one_error_line_naming_it(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from spine_mj.cli import main

    def no_gl(*args, **kwargs):
        raise mujoco.FatalError("an OpenGL platform library has not been loaded")

    monkeypatch.setattr(mujoco, "Renderer", no_gl)
    pytest.importorskip("imageio", reason="needs the optional extra 'video': pip install 'spine-mj[video]'")
    res = CliRunner().invoke(
        main,
        [
            *("simulate", "paper-single-peak", "--start", "-3,-1", "--resolution", "41"),
            *("--duration", "0.01", "--render", "--out", str(tmp_path / "run")),
        ],
    )
    assert res.exit_code == 2, res.output
    assert res.output.strip().startswith("Error: no headless renderer") and "OpenGL platform" in res.output
    assert not (tmp_path / "run").exists()


def test_cli_simulate_on_a_long_narrow_track(tmp_path):
    """A track 21 x 4001 samples (4 wide, 200 long): the run and its figure (whose display
    grid thins each axis on its own, so the 21 rows stay 21) are written."""
    import numpy as np
    from click.testing import CliRunner

    from spine_mj.cli import main
    from spine_mj.surface_io import save_surface
    from spine_mj.surfaces import GridSurface

    x, y = np.linspace(0, 200, 4001), np.linspace(0, 4, 21)
    heights = 0.3 * np.sin(1.3 * x)[None, :] + 0.05 * np.cos(1.7 * y)[:, None]
    path = save_surface(GridSurface(heights=heights, x=x, y=y), tmp_path / "track.npz")
    out = tmp_path / "run"
    res = CliRunner().invoke(
        main,
        ["simulate", str(path), "--mu", "0.5", "--start", "10,2", "--duration", "0.3", "--out", str(out)],
    )
    assert res.exit_code == 0, res.output
    assert (out / "run.png").stat().st_size > 0 and "heights must have" not in res.output


def test_cli_simulate_and_surface_info_on_a_y_varying_strip_with_the_tip_on_its_line(tmp_path):
    """A strip 4 wide whose heights vary along y: `surface info` reports it, `simulate
    --line` keeps the tip on y0 along the whole run (free, it left the strip)."""
    import json

    import numpy as np
    import pandas as pd
    from click.testing import CliRunner

    from spine_mj.cli import main
    from spine_mj.surface_io import save_surface
    from spine_mj.surfaces import GridSurface

    x, y = np.linspace(0, 60, 1201), np.linspace(0, 4, 81)
    heights = 0.3 * np.sin(1.3 * x)[None, :] + 0.4 * np.sin(2 * np.pi * y / 8)[:, None]
    path = save_surface(GridSurface(heights=heights, x=x, y=y), tmp_path / "strip.npz")
    info = CliRunner().invoke(main, ["surface", "info", str(path), "--mu", "0.5", "--json"])
    assert info.exit_code == 0, info.output
    assert json.loads(info.stdout)["slope_correlation_length"] > 0
    run = ["simulate", str(path), "--mu", "0.5", "--start", "10,1", "--duration", "1", "--line"]
    res = CliRunner().invoke(main, [*run, "--out", str(tmp_path / "run")])
    assert res.exit_code == 0, res.output
    y_m = pd.read_parquet(tmp_path / "run" / "trajectory.parquet")["position_y_m"].to_numpy()
    assert np.abs(y_m / 0.01 - 1.0).max() < 1e-6  # a grid without a unit: 0.01 m a unit


def test_bullet_which_has_no_rail_refuses_line_in_one_line_with_nothing_written(tmp_path):
    from click.testing import CliRunner

    from spine_mj.cli import main

    pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    run = ["simulate", "paper-single-peak", "--start", "-3,-1", "--duration", "0.01", "--line"]
    res = CliRunner().invoke(main, [*run, "--engine", "bullet", "--out", str(tmp_path / "bullet")])
    assert res.exit_code == 2 and res.output.strip().splitlines() == [
        "Error: line: not read by engine bullet (its options: timestep_s)"
    ], res.output
    assert not (tmp_path / "bullet").exists()
