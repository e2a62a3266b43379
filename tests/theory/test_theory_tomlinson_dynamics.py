"""The reference Prandtl-Tomlinson integrator against its closed forms."""

import math

import numpy as np
import pytest

from spine_mj.theory.tomlinson import Corrugation, spring_block_x
from spine_mj.theory.tomlinson_dynamics import PTParams, SineProfile, integrate

#: The issue's corrugation, unit wavelength and load, I_e = m V^2 / (W L_c) = 1e-4.
SLOPE, MU, SPEED = 0.3, 0.5, 0.01


def _run(k_factor: float, waves: float, speed: float = SPEED):
    c = Corrugation(SLOPE, MU)
    k = k_factor * c.critical_stiffness() / c.slope_length()  # K W / l_s, W = 1
    p = PTParams(mass_kg=1.0, stiffness_n_m=k, load_n=1.0, speed_m_s=speed, mu=MU)
    dt = 0.01 * 2 * math.pi / p.omega_rad_s
    r = integrate(p, SineProfile(SLOPE), 0.75, waves / speed, dt)
    return c, k_factor * c.critical_stiffness(), r


def test_spring_block_on_a_flat_plane_follows_the_closed_form():
    p = PTParams(mass_kg=0.01, stiffness_n_m=100.0, load_n=0.0981, speed_m_s=0.004, mu=0.5)
    r = integrate(p, SineProfile(0.0), 0.0, 0.5, 1e-4)
    release = p.mu * p.load_n / (p.stiffness_n_m * p.speed_m_s)  # the spring reaches mu W
    after = r.time_s >= release
    pred = spring_block_x(r.time_s[after] - release, p.speed_m_s, p.omega_rad_s)
    assert np.max(np.abs(r.x_m[after] - pred)) < 1e-6 * p.speed_m_s / p.omega_rad_s
    assert r.speed_m_s.max() == pytest.approx(2 * p.speed_m_s, rel=1e-6)
    assert np.all(r.x_m[~after] == 0.0) and not r.events and not r.lifted_off


def test_above_k_star_the_slide_is_smooth():
    _, _, r = _run(4.0, 3.0)
    assert not r.events and r.speed_m_s.max() < 5 * SPEED and not r.lifted_off
    assert r.x_m[-1] - r.x_m[0] > 2.5


def test_below_k_star_one_jump_per_wavelength_at_the_fold():
    c, k, r = _run(0.5, 4.0)
    waves = r.x_m[-1] - r.x_m[0]
    assert len(r.events) / waves == pytest.approx(1.0, abs=0.3)
    onsets = np.array([e.onset_force_n for e in r.events])  # W = 1: over F_p
    assert np.all(np.abs(onsets / c.fold(k)[1] - 1) < 0.05)
    # the spring force peaks at W kappa_max on the stable branch, just before the fold
    assert np.all(np.abs(onsets / c.kappa_range()[1] - 1) < 0.01)
    assert all(0.5 < e.jump_length_m < 1.0 for e in r.events)  # to the next stable branch


def test_far_below_k_star_an_inertial_jump_overshoots_the_next_fold():
    # Coulomb friction alone cannot stop the jump released at the fold within a wavelength
    # (docs/physics.md §6): at K*/8 the tip skips folds, at any slow carriage
    *_, r = _run(0.125, 6.0)
    jumps = [e.jump_length_m for e in r.events]
    assert jumps and min(jumps) > 1.5
    assert len(r.events) / (r.x_m[-1] - r.x_m[0]) < 0.6
