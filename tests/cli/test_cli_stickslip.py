"""``spine-mj stickslip``: the references' catalog and statistics of an ABBM track, and one
Error line for bad input with nothing written."""

import json

import pandas as pd
import pytest
from click.testing import CliRunner

from spine_mj import surfaces
from spine_mj.cli import main
from spine_mj.surface_io import save_surface


@pytest.fixture(scope="module")
def track(tmp_path_factory):
    surf = surfaces.abbm_track(
        length=2000.0, points=20001, width=0.5, slope_intensity=1e-5, correlation_length=1000.0, rng=3
    )
    return save_surface(surf, tmp_path_factory.mktemp("track") / "abbm.npz")


def test_stickslip_writes_the_catalog_and_tau(track, tmp_path):
    out = tmp_path / "slips"
    result = CliRunner().invoke(
        main, ["stickslip", str(track), "--mu", "0.5", "--K", "4.36", "--bootstrap", "10", "--out", str(out)]
    )  # k = 4.36e-3 W / unit, S_m 8 spacings: K 1 when this track's l_s was measured (230, not xi)
    assert result.exit_code == 0, result.output
    events = pd.read_parquet(out / "events.parquet")
    assert {"source", "K", "ie", "size_lc", "duration_s", "force_drop_fp"} <= set(events.columns)
    summary = json.loads((out / "summary.json").read_text())
    od = summary["sources"]["overdamped"]["4.36"]
    assert od["n_events"] >= 300
    assert od["tau"]["low"] < od["tau"]["value"] < od["tau"]["high"]
    assert set(od["likelihood_ratios"]) == {"lognormal", "exponential", "truncated_power_law"}
    assert "overdamped" in result.output and "tau" in result.output
    assert (out / "collapse.png").is_file() and (out / "distributions.png").is_file()
    assert (out / "pulse.png").is_file()
    pulse = summary["pulse"]["overdamped"]["4.36"]
    assert len(pulse["shape"]) == 41 and max(pulse["shape"]) == pytest.approx(1.0)
    assert pulse["parabola_deviation"] < 0.2  # ABBM's parabola
    inertial = summary["pulse"]["inertial"]["4.36"]["shape"]
    assert inertial.index(max(inertial)) > 0.6 * 40  # a tip with mass stops abruptly


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--K", "0.5,x"], "--K"),
        (["--K", "-1"], "--K"),
        (["--K", "1", "--ie", "nan"], "--ie"),
        (["--K", "1", "--travel", "1e9"], "--travel"),
        (["--K", "1", "--drop-floor", "0"], "--drop-floor"),
    ],
)
def test_bad_input_is_one_error_line_and_nothing_written(track, tmp_path, args, needle):
    out = tmp_path / "slips"
    result = CliRunner().invoke(main, ["stickslip", str(track), "--mu", "0.5", "--out", str(out), *args])
    assert result.exit_code == 2
    assert needle in result.output and "Traceback" not in result.output
    assert not out.exists() or not any(out.iterdir())


def test_an_unknown_engine_is_one_error_line_naming_the_registry(monkeypatch, tmp_path):
    """--engine is checked against the registry when the command runs, as simulate's is: an
    engine registered after the CLI loaded is accepted, an unknown name refused."""
    from spine_mj import choices

    third = choices.Engine("third", "a third engine", rig="x:Y", settings="x:y", options=())
    monkeypatch.setitem(choices.ENGINES, third.name, third)
    res = CliRunner().invoke(
        main, ["stickslip", "abbm", "--K", "0.5", "--engine", "ode", "--out", str(tmp_path / "o")]
    )
    assert res.exit_code == 2 and res.output.count("\n") == 1, res.output
    assert res.output.startswith("Error: --engine must be one of mujoco, bullet, third, got 'ode'")
    assert not (tmp_path / "o").exists()


def test_k_defaults_to_the_abbm_range_on_an_abbm_track_and_is_required_elsewhere(track, tmp_path):
    from spine_mj.presets import open_surface

    out = tmp_path / "slips"
    ok = CliRunner().invoke(
        main,
        ["stickslip", str(track), "--mu", "0.5", "--bootstrap", "10", "--travel", "500", "--out", str(out)],
    )
    assert ok.exit_code == 0, ok.output
    expected = surfaces.abbm_stiffness_numbers(open_surface(str(track)), 0.5)
    assert json.loads((out / "summary.json").read_text())["K"] == expected
    res = CliRunner().invoke(main, ["stickslip", "corrugation", "--mu", "0.5", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and res.output.count("\n") == 1, res.output
    assert "give --K" in res.output and not (tmp_path / "o").exists()
