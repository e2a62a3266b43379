"""Figures and ``report.md`` of the validation suite (:mod:`spine_mj.validate`).

The report reads the studies' typed results (one section and one figure per study) and
the summary that ``validation.json`` holds, so that both say the same numbers.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from spine_mj.compare import MISS_REASONS
from spine_mj.errors import atomic_output
from spine_mj.plotting import (
    DIVERGING_CMAP,
    PATH_COLORS,
    THRESHOLD_COLOR,
    height_mappable,
    new_figure,
    path_overlay_figure,
    protocol_color,
    save_figure,
    shared_height_norm,
    sig,
    styled,
)
from spine_mj.presets import list_presets, make_surface
from spine_mj.sweep.analyses.compare import MISS_CHECKPOINTS
from spine_mj.sweep.store import load_runs
from spine_mj.templates import render
from spine_mj.validate.boundary import BoundaryCurve, BoundaryResult
from spine_mj.validate.fractal_lock import SERIES, FractalLockResult
from spine_mj.validate.paths import stored_paths
from spine_mj.validate.plans import FRECHET_TARGET, OUTCOME_TARGET, STATIC_TARGET
from spine_mj.validate.quasistatic_limit import QuasistaticLimitResult
from spine_mj.validate.sandpaper import SandpaperResult
from spine_mj.validate.static_map import StaticMapResult
from spine_mj.validate.stick_slip import StickSlipResult
from spine_mj.validate.stiffness_map import StiffnessMapResult
from spine_mj.validate.stiffness_map_report import ccdf_figure, map_figure, map_sections
from spine_mj.validate.verdicts_report import platform_line, verdicts_section

__all__ = ["write_report"]


def _f(v, digits=3) -> str:
    """A table cell: numbers to ``digits`` significant digits, NaN and None as ``-``."""
    try:
        text = sig(v, digits)
    except (TypeError, ValueError):
        return str(v)
    return "-" if text in ("nan", "-") else text


def _table(rows: list[dict], cols: list[str], names: list[str] | None = None) -> str:
    names = names or cols
    out = ["| " + " | ".join(names) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(_f(r.get(c)) for c in cols) + " |")
    return "\n".join(out)


@styled
def _static_figure(st: StaticMapResult, path: Path) -> Path | None:
    engines = list(st.per_engine)
    if not engines:
        return None
    fig = new_figure(figsize=(5 * len(engines), 4.2), constrained_layout=True)
    axes = fig.subplots(1, len(engines), squeeze=False)[0]
    for ax, label in zip(axes, engines):
        rows = [r for r in st.rows if r["engine"] == label]
        ax.axhspan(0.95, 1.05, color="0.9", label="+-5 % (target)")
        for az in sorted({r["azimuth_deg"] for r in rows}):
            sel = sorted((r for r in rows if r["azimuth_deg"] == az), key=lambda r: r["slope_deg"])
            ax.plot(
                [r["slope_deg"] for r in sel], [r["ratio"] for r in sel], "o-", label=f"azimuth {sig(az)} deg"
            )
            for r in sel:
                if r["region"] != "engaged":
                    mark = {"self_lock": "^", "slip": "v"}[r["region"]]
                    ax.plot(
                        r["slope_deg"], 1.0, mark, color="g" if r["region_agrees"] else "r", ms=9, mfc="none"
                    )
        ax.plot([], [], "^", color="g", mfc="none", label="self-lock / slip plane: MuJoCo agrees")
        ax.plot([], [], "v", color="r", mfc="none", label="... MuJoCo disagrees")
        ax.set(xlabel="slope angle [deg]", ylabel="breakaway ratio kappa_mj / kappa [1]", title=label)
        ax.legend()
    fig.suptitle(f"Static probe on inclined planes, mu = {sig(st.mu)}")
    return save_figure(fig, path)


@styled
def _paths_figure(lim: QuasistaticLimitResult, path: Path) -> Path | None:
    """Paths at the lowest I_e over the peak / valley (shared diverging height scale)."""
    presets = list(lim.paths)
    if not presets:
        return None
    surfaces = {p: make_surface(p) for p in presets}
    norm = shared_height_norm([{"surface": s} for s in surfaces.values()])
    fig = new_figure(figsize=(5.4 * len(presets) + 0.8, 5), constrained_layout=True)
    axes = fig.subplots(1, len(presets), squeeze=False)[0]
    field = None
    for ax, preset in zip(axes, presets):
        x0, x1, y0, y1 = surfaces[preset].bounds
        xs, ys = np.linspace(x0, x1, 161), np.linspace(y0, y1, 161)
        field = ax.contourf(
            xs, ys, surfaces[preset].height(xs[None, :], ys[:, None]), 15, cmap=DIVERGING_CMAP, norm=norm
        )
        for i, p in enumerate(lim.paths[preset]):
            first = i == 0
            ax.plot(
                *p.smooth.T,
                color=PATH_COLORS["streamline"],
                lw=1.5,
                label="streamline (smooth surface)" if first else None,
            )
            ax.plot(
                *p.tri.T,
                color=PATH_COLORS["facets"],
                ls="--",
                lw=1,
                label="streamline (MuJoCo's hfield facets)" if first else None,
            )
            if p.mujoco.shape[0]:
                ax.plot(
                    *p.mujoco.T,
                    color=PATH_COLORS["mujoco"],
                    lw=0.9,
                    label="MuJoCo (spring drive)" if first else None,
                )
        ax.set(xlim=(x0, x1), ylim=(y0, y1), xlabel="x [surface units]", ylabel="y [surface units]")
        ax.set(aspect="equal", title=f"{preset}, I_e = {sig(lim.lowest_ie)}")
        ax.legend(loc="upper left")
    fig.colorbar(
        height_mappable(field),
        ax=list(axes),
        label="surface height [surface units] (peak red, valley blue)",
    )
    return save_figure(fig, path)


def _star_for_figure(star: dict) -> dict | None:
    """The bracketed I_e* to draw: the headline one, else the departure criterion's."""
    if star.get("kind") == "bracketed":
        return star
    dep = star.get("by_criterion", {}).get("departure")
    return dep if dep and dep.get("kind") == "bracketed" else None


