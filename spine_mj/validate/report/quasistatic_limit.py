"""The report of the quasistatic limit (:mod:`spine_mj.validate.quasistatic_limit`): paths at
the lowest I_e against the streamline, per family, and the settings that limit agreement.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    DIVERGING_CMAP,
    PATH_COLORS,
    height_mappable,
    new_figure,
    save_figure,
    shared_height_norm,
    sig,
    styled,
)
from spine_mj.presets import make_surface
from spine_mj.sweep.analyses.compare import MISS_CHECKPOINTS
from spine_mj.theory.agreement import MISS_REASONS
from spine_mj.validate.boundary import BoundaryResult
from spine_mj.validate.convergence import HEADLINES, REFINEMENT_LABELS, quoted, unconverged_mark
from spine_mj.validate.miss_causes import MISS_CAUSES
from spine_mj.validate.platform import platform_info
from spine_mj.validate.predicted_limits import CORNER_PATH_STARTS
from spine_mj.validate.quasistatic_limit import QuasistaticLimitResult
from spine_mj.validate.report.boundary import star_to_draw
from spine_mj.validate.report.common import (
    Headline,
    ReportContext,
    assemble,
    cell,
    corner_text,
    image,
    read_interval,
    read_number,
    read_table,
    refinement_verdict,
    table,
)
from spine_mj.validate.report.verdicts import platform_line, verdicts_section


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
            causes = ", ".join(f"{c} {n}" for c, n in m.get("causes", {}).items())
            parts.append(
                f"{reason} {m['runs']}"
                + (f" (offsets {offs} L_c)" if offs else "")
                + (f" [causes: {causes}]" if causes else "")
            )
        if parts:
            lines.append(f"* {fam}: " + "; ".join(parts))
    if not lines:
        return []
    meaning = "; ".join(f"*{k}*: {v}" for k, v in MISS_REASONS.items())
    meaning += ". Causes: " + "; ".join(f"*{k}*: {v}" for k, v in MISS_CAUSES.items())
    return [
        "Why the runs the engine finished disagree (the reference restarted from "
        f"{MISS_CHECKPOINTS} points along each MuJoCo path, `agreement.miss_reason`): {meaning}.",
        "",
        *lines,
        "",
    ]


def falls_note(limit: QuasistaticLimitResult, boundary: BoundaryResult) -> list[str]:
    """Whether the runs were quasistatic at all: gravity slides on the reference and the
    engine tip's own peak inertia number, with agreement split at the spring drive's I_e*
    (the boundary study's bracket: below its lower end a drive is quasistatic)."""
    star = star_to_draw(boundary.ie_star.get("spring", {}))
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
            "peak": f"{cell(np.nanmedian(peak))} ({cell(np.nanmin(peak))}-{cell(np.nanmax(peak))})",
            "landing": f"{v.get('landing_runs', 0)}: +{v.get('landing_explained', 0)} / "
            f"-{v.get('landing_lost', 0)} (streamline {cell(v.get('outcome_agreement_streamline', np.nan))})",
        }
        for side, keep in (("slow", peak <= cut), ("fast", peak > cut)):
            sel = [r for r, k in zip(runs, keep) if k]
            agree = sum(bool(r["agree"]) for r in sel)
            frechet = np.nanmedian([r["frechet"] for r in sel]) if sel else np.nan
            row[side] = f"{agree}/{len(sel)}, {cell(frechet)}" if sel else "-"
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
        "share of the reference's arc length in the slip region (`agreement.slide_fraction`) "
        "and the tip's peak speed as an inertia number, m v_max^2 / (F_p L_c) "
        f"(`agreement.peak_speed`), split at the lower end of the spring drive's I_e* bracket "
        f"({cell(cut)}): a tip that went faster than that, somewhere, left the quasistatic "
        "regime there. A run whose reference falls is judged against the fall-landing reference "
        "(each fall replaced by the inertial tip on the run's spring until it lands, "
        "`theory.fall_landing`, docs/physics/inertia.md): the runs so judged, the streamline's "
        "misses it explains (+), its agreements it loses (-), and the streamline's own outcome "
        "agreement over all runs.",
        "",
        table(
            rows,
            ["family", "slides", "peak", "slow", "fast", "landing"],
            [
                "family",
                "runs with gravity slides",
                "tip peak I_e: median (range)",
                f"peak I_e <= {cell(cut)}: agree, median Frechet",
                f"peak I_e > {cell(cut)}: agree, median Frechet",
                "judged on the landing reference: +explained / -lost",
            ],
        ),
        "",
    ]


def _marked(v: dict, conv: dict | None) -> dict:
    """The corner's headlines of a family as table cells, each marked where unconverged."""
    return {h: quoted(cell(v[h]), conv, h) for h in HEADLINES if h in v}


