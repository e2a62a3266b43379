"""The report of the array study (:mod:`spine_mj.validate.array_study`): holding per spine
and P(at least one spine self-locks) against N per layout, and the staggered-array conjecture.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from spine_mj.plotting import new_figure, save_figure, sig, styled
from spine_mj.validate.array_study import ArrayStudyResult
from spine_mj.validate.report.common import ReportContext, table

__all__ = ["array_figure", "array_section", "section", "summary_lines"]

_COLORS = {"grid": "#1f77b4", "staggered": "#d62728", "random": "#2ca02c"}


def _ci(lo, hi) -> str:
    return f"[{sig(lo)}, {sig(hi)}]" if np.isfinite(lo) and np.isfinite(hi) else "-"


@styled
def array_figure(res: ArrayStudyResult, path: Path) -> Path | None:
    """Holding per spine and P(at least one spine self-locks) against N per surface and
    layout (MuJoCo with 95 % intervals, the quasistatic reference dashed), at the plan's
    first spacing; None without rows."""
    if not res.rows:
        return None
    surfaces = list(dict.fromkeys(r["surface"] for r in res.rows))
    first = min(r["spacing_nominal_ls"] for r in res.rows)
    fig = new_figure(figsize=(4.0 * len(surfaces), 6.4), constrained_layout=True)
    axes = np.atleast_2d(fig.subplots(2, len(surfaces), squeeze=False))
    for j, surf in enumerate(surfaces):
        for kind, color in _COLORS.items():
            rows = [
                r
                for r in res.rows
                if r["surface"] == surf and r["layout"] == kind and r["spacing_nominal_ls"] == first
            ]
            if not rows:
                continue
            n = np.array([r["n_spines"] for r in rows]) * (1 + 0.04 * (list(_COLORS).index(kind) - 1))
            h = np.array([r["holding_per_spine"] for r in rows])
            lo, hi = np.array([r["holding_ci"] for r in rows]).T
            axes[0, j].errorbar(
                n, h, yerr=[h - lo, hi - h], color=color, marker="o", ms=4, capsize=2, label=kind
            )
            axes[0, j].plot(n, [r["holding_per_spine_qs"] for r in rows], color=color, ls="--", lw=0.8)
            p = np.array([r["p_lock"]["rate"] for r in rows])
            plo = np.array([r["p_lock"]["ci_low"] for r in rows])
            phi = np.array([r["p_lock"]["ci_high"] for r in rows])
            axes[1, j].errorbar(
                n, p, yerr=[p - plo, phi - p], color=color, marker="o", ms=4, capsize=2, label=kind
            )
            axes[1, j].plot(n, [r["p_lock_qs"]["rate"] for r in rows], color=color, ls="--", lw=0.8)
        axes[0, j].set_title(f"{surf} (spacing {sig(first)} x max(l_s, 3 r_tip))")
        for ax in axes[:, j]:
            ax.set_xscale("log", base=2)
            ax.set_xlabel("spines N")
        axes[0, j].set_ylabel("holding force / (N F_p)")
        axes[1, j].set_ylabel("P(at least one spine self-locks)")
        axes[1, j].set_ylim(-0.05, 1.05)
    axes[0, 0].legend(fontsize=7, title="MuJoCo (dashed: quasistatic)", title_fontsize=7)
    return save_figure(fig, path)


def array_section(res: ArrayStudyResult | None, figure: str | None = None) -> str:
    """The report's Markdown section on arrays ("" when the study did not run)."""
    if res is None or not res.rows:
        return ""
    p = res.plan
    paces = p["ie"]
    lines = _method(p, paces)
    rows = [_row(r) for r in res.rows]
    names = ["surface", "N", "spacing [l_s]", "layout", "holding (MuJoCo, I_e -> 0)", "95 % CI"]
    three = len(paces) >= 3
    names += ["holding per pace", "extrapolation step", *(["observed order"] if three else [])]
    names += ["holding (QS)", "predicted excess", "dt / 2 change"]
    names += ["P(lock) MuJoCo", "95 % CI", "P(lock) QS", "lock agreement", "failed", "QS paths short"]
    cols = ["surface", "N", "spacing", "layout", "holding", "holding_ci", "by_pace", "step"]
    cols += [*(["order"] if three else []), "holding_qs"]
    cols += ["excess", "dt", "lock", "lock_ci"]
    lines.append(table(rows, [*cols, "lock_qs", "agreement", "failed", "short"], names))
    lines += _convergence_notes(res.convergence, paces)
    if figure:
        lines += ["", f"![Holding per spine and P(lock) against N per layout]({figure})"]
    lines += ["", "### The conjecture: staggered (and random) against aligned, same placements", ""]
    lines.append(_conjecture_table(res.conjecture))
    lines += ["", _verdict(res)]
    return "\n".join(lines) + "\n"