@styled
def _boundary_figure(bnd: BoundaryResult, path: Path) -> Path | None:
    if not bnd.curves:
        return None
    fig = new_figure(figsize=(12, 4.6), constrained_layout=True)
    a1, a2 = fig.subplots(1, 2)
    for proto, c in bnd.curves.items():
        color = protocol_color(proto)
        lab = proto if proto != "ramp" else "ramp (equivalent I_e)"
        a1.semilogx(c.ie, c.agreement, "o-", color=color, label=lab)
        used = bnd.ie_star[proto].get("ie_used", c.ie)
        off = [i for i, v in enumerate(c.ie) if not np.isclose(used, v).any()]
        if off:  # points that take no part in I_e* (a capped ramp covering < half the path)
            a1.plot(
                np.asarray(c.ie)[off],
                np.asarray(c.agreement)[off],
                "o",
                ms=10,
                mfc="white",
                mec=color,
                zorder=0,
                label=f"{proto}: not used for I_e* (path coverage < 50 %)",
            )
        a2.loglog(
            c.ie, np.maximum(np.asarray(c.frechet, float), 1e-5), "o-", color=color, label=f"{proto}: mean"
        )
        a2.loglog(
            c.ie,
            np.maximum(np.asarray(c.median_frechet, float), 1e-5),
            "s--",
            color=color,
            label=f"{proto}: median",
        )
        s = _star_for_figure(bnd.ie_star[proto])
        if s is not None:
            for ax in (a1, a2):
                ax.axvspan(
                    s["low"],
                    s["high"],
                    alpha=0.12,
                    color=color,
                    label=f"{proto}: I_e* bracket [{sig(s['low'])}, {sig(s['high'])}]" if ax is a1 else None,
                )
                ax.axvline(
                    s["value"],
                    ls=":",
                    color=color,
                    label=f"{proto}: I_e* = {sig(s['value'])}" if ax is a1 else None,
                )
    a1.axhline(
        OUTCOME_TARGET,
        color=THRESHOLD_COLOR,
        lw=1,
        ls="--",
        label=f"target: agreement >= {sig(OUTCOME_TARGET)}",
    )
    a2.axhline(
        FRECHET_TARGET,
        color=THRESHOLD_COLOR,
        lw=1,
        ls="--",
        label=f"target: deviation <= {sig(FRECHET_TARGET)} L_c",
    )
    a1.set(xlabel="inertia number I_e [1]", ylabel="runs that agree [fraction]", ylim=(-0.05, 1.05))
    a2.set(xlabel="inertia number I_e [1]", ylabel="Frechet deviation [L_c] (ramp: prefix)")
    a1.legend(fontsize=7)
    a2.legend(fontsize=7)
    fig.suptitle("Agreement with the quasistatic streamline against I_e (colour = drive protocol)")
    return save_figure(fig, path)


