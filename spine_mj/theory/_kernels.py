"""Compiled (numba) kernels behind :mod:`spine_mj.theory.streamline`; imported on first use.

``run_trajectories`` steps ``lanes`` starts together on one core (a finished lane takes the
next start): per iteration every lane gets its height and slopes, then kappa, region and
slip direction in branch-free loops over the lanes that LLVM vectorizes (AVX2: 4 lanes per
instruction), then a scalar pass controls the step (a point where the slip direction
reverses is rejected and the step halves; see :class:`spine_mj.theory.streamline_types.StreamlineParams`
``max_halvings``), records, stops and steps. The trajectories are independent
and each is computed with the same operations as one at a time, so the result does not
depend on ``lanes``. A single Gaussian has its own path (exp through libm, the rest
vectorized); Gaussian sums and grids evaluate lane by lane. ``kind`` 0
evaluates a Gaussian sum (``g`` rows: amplitude, centre x, centre y, 1/sigma_x,
1/sigma_y), ``kind`` 1 a cubic B-spline grid (``coef`` and ``sp`` = offset, x0, dx, nx,
y0, dy, ny, periodic). The physics mirrors :func:`spine_mj.theory.engagement.kappa` and
:func:`spine_mj.theory.engagement.slip_direction`; ``tests/theory/test_theory_streamline.py`` checks this
kernel against the pure-numpy reference in :mod:`spine_mj.theory.streamline`.
"""

import math

import numpy as np
from numba import njit

__all__ = ["run_trajectories"]

# no "nnan"/"ninf": the kernel relies on NaN and inf semantics. No "reassoc": with it the
# kernel compiled in the process and the same kernel loaded from numba's on-disk cache
# rounded differently (measured: the rigid streamlines on the scan di-1 differed in their
# last bits, and its corner K_path read 102.6 cold and 290.1 warm); without it both agree,
# at the same speed (2.2e7 and 1.1e7 steps/s on the bench's Gaussian and 256^2 fractal)
_FM = {"contract", "arcp", "nsz"}
_GAUSS_CUTOFF = 64.0  # skip Gaussians beyond 8 sigma (relative contribution < 1e-13)


@njit(cache=True, fastmath=_FM)
def gauss_eval(g, x, y):
    f = 0.0
    fx = 0.0
    fy = 0.0
    for m in range(g.shape[1]):
        isx = g[3, m]
        isy = g[4, m]
        u = (x - g[1, m]) * isx
        v = (y - g[2, m]) * isy
        r2 = u * u + v * v
        if r2 > _GAUSS_CUTOFF:
            continue
        e = g[0, m] * math.exp(-0.5 * r2)
        f += e
        fx -= e * u * isx
        fy -= e * v * isy
    return f, fx, fy


@njit(cache=True, fastmath=_FM)
def bspl(t):
    s = 1.0 - t
    t2 = t * t
    t3 = t2 * t
    return (
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
        -0.5 * s * s,
        1.5 * t2 - 2.0 * t,
        -1.5 * t2 + t + 0.5,
        0.5 * t2,
    )


@njit(cache=True, fastmath=_FM)
def cell(c, c0, d, n, periodic):
    u = (c - c0) / d
    if periodic:
        u = u - math.floor(u / n) * n
        i = int(math.floor(u))
        if i > n - 1:
            i = n - 1
    else:
        i = int(math.floor(u))
        if i < 0:
            i = 0
        if i > n - 2:
            i = n - 2
    return i, u - i


@njit(cache=True, fastmath=_FM)
def grid_eval(coef, sp, x, y):
    off = int(sp[0])
    periodic = sp[7] != 0.0
    i, tx = cell(x, sp[1], sp[2], int(sp[3]), periodic)
    j, ty = cell(y, sp[4], sp[5], int(sp[6]), periodic)
    wx = bspl(tx)
    wy = bspl(ty)
    f = 0.0
    fx = 0.0
    fy = 0.0
    for b in range(4):
        row = j - 1 + b + off
        r0 = 0.0
        r1 = 0.0
        for a in range(4):
            c = coef[row, i - 1 + a + off]
            r0 += wx[a] * c
            r1 += wx[4 + a] * c
        f += wy[b] * r0
        fx += wy[b] * r1
        fy += wy[4 + b] * r0
    return f, fx / sp[2], fy / sp[5]


