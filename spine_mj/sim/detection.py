"""From a trajectory to stick/slip states, events and the reason a run ended.

:class:`Detection` holds the thresholds (derived from the scales where not given). The
end conditions are found for a whole group of runs at once (:func:`end_marks`: first step
of each condition per run); each run's candidates (:func:`end_candidates`, plus
:func:`probe_candidates` for a static probe) are then reduced to the earliest, ties going
to the more basic condition (:func:`decide_end`): engine trouble, deep penetration,
leaving the domain, self-lock, then the probe's slide or breakaway.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import check_positive
from spine_mj.sim.params import EndReason, Scales, check_optional
from spine_mj.sim.recording import Recording


@dataclass(frozen=True)
class Detection:
    """Thresholds that turn a trajectory into stick/slip states and events.

    None fields are derived from the scales (:meth:`resolve`), with ``v_c = sqrt(F_p L_c / m)``:

    Attributes
    ----------
    slip_speed_m_s : float or None
        Tangential speed above which the tip slips (default ``1e-3 v_c``).
    stick_speed_m_s : float or None
        Tangential speed below which the tip counts as stuck when the breakaway force is
        read (default ``1e-5 v_c``; noslip holds a stuck tip to ~1e-11 m/s).
    breakaway_distance_m : float or None
        Displacement from the start that means breakaway (default ``min(0.1 r_tip, 0.01 L_c)``).
    kappa_cap : float
        Self-lock when the drive force reaches ``kappa_cap * F_p`` while stuck.
    penetration_tol_m : float or None
        Engine trouble above this penetration (default ``min(0.1 r_tip, 0.01 L_c)``).
    domain_margin_m : float or None
        The run ends when the tip centre comes closer than this to the domain's edge
        (default: the tip radius).
    """

    slip_speed_m_s: float | None = None
    stick_speed_m_s: float | None = None
    breakaway_distance_m: float | None = None
    kappa_cap: float = 20.0
    penetration_tol_m: float | None = None
    domain_margin_m: float | None = None

    def __post_init__(self):
        check_optional(
            self, ["slip_speed_m_s", "stick_speed_m_s", "breakaway_distance_m", "penetration_tol_m"]
        )
        check_optional(self, ["domain_margin_m"], allow_zero=True)
        object.__setattr__(self, "kappa_cap", check_positive("kappa_cap", self.kappa_cap))

    def resolve(self, scales: Scales) -> Detection:
        v_c = scales.speed_m_s
        small = min(0.1 * scales.tip_radius_m, 0.01 * scales.char_length_m)
        defaults = {
            "slip_speed_m_s": 1e-3 * v_c,
            "stick_speed_m_s": 1e-5 * v_c,
            "breakaway_distance_m": small,
            "penetration_tol_m": small,
            "domain_margin_m": scales.tip_radius_m,
        }
        return dataclasses.replace(self, **{k: v for k, v in defaults.items() if getattr(self, k) is None})


@dataclass(frozen=True)
class Event:
    """One event in a run: ``kind`` in {"slip_onset", "slip_stop", "reset"} or an end reason."""

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


def first_indices(mask: np.ndarray) -> np.ndarray:
    """First index of each row's True in a ``(g, n)`` mask, or -1."""
    idx = mask.argmax(axis=1)
    return np.where(mask[np.arange(mask.shape[0]), idx], idx, -1)


def end_marks(
    rec: Recording,
    state: np.ndarray,
    sens: np.ndarray,
    *,
    timestep_s: float,
    bounds_m: Sequence[float],
    det: Detection,
    preload_n: float,
) -> dict[str, np.ndarray]:
    """First step of each end condition for each run of a group (``rec`` ``(g, n, ...)``), or -1.

    Keys: ``nonfinite``, ``reset`` (MuJoCo restarted the time), ``deep`` (penetration
    above tolerance), ``out`` (the tip left the domain) and ``lock`` (the drive force
    reached ``kappa_cap F_p`` while stuck).
    """
    g, n = state.shape[:2]
    dt = timestep_s
    if np.isfinite(state).all() and np.isfinite(sens).all():  # the usual case, one pass
        nonfinite = np.full(g, -1)
    else:
        nonfinite = first_indices(~(np.isfinite(state).all(axis=2) & np.isfinite(sens).all(axis=2)))
    expected = dt * np.arange(1, n + 1)
    xmin, xmax, ymin, ymax = bounds_m
    mg = det.domain_margin_m
    px, py = rec.position_m[:, :, 0], rec.position_m[:, :, 1]
    cap = det.kappa_cap * preload_n
    return {
        "nonfinite": nonfinite,
        "reset": first_indices(np.abs(rec.time_s - expected) > 0.5 * dt),
        "deep": first_indices(rec.penetration_m > det.penetration_tol_m),
        "out": first_indices((px < xmin + mg) | (px > xmax - mg) | (py < ymin + mg) | (py > ymax - mg)),
        "lock": first_indices((rec.drive_force_n >= cap * (1 - 1e-9)) & ~rec.slipping),
    }


def end_candidates(
    marks: dict[str, np.ndarray],
    r: int,
    rec: Recording,
    warning: tuple[int | None, str] | None,
    det: Detection,
    preload_n: float,
) -> list[Ending]:
    """The endings run ``r`` of a group reached (``rec`` is that run's recording)."""
    candidates = []
    if marks["nonfinite"][r] >= 0:
        candidates.append(Ending(int(marks["nonfinite"][r]), 0, EndReason.ENGINE_TROUBLE, "non-finite state"))
    if marks["reset"][r] >= 0:
        candidates.append(
            Ending(
                int(marks["reset"][r]),
                0,
                EndReason.ENGINE_TROUBLE,
                "MuJoCo reset the simulation (warning: bad qpos/qvel/qacc)",
            )
        )
    if warning is not None:
        k, text = warning
        if k is not None:
            candidates.append(Ending(k, 0, EndReason.ENGINE_TROUBLE, f"MuJoCo warning: {text}"))
    if marks["deep"][r] >= 0:
        k = int(marks["deep"][r])
        detail = f"penetration {rec.penetration_m[k]:.3g} m > tolerance {det.penetration_tol_m:.3g} m"
        candidates.append(Ending(k, 1, EndReason.ENGINE_TROUBLE, detail))
    if marks["out"][r] >= 0:
        k = int(marks["out"][r])
        pos = rec.position_m
        detail = f"tip at ({pos[k, 0]:.4g}, {pos[k, 1]:.4g}) m left the domain"
        candidates.append(Ending(k, 2, EndReason.LEFT_DOMAIN, detail))
    if marks["lock"][r] >= 0:
        cap = det.kappa_cap * preload_n
        detail = f"drive force reached kappa_cap * F_p = {cap:.4g} N without slip"
        candidates.append(Ending(int(marks["lock"][r]), 3, EndReason.SELF_LOCK, detail))
    return candidates


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
    """The earliest of the candidates (ties: the lower rank), else completion at step ``n - 1``."""
    if not candidates:
        return Ending(n - 1, 0, EndReason.COMPLETED, "drive duration elapsed")
    return min(candidates, key=lambda c: (c.index, c.rank))


def slip_events(slipping: np.ndarray, t: np.ndarray, start: int) -> list[Event]:
    """Slip onsets and stops from step ``start`` on (the settle phase ignored)."""
    s = slipping.copy()
    s[:start] = False
    change = np.flatnonzero(np.diff(s.astype(np.int8)))
    events = []
    for k in change:
        i = int(k) + 1
        events.append(Event("slip_onset" if s[i] else "slip_stop", i, float(t[i])))
    return events
