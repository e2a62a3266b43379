"""Motion states relative to the drive, against the closed forms (spine_mj.theory.tomlinson)."""

import numpy as np
import pytest
from sim_rigs import MU, flat_rig

from spine_mj.sim import Rig, SpringDrive, TipParams
from spine_mj.surfaces import corrugation
from spine_mj.theory.motion import SLIDING, SLIPPING, STUCK, motion_fractions, motion_states, slip_events
from spine_mj.theory.tomlinson import (
    Corrugation,
    spring_block_period_s,
    spring_block_x,
)


def test_the_spring_block_swing_is_sliding_and_a_fast_jump_is_one_slip():
    v, w = 1.0, 50.0
    t = np.linspace(0, 1, 5001)
    vx = np.gradient(spring_block_x(t, v, w), t)  # 0 .. 2 V: never a slip
    vel = np.column_stack([vx, 0 * vx, 0 * vx])
    states = motion_states(vel, v)
    assert not (states == SLIPPING).any() and (states == SLIDING).any() and (states == STUCK).any()
    vx = np.full(100, 0.01)
    vx[40:46] = [0.5, 2.0, 8.0, 6.0, 2.0, 0.5]  # ahead of the drive from row 41 to 44, peak 8 V
    f = np.linspace(0, 1, 100)
    f[41:46] = [0.38, 0.3, 0.25, 0.2, 0.22]
    states = motion_states(np.column_stack([vx, 0 * vx, 0 * vx]), v)
    assert np.flatnonzero(states == SLIPPING).tolist() == [41, 42, 43, 44]
    (e,) = slip_events(states, np.arange(100.0), np.cumsum(vx), f, vx)
    assert (e.onset, e.stop, e.peak_speed_m_s) == (40, 44, 8.0)
    assert e.onset_force_n == pytest.approx(f[40]) and e.force_drop_n == pytest.approx(f[40] - 0.2)
    assert sum(motion_fractions(states).values()) == pytest.approx(1.0)


def _states_by_loop(vel, v, start):
    """motion_states written out row by row: the reference of its vectorised intervals."""
    speed = np.linalg.norm(vel, axis=1)
    states = np.where(speed < 0.1 * v, STUCK, SLIDING)
    i, n = max(start, 0), len(vel)
    while i < n:
        if vel[i, 0] > v:
            j = i
            while j + 1 < n and vel[j + 1, 0] > v:
                j += 1
            if vel[i : j + 1, 0].max() >= 5.0 * v:
                states[i : j + 1] = SLIPPING
            i = j + 1
        else:
            i += 1
    return states


@pytest.mark.parametrize("seed", range(4))
def test_motion_states_equal_the_row_by_row_rule(seed):
    rng = np.random.default_rng(seed)
    vel = rng.normal(0.0, 1.0, (400, 3)) * [3.0, 0.3, 0.1]
    vel[:5, 0] = 9.0  # intervals at the first rows (inside the settle phase when start > 0)
    vel[-3:, 0] = 9.0  # and one cut by the last row
    for start in (0, 3, 10):
        assert np.array_equal(motion_states(vel, 1.0, start), _states_by_loop(vel, 1.0, start))


def test_spring_block_on_a_flat_plane_period_and_peak_speed():
    """After breakaway x(t) = V t - (V / w) sin(w t): speed 0..2 V, period 2 pi / w."""
    rig = flat_rig()
    v, k = 0.004, 100.0
    res = rig.run(SpringDrive(speed_m_s=v, stiffness_n_m=k, duration_s=1.0), start=(-0.04, 2.3e-4))
    i0 = res.drive_start_index + int(np.argmax(res.moving[res.drive_start_index :]))
    vx, t = res.velocity_m_s[i0:, 0], res.time_s[i0:]
    # the swing's period from the autocorrelation's first peak, its peak speed as the mean
    # plus the fundamental's amplitude (MuJoCo's contact adds step-to-step noise on top)
    dv = vx - vx.mean()
    ac = np.correlate(dv, dv, "full")[dv.size - 1 :]
    dt = t[1] - t[0]
    period = spring_block_period_s(k, rig.tip.mass_kg)
    lags = np.arange(int(0.5 * period / dt), int(1.5 * period / dt))
    measured = lags[np.argmax(ac[lags])] * dt
    assert measured == pytest.approx(period, rel=0.03)
    n = int((t[-1] - t[0]) // measured * measured / dt)
    ph = 2 * np.pi * (t[:n] - t[0]) / measured
    amp = 2 * np.hypot((dv[:n] * np.cos(ph)).mean(), (dv[:n] * np.sin(ph)).mean())
    assert vx[:n].mean() / v == pytest.approx(1.0, rel=0.05)
    assert (vx[:n].mean() + amp) / v == pytest.approx(2.0, rel=0.1)
    assert res.slip_events == () and res.drive_force_n[i0:].mean() == pytest.approx(
        MU * rig.scales.preload_n, rel=0.05
    )


@pytest.fixture(scope="module")
def corrugated():
    return Rig(corrugation(n_waves=4, points_per_wave=128), tip=TipParams(mu_s=0.5, tip_radius_m=1e-4))


@pytest.mark.parametrize("factor", [0.25, 4.0])
def test_prandtl_tomlinson_one_jump_per_wavelength_below_k_star_none_above(corrugated, factor):
    """s = 0.3, mu = 0.5: K* = 0.47; at K*/4 the tip sticks and jumps once per wavelength,
    at the fold's force, many times faster than the carriage; at 4 K* it slides smoothly."""
    rig = corrugated
    sc = rig.scales
    c = Corrugation(0.3, 0.5, wavelength=1.0, tip_radius=rig.tip.tip_radius_m / 0.01)
    ls = sc.slope_length_m / 0.01
    K = factor * c.critical_stiffness(ls)
    v = sc.speed_for(1e-4)
    drive = SpringDrive(speed_m_s=v, stiffness_n_m=sc.stiffness_for(K), duration_s=0.032 / v)
    res = rig.run(drive, start=(0.75, 0.0))
    travel = (res.position_m[-1, 0] - res.position_m[res.drive_start_index, 0]) / 0.01
    per_wave = len(res.slip_events) / travel
    s = res.slip_summary()
    if factor < 1:
        assert 0.5 <= per_wave <= 1.5, (len(res.slip_events), travel)
        # a jump from a tip that reloaded before the fold starts at the fold's force; one that
        # landed past the next fold (inertial overshoot) starts lower, never higher
        onset = np.max(s["slip_onset_forces_fp"])
        assert onset == pytest.approx(c.fold(K, ls)[1], rel=0.05)
        assert s["max_speed_over_drive"] > 10 and s["motion_fractions"]["stuck"] > 0.7
    else:
        assert len(res.slip_events) == 0 and s["max_speed_over_drive"] < 5
        assert s["motion_fractions"]["sliding"] > 0.9
