"""Generators (surfaces/generators.py): closed forms, statistics against their targets,
PSD slopes, seeds, and nonsense refused (sandpaper's among them; its statistics are
tests/surfaces/test_surfaces_sandpaper.py's)."""

import math

import numpy as np
import pytest

from spine_mj import SpineInputError, roughness
from spine_mj.surfaces import (
    GridSurface,
    fractal_fbm,
    random_gaussians,
    sandpaper,
    single_gaussian,
)

RNG = np.random.default_rng(12345)


def test_single_gaussian_paper_normalization():
    peak = single_gaussian()
    assert peak.height(0, 0) == pytest.approx(10 * math.pi / (2 * math.pi * 1.5**2))
    assert peak.height(0, 0) == pytest.approx(2.2222, abs=1e-4)
    # steepest slope of A exp(-r^2/2s^2) is A/s * exp(-1/2) at r = s
    x = np.linspace(0, 5, 20001)
    slope = np.abs(peak.gradient(x, 0 * x)[0]).max()
    assert slope == pytest.approx(10 / (2 * 1.5**2) / 1.5 * math.exp(-0.5), rel=1e-6)
    assert slope == pytest.approx(0.8986, abs=1e-4)


def test_valley_is_mirror_of_peak():
    peak, valley = single_gaussian(sign=1), single_gaussian(sign=-1)
    x, y = RNG.uniform(-5, 5, (2, 100))
    for a, b in zip(peak.evaluate(x, y), valley.evaluate(x, y)):
        np.testing.assert_allclose(a, -b)


def test_random_gaussians_reproducible_and_distributed_as_documented():
    a = random_gaussians(rng=7)
    b = random_gaussians(rng=7)
    c = random_gaussians(rng=8)
    for name in ("amplitude", "center_x", "center_y", "sigma_x", "sigma_y"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.center_x, c.center_x)
    assert a.n_gaussians == 100
    assert np.all((a.sigma_x >= 0.5) & (a.sigma_x <= 1.5))
    np.testing.assert_array_equal(a.sigma_x, a.sigma_y)
    assert np.all((a.amplitude >= 0.5) & (a.amplitude <= 1.5))
    assert np.all((a.center_x >= -10) & (a.center_x <= 10))
    concave = random_gaussians(sign=-1, rng=7)
    np.testing.assert_array_equal(concave.amplitude, -a.amplitude)
    big = random_gaussians(n_peaks=4000, rng=1)
    assert big.amplitude.mean() == pytest.approx(1.0, abs=0.02)
    assert big.center_x.mean() == pytest.approx(0.0, abs=0.3)


def test_random_gaussians_without_overlap_respect_separation():
    s = random_gaussians(n_peaks=30, overlap=False, min_separation=1.5, rng=3)
    d = np.hypot(s.center_x[:, None] - s.center_x, s.center_y[:, None] - s.center_y)
    need = 1.5 * (s.sigma_x[:, None] + s.sigma_x[None, :])
    off = ~np.eye(30, dtype=bool)
    assert np.all(d[off] >= need[off] - 1e-12)
    with pytest.raises(SpineInputError, match="could not place peak"):
        random_gaussians(n_peaks=500, overlap=False, min_separation=3, rng=1)


def radial_psd_slope(surf: GridSurface) -> float:
    """Log-log slope of the package's radially averaged PSD over the middle of the band."""
    q, psd = roughness.radial_psd(surf)
    k = q / (2 * np.pi) * surf.spacing[0]  # cycles per sample
    band = (k > 2 / surf.shape[1]) & (k < 0.3)
    return np.polyfit(np.log(q[band]), np.log(psd[band]), 1)[0]


@pytest.mark.parametrize("hurst", [0.3, 0.5, 0.7, 0.9])
def test_fractal_psd_slope_matches_hurst(hurst):
    slopes = [radial_psd_slope(fractal_fbm(nx=256, hurst=hurst, rng=s)) for s in range(3)]
    assert np.mean(slopes) == pytest.approx(-(2 * hurst + 2), abs=0.1)


