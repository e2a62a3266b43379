"""Engagement ratio kappa of a point spine on a surface z = f(x, y) (paper §2.1, Eqs. 1-3).

Conventions (``docs/physics.md`` §1): drive ``u_x = (1, 0, 0)``, preload ``g = (0, 0, -1)``,
inward normal ``n = (f_x, f_y, -1) / s`` with ``s = sqrt(1 + f_x^2 + f_y^2)``. Per unit
preload the resultant is ``r = kappa u_x + g``; the tip sticks while
``|T| <= mu N`` with ``N = r . n > 0`` and ``T = r - N n``.

Squaring Eq. 1 gives Eq. 2, ``A kappa^2 + B kappa + C = 0``, with (Eq. 3, derived from the
vectors, not copied from the paper's misprinted ``T_w*``)

.. math::

    A = |a|^2 - \\mu^2 n_x^2,\\quad B = 2 (a \\cdot b + \\mu^2 n_x n_z),\\quad
    C = |b|^2 - \\mu^2 n_z^2,

``a = u_x - n_x n``, ``b = g + n_z n``. Since ``|a|^2 = 1 - n_x^2``, ``a . b = n_x n_z`` and
``|b|^2 = 1 - n_z^2``, multiplying by ``s^2 > 0`` leaves the same roots with

.. math::

    A' = 1 + f_y^2 - \\mu^2 f_x^2,\\quad B' = -2 (1 + \\mu^2) f_x,\\quad
    C' = f_x^2 + f_y^2 - \\mu^2 ,

which is what :func:`kappa` evaluates.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError

__all__ = [
    "ENGAGED",
    "REGION_NAMES",
    "SELF_LOCK",
    "SLIP",
    "crease_engagement",
    "kappa",
    "kappa_grid",
    "kappa_of_normal",
    "quadratic_coefficients",
    "slip_direction",
]

#: Region codes returned by :func:`kappa` (paper Fig. 2C).
SLIP = 0
ENGAGED = 1
SELF_LOCK = 2
REGION_NAMES = {SLIP: "slip", ENGAGED: "engaged", SELF_LOCK: "self_lock"}

#: The force cap both sides of a MuJoCo-vs-streamline comparison share (docs/physics.md §4):
#: a drive that needs more than ``DEFAULT_KAPPA_CAP`` times the normal load counts as held,
#: on the engine (:class:`spine_mj.sim.Detection`) and on the streamline
#: (:class:`spine_mj.theory.streamline_types.StreamlineParams` ``kappa_cap``) alike. A safety net for what
#: the self-lock region does not catch: a tip wedged between facets, a path of near-infinite
#: kappa.
DEFAULT_KAPPA_CAP = 20.0

#: Default tolerance on the scaled leading coefficient ``A'`` (dimensionless, O(1)).
DEFAULT_TOL = 1e-12


def _check_mu(mu) -> float:
    try:
        mu = float(mu)
    except (TypeError, ValueError):
        raise SpineInputError(f"mu (static friction coefficient) must be a number, got {mu!r}") from None
    if not (math.isfinite(mu) and mu > 0):
        raise SpineInputError(f"mu (static friction coefficient) must be finite and > 0, got {mu!r}")
    return mu


def quadratic_coefficients(fx, fy, mu) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients ``(A', B', C')`` of Eq. 2 scaled by ``1 + f_x^2 + f_y^2`` (see module).

    Parameters
    ----------
    fx, fy : array_like
        Surface slopes, broadcast together.
    mu : float
        Static friction coefficient mu_s > 0.
    """
    mu = _check_mu(mu)
    fx = np.asarray(fx, dtype=float)
    fy = np.asarray(fy, dtype=float)
    m2 = mu * mu
    return 1.0 + fy * fy - m2 * fx * fx, -2.0 * (1.0 + m2) * fx, fx * fx + fy * fy - m2


