"""The rig's parameters and the one home of its scaling rule.

Parameter records (frozen, validated on construction): :class:`TipParams` (the spine tip),
:class:`EngineSettings` (MuJoCo settings, recorded with every run) and the enums they use,
plus :class:`EndReason`. :class:`Scales` derives the problem's scales from a surface and a
tip (:meth:`Scales.for_surface`: length scale, ``L_c``, ``l_s``, default tip radius, hfield
spacing and coarsening), :class:`EngineUnits` the units MuJoCo works in, and
:func:`default_engine` the engine settings from the scales (rule in :mod:`spine_mj.sim`'s
docstring). Nothing here needs MuJoCo.

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
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.roughness import characteristic_length, slope_correlation_length
from spine_mj.surfaces import LENGTH_UNITS_M, GridSurface, HField, Surface, length_unit, to_hfield

DEFAULT_LENGTH_SCALE_M = 0.01
_REST_PENETRATION_FRACTION = 0.005
#: Largest inertia number a drive may have: beyond it the quasistatic question is moot and
#: the engine step (bounded by impacts at the drive speed) shrinks without end.
MAX_INERTIA_NUMBER = 1e4
#: Most a drive may advance in one time step, in L_c of carriage travel (for a force drive,
#: F_p of force rise: the same number at its equivalent speed). Beyond it an asperity is
#: crossed in a few steps and a run's ending tells of the step, not the surface; the step
#: rule (:func:`default_engine`) keeps it below ~0.004.
MAX_DRIVE_ADVANCE_PER_STEP = 0.1
_IMPACT_DEPTH_OF_TOLERANCE = 0.5  # impact depth an arrival may reach, in penetration tolerances
#: Landing speed of a tip thrown off a crest, in drive speeds: the spring's release and the
#: fall add to the carriage's speed. Measured on the single peak and valley with the default
#: spring at I_e = 0.03-1: normal speeds at contact onset of 1.0-2.0 times the drive speed.
_LANDING_SPEED_FACTOR = 2.0
#: The spring drive's default stiffness number K = k l_s / F_p (docs/physics.md §4). A drive
#: is quasistatic only when it is slow *and* stiff: the elastic energy a spring stores at
#: breakaway, (kappa F_p)^2 / 2k = kappa^2 F_p l_s / 2K, is released into the slip. Measured
#: on three fractal seeds x 5 starts at I_e = 1e-4: K = 3 stopped 8/15 runs on penetration
#: (hops on landing), K = 10 3/15, K = 30 and 100 none, with the median Frechet distance
#: from the streamline 0.35, 0.10, 0.021 and 0.030 L_c. 30 is the softest of those clean ones
#: (the stiffer, the more steps per spring period the time step must resolve).
DEFAULT_STIFFNESS_NUMBER = 30.0
#: Largest ``omega dt`` the step rule gives the drive spring, ``omega = sqrt(k / m)``. MuJoCo
#: integrates a position actuator's stiffness explicitly (``implicitfast`` takes only velocity
#: derivatives implicitly), so the spring-tip oscillator runs under semi-implicit Euler:
#: stable for ``omega dt < 2``, with a period error of ``(omega dt)^2 / 24`` and a peak-speed
#: error of ``(omega dt)^2 / 16`` (0.38 % and 0.57 % at 0.3; docs/physics.md §7).
SPRING_OMEGA_DT = 0.3
#: Largest ``omega dt`` a spring drive may run at on a rig built for a softer spring or with a
#: user's step: twice the rule's, where the spring-block's period is still within 1.5 % and
#: its peak speed within 2.3 % (beyond it the run is refused, never run inaccurately).
MAX_SPRING_OMEGA_DT = 2 * SPRING_OMEGA_DT
_MIN_SPACING_PER_TIP_RADIUS = 0.25  # finer hfields exceed MuJoCo's 50 contacts per geom pair
_SCAN_TIP_SPACINGS = 2.0  # default tip radius of a measured scan, in lateral spacings
MAX_HFIELD_SIDE = 8192  # samples a side of an hfield (memory; MuJoCo's collision stays local)
_MIN_ENGINE_RATIO = 1e-9  # smallest length ratio (tip / L_c, spacing / L_c) the engine resolves
#: Physical range of lengths [m] and masses [kg] (outside it the model means nothing).
PHYSICAL_LENGTH_M = (1e-12, 1e3)
PHYSICAL_MASS_KG = (1e-24, 1e6)
#: Largest load per unit moving mass, F_p / m_eff [m/s^2] (1e5 g): beyond it a run's time
#: scale sqrt(m L_c / F_p) falls below any physical meaning (preload 1e30 N ended a run
#: at 7e-16 s with the carriage at 1.2e14 m/s).
MAX_PRELOAD_ACCELERATION_M_S2 = 1e6


class Cone(enum.Enum):
    """Friction cone (MuJoCo ``opt.cone``)."""

    ELLIPTIC = "elliptic"
    PYRAMIDAL = "pyramidal"


class Integrator(enum.Enum):
    """Integrator (MuJoCo ``opt.integrator``)."""

    EULER = "euler"
    IMPLICITFAST = "implicitfast"
    IMPLICIT = "implicit"
    RK4 = "rk4"


class EndReason(enum.Enum):
    """Why a run ended."""

    COMPLETED = "completed"  # the drive's duration elapsed
    BREAKAWAY = "breakaway"  # static probe: the tip broke away under the rising force
    SLID = "slid"  # static probe: the tip slid off under gravity/preload alone
    SELF_LOCK = "self_lock"  # the drive force reached kappa_cap * F_p without motion
    LEFT_DOMAIN = "left_domain"  # the tip left the surface's bounds
    ENGINE_TROUBLE = "engine_trouble"  # non-finite state, MuJoCo warning or deep penetration


def check_optional(obj, names: Sequence[str], *, allow_zero: bool = False) -> None:
    """Check the named fields of a frozen dataclass that may be None (positive, or >= 0)."""
    for name in names:
        value = getattr(obj, name)
        if value is not None:
            object.__setattr__(obj, name, check_positive(name, value, allow_zero=allow_zero))


@dataclass(frozen=True)
class TipParams:
    """The spine tip.

    Attributes
    ----------
    tip_radius_m : float or None
        Sphere radius [m]; None derives it from the surface (:meth:`Rig.__init__`).
    mass_kg : float
        Effective moving mass m_eff [kg].
    mu_s : float
        Friction coefficient (static = kinetic in MuJoCo), >= 0.
    preload_n : float
        Extra downward force on the tip [N], >= 0, added to gravity.
    gravity_m_s2 : float
        Gravitational acceleration [m/s^2], >= 0 (0 with a preload gives zero-g).
    """

    tip_radius_m: float | None = None
    mass_kg: float = 0.01
    mu_s: float = 0.5
    preload_n: float = 0.0
    gravity_m_s2: float = 9.81

    def __post_init__(self):
        check_optional(self, ["tip_radius_m"])
        object.__setattr__(self, "mass_kg", check_positive("mass_kg", self.mass_kg))
        lo, hi = PHYSICAL_MASS_KG
        if not lo <= self.mass_kg <= hi:
            raise SpineInputError(f"mass_kg must lie in [{lo:g}, {hi:g}] kg, got {self.mass_kg:g}")
        object.__setattr__(self, "mu_s", check_positive("mu_s", self.mu_s, allow_zero=True))
        object.__setattr__(self, "preload_n", check_positive("preload_n", self.preload_n, allow_zero=True))
        object.__setattr__(
            self, "gravity_m_s2", check_positive("gravity_m_s2", self.gravity_m_s2, allow_zero=True)
        )
        if self.preload_n == 0 and self.gravity_m_s2 == 0:
            raise SpineInputError(
                "preload_n and gravity_m_s2 are both 0: the tip has no normal preload; give one of them > 0"
            )
        accel = self.preload_total_n / self.mass_kg
        if not accel <= MAX_PRELOAD_ACCELERATION_M_S2:
            raise SpineInputError(
                f"preload_n and gravity_m_s2: the load per unit mass (m g + preload) / m must be at most "
                f"{MAX_PRELOAD_ACCELERATION_M_S2:g} m/s^2, got {accel:.3g} m/s^2 (preload "
                f"{self.preload_n:g} N, gravity {self.gravity_m_s2:g} m/s^2, mass {self.mass_kg:g} kg)"
            )

    @property
    def preload_total_n(self) -> float:
        """F_p = m g + preload [N]."""
        return self.mass_kg * self.gravity_m_s2 + self.preload_n


@dataclass(frozen=True)
class EngineSettings:
    """MuJoCo settings, recorded with every run (see :func:`default_engine` for the rule).

    Attributes
    ----------
    timestep_s : float
        Time step [s].
    integrator, cone : Integrator, Cone
    impratio : float
        Ratio of frictional to normal constraint impedance (>= 1 sensible).
    noslip_iterations : int
        Noslip solver passes (0 switches it off; then friction creeps).
    solref : (timeconst_s, dampratio)
        Contact reference; ``timeconst_s >= 2 timestep_s`` for stability.
    solimp : (dmin, dmax, width_m, midpoint, power)
        Contact impedance.

    The hfield's resolution is the rig's geometry, not an engine setting: it lives in
    :class:`Scales` (``hfield_resolution``).
    """

    timestep_s: float
    integrator: Integrator = Integrator.IMPLICITFAST
    cone: Cone = Cone.ELLIPTIC
    impratio: float = 1.0
    noslip_iterations: int = 3
    solref: tuple[float, float] = (1e-3, 1.0)
    solimp: tuple[float, float, float, float, float] = (0.99, 0.99, 1e-3, 0.5, 2.0)

    def __post_init__(self):
        object.__setattr__(self, "timestep_s", check_positive("timestep_s", self.timestep_s))
        for name, enum_cls in (("integrator", Integrator), ("cone", Cone)):
            value = getattr(self, name)
            if not isinstance(value, enum_cls):
                try:
                    value = enum_cls(str(value).lower())
                except ValueError:
                    raise SpineInputError(
                        f"{name} must be one of {[e.value for e in enum_cls]}, got {value!r}"
                    ) from None
                object.__setattr__(self, name, value)
        object.__setattr__(self, "impratio", check_positive("impratio", self.impratio))
        ns = self.noslip_iterations
        if isinstance(ns, bool) or int(ns) != ns or ns < 0:
            raise SpineInputError(f"noslip_iterations must be an integer >= 0, got {ns!r}")
        object.__setattr__(self, "noslip_iterations", int(ns))
        if self.cone is Cone.PYRAMIDAL and self.noslip_iterations > 0:
            raise SpineInputError(
                "cone='pyramidal' with noslip_iterations > 0 holds only about half "
                "of mu N (docs/physics.md §5); use the elliptic cone with noslip"
            )
        try:
            tc, dr = (float(v) for v in self.solref)
        except (TypeError, ValueError):
            raise SpineInputError(f"solref must be (timeconst_s, dampratio), got {self.solref!r}") from None
        check_positive("solref dampratio", dr)
        if not (math.isfinite(tc) and tc >= 2 * self.timestep_s * (1 - 1e-9)):
            raise SpineInputError(
                f"solref timeconst_s must be >= 2 timestep_s = {2 * self.timestep_s:g} "
                f"s for a stable contact, got {self.solref[0]!r}"
            )
        object.__setattr__(self, "solref", (tc, dr))
        try:
            si = tuple(float(v) for v in self.solimp)
        except (TypeError, ValueError):
            raise SpineInputError(f"solimp must be 5 numbers, got {self.solimp!r}") from None
        if len(si) != 5 or not (0 < si[0] < 1 and 0 < si[1] < 1 and si[2] > 0):
            raise SpineInputError(
                "solimp must be (dmin, dmax, width_m, midpoint, power) with "
                f"0 < dmin, dmax < 1 and width_m > 0, got {self.solimp!r}"
            )
        object.__setattr__(self, "solimp", si)

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["integrator"], d["cone"] = self.integrator.value, self.cone.value
        return d


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
    slope_length_m : float or None
        l_s, the slope correlation length [m] (:func:`slope_correlation_length`; L_c where
        the surface has none, a plane); the length of the drive stiffness number K.
    extent_m : float or None
        Diagonal of the surface's domain [m] (bounds the energy a run can gain).
    fall_height_m : float
        The height a slip can turn into an impact [m] (:func:`fall_height`: a fall down a
        grit flank or a scan-line step onto the floor below); 0 on planes and on surfaces
        no steeper than the friction angle. It bounds the engine step
        (:func:`default_engine`).
    """

    length_scale_m: float
    char_length_m: float
    mass_kg: float
    preload_n: float
    tip_radius_m: float
    hfield_spacing_m: float
    hfield_resolution: int | None = None
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
    def with_hfield(
        cls,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        length_scale_m: float | None = None,
        char_length_m: float | None = None,
        hfield_resolution: int | None = None,
    ) -> tuple[Scales, HField]:
        """The scales of ``tip`` on ``surface`` and the hfield they were measured on (the
        rig's model is built from that same hfield): the one place the rig's sizing rules
        live.

        * ``length_scale_m``: None gives :data:`DEFAULT_LENGTH_SCALE_M` for a dimensionless
          surface (``unit == "1"``) and the unit's size (:data:`LENGTH_UNITS_M`) otherwise.
        * ``char_length_m``: None gives :func:`characteristic_length` in metres.
        * tip radius (when ``tip.tip_radius_m`` is None): the surface's own
          ``metadata["params"]["tip_radius_m"]`` (sandpaper); for a measured scan (a grid
          in a physical unit) the larger of two lateral spacings and ``L_c / 100`` (the
          sphere rests on several facets, never in one pixel); else the larger of one
          hfield spacing and ``L_c / 100``; to 3 significant digits.
        * hfield resolution: an hfield finer than a quarter tip radius is coarsened to that
          (MuJoCo keeps at most 50 contacts per geom pair: a tip over too many cells loses
          its deepest contacts).
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
        length_scale_m = surface_unit_m(surface, length_scale_m)
        if char_length_m is None:
            char_length_m = characteristic_length(surface) * length_scale_m
        char_length_m = check_physical_length("char_length_m", char_length_m)
        res = hfield_resolution
        if res is not None and (isinstance(res, bool) or int(res) != res or res < 4):
            raise SpineInputError(f"hfield_resolution must be an integer >= 4 or None, got {res!r}")
        if res is not None and res > MAX_HFIELD_SIDE:
            raise SpineInputError(f"hfield_resolution must be <= {MAX_HFIELD_SIDE} samples a side, got {res}")
        hf = hfield_of(surface, hfield_resolution)
        spacing = hfield_spacing(hf, length_scale_m)
        radius = tip.tip_radius_m
        if radius is None:
            radius = default_tip_radius(surface, spacing, char_length_m)
        xmin, xmax, ymin, ymax = (length_scale_m * b for b in surface.bounds)
        _check_sizes(radius, spacing, char_length_m, min(xmax - xmin, ymax - ymin))
        resolution = hfield_resolution
        if resolution is None and spacing < _MIN_SPACING_PER_TIP_RADIUS * radius:
            extent = 2 * max(hf.size[0], hf.size[1]) * length_scale_m
            resolution = math.ceil(extent / (_MIN_SPACING_PER_TIP_RADIUS * radius)) + 1
            hf = hfield_of(surface, resolution)
            spacing = hfield_spacing(hf, length_scale_m)
        rx, ry, elevation = hf.size[0], hf.size[1], hf.size[2]
        fall = fall_height(
            hf.data.astype(float) * (elevation * length_scale_m),  # float64: the same at every scale
            (2 * rx / (hf.ncol - 1) * length_scale_m, 2 * ry / (hf.nrow - 1) * length_scale_m),
            mu=tip.mu_s,
            radius=radius,
        )
        scales = cls(
            length_scale_m=length_scale_m,
            char_length_m=char_length_m,
            mass_kg=tip.mass_kg,
            preload_n=tip.preload_total_n,
            tip_radius_m=radius,
            hfield_spacing_m=spacing,
            hfield_resolution=resolution,
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


def default_tip_radius(surface: Surface, spacing_m: float, char_length_m: float) -> float:
    """The default tip radius [m] (rule in :meth:`Scales.for_surface`)."""
    params = surface.metadata.get("params", {}) if isinstance(surface.metadata, dict) else {}
    radius = params.get("tip_radius_m") if surface.unit != "1" else None
    if radius:
        return float(radius)
    scan = isinstance(surface, GridSurface) and surface.unit != "1"
    spacings = _SCAN_TIP_SPACINGS if scan else 1.0
    return float(f"{max(spacings * spacing_m, 0.01 * char_length_m):.3g}")


def fall_height(
    heights: np.ndarray, spacing: tuple[float, float], *, mu: float, radius: float, rows: int = 512
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
    """
    heights = np.asarray(heights, dtype=float)
    best = 0.0
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
    return best


