"""Sweep runner benchmark (a script, not a test): prints three figures.

1. Throughput of a one-worker MuJoCo sweep against bare ``mujoco.rollout`` of the same
   models, initial states, controls and recording (state and sensors of every step):
   ``bare time / sweep time`` (target >= 0.9). The sweep's time includes placing the tip,
   cutting runs at their end events, metrics and writing the store.
2. Parallel efficiency of the same sweep on 2 workers: ``T(1) / (2 T(2))`` (target >= 0.85;
   the second run includes starting the worker processes).
3. Peak memory (RSS of the sweep process) across 10,000 quasistatic runs, sampled as the
   sweep goes: it should stay flat.

    python benchmarks/bench_sweep.py [--quick] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_common import target_cell

from spine_mj import sweep

MUJOCO_CONFIG = {
    "sweep": {"name": "bench-mujoco", "analyses": ["engine"]},
    "surfaces": [{"preset": "paper-single-peak"}, {"preset": "paper-single-valley"}],
    "starts": {"frame": "absolute", "x": [-3.0], "y": {"linspace": [-4.0, 0.0], "num": 8}},
    "drive": {"protocol": "spring"},
    "grid": {"mu": 1.23},
}


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        pages = int(fh.read().split()[1])
    return pages * resource.getpagesize() / 2**20


def bare_rollout_time(config: sweep.SweepConfig) -> float:
    """Seconds of ``mujoco.rollout`` alone for every case of ``config`` (one thread)."""
    import mujoco
    from mujoco import rollout

    from spine_mj import sim
    from spine_mj.sweep.analyses import engine as an

    total = 0.0
    for case in sweep.expand_cases(config):
        p = case.params
        surface = case.surface.make()
        rig = an.case_rig(case, surface)
        sc = rig.scales
        speed = (p["ie"] * sc.preload_n * sc.char_length_m / sc.mass_kg) ** 0.5
        drive = sim.SpringDrive(speed_m_s=speed)
        det = sim.Detection().resolve(sc)
        starts = case.starts.resolve(surface.bounds, case.seed)
        qpos0 = [rig.place(*s) for s in starts]
        ctrl = np.stack([rig.controls(drive, q, det) for q in qpos0])
        models = [rig.model_for(drive) for _ in qpos0]
        nstate = mujoco.mj_stateSize(rig.model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        init = np.zeros((len(qpos0), nstate))
        init[:, 1:4] = qpos0
        spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
        with rollout.Rollout(nthread=1) as pool:
            datas = [mujoco.MjData(rig.model)]
            t0 = time.perf_counter()
            pool.rollout(
                models,
                datas,
                init,
                ctrl,
                control_spec=spec,
                initial_warmstart=np.zeros((len(qpos0), rig.model.nv)),
            )
            total += time.perf_counter() - t0
    return total


def timed_sweep(config, out: Path, **kwargs) -> float:
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    summary = sweep.run_sweep(config, out, **kwargs)
    elapsed = time.perf_counter() - t0
    assert summary.run_cases == summary.total_cases
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer runs")
    parser.add_argument("--out", type=Path, default=None, help="scratch folder")
    args = parser.parse_args()
    scratch = args.out or Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    load = os.getloadavg()

    n_ie = 2 if args.quick else 12
    doc = dict(MUJOCO_CONFIG, grid={"mu": 1.23, "ie": {"logspace": [1e-3, 1e-1], "num": n_ie}})
    config = sweep.parse_config(doc)
    cases = sweep.expand_cases(config)
    n_runs = sum(c.starts.count for c in cases)
    # warm caches (numba, surface, first rig) outside the timings
    sweep.run_case(cases[0])
    bare = bare_rollout_time(config)
    # the bare timing built and placed through the in-process rig cache: empty it, so the
    # one-worker sweep starts as cold as the two-worker one (rigs, placements)
    from spine_mj.sweep.analyses import engine as an

    an.case_rig.cache_clear()
    t1 = timed_sweep(config, scratch / "mj1", workers=1)
    t2 = timed_sweep(config, scratch / "mj2", workers=2)
    runs = sweep.load_runs(scratch / "mj1")
    cpu1 = runs.groupby("case_id").cpu_s.sum().sum()
    cpu2 = sweep.load_runs(scratch / "mj2").groupby("case_id").cpu_s.sum().sum()
    steps = int(runs.n_steps.sum())
    print(
        f"mujoco sweep: {len(cases)} cases, {n_runs} runs, {steps} recorded steps kept "
        f"(runs cut at their end events)"
    )
    print(f"  bare mujoco.rollout (1 thread):  {bare:8.2f} s")
    print(
        f"  sweep, 1 worker:                 {t1:8.2f} s   throughput ratio "
        f"bare/sweep = {bare / t1:.3f}  (target >= 0.9)"
    )
    print(
        f"  sweep, 2 workers:                {t2:8.2f} s   parallel efficiency "
        f"T1/(2 T2) = {t1 / (2 * t2):.3f}  (target >= 0.85)"
    )
    print(
        f"  CPU time in the analyses: {cpu1:.2f} s (1 worker), {cpu2:.2f} s (2 workers); "
        f"load average before: {load[0]:.2f} on {os.cpu_count()} cores (a busy machine "
        f"lowers the 2-worker figure)"
    )

    n_cases = 200 if args.quick else 2000
    qs_doc = {
        "sweep": {"name": "bench-memory", "analyses": ["quasistatic"]},
        "surfaces": [{"preset": "paper-single-peak"}],
        "starts": {"x": [0.05], "y": {"linspace": [0.1, 0.9], "num": 5}},
        "grid": {"mu": {"linspace": [0.5, 2.0], "num": n_cases}, "dl": 0.02},
    }
    qs = sweep.parse_config(qs_doc)
    samples = []

    def progress(p):
        if p.finished_cases % max(1, n_cases // 10) == 0:
            samples.append((p.finished_cases, _rss_mb()))

    out = scratch / "memory"
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    sweep.run_sweep(qs, out, workers=1, progress=progress)
    elapsed = time.perf_counter() - t0
    n_qs = len(sweep.load_runs(out, columns=["run_id"]))
    print(
        f"quasistatic sweep: {n_qs} runs in {n_cases} cases, {elapsed:.1f} s "
        f"({n_qs / elapsed:.0f} runs/s, 1 worker, store included)"
    )
    print("  RSS [MiB] after cases: " + ", ".join(f"{c}: {m:.0f}" for c, m in samples))
    first = samples[1][1] if len(samples) > 1 else samples[0][1]
    print(
        f"  growth from 10 % to 100 % of the runs: {samples[-1][1] - first:+.1f} MiB; "
        f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB"
    )
    if args.out is None:
        shutil.rmtree(scratch, ignore_errors=True)


def bench_sweep(quick: bool) -> dict:
    from spine_mj.sweep.analyses import engine as an

    n_ie = 2 if quick else 6
    doc = dict(MUJOCO_CONFIG, grid={"mu": 1.23, "ie": {"logspace": [1e-3, 1e-1], "num": n_ie}})
    config = sweep.parse_config(doc)
    cases = sweep.expand_cases(config)
    sweep.run_case(cases[0])  # warm caches outside the timings
    scratch = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    try:
        bare = bare_rollout_time(config)
        an.case_rig.cache_clear()
        t1 = timed_sweep(config, scratch / "mj1", workers=1)
        t2 = timed_sweep(config, scratch / "mj2", workers=2)
        steps = int(sweep.load_runs(scratch / "mj1").n_steps.sum())
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return {
        "cases": len(cases),
        "runs": sum(c.starts.count for c in cases),
        "recorded_steps": steps,
        "bare_s": bare,
        "sweep_1_worker_s": t1,
        "sweep_2_workers_s": t2,
        "bare_over_sweep": bare / t1,
        "parallel_efficiency": t1 / (2 * t2),
    }


def markdown(sw: dict | None) -> list[str]:
    """The sweep rows of the Performance table."""
    lines = []
    if sw:
        ld = f"{sw['load_before']}-{sw['load_after']}"
        lines += [
            f"| sweep, 1 worker / bare rollout ({sw['runs']} runs, store included) | "
            f"{sw['bare_over_sweep']:.3f} | {target_cell(sw['bare_over_sweep'], '>=', 0.9)} | {ld} |",
            f"| sweep parallel efficiency, 2 workers, T1 / (2 T2) | "
            f"{sw['parallel_efficiency']:.3f} | "
            f"{target_cell(sw['parallel_efficiency'], '>=', 0.85)} | {ld} |",
        ]
    return lines


if __name__ == "__main__":
    main()
