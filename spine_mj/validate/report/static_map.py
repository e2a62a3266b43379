"""The report of the static probe (:mod:`spine_mj.validate.static_map`): breakaway ratio on
inclined planes per engine setting.
"""

from __future__ import annotations

from pathlib import Path

from spine_mj.plotting import (
    new_figure,
    save_figure,
    sig,
    styled,
)
from spine_mj.validate.convergence import REFINEMENT_LABELS
from spine_mj.validate.report.common import ReportContext, assemble, cell, image, table
from spine_mj.validate.static_map import PROBE_IE, StaticMapResult


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


def _lines(static: StaticMapResult) -> list[str]:
    return [
        "## Static breakaway ratio on inclined planes",
        "",
        f"mu = {static.mu:g}; probe ramp at I_e = {sig(PROBE_IE)}; kappa from Eqs. 1-3.",
        "",
        table(
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
        f"{cell(static.static_kappa_max_rel_error)}{_convergence_note(static)} (target <= 0.05).",
        "",
        "<details><summary>per plane</summary>",
        "",
        table(
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


def _convergence_note(static: StaticMapResult) -> str:
    """The error's change under each refinement and its verdict (solution verification)."""
    parts = [
        f"{REFINEMENT_LABELS.get(k, k)}: change {cell(e['max_rel_error_change'])}, "
        f"{'converged' if e['converged'] else 'unconverged'}"
        for k, e in static.convergence.items()
    ]
    return f" ({'; '.join(parts)})" if parts else ""


def summary_lines(validation: dict) -> list[str]:
    """The largest static kappa error, engaged, at the default settings."""
    if "static_kappa_max_rel_error" not in validation:
        return []
    error = validation["static_kappa_max_rel_error"]
    return [f"static kappa max rel. error (engaged, default settings): {error:.3g}"]


def results_lines(validation: dict) -> list[str]:
    """The static breakaway of the site's results page: the largest relative error of
    MuJoCo's breakaway force over the engaged planes (``static_kappa_max_rel_error``)."""
    err = validation.get("static_kappa_max_rel_error")
    if err is None:
        return []
    return [
        "## Static breakaway",
        "",
        f"Largest relative error of MuJoCo's breakaway force against `tan(theta + arctan mu)` "
        f"over the engaged planes: {cell(err)} (`static_kappa_max_rel_error`).",
        "",
    ]


def section(static: StaticMapResult, ctx: ReportContext) -> str:
    fig = ctx.draw(_static_figure, static, "static_map.png")
    return assemble("\n".join(_lines(static)), image("Static breakaway ratio on inclined planes", fig))
