"""Study 2: the quasistatic limit. Spring-drive paths at the lowest inertia number against the
streamline, per surface family, with the engine settings that limit agreement varied.

Three comparisons per run separate the errors (the sweep's ``compare`` analysis): MuJoCo
against the streamline traced on the surface its tip touches, the rig's facets dilated by
the tip (like for like: what the targets judge), MuJoCo against the streamline on the
smooth surface (the total), and the two streamlines against each other (the geometry).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from spine_mj.presets import calibrated_mu
from spine_mj.theory.agreement import MISS_REASONS
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET
from spine_mj.validate.convergence import GRID_ONLY, REFINEMENTS, family_convergence, thin_starts
from spine_mj.validate.ensembles import ensemble_family, ensemble_groups, ensemble_verdicts
from spine_mj.validate.intervals import bootstrap, meets_target, wilson
from spine_mj.validate.landing_verdicts import landing_judged, landing_summary
from spine_mj.validate.miss_causes import MISS_CAUSES, miss_cause
from spine_mj.validate.paths import stored_paths, tip_radius
from spine_mj.validate.plans import RECOMMENDED, FamilySpec, ValidationPlan
from spine_mj.validate.predicted_limits import corner_drives, stored_corners
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import engine_grid, family_doc, gridded, refused_by_rig

__all__ = [
    "LimitPath",
    "QuasistaticLimitResult",
    "corner_summary",
    "limit_doc",
    "limit_family_docs",
    "quasistatic_limit",
]

#: Columns of the per-run rows.
RUN_COLUMNS = (
    "family",
    "preset",
    "surface",
    "start",
    "start_x",
    "start_y",
    "agree",
    "frechet",
    "lateral_deviation",
    "end_distance",
    "reference_outcome",
    "end_reason",
    "end_detail",
    "mujoco_status",
    "agree_smooth",
    "frechet_smooth",
    "geometry_frechet",
    "agree_streamline",
    "frechet_streamline",
    "agree_landing",
    "frechet_landing",
    "landing_falls",
    "miss_reason",
    "miss_offset",
    "reference_slide_fraction",
    "tip_peak_ie",
    "ill_conditioned",
)


@dataclass(frozen=True)
class LimitPath:
    """The three paths of one start, for the figure.

    Attributes
    ----------
    smooth, tri, mujoco : ndarray, shape (n, 2)
        x, y in surface units of the streamline on the smooth surface, the streamline on
        MuJoCo's facets, and the MuJoCo run.
    start : tuple of float
        The start.
    """

    smooth: np.ndarray
    tri: np.ndarray
    mujoco: np.ndarray
    start: tuple[float, float]

    def as_dict(self) -> dict:
        return {"smooth": self.smooth, "tri": self.tri, "mujoco": self.mujoco, "start": self.start}


@dataclass(frozen=True)
class QuasistaticLimitResult:
    """Result of :func:`quasistatic_limit`.

    Attributes
    ----------
    families : dict
        Family name -> summary: ``runs``, ``ok_runs``, ``outcome_agreement``,
        ``mean_frechet``, ``median_frechet``, ``mean_lateral_deviation`` (against the
        facet-traced streamline, and where it falls the fall-landing reference:
        :func:`landing_judged`; ``landing_runs`` so judged, ``outcome_agreement_streamline``
        and ``median_frechet_streamline`` the plain streamline's, ``landing_explained`` its
        misses the landing agrees with, ``landing_lost`` its agreements the landing does
        not), ``outcome_agreement_compliant`` and
        ``median_frechet_compliant`` (against the compliant-drive streamline of the run's
        spring), ``outcome_agreement_smooth``, ``median_frechet_smooth``
        (against the smooth one), ``mean_geometry_frechet``, ``failed_runs`` (engine stops
        by status), ``reference_stalled`` (reference streamlines stalled in a groove),
        ``misses`` (disagreeing runs the engine finished, by
        :func:`spine_mj.theory.agreement.miss_reason`, each with its offsets over L_c),
        ``slide_runs`` (runs whose reference slides under gravity somewhere:
        :func:`spine_mj.theory.agreement.slide_fraction` > 0), ``median_tip_peak_ie`` (the engine
        tip's own peak speed as an inertia number), ``meets_target``.
    runs : list of dict
        Per-run rows (:data:`RUN_COLUMNS`).
    variations : dict
        Engine setting label -> summary on the single peak (the recommended one first).
    paths : dict
        Preset of the single peak/valley family -> list of :class:`LimitPath`.
    lowest_ie : float
        The lowest I_e of the families' corners.
    convergence : dict
        Family -> its solution verification
        (:func:`~spine_mj.validate.convergence.family_convergence`): per refinement
        (``dt_halved``, ``hfield_doubled``, ...) the change of each headline and whether it
        is converged; empty where the plan refines nothing.
    """

    families: dict[str, dict]
    runs: list[dict]
    variations: dict[str, dict]
    paths: dict[str, list[LimitPath]]
    lowest_ie: float
    convergence: dict = field(default_factory=dict)
    corners: dict = field(default_factory=dict)

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        fams = self.families
        return {
            "lowest_ie": self.lowest_ie,
            "corner": {fam: corner_drives(v["presets"]) for fam, v in self.corners.items()},
            "corner_limits": self.corners,
            "outcome_agreement_at_lowest_ie": {k: v["outcome_agreement"] for k, v in fams.items()},
            "mean_frechet_at_lowest_ie": {k: v["mean_frechet"] for k, v in fams.items()},
            "median_frechet_at_lowest_ie": {k: v["median_frechet"] for k, v in fams.items()},
            "failed_runs": {k: v["failed_runs"] for k, v in fams.items()},
            "limit_families": fams,
            "limit_variations": self.variations,
            "convergence": self.convergence,
        }

    def as_dict(self) -> dict:
        return {
            "families": self.families,
            "runs": self.runs,
            "variations": self.variations,
            "paths": {k: [p.as_dict() for p in v] for k, v in self.paths.items()},
            "lowest_ie": self.lowest_ie,
            "convergence": self.convergence,
            "corners": self.corners,
        }


def quasistatic_limit(plan: ValidationPlan, runner: StudyRunner) -> QuasistaticLimitResult:
    """Study 2: spring drive at each family's own corner ``(I_e, K)``, from its predicted
    limits (:func:`~spine_mj.validate.predicted_limits.family_corner`; a corner the rig
    refuses gives no verdict), against the streamline, with the three comparisons of the
    module docstring per run (lengths over L_c; a run the engine stopped disagrees, listed
    by status in ``failed_runs``), its refinements, then on the single peak the settings of
    ``plan.limit.variations`` one at a time.

    Parameters
    ----------
    plan : ValidationPlan
        The families, their corners' sample sizes and the refinements.
    runner : StudyRunner
        Runs the sweeps of ``plan`` into resumable stores under the output folder.

    Returns
    -------
    QuasistaticLimitResult
    """
    runner.study = "limit"
    families, runs_rows, paths = {}, [], {}
    corner = [plan.limit.corner_family(fam) for fam in plan.families]
    with runner.phase("the quasistatic corners of the families"):
        corners = stored_corners(plan, corner, runner)
    for fam in corner:
        for c in corners[fam.name]["presets"].values():
            c["timestep_factor"] = fam.timestep_factor
    at = {name: c["presets"] for name, c in corners.items()}
    docs = [(fam, name, doc) for fam in corner for name, doc in limit_family_docs(plan, fam, at[fam.name])]
    for fam in corner:  # a corner the rig refuses (too many steps a run) gives no verdict
        refused = refused_by_rig([doc for f, _, doc in docs if f is fam])
        if refused:
            corners[fam.name]["refused"] = refused
    corner = [fam for fam in corner if "refused" not in corners[fam.name]]
    docs = [d for d in docs if d[0] in corner]
    variations = _variation_docs(plan, at[corner[0].name][corner[0].presets[0]])
    refinements = _refinement_docs(plan, corner, at)
    # every sweep of the study at once: the workers stay busy across the sweeps' ends
    done = runner.many(
        [(doc, f"limit/{name}") for _, name, doc in docs]
        + [(doc, name) for _, name, doc in variations]
        + [(doc, name) for _, _, name, doc in refinements],
        "corner, engine variations and refinements",
    )
    swept = dict(zip([name for _, name, _ in docs], done[: len(docs)]))
    refined_done = done[len(docs) + len(variations) :]
    convergence = {}
    for fam in corner:
        summ, allc = corner_summary(plan, fam, [swept[name] for f, name, _ in docs if f is fam], paths)
        ill = summ.pop("ill_conditioned")
        well = summ.pop("well_conditioned")
        allc["well_conditioned"] = [
            well.get(f"{c}/{int(s)}", False) for c, s in zip(allc["case_id"], allc["start"])
        ]
        summ["corner"] = corner_drives(at[fam.name])
        families[fam.name] = summ
        if plan.limit.convergence_starts > 0:
            refined = _refined_rows(fam.name, plan.limit.convergence_refinements, refinements, refined_done)
            convergence[fam.name] = family_convergence(summ, allc, refined)
        for _, r in allc.iterrows():
            row = {k: _plain(r[k]) for k in RUN_COLUMNS if k != "ill_conditioned"}
            row["ill_conditioned"] = ill.get(f"{r['case_id']}/{int(r['start'])}", "")
            runs_rows.append(row)
    return QuasistaticLimitResult(
        families=families,
        runs=runs_rows,
        variations=_variations(plan, variations, done[len(docs) : len(docs) + len(variations)], runs_rows),
        paths=paths,
        lowest_ie=min(c["ie"] for own in at.values() for c in own.values()),
        convergence=convergence,
        corners=corners,
    )


def corner_summary(
    plan: ValidationPlan, fam: FamilySpec, results, paths: dict | None = None
) -> tuple[dict, pd.DataFrame]:
    """One corner family's summary and comparison rows from its limit sweeps.

    Parameters
    ----------
    plan : ValidationPlan
        The plan the sweeps were written for (its ``limit.ensemble_members``).
    fam : FamilySpec
        The family (its corner: :meth:`~spine_mj.validate.plan_sections.LimitPlan.corner_family`).
    results : sequence of (DataFrame, Path)
        Run table and store of each of the family's limit sweeps (of one engine).
    paths : dict, optional
        Filled with the single peak/valley family's :class:`LimitPath` per preset.

    Returns
    -------
    summary : dict
        The family's entry of :attr:`QuasistaticLimitResult.families`, with
        ``ill_conditioned`` (start key ``case_id/start`` -> the sides it splits on).
    rows : DataFrame
        The ``compare`` rows of every run (each ensemble's own start), with its family,
        preset, end reason and engine status (``mujoco_status``, whichever the engine).
    """
    groups: list[dict] = []
    paths = {} if paths is None else paths
    comps = [_sweep_comparison(plan, fam, df, store, paths, groups) for df, store in results]
    allc = pd.concat(comps, ignore_index=True)
    return _limit_summary(allc, groups), allc


def _limit_summary(allc: pd.DataFrame, groups: list[dict]) -> dict:
    """One family's summary of the quasistatic-limit study from its comparison rows
    ``allc`` and ensemble groups: agreements, distances, failures and the target verdict."""
    summ = _family_summary(allc)
    summ.update(ensemble_verdicts(groups))
    failed = allc.loc[allc["mujoco_status"] != "ok", "mujoco_status"].value_counts()
    summ.update(
        {
            "median_frechet_smooth": float(np.nanmedian(allc["frechet_smooth"])),
            "outcome_agreement_smooth": float(allc["agree_smooth"].fillna(False).astype(bool).mean()),
            "mean_geometry_frechet": float(np.nanmean(allc["geometry_frechet"])),
            # against the compliant-drive streamline of the run's own spring (NaN in a
            # store written before compare had it)
            **_compliant_summary(allc),
            "failed_runs": {str(k): int(v) for k, v in failed.items()},
            # no progress even with the step cut to dl / 2**max_halvings (a fixed step
            # once zig-zagged across grit valleys narrower than itself and stalled
            # there: docs/physics.md §2)
            "reference_stalled": int((allc["reference_outcome"] == "stalled").sum()),
            "misses": _misses(allc),
            "slide_runs": int((allc["reference_slide_fraction"] > 0).sum()),
            **landing_summary(allc),
            "median_tip_peak_ie": float(np.nanmedian(allc["tip_peak_ie"])),
        }
    )
    summ.update(_intervals(allc, summ))
    summ["meets_target"] = bool(
        meets_target(
            summ["agreement_well_conditioned"],
            summ["agreement_ci"],
            OUTCOME_TARGET,
            higher_is_better=True,
        )
        and meets_target(
            summ["median_frechet"], summ["median_frechet_ci"], FRECHET_TARGET, higher_is_better=False
        )
        and "penetration" not in failed
    )
    return summ


def _refinement_docs(
    plan: ValidationPlan, corner: list[FamilySpec], at: dict | None = None
) -> list[tuple[str, str, str, dict]]:
    """``(family, refinement key, store name, config)`` of every refinement of every corner
    family's thinned starts (:func:`~spine_mj.validate.convergence.thin_starts`), one per
    preset, at the preset's corner ``at[family][preset]`` (a gridded surface's hfield is refined
    through its interpolant, :func:`spine_mj.surfaces.refine_grid`)."""
    if plan.limit.convergence_starts <= 0:
        return []
    out = []
    for fam in corner:
        surfaces = len(fam.presets) * len(fam.seeds or (None,)) * len(fam.variants)
        every = len(fam.starts_table()["y"])
        thin = thin_starts(
            fam,
            every
            if fam.name in plan.limit.convergence_all_starts
            else -(-plan.limit.convergence_starts // surfaces),
        )
        for key in plan.limit.convergence_refinements:
            for preset in fam.presets:
                if key in GRID_ONLY and not gridded(preset, fam):
                    continue
                name = f"limit-refined-{key}-{preset}"
                doc = limit_doc(
                    plan, thin, preset, name, REFINEMENTS[key], (at or {}).get(fam.name, {}).get(preset)
                )
                out.append((fam.name, key, f"limit-refined/{key}/{preset}", doc))
    return out


def _refined_rows(family: str, keys, refinements, results) -> dict[str, pd.DataFrame | None]:
    """Refinement key -> the comparison rows of ``family``'s refined sweeps (one run per
    start; ``refinements`` of :func:`_refinement_docs` and their sweeps' ``results``), None
    where no preset of the family could be refined."""
    out: dict[str, pd.DataFrame | None] = {key: None for key in keys}
    for (fam, key, _, _), (df, _) in zip(refinements, results):
        if fam == family:
            rows = landing_judged(df[df["analysis"] == "compare"])
            mj = df[df["analysis"] == "engine"].set_index(["case_id", "start"])
            rows["surface_lc"] = [mj.loc[k, "char_length"] for k in zip(rows["case_id"], rows["start"])]
            out[key] = rows if out[key] is None else pd.concat([out[key], rows], ignore_index=True)
    return out


def limit_doc(
    plan: ValidationPlan, fam: FamilySpec, preset: str, name: str, overrides=(), corner: dict | None = None
) -> dict:
    """The sweep config of one preset of ``fam`` at its ``corner`` (``{"ie", "K"}``; None:
    the plan's ``lowest_ie`` and the default spring, the engines' cross-check's corner) with
    the rig's tip on both sides (``overrides``: an engine variation)."""
    ie = plan.lowest_ie if corner is None else float(corner["ie"])
    k = None if corner is None else float(corner["K"])
    res = dict(overrides).get("hfield_resolution", plan.hfield_resolution)
    tip = tip_radius(preset, fam.seeds, res)
    mu = fam.mu if fam.mu is not None else calibrated_mu(preset)
    grid = {
        "mu": mu,
        "tip_radius": tip,
        "dl": tip / 2,
        **engine_grid(plan, overrides, preset, fam.seeds, tip, mu=mu, ie=ie, stiffness_number=k),
    }
    step_factor = fam.timestep_factor * float(dict(overrides).get("timestep_factor", 1.0))
    if step_factor != 1.0:  # the family's own step, a refinement's relative to it
        grid["timestep_factor"] = step_factor
    members = plan.limit.ensemble_members if not overrides else 1
    if members > 1:
        fam = ensemble_family(fam, preset, members)
        grid["ensemble_members"] = members
    # a variation or refinement level, or a plan that leaves it out: the rigid reference alone
    if overrides or not plan.limit.compliant_reference:
        grid["compliant_reference"] = False
    doc = family_doc(
        fam,
        name=name,
        preset=preset,
        drive={"protocol": "spring", "ie": ie, **({} if k is None else {"K": k})},
        grid=grid,
        miss_reasons=not overrides,
    )
    if members > 1:
        doc["surfaces"] = _chunked(doc["surfaces"], doc["starts"], CASE_STARTS * members)
    return doc


def limit_family_docs(
    plan: ValidationPlan, fam: FamilySpec, corners: dict | None = None
) -> list[tuple[str, dict]]:
    """The sweeps of ``fam``'s corner as ``(name, config)``: one for the whole family where
    its presets share one grid (mu, tip radius, engine, drive: so its cases share the
    workers, and one heavy case of one preset does not leave a core idle while the next
    preset waits), else one per preset (:func:`limit_doc`, each at its corner
    ``corners[preset]``; None: the plan's lowest I_e)."""
    docs = [
        (preset, limit_doc(plan, fam, preset, f"limit-{preset}", corner=(corners or {}).get(preset)))
        for preset in fam.presets
    ]
    first = docs[0][1]
    own_starts = all("starts" in e for _, d in docs for e in d["surfaces"])
    shared = all(d["grid"] == first["grid"] and d["drive"] == first["drive"] for _, d in docs)
    if len(docs) == 1 or not (own_starts and shared):
        return docs
    merged = {**first, "sweep": {**first["sweep"], "name": f"limit-{fam.name}"}}
    merged["surfaces"] = [e for _, d in docs for e in d["surfaces"]]
    return [(fam.name, merged)]


#: Starts (whole ensembles) per case of a limit sweep: a preset's starts split into cases of at
#: most this many, so that the study's cases keep every worker busy (a case's MuJoCo runs
#: share its threads, but its reference streamlines are serial Python), while each case's
#: references still step enough starts side by side to pay their per-step overhead (measured
#: on the quick plan's limit study: 190 s at 3, 169 s at 6, 142 s at 12, 145 s at 24). Each
#: start's runs and comparison are its own, so the numbers do not depend on the split.
CASE_STARTS = 12


def _chunked(surfaces: list[dict], starts: dict, size: int) -> list[dict]:
    """Each ``surfaces`` entry once per run of ``size`` points of ``starts`` (a points table),
    with those points as its own starts."""
    pts = list(starts["points"])
    chunks = [pts[i : i + size] for i in range(0, len(pts), size)]
    return [
        {**entry, "starts": {"frame": starts["frame"], "points": c}} for entry in surfaces for c in chunks
    ]


def _sweep_comparison(
    plan: ValidationPlan, fam: FamilySpec, df: pd.DataFrame, store, paths: dict, groups: list
) -> pd.DataFrame:
    """The ``compare`` rows of one limit sweep (its run table ``df`` and ``store``; each
    ensemble's own start) with the MuJoCo row's end and status and the row's preset; the
    ensembles' outcomes go into ``groups`` (:func:`~spine_mj.validate.ensembles.ensemble_verdicts`),
    the single peak/valley family's paths into ``paths``."""
    members = max(int(plan.limit.ensemble_members), 1)
    groups.extend(ensemble_groups(df, store, members))
    df = df[df["start"].astype(int) % members == 0].copy()  # the runs: each ensemble's own start
    df["start"] = df["start"].astype(int) // members
    comp = landing_judged(df[df["analysis"] == "compare"])
    mj = df[df["analysis"] == "engine"].set_index(["case_id", "start"])
    key = list(zip(comp["case_id"], comp["start"].astype(int)))
    comp["family"] = fam.name
    # a preset surface's label is the preset's name, with "#seed" after a seeded one
    comp["preset"] = comp["surface"].astype(str).str.partition("#")[0]
    comp["surface_lc"] = [mj.loc[k, "char_length"] for k in key]  # tells a generator variant apart
    comp["end_reason"] = [mj.loc[k, "end_reason"] for k in key]
    comp["end_detail"] = [mj.loc[k, "end_detail"] for k in key]
    comp["mujoco_status"] = [mj.loc[k, "status"] for k in key]
    if fam.name == "single_peak_valley":
        for case_id, grp in comp.groupby("case_id", sort=False):
            smooth = stored_paths(store, case_id, "quasistatic")
            facets = stored_paths(store, case_id, "compare")
            mpaths = stored_paths(store, case_id, "engine")
            for s, x0, y0 in zip(grp["start"].astype(int) * members, grp["start_x"], grp["start_y"]):
                empty = np.zeros((0, 2))
                paths.setdefault(grp["preset"].iloc[0], []).append(
                    LimitPath(smooth[s], facets.get(s, empty), mpaths.get(s, empty), (x0, y0))
                )
    return comp


def _variation_docs(plan: ValidationPlan, corner: dict | None = None) -> list[tuple[str, str, dict]]:
    """``(label, store name, config)`` of each engine variation of ``plan`` on the first
    family's first preset, at that family's ``corner``."""
    fam0 = plan.limit.corner_family(plan.families[0])
    preset = fam0.presets[0]
    out = []
    for label, ov in plan.limit.variations:
        tag = "-".join(f"{k}{v}" for k, v in ov)
        out.append(
            (
                label,
                f"limit-var/{preset}-{tag}",
                limit_doc(plan, fam0, preset, f"limit-var-{label}", ov, corner),
            )
        )
    return out


def _variations(plan: ValidationPlan, docs, results, runs_rows: list[dict]) -> dict[str, dict]:
    """The engine variations (``docs`` of :func:`_variation_docs` and their sweeps'
    ``results``) after the recommended settings (summarised from ``runs_rows``)."""
    variations = {}
    preset = plan.limit.corner_family(plan.families[0]).presets[0]
    for (label, _, _), (df, _) in zip(docs, results):
        comp = df[df["analysis"] == "compare"]
        settings = dict(dict(plan.limit.variations)[label])
        variations[label] = {**_family_summary(comp), "settings": settings, "surface": preset}
    base = [r for r in runs_rows if r["preset"] == preset]
    return {
        RECOMMENDED[0]: {
            "outcome_agreement": float(np.mean([bool(r["agree"]) for r in base])),
            "median_frechet": float(np.nanmedian([r["frechet"] for r in base])),
            "mean_frechet": float(np.nanmean([r["frechet"] for r in base])),
            "mean_lateral_deviation": float(np.nanmean([r["lateral_deviation"] for r in base])),
            "runs": len(base),
            "settings": {},
            "surface": preset,
        },
        **variations,
    }


def _intervals(comp, summ: dict) -> dict:
    """The family's 95 % intervals: Wilson on the outcome agreement (``outcome_agreement_ci``, over
    all runs, a stopped run disagreeing), percentile bootstrap over runs on the median
    Frechet distance (``median_frechet_ci``)."""
    n = summ["runs"]
    agree = int(round(summ["outcome_agreement"] * n)) if n else 0
    return {
        "outcome_agreement_ci": list(wilson(agree, n)),
        "median_frechet_ci": list(bootstrap(comp["frechet"].to_numpy(float))),
    }


def _misses(comp) -> dict[str, dict]:
    """Disagreeing runs by miss reason: count and offsets over L_c (separatrix, diverged),
    the runs by physical cause (:func:`miss_cause`) and each miss (``case_id``, ``start``,
    ``cause``, ``offset``)."""
    out = {}
    missed = comp[comp["miss_reason"].astype(str) != ""] if "miss_reason" in comp else comp.iloc[:0]
    for reason in MISS_REASONS:
        rows = missed[missed["miss_reason"] == reason]
        if len(rows):
            each = [
                {
                    "case_id": str(r.get("case_id", "")),
                    "start": int(r.get("start", -1)),
                    "cause": miss_cause(r),
                    "offset": _plain(r.get("miss_offset", np.nan)),
                }
                for _, r in rows.iterrows()
            ]
            out[reason] = {
                "runs": int(len(rows)),
                "offsets": sorted(float(v) for v in rows["miss_offset"] if np.isfinite(v)),
                "causes": {
                    c: sum(m["cause"] == c for m in each)
                    for c in MISS_CAUSES
                    if any(m["cause"] == c for m in each)
                },
                "misses": each,
            }
    return out


def _compliant_summary(comp) -> dict:
    """Outcome agreement and median Frechet of ``compare`` rows against the compliant-drive
    reference (``agree_compliant``, ``compliant_frechet``; NaN without those columns)."""
    if "agree_compliant" not in comp or not comp["agree_compliant"].notna().any():
        return {"outcome_agreement_compliant": float("nan"), "median_frechet_compliant": float("nan")}
    return {
        "outcome_agreement_compliant": float((comp["agree_compliant"] == 1).mean()),
        "median_frechet_compliant": float(np.nanmedian(comp["compliant_frechet"])),
    }


def _family_summary(comp) -> dict:
    """Run count, outcome agreement and mean / median deviations of ``compare`` rows."""
    ok = comp[comp["status"] == "ok"]
    n = int(len(comp))
    return {
        "runs": n,
        "ok_runs": int(len(ok)),
        "outcome_agreement": float(comp["agree"].fillna(False).astype(bool).mean()) if n else float("nan"),
        "mean_frechet": float(np.nanmean(comp["frechet"])) if n else float("nan"),
        "median_frechet": float(np.nanmedian(comp["frechet"])) if n else float("nan"),
        "mean_lateral_deviation": float(np.nanmean(comp["lateral_deviation"])) if n else float("nan"),
    }


def _plain(v):
    """A run-table value as a plain Python scalar for the rows (NaN stays NaN)."""
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating, float)):
        return float(v)
    return v if v is None or isinstance(v, (str, int)) else str(v)
