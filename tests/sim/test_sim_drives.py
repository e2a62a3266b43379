"""The open-loop drives against closed forms: static probes on planes, the spring drive on flat ground."""

from __future__ import annotations

import dataclasses
import math

import pytest
from sim_rigs import MU, PHI, START, flat_rig, plane_rig

from spine_mj.sim import EndReason, SpringDrive, StaticProbe
from spine_mj.theory.engagement import SELF_LOCK, kappa


@pytest.mark.parametrize("slope_deg", [-15.0, 0.0, 20.0, 45.0, 60.0])
def test_static_probe_matches_closed_form(slope_deg):
    rig = plane_rig(slope_deg)
    theta = math.radians(slope_deg)
    low = max(0.0, math.tan(theta - PHI))  # smallest force that holds the tip
    hold = 0.5 * (low + math.tan(theta + PHI)) if low > 0 else 0.0
    res = rig.run(StaticProbe(start_force_n=hold * rig.scales.preload_n), start=START)
    assert res.end_reason is EndReason.BREAKAWAY, res.end_detail
    assert res.kappa_mj == pytest.approx(math.tan(theta + PHI), rel=0.05)
    assert res.events[-1].kind == "breakaway"


def test_static_probe_self_locks_beyond_90_degrees():
    rig = plane_rig(70.0)  # theta + arctan(mu) = 96.6 deg
    probe = StaticProbe(
        start_force_n=1.5 * math.tan(math.radians(70) - PHI) * rig.scales.preload_n,
        rate_n_s=20 * rig.scales.preload_n,
        fast_forward=False,
    )
    res = rig.run(probe, start=START)
    assert res.end_reason is EndReason.SELF_LOCK
    # the shared lock rule ends it (the force cap is only the safety net): stuck on a
    # self-locking normal while the force rose one preload, the streamline's verdict too
    assert res.end_detail.startswith("lock rule")
    fp = rig.scales.preload_n
    # (the held stretch starts in the settle phase, one force increment before the drive)
    assert 0.99 * fp <= res.drive_force_n[-1] - res.drive_force_n[res.drive_start_index] < 2 * fp
    assert res.drive_force_n[-1] < res.detection.kappa_cap * fp
    assert int(kappa(math.tan(math.radians(70)), 0.0, MU)[1]) == SELF_LOCK
    assert math.isnan(res.kappa_mj)
    # fast-forwarded, the force climbs toward the cap at once and the same rule ends it
    fast = rig.run(dataclasses.replace(probe, fast_forward=True), start=START)
    assert fast.end_reason is EndReason.SELF_LOCK and fast.end_detail.startswith("lock rule")
    assert fast.n < res.n


@pytest.mark.parametrize(("slope_deg", "locks"), [(55.0, False), (70.0, True)])
def test_spring_drive_and_streamline_give_the_same_lock_verdict_on_planes(slope_deg, locks):
    """Below the self-lock angle (55 + 26.6 < 90 deg) the tip breaks away on both sides;
    above it (70 + 26.6 > 90) both call it self-locked, by the same rule."""
    rig = plane_rig(slope_deg)
    res = rig.run(SpringDrive(speed_m_s=0.02, duration_s=1.0), start=START)
    assert (res.end_reason is EndReason.SELF_LOCK) == locks
    assert (int(kappa(math.tan(math.radians(slope_deg)), 0.0, MU)[1]) == SELF_LOCK) == locks


def test_tip_on_slope_steeper_than_friction_angle_slides():
    rig = plane_rig(40.0)
    res = rig.run(StaticProbe(), start=START)
    assert res.end_reason is EndReason.SLID
    assert res.position_m[-1, 0] < res.position_m[0, 0]  # downhill, against the drive
    # and at 20 deg (< arctan 0.5) the same tip stays put until pushed
    assert plane_rig(20.0).run(StaticProbe(), start=START).end_reason is EndReason.BREAKAWAY


def test_flat_ground_spring_drive_pulls_with_mu_w():
    rig = flat_rig()
    res = rig.run(SpringDrive(speed_m_s=0.005, duration_s=2.0), start=(-0.04, 2.3e-4))
    assert res.end_reason is EndReason.COMPLETED
    half = res.n // 2
    force = res.drive_force_n[half:].mean()
    assert force == pytest.approx(MU * rig.scales.preload_n, rel=0.02)
    assert res.moving[half:].mean() > 0.5
    assert res.inertia_number == pytest.approx(
        rig.tip.mass_kg * 0.005**2 / (rig.scales.preload_n * rig.scales.char_length_m)
    )
    # cell edges give two contacts: a few um of drift over 80 mm, no more
    assert abs(res.position_m[-1, 1] - res.position_m[0, 1]) < 1e-5
    table = res.table()
    assert len(table) == res.n and {"position_x_m", "drive_force_n", "moving"} <= set(table)


def test_spring_drive_start_force_is_a_stretched_spring():
    """A constant start force f0 stands for a spring stretched by f0 / k at the start: on flat
    ground the tip breaks away when f0 + k (X - x0) reaches mu W, after (mu W - f0) / k of
    carriage, and the recorded drive force holds f0 + k (X - x)."""
    rig = flat_rig()
    fp = rig.scales.preload_n
    k = 0.1 * MU * fp / 0.002  # a tenth of mu W over 2 mm of stretch
    drive = SpringDrive(speed_m_s=0.005, stiffness_n_m=k, duration_s=1.0, start_force_n=0.9 * MU * fp)
    res = rig.run(drive, start=(-0.04, 2.3e-4))
    s = res.drive_start_index
    first = s + int(res.moving[s:].argmax())
    advance = res.carriage_x_m[first] - res.carriage_x_m[s]
    assert advance == pytest.approx(0.1 * MU * fp / k, rel=0.1)
    stretch = res.carriage_x_m[s:] - res.position_m[s:, 0] - (res.carriage_x_m[0] - res.position_m[0, 0])
    assert res.drive_force_n[s:] == pytest.approx(drive.start_force_n + k * stretch, rel=1e-3, abs=1e-3 * fp)
    with pytest.raises(ValueError, match="start_force_n"):
        SpringDrive(speed_m_s=0.005, start_force_n=-1.0)
