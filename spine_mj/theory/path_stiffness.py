"""``K_path``: the stiffness at which a spring drive's quasistatic paths meet the comparison's
criterion against the rigid streamlines (docs/physics.md §8), and what it stands on: the
fold of the hold force along a path (``-dH/dx``, whose largest value times ``l_s`` is the
fold ``K*``), the carriage travel of a spring run, and the criterion itself.

The compliant-drive paths (:mod:`spine_mj.theory.compliant`) are the spring drive's
``I_e -> 0`` limit; :func:`path_stiffness` searches the K at which they agree with the rigid
ones (paper Eq. 4) as a measurement would judge them (:func:`path_criterion`).
:mod:`spine_mj.theory.drive_limits` sets it beside ``K*`` and ``I_e*``.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.surfaces import Surface
from spine_mj.theory import streamline as sl
from spine_mj.theory.agreement import outcome_agreement, path_frechet
from spine_mj.theory.compliant import compliant_streamlines, hold_force
from spine_mj.theory.streamline_types import Outcome, StreamlineParams
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET

__all__ = [
    "PATH_STIFFNESS_CEILING",
    "PATH_STIFFNESS_PROBES",
    "PATH_STIFFNESS_RANGE",
    "PATH_STIFFNESS_RESOLUTION",
    "SPRING_TRAVEL_PAST_EDGE",
    "kappa_fall",
    "max_fall",
    "path_criterion",
    "path_stiffness",
    "spring_run_travel",
    "start_scores",
]

#: A spring run without a duration moves its carriage this many times the distance from
#: its start to the domain's +x edge, plus the spring's stretch (:func:`spring_run_travel`).
SPRING_TRAVEL_PAST_EDGE = 1.1

#: ``K_path`` is bracketed to this factor (the map's ladder steps are 3 and more).
PATH_STIFFNESS_RESOLUTION = 2 ** (1 / 4)
#: The softest K ``path_stiffness`` tries, as a fraction of the first K that passes.
PATH_STIFFNESS_RANGE = 1e-3
#: The stiffest K ``path_stiffness`` tries, as a multiple of the paths' fold ``K*`` (or 1).
PATH_STIFFNESS_CEILING = 2.0**20
#: A start whose compliant path misses at each of these multiples of the fold ``K*`` (or 1)
#: is left out of ``K_path`` (:func:`path_stiffness`). Measured on 20 starts, kappa cap 20:
#: on sandpaper P36 and P60 the same 2 starts miss at K 30, 300 and 3000, each ending at the
#: force cap a few tenths of L_c aside of the rigid path's lock, every other start agrees;
#: on the scan di-1 every path leaves the domain on both sides and the median Frechet
#: distance is 0.24, 0.17, 0.19 and 0.17 L_c at K 30 to 30000 (long paths over many ridges).
#: Counting a Frechet distance above the target as a miss too, the quick plan's corners
#: leave out 8 (P36), 5 (P60), 6 (P600) and 12 (di-1) of 20.
PATH_STIFFNESS_PROBES = (1.0, 10.0, 100.0)


def kappa_fall(x, hold) -> np.ndarray:
    """``-dH/dx`` between consecutive points of one path (shape ``(n - 1,)``); NaN where
    ``x`` does not advance or either hold is not finite."""
    x, hold = np.asarray(x, float), np.asarray(hold, float)
    dx, dh = np.diff(x), np.diff(hold)
    ok = (dx > 1e-12 * max(1.0, float(np.abs(x).max(initial=0.0)))) & np.isfinite(dh)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(ok, -dh / np.where(ok, dx, 1.0), np.nan)


def max_fall(surface, res, mu: float, kappa_cap: float) -> float:
    """``max(-dH/dx)`` over the paths of ``res`` (a stored-path streamline result) on
    ``surface``, hold forces above ``kappa_cap`` left out (held: no fold to fall from)."""
    falls = [np.array([])]
    for i in range(len(res)):
        p = res.path(i)
        _, fx, fy = surface.evaluate(p["x"], p["y"], order=1)
        hold, _ = hold_force(fx, fy, mu)
        falls.append(kappa_fall(p["x"], np.where(hold > kappa_cap, np.nan, hold)))
    return float(np.nanmax(np.concatenate(falls), initial=0.0))


def spring_run_travel(distance_to_edge, stretch_per_fp, mu: float):
    """How far a spring run without a duration moves its carriage: ``1.1`` times the distance
    from its start to the domain's +x edge (none past it), plus the spring's stretch at
    ``(1 + mu) F_p`` (the drive of a slide up a 45 degree slope), in any one length unit.

    Parameters
    ----------
    distance_to_edge : float or array_like
        From the start to the domain's +x edge.
    stretch_per_fp : float or array_like
        ``F_p / k``, the spring's stretch per preload: ``l_s / K`` in surface units.
    mu : float
        mu_s.
    """
    return SPRING_TRAVEL_PAST_EDGE * np.maximum(distance_to_edge, 0.0) + (1.0 + mu) * np.asarray(
        stretch_per_fp, float
    )


def path_criterion(rigid, compliant, char_length: float, keep=None) -> tuple[float, float]:
    """Outcome agreement (share of starts) and median Frechet distance (in ``L_c``, x-y
    traces) of ``compliant`` paths against the ``rigid`` ones from the same starts: the
    comparison a spring-drive run meets against its streamline
    (:func:`spine_mj.theory.agreement.outcome_agreement`, :func:`spine_mj.theory.agreement.path_frechet`; a
    rigid path that stalled decided nothing and disagrees, as in the sweep's comparison),
    over the starts ``keep`` marks (default all)."""
    agree, frechet = start_scores(rigid, compliant, char_length)
    keep = np.ones(len(rigid), bool) if keep is None else np.asarray(keep, bool)
    return float(np.mean(agree[keep])), float(np.median(frechet[keep]))


def start_scores(rigid, compliant, char_length: float) -> tuple[np.ndarray, np.ndarray]:
    """Per start, whether the ``compliant`` path's outcome agrees with the ``rigid`` one's,
    and their Frechet distance in ``L_c`` (:func:`path_criterion`'s two parts)."""
    agree = outcome_agreement(
        rigid.self_locked,
        np.column_stack([rigid.end_x, rigid.end_y]),
        compliant.self_locked,
        np.column_stack([compliant.end_x, compliant.end_y]),
        length_scale=char_length,
    )["agree"] & (rigid.outcome != Outcome.STALLED)
    frechet = np.array(
        [
            path_frechet(
                np.column_stack([compliant.path(i)["x"], compliant.path(i)["y"]]),
                np.column_stack([rigid.path(i)["x"], rigid.path(i)["y"]]),
                length_scale=char_length,
            )
            for i in range(len(rigid))
        ]
    )
    return agree, frechet


def path_stiffness(
    surface: Surface,
    starts,
    params: StreamlineParams,
    *,
    slope_length: float,
    char_length: float,
    frechet_target: float = FRECHET_TARGET,
    outcome_target: float = OUTCOME_TARGET,
    carriage_edge: float | None = None,
) -> tuple[float, float, int]:
    """``K_path``: the smallest ``K = k l_s / W`` at which the compliant-drive paths from
    ``starts`` meet the comparison's criterion against the rigid streamlines (outcome
    agreement >= ``outcome_target``, median Frechet <= ``frechet_target``; docs/physics.md §8).

    With an endless carriage, above the fold ``K*`` of these paths (:func:`kappa_fall`
    along them) no path folds and the compliant path is the rigid one, so the criterion
    holds there; below it a fold's jump counts only through what it does to the trace (a
    lateral offset, a branch of the flow left) and the outcome. With ``carriage_edge`` each
    carriage stops where a run's does (:func:`spring_run_travel` from its start): a tip
    that needs the spring stretched further (a hold of ``H`` at ``x`` needs the carriage at
    ``x + H l_s / K``) ends there, short of the rigid path, at any K below
    ``(H - 1 - mu) l_s / (1.1 d - (x - x0))`` (``d`` the start's distance to the edge),
    fold or none. The search (:func:`_last_failure`) brackets the stiffest K that fails to
    :data:`PATH_STIFFNESS_RESOLUTION`. With ``carriage_edge``, a start that misses (outcome,
    or Frechet above target) at every K of :data:`PATH_STIFFNESS_PROBES` times the fold is
    left out: a miss a hundred times stiffer a spring keeps is not the spring's to fix.

    Parameters
    ----------
    surface : Surface
        The surface the tip's centre rides on (dilated by the tip radius where it has one).
    starts : array_like, shape (n, 2)
    params : StreamlineParams
        Friction, step and force cap of both tracings.
    slope_length, char_length : float
        ``l_s`` (turns ``K`` into ``k / W``) and ``L_c`` (the Frechet distance's unit).
    frechet_target, outcome_target : float
        The criterion (default the comparison's).
    carriage_edge : float, optional
        The runs' +x edge (:func:`spring_run_travel`); None: an endless carriage.

    Returns
    -------
    k_path : float
        The passing end of the bracket (0: an endless carriage and no fold; inf: none
        passes up to :data:`PATH_STIFFNESS_CEILING` times the fold).
    k_fold : float
        The fold ``K*`` on these paths.
    left_out : int
        Starts left out of the criterion: they miss at every stiffness probed.
    """
    pts = np.asarray(starts, float)
    rigid = sl.streamlines(surface, pts, params, store_paths=True)
    k_fold = slope_length * max(0.0, max_fall(surface, rigid, params.mu, params.kappa_cap))
    if carriage_edge is None and not (k_fold > 0 and math.isfinite(k_fold)):
        return 0.0, k_fold, 0

    compliant = _compliant_tracer(surface, pts, params, slope_length, carriage_edge)
    top = k_fold if k_fold > 0 and math.isfinite(k_fold) else 1.0
    misses = np.zeros(len(pts), bool)
    if carriage_edge is not None:
        misses = _missed_at_every_probe(rigid, compliant, top, char_length, frechet_target)
    keep = ~misses
    if not keep.any():
        return math.inf, k_fold, len(pts)

    def passes(k: float) -> bool:
        agreement, frechet = path_criterion(rigid, compliant(k), char_length, keep)
        return agreement >= outcome_target and frechet <= frechet_target

    return _last_failure(passes, top, check_top=carriage_edge is not None), k_fold, int(misses.sum())


def _compliant_tracer(surface, pts, params, slope_length: float, carriage_edge):
    """``K -> `` the compliant-drive paths from ``pts`` at stiffness ``K`` (each carriage
    stopping where a run's does, with ``carriage_edge``), each K traced once: the probes
    and the search meet at the fold."""
    traced = {}

    def compliant(k: float):
        if k not in traced:
            end = (
                None
                if carriage_edge is None
                else pts[:, 0] + spring_run_travel(carriage_edge - pts[:, 0], slope_length / k, params.mu)
            )
            traced[k] = compliant_streamlines(
                surface, pts, params, stiffness=k / slope_length, carriage_end=end
            )
        return traced[k]

    return compliant


def _missed_at_every_probe(rigid, compliant, top: float, char_length: float, frechet_target: float):
    """Per start, whether its ``compliant(K)`` path misses the ``rigid`` one (outcome, or
    Frechet above ``frechet_target``) at every ``K`` of :data:`PATH_STIFFNESS_PROBES` x ``top``."""
    misses = np.ones(len(rigid), bool)
    for factor in PATH_STIFFNESS_PROBES:
        agree, frechet = start_scores(rigid, compliant(factor * top), char_length)
        misses &= ~agree | (frechet > frechet_target)
    return misses


def _last_failure(passes, top: float, *, check_top: bool) -> float:
    """The passing end of the bracket of the stiffest K that fails ``passes``: up from
    ``top`` in doublings to a K that passes (``check_top`` False: ``top`` passes), down in
    halvings to the stiffest K that fails (a measured boundary is the largest K that fails,
    too: softer springs can agree again, their jumps along the path), then that halving
    bisected (see :func:`path_stiffness`)."""
    hi = top
    while check_top and not passes(hi):
        if hi >= PATH_STIFFNESS_CEILING * top:
            return math.inf
        hi *= 2
    first, lo = hi, hi / 2
    while passes(lo):
        if lo <= PATH_STIFFNESS_RANGE * first:
            return lo
        hi, lo = lo, lo / 2
    while hi / lo > PATH_STIFFNESS_RESOLUTION:
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if passes(mid) else (mid, hi)
    return hi
