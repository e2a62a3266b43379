"""Quasistatic engagement streamlines and ideal trajectories (paper §2.2, Eq. 4).

At each point the tip is classified (:func:`spine_mj.theory.engagement.kappa`); a self-locked tip
stops. Otherwise the drive is raised to its limit ``F = kappa W`` (engaged) or is zero
(slip), the tip steps a length ``dl`` along the tangential load ``v = T / |T|`` and is put
back on the surface vertically::

    A_{k+1} = A_k + dl v_k,    B_{k+1} = (A_{k+1,x}, A_{k+1,y}, f(A_{k+1,x}, A_{k+1,y}))

The step is controlled: a step after which the horizontal slip direction reverses is
rejected and retried at half the length (the path crossed a groove floor or a crease
narrower than the step, across which fixed steps zig-zag and stall), and the step grows
back once the path goes on (``StreamlineParams.max_halvings``).

The ideal trajectory keeps ``y = y0`` and walks in +x with arc-length steps ``dl`` along
the section; kappa is evaluated on it and it stops on self-lock as well.

Two backends give the same numbers: ``"numba"`` (compiled kernels for
:class:`~spine_mj.surfaces.GaussianSurface` and :class:`~spine_mj.surfaces.GridSurface`,
one core) and ``"numpy"`` (a plain loop over steps, vectorized over starts, for any
:class:`~spine_mj.surfaces.Surface`; the reference the tests check the kernels against).

A finite tip of radius R rides with its centre on the surface dilated by a ball of radius
R: :func:`~spine_mj.surfaces.dilation.dilate` (re-exported here) builds that surface, on
which the same streamline rules apply.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import (
    BallOnFacets,
    GaussianSurface,
    GridSurface,
    Surface,
    TriangulatedSurface,
)
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory._kernels import run_trajectories
from spine_mj.theory.engagement import (
    REGION_NAMES,
    SELF_LOCK,
    SLIP,
    crease_engagement,
    kappa,
    slip_direction,
)
from spine_mj.theory.multicontact import two_contact_kappa

__all__ = [
    "DEFAULT_STEP_FRACTION",
    "Outcome",
    "StreamlineParams",
    "StreamlineResult",
    "check_step",
    "default_step",
    "dilate",
    "ideal_trajectories",
    "streamlines",
]


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


# --------------------------------------------------------------------------- numba kernels

_KIND_GAUSS = 0
_KIND_GRID = 1
_LANES = 32  # starts the kernel steps together (one core, 2,000 starts: 8 -> 4.3e7 steps/s, 32 -> 6.5e7)


def _get_kernel():

    return run_trajectories


def _surface_data(surface: Surface):
    dummy_g = np.zeros((5, 0))
    dummy_coef = np.zeros((1, 1))
    dummy_sp = np.zeros(8)
    if isinstance(surface, GaussianSurface):
        g = np.ascontiguousarray(
            np.stack(
                [
                    surface.amplitude,
                    surface.center_x,
                    surface.center_y,
                    1.0 / surface.sigma_x,
                    1.0 / surface.sigma_y,
                ]
            )
        )
        return _KIND_GAUSS, g, dummy_coef, dummy_sp
    if isinstance(surface, GridSurface):
        s = surface.spline
        sp = np.array([s.offset, s.x0, s.dx, s.nx, s.y0, s.dy, s.ny, float(s.periodic)])
        return _KIND_GRID, dummy_g, np.ascontiguousarray(s.coef), sp
    return None


# --------------------------------------------------------------------------- public API


def _starts(surface: Surface, starts) -> tuple[np.ndarray, np.ndarray]:
    arr = np.asarray(starts, dtype=float)
    if arr.ndim == 1 and arr.size == 2:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
        raise SpineInputError(f"starts must have shape (n, 2) with n >= 1, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SpineInputError("starts must be finite")
    inside = surface.contains(arr[:, 0], arr[:, 1])
    if not np.all(inside):
        bad = arr[~inside][0]
        raise SpineInputError(
            f"starts must lie inside the surface bounds {tuple(round(b, 6) for b in surface.bounds)}, "
            f"got ({bad[0]:g}, {bad[1]:g})"
        )
    return np.ascontiguousarray(arr[:, 0]), np.ascontiguousarray(arr[:, 1])


#: Smallest step length, relative to the largest coordinate of the surface's bounds: below
#: it, ``x + dl`` keeps too few of dl's digits (float64) for a path to advance truly.
MIN_STEP_OF_COORDINATES = 1e-9


def check_step(surface: Surface, dl: float) -> None:
    """Refuse a step length ``dl`` no path can use on ``surface``: not smaller than the
    domain (every path leaves at its first step) or lost in the rounding of a position."""
    xmin, xmax, ymin, ymax = surface.bounds
    size = min(xmax - xmin, ymax - ymin)
    if dl >= size:
        raise SpineInputError(
            f"dl must be smaller than the surface's domain ({size:g} across), got {dl:g}: "
            "every path would leave it at its first step"
        )
    scale = max(abs(xmin), abs(xmax), abs(ymin), abs(ymax), size)
    if dl < MIN_STEP_OF_COORDINATES * scale:
        raise SpineInputError(
            f"dl must be at least {MIN_STEP_OF_COORDINATES:g} of the surface's coordinates "
            f"(up to {scale:g}), got {dl:g}: a step would be lost in rounding"
        )


def _trajectories(surface, starts, params, *, ideal, store_paths, backend):
    if not isinstance(surface, Surface):
        raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
    if not isinstance(params, StreamlineParams):
        raise SpineInputError(f"params must be a StreamlineParams, got {type(params).__name__}")
    if backend not in ("numba", "numpy", "auto"):
        raise SpineInputError(f"backend must be 'numba', 'numpy' or 'auto', got {backend!r}")
    xs, ys = _starts(surface, starts)
    check_step(surface, params.dl)
    data = _surface_data(surface)
    if backend == "numba" and data is None:
        raise SpineInputError(
            f"backend 'numba' supports GaussianSurface and GridSurface, got {type(surface).__name__}"
        )
    if backend == "numpy" or data is None:
        out = _run_numpy(surface, xs, ys, params, ideal=ideal, store=store_paths)
    else:
        kind, g, coef, sp = data
        out = _get_kernel()(
            kind,
            g,
            coef,
            sp,
            np.asarray(params.domain(surface), dtype=float),
            xs,
            ys,
            bool(ideal),
            float(params.mu),
            float(params.dl),
            float(params.tol),
            int(params.max_steps),
            int(params.stall_window),
            float(params.stall_distance_value),
            bool(store_paths),
            min(_LANES, xs.size),
            float(params.kappa_cap),
            int(params.max_halvings),
        )
    outcome, n_steps, max_k, ex, ey, ez, offsets, px, py, pz, pk, pr = out
    if not store_paths:
        offsets = px = py = pz = pk = pr = None
    return StreamlineResult(
        params=params,
        ideal=bool(ideal),
        start_x=xs,
        start_y=ys,
        outcome=outcome,
        end_x=ex,
        end_y=ey,
        end_z=ez,
        n_steps=n_steps,
        max_kappa=max_k,
        offsets=offsets,
        x=px,
        y=py,
        z=pz,
        kappa=pk,
        region=pr,
    )


#: The step of a streamline given no ``dl``, as a fraction of the domain's longer side.
DEFAULT_STEP_FRACTION = 1e-3


def default_step(surface: Surface) -> float:
    """The streamline step ``dl`` when none is given: :data:`DEFAULT_STEP_FRACTION` of the
    longer side of ``surface.bounds`` (surface units), what ``spine-mj streamline`` and the
    streamline drawn beside a MuJoCo run use."""
    xmin, xmax, ymin, ymax = surface.bounds
    return DEFAULT_STEP_FRACTION * max(xmax - xmin, ymax - ymin)


def streamlines(
    surface: Surface, starts, params: StreamlineParams, *, store_paths: bool = True, backend: str = "auto"
) -> StreamlineResult:
    """Quasistatic engagement streamlines from many starts (paper Eq. 4, Fig. 2C).

    Parameters
    ----------
    surface : Surface
        Any surface; Gaussian and gridded surfaces run on the compiled kernel.
    starts : array_like, shape (n, 2)
        Start points ``(x0, y0)`` inside ``surface.bounds``.
    params : StreamlineParams
        Friction coefficient, step length, caps.
    store_paths : bool
        Keep every path point (False keeps only outcomes, end points and max kappa).
    backend : {"auto", "numba", "numpy"}
        ``"auto"`` uses the kernel where the surface type allows.

    Returns
    -------
    StreamlineResult

    Raises
    ------
    SpineInputError
        Starts outside the bounds, wrong shapes or parameter types.

    Examples
    --------
    The paper's single valley (Fig. 4): a start near its axis is trapped and self-locks,
    one far from it passes by.

    >>> import spine_mj as sm
    >>> valley = sm.make_surface("paper-single-valley")
    >>> res = sm.streamlines(valley, [(-3.0, -1.0), (-3.0, -4.0)], sm.StreamlineParams(mu=1.23))
    >>> [sm.Outcome(o).name for o in res.outcome]
    ['SELF_LOCKED', 'LEFT_DOMAIN']
    >>> path = slice(res.offsets[0], res.offsets[1])  # the first start's points
    >>> bool(res.x[path][-1] == res.end_x[0])
    True
    """
    return _trajectories(surface, starts, params, ideal=False, store_paths=store_paths, backend=backend)


def ideal_trajectories(
    surface: Surface, starts, params: StreamlineParams, *, store_paths: bool = True, backend: str = "auto"
) -> StreamlineResult:
    """Ideal trajectories (paper §3.1.2): ``y = y0``, +x in arc-length steps ``dl``.

    The path a spine would take if it were never deflected: the reference against which the
    streamlines' bypass and trap effects are measured. Stops on self-lock or at the edge.

    Parameters
    ----------
    surface : Surface
        Any surface; Gaussian and gridded surfaces run on the compiled kernel.
    starts : array_like, shape (n, 2)
        Start points ``(x0, y0)`` inside ``surface.bounds``.
    params : StreamlineParams
        Friction coefficient, step length, caps.
    store_paths : bool
        Keep every path point (False keeps only outcomes, end points and max kappa).
    backend : {"auto", "numba", "numpy"}
        ``"auto"`` uses the kernel where the surface type allows.

    Returns
    -------
    StreamlineResult
        As :func:`streamlines` returns, with ``ideal`` True.
    """
    return _trajectories(surface, starts, params, ideal=True, store_paths=store_paths, backend=backend)


#: A step across which the slope along the step grows by more than this crossed a concave
#: crease (a kink of the height's slopes, not a smooth valley: on MuJoCo's facets under a ball
#: every smooth piece curves down, so only creases make the slope grow along a step).
CREASE_KINK = 1e-6


def _wedged(xa, ya, fx, fy, prev, params) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points that crossed a concave crease from the last accepted point and rest there on
    both sides, held: by the two-contact rule
    (:func:`spine_mj.theory.multicontact.two_contact_kappa`) beyond the force cap or for every
    drive. A path that crosses such a crease without turning back (its two sides' slip
    directions less than 90 deg apart, each pressing into the other side) would zig-zag
    across it on single contacts and pass where the tip wedges.

    ``prev``: ``(px, py, pfx, pfy, ok)`` of the last accepted points (``ok``: it exists).
    Returns the held mask, and kappa and region of the held points."""
    px, py, pfx, pfy, ok = prev
    dx, dy = xa - px, ya - py
    step = np.hypot(dx, dy)
    with np.errstate(invalid="ignore", divide="ignore"):
        kink = ok & (((fx - pfx) * dx + (fy - pfy) * dy) > CREASE_KINK * step)
    i = np.flatnonzero(kink)
    held = np.zeros(xa.size, bool)
    kt = np.full(i.size, np.nan)
    rt = np.zeros(i.size, np.int8)
    if i.size:
        kt, rt = two_contact_kappa(pfx[i], pfy[i], fx[i], fy[i], params.mu)
        hold = (rt == SELF_LOCK) | (kt > params.kappa_cap)
        held[i[hold]] = True
        kt, rt = kt[hold], rt[hold]
    return held, kt, rt


