"""The compliant-drive streamline against closed forms (docs/physics.md §6)."""

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
import pytest
from scipy.optimize import brentq

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import (
    BallOnFacets,
    Surface,
    TriangulatedSurface,
    corrugation,
    single_gaussian,
)
from spine_mj.theory.agreement import path_frechet
from spine_mj.theory.compliant import compliant_streamlines, hold_force
from spine_mj.theory.compliant_types import MotionState
from spine_mj.theory.engagement import kappa
from spine_mj.theory.streamline import streamlines
from spine_mj.theory.streamline_types import Outcome, StreamlineParams

L_S = 0.190  # slope correlation length of a corrugation, in wavelengths


@dataclass(frozen=True, eq=False)
class Sine(Surface):
    """z = s / (2 pi) sin(2 pi x), uniform in y, exactly (the corrugation of wavelength 1)."""

    s: float
    bounds: tuple = (0.0, 6.0, -0.5, 0.5)
    unit: str = "1"
    metadata: dict = field(default_factory=dict)

    def _evaluate(self, x, y, order):
        u = 2 * np.pi * x
        out = (self.s / (2 * np.pi) * np.sin(u), self.s * np.cos(u), np.zeros_like(x))
        return out[:1] if order == 0 else out


@dataclass(frozen=True, eq=False)
class Plane(Surface):
    """z = slope x, exactly."""

    slope: float
    bounds: tuple = (-2.0, 2.0, -2.0, 2.0)
    unit: str = "1"
    metadata: dict = field(default_factory=dict)

    def _evaluate(self, x, y, order):
        out = (self.slope * x, np.full_like(x, self.slope), np.zeros_like(x))
        return out[:1] if order == 0 else out


def _distance(a, b, i, length=1.0):
    """Frechet distance between path ``i`` of two results, over ``length``."""
    pa, pb = a.path(i), b.path(i)
    return path_frechet(np.c_[pa["x"], pa["y"]], np.c_[pb["x"], pb["y"]], length_scale=length)


def _pt(s, mu):
    """Prandtl-Tomlinson closed form on z = h sin(2 pi x): kappa(x), -dkappa/dx and K*."""

    def kap(x):
        t = s * np.cos(2 * np.pi * x)
        return (t + mu) / (1 - mu * t)

    def fall(x):
        t = s * np.cos(2 * np.pi * x)
        return (1 + mu * mu) * s * 2 * np.pi * np.sin(2 * np.pi * x) / (1 - mu * t) ** 2

    x = np.linspace(0, 1, 200_001)
    return kap, fall, L_S * fall(x).max()


def _fold_closed_form(s, mu, c):
    """First fold after x = 0 where -dkappa/dx = c on the falling flank, its onset force,
    carriage position and where the tip lands (c (X - x) = kappa(x) further on)."""
    kap, fall, _ = _pt(s, mu)
    x = np.linspace(0, 0.5, 100_001)
    steep = x[np.argmax(fall(x))]
    xf = brentq(lambda u: fall(u) - c, 1e-9, steep)
    X = xf + kap(xf) / c
    xl = brentq(lambda u: c * (X - u) - kap(u), steep + 1e-9, 1.5)
    return xf, kap(xf), X, xl


def test_hold_force_is_kappa_where_engaged_and_holds_in_slip_region():
    fx = np.array([0.0, 0.3, -0.3, -0.7, -0.9, 3.0])
    hold, _ = hold_force(fx, 0.0, 0.5)
    k, _ = kappa(fx, 0.0, 0.5)
    engaged = np.isfinite(k) & (k < np.inf)
    np.testing.assert_allclose(hold[engaged], k[engaged])
    assert hold[-1] == np.inf  # slope 3 > 1/mu: self-locked
    # a slope steeper than the friction angle downhill: a backward pull of
    # tan(theta + phi) < 0 holds it
    for i in (3, 4):
        assert hold[i] == pytest.approx(math.tan(math.atan(fx[i]) + math.atan(0.5)), rel=1e-12)


