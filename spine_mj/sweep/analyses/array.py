"""The ``array`` analysis: an array of spines on one carriage, centred at every start.

Its layout and drive are read from the config's ``[array]`` table (or ``[grid]``): the
keys of ``spine-mj array`` (``layout``, ``rows``, ``cols``, ``spacing``, ``spacing_unit``,
``layout_seed``, ``array_drive``); the tip, engine and drive speed are the ``engine``
analysis's parameters (:data:`~spine_mj.sweep.analyses.engine.ENGINE_PARAMS`, one rig per
case: :func:`~spine_mj.sweep.analyses.engine.case_rig`). Per start it records the keys of
the command's ``summary.json``: ``n_spines``, ``holding_force_n``, ``holding_ratio``, its
predicted dynamic excess ``holding_excess_predicted`` (per spine, ``F_p``), ``peak_ratio``
and ``locked_spines``. Without ``ie`` or ``speed`` the drive runs at the arrays' default
pace (:func:`spine_mj.sim.array_ie`: its predicted excess is 1 % of ``mu F_p``) on the
case's rig (whose step the default single-spine pace bounds: never coarser than the
slower pace would allow). Touches the API of :mod:`spine_mj.sim`'s arrays here only.
"""

from __future__ import annotations

import itertools

import numpy as np

from spine_mj import sim
from spine_mj.choices import ARRAY_DRIVES, check_engine
from spine_mj.errors import SpineInputError
from spine_mj.sim.array import ARRAY_ENGINE_REFUSAL, spines_on_surface
from spine_mj.sim.drives import spring_stiffness_n_m
from spine_mj.sim.layout import MAX_SPINES
from spine_mj.sweep.analyses.engine import (
    CHECK_READS,
    ENGINE_PARAMS,
    PRECHECK_READS,
    case_plan,
    case_rig,
    check_speed,
    precheck_case,
)
from spine_mj.sweep.registry import CASE_THREADS, Analysis, AnalysisResult, ParamSpec, register_analysis

ARRAY_PARAMS = (
    *ENGINE_PARAMS,
    ParamSpec("layout", "str", "array layout", "grid", choices=("grid", "staggered", "random"), array=True),
    ParamSpec("rows", "int", "spines across the drive (y)", 2, 1, maximum=MAX_SPINES, array=True),
    ParamSpec("cols", "int", "spines along the drive (x)", 2, 1, maximum=MAX_SPINES, array=True),
    ParamSpec(
        "spacing", "float", "distance between neighbouring spines", 1.0, 0.0, exclusive=True, array=True
    ),
    ParamSpec("spacing_unit", "str", "unit of spacing", "L_c", choices=("surface", "l_s", "L_c"), array=True),
    ParamSpec("layout_seed", "int", "seed of the random layout", 0, 0, array=True),
    ParamSpec(
        "array_drive",
        "str",
        "speed: the carriage moves at the drive speed; force: a free carriage pulled by a rising force",
        "speed",
        choices=ARRAY_DRIVES,
        array=True,
    ),
)


_LAYOUT_KEYS = ("layout", "rows", "cols", "spacing", "spacing_unit", "layout_seed")


def _layout(p: dict) -> sim.Layout:
    """The layout of parameters ``p`` (one value each), as ``spine-mj array`` builds it."""
    return sim.Layout(
        kind=p["layout"],
        rows=p["rows"],
        cols=p["cols"],
        spacing=p["spacing"],
        spacing_unit=p["spacing_unit"],
        seed=p["layout_seed"],
    )


def _check_drive_keys(grid: dict) -> None:
    """Refuse the single-spine drive keys an array does not read, as ``spine-mj array``
    does (a row records only settings that were applied): the array runs its own drive
    (``array_drive``), not the ramp or the static probe, and a force pull runs to its cap,
    not for a ``duration``."""
    others = [p for p in grid["protocol"] if p != "spring"]
    if others:
        raise SpineInputError(
            f"config key protocol = {list(grid['protocol'])}: the array analysis runs its own drive "
            f"(array_drive: its carriage at the drive speed, or a force pull), not the "
            f"{' and '.join(others)} protocol; remove it, or sweep that protocol without the array"
        )
    if grid["duration"] != (None,) and "force" in grid["array_drive"]:
        raise SpineInputError(
            f"config key duration = {list(grid['duration'])}: the force array drive ignores it (a pull runs "
            "to its cap); remove it, or sweep array_drive = 'speed' separately"
        )