def _method(p: dict, paces) -> list[str]:
    """The section's heading and its paragraph on the method (plan ``p``, paces ``paces``)."""
    return [
        "## Spine arrays and the staggered-layout conjecture",
        "",
        f"Arrays of N = {', '.join(str(s * s) for s in p['sides'])} spines (aligned grid, staggered grid, "
        "random pattern of one footprint; spacings "
        f"{', '.join(sig(v) for v in p['spacings_ls'])} x max(l_s, 3 tip radii)) dragged under "
        f"displacement control at I_e = {', '.join(sig(v) for v in paces)} (each pace the same "
        "placements), K = 30 per spine, "
        f"over {sig(p['travel_ls'])} l_s; {p['placements']} placements per configuration, the same for every "
        f"layout; {p['array_runs']} array runs. Holding = the largest total spring force over N F_p, the "
        "quantity the quasistatic reference computes. Its dynamic excess is the spring-block swing past "
        "breakaway, sqrt(I_e K L_c / l_s) F_p per spine, first order in sqrt(I_e): each placement's holding "
        "is extrapolated to I_e -> 0 by Richardson's step of that order from the two slowest paces "
        "(mean, 95 % bootstrap interval over placements); 'predicted excess' is the swing at the slowest "
        "pace, 'extrapolation step' the extrapolated mean minus the slowest pace's. A holding is converged "
        "when that step lies inside the slowest pace's own 95 % interval, else marked (unconverged: "
        "pace; and dt / 2 where the halved step moved the fastest pace's holding out of its interval); "
        "P(lock) (share of placements where at least one spine self-locked, Wilson 95 %, read at the "
        "slowest pace) likewise with its change from the pace before. The quasistatic reference puts each "
        "spine on its own compliant-drive streamline and sums them; agreement = share of spines whose lock "
        "verdict matches (single-spine target 95 %)."
        + (
            " With three paces, 'observed order' is that of the means in sqrt(I_e) (predicted: 1; '-' where "
            "the changes flip sign or vanish)."
            if len(paces) >= 3
            else ""
        ),
        "",
    ]


def _row(r: dict) -> dict:
    """One row of the holding and P(lock) table, from a study row ``r``."""
    pl, pq = r["p_lock"], r["p_lock_qs"]
    return {
        "surface": r["surface"],
        "N": r["n_spines"],
        "spacing": sig(r["spacing_ls"]),
        "layout": r["layout"],
        "holding": sig(r["holding_per_spine"])
        + _mark(r["holding_converged"], (r.get("dt_halved") or {}).get("converged")),
        "holding_ci": _ci(*r["holding_ci"]),
        "by_pace": ", ".join(sig(b["holding"]) for b in r["holding_by_pace"]),
        "step": sig(r["holding_extrapolation_step"]),
        "order": sig(r["holding_observed_order"]) if math.isfinite(r["holding_observed_order"]) else "-",
        "holding_qs": sig(r["holding_per_spine_qs"]),
        "excess": sig(r["holding_excess_predicted"]),
        "dt": _dt(r.get("dt_halved")),
        "lock": f"{pl['locked']}/{pl['n_ok']}" + _mark(r["p_lock_converged"]),
        "lock_ci": _ci(pl["ci_low"], pl["ci_high"]),
        "lock_qs": f"{pq['locked']}/{pq['n_ok']}",
        "agreement": sig(r["lock_agreement"]),
        "failed": r["failed_runs"],
        "short": r["reference_short_spines"],
    }


