"""Compliant-drive streamlines: the paper's Eq. 4 with a spring in place of the force limit.

A carriage at ``X`` pulls the tip at ``(x, y)`` through a spring acting in x only, the
force per unit preload ``F / W = c (X - x)`` with ``c = k / W`` (1 / surface length; the
dimensionless stiffness is ``K = c l_s``). Quasistatically (docs/physics.md §6):

* the tip **sticks** while the spring force is below its hold force ``H`` (the drive at
  which the hold breaks, ``H = kappa`` where engaged, :func:`hold_force`): the carriage
  advances, the tip waits;
* at ``F = H`` it **slides** with the carriage along ``T / |T|`` of
  ``R = H W u_x + W g``, which is the rigid streamline's step (paper Eq. 4), while the
  carriage keeps ``X = x + H / c``;
* where that branch folds, ``dX / ds = dx / ds + (1 / c) dH / ds`` reaching 0 (in 2-D:
  ``1 + (W / k) d kappa / dx = 0``), the spring force exceeds the hold and the tip
  **slips** along ``T / |T|`` of ``R = c (X - x) W u_x + W g`` with the carriage still,
  until the force has fallen to the hold force again (the landing, where it sticks).

The fold is located by a golden-section search for the maximum of ``X(s)`` along the step
that crossed it, the landing by bisection on ``c (X - x(s)) - H(s)``, both to ~1e-8 of a step
along the path, so the onset force ``H`` at the fold, the carriage position there and the
jump length do not depend on the step (:class:`Fold`). Regions, the self-lock rule, the
step control and the stall test are those of :mod:`spine_mj.theory.streamline` (same
:class:`~spine_mj.theory.streamline_types.StreamlineParams`); above ``K*`` (no fold) the path is the
rigid streamline's and only the carriage differs. The spring never pushes the tip off
the surface here: lift-off is an inertial effect (:mod:`spine_mj.theory.drive_limits`).
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import BallOnFacets, Surface
from spine_mj.theory.compliant_types import CompliantResult, Fold, MotionState
from spine_mj.theory.engagement import DEFAULT_TOL, ENGAGED, SELF_LOCK, SLIP, quadratic_coefficients
from spine_mj.theory.streamline import _surface_data, check_step, start_points
from spine_mj.theory.streamline_types import Outcome, StreamlineParams

__all__ = ["compliant_streamlines", "hold_force"]


def hold_force(fx, fy, mu, *, tol: float = DEFAULT_TOL) -> tuple[np.ndarray, np.ndarray]:
    """Largest drive per unit preload ``H`` (any sign) that holds the tip, and the region.

    ``H = kappa`` where engaged (:func:`spine_mj.theory.engagement.kappa`, the same roots of Eq. 2
    by the same cancellation-free formula), ``+inf`` where self-locked; in the slip region
    the largest root of Eq. 2 with ``N > 0`` when one exists (a backward pull that holds:
    negative), else NaN (nothing holds). A tip held by a spring force ``F`` sticks while
    ``F <= H``.
    """
    fx, fy = np.broadcast_arrays(np.asarray(fx, dtype=float), np.asarray(fy, dtype=float))
    a, b, c = quadratic_coefficients(fx, fy, mu)
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = b * b - 4.0 * a * c
        q = -0.5 * (b + np.where(b >= 0, 1.0, -1.0) * np.sqrt(np.where(disc >= 0, disc, np.nan)))
        big = np.abs(a) >= tol
        r1 = np.where(big & (q != 0), q / np.where(big, a, 1.0), np.nan)
        r2 = np.where(q != 0, c / q, np.nan)
        hold = np.fmax(np.where(1.0 + r1 * fx > 0, r1, np.nan), np.where(1.0 + r2 * fx > 0, r2, np.nan))
    lock = (a < tol) & (fx > 0)
    region = np.where(lock, SELF_LOCK, np.where(hold > 0, ENGAGED, SLIP)).astype(np.int8)
    return np.where(lock, np.inf, hold), region


#: Golden-section steps locating a fold: the bracket shrinks to 0.618**40 ~ 5e-9 of a step
#: (a step is at most dl; in the validation R / 8), six orders below anything compared (the
#: ensembles' 1e-3 L_c). To round-off (60 steps) it cost the quick plan's sandpaper a third
#: more of its 1.3 ms per jump.
_GOLDEN_ITERATIONS = 40
#: Bisections locating a landing: 2**-36 ~ 1.5e-11 of a step.
_BISECTIONS = 36
#: The surface kind of a ball on facets in :func:`spine_mj.theory._compliant_kernel.run_compliant`
#: (0 and 1 are those of the rigid kernel: Gaussian sum, gridded spline).
_KIND_FACETS = 2
#: The fold table's columns after ``start``, as the compiled loop returns them.
_FOLD_COLUMNS = ("x", "y", "carriage", "onset_force", "land_x", "land_y", "land_force", "jump_length")
#: Where the probe sits along a slide step, from its end, as a fraction of the step.
_PROBE = 1e-6


def _direction(fx, fy, force):
    """Horizontal part of ``T / |T|`` for ``R = force u_x + g`` (NaN where ``|T| = 0``)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        s2 = 1.0 + fx * fx + fy * fy
        rn = (force * fx + 1.0) / s2
        tx, ty, tz = force - rn * fx, -rn * fy, -1.0 + rn
        inv = 1.0 / np.sqrt(tx * tx + ty * ty + tz * tz)
        inv = np.where(np.isfinite(inv), inv, np.nan)
    return tx * inv, ty * inv


