"""Study 6: the paper's fractal claim in dynamics. MuJoCo's self-lock rate against the Hurst
exponent H beside the streamline's (Figs. 7E and 9), at the quasistatic corner and at one
dynamic I_e.

The surfaces are the paper-fractal preset with H overridden and the height scale of the
Fig. 9 reproduction (:func:`spine_mj.reproduce.fig9_rms_height`: a fixed spectral
prefactor, so roughness grows with H), seeds :func:`spine_mj.reproduce.fig9_seeds` (the
first surfaces of a Fig. 9 run, distinct per surface and per H). One start per surface,
at mid height, 5 % of the side in from the left edge (Fig. 9 starts on the edge; the rig's
tip needs room there). Per H it counts, among the runs without engine trouble,
those held: the streamline on the smooth surface dilated by the tip (the ``quasistatic``
analysis, with the shared force cap), the streamline on MuJoCo's facets dilated by the
tip (the ``compare`` analysis's reference, when the plan asks for it), and MuJoCo's spring
drive at the plan's lowest I_e and at one dynamic I_e (held: ended by the lock rule or the
force cap). Every rate comes with its count, its Wilson interval and the runs the engine
stopped (``failed_runs``), which are reported, not dropped silently.

Solution verification (``plan.fractal.refinements``, keys of
:data:`~spine_mj.validate.convergence.REFINEMENTS`): both MuJoCo series rerun on the first
``plan.fractal.refined_surfaces`` surfaces of every H under each refinement, each case at
its own rig's step refined (the sweep's ``timestep_factor``: the surfaces' steps differ by
up to a quarter); a rate's change is paired (the refined runs' rate minus the same
surfaces' own, over the surfaces both ran cleanly) and *converged* when the rate plus it
stays inside the rate's Wilson interval
(:func:`~spine_mj.validate.convergence.headline_convergence`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj.choices import COMPARED_ENGINES
from spine_mj.presets import calibrated_mu, load_preset
from spine_mj.reproduce import fig9_rms_height, fig9_seeds
from spine_mj.validate.convergence import REFINEMENTS, headline_convergence
from spine_mj.validate.intervals import CONFIDENCE, wilson
from spine_mj.validate.paths import tip_radius
from spine_mj.validate.plans import ValidationPlan
from spine_mj.validate.study_runner import StudyRunner

__all__ = ["SERIES", "FractalLockResult", "fractal_engines", "fractal_lock", "hurst_rows", "lock_rate"]

#: The study's surface preset.
PRESET = "paper-fractal"
#: The rate series, in the order of the table and the figure.
SERIES = ("streamline", "facets", "mujoco_corner", "mujoco_dynamic")
#: Outcomes of the streamline that hold the tip (the self-lock region or the force cap).
HELD_OUTCOMES = ("self_locked", "force_cap")
#: The series the engine's refinements rerun.
MUJOCO_SERIES = ("mujoco_corner", "mujoco_dynamic")


def lock_rate(locked: Sequence[bool], ok: Sequence[bool] | None = None) -> dict:
    """Self-lock rate among the runs without engine trouble, with its Wilson interval.

    Parameters
    ----------
    locked : sequence of bool
        Held (self-locked or stopped by the force cap), one per run.
    ok : sequence of bool, optional
        Run without engine trouble (default: all). Failed runs count in neither the rate
        nor its interval; they are reported as ``failed_runs``.

    Returns
    -------
    dict
        ``n`` (runs), ``n_ok``, ``locked`` (among the ok runs), ``failed_runs``, ``rate``
        and ``ci_low`` / ``ci_high`` (:data:`CONFIDENCE` Wilson interval; NaN when no run
        is ok).
    """
    locked = np.asarray(locked, bool)
    ok = np.ones(locked.shape, bool) if ok is None else np.asarray(ok, bool)
    if locked.shape != ok.shape:
        raise ValueError(f"locked and ok must have one shape, got {locked.shape} and {ok.shape}")
    n, n_ok, k = int(locked.size), int(ok.sum()), int((locked & ok).sum())
    rate = lo = hi = float("nan")
    if n_ok:
        lo, hi = wilson(k, n_ok, confidence=CONFIDENCE)
        rate = k / n_ok
    return {
        "n": n,
        "n_ok": n_ok,
        "locked": k,
        "failed_runs": n - n_ok,
        "rate": rate,
        "ci_low": lo,
        "ci_high": hi,
    }


def hurst_rows(runs: pd.DataFrame) -> list[dict]:
    """Rows per H from one row per (run, series).

    ``runs`` has columns ``hurst``, ``series`` (one of :data:`SERIES`), ``locked`` and
    ``ok`` (bool). A row holds ``hurst`` and, per series present, ``<key>_<series>`` for
    every key of :func:`lock_rate` (``rate_streamline``, ``ci_low_streamline``,
    ``n_ok_mujoco_corner``, ``failed_runs_mujoco_dynamic``, ...); sorted by H.
    """
    rows = []
    for hurst, grp in runs.groupby("hurst", sort=True):
        row = {"hurst": float(hurst)}
        for series in SERIES:
            sel = grp[grp["series"] == series]
            if sel.empty:
                continue
            for key, value in lock_rate(sel["locked"], sel["ok"]).items():
                row[f"{key}_{series}"] = value
        rows.append(row)
    return rows


@dataclass(frozen=True)
class FractalLockResult:
    """Result of :func:`fractal_lock`.

    Attributes
    ----------
    rows : list of dict
        Per H (:func:`hurst_rows`): rate, Wilson interval, counts and failed runs of every
        series of :data:`SERIES` that ran; where the plan refines the engine,
        ``convergence_<series>`` of each MuJoCo series
        (:func:`~spine_mj.validate.convergence.headline_convergence`).
    corner_ie, dynamic_ie : float
        The inertia numbers of the two MuJoCo series.
    surfaces_per_hurst : int
    confidence : float
        Of the intervals.
    mu : float
    tip_radius : float
        In surface units (the streamlines run on the surface dilated by it).
    runs : list of dict
        One per (surface, series): ``hurst``, ``surface``, ``series``, ``locked``, ``ok``,
        ``outcome`` (the streamline's outcome or MuJoCo's end reason and detail).
    """

    rows: list[dict]
    corner_ie: float
    dynamic_ie: float
    surfaces_per_hurst: int
    confidence: float
    mu: float
    tip_radius: float
    runs: list[dict]

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"fractal_lock_rate": self.as_dict()}

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "corner_ie": self.corner_ie,
            "dynamic_ie": self.dynamic_ie,
            "surfaces_per_hurst": self.surfaces_per_hurst,
            "confidence": self.confidence,
            "mu": self.mu,
            "tip_radius": self.tip_radius,
            "runs": self.runs,
        }


def surfaces_table(hursts: Sequence[float], n: int) -> list[dict]:
    """A sweep ``surfaces`` table: the preset at each H with the Fig. 9 height scale and
    ``n`` seeds (the index of H in the preset's ``[reproduce] hursts`` when it is there,
    so the surfaces are those of a Fig. 9 run; else past the end of that list)."""
    pre = load_preset(PRESET)
    rep = pre.extras["reproduce"]
    known = [float(h) for h in rep.get("hursts", [])]
    out = []
    for j, h in enumerate(hursts):
        h = float(h)
        index = known.index(h) if h in known else len(known) + j
        rms = fig9_rms_height(
            h, int(pre.params["nx"]), float(pre.params["size"]), rep["frequency_unit"], rep["scale"]
        )
        out.append(
            {
                "preset": PRESET,
                "set": {"hurst": h, "rms_height": float(f"{rms:.6g}"), "rms_slope": None},
                "seeds": [int(s) for s in fig9_seeds(index, n)],
            }
        )
    return out


def fractal_lock(plan: ValidationPlan, runner: StudyRunner) -> FractalLockResult:
    """Study 6: self-lock rate against H, streamline and MuJoCo (corner and dynamic I_e).

    Two sweeps over the same surfaces and start: at ``plan.lowest_ie`` with the
    quasistatic, engine (and, when ``plan.fractal.facets``, compare) analyses, and at
    ``plan.fractal.dynamic_ie`` with the engine analysis alone. Default spring drive
    (K = 30), the rig's default tip and engine.

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.

    Returns
    -------
    FractalLockResult
    """
    runner.study = "fractal_lock"
    hursts = tuple(float(h) for h in plan.fractal.hursts)
    n = int(plan.fractal.surfaces)
    mu = calibrated_mu(PRESET)
    tip = tip_radius(PRESET, None, plan.hfield_resolution)
    surfaces = surfaces_table(hursts, n)
    seed_hurst = {seed: s["set"]["hurst"] for s in surfaces for seed in s["seeds"]}
    grid = {"mu": mu, "tip_radius": tip}
    starts = {"frame": "relative", "x": [0.05], "y": [0.5]}
    corner = ["quasistatic", "engine", *(["compare"] if plan.fractal.facets else [])]
    records = []
    series = (("corner", plan.lowest_ie, corner), ("dynamic", plan.fractal.dynamic_ie, ["engine"]))
    for label, ie, analyses in series:
        doc = {
            "sweep": {"name": f"fractal-lock-{label}", "seed": 11, "analyses": analyses},
            "surfaces": surfaces,
            "starts": starts,
            "drive": {"protocol": "spring", "ie": ie},
            "grid": {
                **grid,
                **({"dl": tip / 2} if "quasistatic" in analyses else {}),
                **({"miss_reasons": False} if "compare" in analyses else {}),
            },
        }
        df, _ = runner(doc, f"fractal-lock/{label}")
        records += _records(df, label, seed_hurst)
    runs = pd.DataFrame.from_records(records)
    rows = hurst_rows(runs)
    keys = list(plan.fractal.refinements)
    if keys and plan.fractal.refined_surfaces > 0:
        thin = [{**s, "seeds": s["seeds"][: plan.fractal.refined_surfaces]} for s in surfaces]
        jobs = [
            (key, label, _refined_doc(key, label, ie, thin, starts, grid))
            for key in keys
            for label, ie, _ in series
        ]
        done = runner.many(
            [(doc, f"fractal-lock-refined/{key}/{label}") for key, label, doc in jobs], "refined engine"
        )
        refined = {
            (key, label): pd.DataFrame.from_records(_records(df, label, seed_hurst))
            for (key, label, _), (df, _) in zip(jobs, done)
        }
        _add_convergence(rows, runs, refined, plan.fractal.refinements)
    return FractalLockResult(
        rows=rows,
        corner_ie=float(plan.lowest_ie),
        dynamic_ie=float(plan.fractal.dynamic_ie),
        surfaces_per_hurst=n,
        confidence=CONFIDENCE,
        mu=float(mu),
        tip_radius=tip,
        runs=records,
    )


def _refined_doc(key: str, label: str, ie: float, surfaces: list[dict], starts: dict, grid: dict) -> dict:
    """The MuJoCo series ``label`` at ``ie`` on ``surfaces`` under refinement ``key``: its
    engine keys go to the sweep as they are, so that each case refines its own rig's."""
    return {
        "sweep": {"name": f"fractal-lock-{label}-{key}", "seed": 11, "analyses": ["engine"]},
        "surfaces": surfaces,
        "starts": starts,
        "drive": {"protocol": "spring", "ie": ie},
        "grid": {**grid, **dict(REFINEMENTS[key])},
    }


