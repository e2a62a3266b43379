"""Spine arrays in MuJoCo: many tips on one carriage, each on its own suspension.

:class:`ArrayRig` turns a single-spine :class:`~spine_mj.sim.model.RigModel` (its surface,
tip, scales and engine settings: the one rule of :mod:`spine_mj.sim.scales`, taken as it
is) into one MuJoCo model of ``N`` tips laid out by a :class:`~spine_mj.sim.layout.Layout`.
Each tip is the single rig's sphere on x, y, z slide joints with its own preload; tips
collide with the surface only, never with each other. Each is tied to the carriage by a
spring along the drive (the single rig's suspension; the normal stays a constant preload,
the zero-stiffness limit the quasistatic theory assumes, so that one spine of the array is
exactly the single rig). A spring gives at most ``kappa_cap F_p``: a spine held there while
stuck is self-locked (the single rig's criterion) and carries that much, no more.

Two drives:

* displacement control (:class:`~spine_mj.sim.drives.SpringDrive`): the carriage moves at
  constant speed; each spring's far end follows it (the single rig's spring drive, ``I_e``
  and ``K`` per spine as there). The array's force is the sum of its spines'.
* force control (:class:`ForcePull`): the carriage is a body on an x slide of mass ``N m``
  pulled by a force rising at ``N`` times the single ramp's rate; the springs run from it to
  the tips (a tendon ``x_i - X`` each), so when one spine slips its load passes to the others.

Runs are batched: many placements of one array go through :func:`mujoco.rollout.rollout`
on worker threads, each in pieces continued from its exact state and warm start
(:mod:`spine_mj.sim.rollout`'s lanes), analysed after every piece and stopped once decided.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.sim.array_run import HOLD_FRACTION, ArrayBatch, ArrayDrive, ArrayResult, ForcePull
from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import SpringDrive, StaticProbe, rate_n_s, settle_steps, stiffness_n_m
from spine_mj.sim.lanes import NativeLanes, PythonLane
from spine_mj.sim.layout import Layout
from spine_mj.sim.model import RigModel, compile_spec, start_pair
from spine_mj.sim.open_loop import drive_steps

#: Why arrays run in MuJoCo only: an array is one MuJoCo model (N tips on slide joints, their
#: springs, a free carriage body tied to them by tendons under force control) stepped in
#: batches by MuJoCo's rollout; Bullet's rig is one tip stepped in Python, and an array there
#: would need its own N-body world and carriage coupling.
ARRAY_ENGINE_REFUSAL = (
    "engine {engine}: spine arrays run in MuJoCo only (one MuJoCo model of N tips and their "
    "carriage; the {engine} rig is one tip): use engine mujoco for arrays"
)


def spines_on_surface(layout: Layout, spacing: float, offsets, centres, bounds, margin: float) -> np.ndarray:
    """The spines' starts ``(n_centres, N, 2)`` (surface units) of arrays of ``offsets``
    (the layout's at ``spacing``, surface units) centred at each of ``centres``, or the
    refusal of the first spine outside ``bounds`` or closer to their edge than ``margin``
    (two tip radii: :meth:`ArrayRig.starts`; the sweep's pre-run check of every centre)."""
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    xy = np.asarray(offsets, dtype=float)[None, :, :] + centres[:, None, :]
    xmin, xmax, ymin, ymax = bounds
    x, y = xy[..., 0], xy[..., 1]
    inside = (x >= xmin + margin) & (x <= xmax - margin) & (y >= ymin + margin) & (y <= ymax - margin)
    if not inside.all():
        c, i = np.unravel_index(int(np.argmin(inside)), inside.shape)
        x0, y0 = xy[c, i]
        cx, cy = centres[c]
        lx, ly = layout.footprint(spacing)
        raise SpineInputError(
            f"spacing {layout.spacing:g} {layout.spacing_unit.value} puts spine ({x0:.4g}, "
            f"{y0:.4g}) outside the surface {tuple(bounds)} (footprint {lx:.4g} x {ly:.4g} "
            f"surface units, centre ({cx:.4g}, {cy:.4g})): lower the spacing or the number of spines"
        )
    return xy


class ArrayRig:
    """One MuJoCo model of an array of spines on ``rig``'s surface (see the module docstring).

    Parameters
    ----------
    rig : RigModel
        The single-spine rig whose surface, tip, scales and engine settings the array uses.
    layout : Layout
        How many spines, in which pattern, at which spacing.
    force_control : bool
        Build the free carriage of :class:`ForcePull` (else the moving anchors of a spring drive).

    Raises
    ------
    SpineInputError
        A random layout that cannot keep its tips apart.
    """

    def __init__(self, rig: RigModel, layout: Layout, *, force_control: bool = False):
        if not isinstance(rig, RigModel):
            raise SpineInputError(ARRAY_ENGINE_REFUSAL.format(engine=type(rig).__name__))
        if not isinstance(layout, Layout):
            raise SpineInputError(f"layout must be a Layout, got {type(layout).__name__}")
        if rig.engine.line:
            raise SpineInputError(
                "line holds one tip on its line, not an array's spines: build the rig without it"
            )
        self.rig, self.layout, self.force_control = rig, layout, bool(force_control)
        sc, s = rig.scales, rig.length_scale_m
        self.spacing = layout.spacing_in_surface_units(
            l_s=sc.slope_length_m / s, l_c=sc.char_length_m / s
        )  # surface units
        self.offsets = layout.offsets(self.spacing, tip_radius=rig.tip.tip_radius_m / s)
        self.n = layout.n_spines
        self.spec = self._build_spec()
        self.model = compile_spec(self.spec)
        self.nstate = _state_size(self.model)

    # ----------------------------------------------------------------- model

    def _build_spec(self):
        """The single rig's spec with its tip, carriage, actuators and sensors replaced by
        ``N`` tips, their springs and preloads (and the free carriage and its pull)."""
        import mujoco

        rig, n = self.rig, self.n
        spec = rig.spec.copy()
        tip = spec.geom("tip")
        look = {
            k: copy.copy(getattr(tip, k)) for k in ("size", "mass", "friction", "condim", "solref", "solimp")
        }
        for s in list(spec.sensors):
            spec.delete(s)
        for a in list(spec.actuators):
            spec.delete(a)
        spec.delete(spec.body("tip"))
        spec.delete(spec.body("carriage"))
        surface = spec.geom("surface")
        surface.contype, surface.conaffinity = 1, 2  # tips (2, 1) touch the surface, not each other
        slide = mujoco.mjtJoint.mjJNT_SLIDE
        for i in range(n):
            body = spec.worldbody.add_body(name=f"tip{i}")
            for axis, vec in zip("xyz", np.eye(3)):
                body.add_joint(name=f"tip{i}_{axis}", type=slide, axis=vec)
            g = body.add_geom(name=f"tip{i}", type=mujoco.mjtGeom.mjGEOM_SPHERE, rgba=[0.85, 0.2, 0.15, 1])
            for k, v in look.items():
                setattr(g, k, v)
            g.contype, g.conaffinity = 2, 1
        if self.force_control:
            car = spec.worldbody.add_body(name="carriage")
            car.add_joint(name="carriage_x", type=slide, axis=[1, 0, 0])
            r = look["size"][0]
            car.add_geom(
                name="carriage",
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[r, r, r],
                mass=1.0,
                contype=0,
                conaffinity=0,
            )
            for i in range(n):
                t = spec.add_tendon(name=f"suspension{i}")
                t.wrap_joint(f"tip{i}_x", 1.0)
                t.wrap_joint("carriage_x", -1.0)
        for i in range(n):  # springs: force kp (ctrl - length), length x_i or x_i - X
            a = spec.add_actuator(name=f"spring{i}")
            if self.force_control:
                a.trntype, a.target = mujoco.mjtTrn.mjTRN_TENDON, f"suspension{i}"
            else:
                a.trntype, a.target = mujoco.mjtTrn.mjTRN_JOINT, f"tip{i}_x"
            a.gaintype, a.biastype = mujoco.mjtGain.mjGAIN_FIXED, mujoco.mjtBias.mjBIAS_AFFINE
            a.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            a.forcerange = [-1.0, 1.0]  # set by model_for: kappa_cap F_p
        for i in range(n):  # the preload: a constant force, as the single rig's
            a = spec.add_actuator(name=f"preload{i}", target=f"tip{i}_z", trntype=mujoco.mjtTrn.mjTRN_JOINT)
            a.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            a.biasprm[0] = -rig.tip.preload_n / rig.units.force_n
        if self.force_control:
            spec.add_actuator(name="pull", target="carriage_x", trntype=mujoco.mjtTrn.mjTRN_JOINT)
        spec.modelname = "spine_array"
        return spec

    def model_for(self, drive: ArrayDrive, det: Detection):
        """A shallow copy of the model with the drive's springs (capped at ``kappa_cap F_p``)
        and carriage mass."""
        rig = self.rig
        m = copy.copy(self.model)
        k = stiffness_n_m(drive, rig.scales) / rig.units.stiffness_n_m
        cap = det.kappa_cap * rig.scales.preload_n / rig.units.force_n
        springs = slice(0, self.n)
        m.actuator_gainprm[springs, 0] = k
        m.actuator_biasprm[springs, :3] = [0.0, -k, 0.0]
        m.actuator_forcerange[springs] = [-cap, cap]
        if self.force_control:
            mass = drive.carriage_mass_kg or self.n * rig.tip.mass_kg
            m.body_mass[m.nbody - 1] = mass / rig.units.mass_kg
        return m

    # ----------------------------------------------------------------- placement

    def starts(self, centre: tuple[float, float]) -> np.ndarray:
        """The spines' starts ``(N, 2)`` (surface units) of the array centred at ``centre``.

        Raises
        ------
        SpineInputError
            A spine outside the surface, or closer to its edge than a tip radius.
        """
        margin = 2 * self.rig.tip.tip_radius_m / self.rig.length_scale_m
        return spines_on_surface(
            self.layout, self.spacing, self.offsets, [start_pair(centre)], self.rig.surface.bounds, margin
        )[0]

    def default_centre(self) -> tuple[float, float]:
        """The centre that puts the array's rearmost spines a tenth of the way in from the
        surface's -x edge, at mid y (the single rig's default start)."""
        xmin, xmax, ymin, ymax = self.rig.surface.bounds
        return xmin + 0.1 * (xmax - xmin) - float(self.offsets[:, 0].min()), 0.5 * (ymin + ymax)

    # ----------------------------------------------------------------- running

    def run(self, drive: ArrayDrive, *, centre=None, detection: Detection | None = None, **kw) -> ArrayResult:
        """One run of the array centred at ``centre`` (None: :meth:`default_centre`)."""
        centre = self.default_centre() if centre is None else centre
        return self.run_batch(drive, [centre], detection=detection, **kw)[0]

    def run_batch(
        self,
        drive: ArrayDrive,
        centres: Sequence[tuple[float, float]],
        *,
        detection: Detection | None = None,
        backend: str = "rollout",
        nthread: int | None = None,
    ) -> list[ArrayResult]:
        """Run the array at each centre (surface units): one batch through the native rollout
        (``backend="rollout"``, ``nthread`` worker threads, default all cores) or the plain
        ``mj_step`` reference (``"python"``). Each run stops once decided (module docstring)."""
        if self.force_control != isinstance(drive, ForcePull):
            want = "ForcePull" if self.force_control else "SpringDrive"
            raise SpineInputError(f"this array was built for a {want}, got {type(drive).__name__}")
        if backend not in ("rollout", "python"):
            raise SpineInputError(f"backend must be 'rollout' or 'python', got {backend!r}")
        det = (Detection() if detection is None else detection).resolve(self.rig.scales)
        starts = [self.starts(c) for c in centres]
        import os

        nthread = (os.cpu_count() or 1) if nthread is None else max(1, int(nthread))
        lanes = NativeLanes(nthread) if backend == "rollout" else PythonLane()
        try:
            return ArrayBatch(self, drive, starts, det).run(lanes)
        finally:
            lanes.close()

    def plan(self, drive: ArrayDrive, starts: np.ndarray, det: Detection) -> tuple[int, int]:
        """(settle steps, total steps) of a run from ``starts`` (surface units)."""
        rig = self.rig
        dt = rig.engine.timestep_s
        ns = settle_steps(drive, dt)
        if isinstance(drive, SpringDrive):
            front = float(starts[:, 0].max()) * rig.length_scale_m
            return ns, ns + drive_steps(rig, drive, front, det)
        rate = self.pull_rate_n_s(drive)
        rig.check_drive(StaticProbe(rate_n_s=rate / self.n))
        steps = (det.kappa_cap * rig.scales.preload_n - drive.start_force_n) / (rate / self.n) / dt
        if not (math.isfinite(steps) and steps < 2**22):
            raise SpineInputError(
                f"a force pull at {rate:.3g} N/s would take {steps:.3g} steps: raise its rate"
            )
        return ns, ns + int(math.ceil(steps * (1 + HOLD_FRACTION))) + 1

    def pull_rate_n_s(self, drive: ForcePull) -> float:
        """The pull's rate on the whole array [N/s] (``N`` times the per-spine rate)."""
        return self.n * rate_n_s(StaticProbe(rate_n_s=drive.rate_n_s), self.rig.scales)


def _state_size(model) -> int:
    import mujoco

    return mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)


__all__ = ["ArrayRig"]
