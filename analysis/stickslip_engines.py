"""MuJoCo (and Bullet) slips on the ABBM track against the quasistatic references (issue 42).

For each engine, I_e and variant (``base``; ``dt2``, ``dt4``: half, a quarter of the
engine's step, and with it the rule's contact time constant, 2 dt; ``step2``, ``step4``:
the step alone, the contact's time constant kept; ``hfield2``: the hfield refined twice),
one spring drive per K over the ``abbm`` preset (drawn with ``--seed``, default the
preset's 1; all but a twentieth at each end, in runs of ``--segment`` units from rest),
its slips against the overdamped and inertial references' slips on the same stretch that
the engine's detector would see (peak speed >= 5 V): the Kolmogorov-Smirnov distance and
p-value of sizes and force drops; the same for the force drops deeper than each
``--floors`` value [F_p] (:mod:`spine_mj.theory.force_drops`, one rule for the engine's
steps and the references' paths, key ``drops``; the references also on the profile the
engine's height field makes, straight between its nodes: sources ``*_facets``), with the
engine's resting jitter (the 99th percentile of its elementary force drops); and the creep
of the held tip, MuJoCo's soft friction: the tip's mean x-speed over V in the rows it is
STUCK, and the share of its travel made while stuck. The order of the distance with I_e is
the slope of ``ln D`` against ``ln I_e`` (:func:`order_lines`).

Run: ``nice -n 19 .venv/bin/python analysis/stickslip_engines.py [--ie 1e-4,1e-5]
[--engines mujoco,bullet] [--variants base,dt2,dt4,hfield2] [--travel 150] [--segment 36]
[--floors 3e-4,1e-3] [--seed 1] [--out analysis/reports/stickslip] [--tag NAME]``;
writes ``stickslip_engines_<tag>.json`` after each run (a rerun skips the runs it holds)
and the drop catalogs ``stickslip_drops_<tag>.parquet``, and prints one line per run;
``--report`` tabulates the saved catalogs into ``engines_drops.md`` (:func:`report`), with
the distance's order in I_e (:func:`order_lines`); ``--fits`` gives every saved run's
truncated power law ``tau`` and cutoff ``S_m`` for the engine and the references, and
whether a variant's values leave the base run's intervals (``engines_fits.md``,
:func:`fits`).

``--track abbm``: a cell on the long ``abbm`` preset instead (:func:`abbm_plan` fixes its
floor, travel and I_e from the inertial reference before any run; ``--start``, ``--travel``
a part of it; each run cached under ``segments_<tag>_K<K>``, so a killed cell resumes);
``--cached a,b`` pools the cached runs of stopped cells (:func:`cached_summary`);
``--flat`` measures the first of ``--engines``' breakaway and sliding friction on the preset's
rig made flat, at the rule's step and at half of it (:func:`flat_friction`; ``--flat-length``
units, 20 by default).
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import pickle
import time
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj import presets
from spine_mj.atomic import atomic_output
from spine_mj.errors import check_positive
from spine_mj.jsonio import write_json
from spine_mj.sim.build import build_rig
from spine_mj.theory.force_drops import jitter_scale
from spine_mj.theory.motion import SLIP_SPEED_FACTOR, STUCK
from spine_mj.validate.avalanche_stats import two_sample
from spine_mj.validate.slip_catalog import (
    COLUMNS,
    REFERENCES,
    TrackUnits,
    engine_drop_rows,
    engine_rows,
    facet_count,
    reference_drop_rows,
    reference_rows,
    track_landscape,
)
from spine_mj.validate.stickslip_outputs import EDGE_SHARE, _engine_run

MU = 0.5


def _variant(engine: str, variant: str, ie: float, k: float, surf, dampratio: float | None = None):
    """The variant's rig; with ``dampratio`` its contact's damping ratio set to that at the
    variant's own contact stiffness and step (:func:`at_dampratio`)."""
    rig = _variant_rig(engine, variant, ie, k, surf)
    if dampratio is None:
        return rig
    return _variant_rig(engine, variant, ie, k, surf, **at_dampratio(rig.engine.solref, dampratio))


def at_dampratio(solref, dampratio: float) -> dict:
    """The engine options that give a contact of ``solref = (tc, r0)`` the damping ratio
    ``dampratio`` at the same stiffness: ``solref = (tc r0 / r, r)`` (the rule's ``(2 dt,
    1)`` gives ``(2 dt / r, r)``), since MuJoCo's contact stiffness goes as ``1 / (tc r)^2``
    and its damping as ``1 / tc``: the damping falls as ``r``, the stiffness and the resting
    depth stay."""
    r = check_positive("dampratio", dampratio)
    tc, r0 = solref
    return {"solref_timeconst_s": tc * r0 / r, "solref_dampratio": r}


def _variant_rig(engine: str, variant: str, ie: float, k: float, surf, **contact):
    rig = build_rig(surf, engine=engine, mu=MU, ie=ie, stiffness_number=k, **contact)
    if variant == "base":
        return rig
    if variant in ("step2", "step4"):  # only the step: the contact's time constant kept
        return build_rig(
            surf,
            engine=engine,
            mu=MU,
            ie=ie,
            stiffness_number=k,
            timestep_factor=1 / int(variant[4]),
            **contact,
        )
    if variant in ("dt2", "dt4"):  # the step, and with it the rule's contact time constant (2 dt)
        return build_rig(
            surf,
            engine=engine,
            mu=MU,
            ie=ie,
            stiffness_number=k,
            timestep_s=rig.engine.timestep_s / int(variant[2]),
            **contact,
        )
    if variant == "hfield2":
        return build_rig(
            surf, engine=engine, mu=MU, ie=ie, stiffness_number=k, hfield_refinement=2, **contact
        )
    raise SystemExit(f"unknown variant {variant}")


