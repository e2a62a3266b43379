"""The problem's scales and the one home of the rig's scaling rule.

:class:`Scales` derives the problem's scales from a surface and a tip
(:meth:`Scales.for_surface`: length scale, ``L_c``, ``l_s``, default tip radius, hfield
spacing and coarsening, the surface's fall height), :class:`EngineUnits` the units MuJoCo
works in; :func:`surface_unit_m` and :func:`fall_height` are rules they use, and the hfield
they are measured on is :mod:`spine_mj.sim.rig_hfield`'s. Nothing here needs
MuJoCo.

The scaling rule. MuJoCo sees the problem in its own units: length ``L_c``, force
``F_p = m g + preload``, mass ``m``, hence time ``tau = sqrt(m L_c / F_p)`` and speed
``sqrt(F_p L_c / m)`` (a drive of inertia number ``I_e`` moves at ``sqrt(I_e)``). The same
dimensionless problem at any physical scale is then the same model, bit for bit, and every
number the engine meets (mass 1, tip radius ``r / L_c``, time step ``dt / tau``) is O(1)
or a ratio of the problem's own lengths, far from MuJoCo's absolute floors (``mjMINVAL =
1e-15``) that a micrometre tip in SI units falls below.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.roughness import characteristic_length, slope_correlation_length
from spine_mj.sim.records import TipParams
from spine_mj.sim.rig_hfield import (
    check_hfield_refinement,
    check_hfield_resolution,
    grid_keeps_samples,
    hfield_of,
    hfield_sides,
    hfield_spacing,
    planned_spacing,
)
from spine_mj.surfaces import LENGTH_UNITS_M, GridSurface, HField, Surface, length_unit
from spine_mj.surfaces.hfield import hfield_half_extents

DEFAULT_LENGTH_SCALE_M = 0.01
#: Largest inertia number a drive may have: beyond it the quasistatic question is moot and
#: the engine step (bounded by impacts at the drive speed) shrinks without end.
MAX_INERTIA_NUMBER = 1e4
_MIN_SPACING_PER_TIP_RADIUS = 0.25  # finer hfields exceed MuJoCo's 50 contacts per geom pair
_SCAN_TIP_SPACINGS = 2.0  # default tip radius of a measured scan, in lateral spacings
#: A default tip is at most the domain's width over this many radii: a narrow strip or a
#: long track keeps room for the tip to ride along it (the usual rule on a 1 unit wide
#: strip of long waves would give a tip wider than the strip).
DEFAULT_TIP_RADII_ACROSS = 8
#: Hfield samples from which a rig's preparation reports its stages (2048 a side: seconds).
PROGRESS_MIN_SAMPLES = 2**22
_MIN_ENGINE_RATIO = 1e-9  # smallest length ratio (tip / L_c, spacing / L_c) the engine resolves
#: Physical range of lengths [m] (outside it the model means nothing).
PHYSICAL_LENGTH_M = (1e-12, 1e3)


@dataclass(frozen=True)
class EngineUnits:
    """The units MuJoCo works in: length ``L_c``, force ``F_p``, mass ``m`` (module docstring).

    A number in engine units times the matching unit here is the SI value; the rig
    converts with these and nowhere else.

    Attributes
    ----------
    length_m, force_n, mass_kg : float
    """

    length_m: float
    force_n: float
    mass_kg: float

    @property
    def time_s(self) -> float:
        """sqrt(m L_c / F_p)."""
        return math.sqrt(self.mass_kg * self.length_m / self.force_n)

    @property
    def speed_m_s(self) -> float:
        return self.length_m / self.time_s

    @property
    def acceleration_m_s2(self) -> float:
        return self.force_n / self.mass_kg

    @property
    def stiffness_n_m(self) -> float:
        return self.force_n / self.length_m


@dataclass(frozen=True)
class Scales:
    """The problem's scales, all in SI units; :meth:`for_surface` derives them.

    Attributes
    ----------
    length_scale_m : float
        Metres per surface length unit (1 for surfaces in metres).
    char_length_m : float
        L_c, the characteristic asperity length [m].
    mass_kg, preload_n, tip_radius_m : float
        m_eff [kg], F_p [N], tip radius [m].
    hfield_spacing_m : float
        Larger of the hfield's two sample spacings [m].
    hfield_resolution : int or None
        Samples a side the hfield is resampled to (None: a grid keeps its own samples,
        an analytic surface gets :func:`spine_mj.surfaces.to_hfield`'s default).
    hfield_refinement : int
        That hfield at this many times the samples a side, every sample kept
        (:func:`hfield_of`): solution verification's refined hfield, the tip kept.
    slope_length_m : float or None
        l_s, the slope correlation length [m] (:func:`slope_correlation_length`; L_c where
        the surface has none, a plane); the length of the drive stiffness number K.
    extent_m : float or None
        Diagonal of the surface's domain [m] (bounds the energy a run can gain).
    fall_height_m : float
        The height a slip can turn into an impact [m] (:func:`fall_height`: a fall down a
        grit flank or a scan-line step onto the floor below); 0 on planes and on surfaces
        no steeper than the friction angle. It bounds the engine step
        (:func:`~spine_mj.sim.step_rule.default_engine`).
    """

    length_scale_m: float
    char_length_m: float
    mass_kg: float
    preload_n: float
    tip_radius_m: float
    hfield_spacing_m: float
    hfield_resolution: int | None = None
    hfield_refinement: int = 1
    slope_length_m: float | None = None
    extent_m: float | None = None
    fall_height_m: float = 0.0

    @classmethod
    def for_surface(cls, surface: Surface, **sizing) -> Scales:
        """The scales of a tip on ``surface``: :meth:`with_hfield` (the same keyword
        arguments: ``tip``, ``length_scale_m``, ``char_length_m``, ``hfield_resolution``)
        without the hfield."""
        return cls.with_hfield(surface, **sizing)[0]

    @classmethod
    def for_rig(
        cls,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        sized: tuple[Scales, HField] | None = None,
        **sizing,
    ) -> tuple[Scales, HField, TipParams]:
        """A rig's scales, hfield and tip, where both engines' rigs start: ``sized`` (the
        ``(scales, hfield)`` its builder measured once) or :meth:`with_hfield` of
        ``sizing`` measured here, and ``tip`` (default :class:`TipParams`) carrying the
        scales' tip radius."""
        if not isinstance(surface, Surface):
            raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
        tip = TipParams() if tip is None else tip
        scales, hfield = cls.with_hfield(surface, tip=tip, **sizing) if sized is None else sized
        radius = scales.tip_radius_m
        return (
            scales,
            hfield,
            tip if tip.tip_radius_m == radius else dataclasses.replace(tip, tip_radius_m=radius),
        )

    @classmethod
    def with_hfield(
        cls,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        length_scale_m: float | None = None,
        char_length_m: float | None = None,
        hfield_resolution: int | None = None,
        hfield_refinement: int = 1,
        progress: Callable[[float, float, str], None] | None = None,
    ) -> tuple[Scales, HField]:
        """The scales of ``tip`` on ``surface`` and the hfield they were measured on (the
        rig's model is built from that same hfield): the one place the rig's sizing rules
        live. ``progress(done, total, stage)`` hears each stage (minutes on 8192 a side).

        * ``length_scale_m``: None gives :data:`DEFAULT_LENGTH_SCALE_M` for a dimensionless
          surface (``unit == "1"``) and the unit's size (:data:`LENGTH_UNITS_M`) otherwise.
        * ``char_length_m``: None gives :func:`characteristic_length` in metres.
        * tip radius (when ``tip.tip_radius_m`` is None): the surface's own ``metadata["params"]
          ["tip_radius_m"]`` (sandpaper); for a measured scan (a grid in a physical unit) the larger
          of two lateral spacings and ``L_c / 100`` (the sphere rests on several facets); else of
          one hfield spacing and ``L_c / 100``; at most the width / 8 (a narrow strip); 3 digits.
        * hfield resolution: an hfield finer than a quarter tip radius is coarsened to that (MuJoCo
          keeps at most 50 contacts per geom pair: a tip over too many cells loses its deepest
          contacts); then refined ``hfield_refinement`` times (:func:`hfield_of`)
        * fall height: :func:`fall_height` of that hfield with the tip's ``mu_s`` and radius.

        Raises
        ------
        SpineInputError
            A surface in an unknown unit, scales outside the physical range, a tip larger
            than the surface, or an hfield coarser than two tip radii (the sphere would see
            single facets and their kinks).
        """
        if not isinstance(surface, Surface):
            raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
        tip = TipParams() if tip is None else tip
        hfield_refinement = check_hfield_refinement(hfield_refinement)
        length_scale_m, char_length_m, radius, resolution = _planned_sizing(
            surface, tip, length_scale_m, char_length_m, check_hfield_resolution(hfield_resolution)
        )
        report = _reporter(progress, surface, hfield_resolution, hfield_refinement)
        hf = _sampled_hfield(surface, resolution, hfield_refinement, report)
        spacing = hfield_spacing(hf, length_scale_m)
        xmin, xmax, ymin, ymax = (length_scale_m * b for b in surface.bounds)
        rx, ry, elevation = hf.size[0], hf.size[1], hf.size[2]
        fall = fall_height(
            hf.data.astype(float) * (elevation * length_scale_m),  # float64: the same at every scale
            (2 * rx / (hf.ncol - 1) * length_scale_m, 2 * ry / (hf.nrow - 1) * length_scale_m),
            mu=tip.mu_s,
            radius=radius,
            progress=lambda done, total: report(done, total, "fall height"),
        )
        scales = cls(
            length_scale_m=length_scale_m,
            char_length_m=char_length_m,
            mass_kg=tip.mass_kg,
            preload_n=tip.preload_total_n,
            tip_radius_m=radius,
            hfield_spacing_m=spacing,
            hfield_resolution=resolution,
            hfield_refinement=int(hfield_refinement),
            slope_length_m=_slope_length(surface, length_scale_m, char_length_m),
            extent_m=math.hypot(xmax - xmin, ymax - ymin),
            fall_height_m=fall,
        )
        return scales, hf

    @property
    def units(self) -> EngineUnits:
        """The engine's units: length L_c, force F_p, mass m."""
        return EngineUnits(length_m=self.char_length_m, force_n=self.preload_n, mass_kg=self.mass_kg)

    @property
    def time_s(self) -> float:
        """tau = sqrt(m L_c / F_p), the time over which the preload moves the tip by L_c."""
        return math.sqrt(self.mass_kg * self.char_length_m / self.preload_n)

    @property
    def speed_m_s(self) -> float:
        """sqrt(F_p L_c / m): the speed at which I_e = 1."""
        return math.sqrt(self.preload_n * self.char_length_m / self.mass_kg)

    def inertia_number(self, speed_m_s: float) -> float:
        """I_e = m v^2 / (F_p L_c) (paper §2.2)."""
        return self.mass_kg * speed_m_s**2 / (self.preload_n * self.char_length_m)

    def speed_for(self, inertia_number: float) -> float:
        """The drive speed [m/s] of inertia number ``inertia_number`` (inverse of I_e).

        Raises
        ------
        SpineInputError
            Unless ``0 < I_e <= MAX_INERTIA_NUMBER``.
        """
        return math.sqrt(check_inertia_number(inertia_number)) * self.speed_m_s

    def force_rate_for(self, speed_m_s: float) -> float:
        """The force rate [N/s] of a force drive (ramp, static probe) at equivalent speed
        ``speed_m_s``: ``v F_p / L_c``, the rate at which the force rises by one preload in
        the time the tip would cross one feature at that speed (inverse of
        :meth:`equivalent_speed`)."""
        return speed_m_s * self.preload_n / self.char_length_m

    def equivalent_speed(self, rate_n_s: float) -> float:
        """A force drive's equivalent speed [m/s], ``v_eq = L_c rate / F_p``."""
        return self.char_length_m * rate_n_s / self.preload_n

    def stiffness_number(self, stiffness_n_m: float) -> float:
        """K = k l_s / F_p (docs/physics.md §4), l_s the slope correlation length."""
        return stiffness_n_m * self.slope_length_m / self.preload_n

    def stiffness_for(self, stiffness_number: float) -> float:
        """The spring stiffness [N/m] of drive stiffness number ``K`` (inverse of K)."""
        return stiffness_number * self.preload_n / self.slope_length_m


def surface_unit_m(surface: Surface, length_scale_m: float | None) -> float:
    """Metres per surface length unit: ``length_scale_m``, else by the surface's unit
    (:data:`~spine_mj.surfaces.LENGTH_UNITS_M`; "1", dimensionless, gives
    :data:`DEFAULT_LENGTH_SCALE_M`)."""
    unit = length_unit(surface.unit)
    if surface.unit != "1" and unit is None:
        raise SpineInputError(
            f"surface unit must be '1' (dimensionless) or a length unit {sorted(LENGTH_UNITS_M)}, "
            f"got {surface.unit!r}"
        )
    if length_scale_m is None:
        length_scale_m = DEFAULT_LENGTH_SCALE_M if unit is None else LENGTH_UNITS_M[unit]
    return check_physical_length("length_scale_m", length_scale_m)


def check_physical_length(name: str, value: float) -> float:
    """``value`` [m] if it lies in :data:`PHYSICAL_LENGTH_M`, else :class:`SpineInputError`."""
    value = check_positive(name, value)
    lo, hi = PHYSICAL_LENGTH_M
    if not lo <= value <= hi:
        raise SpineInputError(
            f"{name} must lie in [{lo:g}, {hi:g}] m (a rigid-sphere contact means nothing outside), "
            f"got {value:g}"
        )
    return value


def default_tip_radius(
    surface: Surface, spacing_m: float, char_length_m: float, *, width_m: float = math.inf
) -> float:
    """The default tip radius [m] (rule in :meth:`Scales.for_surface`; ``width_m`` the
    domain's narrower side [m])."""
    params = surface.metadata.get("params", {}) if isinstance(surface.metadata, dict) else {}
    radius = params.get("tip_radius_m") if surface.unit != "1" else None
    if radius:
        return float(radius)
    scan = isinstance(surface, GridSurface) and surface.unit != "1"
    spacings = _SCAN_TIP_SPACINGS if scan else 1.0
    radius = min(max(spacings * spacing_m, 0.01 * char_length_m), width_m / DEFAULT_TIP_RADII_ACROSS)
    return float(f"{radius:.3g}")


def check_tip_radius(
    tip_radius: float | None, name: str = "tip_radius", *, point: bool = True
) -> float | None:
    """A user's tip radius [the surface's length unit], checked: None (the rig's default
    tip), 0 (a point) or a finite radius > 0. ``point`` False: a point is refused, as where
    an engine runs (its tip is a ball). The one meaning of ``tip_radius`` in every command
    and config key (:func:`resolve_tip_radius`, :func:`engine_tip_radius_m`)."""
    if tip_radius is None:
        return None
    if isinstance(tip_radius, bool) or not (math.isfinite(tip_radius) and tip_radius >= 0):
        raise SpineInputError(
            f"{name} must be a finite number >= 0 in the surface's length unit (0: a point), "
            f"got {tip_radius!r}"
        )
    if tip_radius == 0 and not point:
        raise SpineInputError(
            f"{name} 0 is a point tip, and an engine's tip is a ball: give a radius > 0 in the "
            f"surface's length unit, or leave {name} out for the rig's default"
        )
    return float(tip_radius)


def resolve_tip_radius(
    surface: Surface,
    tip_radius: float | None,
    *,
    length_scale_m: float | None = None,
    hfield_resolution: int | None = None,
    name: str = "tip_radius",
) -> float:
    """The tip radius [the surface's length unit] that ``tip_radius`` means: itself (0, a
    point, included), or for None the radius a rig of ``surface`` takes at these sizing
    inputs (:func:`default_tip_radius`; a grid keeps its own samples,
    :func:`grid_keeps_samples`). So a streamline and an engine's run given the same
    ``tip_radius``, or none, trace the same tip."""
    radius = check_tip_radius(tip_radius, name)
    if radius is not None:
        return radius
    unit_m = surface_unit_m(surface, length_scale_m)
    resolution = grid_keeps_samples(surface, check_hfield_resolution(hfield_resolution))
    char_length_m = characteristic_length(surface) * unit_m
    return _tip_rule(surface, None, unit_m, char_length_m, resolution)[2] / unit_m


def engine_tip_radius_m(
    surface: Surface,
    tip_radius: float | None,
    *,
    length_scale_m: float | None = None,
    name: str = "tip_radius",
) -> float | None:
    """What an engine's rig takes of a user's ``tip_radius`` [the surface's length unit]:
    the radius in metres, or None for the rig's default (sized by :meth:`Scales.with_hfield`,
    the same radius :func:`resolve_tip_radius` gives). A point (0) is refused."""
    radius = check_tip_radius(tip_radius, name, point=False)
    return None if radius is None else radius * surface_unit_m(surface, length_scale_m)


def fall_height(
    heights: np.ndarray,
    spacing: tuple[float, float],
    *,
    mu: float,
    radius: float,
    rows: int = 512,
    progress: Callable[[int, int], None] | None = None,
) -> float:
    """The height a slip can turn into an impact: the largest landing of a tip on ``heights``.

    A tip that slips down a slope steeper than its friction angle gains speed; down a
    cliff (a grit's overhang, an AFM scan-line step) it falls. Its speed is that of a fall
    from ``H = drop - mu run``: the sliding friction takes ``mu`` times the weight per unit
    of horizontal run (the work ``mu N ds`` with ``N = W cos(theta)``), nothing where the
    tip is airborne or on a wall. Where the surface then turns up by ``theta`` (measured over
    one tip radius, the scale the sphere feels), the part ``sin(theta)`` of that speed hits
    the next facet: a landing like a fall from ``H sin^2(theta)``. The result is the largest
    such height along every row and column of the grid, walked both ways: exact for the
    straight falls of a quasistatic slip, 0 on a plane (no turn) and where no slope beats
    friction (no drop). Pure numpy, ``rows`` lines at a time.

    Parameters
    ----------
    heights : ndarray, shape (ny, nx)
        ``heights[iy, ix]`` in some length unit (the result is in that unit).
    spacing : (dx, dy)
        Grid spacings in the same unit.
    mu, radius : float
        The tip's friction coefficient and radius (same unit).
    progress : callable, optional
        Called with ``(lines done, lines)`` after each block of ``rows`` lines.
    """
    heights = np.asarray(heights, dtype=float)
    best, done, lines = 0.0, 0, sum(heights.shape)
    for grid, step in ((heights, spacing[0]), (heights.T, spacing[1])):
        m = max(1, round(radius / step))  # cells per tip radius
        n = grid.shape[1]
        if n <= 2 * m:
            continue
        run = mu * step * np.arange(n)
        for lo in range(0, grid.shape[0], rows):
            for a in (grid[lo : lo + rows], grid[lo : lo + rows, ::-1]):
                g = a + run  # height plus the friction's toll: falling from i to j gains g_i - g_j
                drop = np.maximum.accumulate(g, axis=1) - g
                into = np.arctan((a[:, m : n - m] - a[:, : n - 2 * m]) / (m * step))
                out = np.arctan((a[:, 2 * m :] - a[:, m : n - m]) / (m * step))
                turn = np.clip(out - into, 0.0, math.pi / 2)
                best = max(best, float((drop[:, m : n - m] * np.sin(turn) ** 2).max()))
            done += min(rows, grid.shape[0] - lo)
            if progress is not None:
                progress(done, lines)
    return best


def _quiet(done: float, total: float, stage: str) -> None:
    """A progress callback that hears nothing."""


def _reporter(progress, surface: Surface, resolution: int | None, refinement) -> Callable:
    """``progress`` for hfields of PROGRESS_MIN_SAMPLES or more, else :func:`_quiet` (quick: no bars)."""
    ny, nx = hfield_sides(surface, resolution, refinement)
    return progress if progress is not None and nx * ny >= PROGRESS_MIN_SAMPLES else _quiet


def _check_sizes(
    radius: float,
    spacing: float,
    char_length: float,
    span: float,
    *,
    given: bool = True,
    length_scale_m: float = 1.0,
    unit: str = "m",
    gridded: bool = False,
) -> None:
    """Tip, hfield spacing and L_c against each other and the domain (all in metres);
    ``given``: the radius is the user's (a default one is named as such); ``gridded``: the
    surface keeps its own samples (:func:`~spine_mj.sim.rig_hfield.grid_keeps_samples`: no
    ``hfield_resolution`` changes its spacing). Each length is
    named in metres and, for a surface in another ``unit`` (``length_scale_m`` metres), in
    the surface's unit too: the CLI takes the tip radius in it."""

    def length(value_m: float) -> str:
        if unit == "m" and length_scale_m == 1.0:
            return f"{value_m:.3g} m"
        return f"{value_m:.3g} m ({value_m / length_scale_m:.3g} {'surface units' if unit == '1' else unit})"

    what = f"tip_radius_m {length(radius)}" if given else f"the default tip radius {length(radius)}"
    if 2 * radius >= span:
        raise SpineInputError(
            f"{what} is larger than the surface: its diameter must be smaller than the domain's "
            f"width {length(span)}"
        )
    floor = _MIN_ENGINE_RATIO * char_length
    if min(radius, spacing) < floor:
        raise SpineInputError(
            f"tip_radius_m {length(radius)} or hfield spacing {length(spacing)} is finer than the "
            f"engine resolves: both must exceed {_MIN_ENGINE_RATIO:g} L_c = {length(floor)}"
        )
    if spacing > 2 * radius * (1 + 1e-9):
        remedy = (
            f"a gridded surface (a file, a scan) keeps its own samples, so hfield_resolution does not "
            f"apply: use a tip radius of at least {length(spacing / 2)}, or the surface on a finer grid"
            if gridded
            else "raise hfield_resolution or the tip radius"
        )
        raise SpineInputError(
            f"surface too coarse for the tip: hfield spacing {length(spacing)} > 2 x {what} "
            f"= {length(2 * radius)}; {remedy}"
        )


def _slope_length(surface: Surface, length_scale_m: float, char_length_m: float) -> float:
    """l_s [m], or L_c for a surface without one (a plane)."""
    try:
        return slope_correlation_length(surface) * length_scale_m
    except SpineInputError:
        return char_length_m


def _sampled_hfield(surface: Surface, resolution: int | None, refinement: int, report) -> HField:
    """:func:`hfield_of` ``surface`` at ``resolution`` refined ``refinement`` times, its stage
    told to ``report``."""
    report(0, 1, "sampling the hfield" if refinement == 1 else "refining the hfield")
    return hfield_of(surface, resolution, refinement)


def _planned_sizing(surface: Surface, tip: TipParams, length_scale_m, char_length_m, resolution) -> tuple:
    """``(length_scale_m, char_length_m, radius [m], resolution)`` of :meth:`Scales.with_hfield`'s
    rule, before any hfield is sampled: the unit, L_c, the tip's radius (its default where
    None) checked against the hfield's spacing and the domain, and the resolution (a grid
    finer than a quarter tip radius coarsened to that)."""
    length_scale_m = surface_unit_m(surface, length_scale_m)
    if char_length_m is None:
        char_length_m = characteristic_length(surface) * length_scale_m
    char_length_m = check_physical_length("char_length_m", char_length_m)
    spacing, width, radius = _tip_rule(surface, tip.tip_radius_m, length_scale_m, char_length_m, resolution)
    _check_sizes(
        radius,
        spacing,
        char_length_m,
        width,
        given=tip.tip_radius_m is not None,
        length_scale_m=length_scale_m,
        unit=surface.unit,
        gridded=grid_keeps_samples(surface, 0) is None,
    )
    if resolution is None and spacing < _MIN_SPACING_PER_TIP_RADIUS * radius:
        extent = 2 * max(hfield_half_extents(surface)) * length_scale_m
        resolution = math.ceil(extent / (_MIN_SPACING_PER_TIP_RADIUS * radius)) + 1
    return length_scale_m, char_length_m, radius, resolution


def _tip_rule(
    surface: Surface, tip_radius_m, length_scale_m: float, char_length_m: float, resolution
) -> tuple:
    """``(spacing, width, radius)`` [m] of the sizing rule before any hfield is sampled: the
    planned hfield's spacing, the domain's narrower side, and ``tip_radius_m`` or, where None,
    :func:`default_tip_radius` of those (the rig's sizing and :func:`resolve_tip_radius` alike)."""
    spacing = planned_spacing(surface, resolution, 1, length_scale_m)
    xmin, xmax, ymin, ymax = (length_scale_m * b for b in surface.bounds)
    width = min(xmax - xmin, ymax - ymin)
    if tip_radius_m is None:
        tip_radius_m = default_tip_radius(surface, spacing, char_length_m, width_m=width)
    return spacing, width, tip_radius_m


def planned_hfield_sides(
    surface: Surface,
    *,
    tip: TipParams | None = None,
    length_scale_m: float | None = None,
    hfield_resolution: int | None = None,
    hfield_refinement: int = 1,
) -> tuple[int, int]:
    """``(nrow, ncol)`` of the hfield :meth:`Scales.with_hfield` would sample for these
    inputs (the same rule, the coarsening included), measuring only L_c: an engine's limit
    on its heightfield and a memory budget are checked before seconds of sizing."""
    tip = TipParams() if tip is None else tip
    resolution = check_hfield_resolution(hfield_resolution)
    resolution = _planned_sizing(surface, tip, length_scale_m, None, resolution)[3]
    return hfield_sides(surface, resolution, check_hfield_refinement(hfield_refinement))


def check_inertia_number(inertia_number: float, what: str = "inertia number I_e") -> float:
    """``inertia_number`` if ``0 < I_e <= MAX_INERTIA_NUMBER``, else SpineInputError naming ``what``."""
    if isinstance(inertia_number, (int, float)) and inertia_number > MAX_INERTIA_NUMBER * (1 + 1e-12):
        raise SpineInputError(  # (1 + 1e-12): the limit itself, through a speed and back
            f"{what} must be <= {MAX_INERTIA_NUMBER:g} (the tip crosses an asperity "
            f"{math.sqrt(MAX_INERTIA_NUMBER):g} times faster than the preload can move it), "
            f"got {inertia_number:g}"
        )
    return check_positive(what, inertia_number)
