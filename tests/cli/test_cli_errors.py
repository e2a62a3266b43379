"""Hostile input to the CLI: one `Error:` line, exit code 2, nothing half-written."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj.cli import main
from spine_mj.surfaces import MAX_GRID_POINTS


def run(*args, cwd=None):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_one_error_line(result, *fragments):
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


#: A quick simulate on the single peak; the tests add the options they probe.
SIMULATE = ("simulate", "paper-single-peak", "--start", "-3,-1", "--resolution", "41")


def recorded_run(tmp_path):
    """A run folder written by a 0.01 s simulate."""
    run_dir = tmp_path / "run"
    result = run(*SIMULATE, "--duration", "0.01", "--out", run_dir)
    assert result.exit_code == 0, result.output
    return run_dir


@pytest.mark.parametrize(
    ("value", "fragment"),
    [("nan", "nx must be an integer >= 4, got nan"), ("abc", "got 'abc'"), ("3.5", "got 3.5")],
)
def test_nonsense_grid_size_is_refused(tmp_path, value, fragment):
    out = tmp_path / "f.npz"
    assert_one_error_line(
        run("surface", "make", "paper-fractal", "--set", f"nx={value}", "-o", out), fragment
    )
    assert not out.exists()


def test_grid_too_large_for_memory_is_refused_before_allocating(tmp_path):
    out = tmp_path / "f.npz"
    result = run("surface", "make", "paper-fractal", "--set", "nx=100000", "-o", out)
    assert_one_error_line(result, "100000 x 100000", f"{MAX_GRID_POINTS:.3g}", "GiB")
    assert not out.exists()


@pytest.mark.parametrize("scale", ["nan", "inf", "0", "-1"])
def test_stl_scale_must_be_finite_and_positive(tmp_path, scale):
    surf = tmp_path / "p.npz"
    assert run("surface", "make", "paper-single-peak", "-o", surf).exit_code == 0
    stl = tmp_path / "s.stl"
    assert_one_error_line(run("surface", "export", surf, "--stl", stl, "--stl-scale", scale), "--stl-scale")
    assert not stl.exists()


def test_an_unwritable_second_output_leaves_no_first_output(tmp_path):
    (tmp_path / "afile").write_text("x")
    out = tmp_path / "p.npz"
    result = run("surface", "make", "paper-single-peak", "-o", out, "--png", tmp_path / "afile" / "p.png")
    assert_one_error_line(result, "afile is a file, not a folder")
    assert not out.exists()


def test_output_under_a_file_is_one_error_line(tmp_path):
    (tmp_path / "afile").write_text("x")
    result = run("surface", "make", "paper-single-peak", "-o", tmp_path / "afile" / "x.npz")
    assert_one_error_line(result, "afile is a file, not a folder")


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        ({"heights": np.array([["a", "b"], ["c", "d"]])}, "array 'heights' must be numeric"),
        ({"metadata_json": np.array("null")}, "metadata_json must be a JSON object"),
        ({"metadata_json": np.array("{not json")}, "corrupt metadata"),
    ],
)
def test_tampered_surface_files_are_refused(tmp_path, change, fragment):
    good = tmp_path / "p.npz"
    assert run("surface", "make", "paper-fractal", "--set", "nx=16", "-o", good).exit_code == 0
    with np.load(good) as npz:
        arrays = {k: npz[k] for k in npz.files}
    bad = tmp_path / "bad.npz"
    np.savez(bad, **{**arrays, **change})
    png = tmp_path / "bad.png"
    assert_one_error_line(run("surface", "show", bad, "-o", png), fragment)
    assert not png.exists()


def test_corrupt_instrument_file_is_one_line_and_verbose_shows_the_details(tmp_path):
    junk = tmp_path / "scan.plu"
    junk.write_bytes(bytes(range(256)) * 20)
    result = run("surface", "make", "--from-file", junk, "-o", tmp_path / "s.npz")
    assert_one_error_line(result, "cannot read topography scan.plu", "tried")
    verbose = run("-v", "surface", "make", "--from-file", junk, "-o", tmp_path / "s.npz")
    assert verbose.exit_code == 2
    assert len(verbose.output.splitlines()) > 1


def test_view_without_a_display_exits_2(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert_one_error_line(run("view", "paper-single-peak"), "no display")


def test_reproduce_json_is_valid_json(tmp_path):
    result = run("reproduce", "single-peak", "--quick", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    json.loads((tmp_path / "single-peak.json").read_text())


def test_a_run_too_long_to_record_is_refused_before_allocating(tmp_path):
    out = tmp_path / "run"
    for extra in (
        ["--duration", "1e6"],
        ["--duration", "1e308"],
        ["--duration", "0.05", "--timestep", "1e-10"],
    ):
        result = run(*SIMULATE, "--out", out, *extra)
        assert_one_error_line(result, "a spring run of", "more than the limit")
    result = run(*SIMULATE, "--out", out, "--duration", "0.05", "--timestep", "1e-320")
    assert_one_error_line(result, "timestep_s must be at least 1e-09 of the time scale tau")
    assert not out.exists()


def test_a_tip_radius_far_below_the_surface_scale_is_refused_before_dilating(tmp_path):
    # metres given for a dimensionless preset: 1e-6 would need a 8e7 x 8e7 dilation grid
    result = run(
        "streamline", "paper-single-peak", "--start", "0,0", "--tip-radius", "1e-6", "--out", tmp_path / "o"
    )
    assert_one_error_line(result, "dilating by the tip radius 1e-06", "more than the limit")
    result = run(
        "streamline", "paper-single-peak", "--start", "0,0", "--tip-radius", "1e308", "--out", tmp_path / "o"
    )
    assert_one_error_line(result, "the tip's footprint")
    assert not (tmp_path / "o").exists()


def test_kappa_resolution_too_large_is_refused(tmp_path):
    out = tmp_path / "k.png"
    assert_one_error_line(
        run("kappa", "paper-single-peak", "-o", out, "--resolution", "100000000"), "kappa --resolution"
    )
    assert not out.exists()


def test_preset_pairs_of_the_wrong_length_are_named(tmp_path):
    out = tmp_path / "f.npz"
    assert_one_error_line(
        run("surface", "make", "paper-single-peak", "--set", "center=[0]", "-o", out), "center must be a pair"
    )
    assert_one_error_line(
        run("surface", "make", "paper-fractal", "--set", "size=[1,2,3]", "-o", out), "size must be a pair"
    )
    assert not out.exists()


def _npz_with_header_only(path, shape):
    """An .npz whose 'heights' header claims ``shape`` (no data follows): a decompression
    bomb's size, read without inflating anything."""
    import io
    import zipfile

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("heights.npy", buf.getvalue())


