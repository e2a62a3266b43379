"""The ABBM track: a slope that is a random walk of the stated intensity below its
correlation length, stationary beyond it, uniform in y."""

import math

import numpy as np
import pytest

from spine_mj import surfaces
from spine_mj.errors import SpineInputError
from spine_mj.presets import make_surface


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


def test_abbm_preset_and_size_range():
    surf = make_surface("abbm")
    assert surf.heights.shape[1] == 4001
    lo, hi = surfaces.abbm_size_range(0.1, 100.0)
    assert (lo, hi) == pytest.approx((1.0, 10.0))


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
