"""Bullet's settings from rules (:class:`BulletSettings`, :func:`default_bullet_engine`): the
second engine's counterpart of MuJoCo's recommended settings (:mod:`spine_mj.sim.step_rule`),
each derived and its pitfall measured (tests/sim/test_sim_bullet.py).

All in engine units, so Bullet's absolute thresholds meet O(1) numbers at every physical
scale:

* **Recorded step** ``dt``: MuJoCo's step rule (:func:`~spine_mj.sim.step_rule.default_engine`)
  so both engines record the same rows; Bullet runs ``substeps`` steps ``h = dt / n`` per row.
* **Contact slop** (the depth Bullet leaves uncorrected) ``= 0.1`` penetration tolerance
  (``0.01 r_tip`` for small tips). Measured pitfall: a tip held by friction *creeps*
  at ``0.27 h`` L_c/tau whenever the normal load's approach in one step,
  ``a_n h^2``, exceeds the slop (a sphere on a 24 deg slope with mu = 0.5 slid at
  1.3e-3 L_c/tau at ``h = 0.005 tau``, slop 1e-5; nothing, to 1e-13, with the slop above
  ``a_n h^2``). So ``n = ceil(sqrt(1.25 (1 + kappa_cap) a_p dt^2 / slop))``: no creep up
  to a normal load of ``(1 + kappa_cap) F_p``, the largest a self-lock test reaches.
* **Spring**: applied as a force at every Bullet step, semi-implicit Euler, stable for
  ``omega h < 2``; a stiff spring adds substeps so that ``omega h <= 0.2`` (the period's
  error ``(omega h)^2 / 24 < 0.2 %``), ``omega = sqrt(k / m)``.
* **Contact breaking threshold** (speculative contacts): the penetration tolerance. MuJoCo's
  step rule keeps a landing's travel in one step below ``e / 2`` half-tolerances, so every
  landing it was made for is in the solver a step before the tip arrives.
* **Solver**: 50 iterations (single body, at most ~6 contacts: the residual is at round-off
  well before), ``ERP = 0.2`` with split impulse (position correction adds no velocity),
  ``CFM = 0`` (hard contact).
* **Friction**: ``enableConeFriction`` (measured: without it Bullet's two friction rows
  form a pyramid that holds ``sqrt(2) mu N`` at 45 deg to its axes, 0.716 for mu = 0.5);
  Bullet multiplies the two bodies' frictions, so the surface gets 1 and the tip ``mu_s``.
* **Friction anchors while wedged and held** (``friction_anchor="held"``). Measured: a tip
  resting in a V-groove on two flanks without anchors has its load on one flank's contact
  at a time (normal forces 0.90 and 0 F_p at a row, the flanks alternating), sees one
  flank's slope (34 deg, above the 27 deg friction angle) and creeps down the groove at
  0.1 tip radii per second, which a static probe reads as a slide; with anchors the load
  splits (0.77 and 0.43 F_p) and it holds. On a single contact anchors are not needed and
  disturb: with them always on a frictionless tip slid over a flat plane hops by up to
  15 % of its speed and a stiff spring-block's swing (k = 1e4 N/m) peaks at 1.79 V
  instead of 2.00 V. So anchors are set while the tip touches along normals more than
  :data:`WEDGE_ANGLE_DEG` apart and moves slower than the detection's move speed, and
  lifted once it has moved the breakaway distance or runs :data:`ANCHOR_RELEASE` move
  speeds (``"never"`` and ``"always"`` measure the pitfall). Set and lifted at the move
  speed alone they flicker at the creep's speed (0.4-1.4 move speeds) and the groove
  broke away at 0.77 instead of 1.18.
* **Restitution** 0 on both bodies: landings are perfectly inelastic as MuJoCo's critically
  damped contacts are (measured: a tip landing at 1 L_c/tau rebounds at 2e-3 with 0, at
  0.29 with 0.5).
* **Internal edges**: the heightfield is built with ``GEOM_CONCAVE_INTERNAL_EDGE``
  (measured: a sphere sliding at 3 L_c/tau over a flat triangulated plane saw contact
  normals tilted by 1.6 deg at the triangles' shared edges and hopped at 4 % of its speed;
  with internal-edge info, 0 deg and 0.01 %). Its cost, measured and left as a stated
  limit: at a concave kink the adjustment snaps the contact normal to a facet's, so a tip
  pushed into the kink between a floor and a half-embedded sphere (Dai's interlock at
  0.97 times the threshold) self-locks where the facets' rule and MuJoCo release at 10.4;
  without internal edges the same run breaks away at 10.61 (+2.3 %).
* No sleeping (a resting tip must still feel the rising drive force).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.drives import Drive, SpringDrive, stiffness_n_m
from spine_mj.sim.scales import Scales
from spine_mj.sim.step_rule import default_engine, penetration_tolerance_m
from spine_mj.theory.engagement import DEFAULT_KAPPA_CAP

__all__ = ["BulletSettings", "default_bullet_engine", "spring_substeps"]

#: Contact slop in penetration tolerances (module docstring).
SLOP_OF_TOLERANCE = 0.1
#: Margin on the normal load's approach per step against the slop (measured: creep stops at 1).
_SLOP_MARGIN = 1.25
#: Largest omega h of the spring's explicit force.
MAX_SPRING_OMEGA_H = 0.2
#: When friction anchors are on: while the tip is held (the rule), never, always.
FRICTION_ANCHORS = ("held", "never", "always")
#: Contacts whose normals are this far apart wedge the tip (anchors while held).
WEDGE_ANGLE_DEG = 1.0
WEDGE_COS = math.cos(math.radians(WEDGE_ANGLE_DEG))
#: Anchors set while held are lifted above this many move speeds, before the breakaway
#: distance (a wedged tip's swing through zero speed; measured on a plane with anchors
#: always on: a stiff spring-block's swing at k = 1e4 N/m peaked at 1.79 V, 2.00 V without;
#: a wedge's creep runs at 0.4-1.4 move speeds).
ANCHOR_RELEASE = 10.0


@dataclass(frozen=True)
class BulletSettings:
    """Bullet's settings, recorded with every run (rules: :func:`default_bullet_engine`).

    Attributes
    ----------
    timestep_s : float
        The recorded step [s] (one row of a run).
    substeps : int
        Bullet steps per recorded step (at least; a stiff spring adds more).
    contact_slop_m, contact_breaking_m : float
        Depth Bullet leaves uncorrected, and the distance within which contacts enter the
        solver [m].
    solver_iterations : int
    erp, cfm : float
        Error reduction (position correction per step, by split impulse) and constraint
        force mixing (0: hard).
    cone_friction, internal_edges : bool
    friction_anchor : {"held", "never", "always"}
        When Bullet's friction anchors are on (module docstring): ``"held"`` while the tip
        moves slower than the detection's move speed, so a wedge holds and a slide is free.

    The hfield's resolution is the rig's scales' (:attr:`Scales.hfield_resolution`),
    measured once with the hfield (:meth:`Scales.with_hfield`), not a setting.
    """

    timestep_s: float
    substeps: int = 1
    contact_slop_m: float = 0.0
    contact_breaking_m: float = 0.0
    solver_iterations: int = 50
    erp: float = 0.2
    cfm: float = 0.0
    cone_friction: bool = True
    friction_anchor: str = "held"
    internal_edges: bool = True

    def __post_init__(self):
        object.__setattr__(self, "timestep_s", check_positive("timestep_s", self.timestep_s))
        for name in ("substeps", "solver_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or int(v) != v or v < 1:
                raise SpineInputError(f"{name} must be an integer >= 1, got {v!r}")
            object.__setattr__(self, name, int(v))
        for name in ("contact_slop_m", "contact_breaking_m", "cfm"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name), allow_zero=True))
        if self.friction_anchor not in FRICTION_ANCHORS:
            raise SpineInputError(
                f"friction_anchor must be one of {', '.join(FRICTION_ANCHORS)}, got {self.friction_anchor!r}"
            )
        if not 0 <= self.erp <= 1:
            raise SpineInputError(f"erp must lie in [0, 1], got {self.erp!r}")

    def to_dict(self) -> dict:
        """JSON-ready, with ``"engine": "bullet"`` (a MuJoCo run's settings have no such key)."""
        return {"engine": "bullet", **dataclasses.asdict(self)}


def default_bullet_engine(
    scales: Scales,
    *,
    speed_m_s: float | None = None,
    stiffness_n_m: float | None = None,
    kappa_cap: float = DEFAULT_KAPPA_CAP,
    **overrides,
) -> BulletSettings:
    """Bullet's settings from the problem's scales (rules in the module docstring).

    ``speed_m_s`` and ``stiffness_n_m``: the drive's speed and spring, which bound the
    recorded step as they do MuJoCo's (:func:`~spine_mj.sim.step_rule.default_engine`).
    ``overrides`` replace fields (a ``timestep_s`` alone re-derives the substeps).
    """
    # a given step or slop is checked before the substeps are derived from it (NaN, 0)
    for name in ("timestep_s", "contact_slop_m"):
        if overrides.get(name) is not None:
            overrides[name] = check_positive(name, overrides[name])
    dt = overrides.get("timestep_s") or (
        default_engine(scales, speed_m_s=speed_m_s, stiffness_n_m=stiffness_n_m).timestep_s
    )
    tol = penetration_tolerance_m(scales)
    slop = overrides.get("contact_slop_m") or SLOP_OF_TOLERANCE * tol
    approach = _SLOP_MARGIN * (1 + kappa_cap) * scales.preload_n / scales.mass_kg * dt**2
    base = {
        "timestep_s": dt,
        "substeps": max(1, math.ceil(math.sqrt(approach / slop) - 1e-9)),
        "contact_slop_m": slop,
        "contact_breaking_m": tol,
    }
    base.update(overrides)
    return BulletSettings(**base)


def spring_substeps(engine: BulletSettings, drive: Drive, scales: Scales) -> int:
    """Bullet steps per recorded step for ``drive``: the engine's, or more where the spring
    needs them (``omega h <= MAX_SPRING_OMEGA_H``)."""
    n = engine.substeps
    if isinstance(drive, SpringDrive):
        omega = math.sqrt(stiffness_n_m(drive, scales) / scales.mass_kg)
        n = max(n, math.ceil(omega * engine.timestep_s / MAX_SPRING_OMEGA_H - 1e-9))
    return n
