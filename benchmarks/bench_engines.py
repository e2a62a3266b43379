"""Cost of the Bullet engine against MuJoCo's on the same runs (issue 33).

The same spring-drive runs (paper-single-peak, hfield 101, I_e = 1e-3, K = 30, three
starts, 1 L_c of carriage travel, no run ends early) and static probes on a 10 deg plane,
each engine on one thread (MuJoCo: ``Rig.run_batch`` with ``nthread=1``; Bullet steps in
Python). Reported: recorded rows per second, Bullet's own steps per second (``substeps``
per row), and the wall-time ratio Bullet / MuJoCo per compared run.
"""

from __future__ import annotations

import time

from spine_mj.surfaces import inclined_plane


def _cases():
    from spine_mj import presets

    peak = presets.make_surface("paper-single-peak")
    mu = presets.preset_mu(peak) or 0.5
    plane = inclined_plane(slope_deg=10.0)
    yield "spring, single peak", peak, mu, "spring", [(-3.0, y) for y in (-1.0, 0.0, 1.0)]
    yield "static probe, 10 deg plane", plane, 0.5, "static", [(0.0, 0.0)] * 3


def bench_engines(quick: bool) -> dict:
    from spine_mj import sim
    from spine_mj.choices import COMPARED_ENGINES

    rows = []
    for label, surf, mu, protocol, starts in _cases():
        row = {"case": label, "runs": len(starts)}
        for engine in COMPARED_ENGINES:
            rig = sim.build_rig(surf, engine=engine, mu=mu, ie=1e-3, hfield_resolution=101)
            sc = rig.scales
            kw = {"duration_s": sc.char_length_m / sc.speed_for(1e-3)} if protocol == "spring" else {}
            drive = sim.build_drive(sc, protocol, ie=1e-3 if protocol == "spring" else 1e-2, **kw)
            best = None
            for _ in range(1 if quick else 3):
                t0 = time.perf_counter()
                runs = rig.run_batch(drive, starts, nthread=1)
                wall = time.perf_counter() - t0
                best = wall if best is None else min(best, wall)
            recorded = sum(r.n for r in runs)
            row[f"{engine}_s_per_run"] = best / len(starts)
            row[f"{engine}_rows_per_s"] = recorded / best
            if engine == "bullet":
                from spine_mj.sim.bullet_settings import spring_substeps

                n = spring_substeps(rig.engine, drive, sc)
                row["bullet_substeps"] = n
                row["bullet_steps_per_s"] = recorded * n / best
        row["bullet_over_mujoco"] = row["bullet_s_per_run"] / row["mujoco_s_per_run"]
        rows.append(row)
    return {"rows": rows}


def markdown(res: dict | None) -> list[str]:
    if not res:
        return []
    lines = [
        "",
        "### Engines: Bullet against MuJoCo on the same runs (one thread each)",
        "",
        "| case | runs | MuJoCo s/run | Bullet s/run | Bullet / MuJoCo | MuJoCo rows/s | Bullet rows/s "
        "| Bullet substeps | Bullet steps/s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        lines.append(
            f"| {r['case']} | {r['runs']} | {r['mujoco_s_per_run']:.3g} | {r['bullet_s_per_run']:.3g} "
            f"| {r['bullet_over_mujoco']:.3g} | {r['mujoco_rows_per_s']:.3g} | {r['bullet_rows_per_s']:.3g} "
            f"| {r['bullet_substeps']} | {r['bullet_steps_per_s']:.3g} |"
        )
    return lines
