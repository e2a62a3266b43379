"""`spine-mj surface info` prints the predicted drive limits (docs/physics.md §8)."""

import json

import pytest
from click.testing import CliRunner

from spine_mj.cli import main
from spine_mj.surface_io import save_surface
from spine_mj.surfaces import fractal_fbm


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_surface_info_prints_the_drive_limits_of_a_corrugation():
    result = run("surface", "info", "corrugation")
    assert result.exit_code == 0, result.output
    line = next(s for s in result.output.splitlines() if s.startswith("drive limits"))
    # Prandtl-Tomlinson K*; I_e* set by the lag 2 mu 0.1 before lift-off at 0.529
    assert "quasistatic needs K > 0.467 and I_e < 0.1 (set by lag; lift-off 0.529" in line
    doc = json.loads(run("surface", "info", "corrugation", "--json").stdout)
    assert doc["drive_limits"]["k_star"] == pytest.approx(0.467, abs=0.002)
    assert doc["drive_limits"]["limit"] == "lag"


def test_a_file_without_preset_needs_mu(tmp_path):
    path = tmp_path / "scan.npz"
    save_surface(fractal_fbm(nx=64, size=1.0, hurst=0.8, rms_slope=0.3, rng=1), path)
    result = run("surface", "info", str(path))
    assert result.exit_code == 0, result.output
    assert "give --mu" in result.output
    doc = json.loads(run("surface", "info", str(path), "--json", "--mu", "0.5").stdout)
    assert doc["drive_limits"]["mu"] == 0.5 and doc["drive_limits"]["k_star"] > 0


@pytest.mark.parametrize("args", [("--mu", "-1"), ("--mu", "nan"), ("--tip-radius", "-0.1")])
def test_bad_drive_limit_options_exit_2(args):
    result = run("surface", "info", "corrugation", *args)
    assert result.exit_code == 2
    assert result.output.startswith("Error: ") and "Traceback" not in result.output


def test_surface_info_on_a_narrow_strip_of_long_waves(tmp_path):
    """A strip 1 wide whose slopes correlate over 57 (waves 300 long): the streamline step
    l_s / 40 would be wider than the strip; it is capped at an eighth of the width."""
    import numpy as np

    from spine_mj.surfaces import GridSurface

    x, y = np.arange(12001) * 0.125, np.arange(9) * 0.125
    heights = 3 * np.sin(2 * np.pi * x / 300)[None, :] + 0.01 * y[:, None]
    path = save_surface(GridSurface(heights=heights, x=x, y=y), tmp_path / "strip.npz")
    result = run("surface", "info", str(path), "--mu", "0.5", "--json")
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)  # progress, where a slow machine shows it, is on stderr
    assert doc["char_length"] == 1  # L_c is clipped to the domain's narrower side
    assert doc["slope_correlation_length"] == pytest.approx(0.190 * 300, rel=0.05)  # a sine's l_s
    assert doc["drive_limits"]["limit"] == "lag"
