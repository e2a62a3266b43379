"""The engine's step rule: MuJoCo settings derived from the problem's scales.

:func:`default_engine` gives the time step and contact of a rig from its
:class:`~spine_mj.sim.scales.Scales` (the contact's resting depth, impacts at the drive's
speed or the surface's fall, and the drive spring's ``omega dt``; rule in
:mod:`spine_mj.sim`'s docstring); :func:`check_engine_for`, :func:`rest_depth_m` and
:func:`penetration_tolerance_m` hold a user's settings to the same bounds. Nothing here
needs MuJoCo.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.records import Cone, EngineSettings, Integrator
from spine_mj.sim.scales import Scales, check_inertia_number

_REST_PENETRATION_FRACTION = 0.005
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
#: The contact's damping ratio in the rule's ``solref = (2 dt, 1)``: critically damped.
SOLREF_DAMPRATIO = 1.0


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
    ``sqrt(2 a_p scales.fall_height_m)`` (:func:`~spine_mj.sim.scales.fall_height`: falls off grit flanks and
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
        Fields of :class:`~spine_mj.sim.records.EngineSettings` to replace.

    Returns
    -------
    EngineSettings
    """
    dt = rule_timestep_s(scales, speed_m_s=speed_m_s, stiffness_n_m=stiffness_n_m)
    _check_rule_step(dt, speed_m_s, given_step="timestep_s" in overrides)
    return _at_step(scales, dt, overrides)


def rule_timestep_s(
    scales: Scales, *, speed_m_s: float | None = None, stiffness_n_m: float | None = None
) -> float:
    """The rule's time step [s] of :func:`default_engine` (the contact's, impacts at
    ``speed_m_s`` and the spring of ``stiffness_n_m`` bounding it): every setting of the
    rule follows from it, so the settings of a grid's million drives are made once per
    step (:func:`mujoco_settings`). 0 where impacts would need a step below the rule's
    two digits."""
    dt_contact = _contact_step_tau(scales, speed_m_s)  # engine units
    if stiffness_n_m is None:
        stiffness_n_m = scales.stiffness_for(DEFAULT_STIFFNESS_NUMBER)
    omega_tau = math.sqrt(check_positive("stiffness_n_m", stiffness_n_m) / scales.mass_kg) * scales.time_s
    return min(dt_contact, _two_digits_down(SPRING_OMEGA_DT / omega_tau)) * scales.time_s


def _check_rule_step(dt: float, speed_m_s: float | None, *, given_step: bool) -> None:
    if not dt > 0 and not given_step:
        raise SpineInputError(
            f"impacts at drive speed {speed_m_s!r} m/s (or a fall down the surface) would need a time "
            f"step of {dt:.3g} s: lower the speed (I_e)"
        )


def _at_step(scales: Scales, dt: float, overrides: dict) -> EngineSettings:
    """:func:`default_engine`'s settings at the rule's step ``dt`` [s] with ``overrides``."""
    base = {
        "timestep_s": dt,
        "solref": (2 * dt, SOLREF_DAMPRATIO),
        "solimp": (0.99, 0.99, 0.01 * scales.tip_radius_m, 0.5, 2.0),
    }
    if "timestep_s" in overrides and "solref" not in overrides:
        base["solref"] = (2 * float(overrides["timestep_s"]), SOLREF_DAMPRATIO)
    base.update(overrides)
    return _settings(base)


def _settings(fields: dict) -> EngineSettings:
    """``EngineSettings(**fields)``, made (and validated) once per distinct ``fields``: the
    checks of a grid plan a million cases whose steps, rounded by the rule, take a few
    values (frozen: one record serves them all)."""
    key = tuple((k, type(v), v) for k, v in fields.items())  # the type: True is no 1
    try:
        return _cached_settings(key)
    except TypeError:  # an unhashable value (a list): made afresh
        return EngineSettings(**fields)


@functools.lru_cache(maxsize=1024)
def _cached_settings(key: tuple) -> EngineSettings:
    return EngineSettings(**{k: v for k, _, v in key})


