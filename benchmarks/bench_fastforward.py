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
steps.

Spring drive (:func:`spring_rows`, ``--spring``): the cost of a spring run against I_e
(1e-4, 1e-5, 1e-6) and K (3, 30, 300, 3000) with and without fast-forward, on the paper
fractal (seed 1, mu 0.5, two starts, 0.25 L_c of carriage travel; and at the preset's mu
1.25 at K 3, where the tip sticks ~65 % of the time) and on a flat plane where
the spring-block sticks most of the time (K = 10, the carriage covering 1.1 times the
stretch to breakaway): simulated steps and CPU seconds per run, the end reasons,
and the largest end-point difference between the two in L_c. Writes nothing.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import time

import numpy as np

from spine_mj import sim
from spine_mj.sim.ramp import cycle_breakaways, rows_to_reset
from spine_mj.surfaces import inclined_plane
from spine_mj.theory import agreement
from spine_mj.validate.ramp_pilot import pilot_rig
from spine_mj.validate.static_map import hold_force

#: (slope, azimuth) of the probe's planes [deg]: engaged planes of the static map.
PROBE_PLANES = ((0.0, 0.0), (15.0, 0.0), (30.0, 0.0), (45.0, 0.0), (52.5, 0.0), (30.0, 30.0), (30.0, 60.0))
#: Probe starts on the single peak (surface units).
PROBE_PEAK_STARTS = ((-3.0, -1.0), (-2.0, -2.0), (-3.0, 1.0), (-1.0, 1.5), (2.0, 0.5))


def _cases(res: int):
    for slope in (-15.0, 0.0, 10.0, 20.0, 25.0):
        rig = sim.Rig(inclined_plane(slope_deg=slope), tip=sim.TipParams(tip_radius_m=5e-4, mu_s=0.5))
        yield f"plane {slope:g} deg", rig, (-0.01, 0.0)
    for preset, mu in (("paper-single-peak", 1.23), ("paper-single-valley", 1.23)):
        rig, _ = pilot_rig(preset, None, mu, 0.1, res)
        for y0 in (-0.5, -1.0, -2.0, -3.0):
            yield f"{preset} y0={y0:g}", rig, (-3.0, y0)


def _probe_cases(res: int, ie: float):
    """(name, rig, start, probe) of the probe comparison."""
    for slope, az in PROBE_PLANES:
        rig = sim.Rig(inclined_plane(slope_deg=slope, azimuth_deg=az), tip=sim.TipParams(mu_s=0.5))
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
                "frechet_lc": agreement.path_frechet(
                    fast.position_m[:n_f, :2], plain.position_m[:n_p, :2], length_scale=sc.char_length_m
                ),
                "end": f"{plain.end_reason.value}/{fast.end_reason.value}",
                "steps_plain": n_p,
                "steps_fast": n_f,
                "wall_s": (t1 - t0, t2 - t1),
            }
        )
    return rows


#: The spring drive's cost grid: inertia numbers and stiffness numbers K = k l_s / F_p.
SPRING_IES = (1e-4, 1e-5, 1e-6)
SPRING_KS = (3.0, 30.0, 300.0, 3000.0)


def _spring_cases(ies, ks):
    """(surface, I_e, K, rig, drive, starts) of the spring cost grid."""
    from spine_mj import presets

    surface = presets.make_surface("paper-fractal", seed=1)
    # mu 0.5 over the K grid; the preset's mu 1.25 at K 3, where the tip sticks 65 % of the time
    for mu, kgrid in ((0.5, ks), (presets.calibrated_mu("paper-fractal"), ks[:1])):
        for ie in ies:
            for kf in kgrid:  # the engine's step resolves the spring's swing
                rig = sim.build_rig(surface, mu=mu, ie=ie, stiffness_number=kf)
                sc = rig.scales
                x0, x1, y0, y1 = (b / rig.length_scale_m for b in rig.bounds_m)
                starts = [(x0 + 0.05 * (x1 - x0), y0 + f * (y1 - y0)) for f in (0.3, 0.7)]
                v = sc.speed_for(ie)
                drive = sim.SpringDrive(
                    speed_m_s=v, stiffness_n_m=sc.stiffness_for(kf), duration_s=0.25 * sc.char_length_m / v
                )
                yield f"paper fractal, mu {mu:g}", ie, kf, rig, drive, starts
    rig = sim.Rig(
        inclined_plane(slope_deg=0.0, half_width=0.05, n=101),
        tip=sim.TipParams(tip_radius_m=5e-4, mu_s=0.5),
    )
    sc = rig.scales
    for ie in ies:
        v, k = sc.speed_for(ie), sc.stiffness_for(10.0)
        drive = sim.SpringDrive(speed_m_s=v, stiffness_n_m=k, duration_s=1.1 * 0.5 * sc.preload_n / (k * v))
        yield "flat plane", ie, 10.0, rig, drive, [(-0.04, 2.3e-4)]


