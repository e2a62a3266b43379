"""Figures and ``report.md`` of the validation suite (:mod:`spine_mj.validate`).

The report reads the studies' typed results (one section and one figure per study) and
the summary that ``validation.json`` holds, so that both say the same numbers.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from spine_mj.errors import atomic_output
from spine_mj.plotting import new_figure, save_figure
from spine_mj.validate.boundary import BoundaryCurve, BoundaryResult
from spine_mj.validate.quasistatic_limit import QuasistaticLimitResult
from spine_mj.validate.sandpaper import SandpaperResult
from spine_mj.validate.static_map import StaticMapResult
from spine_mj.validate.stick_slip import StickSlipResult

__all__ = ["write_report"]


def _f(v, digits=3) -> str:
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    if math.isnan(v):
        return "-"
    if math.isinf(v):
        return "inf"
    return f"{v:.{digits}g}"


def _table(rows: list[dict], cols: list[str], names: list[str] | None = None) -> str:
    names = names or cols
    out = ["| " + " | ".join(names) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(_f(r.get(c)) for c in cols) + " |")
    return "\n".join(out)


def _static_figure(st: StaticMapResult, path: Path) -> None:
    engines = list(st.per_engine)
    fig = new_figure(figsize=(5 * len(engines), 4), constrained_layout=True)
    axes = fig.subplots(1, len(engines), squeeze=False)[0]
    for ax, label in zip(axes, engines):
        rows = [r for r in st.rows if r["engine"] == label]
        for az in sorted({r["azimuth_deg"] for r in rows}):
            sel = sorted((r for r in rows if r["azimuth_deg"] == az), key=lambda r: r["slope_deg"])
            ax.plot(
                [r["slope_deg"] for r in sel], [r["ratio"] for r in sel], "o-", label=f"azimuth {az:g} deg"
            )
            for r in sel:
                if r["region"] != "engaged":
                    mark = {"self_lock": "^", "slip": "v"}[r["region"]]
                    ok = r["region_agrees"]
                    ax.plot(r["slope_deg"], 1.0, mark, color="g" if ok else "r", ms=9, mfc="none")
        ax.axhspan(0.95, 1.05, color="0.9")
        ax.set(xlabel="slope angle [deg]", ylabel="kappa_mj / kappa", title=label)
        ax.legend(fontsize=7)
    fig.suptitle(
        "Static probe on planes (shaded: +-5 %; ^ self-lock, v slip region at 1: green = MuJoCo agrees)",
        fontsize=9,
    )
    save_figure(fig, path)


def _paths_figure(lim: QuasistaticLimitResult, path: Path) -> None:
    presets = list(lim.paths)
    if not presets:
        return
    fig = new_figure(figsize=(5.5 * len(presets), 5), constrained_layout=True)
    axes = fig.subplots(1, len(presets), squeeze=False)[0]
    for ax, preset in zip(axes, presets):
        for i, p in enumerate(lim.paths[preset]):
            ax.plot(
                p.smooth[:, 0],
                p.smooth[:, 1],
                "k-",
                lw=1.5,
                label="streamline (smooth)" if i == 0 else None,
            )
            ax.plot(
                p.tri[:, 0],
                p.tri[:, 1],
                "b--",
                lw=1,
                label="streamline (hfield facets)" if i == 0 else None,
            )
            if p.mujoco.shape[0]:
                ax.plot(p.mujoco[:, 0], p.mujoco[:, 1], "r-", lw=0.8, label="MuJoCo" if i == 0 else None)
        circle = np.linspace(0, 2 * np.pi, 100)
        ax.plot(1.5 * np.cos(circle), 1.5 * np.sin(circle), color="0.6", lw=0.5)
        ax.set(
            aspect="equal",
            xlim=(-5, 5),
            ylim=(-5, 5),
            xlabel="x",
            ylabel="y",
            title=f"{preset}, I_e = {lim.lowest_ie:g}",
        )
        ax.legend(fontsize=7, loc="upper left")
    save_figure(fig, path)


def _boundary_figure(bnd: BoundaryResult, path: Path) -> None:
    fig = new_figure(figsize=(11, 4), constrained_layout=True)
    a1, a2 = fig.subplots(1, 2)
    for proto, c in bnd.curves.items():
        lab = proto if proto != "ramp" else "ramp (equivalent I_e)"
        (line,) = a1.semilogx(c.ie, c.agreement, "o-", label=lab)
        used = bnd.ie_star[proto].get("ie_used", c.ie)
        off = [i for i, v in enumerate(c.ie) if not np.isclose(used, v).any()]
        if off:  # points that take no part in I_e* (a capped ramp covering < half the path)
            a1.plot(
                np.asarray(c.ie)[off],
                np.asarray(c.agreement)[off],
                "o",
                ms=9,
                mfc="white",
                mec=line.get_color(),
                label=f"{proto}: not used for I_e*",
            )
        for key, style in (("frechet", "o-"), ("median_frechet", "s--")):
            a2.loglog(
                c.ie,
                np.maximum(np.asarray(getattr(c, key), float), 1e-5),
                style,
                label=f"{proto}: {'mean' if key == 'frechet' else 'median'} "
                f"{'prefix ' if proto == 'ramp' else ''}Frechet",
            )
        s = bnd.ie_star[proto]
        if s.get("kind") != "bracketed":
            s = s.get("by_criterion", {}).get("departure") or s
        if s.get("kind") == "bracketed":
            for ax in (a1, a2):
                ax.axvspan(s["low"], s["high"], alpha=0.12, color=line.get_color())
                ax.axvline(s["value"], ls=":", color=line.get_color())
    a1.axhline(0.95, color="r", lw=0.8)
    a2.axhline(0.1, color="r", lw=0.8)
    a1.set(xlabel="I_e", ylabel="fraction of runs that agree")
    a2.set(xlabel="I_e", ylabel="deviation / L_c")
    a1.legend(fontsize=8)
    a2.legend(fontsize=7)
    save_figure(fig, path)


def _stick_figure(ss: StickSlipResult, path: Path) -> None:
    if not ss.traces:
        return
    fig = new_figure(figsize=(11, 4), constrained_layout=True)
    ax = fig.subplots()
    for (ie, k), (t, f) in sorted(ss.traces.items()):
        ax.plot(t / max(t[-1], 1e-12), f, lw=0.8, label=f"I_e {ie:g}, k {k:.3g} N/m")
    ax.set(
        xlabel="time / run duration",
        ylabel="drive force / F_p",
        title=f"Spring drive on {ss.surface} (first start)",
    )
    ax.legend(fontsize=7)
    save_figure(fig, path)


def _sand_figure(sp: SandpaperResult, path: Path) -> None:
    grits = list(sp.paths)
    if not grits:
        return
    fig = new_figure(figsize=(5 * len(grits), 7), constrained_layout=True)
    axes = fig.subplots(2, len(grits), squeeze=False)
    for j, g in enumerate(grits):
        for x, y, _t, f in sp.paths[g]:
            axes[0, j].plot(x * 1e3, (y - y[0]) * 1e3, lw=0.8)
            axes[1, j].plot(x * 1e3, f, lw=0.6)
        axes[0, j].set(title=f"{g}: path (y - y0)", xlabel="x [mm]", ylabel="y - y0 [mm]")
        axes[1, j].set(xlabel="x [mm]", ylabel="drive force / F_p")
    save_figure(fig, path)


def write_report(
    out: Path,
    result: dict,
    *,
    static: StaticMapResult,
    limit: QuasistaticLimitResult,
    boundary: BoundaryResult,
    stick: StickSlipResult,
    sand: SandpaperResult,
) -> Path:
    """Write the figures under ``out/figures`` and ``out/report.md``; returns the report path.

    ``result`` is the content of ``validation.json`` (plan, static error, engine settings,
    timings); the studies' results give the tables and figures.
    """
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    _static_figure(static, figs / "static_map.png")
    _paths_figure(limit, figs / "limit_paths.png")
    _boundary_figure(boundary, figs / "boundary.png")
    _stick_figure(stick, figs / "stick_slip.png")
    _sand_figure(sand, figs / "sandpaper.png")

    lines = [
        f"# Validation: MuJoCo against the quasistatic streamline ({result['plan']} plan)",
        "",
        "Generated by `spine-mj validate`; numbers also in `validation.json`. Lengths "
        "in L_c (characteristic length of each surface), forces in F_p (preload).",
        "",
    ]
    lines += _static_section(static, result)
    lines += _limit_section(limit)
    lines += _boundary_section(boundary)
    lines += _stick_section(stick)
    lines += _sand_section(sand)
    lines += [
        "## Engine settings",
        "",
        "```",
        str(result["engine_settings"]),
        "```",
        "",
        f"Study times [s]: {result['timings_s']}",
        "",
    ]
    path = out / "report.md"
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(lines))
    return path


def _static_section(static: StaticMapResult, result: dict) -> list[str]:
    return [
        "## 1. Static breakaway ratio on planes",
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
        "![static](figures/static_map.png)",
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


def _limit_section(limit: QuasistaticLimitResult) -> list[str]:
    return [
        "## 2. Quasistatic limit (spring drive, lowest I_e)",
        "",
        f"I_e = {limit.lowest_ie:g}, recommended settings. Total = MuJoCo vs smooth "
        "streamline; geometry = streamline on MuJoCo's hfield facets vs smooth; "
        "dynamics = MuJoCo vs facet streamline.",
        "",
        _table(
            [{"family": k, **v} for k, v in limit.families.items()],
            [
                "family",
                "runs",
                "outcome_agreement",
                "mean_frechet",
                "mean_lateral_deviation",
                "mean_geometry_frechet",
                "mean_dynamics_frechet",
                "outcome_agreement_vs_triangulated",
                "meets_target",
            ],
            [
                "family",
                "runs",
                "outcome agr.",
                "mean Frechet",
                "mean lateral",
                "geometry Frechet",
                "dynamics Frechet",
                "outcome agr. vs facets",
                "target met",
            ],
        ),
        "",
        "![paths](figures/limit_paths.png)",
        "",
        "### What limits agreement: settings varied on the single peak",
        "",
        _table(
            [{"setting": k, **v} for k, v in limit.variations.items()],
            ["setting", "runs", "outcome_agreement", "mean_frechet", "mean_lateral_deviation"],
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
                "end_reason",
                "agree",
                "frechet",
                "lateral_deviation",
                "end_distance",
                "geometry_frechet",
                "dynamics_frechet",
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
        "## 3. The quasistatic boundary",
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
    lines += ["![boundary](figures/boundary.png)", ""]
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
    cols = ["ie", "agreement", "mean_frechet", "median_frechet", "lateral", "engine_trouble", "trap_skip"]
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
        "## 4. Stick-slip",
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
        "![stick-slip](figures/stick_slip.png)",
        "",
    ]


def _sand_section(sand: SandpaperResult) -> list[str]:
    if not sand.rows:
        return []
    return [
        "## 5. Sandpaper analogs (25 um tip)",
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
        "![sandpaper](figures/sandpaper.png)",
        "",
    ]
