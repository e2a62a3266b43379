"""Slip-event catalogs: every slip of every run, one row each, whatever made it (the
overdamped and inertial quasistatic references, MuJoCo, Bullet), in one table with one set
of units (docs/physics.md §12).

Columns (:data:`COLUMNS`): ``source``, ``surface``, ``mu``, ``K``, ``ie``, ``start_x_lc``
(where the slip starts, from the surface's origin, in L_c), ``start_time_s`` (from the
drive's start), ``size_lc`` (the tip's travel along x in the slip), ``duration_s`` (time
ahead of the carriage, as :mod:`spine_mj.theory.motion` counts it), ``force_drop_fp``,
``peak_speed_v`` (the largest x-speed over the carriage's), ``dissipated_fp_lc`` (the
spring's work in the slip minus the work against the load, in F_p L_c).

The references run on the track's centre line (``y`` fixed; the surface must be uniform in
y for them to be its exact answer), with the rig's tip radius, stiffness, mass and speed in
the surface's units: ``k = K F_p / l_s``, ``m`` in ``F_p s^2 / unit``. The overdamped
reference's mobility is the critical one, ``1 / sqrt(k m)`` (it sets its durations only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.theory.avalanches import (
    Landscape,
    Slips,
    inertial_slips,
    overdamped_slips,
    pulse_shapes,
    quasistatic_path,
)
from spine_mj.theory.force_drops import drop_bounds

__all__ = [
    "COLUMNS",
    "DROP_FLOOR_FP",
    "REFERENCES",
    "TrackUnits",
    "drop_rows",
    "engine_drop_rows",
    "engine_rows",
    "facet_count",
    "reference_drop_rows",
    "reference_pulses",
    "reference_rows",
    "store_catalog",
    "track_landscape",
]

COLUMNS = (
    "source",
    "surface",
    "mu",
    "K",
    "ie",
    "start_x_lc",
    "start_time_s",
    "size_lc",
    "duration_s",
    "force_drop_fp",
    "peak_speed_v",
    "dissipated_fp_lc",
)
#: The quasistatic references, by source name.
REFERENCES = ("overdamped", "inertial")
#: Landscape points per grid spacing of the surface along x.
REFINEMENT = 4
#: Landscape points over the track's stretch on an analytic surface (no grid spacing).
ANALYTIC_POINTS = 20000
#: The force-drop rule's floor [F_p] (:mod:`spine_mj.theory.force_drops`): three orders
#: above MuJoCo's resting jitter on the abbm track at I_e 1e-6 (99 % of its reversals under
#: 3e-6 F_p, docs/physics.md §12) and, at K 0.5, a slip of 0.03 L_c.
DROP_FLOOR_FP = 1e-3


@dataclass(frozen=True)
class TrackUnits:
    """A rig's scales in the surface's own length unit: ``length_scale_m`` metres per unit,
    ``char_length`` (L_c) and ``slope_length`` (l_s) in units, ``tip_radius`` in units,
    ``preload_n`` (F_p = W), ``mass_kg`` and the drive's ``speed`` [units / s]."""

    length_scale_m: float
    char_length: float
    slope_length: float
    tip_radius: float
    preload_n: float
    mass_kg: float
    speed: float

    @classmethod
    def of(cls, scales, ie: float) -> TrackUnits:
        """From a rig's :class:`~spine_mj.sim.scales.Scales` and the drive's I_e."""
        unit = scales.length_scale_m
        return cls(
            length_scale_m=unit,
            char_length=scales.char_length_m / unit,
            slope_length=scales.slope_length_m / unit,
            tip_radius=scales.tip_radius_m / unit,
            preload_n=scales.preload_n,
            mass_kg=scales.mass_kg,
            speed=scales.speed_for(ie) / unit,
        )

    def stiffness(self, stiffness_number: float) -> float:
        """``k / W`` [1 / unit] of ``K = k l_s / F_p``."""
        return stiffness_number / self.slope_length

    @property
    def mass(self) -> float:
        """The tip's mass in ``W s^2 / unit``."""
        return self.mass_kg * self.length_scale_m / self.preload_n