def _check_layouts(config) -> None:
    """Refuse at config time what ``spine-mj array`` refuses up front, rather than record
    every run ``failed``: the drive keys an array does not read, a layout of more than
    MAX_SPINES spines and ``layout_seed`` where no random layout reads it (what needs a
    case's surface, :func:`_check_case`)."""
    grid = dict(config.grid)
    for engine in grid["engine"]:
        if not check_engine(engine, "config key engine =").arrays:
            raise SpineInputError(ARRAY_ENGINE_REFUSAL.format(engine=engine))
    _check_drive_keys(grid)
    check_speed(config)
    if grid["layout_seed"] != (0,) and "random" not in grid["layout"]:
        raise SpineInputError(
            f"config key layout_seed = {list(grid['layout_seed'])}: the {' and '.join(grid['layout'])} "
            "layout ignores it (read only by the random layout); remove it"
        )
    for values in itertools.product(*(grid[k] for k in _LAYOUT_KEYS)):
        try:
            _layout(dict(zip(_LAYOUT_KEYS, values, strict=True)))
        except SpineInputError as exc:
            raise SpineInputError(f"config [array]: {exc}") from None


def _check_case(case, surface, starts) -> None:
    """The refusals of ``spine-mj array`` a case's runs would meet, before any: spines
    that cannot stand apart at the spacing (a random layout) or that land off the surface
    from any of its centres (every start at once), placed as the run places them from the
    case's tip and scales (:func:`~spine_mj.sweep.analyses.engine.case_plan`: no rig built)."""
    plan = case_plan(case, surface)
    sc, s = plan.scales, plan.length_scale_m
    layout = _layout(case.params)
    spacing = layout.spacing_in_surface_units(l_s=sc.slope_length_m / s, l_c=sc.char_length_m / s)
    offsets = layout.offsets(spacing, tip_radius=plan.tip.tip_radius_m / s)
    spines_on_surface(layout, spacing, offsets, starts, surface.bounds, 2 * plan.tip.tip_radius_m / s)


def _array(case, surface, starts, upstream):
    p = case.params
    layout = _layout(p)
    rig = case_rig(case, surface)
    ie = p["ie"]
    if ie is None and p["speed"] is None:  # the arrays' default pace
        k = spring_stiffness_n_m(rig.scales, stiffness_number=p["K"], stiffness_n_m=p["stiffness"])
        ie = sim.array_ie(
            rig.scales, mu=rig.tip.mu_s, force_control=p["array_drive"] == "force", stiffness_n_m=k
        )
    arr, drive = sim.build_array(
        rig,
        layout,
        p["array_drive"],
        ie=ie,
        speed_m_s=p["speed"],
        stiffness_number=p["K"],
        stiffness_n_m=p["stiffness"],
        duration_s=None if p["array_drive"] == "force" else p["duration"],
        settle_time_s=p["settle_time"],
    )
    det = sim.Detection(kappa_cap=p["kappa_cap"])
    runs = arr.run_batch(drive, [tuple(s) for s in starts], detection=det, nthread=CASE_THREADS.get())
    trouble = np.array([r.end_reason == "engine_trouble" for r in runs])
    status = np.where(
        trouble, ["engine_warning" if "warned" in r.end_detail else "nan" for r in runs], "ok"
    ).astype(object)
    metrics = {
        "n_spines": np.array([r.n_spines for r in runs]),
        "holding_force_n": np.array([r.holding_force_n for r in runs]),
        "holding_ratio": np.array([r.holding_ratio for r in runs]),
        "holding_excess_predicted": np.array([r.holding_excess_predicted for r in runs]),
        "peak_ratio": np.array([r.peak_ratio for r in runs]),
        "locked_spines": np.array([r.locked_spines for r in runs]),
        "end_reason": np.array([r.end_reason for r in runs], dtype=object),
        "simulated_steps": np.array([r.simulated_steps for r in runs]),
    }
    reason = np.array([r.end_detail for r in runs], dtype=object)
    return AnalysisResult(metrics=metrics, status=status, reason=reason)


register_analysis(
    Analysis(
        "array",
        _array,
        ARRAY_PARAMS,
        check_config=_check_layouts,
        check_case=_check_case,
        check_reads=(*_LAYOUT_KEYS, *CHECK_READS),
        precheck_case=precheck_case,
        precheck_reads=PRECHECK_READS,
        doc="an array of spines on one carriage centred at every start ([array] table): sim.ArrayRig",
    )
)
