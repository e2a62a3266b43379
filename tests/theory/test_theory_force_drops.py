"""The force-drop rule: drops counted with hysteresis, tested by hand, against a plain
Python walk, on a synthetic stick-slip saw with a resting tip's jitter (no false events,
where the speed rule fires), and on the quasistatic references' Prandtl-Tomlinson jumps."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar

from spine_mj.errors import SpineInputError
from spine_mj.theory.avalanches import Landscape, inertial_slips, overdamped_slips, quasistatic_path
from spine_mj.theory.force_drops import PLATEAU_SHARE, drop_bounds, jitter_scale
from spine_mj.theory.motion import SLIPPING, motion_states
from spine_mj.theory.tomlinson import Corrugation


def _plain_drops(force, floor):
    """The rule written out: from each peak, a drop once the force is ``floor`` below it;
    its trough is the lowest force before the force climbs ``floor`` above it; then the
    level stretches' ends (within a tenth of ``floor`` of the peak and of the trough)."""
    f = list(force)
    events, i, n = [], 0, len(f)
    while i < n:
        top = i  # find the drop's start: the peak of the loading phase
        j = i + 1
        while j < n and f[j] >= f[top] - floor:
            if f[j] > f[top]:
                top = j
            j += 1
        if j >= n:
            break
        low = j
        while j < n and f[j] <= f[low] + floor:
            if f[j] < f[low]:
                low = j
            j += 1
        if j >= n:
            break  # cut by the end
        tol = PLATEAU_SHARE * floor
        start = top
        while start + 1 < low and f[start + 1] >= f[top] - tol:
            start += 1
        end = next(m for m in range(start + 1, low + 1) if f[m] <= f[low] + tol)
        events.append((start, end))
        i = low + int(np.argmax(f[low + 1 : j + 1])) + 1  # the next loading phase's highest so far
    return events


def test_drops_by_hand():
    f = [0.0, 1.0, 0.2, 0.25, 0.1, 1.5, 1.45, 2.0, 0.5, 0.9]
    on, st = drop_bounds(f, 0.3)
    assert list(zip(on, st)) == [(1, 4), (7, 8)]  # 0.25 - 0.2 and 1.45's dip are under the floor
    on, st = drop_bounds(f, 0.6)
    assert list(zip(on, st)) == [(1, 4)]  # the last drop is cut by the end (0.9 - 0.5 < 0.6)
    assert drop_bounds([1.0], 0.1)[0].size == 0


def test_compiled_walk_equals_the_plain_rule():
    rng = np.random.default_rng(3)
    for floor in (0.3, 1.0, 3.0):
        f = np.cumsum(rng.normal(size=3000))
        on, st = drop_bounds(f, floor)
        assert list(zip(on.tolist(), st.tolist())) == _plain_drops(f, floor)


def _saw(rng, jitter):
    """A spring force over a stick-slip saw: loading at 1 per unit time, a drop of 0.2-0.5
    at known times, and a resting jitter of amplitude ``jitter``, bursts at random rows."""
    dt = 1e-3
    t = np.arange(0.0, 10.0, dt)
    slip_times = np.arange(0.7, 10.0, 0.9)
    drops = rng.uniform(0.2, 0.5, slip_times.size)
    f = t - np.array([drops[slip_times <= s].sum() for s in t])
    burst = rng.random(t.size) < 0.5
    f = f + np.where(burst, rng.uniform(-jitter, jitter, t.size), 0.0)
    return t, f, slip_times, drops


def test_jitter_makes_no_event_and_the_slips_are_exact():
    rng = np.random.default_rng(0)
    jitter = 2e-3
    t, f, slip_times, drops = _saw(rng, jitter)
    assert jitter_scale(f) < 2 * jitter  # the jitter's swings, not the slips'
    floor = 10 * jitter
    on, st = drop_bounds(f, floor)
    inside = slip_times < t[-1] - 0.1
    assert on.size == inside.sum()
    np.testing.assert_allclose(f[on] - f[st], drops[inside], atol=2 * jitter)
    np.testing.assert_allclose(t[st], slip_times[inside], atol=2e-3)
    # the resting jitter alone: no event at all
    ramp = t + np.where(rng.random(t.size) < 0.05, rng.uniform(-jitter, jitter, t.size), 0.0)
    assert drop_bounds(ramp, floor)[0].size == 0


