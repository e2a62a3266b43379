"""Roughness statistics against closed forms and SurfaceTopography."""

import math

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj import roughness
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.surfaces import GaussianSurface, GridSurface, fractal_fbm, single_gaussian


def sine_surface(wavelength=2.0, periods=4, n=256, amplitude=0.3):
    x = np.arange(n) * periods * wavelength / n
    y = np.arange(32) * x[1]
    h = amplitude * np.sin(2 * np.pi * x / wavelength)[None, :] * np.ones((y.size, 1))
    return GridSurface(heights=h, x=x, y=y, periodic=True, unit="1")


def test_slope_correlation_length_of_a_sine():
    """grad f = A k cos(k x): C(r) = cos(k r), 1/e at r = lambda arccos(1/e) / (2 pi)."""
    lam = 2.0
    expected = lam * math.acos(1 / math.e) / (2 * math.pi)
    # linear interpolation of a cosine between lags lambda / 64 apart: error < 1e-3 relative
    assert roughness.slope_correlation_length(sine_surface(lam)) == pytest.approx(expected, rel=1e-3)


def test_slope_correlation_length_of_a_gaussian_bump():
    """Gradient autocorrelation of a Gaussian of width sigma: (1 - u) e^-u, u = r^2 / 4 sigma^2."""
    u = 0.5
    for _ in range(50):  # Newton on (1 - u) e^-u = 1/e
        g = (1 - u) * math.exp(-u) - 1 / math.e
        u -= g / ((u - 2) * math.exp(-u))
    sigma = 1.5
    expected = 2 * sigma * math.sqrt(u)
    assert expected == pytest.approx(1.315 * sigma, rel=1e-3)
    # sampled at sigma / 10 and cut off at the paper's domain (+-3.3 sigma): 1e-3 relative
    assert roughness.slope_correlation_length(single_gaussian()) == pytest.approx(expected, rel=1e-3)
    wide = GaussianSurface(
        amplitude=np.array([1.0]),
        center_x=np.array([0.0]),
        center_y=np.array([0.0]),
        sigma_x=np.array([0.5]),
        sigma_y=np.array([0.5]),
        bounds=(-4.0, 4.0, -4.0, 4.0),
    )
    assert roughness.slope_correlation_length(wide) == pytest.approx(2 * 0.5 * math.sqrt(u), rel=1e-3)


def test_slope_correlation_is_a_few_spacings_on_a_fractal_far_below_lc():
    surf = fractal_fbm(nx=256, hurst=0.7, rng=1)
    ls = roughness.slope_correlation_length(surf)
    dx = surf.spacing[0]
    assert dx < ls < 5 * dx
    assert roughness.characteristic_length(surf) > 10 * ls


def test_a_plane_has_no_slope_correlation_length():
    x = np.linspace(0, 1, 16)
    plane = GridSurface(heights=0.2 * x[None, :] * np.ones((16, 1)), x=x, y=x.copy(), unit="1")
    with pytest.raises(SpineInputError, match="plane"):
        roughness.slope_correlation_length(plane)


def test_summary_matches_closed_forms_of_a_sine():
    amp, lam = 0.3, 2.0
    rough = roughness.summarize(sine_surface(lam, amplitude=amp))
    assert rough.rms_height == pytest.approx(amp / math.sqrt(2), rel=1e-6)
    # SurfaceTopography's rms gradient on the grid: finite differences, 1e-3 at 64 points a period
    assert rough.rms_slope == pytest.approx(amp * 2 * math.pi / lam / math.sqrt(2), rel=1e-3)


@pytest.mark.parametrize("hurst", [0.5, 0.8])
def test_hurst_estimate_of_fractals(hurst):
    estimates = [roughness.summarize(fractal_fbm(nx=256, hurst=hurst, rng=s)).hurst for s in range(3)]
    assert np.mean(estimates) == pytest.approx(hurst, abs=0.1)


def test_radial_psd_agrees_with_surfacetopography():
    """Our numpy PSD (fast path) against SurfaceTopography's power_spectrum_from_area."""
    import SurfaceTopography as st

    surf = fractal_fbm(nx=128, hurst=0.7, size=10.0, rng=3)
    q, psd = roughness.radial_psd(surf)
    topo = st.Topography(surf.heights.T, (10.0, 10.0), periodic=True)
    q_ref, c_ref = (np.ma.filled(a, np.nan) for a in topo.power_spectrum_from_area(nb_points_per_decade=8))
    ok = np.isfinite(c_ref) & (q_ref > q.min()) & (q_ref < q.max())
    mine = np.exp(np.interp(np.log(q_ref[ok]), np.log(q), np.log(psd)))
    # different ring edges: compare the log-spectra on average, not ring by ring
    assert np.median(np.abs(np.log(mine / c_ref[ok]))) < 0.3


