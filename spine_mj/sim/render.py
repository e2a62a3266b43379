"""Pictures of a run: offscreen MP4 frames and the scene decorations the viewer shares.

A frame shows the tip, the path it has travelled so far (orange trail), the quasistatic
streamline from the same start for comparison (cyan; :func:`streamline_path_m`) and a text
overlay with the time and the drive force. Headless rendering needs a GL backend; MuJoCo
picks it from ``MUJOCO_GL`` when it is first imported (:func:`choose_gl_backend`).
"""

from __future__ import annotations

import itertools
import math
import os
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spine_mj.atomic import atomic_output
from spine_mj.errors import SpineInputError
from spine_mj.sim.drives import Drive
from spine_mj.sim.model import RigModel
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import streamline as sl
from spine_mj.theory.streamline_types import StreamlineParams

TRAIL_RGBA = (1.0, 0.55, 0.0, 1.0)
STREAMLINE_RGBA = (0.0, 0.8, 0.9, 0.9)
MAX_SEGMENTS = 300  # per polyline
FPS = 30.0  # of the MP4
MAX_FRAMES = 100_000  # about an hour of video at FPS
_ZERO3, _EYE9 = np.zeros(3), np.eye(3).ravel()


@dataclass(frozen=True)
class Track:
    """What a picture of a run needs (SI): times, tip centres, carriage x, drive force."""

    time_s: np.ndarray
    position_m: np.ndarray
    carriage_x_m: np.ndarray
    drive_force_n: np.ndarray
    start: tuple[float, float]
    drive: Drive

    @classmethod
    def of(cls, run) -> Track:
        """The track of a :class:`~spine_mj.sim.results.RunResult` (a Track passes through)."""
        if isinstance(run, Track):
            return run
        return cls(run.time_s, run.position_m, run.carriage_x_m, run.drive_force_n, run.start, run.drive)


def default_speed(time_s: np.ndarray, seconds: float = 10.0) -> float:
    """Playback speed (run seconds per wall second) that shows the whole run in ``seconds``."""
    return max(float(time_s[-1] - time_s[0]) / seconds, 1e-12)


def choose_gl_backend() -> str:
    """Set ``MUJOCO_GL`` to a headless backend that works here (EGL, else OSMesa) and return it.

    A value already set is kept if it renders, else refused. Each candidate is tried in a
    child process, since MuJoCo reads the variable once, on import. Raises
    :class:`SpineInputError` naming what to install or set.
    """
    probe = "import mujoco; mujoco.Renderer(mujoco.MjModel.from_xml_string('<mujoco/>'), 8, 8).render()"

    def renders(env) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=120
        )

    given = os.environ.get("MUJOCO_GL")
    if given:
        tried = renders(dict(os.environ))
        if tried.returncode != 0:
            lines = tried.stderr.strip().splitlines()
            raise SpineInputError(
                f"MUJOCO_GL={given!r} cannot render here ({lines[-1] if lines else 'no output'}): "
                "set MUJOCO_GL=egl (needs libegl1) or osmesa (needs libosmesa6), or unset it to "
                "let spine-mj choose"
            )
        return given
    for backend in ("egl", "osmesa"):
        if renders(dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)).returncode == 0:
            os.environ["MUJOCO_GL"] = backend
            return backend
    raise SpineInputError(
        "no headless OpenGL backend works (tried MUJOCO_GL=egl and osmesa): install EGL "
        "(Debian: apt-get install libegl1 libegl-mesa0, or a GPU driver) or OSMesa (libosmesa6)"
    )


def streamline_path_m(rig: RigModel, start: tuple[float, float]) -> np.ndarray:
    """Tip-centre path ``(k, 3)`` [m] of the quasistatic streamline from ``start`` with the
    rig's mu_s, on the surface dilated by the tip radius (what the rig's sphere rides on)."""
    s = rig.length_scale_m
    radius = rig.tip.tip_radius_m / s
    params = StreamlineParams(mu=rig.tip.mu_s, dl=sl.default_step(rig.surface))
    path = sl.streamlines(dilate(rig.surface, radius), [start], params).path(0)
    return s * np.column_stack([path["x"], path["y"], path["z"] + radius])


def decimate(points: np.ndarray, n: int = MAX_SEGMENTS) -> np.ndarray:
    """Row indices of ``points`` keeping at most ``n + 1`` of them, the first and last included."""
    step = max(1, math.ceil((len(points) - 1) / n))
    idx = np.arange(0, len(points), step)
    return idx if idx[-1] == len(points) - 1 else np.append(idx, len(points) - 1)


def add_polyline(scene, points: np.ndarray, rgba, width: float) -> None:
    """Append a polyline (engine units; :func:`decimate` it first) to an ``MjvScene`` as
    capsules of diameter ``2 width``, while the scene has room."""
    import mujoco

    rgba = np.asarray(rgba, dtype=np.float32)
    for a, b in itertools.pairwise(points):
        if scene.ngeom >= scene.maxgeom:
            return
        g = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(g, mujoco.mjtGeom.mjGEOM_CAPSULE, _ZERO3, _ZERO3, _EYE9, rgba)
        mujoco.mjv_connector(g, mujoco.mjtGeom.mjGEOM_CAPSULE, width, a, b)
        scene.ngeom += 1


