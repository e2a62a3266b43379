"""What a sweep row records of an engine's runs: the end, the path, the drive's peak and
swing, the slip events and the per-step trajectory columns (:mod:`spine_mj.sweep.analyses.engine`
runs the rigs; this module only reads their :class:`~spine_mj.sim.RunResult`).
"""

from __future__ import annotations

import numpy as np

from spine_mj import sim
from spine_mj.sim.holding import spring_swing
from spine_mj.sim.ramp import nominal_time_s
from spine_mj.theory.motion import MOTION_NAMES

__all__ = ["peak_drive_over_fp", "run_metrics", "run_trajectories"]


def peak_drive_over_fp(run, preload_n: float) -> float:
    """Largest drive force after the settling phase over F_p (NaN for a run that never drove)."""
    return (
        run.drive_force_n[run.drive_start_index :].max() / preload_n
        if run.n > run.drive_start_index
        else np.nan
    )


def run_metrics(rig, runs) -> dict[str, np.ndarray]:
    """Per-run metrics; lengths in the surface's unit."""
    s = rig.length_scale_m
    sc = rig.scales
    n = len(runs)
    end = np.array([r.position_m[-1] for r in runs]) / s
    path_len = (
        np.array(
            [
                np.linalg.norm(np.diff(r.position_m[r.drive_start_index :, :2], axis=0), axis=1).sum()
                for r in runs
            ]
        )
        / s
    )
    return {
        "end_reason": np.array([r.end_reason.value for r in runs], dtype=object),
        # which test ended the run, with its numbers ("lock rule: ...", "force cap: ...")
        "end_detail": np.array([r.end_detail for r in runs], dtype=object),
        "self_locked": np.array([r.end_reason is sim.EndReason.SELF_LOCK for r in runs]),
        "end_x": end[:, 0],
        "end_y": end[:, 1],
        "end_z": end[:, 2],
        "path_length": path_len,
        "end_time_s": np.array([r.time_s[-1] for r in runs]),
        # a fast-forwarded ramp covers its stick phases in less engine time: the time the
        # plain ramp would have taken
        "nominal_end_time_s": np.array(
            [nominal_time_s(r)[-1] if isinstance(r.drive, sim.RampDrive) else r.time_s[-1] for r in runs]
        ),
        "n_steps": np.array([r.n for r in runs], dtype=np.int64),
        "inertia_number": np.array([r.inertia_number for r in runs]),
        "speed_m_s": np.array([r.speed_m_s for r in runs]),
        "stiffness_number": np.array([r.stiffness_number for r in runs]),
        "stiffness_n_m": np.array([r.stiffness_n_m for r in runs]),
        # the spring-block swing sqrt(I_e K L_c / l_s) [F_p]: a spring drive is slow for its
        # stiffness, and a quasistatic comparison like with like, only where it is small
        "spring_swing_fp": np.array([_swing(r, sc) for r in runs]),
        "slope_length": np.full(n, sc.slope_length_m / s),
        "max_drive_over_fp": np.array([peak_drive_over_fp(r, sc.preload_n) for r in runs]),
        "n_move_onsets": np.array(
            [sum(e.kind == "move_onset" for e in r.events) for r in runs], dtype=np.int64
        ),
        **_slip_metrics(runs),
        "max_penetration_m": np.array([r.penetration_m.max() for r in runs]),
        "kappa_mj": np.array([r.kappa_mj for r in runs]),
        "timestep_s": np.array([r.engine.timestep_s for r in runs]),
        "char_length": np.full(n, sc.char_length_m / s),
        "tip_radius_m": np.full(n, rig.tip.tip_radius_m),
    }


def _swing(run, scales: sim.Scales) -> float:
    """The spring-block swing of ``run``'s drive [F_p] (:func:`spine_mj.sim.holding.spring_swing`);
    NaN for a drive without a spring."""
    k = run.stiffness_number
    if not (np.isfinite(k) and k > 0 and run.inertia_number > 0):
        return float("nan")
    return spring_swing(run.inertia_number, k, scales.char_length_m / scales.slope_length_m)


def _slip_metrics(runs) -> dict[str, np.ndarray]:
    """The runs' slip events and motion states (:meth:`spine_mj.sim.RunResult.slip_summary`)
    as columns: ``slip_events``, the mean and largest onset force (F_p; NaN without a
    slip), the fraction of the drive phase ``stuck``, ``sliding`` and ``slipping``, and the
    largest x-speed over the drive's speed."""
    sums = [r.slip_summary() for r in runs]

    def onset(f):
        return np.array([f(d["slip_onset_forces_fp"]) if d["slip_events"] else np.nan for d in sums])

    cols = {
        "slip_events": np.array([d["slip_events"] for d in sums], dtype=np.int64),
        "slip_onset_fp_mean": onset(np.mean),
        "slip_onset_fp_max": onset(np.max),
    }
    for name in MOTION_NAMES:
        cols[f"{name}_fraction"] = np.array([d["motion_fractions"][name] for d in sums])
    cols["max_speed_over_drive"] = np.array([d["max_speed_over_drive"] for d in sums])
    return cols


def run_trajectories(runs, s: float, k: int) -> dict[str, np.ndarray]:
    """Long table of the runs' paths: every ``k``-th recorded step and the last one;
    lengths in the surface's unit (metres over ``s``)."""
    parts = []
    for i, r in enumerate(runs):
        # every k-th step and the last one (a slice, not a copy, when k is 1)
        idx = np.arange(0, r.n, k, dtype=np.int64)
        if r.n and idx[-1] != r.n - 1:
            idx = np.append(idx, r.n - 1)
        rows = slice(None) if k == 1 else idx
        pos = r.position_m[rows]
        parts.append(
            {
                "start": np.full(idx.size, i, np.int64),
                "step": idx,
                "time_s": r.time_s[rows],
                "x": pos[:, 0] / s,
                "y": pos[:, 1] / s,
                "z": pos[:, 2] / s,
                "drive_force_n": r.drive_force_n[rows],
                "normal_force_n": r.normal_force_n[rows],
                "tangential_force_n": r.tangential_force_n[rows],
                "moving": r.moving[rows],
                "motion": r.motion[rows],
                "contact": r.contact[rows],
            }
        )
    return {c: np.concatenate([part[c] for part in parts]) for c in parts[0]}
