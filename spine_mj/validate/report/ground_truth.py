"""The report of the ground-truth study (:mod:`spine_mj.validate.ground_truth`): the
"Ground truth" section, each closed form beside what MuJoCo measured and its error.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.theory.motion import SLIP_SPEED_FACTOR, STUCK_SPEED_FRACTION
from spine_mj.validate.ground_truth import LIFTOFF_GAP_RADII, POINTS_PER_WAVE, TOMLINSON_IE, GroundTruthResult
from spine_mj.validate.report.common import ReportContext, cell, table

__all__ = ["ground_truth_section", "section"]


def _pct(v: float) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{100 * v:+.1f} %"


def section(gt: GroundTruthResult, ctx: ReportContext) -> str:
    return ground_truth_section(gt)


def ground_truth_section(gt: GroundTruthResult | None) -> str:
    """The section's Markdown ("" without a result)."""
    if gt is None:
        return ""
    f = cell
    b = gt.spring_block
    lines = [
        "## Ground truth for the dynamics",
        "",
        'MuJoCo\'s spring drive against three closed forms (docs/physics.md, "Ground truth"). '
        "Motion states are read relative to the drive's speed V: stuck below "
        f"{STUCK_SPEED_FRACTION:g} V; slipping in an interval where the tip outruns the carriage "
        f"(the spring unloads) that reaches {SLIP_SPEED_FACTOR:g} V; sliding otherwise.",
        "",
        f"**Spring-block on a flat plane** (k = 100 N/m, m = 10 g, V = 4 mm/s): period "
        f"{f(b['period_s'])} s against 2 pi / w = {f(b['period_predicted_s'])} s "
        f"({_pct(b['period_rel_error'])}); peak speed {f(b['peak_speed_v'])} V against 2 V "
        f"({_pct(b['peak_speed_rel_error'])}, the swing's mean plus its fundamental's amplitude); "
        f"slip events {b['slip_events']} (the swing is no slip).",
        "",
    ]
    lines += _spring_block_ladder(getattr(gt, "spring_block_ladder", []))
    lines += _tomlinson(gt.tomlinson)
    lines += _liftoff(gt.liftoff)
    return "\n".join(lines)


def _spring_block_ladder(rows: list[dict]) -> list[str]:
    """The step rule's check: the spring-block at K = 3 ... 30000 on a rig built for it."""
    if not rows:
        return []
    f = cell
    out = [
        "**The drive spring at any stiffness.** The engine step resolves the drive spring "
        "(omega dt <= 0.3, omega = sqrt(k / m); the contact keeps its time constant): the "
        "spring-block's period and peak speed from K = 3 to 30000, each run to completion.",
        "",
        "| K | omega dt | steps | period error | peak speed | peak speed error | end |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {f(r['stiffness_number_K'])} | {f(r['omega_dt'])} | {r['steps']} | "
            f"{_pct(r['period_rel_error'])} | {f(r['peak_speed_v'])} V | {_pct(r['peak_speed_rel_error'])} | "
            f"{r['end_reason']} |"
        )
    out += [
        "",
        "The period tests the step (its error grows as (omega dt)^2 / 24); the peak speed also "
        "tests the friction: on a soft spring the swing's force amplitude V sqrt(k m) is small "
        "beside mu W and MuJoCo's velocity-dependent friction rows flatten it.",
        "",
    ]
    return out


def _tomlinson(rows: list[dict]) -> list[str]:
    f = cell
    if not rows:
        return []
    below = [r for r in rows if r["k_over_k_star"] < 1]
    above = [r for r in rows if r["k_over_k_star"] >= 1]
    err = [
        abs(r["onset_max_rel_error"]) for r in below if math.isfinite(r.get("onset_max_rel_error", math.nan))
    ]
    out = [
        f"**Prandtl-Tomlinson on corrugations** (I_e = {TOMLINSON_IE:g}, {POINTS_PER_WAVE} hfield "
        "samples per wavelength, tip radius lambda / 100): K* = l_s max(-dkappa/dx) from the "
        "formula (tip radius included). Above K*: "
        f"{sum(r['slip_events'] for r in above)} slip events over {len(above)} runs, the largest speed "
        f"{f(max((r['max_speed_v'] for r in above), default=math.nan))} V. Below K*: "
        f"{f(np.mean([r['events_per_wave'] for r in below]) if below else math.nan)} events per "
        f"wavelength on average; the largest onset force within {f(100 * max(err, default=math.nan))} % "
        "of W kappa at the fold. The mean onset is lower where a jump overshoots past the next "
        "fold (inertia): the tip then reloads and jumps below the fold's force. The reference "
        "integrator (spine_mj.theory.tomlinson_dynamics: a rigid point tip on the smooth profile with "
        "Coulomb friction, the same m, k, W, V) overshoots too: below about 0.35 K* Coulomb "
        "friction cannot stop a jump within a wavelength at any speed, so one event per "
        "wavelength at the fold's force is not reachable there by correct rigid-body dynamics "
        "(docs/physics.md, section 6).",
        "",
        table(
            rows,
            [
                "slope_amplitude",
                "mu",
                "k_star",
                "k_over_k_star",
                "slip_events",
                "events_per_wave",
                "fold_kappa",
                "onset_max_fp",
                "onset_max_rel_error",
                "onset_mean_rel_error",
                "max_speed_v",
                "stuck_fraction",
                "ref_events_per_wave",
                "ref_onset_max_rel_error",
                "ref_onset_mean_rel_error",
                "ref_max_jump_waves",
            ],
            [
                "s",
                "mu",
                "K*",
                "K / K*",
                "slips",
                "per wavelength",
                "fold kappa",
                "max onset (F_p)",
                "max onset error",
                "mean onset error",
                "max speed (V)",
                "stuck",
                "reference per wavelength",
                "reference max onset error",
                "reference mean onset error",
                "reference longest jump (lambda)",
            ],
        ),
        "",
    ]
    return out


def _liftoff(rows: list[dict]) -> list[str]:
    f = cell
    if not rows:
        return []
    out = [
        "**Lift-off over a Gaussian ridge** (height 0.5 L_c, stiff spring K = 300 so the tip "
        "crosses the crest near the carriage's speed): predicted I_e* = 1 / (L_c c), c the "
        "crest curvature of the tip centre's path, 1 / (sigma^2 / A + r). A run left the crest "
        f"when its centre rose more than {LIFTOFF_GAP_RADII:g} tip radii above the path within "
        "half a width of the crest; I_e is that of the speed measured at the crest. The "
        "approach gap is the largest hop on the flat before the ridge (the harness's own noise).",
        "",
    ]
    table_rows = []
    for r in rows:
        table_rows.append(
            {
                "width": r["width"],
                "ie_star_predicted": r["ie_star_predicted"],
                "last_held": r["last_held_crest_ie"],
                "first_left": r["first_liftoff_crest_ie"],
                "ratio": f"{f(r['ratio_low'])} - {f(r['ratio_high'])}",
                "gaps": ", ".join(
                    f"{f(ie)}: {f(g)}" for ie, g in zip(r["crest_ie_values"], r["crest_gap_radii"])
                ),
                "approach": f(max(r["approach_gap_radii"], default=math.nan)),
            }
        )
    out += [
        table(
            table_rows,
            ["width", "ie_star_predicted", "last_held", "first_left", "ratio", "gaps", "approach"],
            [
                "width sigma (L_c)",
                "predicted I_e*",
                "last crest I_e held",
                "first crest I_e left",
                "measured / predicted",
                "crest I_e: gap (tip radii)",
                "max approach gap",
            ],
        ),
        "",
    ]
    return out
