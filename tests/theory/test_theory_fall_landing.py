"""The fall-landing reference against a block sliding down a ramp onto a floor, and against
the plain streamline where nothing falls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import BallOnFacets, GridSurface, TriangulatedSurface, inclined_plane
from spine_mj.theory import streamline as sl
from spine_mj.theory.fall_landing import FallParams, landing_streamlines
from spine_mj.theory.streamline_types import Outcome, StreamlineParams

MU, W, M = 0.5, 1.0, 0.1  # W / M = 10 m/s^2
G = W / M
THETA = math.radians(40.0)  # steeper than friction: tan 40 deg = 0.84 > 0.5
R = 0.01  # the ball's radius


def _ramp_onto_floor():
    """A ramp descending along +x at THETA onto a flat floor at x = 0, as facets under a ball."""
    x = np.linspace(-1.0, 1.0, 201)  # x = 0 is a grid line: the crease between two faces
    row = np.where(x < 0, -math.tan(THETA) * x, 0.0)
    grid = GridSurface(heights=np.tile(row, (5, 1)), x=x, y=np.linspace(-0.2, 0.2, 5), unit="m")
    return BallOnFacets(TriangulatedSurface.from_grid(grid), R)


def _fall(dt, **kw):
    base = dict(mass_kg=M, load_n=W, spring_n_m=1e-9, speed_m_s=0.0, length_scale_m=1.0)
    return FallParams(**{**base, "timestep_s": dt, "max_fall_s": 5.0, **kw})


def test_a_block_sliding_down_a_ramp_lands_on_the_floor_where_the_closed_form_says():
    """From rest on the ramp: a = g (sin - mu cos) over the ramp, the crease's impact leaves
    v (cos - mu sin) along the floor, which friction stops after v_t^2 / (2 mu g)."""
    surface = _ramp_onto_floor()
    # the ball's centre: R / cos above the ramp, R above the floor; its crease where they meet
    crease = R * (1 / math.cos(THETA) - 1) / math.tan(THETA)
    x0 = -0.5
    v = math.sqrt(2 * G * (math.sin(THETA) - MU * math.cos(THETA)) * (crease - x0) / math.cos(THETA))
    land = crease + (v * (math.cos(THETA) - MU * math.sin(THETA))) ** 2 / (2 * MU * G)
    params = StreamlineParams(mu=MU, dl=0.01)
    errors = []
    for dt in (1e-3, 5e-4):
        res = landing_streamlines(surface, [(x0, 0.05)], params, _fall(dt))
        assert res.meta["falls"][0] == 1
        ((lx, ly),) = res.meta["landings"][0]
        assert lx == pytest.approx(land, rel=0.03) and ly == pytest.approx(0.05, abs=1e-12)
        errors.append(abs(lx - land))
        # from the landing the drive moves the tip on along the floor, to the domain's edge
        assert res.outcome[0] == Outcome.LEFT_DOMAIN and res.end_x[0] > 0.95
        path = res.path(0)
        assert np.all(np.diff(path["x"]) > 0) and np.all(path["y"] == 0.05)
        assert np.all(path["region"][path["x"] < crease - 0.02] == 0)  # the ramp: slip
    assert errors[1] < 0.7 * errors[0]  # first order in the step


def test_where_nothing_falls_the_landing_reference_is_the_streamline():
    surface = inclined_plane(slope_deg=10.0, half_width=1.0, n=41)  # rising: engaged everywhere
    params = StreamlineParams(mu=MU, dl=0.02)
    starts = [(-0.8, 0.1), (-0.5, -0.3)]
    plain = sl.streamlines(surface, starts, params)
    res = landing_streamlines(surface, starts, params, _fall(1e-3))
    assert list(res.meta["falls"]) == [0, 0]
    for c in ("x", "y", "kappa", "region"):
        np.testing.assert_array_equal(getattr(res, c), getattr(plain, c))
    np.testing.assert_array_equal(res.outcome, plain.outcome)


def test_a_stiff_spring_holds_a_forward_fall_to_the_carriage_pace():
    """On the ramp with a stiff spring (W / k a thousandth of the ramp) and a carriage at
    v, the tip cannot run ahead: it glides down the ramp, never faster than a few v."""
    surface = _ramp_onto_floor()
    v = 0.5
    fall = _fall(5e-4, spring_n_m=1e3 * W, speed_m_s=v, max_fall_s=2.0)
    res = landing_streamlines(surface, [(-0.3, 0.0)], StreamlineParams(mu=MU, dl=0.01), fall)
    assert res.meta["falls"][0] >= 1 and res.outcome[0] == Outcome.LEFT_DOMAIN
    assert res.meta["fall_peak_speed_m_s"][0] < 3 * v
    assert res.meta["fall_time_s"][0] == pytest.approx(0.3 / v, rel=0.1)


def test_bad_fall_params_are_refused():
    with pytest.raises(SpineInputError, match="spring_n_m"):
        _fall(1e-3, spring_n_m=0.0)
    with pytest.raises(SpineInputError, match="max_falls"):
        _fall(1e-3, max_falls=-1)