def kappa(fx, fy, mu, *, tol: float = DEFAULT_TOL) -> tuple[np.ndarray, np.ndarray]:
    """Engagement ratio kappa = F_c / W and region at points with slopes ``(fx, fy)``.

    Regions (paper Fig. 2C, ``docs/physics.md`` §1):

    * ``SELF_LOCK`` (2): ``A' < tol`` and ``f_x > 0`` - the drive direction lies inside the
      friction cone and pushes into the surface; ``kappa = +inf``.
    * ``ENGAGED`` (1): a root ``kappa > 0`` of Eq. 2 with ``N > 0`` there (``1 + kappa f_x
      > 0``); kappa is the larger such root, the force at which the hold breaks.
    * ``SLIP`` (0): neither; gravity alone slides the tip; ``kappa = NaN``.

    The larger root is evaluated in closed form, not from the quadratic formula, whose
    discriminant cancels (and whose ``mu^2`` overflows) at large mu: writing the drive
    direction ``r`` at angle ``psi`` from the vertical, the tip sticks for
    ``|psi - theta| <= gamma`` with ``tan theta = f_x`` and
    ``tan gamma = sqrt(mu^2 - w^2) / rho``, ``w = |f_y| / sqrt(1 + f_x^2)``,
    ``rho = sqrt(1 + f_y^2 / (1 + f_x^2))``, so ``kappa = tan(theta + gamma)`` (the 2-D
    closed form ``tan(theta + arctan mu)`` when ``f_y = 0``) and
    ``A' = rho^2 (1 - f_x tan gamma)(1 + f_x tan gamma)``, which decides the self-lock
    without forming ``mu^2``. Right for any finite mu.

    Parameters
    ----------
    fx, fy : array_like
        Slopes ``df/dx``, ``df/dy`` (dimensionless), broadcast together to shape ``S``.
    mu : float
        Static friction coefficient mu_s > 0.
    tol : float
        Tolerance on ``A'`` (dimensionless); points with ``|A'| < tol`` count as on the
        self-lock boundary (self-locked if ``f_x > 0``, linear equation otherwise).

    Returns
    -------
    kappa : ndarray, shape S
        ``F_c / W`` (dimensionless); ``+inf`` where self-locked, NaN where slipping.
    region : ndarray of int8, shape S
        ``SLIP``, ``ENGAGED`` or ``SELF_LOCK``.

    Raises
    ------
    SpineInputError
        If ``mu`` is not a finite number > 0 or ``tol`` is negative.

    Examples
    --------
    Flat ground gives ``kappa = mu``; a 2-D slope of angle theta gives
    ``tan(theta + arctan(mu))``:

    >>> k, r = kappa([0.0, math.tan(0.2)], 0.0, 0.5)
    >>> bool(np.allclose(k, [0.5, math.tan(0.2 + math.atan(0.5))]))
    True
    """
    mu = _check_mu(mu)
    tol = float(tol)
    if not (tol >= 0):
        raise SpineInputError(f"tol must be >= 0, got {tol!r}")
    fx, fy = np.broadcast_arrays(np.asarray(fx, dtype=float), np.asarray(fy, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        one_fx2 = 1.0 + fx * fx
        rho = np.sqrt((one_fx2 + fy * fy) / one_fx2)
        w = np.abs(fy) / np.sqrt(one_fx2)
        # tan(gamma), the cone's half-width in the drive plane; no cone (NaN) where w > mu
        tg = np.sqrt(mu - w) * np.sqrt(mu + w) / rho
        a_scaled = rho * rho * (1.0 - fx * tg) * (1.0 + fx * tg)  # = A' (see kappa docs)
        lock = (fx > 0) & (a_scaled < tol)
        # tan(theta + gamma), divided through by tg where tg > 1 so that nothing overflows
        big = tg > 1.0
        inv = np.where(big, 1.0 / np.where(big, tg, 1.0), 1.0)
        num = np.where(big, fx * inv + 1.0, fx + tg)
        den = np.where(big, inv - fx, 1.0 - fx * tg)
        engaged = ~lock & (num > 0) & (den > 0)
        k = np.where(engaged, num / np.where(engaged, den, 1.0), np.nan)
    region = np.where(lock, SELF_LOCK, np.where(engaged, ENGAGED, SLIP)).astype(np.int8)
    k = np.where(lock, np.inf, k)
    return k, region


def kappa_grid(surface, mu, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """kappa and the region over ``n x n`` points spanning ``surface.bounds`` (Fig. 2B).

    Returns
    -------
    xs, ys : ndarray, shape (n,)
        The grid's x and y.
    heights, kappa, region : ndarray, shape (n, n)
        Indexed ``[iy, ix]``, as :func:`kappa` gives them from the surface's gradient.
    """
    xmin, xmax, ymin, ymax = surface.bounds
    xs = np.linspace(xmin, xmax, n)
    ys = np.linspace(ymin, ymax, n)
    _, fx, fy = surface.evaluate(xs[None, :], ys[:, None], order=1)
    k, region = kappa(fx, fy, mu)
    return xs, ys, surface.height(xs[None, :], ys[:, None]), k, region


def kappa_of_normal(normal, mu, *, tol: float = DEFAULT_TOL) -> tuple[np.ndarray, np.ndarray]:
    """:func:`kappa` and region for contact normals instead of slopes.

    The one lock rule both sides of a comparison use: the quasistatic streamline evaluates
    :func:`kappa` at the surface's slope; a MuJoCo contact reports the normal of the facet
    it touches, pointing out of the solid (``n_out = (-f_x, -f_y, 1) / s``, the opposite of
    the paper's inward normal), which this converts to slopes ``f_x = -n_x / n_z``,
    ``f_y = -n_y / n_z``. A normal with ``n_z <= 0`` (a wall or an overhang: no height
    function) is self-locked when it faces the drive (``n_x < 0``), else slip.

    Parameters
    ----------
    normal : array_like, shape (..., 3)
        Outward unit (or any positive length) contact normals.
    mu, tol
        As in :func:`kappa`.

    Returns
    -------
    kappa, region : ndarray, shape (...)
    """
    n = np.asarray(normal, dtype=float)
    if n.ndim == 0 or n.shape[-1] != 3:
        raise SpineInputError(f"normal must have shape (..., 3), got {n.shape}")
    nx, ny, nz = n[..., 0], n[..., 1], n[..., 2]
    up = nz > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        fx = np.where(up, -nx / np.where(up, nz, 1.0), 0.0)
        fy = np.where(up, -ny / np.where(up, nz, 1.0), 0.0)
    k, region = kappa(fx, fy, mu, tol=tol)
    wall_lock = ~up & (nx < 0)
    region = np.where(up, region, np.where(wall_lock, SELF_LOCK, SLIP)).astype(np.int8)
    k = np.where(up, k, np.where(wall_lock, np.inf, np.nan))
    return k, region


def crease_engagement(fx_a, fy_a, fx_b, fy_b, mu, *, tol: float = DEFAULT_TOL):
    """Engagement of a tip resting on two contacts at once, in a concave crease between
    surfaces of slopes ``(fx_a, fy_a)`` and ``(fx_b, fy_b)``: what the single-contact
    :func:`kappa` cannot describe (beyond the paper, docs/physics.md §4, Creases).

    The tip can only move along the crease, ``c = n_a x n_b`` (unit, turned to the drive:
    ``c_x >= 0``). Under ``F = W (kappa e_x - e_z)`` the normal forces balance the part of
    F across the crease, ``N_a n_a + N_b n_b = -(F - (F.c) c)``, each linear in kappa; the
    friction of both contacts, at most ``mu (N_a + N_b)``, opposes the part along it,
    ``F.c = W (kappa c_x - c_z)``. A V-groove of flank angle theta along the drive gives
    the wedge's ``kappa = mu / cos(theta)``. A crease that rises along the drive more
    steeply than friction holds (``c_z > mu s0``) would let gravity alone slide the tip back
    down it; the drive holds it there from ``kappa_lo = (c_z - mu s0) / (c_x + mu s1)`` on,
    as it holds a tip on a single wall steeper than friction (:func:`kappa`), and the tip
    moves on up the crease at the usual onset: a V-groove of flank angle theta whose axis
    rises at beta gives ``kappa = tan(beta + arctan(mu / cos(theta)))``. Only where no drive
    holds it (``c_x + mu s1 <= 0``), or where a contact has lifted off by ``kappa_lo`` (a
    nearly flat crease across the drive, whose hold would need a squeeze the tip's weight
    cannot give), does it slide back.

    Returns
    -------
    kappa : ndarray
        The drive at which the tip slides along the crease (``ENGAGED``); ``+inf`` where no
        drive can (``SELF_LOCK``); NaN where gravity slides it along whatever the drive
        (``SLIP``) or where the two-contact state does not hold (a normal force would be negative, the
        crease is vertical or the contacts are parallel: ``region`` -1).
    region : ndarray of int8
        ``SLIP``, ``ENGAGED``, ``SELF_LOCK``, or -1 (no two-contact state).
    vx, vy : ndarray
        Unit horizontal direction of motion along the crease (NaN where held or none).
    """
    mu = _check_mu(mu)

    def unit_normal(fx, fy):
        fx, fy = np.asarray(fx, dtype=float), np.asarray(fy, dtype=float)
        s = np.sqrt(1.0 + fx * fx + fy * fy)
        return -fx / s, -fy / s, 1.0 / s

    ax, ay, az = unit_normal(fx_a, fy_a)
    bx, by, bz = unit_normal(fx_b, fy_b)
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    with np.errstate(divide="ignore", invalid="ignore"):
        norm = np.sqrt(cx * cx + cy * cy + cz * cz)
        turn = np.where((cx < 0) | ((cx == 0) & (cy < 0)), -1.0, 1.0) / norm
        cx, cy, cz = cx * turn, cy * turn, cz * turn
        d = ax * bx + ay * by + az * bz
        den = 1.0 - d * d
        a0, a1 = (az - d * bz) / den, (-ax + d * bx) / den
        b0, b1 = (bz - d * az) / den, (-bx + d * ax) / den
        s0, s1 = a0 + b0, a1 + b1
        # gravity alone slides the tip along the crease, unless it slides it back against
        # the drive, which holds it there from kappa_lo = (c_z - mu s0) / (c_x + mu s1) on
        up, fwd = cx + mu * s1, cx - mu * s1
        held_back = (cz > mu * s0) & (up > tol)
        held_back &= (fwd < tol) | ((cz - mu * s0) / up <= (cz + mu * s0) / fwd)
        # ... with both contacts still pressed at kappa_lo: across a nearly flat crease the
        # drive lifts the tip off one side long before its friction could hold it there
        k_lo = (cz - mu * s0) / up
        held_back &= (a0 + k_lo * a1 >= 0) & (b0 + k_lo * b1 >= 0)
        slides = (np.abs(cz) > mu * s0) & ~held_back
        lock = ~slides & (fwd < tol)
        k = np.where(slides | lock, np.nan, (cz + mu * s0) / fwd)
        # both contacts pressed where the tip slides (a contact that gravity alone leaves
        # unloaded, a wall beside a flat floor, is pressed by the drive); held or sliding
        # under gravity alone: pressed without drive
        k_at = np.where(np.isfinite(k), k, 0.0)
        pressed = (a0 + k_at * a1 >= 0) & (b0 + k_at * b1 >= 0)
        pressed &= np.isfinite(k) | ((a0 >= 0) & (b0 >= 0))
        h = np.hypot(cx, cy)
        sign = np.where(slides, -np.sign(cz), 1.0)
        vx, vy = sign * cx / h, sign * cy / h
        valid = pressed & np.isfinite(norm) & (norm > tol) & (h > tol) & (den > tol)
    region = np.where(slides, SLIP, np.where(lock, SELF_LOCK, ENGAGED)).astype(np.int8)
    region = np.where(valid, region, -1).astype(np.int8)
    k = np.where(valid & lock, np.inf, np.where(valid, k, np.nan))
    moving = valid & ~lock
    return k, region, np.where(moving, vx, np.nan), np.where(moving, vy, np.nan)


def slip_direction(fx, fy, kappa_value, region) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit tangential slip direction ``v = T / |T|`` (paper §2.2).

    ``T = r - (r . n) n`` with ``r = kappa u_x + g`` where engaged and ``r = g`` where
    slipping. Self-locked points get NaN (the tip does not move).

    Parameters
    ----------
    fx, fy, kappa_value, region : array_like, broadcast to shape S
        Slopes, engagement ratio and region from :func:`kappa`.

    Returns
    -------
    vx, vy, vz : ndarray, shape S
        Components of ``v``; NaN where self-locked or where ``|T| = 0``.
    """
    fx, fy, kv, reg = np.broadcast_arrays(
        np.asarray(fx, dtype=float),
        np.asarray(fy, dtype=float),
        np.asarray(kappa_value, dtype=float),
        np.asarray(region),
    )
    k = np.where(reg == ENGAGED, kv, 0.0)
    s2 = 1.0 + fx * fx + fy * fy
    rn = (k * fx + 1.0) / s2
    tx = k - rn * fx
    ty = -rn * fy
    tz = -1.0 + rn
    norm = np.sqrt(tx * tx + ty * ty + tz * tz)
    with np.errstate(invalid="ignore", divide="ignore"):
        bad = (reg == SELF_LOCK) | ~(norm > 0)
        inv = np.where(bad, np.nan, 1.0 / norm)
    return tx * inv, ty * inv, tz * inv
