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
:mod:`spine_mj.sim.scales`, :mod:`spine_mj.sim.step_rule`, :mod:`spine_mj.sim.drives` and
:mod:`spine_mj.sim.rollout`.
Needs the optional extra ``bullet`` (``pip install 'spine-mj[bullet]'``).

Bullet's settings come from rules (:mod:`spine_mj.sim.bullet_settings`: the step, slop,
substeps, spring, solver, friction and its anchors, restitution, internal edges).

Runs step in Python (feedback is free here, so the force ramp with reset runs like the
open-loop drives); each row is analysed in windows and a run stops once its ending is
decided, as MuJoCo's batches do. Engine trouble: a non-finite state, penetration beyond the
tolerance, divergence; Bullet has no warnings of its own.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import sys
from collections.abc import Callable, Sequence

import numpy as np

from spine_mj import extras
from spine_mj.errors import SpineInputError
from spine_mj.memory import check_memory
from spine_mj.sim.bullet_settings import (
    ANCHOR_RELEASE,
    WEDGE_COS,
    BulletSettings,
    default_bullet_engine,
    spring_substeps,
)
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
from spine_mj.sim.open_loop import controls
from spine_mj.sim.ramp import ResetController, ramp_duration_s
from spine_mj.sim.records import TipParams
from spine_mj.sim.results import GroupAnalysis, RunResult
from spine_mj.sim.scales import Scales
from spine_mj.sim.step_rule import MIN_TIMESTEP_TAU
from spine_mj.surfaces import HField, Surface

__all__ = ["BulletRig"]

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
    "contact_normal": 20,
}
#: Values in a recorded sensor row (the last address plus its one value).
SENSOR_SIZE = 21
_NSTATE = 7  # time, position, velocity


#: Bytes per hfield sample that building Bullet's heightfield adds at its peak, measured
#: at 384 to 1024 a side (tests/test_memory.py): pybullet keeps every cell's two triangles
#: as a rendering mesh (6 vertices of position, normal and uv in doubles, 0.58 kB a sample),
#: and holds two copies of it while it makes the shape (1.16 kB); the float samples, their
#: list and copies take the rest. The mesh is pybullet's own, made whatever the flags; its
#: renderer's copy of it (0.33 kB more) is avoided by giving the body a visual shape.
BULLET_BYTES_PER_SAMPLE = 1240
#: Bytes a pybullet client takes before any shape (measured on a 64 x 64 heightfield).
BULLET_CLIENT_BYTES = 40 * 2**20


#: The most samples pybullet takes in one heightfield: its client copies the float32 heights
#: through a stream buffer of 8 MiB (1 MiB on macOS), cuts longer data there, and its
#: server then reads past the buffer: measured, 1024 x 2048 samples gave the heights given,
#: 1024 x 2049 an AABB of +-2e12 that no ray hit, and a 2048 x 2048 fractal (1767 x 1767
#: samples in the hfield) ended every run in engine trouble, the tip falling through.
BULLET_MAX_SAMPLES = (2**20 if sys.platform == "darwin" else 2**23) // 4


def check_bullet_hfield(nrow: int, ncol: int) -> None:
    """Refuse in one line a heightfield of more than :data:`BULLET_MAX_SAMPLES` samples, or
    one whose peak (:func:`bullet_heightfield_bytes`) exceeds the memory budget: the
    engine's ``hfield_check``, run on the sizing rule's predicted sides before any sampling
    (:func:`~spine_mj.sim.build.plan_rig`) and again on the rig's hfield."""
    if nrow * ncol > BULLET_MAX_SAMPLES:
        side = math.isqrt(BULLET_MAX_SAMPLES)
        raise SpineInputError(
            f"Bullet's heightfield of {nrow} x {ncol} samples is more than pybullet takes, "
            f"{BULLET_MAX_SAMPLES:,} (its upload buffer; beyond it the heights it reads are "
            f"garbage and the tip falls through): use a coarser grid, at most {side} samples a side"
        )
    where = f"Bullet's heightfield of {nrow} x {ncol} samples"
    check_memory(bullet_heightfield_bytes(nrow, ncol), where=where)


def bullet_heightfield_bytes(nrow: int, ncol: int) -> float:
    """The peak memory that Bullet's heightfield of ``nrow x ncol`` samples adds (its
    client, and :data:`BULLET_BYTES_PER_SAMPLE` a sample)."""
    return BULLET_CLIENT_BYTES + BULLET_BYTES_PER_SAMPLE * float(nrow) * ncol