def test_surface_files_too_large_deep_or_malformed_are_refused(tmp_path):
    bomb = tmp_path / "bomb.npz"
    _npz_with_header_only(bomb, (20000, 20000))
    assert_one_error_line(run("surface", "info", bomb), "array 'heights' has shape (20000, 20000)")

    good = tmp_path / "p.npz"
    assert run("surface", "make", "paper-fractal", "--set", "nx=16", "-o", good).exit_code == 0
    with np.load(good) as npz:
        arrays = {k: npz[k] for k in npz.files}
    for change, fragment in [
        ({"metadata_json": np.array("[" * 100_000 + "]" * 100_000)}, "nested too deep"),
        ({"periodic": np.array([True, False, True])}, "'periodic' must be one boolean"),
        ({"periodic": np.array("no")}, "'periodic' must be one boolean"),
        ({"x": np.arange(16) * 1e-320}, "x spacing"),
        ({"heights": arrays["heights"] + 1j}, "heights must be real numbers"),
    ]:
        bad = tmp_path / "bad.npz"
        np.savez(bad, **{**arrays, **change})
        assert_one_error_line(run("surface", "info", bad), fragment)


def test_replay_of_a_corrupt_run_folder_is_one_error_line(tmp_path):
    run_dir = recorded_run(tmp_path)
    (run_dir / "summary.json").write_text("{bad")
    assert_one_error_line(
        run("replay", run_dir, "--mp4", tmp_path / "x.mp4"), "summary.json is not readable JSON"
    )
    assert not (tmp_path / "x.mp4").exists()


def test_sigterm_removes_a_temporary_output(tmp_path):
    import subprocess
    import sys

    script = f"""
import os, signal, time
from pathlib import Path
from spine_mj.cli.app import _exit_on_sigterm
from spine_mj.atomic import atomic_output
signal.signal(signal.SIGTERM, _exit_on_sigterm)
with atomic_output(Path({str(tmp_path / "out.txt")!r})) as tmp:
    tmp.write_text("half")
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(30)
"""
    proc = subprocess.run([sys.executable, "-c", script], timeout=60)
    assert proc.returncode == 128 + 15
    assert list(tmp_path.iterdir()) == [], "the temporary file outlived the SIGTERM"


def test_an_stl_whose_coordinates_overflow_float32_is_refused(tmp_path):
    surf = tmp_path / "p.npz"
    assert run("surface", "make", "paper-single-peak", "-o", surf).exit_code == 0
    stl = tmp_path / "s.stl"
    assert_one_error_line(run("surface", "export", surf, "--stl", stl, "--base", "1e308"), "32-bit floats")
    assert not stl.exists()


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (["--drive", "spring", "--rate", "1"], "--drive spring does not use --rate; leave it out"),
        (["--drive", "ramp", "--K", "5"], "--drive ramp does not use --K"),
        (["--drive", "static", "--duration", "1", "--speed", "0.1"], "does not use --speed, --duration"),
    ],
)
def test_simulate_refuses_options_its_drive_would_ignore(tmp_path, options, fragment):
    out = tmp_path / "run"
    result = run(*SIMULATE, "--out", out, *options)
    assert_one_error_line(result, fragment)
    assert not out.exists()


def test_fractal_sizes_beyond_floating_point_range_are_named(tmp_path):
    out = tmp_path / "f.npz"
    for setting in ("size=1e308", "rms_slope=1e308"):
        result = run("surface", "make", "paper-fractal", "--set", setting, "-o", out)
        assert_one_error_line(result, "fractal_fbm: size", "beyond floating-point range")
    assert not out.exists()


