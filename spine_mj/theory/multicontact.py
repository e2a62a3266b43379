"""The multi-contact quasistatic lock: a tip resting on several facets at once holds while
the drive and the preload can be balanced by contact forces inside every friction cone.

The single-contact rule (:func:`spine_mj.theory.engagement.kappa`) cannot describe a tip wedged in a
concave crease or a pocket of MuJoCo's facets: on each facet alone the slip direction points
into the other, and the pair holds like one contact of a larger friction (the wedge effect,
:func:`wedge_kappa`). Per unit preload the load on the tip is ``F = kappa e_x - e_z``
(drive along +x, preload down, no lateral drive: the streamline's convention,
docs/physics.md §1); contact ``i`` of outward unit normal ``n_i`` pushes with
``f_i = N_i n_i + t_i``, ``t_i . n_i = 0``, ``|t_i| <= mu N_i``. The tip holds at ``kappa``
iff ``sum_i f_i = -F`` has such a solution; the set of such kappa is an interval (the
cones are convex), and :func:`hold_kappa` returns its upper end: the drive at which the
tip starts to move, by whatever motion (along the crease, or lifting off a facet).

The problem is a small linear program on polyhedral cones: each circular cone is replaced by
the pyramid inscribed in it with :data:`CONE_SIDES` edges (scipy's HiGHS). The inscribed
pyramid is a cone of friction between ``mu cos(pi / sides)`` and ``mu``, so the kappa it
returns is a lower bound on the exact one, as close as ``mu`` and ``mu cos(pi / sides)``
make it (``sides = 64``: 0.12 % of mu). It is exact and general (any number of contacts,
any directions) where a closed form for two contacts would have to enumerate the motions
(slide along the crease with both pressed, or lift off one): the linear program's dual
does that enumeration.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.theory.engagement import ENGAGED, SELF_LOCK, SLIP, crease_engagement, kappa, slip_direction

__all__ = [
    "CONE_SIDES",
    "hold_kappa",
    "normals_of_slopes",
    "two_contact_kappa",
    "wedge_kappa",
    "wedge_normals",
]

#: Edges of the pyramid inscribed in each friction cone (:func:`hold_kappa`).
CONE_SIDES = 64


def normals_of_slopes(fx, fy) -> np.ndarray:
    """Outward unit normals ``(-f_x, -f_y, 1) / s`` of contacts of slopes ``(fx, fy)``,
    shape ``(..., 3)``."""
    fx, fy = np.broadcast_arrays(np.asarray(fx, float), np.asarray(fy, float))
    n = np.stack([-fx, -fy, np.ones_like(fx)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _pyramid(normal: np.ndarray, mu: float, sides: int) -> np.ndarray:
    """The ``(3, sides)`` edges of the pyramid inscribed in the friction cone of ``normal``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(normal, helper)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(normal, t1)
    a = 2.0 * np.pi * np.arange(sides) / sides
    return normal[:, None] + mu * (np.cos(a)[None, :] * t1[:, None] + np.sin(a)[None, :] * t2[:, None])


def hold_kappa(normals, mu: float, *, sides: int = CONE_SIDES) -> float:
    """The largest drive ``kappa = F / W`` the contacts of ``normals`` hold (see the module).

    Parameters
    ----------
    normals : array_like, shape (m, 3) or (3,)
        Outward unit normals of the contacts the tip rests on (m >= 1), as
        :func:`normals_of_slopes` gives them; a normal pointing down is no support.
    mu : float
        Friction coefficient of every contact, >= 0.
    sides : int
        Edges of each inscribed friction pyramid, >= 3.

    Returns
    -------
    float
        ``inf`` where every drive is held (self-lock), NaN where even no drive is (the
        preload alone slides the tip: the slip region), else the drive at which it moves.
        With one contact: :func:`spine_mj.theory.engagement.kappa` (to the pyramid's accuracy).

    Raises
    ------
    SpineInputError
        Wrong shapes, non-finite or zero normals, ``mu < 0`` or ``sides < 3``.
    """
    from scipy.optimize import linprog

    n = np.atleast_2d(np.asarray(normals, dtype=float))
    if n.ndim != 2 or n.shape[1] != 3 or n.shape[0] == 0:
        raise SpineInputError(f"normals must have shape (m, 3) with m >= 1, got shape {n.shape}")
    norm = np.linalg.norm(n, axis=1)
    if not (np.all(np.isfinite(n)) and np.all(norm > 0)):
        raise SpineInputError("normals must be finite and non-zero")
    if not (math.isfinite(mu) and mu >= 0):
        raise SpineInputError(f"mu must be a finite number >= 0, got {mu!r}")
    if int(sides) != sides or sides < 3:
        raise SpineInputError(f"sides must be an integer >= 3, got {sides!r}")
    n = n / norm[:, None]
    edges = np.hstack([_pyramid(v, float(mu), int(sides)) for v in n])
    # unknowns: the edges' weights (>= 0), then kappa (>= 0); sum f_i + kappa e_x = e_z
    a_eq = np.hstack([edges, np.array([[1.0], [0.0], [0.0]])])
    cost = np.zeros(a_eq.shape[1])
    cost[-1] = -1.0
    res = linprog(cost, A_eq=a_eq, b_eq=np.array([0.0, 0.0, 1.0]), bounds=(0, None), method="highs")
    if res.status == 3:
        return math.inf
    if res.status == 2:
        return math.nan
    if res.status != 0:  # pragma: no cover - HiGHS iteration limits on a 3-row problem
        raise RuntimeError(f"hold_kappa: linear program failed ({res.message})")
    return float(res.x[-1])


