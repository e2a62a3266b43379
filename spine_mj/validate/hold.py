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
   resumes where it stopped); the agreement over the well-conditioned starts, Wilson.
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
from spine_mj.validate.intervals import bootstrap, wilson
from spine_mj.validate.study_runner import StudyRunner, ValidationProgress

__all__ = ["LADDERS", "MIN_PAIRED_STARTS", "HoldSettings", "hold_to", "verdict_sentence"]

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
        Wall seconds the MuJoCo levels may take; a level predicted to end past it is not run.
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

    t0 = time.perf_counter()
    out = Path(out_dir).absolute()
    tip, lc, places, limits, corner = _corner(surface, settings)
    mj_starts = places[: settings.starts]
    runner = StudyRunner(out, workers, progress, t0)
    runner.study = "hold"
    held, share = _self_lock_share(runner, surface, places, tip, settings.mu)
    base_grid = {"mu": settings.mu, "tip_radius": tip, "dl": tip / 2}
    drive = {"protocol": "spring", "ie": corner.ie, "K": corner.k}
    table = {"frame": "absolute", "points": [tuple(map(float, p)) for p in mj_starts]}
    surface_file = out / "surface.npz"
    doc = _doc(
        "hold-base",
        surface_file,
        ensemble_starts(table, settings.members, (ENSEMBLE_RADIUS_LC * lc,) * 2),
        drive,
        {**base_grid, "ensemble_members": settings.members},
        settings.members,
    )
    started = time.perf_counter()
    with _undone_on_refusal(out):
        writable_path(out / "summary.json")
        save_surface(surface, surface_file)
        df, store = runner(doc, "base")
    base_s = time.perf_counter() - started
    groups = ensemble_groups(df, store, settings.members)
    verdicts = ensemble_verdicts(groups)
    base = _rows(df, settings.members)
    base["well_conditioned"] = [
        verdicts["well_conditioned"].get(f"{c}/{int(s)}", False)
        for c, s in zip(base["case_id"], base["start"])
    ]
    summ = _headlines(base, verdicts)
    levels, converged, why = _refine(
        runner,
        summ,
        base,
        lambda name, grid: _doc(name, surface_file, table, drive, {**base_grid, **grid}, 1),
        budget_left=settings.budget_s - (time.perf_counter() - t0),
        base_s=base_s / settings.members,
    )
    summary = _summary(label, settings, corner, limits, tip, share, summ, verdicts, levels, converged, why)
    summary["timings_s"] = {"total": time.perf_counter() - t0, "base_level": base_s}
    with all_or_none(out / "summary.json", out / "report.md", out / "hold.png"):
        _write(out, summary, surface, places, held, mj_starts)
    return summary


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


def _corner(surface, settings: HoldSettings):
    """``(tip, L_c, places, limits, corner)``: the rig's tip radius and L_c (surface units),
    the random places (:func:`_places`), the surface's
    :func:`~spine_mj.theory.drive_limits.drive_limits` with that tip and the corner placed
    inside them by the validation's rule
    (:func:`~spine_mj.validate.predicted_limits.surface_corner`), ``K_path`` read on the
    first :data:`~spine_mj.validate.predicted_limits.CORNER_PATH_STARTS` places with each
    carriage stopping where a run's does."""
    from spine_mj import sim
    from spine_mj.theory import drive_limits as dlim
    from spine_mj.validate.predicted_limits import CORNER_PATH_STARTS, surface_corner

    tip_m = sim.scales.engine_tip_radius_m(surface, settings.tip_radius, name="--tip-radius")
    scales = sim.Scales.for_surface(surface, tip=sim.TipParams(tip_radius_m=tip_m, mu_s=settings.mu))
    tip = scales.tip_radius_m / scales.length_scale_m
    places = _places(surface, tip, settings)
    limits = dlim.drive_limits(
        surface,
        settings.mu,
        tip_radius=tip,
        path_starts=places[:CORNER_PATH_STARTS],
        carriage_edge=surface.bounds[1],
    )
    if not limits.k_star > 0:
        raise SpineInputError(
            f"SURFACE: no path on it folds (K* = {limits.k_star:g}: its hold force never falls, a plane "
            "or a slope without features), so there is no drive corner to check MuJoCo at"
        )
    corner = surface_corner([limits])
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
    return held, {"value": n_held / len(held), **_bounds(wilson(n_held, len(held))), "n": int(len(held))}


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


