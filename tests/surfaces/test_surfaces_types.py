"""Surface types (surfaces/types.py): evaluation, derivatives against finite differences,
the grid interpolant's accuracy and order, periodicity, Gaussian sums in blocks, bad data."""

import math

import numpy as np
import pytest
from scipy import ndimage

from spine_mj import SpineInputError
from spine_mj.surfaces import (
    GaussianSurface,
    GridSurface,
    fractal_fbm,
    random_gaussians,
    single_gaussian,
)

RNG = np.random.default_rng(12345)


def test_evaluation_broadcasts_and_matches_separate_calls():
    surf = single_gaussian()
    x = np.linspace(-4, 4, 7)[None, :]
    y = np.linspace(-3, 3, 5)[:, None]
    f = surf.height(x, y)
    assert f.shape == (5, 7)
    fx, fy = surf.gradient(x, y)
    fxx, fxy, fyy = surf.hessian(x, y)
    both = surf.evaluate(x, y)
    for a, b in zip((f, fx, fy, fxx, fxy, fyy), both):
        np.testing.assert_array_equal(a, b)
    assert surf.height(1.0, 2.0).shape == ()


def _grid_errors(h):
    """Max interior errors (value, slope, curvature) of a gridded Gaussian at spacing h."""
    exact = single_gaussian(bounds=(-6, 6, -6, 6))
    n = round(12 / h) + 1
    grid = exact.sample(n)
    x, y = np.random.default_rng(0).uniform(-4, 4, (2, 3000))
    e = exact.evaluate(x, y)
    g = grid.evaluate(x, y)
    return (
        np.abs(e[0] - g[0]).max(),
        max(np.abs(e[1] - g[1]).max(), np.abs(e[2] - g[2]).max()),
        max(np.abs(e[k] - g[k]).max() for k in (3, 4, 5)),
    )


def test_grid_interpolant_accuracy_and_convergence_order():
    coarse, fine = _grid_errors(0.1), _grid_errors(0.05)
    assert coarse[0] < 2e-6 and coarse[1] < 5e-5 and coarse[2] < 2e-3
    orders = [math.log2(c / f) for c, f in zip(coarse, fine)]
    assert orders[0] > 3.5, orders  # O(h^4) heights
    assert orders[1] > 2.5, orders  # O(h^3) slopes
    assert orders[2] > 1.7, orders  # O(h^2) curvatures


def test_grid_interpolates_its_samples():
    surf = fractal_fbm(nx=32, hurst=0.6, rng=1, periodic=False)
    xx, yy = np.meshgrid(surf.x, surf.y)
    np.testing.assert_allclose(surf.height(xx, yy), surf.heights, atol=1e-12)


def test_fast_grid_evaluation_matches_scipy_reference():
    """The hand-written B-spline gather equals scipy.ndimage.map_coordinates."""
    surf = fractal_fbm(nx=48, ny=40, hurst=0.7, rng=2)
    sp = surf.spline
    u = RNG.uniform(0, 48, 400)
    v = RNG.uniform(0, 40, 400)
    ref = ndimage.map_coordinates(surf.heights, [v, u], order=3, mode="grid-wrap")
    np.testing.assert_allclose(surf.height(sp.x0 + u * sp.dx, sp.y0 + v * sp.dy), ref, atol=1e-12)

    flat = fractal_fbm(nx=30, hurst=0.7, rng=3, periodic=False)
    pad = 8
    padded = np.pad(flat.heights, pad, mode="reflect", reflect_type="odd")
    u = RNG.uniform(0, 29, 300)
    v = RNG.uniform(0, 29, 300)
    ref = ndimage.map_coordinates(padded, [v + pad, u + pad], order=3, mode="mirror")
    sp = flat.spline
    np.testing.assert_allclose(flat.height(sp.x0 + u * sp.dx, sp.y0 + v * sp.dy), ref, atol=1e-12)


def test_periodic_grid_repeats_and_nonperiodic_is_nan_outside():
    surf = fractal_fbm(nx=32, size=(8.0, 6.0), hurst=0.8, rng=5)
    x, y = RNG.uniform(-3, 3, (2, 50))
    lx, ly = 8.0, 6.0
    for a, b in zip(surf.evaluate(x, y), surf.evaluate(x + lx, y - 2 * ly)):
        np.testing.assert_allclose(a, b, atol=1e-10)
    flat = single_gaussian().sample(21)
    assert np.isnan(flat.height(5.5, 0.0))
    assert np.isfinite(flat.height(5.0, -5.0))
    assert not flat.contains(5.5, 0.0) and flat.contains(0.0, 0.0)


