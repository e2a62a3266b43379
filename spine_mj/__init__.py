"""spine_mj: will a spine hold on this surface, and can the simulation saying so be trusted?

The analytic side (surfaces, engagement ratio, streamlines, convexity, comparison metrics)
imports without MuJoCo; the MuJoCo rig (:mod:`spine_mj.sim`) and the sweep runner
(:mod:`spine_mj.sweep`) load on first use of their names.

Modules: :mod:`~spine_mj.surfaces`, :mod:`~spine_mj.surface_io`,
:mod:`~spine_mj.presets`, :mod:`~spine_mj.engagement`, :mod:`~spine_mj.streamline`,
:mod:`~spine_mj.compliant`, :mod:`~spine_mj.drive_limits`,
:mod:`~spine_mj.convexity`, :mod:`~spine_mj.compare`, :mod:`~spine_mj.sim`,
:mod:`~spine_mj.sweep`, :mod:`~spine_mj.reproduce`, :mod:`~spine_mj.cli`.
"""

import importlib

from spine_mj._version import __version__
from spine_mj.compare import (
    capture_rate,
    frechet_distance,
    kappa_agreement,
    mean_lateral_deviation,
    outcome_agreement,
)
from spine_mj.compliant import CompliantResult, compliant_streamlines
from spine_mj.convexity import classify_points, hessian_class, sectional_class
from spine_mj.drive_limits import DriveLimits
from spine_mj.engagement import ENGAGED, SELF_LOCK, SLIP, kappa
from spine_mj.errors import SpineInputError
from spine_mj.presets import list_presets, load_preset, make_surface
from spine_mj.streamline import (
    Outcome,
    StreamlineParams,
    StreamlineResult,
    dilate,
    ideal_trajectories,
    streamlines,
)
from spine_mj.surface_io import import_topography, load_surface, save_surface, write_stl
from spine_mj.surfaces import (
    GaussianSurface,
    GridSurface,
    HField,
    Surface,
    TriangulatedSurface,
    fractal_fbm,
    from_hfield,
    random_gaussians,
    sandpaper,
    single_gaussian,
    to_hfield,
)

_LAZY = {
    name: "spine_mj.sim"
    for name in (
        "Rig",
        "TipParams",
        "EngineSettings",
        "SpringDrive",
        "RampDrive",
        "StaticProbe",
        "Detection",
        "RunResult",
        "EndReason",
        "Cone",
        "Integrator",
        "default_engine",
        "inclined_plane",
    )
}


def __getattr__(name):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'spine_mj' has no attribute {name!r}")


__all__ = [
    "ENGAGED",
    "SELF_LOCK",
    "SLIP",
    "CompliantResult",
    "DriveLimits",
    "GaussianSurface",
    "GridSurface",
    "HField",
    "Outcome",
    "SpineInputError",
    "StreamlineParams",
    "StreamlineResult",
    "Surface",
    "TriangulatedSurface",
    "__version__",
    "capture_rate",
    "classify_points",
    "compliant_streamlines",
    "dilate",
    "fractal_fbm",
    "frechet_distance",
    "from_hfield",
    "hessian_class",
    "ideal_trajectories",
    "import_topography",
    "kappa",
    "kappa_agreement",
    "list_presets",
    "load_preset",
    "load_surface",
    "make_surface",
    "mean_lateral_deviation",
    "outcome_agreement",
    "random_gaussians",
    "sandpaper",
    "save_surface",
    "sectional_class",
    "single_gaussian",
    "streamlines",
    "to_hfield",
    "write_stl",
    *sorted(_LAZY),
]