def _stiffness_labels(ss: StickSlipResult) -> dict:
    """``(ie, k [N/m])`` of the traces -> stiffness in F_p / L_c from the rows (matched by
    rank within each I_e: the two units differ by one positive factor)."""
    out = {}
    for ie in {k[0] for k in ss.traces}:
        n_m = sorted(k for i, k in ss.traces if i == ie)
        fp = sorted(r["stiffness_fp_per_lc"] for r in ss.rows if np.isclose(r["ie"], ie))
        out.update({(ie, a): b for a, b in zip(n_m, fp)} if len(n_m) == len(fp) else {})
    return out


@styled
def _stick_figure(ss: StickSlipResult, path: Path) -> Path | None:
    if not ss.traces:
        return None
    fig = new_figure(figsize=(11, 4.2), constrained_layout=True)
    ax = fig.subplots()
    labels = _stiffness_labels(ss)
    for (ie, k), (t, f) in sorted(ss.traces.items()):
        kl = f"{sig(labels[(ie, k)])} F_p/L_c" if (ie, k) in labels else f"{sig(k)} N/m"
        ax.plot(t / max(t[-1], 1e-12), f, lw=0.8, label=f"I_e = {sig(ie)}, k = {kl}")
    ax.set(
        xlabel="time / run duration [1]",
        ylabel="drive force / F_p [1]",
        title=f"Spring drive on {ss.surface} (first start)",
    )
    ax.legend()
    return save_figure(fig, path)


@styled
def _sand_figure(sp: SandpaperResult, path: Path) -> Path | None:
    grits = [g for g in sp.paths if sp.paths[g]]
    if not grits:
        return None
    fig = new_figure(figsize=(5 * len(grits), 7), constrained_layout=True)
    axes = fig.subplots(2, len(grits), squeeze=False)
    for j, g in enumerate(grits):
        for x, y, _t, f in sp.paths[g]:
            axes[0, j].plot(x * 1e3, (y - y[0]) * 1e6, lw=0.8)
            axes[1, j].plot(x * 1e3, f, lw=0.6)
        axes[0, j].set(title=f"{g}: path", xlabel="x [mm]", ylabel="lateral excursion y - y0 [um]")
        axes[1, j].set(xlabel="x [mm]", ylabel="drive force / F_p [1]")
    return save_figure(fig, path)


#: Legend labels of the fractal study's series (:data:`spine_mj.validate.fractal_lock.SERIES`).
def _fractal_labels(fr: FractalLockResult) -> dict[str, str]:
    return {
        "streamline": "streamline (smooth surface, dilated by the tip)",
        "facets": "streamline (MuJoCo's facets, dilated by the tip)",
        "mujoco_corner": f"MuJoCo, spring, I_e = {sig(fr.corner_ie)}",
        "mujoco_dynamic": f"MuJoCo, spring, I_e = {sig(fr.dynamic_ie)}",
    }


@styled
def _fractal_figure(fr: FractalLockResult | None, path: Path) -> Path | None:
    """Self-lock rate against H, one series per counter, Wilson intervals as error bars
    (series side by side in H so that their bars do not hide each other)."""
    if fr is None or not fr.rows:
        return None
    fig = new_figure(figsize=(6.4, 4.4), constrained_layout=True)
    ax = fig.subplots()
    labels = _fractal_labels(fr)
    present = [s for s in SERIES if any(f"rate_{s}" in r for r in fr.rows)]
    hs = np.array([r["hurst"] for r in fr.rows])
    width = 0.006
    for j, series in enumerate(present):
        rate = np.array([r.get(f"rate_{series}", np.nan) for r in fr.rows], float)
        lo = np.array([r.get(f"ci_low_{series}", np.nan) for r in fr.rows], float)
        hi = np.array([r.get(f"ci_high_{series}", np.nan) for r in fr.rows], float)
        x = hs + (j - (len(present) - 1) / 2) * width
        ax.errorbar(x, rate, yerr=[rate - lo, hi - rate], fmt="o-", capsize=3, label=labels[series])
    ax.set(
        xlabel="Hurst exponent H [1]",
        ylabel="self-locked runs [fraction]",
        ylim=(-0.05, 1.05),
        title=f"Self-lock rate against H, {fr.surfaces_per_hurst} fractal surfaces per H "
        f"(bars: {sig(100 * fr.confidence)} % Wilson intervals)",
    )
    ax.legend(loc="upper left")
    return save_figure(fig, path)


