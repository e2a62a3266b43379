"""What ``spine-mj stickslip`` writes: the slip catalog of the quasistatic references (and
of an engine, when asked) on one track at several K, its statistics and figures
(docs/physics.md §12).

:func:`stickslip_to` runs, per K, the overdamped and inertial references over the track's
centre line (:mod:`spine_mj.validate.slip_catalog`) and, with ``engine``, one spring drive
of that engine over the same stretch, then writes ``events.parquet`` (the catalog),
``summary.json`` (per source and K the event count, the truncated power law's ``tau``
with its interval, the cutoff ``S_m`` in L_c, the pure power law's fit, its bootstrap and
likelihood-ratio tests; per K the two-sample tests between sources, an engine's against
the reference slips fast enough for its detector, ``peak_speed_v >=``
:data:`~spine_mj.theory.motion.SLIP_SPEED_FACTOR`; for an ABBM track the
predicted cutoff ``sigma / k^2``; per reference and K the mean pulse of its shorter half of
slips and its distance from ABBM's parabola, :func:`~spine_mj.validate.slip_catalog.reference_pulses`),
``distributions.png``, ``collapse.png``, ``pulse.png`` (the mean slip pulses, an
engine's too) and ``regime.png`` (the (I_e, K) map of :func:`regime_map`) - all or none
of them.

``drops.parquet`` is every source's catalog by one rule, the spring force's drops deeper
than ``drop_floor_fp`` (:mod:`spine_mj.theory.force_drops`): the references' force along
their quasistatic paths, an engine's recorded force, and with an engine also the references
on the profile its height field makes (``*_facets``). ``summary["drops"]`` holds their
counts and the engine's two-sample tests against each, the like-for-like verdict: the speed
rule fires on a resting tip's jitter at small I_e, the drop rule does not.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.theory.motion import SLIP_SPEED_FACTOR
from spine_mj.validate import avalanche_stats as stats
from spine_mj.validate.slip_catalog import (
    COLUMNS,
    DROP_FLOOR_FP,
    REFERENCES,
    TrackUnits,
    engine_drop_rows,
    engine_rows,
    facet_count,
    reference_drop_rows,
    reference_pulses,
    reference_rows,
    track_landscape,
)

__all__ = [
    "OUTPUT_FILES",
    "StickSlipOutputs",
    "drop_summary",
    "pre_stretched_drive",
    "regime_map",
    "stickslip_to",
]

OUTPUT_FILES = (
    "events.parquet",
    "drops.parquet",
    "summary.json",
    "distributions.png",
    "collapse.png",
    "pulse.png",
    "regime.png",
)
#: Share of the track's length kept clear at each end by the default start and travel.
EDGE_SHARE = 0.05


@dataclass(frozen=True)
class StickSlipOutputs:
    """What :func:`stickslip_to` wrote: the ``summary`` dict and the ``files``."""

    summary: dict
    files: tuple[Path, ...]


def _track(surface, start: float | None, travel: float | None) -> tuple[float, float]:
    xmin, xmax, _, _ = surface.bounds
    span = xmax - xmin
    x0 = xmin + EDGE_SHARE * span if start is None else float(start)
    end = xmax - EDGE_SHARE * span
    length = end - x0 if travel is None else check_positive("travel", travel)
    if not (xmin <= x0 and x0 + length <= xmax and length > 0):
        raise SpineInputError(
            f"--travel from the start x {x0:g} must end on the track [{xmin:g}, {xmax:g}], got {length:g}"
        )
    return x0, length


def _abbm_cutoff_lc(surface, mu: float, k: float, lc: float) -> float | None:
    meta = getattr(surface, "metadata", {}) or {}
    if meta.get("generator") != "abbm_track":
        return None
    from spine_mj.surfaces import abbm_force_intensity

    return abbm_force_intensity(meta["params"]["slope_intensity"], mu) / k**2 / lc


def _abbm_smallest_lc(surface, lc: float) -> float:
    """An ABBM track's smallest slip that follows ``S^-3/2`` [L_c]; 0 on any other track."""
    meta = getattr(surface, "metadata", {}) or {}
    if meta.get("generator") != "abbm_track":
        return 0.0
    from spine_mj.surfaces import abbm_smallest_slip

    return abbm_smallest_slip(surface.spacing[0]) / lc


