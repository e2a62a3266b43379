"""The multi-contact lock against the V-groove's closed form and MuJoCo's static probe."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.theory.engagement import ENGAGED, SELF_LOCK, SLIP, kappa
from spine_mj.theory.multicontact import (
    CONE_SIDES,
    hold_kappa,
    normals_of_slopes,
    two_contact_kappa,
    wedge_kappa,
    wedge_normals,
)

WEDGES = [
    (0.0, 0.5, 0.5),
    (0.2, 0.5, 0.5),
    (0.3, 0.8, 0.7),
    (-0.2, 0.4, 0.5),
    (0.0, 1.2, 0.5),
    (0.4, 0.3, 1.0),
]


def _slopes(normals):
    return -normals[:, 0] / normals[:, 2], -normals[:, 1] / normals[:, 2]


@pytest.mark.parametrize(("theta", "alpha", "mu"), WEDGES)
def test_two_contacts_in_a_v_groove_hold_like_one_of_friction_mu_over_cos_alpha(theta, alpha, mu):
    fx, fy = _slopes(wedge_normals(theta, alpha))
    k, region = two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)
    assert int(region) == ENGAGED
    assert float(k) == pytest.approx(math.tan(theta + math.atan(mu / math.cos(alpha))), rel=1e-9)
    assert float(k) == pytest.approx(float(wedge_kappa(theta, alpha, mu)), rel=1e-12)
    # a single-contact rule on the groove's floor gives mu, not mu / cos(alpha): less
    assert float(k) > math.tan(theta + math.atan(mu)) * (1 + 1e-6)
    # the pair is symmetric in its contacts
    k2, _ = two_contact_kappa(fx[1], fy[1], fx[0], fy[0], mu)
    assert float(k2) == pytest.approx(float(k), rel=1e-12)


def test_a_v_groove_self_locks_once_theta_plus_the_wedge_friction_angle_reaches_90_degrees():
    """Where gravity alone does not slide the tip back down the groove (theta below the wedge's
    friction angle, so that angle above 45 deg); steeper, the preload slides it (slip)."""
    mu, alpha = 0.8, 0.8
    phi = math.atan(mu / math.cos(alpha))
    assert phi > math.pi / 4
    for theta, locked in ((math.pi / 2 - phi - 0.02, False), (math.pi / 2 - phi + 0.02, True)):
        fx, fy = _slopes(wedge_normals(theta, alpha))
        k, region = two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)
        assert (int(region) == SELF_LOCK) is locked
        assert math.isinf(float(k)) is locked
        assert math.isinf(float(wedge_kappa(theta, alpha, mu))) is locked
    # down a groove steeper than the wedge's friction angle the preload alone slides it
    fx, fy = _slopes(wedge_normals(-phi - 0.05, alpha))
    k, region = two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)
    assert int(region) == SLIP and math.isnan(float(k))


@pytest.mark.parametrize(("alpha", "mu"), [(0.5, 0.3), (0.8, 0.5), (0.3, 0.2)])
def test_a_groove_rising_steeper_than_its_friction_is_held_by_the_drive(alpha, mu):
    """Up a V-groove whose rise theta exceeds the wedge's friction angle phi, gravity alone
    slides the tip back down; a drive already pushing it holds it from tan(theta - phi) and
    moves it on at the wedge's tan(theta + phi) (self-lock from theta + phi = 90 deg), as one
    contact of friction mu / cos(alpha) would; down a steep groove the preload slides it
    whatever the drive."""
    phi = math.atan(mu / math.cos(alpha))
    for theta in np.linspace(phi + 0.02, math.pi / 2 - phi - 0.02, 5):
        fx, fy = _slopes(wedge_normals(theta, alpha))
        k, region = two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)
        assert int(region) == ENGAGED
        assert float(k) == pytest.approx(math.tan(theta + phi), rel=1e-9)
        assert float(k) == pytest.approx(float(wedge_kappa(theta, alpha, mu)), rel=1e-12)
    fx, fy = _slopes(wedge_normals(math.pi / 2 - phi + 0.02, alpha))
    assert int(two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)[1]) == SELF_LOCK
    fx, fy = _slopes(wedge_normals(-phi - 0.05, alpha))
    assert int(two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)[1]) == SLIP


def test_one_contact_feasibility_is_the_single_contact_kappa():
    rng = np.random.default_rng(3)
    fx, fy = rng.uniform(-0.6, 1.2, 20), rng.uniform(-0.8, 0.8, 20)
    k, reg = kappa(fx, fy, 0.5)
    for i in np.flatnonzero(reg == ENGAGED):
        got = hold_kappa(normals_of_slopes(fx[i], fy[i]), 0.5)
        # the inscribed pyramid's friction lies between mu cos(pi / sides) and mu
        lo = float(kappa(fx[i], fy[i], 0.5 * math.cos(math.pi / CONE_SIDES))[0])
        assert lo * (1 - 1e-6) <= got <= k[i] * (1 + 1e-6)
    assert hold_kappa(normals_of_slopes(2.5, 0.0), 0.5) == math.inf  # past 90 deg - arctan mu
    assert math.isnan(hold_kappa(normals_of_slopes(-1.0, 0.0), 0.5))  # downhill, steeper than mu


@pytest.mark.parametrize(("theta", "alpha", "mu"), WEDGES)
def test_bare_cone_feasibility_bounds_the_wedge_from_above(theta, alpha, mu):
    """Feasibility alone lets a squeeze between the flanks raise the friction: an upper bound."""
    assert hold_kappa(wedge_normals(theta, alpha), mu) >= float(wedge_kappa(theta, alpha, mu)) * (1 - 2e-3)


def test_bad_input_is_refused():
    with pytest.raises(SpineInputError, match="normals must have shape"):
        hold_kappa(np.zeros((2, 2)), 0.5)
    with pytest.raises(SpineInputError, match="finite and non-zero"):
        hold_kappa(np.zeros((1, 3)), 0.5)
    with pytest.raises(SpineInputError, match="mu must be"):
        hold_kappa(wedge_normals(0.0, 0.5), -1.0)
    with pytest.raises(SpineInputError, match="sides must be"):
        hold_kappa(wedge_normals(0.0, 0.5), 0.5, sides=2)


def _groove(theta, alpha, half=0.02, n=41):
    from spine_mj.surfaces import GridSurface

    x = np.linspace(-half, half, n)
    h = math.tan(theta) * x[None, :] + math.tan(alpha) / math.cos(theta) * np.abs(x[:, None])
    return GridSurface(heights=h, x=x, y=x.copy(), unit="m")


@pytest.mark.parametrize(("theta", "alpha", "mu"), [(0.3, 0.8, 0.7), (0.0, 0.6, 0.5)])
def test_mujoco_static_probe_in_a_v_groove_breaks_away_at_the_wedge_kappa(theta, alpha, mu):
    from spine_mj.sim import Rig, StaticProbe, TipParams

    rig = Rig(_groove(theta, alpha), tip=TipParams(tip_radius_m=5e-4, mu_s=mu))
    res = rig.run(StaticProbe(), start=(3.1e-4, 0.0))
    fx, fy = _slopes(wedge_normals(theta, alpha))
    expected = float(two_contact_kappa(fx[0], fy[0], fx[1], fy[1], mu)[0])
    assert res.kappa_mj == pytest.approx(expected, rel=0.02)
    assert res.kappa_mj > math.tan(theta + math.atan(mu)) * 1.05  # not the single-contact rule


def _asymmetric_groove(radius=None):
    """A V-groove along the drive rising at slope 0.7336, its flanks' side slopes -0.296 and
    +0.199 (a crease MuJoCo held at the force cap on a fractal, measured), as facets."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface

    x = np.linspace(-1.0, 1.0, 41)
    h = 0.7336 * x[None, :] + np.maximum(-0.2964 * x[:, None], 0.199 * x[:, None])
    facets = TriangulatedSurface(heights=h, x=x, y=x.copy(), unit="1")
    return facets if radius is None else BallOnFacets(facets, radius)