def _hold_at(surface, x, y, mu, tol):
    _, fx, fy = surface.evaluate(x, y, order=1)
    return hold_force(fx, fy, mu, tol=tol)[0]


def _fold_along(surface, px, py, vx, vy, h, c, mu, tol):
    """``s`` in ``[0, h]`` maximizing ``X(s) = x(s) + H(s) / c`` along ``p + s v``, and
    ``X`` there (golden section, :data:`_GOLDEN_ITERATIONS` steps; NaN or inf ``H``: ``X = -inf``)."""

    def carriage(s):
        hx = _hold_at(surface, px + s * vx, py + s * vy, mu, tol)
        x = px + s * vx
        return np.where(np.isfinite(hx), x + hx / c, -np.inf)

    g = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = np.zeros_like(h), h.copy()
    s1, s2 = b - g * (b - a), a + g * (b - a)
    x1, x2 = carriage(s1), carriage(s2)
    for _ in range(_GOLDEN_ITERATIONS):
        left = x1 >= x2  # the maximum lies in [a, s2]
        b = np.where(left, s2, b)
        a = np.where(left, a, s1)
        s_new = np.where(left, b - g * (b - a), a + g * (b - a))
        x_new = carriage(s_new)
        s2, x2, s1, x1 = (
            np.where(left, s1, s_new),
            np.where(left, x1, x_new),
            np.where(left, s_new, s2),
            np.where(left, x_new, x2),
        )
    s = np.where(x1 >= x2, s1, s2)
    at0 = carriage(np.zeros_like(h))
    best = np.maximum(x1, x2)
    s = np.where(at0 >= best, 0.0, s)
    return s, np.maximum(at0, best)


def _landing_along(surface, px, py, vx, vy, h, carriage, c, mu, tol):
    """Smallest ``s`` in ``(0, h]`` where ``c (X - x(s)) <= H(s)`` (:data:`_BISECTIONS`
    halvings of ``h``): the spring force has fallen to the hold along a slip step (NaN ``H``:
    slips)."""

    def slipping(s):
        hx = _hold_at(surface, px + s * vx, py + s * vy, mu, tol)
        return ~(c * (carriage - (px + s * vx)) <= hx)

    lo, hi = np.zeros_like(h), h.copy()
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        slip = slipping(mid)
        lo, hi = np.where(slip, mid, lo), np.where(slip, hi, mid)
    return hi


