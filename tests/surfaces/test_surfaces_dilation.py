"""Grey-scale dilation by a ball: the row-envelope kernel against the brute force over the
footprint, closed forms, and the surface-level ``dilate``."""

import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import GridSurface, ball_dilation, ball_dilation_reference, dilate, single_gaussian


def _rough(rng, ny, nx, scale):
    """White noise plus a random walk: steep single-sample spikes and long slopes."""
    walk = np.cumsum(np.cumsum(rng.normal(size=(ny, nx)), axis=0), axis=1)
    return scale * (rng.normal(size=(ny, nx)) + 0.1 * walk)


@pytest.mark.parametrize("periodic", [False, True])
def test_matches_the_brute_force_on_rough_grids(periodic):
    rng = np.random.default_rng(7)
    for _ in range(25):
        ny, nx = (int(n) for n in rng.integers(1, 30, 2))
        dx, dy = rng.uniform(0.4, 2.0, 2)
        radius = rng.uniform(0.1, 20.0)  # up to tips wider than the grid (every copy of a period)
        h = _rough(rng, ny, nx, rng.choice([0.01, 1.0, 30.0]))
        fast = ball_dilation(h, radius, spacing=(dx, dy), periodic=periodic)
        slow = ball_dilation_reference(h, radius, spacing=(dx, dy), periodic=periodic)
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-12 * max(1.0, np.abs(slow).max()))


def test_a_single_spike_dilates_to_the_ball():
    """One raised sample: the dilation is the ball's cap around it (over the flat floor)."""
    n, radius, h0 = 41, 7.5, 100.0
    h = np.zeros((n, n))
    h[20, 20] = h0
    g = ball_dilation(h, radius, spacing=(1.0, 1.0))
    u = np.arange(n) - 20.0
    rho2 = u[None, :] ** 2 + u[:, None] ** 2
    cap = np.where(rho2 <= radius**2, h0 + np.sqrt(np.clip(radius**2 - rho2, 0, None)) - radius, 0.0)
    np.testing.assert_allclose(g, cap, atol=1e-12)


def test_a_plane_is_lifted_along_its_normal():
    """A tilted plane z = s x dilates to the parallel plane R (sqrt(1 + s^2) - 1) higher
    (the ball touches it along the normal), up to the sampling of the cap."""
    x = np.arange(-60.0, 61.0) * 0.05
    s, radius = 0.5, 0.8
    h = np.broadcast_to(s * x, (x.size, x.size))
    g = ball_dilation(h, radius, spacing=(0.05, 0.05))
    inner = g[20:-20, 20:-20] - h[20:-20, 20:-20]
    assert inner == pytest.approx(radius * (math.sqrt(1 + s * s) - 1), abs=2e-3)


def test_zero_radius_and_input_checks():
    h = np.arange(12.0).reshape(3, 4)
    np.testing.assert_array_equal(ball_dilation(h, 0.0, spacing=(1, 1)), h)
    with pytest.raises(SpineInputError, match=r"radius \(tip radius\) must be finite and >= 0, got -1.0"):
        ball_dilation(h, -1.0, spacing=(1, 1))
    with pytest.raises(SpineInputError, match=r"spacing must be two finite numbers > 0"):
        ball_dilation(h, 1.0, spacing=(1, 0))
    with pytest.raises(SpineInputError, match="heights must be a 2-D array"):
        ball_dilation(np.zeros(5), 1.0, spacing=(1, 1))
    with pytest.raises(SpineInputError, match="heights contain NaN"):
        ball_dilation(np.full((2, 2), np.nan), 1.0, spacing=(1, 1))


def test_refused_over_the_memory_budget(monkeypatch):
    monkeypatch.setenv("SPINE_MJ_MEMORY_BUDGET", "1M")
    with pytest.raises(
        SpineInputError, match=r"dilating a 300 x 300 grid by a tip would need 2.06 MiB of memory, more than"
    ):
        ball_dilation(np.zeros((300, 300)), 2.0, spacing=(1, 1))


def test_dilate_matches_the_brute_force_on_grids_and_analytic_surfaces():
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 3.0, 61)
    for periodic in (False, True):
        grid = GridSurface(heights=_rough(rng, 61, 61, 0.05), x=x, y=x.copy(), periodic=periodic)
        dx, dy = grid.spacing
        got = dilate(grid, 0.37)
        ref = ball_dilation_reference(grid.heights, 0.37, spacing=(dx, dy), periodic=periodic)
        np.testing.assert_allclose(got.heights, ref, atol=1e-12)
        assert got.periodic is periodic
    # an analytic surface is sampled with a margin of R, so its edge sees the true neighbourhood
    peak = single_gaussian()
    got = dilate(peak, 0.5)
    dx, dy = got.spacing
    rx, ry = int(0.5 // dx), int(0.5 // dy)
    xw = got.x[0] + dx * np.arange(-rx, got.x.size + rx)
    yw = got.y[0] + dy * np.arange(-ry, got.y.size + ry)
    wide = ball_dilation_reference(peak.height(xw[None, :], yw[:, None]), 0.5, spacing=(dx, dy))
    np.testing.assert_allclose(got.heights, wide[ry:-ry, rx:-rx], atol=1e-12)
