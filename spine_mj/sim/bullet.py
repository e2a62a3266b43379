"""The same rig in Bullet (pybullet): a hard-contact second engine beside MuJoCo.

MuJoCo's contact is soft by design: friction creeps without its noslip pass and a sphere
sinks into a wedge between facets. Bullet solves contact and Coulomb friction as hard
constraints (sequential impulses, a projected Gauss-Seidel on the complementarity
problem). :class:`BulletRig` is the rig of :class:`~spine_mj.sim.Rig` in Bullet: the same
surface as a heightfield (the same float32 samples, triangulated along the same cell
diagonal as MuJoCo's hfield), a sphere that cannot rotate (inverse inertia 0: a point-like
tip on three slide joints), gravity, preload, the three drives, and the same
:class:`~spine_mj.sim.RunResult`: the run's steps are written in the layout of MuJoCo's
sensors and read by the same analysis (:class:`~spine_mj.sim.results.GroupAnalysis`:
recordings, motion states, events, end reasons, ``engine_trouble``). Scales, engine units,
drives, detection and the recorded time step are MuJoCo's rules, written once in
:mod:`spine_mj.sim.params`, :mod:`spine_mj.sim.drives` and :mod:`spine_mj.sim.rollout`.
Needs the optional extra ``bullet`` (``pip install 'spine-mj[bullet]'``).

Bullet's settings, from rules (:func:`default_bullet_engine`; all in engine units, so
Bullet's absolute thresholds meet O(1) numbers at every physical scale):

* **Recorded step** ``dt``: MuJoCo's step rule (:func:`~spine_mj.sim.params.default_engine`)
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
  speeds (``"never"`` and ``"always"`` measure the pitfall).
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

Runs step in Python (feedback is free here, so the force ramp with reset runs like the
open-loop drives); each row is analysed in windows and a run stops once its ending is
decided, as MuJoCo's batches do. Engine trouble: a non-finite state, penetration beyond the
tolerance, divergence; Bullet has no warnings of its own.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spine_mj import extras
from spine_mj.engagement import DEFAULT_KAPPA_CAP
from spine_mj.errors import SpineInputError, check_positive
from spine_mj.sim.detection import Detection, Event
from spine_mj.sim.drives import (
    Drive,
    RampDrive,
    SpringDrive,
    StaticProbe,
    rate_n_s,
    settle_steps,
    stiffness_n_m,
)
from spine_mj.sim.model import RigModel, start_pair
from spine_mj.sim.params import (
    MIN_TIMESTEP_TAU,
    Scales,
    TipParams,
    default_engine,
    penetration_tolerance_m,
)
from spine_mj.sim.ramp import ResetController, ramp_duration_s
from spine_mj.sim.results import GroupAnalysis, RunResult
from spine_mj.sim.rollout import controls
from spine_mj.surfaces import HField, Surface

__all__ = ["BulletRig", "BulletSettings", "default_bullet_engine"]

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
#: Rows simulated between two looks at a run's end conditions.
WINDOW_ROWS = 512
#: Recorded sensor layout: MuJoCo's sensors (``models/spine_rig.xml``), in the same order.
SENSOR_ADR = {
    "tip_pos": 0,
    "tip_vel": 3,
    "contact_net": 6,
    "contact_deepest": 10,
    "spring_force": 18,
    "push_force": 19,
}
_NSENS = 20
_NSTATE = 7  # time, position, velocity


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
    recorded step as they do MuJoCo's (:func:`~spine_mj.sim.params.default_engine`).
    ``overrides`` replace fields (a ``timestep_s`` alone re-derives the substeps).
    """
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


