"""The quasistatic slip references against closed forms: Prandtl-Tomlinson's jumps on a
corrugation (fold, onset force, landing by the first stable point or by the energy
balance) and the ABBM laws on the ABBM track (tau = 3/2, S_m = sigma / k^2)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import abbm_force_intensity, abbm_slope_walk
from spine_mj.theory.avalanches import (
    Landscape,
    abbm_cutoff,
    inertial_slips,
    overdamped_slips,
    pulse_shapes,
)
from spine_mj.theory.tomlinson import Corrugation
from spine_mj.validate.avalanche_stats import cutoff_size, truncated_fit_by_ks

MU, SLOPE, WAVES = 0.5, 0.3, 12


def _corrugation(points_per_wave=4000):
    x = np.linspace(0.0, WAVES, WAVES * points_per_wave + 1)
    q = 2 * math.pi
    return Landscape.from_profile(x, SLOPE * np.cos(q * x), SLOPE / q * np.sin(q * x), MU)


def _g(x, k):
    t = SLOPE * np.cos(2 * math.pi * x)
    return (t + MU) / (1 - MU * t) + k * x


@pytest.mark.parametrize("stiffness_number", [0.1, 0.25])
def test_both_references_jump_as_prandtl_tomlinson_on_a_corrugation(stiffness_number):
    pt = Corrugation(SLOPE, MU)
    ls = pt.slope_length()
    k = stiffness_number / ls  # K = k l_s / W
    fold_x, fold_kappa = pt.fold(stiffness_number)  # on a grid of 1 / 20000 wavelength
    fold_x = minimize_scalar(lambda x: -_g(x, k), bounds=(fold_x - 0.01, fold_x + 0.01), method="bounded").x
    land = _corrugation()
    du = land.spacing
    level = _g(fold_x, k)
    od_stop = brentq(lambda x: _g(x, k) - level, fold_x + 1e-3, fold_x + 1.0)  # the first stable point
    # the inertial stop: the spring's, landscape's and friction's work back to zero
    grid = np.linspace(fold_x, fold_x + 2.0, 40001)
    work = np.concatenate(
        [[0.0], np.cumsum(np.diff(grid) * (level - 0.5 * (_g(grid[1:], k) + _g(grid[:-1], k))))]
    )
    first = int(np.flatnonzero((work[1:] < 0) & (grid[1:] > fold_x + 1e-3))[0])
    in_stop = brentq(lambda x: quad(lambda y: level - _g(y, k), fold_x, x)[0], grid[first], grid[first + 1])
    for slips, stop in ((overdamped_slips(land, k), od_stop), (inertial_slips(land, k), in_stop)):
        inside = slips.start_u < WAVES - 1.5
        starts = slips.start_u[inside][1:]  # the first may start from the drive's first fold
        assert starts.size >= (WAVES - 3) // math.ceil(stop - fold_x)  # inertia may skip a wavelength
        phase = (starts - fold_x + 0.5) % 1.0 - 0.5
        assert np.abs(phase).max() < 2 * du  # one jump a wavelength, at the fold
        onset = (slips.start_carriage - slips.start_u) * k  # k (X - u) at the start
        assert np.abs(onset[inside][1:] - fold_kappa).max() < 1e-3  # the onset force W kappa(fold)
        assert np.abs(slips.size[inside][1:] - (stop - fold_x)).max() < 2 * du
        assert slips.force_drop == pytest.approx(k * slips.size)
    assert in_stop > od_stop  # inertia overshoots the first stable point


def test_smooth_slide_above_the_critical_stiffness_has_no_slip():
    pt = Corrugation(SLOPE, MU)
    k = 1.2 * pt.critical_stiffness() / pt.slope_length()
    assert overdamped_slips(_corrugation(400), k).size.size == 0
    assert inertial_slips(_corrugation(400), k).size.size == 0


def _abbm_landscape(points=2_000_000, seed=0):
    dx, d, xi = 0.02, 1e-6, 1e4
    s = abbm_slope_walk(points, dx, d, xi, np.random.default_rng(seed))
    x = dx * np.arange(points)
    return Landscape.from_profile(x, s, np.cumsum(s) * dx, MU), abbm_force_intensity(d, MU)


def test_overdamped_reference_on_the_abbm_track_gives_tau_three_halves_and_cutoff_k_minus_two():
    land, sigma = _abbm_landscape()
    ks = np.array([2e-4, 6e-4, 2e-3])  # S_m from 39 to 0.39: two decades, inside [10 dx, xi / 10]
    cutoffs = []
    for k in ks:
        sizes = overdamped_slips(land, k).size
        cutoffs.append(cutoff_size(sizes, n_bootstrap=50)["value"])
        assert cutoffs[-1] == pytest.approx(abbm_cutoff(sigma, k), rel=0.5)
        if k == 6e-4:
            fit = truncated_fit_by_ks(sizes)
            assert 1.4 <= fit["tau"] <= 1.6
            assert fit["low"] <= 1.5 <= fit["high"]
    slope = np.polyfit(np.log(ks), np.log(cutoffs), 1)[0]
    assert slope == pytest.approx(-2.0, abs=0.2)


def test_inertial_slips_are_longer_and_their_work_balances():
    land, _ = _abbm_landscape(points=50_000, seed=1)
    k = 3e-4
    od, ine = overdamped_slips(land, k), inertial_slips(land, k)
    assert ine.slides_back == 0
    assert np.mean(ine.size) > 1.5 * np.mean(od.size)  # overshoot past stable points
    # inertial: the spring's work equals int F du (no kinetic energy left)
    u = land.positions
    for p, s, x in zip(ine.start_u[:50], ine.size[:50], ine.start_carriage[:50]):
        grid = np.concatenate([[p], u[(u > p) & (u < p + s)], [p + s]])  # exact on the linear pieces
        spring = np.trapezoid(k * (x - grid), grid)
        landscape = np.trapezoid(np.interp(grid, u, land.force), grid)
        assert spring == pytest.approx(landscape, abs=1e-6 * s)
    # overdamped: every point passed over is unstable (no passing), the stop is stable
    g = land.force + k * (u - u[0])
    for p, s, x in zip(od.start_u[:50], od.size[:50], od.start_carriage[:50]):
        level = k * (x - u[0])
        inside = (u > p + land.spacing) & (u < p + s - land.spacing)
        assert np.all(g[inside] < level + 1e-12)


def test_bad_landscapes_are_refused():
    x = np.linspace(0, 1, 10)
    with pytest.raises(SpineInputError):
        Landscape.from_profile(x, np.full(10, 3.0), x, MU)  # self-locks
    with pytest.raises(SpineInputError):
        Landscape.from_profile(x[::-1], np.zeros(10), x, MU)
    with pytest.raises(SpineInputError):
        overdamped_slips(_corrugation(16), -1.0)


def _running_max_slips(land, k):
    """The obvious overdamped reference: the slips are the excursions of g below its running
    maximum, each landing where g first climbs back to the level it left."""
    u = land.positions
    g = land.force + k * (u - u[0])
    below = g < np.maximum.accumulate(g)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], below.astype(int), [0]])))
    sizes = []
    for a, b in zip(edges[0::2], edges[1::2]):  # g[a:b] below the level g[a - 1]
        if b >= g.size:
            break
        level = g[a - 1]
        land_u = u[b - 1] + (level - g[b - 1]) / (g[b] - g[b - 1]) * land.spacing
        sizes.append(land_u - u[a - 1])
    return np.array(sizes)


def test_overdamped_walk_is_the_running_maximum_rule():
    land, _ = _abbm_landscape(points=20_000, seed=4)
    for k in (3e-4, 3e-3):
        np.testing.assert_allclose(
            overdamped_slips(land, k).size, _running_max_slips(land, k), rtol=1e-9, atol=1e-9
        )


def test_abbm_pulse_is_a_parabola_overdamped_and_skewed_with_inertia():
    """ABBM: the mean shape of the overdamped slips of like duration is the parabola
    ``4 x (1 - x)`` (here the shorter half, below the cutoff's time scale); a tip with mass
    speeds up for most of its slip and stops abruptly (peak after 0.6 T)."""
    land, _ = _abbm_landscape(points=200_000, seed=2)
    k = 6e-4
    x = np.linspace(0.0, 1.0, 41)
    shapes, durations = pulse_shapes(land, k, overdamped_slips(land, k), inertial=False)
    short = shapes[durations <= np.median(durations)].mean(axis=0)
    inner = (x >= 0.1) & (x <= 0.9)
    assert np.abs(short / short.max() - 4 * x * (1 - x))[inner].max() < 0.12
    assert np.mean(shapes) == pytest.approx(1.0, abs=0.1)  # v / (S / T) averages to 1
    shapes, _ = pulse_shapes(land, k, inertial_slips(land, k), inertial=True)
    assert x[np.argmax(shapes.mean(axis=0))] > 0.6