def _run_numpy(surface, xs, ys, params, *, ideal, store):
    """The obvious reference: one vectorized evaluation for all active starts per iteration.

    A reversal at the shortest step (or on a crease already followed) is a tip resting in a
    concave crease on two contacts: the path follows the crease at the two-contact kappa of
    its sides (:func:`spine_mj.theory.engagement.crease_engagement`) with whole steps. Only this
    backend has the crease state; the compiled kernel traces smooth surfaces (Gaussian sums,
    splines) and takes such a reversal as it is. On facets (a ball on them or bare), a step
    that crosses a concave crease tests the two contacts' hold there
    (:func:`spine_mj.theory.multicontact.two_contact_kappa`, :func:`_wedged`): a tip wedged beyond
    the force cap, or for every drive, is held where a path on single contacts would
    zig-zag across the crease and go on.

    Each start holds a candidate point reached from its last accepted point by a step ``h``;
    a candidate where the horizontal slip direction reverses against the accepted point's
    is rejected (``h`` halves, down to ``dl / 2**max_halvings``) and the step is retried;
    an accepted candidate lets ``h`` grow back (doubling, up to ``dl``). See
    :class:`StreamlineParams`.
    """
    # One state machine over per-start arrays (point, step, last accepted point, its
    # direction and slopes, crease sides, stall window), kept whole where its steps share
    # them; the crease rule, the endings and the path packing are split out.
    n = xs.size
    creased = isinstance(surface, (BallOnFacets, TriangulatedSurface))  # creases between facets
    xmin, xmax, ymin, ymax = params.domain(surface)
    dl = float(params.dl)
    h_min = dl / 2.0**params.max_halvings
    x, y = xs.copy(), ys.copy()
    cx, cy = x.copy(), y.copy()
    h = np.full(n, dl)  # the step that produced the current point, then the next one
    px, py = x.copy(), y.copy()  # last accepted point and its horizontal slip direction
    pvx, pvy = np.zeros(n), np.zeros(n)
    pfx, pfy = np.zeros(n), np.zeros(n)  # and its slopes (the other side of a crease)
    sides = np.full((n, 4), np.nan)  # the two sides' slopes of the last crease the path met
    in_crease = np.zeros(n, bool)  # the last accepted point was on a crease
    has_prev = np.zeros(n, bool)
    arc = np.zeros(n)  # step lengths since the last progress check
    until = np.full(n, params.stall_window, np.int64)
    outcome = np.zeros(n, np.int8)
    n_steps = np.zeros(n, np.int64)
    max_k = np.full(n, np.nan)
    ez = np.full(n, np.nan)
    paths = [[] for _ in range(n)]
    active = np.arange(n)
    stall_pending = np.zeros(n, bool)  # no progress over a window: ends at the next evaluation
    stall_dist = params.stall_distance_value
    while active.size:
        xa, ya = x[active], y[active]
        f, fx, fy = surface.evaluate(xa, ya, order=1)
        k, reg = kappa(fx, fy, params.mu, tol=params.tol)
        locked = reg == SELF_LOCK
        if ideal:
            vx, vy = 1.0 / np.sqrt(1.0 + fx * fx), np.zeros_like(fx)
        else:
            vx, vy, _ = slip_direction(fx, fy, k, np.where(locked, SLIP, reg))
        finite = np.isfinite(vx) & np.isfinite(vy)
        with np.errstate(invalid="ignore"):
            turned = vx * pvx[active] + vy * pvy[active] < 0.0
        reversed_ = has_prev[active] & ~locked & finite & turned
        crease = np.zeros(active.size, bool)
        if not ideal and creased:
            prev = (px[active], py[active], pfx[active], pfy[active], has_prev[active] & ~locked)
            wedged, kw, rw = _wedged(xa, ya, fx, fy, prev, params)
            k[wedged], reg[wedged], locked[wedged] = kw, rw, rw == SELF_LOCK
            crease |= wedged
            reversed_ &= ~wedged
        if not ideal:
            # reversed at the shortest step, or on a crease already followed: the tip rests in
            # a concave crease, on two contacts (crease_engagement)
            r = np.flatnonzero(reversed_ & ((h[active] <= h_min) | in_crease[active]))
            _on_crease(
                r, active, (pfx, pfy), sides, params.mu, (fx, fy, k, reg, locked, vx, vy, finite), crease
            )
        rejected = reversed_ & (h[active] > h_min) & ~crease
        back = active[rejected]  # evaluated again next iteration, at the shorter step
        if back.size:
            h[back] *= 0.5
            x[back] = px[back] + h[back] * pvx[back]
            y[back] = py[back] + h[back] * pvy[back]
        keep = ~rejected
        active, xa, ya = active[keep], xa[keep], ya[keep]
        f, fx, fy, k, reg, locked = f[keep], fx[keep], fy[keep], k[keep], reg[keep], locked[keep]
        vx, vy, finite, reversed_ = vx[keep], vy[keep], finite[keep], reversed_[keep]
        crease = crease[keep]
        ez[active] = f
        max_k[active] = np.fmax(max_k[active], k)
        if store:
            for j, idx in enumerate(active):
                paths[idx].append((xa[j], ya[j], f[j], k[j], reg[j]))
        done = _endings(
            outcome,
            active,
            locked,
            k > params.kappa_cap,
            stall_pending[active],
            n_steps[active] >= params.max_steps,
            ~finite,
        )
        # an accepted point reached without a reversal lets the step grow back; along a
        # crease the path steps a whole dl
        hn = np.where(crease, dl, np.where(reversed_, h[active], np.minimum(2.0 * h[active], dl)))
        xn = xa + hn * np.where(done, 0.0, vx)
        yn = ya + hn * np.where(done, 0.0, vy)
        out = ~done & ~((xn >= xmin) & (xn <= xmax) & (yn >= ymin) & (yn <= ymax))
        outcome[active[out]] = Outcome.LEFT_DOMAIN
        done |= out
        go = ~done
        move = active[go]
        px[move], py[move] = xa[go], ya[go]
        pvx[move], pvy[move] = vx[go], vy[go]
        pfx[move], pfy[move] = fx[go], fy[go]
        in_crease[move] = crease[go]
        has_prev[move] = True
        h[move] = hn[go]
        x[move], y[move] = xn[go], yn[go]
        n_steps[move] += 1
        arc[move] += np.where(reversed_[go], dl, hn[go])  # a forced step across a crease: a full one
        until[move] -= 1
        check = move[until[move] == 0]
        if check.size:
            # progress asked for in proportion to the path walked (all full steps: stall_distance)
            need = stall_dist * (arc[check] * (1.0 / (params.stall_window * dl)))
            stuck = (x[check] - cx[check]) ** 2 + (y[check] - cy[check]) ** 2 < need * need
            stall_pending[check[stuck]] = True
            cx[check], cy[check], arc[check], until[check] = x[check], y[check], 0.0, params.stall_window
        active = np.sort(np.concatenate([back, move]))
    return outcome, n_steps, max_k, x.copy(), y.copy(), ez, *_packed(paths, store)