def stickslip_to(
    out_dir: str | Path,
    surface,
    *,
    mu: float,
    stiffness_numbers: Sequence[float] | None = None,
    ie: float,
    surface_name: str = "",
    engine: str | None = None,
    start: float | None = None,
    travel: float | None = None,
    n_bootstrap: int = 100,
    drop_floor_fp: float | None = None,
    landscape_refinement: int = 1,
    progress: Callable[[int, int, str], None] | None = None,
    **rig_options,
) -> StickSlipOutputs:
    """The stick-slip study of one track: see the module's docstring.

    Parameters
    ----------
    out_dir : path
        The output folder.
    surface : Surface
        A track uniform in y (the references follow its line ``y = 0``).
    mu, ie : float
        Friction coefficient; the drive's inertia number (the references' speed, mass and
        duration threshold, and the engine's pace).
    stiffness_numbers : sequence of float, optional
        ``K = k l_s / F_p``, each > 0 (None: an ABBM track's own range,
        :func:`~spine_mj.surfaces.abbm_stiffness_numbers`, which refuses any other surface).
    surface_name : str
        The label of the catalog's ``surface`` column.
    engine : str, optional
        Also run this engine (a registered one, :data:`spine_mj.choices.ENGINES`), one
        spring drive per K.
    start, travel : float, optional
        The stretch of track, in surface units (default: all but a twentieth at each end).
    n_bootstrap : int
        Synthetic samples of each goodness-of-fit test.
    drop_floor_fp : float
        The force-drop rule's floor and hysteresis [F_p] (``drops.parquet``), > 0
        (default :data:`~spine_mj.validate.slip_catalog.DROP_FLOOR_FP`).
    landscape_refinement : int
        The references' landscape sampled this many times finer
        (:func:`~spine_mj.validate.slip_catalog.track_landscape`'s ``refinement``): their
        grid convergence, the surface, its scales and an engine's hfield unchanged.
    progress : callable, optional
        ``progress(done, total, what)`` after each step.
    **rig_options
        :func:`~spine_mj.sim.build_rig`'s keywords (tip radius, mass, length scale, ...).
    """
    ks = _stiffness_numbers(surface, mu, stiffness_numbers)
    x0, length = _track(surface, start, travel)
    floor = DROP_FLOOR_FP if drop_floor_fp is None else check_positive("--drop-floor", drop_floor_fp)
    labels = {"surface": surface_name, "mu": float(mu), "ie": float(ie)}
    report = progress or (lambda done, total, what: None)
    total = len(ks) * (2 if engine else 1) + 1
    steps = iter(range(1, total))

    def tick(what: str) -> None:
        report(next(steps), total, what)

    events, drop_events, units_by_k, land, pulses, ref_pulses = _catalogs(
        surface, ks, (x0, x0 + length), floor, labels, engine, rig_options, tick, landscape_refinement
    )
    summary = _summary(events, surface, mu, ie, ks, units_by_k, engine, x0, length, n_bootstrap)
    summary["track"]["landscape_refinement"] = int(landscape_refinement)
    summary["drops"] = drop_summary(drop_events, engine, ks, units_by_k, floor)
    summary["pulse"] = ref_pulses
    summary["regime"] = regime_map(land, events, units_by_k)
    files = _write(Path(out_dir), events, drop_events, summary, pulses)
    report(total, total, "written")
    return StickSlipOutputs(summary, files)


def _stiffness_numbers(surface, mu: float, given) -> list[float]:
    """The study's K values: ``given``, each checked, or an ABBM track's own range."""
    if given is None:
        from spine_mj.surfaces import abbm_stiffness_numbers

        given = abbm_stiffness_numbers(surface, mu)
    ks = [check_positive("--K", k) for k in given]
    if not ks:
        raise SpineInputError("--K must name at least one stiffness number")
    return ks


def _catalogs(surface, ks, x_range, floor, labels, engine, rig_options, tick, refinement):
    """Every K's catalogs (:func:`_catalogs_at`) joined: ``(events, drop events, units by K,
    the last landscape, engine pulses, reference pulses)``."""
    import pandas as pd

    frames, drops, units_by_k, pulses, ref_pulses = [], [], {}, {}, {}
    maps, land = (pulses, ref_pulses), None
    for k_number in ks:
        units, land, frames_k, drops_k = _catalogs_at(
            surface, k_number, x_range, floor, labels, engine, rig_options, maps, tick, refinement
        )
        units_by_k[k_number] = units
        frames, drops = frames + frames_k, drops + drops_k
    events = pd.concat(frames, ignore_index=True)
    return events, pd.concat(drops, ignore_index=True), units_by_k, land, pulses, ref_pulses