@pytest.mark.parametrize("s, mu", [(0.3, 0.5), (0.5, 0.3)])
def test_corrugation_smooth_iff_stiffer_than_prandtl_tomlinson_k_star(s, mu):
    surf = Sine(s)
    p = StreamlineParams(mu=mu, dl=0.02)
    _, _, k_star = _pt(s, mu)
    if (s, mu) == (0.3, 0.5):
        assert k_star == pytest.approx(0.47, abs=0.005)
    starts = [(0.02, 0.0), (0.6, 0.1)]
    rigid = streamlines(surf, starts, p)
    for ratio in (1.05, 2.0):
        r = compliant_streamlines(surf, starts, p, stiffness=ratio * k_star / L_S)
        # no jump (the start's own, from a relaxed spring on a flank steeper than phi, aside)
        assert not np.any(r.folds.x > r.start_x[r.folds.start] + 1e-9)
        for i in range(2):  # no jump: the rigid streamline's path (its last step may differ)
            assert _distance(r, rigid, i) < p.dl
            assert abs(r.end_x[i] - rigid.end_x[i]) < p.dl
    for ratio in (0.25, 0.5, 0.95):
        c = ratio * k_star / L_S
        r = compliant_streamlines(surf, starts, p, stiffness=c)
        xf, onset, X, xl = _fold_closed_form(s, mu, c)
        for i, x0 in enumerate((0.02, 0.6)):
            folds = r.folds_of(i)
            inner = (folds.x > x0 + 1e-9) & np.isfinite(folds.land_x)  # not the start's own jump
            frac = np.mod(folds.x[inner], 1.0)
            assert np.all(np.diff(np.floor(folds.x[inner])) == 1)  # one jump per wavelength
            assert inner.sum() >= 4
            np.testing.assert_allclose(frac, xf, atol=1e-6)
            np.testing.assert_allclose(folds.onset_force[inner], onset, rtol=1e-6)
            np.testing.assert_allclose(np.mod(folds.carriage[inner], 1.0), X % 1.0, atol=1e-6)
            np.testing.assert_allclose(folds.jump_length[inner], xl - xf, rtol=1e-6)
            assert np.all(folds.force_drop[inner] > 0)


def test_folds_do_not_depend_on_the_step():
    surf = corrugation(slope_amplitude=0.3, n_waves=3)
    out = []
    for dl in (0.04, 0.013, 0.005):
        r = compliant_streamlines(surf, [(0.3, 0.0)], StreamlineParams(mu=0.5, dl=dl), stiffness=0.3 / L_S)
        f = r.folds
        out.append(np.c_[f.x, f.onset_force, f.carriage, f.jump_length][:3])
    for o in out[1:]:
        np.testing.assert_allclose(o, out[0], atol=1e-6)


@pytest.mark.parametrize("slope", [0.0, 0.4])
def test_inclined_plane_force_is_tan_theta_plus_phi_once_stretched(slope):
    plane = Plane(slope)
    c = 3.0
    r = compliant_streamlines(plane, [(-1.5, 0.0)], StreamlineParams(mu=0.5, dl=0.05), stiffness=c)
    q = r.path(0)
    expect = math.tan(math.atan(slope) + math.atan(0.5))
    assert q["state"][0] == MotionState.STICK
    assert np.all(q["state"][1:] == MotionState.SLIDE)
    np.testing.assert_allclose(q["force"], expect, rtol=1e-12)
    np.testing.assert_allclose(q["carriage"] - q["x"], expect / c, rtol=1e-12)
    assert r.outcome[0] == Outcome.LEFT_DOMAIN


def test_reduces_to_the_rigid_streamline_as_stiffness_grows():
    surf = single_gaussian(sign=-1)
    starts = [(-3.0, y) for y in (-4.0, -3.0, -2.0, -1.0)]
    p = StreamlineParams(mu=1.25, dl=0.02)
    rigid = streamlines(surf, starts, p)
    dist = []
    for c in (0.1, 1.0, 10.0, 100.0):
        r = compliant_streamlines(surf, starts, p, stiffness=c)
        np.testing.assert_array_equal(r.self_locked[1:], rigid.self_locked[1:]) if c >= 10 else None
        dist.append(max(_distance(r, rigid, i, 1.5) for i in range(len(starts))))
    assert dist[0] > 0.05  # a soft spring jumps off the rigid path
    assert dist[-1] < 1e-3
    assert all(b <= a + 1e-9 for a, b in itertools.pairwise(dist))


def test_ball_on_facets_like_the_rigid_reference():
    grid = corrugation(slope_amplitude=0.3, n_waves=4, points_per_wave=24)
    contact = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.04)
    p = StreamlineParams(mu=0.5, dl=0.005)
    starts = [(0.3, 0.0), (0.5, 0.2)]
    rigid = streamlines(contact, starts, p)
    stiff = compliant_streamlines(contact, starts, p, stiffness=20.0 / L_S)
    for i in range(2):
        assert _distance(stiff, rigid, i) < 1e-3
    soft = compliant_streamlines(contact, starts, p, stiffness=0.1 / L_S)
    for i in range(2):
        f = soft.folds_of(i)
        landed = np.isfinite(f.land_x)
        assert np.all(np.diff(np.floor(f.x[landed & (f.x > starts[i][0] + 1e-9)])) == 1)


