"""Rendering a run's frames offscreen (headless; needs a GL backend such as EGL or OSMesa)."""

from __future__ import annotations

import math

from spine_mj.sim.model import RigModel
from spine_mj.sim.results import RunResult


def render_frames(
    rig: RigModel, result: RunResult, *, fps: float = 30.0, width: int = 640, height: int = 480
):
    """Yield RGB frames ``(height, width, 3)`` uint8 of a run (headless, needs a GL backend)."""
    import mujoco

    m = rig.model_for(result.drive)
    d = mujoco.MjData(m)
    renderer = mujoco.Renderer(m, height=height, width=width)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    to_engine = 1.0 / rig.units.length_m
    span = max(rig.bounds_m[1] - rig.bounds_m[0], rig.bounds_m[3] - rig.bounds_m[2]) * to_engine
    cam.distance = 0.9 * span
    cam.elevation = -35.0
    cam.azimuth = 120.0
    stride = max(1, int(round(1.0 / (fps * rig.engine.timestep_s))))
    try:
        for i in range(0, result.n, stride):
            pos = result.position_m[i] * to_engine
            d.qpos[:] = pos
            if not math.isnan(result.carriage_x_m[i]):
                d.mocap_pos[0] = (
                    result.carriage_x_m[i] * to_engine,
                    pos[1],
                    pos[2] + 2 * rig.tip.tip_radius_m * to_engine,
                )
            mujoco.mj_forward(m, d)
            cam.lookat[:] = pos
            renderer.update_scene(d, camera=cam)
            yield renderer.render().copy()
    finally:
        renderer.close()
