"""The numba kernels compiled once, before a job's worker processes need them.

Every kernel is compiled on its first call and kept in numba's on-disk cache (``cache=True``).
On a fresh clone the cache is empty, and the worker processes of a job's first sweep each
compiled the same kernels at once: measured with an empty cache, the smoke plan's first
study took 129 CPU-s (5.6 with the cache warm), twice the ~60 CPU-s the kernels cost to
compile once. :func:`warm_kernels` compiles them first, in groups spread over the job's
worker processes (each writes the cache), then loads them here, so that the workers forked
afterwards inherit them. With the cache already warm it costs the loads (~1 CPU-s).

Each group calls the public entry points on tiny inputs of the types a job passes, so that
the signatures compiled are the ones the job uses.
"""

from __future__ import annotations

import numpy as np

__all__ = ["warm_kernels"]


def _streamline_kernels() -> None:
    """The smooth surfaces' streamline kernel, the Frechet distance and the ball dilation."""
    from spine_mj.surfaces import fractal_fbm
    from spine_mj.surfaces.dilation import dilate
    from spine_mj.theory.agreement import frechet_distance
    from spine_mj.theory.streamline import streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    grid = _grid()
    streamlines(grid, [(-1.0, 0.0)], StreamlineParams(mu=0.5, dl=0.1, max_steps=20))
    dilate(fractal_fbm(nx=16, size=4.0, rng=0), 0.3)
    frechet_distance(np.zeros((3, 2)), np.ones((4, 2)))


def _facet_kernels() -> None:
    """The ball on facets, its streamline and the two-contact rule that answers its pauses."""
    from spine_mj.theory._streamline_numpy import _two_contact_kappa
    from spine_mj.theory.streamline import streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    ball = _ball()
    ball.evaluate(np.array([0.0]), np.array([0.0]), order=1)
    streamlines(ball, [(-1.0, 0.0)], StreamlineParams(mu=0.5, dl=0.1, max_steps=20))
    _two_contact_kappa(*(np.array([v]) for v in (0.1, 0.0, -0.1, 0.0)), 0.5)


def _compliant_kernels() -> None:
    """The compliant reference's compiled loop (on facets, the engine's contact)."""
    from spine_mj.theory.compliant import compliant_streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    compliant_streamlines(
        _ball(), [(-1.0, 0.0)], StreamlineParams(mu=0.5, dl=0.1, max_steps=20), stiffness=1.0
    )


def _engine_kernels() -> None:
    """The engine runs' window analysis: a short spring run on a plane (the rollout's
    strided carriage) and a short force ramp (the ramp's and Bullet's contiguous one)."""
    from spine_mj import presets
    from spine_mj.sim import RampDrive, Rig, SpringDrive

    rig = Rig(presets.make_surface("plane"))
    xmin, xmax, ymin, ymax = rig.surface.bounds
    start = (0.5 * (xmin + xmax), 0.5 * (ymin + ymax))
    rig.run_batch(SpringDrive(speed_m_s=rig.scales.speed_for(1e-2), duration_s=0.01), [start], nthread=1)
    rig.run(RampDrive(duration_s=0.01), start=start)


def _grid():
    from spine_mj.surfaces import fractal_fbm

    return fractal_fbm(nx=16, size=4.0, rms_slope=0.5, rng=0)


def _ball():
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface

    return BallOnFacets(TriangulatedSurface.from_grid(_grid()), 0.3)


#: The groups, about equal in compile time (measured cold on one core: 19, 18, 21 and
#: ~10 CPU-s), the costliest first.
GROUPS = (_compliant_kernels, _streamline_kernels, _facet_kernels, _engine_kernels)


def _warm(index: int) -> None:
    GROUPS[index]()


def warm_kernels(workers: int) -> None:
    """Compile (or load) every group of :data:`GROUPS` on up to ``workers`` processes, then
    load them in this process."""
    from spine_mj.sweep.executors import map_processes

    if workers > 1:
        map_processes(_warm, range(len(GROUPS)), min(workers, len(GROUPS)))
    for group in GROUPS:
        group()