#: What each plan is, for the report's first lines.
PLAN_NOTES = {
    "smoke": "the seconds-long test plan: two planes, one family with two starts, two I_e values; "
    "its numbers only show that the pipeline runs",
    "quick": "the quick plan (`spine-mj validate --quick`, `make demo`): few starts, six I_e values, "
    "coarse hfields; its agreement numbers are noisier and usually lower than the full plan's",
    "full": "the full plan (`spine-mj validate`), the one the README's headline numbers come from",
}


def write_report(
    out: Path,
    result: dict,
    *,
    static: StaticMapResult,
    limit: QuasistaticLimitResult,
    boundary: BoundaryResult,
    stick: StickSlipResult,
    sand: SandpaperResult,
    fractal: FractalLockResult | None = None,
    kmap: StiffnessMapResult | None = None,
) -> Path:
    """Write the figures under ``out/figures`` and ``out/report.md``; returns the report path.

    ``result`` is the content of ``validation.json`` (plan, static error, engine settings,
    timings); the studies' results give the tables and figures. The report links only
    figures that were written (a study with nothing to draw has no figure).
    """
    out = Path(out)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    drawn = {
        "static": _static_figure(static, figs / "static_map.png"),
        "limit": _paths_figure(limit, figs / "limit_paths.png"),
        "boundary": _boundary_figure(boundary, figs / "boundary.png"),
        "overlays": _overlay_figure(out, figs / "boundary_paths.png"),
        "stick": _stick_figure(stick, figs / "stick_slip.png"),
        "sand": _sand_figure(sand, figs / "sandpaper.png"),
        "fractal": _fractal_figure(fractal, figs / "fractal_lock_rate.png"),
        "kmap": map_figure(kmap, figs / "ie_k_map.png") if kmap is not None else None,
        "slip_ccdf": ccdf_figure(kmap, figs / "slip_ccdf.png") if kmap is not None else None,
    }
    figures = {
        k: (p.relative_to(out).as_posix() if p is not None and p.is_file() else None)
        for k, p in drawn.items()
    }
    plan = result["plan"]
    text = render(
        "validation_report.md.j2",
        plan=plan,
        plan_note=PLAN_NOTES.get(plan, f"the plan {plan!r}"),
        figures=figures,
        headline=_headline(result, boundary),
        targets={"outcome": OUTCOME_TARGET, "frechet": FRECHET_TARGET, "static": STATIC_TARGET},
        boundary="\n".join(_boundary_section(boundary)),
        static="\n".join(_static_section(static, result)),
        limit="\n".join([*_limit_section(limit, boundary), *platform_line(result.get("platform"))]),
        stick="\n".join(_stick_section(stick)),
        sand="\n".join(_sand_section(sand)),
        fractal="\n".join(_fractal_section(fractal)),
        kmap=map_sections(kmap, _table, _f),
        engine_settings=json.dumps(result["engine_settings"], indent=2, default=str),
        timings=", ".join(f"{k} {sig(v)}" for k, v in result["timings_s"].items()),
    )
    path = out / "report.md"
    with atomic_output(path) as tmp:
        tmp.write_text(text)
    return path


def _headline(result: dict, boundary: BoundaryResult) -> list[str]:
    """One line per protocol: its I_e* (or why there is none)."""
    lines = []
    for proto, s in boundary.ie_star.items():
        if s.get("valid") is False:
            lines.append(f"{proto}: I_e* not measured ({s.get('note', '')})")
            continue
        for star in (s, s.get("by_criterion", {}).get("departure")):
            if not star:
                continue
            crit = star.get("criterion", "")
            if star["kind"] == "bracketed":
                value, low, high = (sig(star[k]) for k in ("value", "low", "high"))
                lines.append(f"{proto} ({crit}): I_e* = {value} in [{low}, {high}]")
            elif star["kind"] == "above":
                lines.append(
                    f"{proto} ({crit}): I_e* > {sig(star['low'])} (agreement holds on the whole grid)"
                )
            else:
                lines.append(f"{proto} ({crit}): I_e* < {sig(star['high'])} (no agreement at the lowest I_e)")
    return lines


