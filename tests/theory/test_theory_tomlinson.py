"""Closed forms of the dynamics (spine_mj.theory.tomlinson) against their textbook values."""

import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.theory.tomlinson import (
    Corrugation,
    gaussian_ridge_path_curvature,
    liftoff_inertia_number,
    spring_block_period_s,
    spring_block_x,
)


def test_spring_block_swings_between_zero_and_twice_the_drive_speed():
    w, v = 7.0, 0.3
    t = np.linspace(0, 3 * 2 * math.pi / w, 3001)
    speed = np.gradient(spring_block_x(t, v, w), t)
    assert speed.max() == pytest.approx(2 * v, rel=1e-3) and speed.min() == pytest.approx(0, abs=1e-3)
    assert spring_block_period_s(49.0, 1.0) == pytest.approx(2 * math.pi / 7)


def test_corrugation_critical_stiffness_matches_the_formula():
    c = Corrugation(0.3, 0.5)
    assert c.critical_stiffness() == pytest.approx(0.47, abs=0.005)  # PHYSICS: 0.47
    u = np.linspace(0, 2 * math.pi, 200001)
    s, mu = 0.3, 0.5
    rate = (1 + mu**2) * s * 2 * math.pi * np.sin(u) / (1 - mu * s * np.cos(u)) ** 2
    assert c.max_kappa_drop_rate() == pytest.approx(rate.max(), rel=1e-6)
    assert c.slope_length() == pytest.approx(0.190, abs=5e-4)
    # K* is the same number in any length unit
    assert Corrugation(0.3, 0.5, wavelength=3.0).critical_stiffness() == pytest.approx(c.critical_stiffness())


def test_fold_lies_where_the_carriage_turns_back_and_moves_toward_the_steepest_drop_as_k_rises():
    c = Corrugation(0.3, 0.5)
    ks = c.critical_stiffness()
    lo, hi = c.kappa_range()
    folds = [c.fold(f * ks) for f in (0.1, 0.25, 0.5, 0.9)]
    x = [f[0] for f in folds]
    assert np.all(np.diff(x) > 0) and all(lo < f[1] < hi for f in folds)
    # at the fold 1 + (W / k) dkappa/dx = 0
    k = 0.25 * ks
    xf, kf = c.fold(k)
    u = 2 * math.pi * xf
    t = 0.3 * math.cos(u)
    dk = -(1 + 0.25) * 0.3 * 2 * math.pi * math.sin(u) / (1 - 0.5 * t) ** 2
    assert 1 + c.slope_length() / k * dk == pytest.approx(0, abs=2e-3)
    assert kf == pytest.approx((t + 0.5) / (1 - 0.5 * t), rel=1e-4)
    with pytest.raises(SpineInputError, match="no fold"):
        c.fold(1.01 * ks)


def test_a_round_tip_softens_the_crest():
    assert (
        Corrugation(0.3, 0.5, tip_radius=0.02).critical_stiffness()
        < Corrugation(0.3, 0.5).critical_stiffness()
    )
    with pytest.raises(SpineInputError, match="slope_amplitude"):
        Corrugation(0.6, 0.5)


def test_liftoff_inertia_number():
    c = gaussian_ridge_path_curvature(0.5, 1.0)
    assert c == pytest.approx(0.5)
    assert liftoff_inertia_number(c, 4.0) == pytest.approx(0.5)
    assert gaussian_ridge_path_curvature(0.5, 1.0, 1.0) == pytest.approx(1 / 3)
