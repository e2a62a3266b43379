"""Optional extras and the rendering backend: a missing one is one `Error:` line naming what
to install or set, exit code 2, nothing written."""

import pytest
from click.testing import CliRunner

from spine_mj import extras
from spine_mj.cli import main
from spine_mj.errors import SpineInputError

SIMULATE = ("simulate", "paper-single-peak", "--start", "-3,-2", "--resolution", "41", "--duration", "0.01")


def _one_error_line(result, *fragments):
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def _without(monkeypatch, *modules):
    real = extras.importlib.util.find_spec
    monkeypatch.setattr(
        extras.importlib.util, "find_spec", lambda name, *a: None if name in modules else real(name, *a)
    )


def test_require_names_the_extra_and_the_missing_modules(monkeypatch):
    _without(monkeypatch, "imageio")
    assert "imageio" in extras.missing("video")
    with pytest.raises(SpineInputError, match=r"--render needs the optional extra 'video' \(imageio"):
        extras.require("video", "--render")


def test_render_without_the_video_extra_is_refused_before_anything_runs(tmp_path, monkeypatch):
    _without(monkeypatch, "imageio", "imageio_ffmpeg")
    out = tmp_path / "run"
    result = CliRunner().invoke(main, [*SIMULATE, "--render", "--out", str(out)])
    _one_error_line(result, "pip install 'spine-mj[video]'")
    assert not out.exists()


@pytest.mark.parametrize(
    ("backend", "fragment"), [("bogus", "invalid value for environment variable MUJOCO_GL")]
)
def test_a_rendering_backend_that_cannot_start_is_one_line(tmp_path, monkeypatch, backend, fragment):
    monkeypatch.setattr(extras, "missing", lambda extra: [])  # the backend is checked next
    monkeypatch.setenv("MUJOCO_GL", backend)
    out = tmp_path / "run"
    result = CliRunner().invoke(main, [*SIMULATE, "--render", "--out", str(out)])
    _one_error_line(result, f"MUJOCO_GL='{backend}' cannot render here", fragment, "unset it")
    assert not out.exists()