#: How the report's solution verification is made, above its table.
_CONVERGENCE_RULE = (
    "Each family's corner rerun from a subset of its starts (the same points, one run "
    "each) with the engine's step halved (each run's own rig step, the contact's time "
    "constant kept, so only the step changes) and with an analytic surface's hfield at "
    "twice the samples "
    "a side (every old sample and the tip kept; a gridded surface, the fractal and the "
    "sandpapers, refined through the spline it is defined by: only the facets change). "
    "The change is paired: the refined runs' number "
    "minus the corner's own runs' from the same starts, like for like: the agreement "
    "change is the well-conditioned agreement's (what the target judges), on the paired "
    "starts well-conditioned on both sides; a start whose reference stalled at either level "
    "has no quasistatic answer there and leaves the pair (counted: stalled references). "
    "A headline is converged when it "
    "plus the change stays inside its own 95 % interval; where it does not, it is marked "
    "unconverged wherever it is quoted. Where the plan asks, the solver's tolerances are "
    "tightened a hundredfold (tolerance / 100: MuJoCo's 1e-8 and noslip 1e-6 to 1e-10 and "
    "1e-8)."
)


def convergence_lines(limit: QuasistaticLimitResult) -> list[str]:
    """The solution verification of the corner's headlines (empty where the plan refined
    nothing): per family and refinement the paired change of each headline and the verdict,
    and the observed order of the time step where three levels ran."""
    rows, orders = [], []
    for fam, conv in limit.convergence.items():
        for key, e in conv.items():
            if key in REFINEMENT_LABELS:
                rows.append(
                    {
                        "family": fam,
                        "refinement": REFINEMENT_LABELS[key],
                        "runs": e.get("runs", 0),
                        "stalled": e.get("reference_stalled", "-"),
                        "agreement_change": e.get("agreement_change"),
                        "median_frechet_change": e.get("median_frechet_change"),
                        "verdict": refinement_verdict(e),
                    }
                )
        for series in ("dt_order", "hfield_order"):
            for h, o in conv.get(series, {}).items():
                orders.append({"family": fam, "levels": series.split("_")[0], "headline": h, **o})
    if not rows:
        return []
    lines = [
        "### Solution verification: the corner under a finer step and a finer hfield",
        "",
        _CONVERGENCE_RULE,
        "",
        table(
            rows,
            [
                "family",
                "refinement",
                "runs",
                "stalled",
                "agreement_change",
                "median_frechet_change",
                "verdict",
            ],
            [
                "family",
                "refinement",
                "paired runs",
                "stalled references",
                "agreement change",
                "median Frechet change / L_c",
                "verdict",
            ],
        ),
        "",
    ]
    if orders:
        lines += [
            "Three step levels (dt, dt / 2, dt / 4) on the same starts, and three hfield levels "
            "(x 1, 2, 4) on a gridded surface: the observed order "
            "p = ln((f1 - f2) / (f2 - f3)) / ln 2 (undefined, `-`, where "
            "no run flipped or the changes alternate in sign), the Richardson estimate of "
            "the converged value and Roache's GCI, Fs |(f1 - f2) / f1| / (2^p - 1) (Fs 1.25; "
            "where no order is observed Fs 3 and the formal order 1: docs/physics.md §7, a "
            "semi-implicit Euler step adds a path error of first order in dt). With three levels "
            "a headline is converged only when its last change (finest minus middle level) "
            "also stays inside its interval.",
            "",
            table(
                orders,
                ["family", "levels", "headline", "order", "richardson", "gci"],
                ["family", "levels", "headline", "observed order", "Richardson estimate", "GCI"],
            ),
            "",
        ]
    return lines


def _corner_lines(limit: QuasistaticLimitResult) -> list[str]:
    """The corner each preset of each family is judged at, and why
    (:func:`spine_mj.theory.drive_limits.quasistatic_corner`)."""
    rows = [
        {
            "family": fam,
            "preset": preset,
            **corner,
            **({"reason": f"not run, no verdict: {c['refused']}"} if c.get("refused") else {}),
        }
        for fam, c in limit.corners.items()
        for preset, corner in c["presets"].items()
    ]
    left_out = {
        label: s["k_path_left_out"]
        for c in limit.corners.values()
        for label, s in c["surfaces"].items()
        if s.get("k_path_left_out")
    }
    if not rows:
        return [f"I_e = {limit.lowest_ie:g}, default drive (K = k l_s / F_p = 30).", ""]
    return [
        "Each surface runs at the corner its own predicted limits give (the rule "
        "`theory.drive_limits.quasistatic_corner`, docs/physics.md §8): K ten times its "
        "K_path (at least 30), I_e the lowest of a tenth of its I_e*, the spring's position "
        "swing at a tenth of the path tolerance and its force swing at 1 F_p; a preset's "
        "lowest I_e* and highest K_path over its generator variants."
        + (
            " K_path leaves out the path starts whose compliant path misses the rigid one at "
            "K* and 10 and 100 times it (a miss the spring cannot fix): "
            + ", ".join(f"{label} {n} of {CORNER_PATH_STARTS}" for label, n in left_out.items())
            + "."
            if left_out
            else ""
        ),
        "",
        table(
            rows,
            ["family", "preset", "ie", "K", "swing_fp", "reason"],
            ["family", "preset", "I_e", "K = k l_s / F_p", "swing / F_p", "why"],
        ),
        "",
    ]


