"""Calibration study for the paper's reproductions (issue 3).

Runs the reproductions through the package's public API (``spine_mj.reproduce``,
``spine_mj.theory.streamline``) with the parameters the paper leaves open varied, and writes
``analysis/reports/calibration.md`` plus PNGs beside it. Takes a few minutes on 2 cores::

    .venv/bin/python analysis/calibration.py            # full study
    .venv/bin/python analysis/calibration.py --quick    # smaller scans (a smoke test)

Nothing here re-implements physics: every number comes from the package.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from spine_mj.presets import load_preset
from spine_mj.reproduce import calibrate_single_peak_mu, fractal_hurst, random_gaussian, single_peak
from spine_mj.surfaces import single_gaussian
from spine_mj.theory.streamline import ideal_trajectories, streamlines
from spine_mj.theory.streamline_types import StreamlineParams

OUT = Path(__file__).parent / "reports"
PAPER_RG = {
    "convex_median_ideal": 3.18,
    "convex_median_streamline": 2.87,
    "concave_median_ideal": 3.22,
    "concave_median_streamline": 11.34,
}


def rel(v, ref):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.inf
    return (v - ref) / ref if math.isfinite(v) else math.inf


def fmt(v, nd=3):
    if v is None:
        return "-"
    if isinstance(v, str):
        return v
    return f"{v:.{nd}g}" if math.isfinite(v) else str(v)


def pct(v):
    return "inf" if not math.isfinite(v) else f"{100 * v:+.0f} %"


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


# --------------------------------------------------------------------------- single peak


def study_single_peak(quick):
    mus = np.round(np.arange(1.12, 1.42, 0.04 if quick else 0.02), 3)
    rows, curves = [], {"mu": [], "convex_fine": [], "concave_fine": [], "convex": [], "concave": []}
    for mu in mus:
        n, fig = single_peak(mu=float(mu))
        plt.close(fig)
        curves["mu"].append(mu)
        for k in ("convex_ratio", "concave_ratio"):
            curves[k.split("_")[0] + "_fine"].append(n[k] or np.nan)
            curves[k.split("_")[0]].append(n[k + "_coarse"] or np.nan)
        lock3 = {s["y0"]: s["streamline"] for s in n["concave_starts"]}[-3.0]
        rows.append(
            [
                f"{mu:.2f}",
                fmt(n["convex_ideal_range"]),
                fmt(n["convex_streamline_range"]),
                fmt(n["concave_streamline_range"]),
                fmt(n["convex_ratio"]),
                fmt(n["concave_ratio"]),
                fmt(n["convex_ratio_coarse"]),
                fmt(n["concave_ratio_coarse"]),
                lock3,
            ]
        )
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for a, name, ref in ((ax[0], "convex", 0.833), (ax[1], "concave", 5.667)):
        a.plot(curves["mu"], curves[name + "_fine"], "o-", label="fine scan (0.01, -5..5)")
        a.plot(curves["mu"], curves[name], "s--", label="preset scan (counts)")
        a.axhline(ref, color="k", lw=0.8, label=f"paper {ref}")
        a.axhspan(0.85 * ref, 1.15 * ref, color="0.9")
        a.set_xlabel("mu_s")
        a.set_title(f"{name} streamline / ideal self-lock start range")
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "cal_single_peak.png", dpi=110)
    plt.close(fig)

    # geometry: the convex/concave trade-off at a fixed ideal range (fine scan)
    step = 0.02
    ys = np.arange(-5 + step / 2, 0, step)
    st = np.c_[np.full(ys.size, -3.0), ys]

    def widths(amp, sig, mu):
        p = StreamlineParams(mu=mu, dl=0.01 * sig)
        k = amp * 2 * math.pi * sig * sig
        out = []
        for s in (1, -1):
            surf = single_gaussian(sign=s, k=k, sigma_x=sig, sigma_y=sig)
            if s == 1:
                out.append(ideal_trajectories(surf, st, p, store_paths=False).self_locked.sum() * step)
            out.append(streamlines(surf, st, p, store_paths=False).self_locked.sum() * step)
        return out

    geo = []
    combos = (
        [(2.22, 1.5), (3.0, 1.5)]
        if quick
        else [(1.5, 1.5), (2.22, 1.06), (2.22, 1.5), (2.22, 2.0), (3.0, 1.5), (3.0, 2.0)]
    )
    for amp, sig in combos:
        lo, hi = 0.3, 5.0
        for _ in range(10 if quick else 13):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if widths(amp, sig, mid)[0] < 0.55 else (lo, mid)
        w = widths(amp, sig, hi)
        geo.append(
            [
                fmt(amp),
                fmt(sig),
                f"{amp / sig * math.exp(-0.5):.2f}",
                f"{hi:.3f}",
                fmt(w[0]),
                fmt(w[1] / w[0]),
                fmt(w[2] / w[0]),
                fmt(w[2]),
            ]
        )
    default = single_peak()[0]
    choice = calibrate_single_peak_mu(np.round(np.arange(1.12, 1.4001, 0.02 if quick else 0.005), 3))
    return rows, geo, default, choice


# --------------------------------------------------------------------------- random Gaussian


def rg_row(label, n):
    vals = [n[k] for k in PAPER_RG]
    errs = [rel(n[k], ref) for k, ref in PAPER_RG.items()]
    worst = max(abs(e) for e in errs)
    return worst, [
        label,
        *[fmt(v) for v in vals],
        pct(n["bypass_change"]) if n["bypass_change"] is not None else "-",
        pct(n["trap_change"]) if n["trap_change"] is not None else "-",
        f"{n['convex_self_locked_streamline']}/{n['concave_self_locked_streamline']}",
        pct(worst),
    ]


def study_random(quick):
    runs = 40 if quick else 100
    grid = []
    for ov, ms, sr in ((True, 2.0, (0.5, 1.5)), (False, 1.0, (0.3, 0.6)), (False, 1.5, (0.3, 0.6))):
        for ar in ((0.15, 0.45), (0.2, 0.5), (0.25, 0.55), (0.3, 0.6)):
            grid.append(dict(overlap=ov, min_separation=ms, sigma_range=sr, amplitude_range=ar, k_range=None))
    if quick:
        grid = grid[::3]
    rows = []
    for g in grid:
        n, fig = random_gaussian(n_runs=runs, **g)
        plt.close(fig)
        label = (
            f"{'overlap' if g['overlap'] else 'sep ' + fmt(g['min_separation'])}, "
            f"sigma {g['sigma_range']}, a {g['amplitude_range']}"
        )
        rows.append(rg_row(label, n))
    rows.sort(key=lambda r: r[0])
    # sensitivity around the preset defaults
    sens = []
    variants = [("defaults", {"n_runs": None})]
    for mu in (1.15, 1.2, 1.3, 1.35):
        variants.append((f"mu {mu}", {"mu": mu}))
    variants += [
        ("starts: 100 along one left edge", {"starts": "edge", "n_runs": 100}),
        ("kappa cap 50 in the median", {"kappa_cap": 50.0}),
        ("dl halved", {"dl": None}),
    ]
    for label, over in variants:
        if "dl" in over:
            continue
        n, fig = random_gaussian(**({"n_runs": None} | over))
        if label == "defaults":
            fig.savefig(OUT / "cal_random_gaussian_default.png", dpi=100)
            default = n
        plt.close(fig)
        sens.append(rg_row(label, n))
    return [r[1] for r in rows], [r[1] for r in sens], default


# --------------------------------------------------------------------------- fractal


def study_fractal(quick):
    hursts = [0.65, 0.75, 0.85, 0.95] if quick else [0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95]
    n_surf = 30 if quick else 90
    rep = load_preset("paper-fractal").extras["reproduce"]
    base = float(rep["scale"])
    cases = [("pixel", base * f) for f in ((0.8, 1.0, 1.25) if quick else (0.6, 0.8, 1.0, 1.25, 1.6))]
    cases += [("length", 0.14), ("length", 0.3)]
    rows, curves = [], {}
    for unit, scale in cases:
        n, fig = fractal_hurst(surfaces=n_surf, hursts=hursts, scale=scale, frequency_unit=unit)
        plt.close(fig)
        rates = [e["rate_mean"] for e in n["by_hurst"]]
        curves[(unit, scale)] = rates
        rows.append([unit, fmt(scale), *[f"{r:.2f}" for r in rates]])
    fig, ax = plt.subplots(figsize=(6, 4))
    for (unit, scale), rates in curves.items():
        ax.plot(hursts, rates, "o-" if unit == "pixel" else "x:", label=f"{unit}, scale {scale:.3g}")
    ax.plot([0.65, 0.95], [0.0, 1.0], "k--", lw=0.8, label="paper (trend)")
    ax.set_xlabel("Hurst index H")
    ax.set_ylabel("self-lock rate")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "cal_fractal_scale.png", dpi=110)
    plt.close(fig)
    t = time.perf_counter()
    full, fig = fractal_hurst(quick=quick)
    wall = time.perf_counter() - t
    fig.savefig(OUT / "cal_fractal_default.png", dpi=100)
    plt.close(fig)
    return hursts, n_surf, rows, full, wall


# --------------------------------------------------------------------------- hypotheses (issue 3)

MED = ("convex_median_ideal", "convex_median_streamline", "concave_median_ideal", "concave_median_streamline")
K_FAMILY = {"overlap": True, "sigma_range": (0.5, 1.5)}


def rg_line(label, n):
    return [
        label,
        *[fmt(float(n[k]) if n[k] != "inf" else math.inf) for k in MED],
        pct(n["bypass_change"]) if n["bypass_change"] is not None else "-",
        pct(n["trap_change"]) if n["trap_change"] is not None else "-",
        f"{n['convex_self_locked_streamline']}/{n['concave_self_locked_streamline']}",
        pct(max(abs(rel(n[k], PAPER_RG[k])) for k in MED)),
    ]


def _h1_max_kappa_convention(quick, runs):
    """H1: the max-kappa convention and its dl dependence."""
    # H1: max-kappa convention and its dl dependence on a family where > 50 % of the concave
    # streamlines self-lock (for the defaults the convention changes nothing: few self-lock)
    h1 = []
    fams = [
        ("preset family (k on [0, 0.7 pi])", {}),
        ("k = pi/2 for all peaks", dict(K_FAMILY, k_range=(math.pi / 2, math.pi / 2))),
        (
            "sep 1.5, sigma (0.3, 0.6), a (0.3, 0.6)",
            dict(
                overlap=False,
                min_separation=1.5,
                sigma_range=(0.3, 0.6),
                amplitude_range=(0.3, 0.6),
                k_range=None,
            ),
        ),
    ]
    dls = (0.015, 0.06) if quick else (0.0075, 0.015, 0.03, 0.06, 0.12, 0.24)
    for label, g in fams:
        for conv in ("inf", "finite"):
            for dl in dls if conv == "finite" else (0.015,):
                n, fig = random_gaussian(n_runs=runs, max_kappa=conv, dl=dl, **g)
                plt.close(fig)
                h1.append(rg_line(f"{label}; {conv}; dl {dl}", n))
    return h1


def _h2_start_point(quick, runs):
    """H2: where the trajectories start."""
    # H2: start point
    h2 = []
    for off in (1e-9, 0.05, 0.5, 1.0):
        n, fig = random_gaussian(n_runs=runs, x0_offset=off)
        plt.close(fig)
        h2.append(
            [
                f"x0 = -10 + {off:g}",
                f"{n['convex_starts_in_slip']}/{n['concave_starts_in_slip']}",
                *rg_line("", n)[1:],
            ]
        )
    n, fig = random_gaussian(n_runs=runs, starts="edge")
    plt.close(fig)
    h2.append(
        [
            "one surface, 100 starts along the left edge",
            f"{n['convex_starts_in_slip']}/{n['concave_starts_in_slip']}",
            *rg_line("", n)[1:],
        ]
    )
    return h2


def _h3_single_peak_normalization(quick):
    """H3: random fields with the single peak's normalization."""
    # H3: random-field families with the single peak's normalization a = k / (2 pi sigma^2)
    h3 = []
    pooled = 100 if quick else 500
    kfams = [
        ("sigma (0.5, 1.5), k = pi/4", dict(K_FAMILY, k_range=(math.pi / 4,) * 2)),
        ("sigma (0.5, 1.5), k = 3 pi/8", dict(K_FAMILY, k_range=(3 * math.pi / 8,) * 2)),
        ("sigma (0.5, 1.5), k = pi/2", dict(K_FAMILY, k_range=(math.pi / 2,) * 2)),
        ("sigma (0.5, 1.5), k = 10 pi (paper's k)", dict(K_FAMILY, k_range=(10 * math.pi,) * 2)),
        (
            "sigma 1.5, k = 10 pi (paper's single peak x 100)",
            dict(K_FAMILY, sigma_range=(1.5, 1.5), k_range=(10 * math.pi,) * 2),
        ),
        ("sigma (1, 2), k = 1.5 pi", dict(K_FAMILY, sigma_range=(1.0, 2.0), k_range=(1.5 * math.pi,) * 2)),
        ("sigma (1, 2), k on [0, 3 pi]", dict(K_FAMILY, sigma_range=(1.0, 2.0), k_range=(0.0, 3 * math.pi))),
        (
            "sigma (0.3, 0.6), k on [0, 3 pi/16]",
            dict(K_FAMILY, sigma_range=(0.3, 0.6), k_range=(0.0, 3 * math.pi / 16)),
        ),
    ]
    for khi in (0.7,) if quick else (0.6, 0.65, 0.7, 0.75, 0.8):
        kfams.append((f"sigma (0.5, 1.5), k on [0, {khi} pi]", dict(K_FAMILY, k_range=(0.0, khi * math.pi))))
    for label, g in kfams:
        n, fig = random_gaussian(n_runs=pooled, **g)
        plt.close(fig)
        h3.append(rg_line(f"{label} ({pooled} runs)", n))
    return h3


