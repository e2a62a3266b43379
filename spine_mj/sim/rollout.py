"""Open-loop runs in batches: controls, grouping, and the pipelined native rollout.

Spring drives and static probes need no feedback: their controls are known in advance
(:func:`controls`), so many runs go through :func:`mujoco.rollout.rollout` on native
threads at once. Runs of equal length are grouped (rollout takes one ``nstep`` a call),
groups are cut to stay within 256 MiB of output and simulated in up to 4 pieces,
pipelined: while the native threads simulate one piece, the calling thread analyses the
previous one and places the next (``rollout`` releases the GIL). :func:`python_rollout`
is the plain ``mj_step`` reference of the same call.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
from collections.abc import Sequence

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import (
    Drive,
    RampDrive,
    SpringDrive,
    StaticProbe,
    rate_n_s,
    settle_steps,
    stiffness_n_m,
)
from spine_mj.sim.model import RigModel
from spine_mj.sim.results import RunResult, analyse_group

BATCH_MEMORY_BYTES = 256 * 2**20
PIPELINE_PIECES = 4  # a batch group is simulated in up to this many pieces


def drive_steps(rig: RigModel, drive: Drive, x0_m: float, detection: Detection) -> int:
    """Steps of the drive phase of an open-loop run starting at ``x0_m`` [m]."""
    dt = rig.engine.timestep_s
    if isinstance(drive, SpringDrive):
        duration = drive.duration_s
        if duration is None:
            stretch = (1 + rig.tip.mu_s) * rig.scales.preload_n / stiffness_n_m(drive, rig.scales)
            duration = (1.1 * max(rig.bounds_m[1] - x0_m, 0.0) + stretch) / drive.speed_m_s
        return max(1, int(math.ceil(duration / dt)))
    if isinstance(drive, StaticProbe):
        cap = detection.kappa_cap * rig.scales.preload_n
        rate = rate_n_s(drive, rig.scales)
        return max(1, int(math.ceil((cap - drive.start_force_n) / rate / dt)) + 2)
    raise SpineInputError(
        f"open-loop controls exist for SpringDrive and StaticProbe, got {type(drive).__name__}"
    )


def controls(rig: RigModel, drive: Drive, qpos0: np.ndarray, detection: Detection) -> np.ndarray:
    """Open-loop controls ``(nstep, 6)`` in engine units: ctrl (spring, push, preload) then mocap xyz.

    ``qpos0`` is the placed start (:meth:`RigModel.place`, engine units), ``detection``
    resolved (:meth:`Detection.resolve`): its ``kappa_cap`` bounds a probe's force.
    """
    u = rig.units
    dt = rig.engine.timestep_s
    n_settle = settle_steps(drive, dt)
    cap = detection.kappa_cap * rig.scales.preload_n / u.force_n
    n_drive = drive_steps(rig, drive, qpos0[0] * u.length_m, detection)
    n = n_settle + n_drive
    ctrl = np.zeros((n, 6))
    ctrl[:, 2] = -rig.tip.preload_n / u.force_n
    ctrl[:, 3] = qpos0[0]
    ctrl[:, 4] = qpos0[1]
    ctrl[:, 5] = qpos0[2] + 2 * rig.tip.tip_radius_m / u.length_m
    ramp_t = (dt / u.time_s) * np.arange(1, n_drive + 1)
    if isinstance(drive, SpringDrive):
        ctrl[:, 0] = qpos0[0]
        ctrl[n_settle:, 0] = qpos0[0] + (drive.speed_m_s / u.speed_m_s) * ramp_t
        ctrl[:, 3] = ctrl[:, 0]
    else:
        f0 = drive.start_force_n / u.force_n
        ctrl[:, 1] = f0
        rate = rate_n_s(drive, rig.scales) * u.time_s / u.force_n
        ctrl[n_settle:, 1] = np.minimum(f0 + rate * ramp_t, cap * (1 + 1e-9))
    return ctrl


def plan_batches(lengths: Sequence[int], bytes_per_step: int, nthread: int) -> list[list[int]]:
    """Run indices in pieces of equal length, each within :data:`BATCH_MEMORY_BYTES` of output.

    Runs are grouped by length (shortest first); a group is cut into up to
    :data:`PIPELINE_PIECES` pieces of at least ``nthread`` runs, so one piece can be
    simulated while the previous one is analysed (and the next one placed).
    """
    order = sorted(range(len(lengths)), key=lambda i: lengths[i])
    batches = []
    i = 0
    while i < len(order):
        nstep = lengths[order[i]]
        group = [order[i]]
        limit = max(1, BATCH_MEMORY_BYTES // (bytes_per_step * nstep))
        while i + len(group) < len(order) and len(group) < limit and lengths[order[i + len(group)]] == nstep:
            group.append(order[i + len(group)])
        i += len(group)
        size = max(nthread, -(-len(group) // PIPELINE_PIECES))
        batches += [group[k : k + size] for k in range(0, len(group), size)]
    return batches


def batch_drives(drives, starts) -> tuple[list[Drive], list[tuple[float, float]]]:
    """``drives`` as one drive per start (one drive is shared by all), checked: an open-loop
    batch takes spring drives and static probes only."""
    starts = [tuple(float(v) for v in s) for s in starts]
    if isinstance(drives, (SpringDrive, StaticProbe, RampDrive)):
        drives = [drives] * len(starts)
    drives = list(drives)
    if len(drives) != len(starts):
        raise SpineInputError(f"drives must be one drive or one per start ({len(starts)}), got {len(drives)}")
    if any(isinstance(d, RampDrive) for d in drives):
        raise SpineInputError("RampDrive needs feedback; use Rig.run for it")
    return drives, starts


def run_batch(
    rig: RigModel,
    drives: Drive | Sequence[Drive],
    starts: Sequence[tuple[float, float]],
    *,
    detection: Detection | None = None,
    backend: str = "rollout",
    nthread: int | None = None,
) -> list[RunResult]:
    """Run many starts and/or drive parameter sets of ``rig``'s model (see :meth:`Rig.run_batch`)."""
    drives, starts = batch_drives(drives, starts)
    if backend not in ("rollout", "python"):
        raise SpineInputError(f"backend must be 'rollout' or 'python', got {backend!r}")
    det = (Detection() if detection is None else detection).resolve(rig.scales)
    for x0, y0 in starts:
        rig.check_start(x0, y0)
    runner = _BatchRunner(rig, drives, starts, det)
    nthread = os.cpu_count() or 1 if nthread is None else int(nthread)
    batches = plan_batches(runner.lengths, 8 * (runner.nstate + rig.model.nsensordata), nthread)
    if backend == "python":
        for batch in batches:
            batch, ctrls, init, ctrl = runner.prepare(batch)
            state, sens, warn = python_rollout([runner.models[j] for j in batch], init, ctrl)
            runner.analyse(batch, ctrls, state, sens, warn)
    else:
        runner.pipeline(batches, nthread)
    return runner.results


