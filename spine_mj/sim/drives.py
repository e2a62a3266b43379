"""The three drives and the rules that turn a drive into numbers on a rig.

:class:`SpringDrive`, :class:`RampDrive` and :class:`StaticProbe` are frozen parameter
records (docs/physics.md §4); None fields are derived from the problem's :class:`Scales` and
the engine's time step by the functions below (spring stiffness, force rate, settle steps,
the drive's speed), so a drive means the same wherever it is run.
"""

from __future__ import annotations

from dataclasses import dataclass

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.records import check_optional
from spine_mj.sim.scales import Scales
from spine_mj.sim.step_rule import DEFAULT_STIFFNESS_NUMBER


@dataclass(frozen=True)
class SpringDrive:
    """Spring carriage: the carriage moves at ``speed_m_s`` in +x and pulls the tip through a
    spring of stiffness ``stiffness_n_m`` acting in x only.

    ``stiffness_n_m`` None: :data:`DEFAULT_STIFFNESS_NUMBER` ``F_p / l_s``. ``duration_s``
    None: the time the carriage needs to cover 1.1 times the distance to the domain's +x
    edge plus the spring stretch at ``(1 + mu_s) F_p``.

    ``fast_forward``: while the tip sticks on one contact normal (noslip on), the carriage
    advances quickly until the spring force is ``1 - fast_forward_margin`` of the breakaway
    force predicted from that normal, then at ``speed_m_s`` again through breakaway
    (:mod:`spine_mj.sim.rollout`, the rule of :mod:`spine_mj.sim.fastforward`); a tip that
    moves during the climb goes on from before it on the plain controls. ``duration_s`` and
    the result's ``time_s`` count physical time (the carriage's), not engine steps. Only
    where a stick phase can outlast a climb (a preload is many steps of the spring's force
    increment ``k V dt``: soft springs, slow drives; ``rollout.SPRING_MIN_CLIMB_STEPS``), on
    the CPU backends.

    ``start_force_n``: a constant force in +x added to the spring's from the settle on (the
    push actuator), as if the spring started stretched by ``start_force_n / k``: a soft
    spring's climb to the first breakaway can be longer than any run (on the ``abbm``
    preset at K 10, 1600 units of carriage), and this starts the run just below it.

    Attributes
    ----------
    speed_m_s : float
        Carriage speed V [m/s] (``I_e = m V^2 / (F_p L_c)``).
    stiffness_n_m : float or None
        Spring stiffness k [N/m] (``K = k l_s / F_p``).
    duration_s, settle_time_s : float or None
        Run time after settling [s], and the settle phase before the carriage moves [s].
    fast_forward : bool
    fast_forward_margin : float
        Fraction below the predicted breakaway where the fast climb stops.
    start_force_n : float
        The constant force [N] >= 0 added to the spring's.
    """

    speed_m_s: float
    stiffness_n_m: float | None = None
    duration_s: float | None = None
    settle_time_s: float | None = None
    fast_forward: bool = True
    fast_forward_margin: float = 0.03
    start_force_n: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "speed_m_s", check_positive("speed_m_s", self.speed_m_s))
        object.__setattr__(
            self, "start_force_n", check_positive("start_force_n", self.start_force_n, allow_zero=True)
        )
        check_optional(self, ["stiffness_n_m", "duration_s"])
        check_optional(self, ["settle_time_s"], allow_zero=True)
        _check_margin(self)


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

    ``fast_forward``: while the tip sticks (noslip on), the force climbs quickly to
    ``1 - fast_forward_margin`` of the breakaway force predicted from the contact normal,
    then at ``rate_n_s`` through breakaway (:mod:`spine_mj.sim.ramp`; ``duration_s`` counts
    engine time). ``stop_early``: the run stops stepping at its first end event (left the
    domain, self-lock, engine trouble) instead of running out its duration.

    Attributes
    ----------
    rate_n_s : float or None
        Force rate [N/s].
    duration_s, settle_time_s : float or None
        Run time [s], and how long the tip must stay stuck before a new ramp [s].
    slide_distance_m : float or None
        Slip [m] after which the force drops.
    fast_forward : bool
    fast_forward_margin : float
        Fraction below the predicted breakaway where the fast climb stops.
    stop_early : bool
    """

    rate_n_s: float | None = None
    duration_s: float | None = None
    settle_time_s: float | None = None
    slide_distance_m: float | None = None
    fast_forward: bool = True
    fast_forward_margin: float = 0.03
    stop_early: bool = True

    def __post_init__(self):
        check_optional(self, ["rate_n_s", "duration_s"])
        check_optional(self, ["settle_time_s", "slide_distance_m"], allow_zero=True)
        _check_margin(self)


@dataclass(frozen=True)
class StaticProbe:
    """Static probe: the tip rests at the start with ``start_force_n`` applied in +x, then
    the force rises at ``rate_n_s`` until breakaway; ``kappa_mj = F_breakaway / F_p``.

    A start force is needed where gravity alone would slide the tip (a slope steeper than
    arctan mu): the tip is held by friction at ``start_force_n``. ``rate_n_s`` None:
    ``0.1 F_p / tau`` (``I_e = 0.01``).

    ``fast_forward``: when the tip has settled stuck on one contact normal (noslip on), the
    force climbs quickly from ``start_force_n`` to ``1 - fast_forward_margin`` of the
    breakaway force predicted from that normal, then at ``rate_n_s`` through breakaway
    (:mod:`spine_mj.sim.fastforward`, the rule the ramp uses); a tip that moves during the
    climb is run again from the settled state at the nominal rate.

    Attributes
    ----------
    rate_n_s : float or None
        Force rate [N/s].
    start_force_n : float
        Force [N] applied from the start, >= 0.
    settle_time_s : float or None
        Settle phase before the force rises [s].
    fast_forward : bool
    fast_forward_margin : float
        Fraction below the predicted breakaway where the fast climb stops.
    """

    rate_n_s: float | None = None
    start_force_n: float = 0.0
    settle_time_s: float | None = None
    fast_forward: bool = True
    fast_forward_margin: float = 0.03

    def __post_init__(self):
        check_optional(self, ["rate_n_s"])
        check_optional(self, ["settle_time_s"], allow_zero=True)
        object.__setattr__(
            self, "start_force_n", check_positive("start_force_n", self.start_force_n, allow_zero=True)
        )
        _check_margin(self)


Drive = SpringDrive | RampDrive | StaticProbe


def _check_margin(drive: Drive) -> None:
    """``fast_forward_margin`` must lie in (0, 1): the fast climb stops that fraction below
    the predicted breakaway force."""
    m = check_positive("fast_forward_margin", drive.fast_forward_margin)
    if m >= 1:
        raise SpineInputError(f"fast_forward_margin must be < 1, got {m!r}")
    object.__setattr__(drive, "fast_forward_margin", m)


def stiffness_n_m(drive: SpringDrive, scales: Scales) -> float:
    """The spring's stiffness [N/m]: the drive's own, else K = :data:`DEFAULT_STIFFNESS_NUMBER`
    on the surface's slope length (``K F_p / l_s``)."""
    return spring_stiffness_n_m(scales, stiffness_n_m=drive.stiffness_n_m)


