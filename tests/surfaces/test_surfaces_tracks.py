"""The ABBM track: a slope that is a random walk of the stated intensity below its
correlation length, stationary beyond it, uniform in y."""

import math

import numpy as np
import pytest

from spine_mj import surfaces
from spine_mj.errors import SpineInputError


def test_slope_walk_has_the_stated_intensity_below_and_rms_beyond_the_correlation_length():
    d, xi, dx = 1e-4, 100.0, 0.1
    s = surfaces.abbm_slope_walk(400_000, dx, d, xi, np.random.default_rng(3))
    for lag in (1, 10, 50):  # <(s(x + r) - s(x))^2> = 2 D xi (1 - exp(-r / xi)) exactly
        expected = 2 * d * xi * (1 - math.exp(-lag * dx / xi))
        assert np.mean((s[lag:] - s[:-lag]) ** 2) == pytest.approx(expected, rel=0.05)
        assert expected == pytest.approx(2 * d * lag * dx, rel=0.03)  # a walk of intensity D
    assert s.std() == pytest.approx(math.sqrt(d * xi), rel=0.1)


def test_track_is_uniform_in_y_and_its_slope_is_the_walk():
    surf = surfaces.abbm_track(length=100.0, points=1001, width=2.0, correlation_length=50.0, rng=7)
    assert np.ptp(surf.heights, axis=0).max() == 0.0
    again = surfaces.abbm_track(length=100.0, points=1001, width=2.0, correlation_length=50.0, rng=7)
    assert np.array_equal(surf.heights, again.heights)
    walk = surfaces.abbm_slope_walk(1001, 0.1, 1e-4, 50.0, np.random.default_rng(7))
    x = surf.x[5:-5]
    gx, gy = surf.gradient(x, np.zeros_like(x))
    assert np.abs(gy).max() < 1e-12
    assert np.abs(gx - walk[5:-5]).max() < 0.1 * walk.std()


def test_force_intensity_maps_the_slope_walk_through_the_landscape_force():
    mu, d = 0.5, 1e-4
    s = surfaces.abbm_slope_walk(200_000, 0.1, d, 1000.0, np.random.default_rng(1)) * 0.2
    force = np.tan(np.arctan(s) + np.arctan(mu))
    sigma = np.mean(np.diff(force) ** 2) / (2 * 0.1)
    assert sigma == pytest.approx(surfaces.abbm_force_intensity(d * 0.04, mu), rel=0.05)


def test_abbm_preset_is_derived_from_the_abbm_scales():
    """The preset's parameters are the derivation of spine_mj.surfaces.tracks: at mu 0.5, K
    from 1 to 10 puts S_m = sigma / k^2 from xi / 64 down to 50 spacings, the track holds
    800 cutoffs of K 1 in the stretch a study keeps, and the rms slope is 0.1."""
    from spine_mj.presets import load_preset

    preset = load_preset("abbm")
    p = preset.params
    dx = p["length"] / (p["points"] - 1)
    d, xi, mu = p["slope_intensity"], p["correlation_length"], preset.extras["engagement"]["mu"]
    assert surfaces.abbm_size_range(dx, xi) == pytest.approx((50 * dx, xi / 64))
    assert surfaces.abbm_stiffness_range(dx, d, xi, mu) == pytest.approx((1.0, 10.0))
    sigma = surfaces.abbm_force_intensity(d, mu)
    for k_number, cutoff in ((1.0, xi / 64), (10.0, 50 * dx)):  # S_m = sigma / k^2, k = K / xi
        assert sigma / (k_number / xi) ** 2 == pytest.approx(cutoff)
    assert 0.9 * p["length"] >= surfaces.abbm_length(d, xi, mu, 1.0)
    assert math.sqrt(d * xi) == pytest.approx(0.1)


def test_abbm_track_states_its_slope_length_and_default_stiffness_numbers():
    """l_s of an ABBM track is its xi, exact for the ensemble (the walk's autocorrelation
    exp(-r / xi) falls to 1/e at xi; pooled over draws it does), where one track measures
    it poorly; the default K span the ABBM range, three a decade."""
    from spine_mj.roughness import slope_autocorrelation, slope_correlation_length

    xi = 20.0
    tracks = [
        surfaces.abbm_track(length=2000.0, points=2001, width=3.0, correlation_length=xi, rng=s)
        for s in range(8)
    ]
    assert all(slope_correlation_length(t) == xi for t in tracks)
    lags, _ = slope_autocorrelation(tracks[0])
    pooled = np.mean([slope_autocorrelation(t)[1][: int(2 * xi)] for t in tracks], axis=0)
    assert np.interp(1 / math.e, pooled[::-1], lags[: int(2 * xi)][::-1]) == pytest.approx(xi, rel=0.15)
    track = surfaces.abbm_track(
        length=4000.0, points=40001, width=0.5, slope_intensity=1e-5, correlation_length=1000.0, rng=1
    )
    lo, hi = surfaces.abbm_stiffness_range(0.1, 1e-5, 1000.0, 0.5)
    ks = surfaces.abbm_stiffness_numbers(track, 0.5)
    assert ks[0] == pytest.approx(lo, rel=5e-3) and ks[-1] == pytest.approx(hi, rel=5e-3)  # 3 figures
    assert len(ks) == round(3 * math.log10(hi / lo)) + 1
    with pytest.raises(SpineInputError, match="ABBM track"):
        surfaces.abbm_stiffness_numbers(surfaces.corrugation(), 0.5)


@pytest.mark.parametrize(
    "bad",
    [
        {"length": -1.0},
        {"points": 3},
        {"slope_intensity": math.nan},
        {"correlation_length": 1e9},
        {"slope_intensity": 1.0},
        {"width": 0.0},
    ],
)
def test_track_refuses_nonsense(bad):
    with pytest.raises(SpineInputError):
        surfaces.abbm_track(**bad)
