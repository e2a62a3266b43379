"""Study: the quasistatic-limit headlines in both engines, MuJoCo (soft contact) beside Bullet
(hard contact).

The corner of the quasistatic-limit study (:mod:`spine_mj.validate.quasistatic_limit`): the
spring drive at the plan's lowest I_e against the streamline traced on the rig's facets,
every start an ensemble (:mod:`spine_mj.validate.ensembles`), the agreement judged on the
starts well-conditioned on both sides with its Wilson interval and the median Frechet
distance with its bootstrap one. Each family's limit sweeps run once with
``engine = ["mujoco", "bullet"]`` (the same surfaces, starts, ensembles, pool and resumable
stores), and each engine's half is summarised by the study's own rule
(:func:`~spine_mj.validate.quasistatic_limit.corner_summary`). Where the engines end a
start differently the streamline, the closed form of the quasistatic limit (Eqs. 1-3 traced
along the flow), says which one it supports.

Then the misses MuJoCo's full-plan report attributes to its soft contact
(:data:`SOFT_CONTACT_MISSES`, miss reason ``engine_held``: MuJoCo held where the rigid-facet
reference, restarted at MuJoCo's end, moves on) rerun from the same starts with the full
plan's settings in both engines: where Bullet agrees with the reference and MuJoCo still
holds, the miss is MuJoCo's contact model.

Run by ``spine-mj compare-engines --out DIR --headlines N`` (N y starts per surface of the
plan's corner, :func:`~spine_mj.validate.convergence.thin_starts`), which writes
:data:`RESULT_FILE` beside ``engines.json`` and its section
(:func:`spine_mj.validate.report.engine_headlines.section`) into ``engines.md`` (the
committed ``analysis/reports/engines-headlines.md``); it is too long for a validation plan,
whose engines study is the closed forms (:func:`spine_mj.validate.engines.engines_study`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj.choices import COMPARED_ENGINES
from spine_mj.theory import agreement
from spine_mj.validate.convergence import thin_starts
from spine_mj.validate.ensembles import ensemble_family
from spine_mj.validate.intervals import newcombe_difference
from spine_mj.validate.plans import PLANS, FamilySpec, ValidationPlan, paper_starts, relative_starts
from spine_mj.validate.predicted_limits import corner_drives, family_corner
from spine_mj.validate.quasistatic_limit import corner_summary, limit_doc, limit_family_docs
from spine_mj.validate.study_runner import StudyRunner

__all__ = [
    "REPORTED_FULL",
    "RESULT_FILE",
    "SOFT_CONTACT_MISSES",
    "EngineHeadlinesResult",
    "MissStart",
    "engine_headlines",
    "load",
    "run_engine_headlines",
]

#: The study's result, in the folder of ``engines.json``.
RESULT_FILE = "headlines.json"

#: Summary fields kept per family and engine (:func:`corner_summary`).
KEPT = (
    "starts",
    "members",
    "well_conditioned_runs",
    "agreement_well_conditioned",
    "agreement_ci",
    "ill_conditioned_share",
    "stopped_starts",
    "median_frechet",
    "median_frechet_ci",
    "failed_runs",
    "misses",
    "meets_target",
)


@dataclass(frozen=True)
class MissStart:
    """One start of a plan's quasistatic-limit corner.

    Attributes
    ----------
    family : str
        The family's name in the plan.
    preset : str
    seed : int or None
        The surface seed (None: the preset's own).
    variant : tuple
        The generator parameter set (a :class:`~spine_mj.validate.plans.FamilySpec` variant).
    start : int
        Index of the start in the corner's y starts.
    shown : tuple of float
        The start (x, y) in surface units as the report's run table shows it (rounded).
    """

    family: str
    preset: str
    seed: int | None
    variant: tuple
    start: int
    shown: tuple[float, float]

    @property
    def label(self) -> str:
        seed = "" if self.seed is None else f"#{self.seed}"
        var = "".join(f", {k} {v:g}" for k, v in self.variant)
        return f"{self.preset}{seed}{var} at ({self.shown[0]:g}, {self.shown[1]:g})"


#: The runs of the full plan's corner that its report (analysis/reports/validation-full, run
#: table) attributes to MuJoCo's soft contact: miss reason
#: ``engine_held``, MuJoCo held where the rigid-facet reference moves on. The fractal rows
#: of that table run H = 0.7 (its first 60) before H = 0.9; the quick plan's one such miss
#: is the last one here.
SOFT_CONTACT_MISSES = (
    MissStart("single_peak_valley", "paper-single-valley", None, (), 28, (-3.0, -2.71)),
    MissStart("random_gaussian", "paper-random-concave", 2, (), 5, (-9.0, -3.78)),
    MissStart("fractal", "paper-fractal", 2, (("hurst", 0.7),), 2, (-9.0, -3.82)),
    MissStart("fractal", "paper-fractal", 4, (("hurst", 0.7),), 4, (-9.0, -1.64)),
    MissStart("fractal", "paper-fractal", 1, (("hurst", 0.9),), 9, (-9.0, 3.82)),
    MissStart("fractal", "paper-fractal", 2, (("hurst", 0.9),), 0, (-9.0, -6.0)),
)


#: The full plan as its committed report ran the corner (before each family had its own
#: corner and sample, issue 41): the starts :data:`SOFT_CONTACT_MISSES` index.
REPORTED_FULL = dataclasses.replace(
    PLANS["full"],
    limit=dataclasses.replace(
        PLANS["full"].limit,
        corner=(
            ("single_peak_valley", None, paper_starts(np.linspace(-0.25, -5.0, 55).round(4))),
            ("random_gaussian", (1, 2), relative_starts(28)),
            ("fractal", (1, 2, 3, 4, 5), relative_starts(12)),
            ("sandpaper", None, relative_starts(12, 0.25)),
        ),
    ),
)


@dataclass(frozen=True)
class EngineHeadlinesResult:
    """Result of :func:`engine_headlines`.

    Attributes
    ----------
    plan : str
        The plan whose corner ran.
    lowest_ie : float
        The lowest I_e of the corners.
    starts_per_surface : int or None
        Y starts per surface (None: the corner's own).
    engines : tuple of str
    families : dict
        Family -> engine -> the corner summary's :data:`KEPT` fields, and ``difference``
        (Bullet minus MuJoCo agreement with Newcombe's interval) and ``pairs`` (per start
        well-conditioned in both engines, which sides agree with the streamline:
        :func:`_pairs`).
    rechecks : list of dict
        Per :data:`SOFT_CONTACT_MISSES` start and engine: agreement, outcome, miss reason.
    recheck_plan : str
    cpu_s : dict
        Family (and ``rechecks``) -> engine -> ``engine`` (the engine's runs) and
        ``reference`` (the streamlines compared with them) CPU seconds, and ``runs``.
    wall_s : float
    corners : dict
        Family -> preset -> ``{"ie", "K"}``: each surface's own corner (empty in a result
        made when every family ran at the plan's lowest I_e and the default spring).
    """

    plan: str
    lowest_ie: float
    starts_per_surface: int | None
    engines: tuple[str, ...]
    families: dict
    rechecks: list[dict]
    recheck_plan: str
    cpu_s: dict
    wall_s: float
    corners: dict = dataclasses.field(default_factory=dict)

    def as_dict(self) -> dict:
        return {**dataclasses.asdict(self), "engines": list(self.engines)}

    @classmethod
    def from_dict(cls, d: dict) -> EngineHeadlinesResult:
        """The result :meth:`as_dict` wrote (:data:`RESULT_FILE`)."""
        return cls(**{**d, "engines": tuple(d["engines"])})


def _both_engines(doc: dict, name: str, engines: Sequence[str]) -> dict:
    """``doc`` run in every engine of ``engines`` (the sweep key ``engine``), named ``name``,
    each engine at its own step rule: a family's ``timestep_factor`` (MuJoCo's step refined
    where its sliding hops left the Frechet distance unconverged) is a MuJoCo setting that
    Bullet's sweep refuses, and the study compares agreements, which that step leaves
    unchanged (the single peak and valley: 64 of 64 at both)."""
    grid = {k: v for k, v in doc["grid"].items() if k != "timestep_factor"}
    return {**doc, "sweep": {**doc["sweep"], "name": name}, "grid": {**grid, "engine": list(engines)}}


def _corner_docs(
    plan: ValidationPlan, starts: int | None, engines
) -> tuple[list[tuple[FamilySpec, str, dict]], dict]:
    """``(corner family, store name, config)`` of every limit sweep of the plan's corner, each
    surface at its own corner (I_e, K) as the quasistatic-limit study runs it
    (:func:`~spine_mj.validate.predicted_limits.family_corner`), its y starts thinned to
    ``starts`` per surface (None: all), in every engine; and those corners, family -> preset
    -> ``{"ie", "K"}``; each engine at its own step rule (:func:`_both_engines`)."""
    out, corners = [], {}
    for fam in plan.families:
        corner = plan.limit.corner_family(fam)
        own = family_corner(plan, corner)["presets"]
        corners[fam.name] = corner_drives(own)
        if starts is not None:
            corner = thin_starts(corner, starts)
        for name, doc in limit_family_docs(plan, corner, own):
            out.append(
                (corner, f"engines-limit/{name}", _both_engines(doc, f"engines-limit-{name}", engines))
            )
    return out, corners


def miss_family(plan: ValidationPlan, miss: MissStart) -> FamilySpec:
    """The corner family of ``plan`` reduced to ``miss``'s surface and start, its ensemble
    the one the plan ran (:func:`~spine_mj.validate.ensembles.ensemble_family` over the
    whole family: the stencil's radius is its first surface's), as explicit points."""
    (fam,) = [f for f in plan.families if f.name == miss.family]
    corner = plan.limit.corner_family(fam)
    members = max(int(plan.limit.ensemble_members), 1)
    table = ensemble_family(corner, miss.preset, members).starts_table() if members > 1 else None
    if table is None:
        t = dict(corner.starts)
        starts = (*[(k, v) for k, v in t.items() if k != "y"], ("y", (t["y"][miss.start],)))
    else:
        pts = tuple(table["points"][miss.start * members : (miss.start + 1) * members])
        starts = (("frame", table["frame"]), ("points", pts))
    return dataclasses.replace(
        corner,
        presets=(miss.preset,),
        seeds=None if miss.seed is None else (miss.seed,),
        variants=(tuple(miss.variant),),
        starts=starts,
    )


def _miss_doc(plan: ValidationPlan, miss: MissStart, k: int, engines) -> dict:
    """The sweep of one soft-contact miss: its ensemble's points run as the plan ran them."""
    members = max(int(plan.limit.ensemble_members), 1)
    fam = miss_family(plan, miss)
    doc = limit_doc(
        dataclasses.replace(plan, limit=dataclasses.replace(plan.limit, ensemble_members=1)),
        fam,
        miss.preset,
        f"engines-miss-{k}",
    )
    doc["grid"]["ensemble_members"] = members
    return _both_engines(doc, f"engines-miss-{k}", engines)


def run_engine_headlines(
    out_dir: Path,
    *,
    plan: str = "quick",
    starts_per_surface: int | None = None,
    rechecks: Sequence[MissStart] = SOFT_CONTACT_MISSES,
    recheck_plan: str = "full",
    workers: int | None = None,
) -> EngineHeadlinesResult:
    """:func:`engine_headlines` with its sweeps stored under ``out_dir/sweeps``."""
    runner = StudyRunner(Path(out_dir).resolve(), workers, None, time.perf_counter())
    return engine_headlines(
        PLANS[plan],
        runner,
        starts_per_surface=starts_per_surface,
        rechecks=rechecks,
        recheck_plan=REPORTED_FULL if recheck_plan == "full" else PLANS[recheck_plan],
    )


def engine_headlines(
    plan: ValidationPlan,
    runner: StudyRunner,
    *,
    starts_per_surface: int | None = None,
    rechecks: Sequence[MissStart] = SOFT_CONTACT_MISSES,
    recheck_plan: ValidationPlan = REPORTED_FULL,
    engines: Sequence[str] = COMPARED_ENGINES,
) -> EngineHeadlinesResult:
    """The corner agreement per family in every engine, and the soft-contact misses rechecked.

    Parameters
    ----------
    plan : ValidationPlan
        Whose corner runs (families, seeds, starts, ensembles, lowest I_e, hfield).
    runner : StudyRunner
        Runs the sweeps (all at once, sharing the workers) into resumable stores.
    starts_per_surface : int, optional
        Y starts per surface kept of each corner family (both ends kept; None: all).
    rechecks : sequence of MissStart
        Starts of ``recheck_plan``'s corner to rerun in every engine.
    recheck_plan : ValidationPlan
        The plan whose report named ``rechecks`` (its settings and ensembles).
    engines : sequence of str

    Returns
    -------
    EngineHeadlinesResult
    """
    t0 = time.perf_counter()
    runner.study = "engines"
    corner, corners = _corner_docs(plan, starts_per_surface, engines)
    misses = [
        (m, f"engines-miss/{k}", _miss_doc(recheck_plan, m, k, engines)) for k, m in enumerate(rechecks)
    ]
    done = runner.many([(doc, name) for _, name, doc in corner + misses], "corner and misses, both engines")
    swept = done[: len(corner)]
    families, cpu = {}, {}
    for fam in dict.fromkeys(f for f, _, _ in corner):
        results = [res for (f, _, _), res in zip(corner, swept) if f is fam]
        families[fam.name], cpu[fam.name] = _family(plan, fam, results, engines)
    rows = []
    miss_cpu = {e: {"engine": 0.0, "reference": 0.0, "runs": 0} for e in engines}
    for miss, res in zip(rechecks, done[len(corner) :]):
        fam = miss_family(recheck_plan, miss)
        for e in engines:
            summ, allc = corner_summary(recheck_plan, fam, [_engine_half(res, e)])
            rows.append(_recheck_row(miss, e, summ, allc))
            for k, v in _cpu(res[0], e).items():
                miss_cpu[e][k] += v
    if rechecks:
        cpu["rechecks"] = miss_cpu
    return EngineHeadlinesResult(
        plan=plan.name,
        lowest_ie=min(c["ie"] for own in corners.values() for c in own.values()),
        starts_per_surface=starts_per_surface,
        engines=tuple(engines),
        families=families,
        rechecks=rows,
        recheck_plan=recheck_plan.name,
        cpu_s=cpu,
        wall_s=round(time.perf_counter() - t0, 1),
        corners=corners,
    )


def _engine_half(result, engine: str):
    """A sweep's ``(run table, store)`` with only ``engine``'s cases."""
    df, store = result
    return df[df["engine"] == engine], store


def _cpu(df: pd.DataFrame, engine: str) -> dict:
    """CPU seconds of ``engine``'s runs and of the streamlines compared with them, and runs."""
    d = df[df["engine"] == engine]
    runs = d["analysis"] == "engine"
    return {
        "engine": float(d.loc[runs, "cpu_s"].sum()),
        "reference": float(d.loc[~runs, "cpu_s"].sum()),
        "runs": int(runs.sum()),
    }


def _family(plan: ValidationPlan, fam: FamilySpec, results, engines) -> tuple[dict, dict]:
    """One family's per-engine summaries (:data:`KEPT`), engine difference and start pairs;
    and its CPU seconds per engine."""
    out, cpu, starts = {}, {}, {}
    for e in engines:
        halves = [_engine_half(r, e) for r in results]
        summ, allc = corner_summary(plan, fam, halves)
        out[e] = {k: summ[k] for k in KEPT}
        starts[e] = _start_outcomes(plan, halves, allc, summ["ill_conditioned"])
        cpu[e] = {k: sum(_cpu(r[0], e)[k] for r in results) for k in ("engine", "reference", "runs")}
    if len(engines) == 2:
        a, b = (_rate(out[e]) for e in engines)
        out["difference"] = newcombe_difference(b, a)
        out["pairs"] = _pairs(*(starts[e] for e in engines))
    return out, cpu


def _rate(summ: dict) -> dict:
    """The corner agreement as a rate record (:func:`newcombe_difference`)."""
    lo, hi = summ["agreement_ci"]
    return {"rate": summ["agreement_well_conditioned"], "ci_low": lo, "ci_high": hi}


def _start_outcomes(plan: ValidationPlan, halves, allc: pd.DataFrame, ill: dict) -> pd.DataFrame:
    """Per start (its own ensemble member) of one engine: agreement with the streamline,
    whether the start is well-conditioned and finished on every side, the engine's held flag
    and end, L_c; indexed by the surface, its L_c and the start point (the same in every
    engine)."""
    members = max(int(plan.limit.ensemble_members), 1)
    runs = []
    for df, _ in halves:
        mj = df[(df["analysis"] == "engine") & (df["start"].astype(int) % members == 0)].copy()
        mj["start"] = mj["start"].astype(int) // members
        runs.append(mj)
    mj = pd.concat(runs, ignore_index=True).set_index(["case_id", "start"])
    key = list(zip(allc["case_id"], allc["start"].astype(int)))
    return pd.DataFrame(
        {
            "agree": allc["agree"].fillna(False).astype(bool).to_numpy(),
            "well": [
                not ill.get(f"{c}/{s}", "") and st == "ok" and ref != "stalled"
                for (c, s), st, ref in zip(key, allc["mujoco_status"], allc["reference_outcome"])
            ],
            "held": [bool(mj.loc[k, "self_locked"]) for k in key],
            "end_x": [float(mj.loc[k, "end_x"]) for k in key],
            "end_y": [float(mj.loc[k, "end_y"]) for k in key],
            "lc": allc["surface_lc"].to_numpy(float),
        },
        index=pd.MultiIndex.from_arrays(
            [allc["surface"], allc["surface_lc"].round(9), allc["start_x"].round(9), allc["start_y"].round(9)]
        ),
    )


def _pairs(a: pd.DataFrame, b: pd.DataFrame) -> dict:
    """Over the starts well-conditioned and finished in both engines ``a`` and ``b`` (and on
    the reference): how many both agree with the streamline, only ``a`` (the closed form
    supports ``a``), only ``b``, neither; and how many the two engines end alike (held or
    free, and where held the same trap: :func:`spine_mj.theory.agreement.outcome_agreement`)."""
    both = a.merge(b, left_index=True, right_index=True, suffixes=("_a", "_b"))
    both = both[both["well_a"] & both["well_b"]]
    lc = both["lc_a"].to_numpy(float)
    same = np.zeros(len(both), bool)
    for scale in np.unique(lc):  # each surface's own L_c (a family's grits differ 10-fold)
        m = lc == scale
        same[m] = agreement.outcome_agreement(
            both["held_a"].to_numpy()[m],
            both[["end_x_a", "end_y_a"]].to_numpy()[m],
            both["held_b"].to_numpy()[m],
            both[["end_x_b", "end_y_b"]].to_numpy()[m],
            length_scale=float(scale),
        )["agree"]
    ga, gb = both["agree_a"].to_numpy(bool), both["agree_b"].to_numpy(bool)
    return {
        "starts": int(len(both)),
        "both_agree": int((ga & gb).sum()),
        "only_first": int((ga & ~gb).sum()),
        "only_second": int((~ga & gb).sum()),
        "neither": int((~ga & ~gb).sum()),
        "engines_alike": int(np.sum(same)),
    }


def _recheck_row(miss: MissStart, engine: str, summ: dict, allc: pd.DataFrame) -> dict:
    """One soft-contact miss in one engine: its own start's comparison and its ensemble."""
    (r,) = allc.to_dict("records")
    sides = next(iter(summ["ill_conditioned"].values()), "")
    return {
        "start": miss.label,
        "family": miss.family,
        "engine": engine,
        "agree": bool(r["agree"]) if r["agree"] == r["agree"] else False,
        "ill_conditioned": sides,
        "reference_outcome": r["reference_outcome"],
        "end_reason": r["end_reason"],
        "status": r["mujoco_status"],
        "miss_reason": r["miss_reason"] if isinstance(r["miss_reason"], str) else "",
    }


def load(folder: Path) -> EngineHeadlinesResult | None:
    """The result in ``folder`` (:data:`RESULT_FILE`), None where there is none."""
    import json

    path = Path(folder) / RESULT_FILE
    return EngineHeadlinesResult.from_dict(json.loads(path.read_text())) if path.is_file() else None