class _Lanes:
    """Per-start state of the vectorized loop (structure of arrays)."""

    def __init__(self, xs, ys, dl, window):
        n = xs.size
        self.x, self.y = xs.copy(), ys.copy()  # the point to evaluate next
        self.px, self.py = xs.copy(), ys.copy()  # last accepted point
        self.pvx, self.pvy = np.zeros(n), np.zeros(n)  # and the direction it left along
        self.h = np.full(n, dl)  # the step from (px, py) to (x, y)
        self.has_prev = np.zeros(n, bool)
        self.X = xs.copy()  # carriage; spring relaxed at the start
        self.slipping = np.zeros(n, bool)  # the step into (x, y) was a slip
        self.pending = np.zeros(n, np.int8)  # (x, y) is a located fold (1) or landing (2)
        self.fold_row = np.full(n, -1, np.int64)  # the open jump's row in the fold table
        self.jump = np.zeros(n)
        self.outcome = np.zeros(n, np.int8)
        self.n_steps = np.zeros(n, np.int64)
        self.max_k = np.full(n, np.nan)
        self.cx, self.cy = xs.copy(), ys.copy()  # stall checkpoint
        self.arc = np.zeros(n)
        self.until = np.full(n, window, np.int64)


def compliant_streamlines(
    surface: Surface,
    starts,
    params: StreamlineParams,
    *,
    stiffness: float,
    carriage_end=None,
    backend: str = "auto",
) -> CompliantResult:
    """Quasistatic paths of a tip pulled through a spring of stiffness ``k = stiffness W``.

    Parameters
    ----------
    surface : Surface
        Any surface (evaluated through ``surface.evaluate``, vectorized over starts).
    starts : array_like, shape (n, 2)
        Start points; the spring is relaxed there (``X = x0``).
    params : StreamlineParams
        Friction, step, caps, stall test and step control, as for the rigid streamline.
    stiffness : float
        ``k / W`` in 1 / surface length, finite and > 0 (``K / l_s``).
    carriage_end : float or array_like, shape (n,), optional
        Where the carriage stops (surface units, >= the start's x): a path whose hold
        needs the carriage further ends there (``Outcome.DRIVE_END``), the tip held short
        of its hold, as a run whose drive ends does. None: the carriage goes on.
    backend : {"auto", "numba", "numpy"}
        ``"numba"``: the compiled loop (:func:`spine_mj.theory._compliant_kernel.run_compliant`,
        start by start) on a Gaussian sum, a gridded surface or a ball on compiled facets;
        ``"numpy"``: the plain loop here, vectorized over starts, for any surface (the
        reference the compiled one is tested against; about 0.3 ms of interpreter per
        iteration, which a tip creeping along a crease repeats ~1e5 times); ``"auto"``:
        the compiled loop where it applies.

    Returns
    -------
    CompliantResult
        (:mod:`spine_mj.theory.compliant_types`)
    """
    if not isinstance(surface, Surface):
        raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
    if not isinstance(params, StreamlineParams):
        raise SpineInputError(f"params must be a StreamlineParams, got {type(params).__name__}")
    c = stiffness
    number = isinstance(c, (int, float, np.floating)) and not isinstance(c, bool)
    if not (number and math.isfinite(c) and c > 0):
        raise SpineInputError(f"stiffness (k / W, 1 / length) must be a finite number > 0, got {stiffness!r}")
    xs, ys = start_points(surface, starts)
    check_step(surface, params.dl)
    end = np.broadcast_to(np.asarray(np.inf if carriage_end is None else carriage_end, float), xs.shape)
    if np.isnan(end).any() or (end < xs).any():
        raise SpineInputError(
            "carriage_end must be >= each start's x (or None: no end), got " + repr(carriage_end)
        )
    if backend not in ("auto", "numba", "numpy"):
        raise SpineInputError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
    data = _kernel_surface(surface) if backend != "numpy" else None
    if backend == "numba" and data is None:
        raise SpineInputError(
            "backend 'numba' supports GaussianSurface, GridSurface and compiled BallOnFacets, "
            f"got {type(surface).__name__}"
        )
    if data is None:
        return _run(surface, xs, ys, params, float(c), np.array(end))
    return _run_compiled(data, surface, xs, ys, params, float(c), np.array(end))


