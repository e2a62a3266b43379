"""Slip events as drops of the spring's force, with hysteresis: one rule for every source
(docs/physics.md §12).

A spring drive loads while the tip holds (the force ``k (X - u)`` rises with the carriage)
and unloads while the tip outruns the carriage. A *drop* runs from a peak of the force to
the lowest force after it, and counts once the force has fallen more than ``floor`` below
the peak; it ends where the force has risen more than ``floor`` above that lowest point
(hysteresis: reversals smaller than ``floor`` inside a drop, or inside a loading phase, do
not cut it). The rule reads the force's curve, not the tip's speed, so

* a resting tip's jitter, however fast at a small drive speed, makes no event while its
  force swings stay under ``floor`` (the speed rule of :mod:`spine_mj.theory.motion`, 5 V,
  fires on it once V is small enough);
* it applies unchanged to a quasistatic reference's curve (the force at each carriage
  position, a slip being a drop at one position) and to an engine's recorded steps, so two
  catalogs built by it compare like with like, both cut at the same ``floor``.

A drop includes a stable slide down a falling stretch of the landscape that runs into a
slip (the force falls there too, slowly): on both sides alike. Where the force stays level
at its peak (a tip sliding along a facet of an engine's height field at a constant
threshold) the drop starts at the plateau's end, the last point within
:data:`PLATEAU_SHARE` ``floor`` of the peak; likewise it stops at the trough's first point
within that of the lowest force. A drop still under way at the series' end is not an
event (its trough is unknown).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from spine_mj.errors import SpineInputError, check_positive

__all__ = ["PLATEAU_SHARE", "drop_bounds", "jitter_scale"]

#: A drop starts at the last point within this share of ``floor`` of its peak force, and
#: stops at the first within it of its lowest: a level stretch's ends, not its arg-max.
PLATEAU_SHARE = 0.1


@njit(cache=True)
def _drop_walk(force, floor):
    n = force.size
    onset = np.empty(n // 2 + 1, np.int64)
    stop = np.empty(n // 2 + 1, np.int64)
    count = 0
    top = 0  # the running peak while loading
    low = 0  # the running trough while dropping
    dropping = False
    for i in range(1, n):
        f = force[i]
        if not dropping:
            if f > force[top]:
                top = i
            elif f < force[top] - floor:
                dropping = True
                low = i
        else:
            if f < force[low]:
                low = i
            elif f > force[low] + floor:
                onset[count] = top
                stop[count] = low
                count += 1
                dropping = False
                top = i
                for j in range(low + 1, i + 1):  # the highest point since the trough
                    if force[j] > force[top]:
                        top = j
    return onset[:count], stop[:count]


def drop_bounds(force, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """The drops of a force series deeper than ``floor``, as index arrays ``(onset,
    stop)``: the peak before each drop and the trough that ends it (see the module's
    docstring).

    Parameters
    ----------
    force : (n,) array
        The spring's force in time order (any unit; ``floor`` in the same).
    floor : float
        > 0: the hysteresis, the smallest drop and the smallest reload that count.

    Returns
    -------
    tuple of (m,) int arrays

    Raises
    ------
    SpineInputError
        A force that is not a finite 1-D array, or a floor that is not positive.
    """
    f = np.asarray(force, float)
    if f.ndim != 1 or not np.all(np.isfinite(f)):
        raise SpineInputError(f"force must be a finite 1-D array, got shape {f.shape}")
    h = check_positive("floor", floor)
    if f.size < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return _plateau_ends(f, *_drop_walk(f, h), PLATEAU_SHARE * h)


@njit(cache=True)
def _plateau_ends(force, onset, stop, tol):
    """Each drop's start moved to the last point before its trough within ``tol`` of the
    peak, its stop to the first point after its start within ``tol`` of the trough."""
    for m in range(onset.size):
        top, low = onset[m], stop[m]
        i = top
        while i + 1 < low and force[i + 1] >= force[top] - tol:
            i += 1
        j = i + 1
        while j < low and force[j] > force[low] + tol:
            j += 1
        onset[m], stop[m] = i, j
    return onset, stop


def jitter_scale(force, quantile: float = 0.99) -> float:
    """The ``quantile`` of a force series' elementary drops (each uninterrupted fall, from a
    step that starts falling to the next that does not), 0 without any: where the resting
    tip's jitter makes most of the reversals (thousands a run at small I_e, against tens
    of slips), the size of its swings, which a ``floor`` must clear.

    Parameters
    ----------
    force : (n,) array
    quantile : float
        In (0, 1].

    Returns
    -------
    float
    """
    f = np.asarray(force, float)
    if f.ndim != 1 or not np.all(np.isfinite(f)):
        raise SpineInputError(f"force must be a finite 1-D array, got shape {f.shape}")
    q = float(quantile)
    if not 0.0 < q <= 1.0:
        raise SpineInputError(f"quantile must lie in (0, 1], got {quantile!r}")
    d = np.diff(f)
    falling = np.concatenate([[False], d < 0, [False]])
    edges = np.flatnonzero(falling[1:] != falling[:-1])
    if edges.size == 0:
        return 0.0
    total = np.concatenate([[0.0], np.cumsum(d)])
    drops = total[edges[0::2]] - total[edges[1::2]]
    return float(np.quantile(drops, q))
