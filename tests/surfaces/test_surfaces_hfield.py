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
