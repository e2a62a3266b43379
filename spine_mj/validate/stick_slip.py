"""Study 4: stick-slip. Drive-force curves, slip-event statistics and trap skipping of the
spring drive on a random concave surface, against I_e and spring stiffness.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from spine_mj import presets, sim
from spine_mj.errors import SpineInputError
from spine_mj.presets import calibrated_mu
from spine_mj.roughness import characteristic_length
from spine_mj.theory.motion import slip_events
from spine_mj.theory.tomlinson import Corrugation
from spine_mj.validate.ground_truth import CORRUGATION_START, TOMLINSON_TIP, corrugation_runs
from spine_mj.validate.paths import mujoco_traces, tip_radius
from spine_mj.validate.plans import GRAVITY, MASS_KG, FamilySpec, ValidationPlan, relative_starts
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import family_doc

__all__ = ["SlipStats", "StickSlipResult", "complementary_cdf", "slip_statistics", "stick_slip"]

#: The surface of the study (seed 1).
PRESET = "paper-random-concave"
#: The corrugation of the K scan: slope amplitude and mu (K* = 0.46 with a tip of lambda / 100).
K_SCAN_SURFACE = (0.3, 0.5)
#: A corrugation run is stick-slip when it slips at least this often per wavelength.
SLIPS_PER_WAVE = 0.5


@dataclass(frozen=True)
class SlipStats:
    """Slip events of one drive-force trace.

    Attributes
    ----------
    count : int
        Slip events (runs of ``slipping`` motion states).
    jump_lengths : ndarray, shape (count,)
        Distance travelled in x-y during each event.
    force_drops : ndarray, shape (count,)
        Peak drive force of each event minus the lowest force after it within the event
        (same units as the force trace; >= 0).
    durations : ndarray, shape (count,)
    onset_indices, stop_indices : ndarray of int, shape (count,)
        Trace samples at which each event begins (the last loading sample before it) and
        ends, so that the spring energy released over the same
        events (:func:`spine_mj.theory.energy.elastic_release_j`) is read at the same points.
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