def _refine(runner, summ: dict, base: pd.DataFrame, make_doc, *, budget_left: float, base_s: float):
    """Climb each ladder of :data:`LADDERS` until its last change is inside the intervals.

    Returns ``(levels, converged, why)``: one entry per level run or skipped (key, label,
    runs, per headline its base, refined and change, ``converged``), whether every axis
    converged, and what left it unconverged (empty when converged)."""
    levels, reasons = [], []
    wc = base[["start_x", "start_y", "well_conditioned"]]
    for ladder in LADDERS.values():
        before, before_label = base, "corner"
        for key, label, grid in ladder:
            cost = base_s * math.prod(_LEVEL_COST[k](v) for k, v in grid.items() if k in _LEVEL_COST)
            if cost > budget_left:
                levels.append({"key": key, "label": label, "run": False, "note": f"predicted {cost:.0f} s"})
                reasons.append(
                    f"{label} did not fit the budget ({cost:.0f} s predicted, {budget_left:.0f} s left)"
                )
                break
            started = time.perf_counter()
            df, _ = runner(make_doc(f"hold-{key}", grid), key)
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
    return levels, not reasons, "; ".join(reasons)


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


def _bounds(interval) -> dict:
    low, high = interval
    return {"low": float(low), "high": float(high)}


def _summary(label, settings, corner, limits, tip, share, summ, verdicts, levels, converged, why) -> dict:
    agreement = {
        "value": summ["agreement_well_conditioned"],
        **_bounds(summ["agreement_ci"]),
        "n_well_conditioned": int(verdicts["well_conditioned_runs"]),
        "starts": int(verdicts["starts"]),
        "ill_conditioned_starts": int(verdicts["ill_conditioned_starts"]),
        "all_starts": summ["outcome_agreement"],
        "all_starts_interval": list(summ["outcome_agreement_ci"]),
    }
    refinements = [
        {
            "level": lv["label"],
            "key": lv["key"],
            "run": lv["run"],
            **(
                {
                    "from": lv["from"],
                    "runs": lv["runs"],
                    "well_conditioned_runs": lv["well_conditioned_runs"],
                    "reference_stalled": lv["reference_stalled"],
                    "change": lv["agreement_well_conditioned"]["change"],
                    "median_frechet_change": lv["median_frechet"]["change"],
                    "failed_runs": lv["failed_runs"],
                    "converged": lv["converged"],
                }
                if lv["run"]
                else {"note": lv["note"]}
            ),
        }
        for lv in levels
    ]
    out = {
        "surface": label,
        "mu": settings.mu,
        "tip_radius": tip,
        "corner": corner.as_dict(),
        "drive_limits": limits.as_dict(),
        "self_lock_share": share,
        "agreement": agreement,
        "median_frechet": {"value": summ["median_frechet"], **_bounds(summ["median_frechet_ci"])},
        "failed_runs": summ["failed_runs"],
        "converged": bool(converged),
        "why_unconverged": why,
        "refinements": refinements,
    }
    out["verdict"] = verdict_sentence(out)
    return out


def verdict_sentence(s: dict) -> str:
    """The summary's one-sentence verdict."""
    sh, ag, c = s["self_lock_share"], s["agreement"], s["corner"]
    hold = (
        f"a spine pulled along x holds from {sh['value']:.1%} of {sh['n']} places "
        f"[{sh['low']:.1%}, {sh['high']:.1%}] on {s['surface']} at mu_s {s['mu']:g}"
    )
    check = (
        f"MuJoCo at I_e {c['ie']:.3g}, K {c['K']:.3g} agrees on {ag['value']:.3f} "
        f"[{ag['low']:.2f}, {ag['high']:.2f}] of {ag['n_well_conditioned']} well-conditioned starts"
    )
    run = [r["level"] for r in s["refinements"] if r.get("run")]
    if s["converged"]:
        return f"{hold.capitalize()}; {check}, converged under {', '.join(run)}."
    return f"{hold.capitalize()}; {check}, not converged: {s['why_unconverged']}."


