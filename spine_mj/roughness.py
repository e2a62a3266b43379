"""Roughness statistics of a surface: heights, slopes, correlation lengths, PSD, Hurst.

Two lengths set the scales of spine engagement on a rough surface:

* ``L_c``, the characteristic asperity length of the inertia number
  ``I_e = m v^2 / (F_p L_c)`` (paper §2.2): :func:`characteristic_length`;
* ``l_s``, the slope correlation length: the distance along the drive over which the
  surface slope, and with it the engagement ratio kappa, changes. It sets the drive
  stiffness number ``K = k l_s / F_p`` (a spring of stiffness k stores ``F^2 / 2k`` and
  releases it at breakaway: quasistatic needs ``K`` large as well as ``I_e`` small):
  :func:`slope_correlation_length`.

For a fractal, ``L_c`` follows the long waves and ``l_s`` the short ones, so the two can
differ by tens of grid spacings; for a single Gaussian of width sigma, ``L_c = sigma`` and
``l_s = 1.315 sigma``.

:func:`summarize` adds RMS height, slope and curvature, the radially averaged power
spectral density and a Hurst estimate, computed with SurfaceTopography, the library the
measured scans are read with.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.memory import check_memory
from spine_mj.surfaces import GaussianSurface, GridSurface, Surface, check_grid_size

__all__ = [
    "PLANE_NOTE",
    "Roughness",
    "characteristic_length",
    "radial_psd",
    "slope_autocorrelation",
    "slope_correlation_length",
    "summarize",
]

#: Level at which the normalized slope autocorrelation defines l_s.
SLOPE_CORRELATION_LEVEL = 1 / math.e
_GAUSSIAN_SAMPLES_PER_SIGMA = 10
#: Bytes per grid point :func:`summarize` adds at its peak: SurfaceTopography's rms slope and
#: curvature stencils, the PSD's transform and the slope autocorrelation, about 19 float64
#: arrays of the grid. Measured 145-152 B a point from 512 to 2048 a side, periodic or not
#: (tests/test_memory.py); `surface info` on a 4096 x 4096 fractal peaked at 2.85 GB.
SUMMARY_BYTES_PER_POINT = 150
_PLANE_SLOPE_SPREAD = 1e-4  # slope spread below this fraction of the mean slope: a plane
#: Why a plane has no slope correlation length (:attr:`Roughness.slope_correlation_note`).
PLANE_NOTE = "surface has no slope variation (a plane): no slope correlation length"


def characteristic_length(surface: Surface) -> float:
    """L_c of a surface, in the surface's own units.

    Rule: for a Gaussian sum, the mean of its widths ``(sigma_x + sigma_y) / 2``; for a
    grid, ``2 pi`` times the rms height over the rms slope (the wavelength of a sine with
    the same rms height and slope), clipped to ``[4 dx, domain size]``; a plane (no
    height variation) gives the domain size.

    Parameters
    ----------
    surface : Surface
        Any surface.

    Returns
    -------
    float
        ``L_c``, the length of the inertia number ``I_e = m v^2 / (F_p L_c)``.
    """
    xmin, xmax, ymin, ymax = surface.bounds
    span = float(min(xmax - xmin, ymax - ymin))
    if isinstance(surface, GaussianSurface):
        return float(np.mean(0.5 * (surface.sigma_x + surface.sigma_y)))
    grid = surface if isinstance(surface, GridSurface) else surface.sample(201)
    h = grid.heights - grid.heights.mean()
    dx, dy = grid.spacing
    gy, gx = np.gradient(grid.heights, dy, dx)
    detrended = h - (
        gx.mean() * (grid.x[None, :] - grid.x.mean()) + gy.mean() * (grid.y[:, None] - grid.y.mean())
    )
    rms_h = float(np.sqrt(np.mean(detrended**2)))
    rms_s = float(np.sqrt(np.mean((gx - gx.mean()) ** 2 + (gy - gy.mean()) ** 2)))
    if rms_s <= 1e-12 or rms_h <= 1e-12 * span:
        return span
    return float(np.clip(2 * math.pi * rms_h / rms_s, 4 * max(dx, dy), span))


def _gradient_grid(surface: Surface) -> tuple[np.ndarray, np.ndarray, float, bool]:
    """Slopes ``(gx, gy)`` of shape ``(ny, nx)`` on a uniform grid, its x spacing, and
    whether the grid wraps around in x. Grids use their own nodes; a Gaussian sum is
    sampled at a tenth of its narrowest width over its bounds."""
    if isinstance(surface, GridSurface):
        x, y, dx, periodic = surface.x, surface.y, surface.spacing[0], surface.periodic
    else:
        xmin, xmax, ymin, ymax = surface.bounds
        width = (
            float(min(surface.sigma_x.min(), surface.sigma_y.min()))
            if isinstance(surface, GaussianSurface)
            else max(xmax - xmin, ymax - ymin) / 200
        )
        step = width / _GAUSSIAN_SAMPLES_PER_SIGMA
        nx = int(math.ceil((xmax - xmin) / step)) + 1
        ny = int(math.ceil((ymax - ymin) / step)) + 1
        check_grid_size(nx, ny, where="slope autocorrelation")
        x, y = np.linspace(xmin, xmax, nx), np.linspace(ymin, ymax, ny)
        dx, periodic = float(x[1] - x[0]), False
    gx, gy = surface.gradient(x[None, :], y[:, None])
    if not (np.all(np.isfinite(gx)) and np.all(np.isfinite(gy))):
        raise SpineInputError("surface slopes are not finite on its own grid; cannot correlate them")
    return gx, gy, float(dx), bool(periodic)


def slope_autocorrelation(surface: Surface) -> tuple[np.ndarray, np.ndarray]:
    """Normalized autocorrelation of the surface gradient along the drive direction x.

    ``C(r) = <grad f(x, y) . grad f(x + r, y)> / <|grad f|^2>`` with the mean slope
    removed, averaged over rows; circular on a periodic grid, otherwise over the overlap
    and divided by the full row length (so that a localized feature, like a single
    Gaussian, gives its infinite-domain autocorrelation).

    Returns
    -------
    lags : ndarray, shape (n,)
        ``r`` in the surface's length unit, from 0.
    corr : ndarray, shape (n,)
        ``C(r)``, with ``C(0) = 1``.
    """
    gx, gy, dx, periodic = _gradient_grid(surface)
    spread = math.sqrt(gx.var() + gy.var())
    if spread <= _PLANE_SLOPE_SPREAD * max(math.hypot(gx.mean(), gy.mean()), 1e-300):
        raise SpineInputError(PLANE_NOTE)
    nx = gx.shape[1]
    size = nx if periodic else 2 * nx
    power = np.zeros(size // 2 + 1)
    for g in (gx - gx.mean(), gy - gy.mean()):
        spec = np.fft.rfft(g, n=size, axis=1)
        power = power + (np.abs(spec) ** 2).sum(axis=0)
    corr = np.fft.irfft(power, n=size)[: nx if not periodic else nx // 2 + 1]
    return dx * np.arange(corr.size), corr / corr[0]


#: ``l_s`` (or why there is none) of each surface measured in this process: a surface is
#: immutable, and every rig built on it measures it (a sweep builds one per drive and the
#: preflight one more: 236 measurements of ~0.03 s in the quick validation's main process).
_SLOPE_LENGTHS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def slope_correlation_length(surface: Surface) -> float:
    """``l_s``: the shortest lag along x where :func:`slope_autocorrelation` falls to 1/e.

    Linear interpolation between grid lags. Closed forms (tested): a sine of wavelength
    lambda gives ``lambda arccos(1/e) / (2 pi) = 0.190 lambda``; a Gaussian bump of
    width sigma gives ``2 sigma sqrt(u)`` with ``(1 - u) e^-u = 1/e``, i.e. ``1.315 sigma``.
    Measured once per surface object; a generator that knows its slopes' correlation
    exactly states it as ``metadata["slope_length"]``, which is returned instead (the ABBM
    track: its Ornstein-Uhlenbeck slope's ``xi``, where one track measures 0.1 to 0.8
    ``xi`` at 4 ``xi`` long, 0.6 to 1.2 ``xi`` at 100 ``xi``).

    Raises
    ------
    SpineInputError
        For a plane, or when the correlation never falls to 1/e within the domain.
    """
    meta = surface.metadata if isinstance(surface.metadata, dict) else {}
    if meta.get("slope_length"):
        return float(meta["slope_length"])
    known = _SLOPE_LENGTHS.get(surface)
    if known is None:
        try:
            known = _slope_correlation_length(surface)
        except SpineInputError as exc:  # the message only: a traceback would hold the surface
            known = str(exc)
        _SLOPE_LENGTHS[surface] = known
    if isinstance(known, str):
        raise SpineInputError(known)
    return known


def stiffness_length(surface: Surface) -> float:
    """The length of the drive stiffness number ``K = k l / F_p``: ``l_s``
    (:func:`slope_correlation_length`), or ``L_c`` (:func:`characteristic_length`) for a
    surface without one (a plane, or slopes correlated across the whole domain)."""
    try:
        return slope_correlation_length(surface)
    except SpineInputError:
        return characteristic_length(surface)


def _slope_correlation_length(surface: Surface) -> float:
    lags, corr = slope_autocorrelation(surface)
    below = np.flatnonzero(corr <= SLOPE_CORRELATION_LEVEL)
    if below.size == 0:
        raise SpineInputError(
            "surface slopes stay correlated above 1/e across the whole domain: "
            "no slope correlation length shorter than the surface"
        )
    j = int(below[0])
    c0, c1 = corr[j - 1], corr[j]
    return float(lags[j - 1] + (c0 - SLOPE_CORRELATION_LEVEL) / (c0 - c1) * (lags[j] - lags[j - 1]))


def radial_psd(surface: GridSurface, *, bins_per_decade: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Radially averaged 2-D power spectral density of a grid's heights.

    ``C(q) = dx dy |FFT(h - <h>)|^2 / (nx ny)`` averaged over log-spaced rings of the
    wavevector magnitude ``q = 2 pi |f|`` (radians per length unit), the convention of
    SurfaceTopography's ``power_spectrum_from_area``.

    Returns
    -------
    q, psd : ndarray, shape (n_bins,)
        Ring centres and mean PSD; empty rings are dropped.
    """
    if not isinstance(surface, GridSurface):
        raise SpineInputError(f"radial_psd needs a GridSurface, got {type(surface).__name__}")
    h = surface.heights - surface.heights.mean()
    ny, nx = h.shape
    dx, dy = surface.spacing
    power = dx * dy * np.abs(np.fft.fft2(h)) ** 2 / (nx * ny)
    q = 2 * np.pi * np.hypot(*np.meshgrid(np.fft.fftfreq(nx, dx), np.fft.fftfreq(ny, dy)))
    q_min, q_max = 2 * np.pi / max(nx * dx, ny * dy), np.pi / min(dx, dy)
    edges = np.logspace(np.log10(q_min), np.log10(q_max), int(bins_per_decade * np.log10(q_max / q_min)) + 2)
    ring = np.digitize(q.ravel(), edges)
    counts = np.bincount(ring, minlength=edges.size + 1)[1:-1]
    sums = np.bincount(ring, weights=power.ravel(), minlength=edges.size + 1)[1:-1]
    qsum = np.bincount(ring, weights=q.ravel(), minlength=edges.size + 1)[1:-1]
    keep = counts > 0
    return qsum[keep] / counts[keep], sums[keep] / counts[keep]


