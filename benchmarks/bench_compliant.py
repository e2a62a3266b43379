"""The compliant-drive reference's cost (issue 41, item 7): its compiled loop against the
plain numpy loop, and the P600 sandpaper comparison it made slow.

* ``loop``: path points per CPU second of :func:`spine_mj.theory.compliant.compliant_streamlines`
  compiled (``backend="numba"``) and numpy (``backend="numpy"``) on the same soft-spring
  starts of a ball on a corrugation's facets (a jump per wave), and whether the two gave
  the same points (bit for bit on facets).
* ``p600``: the sweep's ``compare`` analysis on the P600 sandpaper as the issue measured it
  (spring drive at I_e 1e-4, default K, mu 0.5, starts at relative x 0.25, y 0.2-0.8; 12
  starts, 2 with ``--quick``), its CPU seconds from the store's per-run ``cpu_s``. One start creeps along a
  crease of the grit's facets in ~1.8e4 stick-slip cycles of dl / 1024 (the compliant
  reference has no crease state; the rigid one follows a crease on two contacts).

    python benchmarks/bench_compliant.py [--quick]
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_common import fmt

#: The issue's P600 comparison, before the compiled loop: 435 s (wall, hfield x 1, 12 starts).
P600_BEFORE_S = 435.0


def _cpu(fn):
    t = time.process_time()
    out = fn()
    return out, time.process_time() - t


def loop_rates(quick: bool) -> dict:
    """Points per CPU second of the compiled and numpy loops on the same soft-spring starts."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface, corrugation
    from spine_mj.theory.compliant import compliant_streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    grid = corrugation(slope_amplitude=0.3, n_waves=4, points_per_wave=24)
    contact = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.04)
    n = 4 if quick else 16
    starts = np.c_[np.full(n, 0.3), np.linspace(-0.3, 0.3, n)]
    p = StreamlineParams(mu=0.5, dl=0.005)
    c = 0.1 / 0.190

    def run(backend):
        return compliant_streamlines(contact, starts, p, stiffness=c, backend=backend)

    run("numba")  # compile or load the cache
    fast, fast_s = min((_cpu(lambda: run("numba")) for _ in range(3)), key=lambda r: r[1])
    slow, slow_s = _cpu(lambda: run("numpy"))
    keys = ("x", "y", "force")
    same = all(np.array_equal(getattr(fast, k), getattr(slow, k), equal_nan=True) for k in keys)
    points = int(fast.x.size)
    return {
        "starts": n,
        "points": points,
        "jumps": len(fast.folds),
        "numba_points_per_cpu_s": points / max(fast_s, 1e-9),
        "numpy_points_per_cpu_s": points / max(slow_s, 1e-9),
        "same_points": bool(same),
    }


def p600_compare(quick: bool) -> dict:
    """The P600 comparison as a sweep (quasistatic, mujoco, compare; one worker) in a
    temporary folder: each analysis's CPU seconds from the store."""
    from spine_mj import sweep

    n = 2 if quick else 12
    doc = {
        "sweep": {"name": "p600-compare", "seed": 11, "analyses": ["quasistatic", "engine", "compare"]},
        "surfaces": [{"preset": "sandpaper-P600"}],
        "starts": {"frame": "relative", "x": [0.25], "y": {"linspace": [0.2, 0.8], "num": n}},
        "drive": {"protocol": "spring", "ie": 1e-4},
        "grid": {"mu": 0.5},
    }
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        sweep.run_sweep(sweep.parse_config(doc), Path(tmp) / "store", workers=1)
        wall = time.perf_counter() - t0
        df = sweep.load_runs(Path(tmp) / "store", columns=["analysis", "cpu_s"])
    cpu = df.groupby("analysis")["cpu_s"].sum()
    return {
        "starts": n,
        "sweep_wall_s": round(wall, 1),
        "compare_cpu_s": round(float(cpu.get("compare", np.nan)), 1),
        "mujoco_cpu_s": round(float(cpu.get("engine", np.nan)), 1),
        "quasistatic_cpu_s": round(float(cpu.get("quasistatic", np.nan)), 1),
    }


def bench_compliant(quick: bool) -> dict:
    return {"loop": loop_rates(quick), "p600": p600_compare(quick)}


def markdown(res: dict | None) -> list[str]:
    """The compliant reference's rows of the Performance table."""
    if not res:
        return []
    ld = f"{res['load_before']}-{res['load_after']}"
    lo, p6 = res["loop"], res["p600"]
    same = "the same points, bit for bit" if lo["same_points"] else "**points differ**"
    return [
        f"| compliant reference, compiled loop: ball on a corrugation's facets, soft spring, "
        f"{lo['starts']} starts, {lo['jumps']} jumps | {fmt(lo['numba_points_per_cpu_s'])} points / CPU-s "
        f"(numpy loop {fmt(lo['numpy_points_per_cpu_s'])}: "
        f"{lo['numba_points_per_cpu_s'] / lo['numpy_points_per_cpu_s']:.0f}x; {same}) | | {ld} |",
        f"| P600 sandpaper `compare` ({p6['starts']} starts, spring I_e 1e-4, default K, mu 0.5, "
        f"hfield x 1; the issue's 12 starts took {P600_BEFORE_S:.0f} s before) | "
        f"{p6['compare_cpu_s']:.0f} CPU-s (MuJoCo {p6['mujoco_cpu_s']:.0f}, quasistatic "
        f"{p6['quasistatic_cpu_s']:.0f}) | | {ld} |",
    ]


if __name__ == "__main__":
    import json

    print(json.dumps(bench_compliant(quick="--quick" in sys.argv[1:]), indent=1))
