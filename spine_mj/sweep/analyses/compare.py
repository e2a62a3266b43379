"""The ``compare`` analysis: quasistatic against MuJoCo per start, lengths over L_c.

Touches the API of :mod:`spine_mj.compare` here only; needs the results of the
``quasistatic`` and ``mujoco`` analyses of the same case.
"""

from __future__ import annotations

import numpy as np

from spine_mj import compare
from spine_mj.sweep.analyses.mujoco import peak_drive_over_fp
from spine_mj.sweep.registry import Analysis, AnalysisResult, register_analysis


def _compare(case, surface, starts, upstream):
    qs = upstream["quasistatic"].data
    rig, runs = upstream["mujoco"].data
    s = rig.length_scale_m
    lc = rig.scales.char_length_m / s
    n = len(runs)
    frechet = np.full(n, np.nan)
    lateral = np.full(n, np.nan)
    for i, r in enumerate(runs):
        q = qs.path(i)
        qpath = np.column_stack([q["x"], q["y"]])
        mpath = r.position_m[r.drive_start_index :, :2] / s
        if mpath.shape[0] == 0:
            continue
        frechet[i] = compare.path_frechet(mpath, qpath, length_scale=lc)
        lateral[i] = compare.mean_lateral_deviation(mpath, qpath, length_scale=lc)
    mj_locked = np.array([r.end_reason.value == "self_lock" for r in runs])
    mj_end = np.array([r.position_m[-1, :2] / s for r in runs])
    agree = compare.outcome_agreement(
        qs.self_locked, np.column_stack([qs.end_x, qs.end_y]), mj_locked, mj_end, length_scale=lc
    )
    peak = np.array([peak_drive_over_fp(r, rig.scales.preload_n) for r in runs])
    kap = compare.kappa_agreement(qs.max_kappa, peak, kappa_cap=runs[0].detection.kappa_cap)
    metrics = {
        "frechet": frechet,
        "lateral_deviation": lateral,
        "end_distance": np.linalg.norm(np.column_stack([qs.end_x, qs.end_y]) - mj_end, axis=1) / lc,
        "agree_lock": agree["lock"],
        "agree_end": agree["end"],
        "same_trap": agree["same_trap"],
        "agree": agree["agree"],
        "kappa_ratio": kap["ratio"],
        "inertia_number": np.array([r.inertia_number for r in runs]),
    }
    status = np.array(
        upstream["mujoco"].status if upstream["mujoco"].status is not None else np.full(n, "ok"), dtype=object
    )
    reason = np.where(
        status == "ok", "", "mujoco run: " + np.asarray(upstream["mujoco"].reason, dtype=object)
    ).astype(object)
    status = np.where(status == "ok", "ok", "dependency_failed").astype(object)
    return AnalysisResult(metrics=metrics, status=status, reason=reason)


register_analysis(
    Analysis(
        "compare",
        _compare,
        (),
        requires=("quasistatic", "mujoco"),
        doc="quasistatic against MuJoCo per start (lengths over L_c): spine_mj.compare",
    )
)
