"""What a user chooses among by name: the engines (their registry), the drive protocols,
the fill methods of a scan's missing points and the validation plans.

The command line, the sweep configs and the validation read their name lists here, so a
name is written once. Nothing here imports numpy, MuJoCo or the rest of the package: the
command line lists the choices in its help without loading an engine.

An engine is one :class:`Engine` entry in :data:`ENGINES`: its rig class and its settings
factory (named ``"module:attribute"``, imported when a rig is built), the options of
:func:`spine_mj.sim.build_rig` only it reads, the optional extra it needs, and what it can
run (arrays of tips, the static probe). :func:`spine_mj.sim.build_rig` builds a rig of any
registered engine the same way, so a third engine is one module (its rig and its settings)
and one :func:`register_engine` call.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable
from dataclasses import dataclass

from spine_mj import extras
from spine_mj.errors import SpineInputError

__all__ = [
    "ARRAY_DRIVES",
    "COMPARED_ENGINES",
    "DEFAULT_ENGINE",
    "ENGINES",
    "FILL_METHODS",
    "PLAN_NAMES",
    "PROTOCOLS",
    "Engine",
    "check_engine",
    "engine_names",
    "register_engine",
]

#: The drive protocols of a single spine: spring carriage, force ramp with reset, static probe.
PROTOCOLS = ("spring", "ramp", "static")
#: How a measured scan's missing (NaN / masked) points are treated on import
#: (:func:`spine_mj.surface_io.import_topography`, ``--fill`` of ``surface make`` and ``hold``).
FILL_METHODS = ("refuse", "harmonic", "nearest", "mean")
#: An array's carriage drives (``spine-mj array --drive``, a sweep's ``array_drive``).
ARRAY_DRIVES = ("speed", "force")
#: The validation plans, smallest first (their contents: :data:`spine_mj.validate.plans.PLANS`).
PLAN_NAMES = ("smoke", "quick", "full")
DEFAULT_ENGINE = "mujoco"
#: The engines the validation's engines study sets side by side.
COMPARED_ENGINES = ("mujoco", "bullet")


@dataclass(frozen=True)
class Engine:
    """One engine's entry in the registry.

    Attributes
    ----------
    name : str
        The name ``--engine`` and the sweep key ``engine`` take.
    summary : str
        One line for the help: the engine and its contact model.
    rig : str or type
        ``"module:Class"`` of its rig (or the class itself): built as ``Class(surface,
        tip=tip, engine=settings, sized=(scales, hfield))``, offering
        :class:`spine_mj.sim.engine_rig.EngineRig`.
    settings : str or callable
        ``"module:function"`` of its settings factory (or the function itself):
        ``function(scales, *, speed_m_s, stiffness_n_m, **options)`` gives the settings the
        rig runs with.
    options : tuple of str
        The keywords of :func:`spine_mj.sim.build_rig` that the settings factory reads (an
        option another engine reads and this one does not is refused when given).
    extra : str or None
        The optional extra it needs (:data:`spine_mj.extras.EXTRAS`), None for none.
    arrays : bool
        Whether it runs arrays of tips (``spine-mj array``, the sweep's ``array`` analysis).
    static_probe : bool
        Whether it runs the static probe.
    hfield_check : str or callable or None
        ``"module:function"`` refusing a heightfield of ``(nrow, ncol)`` samples the engine
        cannot take (its size limit, its memory), called with the sides the sizing rule
        predicts before any surface is sampled; None for none.
    """

    name: str
    summary: str
    rig: str | type
    settings: str | Callable
    options: tuple[str, ...]
    extra: str | None = None
    arrays: bool = False
    static_probe: bool = True
    hfield_check: str | Callable | None = None

    def rig_class(self):
        """The rig class (imports its module)."""
        return _load(self.rig)

    def settings_factory(self):
        """The settings factory (imports its module)."""
        return _load(self.settings)

    def hfield_limit(self) -> Callable[[int, int], None] | None:
        """The heightfield check (imports its module), or None."""
        return None if self.hfield_check is None else _load(self.hfield_check)


@functools.cache
def _load(path):
    """The object ``"module:name"`` names (imported now, looked up once: a grid's checks ask
    for a case's engine a million times), or ``path`` itself if not a string."""
    if not isinstance(path, str):
        return path
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


#: The registered engines, by name, in the order they were registered.
ENGINES: dict[str, Engine] = {}


def register_engine(engine: Engine) -> Engine:
    """Add ``engine`` to :data:`ENGINES` (its name must be new); returns it."""
    if engine.name in ENGINES:
        raise ValueError(f"engine {engine.name!r} is registered already")
    ENGINES[engine.name] = engine
    return engine


def engine_names() -> tuple[str, ...]:
    """The registered engines' names, in registration order."""
    return tuple(ENGINES)


def check_engine(name: str, what: str = "engine") -> Engine:
    """The entry of engine ``name``, its extra checked.

    Parameters
    ----------
    name : str
        The engine's name.
    what : str
        How a message names the argument (an option, a config key).

    Raises
    ------
    SpineInputError
        An unknown name, or the engine's extra not installed.
    """
    if name not in ENGINES:
        raise SpineInputError(f"{what} must be one of {', '.join(ENGINES)}, got {name!r}")
    engine = ENGINES[name]
    if engine.extra is not None:
        extras.require(engine.extra, f"{what} {name}")
    return engine


register_engine(
    Engine(
        "mujoco",
        "MuJoCo: soft convex contact (the default)",
        rig="spine_mj.sim.rig:Rig",
        settings="spine_mj.sim.step_rule:mujoco_settings",
        options=(
            "timestep_s",
            "timestep_factor",
            "integrator",
            "cone",
            "impratio",
            "noslip_iterations",
            "tolerance",
            "noslip_tolerance",
            "solref_timeconst_s",
            "solref_dampratio",
            "line",
        ),
        arrays=True,
    )
)
register_engine(
    Engine(
        "bullet",
        "Bullet: hard contact, Coulomb friction by sequential impulses (the [bullet] extra)",
        rig="spine_mj.sim.bullet:BulletRig",
        settings="spine_mj.sim.bullet_settings:default_bullet_engine",
        options=("timestep_s",),
        extra="bullet",
        hfield_check="spine_mj.sim.bullet:check_bullet_hfield",
    )
)