def track_landscape(
    surface,
    mu: float,
    tip_radius: float,
    x_range: tuple[float, float],
    y: float = 0.0,
    *,
    facets: int | None = None,
    refinement: int = 1,
):
    """The landscape of ``surface`` along the line ``y`` over ``x_range`` (surface units),
    sampled at :data:`REFINEMENT` points per grid spacing from its spline (heights and
    slopes; an analytic surface at :data:`ANALYTIC_POINTS` over the stretch), times
    ``refinement`` (the references' grid refined: the surface and its scales unchanged),
    for a ball tip of ``tip_radius``. Where the radius exceeds a concave radius of
    curvature of the line (a rough profile: the offset path would loop), the centre rides
    the line's dilation by the ball's disk instead (it touches two points across each such
    valley; :func:`~spine_mj.surfaces.dilation.ball_dilation` on the one row), and its
    slope is the contact's.

    ``facets``: the profile an engine's height field makes of the line instead, straight
    between that many nodes over the surface's x extent (:func:`facet_count` of a rig),
    its slope stepping at each node; the centre rides its dilation by the ball's disk.
    An engine's slips start at those steps (docs/physics.md §12)."""
    x0, x1 = x_range
    xmin, xmax, _, _ = surface.bounds
    if not (xmin <= x0 < x1 <= xmax):
        raise SpineInputError(f"the track's x range must lie in [{xmin:g}, {xmax:g}], got [{x0:g}, {x1:g}]")
    if isinstance(refinement, bool) or int(refinement) != refinement or refinement < 1:
        raise SpineInputError(f"the landscape's refinement must be an integer >= 1, got {refinement!r}")
    dx = surface.spacing[0] / REFINEMENT if hasattr(surface, "spacing") else (x1 - x0) / ANALYTIC_POINTS
    dx /= int(refinement)
    x = np.linspace(x0, x1, int(math.ceil((x1 - x0) / dx)) + 1)
    yy = np.full_like(x, y)
    r = float(tip_radius)
    if facets is not None:
        nodes = np.linspace(xmin, xmax, int(facets))
        z = np.interp(x, nodes, surface.height(nodes, np.full_like(nodes, y)))
        gx = np.gradient(z, x[1] - x[0])
    else:
        z = surface.height(x, yy)
        gx, _ = surface.gradient(x, yy)
    if facets is not None or (r > 0 and not np.all(np.diff(x - r * gx / np.sqrt(1 + gx * gx)) > 0)):
        from spine_mj.surfaces.dilation import ball_dilation

        step = x[1] - x[0]
        z = ball_dilation(z[None, :], r, spacing=(step, step))[0] + r
        return Landscape.from_profile(x, np.gradient(z, step), z, mu, 0.0)
    return Landscape.from_profile(x, gx, z, mu, tip_radius)


def reference_rows(landscape: Landscape, units: TrackUnits, stiffness_number: float, **labels) -> dict:
    """Both references' slips on ``landscape`` at ``K = stiffness_number`` as catalog columns
    (``labels``: ``surface``, ``mu``, ``ie``)."""
    k = units.stiffness(stiffness_number)
    m = units.mass
    out = {}
    for source in REFERENCES:
        if source == "overdamped":
            slips = overdamped_slips(landscape, k, mobility=1.0 / math.sqrt(k * m), slow=units.speed)
        else:
            slips = inertial_slips(landscape, k, mass=m, slow=units.speed)
        out[source] = _rows(source, slips, units, stiffness_number, landscape.start, labels)
    return out