def spring_stiffness_n_m(
    scales: Scales, *, stiffness_number: float | None = None, stiffness_n_m: float | None = None
) -> float:
    """A spring's stiffness [N/m] from ``stiffness_n_m``, else the stiffness number
    ``stiffness_number`` (``k = K F_p / l_s``), else :data:`DEFAULT_STIFFNESS_NUMBER`."""
    if stiffness_n_m is not None:
        return check_positive("stiffness_n_m", stiffness_n_m)
    k_number = DEFAULT_STIFFNESS_NUMBER if stiffness_number is None else stiffness_number
    return scales.stiffness_for(check_positive("K", k_number))


def rate_n_s(drive: RampDrive | StaticProbe, scales: Scales) -> float:
    """The force rate [N/s]: the drive's own, else ``0.1 F_p / tau`` (``I_e = 0.01``)."""
    if drive.rate_n_s is not None:
        return drive.rate_n_s
    return 0.1 * scales.preload_n / scales.time_s


def settle_steps(drive: Drive, timestep_s: float) -> int:
    """Steps of the settle phase before the drive starts (default 200 steps)."""
    t = drive.settle_time_s
    if t is None:
        t = 200 * timestep_s
    return max(1, int(round(t / timestep_s)))


def speed_m_s(drive: Drive, scales: Scales) -> float:
    """The drive's speed [m/s]: carriage speed, or ``L_c rate / F_p`` for force drives."""
    if isinstance(drive, SpringDrive):
        return drive.speed_m_s
    return scales.equivalent_speed(rate_n_s(drive, scales))