def _pool(parts: list[dict]) -> dict:
    """Catalog columns of several segments as one."""
    return {c: np.concatenate([np.asarray(p[c]) for p in parts]) if parts else np.zeros(0) for c in COLUMNS}


def _segment(engine, rig, units, surf, k: float, ie: float, a: float, b: float, floors) -> dict:
    """One run from rest over [a, b] and the references on the same stretch (spline and
    facets): the catalog parts, the engine's CPU seconds, end, creep and jitter."""
    land = track_landscape(surf, MU, units.tip_radius, (a, b))
    faceted = track_landscape(surf, MU, units.tip_radius, (a, b), facets=facet_count(rig))
    c0 = time.process_time()
    result = _engine_run(rig, units, land, k, ie, a, b - a)
    piece = {"cpu": time.process_time() - c0, "end": result.end_reason.value}
    piece["eng"] = engine_rows(result, units, engine, k)
    piece["refs"] = reference_rows(land, units, k)
    start = result.drive_start_index
    stuck = np.asarray(result.motion)[start:] == STUCK
    vx = result.velocity_m_s[start:, 0] / (units.speed * units.length_scale_m)
    dx = np.diff(result.position_m[start:, 0], prepend=result.position_m[start, 0])
    piece |= {"stuck_v": vx[stuck], "creep": float(dx[stuck].sum()), "travel": float(dx.sum())}
    piece["jitter"] = jitter_scale(result.drive_force_n[start:] / units.preload_n)
    piece["drops"] = {}
    for floor in floors:
        refs = dict(reference_drop_rows(land, units, k, floor))
        for source, r in reference_drop_rows(faceted, units, k, floor).items():
            r["source"] = [f"{source}_facets"] * len(r["source"])
            refs[f"{source}_facets"] = r
        piece["drops"][floor] = (engine_drop_rows(result, units, engine, k, floor), refs)
    return piece


