"""Compiled (numba) facet streamline: :func:`spine_mj.theory._streamline_numpy.run_numpy` on a
compiled :class:`~spine_mj.surfaces.BallOnFacets`, start by start; imported on first use.

The numpy reference steps every start together and pays numpy's per-call overhead on a
handful of points at each of the ~1e4 steps of a grit path (the compare analysis of the
quick plan's sandpaper spent ~90 CPU-s there). This kernel walks one start at a time with
the same rules in the same order: the ball's height and contact slopes
(:func:`spine_mj.surfaces._contact_kernel.ball_at`), the single-contact kappa and slip
direction, the step-size control, a concave crease crossed and held on two contacts
(``_wedged``), a crease followed on two contacts (``_on_crease``), the endings and the
progress checks. The one rule it leaves out is the friction-cone feasibility bound of
:func:`spine_mj.theory.multicontact.two_contact_kappa` (a linear program, where no motion
counts at a wedge): a start that meets it pauses with its question (the two contacts'
slopes), its caller answers with the reference's linear program and calls again, and the
start resumes at the same point (whose height and slopes it computes again, the same
numbers). ``tests/theory/test_theory_streamline.py`` checks the kernel against the reference.
"""

import math

import numpy as np
from numba import njit

from spine_mj.surfaces._contact_kernel import ball_at
from spine_mj.theory._multicontact_kernel import _crease_one, _kappa, _slip_direction, two_contact_one

__all__ = ["ANSWER", "HEIGHT", "MAX_KAPPA", "PAUSED", "STEPS", "X", "Y", "new_state", "run_facets"]

_SLIP, _ENGAGED, _SELF_LOCK = 0, 1, 2
_SELF_LOCKED, _LEFT_DOMAIN, _STALLED, _STEP_CAP, _FORCE_CAP = 1, 2, 3, 4, 5
#: The outcome of a start paused on a question (see the module)
PAUSED = -1
# a start's state between calls: one row of floats
(
    _X,
    _Y,
    _CX,
    _CY,
    _H,
    _PX,
    _PY,
    _PVX,
    _PVY,
    _PFX,
    _PFY,
    _S0,
    _S1,
    _S2,
    _S3,
    _IN_CREASE,
    _HAS_PREV,
    _ARC,
    _UNTIL,
    _STALL,
    _STEPS,
    _MK,
    _EZ,
    _ANSWERED,
    _ANS_K,
    _ANS_R,
) = range(26)
_STATE = 26
#: Columns of the state a caller reads (position, steps, largest kappa, last height) and
#: writes (the answer to a start's question: set, kappa, region)
X, Y, STEPS, MAX_KAPPA, HEIGHT, ANSWER = _X, _Y, _STEPS, _MK, _EZ, slice(_ANSWERED, _ANS_R + 1)


def new_state(xs, ys, dl, stall_window):
    """The state rows of fresh starts at ``xs``, ``ys`` (a full step, nothing behind them)."""
    st = np.zeros((xs.size, _STATE))
    st[:, _X], st[:, _Y], st[:, _CX], st[:, _CY] = xs, ys, xs, ys
    st[:, _H] = dl
    st[:, _PX], st[:, _PY] = xs, ys
    st[:, _S0 : _S3 + 1] = np.nan
    st[:, _UNTIL] = stall_window
    st[:, _MK] = np.nan
    st[:, _EZ] = np.nan
    return st


@njit(cache=True, error_model="numpy")
def _grow(a, cap):
    b = np.empty(cap, a.dtype)
    b[: a.size] = a
    return b


