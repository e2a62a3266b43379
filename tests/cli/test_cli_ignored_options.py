"""Hostile input, per command: an option (or sweep key) that the chosen input or drive
would ignore is refused before anything runs, in one `Error:` line naming it, exit code 2,
nothing written. Random subsets of such options, on validation-only paths (fast)."""

import os
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spine_mj.cli import main

SCALE = int(os.environ.get("SPINE_MJ_PROPERTY_SCALE", "1"))
SETTINGS = settings(
    max_examples=8 * SCALE,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def refused(args, folder: Path, names):
    """``args`` ends in one Error line naming one of ``names``, exit 2, ``folder`` empty."""
    result = CliRunner().invoke(main, [str(a) for a in args])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == 2, (args, result.output)
    assert len(lines) == 1 and lines[0].startswith("Error: "), (args, result.output)
    assert any(n in lines[0] for n in names), (args, lines[0])
    assert not [p for p in folder.rglob("*") if p.is_file()], (args, list(folder.rglob("*")))


def subsets(options: dict):
    return st.lists(st.sampled_from(sorted(options)), min_size=1, max_size=len(options), unique=True)


IMPORT_ONLY = {"--fill": ["harmonic"], "--spacing": ["1e-6"], "--no-level": [], "--channel": ["3"]}
GENERATOR_ONLY = {"--seed": ["3"], "--hurst": ["0.7"], "--set": ["nx=5"]}


@SETTINGS
@given(preset=st.sampled_from(["paper-single-peak", "paper-fractal"]), given_=subsets(IMPORT_ONLY))
def test_surface_make_from_a_preset_refuses_import_options(tmp_path_factory, preset, given_):
    out = tmp_path_factory.mktemp("make")
    args = ["surface", "make", preset, "-o", out / "s.npz"]
    for opt in given_:
        args += [opt, *IMPORT_ONLY[opt]]
    refused(args, out, given_)


@SETTINGS
@given(scan=st.sampled_from(["example:di-1.di", "example:plu-1.plu"]), given_=subsets(GENERATOR_ONLY))
def test_surface_make_from_a_file_refuses_generator_options(tmp_path_factory, scan, given_):
    out = tmp_path_factory.mktemp("import")
    args = ["surface", "make", "--from-file", scan, "-o", out / "s.npz"]
    for opt in given_:
        args += [opt, *GENERATOR_ONLY[opt]]
    refused(args, out, given_)


#: What each drive of `simulate` does not read.
NOT_FOR_DRIVE = {
    "spring": {"--rate": ["1.0"], "--start-force": ["0.1"]},
    "ramp": {"--speed": ["0.01"], "--K": ["10"], "--stiffness": ["5"], "--start-force": ["0.1"]},
    "static": {"--speed": ["0.01"], "--K": ["10"], "--stiffness": ["5"], "--duration": ["1"]},
}


@SETTINGS
@given(data=st.data(), drive=st.sampled_from(sorted(NOT_FOR_DRIVE)))
def test_simulate_refuses_options_its_drive_ignores(tmp_path_factory, data, drive):
    out = tmp_path_factory.mktemp("sim")
    options = NOT_FOR_DRIVE[drive]
    given_ = data.draw(subsets(options))
    args = ["simulate", "paper-single-peak", "--start", "-3,-1", "--drive", drive, "--out", out / "run"]
    for opt in given_:
        args += [opt, *options[opt]]
    refused(args, out, given_)


@SETTINGS
@given(
    name=st.sampled_from(["single-peak", "random-gaussian", "kappa-map"]),
    given_=subsets({"--surfaces": ["5"], "--workers": ["2"]}),
)
def test_reproduce_refuses_fractal_options_for_other_figures(tmp_path_factory, name, given_):
    out = tmp_path_factory.mktemp("repro")
    args = ["reproduce", name, "--quick", "--out", out / "r"]
    for opt in given_:
        args += [opt, {"--surfaces": "5", "--workers": "2"}[opt]]
    refused(args, out, given_)


#: Drive keys of a sweep config and the protocols that do not read them.
SWEEP_KEYS = {
    "K": ("3.0", ["static", "ramp"]),
    "stiffness": ("10.0", ["static", "ramp"]),
    "duration": ("1.0", ["static"]),
    "start_force": ("0.1", ["spring", "ramp"]),
    "slide_distance": ("1e-3", ["spring", "static"]),
}


@SETTINGS
@given(data=st.data(), key=st.sampled_from(sorted(SWEEP_KEYS)))
def test_sweep_refuses_a_drive_key_its_protocol_ignores(tmp_path_factory, data, key):
    folder = tmp_path_factory.mktemp("sweep")
    value, ignoring = SWEEP_KEYS[key]
    protocol = data.draw(st.sampled_from(ignoring))
    config = folder / "c.toml"
    config.write_text(
        '[sweep]\nanalyses = ["engine"]\n[[surfaces]]\npreset = "paper-single-peak"\n'
        f'[starts]\npoints = [[0.1, 0.5]]\n[drive]\nprotocol = "{protocol}"\n{key} = {value}\n'
    )
    result = CliRunner().invoke(main, ["sweep", str(config), "--out", str(folder / "out")])
    assert result.exit_code == 2 and f"config key {key} = " in result.output, result.output
    assert "ignores it" in result.output and not (folder / "out").exists()


def test_sweep_refuses_worker_wait_without_a_scheduler(tmp_path):
    config = tmp_path / "c.toml"
    config.write_text('[[surfaces]]\npreset = "paper-single-peak"\n[starts]\npoints = [[0.1, 0.5]]\n')
    (tmp_path / "keep").mkdir()
    refused(
        ["sweep", config, "--out", tmp_path / "keep" / "out", "--worker-wait", "5"],
        tmp_path / "keep",
        ["--worker-wait"],
    )


def test_sweep_on_a_scheduler_refuses_local_workers(tmp_path):
    config = tmp_path / "c.toml"
    config.write_text('[[surfaces]]\npreset = "paper-single-peak"\n[starts]\npoints = [[0.1, 0.5]]\n')
    (tmp_path / "keep").mkdir()
    refused(
        [
            "sweep",
            "run",
            config,
            "--out",
            tmp_path / "keep" / "out",
            "--scheduler",
            "tcp://nowhere:1",
            "--workers",
            "2",
        ],
        tmp_path / "keep",
        ["--workers"],
    )


def test_surface_info_without_a_mu_refuses_a_tip_radius(tmp_path):
    scan = "example:plu-1.plu"  # a measured scan: no preset mu_s
    refused(["surface", "info", scan, "--tip-radius", "1e-6"], tmp_path, ["--tip-radius"])
    result = CliRunner().invoke(main, ["surface", "info", scan, "--tip-radius", "1e-6", "--mu", "0.5"])
    assert result.exit_code == 0 and "drive limits (mu_s 0.5)" in result.output, result.output


@pytest.fixture(scope="module")
def recorded_run(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("replay") / "run"
    args = ["simulate", "paper-single-peak", "--start", "-3,-1", "--resolution", "41", "--duration", "0.01"]
    result = CliRunner().invoke(main, [*args, "--out", str(run_dir)])
    assert result.exit_code == 0, result.output
    return run_dir


@settings(SETTINGS, max_examples=4 * SCALE)
@given(speed=st.sampled_from(["0.01", "1", "1e-6"]), duration=st.sampled_from(["20", "0.5", "-1", "nan"]))
def test_replay_to_an_mp4_refuses_duration(tmp_path_factory, recorded_run, speed, duration):
    out = tmp_path_factory.mktemp("mp4")
    refused(
        ["replay", recorded_run, "--speed", speed, "--duration", duration, "--mp4", out / "r.mp4"],
        out,
        ["--duration"],
    )
