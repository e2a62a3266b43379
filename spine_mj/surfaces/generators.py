"""Surface generators: the paper's single Gaussian and random Gaussian surfaces (§3.1-3.2),
fractal fBm surfaces and, from :mod:`spine_mj.surfaces.sandpaper`, sandpaper analogs
(§3.3). Pure functions with keyword-only options; randomness enters only through ``rng``,
so a seed reproduces a surface bit for bit."""

from __future__ import annotations

import math

import numpy as np

from spine_mj.errors import SpineInputError, check_positive
from spine_mj.surfaces.base import (
    _MIN_POINTS_PER_SIDE,
    MAX_PEAKS,
    _bounds,
    _count_at_least,
    _flag,
    _grid_count,
    _meta,
    _pair,
    _range,
    _rng_and_seed,
    check_grid_size,
    check_unit,
)
from spine_mj.surfaces.types import GaussianSurface, GridSurface


def single_gaussian(
    *,
    sign: int = 1,
    k: float = 10 * math.pi,
    sigma_x: float = 1.5,
    sigma_y: float = 1.5,
    center: tuple[float, float] = (0.0, 0.0),
    bounds: tuple[float, float, float, float] = (-5.0, 5.0, -5.0, 5.0),
) -> GaussianSurface:
    """The paper's single Gaussian peak (``sign=+1``) or valley (``sign=-1``), §3.1.

    ``f = sign * k / (2 pi sx sy) * exp(-(x-mx)^2/(2 sx^2) - (y-my)^2/(2 sy^2))``; with the
    paper's ``k = 10 pi`` and ``sx = sy = 1.5`` the amplitude is 2.22 and the steepest
    slope 0.90 (docs/physics.md §3). Dimensionless.

    Parameters
    ----------
    sign : {1, -1}
        Peak or valley.
    k : float
        Volume under the Gaussian, > 0.
    sigma_x, sigma_y : float
        Widths ``sx``, ``sy`` > 0.
    center : tuple of float
        ``(mx, my)``.
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the domain.

    Returns
    -------
    GaussianSurface
    """
    if sign not in (1, -1):
        raise SpineInputError(f"sign must be +1 (peak) or -1 (valley), got {sign!r}")
    k = check_positive("k", k)
    sx, sy = check_positive("sigma_x", sigma_x), check_positive("sigma_y", sigma_y)
    mx, my = _pair("center", center)
    amplitude = sign * k / (2 * math.pi * sx * sy)
    return GaussianSurface(
        amplitude=[amplitude],
        center_x=[mx],
        center_y=[my],
        sigma_x=[sx],
        sigma_y=[sy],
        bounds=_bounds(bounds),
        unit="1",
        metadata=_meta(
            "single_gaussian",
            None,
            sign=sign,
            k=k,
            sigma_x=sx,
            sigma_y=sy,
            center=(mx, my),
            bounds=tuple(bounds),
        ),
    )


def inclined_plane(
    *, slope_deg: float, azimuth_deg: float = 0.0, half_width: float = 0.02, n: int = 41, unit: str = "m"
) -> GridSurface:
    """A plane ``z = tan(slope) (x cos(az) + y sin(az))`` on a square grid.

    ``azimuth_deg = 0`` makes the plane rise in +x (the closed form's theta > 0), where
    ``kappa = tan(theta + arctan mu)`` (docs/physics.md §1) is the static probe's target.

    Parameters
    ----------
    slope_deg : float
        Inclination theta [deg].
    azimuth_deg : float
        Direction of steepest rise from +x [deg].
    half_width : float
        Half the side of the square domain, centred on 0.
    n : int
        Grid points a side.
    unit : str
        Length unit of the coordinates and heights.

    Returns
    -------
    GridSurface
    """
    slope = _finite("slope_deg", slope_deg)
    if not -89.0 <= slope <= 89.0:
        raise SpineInputError(f"slope_deg must lie in [-89, 89], got {slope_deg!r}")
    azimuth = _finite("azimuth_deg", azimuth_deg)
    half_width = check_positive("half_width", half_width)
    unit = check_unit(unit)
    n = _grid_count("n", n)
    check_grid_size(n, n, where="inclined_plane")
    t = math.tan(math.radians(slope))
    az = math.radians(azimuth)
    x = np.linspace(-half_width, half_width, n)
    h = t * (math.cos(az) * x[None, :] + math.sin(az) * x[:, None])
    return GridSurface(
        heights=h,
        x=x,
        y=x.copy(),
        unit=unit,
        metadata={"generator": "inclined_plane", "slope_deg": slope, "azimuth_deg": azimuth},
    )


