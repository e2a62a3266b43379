"""Study 4: stick-slip. Drive-force curves, slip-event statistics and trap skipping of the
spring drive on a random concave surface, against I_e and spring stiffness.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from spine_mj import presets, sim
from spine_mj.errors import SpineInputError
from spine_mj.presets import calibrated_mu
from spine_mj.validate.paths import mujoco_traces, tip_radius
from spine_mj.validate.plans import GRAVITY, MASS_KG, FamilySpec, ValidationPlan, relative_starts
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import family_doc

__all__ = ["SlipStats", "StickSlipResult", "complementary_cdf", "slip_statistics", "stick_slip"]

#: The surface of the study (seed 1).
PRESET = "paper-random-concave"


@dataclass(frozen=True)
class SlipStats:
    """Slip events of one drive-force trace.

    Attributes
    ----------
    count : int
        Slip events (a run of ``slipping`` samples, counted once it has ended or the trace
        ends).
    jump_lengths : ndarray, shape (count,)
        Distance travelled in x-y during each event.
    force_drops : ndarray, shape (count,)
        Drive force at the onset minus the force at the end of each event (same units as
        the force trace).
    durations : ndarray, shape (count,)
    onset_indices, stop_indices : ndarray of int, shape (count,)
        Trace samples at which each event's force drop is measured (the last stuck sample
        before it and its last sample), so that the spring energy released over the same
        events (:func:`spine_mj.energy.elastic_release_j`) is read at the same points.
    """

    count: int
    jump_lengths: np.ndarray
    force_drops: np.ndarray
    durations: np.ndarray
    onset_indices: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    stop_indices: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    def summary(self) -> dict:
        def stat(a):
            return float(np.mean(a)) if a.size else 0.0

        return {
            "count": self.count,
            "mean_jump": stat(self.jump_lengths),
            "max_jump": float(self.jump_lengths.max()) if self.count else 0.0,
            "mean_force_drop": stat(self.force_drops),
            "max_force_drop": float(self.force_drops.max()) if self.count else 0.0,
        }


def slip_statistics(time_s, x, y, force, slipping, *, min_samples: int = 1) -> SlipStats:
    """Slip events (runs of ``slipping``) of a trace, with jump length and force drop.

    Parameters
    ----------
    time_s, x, y, force : array_like, shape (n,)
    slipping : array_like of bool, shape (n,)
    min_samples : int
        Shorter runs of ``slipping`` are ignored (detector chatter).

    Returns
    -------
    SlipStats
    """
    t = np.asarray(time_s, float)
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    f = np.asarray(force, float)
    s = np.asarray(slipping, bool)
    if not (t.shape == x.shape == y.shape == f.shape == s.shape) or t.ndim != 1:
        raise SpineInputError(
            f"time_s, x, y, force and slipping must be 1-D of one length, "
            f"got {t.shape}, {x.shape}, {y.shape}, {f.shape}, {s.shape}"
        )
    edges = np.diff(np.r_[0, s.astype(np.int8), 0])
    on, off = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)  # [on, off)
    keep = (off - on) >= min_samples
    on, off = on[keep], off[keep]
    jumps, drops, durs, starts, ends = [], [], [], [], []
    for a, b in zip(on, off):
        end = min(b, t.size - 1)
        start = max(a - 1, 0)  # the last stuck sample before the slip
        seg = np.column_stack([x[start : end + 1], y[start : end + 1]])
        jumps.append(float(np.linalg.norm(np.diff(seg, axis=0), axis=1).sum()))
        drops.append(float(f[start] - f[end]))
        durs.append(float(t[end] - t[start]))
        starts.append(start)
        ends.append(end)
    return SlipStats(
        len(jumps),
        np.array(jumps),
        np.array(drops),
        np.array(durs),
        np.array(starts, np.int64),
        np.array(ends, np.int64),
    )


def complementary_cdf(samples) -> tuple[np.ndarray, np.ndarray]:
    """The empirical complementary CDF of ``samples``: sorted finite values ``x`` and the
    fraction ``P(X >= x)`` of samples at least as large (1 at the smallest, ``1/n`` at the
    largest), the form in which heavy-tailed slip sizes are drawn on log axes."""
    x = np.sort(np.asarray(samples, dtype=float).ravel())
    x = x[np.isfinite(x)]
    n = x.size
    # ties share the fraction of their first occurrence: P(X >= x) counts them all
    first = np.searchsorted(x, x, side="left")
    return x, (n - first) / n if n else np.zeros(0)


@dataclass(frozen=True)
class StickSlipResult:
    """Result of :func:`stick_slip`.

    Attributes
    ----------
    rows : list of dict
        Per (I_e, stiffness), sorted: ``ie``, ``stiffness_fp_per_lc``, ``runs``,
        ``slip_events_per_run``, mean and max jump (L_c) and force drop (F_p),
        ``quasistatic_traps``, ``skipped_traps`` (quasistatic self-lock, MuJoCo not),
        ``extra_locks``.
    traces : dict
        ``(ie, stiffness_n_m)`` -> (time_s, drive force / F_p) of the first start.
    surface : str
    """

    rows: list[dict]
    traces: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]]
    surface: str

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"stick_slip": self.rows}

    def as_dict(self) -> dict:
        return {"rows": self.rows, "traces": self.traces, "surface": self.surface}


def stick_slip(plan: ValidationPlan, runner: StudyRunner) -> StickSlipResult:
    """Study 4: spring drive on a random concave surface (traps) over I_e x stiffness.

    Returns
    -------
    StickSlipResult
        Slip statistics (force in F_p, lengths in L_c) and the trap-skipping rate per
        (I_e, stiffness); drive-force curves of the first start for the figure.
    """
    runner.study = "stick_slip"
    fam = FamilySpec("stick", (PRESET,), (1,), relative_starts(plan.stick_slip_starts, 0.1))
    tip = tip_radius(PRESET, fam.seeds, plan.hfield_resolution)
    lc_units = sim.characteristic_length(presets.make_surface(PRESET, seed=1))
    fp = MASS_KG * GRAVITY
    lc_m = lc_units * sim.DEFAULT_LENGTH_SCALE_M
    stiff = [float(f"{k * fp / lc_m:.6g}") for k in plan.stick_slip_stiffness]
    grid = {
        "mu": calibrated_mu(PRESET),
        "tip_radius": tip,
        "dl": tip / 2,
        "hfield_resolution": plan.hfield_resolution,
    }
    doc = family_doc(
        fam,
        name="stick-slip",
        preset=PRESET,
        drive={"protocol": "spring", "ie": list(plan.stick_slip_ie), "stiffness": stiff},
        grid=grid,
    )
    df, store = runner(doc, "stick-slip")
    mj = df[df["analysis"] == "mujoco"]
    comp = df[df["analysis"] == "compare"].set_index(["case_id", "start"])
    rows, traces = [], {}
    for (case_id, ie, k), grp in mj.groupby(["case_id", "ie", "stiffness"], sort=False):
        stats = []
        for s, tr in mujoco_traces(store, case_id).items():
            stats.append(
                slip_statistics(
                    tr["time_s"],
                    tr["x"] / lc_units,
                    tr["y"] / lc_units,
                    tr["drive_force_n"] / fp,
                    tr["slipping"],
                    min_samples=3,
                )
            )
            if s == 0:
                traces[(float(ie), float(k))] = (tr["time_s"].to_numpy(), tr["drive_force_n"].to_numpy() / fp)
        locked_mj = grp["self_locked"].astype(bool).to_numpy()
        agree_lock = np.array([bool(comp.loc[(case_id, int(s)), "agree_lock"]) for s in grp["start"]])
        qs_locked = np.where(agree_lock, locked_mj, ~locked_mj)  # agree_lock: same as qs
        rows.append(_row(float(ie), float(k) * lc_m / fp, stats, qs_locked, locked_mj))
    rows.sort(key=lambda r: (r["ie"], r["stiffness_fp_per_lc"]))
    return StickSlipResult(rows=rows, traces=traces, surface=f"{PRESET}#1")


def _row(
    ie: float,
    stiffness_fp_per_lc: float,
    stats: list[SlipStats],
    qs_locked: np.ndarray,
    locked_mj: np.ndarray,
) -> dict:
    """The row of one (I_e, stiffness) case from its starts' slip statistics and locks."""
    jumps = np.concatenate([st.jump_lengths for st in stats]) if stats else np.array([])
    drops = np.concatenate([st.force_drops for st in stats]) if stats else np.array([])
    return {
        "ie": ie,
        "stiffness_fp_per_lc": stiffness_fp_per_lc,
        "runs": len(stats),
        "slip_events_per_run": float(np.mean([st.count for st in stats])) if stats else 0.0,
        "mean_jump_lc": float(jumps.mean()) if jumps.size else 0.0,
        "max_jump_lc": float(jumps.max()) if jumps.size else 0.0,
        "mean_force_drop_fp": float(drops.mean()) if drops.size else 0.0,
        "max_force_drop_fp": float(drops.max()) if drops.size else 0.0,
        "quasistatic_traps": int(qs_locked.sum()),
        "skipped_traps": int((qs_locked & ~locked_mj).sum()),
        "extra_locks": int((~qs_locked & locked_mj).sum()),
    }
