"""Solution verification of the quasistatic corner: is a headline the engine's answer, or
its step's and its hfield's? (docs/physics.md §7; ASME V&V 20, Roache.)

Each family's corner headlines (outcome agreement and median Frechet distance at the
lowest I_e, :mod:`spine_mj.validate.quasistatic_limit`) are recomputed under refinement
(:data:`REFINEMENTS`, engine variations of
:func:`~spine_mj.validate.sweep_configs.engine_grid`):

- ``dt_halved``: each run's own rig step halved, the contact's time constant kept so that
  only the step changes (the sweep's ``timestep_factor``; and ``dt_quartered``, a third
  level, where the plan asks for an observed order);
- ``tolerance_tightened``: MuJoCo's solver and noslip tolerances a hundredth of their
  defaults (the main solver converges in 4 to 13 iterations at 1e-8, yet 1e-10 moved paths
  on the fractal by up to 0.04 L_c and one of four self-lock points: measured, K = 30,
  I_e = 1e-4);
- ``hfield_doubled``: the rig's hfield at twice the samples a side, every old sample kept
  and the tip's radius kept: an analytic surface sampled twice as densely, a gridded one (a
  generated fractal, a scan) refined through the interpolant it is defined by, or where the
  rig resamples it (a grit coarsened to a quarter tip radius) through that of the samples
  it was resampled to (:func:`spine_mj.sim.hfield_of`: only the facets change, not the
  surface).

A refinement reruns a subset of the corner's starts (``plan.limit.convergence_starts`` y
starts per surface, the same points, one run each), and the change of a headline is the
paired change on those starts: the refined runs' number minus the same number of the
corner's own runs from those starts, like for like. The corner's agreement headline, the one its target
judges, is over the starts well-conditioned on both sides and in their verdict
(:mod:`spine_mj.validate.ensembles`: every MuJoCo-reference member pair gives the same
verdict, so the lead run's verdict, the one a refined level's single run is paired with, is
the one the headline counts): its change is paired on the subset's well-conditioned
starts only, the set fixed once, at the corner's level. An ill-conditioned start lies
within 1e-3 L_c of a watershed, so any change of the engine's rounding (a finer step, a
tighter tolerance) flips it as a coin would, and the headline leaves it out for that
reason (measured on the full plan's fractal, 30 paired
starts: dt / 2 flipped 2 runs, 1 of them ill-conditioned; tolerance / 100 flipped 3, 2 of
them ill-conditioned). The agreement over all starts is judged on all paired starts, beside
it. A headline is *converged* under a refinement when the headline
plus that change lies inside the headline's own 95 % interval (Wilson for the agreement,
bootstrap for the median): the refinement moves it less than the sample already leaves
open; or when the change is below what the metric resolves (:data:`RESOLUTIONS`). With
three step levels the observed order and the Richardson estimate follow
(:func:`observed_order`, :func:`richardson`), with Roache's grid convergence index
(:func:`gci`); the same of three hfield levels where a gridded surface is refined four
times too (``hfield_quadrupled``, through the same interpolant). Where three levels are run
a headline is converged only when its *last* change (finest level minus the middle one)
also lies inside its interval (:func:`family_convergence`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from spine_mj.errors import SpineInputError
from spine_mj.validate.plans import FamilySpec
from spine_mj.validate.theory_orders import FRECHET_FLOOR_LC

__all__ = [
    "GRID_ONLY",
    "HEADLINES",
    "JUDGED",
    "REFINEMENTS",
    "REFINEMENT_LABELS",
    "family_convergence",
    "gci",
    "headline_convergence",
    "is_converged",
    "observed_order",
    "paired_change",
    "quoted",
    "refinement_note",
    "richardson",
    "thin_starts",
    "unconverged_mark",
]

#: Refinements by their key in ``validation.json``: engine-variation overrides
#: (:func:`~spine_mj.validate.sweep_configs.engine_grid`).
REFINEMENTS: dict[str, tuple[tuple[str, Any], ...]] = {
    "dt_halved": (("timestep_factor", 0.5),),
    "dt_quartered": (("timestep_factor", 0.25),),
    "hfield_doubled": (("hfield_factor", 2),),
    "hfield_quadrupled": (("hfield_factor", 4),),
    "tolerance_tightened": (("tolerance", 1e-10), ("noslip_tolerance", 1e-8)),
}

#: How the report names each refinement.
REFINEMENT_LABELS = {
    "dt_halved": "dt / 2",
    "dt_quartered": "dt / 4",
    "hfield_doubled": "hfield x 2",
    "hfield_quadrupled": "hfield x 4",
    "tolerance_tightened": "tolerance / 100",
}

#: The corner's numbers under refinement: key in the family summary -> the key of its 95 %
#: interval. ``agreement_well_conditioned`` is the agreement the target judges (over the
#: starts well-conditioned on both sides), ``outcome_agreement`` the one over all starts.
HEADLINES = {
    "agreement_well_conditioned": "agreement_ci",
    "outcome_agreement": "outcome_agreement_ci",
    "median_frechet": "median_frechet_ci",
}

#: The headlines a family's verdict ``converged`` rests on: those the targets judge.
JUDGED = ("agreement_well_conditioned", "median_frechet")

#: The resolution of each headline: the Frechet distance resolves half a sample of the
#: paths' L_c / 50 resampling (:data:`spine_mj.validate.theory_orders.FRECHET_FLOOR_LC`; the
#: corner's medians sit at it where paths coincide, so their bootstrap interval can be
#: narrower than what the metric tells apart); a rate, one run.
RESOLUTIONS = {
    "agreement_well_conditioned": 0.0,
    "outcome_agreement": 0.0,
    "median_frechet": FRECHET_FLOOR_LC,
}

#: The names of the changes in ``validation.json`` (the issue's keys: ``agreement_change`` is
#: the change of the agreement the target judges).
CHANGE_KEYS = {
    "agreement_well_conditioned": "agreement_change",
    "outcome_agreement": "agreement_change_all_starts",
    "median_frechet": "median_frechet_change",
}


def observed_order(fine: float, medium: float, coarse: float, *, ratio: float = 2.0) -> float:
    """Observed order of convergence from three levels refined by ``ratio`` each:
    ``p = ln((coarse - medium) / (medium - fine)) / ln(ratio)``.

    NaN where it is undefined: a level not finite, no change between the two finer levels
    (converged there already, or a rate that flipped no run), or changes of opposite sign
    (oscillatory convergence, no asymptotic order).
    """
    if ratio <= 1:
        raise ValueError(f"ratio must be > 1, got {ratio!r}")
    d_coarse, d_fine = coarse - medium, medium - fine
    if not all(math.isfinite(v) for v in (d_coarse, d_fine)) or d_fine == 0 or d_coarse * d_fine <= 0:
        return math.nan
    return math.log(d_coarse / d_fine) / math.log(ratio)


def richardson(fine: float, medium: float, order: float, *, ratio: float = 2.0) -> float:
    """Richardson estimate of the converged value, ``fine + (fine - medium) / (ratio^p - 1)``
    (NaN without a positive finite ``order``)."""
    if not (math.isfinite(order) and order > 0):
        return math.nan
    return fine + (fine - medium) / (ratio**order - 1.0)


#: Refinements only a gridded surface gets (through its interpolant; an analytic surface's
#: hfield at four times its samples a side is 16 times the facets for no new geometry).
GRID_ONLY = ("hfield_quadrupled",)

#: Three-level series: (coarse-to-medium refinement, medium-to-fine refinement, key of the
#: order in ``validation.json``). The levels are the corner's runs and the two refinements.
SERIES = (("dt_halved", "dt_quartered", "dt_order"), ("hfield_doubled", "hfield_quadrupled", "hfield_order"))

#: The formal orders the GCI assumes where no order is observed (Roache's two-level
#: estimate): semi-implicit Euler's path error is first order in dt (docs/physics.md §7);
#: a tip riding a facet edge instead of the surface errs by first order in the facet size.
FORMAL_ORDER = 1.0
#: Roache's safety factors: three levels that give an observed order, two levels.
GCI_SAFETY = {3: 1.25, 2: 3.0}


def gci(fine: float, medium: float, order: float, *, ratio: float = 2.0) -> float:
    """Roache's grid convergence index ``Fs |(f1 - f2) / f1| / (r^p - 1)`` (docs/physics.md
    §7): the relative band about the finest value ``fine``. ``Fs`` 1.25 with an observed
    ``order``; with NaN (two levels, or three that gave none) 3 and :data:`FORMAL_ORDER`.
    NaN where ``fine`` is 0 or either value is not finite."""
    if not (math.isfinite(fine) and math.isfinite(medium)) or fine == 0:
        return math.nan
    observed = math.isfinite(order) and order > 0
    p, fs = (order, GCI_SAFETY[3]) if observed else (FORMAL_ORDER, GCI_SAFETY[2])
    return fs * abs((fine - medium) / fine) / (ratio**p - 1.0)


def is_converged(
    value: float, change: float, interval: Sequence[float], *, resolution: float = 0.0
) -> bool | None:
    """Whether ``value + change`` lies inside ``interval`` (the value's own 95 % interval),
    or the change is within the metric's ``resolution`` (a change the metric cannot tell
    from none); None where any of them is not finite (nothing was refined, or no
    interval)."""
    low, high = (float(b) for b in interval)
    if not all(math.isfinite(v) for v in (value, change, low, high)):
        return None
    return bool(low <= value + change <= high or abs(change) <= resolution)


def thin_starts(fam: FamilySpec, n: int) -> FamilySpec:
    """``fam`` with at most ``n`` of its y starts (spread over its list, both ends kept; the
    same values, so the same points), on all its seeds and generator variants."""
    if n < 1:
        raise SpineInputError(f"starts must be >= 1, got {n}")
    t = dict(fam.starts)
    ys = tuple(t["y"])
    if len(ys) > n:
        idx = np.unique(np.linspace(0, len(ys) - 1, n).round().astype(int))
        t["y"] = tuple(ys[i] for i in idx)
    return dataclasses.replace(fam, starts=tuple(t.items()))


def _statistic(rows: pd.DataFrame, headline: str) -> float:
    """A headline over ``rows``: the share agreeing (a run without an outcome disagrees) or
    the median Frechet distance (NaN without finite ones)."""
    if headline == "agreement_well_conditioned":
        rows = rows[rows["well_conditioned"]] if "well_conditioned" in rows else rows
    if not len(rows):
        return math.nan
    if headline in ("outcome_agreement", "agreement_well_conditioned"):
        return float(rows["agree"].fillna(False).astype(bool).mean())
    f = rows["frechet"].to_numpy(dtype=float)
    return float(np.median(f[np.isfinite(f)])) if np.isfinite(f).any() else math.nan


def _keys(rows: pd.DataFrame) -> pd.Series:
    """A start's identity across sweeps: its surface (label and L_c: a generator variant
    keeps the label) and its point (rounded far below any ensemble offset)."""
    return (
        rows["surface"].astype(str)
        + "/"
        + rows["surface_lc"].astype(float).round(9).astype(str)
        + "@"
        + rows["start_x"].astype(float).round(9).astype(str)
        + ","
        + rows["start_y"].astype(float).round(9).astype(str)
    )


def paired_change(base: pd.DataFrame, refined: pd.DataFrame) -> dict:
    """Each headline of the corner's own runs ``base`` and of the ``refined`` runs on the
    starts both have (``surface``, ``surface_lc``: the surface's L_c, ``start_x``,
    ``start_y``, ``agree``, ``frechet``), and its change (refined - base), with the number
    of paired runs ``runs``.

    ``base`` may carry ``well_conditioned`` (bool: the start's ensemble ended in one outcome
    on both sides, none stopped): the well-conditioned agreement is then paired on those
    starts only (``well_conditioned_runs`` of them; without the column, on all).

    A start whose reference stalled at either level (``reference_outcome`` "stalled": the
    reference has no answer there, as on a stalled start of the corner itself,
    :mod:`spine_mj.validate.ensembles`) leaves the well-conditioned agreement's and the median
    Frechet distance's pairs (the all-starts agreement keeps it, a miss), and is counted in
    ``reference_stalled``: a refinement that resolves a pit the reference cannot leave
    (measured: sandpaper P600's hfield x 2, 12 of 40 references stalled where MuJoCo's tip
    climbed out at 4-5 F_p) changes the reference's coverage, which the count reports, not
    MuJoCo's agreement."""
    b = base.assign(_key=_keys(base)).drop_duplicates("_key").set_index("_key")
    r = refined.assign(_key=_keys(refined)).drop_duplicates("_key").set_index("_key")
    common = b.index.intersection(r.index)
    b, r = b.loc[common], r.loc[common]
    answered = _answered(b) & _answered(r)
    wc = b["well_conditioned"].astype(bool) if "well_conditioned" in b else pd.Series(True, index=common)
    out: dict[str, Any] = {
        "runs": int(len(common)),
        "well_conditioned_runs": int((wc & answered).sum()),
        "reference_stalled": int((wc & ~answered).sum()),
    }
    b, r = b.assign(well_conditioned=wc & answered), r.assign(well_conditioned=wc & answered)
    for headline in HEADLINES:
        # the all-starts agreement keeps every start: a stall is its miss at either level
        on = slice(None) if headline == "outcome_agreement" else answered
        before, after = _statistic(b[on], headline), _statistic(r[on], headline)
        out[headline] = {"base": before, "refined": after, "change": after - before}
    return out