def _check_sizes(radius: float, spacing: float, char_length: float, span: float) -> None:
    """Tip, hfield spacing and L_c against each other and the domain (all in metres)."""
    if 2 * radius >= span:
        raise SpineInputError(
            f"tip_radius_m {radius:.3g} m is larger than the surface: its diameter must be "
            f"smaller than the domain's width {span:.3g} m"
        )
    if min(radius, spacing) < _MIN_ENGINE_RATIO * char_length:
        raise SpineInputError(
            f"tip_radius_m {radius:.3g} m or hfield spacing {spacing:.3g} m is finer than the engine "
            f"resolves: both must exceed {_MIN_ENGINE_RATIO:g} L_c = {_MIN_ENGINE_RATIO * char_length:.3g} m"
        )
    if spacing > 2 * radius * (1 + 1e-9):
        raise SpineInputError(
            f"surface too coarse for the tip: hfield spacing {spacing:.3g} m > 2 x tip_radius_m "
            f"= {2 * radius:.3g} m; raise hfield_resolution or the tip radius"
        )


def _slope_length(surface: Surface, length_scale_m: float, char_length_m: float) -> float:
    """l_s [m], or L_c for a surface without one (a plane)."""
    try:
        return slope_correlation_length(surface) * length_scale_m
    except SpineInputError:
        return char_length_m