def _on_crease(r, active, prev_slopes, sides, mu, point, crease) -> None:
    """Where the tip rests in a concave crease (rows ``r`` of the ``active`` starts): the
    two-contact kappa, region and direction of its sides (:func:`crease_engagement`), the
    last point's slopes ``prev_slopes`` and the current ones, else the crease's other side
    from ``sides``; written into ``point`` = (fx, fy, k, reg, locked, vx, vy, finite),
    ``sides`` and ``crease`` where two contacts hold (:func:`_run_numpy`)."""
    pfx, pfy = prev_slopes
    fx, fy, k, reg, locked, vx, vy, finite = point
    other = np.column_stack([pfx[active[r]], pfy[active[r]]])
    got = crease_engagement(other[:, 0], other[:, 1], fx[r], fy[r], mu)
    for c in (0, 2):  # on the same side as the last point: the crease's other side
        again = got[1] < 0
        retry = sides[active[r], c : c + 2]
        alt = crease_engagement(retry[:, 0], retry[:, 1], fx[r], fy[r], mu)
        got = tuple(np.where(again, b, a) for a, b in zip(got, alt))
        other = np.where(again[:, None], retry, other)
    kc, rc, cvx, cvy = got
    two = rc >= 0
    r = r[two]
    sides[active[r]] = np.column_stack([other[two], fx[r], fy[r]])
    crease[r] = True
    k[r], reg[r], locked[r] = kc[two], rc[two], rc[two] == SELF_LOCK
    vx[r], vy[r] = cvx[two], cvy[two]
    finite[r] = locked[r] | (np.isfinite(vx[r]) & np.isfinite(vy[r]))