@dataclass(frozen=True)
class Roughness:
    """Roughness summary of a surface (lengths in the surface's unit).

    Attributes
    ----------
    unit : str
        The surface's length unit (a key of :data:`~spine_mj.surfaces.LENGTH_UNITS_M`, or "1").
    rms_height, rms_slope, rms_curvature : float
        Sq, the rms gradient and the rms Laplacian / 2 (SurfaceTopography's definitions).
    char_length : float
        L_c (:func:`characteristic_length`).
    slope_correlation_length : float
        l_s (:func:`slope_correlation_length`).
    hurst : float
        ``-(s + 2) / 2`` from the log-log slope ``s`` of the PSD over its middle decade(s)
        (``C ~ q^-(2H+2)``); NaN ("not estimated") when fewer than 4 rings are usable, or
        when the fit is no self-affine power law: H outside :data:`HURST_RANGE` or a fit
        explaining less than :data:`MIN_HURST_FIT_R2` of the log PSD's variance; NaN on a
        plane (a tilted one's PSD is its edges' ``q^-3`` step, which read H 0.45).
    slope_correlation_note : str
        Why ``slope_correlation_length`` is NaN (a plane, or slopes correlated across the
        whole domain); empty when it was measured.
    psd_prefactor, fit_range : float, (float, float)
        The fit ``C = psd_prefactor q^-(2H+2)`` and the q range it was made over.
    q, psd : ndarray
        Radially averaged PSD (:func:`radial_psd`).
    """

    unit: str
    rms_height: float
    rms_slope: float
    rms_curvature: float
    char_length: float
    slope_correlation_length: float
    hurst: float
    psd_prefactor: float
    fit_range: tuple[float, float]
    q: np.ndarray
    psd: np.ndarray
    slope_correlation_note: str = ""

    def as_dict(self) -> dict:
        """Scalars only (for JSON and printing)."""
        skip = ("q", "psd", "psd_prefactor", "fit_range")
        return {k: getattr(self, k) for k in self.__dataclass_fields__ if k not in skip}


