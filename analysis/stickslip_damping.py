"""MuJoCo's K 10 cells on the ``abbm`` preset at the rule's contact and at a lowered contact
damping (issue 42 item 5), from the saved cells only (``stickslip_engines.py --track abbm``
JSONs and drop catalogs under analysis/reports/stickslip/; nothing rerun).

Per cell: the drop counts, median sizes, and MuJoCo's sizes and force drops against each
reference (KS and AD, from the cell's JSON); the count ratio MuJoCo / inertial and the
median sizes with 95 % intervals by resampling the cell's runs; per run the counts
(drops starting in the run's stretch), and MuJoCo's count against the inertial
reference's and against the other contact's on the same runs, by the Wilcoxon signed-rank
test (ties dropped). Pairs are cells with the same seed and plan.

    python analysis/stickslip_damping.py

Writes ``analysis/reports/stickslip/damping_cells.json`` and prints it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import wilcoxon

from spine_mj.jsonio import write_json
from spine_mj.validate.avalanche_stats import two_sample

REPORTS = Path(__file__).resolve().parent / "reports" / "stickslip"
#: (label, tags pooled, the contact's damping ratio); cells of one seed are paired run by run.
CELLS = (
    ("seed 8181, dt / 2, rule's contact", ("abbm_k10_seed8181_dt2",), 1.0),
    ("seed 8181, dt / 2, damping 0.5", ("abbm_k10_seed8181_dt2_r05",), 0.5),
    ("seed 1 first half, dt / 2, rule's contact", ("abbm_k10_seed1_dt2a",), 1.0),
    ("seed 1 first half, dt / 2, damping 0.5", ("abbm_k10_seed1_dt2a_r05",), 0.5),
)
SOURCES = ("mujoco", "inertial", "inertial_facets", "overdamped", "overdamped_facets")
N_BOOT = 2000


def _rows(tag: str) -> list[dict]:
    return json.loads((REPORTS / f"stickslip_engines_{tag}.json").read_text())


def _lc(row: dict) -> float:
    """Surface units per L_c of the cell's rig (its crop at the cell's start)."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from stickslip_engines import MU, abbm_prefix, crop

    from spine_mj.sim.build import build_rig
    from spine_mj.validate.slip_catalog import TrackUnits

    x0 = row["start"]
    surf = crop(abbm_prefix(row["seed"], x0 + 60), x0 - 10, x0 + 50)
    rig = build_rig(surf, engine="mujoco", mu=MU, ie=row["ie"], stiffness_number=row["K"])
    return TrackUnits.of(rig.scales, row["ie"]).char_length


def run_index(cat: pd.DataFrame, row: dict, lc: float) -> np.ndarray:
    """The run of each drop: the one whose stretch holds its start."""
    edges = row["start"] + row["segment_length"] * np.arange(row["segments"] + 1)
    x = cat["start_x_lc"].to_numpy() * lc
    return np.clip(np.searchsorted(edges, x, side="right") - 1, 0, row["segments"] - 1)


def per_run_counts(cat: pd.DataFrame, row: dict, lc: float) -> pd.DataFrame:
    """Drops per run (rows) and source (columns)."""
    counts = pd.crosstab(run_index(cat, row, lc), cat["source"]).reindex(range(row["segments"]), fill_value=0)
    return counts.reindex(columns=list(SOURCES), fill_value=0)


def _boot(counts: pd.DataFrame, sizes: dict, rng) -> dict:
    """95 % intervals over the runs resampled: count ratio MuJoCo / inertial, median sizes."""
    n = len(counts)
    ratios, med_m, med_i = [], [], []
    for _ in range(N_BOOT):
        pick = rng.integers(0, n, n)
        c = counts.iloc[pick].sum()
        ratios.append(c["mujoco"] / max(c["inertial"], 1))
        m = np.concatenate([sizes["mujoco"][i] for i in pick])
        r = np.concatenate([sizes["inertial"][i] for i in pick])
        med_m.append(np.median(m) if m.size else math.nan)
        med_i.append(np.median(r) if r.size else math.nan)
    return {
        "count_ratio_95": _interval(ratios),
        "median_size_mujoco_95": _interval(med_m),
        "median_size_inertial_95": _interval(med_i),
    }