@pytest.mark.parametrize("hurst", [0.3, 0.6, 0.9])
def test_fractal_psd_slope_by_surfacetopography(hurst):
    """Independent estimator: SurfaceTopography's radially averaged PSD."""
    import SurfaceTopography as st

    slopes = []
    for seed in range(3):
        surf = fractal_fbm(nx=256, hurst=hurst, rng=seed)
        topo = st.Topography(surf.heights.T, (20.0, 20.0), periodic=True)
        q, c = topo.power_spectrum_from_area(nb_points_per_decade=8)
        ok = np.isfinite(c) & (q > 2 * np.pi * 4 / 20) & (q < 2 * np.pi * 0.3 / (20 / 256))
        slopes.append(np.polyfit(np.log(q[ok]), np.log(c[ok]), 1)[0])
    assert np.mean(slopes) == pytest.approx(-(2 * hurst + 2), abs=0.1)


def test_fractal_normalization_and_reproducibility():
    a = fractal_fbm(nx=64, ny=63, hurst=0.7, rms_height=2.5, rng=11)
    b = fractal_fbm(nx=64, ny=63, hurst=0.7, rms_height=2.5, rng=11)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert a.shape == (63, 64)
    assert a.heights.std() == pytest.approx(2.5)
    assert a.heights.mean() == pytest.approx(0.0, abs=1e-12)
    s = fractal_fbm(nx=128, hurst=0.7, rms_slope=0.4, rng=1)
    # periodic: the rms of the Fourier derivative (which drops the Nyquist row and column)
    spec = np.fft.fft2(s.heights)
    k = 2j * np.pi * np.fft.fftfreq(128, s.spacing[0])
    gx = np.fft.ifft2(spec * k[None, :]).real
    gy = np.fft.ifft2(spec * k[:, None]).real
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(0.4, rel=0.01)
    nonper = fractal_fbm(nx=64, hurst=0.7, rms_slope=0.4, periodic=False, rng=1)
    gy, gx = np.gradient(nonper.heights, nonper.spacing[1], nonper.spacing[0])
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(0.4)
    assert not nonper.periodic


@pytest.mark.parametrize(
    "func, kwargs, match",
    [
        (fractal_fbm, dict(hurst=1.0), r"hurst must lie in the open interval \(0, 1\)"),
        (fractal_fbm, dict(hurst=0.0), "hurst"),
        (fractal_fbm, dict(hurst=0.5, nx=3), "nx must be an integer >= 4"),
        (fractal_fbm, dict(rms_height=1, rms_slope=1), "not both"),
        (fractal_fbm, dict(periodic=3), "periodic must be true or false, got 3"),
        (fractal_fbm, dict(periodic="no"), "periodic must be true or false"),
        (random_gaussians, dict(n_peaks=0), "n_peaks must be an integer in 1..100000"),
        (random_gaussians, dict(n_peaks=10**8), "n_peaks must be an integer in 1..100000"),
        (random_gaussians, dict(n_peaks=-5), "n_peaks"),
        (random_gaussians, dict(sigma_range=(0.0, 1.0)), "widths"),
        (random_gaussians, dict(sigma_range=(-1.0, 1.0)), "widths"),
        (random_gaussians, dict(sign=0), "sign"),
        (single_gaussian, dict(sigma_x=0), "sigma_x must be a finite number > 0"),
        (sandpaper, dict(grit="P80"), "grit must be one of"),
        (sandpaper, dict(grit="P36", spacing_m=-1), "spacing_m"),
        (random_gaussians, dict(rng=-1), "rng"),
    ],
)
def test_generators_reject_nonsense(func, kwargs, match):
    with pytest.raises(SpineInputError, match=match):
        func(**kwargs)


@pytest.mark.parametrize(
    "key, value", [("overlap", float("nan")), ("overlap", 2), ("anisotropic", "no"), ("anisotropic", None)]
)
def test_random_gaussians_refuse_a_flag_that_is_not_a_boolean(key, value):
    with pytest.raises(SpineInputError, match=f"{key} must be true or false"):
        random_gaussians(n_peaks=3, rng=0, **{key: value})


def test_sweep_set_with_a_non_boolean_flag_is_refused_when_the_config_is_read():
    from spine_mj.sweep import parse_config

    doc = {
        "surfaces": [{"preset": "paper-random-convex", "set": {"anisotropic": "no"}}],
        "starts": {"points": [[0.1, 0.5]]},
        "grid": {"mu": 0.5},
    }
    with pytest.raises(SpineInputError, match="anisotropic must be true or false"):
        parse_config(doc)
