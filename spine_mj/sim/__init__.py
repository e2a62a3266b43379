"""MuJoCo rig: any surface as an hfield, a point-like spine tip under gravity, three drives.

The rig (``models/spine_rig.xml``) is a sphere of radius ``tip_radius_m`` on three slide
joints (x, y, z; no rotation) with mass ``mass_kg``, friction ``mu_s`` (condim 3), gravity
and an optional extra downward preload. :class:`Rig` loads that file with ``MjSpec``,
attaches the surface as an hfield through :func:`spine_mj.surfaces.to_hfield` and compiles.

Units. Users give and get SI: a dimensionless surface (``unit == "1"``, the paper's
Gaussian surfaces) is scaled by ``length_scale_m`` (default 1 cm per unit) in x, y and z, a
surface in a length unit ("m", "mm", "um", "nm") by that unit. Positions in results are in
metres; divide by ``rig.length_scale_m`` for surface units. MuJoCo itself works in the
problem's own units (:class:`EngineUnits`: length ``L_c``, force ``F_p = m g + preload``,
mass ``m``, time ``tau = sqrt(m L_c / F_p)``), so a nanometre AFM scan and a centimetre
print are the same kind of model; ``rig.model``, :meth:`Rig.place` and :meth:`Rig.controls`
are in engine units, everything in a :class:`RunResult` is SI.

Scales and default engine settings (:func:`default_engine`). With ``a_p = F_p / mass_kg``
and ``L_c`` the surface's characteristic length (:func:`spine_mj.roughness.characteristic_length`):

* contacts use ``solref = (2 dt, 1)`` (the stiffest stable time constant, critically
  damped) and ``solimp = (0.99, 0.99, ...)``; the resting depth is then
  ``(1 - 0.99) a_p (2 dt)^2 = 0.04 a_p dt^2``, and the deepest contact seen while a drive
  loads the tip stays within a few ``a_p dt^2`` per preload of drive force;
* ``dt = sqrt(0.005 min(r_tip, L_c) / L_c) tau`` (``a_p dt^2 = 0.005 min(r_tip, L_c)``),
  rounded in engine units: resting penetration ``2e-4 min(r_tip, L_c)``; shorter where
  impacts need it, so that a tip arriving at the drive's speed or landing from the
  surface's fall (:func:`~spine_mj.sim.scales.fall_height`: grit flanks, scan-line steps)
  sinks at most half the penetration tolerance;
* ``cone = elliptic`` with ``noslip_iterations = 3``: MuJoCo's friction is soft and creeps
  at any in-cone load without the noslip pass (docs/physics.md §5); ``impratio`` stays 1;
* a run ends as engine trouble (:data:`~spine_mj.sim.detection.TROUBLES`) on a MuJoCo
  warning or a non-finite number anywhere, or, before any physical ending, on a speed
  beyond the energy bound, a tip far below or above the surface, or penetration above
  :func:`~spine_mj.sim.step_rule.penetration_tolerance_m`.

Drives (docs/physics.md §4): :class:`SpringDrive` (a carriage moves at constant speed in +x and
pulls the tip through a spring acting in x only), :class:`RampDrive` (force rises at a set
rate until slip, drops to zero, ramps again once the tip has settled) and
:class:`StaticProbe` (ramp at one point until breakaway, ``kappa_mj = F / F_p``). Each run
reports its inertia number ``I_e = m v^2 / (F_p L_c)``; for the force drives ``v`` is the
equivalent speed ``v_eq = L_c (dF/dt) / F_p`` (the speed at which the tip would cross one
feature in the time the force takes to rise by one preload).

Spring drives and static probes run open loop through :func:`mujoco.rollout.rollout` on
worker threads (a batch of starts or parameter sets at once, each run in pieces continued
from its exact state and stopped once its outcome is decided); the force ramp with reset
needs feedback and steps in Python. The ramp and the static probe fast-forward their
stick phases (:mod:`~spine_mj.sim.fastforward`). Every run ends with a recorded
:class:`EndReason`, never with an exception from the engine.

Modules: :mod:`~spine_mj.sim.records` (the parameter records), :mod:`~spine_mj.sim.scales`
(the scales and hfield), :mod:`~spine_mj.sim.step_rule` (the engine's step rule),
:mod:`~spine_mj.sim.drives`, :mod:`~spine_mj.sim.model` (building the MuJoCo model),
:mod:`~spine_mj.sim.placement`, :mod:`~spine_mj.sim.recording` (per-step columns),
:mod:`~spine_mj.sim.detection` (events, end reasons), :mod:`~spine_mj.sim.results`,
:mod:`~spine_mj.sim.rollout` (open-loop batches, on :mod:`~spine_mj.sim.open_loop`'s
controls and :mod:`~spine_mj.sim.lanes`' worker threads), :mod:`~spine_mj.sim.ramp` (closed loop),
:mod:`~spine_mj.sim.fastforward` (the stick-phase fast-forward rule both use),
:mod:`~spine_mj.sim.engine_rig` (:class:`EngineRig`, what a rig of every engine offers),
:mod:`~spine_mj.sim.bullet` (the same rig in Bullet, hard contact; the ``[bullet]`` extra),
:mod:`~spine_mj.sim.render`, :mod:`~spine_mj.sim.rig`
(:class:`Rig`, the object users hold) and :mod:`~spine_mj.sim.build` (:func:`build_rig` and
:func:`build_drive`: a rig and a drive from dimensionless or SI inputs, the rig's in one
record, :class:`RigInputs` of :mod:`~spine_mj.sim.rig_inputs`) and
:mod:`~spine_mj.sim.holding` (an array's predicted holding excess and its default pace).
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
