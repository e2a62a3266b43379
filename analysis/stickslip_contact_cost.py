"""What a lowered contact damping costs (issue 42 item 5): one run of an ``abbm`` K-cell
(``stickslip_engines.py --track abbm``, its plan and cut into runs as the cell was) rerun
at the rule's contact and at each ``--dampratio`` at the same contact stiffness
(:func:`stickslip_engines.at_dampratio`), with the penetration the cell's pieces do not
keep: its depth at rest (rows STUCK after the drive's start) and while the tip moves (the
other rows in contact), against the resting depth MuJoCo's contact predicts
(:func:`spine_mj.sim.step_rule.rest_depth_m`), with the share of moving rows in flight; the
resting force jitter (the 99th percentile of the elementary force drops), the held tip's
creep (mean x-speed over V in STUCK rows, and the share of the run's travel made while
STUCK), the run's drops above the plan's floor (start x, size; against the cell's
cached run of the same contact where one is saved: the same rig and crop, so the same
drops) and a trace of tip, carriage and force. Run from the repository root (~60 CPU s a contact at dt / 2)::

    python analysis/stickslip_contact_cost.py --tag abbm_k10_seed8181_dt2 --seed 8181 \\
        --run 1 --dampratio 1,0.5

Writes ``analysis/reports/stickslip/contact_cost_<tag>_run<i>.json`` and prints it.
``--flat 2:0.5,4:1``: instead, the flat strip's breakaway and sliding force
(:func:`stickslip_engines.flat_friction`; seed 1's rig at K 10, I_e 7.3e-6) at dt / 2 with
``solref = (n dt, r)`` for each ``n:r``: which of the time constant and the damping ratio
moves the sliding force (``contact_cost_flat.json``; ~30 CPU s each); ``n:r:i`` also sets
MuJoCo's ``impratio`` to i (the friction's impedance over the normal's; the rule's is 1),
``--flat-out`` names the file.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import pickle
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from stickslip_engines import MU, _positive, _variant, abbm_prefix, crop, flat_friction

from spine_mj.jsonio import write_json
from spine_mj.sim.step_rule import rest_depth_m
from spine_mj.theory.force_drops import jitter_scale
from spine_mj.theory.motion import STUCK
from spine_mj.validate.slip_catalog import TrackUnits, engine_drop_rows, track_landscape
from spine_mj.validate.stickslip_outputs import _engine_run

OUT = Path(__file__).resolve().parent / "reports" / "stickslip"


def _quantiles(depth: np.ndarray, scale: float) -> dict:
    """Median, 99th percentile and maximum of ``depth`` over ``scale`` (NaN when empty)."""
    if depth.size == 0:
        return {"n": 0, "median": math.nan, "p99": math.nan, "max": math.nan}
    q = np.percentile(depth, [50, 99]) / scale
    top = float(depth.max() / scale)
    return {"n": int(depth.size), "median": float(q[0]), "p99": float(q[1]), "max": top}


def run_bounds(plan: dict, start: float, segment: float) -> list[tuple[float, float]]:
    """The cell's runs ``(a, b)``, cut as :func:`stickslip_engines.one` cuts them."""
    count = max(1, math.ceil(plan["travel"] / segment - 1e-9))
    bounds = start + plan["travel"] * np.arange(count + 1) / count
    return [(float(a), float(b)) for a, b in itertools.pairwise(bounds)]


def measure(seed: int, plan: dict, a: float, b: float, segment: float, end: float, dampratio) -> dict:
    """One run over [a, b] of the cell's crop (``end``: the cell's last x) at ``dampratio``
    (None: the rule's contact): the penetration, jitter, creep and drops."""
    whole = abbm_prefix(seed, end)
    surf = crop(whole, a - segment / 4, b + segment / 4)
    k, ie, floor = plan["K"], plan["ie"], plan["floor_fp"]
    rig = _variant("mujoco", "dt2", ie, k, surf, dampratio)
    units = TrackUnits.of(rig.scales, ie)
    land = track_landscape(surf, MU, units.tip_radius, (a, b))
    c0 = time.process_time()
    res = _engine_run(rig, units, land, k, ie, a, b - a)
    cpu = time.process_time() - c0
    s = res.drive_start_index
    stuck = np.asarray(res.motion)[s:] == STUCK
    touch = np.asarray(res.contact)[s:]
    pen = np.asarray(res.penetration_m)[s:]
    rest = rest_depth_m(rig.engine, rig.scales)
    vx = res.velocity_m_s[s:, 0] / (units.speed * units.length_scale_m)
    dx = np.diff(res.position_m[s:, 0], prepend=res.position_m[s, 0])
    drops = engine_drop_rows(res, units, "mujoco", k, floor)
    lc = units.char_length
    return {
        "dampratio": dampratio,
        "solref": list(rig.engine.solref),
        "timestep_s": rig.engine.timestep_s,
        "cpu_s": cpu,
        "end": res.end_reason.value,
        "steps": int(len(pen)),
        "lc_units": lc,
        "rest_depth_predicted_m": rest,
        "tip_radius_m": rig.scales.tip_radius_m,
        "depth_at_rest_over_predicted": _quantiles(pen[stuck & touch], rest),
        "depth_moving_over_predicted": _quantiles(pen[~stuck & touch], rest),
        "moving_rows_in_flight": float(np.mean(~touch[~stuck])) if (~stuck).any() else math.nan,
        "stuck_rows_in_flight": float(np.mean(~touch[stuck])) if stuck.any() else math.nan,
        "jitter_fp": jitter_scale(res.drive_force_n[s:] / units.preload_n),
        "creep_speed_v": float(np.mean(vx[stuck])) if stuck.any() else math.nan,
        "creep_share_of_travel": float(dx[stuck].sum() / max(dx.sum(), 1e-300)),
        "drops": [
            {"start_x": float(x * lc), "size_lc": float(z), "force_drop_fp": float(f)}
            for x, z, f in zip(drops["start_x_lc"], drops["size_lc"], drops["force_drop_fp"])
        ],
        "trace": _trace(res, units, s),
    }