def _kernel_surface(surface):
    """The surface as :func:`spine_mj.theory._compliant_kernel.run_compliant` takes it, or None.
    Its arrays writable and contiguous whatever the surface's: a read-only one is another
    numba type, and each type compiles the loop anew (~10-25 CPU-s)."""
    if isinstance(surface, BallOnFacets):
        if not surface.compiled:
            return None
        data = (_KIND_FACETS, np.zeros((5, 0)), np.zeros((1, 1)), np.zeros(8), *surface.kernel_args())
    else:
        data = _surface_data(surface)
        if data is None:
            return None
        data = (*data, np.zeros((1, 1)), 0.0, 0.0, 1.0, 1.0, 0.0)
    return tuple(np.require(v, float, ["C", "W"]) if isinstance(v, np.ndarray) else v for v in data)


def _run_compiled(data, surface, xs, ys, params, c, carriage_end) -> CompliantResult:
    """:func:`_run` compiled, start by start (the same steps; fold rows in start order)."""
    from spine_mj.theory._compliant_kernel import run_compliant

    outcome, max_k, offsets, pts, states, fstart, fold = run_compliant(
        data,
        xs,
        ys,
        np.ascontiguousarray(carriage_end, dtype=float),
        np.asarray(params.domain(surface), dtype=float),
        c,
        float(params.mu),
        float(params.tol),
        float(params.dl),
        int(params.max_steps),
        int(params.stall_window),
        float(params.stall_distance_value),
        int(params.max_halvings),
        float(params.kappa_cap),
        _GOLDEN_ITERATIONS,
        _BISECTIONS,
        _PROBE,
    )
    last = offsets[1:] - 1
    folds = Fold(start=fstart, **{k: fold[:, j].copy() for j, k in enumerate(_FOLD_COLUMNS)})
    cols = {k: pts[:, j].copy() for j, k in enumerate(("x", "y", "z", "kappa", "carriage", "force"))}
    return CompliantResult(
        params=params,
        stiffness=c,
        start_x=xs,
        start_y=ys,
        outcome=outcome,
        end_x=cols["x"][last],
        end_y=cols["y"][last],
        n_steps=np.diff(offsets) - 1,
        max_kappa=max_k,
        offsets=offsets,
        folds=folds,
        state=states,
        **cols,
    )


class _Record:
    """Accepted path points, appended per iteration, sorted by start at the end."""

    def __init__(self):
        self.parts = []
        self.folds = {k: [] for k in Fold.__dataclass_fields__}

    def add(self, idx, **cols):
        self.parts.append((idx, cols))

    def open_fold(self, start, x, y, carriage, onset):
        rows = len(self.folds["start"])
        for k, v in (("start", start), ("x", x), ("y", y), ("carriage", carriage), ("onset_force", onset)):
            self.folds[k].append(v)
        for k in ("land_x", "land_y", "land_force", "jump_length"):
            self.folds[k].append(math.nan)
        return rows

    def paths(self, n):
        idx = np.concatenate([p[0] for p in self.parts])
        order = np.argsort(idx, kind="stable")
        cols = {k: np.concatenate([p[1][k] for p in self.parts])[order] for k in self.parts[0][1]}
        offsets = np.zeros(n + 1, np.int64)
        offsets[1:] = np.cumsum(np.bincount(idx, minlength=n))
        return offsets, cols

    def fold_table(self):
        """The jumps in start order, then along the path (as the compiled loop gives them)."""
        f = self.folds
        start = np.asarray(f["start"], np.int64)
        order = np.argsort(start, kind="stable")
        return Fold(
            start=start[order],
            **{k: np.asarray(f[k], float)[order] for k in Fold.__dataclass_fields__ if k != "start"},
        )


