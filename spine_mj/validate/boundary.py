"""Study 3: the quasistatic boundary. Agreement against I_e for the spring and ramp drives,
and the I_e* where it breaks, with a bracketing interval and a bootstrap over starts.

Solution verification of I_e* (``plan.boundary.refinements``, keys of
:data:`~spine_mj.validate.convergence.REFINEMENTS`): every start rerun under the refinement
at the grid values of the headline's bracket and :data:`IE_WINDOW` either side of it (where
I_e* is decided; a run there is fast, the carriage at I_e ~ 0.1), the refined I_e* read from
the curve with those values replaced, and *converged* when it lies inside the headline's own
95 % bootstrap interval (:func:`~spine_mj.validate.convergence.headline_convergence`, on
``log10 I_e*``). The grid values outside the window keep their runs: there agreement holds
(below) or fails (above) by a margin, and the corner's own refinement
(:mod:`spine_mj.validate.quasistatic_limit`) checks the lowest I_e.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from spine_mj import presets
from spine_mj.presets import calibrated_mu
from spine_mj.roughness import characteristic_length
from spine_mj.theory.targets import FRECHET_TARGET
from spine_mj.validate.convergence import REFINEMENTS, headline_convergence
from spine_mj.validate.ie_star import (
    IE_STAR_CRITERIA,
    bootstrap_ie_star,
    criterion_ie_star,
    grid_point,
    ie_star_by_criterion,
    quiet_nan_warnings,
)
from spine_mj.validate.paths import prefix_frechet, stored_paths, tip_radius
from spine_mj.validate.plans import RAMP_MIN_COVERAGE, FamilySpec, ValidationPlan
from spine_mj.validate.ramp_pilot import pilot_rig, ramp_duration
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import engine_grid, family_doc

__all__ = [
    "HEADLINE_CRITERION",
    "IE_WINDOW",
    "BoundaryCurve",
    "BoundaryResult",
    "boundary",
    "preset_grid",
    "quasistatic_locked",
    "refinement_window",
]

#: The criterion of the I_e* headline (:data:`~spine_mj.validate.ie_star.IE_STAR_CRITERIA`).
HEADLINE_CRITERION = "median_frechet"
#: Grid values either side of the headline I_e*'s bracket rerun under refinement.
IE_WINDOW = 1


@dataclass(frozen=True)
class BoundaryCurve:
    """Agreement of one drive protocol against I_e (one entry per I_e value).

    Attributes
    ----------
    ie : list of float
    agreement : list of float
        Fraction of runs that agree.
    frechet, median_frechet : list of float
        Mean and median deviation / L_c over the runs (prefix Frechet for the ramp).
    lateral, engine_trouble : list of float
    runs_per_ie : int
    frechet_kind : str
    coverage, ie_achieved : list of float or None
        Ramp only: mean covered fraction of the path to the domain edge, and the median
        I_e of the runs' mean x speed.
    ie_kind : str or None
    ramp_max_steps : int or None
    ramp_plans : dict or None
        Ramp only: preset -> I_e -> :meth:`RampPlan.as_dict`.
    """

    ie: list[float]
    agreement: list[float]
    frechet: list[float]
    median_frechet: list[float]
    lateral: list[float]
    engine_trouble: list[float]
    runs_per_ie: int
    frechet_kind: str
    coverage: list[float] | None = None
    ie_achieved: list[float] | None = None
    ie_kind: str | None = None
    ramp_max_steps: int | None = None
    ramp_plans: dict | None = None

    @property
    def is_ramp(self) -> bool:
        return self.coverage is not None

    def as_dict(self) -> dict:
        d = {
            "ie": self.ie,
            "agreement": self.agreement,
            "frechet": self.frechet,
            "median_frechet": self.median_frechet,
            "lateral": self.lateral,
            "engine_trouble": self.engine_trouble,
            "runs_per_ie": self.runs_per_ie,
            "frechet_kind": self.frechet_kind,
        }
        if self.is_ramp:
            d.update(
                {
                    "coverage": self.coverage,
                    "ie_achieved": self.ie_achieved,
                    "ie_kind": self.ie_kind,
                    "ramp_max_steps": self.ramp_max_steps,
                    "ramp_plans": self.ramp_plans,
                }
            )
        return d


@dataclass(frozen=True)
class BoundaryResult:
    """Result of :func:`boundary`.

    Attributes
    ----------
    curves : dict
        Protocol -> :class:`BoundaryCurve`.
    ie_star : dict
        Protocol -> the headline (median-Frechet) :meth:`IeStar.as_dict` with ``criterion``,
        ``by_criterion`` (:func:`ie_star_by_criterion`) and ``ie_used``, and where the plan
        refines it ``convergence`` (:func:`~spine_mj.validate.convergence.headline_convergence`
        on ``log10 I_e*`` with ``ie_refined``, the window rerun, and ``ci95``, the
        headline's 95 % interval); or, for a ramp that covers too little of the path,
        ``kind`` ``"not measured"``, ``valid`` False and a ``note``.
    skip_rate : dict
        Protocol -> per-I_e fraction of quasistatic traps MuJoCo skips.
    families : list of str
    """

    curves: dict[str, BoundaryCurve]
    ie_star: dict[str, dict]
    skip_rate: dict[str, list[float]]
    families: list[str]

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {
            "ie_star": self.ie_star,
            "ie_curves": {k: c.as_dict() for k, c in self.curves.items()},
            "trap_skip_rate": self.skip_rate,
        }

    def as_dict(self) -> dict:
        return {
            "curves": {k: c.as_dict() for k, c in self.curves.items()},
            "ie_star": self.ie_star,
            "skip_rate": self.skip_rate,
            "families": self.families,
        }


def boundary(plan: ValidationPlan, runner: StudyRunner) -> BoundaryResult:
    """Study 3: agreement against I_e for the spring and ramp drives, and I_e*.

    Spring drive: per run, outcome agreement (``agreement.outcome_agreement``: lock and trap)
    and the Frechet deviation from the streamline. Ramp with reset: its ``I_e`` is the
    equivalent one, ``m v_eq^2 / (F_p L_c)`` with ``v_eq = L_c rate / F_p``; its duration is
    set from a pilot run's per-cycle slip so that the tip covers the path to the domain edge
    (:func:`ramp_duration`), capped at ``plan.boundary.ramp_max_steps``. A capped ramp covers only a
    prefix of the path, so a ramp run agrees when it has no engine trouble, does not
    self-lock where the streamline does not, and its path deviates from the streamline cut
    at the same arc length by <= 0.1 L_c (prefix Frechet); the covered fraction is reported.

    I_e* comes from three criteria (:data:`IE_STAR_CRITERIA`): outcome agreement alone, with
    the median Frechet over starts (the headline: robust to one marginal start), and with
    the mean, each with a bootstrap interval over starts.

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.

    Returns
    -------
    BoundaryResult
    """
    runner.study = "boundary"
    fams = [f for f in plan.families if f.name in plan.boundary.families]
    curves, stars, skip = {}, {}, {}
    ramp_plans = {proto: {} for proto in plan.boundary.protocols}
    jobs = [
        (proto, job)
        for proto in plan.boundary.protocols
        for fam in fams
        for preset in fam.presets
        for job in _preset_jobs(plan, runner, fam, preset, proto, ramp_plans[proto])
    ]
    # every drive's sweeps at once: the workers stay busy across the sweeps' ends
    done = runner.many([(doc, name) for _, (doc, name, _) in jobs], "spring and ramp sweeps")
    matrices = {}
    for proto in plan.boundary.protocols:
        comp, mj = _rows_of(proto, jobs, done)
        curves[proto], skip[proto], amat, fmat = _curve(plan, proto, comp, mj, ramp_plans[proto])
        stars[proto] = _protocol_ie_star(plan, curves[proto], amat, fmat)
        matrices[proto] = (amat, fmat)
    refined = _refined_jobs(plan, fams, jobs, curves, stars)
    if refined:
        rdone = runner.many([(doc, name) for _, _, (doc, name, _) in refined], "I_e* under refinement")
        for proto in plan.boundary.protocols:
            if stars[proto].get("valid") is not False:
                stars[proto]["convergence"] = _ie_star_convergence(
                    plan, proto, curves[proto], matrices[proto], refined, rdone, ramp_plans[proto]
                )
    return BoundaryResult(curves=curves, ie_star=stars, skip_rate=skip, families=[f.name for f in fams])


def _rows_of(proto: str, jobs, done, key: str | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The (``compare``, ``engine``) rows of ``proto``'s sweeps among ``jobs`` (``(proto,
    job)``, or ``(proto, key, job)`` with the refinement ``key``) and their results
    ``done``."""
    comps, mjs = [], []
    for job, (df, store) in zip(jobs, done):
        p, k, (_, _, rows) = job if len(job) == 3 else (job[0], None, job[1])
        if p == proto and k == key:
            c, m = rows(df, store)
            comps.append(c)
            mjs.append(m)
    if not comps:
        return pd.DataFrame(), pd.DataFrame()
    return pd.concat(comps, ignore_index=True), pd.concat(mjs, ignore_index=True)


def refinement_window(ie, star: dict) -> list[float]:
    """The I_e values rerun under refinement: the headline I_e*'s bracket (its two grid
    values; the grid's top two where agreement holds everywhere, its bottom two where it
    holds nowhere) and :data:`IE_WINDOW` grid values either side, from ``ie`` (the values
    the estimate used, increasing); empty where I_e* was not measured."""
    ies = [float(v) for v in ie]
    kind = star.get("kind")
    if kind == "bracketed":
        lo = int(np.argmin(np.abs(np.log(ies) - np.log(star["low"]))))
        hi = lo + 1
    elif kind == "above":
        lo, hi = len(ies) - 2, len(ies) - 1
    elif kind == "below":
        lo, hi = 0, 1
    else:
        return []
    return ies[max(0, lo - IE_WINDOW) : hi + IE_WINDOW + 1]


def _refined_jobs(plan: ValidationPlan, fams, jobs, curves, stars) -> list[tuple[str, str, tuple]]:
    """``(protocol, refinement key, (config, store name, rows))`` of every refinement of
    ``plan.boundary.refinements``: each sweep of ``jobs`` once per I_e of its protocol's
    :func:`refinement_window`, with the refinement's engine keys at that I_e (the step is
    the rig's own at that pace, :func:`~spine_mj.validate.sweep_configs.engine_grid`)."""
    seeds = {p: f.seeds for f in fams for p in f.presets}
    out = []
    for key in plan.boundary.refinements:
        for proto, (doc, name, rows) in jobs:
            star = stars[proto]
            window = refinement_window(star.get("ie_used", curves[proto].ie), star)
            preset = doc["surfaces"][0]["preset"]
            grid = doc["grid"]
            for v in (float(x) for x in doc["drive"]["ie"]):
                if not np.isclose(window, v, rtol=1e-9).any():
                    continue
                keys = engine_grid(
                    plan, REFINEMENTS[key], preset, seeds[preset], grid["tip_radius"], mu=grid["mu"], ie=v
                )
                refined = {
                    **doc,
                    "sweep": {**doc["sweep"], "name": f"{doc['sweep']['name']}-{key}-ie{v:.3g}"},
                    "drive": {**doc["drive"], "ie": [v]},
                    "grid": {**grid, **keys},
                }
                store = f"boundary-refined/{key}/{name.split('/')[-1]}-ie{v:.3g}"
                out.append((proto, key, (refined, store, rows)))
    return out


def _ie_star_convergence(
    plan: ValidationPlan, proto: str, curve: BoundaryCurve, matrices, refined, rdone, ramp_plans: dict
) -> dict:
    """The headline I_e*'s ``convergence`` entry of one protocol: per refinement the I_e*
    of the curve whose window values (:func:`refinement_window`) are the refined runs',
    judged against the headline's 95 % bootstrap interval."""
    ies, a_base, f_base = _used(curve, *matrices)
    stat = IE_STAR_CRITERIA[HEADLINE_CRITERION][0]
    ci95 = bootstrap_ie_star(
        ies, a_base, f_base, n_boot=plan.bootstrap, rng=12345, stat=stat, confidence=0.95
    )
    base = grid_point(criterion_ie_star(ies, a_base, f_base, HEADLINE_CRITERION))
    by_key: dict[str, dict | None] = {}
    window: list[float] = []
    for key in plan.boundary.refinements:
        comp, mj = _rows_of(proto, refined, rdone, key)
        if comp.empty:
            by_key[key] = None
            continue
        rc, _, ra, rf = _curve(plan, proto, comp, mj, ramp_plans)
        a, f = a_base.copy(), f_base.copy()
        n = a.shape[1]
        for v, ar, fr in zip(rc.ie, ra, rf):
            i = np.flatnonzero(np.isclose(ies, v, rtol=1e-9))
            if i.size and len(ar) >= n:
                a[i[0]], f[i[0]] = ar[:n], fr[:n]
        window = [float(v) for v in rc.ie]
        star = criterion_ie_star(ies, a, f, HEADLINE_CRITERION)
        by_key[key] = {"base": base, "refined": grid_point(star), "runs": int(len(comp))}
    conv = headline_convergence(base, ci95, by_key, log=True, note="not in the plan's boundary.refinements")
    return {**conv, "ie_refined": window, "ci95": list(ci95)}


def preset_grid(plan: ValidationPlan, fam: FamilySpec, preset: str) -> dict:
    """Sweep grid keys of a boundary-type study on ``preset``: its calibrated mu, the rig's
    tip radius (the streamline traces the same sphere), a step of half the tip, the plan's
    hfield resolution."""
    tip = tip_radius(preset, fam.seeds, plan.hfield_resolution)
    return {
        "mu": calibrated_mu(preset),
        "tip_radius": tip,
        "dl": tip / 2,
        "hfield_resolution": plan.hfield_resolution,
    }


def quasistatic_locked(agree_lock, mj_locked) -> np.ndarray:
    """Whether the streamline self-locked, per run: MuJoCo's lock where the two agree on
    it (``agree_lock``, missing counted as disagreeing), its opposite where they do not."""
    mj = np.asarray(mj_locked, dtype=bool)
    agree = pd.Series(agree_lock).fillna(False).astype(bool).to_numpy()
    return np.where(agree, mj, ~mj)


def _preset_jobs(
    plan: ValidationPlan, runner: StudyRunner, fam: FamilySpec, preset: str, proto: str, ramp_plans: dict
) -> list[tuple[dict, str, Callable]]:
    """One preset's sweeps under ``proto`` as ``(config, store name, rows)``: ``rows(df,
    store)`` gives the sweep's (``compare``, ``engine``) rows."""
    grid = preset_grid(plan, fam, preset)
    mu, tip = grid["mu"], grid["tip_radius"]
    if proto == "ramp":
        return _ramp_jobs(plan, runner, fam, preset, mu, tip, grid, ramp_plans)
    doc = family_doc(
        fam,
        name=f"boundary-{proto}-{preset}",
        preset=preset,
        drive={"protocol": proto, "ie": list(plan.boundary.ie_values)},
        grid=grid,
    )

    def rows(df, _store):
        return df[df["analysis"] == "compare"], df[df["analysis"] == "engine"]

    return [(doc, f"boundary/{proto}-{preset}", rows)]


def _ramp_jobs(
    plan: ValidationPlan,
    runner: StudyRunner,
    fam: FamilySpec,
    preset: str,
    mu: float,
    tip: float,
    grid: dict,
    ramp_plans: dict,
) -> list[tuple[dict, str, Callable]]:
    """Ramp sweeps of one preset (as :func:`_preset_jobs`): a pilot per I_e sets the
    duration (into ``ramp_plans``); I_e values that share a duration run in one sweep."""
    seed = None if fam.seeds is None else fam.seeds[0]
    rig, _ = pilot_rig(preset, seed, mu, tip, plan.hfield_resolution)
    surface = presets.make_surface(preset, **({} if seed is None else {"seed": int(seed)}))
    lc = characteristic_length(surface)
    sx, sy = fam.first_start(surface)
    by_dur: dict[float, list[float]] = {}
    with runner.phase(f"ramp pilots on {preset}", len(plan.boundary.ie_values)) as tick:
        for v in plan.boundary.ie_values:
            rp = ramp_duration(
                rig,
                (sx, sy),
                v,
                target_lc=(surface.bounds[1] - sx) / lc,
                max_steps=plan.boundary.ramp_max_steps,
                slide_lc=plan.boundary.ramp_slide_lc,
            )
            ramp_plans.setdefault(preset, {})[float(v)] = rp.as_dict()
            by_dur.setdefault(rp.duration_s, []).append(float(v))
            tick()

    def rows(df, store):
        c = df[df["analysis"] == "compare"].copy()
        m = df[df["analysis"] == "engine"]
        c["prefix_frechet"], c["coverage"], c["ie_achieved"] = _ramp_metrics(c, m, store, surface, rig)
        return c, m

    out = []
    for j, (dur, ies_) in enumerate(sorted(by_dur.items())):
        doc = family_doc(
            fam,
            name=f"boundary-ramp-{preset}-{j}",
            preset=preset,
            drive={
                "protocol": "ramp",
                "ie": ies_,
                "duration": dur,
                "slide_distance": plan.boundary.ramp_slide_lc * rig.scales.char_length_m,
            },
            grid=grid,
        )
        out.append((doc, f"boundary/ramp-{preset}-d{dur:.4g}", rows))
    return out


def _ramp_metrics(c: pd.DataFrame, m: pd.DataFrame, store, surface, rig) -> tuple[list, list, list]:
    """Per ramp run: prefix Frechet, covered fraction of the path (x advance over the
    distance to the domain edge; 1 for a run that self-locked or left the domain: its
    outcome is decided), and the I_e of its mean x speed over the plain ramp's time."""
    mi = m.set_index(["case_id", "start"])
    pf, cov, ach = [], [], []
    for case_id, grp in c.groupby("case_id", sort=False):
        mp = stored_paths(store, case_id, "engine")
        qp = stored_paths(store, case_id, "quasistatic")
        for s in grp["start"].astype(int):
            row = mi.loc[(case_id, s)]
            lc_run = float(row["char_length"])
            a = mp.get(s, np.zeros((0, 2)))
            pf.append(prefix_frechet(a, qp.get(s, np.zeros((0, 2))), lc_run))
            x0 = float(grp.loc[grp["start"] == s, "start_x"].iloc[0])
            target = surface.bounds[1] - x0
            dx = float(row["end_x"]) - x0
            # a run that locked or left the domain has covered its whole path
            decided = row["end_reason"] in ("self_lock", "left_domain")
            cov.append(1.0 if decided else (dx / target if target > 0 else float("nan")))
            t_run = float(row["nominal_end_time_s"])
            v_mean = dx * rig.length_scale_m / max(t_run, 1e-12)
            ach.append(rig.scales.inertia_number(max(v_mean, 0.0)))
    return pf, cov, ach


def _curve(
    plan: ValidationPlan, proto: str, comp: pd.DataFrame, mj: pd.DataFrame, ramp_plans: dict
) -> tuple[BoundaryCurve, list[float], list[np.ndarray], list[np.ndarray]]:
    """The protocol's curve, trap-skip rates, and per-I_e run agreement and deviation."""
    ramp = proto == "ramp"
    ies = np.array(sorted(comp["ie"].unique()), dtype=float)
    ag, fr, frm, lat, trouble, skips, cov, ach = [], [], [], [], [], [], [], []
    amat, fmat = [], []
    for v in ies:
        c = comp[np.isclose(comp["ie"], v)].sort_values(["surface", "case_id", "start"])
        m = mj[np.isclose(mj["ie"], v)].sort_values(["surface", "case_id", "start"])
        mj_locked = m["self_locked"].astype(bool).to_numpy()
        qs_locked = quasistatic_locked(c["agree_lock"].to_numpy(), mj_locked)
        if ramp:
            f_run = c["prefix_frechet"].to_numpy(dtype=float)
            ok = (m["end_reason"] != "engine_trouble").to_numpy()
            a_run = ok & ~(mj_locked & ~qs_locked) & (np.nan_to_num(f_run, nan=np.inf) <= FRECHET_TARGET)
            cov.append(float(np.nanmean(c["coverage"])))
            ach.append(float(np.nanmedian(c["ie_achieved"])))
        else:
            f_run = c["frechet"].to_numpy(dtype=float)
            a_run = c["agree"].fillna(False).astype(bool).to_numpy()
        ag.append(float(a_run.mean()))
        with quiet_nan_warnings():
            fr.append(float(np.nanmean(f_run)))
            frm.append(float(np.nanmedian(f_run)))
            lat.append(float(np.nanmean(c["lateral_deviation"])))
        trouble.append(float((m["end_reason"] == "engine_trouble").mean()))
        amat.append(a_run.astype(float))
        fmat.append(f_run)
        traps = qs_locked.sum()
        skipped = (qs_locked & ~mj_locked).sum()
        skips.append(float(skipped / traps) if traps else float("nan"))
    curve = BoundaryCurve(
        ie=ies.tolist(),
        agreement=ag,
        frechet=fr,
        median_frechet=frm,
        lateral=lat,
        engine_trouble=trouble,
        runs_per_ie=int(min(len(x) for x in amat)),
        frechet_kind="prefix Frechet (streamline cut at the MuJoCo path's arc length)" if ramp else "Frechet",
        **(
            {
                "coverage": cov,
                "ie_achieved": ach,
                "ie_kind": "equivalent: m v_eq^2 / (F_p L_c), v_eq = L_c rate / F_p",
                "ramp_max_steps": plan.boundary.ramp_max_steps,
                "ramp_plans": ramp_plans,
            }
            if ramp
            else {}
        ),
    )
    return curve, skips, amat, fmat


def _used(
    curve: BoundaryCurve, amat: list[np.ndarray], fmat: list[np.ndarray]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The I_e values an I_e* of ``curve`` uses and their per-run agreement and deviation
    ``(n_ie, runs_per_ie)``: a capped ramp that covers a sliver of the path agrees
    trivially, so such I_e values take no part."""
    ies = np.asarray(curve.ie, dtype=float)
    n_min = curve.runs_per_ie
    use = (np.asarray(curve.coverage) >= RAMP_MIN_COVERAGE) if curve.is_ramp else np.ones(len(ies), bool)
    a = np.array([x[:n_min] for x, u in zip(amat, use) if u], dtype=float).reshape(-1, n_min)
    f = np.array([x[:n_min] for x, u in zip(fmat, use) if u], dtype=float).reshape(-1, n_min)
    return ies[use], a, f


def _protocol_ie_star(
    plan: ValidationPlan, curve: BoundaryCurve, amat: list[np.ndarray], fmat: list[np.ndarray]
) -> dict:
    """I_e* of one protocol: the headline criterion with all of them under ``by_criterion``."""
    ies, a, f = _used(curve, amat, fmat)
    if len(ies) >= 2:
        by = ie_star_by_criterion(ies, a, f, n_boot=plan.bootstrap)
        return {**by[HEADLINE_CRITERION], "by_criterion": by, "ie_used": ies.tolist()}
    return {
        "kind": "not measured",
        "valid": False,
        "by_criterion": {},
        "note": f"the capped ramp covers >= {RAMP_MIN_COVERAGE:g} of the path "
        f"at fewer than two I_e values (best {np.nanmax(curve.coverage):.2g}); "
        "see ramp_plans for the steps needed",
    }