def _catalogs_at(surface, k_number, x_range, floor, labels, engine, rig_options, maps, tick, refinement=1):
    """One K's catalogs (:func:`stickslip_to`): ``(units, landscape, slip frames, drop
    frames)``, its mean pulses into ``maps`` (the figure's and the references'),
    ``tick(what)`` after the references and after the engine."""
    pulses, ref_pulses = maps
    x0, x1 = x_range
    ie = labels["ie"]
    rig, scales = _rig_and_scales(surface, engine, labels["mu"], ie, k_number, rig_options)
    units = TrackUnits.of(scales, ie)
    land = track_landscape(surface, labels["mu"], units.tip_radius, x_range, refinement=refinement)
    frames, drops = _reference_frames(land, units, k_number, floor, labels)
    _add_pulses(land, units, k_number, ref_pulses, pulses)
    tick(f"references, K {k_number:g}")
    if engine:
        result = _engine_run(rig, units, land, k_number, ie, x0, x1 - x0)
        pulses[(engine, k_number)] = _pulse(result)
        own, own_drops = _engine_frames(result, rig, surface, units, k_number, x_range, engine, floor, labels)
        frames, drops = frames + own, drops + own_drops
        tick(f"{engine}, K {k_number:g}")
    return units, land, frames, drops


def _reference_frames(land, units, k_number: float, floor: float, labels: dict) -> tuple[list, list]:
    """Both references' catalogs at one K on ``land``: their slips, and their force drops
    deeper than ``floor``, as lists of catalog frames."""
    import pandas as pd

    slips = reference_rows(land, units, k_number, **labels).values()
    drops = reference_drop_rows(land, units, k_number, floor, **labels).values()
    return [pd.DataFrame(r, columns=COLUMNS) for r in slips], [
        pd.DataFrame(r, columns=COLUMNS) for r in drops
    ]


def _engine_frames(
    result, rig, surface, units, k_number, x_range, engine, floor, labels
) -> tuple[list, list]:
    """An engine run's catalogs: its slips (speed rule), and its force drops with both
    references' on the profile its height field makes over ``x_range`` (sources
    ``*_facets``), as lists of catalog frames."""
    import pandas as pd

    faceted = track_landscape(surface, labels["mu"], units.tip_radius, x_range, facets=facet_count(rig))
    slips = pd.DataFrame(engine_rows(result, units, engine, k_number, **labels), columns=COLUMNS)
    drops = [
        pd.DataFrame(engine_drop_rows(result, units, engine, k_number, floor, **labels), columns=COLUMNS)
    ]
    for source, rows in reference_drop_rows(faceted, units, k_number, floor, **labels).items():
        rows["source"] = [f"{source}_facets"] * len(rows["source"])
        drops.append(pd.DataFrame(rows, columns=COLUMNS))
    return [slips], drops


def drop_summary(drops, engine: str | None, ks: Sequence[float], units_by_k: dict, floor: float) -> dict:
    """``summary["drops"]``: the rule's ``floor_fp``, per source and K the drop count, and
    per K the engine's two-sample tests against each reference source: ``size_lc``,
    ``force_drop_fp`` and ``force_drop_fixed_carriage_fp``, the engine's drop plus
    ``k V T`` (its carriage moves ``V T`` during a drop of duration T, the references'
    stands still; the term vanishes as ``sqrt(I_e)``, docs/physics.md §12)."""
    counts: dict = {}
    for (source, k), g in drops.groupby(["source", "K"], sort=False):
        counts.setdefault(source, {})[f"{k:g}"] = len(g)
    tests: dict = {}
    for k in ks if engine else ():
        at_k = drops[drops["K"] == k]
        eng = at_k[at_k["source"] == engine]
        units = units_by_k[k]
        fixed = eng["force_drop_fp"] + units.stiffness(k) * units.speed * eng["duration_s"]
        for source in sorted(set(at_k["source"]) - {engine}):
            ref = at_k[at_k["source"] == source]
            if len(eng) < 2 or len(ref) < 2:
                continue
            tests.setdefault(f"{k:g}", {})[f"{engine}_vs_{source}"] = {
                "size_lc": stats.two_sample(eng["size_lc"].to_numpy(), ref["size_lc"].to_numpy()),
                "force_drop_fp": stats.two_sample(
                    eng["force_drop_fp"].to_numpy(), ref["force_drop_fp"].to_numpy()
                ),
                "force_drop_fixed_carriage_fp": stats.two_sample(
                    fixed.to_numpy(), ref["force_drop_fp"].to_numpy()
                ),
            }
    return {"floor_fp": float(floor), "n_events": counts, "two_sample": tests}