class _BatchRunner:
    """The runs of one :func:`run_batch` call: their models, lengths, preparation and analysis."""

    def __init__(self, rig: RigModel, drives: list[Drive], starts: list[tuple[float, float]], det: Detection):
        import mujoco

        self.rig, self.drives, self.starts, self.det = rig, drives, starts, det
        by_stiffness: dict[float, object] = {}
        for d in drives:
            k = stiffness_n_m(d, rig.scales) if isinstance(d, SpringDrive) else 0.0
            if k not in by_stiffness:
                by_stiffness[k] = rig.model_for(d)
        self.models = [
            by_stiffness[stiffness_n_m(d, rig.scales) if isinstance(d, SpringDrive) else 0.0] for d in drives
        ]
        s, dt = rig.length_scale_m, rig.engine.timestep_s
        self.lengths = [
            settle_steps(d, dt) + drive_steps(rig, d, x0 * s, det) for d, (x0, _) in zip(drives, starts)
        ]
        self.nstate = mujoco.mj_stateSize(rig.model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        self.results: list[RunResult | None] = [None] * len(starts)

    def prepare(self, batch):
        """Place the batch's tips; their controls, initial states and stacked controls."""
        qpos0 = [self.rig.place(*self.starts[j]) for j in batch]
        ctrls = [controls(self.rig, self.drives[j], q, self.det) for j, q in zip(batch, qpos0)]
        init = np.zeros((len(batch), self.nstate))
        init[:, 1:4] = qpos0
        return batch, ctrls, init, np.stack(ctrls)

    def analyse(self, batch, ctrls, state, sens, warn) -> None:
        """Store the results of a simulated batch."""
        drives, starts = [self.drives[j] for j in batch], [self.starts[j] for j in batch]
        for j, res in zip(batch, analyse_group(self.rig, drives, starts, state, sens, ctrls, self.det, warn)):
            self.results[j] = res

    def pipeline(self, batches: list[list[int]], nthread: int) -> None:
        """Simulate the batches natively, one piece at a time on a helper thread, while the
        calling thread analyses the previous piece and prepares the next."""
        import mujoco
        from mujoco import rollout

        model = self.rig.model
        spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
        pool = rollout.Rollout(nthread=nthread)
        datas = [mujoco.MjData(model) for _ in range(max(1, nthread))]

        def simulate(batch, init, ctrl):
            return pool.rollout(
                [self.models[j] for j in batch],
                datas,
                init,
                ctrl,
                control_spec=spec,
                initial_warmstart=np.zeros((len(batch), model.nv)),
            )

        try:
            with cf.ThreadPoolExecutor(max_workers=1) as sim_thread:
                running = None
                ready = self.prepare(batches[0]) if batches else None
                for k in range(len(batches)):
                    batch, ctrls, init, ctrl = ready
                    future = sim_thread.submit(simulate, batch, init, ctrl)
                    if running is not None:
                        self.analyse(*running)
                    ready = self.prepare(batches[k + 1]) if k + 1 < len(batches) else None
                    running = (batch, ctrls, *future.result(), [None] * len(batch))
                if running is not None:
                    self.analyse(*running)
        finally:
            pool.close()


def warning_total(d) -> int:
    """The number of MuJoCo warnings ``d`` (an ``MjData``) has seen."""
    return int(sum(w.number for w in d.warning))


def warning_text(d) -> str:
    """The names of the warnings ``d`` has seen, comma separated."""
    import mujoco

    names = [n for n in dir(mujoco.mjtWarning) if n.startswith("mjWARN_") and n != "mjWARN_NWARNING"]
    hit = [n for n in names if d.warning[int(getattr(mujoco.mjtWarning, n))].number > 0]
    return ", ".join(h.removeprefix("mjWARN_") for h in hit) or "unknown"


def python_rollout(models, init, ctrl):
    """Reference for :func:`mujoco.rollout.rollout`: a plain ``mj_step`` loop per run.

    Returns state ``(nbatch, nstep, nstate)``, sensordata ``(nbatch, nstep, nsensordata)``
    and per run ``(first step with a new MuJoCo warning or None, warning names)``.
    """
    import mujoco

    nbatch, nstep, _ = ctrl.shape
    m0 = models[0]
    nstate = mujoco.mj_stateSize(m0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.empty((nbatch, nstep, nstate))
    sens = np.empty((nbatch, nstep, m0.nsensordata))
    warns = []
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    for b, m in enumerate(models):
        d = mujoco.MjData(m)
        mujoco.mj_setState(m, d, init[b], full)
        d.qacc_warmstart[:] = 0
        first_warn = None
        for i in range(nstep):
            d.ctrl[:] = ctrl[b, i, :3]
            d.mocap_pos[0] = ctrl[b, i, 3:6]
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, state[b, i], full)
            sens[b, i] = d.sensordata
            if first_warn is None and warning_total(d):
                first_warn = (i, warning_text(d))
        warns.append(first_warn if first_warn is not None else (None, ""))
    return state, sens, warns
