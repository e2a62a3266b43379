"""Cost of the stick-slip study (``spine-mj stickslip``): the quasistatic references per
slip, their pulses, the force-drop rule per recorded row, the statistics of one series,
and MuJoCo per slip on the ABBM track.

    python benchmarks/run_all.py --only stickslip
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time

import numpy as np
from bench_common import fmt, target_cell

#: Landscape points of the references' timing (an ABBM walk, dx 0.02).
POINTS = 2_000_000
#: Target: slips per CPU second of each reference (a study's 10^5 slips in a second).
REFERENCE_TARGET = 1e5


#: The ``abbm`` preset's engine cell timed: K 10 at the I_e of its study cell on seed 1
#: (``analysis/stickslip_engines.py --track abbm``: the carriage advances 0.12 median drops
#: in a half period), one run of :data:`ABBM_ENGINE_TRAVEL` units.
ABBM_ENGINE = {"K": 10.0, "ie": 7.3e-6}
ABBM_ENGINE_TRAVEL = 10.0

_ABBM_CHILD = r"""
import dataclasses, json, resource, sys, tempfile, time
from spine_mj import presets
from spine_mj.sim.build import build_rig
from spine_mj.validate.slip_catalog import TrackUnits, track_landscape
from spine_mj.validate.stickslip_outputs import _engine_run, stickslip_to
length = float(sys.argv[1])
K, ie, travel = float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
c0 = time.process_time()
surf = presets.make_surface("abbm", length=length, points=int(round(10 * length)) + 1)
make_s = time.process_time() - c0
c0 = time.process_time()
with tempfile.TemporaryDirectory() as tmp:
    out = stickslip_to(tmp, surf, mu=0.5, ie=ie, n_bootstrap=10)
refs_s = time.process_time() - c0
slips = sum(e["n_events"] for per_k in out.summary["sources"].values() for e in per_k.values())
x0 = 0.05 * length
keep = (surf.x >= x0 - 5) & (surf.x <= x0 + travel + 5)
part = dataclasses.replace(surf, heights=surf.heights[:, keep].copy(), x=surf.x[keep].copy())
del surf, out
rig = build_rig(part, engine="mujoco", mu=0.5, ie=ie, stiffness_number=K)
units = TrackUnits.of(rig.scales, ie)
land = track_landscape(part, 0.5, units.tip_radius, (x0, x0 + travel))
c0 = time.process_time()
_engine_run(rig, units, land, K, ie, x0, travel)
mj_s = time.process_time() - c0
print(json.dumps({"length": length, "make_cpu_s": make_s, "references_cpu_s": refs_s, "slips": slips,
                  "mujoco_cpu_s": mj_s, "mujoco_steps_per_unit": 1 / (units.speed * rig.engine.timestep_s),
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024}))
"""


def bench_abbm_preset(quick: bool) -> dict:
    """The ``abbm`` preset (``--quick``: its first tenth, 45 000 units) in a process of its
    own: CPU seconds to make it, to run both references and their statistics over it at its
    default K (``spine-mj stickslip abbm``), MuJoCo's per unit of travel at K 10, and the
    peak resident memory."""
    from spine_mj import presets

    length = presets.load_preset("abbm").params["length"] / (10 if quick else 1)
    args = [str(length), str(ABBM_ENGINE["K"]), str(ABBM_ENGINE["ie"]), str(ABBM_ENGINE_TRAVEL)]
    out = subprocess.run(
        [sys.executable, "-c", _ABBM_CHILD, *args], capture_output=True, text=True, check=True
    )
    res = json.loads(out.stdout.strip().splitlines()[-1])
    res["mujoco_cpu_s_per_unit"] = res["mujoco_cpu_s"] / ABBM_ENGINE_TRAVEL
    return res | {"K": ABBM_ENGINE["K"], "ie": ABBM_ENGINE["ie"]}


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
        "abbm": bench_abbm_preset(quick),
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
    if "abbm" in res:
        ab = res["abbm"]
        rows.append(
            f"| `abbm` preset, {ab['length']:g} units: made; both references and their statistics at "
            f"its K ({ab['slips']} slips) | {fmt(ab['make_cpu_s'])} + {fmt(ab['references_cpu_s'])} CPU s, "
            f"peak {ab['peak_rss_mb'] / 1024:.1f} GB | - | {load} |"
        )
        rows.append(
            f"| MuJoCo on the `abbm` preset, K {ab['K']:g}, I_e {ab['ie']:g}, a run of "
            f"{ABBM_ENGINE_TRAVEL:g} units and the spring's last 0.2 % of stretch "
            f"({ab['mujoco_steps_per_unit']:.3g} steps a unit) | "
            f"{fmt(ab['mujoco_cpu_s_per_unit'])} CPU s per unit of travel | - | {load} |"
        )
    return rows
