"""Compiled (numba) two-contact rules of the facet streamline; imported on first use.

On MuJoCo's facets nearly every step of a streamline crosses a kink between facets, where
:func:`spine_mj.theory._streamline_numpy.run_numpy` asks the two-contact rules
(:func:`spine_mj.theory.engagement.crease_engagement`,
:func:`spine_mj.theory.multicontact.two_contact_kappa`) about a handful of points. Their numpy
forms spend ~1 ms of call overhead on each such question: measured on a P600 grit case of
four starts, 4.8 of the reference's 11.9 CPU seconds. These kernels answer it point by point
with the same operations in the same order (``tests/theory/test_theory_multicontact.py``
checks them against the numpy forms); the one step they leave out is the friction-cone
feasibility bound of :func:`~spine_mj.theory.multicontact.two_contact_kappa` (a linear
program, where no motion counts), which :func:`two_contact` flags for its caller.
"""

import math

import numpy as np
from numba import njit

__all__ = ["crease", "single_contact", "two_contact", "two_contact_one"]

_SLIP, _ENGAGED, _SELF_LOCK = 0, 1, 2


@njit(cache=True, error_model="numpy")
def _kappa(fx, fy, mu, tol):
    """:func:`spine_mj.theory.engagement.kappa` at one point: ``(kappa, region)``."""
    one_fx2 = 1.0 + fx * fx
    rho = np.sqrt((one_fx2 + fy * fy) / one_fx2)
    w = np.abs(fy) / np.sqrt(one_fx2)
    tg = np.sqrt(mu - w) * np.sqrt(mu + w) / rho
    a_scaled = rho * rho * (1.0 - fx * tg) * (1.0 + fx * tg)
    lock = (fx > 0) and (a_scaled < tol)
    big = tg > 1.0
    inv = 1.0 / tg if big else 1.0
    num = fx * inv + 1.0 if big else fx + tg
    den = inv - fx if big else 1.0 - fx * tg
    engaged = (not lock) and (num > 0) and (den > 0)
    if lock:
        return np.inf, _SELF_LOCK
    if engaged:
        return num / den, _ENGAGED
    return np.nan, _SLIP


@njit(cache=True, error_model="numpy")
def _slip_direction(fx, fy, kv, reg):
    """:func:`spine_mj.theory.engagement.slip_direction` at one point."""
    k = kv if reg == _ENGAGED else 0.0
    s2 = 1.0 + fx * fx + fy * fy
    rn = (k * fx + 1.0) / s2
    tx = k - rn * fx
    ty = -rn * fy
    tz = -1.0 + rn
    norm = np.sqrt(tx * tx + ty * ty + tz * tz)
    bad = (reg == _SELF_LOCK) or not (norm > 0)
    inv = np.nan if bad else 1.0 / norm
    return tx * inv, ty * inv, tz * inv


@njit(cache=True, error_model="numpy")
def _unit_normal(fx, fy):
    s = np.sqrt(1.0 + fx * fx + fy * fy)
    return -fx / s, -fy / s, 1.0 / s


@njit(cache=True, error_model="numpy")
def _normal_of_slopes(fx, fy):
    """:func:`spine_mj.theory.multicontact.normals_of_slopes` at one point (its norm's order)."""
    s = np.sqrt(fx * fx + fy * fy + 1.0)
    return -fx / s, -fy / s, 1.0 / s


@njit(cache=True, error_model="numpy")
def _sign(v):
    if v > 0:
        return 1.0
    if v < 0:
        return -1.0
    return v  # 0 or NaN, as np.sign


@njit(cache=True, error_model="numpy")
def _crease_one(fxa, fya, fxb, fyb, mu, tol):
    """:func:`spine_mj.theory.engagement.crease_engagement` at one pair of contacts:
    ``(kappa, region, vx, vy)``."""
    ax, ay, az = _unit_normal(fxa, fya)
    bx, by, bz = _unit_normal(fxb, fyb)
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    norm = np.sqrt(cx * cx + cy * cy + cz * cz)
    turn = (-1.0 if (cx < 0) or ((cx == 0) and (cy < 0)) else 1.0) / norm
    cx, cy, cz = cx * turn, cy * turn, cz * turn
    d = ax * bx + ay * by + az * bz
    den = 1.0 - d * d
    a0, a1 = (az - d * bz) / den, (-ax + d * bx) / den
    b0, b1 = (bz - d * az) / den, (-bx + d * ax) / den
    s0, s1 = a0 + b0, a1 + b1
    up = cx + mu * s1  # the drive's pull back up the crease per kappa, net of its friction
    fwd = cx - mu * s1
    held_back = (
        (cz > mu * s0) and (up > tol) and ((fwd < tol) or ((cz - mu * s0) / up <= (cz + mu * s0) / fwd))
    )
    if held_back:  # both contacts still pressed at kappa_lo
        k_lo = (cz - mu * s0) / up
        held_back = (a0 + k_lo * a1 >= 0) and (b0 + k_lo * b1 >= 0)
    slides = (np.abs(cz) > mu * s0) and not held_back
    lock = (not slides) and (fwd < tol)
    k = np.nan if (slides or lock) else (cz + mu * s0) / fwd
    k_at = k if np.isfinite(k) else 0.0
    pressed = (a0 + k_at * a1 >= 0) and (b0 + k_at * b1 >= 0)
    pressed = pressed and (np.isfinite(k) or ((a0 >= 0) and (b0 >= 0)))
    h = math.hypot(cx, cy)
    sign = -_sign(cz) if slides else 1.0
    vx, vy = sign * cx / h, sign * cy / h
    valid = pressed and np.isfinite(norm) and (norm > tol) and (h > tol) and (den > tol)
    region = _SLIP if slides else (_SELF_LOCK if lock else _ENGAGED)
    if not valid:
        return np.nan, -1, np.nan, np.nan
    if lock:
        return np.inf, region, np.nan, np.nan
    return k, region, vx, vy