def plain_scene(scene) -> None:
    """No shadows or reflections: a software renderer draws four times as fast, and the
    hfield's shadow hides the path."""
    import mujoco

    scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
    scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0


def overlay_text(frame: np.ndarray, lines: list[str]) -> np.ndarray:
    """``frame`` with ``lines`` written in its top-left corner on a dark band (Pillow)."""
    from PIL import Image, ImageDraw, ImageFont

    img = Image.fromarray(frame)
    draw = ImageDraw.Draw(img, "RGBA")
    font = ImageFont.load_default(size=max(12, frame.shape[0] // 30))
    box = draw.multiline_textbbox((8, 6), "\n".join(lines), font=font)
    draw.rectangle((0, 0, box[2] + 8, box[3] + 6), fill=(0, 0, 0, 150))
    draw.multiline_text((8, 6), "\n".join(lines), font=font, fill=(255, 255, 255, 255))
    draw.text(
        (8, frame.shape[0] - 24), "orange: tip path   cyan: streamline", font=font, fill=(255, 255, 255, 255)
    )
    return np.asarray(img)


def render_frames(
    rig: RigModel,
    run,
    *,
    fps: float = FPS,
    width: int = 640,
    height: int = 480,
    speed: float | None = None,
    streamline: bool = True,
    progress: Callable[[int, int], None] | None = None,
):
    """Yield RGB frames ``(height, width, 3)`` uint8 of a run (a RunResult or :class:`Track`).

    One frame per ``speed / fps`` seconds of run time (``speed`` None: :func:`default_speed`),
    camera following the tip; trail, streamline and overlay as in the module docstring.
    ``progress(done, total)`` is called as each frame is ready.
    """
    import mujoco

    track = Track.of(run)
    t = track.time_s
    speed = default_speed(t) if speed is None else speed
    frames = (t[-1] - t[0]) * fps / speed
    if not frames <= MAX_FRAMES:
        raise SpineInputError(
            f"speed {speed:.3g} makes a video of {frames:.3g} frames at {fps:g} fps, more than "
            f"{MAX_FRAMES}: raise the speed"
        )
    m = rig.model_for(track.drive)
    d = mujoco.MjData(m)
    try:
        renderer = mujoco.Renderer(m, height=height, width=width, max_geom=2 * MAX_SEGMENTS + 100)
        renderer.render()  # some backends fail only on the first frame
    except Exception as exc:  # a missing GL backend surfaces as many exception types
        raise SpineInputError(
            f"no headless renderer (MUJOCO_GL={os.environ.get('MUJOCO_GL', '')!r}: "
            f"{type(exc).__name__}: {exc}); install EGL (libegl1) or OSMesa (libosmesa6), or run "
            "without --render"
        ) from None
    to_engine = 1.0 / rig.units.length_m
    r = rig.tip.tip_radius_m * to_engine
    ref = streamline_path_m(rig, track.start) * to_engine if streamline else np.empty((0, 3))
    ref = ref[decimate(ref)] if len(ref) else ref
    pos = track.position_m * to_engine
    kept = decimate(pos)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.elevation, cam.azimuth = 80 * r, -30.0, 20.0
    f_p = rig.scales.preload_n
    rows = np.unique(np.searchsorted(t, np.arange(t[0], t[-1], speed / fps)).clip(0, len(t) - 1))
    rows = np.append(rows, len(t) - 1) if rows[-1] != len(t) - 1 else rows
    try:
        for k, i in enumerate(rows):
            d.qpos[:] = pos[i]
            if not math.isnan(track.carriage_x_m[i]):
                d.mocap_pos[0] = (track.carriage_x_m[i] * to_engine, pos[i, 1], pos[i, 2] + 2 * r)
            mujoco.mj_forward(m, d)
            cam.lookat[:] = pos[i]
            renderer.update_scene(d, camera=cam)
            plain_scene(renderer.scene)
            add_polyline(renderer.scene, ref, STREAMLINE_RGBA, 0.25 * r)
            trail = np.vstack([pos[kept[kept < i]], pos[i : i + 1]])
            add_polyline(renderer.scene, trail, TRAIL_RGBA, 0.35 * r)
            f = track.drive_force_n[i]
            lines = [f"t = {t[i]:.4f} s", f"drive force = {f * 1e3:.3g} mN = {f / f_p:.3f} F_p"]
            frame = overlay_text(renderer.render(), lines)
            if progress is not None:
                progress(k + 1, len(rows))
            yield frame
    finally:
        renderer.close()


def write_mp4(
    rig: RigModel,
    run,
    path,
    *,
    speed: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Write the MP4 of a run (a RunResult or :class:`Track`) to ``path``, atomically.

    Frames as :func:`render_frames` draws them; a missing renderer fails before the file
    is opened. Needs the ``[video]`` extra (imageio with ffmpeg).
    """
    import imageio.v2 as imageio  # the optional [video] extra: imported only to write a video

    frames = render_frames(rig, run, speed=speed, progress=progress)
    first = next(frames)
    with atomic_output(path) as tmp:
        with imageio.get_writer(tmp, fps=FPS, codec="libx264", format="FFMPEG") as writer:
            writer.append_data(first)
            for frame in frames:
                writer.append_data(frame)
