"""The one conversion to and from MuJoCo's height field (surfaces/hfield.py): round trip
and row order."""

import numpy as np
import pytest

from spine_mj.surfaces import (
    GridSurface,
    from_hfield,
    single_gaussian,
    to_hfield,
)


def _asymmetric_grid():
    x = np.linspace(-2.0, 3.0, 26)
    y = np.linspace(-1.0, 1.5, 11)
    xx, yy = np.meshgrid(x, y)
    h = 0.1 * xx - 0.05 * yy + 2.0 * np.exp(-((xx - 1.5) ** 2 + (yy - 0.8) ** 2))
    return GridSurface(heights=h, x=x, y=y)


def test_hfield_round_trip_and_layout():
    surf = _asymmetric_grid()
    hf = to_hfield(surf)
    assert hf.data.dtype == np.float32 and hf.data.shape == (11, 26)
    assert hf.data.min() == 0.0 and hf.data.max() == pytest.approx(1.0)
    rx, ry, elev, base = hf.size
    assert (rx, ry) == pytest.approx((2.5, 1.25))
    assert elev == pytest.approx(np.ptp(surf.heights)) and base > 0
    assert hf.pos == pytest.approx((0.5, 0.25, surf.heights.min()))
    # row 0 is the smallest y, column 0 the smallest x
    iy, ix = np.unravel_index(np.argmax(hf.data), hf.data.shape)
    assert surf.x[ix] > 1.0 and surf.y[iy] > 0.5
    back = from_hfield(hf)
    np.testing.assert_allclose(back.x, surf.x)
    np.testing.assert_allclose(back.y, surf.y)
    np.testing.assert_allclose(back.heights, surf.heights, atol=1e-6 * elev)


def test_hfield_of_analytic_and_flat_surfaces():
    hf = to_hfield(single_gaussian(), ncol=51, nrow=41)
    assert hf.data.shape == (41, 51)
    assert hf.data[20, 25] == pytest.approx(1.0)
    flat = GridSurface(heights=np.zeros((5, 5)), x=np.arange(5.0), y=np.arange(5.0))
    hf = to_hfield(flat)
    assert hf.size[2] > 0 and np.all(hf.data == 0)


@pytest.mark.parametrize("periodic", [False, True])
def test_a_refined_grid_keeps_every_sample_and_its_spline_between_them(periodic):
    from spine_mj.surfaces import refine_grid

    surf = _asymmetric_grid()
    if periodic:
        surf = GridSurface(heights=surf.heights, x=surf.x, y=surf.y, periodic=True)
    fine = refine_grid(surf, 2)
    assert fine.heights.shape == (21, 51)
    assert (fine.x[0], fine.x[-1], fine.y[0], fine.y[-1]) == (surf.x[0], surf.x[-1], surf.y[0], surf.y[-1])
    np.testing.assert_array_equal(fine.heights[::2, ::2], surf.heights)  # every sample, exactly
    np.testing.assert_array_equal(fine.x[::2], surf.x)
    mid = surf.height(fine.x[1::2][None, :], fine.y[1::2][:, None])
    np.testing.assert_allclose(fine.heights[1::2, 1::2], mid, rtol=0, atol=1e-12)
    assert refine_grid(surf, 1).heights.shape == surf.heights.shape
    with pytest.raises(ValueError, match="factor must be an integer >= 1, got 0"):
        refine_grid(surf, 0)


def test_a_doubled_hfield_of_a_sampled_smooth_surface_is_the_surfaces_doubled_hfield():
    # the paper's peak (2.22 high) sampled on 41 x 41: its hfield refined x 2 through the
    # grid's spline is the analytic peak's own 81 x 81 hfield, to the spline's error (O(h^2)
    # at the reflected edges, O(h^4) inside), far below the facets' (linear) error
    from spine_mj.sim import hfield_of

    smooth = single_gaussian(bounds=(-3.0, 3.0, -3.0, 3.0))
    errors = []
    for n in (21, 41):
        grid = smooth.sample(n)
        coarse, doubled, exact = hfield_of(grid), hfield_of(grid, refinement=2), hfield_of(smooth, 2 * n - 1)
        assert coarse.data.shape == (n, n) and doubled.data.shape == exact.data.shape == (2 * n - 1,) * 2
        assert doubled.size == pytest.approx(exact.size, rel=1e-3) and doubled.pos == pytest.approx(exact.pos)
        h0, h1, h2 = (hf.data.astype(float) * hf.size[2] + hf.pos[2] for hf in (coarse, doubled, exact))
        np.testing.assert_allclose(h1[::2, ::2], h0, atol=1e-5)  # the old samples kept
        err = np.abs(h1 - h2).max()
        facets = 0.25 * sum(h0[a : a + n - 1, b : b + n - 1] for a in (0, 1) for b in (0, 1))
        assert err < 0.1 * np.abs(h2[1::2, 1::2] - facets).max()  # a refinement, not the facets
        errors.append(err)
    assert errors[1] < 1e-3 and errors[1] < errors[0] / 3.5  # converges, at least as h^2