def hfield_of(surface: Surface, resolution: int | None = None) -> HField:
    """The surface as MuJoCo hfield data, resampled to ``resolution`` a side when given.

    Parameters
    ----------
    surface : Surface
        Any surface.
    resolution : int, optional
        Samples a side (None: a grid surface's own, 201 for an analytic one).

    Returns
    -------
    HField
    """
    return to_hfield(surface, nrow=resolution, ncol=resolution) if resolution else to_hfield(surface)


def hfield_spacing(hfield: HField, length_scale_m: float = 1.0) -> float:
    """The larger of an hfield's two sample spacings, in metres.

    Parameters
    ----------
    hfield : HField
        MuJoCo height field data.
    length_scale_m : float
        Metres per surface unit.

    Returns
    -------
    float
    """
    rx, ry = hfield.size[0], hfield.size[1]
    return length_scale_m * 2 * max(rx / (hfield.ncol - 1), ry / (hfield.nrow - 1))


def default_engine(
    scales: Scales,
    *,
    speed_m_s: float | None = None,
    stiffness_n_m: float | None = None,
    **overrides,
) -> EngineSettings:
    """Engine settings derived from the problem's scales, by one rule in engine units.

    ``dt = sqrt(0.005 min(r_tip, L_c) / L_c) tau`` (``dt / tau`` rounded to 2 digits, so the
    rule gives the same engine step at every physical scale): the resting depth of the
    soft contact, ``(1 - dmax) a_p (2 dt)^2 = 0.04 a_p dt^2`` with ``a_p = F_p / m``, is
    then ``2e-4 min(r_tip, L_c)``, well under 0.5 % of the tip radius. ``solref = (2 dt,
    1)`` (the stiffest stable time constant, critically damped), ``solimp`` width 1 % of the
    tip radius (no effect while ``dmin = dmax``), elliptic cone, 3 noslip iterations,
    ``impratio = 1``. ``overrides`` replace fields (a ``timestep_s`` alone also sets
    ``solref = (2 timestep_s, 1)``).

    Impacts also limit the step: a tip arriving at speed ``v`` sinks about ``v t_c / e``
    into the soft contact (time constant ``t_c = 2 dt``) before it stops, and one step
    carries it up to ``v dt`` past the surface, so ``dt <= e d / (2 v)`` keeps the impact at
    ``d``, half the penetration tolerance (:func:`penetration_tolerance_m`; ``d = 0.05
    r_tip`` for tips up to ``L_c / 10``, ``0.005 L_c`` for larger ones). ``v`` is the larger
    of twice the drive's speed ``speed_m_s`` (when given: a tip thrown off a crest lands at
    up to twice the carriage's speed) and the landing speed of the surface's fall,
    ``sqrt(2 a_p scales.fall_height_m)`` (:func:`fall_height`: falls off grit flanks and
    scan-line steps land at many times a quasistatic drive's speed).

    The drive spring also limits the step: ``dt <= SPRING_OMEGA_DT / omega``, ``omega =
    sqrt(k / m)``, for the spring of ``stiffness_n_m`` (None: the default spring, ``K =``
    :data:`DEFAULT_STIFFNESS_NUMBER`), since MuJoCo integrates the spring explicitly
    (:data:`SPRING_OMEGA_DT`). In engine units ``omega tau = sqrt(K L_c / l_s)``, so a
    stiff drive costs ``sqrt(K)`` in steps: on the paper's fractal (``L_c / l_s = 24``)
    K = 30 is still set by the contact, K = 3000 takes 10 times the steps. The contact's
    time constant follows the step (``solref = (2 dt, 1)``, the stiffest stable one): a
    contact softer than the drive spring lets the tip sink and rock on its facets under the
    spring's swings (measured on the fractal at K = 3000 with the contact kept at the
    contact rule's 2 dt: half the runs oscillated at +-50 F_p and agreed with the
    streamline 12 of 24; with the contact following the step, see docs/physics.md §7).

    Parameters
    ----------
    scales : Scales
        The problem's scales (tip radius, L_c, F_p, mass, the surface's fall).
    speed_m_s : float, optional
        The drive's speed [m/s], for the impact bound.
    stiffness_n_m : float, optional
        The drive spring's stiffness [N/m], for the spring bound.
    **overrides
        Fields of :class:`EngineSettings` to replace.

    Returns
    -------
    EngineSettings
    """
    dt_contact = _contact_step_tau(scales, speed_m_s)  # engine units
    if stiffness_n_m is None:
        stiffness_n_m = scales.stiffness_for(DEFAULT_STIFFNESS_NUMBER)
    omega_tau = math.sqrt(check_positive("stiffness_n_m", stiffness_n_m) / scales.mass_kg) * scales.time_s
    dt_tau = min(dt_contact, _two_digits_down(SPRING_OMEGA_DT / omega_tau))
    dt = dt_tau * scales.time_s
    if not dt > 0 and "timestep_s" not in overrides:
        raise SpineInputError(
            f"impacts at drive speed {speed_m_s!r} m/s (or a fall down the surface) would need a time "
            f"step of {dt:.3g} s: lower the speed (I_e)"
        )
    base = {
        "timestep_s": dt,
        "solref": (2 * dt, 1.0),
        "solimp": (0.99, 0.99, 0.01 * scales.tip_radius_m, 0.5, 2.0),
    }
    if "timestep_s" in overrides and "solref" not in overrides:
        base["solref"] = (2 * float(overrides["timestep_s"]), 1.0)
    base.update(overrides)
    return EngineSettings(**base)


