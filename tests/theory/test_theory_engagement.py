import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spine_mj.errors import SpineInputError
from spine_mj.theory.engagement import ENGAGED, SELF_LOCK, SLIP, kappa, kappa_of_normal, slip_direction


def _holds(fx, fy, mu, k, margin=0.0):
    """Brute force from the vector definitions (docs/physics.md §1): |T| <= mu N and N > 0."""
    s = math.sqrt(1 + fx * fx + fy * fy)
    n = np.array([fx, fy, -1.0]) / s
    r = np.array([k, 0.0, -1.0])
    normal = r @ n
    t = r - normal * n
    return normal > 0 and np.linalg.norm(t) <= mu * normal * (1 + margin)


@pytest.mark.parametrize("mu", [0.2, 0.5, 1.0, 1.25])
def test_two_d_closed_form(mu):
    phi = math.atan(mu)
    theta = np.linspace(-1.5, 1.5, 601)
    k, region = kappa(np.tan(theta), 0.0, mu)
    engaged = (theta + phi > 1e-9) & (theta + phi < math.pi / 2 - 1e-9)
    np.testing.assert_allclose(k[engaged], np.tan(theta[engaged] + phi), rtol=1e-9)
    assert np.all(region[engaged] == ENGAGED)
    assert np.all(region[theta + phi > math.pi / 2 + 1e-9] == SELF_LOCK)
    assert np.all(np.isposinf(k[region == SELF_LOCK]))
    assert np.all(region[theta + phi < -1e-9] == SLIP)
    assert np.all(np.isnan(k[region == SLIP]))


def test_self_lock_threshold_is_slope_one_over_mu():
    mu = 1.25
    k, region = kappa([1 / mu - 1e-6, 1 / mu + 1e-6], 0.0, mu)
    assert region.tolist() == [ENGAGED, SELF_LOCK]
    assert k[0] > 1e5


def test_boundary_a_zero_is_finite_and_classified():
    mu = 0.8
    fy = np.array([0.0, 0.3, 1.0])
    fx_edge = np.sqrt(1 + fy**2) / mu  # A' = 0 exactly
    k, region = kappa(fx_edge, fy, mu)
    assert np.all(region == SELF_LOCK)
    k, region = kappa(-fx_edge, fy, mu)  # descending side: linear equation, no blow-up
    assert not np.any(np.isinf(k))


def test_flat_ground_gives_mu():
    for mu in (0.1, 0.5, 1.0, 3.0):
        k, region = kappa(0.0, 0.0, mu)
        assert region == ENGAGED
        assert k == pytest.approx(mu, rel=1e-12)


@settings(max_examples=300, deadline=None)
@given(st.floats(-4, 4), st.floats(-4, 4))
def test_y_mirror_symmetry(fx, fy):
    k1, r1 = kappa(fx, fy, 0.7)
    k2, r2 = kappa(fx, -fy, 0.7)
    assert r1 == r2
    np.testing.assert_allclose(k1, k2, rtol=1e-12, equal_nan=True)


@settings(max_examples=400, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(0.05, 2.5))
def test_brute_force_friction_cone(fx, fy, mu):
    k, region = kappa(fx, fy, mu)
    k = float(k)
    if region == SELF_LOCK:
        for big in (1e3, 1e6):
            assert _holds(fx, fy, mu, big)
    elif region == ENGAGED:
        assert k > 0
        eps = 1e-6 * max(1.0, k)
        assert _holds(fx, fy, mu, k - min(eps, 0.5 * k), margin=1e-9)
        # nothing above kappa holds: the hold really breaks there
        for above in k + eps + np.geomspace(1e-6, 1e6, 60):
            assert not _holds(fx, fy, mu, above, margin=-1e-9)
    else:
        for trial in np.concatenate([[0.0], np.geomspace(1e-6, 1e6, 200)]):
            assert not _holds(fx, fy, mu, trial, margin=-1e-9)