@pytest.mark.parametrize("radius", [None, 0.05])
def test_a_streamline_crossing_a_wedging_crease_is_held_there(radius):
    """Each flank alone moves at kappa 15.5 and 19.2, below the cap of 20; the two together
    hold to 30.6: a path on single contacts zig-zags across the crease and goes on."""
    from spine_mj.theory import streamline as sl
    from spine_mj.theory.streamline_types import Outcome, StreamlineParams

    surface = _asymmetric_groove(radius)
    ks = kappa(np.array([0.7336, 0.7336]), np.array([-0.2964, 0.199]), 1.25)[0]
    assert np.all(ks < 20.0)
    pair = float(two_contact_kappa(0.7336, -0.2964, 0.7336, 0.199, 1.25)[0])
    assert pair > 20.0
    params = StreamlineParams(mu=1.25, dl=0.01, kappa_cap=20.0)
    res = sl.streamlines(surface, [(-0.8, -0.2), (-0.8, 0.12)], params)
    assert [Outcome(o) for o in res.outcome] == [Outcome.FORCE_CAP] * 2
    # held at the crease (within a step of the tip's contact line), far from the edge
    assert np.all(np.abs(res.end_y) < 0.05)
    assert np.all(res.end_x < 0.5)
    assert np.allclose(res.max_kappa, pair, rtol=1e-6)
    # a cap above the pair's hold lets the path go on, up the crease to the domain's edge
    free = sl.streamlines(surface, [(-0.8, -0.2)], dataclasses.replace(params, kappa_cap=40.0))
    assert Outcome(free.outcome[0]) is Outcome.LEFT_DOMAIN


