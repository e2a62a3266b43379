"""The numpy reference backend of :mod:`spine_mj.theory.streamline`: a plain loop over
steps, vectorized over starts, for any :class:`~spine_mj.surfaces.Surface` (the compiled
kernel, :mod:`spine_mj.theory._kernels`, is tested against it)."""

from __future__ import annotations

import numpy as np

from spine_mj.surfaces import BallOnFacets, TriangulatedSurface
from spine_mj.theory.engagement import DEFAULT_TOL, ENGAGED, SELF_LOCK, SLIP, kappa
from spine_mj.theory.multicontact import hold_kappa, normals_of_slopes
from spine_mj.theory.streamline_types import Outcome

__all__ = ["CREASE_KINK", "run_numpy"]


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
        kt, rt = _two_contact_kappa(pfx[i], pfy[i], fx[i], fy[i], params.mu)
        hold = (rt == SELF_LOCK) | (kt > params.kappa_cap)
        held[i[hold]] = True
        kt, rt = kt[hold], rt[hold]
    return held, kt, rt


def _single_contact(fx, fy, mu, tol):
    """:func:`spine_mj.theory.engagement.kappa` and :func:`~spine_mj.theory.engagement.slip_direction`
    (a self-locked point's as if it slipped) on 1-d arrays, compiled
    (:func:`spine_mj.theory._multicontact_kernel.single_contact`, the same numbers)."""
    from spine_mj.theory._multicontact_kernel import single_contact

    fx, fy = np.ascontiguousarray(fx, dtype=float), np.ascontiguousarray(fy, dtype=float)
    return single_contact(fx, fy, float(mu), float(tol))


def _crease_engagement(fx_a, fy_a, fx_b, fy_b, mu):
    """:func:`spine_mj.theory.engagement.crease_engagement` on 1-d arrays, compiled
    (:func:`spine_mj.theory._multicontact_kernel.crease`: the same numbers, without numpy's
    per-call overhead on the few points a step asks about)."""
    from spine_mj.theory._multicontact_kernel import crease

    args = (np.ascontiguousarray(v, dtype=float) for v in (fx_a, fy_a, fx_b, fy_b))
    return crease(*args, float(mu), DEFAULT_TOL)


def _two_contact_kappa(fx_a, fy_a, fx_b, fy_b, mu):
    """:func:`spine_mj.theory.multicontact.two_contact_kappa` on 1-d arrays, compiled
    (:func:`spine_mj.theory._multicontact_kernel.two_contact`), the friction-cone bound of the
    points where no motion counts from :func:`~spine_mj.theory.multicontact.hold_kappa`."""
    from spine_mj.theory._multicontact_kernel import two_contact

    fx_a, fy_a, fx_b, fy_b = (np.ascontiguousarray(v, dtype=float) for v in (fx_a, fy_a, fx_b, fy_b))
    k, region, bound = two_contact(fx_a, fy_a, fx_b, fy_b, float(mu), DEFAULT_TOL)
    for i in np.flatnonzero(bound):
        na, nb = normals_of_slopes(fx_a[i], fy_a[i]), normals_of_slopes(fx_b[i], fy_b[i])
        k[i] = hold_kappa(np.array([na, nb]), float(mu))
        region[i] = SLIP if np.isnan(k[i]) else (SELF_LOCK if np.isinf(k[i]) else ENGAGED)
    return k, region


