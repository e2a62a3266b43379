"""Stick-phase fast-forward and early termination of the force ramp: same physics, fewer steps.

The plain ramp (``fast_forward=False``) is the reference: where it finishes its cycles the
fast-forwarded ramp must break away at the same force (0.5 %), end the same way and follow
the same path (Frechet <= 0.01 L_c); early termination must leave the recorded run unchanged.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from sim_rigs import PHI, plane_rig

from spine_mj import compare, sim
from spine_mj.sim import EndReason, RampDrive
from spine_mj.sim.ramp import cycle_breakaways, nominal_time_s, rows_to_reset


def _assert_same_physics(plain, fast, cycles):
    lc = plain.scales.char_length_m
    kp, kf = cycle_breakaways(plain, cycles), cycle_breakaways(fast, cycles)
    assert kp.size == cycles and kf.size == cycles
    np.testing.assert_allclose(kf, kp, rtol=0.005)
    a, b = (
        plain.position_m[: rows_to_reset(plain, cycles), :2],
        fast.position_m[: rows_to_reset(fast, cycles), :2],
    )
    assert compare.path_frechet(b, a, length_scale=lc) <= 0.01


@pytest.mark.parametrize("slope", [-15.0, 0.0, 15.0, 25.0])
def test_fast_forward_breaks_away_where_the_plain_ramp_does_on_planes(slope):
    rig = plane_rig(slope)
    rate = 0.05 * rig.scales.preload_n / rig.scales.time_s  # I_e = 2.5e-3
    drive = RampDrive(
        rate_n_s=rate, duration_s=3.2 * (math.tan(math.radians(slope) + PHI)) * rig.scales.time_s * 20
    )
    plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=(-0.01, 0.0))
    fast = rig.run(drive, start=(-0.01, 0.0))
    _assert_same_physics(plain, fast, 2)
    kf = cycle_breakaways(fast, 2)
    np.testing.assert_allclose(kf, math.tan(math.radians(slope) + PHI), rtol=0.05)
    # the stick phases are skipped: the same two cycles in fewer steps, at most the
    # settle, slide and the nominal approach through the margin, RISE_STEPS and QUIET_STEPS
    n_plain, n_fast = rows_to_reset(plain, 2), rows_to_reset(fast, 2)
    assert n_fast < n_plain
    np.testing.assert_allclose(nominal_time_s(plain), plain.time_s)
    t_nom = nominal_time_s(fast)[rows_to_reset(fast, 2) - 1]
    assert t_nom == pytest.approx(plain.time_s[rows_to_reset(plain, 2) - 1], rel=0.05)


@pytest.mark.parametrize("y0", [-1.0, -2.0])
def test_fast_forward_breaks_away_where_the_plain_ramp_does_on_the_single_peak(y0):
    from spine_mj.validate.ramp_plan import pilot_rig

    rig, _ = pilot_rig("paper-single-peak", None, 1.23, 0.1, 61)  # coarse hfield: fast
    rate = 0.1 * rig.scales.preload_n / rig.scales.time_s  # I_e = 1e-2
    drive = RampDrive(
        rate_n_s=rate, duration_s=90 * rig.scales.time_s, slide_distance_m=0.05 * rig.scales.char_length_m
    )
    plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=(-3.0, y0))
    fast = rig.run(drive, start=(-3.0, y0))
    _assert_same_physics(plain, fast, 2)
    assert rows_to_reset(fast, 2) < 0.5 * rows_to_reset(plain, 2)


def _lock_rig():
    # slope 30 deg > arctan(1 / mu): the drive pushes inside the friction cone
    return sim.Rig(sim.inclined_plane(slope_deg=30.0), tip=sim.TipParams(tip_radius_m=5e-4, mu_s=3.0))


def test_a_self_locked_tip_reaches_the_cap_in_one_phase_with_the_plain_ramps_verdict():
    rig = _lock_rig()
    fp = rig.scales.preload_n
    drive = RampDrive(rate_n_s=10 * fp / rig.scales.time_s, duration_s=20 * rig.scales.time_s)
    plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=(0.0, 0.0))
    fast = rig.run(drive, start=(0.0, 0.0))
    assert plain.end_reason is EndReason.SELF_LOCK and fast.end_reason is EndReason.SELF_LOCK
    assert fast.n < plain.n
    np.testing.assert_allclose(fast.position_m[-1], plain.position_m[-1], atol=1e-3 * rig.scales.tip_radius_m)
    slow = rig.run(dataclasses.replace(drive, rate_n_s=1e-3 * fp / rig.scales.time_s), start=(0.0, 0.0))
    assert slow.end_reason is EndReason.SELF_LOCK  # the plain ramp would need 2e4 tau


def _same_run(a, b):
    assert a.end_reason is b.end_reason and a.n == b.n
    assert a.events == b.events
    for name in ("time_s", "position_m", "velocity_m_s", "drive_force_n", "normal_force_n"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_early_termination_leaves_the_recorded_run_unchanged():
    rig = plane_rig(0.0)
    drive = RampDrive(
        rate_n_s=0.3 * rig.scales.preload_n / rig.scales.time_s,
        duration_s=400 * rig.scales.time_s,
        slide_distance_m=2e-3,
    )
    early = rig.run(drive, start=(0.012, 0.0))
    full = rig.run(dataclasses.replace(drive, stop_early=False), start=(0.012, 0.0))
    assert early.end_reason is EndReason.LEFT_DOMAIN
    _same_run(early, full)
    rig = _lock_rig()
    drive = RampDrive(
        rate_n_s=1e-3 * rig.scales.preload_n / rig.scales.time_s, duration_s=5 * rig.scales.time_s
    )
    early = rig.run(drive, start=(0.0, 0.0))
    assert early.end_reason is EndReason.SELF_LOCK
    _same_run(early, rig.run(dataclasses.replace(drive, stop_early=False), start=(0.0, 0.0)))