def test_a_streamline_up_a_crease_steeper_than_friction_climbs_it():
    """Two facets of the scan di-1 (slopes (0.455, 0.504) and (0.668, -0.459), mu 0.5) meet in
    a crease rising along the drive more steeply than the pair's friction holds: gravity alone
    would slide the tip back down it. A ball driven into it slid back down, climbed a flank
    again and came back: 6 of 9 paths stalled, 3 slid out at -x (on the scan a third of the
    quick plan's paths stalled so). The drive holds it in the crease (from kappa_lo) and moves
    it up at the pair's kappa, as on one steep wall: every path climbs and leaves at +x."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface
    from spine_mj.theory import streamline as sl
    from spine_mj.theory.engagement import crease_engagement
    from spine_mj.theory.streamline_types import Outcome, StreamlineParams

    a, b, mu = (0.455, 0.504), (0.668, -0.459), 0.5
    k, region, vx, _ = crease_engagement(*a, *b, mu)
    assert int(region) == ENGAGED and 0 < float(k) < 20.0 and float(vx) > 0
    x = np.linspace(-1.0, 1.0, 81)
    h = np.maximum(a[0] * x[None, :] + a[1] * x[:, None], b[0] * x[None, :] + b[1] * x[:, None])
    surface = BallOnFacets(TriangulatedSurface(heights=h, x=x, y=x.copy(), unit="1"), 0.05)
    starts = np.column_stack([np.full(9, -0.6), np.linspace(-0.5, 0.3, 9)])
    res = sl.streamlines(surface, starts, StreamlineParams(mu=mu, dl=0.01, kappa_cap=20.0))
    assert [Outcome(o) for o in res.outcome] == [Outcome.LEFT_DOMAIN] * 9
    assert np.all(res.end_x > 0.9)


def test_a_nearly_flat_crease_down_a_slope_steeper_than_friction_does_not_hold_the_tip():
    """Two facets of the scan di-1 at hfield x 2 (slopes (-0.0047, -0.626) and (0.0256,
    -0.626), mu 0.5): a crease across the drive, kinked by 0.03 rad, running down a slope
    steeper than friction. The drive holds a tip in a crease only while both sides stay
    pressed; here the pair's hold would need kappa_lo = 24, where the first side's normal
    force is -934 W: the drive has lifted the tip off it long before. Gravity slides the tip
    down the crease (+y), as on either facet alone; the rule that called it a self-lock held
    7 of 15 reference paths on di-1's refined facets where MuJoCo passed."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface
    from spine_mj.theory import streamline as sl
    from spine_mj.theory.engagement import crease_engagement
    from spine_mj.theory.streamline_types import Outcome, StreamlineParams

    a, b, mu = (-0.0047, -0.6257), (0.0256, -0.6257), 0.5
    k, region, _vx, vy = crease_engagement(*a, *b, mu)
    assert int(region) == SLIP and np.isnan(k) and float(vy) > 0.99
    k2, region2 = two_contact_kappa(*a, *b, mu)
    assert int(region2) == SLIP and np.isnan(k2)
    x = np.linspace(-1.0, 1.0, 81)
    h = np.maximum(a[0] * x[None, :] + a[1] * x[:, None], b[0] * x[None, :] + b[1] * x[:, None])
    surface = BallOnFacets(TriangulatedSurface(heights=h, x=x, y=x.copy(), unit="1"), 0.05)
    starts = np.column_stack([np.full(5, -0.3), np.linspace(-0.6, -0.2, 5)])
    res = sl.streamlines(surface, starts, StreamlineParams(mu=mu, dl=0.01, kappa_cap=20.0))
    assert Outcome.SELF_LOCKED not in [Outcome(o) for o in res.outcome]