@settings(max_examples=200, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(0.05, 2.5))
def test_slip_direction_is_tangent_and_critical(fx, fy, mu):
    k, region = kappa(fx, fy, mu)
    v = np.array(slip_direction(fx, fy, k, region), dtype=float)
    if region == SELF_LOCK:
        assert np.all(np.isnan(v))
        return
    n = np.array([fx, fy, -1.0]) / math.sqrt(1 + fx * fx + fy * fy)
    assert np.linalg.norm(v) == pytest.approx(1.0, abs=1e-9)
    assert abs(v @ n) < 1e-9
    if region == SLIP:
        assert v[2] <= 1e-12  # gravity alone slides the tip downhill


def test_vectorized_equals_pointwise():
    rng = np.random.default_rng(0)
    fx, fy = rng.normal(0, 1.5, (2, 50))
    k, region = kappa(fx, fy, 0.9)
    for i in range(50):
        ki, ri = kappa(fx[i], fy[i], 0.9)
        assert ri == region[i]
        # same numpy code on the same inputs, only +-*/ and sqrt (correctly rounded in
        # scalar and SIMD loops alike), so bitwise equality holds on any CPU
        np.testing.assert_equal(ki, k[i])


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf"), "x"])
def test_bad_mu_names_the_argument(bad):
    with pytest.raises(SpineInputError, match="mu"):
        kappa(0.1, 0.1, bad)


@pytest.mark.parametrize("slope_deg", [-30.0, 0.0, 20.0, 40.0, 60.0, 80.0])
def test_kappa_of_normal_is_kappa_of_the_slope_it_stands_for(slope_deg):
    """The shared lock rule: a contact normal gives the verdict of the slope it belongs to."""
    mu = 0.5
    t = math.tan(math.radians(slope_deg))
    normal = np.array([-t, 0.0, 1.0]) / math.hypot(t, 1.0)  # outward, surface rising in +x
    k_n, r_n = kappa_of_normal(normal, mu)
    k_s, r_s = kappa(t, 0.0, mu)
    assert int(r_n) == int(r_s)
    if np.isfinite(k_s):
        # the slope recovered from the normal differs by rounding only
        assert float(k_n) == pytest.approx(float(k_s), rel=1e-12)
    # 2-D closed form: self-lock exactly when theta + arctan(mu) >= 90 deg
    assert (int(r_n) == SELF_LOCK) == (slope_deg + math.degrees(math.atan(mu)) >= 90)


def test_kappa_of_normal_handles_walls_and_batches():
    mu = 0.3
    normals = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    k, region = kappa_of_normal(normals, mu)
    assert region.tolist() == [SELF_LOCK, SLIP, ENGAGED]
    assert k[0] == np.inf and np.isnan(k[1]) and k[2] == pytest.approx(mu)
    with pytest.raises(SpineInputError, match=r"shape \(\.\.\., 3\)"):
        kappa_of_normal([1.0, 0.0], mu)


def test_crease_engagement_of_a_v_groove_is_the_wedge():
    """A V-groove along the drive with flanks of angle theta: the wedge's kappa = mu / cos(theta),
    sliding along +x; symmetric in the order of the sides."""
    from spine_mj.theory.engagement import crease_engagement

    t = 2.0  # tan(theta)
    for a, b in (((0.0, t), (0.0, -t)), ((0.0, -t), (0.0, t))):
        k, region, vx, vy = crease_engagement(*a, *b, 0.5)
        assert region == ENGAGED
        assert float(k) == pytest.approx(0.5 * math.sqrt(1 + t * t))
        assert (float(vx), float(vy)) == pytest.approx((1.0, 0.0))
    # parallel contacts are no crease
    assert crease_engagement(0.3, 0.1, 0.3, 0.1, 0.5)[1] == -1


