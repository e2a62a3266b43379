"""A ball on triangulated facets (surfaces/facets.py): closed forms on a tilted plane and
a spike, brute force over the footprint, bad input."""

import math

import numpy as np
import pytest

from spine_mj import SpineInputError
from spine_mj.surfaces import (
    BallOnFacets,
    TriangulatedSurface,
    single_gaussian,
)

RNG = np.random.default_rng(12345)


def test_ball_on_a_tilted_plane_rides_its_offset_plane():
    """Face contacts only: the centre rides the plane lifted by r sqrt(1 + a^2 + b^2), at the
    plane's slopes (closed form)."""
    x = np.linspace(0.0, 1.0, 11)
    a, b = 0.7, -0.3
    tri = TriangulatedSurface(heights=a * x[None, :] + b * x[:, None], x=x, y=x.copy())
    ball = BallOnFacets(tri, 0.05)
    px, py = RNG.uniform(0.2, 0.8, (2, 50))
    f, fx, fy = ball.evaluate(px, py, order=1)
    lift = 0.05 * math.sqrt(1 + a * a + b * b) - 0.05
    np.testing.assert_allclose(f, a * px + b * py + lift, atol=1e-12)
    np.testing.assert_allclose(fx, a, atol=1e-12)
    np.testing.assert_allclose(fy, b, atol=1e-12)


def test_ball_on_a_spike_rides_the_sphere_around_its_tip():
    """One raised node on flat ground: within the spike's reach the ball rests on its
    vertex (a sphere of radius r around it), slopes pointing away from it."""
    x = np.linspace(-1.0, 1.0, 21)
    h = np.zeros((21, 21))
    h[10, 10] = 1.0
    ball = BallOnFacets(TriangulatedSurface(heights=h, x=x, y=x.copy()), 0.3)
    d = np.array([0.0, 0.05, 0.1])
    f, fx, fy = ball.evaluate(d, 0.5 * d, order=1)
    rho = np.hypot(d, 0.5 * d)
    z = 1.0 + np.sqrt(0.09 - rho**2)  # the centre on the vertex's sphere
    np.testing.assert_allclose(f, z - 0.3, atol=1e-12)
    np.testing.assert_allclose(fx, -d / (z - 1.0), atol=1e-12)
    np.testing.assert_allclose(fy, -0.5 * d / (z - 1.0), atol=1e-12)


def test_ball_on_facets_against_brute_force_over_the_footprint():
    """Random facets with a steep wall: the exact contact is at least as high as the best of
    a fine grid of points under the ball (the slow, obvious reference) and within its
    resolution; the slopes agree where they are moderate."""
    x = np.linspace(0.0, 1.0, 21)
    h = RNG.normal(0.0, 0.05, (21, 21))
    h[8:10, :] += 0.3
    tri = TriangulatedSurface(heights=h, x=x, y=x.copy())
    r, n = 0.05, 401
    ball = BallOnFacets(tri, r)
    pts = RNG.uniform(0.2, 0.8, (25, 2))
    f, fx, fy = ball.evaluate(pts[:, 0], pts[:, 1], order=1)
    u = np.linspace(-r, r, n)
    for k, (cx, cy) in enumerate(pts):
        gx, gy = np.meshgrid(cx + u, cy + u)
        d2 = (gx - cx) ** 2 + (gy - cy) ** 2
        inside = d2 <= r * r
        base = tri.height(gx[inside], gy[inside])
        top = base + np.sqrt(r * r - d2[inside])
        i = int(np.argmax(top))
        assert -1e-12 <= f[k] + r - top[i] <= 10 * (2 * r / (n - 1))  # slope 10 x one sample
        slope = np.array([gx[inside][i] - cx, gy[inside][i] - cy]) / (top[i] - base[i])
        if np.hypot(*slope) < 2:
            np.testing.assert_allclose([fx[k], fy[k]], slope, atol=0.02)


def test_ball_on_facets_rejects_bad_input():
    x = np.linspace(0.0, 1.0, 5)
    tri = TriangulatedSurface(heights=np.zeros((5, 5)), x=x, y=x.copy())
    with pytest.raises(SpineInputError, match="radius"):
        BallOnFacets(tri, 0.0)
    with pytest.raises(SpineInputError, match="TriangulatedSurface"):
        BallOnFacets(single_gaussian(), 0.1)
    with pytest.raises(SpineInputError, match="Hessian"):
        BallOnFacets(tri, 0.1).hessian(0.5, 0.5)


def test_a_fortran_ordered_grid_reaches_the_kernels_without_a_copy():
    """A scan's heights may arrive transposed (Fortran order); the grid keeps them in C order
    once, so each kernel call takes the array as it is (a copy per call was 26 of the 89
    CPU-s of comparing 12 starts on di-1)."""
    h = np.asfortranarray(np.random.default_rng(0).normal(size=(40, 30)))
    fac = TriangulatedSurface(heights=h, x=np.arange(30.0), y=np.arange(40.0))
    assert fac.heights.flags.c_contiguous
    np.testing.assert_array_equal(fac.heights, h)
    ball = BallOnFacets(fac, radius=1.5)
    assert ball.kernel_args()[0] is ball.kernel_args()[0]