@dataclass(frozen=True)
class EngineOverrides:
    """A user's replacements for the step rule's engine settings (:func:`default_engine`):
    what :func:`~spine_mj.sim.build_rig` takes besides the problem (``--timestep``,
    ``--noslip``, ``--impratio``, a sweep's engine keys). None keeps the rule's value.

    Attributes
    ----------
    timestep_s : float or None
        Time step [s] (the contact's time constant then follows it, ``2 timestep_s``).
    integrator, cone : str, Integrator, Cone or None
        MuJoCo's integrator and friction cone.
    impratio : float or None
        Frictional to normal constraint impedance.
    noslip_iterations : int or None
        Noslip solver passes.
    tolerance, noslip_tolerance : float or None
        MuJoCo's solver and noslip tolerances.
    solref_timeconst_s, solref_dampratio : float or None
        The contact's time constant [s] and damping ratio, each replacing its half of the
        rule's ``solref`` (the other half stays the rule's).
    timestep_factor : float or None
        The rule's step times this, the contact's time constant kept at the rule's: only
        the step changes (solution verification, :mod:`spine_mj.validate.convergence`);
        not with ``timestep_s``.
    line : bool or None
        Hold the tip on its start line (:class:`~spine_mj.sim.records.EngineSettings`).
    """

    timestep_s: float | None = None
    integrator: str | Integrator | None = None
    cone: str | Cone | None = None
    impratio: float | None = None
    noslip_iterations: int | None = None
    tolerance: float | None = None
    noslip_tolerance: float | None = None
    solref_timeconst_s: float | None = None
    solref_dampratio: float | None = None
    timestep_factor: float | None = None
    line: bool | None = None

    def engine(
        self, scales: Scales, *, speed_m_s: float | None = None, stiffness_n_m: float | None = None
    ) -> EngineSettings:
        """:func:`default_engine` for a drive of ``speed_m_s`` and spring ``stiffness_n_m``
        with these overrides.

        Parameters
        ----------
        scales : Scales
            The rig's scales.
        speed_m_s : float, optional
            The drive's speed [m/s] (None: an undriven rig, only the surface's falls bound
            the step).
        stiffness_n_m : float, optional
            The drive spring's stiffness [N/m] (None: the default spring).

        Returns
        -------
        EngineSettings
        """
        dt = rule_timestep_s(scales, speed_m_s=speed_m_s, stiffness_n_m=stiffness_n_m)
        _check_rule_step(dt, speed_m_s, given_step=self.timestep_s is not None)
        return self.at_step(scales, dt)

    def at_step(self, scales: Scales, dt: float) -> EngineSettings:
        """:meth:`engine` where the rule's step is ``dt`` [s] (:func:`rule_timestep_s`)."""
        given = {k: v for k in _OVERRIDES if (v := getattr(self, k)) is not None}  # asdict deep-copies
        timeconst_s, dampratio = given.pop("solref_timeconst_s", None), given.pop("solref_dampratio", None)
        factor = given.pop("timestep_factor", None)
        if factor is not None:
            if "timestep_s" in given:
                raise SpineInputError(
                    f"timestep_s and timestep_factor: give one of them, got {given['timestep_s']!r} "
                    f"and {factor!r}"
                )
            rule = _at_step(scales, dt, given)
            given["timestep_s"] = rule.timestep_s * check_positive("timestep_factor", factor)
            given["solref"] = rule.solref
        rule = _at_step(scales, dt, given)
        if timeconst_s is None and dampratio is None:
            return rule
        solref = (
            rule.solref[0] if timeconst_s is None else timeconst_s,
            rule.solref[1] if dampratio is None else dampratio,
        )
        # _at_step with ``solref=solref`` too: a given solref replaces the rule's as is
        return _settings({**{k: getattr(rule, k) for k in _SETTINGS}, "solref": solref})


_OVERRIDES = tuple(f.name for f in dataclasses.fields(EngineOverrides))
_SETTINGS = tuple(f.name for f in dataclasses.fields(EngineSettings))


def mujoco_settings(
    scales: Scales, *, speed_m_s: float | None = None, stiffness_n_m: float | None = None, **options
) -> EngineSettings:
    """MuJoCo's settings factory in the engine registry (:data:`spine_mj.choices.ENGINES`):
    :func:`default_engine` with ``options``, the fields of :class:`EngineOverrides`, checked
    against the scales (:func:`check_engine_for`)."""
    dt = rule_timestep_s(scales, speed_m_s=speed_m_s, stiffness_n_m=stiffness_n_m)
    _check_rule_step(dt, speed_m_s, given_step=options.get("timestep_s") is not None)
    key = (id(scales), dt, *((k, type(v), v) for k, v in options.items()))  # the type: True is no 1
    try:
        hit = _AT_STEP.get(key)
    except TypeError:  # an unhashable option (a list): made afresh
        return _checked_at_step(EngineOverrides(**options), scales, dt)
    if hit is None:
        if len(_AT_STEP) >= 1024:
            _AT_STEP.clear()
        hit = _AT_STEP[key] = (scales, _checked_at_step(EngineOverrides(**options), scales, dt))  # held
    return hit[1]


#: :func:`mujoco_settings` by the id of the scales (held with the settings, so the id stays
#: theirs), the rule's step and the options: the rule rounds a grid's million drives to a
#: few steps, each made and checked once.
_AT_STEP: dict = {}


def _checked_at_step(overrides: EngineOverrides, scales: Scales, dt: float) -> EngineSettings:
    settings = overrides.at_step(scales, dt)
    check_engine_for(settings, scales)
    return settings


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


def check_drive_speed(scales: Scales, speed_m_s: float) -> float:
    """``speed_m_s`` if its inertia number is within :data:`~spine_mj.sim.scales.MAX_INERTIA_NUMBER` (a speed,
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
