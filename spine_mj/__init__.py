"""spine_mj: will a spine hold on this surface, and can the simulation saying so be trusted?

The analytic side (surfaces, engagement ratio, streamlines, convexity, comparison metrics)
imports without MuJoCo; the MuJoCo rig (:mod:`spine_mj.sim`) and the sweep runner
(:mod:`spine_mj.sweep`) load on first use of their names.

Modules: :mod:`~spine_mj.surfaces`, :mod:`~spine_mj.surface_io`,
:mod:`~spine_mj.presets`, :mod:`~spine_mj.theory` (engagement, streamlines, compliant drive,
convexity, drive limits), :mod:`~spine_mj.compare`, :mod:`~spine_mj.sim`,
:mod:`~spine_mj.sweep`, :mod:`~spine_mj.reproduce`, :mod:`~spine_mj.cli`.

Modules that moved keep their old import paths (``import spine_mj.streamline``,
``from spine_mj.engagement import kappa``): :data:`MOVED` maps each old name to its home,
and an import finder hands out the module from there (the same module object, imported on
first use).
"""

import importlib
import importlib.abc
import importlib.util
import sys

from spine_mj._version import __version__
from spine_mj.compare import (
    capture_rate,
    frechet_distance,
    kappa_agreement,
    mean_lateral_deviation,
    outcome_agreement,
)
from spine_mj.errors import SpineInputError
from spine_mj.presets import list_presets, load_preset, make_surface
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
from spine_mj.theory.compliant import CompliantResult, compliant_streamlines
from spine_mj.theory.convexity import classify_points, hessian_class, sectional_class
from spine_mj.theory.drive_limits import DriveLimits
from spine_mj.theory.engagement import ENGAGED, SELF_LOCK, SLIP, kappa
from spine_mj.theory.streamline import (
    Outcome,
    StreamlineParams,
    StreamlineResult,
    dilate,
    ideal_trajectories,
    streamlines,
)

#: Old module name -> the module's home (imports by the old name get the same module).
MOVED = {
    **{
        f"spine_mj.{name}": f"spine_mj.theory.{name}"
        for name in (
            "engagement",
            "streamline",
            "compliant",
            "convexity",
            "multicontact",
            "tomlinson",
            "tomlinson_dynamics",
            "drive_limits",
            "energy",
            "array_reference",
            "_kernels",
            "_compliant_kernel",
        )
    },
    "spine_mj._contact_kernel": "spine_mj.surfaces._contact_kernel",
    "spine_mj.array_outputs": "spine_mj.sim.array_outputs",
}


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Import finder for :data:`MOVED`: the old name's entry in ``sys.modules`` is the module
    at its home, so ``spine_mj.streamline is spine_mj.theory.streamline``."""

    def find_spec(self, fullname, path=None, target=None):
        return importlib.util.spec_from_loader(fullname, self) if fullname in MOVED else None

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        # the import system returns what sys.modules holds under the name after this call
        sys.modules[module.__name__] = importlib.import_module(MOVED[module.__name__])


if not any(isinstance(f, _MovedModules) for f in sys.meta_path):
    sys.meta_path.append(_MovedModules())

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
    if f"spine_mj.{name}" in MOVED:
        return importlib.import_module(f"spine_mj.{name}")
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