class BulletRig:
    """The rig of one surface and one tip in Bullet (parameters as :class:`~spine_mj.sim.Rig`,
    ``engine`` a :class:`BulletSettings`; None: :func:`default_bullet_engine`).

    ``sized``, when given, is ``Scales.with_hfield`` of this surface and tip computed by the
    caller (:func:`~spine_mj.sim.build_engine_rig` needs the scales for the settings
    first), as for MuJoCo's rig: the scales and the hfield are measured once.

    The attributes and checks that do not depend on the engine (``scales``, ``tip``,
    ``units``, ``hfield``, ``bounds_m``, :meth:`check_drive`, :meth:`contact_surface`, ...)
    are MuJoCo's rig's (:class:`~spine_mj.sim.model.RigModel`), so a run means the same
    in both engines.

    Raises
    ------
    SpineInputError
        As :class:`~spine_mj.sim.Rig`; also when pybullet is not installed (names the extra).
    """

    name = "bullet"
    sensor_adr = SENSOR_ADR

    def __init__(
        self,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        engine: BulletSettings | None = None,
        length_scale_m: float | None = None,
        char_length_m: float | None = None,
        hfield_resolution: int | None = None,
        sized: tuple[Scales, HField] | None = None,
    ):
        extras.require("bullet", "the Bullet engine")
        if not isinstance(surface, Surface):
            raise SpineInputError(f"surface must be a spine_mj Surface, got {type(surface).__name__}")
        tip = TipParams() if tip is None else tip
        if sized is None:
            sized = Scales.with_hfield(
                surface,
                tip=tip,
                length_scale_m=length_scale_m,
                char_length_m=char_length_m,
                hfield_resolution=hfield_resolution,
            )
        self.scales, self.hfield = sized
        self.surface = surface
        self.tip = dataclasses.replace(tip, tip_radius_m=self.scales.tip_radius_m)
        self.length_scale_m = self.scales.length_scale_m
        self.units = self.scales.units
        self.engine = default_bullet_engine(self.scales) if engine is None else engine
        if self.engine.timestep_s < MIN_TIMESTEP_TAU * self.scales.time_s:
            raise SpineInputError(
                f"timestep_s must be at least {MIN_TIMESTEP_TAU:g} of the time scale tau = "
                f"{self.scales.time_s:.3g} s, or none (derived), got {self.engine.timestep_s:.3g}"
            )
        xmin, xmax, ymin, ymax = surface.bounds
        self.bounds_m = tuple(self.length_scale_m * b for b in (xmin, xmax, ymin, ymax))
        self.z_range_m = RigModel._z_range_m(self)
        self._contact = None
        self._world = None

    # the engine-free parts of MuJoCo's rig, shared (they read scales, tip, surface, hfield)
    contact_surface = RigModel.contact_surface
    default_start = RigModel.default_start
    speed_of = RigModel.speed_of
    inertia_number = RigModel.inertia_number
    check_drive = RigModel.check_drive
    check_start = RigModel.check_start
    check_starts = RigModel.check_starts

    def place_many(self, starts) -> np.ndarray:
        """Tip centres ``(k, 3)`` in engine units resting on the facets at ``starts`` (surface
        units): the exact ball-on-facets height (:meth:`contact_surface`, the same triangles
        Bullet collides with), touching, not sunk in (measured: a tip started a slop deep
        on a 10 deg plane crept downhill at ``0.7 g sin(theta) h`` for good; started
        touching, it sinks less than ``a_p h^2`` and holds)."""
        xy = np.array([start_pair(s) for s in starts], dtype=float).reshape(-1, 2)
        self.check_starts(xy)
        ball = self.contact_surface()
        z = ball.height(xy[:, 0], xy[:, 1]) + ball.radius
        s = self.length_scale_m / self.units.length_m
        return np.column_stack([xy * s, z * s])

    def place(self, x0: float, y0: float) -> np.ndarray:
        """:meth:`place_many` of one start."""
        return self.place_many([(x0, y0)])[0]

    # ----------------------------------------------------------------- the Bullet world

    def world(self):
        """The pybullet client of this rig (built once): the heightfield, no tip yet."""
        if self._world is None:
            self._world = _World(self)
        return self._world

    def close(self) -> None:
        """Disconnect the Bullet client (a later run connects again)."""
        if self._world is not None:
            self._world.close()
            self._world = None

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: pybullet may be gone
            pass

    # ----------------------------------------------------------------- runs

    def run(
        self,
        drive: Drive,
        *,
        start: tuple[float, float],
        detection: Detection | None = None,
        progress: Callable[[float], None] | None = None,
        **_ignored,
    ) -> RunResult:
        """Run one drive from ``start`` (surface units); ``progress`` receives the fraction done."""
        return self._run(drive, start_pair(start), detection, progress, stop_early=True)

    def run_batch(
        self,
        drives: Drive | Sequence[Drive],
        starts: Sequence[tuple[float, float]],
        *,
        detection: Detection | None = None,
        stop_early: bool = True,
        **_ignored,
    ) -> list[RunResult]:
        """Run many starts and/or drives (one drive for all or one per start), one after the
        other on this process's client (parallel runs come from the sweep's process pool).
        Takes the force ramp too. ``stop_early`` as :meth:`~spine_mj.sim.Rig.run_batch`;
        MuJoCo-only options (``backend``, ``nthread``, ``refine``) are ignored."""
        starts = [start_pair(s) for s in starts]
        if isinstance(drives, (SpringDrive, StaticProbe, RampDrive)):
            drives = [drives] * len(starts)
        drives = list(drives)
        if len(drives) != len(starts):
            raise SpineInputError(
                f"drives must be one drive or one per start ({len(starts)}), got {len(drives)}"
            )
        return [self._run(d, s, detection, None, stop_early=stop_early) for d, s in zip(drives, starts)]

    def _run(self, drive, start, detection, progress, *, stop_early: bool) -> RunResult:
        self.check_drive(drive)
        det = (Detection() if detection is None else detection).resolve(self.scales)
        qpos0 = self.place(*start)
        u = self.units
        ramp = isinstance(drive, RampDrive)
        if ramp:
            nstep, ctl = self._ramp_plan(drive, det)
            ctrl = np.zeros((nstep, 6))
            ctrl[:, 2] = -self.tip.preload_n / u.force_n
            ctrl[:, 3] = np.nan
        else:
            ctrl = controls(self, drive, qpos0, det)
            nstep, ctl = ctrl.shape[0], None
        state = np.zeros((1, nstep, _NSTATE))
        sens = np.zeros((1, nstep, _NSENS))
        carriage = ctrl[None, :, 3] if isinstance(drive, SpringDrive) else np.full((1, nstep), np.nan)
        analysis = GroupAnalysis(self, [drive], [start], det, carriage)
        k = stiffness_n_m(drive, self.scales) / u.stiffness_n_m if isinstance(drive, SpringDrive) else 0.0
        n_sub = spring_substeps(self.engine, drive, self.scales)
        n_settle = settle_steps(drive, self.engine.timestep_s)
        sim = self.world().start(
            qpos0, n_sub, held=(det.move_speed_m_s / u.speed_m_s, det.breakaway_distance_m / u.length_m)
        )
        done, steps = 0, 0
        while done < nstep:
            end = min(nstep, done + WINDOW_ROWS)
            for i in range(done, end):
                if ctl is not None and i >= n_settle:
                    ctrl[i, 1] = ctl.push()
                x_prev = ctrl[i - 1, 0] if i else ctrl[0, 0]
                sim.step(i, ctrl[i], x_prev, k, state[0, i], sens[0, i])
                if ctl is not None:
                    ctl.observe(i, sens[0, i], driving=i >= n_settle)
            steps += (end - done) * n_sub
            decided = bool(analysis.add(slice(0, 1), done, end, state, sens)[0])
            done = end
            if progress is not None:
                progress(done / nstep)
            if stop_early and (decided or not np.isfinite(state[0, end - 1]).all()):
                break
        analysis.simulated[0] = done
        result = analysis.results([None])[0]
        if ctl is not None:
            resets = tuple(Event("reset", i, float(result.time_s[i])) for i in ctl.resets if i < result.n)
            events = sorted(
                result.events + resets, key=lambda e: (e.index, e.kind == result.end_reason.value)
            )
            result = dataclasses.replace(result, events=tuple(events))
        return result

    def _ramp_plan(self, drive: RampDrive, det: Detection) -> tuple[int, ResetController]:
        """Rows and the feedback controller of a force ramp with reset (MuJoCo's
        :class:`~spine_mj.sim.ramp.ResetController`, which reads rows in the sensor layout
        written here), in engine units; no fast-forward."""
        u, dt, sc = self.units, self.engine.timestep_s, self.scales
        n_settle = settle_steps(drive, dt)
        slide = drive.slide_distance_m
        ctl = ResetController(
            step_n=rate_n_s(drive, sc) * dt / u.force_n,
            cap_n=det.kappa_cap * sc.preload_n / u.force_n * (1 + 1e-9),
            slide_distance_m=(0.01 * sc.char_length_m if slide is None else slide) / u.length_m,
            settle_steps=n_settle,
            move_speed_m_s=det.move_speed_m_s / u.speed_m_s,
            sensor_adr=SENSOR_ADR,
        )
        return n_settle + int(math.ceil(ramp_duration_s(drive, det, sc) / dt)), ctl