def _overlay_figure(out: Path, path: Path) -> Path | None:
    """MuJoCo paths over the streamline at the lowest and highest I_e of the boundary
    study's spring sweeps (``out/sweeps/boundary/spring-*``); None when there are none."""
    panels = []
    for store in sorted((out / "sweeps" / "boundary").glob("spring-*")):
        if not (store / "manifest.json").is_file():
            continue
        df = load_runs(store)
        mj = df[(df.analysis == "mujoco") & (df.status == "ok")]
        comp = df[(df.analysis == "compare") & (df.status == "ok")].set_index(["case_id", "start"])
        if mj.empty:
            continue
        preset = str(mj["surface"].iloc[0]).split("#")[0]
        surface = make_surface(preset) if preset in list_presets() else None
        for ie in sorted({mj["ie"].min(), mj["ie"].max()}):
            case_id = mj.loc[mj["ie"] == ie, "case_id"].iloc[0]
            starts = sorted(mj.loc[mj["case_id"] == case_id, "start"].astype(int))[:3]
            qs = stored_paths(store, case_id, "quasistatic")
            mp = stored_paths(store, case_id, "mujoco")
            pairs = [(qs[s], mp.get(s, np.zeros((0, 2)))) for s in starts if s in qs]
            n_agree = sum(bool(comp["agree"].get((case_id, s), False)) for s in starts)
            title = f"{preset}, spring, I_e = {sig(ie)}: {n_agree}/{len(starts)} agree"
            panels.append({"title": title, "paths": pairs, "surface": surface})
    if not panels:
        return None
    return save_figure(path_overlay_figure(panels), path)


def _static_section(static: StaticMapResult, result: dict) -> list[str]:
    return [
        "## Static breakaway ratio on inclined planes",
        "",
        f"mu = {static.mu:g}; probe ramp at I_e = 0.01; kappa from Eqs. 1-3.",
        "",
        _table(
            [{"engine": k, **v} for k, v in static.per_engine.items()],
            [
                "engine",
                "engaged_planes",
                "engaged_breakaways",
                "max_rel_error",
                "mean_rel_error",
                "region_agreement",
            ],
        ),
        "",
        f"`static_kappa_max_rel_error` (engaged, default settings) = "
        f"{_f(result['static_kappa_max_rel_error'])} (target <= 0.05).",
        "",
        "<details><summary>per plane</summary>",
        "",
        _table(
            static.rows,
            [
                "engine",
                "slope_deg",
                "azimuth_deg",
                "region",
                "kappa",
                "kappa_mj",
                "ratio",
                "end_reason",
                "region_agrees",
            ],
        ),
        "",
        "</details>",
        "",
    ]


def _stalled_note(limit: QuasistaticLimitResult) -> list[str]:
    """A sentence on the reference streamlines that stalled in a groove, where there are any."""
    stalled = {k: v["reference_stalled"] for k, v in limit.families.items() if v.get("reference_stalled")}
    if not stalled:
        return []
    counts = ", ".join(f"{k} {n} of {limit.families[k]['runs']}" for k, n in stalled.items())
    return [
        f"Reference streamlines that stalled ({counts}): no net progress even with the step "
        "cut to 1/1024 of dl (the step control of docs/physics.md §2), a point that neither "
        "one contact nor two (the crease rule, §4) can leave or rest on. These runs count as "
        "disagreements.",
        "",
    ]


def _misses_note(limit: QuasistaticLimitResult) -> list[str]:
    """Why the runs that the engine finished disagree, per family, where any do."""
    lines = []
    for fam, v in limit.families.items():
        parts = []
        for reason, m in v.get("misses", {}).items():
            offs = ", ".join(f"{o:.3g}" for o in m["offsets"])
            parts.append(f"{reason} {m['runs']}" + (f" (offsets {offs} L_c)" if offs else ""))
        if parts:
            lines.append(f"* {fam}: " + "; ".join(parts))
    if not lines:
        return []
    meaning = "; ".join(f"*{k}*: {v}" for k, v in MISS_REASONS.items())
    return [
        "Why the runs the engine finished disagree (the reference restarted from "
        f"{MISS_CHECKPOINTS} points along each MuJoCo path, `compare.miss_reason`): {meaning}.",
        "",
        *lines,
        "",
    ]


