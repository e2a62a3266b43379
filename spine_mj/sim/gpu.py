"""Open-loop batches on a GPU through MuJoCo Warp: the optional backend of ``run_batch``.

Install with ``pip install 'spine_mj[gpu]'`` (``mujoco-warp``, which brings ``warp-lang``).
:func:`run_batch_gpu` takes a rig, drives, starts and the :class:`~spine_mj.sim.rollout.BatchOptions`
of :meth:`Rig.run_batch` and returns the
same :class:`~spine_mj.sim.results.RunResult` objects: tips are placed, controls built and
runs analysed by the same public functions as the CPU rollout
(:func:`~spine_mj.sim.rollout.controls`, :func:`~spine_mj.sim.results.analyse_group`);
only the stepping moves to the device, every world one run.

Choosing the backend (:func:`resolve_backend`):

* ``"gpu"``: MuJoCo Warp on a CUDA device. Without the packages: one
  :class:`~spine_mj.errors.SpineInputError` naming the missing one; without a CUDA device:
  a SpineInputError saying so (no silent fallback: a user who asked for the GPU learns
  that none is used).
* ``"auto"``: the GPU when the packages and a CUDA device are present, else the CPU
  ``mujoco.rollout`` (the same results up to the engines' differences below).

Engine differences. MuJoCo Warp steps in float32 (the CPU engine in float64) and, from
mujoco-warp 4.0 on, has the noslip pass the rig relies on to hold a stuck tip
(docs/physics.md §5); older MuJoCo Warp and MJX have none, so a rig for them needs
``noslip_iterations=0`` and a high ``impratio``. ``benchmarks/run_all.py --gpu`` measures the
static kappa error of both settings against the CPU engine on inclined planes.
``BatchOptions(device="cpu")`` runs MuJoCo Warp on Warp's CPU device (slow; for checking the path where
no GPU exists).
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
from collections.abc import Sequence

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import Drive, SpringDrive, settle_steps, stiffness_n_m
from spine_mj.sim.model import RigModel
from spine_mj.sim.open_loop import controls, drive_steps
from spine_mj.sim.results import RunResult, analyse_group
from spine_mj.sim.rollout import BatchOptions, batch_drives, run_batch

# import name -> the PyPI package that provides it
GPU_PACKAGES = {"warp": "warp-lang", "mujoco_warp": "mujoco-warp"}
BACKENDS = ("rollout", "python", "gpu", "auto")
DEVICE_MEMORY_BYTES = 1 << 30  # recorded history per device chunk
CONTACTS_PER_WORLD = 64  # MuJoCo keeps at most 50 sphere-hfield contacts


def missing_packages() -> list[str]:
    """PyPI names of the GPU backend's packages that are not installed (import not tried)."""
    return [pkg for mod, pkg in GPU_PACKAGES.items() if importlib.util.find_spec(mod) is None]


def require_packages():
    """Import and return ``(warp, mujoco_warp)``.

    Raises
    ------
    SpineInputError
        A package is missing (named, with the install command) or fails to import.
    """
    missing = missing_packages()
    if missing:
        raise SpineInputError(
            f"the GPU backend needs the package(s) {', '.join(missing)}: pip install 'spine_mj[gpu]'"
        )
    try:
        wp = importlib.import_module("warp")
        mjw = importlib.import_module("mujoco_warp")
    except Exception as exc:  # a broken install: say which, not a traceback
        raise SpineInputError(f"the GPU backend's packages fail to import: {exc}") from None
    return wp, mjw


def cuda_device_count() -> int:
    """CUDA devices Warp sees; 0 without the packages or a driver."""
    if missing_packages():
        return 0
    try:
        wp, _ = require_packages()
        wp.init()
        return int(wp.get_cuda_device_count())
    except Exception:
        return 0


def gpu_available() -> bool:
    """Whether :func:`run_batch_gpu` can run on a CUDA device here."""
    return cuda_device_count() > 0


