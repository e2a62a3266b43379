"""The report of ``spine-mj hold`` (:mod:`spine_mj.validate.hold`): its figure, summary and
markdown page."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["write_hold"]


def write_hold(out: Path, summary: dict, surface, places, held, mj_starts) -> None:
    """``hold.png``, ``summary.json`` and ``report.md`` of a hold's ``summary`` under ``out``."""
    from spine_mj.jsonio import write_json
    from spine_mj.plotting import save_figure, styled

    save_figure(styled(_figure)(surface, places, held, mj_starts, summary), out / "hold.png")
    write_json(out / "summary.json", summary)
    (out / "report.md").write_text(_report(summary))


def _report(s: dict) -> str:
    sh, ag, c, mf = s["self_lock_share"], s["agreement"], s["corner"], s["median_frechet"]
    lines = [
        f"# Will a spine hold on {s['surface']}?",
        "",
        s["verdict"],
        "",
        "![places and refinement](hold.png)",
        "",
        "| quantity | value | 95 % interval | n |",
        "|---|---|---|---|",
        f"| self-lock share (quasistatic) | {sh['value']:.3f} | [{sh['low']:.3f}, {sh['high']:.3f}] "
        f"| {sh['n']} |",
        f"| agreement (well-conditioned) | {ag['value']:.3f} | [{ag['low']:.3f}, {ag['high']:.3f}] "
        f"| {ag['n_well_conditioned']} |",
        f"| median Frechet [L_c] | {mf['value']:.3g} | [{mf['low']:.3g}, {mf['high']:.3g}] "
        f"| {ag['starts']} |",
        "",
        f"Corner: {c['reason']}. Tip radius {s['tip_radius']:.3g} (surface units), mu_s {s['mu']:g}.",
        "",
        _starts_line(s["mujoco_starts"]),
        "",
        "| refinement | from | paired starts | agreement change | median Frechet change | converged |",
        "|---|---|---|---|---|---|",
    ]
    for r in s["refinements"]:
        if r["run"]:
            lines.append(
                f"| {r['level']} | {r['from']} | {r['runs']} | {r['change']:+.3f} "
                f"| {r['median_frechet_change']:+.3g} | {'yes' if r['converged'] else 'no'} |"
            )
        else:
            lines.append(f"| {r['level']} | | | not run: {r['note']} | | |")
    return "\n".join(lines) + "\n"


def _starts_line(ms: dict) -> str:
    """How many MuJoCo starts ran, and why more than asked."""
    added = ms["added_rounds"]
    more = (
        f", {ms['run'] - ms['asked']} added in {added} round{'s' * (added > 1)} where too few paired "
        "well-conditioned starts were left"
        if added
        else ""
    )
    return f"MuJoCo starts: {ms['run']} ({ms['asked']} asked{more})."


def _figure(surface, places, held, mujoco_starts, summary: dict, *, max_points: int = 300):
    """``spine-mj hold``'s figure: the places traced on the height map (held: crosses, free:
    dots; the MuJoCo starts ringed), and the agreement of each refinement level on its
    paired starts against the corner's own 95 % interval (shaded)."""
    from spine_mj import plotting as pl

    grid = pl._display_grid(surface, max_points)
    units = pl._axes_units(surface, grid)
    lf = units[0]
    fig = pl.new_figure(figsize=(12, 4.5), layout="constrained")
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    pl._height_map(fig, ax, grid, units)
    places, held = np.asarray(places, float) * lf, np.asarray(held, bool)
    ax.plot(*places[~held].T, ".", ms=3, color="#cccccc", label="free")
    ax.plot(*places[held].T, "x", ms=5, color=pl.PATH_COLORS["mujoco"], label="held (quasistatic)")
    ring = np.asarray(mujoco_starts, float) * lf
    ax.plot(*ring.T, "o", mfc="none", ms=7, color=pl.PATH_COLORS["facets"], label="MuJoCo starts")
    ax.legend(loc="upper right", fontsize="small")
    share = summary["self_lock_share"]
    ax.set_title(f"held from {share['value']:.1%} of {share['n']} places")
    ag = summary["agreement"]
    labels, values = ["corner"], [ag["value"]]
    for r in summary["refinements"]:
        if r.get("run"):
            labels.append(r["level"])
            values.append(values[labels.index(r["from"]) if r["from"] in labels else 0] + r["change"])
    bx.axhspan(ag["low"], ag["high"], color="#dddddd", label="corner's 95 % interval")
    bx.plot(range(len(values)), values, "o-", color=pl.SERIES_COLORS[0], label="agreement")
    bx.set_xticks(range(len(values)), labels, rotation=20)
    bx.set_ylim(min(0.0, min(values)) - 0.02, 1.02)
    bx.set_ylabel("agreement (well-conditioned starts)")
    bx.set_title("converged" if summary["converged"] else "not converged")
    bx.legend(loc="lower left", fontsize="small")
    return fig