def _add_convergence(rows: list[dict], runs: pd.DataFrame, refined: dict, keys) -> None:
    """Each row's ``convergence_<series>`` of the MuJoCo series: per refinement of ``keys``
    the rate of the refined runs (``refined``: (key, label) -> records) against the same
    surfaces' own (``runs``), over the surfaces both ran cleanly."""
    for row in rows:
        h = row["hurst"]
        for series in MUJOCO_SERIES:
            if f"rate_{series}" not in row:
                continue
            label = series.removeprefix("mujoco_")
            by_key: dict[str, dict | None] = {}
            for key in keys:
                r = refined.get((key, label))
                if r is None:
                    by_key[key] = None
                    continue
                base = runs[(runs["hurst"] == h) & (runs["series"] == series)].set_index("surface")
                ref = r[r["hurst"] == h].set_index("surface")
                both = base.index.intersection(ref.index)
                both = both[base.loc[both, "ok"].to_numpy(bool) & ref.loc[both, "ok"].to_numpy(bool)]
                by_key[key] = {
                    "base": lock_rate(base.loc[both, "locked"])["rate"],
                    "refined": lock_rate(ref.loc[both, "locked"])["rate"],
                    "runs": len(both),
                }
            row[f"convergence_{series}"] = headline_convergence(
                row[f"rate_{series}"],
                (row[f"ci_low_{series}"], row[f"ci_high_{series}"]),
                by_key,
                note="not in the plan's fractal.refinements",
            )


