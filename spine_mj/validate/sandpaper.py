"""Study 5: sandpaper. P36 / P60 / P600 analogs with a 25 um tip (paper Fig. 6): path
waviness and force peaks of the spring drive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks

from spine_mj import presets
from spine_mj.validate.paths import mujoco_traces
from spine_mj.validate.plans import GRAVITY, MASS_KG, SANDPAPER_MU, ValidationPlan
from spine_mj.validate.study_runner import StudyRunner

__all__ = ["SandpaperResult", "sandpaper"]


@dataclass(frozen=True)
class SandpaperResult:
    """Result of :func:`sandpaper`.

    Attributes
    ----------
    rows : list of dict
        Per grit: the lateral excursion (max and rms ``|y - y0|`` over the path, in tip
        radii and in mm), path tortuosity (path length / x travel), force peaks (local
        maxima of the drive force above 1.5 times its median) and the peak / median force,
        the self-lock fraction, end reasons and failures.
    paths : dict
        Grit -> list of (x, y, time_s, drive force / F_p) for the figure.
    mu : float
    """

    rows: list[dict]
    paths: dict[str, list[tuple]]
    mu: float

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"sandpaper": self.rows}

    def as_dict(self) -> dict:
        return {"rows": self.rows, "paths": self.paths, "mu": self.mu}


def sandpaper(plan: ValidationPlan, runner: StudyRunner) -> SandpaperResult:
    """Study 5: spring drive over sandpaper analogs with a 25 um tip (paper Fig. 6).

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.

    Returns
    -------
    SandpaperResult
    """
    runner.study = "sandpaper"
    rows, paths = [], {}
    for grit in plan.sandpaper.grits:
        preset = f"sandpaper-{grit}"
        params = presets.load_preset(preset).params
        # start at least four tip radii inside the patch: the rig ends a run whose tip comes
        # within one tip radius of the edge (the P600 patch is only 16 tip radii wide)
        x_rel = max(0.05, 4 * params.get("tip_radius_m", 25e-6) / params["size_m"])
        doc = {
            "sweep": {"name": f"sandpaper-{grit}", "seed": 3, "analyses": ["engine"]},
            "surfaces": [{"preset": preset}],
            "starts": {
                "frame": "relative",
                "x": [round(x_rel, 4)],
                "y": list(np.linspace(0.25, 0.75, plan.sandpaper.starts).round(4)),
            },
            "drive": {"protocol": "spring", "ie": plan.sandpaper.ie},
            "grid": {"mu": SANDPAPER_MU, "record_every": 5},
        }
        df, store = runner(doc, f"sandpaper/{grit}")
        rows.append(_grit_row(grit, df[df["analysis"] == "engine"], store, paths))
    return SandpaperResult(rows=rows, paths=paths, mu=SANDPAPER_MU)


def _grit_row(grit: str, mj_all, store, paths: dict) -> dict:
    """The row of one grit from its ``engine`` rows and stored paths (added to ``paths``)."""
    failed = sorted(set(mj_all.loc[mj_all["status"] != "ok", "reason"].astype(str)))
    mj = mj_all[mj_all["status"] == "ok"] if "tip_radius_m" in mj_all else mj_all.iloc[:0]
    if mj.empty:
        return {"grit": grit, "runs": 0, "failed_runs": int(len(mj_all)), "failures": failed}
    tip_m = float(mj["tip_radius_m"].iloc[0])
    fp = MASS_KG * GRAVITY
    exc, rms, tort, peaks, ratio = [], [], [], [], []
    ok_starts = set(zip(mj["case_id"], mj["start"].astype(int)))
    for case_id in mj["case_id"].unique():
        for st, tr in mujoco_traces(store, case_id).items():
            if (case_id, st) not in ok_starts:
                continue
            x, y = tr["x"].to_numpy(), tr["y"].to_numpy()
            f = tr["drive_force_n"].to_numpy() / fp
            dy = np.abs(y - y[0])
            exc.append(dy.max())
            rms.append(np.sqrt(np.mean((y - y.mean()) ** 2)))
            travel = max(x[-1] - x[0], 1e-12)
            tort.append(np.linalg.norm(np.diff(np.column_stack([x, y]), axis=0), axis=1).sum() / travel)
            med = np.median(f[f > 0]) if np.any(f > 0) else 0.0
            pk, _ = find_peaks(f, height=1.5 * med if med > 0 else None, prominence=0.2)
            peaks.append(len(pk) / max(travel / tip_m, 1e-12) * 100)
            ratio.append(f.max() / med if med > 0 else float("nan"))
            paths.setdefault(grit, []).append((x, y, tr["time_s"].to_numpy(), f))
    return {
        "grit": grit,
        "runs": len(exc),
        "tip_radius_um": tip_m * 1e6,
        "max_lateral_excursion_mm": float(np.max(exc)) * 1e3,
        "mean_lateral_excursion_tip_radii": float(np.mean(exc)) / tip_m,
        "rms_lateral_tip_radii": float(np.mean(rms)) / tip_m,
        "tortuosity": float(np.mean(tort)),
        "force_peaks_per_100_tip_radii": float(np.mean(peaks)),
        "peak_over_median_force": float(np.nanmean(ratio)),
        "self_locked_fraction": float(mj["self_locked"].astype(bool).mean()),
        "end_reasons": sorted(set(mj_all["end_reason"].dropna().astype(str))),
        "failed_runs": int(len(mj_all) - len(mj)),
        "failures": failed,
    }
