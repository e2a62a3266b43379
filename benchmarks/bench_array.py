"""Cost of a spine array against N single-spine runs of the same length (issue 27).

An array of N spines is one MuJoCo model stepped through the rollout lanes; the N single
spines are one ``Rig.run_batch`` of N starts. Both on one worker thread, same surface
(paper-random-concave, hfield 151), drive (I_e = 1e-3, K = 30) and starts (an aligned grid
at 1 L_c), over 2 L_c of carriage travel (no run ends early); pairs run in alternating
order, the median of the per-pair wall-time ratios array / singles reported. The target:
at most about 1 (an array costs at most about N single runs).
"""

from __future__ import annotations

import statistics
import time


def bench_array(quick: bool) -> dict:
    from spine_mj import presets, sim

    surf = presets.make_surface("paper-random-concave")
    tip = sim.TipParams(mu_s=presets.preset_mu(surf) or 0.5)
    sc, hfield = sim.Scales.with_hfield(surf, tip=tip, hfield_resolution=151)
    speed = sc.speed_for(1e-3)
    rig = sim.Rig(surf, tip=tip, engine=sim.default_engine(sc, speed_m_s=speed), sized=(sc, hfield))
    drive = sim.SpringDrive(speed_m_s=speed, duration_s=2 * sc.char_length_m / speed)
    repeats = 2 if quick else 5
    rows = []
    for side in (1, 2, 4) if quick else (1, 2, 4, 8):
        arr = sim.ArrayRig(rig, sim.Layout(rows=side, cols=side, spacing=1.0))
        starts = [tuple(p) for p in arr.starts((0.0, 0.0))]
        ratios, t_arr, t_one, steps = [], [], [], 0
        for i in range(repeats):
            order = ("array", "singles") if i % 2 == 0 else ("singles", "array")
            times = {}
            for what in order:
                t = time.perf_counter()
                if what == "array":
                    res = arr.run(drive, centre=(0.0, 0.0), nthread=1)
                    steps = res.simulated_steps
                else:
                    rig.run_batch(drive, starts, nthread=1)
                times[what] = time.perf_counter() - t
            ratios.append(times["array"] / times["singles"])
            t_arr.append(times["array"])
            t_one.append(times["singles"])
        rows.append(
            {
                "n_spines": side * side,
                "steps": steps,
                "array_s": round(statistics.median(t_arr), 4),
                "singles_s": round(statistics.median(t_one), 4),
                "ratio": round(statistics.median(ratios), 3),
            }
        )
    return {"rows": rows, "repeats": repeats, "target": "ratio <= ~1"}


def markdown(res: dict | None) -> list[str]:
    """The array section of the benchmark report."""
    if not res:
        return []
    out = [
        "",
        "Arrays: one model of N spines against N single-spine runs of the same length "
        f"(one thread, median of {res['repeats']} alternating pairs; target ratio <= ~1):",
        "",
        "| N | steps | array [s] | N singles [s] | array / singles |",
        "|---|---|---|---|---|",
    ]
    out += [
        f"| {r['n_spines']} | {r['steps']} | {r['array_s']} | {r['singles_s']} | {r['ratio']} |"
        for r in res["rows"]
    ]
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(bench_array(quick=False), indent=2))
