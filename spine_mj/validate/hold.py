"""Will a spine hold on this surface? ``spine-mj hold``: a user's own surface (a preset, an
.npz, an instrument scan) judged as the validation judges its families (issue 41, 6).

1. The corner: :func:`~spine_mj.theory.drive_limits.drive_limits` of the surface with the
   rig's own tip, and the validation's rule from them
   (:func:`~spine_mj.validate.predicted_limits.surface_corner`): the spring drive
   ``(I_e, K)`` at which this surface's paths are quasistatic, ``K_path`` read on the
   first places.
2. The self-lock share: quasistatic streamlines of the tip-dilated surface from
   ``reference_starts`` random places, pulled along +x; the share that ends held (the
   self-lock region, or the comparison's force cap), with its Wilson interval.
3. The check: MuJoCo at that corner from a subsample of those places (the first
   ``starts``), each run as an ensemble (:mod:`~spine_mj.validate.ensembles`), through the
   sweep machinery (:class:`~spine_mj.validate.study_runner.StudyRunner`: a killed run
   resumes where it stopped); the agreement over the well-conditioned starts, Wilson. The
   first case of starts runs first, and the rest only where, at its pace, they fit the
   budget (:func:`_rest_of_base`).
   Where fewer than :data:`MIN_PAIRED_STARTS` of them are left paired at every level (starts
   on watersheds, references stalled in pits), more places are added as starts
   (:func:`_more_starts`: by their count, never by their outcome) and everything is judged
   again on all of them.
4. Refinement until converged (:mod:`~spine_mj.validate.convergence`): along each axis of
   :data:`LADDERS` (the step, the hfield, the solver's tolerance) the next level runs on the
   same starts until its change from the level before lies inside the agreement's (and the
   median Frechet's) own interval; an axis whose last level still moves it, or a budget
   spent before a level could run, leaves the verdict unconverged, and says which.

Everything is written under the output folder: ``surface.npz`` (the surface the sweeps
read), ``sweeps/`` (the resumable stores), ``summary.json``, ``report.md`` and
``hold.png``; ``summary.json`` and the report are written last, all or none.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from spine_mj.errors import SpineInputError
from spine_mj.validate.convergence import HEADLINES, JUDGED, RESOLUTIONS, is_converged, paired_change
from spine_mj.validate.ensembles import (
    ENSEMBLE_RADIUS_LC,
    ensemble_groups,
    ensemble_starts,
    ensemble_verdicts,
)
from spine_mj.validate.hold_summary import hold_summary, interval_bounds
from spine_mj.validate.intervals import bootstrap, wilson
from spine_mj.validate.study_runner import StudyRunner, ValidationProgress

__all__ = ["LADDERS", "MIN_PAIRED_STARTS", "HoldSettings", "hold_to"]

#: Refinement axes, each a ladder of levels (key, label, the sweep's grid keys): a level
#: runs only where the one before it still moved the headlines.
LADDERS: dict[str, tuple[tuple[str, str, dict], ...]] = {
    "step": (
        ("dt_halved", "dt / 2", {"timestep_factor": 0.5}),
        ("dt_quartered", "dt / 4", {"timestep_factor": 0.25}),
        ("dt_eighth", "dt / 8", {"timestep_factor": 0.125}),
    ),
    "hfield": (
        ("hfield_doubled", "hfield x 2", {"hfield_refinement": 2}),
        ("hfield_quadrupled", "hfield x 4", {"hfield_refinement": 4}),
    ),
    "tolerance": (
        ("tolerance_tightened", "tolerance / 100", {"tolerance": 1e-10, "noslip_tolerance": 1e-8}),
    ),
}

#: A refined level costs about this many times the base level's time per run (a step
#: halved doubles the steps; the hfield's cost is in its collisions, bounded the same way).
_LEVEL_COST = {"timestep_factor": lambda f: 1.0 / f, "hfield_refinement": lambda f: float(f)}

#: Paired well-conditioned starts a converged verdict needs (the project's rule: a number
#: counts once halving the step and refining the grid leave it inside its interval on 30
#: or more paired starts); fewer run, and are reported, but leave the verdict unconverged.
MIN_PAIRED_STARTS = 30

#: Rounds of starts added where too few paired well-conditioned ones are left (:func:`_more_starts`).
POWER_ROUNDS = 2

#: Starts (whole ensembles) per sweep case: the cases keep the workers busy.
_CASE_STARTS = 12


@dataclasses.dataclass(frozen=True)
class HoldSettings:
    """What ``spine-mj hold`` runs.

    Attributes
    ----------
    mu : float
        Friction coefficient mu_s (resolved by :func:`spine_mj.presets.resolve_mu`).
    tip_radius : float or None
        Tip radius in the surface's length unit (None: the rig's default,
        :meth:`spine_mj.sim.scales.Scales.for_surface`).
    starts : int
        MuJoCo starts (each an ensemble of ``members``; the refinements pair on them). 40:
        a verdict needs :data:`MIN_PAIRED_STARTS` well-conditioned ones, and a rough
        surface puts some starts on a watershed (10 of 30 on the AFM scan di-1).
    reference_starts : int
        Places the self-lock share is traced from (the MuJoCo starts are the first of them).
    members : int
        Ensemble members per MuJoCo start (:mod:`spine_mj.validate.ensembles`).
    budget_s : float
        Wall seconds from the start. The corner's limits, the self-lock share and its first
        case of MuJoCo runs (the first :data:`_CASE_STARTS` starts) always run, and count;
        the rest of the starts asked for, a refinement level or a round of added starts,
        predicted at the pace measured so far to end past them, is not run, and the verdict
        says so.
    seed : int
        Seed of the random places.
    """

    mu: float
    tip_radius: float | None = None
    starts: int = 40
    reference_starts: int = 400
    members: int = 2
    budget_s: float = 3600.0
    seed: int = 1

    def __post_init__(self):
        for name, lo in (("starts", 1), ("reference_starts", 1), ("members", 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
                raise SpineInputError(f"--{name.replace('_', '-')} must be an integer >= {lo}, got {v!r}")
        if self.reference_starts < self.starts:
            raise SpineInputError(
                f"--reference-starts ({self.reference_starts}) must be at least --starts ({self.starts}): "
                "the MuJoCo starts are a subsample of the reference's"
            )
        if not (
            isinstance(self.budget_s, (int, float)) and math.isfinite(self.budget_s) and self.budget_s > 0
        ):
            raise SpineInputError(f"--budget must be a finite number of seconds > 0, got {self.budget_s!r}")
        if not (isinstance(self.mu, (int, float)) and math.isfinite(self.mu) and self.mu > 0):
            raise SpineInputError(f"--mu must be a finite number > 0, got {self.mu!r}")
        from spine_mj.sim.scales import check_tip_radius

        check_tip_radius(self.tip_radius, "--tip-radius", point=False)


def hold_to(
    surface,
    out_dir,
    settings: HoldSettings,
    *,
    label: str = "surface",
    workers: int | None = None,
    progress: Callable[[ValidationProgress], None] | None = None,
) -> dict:
    """Judge ``surface`` (a :class:`~spine_mj.surfaces.Surface`) and write the verdict under
    ``out_dir`` (module doc); ``label`` names it in the verdict. Returns the summary
    (``summary.json``'s contents).

    Raises
    ------
    SpineInputError
        A surface the rig cannot run (too narrow for the tip, ...) or limits that place no
        corner, before anything is written; an output folder that cannot be written.
    """
    from spine_mj.atomic import all_or_none, writable_path
    from spine_mj.surface_io import save_surface
    from spine_mj.validate.report.hold import write_hold

    t0 = time.perf_counter()
    out = Path(out_dir).absolute()
    runner = StudyRunner(out, workers, progress, t0)
    runner.study = "hold"
    tip, lc, places, limits, corner = _corner(surface, settings, runner.report)
    held, share = _self_lock_share(runner, surface, places, tip, settings.mu)
    first = places[: settings.starts]
    batches = _Batches(
        runner,
        out / "surface.npz",
        {"protocol": "spring", "ie": corner.ie, "K": corner.k},
        {"mu": settings.mu, "tip_radius": tip, "dl": tip / 2},
        (ENSEMBLE_RADIUS_LC * lc,) * 2,
        [first[:_CASE_STARTS]],
    )
    with _undone_on_refusal(out):
        writable_path(out / "summary.json")
        save_surface(surface, batches.surface_file)
        base = batches.base(settings.members)
    base, base_note = _rest_of_base(batches, base, first[_CASE_STARTS:], settings, t0)
    first_batches = len(batches.points)
    while True:
        judged = _judge(batches, base, settings, budget_left=settings.budget_s - (time.perf_counter() - t0))
        n_run = batches.starts()
        add, note = _more_starts(
            judged["paired"],
            n_run,
            len(places),
            settings.budget_s - (time.perf_counter() - t0),
            (time.perf_counter() - base["started"]) / max(len(batches.points[-1]), 1),
        )
        if add and len(batches.points) - first_batches >= POWER_ROUNDS:
            note = f"{POWER_ROUNDS} rounds of added starts were not enough"
        if judged["converged"] or note or not add:
            why = "; ".join(w for w in (base_note, judged["why"], note) if w)
            break
        batches.points.append(places[n_run : n_run + add])
        base = batches.base(settings.members)
    summ, verdicts, levels = judged["summ"], judged["verdicts"], judged["levels"]
    summary = hold_summary(
        label, settings, corner, limits, tip, share, summ, verdicts, levels, judged["converged"], why
    )
    summary["mujoco_starts"] = {
        "run": n_run,
        "asked": settings.starts,
        "added_rounds": len(batches.points) - first_batches,
    }
    summary["timings_s"] = {"total": time.perf_counter() - t0, "base_level": base["seconds"]}
    with all_or_none(out / "summary.json", out / "report.md", out / "hold.png"):
        write_hold(out, summary, surface, places, held, places[:n_run])
    return summary


@dataclasses.dataclass
class _Batches:
    """The hold's sweeps over its batches of MuJoCo starts: the starts asked for, then each
    round of added ones (:func:`_more_starts`), each batch its own store (resumed where it
    ran), the run tables concatenated."""

    runner: StudyRunner
    surface_file: Path
    drive: dict
    grid: dict
    radius: tuple
    points: list

    def starts(self) -> int:
        return sum(len(p) for p in self.points)

    def run(self, name: str, grid: dict, members: int, key: str) -> list:
        """``[(df, store)]`` of the sweep ``name`` (``grid`` over the base's) on each batch,
        stored under ``sweeps/<key>`` (the first batch) and ``sweeps/<key>-<n>``."""
        jobs = [
            (
                _doc(
                    name,
                    self.surface_file,
                    _ensembles(pts, members, self.radius),
                    self.drive,
                    {**self.grid, **grid},
                    members,
                ),
                key if b == 0 else f"{key}-{b + 1}",
            )
            for b, pts in enumerate(self.points)
        ]
        return self.runner.many(jobs, key)

    def base(self, members: int) -> dict:
        """The corner's ensembles on every batch, with when it started and its seconds: the
        wall time now, or where cases were resumed from their stores, the time they recorded
        then (:func:`_recorded_s`), so that a resumed hold paces its budget as a fresh one."""
        started = time.perf_counter()
        ran = self.run("hold-base", {"ensemble_members": members}, members, "base")
        wall = time.perf_counter() - started
        return {"ran": ran, "started": started, "seconds": max(wall, _recorded_s(ran, self.runner.n_workers))}

    def level(self, key: str, grid: dict) -> pd.DataFrame:
        """A refinement level's run table: one run a start, every batch."""
        return pd.concat([df for df, _ in self.run(f"hold-{key}", grid, 1, key)], ignore_index=True)


def _recorded_s(ran, workers: int) -> float:
    """The wall seconds the sweeps ``ran`` took when their cases ran: each run row's share of
    its case's time (``time_s``), summed and shared by the ``workers``."""
    return sum(float(df["time_s"].sum()) for df, _ in ran if "time_s" in df) / max(workers, 1)


def _judge(batches: _Batches, base: dict, settings: HoldSettings, *, budget_left: float) -> dict:
    """One round's verdict: the corner's headlines over the well-conditioned ensembles, and
    the refinement ladders climbed on the same starts (:func:`_refine`)."""
    ran, members = base["ran"], settings.members
    verdicts = ensemble_verdicts([g for df, st in ran for g in ensemble_groups(df, st, members)])
    rows = pd.concat([_rows(df, members) for df, _ in ran], ignore_index=True)
    rows["well_conditioned"] = [
        verdicts["well_conditioned"].get(f"{c}/{int(s)}", False)
        for c, s in zip(rows["case_id"], rows["start"])
    ]
    summ = _headlines(rows, verdicts)
    levels, converged, why, paired = _refine(
        batches.level, summ, rows, budget_left=budget_left, base_s=base["seconds"] / members
    )
    return {
        "summ": summ,
        "verdicts": verdicts,
        "levels": levels,
        "converged": converged,
        "why": why,
        "paired": paired,
    }


def _rest_of_base(batches: _Batches, base: dict, rest, settings: HoldSettings, t0: float):
    """``(base, note)``: the corner's first case (its first :data:`_CASE_STARTS` starts) has
    run; the rest of the starts asked for run too where, at the first case's pace, they end
    within the budget, else the verdict rests on the first case and ``note`` says why. The
    base's seconds are both batches'."""
    if not len(rest):
        return base, ""
    first = len(batches.points[0])
    predicted = base["seconds"] / first * len(rest)
    left = settings.budget_s - (time.perf_counter() - t0)
    if predicted > left:
        return base, (
            f"the corner's other {len(rest)} starts would take {predicted:.0f} s, past the budget "
            f"({_left(left)}): its first {first} ran"
        )
    batches.points.append(rest)
    spent = base["seconds"]
    base = batches.base(settings.members)
    return {**base, "seconds": base["seconds"] + spent}, ""


def _ensembles(points, members: int, radius) -> dict:
    """The starts table of ``points``, each the first of an ensemble of ``members``."""
    table = {"frame": "absolute", "points": [tuple(map(float, p)) for p in points]}
    return ensemble_starts(table, members, radius) if members > 1 else table


def _more_starts(paired: int, n_run: int, n_places: int, budget_left: float, per_start_s: float):
    """``(starts to add, note)`` where fewer than :data:`MIN_PAIRED_STARTS` paired
    well-conditioned starts are left (stalled references, watersheds): enough more, at the
    yield so far and a quarter over, that the next round reaches them; 0 with the reason
    where the places or the budget (``per_start_s`` each, every level) do not allow."""
    if paired >= MIN_PAIRED_STARTS:
        return 0, ""
    want = math.ceil(MIN_PAIRED_STARTS * 1.25 * n_run / max(paired, 1)) - n_run
    want = min(want, n_run, n_places - n_run)
    if want <= 0:
        return 0, f"no more places to add starts from (--reference-starts {n_places})"
    if want * per_start_s > budget_left:
        return 0, (
            f"{want} more starts would take {want * per_start_s:.0f} s, past the budget "
            f"({_left(budget_left)})"
        )
    return want, ""


def _left(budget_left: float) -> str:
    """What is left of the budget, in words: ``"120 s left"``, or ``"spent 30 s over"`` where
    the corner and its first case of runs (which always run) took more than all of it."""
    return f"{budget_left:.0f} s left" if budget_left >= 0 else f"spent {-budget_left:.0f} s over"


@contextlib.contextmanager
def _undone_on_refusal(out: Path):
    """Remove what this call wrote under ``out`` (the folder if it made it, else the surface
    file it added) when the corner's sweep is refused before it runs (one Error line,
    nothing half-written); a folder being resumed keeps what it had."""
    made, had_surface = not out.exists(), (out / "surface.npz").exists()
    try:
        yield
    except SpineInputError:
        if made:
            shutil.rmtree(out, ignore_errors=True)
        elif not had_surface:
            (out / "surface.npz").unlink(missing_ok=True)
        raise


def _corner(surface, settings: HoldSettings, report: Callable[[str, int, int], None]):
    """``(tip, L_c, places, limits, corner)``: the rig's tip radius and L_c (surface units),
    the random places (:func:`_places`), the surface's
    :func:`~spine_mj.theory.drive_limits.drive_limits` with that tip and the corner placed
    inside them by the validation's rule
    (:func:`~spine_mj.validate.predicted_limits.surface_corner`), ``K_path`` read on the
    first :data:`~spine_mj.validate.predicted_limits.CORNER_PATH_STARTS` places with each
    carriage stopping where a run's does. ``report(step, done, total)`` hears the two parts
    that grow with the grid where they are long (the rig's sizing of a large hfield, the
    limits' dilation of a large grid by the tip: a quick one, and a refusal, print nothing),
    and the corner once placed."""
    from spine_mj import sim
    from spine_mj.theory import drive_limits as dlim
    from spine_mj.validate.predicted_limits import CORNER_PATH_STARTS, surface_corner

    tip_m = sim.scales.engine_tip_radius_m(surface, settings.tip_radius, name="--tip-radius")
    scales = sim.Scales.for_surface(
        surface,
        tip=sim.TipParams(tip_radius_m=tip_m, mu_s=settings.mu),
        progress=lambda done, total, stage: report(f"corner: {stage}", int(done), int(total)),
    )
    tip = scales.tip_radius_m / scales.length_scale_m
    places = _places(surface, tip, settings)
    limits = dlim.drive_limits(
        surface,
        settings.mu,
        tip_radius=tip,
        path_starts=places[:CORNER_PATH_STARTS],
        carriage_edge=surface.bounds[1],
        progress=lambda done, total: report("corner: drive limits (dilating by the tip)", done, total),
    )
    if not limits.k_star > 0:
        raise SpineInputError(
            f"SURFACE: no path on it folds (K* = {limits.k_star:g}: its hold force never falls, a plane "
            "or a slope without features), so there is no drive corner to check MuJoCo at"
        )
    corner = surface_corner([limits])
    report("corner", 1, 1)
    return tip, scales.char_length_m / scales.length_scale_m, places, limits, corner


def _self_lock_share(runner, surface, places, tip: float, mu: float) -> tuple[np.ndarray, dict]:
    """Whether each place's quasistatic streamline on the tip-dilated surface ends held, and
    the held share with its Wilson interval."""
    from spine_mj.surfaces.dilation import dilate
    from spine_mj.theory import streamline as sl
    from spine_mj.theory.streamline_types import StreamlineParams

    with runner.phase("self-lock share") as tick:
        traced = dilate(surface, tip)
        params = StreamlineParams(mu=mu, dl=tip / 2, edge_margin=tip)
        ref = sl.streamlines(traced, places, params, store_paths=False)
        tick()
    held = np.asarray(ref.self_locked, bool)
    n_held = int(held.sum())
    return held, {
        "value": n_held / len(held),
        **interval_bounds(wilson(n_held, len(held))),
        "n": int(len(held)),
    }


def _places(surface, tip: float, settings: HoldSettings) -> np.ndarray:
    """``reference_starts`` random places inside the bounds (a tip radius and 5 % in from each
    edge), from ``settings.seed``."""
    xmin, xmax, ymin, ymax = surface.bounds
    mx, my = (max(tip, 0.05 * (b - a)) for a, b in ((xmin, xmax), (ymin, ymax)))
    rng = np.random.default_rng(settings.seed)
    u = rng.random((settings.reference_starts, 2))
    return np.column_stack(
        [xmin + mx + u[:, 0] * (xmax - xmin - 2 * mx), ymin + my + u[:, 1] * (ymax - ymin - 2 * my)]
    )


def _doc(name: str, surface_file: Path, starts: dict, drive: dict, grid: dict, members: int) -> dict:
    """A hold sweep: the surface file, ``starts`` split into cases of whole ensembles."""
    pts = list(starts["points"])
    size = _CASE_STARTS * members
    chunks = [pts[i : i + size] for i in range(0, len(pts), size)]
    return {
        "sweep": {"name": name, "seed": 11, "analyses": ["quasistatic", "engine", "compare"]},
        "surfaces": [
            {"file": str(surface_file), "starts": {"frame": "absolute", "points": c}} for c in chunks
        ],
        "drive": drive,
        # the verdict is the rigid reference's: the compliant one (most of a grit's time) is not run
        "grid": {**grid, "miss_reasons": False, "compliant_reference": False},
    }


def _rows(df: pd.DataFrame, members: int) -> pd.DataFrame:
    """The ``compare`` rows of each ensemble's own start (``start`` renumbered per start),
    with the MuJoCo run's L_c (``surface_lc``) and status."""
    df = df[df["start"].astype(int) % members == 0].copy()
    df["start"] = df["start"].astype(int) // members
    comp = df[df["analysis"] == "compare"].copy()
    mj = df[df["analysis"] == "engine"].set_index(["case_id", "start"])
    key = list(zip(comp["case_id"], comp["start"].astype(int)))
    comp["surface_lc"] = [mj.loc[k, "char_length"] for k in key]
    comp["mujoco_status"] = [mj.loc[k, "status"] for k in key]
    return comp.reset_index(drop=True)


def _headlines(rows: pd.DataFrame, verdicts: dict) -> dict:
    """The base level's headlines (:data:`~spine_mj.validate.convergence.HEADLINES`) and
    their 95 % intervals."""
    n = len(rows)
    agree = int(rows["agree"].fillna(False).astype(bool).sum())
    frechet = rows["frechet"].to_numpy(float)
    return {
        "agreement_well_conditioned": verdicts["agreement_well_conditioned"],
        "agreement_ci": verdicts["agreement_ci"],
        "outcome_agreement": agree / n if n else math.nan,
        "outcome_agreement_ci": list(wilson(agree, n)),
        "median_frechet": float(np.nanmedian(frechet)) if np.isfinite(frechet).any() else math.nan,
        "median_frechet_ci": list(bootstrap(frechet)),
        "runs": n,
        "failed_runs": int((rows["mujoco_status"] != "ok").sum()),
    }


def _refine(run_level, summ: dict, base: pd.DataFrame, *, budget_left: float, base_s: float):
    """Climb each ladder of :data:`LADDERS` until its last change is inside the intervals;
    ``run_level(key, grid)`` gives a level's run table.

    Returns ``(levels, converged, why, paired)``: one entry per level run or skipped (key,
    label, runs, per headline its base, refined and change, ``converged``), whether every
    axis converged, what left it unconverged (empty when converged), and the fewest paired
    well-conditioned starts of a level run."""
    levels, reasons = [], []
    wc = base[["start_x", "start_y", "well_conditioned"]]
    for ladder in LADDERS.values():
        before, before_label = base, "corner"
        for key, label, grid in ladder:
            cost = base_s * math.prod(_LEVEL_COST[k](v) for k, v in grid.items() if k in _LEVEL_COST)
            if cost > budget_left:
                levels.append({"key": key, "label": label, "run": False, "note": f"predicted {cost:.0f} s"})
                reasons.append(
                    f"{label} did not fit the budget ({cost:.0f} s predicted, {_left(budget_left)})"
                )
                break
            started = time.perf_counter()
            df = run_level(key, grid)
            budget_left -= time.perf_counter() - started
            rows = _rows(df, 1).merge(wc, on=["start_x", "start_y"], how="left")
            rows["well_conditioned"] = rows["well_conditioned"].fillna(False).astype(bool)
            entry = _level(summ, before, rows, key, label, before_label)
            levels.append(entry)
            if entry["converged"]:
                break
            before, before_label = rows, label
        else:  # the ladder's last level still moved a headline
            last = levels[-1]
            moved = ", ".join(
                f"{h} by {last[h]['change']:+.3g}" for h in JUDGED if last.get(f"{h}_converged") is False
            )
            reasons.append(f"{last['label']} still moved {moved} (from {last['from']}), past its interval")
    paired = min((lv["well_conditioned_runs"] for lv in levels if lv["run"]), default=0)
    if paired < MIN_PAIRED_STARTS:
        stalled = [
            f"{lv['reference_stalled']} at {lv['label']}" for lv in levels if lv.get("reference_stalled")
        ]
        reasons.append(
            f"{paired} paired well-conditioned starts, fewer than the {MIN_PAIRED_STARTS} a verdict needs"
            + (f" (references stalled, no quasistatic answer: {', '.join(stalled)})" if stalled else "")
        )
    return levels, not reasons, "; ".join(reasons), paired


def _level(
    summ: dict, before: pd.DataFrame, rows: pd.DataFrame, key: str, label: str, before_label: str
) -> dict:
    """One refinement level: the paired change of each headline from the level before
    (:func:`~spine_mj.validate.convergence.paired_change`), judged in the base level's own
    interval (:func:`~spine_mj.validate.convergence.is_converged`)."""
    pc = paired_change(before, rows)
    entry: dict[str, Any] = {
        "key": key,
        "label": label,
        "run": True,
        "from": before_label,
        "runs": pc["runs"],
        "well_conditioned_runs": pc["well_conditioned_runs"],
        "reference_stalled": pc["reference_stalled"],
        "failed_runs": int((rows["mujoco_status"] != "ok").sum()),
    }
    for headline, ci in HEADLINES.items():
        change = pc[headline]["change"]
        entry[headline] = {"base": pc[headline]["base"], "refined": pc[headline]["refined"], "change": change}
        ok = is_converged(summ[headline], change, summ[ci], resolution=RESOLUTIONS[headline])
        entry[f"{headline}_converged"] = ok
    entry["converged"] = all(entry[f"{h}_converged"] is not False for h in JUDGED)
    return entry
