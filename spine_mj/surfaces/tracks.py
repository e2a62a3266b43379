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
``D`` below ``xi``, stationary with rms ``s = sqrt(D xi)`` beyond it.

**The track's scales, from ABBM's own** (:func:`abbm_size_range`,
:func:`abbm_stiffness_range`, :func:`abbm_length`). ABBM has one length at each spring,
the cutoff ``S_m = sigma / k^2``. A track reproduces it between two bounds:

- below, the grid: under the spacing ``dx`` the spline's slope is smooth, not a walk. A
  slip that starts with a force overshoot ``a`` has the first-passage law of a drifted
  walk, ``P(S) ~ a S^-3/2 exp(-(a - k S)^2 / (4 sigma S))``, whose local exponent is
  ``3/2 - a^2 / (4 sigma S)``; on the grid ``a^2 ~ sigma dx``, so ``S^-3/2`` holds from
  :data:`POWER_LAW_SPACINGS` spacings (:func:`abbm_smallest_slip`), and the stiffest
  spring's ``S_m`` at :data:`GRID_SPACINGS` spacings leaves sizes up to ``4 S_m = 200 dx``;
- above, the mean reversion: the slope's drift ``-s / xi`` is an extra stiffness of rms
  ``sqrt(sigma / xi)`` on the force, and slips pooled over a track measure
  ``sigma <k_eff^-2> = (sigma / k^2) (1 + 3 S_m / xi)``: 5 % at ``S_m = xi /``
  :data:`XI_FRACTION`.

The stiffness number is ``K = k l_s / W`` with ``l_s = xi`` (the 1/e length of the
slope's correlation ``exp(-r / xi)``, exact for the ensemble and stated in the surface's
metadata, where one track measures 0.1 to 0.8 ``xi`` at 4 ``xi`` long, 0.6 to 1.2 at
100 ``xi``). So
``S_m / xi = ((1 + mu^2) s / K)^2``: the upper bound sets the softest spring
``K_lo = (1 + mu^2) s sqrt(64)`` and a decade of K (two decades of ``S_m``) needs
``xi / dx >= 100 x 50 x 64``. The length follows from ``S_m``'s own scatter: its 95 %
interval is about ``6 / sqrt(L / S_m)`` relative (the §12 walk: 25 % at 900 cutoffs,
7 % at 7000), so :data:`CUTOFFS_PER_TRACK` cutoffs of the softest spring give it to
21 % and the exponent of ``S_m`` against K, over a decade, to about 0.06.
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

__all__ = [
    "abbm_force_intensity",
    "abbm_length",
    "abbm_size_range",
    "abbm_slope_walk",
    "abbm_smallest_slip",
    "abbm_stiffness_numbers",
    "abbm_stiffness_range",
    "abbm_track",
]

#: Largest rms slope of a track: slopes stay well inside (-mu, 1 / mu) at every mu >= 0.5
#: over ten standard deviations (engaged, never self-locking).
MAX_RMS_SLOPE = 0.15
#: The smallest slip that follows ``S^-3/2``, in grid spacings (:func:`abbm_smallest_slip`):
#: read off the preset's seeds 1, 5151-5353 (tau fitted from 10 spacings 1.46-1.50, from 30
#: 1.49-1.52 with 3/2 inside in 8 of 8 cells), then checked on seeds 6161 and 6262.
POWER_LAW_SPACINGS = 30.0
#: The stiffest spring's cutoff ``S_m``, in grid spacings: on the §12 walk ``tau`` left its
#: interval (about 0.02 wide on 1e5 slips) at 20 spacings in 2 of 5 draws, at 220 in none.
GRID_SPACINGS = 50.0
#: The softest spring's cutoff is ``xi`` over this: the mean reversion raises ``S_m`` by
#: ``3 S_m / xi``, 5 %.
XI_FRACTION = 64.0
#: A track's length in cutoffs ``S_m`` of its softest spring: ``S_m`` to about 21 %.
CUTOFFS_PER_TRACK = 800.0
#: A study's stiffness numbers per decade of K (:func:`abbm_stiffness_numbers`).
K_PER_DECADE = 3


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
        )
        | {"slope_length": xi},
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
    """The cutoffs ``S_m = sigma / k^2`` over which a track behaves as ABBM (the module's
    docstring): from :data:`GRID_SPACINGS` grid spacings (below, the spline's smooth slope
    shortens the ``S^-3/2`` range) to the correlation length over :data:`XI_FRACTION`
    (beyond, the mean reversion raises ``S_m`` by more than 5 %).

    Parameters
    ----------
    spacing : float
        The track's grid spacing, in surface units.
    correlation_length : float
        The slope walk's correlation length, in surface units.

    Returns
    -------
    tuple of float
        ``(smallest, largest)`` cutoff, in surface units.
    """
    return GRID_SPACINGS * spacing, correlation_length / XI_FRACTION