def _finite(name: str, value) -> float:
    """``float(value)`` if it is a finite number (not a bool or a string), else a
    :class:`SpineInputError` naming ``name``."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    if not (ok and math.isfinite(value)):
        raise SpineInputError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def corrugation(
    *,
    wavelength: float = 1.0,
    slope_amplitude: float = 0.3,
    n_waves: int = 8,
    width: float = 1.0,
    points_per_wave: int = 32,
) -> GridSurface:
    """A sinusoidal corrugation ``z = h sin(2 pi x / lambda)``, uniform in y: the
    Prandtl-Tomlinson profile, a surface whose dynamics have closed forms (docs/physics.md §6).

    ``h = slope_amplitude * wavelength / (2 pi)``, so the steepest slope is
    ``slope_amplitude``; ``L_c = wavelength`` (rms height over rms slope times 2 pi) and the
    slope correlation length is ``0.190 wavelength``. The grid is periodic in x over
    ``n_waves`` whole wavelengths starting at x = 0 (a crest's rising flank begins there)
    and spans ``width`` in y, centred on y = 0. Dimensionless.

    Parameters
    ----------
    wavelength : float
        ``lambda`` > 0.
    slope_amplitude : float
        The steepest slope ``2 pi h / lambda``, in [0, 10].
    n_waves : int
        Whole wavelengths along x, >= 1.
    width : float
        Extent in y, > 0.
    points_per_wave : int
        Grid points per wavelength, >= 8 (128 for MuJoCo runs: a coarse hfield's facet kinks
        add slip bursts).

    Returns
    -------
    GridSurface
    """
    lam = check_positive("wavelength", wavelength)
    s = float(slope_amplitude)
    if not (math.isfinite(s) and 0.0 <= s <= 10.0):
        raise SpineInputError(f"slope_amplitude must lie in [0, 10], got {slope_amplitude!r}")
    waves = _count_at_least("n_waves", n_waves, 1)
    per_wave = _count_at_least("points_per_wave", points_per_wave, 8)
    w = check_positive("width", width)
    nx = waves * per_wave
    dx = lam / per_wave
    ny = max(_MIN_POINTS_PER_SIDE, int(math.ceil(w / dx)))
    check_grid_size(nx, ny, where="corrugation")
    x = np.arange(nx) * dx
    y = -w / 2 + np.arange(ny) * (w / ny)
    h = s * lam / (2 * math.pi)
    heights = np.broadcast_to(h * np.sin(2 * math.pi * x / lam), (ny, nx)).copy()
    return GridSurface(
        heights=heights,
        x=x,
        y=y,
        periodic=True,
        unit="1",
        metadata=_meta(
            "corrugation",
            None,
            wavelength=lam,
            slope_amplitude=s,
            n_waves=waves,
            width=w,
            points_per_wave=per_wave,
        ),
    )


def random_gaussians(
    *,
    n_peaks: int = 100,
    sign: int = 1,
    bounds: tuple[float, float, float, float] = (-10.0, 10.0, -10.0, 10.0),
    sigma_range: tuple[float, float] = (0.5, 1.5),
    amplitude_range: tuple[float, float] = (0.5, 1.5),
    anisotropic: bool = False,
    overlap: bool = True,
    min_separation: float = 2.0,
    rng: int | np.random.Generator | None = None,
) -> GaussianSurface:
    """Random Gaussian surface of §3.2: ``n_peaks`` Gaussians scattered over ``bounds``.

    Distributions (the paper gives none; the defaults are calibrated in ``analysis/``):

    * centres: uniform over ``bounds``;
    * widths: ``sigma`` uniform on ``sigma_range``; ``sigma_x = sigma_y`` unless
      ``anisotropic``, when both are drawn independently;
    * heights: amplitude ``|a|`` uniform on ``amplitude_range``, sign ``sign`` (+1 convex
      peaks, -1 concave valleys);
    * ``overlap=False`` rejects centres closer than ``min_separation * (sigma_i + sigma_j)``
      (drawn in sequence), and fails clearly when they cannot all be placed.

    The draws happen in a fixed order (widths, amplitudes, centres), so one seed gives the
    same surface on every machine.

    Parameters
    ----------
    n_peaks : int
        Number of Gaussians, 1 to :data:`MAX_PEAKS`.
    sign : {1, -1}
        Convex peaks or concave valleys.
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the domain.
    sigma_range, amplitude_range : tuple of float
        Ranges of the widths and of the amplitudes' magnitude.
    anisotropic : bool
        Draw ``sigma_x`` and ``sigma_y`` independently.
    overlap, min_separation : bool, float
        Allow centres closer than ``min_separation * (sigma_i + sigma_j)``.
    rng : int or numpy.random.Generator, optional
        The only source of randomness: a seed or a generator.

    Returns
    -------
    GaussianSurface
    """
    params = _random_gaussian_params(
        n_peaks, sign, bounds, sigma_range, amplitude_range, anisotropic, overlap, min_separation
    )
    gen, seed = _rng_and_seed(rng)
    return GaussianSurface(
        **_draw_peaks(gen, **params),
        bounds=params["bounds"],
        unit="1",
        metadata=_meta("random_gaussians", seed, **params),
    )


def _random_gaussian_params(
    n_peaks, sign, bounds, sigma_range, amplitude_range, anisotropic, overlap, min_separation
) -> dict:
    """The arguments of :func:`random_gaussians` checked, in the order its metadata records them."""
    n_peaks = _peak_count(n_peaks, sign)
    anisotropic, overlap = _flag("anisotropic", anisotropic), _flag("overlap", overlap)
    box = _bounds(bounds)
    sigmas = _range("sigma_range (widths)", sigma_range)
    amplitudes = _range("amplitude_range (heights)", amplitude_range)
    min_separation = float(min_separation)
    if not overlap and not (min_separation > 0):
        raise SpineInputError(f"min_separation must be > 0, got {min_separation!r}")
    return {
        "n_peaks": n_peaks,
        "sign": sign,
        "bounds": box,
        "sigma_range": sigmas,
        "amplitude_range": amplitudes,
        "anisotropic": bool(anisotropic),
        "overlap": bool(overlap),
        "min_separation": min_separation,
    }


def _peak_count(n_peaks, sign) -> int:
    """``n_peaks`` as an int, checked (1 to :data:`MAX_PEAKS`), and ``sign`` checked (+-1)."""
    if isinstance(n_peaks, bool) or int(n_peaks) != n_peaks or not 0 < n_peaks <= MAX_PEAKS:
        raise SpineInputError(f"n_peaks must be an integer in 1..{MAX_PEAKS}, got {n_peaks!r}")
    if sign not in (1, -1):
        raise SpineInputError(f"sign must be +1 (convex peaks) or -1 (concave valleys), got {sign!r}")
    return int(n_peaks)


def _draw_peaks(
    gen, *, n_peaks, sign, bounds, sigma_range, amplitude_range, anisotropic, overlap, min_separation
) -> dict:
    """The peaks of :func:`random_gaussians` as its keyword arguments of
    :class:`GaussianSurface`, drawn from ``gen`` in a fixed order: widths, amplitudes,
    centres."""
    xmin, xmax, ymin, ymax = bounds
    sigma_x = gen.uniform(*sigma_range, n_peaks)
    sigma_y = gen.uniform(*sigma_range, n_peaks) if anisotropic else sigma_x.copy()
    amplitude = sign * gen.uniform(*amplitude_range, n_peaks)
    if overlap:
        cx = gen.uniform(xmin, xmax, n_peaks)
        cy = gen.uniform(ymin, ymax, n_peaks)
    else:
        cx, cy = _separated_centres(gen, bounds, 0.5 * (sigma_x + sigma_y), min_separation)
    return {"amplitude": amplitude, "center_x": cx, "center_y": cy, "sigma_x": sigma_x, "sigma_y": sigma_y}


def _separated_centres(gen, bounds, radius: np.ndarray, min_separation: float):
    """Centres drawn one at a time, uniform over ``bounds``, each at least ``min_separation``
    times the sum of two radii from those before it (10 000 tries each)."""
    xmin, xmax, ymin, ymax = bounds
    n_peaks = radius.size
    cx, cy = np.empty(n_peaks), np.empty(n_peaks)
    for i in range(n_peaks):
        for _ in range(10_000):
            px, py = gen.uniform(xmin, xmax), gen.uniform(ymin, ymax)
            d = np.hypot(cx[:i] - px, cy[:i] - py)
            if np.all(d >= min_separation * (radius[:i] + radius[i])):
                cx[i], cy[i] = px, py
                break
        else:
            raise SpineInputError(
                f"overlap=False: could not place peak {i + 1} of {n_peaks} with "
                f"min_separation={min_separation}; lower n_peaks, the widths or "
                "min_separation, or allow overlap"
            )
    return cx, cy


def _spectral_rms_slope(heights: np.ndarray, dx: float, dy: float) -> float:
    """``sqrt(<|grad f|^2>)`` of a periodic grid by Parseval: ``sum q^2 |F(q)|^2 / N^2``."""
    ny, nx = heights.shape
    power = np.abs(np.fft.fft2(heights)) ** 2 / heights.size**2
    q2 = (2 * np.pi) ** 2 * (np.fft.fftfreq(nx, dx)[None, :] ** 2 + np.fft.fftfreq(ny, dy)[:, None] ** 2)
    return float(np.sqrt(np.sum(q2 * power)))


def fractal_fbm(
    *,
    nx: int = 256,
    ny: int | None = None,
    size: float | tuple[float, float] = 20.0,
    hurst: float = 0.8,
    rms_height: float | None = None,
    rms_slope: float | None = None,
    periodic: bool = True,
    long_cutoff: float | None = None,
    short_cutoff: float | None = None,
    unit: str = "1",
    rng: int | np.random.Generator | None = None,
) -> GridSurface:
    """Fractal (fBm) surface by spectral synthesis, paper Eq. 5 and Fig. 7A-C.

    White Gaussian noise is Fourier transformed (a complex Gaussian field with Hermitian
    symmetry), filtered by ``A(f) = sqrt(P(f)) = |f|^-(H+1)`` so that the 2-D PSD is
    ``P(f) ~ |f|^-(2H+2)``, and transformed back. ``f`` is spatial frequency in cycles per
    unit length. Below ``1/long_cutoff`` the filter is flat (roll-off); above
    ``1/short_cutoff`` it is zero. The mean height is removed.

    Parameters
    ----------
    nx, ny
        Grid points per side (``ny`` defaults to ``nx``); spacing is ``size / n``.
    size
        Physical side lengths ``(Lx, Ly)`` or one value for both; the grid is centred at 0.
    hurst
        Hurst index H, 0 < H < 1.
    rms_height, rms_slope
        Normalization: exactly one may be given (neither gives ``rms_height=1``). RMS slope
        is ``sqrt(<|grad f|^2>)``, evaluated spectrally on a periodic surface and by
        central differences on a non-periodic one.
    periodic
        If False, a surface twice as large is synthesized and one quadrant kept, so the
        result does not wrap around.
    long_cutoff, short_cutoff : float, optional
        Wavelengths (length unit) above which the PSD is flat and below which it is zero
        (default: neither; the grid's own size and spacing bound it).
    unit : str
        Length unit of the coordinates and heights (``"1"``: dimensionless).
    rng : int or numpy.random.Generator, optional
        The only source of randomness: a seed or a generator.

    Returns
    -------
    GridSurface
        Periodic (unless ``periodic=False``), zero mean, metadata recording every argument.
    """
    periodic, unit = _flag("periodic", periodic), check_unit(unit)
    nx, ny, lx, ly = _fbm_grid(nx, ny, size, periodic)
    hurst = _hurst(hurst)
    rms_height, rms_slope = _fbm_normalization(rms_height, rms_slope)
    long_cutoff = None if long_cutoff is None else check_positive("long_cutoff", long_cutoff)
    short_cutoff = None if short_cutoff is None else check_positive("short_cutoff", short_cutoff)
    gen, seed = _rng_and_seed(rng)
    dx, dy = lx / nx, ly / ny
    heights = _fbm_heights(gen, (nx, ny), (dx, dy), hurst, periodic, long_cutoff, short_cutoff)
    return GridSurface(
        heights=_fbm_normalized(heights, (lx, ly), (dx, dy), periodic, rms_height, rms_slope),
        x=-lx / 2 + dx * np.arange(nx),
        y=-ly / 2 + dy * np.arange(ny),
        periodic=bool(periodic),
        unit=unit,
        metadata=_meta(
            "fractal_fbm",
            seed,
            nx=nx,
            ny=ny,
            size=(lx, ly),
            hurst=hurst,
            rms_height=rms_height,
            rms_slope=rms_slope,
            periodic=bool(periodic),
            long_cutoff=long_cutoff,
            short_cutoff=short_cutoff,
            unit=unit,
        ),
    )


def _hurst(hurst) -> float:
    """The Hurst index H as a float, checked: 0 < H < 1."""
    hurst = float(hurst)
    if not (0.0 < hurst < 1.0):
        raise SpineInputError(f"hurst must lie in the open interval (0, 1), got {hurst!r}")
    return hurst


def _fbm_normalized(heights, size, spacing, periodic: bool, rms_height, rms_slope) -> np.ndarray:
    """``heights`` scaled in place to ``rms_slope`` (when given) or ``rms_height``; refused
    where that leaves floating-point range."""
    (lx, ly), (dx, dy) = size, spacing
    if rms_slope is not None:
        heights *= rms_slope / _rms_slope(heights, dx, dy, periodic)
    else:
        heights *= rms_height / heights.std()
    if not np.isfinite(heights).all():
        raise SpineInputError(
            f"fractal_fbm: size {lx:g} x {ly:g} with rms_height {rms_height} and rms_slope {rms_slope} "
            "gives heights beyond floating-point range; use sizes and RMS values nearer 1"
        )
    return heights


def _fbm_grid(nx, ny, size, periodic: bool) -> tuple[int, int, float, float]:
    """Points and side lengths of a :func:`fractal_fbm` grid, checked (a non-periodic one
    is synthesized twice as large)."""
    nx = _grid_count("nx", nx)
    ny = nx if ny is None else _grid_count("ny", ny)
    fac = 1 if periodic else 2
    check_grid_size(fac * nx, fac * ny, where="fractal_fbm", nbytes=fbm_bytes(nx, ny, periodic))
    lx, ly = (size, size) if np.isscalar(size) else _pair("size", size)
    return nx, ny, check_positive("size x", lx), check_positive("size y", ly)


def _fbm_normalization(rms_height, rms_slope) -> tuple[float | None, float | None]:
    """``(rms_height, rms_slope)`` checked: one of them (neither: ``rms_height = 1``)."""
    if rms_height is not None and rms_slope is not None:
        raise SpineInputError("give rms_height or rms_slope, not both")
    if rms_slope is not None:
        return None, check_positive("rms_slope", rms_slope)
    return (1.0 if rms_height is None else check_positive("rms_height", rms_height)), None


def _rms_slope(heights: np.ndarray, dx: float, dy: float, periodic: bool) -> float:
    """``sqrt(<|grad f|^2>)``: spectral on a periodic grid, central differences otherwise."""
    if periodic:
        return _spectral_rms_slope(heights, dx, dy)
    gy, gx = np.gradient(heights, dy, dx)
    return float(np.sqrt(np.mean(gx * gx + gy * gy)))


#: Bytes per point of the synthesis grid that :func:`fractal_fbm` holds at its peak: nine
#: float64-sized arrays (the noise, the frequencies, the filter, the spectrum, the filtered
#: spectrum and the inverse transform, complex ones counting twice). Measured 72.2 B per
#: point from 1024 to 2048 a side, periodic or not (tests/test_memory.py).
FBM_BYTES_PER_POINT = 72


def fbm_bytes(nx: int, ny: int, periodic: bool = True) -> float:
    """The peak bytes :func:`fractal_fbm` of ``nx`` x ``ny`` points allocates (a
    non-periodic surface is synthesized on a grid twice as large a side)."""
    fac = 1 if periodic else 2
    return float(FBM_BYTES_PER_POINT) * fac * nx * fac * ny


def _fbm_heights(gen, shape, spacing, hurst, periodic, long_cutoff, short_cutoff) -> np.ndarray:
    """Zero-mean fBm heights ``(ny, nx)`` before normalization (:func:`fractal_fbm`): white
    noise filtered by ``|f|^-(H+1)``, flat below ``1/long_cutoff``, zero above
    ``1/short_cutoff``; a non-periodic surface is one quadrant of one twice as large."""
    (nx, ny), (dx, dy) = shape, spacing
    fac = 1 if periodic else 2
    mx, my = fac * nx, fac * ny
    fx = np.fft.fftfreq(mx, dx)[None, :]
    fy = np.fft.fftfreq(my, dy)[:, None]
    freq = np.hypot(fx, fy)
    if long_cutoff is not None:
        freq = np.maximum(freq, 1.0 / long_cutoff)
    with np.errstate(divide="ignore"):
        amp = np.where(freq > 0, freq ** -(hurst + 1.0), 0.0)
    if short_cutoff is not None:
        amp[np.hypot(fx, fy) > 1.0 / short_cutoff] = 0.0
    amp[0, 0] = 0.0
    noise = gen.standard_normal((my, mx))
    heights = np.fft.ifft2(np.fft.fft2(noise) * amp).real[:ny, :nx]
    heights -= heights.mean()
    return heights