def test_compiled_fold_and_landing_searches_equal_the_numpy_ones():
    from spine_mj.theory import _compliant_kernel as kernel
    from spine_mj.theory.compliant import _BISECTIONS, _GOLDEN_ITERATIONS, _fold_along, _landing_along

    grid = corrugation(slope_amplitude=0.4, n_waves=3, points_per_wave=16)
    contact = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.05)
    rng = np.random.default_rng(7)
    n = 64
    px, py = rng.uniform(0.2, 2.6, n), rng.uniform(-0.2, 0.2, n)
    ang = rng.uniform(-0.6, 0.6, n)
    vx, vy, h = np.cos(ang), np.sin(ang), rng.uniform(0.01, 0.2, n)
    c, mu, tol = 3.0, 0.6, 1e-12
    s_ref, x_ref = _fold_along(contact, px, py, vx, vy, h, c, mu, tol)
    s_fast, x_fast = kernel.fold_on_facets(
        px, py, vx, vy, h, c, mu, tol, _GOLDEN_ITERATIONS, *contact.kernel_args()
    )
    np.testing.assert_allclose(s_fast, s_ref, rtol=0, atol=1e-12 * h.max())
    np.testing.assert_allclose(x_fast, x_ref, rtol=1e-12)
    carriage = px + rng.uniform(0.0, 0.5, n)
    l_ref = _landing_along(contact, px, py, vx, vy, h, carriage, c, mu, tol)
    l_fast = kernel.landing_on_facets(
        px, py, vx, vy, h, carriage, c, mu, tol, _BISECTIONS, *contact.kernel_args()
    )
    np.testing.assert_allclose(l_fast, l_ref, rtol=0, atol=1e-12 * h.max())


def test_soft_spring_on_facets_compiled_and_numpy_alike():
    """The whole soft-spring path (many folds and landings) with the compiled kernels and with
    the numpy contact and searches: the same jumps, paths within round-off."""
    grid = corrugation(slope_amplitude=0.3, n_waves=4, points_per_wave=24)
    facets = TriangulatedSurface.from_grid(grid)
    p = StreamlineParams(mu=0.5, dl=0.005)
    starts = [(0.3, 0.0), (0.5, 0.2)]
    fast = compliant_streamlines(BallOnFacets(facets, 0.04), starts, p, stiffness=0.1 / L_S)
    slow = compliant_streamlines(BallOnFacets(facets, 0.04, compiled=False), starts, p, stiffness=0.1 / L_S)
    assert len(fast.folds) == len(slow.folds) >= 6
    np.testing.assert_array_equal(fast.outcome, slow.outcome)
    for i in range(2):
        assert _distance(fast, slow, i) < 1e-9
    np.testing.assert_allclose(fast.folds.onset_force, slow.folds.onset_force, rtol=1e-9)


def test_many_starts_equal_one_at_a_time():
    surf = single_gaussian(sign=1)
    starts = [(-3.0, y) for y in (-3.0, -1.0, -0.5)]
    p = StreamlineParams(mu=1.25, dl=0.03)
    both = compliant_streamlines(surf, starts, p, stiffness=0.5)
    for i, st in enumerate(starts):
        one = compliant_streamlines(surf, [st], p, stiffness=0.5)
        for key in ("x", "y", "carriage", "force", "state"):
            np.testing.assert_allclose(both.path(i)[key], one.path(0)[key], rtol=1e-12, atol=1e-12)
        assert len(one.folds) == len(both.folds_of(i))


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, True, "1"])
def test_stiffness_is_validated(bad):
    with pytest.raises(SpineInputError, match="stiffness"):
        compliant_streamlines(corrugation(), [(0.1, 0.0)], StreamlineParams(mu=0.5), stiffness=bad)