#: A Hurst index is reported only inside this range (self-affine surfaces, 0 <= H <= 1) ...
HURST_RANGE = (0.0, 1.0)
#: ... and when the log-log fit of the PSD explains at least this share of its variance.
MIN_HURST_FIT_R2 = 0.9


def _hurst_fit(q: np.ndarray, psd: np.ndarray) -> tuple[float, float, tuple[float, float]]:
    """Least-squares fit ``log C = log A - (2H + 2) log q`` over the rings between 4 times
    the lowest and a third of the highest q: ``(H, A, (q_lo, q_hi))``, NaN when fewer
    than 4 rings are usable or the fit is no self-affine power law (see :class:`Roughness`)."""
    ok = (q > 4 * q.min()) & (q < q.max() / 3) & (psd > 0)
    nan = float("nan")
    if ok.sum() < 4:
        return nan, nan, (nan, nan)
    x, y = np.log(q[ok]), np.log(psd[ok])
    slope, intercept = np.polyfit(x, y, 1)
    hurst = float(-(slope + 2) / 2)
    r2 = 1.0 - np.sum((y - (slope * x + intercept)) ** 2) / max(np.sum((y - y.mean()) ** 2), 1e-300)
    if not (HURST_RANGE[0] <= hurst <= HURST_RANGE[1] and r2 >= MIN_HURST_FIT_R2):
        return nan, nan, (nan, nan)  # not a self-affine power law over those rings
    return hurst, float(np.exp(intercept)), (float(q[ok].min()), float(q[ok].max()))