@njit(cache=True, error_model="numpy")
def crease(fxa, fya, fxb, fyb, mu, tol):
    """:func:`~spine_mj.theory.engagement.crease_engagement` on arrays (1-d, one length):
    ``(kappa, region, vx, vy)``."""
    n = fxa.size
    k = np.empty(n)
    reg = np.empty(n, np.int8)
    vx = np.empty(n)
    vy = np.empty(n)
    for i in range(n):
        k[i], reg[i], vx[i], vy[i] = _crease_one(fxa[i], fya[i], fxb[i], fyb[i], mu, tol)
    return k, reg, vx, vy


@njit(cache=True, error_model="numpy")
def _leaves(fx, fy, ox, oy, oz, mu, tol):
    """One contact of a pair alone: ``(kappa, region, leaves)``, ``leaves`` where its slip
    direction does not press into the other contact (normal ``o``)."""
    k, reg = _kappa(fx, fy, mu, tol)
    vx, vy, vz = _slip_direction(fx, fy, k, reg)
    dot = vx * ox + vy * oy + vz * oz
    dot = -1.0 if np.isnan(dot) else dot
    return k, reg, (reg != _SELF_LOCK) and (dot >= -1e-9)


@njit(cache=True, error_model="numpy")
def two_contact_one(fxa, fya, fxb, fyb, mu, tol):
    """:func:`two_contact` at one pair of contacts: ``(kappa, region, bound)`` (for compiled
    callers that step along a path, :mod:`spine_mj.theory._facet_streamline_kernel`)."""
    na = _normal_of_slopes(fxa, fya)
    nb = _normal_of_slopes(fxb, fyb)
    kc, rc, _, _ = _crease_one(fxa, fya, fxb, fyb, mu, tol)
    slides = rc == _SLIP
    onset = (np.inf if rc == _SELF_LOCK else kc) if rc >= 0 else np.nan
    counts = rc >= 0
    for side in range(2):
        fx, fy = (fxa, fya) if side == 0 else (fxb, fyb)
        ox, oy, oz = nb if side == 0 else na
        k, reg, leaves = _leaves(fx, fy, ox, oy, oz, mu, tol)
        slides = slides or (leaves and reg == _SLIP)
        if leaves and reg == _ENGAGED:
            onset = np.fmin(onset, k)
        counts = counts or leaves
    o = np.nan if slides else onset
    region = _SLIP if np.isnan(o) else (_SELF_LOCK if np.isinf(o) else _ENGAGED)
    return o, region, not counts


@njit(cache=True, error_model="numpy")
def two_contact(fxa, fya, fxb, fyb, mu, tol):
    """:func:`~spine_mj.theory.multicontact.two_contact_kappa` on arrays (1-d, one length):
    ``(kappa, region, bound)``, ``bound`` True where no motion counts at its onset and the
    caller owes the friction-cone feasibility bound (kappa and region are then undefined)."""
    n = fxa.size
    out = np.empty(n)
    region = np.empty(n, np.int8)
    bound = np.zeros(n, np.bool_)
    for i in range(n):
        out[i], region[i], bound[i] = two_contact_one(fxa[i], fya[i], fxb[i], fyb[i], mu, tol)
    return out, region, bound


@njit(cache=True, error_model="numpy")
def single_contact(fx, fy, mu, tol):
    """:func:`~spine_mj.theory.engagement.kappa` and the slip direction
    (:func:`~spine_mj.theory.engagement.slip_direction`, a self-locked point's as if it
    slipped) on 1-d arrays: ``(kappa, region, vx, vy)``."""
    n = fx.size
    k = np.empty(n)
    reg = np.empty(n, np.int8)
    vx = np.empty(n)
    vy = np.empty(n)
    for i in range(n):
        k[i], reg[i] = _kappa(fx[i], fy[i], mu, tol)
        r = _SLIP if reg[i] == _SELF_LOCK else reg[i]
        vx[i], vy[i], _ = _slip_direction(fx[i], fy[i], k[i], r)
    return k, reg, vx, vy
