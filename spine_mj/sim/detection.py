"""From a trajectory to stick/slip states, events and the reason a run ended.

:class:`Detection` holds the thresholds (derived from the scales where not given). The
end conditions are found for a whole group of runs at once (:func:`end_marks`: first step
of each condition per run); each run's candidates (:func:`end_candidates`, plus
:func:`probe_candidates` for a static probe) are then reduced to one (:func:`decide_end`):
a MuJoCo warning or a non-finite number anywhere in a run makes it engine trouble, whatever
happened before; otherwise the earliest ending wins, ties going to the more basic
condition: divergence (speed beyond the energy bound, the tip far below or above the
surface), deep penetration, leaving the domain, self-lock, then the probe's slide or
breakaway. Engine trouble names what happened in :attr:`Ending.trouble` (one of
:data:`TROUBLES`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import check_positive
from spine_mj.sim.recording import Recording
from spine_mj.sim.records import EndReason, check_optional
from spine_mj.sim.scales import Scales
from spine_mj.sim.step_rule import penetration_tolerance_m
from spine_mj.theory.engagement import DEFAULT_KAPPA_CAP, SELF_LOCK, kappa_of_normal

#: Kinds of engine trouble: a non-finite number, a MuJoCo warning (the engine stopped or
#: reset the run), penetration above tolerance, or a diverging state (speed or position).
TROUBLES = ("nan", "engine_warning", "penetration", "diverged")


@dataclass(frozen=True)
class Detection:
    """Thresholds that turn a trajectory into stick/slip states and events.

    None fields are derived from the scales (:meth:`resolve`), with ``v_c = sqrt(F_p L_c / m)``:

    Attributes
    ----------
    move_speed_m_s : float or None
        Tangential speed above which the tip slips (default ``1e-3 v_c``).
    stick_speed_m_s : float or None
        Tangential speed below which the tip counts as stuck when the breakaway force is
        read (default ``1e-5 v_c``; noslip holds a stuck tip to ~1e-11 m/s).
    breakaway_distance_m : float or None
        Displacement from the start that means breakaway (default ``min(0.1 r_tip, 0.01 L_c)``).
    kappa_cap : float
        Self-lock when the drive force reaches ``kappa_cap * F_p`` while stuck.
    penetration_tol_m : float or None
        Engine trouble above this penetration (default
        :func:`~spine_mj.sim.step_rule.penetration_tolerance_m`).
    domain_margin_m : float or None
        The run ends when the tip centre comes closer than this to the domain's edge
        (default: the tip radius).
    """

    move_speed_m_s: float | None = None
    stick_speed_m_s: float | None = None
    breakaway_distance_m: float | None = None
    kappa_cap: float = DEFAULT_KAPPA_CAP
    penetration_tol_m: float | None = None
    domain_margin_m: float | None = None

    def __post_init__(self):
        check_optional(
            self, ["move_speed_m_s", "stick_speed_m_s", "breakaway_distance_m", "penetration_tol_m"]
        )
        check_optional(self, ["domain_margin_m"], allow_zero=True)
        object.__setattr__(self, "kappa_cap", check_positive("kappa_cap", self.kappa_cap))

    def resolve(self, scales: Scales) -> Detection:
        v_c = scales.speed_m_s
        small = min(0.1 * scales.tip_radius_m, 0.01 * scales.char_length_m)
        defaults = {
            "move_speed_m_s": 1e-3 * v_c,
            "stick_speed_m_s": 1e-5 * v_c,
            "breakaway_distance_m": small,
            "penetration_tol_m": penetration_tolerance_m(scales),
            "domain_margin_m": scales.tip_radius_m,
        }
        return dataclasses.replace(self, **{k: v for k, v in defaults.items() if getattr(self, k) is None})

    def force_limit_n(self, scales: Scales, drive_speed_m_s: float, stiffness_n_m: float) -> float:
        """Drive force beyond which a spring run has diverged: the force cap and the
        preload, ``2 (kappa_cap + 1) F_p``, plus the force of a spring that holds the
        energy bound's kinetic energy, ``v_max sqrt(k m)`` with ``v_max`` =
        :meth:`speed_limit_m_s` (the same energy stored in the spring instead of the motion).
        A spring the step integrates unstably grows its stretch geometrically and crosses
        it within steps; infinite for force drives, whose force is the ramp's own."""
        if stiffness_n_m <= 0:
            return math.inf
        swing = self.speed_limit_m_s(scales, drive_speed_m_s) * math.sqrt(stiffness_n_m * scales.mass_kg)
        return 2 * (self.kappa_cap + 1) * scales.preload_n + swing

    def speed_limit_m_s(self, scales: Scales, drive_speed_m_s: float) -> float:
        """Speed above which a run diverges: 10 times the larger of the drive's speed and the
        speed the drive (at most ``kappa_cap F_p``) and the preload could give the tip over
        the whole domain, ``sqrt(2 (kappa_cap + 1) F_p D / m)`` (energy bound)."""
        extent = scales.extent_m if scales.extent_m is not None else scales.char_length_m
        energy = math.sqrt(2 * (self.kappa_cap + 1) * scales.preload_n * extent / scales.mass_kg)
        return 10 * max(drive_speed_m_s, energy)


