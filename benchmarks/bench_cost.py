"""Cost of a spring-drive run: steps per run against I_e and the spring stiffness K on the
single peak and on a fractal, with a fitted cost model (:func:`fit_cost`).

    python benchmarks/run_all.py --only cost
"""

from __future__ import annotations

import math
import time

import numpy as np
from bench_common import rig_detection


def bench_cost(quick: bool) -> dict:
    """Steps per spring-drive run against I_e and K on two surface families, and fits."""
    from spine_mj import presets
    from spine_mj.sim import Rig, SpringDrive, TipParams

    # I_e where the contact sets the step; above ~0.008 (peak) the impact rule shortens it as
    # I_e^-1/2, so the steps grow as 1 / I_e there (sim.default_engine)
    ies = [3e-4, 1e-3, 3e-3] if quick else [1e-4, 3e-4, 1e-3, 3e-3]
    stiffness_numbers = [3.0, 10.0, 30.0]  # K = k l_s / F_p (30: the default)
    n_starts = 2 if quick else 4
    families = {}
    for family, preset in (("single peak", "paper-single-peak"), ("fractal", "paper-fractal")):
        surface = presets.make_surface(preset)
        rig = Rig(surface, tip=TipParams(mu_s=presets.calibrated_mu(preset)))
        sc = rig.scales
        xmin, _, ymin, ymax = surface.bounds
        starts = [(0.9 * xmin, float(y)) for y in np.linspace(0.8 * ymin, 0.8 * ymax, n_starts)]
        rows = []
        for ie in ies:
            for kf in stiffness_numbers:
                drive = SpringDrive(speed_m_s=sc.speed_for(ie), stiffness_n_m=sc.stiffness_for(kf))
                t0 = time.perf_counter()
                res = rig.run_batch(drive, starts, nthread=1)
                wall = time.perf_counter() - t0
                planned = rig.controls(drive, rig.place(*starts[0]), rig_detection(rig)).shape[0]
                rows.append(
                    {
                        "ie": ie,
                        "K": kf,
                        "planned_steps": planned,
                        "simulated_steps_mean": float(np.mean([r.simulated_steps for r in res])),
                        "recorded_steps_mean": float(np.mean([r.n for r in res])),
                        "end_reasons": sorted({r.end_reason.value for r in res}),
                        "wall_s_per_run": wall / len(starts),
                    }
                )
        families[family] = {
            "preset": preset,
            "timestep_s": rig.engine.timestep_s,
            "rows": rows,
            "fit": fit_cost(rows),
        }
    return {"starts_per_point": n_starts, "families": families}


def fit_cost(rows: list[dict]) -> dict:
    """Fit the simulated steps per run (``planned_steps``: rollout steps every planned step).

    Model: ``steps = s0 + I_e^-1/2 (A + B / K)`` with ``K = k l_s / F_p``: a run lasts
    (path + spring stretch) / speed, the speed is ``sqrt(I_e) v_c`` and dt is fixed by the
    contact. Also the plain power law ``steps = a I_e^b`` (b should be ~ -1/2).
    Quality: R^2 and the largest relative error of each fit.
    """
    ie = np.array([r["ie"] for r in rows])
    kf = np.array([r["K"] for r in rows])
    y = np.array([r["planned_steps"] for r in rows], dtype=float)
    design = np.c_[np.ones_like(ie), ie**-0.5, ie**-0.5 / kf]
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    pred = design @ coef
    b, loga = np.polyfit(np.log(ie), np.log(y), 1)
    pred_pow = np.exp(loga) * ie**b

    def quality(p):
        r2 = 1 - np.sum((y - p) ** 2) / np.sum((y - y.mean()) ** 2)
        return float(r2), float(np.max(np.abs(p / y - 1)))

    r2, err = quality(pred)
    r2p, errp = quality(pred_pow)
    return {
        "model": "steps = s0 + I_e^-1/2 (A + B / K), K = k l_s / F_p",
        "s0": float(coef[0]),
        "A": float(coef[1]),
        "B": float(coef[2]),
        "r2": r2,
        "max_rel_err": err,
        "power_law": {"a": float(math.exp(loga)), "b": float(b), "r2": r2p, "max_rel_err": errp},
    }


def markdown(cost: dict | None) -> list[str]:
    """The cost model's tables of the Performance page."""
    if not cost:
        return []
    out = [
        "",
        "**Cost model** (spring drive, planned steps per run: what a run takes at most at its "
        "step; a run whose outcome is decided earlier stops within a piece of its end, and a "
        "run stopped on penetration runs once more at a quarter of the step (`Rig.run_batch`'s "
        "`refine`), up to 4x its planned steps more: see the simulated steps). "
        "A run lasts (path + spring stretch) / "
        "speed with speed = sqrt(I_e) v_c and dt fixed by the contact, so "
        "`steps = s0 + I_e^-1/2 (A + B / K)` with `K = k l_s / F_p` (the spring's stretch "
        "`(1 + mu) l_s / K`), up to I_e ~ 0.008 (single peak), where the impact rule starts "
        "to shorten the step as I_e^-1/2. Size a sweep as at most "
        "runs x steps / (steps/s of `Rig.run_batch` above).",
        "",
        "| surface | dt [s] | s0 | A | B | R^2 | max rel. err | power law a I_e^b: b (R^2) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for fam, f in cost["families"].items():
        fit = f["fit"]
        pl = fit["power_law"]
        out.append(
            f"| {fam} | {f['timestep_s']:g} | {fit['s0']:.0f} | {fit['A']:.0f} | {fit['B']:.0f} | "
            f"{fit['r2']:.5f} | {fit['max_rel_err']:.2%} | {pl['b']:.3f} ({pl['r2']:.4f}) |"
        )
    out += [
        "",
        "| surface | I_e | K = k l_s / F_p | planned steps | simulated steps (mean) | recorded steps (mean) "
        "| wall s / run | end |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for fam, f in cost["families"].items():
        for r in f["rows"]:
            sim_steps = r.get("simulated_steps_mean", float(r["planned_steps"]))
            out.append(
                f"| {fam} | {r['ie']:g} | {r['K']:g} | {r['planned_steps']} | {sim_steps:.0f} | "
                f"{r['recorded_steps_mean']:.0f} | {r['wall_s_per_run']:.3f} | "
                f"{', '.join(r['end_reasons'])} |"
            )
    out.append(f"\nLoad during the cost runs: {cost['load_before']}-{cost['load_after']}.")
    return out
