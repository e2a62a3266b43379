"""The compiled dilation kernel (surfaces/_dilation_kernel.py) called directly: its row
envelope of half-circles against the brute force, and the whole kernel against the numpy
reference of the dilation module."""

import math

import numpy as np
import pytest

from spine_mj.surfaces import ball_dilation, ball_dilation_reference
from spine_mj.surfaces._dilation_kernel import _line, ball_rows, footprint_rows


def _line_brute(f, dx, r):
    """``max_j f[j] + sqrt(r^2 - ((i - j) dx)^2)`` over ``|i - j| dx <= r``, by every pair."""
    n = len(f)
    out = np.full(n, -np.inf)
    for i in range(n):
        for j in range(n):
            u = (i - j) * dx
            if abs(u) <= r:
                out[i] = max(out[i], f[j] + math.sqrt(r * r - u * u))
    return out


@pytest.mark.parametrize("seed", range(6))
def test_the_row_envelope_is_the_brute_force_maximum(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 40))
    dx, r = rng.uniform(0.3, 2.0), rng.uniform(0.1, 30.0)  # from one sample to the whole row
    f = rng.normal(scale=rng.choice([0.01, 1.0, 20.0]), size=n)
    out, v, z = np.empty(n), np.empty(n, dtype=np.int64), np.empty(n + 1)
    _line(f, n, dx, r, out, v, z)
    np.testing.assert_allclose(out, _line_brute(f, dx, r), rtol=0, atol=1e-12 * max(1.0, np.abs(f).max() + r))


def test_equal_heights_tie_and_a_lone_sample_is_its_own_cap():
    """Flat row: every circle ties, the envelope is f + r; one sample alone: f + r."""
    out, v, z = np.empty(9), np.empty(9, dtype=np.int64), np.empty(10)
    _line(np.full(9, 2.0), 9, 0.5, 1.0, out, v, z)
    np.testing.assert_allclose(out, 3.0)
    _line(np.array([5.0]), 1, 1.0, 0.7, out, v, z)
    assert out[0] == pytest.approx(5.7)


@pytest.mark.parametrize("wrap", [False, True])
def test_the_kernel_equals_the_reference_and_reports_each_row_of_the_footprint(wrap):
    """The footprint's rows one call each (as ball_dilation reports them) or all in one
    call give the reference's dilation; progress hears every row, the last as done."""
    rng = np.random.default_rng(3)
    h = rng.normal(size=(13, 17))
    heard = []
    fast = ball_dilation(
        h, 2.5, spacing=(0.7, 0.9), periodic=wrap, progress=lambda d, t: heard.append((d, t))
    )
    slow = ball_dilation_reference(h, 2.5, spacing=(0.7, 0.9), periodic=wrap)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-12)
    n = footprint_rows(2.5, 0.9, 13, wrap)
    assert n == 3 and heard == [(k, n) for k in range(1, n + 1)]
    whole = np.full(h.shape, -np.inf)
    ball_rows(h, 2.5, 0.7, 0.9, wrap, 0, n, whole)
    np.testing.assert_allclose(whole - 2.5, slow, rtol=0, atol=1e-12)