def _median_spread(quick, runs):
    """Batch-to-batch scatter of 100-run medians."""
    # batch-to-batch scatter of 100-run medians (the paper's sample size)
    spread = []
    for label, g in (
        ("preset family", {}),
        (
            "previous defaults (sep 1.5, sigma (0.3, 0.6), a (0.15, 0.45))",
            dict(
                overlap=False,
                min_separation=1.5,
                sigma_range=(0.3, 0.6),
                amplitude_range=(0.15, 0.45),
                k_range=None,
            ),
        ),
    ):
        for seed in (1, 1001) if quick else (1, 1001, 2001, 3001, 4001):
            n, fig = random_gaussian(n_runs=runs, seed=seed, **g)
            plt.close(fig)
            spread.append(rg_line(f"{label}, seeds {seed}..{seed + runs - 1}", n))
    return spread


def _h4_fractal_lock_point(quick):
    """H4: fractal shares by where the self-lock point is classified."""
    # H4: fractal shares: lock point vs one step before, dl, and ideal trajectories
    h4 = []
    hs = [0.65, 0.8, 0.95]
    nsurf = 60 if quick else 150
    cases = [
        (dl, lp, "streamline")
        for dl in ((0.02, 0.01) if quick else (0.04, 0.02, 0.01, 0.005))
        for lp in ("lock", "before")
    ]
    cases.append((0.01, "lock", "ideal"))
    for dl, lp, tr in cases:
        n, fig = fractal_hurst(surfaces=nsurf, hursts=hs, dl=dl, lock_point=lp, trajectory=tr)
        plt.close(fig)
        for e in n["by_hurst"]:
            h4.append(
                [
                    tr,
                    lp,
                    dl,
                    e["hurst"],
                    fmt(e["rate_mean"], 2),
                    *[
                        fmt(e[k], 2)
                        for k in (
                            "sect_concave_mean",
                            "hess_concave_mean",
                            "hess_saddle_mean",
                            "hess_convex_mean",
                        )
                    ],
                ]
            )
    return (nsurf, h4)


