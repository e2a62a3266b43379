"""What ``spine-mj streamline`` gives: the streamlines and ideal trajectories from a set of
starts (paper Eq. 4 and §3.1.2) on a surface ridden by a tip, as one long table and a figure.

:func:`trace_starts` runs both analyses on the surface (dilated by the tip radius when it
has one) into a :class:`StreamlineRun`; :meth:`StreamlineRun.table` joins them into one
table (one row per path point); :func:`write_streamline_outputs` writes the table and the
figure into one folder, both or neither.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from spine_mj.atomic import all_or_none, atomic_output
from spine_mj.errors import SpineInputError
from spine_mj.surfaces import Surface
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import streamline as sl
from spine_mj.theory.streamline_types import StreamlineParams, StreamlineResult

#: The table formats :func:`write_streamline_outputs` writes.
TABLE_FORMATS = ("parquet", "csv")
#: The figure :func:`write_streamline_outputs` writes beside the table.
FIGURE_NAME = "streamlines.png"


@dataclass(frozen=True)
class StreamlineRun:
    """Streamlines and ideal trajectories from the same starts.

    Attributes
    ----------
    surface : Surface
        The surface the paths ride: the given one dilated by ``tip_radius`` (the tip
        centre's surface), or the given one for a point tip.
    starts : list of (float, float)
        Start points ``(x0, y0)`` (surface units).
    mu : float
        Static friction coefficient mu_s.
    tip_radius : float
        Spherical tip radius (surface units; 0: a point).
    stream, ideal : StreamlineResult
        The quasistatic streamlines and the ideal trajectories.
    """

    surface: Surface
    starts: list[tuple[float, float]]
    mu: float
    tip_radius: float
    stream: StreamlineResult
    ideal: StreamlineResult

    def table(self):
        """Both analyses as one long pandas DataFrame: the columns of
        :meth:`~spine_mj.theory.streamline_types.StreamlineResult.to_frame` (``trajectory`` names the
        analysis) and ``mu``, ``tip_radius``."""
        import pandas as pd

        table = pd.concat([self.stream.to_frame(), self.ideal.to_frame()], ignore_index=True)
        table["mu"] = self.mu
        table["tip_radius"] = self.tip_radius
        return table

    def summary_lines(self) -> list[str]:
        """One line per start: each analysis's outcome, end point and largest kappa."""
        s, i = self.stream, self.ideal
        return [
            f"start ({x:g}, {y:g}): streamline {s.outcome_names[k]} at ({s.end_x[k]:.3f}, "
            f"{s.end_y[k]:.3f}), max kappa {s.max_kappa[k]:.3g}; ideal {i.outcome_names[k]}, "
            f"max kappa {i.max_kappa[k]:.3g}"
            for k, (x, y) in enumerate(self.starts)
        ]


def trace_starts(
    surface: Surface,
    starts,
    *,
    mu: float,
    dl: float | None = None,
    tip_radius: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
) -> StreamlineRun:
    """Streamlines and ideal trajectories from every start of ``starts`` (``(n, 2)``).

    Parameters
    ----------
    surface : Surface
        The surface as measured or made.
    mu : float
        Static friction coefficient mu_s (> 0).
    dl : float or None
        Step length (surface units); None: :func:`~spine_mj.theory.streamline.default_step` of
        the surface.
    tip_radius : float
        Spherical tip radius R (>= 0, surface units): the paths ride ``surface`` dilated
        by R (:func:`~spine_mj.surfaces.dilation.dilate`).
    progress : callable, optional
        Hears ``(done, total)`` through that dilation (seconds to minutes on a big grid).

    Raises
    ------
    SpineInputError
        A parameter out of range or a start outside the surface (named).
    """
    params = StreamlineParams(mu=mu, dl=sl.default_step(surface) if dl is None else dl)
    ridden = dilate(surface, tip_radius, progress=progress) if tip_radius else surface
    points = [(float(x), float(y)) for x, y in starts]
    return StreamlineRun(
        surface=ridden,
        starts=points,
        mu=mu,
        tip_radius=tip_radius,
        stream=sl.streamlines(ridden, points, params),
        ideal=sl.ideal_trajectories(ridden, points, params),
    )


def write_streamline_outputs(
    run: StreamlineRun, out_dir: str | os.PathLike, *, fmt: str = "parquet"
) -> list[Path]:
    """Write ``streamlines.<fmt>`` (:meth:`StreamlineRun.table`) and :data:`FIGURE_NAME`
    (the 3-D view and kappa along the paths) into ``out_dir``, both or neither; returns
    their paths."""
    from spine_mj.plotting import save_figure, streamline_figure

    if fmt not in TABLE_FORMATS:
        raise SpineInputError(f"table format must be one of {', '.join(TABLE_FORMATS)}, got {fmt!r}")
    out = Path(out_dir)
    table_path, figure_path = out / f"streamlines.{fmt}", out / FIGURE_NAME
    table = run.table()
    with all_or_none(table_path, figure_path):
        with atomic_output(table_path) as tmp:
            if fmt == "parquet":
                table.to_parquet(tmp, index=False)
            else:
                table.to_csv(tmp, index=False)
        figure = streamline_figure(run.surface, run.stream, run.ideal, title=f"mu_s = {run.mu:g}")
        save_figure(figure, figure_path)
    return [table_path, figure_path]


def streamline_to(
    out_dir: str | os.PathLike, surface: Surface, starts, *, mu: float, fmt: str = "parquet", **trace_options
) -> tuple[StreamlineRun, list[Path]]:
    """:func:`trace_starts` from ``starts`` and :func:`write_streamline_outputs` into
    ``out_dir`` (``spine-mj streamline``); ``trace_options`` are :func:`trace_starts`'s
    ``dl``, ``tip_radius`` and ``progress``. Returns the run and the paths written."""
    run = trace_starts(surface, starts, mu=mu, **trace_options)
    return run, write_streamline_outputs(run, out_dir, fmt=fmt)