def _records(df: pd.DataFrame, label: str, seed_hurst: dict) -> list[dict]:
    """One record per (run, series) of one sweep's run table ``label``."""
    out = []
    for _, r in df.iterrows():
        analysis, ok = r["analysis"], r["status"] == "ok"
        if analysis == "quasistatic":
            series, outcome = "streamline", r.get("outcome")
            locked = bool(r["self_locked"]) if ok else False
        elif analysis == "compare":  # the reference streamline exists when MuJoCo failed too
            series, outcome = "facets", r.get("reference_outcome")
            ok = isinstance(outcome, str) and bool(outcome)
            locked = outcome in HELD_OUTCOMES
        elif analysis == "engine":
            series = f"mujoco_{label}"
            outcome = f"{r.get('end_reason')}: {r.get('end_detail')}" if ok else str(r.get("reason"))
            locked = bool(r["self_locked"]) if ok else False
        else:
            continue
        out.append(
            {
                "hurst": seed_hurst[int(r["surface_seed"])],
                "surface": str(r["surface"]),
                "series": series,
                "locked": bool(locked),
                "ok": bool(ok),
                "outcome": None if pd.isna(outcome) else str(outcome),
            }
        )
    return out


#: The fractal self-lock comparison's Hurst exponents and I_e: the full validation plan's
#: fractal study (its corner); surfaces per H are the caller's (``--fractal N``).
FRACTAL_HURSTS = (0.65, 0.75, 0.8, 0.85, 0.95)
FRACTAL_SURFACES = 30
FRACTAL_IE = 1e-4


