"""Study 2: the quasistatic limit. Spring-drive paths at the lowest inertia number against the
streamline, per surface family, with the engine settings that limit agreement varied.

Three comparisons per run separate the errors: MuJoCo against the streamline on the smooth
surface (total), the streamline on MuJoCo's triangulated hfield against the smooth one
(geometry), MuJoCo against the triangulated streamline (dynamics).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from spine_mj import compare, presets
from spine_mj.presets import calibrated_mu
from spine_mj.validate.paths import (
    mujoco_traces,
    path_metrics,
    streamline_paths,
    tip_radius,
    triangulated_surface,
)
from spine_mj.validate.plans import FRECHET_TARGET, OUTCOME_TARGET, RECOMMENDED, FamilySpec, ValidationPlan
from spine_mj.validate.runner import StudyRunner
from spine_mj.validate.sweep_docs import engine_grid, family_doc

__all__ = ["LimitPath", "QuasistaticLimitResult", "quasistatic_limit"]

#: Columns of the per-run rows.
RUN_COLUMNS = (
    "preset",
    "surface",
    "start",
    "start_x",
    "start_y",
    "frechet",
    "lateral_deviation",
    "end_distance",
    "agree",
    "geometry_frechet",
    "dynamics_frechet",
    "dynamics_agree",
    "end_reason",
)


@dataclass(frozen=True)
class LimitPath:
    """The three paths of one start (``(n, 2)`` x, y in surface units) for the figure."""

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
        ``mean_frechet``, ``median_frechet``, ``mean_lateral_deviation``,
        ``mean_geometry_frechet``, ``mean_dynamics_frechet``,
        ``outcome_agreement_vs_triangulated``, ``meets_target``.
    runs : list of dict
        Per-run rows (:data:`RUN_COLUMNS`).
    variations : dict
        Engine setting label -> summary on the single peak (the recommended one first).
    paths : dict
        Preset of the single peak/valley family -> list of :class:`LimitPath`.
    lowest_ie : float
    """

    families: dict[str, dict]
    runs: list[dict]
    variations: dict[str, dict]
    paths: dict[str, list[LimitPath]]
    lowest_ie: float

    def as_dict(self) -> dict:
        return {
            "families": self.families,
            "runs": self.runs,
            "variations": self.variations,
            "paths": {k: [p.as_dict() for p in v] for k, v in self.paths.items()},
            "lowest_ie": self.lowest_ie,
        }


def quasistatic_limit(plan: ValidationPlan, runner: StudyRunner) -> QuasistaticLimitResult:
    """Study 2: spring drive at the lowest I_e against the streamline, per surface family.

    For every run, three comparisons (lengths over L_c): MuJoCo against the streamline on
    the smooth surface (the total error; the sweep's ``compare`` analysis), the streamline
    on MuJoCo's triangulated hfield against the smooth one (geometry error), and MuJoCo
    against the triangulated streamline (dynamics error). Then on the single peak the
    settings of ``plan.limit_variations`` one at a time.

    Returns
    -------
    QuasistaticLimitResult
    """
    runner.study = "limit"
    families, runs_rows, paths = {}, [], {}
    for fam in plan.families:
        comps = [_preset_comparison(plan, runner, fam, preset, paths) for preset in fam.presets]
        allc = pd.concat(comps, ignore_index=True)
        summ = _family_summary(allc)
        summ.update(
            {
                "mean_geometry_frechet": float(np.nanmean(allc["geometry_frechet"])),
                "mean_dynamics_frechet": float(np.nanmean(allc["dynamics_frechet"])),
                "outcome_agreement_vs_triangulated": float(np.mean(allc["dynamics_agree"])),
                "meets_target": bool(
                    summ["outcome_agreement"] >= OUTCOME_TARGET and summ["mean_frechet"] <= FRECHET_TARGET
                ),
            }
        )
        families[fam.name] = summ
        for _, r in allc.iterrows():
            runs_rows.append({k: _plain(r[k]) for k in RUN_COLUMNS})
    return QuasistaticLimitResult(
        families=families,
        runs=runs_rows,
        variations=_variations(plan, runner, runs_rows),
        paths=paths,
        lowest_ie=plan.lowest_ie,
    )