def reference_pulses(landscape: Landscape, units: TrackUnits, stiffness_number: float) -> dict:
    """Per reference, the mean pulse of its slips at ``K = stiffness_number``
    (:func:`~spine_mj.theory.avalanches.pulse_shapes`, speeds above the drive's counted):
    ``{source: {"shape": v / (S / T) at 41 times t / T, normalized to its peak, "n": slips
    averaged, "parabola_deviation": the largest distance from 4 x (1 - x) over t / T in
    [0.1, 0.9]}}``, of the shorter half of the slips (ABBM's parabola is the shape at
    durations below the cutoff's)."""
    k = units.stiffness(stiffness_number)
    m = units.mass
    out = {}
    for source in REFERENCES:
        inertial = source == "inertial"
        slips = inertial_slips(landscape, k, mass=m) if inertial else overdamped_slips(landscape, k)
        # the speed scale of a unit mobility (critical, 1 / sqrt(k m)) or mass, as reference_rows
        slow = units.speed * (math.sqrt(m) if inertial else math.sqrt(k * m))
        shapes, durations = pulse_shapes(landscape, k, slips, inertial=inertial, slow=slow)
        if not durations.size:
            out[source] = {"shape": None, "n": 0, "parabola_deviation": None}
            continue
        mean = shapes[durations <= np.median(durations)].mean(axis=0)
        mean = mean / mean.max()
        x = np.linspace(0.0, 1.0, mean.size)
        inner = (x >= 0.1) & (x <= 0.9)
        out[source] = {
            "shape": mean.tolist(),
            "n": int((durations <= np.median(durations)).sum()),
            "parabola_deviation": float(np.abs(mean - 4 * x * (1 - x))[inner].max()),
        }
    return out


def _label_columns(source: str, n: int, stiffness_number: float, labels) -> dict:
    """The catalog's first columns, one value for all ``n`` rows of a run."""
    return {
        "source": [source] * n,
        "surface": [labels.get("surface", "")] * n,
        "mu": np.full(n, labels.get("mu", math.nan)),
        "K": np.full(n, float(stiffness_number)),
        "ie": np.full(n, labels.get("ie", math.nan)),
    }


def _rows(
    source: str, slips: Slips, units: TrackUnits, stiffness_number: float, start: float, labels
) -> dict:
    lc, n = units.char_length, slips.size.size
    # the drive starts with the spring unloaded and the tip at the landscape's start
    return {
        **_label_columns(source, n, stiffness_number, labels),
        "start_x_lc": slips.start_u / lc,
        "start_time_s": (slips.start_carriage - start) / units.speed,
        "size_lc": slips.size / lc,
        "duration_s": slips.duration,
        "force_drop_fp": slips.force_drop,
        "peak_speed_v": slips.peak_speed / units.speed,
        "dissipated_fp_lc": slips.dissipated / lc,
    }


def facet_count(rig) -> int:
    """Nodes along x of ``rig``'s height field (:attr:`~spine_mj.surfaces.hfield.HField.ncol`)."""
    return int(rig.hfield.ncol)


def reference_path(landscape: Landscape, slips: Slips, stiffness: float):
    """A reference run's tip ``u`` at carriage positions ``X`` (both [length]): a uniform
    grid of the landscape's spacing from its start to the last slip, plus each slip's two
    ends at its one carriage position (before, then after), in order."""
    last = float(slips.start_carriage[-1]) if slips.size.size else landscape.start
    grid = np.linspace(landscape.start, last, max(int((last - landscape.start) / landscape.spacing), 1) + 1)
    u = quasistatic_path(landscape, stiffness, slips, grid)
    x = np.concatenate([grid, slips.start_carriage, slips.start_carriage])
    uu = np.concatenate([u, slips.start_u, slips.start_u + slips.size])
    order = np.concatenate([np.ones(grid.size), np.zeros(slips.size.size), np.full(slips.size.size, 2.0)])
    keep = np.lexsort((order, x))
    return x[keep], uu[keep]