def _add_pulses(land, units: TrackUnits, k_number: float, ref_pulses: dict, pulses: dict) -> None:
    """The references' mean pulses at one K into the summary's ``ref_pulses`` (by source,
    then K) and the figure's ``pulses`` (by source and K)."""
    for source, pulse in reference_pulses(land, units, k_number).items():
        ref_pulses.setdefault(source, {})[f"{k_number:g}"] = pulse
        if pulse["shape"] is not None:
            pulses[(source, k_number)] = np.asarray(pulse["shape"])


def _rig_and_scales(surface, engine, mu: float, ie: float, k_number: float, rig_options: dict):
    """``(rig, scales)`` of one K: the engine's rig where one runs, else ``(None, the
    surface's scales)`` for the references alone."""
    from spine_mj.sim.build import build_rig
    from spine_mj.sim.scales import Scales

    if engine:
        rig = build_rig(surface, engine=engine, mu=mu, ie=ie, stiffness_number=k_number, **rig_options)
        return rig, rig.scales
    sizing = {
        key: rig_options[key]
        for key in ("length_scale_m", "hfield_resolution")
        if rig_options.get(key) is not None
    }
    return None, Scales.for_surface(surface, **sizing)


def _engine_run(rig, units: TrackUnits, land, k_number: float, ie: float, x0: float, length: float):
    """One spring drive from ``x0`` (:func:`pre_stretched_drive`) on ``rig``."""
    return rig.run(pre_stretched_drive(rig.scales, units, land, k_number, ie, length), start=(x0, 0.0))


def pre_stretched_drive(scales, units: TrackUnits, land, k_number: float, ie: float, length: float):
    """The spring drive of one run over ``length`` of track: the carriage runs the track's
    ``length`` plus the spring's stretch at the start's threshold (the stick phase before the
    first slide is fast-forwarded). A stretch longer than the run (a soft spring: 1600 units
    on the ``abbm`` preset at K 10, beyond any run's steps) is mostly made at the start
    instead: the spring starts stretched to all but :data:`START_MARGIN` of it
    (``SpringDrive.start_force_n``)."""
    from spine_mj.sim.build import build_drive

    threshold = max(float(land.force[0]), 0.0)
    share = 1 - START_MARGIN if threshold / units.stiffness(k_number) > length else 0.0
    lead = (1 - share) * threshold / units.stiffness(k_number)
    return build_drive(
        scales,
        "spring",
        ie=ie,
        stiffness_number=k_number,
        duration_s=(length + lead) / units.speed,
        start_force_n=share * threshold * units.preload_n,
    )


#: The share of the start's threshold force a pre-stretched spring still climbs
#: (:func:`_engine_run`), so that an engine whose breakaway lies a little below the
#: reference's still starts at rest: MuJoCo's on a flat strip of the ``abbm`` preset lies
#: within 1e-5 of it (0.5000012 F_p at mu 0.5 at the default step, 0.5000062 at dt / 2).
START_MARGIN = 0.002


#: Points of the mean pulse's normalized time axis.
PULSE_POINTS = 41


def _pulse(result) -> np.ndarray:
    """The mean x-speed of the run's slips against the time from onset over the duration,
    as the references' (:func:`~spine_mj.validate.slip_catalog.reference_pulses`): each
    slip's speed over its mean speed, the shorter half of the slips averaged, the mean
    over its peak: ``(PULSE_POINTS,)`` (NaN without slips)."""
    grid = np.linspace(0.0, 1.0, PULSE_POINTS)
    shapes, durations = [], []
    for e in result.slip_events:
        t = result.time_s[e.onset : e.stop + 1]
        v = result.velocity_m_s[e.onset : e.stop + 1, 0]
        if t.size < 5 or not np.max(v) > 0 or not e.jump_length_m > 0:
            continue
        span = t[-1] - t[0]
        shapes.append(np.interp(grid, (t - t[0]) / span, v / (e.jump_length_m / span)))
        durations.append(span)
    if not shapes:
        return np.full(PULSE_POINTS, math.nan)
    durations = np.asarray(durations)
    mean = np.asarray(shapes)[durations <= np.median(durations)].mean(axis=0)
    return mean / mean.max()