def test_a_drive_speed_no_time_step_can_resolve_names_the_speed(tmp_path):
    result = run(*SIMULATE, "--speed", "1e308", "--out", tmp_path / "r")
    assert_one_error_line(result, "inertia number I_e (speed 1e+308 m/s) must be <= 10000", "got inf")


def test_replay_at_a_speed_that_would_need_endless_frames_is_refused(tmp_path):
    pytest.importorskip("imageio", reason="needs the optional extra 'video': pip install 'spine-mj[video]'")
    run_dir = recorded_run(tmp_path)
    mp4 = tmp_path / "x.mp4"
    assert_one_error_line(
        run("replay", run_dir, "--speed", "1e-320", "--mp4", mp4), "frames", "raise the speed"
    )
    assert_one_error_line(run("replay", run_dir, "--duration", "-1", "--mp4", mp4), "--duration")
    assert not mp4.exists()


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (("simulate", "paper-single-peak"), ("Missing option '--start'", "(see 'main simulate --help')")),
        (("simulate", "paper-single-peak", "--start", "0,0", "--ie", "abc"), ("'abc' is not a valid float",)),
        (("simulate", "paper-single-peak", "--start", "0,0", "--bogus"), ("No such option '--bogus'",)),
        (("nosuch",), ("No such command 'nosuch'", "(see 'main --help')")),
        (("surface", "make", "--set"), ("Option '--set' requires an argument",)),
    ],
)
def test_usage_errors_are_one_line_too(args, fragments):
    assert_one_error_line(run(*args), *fragments)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("paper-single-peak", "--fill", "harmonic"), "does not use --fill"),
        (("paper-single-peak", "--spacing", "1e-6"), "does not use --spacing"),
        (("paper-single-peak", "--no-level"), "does not use --no-level"),
        (("paper-single-peak", "--channel", "3"), "does not use --channel"),
        (("--from-file", "tests/data/di-1.di", "--seed", "3"), "does not use --seed"),
        (("--from-file", "tests/data/di-1.di", "--hurst", "0.7"), "does not use --hurst"),
        (("--from-file", "tests/data/di-1.di", "--set", "nx=5"), "does not use --set"),
    ],
)
def test_surface_make_refuses_options_its_input_would_ignore(tmp_path, args, fragment):
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    args = tuple(str(root / a) if a.startswith("tests/data") else a for a in args)
    out = tmp_path / "s.npz"
    assert_one_error_line(run("surface", "make", *args, "-o", out), fragment)
    assert not out.exists()


def test_headless_replay_refuses_duration_which_only_closes_a_viewer(tmp_path):
    run_dir = recorded_run(tmp_path)
    mp4 = tmp_path / "x.mp4"
    assert_one_error_line(
        run("replay", run_dir, "--speed", "0.01", "--duration", "20", "--mp4", mp4), "--duration"
    )
    assert not mp4.exists()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--bogus",), "No such option '--bogus'"),
        (("reproduce",), "Choose from: single-peak, random-gaussian"),
    ],
)
def test_root_and_choice_usage_errors_are_one_line(args, fragment):
    assert_one_error_line(run(*args), fragment)


def test_a_reader_that_leaves_the_pipe_early_gets_no_error_line():
    # `spine-mj examples | head -1`: writing into a pipe whose reader has gone is no error
    import os
    import subprocess
    import sys

    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "spine_mj.cli", "examples"],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    finally:
        os.close(write_end)
    assert proc.stderr == ""
    assert proc.returncode == 141  # 128 + SIGPIPE, what a shell reports for such a writer


@pytest.mark.parametrize(
    ("setting", "fragment"),
    [
        ('slope_deg="steep"', "slope_deg must be a finite number, got 'steep'"),
        ("azimuth_deg=inf", "azimuth_deg must be a finite number, got inf"),
        ("unit=banana", "unit must be '1' (dimensionless) or a length unit"),
        ("n=100000", "100000 x 100000"),
    ],
)
def test_plane_arguments_are_refused_before_a_file_is_written(tmp_path, setting, fragment):
    out = tmp_path / "p.npz"
    assert_one_error_line(run("surface", "make", "plane", "--set", setting, "-o", out), fragment)
    assert not out.exists()


def test_a_generated_surface_in_an_unknown_unit_is_refused_when_made(tmp_path):
    out = tmp_path / "f.npz"
    result = run("surface", "make", "paper-fractal", "--set", "unit=banana", "--set", "nx=16", "-o", out)
    assert_one_error_line(result, "got 'banana'")
    assert not out.exists()


@pytest.mark.parametrize("step", ["nan", "0", "-1"])
def test_bullet_refuses_a_nonsense_time_step_as_mujoco_does(tmp_path, step):
    pytest.importorskip("pybullet")
    for engine in ("mujoco", "bullet"):
        result = run(*SIMULATE, "--engine", engine, "--timestep", step, "--out", tmp_path / engine)
        assert_one_error_line(result, "timestep_s must be a finite number > 0")
        assert not (tmp_path / engine).exists()
