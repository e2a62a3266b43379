"""The ``spine-mj`` command line (click).

Bad input ends in one line ``Error: ...`` on stderr and exit code 2, never a traceback;
outputs are written atomically, so a failed command leaves nothing half-written.
Printing and progress bars live here; the library reports through return values and
callbacks.
"""

from __future__ import annotations

import json
import os
import signal
import sys
from pathlib import Path

import click
import numpy as np
import pandas as pd
from tqdm import tqdm

from spine_mj import engagement, extras, presets, reproduce, roughness, sim, surface_io, validate
from spine_mj import sweep as sw
from spine_mj.engagement import kappa
from spine_mj.errors import SpineInputError, all_or_none, atomic_output, check_positive
from spine_mj.jsonio import to_jsonable, write_json
from spine_mj.plotting import (
    kappa_map_figure,
    roughness_figure,
    save_figure,
    sim_run_figure,
    streamline_figure,
    surface_preview,
)
from spine_mj.sim.model import compile_spec
from spine_mj.sim.render import FPS, choose_gl_backend, default_speed, render_frames
from spine_mj.sim.replay import load_run, play_in_viewer, run_in_viewer
from spine_mj.streamline import StreamlineParams, dilate, ideal_trajectories, streamlines
from spine_mj.surfaces import LENGTH_UNITS_M, check_grid_size, length_unit, to_hfield

INPUT_ERROR_EXIT = 2


class Progress:
    """The CLI's one progress display: a tqdm bar on stderr, or nothing with ``quiet``.

    ``update(done, total, desc=None, **postfix)`` moves the bar to ``done`` of ``total``
    (a new ``desc`` starts a fresh bar); used as a context manager it closes the bar.
    """

    def __init__(self, desc: str, *, unit: str = "it", quiet: bool = False):
        self.desc, self.unit, self.quiet, self.bar = desc, unit, quiet, None

    def update(self, done: float, total: float, desc: str | None = None, **postfix) -> None:
        if self.quiet:
            return
        if self.bar is not None and desc is not None and desc != self.bar.desc:
            self.close()
        if self.bar is None:
            tqdm.monitor_interval = 0  # no monitor thread: a single-threaded CLI forks its workers
            self.bar = tqdm(
                total=total, desc=desc or self.desc, unit=self.unit, dynamic_ncols=True, file=sys.stderr
            )
        self.bar.total = total
        self.bar.n = done
        if postfix:
            self.bar.set_postfix(postfix, refresh=False)
        self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class InputError(click.ClickException):
    """A :class:`SpineInputError` (or unreadable file) shown as one line, exit code 2."""

    exit_code = INPUT_ERROR_EXIT


#: The usage error by which a group given no arguments shows its help (click >= 8.2).
_SHOWS_HELP = tuple(e for e in [getattr(click.exceptions, "NoArgsIsHelpError", None)] if e)


class _Group(click.Group):
    """Turns the library's input errors and click's usage errors into :class:`InputError`
    (one line) for every subcommand, and so too a request too large for memory or out of
    floating-point range that no check at the boundary caught (not a traceback)."""

    def invoke(self, ctx):
        try:
            # numpy's overflow and invalid-value warnings would print lines before the one
            # error line; results are checked for finiteness where it matters
            with np.errstate(all="ignore"):
                return super().invoke(ctx)
        except _SHOWS_HELP:
            raise
        except click.UsageError as exc:  # click's own: usage, hint and error in one line
            hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
            raise InputError(exc.format_message() + hint) from None
        except SpineInputError as exc:
            root = ctx.find_root()
            if exc.details and root.params.get("verbose"):
                click.echo(exc.details, err=True)
            raise InputError(str(exc)) from None
        except OSError as exc:
            where = f": {exc.filename}" if exc.filename is not None else " (the system named no file)"
            raise InputError(f"{exc.strerror or exc}{where}") from None
        except MemoryError as exc:  # the checks at the boundary missed a size: still one line
            raise InputError(
                f"not enough memory for this request ({exc or 'MemoryError'}): a size, resolution or "
                "duration is too large, or a length too small for the surface"
            ) from None
        except (OverflowError, RecursionError) as exc:
            raise InputError(
                f"a value is out of range ({type(exc).__name__}: {exc}); check the parameters given"
            ) from None


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="spine_mj")
@click.option("-v", "--verbose", is_flag=True, help="Show the full text behind an error (e.g. a reader's).")
def main(verbose):
    """spine_mj: streamline theory and MuJoCo dynamics of bio-inspired spines on rough
    surfaces."""


