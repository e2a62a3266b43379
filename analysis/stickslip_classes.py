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
from spine_mj.validate.stickslip_outputs import stickslip_to

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


def _folder(out: Path, family: str, seed: int) -> Path:
    return out / "classes" / f"{family.replace(' ', '_')}_seed{seed}"


def run(out: Path) -> None:
    for family, (recipe, seeds, resolution) in FAMILIES.items():
        for seed in seeds:
            folder = _folder(out, family, seed)
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
                    **extra,
                )
            except SpineInputError as exc:  # a slope past 1 / mu: the tip locks, no reference
                if "self-locks" not in str(exc):
                    raise
                write_json(folder / "locked.json", {"family": family, "seed": seed, "reason": str(exc)})
                print(f"{family} seed {seed}: locks ({exc})", flush=True)
                continue
            print(f"{family} seed {seed}: written", flush=True)


def _survives(fit: dict) -> bool:
    if "gof" not in fit or fit["gof"]["p"] <= SURVIVE_P:
        return False
    return not any(t["R"] < 0 and t["p"] < SURVIVE_P for t in fit["likelihood_ratios"].values())


def report(out: Path, bootstrap: int) -> dict:
    result: dict = {}
    lines = [
        "| family | source | K | slips | tau (truncated) | power-law exponent | power law survives "
        "| S_m [L_c] |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for family, (_, seeds, _) in FAMILIES.items():
        frames = [
            pd.read_parquet(_folder(out, family, s) / "events.parquet")
            for s in seeds
            if (_folder(out, family, s) / "events.parquet").is_file()
        ]
        if not frames:
            continue
        events = pd.concat(frames, ignore_index=True)
        locked = sum((_folder(out, family, s) / "locked.json").is_file() for s in seeds)
        result[family] = {"seeds": len(frames), "seeds_locked": locked}
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
    ap.add_argument("step", choices=("run", "report"))
    ap.add_argument("--out", default="analysis/reports/stickslip")
    ap.add_argument("--bootstrap", type=int, default=100)
    a = ap.parse_args(argv)
    out = Path(a.out)
    if a.step == "run":
        run(out)
    else:
        print(json.dumps(report(out, a.bootstrap), indent=1)[:2000])


if __name__ == "__main__":
    main()
