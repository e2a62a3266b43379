"""The result of a run, and the analysis that turns a rollout into results.

:class:`RunResult` is what every drive returns. :class:`GroupAnalysis` reads a group of
runs of equal planned length, window by window (rows a..b-1 of some of its runs, as the
batch runner simulates them): the per-step :class:`~spine_mj.sim.recording.Recording` and
the end conditions of a window are computed for its runs at once and merged with the
earlier windows, so the runner knows after every window which runs are decided; at the end
each run gets its ending, its slip events and its result, a cut of the group's columns.
:func:`analyse_group` is the same analysis of whole runs in one window.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from spine_mj.sim.detection import (
    LOCK_RISE_FP,
    MARK_KEYS,
    Detection,
    Ending,
    Event,
    decide_end,
    end_candidates,
    end_marks,
    move_events,
    normal_lock_marks,
    probe_candidates,
)
from spine_mj.sim.drives import Drive, SpringDrive, StaticProbe, settle_steps, stiffness_n_m
from spine_mj.sim.model import RigModel
from spine_mj.sim.recording import COLUMNS, RESULT_COLUMNS, SENSOR_NAMES, Recording, RunColumns
from spine_mj.sim.records import EndReason, EngineSettings, TipParams
from spine_mj.sim.scales import Scales
from spine_mj.theory.engagement import DEFAULT_TOL
from spine_mj.theory.motion import MOTION_NAMES, SlipEvent, motion_fractions, motion_states, slip_events


def breakaway_rows(speed_m_s: np.ndarray, onsets, stick_speed_m_s: float) -> np.ndarray:
    """Where each breakaway's force is read: for every move onset with a stuck row (tangential
    speed at most ``stick_speed_m_s``) after the onset before it, the last such row. An
    onset without one (the tip slowed below the move speed but never stuck, or hopped) is
    the same slip going on, not a new breakaway.

    At the onset itself (speed above ``Detection.move_speed_m_s``) the force has risen past
    breakaway while the tip accelerated, by ``sqrt(2 m v_move rate)``: ``sqrt(2e-3
    sqrt(I_e)) F_p`` at the default move speed, 1.4 % of ``F_p`` at the ramp's default
    ``I_e = 0.01``; at a stuck row the lag is one step's rise and ``sqrt(2e-5 sqrt(I_e)) F_p``
    (the static probe's ``kappa_mj`` is read the same way)."""
    onsets = np.asarray(onsets, dtype=int)
    stuck = np.flatnonzero(np.asarray(speed_m_s) <= stick_speed_m_s)
    if not stuck.size:
        return onsets[:0]
    at = np.searchsorted(stuck, onsets) - 1  # the last stuck row before each onset
    row = stuck[np.maximum(at, 0)]
    after = np.concatenate([[-1], onsets[:-1]])
    return row[(at >= 0) & (row > after)]


@dataclass(frozen=True, eq=False)
class RunResult(RunColumns):
    """One run. Arrays have ``n`` rows, one per recorded step (the settle phase included).

    Attributes
    ----------
    time_s : (n,)
    position_m, velocity_m_s : (n, 3)
        Tip centre position and velocity, world frame [m], [m/s].
    contact : (n,) bool
        Whether the tip touches the surface.
    normal : (n, 3)
        Unit normal of the deepest contact, pointing out of the surface (NaN without contact).
    contact_point_m : (n, 3)
        Position of the deepest contact (NaN without contact).
    penetration_m : (n,)
        Depth of the deepest contact (>= 0; 0 without contact).
    normal_force_n : (n,)
        Sum of the normal forces of all the tip's contacts (>= 0; MuJoCo's touch sensor). On
        one contact it is the net contact force along the normal; a tip wedged between
        facets touches several, whose normal forces add up to more than the net force
        along any one normal (which can even be negative).
    tangential_force_n : (n,)
        Magnitude of the net contact force in the tangent plane of the deepest contact.
    drive_force_n : (n,)
        Force of the drive on the tip in +x [N].
    carriage_x_m : (n,)
        Carriage position (spring drive; NaN otherwise).
    moving : (n,) bool
        Tangential speed above ``detection.move_speed_m_s`` (the engine side's "not stuck",
        read by the lock rule and the fast-forward; not a slip).
    motion : (n,) int8
        Motion state relative to the drive, :data:`~spine_mj.theory.motion.STUCK`,
        ``SLIDING`` or ``SLIPPING`` (:func:`~spine_mj.theory.motion.motion_states`).
    slip_events : tuple of SlipEvent
        The slips (:func:`~spine_mj.theory.motion.slip_events`): onset force, force drop,
        jump length and duration of each.
    events : tuple of Event
    end_reason : EndReason
    end_detail : str
        What ended the run, with its numbers.
    engine_trouble : str
        For ENGINE_TROUBLE the kind (``nan``, ``engine_warning``, ``penetration`` or
        ``diverged``; :data:`~spine_mj.sim.detection.TROUBLES`), else "".
    drive_start_index : int
        First row after the settle phase.
    kappa_mj : float
        Static probe: F_breakaway / F_p (NaN unless ``end_reason`` is BREAKAWAY).
    breakaway_kappas : (k,)
        Drive force / F_p at each breakaway after the settle phase (a ``move_onset`` after
        the tip had stuck: a force ramp's breakaway per cycle), read at the last stuck row
        before it (:func:`breakaway_rows`), as the static probe's ``kappa_mj``.
    inertia_number, speed_m_s : float
        I_e and the speed (or equivalent speed) it uses.
    stiffness_number, stiffness_n_m : float
        K = k l_s / F_p and the spring's stiffness k (0 for force drives).
    simulated_steps : int
        Engine steps simulated for the run: ``n`` plus the steps after its end that were
        simulated before the end was seen (up to one piece of a batch), plus steps a
        fast-forward rolled back.
    start : (x0, y0)
        Start in surface units.
    """

    motion: np.ndarray
    slip_events: tuple[SlipEvent, ...]
    events: tuple[Event, ...]
    end_reason: EndReason
    end_detail: str
    engine_trouble: str
    drive_start_index: int
    kappa_mj: float
    breakaway_kappas: np.ndarray
    inertia_number: float
    speed_m_s: float
    stiffness_number: float
    stiffness_n_m: float
    simulated_steps: int
    start: tuple[float, float]
    drive: Drive
    tip: TipParams
    engine: EngineSettings
    scales: Scales
    detection: Detection

    @property
    def n(self) -> int:
        return self.time_s.size

    def table(self):
        """The trajectory as a :class:`pandas.DataFrame` (one row per recorded step)."""

        cols = {"time_s": self.time_s}
        for name in ("position_m", "velocity_m_s", "normal", "contact_point_m"):
            arr = getattr(self, name)
            for k, axis in enumerate("xyz"):
                cols[f"{name.split('_')[0]}_{axis}{name[len(name.split('_')[0]) :]}"] = arr[:, k]
        for name in (
            "contact",
            "penetration_m",
            "normal_force_n",
            "tangential_force_n",
            "drive_force_n",
            "carriage_x_m",
            "moving",
        ):
            cols[name] = getattr(self, name)
        cols["motion"] = pd.Categorical.from_codes(self.motion, MOTION_NAMES)
        return pd.DataFrame(cols)

    def summary(self) -> dict:
        """JSON-ready description of the run: parameters, engine settings, outcome."""

        def enc(obj):
            d = dataclasses.asdict(obj)
            return {k: (v.value if isinstance(v, enum.Enum) else v) for k, v in d.items()}

        return {
            "drive": type(self.drive).__name__,
            "drive_params": enc(self.drive),
            "tip": enc(self.tip),
            "engine": self.engine.to_dict(),
            "scales": enc(self.scales),
            "detection": enc(self.detection),
            "start": list(self.start),
            "end_reason": self.end_reason.value,
            "end_detail": self.end_detail,
            "engine_trouble": self.engine_trouble,
            "end_time_s": float(self.time_s[-1]) if self.n else 0.0,
            "kappa_mj": None if math.isnan(self.kappa_mj) else self.kappa_mj,
            "breakaway_kappas": self.breakaway_kappas.tolist(),
            "inertia_number": self.inertia_number,
            "speed_m_s": self.speed_m_s,
            "stiffness_number_K": self.stiffness_number,
            "stiffness_n_m": self.stiffness_n_m,
            "slope_length_m": self.scales.slope_length_m,
            "char_length_m": self.scales.char_length_m,
            "engine_units": enc(self.scales.units),
            "n_move_onsets": sum(e.kind == "move_onset" for e in self.events),
            **self.slip_summary(),
            "simulated_steps": self.simulated_steps,
            "max_penetration_m": float(self.penetration_m.max()) if self.n else 0.0,
        }

    def slip_summary(self) -> dict:
        """The slip events and motion states of the run, JSON-ready: ``slip_events``
        (count), ``slip_onset_forces_fp``, ``slip_force_drops_fp``, ``slip_jump_lengths_m``,
        ``slip_durations_s``, ``motion_fractions`` (of the drive phase's time) and
        ``max_speed_over_drive`` (the tip's largest x-speed after the settle phase over
        the drive's speed)."""
        fp, ev = self.scales.preload_n, self.slip_events
        vx = self.velocity_m_s[self.drive_start_index :, 0]
        return {
            "slip_events": len(ev),
            "slip_onset_forces_fp": [e.onset_force_n / fp for e in ev],
            "slip_force_drops_fp": [e.force_drop_n / fp for e in ev],
            "slip_jump_lengths_m": [e.jump_length_m for e in ev],
            "slip_durations_s": [e.duration_s for e in ev],
            "motion_fractions": motion_fractions(self.motion, self.drive_start_index, self.time_s),
            "max_speed_over_drive": float(vx.max() / self.speed_m_s) if vx.size else 0.0,
        }


def analyse_group(
    rig: RigModel,
    drives: Sequence[Drive],
    starts: Sequence[tuple[float, float]],
    state: np.ndarray,
    sens: np.ndarray,
    ctrls: Sequence[np.ndarray],
    det: Detection,
    warnings: Sequence[tuple[int | None, str] | None],
) -> list[RunResult]:
    """The results of a group of whole runs of equal length on ``rig`` (one window of a
    :class:`GroupAnalysis`).

    ``state`` ``(g, n, nstate)`` and ``sens`` ``(g, n, nsensordata)``; ``ctrls`` are the
    runs' controls (the carriage is column 3), ``warnings`` per run ``(first step with a
    MuJoCo warning or None, its text)`` or None.
    """
    g, n = state.shape[:2]
    group = GroupAnalysis(rig, drives, starts, det, np.stack([c[:, 3] for c in ctrls]))
    group.add(np.arange(g), 0, n, state, sens)
    return group.results(warnings)


class GroupAnalysis:
    """The recording and end marks of a group of runs on ``rig``, filled window by window.

    Parameters
    ----------
    rig, drives, starts, det
        The runs (``det`` resolved).
    carriage : (g, n) array
        The carriage x of each run and step in engine units (read for spring drives only);
        ``n`` is the group's planned length.
    compiled : bool
        Analyse each window in one compiled pass (:mod:`~spine_mj.sim._window_kernel`);
        False: by the numpy reference it is tested against (the same numbers, bit for bit).

    Notes
    -----
    :meth:`add` takes rows a..b-1 of some runs; windows of a run must come in order and
    without gaps. Every end mark is the first row of a condition (:func:`end_marks`) and the
    lock rule carries its held streak from one window to the next
    (:func:`~spine_mj.sim.detection.normal_lock_marks`), so after any window a run's marks
    and its probe endings are those of its whole run's analysis up to that row: a run with
    an ending there is decided, and cutting it there changes neither its recording nor its
    ending (except that engine trouble after the ending is never seen, which a whole run
    would report instead of the ending). Columns hold only the rows added.
    """

    def __init__(
        self, rig: RigModel, drives, starts, det: Detection, carriage: np.ndarray, *, compiled: bool = True
    ):
        self.rig, self.drives, self.starts, self.det = rig, list(drives), list(starts), det
        self.compiled = compiled
        self.g, self.n = carriage.shape
        self.carriage = carriage
        self.spring = np.array([isinstance(d, SpringDrive) for d in self.drives])
        self.probe = [isinstance(d, StaticProbe) for d in self.drives]
        self.n_settle = [settle_steps(d, rig.engine.timestep_s) for d in self.drives]
        self.speeds = [rig.speed_of(d) for d in self.drives]  # [m/s]
        self.stiffness = [  # [N/m], 0 for force drives
            stiffness_n_m(d, rig.scales) if sp else 0.0 for d, sp in zip(self.drives, self.spring)
        ]
        self.limits = np.array([det.speed_limit_m_s(rig.scales, v) for v in self.speeds])
        self.force_limits = np.array(
            [det.force_limit_n(rig.scales, v, k) for v, k in zip(self.speeds, self.stiffness)]
        )
        self.cols = Recording.empty((self.g, self.n))
        self._results_view = self.cols.read_only()  # a RunResult cannot write the group's columns
        self._mark_rows = np.full((self.g, len(MARK_KEYS)), -1)  # first run row of each end mark
        self.marks = {k: self._mark_rows[:, j] for j, k in enumerate(MARK_KEYS)}
        self.held_from_n = np.full(self.g, np.nan)
        a, u, e = rig.sensor_adr, rig.units, (*rig.bounds_m, *rig.z_range_m)
        self._adr = np.array([a[k] for k in SENSOR_NAMES], dtype=np.int64)
        self._units = np.array([u.length_m, u.force_n, u.speed_m_s, u.time_s])
        span = max(e[1] - e[0], e[3] - e[2])
        self._prm = np.array(
            [
                rig.engine.timestep_s,
                *e[:5],
                e[5] + span,
                det.domain_margin_m,
                det.move_speed_m_s,
                det.penetration_tol_m,
                det.kappa_cap * rig.scales.preload_n * (1 - 1e-9),
                rig.tip.mu_s,
                DEFAULT_TOL,
                LOCK_RISE_FP * rig.scales.preload_n,
            ]
        )
        self.rows = np.zeros(self.g, dtype=int)
        self.simulated = np.zeros(self.g, dtype=int)

    def add(self, runs: np.ndarray | slice, a, b, state: np.ndarray, sens: np.ndarray) -> np.ndarray:
        """Rows ``a..b-1`` of ``runs`` (indices, or a slice of the group; ``a`` and ``b``
        one window for all or one per run) from the group's ``state`` ``(g, n, nstate)``
        and ``sens`` ``(g, n, nsensordata)`` (the rows, read in place); returns, per run,
        whether it is decided (an ending at or before its row b-1)."""
        rig, det = self.rig, self.det
        index = np.arange(self.g)[runs]
        a = np.broadcast_to(np.asarray(a, dtype=np.int64), index.shape)
        b = np.broadcast_to(np.asarray(b, dtype=np.int64), index.shape)
        if self.compiled:
            marks = self._marks_compiled(index, a, b, state, sens)
        else:
            marks = np.empty((index.size, len(MARK_KEYS)), dtype=np.int64)
            for aw, bw in sorted(set(zip(a.tolist(), b.tolist()))):
                sel = np.flatnonzero((a == aw) & (b == bw))
                window = _as_block(index[sel])
                marks[sel] = self._marks_reference(window, aw, bw, state[window, aw:bw], sens[window, aw:bw])
        old = self._mark_rows[runs]
        merged = np.where((old < 0) & (marks >= 0), marks + a[:, None], old)
        self._mark_rows[runs] = merged
        decided = (merged >= 0).any(axis=1)
        self.rows[runs] = b
        for i, r in enumerate(index):
            if self.probe[r] and not decided[i]:
                decided[i] = bool(
                    probe_candidates(self.run(r), self.n_settle[r], det, rig.scales.preload_n)[0]
                )
        return decided

    def _marks_reference(self, runs, a: int, b: int, state, sens) -> np.ndarray:
        """The window's columns (into the group's) and end marks ``(runs, len(MARK_KEYS))``
        (window rows, -1: none) by the numpy reference:
        :meth:`Recording.from_sensors`, :func:`end_marks`, :func:`normal_lock_marks`."""
        rig, det = self.rig, self.det
        block = isinstance(runs, slice)  # the window's columns are views of the group's: written in place
        if block:
            rec = Recording(**{k: getattr(self.cols, k)[runs, a:b] for k in COLUMNS})
        else:
            rec = Recording.empty(state.shape[:2])
        carriage = np.where(self.spring[runs, None], self.carriage[runs, a:b], np.nan)
        Recording.from_sensors(
            rig.sensor_adr,
            state,
            sens,
            units=rig.units,
            carriage_x=carriage,
            move_speed_m_s=det.move_speed_m_s,
            out=rec,
        )
        marks = end_marks(
            rec,
            state,
            sens,
            timestep_s=rig.engine.timestep_s,
            bounds_m=(*rig.bounds_m, *rig.z_range_m),
            det=det,
            preload_n=rig.scales.preload_n,
            speed_limit_m_s=self.limits[runs],
            force_limit_n=self.force_limits[runs],
            first_step=a,
        )
        marks["lock_rule"], self.held_from_n[runs] = normal_lock_marks(
            rec, rig.tip.mu_s, rig.scales.preload_n, self.held_from_n[runs]
        )
        if not block:
            for k in COLUMNS:
                getattr(self.cols, k)[runs, a:b] = getattr(rec, k)
        return np.stack([marks[k] for k in MARK_KEYS], axis=1)

    def _marks_compiled(self, runs: np.ndarray, a: np.ndarray, b: np.ndarray, state, sens) -> np.ndarray:
        """:meth:`_marks_reference` of every run's own window ``a..b-1`` (run indices
        ``runs``) in one compiled pass (:mod:`~spine_mj.sim._window_kernel`), writing the
        group's columns in place."""
        from spine_mj.sim._window_kernel import analyse_window

        marks = np.empty((runs.size, len(MARK_KEYS)), dtype=np.int64)
        held = np.empty(runs.size)
        analyse_window(
            state,
            sens,
            np.ascontiguousarray(b - a),
            self.carriage,
            self.spring[runs],
            self._adr,
            self._units,
            self._prm,
            self.limits[runs] ** 2,
            self.force_limits[runs],
            np.ascontiguousarray(a),
            self.held_from_n[runs],
            runs,
            *(getattr(self.cols, k) for k in COLUMNS),
            marks,
            held,
        )
        self.held_from_n[runs] = held
        return marks

    def add_time(self, r: int, a: int, b: int, extra_s) -> None:
        """Add ``extra_s`` [s] (a number, or one per row) to the recorded time of rows
        ``a..b-1`` of run ``r``, after :meth:`add`: the time a fast-forward skipped (the
        engine's clock, which the reset check reads, counts one step a row)."""
        self.cols.time_s[r, a:b] += extra_s

    def run(self, r: int) -> Recording:
        """The recorded rows of run ``r`` (views of the group's columns)."""
        return self.cols.run(r, self.rows[r])

    def results(self, warnings: Sequence[tuple[int | None, str] | None], runs=None) -> list[RunResult]:
        """The ending and result of each run (of ``runs``, indices; None: all); a run without
        an ending completed its recorded rows.

        ``warnings``: per run of the group ``(first step with a MuJoCo warning or None, its
        text)`` or None.
        """
        fp = self.rig.scales.preload_n
        view = self._results_view
        out = []
        for r in range(self.g) if runs is None else runs:
            rows = int(self.rows[r])
            rec = view.run(r, rows)
            marks = dict(zip(MARK_KEYS, self._mark_rows[r].tolist()))
            candidates = end_candidates(marks, rec, warnings[r], self.det, fp)
            kappa = math.nan
            if self.probe[r]:
                probe, kappa = probe_candidates(rec, self.n_settle[r], self.det, fp)
                candidates += probe
            ending = decide_end(candidates, rows)
            if ending.reason is not EndReason.BREAKAWAY:
                kappa = math.nan
            cut = rec if ending.index + 1 == rows else view.run(r, ending.index + 1)
            out.append(self._result(r, cut, ending, kappa, max(int(self.simulated[r]), rows)))
        return out

    def _result(
        self, r: int, rec: Recording, ending: Ending, kappa_mj: float, simulated_steps: int
    ) -> RunResult:
        """The result of run ``r``, its recording ``rec`` cut at its ``ending``."""
        rig, drive, n_settle = self.rig, self.drives[r], self.n_settle[r]
        events = move_events(rec.moving, rec.time_s, n_settle)
        events.append(Event(ending.reason.value, ending.index, float(rec.time_s[ending.index])))
        onsets = [e.index for e in events if e.kind == "move_onset"]
        speed, k = self.speeds[r], self.stiffness[r]
        motion = motion_states(rec.velocity_m_s, speed, n_settle)
        slips = slip_events(
            motion, rec.time_s, rec.position_m[:, 0], rec.drive_force_n, rec.velocity_m_s[:, 0]
        )
        return RunResult(
            **{name: getattr(rec, name) for name in RESULT_COLUMNS},
            motion=motion,
            slip_events=tuple(slips),
            events=tuple(events),
            end_reason=ending.reason,
            end_detail=ending.detail,
            engine_trouble=ending.trouble,
            drive_start_index=n_settle,
            kappa_mj=kappa_mj,
            breakaway_kappas=rec.drive_force_n[
                breakaway_rows(rec.tangential_speed_m_s, onsets, self.det.stick_speed_m_s)
            ]
            / rig.scales.preload_n,
            inertia_number=rig.scales.inertia_number(speed),
            speed_m_s=speed,
            stiffness_number=rig.scales.stiffness_number(k),
            stiffness_n_m=k,
            simulated_steps=simulated_steps,
            start=tuple(self.starts[r]),
            drive=drive,
            tip=rig.tip,
            engine=rig.engine,
            scales=rig.scales,
            detection=self.det,
        )


def _as_block(ks: np.ndarray) -> slice | np.ndarray:
    """Sorted run indices as a slice where they form a block (the reference then writes the
    group's columns through views), else as they are."""
    if ks.size and ks[-1] - ks[0] + 1 == ks.size and (np.diff(ks) == 1).all():
        return slice(int(ks[0]), int(ks[-1]) + 1)
    return ks