def _two_digits_down(x: float) -> float:
    """``x`` > 0 cut to two significant digits (never rounded up: the bound stays a bound)."""
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.floor(x / scale * (1 + 1e-12)) * scale


def spring_omega_dt(stiffness_n_m: float, mass_kg: float, timestep_s: float) -> float:
    """``omega dt`` of a drive spring on a tip of ``mass_kg``, ``omega = sqrt(k / m)``.

    Parameters
    ----------
    stiffness_n_m : float
        The spring's stiffness k [N/m].
    mass_kg : float
        The tip's mass m [kg].
    timestep_s : float
        The engine step dt [s].

    Returns
    -------
    float
        Dimensionless; the step rule keeps it at most :data:`SPRING_OMEGA_DT`.
    """
    return math.sqrt(stiffness_n_m / mass_kg) * timestep_s


def _contact_step_tau(scales: Scales, speed_m_s: float | None) -> float:
    """The contact's step rule of :func:`default_engine` in engine units (``dt / tau``,
    rounded to 2 digits; 0 where impacts would need a step below that precision)."""
    ratio = min(scales.tip_radius_m / scales.char_length_m, 1.0)
    dt_tau = math.sqrt(_REST_PENETRATION_FRACTION * ratio)
    v = math.sqrt(2 * scales.fall_height_m / scales.char_length_m)  # engine units: a_p = 1
    if speed_m_s is not None:
        drive = check_drive_speed(scales, speed_m_s) * scales.time_s / scales.char_length_m
        v = max(v, _LANDING_SPEED_FACTOR * drive)
    if v > 0:
        depth = _IMPACT_DEPTH_OF_TOLERANCE * penetration_tolerance_m(scales) / scales.char_length_m
        dt_tau = min(dt_tau, math.e * depth / (2 * v))
    return float(f"{dt_tau:.2g}")


