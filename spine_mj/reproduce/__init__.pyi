"""The public names of :mod:`spine_mj.reproduce`, for type checkers and the docs; ``__init__.py``
loads each from its home on first use (``lazy_loader.attach_stub`` reads this file)."""

from .fractal import fig9_rms_height as fig9_rms_height
from .fractal import fig9_seeds as fig9_seeds
from .fractal import fractal_hurst as fractal_hurst
from .fractal import raw_rms_height as raw_rms_height
from .random_gaussian import random_gaussian as random_gaussian
from .registry import REPRODUCTIONS as REPRODUCTIONS
from .registry import run as run
from .registry import run_to as run_to
from .single_peak import calibrate_single_peak_mu as calibrate_single_peak_mu
from .single_peak import kappa_map as kappa_map
from .single_peak import kappa_map_to as kappa_map_to
from .single_peak import single_peak as single_peak
