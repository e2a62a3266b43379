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
one core, :mod:`spine_mj.theory._kernels`; and for a compiled
:class:`~spine_mj.surfaces.BallOnFacets`, the engine's own contact, with the crease rules of
the reference, :mod:`spine_mj.theory._facet_streamline_kernel`) and ``"numpy"`` (a plain loop
over steps, vectorized over starts, for any :class:`~spine_mj.surfaces.Surface`,
:mod:`spine_mj.theory._streamline_numpy`; the reference the tests check the kernels
against). The records (:class:`Outcome`, :class:`StreamlineParams`,
:class:`StreamlineResult`) live in :mod:`spine_mj.theory.streamline_types`; this module
holds the entry points.

A finite tip of radius R rides with its centre on the surface dilated by a ball of radius
R: :func:`~spine_mj.surfaces.dilation.dilate` builds that surface, on
which the same streamline rules apply.
"""

from __future__ import annotations

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import BallOnFacets, GaussianSurface, GridSurface, Surface
from spine_mj.theory._kernels import run_trajectories
from spine_mj.theory._streamline_numpy import CREASE_KINK, _two_contact_kappa, run_numpy
from spine_mj.theory.engagement import DEFAULT_TOL
from spine_mj.theory.streamline_types import StreamlineParams, StreamlineResult

__all__ = [
    "DEFAULT_STEP_FRACTION",
    "check_step",
    "default_step",
    "ideal_trajectories",
    "start_points",
    "streamlines",
]


_KIND_GAUSS = 0
_KIND_GRID = 1
_LANES = 32  # starts the kernel steps together (one core, 2,000 starts: 8 -> 4.3e7 steps/s, 32 -> 6.5e7)


def _get_kernel():

    return run_trajectories


def _readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a``: the kernel's grid argument is read-only for every surface
    (a GridSurface's spline coefficients are), so that Gaussians and grids share one
    compiled signature (a writable dummy cost a second compile, ~16 CPU-s cold)."""
    v = a.view()
    v.flags.writeable = False
    return v


def _surface_data(surface: Surface):
    dummy_g = np.zeros((5, 0))
    dummy_coef = _readonly(np.zeros((1, 1)))
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
        return _KIND_GRID, dummy_g, _readonly(np.ascontiguousarray(s.coef)), sp
    return None


# --------------------------------------------------------------------------- public API


def start_points(surface: Surface, starts) -> tuple[np.ndarray, np.ndarray]:
    """``starts`` (shape ``(n, 2)``, or one pair) as contiguous ``x`` and ``y`` arrays, or
    SpineInputError: not ``n >= 1`` pairs, not finite, or outside ``surface.bounds``."""
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
    xs, ys = start_points(surface, starts)
    check_step(surface, params.dl)
    data = _surface_data(surface)
    facets = isinstance(surface, BallOnFacets) and surface.compiled
    if backend == "numba" and data is None and not facets:
        raise SpineInputError(
            "backend 'numba' supports GaussianSurface, GridSurface and compiled BallOnFacets, "
            f"got {type(surface).__name__}"
        )
    if backend != "numpy" and facets:
        out = _run_facets(surface, xs, ys, params, ideal=ideal, store=store_paths)
    elif backend == "numpy" or data is None:
        out = run_numpy(surface, xs, ys, params, ideal=ideal, store=store_paths)
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


def _run_facets(surface: BallOnFacets, xs, ys, params, *, ideal, store):
    """:func:`run_numpy`'s outputs on a compiled ball on facets from the compiled walk
    (:mod:`spine_mj.theory._facet_streamline_kernel`); the wedges where only the friction-cone
    bound decides are answered here by the reference's rule (:func:`_two_contact_kappa`)."""
    from spine_mj.theory import _facet_streamline_kernel as fk

    st = fk.new_state(xs, ys, float(params.dl), int(params.stall_window))
    outcome = np.zeros(xs.size, np.int8)
    ask = np.zeros((xs.size, 4))
    pieces = []
    while True:
        pieces.append(
            fk.run_facets(
                *surface.kernel_args(),
                np.asarray(params.domain(surface), dtype=float),
                st,
                outcome,
                ask,
                bool(ideal),
                float(params.mu),
                float(params.dl),
                float(params.tol),
                DEFAULT_TOL,
                CREASE_KINK,
                int(params.max_steps),
                int(params.stall_window),
                float(params.stall_distance_value),
                bool(store),
                float(params.kappa_cap),
                int(params.max_halvings),
            )
        )
        paused = np.flatnonzero(outcome == fk.PAUSED)
        if not paused.size:
            break
        k, region = _two_contact_kappa(*ask[paused].T, float(params.mu))
        st[paused, fk.ANSWER] = np.c_[np.ones(paused.size), k, region]
    n_steps = st[:, fk.STEPS].astype(np.int64)
    fields = (st[:, c].copy() for c in (fk.MAX_KAPPA, fk.X, fk.Y, fk.HEIGHT))
    offsets = np.zeros(xs.size + 1, np.int64)
    if not store:
        empty = np.empty(0)
        return outcome, n_steps, *fields, offsets, empty, empty, empty, empty, np.empty(0, np.int8)
    start, *cols = (np.concatenate(c) for c in zip(*pieces, strict=True))
    order = np.argsort(start, kind="stable")  # each start's points stay in path order
    offsets[1:] = np.cumsum(np.bincount(start, minlength=xs.size))
    return outcome, n_steps, *fields, offsets, *(c[order] for c in cols)


#: The step of a streamline given no ``dl``, as a fraction of the domain's shorter side.
DEFAULT_STEP_FRACTION = 1e-3


def default_step(surface: Surface) -> float:
    """The streamline step ``dl`` when none is given: :data:`DEFAULT_STEP_FRACTION` of the
    shorter side of ``surface.bounds`` (surface units). The one default of ``spine-mj
    streamline``, the sweep's ``quasistatic`` analysis and the streamline drawn beside a
    MuJoCo run. The shorter side, because a path turns on the scale of the domain's width
    as well as its length: on a long strip a thousandth of its length could be as coarse as
    its features (and a strip 1000 times longer than wide would leave at the first step).

    Parameters
    ----------
    surface : Surface
        The surface traced.

    Returns
    -------
    float
    """
    xmin, xmax, ymin, ymax = surface.bounds
    return DEFAULT_STEP_FRACTION * min(xmax - xmin, ymax - ymin)


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
