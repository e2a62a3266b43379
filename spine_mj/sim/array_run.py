"""Running a batch of array runs: controls, pieces, per-piece analysis and the results.

:class:`ArrayBatch` steps each run of an :class:`~spine_mj.sim.array.ArrayRig` in pieces of
:data:`ARRAY_PIECE_STEPS` on the single rig's lanes (native rollout
worker threads, or the plain ``mj_step`` reference), each piece continued from the run's
last state and warm start. After each piece it reads every step: the springs' forces
(``k (anchor - x)`` capped at ``kappa_cap F_p``, what the actuators apply), the tips'
speeds, self-locks, the domain's edge and non-finite numbers; it keeps every
``stride``-th row. A run ends at its first decided row.

The holding force is read where the array lets go (displacement control: the last step
before every spine moves; force control: the largest pull under which the carriage held),
not at the spring force's dynamic peak, and stated with its predicted excess over the
quasistatic holding (:mod:`spine_mj.sim.holding`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import SpringDrive, stiffness_n_m
from spine_mj.sim.holding import holding_excess
from spine_mj.sim.records import check_optional
from spine_mj.theory.motion import STUCK_SPEED_FRACTION

_CAP_SLACK = 1e-6
#: Force control: a carriage this far (L_c) past where it last held has let go for good
#: (spines that re-engage catch it well before; the run stops there).
LET_GO_TRAVEL_LC = 2.0


#: Steps of each piece of an array run between two looks at its end conditions.
ARRAY_PIECE_STEPS = 1024
#: Rows an array run keeps before it thins them to every other (maxima and the
#: end conditions read every step).
MAX_RECORDED_ROWS = 2000
#: A force-controlled run holds its full pull this long, in ramp steps, before it counts as held.
HOLD_FRACTION = 0.05


@dataclass(frozen=True)
class ForcePull:
    """Force control: the carriage is free and pulled by a force that rises at ``N``
    times ``rate_n_s`` (so each spine's share rises at ``rate_n_s``) up to ``N kappa_cap
    F_p``, then holds.

    Attributes
    ----------
    rate_n_s : float or None
        Rate per spine [N/s]; None: the single ramp's ``0.1 F_p / tau`` (``I_e = 0.01``,
        :func:`~spine_mj.sim.drives.rate_n_s`).
    stiffness_n_m : float or None
        Each spring's stiffness; None: the spring drive's default ``K = 30``.
    settle_time_s : float or None
        Settle phase before the pull starts (None: 200 steps).
    carriage_mass_kg : float or None
        None: the tips' total mass ``N m``.
    start_force_n : float
        Each spine's share of the pull when the ramp starts [N] (>= 0): a slow ramp need
        not climb slowly through forces that hold for sure.
    """

    rate_n_s: float | None = None
    stiffness_n_m: float | None = None
    settle_time_s: float | None = None
    carriage_mass_kg: float | None = None
    start_force_n: float = 0.0

    def __post_init__(self):
        check_optional(self, ["rate_n_s", "stiffness_n_m", "carriage_mass_kg"])
        check_optional(self, ["start_force_n"], allow_zero=True)
        check_optional(self, ["settle_time_s"], allow_zero=True)


ArrayDrive = SpringDrive | ForcePull


@dataclass(frozen=True, eq=False)
class ArrayResult:
    """One array run (SI units). ``m`` recorded rows (``step_index``), ``N`` spines.

    Attributes
    ----------
    time_s, carriage_x_m, total_force_n, pull_n : (m,)
        Time, carriage displacement from its start, the sum of the spines' spring forces
        and (force control) the pull on the carriage (NaN under displacement control).
    spine_force_n : (m, N)
        Each spring's force on its tip in +x.
    position_m : (m, N, 3)
        Tip centres.
    start_xy : (N, 2)
        Spine starts in surface units.
    max_force_n : (N,)
        Each spine's largest spring force over the run (every step).
    locked : (N,) bool
        Spines that reached ``kappa_cap F_p`` while stuck (self-lock).
    holding_force_n : float
        Displacement control: the largest total force the spines carried while the array
        held, up to the last step before every spine moved faster than
        :data:`~spine_mj.theory.motion.STUCK_SPEED_FRACTION` of the carriage speed (the whole
        run if some spine never let go). Force control: the largest pull under which the
        carriage held, moving slower than the pull's equivalent speed ``L_c (dF/dt) / (N
        F_p)`` (faster, it has let go; a carriage caught again by re-engaging spines holds
        again).
    holding_ratio : float
        ``holding_force_n`` over the total preload ``N F_p``.
    holding_excess_predicted : float
        The predicted dynamic excess of ``holding_ratio`` over the quasistatic holding
        (:func:`~spine_mj.sim.holding.holding_excess`, per spine in ``F_p``): the part of
        the spring-block swing read before let-go, or the force-rate lag.
    peak_force_n, peak_ratio : float
        The largest total spring force over the whole run (every step) and it over ``N F_p``:
        the force-displacement curve's maximum, dynamic swings included (under displacement
        control up to ``sqrt(I_e K L_c / l_s)`` per spine above the quasistatic curve).
    inertia_number : float
        The drive's pace: ``I_e`` of the carriage's speed, or of the pull's rate per spine.
    end_reason : str
        ``completed``, ``left_domain`` (a tip reached the domain's edge), ``locked`` (every
        spine self-locked), ``held`` (force control: the full pull held) or ``engine_trouble``.
    end_detail : str
    simulated_steps : int
    step_index : (m,) int
        The step each recorded row is the state after (0: the first step); every
        ``2^j``-th step is kept, at most ~2 :data:`MAX_RECORDED_ROWS` rows, plus the last.
    """

    time_s: np.ndarray
    carriage_x_m: np.ndarray
    total_force_n: np.ndarray
    pull_n: np.ndarray
    spine_force_n: np.ndarray
    position_m: np.ndarray
    start_xy: np.ndarray
    max_force_n: np.ndarray
    locked: np.ndarray
    holding_force_n: float
    holding_ratio: float
    end_reason: str
    end_detail: str
    simulated_steps: int
    step_index: np.ndarray
    holding_excess_predicted: float
    peak_force_n: float
    peak_ratio: float
    inertia_number: float

    @property
    def n_spines(self) -> int:
        return int(self.start_xy.shape[0])

    @property
    def locked_spines(self) -> int:
        return int(self.locked.sum())


class _Run:
    """The progress of one run: its start, last state, warm start, maxima and kept rows."""

    def __init__(self, init: np.ndarray, x0: np.ndarray, nv: int, n_spines: int):
        self.init, self.x0 = init, x0
        self.last = init
        self.warm = np.zeros((1, nv))
        self.done = 0
        self.max_force = np.full(n_spines, -np.inf)
        self.locked = np.zeros(n_spines, dtype=bool)
        self.hold = -np.inf  # holding force so far (engine units)
        self.peak = -np.inf  # largest total spring force so far
        self.let_go = False  # displacement control: every spine has moved
        self.held_x = init[0, 1 + 3 * n_spines] if init.shape[1] > 1 + 3 * n_spines else 0.0
        self.rows: list[tuple] = []  # kept rows: (time, X, forces, positions, pull, step index)
        self.stride, self.kept = 1, 0
        self.end: tuple[str, str] | None = None

    def thin(self) -> None:
        """Keep every other kept row (and the last): the stride doubles."""
        cols = [np.concatenate(c) for c in zip(*self.rows)]
        steps = cols[-1]
        self.stride *= 2
        keep = ((steps + 1) % self.stride == 0) | (np.arange(steps.size) == steps.size - 1)
        self.rows = [tuple(c[keep] for c in cols)]
        self.kept = int(keep.sum())


class ArrayBatch:
    """The runs of one :meth:`ArrayRig.run_batch` call (engine units inside)."""

    def __init__(self, arr, drive, starts: list[np.ndarray], det: Detection):
        rig = arr.rig
        u = rig.units
        self.arr, self.drive, self.det, self.u = arr, drive, det, u
        self.n = arr.n
        self.force = isinstance(drive, ForcePull)
        self.model = arr.model_for(drive, det)
        self.k = stiffness_n_m(drive, rig.scales) / u.stiffness_n_m  # each spring, engine units
        self.cap = det.kappa_cap * rig.scales.preload_n / u.force_n
        self.dt = rig.engine.timestep_s / u.time_s
        self.slip = det.move_speed_m_s / u.speed_m_s
        margin = det.domain_margin_m / u.length_m
        xmin, xmax, ymin, ymax = (b / u.length_m for b in rig.bounds_m)
        self.box = (xmin + margin, xmax - margin, ymin + margin, ymax - margin)
        self.nq, self.nv = self.model.nq, self.model.nv
        self.starts = starts
        self.runs: list[_Run] = []
        self.plans = []
        for xy in starts:
            q = rig.place_many(xy)  # (N, 3) engine units
            init = np.zeros((1, arr.nstate))
            init[0, 1 : 1 + 3 * self.n] = q.ravel()
            if isinstance(drive, ForcePull):  # springs stretched to the start force: at rest from t = 0
                init[0, 1 + 3 * self.n] = drive.start_force_n / u.force_n / self.k
            self.runs.append(_Run(init, q[:, 0].copy(), self.nv, self.n))
            self.plans.append(arr.plan(drive, xy, det))
        self.rate = arr.pull_rate_n_s(drive) * u.time_s / u.force_n if self.force else 0.0
        self.speed = 0.0 if self.force else drive.speed_m_s / u.speed_m_s
        # force control: the carriage has let go while faster than the pull's equivalent speed
        # (L_c per F_p of pull per spine, engine units: rate / N)
        self.release = self.rate / self.n
        self.f0 = self.n * drive.start_force_n / u.force_n if self.force else 0.0
        sc = rig.scales
        self.ie = sc.inertia_number(
            sc.equivalent_speed(arr.pull_rate_n_s(drive) / self.n) if self.force else drive.speed_m_s
        )
        self.excess = holding_excess(
            self.ie,
            force_control=self.force,
            stiffness_number=sc.stiffness_number(stiffness_n_m(drive, sc)),
            lc_over_ls=sc.char_length_m / sc.slope_length_m,
        )

    # ----------------------------------------------------------------- controls

    def carriage(self, k: int, rows: np.ndarray) -> np.ndarray:
        """Displacement control: the carriage's displacement at ``rows`` (engine units)."""
        ns = self.plans[k][0]
        return self.speed * self.dt * np.maximum(0, rows - ns + 1)

    def pull(self, k: int, rows: np.ndarray) -> np.ndarray:
        """Force control: the pull at ``rows`` (engine units), capped at ``N kappa_cap``."""
        ns = self.plans[k][0]
        ramp = self.f0 + self.rate * self.dt * np.maximum(0, rows - ns + 1)
        return np.minimum(ramp, self.n * self.cap)

    def controls(self, k: int, a: int, b: int) -> np.ndarray:
        """Controls ``(b - a, nu)`` of rows a..b-1: springs, preloads (0: a bias), pull."""
        rows = np.arange(a, b)
        ctrl = np.zeros((b - a, self.model.nu))
        x0 = self.runs[k].x0
        if self.force:
            ctrl[:, : self.n] = x0  # rest lengths: the carriage starts at X = 0
            ctrl[:, -1] = self.pull(k, rows)
        else:
            ctrl[:, : self.n] = x0[None, :] + self.carriage(k, rows)[:, None]
        return ctrl

    # ----------------------------------------------------------------- stepping

    def run(self, lanes) -> list[ArrayResult]:
        out = 0
        for k in range(len(self.runs)):
            out += self.submit(k, lanes)
        while out:
            done = lanes.take(1)
            out -= len(done)
            for k, a, b, state, warm, warning in done:
                self.analyse(k, a, b, state[0], warning)
                self.runs[k].warm = np.asarray(warm, dtype=float).reshape(1, -1)
                out += self.submit(k, lanes)
        return [self.result(k) for k in range(len(self.runs))]

    def submit(self, k: int, lanes) -> int:
        run = self.runs[k]
        n = self.plans[k][1]
        if run.end is not None or run.done >= n:
            return 0
        a = run.done
        b = min(n, a + ARRAY_PIECE_STEPS)
        lanes.put(self.piece, (lanes, k, a, b))
        return 1

    def piece(self, lanes, k: int, a: int, b: int):
        """Rows a..b-1 of run ``k`` from its last state (a worker thread's job)."""
        run = self.runs[k]
        ctrl = self.controls(k, a, b)[None]
        state = np.empty((1, b - a, self.arr.nstate))
        sens = np.empty((1, b - a, self.model.nsensordata))
        warm, warning = lanes.step(self.model, run.last, run.warm, ctrl, state, sens)
        return k, a, b, state, warm, warning

    # ----------------------------------------------------------------- analysis

    def analyse(self, k: int, a: int, b: int, st: np.ndarray, warning) -> None:
        """Read rows a..b-1 of run ``k``: forces, locks, ends; keep the strided rows."""
        run, n = self.runs[k], self.n
        rows = np.arange(a, b)
        qpos = st[:, 1 : 1 + self.nq]
        qvel = st[:, 1 + self.nq : 1 + self.nq + self.nv]
        pos = qpos[:, : 3 * n].reshape(-1, n, 3)
        X = qpos[:, 3 * n] if self.force else self.carriage(k, rows)
        f = np.clip(self.k * (X[:, None] + run.x0[None, :] - pos[:, :, 0]), -self.cap, self.cap)
        speed = np.linalg.norm(qvel[:, : 3 * n].reshape(-1, n, 3), axis=2)
        bad = ~np.isfinite(st).all(axis=1)
        xmin, xmax, ymin, ymax = self.box
        x, y = pos[:, :, 0], pos[:, :, 1]
        out = ((x < xmin) | (x > xmax) | (y < ymin) | (y > ymax)).any(axis=1)
        lock_now = (f >= self.cap * (1 - _CAP_SLACK)) & (speed < self.slip)
        if self.force:
            held = np.abs(qvel[:, 3 * n]) < self.release
            last_held = np.maximum.accumulate(np.where(held, X, run.held_x))
            gone = X - last_held > LET_GO_TRAVEL_LC
        locked_by_row = run.locked[None, :] | np.logical_or.accumulate(lock_now, axis=0)
        ends = []
        if bad.any():
            ends.append((int(np.argmax(bad)), "engine_trouble", "a non-finite number in the state"))
        if warning is not None:
            ends.append((b - a - 1, "engine_trouble", f"MuJoCo warned ({warning})"))
        if out.any():
            i = int(np.argmax(out))
            ends.append(
                (i, "left_domain", f"a tip reached the domain's edge at t = {st[i, 0] * self.u.time_s:.4g} s")
            )
        if self.force and gone.any():
            i = int(np.argmax(gone))
            ends.append((i, "let_go", f"the carriage ran {LET_GO_TRAVEL_LC:g} L_c past where it last held"))
        if not self.force and locked_by_row[-1].all():
            i = int(np.argmax(locked_by_row.all(axis=1)))
            ends.append((i, "locked", f"all {n} spines self-locked"))
        last = b - a
        if ends:
            i, reason, detail = min(ends, key=lambda e: e[0])
            last = i + 1
            run.end = (reason, detail)
        elif b >= self.plans[k][1]:
            run.end = self.completion(k, speed[-1])
        keep = slice(0, last)
        run.max_force = np.maximum(run.max_force, f[keep].max(axis=0))
        run.peak = max(run.peak, float(f[keep].sum(axis=1).max()))
        if self.force:  # the pull while the carriage holds (slower than the release speed)
            run.held_x = float(last_held[last - 1])
            if held[keep].any():
                run.hold = max(run.hold, float(self.pull(k, rows[keep][held[keep]]).max()))
        elif not run.let_go:  # the total force up to the last step before every spine moved
            moving = (speed[keep] >= STUCK_SPEED_FRACTION * self.speed).all(axis=1)
            moving &= rows[keep] >= self.plans[k][0]  # once the carriage moves
            held = int(np.argmax(moving)) if moving.any() else last
            run.let_go = bool(moving.any())
            if held:
                run.hold = max(run.hold, float(f[:held].sum(axis=1).max()))
        run.locked = locked_by_row[last - 1]
        pick = np.flatnonzero(((rows[keep] + 1) % run.stride == 0) | (np.arange(last) == last - 1))
        u = self.u
        pull = self.pull(k, rows[pick]) * u.force_n if self.force else np.full(pick.size, np.nan)
        run.rows.append(
            (
                st[pick, 0] * u.time_s,
                X[pick] * u.length_m,
                f[pick] * u.force_n,
                pos[pick] * u.length_m,
                pull,
                rows[pick],
            )
        )
        run.kept += pick.size
        if run.kept > 2 * MAX_RECORDED_ROWS:
            run.thin()
        run.last = st[last - 1 : last].copy()
        run.done = a + last

    def completion(self, k: int, speed: np.ndarray) -> tuple[str, str]:
        """How a run that ran its planned steps ended."""
        if self.force and float(self.pull(k, np.array([self.plans[k][1] - 1]))[0]) >= self.n * self.cap * (
            1 - 1e-9
        ):
            if float(speed.max()) < self.slip:
                return "held", f"the full pull {self.n * self.cap:g} F_p held"
        return "completed", "the drive's duration elapsed"

    def result(self, k: int) -> ArrayResult:
        run, u = self.runs[k], self.u
        t, X, f, pos, pull, steps = (np.concatenate(c) for c in zip(*run.rows))
        fp = self.arr.rig.scales.preload_n
        total_f = f.sum(axis=1)
        hold = run.hold * u.force_n
        return ArrayResult(
            time_s=t,
            carriage_x_m=X,
            total_force_n=total_f,
            pull_n=pull,
            spine_force_n=f,
            position_m=pos,
            start_xy=np.asarray(self.starts[k], dtype=float),
            max_force_n=run.max_force * u.force_n,
            locked=run.locked.copy(),
            holding_force_n=hold,
            holding_ratio=hold / (self.n * fp),
            end_reason=run.end[0] if run.end else "completed",
            end_detail=run.end[1] if run.end else "",
            simulated_steps=int(run.done),
            step_index=steps,
            holding_excess_predicted=self.excess,
            peak_force_n=run.peak * u.force_n,
            peak_ratio=run.peak * u.force_n / (self.n * fp),
            inertia_number=self.ie,
        )


__all__ = ["ARRAY_PIECE_STEPS", "ArrayBatch", "ArrayDrive", "ArrayResult", "ForcePull"]