def regime_map(landscape, events, units_by_k: dict) -> dict:
    """The predicted (I_e, K) regimes of a spring drive on the track (docs/physics.md §12):

    * ``K_star``: the fold criterion, ``l_s max(-dF/du) / W`` on the track's landscape;
      above it the quasistatic tip slides steadily (no fold), below it sticks and slips;
    * per K, ``swing_ie``: where the spring-block's force swing after a slip,
      ``sqrt(I_e K_c) F_p`` (``K_c = K L_c / l_s``, :func:`~spine_mj.theory.drive_limits.spring_ie_limits`),
      reaches the inertial reference's median force drop at that K: below it a slip ends
      in a stick (stick-slip), above it the tip swings on through the next folds
      (multiple slip);
    * per K, ``quasistatic_ie``: the swing-force limit of the drive (its swing reaches
      :data:`~spine_mj.theory.drive_limits.SWING_BOUND_FP`), above which no reference applies.
    """
    from spine_mj.theory.drive_limits import spring_ie_limits

    any_units = next(iter(units_by_k.values()))
    fall = float(np.max(-np.diff(landscape.force)) / landscape.spacing)
    out = {"K_star": max(fall, 0.0) * any_units.slope_length, "swing_ie": {}, "quasistatic_ie": {}}
    for k, units in units_by_k.items():
        ratio = units.char_length / units.slope_length
        drops = events.loc[(events["source"] == "inertial") & (events["K"] == k), "force_drop_fp"]
        kc = k * ratio
        out["swing_ie"][f"{k:g}"] = float(np.median(drops) ** 2 / kc) if len(drops) else None
        out["quasistatic_ie"][f"{k:g}"] = spring_ie_limits(k, ratio)["swing-force"]
    return out


def _summary(events, surface, mu, ie, ks, units_by_k, engine, x0, length, n_bootstrap) -> dict:
    sources = [*REFERENCES, *([engine] if engine else [])]
    per_source: dict = {}
    for source in sources:
        per_source[source] = {}
        for k in ks:
            sizes = events.loc[(events["source"] == source) & (events["K"] == k), "size_lc"].to_numpy()
            fit = stats.summarize_sizes(
                sizes,
                n_bootstrap=n_bootstrap,
                xmin_floor=_abbm_smallest_lc(surface, units_by_k[k].char_length),
            )
            entry = {"n_events": fit["n_events"]}
            if "tau" in fit:
                entry.update(
                    tau=fit["tau"],
                    tau_xmin_lc=fit["tau_xmin"],
                    cutoff_lc=fit["cutoff"],
                    power_law=fit["alpha"] | {"xmin_lc": fit["xmin"], "n_tail": fit["n_tail"]},
                    goodness_of_fit=fit["gof"],
                    likelihood_ratios=fit["likelihood_ratios"],
                )
            per_source[source][f"{k:g}"] = entry
    comparisons: dict = {}
    pairs = [("inertial", "overdamped")] + ([(engine, "inertial"), (engine, "overdamped")] if engine else [])
    for k in ks:
        at_k = events[events["K"] == k]
        for a, b in pairs:
            sa, sb = at_k[at_k["source"] == a], at_k[at_k["source"] == b]
            if a == engine:  # the engine's detector sees a slip only once it outruns the carriage 5 times
                sb = sb[sb["peak_speed_v"] >= SLIP_SPEED_FACTOR]
            if len(sa) < 2 or len(sb) < 2:
                continue
            comparisons.setdefault(f"{k:g}", {})[f"{a}_vs_{b}"] = {
                col: stats.two_sample(sa[col].to_numpy(), sb[col].to_numpy())
                for col in ("size_lc", "force_drop_fp")
            }
    any_units = units_by_k[ks[0]]
    predicted = {
        f"{k:g}": _abbm_cutoff_lc(surface, mu, units_by_k[k].stiffness(k), units_by_k[k].char_length)
        for k in ks
    }
    return {
        "mu": float(mu),
        "ie": float(ie),
        "K": [float(k) for k in ks],
        "engine": engine,
        "track": {"start": x0, "travel": length, "L_c": any_units.char_length, "l_s": any_units.slope_length},
        "sources": per_source,
        "two_sample": comparisons,
        "abbm_cutoff_lc": predicted if any(v is not None for v in predicted.values()) else None,
    }