def abbm_stiffness_range(
    spacing: float, slope_intensity: float, correlation_length: float, mu: float
) -> tuple[float, float]:
    """The stiffness numbers ``K = k xi / W`` whose cutoff ``S_m = sigma / k^2`` lies in
    :func:`abbm_size_range`: ``K = (1 + mu^2) xi sqrt(D / S_m)`` at its two ends.

    Parameters
    ----------
    spacing, slope_intensity, correlation_length : float
        The track's ``dx``, ``D`` and ``xi`` (:func:`abbm_track`).
    mu : float
        The tip's friction coefficient.

    Returns
    -------
    tuple of float
        ``(softest, stiffest)`` K.
    """
    low, high = abbm_size_range(spacing, correlation_length)
    scale = (1 + mu * mu) * correlation_length * math.sqrt(slope_intensity)
    return scale / math.sqrt(high), scale / math.sqrt(low)


def abbm_length(
    slope_intensity: float, correlation_length: float, mu: float, stiffness_number: float
) -> float:
    """The track length that holds :data:`CUTOFFS_PER_TRACK` cutoffs ``S_m`` of the spring
    ``K = stiffness_number`` (``k = K W / xi``), in surface units.

    Parameters
    ----------
    slope_intensity, correlation_length : float
        The track's ``D`` and ``xi``.
    mu : float
        The tip's friction coefficient.
    stiffness_number : float
        The softest K of a study.

    Returns
    -------
    float
    """
    k = stiffness_number / correlation_length
    return CUTOFFS_PER_TRACK * abbm_force_intensity(slope_intensity, mu) / (k * k)


def abbm_stiffness_numbers(surface: GridSurface, mu: float) -> list[float]:
    """A study's K on an ABBM track: log-spaced, :data:`K_PER_DECADE` a decade, over
    :func:`abbm_stiffness_range` (1, 2.15, 4.64 and 10 on the ``abbm`` preset at mu 0.5),
    to three significant figures.

    Parameters
    ----------
    surface : GridSurface
        A track made by :func:`abbm_track`.
    mu : float
        The tip's friction coefficient.

    Returns
    -------
    list of float

    Raises
    ------
    SpineInputError
        For a surface that is not an ABBM track.
    """
    meta = surface.metadata if isinstance(surface.metadata, dict) else {}
    if meta.get("generator") != "abbm_track":
        kind = meta.get("generator") or type(surface).__name__
        raise SpineInputError(f"default stiffness numbers need an ABBM track, got a {kind} surface: give --K")
    params = meta["params"]
    lo, hi = abbm_stiffness_range(
        surface.spacing[0], params["slope_intensity"], params["correlation_length"], mu
    )
    n = max(2, int(round(K_PER_DECADE * math.log10(hi / lo))) + 1)
    return [float(f"{v:.3g}") for v in np.geomspace(lo, hi, n)]


def abbm_smallest_slip(spacing: float) -> float:
    """The smallest slip size that follows ABBM's ``S^-3/2`` on a track of grid ``spacing``:
    :data:`POWER_LAW_SPACINGS` spacings (the module's docstring: the start's overshoot
    bends the law by ``a^2 / (4 sigma S)``, ``a^2 ~ sigma dx``). A fit's lower cutoff
    belongs above it.

    Parameters
    ----------
    spacing : float
        The track's grid spacing, in surface units.

    Returns
    -------
    float
        In surface units.
    """
    return POWER_LAW_SPACINGS * spacing
