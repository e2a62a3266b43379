"""The surfaces' shared rules: length units, size limits (a grid's point count, a random
surface's peak count) and the checks of generator arguments."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from spine_mj._version import __version__
from spine_mj.errors import SpineInputError
from spine_mj.memory import check_memory

#: Mean particle sizes of the sandpapers in the paper's experiment (§3.3), metres.
GRIT_PARTICLE_DIAMETER_M = {"P36": 538e-6, "P60": 269e-6, "P600": 25.8e-6}

#: Metres per unit of the length units a surface may carry, one ASCII spelling each
#: (:func:`length_unit` maps the others onto them); ``unit == "1"`` is dimensionless.
LENGTH_UNITS_M = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "pm": 1e-12}
#: Other spellings of those units: the micro sign (SurfaceTopography's "µm") and Greek mu.
_UNIT_SPELLINGS = {"\u00b5m": "um", "\u03bcm": "um"}

_MIN_POINTS_PER_SIDE = 4
#: Most points a generated or resampled grid may have (512 MiB per float64 array).
MAX_GRID_POINTS = 2**26
#: Most Gaussians of a random surface: every height costs one exponential per Gaussian.
MAX_PEAKS = 100_000
_CHUNK = 1 << 15
# float64 arrays of a grid's size that making and holding one takes at once (check_grid_size)
_GRID_ARRAYS = 4
_NONPERIODIC_PAD = 8  # cells of odd reflection before the spline filter, see GridSurface


def length_unit(unit: str) -> str | None:
    """The spelling of :data:`LENGTH_UNITS_M` for a length unit ("µm" -> "um").

    Parameters
    ----------
    unit : str
        A unit as a file or a user writes it.

    Returns
    -------
    str or None
        The table's spelling, or None when ``unit`` is not one of them (dimensionless "1",
        "A", "km", ...).
    """
    unit = _UNIT_SPELLINGS.get(unit, unit) if isinstance(unit, str) else None
    return unit if unit in LENGTH_UNITS_M else None


def check_unit(unit, name: str = "unit") -> str:
    """``unit`` if a surface may carry it: ``"1"`` (dimensionless) or a length unit of
    :data:`LENGTH_UNITS_M` (in any spelling :func:`length_unit` knows), else a
    :class:`SpineInputError` naming ``name``: refused when a surface is made, not when a
    command later reads its file.

    Parameters
    ----------
    unit : str
        The unit to check.
    name : str
        The argument's name in the error message.

    Returns
    -------
    str
        ``unit``, unchanged.
    """
    if unit != "1" and length_unit(unit) is None:
        raise SpineInputError(
            f"{name} must be '1' (dimensionless) or a length unit {sorted(LENGTH_UNITS_M)}, got {unit!r}"
        )
    return unit


def _rng_and_seed(rng: int | np.random.Generator | None) -> tuple[np.random.Generator, Any]:
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        return np.random.default_rng(), None
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0:
        return np.random.default_rng(int(rng)), int(rng)
    raise SpineInputError(f"rng must be a non-negative int seed or a numpy Generator, got {rng!r}")


def _flag(name: str, value) -> bool:
    """``value`` as a bool: True, False, their numpy forms, 1 or 0; not 3 or "no"."""
    if isinstance(value, str) or value not in (True, False):
        raise SpineInputError(f"{name} must be true or false, got {value!r}")
    return bool(value)


def _pair(name: str, value) -> tuple[float, float]:
    """``value`` as two finite floats, or a :class:`SpineInputError` naming ``name``."""
    try:
        a, b = (float(v) for v in value)
    except (TypeError, ValueError):
        raise SpineInputError(f"{name} must be a pair of numbers, got {value!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise SpineInputError(f"{name} must be finite, got {value!r}")
    return a, b


def _range(name: str, value, *, positive: bool = True) -> tuple[float, float]:
    """``value`` as a finite pair ``(low, high)`` with low <= high (and low > 0 if ``positive``)."""
    lo, hi = _pair(name, value)
    if not lo <= hi:
        raise SpineInputError(f"{name} must be a pair (low, high) with low <= high, got {value!r}")
    if positive and lo <= 0:
        raise SpineInputError(f"{name} must be > 0, got {value!r}")
    return lo, hi


def _bounds(value) -> tuple[float, float, float, float]:
    try:
        xmin, xmax, ymin, ymax = (float(v) for v in value)
    except (TypeError, ValueError):
        raise SpineInputError(f"bounds must be (xmin, xmax, ymin, ymax), got {value!r}") from None
    if not all(math.isfinite(v) for v in (xmin, xmax, ymin, ymax, xmax - xmin, ymax - ymin)):
        raise SpineInputError(f"bounds and their extents must be finite, got {value!r}")
    if not (xmin < xmax and ymin < ymax):
        raise SpineInputError(f"bounds must satisfy xmin < xmax and ymin < ymax, got {value!r}")
    return xmin, xmax, ymin, ymax


def _broadcast_points(x, y) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    return x.ravel(), y.ravel(), x.shape


def _grid_count(name: str, n) -> int:
    """``n`` as a number of grid points a side: an integer in [4, MAX_GRID_POINTS]."""
    ok = isinstance(n, (int, np.integer, float, np.floating)) and not isinstance(n, (bool, np.bool_))
    if not ok or not math.isfinite(n) or int(n) != n or n < _MIN_POINTS_PER_SIDE:
        raise SpineInputError(f"{name} must be an integer >= {_MIN_POINTS_PER_SIDE}, got {n!r}")
    return int(n)


def _count_at_least(name: str, n, least: int) -> int:
    """``n`` as an integer count of at least ``least``."""
    ok = isinstance(n, (int, np.integer, float, np.floating)) and not isinstance(n, (bool, np.bool_))
    if not ok or not math.isfinite(n) or int(n) != n or n < least or n > MAX_GRID_POINTS:
        raise SpineInputError(f"{name} must be an integer in [{least}, {MAX_GRID_POINTS}], got {n!r}")
    return int(n)


def check_grid_size(nx: int, ny: int, *, where: str, nbytes: float | None = None) -> None:
    """Refuse a grid of more than :data:`MAX_GRID_POINTS` points, or one whose arrays
    (:data:`_GRID_ARRAYS` float64 arrays of its size: heights, spline coefficients and the
    temporaries of making them) would exceed the memory budget, before allocating it.

    Parameters
    ----------
    nx, ny : int
        The grid's points along x and y.
    where : str
        What makes the grid, for the message (a generator, a resampling, a file).
    nbytes : float, optional
        The peak bytes of making it, where its maker predicts them (:func:`fractal_fbm`'s
        synthesis); else :data:`_GRID_ARRAYS` float64 arrays of its size.

    Raises
    ------
    SpineInputError
        Naming ``where``, the grid's shape, the limit and the memory one height array
        of that shape would take; or the memory needed and the budget
        (:func:`spine_mj.memory.check_memory`).
    """
    points = float(nx) * float(ny)  # counts may come as floats, before rounding: inf is refused too
    if not points <= MAX_GRID_POINTS:
        gib = points * 8 / 2**30
        raise SpineInputError(
            f"{where}: a {_count(ny)} x {_count(nx)} grid has {points:.3g} points, more than the limit "
            f"{MAX_GRID_POINTS:.3g} ({gib:.3g} GiB per height array); use fewer points or a coarser spacing"
        )
    nbytes = 8.0 * _GRID_ARRAYS * points if nbytes is None else nbytes
    check_memory(nbytes, where=f"{where}: a {_count(ny)} x {_count(nx)} grid")


def _count(n) -> str:
    """A point count for a message: whole numbers as integers, others as floats."""
    n = float(n)
    return str(int(n)) if math.isfinite(n) and n == int(n) and abs(n) < 1e15 else f"{n:.4g}"


def _meta(generator: str, seed, **params) -> dict:
    """A generated surface's metadata: the generator, its seed and every parameter."""
    clean = {k: (list(v) if isinstance(v, tuple) else v) for k, v in params.items()}
    return {"generator": generator, "seed": seed, "params": clean, "spine_mj_version": __version__}