def _interval(values) -> list:
    """The 2.5 and 97.5 percentiles of the finite ``values`` (NaN if none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return [float(x) for x in np.percentile(v, [2.5, 97.5])] if v.size else [math.nan, math.nan]


def _paired(a: np.ndarray, b: np.ndarray) -> dict:
    """Per-run counts ``a`` against ``b``: runs with fewer, more, equal; Wilcoxon p."""
    d = a - b
    p = float(wilcoxon(a, b).pvalue) if np.any(d != 0) else 1.0
    return {"fewer": int((d < 0).sum()), "more": int((d > 0).sum()), "equal": int((d == 0).sum()), "p": p}


def cell(label: str, tags, dampratio: float, rng) -> dict | None:
    """One cell's summary (None if its files are not saved)."""
    if not all((REPORTS / f"stickslip_engines_{t}.json").exists() for t in tags):
        return None
    rows = [r for t in tags for r in _rows(t)]
    cats = [pd.read_parquet(REPORTS / f"stickslip_drops_{t}.parquet") for t in tags]
    lc = _lc(rows[0])
    counts = pd.concat([per_run_counts(c, r, lc) for c, r in zip(cats, rows)], ignore_index=True)
    cat = pd.concat(cats, ignore_index=True)
    floor = f"{rows[0]['plan']['floor_fp']:g}"
    sizes = {}
    for source in ("mujoco", "inertial"):
        sizes[source] = []
        for c, r in zip(cats, rows):
            g = c[c.source == source]
            idx = run_index(g, r, lc)
            sizes[source] += [g["size_lc"].to_numpy()[idx == i] for i in range(r["segments"])]
    out = {
        "cell": label,
        "tags": list(tags),
        "dampratio": dampratio,
        "solref": [s for r in rows for s in r.get("solref", [])],
        "seed": rows[0]["seed"],
        "start": rows[0]["start"],
        "runs": int(len(counts)),
        "segment_length": rows[0]["segment_length"],
        "cpu_s": float(sum(r["cpu_s"] for r in rows)),
        "ends": sorted({e for r in rows for e in r["end"]}),
        "lc_units": lc,
        "n": {s: int(counts[s].sum()) for s in SOURCES},
        "median_size_lc": {s: float(cat.loc[cat.source == s, "size_lc"].median()) for s in SOURCES},
        "tests": {},
        "jitter_fp": max(r["jitter_fp"] for r in rows),
        "creep_speed_v": float(np.mean([r["creep_speed_v"] for r in rows])),
        "creep_share_of_travel": float(np.mean([r["creep_share_of_travel"] for r in rows])),
        "per_run": {s: counts[s].tolist() for s in SOURCES},
        "mujoco_vs_inertial_per_run": _paired(counts["mujoco"].to_numpy(), counts["inertial"].to_numpy()),
    }
    if len(rows) == 1:
        out["tests"] = {k: v for k, v in rows[0]["drops"][floor].items() if "_vs_" in k}
    else:
        for source in SOURCES[1:]:
            for col in ("size_lc", "force_drop_fp"):
                e, r = (cat.loc[cat.source == s, col].to_numpy() for s in ("mujoco", source))
                out["tests"][f"{col}_vs_{source}"] = two_sample(e, r)
    out |= _boot(counts, sizes, rng)
    return out


def _sizes(c: dict, runs: int, source: str = "mujoco") -> np.ndarray:
    """A source's drop sizes in cell ``c``'s first ``runs`` runs."""
    row = {"start": c["start"], "segment_length": c["segment_length"], "segments": c["runs"]}
    cat = pd.read_parquet(REPORTS / f"stickslip_drops_{c['tags'][0]}.parquet")
    cat = cat[cat.source == source]
    return cat["size_lc"].to_numpy()[run_index(cat, row, c["lc_units"]) < runs]


def pair(low: dict, rule: dict) -> dict:
    """Two contacts' cells on the same runs (the first ``n`` of both, n the fewer): MuJoCo's
    per-run counts and sizes against each other, and whether the references' counts agree
    (the same stretches, so they must)."""
    n = min(low["runs"], rule["runs"])
    counts = {c["cell"]: {s: c["per_run"][s][:n] for s in SOURCES} for c in (low, rule)}
    a, b = counts[low["cell"]], counts[rule["cell"]]
    ea, eb = _sizes(low, n), _sizes(rule, n)
    refs = {c["cell"]: _sizes(c, n, "inertial") for c in (low, rule)}
    return {
        "lowered": low["cell"],
        "rule": rule["cell"],
        "runs": n,
        "n": {k: {s: int(sum(v[s])) for s in SOURCES} for k, v in counts.items()},
        "mujoco_per_run": _paired(np.array(a["mujoco"]), np.array(b["mujoco"])),
        "inertial_counts_equal": a["inertial"] == b["inertial"],
        "mujoco_sizes_lowered_vs_rule": two_sample(ea, eb) if min(ea.size, eb.size) >= 2 else None,
        "mujoco_sizes_vs_inertial": {
            c["cell"]: two_sample(e, refs[c["cell"]]) if e.size >= 2 else None
            for c, e in ((low, ea), (rule, eb))
        },
    }


def main() -> None:
    rng = np.random.default_rng(0)
    cells = [c for c in (cell(label, tags, r, rng) for label, tags, r in CELLS) if c is not None]
    by_stretch: dict = {}
    for c in cells:  # cells on the same seed, start and run length
        by_stretch.setdefault((c["seed"], c["start"], round(c["segment_length"], 6)), []).append(c)
    pairs = [
        pair(low, rule)
        for group in by_stretch.values()
        for low in group
        if low["dampratio"] != 1.0
        for rule in group
        if rule["dampratio"] == 1.0
    ]
    out = {"cells": cells, "pairs": pairs}
    write_json(REPORTS / "damping_cells.json", out)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
