"""The compiled contact of a ball on facets (surfaces/_contact_kernel.py) against the
numpy reference, and its one-point form against its many-point one."""

import numpy as np
import pytest

from spine_mj.surfaces import (
    BallOnFacets,
    TriangulatedSurface,
)

RNG = np.random.default_rng(12345)


@pytest.mark.parametrize("radius", [0.02, 0.05, 0.16])
def test_ball_on_facets_compiled_matches_the_numpy_reference(radius):
    """The compiled contact against the array reference, on rough facets with a wall, a flat
    patch (ties between features) and points past the edges (the ball sees only the facets
    inside; no contact at all gives -inf)."""
    x = np.linspace(0.0, 1.0, 26)
    y = np.linspace(-0.5, 0.5, 21)
    h = RNG.normal(0.0, 0.05, (21, 26))
    h[8:10, :] += 0.3
    h[:, :6] = 0.0
    tri = TriangulatedSurface(heights=h, x=x, y=y)
    px = np.concatenate([RNG.uniform(-0.1, 1.1, 300), [0.1, 0.12, 1.0, 2.0]])
    py = np.concatenate([RNG.uniform(-0.6, 0.6, 300), [0.0, -0.2, 0.5, 2.0]])
    fast = BallOnFacets(tri, radius).evaluate(px, py, order=1)
    slow = BallOnFacets(tri, radius, compiled=False).evaluate(px, py, order=1)
    for a, b in zip(fast, slow):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    assert fast[0][-1] == -np.inf


def test_one_point_and_many_point_forms_agree_and_a_flat_grid_lifts_the_ball_by_nothing():
    """``ball_at`` (the compiled callers' one-point form) equals ``ball_on_facets`` point by
    point; on a flat grid at height c every feature ties and the centre rests at c + r:
    f = c with zero slopes, wherever the ball lies inside."""
    from spine_mj.surfaces._contact_kernel import ball_at, ball_on_facets

    h = RNG.normal(0.0, 0.05, (15, 17))
    args = (h, -1.0, -0.7, 2.0 / 16, 1.4 / 14, 0.09)
    px, py = RNG.uniform(-0.9, 0.9, 40), RNG.uniform(-0.6, 0.6, 40)
    many = np.column_stack(ball_on_facets(px, py, *args))
    one = np.array([ball_at(a, b, *args) for a, b in zip(px, py)])
    np.testing.assert_array_equal(one, many)
    flat = np.full((15, 17), 0.25)
    f, fx, fy = ball_on_facets(px, py, flat, *args[1:])
    np.testing.assert_allclose(f, 0.25, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.c_[fx, fy], 0.0, atol=1e-12)