def _classify(L, a, hold, region, c):
    """Tentative motion at the evaluated points of lanes ``a``: slip flag and drive force."""
    force = c * (L.X[a] - L.x[a])
    slip = ~(force <= hold)
    slip = np.where(L.pending[a] == 1, True, np.where(L.pending[a] == 2, False, slip))
    slip &= region != SELF_LOCK
    return slip, np.where(slip, force, hold)


def _search(surface, L, lanes, kind, c, params):
    """Replace the candidate of ``lanes`` by the fold (kind 1) or landing (kind 2) located
    along the step from their last accepted point; on the tip's compiled facets by the same
    searches compiled (:mod:`spine_mj.theory._compliant_kernel`: the numpy ones spent ~100 us of
    call overhead per evaluation of a few lanes)."""
    if lanes.size == 0:
        return
    px, py, vx, vy, h = L.px[lanes], L.py[lanes], L.pvx[lanes], L.pvy[lanes], L.h[lanes]
    mu, tol = float(params.mu), float(params.tol)
    compiled = isinstance(surface, BallOnFacets) and surface.compiled
    if compiled:
        from spine_mj.theory import _compliant_kernel as kernel
    if kind == 1:
        if compiled:
            grid = surface.kernel_args()
            s, xstar = kernel.fold_on_facets(px, py, vx, vy, h, c, mu, tol, _GOLDEN_ITERATIONS, *grid)
        else:
            s, xstar = _fold_along(surface, px, py, vx, vy, h, c, mu, tol)
        L.X[lanes] = np.maximum(L.X[lanes], xstar)
    elif compiled:
        carriage = np.ascontiguousarray(L.X[lanes])
        s = kernel.landing_on_facets(
            px, py, vx, vy, h, carriage, c, mu, tol, _BISECTIONS, *surface.kernel_args()
        )
    else:
        s = _landing_along(surface, px, py, vx, vy, h, L.X[lanes], c, mu, tol)
    L.x[lanes], L.y[lanes] = px + s * vx, py + s * vy
    L.pending[lanes] = kind


def _accept(L, rec, a, z, kap, hold, slip, c, carriage_end, kappa_cap):
    """Record the accepted points of lanes ``a``; open and close jumps; move the carriage
    (to the hold, or to the force cap where the hold exceeds it: a run decides its lock
    there, and a carriage that reaches it has not stopped short)."""
    x, y = L.x[a], L.y[a]
    arrived_slipping = L.slipping[a] & L.has_prev[a]
    L.jump[a] += np.where(arrived_slipping, np.hypot(x - L.px[a], y - L.py[a]), 0.0)
    landed = arrived_slipping & ~slip
    for i in np.flatnonzero(landed):
        row = L.fold_row[a[i]]
        rec.folds["land_x"][row], rec.folds["land_y"][row] = x[i], y[i]
        rec.folds["land_force"][row] = c * (L.X[a[i]] - x[i])
        rec.folds["jump_length"][row] = L.jump[a[i]]
        L.fold_row[a[i]] = -1
    for i in np.flatnonzero(slip & ((L.pending[a] == 1) | ~L.has_prev[a])):
        onset = c * (L.X[a[i]] - x[i])  # at a fold: the hold there
        L.fold_row[a[i]] = rec.open_fold(int(a[i]), x[i], y[i], L.X[a[i]], onset)
        L.jump[a[i]] = 0.0
    stick = ~slip & (~L.has_prev[a] | landed)
    with np.errstate(invalid="ignore"):
        follow = ~slip & np.isfinite(hold)
        L.X[a] = np.where(follow, np.maximum(L.X[a], x + np.minimum(hold, kappa_cap) / c), L.X[a])
    stopped = L.X[a] > carriage_end[a]  # the carriage stops short of the hold: the tip stays
    L.X[a] = np.where(stopped, carriage_end[a], L.X[a])
    state = np.where(slip, MotionState.SLIP, np.where(stick, MotionState.STICK, MotionState.SLIDE))
    force = c * (L.X[a] - x)
    rec.add(a, x=x, y=y, z=z, kappa=kap, carriage=L.X[a].copy(), force=force, state=state.astype(np.int8))
    L.max_k[a] = np.fmax(L.max_k[a], kap)
    L.pending[a] = 0
    return stopped