def drop_rows(
    x,
    force_fp,
    floor_fp: float,
    *,
    source: str,
    stiffness_number: float,
    char_length: float,
    time_s=None,
    velocity_v=None,
    **labels,
) -> dict:
    """Catalog columns of the force drops deeper than ``floor_fp`` of one run
    (:func:`~spine_mj.theory.force_drops.drop_bounds`): rows in time order with the tip's
    ``x`` (surface units), the spring's force [F_p] and, where the source has them, the
    time [s] and x-speed over the drive's (else those columns are NaN). The size is the
    tip's travel from the peak to the trough, the duration their time apart."""
    x, f = np.asarray(x, float), np.asarray(force_fp, float)
    on, st = drop_bounds(f, floor_fp)
    n, nan = on.size, np.full(on.size, math.nan)
    t = None if time_s is None else np.asarray(time_s, float)
    if velocity_v is None:
        peak = nan
    else:
        v = np.asarray(velocity_v, float)
        peak = np.array([v[a : b + 1].max() for a, b in zip(on, st)]) if n else nan
    return {
        **_label_columns(source, n, stiffness_number, labels),
        "start_x_lc": x[on] / char_length,
        "start_time_s": nan if t is None else t[on] - t[0],
        "size_lc": (x[st] - x[on]) / char_length,
        "duration_s": nan if t is None else t[st] - t[on],
        "force_drop_fp": f[on] - f[st],
        "peak_speed_v": peak,
        "dissipated_fp_lc": nan,
    }


def reference_drop_rows(
    landscape: Landscape,
    units: TrackUnits,
    stiffness_number: float,
    floor_fp: float = DROP_FLOOR_FP,
    **labels,
) -> dict:
    """Both references' force drops deeper than ``floor_fp`` at ``K = stiffness_number``:
    the drop rule on each reference's force ``k (X - u)`` along its path
    (:func:`reference_path`), as catalog columns per source."""
    k = units.stiffness(stiffness_number)
    out = {}
    for source in REFERENCES:
        slips = overdamped_slips(landscape, k) if source == "overdamped" else inertial_slips(landscape, k)
        x, u = reference_path(landscape, slips, k)
        out[source] = drop_rows(
            u,
            k * (x - u),
            floor_fp,
            source=source,
            stiffness_number=stiffness_number,
            char_length=units.char_length,
            **labels,
        )
    return out


def engine_drop_rows(
    result, units: TrackUnits, source: str, stiffness_number: float, floor_fp: float = DROP_FLOOR_FP, **labels
) -> dict:
    """An engine run's force drops deeper than ``floor_fp`` from the drive's start, by the
    rule the references' go by (:func:`reference_drop_rows`)."""
    s = result.drive_start_index
    unit = units.length_scale_m
    return drop_rows(
        result.position_m[s:, 0] / unit,
        result.drive_force_n[s:] / units.preload_n,
        floor_fp,
        source=source,
        stiffness_number=stiffness_number,
        char_length=units.char_length,
        time_s=result.time_s[s:],
        velocity_v=result.velocity_m_s[s:, 0] / (units.speed * unit),
        **labels,
    )


def engine_rows(result, units: TrackUnits, source: str, stiffness_number: float, **labels) -> dict:
    """The slip events of an engine's run (:attr:`RunResult.slip_events`) as catalog columns."""
    unit = units.length_scale_m
    t0 = float(result.time_s[result.drive_start_index]) if len(result.time_s) else 0.0
    return event_rows(
        result.slip_events,
        result.position_m[:, 0] / unit,
        result.position_m[:, 2] / unit,
        result.drive_force_n,
        source=source,
        stiffness_number=stiffness_number,
        char_length=units.char_length,
        preload_n=units.preload_n,
        speed=units.speed,
        length_unit_m=unit,
        start_time_s=t0,
        **labels,
    )


