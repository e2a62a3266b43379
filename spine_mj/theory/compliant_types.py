"""The compliant-drive streamline's result types (:mod:`spine_mj.theory.compliant`): how the tip
leaves each path point, the jumps, and the paths with their carriage and force."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.theory.streamline_types import Outcome, StreamlineParams

__all__ = ["CompliantResult", "Fold", "MotionState"]


class MotionState(enum.IntEnum):
    """How the tip leaves a path point."""

    STICK = 0  #: waits while the carriage brings the spring up to the hold (start, landings)
    SLIDE = 1  #: moves with the carriage at the hold force (the rigid streamline's step)
    SLIP = 2  #: moves with the carriage still, the spring force above the hold (a jump)


@dataclass(frozen=True)
class Fold:
    """Jump onsets of a :class:`CompliantResult`, one row per jump (arrays of shape (m,)).

    Attributes
    ----------
    start : ndarray of int64
        Index of the start whose path jumps.
    x, y : ndarray
        The fold: where ``X(s)`` peaks along the path (surface length unit).
    carriage : ndarray
        Carriage position ``X`` at the onset.
    onset_force : ndarray
        Drive force at the onset over ``W``: the hold force there.
    land_x, land_y : ndarray
        Where the tip sticks again (NaN if the jump ended the path).
    land_force : ndarray
        Spring force over ``W`` at the landing (NaN if none).
    jump_length : ndarray
        Horizontal path length from fold to landing (to the path's end if none).
    """

    start: np.ndarray
    x: np.ndarray
    y: np.ndarray
    carriage: np.ndarray
    onset_force: np.ndarray
    land_x: np.ndarray
    land_y: np.ndarray
    land_force: np.ndarray
    jump_length: np.ndarray

    def __len__(self) -> int:
        return self.start.size

    @property
    def force_drop(self) -> np.ndarray:
        """Onset force less landing force over ``W`` (>= 0 for a jump that landed)."""
        return self.onset_force - self.land_force


@dataclass(frozen=True, eq=False)
class CompliantResult:
    """Compliant-drive streamlines from ``n`` starts; paths back to back (CSR layout).

    Attributes
    ----------
    params : StreamlineParams
    stiffness : float
        ``c = k / W`` (1 / surface length).
    start_x, start_y, outcome, end_x, end_y, n_steps, max_kappa : ndarray, shape (n,)
        As in :class:`spine_mj.theory.streamline_types.StreamlineResult` (``outcome``:
        :class:`~spine_mj.theory.streamline_types.Outcome` codes).
    offsets : ndarray of int64, shape (n + 1,)
    x, y, z, kappa : ndarray, shape (total,)
        Path points and kappa there (NaN in the slip region).
    carriage : ndarray, shape (total,)
        Carriage position ``X`` when the tip leaves the point.
    force : ndarray, shape (total,)
        Drive force over ``W`` when the tip leaves the point, ``c (X - x)``.
    state : ndarray of int8, shape (total,)
        :class:`MotionState` codes.
    folds : Fold
    """

    params: StreamlineParams
    stiffness: float
    start_x: np.ndarray
    start_y: np.ndarray
    outcome: np.ndarray
    end_x: np.ndarray
    end_y: np.ndarray
    n_steps: np.ndarray
    max_kappa: np.ndarray
    offsets: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    kappa: np.ndarray
    carriage: np.ndarray
    force: np.ndarray
    state: np.ndarray
    folds: Fold

    def __len__(self) -> int:
        return self.start_x.size

    @property
    def self_locked(self) -> np.ndarray:
        """Boolean ``(n,)``: held by the self-lock region or the force cap."""
        return (self.outcome == Outcome.SELF_LOCKED) | (self.outcome == Outcome.FORCE_CAP)

    def path(self, i: int) -> dict[str, np.ndarray]:
        """Path ``i``: arrays ``x, y, z, kappa, carriage, force, state``."""
        if not (-len(self) <= i < len(self)):
            raise SpineInputError(f"path index must be in [0, {len(self)}), got {i}")
        i %= len(self)
        s = slice(self.offsets[i], self.offsets[i + 1])
        return {k: getattr(self, k)[s] for k in ("x", "y", "z", "kappa", "carriage", "force", "state")}

    def folds_of(self, i: int) -> Fold:
        """The jumps of start ``i``."""
        sel = self.folds.start == (i % len(self))
        return Fold(**{k: getattr(self.folds, k)[sel] for k in Fold.__dataclass_fields__})
