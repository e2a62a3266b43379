"""Study 3: the quasistatic boundary. Agreement against I_e for the spring and ramp drives,
and the I_e* where it breaks, with a bracketing interval and a bootstrap over starts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from spine_mj import presets, sim
from spine_mj.presets import calibrated_mu
from spine_mj.validate.ie_star import ie_star_by_criterion, quiet_nan_warnings
from spine_mj.validate.paths import prefix_frechet, stored_paths, tip_radius
from spine_mj.validate.plans import FRECHET_TARGET, RAMP_MIN_COVERAGE, FamilySpec, ValidationPlan
from spine_mj.validate.ramp_pilot import pilot_rig, ramp_duration
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import family_doc

__all__ = ["BoundaryCurve", "BoundaryResult", "boundary", "preset_grid", "quasistatic_locked"]


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
        ``by_criterion`` (:func:`ie_star_by_criterion`) and ``ie_used``; or, for a ramp that
        covers too little of the path, ``kind`` ``"not measured"``, ``valid`` False and a
        ``note``.
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

    Spring drive: per run, outcome agreement (``compare.outcome_agreement``: lock and trap)
    and the Frechet deviation from the streamline. Ramp with reset: its ``I_e`` is the
    equivalent one, ``m v_eq^2 / (F_p L_c)`` with ``v_eq = L_c rate / F_p``; its duration is
    set from a pilot run's per-cycle slip so that the tip covers the path to the domain edge
    (:func:`ramp_duration`), capped at ``plan.ramp_max_steps``. A capped ramp covers only a
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
    fams = [f for f in plan.families if f.name in plan.boundary_families]
    curves, stars, skip = {}, {}, {}
    ramp_plans = {proto: {} for proto in plan.protocols}
    jobs = [
        (proto, job)
        for proto in plan.protocols
        for fam in fams
        for preset in fam.presets
        for job in _preset_jobs(plan, runner, fam, preset, proto, ramp_plans[proto])
    ]
    # every drive's sweeps at once: the workers stay busy across the sweeps' ends
    done = runner.many([(doc, name) for _, (doc, name, _) in jobs], "spring and ramp sweeps")
    for proto in plan.protocols:
        comps, mjs = [], []
        for (p, (_, _, rows)), (df, store) in zip(jobs, done):
            if p == proto:
                c, m = rows(df, store)
                comps.append(c)
                mjs.append(m)
        comp = pd.concat(comps, ignore_index=True)
        mj = pd.concat(mjs, ignore_index=True)
        curves[proto], skip[proto], amat, fmat = _curve(plan, proto, comp, mj, ramp_plans[proto])
        stars[proto] = _protocol_ie_star(plan, curves[proto], amat, fmat)
    return BoundaryResult(curves=curves, ie_star=stars, skip_rate=skip, families=[f.name for f in fams])


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
    store)`` gives the sweep's (``compare``, ``mujoco``) rows."""
    grid = preset_grid(plan, fam, preset)
    mu, tip = grid["mu"], grid["tip_radius"]
    if proto == "ramp":
        return _ramp_jobs(plan, runner, fam, preset, mu, tip, grid, ramp_plans)
    doc = family_doc(
        fam,
        name=f"boundary-{proto}-{preset}",
        preset=preset,
        drive={"protocol": proto, "ie": list(plan.ie_values)},
        grid=grid,
    )

    def rows(df, _store):
        return df[df["analysis"] == "compare"], df[df["analysis"] == "mujoco"]

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
    lc = sim.characteristic_length(surface)
    sx, sy = fam.first_start(surface)
    by_dur: dict[float, list[float]] = {}
    with runner.phase(f"ramp pilots on {preset}", len(plan.ie_values)) as tick:
        for v in plan.ie_values:
            rp = ramp_duration(
                rig,
                (sx, sy),
                v,
                target_lc=(surface.bounds[1] - sx) / lc,
                max_steps=plan.ramp_max_steps,
                slide_lc=plan.ramp_slide_lc,
            )
            ramp_plans.setdefault(preset, {})[float(v)] = rp.as_dict()
            by_dur.setdefault(rp.duration_s, []).append(float(v))
            tick()

    def rows(df, store):
        c = df[df["analysis"] == "compare"].copy()
        m = df[df["analysis"] == "mujoco"]
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
                "slide_distance": plan.ramp_slide_lc * rig.scales.char_length_m,
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
        mp = stored_paths(store, case_id, "mujoco")
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
                "ramp_max_steps": plan.ramp_max_steps,
                "ramp_plans": ramp_plans,
            }
            if ramp
            else {}
        ),
    )
    return curve, skips, amat, fmat


def _protocol_ie_star(
    plan: ValidationPlan, curve: BoundaryCurve, amat: list[np.ndarray], fmat: list[np.ndarray]
) -> dict:
    """I_e* of one protocol: the headline criterion with all of them under ``by_criterion``."""
    ies = np.asarray(curve.ie, dtype=float)
    n_min = curve.runs_per_ie
    # a capped ramp that covers a sliver of the path agrees trivially: such I_e values
    # take no part in its I_e*
    use = (np.asarray(curve.coverage) >= RAMP_MIN_COVERAGE) if curve.is_ramp else np.ones(len(ies), bool)
    if use.sum() >= 2:
        by = ie_star_by_criterion(
            ies[use],
            np.array([x[:n_min] for x, u in zip(amat, use) if u]),
            np.array([x[:n_min] for x, u in zip(fmat, use) if u]),
            n_boot=plan.bootstrap,
        )
        return {**by["median_frechet"], "by_criterion": by, "ie_used": ies[use].tolist()}
    return {
        "kind": "not measured",
        "valid": False,
        "by_criterion": {},
        "note": f"the capped ramp covers >= {RAMP_MIN_COVERAGE:g} of the path "
        f"at fewer than two I_e values (best {np.nanmax(curve.coverage):.2g}); "
        "see ramp_plans for the steps needed",
    }
