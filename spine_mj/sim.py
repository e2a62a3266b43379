"""MuJoCo rig: any surface as an hfield, a point-like spine tip under gravity, three drives.

The rig (``models/spine_rig.xml``) is a sphere of radius ``tip_radius_m`` on three slide
joints (x, y, z; no rotation) with mass ``mass_kg``, friction ``mu_s`` (condim 3), gravity
and an optional extra downward preload. :class:`Rig` loads that file with ``MjSpec``,
attaches the surface as an hfield through :func:`spine_mj.surfaces.to_hfield` and compiles.

Units. The model is in SI units. A dimensionless surface (``unit == "1"``, the paper's
Gaussian surfaces) is scaled by ``length_scale_m`` (default 1 cm per unit) in x, y and z; a
surface in metres is used as it is. Positions in results are in metres; divide by
``rig.length_scale_m`` for surface units.

Scales and default engine settings (:func:`default_engine`). With
``F_p = mass_kg * gravity + preload_n`` (the normal preload), ``a_p = F_p / mass_kg`` and
``L_c`` the surface's characteristic length (:func:`characteristic_length`):

* contacts use ``solref = (2 dt, 1)`` (the stiffest stable time constant, critically
  damped) and ``solimp = (0.99, 0.99, ...)``; the resting depth is then
  ``(1 - 0.99) a_p (2 dt)^2 = 0.04 a_p dt^2``, and the deepest contact seen while a drive
  loads the tip stays within a few ``a_p dt^2`` per preload of drive force;
* ``dt`` is the largest step (at most 1 ms) with ``a_p dt^2 <= 0.005 min(r_tip, L_c)``:
  measured penetration 2-4 um for a 0.5 mm tip at F <= 5 F_p and 37 um at 17 F_p (a
  60 degree slope), always far below 1 % of ``L_c``;
* ``cone = elliptic`` with ``noslip_iterations = 3``: MuJoCo's friction is soft and creeps
  at any in-cone load without the noslip pass (PHYSICS.md §5); ``impratio`` stays 1.

Drives (PHYSICS.md §4): :class:`SpringDrive` (a carriage moves at constant speed in +x and
pulls the tip through a spring acting in x only), :class:`RampDrive` (force rises at a set
rate until slip, drops to zero, ramps again once the tip has settled) and
:class:`StaticProbe` (ramp at one point until breakaway, ``kappa_mj = F / F_p``). Each run
reports its inertia number ``I_e = m v^2 / (F_p L_c)``; for the force drives ``v`` is the
equivalent speed ``v_eq = L_c (dF/dt) / F_p`` (the speed at which the tip would cross one
feature in the time the force takes to rise by one preload).

Spring drives and static probes run open loop through :func:`mujoco.rollout.rollout` on
native threads (a batch of starts or parameter sets at once); the force ramp with reset
needs feedback and steps in Python. Every run ends with a recorded :class:`EndReason`,
never with an exception from the engine.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spine_mj.errors import SpineInputError, atomic_output, check_positive
from spine_mj.surfaces import GaussianSurface, GridSurface, HField, Surface, to_hfield

__all__ = [
    "Cone",
    "Detection",
    "EndReason",
    "EngineSettings",
    "Event",
    "Integrator",
    "RampDrive",
    "Rig",
    "RunResult",
    "Scales",
    "SpringDrive",
    "StaticProbe",
    "TipParams",
    "characteristic_length",
    "default_engine",
    "hfield_of",
    "hfield_spacing",
    "inclined_plane",
]

MODEL_PATH = Path(__file__).resolve().parent.parent / "models" / "spine_rig.xml"
DEFAULT_LENGTH_SCALE_M = 0.01
_MAX_TIMESTEP_S = 1e-3
_REST_PENETRATION_FRACTION = 0.005
_MIN_SPACING_PER_TIP_RADIUS = 0.25  # finer hfields exceed MuJoCo's 50 contacts per geom pair
_BATCH_MEMORY_BYTES = 256 * 2**20
_PLACE_CACHE_SIZE = 4096  # placements kept per rig (by start)
_PIPELINE_PIECES = 4  # a batch group is simulated in up to this many pieces


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


def _check_optional(obj, names: Sequence[str], *, allow_zero: bool = False) -> None:
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
        _check_optional(self, ["tip_radius_m"])
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
                "of mu N (PHYSICS.md §5); use the elliptic cone with noslip"
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


def characteristic_length(surface: Surface) -> float:
    """L_c of a surface, in the surface's own units.

    Rule: for a Gaussian sum, the mean of its widths ``(sigma_x + sigma_y) / 2``; for a
    grid, ``2 pi`` times the rms height over the rms slope (the wavelength of a sine with
    the same rms height and slope), clipped to ``[4 dx, domain size]``; a plane (no
    height variation) gives the domain size.
    """
    xmin, xmax, ymin, ymax = surface.bounds
    span = float(min(xmax - xmin, ymax - ymin))
    if isinstance(surface, GaussianSurface):
        return float(np.mean(0.5 * (surface.sigma_x + surface.sigma_y)))
    grid = surface if isinstance(surface, GridSurface) else surface.sample(201)
    h = grid.heights - grid.heights.mean()
    dx, dy = grid.spacing
    gy, gx = np.gradient(grid.heights, dy, dx)
    detrended = h - (
        gx.mean() * (grid.x[None, :] - grid.x.mean()) + gy.mean() * (grid.y[:, None] - grid.y.mean())
    )
    rms_h = float(np.sqrt(np.mean(detrended**2)))
    rms_s = float(np.sqrt(np.mean((gx - gx.mean()) ** 2 + (gy - gy.mean()) ** 2)))
    if rms_s <= 1e-12 or rms_h <= 1e-12 * span:
        return span
    return float(np.clip(2 * math.pi * rms_h / rms_s, 4 * max(dx, dy), span))


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


@dataclass(frozen=True)
class Detection:
    """Thresholds that turn a trajectory into stick/slip states and events.

    None fields are derived from the scales (:meth:`resolve`), with ``v_c = sqrt(F_p L_c / m)``:

    Attributes
    ----------
    slip_speed_m_s : float or None
        Tangential speed above which the tip slips (default ``1e-3 v_c``).
    stick_speed_m_s : float or None
        Tangential speed below which the tip counts as stuck when the breakaway force is
        read (default ``1e-5 v_c``; noslip holds a stuck tip to ~1e-11 m/s).
    breakaway_distance_m : float or None
        Displacement from the start that means breakaway (default ``min(0.1 r_tip, 0.01 L_c)``).
    kappa_cap : float
        Self-lock when the drive force reaches ``kappa_cap * F_p`` while stuck.
    penetration_tol_m : float or None
        Engine trouble above this penetration (default ``min(0.1 r_tip, 0.01 L_c)``).
    domain_margin_m : float or None
        The run ends when the tip centre comes closer than this to the domain's edge
        (default: the tip radius).
    """

    slip_speed_m_s: float | None = None
    stick_speed_m_s: float | None = None
    breakaway_distance_m: float | None = None
    kappa_cap: float = 20.0
    penetration_tol_m: float | None = None
    domain_margin_m: float | None = None

    def __post_init__(self):
        _check_optional(
            self, ["slip_speed_m_s", "stick_speed_m_s", "breakaway_distance_m", "penetration_tol_m"]
        )
        _check_optional(self, ["domain_margin_m"], allow_zero=True)
        object.__setattr__(self, "kappa_cap", check_positive("kappa_cap", self.kappa_cap))

    def resolve(self, scales: Scales) -> Detection:
        v_c = scales.speed_m_s
        small = min(0.1 * scales.tip_radius_m, 0.01 * scales.char_length_m)
        defaults = {
            "slip_speed_m_s": 1e-3 * v_c,
            "stick_speed_m_s": 1e-5 * v_c,
            "breakaway_distance_m": small,
            "penetration_tol_m": small,
            "domain_margin_m": scales.tip_radius_m,
        }
        return dataclasses.replace(self, **{k: v for k, v in defaults.items() if getattr(self, k) is None})


@dataclass(frozen=True)
class SpringDrive:
    """Spring carriage: the carriage moves at ``speed_m_s`` in +x and pulls the tip through a
    spring of stiffness ``stiffness_n_m`` acting in x only.

    ``stiffness_n_m`` None: ``10 F_p / L_c``. ``duration_s`` None: the time the carriage
    needs to cover 1.1 times the distance to the domain's +x edge plus the spring stretch
    at ``(1 + mu_s) F_p``.
    """

    speed_m_s: float
    stiffness_n_m: float | None = None
    duration_s: float | None = None
    settle_time_s: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "speed_m_s", check_positive("speed_m_s", self.speed_m_s))
        _check_optional(self, ["stiffness_n_m", "duration_s"])
        _check_optional(self, ["settle_time_s"], allow_zero=True)


@dataclass(frozen=True)
class RampDrive:
    """Force ramp with reset, the paper's algorithm (§2.2) in dynamics: F rises from 0 at
    ``rate_n_s`` until slip is detected, keeps rising while the tip slides
    ``slide_distance_m`` (horizontal distance from where the slip began; the paper's step
    dl), then drops to 0; the ramp starts again once the tip has settled (stuck for
    ``settle_time_s``).

    ``rate_n_s`` None: ``0.1 F_p / tau`` (``I_e = 0.01``). ``duration_s`` None: 40 ramps to
    ``kappa_cap F_p``, capped at 200 tau. ``slide_distance_m`` None: ``0.01 L_c`` (the
    paper's dl ~ 0.01 sigma); 0 drops the force at the first sign of slip.
    """

    rate_n_s: float | None = None
    duration_s: float | None = None
    settle_time_s: float | None = None
    slide_distance_m: float | None = None

    def __post_init__(self):
        _check_optional(self, ["rate_n_s", "duration_s"])
        _check_optional(self, ["settle_time_s", "slide_distance_m"], allow_zero=True)


@dataclass(frozen=True)
class StaticProbe:
    """Static probe: the tip rests at the start with ``start_force_n`` applied in +x, then
    the force rises at ``rate_n_s`` until breakaway; ``kappa_mj = F_breakaway / F_p``.

    A start force is needed where gravity alone would slide the tip (a slope steeper than
    arctan mu): the tip is held by friction at ``start_force_n``. ``rate_n_s`` None:
    ``0.1 F_p / tau`` (``I_e = 0.01``).
    """

    rate_n_s: float | None = None
    start_force_n: float = 0.0
    settle_time_s: float | None = None

    def __post_init__(self):
        _check_optional(self, ["rate_n_s"])
        _check_optional(self, ["settle_time_s"], allow_zero=True)
        object.__setattr__(
            self, "start_force_n", check_positive("start_force_n", self.start_force_n, allow_zero=True)
        )


Drive = SpringDrive | RampDrive | StaticProbe


@dataclass(frozen=True)
class Event:
    """One event in a run: ``kind`` in {"slip_onset", "slip_stop", "reset"} or an end reason."""

    kind: str
    index: int
    time_s: float


@dataclass(frozen=True, eq=False)
class RunResult:
    """One run. Arrays have ``n`` rows, one per recorded step (the settle phase included).

    Attributes
    ----------
    time_s : (n,)
    position_m, velocity_m_s : (n, 3)
        Tip centre position and velocity, world frame [m], [m/s].
    contact : (n,) bool
        Whether the tip touches the surface.
    normal : (n, 3)
        Unit normal of the deepest contact, pointing out of the surface (NaN without contact).
    contact_point_m : (n, 3)
        Position of the deepest contact (NaN without contact).
    penetration_m : (n,)
        Depth of the deepest contact (>= 0; 0 without contact).
    normal_force_n, tangential_force_n : (n,)
        Net contact force on the tip along the normal and its magnitude in the tangent plane.
    drive_force_n : (n,)
        Force of the drive on the tip in +x [N].
    carriage_x_m : (n,)
        Carriage position (spring drive; NaN otherwise).
    slipping : (n,) bool
        Tangential speed above ``detection.slip_speed_m_s``.
    events : tuple of Event
    end_reason : EndReason
    end_detail : str
    drive_start_index : int
        First row after the settle phase.
    kappa_mj : float
        Static probe: F_breakaway / F_p (NaN unless ``end_reason`` is BREAKAWAY).
    slip_kappas : (k,)
        Drive force / F_p at each slip onset after the settle phase.
    inertia_number, speed_m_s : float
        I_e and the speed (or equivalent speed) it uses.
    start : (x0, y0)
        Start in surface units.
    """

    time_s: np.ndarray
    position_m: np.ndarray
    velocity_m_s: np.ndarray
    contact: np.ndarray
    normal: np.ndarray
    contact_point_m: np.ndarray
    penetration_m: np.ndarray
    normal_force_n: np.ndarray
    tangential_force_n: np.ndarray
    drive_force_n: np.ndarray
    carriage_x_m: np.ndarray
    slipping: np.ndarray
    events: tuple[Event, ...]
    end_reason: EndReason
    end_detail: str
    drive_start_index: int
    kappa_mj: float
    slip_kappas: np.ndarray
    inertia_number: float
    speed_m_s: float
    start: tuple[float, float]
    drive: Drive
    tip: TipParams
    engine: EngineSettings
    scales: Scales
    detection: Detection

    @property
    def n(self) -> int:
        return self.time_s.size

    def table(self):
        """The trajectory as a :class:`pandas.DataFrame` (one row per recorded step)."""
        import pandas as pd

        cols = {"time_s": self.time_s}
        for name in ("position_m", "velocity_m_s", "normal", "contact_point_m"):
            arr = getattr(self, name)
            for k, axis in enumerate("xyz"):
                cols[f"{name.split('_')[0]}_{axis}{name[len(name.split('_')[0]) :]}"] = arr[:, k]
        for name in (
            "contact",
            "penetration_m",
            "normal_force_n",
            "tangential_force_n",
            "drive_force_n",
            "carriage_x_m",
            "slipping",
        ):
            cols[name] = getattr(self, name)
        return pd.DataFrame(cols)

    def summary(self) -> dict:
        """JSON-ready description of the run: parameters, engine settings, outcome."""

        def enc(obj):
            d = dataclasses.asdict(obj)
            return {k: (v.value if isinstance(v, enum.Enum) else v) for k, v in d.items()}

        return {
            "drive": type(self.drive).__name__,
            "drive_params": enc(self.drive),
            "tip": enc(self.tip),
            "engine": self.engine.to_dict(),
            "scales": enc(self.scales),
            "detection": enc(self.detection),
            "start": list(self.start),
            "end_reason": self.end_reason.value,
            "end_detail": self.end_detail,
            "end_time_s": float(self.time_s[-1]) if self.n else 0.0,
            "kappa_mj": None if math.isnan(self.kappa_mj) else self.kappa_mj,
            "slip_kappas": self.slip_kappas.tolist(),
            "inertia_number": self.inertia_number,
            "speed_m_s": self.speed_m_s,
            "n_slip_onsets": sum(e.kind == "slip_onset" for e in self.events),
            "max_penetration_m": float(self.penetration_m.max()) if self.n else 0.0,
        }


def inclined_plane(
    *, slope_deg: float, azimuth_deg: float = 0.0, half_width: float = 0.02, n: int = 41, unit: str = "m"
) -> GridSurface:
    """A plane ``z = tan(slope) (x cos(az) + y sin(az))`` on a square grid.

    ``azimuth_deg = 0`` makes the plane rise in +x (the closed form's theta > 0).
    """
    slope = float(slope_deg)
    if not (math.isfinite(slope) and -89.0 <= slope <= 89.0):
        raise SpineInputError(f"slope_deg must lie in [-89, 89], got {slope_deg!r}")
    half_width = check_positive("half_width", half_width)
    t = math.tan(math.radians(slope))
    az = math.radians(float(azimuth_deg))
    x = np.linspace(-half_width, half_width, int(n))
    h = t * (math.cos(az) * x[None, :] + math.sin(az) * x[:, None])
    return GridSurface(
        heights=h,
        x=x,
        y=x.copy(),
        unit=unit,
        metadata={"generator": "inclined_plane", "slope_deg": slope, "azimuth_deg": float(azimuth_deg)},
    )


# --------------------------------------------------------------------------- the rig


class Rig:
    """The MuJoCo model of one surface and one tip, ready to run drives.

    Parameters
    ----------
    surface : Surface
        Any surface; dimensionless ones are scaled by ``length_scale_m``.
    tip : TipParams
    engine : EngineSettings or None
        None: :func:`default_engine` of the scales.
    length_scale_m : float or None
        Metres per surface unit; None gives 0.01 for ``unit == "1"`` and 1 for ``"m"``.
    char_length_m : float or None
        L_c [m]; None: :func:`characteristic_length` times ``length_scale_m``.

    Raises
    ------
    SpineInputError
        Bad parameters, a surface in another unit, or a surface too coarse for the tip
        (hfield spacing > 2 tip radii: the sphere would see single facets and their kinks).

    Notes
    -----
    Default tip radius: ``surface.metadata["params"]["tip_radius_m"]`` if the surface has
    one (sandpaper), else the larger of one hfield spacing and ``L_c / 100``.
    """

    def __init__(
        self,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        engine: EngineSettings | None = None,
        length_scale_m: float | None = None,
        char_length_m: float | None = None,
    ):
        import mujoco

        if not isinstance(surface, Surface):
            raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
        tip = TipParams() if tip is None else tip
        self.scales = Scales.for_surface(
            surface,
            tip=tip,
            length_scale_m=length_scale_m,
            char_length_m=char_length_m,
            hfield_resolution=engine.hfield_resolution if engine is not None else None,
        )
        resolution = self.scales.hfield_resolution
        if engine is not None and engine.hfield_resolution != resolution:
            engine = dataclasses.replace(engine, hfield_resolution=resolution)
        self.surface = surface
        self.tip = dataclasses.replace(tip, tip_radius_m=self.scales.tip_radius_m)
        self.length_scale_m = length_scale_m = self.scales.length_scale_m
        self.engine = default_engine(self.scales) if engine is None else engine
        self.hfield = hf = hfield_of(surface, resolution)
        self.hfield = hf
        xmin, xmax, ymin, ymax = surface.bounds
        self.bounds_m = tuple(length_scale_m * b for b in (xmin, xmax, ymin, ymax))
        self.spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
        self._configure_spec()
        self.model = self.spec.compile()
        self._ids()

    # ----------------------------------------------------------------- model building

    def _configure_spec(self) -> None:
        import mujoco

        spec, eng, tip, s = self.spec, self.engine, self.tip, self.length_scale_m
        spec.option.timestep = eng.timestep_s
        spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{eng.integrator.name}")
        spec.option.cone = getattr(mujoco.mjtCone, f"mjCONE_{eng.cone.name}")
        spec.option.impratio = eng.impratio
        spec.option.noslip_iterations = eng.noslip_iterations
        spec.option.gravity = [0.0, 0.0, -tip.gravity_m_s2]
        spec.modelname = "spine_rig"
        r = tip.tip_radius_m
        tip_geom = spec.geom("tip")
        tip_geom.size = [r, 0, 0]
        tip_geom.mass = tip.mass_kg
        car = spec.geom("carriage")
        car.size = [r, r, r]
        hf = self.hfield
        rx, ry, elev, base = hf.size
        spec.add_hfield(
            name="surface",
            size=[rx * s, ry * s, elev * s, base * s],
            nrow=hf.nrow,
            ncol=hf.ncol,
            userdata=hf.data.ravel().tolist(),
        )
        geom = spec.worldbody.add_geom(
            name="surface",
            type=mujoco.mjtGeom.mjGEOM_HFIELD,
            hfieldname="surface",
            pos=[p * s for p in hf.pos],
            material="ground",
        )
        for g in (tip_geom, geom):
            g.friction = [tip.mu_s, 0.0, 0.0]
            g.condim = 3
            g.solref = list(eng.solref)
            g.solimp = list(eng.solimp)
        span = max(rx, ry) * s
        spec.visual.map.znear = 1e-4
        spec.stat.extent = 2 * span
        spec.stat.center = [hf.pos[0] * s, hf.pos[1] * s, (hf.pos[2] + elev / 2) * s]

    def _ids(self) -> None:
        import mujoco

        m = self.model
        self.geom_tip = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "tip")
        self.geom_surface = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "surface")
        self.act_spring = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "spring")
        self.act_push = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "push")
        self.act_preload = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "preload")
        adr = {}
        for name in ("tip_pos", "tip_vel", "contact_net", "contact_deepest", "spring_force", "push_force"):
            sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, name)
            adr[name] = int(m.sensor_adr[sid])
        self._sensor_adr = adr

    def set_surface(self, surface: Surface) -> None:
        """Replace the surface (same grid size) and recompile in place (``spec.recompile``)."""
        import mujoco

        hf = hfield_of(surface, self.engine.hfield_resolution)
        if (hf.nrow, hf.ncol) != (self.hfield.nrow, self.hfield.ncol):
            raise SpineInputError(
                f"set_surface needs a {self.hfield.nrow} x {self.hfield.ncol} hfield, "
                f"got {hf.nrow} x {hf.ncol}; build a new Rig instead"
            )
        s = self.length_scale_m
        h = self.spec.hfield("surface")
        h.userdata = hf.data.ravel().tolist()
        h.size = [v * s for v in hf.size]
        self.spec.geom("surface").pos = [p * s for p in hf.pos]
        data = mujoco.MjData(self.model)
        self.model, _ = self.spec.recompile(self.model, data)
        self.surface, self.hfield = surface, hf
        xmin, xmax, ymin, ymax = surface.bounds
        self.bounds_m = tuple(s * b for b in (xmin, xmax, ymin, ymax))
        self._ids()

    def to_xml(self) -> str:
        """A self-contained MJCF of the rig (the hfield inlined as ``elevation``)."""
        return self.spec.to_xml()

    def export_xml(self, path: str | os.PathLike) -> Path:
        """Write :meth:`to_xml` to ``path`` atomically; MuJoCo's viewer opens it directly."""
        path = Path(path)
        with atomic_output(path) as tmp:
            tmp.write_text(self.to_xml())
        return path

    # ----------------------------------------------------------------- placement

    def _model_for(self, drive: Drive | None):
        m = copy.copy(self.model)
        k = self._stiffness(drive) if isinstance(drive, SpringDrive) else 0.0
        m.actuator_gainprm[self.act_spring, 0] = k
        m.actuator_biasprm[self.act_spring, 1] = -k
        return m

    def place(self, x0: float, y0: float) -> np.ndarray:
        """qpos ``(3,)`` [m] with the tip resting on the hfield at ``(x0, y0)`` (surface units).

        The sphere centre is found by a safeguarded Newton search in z on the engine's own
        sphere-hfield distance (to 1e-7 tip radii), then lowered by the soft contact's resting depth
        ``(1 - dmax) (F_p / m) (timeconst dampratio)^2``: it starts at rest and in
        contact, never dropped (a start just above the surface falls for one step).
        """
        import mujoco

        x0, y0 = float(x0), float(y0)
        self._check_start(x0, y0)
        s, r = self.length_scale_m, self.tip.tip_radius_m
        if getattr(self, "_place_model", None) is None or self._place_model[0] is not self.model:
            pm = copy.copy(self.model)
            pm.geom_margin[self.geom_tip] = 0.2 * r  # few contacts, but a gap above the surface
            self._place_model = (self.model, pm, mujoco.MjData(pm), {})
        _, m, d, placed = self._place_model
        if (x0, y0) in placed:  # the search is deterministic: a start seen before is reused
            return placed[(x0, y0)].copy()
        _, _, elev, _ = self.hfield.size

        def probe(z):
            d.qpos[:] = (x0 * s, y0 * s, z)
            mujoco.mj_kinematics(m, d)  # positions and contacts only: no dynamics needed
            mujoco.mj_collision(m, d)
            if not d.ncon:
                return None, 1.0
            k = int(np.argmin(d.contact.dist[: d.ncon]))
            return float(d.contact.dist[k]), abs(float(d.contact.frame[k, 2]))

        hi = (self.hfield.pos[2] + elev) * s + 2 * r
        lo = float(self.surface.height(x0, y0)) * s
        if not (probe(hi)[0] is None and (probe(lo)[0] or 0.0) < 0):
            raise SpineInputError(f"could not place the tip on the surface at ({x0:g}, {y0:g})")
        z = lo + r
        for _ in range(100):  # Newton on the engine's distance, safeguarded by [lo, hi]
            g, nz = probe(z)
            if g is None:
                hi, z = z, 0.5 * (z + lo)
                continue
            if abs(g) < 1e-7 * r:
                break
            if g > 0:
                hi = z
            else:
                lo = z
            z_new = z - g / max(nz, 0.05)
            z = z_new if lo < z_new < hi else 0.5 * (lo + hi)
        else:
            raise SpineInputError(f"could not place the tip on the surface at ({x0:g}, {y0:g})")
        z -= g
        # sink to the soft contact's resting depth (1 - dmax) a_p (timeconst dampratio)^2
        tc, dr = self.engine.solref
        a_p = self.scales.preload_n / self.tip.mass_kg
        z -= (1 - self.engine.solimp[1]) * a_p * (tc * dr) ** 2
        qpos = np.array([x0 * s, y0 * s, z])
        if len(placed) >= _PLACE_CACHE_SIZE:
            placed.pop(next(iter(placed)))
        placed[(x0, y0)] = qpos
        return qpos.copy()

    def _check_start(self, x0: float, y0: float) -> None:
        if not bool(self.surface.contains(x0, y0)):
            raise SpineInputError(
                f"start ({x0:g}, {y0:g}) lies outside the surface bounds {self.surface.bounds}"
            )

    # ----------------------------------------------------------------- drive parameters

    def _stiffness(self, drive: SpringDrive) -> float:
        if drive.stiffness_n_m is not None:
            return drive.stiffness_n_m
        return 10 * self.scales.preload_n / self.scales.char_length_m

    def _rate(self, drive) -> float:
        if drive.rate_n_s is not None:
            return drive.rate_n_s
        return 0.1 * self.scales.preload_n / self.scales.time_s

    def _settle_steps(self, drive) -> int:
        t = drive.settle_time_s
        if t is None:
            t = 200 * self.engine.timestep_s
        return max(1, int(round(t / self.engine.timestep_s)))

    def speed_of(self, drive: Drive) -> float:
        """The drive's speed [m/s]: carriage speed, or ``L_c rate / F_p`` for force drives."""
        if isinstance(drive, SpringDrive):
            return drive.speed_m_s
        return self.scales.char_length_m * self._rate(drive) / self.scales.preload_n

    def inertia_number(self, drive: Drive) -> float:
        """I_e = m v^2 / (F_p L_c) of a drive (equivalent speed for force drives)."""
        return self.scales.inertia_number(self.speed_of(drive))

    # ----------------------------------------------------------------- controls

    def _drive_steps(self, drive: Drive, x0_m: float, detection: Detection) -> int:
        """Steps of the drive phase of an open-loop run starting at ``x0_m`` [m]."""
        dt = self.engine.timestep_s
        if isinstance(drive, SpringDrive):
            duration = drive.duration_s
            if duration is None:
                stretch = (1 + self.tip.mu_s) * self.scales.preload_n / self._stiffness(drive)
                duration = (1.1 * max(self.bounds_m[1] - x0_m, 0.0) + stretch) / drive.speed_m_s
            return max(1, int(math.ceil(duration / dt)))
        if isinstance(drive, StaticProbe):
            cap = detection.kappa_cap * self.scales.preload_n
            rate = self._rate(drive)
            return max(1, int(math.ceil((cap - drive.start_force_n) / rate / dt)) + 2)
        raise SpineInputError(
            f"open-loop controls exist for SpringDrive and StaticProbe, got {type(drive).__name__}"
        )

    def _controls(self, drive: Drive, qpos0: np.ndarray, detection: Detection) -> np.ndarray:
        """Open-loop controls ``(nstep, 6)``: ctrl (spring, push, preload) then mocap xyz."""
        dt = self.engine.timestep_s
        n_settle = self._settle_steps(drive)
        cap = detection.kappa_cap * self.scales.preload_n
        n_drive = self._drive_steps(drive, qpos0[0], detection)
        n = n_settle + n_drive
        ctrl = np.zeros((n, 6))
        ctrl[:, 2] = -self.tip.preload_n
        ctrl[:, 3] = qpos0[0]
        ctrl[:, 4] = qpos0[1]
        ctrl[:, 5] = qpos0[2] + 2 * self.tip.tip_radius_m
        ramp_t = dt * np.arange(1, n_drive + 1)
        if isinstance(drive, SpringDrive):
            ctrl[:, 0] = qpos0[0]
            ctrl[n_settle:, 0] = qpos0[0] + drive.speed_m_s * ramp_t
            ctrl[:, 3] = ctrl[:, 0]
        else:
            ctrl[:, 1] = drive.start_force_n
            ctrl[n_settle:, 1] = np.minimum(
                drive.start_force_n + self._rate(drive) * ramp_t, cap * (1 + 1e-9)
            )
        return ctrl

    # ----------------------------------------------------------------- running

    def run(
        self,
        drive: Drive,
        *,
        start: tuple[float, float],
        detection: Detection | None = None,
        backend: str = "rollout",
        progress: Callable[[float], None] | None = None,
    ) -> RunResult:
        """Run one drive from ``start`` (surface units).

        ``backend`` "rollout" (native) or "python" (a plain ``mj_step`` loop, the reference
        implementation); the force ramp with reset always steps in Python. ``progress``
        receives the fraction done (Python backends only).
        """
        if isinstance(drive, RampDrive):
            return self._run_ramp(drive, start, detection, progress)
        return self.run_batch([drive], [start], detection=detection, backend=backend)[0]

    def run_batch(
        self,
        drives: Drive | Sequence[Drive],
        starts: Sequence[tuple[float, float]],
        *,
        detection: Detection | None = None,
        backend: str = "rollout",
        nthread: int | None = None,
    ) -> list[RunResult]:
        """Run many starts and/or drive parameter sets of this model.

        ``drives`` is one drive for all starts or one per start (SpringDrive or StaticProbe;
        mixed kinds are allowed). Runs go through :func:`mujoco.rollout.rollout` on
        ``nthread`` native threads (default: CPU count), in groups sized to stay within
        256 MiB of output; each run is then cut at its first end event. A group runs in up
        to 4 pieces, pipelined: while the native threads simulate one piece, the calling
        thread analyses the previous one and places the next (``rollout`` releases the GIL);
        the results are those of one run at a time. The arrays of a result are read-only
        views of its group's columns.
        """
        import mujoco
        from mujoco import rollout

        starts = [tuple(float(v) for v in s) for s in starts]
        if isinstance(drives, (SpringDrive, StaticProbe, RampDrive)):
            drives = [drives] * len(starts)
        drives = list(drives)
        if len(drives) != len(starts):
            raise SpineInputError(
                f"drives must be one drive or one per start ({len(starts)}), got {len(drives)}"
            )
        if any(isinstance(d, RampDrive) for d in drives):
            raise SpineInputError("RampDrive needs feedback; use Rig.run for it")
        if backend not in ("rollout", "python"):
            raise SpineInputError(f"backend must be 'rollout' or 'python', got {backend!r}")
        det = (Detection() if detection is None else detection).resolve(self.scales)
        for x0, y0 in starts:
            self._check_start(x0, y0)
        by_stiffness: dict[float, object] = {}
        for d in drives:
            k = self._stiffness(d) if isinstance(d, SpringDrive) else 0.0
            if k not in by_stiffness:
                by_stiffness[k] = self._model_for(d)
        models = [by_stiffness[self._stiffness(d) if isinstance(d, SpringDrive) else 0.0] for d in drives]
        s = self.length_scale_m
        lengths = [
            self._settle_steps(d) + self._drive_steps(d, x0 * s, det) for d, (x0, _) in zip(drives, starts)
        ]
        nstate = mujoco.mj_stateSize(self.model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
        results: list[RunResult | None] = [None] * len(starts)
        # group runs of equal length (rollout needs one nstep per call)
        order = sorted(range(len(starts)), key=lambda i: lengths[i])
        per_row = 8 * (nstate + self.model.nsensordata)
        nthread = os.cpu_count() or 1 if nthread is None else int(nthread)
        batches = []
        i = 0
        while i < len(order):
            nstep = lengths[order[i]]
            group = [order[i]]
            limit = max(1, _BATCH_MEMORY_BYTES // (per_row * nstep))
            while (
                i + len(group) < len(order) and len(group) < limit and lengths[order[i + len(group)]] == nstep
            ):
                group.append(order[i + len(group)])
            i += len(group)
            # pieces of a group pipeline: one piece is simulated while the previous one is
            # analysed (and the next one placed) on the calling thread
            size = max(nthread, -(-len(group) // _PIPELINE_PIECES))
            batches += [group[k : k + size] for k in range(0, len(group), size)]

        def prepare(batch):
            qpos0 = [self.place(*starts[j]) for j in batch]
            ctrls = [self._controls(drives[j], q, det) for j, q in zip(batch, qpos0)]
            init = np.zeros((len(batch), nstate))
            init[:, 1:4] = qpos0
            return batch, ctrls, init, np.stack(ctrls)

        def analyse(batch, ctrls, state, sens, warn):
            for j, res in zip(
                batch,
                self._analyse_group(
                    [drives[j] for j in batch], [starts[j] for j in batch], state, sens, ctrls, det, warn
                ),
            ):
                results[j] = res

        if backend == "python":
            for batch in batches:
                batch, ctrls, init, ctrl = prepare(batch)
                state, sens, warn = _python_rollout([models[j] for j in batch], init, ctrl)
                analyse(batch, ctrls, state, sens, warn)
            return results
        import concurrent.futures as cf

        pool = rollout.Rollout(nthread=nthread)
        datas = [mujoco.MjData(self.model) for _ in range(max(1, nthread))]

        def simulate(batch, init, ctrl):
            return pool.rollout(
                [models[j] for j in batch],
                datas,
                init,
                ctrl,
                control_spec=spec,
                initial_warmstart=np.zeros((len(batch), self.model.nv)),
            )

        try:
            with cf.ThreadPoolExecutor(max_workers=1) as sim_thread:
                running = None
                ready = prepare(batches[0]) if batches else None
                for k in range(len(batches)):
                    batch, ctrls, init, ctrl = ready
                    future = sim_thread.submit(simulate, batch, init, ctrl)
                    if running is not None:
                        analyse(*running)
                    ready = prepare(batches[k + 1]) if k + 1 < len(batches) else None
                    running = (batch, ctrls, *future.result(), [None] * len(batch))
                if running is not None:
                    analyse(*running)
        finally:
            pool.close()
        return results

    # ----------------------------------------------------------------- analysis

    def _columns(self, state: np.ndarray, sens: np.ndarray):
        """Per-step columns of ``N`` steps (``state`` ``(N, nstate)``, ``sens`` ``(N, nsensordata)``).

        Every column is a fresh C-contiguous array: the strided sensor slices are copied
        once, so the arithmetic reads contiguous memory (the row-wise operations, einsum
        and norm included, are those of a plain per-row evaluation: same results).
        """
        a = self._sensor_adr
        cn, cd = a["contact_net"], a["contact_deepest"]
        t = state[:, 0].copy()
        pos = sens[:, a["tip_pos"] : a["tip_pos"] + 3].copy()
        vel = sens[:, a["tip_vel"] : a["tip_vel"] + 3].copy()
        contact = sens[:, cd] > 0
        no_contact = ~contact[:, None]
        force = np.negative(sens[:, cn + 1 : cn + 4])  # the sensor reports the tip's force on the surface
        normal = sens[:, cd + 5 : cd + 8].copy()
        np.negative(normal, out=normal, where=normal[:, 2:3] < 0)  # point out of the surface
        np.copyto(normal, np.nan, where=no_contact)
        point = sens[:, cd + 2 : cd + 5].copy()
        np.copyto(point, np.nan, where=no_contact)
        pen = np.where(contact, np.maximum(-sens[:, cd + 1], 0.0), 0.0)
        nn = np.nan_to_num(normal)
        fn = np.where(contact, np.einsum("ij,ij->i", nn, force), 0.0)
        ft = np.where(contact, _norm3(force - fn[:, None] * nn), 0.0)
        drive_f = sens[:, a["spring_force"]] + sens[:, a["push_force"]]
        vt = vel - np.einsum("ij,ij->i", vel, nn)[:, None] * nn
        return t, pos, vel, contact, normal, point, pen, fn, ft, drive_f, _norm3(vt)

    def _analyse(self, drive, start, state, sens, ctrl, det: Detection, warnings) -> RunResult:
        return self._analyse_group([drive], [start], state[None], sens[None], [ctrl], det, [warnings])[0]

    def _analyse_group(self, drives, starts, state, sens, ctrls, det: Detection, warnings) -> list[RunResult]:
        """:meth:`_analyse` of a group of runs of equal length at once.

        ``state`` ``(g, n, nstate)`` and ``sens`` ``(g, n, nsensordata)``: the per-step
        columns and the event masks are computed for the whole group in one pass (the same
        arithmetic per row as one run at a time); only the events of each run are read
        per run.
        """
        g, n = state.shape[:2]
        dt = self.engine.timestep_s
        fp = self.scales.preload_n
        cols = self._columns(state.reshape(g * n, -1), sens.reshape(g * n, -1))
        t, pos, vel, contact, normal, point, pen, fn, ft, drive_f, vt = (
            c.reshape(g, n, *c.shape[1:]) for c in cols
        )
        slipping = vt > det.slip_speed_m_s
        rows = np.arange(g)

        def firsts(mask):
            """First index of each row's True, or -1."""
            idx = mask.argmax(axis=1)
            return np.where(mask[rows, idx], idx, -1)

        if np.isfinite(state).all() and np.isfinite(sens).all():  # the usual case, one pass
            k_nonfinite = np.full(g, -1)
        else:
            k_nonfinite = firsts(~(np.isfinite(state).all(axis=2) & np.isfinite(sens).all(axis=2)))
        expected = dt * np.arange(1, n + 1)
        k_reset = firsts(np.abs(t - expected) > 0.5 * dt)
        k_deep = firsts(pen > det.penetration_tol_m)
        xmin, xmax, ymin, ymax = self.bounds_m
        mg = det.domain_margin_m
        px, py = pos[:, :, 0], pos[:, :, 1]
        k_out = firsts((px < xmin + mg) | (px > xmax - mg) | (py < ymin + mg) | (py > ymax - mg))
        cap = det.kappa_cap * fp
        k_lock = firsts((drive_f >= cap * (1 - 1e-9)) & ~slipping)
        results = []
        for r in range(g):
            drive = drives[r]
            n_settle = self._settle_steps(drive)
            candidates = []
            if k_nonfinite[r] >= 0:
                candidates.append((int(k_nonfinite[r]), 0, EndReason.ENGINE_TROUBLE, "non-finite state"))
            if k_reset[r] >= 0:
                candidates.append(
                    (
                        int(k_reset[r]),
                        0,
                        EndReason.ENGINE_TROUBLE,
                        "MuJoCo reset the simulation (warning: bad qpos/qvel/qacc)",
                    )
                )
            if warnings[r] is not None:
                k, text = warnings[r]
                if k is not None:
                    candidates.append((k, 0, EndReason.ENGINE_TROUBLE, f"MuJoCo warning: {text}"))
            if k_deep[r] >= 0:
                k = int(k_deep[r])
                candidates.append(
                    (
                        k,
                        1,
                        EndReason.ENGINE_TROUBLE,
                        f"penetration {pen[r, k]:.3g} m > tolerance {det.penetration_tol_m:.3g} m",
                    )
                )
            if k_out[r] >= 0:
                k = int(k_out[r])
                candidates.append(
                    (
                        k,
                        2,
                        EndReason.LEFT_DOMAIN,
                        f"tip at ({pos[r, k, 0]:.4g}, {pos[r, k, 1]:.4g}) m left the domain",
                    )
                )
            if k_lock[r] >= 0:
                candidates.append(
                    (
                        int(k_lock[r]),
                        3,
                        EndReason.SELF_LOCK,
                        f"drive force reached kappa_cap * F_p = {cap:.4g} N without slip",
                    )
                )
            kappa = math.nan
            if isinstance(drive, StaticProbe):
                kappa = self._probe_events(candidates, pos[r], vt[r], drive_f[r], n_settle, det, fp)
            end, reason, detail = n - 1, EndReason.COMPLETED, "drive duration elapsed"
            if candidates:
                end, _, reason, detail = min(candidates, key=lambda c: (c[0], c[1]))
            if reason is not EndReason.BREAKAWAY:
                kappa = math.nan
            sl = slice(0, end + 1)
            events = _slip_events(slipping[r, sl], t[r, sl], n_settle)
            events.append(Event(reason.value, end, float(t[r, end])))
            onsets = [e.index for e in events if e.kind == "slip_onset"]
            carriage = ctrls[r][:, 3].copy() if isinstance(drive, SpringDrive) else np.full(n, np.nan)
            results.append(
                self._result(
                    drive,
                    starts[r],
                    det,
                    t[r],
                    pos[r],
                    vel[r],
                    contact[r],
                    normal[r],
                    point[r],
                    pen[r],
                    fn[r],
                    ft[r],
                    drive_f[r],
                    carriage,
                    slipping[r],
                    sl,
                    events,
                    reason,
                    detail,
                    n_settle,
                    kappa,
                    np.array([drive_f[r, i] / fp for i in onsets]),
                )
            )
        return results

    @staticmethod
    def _probe_events(candidates, pos, vt, drive_f, n_settle, det: Detection, fp: float) -> float:
        """Static probe: append slid/breakaway candidates; returns kappa_mj (NaN if none)."""
        n = pos.shape[0]
        kappa = math.nan

        def first(mask):
            idx = np.flatnonzero(mask)
            return int(idx[0]) if idx.size else None

        p_ref = pos[min(n_settle, n) - 1]
        moved = np.linalg.norm(pos - pos[0], axis=1) > det.breakaway_distance_m
        k_settle = first(moved[:n_settle])
        if k_settle is not None:
            candidates.append(
                (k_settle, 4, EndReason.SLID, "the tip slid during settling at the start force")
            )
        moved = np.linalg.norm(pos - p_ref, axis=1) > det.breakaway_distance_m
        moved[:n_settle] = False
        k = first(moved)
        if k is not None:
            stuck = np.flatnonzero(vt[:k] <= det.stick_speed_m_s)
            j = int(stuck[-1]) if stuck.size else n_settle - 1
            f_break = drive_f[max(j, n_settle - 1)]
            if pos[k, 0] - p_ref[0] <= 0 or j < n_settle:
                candidates.append(
                    (k, 4, EndReason.SLID, f"the tip slid against the drive at F = {f_break:.4g} N")
                )
            else:
                kappa = float(f_break / fp)
                candidates.append(
                    (k, 4, EndReason.BREAKAWAY, f"breakaway at F = {f_break:.4g} N, kappa_mj = {kappa:.4g}")
                )
        return kappa

    def _result(
        self,
        drive,
        start,
        det,
        t,
        pos,
        vel,
        contact,
        normal,
        point,
        pen,
        fn,
        ft,
        drive_f,
        carriage,
        slipping,
        sl,
        events,
        reason,
        detail,
        n_settle,
        kappa,
        slip_kappas,
    ):
        def cut(a):
            out = a[sl]  # a view of the group's column (C-contiguous rows), read-only
            out.flags.writeable = False
            return out

        speed = self.speed_of(drive)
        return RunResult(
            time_s=cut(t),
            position_m=cut(pos),
            velocity_m_s=cut(vel),
            contact=cut(contact),
            normal=cut(normal),
            contact_point_m=cut(point),
            penetration_m=cut(pen),
            normal_force_n=cut(fn),
            tangential_force_n=cut(ft),
            drive_force_n=cut(drive_f),
            carriage_x_m=cut(carriage),
            slipping=cut(slipping),
            events=tuple(events),
            end_reason=reason,
            end_detail=detail,
            drive_start_index=n_settle,
            kappa_mj=kappa,
            slip_kappas=slip_kappas,
            inertia_number=self.scales.inertia_number(speed),
            speed_m_s=speed,
            start=tuple(start),
            drive=drive,
            tip=self.tip,
            engine=self.engine,
            scales=self.scales,
            detection=det,
        )

    # ----------------------------------------------------------------- ramp with reset

    def _run_ramp(self, drive: RampDrive, start, detection, progress) -> RunResult:
        import mujoco

        det = (Detection() if detection is None else detection).resolve(self.scales)
        start = tuple(float(v) for v in start)
        qpos0 = self.place(*start)
        m = self._model_for(drive)
        d = mujoco.MjData(m)
        d.qpos[:] = qpos0
        d.ctrl[self.act_preload] = -self.tip.preload_n
        d.mocap_pos[0] = qpos0 + np.array([0.0, 0.0, 2 * self.tip.tip_radius_m])
        dt = self.engine.timestep_s
        rate = self._rate(drive)
        fp = self.scales.preload_n
        cap = det.kappa_cap * fp
        n_settle = self._settle_steps(drive)
        duration = drive.duration_s
        if duration is None:
            duration = min(40 * cap / rate, 200 * self.scales.time_s)
        nstep = n_settle + int(math.ceil(duration / dt))
        nstate = mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        state = np.empty((nstep, nstate))
        sens = np.empty((nstep, m.nsensordata))
        ctrl_log = np.zeros((nstep, 6))
        a = self._sensor_adr
        slide = 0.01 * self.scales.char_length_m if drive.slide_distance_m is None else drive.slide_distance_m
        force, ramping, stuck_steps, stop = 0.0, True, 0, nstep
        slip_from = None  # (x, y) where the current slip began, while the force still acts
        resets = []
        warn_total = _warning_total(d)
        warn_at = None
        nrm = np.zeros(3)
        for i in range(nstep):
            if i >= n_settle:
                if ramping:
                    force = min(force + rate * dt, cap * (1 + 1e-9))
                d.ctrl[self.act_push] = force if ramping else 0.0
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, state[i], mujoco.mjtState.mjSTATE_FULLPHYSICS)
            sens[i] = d.sensordata
            ctrl_log[i, 1] = d.ctrl[self.act_push]
            if i % 64 == 63 and _warning_total(d) != warn_total:
                warn_at = (i, _warning_text(d))
                stop = i + 1
                break
            if not np.isfinite(state[i]).all():
                stop = i + 1
                break
            vel = sens[i, a["tip_vel"] : a["tip_vel"] + 3]
            if sens[i, a["contact_deepest"]] > 0:
                nrm = sens[i, a["contact_deepest"] + 5 : a["contact_deepest"] + 8]
            vt = float(np.linalg.norm(vel - (vel @ nrm) * nrm))
            if i >= n_settle:
                if ramping and slip_from is None and vt > det.slip_speed_m_s:
                    slip_from = sens[i, a["tip_pos"] : a["tip_pos"] + 2].copy()
                if ramping and slip_from is not None:
                    moved = sens[i, a["tip_pos"] : a["tip_pos"] + 2] - slip_from
                    if math.hypot(moved[0], moved[1]) >= slide:
                        ramping, stuck_steps, slip_from = False, 0, None
                        force = 0.0
                elif not ramping:
                    stuck_steps = stuck_steps + 1 if vt <= det.slip_speed_m_s else 0
                    if stuck_steps >= n_settle:
                        ramping = True
                        resets.append(i)
            if progress is not None and i % 2000 == 0:
                progress(i / nstep)
        state, sens, ctrl_log = state[:stop], sens[:stop], ctrl_log[:stop]
        result = self._analyse(
            drive, start, state, sens, ctrl_log, det, (warn_at if warn_at is not None else (None, ""))
        )
        events = tuple(
            sorted(
                result.events + tuple(Event("reset", i, float(state[i, 0])) for i in resets if i < result.n),
                key=lambda e: (e.index, e.kind == result.end_reason.value),
            )
        )
        return dataclasses.replace(result, events=events)

    # ----------------------------------------------------------------- rendering

    def render_frames(self, result: RunResult, *, fps: float = 30.0, width: int = 640, height: int = 480):
        """Yield RGB frames ``(height, width, 3)`` uint8 of a run (headless, needs a GL backend)."""
        import mujoco

        m = self._model_for(result.drive)
        d = mujoco.MjData(m)
        renderer = mujoco.Renderer(m, height=height, width=width)
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        span = max(self.bounds_m[1] - self.bounds_m[0], self.bounds_m[3] - self.bounds_m[2])
        cam.distance = 0.9 * span
        cam.elevation = -35.0
        cam.azimuth = 120.0
        stride = max(1, int(round(1.0 / (fps * self.engine.timestep_s))))
        try:
            for i in range(0, result.n, stride):
                d.qpos[:] = result.position_m[i]
                if not math.isnan(result.carriage_x_m[i]):
                    d.mocap_pos[0] = (
                        result.carriage_x_m[i],
                        result.position_m[i, 1],
                        result.position_m[i, 2] + 2 * self.tip.tip_radius_m,
                    )
                mujoco.mj_forward(m, d)
                cam.lookat[:] = result.position_m[i]
                renderer.update_scene(d, camera=cam)
                yield renderer.render().copy()
        finally:
            renderer.close()


def _warning_total(d) -> int:
    return int(sum(w.number for w in d.warning))


def _warning_text(d) -> str:
    import mujoco

    names = [n for n in dir(mujoco.mjtWarning) if n.startswith("mjWARN_") and n != "mjWARN_NWARNING"]
    hit = [n for n in names if d.warning[int(getattr(mujoco.mjtWarning, n))].number > 0]
    return ", ".join(h.removeprefix("mjWARN_") for h in hit) or "unknown"


def _python_rollout(models, init, ctrl):
    """Reference for :func:`mujoco.rollout.rollout`: a plain ``mj_step`` loop per run.

    Returns state ``(nbatch, nstep, nstate)``, sensordata ``(nbatch, nstep, nsensordata)``
    and per run ``(first step with a new MuJoCo warning or None, warning names)``.
    """
    import mujoco

    nbatch, nstep, _ = ctrl.shape
    m0 = models[0]
    nstate = mujoco.mj_stateSize(m0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.empty((nbatch, nstep, nstate))
    sens = np.empty((nbatch, nstep, m0.nsensordata))
    warns = []
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    for b, m in enumerate(models):
        d = mujoco.MjData(m)
        mujoco.mj_setState(m, d, init[b], full)
        d.qacc_warmstart[:] = 0
        first_warn = None
        for i in range(nstep):
            d.ctrl[:] = ctrl[b, i, :3]
            d.mocap_pos[0] = ctrl[b, i, 3:6]
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, state[b, i], full)
            sens[b, i] = d.sensordata
            if first_warn is None and _warning_total(d):
                first_warn = (i, _warning_text(d))
        warns.append(first_warn if first_warn is not None else (None, ""))
    return state, sens, warns


def _norm3(v: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(v, axis=1)`` of ``(N, 3)`` rows, bit for bit (numpy sums fewer than 8
    terms in order: ``(x^2 + y^2) + z^2``), without the slow reduction over a short axis."""
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    return np.sqrt(x * x + y * y + z * z)


def _slip_events(slipping: np.ndarray, t: np.ndarray, start: int) -> list[Event]:
    s = slipping.copy()
    s[:start] = False
    change = np.flatnonzero(np.diff(s.astype(np.int8)))
    events = []
    for k in change:
        i = int(k) + 1
        events.append(Event("slip_onset" if s[i] else "slip_stop", i, float(t[i])))
    return events