def run_numpy(surface, xs, ys, params, *, ideal, store):
    """The obvious reference: one vectorized evaluation for all active starts per iteration.

    A reversal at the shortest step (or on a crease already followed) is a tip resting in a
    concave crease on two contacts: the path follows the crease at the two-contact kappa of
    its sides (:func:`spine_mj.theory.engagement.crease_engagement`) with whole steps. The
    compiled kernel of smooth surfaces (Gaussian sums, splines) has no crease state and takes
    such a reversal as it is; the compiled facet walk
    (:mod:`spine_mj.theory._facet_streamline_kernel`) has this backend's. On facets (a ball on
    them or bare), a step that crosses a concave crease tests the two contacts' hold there
    (:func:`spine_mj.theory.multicontact.two_contact_kappa`, :func:`_wedged`): a tip wedged beyond
    the force cap, or for every drive, is held where a path on single contacts would
    zig-zag across the crease and go on.

    Each start holds a candidate point reached from its last accepted point by a step ``h``;
    a candidate where the horizontal slip direction reverses against the accepted point's
    is rejected (``h`` halves, down to ``dl / 2**max_halvings``) and the step is retried;
    an accepted candidate lets ``h`` grow back (doubling, up to ``dl``). See
    :class:`StreamlineParams`.
    """
    walk = _Walk(xs, ys, params)
    creased = isinstance(surface, (BallOnFacets, TriangulatedSurface))  # creases between facets
    active = np.arange(xs.size)
    while active.size:
        xa, ya = walk.x[active], walk.y[active]
        f, fx, fy = surface.evaluate(xa, ya, order=1)
        point = walk.classify(active, xa, ya, fx, fy, ideal=ideal, creased=creased)
        k, reg, locked, vx, vy, finite, reversed_, crease = point
        rejected = reversed_ & (walk.h[active] > walk.h_min) & ~crease
        back = active[rejected]  # evaluated again next iteration, at the shorter step
        walk.retreat(back)
        keep = ~rejected
        active, xa, ya, f, fx, fy = active[keep], xa[keep], ya[keep], f[keep], fx[keep], fy[keep]
        k, reg, locked, vx, vy, finite, reversed_, crease = (v[keep] for v in point)
        walk.record(active, xa, ya, f, k, reg, store)
        done = _endings(
            walk.outcome,
            active,
            locked,
            k > params.kappa_cap,
            walk.stall_pending[active],
            walk.n_steps[active] >= params.max_steps,
            ~finite,
        )
        move = walk.advance(active, done, (xa, ya, vx, vy, fx, fy), crease, reversed_, params.domain(surface))
        walk.check_progress(move)
        active = np.sort(np.concatenate([back, move]))
    w = walk
    return w.outcome, w.n_steps, w.max_k, w.x.copy(), w.y.copy(), w.ez, *_packed(w.paths, store)


