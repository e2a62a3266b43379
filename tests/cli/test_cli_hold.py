"""``spine-mj hold``'s refusals: one Error line, exit code 2, nothing written."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj.cli import main


def _refused(args, out):
    res = CliRunner().invoke(main, ["hold", *args, "--out", str(out)])
    assert res.exit_code == 2, res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ") and "Traceback" not in res.output
    assert not out.exists()
    return lines[0]


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["paper-single-peak", "--mu", "nan"], "--mu"),
        (["paper-single-peak", "--starts", "0"], "--starts must be an integer >= 1, got 0"),
        (["no-such-surface.npz", "--mu", "0.5"], "no-such-surface.npz"),
    ],
)
def test_bad_input_is_one_error_line_and_nothing_written(tmp_path, args, match):
    assert match in _refused(args, tmp_path / "out")


def test_a_tip_too_wide_for_a_narrow_strip_is_refused_with_the_users_number(tmp_path):
    from spine_mj.surface_io import save_surface
    from spine_mj.surfaces import GridSurface

    x, y = np.linspace(0, 50, 1001), np.linspace(0, 1, 9)
    strip = GridSurface(heights=0.2 * np.sin(x)[None, :] * np.ones((9, 1)), x=x, y=y)
    path = save_surface(strip, tmp_path / "strip.npz")
    line = _refused([str(path), "--mu", "0.5", "--tip-radius", "0.6"], tmp_path / "out")
    assert "tip_radius_m 0.006 m (0.6 surface units) is larger than the surface" in line


def test_a_plane_is_refused_in_one_line_naming_why(tmp_path):
    from spine_mj.surface_io import save_surface
    from spine_mj.surfaces import GridSurface

    x = np.linspace(0, 4, 17)
    path = save_surface(GridSurface(heights=np.zeros((17, 17)), x=x, y=x.copy()), tmp_path / "plane.npz")
    line = _refused([str(path), "--mu", "0.5", "--starts", "2", "--reference-starts", "5"], tmp_path / "out")
    assert "no path on it folds (K* = 0" in line


def test_a_scan_with_missing_points_needs_fill_and_a_preset_takes_none(tmp_path):
    import SurfaceTopography as st

    h = np.add.outer(np.linspace(0, 1, 40), np.linspace(0, 2, 30))
    masked = np.ma.masked_array(h, mask=np.zeros_like(h, dtype=bool))
    masked.mask[10:13, 5:9] = True
    scan = tmp_path / "holey.x3p"
    st.Topography(masked, (40.0, 30.0), unit="um").to_x3p(str(scan))
    line = _refused([str(scan), "--mu", "0.5"], tmp_path / "out")
    assert "12 missing points" in line and "fill" in line
    line = _refused(["paper-single-peak", "--mu", "0.5", "--fill", "harmonic"], tmp_path / "out")
    assert "fill is for an instrument file's missing points" in line
    from spine_mj.presets import open_surface

    filled = open_surface(str(scan), fill="harmonic")
    assert np.isfinite(filled.heights).all() and filled.metadata["missing_points"] == 12