def run() -> None:
    """The ``spine-mj`` program: :func:`main`, with a SIGTERM (kill, timeout, a scheduler)
    unwinding like Ctrl-C so that temporary outputs are removed. Callers of :func:`main`
    in their own process (tests, notebooks) keep their signal handling."""
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    main()


def _exit_on_sigterm(signum, frame):
    """SIGTERM's handler: exit as a kill would (128 + signal), through every ``finally``."""
    raise SystemExit(128 + signum)


# --------------------------------------------------------------------------- surface


@main.group(cls=_Group)
def surface():
    """Make, import, preview and export rough surfaces."""


def load_surface_arg(spec: str):
    """A SURFACE argument: a saved .npz, a preset name, or an instrument file."""

    path = Path(spec)
    if path.suffix == ".npz":
        return surface_io.load_surface(path)
    if spec in presets.list_presets() or path.suffix == ".toml":
        return presets.make_surface(spec)
    if path.is_file():
        return surface_io.import_topography(path)
    raise SpineInputError(
        f"SURFACE must be a .npz file, a preset ({', '.join(presets.list_presets())}) or an "
        f"instrument file, got {spec!r}"
    )


@surface.command("list")
def surface_list():
    """List the surface presets in surfaces/."""

    for name in presets.list_presets():
        click.echo(f"{name:24s} {presets.load_preset(name).description}")