class BulletRig:
    """The rig of one surface and one tip in Bullet (parameters as :class:`~spine_mj.sim.Rig`,
    ``engine`` a :class:`BulletSettings`; None: :func:`default_bullet_engine`).

    ``sized``, when given, is ``Scales.with_hfield`` of this surface and tip computed by the
    caller (:func:`~spine_mj.sim.build_rig` needs the scales for the settings
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
        sized: tuple[Scales, HField] | None = None,
        **sizing,
    ):
        extras.require("bullet", "the Bullet engine")
        self.scales, self.hfield, self.tip = Scales.for_rig(
            surface,
            tip=tip,
            sized=sized,
            **sizing,
        )
        self.surface = surface
        self.length_scale_m = self.scales.length_scale_m
        self.units = self.scales.units
        self.engine = default_bullet_engine(self.scales) if engine is None else engine
        if self.engine.timestep_s < MIN_TIMESTEP_TAU * self.scales.time_s:
            raise SpineInputError(
                f"timestep_s must be at least {MIN_TIMESTEP_TAU:g} of the time scale tau = "
                f"{self.scales.time_s:.3g} s, or none (derived), got {self.engine.timestep_s:.3g}"
            )
        check_bullet_hfield(self.hfield.nrow, self.hfield.ncol)
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
        self.check_starts([start_pair(start)], det.domain_margin_m)
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
        sens = np.zeros((1, nstep, SENSOR_SIZE))
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


def _pybullet():
    """pybullet, imported without the "pybullet build time: ..." line its C code prints at
    import (every Bullet run printed it): standard output and error point at /dev/null for
    the import, C's buffers flushed before they are given back."""
    if "pybullet" in sys.modules:
        return sys.modules["pybullet"]
    import ctypes

    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    saved = {}
    try:
        with open(os.devnull, "w") as null:
            for fd in (1, 2):
                with contextlib.suppress(OSError):
                    saved[fd] = os.dup(fd)
                    os.dup2(null.fileno(), fd)
            import pybullet

            with contextlib.suppress(OSError, AttributeError):
                ctypes.CDLL(None).fflush(None)
    finally:
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
    return pybullet


class _World:
    """One pybullet client in engine units: the heightfield, and the tip of the current run."""

    def __init__(self, rig: BulletRig):
        pb = _pybullet()
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
        centre = [hf.pos[0] * s, hf.pos[1] * s, 0.5 * (heights.min() + heights.max())]
        data = heights[:, ::-1].T.ravel().tolist()  # pybullet reads a sequence of floats
        del heights  # only the list while pybullet builds the shape (its peak)
        flags = pb.GEOM_CONCAVE_INTERNAL_EDGE if rig.engine.internal_edges else 0
        shape = pb.createCollisionShape(
            pb.GEOM_HEIGHTFIELD,
            flags=flags,
            meshScale=[dy, dx, 1.0],
            heightfieldData=data,
            numHeightfieldRows=hf.nrow,
            numHeightfieldColumns=hf.ncol,
            physicsClientId=self.cid,
        )
        del data
        quarter = pb.getQuaternionFromEuler([0.0, 0.0, math.pi / 2])
        # a body without a visual shape gets its collision triangles copied into pybullet's
        # renderer (0.33 kB a sample, measured at 2048 a side); a point's visual holds none
        unseen = pb.createVisualShape(pb.GEOM_SPHERE, radius=1e-9, physicsClientId=self.cid)
        body = pb.createMultiBody(
            0,
            shape,
            baseVisualShapeIndex=unseen,
            basePosition=centre,
            baseOrientation=quarter,
            physicsClientId=self.cid,
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
        load = 0.0
        deepest = None
        normals = []
        for p in pts:
            dist = p[8]
            if dist > touch:
                continue
            normals.append(p[7])
            net += p[9] * np.asarray(p[7]) + p[10] * np.asarray(p[11]) + p[12] * np.asarray(p[13])
            load += p[9]
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
        sens[20] = load  # MuJoCo's touch sensor: the contacts' normal forces summed

    def _anchor(self) -> None:
        """Friction anchors, rule ``"held"`` (:mod:`spine_mj.sim.bullet_settings`): set
        once the tip is wedged (touching along normals more than ``WEDGE_ANGLE_DEG``
        apart) and moves slower than the move speed; lifted once it has moved the
        breakaway distance from where they were set (the detection's own meaning of held)
        or runs ``ANCHOR_RELEASE`` move speeds. The ground's flag: pybullet sets none on a
        body of maximal coordinates."""
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