def _falls_note(limit: QuasistaticLimitResult, boundary: BoundaryResult) -> list[str]:
    """Whether the runs were quasistatic at all: gravity slides on the reference and the
    engine tip's own peak inertia number, with agreement split at the spring drive's I_e*
    (the boundary study's bracket: below its lower end a drive is quasistatic)."""
    star = _star_for_figure(boundary.ie_star.get("spring", {}))
    if star is None:
        return []
    cut = float(star["low"])
    rows = []
    for fam, v in limit.families.items():
        runs = [r for r in limit.runs if r.get("family") == fam]
        peak = np.array([r.get("tip_peak_ie", np.nan) for r in runs], dtype=float)
        if not np.isfinite(peak).any():
            continue
        row = {
            "family": fam,
            "slides": f"{v.get('slide_runs', 0)}/{len(runs)}",
            "peak": f"{_f(np.nanmedian(peak))} ({_f(np.nanmin(peak))}-{_f(np.nanmax(peak))})",
        }
        for side, keep in (("slow", peak <= cut), ("fast", peak > cut)):
            sel = [r for r, k in zip(runs, keep) if k]
            agree = sum(bool(r["agree"]) for r in sel)
            frechet = np.nanmedian([r["frechet"] for r in sel]) if sel else np.nan
            row[side] = f"{agree}/{len(sel)}, {_f(frechet)}" if sel else "-"
        rows.append(row)
    if not rows:
        return []
    return [
        "### Was the path quasistatic? Gravity slides and the tip's own speed",
        "",
        "A slow, stiff drive makes a path quasistatic only where the drive moves the tip. Where "
        "a descent is steeper than the friction angle (the slip region, docs/physics.md §2) "
        "gravity alone slides the tip: the quasistatic model has no rate there, and the "
        "engine's tip falls at the speed gravity gives it, whatever the drive's. Per run, the "
        "share of the reference's arc length in the slip region (`compare.slide_fraction`) "
        "and the tip's peak speed as an inertia number, m v_max^2 / (F_p L_c) "
        f"(`compare.peak_speed`), split at the lower end of the spring drive's I_e* bracket "
        f"({_f(cut)}): a tip that went faster than that, somewhere, left the quasistatic "
        "regime there.",
        "",
        _table(
            rows,
            ["family", "slides", "peak", "slow", "fast"],
            [
                "family",
                "runs with gravity slides",
                "tip peak I_e: median (range)",
                f"peak I_e <= {_f(cut)}: agree, median Frechet",
                f"peak I_e > {_f(cut)}: agree, median Frechet",
            ],
        ),
        "",
    ]


def _limit_section(limit: QuasistaticLimitResult, boundary: BoundaryResult) -> list[str]:
    families = [
        {
            "family": k,
            "ok_n": f"{v['ok_runs']}/{v['runs']}",
            "stopped": ", ".join(f"{s} {n}" for s, n in v["failed_runs"].items()) or "none",
            **v,
        }
        for k, v in limit.families.items()
    ]
    return [
        "## Quasistatic limit (spring drive, lowest I_e)",
        "",
        f"I_e = {limit.lowest_ie:g}, default drive (K = k l_s / F_p = 30) and engine. Like for "
        "like: each MuJoCo path is compared with the streamline traced on the surface its tip "
        "touches (a ball of the tip's radius on MuJoCo's hfield facets, exactly: "
        "`surfaces.BallOnFacets`), ending where the engine's run ends, with the same force "
        "cap on both sides (a path needing more than the cap times F_p is held). A run the "
        "engine stopped, or whose reference stalled, counts as a disagreement. Beside it: the "
        "comparison with the streamline on the smooth surface and the geometry part (smooth vs "
        "facet streamline).",
        "",
        _table(
            families,
            [
                "family",
                "ok_n",
                "stopped",
                "outcome_agreement",
                "median_frechet",
                "mean_frechet",
                "outcome_agreement_smooth",
                "median_frechet_smooth",
                "mean_geometry_frechet",
                "meets_target",
            ],
            [
                "family",
                "ok/runs",
                "engine stops",
                "outcome agr.",
                "median Frechet",
                "mean Frechet",
                "outcome agr. (smooth)",
                "median Frechet (smooth)",
                "geometry Frechet",
                "target met (this plan)",
            ],
        ),
        "",
        *verdicts_section(limit.families),
        *_stalled_note(limit),
        *_misses_note(limit),
        *_falls_note(limit, boundary),
        "### What limits agreement: settings varied on the single peak",
        "",
        _table(
            [{"setting": k, **v} for k, v in limit.variations.items()],
            [
                "setting",
                "runs",
                "outcome_agreement",
                "median_frechet",
                "mean_frechet",
                "mean_lateral_deviation",
            ],
        ),
        "",
        "<details><summary>per run</summary>",
        "",
        _table(
            limit.runs,
            [
                "surface",
                "start_x",
                "start_y",
                "agree",
                "frechet",
                "reference_outcome",
                "end_reason",
                "end_detail",
                "miss_reason",
                "miss_offset",
                "agree_smooth",
                "frechet_smooth",
                "geometry_frechet",
            ],
        ),
        "",
        "</details>",
        "",
    ]


