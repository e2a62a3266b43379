"""``spine-mj hold``: will a spine hold on my surface? (:mod:`spine_mj.validate.hold`)."""

from __future__ import annotations

from pathlib import Path

import click

from spine_mj.cli.app import Progress, main
from spine_mj.cli.options import fill_option
from spine_mj.errors import SpineInputError


@main.command("hold")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--mu", type=float, help="Static friction coefficient mu_s (default: the preset's).")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(),
    help="Output folder: summary.json, report.md, hold.png, surface.npz, sweeps/ (resumable).",
)
@click.option(
    "--tip-radius",
    type=float,
    default=None,
    help="Tip radius in the surface's length unit (default: the rig's default tip; 0, a point, "
    "is refused: the engine's tip is a ball).",
)
@click.option(
    "--starts",
    type=int,
    default=40,
    show_default=True,
    help="MuJoCo starts (paired under refinement); more are added from the places where too "
    "few paired well-conditioned ones are left for a verdict, as far as --budget allows.",
)
@click.option(
    "--reference-starts",
    type=int,
    default=400,
    show_default=True,
    help="Places the quasistatic self-lock share is traced from.",
)
@click.option(
    "--budget",
    type=float,
    default=3600.0,
    show_default=True,
    help="Wall seconds from the start; the rest of the starts, a refinement level or a round of added "
    "starts predicted to end past them is not run (the corner's limits, the self-lock share and the "
    "first 12 starts' MuJoCo runs always run, and count).",
)
@click.option(
    "--workers", type=click.IntRange(min=1), default=None, help="Worker processes (default: all cores)."
)
@fill_option("Missing points of an instrument file (as `surface make --fill`).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def hold_cmd(surface_spec, mu, out_dir, tip_radius, starts, reference_starts, budget, workers, fill, quiet):
    """Will a spine hold on SURFACE (preset, .npz or instrument scan)? Chooses the drive's
    corner from the surface's own limits, traces the self-lock share with its interval,
    checks it in MuJoCo and refines until converged.

    \b
    Example:
      spine-mj hold example:di-1.di --mu 1.5 --out hold-afm
    """
    from spine_mj import presets
    from spine_mj.validate.hold import HoldSettings, hold_to

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SpineInputError(f"--out {out} exists and is not a folder")
    surf = presets.open_surface(surface_spec, fill=fill)
    settings = HoldSettings(
        mu=presets.resolve_mu(surf, mu, name="--mu"),
        tip_radius=tip_radius,
        starts=starts,
        reference_starts=reference_starts,
        budget_s=budget,
    )
    with Progress("hold", unit="case", quiet=quiet) as bar:
        summary = hold_to(
            surf,
            out,
            settings,
            label=surface_spec,
            workers=workers,
            progress=lambda p: bar.update(p.finished_cases, max(p.total_cases, 1), desc=f"hold: {p.step}"),
        )
    click.echo(summary["verdict"])
    click.echo(f"wrote {out / 'summary.json'}, {out / 'report.md'} ({summary['timings_s']['total']:.0f} s)")