def resolve_backend(backend: str) -> str:
    """The backend that runs: ``"auto"`` becomes ``"gpu"`` or ``"rollout"``.

    Raises
    ------
    SpineInputError
        An unknown name; ``"gpu"`` without its packages or without a CUDA device.
    """
    if backend not in BACKENDS:
        raise SpineInputError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
    if backend == "auto":
        return "gpu" if gpu_available() else "rollout"
    if backend == "gpu":
        require_packages()
        if not gpu_available():
            raise SpineInputError(
                "backend 'gpu' needs a CUDA device and Warp finds none; use backend='auto' to fall "
                "back to the CPU rollout"
            )
    return backend


def run_batch_gpu(
    rig: RigModel,
    drives: Drive | Sequence[Drive],
    starts: Sequence[tuple[float, float]],
    options: BatchOptions | None = None,
) -> list[RunResult]:
    """:meth:`Rig.run_batch` with the stepping on a GPU (MuJoCo Warp).

    Parameters
    ----------
    rig : RigModel
    drives, starts
        As for :meth:`Rig.run_batch`.
    options : BatchOptions or None
        As for :meth:`Rig.run_batch` (None: ``BatchOptions(backend="gpu")``). ``backend``:
        see the module docstring; the CPU names run :func:`spine_mj.sim.rollout.run_batch`,
        which alone uses ``nthread``. ``device``: the Warp device (None: the CUDA device;
        ``"cpu"`` runs MuJoCo Warp on the CPU, for tests).

    Returns
    -------
    list of RunResult
        One per start, in order.

    Raises
    ------
    SpineInputError
        As :func:`resolve_backend`; bad drives or starts as :meth:`Rig.run_batch`.
    """
    opt = BatchOptions(backend="gpu") if options is None else options
    backend, device = opt.backend, opt.device
    if device is None or backend != "gpu":
        backend = resolve_backend(backend)
    if backend != "gpu":
        return run_batch(rig, drives, starts, dataclasses.replace(opt, backend=backend))
    wp, mjw = require_packages()
    drives, starts = batch_drives(drives, starts)
    det = (Detection() if opt.detection is None else opt.detection).resolve(rig.scales)
    rig.check_starts(starts, det.domain_margin_m)
    dev = device or "cuda:0"
    dt, s = rig.engine.timestep_s, rig.length_scale_m
    lengths = [settle_steps(d, dt) + drive_steps(rig, d, x0 * s, det) for d, (x0, _) in zip(drives, starts)]
    groups: dict[tuple[float, int], list[int]] = {}
    for j, d in enumerate(drives):
        k = stiffness_n_m(d, rig.scales) if isinstance(d, SpringDrive) else 0.0
        groups.setdefault((k, lengths[j]), []).append(j)
    results: list[RunResult | None] = [None] * len(starts)
    for (_, nstep), idx in groups.items():
        model = rig.model_for(drives[idx[0]])
        per_world = 8 * nstep * (model.nq + model.nv + model.nsensordata)
        size = max(1, DEVICE_MEMORY_BYTES // per_world)
        for c in range(0, len(idx), size):
            chunk = idx[c : c + size]
            qpos0 = [rig.place(*starts[j]) for j in chunk]
            ctrls = [controls(rig, drives[j], q, det) for j, q in zip(chunk, qpos0)]
            state, sens = simulate(wp, mjw, model, np.stack(qpos0), np.stack(ctrls), dev)
            group = analyse_group(
                rig,
                [drives[j] for j in chunk],
                [starts[j] for j in chunk],
                state,
                sens,
                ctrls,
                det,
                [None] * len(chunk),
            )
            for j, res in zip(chunk, group):
                results[j] = res
    return results


def state_layout(model) -> dict[str, slice]:
    """Slices of ``time``, ``qpos``, ``qvel`` (and ``mocap_pos``, ``mocap_quat`` where the
    MuJoCo version has them there) in the ``mjSTATE_FULLPHYSICS`` vector of ``model``
    (elements in their bit order)."""
    import mujoco

    full = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
    names = {
        "mjSTATE_TIME": "time",
        "mjSTATE_QPOS": "qpos",
        "mjSTATE_QVEL": "qvel",
        "mjSTATE_MOCAP_POS": "mocap_pos",
        "mjSTATE_MOCAP_QUAT": "mocap_quat",
    }
    bits = sorted(
        (int(getattr(mujoco.mjtState, n)), n)
        for n in dir(mujoco.mjtState)
        if n.startswith("mjSTATE_") and bin(int(getattr(mujoco.mjtState, n))).count("1") == 1
    )
    out, at = {}, 0
    for bit, name in bits:
        if not full & bit:
            continue
        size = mujoco.mj_stateSize(model, bit)
        if name in names:
            out[names[name]] = slice(at, at + size)
        at += size
    return out


def simulate(wp, mjw, model, qpos0: np.ndarray, ctrl: np.ndarray, device: str):
    """Step ``len(qpos0)`` worlds of ``model`` on ``device`` with open-loop ``ctrl``
    ``(nworld, nstep, 6)`` (ctrl then mocap xyz, as :func:`~spine_mj.sim.rollout.controls`).

    Returns state ``(nworld, nstep, nstate)`` (``mjSTATE_FULLPHYSICS`` layout; time, qpos,
    qvel and the mocap filled) and sensordata ``(nworld, nstep, nsensordata)``, float64.
    """
    import mujoco

    nworld, nstep, _ = ctrl.shape
    d0 = mujoco.MjData(model)
    with wp.ScopedDevice(device):
        m = mjw.put_model(model)
        d = mjw.put_data(model, d0, nworld=nworld, nconmax=CONTACTS_PER_WORLD, njmax=3 * CONTACTS_PER_WORLD)
        wp.copy(d.qpos, wp.array(qpos0.astype(np.float32), dtype=float))
        ctrl_dev = wp.array(np.ascontiguousarray(ctrl[:, :, :3].transpose(1, 0, 2), np.float32), dtype=float)
        mocap = np.ascontiguousarray(ctrl[:, :, 3:6].transpose(1, 0, 2)[:, :, None, :], np.float32)
        mocap_dev = wp.array(mocap, dtype=wp.vec3)
        hist = {
            name: wp.zeros((nstep, nworld, n), dtype=float)
            for name, n in (("qpos", model.nq), ("qvel", model.nv), ("sens", model.nsensordata))
        }
        graph = None
        if wp.get_device(device).is_cuda:
            mjw.step(m, d)  # compile the kernels outside the capture; the state is reset below
            wp.copy(d.qpos, wp.array(qpos0.astype(np.float32), dtype=float))
            d.qvel.zero_()
            d.qacc_warmstart.zero_()
            d.time.zero_()
            with wp.ScopedCapture() as cap:
                mjw.step(m, d)
            graph = cap.graph
        for i in range(nstep):
            wp.copy(d.ctrl, ctrl_dev[i])
            wp.copy(d.mocap_pos, mocap_dev[i])
            if graph is None:
                mjw.step(m, d)
            else:
                wp.capture_launch(graph)
            wp.copy(hist["qpos"][i], d.qpos)
            wp.copy(hist["qvel"][i], d.qvel)
            wp.copy(hist["sens"][i], d.sensordata)
        host = {k: v.numpy().astype(np.float64).transpose(1, 0, 2) for k, v in hist.items()}
    return _full_state(model, host, ctrl), host["sens"]


def _full_state(model, host: dict, ctrl: np.ndarray) -> np.ndarray:
    """The ``mjSTATE_FULLPHYSICS`` rows of a recorded history (other elements zero)."""
    import mujoco

    nworld, nstep, _ = ctrl.shape
    layout = state_layout(model)
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.zeros((nworld, nstep, nstate))
    state[:, :, layout["time"]] = (model.opt.timestep * np.arange(1, nstep + 1))[None, :, None]
    state[:, :, layout["qpos"]] = host["qpos"]
    state[:, :, layout["qvel"]] = host["qvel"]
    if "mocap_pos" in layout:  # not part of FULLPHYSICS from MuJoCo 4 on
        state[:, :, layout["mocap_pos"]] = ctrl[:, :, 3:6]
        quat = np.zeros(layout["mocap_quat"].stop - layout["mocap_quat"].start)
        quat[0::4] = 1.0
        state[:, :, layout["mocap_quat"]] = quat
    return state