def _preset_comparison(
    plan: ValidationPlan, runner: StudyRunner, fam: FamilySpec, preset: str, paths: dict
) -> pd.DataFrame:
    """The ``compare`` rows of one preset's sweep with geometry and dynamics errors added;
    the single peak/valley family's paths go into ``paths``."""
    mu = calibrated_mu(preset)
    tip = tip_radius(preset, fam.seeds, plan.hfield_resolution)
    dl = tip / 2
    grid = {"mu": mu, "tip_radius": tip, "dl": dl, **engine_grid(plan, (), preset, fam.seeds, tip)}
    doc = family_doc(
        fam,
        name=f"limit-{preset}",
        preset=preset,
        drive={"protocol": "spring", "ie": plan.lowest_ie},
        grid=grid,
    )
    df, store = runner(doc, f"limit/{preset}")
    comp = df[df["analysis"] == "compare"].copy()
    mj = df[df["analysis"] == "mujoco"].set_index(["case_id", "start"])
    runner.note(f"triangulated streamlines on {preset}")
    geo, dyn, dyn_agree = [], [], []
    for case_id, grp in comp.groupby("case_id", sort=False):
        seed = grp["surface_seed"].iloc[0]
        surface = presets.make_surface(preset, **({} if pd.isna(seed) else {"seed": int(seed)}))
        starts = grp[["start_x", "start_y"]].to_numpy()
        lc = float(mj.loc[(case_id, int(grp["start"].iloc[0])), "char_length"])
        smooth = streamline_paths(surface, starts, mu, dl, tip)
        tri = streamline_paths(triangulated_surface(surface, plan.hfield_resolution), starts, mu, dl, tip)
        mpaths = mujoco_traces(store, case_id)
        for i, s in enumerate(grp["start"].astype(int)):
            qs_p = smooth.path(i)
            tr_p = tri.path(i)
            qa = np.column_stack([qs_p["x"], qs_p["y"]])
            ta = np.column_stack([tr_p["x"], tr_p["y"]])
            g, _ = path_metrics(ta, qa, lc)
            m = mpaths.get(s)
            mp = np.column_stack([m["x"], m["y"]]) if m is not None else np.zeros((0, 2))
            d, _ = path_metrics(mp, ta, lc)
            row = mj.loc[(case_id, s)]
            ag = compare.outcome_agreement(
                [bool(tri.self_locked[i])],
                [[tri.end_x[i], tri.end_y[i]]],
                [bool(row["self_locked"])],
                [[row["end_x"], row["end_y"]]],
                length_scale=lc,
            )["agree"][0]
            geo.append(g)
            dyn.append(d)
            dyn_agree.append(bool(ag))
            if fam.name == "single_peak_valley":
                paths.setdefault(preset, []).append(LimitPath(qa, ta, mp, tuple(starts[i])))
    comp["geometry_frechet"] = geo
    comp["dynamics_frechet"] = dyn
    comp["dynamics_agree"] = dyn_agree
    comp["preset"] = preset
    comp["end_reason"] = [mj.loc[(c, int(s)), "end_reason"] for c, s in zip(comp["case_id"], comp["start"])]
    return comp


def _variations(plan: ValidationPlan, runner: StudyRunner, runs_rows: list[dict]) -> dict[str, dict]:
    """The plan's engine variations on the first family's first preset, after the
    recommended settings (summarised from ``runs_rows``)."""
    variations = {}
    fam0 = plan.families[0]
    preset = fam0.presets[0]
    for label, ov in plan.limit_variations:
        mu = calibrated_mu(preset)
        tip = tip_radius(preset, fam0.seeds, dict(ov).get("hfield_resolution", plan.hfield_resolution))
        grid = {"mu": mu, "tip_radius": tip, "dl": tip / 2, **engine_grid(plan, ov, preset, fam0.seeds, tip)}
        doc = family_doc(
            fam0,
            name=f"limit-var-{label}",
            preset=preset,
            drive={"protocol": "spring", "ie": plan.lowest_ie},
            grid=grid,
        )
        tag = "-".join(f"{k}{v}" for k, v in ov)
        df, _ = runner(doc, f"limit-var/{preset}-{tag}")
        comp = df[df["analysis"] == "compare"]
        variations[label] = {**_family_summary(comp), "settings": dict(ov), "surface": preset}
    base = [r for r in runs_rows if r["preset"] == preset]
    return {
        RECOMMENDED[0]: {
            "outcome_agreement": float(np.mean([bool(r["agree"]) for r in base])),
            "mean_frechet": float(np.nanmean([r["frechet"] for r in base])),
            "mean_lateral_deviation": float(np.nanmean([r["lateral_deviation"] for r in base])),
            "runs": len(base),
            "settings": {},
            "surface": preset,
        },
        **variations,
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
