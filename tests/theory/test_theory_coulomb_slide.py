"""The sliding-particle reference against a block on an incline and on flat ground."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import inclined_plane
from spine_mj.theory.coulomb_slide import SlideOutcome, SlideParams, slide_until_stuck

MU, W, M = 0.5, 1.0, 0.1  # a_p = W / M = 10 m/s^2
A_P = W / M


def _plane(theta_deg):
    return inclined_plane(slope_deg=theta_deg, half_width=2.0, n=21)  # rises in +x


@pytest.mark.parametrize("theta_deg", [0.0, 10.0, 26.0])
def test_a_block_on_an_incline_no_steeper_than_friction_stays(theta_deg):
    assert math.tan(math.radians(theta_deg)) <= MU
    res = slide_until_stuck(_plane(theta_deg), [(0.3, -0.2)], SlideParams(MU, W, M, 1e-3, 1.0))
    assert res.outcome[0] == SlideOutcome.STUCK
    assert (res.x[0], res.y[0]) == (0.3, -0.2) and res.path_length[0] == 0.0


@pytest.mark.parametrize("theta_deg", [30.0, 60.0])
def test_a_block_on_an_incline_steeper_than_friction_accelerates_at_the_closed_form(theta_deg):
    th = math.radians(theta_deg)
    a = A_P * (math.sin(th) - MU * math.cos(th))
    t_end = 0.2
    res = slide_until_stuck(_plane(theta_deg), [(0.5, 0.0)], SlideParams(MU, W, M, 1e-3, t_end))
    assert res.outcome[0] == SlideOutcome.TIMED_OUT
    assert res.path_length[0] == pytest.approx(0.5 * a * t_end**2, rel=1e-2)
    assert res.max_speed_m_s[0] == pytest.approx(a * t_end, rel=1e-2)
    assert res.y[0] == pytest.approx(0.0, abs=1e-12) and res.x[0] < 0.5  # straight down the slope
    assert res.airborne_steps[0] == 0


@pytest.mark.parametrize("theta_deg", [0.0, 20.0])
def test_a_block_launched_down_an_incline_stops_after_the_closed_form_distance(theta_deg):
    th = math.radians(theta_deg)
    v = 0.8
    decel = A_P * (MU * math.cos(th) - math.sin(th))
    stop = v**2 / (2 * decel)
    errors = []
    for steps in (100, 200):  # steps over the slide's duration v / decel: error ~ 1 / steps
        res = slide_until_stuck(
            _plane(theta_deg),
            [(1.5, 0.0)],
            SlideParams(MU, W, M, v / decel / steps, 5.0),
            velocity_m_s=[(-v * math.cos(th), 0.0)],  # down the slope
        )
        assert res.outcome[0] == SlideOutcome.STUCK
        assert res.time_s[0] == pytest.approx(v / decel, rel=2 / steps)
        errors.append(abs(res.path_length[0] - stop))
        assert res.path_length[0] == pytest.approx(stop, rel=2 / steps)
    assert errors[1] < 0.7 * errors[0] + 1e-9  # first order in the step


def test_a_drive_on_flat_ground_holds_up_to_mu_w_and_then_accelerates_at_the_excess():
    plane = _plane(0.0)
    held = slide_until_stuck(plane, [(0.0, 0.0)], SlideParams(MU, W, M, 1e-3, 1.0, drive_force_n=MU * W))
    assert held.outcome[0] == SlideOutcome.STUCK and held.x[0] == 0.0
    f = 1.5 * MU * W
    res = slide_until_stuck(plane, [(-1.0, 0.0)], SlideParams(MU, W, M, 1e-3, 0.3, drive_force_n=f))
    assert res.x[0] + 1.0 == pytest.approx(0.5 * (f - MU * W) / M * 0.3**2, rel=1e-2)


def test_a_block_sliding_off_a_ledge_flies_lands_and_stops_where_the_closed_form_says():
    """Off a ledge 5 cm high (rounded over 4 mm) at speed v: it flies sqrt(2 h / a) s, lands
    with normal speed sqrt(2 a h), whose impulse takes mu times that off its horizontal speed,
    then slides to rest after (v - mu sqrt(2 a h))^2 / (2 mu a)."""
    from spine_mj.surfaces import GridSurface

    drop, mu = 0.05, 0.5
    x = np.linspace(-0.1, 0.4, 501)
    row = -drop / (1 + np.exp(-x / 0.001))
    grid = GridSurface(heights=np.tile(row, (4, 1)), x=x, y=np.linspace(-1.0, 1.0, 4), unit="m")
    x0, v0 = -0.02, 1.0
    v = math.sqrt(v0**2 - 2 * mu * A_P * abs(x0))  # at the edge
    res = slide_until_stuck(grid, [(x0, 0.0)], SlideParams(mu, W, M, 2e-4, 1.0), velocity_m_s=[(v0, 0.0)])
    assert res.outcome[0] == SlideOutcome.STUCK
    t_fly = math.sqrt(2 * drop / A_P)
    assert res.airborne_steps[0] * 2e-4 == pytest.approx(t_fly, rel=0.03)
    landing = v * t_fly
    after = v - mu * math.sqrt(2 * A_P * drop)
    assert res.x[0] == pytest.approx(landing + after**2 / (2 * mu * A_P), abs=0.01)


def test_bad_input_is_refused():
    with pytest.raises(SpineInputError, match="mu"):
        SlideParams(-0.1, W, M, 1e-3, 1.0)
    with pytest.raises(SpineInputError, match="timestep_s"):
        SlideParams(MU, W, M, 0.0, 1.0)
    with pytest.raises(SpineInputError, match="drive_force_n"):
        SlideParams(MU, W, M, 1e-3, 1.0, drive_force_n=math.nan)
    with pytest.raises(SpineInputError, match="starts"):
        slide_until_stuck(_plane(0.0), [(0.0, math.nan)], SlideParams(MU, W, M, 1e-3, 1.0))


@pytest.mark.parametrize("theta_deg", [0.0, 15.0, -35.0])
def test_a_block_released_on_a_spring_stops_where_the_closed_form_says(theta_deg):
    """Released at rest with a spring force F_0 from a carriage that stays, on an incline
    along x: half a period of the spring's stiffness along the slope k_e, stopping 2 u* on."""
    th = math.radians(theta_deg)
    k, f0 = 400.0, 1.6 * W
    ke = k * math.cos(th) * (math.cos(th) - MU * math.sin(th))
    u_star = (f0 * (math.cos(th) - MU * math.sin(th)) - W * (math.sin(th) + MU * math.cos(th))) / ke
    assert u_star > 0
    half_period = math.pi * math.sqrt(M / ke)
    x0 = -0.5
    for steps in (100, 200):  # steps a half period
        p = SlideParams(MU, W, M, half_period / steps, 1.0, spring_n_m=k)
        res = slide_until_stuck(_plane(theta_deg), [(x0, 0.3)], p, carriage_x=[x0 + f0 / k])
        assert res.outcome[0] == SlideOutcome.STUCK
        # at 2 u* the spring pulls back F_0 - 2 k cos(theta) u*, which friction still holds
        assert (res.x[0] - x0) / math.cos(th) == pytest.approx(2 * u_star, rel=3 / steps)
        assert res.time_s[0] == pytest.approx(half_period, rel=3 / steps)
        assert res.spring_force_n[0] == pytest.approx(k * (x0 + f0 / k - res.x[0]), rel=1e-12)
        assert res.y[0] == pytest.approx(0.3, abs=1e-12)