def slip_statistics(time_s, x, y, force, motion) -> SlipStats:
    """Slip events of a trace (its runs of ``slipping`` motion states,
    :func:`spine_mj.theory.motion.slip_events`), with jump length and force drop.

    Parameters
    ----------
    time_s, x, y, force : array_like, shape (n,)
        The recorded rows: time, tip position and drive force, in one consistent set of
        units (the study passes seconds, L_c and F_p).
    motion : array_like of int, shape (n,)
        Motion state codes (:data:`spine_mj.theory.motion.MOTION_NAMES`), as recorded.

    Returns
    -------
    SlipStats
        Jump lengths along the x-y path from the onset (the last loading sample) to the
        event's last sample; force drops from the event's peak force to the lowest force
        after it (never negative).
    """
    t = np.asarray(time_s, float)
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    f = np.asarray(force, float)
    m = np.asarray(motion)
    if not (t.shape == x.shape == y.shape == f.shape == m.shape) or t.ndim != 1:
        raise SpineInputError(
            f"time_s, x, y, force and motion must be 1-D of one length, "
            f"got {t.shape}, {x.shape}, {y.shape}, {f.shape}, {m.shape}"
        )
    events = slip_events(m, t, x, f)
    jumps = [
        float(
            np.linalg.norm(
                np.diff(np.column_stack([x[e.onset : e.stop + 1], y[e.onset : e.stop + 1]]), axis=0), axis=1
            ).sum()
        )
        for e in events
    ]
    return SlipStats(
        len(events),
        np.array(jumps),
        np.array([e.force_drop_n for e in events]),
        np.array([e.duration_s for e in events]),
        np.array([e.onset for e in events], np.int64),
        np.array([e.stop for e in events], np.int64),
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
    k_scan : list of dict
        The spring drive on the corrugation :data:`K_SCAN_SURFACE` per (I_e, K): slip
        events, events per wavelength, motion fractions, the largest speed [V].
    k_star : float
        That corrugation's K* (:meth:`spine_mj.theory.tomlinson.Corrugation.critical_stiffness`).
    transitions : list of dict
        Per I_e of the scan: where stick-slip gives way to steady sliding (the bracket of K
        between the last K with at least :data:`SLIPS_PER_WAVE` slips per wavelength and the
        next) against K*.
    """

    rows: list[dict]
    traces: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]]
    surface: str
    k_scan: list[dict] = field(default_factory=list)
    k_star: float = float("nan")
    transitions: list[dict] = field(default_factory=list)

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"stick_slip": self.rows}

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "traces": self.traces,
            "surface": self.surface,
            "k_scan": self.k_scan,
            "k_star": self.k_star,
            "transitions": self.transitions,
        }


def stick_slip(plan: ValidationPlan, runner: StudyRunner) -> StickSlipResult:
    """Study 4: spring drive on a random concave surface (traps) over I_e x stiffness.

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.

    Returns
    -------
    StickSlipResult
        Slip statistics (force in F_p, lengths in L_c) and the trap-skipping rate per
        (I_e, stiffness); drive-force curves of the first start for the figure.
    """
    runner.study = "stick_slip"
    fam = FamilySpec("stick", (PRESET,), (1,), relative_starts(plan.stick_slip.starts, 0.1))
    tip = tip_radius(PRESET, fam.seeds, plan.hfield_resolution)
    lc_units = characteristic_length(presets.make_surface(PRESET, seed=1))
    fp = MASS_KG * GRAVITY
    lc_m = lc_units * sim.DEFAULT_LENGTH_SCALE_M
    stiff = [float(f"{k * fp / lc_m:.6g}") for k in plan.stick_slip.stiffness]
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
        drive={"protocol": "spring", "ie": list(plan.stick_slip.ie), "stiffness": stiff},
        grid=grid,
    )
    df, store = runner(doc, "stick-slip")
    mj = df[df["analysis"] == "engine"]
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
                    tr["motion"],
                )
            )
            if s == 0:
                traces[(float(ie), float(k))] = (tr["time_s"].to_numpy(), tr["drive_force_n"].to_numpy() / fp)
        locked_mj = grp["self_locked"].astype(bool).to_numpy()
        agree_lock = np.array([bool(comp.loc[(case_id, int(s)), "agree_lock"]) for s in grp["start"]])
        qs_locked = np.where(agree_lock, locked_mj, ~locked_mj)  # agree_lock: same as qs
        rows.append(_row(float(ie), float(k) * lc_m / fp, stats, qs_locked, locked_mj))
    rows.sort(key=lambda r: (r["ie"], r["stiffness_fp_per_lc"]))
    scan, k_star = k_scan(plan, runner)
    return StickSlipResult(
        rows=rows,
        traces=traces,
        surface=f"{PRESET}#1",
        k_scan=scan,
        k_star=k_star,
        transitions=transitions(scan, k_star),
    )


def k_scan(plan: ValidationPlan, runner: StudyRunner) -> tuple[list[dict], float]:
    """The spring drive on the corrugation :data:`K_SCAN_SURFACE` over ``plan.stick_slip.k_ie``
    x ``plan.stick_slip.k_factors`` K*: one row per run, and K*."""
    s, mu = K_SCAN_SURFACE
    k_star = Corrugation(s, mu, tip_radius=TOMLINSON_TIP).critical_stiffness()
    ks = [float(f"{f * k_star:.6g}") for f in plan.stick_slip.k_factors]
    mj = corrugation_runs(runner, "stick-slip/corrugation", s, mu, ks, list(plan.stick_slip.k_ie), 4)
    rows = []
    for _, r in mj.sort_values(["ie", "K"]).iterrows():
        travel = float(r["end_x"]) - CORRUGATION_START
        rows.append(
            {
                "ie": float(r["ie"]),
                "K": float(r["K"]),
                "k_over_k_star": float(r["K"]) / k_star,
                "slip_events": int(r["slip_events"]),
                "events_per_wave": int(r["slip_events"]) / travel if travel > 0 else float("nan"),
                "onset_mean_fp": float(r["slip_onset_fp_mean"]),
                "stuck": float(r["stuck_fraction"]),
                "sliding": float(r["sliding_fraction"]),
                "slipping": float(r["slipping_fraction"]),
                "max_speed_v": float(r["max_speed_over_drive"]),
                "status": str(r["status"]),
            }
        )
    return rows, k_star


def transitions(scan: list[dict], k_star: float) -> list[dict]:
    """Per I_e of ``scan``: the K bracket where stick-slip (at least :data:`SLIPS_PER_WAVE`
    slips per wavelength) gives way to steady sliding, and its geometric mean over K*."""
    out = []
    for ie in sorted({r["ie"] for r in scan}):
        rows = sorted((r for r in scan if r["ie"] == ie), key=lambda r: r["K"])
        slips = [r["K"] for r in rows if r["events_per_wave"] >= SLIPS_PER_WAVE]
        low = max(slips) if slips else float("nan")
        above = [r["K"] for r in rows if not slips or r["K"] > low]
        high = min(above) if above else float("nan")
        mid = float(np.sqrt(low * high)) if slips and above else float("nan")
        out.append({"ie": ie, "k_low": low, "k_high": high, "k_transition": mid, "over_k_star": mid / k_star})
    return out


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
