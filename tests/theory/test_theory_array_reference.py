"""The quasistatic array reference and the layouts: hand-checkable cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.sim.layout import MAX_SPINES, Layout
from spine_mj.theory.array_reference import (
    force_control_release,
    forward_branch,
    profile_spine_curve,
    summed_curve,
)


def test_forward_branch_jumps_past_a_fold():
    x = np.arange(6.0)
    hold = np.array([0.0, 1.0, 2.0, 1.5, 1.8, 3.0])  # folds after x = 2
    assert forward_branch(x, hold, np.array([0.5, 2.0, 2.5])).tolist() == [1, 2, 5]


def test_flat_profile_curve_is_stick_then_mu():
    x = np.linspace(0, 1, 101)
    f = profile_spine_curve(x, x0=0.0, slope=np.zeros_like, mu=0.5, spring_per_preload=10.0)
    assert np.allclose(f[x < 0.049], 10 * x[x < 0.049]) and np.allclose(f[x > 0.051], 0.5)


def test_corrugation_curve_peaks_at_the_steepest_kappa_above_k_star():
    s, mu = 0.3, 0.5
    x = np.linspace(0, 3, 3001)
    slope = lambda u: s * np.cos(2 * math.pi * u)  # noqa: E731
    f = profile_spine_curve(x, x0=0.25, slope=slope, mu=mu, spring_per_preload=200.0)
    assert f.max() == pytest.approx((s + mu) / (1 - mu * s), rel=1e-3)
    assert f[x > 0.5].min() == pytest.approx((mu - s) / (1 + mu * s), rel=1e-3)


def test_soft_spring_on_a_corrugation_jumps_at_the_fold_below_its_peak_kappa():
    # K < K*: the forward branch folds before the steepest kappa; the force drops at the jump
    s, mu = 0.3, 0.5
    x = np.linspace(0, 3, 30001)
    slope = lambda u: s * np.cos(2 * math.pi * u)  # noqa: E731
    f = profile_spine_curve(x, x0=0.25, slope=slope, mu=mu, spring_per_preload=1.0)
    assert np.diff(f).min() < -0.3  # a jump
    assert f.max() <= (s + mu) / (1 - mu * s) + 1e-9


def test_summed_curve_of_two_half_wave_shifts_is_flatter_than_either():
    x = np.linspace(0, 3, 3001)
    slope = lambda u: 0.3 * np.cos(2 * math.pi * u)  # noqa: E731
    a, b = (
        profile_spine_curve(x, x0=x0, slope=slope, mu=0.5, spring_per_preload=200.0) for x0 in (0.25, 0.75)
    )
    tot = summed_curve([a, b])
    late = x > 1
    assert np.ptp(tot[late]) < 0.5 * np.ptp(a[late])


def test_force_control_release_reports_the_catch():
    x = np.arange(7.0)
    rel = force_control_release(x, np.array([0.0, 2.0, 3.0, 1.0, 2.5, 4.0, 1.0]))
    assert (rel.first_let_go, rel.holding, rel.caught) == (3.0, 4.0, True)
    assert (rel.first_let_go_x, rel.holding_x) == (2.0, 5.0)
    mono = force_control_release(x, np.arange(7.0))
    assert mono.first_let_go == mono.holding == 6.0 and not mono.caught
    with pytest.raises(SpineInputError, match="one length"):
        force_control_release(x, np.arange(3.0))


@pytest.mark.parametrize("kind", ["grid", "staggered", "random"])
def test_layouts_share_one_footprint_and_keep_tips_apart(kind):
    lay = Layout(kind=kind, rows=4, cols=5, spacing=1.0, seed=3)
    xy = lay.offsets(1.0, tip_radius=0.05)
    assert xy.shape == (20, 2)
    assert np.all(np.abs(xy[:, 0]) <= 2.5 + 1e-12) and np.all(np.abs(xy[:, 1]) <= 2.0 + 1e-12)
    d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
    assert d[~np.eye(20, dtype=bool)].min() >= 0.1 - 1e-12


def test_staggered_rows_are_shifted_half_a_spacing():
    xy = Layout(kind="staggered", rows=2, cols=3, spacing=2.0).offsets(2.0)
    assert np.allclose(xy[3:, 0] - xy[:3, 0], 1.0) and np.isclose(xy[:, 0].mean(), 0.0)


def test_bad_layouts_are_refused():
    with pytest.raises(SpineInputError, match="kind must be one of"):
        Layout(kind="hex")
    with pytest.raises(SpineInputError, match=f"at most {MAX_SPINES} spines"):
        Layout(rows=20, cols=20)
    with pytest.raises(SpineInputError, match="rows must be an integer >= 1"):
        Layout(rows=0)
    with pytest.raises(SpineInputError, match="spacing"):
        Layout(spacing=float("nan"))


def test_compliant_spine_curves_follow_the_prandtl_tomlinson_curve_on_a_corrugation():
    from spine_mj.surfaces import corrugation
    from spine_mj.theory.array_reference import compliant_spine_curves
    from spine_mj.theory.compliant import compliant_streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    surf = corrugation(n_waves=4, width=0.5, points_per_wave=64)
    starts = np.array([[1.1, 0.0], [1.4, 0.0]])
    c = 150.0  # K = c l_s = 28.5 > K* = 0.47: smooth
    X = np.linspace(0.0, 1.0, 201)
    params = StreamlineParams(mu=0.5, dl=0.005)
    # two steps of margin: the last point, where the carriage stops mid-step, is off the curve
    paths = compliant_streamlines(surf, starts, params, stiffness=c, carriage_end=starts[:, 0] + 1.01)
    forces, locked = compliant_spine_curves(paths, X, kappa_cap=20.0)
    slope = lambda u: 0.3 * np.cos(2 * math.pi * u)  # noqa: E731
    for f, x0 in zip(forces, starts[:, 0]):
        pt = profile_spine_curve(X, x0=x0, slope=slope, mu=0.5, spring_per_preload=c)
        assert np.max(np.abs(f - pt)) < 0.02
    assert not locked.any()
