"""The open-loop controls of spring drives and static probes, known before a run starts.

:func:`controls` gives a placed start's controls ``(nstep, 6)`` in engine units: the
drive's :func:`control_profile` (what every start of one drive shares, computed once per
drive in a batch) shifted by the start (:func:`start_offsets`); :func:`drive_steps` is the
length of the drive phase, refused beyond :data:`MAX_RUN_STEPS`. The batches of
:mod:`spine_mj.sim.rollout` (which re-exports every name) and the GPU path run on them.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import Drive, SpringDrive, StaticProbe, rate_n_s, settle_steps, stiffness_n_m
from spine_mj.sim.model import RigModel
from spine_mj.theory.path_stiffness import spring_run_travel

#: Most steps an open-loop run may plan: its recording (~0.5 kB a step) stays within ~2 GiB.
MAX_RUN_STEPS = 2**22


def length_from_start(drive: Drive) -> bool:
    """Whether :func:`drive_steps` depends on the start: a spring drive without a duration
    runs until its carriage has passed the far edge."""
    return isinstance(drive, SpringDrive) and drive.duration_s is None


def drive_steps(rig: RigModel, drive: Drive, x0_m: float, detection: Detection) -> int:
    """Steps of the drive phase of an open-loop run starting at ``x0_m`` [m]."""
    rig.check_drive(drive)
    dt = rig.engine.timestep_s
    if isinstance(drive, SpringDrive):
        duration = drive.duration_s
        if length_from_start(drive):
            per_fp = rig.scales.preload_n / stiffness_n_m(drive, rig.scales)
            duration = (
                float(spring_run_travel(rig.bounds_m[1] - x0_m, per_fp, rig.tip.mu_s)) / drive.speed_m_s
            )
        steps = duration / dt
        _check_run_steps(
            steps,
            dt,
            f"a spring run of {duration:.3g} s",
            "shorten duration_s, or raise the speed (I_e) or the timestep",
        )
        return max(1, int(math.ceil(steps)))
    if isinstance(drive, StaticProbe):
        cap = detection.kappa_cap * rig.scales.preload_n
        rate = rate_n_s(drive, rig.scales)
        steps = (cap - drive.start_force_n) / rate / dt
        what = (
            f"a static probe from {drive.start_force_n:.3g} N to the force cap {cap:.3g} N at {rate:.3g} N/s"
        )
        _check_run_steps(steps, dt, what, "raise the rate or lower kappa_cap")
        return max(1, int(math.ceil(steps)) + 2)
    raise SpineInputError(
        f"open-loop controls exist for SpringDrive and StaticProbe, got {type(drive).__name__}"
    )


def _check_run_steps(steps: float, dt: float, what: str, remedy: str) -> None:
    """Refuse a run of ``steps`` (a float, before rounding) beyond :data:`MAX_RUN_STEPS`."""
    if not (math.isfinite(steps) and steps <= MAX_RUN_STEPS):
        raise SpineInputError(
            f"{what} would take {steps:.3g} steps of {dt:.3g} s, more than the limit "
            f"{MAX_RUN_STEPS}: {remedy}"
        )


def controls(
    rig: RigModel, drive: Drive, qpos0: np.ndarray, detection: Detection, out: np.ndarray | None = None
) -> np.ndarray:
    """Open-loop controls ``(nstep, 6)`` in engine units: ctrl (spring, push, preload) then mocap xyz.

    ``qpos0`` is the placed start (:meth:`RigModel.place`, engine units), ``detection``
    resolved (:meth:`Detection.resolve`): its ``kappa_cap`` bounds a probe's force.
    ``out``: an array of that shape to fill and return (a batch's row) instead of a new one.
    The controls are the drive's :func:`control_profile` shifted by the start
    (:func:`start_offsets`).
    """
    profile = control_profile(rig, drive, qpos0[0] * rig.units.length_m, detection)
    if out is not None and out.shape != profile.shape:
        raise ValueError(f"out must have shape {profile.shape}, got {out.shape}")
    return np.add(profile, start_offsets(drive, qpos0), out=out)


def control_profile(rig: RigModel, drive: Drive, x0_m: float, detection: Detection) -> np.ndarray:
    """The controls of :func:`controls` for a start at the origin ``(nstep, 6)``, engine
    units (``x0_m`` [m] sets only the length of a spring run without a duration): what
    every start of one drive shares, so that a batch computes it once per drive."""
    u = rig.units
    dt = rig.engine.timestep_s
    n_settle = settle_steps(drive, dt)
    n_drive = drive_steps(rig, drive, x0_m, detection)
    ctrl = np.zeros((n_settle + n_drive, 6))
    ctrl[:, 2] = -rig.tip.preload_n / u.force_n
    ctrl[:, 5] = 2 * rig.tip.tip_radius_m / u.length_m
    ramp_t = (dt / u.time_s) * np.arange(1, n_drive + 1)
    if isinstance(drive, SpringDrive):
        ctrl[n_settle:, 0] = (drive.speed_m_s / u.speed_m_s) * ramp_t
        ctrl[:, 3] = ctrl[:, 0]
        ctrl[:, 1] = drive.start_force_n / u.force_n
    else:
        cap = detection.kappa_cap * rig.scales.preload_n / u.force_n
        f0 = drive.start_force_n / u.force_n
        ctrl[:, 1] = f0
        rate = rate_n_s(drive, rig.scales) * u.time_s / u.force_n
        ctrl[n_settle:, 1] = np.minimum(f0 + rate * ramp_t, cap * (1 + 1e-9))
    return ctrl


def start_offsets(drive: Drive, qpos0: np.ndarray) -> np.ndarray:
    """What a placed start ``qpos0`` (engine units) adds to each row of its drive's
    :func:`control_profile` ``(6,)``: the spring's anchor and the mocap carriage follow the
    start (the anchor only for a spring drive)."""
    x0, y0, z0 = (float(c) for c in qpos0)
    return np.array([x0 if isinstance(drive, SpringDrive) else 0.0, 0.0, 0.0, x0, y0, z0])


def profile_key(drive: Drive, x0: float):
    """What a run's :func:`control_profile` (and length) depends on: the drive, and the
    start ``x0`` where the length does (:func:`length_from_start`)."""
    return (id(drive), x0) if length_from_start(drive) else id(drive)
