"""`spine-mj surface ...` as a user runs it: outputs written, bad input exits 2 cleanly."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj.cli import main
from spine_mj.surface_io import load_surface


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_help_on_every_surface_command():
    for args in (
        ["--help"],
        ["surface", "--help"],
        ["surface", "make", "--help"],
        ["surface", "show", "--help"],
        ["surface", "export", "--help"],
        ["surface", "list", "--help"],
    ):
        result = run(*args)
        assert result.exit_code == 0, result.output
        assert "Usage" in result.output


def test_make_show_export(tmp_path):
    out = tmp_path / "f.npz"
    result = run(
        "surface",
        "make",
        "paper-fractal",
        "--hurst",
        "0.7",
        "--seed",
        "3",
        "--set",
        "nx=64",
        "-o",
        str(out),
        "--png",
        str(tmp_path / "f.png"),
    )
    assert result.exit_code == 0, result.output
    surf = load_surface(out)
    assert surf.shape == (64, 64) and surf.metadata["params"]["hurst"] == 0.7
    assert (tmp_path / "f.png").stat().st_size > 10_000
    assert run("surface", "show", str(out), "-o", str(tmp_path / "s.png")).exit_code == 0
    result = run(
        "surface", "export", str(out), "--stl", str(tmp_path / "f.stl"), "--hfield", str(tmp_path / "h.npz")
    )
    assert result.exit_code == 0, result.output
    with np.load(tmp_path / "h.npz", allow_pickle=False) as hf:
        assert hf["data"].shape == (64, 64) and hf["size"].shape == (4,)
    import trimesh

    assert trimesh.load(tmp_path / "f.stl").is_watertight


def test_import_from_file(tmp_path, topography_dir):
    out = tmp_path / "di.npz"
    result = run(
        "surface", "make", "--from-file", str(topography_dir / "di-1.di"), "--spacing", "4e-9", "-o", str(out)
    )
    assert result.exit_code == 0, result.output
    surf = load_surface(out)  # the AFM's nm kept; --spacing is in metres
    assert surf.unit == "nm" and surf.spacing[0] == pytest.approx(4.0)
    result = run("surface", "info", str(out), "-o", str(tmp_path / "psd.png"))
    assert result.exit_code == 0, result.output
    info = {line[:25].strip(): line[25:].split() for line in result.output.splitlines()[:6]}
    value, unit = info["rms height"]
    assert unit == "nm" and 5 < float(value) < 20  # Sq of this AFM scan: 9.8 nm
    assert info["L_c (asperity length)"][1] == info["l_s (slope correlation)"][1] == "nm"
    assert info["rms curvature"][1] == "1/nm" and len(info["rms slope"]) == 1
    assert run("surface", "show", str(out), "-o", str(tmp_path / "s.png")).exit_code == 0
    result = run("surface", "export", str(out), "--stl", str(tmp_path / "s.stl"))
    assert result.exit_code == 0 and "scale 1e-06" in result.output  # nm -> mm


@pytest.mark.parametrize(
    "args, message",
    [
        (["surface", "make", "nope", "-o", "{d}/x.npz"], "unknown preset 'nope'"),
        (["surface", "make", "paper-fractal", "--hurst", "1.5", "-o", "{d}/x.npz"], "hurst"),
        (["surface", "make", "paper-random-convex", "--set", "n_peaks=0", "-o", "{d}/x.npz"], "n_peaks"),
        (
            ["surface", "make", "paper-random-convex", "--set", "sigma_range=[0, 1]", "-o", "{d}/x.npz"],
            "widths",
        ),
        (
            ["surface", "make", "paper-single-peak", "--set", "k=abc", "-o", "{d}/x.npz"],
            "k must be a number, got 'abc'",
        ),
        (["surface", "make", "--from-file", "{d}/corrupt.plu", "-o", "{d}/x.npz"], "cannot read topography"),
        (["surface", "make", "--from-file", "{d}/missing.x3p", "-o", "{d}/x.npz"], "not found"),
        (["surface", "show", "{d}/corrupt.npz", "-o", "{d}/x.png"], "not a readable"),
        (["surface", "make", "-o", "{d}/x.npz"], "exactly one of PRESET or --from-file"),
        (["surface", "export", "paper-single-peak", "--stl", "{d}/x.obj"], ".stl"),
    ],
)
def test_bad_input_exits_2_with_one_line_and_no_output(tmp_path, args, message):
    (tmp_path / "corrupt.plu").write_bytes(b"garbage" * 20)
    (tmp_path / "corrupt.npz").write_bytes(b"garbage" * 20)
    before = set(tmp_path.iterdir())
    result = run(*[a.format(d=tmp_path) for a in args])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output
    assert set(tmp_path.iterdir()) == before


def test_console_script_exit_code_and_stderr(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "spine_mj.cli", "surface", "make", "nope", "-o", str(tmp_path / "x.npz")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip().splitlines()[0]]
    assert proc.stderr.startswith("Error: unknown preset")
    assert not (tmp_path / "x.npz").exists()
