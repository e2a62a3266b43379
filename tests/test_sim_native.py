"""The MuJoCo-native workflow: an exported model that runs in MuJoCo, replay of a recorded
run, and the MP4's trail, streamline and overlay."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj import presets
from spine_mj.cli import main
from spine_mj.sim import Rig


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
    assert m.actuator_gainprm[0, 0] == pytest.approx(10.0)  # 10 F_p / L_c in engine units

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
