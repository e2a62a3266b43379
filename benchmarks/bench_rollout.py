"""Run rate of spine_mj's batched runs against bare ``mujoco.rollout`` (same model, controls
and recording), in one process.

    .venv/bin/python benchmarks/bench_rollout.py [--runs 64] [--threads N] [--duration 0.5]

spine_mj adds placement, per-run models (spring stiffness), control building, stepping
each run in pieces (so that a decided run can stop) and the analysis of each run
(stick/slip, events, end reason) around the same stepping. The runs do not end early
(``kappa_cap`` 1e6, 0.5 s on the single peak), so stopping decided runs saves nothing
here: the ratio is the cost of the machinery. The target is a ratio >= 0.95. Prints one
line per measurement; writes nothing.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import mujoco
import numpy as np
from bench_common import ci_text, fmt, median_interval, target_cell
from mujoco import rollout

from spine_mj.sim import Detection, Rig, SpringDrive, TipParams
from spine_mj.surfaces import single_gaussian


def paired_setup(runs: int, duration: float, threads: int):
    """``(bare, ours, nstep)``: two callables running the same ``runs`` spring-drive runs of
    ``duration`` simulated seconds, by bare ``mujoco.rollout`` and by ``Rig.run_batch``."""
    rig = Rig(single_gaussian(), tip=TipParams(tip_radius_m=5e-4, mu_s=1.2))
    drive = SpringDrive(speed_m_s=0.02, duration_s=duration)
    rng = np.random.default_rng(0)
    starts = [(-3.0, float(y)) for y in rng.uniform(-4, -0.5, runs)]
    det = Detection(kappa_cap=1e6)  # no early self-lock: both sides simulate every step

    # the bare side gets everything spine_mj computes before the rollout, for free
    det_r = det.resolve(rig.scales)
    qpos0 = [rig.place(*s) for s in starts]
    model = rig.model_for(drive)
    ctrl = np.stack([rig.controls(drive, q, det_r) for q in qpos0])
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    init = np.zeros((runs, nstate))
    init[:, 1:4] = qpos0
    spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)

    def bare():
        with rollout.Rollout(nthread=threads) as pool:
            datas = [mujoco.MjData(model) for _ in range(threads)]
            pool.rollout(
                [model] * runs,
                datas,
                init,
                ctrl,
                control_spec=spec,
                initial_warmstart=np.zeros((runs, model.nv)),
            )

    calls = iter(range(1, 10**6))

    def ours():
        # fresh starts (jittered by 1e-9 surface units) so no placement comes from the cache:
        # spine_mj pays for placing every tip, as a user with new starts would
        eps = 1e-9 * next(calls)
        rig.run_batch(drive, [(x + eps, y) for x, y in starts], detection=det, nthread=threads)

    return bare, ours, ctrl.shape[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=64)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--duration", type=float, default=0.5, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    bare, ours, nstep = paired_setup(args.runs, args.duration, args.threads)
    ours()  # warm-up
    bare()
    best = {}
    for _ in range(args.repeat):
        for name, fn in (("bare mujoco.rollout", bare), ("spine_mj run_batch", ours)):
            t0 = time.perf_counter()
            fn()
            dt = time.perf_counter() - t0
            best[name] = min(best.get(name, np.inf), dt)
    for name, dt in best.items():
        print(
            f"{name:22s} {args.runs / dt:8.1f} runs/s  {args.runs * nstep / dt:10.3g} steps/s "
            f"({args.runs} runs x {nstep} steps, {args.threads} threads)"
        )
    ratio = best["bare mujoco.rollout"] / best["spine_mj run_batch"]
    print(f"ratio spine_mj / bare = {ratio:.3f} (target >= 0.95)")


def bench_rollout(quick: bool) -> dict:
    """Paired timings of ``Rig.run_batch`` and bare ``mujoco.rollout`` (see bench_rollout.py)."""
    runs, duration, pairs = (16, 0.2, 5) if quick else (64, 0.5, 21)
    nthread = os.cpu_count() or 1
    bare, ours, nstep = paired_setup(runs, duration, nthread)
    ours()
    bare()  # warm-up
    t_bare, t_ours, cpu_main = [], [], []
    cpu = {bare: [], ours: []}  # the process's CPU per batch, all threads
    for k in range(pairs):
        order = ((t_bare, bare), (t_ours, ours)) if k % 2 == 0 else ((t_ours, ours), (t_bare, bare))
        for times, fn in order:
            t0, c0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
            fn()
            times.append(time.perf_counter() - t0)
            cpu[fn].append(time.process_time() - p0)
            if fn is ours:  # the calling thread's own CPU: it competes with the worker threads
                cpu_main.append(time.thread_time() - c0)
    ratios = [b / o for b, o in zip(t_bare, t_ours)]
    cpu_ratios = [b / o for b, o in zip(cpu[bare], cpu[ours])]
    steps = runs * nstep
    return {
        "runs": runs,
        "steps_per_run": nstep,
        "threads": nthread,
        "pairs": pairs,
        "bare_steps_s": steps / statistics.median(t_bare),
        "run_batch_steps_s": steps / statistics.median(t_ours),
        "ratios": ratios,
        "ratio_median": statistics.median(ratios),
        "ratio_median_ci95": median_interval(ratios),
        "cpu_ratios": cpu_ratios,
        "cpu_ratio_median": statistics.median(cpu_ratios),
        "calling_thread_cpu_s": statistics.median(cpu_main),
        "bare_wall_s": statistics.median(t_bare),
        "target": 0.95,
        "early": early_stop(quick, nthread),
    }


def early_stop(quick: bool, nthread: int) -> dict:
    """``Rig.run_batch`` on ``paper-fractal`` (preset mu, I_e 1e-3, default K), where most
    runs self-lock early: simulated steps and wall time with and without ``stop_early``."""
    from spine_mj import presets
    from spine_mj.sim import Rig, SpringDrive, TipParams

    surface = presets.make_surface("paper-fractal")
    rig = Rig(surface, tip=TipParams(mu_s=presets.calibrated_mu("paper-fractal")))
    xmin, xmax, ymin, ymax = surface.bounds
    n = 4 if quick else 8
    starts = [
        (xmin + 0.05 * (xmax - xmin), float(y))
        for y in np.linspace(ymin + 0.2 * (ymax - ymin), ymax - 0.2 * (ymax - ymin), n)
    ]
    drive = SpringDrive(speed_m_s=rig.scales.speed_for(1e-3))
    out = {"preset": "paper-fractal", "mu": rig.tip.mu_s, "ie": 1e-3, "runs": n}
    for stop in (False, True):
        t0 = time.perf_counter()
        res = rig.run_batch(drive, starts, nthread=nthread, stop_early=stop)
        out["early" if stop else "plain"] = {
            "wall_s": time.perf_counter() - t0,
            "simulated_steps": int(sum(r.simulated_steps for r in res)),
            "recorded_steps": int(sum(r.n for r in res)),
            "end_reasons": sorted({r.end_reason.value for r in res}),
        }
    return out


def markdown(ro: dict | None) -> list[str]:
    """The rollout rows of the Performance table."""
    lines = []
    if ro:
        ld = f"{ro['load_before']}-{ro['load_after']}"
        lines += [
            f"| bare `mujoco.rollout`, {ro['runs']} runs x {ro['steps_per_run']} steps, "
            f"{ro['threads']} threads | "
            f"{fmt(ro['bare_steps_s'])} steps/s | | {ld} |",
            f"| `Rig.run_batch`, same runs (tips placed afresh, analysis included) | "
            f"{fmt(ro['run_batch_steps_s'])} steps/s | | {ld} |",
            f"| `Rig.run_batch` / bare rollout, median of {ro['pairs']} paired runs "
            f"(range {min(ro['ratios']):.3f}-{max(ro['ratios']):.3f}{ci_text(ro)}) | "
            f"{ro['ratio_median']:.3f} | {target_cell(ro['ratio_median'], '>=', 0.95)} | {ld} |",
        ]
        if "cpu_ratio_median" in ro:  # results from before it was measured lack it
            lines.append(
                f"| `Rig.run_batch` / bare rollout in CPU time (all threads; a shared machine's "
                f"noise moves it less than the wall ratio), median of the same pairs "
                f"(range {min(ro['cpu_ratios']):.3f}-{max(ro['cpu_ratios']):.3f}) | "
                f"{ro['cpu_ratio_median']:.3f} | | {ld} |"
            )
        if "calling_thread_cpu_s" in ro:  # results from before it was measured lack it
            lines.append(
                "| `Rig.run_batch`: the calling thread's CPU per batch (placement, controls, "
                "analysis, results; it competes with the worker threads), median | "
                f"{1000 * ro['calling_thread_cpu_s']:.1f} ms, "
                f"{100 * ro['calling_thread_cpu_s'] / ro['bare_wall_s']:.1f} % of a bare batch's "
                f"wall | | {ld} |"
            )
        e = ro.get("early")
        if e:
            p, q = e["plain"], e["early"]
            lines.append(
                f"| `Rig.run_batch` stopping decided runs, {e['preset']} (mu {e['mu']:g}, I_e {e['ie']:g}, "
                f"{e['runs']} runs, ends: {', '.join(q['end_reasons'])}): simulated steps, wall | "
                f"{q['simulated_steps']} instead of {p['simulated_steps']} "
                f"({p['simulated_steps'] / q['simulated_steps']:.1f}x fewer; "
                f"recorded {q['recorded_steps']}), "
                f"{q['wall_s']:.2f} s instead of {p['wall_s']:.2f} s | | {ld} |"
            )
    return lines


if __name__ == "__main__":
    main()