def fractal_engines(
    out_dir: Path,
    *,
    hursts=FRACTAL_HURSTS,
    surfaces_per_hurst: int = FRACTAL_SURFACES,
    ie: float = FRACTAL_IE,
    workers: int | None = None,
) -> list[dict]:
    """The fractal self-lock rate against H in both engines (the validation's fractal study,
    :mod:`spine_mj.validate.fractal_lock`: its surfaces, start, spring drive and lock rule),
    one sweep with ``engine = ["mujoco", "bullet"]``; per H and engine the rate among the
    runs without engine trouble with its Wilson interval. Stored under ``out_dir/sweeps``."""
    surfaces = surfaces_table(hursts, surfaces_per_hurst)
    seed_hurst = {seed: s["set"]["hurst"] for s in surfaces for seed in s["seeds"]}
    tip = tip_radius(PRESET, None, None)
    doc = {
        "sweep": {"name": "fractal-engines", "seed": 11, "analyses": ["engine"], "store_trajectories": False},
        "surfaces": surfaces,
        "starts": {"frame": "relative", "x": [0.05], "y": [0.5]},
        "drive": {"protocol": "spring", "ie": ie},
        "grid": {"mu": calibrated_mu(PRESET), "tip_radius": tip, "engine": list(COMPARED_ENGINES)},
    }
    runner = StudyRunner(Path(out_dir).resolve(), workers, None, time.perf_counter())
    runner.study = "engines"
    df, _ = runner(doc, "fractal-engines")
    rows = []
    for h in hursts:
        for engine in COMPARED_ENGINES:
            sel = df[(df["engine"] == engine) & (df["surface_seed"].map(seed_hurst) == h)]
            rate = lock_rate(
                sel["self_locked"].fillna(False).astype(bool).tolist(), (sel["status"] == "ok").tolist()
            )
            rows.append({"hurst": float(h), "engine": engine, "ie": ie, **rate})
    return rows
