"""Long tracks uniform in y for stick-slip studies: the ABBM track, whose slope along x is
a random walk (docs/physics.md §12).

A tip pulled along x over a profile ``z = f(x)`` meets the landscape force
``F(x) = W tan(theta(x) + arctan mu)``, ``tan theta = f'``; for small slopes
``F ~ W (mu + (1 + mu^2) f')``. When ``f'`` is a random walk,
``<(f'(x) - f'(x'))^2> = 2 D |x - x'|``, the force is one too, with intensity
``sigma = W^2 (1 + mu^2)^2 D`` (:func:`abbm_force_intensity`): the
Alessandro-Beatrice-Bertotti-Montorsi (ABBM) model, whose slips have closed-form
statistics. An unbounded walk would steepen the track without limit, so the slope here is
an Ornstein-Uhlenbeck process of correlation length ``xi``: a random walk of intensity
``D`` below ``xi``, stationary with rms ``sqrt(D xi)`` beyond it. ABBM holds for slips
between the grid spacing and ``xi`` (:func:`abbm_size_range`).
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.surfaces.base import (
    _MIN_POINTS_PER_SIDE,
    _count_at_least,
    _meta,
    _rng_and_seed,
    check_grid_size,
)
from spine_mj.surfaces.types import GridSurface

__all__ = ["abbm_force_intensity", "abbm_size_range", "abbm_slope_walk", "abbm_track"]

#: Largest rms slope of a track: slopes stay well inside (-mu, 1 / mu) at every mu >= 0.5
#: over ten standard deviations (engaged, never self-locking).
MAX_RMS_SLOPE = 0.15


def abbm_slope_walk(
    n: int, spacing: float, slope_intensity: float, correlation_length: float, rng: np.random.Generator
) -> np.ndarray:
    """``n`` slopes ``f'`` a ``spacing`` apart: the exact discretization of an
    Ornstein-Uhlenbeck process, ``s[i+1] = a s[i] + sqrt(D xi (1 - a^2)) N(0, 1)``,
    ``a = exp(-spacing / xi)``, started from its stationary law N(0, D xi). Below ``xi``
    its increments have variance ``2 D |dx|`` (to first order in ``dx / xi``): a random
    walk of intensity ``D = slope_intensity``.

    Parameters
    ----------
    n : int
        Number of slopes.
    spacing : float
        Distance between them, in surface units.
    slope_intensity : float
        ``D``, the walk's intensity (per surface unit).
    correlation_length : float
        ``xi``, in surface units: beyond it the slope stops wandering.
    rng : numpy.random.Generator
        The source of the walk's noise.

    Returns
    -------
    numpy.ndarray
        The ``n`` slopes.
    """
    a = math.exp(-spacing / correlation_length)
    var = slope_intensity * correlation_length
    noise = rng.standard_normal(n)
    noise[1:] *= math.sqrt(var * (1 - a * a))
    noise[0] *= math.sqrt(var)
    from scipy.signal import lfilter

    return lfilter([1.0], [1.0, -a], noise)


def abbm_track(
    *,
    length: float = 400.0,
    points: int = 4001,
    width: float = 1.0,
    slope_intensity: float = 1e-4,
    correlation_length: float = 100.0,
    rng: int | np.random.Generator | None = None,
) -> GridSurface:
    """An ABBM track: a strip uniform in y whose slope along x is a random walk of
    intensity ``slope_intensity`` (an Ornstein-Uhlenbeck slope of correlation length
    ``correlation_length``, see the module's docstring). Dimensionless.

    Heights are the trapezoid integral of the slopes, with their mean removed; x runs from
    0 to ``length`` over ``points`` samples; y spans ``width`` centred on 0 with at least
    four rows. The slope correlation length ``l_s`` (:mod:`spine_mj.roughness`) is
    ``correlation_length`` for a track many times longer; the height's rms grows with the
    length (the integral of a walk), so ``L_c`` is a sizable part of the track.

    Parameters
    ----------
    length : float
        Extent in x, > 0.
    points : int
        Samples along x, >= 16.
    width : float
        Extent in y, > 0.
    slope_intensity : float
        ``D`` > 0 [1 / length]: ``<(f'(x) - f'(x'))^2> = 2 D |x - x'|`` below the
        correlation length.
    correlation_length : float
        ``xi``, > 0 and at most ``length``; the rms slope ``sqrt(D xi)`` must not exceed
        :data:`MAX_RMS_SLOPE`.
    rng : int or Generator, optional
        Seed.

    Returns
    -------
    GridSurface
    """
    size = check_positive("length", length)
    nx = _count_at_least("points", points, 16)
    w = check_positive("width", width)
    d = check_positive("slope_intensity", slope_intensity)
    xi = check_positive("correlation_length", correlation_length)
    if xi > size:
        raise SpineInputError(
            f"correlation_length must be at most the length {size!r}, got {correlation_length!r}"
        )
    if not math.sqrt(d * xi) <= MAX_RMS_SLOPE:
        raise SpineInputError(
            f"slope_intensity x correlation_length must give an rms slope of at most {MAX_RMS_SLOPE}, "
            f"got sqrt({d!r} x {xi!r}) = {math.sqrt(d * xi):.3g}"
        )
    gen, seed = _rng_and_seed(rng)
    dx = size / (nx - 1)
    ny = max(_MIN_POINTS_PER_SIDE, int(math.ceil(w / dx)) + 1)
    check_grid_size(nx, ny, where="abbm_track")
    slope = abbm_slope_walk(nx, dx, d, xi, gen)
    z = np.concatenate([[0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * dx)])
    z -= z.mean()
    x = np.linspace(0.0, size, nx)
    y = np.linspace(-w / 2, w / 2, ny)
    return GridSurface(
        heights=np.broadcast_to(z, (ny, nx)).copy(),
        x=x,
        y=y,
        periodic=False,
        unit="1",
        metadata=_meta(
            "abbm_track",
            seed,
            length=size,
            points=nx,
            width=w,
            slope_intensity=d,
            correlation_length=xi,
        ),
    )


def abbm_force_intensity(slope_intensity: float, mu: float, load: float = 1.0) -> float:
    """``sigma = W^2 (1 + mu^2)^2 D``: the intensity of the landscape force's walk,
    ``<(F(x) - F(x'))^2> = 2 sigma |x - x'|``, from ``F = W tan(theta + arctan mu)``
    linearized at zero slope (``dF/df' = W (1 + mu^2)``).

    Parameters
    ----------
    slope_intensity : float
        ``D`` of the slope's walk (:func:`abbm_slope_walk`).
    mu : float
        The tip's friction coefficient.
    load : float
        The preload ``W`` (1: forces in units of ``F_p``).

    Returns
    -------
    float
    """
    return load * load * (1 + mu * mu) ** 2 * slope_intensity


def abbm_size_range(spacing: float, correlation_length: float) -> tuple[float, float]:
    """The slip sizes over which a track behaves as ABBM: above ten grid spacings (below,
    the spline's smooth slope replaces the walk) and below a tenth of the correlation length
    (beyond it, the slope stops wandering and the force becomes stationary). A study's
    cutoff ``S_m = sigma / k^2`` should lie in this range.

    Parameters
    ----------
    spacing : float
        The track's grid spacing, in surface units.
    correlation_length : float
        The slope walk's correlation length, in surface units.

    Returns
    -------
    tuple of float
        ``(smallest, largest)`` slip size, in surface units.
    """
    return 10.0 * spacing, 0.1 * correlation_length
