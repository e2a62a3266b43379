"""One rig, two engines: the interface both rigs offer and the one way to build either.

A rig is a surface as a heightfield, a spherical tip under gravity and preload, and the
three drives (spring carriage, force ramp with reset, static probe), given in SI and run
in the problem's engine units (:class:`~spine_mj.sim.scales.EngineUnits`). Two engines
implement it: ``"mujoco"`` (:class:`~spine_mj.sim.Rig`, soft convex contact, the default)
and ``"bullet"`` (:class:`~spine_mj.sim.bullet.BulletRig`, hard contact and Coulomb
friction by sequential impulses; the ``[bullet]`` extra). Both take the same inputs
through :func:`build_engine_rig`, share the scale, drive, detection and step rules, and
return the same :class:`~spine_mj.sim.RunResult` (:class:`EngineRig`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from spine_mj import extras
from spine_mj.errors import SpineInputError
from spine_mj.sim.build import _sized, build_rig, drive_speed_m_s
from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import Drive, spring_stiffness_n_m
from spine_mj.sim.records import TipParams
from spine_mj.sim.results import RunResult
from spine_mj.sim.scales import EngineUnits, Scales
from spine_mj.surfaces import Surface

__all__ = ["DEFAULT_ENGINE", "ENGINES", "EngineRig", "build_engine_rig", "check_engine_name"]

#: The engines, by the names the CLI (``--engine``) and sweep configs (``engine``) use.
ENGINES = ("mujoco", "bullet")
DEFAULT_ENGINE = "mujoco"
#: Options of :func:`spine_mj.sim.build_rig` that only MuJoCo reads.
MUJOCO_ONLY = (
    "integrator",
    "cone",
    "impratio",
    "noslip_iterations",
    "tolerance",
    "noslip_tolerance",
    "solref_timeconst_s",
    "solref_dampratio",
    "timestep_factor",
)


class EngineRig(Protocol):
    """What a rig of either engine offers (SI in, SI out; starts in surface units).

    Attributes
    ----------
    surface : Surface
        The surface the rig was built on.
    scales : Scales
        Its scales (``L_c``, ``l_s``, ``F_p``, the tip radius, the hfield spacing).
    tip : TipParams
        The tip, its radius sized by the scales.
    units : EngineUnits
        The units the engine works in.
    length_scale_m : float
        Metres per surface unit.
    """

    surface: Surface
    scales: Scales
    tip: TipParams
    units: EngineUnits
    length_scale_m: float

    def run(
        self,
        drive: Drive,
        *,
        start: tuple[float, float],
        detection: Detection | None = None,
        progress: Callable[[float], None] | None = None,
    ) -> RunResult: ...

    def run_batch(
        self,
        drives: Drive | Sequence[Drive],
        starts: Sequence[tuple[float, float]],
        *,
        detection: Detection | None = None,
    ) -> list[RunResult]: ...

    def check_drive(self, drive: Drive) -> None: ...


def check_engine_name(engine: str, what: str = "engine") -> str:
    """``engine`` if it is one of :data:`ENGINES`; for ``"bullet"`` the extra must be installed.

    Parameters
    ----------
    engine : str
        The engine's name.
    what : str
        How the message names the argument (an option, a config key).

    Returns
    -------
    str
        ``engine``.
    """
    if engine not in ENGINES:
        raise SpineInputError(f"{what} must be one of {', '.join(ENGINES)}, got {engine!r}")
    if engine == "bullet":
        extras.require("bullet", f"{what} bullet")
    return engine


def build_engine_rig(surface: Surface, *, engine: str = DEFAULT_ENGINE, **options) -> EngineRig:
    """The rig of ``surface`` in ``engine`` (``"mujoco"`` or ``"bullet"``).

    Parameters
    ----------
    surface : Surface
        The surface, as for :func:`spine_mj.sim.build_rig`.
    engine : {"mujoco", "bullet"}
        The engine that runs the rig.
    **options
        :func:`spine_mj.sim.build_rig`'s keywords (same meaning, same rules); MuJoCo's own
        solver options (:data:`MUJOCO_ONLY`) are refused for Bullet when given, a
        ``timestep_s`` sets Bullet's recorded step.

    Returns
    -------
    EngineRig
        A :class:`~spine_mj.sim.Rig` for MuJoCo, a ``BulletRig`` for Bullet.

    Raises
    ------
    SpineInputError
        An unknown engine, the Bullet extra missing, a MuJoCo-only option for Bullet, or
        any input :func:`~spine_mj.sim.build_rig` refuses.
    """
    check_engine_name(engine)
    if engine == "mujoco":
        return build_rig(surface, **options)
    given = [k for k in MUJOCO_ONLY if options.get(k) is not None]
    if given:
        raise SpineInputError(f"{', '.join(given)}: MuJoCo's solver options, not read by engine bullet")
    from spine_mj.sim.bullet import BulletRig, default_bullet_engine

    tip = TipParams(
        tip_radius_m=options.get("tip_radius_m"),
        mu_s=options["mu"],
        **{k: options[k] for k in ("mass_kg", "preload_n", "gravity_m_s2") if options.get(k) is not None},
    )
    tip, scales, hfield = _sized(
        surface,
        tip,
        options.get("length_scale_m"),
        options.get("hfield_resolution"),
        options.get("hfield_refinement", 1),
    )
    speed = None
    if options.get("driven", True):
        speed = drive_speed_m_s(
            scales, ie=options.get("ie"), speed_m_s=options.get("speed_m_s"), rate_n_s=options.get("rate_n_s")
        )
    overrides = {"timestep_s": options["timestep_s"]} if options.get("timestep_s") is not None else {}
    spring = spring_stiffness_n_m(
        scales, stiffness_number=options.get("stiffness_number"), stiffness_n_m=options.get("stiffness_n_m")
    )
    settings = default_bullet_engine(scales, speed_m_s=speed, stiffness_n_m=spring, **overrides)
    return BulletRig(surface, tip=tip, engine=settings, sized=(scales, hfield))