def study_hypotheses(quick):
    """H1-H3 on random Gaussian surfaces, H4 on fractal surfaces."""
    runs = 40 if quick else 100
    return {
        "h1": _h1_max_kappa_convention(quick, runs),
        "h2": _h2_start_point(quick, runs),
        "h3": _h3_single_peak_normalization(quick),
        "spread": _median_spread(quick, runs),
        "h4": _h4_fractal_lock_point(quick),
    }


# --------------------------------------------------------------------------- report


def main():  # the report's text, kept whole so that it reads as the report it writes
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller scans (smoke test)")
    quick = ap.parse_args().quick
    OUT.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    sp_rows, sp_geo, sp, sp_choice = study_single_peak(quick)
    print(f"single peak done {time.perf_counter() - t0:.0f} s", flush=True)
    rg_rows, rg_sens, rg = study_random(quick)
    print(f"random Gaussian done {time.perf_counter() - t0:.0f} s", flush=True)
    hursts, n_surf, fr_rows, fr, fr_wall = study_fractal(quick)
    print(f"fractal done {time.perf_counter() - t0:.0f} s", flush=True)
    hy = study_hypotheses(quick)
    print(f"hypotheses done {time.perf_counter() - t0:.0f} s", flush=True)
    rg_head = [
        "variant",
        "cvx ideal",
        "cvx stream",
        "ccv ideal",
        "ccv stream",
        "bypass",
        "trap",
        "locked",
        "worst",
    ]

    eng = {
        name: load_preset(name).extras
        for name in ("paper-single-peak", "paper-random-convex", "paper-fractal")
    }
    md = [
        f"# Calibration study (issue 3){' -- QUICK RUN' if quick else ''}",
        "",
        "Generated by `analysis/calibration.py` (do not edit by hand). Every number comes from",
        "`spine_mj.reproduce` with the parameter named in the row changed; everything else is",
        "the preset default (`surfaces/paper-*.toml`, tables `[engagement]` and `[reproduce]`).",
        f"Wall time {time.perf_counter() - t0:.0f} s.",
        "",
        "## 1. Single peak / valley (Figs. 3-4)",
        "",
        "Geometry fixed by the paper (k = 10 pi, sigma = 1.5, amplitude 2.22 with the",
        "normalization of docs/physics.md §3); mu_s is the only free parameter. Ranges are widths of",
        "the self-locking start set y0 at x0 = -3. *fine* (the primary measurement): a 0.01 scan",
        "of -5..5; *coarse count*: the preset's y0 scan "
        f"({sp['y0_range_coarse']}, step {sp['y0_step_coarse']}, end points included), ratio of",
        "counts. The paper's 83.3 % = 5/6 and 566.7 % = 34/6 are ratios of small integers",
        "with the same denominator, which is what a count on a coarse scan gives (6 ideal",
        "self-locking starts); a fine scan cannot produce them except by coincidence.",
        "",
        "**mu_s by a stated criterion** (`spine_mj.reproduce.calibrate_single_peak_mu`): the mu_s",
        "on a 0.005 grid over 1.12-1.40 that minimizes the larger relative error of the two",
        f"fine-scan ratios against the paper's. It picks mu_s = {sp_choice['best_mu']:g}, where both",
        f"ratios miss by up to {100 * sp_choice['best_error']:.0f} %.",
        "",
        "**The conflict, plainly:** no mu_s meets both of the paper's ratios within 15 % on the",
        "fine scan: where the convex ratio rises towards 0.833 the concave one falls far below",
        "5.667, and the reverse. The concave start y0 = -3 "
        + (
            "never self-locks for any mu_s in 1.12-1.40"
            if not sp_choice["y0_minus_3_locks_anywhere"]
            else "self-locks only for some mu_s"
        )
        + ", though the paper's Fig. 4 shows it trapped.",
        "",
        table(
            [
                "mu",
                "ideal range",
                "convex stream range",
                "concave stream range",
                "convex ratio (fine)",
                "concave ratio (fine)",
                "convex ratio (coarse count)",
                "concave ratio (coarse count)",
                "concave y0=-3",
            ],
            sp_rows,
        ),
        "",
        "![single peak](cal_single_peak.png)",
        "",
        "Geometry check (not used for the defaults; the paper states k and sigma): mu chosen",
        "so the ideal half range is 0.55 (fine scan of y0 < 0), ratios then follow.",
        "",
        table(
            [
                "amplitude",
                "sigma",
                "max slope",
                "mu",
                "ideal half range",
                "convex ratio",
                "concave ratio",
                "concave half range",
            ],
            sp_geo,
        ),
        "",
        "## 2. Random Gaussian surfaces (Fig. 5)",
        "",
        "Medians of the maximum kappa (paper: convex 3.18 ideal / 2.87 streamline, concave",
        "3.22 / 11.34). Self-locked trajectories rank as +inf unless a cap is set; never-engaged",
        "ones count as 0. `worst` = largest relative deviation of the four medians. Columns",
        "`locked` = self-locked streamlines convex/concave out of the runs.",
        "",
        f"Grid (mu = preset {eng['paper-random-convex']['engagement']['mu']}, "
        f"{40 if quick else 100} runs each), best first:",
        "",
        table(
            [
                "surface",
                "cvx ideal",
                "cvx stream",
                "ccv ideal",
                "ccv stream",
                "bypass",
                "trap",
                "locked",
                "worst",
            ],
            rg_rows,
        ),
        "",
        "Sensitivity around the preset defaults:",
        "",
        table(
            [
                "variant",
                "cvx ideal",
                "cvx stream",
                "ccv ideal",
                "ccv stream",
                "bypass",
                "trap",
                "locked",
                "worst",
            ],
            rg_sens,
        ),
        "",
        "![random Gaussian](cal_random_gaussian_default.png)",
        "",
        "## 3. Fractal surfaces (Figs. 7E, 9)",
        "",
        f"Self-lock rate against H ({n_surf} surfaces per H here). `pixel`: fixed spectral",
        "prefactor with frequencies in cycles per pixel (all |f| <= 0.5 per axis, so the",
        "amplitude |f|^-(H+1) grows with H at every frequency and so does the roughness);",
        "`length`: frequencies in cycles per unit length on the 20-unit domain (most",
        "frequencies above 1, so slopes barely change with H).",
        "",
        table(["frequency unit", "scale", *[f"H={h}" for h in hursts]], fr_rows),
        "",
        "![fractal scale](cal_fractal_scale.png)",
        "",
        f"Defaults ({fr['surfaces_per_hurst']} surfaces per H, {fr['groups']} groups, "
        f"{fr_wall:.0f} s on 2 workers; mean +- sd over groups):",
        "",
        table(
            [
                "H",
                "self-lock rate",
                "sectional concave",
                "Hessian concave",
                "Hessian saddle",
                "Hessian convex",
            ],
            [
                [
                    e["hurst"],
                    f"{fmt(e['rate_mean'], 2)} +- {fmt(e['rate_sd'], 2)}",
                    fmt(e["sect_concave_mean"], 2),
                    fmt(e["hess_concave_mean"], 2),
                    fmt(e["hess_saddle_mean"], 2),
                    fmt(e["hess_convex_mean"], 2),
                ]
                for e in fr["by_hurst"]
            ],
        ),
        "",
        "![fractal default](cal_fractal_default.png)",
        "",
        "## 4. Hypotheses about what the paper did",
        "",
        "### H1. Max kappa over the finite values (self-lock step excluded)",
        "",
        "`finite`: a self-locked path scores the largest kappa over its engaged points, i.e.",
        "the last one before the self-lock boundary, where kappa diverges as A -> 0; `inf`:",
        "self-locked = inf (ranked highest). The two differ only when a median falls among",
        "self-locked paths; the `finite` value then scales roughly as 1/dl (halving dl about",
        "doubles it), so it is a property of the step, not of the surface. A median near 11",
        "needs dl ~ 0.2 (about 0.2-0.5 sigma), 20-50 x the paper's dl ~ 0.01 sigma.",
        "",
        table(rg_head, hy["h1"]),
        "",
        "### H2. Start point (one surface per run, one start on y = 0 at the left edge)",
        "",
        "The implementation runs the ideal trajectory and the streamline from the same start",
        "(x0 = -10 + offset, y0 = 0), one new surface per run, as the paper's Fig. 5A/D and",
        "'100 simulations' read. `slip starts` = starts in the slip region (convex/concave).",
        "",
        table(["start", "slip starts", *rg_head[1:]], hy["h2"]),
        "",
        "### H3. Random-field families with the single peak's normalization",
        "",
        "a = k / (2 pi sigma^2) per peak (Figs. 3-4 use k = 10 pi, sigma = 1.5), overlapping",
        "centres. With the paper's k = 10 pi every family self-locks almost everywhere",
        "(medians inf, or 0 when starts already sit in the self-lock region); k must be",
        "10-40 x smaller for medians near 3.",
        "",
        table(rg_head, hy["h3"]),
        "",
        "Scatter of 100-run medians (the paper's sample size) between disjoint seed batches:",
        "",
        table(rg_head, hy["spread"]),
        "",
        "### H4. Fractal shares: where the self-lock point is classified",
        "",
        f"{hy['h4'][0]} surfaces per H. `lock`: the first self-lock point the trajectory",
        "reaches; `before`: the engaged point one step earlier; `ideal`: the same statistics",
        "for ideal trajectories (the paper's Fig. 9 uses streamlines).",
        "",
        table(
            [
                "trajectory",
                "point",
                "dl",
                "H",
                "self-lock rate",
                "sectional concave",
                "Hessian concave",
                "Hessian saddle",
                "Hessian convex",
            ],
            hy["h4"][1],
        ),
        "",
        "## Defaults chosen",
        "",
        f"- single peak: mu_s = {sp['mu']} (the criterion above): fine scan convex "
        f"{fmt(sp['convex_ratio'])} (paper 0.833), concave {fmt(sp['concave_ratio'])} (paper 5.667); "
        f"coarse count {fmt(sp['convex_ratio_coarse'])} / {fmt(sp['concave_ratio_coarse'])}.",
        f"- random Gaussian: {eng['paper-random-convex']['reproduce']}, generator "
        f"{dict(load_preset('paper-random-convex').params)}: medians "
        f"{fmt(rg['convex_median_ideal'])} / {fmt(rg['convex_median_streamline'])} / "
        f"{fmt(rg['concave_median_ideal'])} / {fmt(rg['concave_median_streamline'])}.",
        f"- fractal: {eng['paper-fractal']['reproduce']}.",
        "",
    ]
    (OUT / "calibration.md").write_text("\n".join(md))
    print(f"wrote {OUT / 'calibration.md'}")


if __name__ == "__main__":
    main()
