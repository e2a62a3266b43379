"""``spine-mj surface ...``: make, import, preview and export rough surfaces."""

from __future__ import annotations

import json
import math

import click

from spine_mj.cli.app import _Group, check_suffix, main, refuse_options_not_for
from spine_mj.errors import SpineInputError, check_positive


@main.group(cls=_Group)
def surface():
    """Make, import, preview and export rough surfaces."""


@surface.command("list")
def surface_list():
    """List the surface presets in surfaces/."""
    from spine_mj import presets

    for name in presets.list_presets():
        click.echo(f"{name:24s} {presets.load_preset(name).description}")


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
@click.option(
    "--fill",
    type=click.Choice(["refuse", "harmonic", "nearest", "mean"]),
    default="refuse",
    show_default=True,
    help="Missing points in imported files.",
)
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

    from spine_mj import examples, presets, surface_io
    from spine_mj.atomic import all_or_none
    from spine_mj.plotting import save_figure, surface_preview

    if (preset is None) == (from_file is None):
        raise SpineInputError("give exactly one of PRESET or --from-file")
    if from_file is None:
        refuse_options_not_for(
            f"preset {preset!r} (not a file import)", ["fill", "no_level", "spacing", "channel"]
        )
    else:
        refuse_options_not_for("--from-file (an import, not a generator)", ["seed", "hurst", "sets"])
    if from_file is not None:
        surf = surface_io.import_topography(
            examples.resolve(from_file), channel=channel, fill=fill, level=not no_level, spacing_m=spacing
        )
    else:
        overrides = dict(presets.parse_override(s) for s in sets)
        if seed is not None:
            overrides["seed"] = seed
        if hurst is not None:
            overrides["hurst"] = hurst
        surf = presets.make_surface(preset, **overrides)
    if png:
        check_suffix(png, ".png", "--png")
    with all_or_none(output, png):
        surface_io.save_surface(surf, output)
        if png:
            save_figure(surface_preview(surf), png)
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

    from spine_mj import presets
    from spine_mj.plotting import save_figure, surface_preview

    check_suffix(output, ".png", "-o/--output")
    surf = presets.open_surface(surface_file)
    save_figure(surface_preview(surf), output)
    click.echo(f"wrote {output}")


@surface.command("info")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the PSD plot (.png).")
@click.option("--json", "as_json", is_flag=True, help="Print the numbers as JSON.")
@click.option("--mu", type=float, help="mu_s for the drive limits (default: the preset's).")
@click.option(
    "--tip-radius", type=float, default=0.0, show_default=True, help="Tip radius for the drive limits."
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
    from spine_mj.jsonio import to_jsonable

    if output:
        check_suffix(output, ".png", "-o/--output")
    surf = presets.open_surface(surface_spec)
    if mu is None and presets.preset_mu(surf) is None:  # no drive limits: nothing uses the tip
        refuse_options_not_for("surface info without a mu_s (no --mu, no preset's)", ["tip_radius"])
    rough = roughness.summarize(surf)
    limits = _drive_limits(surf, mu, tip_radius)
    if output:
        from spine_mj.plotting import roughness_figure, save_figure

        save_figure(roughness_figure(rough), output)
    if as_json:
        doc = dict(rough.as_dict(), drive_limits=None if limits is None else limits.as_dict())
        click.echo(json.dumps(to_jsonable(doc), indent=2))
        return
    unit = "" if surf.unit == "1" else f" {surf.unit}"
    click.echo(f"rms height               {rough.rms_height:.4g}{unit}")
    click.echo(f"rms slope                {rough.rms_slope:.4g}")
    click.echo(f"rms curvature            {rough.rms_curvature:.4g}{'' if not unit else ' 1/' + surf.unit}")
    click.echo(f"L_c (asperity length)    {rough.char_length:.4g}{unit}")
    click.echo(f"l_s (slope correlation)  {rough.slope_correlation_length:.4g}{unit}")
    hurst = f"{rough.hurst:.3g}" if math.isfinite(rough.hurst) else "not estimated (the PSD is no power law)"
    click.echo(f"Hurst estimate (PSD fit) {hurst}")
    if limits is None:
        click.echo("drive limits             give --mu (no preset mu_s)")
    else:
        click.echo(f"drive limits (mu_s {limits.mu:g})  {limits.sentence()}")
    if output:
        click.echo(f"wrote {output}")


def _drive_limits(surf, mu, tip_radius):
    """:func:`spine_mj.theory.drive_limits.drive_limits` of ``surf`` with the one mu rule
    (:func:`spine_mj.presets.resolve_mu`); None without a mu_s (info still reports the
    roughness)."""
    from spine_mj import presets
    from spine_mj.theory.drive_limits import drive_limits

    if mu is None and presets.preset_mu(surf) is None:
        return None
    mu = presets.resolve_mu(surf, mu, name="--mu")
    if not (math.isfinite(tip_radius) and tip_radius >= 0):
        raise SpineInputError(f"--tip-radius must be a finite number >= 0, got {tip_radius!r}")
    return drive_limits(surf, mu, tip_radius=tip_radius)


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
    from spine_mj.atomic import all_or_none
    from spine_mj.surfaces import LENGTH_UNITS_M, length_unit

    if not stl and not hfield:
        raise SpineInputError("nothing to export: give --stl and/or --hfield")
    if stl:
        check_suffix(stl, ".stl", "--stl")
    if hfield:
        check_suffix(hfield, ".npz", "--hfield")
    surf = presets.open_surface(surface_file)
    unit = length_unit(surf.unit)
    mm_scale = 1.0 if unit is None else LENGTH_UNITS_M[unit] / LENGTH_UNITS_M["mm"]
    scale = stl_scale if stl_scale is not None else mm_scale
    scale = check_positive("--stl-scale", scale)
    if base_thickness is not None:
        base_thickness = check_positive("--base", base_thickness)
    written = []
    with all_or_none(stl, hfield):
        if stl:
            mesh_opts = {"scale": scale, "base_thickness": base_thickness}
            if resolution:
                mesh_opts["resolution"] = resolution
            surface_io.write_stl(surf, stl, **mesh_opts)
            written.append(f"wrote {stl} (scale {scale:g})")
        if hfield:
            hf = surface_io.write_hfield(surf, hfield, resolution=resolution)
            written.append(f"wrote {hfield} ({hf.nrow} x {hf.ncol}, size {json.dumps(hf.size)})")
    click.echo("\n".join(written))
