"""The MuJoCo-native workflow: an exported model that runs in MuJoCo, replay of a recorded
run, and the MP4's trail, streamline and overlay."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj import presets
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.sim import Rig
from spine_mj.sim.render import choose_gl_backend, streamline_path_m
from spine_mj.sim.run_folder import load_run


def _surface_height_m(rig, x_m, y_m):
    s = rig.length_scale_m
    return s * rig.surface.height(x_m / s, y_m / s)


def test_exported_model_rests_on_the_surface_and_the_spring_drives_it(tmp_path):
    result = CliRunner().invoke(
        main, ["sim", "export", "paper-single-peak", "--start", "-4,0.5", "-o", str(tmp_path / "rig.xml")]
    )
    assert result.exit_code == 0, result.output
    rig = Rig(presets.make_surface("paper-single-peak"))
    L, r = rig.units.length_m, rig.tip.tip_radius_m
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "rig.xml"))
    d = mujoco.MjData(m)
    # a fresh MjData already holds the rest state, the same as the keyframe
    q_fresh = d.qpos.copy()
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    np.testing.assert_allclose(d.qpos, q_fresh)
    np.testing.assert_allclose(d.qpos[:2] * L, [-0.04, 0.005], atol=1e-7)  # MJCF keeps 6 digits
    # the default K = 30 on l_s, in engine units F_p / L_c
    k_default = 30 * rig.scales.char_length_m / rig.scales.slope_length_m
    assert m.actuator_gainprm[0, 0] == pytest.approx(k_default, rel=1e-5)  # MJCF keeps 6 digits

    def gap_m():
        x, y, z = d.qpos * L
        return z - r - _surface_height_m(rig, x, y)  # the start region is nearly flat

    for _ in range(400):
        mujoco.mj_step(m, d)
        assert d.ncon >= 1 and abs(gap_m()) < 0.02 * r  # resting: neither buried nor falling
    assert np.linalg.norm(d.qpos[:2] * L - [-0.04, 0.005]) < 1e-3 * r
    touching = 0
    for i in range(600):  # the slider moved slowly to one L_c: the spring pulls the tip along
        d.ctrl[0] = min(1.0, i / 400)
        mujoco.mj_step(m, d)
        # on the flank the centre sits r (1/cos(slope) - 1) above; it chatters by ~1 % of r
        assert -0.05 * r < gap_m() < 0.5 * r
        touching += d.ncon >= 1
    assert touching > 0.3 * 600
    assert d.qpos[0] * L > -0.04 + 0.3 * L


SPINE_MJ = [sys.executable, "-m", "spine_mj.cli"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A short recorded spring run (the tip climbs the peak's flank)."""
    out = tmp_path_factory.mktemp("run")
    args = ["simulate", "paper-single-peak", "--start", "-3,-1", "--speed", "0.05", "--duration", "0.3"]
    result = CliRunner().invoke(main, [*args, "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert (out / "surface.npz").is_file()
    return out


def _headless_env(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    try:
        monkeypatch.setenv("MUJOCO_GL", choose_gl_backend())
    except SpineInputError as exc:
        pytest.skip(f"no headless GL here: {exc}")
    return dict(os.environ)


def test_replay_without_a_display_writes_an_mp4_with_trail_streamline_and_overlay(run_dir, monkeypatch):
    iio = pytest.importorskip(
        "imageio.v3", reason="needs the optional extra 'video': pip install 'spine-mj[video]'"
    )

    _, track = load_run(run_dir)
    span = float(track.time_s[-1] - track.time_s[0])
    mp4 = run_dir / "replay.mp4"
    # 3 s of video at 30 fps: --speed is run seconds per second
    proc = subprocess.run(
        [*SPINE_MJ, "replay", str(run_dir), "--speed", f"{span / 3:.6g}"],
        env=_headless_env(monkeypatch),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "no display: writing an MP4" in proc.stderr and "rendering MP4" in proc.stderr
    frames = iio.imread(mp4)
    assert 85 <= len(frames) <= 95
    last = frames[-1].astype(int)
    r, g, b = last[..., 0], last[..., 1], last[..., 2]
    assert ((r > 200) & (g > 100) & (g < 180) & (b < 60)).sum() > 50  # the orange trail
    assert ((r < 60) & (g > 150) & (b > 170)).sum() > 50  # the cyan streamline
    assert (last[:20, :120].mean() < 90) and (last[:20, :120] > 200).any()  # text on the dark band


def test_streamline_path_starts_at_the_tip_and_rides_the_surface(run_dir):
    rig, track = load_run(run_dir)
    path = streamline_path_m(rig, track.start)
    np.testing.assert_allclose(path[0, :2], np.array(track.start) * rig.length_scale_m, atol=1e-12)
    # the tip centre at the start, recorded by the rig, lies one radius above the same point
    assert path[0, 2] == pytest.approx(track.position_m[0, 2], abs=0.02 * rig.tip.tip_radius_m)


def test_replay_refuses_a_folder_without_the_rig(tmp_path):
    result = CliRunner().invoke(main, ["replay", str(tmp_path), "--mp4", str(tmp_path / "x.mp4")])
    assert result.exit_code == 2
    assert "not a replayable run folder" in result.output and "Traceback" not in result.output


@pytest.mark.skipif(
    shutil.which("xvfb-run") is None, reason="xvfb-run not installed (Debian: apt-get install xvfb)"
)
def test_replay_opens_the_viewer_under_xvfb_and_exits_by_itself(run_dir):
    env = dict(os.environ)
    env.pop("MUJOCO_GL", None)  # the viewer uses GLFW on the X display
    proc = subprocess.run(
        [
            "xvfb-run",
            "-a",
            "-s",
            "-screen 0 1024x768x24",
            *SPINE_MJ,
            "replay",
            str(run_dir),
            "--duration",
            "2",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "replaying" in proc.stderr


@pytest.mark.skipif(
    shutil.which("xvfb-run") is None, reason="xvfb-run not installed (Debian: apt-get install xvfb)"
)
def test_view_runs_the_ready_model_under_xvfb_and_exits_by_itself():
    env = dict(os.environ)
    env.pop("MUJOCO_GL", None)
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", *SPINE_MJ, "view", "paper-single-peak"]
    proc = subprocess.run([*cmd, "--duration", "3"], env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr


def test_display_rule_and_replay_refusals_before_any_run_is_read(tmp_path, monkeypatch):
    from spine_mj.sim.replay import has_display, replay_run

    monkeypatch.setenv("DISPLAY", ":0")
    assert has_display()
    monkeypatch.delenv("DISPLAY")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert has_display() is not sys.platform.startswith("linux")
    with pytest.raises(SpineInputError, match=r"replay to an MP4 .* does not use --duration"):
        replay_run(tmp_path, duration_s=5.0, mp4=tmp_path / "r.mp4")  # an empty folder: not read