def _write(out: Path, summary: dict, surface, places, held, mj_starts) -> None:
    from spine_mj.jsonio import write_json
    from spine_mj.plotting import save_figure, styled

    save_figure(styled(_figure)(surface, places, held, mj_starts, summary), out / "hold.png")
    write_json(out / "summary.json", summary)
    (out / "report.md").write_text(_report(summary))


def _report(s: dict) -> str:
    sh, ag, c, mf = s["self_lock_share"], s["agreement"], s["corner"], s["median_frechet"]
    lines = [
        f"# Will a spine hold on {s['surface']}?",
        "",
        s["verdict"],
        "",
        "![places and refinement](hold.png)",
        "",
        "| quantity | value | 95 % interval | n |",
        "|---|---|---|---|",
        f"| self-lock share (quasistatic) | {sh['value']:.3f} | [{sh['low']:.3f}, {sh['high']:.3f}] "
        f"| {sh['n']} |",
        f"| agreement (well-conditioned) | {ag['value']:.3f} | [{ag['low']:.3f}, {ag['high']:.3f}] "
        f"| {ag['n_well_conditioned']} |",
        f"| median Frechet [L_c] | {mf['value']:.3g} | [{mf['low']:.3g}, {mf['high']:.3g}] "
        f"| {ag['starts']} |",
        "",
        f"Corner: {c['reason']}. Tip radius {s['tip_radius']:.3g} (surface units), mu_s {s['mu']:g}.",
        "",
        "| refinement | from | paired starts | agreement change | median Frechet change | converged |",
        "|---|---|---|---|---|---|",
    ]
    for r in s["refinements"]:
        if r["run"]:
            lines.append(
                f"| {r['level']} | {r['from']} | {r['runs']} | {r['change']:+.3f} "
                f"| {r['median_frechet_change']:+.3g} | {'yes' if r['converged'] else 'no'} |"
            )
        else:
            lines.append(f"| {r['level']} | | | not run: {r['note']} | | |")
    return "\n".join(lines) + "\n"


def _figure(surface, places, held, mujoco_starts, summary: dict, *, max_points: int = 300):
    """``spine-mj hold``'s figure: the places traced on the height map (held: crosses, free:
    dots; the MuJoCo starts ringed), and the agreement of each refinement level on its
    paired starts against the corner's own 95 % interval (shaded)."""
    from spine_mj import plotting as pl

    grid = pl._display_grid(surface, max_points)
    units = pl._axes_units(surface, grid)
    lf = units[0]
    fig = pl.new_figure(figsize=(12, 4.5), layout="constrained")
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    pl._height_map(fig, ax, grid, units)
    places, held = np.asarray(places, float) * lf, np.asarray(held, bool)
    ax.plot(*places[~held].T, ".", ms=3, color="#cccccc", label="free")
    ax.plot(*places[held].T, "x", ms=5, color=pl.PATH_COLORS["mujoco"], label="held (quasistatic)")
    ring = np.asarray(mujoco_starts, float) * lf
    ax.plot(*ring.T, "o", mfc="none", ms=7, color=pl.PATH_COLORS["facets"], label="MuJoCo starts")
    ax.legend(loc="upper right", fontsize="small")
    share = summary["self_lock_share"]
    ax.set_title(f"held from {share['value']:.1%} of {share['n']} places")
    ag = summary["agreement"]
    labels, values = ["corner"], [ag["value"]]
    for r in summary["refinements"]:
        if r.get("run"):
            labels.append(r["level"])
            values.append(values[labels.index(r["from"]) if r["from"] in labels else 0] + r["change"])
    bx.axhspan(ag["low"], ag["high"], color="#dddddd", label="corner's 95 % interval")
    bx.plot(range(len(values)), values, "o-", color=pl.SERIES_COLORS[0], label="agreement")
    bx.set_xticks(range(len(values)), labels, rotation=20)
    bx.set_ylim(min(0.0, min(values)) - 0.02, 1.02)
    bx.set_ylabel("agreement (well-conditioned starts)")
    bx.set_title("converged" if summary["converged"] else "not converged")
    bx.legend(loc="lower left", fontsize="small")
    return fig