def _end(L, rec, a, done_code):
    """Close the open jumps of lanes ``a`` (ended by ``done_code``) at the path's end."""
    L.outcome[a] = done_code
    for i in a:
        if L.fold_row[i] >= 0:
            rec.folds["jump_length"][L.fold_row[i]] = L.jump[i]
            L.fold_row[i] = -1


def _step(L, a, vx, vy, slip, reversed_, params, domain):
    """Advance the accepted lanes ``a`` (not ended); returns the lanes that left the domain."""
    dl = params.dl
    hn = np.where(L.pending[a] > 0, dl, np.where(reversed_, L.h[a], np.minimum(2.0 * L.h[a], dl)))
    xn, yn = L.x[a] + hn * vx, L.y[a] + hn * vy
    xmin, xmax, ymin, ymax = domain
    out = ~((xn >= xmin) & (xn <= xmax) & (yn >= ymin) & (yn <= ymax))
    go = a[~out]
    g = ~out
    L.px[go], L.py[go] = L.x[go], L.y[go]
    L.pvx[go], L.pvy[go] = vx[g], vy[g]
    L.h[go] = hn[g]
    L.x[go], L.y[go] = xn[g], yn[g]
    L.slipping[go] = slip[g]
    L.has_prev[go] = True
    L.n_steps[go] += 1
    L.arc[go] += hn[g]
    L.until[go] -= 1
    return a[out]


def _stalled(L, a, params):
    """Lanes of ``a`` at a progress check with too little net progress over the window."""
    check = a[L.until[a] == 0]
    need = params.stall_distance_value * L.arc[check] / (params.stall_window * params.dl)
    stuck = np.hypot(L.x[check] - L.cx[check], L.y[check] - L.cy[check]) < need
    L.cx[check], L.cy[check] = L.x[check], L.y[check]
    L.arc[check] = 0.0
    L.until[check] = params.stall_window
    return check[stuck]


def _end_decided(L, rec, a, stopped, locked, hold, finite, params) -> np.ndarray:
    """End the lanes ``a`` whose path is decided at their accepted point, each by the first
    reason that applies (carriage at its end, self-lock, force cap, step cap, no direction);
    returns the mask of the ended ones."""
    ended = np.zeros(a.size, bool)
    for mask, code in (
        (stopped, Outcome.DRIVE_END),
        (locked, Outcome.SELF_LOCKED),
        (~locked & (hold > params.kappa_cap), Outcome.FORCE_CAP),
        (L.n_steps[a] >= params.max_steps, Outcome.STEP_CAP),
        (~finite, Outcome.STALLED),
    ):
        m = mask & ~ended
        if m.any():
            _end(L, rec, a[m], code)
            ended |= m
    return ended


