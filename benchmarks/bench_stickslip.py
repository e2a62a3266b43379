"""Cost of the stick-slip study (``spine-mj stickslip``): the quasistatic references per
slip, their pulses, the force-drop rule per recorded row, the statistics of one series,
and MuJoCo per slip on the ABBM track.

    python benchmarks/run_all.py --only stickslip
"""

from __future__ import annotations

import tempfile
import time

import numpy as np
from bench_common import fmt, target_cell

#: Landscape points of the references' timing (an ABBM walk, dx 0.02).
POINTS = 2_000_000
#: Target: slips per CPU second of each reference (a study's 10^5 slips in a second).
REFERENCE_TARGET = 1e5


def bench_stickslip(quick: bool) -> dict:
    """References' slips per CPU second, the statistics' CPU seconds per series, MuJoCo's CPU
    seconds per slip."""
    from spine_mj import presets, surfaces
    from spine_mj.theory.avalanches import Landscape, inertial_slips, overdamped_slips, pulse_shapes
    from spine_mj.theory.force_drops import drop_bounds
    from spine_mj.validate.avalanche_stats import summarize_sizes
    from spine_mj.validate.stickslip_outputs import stickslip_to

    n = POINTS // 4 if quick else POINTS
    s = surfaces.abbm_slope_walk(n, 0.02, 1e-6, 1e4, np.random.default_rng(0))
    land = Landscape.from_profile(0.02 * np.arange(n), s, np.cumsum(s) * 0.02, 0.5)
    overdamped_slips(land, 1e-3)  # compiled once
    refs = {}
    for name, fn in (("overdamped", overdamped_slips), ("inertial", inertial_slips)):
        c0 = time.process_time()
        slips = fn(land, 6e-4)
        cpu = time.process_time() - c0
        refs[name] = {
            "slips": int(slips.size.size),
            "cpu_s": cpu,
            "slips_per_cpu_s": slips.size.size / max(cpu, 1e-9),
        }
    slips = overdamped_slips(land, 6e-4)
    c0 = time.process_time()
    pulse_shapes(land, 6e-4, slips, inertial=False)
    pulse_cpu = time.process_time() - c0
    force = np.cumsum(np.random.default_rng(1).normal(size=n))  # a recorded force, n rows
    drop_bounds(force[:100], 1.0)  # compiled once
    c0 = time.process_time()
    drop_bounds(force, 3.0)
    drop_cpu = time.process_time() - c0
    sizes = slips.size
    c0 = time.process_time()
    summarize_sizes(sizes, n_bootstrap=100)
    stats_cpu = time.process_time() - c0
    surf = presets.make_surface("abbm-short")
    c0 = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        out = stickslip_to(
            tmp, surf, mu=0.5, stiffness_numbers=[0.5], ie=1e-3, engine="mujoco", travel=100.0, n_bootstrap=10
        )
    mj_cpu = time.process_time() - c0
    mj_slips = out.summary["sources"]["mujoco"]["0.5"]["n_events"]
    return {
        "points": n,
        "references": refs,
        "stats": {"events": int(sizes.size), "cpu_s": stats_cpu},
        "pulses": {"slips": int(sizes.size), "cpu_s": pulse_cpu},
        "drops": {"rows": n, "cpu_s": drop_cpu},
        "mujoco": {"travel": 100.0, "ie": 1e-3, "K": 0.5, "slips": mj_slips, "cpu_s": mj_cpu},
    }


def markdown(res: dict | None) -> list[str]:
    """The stick-slip rows of the Performance page."""
    if not res:
        return []
    load = f"{res['load_before']}-{res['load_after']}"
    rows = []
    for name, r in res["references"].items():
        rows.append(
            f"| {name} reference, {res['points']:.0e} points (ABBM walk) | "
            f"{fmt(r['slips_per_cpu_s'])} slips per CPU s ({r['slips']} slips) | "
            f"{target_cell(r['slips_per_cpu_s'], '>=', REFERENCE_TARGET)} | {load} |"
        )
    st, mj = res["stats"], res["mujoco"]
    if "pulses" in res:
        pu, dr = res["pulses"], res["drops"]
        rows.append(
            f"| overdamped reference's pulses ({pu['slips']} slips) | {fmt(pu['cpu_s'])} CPU s | - | {load} |"
        )
        rows.append(
            f"| force-drop rule (`theory.force_drops`), {dr['rows']:.0e} recorded rows | "
            f"{fmt(dr['cpu_s'])} CPU s | - | {load} |"
        )
    rows.append(
        f"| slip statistics of one series (truncated fit by KS, 100 bootstraps, likelihood ratios) | "
        f"{fmt(st['cpu_s'])} CPU s for {st['events']} slips | - | {load} |"
    )
    rows.append(
        f"| `stickslip abbm-short --engine mujoco`, K {mj['K']:g}, I_e {mj['ie']:g}, "
        f"{mj['travel']:g} units | "
        f"{fmt(mj['cpu_s'])} CPU s, {mj['slips']} MuJoCo slips | - | {load} |"
    )
    return rows
