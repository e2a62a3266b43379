"""The stored runs whose reference falls, judged again against the fall-landing reference.

For every ``compare`` row of the given limit-study stores whose facets' reference slides
under gravity (``reference_slide_fraction`` > 0; each ensemble's own start), this rebuilds
the case's rig and reference (:func:`spine_mj.sweep.analyses.compare.facet_reference`),
traces the plain streamline and the fall-landing one
(:mod:`spine_mj.theory.fall_landing`, the run's own spring, pace and step), and sets the
stored MuJoCo run's outcome (its end reason and last point) against both, as the
``compare`` analysis does in a new sweep. Nothing is run in MuJoCo.

Usage::

    python analysis/fall_landing_check.py STORE [STORE ...] [--out table.csv]

Each STORE is a limit sweep's folder (``OUT/sweeps/limit/sandpaper-P36``). Prints one line
per run and the counts per store: runs whose reference falls, agreeing with the plain
streamline (stored, and as retraced here: the check that the rebuild is the same
reference), and with the landing reference.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj import sweep
from spine_mj.sweep.analyses.compare import facet_reference, fall_params, landing_verdicts
from spine_mj.sweep.analyses.engine import case_rig
from spine_mj.sweep.config import StartsSpec, SurfaceSpec, SweepConfig
from spine_mj.theory.agreement import outcome_agreement
from spine_mj.validate.paths import stored_paths


def _config(doc: dict) -> SweepConfig:
    """The sweep config of a store's manifest (its normalized form, ``SweepConfig.as_dict``)."""

    def starts(d):
        return None if d is None else StartsSpec(**d)

    return SweepConfig(
        name=doc["name"],
        seed=doc["seed"],
        analyses=tuple(doc["analyses"]),
        surfaces=tuple(
            SurfaceSpec(
                kind=s["kind"], source=s["source"], seed=s["seed"], overrides=tuple(s["overrides"].items())
            )
            for s in doc["surfaces"]
        ),
        starts=starts(doc["starts"]),
        grid=tuple((k, tuple(v)) for k, v in doc["grid"].items()),
        store_trajectories=doc["store_trajectories"],
        surface_starts=tuple(starts(d) for d in doc.get("surface_starts", [])),
    )


def _store_rows(store: Path, dt_factor: float = 1.0) -> list[dict]:
    manifest = json.loads((store / "manifest.json").read_text())
    cases = {c.case_id: c for c in sweep.expand_cases(_config(manifest["config"]))}
    runs = sweep.load_runs(store)
    comp = runs[runs["analysis"] == "compare"]
    eng = runs[runs["analysis"] == "engine"].set_index(["case_id", "start"])
    members = comp["ensemble_members"].fillna(1).astype(int).clip(lower=1)
    lead = comp["start"].astype(int) % members == 0
    falls = comp[lead & (comp["reference_slide_fraction"] > 0) & (comp["status"] == "ok")]
    rows = []
    for case_id, grp in falls.groupby("case_id", sort=False):
        case = cases.get(case_id)
        if case is None:  # written by another version of the config
            continue
        t0 = time.process_time()
        surface = case.surface.make()
        rig = case_rig(case, surface)
        s = rig.length_scale_m
        trace, contact, params = facet_reference(case, surface, rig, rig.scales.tip_radius_m / s)
        mpaths = stored_paths(store, case_id, "engine")
        e = eng.loc[case_id]
        idx = grp["start"].astype(int).to_numpy()
        starts = grp[["start_x", "start_y"]].to_numpy(float)
        locked = np.array([e.loc[i, "end_reason"] == "self_lock" for i in idx])
        ends = np.array([mpaths[i][-1] for i in idx])
        lc = rig.scales.char_length_m / s
        plain = trace(contact, starts, params, store_paths=False)
        replain = outcome_agreement(
            plain.self_locked, np.column_stack([plain.end_x, plain.end_y]), locked, ends, length_scale=lc
        )["agree"] & (plain.outcome_names != "stalled")
        fall = fall_params(
            rig.scales,
            stiffness_n_m=float(e["stiffness_n_m"].iloc[0]),
            speed_m_s=float(e["speed_m_s"].iloc[0]),
            timestep_s=float(e["timestep_s"].iloc[0]) * dt_factor,
            length_scale_m=s,
            duration_s=float(e["end_time_s"].max()),
        )
        got = landing_verdicts(
            contact, params, trace, starts, fall, locked, ends, [mpaths[i] for i in idx], lc
        )
        cpu = time.process_time() - t0
        for j, (_, r) in enumerate(grp.iterrows()):
            rows.append(
                {
                    "store": store.name,
                    "case_id": case_id,
                    "start": int(r["start"]),
                    "slide_fraction": float(r["reference_slide_fraction"]),
                    "tip_peak_ie": float(r["tip_peak_ie"]),
                    "mujoco_end": str(e.loc[int(r["start"]), "end_reason"]),
                    "agree_stored": bool(r["agree"]),
                    "agree_retraced": bool(replain[j]),
                    "agree_landing": bool(got["agree_landing"][j]),
                    "frechet_stored": float(r["frechet"]),
                    "frechet_landing": float(got["frechet_landing"][j]),
                    "landing_falls": int(got["landing_falls"][j]),
                    "case_cpu_s": cpu,
                }
            )
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("stores", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, default=None, help="CSV of the per-run rows")
    ap.add_argument(
        "--dt-factor", type=float, default=1.0, help="the falls' step over the engine's (0.5: its refinement)"
    )
    args = ap.parse_args(argv)
    rows = []
    for store in args.stores:
        if not (store / "manifest.json").is_file():
            print(f"Error: {store} is not a sweep store (no manifest.json)", file=sys.stderr)
            return 2
        got = _store_rows(store, args.dt_factor)
        rows += got
        df = pd.DataFrame(got)
        if df.empty:
            print(f"{store}: no run whose reference falls")
            continue
        print(
            f"{store}: {len(df)} runs whose reference falls; agree with the streamline "
            f"{int(df['agree_stored'].sum())} stored, {int(df['agree_retraced'].sum())} retraced; "
            f"with the landing reference {int(df['agree_landing'].sum())}; misses the landing "
            f"explains {int((~df['agree_retraced'] & df['agree_landing']).sum())}, agreements it "
            f"loses {int((df['agree_retraced'] & ~df['agree_landing']).sum())}; "
            f"{df.groupby('case_id')['case_cpu_s'].first().sum():.0f} CPU-s"
        )
    if rows:
        with pd.option_context("display.width", 200, "display.max_columns", 20):
            print(pd.DataFrame(rows).drop(columns=["case_cpu_s"]).to_string(index=False))
        if args.out is not None:
            pd.DataFrame(rows).to_csv(args.out, index=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
