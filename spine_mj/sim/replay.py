"""MuJoCo's interactive viewer: a rig simulated live (:func:`run_in_viewer`, or
:func:`view_rig` from a surface: ``spine-mj view``), the same model written for it
(:func:`export_rig`: ``spine-mj sim export``) and a recorded run played back
(:func:`play_in_viewer`, the rig and track of :func:`spine_mj.sim.run_folder.load_run`),
or written as an MP4 where there is no display (:func:`replay_run`: ``spine-mj replay``).
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.build import build_rig
from spine_mj.sim.model import RigModel, compile_spec
from spine_mj.sim.render import (
    STREAMLINE_RGBA,
    TRAIL_RGBA,
    Track,
    add_polyline,
    choose_gl_backend,
    decimate,
    default_speed,
    streamline_path_m,
    write_mp4,
)
from spine_mj.sim.rig import Rig


def export_rig(
    path, surface, *, mu: float, start=None, stiffness_n_m: float | None = None, **rig_options
) -> Rig:
    """Write the self-contained MJCF of the rig on ``surface`` for MuJoCo's viewer, the tip
    resting at ``start`` with the spring on (:meth:`~spine_mj.sim.Rig.export_xml`).

    Parameters
    ----------
    path : path
        The ``.xml`` to write.
    surface : Surface
        The surface.
    mu : float
        The tip's friction coefficient.
    start : (float, float), optional
        Where the tip rests, in surface units (None: a tenth in from the -x edge, mid y).
    stiffness_n_m : float, optional
        The spring's stiffness [N/m] (None: K = 30); it bounds the step.
    **rig_options
        :func:`~spine_mj.sim.build_rig`'s other keywords; the rig is built undriven
        (the user's sliders drive it).

    Returns
    -------
    Rig
        The rig written (its hfield, step, tip and units, for the caller to report).
    """
    rig = build_rig(surface, mu=mu, stiffness_n_m=stiffness_n_m, driven=False, **rig_options)
    rig.export_xml(path, start=start, stiffness_n_m=stiffness_n_m)
    return rig


def view_rig(surface, *, mu: float, start=None, duration_s: float | None = None, **rig_options) -> None:
    """Open the model :func:`export_rig` writes in MuJoCo's viewer, running in physical
    real time (:func:`run_in_viewer`; needs a display).

    Parameters
    ----------
    surface : Surface
        The surface.
    mu : float
        The tip's friction coefficient.
    start : (float, float), optional
        Where the tip rests, in surface units (None: a tenth in from the -x edge, mid y).
    duration_s : float, optional
        Close the viewer after this many wall seconds.
    **rig_options
        :func:`~spine_mj.sim.build_rig`'s other keywords (the rig is built undriven).
    """
    rig = build_rig(surface, mu=mu, driven=False, **rig_options)
    model = compile_spec(rig.export_spec(start))
    run_in_viewer(model, time_scale=1.0 / rig.units.time_s, duration_s=duration_s)


def has_display() -> bool:
    """Whether a window can open here: not on Linux without ``DISPLAY`` or ``WAYLAND_DISPLAY``."""
    return not sys.platform.startswith("linux") or bool(
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )


@dataclass(frozen=True)
class Replay:
    """What :func:`replay_run` did: the run's span and the playback speed, and the MP4
    written (None: the run was played in the viewer)."""

    span_s: float
    speed: float
    mp4: Path | None


def replay_run(
    run_dir,
    *,
    speed: float | None = None,
    duration_s: float | None = None,
    mp4=None,
    notice: Callable[[str], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Replay:
    """Play the run recorded in ``run_dir`` (``spine-mj simulate``'s output folder) in
    MuJoCo's viewer or, with ``mp4`` or without a display (:func:`has_display`), write it as
    an MP4 (``mp4``, else ``run_dir/replay.mp4``) instead.

    Parameters
    ----------
    run_dir : path
        The run folder (:func:`~spine_mj.sim.run_folder.load_run`).
    speed : float, optional
        Run seconds per wall second (None: the whole run in about 10 s).
    duration_s : float, optional
        Close the viewer after this many wall seconds; refused for an MP4 (it has the
        run's length at ``speed``).
    mp4 : path, optional
        The MP4 to write instead of opening the viewer.
    notice : callable, optional
        ``notice(text)``: what is about to happen (the viewer opening, or an MP4 written
        for want of a display).
    progress : callable, optional
        ``progress(done, total)`` per MP4 frame.

    Raises
    ------
    SpineInputError
        ``duration_s`` for an MP4, ``duration_s`` or ``speed`` not > 0, ``mp4`` not a
        ``.mp4``, no renderer or no ``[video]`` extra for an MP4, an unreadable run folder.
    """
    from spine_mj import extras
    from spine_mj.sim.run_folder import load_run  # pandas: only for a recorded run

    say = notice or (lambda text: None)
    headless = mp4 is not None or not has_display()
    if headless and duration_s is not None:
        raise SpineInputError("replay to an MP4 (no display, or --mp4) does not use --duration; leave it out")
    if duration_s is not None:
        check_positive("--duration", duration_s)
    if headless:
        choose_gl_backend()
    rig, track = load_run(run_dir)
    if headless:
        extras.require("video", "replay without a display (an MP4)" if mp4 is None else "--mp4")
    span = float(track.time_s[-1] - track.time_s[0])
    speed = check_positive("--speed", speed) if speed is not None else default_speed(track.time_s)
    if not headless:
        say(f"replaying {span:g} s of run at {speed:g}x; close the window to stop")
        play_in_viewer(rig, track, speed=speed, duration_s=duration_s)
        return Replay(span, speed, None)
    path = Path(mp4) if mp4 is not None else Path(run_dir) / "replay.mp4"
    if path.suffix.lower() != ".mp4":
        raise SpineInputError(f"--mp4 must name a .mp4 file, got {str(path)!r}")
    if mp4 is None:
        say("no display: writing an MP4 instead of opening the viewer")
    write_mp4(rig, track, path, speed=speed, progress=progress)
    return Replay(span, speed, path)


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
