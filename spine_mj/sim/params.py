"""The rig's parameters and the one home of its scaling rule.

Parameter records (frozen, validated on construction): :class:`TipParams` (the spine tip),
:class:`EngineSettings` (MuJoCo settings, recorded with every run) and the enums they use,
plus :class:`EndReason`. :class:`Scales` derives the problem's scales from a surface and a
tip (:meth:`Scales.for_surface`: length scale, ``L_c``, default tip radius, hfield spacing
and coarsening), and :func:`default_engine` the engine settings from the scales (rule in
:mod:`spine_mj.sim`'s docstring). Nothing here needs MuJoCo.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.roughness import characteristic_length
from spine_mj.surfaces import HField, Surface, to_hfield

DEFAULT_LENGTH_SCALE_M = 0.01
_MAX_TIMESTEP_S = 1e-3
_REST_PENETRATION_FRACTION = 0.005
_MIN_SPACING_PER_TIP_RADIUS = 0.25  # finer hfields exceed MuJoCo's 50 contacts per geom pair


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
        object.__setattr__(self, "mu_s", check_positive("mu_s", self.mu_s, allow_zero=True))
        object.__setattr__(self, "preload_n", check_positive("preload_n", self.preload_n, allow_zero=True))
        object.__setattr__(
            self, "gravity_m_s2", check_positive("gravity_m_s2", self.gravity_m_s2, allow_zero=True)
        )
        if self.preload_n == 0 and self.gravity_m_s2 == 0:
            raise SpineInputError(
                "preload_n and gravity_m_s2 are both 0: the tip has no normal preload; give one of them > 0"
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
    hfield_resolution : int or None
        Samples per side when an analytic surface is turned into an hfield (None: 201;
        a grid surface keeps its own samples).
    """

    timestep_s: float
    integrator: Integrator = Integrator.IMPLICITFAST
    cone: Cone = Cone.ELLIPTIC
    impratio: float = 1.0
    noslip_iterations: int = 3
    solref: tuple[float, float] = (1e-3, 1.0)
    solimp: tuple[float, float, float, float, float] = (0.99, 0.99, 1e-3, 0.5, 2.0)
    hfield_resolution: int | None = None

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
        res = self.hfield_resolution
        if res is not None and (isinstance(res, bool) or int(res) != res or res < 4):
            raise SpineInputError(f"hfield_resolution must be an integer >= 4 or None, got {res!r}")

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["integrator"], d["cone"] = self.integrator.value, self.cone.value
        return d


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
    """

    length_scale_m: float
    char_length_m: float
    mass_kg: float
    preload_n: float
    tip_radius_m: float
    hfield_spacing_m: float
    hfield_resolution: int | None = None

    @classmethod
    def for_surface(
        cls,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        length_scale_m: float | None = None,
        char_length_m: float | None = None,
        hfield_resolution: int | None = None,
    ) -> Scales:
        """The scales of ``tip`` on ``surface``: the one place the rig's sizing rules live.

        * ``length_scale_m``: None gives :data:`DEFAULT_LENGTH_SCALE_M` for a dimensionless
          surface (``unit == "1"``) and 1 for one in metres.
        * ``char_length_m``: None gives :func:`characteristic_length` in metres.
        * tip radius (when ``tip.tip_radius_m`` is None): the surface's own
          ``metadata["params"]["tip_radius_m"]`` (sandpaper), else the larger of one hfield
          spacing and ``L_c / 100``, to 3 significant digits.
        * hfield resolution: an hfield finer than a quarter tip radius is coarsened to that
          (MuJoCo keeps at most 50 contacts per geom pair: a tip over too many cells loses
          its deepest contacts).

        Raises
        ------
        SpineInputError
            A surface in a unit other than "1" or "m", non-positive scales, or an hfield
            coarser than two tip radii (the sphere would see single facets and their kinks).
        """
        if not isinstance(surface, Surface):
            raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
        tip = TipParams() if tip is None else tip
        if surface.unit not in ("1", "m"):
            raise SpineInputError(f"surface unit must be '1' (dimensionless) or 'm', got {surface.unit!r}")
        if length_scale_m is None:
            length_scale_m = DEFAULT_LENGTH_SCALE_M if surface.unit == "1" else 1.0
        length_scale_m = check_positive("length_scale_m", length_scale_m)
        if char_length_m is None:
            char_length_m = characteristic_length(surface) * length_scale_m
        char_length_m = check_positive("char_length_m", char_length_m)
        resolution = hfield_resolution
        hf = hfield_of(surface, resolution)
        spacing = hfield_spacing(hf, length_scale_m)
        radius = tip.tip_radius_m
        if radius is None:
            params = surface.metadata.get("params", {}) if isinstance(surface.metadata, dict) else {}
            radius = params.get("tip_radius_m") if surface.unit == "m" else None
            radius = float(radius) if radius else max(spacing, 0.01 * char_length_m)
            radius = float(f"{radius:.3g}")
        if resolution is None and spacing < _MIN_SPACING_PER_TIP_RADIUS * radius:
            extent = 2 * max(hf.size[0], hf.size[1]) * length_scale_m
            resolution = math.ceil(extent / (_MIN_SPACING_PER_TIP_RADIUS * radius)) + 1
            spacing = hfield_spacing(hfield_of(surface, resolution), length_scale_m)
        if spacing > 2 * radius * (1 + 1e-9):
            raise SpineInputError(
                f"surface too coarse for the tip: hfield spacing {spacing:.3g} m > 2 x tip_radius_m "
                f"= {2 * radius:.3g} m; raise hfield_resolution or the tip radius"
            )
        return cls(
            length_scale_m=length_scale_m,
            char_length_m=char_length_m,
            mass_kg=tip.mass_kg,
            preload_n=tip.preload_total_n,
            tip_radius_m=radius,
            hfield_spacing_m=spacing,
            hfield_resolution=resolution,
        )

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
        """The drive speed [m/s] of inertia number ``inertia_number`` (inverse of I_e)."""
        return math.sqrt(inertia_number) * self.speed_m_s


def hfield_of(surface: Surface, resolution: int | None = None) -> HField:
    """The surface as MuJoCo hfield data, resampled to ``resolution`` a side when given."""
    return to_hfield(surface, nrow=resolution, ncol=resolution) if resolution else to_hfield(surface)


def hfield_spacing(hfield: HField, length_scale_m: float = 1.0) -> float:
    """The larger of an hfield's two sample spacings, in metres."""
    rx, ry = hfield.size[0], hfield.size[1]
    return length_scale_m * 2 * max(rx / (hfield.ncol - 1), ry / (hfield.nrow - 1))


def default_engine(scales: Scales, **overrides) -> EngineSettings:
    """Engine settings derived from the problem's scales (rule in the module docstring).

    ``dt = min(1 ms, sqrt(0.005 min(r_tip, L_c) m / F_p))``, ``solref = (2 dt, 1)``,
    elliptic cone, 3 noslip iterations, ``impratio = 1``. ``overrides`` replace fields.
    """
    length = min(scales.tip_radius_m, scales.char_length_m)
    dt = math.sqrt(_REST_PENETRATION_FRACTION * length * scales.mass_kg / scales.preload_n)
    dt = min(_MAX_TIMESTEP_S, dt)
    dt = float(f"{dt:.2g}")
    base = {"timestep_s": dt, "solref": (2 * dt, 1.0), "hfield_resolution": scales.hfield_resolution}
    if "timestep_s" in overrides and "solref" not in overrides:
        base["solref"] = (2 * float(overrides["timestep_s"]), 1.0)
    base.update(overrides)
    return EngineSettings(**base)
