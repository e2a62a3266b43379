"""The records of a streamline computation: why a path ended (:class:`Outcome`), its
parameters (:class:`StreamlineParams`) and its paths (:class:`StreamlineResult`), shared by
both backends of :mod:`spine_mj.theory.streamline` and by the compliant drive
(:mod:`spine_mj.theory.compliant`)."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import Surface
from spine_mj.theory.engagement import REGION_NAMES

__all__ = ["Outcome", "StreamlineParams", "StreamlineResult"]


class Outcome(enum.IntEnum):
    """Why a trajectory ended."""

    SELF_LOCKED = 1  #: entered the self-lock region (kappa = inf)
    LEFT_DOMAIN = 2  #: the next step would leave the surface's bounds
    STALLED = 3  #: no net progress (|T| = 0, or too little progress over stall_window steps)
    STEP_CAP = 4  #: max_steps taken without any of the above
    FORCE_CAP = 5  #: the drive force needed, kappa W, exceeds ``kappa_cap`` W (held by the cap)
    DRIVE_END = 6  #: the carriage reached the end of its travel (:mod:`~spine_mj.theory.compliant`)


@dataclass(frozen=True)
class StreamlineParams:
    """Parameters of a streamline computation.

    Attributes
    ----------
    mu : float
        Static friction coefficient mu_s (> 0).
    dl : float
        Step length along the surface, in the surface's length unit (paper: about
        0.01 sigma for Gaussian surfaces).
    max_steps : int
        Step cap per trajectory (outcome ``STEP_CAP``).
    stall_window : int
        Steps between progress checks.
    stall_distance : float or None
        Minimum horizontal net displacement per ``stall_window`` steps of length ``dl``
        (surface length unit); less is ``STALLED``. Shorter steps ask for proportionally
        less (the progress asked for is ``stall_distance`` times the path walked over the
        window divided by ``stall_window dl``), except a step taken across a reversal at
        the shortest length, which counts as a full one: a path zig-zagging across a
        concave crease (two contacts, which a single-contact path cannot rest on) stalls
        within a window instead of creeping until the step cap. None means ``dl``.
    tol : float
        Tolerance on the scaled self-lock coefficient A' (see :func:`~spine_mj.theory.engagement.kappa`).
    max_halvings : int
        Step-size control: a step after which the horizontal slip direction reverses (turns
        by more than 90 degrees) has crossed something it did not resolve, such as the floor
        of a groove narrower than the step, across which a fixed step would zig-zag and
        stall while the path itself follows the floor. Such a step is rejected and retried
        at half the length, at most ``max_halvings`` times (down to ``dl / 2**max_halvings``,
        where it is taken as it is); each accepted step lets the next one grow back by a
        factor 2, up to ``dl``. 0: fixed steps ``dl``.
    kappa_cap : float
        The force cap, the safety net a comparison with the engine shares: a point whose
        kappa exceeds it ends the path as ``FORCE_CAP`` (held: no drive up to ``kappa_cap W``
        moves it), as a MuJoCo drive that reaches ``kappa_cap F_p`` unmoved ends there
        (:class:`spine_mj.sim.Detection`, the same default
        :data:`spine_mj.theory.engagement.DEFAULT_KAPPA_CAP` in a comparison). ``inf``, the
        paper's theory: only the self-lock region stops a path.
    edge_margin : float
        A path ends ``LEFT_DOMAIN`` where its next step would come closer than this to
        the surface's edges (surface length unit; 0: at the edges). A comparison with the
        engine passes the MuJoCo run's domain margin (the tip radius,
        :class:`spine_mj.sim.Detection`), so that both sides end at the same place.
    """

    mu: float
    dl: float = 0.015
    max_steps: int = 200_000
    stall_window: int = 64
    stall_distance: float | None = None
    tol: float = 1e-12
    max_halvings: int = 10
    kappa_cap: float = math.inf
    edge_margin: float = 0.0

    def __post_init__(self):
        for name in ("mu", "dl"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
                raise SpineInputError(f"{name} must be a finite number > 0, got {v!r}")
        for name in ("max_steps", "stall_window"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise SpineInputError(f"{name} must be an integer >= 1, got {v!r}")
        v = self.max_halvings
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not (0 <= v <= 60):
            raise SpineInputError(f"max_halvings must be an integer in [0, 60], got {v!r}")
        if self.stall_distance is not None and not (self.stall_distance >= 0):
            raise SpineInputError(f"stall_distance must be >= 0 or None, got {self.stall_distance!r}")
        if not (self.tol >= 0):
            raise SpineInputError(f"tol must be >= 0, got {self.tol!r}")
        if not (self.kappa_cap > 0):
            raise SpineInputError(f"kappa_cap must be > 0 (inf: no cap), got {self.kappa_cap!r}")
        m = self.edge_margin
        if not (isinstance(m, (int, float, np.floating)) and math.isfinite(m) and m >= 0):
            raise SpineInputError(f"edge_margin must be a finite number >= 0, got {self.edge_margin!r}")

    def domain(self, surface: Surface) -> tuple[float, float, float, float]:
        """``(xmin, xmax, ymin, ymax)`` a path on ``surface`` stays within: its bounds
        less ``edge_margin``."""
        xmin, xmax, ymin, ymax = surface.bounds
        m = float(self.edge_margin)
        return xmin + m, xmax - m, ymin + m, ymax - m

    @property
    def stall_distance_value(self) -> float:
        return self.dl if self.stall_distance is None else float(self.stall_distance)


@dataclass(frozen=True, eq=False)
class StreamlineResult:
    """Trajectories from ``n`` starts; paths stored back to back (CSR layout).

    Attributes
    ----------
    params : StreamlineParams
    ideal : bool
        True for ideal trajectories (y = y0), False for streamlines.
    start_x, start_y : ndarray, shape (n,)
    outcome : ndarray of int8, shape (n,)
        :class:`Outcome` codes.
    end_x, end_y, end_z : ndarray, shape (n,)
        Last point of each trajectory (the self-lock point for ``SELF_LOCKED``, the last
        point inside the domain for ``LEFT_DOMAIN``).
    n_steps : ndarray of int64, shape (n,)
        Steps taken; the path has ``n_steps + 1`` points.
    max_kappa : ndarray, shape (n,)
        Largest kappa met (``inf`` if self-locked, NaN if only slip points were met).
    offsets : ndarray of int64, shape (n + 1,) or None
        Path ``i`` occupies ``[offsets[i], offsets[i+1])`` of the flat arrays; None when the
        paths were not stored.
    x, y, z, kappa : ndarray, shape (total,) or None
        Flat path points and kappa at each point.
    region : ndarray of int8, shape (total,) or None
        Region code at each point (SLIP, ENGAGED, SELF_LOCK).
    """

    params: StreamlineParams
    ideal: bool
    start_x: np.ndarray
    start_y: np.ndarray
    outcome: np.ndarray
    end_x: np.ndarray
    end_y: np.ndarray
    end_z: np.ndarray
    n_steps: np.ndarray
    max_kappa: np.ndarray
    offsets: np.ndarray | None = None
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    z: np.ndarray | None = None
    kappa: np.ndarray | None = None
    region: np.ndarray | None = None
    meta: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return self.start_x.size

    @property
    def outcome_names(self) -> list[str]:
        """Outcome of each trajectory as a lower-case name (``self_locked``, ...)."""
        return [Outcome(int(o)).name.lower() for o in self.outcome]

    @property
    def self_locked(self) -> np.ndarray:
        """Boolean ``(n,)``: held, in the self-lock region or by the force cap
        (``params.kappa_cap``; never with the default ``inf``)."""
        return (self.outcome == Outcome.SELF_LOCKED) | (self.outcome == Outcome.FORCE_CAP)

    def path(self, i: int) -> dict[str, np.ndarray]:
        """Path ``i`` as arrays ``x, y, z, kappa, region`` of shape ``(n_steps[i] + 1,)``."""
        if self.offsets is None:
            raise SpineInputError("paths were not stored (store_paths=False)")
        if not (-len(self) <= i < len(self)):
            raise SpineInputError(f"path index must be in [0, {len(self)}), got {i}")
        s = slice(self.offsets[i], self.offsets[i + 1])
        return {k: getattr(self, k)[s] for k in ("x", "y", "z", "kappa", "region")}

    def to_frame(self):
        """Long table (pandas DataFrame): one row per path point, columns ``start``,
        ``step``, ``start_x``, ``start_y``, ``x``, ``y``, ``z``, ``kappa``, ``region``,
        ``outcome`` (names)."""

        if self.offsets is None:
            raise SpineInputError("paths were not stored (store_paths=False)")
        counts = np.diff(self.offsets)
        start = np.repeat(np.arange(len(self)), counts)
        step = np.arange(self.x.size) - np.repeat(self.offsets[:-1], counts)
        names = np.array(["", *[o.name.lower() for o in Outcome]])
        return pd.DataFrame(
            {
                "trajectory": "ideal" if self.ideal else "streamline",
                "start": start,
                "step": step,
                "start_x": self.start_x[start],
                "start_y": self.start_y[start],
                "x": self.x,
                "y": self.y,
                "z": self.z,
                "kappa": self.kappa,
                "region": np.array([REGION_NAMES[c] for c in sorted(REGION_NAMES)])[self.region],
                "outcome": names[self.outcome[start]],
            }
        )