def check_inertia_number(inertia_number: float, what: str = "inertia number I_e") -> float:
    """``inertia_number`` if ``0 < I_e <= MAX_INERTIA_NUMBER``, else SpineInputError naming ``what``."""
    if isinstance(inertia_number, (int, float)) and inertia_number > MAX_INERTIA_NUMBER * (1 + 1e-12):
        raise SpineInputError(  # (1 + 1e-12): the limit itself, through a speed and back
            f"{what} must be <= {MAX_INERTIA_NUMBER:g} (the tip crosses an asperity "
            f"{math.sqrt(MAX_INERTIA_NUMBER):g} times faster than the preload can move it), "
            f"got {inertia_number:g}"
        )
    return check_positive(what, inertia_number)


def check_drive_speed(scales: Scales, speed_m_s: float) -> float:
    """``speed_m_s`` if its inertia number is within :data:`MAX_INERTIA_NUMBER` (a speed,
    or a force drive's equivalent speed)."""
    speed = check_positive("speed_m_s", speed_m_s)
    try:
        ie = scales.inertia_number(speed)
    except OverflowError:  # speed**2 beyond float range
        ie = math.inf
    check_inertia_number(ie, f"the drive's inertia number I_e (speed {speed:.3g} m/s)")
    return speed


def rest_depth_m(engine: EngineSettings, scales: Scales) -> float:
    """How deep the soft contact lets the tip rest under its preload [m]:
    ``(1 - dmax) a_p (timeconst dampratio)^2`` with ``a_p = F_p / m`` (MuJoCo's reference
    acceleration balancing the preload; 2e-4 min(r_tip, L_c) with :func:`default_engine`)."""
    tc, dr = engine.solref
    return (1 - engine.solimp[1]) * scales.preload_n / scales.mass_kg * (tc * dr) ** 2


