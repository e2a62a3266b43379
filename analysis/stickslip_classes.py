"""The stick-slip classes (issue 42): slip sizes of the quasistatic references on profiles
whose slope is stationary (a random Gaussian field, fractals of H 0.3 and 0.9, sandpaper)
against the ABBM track's walk, K by K: is there a 3/2 law?

Two steps. ``run`` makes each recipe of ``analysis/stickslip_classes/`` (several seeds
where one strip holds few slips) and writes the references' catalogs with
:func:`spine_mj.validate.stickslip_outputs.stickslip_to`, the function behind ``spine-mj
stickslip`` (one folder a family and seed; a folder already written is kept, so a killed
run resumes). ``report`` reads those folders, pools each family's seeds and gives, per
source and K: the slip count, the truncated power law's tau and the pure power law's
exponent with their intervals, whether a power law survives (the bootstrap does not reject
it, p > 0.1, and no likelihood-ratio test prefers lognormal, exponential or the truncated
power law at p < 0.1), ``S_m = <S^2> / 2<S>`` with its interval, and per family the
exponent of ``S_m`` against K; it writes ``classes.json`` and ``classes.md`` under
``--out``. Sizes in the strip's L_c (a strip's L_c is capped by its width: compare within
a family). A seed whose line (the ball's path on it) is steeper than ``1 / mu`` somewhere
locks the tip, and the references do not apply: it is skipped and counted
(``seeds_locked``).

Run: ``nice -n 19 .venv/bin/python analysis/stickslip_classes.py run`` (about 6 CPU
minutes on one core), then ``... report``.

Grid convergence: ``... run --refinement 2`` writes the same catalogs on the references'
landscape sampled twice as finely (``landscape_refinement``: the surface, its scales and
the stretch unchanged; folders under ``classes_refined2/``), and ``... compare
--refinement 2`` sets each family's pooled ``tau`` and ``S_m`` (and the exponent of
``S_m`` against K) beside the base run's, flagging every value that leaves the other's
interval (``classes_refined2.md``, ``classes_refined2.json``).

Track to track: ``... abbm --seeds 4242,4243`` runs both references on the ``abbm``
preset drawn with each seed and made ``--length`` units long (its spacing, intensity and
correlation length kept; the first 400 units are the preset's track of that seed, the one
an engine runs on, and K is read with that track's scales), at :data:`ABBM_K` (a decade),
and gives per seed, source and K the slip count, the truncated power law's ``tau``, ``S_m``
against ``sigma / k^2``, and ``S_m``'s exponent against K over the decade and over the K
whose ``sigma / k^2`` lies in the ABBM range (``abbm_tracks.md``, ``.json``; catalogs
``abbm_tracks/seed<s>.parquet``, kept on a rerun). ``... walk --seeds ...`` does the
same for the overdamped reference on the walk of docs/physics §12's test
(:data:`WALK`: an ABBM range of three decades, 2e6 points) at :data:`WALK_K`, k in W per
unit length (``abbm_walks.md``, ``.json``).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj import presets
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import write_json
from spine_mj.validate import avalanche_stats as stats
from spine_mj.validate.stickslip_outputs import EDGE_SHARE, _abbm_cutoff_lc, stickslip_to

RECIPES = Path(__file__).parent / "stickslip_classes"
#: Family -> (recipe, seeds, analytic hfield samples a side or None).
FAMILIES = {
    "gaussian": ("gaussian.toml", (1, 2, 3), 2048),
    "fractal H 0.3": ("fractal-H0.3.toml", (1,), None),
    "fractal H 0.9": ("fractal-H0.9.toml", tuple(range(1, 9)), None),
    "sandpaper P60": ("sandpaper-P60.toml", tuple(range(1, 9)), None),
}
K_VALUES = (0.05, 0.1, 0.2, 0.4)
MU = 0.5
#: The power law survives where no test rejects it at this level.
SURVIVE_P = 0.1


def _tree(refinement: int) -> str:
    return "classes" if refinement == 1 else f"classes_refined{refinement}"


def _folder(out: Path, family: str, seed: int, refinement: int = 1) -> Path:
    return out / _tree(refinement) / f"{family.replace(' ', '_')}_seed{seed}"


def run(out: Path, refinement: int = 1) -> None:
    for family, (recipe, seeds, resolution) in FAMILIES.items():
        for seed in seeds:
            folder = _folder(out, family, seed, refinement)
            if (folder / "summary.json").is_file() or (folder / "locked.json").is_file():
                continue
            surf = presets.open_surface(str(RECIPES / recipe), seed=seed)
            extra = {"hfield_resolution": resolution} if resolution else {}
            try:
                stickslip_to(
                    folder,
                    surf,
                    mu=MU,
                    stiffness_numbers=K_VALUES,
                    ie=1e-4,
                    surface_name=f"{family} seed {seed}",
                    n_bootstrap=20,  # each folder's own summary; report() pools the seeds
                    landscape_refinement=refinement,
                    **extra,
                )
            except SpineInputError as exc:  # a slope past 1 / mu: the tip locks, no reference
                if "self-locks" not in str(exc):
                    raise
                write_json(folder / "locked.json", {"family": family, "seed": seed, "reason": str(exc)})
                print(f"{family} seed {seed}: locks ({exc})", flush=True)
                continue
            print(f"{family} seed {seed}: written", flush=True)


def abbm_tracks(out: Path, seeds, preset: str = "abbm", tag: str = "abbm_tracks") -> dict:
    """Both references on ``preset`` drawn with each of ``seeds`` (the module's docstring),
    at :func:`~spine_mj.surfaces.abbm_stiffness_numbers`: per seed the catalogs, then per source and K ``tau``
    and ``S_m`` with their intervals, ``S_m`` over ``sigma / k^2``, whether ``sigma / k^2``
    lies in the ABBM range, and ``S_m``'s exponent against K; with the CPU seconds of each
    seed's references. Written to ``<tag>.json``, ``<tag>.md``, catalogs
    ``<tag>/seed<s>.parquet`` (kept on a rerun)."""
    import time

    from spine_mj.sim.scales import Scales
    from spine_mj.surfaces import abbm_size_range, abbm_smallest_slip, abbm_stiffness_numbers
    from spine_mj.validate.slip_catalog import TrackUnits, reference_rows, track_landscape

    folder = out / tag
    folder.mkdir(parents=True, exist_ok=True)
    result: dict = {"preset": preset, "seeds": {}}
    for seed in seeds:
        path = folder / f"seed{seed}.parquet"
        surf = presets.make_surface(preset, seed=seed)
        ks = abbm_stiffness_numbers(surf, MU)
        result["K"] = ks
        units = TrackUnits.of(Scales.for_surface(surf), 1e-6)
        cpu = None
        if not path.is_file():
            c0 = time.process_time()
            xmin, xmax, _, _ = surf.bounds
            x0, x1 = xmin + EDGE_SHARE * (xmax - xmin), xmax - EDGE_SHARE * (xmax - xmin)
            land = track_landscape(surf, MU, units.tip_radius, (x0, x1))
            kept = ["source", "K", "start_x_lc", "size_lc", "duration_s", "force_drop_fp"]
            frames = []
            for k in ks:
                for rows in reference_rows(
                    land, units, k, surface=f"{preset} seed {seed}", mu=MU, ie=1e-6
                ).values():
                    frames.append(pd.DataFrame(rows)[kept])
                print(f"seed {seed}: K {k:g} done", flush=True)
            del land
            pd.concat(frames, ignore_index=True).to_parquet(path, index=False, compression="zstd")
            cpu = time.process_time() - c0
        events = pd.read_parquet(path)
        params = surf.metadata["params"]
        low, high = (
            v / units.char_length for v in abbm_size_range(surf.spacing[0], params["correlation_length"])
        )
        smallest = abbm_smallest_slip(surf.spacing[0]) / units.char_length
        entry: dict = {
            "L_c": units.char_length,
            "l_s": units.slope_length,
            "abbm_range_lc": [low, high],
            "references_cpu_s": cpu,
            "mean_slope": float(np.mean(np.diff(surf.heights[0]) / surf.spacing[0])),
        }
        for source, by_source in events.groupby("source"):
            cells: dict = {}
            for k, rows in by_source.groupby("K"):
                sizes = rows["size_lc"].to_numpy()
                free = stats.truncated_fit_by_ks(sizes)
                tr = stats.truncated_fit_by_ks(sizes, xmin_floor=smallest)
                cut = stats.cutoff_size(sizes)
                predicted = _abbm_cutoff_lc(surf, MU, units.stiffness(k), units.char_length)
                cells[f"{k:g}"] = {
                    "n_events": int(sizes.size),
                    "tau": {"value": tr["tau"], "low": tr["low"], "high": tr["high"], "xmin_lc": tr["xmin"]},
                    "tau_free_xmin": {
                        "value": free["tau"],
                        "low": free["low"],
                        "high": free["high"],
                        "xmin_lc": free["xmin"],
                    },
                    "cutoff_lc": cut,
                    "predicted_cutoff_lc": predicted,
                    "in_abbm_range": bool(low <= predicted * (1 + 1e-9) and predicted <= high * (1 + 1e-9)),
                }
            for name, kk in (
                ("decade", [float(k) for k in cells]),
                ("abbm_range", [float(k) for k, c in cells.items() if c["in_abbm_range"]]),
            ):
                if len(kk) >= 2:
                    y = np.log([cells[f"{k:g}"]["cutoff_lc"]["value"] for k in kk])
                    slope = float(np.polyfit(np.log(kk), y, 1)[0])
                    se = (
                        float(math.sqrt(np.polyfit(np.log(kk), y, 1, cov=True)[1][0, 0]))
                        if len(kk) > 2
                        else math.nan
                    )
                    cells[f"exponent_{name}"] = {"value": slope, "se": se, "K": kk}
            entry[source] = cells
        result["seeds"][str(seed)] = entry
        write_json(out / f"{tag}.json", result)
    (out / f"{tag}.md").write_text(_abbm_table(result))
    return result


#: The walk of docs/physics §12's test: spacing, intensity D, correlation length, points.
WALK = {"dx": 0.02, "slope_intensity": 1e-6, "correlation_length": 1e4, "points": 2_000_000}
#: Its stiffnesses k [W / unit]: a decade, sigma / k^2 from 39 to 0.39.
WALK_K = (2e-4, 6e-4, 2e-3)


def abbm_walks(out: Path, seeds) -> dict:
    """The overdamped reference on :data:`WALK` drawn with each seed, at :data:`WALK_K`:
    per seed and k the slip count, ``tau`` (truncated power law, cutoff by KS) and ``S_m``
    with their intervals against ``sigma / k^2``, and ``S_m``'s exponent against k."""
    from spine_mj.surfaces import abbm_force_intensity, abbm_slope_walk
    from spine_mj.theory.avalanches import Landscape, overdamped_slips

    w = WALK
    sigma = abbm_force_intensity(w["slope_intensity"], MU)
    result: dict = {"walk": w, "mu": MU, "k": list(WALK_K), "seeds": {}}
    for seed in seeds:
        s = abbm_slope_walk(
            w["points"], w["dx"], w["slope_intensity"], w["correlation_length"], np.random.default_rng(seed)
        )
        land = Landscape.from_profile(w["dx"] * np.arange(s.size), s, np.cumsum(s) * w["dx"], MU)
        cells: dict = {}
        for k in WALK_K:
            sizes = overdamped_slips(land, k).size
            tr = stats.truncated_fit_by_ks(sizes)
            cells[f"{k:g}"] = {
                "n_events": int(sizes.size),
                "tau": {"value": tr["tau"], "low": tr["low"], "high": tr["high"]},
                "cutoff": stats.cutoff_size(sizes),
                "predicted_cutoff": sigma / k**2,
            }
        y = np.log([cells[f"{k:g}"]["cutoff"]["value"] for k in WALK_K])
        coef, cov = np.polyfit(np.log(WALK_K), y, 1, cov=True)
        cells["exponent"] = {"value": float(coef[0]), "se": float(math.sqrt(cov[0, 0]))}
        cells["mean_slope"] = float(np.mean(s))
        result["seeds"][str(seed)] = cells
    write_json(out / "abbm_walks.json", result)
    lines = [
        "# The overdamped reference on fresh draws of the §12 walk (dx 0.02, D 1e-6, xi 1e4, 2e6 points)",
        "",
        "| seed | k [W / unit] | slips | tau [95 %] | tau in [1.4, 1.6], 1.5 inside | S_m [95 %] "
        "| sigma / k^2 |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    slopes = []
    for seed, cells in result["seeds"].items():
        for k in WALK_K:
            c = cells[f"{k:g}"]
            t, m = c["tau"], c["cutoff"]
            ok = 1.4 <= t["value"] <= 1.6 and t["low"] <= 1.5 <= t["high"]
            lines.append(
                f"| {seed} | {k:g} | {c['n_events']} | {t['value']:.3f} [{t['low']:.3f}, {t['high']:.3f}] "
                f"| {'yes' if ok else 'no'} | {m['value']:.3g} [{m['low']:.3g}, {m['high']:.3g}] "
                f"| {c['predicted_cutoff']:.3g} |"
            )
        e = cells["exponent"]
        slopes.append(
            f"- seed {seed}: S_m ~ k^{e['value']:.2f} (+- {e['se']:.2f}); "
            f"mean slope {cells['mean_slope']:.3f}"
        )
    (out / "abbm_walks.md").write_text("\n".join([*lines, "", *slopes, ""]))
    return result


def _abbm_table(result: dict) -> str:
    lines = [
        f"# Both references on the `{result.get('preset', 'abbm')}` preset drawn with each seed",
        "",
        "tau: the truncated power law's, its lower cutoff chosen by KS distance above the smallest",
        "slip that follows S^-3/2 (30 grid spacings, `abbm_smallest_slip`); free xmin: the same with",
        "no floor. 1.5 in: whether the interval contains 3/2.",
        "",
        "| seed | source | K | slips | tau [95 %] | 1.5 in | free xmin: tau [95 %] (xmin [dx]) | S_m [L_c] "
        "| sigma / k^2 [L_c] | in ABBM range |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    slopes = []
    for seed, entry in result["seeds"].items():
        dx_lc = entry["abbm_range_lc"][0] / 50.0 if "abbm_range_lc" in entry else math.nan
        for source in ("overdamped", "inertial"):
            for k, c in entry.get(source, {}).items():
                if k.startswith("exponent_"):
                    slopes.append(
                        f"- seed {seed}, {source}, {k.removeprefix('exponent_')} "
                        f"(K {c['K'][0]:g}-{c['K'][-1]:g}): S_m ~ K^{c['value']:.2f} (+- {c['se']:.2f})"
                    )
                    continue
                t, m = c["tau"], c["cutoff_lc"]
                inside = "yes" if t["low"] <= 1.5 <= t["high"] else "no"
                f = c.get("tau_free_xmin")
                free = (
                    f"{f['value']:.3f} [{f['low']:.3f}, {f['high']:.3f}] ({f['xmin_lc'] / dx_lc:.0f})"
                    if f
                    else ""
                )
                lines.append(
                    f"| {seed} | {source} | {k} | {c['n_events']} | {t['value']:.3f} [{t['low']:.3f}, "
                    f"{t['high']:.3f}] | {inside} | {free} | "
                    f"{m['value']:.3g} [{m['low']:.3g}, {m['high']:.3g}] | "
                    f"{c['predicted_cutoff_lc']:.3g} | {'yes' if c['in_abbm_range'] else 'no'} |"
                )
    return "\n".join([*lines, "", *slopes, ""])


def _survives(fit: dict) -> bool:
    if "gof" not in fit or fit["gof"]["p"] <= SURVIVE_P:
        return False
    return not any(t["R"] < 0 and t["p"] < SURVIVE_P for t in fit["likelihood_ratios"].values())


def report(out: Path, bootstrap: int) -> dict:
    result, lines = pooled(out, bootstrap)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "classes.json", result)
    slopes = [
        f"- {family}, {source}: S_m ~ K^{e['cutoff_exponent']['value']:.2f} "
        f"(+- {e['cutoff_exponent']['se']:.2f}); ABBM's is K^-2"
        for family, per in result.items()
        for source, e in per.items()
        if isinstance(e, dict) and "cutoff_exponent" in e
    ]
    title = ["# Stick-slip classes: slip statistics on stationary-slope profiles", ""]
    (out / "classes.md").write_text("\n".join([*title, *lines, "", *slopes, ""]))
    return result


def pooled(out: Path, bootstrap: int, refinement: int = 1, only=None) -> tuple[dict, list[str]]:
    """Each family's seeds pooled, per source and K (the module's docstring): the result
    dict and its table's lines. ``only``: family -> the seeds to pool (default all)."""
    result: dict = {}
    lines = [
        "| family | source | K | slips | tau (truncated) | power-law exponent | power law survives "
        "| S_m [L_c] |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for family, (_, seeds, _) in FAMILIES.items():
        seeds = seeds if only is None else only.get(family, ())
        folders = [_folder(out, family, s, refinement) for s in seeds]
        frames = [pd.read_parquet(f / "events.parquet") for f in folders if (f / "events.parquet").is_file()]
        if not frames:
            continue
        events = pd.concat(frames, ignore_index=True)
        locked = sum((f / "locked.json").is_file() for f in folders)
        done = [s for s, f in zip(seeds, folders) if (f / "events.parquet").is_file()]
        result[family] = {"seeds": len(frames), "seeds_locked": locked, "seed_list": done}
        for source, by_source in events.groupby("source"):
            entry: dict = {}
            for k, rows in by_source.groupby("K"):
                fit = stats.summarize_sizes(rows["size_lc"].to_numpy(), n_bootstrap=bootstrap)
                cell = {"n_events": fit["n_events"]}
                if "tau" in fit:
                    cell |= {
                        "tau": fit["tau"],
                        "alpha": fit["alpha"],
                        "cutoff_lc": fit["cutoff"],
                        "gof_p": fit["gof"]["p"],
                        "likelihood_ratios": fit["likelihood_ratios"],
                        "power_law_survives": _survives(fit),
                        "three_halves_in_tau": bool(fit["tau"]["low"] <= 1.5 <= fit["tau"]["high"]),
                    }
                entry[f"{k:g}"] = cell
                lines.append(_line(family, source, k, cell))
            ks = [float(k) for k, c in entry.items() if "cutoff_lc" in c]
            if len(ks) >= 3:
                cut = np.log([entry[f"{k:g}"]["cutoff_lc"]["value"] for k in ks])
                coef, cov = np.polyfit(np.log(ks), cut, 1, cov=True)
                entry["cutoff_exponent"] = {"value": float(coef[0]), "se": float(math.sqrt(cov[0, 0]))}
            result[family][source] = entry
    return result, lines


def interval_outside(a: dict, b: dict) -> str:
    """Which of two ``{value, low, high}`` leaves the other's interval: ``""``, ``"refined"``
    (b's value outside a's interval), ``"base"`` or ``"both"``."""
    b_out = not a["low"] <= b["value"] <= a["high"]
    a_out = not b["low"] <= a["value"] <= b["high"]
    return {(False, False): "", (True, False): "refined", (False, True): "base"}.get((b_out, a_out), "both")


def compare(out: Path, bootstrap: int, refinement: int) -> dict:
    """The base run's pooled ``tau``, ``S_m`` and ``S_m``'s exponent against K beside the
    run on the landscape refined ``refinement`` times (the module's docstring), with the
    slip counts and every value that leaves the other's interval (the exponent's interval:
    its value +- 2 standard errors); writes ``classes_refined<f>.md`` and ``.json``. Both
    pool the seeds the refined run holds (a partial run compares like with like)."""
    fine, _ = pooled(out, bootstrap, refinement)
    base, _ = pooled(out, bootstrap, only={f: tuple(e["seed_list"]) for f, e in fine.items()})
    rows, moved = [], {"tau": 0, "S_m": 0, "cells": 0}
    lines = [
        f"| family | source | K | slips (x 1 / x {refinement}) | tau x 1 | tau x {refinement} | moved "
        f"| S_m x 1 [L_c] | S_m x {refinement} | moved |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    seeds = {family: per["seed_list"] for family, per in fine.items()}
    for family, per in base.items():
        for source, entry in per.items():
            if not isinstance(entry, dict) or source not in fine.get(family, {}):
                continue
            other = fine[family][source]
            for k, cell in entry.items():
                if k == "cutoff_exponent" or k not in other:
                    continue
                two = other[k]
                counts = [cell["n_events"], two["n_events"]]
                row = {"family": family, "source": source, "K": float(k), "n": counts}
                cells = [f"{cell['n_events']} / {two['n_events']}"]
                for key, name, fmt in (("tau", "tau", ".2f"), ("cutoff_lc", "S_m", ".3g")):
                    if key in cell and key in two:
                        flag = interval_outside(cell[key], two[key])
                        row[name] = {"base": cell[key], "refined": two[key], "outside": flag}
                        moved[name] += bool(flag)
                        cells += [_interval(cell[key], fmt), _interval(two[key], fmt), flag or "-"]
                    else:
                        cells += ["-", "-", "-"]
                moved["cells"] += "tau" in row
                rows.append(row)
                lines.append(f"| {family} | {source} | {float(k):g} | " + " | ".join(cells) + " |")
            if "cutoff_exponent" in entry and "cutoff_exponent" in other:
                a, b = (
                    {"value": e["value"], "low": e["value"] - 2 * e["se"], "high": e["value"] + 2 * e["se"]}
                    for e in (entry["cutoff_exponent"], other["cutoff_exponent"])
                )
                rows.append({"family": family, "source": source, "S_m_exponent": {"base": a, "refined": b}})
                lines.append(
                    f"| {family} | {source} | S_m ~ K^p | | {_interval(a, '.2f')} | {_interval(b, '.2f')} "
                    f"| {interval_outside(a, b) or '-'} | | | |"
                )
    result = {"refinement": refinement, "seeds": seeds, "moved": moved, "rows": rows}
    write_json(out / f"classes_refined{refinement}.json", result)
    title = [f"# Stick-slip classes under the references' landscape refined x {refinement}", ""]
    summary = [
        "Seeds pooled on both sides: " + "; ".join(f"{f} {s}" for f, s in seeds.items()) + ".",
        "",
        f"Fitted cells: {moved['cells']}; tau leaves an interval in {moved['tau']}, "
        f'S_m in {moved["S_m"]} ("refined": the refined value outside the base\'s interval, '
        '"base": the reverse, "both").',
    ]
    (out / f"classes_refined{refinement}.md").write_text("\n".join([*title, *lines, "", *summary, ""]))
    return result


def _interval(v: dict, fmt: str) -> str:
    return f"{v['value']:{fmt}} [{v['low']:{fmt}}, {v['high']:{fmt}}]"


def _line(family: str, source: str, k: float, cell: dict) -> str:
    if "tau" not in cell:
        return f"| {family} | {source} | {k:g} | {cell['n_events']} | - | - | - | - |"
    t, a, c = cell["tau"], cell["alpha"], cell["cutoff_lc"]
    return (
        f"| {family} | {source} | {k:g} | {cell['n_events']} | {t['value']:.2f} [{t['low']:.2f}, "
        f"{t['high']:.2f}] | {a['value']:.2f} [{a['low']:.2f}, {a['high']:.2f}] | "
        f"{'yes' if cell['power_law_survives'] else 'no'} | "
        f"{c['value']:.3g} [{c['low']:.3g}, {c['high']:.3g}] |"
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("step", choices=("run", "report", "compare", "abbm", "walk"))
    ap.add_argument("--seeds", default="4242", help="abbm: the tracks' seeds")
    ap.add_argument("--preset", default="abbm", help="abbm: the track's preset")
    ap.add_argument("--tag", default="abbm_tracks", help="abbm: the outputs' name")
    ap.add_argument("--out", default="analysis/reports/stickslip")
    ap.add_argument("--bootstrap", type=int, default=100)
    ap.add_argument("--refinement", type=int, default=1, help="landscape sampled this much finer")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if a.step == "run":
        run(out, a.refinement)
    elif a.step == "walk":
        abbm_walks(out, [int(v) for v in a.seeds.split(",")])
        print((out / "abbm_walks.md").read_text())
    elif a.step == "abbm":
        seeds = [int(v) for v in a.seeds.split(",")]
        print(_abbm_table(abbm_tracks(out, seeds, a.preset, a.tag)))
    elif a.step == "compare":
        print(json.dumps(compare(out, a.bootstrap, a.refinement)["moved"]))
    else:
        print(json.dumps(report(out, a.bootstrap), indent=1)[:2000])


if __name__ == "__main__":
    main()
