"""``spine-mj surface ...``: make, import, preview and export rough surfaces."""

from __future__ import annotations

import json
import math

import click

from spine_mj.cli.app import PREPARATION_DELAY_S, Progress, _Group, check_suffix, main, refuse_options_not_for
from spine_mj.cli.options import fill_option
from spine_mj.errors import SpineInputError


@main.group(cls=_Group)
def surface():
    """Make, import, preview and export rough surfaces."""


@surface.command("list")
def surface_list():
    """List the surface presets in surfaces/."""
    from spine_mj import presets

    for name, description in presets.preset_descriptions().items():
        click.echo(f"{name:24s} {description}")


@surface.command("make")
@click.argument("preset", required=False)
@click.option(
    "--from-file",
    "from_file",
    type=click.Path(dir_okay=False),
    help="Import a measured topography (x3p, opd, datx, plu, di, sur, ...; or example:plu-1.plu).",
)
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output .npz file.")
@click.option("--seed", type=click.IntRange(min=0), help="Override the preset's seed.")
@click.option("--hurst", type=float, help="Override the Hurst index (fractal presets).")
@click.option(
    "--set",
    "sets",
    multiple=True,
    metavar="KEY=VALUE",
    help="Override any generator parameter (TOML value), repeatable.",
)
@fill_option("Missing points in imported files.")
@click.option("--no-level", is_flag=True, help="Keep the tilt of an imported file.")
@click.option("--spacing", type=float, help="Resample an imported file to this spacing [m].")
@click.option("--channel", type=int, default=0, show_default=True, help="Data channel of an imported file.")
@click.option("--png", type=click.Path(dir_okay=False), help="Also write a PNG preview.")
def surface_make(preset, from_file, output, seed, hurst, sets, fill, no_level, spacing, channel, png):
    """Make a surface from PRESET (see `spine-mj surface list`) or import one with
    --from-file, and save it as .npz.

    \b
    Examples:
      spine-mj surface make paper-fractal --hurst 0.7 --seed 3 -o fractal.npz
      spine-mj surface make --from-file scan.plu --fill harmonic -o scan.npz
    """

    from spine_mj import presets

    if (preset is None) == (from_file is None):
        raise SpineInputError("give exactly one of PRESET or --from-file")
    if from_file is None:
        refuse_options_not_for(
            f"preset {preset!r} (not a file import)", ["fill", "no_level", "spacing", "channel"]
        )
    else:
        refuse_options_not_for("--from-file (an import, not a generator)", ["seed", "hurst", "sets"])
    overrides = dict(presets.parse_override(s) for s in sets)
    if seed is not None:
        overrides["seed"] = seed
    if hurst is not None:
        overrides["hurst"] = hurst
    if png:
        check_suffix(png, ".png", "--png")
    presets.make_surface_file(
        output,
        preset=preset,
        from_file=from_file,
        overrides=overrides,
        import_options={"channel": channel, "fill": fill, "level": not no_level, "spacing_m": spacing},
        png=png,
    )
    click.echo(f"wrote {output}" + (f" and {png}" if png else ""))


@surface.command("show")
@click.argument("surface_file")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output PNG.")
def surface_show(surface_file, output):
    """Write a PNG preview (height map and 3-D view) of SURFACE_FILE.

    \b
    Example:
      spine-mj surface show fractal.npz -o fractal.png
    """

    from spine_mj import presets, surface_io

    check_suffix(output, ".png", "-o/--output")
    surf = presets.open_surface(surface_file)
    surface_io.write_preview(surf, output)
    click.echo(f"wrote {output}")


