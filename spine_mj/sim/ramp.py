"""The force ramp with reset: the one drive that needs feedback, stepped in Python.

The paper's algorithm (§2.2) in dynamics (:class:`~spine_mj.sim.RampDrive`): the force
rises until slip is detected, keeps rising while the tip slides the set distance, drops to
zero, and ramps again once the tip has been stuck for the settle time.
:class:`ResetController` is that feedback; :func:`run_ramp` steps the model with it and
analyses the run like any other, adding the resets to the events.

Stick-phase fast-forward (``RampDrive.fast_forward``, on by default; the rule is
:class:`~spine_mj.sim.fastforward.StickFastForward`, shared with the static probe). While
the ramp is on, every stick phase may climb fast to just below the breakaway force
predicted from the contact normal and approach it at a few times the nominal rate; the
tip's motion at breakaway puts the run back to the checkpoint taken 8 to 16 steps earlier
(state, controller and recorded rows), and the nominal rate carries the force through
breakaway and the slip. A phase ends early when the contact normal changes. A new phase
needs the tip to have slipped since the last one, or the nominal ramp to have carried
the force past where the last one ended. ``duration_s`` and ``time_s`` count engine
time, so a fast-forwarded run covers more of the path in the same duration;
:func:`nominal_time_s` gives the time the plain ramp would have taken.

What the equivalence neglects. (1) Creep: noslip makes the stick rigid (a stuck tip moves
~1e-11 m/s), so the plain ramp's long stick moves the tip by nothing measurable; without
noslip friction creeps at any load and fast-forward is off. (2) The soft normal contact:
the faster rise loads the contact within ``RISE_STEPS = 50`` contact time constants, far
slower than its response, and the nominal ramp after a rollback lasts 32 to 64 time
constants before breakaway, so the breakaway starts from the same quasistatic contact.
(3) The prediction: it uses the deepest contact's normal; where two facets share the load
(an hfield edge) the breakaway can lie below it by a few per cent (measured up to 1.5 %
on the single peak), inside the default 3 % margin of the climb, or above it (a wedge),
where the approach goes on to the cap; either way the breakaway itself is taken at the
nominal rate. On the cases of ``tests/sim/test_sim_fastforward.py`` and
``benchmarks/bench_fastforward.py`` the breakaway forces agree with the plain ramp's within
0.5 % and the outcomes and paths agree (Frechet <= 0.01 L_c).

Early termination (``RampDrive.stop_early``): every :data:`END_CHECK_STEPS` steps outside
a fast-forward phase the new rows go into the run's analysis
(:class:`~spine_mj.sim.results.GroupAnalysis`, the one the result comes from); at the
first ending the run stops, so the recorded trajectory and end reason are those of the
full run up to its end. With fast-forward a
tip on a self-locking normal reaches the cap within a phase instead of after
``kappa_cap F_p / rate``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from spine_mj.sim.detection import Detection, Event
from spine_mj.sim.drives import RampDrive, rate_n_s, settle_steps
from spine_mj.sim.fastforward import APPROACH_RATE, CHECKPOINT_STEPS, StickFastForward, fast_forward_on
from spine_mj.sim.lanes import warning_text, warning_total
from spine_mj.sim.model import RigModel, start_pair
from spine_mj.sim.results import GroupAnalysis, RunResult

#: Steps between two early-termination checks.
END_CHECK_STEPS = 256


class ResetController:
    """The ramp's feedback: the push force of each step from the tip's motion so far.

    Parameters
    ----------
    step_n : float
        Force added per step while ramping at the nominal rate [N].
    cap_n : float
        Largest force [N].
    slide_distance_m : float
        Horizontal slide after slip onset at which the force drops to 0 [m].
    settle_steps : int
        Steps the tip must stay stuck before the ramp starts again.
    move_speed_m_s : float
        Tangential speed above which the tip slips.
    sensor_adr : dict
        Sensor addresses of the rig (:attr:`RigModel.sensor_adr`).
    fast_forward : StickFastForward or None
        Stick-phase fast-forward; None ramps at the nominal rate throughout.
    """

    _SNAPSHOT = ("force", "ramping", "stuck_steps", "slip_from", "normal", "resets")

    def __init__(
        self, *, step_n, cap_n, slide_distance_m, settle_steps, move_speed_m_s, sensor_adr, fast_forward=None
    ):
        self.step_n, self.cap_n, self.slide_distance_m = step_n, cap_n, slide_distance_m
        self.settle_steps, self.move_speed_m_s, self.adr = settle_steps, move_speed_m_s, sensor_adr
        self.ff = fast_forward
        self.force, self.ramping, self.stuck_steps = 0.0, True, 0
        self.slip_from = None  # (x, y) where the current slip began, while the force still acts
        self.normal = np.zeros(3)  # normal of the last contact
        self.resets: list[int] = []

    def snapshot(self) -> dict:
        """The controller's state (the fast-forward's own state is not part of it)."""
        snap = {k: getattr(self, k) for k in self._SNAPSHOT}
        snap["normal"], snap["resets"] = self.normal.copy(), list(self.resets)
        return snap

    def restore(self, snap: dict) -> None:
        for k, v in snap.items():
            setattr(self, k, v.copy() if isinstance(v, (np.ndarray, list)) else v)

    def push(self) -> float:
        """The push force of the next step (the ramp advances while ramping)."""
        if self.ramping:
            if self.ff is not None and self.ff.active:
                self.force = min(self.force + self.ff.step_n, self.ff.target_n)
            else:
                self.force = min(self.force + self.step_n, self.cap_n)
        return self.force if self.ramping else 0.0

    def observe(self, i: int, sens: np.ndarray, *, driving: bool) -> str:
        """Update from step ``i``'s sensordata; ``driving`` is False during the settle phase.

        Returns the fast-forward's verdict (``"start"``, ``"rollback"`` or ``""``).
        """
        a = self.adr
        vel = sens[a["tip_vel"] : a["tip_vel"] + 3]
        contact = bool(sens[a["contact_deepest"]] > 0)
        if contact:
            self.normal = sens[a["contact_deepest"] + 5 : a["contact_deepest"] + 8]
        nrm = self.normal
        vt = float(np.linalg.norm(vel - (vel @ nrm) * nrm))
        if not driving:
            return ""
        verdict = ""
        if self.ff is not None and self.ramping:
            out = nrm if nrm[2] >= 0 else -nrm
            verdict = self.ff.watch(vt, out, contact, self.force, self.step_n)
            if verdict == "rollback":
                return verdict
        if self.ramping and self.slip_from is None and vt > self.move_speed_m_s:
            self.slip_from = sens[a["tip_pos"] : a["tip_pos"] + 2].copy()
        if self.ramping and self.slip_from is not None:
            moved = sens[a["tip_pos"] : a["tip_pos"] + 2] - self.slip_from
            if math.hypot(moved[0], moved[1]) >= self.slide_distance_m:
                self.ramping, self.stuck_steps, self.slip_from = False, 0, None
                self.force = 0.0
                if self.ff is not None:
                    self.ff.active = False
        elif not self.ramping:
            self.stuck_steps = self.stuck_steps + 1 if vt <= self.move_speed_m_s else 0
            if self.stuck_steps >= self.settle_steps:
                self.ramping = True
                self.resets.append(i)
        return verdict


def rows_to_reset(result: RunResult, cycles: int) -> int:
    """Rows of a ramp run up to its ``cycles``-th reset (the whole run if it has fewer)."""
    resets = [e.index for e in result.events if e.kind == "reset"]
    return resets[cycles - 1] + 1 if len(resets) >= cycles else result.n


def cycle_breakaways(result: RunResult, cycles: int) -> np.ndarray:
    """Drive force / F_p at the first slip onset of each ramp cycle (after the start and
    after each reset), at most ``cycles`` of them: what a fast-forwarded ramp must keep."""
    out, armed = [], True
    for e in result.events:
        if e.kind == "reset":
            armed = True
        elif e.kind == "move_onset" and armed:
            out.append(result.drive_force_n[e.index] / result.scales.preload_n)
            armed = False
    return np.array(out[:cycles])


def nominal_time_s(result: RunResult) -> np.ndarray:
    """The time the plain ramp (no fast-forward) would have taken to reach each row [s].

    A step whose force rose by more than the nominal increment counts for the time the
    nominal rate needs for that rise; every other step for one time step. Equals
    ``result.time_s`` for a run without fast-forward.
    """
    dt = result.engine.timestep_s
    step = rate_n_s(result.drive, result.scales) * dt
    rise = np.diff(result.drive_force_n, prepend=0.0)
    per = np.where(rise > step * (1 + 1e-6), rise / step, 1.0) * dt
    per[: result.drive_start_index] = dt
    return result.time_s[0] - dt + np.cumsum(per)


class _Stepper:
    """The stepping loop's arrays, checkpoints and the analysis of its rows: one row per
    engine step."""

    def __init__(self, m, d, nstep: int, ctl: ResetController, analysis: GroupAnalysis):
        import mujoco

        self.m, self.d, self.ctl = m, d, ctl
        self.analysis, self.analysed = analysis, 0  # rows 0..analysed-1 are in the analysis
        self.full = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.exact = mujoco.mjtState.mjSTATE_INTEGRATION  # warm start included: an exact restart
        self.state = np.empty((nstep, mujoco.mj_stateSize(m, self.full)))
        self.sens = np.empty((nstep, m.nsensordata))
        self.ctrl_log = np.zeros((nstep, 6))
        self.ck_size = mujoco.mj_stateSize(m, self.exact)
        self.checkpoints: list[tuple[int, np.ndarray, dict]] = []
        self.steps = 0  # engine steps taken, rolled-back ones included

    def record(self, i: int, push_id: int) -> None:
        import mujoco

        mujoco.mj_getState(self.m, self.d, self.state[i], self.full)
        self.sens[i] = self.d.sensordata
        self.ctrl_log[i, 1] = self.d.ctrl[push_id]

    def checkpoint(self, next_row: int, *, fresh: bool) -> None:
        """Remember the state before row ``next_row``: the last two of a phase are kept
        (``fresh``: the first of a new phase)."""
        import mujoco

        buf = np.empty(self.ck_size)
        mujoco.mj_getState(self.m, self.d, buf, self.exact)
        kept = [] if fresh else self.checkpoints[-1:]
        self.checkpoints = [*kept, (next_row, buf, self.ctl.snapshot())]

    def rollback(self) -> int:
        """Go back to the older checkpoint; returns the row to write next."""
        import mujoco

        row, buf, snap = self.checkpoints[0]
        mujoco.mj_setState(self.m, self.d, buf, self.exact)
        self.ctl.restore(snap)
        self.checkpoints = []
        return row

    def analyse_to(self, b: int) -> bool:
        """Add rows ``analysed..b-1`` to the run's analysis (they are final: a rollback never
        reaches back before the phase, and rows are added outside phases); whether the run
        has an ending by row b-1."""
        a, self.analysed = self.analysed, max(b, self.analysed)
        if b <= a:
            return False
        return bool(self.analysis.add(slice(0, 1), a, b, self.state[None], self.sens[None])[0])


def _controller(rig: RigModel, drive: RampDrive, det: Detection, n_settle: int) -> ResetController:
    """The drive's controller, with stick-phase fast-forward where the drive and engine allow it.

    The controller reads the engine's sensors, so its forces, lengths and speeds are given
    in engine units (``rig.units``); the drive and detection settings are SI.
    """
    u = rig.units
    dt = rig.engine.timestep_s
    cap = det.kappa_cap * rig.scales.preload_n / u.force_n
    ff = None
    if fast_forward_on(drive, rig.engine, rig.tip):
        ff = StickFastForward(
            mu=rig.tip.mu_s,
            preload_n=rig.scales.preload_n / u.force_n,
            cap_n=cap * (1 + 1e-9),
            margin=drive.fast_forward_margin,
            stick_speed_m_s=det.stick_speed_m_s / u.speed_m_s,
            move_speed_m_s=det.move_speed_m_s / u.speed_m_s,
            approach_rate=APPROACH_RATE,
        )
    slide = drive.slide_distance_m
    return ResetController(
        step_n=rate_n_s(drive, rig.scales) * dt / u.force_n,
        cap_n=cap * (1 + 1e-9),
        slide_distance_m=(0.01 * rig.scales.char_length_m if slide is None else slide) / u.length_m,
        settle_steps=n_settle,
        move_speed_m_s=det.move_speed_m_s / u.speed_m_s,
        sensor_adr=rig.sensor_adr,
        fast_forward=ff,
    )


def _step_loop(rig, st: _Stepper, nstep: int, n_settle: int, stop_early: bool, progress):
    """Step until ``nstep`` rows, an early end or engine trouble; returns (rows, warning)."""
    import mujoco

    m, d, ctl = st.m, st.d, st.ctl
    ff = ctl.ff
    warn_total, i = warning_total(d), 0
    while i < nstep:
        if i >= n_settle:
            d.ctrl[rig.act_push] = ctl.push()
        mujoco.mj_step(m, d)
        st.steps += 1
        st.record(i, rig.act_push)
        if i % 64 == 63 and warning_total(d) != warn_total:
            return i + 1, (i, warning_text(d))
        if not np.isfinite(st.state[i]).all():
            return i + 1, None
        verdict = ctl.observe(i, st.sens[i], driving=i >= n_settle)
        if verdict == "rollback":
            i = st.rollback()
            continue
        i += 1
        if verdict == "start" or (ff is not None and ff.active and i % CHECKPOINT_STEPS == 0):
            st.checkpoint(i, fresh=verdict == "start")
        if (
            stop_early
            and not (ff is not None and ff.active)
            and (i - st.analysed >= END_CHECK_STEPS or i == nstep)
            and st.analyse_to(i)
        ):
            return i, None
        if progress is not None and i % 2000 == 0:
            progress(i / nstep)
    return nstep, None


def ramp_duration_s(drive: RampDrive, det: Detection, scales) -> float:
    """The ramp's drive phase [s]: its ``duration_s``, else 40 ramps to ``kappa_cap F_p``,
    capped at 200 tau (:class:`~spine_mj.sim.RampDrive`); ``det`` resolved."""
    if drive.duration_s is not None:
        return drive.duration_s
    return min(40 * det.kappa_cap * scales.preload_n / rate_n_s(drive, scales), 200 * scales.time_s)


def run_ramp(
    rig: RigModel,
    drive: RampDrive,
    start: tuple[float, float],
    detection: Detection | None,
    progress: Callable[[float], None] | None,
) -> RunResult:
    """Run the force ramp with reset from ``start`` (surface units); see :meth:`Rig.run`."""
    import mujoco

    rig.check_drive(drive)
    det = (Detection() if detection is None else detection).resolve(rig.scales)
    start = start_pair(start)
    u = rig.units  # the model is in engine units (spine_mj.sim.scales.EngineUnits)
    qpos0 = rig.place(*start)
    m = rig.model_for(drive)
    d = mujoco.MjData(m)
    d.qpos[:] = qpos0
    d.ctrl[rig.act_preload] = -rig.tip.preload_n / u.force_n
    d.mocap_pos[0] = qpos0 + np.array([0.0, 0.0, 2 * rig.tip.tip_radius_m / u.length_m])
    dt = rig.engine.timestep_s
    n_settle = settle_steps(drive, dt)
    nstep = n_settle + int(math.ceil(ramp_duration_s(drive, det, rig.scales) / dt))
    ctl = _controller(rig, drive, det, n_settle)
    st = _Stepper(m, d, nstep, ctl, GroupAnalysis(rig, [drive], [start], det, np.full((1, nstep), np.nan)))
    stop, warning = _step_loop(rig, st, nstep, n_settle, drive.stop_early, progress)
    st.analyse_to(stop)
    result = st.analysis.results([warning or (None, "")])[0]
    resets = tuple(Event("reset", i, float(st.state[i, 0])) for i in ctl.resets if i < result.n)
    events = sorted(result.events + resets, key=lambda e: (e.index, e.kind == result.end_reason.value))
    return dataclasses.replace(result, events=tuple(events), simulated_steps=st.steps)
