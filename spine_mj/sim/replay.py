"""Replaying a recorded ``simulate`` run: rebuilding its rig from the run folder and
playing the recorded tip positions in MuJoCo's interactive viewer.

The run folder holds ``summary.json`` (tip, engine, scales, drive), ``surface.npz`` and
``trajectory.parquet``; the rig is rebuilt from them, so the replay shows the same model.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow

from spine_mj import surface_io
from spine_mj.errors import SpineInputError
from spine_mj.sim.drives import RampDrive, SpringDrive, StaticProbe
from spine_mj.sim.model import RigModel
from spine_mj.sim.params import EngineSettings, TipParams
from spine_mj.sim.render import (
    STREAMLINE_RGBA,
    TRAIL_RGBA,
    Track,
    add_polyline,
    decimate,
    streamline_path_m,
)

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
        rig = RigModel(
            surface_io.load_surface(run_dir / "surface.npz"),
            tip=TipParams(**summary["tip"]),
            engine=EngineSettings(**summary["engine"]),
            length_scale_m=sc["length_scale_m"],
            char_length_m=sc["char_length_m"],
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


def run_in_viewer(model, *, time_scale: float = 1.0, duration_s: float | None = None) -> None:
    """Simulate ``model`` live in MuJoCo's passive viewer, on its first camera (needs a display).

    ``time_scale`` is model seconds per wall second (``1 / units.time_s`` runs an engine-unit
    model in physical real time). Ends when the window is closed or after ``duration_s``
    wall seconds. The viewer's own sliders and Reset act on the running model.
    """
    import mujoco
    import mujoco.viewer

    d = mujoco.MjData(model)
    mujoco.mj_forward(model, d)
    most = max(1, int(0.1 * time_scale / model.opt.timestep))  # steps per frame, at most 0.1 s
    before = set(threading.enumerate())
    t0 = time.monotonic()
    with mujoco.viewer.launch_passive(model, d) as viewer:
        if model.ncam:
            viewer.cam.type, viewer.cam.fixedcamid = mujoco.mjtCamera.mjCAMERA_FIXED, 0
        sim0 = d.time
        while viewer.is_running():
            wall = time.monotonic() - t0
            if duration_s is not None and wall >= duration_s:
                break
            with viewer.lock():
                n = min(most, int((sim0 + wall * time_scale - d.time) / model.opt.timestep))
                for _ in range(max(0, n)):
                    mujoco.mj_step(model, d)
            viewer.sync()
            time.sleep(1 / 60)
    _join_new_threads(before)


def play_in_viewer(
    rig: RigModel,
    track: Track,
    *,
    speed: float = 1.0,
    duration_s: float | None = None,
    on_frame: Callable[[float], None] | None = None,
) -> None:
    """Play ``track`` in MuJoCo's passive viewer at ``speed`` times real time (needs a display).

    The camera follows the tip; the trail and the streamline are drawn as in the MP4.
    Ends when the window is closed, or after ``duration_s`` wall seconds (None: the window
    stays open on the last frame until closed). ``on_frame`` gets the run time shown.
    """
    import mujoco
    import mujoco.viewer

    m = rig.model_for(track.drive)
    d = mujoco.MjData(m)
    to_engine = 1.0 / rig.units.length_m
    pos, t = track.position_m * to_engine, track.time_s
    ref = streamline_path_m(rig, track.start) * to_engine
    ref, kept = ref[decimate(ref)], decimate(pos)
    r = rig.tip.tip_radius_m * to_engine
    before = set(threading.enumerate())
    t0 = time.monotonic()
    with mujoco.viewer.launch_passive(m, d, show_left_ui=False, show_right_ui=False) as viewer:
        viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
        viewer.cam.trackbodyid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "tip")
        viewer.cam.distance, viewer.cam.elevation, viewer.cam.azimuth = 80 * r, -30.0, 20.0
        while viewer.is_running():
            wall = time.monotonic() - t0
            if duration_s is not None and wall >= duration_s:
                break
            i = min(int(np.searchsorted(t, t[0] + wall * speed)), len(t) - 1)
            d.qpos[:] = pos[i]
            if not np.isnan(track.carriage_x_m[i]):
                d.mocap_pos[0] = (track.carriage_x_m[i] * to_engine, pos[i, 1], pos[i, 2] + 2 * r)
            mujoco.mj_forward(m, d)
            with viewer.lock():
                viewer.user_scn.ngeom = 0
                add_polyline(viewer.user_scn, ref, STREAMLINE_RGBA, 0.25 * r)
                trail = np.vstack([pos[kept[kept < i]], pos[i : i + 1]])
                add_polyline(viewer.user_scn, trail, TRAIL_RGBA, 0.35 * r)
            viewer.sync()
            if on_frame is not None:
                on_frame(float(t[i]))
            time.sleep(1 / 60)
    _join_new_threads(before)


def _join_new_threads(before: set) -> None:
    """Wait for the viewer's daemon thread to tear down its window: an exit before that
    crashes in GLFW."""
    for thread in set(threading.enumerate()) - before:
        thread.join(timeout=10)
