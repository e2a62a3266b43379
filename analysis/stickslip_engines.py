"""MuJoCo (and Bullet) slips on the ABBM track against the quasistatic references (issue 42).

For each engine, I_e and variant (``base``; ``dt2``: half the engine's step; ``hfield2``:
the hfield refined twice), one spring drive per K over the ``abbm`` preset (all but a
twentieth at each end), its slips against the overdamped and inertial references' slips on
the same stretch that the engine's detector would see (peak speed >= 5 V): the
Kolmogorov-Smirnov distance and p-value of sizes and force drops; and the creep of the held
tip, MuJoCo's soft friction: the tip's mean x-speed over V in the rows it is STUCK, and the
share of its travel made while stuck. The order of the distance with I_e is the slope of
``ln D`` against ``ln I_e``.

Run: ``nice -n 19 .venv/bin/python analysis/stickslip_engines.py [--ie 1e-4,1e-5]
[--engines mujoco,bullet] [--variants base,dt2,hfield2] [--travel 150]
[--out analysis/reports/stickslip]``;
writes ``stickslip_engines.json`` and prints one line per run.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from spine_mj import presets
from spine_mj.jsonio import write_json
from spine_mj.sim.build import build_rig
from spine_mj.theory.motion import SLIP_SPEED_FACTOR, STUCK
from spine_mj.validate.avalanche_stats import two_sample
from spine_mj.validate.slip_catalog import TrackUnits, engine_rows, reference_rows, track_landscape
from spine_mj.validate.stickslip_outputs import EDGE_SHARE, _engine_run

MU = 0.5


def _variant(engine: str, variant: str, ie: float, k: float, surf):
    rig = build_rig(surf, engine=engine, mu=MU, ie=ie, stiffness_number=k)
    if variant == "base":
        return rig
    if variant == "dt2":
        return build_rig(
            surf, engine=engine, mu=MU, ie=ie, stiffness_number=k, timestep_s=rig.engine.timestep_s / 2
        )
    if variant == "hfield2":
        return build_rig(surf, engine=engine, mu=MU, ie=ie, stiffness_number=k, hfield_refinement=2)
    raise SystemExit(f"unknown variant {variant}")


def one(engine: str, variant: str, ie: float, k: float, travel: float | None = None) -> dict:
    surf = presets.make_surface("abbm")
    xmin, xmax, _, _ = surf.bounds
    x0, length = xmin + EDGE_SHARE * (xmax - xmin), (1 - 2 * EDGE_SHARE) * (xmax - xmin)
    length = length if travel is None else travel
    rig = _variant(engine, variant, ie, k, surf)
    units = TrackUnits.of(rig.scales, ie)
    land = track_landscape(surf, MU, units.tip_radius, (x0, x0 + length))
    refs = reference_rows(land, units, k)
    c0 = time.process_time()
    result = _engine_run(rig, units, land, k, ie, x0, length)
    cpu = time.process_time() - c0
    eng = engine_rows(result, units, engine, k)
    row = {
        "engine": engine,
        "variant": variant,
        "ie": ie,
        "K": k,
        "cpu_s": cpu,
        "end": result.end_reason.value,
    }
    row["n"] = {engine: len(eng["size_lc"])} | {s: int(np.size(r["size_lc"])) for s, r in refs.items()}
    for source, r in refs.items():
        seen = np.asarray(r["peak_speed_v"]) >= SLIP_SPEED_FACTOR
        row["n"][f"{source}_seen"] = int(seen.sum())
        for col in ("size_lc", "force_drop_fp"):
            if len(eng[col]) >= 2 and seen.sum() >= 2:
                row[f"{col}_vs_{source}"] = two_sample(eng[col], np.asarray(r[col])[seen])
        row[f"mean_size_{source}"] = (
            float(np.mean(np.asarray(r["size_lc"])[seen])) if seen.any() else math.nan
        )
    row[f"mean_size_{engine}"] = float(np.mean(eng["size_lc"])) if len(eng["size_lc"]) else math.nan
    start = result.drive_start_index
    stuck = np.asarray(result.motion)[start:] == STUCK
    vx = result.velocity_m_s[start:, 0] / (units.speed * units.length_scale_m)
    dx = np.diff(result.position_m[start:, 0], prepend=result.position_m[start, 0])
    row["creep_speed_v"] = float(np.mean(vx[stuck])) if stuck.any() else math.nan
    row["creep_share_of_travel"] = float(dx[stuck].sum() / max(dx.sum(), 1e-300))
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ie", default="1e-4,1e-5")
    ap.add_argument("--K", default="0.5")
    ap.add_argument("--engines", default="mujoco")
    ap.add_argument("--variants", default="base")
    ap.add_argument("--travel", type=float, default=None, help="surface units (default: the track)")
    ap.add_argument("--out", default="analysis/reports/stickslip")
    a = ap.parse_args(argv)
    rows = []
    for engine in a.engines.split(","):
        for variant in a.variants.split(","):
            for ie in (float(v) for v in a.ie.split(",")):
                for k in (float(v) for v in a.K.split(",")):
                    row = one(engine, variant, ie, k, a.travel)
                    rows.append(row)
                    d = row.get("size_lc_vs_inertial", {})
                    print(
                        f"{engine} {variant} I_e {ie:g} K {k:g}: {row['n']} sizes vs inertial "
                        f"D {d.get('ks', math.nan):.3f} p {d.get('ks_p', math.nan):.3g}; "
                        f"creep {row['creep_speed_v']:.3g} V, "
                        f"{row['creep_share_of_travel']:.3g} of travel; {row['cpu_s']:.0f} CPU s",
                        flush=True,
                    )
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(
        out / f"stickslip_engines_{a.engines.replace(',', '_')}_{a.variants.replace(',', '_')}.json", rows
    )


if __name__ == "__main__":
    main()