class _Walk:
    """The per-start state of :func:`run_numpy`: current point and the step that produced
    it (then the next one), the last accepted point with its horizontal slip direction and
    slopes (the other side of a crease), the sides of the last crease met, the stall
    window, and what is recorded (outcome, steps, max kappa, last height, paths)."""

    def __init__(self, xs, ys, params):
        n = xs.size
        self.params = params
        self.dl = float(params.dl)
        self.h_min = self.dl / 2.0**params.max_halvings
        self.x, self.y = xs.copy(), ys.copy()
        self.cx, self.cy = self.x.copy(), self.y.copy()  # the last progress check's point
        self.h = np.full(n, self.dl)
        self.px, self.py = self.x.copy(), self.y.copy()
        self.pvx, self.pvy = np.zeros(n), np.zeros(n)
        self.pfx, self.pfy = np.zeros(n), np.zeros(n)
        self.sides = np.full((n, 4), np.nan)  # the two sides' slopes of the last crease met
        self.in_crease = np.zeros(n, bool)  # the last accepted point was on a crease
        self.has_prev = np.zeros(n, bool)
        self.arc = np.zeros(n)  # step lengths since the last progress check
        self.until = np.full(n, params.stall_window, np.int64)
        self.stall_pending = np.zeros(n, bool)  # no progress over a window: ends at the next evaluation
        self.outcome = np.zeros(n, np.int8)
        self.n_steps = np.zeros(n, np.int64)
        self.max_k = np.full(n, np.nan)
        self.ez = np.full(n, np.nan)
        self.paths = [[] for _ in range(n)]

    def classify(self, active, xa, ya, fx, fy, *, ideal, creased) -> tuple:
        """``(k, reg, locked, vx, vy, finite, reversed_, crease)`` at the ``active`` starts'
        points: kappa and region, the direction of the next step, whether it turned back
        against the last accepted point's, and whether the tip rests in a crease (wedged on
        facets, :func:`_wedged`, or following one, :func:`_on_crease`)."""
        params = self.params
        if ideal:
            k, reg = kappa(fx, fy, params.mu, tol=params.tol)
            vx, vy = 1.0 / np.sqrt(1.0 + fx * fx), np.zeros_like(fx)
        else:
            k, reg, vx, vy = _single_contact(fx, fy, params.mu, params.tol)
        locked = reg == SELF_LOCK
        finite = np.isfinite(vx) & np.isfinite(vy)
        with np.errstate(invalid="ignore"):
            turned = vx * self.pvx[active] + vy * self.pvy[active] < 0.0
        reversed_ = self.has_prev[active] & ~locked & finite & turned
        crease = np.zeros(active.size, bool)
        if not ideal and creased:
            prev = (self.px[active], self.py[active], self.pfx[active], self.pfy[active])
            wedged, kw, rw = _wedged(xa, ya, fx, fy, (*prev, self.has_prev[active] & ~locked), params)
            k[wedged], reg[wedged], locked[wedged] = kw, rw, rw == SELF_LOCK
            crease |= wedged
            reversed_ &= ~wedged
        if not ideal:
            # reversed at the shortest step, or on a crease already followed: the tip rests in
            # a concave crease, on two contacts (crease_engagement)
            r = np.flatnonzero(reversed_ & ((self.h[active] <= self.h_min) | self.in_crease[active]))
            point = (fx, fy, k, reg, locked, vx, vy, finite)
            _on_crease(r, active, (self.pfx, self.pfy), self.sides, params.mu, point, crease)
        return k, reg, locked, vx, vy, finite, reversed_, crease

    def retreat(self, back) -> None:
        """Halve the step of the starts ``back`` and put them back on it from their last
        accepted point (their step reversed the slip direction)."""
        if back.size:
            self.h[back] *= 0.5
            self.x[back] = self.px[back] + self.h[back] * self.pvx[back]
            self.y[back] = self.py[back] + self.h[back] * self.pvy[back]

    def record(self, active, xa, ya, f, k, reg, store) -> None:
        """The accepted points: last height, largest kappa, and (``store``) the path."""
        self.ez[active] = f
        self.max_k[active] = np.fmax(self.max_k[active], k)
        if store:
            for j, idx in enumerate(active):
                self.paths[idx].append((xa[j], ya[j], f[j], k[j], reg[j]))

    def advance(self, active, done, point, crease, reversed_, domain) -> np.ndarray:
        """Step the ``active`` starts that go on (not ``done``, next point inside
        ``domain``; the others leaving it end ``LEFT_DOMAIN``); returns those moved."""
        xa, ya, vx, vy, fx, fy = point
        dl = self.dl
        xmin, xmax, ymin, ymax = domain
        # an accepted point reached without a reversal lets the step grow back; along a
        # crease the path steps a whole dl
        hn = np.where(crease, dl, np.where(reversed_, self.h[active], np.minimum(2.0 * self.h[active], dl)))
        xn = xa + hn * np.where(done, 0.0, vx)
        yn = ya + hn * np.where(done, 0.0, vy)
        out = ~done & ~((xn >= xmin) & (xn <= xmax) & (yn >= ymin) & (yn <= ymax))
        self.outcome[active[out]] = Outcome.LEFT_DOMAIN
        go = ~(done | out)
        move = active[go]
        self.px[move], self.py[move] = xa[go], ya[go]
        self.pvx[move], self.pvy[move] = vx[go], vy[go]
        self.pfx[move], self.pfy[move] = fx[go], fy[go]
        self.in_crease[move] = crease[go]
        self.has_prev[move] = True
        self.h[move] = hn[go]
        self.x[move], self.y[move] = xn[go], yn[go]
        self.n_steps[move] += 1
        self.arc[move] += np.where(reversed_[go], dl, hn[go])  # a forced step across a crease: a full one
        self.until[move] -= 1
        return move

    def check_progress(self, move) -> None:
        """Progress checks of the starts whose window ends: too little net progress for
        the path walked (all full steps: ``stall_distance``) ends them at the next point."""
        p = self.params
        check = move[self.until[move] == 0]
        if check.size:
            need = p.stall_distance_value * (self.arc[check] * (1.0 / (p.stall_window * self.dl)))
            stuck = (self.x[check] - self.cx[check]) ** 2 + (
                self.y[check] - self.cy[check]
            ) ** 2 < need * need
            self.stall_pending[check[stuck]] = True
            self.cx[check], self.cy[check] = self.x[check], self.y[check]
            self.arc[check], self.until[check] = 0.0, p.stall_window


def _on_crease(r, active, prev_slopes, sides, mu, point, crease) -> None:
    """Where the tip rests in a concave crease (rows ``r`` of the ``active`` starts): the
    two-contact kappa, region and direction of its sides (:func:`crease_engagement`), the
    last point's slopes ``prev_slopes`` and the current ones, else the crease's other side
    from ``sides``; written into ``point`` = (fx, fy, k, reg, locked, vx, vy, finite),
    ``sides`` and ``crease`` where two contacts hold (:func:`run_numpy`)."""
    if not r.size:
        return
    pfx, pfy = prev_slopes
    fx, fy, k, reg, locked, vx, vy, finite = point
    other = np.column_stack([pfx[active[r]], pfy[active[r]]])
    got = _crease_engagement(other[:, 0], other[:, 1], fx[r], fy[r], mu)
    for c in (0, 2):  # on the same side as the last point: the crease's other side
        again = got[1] < 0
        retry = sides[active[r], c : c + 2]
        alt = _crease_engagement(retry[:, 0], retry[:, 1], fx[r], fy[r], mu)
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
