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
from spine_mj.validate.static_map import KAPPA_FLOOR, LADDERS, PROBE_IE, StaticMapResult


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
        *_plane_lines(static),
        "<details><summary>per plane and setting</summary>",
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


def _plane_lines(static: StaticMapResult) -> list[str]:
    """The per-plane table: MuJoCo's kappa at every refinement, the error by the map's rule,
    what held the tip at breakaway, the plane's convergence and the cause of each miss."""
    if not static.planes:
        return []
    summ = static.plane_summary()
    refined = [k for keys in LADDERS.values() for k in keys if f"kappa_mj_{k}" in static.planes[0]]
    changes = [f"change_{ladder}" for ladder in LADDERS if f"change_{ladder}" in static.planes[0]]
    kappas = ["kappa", "kappa_mj", "first_slip_kappa", *(f"kappa_mj_{k}" for k in refined)]
    rows = [
        {**p, **{k: cell(p.get(k), 4) for k in kappas}, "converged": "yes" if p["converged"] else "no"}
        for p in static.planes
    ]
    cols = [
        "slope_deg",
        "azimuth_deg",
        "kappa",
        "kappa_mj",
        *(f"kappa_mj_{k}" for k in refined),
        "error",
        *(f"error_{k}" for k in refined),
        "abs_error_fp",
        "breakaway_contacts",
        "held_contacts",
        "contact_tilt_deg",
        "contacts_lock_kappa",
        "first_slip_kappa",
        *changes,
        "converged",
        "cause",
    ]
    names = [
        "slope",
        "azimuth",
        "kappa",
        "MuJoCo",
        *(REFINEMENT_LABELS.get(k, k) for k in refined),
        "error",
        *(f"error {REFINEMENT_LABELS.get(k, k)}" for k in refined),
        "MuJoCo - kappa [F_p]",
        "contacts",
        "most contacts held",
        "largest tilt [deg]",
        "contacts' lock",
        "first slip",
        *(f"last change ({ladder})" for ladder in LADDERS if f"change_{ladder}" in static.planes[0]),
        "converged",
        "cause",
    ]
    return [
        "### Per plane: refinement, what held the tip, and the cause of each miss",
        "",
        f"Error rule: {summ['error_rule']}. In the drive's section kappa = tan(theta + arctan mu); a "
        "tilt of the contact normal moves ln kappa by (1 + kappa^2) / kappa per radian, least (2) at "
        f"kappa = 1 and twice that at kappa = {KAPPA_FLOOR:.3f}: below it a relative error grows as "
        "1 / kappa while the absolute one does not, so the error is absolute there (the 5 % target "
        f"is {0.05 * KAPPA_FLOOR:.4f} F_p). Contacts: those MuJoCo finds with the tip where the "
        "breakaway is read (one per hfield prism it overlaps); the most of them, their largest tilt "
        "from the plane's normal and the drive they hold together over the stuck steps since the "
        "first slip (the multi-contact lock, the closed form "
        "tan(theta + arctan mu) for one contact with the plane's normal). First slip: the force "
        "where the tip first moved. A plane is converged when the last change of each ladder "
        "(hfield x 2 -> x 4, dt -> dt / 2) lies within the target rule's slack plus both readings' "
        "ramp step. Edge catch: the tip slipped at the plane's kappa, slid less than the breakaway "
        "distance and was held again where the next hfield prism's contact, its normal tilted by "
        "that prism's side wall, came in.",
        "",
        f"Default settings: largest error {cell(summ['max_error'])}; {summ['converged_planes']} of "
        f"{summ['planes']} engaged planes converged; {summ['edge_catches']} with an edge catch.",
        "",
        table(rows, cols, names),
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
    lines = [f"static kappa max rel. error (engaged, default settings): {error:.3g}"]
    summ = validation.get("static_plane_summary")
    if summ:
        lines.append(
            f"static kappa per plane: largest error {summ['max_error']:.3g} (relative, absolute below "
            f"kappa {summ['kappa_floor']:.3g}); {summ['converged_planes']} of {summ['planes']} planes "
            f"converged; {summ['edge_catches']} edge catches"
        )
    return lines


def results_lines(validation: dict) -> list[str]:
    """The static breakaway of the site's results page: the largest relative error of
    MuJoCo's breakaway force over the engaged planes (``static_kappa_max_rel_error``) and,
    in a report that has it, the per-plane verdict (``static_plane_summary``)."""
    err = validation.get("static_kappa_max_rel_error")
    if err is None:
        return []
    lines = [
        "## Static breakaway",
        "",
        f"Largest relative error of MuJoCo's breakaway force against `tan(theta + arctan mu)` "
        f"over the engaged planes: {cell(err)} (`static_kappa_max_rel_error`).",
        "",
    ]
    summ = validation.get("static_plane_summary")
    if summ:
        lines += [
            f"Per plane ({summ['error_rule']}): largest error {cell(summ['max_error'])}; "
            f"{summ['converged_planes']} of {summ['planes']} engaged planes converged under "
            f"refinement; {summ['edge_catches']} with an edge catch (the report's per-plane "
            "table gives each plane's contacts and cause).",
            "",
        ]
    return lines


def section(static: StaticMapResult, ctx: ReportContext) -> str:
    fig = ctx.draw(_static_figure, static, "static_map.png")
    return assemble("\n".join(_lines(static)), image("Static breakaway ratio on inclined planes", fig))
