"""The one way from a problem's inputs to a rig and a drive.

Users, the sweep's ``engine`` analysis, the validation and the benchmarks give the same
things: a surface, a friction coefficient, a tip (radius, mass, preload), a length scale
and hfield resolution, an engine and its options, and a drive either dimensionless
(inertia number ``I_e``, stiffness number ``K``) or in SI (speed [m/s], stiffness [N/m],
force rate [N/s]). :func:`build_rig` and :func:`build_drive` turn them into a rig of any
registered engine (:data:`spine_mj.choices.ENGINES`) and a drive by the rules of
:class:`~spine_mj.sim.scales.Scales`, so that ``spine-mj simulate`` and a sweep case with
the same inputs run the same model (tested).

Two rules live here:

* a gridded surface keeps its own samples as the hfield: ``hfield_resolution`` resamples
  analytic surfaces only (:func:`~spine_mj.sim.rig_hfield.grid_keeps_samples`, the rule's home).
* a drive given neither an inertia number, nor a speed, nor a force rate runs at
  ``I_e = DEFAULT_INERTIA_NUMBER`` (slow: quasistatic on the paper's surfaces).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from spine_mj.choices import ARRAY_DRIVES, PROTOCOLS, check_engine
from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.array import ArrayRig
from spine_mj.sim.array_run import ArrayDrive, ForcePull
from spine_mj.sim.drives import Drive, RampDrive, SpringDrive, StaticProbe, spring_stiffness_n_m
from spine_mj.sim.engine_rig import EngineRig
from spine_mj.sim.holding import array_ie
from spine_mj.sim.layout import Layout
from spine_mj.sim.model import check_drive_on, check_starts_on
from spine_mj.sim.records import TipParams
from spine_mj.sim.rig import Rig
from spine_mj.sim.rig_hfield import check_hfield_size, grid_keeps_samples, hfield_sides
from spine_mj.sim.rig_inputs import RigInputs, at_most_one
from spine_mj.sim.scales import PROGRESS_MIN_SAMPLES, Scales, planned_hfield_sides
from spine_mj.surfaces import Surface

__all__ = [
    "DEFAULT_INERTIA_NUMBER",
    "RigPlan",
    "build_array",
    "build_array_on",
    "build_drive",
    "build_rig",
    "check_planned_hfield",
    "drive_speed_m_s",
    "plan_rig",
    "plan_settings",
    "rig_of_plan",
    "rig_scales",
    "rig_sizing",
]

#: The inertia number of a drive given no speed, rate or I_e.
DEFAULT_INERTIA_NUMBER = 1e-3


def drive_speed_m_s(
    scales: Scales,
    *,
    ie: float | None = None,
    speed_m_s: float | None = None,
    rate_n_s: float | None = None,
) -> float:
    """The drive's speed [m/s] from whichever pace is given.

    ``speed_m_s`` when given, else a force rate's equivalent speed
    (:meth:`Scales.equivalent_speed`), else the speed of ``ie`` (default
    :data:`DEFAULT_INERTIA_NUMBER`): ``v = sqrt(I_e F_p L_c / m)``.

    Parameters
    ----------
    scales : Scales
        The rig's scales.
    ie : float, optional
        Inertia number ``m v^2 / (F_p L_c)``.
    speed_m_s : float, optional
        Carriage speed [m/s].
    rate_n_s : float, optional
        Force rate [N/s] of a ramp or probe.

    Returns
    -------
    float
    """
    at_most_one(ie=ie, speed_m_s=speed_m_s, rate_n_s=rate_n_s)
    if speed_m_s is not None:
        return speed_m_s
    if rate_n_s is not None:
        return scales.equivalent_speed(check_positive("rate_n_s", rate_n_s))
    return scales.speed_for(DEFAULT_INERTIA_NUMBER if ie is None else check_positive("I_e", ie))


def build_rig(
    surface: Surface,
    inputs: RigInputs | None = None,
    /,
    *,
    progress: Callable[[float, float, str], None] | None = None,
    **keywords,
) -> EngineRig:
    """The rig of ``surface`` built from ``inputs`` (:class:`RigInputs`, the one record of a
    rig's inputs), or from its fields given as keywords, any other keyword an engine option
    (:meth:`RigInputs.from_keywords`); None leaves a value to its rule.

    Parameters
    ----------
    surface : Surface
        The surface the tip runs on (any unit; dimensionless ones scaled by ``length_scale_m``).
    inputs : RigInputs, optional
        The friction coefficient (resolve a command's with :func:`spine_mj.presets.resolve_mu`),
        the engine and its options, the tip, the sizing and the drive's pace and spring, which
        bound the engine step (a stiffer spring: :meth:`Rig.check_drive` refuses).
    progress : callable, optional
        Hears ``(done, total, stage)`` through the preparation (:meth:`Scales.with_hfield`).
    **keywords
        Instead of ``inputs``: ``mu=...``, ``engine=...``, ``tip_radius_m=...``, ...

    Returns
    -------
    EngineRig
        The engine's rig (:class:`~spine_mj.sim.Rig` for MuJoCo).

    Raises
    ------
    SpineInputError
        An unknown engine or missing extra, an option the engine does not read, a parameter
        out of range (named), or a drive the engine cannot resolve.

    Examples
    --------
    A spring-drive run at ``I_e = 1e-3`` in front of the paper's single peak (SI units).

    >>> import spine_mj as sm
    >>> from spine_mj import sim
    >>> rig = sim.build_rig(sm.make_surface("paper-single-peak"), mu=1.23)
    >>> drive = sim.build_drive(rig.scales, "spring", ie=1e-3)
    >>> run = rig.run(drive, start=(-3.0, -1.0))
    >>> run.end_reason.name
    'LEFT_DOMAIN'
    >>> round(run.inertia_number, 6)
    0.001
    """
    if inputs is None:
        inputs = RigInputs.from_keywords(**keywords)
    elif keywords:
        raise SpineInputError(f"build_rig: give RigInputs or keywords, not both (got {', '.join(keywords)})")
    plan = plan_rig(surface, inputs, progress=progress)
    stage, big = f"building {inputs.engine}'s model", plan.hfield.data.size >= PROGRESS_MIN_SAMPLES
    if progress is not None and big:
        progress(0, 1, stage)
    rig = rig_of_plan(plan, inputs.engine)
    if progress is not None and big:
        progress(1, 1, stage)
    return rig


def rig_of_plan(plan: RigPlan, engine: str) -> EngineRig:
    """The rig of ``engine`` that :func:`plan_rig` planned (:func:`build_rig` without the
    sizing: a caller that measured it once, :func:`rig_sizing`, builds many rigs on it)."""
    rig_class = check_engine(engine).rig_class()
    return rig_class(plan.surface, tip=plan.tip, engine=plan.engine, sized=(plan.scales, plan.hfield))


@dataclasses.dataclass(frozen=True, eq=False)
class RigPlan:
    """The rig :func:`build_rig` would build, without its MuJoCo model: the surface, the
    tip, the scales and hfield, and the engine settings (every sizing and step rule
    applied, nothing compiled). It checks a drive as the rig would
    (:func:`~spine_mj.sim.model.check_drive_on`) and counts an open-loop run's steps
    (:func:`~spine_mj.sim.open_loop.drive_steps`): checks of many cases before any runs."""

    surface: Surface
    tip: TipParams
    scales: Scales
    hfield: object
    engine: object

    @property
    def length_scale_m(self) -> float:
        return self.scales.length_scale_m

    @property
    def bounds_m(self) -> tuple[float, float, float, float]:
        return tuple(self.length_scale_m * b for b in self.surface.bounds)

    def check_drive(self, drive: Drive) -> None:
        check_drive_on(self, drive)

    def check_starts(self, starts, margin_m: float) -> None:
        """Refuse starts a run would end at once (:func:`~spine_mj.sim.model.check_starts_on`)."""
        check_starts_on(self.surface, starts, margin_m / self.length_scale_m)


def plan_rig(
    surface: Surface,
    inputs: RigInputs,
    *,
    sized: tuple | None = None,
    progress: Callable[[float, float, str], None] | None = None,
) -> RigPlan:
    """The :class:`RigPlan` of :func:`build_rig`'s ``inputs`` (the same rules, the same
    refusals, no model compiled). ``sized``: the ``(tip, scales, hfield)`` of the same
    surface and tip sizing, measured before (:func:`rig_sizing`), so that plans differing
    only in the drive or the engine settings measure the surface once; ``progress`` as for
    :meth:`Scales.with_hfield`."""
    if sized is None:
        check_planned_hfield(surface, inputs)
        sized = _sized(surface, inputs.tip, **inputs.sizing, progress=progress)
    tip, scales, hfield = sized
    return RigPlan(surface, tip, scales, hfield, plan_settings(scales, inputs))


def plan_settings(scales: Scales, inputs: RigInputs, *, pace: dict | None = None, spring: dict | None = None):
    """The engine settings of ``inputs`` on ``scales``: its engine's settings factory with
    its options, the step bounded by the drive's speed and spring. ``pace`` and ``spring``
    (:attr:`RigInputs.pace`, :attr:`RigInputs.spring`), when given, replace those of
    ``inputs``: a grid's checks plan the cases that differ only in the drive on one
    record of the rest (:func:`~spine_mj.sweep.analyses.engine.case_plan`)."""
    pace = inputs.pace if pace is None else pace
    spring = inputs.spring if spring is None else spring
    at_most_one(**spring)
    speed = drive_speed_m_s(scales, **pace) if inputs.driven else None
    factory = check_engine(inputs.engine).settings_factory()
    return factory(
        scales,
        speed_m_s=speed,
        stiffness_n_m=spring_stiffness_n_m(scales, **spring),
        **dict(inputs.engine_options),
    )


def check_planned_hfield(surface: Surface, inputs: RigInputs) -> None:
    """The hfield's size limits (:func:`~spine_mj.sim.rig_hfield.check_hfield_size`: sides,
    memory) and the engine's ``hfield_check`` (Bullet's sample limit and memory) on the
    sides the sizing rule will give (:func:`~spine_mj.sim.scales.planned_hfield_sides`),
    before any sampling: the uncoarsened sides first (no L_c measured), the rule's only when
    those fail (its coarsening of a fine grid can bring them under a limit)."""
    engine_check = check_engine(inputs.engine).hfield_limit()

    def check(nrow, ncol):
        check_hfield_size(nrow, ncol, inputs.hfield_refinement)
        if engine_check is not None:
            engine_check(nrow, ncol)

    resolution = grid_keeps_samples(surface, inputs.hfield_resolution)
    try:
        check(*hfield_sides(surface, resolution, inputs.hfield_refinement))
    except SpineInputError:
        sizing = {"length_scale_m": inputs.length_scale_m, "hfield_refinement": inputs.hfield_refinement}
        check(*planned_hfield_sides(surface, tip=inputs.tip, hfield_resolution=resolution, **sizing))


def rig_sizing(
    surface: Surface,
    *,
    tip: TipParams,
    length_scale_m: float | None = None,
    hfield_resolution: int | None = None,
    hfield_refinement: int = 1,
) -> tuple:
    """``(tip, scales, hfield)``: the sizing :func:`plan_rig` takes as ``sized`` (the tip
    carrying the scales' radius)."""
    return _sized(surface, tip, length_scale_m, hfield_resolution, hfield_refinement)


def rig_scales(
    surface: Surface,
    *,
    tip: TipParams,
    length_scale_m: float | None = None,
    hfield_resolution: int | None = None,
    hfield_refinement: int = 1,
) -> Scales:
    """The scales :func:`build_rig` sizes its rig by, without building it: for checks of a
    configuration before any run.

    Parameters
    ----------
    surface : Surface
        The surface.
    tip : TipParams
        The tip (its radius None: the rule's).
    length_scale_m, hfield_resolution, hfield_refinement
        As for :func:`build_rig`.

    Returns
    -------
    Scales
    """
    return _sized(surface, tip, length_scale_m, hfield_resolution, hfield_refinement)[1]


def _sized(
    surface: Surface,
    tip: TipParams,
    length_scale_m=None,
    hfield_resolution=None,
    hfield_refinement=1,
    progress=None,
) -> tuple:
    """``(tip, scales, hfield)`` of ``tip`` on ``surface``: the tip with the radius the rig
    was sized for (a gridded surface keeps its own samples: ``hfield_resolution`` ignored),
    on the hfield refined ``hfield_refinement`` times with that radius kept."""
    resolution = grid_keeps_samples(surface, hfield_resolution)
    scales, hfield = Scales.with_hfield(
        surface, tip=tip, length_scale_m=length_scale_m, hfield_resolution=resolution, progress=progress
    )
    tip = dataclasses.replace(tip, tip_radius_m=scales.tip_radius_m)
    if hfield_refinement != 1:
        scales, hfield = Scales.with_hfield(
            surface,
            tip=tip,
            length_scale_m=length_scale_m,
            hfield_resolution=scales.hfield_resolution,
            hfield_refinement=hfield_refinement,
            progress=progress,
        )
    return tip, scales, hfield


def build_drive(
    scales: Scales,
    protocol: str = "spring",
    *,
    ie: float | None = None,
    speed_m_s: float | None = None,
    rate_n_s: float | None = None,
    stiffness_number: float | None = None,
    stiffness_n_m: float | None = None,
    duration_s: float | None = None,
    settle_time_s: float | None = None,
    start_force_n: float = 0.0,
    slide_distance_m: float | None = None,
) -> Drive:
    """The drive ``protocol`` ("spring", "ramp" or "static") on a rig of ``scales``.

    Parameters
    ----------
    scales : Scales
        The rig's scales (``rig.scales``): L_c, F_p, l_s and the length unit.
    protocol : {"spring", "ramp", "static"}
        The spring drive, the force ramp with reset, or the static probe.
    ie, speed_m_s, rate_n_s
        Its pace: an inertia number, a carriage speed [m/s] (spring) or a force rate
        [N/s] (ramp, static), at most one of them; none: ``I_e =``
        :data:`DEFAULT_INERTIA_NUMBER`. A force drive's rate at a speed is
        :meth:`Scales.force_rate_for` (its equivalent speed ``L_c rate / F_p``).
    stiffness_number, stiffness_n_m
        The spring's stiffness as ``K = k l_s / F_p`` or in N/m (none: K = 30).
    duration_s, settle_time_s, start_force_n, slide_distance_m
        As the drives take them (:class:`SpringDrive`, :class:`RampDrive`, :class:`StaticProbe`).
    """
    at_most_one(ie=ie, speed_m_s=speed_m_s, rate_n_s=rate_n_s)
    at_most_one(stiffness_number=stiffness_number, stiffness_n_m=stiffness_n_m)
    if rate_n_s is None:
        rate_n_s = scales.force_rate_for(drive_speed_m_s(scales, ie=ie, speed_m_s=speed_m_s))
    if stiffness_number is not None:
        stiffness_n_m = scales.stiffness_for(check_positive("K", stiffness_number))
    if protocol == "spring":
        return SpringDrive(
            speed_m_s=drive_speed_m_s(scales, ie=ie, speed_m_s=speed_m_s),
            stiffness_n_m=stiffness_n_m,
            duration_s=duration_s,
            settle_time_s=settle_time_s,
            start_force_n=start_force_n,
        )
    if protocol == "static":
        return StaticProbe(rate_n_s=rate_n_s, start_force_n=start_force_n, settle_time_s=settle_time_s)
    if protocol == "ramp":
        return RampDrive(
            rate_n_s=rate_n_s,
            duration_s=duration_s,
            settle_time_s=settle_time_s,
            slide_distance_m=slide_distance_m,
        )
    raise SpineInputError(f"protocol must be one of {', '.join(PROTOCOLS)}, got {protocol!r}")


def build_array(
    rig: Rig,
    layout: Layout,
    drive: str = "speed",
    *,
    ie: float | None = None,
    speed_m_s: float | None = None,
    stiffness_number: float | None = None,
    stiffness_n_m: float | None = None,
    duration_s: float | None = None,
    settle_time_s: float | None = None,
) -> tuple[ArrayRig, ArrayDrive]:
    """An array of ``layout`` on ``rig``'s surface and tip, and its carriage's drive: the
    one way ``spine-mj array`` and a sweep's ``array`` analysis make them.

    Parameters
    ----------
    rig : Rig
        The single-spine rig whose surface, tip, scales and engine the array takes.
    layout : Layout
        Where the spines sit on the carriage.
    drive : {"speed", "force"}
        ``speed``: the carriage moves at the drive's speed, each spine on its spring (the
        spring drive of :func:`build_drive`); ``force``: a free carriage pulled by a
        force whose rate per spine has the drive speed's equivalent
        (:meth:`Scales.force_rate_for`, :class:`~spine_mj.sim.ForcePull`).
    ie, speed_m_s
        The pace, as for :func:`drive_speed_m_s` (none: ``I_e =`` :data:`DEFAULT_INERTIA_NUMBER`).
    stiffness_number, stiffness_n_m
        Each spring's stiffness as ``K = k l_s / F_p`` or in N/m (none: the drives' default).
    duration_s
        Run time of a speed drive (None: to the far edge); a force pull runs to its cap.
    settle_time_s
        Settle phase before the drive starts (None: the drives' default).

    Raises
    ------
    SpineInputError
        An unknown ``drive``, a ``duration_s`` for a force pull, or any value out of range.
    """
    if drive not in ARRAY_DRIVES:
        raise SpineInputError(f"array drive must be one of {', '.join(ARRAY_DRIVES)}, got {drive!r}")
    if stiffness_number is not None:
        stiffness_n_m = rig.scales.stiffness_for(check_positive("K", stiffness_number))
    if drive == "speed":
        carriage = build_drive(
            rig.scales,
            "spring",
            ie=ie,
            speed_m_s=speed_m_s,
            stiffness_n_m=stiffness_n_m,
            duration_s=duration_s,
            settle_time_s=settle_time_s,
        )
    else:
        if duration_s is not None:
            raise SpineInputError("duration is for the speed drive (a force pull runs to its cap)")
        speed = drive_speed_m_s(rig.scales, ie=ie, speed_m_s=speed_m_s)
        carriage = ForcePull(
            rate_n_s=rig.scales.force_rate_for(speed),
            stiffness_n_m=stiffness_n_m,
            settle_time_s=settle_time_s,
        )
    return ArrayRig(rig, layout, force_control=drive == "force"), carriage


def build_array_on(
    surface: Surface,
    layout: Layout,
    drive: str = "speed",
    *,
    mu: float,
    ie: float | None = None,
    stiffness_number: float | None = None,
    stiffness_n_m: float | None = None,
    duration_s: float | None = None,
    settle_time_s: float | None = None,
    **rig_options,
) -> tuple[ArrayRig, ArrayDrive, float]:
    """An array of ``layout`` on ``surface`` at the arrays' own pace (``spine-mj array``):
    the rig of ``mu`` and ``rig_options`` (:func:`build_rig`'s keywords), its array and
    drive (:func:`build_array`), and the inertia number they run at.

    Parameters
    ----------
    surface : Surface
        The surface the array is dragged over.
    layout : Layout
        Where the spines sit on the carriage.
    drive : {"speed", "force"}
        As for :func:`build_array`.
    mu : float
        The tips' friction coefficient.
    ie : float or None
        The pace; None: :func:`~spine_mj.sim.holding.array_ie`, the fastest pace whose
        predicted holding excess stays within
        :data:`~spine_mj.sim.holding.HOLDING_TOLERANCE` ``mu F_p`` per spine. The rig is
        built for that pace and spring (they bound the engine step).
    stiffness_number, stiffness_n_m, duration_s, settle_time_s
        As for :func:`build_array`.
    **rig_options
        :func:`build_rig`'s other keywords (tip, length scale, hfield, engine overrides).

    Returns
    -------
    (ArrayRig, ArrayDrive, float)
        The array, its carriage's drive and the inertia number they run at.
    """
    springs = {"stiffness_number": stiffness_number, "stiffness_n_m": stiffness_n_m}
    if ie is None:
        scales = build_rig(surface, mu=mu, **springs, **rig_options).scales
        k = spring_stiffness_n_m(scales, **springs)
        ie = array_ie(scales, mu=mu, force_control=drive == "force", stiffness_n_m=k)
    rig = build_rig(surface, mu=mu, ie=check_positive("I_e", ie), **springs, **rig_options)
    arr, carriage = build_array(
        rig, layout, drive, ie=ie, **springs, duration_s=duration_s, settle_time_s=settle_time_s
    )
    return arr, carriage, ie