def _trace(res, units: TrackUnits, start: int, points: int = 600) -> dict:
    """The run's tip x and carriage x [units], drive force [F_p] and whether STUCK, at
    ``points`` times from the drive's start (where the tip slid, where it stuck)."""
    idx = np.linspace(start, len(res.time_s) - 1, points).astype(int)
    scale = units.length_scale_m
    return {
        "x": np.round(res.position_m[idx, 0] / scale, 3).tolist(),
        "carriage_x": np.round(np.asarray(res.carriage_x_m)[idx] / scale, 3).tolist(),
        "force_fp": np.round(res.drive_force_n[idx] / units.preload_n, 7).tolist(),
        "stuck": (np.asarray(res.motion)[idx] == STUCK).astype(int).tolist(),
    }


def cached_drops(tag: str, k: float, run: int, lc: float) -> list | None:
    """The cell's cached run ``run``'s engine drops (start x, size), None if not saved."""
    path = OUT / f"segments_{tag}_K{k:g}" / f"segment_{run:04d}.pkl"
    if not path.exists():
        return None
    piece = pickle.loads(path.read_bytes())
    ((_, (eng, _)),) = piece["drops"].items()
    rows = zip(eng["start_x_lc"], eng["size_lc"])
    return [{"start_x": float(x * lc), "size_lc": float(z)} for x, z in rows]


def flat_settings(text: str) -> list[tuple[float, float, float | None]]:
    """``--flat``'s ``n:r[:i],...``: each contact's ``(n, r, impratio)`` (None: the rule's
    impratio), every number positive; else argparse's error line naming ``--flat`` (exit 2)."""
    rows = []
    for item in text.split(","):
        parts = item.split(":")
        if len(parts) not in (2, 3):
            raise argparse.ArgumentTypeError(f"--flat expects n:r or n:r:i, comma-separated, got {item!r}")
        n, r, *i = (_positive("--flat")(part) for part in parts)
        rows.append((n, r, i[0] if i else None))
    return rows


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tag", help="the cell's tag (its plan: stickslip_plan_<tag>_K<K>.json)")
    p.add_argument("--K", type=float, default=10.0)
    p.add_argument("--seed", type=int, help="the cell's seed")
    p.add_argument("--start", type=float, default=22500.0, help="the cell's first x")
    p.add_argument("--segment", type=float, default=44.0, help="the cell's --segment")
    p.add_argument("--run", type=int, default=1, help="which of the cell's runs (0-based)")
    p.add_argument("--dampratio", default="1,0.5", help="1: the rule's contact; others at its stiffness")
    p.add_argument("--cached-tags", default="", help="cells whose cached runs to compare, ratio=tag,...")
    p.add_argument(
        "--flat",
        type=flat_settings,
        default=None,
        help="only the flat strip at dt / 2, solref (n dt, r) and impratio i: n:r[:i],...",
    )
    p.add_argument("--flat-out", default="contact_cost_flat", help="--flat: the json's name (no suffix)")
    a = p.parse_args(argv)
    if a.flat:
        rows = [flat_friction(1, 10.0, 7.3e-6, 0.5, solref_steps=(n, r), impratio=i) for n, r, i in a.flat]
        write_json(OUT / f"{a.flat_out}.json", rows)
        print(json.dumps(rows, indent=1))
        return
    if a.tag is None or a.seed is None:
        p.error("--tag and --seed are required (or --flat)")
    plan = json.loads((OUT / f"stickslip_plan_{a.tag}_K{a.K:g}.json").read_text())
    bounds = run_bounds(plan, a.start, a.segment)
    x0, x1 = bounds[a.run]
    end = a.start + plan["travel"] + a.segment
    cached = dict(item.split("=") for item in a.cached_tags.split(",") if item)
    rows = []
    for text in a.dampratio.split(","):
        r = float(text)
        row = measure(a.seed, plan, x0, x1, a.segment, end, None if r == 1.0 else r)
        if text in cached:
            saved = cached_drops(cached[text], a.K, a.run, row["lc_units"])
            row["cached"] = {"tag": cached[text], "drops": saved}
        rows.append(row)
    out = {"tag": a.tag, "seed": a.seed, "run": a.run, "x": [x0, x1], "plan": plan, "rows": rows}
    write_json(OUT / f"contact_cost_{a.tag}_run{a.run}.json", out)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