def _run(surface, xs, ys, params, c, carriage_end):
    """The vectorized loop: one surface evaluation for all active lanes per iteration."""
    n = xs.size
    L = _Lanes(xs, ys, params.dl, params.stall_window)
    rec = _Record()
    h_min = params.dl / 2.0**params.max_halvings
    domain = params.domain(surface)
    active = np.arange(n)
    while active.size:
        a = active
        # the carriage's slope at the end of a slide step, from a probe just before it: a
        # fold inside the step shows as X falling there even where X(h) >= X(0)
        probe = a[L.has_prev[a] & ~L.slipping[a] & (L.pending[a] == 0)]
        t = L.h[probe] * (1.0 - _PROBE)
        qx, qy = L.px[probe] + t * L.pvx[probe], L.py[probe] + t * L.pvy[probe]
        z, fx, fy = surface.evaluate(np.concatenate([L.x[a], qx]), np.concatenate([L.y[a], qy]), order=1)
        hold, region = hold_force(fx, fy, params.mu, tol=params.tol)  # elementwise: one call
        hold_q = hold[a.size :]
        z, fx, fy, hold, region = z[: a.size], fx[: a.size], fy[: a.size], hold[: a.size], region[: a.size]
        kap = np.where(region == SLIP, np.nan, hold)
        slip, drive = _classify(L, a, hold, region, c)
        at = np.searchsorted(a, probe)
        with np.errstate(invalid="ignore"):
            falling = ~(L.x[probe] + hold[at] / c >= qx + hold_q / c) & np.isfinite(hold[at])
        falls = np.zeros(a.size, bool)
        falls[at[falling]] = True
        vx, vy = _direction(fx, fy, drive)
        locked = region == SELF_LOCK
        finite = np.isfinite(vx) & np.isfinite(vy)
        with np.errstate(invalid="ignore"):
            reversed_ = L.has_prev[a] & ~locked & finite & (vx * L.pvx[a] + vy * L.pvy[a] < 0.0)
        fresh = L.pending[a] == 0
        reject = reversed_ & (L.h[a] > h_min) & fresh
        back = a[reject]
        L.h[back] *= 0.5
        L.x[back], L.y[back] = L.px[back] + L.h[back] * L.pvx[back], L.py[back] + L.h[back] * L.pvy[back]
        moving = ~reject & ~locked & fresh & L.has_prev[a]
        fold = moving & ~L.slipping[a] & (slip | falls)
        land = moving & L.slipping[a] & ~slip
        _search(surface, L, a[fold], 1, c, params)
        _search(surface, L, a[land], 2, c, params)
        ok = ~(reject | fold | land)
        a, z, kap, hold, slip = a[ok], z[ok], kap[ok], hold[ok], slip[ok]
        vx, vy, locked, finite, reversed_ = vx[ok], vy[ok], locked[ok], finite[ok], reversed_[ok]
        stopped = _accept(L, rec, a, z, kap, hold, slip, c, carriage_end, params.kappa_cap)
        ended = _end_decided(L, rec, a, stopped, locked, hold, finite, params)
        go = a[~ended]
        left = _step(L, go, vx[~ended], vy[~ended], slip[~ended], reversed_[~ended], params, domain)
        _end(L, rec, left, Outcome.LEFT_DOMAIN)
        # lane sets as masks over the starts: sorted and unique, as the loop takes them
        keep = np.zeros(n, bool)
        keep[go] = True
        keep[left] = False
        stalled = _stalled(L, go, params)
        stalled = stalled[keep[stalled]]
        _end(L, rec, stalled, Outcome.STALLED)
        keep[stalled] = False
        keep[back] = True
        keep |= L.pending > 0
        active = np.flatnonzero(keep)
    offsets, cols = rec.paths(n)
    last = offsets[1:] - 1
    return CompliantResult(
        params=params,
        stiffness=c,
        start_x=xs,
        start_y=ys,
        outcome=L.outcome,
        end_x=cols["x"][last],
        end_y=cols["y"][last],
        n_steps=np.diff(offsets) - 1,
        max_kappa=L.max_k,
        offsets=offsets,
        folds=rec.fold_table(),
        **cols,
    )
