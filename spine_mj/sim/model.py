"""The compiled MuJoCo model of one surface and one tip: building, surface swaps, export, placement.

:class:`RigModel` loads ``models/spine_rig.xml`` with ``MjSpec``, sizes it from the
:class:`~spine_mj.sim.scales.Scales` (the rule lives there),
attaches the surface as an hfield, compiles, and knows its ids and sensor addresses;
it places tips (:mod:`spine_mj.sim.placement`) and gives each drive its model.

The model is built in engine units (:class:`~spine_mj.sim.scales.EngineUnits`: length
``L_c``, force ``F_p``, mass ``m``): ``rig.units`` converts. Everything that talks to MuJoCo
(``model``, :meth:`RigModel.place`, the controls) is in those units; results are converted
back to SI in one place (:meth:`~spine_mj.sim.recording.Recording.from_sensors`).
:class:`~spine_mj.sim.Rig` adds running on top; the run machinery
(:mod:`~spine_mj.sim.rollout`, :mod:`~spine_mj.sim.ramp`, :mod:`~spine_mj.sim.results`,
:mod:`~spine_mj.sim.render`) works on a :class:`RigModel`.
"""

from __future__ import annotations

import collections
import copy
import os
from pathlib import Path

import numpy as np

from spine_mj.atomic import atomic_output
from spine_mj.choices import ENGINES
from spine_mj.errors import SpineInputError
from spine_mj.resources import model_path
from spine_mj.sim.drives import Drive, SpringDrive, speed_m_s, stiffness_n_m
from spine_mj.sim.drives import stiffness_n_m as spring_stiffness_n_m
from spine_mj.sim.placement import Placer
from spine_mj.sim.recording import SENSOR_NAMES
from spine_mj.sim.records import EngineSettings, TipParams
from spine_mj.sim.rig_hfield import hfield_of
from spine_mj.sim.scales import Scales
from spine_mj.sim.step_rule import (
    MAX_DRIVE_ADVANCE_PER_STEP,
    MAX_SPRING_OMEGA_DT,
    check_drive_speed,
    check_engine_for,
    default_engine,
    rest_depth_m,
    spring_omega_dt,
)
from spine_mj.surfaces import BallOnFacets, HField, Surface, TriangulatedSurface, from_hfield

MODEL_PATH = model_path()
#: MuJoCo's latest warning messages (the engine's own text), newest last.
ENGINE_MESSAGES: collections.deque[str] = collections.deque(maxlen=64)
_ENGINE_QUIET = []


def quiet_engine() -> None:
    """Route MuJoCo's warnings to :data:`ENGINE_MESSAGES` instead of stdout and a
    ``MUJOCO_LOG.TXT`` in the working folder (once per process; runs record their warnings
    in their end detail)."""
    import mujoco

    if not _ENGINE_QUIET:
        mujoco.set_mju_user_warning(ENGINE_MESSAGES.append)
        _ENGINE_QUIET.append(True)


def compile_spec(spec):
    """``spec.compile()``, a model MuJoCo refuses raised as :class:`SpineInputError` (one line)."""
    try:
        return spec.compile()
    except ValueError as exc:
        raise SpineInputError(f"MuJoCo refused the rig's model: {str(exc).strip().splitlines()[0]}") from None


def _follow_camera(distance: float) -> dict:
    """``pos`` and ``xyaxes`` of a camera ``distance`` from its body, looking at it from
    the -x, -y side and 40 degrees above."""
    ahead = np.array([1.0, 1.0, -1.2]) / np.linalg.norm([1.0, 1.0, -1.2])
    right = np.array([1.0, -1.0, 0.0]) / np.sqrt(2)
    up = np.cross(right, ahead)
    return {"pos": list(-distance * ahead), "xyaxes": [*right, *up]}


def start_pair(start) -> tuple[float, float]:
    """``start`` as ``(x0, y0)`` floats, or :class:`SpineInputError` naming what arrived."""
    try:
        x0, y0 = (float(v) for v in start)
    except (TypeError, ValueError):
        raise SpineInputError(f"each start must be a pair (x0, y0) of numbers, got {start!r}") from None
    return x0, y0