@njit(cache=True, fastmath=_FM, boundscheck=False, error_model="numpy")
def run_trajectories(
    kind,
    g,
    coef,
    sp,
    bounds,
    xs,
    ys,
    ideal,
    mu,
    dl,
    tol,
    max_steps,
    stall_window,
    stall_dist,
    store,
    lanes,
    kappa_cap,
    max_halvings,
):
    n = xs.size
    outcome = np.zeros(n, np.int8)
    n_steps = np.zeros(n, np.int64)
    max_k = np.full(n, np.nan)
    ex = np.empty(n)
    ey = np.empty(n)
    ez = np.empty(n)
    L = lanes  # a run-time count: LLVM vectorizes the lane loops instead of unrolling them
    # lane state (structure of arrays)
    lx = np.empty(L)
    ly = np.empty(L)
    lcx = np.empty(L)
    lcy = np.empty(L)
    lmk = np.empty(L)
    lstep = np.zeros(L, np.int64)
    luntil = np.zeros(L, np.int64)
    lidx = np.full(L, -1, np.int64)
    # per-step results of the lanes
    lu = np.empty(L)
    lv = np.empty(L)
    le = np.empty(L)
    lf = np.empty(L)
    lfx = np.empty(L)
    lfy = np.empty(L)
    lk = np.empty(L)
    lkk = np.empty(L)
    lreg = np.empty(L, np.int8)
    lvx = np.empty(L)
    lvy = np.empty(L)
    lok = np.empty(L, np.bool_)
    lmoved = np.empty(L, np.bool_)  # stepped to a new point, not yet evaluated
    levent = np.empty(L, np.bool_)
    lstall = np.zeros(L, np.bool_)  # no progress over a window: ends after its next evaluation
    # step-size control: the step that produced the lane's point (then the next one), the
    # last accepted point with its horizontal slip direction, the path walked since the
    # last progress check
    lh = np.empty(L)
    lpx = np.empty(L)
    lpy = np.empty(L)
    lpvx = np.empty(L)
    lpvy = np.empty(L)
    lhp = np.zeros(L, np.bool_)
    larc = np.zeros(L)
    lrev = np.empty(L, np.bool_)
    lrej = np.empty(L, np.bool_)
    h_min = dl / 2.0**max_halvings
    arc_norm = 1.0 / (stall_window * dl)
    # path points in the order they are produced, tagged with their start
    cap = 1024 if store else 1
    bx = np.empty(cap)
    by = np.empty(cap)
    bz = np.empty(cap)
    bk = np.empty(cap)
    br = np.empty(cap, np.int8)
    bi = np.empty(cap, np.int64)
    pos = 0
    xmin, xmax, ymin, ymax = bounds[0], bounds[1], bounds[2], bounds[3]
    m2 = mu * mu
    single = kind == 0 and g.shape[1] == 1
    amp = g[0, 0] if single else 0.0
    gx = g[1, 0] if single else 0.0
    gy = g[2, 0] if single else 0.0
    isx = g[3, 0] if single else 0.0
    isy = g[4, 0] if single else 0.0
    nxt = 0
    nact = 0
    for j in range(L):
        lx[j] = xs[0]  # idle lanes compute on a valid point, results unused
        ly[j] = ys[0]
    while True:
        for j in range(L):  # idle lanes take the next starts, in lane order
            if lidx[j] < 0 and nxt < n:
                _load_lane(
                    j,
                    nxt,
                    xs,
                    ys,
                    stall_window,
                    dl,
                    lidx,
                    lx,
                    ly,
                    lcx,
                    lcy,
                    lmk,
                    lstep,
                    luntil,
                    lstall,
                    lh,
                    lhp,
                    larc,
                )
                nxt += 1
                nact += 1
        if nact == 0:
            break
        # 1. height and slopes of every lane
        if single:
            for j in range(L):
                u = (lx[j] - gx) * isx
                v = (ly[j] - gy) * isy
                lu[j] = u
                lv[j] = v
                le[j] = -0.5 * (u * u + v * v)
            for j in range(L):
                le[j] = math.exp(le[j])  # libm, as the reference; the rest vectorizes
            for j in range(L):
                e = amp * le[j] if lu[j] * lu[j] + lv[j] * lv[j] <= _GAUSS_CUTOFF else 0.0
                lf[j] = e
                lfx[j] = -(e * lu[j] * isx)
                lfy[j] = -(e * lv[j] * isy)
        elif kind == 0:
            for j in range(L):
                lf[j], lfx[j], lfy[j] = gauss_eval(g, lx[j], ly[j])
        else:
            for j in range(L):
                lf[j], lfx[j], lfy[j] = grid_eval(coef, sp, lx[j], ly[j])
        # 2. kappa, region and slip direction (branch-free, vectorizes)
        for j in range(L):
            fx = lfx[j]
            fy = lfy[j]
            a = 1.0 + fy * fy - m2 * fx * fx
            lock = (a < tol) & (fx > 0.0)
            b = -2.0 * (1.0 + m2) * fx
            c = fx * fx + fy * fy - m2
            sq = math.sqrt(b * b - 4.0 * a * c)  # NaN when no real root: slip
            q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
            r1 = q / a  # used only where |a| >= tol
            r2 = c / q
            qnz = q != 0.0
            ok1 = qnz & (abs(a) >= tol) & (r1 > 0.0) & (1.0 + r1 * fx > 0.0)
            best = r1 if ok1 else math.nan
            ok2 = qnz & (r2 > 0.0) & (1.0 + r2 * fx > 0.0) & ((r2 > best) | (best != best))
            best = r2 if ok2 else best
            eng = best == best
            lk[j] = math.inf if lock else best
            lreg[j] = 2 if lock else (1 if eng else 0)
            lkk[j] = 0.0 if lock else (best if eng else 0.0)
        if ideal:
            for j in range(L):
                fx = lfx[j]
                lvx[j] = 1.0 / math.sqrt(1.0 + fx * fx)
                lvy[j] = 0.0
                lok[j] = True
        else:
            for j in range(L):
                fx = lfx[j]
                fy = lfy[j]
                kk = lkk[j]
                rn = (kk * fx + 1.0) / (1.0 + fx * fx + fy * fy)
                tx = kk - rn * fx
                ty = -rn * fy
                tz = -1.0 + rn
                tn2 = tx * tx + ty * ty + tz * tz
                inv = 1.0 / math.sqrt(tn2)
                lvx[j] = tx * inv
                lvy[j] = ty * inv
                lok[j] = tn2 > 0.0
        # 3. step-size control: a point where the horizontal slip direction reverses against
        # the last accepted point's is rejected (the step halves and is retried from there)
        # unless the step is already the shortest; a self-locked point has no direction
        for j in range(L):
            turned = lvx[j] * lpvx[j] + lvy[j] * lpvy[j] < 0.0
            rev = lhp[j] & (lreg[j] != 2) & lok[j] & turned
            lrev[j] = rev
            lrej[j] = rev & (lh[j] > h_min) & (lidx[j] >= 0)
        # 4. record the accepted points, then move every lane that goes on (branch-free)
        if store:
            if pos + L > cap:
                cap *= 2
                bx = _grow(bx, pos, cap)
                by = _grow(by, pos, cap)
                bz = _grow(bz, pos, cap)
                bk = _grow(bk, pos, cap)
                br = _grow(br, pos, cap)
                bi = _grow(bi, pos, cap)
            for j in range(L):
                if lidx[j] >= 0 and not lrej[j]:
                    bx[pos] = lx[j]
                    by[pos] = ly[j]
                    bz[pos] = lf[j]
                    bk[pos] = lk[j]
                    br[pos] = lreg[j]
                    bi[pos] = lidx[j]
                    pos += 1
        for j in range(L):
            if lrej[j]:
                h = 0.5 * lh[j]
                lh[j] = h
                lx[j] = lpx[j] + h * lpvx[j]
                ly[j] = lpy[j] + h * lpvy[j]
                lmoved[j] = False
                levent[j] = False
                continue
            k = lk[j]
            mk = lmk[j]
            lmk[j] = k if ((k > mk) | (mk != mk)) & (k == k) else mk
            x = lx[j]
            y = ly[j]
            # an accepted point reached without a reversal lets the step grow back
            h = lh[j] if lrev[j] else min(2.0 * lh[j], dl)
            xn = x + h * lvx[j]
            yn = y + h * lvy[j]
            inside = (xn >= xmin) & (xn <= xmax) & (yn >= ymin) & (yn <= ymax)
            go = (
                (lreg[j] != 2)
                & (not (k > kappa_cap))
                & (lstep[j] < max_steps)
                & lok[j]
                & inside
                & (not lstall[j])
            )
            if go:
                lpx[j] = x
                lpy[j] = y
                lpvx[j] = lvx[j]
                lpvy[j] = lvy[j]
                lhp[j] = True
                lh[j] = h
                larc[j] += dl if lrev[j] else h  # a forced step across a crease: judged as a full one
                lx[j] = xn
                ly[j] = yn
            lstep[j] += go
            u = luntil[j] - go
            luntil[j] = u
            lmoved[j] = go
            levent[j] = (not go) | (u == 0)
        # 5. the rare events: a trajectory ends (its lane takes the next start), stall checks.
        # A lane that moved is on a point not evaluated yet: it only gets its progress check
        # here (a stall or the step cap ends it after the next pass has recorded that point).
        # A lane that did not move ends now, on the point just recorded. Deciding an end for
        # a lane that moved (as the cap test once did when the cap fell on a progress check,
        # max_steps a multiple of stall_window) loses the path's last point.
        for j in range(L):
            if not levent[j]:
                continue
            i = lidx[j]
            if i < 0:
                continue
            x = lx[j]
            y = ly[j]
            code = 0
            if lmoved[j]:
                luntil[j] = stall_window
                dxs = x - lcx[j]
                dys = y - lcy[j]
                # progress asked for in proportion to the path walked (full steps: stall_dist)
                need = stall_dist * (larc[j] * arc_norm)
                if dxs * dxs + dys * dys < need * need:
                    lstall[j] = True
                lcx[j] = x
                lcy[j] = y
                larc[j] = 0.0
            elif lreg[j] == 2:
                code = 1
            elif lk[j] > kappa_cap:
                code = 5
            elif lstall[j]:
                code = 3
            elif lstep[j] >= max_steps:
                code = 4
            elif not lok[j]:
                code = 3
            else:
                code = 2  # the next step would leave the bounds
            if code != 0:
                outcome[i] = code
                n_steps[i] = lstep[j]
                max_k[i] = lmk[j]
                ex[i] = x
                ey[i] = y
                ez[i] = lf[j]
                lidx[j] = -1
                nact -= 1
    # paths back to back in start order (points of one start were produced in step order)
    offsets = np.zeros(n + 1, np.int64)
    if not store:
        return (outcome, n_steps, max_k, ex, ey, ez, offsets, bx[:0], by[:0], bz[:0], bk[:0], br[:0])
    for i in range(n):
        offsets[i + 1] = offsets[i] + n_steps[i] + 1
    if offsets[n] != pos:  # every path has n_steps + 1 points; never scatter out of bounds
        raise RuntimeError("streamline kernel: stored points do not match the step counts")
    px = np.empty(pos)
    py = np.empty(pos)
    pz = np.empty(pos)
    pk = np.empty(pos)
    pr = np.empty(pos, np.int8)
    cur = offsets[:-1].copy()
    for p in range(pos):
        i = bi[p]
        d = cur[i]
        cur[i] = d + 1
        px[d] = bx[p]
        py[d] = by[p]
        pz[d] = bz[p]
        pk[d] = bk[p]
        pr[d] = br[p]
    return outcome, n_steps, max_k, ex, ey, ez, offsets, px, py, pz, pk, pr


@njit(cache=True, inline="always")
def _load_lane(
    j, i, xs, ys, stall_window, dl, lidx, lx, ly, lcx, lcy, lmk, lstep, luntil, lstall, lh, lhp, larc
):
    """Put start ``i`` into lane ``j``: position, progress anchor, fresh counters, a full step."""
    lidx[j] = i
    lx[j] = xs[i]
    ly[j] = ys[i]
    lcx[j] = xs[i]
    lcy[j] = ys[i]
    lmk[j] = math.nan
    lstep[j] = 0
    luntil[j] = stall_window
    lstall[j] = False
    lh[j] = dl
    lhp[j] = False
    larc[j] = 0.0


@njit(cache=True)
def _grow(a, used, cap):
    b = np.empty(cap, a.dtype)
    b[:used] = a[:used]
    return b
