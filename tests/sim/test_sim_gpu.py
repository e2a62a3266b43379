"""The optional GPU backend (MuJoCo Warp): its import guards, the CPU fallback, and, where
the packages are installed, its trajectories on Warp's CPU device against the CPU engine."""

from __future__ import annotations

import sys

import mujoco
import numpy as np
import pytest
from sim_rigs import MU, START, flat_rig

from spine_mj.errors import SpineInputError
from spine_mj.sim import BatchOptions, SpringDrive, gpu

DRIVE = SpringDrive(speed_m_s=0.01, stiffness_n_m=50.0, duration_s=0.25)  # slides after ~0.1 s
STARTS = [START, (1e-3, -2e-3)]


@pytest.fixture(scope="module")
def rig():
    return flat_rig()


def test_missing_package_is_one_clear_error(rig, monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco_warp", None)  # what find_spec reports when absent
    assert "mujoco-warp" in gpu.missing_packages()
    with pytest.raises(SpineInputError, match=r"mujoco-warp.*pip install 'spine_mj\[gpu\]'"):
        gpu.run_batch_gpu(rig, DRIVE, STARTS, BatchOptions(backend="gpu"))
    assert gpu.cuda_device_count() == 0


def test_gpu_without_cuda_refuses(rig):
    if gpu.gpu_available():
        pytest.skip("a CUDA device is present")
    with pytest.raises(SpineInputError, match=r"CUDA device|spine_mj\[gpu\]"):
        gpu.resolve_backend("gpu")


def test_auto_falls_back_to_the_cpu_rollout(rig):
    if gpu.gpu_available():
        pytest.skip("a CUDA device is present: auto runs on it")
    assert gpu.resolve_backend("auto") == "rollout"
    got = gpu.run_batch_gpu(rig, DRIVE, STARTS, BatchOptions(backend="auto"))
    ref = rig.run_batch(DRIVE, STARTS)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a.position_m, b.position_m)
        assert a.end_reason is b.end_reason


def test_unknown_backend_is_refused():
    with pytest.raises(SpineInputError, match="backend must be one of"):
        gpu.resolve_backend("cuda")


def test_state_layout_matches_mj_get_state(rig):
    m = rig.model
    d = mujoco.MjData(m)
    d.time, d.qpos[:], d.qvel[:] = 0.25, [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]
    state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    lay = gpu.state_layout(m)
    assert state[lay["time"]].tolist() == [0.25]
    assert state[lay["qpos"]].tolist() == [1.0, 2.0, 3.0]
    assert state[lay["qvel"]].tolist() == [4.0, 5.0, 6.0]


@pytest.mark.slow
def test_warp_on_cpu_matches_the_cpu_engine(rig):
    """Flat ground, spring drive past breakaway: the tip slides at mu N on both engines.

    Tolerances: MuJoCo Warp steps in float32 (relative eps 6e-8). While the tip is stuck
    the two agree to 1e-7 m (a tenth of a micrometre on 1e-3 m positions). Once it slides,
    the contact chatters on the scale of the contact's depth per step, a_p dt^2 = 2.5e-6 m,
    and float32 rounding shifts the stick-slip chatter by a step here and there; the shift
    accumulates over the 0.15 s of sliding: 5e-5 m (10 % of the tip radius, 2 % of the
    2.5 mm path) bounds it (measured 2.4e-5 m on Warp's CPU device). The sliding force ratio
    must hold mu within 3 % on both (the noslip pass holds it; without noslip the soft
    friction cone creeps below mu N).
    """
    pytest.importorskip("mujoco_warp")
    got = gpu.run_batch_gpu(rig, DRIVE, STARTS, BatchOptions(backend="gpu", device="cpu"))
    ref = rig.run_batch(DRIVE, STARTS)
    for a, b in zip(got, ref):
        assert a.n == b.n and a.end_reason is b.end_reason
        stuck = np.flatnonzero(b.moving[b.drive_start_index :])[0] + b.drive_start_index
        np.testing.assert_allclose(a.position_m[:stuck], b.position_m[:stuck], rtol=0, atol=1e-7)
        np.testing.assert_allclose(a.position_m, b.position_m, rtol=0, atol=5e-5)
        for r in (a, b):
            sliding = r.moving & r.contact & (np.arange(r.n) > r.drive_start_index)
            assert r.moving[-50:].all() and sliding.sum() > 100
            ratio = r.tangential_force_n[sliding] / r.normal_force_n[sliding]
            assert np.median(ratio) == pytest.approx(MU, rel=0.03)