def _answered(rows: pd.DataFrame) -> pd.Series:
    """Rows whose reference did not stall (all, without a ``reference_outcome`` column)."""
    if "reference_outcome" not in rows:
        return pd.Series(True, index=rows.index)
    return rows["reference_outcome"] != "stalled"


def family_convergence(summary: dict, base: pd.DataFrame, refined: dict[str, pd.DataFrame | None]) -> dict:
    """A family's ``convergence`` entry of ``validation.json``.

    Parameters
    ----------
    summary : dict
        The family's corner summary (its headlines and their ``*_ci`` intervals).
    base : DataFrame
        The corner's own comparison rows of the family, with ``well_conditioned``
        (:func:`paired_change`).
    refined : dict
        Refinement key -> the refined comparison rows (None: not run).

    Returns
    -------
    dict
        Per refinement: ``refined`` (bool), ``runs`` (paired) and
        ``well_conditioned_runs``, ``reference_stalled`` (:func:`paired_change`),
        ``agreement_change`` (the well-conditioned agreement's),
        ``agreement_change_all_starts``, ``median_frechet_change`` (NaN where not refined),
        per headline (:data:`HEADLINES`) its base / refined values on the paired starts and
        ``*_converged`` (:func:`is_converged`), and ``converged``: the headlines the targets
        judge (:data:`JUDGED`; None where not refined). With ``dt_halved`` and
        ``dt_quartered``, ``dt_order``: per headline the observed order of the three step
        levels on the paired starts and the Richardson estimate. ``converged`` at the top:
        every refined verdict true (None where nothing was refined).
    """
    out: dict[str, Any] = {}
    for key, rows in refined.items():
        entry: dict[str, Any] = {"refined": rows is not None}
        if rows is None:
            entry.update(
                runs=0,
                note="not run",
                converged=None,
                **{name: math.nan for name in CHANGE_KEYS.values()},
            )
            out[key] = entry
            continue
        pc = paired_change(base, rows)
        entry["runs"] = pc["runs"]
        entry["well_conditioned_runs"] = pc["well_conditioned_runs"]
        entry["reference_stalled"] = pc["reference_stalled"]
        for headline, ci_key in HEADLINES.items():
            change = pc[headline]["change"]
            ok = is_converged(summary[headline], change, summary[ci_key], resolution=RESOLUTIONS[headline])
            entry[CHANGE_KEYS[headline]] = change
            entry[headline] = {"base": pc[headline]["base"], "refined": pc[headline]["refined"]}
            entry[f"{headline}_converged"] = ok
        verdicts = [entry[f"{headline}_converged"] for headline in JUDGED]
        entry["converged"] = None if any(v is None for v in verdicts) else all(verdicts)
        out[key] = entry
    for medium_key, fine_key, order_key in SERIES:
        medium, fine = out.get(medium_key, {}), out.get(fine_key, {})
        if medium.get("refined") and fine.get("refined"):
            out[order_key] = {
                h: _step_order(medium[h]["base"], medium[h]["refined"], fine[h]["refined"]) for h in HEADLINES
            }
            _judge_last_change(summary, medium, fine)
        elif medium.get("refined"):
            out[order_key] = {
                h: {
                    "order": math.nan,
                    "richardson": math.nan,
                    "gci": gci(medium[h]["refined"], medium[h]["base"], math.nan),
                }
                for h in HEADLINES
            }
    out["converged"] = _overall(out)
    return out


