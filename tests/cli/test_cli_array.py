"""`spine-mj array`: the designer's outputs, and bad input refused with nothing written."""

import json
import math

import pandas as pd
import pytest
from click.testing import CliRunner

from spine_mj.cli import main

ARRAY = (
    "array",
    "corrugation",
    "--rows",
    "1",
    "--cols",
    "2",
    "--spacing",
    "0.3",
    "--spacing-unit",
    "surface",
)


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_array_writes_curve_spines_summary_and_figure(tmp_path):
    out = tmp_path / "arr"
    result = run(*ARRAY, "--ie", "1e-2", "--duration", "0.02", "--out", out)
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_spines"] == 2 and summary["locked_spines"] == 0
    assert summary["holding_ratio"] == pytest.approx(
        summary["holding_force_n"] / (2 * summary["preload_per_spine_n"])
    )
    spines = pd.read_csv(out / "spines.csv")
    assert len(spines) == 2 and spines["x0"].diff().iloc[1] == pytest.approx(0.3)
    curve = pd.read_csv(out / "curve.csv")
    assert curve["total_force_n"].max() == pytest.approx(summary["peak_force_n"], rel=1e-9)
    assert summary["holding_force_n"] <= summary["peak_force_n"]
    assert summary["holding_excess_predicted"] > 0 and summary["inertia_number"] == pytest.approx(1e-2)
    assert (out / "layout.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--spacing", "20", "--spacing-unit", "L_c"), "puts spine"),
        (("--rows", "20", "--cols", "20"), "at most 256 spines"),
        (("--rows", "0"), "rows must be an integer >= 1"),
        (("--spacing", "nan"), "spacing"),
        (
            ("--drive", "force", "--duration", "1"),
            "--drive force (a pull runs to its cap) does not use --duration",
        ),
        (("--layout", "random", "--seed", "-1"), "--seed"),
        (("--layout", "grid", "--seed", "5"), "--layout grid does not use --seed"),
        (("--layout", "staggered", "--seed", "0"), "--layout staggered does not use --seed"),
        (("--centre", "100,0"), "puts spine"),
    ],
)
def test_bad_array_input_is_one_error_line_and_writes_nothing(tmp_path, args, fragment):
    out = tmp_path / "arr"
    result = run(*ARRAY, *args, "--out", out)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ") and fragment in lines[0], result.output
    assert not out.exists()


@pytest.mark.parametrize(("slope_deg", "drive"), [(0.0, "speed"), (15.0, "force")])
def test_array_on_the_plane_preset_holds_n_tan_theta_plus_phi_w_at_its_default_pace(
    tmp_path, slope_deg, drive
):
    # the user's path: the plane preset (its mu 0.5), tilted with --set, then the array at its
    # default pace; the plane's L_c is its side, so the spacing is given in surface units
    surface = tmp_path / "plane.npz"
    made = run("surface", "make", "plane", "--set", f"slope_deg={slope_deg}", "-o", surface)
    assert made.exit_code == 0, made.output
    out = tmp_path / "arr"
    args = ("--spacing", "0.01", "--spacing-unit", "surface", "--mu", "0.5", "--drive", drive)
    result = run("array", surface, *args, "--out", out)
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    kappa = math.tan(math.radians(slope_deg) + math.atan(0.5))
    assert summary["n_spines"] == 4 and summary["locked_spines"] == 0
    assert summary["holding_ratio"] == pytest.approx(kappa, rel=0.01)
