"""The public names of :mod:`spine_mj.surfaces`, for type checkers and the docs; ``__init__.py``
loads each from its home on first use (``lazy_loader.attach_stub`` reads this file)."""

from .base import GRIT_PARTICLE_DIAMETER_M as GRIT_PARTICLE_DIAMETER_M
from .base import LENGTH_UNITS_M as LENGTH_UNITS_M
from .base import MAX_GRID_POINTS as MAX_GRID_POINTS
from .base import MAX_PEAKS as MAX_PEAKS
from .base import check_grid_size as check_grid_size
from .base import check_unit as check_unit
from .base import length_unit as length_unit
from .dilation import ball_dilation as ball_dilation
from .dilation import ball_dilation_reference as ball_dilation_reference
from .dilation import dilate as dilate
from .facets import BallOnFacets as BallOnFacets
from .facets import TriangulatedSurface as TriangulatedSurface
from .generators import corrugation as corrugation
from .generators import fractal_fbm as fractal_fbm
from .generators import inclined_plane as inclined_plane
from .generators import random_gaussians as random_gaussians
from .generators import single_gaussian as single_gaussian
from .hfield import HField as HField
from .hfield import from_hfield as from_hfield
from .hfield import refine_grid as refine_grid
from .hfield import to_hfield as to_hfield
from .sandpaper import sandpaper as sandpaper
from .tracks import abbm_force_intensity as abbm_force_intensity
from .tracks import abbm_length as abbm_length
from .tracks import abbm_size_range as abbm_size_range
from .tracks import abbm_slope_walk as abbm_slope_walk
from .tracks import abbm_smallest_slip as abbm_smallest_slip
from .tracks import abbm_stiffness_numbers as abbm_stiffness_numbers
from .tracks import abbm_stiffness_range as abbm_stiffness_range
from .tracks import abbm_track as abbm_track
from .types import BSplineGrid as BSplineGrid
from .types import GaussianSurface as GaussianSurface
from .types import GridSurface as GridSurface
from .types import Surface as Surface