def _judge_last_change(summary: dict, medium: dict, fine: dict) -> None:
    """Judge the last change of a three-level series, the finest level minus the middle one
    (paired on their own starts), and make ``fine``'s verdict need it as well."""
    fine["last_change"] = {}
    for headline, ci_key in HEADLINES.items():
        last = fine[headline]["refined"] - medium[headline]["refined"]
        ok = is_converged(summary[headline], last, summary[ci_key], resolution=RESOLUTIONS[headline])
        fine["last_change"][headline] = last
        fine[f"{headline}_last_converged"] = ok
    verdicts = [fine[f"{h}_converged"] for h in JUDGED] + [fine[f"{h}_last_converged"] for h in JUDGED]
    fine["converged"] = None if any(v is None for v in verdicts) else all(verdicts)


def headline_convergence(
    value: float,
    interval: Sequence[float],
    refined: dict[str, dict | None],
    *,
    log: bool = False,
    resolution: float = 0.0,
    note: str = "nothing to refine",
) -> dict:
    """The ``convergence`` entry of one headline number (an I_e*, a lock rate).

    Parameters
    ----------
    value : float
        The headline.
    interval : (low, high)
        Its own 95 % interval.
    refined : dict
        Refinement key -> ``{"base", "refined", "runs"}``: the headline recomputed on the
        refined runs and on the headline's own runs from the same starts (``runs`` of them;
        the change is paired); None where the refinement changes nothing (``note`` says
        why).
    log : bool
        Judge ``log10`` of the numbers (a quantity located on a logarithmic grid, I_e*).
    resolution : float
        A change the headline cannot tell from none (:func:`is_converged`), on the scale
        judged.

    Returns
    -------
    dict
        Per refinement: ``refined`` (bool), ``runs``, ``base``, ``refined_value``,
        ``change`` (refined - base, of ``log10`` where ``log``) and ``converged``
        (:func:`is_converged`; None where not refined); with ``dt_halved`` and
        ``dt_quartered`` ``dt_order`` (:func:`observed_order` and :func:`richardson`, of
        the judged scale); ``converged`` at the top: every refined verdict true (None where
        nothing was refined).
    """

    def judged(v):
        return math.log10(v) if log and v > 0 else (math.nan if log else v)

    out: dict[str, Any] = {}
    for key, r in refined.items():
        if r is None:
            out[key] = {"refined": False, "runs": 0, "note": note, "change": math.nan, "converged": None}
            continue
        change = judged(float(r["refined"])) - judged(float(r["base"]))
        ok = is_converged(judged(value), change, [judged(float(b)) for b in interval], resolution=resolution)
        out[key] = {
            "refined": True,
            "runs": int(r["runs"]),
            "base": float(r["base"]),
            "refined_value": float(r["refined"]),
            "change": change,
            "converged": ok,
        }
    if out.get("dt_halved", {}).get("refined") and out.get("dt_quartered", {}).get("refined"):
        order = _step_order(
            judged(out["dt_halved"]["base"]),
            judged(out["dt_halved"]["refined_value"]),
            judged(out["dt_quartered"]["refined_value"]),
        )
        if log and math.isfinite(order["richardson"]):
            order["richardson"] = 10 ** order["richardson"]
        out["dt_order"] = order
    out["converged"] = _overall(out)
    return out


