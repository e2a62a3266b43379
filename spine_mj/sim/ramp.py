"""The force ramp with reset: the one drive that needs feedback, stepped in Python.

The paper's algorithm (§2.2) in dynamics (:class:`~spine_mj.sim.RampDrive`): the force
rises until slip is detected, keeps rising while the tip slides the set distance, drops to
zero, and ramps again once the tip has been stuck for the settle time.
:class:`ResetController` is that feedback; :func:`run_ramp` steps the model with it and
analyses the run like any other, adding the resets to the events.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from spine_mj.sim.detection import Detection, Event
from spine_mj.sim.drives import RampDrive, rate_n_s, settle_steps
from spine_mj.sim.model import RigModel
from spine_mj.sim.results import RunResult, analyse
from spine_mj.sim.rollout import warning_text, warning_total


class ResetController:
    """The ramp's feedback: the push force of each step from the tip's motion so far.

    Parameters
    ----------
    step_n : float
        Force added per step while ramping [N].
    cap_n : float
        Largest force [N].
    slide_distance_m : float
        Horizontal slide after slip onset at which the force drops to 0 [m].
    settle_steps : int
        Steps the tip must stay stuck before the ramp starts again.
    slip_speed_m_s : float
        Tangential speed above which the tip slips.
    sensor_adr : dict
        Sensor addresses of the rig (:attr:`RigModel.sensor_adr`).
    """

    def __init__(self, *, step_n, cap_n, slide_distance_m, settle_steps, slip_speed_m_s, sensor_adr):
        self.step_n, self.cap_n, self.slide_distance_m = step_n, cap_n, slide_distance_m
        self.settle_steps, self.slip_speed_m_s, self.adr = settle_steps, slip_speed_m_s, sensor_adr
        self.force, self.ramping, self.stuck_steps = 0.0, True, 0
        self.slip_from = None  # (x, y) where the current slip began, while the force still acts
        self.normal = np.zeros(3)  # normal of the last contact
        self.resets: list[int] = []

    def push(self) -> float:
        """The push force of the next step (the ramp advances while ramping)."""
        if self.ramping:
            self.force = min(self.force + self.step_n, self.cap_n)
        return self.force if self.ramping else 0.0

    def observe(self, i: int, sens: np.ndarray, *, driving: bool) -> None:
        """Update from step ``i``'s sensordata; ``driving`` is False during the settle phase."""
        a = self.adr
        vel = sens[a["tip_vel"] : a["tip_vel"] + 3]
        if sens[a["contact_deepest"]] > 0:
            self.normal = sens[a["contact_deepest"] + 5 : a["contact_deepest"] + 8]
        nrm = self.normal
        vt = float(np.linalg.norm(vel - (vel @ nrm) * nrm))
        if not driving:
            return
        if self.ramping and self.slip_from is None and vt > self.slip_speed_m_s:
            self.slip_from = sens[a["tip_pos"] : a["tip_pos"] + 2].copy()
        if self.ramping and self.slip_from is not None:
            moved = sens[a["tip_pos"] : a["tip_pos"] + 2] - self.slip_from
            if math.hypot(moved[0], moved[1]) >= self.slide_distance_m:
                self.ramping, self.stuck_steps, self.slip_from = False, 0, None
                self.force = 0.0
        elif not self.ramping:
            self.stuck_steps = self.stuck_steps + 1 if vt <= self.slip_speed_m_s else 0
            if self.stuck_steps >= self.settle_steps:
                self.ramping = True
                self.resets.append(i)


def run_ramp(
    rig: RigModel,
    drive: RampDrive,
    start: tuple[float, float],
    detection: Detection | None,
    progress: Callable[[float], None] | None,
) -> RunResult:
    """Run the force ramp with reset from ``start`` (surface units); see :meth:`Rig.run`."""
    import mujoco

    det = (Detection() if detection is None else detection).resolve(rig.scales)
    start = tuple(float(v) for v in start)
    u = rig.units  # the model is in engine units (spine_mj.sim.params.EngineUnits)
    qpos0 = rig.place(*start)
    m = rig.model_for(drive)
    d = mujoco.MjData(m)
    d.qpos[:] = qpos0
    d.ctrl[rig.act_preload] = -rig.tip.preload_n / u.force_n
    d.mocap_pos[0] = qpos0 + np.array([0.0, 0.0, 2 * rig.tip.tip_radius_m / u.length_m])
    dt = rig.engine.timestep_s
    rate = rate_n_s(drive, rig.scales)
    cap = det.kappa_cap * rig.scales.preload_n
    n_settle = settle_steps(drive, dt)
    duration = drive.duration_s
    if duration is None:
        duration = min(40 * cap / rate, 200 * rig.scales.time_s)
    nstep = n_settle + int(math.ceil(duration / dt))
    nstate = mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.empty((nstep, nstate))
    sens = np.empty((nstep, m.nsensordata))
    ctrl_log = np.zeros((nstep, 6))
    slide = 0.01 * rig.scales.char_length_m if drive.slide_distance_m is None else drive.slide_distance_m
    ctl = ResetController(
        step_n=rate * dt / u.force_n,
        cap_n=cap * (1 + 1e-9) / u.force_n,
        slide_distance_m=slide / u.length_m,
        settle_steps=n_settle,
        slip_speed_m_s=det.slip_speed_m_s / u.speed_m_s,
        sensor_adr=rig.sensor_adr,
    )
    stop, warn_total, warn_at = nstep, warning_total(d), None
    for i in range(nstep):
        if i >= n_settle:
            d.ctrl[rig.act_push] = ctl.push()
        mujoco.mj_step(m, d)
        mujoco.mj_getState(m, d, state[i], mujoco.mjtState.mjSTATE_FULLPHYSICS)
        sens[i] = d.sensordata
        ctrl_log[i, 1] = d.ctrl[rig.act_push]
        if i % 64 == 63 and warning_total(d) != warn_total:
            warn_at, stop = (i, warning_text(d)), i + 1
            break
        if not np.isfinite(state[i]).all():
            stop = i + 1
            break
        ctl.observe(i, sens[i], driving=i >= n_settle)
        if progress is not None and i % 2000 == 0:
            progress(i / nstep)
    state, sens, ctrl_log = state[:stop], sens[:stop], ctrl_log[:stop]
    warning = warn_at if warn_at is not None else (None, "")
    result = analyse(rig, drive, start, state, sens, ctrl_log, det, warning)
    resets = tuple(Event("reset", i, float(state[i, 0])) for i in ctl.resets if i < result.n)
    events = sorted(result.events + resets, key=lambda e: (e.index, e.kind == result.end_reason.value))
    return dataclasses.replace(result, events=tuple(events))
