"""The report of the sandpaper study (:mod:`spine_mj.validate.sandpaper`): path waviness and
force peaks on the P36 / P60 / P600 analogs.
"""

from __future__ import annotations

from pathlib import Path

from spine_mj.plotting import (
    new_figure,
    save_figure,
    styled,
)
from spine_mj.validate.report.common import ReportContext, assemble, image, table
from spine_mj.validate.sandpaper import SandpaperResult


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


def _lines(sand: SandpaperResult) -> list[str]:
    if not sand.rows:
        return []
    return [
        "## Sandpaper analogs (25 um tip)",
        "",
        f"Spring drive, mu = {sand.mu:g} (assumed; the paper gives none for grit).",
        "",
        table(
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


def section(sand: SandpaperResult, ctx: ReportContext) -> str:
    fig = ctx.draw(_sand_figure, sand, "sandpaper.png")
    return assemble("\n".join(_lines(sand)), image("Sandpaper paths and drive force", fig))
