"""Stick-phase fast-forward of the force ramp: same physics as the plain ramp, fewer steps.

    .venv/bin/python benchmarks/bench_fastforward.py [--ie 1e-2] [--cycles 2] [--res 61]

For each case (inclined planes at several slopes; the paper's single peak and valley from
several starts on an hfield of ``--res`` samples a side) the plain ramp
(``fast_forward=False``) and the default one run for the same number of ramp cycles. Prints
per case the breakaway forces after each reset (largest relative difference; target
<= 0.5 %), the Frechet distance of the paths over ``L_c`` (target <= 0.01), the end
reasons, the engine steps of each and their ratio, and the load average. Writes nothing.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import time

import numpy as np

from spine_mj import compare, sim
from spine_mj.sim.ramp import cycle_breakaways, rows_to_reset
from spine_mj.validate.ramp_plan import pilot_rig


def _cases(res: int):
    for slope in (-15.0, 0.0, 10.0, 20.0, 25.0):
        rig = sim.Rig(sim.inclined_plane(slope_deg=slope), tip=sim.TipParams(tip_radius_m=5e-4, mu_s=0.5))
        yield f"plane {slope:g} deg", rig, (-0.01, 0.0)
    for preset, mu in (("paper-single-peak", 1.23), ("paper-single-valley", 1.23)):
        rig, _ = pilot_rig(preset, None, mu, 0.1, res)
        for y0 in (-0.5, -1.0, -2.0, -3.0):
            yield f"{preset} y0={y0:g}", rig, (-3.0, y0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ie", type=float, default=1e-2)
    ap.add_argument("--cycles", type=int, default=2)
    ap.add_argument("--res", type=int, default=61)
    args = ap.parse_args()
    for name, rig, start in _cases(args.res):
        sc = rig.scales
        rate = math.sqrt(args.ie) * sc.preload_n / sc.time_s
        per_cycle = 5 * sc.preload_n / rate + 400 * rig.engine.timestep_s
        drive = sim.RampDrive(
            rate_n_s=rate, duration_s=args.cycles * per_cycle, slide_distance_m=0.05 * sc.char_length_m
        )
        t0 = time.perf_counter()
        plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=start)
        t1 = time.perf_counter()
        fast = rig.run(drive, start=start)
        t2 = time.perf_counter()
        kp, kf = cycle_breakaways(plain, args.cycles), cycle_breakaways(fast, args.cycles)
        k = min(kp.size, kf.size)
        dk = float(np.max(np.abs(kf[:k] / kp[:k] - 1))) if k else math.nan
        a, b = (
            plain.position_m[: rows_to_reset(plain, args.cycles), :2],
            fast.position_m[: rows_to_reset(fast, args.cycles), :2],
        )
        fr = compare.path_frechet(b, a, length_scale=sc.char_length_m)
        n_p, n_f = rows_to_reset(plain, args.cycles), rows_to_reset(fast, args.cycles)
        print(
            f"{name:32s} breakaways {k}/{kp.size} max rel diff {dk:.2e}  Frechet/L_c {fr:.2e}  "
            f"end {plain.end_reason.value}/{fast.end_reason.value}  "
            f"steps {n_p}/{n_f} = {n_p / max(n_f, 1):.1f}x  "
            f"wall {t1 - t0:.1f}/{t2 - t1:.1f} s  load {os.getloadavg()[0]:.1f}"
        )


if __name__ == "__main__":
    main()
