"""The engagement theory's commands: ``kappa``, ``streamline`` and ``reproduce`` (the paper's figures)."""

from __future__ import annotations

from pathlib import Path

import click

from spine_mj.cli.app import Progress, check_suffix, main, parse_start, refuse_options_not_for


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

    import numpy as np

    from spine_mj import presets
    from spine_mj.plotting import kappa_map_figure, save_figure
    from spine_mj.surfaces import check_grid_size
    from spine_mj.theory import engagement

    check_suffix(output, ".png", "-o/--output")
    check_grid_size(resolution, resolution, where="kappa --resolution")
    surf = presets.open_surface(surface_spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    xs, _, heights, k, region = engagement.kappa_grid(surf, mu, resolution)
    fig = kappa_map_figure({surf.metadata.get("preset", "surface"): (xs, heights, k, region)}, mu)
    save_figure(fig, output)
    shares = ", ".join(f"{n} {100 * np.mean(region == c):.1f} %" for c, n in engagement.REGION_NAMES.items())
    click.echo(f"wrote {output} ({shares})")


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
    default=0.0,
    show_default=True,
    help="Spherical tip radius R; the tip centre rides the surface dilated by R.",
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
    from spine_mj.theory.streamline_outputs import trace_starts, write_streamline_outputs

    pts = [parse_start(s) for s in starts]
    surf = presets.open_surface(surface_spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    run = trace_starts(surf, pts, mu=mu, dl=dl, tip_radius=tip_radius)
    written = write_streamline_outputs(run, out_dir, fmt=fmt)
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
    from spine_mj.atomic import all_or_none
    from spine_mj.jsonio import write_json
    from spine_mj.plotting import save_figure

    options = {}
    if name == "fractal-hurst":
        options = {"workers": workers}
        if surfaces is not None:
            options["surfaces"] = surfaces
    else:
        refuse_options_not_for(f"reproduce {name}", ["surfaces", "workers"])
    with Progress(name) as bar:
        numbers, fig = reproduce.run(name, quick=quick, progress=bar.update, **options)
    out = Path(out_dir)
    with all_or_none(out / f"{name}.json", out / f"{name}.png"):
        write_json(out / f"{name}.json", numbers)
        save_figure(fig, out / f"{name}.png")
    click.echo(f"wrote {out / name}.json and {out / name}.png")
