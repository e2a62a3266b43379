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
