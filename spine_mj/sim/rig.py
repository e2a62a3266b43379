"""The user-facing rig: one surface and one tip, ready to run drives.

:class:`Rig` is the compiled model (:class:`~spine_mj.sim.model.RigModel`: building,
surface swaps, export, placement) plus thin methods that hand each kind of run to its
module: open-loop batches to :mod:`~spine_mj.sim.rollout`, the force ramp with reset to
:mod:`~spine_mj.sim.ramp`, frames to :mod:`~spine_mj.sim.render`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from spine_mj.sim.detection import Detection
from spine_mj.sim.drives import Drive, RampDrive
from spine_mj.sim.gpu import run_batch_gpu
from spine_mj.sim.model import RigModel
from spine_mj.sim.open_loop import controls
from spine_mj.sim.ramp import run_ramp
from spine_mj.sim.render import render_frames
from spine_mj.sim.results import RunResult
from spine_mj.sim.rollout import BatchOptions, batch_drives, run_batch

#: A run stopped on penetration is run once more at this fraction of the time step and
#: contact time constant (``Rig.run_batch``, ``refine``). The engine rule bounds the
#: landings it can foresee (twice the drive's speed, falls off the surface's steps); a hop
#: thrown by the spring's release at a breakaway can land faster (measured: a fractal run
#: at I_e = 1e-4 landing at 0.19 m/s, 1.14 tolerances deep). A result's ``engine`` says
#: which step it ran at.
REFINE_TIMESTEP = 0.25


class Rig(RigModel):
    """The MuJoCo model of one surface and one tip, ready to run drives.

    Parameters
    ----------
    surface : Surface
        Any surface; dimensionless ones are scaled by ``length_scale_m``.
    tip : TipParams
        The tip: radius, mass, friction, preload.
    engine : EngineSettings or None
        None: :func:`default_engine` of the scales.
    sized : (Scales, HField) or None
        ``Scales.with_hfield`` of this surface and tip when the caller already has them
        (:func:`~spine_mj.sim.build.build_rig`); None measures them here.
    **sizing
        Without ``sized``, the keywords of :meth:`~spine_mj.sim.scales.Scales.with_hfield`
        (``length_scale_m``, ``char_length_m``, ``hfield_resolution``; None: their rules).

    Raises
    ------
    SpineInputError
        Bad parameters, a surface in another unit, or a surface too coarse for the tip
        (hfield spacing > 2 tip radii: the sphere would see single facets and their kinks).

    Notes
    -----
    Default tip radius: ``surface.metadata["params"]["tip_radius_m"]`` if the surface has
    one (sandpaper), the larger of two lateral spacings and ``L_c / 100`` for a measured
    scan, else the larger of one hfield spacing and ``L_c / 100``
    (:meth:`~spine_mj.sim.scales.Scales.for_surface`).
    """

    def run(
        self,
        drive: Drive,
        *,
        start: tuple[float, float],
        detection: Detection | None = None,
        backend: str = "rollout",
        progress: Callable[[float], None] | None = None,
    ) -> RunResult:
        """Run one drive from ``start`` (surface units).

        ``backend`` "rollout" (native) or "python" (a plain ``mj_step`` loop, the reference
        implementation); the force ramp with reset always steps in Python. ``progress``
        receives the fraction done (Python backends only).
        """
        if isinstance(drive, RampDrive):
            return run_ramp(self, drive, start, detection, progress)
        return self.run_batch([drive], [start], detection=detection, backend=backend)[0]

    def run_batch(
        self,
        drives: Drive | Sequence[Drive],
        starts: Sequence[tuple[float, float]],
        *,
        detection: Detection | None = None,
        backend: str = "rollout",
        nthread: int | None = None,
        stop_early: bool = True,
        refine: bool = True,
    ) -> list[RunResult]:
        """Run many starts and/or drive parameter sets of this model.

        ``drives`` is one drive for all starts or one per start (SpringDrive or StaticProbe;
        mixed kinds are allowed). Runs go through :func:`mujoco.rollout.rollout` on
        ``nthread`` worker threads (default: CPU count), in groups of equal planned length
        sized to stay within 256 MiB of output, each run in pieces continued from its exact
        state (:mod:`spine_mj.sim.rollout`); each run is cut at its first end event.
        ``stop_early``: a run is not simulated past the piece in which its outcome was
        decided (self-lock, left the domain, engine trouble, a probe's breakaway or slide);
        its recording and ending are those of the whole run, except that engine trouble
        after the ending goes unseen. False simulates every planned step (the reference).
        While the worker threads simulate, the calling thread analyses and places tips; the
        results are those of one run at a time. The arrays of a result are read-only views
        of its group's columns.

        ``backend``: ``"rollout"`` (native CPU threads), ``"python"`` (the plain reference
        loop), ``"gpu"`` (MuJoCo Warp on a CUDA device, :mod:`spine_mj.sim.gpu`; the
        ``[gpu]`` extra) or ``"auto"`` (the GPU where one is present, else the CPU rollout).

        ``refine``: each run that stopped on penetration is run once more on a copy of this
        rig at :data:`REFINE_TIMESTEP` of its step (a landing the engine rule did not
        foresee); its result replaces the stopped one (CPU backends).
        """
        return self.run_batch_with(
            drives,
            starts,
            BatchOptions(
                detection=detection, backend=backend, nthread=nthread, stop_early=stop_early, refine=refine
            ),
        )

    def run_batch_with(
        self, drives: Drive | Sequence[Drive], starts: Sequence[tuple[float, float]], options: BatchOptions
    ) -> list[RunResult]:
        """:meth:`run_batch` with its options as one record (and a GPU ``device``)."""
        if options.backend in ("gpu", "auto"):
            return run_batch_gpu(self, drives, starts, options)
        runs = run_batch(self, drives, starts, options)
        redo = [i for i, r in enumerate(runs) if r.engine_trouble == "penetration"]
        if not options.refine or not redo:
            return runs
        drive_list, start_list = batch_drives(drives, starts)
        again = self.refined().run_batch_with(
            [drive_list[i] for i in redo],
            [start_list[i] for i in redo],
            dataclasses.replace(options, refine=False),
        )
        runs = list(runs)
        for i, run in zip(redo, again):
            runs[i] = run
        return runs

    def refined(self, factor: float = REFINE_TIMESTEP) -> Rig:
        """A copy of this rig whose time step and contact time constant are ``factor`` times
        this one's (same surface, tip, scales and other engine settings)."""
        e = self.engine
        engine = dataclasses.replace(
            e, timestep_s=factor * e.timestep_s, solref=(factor * e.solref[0], e.solref[1])
        )
        return Rig(self.surface, tip=self.tip, engine=engine, sized=(self.scales, self.hfield))

    def controls(self, drive: Drive, qpos0: np.ndarray, detection: Detection) -> np.ndarray:
        """Open-loop controls ``(nstep, 6)`` of a run from the placed start ``qpos0``.

        Columns: ctrl (spring, push, preload) then mocap xyz; ``detection`` resolved
        (:meth:`Detection.resolve`). See :func:`spine_mj.sim.rollout.controls`.
        """
        return controls(self, drive, qpos0, detection)

    def render_frames(self, result: RunResult, *, fps: float = 30.0, width: int = 640, height: int = 480):
        """Yield RGB frames ``(height, width, 3)`` uint8 of a run (headless, needs a GL backend)."""
        return render_frames(self, result, fps=fps, width=width, height=height)