@dataclass(frozen=True)
class Event:
    """One event in a run.

    Attributes
    ----------
    kind : str
        ``"move_onset"``, ``"move_stop"``, ``"reset"`` (a force ramp's) or an end reason.
    index : int
        The recorded row it happened at.
    time_s : float
        Its time [s].
    """

    kind: str
    index: int
    time_s: float


@dataclass(frozen=True)
class Ending:
    """A way a run can end: at step ``index``, for ``reason``; ``rank`` breaks ties (lower first)."""

    index: int
    rank: int
    reason: EndReason
    detail: str
    trouble: str = ""  # engine trouble: one of TROUBLES


def first_indices(mask: np.ndarray) -> np.ndarray:
    """First index of each row's True in a ``(g, n)`` mask, or -1."""
    idx = mask.argmax(axis=1)
    return np.where(mask[np.arange(mask.shape[0]), idx], idx, -1)


#: The MuJoCo side of the shared lock rule: the drive force must rise by this many F_p while
#: the tip stays stuck on a contact normal in the self-lock region.
LOCK_RISE_FP = 1.0


def normal_lock_marks(
    rec: Recording, mu: float, preload_n: float, held_from_n: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """First step of each run at which the shared lock rule holds (or -1), and the carry.

    The rule the streamline uses (:func:`spine_mj.theory.engagement.kappa_of_normal`, paper
    Fig. 2C), made sustained for a dynamic run: the tip is stuck in contact, the normal of
    its deepest contact lies in the self-lock region, and while both hold without a break
    the drive force has risen by :data:`LOCK_RISE_FP` preloads (the drive pushes into the
    surface and the contact holds, as the theory says it must at any force).

    ``rec`` may be a window of the runs (rows a..b-1): ``held_from_n`` ``(g,)`` is then the
    drive force at the start of a held streak still going on at row a-1 (NaN: none), and
    the second result is the same for row b-1, to pass with the next window; the marks
    are window rows. Windows passed in order give the marks of the whole run.
    """
    g, n = rec.contact.shape
    candidate = rec.contact & ~rec.moving
    region = np.zeros((g, n), np.int8)  # the rule is evaluated where the tip is stuck in contact
    region[candidate] = kappa_of_normal(rec.normal[candidate], mu)[1]
    held = candidate & (region == SELF_LOCK)
    if not held.any():
        return np.full(g, -1), np.full(g, np.nan)
    # first row of the held streak each row belongs to (0: since the window's first row)
    start = np.maximum.accumulate(np.where(held, 0, np.arange(1, n + 1)), axis=1)
    force = rec.drive_force_n
    base = np.take_along_axis(force, np.minimum(start, n - 1), axis=1)
    if held_from_n is not None:
        base = np.where((start == 0) & np.isfinite(held_from_n)[:, None], held_from_n[:, None], base)
    hit = held & (force - base >= LOCK_RISE_FP * preload_n)
    carry = np.where(held[:, -1], base[:, -1], np.nan) if n else np.full(g, np.nan)
    return first_indices(hit), carry


#: The end conditions, in the order of a group's mark columns (the keys of :func:`end_marks`).
MARK_KEYS = ("nonfinite", "reset", "fast", "sank", "flew", "deep", "out", "lock", "lock_rule", "strained")


def end_marks(
    rec: Recording,
    state: np.ndarray,
    sens: np.ndarray,
    *,
    timestep_s: float,
    bounds_m: Sequence[float],
    det: Detection,
    preload_n: float,
    speed_limit_m_s: np.ndarray,
    force_limit_n: np.ndarray | None = None,
    mu: float | None = None,
    first_step: int = 0,
) -> dict[str, np.ndarray]:
    """First step of each end condition for each run of a group (``rec`` ``(g, n, ...)``), or -1.

    Keys: ``nonfinite``, ``reset`` (MuJoCo reset the time, or froze it: the native rollout
    stops a run at its first warning), ``fast`` (speed above the run's ``speed_limit_m_s``,
    ``(g,)``), ``sank`` / ``flew`` (the tip centre below the surface's lowest point or
    above its highest by the domain's size; ``bounds_m`` is ``(xmin, xmax, ymin, ymax,
    zmin, zmax)``), ``deep`` (penetration above tolerance), ``out`` (the tip left the
    domain), ``lock_rule`` (the shared lock rule, :func:`normal_lock_marks`; needs ``mu``)
    and ``lock`` (the safety net: the drive force reached ``kappa_cap F_p`` while stuck),
    ``strained`` (a drive force beyond the run's ``force_limit_n`` ``(g,)``,
    :meth:`Detection.force_limit_n`: a spring stretch no drive can produce).
    ``first_step``: the run step of the rows' first row (a window of a run; the marks are
    window rows, and the lock rule sees the window alone).
    """
    g, n = state.shape[:2]
    dt = timestep_s
    if np.isfinite(state).all() and np.isfinite(sens).all():  # the usual case, one pass
        nonfinite = np.full(g, -1)
    else:
        nonfinite = first_indices(~(np.isfinite(state).all(axis=2) & np.isfinite(sens).all(axis=2)))
    expected = dt * np.arange(first_step + 1, first_step + n + 1)
    xmin, xmax, ymin, ymax, zmin, zmax = bounds_m
    mg = det.domain_margin_m
    px, py, pz = rec.position_m[:, :, 0], rec.position_m[:, :, 1], rec.position_m[:, :, 2]
    v = rec.velocity_m_s
    speed2 = v[:, :, 0] ** 2 + v[:, :, 1] ** 2 + v[:, :, 2] ** 2
    cap = det.kappa_cap * preload_n
    span = max(xmax - xmin, ymax - ymin)
    return {
        "nonfinite": nonfinite,
        "reset": first_indices(~(np.abs(rec.time_s - expected) <= 0.5 * dt)),
        "fast": first_indices(~(speed2 <= np.asarray(speed_limit_m_s)[:, None] ** 2)),
        "sank": first_indices(pz < zmin),
        "flew": first_indices(pz > zmax + span),
        "deep": first_indices(rec.penetration_m > det.penetration_tol_m),
        "out": first_indices((px < xmin + mg) | (px > xmax - mg) | (py < ymin + mg) | (py > ymax - mg)),
        "lock": first_indices((rec.drive_force_n >= cap * (1 - 1e-9)) & ~rec.moving),
        "lock_rule": np.full(g, -1) if mu is None else normal_lock_marks(rec, mu, preload_n)[0],
        "strained": np.full(g, -1)
        if force_limit_n is None
        else first_indices(~(np.abs(rec.drive_force_n) <= np.asarray(force_limit_n)[:, None])),
    }


def end_candidates(
    marks: dict[str, int],
    rec: Recording,
    warning: tuple[int | None, str] | None,
    det: Detection,
    preload_n: float,
) -> list[Ending]:
    """The endings a run reached: ``marks`` its row of each of :data:`MARK_KEYS` (-1: none),
    ``rec`` its recording."""
    if warning is None and max(marks.values()) < 0:
        return []  # most runs: nothing to look up
    trouble = EndReason.ENGINE_TROUBLE
    candidates = []

    def mark(key):
        return marks[key] if marks[key] >= 0 else None

    if (k := mark("nonfinite")) is not None:
        candidates.append(Ending(k, 0, trouble, f"non-finite state at t = {rec.time_s[k]:.4g} s", "nan"))
    if (k := mark("reset")) is not None:
        detail = (
            f"MuJoCo warning: the engine reset or stopped the run at step {k} "
            "(bad qpos/qvel/qacc or a full contact buffer)"
        )
        candidates.append(Ending(k, 0, trouble, detail, "engine_warning"))
    if warning is not None and warning[0] is not None:
        candidates.append(Ending(warning[0], 0, trouble, f"MuJoCo warning: {warning[1]}", "engine_warning"))
    pos, vel = rec.position_m, rec.velocity_m_s
    if (k := mark("fast")) is not None:
        detail = f"speed {np.linalg.norm(vel[k]):.3g} m/s beyond the energy bound (diverged)"
        candidates.append(Ending(k, 1, trouble, detail, "diverged"))
    if (k := mark("strained")) is not None:
        detail = (
            f"drive force {rec.drive_force_n[k]:.3g} N: a spring stretch no drive can produce "
            f"({rec.drive_force_n[k] / preload_n:.3g} F_p, diverged)"
        )
        candidates.append(Ending(k, 1, trouble, detail, "diverged"))
    for key, where in (("sank", "below the surface's lowest point"), ("flew", "far above the surface")):
        if (k := mark(key)) is not None:
            detail = f"tip centre at z = {pos[k, 2]:.4g} m, {where} (diverged)"
            candidates.append(Ending(k, 1, trouble, detail, "diverged"))
    if (k := mark("deep")) is not None:
        detail = (
            f"penetration {rec.penetration_m[k]:.3g} m > tolerance {det.penetration_tol_m:.3g} m"
            f" ({_penetration_cause(rec, k, preload_n)})"
        )
        candidates.append(Ending(k, 1, trouble, detail, "penetration"))
    if (k := mark("out")) is not None:
        detail = f"tip at ({pos[k, 0]:.4g}, {pos[k, 1]:.4g}) m left the domain"
        candidates.append(Ending(k, 2, EndReason.LEFT_DOMAIN, detail))
    if (k := mark("lock_rule")) is not None:
        detail = (
            f"lock rule: stuck on a contact normal in the self-lock region while the drive force "
            f"rose by {LOCK_RISE_FP:g} F_p (to {rec.drive_force_n[k] / preload_n:.3g} F_p; "
            f"{_held_by(rec, k, preload_n)})"
        )
        candidates.append(Ending(k, 3, EndReason.SELF_LOCK, detail))
    if (k := mark("lock")) is not None:
        cap = det.kappa_cap * preload_n
        detail = (
            f"force cap: drive force reached kappa_cap * F_p = {cap:.4g} N without slip "
            f"({_held_by(rec, k, preload_n)})"
        )
        candidates.append(Ending(k, 3, EndReason.SELF_LOCK, detail))
    return candidates


#: Steps after touch-down within which a penetration counts as the landing's: an impact
#: sinks deepest about one contact time constant after touch-down, 2 to 3 steps by the step
#: rule (a step refined for the spring drive keeps the contact's time constant).
_LANDING_STEPS = 8


def _penetration_cause(rec: Recording, k: int, preload_n: float) -> str:
    """What sank the tip at step ``k``: a landing (the speed it arrived with, how long it
    was airborne) or a contact pressed by a large force (the normal force in F_p)."""
    apart = np.flatnonzero(~rec.contact[: k + 1])
    onset = int(apart[-1]) + 1 if apart.size else 0  # first step of the contact that sank
    if 0 < onset and k - onset < _LANDING_STEPS:
        before = np.flatnonzero(rec.contact[:onset])
        airborne = onset - 1 - int(before[-1]) if before.size else onset
        speed = float(np.linalg.norm(rec.velocity_m_s[onset - 1]))
        return f"landing at {speed:.3g} m/s after {airborne} steps airborne"
    return f"contact pressed by a normal force of {rec.normal_force_n[k] / preload_n:.3g} F_p"


def _held_by(rec: Recording, k: int, preload_n: float) -> str:
    """The contacts that hold a lock at step ``k``: their normal forces summed, in F_p, and
    the deepest one's depth. A tip wedged between facets carries more normal force than a
    single contact would (``(W cos theta + F sin theta) / cos alpha`` on the two flanks of
    a V-groove it slides along, docs/physics.md §6; a jam's is not determined), held at
    the soft contact's depth, which is not engine trouble while it stays within the
    tolerance."""
    return (
        f"held with a normal force of {rec.normal_force_n[k] / preload_n:.3g} F_p "
        f"at a depth of {rec.penetration_m[k]:.3g} m"
    )


def probe_candidates(
    rec: Recording, n_settle: int, det: Detection, preload_n: float
) -> tuple[list[Ending], float]:
    """Static probe: the slid/breakaway endings of a run and kappa_mj (NaN if none)."""
    pos, vt, drive_f = rec.position_m, rec.tangential_speed_m_s, rec.drive_force_n
    n = pos.shape[0]
    kappa = math.nan
    candidates = []

    def first(mask):
        idx = np.flatnonzero(mask)
        return int(idx[0]) if idx.size else None

    p_ref = pos[min(n_settle, n) - 1]
    moved = np.linalg.norm(pos - pos[0], axis=1) > det.breakaway_distance_m
    k_settle = first(moved[:n_settle])
    if k_settle is not None:
        candidates.append(
            Ending(k_settle, 4, EndReason.SLID, "the tip slid during settling at the start force")
        )
    moved = np.linalg.norm(pos - p_ref, axis=1) > det.breakaway_distance_m
    moved[:n_settle] = False
    k = first(moved)
    if k is not None:
        stuck = np.flatnonzero(vt[:k] <= det.stick_speed_m_s)
        j = int(stuck[-1]) if stuck.size else n_settle - 1
        f_break = drive_f[max(j, n_settle - 1)]
        if pos[k, 0] - p_ref[0] <= 0 or j < n_settle:
            candidates.append(
                Ending(k, 4, EndReason.SLID, f"the tip slid against the drive at F = {f_break:.4g} N")
            )
        else:
            kappa = float(f_break / preload_n)
            detail = f"breakaway at F = {f_break:.4g} N, kappa_mj = {kappa:.4g}"
            candidates.append(Ending(k, 4, EndReason.BREAKAWAY, detail))
    return candidates, kappa


def decide_end(candidates: Sequence[Ending], n: int) -> Ending:
    """The ending of a run: the first MuJoCo warning or non-finite number if there is one
    (never a physical outcome), else the earliest candidate (ties: the lower rank), else
    completion at step ``n - 1``."""
    engine = [c for c in candidates if c.rank == 0]
    if engine:
        return min(engine, key=lambda c: c.index)
    if not candidates:
        return Ending(n - 1, 0, EndReason.COMPLETED, "drive duration elapsed")
    return min(candidates, key=lambda c: (c.index, c.rank))


def move_events(moving: np.ndarray, t: np.ndarray, start: int) -> list[Event]:
    """Slip onsets and stops from step ``start`` on, the settle phase taken as stuck: an
    onset at ``start`` if the tip slips there (``start`` >= 1), then every change of
    ``moving`` after it."""
    seg = moving[start:]
    changes = np.flatnonzero(seg[1:] != seg[:-1]) + (start + 1)
    if start >= 1 and seg.size and seg[0]:
        changes = np.concatenate([[start], changes])
    rows = zip(changes.tolist(), moving[changes].tolist(), t[changes].tolist())
    return [Event("move_onset" if slips else "move_stop", i, ti) for i, slips, ti in rows]
