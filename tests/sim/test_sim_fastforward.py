"""Stick-phase fast-forward of the force ramp, the static probe and the spring drive, and
the ramp's early termination: same physics, fewer steps.

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
from sim_rigs import MU, PHI, flat_rig, plane_rig

from spine_mj import sim
from spine_mj.sim import EndReason, RampDrive, Rig, SpringDrive, TipParams
from spine_mj.sim.ramp import cycle_breakaways, nominal_time_s, rows_to_reset
from spine_mj.surfaces import corrugation, inclined_plane
from spine_mj.theory import agreement
from spine_mj.theory.tomlinson import Corrugation


def _assert_same_physics(plain, fast, cycles):
    lc = plain.scales.char_length_m
    kp, kf = cycle_breakaways(plain, cycles), cycle_breakaways(fast, cycles)
    assert kp.size == cycles and kf.size == cycles
    np.testing.assert_allclose(kf, kp, rtol=0.005)
    a, b = (
        plain.position_m[: rows_to_reset(plain, cycles), :2],
        fast.position_m[: rows_to_reset(fast, cycles), :2],
    )
    assert agreement.path_frechet(b, a, length_scale=lc) <= 0.01


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
    return sim.Rig(inclined_plane(slope_deg=30.0), tip=sim.TipParams(tip_radius_m=5e-4, mu_s=3.0))


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
    rig = sim.Rig(inclined_plane(slope_deg=slope, azimuth_deg=azimuth), tip=sim.TipParams(mu_s=0.5))
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


# -- spring drives ------------------------------------------------------------------------
# The plain spring run (``fast_forward=False``) is the reference. Its time_s is physical in
# both, so the two are compared at equal times and carriage positions.

BLOCK_START = (-0.04, 2.3e-4)


def _spring_block(stick_fraction):
    """The flat rig and a spring-block drive (K = 10, I_e = 1e-6) whose run lasts
    ``stick_fraction`` times the stick phase ``t_b = mu F_p / (k V)`` (4.9 s)."""
    rig = flat_rig()
    v, k = 0.001, 10.0
    t_b = MU * rig.scales.preload_n / (k * v)
    return rig, SpringDrive(speed_m_s=v, stiffness_n_m=k, duration_s=stick_fraction * t_b), t_b


def _plain_and_fast(rig, drive, start=BLOCK_START):
    return tuple(rig.run(dataclasses.replace(drive, fast_forward=f), start=start) for f in (False, True))


def test_a_fast_forwarded_spring_block_breaks_away_where_the_plain_one_does():
    """Flat plane, K = 10, I_e = 1e-6: the block sticks until k V t = mu F_p (4.9 s, ~9700
    steps), then swings. The climb skips most of the stick: the same breakaway time and
    force, the same path at every time after it (the stuck tip does not notice how fast
    its spring was loaded), the same end time and carriage position, in 1/8 of the steps."""
    rig, drive, t_b = _spring_block(1.08)
    plain, fast = _plain_and_fast(rig, drive)
    assert plain.end_reason is EndReason.COMPLETED and fast.end_reason is EndReason.COMPLETED
    onset = [r.drive_start_index + int(np.argmax(r.moving[r.drive_start_index :])) for r in (plain, fast)]
    t0 = plain.time_s[plain.drive_start_index - 1]
    assert plain.time_s[onset[0]] - t0 == pytest.approx(t_b, rel=0.01)  # k V t = mu F_p
    assert fast.time_s[onset[1]] == pytest.approx(plain.time_s[onset[0]], abs=0.5 * rig.engine.timestep_s)
    assert fast.drive_force_n[onset[1]] == pytest.approx(plain.drive_force_n[onset[0]], rel=1e-6)
    t = plain.time_s[onset[0] :]
    x_fast = np.interp(t, fast.time_s, fast.position_m[:, 0])
    assert np.abs(x_fast - plain.position_m[onset[0] :, 0]).max() < 1e-6 * rig.scales.char_length_m
    assert fast.time_s[-1] == pytest.approx(plain.time_s[-1], rel=1e-9)
    assert fast.carriage_x_m[-1] == pytest.approx(plain.carriage_x_m[-1], rel=1e-9)
    frac = (plain.slip_summary()["motion_fractions"], fast.slip_summary()["motion_fractions"])
    assert frac[1]["stuck"] == pytest.approx(frac[0]["stuck"], abs=1e-6)  # time-weighted
    assert fast.simulated_steps < plain.simulated_steps / 6


def _same_slips(plain, fast, *, force_rel, travel_lc, share):
    """At least ``share`` of the plain run's slip events have one in the fast run whose
    onset lies within ``travel_lc`` L_c of carriage travel and ``force_rel`` of its force."""
    lc, v = plain.scales.char_length_m, plain.speed_m_s
    hits = 0
    for e in plain.slip_events:
        hits += any(
            abs(f.onset_time_s - e.onset_time_s) * v <= travel_lc * lc
            and abs(f.onset_force_n / e.onset_force_n - 1) <= force_rel
            for f in fast.slip_events
        )
    return hits >= share * len(plain.slip_events)


def test_fast_forward_keeps_the_prandtl_tomlinson_stick_slip_on_a_corrugation():
    """s = 0.3, mu = 0.5, K = 0.8 K*, I_e = 1e-5, three wavelengths: the tip sticks at the
    start and after each landing, slides up to the fold and jumps (three slips). Plain runs
    from starts 1e-9 m apart differ by 0.04 s in the onsets (0.004 L_c of travel), 0.1 % in
    their forces and up to 0.07 L_c in the jumps; the fast-forwarded run lies within that."""
    rig = Rig(corrugation(n_waves=4, points_per_wave=128), tip=TipParams(mu_s=0.5, tip_radius_m=1e-4))
    sc = rig.scales
    c = Corrugation(0.3, 0.5, wavelength=1.0, tip_radius=rig.tip.tip_radius_m / 0.01)
    K = 0.8 * c.critical_stiffness(sc.slope_length_m / 0.01)
    v = sc.speed_for(1e-5)
    drive = SpringDrive(speed_m_s=v, stiffness_n_m=sc.stiffness_for(K), duration_s=0.03 / v)
    plain, fast = rig.run_batch([dataclasses.replace(drive, fast_forward=False), drive], [(0.75, 0.0)] * 2)
    assert plain.end_reason is EndReason.COMPLETED and fast.end_reason is EndReason.COMPLETED
    assert len(plain.slip_events) == len(fast.slip_events) == 3
    assert _same_slips(plain, fast, force_rel=0.01, travel_lc=0.01, share=1.0)
    jumps = [[e.jump_length_m / sc.char_length_m for e in r.slip_events] for r in (plain, fast)]
    np.testing.assert_allclose(jumps[1], jumps[0], atol=0.1)
    assert np.abs(fast.position_m[-1] - plain.position_m[-1]).max() < 0.01 * sc.char_length_m
    assert fast.time_s[-1] == pytest.approx(plain.time_s[-1], rel=1e-9)
    assert fast.simulated_steps < 0.95 * plain.simulated_steps


def test_fast_forward_keeps_spring_runs_on_a_fractal():
    """paper-fractal, K = 3, I_e = 1e-5, four starts, 0.5 L_c of travel (~25 slips each, the
    tip stuck 40 % of the time in phases of at most ~900 steps: few outlast a climb, and the
    steps fall by 3 %). The fast-forwarded runs end
    within 0.01 L_c of the plain ones, on paths within 0.01 L_c (Frechet), and match 90 % of
    their slip events (onset within 0.01 L_c of travel and 5 % of force). Plain runs from
    starts 1e-9 m apart already differ by up to 3 slips of 28 after 7 s: the landings of
    the larger jumps are ill-conditioned."""
    from spine_mj import presets
    from spine_mj.sim import build_rig

    rig = build_rig(presets.make_surface("paper-fractal", seed=1), mu=0.5, ie=1e-5)
    sc = rig.scales
    v = sc.speed_for(1e-5)
    drive = SpringDrive(
        speed_m_s=v, stiffness_n_m=sc.stiffness_for(3.0), duration_s=0.5 * sc.char_length_m / v
    )
    x0, x1, y0, y1 = (b / rig.length_scale_m for b in rig.bounds_m)
    starts = [(x0 + 0.05 * (x1 - x0), y0 + f * (y1 - y0)) for f in (0.2, 0.4, 0.6, 0.8)]
    plain = rig.run_batch(dataclasses.replace(drive, fast_forward=False), starts)
    fast = rig.run_batch(drive, starts)
    lc = sc.char_length_m
    for p, f in zip(plain, fast):
        assert p.end_reason is f.end_reason
        assert np.abs(f.position_m[-1] - p.position_m[-1]).max() < 0.01 * lc
        assert agreement.path_frechet(f.position_m[:, :2], p.position_m[:, :2], length_scale=lc) <= 0.01
        assert _same_slips(p, f, force_rel=0.05, travel_lc=0.01, share=0.85)
    assert sum(len(f.slip_events) for f in fast) == pytest.approx(
        sum(len(p.slip_events) for p in plain), rel=0.05
    )
    assert sum(f.simulated_steps for f in fast) < sum(p.simulated_steps for p in plain)  # 3 % fewer


def test_a_spring_whose_tip_moves_during_its_climb_goes_on_as_the_plain_run(monkeypatch):
    """A breakaway predicted 50 % too high: the tip slips during each climb, the climb is
    dropped and the run goes on from before it on the plain controls, so the run is the
    plain run to the last bit (plus RISE_STEPS dropped steps a climb)."""
    import spine_mj.sim.fastforward as ff

    rig, drive, _ = _spring_block(1.08)
    plain = rig.run(dataclasses.replace(drive, fast_forward=False), start=BLOCK_START)
    kappa_of_normal = ff.kappa_of_normal
    monkeypatch.setattr(
        ff, "kappa_of_normal", lambda n, mu: (1.5 * kappa_of_normal(n, mu)[0], kappa_of_normal(n, mu)[1])
    )
    fast = rig.run(drive, start=BLOCK_START)
    for name in ("time_s", "position_m", "drive_force_n", "carriage_x_m"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(plain, name))
    dropped = fast.simulated_steps - plain.simulated_steps
    assert dropped > 0 and dropped % ff.RISE_STEPS == 0


def test_a_spring_run_that_ends_stuck_completes_where_the_plain_one_does():
    """The planned end falls inside the stick phase: the climb stops at the plain run's last
    carriage position, and the run completes there, at the same physical time."""
    rig, drive, _ = _spring_block(0.5)
    plain, fast = _plain_and_fast(rig, drive)
    assert plain.end_reason is EndReason.COMPLETED and fast.end_reason is EndReason.COMPLETED
    assert not plain.moving.any() and not fast.moving.any()
    assert fast.time_s[-1] == pytest.approx(plain.time_s[-1], rel=1e-9)
    assert fast.carriage_x_m[-1] == plain.carriage_x_m[-1]
    assert fast.drive_force_n[-1] == pytest.approx(plain.drive_force_n[-1], rel=1e-6)
    assert fast.simulated_steps < plain.simulated_steps / 4


def test_the_fast_forwarded_rollout_equals_its_python_reference():
    """The native pieces and the plain mj_step loop take the same climbs: the same run."""
    rig, drive, _ = _spring_block(1.04)
    native, python = (rig.run(drive, start=BLOCK_START, backend=b) for b in ("rollout", "python"))
    assert native.simulated_steps == python.simulated_steps < 2000
    for name in ("time_s", "position_m", "drive_force_n", "carriage_x_m"):
        np.testing.assert_array_equal(getattr(native, name), getattr(python, name))