def test_mujoco_static_probe_at_a_fractal_crease_breaks_away_near_the_two_contact_kappa():
    """A crease of the quick plan's fractal (seed 2, H 0.7, hfield 151) where MuJoCo's
    spring run held at the force cap while the single-contact reference moved on: each side
    alone moves at kappa 15.5 and 19.2, the pair holds to 30.6; MuJoCo's probe breaks away
    at 29.0 (measured): the wedge, within MuJoCo's soft contacts."""
    from spine_mj.sim import Detection, StaticProbe
    from spine_mj.sweep.analyses.engine import case_rig
    from spine_mj.sweep.cases import expand_cases
    from spine_mj.sweep.config import parse_config
    from spine_mj.validate.plans import PLANS
    from spine_mj.validate.quasistatic_limit import limit_doc

    plan = PLANS["quick"]
    fam = next(f for f in plan.families if f.name == "fractal")
    case = expand_cases(parse_config(limit_doc(plan, fam, "paper-fractal", "crease")))[1]
    rig = case_rig(case)
    x, y = -5.39600533476336, -2.809769605280573
    a = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    _, fx, fy = rig.contact_surface().evaluate(x + 1e-3 * np.cos(a), y + 1e-3 * np.sin(a), order=1)
    sides = np.unique(np.round(np.column_stack([fx, fy]), 6), axis=0)
    assert len(sides) == 2
    single = kappa(sides[:, 0], sides[:, 1], 1.25)[0]
    pair = float(two_contact_kappa(sides[0, 0], sides[0, 1], sides[1, 0], sides[1, 1], 1.25)[0])
    res = rig.run(
        StaticProbe(start_force_n=5 * rig.scales.preload_n),
        start=(x, y),
        detection=Detection(kappa_cap=100.0),
    )
    assert res.kappa_mj == pytest.approx(pair, rel=0.1)
    assert res.kappa_mj > 1.3 * single.max()


def _close(got, want, name):
    """A compiled rule's numbers against the numpy rule's: regions equal, values within
    rounding (two code paths; a CPU's fused or vectorized arithmetic may round differently)."""
    if np.asarray(want).dtype.kind in "iub":
        np.testing.assert_array_equal(got, want, err_msg=name)
    else:
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15, err_msg=name)


def _slope_pairs(n: int = 4000):
    """Random contact pairs over every regime (flat to steep, opposed and alike), with the
    degenerate ones: equal slopes (no crease), mirrored walls, a flat floor."""
    rng = np.random.default_rng(7)
    fa = rng.normal(scale=rng.choice([0.1, 1.0, 5.0], size=(n, 1)), size=(n, 2))
    fb = rng.normal(scale=rng.choice([0.1, 1.0, 5.0], size=(n, 1)), size=(n, 2))
    fb[:50] = fa[:50]
    fb[50:100] = -fa[50:100]
    fa[100:150] = 0.0
    return fa[:, 0].copy(), fa[:, 1].copy(), fb[:, 0].copy(), fb[:, 1].copy()


@pytest.mark.parametrize("mu", [0.3, 0.8, 2.5])
def test_the_compiled_crease_rule_gives_the_numpy_rules_numbers(mu):
    from spine_mj.theory._multicontact_kernel import crease
    from spine_mj.theory.engagement import DEFAULT_TOL, crease_engagement

    args = _slope_pairs()
    got, want = crease(*args, mu, DEFAULT_TOL), crease_engagement(*args, mu)
    for g, w, name in zip(got, want, ("kappa", "region", "vx", "vy"), strict=True):
        _close(g, w, name)


@pytest.mark.parametrize("mu", [0.3, 0.8, 2.5])
def test_the_compiled_two_contact_rule_gives_the_numpy_rules_numbers(mu):
    from spine_mj.theory._multicontact_kernel import two_contact
    from spine_mj.theory._streamline_numpy import _two_contact_kappa
    from spine_mj.theory.engagement import DEFAULT_TOL

    args = _slope_pairs(1500)
    k, region, bound = two_contact(*args, mu, DEFAULT_TOL)
    want_k, want_region = two_contact_kappa(*args, mu)
    # where a motion counts the kernel decides alone; elsewhere the caller's linear program
    assert bound.any() and (~bound).sum() > 1000
    _close(k[~bound], want_k[~bound], "kappa")
    _close(region[~bound], want_region[~bound], "region")
    got_k, got_region = _two_contact_kappa(*args, mu)
    _close(got_k, want_k, "kappa")
    _close(got_region, want_region, "region")


@pytest.mark.parametrize("mu", [0.3, 0.8, 2.5])
def test_the_compiled_single_contact_rule_gives_kappa_and_the_slip_direction(mu):
    from spine_mj.theory._multicontact_kernel import single_contact
    from spine_mj.theory.engagement import DEFAULT_TOL, slip_direction

    fx, fy, _, _ = _slope_pairs()
    k, region, vx, vy = single_contact(fx, fy, mu, DEFAULT_TOL)
    want_k, want_region = kappa(fx, fy, mu)
    want_vx, want_vy, _ = slip_direction(
        fx, fy, want_k, np.where(want_region == SELF_LOCK, SLIP, want_region)
    )
    assert set(np.unique(region)) == {SLIP, ENGAGED, SELF_LOCK}
    for got, want, name in (
        (k, want_k, "kappa"),
        (region, want_region, "region"),
        (vx, want_vx, "vx"),
        (vy, want_vy, "vy"),
    ):
        _close(got, want, name)