def test_a_block_on_a_moving_carriage_follows_the_closed_form_and_rests_after_one_period():
    """On flat ground at the breakaway force mu W from a carriage moving at v:
    x = x_0 + v t - (v / omega) sin(omega t), at rest again at t = 2 pi / omega."""
    k, v = 400.0, 0.05
    omega = math.sqrt(k / M)
    period = 2 * math.pi / omega
    x0 = -0.5
    p = SlideParams(MU, W, M, period / 500, 1.0, spring_n_m=k, carriage_speed_m_s=v)
    res = slide_until_stuck(
        _plane(0.0), [(x0, 0.0)], p, carriage_x=[x0 + MU * W / k * (1 + 1e-9)], store_paths=True
    )
    assert res.outcome[0] == SlideOutcome.STUCK
    assert res.time_s[0] == pytest.approx(period, rel=1e-2)
    assert res.x[0] - x0 == pytest.approx(v * period, rel=1e-2)
    path = res.paths[0]
    t = np.arange(path.shape[0]) * p.timestep_s
    closed = x0 + v * t - v / omega * np.sin(omega * t)
    assert np.max(np.abs(path[:, 0] - closed)) < 1e-2 * v * period


def test_a_block_at_rest_on_a_moving_carriage_ends_only_where_held_says():
    """At rest short of breakaway, a moving carriage loads the spring until the block goes:
    with ``held`` false everywhere it keeps going until the bounds."""
    k, v = 400.0, 2.0
    p = SlideParams(MU, W, M, 5e-3, 3.0, spring_n_m=k, carriage_speed_m_s=v)
    waits = slide_until_stuck(_plane(0.0), [(-1.5, 0.0)], p)
    assert waits.outcome[0] == SlideOutcome.STUCK and waits.time_s[0] == pytest.approx(5e-3)
    goes = slide_until_stuck(_plane(0.0), [(-1.5, 0.0)], p, held=lambda x, y: np.zeros(x.shape, bool))
    assert goes.outcome[0] == SlideOutcome.LEFT_DOMAIN and goes.x[0] > 1.9


def test_paths_start_at_the_start_and_end_at_the_end():
    res = slide_until_stuck(
        _plane(40.0), [(0.5, 0.1), (0.2, 0.0)], SlideParams(MU, W, M, 1e-3, 0.05), store_paths=True
    )
    for i, path in enumerate(res.paths):
        assert path.shape == (51, 2)
        assert tuple(path[-1]) == (res.x[i], res.y[i])
    assert tuple(res.paths[0][0]) == (0.5, 0.1)
