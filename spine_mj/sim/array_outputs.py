"""What an array run gives a designer: its force-displacement curve, a per-spine table, a
summary and a figure of the layout on the surface with each spine's path.

:func:`array_summary`, :func:`curve_table` and :func:`spine_table` turn an
:class:`~spine_mj.sim.ArrayResult` into plain records (SI units);
:func:`spine_mj.plotting.array_figure` draws it; :func:`write_array_outputs` writes them
all or none into one folder; :func:`array_to` builds, places and runs an array and writes
its folder (the whole of ``spine-mj array``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from spine_mj.atomic import all_or_none, atomic_output
from spine_mj.jsonio import write_json
from spine_mj.sim.build import build_array_on

#: The files :func:`write_array_outputs` writes.
ARRAY_OUTPUTS = ("curve.csv", "spines.csv", "summary.json", "layout.png")


def array_summary(res, arr) -> dict:
    """``summary.json`` of an array run: ``n_spines``, ``holding_force_n``, ``holding_ratio``
    (holding force over the total preload ``N F_p``), ``locked_spines``, the holding's
    predicted dynamic excess per spine (``holding_excess_predicted``, in ``F_p``), the
    largest total force of the run (``peak_force_n``, ``peak_ratio``), the pace
    (``inertia_number``) and what they came from."""
    rig, lay = arr.rig, arr.layout
    sc = rig.scales
    return {
        "n_spines": res.n_spines,
        "holding_force_n": res.holding_force_n,
        "holding_ratio": res.holding_ratio,
        "locked_spines": res.locked_spines,
        "holding_force_per_spine_n": res.holding_force_n / res.n_spines,
        "holding_excess_predicted": res.holding_excess_predicted,
        "peak_force_n": res.peak_force_n,
        "peak_ratio": res.peak_ratio,
        "inertia_number": res.inertia_number,
        "drive": "force" if arr.force_control else "speed",
        "end_reason": res.end_reason,
        "end_detail": res.end_detail,
        "layout": {
            "kind": lay.kind.value,
            "rows": lay.rows,
            "cols": lay.cols,
            "spacing": lay.spacing,
            "spacing_unit": lay.spacing_unit.value,
            "spacing_surface_units": arr.spacing,
            "seed": lay.seed,
        },
        "preload_per_spine_n": sc.preload_n,
        "mu_s": rig.tip.mu_s,
        "tip_radius_m": rig.tip.tip_radius_m,
        "char_length_m": sc.char_length_m,
        "slope_length_m": sc.slope_length_m,
        "length_scale_m": rig.length_scale_m,
        "simulated_steps": res.simulated_steps,
        "engine": rig.engine.to_dict(),
    }


def curve_table(res) -> pd.DataFrame:
    """The array's force-displacement curve: one row per recorded step."""
    return pd.DataFrame(
        {
            "time_s": res.time_s,
            "carriage_x_m": res.carriage_x_m,
            "total_force_n": res.total_force_n,
            "pull_n": res.pull_n,
        }
    )


def spine_table(res, length_scale_m: float) -> pd.DataFrame:
    """One row per spine: start (surface units and m), end position, largest force, lock."""
    end = res.position_m[-1]
    return pd.DataFrame(
        {
            "spine": np.arange(res.n_spines),
            "x0": res.start_xy[:, 0],
            "y0": res.start_xy[:, 1],
            "x0_m": res.start_xy[:, 0] * length_scale_m,
            "y0_m": res.start_xy[:, 1] * length_scale_m,
            "x_end_m": end[:, 0],
            "y_end_m": end[:, 1],
            "travel_m": end[:, 0] - res.start_xy[:, 0] * length_scale_m,
            "max_force_n": res.max_force_n,
            "locked": res.locked,
        }
    )


def write_array_outputs(res, arr, out_dir: str | os.PathLike) -> list[Path]:
    """Write :data:`ARRAY_OUTPUTS` into ``out_dir``, all of them or none."""
    from spine_mj.plotting import array_figure, save_figure

    out = Path(out_dir)
    paths = [out / name for name in ARRAY_OUTPUTS]
    with all_or_none(*paths):
        with atomic_output(paths[0]) as tmp:
            curve_table(res).to_csv(tmp, index=False)
        with atomic_output(paths[1]) as tmp:
            spine_table(res, arr.rig.length_scale_m).to_csv(tmp, index=False)
        write_json(paths[2], array_summary(res, arr))
        save_figure(array_figure(res, arr), paths[3])
    return paths


def array_to(
    out_dir: str | os.PathLike,
    surface,
    layout,
    drive: str = "speed",
    *,
    mu: float,
    centre: tuple[float, float] | None = None,
    started: Callable[[float], None] | None = None,
    **array_options,
) -> tuple:
    """An array of ``layout`` dragged over ``surface`` and its outputs written: what
    ``spine-mj array`` does.

    The array and its carriage's drive (:func:`~spine_mj.sim.build_array_on`, at its own
    pace unless ``ie`` is given), its placement at ``centre`` (refused before anything runs
    when a spine would sit off the surface), the run and :func:`write_array_outputs`.

    Parameters
    ----------
    out_dir : path
        The output folder (:data:`ARRAY_OUTPUTS`).
    surface : Surface
        The surface the array is dragged over.
    layout : Layout
        Where the spines sit on the carriage.
    drive : {"speed", "force"}
        As for :func:`~spine_mj.sim.build_array`.
    mu : float
        The tips' friction coefficient.
    centre : (float, float), optional
        The array's centre in surface units (None: its default, the rear a tenth in).
    started : callable, optional
        Called with the inertia number once the array is placed, before it runs.
    **array_options
        :func:`~spine_mj.sim.build_array_on`'s other keywords (pace, springs, duration, the
        rig's options).

    Returns
    -------
    (ArrayResult, float, list of Path)
        The run, the inertia number it ran at and the files written.
    """
    arr, carriage, ie = build_array_on(surface, layout, drive, mu=mu, **array_options)
    where = arr.default_centre() if centre is None else centre
    arr.starts(where)  # spines off the surface: refused before anything runs or is written
    if started is not None:
        started(ie)
    res = arr.run(carriage, centre=where)
    return res, ie, write_array_outputs(res, arr, out_dir)
