"""Stick-phase fast-forward of the force ramp and the static probe, and the ramp's early
termination: same physics, fewer steps.

The plain ramp (``fast_forward=False``) is the reference: where it finishes its cycles the
fast-forwarded ramp must break away at the same force (0.5 %), end the same way and follow
the same path (Frechet <= 0.01 L_c); early termination must leave the recorded run unchanged.
The plain probe is the probe's: the same ending, kappa_mj within 0.5 %.
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
    from spine_mj.validate.ramp_pilot import pilot_rig

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


def test_a_tip_wedged_in_the_valley_reaches_the_cap_with_the_plain_ramps_verdict():
    """In the single valley's trap the tip is wedged between facets: it holds beyond the
    breakaway its deepest normal predicts, so only the force cap ends the run. The
    fast-forward's approach takes it there at 8 times the nominal rate: the same verdict,
    the same place (0.006 L_c apart after 20 cycles), in under half the steps."""
    from spine_mj.validate.ramp_pilot import pilot_rig

    rig, _ = pilot_rig("paper-single-valley", None, 1.23, 0.1, 61)
    sc = rig.scales
    drive = RampDrive(
        rate_n_s=0.1 * sc.preload_n / sc.time_s,
        duration_s=3000 * sc.time_s,
        slide_distance_m=0.1 * sc.char_length_m,
    )
    plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=(-3.0, -1.0))
    fast = rig.run(drive, start=(-3.0, -1.0))
    for r in (plain, fast):
        assert r.end_reason is EndReason.SELF_LOCK and r.end_detail.startswith("force cap")
    assert np.abs(fast.position_m[-1] - plain.position_m[-1]).max() < 0.01 * sc.char_length_m
    assert cycle_breakaways(fast, 100).size == cycle_breakaways(plain, 100).size
    assert fast.simulated_steps < 0.5 * plain.simulated_steps


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


def _probe(rig, ie, fx, fy):
    """The static map's probe (validate.static_map) at ``I_e = ie`` on a plane of slopes
    (fx, fy): it starts holding the smallest force that keeps the tip put plus half the gap
    to the breakaway force."""
    from spine_mj.validate.static_map import hold_force

    k, low, _ = hold_force(fx, fy, rig.tip.mu_s)
    hold = 0.5 * (low + k) if low > 0 else 0.0
    sc = rig.scales
    return sim.StaticProbe(
        rate_n_s=sc.speed_for(ie) * sc.preload_n / sc.char_length_m, start_force_n=hold * sc.preload_n
    )


@pytest.mark.parametrize(
    ("slope", "azimuth", "saves"),
    [
        (0.0, 0.0, True),
        (15.0, 0.0, True),
        (30.0, 0.0, True),
        (45.0, 0.0, True),
        (52.5, 0.0, True),
        (30.0, 30.0, True),
        # kappa 0.29: the climb would skip less than it costs (StickFastForward declines)
        (20.0, 150.0, False),
    ],
)
@pytest.mark.parametrize("ie", [1e-2, 1e-3])
def test_probe_fast_forward_breaks_away_where_the_plain_probe_does_on_planes(slope, azimuth, saves, ie):
    rig = sim.Rig(sim.inclined_plane(slope_deg=slope, azimuth_deg=azimuth), tip=sim.TipParams(mu_s=0.5))
    t = math.tan(math.radians(slope))
    probe = _probe(rig, ie, t * math.cos(math.radians(azimuth)), t * math.sin(math.radians(azimuth)))
    plain = rig.run(dataclasses.replace(probe, fast_forward=False), start=(0.0, 0.0))
    fast = rig.run(probe, start=(0.0, 0.0))
    assert plain.end_reason is EndReason.BREAKAWAY and fast.end_reason is EndReason.BREAKAWAY
    assert fast.kappa_mj == pytest.approx(plain.kappa_mj, rel=0.005)
    assert fast.n <= plain.n
    if ie == 1e-3 and saves:  # slow enough that the climb saves steps
        assert fast.n < 0.6 * plain.n and fast.simulated_steps < plain.simulated_steps


@pytest.mark.parametrize(
    ("start", "end"),
    [
        ((-3.0, -1.0), EndReason.BREAKAWAY),
        ((-2.0, -2.0), EndReason.BREAKAWAY),
        ((-3.0, 1.0), EndReason.BREAKAWAY),
        ((-1.0, 1.5), EndReason.BREAKAWAY),
        ((-1.5, -0.5), EndReason.SELF_LOCK),  # a facet steeper than 1 / mu
    ],
)
def test_probe_fast_forward_breaks_away_where_the_plain_probe_does_on_the_single_peak(start, end):
    from spine_mj.validate.ramp_pilot import pilot_rig

    rig, _ = pilot_rig("paper-single-peak", None, 1.23, 0.1, 61)
    sc = rig.scales
    probe = sim.StaticProbe(rate_n_s=sc.speed_for(1e-3) * sc.preload_n / sc.char_length_m)
    plain = rig.run(dataclasses.replace(probe, fast_forward=False), start=start)
    fast = rig.run(probe, start=start)
    assert plain.end_reason is end and fast.end_reason is end
    assert fast.end_detail.split(":")[0] == plain.end_detail.split(":")[0]
    if end is EndReason.BREAKAWAY:
        assert fast.kappa_mj == pytest.approx(plain.kappa_mj, rel=0.005)
    assert fast.n < 0.6 * plain.n


def test_a_probe_that_moves_during_its_climb_goes_on_as_the_plain_probe(monkeypatch):
    """A breakaway predicted 50 % too high: the tip slips during the climb, the climb is
    dropped and the probe goes on from its settled state with the plain controls, so the
    run is the plain probe's to the last bit (plus the dropped steps)."""
    import spine_mj.sim.fastforward as ff

    rig = plane_rig(15.0)
    probe = _probe(rig, 1e-3, math.tan(math.radians(15.0)), 0.0)
    plain = rig.run(dataclasses.replace(probe, fast_forward=False), start=(0.0, 0.0))
    kappa_of_normal = ff.kappa_of_normal
    monkeypatch.setattr(
        ff, "kappa_of_normal", lambda n, mu: (1.5 * kappa_of_normal(n, mu)[0], kappa_of_normal(n, mu)[1])
    )
    fast = rig.run(probe, start=(0.0, 0.0))
    assert fast.end_reason is EndReason.BREAKAWAY and fast.kappa_mj == plain.kappa_mj
    np.testing.assert_array_equal(fast.position_m, plain.position_m)
    np.testing.assert_array_equal(fast.drive_force_n, plain.drive_force_n)
    assert fast.simulated_steps == plain.simulated_steps + ff.RISE_STEPS