#: Shortest time step, in time scales tau: a tip moving L_c per tau then advances by less
#: than 1e-9 L_c a step, of which float64 keeps only ~7 digits.
MIN_TIMESTEP_TAU = 1e-9


def check_engine_for(engine: EngineSettings, scales: Scales) -> None:
    """Refuse engine settings whose contact rests the tip deeper than the penetration
    tolerance (every run on them would end as engine trouble, and an exported model would
    show a tip sunk into the surface; the message gives the largest time step that fits),
    or whose step is below :data:`MIN_TIMESTEP_TAU`."""
    if engine.timestep_s < MIN_TIMESTEP_TAU * scales.time_s:
        raise SpineInputError(
            f"timestep_s must be at least {MIN_TIMESTEP_TAU:g} of the time scale tau = "
            f"{scales.time_s:.3g} s, or none (derived), got {engine.timestep_s:.3g}"
        )
    depth, tol = rest_depth_m(engine, scales), penetration_tolerance_m(scales)
    if depth > tol:
        tc, dr = engine.solref
        most_dt = math.sqrt(tol / ((1 - engine.solimp[1]) * scales.preload_n / scales.mass_kg)) / (2 * dr)
        raise SpineInputError(
            f"timestep_s {engine.timestep_s:.3g} s (contact time constant {tc:.3g} s) rests the "
            f"tip {depth:.3g} m deep in the surface, beyond the penetration tolerance "
            f"{tol:.3g} m: use a time step of at most {most_dt:.3g} s, or none (derived)"
        )


def penetration_tolerance_m(scales: Scales) -> float:
    """Penetration [m] above which a run ends as engine trouble: ``min(0.1 r_tip, 0.01 L_c)``.

    Beyond ~10 % of the tip radius the contacts of neighbouring facets tilt the normal by
    tens of degrees (docs/physics.md §5); beyond 1 % of L_c the tip no longer follows the
    surface it is meant to probe.

    Parameters
    ----------
    scales : Scales
        The problem's scales (tip radius, L_c).

    Returns
    -------
    float
    """
    return min(0.1 * scales.tip_radius_m, 0.01 * scales.char_length_m)