@pytest.mark.parametrize("floor_fy", [0.0, 1e-4, -1e-4])
def test_crease_engagement_of_a_floor_beside_a_wall(floor_fy):
    """A flat floor meeting a steep wall the drive pushes into: gravity alone leaves the wall
    unloaded, the drive presses it. Force balance on the floor (load W) and the wall (normal
    n_b, horizontal part h_b) gives ``kappa = mu / (c_x - mu |c_y| (1 - n_bz) / h_b)`` along
    the foot ``c``; a floor tilted by 1e-4 either way changes it by about that much (it was
    rejected as no two-contact state when the tilt left the wall's load at zero drive < 0)."""
    from spine_mj.theory.engagement import crease_engagement

    mu, wall = 0.5, (5.0, -4.0)
    s = math.sqrt(1.0 + wall[0] ** 2 + wall[1] ** 2)
    nbx, nby, nbz = -wall[0] / s, -wall[1] / s, 1.0 / s
    hb = math.hypot(nbx, nby)
    cx, cy = abs(nby) / hb, nbx / hb  # the foot, horizontal, turned to the drive
    expected = mu / (cx - mu * abs(cy) * (1.0 - nbz) / hb)
    for a, b in (((0.0, floor_fy), wall), (wall, (0.0, floor_fy))):
        k, region, vx, vy = crease_engagement(*a, *b, mu)
        assert region == ENGAGED
        assert float(k) == pytest.approx(expected, rel=1e-3)
        assert (float(vx), abs(float(vy))) == pytest.approx((cx, abs(cy)), abs=1e-3)


@pytest.mark.parametrize("mu", [2.0, 1e4, 1e8, 1e15, 1e100, 1e300, 1.7e308])
def test_two_d_closed_form_at_any_finite_mu(mu):
    """tan(theta + arctan mu) written as (f_x + mu) / (1 - mu f_x), exact for large mu."""
    fx = np.array([-50.0, -3.0, -0.9, -0.5, -1e-3, 0.0])
    k, region = kappa(fx, 0.0, mu)
    descends_past_phi = fx < -mu  # theta + phi < 0
    assert np.all(region[descends_past_phi] == SLIP)
    fx, k, region = fx[~descends_past_phi], k[~descends_past_phi], region[~descends_past_phi]
    assert np.all(region == ENGAGED)
    expected = (fx / mu + 1.0) / (1.0 / mu - fx)  # the closed form divided through by mu
    np.testing.assert_allclose(k, expected, rtol=1e-12)
    # no point can slip once mu exceeds the steepest slope; uphill past 1/mu self-locks
    up = np.array([0.9, 1.0, 10.0]) * max(1.0 / mu, 1e-300) * 2.0
    _, region_up = kappa(up, 0.0, mu)
    assert np.all(region_up == SELF_LOCK)


@pytest.mark.parametrize("mu", [1e8, 1e15, 1e100, 1e308])
def test_no_slip_on_the_single_peak_once_mu_exceeds_its_steepest_slope(mu):
    from spine_mj.presets import make_surface

    surf = make_surface("paper-single-peak")
    x, y = np.meshgrid(np.linspace(-5, 5, 201), np.linspace(-5, 5, 201))
    fx, fy = surf.gradient(x, y)
    assert max(np.abs(fx).max(), np.abs(fy).max()) < 1.0 < mu
    k, region = kappa(fx, fy, mu)
    assert not np.any(region == SLIP)
    assert np.all(np.isfinite(k[region == ENGAGED]))
    assert np.all(k[region == ENGAGED] > 0)


@settings(max_examples=300, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(2.5, 1e6))
def test_brute_force_friction_cone_at_large_mu(fx, fy, mu):
    k, region = kappa(fx, fy, mu)
    k = float(k)
    if region == ENGAGED:
        eps = 1e-6 * max(1.0, k)
        assert _holds(fx, fy, mu, k - min(eps, 0.5 * k), margin=1e-9)
        assert not _holds(fx, fy, mu, k + eps + 1e-3 * k, margin=-1e-9)
    elif region == SELF_LOCK:
        assert _holds(fx, fy, mu, 1e9)
