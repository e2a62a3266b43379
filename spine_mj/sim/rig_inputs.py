"""What a rig is built from: :class:`RigInputs`, the one record of a rig's inputs.

``spine-mj simulate``, ``sim export`` and ``view``, the sweep's ``engine`` analysis, the
validation and the benchmarks build their rigs from the same list of inputs: a friction
coefficient, an engine and its options, a tip, a length scale and an hfield, and the pace
and spring of the drive the engine's step must resolve. That list is written here once, as
the fields of a frozen dataclass checked once when it is made;
:func:`~spine_mj.sim.build.build_rig`, :func:`~spine_mj.sim.build.plan_rig` and
:func:`~spine_mj.sim.run_folder.simulate_to` take it, and a sweep case's rig is cached by it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from spine_mj.choices import DEFAULT_ENGINE, check_engine
from spine_mj.errors import SpineInputError
from spine_mj.sim.records import TipParams
from spine_mj.sim.rig_hfield import check_hfield_refinement, check_hfield_resolution

__all__ = ["RigInputs", "at_most_one"]


def at_most_one(**given) -> None:
    """Refuse two ways of giving one quantity (a pace, a stiffness): neither silently wins."""
    named = {k: v for k, v in given.items() if v is not None}
    if len(named) > 1:
        raise SpineInputError(
            f"give at most one of {', '.join(given)}, got "
            + ", ".join(f"{k}={v!r}" for k, v in named.items())
        )


@dataclass(frozen=True)
class RigInputs:
    """The inputs of one rig, checked once here: an unknown engine or missing extra, an
    engine option the engine does not read, two paces or two stiffnesses, an hfield
    resolution or refinement that is no whole count, and a tip out of range
    (:class:`TipParams`) are refused, named, when the record is made. None leaves a
    value to its rule. Hashable: equal inputs build equal rigs.

    Attributes
    ----------
    mu : float
        The tip's static friction coefficient mu_s (a command's, from
        :func:`spine_mj.presets.resolve_mu`).
    engine : str
        A registered engine (:data:`spine_mj.choices.ENGINES`).
    tip_radius_m : float or None
        Tip radius [m]; None: the rig's default tip (:meth:`Scales.with_hfield`). A user's
        ``tip_radius`` (the surface's length unit) becomes this by
        :func:`~spine_mj.sim.scales.engine_tip_radius_m`.
    mass_kg, preload_n, gravity_m_s2 : float or None
        The tip's moving mass [kg], extra preload [N] and gravity [m/s^2] (None: the
        defaults of :class:`TipParams`).
    length_scale_m : float or None
        Metres per surface unit (None: 0.01 for dimensionless surfaces, else the unit's).
    hfield_resolution : int or None
        An analytic surface's hfield samples a side (a grid keeps its own).
    hfield_refinement : int
        The hfield refined so many times, the default tip radius kept.
    ie, speed_m_s, rate_n_s : float or None
        The drive's pace, at most one: an inertia number, a speed [m/s] or a force rate
        [N/s] (none: ``I_e = DEFAULT_INERTIA_NUMBER``). Its speed bounds the engine step for
        impacts.
    stiffness_number, stiffness_n_m : float or None
        The drive spring's stiffness, at most one: ``K = k l_s / F_p`` or [N/m] (none: K =
        30). It bounds the engine step: a rig runs springs up to it.
    driven : bool
        False for a model no drive of ours runs (``sim export``, the viewer: the user's
        sliders drive it): then only the surface's falls bound the step.
    engine_options : tuple of (str, value) pairs
        The engine's own options (its registry entry's ``options``: MuJoCo's are the fields
        of :class:`~spine_mj.sim.step_rule.EngineOverrides`, Bullet reads ``timestep_s``);
        a mapping is accepted, and options of None (the engine's rule) are dropped.
    """

    mu: float
    engine: str = DEFAULT_ENGINE
    tip_radius_m: float | None = None
    mass_kg: float | None = None
    preload_n: float | None = None
    gravity_m_s2: float | None = None
    length_scale_m: float | None = None
    hfield_resolution: int | None = None
    hfield_refinement: int = 1
    ie: float | None = None
    speed_m_s: float | None = None
    rate_n_s: float | None = None
    stiffness_number: float | None = None
    stiffness_n_m: float | None = None
    driven: bool = True
    engine_options: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self):
        options = self.engine_options
        options = options.items() if isinstance(options, Mapping) else options
        object.__setattr__(self, "engine_options", tuple(sorted((k, v) for k, v in options if v is not None)))
        entry = check_engine(self.engine)
        unread = [k for k, _ in self.engine_options if k not in entry.options]
        if unread:
            raise SpineInputError(
                f"{', '.join(unread)}: not read by engine {self.engine} "
                f"(its options: {', '.join(entry.options)})"
            )
        object.__setattr__(self, "hfield_resolution", check_hfield_resolution(self.hfield_resolution))
        object.__setattr__(self, "hfield_refinement", check_hfield_refinement(self.hfield_refinement))
        at_most_one(ie=self.ie, speed_m_s=self.speed_m_s, rate_n_s=self.rate_n_s)
        at_most_one(stiffness_number=self.stiffness_number, stiffness_n_m=self.stiffness_n_m)
        self.tip  # noqa: B018 (the tip's own checks, once)

    @classmethod
    def from_keywords(cls, **keywords) -> RigInputs:
        """The record of :func:`~spine_mj.sim.build_rig`'s keywords: its fields by name,
        any other keyword an engine option."""
        names = {f.name for f in dataclasses.fields(cls)} - {"engine_options"}
        options = {k: v for k, v in keywords.items() if k not in names}
        return cls(**{k: v for k, v in keywords.items() if k in names}, engine_options=options)

    @property
    def tip(self) -> TipParams:
        """The tip (its radius None: the rig's default)."""
        given = {"mass_kg": self.mass_kg, "preload_n": self.preload_n, "gravity_m_s2": self.gravity_m_s2}
        return TipParams(
            tip_radius_m=self.tip_radius_m, mu_s=self.mu, **{k: v for k, v in given.items() if v is not None}
        )

    @property
    def sizing(self) -> dict:
        """The keywords of the rig's sizing (:func:`~spine_mj.sim.build.rig_sizing`) besides the tip."""
        return {
            "length_scale_m": self.length_scale_m,
            "hfield_resolution": self.hfield_resolution,
            "hfield_refinement": self.hfield_refinement,
        }

    @property
    def pace(self) -> dict:
        """The drive's pace, as :func:`~spine_mj.sim.build_drive` takes it."""
        return {"ie": self.ie, "speed_m_s": self.speed_m_s, "rate_n_s": self.rate_n_s}

    @property
    def spring(self) -> dict:
        """The drive spring's stiffness, as :func:`~spine_mj.sim.build_drive` takes it."""
        return {"stiffness_number": self.stiffness_number, "stiffness_n_m": self.stiffness_n_m}
