"""The validation suite: runs the studies for a plan and writes ``validation.json`` and
``report.md`` (with PNG figures) into one output folder.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable
from pathlib import Path

from spine_mj import sim
from spine_mj.errors import SpineInputError, remove_temporaries
from spine_mj.jsonio import write_json
from spine_mj.surfaces import single_gaussian
from spine_mj.validate.boundary import BoundaryResult, boundary
from spine_mj.validate.fractal_lock import FractalLockResult, fractal_lock
from spine_mj.validate.plans import (
    FRECHET_TARGET,
    MASS_KG,
    OUTCOME_TARGET,
    PLANS,
    SANDPAPER_MU,
    STATIC_TARGET,
    ValidationPlan,
)
from spine_mj.validate.quasistatic_limit import QuasistaticLimitResult, quasistatic_limit
from spine_mj.validate.report import write_report
from spine_mj.validate.runner import StudyRunner, ValidationProgress
from spine_mj.validate.sandpaper import SandpaperResult, sandpaper
from spine_mj.validate.static_map import StaticMapResult, static_map
from spine_mj.validate.stick_slip import StickSlipResult, stick_slip
from spine_mj.validate.stiffness_map import StiffnessMapResult, stiffness_map
from spine_mj.workers import check_workers

__all__ = ["run_validation"]


def run_validation(
    out_dir: str | os.PathLike,
    *,
    plan: ValidationPlan | str = "quick",
    workers: int | None = None,
    progress: Callable[[ValidationProgress], None] | None = None,
) -> dict:
    """Run the validation suite into ``out_dir``: sweeps, ``validation.json``, ``report.md``.

    Parameters
    ----------
    out_dir : path
        Created if missing; ``out_dir/sweeps`` holds one resumable sweep store per study
        (a killed run resumes where it stopped), ``out_dir/figures`` the PNGs.
    plan : ValidationPlan or {"quick", "full", "smoke"}
    workers : int, optional
        Local worker processes of the sweeps (default: all cores).
    progress : callable, optional
        Called with :class:`ValidationProgress` after every finished case and phase.

    Returns
    -------
    dict
        The content of ``validation.json``.

    Raises
    ------
    SpineInputError
        Unknown plan, bad ``workers``, or ``out_dir`` is a file.
    """
    if isinstance(plan, str):
        if plan not in PLANS:
            raise SpineInputError(f"plan must be one of {sorted(PLANS)}, got {plan!r}")
        plan = PLANS[plan]
    if workers is not None:
        check_workers(workers)  # before anything is written
    out = Path(out_dir).resolve()  # stores refer to files under it: one absolute root
    if out.exists() and not out.is_dir():
        raise SpineInputError(f"--out {out} exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    remove_temporaries(out)  # of a killed run this one resumes
    t0 = time.perf_counter()
    runner = StudyRunner(out, workers, progress, t0)
    timings = {}

    def timed(name, func, *args, **kw):
        t = time.perf_counter()
        res = func(*args, **kw)
        timings[name] = round(time.perf_counter() - t, 2)
        return res

    st = timed("static", static_map, plan, runner)
    lim = timed("limit", quasistatic_limit, plan, runner)
    bnd = timed("boundary", boundary, plan, runner)
    ss = timed("stick_slip", stick_slip, plan, runner)
    sp = (
        timed("sandpaper", sandpaper, plan, runner)
        if plan.sandpaper_grits
        else SandpaperResult(rows=[], paths={}, mu=SANDPAPER_MU)
    )
    fr = timed("fractal_lock", fractal_lock, plan, runner)
    km = timed("stiffness_map", stiffness_map, plan, runner)
    runner.study = "report"
    with runner.phase("figures and report"):
        result = _summary(plan, st, lim, bnd, ss, sp, timings, fr)
        result.update(_stiffness_map_summary(km))
        write_report(out, result, static=st, limit=lim, boundary=bnd, stick=ss, sand=sp, fractal=fr, kmap=km)
    result["timings_s"]["total"] = round(time.perf_counter() - t0, 2)
    write_json(out / "validation.json", result)
    return result


def _summary(
    plan: ValidationPlan,
    st: StaticMapResult,
    lim: QuasistaticLimitResult,
    bnd: BoundaryResult,
    ss: StickSlipResult,
    sp: SandpaperResult,
    timings: dict,
    fr: FractalLockResult,
) -> dict:
    """The content of ``validation.json`` (``timings_s`` is ``timings``, not a copy)."""
    return {
        "plan": plan.name,
        "static_kappa_max_rel_error": st.static_kappa_max_rel_error,
        "static_by_engine": st.per_engine,
        "lowest_ie": plan.lowest_ie,
        "outcome_agreement_at_lowest_ie": {k: v["outcome_agreement"] for k, v in lim.families.items()},
        "mean_frechet_at_lowest_ie": {k: v["mean_frechet"] for k, v in lim.families.items()},
        "median_frechet_at_lowest_ie": {k: v["median_frechet"] for k, v in lim.families.items()},
        "failed_runs": {k: v["failed_runs"] for k, v in lim.families.items()},
        "limit_families": lim.families,
        "limit_variations": lim.variations,
        "ie_star": bnd.ie_star,
        "ie_curves": {k: c.as_dict() for k, c in bnd.curves.items()},
        "trap_skip_rate": bnd.skip_rate,
        "stick_slip": ss.rows,
        "sandpaper": sp.rows,
        "fractal_lock_rate": fr.as_dict(),
        "targets": {
            "outcome_agreement": OUTCOME_TARGET,
            "mean_frechet_lc": FRECHET_TARGET,
            "static_kappa_rel_error": STATIC_TARGET,
        },
        "engine_settings": _engine_settings(plan),
        "timings_s": timings,
    }


def _stiffness_map_summary(km: StiffnessMapResult) -> dict:
    """The map's ``validation.json`` keys: ``ie_star_by_stiffness`` (family -> K -> I_e*
    with bracket ``low``/``high``, bootstrap ``ci_low``/``ci_high`` and ``kind``) and
    ``stiffness_map`` (the agreement grid with n_ok / n per cell, the energy and slip
    tables)."""
    return {"ie_star_by_stiffness": km.ie_star(), "stiffness_map": km.as_dict()}


def _engine_settings(plan: ValidationPlan) -> dict:
    """The recommended engine settings (on the default single Gaussian), their rule, and
    the plan's variants."""
    recommended = sim.default_engine(
        sim.Scales.for_surface(single_gaussian(), tip=sim.TipParams(tip_radius_m=5e-4, mass_kg=MASS_KG))
    )
    return {
        "recommended": {
            k: (v.value if hasattr(v, "value") else v) for k, v in dataclasses.asdict(recommended).items()
        },
        "rule": "dt = min(1 ms, sqrt(0.005 min(r_tip, L_c) m / F_p)), solref = (2 dt, 1), "
        "elliptic cone, noslip_iterations = 3, impratio = 1 (spine_mj.sim)",
        "static_variants": {label: dict(ov) for label, ov in plan.static_engines},
        "hfield_resolution": plan.hfield_resolution,
        "mass_kg": MASS_KG,
        "length_scale_m": sim.DEFAULT_LENGTH_SCALE_M,
    }
