"""The validation suite: runs the studies for a plan and writes ``validation.json`` and
``report.md`` (with PNG figures) into one output folder.
"""

from __future__ import annotations

import dataclasses
import os
import resource
import time
from collections.abc import Callable
from pathlib import Path

from spine_mj import sim
from spine_mj.atomic import remove_temporaries
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import write_json
from spine_mj.surfaces import single_gaussian
from spine_mj.sweep.kernel_warmup import warm_kernels
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET
from spine_mj.validate import studies
from spine_mj.validate.intervals import TARGET_RULE
from spine_mj.validate.plans import MASS_KG, PLANS, STATIC_TARGET, ValidationPlan
from spine_mj.validate.platform import platform_info
from spine_mj.validate.report.document import write_report
from spine_mj.validate.study_runner import StudyRunner, ValidationProgress
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
        The content of ``validation.json``; per study (and ``report``, ``total``) its wall
        seconds in ``timings_s`` and its CPU seconds in ``cpu_s`` (the process and the workers it forked).

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
    timings, cpu = {}, {}
    c0 = _cpu_seconds()
    runner.study = "kernels"
    with runner.phase("compiling the kernels"):
        warm_kernels(runner.n_workers)  # once, not in every worker of the first sweeps
    timings["kernels"], cpu["kernels"] = round(time.perf_counter() - t0, 2), round(_cpu_seconds() - c0, 2)
    results = []
    for study in studies.STUDIES:
        t, c = time.perf_counter(), _cpu_seconds()
        results.append(study.run(plan, runner))
        timings[study.name] = round(time.perf_counter() - t, 2)
        cpu[study.name] = round(_cpu_seconds() - c, 2)
    runner.study = "report"
    with runner.phase("figures and report"):
        c = _cpu_seconds()
        result = _summary(plan, results, timings)
        write_report(out, result, results)
        cpu["report"] = round(_cpu_seconds() - c, 2)
    result["timings_s"]["total"] = round(time.perf_counter() - t0, 2)
    cpu["total"] = round(_cpu_seconds() - c0, 2)
    result["cpu_s"] = cpu
    write_json(out / "validation.json", result)
    return result


def _cpu_seconds() -> float:
    """CPU seconds of this process (every thread) and of its finished child processes (the
    sweeps' local workers, forked and joined): what a study costs on any machine, where its
    wall time depends on the load and the cores (``validation.json``'s ``cpu_s``, per study)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def _summary(plan: ValidationPlan, results: list, timings: dict) -> dict:
    """The content of ``validation.json``: the plan, every study's keys
    (``validation_keys()``), the targets and engine settings (``timings_s`` is
    ``timings``, not a copy)."""
    summary = {"plan": plan.name}
    for res in results:
        summary.update(res.validation_keys())
    summary["targets"] = {
        "outcome_agreement": OUTCOME_TARGET,
        "mean_frechet_lc": FRECHET_TARGET,
        "static_kappa_rel_error": STATIC_TARGET,
        "rule": TARGET_RULE,
    }
    summary["engine_settings"] = _engine_settings(plan)
    summary["platform"] = platform_info()
    summary["timings_s"] = timings
    return summary


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
        "static_variants": {label: dict(ov) for label, ov in plan.static.engines},
        "hfield_resolution": plan.hfield_resolution,
        "mass_kg": MASS_KG,
        "length_scale_m": sim.DEFAULT_LENGTH_SCALE_M,
    }
