"""Does hfield resolution close the smooth-vs-faceted streamline gap? (issue 6, validation).

For the random Gaussian (convex, concave) and fractal presets, the quasistatic streamline on
the smooth surface is compared with the streamline on MuJoCo's triangulated hfield of that
surface, at several hfield resolutions, from the validation's starts. Two tip conventions:
the tip fixed at the rig's default for the quick plan (151 samples), which isolates the
facet geometry, and the tip the rig would use at each resolution (one hfield spacing, at
least L_c / 100; only up to 201 samples, as a smaller tip makes the facet streamline
slow). Fractal presets are grid surfaces: their hfield is their own grid, so
their resolution does not change (one row per tip convention).

Run: ``nice -n 19 .venv/bin/python analysis/hfield_geometry.py [--out analysis/reports]``;
writes ``hfield_geometry.json`` and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from spine_mj import presets
from spine_mj import validate as V
from spine_mj.jsonio import write_json
from spine_mj.roughness import characteristic_length
from spine_mj.surfaces import GridSurface

RESOLUTIONS = (151, 201, 401, 801)
RIG_TIP_MAX_RES = 201
CASES = (("paper-random-convex", (1,)), ("paper-random-concave", (1,)), ("paper-fractal", (1,)))


def _starts(surface, n=5, x=0.05):
    xmin, xmax, ymin, ymax = surface.bounds
    ys = np.linspace(0.2, 0.8, n)
    return np.column_stack([np.full(n, xmin + x * (xmax - xmin)), ymin + ys * (ymax - ymin)])


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="analysis/reports")
    args = ap.parse_args(argv)
    rows = []
    for preset, seeds in CASES:
        mu = V.calibrated_mu(preset)
        for seed in seeds:
            surface = presets.make_surface(preset, seed=seed)
            lc = characteristic_length(surface)
            starts = _starts(surface)
            tip151 = V.tip_radius(preset, (seed,), 151)
            grid = isinstance(surface, GridSurface)
            for res in (surface.heights.shape[1],) if grid else RESOLUTIONS:
                tips = {"fixed (quick-plan tip)": tip151}
                if res <= RIG_TIP_MAX_RES:
                    # the facet sampling step follows the tip (tip / 8): finer tips cost more
                    tips["rig default at this resolution"] = V.tip_radius(preset, (seed,), res)
                for label, tip in tips.items():
                    t0 = time.perf_counter()
                    smooth = V.streamline_paths(surface, starts, mu, tip / 2, tip)
                    tri = V.streamline_paths(
                        V.triangulated_surface(surface, None if grid else res), starts, mu, tip / 2, tip
                    )
                    fr, lock_agree = [], []
                    for i in range(len(starts)):
                        a, b = smooth.path(i), tri.path(i)
                        g, _ = V.path_metrics(
                            np.column_stack([b["x"], b["y"]]), np.column_stack([a["x"], a["y"]]), lc
                        )
                        fr.append(g)
                        lock_agree.append(bool(smooth.self_locked[i]) == bool(tri.self_locked[i]))
                    span = surface.bounds[1] - surface.bounds[0]
                    rows.append(
                        {
                            "preset": preset,
                            "seed": seed,
                            "resolution": res,
                            "spacing_over_lc": span / (res - 1) / lc,
                            "tip": label,
                            "tip_over_lc": tip / lc,
                            "frechet": fr,
                            "median_frechet": float(np.nanmedian(fr)),
                            "mean_frechet": float(np.nanmean(fr)),
                            "max_frechet": float(np.nanmax(fr)),
                            "lock_agreement": float(np.mean(lock_agree)),
                            "seconds": round(time.perf_counter() - t0, 1),
                        }
                    )
                    r = rows[-1]
                    print(
                        f"{preset}#{seed} res {res} {label}: median {r['median_frechet']:.3g} "
                        f"mean {r['mean_frechet']:.3g} max {r['max_frechet']:.3g} L_c, "
                        f"lock agr {r['lock_agreement']:.2f} ({r['seconds']} s)",
                        flush=True,
                    )
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "hfield_geometry.json", rows, indent=1)
    # summary per preset family x resolution x tip
    print(
        "\n| surface | hfield samples | spacing / L_c | tip | median Frechet | mean | max | "
        "lock agreement |\n|---|---|---|---|---|---|---|---|"
    )
    keys = sorted({(r["preset"], r["resolution"], r["tip"]) for r in rows})
    for p, res, tip in keys:
        sel = [r for r in rows if (r["preset"], r["resolution"], r["tip"]) == (p, res, tip)]
        fr = np.concatenate([r["frechet"] for r in sel])
        print(
            f"| {p} | {res} | {sel[0]['spacing_over_lc']:.3g} | {tip} | "
            f"{np.nanmedian(fr):.3g} | {np.nanmean(fr):.3g} | {np.nanmax(fr):.3g} | "
            f"{np.mean([r['lock_agreement'] for r in sel]):.2f} |"
        )


if __name__ == "__main__":
    main()