def check_starts_on(surface, starts, margin: float = 0.0) -> None:
    """Refuse, naming the first, a start ``(x0, y0)`` (surface units) that is not strictly
    inside ``surface``'s domain by more than ``margin`` (surface units): a run ends
    (``left_domain``) where its tip's centre comes within
    :attr:`~spine_mj.sim.detection.Detection.domain_margin_m` (the tip radius) of an edge,
    so a start on the edge, or nearer than that, would end before it began. Placement
    checks with no margin; a run's entry points, and the sweep's pre-run check, with its
    detection's (:class:`~spine_mj.sim.build.RigPlan`)."""
    xy = np.asarray(starts, dtype=float)
    if xy.size == 0:
        return
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise SpineInputError(f"starts must be (x0, y0) pairs, got an array of shape {xy.shape}")
    xmin, xmax, ymin, ymax = surface.bounds
    x, y = xy[:, 0], xy[:, 1]
    inside = (x > xmin + margin) & (x < xmax - margin) & (y > ymin + margin) & (y < ymax - margin)
    if inside.all():
        return
    x0, y0 = xy[int(np.argmin(inside))]
    domain = f"the surface's domain x in [{xmin:g}, {xmax:g}], y in [{ymin:g}, {ymax:g}]"
    if not surface.contains(x0, y0):
        raise SpineInputError(f"start ({x0:g}, {y0:g}) lies outside {domain}")
    why = f"a run ends (left_domain) where the tip's centre comes within {margin:.3g} (a tip radius) of it"
    if min(x0 - xmin, xmax - x0, y0 - ymin, ymax - y0) == 0:
        more = f" by more than {margin:.3g}: {why}" if margin > 0 else ""
        raise SpineInputError(f"start ({x0:g}, {y0:g}) lies on the edge of {domain}; start inside it{more}")
    raise SpineInputError(
        f"start ({x0:g}, {y0:g}) lies within {margin:.3g} of the edge of {domain}: {why}; "
        "start farther inside"
    )


def check_drive_on(rig, drive: Drive) -> None:
    """Refuse a drive whose inertia number is beyond :data:`MAX_INERTIA_NUMBER`, however it
    was given (an I_e, a speed or a force rate), that advances more than
    :data:`MAX_DRIVE_ADVANCE_PER_STEP` L_c in one time step of this rig, or whose spring
    this rig's step cannot integrate (``omega dt`` above
    :data:`~spine_mj.sim.step_rule.MAX_SPRING_OMEGA_DT`).

    ``rig`` is anything with the ``scales`` and ``engine`` of a rig: a :class:`RigModel`, or
    the :class:`~spine_mj.sim.build.RigPlan` of one not built yet."""
    speed = check_drive_speed(rig.scales, speed_m_s(drive, rig.scales))
    dt, lc = rig.engine.timestep_s, rig.scales.char_length_m
    if speed * dt > MAX_DRIVE_ADVANCE_PER_STEP * lc:
        raise SpineInputError(
            f"the drive advances {speed * dt / lc:.3g} L_c in one time step of {dt:.3g} s (speed "
            f"{speed:.3g} m/s), more than {MAX_DRIVE_ADVANCE_PER_STEP:g}: use a time step of at most "
            f"{MAX_DRIVE_ADVANCE_PER_STEP * lc / speed:.3g} s, or none (derived)"
        )
    if isinstance(drive, SpringDrive):
        k = stiffness_n_m(drive, rig.scales)
        wdt = spring_omega_dt(k, rig.scales.mass_kg, dt)
        if wdt > MAX_SPRING_OMEGA_DT * (1 + 1e-9):
            most = MAX_SPRING_OMEGA_DT / wdt * dt
            raise SpineInputError(
                f"the drive spring (K = {rig.scales.stiffness_number(k):.3g}, k = {k:.3g} N/m) swings "
                f"{wdt:.3g} rad in one time step of {dt:.3g} s, more than {MAX_SPRING_OMEGA_DT:g}: the "
                f"engine integrates it explicitly and would get it wrong; build the rig for this "
                f"stiffness (build_rig(stiffness_number=...)) or use a time step of at most {most:.3g} s"
            )


