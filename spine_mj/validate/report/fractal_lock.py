"""The report of the fractal self-lock study (:mod:`spine_mj.validate.fractal_lock`): the
self-lock rate against the Hurst exponent, streamline beside MuJoCo.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.plotting import (
    new_figure,
    save_figure,
    sig,
    styled,
)
from spine_mj.validate.convergence import refinement_note, unconverged_mark
from spine_mj.validate.fractal_lock import MUJOCO_SERIES, SERIES, FractalLockResult
from spine_mj.validate.report.common import (
    Headline,
    ReportContext,
    assemble,
    cell,
    image,
    read_interval,
    read_number,
    read_table,
    refinement_rows,
    table,
)


#: Legend labels of the fractal study's series (:data:`spine_mj.validate.fractal_lock.SERIES`).
def _fractal_labels(fr: FractalLockResult) -> dict[str, str]:
    return {
        "streamline": "streamline (smooth surface, dilated by the tip)",
        "facets": "streamline (MuJoCo's facets, dilated by the tip)",
        "mujoco_corner": f"MuJoCo, spring, I_e = {sig(fr.corner_ie)}",
        "mujoco_dynamic": f"MuJoCo, spring, I_e = {sig(fr.dynamic_ie)}",
    }


@styled
def _fractal_figure(fr: FractalLockResult, path: Path) -> Path | None:
    """Self-lock rate against H, one series per counter, Wilson intervals as error bars
    (series side by side in H so that their bars do not hide each other)."""
    if not fr.rows:
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


def _lines(fr: FractalLockResult) -> list[str]:
    """The fractal self-lock table (rate, Wilson interval, locked / ok runs, failed runs
    per series and H) and one sentence on what it shows."""
    if not fr.rows:
        return []
    labels = _fractal_labels(fr)
    present = [s for s in SERIES if any(f"rate_{s}" in r for r in fr.rows)]
    rows = []
    for r in fr.rows:
        row = {"H": r["hurst"]}
        for s in present:
            row[s] = (
                f"{cell(r[f'rate_{s}'], 2)} [{cell(r[f'ci_low_{s}'], 2)}, {cell(r[f'ci_high_{s}'], 2)}] "
                f"({r[f'locked_{s}']}/{r[f'n_ok_{s}']}, failed {r[f'failed_runs_{s}']})"
                + refinement_note(r.get(f"convergence_{s}"))
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
        table(rows, ["H", *present], ["H", *(labels[s] for s in present)]),
        "",
        _fractal_sentence(fr),
        "",
        *_convergence_lines(fr),
    ]


def _convergence_lines(fr: FractalLockResult) -> list[str]:
    """The MuJoCo rates' solution verification (empty where the plan refined nothing)."""
    labels = _fractal_labels(fr)
    rows = [
        r
        for row in fr.rows
        for s in MUJOCO_SERIES
        if row.get(f"convergence_{s}")
        for r in refinement_rows(row[f"convergence_{s}"], H=row["hurst"], series=labels[s])
    ]
    if not rows:
        return []
    return [
        "### Solution verification of the MuJoCo rates",
        "",
        "Both MuJoCo series rerun on the first surfaces of every H under each refinement (each "
        "surface's own rig step halved, the contact's time constant kept); the change is "
        "paired (the refined runs' rate minus the same surfaces' own, over the surfaces both "
        "ran cleanly), converged when the rate plus the change stays inside its Wilson interval. "
        "A run the engine stopped on penetration is rerun at a quarter of its step and contact "
        "time constant (`spine_mj.sim.rig.REFINE_TIMESTEP`) on either side, and is paired as the "
        "rate counted it.",
        "",
        table(
            rows,
            ["H", "series", "refinement", "runs", "base", "refined", "change", "verdict"],
            [
                "H",
                "series",
                "refinement",
                "paired surfaces",
                "rate (same surfaces)",
                "refined",
                "change",
                "verdict",
            ],
        ),
        "",
    ]


def _fractal_sentence(fr: FractalLockResult) -> str:
    """What the table shows, from its numbers: the streamline's and MuJoCo's rates at the
    lowest and highest H, and whether their intervals overlap at every H."""
    first, last = fr.rows[0], fr.rows[-1]

    def ends(s):
        return f"{cell(first.get(f'rate_{s}'), 2)} -> {cell(last.get(f'rate_{s}'), 2)}"

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


#: The series whose rates are headlines (the facets' streamline is the report's alone).
HEADLINE_SERIES = ("streamline", "mujoco_corner", "mujoco_dynamic")


def summary_lines(validation: dict) -> list[str]:
    """Per H the self-lock rate of each series of :data:`HEADLINE_SERIES`, marked where
    unconverged."""
    lines = []
    for row in validation.get("fractal_lock_rate", {}).get("rows", []):
        rates = ", ".join(
            f"{k} {row[f'rate_{k}']:.2f} ({row[f'locked_{k}']}/{row[f'n_ok_{k}']})"
            + unconverged_mark(row.get(f"convergence_{k}"))
            for k in HEADLINE_SERIES
            if f"rate_{k}" in row
        )
        lines.append(f"fractal self-lock rate, H = {row['hurst']:g}: {rates}")
    return lines


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """Per H and series of :data:`HEADLINE_SERIES` the self-lock rate with its Wilson
    interval, keyed ``fractal_lock.H<hurst>.<series>``."""
    lock = read_table("fractal_lock_rate", validation.get("fractal_lock_rate") or {})
    rows = lock.get("rows", [])
    if not isinstance(rows, list):
        raise SpineInputError(f"fractal_lock_rate.rows must be a list, got {rows!r:.60}")
    out: dict[str, Headline] = {}
    for i, row in enumerate(rows):
        row = read_table(f"fractal_lock_rate.rows[{i}]", row)
        for series in HEADLINE_SERIES:
            if f"rate_{series}" in row:
                key = f"fractal_lock.H{row.get('hurst')}.{series}"
                where = f"fractal_lock_rate.rows[{i}]."
                value = read_number(where + f"rate_{series}", row[f"rate_{series}"])
                pair = [row.get(f"ci_low_{series}"), row.get(f"ci_high_{series}")]
                out[key] = Headline(key, value, read_interval(where + f"ci_low/high_{series}", pair))
    return out


def section(fr: FractalLockResult, ctx: ReportContext) -> str:
    fig = ctx.draw(_fractal_figure, fr, "fractal_lock_rate.png")
    return assemble(
        "\n".join(_lines(fr)),
        image(
            "Self-lock rate against the Hurst exponent H, streamline and MuJoCo, with Wilson intervals", fig
        ),
    )