def _boundary_section(boundary: BoundaryResult) -> list[str]:
    star_rows = [
        {"protocol": p, "criterion_id": k, **v}
        for p, s in boundary.ie_star.items()
        for k, v in s["by_criterion"].items()
    ]
    lines = [
        "## Agreement against I_e (boundary study)",
        "",
        f"Families: {', '.join(boundary.families)}. Spring: a run agrees when its "
        "outcome agrees (`compare.outcome_agreement`); its deviation is the Frechet "
        "distance from the streamline. Ramp with reset: its I_e is the equivalent one, "
        "m v_eq^2 / (F_p L_c) with v_eq = L_c rate / F_p; its duration comes from a "
        "pilot run's per-cycle slip so that it would cover the path to the domain edge, "
        "capped at a step budget. A ramp run agrees when it has no engine trouble, does "
        "not self-lock where the streamline does not, and deviates <= 0.1 L_c from the "
        "streamline cut at its own arc length (prefix Frechet). I_e* interpolated in "
        "log I_e inside the bracket [last pass, first fail] for four criteria "
        "(headline: median; `departure` measures where agreement falls below its own "
        "low-I_e level); ramp I_e values whose runs cover under half the path take no "
        "part; ci = 16-84 % bootstrap over starts.",
        "",
        _table(star_rows, ["protocol", "criterion", "kind", "value", "low", "high", "ci_low", "ci_high"]),
        "",
    ]
    lines += [
        f"**I_e* ({p}) {s['note']}**" for p, s in boundary.ie_star.items() if s.get("valid") is False
    ] + [""]
    for proto, c in boundary.curves.items():
        lines += _curve_table(c, proto, boundary.skip_rate[proto])
    return lines


def _curve_table(c: BoundaryCurve, proto: str, skip_rate: list[float]) -> list[str]:
    rows = [
        {
            "ie": ie,
            "agreement": a,
            "mean_frechet": f,
            "median_frechet": fm,
            "lateral": la,
            "engine_trouble": e,
            "trap_skip": s,
        }
        for ie, a, f, fm, la, e, s in zip(
            c.ie, c.agreement, c.frechet, c.median_frechet, c.lateral, c.engine_trouble, skip_rate
        )
    ]
    n = c.runs_per_ie
    for r in rows:
        r["agree_n"] = f"{round(r['agreement'] * n)}/{n}"
        r["ok_n"] = f"{round((1 - r['engine_trouble']) * n)}/{n}"
    cols = [
        "ie",
        "agreement",
        "agree_n",
        "mean_frechet",
        "median_frechet",
        "lateral",
        "ok_n",
        "engine_trouble",
        "trap_skip",
    ]
    if proto == "ramp":
        for r, cv, ach in zip(rows, c.coverage, c.ie_achieved):
            r.update({"coverage": cv, "ie_achieved": ach})
        cols += ["coverage", "ie_achieved"]
    lines = [
        f"**{proto}** ({c.runs_per_ie} runs per I_e; deviation: {c.frechet_kind})",
        "",
        _table(rows, cols),
        "",
    ]
    if proto == "ramp":
        plans = [
            {"surface": p, "ie": float(ie), **rp} for p, d in c.ramp_plans.items() for ie, rp in d.items()
        ]
        lines += [
            f"Ramp durations (pilot from the family's first start; cap "
            f"{c.ramp_max_steps} steps; coverage = x advance / distance to the "
            "domain edge; ie_achieved from the mean x speed):",
            "",
            _table(
                plans,
                [
                    "surface",
                    "ie",
                    "rate_n_s",
                    "slip_per_cycle_lc",
                    "cycle_s",
                    "target_lc",
                    "required_steps",
                    "duration_s",
                    "capped",
                    "coverage_expected",
                ],
            ),
            "",
        ]
    return lines


def _stick_section(stick: StickSlipResult) -> list[str]:
    return [
        "## Stick-slip",
        "",
        f"Spring drive on {stick.surface}.",
        "",
        _table(
            stick.rows,
            [
                "ie",
                "stiffness_fp_per_lc",
                "runs",
                "slip_events_per_run",
                "mean_jump_lc",
                "max_jump_lc",
                "mean_force_drop_fp",
                "max_force_drop_fp",
                "quasistatic_traps",
                "skipped_traps",
                "extra_locks",
            ],
        ),
        "",
    ]