def _step_order(coarse: float, medium: float, fine: float) -> dict:
    """The observed order of three levels, the Richardson estimate and the GCI."""
    p = observed_order(fine, medium, coarse)
    return {"order": p, "richardson": richardson(fine, medium, p), "gci": gci(fine, medium, p)}


def _overall(entries: dict) -> bool | None:
    """Every decided refinement verdict of ``entries`` true (None where none was decided)."""
    verdicts = [e["converged"] for e in entries.values() if isinstance(e, dict) and "converged" in e]
    known = [v for v in verdicts if v is not None]
    return all(known) if known else None


def unconverged_mark(convergence: dict | None, headline: str | None = None) -> str:
    """What to write after a headline quoted anywhere: `` (unconverged: dt / 2, ...)``
    naming the refinements that moved it outside its interval; empty where none did or
    nothing was refined. ``convergence`` is a family's entry (:func:`family_convergence`,
    ``headline`` a key of :data:`HEADLINES`) or one headline's
    (:func:`headline_convergence`, ``headline`` None)."""
    moved = _judged(convergence, headline, False)
    return f" (unconverged: {', '.join(moved)})" if moved else ""


def quoted(text: str, convergence: dict | None, headline: str | None = None) -> str:
    """``text`` (a headline as written) where no refinement moved it, else ``"not quoted
    (unconverged: dt / 2, ...)"`` in its place: an unconverged number is never quoted
    (arguments as for :func:`unconverged_mark`)."""
    mark = unconverged_mark(convergence, headline)
    return f"not quoted{mark}" if mark else text


def refinement_note(convergence: dict | None, headline: str | None = None) -> str:
    """What to write beside a headline: :func:`unconverged_mark` where a refinement moved
    it, `` (converged: dt / 2, hfield x 2)`` naming the refinements that did not, empty
    where nothing was refined (arguments as for :func:`unconverged_mark`)."""
    mark = unconverged_mark(convergence, headline)
    kept = _judged(convergence, headline, True)
    return mark or (f" (converged: {', '.join(kept)})" if kept else "")


def _judged(convergence: dict | None, headline: str | None, verdict: bool) -> list[str]:
    """The labels of the refinements whose verdict on ``headline`` is ``verdict``."""
    key = "converged" if headline is None else f"{headline}_converged"
    return [
        REFINEMENT_LABELS.get(name, name)
        for name, entry in (convergence or {}).items()
        if isinstance(entry, dict) and entry.get(key) is verdict
    ]
