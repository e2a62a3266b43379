"""The interface a rig of every engine offers.

A rig is a surface as a heightfield, a spherical tip under gravity and preload, and the
three drives (spring carriage, force ramp with reset, static probe), given in SI and run
in the problem's engine units (:class:`~spine_mj.sim.scales.EngineUnits`). Two engines
implement it, registered in :data:`spine_mj.choices.ENGINES`: ``"mujoco"``
(:class:`~spine_mj.sim.Rig`, soft convex contact, the default) and ``"bullet"``
(:class:`~spine_mj.sim.bullet.BulletRig`, hard contact and Coulomb friction by sequential
impulses; the ``[bullet]`` extra). Every engine takes the same inputs through
:func:`spine_mj.sim.build_rig`, shares the scale, drive, detection and step rules, and
returns the same :class:`~spine_mj.sim.RunResult` (:class:`EngineRig`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import Drive
from spine_mj.sim.records import TipParams
from spine_mj.sim.results import RunResult
from spine_mj.sim.scales import EngineUnits, Scales
from spine_mj.surfaces import Surface

__all__ = ["EngineRig"]


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
