"""The MuJoCo rig's commands: ``simulate``, ``replay``, ``view`` and ``sim export``."""

from __future__ import annotations

import click

from spine_mj.choices import DEFAULT_ENGINE, ENGINES, PROTOCOLS, check_engine
from spine_mj.cli.app import (
    PREPARATION_DELAY_S,
    InputError,
    Progress,
    _Group,
    check_suffix,
    main,
    parse_start,
    refuse_options_not_for,
)
from spine_mj.errors import SpineInputError, check_positive


def _rig_options(f):
    """Options shared by `sim export`, `simulate` and `view` (tip, scale, engine)."""
    opts = [
        click.option(
            "--tip-radius",
            type=float,
            default=None,
            help="Tip radius in the surface's length unit (default: the rig's default tip: the "
            "surface's own, 2 spacings for a scan, else max(1 spacing, L_c / 100); 0, a point, "
            "is refused: the engine's tip is a ball).",
        ),
        click.option(
            "--mass", type=float, default=None, help="m_eff [kg] (default: the tip's, sim.TipParams)."
        ),
        click.option(
            "--mu",
            type=float,
            default=None,
            help="Friction coefficient mu_s > 0 (default: the preset's [engagement] mu; required "
            "for other surfaces).",
        ),
        click.option(
            "--preload",
            type=float,
            default=None,
            help="Extra downward preload [N] (default: the tip's, sim.TipParams: none).",
        ),
        click.option(
            "--length-scale",
            type=float,
            default=None,
            help="Metres per unit of a dimensionless surface (default 0.01).",
        ),
        click.option(
            "--resolution",
            type=int,
            default=None,
            help="hfield samples a side for analytic surfaces (default 201); a gridded surface "
            "keeps its own samples.",
        ),
        click.option("--timestep", type=float, default=None, help="Time step [s] (default: derived)."),
        click.option("--noslip", type=int, default=None, help="noslip_iterations (default 3)."),
        click.option("--impratio", type=float, default=None, help="impratio (default 1)."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _rig_inputs(
    surface_spec, tip_radius, mass, mu, preload, length_scale, resolution, timestep, noslip, impratio
):
    """The SURFACE argument and the shared rig options parsed: the surface
    (:func:`spine_mj.presets.open_surface`) and :func:`spine_mj.sim.build_rig`'s keywords
    (``mu`` resolved by the one mu rule)."""
    from spine_mj import presets
    from spine_mj.sim.scales import engine_tip_radius_m

    surf = presets.open_surface(surface_spec)
    return surf, {
        "mu": presets.resolve_mu(surf, mu, name="--mu"),
        "tip_radius_m": engine_tip_radius_m(
            surf, tip_radius, length_scale_m=length_scale, name="--tip-radius"
        ),
        "mass_kg": mass,
        "preload_n": preload,
        "length_scale_m": length_scale,
        "hfield_resolution": resolution,
        "timestep_s": timestep,
        "noslip_iterations": noslip,
        "impratio": impratio,
    }


def _with_drive(rig_kw: dict, **drive):
    """The :class:`~spine_mj.sim.RigInputs` of the shared rig options (:func:`_rig_inputs`)
    and a command's engine and drive."""
    from spine_mj.sim.rig_inputs import RigInputs

    return RigInputs.from_keywords(**rig_kw, **drive)


@main.group("sim", cls=_Group)
def sim_group():
    """The MuJoCo rig: export the model of a surface."""


@sim_group.command("export")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output .xml.")
@click.option(
    "--start",
    default=None,
    help="Where the tip rests, 'x0,y0' in surface units (default: a tenth in from the -x edge, mid y).",
)
@click.option("--stiffness", type=float, default=None, help="Spring stiffness [N/m] (default K = 30).")
@_rig_options
def sim_export(surface_spec, output, start, stiffness, **rig_opts):
    """Write a self-contained MJCF of the rig on SURFACE, ready for MuJoCo's viewer.

    The tip rests on the surface at --start (keyframe 'home', also the initial state),
    the spring is on with its target at the tip. Plain MJCF has no controller, so
    nothing moves by itself: in the viewer's Control panel move the 'spring' slider (the
    carriage's x, engine units) to pull the tip in x, or 'push' (a force, +-2 F_p).
    Press Backspace (reset) to return to the start. The camera 'follow' tracks the tip.
    Units are engine units: length L_c, force F_p, mass m (printed below).

    \b
    Example:
      spine-mj sim export paper-single-peak -o rig.xml && python -m mujoco.viewer --mjcf rig.xml
    """
    from spine_mj.sim.replay import export_rig

    check_suffix(output, ".xml", "-o/--output")
    if stiffness is not None:
        check_positive("--stiffness", stiffness)
    surf, rig_kw = _rig_inputs(surface_spec, **rig_opts)
    xy = None if start is None else parse_start(start)
    rig = export_rig(output, surf, start=xy, stiffness_n_m=stiffness, **rig_kw)
    u = rig.units
    click.echo(
        f"wrote {output} (hfield {rig.hfield.nrow} x {rig.hfield.ncol}, "
        f"dt {rig.engine.timestep_s:g} s, tip radius {rig.tip.tip_radius_m:g} m; "
        f"engine units: L_c = {u.length_m:g} m, F_p = {u.force_n:g} N, m = {u.mass_kg:g} kg)"
    )
    click.echo("in the viewer: Control panel, move 'spring' (carriage x) or 'push' to drive the tip")


#: ``--engine``'s help: the registered engines (:data:`spine_mj.choices.ENGINES`).
_ENGINE_HELP = (
    "Physics engine, one of " + "; ".join(f"{e.name} ({e.summary})" for e in ENGINES.values()) + "."
)


@main.command("simulate")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--start", required=True, help="Start 'x0,y0' in surface units, e.g. -3,-1.")
@click.option("--drive", type=click.Choice(PROTOCOLS), default="spring", show_default=True)
@click.option(
    "--ie",
    type=float,
    default=None,
    help="Inertia number I_e = m v^2 / (F_p L_c): sets the carriage speed (spring) or the "
    "force rate (ramp, static); default 1e-3 unless --speed or --rate is given.",
)
@click.option("--speed", type=float, default=None, help="Carriage speed [m/s] (spring; instead of --ie).")
@click.option(
    "--K",
    "stiffness_number",
    type=float,
    default=None,
    help="Drive stiffness number K = k l_s / F_p (l_s: slope correlation length; spring).",
)
@click.option(
    "--stiffness",
    type=float,
    default=None,
    help="Spring stiffness [N/m] (instead of --K; default K = 30).",
)
@click.option("--rate", type=float, default=None, help="Force rate [N/s] (ramp, static; instead of --ie).")
@click.option(
    "--start-force",
    type=float,
    default=0.0,
    show_default=True,
    help="Static probe: force [N] applied while the tip settles.",
)
@click.option("--duration", type=float, default=None, help="Run time [s] (spring, ramp).")
@click.option(
    "--engine",
    default=DEFAULT_ENGINE,
    show_default=True,
    help=_ENGINE_HELP,
)
@click.option(
    "--render",
    is_flag=True,
    help="Also write run.mp4 (headless: MUJOCO_GL=egl, else osmesa) with the tip's path, the "
    "streamline from the same start and the drive force.",
)
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Output folder (trajectory.parquet, summary.json, surface.npz, run.png, run.mp4).",
)
@click.option(
    "--line",
    is_flag=True,
    help="Hold the tip on its start line (y fixed; MuJoCo): a narrow strip or long track whose y "
    "slopes would carry the tip off it runs along x.",
)
@_rig_options
def simulate(
    surface_spec,
    start,
    drive,
    ie,
    speed,
    stiffness_number,
    stiffness,
    rate,
    start_force,
    duration,
    engine,
    render,
    out_dir,
    line,
    **rig_opts,
):
    """Run one drive on SURFACE: writes trajectory.parquet, run.png, summary.json (and run.mp4).

    Lengths, forces and times are SI; --ie and --K give the drive in dimensionless terms.

    \b
    Example:
      spine-mj simulate paper-single-peak --start -3,-1 --drive spring --ie 1e-3 --K 10 --out out/
    """
    from spine_mj.sim.run_folder import simulate_to

    check_engine(engine, "--engine")
    if render:
        _check_render(engine)
    xy = parse_start(start)
    _check_drive_options(
        drive, ie=ie, speed=speed, rate=rate, stiffness_number=stiffness_number, stiffness=stiffness
    )
    surf, rig_kw = _rig_inputs(surface_spec, **rig_opts)
    pace = {"ie": ie, "speed_m_s": speed, "rate_n_s": rate}
    inputs = _with_drive(
        rig_kw,
        engine=engine,
        stiffness_number=stiffness_number,
        stiffness_n_m=stiffness,
        line=line or None,  # None: an engine without the option is not asked for it
        **pace,
    )
    with (
        Progress("preparing", delay_s=PREPARATION_DELAY_S) as preparing,
        Progress("simulating", unit="%") as bar,
        Progress("rendering MP4", unit="frame", quiet=not render) as frames,
    ):

        def prepared(done, total, stage):
            preparing.update(done, total, stage)
            if done >= total:  # a stage's bar closes when it is done
                preparing.close()

        def rendering(done, total):
            bar.complete()  # the run is over (a run that broke away early too)
            bar.close()
            frames.update(done, total)

        result, written = simulate_to(
            out_dir,
            surf,
            inputs,
            start=xy,
            protocol=drive,
            duration_s=duration,
            start_force_n=start_force,
            mp4=render,
            progress=lambda frac: bar.update(round(100 * frac, 1), 100),
            render_progress=rendering,
            prepare_progress=prepared,
        )
        bar.complete()
    click.echo(
        f"end: {result.end_reason.value} ({result.end_detail}); I_e = {result.inertia_number:.3g}"
        + (f", K = {result.stiffness_number:.3g}" if drive == "spring" else "")
    )
    click.echo(_motion_line(result))
    click.echo(f"wrote {', '.join(str(w) for w in written)}")


def _check_render(engine: str) -> None:
    """Refuse --render where it cannot run (an engine whose rig is not a MuJoCo model, no
    video extra); choose the GL backend."""
    from spine_mj import extras
    from spine_mj.sim.model import has_mujoco_model
    from spine_mj.sim.render import choose_gl_backend

    if not has_mujoco_model(engine):
        raise SpineInputError(
            f"--render draws with MuJoCo's renderer, not with --engine {engine}: run without it, "
            "then `spine-mj replay RUN_DIR --mp4 run.mp4` shows the run on MuJoCo's model"
        )
    extras.require("video", "--render")
    choose_gl_backend()


def _check_drive_options(drive: str, *, ie, speed, rate, stiffness_number, stiffness) -> None:
    """Refuse the options --drive does not read, and pace or stiffness given twice."""
    refuse_options_not_for(
        f"--drive {drive}",
        {
            "spring": ["rate", "start_force"],
            "ramp": ["speed", "stiffness_number", "stiffness", "start_force"],
            "static": ["speed", "stiffness_number", "stiffness", "duration"],
        }[drive],
    )
    for a, b, names in ((ie, speed, "--ie or --speed"), (ie, rate, "--ie or --rate")):
        if a is not None and b is not None:
            raise SpineInputError(f"give one of {names}, got both")
    if stiffness_number is not None and stiffness is not None:
        raise SpineInputError("give one of --K or --stiffness, got both")
    if ie is not None:
        check_positive("--ie", ie)


def _motion_line(result) -> str:
    """One line on the run's motion relative to the drive: the time stuck, sliding and
    slipping, the slip events and the largest speed over the drive's."""
    s = result.slip_summary()
    frac = ", ".join(f"{k} {100 * v:.0f} %" for k, v in s["motion_fractions"].items())
    onsets = s["slip_onset_forces_fp"]
    slips = f"{s['slip_events']} slip events" + (f" (onset up to {max(onsets):.3g} F_p)" if onsets else "")
    return f"motion: {frac}; {slips}; largest speed {s['max_speed_over_drive']:.3g} V"


@main.command("replay")
@click.argument("run_dir", type=click.Path(file_okay=False, exists=True))
@click.option(
    "--speed", type=float, default=None, help="Playback speed, times real time (default: the run in ~10 s)."
)
@click.option("--duration", type=float, default=None, help="Close the viewer after this many seconds.")
@click.option(
    "--mp4", type=click.Path(dir_okay=False), default=None, help="Write this MP4 instead (headless)."
)
def replay(run_dir, speed, duration, mp4):
    """Play a run recorded by `spine-mj simulate` in MuJoCo's viewer (RUN_DIR: its --out).

    The tip moves through its recorded positions at the recorded times (times --speed),
    with its path so far (orange) and the streamline from the same start (cyan). Without a
    display, or with --mp4, it writes an MP4 instead (RUN_DIR/replay.mp4 by default).

    \b
    Example:
      spine-mj simulate paper-single-peak --start -3,-1 --out run/ && spine-mj replay run/
    """
    from spine_mj.sim.replay import replay_run

    with Progress("rendering MP4", unit="frame") as bar:
        done = replay_run(
            run_dir,
            speed=speed,
            duration_s=duration,
            mp4=mp4,
            notice=lambda text: click.echo(text, err=True),
            progress=bar.update,
        )
    if done.mp4 is not None:
        click.echo(f"wrote {done.mp4}")


@main.command("view")
@click.argument("surface_spec", metavar="SURFACE")
@click.option(
    "--start",
    default=None,
    help="Where the tip rests, 'x0,y0' in surface units (default: a tenth in from the -x edge, mid y).",
)
@click.option("--duration", type=float, default=None, help="Close the viewer after this many seconds.")
@_rig_options
def view(surface_spec, start, duration, **rig_opts):
    """Open the rig on SURFACE in MuJoCo's interactive viewer (needs a display).

    The model is the one `sim export` writes: the tip rests at --start with the spring on;
    drive it with the 'spring' (carriage x) or 'push' slider in the Control panel. It
    runs in physical real time, seen from the camera 'follow' (Esc: the free camera).
    To watch a recorded run instead, use `spine-mj replay RUN_DIR`.
    """

    from spine_mj.sim.replay import has_display, view_rig

    if duration is not None:
        check_positive("--duration", duration)
    if not has_display():
        raise InputError(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset): the viewer "
            "needs one; use `spine-mj sim export`, `simulate --render` or `replay --mp4`"
        )
    surf, rig_kw = _rig_inputs(surface_spec, **rig_opts)
    view_rig(surf, start=None if start is None else parse_start(start), duration_s=duration, **rig_kw)