class _World:
    """One pybullet client in engine units: the heightfield, and the tip of the current run."""

    def __init__(self, rig: BulletRig):
        import pybullet as pb

        self.pb, self.rig = pb, rig
        e, u, tip = rig.engine, rig.units, rig.tip
        self.cid = pb.connect(pb.DIRECT)
        self.lu = u.length_m
        pb.setGravity(0, 0, -tip.gravity_m_s2 / u.acceleration_m_s2, physicsClientId=self.cid)
        pb.setPhysicsEngineParameter(
            numSolverIterations=e.solver_iterations,
            erp=e.erp,
            contactERP=e.erp,
            frictionERP=e.erp,
            globalCFM=e.cfm,
            useSplitImpulse=1,
            splitImpulsePenetrationThreshold=0.0,
            enableConeFriction=int(e.cone_friction),
            contactBreakingThreshold=e.contact_breaking_m / self.lu,
            contactSlop=e.contact_slop_m / self.lu,
            restitutionVelocityThreshold=0.0,
            deterministicOverlappingPairs=1,
            physicsClientId=self.cid,
        )
        self.ground = self._heightfield()
        self.tip_shape = pb.createCollisionShape(
            pb.GEOM_SPHERE, radius=tip.tip_radius_m / self.lu, physicsClientId=self.cid
        )
        self.tip = None

    def _heightfield(self) -> int:
        """The hfield's samples as Bullet's heightfield, turned a quarter about z so that
        Bullet's cells split along MuJoCo's diagonal (tested against MuJoCo's facets)."""
        pb, rig = self.pb, self.rig
        hf = rig.hfield
        s = rig.length_scale_m / self.lu
        rx, ry, elev, _ = hf.size
        heights = (hf.pos[2] + hf.data.astype(float) * elev) * s  # (nrow = y, ncol = x), engine units
        dx, dy = 2 * rx * s / (hf.ncol - 1), 2 * ry * s / (hf.nrow - 1)
        # Bullet splits each cell from (x+1, y) to (x, y+1) of its own grid; its local x is
        # world y and its local y world -x, which makes that MuJoCo's (x, y) to (x+1, y+1)
        local = heights[:, ::-1].T
        flags = pb.GEOM_CONCAVE_INTERNAL_EDGE if rig.engine.internal_edges else 0
        shape = pb.createCollisionShape(
            pb.GEOM_HEIGHTFIELD,
            flags=flags,
            meshScale=[dy, dx, 1.0],
            heightfieldData=local.ravel().tolist(),
            numHeightfieldRows=hf.nrow,
            numHeightfieldColumns=hf.ncol,
            physicsClientId=self.cid,
        )
        centre = [hf.pos[0] * s, hf.pos[1] * s, 0.5 * (heights.min() + heights.max())]
        quarter = pb.getQuaternionFromEuler([0.0, 0.0, math.pi / 2])
        body = pb.createMultiBody(
            0, shape, basePosition=centre, baseOrientation=quarter, physicsClientId=self.cid
        )
        pb.changeDynamics(
            body,
            -1,
            lateralFriction=1.0,
            restitution=0.0,
            rollingFriction=0.0,
            spinningFriction=0.0,
            frictionAnchor=int(rig.engine.friction_anchor == "always"),
            physicsClientId=self.cid,
        )
        return body

    def start(self, qpos0: np.ndarray, substeps: int, held: tuple[float, float] = (0.0, 0.0)) -> _Run:
        """A fresh tip resting at ``qpos0`` (engine units), stepping ``substeps`` per row;
        ``held``: the detection's move speed and breakaway distance (engine units), which
        say when the tip is held (friction anchors ``"held"``)."""
        pb, rig = self.pb, self.rig
        if self.tip is not None:
            pb.removeBody(self.tip, physicsClientId=self.cid)
        self.tip = pb.createMultiBody(
            1.0,
            self.tip_shape,
            basePosition=list(map(float, qpos0)),
            useMaximalCoordinates=True,
            physicsClientId=self.cid,
        )
        pb.changeDynamics(
            self.tip,
            -1,
            mass=1.0,
            localInertiaDiagonal=[1e8] * 3,
            lateralFriction=rig.tip.mu_s,
            restitution=0.0,
            rollingFriction=0.0,
            spinningFriction=0.0,
            linearDamping=0.0,
            angularDamping=0.0,
            activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
            physicsClientId=self.cid,
        )
        h = rig.engine.timestep_s / rig.units.time_s / substeps
        pb.setPhysicsEngineParameter(fixedTimeStep=h, numSubSteps=0, physicsClientId=self.cid)
        return _Run(self, substeps, h, held)

    def close(self) -> None:
        try:
            self.pb.disconnect(physicsClientId=self.cid)
        except self.pb.error:
            pass