def test_resample_keeps_surface():
    exact = single_gaussian()
    grid = exact.sample(101)
    fine = grid.resample(0.05)
    assert fine.spacing == pytest.approx((0.05, 0.05))
    x, y = RNG.uniform(-4, 4, (2, 200))
    np.testing.assert_allclose(fine.height(x, y), exact.height(x, y), atol=1e-4)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(heights=np.full((5, 5), np.nan)), "NaN or infinite"),
        (dict(heights=np.where(np.eye(5) > 0, np.inf, 0.0)), "NaN or infinite"),
        (dict(heights=np.zeros((3, 5)), y=np.arange(3.0)), "at least 4 points a side"),
        (dict(x=np.array([0.0, 1, 1, 2, 3])), "strictly increasing"),
        (dict(x=np.array([0.0, 1, 2, 4, 5])), "uniformly spaced"),
        (dict(heights=np.zeros(25)), "2-D"),
    ],
)
def test_grid_surface_rejects_bad_data(kwargs, match):
    base = dict(heights=np.zeros((5, 5)), x=np.arange(5.0), y=np.arange(5.0))
    base.update(kwargs)
    with pytest.raises(SpineInputError, match=match):
        GridSurface(**base)


def test_gaussian_surface_rejects_bad_widths():
    with pytest.raises(SpineInputError, match="sigma_y must be > 0"):
        GaussianSurface(
            amplitude=[1.0],
            center_x=[0.0],
            center_y=[0.0],
            sigma_x=[1.0],
            sigma_y=[0.0],
            bounds=(-1, 1, -1, 1),
        )
    with pytest.raises(SpineInputError, match="bounds"):
        GaussianSurface(
            amplitude=[1.0],
            center_x=[0.0],
            center_y=[0.0],
            sigma_x=[1.0],
            sigma_y=[1.0],
            bounds=(1, -1, -1, 1),
        )


def test_gaussian_sum_on_a_grid_equals_its_pointwise_values():
    """The separable grid path (x a row, y a column) against the pointwise sum, orders 0-2."""
    from spine_mj.surfaces import GaussianSurface

    k = 30
    surf = GaussianSurface(
        amplitude=RNG.normal(0.0, 1.0, k),
        center_x=RNG.uniform(-2, 2, k),
        center_y=RNG.uniform(-2, 2, k),
        sigma_x=RNG.uniform(0.2, 1.0, k),
        sigma_y=RNG.uniform(0.2, 1.0, k),
        bounds=(-2, 2, -2, 2),
    )
    x, y = np.linspace(-2, 2, 37), np.linspace(-2.5, 2, 23)
    grid = surf.evaluate(x[None, :], y[:, None], order=2)
    X, Y = np.meshgrid(x, y)
    points = surf.evaluate(X, Y, order=2)
    for a, b in zip(grid, points):
        assert a.shape == (23, 37)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def test_gaussian_sums_in_byte_budget_blocks_equal_one_pass(monkeypatch):
    """A Gaussian surface evaluates points x Gaussians in blocks within BLOCK_BYTES (at
    MAX_PEAKS Gaussians one 32768-point chunk held 26 GB per temporary); whatever the
    blocks, on a tensor grid and pointwise, the sums are the one-pass ones."""
    from spine_mj.surfaces import types

    surf = random_gaussians(n_peaks=300, rng=1)
    x = np.linspace(*surf.bounds[:2], 57)
    y = np.linspace(*surf.bounds[2:], 43)
    xx, yy = np.meshgrid(x, y)
    whole = surf.evaluate(x[None, :], y[:, None], order=2)
    # blocks of 5 points, and of 15 Gaussians on the grid
    monkeypatch.setattr(types, "BLOCK_BYTES", 8 * 8 * 300 * 5)
    assert surf._points_per_chunk() == 5
    for got in (surf.evaluate(x[None, :], y[:, None], order=2), surf.evaluate(xx, yy, order=2)):
        for a, b in zip(got, whole, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_gaussian_derivatives_match_finite_differences():
    surf = random_gaussians(n_peaks=20, anisotropic=True, rng=4)
    x, y = RNG.uniform(-8, 8, (2, 200))
    h = 1e-5
    _, fx, fy, fxx, fxy, fyy = surf.evaluate(x, y)
    np.testing.assert_allclose(fx, (surf.height(x + h, y) - surf.height(x - h, y)) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(fy, (surf.height(x, y + h) - surf.height(x, y - h)) / (2 * h), atol=1e-7)
    gx_p, _ = surf.gradient(x + h, y)
    gx_m, _ = surf.gradient(x - h, y)
    _, gy_p = surf.gradient(x, y + h)
    _, gy_m = surf.gradient(x, y - h)
    gxy_p, _ = surf.gradient(x, y + h)
    gxy_m, _ = surf.gradient(x, y - h)
    np.testing.assert_allclose(fxx, (gx_p - gx_m) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(fyy, (gy_p - gy_m) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(fxy, (gxy_p - gxy_m) / (2 * h), atol=1e-6)
