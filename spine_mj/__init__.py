"""spine_mj: will a spine hold on this surface, and can the simulation saying so be trusted?

The analytic side (surfaces, engagement ratio, streamlines, convexity, comparison metrics)
imports without MuJoCo; the MuJoCo rig (:mod:`spine_mj.sim`) and the sweep runner
(:mod:`spine_mj.sweep`) load on first use of their names.

Modules: :mod:`~spine_mj.surfaces`, :mod:`~spine_mj.surface_io`,
:mod:`~spine_mj.presets`, :mod:`~spine_mj.theory` (engagement, streamlines, compliant drive,
convexity, drive limits, agreement metrics), :mod:`~spine_mj.sim`,
:mod:`~spine_mj.sweep`, :mod:`~spine_mj.reproduce`, :mod:`~spine_mj.cli`.

``import spine_mj`` itself is light (no numba, pandas, SciPy or MuJoCo): every public name
is imported from its home module on first use (:func:`__getattr__`, :data:`HOMES`), so the
command line starts at once and a user pays only for what they touch.
"""

import importlib
import importlib.util

from spine_mj._version import __version__ as __version__

#: Public name -> the module that defines it (imported on first use of the name).
HOMES = {
    **dict.fromkeys(
        (
            "capture_rate",
            "frechet_distance",
            "kappa_agreement",
            "mean_lateral_deviation",
            "outcome_agreement",
        ),
        "spine_mj.theory.agreement",
    ),
    "compliant_streamlines": "spine_mj.theory.compliant",
    "CompliantResult": "spine_mj.theory.compliant_types",
    **dict.fromkeys(("classify_points", "hessian_class", "sectional_class"), "spine_mj.theory.convexity"),
    "DriveLimits": "spine_mj.theory.drive_limits",
    **dict.fromkeys(("ENGAGED", "SELF_LOCK", "SLIP", "kappa"), "spine_mj.theory.engagement"),
    "SpineInputError": "spine_mj.errors",
    **dict.fromkeys(("list_presets", "load_preset", "make_surface", "open_surface"), "spine_mj.presets"),
    **dict.fromkeys(("Outcome", "StreamlineParams", "StreamlineResult"), "spine_mj.theory.streamline_types"),
    **dict.fromkeys(("ideal_trajectories", "streamlines"), "spine_mj.theory.streamline"),
    "dilate": "spine_mj.surfaces.dilation",
    **dict.fromkeys(
        ("import_topography", "load_surface", "save_surface", "write_stl"), "spine_mj.surface_io"
    ),
    **dict.fromkeys(
        (
            "GaussianSurface",
            "GridSurface",
            "HField",
            "Surface",
            "TriangulatedSurface",
            "fractal_fbm",
            "from_hfield",
            "random_gaussians",
            "sandpaper",
            "single_gaussian",
            "to_hfield",
        ),
        "spine_mj.surfaces",
    ),
    **dict.fromkeys(
        (
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
        ),
        "spine_mj.sim",
    ),
}


def __getattr__(name):
    """A public name from its home (:data:`HOMES`), or a submodule (``spine_mj.sim``) on
    first use."""
    if name in HOMES:
        value = getattr(importlib.import_module(HOMES[name]), name)
        globals()[name] = value
        return value
    if not name.startswith("_") and importlib.util.find_spec(f"spine_mj.{name}") is not None:
        return importlib.import_module(f"spine_mj.{name}")
    raise AttributeError(f"module 'spine_mj' has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})


__all__ = sorted(["__version__", *HOMES])