def spring_rows(ies=SPRING_IES, ks=SPRING_KS) -> list[dict]:
    """Plain and fast-forwarded spring runs on the cost grid: steps and CPU seconds per run."""
    rows, warm = [], True
    for surface, ie, kf, rig, drive, starts in _spring_cases(ies, ks):
        if warm:  # compile the window kernel outside the timings
            rig.run_batch(drive, starts[:1], nthread=1)
            warm = False
        row = {"surface": surface, "ie": ie, "K": kf, "runs": len(starts)}
        ends = {}
        for label, ff in (("plain", False), ("fast", True)):
            c0 = time.process_time()
            res = rig.run_batch(dataclasses.replace(drive, fast_forward=ff), starts, nthread=1)
            row[f"cpu_s_{label}"] = (time.process_time() - c0) / len(starts)
            row[f"steps_{label}"] = float(np.mean([r.simulated_steps for r in res]))
            row[f"end_{label}"] = sorted({r.end_reason.value for r in res})
            ends[label] = res
        row["end_dx_lc"] = max(
            float(np.abs(f.position_m[-1] - p.position_m[-1]).max()) / rig.scales.char_length_m
            for p, f in zip(ends["plain"], ends["fast"])
        )
        rows.append(row)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ie", type=float, default=1e-2)
    ap.add_argument("--cycles", type=int, default=2)
    ap.add_argument("--res", type=int, default=61)
    ap.add_argument("--spring", action="store_true", help="only the spring drive's cost grid")
    args = ap.parse_args()
    if args.spring:
        for r in spring_rows():
            print(
                f"spring {r['surface']:13s} I_e {r['ie']:.0e} K {r['K']:6g}  "
                f"steps/run {r['steps_plain']:9.0f} / {r['steps_fast']:9.0f} = "
                f"{r['steps_plain'] / r['steps_fast']:4.1f}x  CPU s/run {r['cpu_s_plain']:6.2f} / "
                f"{r['cpu_s_fast']:6.2f}  end {','.join(r['end_plain'])}/{','.join(r['end_fast'])}  "
                f"end dx {r['end_dx_lc']:.1e} L_c  load {os.getloadavg()[0]:.1f}",
                flush=True,
            )
        return
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


def bench_fastforward(quick: bool) -> dict:
    """The static probe at I_e 1e-3 and 1e-2, the ramp at I_e 1e-2 (2 cycles) and the spring
    drive's cost grid (I_e 1e-4...1e-6, K 3...3000; quick: I_e 1e-4, 1e-5 and K 3, 30),
    plain and fast-forwarded (see bench_fastforward.py)."""
    out = {"probe": {str(ie): probe_rows(61, ie) for ie in (1e-3, 1e-2)}}
    if not quick:
        out["ramp"] = ramp_rows(61, 1e-2, 2)
    out["spring"] = spring_rows(SPRING_IES[:2], SPRING_KS[:2]) if quick else spring_rows()
    return out


def markdown(ff: dict | None) -> list[str]:
    """The fast-forward tables of the Performance page."""
    if not ff:
        return []
    out = [
        "",
        "**Stick-phase fast-forward** (`benchmarks/bench_fastforward.py`; plain = `fast_forward=False`). "
        "Static probe, the static map's probe on inclined planes (mu 0.5) and on the single peak "
        "(hfield 61, mu 1.23):",
        "",
        "| I_e | case | end | kappa_mj plain / fast-forwarded | rel. diff | rows | simulated steps |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for ie, rows in ff["probe"].items():
        for r in rows:
            out.append(
                f"| {float(ie):g} | {r['case']} | {r['end']} | "
                f"{r['kappa_plain']:.4f} / {r['kappa_fast']:.4f} | "
                f"{r['rel_diff']:+.1e} | {r['rows_plain']} / {r['rows_fast']} | "
                f"{r['steps_plain']} / {r['steps_fast']} |"
            )
    if ff.get("ramp"):
        rows = ff["ramp"]
        out.append(
            f"\nForce ramp, I_e 1e-2, 2 cycles, {len(rows)} cases (planes -15...25 deg, single peak and "
            f"valley from 4 starts each): breakaway forces within "
            f"{max(r['max_rel_diff'] for r in rows):.2%} of the plain ramp's, paths within Frechet "
            f"{max(r['frechet_lc'] for r in rows):.1e} L_c, steps to the second reset "
            f"{sum(r['steps_plain'] for r in rows)} plain against {sum(r['steps_fast'] for r in rows)}."
        )
    out += _spring_markdown(ff.get("spring"))
    out.append(f"\nLoad: {ff['load_before']}-{ff['load_after']}.")
    return out


def _spring_markdown(rows) -> list[str]:
    if not rows:
        return []
    out = [
        "",
        "Spring drive, cost per run against I_e and K = k l_s / F_p, plain / fast-forwarded: the "
        "paper fractal (seed 1, mu 0.5 and, at K 3, the preset's 1.25; 2 starts, 0.25 L_c of travel) "
        "and the spring-block on a "
        "flat plane (stuck until k V t = mu F_p, 91 % of the run). A spring run "
        "fast-forwards only where a preload is over 400 of its steps' increments k V dt "
        "(`rollout.SPRING_MIN_CLIMB_STEPS`); the end-point difference is in L_c:",
        "",
        "| surface | I_e | K | steps / run | ratio | CPU s / run | end | end-point diff. |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        out.append(
            f"| {r['surface']} | {r['ie']:g} | {r['K']:g} | {r['steps_plain']:.0f} / {r['steps_fast']:.0f} | "
            f"{r['steps_plain'] / r['steps_fast']:.2f} | {r['cpu_s_plain']:.3f} / {r['cpu_s_fast']:.3f} | "
            f"{', '.join(r['end_plain'])} / {', '.join(r['end_fast'])} | {r['end_dx_lc']:.1e} |"
        )
    return out


if __name__ == "__main__":
    main()