def summarize(surface: Surface) -> Roughness:
    """Roughness statistics of ``surface`` (an analytic one is sampled on 201 x 201).

    RMS height, slope and curvature come from SurfaceTopography's ``Topography``
    (``rms_height_from_area``, ``rms_gradient``, ``rms_curvature_from_area``) on the same
    grid, with the grid's periodicity.
    """

    import SurfaceTopography as st  # lazy like mujoco: 1.7 s to import

    if isinstance(surface, GridSurface):
        ny, nx = surface.shape
        check_memory(SUMMARY_BYTES_PER_POINT * float(nx) * ny, where=f"the roughness of a {ny} x {nx} grid")
    grid = surface if isinstance(surface, GridSurface) else surface.sample(201)
    ny, nx = grid.shape
    dx, dy = grid.spacing
    # SurfaceTopography's pixel is physical size / points, periodic or not: (nx - 1) dx
    # made a 9-row strip's y slopes 9/8 too steep
    topo = st.Topography(grid.heights.T, (nx * dx, ny * dy), periodic=grid.periodic)
    q, psd = radial_psd(grid)
    hurst, prefactor, fit_range = _hurst_fit(q, psd)
    try:
        l_s, note = slope_correlation_length(surface), ""
    except SpineInputError as exc:  # a plane: report what it has, and why it has no l_s
        l_s, note = math.nan, str(exc)
    if note == PLANE_NOTE:
        hurst, prefactor, fit_range = math.nan, math.nan, (math.nan, math.nan)
    return Roughness(
        unit=surface.unit,
        rms_height=float(topo.rms_height_from_area()),
        rms_slope=float(topo.rms_gradient()),
        rms_curvature=float(topo.rms_curvature_from_area()),
        char_length=characteristic_length(surface),
        slope_correlation_length=l_s,
        slope_correlation_note=note,
        hurst=hurst,
        psd_prefactor=prefactor,
        fit_range=fit_range,
        q=q,
        psd=psd,
    )