@surface.command("info")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the PSD plot (.png).")
@click.option("--json", "as_json", is_flag=True, help="Print the numbers as JSON.")
@click.option("--mu", type=float, help="mu_s for the drive limits (default: the preset's).")
@click.option(
    "--tip-radius",
    type=float,
    default=None,
    help="Tip radius of the drive limits, in the surface's length unit (default: the rig's default "
    "tip; 0: a point).",
)
def surface_info(surface_spec, output, as_json, mu, tip_radius):
    """Roughness of SURFACE (preset, .npz or instrument file): rms height, slope and
    curvature, L_c, the slope correlation length l_s, a Hurst estimate and the PSD; and
    the predicted drive limits, "quasistatic needs K > ... and I_e < ..." (docs/physics.md
    §8), where mu_s is known (--mu or the preset's).

    \b
    Example:
      spine-mj surface info example:plu-1.plu --mu 0.5 -o psd.png
    """
    from spine_mj import presets, roughness

    if output:
        check_suffix(output, ".png", "-o/--output")
    surf = presets.open_surface(surface_spec)
    if mu is None and presets.preset_mu(surf) is None:  # no drive limits: nothing uses the tip
        refuse_options_not_for("surface info without a mu_s (no --mu, no preset's)", ["tip_radius"])
    with Progress("dilating by the tip", unit="row", delay_s=PREPARATION_DELAY_S) as bar:
        info = presets.surface_info(surf, mu=mu, tip_radius=tip_radius, psd_png=output, progress=bar.update)
    if as_json:
        click.echo(json.dumps(info.as_dict(), indent=2))
        return
    rough, limits = info.roughness, info.drive_limits
    unit = "" if info.unit == "1" else f" {info.unit}"
    click.echo(f"rms height               {rough.rms_height:.4g}{unit}")
    click.echo(f"rms slope                {rough.rms_slope:.4g}")
    click.echo(f"rms curvature            {rough.rms_curvature:.4g}{'' if not unit else ' 1/' + info.unit}")
    click.echo(f"L_c (asperity length)    {rough.char_length:.4g}{unit}")
    l_s = rough.slope_correlation_length
    l_s_text = f"{l_s:.4g}{unit}" if math.isfinite(l_s) else f"none: {rough.slope_correlation_note}"
    click.echo(f"l_s (slope correlation)  {l_s_text}")
    why = "a plane" if rough.slope_correlation_note == roughness.PLANE_NOTE else "the PSD is no power law"
    hurst = f"{rough.hurst:.3g}" if math.isfinite(rough.hurst) else f"not estimated ({why})"
    click.echo(f"Hurst estimate (PSD fit) {hurst}")
    if limits is None:
        click.echo("drive limits             give --mu (no preset mu_s)")
    else:
        click.echo(f"drive limits (mu_s {limits.mu:g})  {limits.sentence()}")
    if output:
        click.echo(f"wrote {output}")


@surface.command("export")
@click.argument("surface_file")
@click.option("--stl", type=click.Path(dir_okay=False), help="Watertight STL solid.")
@click.option(
    "--stl-scale",
    type=float,
    default=None,
    help="Multiply coordinates in the STL (default: the surface's length unit to mm for "
    "physical surfaces, 1 for dimensionless ones).",
)
@click.option(
    "--base",
    "base_thickness",
    type=float,
    default=None,
    help="STL base thickness below the lowest point (surface units).",
)
@click.option(
    "--hfield",
    type=click.Path(dir_okay=False),
    help="MuJoCo hfield data: .npz with `data` (nrow x ncol in [0, 1]), `size`, `pos`.",
)
@click.option(
    "--resolution", type=click.IntRange(min=4), default=None, help="Samples a side for analytic surfaces."
)
def surface_export(surface_file, stl, stl_scale, base_thickness, hfield, resolution):
    """Export SURFACE_FILE as an STL solid for printing and/or as MuJoCo hfield data.

    \b
    Example:
      spine-mj surface export fractal.npz --stl fractal.stl --hfield fractal-hfield.npz
    """

    from spine_mj import presets, surface_io

    if not stl and not hfield:
        raise SpineInputError("nothing to export: give --stl and/or --hfield")
    if stl:
        check_suffix(stl, ".stl", "--stl")
    if hfield:
        check_suffix(hfield, ".npz", "--hfield")
    surf = presets.open_surface(surface_file)
    scale, hf = surface_io.export_surface(
        surf,
        stl=stl,
        hfield=hfield,
        stl_scale=stl_scale,
        base_thickness=base_thickness,
        resolution=resolution,
    )
    written = [f"wrote {stl} (scale {scale:g})"] if stl else []
    if hfield:
        written.append(f"wrote {hfield} ({hf.nrow} x {hf.ncol}, size {json.dumps(hf.size)})")
    click.echo("\n".join(written))
