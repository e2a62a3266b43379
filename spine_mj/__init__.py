"""spine_mj: will a spine hold on this surface, and can the simulation saying so be trusted?

Rough surfaces (:mod:`spine_mj.surfaces`), their import and export
(:mod:`spine_mj.surface_io`), and the recipes in ``surfaces/`` (:mod:`spine_mj.presets`).
The analytic side imports without MuJoCo.
"""

__version__ = "0.1.0"

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import (
    GaussianSurface,
    GridSurface,
    HField,
    Surface,
    fractal_fbm,
    from_hfield,
    random_gaussians,
    sandpaper,
    single_gaussian,
    to_hfield,
)

__all__ = [
    "GaussianSurface",
    "GridSurface",
    "HField",
    "SpineInputError",
    "Surface",
    "__version__",
    "fractal_fbm",
    "from_hfield",
    "random_gaussians",
    "sandpaper",
    "single_gaussian",
    "to_hfield",
]