def _write(out: Path, events, drops, summary: dict, pulses: dict) -> tuple[Path, ...]:
    from spine_mj.atomic import all_or_none, atomic_output
    from spine_mj.jsonio import write_json

    paths = [out / n for n in OUTPUT_FILES]
    with all_or_none(*paths):
        with atomic_output(paths[0]) as tmp:
            events.to_parquet(tmp, index=False)
        with atomic_output(paths[1]) as tmp:
            drops.to_parquet(tmp, index=False)
        write_json(paths[2], summary)
        _figures(out, events, summary, pulses)
    return tuple(paths)


def _figures(out: Path, events, summary: dict, pulses: dict) -> None:
    from spine_mj.plotting import new_figure, save_figure

    ks = summary["K"]
    sources = list(summary["sources"])
    fig = new_figure(figsize=(4 * len(ks), 3.4), layout="constrained")
    axes = fig.subplots(1, len(ks), squeeze=False)
    for ax, k in zip(axes[0], ks):
        for source in sources:
            s = np.sort(events.loc[(events["source"] == source) & (events["K"] == k), "size_lc"].to_numpy())
            if s.size:
                ax.loglog(s, 1.0 - np.arange(s.size) / s.size, label=f"{source} ({s.size})")
        ax.set_xlabel("slip size S / L_c")
        ax.set_title(f"K = {k:g}")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    axes[0][0].set_ylabel("P(size >= S)")
    save_figure(fig, out / "distributions.png")
    fig = new_figure(figsize=(4 * len(sources), 3.4), layout="constrained")
    axes = fig.subplots(1, len(sources), squeeze=False)
    for ax, source in zip(axes[0], sources):
        series = {
            k: events.loc[(events["source"] == source) & (events["K"] == k), "size_lc"].to_numpy() for k in ks
        }
        series = {k: s for k, s in series.items() if (s > 0).sum() >= 10}
        for k, (x, y) in stats.collapse(series, 1.5).items():
            ax.loglog(x, y, "o-", ms=3, label=f"K = {k:g}")
        ax.set_xlabel("S / S_m")
        ax.set_title(source)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    axes[0][0].set_ylabel("S^3/2 P(S)")
    save_figure(fig, out / "collapse.png")
    _regime_figure(out, summary)
    fig = new_figure(figsize=(4.5, 3.4), layout="constrained")
    ax = fig.subplots()
    grid = np.linspace(0.0, 1.0, PULSE_POINTS)
    for (source, k), shape in pulses.items():
        ax.plot(grid, shape, label=f"{source}, K = {k:g}")
    ax.plot(grid, 4 * grid * (1 - grid), "k--", label="parabola (ABBM)")
    ax.set_xlabel("t / T")
    ax.set_ylabel("mean v / v_peak")
    ax.legend(fontsize=6)
    save_figure(fig, out / "pulse.png")


def _regime_figure(out: Path, summary: dict) -> None:
    from spine_mj.plotting import new_figure, save_figure

    reg, ie = summary["regime"], summary["ie"]
    ks = np.array(summary["K"], float)
    swing = np.array([reg["swing_ie"][f"{k:g}"] or np.nan for k in ks], float)
    quasi = np.array([reg["quasistatic_ie"][f"{k:g}"] for k in ks], float)
    fig = new_figure(figsize=(4.8, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.loglog(ks, swing, "o-", label="swing = median slip drop (stick-slip below)")
    ax.loglog(ks, quasi, "s--", label="swing = 1 F_p (quasistatic below)")
    ax.axvline(reg["K_star"], color="k", ls=":", label=f"K* = {reg['K_star']:.3g} (steady sliding right)")
    ax.scatter(ks, np.full(ks.size, ie), marker="x", color="r", label=f"this study (I_e {ie:g})")
    ax.set_xlabel("K")
    ax.set_ylabel("I_e")
    ax.set_title("stick-slip below the swing line, multiple slip above", fontsize=8)
    ax.legend(fontsize=6)
    save_figure(fig, out / "regime.png")