def test_the_speed_rule_fires_on_the_jitter_that_the_drop_rule_ignores():
    # a spring k = 1 at drive speed V = 1e-3: the tip's x = X - f / k, jitter 1e-4 in f
    rng = np.random.default_rng(1)
    dt, speed = 1e-2, 1e-3
    x = speed * np.arange(0.0, 100.0, dt)
    f = 1e-4 * rng.uniform(-1, 1, x.size) * (rng.random(x.size) < 0.05)
    tip = np.zeros_like(x) - f  # a tip resting at 0 while the carriage loads the spring
    v = np.zeros((x.size, 3))
    v[:, 0] = np.gradient(tip, dt)
    assert np.sum(motion_states(v, speed) == SLIPPING) > 0  # 5 V is 5e-3: jitter outruns it
    assert drop_bounds(x + f, 1e-3)[0].size == 0


def test_a_level_peak_starts_its_drop_at_its_end_and_a_level_trough_stops_it_at_its_start():
    f = [0.0, 1.0, 1.0, 1.0, 0.5, 0.2, 0.2, 0.2, 0.9]
    on, st = drop_bounds(f, 0.3)
    assert list(zip(on, st)) == [(3, 5)]


def test_bad_input_is_refused():
    with pytest.raises(SpineInputError, match="floor"):
        drop_bounds([0.0, 1.0], 0.0)
    with pytest.raises(SpineInputError, match="finite 1-D"):
        drop_bounds([0.0, math.nan], 1.0)
    with pytest.raises(SpineInputError, match="quantile"):
        jitter_scale([0.0, 1.0, 0.0], 1.5)
    assert jitter_scale([0.0, 1.0, 2.0]) == 0.0


MU, SLOPE, WAVES = 0.5, 0.3, 12


def _force(x):
    s = SLOPE * np.cos(2 * math.pi * x)
    return (s + MU) / (1 - MU * s)


@pytest.mark.parametrize("stiffness_number", [0.1, 0.25])
def test_references_drops_on_a_corrugation_run_from_the_force_peak_to_the_stop(stiffness_number):
    """Prandtl-Tomlinson: along the stable branch the spring holds the tip at ``F(u)``,
    which peaks at the slope's crest (u integer) before the fold; the drop runs from there
    to the slip's stop (the inertial tip rests there, the overdamped one slides on while
    ``F`` still falls, down to ``F``'s minimum at u + 1/2 if it lands before)."""
    pt = Corrugation(SLOPE, MU)
    k = stiffness_number / pt.slope_length()
    g = lambda x: _force(x) + k * x  # noqa: E731
    fold = pt.fold(stiffness_number)[0]
    fold = minimize_scalar(lambda x: -g(x), bounds=(fold - 0.01, fold + 0.01), method="bounded").x
    level = g(fold)
    od_stop = brentq(lambda x: g(x) - level, fold + 1e-3, fold + 1.0)
    grid = np.linspace(fold + 1e-3, fold + 2.0, 4001)
    work = np.array([quad(lambda y: level - g(y), fold, b)[0] for b in grid])
    first = int(np.flatnonzero(work < 0)[0])
    in_stop = brentq(lambda x: quad(lambda y: level - g(y), fold, x)[0], grid[first - 1], grid[first])
    od_trough = max(od_stop, math.floor(fold) + 0.5)
    expected = {
        "overdamped": (od_trough - math.floor(fold), _force(0.0) - _force(od_trough)),
        "inertial": (in_stop - math.floor(fold), _force(0.0) - (level - k * in_stop)),
    }
    x = np.linspace(0.0, WAVES, WAVES * 2000 + 1)
    land = Landscape.from_profile(
        x, SLOPE * np.cos(2 * math.pi * x), SLOPE / (2 * math.pi) * np.sin(2 * math.pi * x), MU
    )
    for source, slips in (("overdamped", overdamped_slips(land, k)), ("inertial", inertial_slips(land, k))):
        carriage = np.linspace(0.0, slips.start_carriage[-1], 40001)
        u = quasistatic_path(land, k, slips, carriage)
        force = k * (carriage - u)
        on, st = drop_bounds(force, 1e-3)
        inside = (u[on] > 0.5) & (u[on] < WAVES - 2)
        assert inside.sum() >= (WAVES - 3) // math.ceil(in_stop - fold)
        phase = (u[on][inside] + 0.5) % 1.0 - 0.5
        assert np.abs(phase).max() < 5e-3  # at the crest
        size, drop = expected[source]
        np.testing.assert_allclose(u[st][inside] - u[on][inside], size, atol=5e-3)
        np.testing.assert_allclose(force[on][inside] - force[st][inside], drop, atol=k * 5e-3 + 1e-4)
