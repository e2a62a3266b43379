"""The run folder of ``spine-mj simulate``: written and read back here.

A run folder holds ``trajectory.parquet`` (:meth:`RunResult.table`), ``summary.json``
(:meth:`RunResult.summary`: tip, engine, scales, drive), ``surface.npz`` (the surface),
``run.png`` (:func:`spine_mj.plotting.sim_run_figure`) and, when asked, ``run.mp4``.
:func:`simulate_to` builds the rig and drive, runs it and writes the folder (the whole of
``spine-mj simulate``); :func:`write_run` writes all of them or none; :func:`load_run`
rebuilds the rig from the first three, so that ``spine-mj replay`` shows the same model (a
Bullet run's on MuJoCo's model of the same surface and tip).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import pyarrow

from spine_mj import surface_io
from spine_mj.atomic import all_or_none, atomic_output
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import write_json
from spine_mj.plotting import save_figure, sim_run_figure
from spine_mj.sim.build import build_drive, build_rig
from spine_mj.sim.drives import RampDrive, SpringDrive, StaticProbe
from spine_mj.sim.model import RigModel
from spine_mj.sim.records import EngineSettings, TipParams
from spine_mj.sim.render import Track, write_mp4
from spine_mj.sim.results import RunResult
from spine_mj.sim.rig_inputs import RigInputs
from spine_mj.surfaces import Surface

__all__ = ["RUN_FILES", "load_run", "simulate_to", "write_run"]

RUN_FILES = ("summary.json", "surface.npz", "trajectory.parquet")
_DRIVES = {cls.__name__: cls for cls in (SpringDrive, RampDrive, StaticProbe)}


def load_run(run_dir: str | Path) -> tuple[RigModel, Track]:
    """The rig and the track of the run recorded in ``run_dir`` by ``spine-mj simulate``."""
    run_dir = Path(run_dir)
    missing = [name for name in RUN_FILES if not (run_dir / name).is_file()]
    if missing:
        raise SpineInputError(
            f"{run_dir} is not a replayable run folder: {', '.join(missing)} missing "
            "(written by `spine-mj simulate`; older runs lack surface.npz)"
        )
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise SpineInputError(f"{run_dir / 'summary.json'} is not readable JSON ({exc})") from None
    try:
        sc = summary["scales"]
        engine = dict(summary["engine"])
        engine.pop("hfield_resolution", None)  # older runs recorded it with the engine; the scales hold it
        rig = RigModel(
            surface_io.load_surface(run_dir / "surface.npz"),
            tip=TipParams(**summary["tip"]),
            # MuJoCo's settings name no engine (a run on MuJoCo's step rule is played with them);
            # another engine's run is shown on MuJoCo's model of the same surface (its derived settings)
            engine=EngineSettings(**engine) if "engine" not in engine else None,
            length_scale_m=sc["length_scale_m"],
            char_length_m=sc["char_length_m"],
            hfield_resolution=sc.get("hfield_resolution"),
        )
        drive = _DRIVES[summary["drive"]](**summary["drive_params"])
        start = tuple(summary["start"])
    except (KeyError, TypeError) as exc:
        raise SpineInputError(f"{run_dir / 'summary.json'} does not describe a run: {exc!r}") from None
    try:
        table = pd.read_parquet(run_dir / "trajectory.parquet")
        track = Track(
            time_s=table["time_s"].to_numpy(),
            position_m=table[["position_x_m", "position_y_m", "position_z_m"]].to_numpy(),
            carriage_x_m=table["carriage_x_m"].to_numpy(),
            drive_force_n=table["drive_force_n"].to_numpy(),
            start=start,
            drive=drive,
        )
    except (pyarrow.ArrowException, KeyError) as exc:
        raise SpineInputError(f"{run_dir / 'trajectory.parquet'} is not a run's trajectory ({exc})") from None
    return rig, track


def write_run(
    out_dir: str | Path,
    rig: RigModel,
    result: RunResult,
    *,
    mp4: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> list[Path]:
    """Write the run folder of ``result`` (module docstring) into ``out_dir``: every file
    or none (an existing folder's files are restored if a write fails).

    ``mp4`` also writes ``run.mp4`` (:func:`~spine_mj.sim.render.write_mp4`), reporting
    ``progress(frames done, frames)``. Returns the paths written.
    """
    out = Path(out_dir)
    names = ["trajectory.parquet", "summary.json", "surface.npz", "run.png"] + (["run.mp4"] if mp4 else [])
    paths = [out / name for name in names]
    with all_or_none(*paths):
        with atomic_output(out / "trajectory.parquet") as tmp:
            result.table().to_parquet(tmp, index=False)
        write_json(out / "summary.json", result.summary())
        surface_io.save_surface(rig.surface, out / "surface.npz")
        save_figure(sim_run_figure(result, rig.surface, length_scale_m=rig.length_scale_m), out / "run.png")
        if mp4:
            write_mp4(rig, result, out / "run.mp4", progress=progress)
    return paths


def simulate_to(
    out_dir: str | Path,
    surface: Surface,
    inputs: RigInputs,
    *,
    start: tuple[float, float],
    protocol: str = "spring",
    duration_s: float | None = None,
    start_force_n: float = 0.0,
    mp4: bool = False,
    progress: Callable[[float], None] | None = None,
    render_progress: Callable[[int, int], None] | None = None,
    prepare_progress: Callable[[float, float, str], None] | None = None,
) -> tuple[RunResult, list[Path]]:
    """One drive on ``surface`` written as a run folder: what ``spine-mj simulate`` does.

    The rig of ``inputs`` (:func:`~spine_mj.sim.build_rig`, its step bounded by the drive's
    pace and spring), the drive of the same pace and spring
    (:func:`~spine_mj.sim.build_drive`), the run from ``start``, and its folder
    (:func:`write_run`: every file or none).

    Parameters
    ----------
    out_dir : path
        The run folder.
    surface : Surface
        The surface the tip runs on.
    inputs : RigInputs
        The rig's inputs: mu, engine, tip, sizing, and the drive's pace and spring.
    start : (float, float)
        The start ``(x0, y0)`` in surface units.
    protocol : {"spring", "ramp", "static"}
        The drive.
    duration_s, start_force_n
        The drive's, as for :func:`~spine_mj.sim.build_drive`.
    mp4 : bool
        Also write ``run.mp4``.
    progress : callable, optional
        Called with the run's fraction done while it runs.
    render_progress : callable, optional
        Called with ``(frames done, frames)`` while the MP4 is written.
    prepare_progress : callable, optional
        Called with ``(done, total, stage)`` while the rig is prepared (``build_rig``'s).

    Returns
    -------
    (RunResult, list of Path)
        The run and the files written.
    """
    rig = build_rig(surface, inputs, progress=prepare_progress)
    drive = build_drive(
        rig.scales,
        protocol,
        **inputs.pace,
        **inputs.spring,
        duration_s=duration_s,
        start_force_n=start_force_n,
    )
    result = rig.run(drive, start=start, progress=progress)
    return result, write_run(out_dir, rig, result, mp4=mp4, progress=render_progress)