def _convergence_notes(conv: dict, paces) -> list[str]:
    """The lines on the extrapolation's and the halved step's convergence (none where not run)."""
    lines = []
    if conv.get("pace"):
        c = conv["pace"]
        lines += [
            "",
            f"Extrapolation to I_e -> 0: {c['rows_converged']} of {c['rows']} holdings converged (the "
            "step inside the slowest pace's 95 % interval); largest step "
            f"{sig(c['max_abs_change'])} F_p per spine.",
        ]
    if conv.get("dt_halved"):
        c = conv["dt_halved"]
        lines += [
            "",
            f"Solution verification: the grid layout rerun at I_e = {sig(paces[0])} with the engine's step "
            f"halved: {c['rows_converged']} of {c['rows']} holdings converged (the change inside the "
            f"holding's own 95 % interval); largest change {sig(c['max_abs_change'])} F_p per spine.",
        ]
    return lines


def _conjecture_table(conjecture: list[dict]) -> str:
    """The table of staggered (and random) against aligned, same placements."""
    diffs = [
        {
            "surface": c["surface"],
            "N": c["n_spines"],
            "spacing": sig(c["spacing_ls"]),
            "layout": c["layout"],
            "p_lock": sig(c["p_lock_diff"]["diff"]),
            "p_lock_ci": _ci(c["p_lock_diff"]["ci_low"], c["p_lock_diff"]["ci_high"]),
            "holding": sig(c["holding_diff"]["diff"]),
            "holding_ci": _ci(c["holding_diff"]["ci_low"], c["holding_diff"]["ci_high"]),
        }
        for c in conjecture
    ]
    names = ["surface", "N", "spacing [l_s]", "layout", "P(lock) - P(lock, grid)", "95 % CI"]
    names += ["holding - holding(grid)", "95 % CI"]
    cols = ["surface", "N", "spacing", "layout", "p_lock", "p_lock_ci", "holding", "holding_ci"]
    return table(diffs, cols, names)


def _mark(converged, dt_converged=None) -> str:
    """`` (unconverged: pace, dt / 2)`` after a number, naming the checks whose verdict is
    False (``converged``: the extrapolation's, ``dt_converged``: the halved step's)."""
    moved = [name for name, v in (("pace", converged), ("dt / 2", dt_converged)) if v is False]
    return f" (unconverged: {', '.join(moved)})" if moved else ""


def _dt(check: dict | None) -> str:
    """The holding's change with the engine's step halved (at the fastest pace), marked."""
    return "-" if not check else sig(check["holding_change"]) + _mark(check["converged"])


def _verdict(res: ArrayStudyResult) -> str:
    """One paragraph: the pooled lock-probability differences and what they say."""
    parts = []
    for kind, pool in res.pooled.items():
        d = pool.get("diff")
        if not d:
            continue
        a, b = pool["p_lock"], pool["p_lock_grid"]
        verdict = (
            "higher"
            if d["ci_low"] > 0
            else "lower"
            if d["ci_high"] < 0
            else "not distinguishable from aligned"
        )
        parts.append(
            f"{kind}: P(lock) {sig(a['rate'])} ({a['locked']}/{a['n_ok']}) against aligned {sig(b['rate'])} "
            f"({b['locked']}/{b['n_ok']}), difference {sig(d['diff'])} "
            f"{_ci(d['ci_low'], d['ci_high'])}: {verdict}"
        )
    if not parts:
        return "No N > 1 configuration ran: the conjecture is not tested at this size."
    width = max(
        (p["ci_high"] - p["ci_low"]) for p in (v["diff"] for v in res.pooled.values() if v.get("diff"))
    )
    return (
        "**Answer (pooled over surfaces, N > 1 and spacings, paired placements):** "
        + "; ".join(parts)
        + f". The pooled interval is {sig(width)} wide"
        + (
            ", so a difference smaller than that is not resolved at this size."
            if math.isfinite(width)
            else "."
        )
    )


def summary_lines(validation: dict) -> list[str]:
    """Per layout the pooled difference of P(at least one spine locks) from the aligned one,
    with its interval."""
    lines = []
    for kind, pool in validation.get("arrays", {}).get("pooled", {}).items():
        if pool.get("diff"):
            d = pool["diff"]
            lines.append(
                f"arrays: P(at least one spine locks), {kind} - aligned = {d['diff']:+.3f} "
                f"[{d['ci_low']:+.3f}, {d['ci_high']:+.3f}] ({pool['locked']}/{pool['n_ok']} against "
                f"{pool['locked_grid']}/{pool['n_ok_grid']})"
            )
    return lines


def section(res: ArrayStudyResult, ctx: ReportContext) -> str:
    return array_section(res, ctx.draw(array_figure, res, "arrays.png"))