@njit(cache=True, error_model="numpy")
def run_facets(
    h,
    x0,
    y0,
    dx,
    dy,
    radius,
    bounds,
    st,
    outcome,
    ask,
    ideal,
    mu,
    dl,
    tol,
    crease_tol,
    crease_kink,
    max_steps,
    stall_window,
    stall_dist,
    store,
    kappa_cap,
    max_halvings,
):
    """Walk every start whose ``outcome`` is 0 or :data:`PAUSED` (answered: its state row's
    answer set) on from its state row ``st`` (:func:`new_state`) until it ends (``outcome``
    its :class:`~spine_mj.theory.streamline_types.Outcome`) or pauses on a question (``ask``
    its row: the last accepted point's slopes, then the current ones). Returns the accepted
    points of this call ``(start, x, y, z, kappa, region)``, each start's in path order."""
    n = outcome.size
    cap = 1024 if store else 0
    bi = np.empty(cap, np.int64)
    bx = np.empty(cap)
    by = np.empty(cap)
    bz = np.empty(cap)
    bk = np.empty(cap)
    br = np.empty(cap, np.int8)
    pos = 0
    xmin, xmax, ymin, ymax = bounds[0], bounds[1], bounds[2], bounds[3]
    h_min = dl / 2.0**max_halvings
    sides = np.empty(4)
    for s in range(n):
        if outcome[s] > 0:
            continue
        r = st[s]
        x, y, cx, cy, hs = r[_X], r[_Y], r[_CX], r[_CY], r[_H]
        px, py, pvx, pvy, pfx, pfy = r[_PX], r[_PY], r[_PVX], r[_PVY], r[_PFX], r[_PFY]
        sides[0], sides[1], sides[2], sides[3] = r[_S0], r[_S1], r[_S2], r[_S3]
        in_crease = r[_IN_CREASE] != 0.0
        has_prev = r[_HAS_PREV] != 0.0
        arc = r[_ARC]
        until = int(r[_UNTIL])
        stall_pending = r[_STALL] != 0.0
        steps = int(r[_STEPS])
        mk = r[_MK]
        fz = r[_EZ]
        answered = r[_ANSWERED] != 0.0
        code = 0
        while True:
            f, fx, fy = ball_at(x, y, h, x0, y0, dx, dy, radius)
            # classify: the single contact
            k, reg = _kappa(fx, fy, mu, tol)
            if ideal:
                vx, vy = 1.0 / np.sqrt(1.0 + fx * fx), 0.0
            else:
                vx, vy, _ = _slip_direction(fx, fy, k, _SLIP if reg == _SELF_LOCK else reg)
            locked = reg == _SELF_LOCK
            finite = np.isfinite(vx) and np.isfinite(vy)
            turned = vx * pvx + vy * pvy < 0.0
            reversed_ = has_prev and (not locked) and finite and turned
            crease = False
            if not ideal:
                # a concave crease crossed from the last accepted point, held there (_wedged)
                ddx, ddy = x - px, y - py
                step = math.hypot(ddx, ddy)
                kink = (
                    has_prev and (not locked) and ((fx - pfx) * ddx + (fy - pfy) * ddy > crease_kink * step)
                )
                if kink:
                    kt, rt, bound = two_contact_one(pfx, pfy, fx, fy, mu, crease_tol)
                    if bound and answered:
                        kt, rt = r[_ANS_K], int(r[_ANS_R])
                        answered = False
                    elif bound:
                        ask[s, 0], ask[s, 1], ask[s, 2], ask[s, 3] = pfx, pfy, fx, fy
                        code = PAUSED
                        break
                    if rt == _SELF_LOCK or kt > kappa_cap:
                        k, reg, locked = kt, rt, rt == _SELF_LOCK
                        crease = True
                        reversed_ = False
                # reversed at the shortest step, or on a crease already followed (_on_crease)
                if reversed_ and (hs <= h_min or in_crease):
                    ox, oy = pfx, pfy
                    kc, rc, cvx, cvy = _crease_one(ox, oy, fx, fy, mu, crease_tol)
                    for c in (0, 2):
                        if rc < 0:
                            ox, oy = sides[c], sides[c + 1]
                            kc, rc, cvx, cvy = _crease_one(ox, oy, fx, fy, mu, crease_tol)
                    if rc >= 0:
                        sides[0], sides[1], sides[2], sides[3] = ox, oy, fx, fy
                        crease = True
                        k, reg, locked = kc, rc, rc == _SELF_LOCK
                        vx, vy = cvx, cvy
                        finite = locked or (np.isfinite(vx) and np.isfinite(vy))
            if reversed_ and hs > h_min and not crease:  # rejected: retry at half the step
                hs *= 0.5
                x = px + hs * pvx
                y = py + hs * pvy
                continue
            # record the accepted point
            fz = f
            if k == k and not (k <= mk):  # np.fmax
                mk = k
            if store:
                if pos == cap:
                    cap = 2 * cap
                    bi, bx, by = _grow(bi, cap), _grow(bx, cap), _grow(by, cap)
                    bz, bk, br = _grow(bz, cap), _grow(bk, cap), _grow(br, cap)
                bi[pos], bx[pos], by[pos], bz[pos], bk[pos], br[pos] = s, x, y, f, k, reg
                pos += 1
            # endings, the first reason in this order winning (_endings)
            if locked:
                code = _SELF_LOCKED
            elif k > kappa_cap:
                code = _FORCE_CAP
            elif stall_pending:
                code = _STALLED
            elif steps >= max_steps:
                code = _STEP_CAP
            elif not finite:
                code = _STALLED
            if code:
                break
            hn = dl if crease else (hs if reversed_ else min(2.0 * hs, dl))
            xn = x + hn * vx
            yn = y + hn * vy
            if not ((xn >= xmin) and (xn <= xmax) and (yn >= ymin) and (yn <= ymax)):
                code = _LEFT_DOMAIN
                break
            px, py, pvx, pvy, pfx, pfy = x, y, vx, vy, fx, fy
            in_crease = crease
            has_prev = True
            hs = hn
            x, y = xn, yn
            steps += 1
            arc += dl if reversed_ else hn
            until -= 1
            if until == 0:  # the progress check (check_progress)
                need = stall_dist * (arc * (1.0 / (stall_window * dl)))
                if (x - cx) ** 2 + (y - cy) ** 2 < need * need:
                    stall_pending = True
                cx, cy = x, y
                arc, until = 0.0, stall_window
        outcome[s] = code
        r[_X], r[_Y], r[_CX], r[_CY], r[_H] = x, y, cx, cy, hs
        r[_PX], r[_PY], r[_PVX], r[_PVY], r[_PFX], r[_PFY] = px, py, pvx, pvy, pfx, pfy
        r[_S0], r[_S1], r[_S2], r[_S3] = sides[0], sides[1], sides[2], sides[3]
        r[_IN_CREASE], r[_HAS_PREV], r[_ARC] = 1.0 if in_crease else 0.0, 1.0 if has_prev else 0.0, arc
        r[_UNTIL], r[_STALL], r[_STEPS], r[_MK], r[_EZ] = until, 1.0 if stall_pending else 0.0, steps, mk, fz
        r[_ANSWERED] = 0.0
    return bi[:pos], bx[:pos], by[:pos], bz[:pos], bk[:pos], br[:pos]