#: Damping of the tip's y joint that holds it on its line (``EngineSettings.line``), in engine
#: units (F_p per L_c / tau): a lateral force F_y moves it at ``F_y / F_p / RAIL_DAMPING`` L_c
#: per tau (3e-10 m over a 6 cm run across a 0.4-high y slope, tests/sim/test_sim_model.py).
RAIL_DAMPING = 1e9
#: Radius of the touch sensor's zone (the site ``tip_zone``) in tip radii. MuJoCo's touch
#: sensor sums the normal force of each contact whose point lies in the zone (or whose
#: normal ray meets it); a contact point lies within its depth of the tip's surface, and
#: the penetration rule ends a run long before that reaches a tip radius.
TOUCH_ZONE_RADII = 2.0


def hfield_userdata(hf: HField) -> memoryview:
    """``hf``'s samples as MjSpec ``userdata`` wants them, as a buffer MuJoCo copies once
    (4 B a sample): a Python list of them took 32 B a sample more (0.85 GB at 4096 a side,
    the peak of ``simulate --resolution 4096``)."""
    return memoryview(np.ascontiguousarray(hf.data, dtype=np.float32).ravel())


class RigModel:
    """The MuJoCo model of one surface and one tip (parameters as for :class:`~spine_mj.sim.Rig`).

    ``sized``, when given, is ``Scales.with_hfield`` of this surface and tip, computed by
    the caller (:func:`~spine_mj.sim.build.build_rig` needs the scales for the engine
    first): the rig then uses those scales and that hfield instead of measuring again
    (the ``sizing`` keywords are theirs)."""

    def __init__(
        self,
        surface: Surface,
        *,
        tip: TipParams | None = None,
        engine: EngineSettings | None = None,
        sized: tuple[Scales, HField] | None = None,
        **sizing,
    ):
        import mujoco

        self.scales, self.hfield, self.tip = Scales.for_rig(
            surface,
            tip=tip,
            sized=sized,
            **sizing,
        )
        quiet_engine()
        self.surface = surface
        self.length_scale_m = length_scale_m = self.scales.length_scale_m
        self.units = self.scales.units
        self.engine = default_engine(self.scales) if engine is None else engine
        check_engine_for(self.engine, self.scales)
        xmin, xmax, ymin, ymax = surface.bounds
        self.bounds_m = tuple(length_scale_m * b for b in (xmin, xmax, ymin, ymax))
        self.z_range_m = self._z_range_m()
        self.spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
        self._configure_spec()
        self.model = compile_spec(self.spec)
        self._ids()
        self._placer: Placer | None = None
        self._contact = None  # (hfield, its contact surface), see contact_surface
        self._collision_data = None  # (model, MjData) of contacts_at

    # ----------------------------------------------------------------- model building

    def _configure_spec(self) -> None:
        """Options, tip, carriage and the hfield from the engine settings, tip and scales."""
        import mujoco

        spec, eng, tip, u = self.spec, self.engine, self.tip, self.units
        s = self.length_scale_m / u.length_m  # engine lengths per surface unit
        spec.option.timestep = eng.timestep_s / u.time_s
        spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{eng.integrator.name}")
        spec.option.cone = getattr(mujoco.mjtCone, f"mjCONE_{eng.cone.name}")
        spec.option.impratio = eng.impratio
        spec.option.noslip_iterations = eng.noslip_iterations
        spec.option.tolerance = eng.tolerance
        spec.option.noslip_tolerance = eng.noslip_tolerance
        spec.option.gravity = [0.0, 0.0, -tip.gravity_m_s2 / u.acceleration_m_s2]
        spec.modelname = "spine_rig"
        r = tip.tip_radius_m / u.length_m
        tip_geom = spec.geom("tip")
        tip_geom.size = [r, 0, 0]
        tip_geom.mass = tip.mass_kg / u.mass_kg
        spec.site("tip_zone").size = [TOUCH_ZONE_RADII * r, 0, 0]
        car = spec.geom("carriage")
        car.size = [r, r, r]
        if eng.line:
            spec.joint("tip_y").damping = [RAIL_DAMPING, 0.0, 0.0]  # MuJoCo's (linear, 0, 0)
        hf = self.hfield
        rx, ry, elev, base = hf.size
        spec.add_hfield(
            name="surface",
            size=[rx * s, ry * s, elev * s, base * s],
            nrow=hf.nrow,
            ncol=hf.ncol,
            userdata=hfield_userdata(hf),
        )
        geom = spec.worldbody.add_geom(
            name="surface",
            type=mujoco.mjtGeom.mjGEOM_HFIELD,
            hfieldname="surface",
            pos=[p * s for p in hf.pos],
            material="ground",
        )
        for g in (tip_geom, geom):
            g.friction = [tip.mu_s, 0.0, 0.0]
            g.condim = 3
            g.solref = [eng.solref[0] / u.time_s, eng.solref[1]]
            g.solimp = [*eng.solimp[:2], eng.solimp[2] / u.length_m, *eng.solimp[3:]]
        span = max(rx, ry) * s
        spec.visual.map.znear = 1e-4
        spec.stat.extent = 2 * span
        spec.stat.center = [hf.pos[0] * s, hf.pos[1] * s, (hf.pos[2] + elev / 2) * s]

    def _z_range_m(self) -> tuple[float, float]:
        """Lowest and highest point of the hfield [m]."""
        hf, s = self.hfield, self.length_scale_m
        return hf.pos[2] * s, (hf.pos[2] + hf.size[2]) * s

    def _ids(self) -> None:
        """Ids of the geoms and actuators and the sensors' addresses in the compiled model."""
        import mujoco

        m = self.model
        self.geom_tip = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "tip")
        self.geom_surface = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "surface")
        self.act_spring = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "spring")
        self.act_push = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "push")
        self.act_preload = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "preload")
        adr = {}
        for name in SENSOR_NAMES:
            sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, name)
            adr[name] = int(m.sensor_adr[sid])
        self.sensor_adr = adr  # sensor name -> first index in sensordata

    def set_surface(self, surface: Surface) -> None:
        """Replace the surface (same grid size) and recompile in place (``spec.recompile``)."""
        import mujoco

        hf = hfield_of(surface, self.scales.hfield_resolution, self.scales.hfield_refinement)
        if (hf.nrow, hf.ncol) != (self.hfield.nrow, self.hfield.ncol):
            raise SpineInputError(
                f"set_surface needs a {self.hfield.nrow} x {self.hfield.ncol} hfield, "
                f"got {hf.nrow} x {hf.ncol}; build a new Rig instead"
            )
        s = self.length_scale_m / self.units.length_m
        h = self.spec.hfield("surface")
        h.userdata = hfield_userdata(hf)
        h.size = [v * s for v in hf.size]
        self.spec.geom("surface").pos = [p * s for p in hf.pos]
        data = mujoco.MjData(self.model)
        self.model, _ = self.spec.recompile(self.model, data)
        self.surface, self.hfield = surface, hf
        xmin, xmax, ymin, ymax = surface.bounds
        self.bounds_m = tuple(self.length_scale_m * b for b in (xmin, xmax, ymin, ymax))
        self.z_range_m = self._z_range_m()
        self._ids()

    def contact_surface(self) -> BallOnFacets:
        """The surface the tip's centre rides on, in surface units and shifted down by the
        tip radius: MuJoCo's hfield facets (the float32 samples the engine collides with,
        triangulated as MuJoCo does) under a ball of the tip's radius, with the height and
        the contact's slopes computed exactly (:class:`~spine_mj.surfaces.BallOnFacets`).
        A streamline traced on it is the fair reference for this rig (docs/physics.md §4);
        built once per hfield."""
        cached = self._contact
        if cached is None or cached[0] is not self.hfield:
            facets = TriangulatedSurface.from_grid(from_hfield(self.hfield, unit=self.surface.unit))
            cached = (self.hfield, BallOnFacets(facets, self.tip.tip_radius_m / self.length_scale_m))
            self._contact = cached
        return cached[1]

    def contacts_at(self, position_m) -> tuple[np.ndarray, np.ndarray]:
        """The contacts MuJoCo's collision finds with the tip's centre at ``position_m``
        ``(3,)`` [m]: their depths ``(k,)`` [m, > 0 inside] and outward unit normals ``(k,
        3)``. One per hfield prism the tip overlaps (docs/physics.md §5), each with the normal
        of its own prism's penetration, not of the facet's plane: near a cell's edge a
        prism's side wall tilts it (what holds a tip beyond a plane's kappa, the static map's
        edge catch)."""
        import mujoco

        if self._collision_data is None or self._collision_data[0] is not self.model:
            self._collision_data = (self.model, mujoco.MjData(self.model))
        d = self._collision_data[1]
        d.qpos[:3] = np.asarray(position_m, dtype=float) / self.units.length_m
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        normals = np.array([c.frame[:3] for c in d.contact[: d.ncon]]).reshape(-1, 3)
        normals *= np.where(normals[:, 2:] < 0, -1.0, 1.0)  # out of the surface (a height field's: z > 0)
        depths = np.array([-c.dist for c in d.contact[: d.ncon]], dtype=float) * self.units.length_m
        return depths, normals

    def default_start(self) -> tuple[float, float]:
        """The export's and viewer's start (surface units): a tenth of the way in from the
        -x edge, at mid y, so a +x drive has the whole surface ahead of it."""
        xmin, xmax, ymin, ymax = self.surface.bounds
        return xmin + 0.1 * (xmax - xmin), 0.5 * (ymin + ymax)

    def export_spec(self, start: tuple[float, float] | None = None, stiffness_n_m: float | None = None):
        """A copy of the spec ready for MuJoCo's viewer: the tip resting at ``start``, spring on.

        The tip's rest state is the model's reference state (body position and joint
        ``ref``), so a fresh ``MjData`` and a reset both start there; keyframe ``home``
        holds it too (qpos stays the world position). Plain MJCF has no controller, so the
        controls are offsets from that state: ``spring`` is the carriage's displacement
        in +x from the start (L_c; spring of ``stiffness_n_m``, None: the spring drive's
        default ``K = 30``, relaxed at 0), ``push`` a force within +-2 F_p, and the preload
        is built into its actuator's bias. The carriage box marks where the spring starts
        (it does not follow the slider); the camera ``follow`` tracks the tip.
        """
        import mujoco

        x0, y0 = self.default_start() if start is None else start
        qpos = [float(v) for v in self.place(x0, y0)]
        u = self.units
        drive = SpringDrive(speed_m_s=1.0, stiffness_n_m=stiffness_n_m)  # the speed is not used
        k = spring_stiffness_n_m(drive, self.scales) / u.stiffness_n_m
        spec = self.spec.copy()
        tip = spec.body("tip")
        tip.pos = qpos
        for axis, q in zip("xyz", qpos):
            spec.joint(f"tip_{axis}").ref = q
        spring, push, preload = (spec.actuator(n) for n in ("spring", "push", "preload"))
        spring.gainprm[0], spring.biasprm[:2] = k, [k * qpos[0], -k]
        xmin, xmax = (b / u.length_m - qpos[0] for b in self.bounds_m[:2])
        spring.ctrlrange, push.ctrlrange = [xmin, xmax], [-2.0, 2.0]
        spring.ctrllimited = push.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        preload.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        preload.biasprm[0] = -self.tip.preload_n / u.force_n
        r = self.tip.tip_radius_m / u.length_m
        mpos = [qpos[0], qpos[1], qpos[2] + 2 * r]
        spec.body("carriage").pos = mpos
        car = spec.geom("carriage")
        car.size, car.rgba = [0.5 * r] * 3, [0.2, 0.4, 0.9, 0.35]
        spec.add_key(name="home", qpos=qpos, qvel=[0.0] * 3, mpos=mpos, ctrl=[0.0] * 3)
        tip.add_camera(name="follow", mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACK, **_follow_camera(60 * r))
        return spec

    def to_xml(self, start: tuple[float, float] | None = None, stiffness_n_m: float | None = None) -> str:
        """A self-contained MJCF of the rig ready for the viewer (:meth:`export_spec`; the
        hfield inlined as ``elevation``), in engine units."""
        return self.export_spec(start, stiffness_n_m).to_xml()

    def export_xml(
        self,
        path: str | os.PathLike,
        start: tuple[float, float] | None = None,
        stiffness_n_m: float | None = None,
    ) -> Path:
        """Write :meth:`to_xml` to ``path`` atomically; MuJoCo's viewer opens it directly
        (load the keyframe ``home`` to start, move the ``spring`` slider to drive)."""
        path = Path(path)
        with atomic_output(path) as tmp:
            tmp.write_text(self.to_xml(start, stiffness_n_m))
        return path

    def model_for(self, drive: Drive | None):
        """A shallow copy of the model with the drive's spring stiffness (0 for force drives)."""
        m = copy.copy(self.model)
        k = stiffness_n_m(drive, self.scales) if isinstance(drive, SpringDrive) else 0.0
        k /= self.units.stiffness_n_m
        m.actuator_gainprm[self.act_spring, 0] = k
        m.actuator_biasprm[self.act_spring, 1] = -k
        return m

    # ----------------------------------------------------------------- placement

    def place(self, x0: float, y0: float) -> np.ndarray:
        """qpos ``(3,)`` (engine units: metres over ``units.length_m``) with the tip resting on the
        hfield at ``(x0, y0)`` (surface units).

        The sphere centre is found by a safeguarded Newton search in z on the engine's own
        sphere-hfield distance (to 1e-7 tip radii), then lowered by the soft contact's resting depth
        under one contact (:func:`~spine_mj.sim.step_rule.rest_depth_m`): it starts at rest and in
        contact, never dropped (a start just above the surface falls for one step).
        """
        return self.place_many([(x0, y0)])[0]

    def place_many(self, starts) -> np.ndarray:
        """:meth:`place` of many starts (surface units): qpos ``(k, 3)`` in engine units."""
        starts = [(float(x0), float(y0)) for x0, y0 in starts]
        self.check_starts(starts)
        if self._placer is None or self._placer.model is not self.model:
            u = self.units
            self._placer = Placer(
                self.model,
                geom_tip=self.geom_tip,
                surface=self.surface,
                hfield=self.hfield,
                length_scale=self.length_scale_m / u.length_m,
                tip_radius=self.tip.tip_radius_m / u.length_m,
                rest_depth=rest_depth_m(self.engine, self.scales) / u.length_m,
            )
        return self._placer.place_many(starts)

    def check_start(self, x0: float, y0: float, margin_m: float = 0.0) -> None:
        """Raise :class:`SpineInputError` unless ``(x0, y0)`` (surface units) lies inside the
        surface's domain, farther than ``margin_m`` from its edges (:func:`check_starts_on`)."""
        self.check_starts([(x0, y0)], margin_m)

    def check_starts(self, starts, margin_m: float = 0.0) -> None:
        """:meth:`check_start` of many ``(x0, y0)`` at once (the first refused is named)."""
        check_starts_on(self.surface, starts, margin_m / self.length_scale_m)

    # ----------------------------------------------------------------- drive parameters

    def speed_of(self, drive: Drive) -> float:
        """The drive's speed [m/s]: carriage speed, or ``L_c rate / F_p`` for force drives."""
        return speed_m_s(drive, self.scales)

    def inertia_number(self, drive: Drive) -> float:
        """I_e = m v^2 / (F_p L_c) of a drive (equivalent speed for force drives)."""
        return self.scales.inertia_number(self.speed_of(drive))

    def check_drive(self, drive: Drive) -> None:
        """Refuse a drive this rig cannot run (:func:`check_drive_on`)."""
        check_drive_on(self, drive)


def has_mujoco_model(engine: str) -> bool:
    """Whether the registered ``engine``'s rig (:data:`spine_mj.choices.ENGINES`) is a MuJoCo
    model, a :class:`RigModel`: MuJoCo's renderer draws its runs (``simulate --render``), and
    a :class:`~spine_mj.sim.build.RigPlan` checks its cases as its rig would, with nothing
    compiled. MuJoCo's is; Bullet's is not; a third engine on MuJoCo's rig class is too."""
    return issubclass(ENGINES[engine].rig_class(), RigModel)