def _endings(outcome, active, locked, held, stalled, capped, still) -> np.ndarray:
    """Which ``active`` starts end here, the first reason in this order winning: self-lock,
    the force cap, a stall, the step cap, no finite direction (a stall); their outcomes
    are written into ``outcome``."""
    done = np.zeros(active.size, bool)
    for mask, code in (
        (locked, Outcome.SELF_LOCKED),
        (held, Outcome.FORCE_CAP),
        (stalled, Outcome.STALLED),
        (capped, Outcome.STEP_CAP),
        (still, Outcome.STALLED),
    ):
        new = ~done & mask
        outcome[active[new]] = code
        done |= new
    return done


def _packed(paths: list, store: bool) -> tuple:
    """Per-start paths as ``offsets`` and flat ``x, y, z, kappa, region`` arrays."""
    offsets = np.zeros(len(paths) + 1, np.int64)
    if not store:
        return offsets, np.empty(0), np.empty(0), np.empty(0), np.empty(0), np.empty(0, np.int8)
    offsets[1:] = np.cumsum([len(p) for p in paths])
    flat = np.array([pt for p in paths for pt in p], dtype=float).reshape(-1, 5)
    ppx, ppy, ppz, ppk = (np.ascontiguousarray(flat[:, c]) for c in range(4))
    return offsets, ppx, ppy, ppz, ppk, flat[:, 4].astype(np.int8)
