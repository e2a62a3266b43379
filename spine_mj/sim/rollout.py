"""Open-loop runs in batches: grouping, and the pieced native rollout.

Spring drives and static probes need no feedback: their controls are known in advance
(:func:`~spine_mj.sim.open_loop.controls`), so they go through
:func:`mujoco.rollout.rollout` on worker threads (``rollout`` releases the GIL). Runs of
equal planned length form a group (within 256 MiB of output); each run is simulated in
pieces (its settle phase, then :data:`PIECE_STEPS` steps at a time), and after each piece
its new rows are analysed (:class:`~spine_mj.sim.results.GroupAnalysis`): a run whose
outcome is decided (self-lock, left the domain, engine trouble, a probe's breakaway or
slide) is not simulated further. The pieces stream: worker threads take them from one
queue, and the calling thread takes finished ones in small batches, analyses them and
queues each live run's next piece while the workers still have queued pieces to simulate
(no round waits for its slowest piece).

A run is continued from its exact state: the full physics state of its last row and the
warm start (``qacc_warmstart``) its worker's ``MjData`` holds after the piece, which the
recorded state lacks (without it the constraint solver starts elsewhere and the trajectory
drifts by ~1e-5 L_c within a step). Each piece is one run on one ``MjData``, so that warm
start is there to read; the pieces then give bit for bit the trajectory of one
uninterrupted rollout (tested). The controls are :mod:`spine_mj.sim.open_loop`'s, the
worker threads and the plain ``mj_step`` reference of a piece
(:func:`~spine_mj.sim.lanes.python_steps`) are :mod:`spine_mj.sim.lanes`'; this module
re-exports their public names.

A static probe with fast-forward (:class:`~spine_mj.sim.drives.StaticProbe`) is decided
after its settle piece: :class:`~spine_mj.sim.fastforward.StickFastForward` reads the
settled rows and, where it predicts a breakaway, the probe's remaining controls climb to
just below it in :data:`~spine_mj.sim.fastforward.RISE_STEPS` steps, then go on at the
nominal rate. That climb is its own piece; if the tip moved during it, the piece is
dropped and the probe goes on from its settled state with the plain controls.

A spring drive with fast-forward (:class:`~spine_mj.sim.drives.SpringDrive`) is watched
the same way after each of its pieces: where the tip has been still on one normal for its
last :data:`~spine_mj.sim.fastforward.QUIET_STEPS` rows and the spring force ``k (X - x)``
lies far below the breakaway force predicted from that normal, its next piece is a
climb. A stuck tip sees the force rise at ``k V`` whatever the carriage did before, so
the climb covers ``s`` rows of the carriage's schedule in
:data:`~spine_mj.sim.fastforward.RISE_STEPS` (the carriage, the spring's anchor, moving
``s / RISE_STEPS`` times faster) to just below the breakaway force, and the rest of the
schedule follows at the carriage's speed V: the run plans ``s - RISE_STEPS`` rows fewer
and ends where the plain run's carriage does. The rise is the one the ramp and the probe
use (50 contact time constants): the stuck contact follows it, and a stuck tip does not
load the spring's own oscillation. A tip that moved, lost contact or changed its normal
during the climb sends the run back to before it, on the plain controls (the rows, the
warm start and the planned length as they were), and no new climb starts until the tip has
slipped or the force has passed where it moved. The recorded ``time_s`` is physical time:
each row of a climb counts ``s / RISE_STEPS`` steps and every later row carries the time
skipped, so the carriage sits at ``V t`` from its start as in the plain run (the engine's
own clock, one step a row, is what the reset check reads).
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

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
from spine_mj.sim.fastforward import QUIET_STEPS, RISE_STEPS, StickFastForward, fast_forward_on
from spine_mj.sim.lanes import NativeLanes, PythonLane
from spine_mj.sim.model import RigModel, start_pair
from spine_mj.sim.open_loop import (
    control_profile,
    drive_steps,
    length_from_start,
    profile_key,
    start_offsets,
)
from spine_mj.sim.recording import Recording
from spine_mj.sim.results import GroupAnalysis, RunResult

BATCH_MEMORY_BYTES = 256 * 2**20
#: Steps of a run's first piece after its settle phase; each next piece is twice as long,
#: up to :data:`PIECE_STEPS` (a last piece under half that joins the one before): a run is
#: not simulated past its end by much more than it had run before it, nor by more than
#: 1.5 :data:`PIECE_STEPS`.
FIRST_PIECE_STEPS = 128
#: Longest piece: the most steps a run is simulated between two looks at its end conditions.
PIECE_STEPS = 1024
#: A spring run fast-forwards only where one preload ``F_p`` is more than this many of its
#: steps' increments ``k V dt``: a stick phase gains about a preload's worth of force (kappa
#: varies by O(1) along a path), and a shorter one hardly outlasts the climb
#: (:data:`~spine_mj.sim.fastforward.RISE_STEPS`), its nominal approach and the wait for
#: the end of a piece, so the checks after each piece would be spent for nothing. On the
#: paper fractal at K = 30 (step 0.004 F_p at I_e = 1e-6) no still phase lasted 300 steps.
#: (A stick phase is seen at the end of a piece; capping a fast-forwarding run's pieces at
#: 256 steps saved 5 % of its steps on the fractal at K = 3, mu 1.25, I_e 1e-6, but cost
#: 15 % more CPU time than the usual pieces: a piece costs ~15 steps' time.)
SPRING_MIN_CLIMB_STEPS = 4 * RISE_STEPS
#: Tips placed at a time, their first pieces then handed to the workers (the very first
#: chunk is one tip per worker, so that each starts as soon as it can). Placing 16 tips
#: (~1 ms) takes less than a first piece (~2.5 ms on the single peak), and a 64-run batch
#: spends 1.3 ms less of its calling thread's CPU than with chunks of 4 (fewer cold calls).
PLACE_CHUNK = 16


def plan_groups(lengths: Sequence[int], bytes_per_step: int) -> list[list[int]]:
    """Run indices in groups of equal planned length (shortest first), each within
    :data:`BATCH_MEMORY_BYTES` of output."""
    order = sorted(range(len(lengths)), key=lambda i: lengths[i])
    groups = []
    i = 0
    while i < len(order):
        nstep = lengths[order[i]]
        group = [order[i]]
        limit = max(1, BATCH_MEMORY_BYTES // (bytes_per_step * nstep))
        while i + len(group) < len(order) and len(group) < limit and lengths[order[i + len(group)]] == nstep:
            group.append(order[i + len(group)])
        i += len(group)
        groups.append(group)
    return groups


def batch_drives(drives, starts) -> tuple[list[Drive], list[tuple[float, float]]]:
    """``drives`` as one drive per start (one drive is shared by all) and ``starts`` as
    ``(x0, y0)`` float pairs, checked: an open-loop batch takes spring drives and static
    probes only."""
    starts = [start_pair(s) for s in starts]
    if isinstance(drives, (SpringDrive, StaticProbe, RampDrive)):
        drives = [drives] * len(starts)
    drives = list(drives)
    if len(drives) != len(starts):
        raise SpineInputError(f"drives must be one drive or one per start ({len(starts)}), got {len(drives)}")
    if any(isinstance(d, RampDrive) for d in drives):
        raise SpineInputError("RampDrive needs feedback; use Rig.run for it")
    return drives, starts


@dataclass(frozen=True)
class BatchOptions:
    """How a batch runs: the options of :meth:`~spine_mj.sim.Rig.run_batch`, one record
    for the CPU path (:func:`run_batch`) and the GPU path
    (:func:`~spine_mj.sim.gpu.run_batch_gpu`).

    Attributes
    ----------
    detection : Detection or None
        The end events (None: :class:`~spine_mj.sim.detection.Detection`'s defaults).
    backend : {"rollout", "python", "gpu", "auto"}
        Native CPU threads, the plain reference loop, MuJoCo Warp, or the GPU where one is
        present (:func:`~spine_mj.sim.gpu.resolve_backend`).
    nthread : int or None
        Worker threads of the CPU rollout (None: the CPU count).
    stop_early : bool
        Stop a run after the piece that decided its outcome (CPU backends).
    refine : bool
        Run a run stopped on penetration once more at a finer step (CPU backends;
        :meth:`~spine_mj.sim.Rig.run_batch`).
    device : str or None
        Warp device of the GPU backend (None: the CUDA device; ``"cpu"``: Warp's CPU).
    """

    detection: Detection | None = None
    backend: str = "rollout"
    nthread: int | None = None
    stop_early: bool = True
    refine: bool = True
    device: str | None = None


def run_batch(
    rig: RigModel,
    drives: Drive | Sequence[Drive],
    starts: Sequence[tuple[float, float]],
    options: BatchOptions | None = None,
) -> list[RunResult]:
    """Run many starts and/or drive parameter sets of ``rig``'s model on the CPU (see
    :meth:`Rig.run_batch`; ``options.refine`` and ``options.device`` are not used here)."""
    opt = BatchOptions() if options is None else options
    drives, starts = batch_drives(drives, starts)
    if opt.backend not in ("rollout", "python"):
        raise SpineInputError(f"backend must be 'rollout' or 'python', got {opt.backend!r}")
    det = (Detection() if opt.detection is None else opt.detection).resolve(rig.scales)
    rig.check_starts(starts, det.domain_margin_m)
    runner = _BatchRunner(rig, drives, starts, det)
    nthread = (os.cpu_count() or 1) if opt.nthread is None else max(1, int(opt.nthread))
    lanes = NativeLanes(nthread) if opt.backend == "rollout" else PythonLane()
    try:
        for idx in plan_groups(runner.lengths, 8 * (runner.nstate + rig.model.nsensordata)):
            group = _Group(runner, idx, opt.stop_early)
            for j, res in zip(idx, group.run(lanes)):
                runner.results[j] = res
    finally:
        lanes.close()
    return runner.results


class _BatchRunner:
    """The runs of one :func:`run_batch` call: their drives, starts, models and lengths."""

    def __init__(self, rig: RigModel, drives: list[Drive], starts: list[tuple[float, float]], det: Detection):
        import mujoco

        self.rig, self.drives, self.starts, self.det = rig, drives, starts, det
        s, dt = rig.length_scale_m, rig.engine.timestep_s
        by_stiffness: dict[float, object] = {}
        lengths: dict[object, int] = {}  # by drive object, and by start where the length depends on it
        self.models, self.lengths = [], []
        for d, (x0, _) in zip(drives, starts):
            k = stiffness_n_m(d, rig.scales) if isinstance(d, SpringDrive) else 0.0
            if k not in by_stiffness:
                by_stiffness[k] = rig.model_for(d)
            self.models.append(by_stiffness[k])
            key = profile_key(d, x0)
            if key not in lengths:
                lengths[key] = settle_steps(d, dt) + drive_steps(rig, d, x0 * s, det)
            self.lengths.append(lengths[key])
        self.nstate = mujoco.mj_stateSize(rig.model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        self.results: list[RunResult | None] = [None] * len(starts)


class _Group:
    """One group of runs of equal planned length: its arrays, each run's progress, the
    analysis of its rows and the probes' fast-forward (``k`` below: a run's index in the group)."""

    def __init__(self, runner: _BatchRunner, idx: list[int], stop_early: bool):
        rig = runner.rig
        self.rig, self.det, self.stop_early = rig, runner.det, stop_early
        self.drives = [runner.drives[j] for j in idx]
        self.starts = [runner.starts[j] for j in idx]
        self.models = [runner.models[j] for j in idx]
        g, n = len(idx), runner.lengths[idx[0]]
        self.n = n
        self.ctrl = np.empty((g, n, 6))
        self.state = np.empty((g, n, runner.nstate))
        self.sens = np.empty((g, n, rig.model.nsensordata))
        self.init = np.zeros((g, runner.nstate))
        self.warm = np.zeros((g, rig.model.nv))  # the warm start each run goes on from
        self.done = np.zeros(g, dtype=int)  # rows simulated and analysed
        self.pieces = np.zeros(g, dtype=int)  # pieces after the settle phase (and a climb)
        self.end = np.full(g, n)  # rows planned (a fast-forwarded probe plans fewer)
        self.live = np.ones(g, dtype=bool)
        self.warnings: list[tuple[int | None, str] | None] = [None] * g
        self.n_settle = [settle_steps(d, rig.engine.timestep_s) for d in self.drives]
        self.climbs: dict[int, _Climb] = {}  # climb pieces under way
        # a probe that may fast-forward is decided from its settled rows: its settle phase is a piece
        self.settle_apart = [
            isinstance(d, StaticProbe) and fast_forward_on(d, rig.engine, rig.tip) for d in self.drives
        ]
        # a spring run that may fast-forward is watched after each piece, where its stick
        # phases (about a preload's worth of force each) can outlast a climb
        self.spring_ff = [
            isinstance(d, SpringDrive)
            and fast_forward_on(d, rig.engine, rig.tip)
            and rig.scales.preload_n > SPRING_MIN_CLIMB_STEPS * self.nominal_step_n(k)
            for k, d in enumerate(self.drives)
        ]
        self.watchers: dict[int, StickFastForward] = {}  # spring runs' watchers, kept across pieces
        self.skipped_s = np.zeros(g)  # physical time a spring run's climbs skipped [s]
        self.analysis: GroupAnalysis | None = None  # built once the workers have pieces
        self.profiles: dict[object, np.ndarray] = {}  # control profiles shared by starts (profile_key)

    def run(self, lanes) -> list[RunResult]:
        """Simulate the group piece by piece; the results in group order.

        The calling thread takes finished pieces as a batch once it can do so and still leave
        each worker a queued piece (``batch`` at most, at least one), analyses them, queues
        the live runs' next pieces and makes the results of the runs that ended. Each wake
        costs more than its pieces (the thread's code and data are cold after the workers
        ran), so a batch is up to half the group: per 64-run batch of 3 pieces a run, that
        took 2.4 ms less of the calling thread's CPU than a quarter (21.1 against 23.5 ms,
        medians of 30) and the wall time fell by 1.1 %. The pieces and so the results do
        not depend on it."""
        g = len(self.drives)
        out = 0  # pieces queued or being simulated
        edges = [0, *range(min(lanes.nthread, g), g, PLACE_CHUNK), g]  # one tip per worker first
        for lo, hi in itertools.pairwise(edges):  # the workers start on the first tips placed
            ks = np.arange(lo, hi)
            self.prepare(ks)
            out += self.submit(ks, lanes)
            if self.analysis is None:
                carriage = self.ctrl[:, :, 3]
                self.analysis = GroupAnalysis(self.rig, self.drives, self.starts, self.det, carriage)
        batch = max(lanes.nthread, g // 2)
        results: list[RunResult | None] = [None] * g
        while out:
            done = lanes.take(max(1, min(batch, out - 2 * lanes.nthread)))
            out -= len(done)
            self.advance(sorted(done))
            ks = np.array(sorted({d[0] for d in done}), dtype=int)
            out += self.submit(ks[self.live[ks]], lanes)
            ended = ks[~self.live[ks]]
            for k, res in zip(ended, self.analysis.results(self.warnings, ended)):
                results[k] = res
        return results

    def prepare(self, ks: np.ndarray) -> None:
        """Place the tips of runs ``ks``; their controls and initial states."""
        for k, q in zip(ks, self.rig.place_many([self.starts[k] for k in ks])):
            np.add(self.profile(k), start_offsets(self.drives[k], q), out=self.ctrl[k])
            self.init[k, 1:4] = q

    def profile(self, k: int) -> np.ndarray:
        """The :func:`control_profile` of run ``k``, computed once per drive (once per run
        where its length depends on its start)."""
        drive, x0 = self.drives[k], self.starts[k][0]
        key = profile_key(drive, x0)
        profile = self.profiles.get(key)
        if profile is None:
            profile = control_profile(self.rig, drive, x0 * self.rig.length_scale_m, self.det)
            if not length_from_start(drive):
                self.profiles[key] = profile
        return profile

    def submit(self, ks: np.ndarray, lanes) -> int:
        """Queue the next piece of each run in ``ks`` (longest first): a fast-forwarding
        probe's settle phase or climb, or the next of the pieces that double from
        :data:`FIRST_PIECE_STEPS` to :data:`PIECE_STEPS` (the first with the settle phase).
        Returns the number queued."""
        todo = []
        for k in ks.tolist():
            a = int(self.done[k])
            if a < self.n_settle[k] and self.settle_apart[k]:
                b = self.n_settle[k]
            elif k in self.climbs:
                b = a + RISE_STEPS
            else:
                size = min(PIECE_STEPS, FIRST_PIECE_STEPS << int(self.pieces[k]))
                b = max(a, self.n_settle[k]) + size
                if self.end[k] - b < size // 2:  # no short last piece: it joins this one
                    b = int(self.end[k])
                self.pieces[k] += 1
            todo.append((k, a, min(b, int(self.end[k]))))
        for k, a, b in sorted(todo, key=lambda t: t[1] - t[2]):
            lanes.put(self.piece, (lanes, k, a, b))
        return len(todo)

    def piece(self, lanes, k: int, a: int, b: int):
        """Simulate rows ``a..b-1`` of run ``k`` from its exact state (a worker thread's job)."""
        r = slice(k, k + 1)
        init = self.init[r] if a == 0 else self.state[r, a - 1]
        warm, warning = lanes.step(
            self.models[k], init, self.warm[r], self.ctrl[r, a:b], self.state[r, a:b], self.sens[r, a:b]
        )
        return k, a, b, warm, warning

    def advance(self, done: list) -> None:
        """Take finished pieces: check climbs, analyse the new rows (all at once), stop
        decided runs, decide probes' fast-forward after settling and springs' after each piece."""
        new = []
        stop = set()
        held: dict[int, int] = {}  # spring runs whose climb held: the rows it skipped
        runs = [piece[0] for piece in done]  # a run has one piece out at a time: no repeats
        self.analysis.simulated[runs] += [b - a for _, a, b, _, _ in done]
        self.warm[runs] = [piece[3] for piece in done]
        for k, a, b, _, warning in done:
            if warning == "frozen":
                # the native rollout stops a run at a MuJoCo warning and repeats its last row
                # to the end of the call: the rows a whole-run rollout would have recorded
                self.state[k, b : self.end[k]] = self.state[k, b - 1]
                self.sens[k, b : self.end[k]] = self.sens[k, b - 1]
                b = int(self.end[k])
                stop.add(k)
            elif warning is not None:
                self.warnings[k] = (a + warning[0], warning[1])
                stop.add(k)
            if k in self.climbs:
                climb = self.climbs.pop(k)
                if not self.climb_held(k, climb, a, b):
                    continue  # dropped: the run goes on from before the climb
                # the breakaway is expected within ~2 NOMINAL_STEPS: a 256-step piece (a
                # spring's margin may take longer, and its next stick phase is to be seen soon)
                self.pieces[k] = 0 if climb.skip else 1
                if climb.skip:
                    held[k] = climb.skip
            new.append((k, a, b))
        if not new:
            return
        ks, a, b = (np.array(col, dtype=np.int64) for col in zip(*new))
        decided = self.analysis.add(ks, a, b, self.state, self.sens)
        self.add_skipped_time(new, held)
        self.done[ks] = b
        for k, ak, bk, dec in zip(ks.tolist(), a.tolist(), b.tolist(), decided):
            if bk >= self.end[k] or (self.stop_early and (dec or k in stop)):
                self.live[k] = False
            elif bk == self.n_settle[k] and not dec:
                self.fast_forward(k)
            elif self.spring_ff[k] and not dec and k not in stop and k not in held:
                self.spring_climb(k, ak, bk)

    def add_skipped_time(self, new: list, held: dict[int, int]) -> None:
        """Make the recorded time of spring runs' new rows physical: a held climb's row i
        (from 0) counts ``(i + 1) skip / RISE_STEPS`` steps, every later row the climbs'
        skipped time (see the module docstring)."""
        dt = self.rig.engine.timestep_s
        for k, a, b in new:
            extra = self.skipped_s[k]
            skip = held.get(k)
            if skip is not None:
                rows = np.minimum(np.arange(1, b - a + 1), RISE_STEPS)
                extra = extra + rows * (skip / RISE_STEPS - 1) * dt
                self.skipped_s[k] += (skip - RISE_STEPS) * dt
            if skip is not None or extra:
                self.analysis.add_time(k, a, b, extra)

    def fast_forward(self, k: int) -> None:
        """After settling: a probe whose tip is stuck on one normal gets controls that climb
        to just below the breakaway force predicted from it (:class:`StickFastForward`)."""
        rig, drive = self.rig, self.drives[k]
        if not self.settle_apart[k]:
            return
        cap = self.det.kappa_cap * rig.scales.preload_n
        ff, step = self.watcher(k), self.nominal_step_n(k)
        rec, ns = self.analysis.run(k), self.n_settle[k]
        verdict = ""
        for i in range(max(0, ns - QUIET_STEPS - 1), ns):
            verdict = ff.watch(*_still(rec, i), float(rec.drive_force_n[i]), step)
        if verdict != "start":
            return
        rise = drive.start_force_n + ff.step_n * np.arange(1, RISE_STEPS + 1)
        rise[-1] = ff.target_n
        nominal = ff.target_n + step * np.arange(1, int(math.ceil((cap - ff.target_n) / step)) + 3)
        push = np.concatenate([rise, np.minimum(nominal, cap * (1 + 1e-9))]) / rig.units.force_n
        if ns + push.size > self.n:
            return
        self.climbs[k] = _Climb(ff, self.warm[k].copy(), [1], self.ctrl[k][ns:, [1]], int(self.end[k]), 0)
        self.ctrl[k, ns : ns + push.size, 1] = push
        self.end[k] = ns + push.size

    def spring_climb(self, k: int, a: int, b: int) -> None:
        """After rows a..b-1 of spring run ``k``: where its tip has been still on one normal
        for the last :data:`QUIET_STEPS` rows and the force lies far below the predicted
        breakaway (:meth:`StickFastForward.watch`), its next piece is a climb that covers
        ``skip`` rows of the carriage's schedule in :data:`RISE_STEPS` (see the module
        docstring); the schedule's rows after them follow, ``skip - RISE_STEPS`` earlier."""
        lo = max(a, self.n_settle[k])
        if b - lo <= QUIET_STEPS:
            return
        ff = self.watchers.get(k)
        if ff is None:
            ff = self.watchers[k] = self.watcher(k)
        rec, step = self.analysis.run(k), self.nominal_step_n(k)
        ff.skim(float(rec.tangential_speed_m_s[lo:b].max()), float(rec.drive_force_n[lo:b].max()))
        verdict = ""
        for i in range(b - QUIET_STEPS - 1, b):
            verdict = ff.watch(*_still(rec, i), float(rec.drive_force_n[i]), step)
        if verdict != "start":
            return
        force, end = float(rec.drive_force_n[b - 1]), int(self.end[k])
        skip = min(int((ff.target_n - force) / step), end - b)
        if skip < 2 * RISE_STEPS:  # the plan ends first: the climb would save too little
            ff.finish(force)
            return
        cols = [0, 3]  # the spring's anchor and the carriage: the others are constant while driving
        ctrl = self.ctrl[k]
        rows = ctrl[b:end, cols]  # a copy
        self.climbs[k] = _Climb(ff, self.warm[k].copy(), cols, rows, end, skip)
        self.end[k] = end - skip + RISE_STEPS
        ctrl[b + RISE_STEPS : self.end[k], cols] = rows[skip:]
        frac = np.arange(1, RISE_STEPS + 1)[:, None] / RISE_STEPS
        ctrl[b : b + RISE_STEPS, cols] = ctrl[b - 1, cols] + frac * (rows[skip - 1] - ctrl[b - 1, cols])

    def watcher(self, k: int) -> StickFastForward:
        """A :class:`StickFastForward` for run ``k`` (SI: it reads the recorded rows)."""
        rig, det = self.rig, self.det
        return StickFastForward(
            mu=rig.tip.mu_s,
            preload_n=rig.scales.preload_n,
            cap_n=det.kappa_cap * rig.scales.preload_n * (1 + 1e-9),
            margin=self.drives[k].fast_forward_margin,
            stick_speed_m_s=det.stick_speed_m_s,
            move_speed_m_s=det.move_speed_m_s,
        )

    def nominal_step_n(self, k: int) -> float:
        """The force run ``k``'s drive adds per step at its nominal pace [N]: ``k V dt`` on
        a stuck tip for a spring, ``rate dt`` for a probe."""
        rig, drive = self.rig, self.drives[k]
        if isinstance(drive, SpringDrive):
            return stiffness_n_m(drive, rig.scales) * drive.speed_m_s * rig.engine.timestep_s
        return rate_n_s(drive, rig.scales) * rig.engine.timestep_s

    def climb_held(self, k: int, climb: _Climb, a: int, b: int) -> bool:
        """Whether run ``k`` stayed stuck on its normal through its climb (rows a..b-1); if
        not, its controls, planned length and warm start go back to those before the climb."""
        rig, det, ff = self.rig, self.det, climb.ff
        rec = Recording.from_sensors(
            rig.sensor_adr,
            self.state[k : k + 1, a:b],
            self.sens[k : k + 1, a:b],
            units=rig.units,
            carriage_x=np.full((1, b - a), np.nan),
            move_speed_m_s=det.move_speed_m_s,
        ).run(0)
        step = self.nominal_step_n(k)
        for i in range(b - a):
            verdict = ff.watch(*_still(rec, i), float(rec.drive_force_n[i]), step)
            if verdict == "rollback" or (not ff.active and i < b - a - 1):
                self.ctrl[k][a : climb.end, climb.cols] = climb.rows
                self.end[k], self.warm[k] = climb.end, climb.warm
                return False
        if ff.active:
            ff.finish(float(rec.drive_force_n[-1]))
        return True


class _Climb(NamedTuple):
    """A climb piece under way: its watcher, and what puts the run back if the tip moves."""

    ff: StickFastForward
    warm: np.ndarray  # the warm start before the climb
    cols: list[int]  # the control columns the climb changes
    rows: np.ndarray  # those columns from the climb's first row to ``end``, as they were
    end: int  # the planned rows before the climb
    skip: int  # rows of a spring's schedule the climb covers (0: a probe's climb)


def _still(rec: Recording, i: int) -> tuple[float, np.ndarray, bool]:
    """Tangential speed, outward normal and contact of row ``i``: what
    :meth:`StickFastForward.watch` reads."""
    return float(rec.tangential_speed_m_s[i]), rec.normal[i], bool(rec.contact[i])