def test_a_carriage_that_stops_leaves_the_tip_short_of_its_hold():
    c, end = 3.0, -0.5
    r = compliant_streamlines(
        Plane(0.4),
        [(-1.5, 0.0), (-1.0, 0.5)],
        StreamlineParams(mu=0.5, dl=0.05),
        stiffness=c,
        carriage_end=[end, 10.0],
    )
    assert r.outcome[0] == Outcome.DRIVE_END and r.outcome[1] == Outcome.LEFT_DOMAIN
    q = r.path(0)
    assert q["carriage"][-1] == end and q["force"][-1] <= math.tan(math.atan(0.4) + math.atan(0.5))
    assert end - q["x"][-1] == pytest.approx(q["force"][-1] / c)
    with pytest.raises(SpineInputError, match="carriage_end"):
        compliant_streamlines(
            Plane(0.4), [(-1.5, 0.0)], StreamlineParams(mu=0.5), stiffness=c, carriage_end=-2.0
        )


def _alike(fast, slow, *, atol, rtol=0.0):
    """The compiled loop's result against the numpy reference's: same outcomes, steps and
    jumps, every column within ``atol`` + ``rtol`` of its value (NaN where the other is NaN)."""
    np.testing.assert_array_equal(fast.outcome, slow.outcome)
    np.testing.assert_array_equal(fast.n_steps, slow.n_steps)
    np.testing.assert_array_equal(fast.state, slow.state)
    np.testing.assert_array_equal(fast.folds.start, slow.folds.start)
    for key in ("x", "y", "z", "kappa", "carriage", "force"):
        np.testing.assert_allclose(getattr(fast, key), getattr(slow, key), rtol=rtol, atol=atol, err_msg=key)
    for key in ("x", "y", "carriage", "onset_force", "land_x", "land_y", "land_force", "jump_length"):
        a, b = getattr(fast.folds, key), getattr(slow.folds, key)
        np.testing.assert_allclose(a, b, rtol=rtol, atol=atol, err_msg=f"folds.{key}")
    np.testing.assert_allclose(fast.max_kappa, slow.max_kappa, rtol=rtol, atol=atol)


@pytest.mark.parametrize(
    "surface, starts, mu, dl, c, end",
    [
        # a Gaussian sum: sticks, slides, a fold and its landing on the far flank
        (single_gaussian(sign=1), [(-3.0, y) for y in (-3.0, -1.0, -0.5, 0.2)], 1.25, 0.03, 0.5, None),
        # a gridded spline, soft: a jump per wave, one carriage that stops short
        (
            corrugation(slope_amplitude=0.4, n_waves=3),
            [(0.1, 0.0), (0.3, 0.1)],
            0.5,
            0.01,
            0.1 / L_S,
            [1.2, np.inf],
        ),
    ],
)
def test_compiled_loop_equals_the_numpy_reference(surface, starts, mu, dl, c, end):
    """The compiled loop (backend numba, start by start) takes the numpy reference's steps:
    same outcomes, steps, states and jumps; positions within 1e-6 of a step and forces
    within 1e-6 of their value. The surfaces are
    evaluated by different code (round-off apart), which can move a fold's golden-section
    bracket: the searches resolve a fold to 0.618**40 ~ 5e-9 of a step, and the path
    after it inherits that shift."""
    p = StreamlineParams(mu=mu, dl=dl)
    fast = compliant_streamlines(surface, starts, p, stiffness=c, carriage_end=end, backend="numba")
    slow = compliant_streamlines(surface, starts, p, stiffness=c, carriage_end=end, backend="numpy")
    assert len(slow.folds) >= 2
    _alike(fast, slow, atol=1e-6 * dl, rtol=1e-6)


def test_compiled_loop_on_facets_is_the_numpy_loop_bit_for_bit():
    """On a ball on facets both loops evaluate the same compiled contact: the same numbers."""
    grid = corrugation(slope_amplitude=0.3, n_waves=4, points_per_wave=24)
    contact = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.04)
    p = StreamlineParams(mu=0.5, dl=0.005, kappa_cap=3.0)
    starts = [(0.3, 0.0), (0.5, 0.2), (2.0, -0.3)]
    fast = compliant_streamlines(contact, starts, p, stiffness=0.1 / L_S, backend="numba")
    slow = compliant_streamlines(contact, starts, p, stiffness=0.1 / L_S, backend="numpy")
    assert len(slow.folds) >= 6
    _alike(fast, slow, atol=0.0)


def test_backend_is_validated():
    with pytest.raises(SpineInputError, match="backend must be"):
        compliant_streamlines(
            corrugation(), [(0.1, 0.0)], StreamlineParams(mu=0.5), stiffness=1.0, backend="gpu"
        )
    with pytest.raises(SpineInputError, match="backend 'numba' supports"):
        compliant_streamlines(
            Plane(0.4), [(0.1, 0.0)], StreamlineParams(mu=0.5), stiffness=1.0, backend="numba"
        )
