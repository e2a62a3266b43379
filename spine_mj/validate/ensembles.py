"""Ill-conditioned starts, found on both sides: each compared start runs as a small ensemble.

MuJoCo rounds differently on different CPUs, and a path near a watershed (a separatrix
of the streamline flow, a crease it barely misses) amplifies that into a different trap: a
verdict drawn from one such run is a coin toss. So every start of the quasistatic-limit
study runs as an ensemble: the start itself and ``members - 1`` starts on a circle of
radius :data:`ENSEMBLE_RADIUS_LC` L_c around it (a fixed stencil: the ensemble is a
function of the plan alone). The radius is far above rounding (1e-16 relative) and far
below what tells traps apart (the end tolerance of :func:`spine_mj.theory.agreement.outcome_agreement`,
0.25 L_c) and the hfield's spacing (~0.06 L_c on the fractal): two members that end in
different traps say the start lies within 1e-3 L_c of a watershed, where another CPU's last
bits may flip it. The machine-to-machine flips measured on the fractal (issue: separatrix
offsets 0.001-0.08 L_c) sit at that scale.

A start is ill-conditioned on a side (MuJoCo, or the reference streamline) when its members
there do not all end in the same outcome (held or free, and where held, the same trap:
:func:`spine_mj.theory.agreement.outcome_agreement` between members, the comparison's own rule),
and ill-conditioned in its *verdict* when each side is one outcome but the MuJoCo-reference
member pairs do not all give the same verdict: the comparison's own watershed, its end
tolerance, runs through the ensemble (the outcome rule is not transitive: members 0.09 L_c
apart on one side can straddle the 0.25 L_c tolerance from the other's end), so which member
is drawn decides agree or not, a coin toss as a split side is. Measured on the full plan's
sandpaper P36 (y -1.5e-3): MuJoCo's three members locked 0.193, 0.27 and 0.27 L_c from the
reference's lock; the lead run agreed, the ensemble did not, and hfield x 2 moved the lead
to where its neighbours already were (0.271 L_c), a flip of a verdict the headline never
counted. Agreement is then judged on the starts well-conditioned on both sides and in their
verdict, where every member pair gives the same verdict (so the lead run's verdict is the
ensemble's, and a refinement's single run is paired like for like); the others are counted
per side, with the overlap of the two outcome distributions (the share of MuJoCo-reference
member pairs that agree).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from spine_mj import presets, sim
from spine_mj.sim.rig_hfield import grid_keeps_samples
from spine_mj.theory import agreement
from spine_mj.validate.intervals import wilson
from spine_mj.validate.paths import stored_paths
from spine_mj.validate.plans import MASS_KG, FamilySpec

__all__ = [
    "ENSEMBLE_RADIUS_LC",
    "ensemble_family",
    "ensemble_groups",
    "ensemble_starts",
    "ensemble_verdicts",
    "member_offsets",
]

#: Reference outcomes that hold the tip (the self-lock region or the force cap).
HELD = ("self_locked", "force_cap")

#: Radius of the ensemble's stencil around each start, in L_c (see the module).
ENSEMBLE_RADIUS_LC = 1e-3


def member_offsets(members: int) -> np.ndarray:
    """``(members, 2)`` offsets on the unit circle: the start itself, then ``members - 1``
    evenly spaced directions (from +x)."""
    if int(members) != members or members < 1:
        raise ValueError(f"members must be an integer >= 1, got {members!r}")
    a = 2.0 * np.pi * np.arange(members - 1) / max(members - 1, 1)
    return np.vstack([[0.0, 0.0], np.column_stack([np.cos(a), np.sin(a)])])[:members]


def _base_points(table: dict) -> list[tuple[float, float]]:
    """The starts of a sweep ``starts`` table with explicit points or x / y lists."""
    if "points" in table:
        return [(float(x), float(y)) for x, y in table["points"]]
    xs, ys = table["x"], table["y"]
    xs = list(xs) if isinstance(xs, (list, tuple)) else [xs]
    ys = list(ys) if isinstance(ys, (list, tuple)) else [ys]
    return [(float(x), float(y)) for x in xs for y in ys]


def ensemble_starts(table: dict, members: int, radius_xy: Sequence[float]) -> dict:
    """The starts table with every start expanded into its ensemble (``members`` points in a
    row, the start first), the offsets scaled by ``radius_xy`` (x, y: the radius in the
    table's frame; a relative frame stays inside [0, 1])."""
    off = member_offsets(members) * np.asarray(radius_xy, float)[None, :]
    pts = []
    for x, y in _base_points(table):
        p = np.array([x, y])[None, :] + off
        if table.get("frame") == "relative":
            p = np.clip(p, 0.0, 1.0)
        pts.extend((float(a), float(b)) for a, b in p)
    return {"frame": table.get("frame", "relative"), "points": pts}


def _same(a_held, a_end, b_held, b_end, lc: float) -> np.ndarray:
    """Outcome equality (held or not, and where held the same trap) of run pairs."""
    return agreement.outcome_agreement(a_held, a_end, b_held, b_end, length_scale=lc)["agree"]


def _split(held: np.ndarray, end: np.ndarray, lc: float) -> bool:
    """Whether an ensemble's members end in more than one outcome."""
    n = held.size
    i, j = np.triu_indices(n, 1)
    return bool(i.size and not np.all(_same(held[i], end[i], held[j], end[j], lc)))


def ensemble_verdicts(groups: Sequence[dict]) -> dict:
    """The family's verdict over its ensembles.

    Parameters
    ----------
    groups : sequence of dict
        One per start: ``mj_held``, ``ref_held`` (bool arrays, one per member), ``mj_end``,
        ``ref_end`` (``(members, 2)`` end points), ``lc`` (L_c in the same unit) and ``ok``
        (no member stopped by the engine or stalled on the reference).

    Returns
    -------
    dict
        ``starts``, ``members``, ``ill_conditioned_share`` ({``mujoco``, ``reference``}: the
        share of starts whose ensemble splits there), ``ill_conditioned_starts`` (either
        side, or the verdict), ``verdict_split_starts`` (each side one outcome, the member
        pairs' verdicts not one), ``well_conditioned_runs`` (starts one outcome on both sides
        and one verdict, none stopped),
        ``stopped_starts`` (a member stopped by the engine or stalled on the reference),
        ``agreement_well_conditioned`` (the share of those where the outcomes agree) with
        its Wilson ``agreement_ci``, and ``distribution_agreement`` (over all starts, the
        mean share of MuJoCo-reference member pairs that agree); ``ill_conditioned``: the
        groups' optional ``key`` -> the sides where that start splits (:func:`_sides`);
        ``well_conditioned``: key -> whether that start counts in
        ``agreement_well_conditioned``.
    """
    n = len(groups)
    mj_split = np.zeros(n, bool)
    ref_split = np.zeros(n, bool)
    verdict_split = np.zeros(n, bool)
    agree = np.zeros(n, bool)
    overlap = np.full(n, np.nan)
    ok = np.array([bool(g["ok"]) for g in groups], bool)
    for k, g in enumerate(groups):
        mh, rh = np.asarray(g["mj_held"], bool), np.asarray(g["ref_held"], bool)
        me, re = np.asarray(g["mj_end"], float), np.asarray(g["ref_end"], float)
        lc = float(g["lc"])
        mj_split[k], ref_split[k] = _split(mh, me, lc), _split(rh, re, lc)
        i, j = np.meshgrid(np.arange(mh.size), np.arange(rh.size), indexing="ij")
        pairs = _same(mh[i.ravel()], me[i.ravel()], rh[j.ravel()], re[j.ravel()], lc)
        overlap[k] = float(pairs.mean()) if ok[k] else 0.0
        agree[k] = ok[k] and bool(pairs.all())
        verdict_split[k] = bool(pairs.any()) and not bool(pairs.all())
    # a verdict split counts only where neither side splits (a split side already says it)
    verdict_split &= ~mj_split & ~ref_split
    well = ok & ~mj_split & ~ref_split & ~verdict_split
    n_well, n_agree = int(well.sum()), int((agree & well).sum())
    return {
        "starts": n,
        "members": int(max((len(g["mj_held"]) for g in groups), default=0)),
        "ill_conditioned_share": {
            "mujoco": float(mj_split.mean()) if n else math.nan,
            "reference": float(ref_split.mean()) if n else math.nan,
        },
        "ill_conditioned_starts": int((mj_split | ref_split | verdict_split).sum()),
        "verdict_split_starts": int(verdict_split.sum()),
        "well_conditioned_runs": n_well,
        "stopped_starts": int((~ok).sum()),
        "agreement_well_conditioned": n_agree / n_well if n_well else math.nan,
        "agreement_ci": list(wilson(n_agree, n_well)),
        "distribution_agreement": float(np.mean(overlap)) if n else math.nan,
        "ill_conditioned": {
            g["key"]: _sides(mj_split[k], ref_split[k], verdict_split[k])
            for k, g in enumerate(groups)
            if "key" in g
        },
        "well_conditioned": {g["key"]: bool(well[k]) for k, g in enumerate(groups) if "key" in g},
    }


def _sides(mj: bool, ref: bool, verdict: bool = False) -> str:
    """Which sides split: ``""``, ``mujoco``, ``reference`` or ``both``; ``verdict`` where
    neither does but the member pairs' verdicts do."""
    if verdict and not (mj or ref):
        return "verdict"
    return {(False, False): "", (True, False): "mujoco", (False, True): "reference"}.get(
        (bool(mj), bool(ref)), "both"
    )


def _radius_xy(fam: FamilySpec, preset: str) -> tuple[float, float]:
    """:data:`ENSEMBLE_RADIUS_LC` L_c of the preset's first surface in the family's starts
    frame (surface units, or fractions of the bounds in the relative frame)."""
    kw = {} if fam.seeds is None else {"seed": fam.seeds[0]}
    kw.update(dict(fam.variants[0]))
    surface = presets.open_surface(preset, **kw)
    scales = sim.Scales.for_surface(
        surface,
        tip=sim.TipParams(mass_kg=MASS_KG),
        hfield_resolution=grid_keeps_samples(surface, 101),
    )
    r = ENSEMBLE_RADIUS_LC * scales.char_length_m / scales.length_scale_m
    if fam.starts_table().get("frame") == "relative":
        xmin, xmax, ymin, ymax = surface.bounds
        return r / (xmax - xmin), r / (ymax - ymin)
    return r, r


def ensemble_family(fam: FamilySpec, preset: str, members: int) -> FamilySpec:
    """``fam`` with every start expanded into its ensemble of ``members`` (:func:`ensemble_starts`
    at :data:`ENSEMBLE_RADIUS_LC` L_c of ``preset``): start ``i`` of the family becomes
    starts ``i * members ... i * members + members - 1`` of the sweep."""
    table = ensemble_starts(fam.starts_table(), members, _radius_xy(fam, preset))
    return dataclasses.replace(fam, starts=(("frame", table["frame"]), ("points", tuple(table["points"]))))


def ensemble_groups(df, store, members: int) -> list[dict]:
    """The ensembles of one limit sweep (its run table ``df`` and ``store``) as the groups
    of :func:`ensemble_verdicts`: MuJoCo's held flag and end from its rows, the reference's
    from the ``compare`` row and the end of its stored path."""
    mj = df[df["analysis"] == "engine"]
    comp = df[df["analysis"] == "compare"].set_index(["case_id", "start"])
    groups = []
    for case_id, rows in mj.groupby("case_id", sort=False):
        ref_paths = stored_paths(store, case_id, "compare")
        rows = rows.assign(start=rows["start"].astype(int)).sort_values("start")
        for _, g in rows.groupby(rows["start"] // members, sort=True):
            starts = g["start"].to_numpy()
            ref = comp.loc[[(case_id, s) for s in starts]]
            ends = [ref_paths.get(int(s), np.full((1, 2), np.nan))[-1] for s in starts]
            groups.append(
                {
                    "key": f"{case_id}/{int(starts[0]) // members}",
                    "mj_held": g["self_locked"].fillna(False).astype(bool).to_numpy(),
                    "mj_end": g[["end_x", "end_y"]].to_numpy(float),
                    "ref_held": ref["reference_outcome"].isin(HELD).to_numpy(),
                    "ref_end": np.array(ends, float),
                    "lc": float(g["char_length"].iloc[0]),
                    "ok": bool((g["status"] == "ok").all() and (ref["reference_outcome"] != "stalled").all()),
                }
            )
    return groups
