"""Motion states relative to the drive, and the slip events they make.

Every recorded step is ``stuck``, ``sliding`` (moving with the drive) or ``slipping`` (the
tip outrunning the drive on the inertial time scale while the spring unloads). The rule
reads the tip's velocity against the drive's speed V (the carriage speed; for a force drive
the equivalent speed ``L_c rate / F_p``), never against a fixed fraction of v_c, so steady
sliding is never called slip at any I_e. docs/physics.md ("Motion states") derives the two
thresholds:

* a step is *slipping* when it lies in an interval over which the tip outruns the drive
  (``v_x > V``: for a spring, ``dF/dt = k (V - v_x) < 0``, the spring unloads) and that
  interval reaches :data:`SLIP_SPEED_FACTOR` ``V``. A stable quasistatic slide moves at
  ``V / (1 + (W/k) dkappa/dx)``, at most 2 V for ``K >= 2 K*``, and a spring-block on a
  flat plane swings between 0 and 2 V; a jump's speed is set by ``w = sqrt(k/m)`` and the
  force drop (``~ dF / sqrt(k m)``), not by V, and exceeds 5 V by far at small I_e.
* otherwise a step is *stuck* when the tip's speed is below :data:`STUCK_SPEED_FRACTION`
  ``V`` (the spring takes at least 90 % of the carriage's advance), else *sliding*.

A slip event is one slipping interval: its onset is the step before the interval (the last
step at which the spring was still loading, where its force peaks), and it carries the
onset force, the force drop (peak minus the lowest force after it within the event, never
negative by construction), the jump length along x and the duration. A slip still going
on at the run's last row (a run cut by its end) is not an event: its drop is unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Motion state codes and their names (the index is the code).
STUCK, SLIDING, SLIPPING = 0, 1, 2
MOTION_NAMES = ("stuck", "sliding", "slipping")

#: A step is stuck when the tip's speed is below this fraction of the drive's speed V.
STUCK_SPEED_FRACTION = 0.1
#: An interval of the tip outrunning the drive is a slip when its x-speed reaches this many V:
#: above the 2 V of a spring-block's swing and of any stable slide at K >= 2 K*, plus the
#: bursts of up to ~2 V the hfield's facet kinks add (measured on a corrugation at 128 points
#: per wavelength, K = 2 K*, I_e = 1e-4); a jump there reaches 50-80 V (docs/physics.md).
SLIP_SPEED_FACTOR = 5.0


@dataclass(frozen=True)
class SlipEvent:
    """One slip: rows ``onset`` (the last loading step) to ``stop`` (the last unloading step).

    Attributes
    ----------
    onset, stop : int
        Rows of the recording.
    onset_time_s : float
    onset_force_n : float
        Peak drive force at the onset [N].
    force_drop_n : float
        Onset force minus the lowest drive force after it within the event [N] (>= 0).
    jump_length_m : float
        Tip x displacement from onset to stop [m].
    duration_s : float
    peak_speed_m_s : float
        Largest x-speed in the event [m/s] (NaN when built from states alone).
    """

    onset: int
    stop: int
    onset_time_s: float
    onset_force_n: float
    force_drop_n: float
    jump_length_m: float
    duration_s: float
    peak_speed_m_s: float = float("nan")


def motion_states(velocity_m_s: np.ndarray, drive_speed_m_s: float, start: int = 0) -> np.ndarray:
    """The motion state (:data:`STUCK`, :data:`SLIDING`, :data:`SLIPPING`) of each row.

    Parameters
    ----------
    velocity_m_s : (n, 3) array
        Tip velocity [m/s]; x is the drive direction.
    drive_speed_m_s : float
        The drive's speed V [m/s].
    start : int
        First row of the drive (rows before it, the settle phase, are never slipping).
    """
    v = np.asarray(velocity_m_s, float)
    speed = np.sqrt((v * v).sum(axis=1))
    states = np.where(speed < STUCK_SPEED_FRACTION * drive_speed_m_s, STUCK, SLIDING).astype(np.int8)
    ahead = v[:, 0] > drive_speed_m_s
    ahead[: max(start, 0)] = False
    first, last = _run_bounds(ahead)
    if first.size:
        # each interval's peak x-speed at once (thousands of intervals a run at low I_e)
        vx = np.append(v[:, 0], -np.inf)  # room for the end of an interval at the last row
        peak = np.maximum.reduceat(vx, np.ravel(np.column_stack([first, last + 1])))[::2]
        slip = peak >= SLIP_SPEED_FACTOR * drive_speed_m_s
        mark = np.zeros(len(v) + 1, np.int64)
        np.add.at(mark, first[slip], 1)
        np.add.at(mark, last[slip] + 1, -1)
        states[np.cumsum(mark[:-1]) > 0] = SLIPPING
    return states


def _run_bounds(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last rows of the maximal runs of True in a 1-D mask."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return edges[0::2], edges[1::2] - 1


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Maximal runs of True in a 1-D mask as (first, last) rows."""
    first, last = _run_bounds(mask)
    return list(zip(first.tolist(), last.tolist()))


def slip_events(
    states: np.ndarray,
    time_s: np.ndarray,
    x_m: np.ndarray,
    force_n: np.ndarray,
    velocity_x_m_s: np.ndarray | None = None,
) -> list[SlipEvent]:
    """The slip events of a run from its motion ``states`` (one per run of SLIPPING rows)
    and its time, tip x and drive force (and x-speed, for the peak speed) per row."""
    out = []
    n = len(states)
    for a, b in _runs(np.asarray(states) == SLIPPING):
        if b == n - 1:  # cut by the end of the run
            continue
        o = max(a - 1, 0)
        f = force_n[o : b + 1]
        p = int(np.argmax(f))
        peak = float(np.max(velocity_x_m_s[a : b + 1])) if velocity_x_m_s is not None else float("nan")
        out.append(
            SlipEvent(
                onset=o,
                stop=b,
                onset_time_s=float(time_s[o]),
                onset_force_n=float(f[p]),
                force_drop_n=float(f[p] - f[p:].min()),
                jump_length_m=float(x_m[b] - x_m[o]),
                duration_s=float(time_s[b] - time_s[o]),
                peak_speed_m_s=peak,
            )
        )
    return out


def motion_fractions(
    states: np.ndarray, start: int = 0, time_s: np.ndarray | None = None
) -> dict[str, float]:
    """Fraction of the rows from ``start`` on spent in each state (zeros when none).

    ``time_s`` (the rows' times, the first one step after time 0): fractions of the time
    instead, each row counting the time since the row before (a fast-forwarded stick
    phase's rows count more than one step each; for a plain run the two agree)."""
    s = np.asarray(states)[start:]
    if time_s is None:
        w = np.ones(s.size)
    else:
        w = np.diff(np.asarray(time_s, float), prepend=0.0)[start:]
    total = w.sum()
    if not total > 0:
        return {name: 0.0 for name in MOTION_NAMES}
    return {name: float(w[s == code].sum() / total) for code, name in enumerate(MOTION_NAMES)}