def event_rows(
    events,
    x,
    z,
    force_n,
    *,
    source: str,
    stiffness_number: float,
    char_length: float,
    preload_n: float,
    speed: float,
    length_unit_m: float,
    start_time_s: float = 0.0,
    **labels,
) -> dict:
    """Catalog columns of :class:`~spine_mj.theory.motion.SlipEvent` s of one run whose rows
    have the tip's ``x`` and ``z`` (surface units) and the drive force [N]; ``speed`` is the
    drive's in surface units per second, ``length_unit_m`` metres per unit (the events'
    lengths and speeds are in metres)."""
    n, lc, fp, unit = len(events), char_length, preload_n, length_unit_m
    f = np.asarray(force_n, float)
    dissipated = []
    for e in events:
        seg = slice(e.onset, e.stop + 1)
        work = float(np.sum(0.5 * (f[seg][1:] + f[seg][:-1]) * np.diff(x[seg])))
        dissipated.append((work - fp * (z[e.stop] - z[e.onset])) / (fp * lc))
    return {
        **_label_columns(source, n, stiffness_number, labels),
        "start_x_lc": np.array([x[e.onset] / lc for e in events]),
        "start_time_s": np.array([e.onset_time_s - start_time_s for e in events]),
        "size_lc": np.array([e.jump_length_m / unit / lc for e in events]),
        "duration_s": np.array([e.duration_s for e in events]),
        "force_drop_fp": np.array([e.force_drop_n / fp for e in events]),
        "peak_speed_v": np.array([e.peak_speed_m_s / (speed * unit) for e in events]),
        "dissipated_fp_lc": np.array(dissipated),
    }


def store_catalog(out_dir, analysis: str = "engine"):
    """The catalog of every slip of every ``analysis`` run of a sweep store, rebuilt from
    its stored trajectories by the runs' own rule (:func:`spine_mj.theory.motion.slip_events`
    on the recorded motion states): it survives a kill and a resume as the trajectories do.
    Exact for ``record_every = 1`` (a coarser record merges or drops rows). ``source`` is
    the run's engine; ``peak_speed_v`` is the finite-difference x-speed over the drive's,
    the surface's unit taken as ``length_scale`` (the default rule's metres for a
    dimensionless surface); ``start_time_s`` counts from the run's start.

    Returns a pandas DataFrame with the columns :data:`COLUMNS`."""
    import pandas as pd

    from spine_mj import sweep
    from spine_mj.sim.scales import DEFAULT_LENGTH_SCALE_M
    from spine_mj.theory.motion import slip_events

    runs = sweep.load_runs(out_dir)
    runs = runs[(runs["analysis"] == analysis) & (runs["status"] == "ok")]
    frames = []
    for case_id, case in runs.groupby("case_id", sort=False):
        traj = sweep.load_trajectories(out_dir, case_id, analysis=analysis)
        for _, run in case.iterrows():
            tr = traj[traj["start"] == run["start"]].sort_values("step")
            t, x, z = (tr[c].to_numpy(float) for c in ("time_s", "x", "z"))
            f = tr["drive_force_n"].to_numpy(float)
            vx = np.gradient(x, t) if t.size > 1 else np.zeros_like(x)
            events = slip_events(tr["motion"].to_numpy(), t, x, f, vx)
            unit = run["length_scale"] if np.isfinite(run["length_scale"]) else DEFAULT_LENGTH_SCALE_M
            # the stored x is in surface units and the speeds derived from it too: unit 1
            rows = event_rows(
                events,
                x,
                z,
                f,
                source=run["engine"],
                stiffness_number=run["stiffness_number"],
                char_length=run["char_length"],
                preload_n=run["mass"] * run["gravity"] + run["preload"],
                speed=run["speed_m_s"] / unit,
                length_unit_m=1.0,
                surface=run["surface"],
                mu=run["mu"],
                ie=run["inertia_number"],
            )
            frames.append(pd.DataFrame(rows, columns=COLUMNS))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=COLUMNS)