@surface.command("make")
@click.argument("preset", required=False)
@click.option(
    "--from-file",
    "from_file",
    type=click.Path(dir_okay=False),
    help="Import a measured topography (x3p, opd, datx, plu, di, sur, ...).",
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

    if (preset is None) == (from_file is None):
        raise SpineInputError("give exactly one of PRESET or --from-file")
    if from_file is not None:
        surf = surface_io.import_topography(
            from_file, channel=channel, fill=fill, level=not no_level, spacing_m=spacing
        )
    else:
        overrides = dict(presets.parse_override(s) for s in sets)
        if seed is not None:
            overrides["seed"] = seed
        if hurst is not None:
            overrides["hurst"] = hurst
        surf = presets.make_surface(preset, **overrides)
    if png:
        _check_suffix(png, ".png", "--png")
    with all_or_none(output, png):
        surface_io.save_surface(surf, output)
        if png:
            save_figure(surface_preview(surf), png)
    click.echo(f"wrote {output}" + (f" and {png}" if png else ""))


def _check_suffix(path: str, suffix: str, option: str) -> None:
    if Path(path).suffix.lower() != suffix:
        raise SpineInputError(f"{option} must name a {suffix} file, got {path!r}")


@surface.command("show")
@click.argument("surface_file")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output PNG.")
def surface_show(surface_file, output):
    """Write a PNG preview (height map and 3-D view) of SURFACE_FILE.

    \b
    Example:
      spine-mj surface show fractal.npz -o fractal.png
    """

    _check_suffix(output, ".png", "-o/--output")
    surf = load_surface_arg(surface_file)
    save_figure(surface_preview(surf), output)
    click.echo(f"wrote {output}")


@surface.command("info")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the PSD plot (.png).")
@click.option("--json", "as_json", is_flag=True, help="Print the numbers as JSON.")
def surface_info(surface_spec, output, as_json):
    """Roughness of SURFACE (preset, .npz or instrument file): rms height, slope and
    curvature, L_c, the slope correlation length l_s, a Hurst estimate and the PSD.

    \b
    Example:
      spine-mj surface info tests/data/plu-1.plu -o psd.png
    """
    if output:
        _check_suffix(output, ".png", "-o/--output")
    surf = load_surface_arg(surface_spec)
    rough = roughness.summarize(surf)
    if output:
        save_figure(roughness_figure(rough), output)
    if as_json:
        click.echo(json.dumps(to_jsonable(rough.as_dict()), indent=2))
        return
    unit = "" if surf.unit == "1" else f" {surf.unit}"
    click.echo(f"rms height               {rough.rms_height:.4g}{unit}")
    click.echo(f"rms slope                {rough.rms_slope:.4g}")
    click.echo(f"rms curvature            {rough.rms_curvature:.4g}{'' if not unit else ' 1/' + surf.unit}")
    click.echo(f"L_c (asperity length)    {rough.char_length:.4g}{unit}")
    click.echo(f"l_s (slope correlation)  {rough.slope_correlation_length:.4g}{unit}")
    hurst = f"{rough.hurst:.3g}" if np.isfinite(rough.hurst) else "not estimated (the PSD is no power law)"
    click.echo(f"Hurst estimate (PSD fit) {hurst}")
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

    if not stl and not hfield:
        raise SpineInputError("nothing to export: give --stl and/or --hfield")
    if stl:
        _check_suffix(stl, ".stl", "--stl")
    if hfield:
        _check_suffix(hfield, ".npz", "--hfield")
    surf = load_surface_arg(surface_file)
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
            hf = to_hfield(surf, ncol=resolution, nrow=resolution) if resolution else to_hfield(surf)
            with atomic_output(hfield) as tmp, open(tmp, "wb") as fh:
                np.savez(
                    fh,
                    data=hf.data,
                    size=np.asarray(hf.size),
                    pos=np.asarray(hf.pos),
                    unit=np.array(surf.unit),
                )
            written.append(f"wrote {hfield} ({hf.nrow} x {hf.ncol}, size {json.dumps(hf.size)})")
    click.echo("\n".join(written))


# --------------------------------------------------------------------------- sweep (issue 5)


class _SweepGroup(_Group):
    """`sweep CONFIG.toml ...` runs a sweep; `sweep status DIR` is a subcommand."""

    def parse_args(self, ctx, args):
        if args and args[0] not in self.commands and args[0] not in ctx.help_option_names:
            args = ["run", *args]
        return super().parse_args(ctx, args)

    def format_options(self, ctx, formatter):
        """The group's help lists the options of `sweep run`, the command it runs by default."""
        super().format_options(ctx, formatter)
        run = self.commands["run"]
        opts = [p for p in run.params if isinstance(p, click.Option)]
        records = [r for r in (p.get_help_record(ctx) for p in opts) if r]
        with formatter.section("Options of `sweep CONFIG.toml` (sweep run)"):
            formatter.write_dl(records)


@main.group(cls=_SweepGroup)
def sweep():
    """Batch sweeps: `spine-mj sweep CONFIG.toml --out DIR` runs (or resumes) a sweep,
    `spine-mj sweep status DIR` tells how far it got.

    \b
    Examples:
      spine-mj sweep analysis/sweeps/paper-quasistatic.toml --out runs/qs
      spine-mj sweep config.toml --out runs/x --scheduler tcp://head:8786
      spine-mj sweep status runs/qs
    """


@sweep.command("run")
@click.argument("config", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Result store folder (resumed if it holds this config's sweep).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Local worker processes [default: all cores; at most 4 per core].",
)
@click.option(
    "--scheduler", metavar="ADDRESS", help="Run on a Dask distributed cluster (e.g. tcp://head:8786)."
)
@click.option(
    "--overwrite",
    is_flag=True,
    help="Replace a store in --out that holds another config's sweep or one computed on changed "
    "inputs (removes only the files the store wrote).",
)
@click.option("--retry-failed", is_flag=True, help="Run again the cases with failed runs.")
@click.option(
    "--worker-wait",
    type=float,
    default=sw.DEFAULT_WORKER_WAIT_S,
    show_default=True,
    metavar="SECONDS",
    help="With --scheduler: how long to wait for its first worker before giving up.",
)
@click.option("--quiet", is_flag=True, help="No progress bar.")
def sweep_run(config, out_dir, workers, scheduler, overwrite, retry_failed, worker_wait, quiet):
    """Run the sweep CONFIG (TOML) into --out; re-running resumes and skips finished runs.

    \b
    Example:
      spine-mj sweep analysis/sweeps/paper-quasistatic.toml --out runs/qs --workers 4
    """

    if scheduler is None:
        _refuse_options_not_for("a sweep without --scheduler", ["worker_wait"])
    cfg = sw.load_config(config)
    with Progress(cfg.name, unit="case", quiet=quiet) as bar:
        try:
            summary = sw.run_sweep(
                cfg,
                out_dir,
                workers=workers,
                scheduler=scheduler,
                overwrite=overwrite,
                retry_failed=retry_failed,
                progress=lambda p: bar.update(
                    p.finished_cases + p.skipped_cases, p.total_cases, ok=p.ok_runs, failed=p.failed_runs
                ),
                worker_wait_s=worker_wait,
                notice=lambda text: click.echo(text, err=True),
            )
        except sw.SchedulerUnavailable as exc:  # the environment: exit code 1
            raise click.ClickException(str(exc)) from None
        except sw.WorkersCannotStart as exc:  # the environment, not the input: exit code 1
            raise click.ClickException(f"{exc}; the finished cases are kept, a re-run resumes") from None
    if summary.rerun_corrupt:
        click.echo(
            f"ran again {len(summary.rerun_corrupt)} case(s) whose stored rows could not be read: "
            + ", ".join(summary.rerun_corrupt[:10])
            + (" ..." if len(summary.rerun_corrupt) > 10 else "")
        )
    where = (
        f"scheduler {scheduler}"
        if scheduler
        else f"{summary.workers} worker{'s' if summary.workers != 1 else ''}"
    )
    click.echo(
        f"{cfg.name}: {summary.total_runs} runs in {summary.total_cases} cases; "
        f"done {summary.ok_runs}, failed {summary.failed_runs}, skipped "
        f"{summary.skipped_runs} (finished before); {summary.elapsed_s:.1f} s on {where}"
    )
    bad = {k: v for k, v in summary.status_counts.items() if k != "ok"}
    if bad:
        click.echo(
            "not ok in the store: "
            + ", ".join(f"{k} {v}" for k, v in sorted(bad.items()))
            + f" (see {Path(out_dir) / 'runs.parquet'}, column reason)"
        )
    click.echo(f"wrote {Path(out_dir) / 'runs.parquet'}")


@sweep.command("status")
@click.argument("out_dir", metavar="DIR", type=click.Path(file_okay=False))
def sweep_status(out_dir):
    """How far the sweep in DIR got: finished cases and runs by status.

    \b
    Example:
      spine-mj sweep status runs/qs
    """

    st = sw.store_status(out_dir)
    runs = sum(st.status_counts.values())
    click.echo(
        f"{st.name} (config {st.config_hash[:12]}, created {st.created}, "
        f"{st.sessions} session{'s' if st.sessions != 1 else ''})"
    )
    click.echo(
        f"cases {st.finished_cases}/{st.total_cases}, runs {runs}/{st.total_runs}"
        + (" - complete" if st.complete else " - unfinished: run the same command again")
    )
    for status, n in sorted(st.status_counts.items()):
        click.echo(f"  {status:18s} {n}")
    if st.corrupt_cases:
        click.echo(
            f"corrupt case files ({len(st.corrupt_cases)}, run again by a resume): "
            + ", ".join(f"runs/{c}.parquet" for c in st.corrupt_cases)
        )


@main.command("report")
@click.argument("out_dir", metavar="DIR", type=click.Path(file_okay=False))
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output .html file.")
def report(out_dir, output):
    """Write an HTML report of the sweep in DIR: runs by status, metric tables and plots of
    the metrics against the swept parameters.

    \b
    Example:
      spine-mj report runs/qs -o qs-report.html
    """

    _check_suffix(output, ".html", "-o/--output")
    sw.write_report(out_dir, output)
    click.echo(f"wrote {output}")


# --------------------------------------------------------------------------- end sweep


# --------------------------------------------------------------------------- MuJoCo rig (issue 4)


def _rig_options(f):
    """Options shared by `sim export`, `simulate` and `view` (tip, scale, engine)."""
    opts = [
        click.option(
            "--tip-radius",
            type=float,
            default=None,
            help="Tip radius [m] (default: the surface's own, 2 spacings for a scan, else "
            "max(1 spacing, L_c / 100)).",
        ),
        click.option("--mass", type=float, default=0.01, show_default=True, help="m_eff [kg]."),
        click.option(
            "--mu",
            type=float,
            default=None,
            help="Friction coefficient mu_s (default: the preset's [engagement] mu, else 0.5).",
        ),
        click.option(
            "--preload", type=float, default=0.0, show_default=True, help="Extra downward preload [N]."
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
            help="hfield samples a side for analytic surfaces (default 201).",
        ),
        click.option("--timestep", type=float, default=None, help="Time step [s] (default: derived)."),
        click.option("--noslip", type=int, default=None, help="noslip_iterations (default 3)."),
        click.option("--impratio", type=float, default=None, help="impratio (default 1)."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _build_rig(
    surface_spec,
    tip_radius,
    mass,
    mu,
    preload,
    length_scale,
    resolution,
    timestep,
    noslip,
    impratio,
    *,
    ie=None,
    speed=None,
):
    """The rig of the shared rig options; ``ie`` or ``speed`` (the drive's) bound the engine
    step for impacts (:func:`spine_mj.sim.default_engine`)."""

    surf = load_surface_arg(surface_spec)
    mu = presets.preset_mu(surf) if mu is None else mu
    tip = sim.TipParams(
        tip_radius_m=tip_radius, mass_kg=mass, preload_n=preload, **({} if mu is None else {"mu_s": mu})
    )
    overrides = {
        k: v
        for k, v in (
            ("timestep_s", timestep),
            ("noslip_iterations", noslip),
            ("impratio", impratio),
            ("hfield_resolution", resolution),
        )
        if v is not None
    }
    scales = sim.Scales.for_surface(surf, tip=tip, length_scale_m=length_scale, hfield_resolution=resolution)
    if ie is not None:
        speed = scales.speed_for(check_positive("--ie", ie))
    engine = sim.default_engine(scales, speed_m_s=speed, **overrides)
    return sim.Rig(surf, tip=tip, length_scale_m=length_scale, engine=engine)


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
    _check_suffix(output, ".xml", "-o/--output")
    rig = _build_rig(surface_spec, **rig_opts)
    xy = None if start is None else _parse_start(start)
    if stiffness is not None:
        check_positive("--stiffness", stiffness)
    rig.export_xml(output, start=xy, stiffness_n_m=stiffness)
    u = rig.units
    click.echo(
        f"wrote {output} (hfield {rig.hfield.nrow} x {rig.hfield.ncol}, "
        f"dt {rig.engine.timestep_s:g} s, tip radius {rig.tip.tip_radius_m:g} m; "
        f"engine units: L_c = {u.length_m:g} m, F_p = {u.force_n:g} N, m = {u.mass_kg:g} kg)"
    )
    click.echo("in the viewer: Control panel, move 'spring' (carriage x) or 'push' to drive the tip")


@main.command("simulate")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--start", required=True, help="Start 'x0,y0' in surface units, e.g. -3,-1.")
@click.option("--drive", type=click.Choice(["spring", "ramp", "static"]), default="spring", show_default=True)
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
    render,
    out_dir,
    **rig_opts,
):
    """Run one drive on SURFACE: writes trajectory.parquet, run.png, summary.json (and run.mp4).

    Lengths, forces and times are SI; --ie and --K give the drive in dimensionless terms.

    \b
    Example:
      spine-mj simulate paper-single-peak --start -3,-1 --drive spring --ie 1e-3 --K 10 --out out/
    """

    if render:
        extras.require("video", "--render")
        choose_gl_backend()

    x0, y0 = _parse_start(start)
    _refuse_options_not_for(
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
    if ie is None and speed is None and rate is None:
        ie = 1e-3
    rig = _build_rig(surface_spec, **rig_opts, ie=ie, speed=speed)
    sc = rig.scales
    if ie is not None:
        speed = sc.speed_for(check_positive("--ie", ie))
        rate = speed * sc.preload_n / sc.char_length_m
    if stiffness_number is not None:
        stiffness = sc.stiffness_for(check_positive("--K", stiffness_number))
    if drive == "spring":
        drv = sim.SpringDrive(speed_m_s=speed, stiffness_n_m=stiffness, duration_s=duration)
    elif drive == "ramp":
        drv = sim.RampDrive(rate_n_s=rate, duration_s=duration)
    else:
        drv = sim.StaticProbe(rate_n_s=rate, start_force_n=start_force)
    with Progress("simulating", unit="%") as bar:
        result = rig.run(drv, start=(x0, y0), progress=lambda frac: bar.update(round(100 * frac, 1), 100))
        bar.update(100, 100)  # a run that ends early (a breakaway, a lock) is done too
    out = Path(out_dir)
    written = ["trajectory.parquet", "summary.json", "surface.npz", "run.png"] + (
        ["run.mp4"] if render else []
    )
    with all_or_none(*(out / name for name in written)):
        with atomic_output(out / "trajectory.parquet") as tmp:
            result.table().to_parquet(tmp, index=False)
        write_json(out / "summary.json", result.summary())
        surface_io.save_surface(rig.surface, out / "surface.npz")  # for `spine-mj replay`
        save_figure(sim_run_figure(result, rig.surface, length_scale_m=rig.length_scale_m), out / "run.png")
        if render:
            _render_mp4(rig, result, out / "run.mp4")
    click.echo(
        f"end: {result.end_reason.value} ({result.end_detail}); I_e = {result.inertia_number:.3g}"
        + (f", K = {result.stiffness_number:.3g}" if drive == "spring" else "")
    )
    click.echo(f"wrote {', '.join(str(out / w) for w in written)}")


def _refuse_options_not_for(what: str, params: list[str]) -> None:
    """A :class:`SpineInputError` if any of the current command's ``params`` was given on
    the command line: options that ``what`` would ignore."""
    ctx = click.get_current_context()
    given = [
        opt.opts[0]
        for opt in ctx.command.params
        if opt.name in params and ctx.get_parameter_source(opt.name) is click.core.ParameterSource.COMMANDLINE
    ]
    if given:
        raise SpineInputError(
            f"{what} does not use {', '.join(given)}; leave {'it' if len(given) == 1 else 'them'} out"
        )


def _render_mp4(rig, run, path: Path, *, speed: float | None = None) -> None:
    """Write the MP4 of a run (a RunResult or a replay Track), with a progress bar."""
    import imageio.v2 as imageio

    with Progress("rendering MP4", unit="frame") as bar:
        frames = render_frames(rig, run, speed=speed, progress=bar.update)
        first = next(frames)  # a missing renderer fails here, before the file is opened
        with atomic_output(path) as tmp:
            with imageio.get_writer(tmp, fps=FPS, codec="libx264", format="FFMPEG") as writer:
                writer.append_data(first)
                for frame in frames:
                    writer.append_data(frame)


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
    """Play a run recorded by `spine-mj simulate` in MuJoCo's viewer (RUN_DIR: its --out-dir).

    The tip moves through its recorded positions at the recorded times (times --speed),
    with its path so far (orange) and the streamline from the same start (cyan). Without a
    display, or with --mp4, it writes an MP4 instead (RUN_DIR/replay.mp4 by default).

    \b
    Example:
      spine-mj simulate paper-single-peak --start -3,-1 --out run/ && spine-mj replay run/
    """
    headless = mp4 is not None or (
        sys.platform.startswith("linux")
        and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    )
    if duration is not None:
        check_positive("--duration", duration)
    if headless:
        choose_gl_backend()
    rig, track = load_run(run_dir)
    if headless:
        extras.require("video", "replay without a display (an MP4)" if mp4 is None else "--mp4")
    span = float(track.time_s[-1] - track.time_s[0])
    speed = check_positive("--speed", speed) if speed is not None else default_speed(track.time_s)
    if headless:
        path = Path(mp4) if mp4 is not None else Path(run_dir) / "replay.mp4"
        _check_suffix(str(path), ".mp4", "--mp4")
        if mp4 is None:
            click.echo("no display: writing an MP4 instead of opening the viewer", err=True)
        _render_mp4(rig, track, path, speed=speed)
        click.echo(f"wrote {path}")
        return
    click.echo(f"replaying {span:g} s of run at {speed:g}x; close the window to stop", err=True)
    play_in_viewer(rig, track, speed=speed, duration_s=duration)


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

    if duration is not None:
        check_positive("--duration", duration)
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise InputError(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset): the viewer "
            "needs one; use `spine-mj sim export`, `simulate --render` or `replay --mp4`"
        )
    rig = _build_rig(surface_spec, **rig_opts)
    model = compile_spec(rig.export_spec(None if start is None else _parse_start(start)))
    run_in_viewer(model, time_scale=1.0 / rig.units.time_s, duration_s=duration)


# --------------------------------------------------------------------------- end MuJoCo rig


# --------------------------------------------------------------------------- engagement theory (issue 3)


def _parse_start(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise SpineInputError(f"--start must look like X,Y (e.g. -3,-1), got {text!r}") from None
    return x, y


def _engagement_mu(surf, mu):
    if mu is None:
        mu = presets.preset_mu(surf)
    if mu is None:
        raise SpineInputError("--mu is required for a surface whose preset has no [engagement] mu")
    return mu


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

    _check_suffix(output, ".png", "-o/--output")
    check_grid_size(resolution, resolution, where="kappa --resolution")
    surf = load_surface_arg(surface_spec)
    mu = _engagement_mu(surf, mu)
    xmin, xmax, ymin, ymax = surf.bounds
    xs = np.linspace(xmin, xmax, resolution)
    ys = np.linspace(ymin, ymax, resolution)
    _, fx, fy = surf.evaluate(xs[None, :], ys[:, None], order=1)
    k, region = kappa(fx, fy, mu)
    heights = surf.height(xs[None, :], ys[:, None])
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
@click.option("--dl", type=float, default=None, help="Step length (default: 1/1000 of the domain).")
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
      spine-mj streamline paper-single-valley --mu 1.2 --start -3,-1 --start -3,-2 -o out/
    """

    pts = [_parse_start(s) for s in starts]
    surf = load_surface_arg(surface_spec)
    mu = _engagement_mu(surf, mu)
    xmin, xmax, ymin, ymax = surf.bounds
    params = StreamlineParams(mu=mu, dl=dl if dl is not None else max(xmax - xmin, ymax - ymin) / 1000)
    if tip_radius:
        surf = dilate(surf, tip_radius)
    stream = streamlines(surf, pts, params)
    ideal = ideal_trajectories(surf, pts, params)
    table = pd.concat([stream.to_frame(), ideal.to_frame()], ignore_index=True)
    table["mu"] = mu
    table["tip_radius"] = tip_radius
    out = Path(out_dir)
    path = out / f"streamlines.{fmt}"
    with all_or_none(path, out / "streamlines.png"):
        with atomic_output(path) as tmp:
            if fmt == "parquet":
                table.to_parquet(tmp, index=False)
            else:
                table.to_csv(tmp, index=False)
        save_figure(streamline_figure(surf, stream, ideal, title=f"mu_s = {mu:g}"), out / "streamlines.png")
    for i, (x, y) in enumerate(pts):
        click.echo(
            f"start ({x:g}, {y:g}): streamline {stream.outcome_names[i]} at "
            f"({stream.end_x[i]:.3f}, {stream.end_y[i]:.3f}), max kappa "
            f"{stream.max_kappa[i]:.3g}; ideal {ideal.outcome_names[i]}, max kappa "
            f"{ideal.max_kappa[i]:.3g}"
        )
    click.echo(f"wrote {path} and {out / 'streamlines.png'}")


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

    options = {}
    if name == "fractal-hurst":
        options = {"workers": workers}
        if surfaces is not None:
            options["surfaces"] = surfaces
    else:
        _refuse_options_not_for(f"reproduce {name}", ["surfaces", "workers"])
    with Progress(name) as bar:
        numbers, fig = reproduce.run(name, quick=quick, progress=bar.update, **options)
    out = Path(out_dir)
    with all_or_none(out / f"{name}.json", out / f"{name}.png"):
        write_json(out / f"{name}.json", numbers)
        save_figure(fig, out / f"{name}.png")
    click.echo(f"wrote {out / name}.json and {out / name}.png")


# --------------------------------------------------------------------------- end engagement theory


# --------------------------------------------------------------------------- validation (issue 6)


@main.command("validate")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(),
    help="Output folder: report.md, validation.json, figures/, sweeps/ (resumable).",
)
@click.option(
    "--quick",
    is_flag=True,
    help="The quick plan (<= 5 min on 2 cores): fewer starts and I_e values, coarser hfields.",
)
@click.option(
    "--plan",
    "plan_name",
    type=click.Choice(["smoke", "quick", "full"]),
    default=None,
    hidden=True,
    help="Plan by name (smoke: a seconds-long test size).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Worker processes for the sweeps (default: all cores).",
)
@click.option("--quiet", is_flag=True, help="No progress lines.")
def validate_cmd(out_dir, quick, plan_name, workers, quiet):
    """Run the validation suite (MuJoCo against the quasistatic streamline across inertia
    numbers) and write --out/report.md and --out/validation.json.

    \b
    Example:
      spine-mj validate --quick --out demo-out
    """

    if plan_name is not None and quick and plan_name != "quick":
        raise SpineInputError(f"--quick and --plan {plan_name}: give one of them")
    plan = plan_name or ("quick" if quick else "full")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SpineInputError(f"--out {out} exists and is not a folder")
    with Progress("validate", unit="case", quiet=quiet) as bar:
        result = validate.run_validation(
            out,
            plan=plan,
            workers=workers,
            progress=lambda p: bar.update(
                p.finished_cases, max(p.total_cases, 1), desc=f"{p.study}: {p.step}"
            ),
        )
    click.echo(
        f"static kappa max rel. error (engaged, default settings): {result['static_kappa_max_rel_error']:.3g}"
    )
    for fam, summ in result["limit_families"].items():
        stops = ", ".join(f"{k} {n}" for k, n in summ["failed_runs"].items()) or "none"
        click.echo(
            f"I_e = {result['lowest_ie']:g}, {fam}: outcome agreement {summ['outcome_agreement']:.0%} "
            f"of {summ['runs']}, median Frechet {summ['median_frechet']:.3g} L_c, engine stops: {stops}"
        )
    for row in result.get("fractal_lock_rate", {}).get("rows", []):
        rates = ", ".join(
            f"{k} {row[f'rate_{k}']:.2f} ({row[f'locked_{k}']}/{row[f'n_ok_{k}']})"
            for k in ("streamline", "mujoco_corner", "mujoco_dynamic")
            if f"rate_{k}" in row
        )
        click.echo(f"fractal self-lock rate, H = {row['hurst']:g}: {rates}")
    for proto, s in result["ie_star"].items():
        if s.get("valid") is False:
            click.echo(f"I_e* ({proto}) {s['note']}")
            continue
        for star in (s, s["by_criterion"].get("departure")):
            if star is None:
                continue
            click.echo(f"I_e* ({proto}) criterion: {star['criterion']}")
            if star["kind"] == "bracketed":
                click.echo(f"  I_e* = {star['value']:.3g} in [{star['low']:.3g}, {star['high']:.3g}]")
            elif star["kind"] == "above":
                click.echo(f"  I_e* > {star['low']:.3g} (agreement holds on the whole grid)")
            else:
                click.echo(f"  I_e* < {star['high']:.3g} (no agreement at the lowest I_e)")
    click.echo(
        f"wrote {out / 'report.md'} and {out / 'validation.json'} ({result['timings_s']['total']:.0f} s)"
    )


# --------------------------------------------------------------------------- end validation


if __name__ == "__main__":  # pragma: no cover
    run()