def _lines(limit: QuasistaticLimitResult, boundary: BoundaryResult) -> list[str]:
    families = [
        {
            "family": k,
            "ok_n": f"{v['ok_runs']}/{v['runs']}",
            "stopped": ", ".join(f"{s} {n}" for s, n in v["failed_runs"].items()) or "none",
            **v,
            **_marked(v, limit.convergence.get(k)),
        }
        for k, v in limit.families.items()
    ]
    return [
        "## Quasistatic limit (spring drive, each family at its own corner)",
        "",
        *_corner_lines(limit),
        "Default engine. Like for "
        "like: each MuJoCo path is compared with the streamline traced on the surface its tip "
        "touches (a ball of the tip's radius on MuJoCo's hfield facets, exactly: "
        "`surfaces.BallOnFacets`), ending where the engine's run ends, with the same force "
        "cap on both sides (a path needing more than the cap times F_p is held). A run the "
        "engine stopped, or whose reference stalled, counts as a disagreement. Beside it: the "
        "comparison with the compliant-drive streamline of the run's spring on the same facets "
        "(docs/physics.md §7: what the spring itself does, jumps at folds, predicted; `-` where "
        "the plan leaves it out, as the quick plan does for its cost), with the "
        "streamline on the smooth surface, and the geometry part (smooth vs facet streamline).",
        "",
        table(
            families,
            [
                "family",
                "ok_n",
                "stopped",
                "outcome_agreement",
                "median_frechet",
                "mean_frechet",
                "outcome_agreement_compliant",
                "median_frechet_compliant",
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
                "outcome agr. (compliant ref.)",
                "median Frechet (compliant ref.)",
                "outcome agr. (smooth)",
                "median Frechet (smooth)",
                "geometry Frechet",
                "target met (this plan)",
            ],
        ),
        "",
        *verdicts_section(limit.families, limit.convergence),
        *convergence_lines(limit),
        *platform_line(platform_info()),
        *_stalled_note(limit),
        *_misses_note(limit),
        *falls_note(limit, boundary),
        *_variations_and_runs(limit),
    ]


def _variations_and_runs(limit: QuasistaticLimitResult) -> list[str]:
    """The settings varied on the single peak, and the per-run table (folded)."""
    return [
        "### What limits agreement: settings varied on the single peak",
        "",
        table(
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
        table(
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
                "ill_conditioned",
            ],
        ),
        "",
        "</details>",
        "",
    ]


def summary_lines(validation: dict) -> list[str]:
    """Per family at its corner: the outcome agreement, the median Frechet distance (each
    marked where unconverged) and the engine's stops."""
    lines = []
    for fam, summ in validation.get("limit_families", {}).items():
        stops = ", ".join(f"{k} {n}" for k, n in summ["failed_runs"].items()) or "none"
        conv = validation.get("convergence", {}).get(fam)
        at = (validation.get("corner") or {}).get(fam) or {"ie": validation["lowest_ie"], "K": 30.0}
        lines.append(
            f"I_e, K = {corner_text(at)}, {fam}: outcome agreement {summ['outcome_agreement']:.0%}"
            f"{unconverged_mark(conv, 'outcome_agreement')} of {summ['runs']}, median Frechet "
            f"{summ['median_frechet']:.3g} L_c{unconverged_mark(conv, 'median_frechet')}, "
            f"engine stops: {stops}"
        )
    return lines


#: A family's headline numbers and the keys of their intervals in ``limit_families``.
LIMIT_HEADLINES = (
    ("agreement_well_conditioned", "agreement_ci"),
    ("outcome_agreement", "outcome_agreement_ci"),
    ("median_frechet", "median_frechet_ci"),
)


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """Per family of the corner (``limit_families``) the numbers of :data:`LIMIT_HEADLINES`
    with their intervals (Wilson; bootstrap for the Frechet distance) and the family's
    ``meets_target`` as verdict, keyed ``limit.FAMILY.NAME``."""
    out: dict[str, Headline] = {}
    for fam, s in read_table("limit_families", validation.get("limit_families") or {}).items():
        s = read_table(f"limit_families.{fam}", s)
        verdict = s.get("meets_target")
        if verdict is not None and not isinstance(verdict, bool):
            raise SpineInputError(f"limit_families.{fam}.meets_target must be true or false, got {verdict!r}")
        for name, ci in LIMIT_HEADLINES:
            if name in s and ci in s:
                key, where = f"limit.{fam}.{name}", f"limit_families.{fam}."
                out[key] = Headline(
                    key, read_number(where + name, s[name]), read_interval(where + ci, s[ci]), verdict
                )
    return out


def section(limit: QuasistaticLimitResult, ctx: ReportContext) -> str:
    """The section; the note on gravity slides cites the boundary study's I_e* (none
    without that study's result)."""
    boundary = ctx.results.get("boundary", BoundaryResult(curves={}, ie_star={}, skip_rate={}, families=[]))
    fig = ctx.draw(_paths_figure, limit, "limit_paths.png")
    return assemble(
        "\n".join(_lines(limit, boundary)),
        image("Paths at the lowest I_e over the single peak and valley", fig),
    )
