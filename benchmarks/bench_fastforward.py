"""Stick-phase fast-forward of the force ramp and the static probe: same physics, fewer steps.

    .venv/bin/python benchmarks/bench_fastforward.py [--ie 1e-2] [--cycles 2] [--res 61]

Ramp: for each case (inclined planes at several slopes; the paper's single peak and valley
from several starts on an hfield of ``--res`` samples a side) the plain ramp
(``fast_forward=False``) and the default one run for the same number of ramp cycles.
Prints per case the breakaway forces after each reset (largest relative difference;
target <= 0.5 %), the Frechet distance of the paths over ``L_c`` (target <= 0.01), the end
reasons, the engine steps of each and their ratio, and the load average.

Static probe (:func:`probe_rows`): the static map's probe (validate.static_map) on inclined
planes at several slopes and azimuths and on the single peak, plain and fast-forwarded, at
``--ie``: kappa_mj of each (target: within 0.5 %), the recorded rows and the simulated
steps. Writes nothing.
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
from spine_mj.validate.ramp_pilot import pilot_rig
from spine_mj.validate.static_map import hold_force

#: (slope, azimuth) of the probe's planes [deg]: engaged planes of the static map.
PROBE_PLANES = ((0.0, 0.0), (15.0, 0.0), (30.0, 0.0), (45.0, 0.0), (52.5, 0.0), (30.0, 30.0), (30.0, 60.0))
#: Probe starts on the single peak (surface units).
PROBE_PEAK_STARTS = ((-3.0, -1.0), (-2.0, -2.0), (-3.0, 1.0), (-1.0, 1.5), (2.0, 0.5))


def _cases(res: int):
    for slope in (-15.0, 0.0, 10.0, 20.0, 25.0):
        rig = sim.Rig(sim.inclined_plane(slope_deg=slope), tip=sim.TipParams(tip_radius_m=5e-4, mu_s=0.5))
        yield f"plane {slope:g} deg", rig, (-0.01, 0.0)
    for preset, mu in (("paper-single-peak", 1.23), ("paper-single-valley", 1.23)):
        rig, _ = pilot_rig(preset, None, mu, 0.1, res)
        for y0 in (-0.5, -1.0, -2.0, -3.0):
            yield f"{preset} y0={y0:g}", rig, (-3.0, y0)


def _probe_cases(res: int, ie: float):
    """(name, rig, start, probe) of the probe comparison."""
    for slope, az in PROBE_PLANES:
        rig = sim.Rig(sim.inclined_plane(slope_deg=slope, azimuth_deg=az), tip=sim.TipParams(mu_s=0.5))
        t = math.tan(math.radians(slope))
        k, low, _ = hold_force(t * math.cos(math.radians(az)), t * math.sin(math.radians(az)), 0.5)
        sc = rig.scales
        probe = sim.StaticProbe(
            rate_n_s=sc.force_rate_for(sc.speed_for(ie)),
            start_force_n=(0.5 * (low + k) if low > 0 else 0.0) * sc.preload_n,
        )
        yield f"plane {slope:g} deg, azimuth {az:g}", rig, (0.0, 0.0), probe
    rig, _ = pilot_rig("paper-single-peak", None, 1.23, 0.1, res)
    sc = rig.scales
    probe = sim.StaticProbe(rate_n_s=sc.force_rate_for(sc.speed_for(ie)))
    for start in PROBE_PEAK_STARTS:
        yield f"single peak {start}", rig, start, probe


def probe_rows(res: int, ie: float) -> list[dict]:
    """Plain and fast-forwarded static probes on every case: kappa_mj, rows, simulated steps."""
    rows = []
    for name, rig, start, probe in _probe_cases(res, ie):
        t0 = time.perf_counter()
        plain = rig.run(dataclasses.replace(probe, fast_forward=False), start=start)
        t1 = time.perf_counter()
        fast = rig.run(probe, start=start)
        t2 = time.perf_counter()
        rows.append(
            {
                "case": name,
                "end": f"{plain.end_reason.value}/{fast.end_reason.value}",
                "kappa_plain": plain.kappa_mj,
                "kappa_fast": fast.kappa_mj,
                "rel_diff": fast.kappa_mj / plain.kappa_mj - 1,
                "rows_plain": plain.n,
                "rows_fast": fast.n,
                "steps_plain": plain.simulated_steps,
                "steps_fast": fast.simulated_steps,
                "wall_s": (t1 - t0, t2 - t1),
            }
        )
    return rows


def ramp_rows(res: int, ie: float, cycles: int) -> list[dict]:
    """Plain and fast-forwarded ramps for ``cycles`` cycles on every case: breakaway forces,
    Frechet distance of the paths, rows to the last reset of each."""
    rows = []
    for name, rig, start in _cases(res):
        sc = rig.scales
        rate = sc.force_rate_for(sc.speed_for(ie))
        per_cycle = 5 * sc.preload_n / rate + 400 * rig.engine.timestep_s
        drive = sim.RampDrive(
            rate_n_s=rate, duration_s=cycles * per_cycle, slide_distance_m=0.05 * sc.char_length_m
        )
        t0 = time.perf_counter()
        plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=start)
        t1 = time.perf_counter()
        fast = rig.run(drive, start=start)
        t2 = time.perf_counter()
        kp, kf = cycle_breakaways(plain, cycles), cycle_breakaways(fast, cycles)
        k = min(kp.size, kf.size)
        n_p, n_f = rows_to_reset(plain, cycles), rows_to_reset(fast, cycles)
        rows.append(
            {
                "case": name,
                "breakaways": f"{k}/{kp.size}",
                "max_rel_diff": float(np.max(np.abs(kf[:k] / kp[:k] - 1))) if k else math.nan,
                "frechet_lc": compare.path_frechet(
                    fast.position_m[:n_f, :2], plain.position_m[:n_p, :2], length_scale=sc.char_length_m
                ),
                "end": f"{plain.end_reason.value}/{fast.end_reason.value}",
                "steps_plain": n_p,
                "steps_fast": n_f,
                "wall_s": (t1 - t0, t2 - t1),
            }
        )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ie", type=float, default=1e-2)
    ap.add_argument("--cycles", type=int, default=2)
    ap.add_argument("--res", type=int, default=61)
    args = ap.parse_args()
    for r in ramp_rows(args.res, args.ie, args.cycles):
        print(
            f"{r['case']:32s} breakaways {r['breakaways']} max rel diff {r['max_rel_diff']:.2e}  "
            f"Frechet/L_c {r['frechet_lc']:.2e}  end {r['end']}  "
            f"steps {r['steps_plain']}/{r['steps_fast']} = {r['steps_plain'] / r['steps_fast']:.1f}x  "
            f"wall {r['wall_s'][0]:.1f}/{r['wall_s'][1]:.1f} s  load {os.getloadavg()[0]:.1f}"
        )
    for r in probe_rows(args.res, args.ie):
        print(
            f"probe {r['case']:36s} end {r['end']}  kappa_mj {r['kappa_plain']:.4f}/{r['kappa_fast']:.4f} "
            f"rel diff {r['rel_diff']:.1e}  rows {r['rows_plain']}/{r['rows_fast']}  "
            f"steps {r['steps_plain']}/{r['steps_fast']} = {r['steps_plain'] / r['steps_fast']:.1f}x  "
            f"load {os.getloadavg()[0]:.1f}"
        )


if __name__ == "__main__":
    main()
