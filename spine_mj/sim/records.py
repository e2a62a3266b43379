"""The rig's parameter records and enums, frozen and validated on construction.

:class:`TipParams` (the spine tip), :class:`EngineSettings` (MuJoCo settings, recorded with
every run; the rule that derives them is :func:`~spine_mj.sim.step_rule.default_engine`),
the enums they use (:class:`Cone`, :class:`Integrator`) and :class:`EndReason`, why a run
ended. Nothing here needs MuJoCo.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from spine_mj.errors import SpineInputError, check_positive

#: Physical range of masses [kg] (outside it the model means nothing).
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
    """MuJoCo settings, recorded with every run (the rule: :func:`~spine_mj.sim.step_rule.default_engine`).

    Attributes
    ----------
    timestep_s : float
        Time step [s].
    integrator, cone : Integrator, Cone
    impratio : float
        Ratio of frictional to normal constraint impedance (>= 1 sensible).
    noslip_iterations : int
        Noslip solver passes (0 switches it off; then friction creeps).
    tolerance, noslip_tolerance : float
        MuJoCo's early-termination thresholds of the constraint solver and of the noslip
        solver (MuJoCo's defaults, 1e-8 and 1e-6; tightened to check that a result does not
        depend on them, :mod:`spine_mj.validate.convergence`).
    solref : (timeconst_s, dampratio)
        Contact reference; ``timeconst_s >= 2 timestep_s`` for stability.
    solimp : (dmin, dmax, width_m, midpoint, power)
        Contact impedance.
    line : bool
        Hold the tip on its start line ``y = y0`` (a rail across y: the run of a narrow strip
        or long track whose y slopes would carry the tip off it). The tip's y joint is damped
        at :data:`~spine_mj.sim.model.RAIL_DAMPING` in engine units, treated implicitly (not
        with ``rk4``), so it creeps at most ``|F_y| / F_p`` over that many L_c per tau.

    The hfield's resolution is the rig's geometry, not an engine setting: it lives in
    :class:`Scales` (``hfield_resolution``).
    """

    timestep_s: float
    integrator: Integrator = Integrator.IMPLICITFAST
    cone: Cone = Cone.ELLIPTIC
    impratio: float = 1.0
    noslip_iterations: int = 3
    tolerance: float = 1e-8
    noslip_tolerance: float = 1e-6
    solref: tuple[float, float] = (1e-3, 1.0)
    solimp: tuple[float, float, float, float, float] = (0.99, 0.99, 1e-3, 0.5, 2.0)
    line: bool = False

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
        for name in ("tolerance", "noslip_tolerance"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
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
        if not isinstance(self.line, bool):
            raise SpineInputError(f"line must be true or false, got {self.line!r}")
        if self.line and self.integrator is Integrator.RK4:
            raise SpineInputError(
                "line holds the tip by a damper only an implicit integrator steps (euler, implicitfast, "
                "implicit), got integrator rk4"
            )

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["integrator"], d["cone"] = self.integrator.value, self.cone.value
        return d
