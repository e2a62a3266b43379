"""``spine-mj array``: many spines on one carriage, for gripper and climbing-robot designers."""

from __future__ import annotations

import click

from spine_mj.choices import ARRAY_DRIVES
from spine_mj.cli.app import main, parse_start, refuse_options_not_for
from spine_mj.cli.sim import _rig_inputs, _rig_options
from spine_mj.errors import check_positive


@main.command("array")
@click.argument("surface_spec", metavar="SURFACE")
@click.option(
    "--layout", "kind", type=click.Choice(["grid", "staggered", "random"]), default="grid", show_default=True
)
@click.option("--rows", type=int, default=2, show_default=True, help="Spines across the drive (y).")
@click.option("--cols", type=int, default=2, show_default=True, help="Spines along the drive (x).")
@click.option("--spacing", type=float, default=1.0, show_default=True, help="Distance between neighbours.")
@click.option(
    "--spacing-unit",
    type=click.Choice(["surface", "l_s", "L_c"]),
    default="L_c",
    show_default=True,
    help="Unit of --spacing: surface units, or the surface's l_s or L_c.",
)
@click.option(
    "--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Seed of the random layout."
)
@click.option(
    "--drive",
    type=click.Choice(ARRAY_DRIVES),
    default="speed",
    show_default=True,
    help="speed: the carriage moves at constant speed; force: a free carriage pulled by a rising force.",
)
@click.option(
    "--ie",
    type=float,
    default=None,
    help="Inertia number of the carriage's speed, or of the pull's rate per spine (force); default: "
    "the fastest pace whose predicted holding excess is 1 % of mu F_p (sim.array_ie).",
)
@click.option(
    "--K", "stiffness_number", type=float, default=None, help="Each spring's K = k l_s / F_p (default 30)."
)
@click.option(
    "--centre", default=None, help="Array centre 'x,y' (surface units; default: its rear a tenth in)."
)
@click.option("--duration", type=float, default=None, help="Run time [s] (speed; default: to the far edge).")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Output folder: curve.csv, spines.csv, summary.json, layout.png.",
)
@_rig_options
def array_cmd(
    surface_spec,
    kind,
    rows,
    cols,
    spacing,
    spacing_unit,
    seed,
    drive,
    ie,
    stiffness_number,
    centre,
    duration,
    out_dir,
    **rig_opts,
):
    """Run an array of spines on one carriage over SURFACE: how much it holds, and which spines lock.

    Writes the array's force-displacement curve (curve.csv), one row per spine (spines.csv),
    summary.json (n_spines, holding_force_n, holding_ratio = holding force / (N F_p), its
    predicted dynamic excess holding_excess_predicted, locked_spines) and layout.png (the
    layout on the surface with each spine's path). The default pace keeps the predicted
    excess (the spring-block swing read before let-go, the force-rate lag) within 1 % of
    mu F_p per spine.

    \b
    Example:
      spine-mj array corrugation --layout staggered --rows 2 --cols 3 --spacing 0.3 --drive force --out arr/
    """
    from spine_mj import sim
    from spine_mj.sim.array_outputs import array_to

    if kind != "random":
        refuse_options_not_for(f"--layout {kind}", ["seed"])
    if drive == "force":
        refuse_options_not_for("--drive force (a pull runs to its cap)", ["duration"])
    for name, value in (("--ie", ie), ("--K", stiffness_number)):
        if value is not None:
            check_positive(name, value)
    layout = sim.Layout(
        kind=kind, rows=rows, cols=cols, spacing=spacing, spacing_unit=spacing_unit, seed=seed
    )
    surf, rig_kw = _rig_inputs(surface_spec, **rig_opts)
    res, ie, written = array_to(
        out_dir,
        surf,
        layout,
        drive,
        centre=None if centre is None else parse_start(centre),
        started=lambda pace: click.echo(
            f"{layout.n_spines} spines, {drive} drive, I_e = {pace:g}: simulating ..."
        ),
        ie=ie,
        stiffness_number=stiffness_number,
        duration_s=duration,
        **rig_kw,
    )
    click.echo(
        f"holding force {res.holding_force_n:.4g} N ({res.holding_ratio:.4g} of the total preload, predicted "
        f"dynamic excess {res.holding_excess_predicted:.2g} per spine), "
        f"{res.locked_spines} of {res.n_spines} spines self-locked; end: {res.end_reason} ({res.end_detail})"
    )
    click.echo(f"wrote {', '.join(str(p) for p in written)}")
