import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spine_mj.surfaces import single_gaussian
from spine_mj.theory.convexity import (
    CONCAVE,
    CONVEX,
    SADDLE,
    classify_points,
    hessian_class,
    section_curvature,
    sectional_class,
)

finite = st.floats(-5, 5)


@settings(max_examples=300, deadline=None)
@given(st.floats(0.05, 5), finite, finite, finite, finite)
def test_eq11_quadratic_form_identity(fx, fy, fxx, fxy, fyy):
    h = np.array([[fxx, fxy], [fxy, fyy]])
    v = np.array([fy, -fx])
    expected = -(v @ h @ v) / fx**3
    assert section_curvature(fx, fy, fxx, fxy, fyy) == pytest.approx(expected, rel=1e-9, abs=1e-12)


@settings(max_examples=300, deadline=None)
@given(st.floats(0.05, 5), finite, finite, finite, finite)
def test_definite_hessian_forces_the_sectional_class(fx, fy, fxx, fxy, fyy):
    h = hessian_class(fxx, fxy, fyy)
    s = sectional_class(fx, fy, fxx, fxy, fyy)
    clear = fxx * fyy - fxy * fxy > 1e-6
    if h == CONCAVE and clear:
        assert s == CONCAVE
    if h == CONVEX and clear:
        assert s == CONVEX


def test_contour_curvature_matches_numerical_contour():
    # f = x - a y^2: contour x = c + a y^2 has d2x/dy2 = 2a, and f_x = 1 > 0
    a = 0.3
    assert section_curvature(1.0, 0.0, 0.0, 0.0, -2 * a) == pytest.approx(2 * a)
    assert sectional_class(1.0, 0.0, 0.0, 0.0, -2 * a) == CONVEX


def test_gaussian_peak_and_valley():
    peak, valley = single_gaussian(sign=1), single_gaussian(sign=-1)
    # rising flank of the peak, near the top: convex by both methods
    s, h = classify_points(peak, -0.5, -0.3)
    assert (s, h) == (CONVEX, CONVEX)
    # far side of the valley's floor (rising in +x): concave by both methods
    s, h = classify_points(valley, 0.5, -0.3)
    assert (s, h) == (CONCAVE, CONCAVE)
    # outside the inflection circle of a peak (r > sigma) in the diagonal: a saddle
    assert hessian_class(*peak.hessian(-1.6, -1.6)) == SADDLE


def test_undefined_where_fx_is_zero():
    assert np.isnan(section_curvature(0.0, 1.0, 1.0, 0.0, 1.0))
    assert sectional_class(0.0, 1.0, 1.0, 0.0, 1.0) == 0
