"""Does an engine stop a slip early on the abbm preset at K 10 because it loses more than
Coulomb friction? Reads the saved drop catalogs and flat-strip results only
(analysis/reports/stickslip/); prints the numbers of the README's section "Where
MuJoCo's slips stop, and the energy" (and those of the cells at a lowered contact damping)
and writes them to ``stickslip_energy.json``.

The drop catalogs carry no dissipated energy (``drop_rows`` writes NaN) and the references
no speed, so the energy is bounded from the engines' own peak speeds: a slip's kinetic
energy at its peak, ``m v^2 / 2`` with ``m = k (T / pi)^2`` (T the spring-block's half
period), is the most that an extra loss must remove to stop the tip before the inertial
reference does.

    python analysis/stickslip_energy.py
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import binom

from spine_mj.jsonio import write_json

REPORTS = Path(__file__).resolve().parent / "reports" / "stickslip"
CELLS = {
    "seed 1, default": ("abbm_k10_seed1",),
    "seed 1, dt / 2": ("abbm_k10_seed1_dt2a", "abbm_k10_seed1_dt2b"),
    "seed 8181, dt / 2": ("abbm_k10_seed8181_dt2",),
    "seed 1, Bullet": ("abbm_k10_seed1_bullet",),
    "seed 8181, dt / 2, damping 0.5": ("abbm_k10_seed8181_dt2_r05",),
    "seed 1 first half, dt / 2": ("abbm_k10_seed1_dt2a",),
    "seed 1 first half, dt / 2, damping 0.5": ("abbm_k10_seed1_dt2a_r05",),
}
FLAT = {
    "seed 1, default": ("mujoco", 0),
    "seed 1, dt / 2": ("mujoco", 1),
    "seed 8181, dt / 2": ("mujoco", 1),
    "seed 8181, dt / 2, damping 0.5": ("mujoco_r0.5", 1),
    "seed 1 first half, dt / 2": ("mujoco", 1),
    "seed 1 first half, dt / 2, damping 0.5": ("mujoco_r0.5", 1),
}
#: The flat-strip results by engine (and contact): the file's rows are the rule's step, dt / 2.
FLAT_FILES = {"mujoco": "abbm_flat", "bullet": "abbm_flat_bullet", "mujoco_r0.5": "abbm_flat_r0.5"}
MATCH_LC = 1.0


def _load(tags) -> pd.DataFrame:
    return pd.concat(
        [pd.read_parquet(REPORTS / f"stickslip_drops_{t}.parquet") for t in tags], ignore_index=True
    )


def _plan(tag: str) -> dict:
    d = json.loads((REPORTS / f"stickslip_engines_{tag}.json").read_text())
    return (d[0] if isinstance(d, list) else d)["plan"]


def _flat_excess() -> dict:
    """Sliding force minus mu W [F_p] on the flat strip, per (engine, row)."""
    out = {}
    for engine, name in FLAT_FILES.items():
        path = REPORTS / f"stickslip_engines_{name}.json"
        for i, r in enumerate(json.loads(path.read_text()) if path.exists() else []):
            out[(engine, i)] = r["sliding_fp"] - r["mu"]
    return out


def _nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from each of ``a`` to the nearest of ``b``."""
    b = np.sort(b)
    i = np.clip(np.searchsorted(b, a), 1, max(b.size - 1, 1))
    return np.minimum(np.abs(a - b[i - 1]), np.abs(a - b[np.minimum(i, b.size - 1)]))


def cell(label: str, tags, flat: dict) -> dict:
    d = _load(tags)
    plan = _plan(tags[0])
    engine = "bullet" if "bullet" in set(d.source) else "mujoco"
    ref = d[d.source == "inertial"]
    ratio = ref.force_drop_fp / ref.size_lc
    k = float(ratio.median())
    e = d[d.source == engine].copy()
    if e.empty:  # no drop above the floor: nothing ends anywhere
        return {"cell": label, "n_engine": 0, "n_inertial": len(ref)}
    # The carriage advances V D in a slip, so the spring's drop is k (S - V D): read L_c [units].
    lag = 1.0 - e.force_drop_fp / (k * e.size_lc)
    lc = float(np.median(plan["speed"] * e.duration_s / (e.size_lc * lag)))
    t, v = plan["half_period_s"], plan["speed"]
    speed_lc_s = e.peak_speed_v * v / lc
    kinetic = 0.5 * k * (t / math.pi) ** 2 * speed_lc_s**2
    coulomb = 0.5 * e.size_lc
    ends = {s: (g.start_x_lc + g.size_lc).to_numpy() for s, g in d.groupby("source")}
    e_end = (e.start_x_lc + e.size_lc).to_numpy()
    near_od = _nearest(e_end, ends["overdamped"]) < MATCH_LC
    near_in = _nearest(e_end, ends["inertial"]) < MATCH_LC
    grid = np.arange(e_end.min(), e_end.max(), 0.05)
    chance_od = float(np.mean(_nearest(grid, ends["overdamped"]) < MATCH_LC))
    chance_in = float(np.mean(_nearest(grid, ends["inertial"]) < MATCH_LC))
    out = {
        "cell": label,
        "n_engine": len(e),
        "n_inertial": len(ref),
        "inertial_k_fp_per_lc": k,
        "inertial_rows_at_k_1e-6": f"{int(((ratio / k - 1).abs() < 1e-6).sum())} of {len(ref)}",
        "lc_units_from_lag": lc,
        "kinetic_over_coulomb_median": float(np.median(kinetic / coulomb)),
        "kinetic_per_size_fp_median": float(np.median(kinetic / e.size_lc)),
        "kinetic_over_harmonic_median": float(np.median(kinetic / (k * e.size_lc**2 / 8))),
        "ends_at_overdamped_only": int(np.sum(near_od & ~near_in)),
        "ends_at_inertial_only": int(np.sum(near_in & ~near_od)),
        "ends_at_both": int(np.sum(near_in & near_od)),
        "chance_near_overdamped_end": chance_od,
        "chance_near_inertial_end": chance_in,
        # Binomial tail of the overdamped-only count, the two windows taken as independent.
        "overdamped_only_p": float(
            binom.sf(np.sum(near_od & ~near_in) - 1, len(e), chance_od * (1 - chance_in))
        ),
    }
    if label in flat:
        out["flat_sliding_excess_fp"] = flat[label]
        out["flat_loss_over_kinetic_median"] = float(np.median(flat[label] * e.size_lc / kinetic))
    return out


def main() -> None:
    excess = _flat_excess()
    flat = {label: excess[key] for label, key in FLAT.items() if key in excess}
    rows = [
        cell(label, tags, flat)
        for label, tags in CELLS.items()
        if all((REPORTS / f"stickslip_drops_{t}.parquet").exists() for t in tags)
    ]
    write_json(REPORTS / "stickslip_energy.json", rows)
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