def wedge_kappa(theta, alpha, mu):
    """Closed form of a tip wedged in a V-groove running along the drive (docs/physics.md §4).

    The groove rises at ``theta`` along +x; its two flanks' normals tilt by ``alpha`` from
    the groove floor's normal, to either side. The two contacts carry the load across the
    groove with normal forces summing to that load over ``cos(alpha)``, so the pair holds
    like one contact of friction ``mu / cos(alpha)``:
    ``kappa = tan(theta + arctan(mu / cos(alpha)))``, ``inf`` (self-lock) once
    ``theta + arctan(mu / cos(alpha)) >= pi / 2``. A single-contact rule gives ``mu``
    instead of ``mu / cos(alpha)``.

    Parameters
    ----------
    theta, alpha : array_like
        Rise of the groove and tilt of its flanks [rad], ``|theta| < pi / 2``,
        ``0 <= alpha < pi / 2``.
    mu : float
        Friction coefficient, >= 0.
    """
    theta, alpha = np.asarray(theta, float), np.asarray(alpha, float)
    angle = theta + np.arctan(mu / np.cos(alpha))
    with np.errstate(over="ignore"):
        return np.where(angle >= np.pi / 2, np.inf, np.tan(np.minimum(angle, np.pi / 2)))


def wedge_normals(theta: float, alpha: float) -> np.ndarray:
    """The ``(2, 3)`` outward normals of the flanks of :func:`wedge_kappa`'s V-groove: the
    floor's normal ``(-sin theta, 0, cos theta)`` turned by ``+-alpha`` about the groove."""
    floor = np.array([-math.sin(theta), 0.0, math.cos(theta)])
    side = np.array([0.0, 1.0, 0.0])
    return np.array([math.cos(alpha) * floor + s * math.sin(alpha) * side for s in (1.0, -1.0)])


def two_contact_kappa(fx_a, fy_a, fx_b, fy_b, mu) -> tuple[np.ndarray, np.ndarray]:
    """The drive at which a tip resting on two contacts (slopes ``a`` and ``b``) moves.

    Each way the tip can move is tried at its own onset drive: sliding along the crease with
    both contacts pressed (:func:`spine_mj.theory.engagement.crease_engagement`), or sliding on one
    contact alone (:func:`spine_mj.theory.engagement.kappa` and its slip direction), which only
    counts where that direction leaves the other contact (does not press into it). The tip
    moves at the smallest onset drive of the motions that count. The normal forces are those
    the load itself presses, with no squeeze between the contacts: what MuJoCo's contacts
    do, and what gives the V-groove's closed form :func:`wedge_kappa` (the bare friction-cone
    feasibility, :func:`hold_kappa`, lets a squeeze raise the friction: measured on a V-groove
    of theta 0.3, alpha 0.8, mu 0.7, MuJoCo's static probe broke away at 1.906 F_p, the
    closed form gives 1.907, the feasibility 3.18). Where no motion counts at its onset, the
    feasibility's kappa is the bound: the tip holds at least up to the smallest onset drive,
    and at most up to that bound. Where gravity slides the tip down the crease whatever the
    drive, that comes first (slip; :func:`~spine_mj.theory.engagement.crease_engagement`: up a
    crease steeper than friction the drive holds it, as on one steep wall).

    Parameters
    ----------
    fx_a, fy_a, fx_b, fy_b : array_like, broadcast to shape S
        Slopes of the two contacts.
    mu : float
        Friction coefficient, >= 0.

    Returns
    -------
    kappa : ndarray, shape S
        The drive over the preload at which the tip moves; ``inf`` where it never does
        (self-lock); NaN where the preload alone slides it.
    region : ndarray of int8, shape S
        ``SLIP``, ``ENGAGED`` or ``SELF_LOCK`` (:mod:`spine_mj.theory.engagement`).
    """
    fx_a, fy_a, fx_b, fy_b = np.broadcast_arrays(*(np.asarray(v, float) for v in (fx_a, fy_a, fx_b, fy_b)))
    na, nb = normals_of_slopes(fx_a, fy_a), normals_of_slopes(fx_b, fy_b)
    kc, rc, _, _ = crease_engagement(fx_a, fy_a, fx_b, fy_b, mu)
    slides = rc == SLIP
    onset = np.where(rc >= 0, np.where(rc == SELF_LOCK, np.inf, kc), np.nan)
    counts = rc >= 0
    for (fx, fy), other in (((fx_a, fy_a), nb), ((fx_b, fy_b), na)):
        k, reg = kappa(fx, fy, mu)
        v = np.stack(slip_direction(fx, fy, k, reg), axis=-1)
        with np.errstate(invalid="ignore"):
            leaves = (reg != SELF_LOCK) & (np.nan_to_num(np.sum(v * other, axis=-1), nan=-1.0) >= -1e-9)
        slides |= leaves & (reg == SLIP)
        onset = np.where(leaves & (reg == ENGAGED), np.fmin(onset, k), onset)
        counts |= leaves
    out = np.where(slides, np.nan, onset)
    for i in np.ndindex(out.shape):  # no motion counts: the feasibility bound
        if not counts[i]:
            out[i] = hold_kappa(np.array([na[i], nb[i]]), float(mu))
    region = np.where(np.isnan(out), SLIP, np.where(np.isinf(out), SELF_LOCK, ENGAGED)).astype(np.int8)
    return out, region