def one(
    engine: str,
    variant: str,
    ie: float,
    k: float,
    travel: float | None = None,
    floors=(),
    catalogs=None,
    segment: float = 80.0,
    track_length: float | None = None,
    seed: int = 1,
    track: str = "abbm-short",
    start: float | None = None,
    cache: Path | None = None,
    dampratio: float | None = None,
) -> dict:
    """One engine, variant, I_e and K over the track in runs of ``segment`` units (each
    from rest, the references on the same stretch): the catalogs pooled over the runs.
    ``track_length``: the abbm preset made that long (its spacing kept) instead; ``seed``:
    the preset's draw; ``track`` "abbm": the long preset's stretch from ``start``, a rig per
    run on its stretch; ``cache``: a folder that keeps each run's parts (a rerun resumes);
    ``dampratio``: the contact's damping ratio at the variant's contact stiffness
    (:func:`_variant`; None: the rule's)."""
    longer = (
        {} if track_length is None else {"length": track_length, "points": int(round(track_length * 10)) + 1}
    )
    if track == "abbm":  # the long preset: its prefix, and a rig per run on the run's stretch
        surf = whole = abbm_prefix(seed, start + travel + segment)
        xmin, xmax, _, _ = surf.bounds
        x0, length = start, travel
    else:
        surf = presets.make_surface("abbm-short", seed=seed, **longer)
        xmin, xmax, _, _ = surf.bounds
        x0, length = xmin + EDGE_SHARE * (xmax - xmin), (1 - 2 * EDGE_SHARE) * (xmax - xmin)
        length = length if travel is None else travel
        rig = _variant(engine, variant, ie, k, surf, dampratio)
        units = TrackUnits.of(rig.scales, ie)
    count = max(1, math.ceil(length / segment - 1e-9))
    bounds = x0 + length * np.arange(count + 1) / count
    parts: dict = {"eng": [], "refs": {s: [] for s in REFERENCES}, "drops": {f: ([], {}) for f in floors}}
    cpu, ends, stuck_v, creep, travel_sum, jitter = 0.0, [], [], 0.0, 0.0, []
    solrefs: set = set()
    for i, (a, b) in enumerate(itertools.pairwise(bounds)):
        saved = None if cache is None else Path(cache) / f"segment_{i:04d}.pkl"
        if saved is not None and saved.exists():
            piece = pickle.loads(saved.read_bytes())
        else:
            if track == "abbm":
                surf = crop(whole, a - segment / 4, b + segment / 4)
                rig = _variant(engine, variant, ie, k, surf, dampratio)
                units = TrackUnits.of(rig.scales, ie)
            piece = _segment(engine, rig, units, surf, k, ie, a, b, floors)
            piece["solref"] = list(rig.engine.solref)
            if saved is not None:
                saved.parent.mkdir(parents=True, exist_ok=True)
                with atomic_output(saved) as tmp:
                    Path(tmp).write_bytes(pickle.dumps(piece))
            if cache is not None:
                print(f"  segment {i + 1}/{count}: {piece['cpu']:.0f} CPU s", flush=True)
        cpu += piece["cpu"]
        ends.append(piece["end"])
        solrefs.add(tuple(piece.get("solref", ())))
        parts["eng"].append(piece["eng"])
        for source, r in piece["refs"].items():
            parts["refs"][source].append(r)
        stuck_v.append(piece["stuck_v"])
        creep += piece["creep"]
        travel_sum += piece["travel"]
        jitter.append(piece["jitter"])
        for floor in floors:
            eng_parts, ref_parts = parts["drops"][floor]
            eng_parts.append(piece["drops"][floor][0])
            for source, r in piece["drops"][floor][1].items():
                ref_parts.setdefault(source, []).append(r)
    eng = _pool(parts["eng"])
    refs = {s: _pool(v) for s, v in parts["refs"].items()}
    row = {
        "engine": engine,
        "variant": variant,
        "ie": ie,
        "K": k,
        "seed": seed,
        "track": track,
        "start": float(x0),
        "track_length": float(xmax - xmin),
        "segments": count,
        "segment_length": float(length / count),
        "cpu_s": cpu,
        "end": sorted(set(ends)),
        "dampratio": dampratio,
        "solref": [list(v) for v in sorted(solrefs) if v],
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
    stuck_v = np.concatenate(stuck_v)
    row["creep_speed_v"] = float(np.mean(stuck_v)) if stuck_v.size else math.nan
    row["creep_share_of_travel"] = creep / max(travel_sum, 1e-300)
    row["jitter_fp"] = float(max(jitter))
    row["drops"] = {}
    for floor in floors:
        eng_parts, ref_parts = parts["drops"][floor]
        eng_d, ref_d = _pool(eng_parts), {s: _pool(v) for s, v in ref_parts.items()}
        entry = {"n": {engine: len(eng_d["size_lc"])} | {s: len(r["size_lc"]) for s, r in ref_d.items()}}
        for source, r in ref_d.items():
            for col in ("size_lc", "force_drop_fp"):
                if len(eng_d[col]) >= 2 and len(r[col]) >= 2:
                    entry[f"{col}_vs_{source}"] = two_sample(eng_d[col], r[col])
        entry["mean_size_lc"] = {
            s: float(np.mean(r["size_lc"])) for s, r in (ref_d | {engine: eng_d}).items()
        }
        row["drops"][f"{floor:g}"] = entry
        if catalogs is not None:
            for r in (eng_d, *ref_d.values()):
                frame = pd.DataFrame(r, columns=COLUMNS)
                frame["variant"], frame["floor_fp"], frame["ie"], frame["seed"] = variant, floor, ie, seed
                frame["dampratio"] = math.nan if dampratio is None else dampratio
                catalogs.append(frame)
    return row


#: A slip's share of the carriage's advance ``V T`` (T the spring-block's half period
#: ``pi sqrt(m / k)``) over the median inertial drop, below which the drive counts as slow
#: (:func:`slow_ie`). Derived from the saved ``abbm-short`` runs (seed 1, K 1, floor 1e-3,
#: before any run on the ``abbm`` preset): the size distance there fell as ``D = 0.31 Lambda``
#: (0.214 at Lambda 0.69, I_e 1e-4), and Lambda 0.12 keeps it to a third of the KS critical
#: value of 300 against 300 drops (0.111).
SLOWNESS = 0.12
#: The force-drop floor as a share of the cutoff's drop ``k S_m = sigma / k``: the
#: ``abbm-short`` runs' 1e-3 F_p at their K 1 (``sigma / k`` 9.1e-3 F_p), so that every K
#: keeps the same part of its size distribution.
FLOOR_SHARE = 0.11
#: Inertial drops a cell's travel must hold (the test's power: KS's 95 % critical distance
#: 1.36 sqrt(2 / 300) = 0.11 against as many reference drops).
DROPS_PER_CELL = 300
#: A run's stretch in cutoffs ``S_m = sigma / k^2``: every slip (up to ~4 inertial cutoffs,
#: 3 S_m each) fits many times, and MuJoCo's float32 hfield keeps a tenth of the walk's
#: curvature per node over it (height range <= 0.1 x 40 S_m).
SEGMENT_CUTOFFS = 40.0


def abbm_prefix(seed: int, end: float):
    """The ``abbm`` preset drawn with ``seed`` from x = 0 to at least ``end`` (and at least
    its correlation length): the preset's own first points, since the slope walk is drawn
    point after point from the seed (heights differ by a constant, the mean removed)."""
    from spine_mj.presets import load_preset

    params = load_preset("abbm").params
    dx = params["length"] / (params["points"] - 1)
    end = max(end, params["correlation_length"])
    n = int(math.ceil(end / dx)) + 1
    return presets.make_surface("abbm", seed=seed, length=(n - 1) * dx, points=n)


def crop(surf, a: float, b: float):
    """The strip of ``surf`` over x in [a, b] (its grid points there, metadata kept: the
    slope length and so K mean the same spring)."""
    import dataclasses

    keep = (surf.x >= a) & (surf.x <= b)
    return dataclasses.replace(surf, heights=surf.heights[:, keep].copy(), x=surf.x[keep].copy())


def abbm_plan(surf, k: float, start: float, longest: float, drops: int = DROPS_PER_CELL) -> dict:
    """One K's cell on an ``abbm`` track, fixed from the inertial reference before any
    engine run: the floor (:data:`FLOOR_SHARE` of ``sigma / k``), the travel that holds
    :data:`DROPS_PER_CELL` inertial drops (searched up to ``longest`` units), and the I_e at
    which the carriage advances :data:`SLOWNESS` median drops in a half period."""
    from spine_mj.surfaces.tracks import abbm_force_intensity

    params = surf.metadata["params"]
    xi = params["correlation_length"]
    sigma = abbm_force_intensity(params["slope_intensity"], MU)
    kk = k / xi
    floor = float(f"{FLOOR_SHARE * sigma / kk:.2g}")
    cutoff = sigma / kk**2
    segment = SEGMENT_CUTOFFS * cutoff
    probe = crop(surf, start - 1, start + 50)
    units = TrackUnits.of(build_rig(probe, engine="mujoco", mu=MU, ie=1.0, stiffness_number=k).scales, 1.0)
    sizes, ends = [], []
    x = start
    while x < start + longest and len(sizes) < drops:
        land = track_landscape(surf, MU, units.tip_radius, (x, x + segment))
        r = reference_drop_rows(land, units, k, floor)["inertial"]
        sizes += list(np.asarray(r["size_lc"]) * units.char_length)
        x += segment
        ends.append(x)
    travel = x - start
    s_med = float(np.median(sizes))
    half_period = math.pi * math.sqrt(units.mass / kk)
    speed = SLOWNESS * s_med / half_period
    ie = float(f"{(speed / units.speed) ** 2:.2g}")
    return {
        "K": k,
        "floor_fp": floor,
        "cutoff": cutoff,
        "segment": segment,
        "travel": travel,
        "inertial_drops": len(sizes),
        "median_drop": s_med,
        "half_period_s": half_period,
        "ie": ie,
        "speed": speed,
    }


def batch_mean_se(series: np.ndarray, batches: int = 20) -> float:
    """The standard error of a correlated series' mean by batch means: the spread of the
    means of ``batches`` contiguous blocks over ``sqrt(batches)`` (a sliding force rings, so
    its rows are not independent and ``std / sqrt(n)`` would be far too narrow)."""
    blocks = np.array_split(np.asarray(series, dtype=float), batches)
    means = np.array([b.mean() for b in blocks])
    return float(means.std(ddof=1) / np.sqrt(batches))


def flat_rig(
    flat,
    engine: str,
    ie: float,
    k: float,
    step_share: float,
    dampratio: float | None = None,
    solref_steps: tuple[float, float] | None = None,
    impratio: float | None = None,
):
    """:func:`flat_friction`'s rig on the strip ``flat``: the rule's step times ``step_share``,
    the contact as :func:`flat_friction` says (MuJoCo's tip held on its line)."""
    rail = {"line": True} if engine == "mujoco" else {}  # Bullet's tip has no lateral force here
    base = build_rig(flat, engine=engine, mu=MU, ie=ie, stiffness_number=k, **rail)
    step = {"timestep_s": base.engine.timestep_s * step_share}
    rig = build_rig(flat, engine=engine, mu=MU, ie=ie, stiffness_number=k, **step, **rail)
    contact = {}
    if dampratio is not None:
        contact = at_dampratio(rig.engine.solref, dampratio)
    if solref_steps is not None:
        n, r = solref_steps
        contact = {"solref_timeconst_s": n * rig.engine.timestep_s, "solref_dampratio": r}
    if impratio is not None:
        contact["impratio"] = impratio
    if contact:
        rig = build_rig(flat, engine=engine, mu=MU, ie=ie, stiffness_number=k, **step, **rail, **contact)
    return rig


def flat_friction(
    seed: int,
    k: float,
    ie: float,
    step_share: float,
    x0: float = 22580.0,
    engine: str = "mujoco",
    length: float = 20.0,
    dampratio: float | None = None,
    solref_steps: tuple[float, float] | None = None,
    impratio: float | None = None,
) -> dict:
    """An engine's spring drive on a flat strip of the ``abbm`` preset's rig (its crop at ``x0``,
    heights zeroed, so the same scales, tip and step): the breakaway force and the sliding
    force over the second half of a run of ``length`` units (the reference's is ``mu W`` for both),
    at the rule's step times ``step_share`` (the contact's time constant following it; with
    ``dampratio``, its damping ratio that at the same contact stiffness, :func:`at_dampratio`;
    with ``solref_steps = (n, r)``, ``solref = (n dt, r)`` at the run's step dt; with
    ``impratio``, MuJoCo's frictional-to-normal impedance ratio, the rule's 1 otherwise)."""
    import dataclasses

    part = crop(abbm_prefix(seed, x0 + 40), x0 - 10, x0 + 30)
    flat = dataclasses.replace(part, heights=np.zeros_like(part.heights))
    rig = flat_rig(flat, engine, ie, k, step_share, dampratio, solref_steps, impratio)
    units = TrackUnits.of(rig.scales, ie)
    land = track_landscape(flat, MU, units.tip_radius, (x0, x0 + length))
    c0 = time.process_time()
    res = _engine_run(rig, units, land, k, ie, x0, length)
    f = res.drive_force_n[res.drive_start_index :] / units.preload_n
    late = f[f.size // 2 :]
    return {
        "engine": engine,
        "seed": seed,
        "K": k,
        "ie": ie,
        "timestep_s": rig.engine.timestep_s,
        "solref": list(rig.engine.solref),
        "impratio": rig.engine.impratio,
        "breakaway_fp": float(f.max()),
        "sliding_fp": float(late.mean()),
        "sliding_std_fp": float(late.std()),
        "sliding_se_fp": batch_mean_se(late),
        "mu": MU,
        "cpu_s": time.process_time() - c0,
    }


def cached_summary(folders: list[Path], engine: str = "mujoco") -> dict:
    """The runs cells' ``cache`` folders hold (a cell stopped before its last run), pooled: counts,
    engine CPU seconds, end reasons and the engine's drop sizes against each reference's on
    the same stretches (KS and AD, :func:`~spine_mj.validate.avalanche_stats.two_sample`)."""
    files = [f for folder in folders for f in sorted(Path(folder).glob("segment_*.pkl"))]
    pieces = [pickle.loads(f.read_bytes()) for f in files]
    ((floor, _),) = pieces[0]["drops"].items()
    eng = _pool([p["drops"][floor][0] for p in pieces])
    refs = {s: _pool([p["drops"][floor][1][s] for p in pieces]) for s in pieces[0]["drops"][floor][1]}
    out = {
        "runs": len(pieces),
        "floor_fp": floor,
        "cpu_s": sum(p["cpu"] for p in pieces),
        "ends": sorted({p["end"] for p in pieces}),
        "n": {engine: len(eng["size_lc"])} | {s: len(r["size_lc"]) for s, r in refs.items()},
        "jitter_fp": max(p["jitter"] for p in pieces),
    }
    for source, r in refs.items():
        if len(eng["size_lc"]) >= 2 and len(r["size_lc"]) >= 2:
            out[f"size_lc_vs_{source}"] = two_sample(eng["size_lc"], r["size_lc"])
    out["median_size_lc"] = {
        s: float(np.median(r["size_lc"])) for s, r in (refs | {engine: eng}).items() if len(r["size_lc"])
    }
    out["median_duration_s"] = float(np.median(eng["duration_s"])) if len(eng["duration_s"]) else math.nan
    return out


def _positive(name: str):
    """An argparse type: a float > 0, else argparse's error line naming ``name`` (exit 2)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not value > 0 or not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{name} expects a positive number, got {text!r}")
        return value

    return parse


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ie", default="1e-4,1e-5")
    ap.add_argument("--K", default="0.5")
    ap.add_argument("--engines", default="mujoco")
    ap.add_argument("--variants", default="base")
    ap.add_argument("--travel", type=float, default=None, help="surface units (default: the track)")
    ap.add_argument("--segment", type=float, default=80.0, help="surface units a run (from rest)")
    ap.add_argument("--track-length", type=float, default=None, help="abbm preset's length (default 400)")
    ap.add_argument("--floors", default="3e-4,1e-3", help="force-drop floors [F_p]")
    ap.add_argument("--seed", type=int, default=1, help="the abbm preset's seed")
    ap.add_argument("--out", default="analysis/reports/stickslip")
    ap.add_argument("--tag", default=None, help="output name (default: engines_variants)")
    ap.add_argument("--report", action="store_true", help="only tabulate the saved drop catalogs")
    ap.add_argument("--fits", action="store_true", help="only fit tau and S_m to the saved catalogs")
    ap.add_argument("--track", default="abbm-short", help="abbm-short, or abbm (the long preset)")
    ap.add_argument("--drops", type=int, default=DROPS_PER_CELL, help="abbm: inertial drops a cell holds")
    ap.add_argument("--start", type=float, default=None, help="abbm: the cell's first x (default: 5 %% in)")
    ap.add_argument(
        "--flat", action="store_true", help="only the engine's friction on a flat strip (default, dt / 2)"
    )
    ap.add_argument(
        "--flat-length", type=float, default=20.0, help="--flat: the run's units past the start's lead"
    )
    ap.add_argument(
        "--dampratio",
        type=_positive("--dampratio"),
        default=None,
        help="the contact's damping ratio at the variant's contact stiffness (default: the rule's 1)",
    )
    ap.add_argument("--cached", default=None, help="only summarize cached runs (folders, a,b)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if a.flat:
        engine = a.engines.split(",")[0]
        rows = [
            flat_friction(
                a.seed,
                float(a.K),
                float(a.ie),
                share,
                engine=engine,
                length=a.flat_length,
                dampratio=a.dampratio,
            )
            for share in (1.0, 0.5)
        ]
        name = "abbm_flat" if engine == "mujoco" else f"abbm_flat_{engine}"
        name += "" if a.dampratio is None else f"_r{a.dampratio:g}"
        write_json(out / f"stickslip_engines_{name}.json", rows)
        print(json.dumps(rows, indent=1))
        return
    if a.cached:
        folders = [Path(f) for f in a.cached.split(",")]
        summary = cached_summary(folders)
        write_json(out / f"{folders[0].name}_cached.json", summary | {"folders": [f.name for f in folders]})
        print(json.dumps(summary, indent=1))
        return
    if a.report:
        print(report(out))
        return
    if a.fits:
        print(fits(out))
        return
    out.mkdir(parents=True, exist_ok=True)
    tag = a.tag or f"{a.engines.replace(',', '_')}_{a.variants.replace(',', '_')}"
    path, cat_path = out / f"stickslip_engines_{tag}.json", out / f"stickslip_drops_{tag}.parquet"
    rows = json.loads(path.read_text()) if path.exists() else []
    catalogs = [pd.read_parquet(cat_path)] if cat_path.exists() else []
    floors = [float(v) for v in a.floors.split(",") if v.strip()]
    if a.track == "abbm":  # each K's floor, travel and I_e from the inertial reference (abbm_plan)
        start = EDGE_SHARE * presets.load_preset("abbm").params["length"] if a.start is None else a.start
        for k in (float(v) for v in a.K.split(",")):
            plan_path = out / f"stickslip_plan_{a.tag}_K{k:g}.json"
            if plan_path.exists():
                plan = json.loads(plan_path.read_text())
            else:
                plan = abbm_plan(abbm_prefix(a.seed, start + 60000), k, start, 60000, a.drops)
                write_json(plan_path, plan)
            print(f"plan K {k:g}: {plan}", flush=True)
            for engine in a.engines.split(","):
                for variant in a.variants.split(","):
                    if any(
                        (r["engine"], r["variant"], r["K"], r.get("seed", 1), r.get("dampratio"))
                        == (engine, variant, k, a.seed, a.dampratio)
                        for r in rows
                    ):
                        continue
                    row = one(
                        engine,
                        variant,
                        plan["ie"],
                        k,
                        plan["travel"] if a.travel is None else min(a.travel, plan["travel"]),
                        [plan["floor_fp"]],
                        catalogs,
                        a.segment,
                        None,
                        a.seed,
                        "abbm",
                        start,
                        out / f"segments_{a.tag}_K{k:g}",
                        a.dampratio,
                    )
                    row["plan"] = plan
                    rows.append(row)
                    write_json(path, rows)
                    with atomic_output(cat_path) as tmp:
                        pd.concat(catalogs, ignore_index=True).to_parquet(tmp, index=False)
                    e = row["drops"][f"{plan['floor_fp']:g}"]
                    tests = {c: (v["ks"], v["ks_p"]) for c, v in e.items() if c.startswith("size_lc_vs")}
                    print(
                        f"{engine} {variant} seed {a.seed} K {k:g} I_e {plan['ie']:g}: {e['n']} {tests} "
                        f"jitter {row['jitter_fp']:.3g} F_p; {row['cpu_s']:.0f} CPU s",
                        flush=True,
                    )
        return
    for engine in a.engines.split(","):
        for variant in a.variants.split(","):
            for ie in (float(v) for v in a.ie.split(",")):
                for k in (float(v) for v in a.K.split(",")):
                    if any(
                        (r["engine"], r["variant"], r["ie"], r["K"], r.get("seed", 1), r.get("dampratio"))
                        == (engine, variant, ie, k, a.seed, a.dampratio)
                        for r in rows
                    ):
                        continue
                    row = one(
                        engine,
                        variant,
                        ie,
                        k,
                        a.travel,
                        floors,
                        catalogs,
                        a.segment,
                        a.track_length,
                        a.seed,
                        dampratio=a.dampratio,
                    )
                    rows.append(row)
                    write_json(path, rows)
                    with atomic_output(cat_path) as tmp:
                        pd.concat(catalogs, ignore_index=True).to_parquet(tmp, index=False)
                    d = row.get("size_lc_vs_inertial", {})
                    print(
                        f"{engine} {variant} seed {a.seed} I_e {ie:g} K {k:g}: {row['n']} sizes vs inertial "
                        f"D {d.get('ks', math.nan):.3f} p {d.get('ks_p', math.nan):.3g}; "
                        f"creep {row['creep_speed_v']:.3g} V, "
                        f"{row['creep_share_of_travel']:.3g} of travel; {row['cpu_s']:.0f} CPU s",
                        flush=True,
                    )
                    for floor, e in row["drops"].items():
                        d = e.get("size_lc_vs_inertial", {})
                        print(
                            f"  drops > {floor} F_p: {e['n']} sizes vs inertial "
                            f"D {d.get('ks', math.nan):.3f} "
                            f"p {d.get('ks_p', math.nan):.3g}; jitter {row['jitter_fp']:.3g} F_p",
                            flush=True,
                        )


def _saved_runs(out: Path) -> dict:
    """Every saved drop catalog under ``out`` by ``(seed, variant, ie, K, floor)``; a run
    that two files hold, the first file's."""
    runs: dict = {}
    for path in _short_track_catalogs(out):
        for key, g in _with_seed(pd.read_parquet(path)).groupby(["seed", "variant", "ie", "K", "floor_fp"]):
            runs.setdefault(key, g)
    return runs


def fits(out: Path, sources=("inertial", "inertial_facets", "overdamped"), floor_fp: float = 1e-3) -> str:
    """Per saved run (:func:`_saved_runs`) at the floor ``floor_fp`` [F_p] the engine's and
    ``sources``' drop sizes fitted (a catalog met before, its fit reused):
    the truncated power law's ``tau`` (cutoff chosen by KS) and ``S_m = <S^2> / 2<S>``,
    with 95 % intervals; a variant's engine values flagged where they leave the base run's
    interval at the same seed, I_e, K and floor, or the base's leave theirs (the engine's
    exponent and cutoff under dt / 2 and hfield x 2). Written to ``engines_fits.md``."""
    from stickslip_classes import interval_outside

    from spine_mj.validate import avalanche_stats as stats
    from spine_mj.validate.slip_tails import MIN_EVENTS

    cells, seen = {}, {}
    lines = [
        "| seed | variant | I_e | K | source | drops | tau [95 %] | S_m [L_c] [95 %] "
        "| against base: tau, S_m |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for (seed, variant, ie, k, floor), g in sorted(_saved_runs(out).items()):
        if not math.isclose(floor, floor_fp):
            continue
        engines = sorted(set(g["source"]) - set(REFERENCES) - {f"{r}_facets" for r in REFERENCES})
        for source in (*engines, *sources):
            sizes = g.loc[g["source"] == source, "size_lc"].to_numpy()
            if sizes.size < MIN_EVENTS or np.unique(sizes).size < 10:  # summarize_sizes' guard
                continue
            key = (source, sizes.tobytes())
            if key not in seen:
                tr = stats.truncated_fit_by_ks(sizes)
                seen[key] = {
                    "n": int(sizes.size),
                    "tau": {"value": tr["tau"], "low": tr["low"], "high": tr["high"]},
                    "S_m": stats.cutoff_size(sizes),
                }
            fit = seen[key]
            cells[(seed, variant, ie, k, floor, source)] = fit
            base = cells.get((seed, "base", ie, k, floor, source))
            flags = (
                "-"
                if base is None or variant == "base" or source not in engines
                else ", ".join(interval_outside(base[q], fit[q]) or "in" for q in ("tau", "S_m"))
            )
            t, m = fit["tau"], fit["S_m"]
            lines.append(
                f"| {seed} | {variant} | {ie:g} | {k:g} | {source} | {fit['n']} | {t['value']:.2f} "
                f"[{t['low']:.2f}, {t['high']:.2f}] | {m['value']:.3g} [{m['low']:.3g}, {m['high']:.3g}] "
                f"| {flags} |"
            )
    title = f"# Engines' and references' drop sizes fitted (force drops deeper than {floor_fp:g} F_p)"
    text = "\n".join([title, "", *lines, ""])
    (out / "engines_fits.md").write_text(text)
    return text


def report(out: Path) -> str:
    """The force-drop comparisons of every saved ``stickslip_drops_*.parquet`` under
    ``out`` as a markdown table (written to ``engines_drops.md``): per run and floor the
    counts, and the engine's sizes and force drops against each reference by
    Kolmogorov-Smirnov (D, p) and Anderson-Darling (p). The force drops also at a fixed
    carriage: an engine's drop plus ``k V T`` (its carriage moves ``V T`` during a drop of
    duration T; the references' carriage stands still), in F_p."""
    rows = [
        "| run | K | I_e | floor [F_p] | engine drops | reference | reference drops "
        "| sizes D, p (AD p) | drops D, p (AD p) | drops at fixed carriage D, p (AD p) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for path in _short_track_catalogs(out):
        cat = _with_seed(pd.read_parquet(path))
        runs = json.loads(
            (out / path.name.replace("stickslip_drops_", "stickslip_engines_"))
            .with_suffix(".json")
            .read_text()
        )
        for (variant, ie, k, floor, seed), g in cat.groupby(["variant", "ie", "K", "floor_fp", "seed"]):
            run = next(
                r for r in runs if (r["variant"], r["ie"], r["K"], r.get("seed", 1)) == (variant, ie, k, seed)
            )
            engine = g[g["source"] == run["engine"]]
            fixed = (
                engine["force_drop_fp"] + _carriage_rate(run["engine"], ie, k, seed) * engine["duration_s"]
            )
            for source in sorted(set(g["source"]) - {run["engine"]}):
                ref = g[g["source"] == source]
                cells = [
                    two_sample(a, ref[col])
                    for a, col in (
                        (engine["size_lc"], "size_lc"),
                        (engine["force_drop_fp"], "force_drop_fp"),
                        (fixed, "force_drop_fp"),
                    )
                ]
                rows.append(
                    f"| {path.stem.removeprefix('stickslip_drops_')} {variant}{_seed_label(seed)} | {k:g} "
                    f"| {ie:g} | {floor:g} "
                    f"| {len(engine)} | {source} | {len(ref)} | "
                    + " | ".join(f"{c['ks']:.3f}, {c['ks_p']:.3g} ({c['ad_p']:.3g})" for c in cells)
                    + " |"
                )
    text = (
        "\n".join(["# Engines' force drops against the references", "", *rows, "", *order_lines(out)]) + "\n"
    )
    (out / "engines_drops.md").write_text(text)
    return text


#: Kolmogorov-Smirnov's 95 % critical distance of two samples is this times sqrt((n + m) / (n m)).
KS_95 = 1.358


def _carriage_rate(engine: str, ie: float, k: float, seed: int = 1) -> float:
    """``k V`` [F_p / s] of the abbm preset's drive (drawn with ``seed``) at ``ie`` and
    ``K = k``: an engine's drop plus this times its duration is its drop at a fixed
    carriage, as the references'."""
    surf = presets.make_surface("abbm-short", seed=int(seed))
    units = TrackUnits.of(build_rig(surf, engine=engine, mu=MU, ie=ie, stiffness_number=k).scales, ie)
    return units.stiffness(k) * units.speed


def _short_track_catalogs(out: Path) -> list[Path]:
    """The saved drop catalogs of the ``abbm-short`` runs (the ``abbm`` preset's cells,
    ``stickslip_drops_abbm_*``, carry their own summaries in their JSON)."""
    return [
        p
        for p in sorted(out.glob("stickslip_drops_*.parquet"))
        if not p.name.startswith("stickslip_drops_abbm_")
    ]


def _with_seed(cat: pd.DataFrame) -> pd.DataFrame:
    """A saved catalog with its ``seed`` column (catalogs written before it: the preset's 1)."""
    return cat if "seed" in cat else cat.assign(seed=1)


def _seed_label(seed) -> str:
    return "" if int(seed) == 1 else f" (seed {int(seed)})"


def _order(ies, engine_sizes, ref_sizes) -> float:
    """The slope of ``ln D`` against ``ln I_e``, D the KS distance of each engine sample
    from the reference's sample at the same I_e."""
    d = [two_sample(e, r)["ks"] for e, r in zip(engine_sizes, ref_sizes)]
    return float(np.polyfit(np.log(ies), np.log(d), 1)[0])


def _order_cells(by_ie: dict, engine: str, ref: str, rng, n_boot: int, kv=None) -> tuple[list[str], str]:
    """One series' cells of :func:`order_lines`: per I_e (falling) the counts, D, D_95 and
    p; the order over the leading I_e values whose D exceeds D_95 (from the largest I_e
    down to the last before D first meets the sampling floor), with its bootstrap interval.
    Sizes, or with ``kv`` (I_e -> ``k V`` [F_p / s]) the force drops at a fixed carriage."""
    cells, used = [], []
    for ie, h in sorted(by_ie.items(), reverse=True):
        if kv is None:
            eng, refs = (h.loc[h["source"] == s, "size_lc"].to_numpy() for s in (engine, ref))
        else:
            e = h[h["source"] == engine]
            eng = (e["force_drop_fp"] + kv[ie] * e["duration_s"]).to_numpy()
            refs = h.loc[h["source"] == ref, "force_drop_fp"].to_numpy()
        if eng.size < 2 or refs.size < 2:
            continue
        t = two_sample(eng, refs)
        crit = KS_95 * math.sqrt((eng.size + refs.size) / (eng.size * refs.size))
        cells.append(f"{ie:g}: {eng.size} / {refs.size}, {t['ks']:.3f} ({crit:.3f}, {t['ks_p']:.2g})")
        if t["ks"] > crit and len(used) == len(cells) - 1:  # the leading run above the floor
            used.append((ie, eng, refs))
    if len(used) < 2:
        return cells, "-"
    ies, engs, refs = zip(*used)
    boot = [
        _order(ies, [rng.choice(e, e.size) for e in engs], [rng.choice(r, r.size) for r in refs])
        for _ in range(n_boot)
    ]
    low, high = np.percentile(boot, [2.5, 97.5])
    return cells, f"{_order(ies, engs, refs):.2f} [{low:.2f}, {high:.2f}] over I_e {ies[-1]:g}-{ies[0]:g}"


def order_lines(out: Path, n_boot: int = 400, seed: int = 0) -> list[str]:
    """The distance of an engine's drop sizes from each reference's against I_e, from every
    saved ``stickslip_drops_*.parquet`` under ``out`` (one row per variant, K, floor and
    reference; each I_e against the reference's catalog on the same stretches; a run that
    two files hold, the first file's). Per I_e the counts, the KS
    distance D, its p-value and its 95 % critical value D_95 (the sampling floor: below it
    D is noise); per series the order ``p`` of ``D ~ I_e^p``, fitted by least squares in
    logs over the I_e values whose D exceeds D_95 from the largest down (where the distance
    falls, before it reaches the floor), with a 95 % bootstrap interval (the catalogs
    resampled ``n_boot`` times). A D above D_95 again at smaller I_e is in the cells."""
    frames, seen = [], set()
    for path in _short_track_catalogs(out):  # a run repeated in a later file: the first
        for key, g in _with_seed(pd.read_parquet(path)).groupby(["variant", "ie", "K", "floor_fp", "seed"]):
            if key not in seen:
                seen.add(key)
                frames.append(g)
    if not frames:
        return []
    cat = pd.concat(frames, ignore_index=True)
    rng = np.random.default_rng(seed)
    lines = [
        "## The distance against I_e",
        "",
        "| variant | K | floor [F_p] | reference | of | I_e: engine / reference drops, KS D (D_95, p) "
        "| order p of D ~ I_e^p [95 %] |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    facets = {f"{r}_facets" for r in REFERENCES}
    for (variant, k, floor, seed), g in cat.groupby(["variant", "K", "floor_fp", "seed"]):
        engines = sorted(set(g["source"]) - set(REFERENCES) - facets)
        if len(engines) != 1 or g["ie"].nunique() < 2:
            continue
        by_ie = dict(tuple(g.groupby("ie")))
        kv = {ie: _carriage_rate(engines[0], ie, k, seed) for ie in by_ie}
        for ref in sorted(set(g["source"]) - set(engines)):
            for of, rate in (("sizes", None), ("drops, fixed carriage", kv)):
                cells, order = _order_cells(by_ie, engines[0], ref, rng, n_boot, rate)
                lines.append(
                    f"| {variant}{_seed_label(seed)} | {k:g} | {floor:g} | {ref} | {of} | "
                    + "; ".join(cells)
                    + f" | {order} |"
                )
    return lines


if __name__ == "__main__":
    main()