def _sand_section(sand: SandpaperResult) -> list[str]:
    if not sand.rows:
        return []
    return [
        "## Sandpaper analogs (25 um tip)",
        "",
        f"Spring drive, mu = {sand.mu:g} (assumed; the paper gives none for grit).",
        "",
        _table(
            sand.rows,
            [
                "grit",
                "runs",
                "tip_radius_um",
                "max_lateral_excursion_mm",
                "mean_lateral_excursion_tip_radii",
                "rms_lateral_tip_radii",
                "tortuosity",
                "force_peaks_per_100_tip_radii",
                "peak_over_median_force",
                "self_locked_fraction",
                "failed_runs",
            ],
        ),
        "",
        "Failures: "
        + "; ".join(f"{r['grit']}: {', '.join(r['failures'])}" for r in sand.rows if r.get("failures"))
        + ".",
        "",
    ]


def _fractal_section(fr: FractalLockResult | None) -> list[str]:
    """The fractal self-lock table (rate, Wilson interval, locked / ok runs, failed runs
    per series and H) and one sentence on what it shows."""
    if fr is None or not fr.rows:
        return []
    labels = _fractal_labels(fr)
    present = [s for s in SERIES if any(f"rate_{s}" in r for r in fr.rows)]
    rows = []
    for r in fr.rows:
        row = {"H": r["hurst"]}
        for s in present:
            row[s] = (
                f"{_f(r[f'rate_{s}'], 2)} [{_f(r[f'ci_low_{s}'], 2)}, {_f(r[f'ci_high_{s}'], 2)}] "
                f"({r[f'locked_{s}']}/{r[f'n_ok_{s}']}, failed {r[f'failed_runs_{s}']})"
            )
        rows.append(row)
    return [
        "## Self-lock rate against the Hurst exponent (fractal surfaces)",
        "",
        f"The paper's claim (Figs. 7E, 9) that self-lock becomes more frequent with H, checked "
        f"in dynamics: {fr.surfaces_per_hurst} paper-fractal surfaces per H (the Fig. 9 "
        f"height scale and seeds), one start each at mid height near the left edge, default "
        f"spring drive (K = 30), mu = {sig(fr.mu)}, tip radius {sig(fr.tip_radius)} surface "
        "units. Held = the lock rule or the shared force cap ended the path. Cells: rate [Wilson "
        f"{sig(100 * fr.confidence)} % interval] (held / runs without engine trouble, runs "
        "the engine stopped).",
        "",
        _table(rows, ["H", *present], ["H", *(labels[s] for s in present)]),
        "",
        _fractal_sentence(fr),
        "",
    ]


def _fractal_sentence(fr: FractalLockResult) -> str:
    """What the table shows, from its numbers: the streamline's and MuJoCo's rates at the
    lowest and highest H, and whether their intervals overlap at every H."""
    first, last = fr.rows[0], fr.rows[-1]

    def ends(s):
        return f"{_f(first.get(f'rate_{s}'), 2)} -> {_f(last.get(f'rate_{s}'), 2)}"

    pairs = [
        (r[f"ci_low_{s}"], r[f"ci_high_{s}"], r["ci_low_streamline"], r["ci_high_streamline"])
        for r in fr.rows
        for s in ("mujoco_corner", "mujoco_dynamic")
        if np.isfinite(r.get(f"rate_{s}", np.nan)) and np.isfinite(r.get("rate_streamline", np.nan))
    ]
    if not pairs:
        return "No H has both a streamline rate and a MuJoCo rate (every run stopped by the engine)."
    overlap = all(max(a_lo, b_lo) <= min(a_hi, b_hi) for a_lo, a_hi, b_lo, b_hi in pairs)
    return (
        f"From H = {sig(first['hurst'])} to {sig(last['hurst'])} the streamline's rate goes "
        f"{ends('streamline')}, MuJoCo's {ends('mujoco_corner')} at I_e = {sig(fr.corner_ie)} "
        f"and {ends('mujoco_dynamic')} at I_e = {sig(fr.dynamic_ie)}; the MuJoCo intervals "
        + ("overlap the streamline's at every H." if overlap else "miss the streamline's at some H.")
        + " With this many surfaces per H, only differences larger than the intervals count."
    )
