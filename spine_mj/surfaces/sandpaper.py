"""Sandpaper analogs (§3.3): partly embedded spherical grit particles on a flat base.

:func:`sandpaper` draws the particles (log-normal diameters, uniform positions and
embedding) and takes the upper envelope of their exposed caps and the base on a periodic
grid that resolves both the tip and the grains. Randomness enters only through ``rng``.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.surfaces.base import (
    _MIN_POINTS_PER_SIDE,
    GRIT_PARTICLE_DIAMETER_M,
    _meta,
    _range,
    _rng_and_seed,
    check_grid_size,
)
from spine_mj.surfaces.types import GridSurface


def _particle_envelope(n, spacing, diam, px, py, embed) -> np.ndarray:
    """Upper envelope ``(n, n)`` of the base z = 0 and spheres of diameters ``diam`` at
    ``(px, py)``, each sunk by ``embed`` times its diameter, on a periodic grid."""
    heights = np.zeros((n, n))
    grid = np.arange(n)
    for d, cx, cy, e in zip(diam, px, py, embed):
        r = d / 2
        zc = r - e * d
        half = int(math.ceil(r / spacing)) + 1
        ix0, iy0 = int(round(cx / spacing)), int(round(cy / spacing))
        ix = np.arange(ix0 - half, ix0 + half + 1)
        iy = np.arange(iy0 - half, iy0 + half + 1)
        ddx = ix * spacing - cx
        ddy = iy * spacing - cy
        rho2 = ddy[:, None] ** 2 + ddx[None, :] ** 2
        cap = zc + np.sqrt(np.clip(r * r - rho2, 0, None))
        cap[rho2 >= r * r] = 0.0
        rows, cols = grid[np.mod(iy, n)], grid[np.mod(ix, n)]
        block = heights[np.ix_(rows, cols)]
        heights[np.ix_(rows, cols)] = np.maximum(block, cap)
    return heights


def sandpaper(
    *,
    grit: str | None = None,
    particle_diameter_m: float | None = None,
    size_m: float = 4e-3,
    tip_radius_m: float = 25e-6,
    spacing_m: float | None = None,
    coverage: float = 0.6,
    size_cv: float = 0.25,
    embed_range: tuple[float, float] = (0.3, 0.6),
    rng: int | np.random.Generator | None = None,
) -> GridSurface:
    """Sandpaper analog: partly embedded spherical grit particles on a flat base (§3.3).

    Particles are placed uniformly at random (overlaps allowed) on a square periodic
    patch; diameters are log-normal with mean ``particle_diameter_m`` and coefficient of
    variation ``size_cv``; each sphere is sunk into the base by a fraction of its diameter
    drawn uniformly from ``embed_range``. The height is the upper envelope of the exposed
    caps and the base (z = 0). Their number fills ``coverage`` of the base area with
    particle cross-sections (counting overlaps).

    The default spacing, ``min(tip_radius_m / 5, particle_diameter_m / 10)``, resolves both
    a tip of radius ``tip_radius_m`` and the particles (P600's 25.8 um grains included).

    Parameters
    ----------
    grit
        One of ``P36``, ``P60``, ``P600`` (mean particle size from the paper), or None
        when ``particle_diameter_m`` is given.
    particle_diameter_m : float, optional
        Mean particle diameter [m], instead of ``grit``.
    size_m
        Side of the square patch, metres.
    tip_radius_m : float
        Radius of the tip the grid must resolve [m] (sets the default spacing).
    spacing_m : float, optional
        Grid spacing [m]; default ``min(tip_radius_m / 5, particle_diameter_m / 10)``.
    coverage : float
        Share of the base area covered by particle cross-sections (overlaps counted).
    size_cv : float
        Coefficient of variation of the log-normal diameters.
    embed_range : tuple of float
        Range of the sunk fraction of each diameter, drawn uniformly.
    rng : int or numpy.random.Generator, optional
        The only source of randomness: a seed or a generator.

    Returns
    -------
    GridSurface
        Periodic, in metres.
    """
    params = _sandpaper_params(
        grit, particle_diameter_m, size_m, tip_radius_m, spacing_m, coverage, size_cv, embed_range
    )
    d_mean, size_m, size_cv = params["particle_diameter_m"], params["size_m"], params["size_cv"]
    n = _patch_points(size_m, params["spacing_m"], d_mean)
    gen, seed = _rng_and_seed(rng)
    spacing = params["spacing_m"] = size_m / n  # the patch's own, recorded in the metadata
    mean_area = math.pi * (d_mean / 2) ** 2 * (1 + size_cv**2)
    n_particles = max(1, round(params["coverage"] * size_m**2 / mean_area))
    particles = _particles(gen, n_particles, d_mean, size_cv, size_m, params["embed_range"])
    coords = spacing * np.arange(n) - size_m / 2
    return GridSurface(
        heights=_particle_envelope(n, spacing, *particles),
        x=coords,
        y=coords.copy(),
        periodic=True,
        unit="m",
        metadata=_meta("sandpaper", seed, **params, n_particles=n_particles),
    )


def _sandpaper_params(
    grit, particle_diameter_m, size_m, tip_radius_m, spacing_m, coverage, size_cv, embed_range
) -> dict:
    """The arguments of :func:`sandpaper` checked, in the order its metadata records them
    (``spacing_m`` the one asked for: the patch's whole number of points then sets it)."""
    d_mean = _grit_diameter(grit, particle_diameter_m)
    size_m = check_positive("size_m", size_m)
    tip_radius_m = check_positive("tip_radius_m", tip_radius_m)
    spacing_m = (
        min(tip_radius_m / 5, d_mean / 10) if spacing_m is None else check_positive("spacing_m", spacing_m)
    )
    coverage = check_positive("coverage", coverage)
    size_cv = float(size_cv)
    if not (0 <= size_cv < 2):
        raise SpineInputError(f"size_cv must be in [0, 2), got {size_cv!r}")
    e_lo, e_hi = _range("embed_range", embed_range, positive=False)
    if not (0 <= e_lo and e_hi < 1):
        raise SpineInputError(f"embed_range must lie within [0, 1), got {embed_range!r}")
    return {
        "grit": grit,
        "particle_diameter_m": d_mean,
        "size_m": size_m,
        "tip_radius_m": tip_radius_m,
        "spacing_m": spacing_m,
        "coverage": coverage,
        "size_cv": size_cv,
        "embed_range": (e_lo, e_hi),
    }


def _grit_diameter(grit: str | None, particle_diameter_m: float | None) -> float:
    """The mean particle diameter [m]: ``particle_diameter_m``, else the grit's."""
    if grit is not None:
        if grit not in GRIT_PARTICLE_DIAMETER_M:
            raise SpineInputError(f"grit must be one of {sorted(GRIT_PARTICLE_DIAMETER_M)}, got {grit!r}")
        if particle_diameter_m is None:
            particle_diameter_m = GRIT_PARTICLE_DIAMETER_M[grit]
    if particle_diameter_m is None:
        raise SpineInputError("give grit (P36, P60, P600) or particle_diameter_m")
    return check_positive("particle_diameter_m", particle_diameter_m)


def _patch_points(size_m: float, spacing_m: float, d_mean: float) -> int:
    """Grid points a side of a sandpaper patch, refused when too many or too few, or when the
    patch is smaller than two particles."""
    check_grid_size(
        size_m / spacing_m, size_m / spacing_m, where="sandpaper (size_m / spacing_m points a side)"
    )
    n = math.ceil(size_m / spacing_m - 1e-9)
    if n < _MIN_POINTS_PER_SIDE:
        raise SpineInputError(f"size_m / spacing_m gives {n} points; need at least 4")
    if size_m < 2 * d_mean:
        raise SpineInputError(
            f"size_m ({size_m:g}) must be at least twice the particle diameter ({d_mean:g})"
        )
    return n


def _particles(gen, n_particles: int, d_mean: float, size_cv: float, size_m: float, embed_range):
    """Diameters (log-normal, mean ``d_mean``, variation ``size_cv``), centres (uniform on the
    patch) and embedding fractions (uniform on ``embed_range``), drawn in that order."""
    sig_ln = math.sqrt(math.log1p(size_cv**2))
    diam = d_mean * np.exp(gen.normal(-0.5 * sig_ln**2, sig_ln, n_particles))
    px = gen.uniform(0, size_m, n_particles)
    py = gen.uniform(0, size_m, n_particles)
    embed = gen.uniform(*embed_range, n_particles)
    return diam, px, py, embed
