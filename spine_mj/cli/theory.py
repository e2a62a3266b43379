"""The engagement theory's commands: ``kappa``, ``streamline`` and ``reproduce`` (the paper's figures)."""

from __future__ import annotations

import click

from spine_mj.cli.app import (
    PREPARATION_DELAY_S,
    Progress,
    check_suffix,
    main,
    parse_start,
    refuse_options_not_for,
)


@main.command("kappa")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--mu", type=float, help="Static friction coefficient mu_s (default: the preset's).")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output PNG.")
@click.option(
    "--resolution", type=click.IntRange(min=8), default=301, show_default=True, help="Samples a side."
)
def kappa_cmd(surface_spec, mu, output, resolution):
    """Map the engagement ratio kappa over SURFACE (paper Fig. 2B): slip blank, self-lock
    dark red.

    \b
    Example:
      spine-mj kappa paper-single-peak --mu 1.2 -o map.png
    """

    from spine_mj import presets
    from spine_mj.reproduce import kappa_map_to
    from spine_mj.surfaces import check_grid_size

    check_suffix(output, ".png", "-o/--output")
    check_grid_size(resolution, resolution, where="kappa --resolution")
    surf = presets.open_surface(surface_spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    shares = kappa_map_to(output, surf, mu=mu, resolution=resolution)
    click.echo(f"wrote {output} ({', '.join(f'{n} {100 * f:.1f} %' for n, f in shares.items())})")


@main.command("streamline")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--mu", type=float, help="Static friction coefficient mu_s (default: the preset's).")
@click.option(
    "--start", "starts", multiple=True, required=True, metavar="X,Y", help="Start point, repeatable."
)
@click.option(
    "--dl", type=float, default=None, help="Step length (default: 1/1000 of the domain's shorter side)."
)
@click.option(
    "--tip-radius",
    type=float,
    default=None,
    help="Spherical tip radius R in the surface's length unit; the tip centre rides the surface "
    "dilated by R (default: the rig's default tip; 0: a point).",
)
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["parquet", "csv"]),
    default="parquet",
    show_default=True,
    help="Table format.",
)
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Output folder (streamlines.parquet|csv and streamlines.png).",
)
def streamline_cmd(surface_spec, mu, starts, dl, tip_radius, fmt, out_dir):
    """Quasistatic streamlines and ideal trajectories from each --start (paper Eq. 4):
    a table (one row per path point) and a PNG (3-D view and kappa along the paths).

    \b
    Example:
      spine-mj streamline paper-single-valley --mu 1.2 --start -3,-1 --start -3,-2 --out out/
    """

    from spine_mj import presets
    from spine_mj.sim.scales import resolve_tip_radius
    from spine_mj.theory.streamline_outputs import streamline_to

    pts = [parse_start(s) for s in starts]
    surf = presets.open_surface(surface_spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    tip_radius = resolve_tip_radius(surf, tip_radius, name="--tip-radius")
    with Progress("dilating by the tip", unit="row", delay_s=PREPARATION_DELAY_S) as bar:
        run, written = streamline_to(
            out_dir, surf, pts, mu=mu, fmt=fmt, dl=dl, tip_radius=tip_radius, progress=bar.update
        )
    for line in run.summary_lines():
        click.echo(line)
    click.echo(f"wrote {written[0]} and {written[1]}")


@main.command("reproduce")
@click.argument("name", type=click.Choice(["single-peak", "random-gaussian", "fractal-hurst", "kappa-map"]))
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Output folder for NAME.png and NAME.json.",
)
@click.option("--quick", is_flag=True, help="Reduced run (fewer surfaces and starts).")
@click.option(
    "--surfaces",
    type=click.IntRange(min=3),
    default=None,
    help="fractal-hurst: surfaces per H (default 300).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=2,
    show_default=True,
    help="fractal-hurst: worker processes.",
)
def reproduce_cmd(name, out_dir, quick, surfaces, workers):
    """Reproduce a figure of the paper: writes DIR/NAME.png and DIR/NAME.json.

    \b
    single-peak      Figs. 3-4: five starts, self-lock start-range ratios
    random-gaussian  Fig. 5: medians of max kappa, bypass / trap changes
    fractal-hurst    Figs. 7E, 9: self-lock rate and concavity shares vs H
    kappa-map        Fig. 2B: kappa over the single peak and valley

    \b
    Example:
      spine-mj reproduce single-peak --out repro/
    """

    from spine_mj import reproduce

    options = {}
    if name == "fractal-hurst":
        options = {"workers": workers}
        if surfaces is not None:
            options["surfaces"] = surfaces
    else:
        refuse_options_not_for(f"reproduce {name}", ["surfaces", "workers"])
    with Progress(name) as bar:
        written = reproduce.run_to(out_dir, name, quick=quick, progress=bar.update, **options)
    click.echo(f"wrote {written[0]} and {written[1]}")
