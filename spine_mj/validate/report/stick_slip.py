"""The report of the stick-slip study (:mod:`spine_mj.validate.stick_slip`): drive-force
traces and slip-event statistics.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spine_mj.plotting import (
    new_figure,
    save_figure,
    sig,
    styled,
)
from spine_mj.theory.motion import SLIP_SPEED_FACTOR
from spine_mj.validate.report.common import ReportContext, assemble, cell, image, table
from spine_mj.validate.stick_slip import K_SCAN_SURFACE, SLIPS_PER_WAVE, StickSlipResult


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


def _lines(stick: StickSlipResult) -> list[str]:
    return [
        "## Stick-slip",
        "",
        f"Spring drive on {stick.surface}.",
        "",
        table(
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
        *k_scan_section(stick),
    ]


def k_scan_section(stick: StickSlipResult) -> list[str]:
    """The K-scan paragraph and tables: slip events against K / K* on a corrugation and
    where stick-slip gives way to sliding ([] without a scan)."""
    f = cell
    if not stick.k_scan:
        return []
    s, mu = K_SCAN_SURFACE
    lines = [
        f"**Slip events against K on a corrugation** (slope amplitude {s:g}, mu {mu:g}, K* = "
        f"{f(stick.k_star)} from the Prandtl-Tomlinson closed form). A slip is a stretch where the "
        f"tip outruns the carriage and reaches {SLIP_SPEED_FACTOR:g} V (docs/physics.md §6); steady "
        "sliding is no slip.",
        "",
        table(
            stick.k_scan,
            [
                "ie",
                "k_over_k_star",
                "slip_events",
                "events_per_wave",
                "onset_mean_fp",
                "stuck",
                "sliding",
                "slipping",
                "max_speed_v",
            ],
            [
                "I_e",
                "K / K*",
                "slips",
                "per wavelength",
                "mean onset (F_p)",
                "stuck",
                "sliding",
                "slipping",
                "max speed (V)",
            ],
        ),
        "",
        f"Where stick-slip (at least {SLIPS_PER_WAVE:g} slips per wavelength) gives way to steady "
        "sliding, against the prediction K*:",
        "",
        table(
            stick.transitions,
            ["ie", "k_low", "k_high", "over_k_star"],
            ["I_e", "last K with stick-slip", "first K sliding", "transition / K*"],
        ),
        "",
    ]
    return lines


def section(stick: StickSlipResult, ctx: ReportContext) -> str:
    fig = ctx.draw(_stick_figure, stick, "stick_slip.png")
    return assemble("\n".join(_lines(stick)), image("Drive force of the spring drive against time", fig))
