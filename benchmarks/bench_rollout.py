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
import time

import mujoco
import numpy as np
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


if __name__ == "__main__":
    main()
