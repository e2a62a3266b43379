"""The static kappa error on inclined planes (breakaway force / F_p against
``tan(theta + arctan mu)``) of the CPU engine with noslip, without noslip at a high
impratio, and of MuJoCo Warp with both where a CUDA device exists; GPU against CPU
throughput.

    python benchmarks/run_all.py --gpu --only gpu
"""

from __future__ import annotations

import math
import time

import numpy as np
from bench_common import fmt, rig_detection


def static_kappa(rig, slopes, mu, backend_fn) -> list[dict]:
    """Static probe kappa on each inclined plane against ``tan(theta + arctan mu)``."""
    from spine_mj.sim import StaticProbe

    out = []
    for slope, r in zip(slopes, backend_fn(StaticProbe())):
        exact = math.tan(math.radians(slope) + math.atan(mu))
        out.append(
            {"slope_deg": slope, "kappa": r.kappa_mj, "exact": exact, "rel_err": r.kappa_mj / exact - 1}
        )
    return out


def bench_gpu(quick: bool) -> dict:
    """Static kappa error of each engine setting, and GPU against CPU throughput."""
    import dataclasses

    from spine_mj.sim import Rig, TipParams, gpu
    from spine_mj.surfaces import inclined_plane

    mu, slopes = 0.5, [0.0, 10.0, 20.0, 25.0]  # below arctan(mu) = 26.6 deg: no start force needed
    high_impratio = 100.0
    has_gpu = gpu.gpu_available()
    settings = {"noslip (CPU default)": {}, f"no noslip, impratio {high_impratio:g}": {}}
    settings[f"no noslip, impratio {high_impratio:g}"] = {"noslip_iterations": 0, "impratio": high_impratio}
    rows = {}
    for label, over in settings.items():
        for engine_name in ("cpu", "gpu") if has_gpu else ("cpu",):
            results = []
            for slope in slopes:
                base = Rig(inclined_plane(slope_deg=slope), tip=TipParams(tip_radius_m=5e-4, mu_s=mu))
                rig = Rig(
                    inclined_plane(slope_deg=slope),
                    tip=TipParams(tip_radius_m=5e-4, mu_s=mu),
                    engine=dataclasses.replace(base.engine, **over),
                )
                if engine_name == "cpu":
                    run = lambda drive, rig=rig: rig.run_batch(drive, [(3.1e-4, 2.7e-4)])  # noqa: E731
                else:
                    run = lambda drive, rig=rig: gpu.run_batch_gpu(rig, drive, [(3.1e-4, 2.7e-4)])  # noqa: E731
                results += static_kappa(rig, [slope], mu, run)
            rows[f"{engine_name}: {label}"] = results
    out = {"gpu_available": has_gpu, "missing_packages": gpu.missing_packages(), "mu": mu, "kappa": rows}
    if has_gpu:
        out["throughput"] = gpu_throughput(quick)
    return out


def gpu_throughput(quick: bool) -> dict:
    from spine_mj import presets
    from spine_mj.sim import Rig, SpringDrive, gpu

    surface = presets.make_surface("paper-single-peak")
    rig = Rig(surface)
    drive = SpringDrive(speed_m_s=rig.scales.speed_for(1e-2), duration_s=0.5)
    out = {}
    for n in (256, 4096) if not quick else (256,):
        starts = [(-4.5, float(y)) for y in np.linspace(-4, 4, n)]
        gpu.run_batch_gpu(rig, drive, starts[:8])  # compile
        t0 = time.perf_counter()
        res = gpu.run_batch_gpu(rig, drive, starts)
        t_gpu = time.perf_counter() - t0
        t0 = time.perf_counter()
        rig.run_batch(drive, starts)
        t_cpu = time.perf_counter() - t0
        steps = n * rig.controls(drive, rig.place(*starts[0]), rig_detection(rig)).shape[0]
        out[str(n)] = {"gpu_steps_s": steps / t_gpu, "cpu_steps_s": steps / t_cpu, "runs_ended": len(res)}
    return out


def markdown(g: dict | None) -> list[str]:
    """The static kappa error and GPU throughput of the Performance page."""
    if not g:
        return [
            "",
            "GPU backend (`pip install 'spine_mj[gpu]'`, `backend='gpu'`): not measured in this "
            "run; `python benchmarks/run_all.py --gpu` measures its static kappa error and throughput.",
        ]
    out = [
        "",
        f"**Static kappa error** (static probe on inclined planes, mu = {g['mu']}, breakaway "
        "force / F_p against tan(theta + arctan mu)); GPU "
        + ("measured." if g["gpu_available"] else "not available on this machine: CPU rows only."),
        "",
        "| engine | " + " | ".join(f"{r['slope_deg']:g} deg" for r in next(iter(g["kappa"].values()))) + " |",
        "| --- |" + " --- |" * len(next(iter(g["kappa"].values()))),
    ]
    for label, rows in g["kappa"].items():
        out.append(f"| {label} | " + " | ".join(f"{r['rel_err']:+.2%}" for r in rows) + " |")
    for n, t in g.get("throughput", {}).items():
        out.append(
            f"\nGPU {n} runs: {fmt(t['gpu_steps_s'])} steps/s against {fmt(t['cpu_steps_s'])} on the CPU."
        )
    out.append(f"\nLoad: {g['load_before']}-{g['load_after']}.")
    return out