class _Run:
    """The stepping of one run: a row is ``substeps`` Bullet steps, written in MuJoCo's
    state and sensor layout (engine units)."""

    def __init__(self, world: _World, substeps: int, h: float, held: tuple[float, float]):
        self.w, self.n, self.h = world, substeps, h
        self.held_speed, self.held_distance = held
        self.anchored_at = None  # where the anchors were set (rule "held")
        self.wedged = False  # touching the surface along normals apart (the last row)
        self.t = 0.0

    def step(self, i: int, ctrl: np.ndarray, x_prev: float, k: float, state: np.ndarray, sens: np.ndarray):
        """Row ``i``: ``ctrl`` (spring target, push, preload force, ...) held, the spring's
        target moving linearly from ``x_prev``; fills ``state`` (time, position, velocity)
        and ``sens`` (:data:`SENSOR_ADR`)."""
        pb, cid, tip, n = self.w.pb, self.w.cid, self.w.tip, self.n
        push, fz = float(ctrl[1]), float(ctrl[2])
        if self.w.rig.engine.friction_anchor == "held":
            self._anchor()
        spring_sum = 0.0
        for j in range(n):
            pos = pb.getBasePositionAndOrientation(tip, physicsClientId=cid)[0]
            fs = k * (x_prev + (j + 1) / n * (ctrl[0] - x_prev) - pos[0]) if k else 0.0
            spring_sum += fs
            pb.applyExternalForce(tip, -1, [fs + push, 0.0, fz], pos, pb.WORLD_FRAME, physicsClientId=cid)
            pb.stepSimulation(physicsClientId=cid)
        self.t = (i + 1) * n * self.h
        pos = pb.getBasePositionAndOrientation(tip, physicsClientId=cid)[0]
        vel = pb.getBaseVelocity(tip, physicsClientId=cid)[0]
        state[0] = self.t
        state[1:4] = pos
        state[4:7] = vel
        sens[0:3] = pos
        sens[3:6] = vel
        sens[6:] = 0.0
        sens[18] = spring_sum / n
        sens[19] = push
        pts = pb.getContactPoints(tip, self.w.ground, physicsClientId=cid)
        self.wedged = False
        if not pts:
            return
        touch = 0.5 * self.w.rig.engine.contact_slop_m / self.w.lu
        net = np.zeros(3)
        deepest = None
        normals = []
        for p in pts:
            dist = p[8]
            if dist > touch:
                continue
            normals.append(p[7])
            net += p[9] * np.asarray(p[7]) + p[10] * np.asarray(p[11]) + p[12] * np.asarray(p[13])
            if deepest is None or dist < deepest[8]:
                deepest = p
        if deepest is None:
            return
        normals = np.asarray(normals)
        self.wedged = bool((normals @ normals.T).min() < WEDGE_COS)
        sens[6] = 1.0
        sens[7:10] = -net  # MuJoCo's sensor: the tip's force on the surface
        sens[10] = 1.0
        sens[11] = deepest[8]
        sens[12:15] = deepest[6]
        sens[15:18] = deepest[7]

    def _anchor(self) -> None:
        """Friction anchors (rule ``"held"``): set once the tip is wedged (touching along
        normals more than :data:`WEDGE_ANGLE_DEG` apart) and moves slower than the move
        speed; lifted once it has moved the breakaway distance from where they were set (the
        detection's own meaning of held) or runs :data:`ANCHOR_RELEASE` move speeds. On
        and off at the move speed alone they flicker at a creep's speed and the creep goes
        on; on a single contact they are not needed (no creep) and a swing through zero
        speed would be caught by them. The ground's flag: pybullet sets none on a body of
        maximal coordinates."""
        pb, cid, tip = self.w.pb, self.w.cid, self.w.tip
        pos = np.asarray(pb.getBasePositionAndOrientation(tip, physicsClientId=cid)[0])
        speed = np.linalg.norm(pb.getBaseVelocity(tip, physicsClientId=cid)[0])
        if self.anchored_at is not None:
            moved = np.linalg.norm(pos - self.anchored_at) > self.held_distance
            if not moved and speed <= ANCHOR_RELEASE * self.held_speed:
                return
            self.anchored_at = None
        elif speed < self.held_speed and self.wedged:
            self.anchored_at = pos
        else:
            return
        pb.changeDynamics(
            self.w.ground, -1, frictionAnchor=int(self.anchored_at is not None), physicsClientId=cid
        )