def test_cli_surface_info(tmp_path):
    png = tmp_path / "psd.png"
    result = CliRunner().invoke(main, ["surface", "info", "paper-single-peak", "-o", str(png)])
    assert result.exit_code == 0, result.output
    assert "l_s (slope correlation)" in result.output and png.stat().st_size > 0
    result = CliRunner().invoke(main, ["surface", "info", "paper-single-peak", "--json"])
    assert result.exit_code == 0, result.output
    assert '"slope_correlation_length": 1.97' in result.output


def test_hurst_is_not_estimated_where_the_psd_is_no_power_law():
    """Thousands of overlapping Gaussians: the log-log PSD fit gave H = 4.74, meaningless."""
    from spine_mj.surfaces import random_gaussians

    rough = roughness.summarize(random_gaussians(n_peaks=2000, rng=0))
    assert np.isnan(rough.hurst)


def test_a_surface_is_measured_once_its_answer_kept_while_it_lives():
    import gc
    import weakref

    surf = single_gaussian()
    first = roughness.slope_correlation_length(surf)
    assert roughness._SLOPE_LENGTHS[surf] == first == roughness.slope_correlation_length(surf)
    x = np.linspace(0, 1, 16)
    plane = GridSurface(heights=0.2 * x[None, :] * np.ones((16, 1)), x=x, y=x.copy(), unit="1")
    for _ in range(2):  # the kept answer of a plane is its error, raised again
        with pytest.raises(SpineInputError, match="plane"):
            roughness.slope_correlation_length(plane)
    refs = [weakref.ref(surf), weakref.ref(plane)]
    del surf, plane
    gc.collect()
    assert all(r() is None for r in refs)  # the answers do not keep their surfaces alive


def test_a_plane_is_summarized_with_what_it_has():
    """A plane has heights, slopes and L_c (the domain length), and no l_s: NaN and why."""
    x = np.linspace(0, 4, 17)
    plane = GridSurface(heights=np.zeros((17, 17)), x=x, y=x.copy(), unit="1")
    rough = roughness.summarize(plane)
    assert rough.rms_height == 0 and rough.rms_slope == 0 and rough.char_length == 4
    assert math.isnan(rough.slope_correlation_length) and "plane" in rough.slope_correlation_note
    assert roughness.stiffness_length(plane) == 4  # K's length falls back on L_c


def test_cli_surface_info_on_a_plane_reports_what_it_can(tmp_path):
    from spine_mj.surface_io import save_surface

    x = np.linspace(0, 4, 17)
    path = save_surface(GridSurface(heights=np.zeros((17, 17)), x=x, y=x.copy()), tmp_path / "plane.npz")
    result = CliRunner().invoke(main, ["surface", "info", str(path), "--mu", "0.5"])
    assert result.exit_code == 0, result.output
    assert "l_s (slope correlation)  none: surface has no slope variation (a plane)" in result.output
    # no slope: no fold (K* 0), no crest, no trap; the lag 2 mu 0.1 sets I_e*
    assert "quasistatic needs K > 0 and I_e < 0.1 (set by lag" in result.output


def test_a_tilted_plane_has_no_hurst_estimate(tmp_path):
    """A plane at 20 deg: its PSD is the q^-3 of its edges' step, which the fit read as
    H 0.45; a plane has no roughness spectrum, so no H, and `surface info` says why."""
    from spine_mj.surface_io import save_surface

    x = np.linspace(0, 4, 65)
    tilted = GridSurface(heights=np.tan(np.radians(20)) * x[None, :] * np.ones((65, 1)), x=x, y=x.copy())
    rough = roughness.summarize(tilted)
    assert rough.slope_correlation_note == roughness.PLANE_NOTE
    assert math.isnan(rough.hurst) and rough.rms_slope == pytest.approx(np.tan(np.radians(20)), rel=1e-6)
    result = CliRunner().invoke(main, ["surface", "info", str(save_surface(tilted, tmp_path / "t.npz"))])
    assert result.exit_code == 0, result.output
    assert "Hurst estimate (PSD fit) not estimated (a plane)" in result.output


def test_rms_slope_and_curvature_of_a_few_samples_are_the_closed_forms():
    """A ramp 9 samples across (slope 0.5 along y) and a parabola: rms slope 0.5 and
    curvature (Laplacian / 2) 1 exactly, on grids of few samples; SurfaceTopography's
    pixel is size / points, periodic or not (given (n - 1) dx, the ramp read 9/8 of 0.5)."""
    x, y = np.linspace(0, 50, 401), np.linspace(0, 1, 9)
    ramp = GridSurface(heights=0.5 * y[:, None] * np.ones((1, 401)), x=x, y=y)
    assert roughness.summarize(ramp).rms_slope == pytest.approx(0.5, rel=1e-9)
    u = np.linspace(-1, 1, 11)
    bowl = GridSurface(heights=(u[None, :] ** 2 + 0 * u[:, None]), x=u, y=u.copy())
    assert roughness.summarize(bowl).rms_curvature == pytest.approx(1.0, rel=1e-9)
