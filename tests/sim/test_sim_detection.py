"""End reasons: every one is reachable and recorded."""

from __future__ import annotations

import numpy as np
import pytest
from sim_rigs import START, flat_rig, plane_rig

from spine_mj.errors import SpineInputError
from spine_mj.sim import Detection, EndReason, SpringDrive, StaticProbe


def test_every_end_reason_is_reachable_and_recorded():
    rig = flat_rig()
    reasons = {}
    res = rig.run(SpringDrive(speed_m_s=0.02, duration_s=0.3), start=(0.0, 0.0))
    reasons[res.end_reason] = res
    res = rig.run(SpringDrive(speed_m_s=0.05), start=(0.044, 0.0))
    assert res.end_reason is EndReason.LEFT_DOMAIN
    reasons[res.end_reason] = res
    # (refine=False: the run at a quarter of the step would stop too, on its settling)
    res = rig.run_batch(
        SpringDrive(speed_m_s=0.02, duration_s=0.3),
        [(0.0, 0.0)],
        detection=Detection(penetration_tol_m=1e-7),
        refine=False,
    )[0]
    assert "penetration" in res.end_detail
    # the detail says what sank the tip: here its own weight, no landing
    force = float(res.end_detail.split("pressed by a normal force of ")[1].split()[0])
    assert 0.95 < force < 1.05
    reasons[res.end_reason] = res
    # a spring the step cannot integrate is refused; run anyway, it blows up into a MuJoCo reset
    blow_up = SpringDrive(speed_m_s=0.01, stiffness_n_m=1e9, duration_s=0.05)
    with pytest.raises(SpineInputError, match=r"drive spring .* swings .* rad in one time step"):
        rig.run(blow_up, start=(0.0, 0.0))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(type(rig), "check_drive", lambda self, drive: None)
        res = rig.run(blow_up, start=(0.0, 0.0), detection=Detection(kappa_cap=1e12))
    assert res.end_reason is EndReason.ENGINE_TROUBLE and "reset" in res.end_detail
    for slope, probe in ((0.0, StaticProbe()), (40.0, StaticProbe())):
        res = plane_rig(slope).run(probe, start=START)
        reasons[res.end_reason] = res
    lock = plane_rig(70.0)
    res = lock.run(
        StaticProbe(start_force_n=1.5 * lock.scales.preload_n, rate_n_s=20 * lock.scales.preload_n),
        start=START,
    )
    reasons[res.end_reason] = res
    assert set(reasons) == set(EndReason)
    for reason, res in reasons.items():
        assert res.events[-1].kind == reason.value
        assert res.summary()["end_reason"] == reason.value and res.end_detail


def _move_events_reference(moving, t, start):
    """The obvious form: the settle phase set to stuck, then every change of the flag."""
    s = moving.copy()
    s[:start] = False
    return [
        ("move_onset" if s[i] else "move_stop", int(i), float(t[i]))
        for i in np.flatnonzero(np.diff(s.astype(np.int8))) + 1
    ]


def test_move_events_match_the_reference_on_random_flags():
    from spine_mj.sim.detection import move_events

    rng = np.random.default_rng(3)
    for n in (0, 1, 2, 7, 300):
        t = np.arange(n) * 1e-3
        for p in (0.0, 0.1, 0.5, 1.0):
            moving = rng.random(n) < p
            for start in sorted({0, 1, n // 3, n, n + 2}):
                got = [(e.kind, e.index, e.time_s) for e in move_events(moving, t, start)]
                assert got == _move_events_reference(moving, t, start), (n, p, start)


def test_a_spring_integrated_unstably_ends_as_diverged_never_ok():
    """omega dt = 2.2 (the refusal switched off): the spring's stretch grows 2.4x a step once
    the tip breaks away; the run ends as engine trouble "diverged" (its speed or its spring
    force beyond the energy bound, Detection.speed_limit_m_s / force_limit_n) before MuJoCo
    would warn; omega dt = 0.5 runs clean."""
    rig = flat_rig()
    dt, m = rig.engine.timestep_s, rig.scales.mass_kg
    det = Detection().resolve(rig.scales)
    ends = {}
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(type(rig), "check_drive", lambda self, drive: None)
        for wdt in (0.5, 2.2):
            drive = SpringDrive(speed_m_s=0.01, stiffness_n_m=m * (wdt / dt) ** 2, duration_s=15 * dt)
            ends[wdt] = rig.run(drive, start=(0.0, 0.0))
    assert ends[0.5].engine_trouble == "" and ends[0.5].end_reason is EndReason.COMPLETED
    bad = ends[2.2]
    assert bad.end_reason is EndReason.ENGINE_TROUBLE and bad.engine_trouble == "diverged", bad.end_detail
    speed = np.linalg.norm(bad.velocity_m_s[-1])
    force = abs(bad.drive_force_n[-1])
    assert speed > det.speed_limit_m_s(rig.scales, 0.01) or force > det.force_limit_n(
        rig.scales, 0.01, m * (2.2 / dt) ** 2
    )


def test_a_spring_stretch_beyond_the_energy_bound_is_a_divergence():
    """The force limit is the energy bound's kinetic energy stored in the spring instead,
    plus the force cap and preload: above every force a run within the bound can reach."""
    rig = flat_rig()
    det = Detection().resolve(rig.scales)
    k, v = 1e4, 0.01
    fp = rig.scales.preload_n
    limit = det.force_limit_n(rig.scales, v, k)
    swing = det.speed_limit_m_s(rig.scales, v) * np.sqrt(k * rig.scales.mass_kg)
    assert limit == pytest.approx(2 * (det.kappa_cap + 1) * fp + swing)
    assert det.force_limit_n(rig.scales, v, 0.0) == np.inf  # a force drive pulls with its own force


@pytest.mark.parametrize("refinement", [1, 4])
def test_a_tip_wedged_in_a_v_groove_ends_held_never_as_engine_trouble(refinement):
    """A spring drive up a V-groove (docs/physics.md §6): rising at theta = 50 deg with flanks
    at alpha = 70 deg, the pair of contacts self-locks (theta + arctan(mu / cos alpha') =
    95.5 deg > 90 deg) where either flank's slope alone would not; a gentler groove (20, 30
    deg) slides at the wedge's kappa = tan(theta + arctan(mu / cos alpha')). On the hfield
    refined 1 and 4 times (16 cells a tip radius at 4) the wedged tip ends held at the
    force cap, at a healthy depth, with the normal load its flanks carry in the detail: a
    jam's split is not determined (friction can carry some of the load), but Coulomb's law
    bounds it below by |F_net| / sqrt(1 + mu^2) (each contact's force is at most sqrt(1 +
    mu^2) times its normal force), which the net force along one flank's normal, (W cos
    theta + F sin theta) cos alpha', falls far below."""
    import math

    from spine_mj import sim
    from spine_mj.validate.wedges import flank_tilt, groove

    mu = 0.5
    for theta, alpha in ((50.0, 70.0), (20.0, 30.0)):
        tilt = flank_tilt(theta, alpha)
        th = math.radians(theta)
        rig = sim.build_rig(
            groove(theta, alpha), mu=mu, tip_radius_m=2e-3, hfield_refinement=refinement, ie=1e-4
        )
        fp, r_tip = rig.scales.preload_n, rig.scales.tip_radius_m
        res = rig.run(sim.build_drive(rig.scales, "spring", ie=1e-4), start=(-0.01, 0.0))
        assert not res.engine_trouble
        assert res.penetration_m.max() < 0.02 * r_tip
        force = res.drive_force_n[res.drive_start_index :] / fp
        if theta + math.degrees(math.atan(mu / math.cos(tilt))) > 90:
            assert res.end_reason is sim.EndReason.SELF_LOCK
            assert res.end_detail.startswith("force cap") and "held with a normal force of" in res.end_detail
            assert force[-1] == pytest.approx(Detection().kappa_cap, rel=1e-3)
            held = float(res.end_detail.split("held with a normal force of ")[1].split()[0])
            assert held == pytest.approx(res.normal_force_n[-1] / fp, rel=1e-2)
            assert held >= math.hypot(force[-1], 1.0) / math.hypot(1.0, mu)
            assert held > 2 * (math.cos(th) + force[-1] * math.sin(th)) * math.cos(tilt)
            assert abs(res.position_m[-1, 1]) < 0.01 * r_tip  # held in the crease
        else:
            assert res.end_reason is sim.EndReason.LEFT_DOMAIN  # slid up the groove
            wedge = math.tan(th + math.atan(mu / math.cos(tilt)))
            assert np.mean(force[len(force) // 3 :]) == pytest.approx(wedge, rel=0.05)
            assert np.mean(force[len(force) // 3 :]) > 1.05 * math.tan(th + math.atan(mu))


@pytest.mark.parametrize("alpha", [45.0, 60.0])
def test_normal_force_sums_the_contacts_of_a_tip_sliding_along_a_v_groove(alpha):
    """The normal force a run records is the sum of its contacts' normal forces. A tip
    sliding along a level V-groove whose flanks tilt by alpha touches both: they carry W /
    cos(alpha) together (friction runs along the groove, so the cross-section is
    frictionless), and the drive pulls against mu times that. The net contact force along
    one flank's normal is W cos(alpha) (0.71 and 0.5 W), what the rig recorded before (in a
    P60 grit's crease it read -16 F_p while the flanks carried 374). mu = 0.05 keeps the
    flanks from jamming, where the split is not determined."""
    import math

    from spine_mj import sim
    from spine_mj.validate.wedges import groove

    mu = 0.05
    rig = sim.build_rig(groove(0.0, alpha), mu=mu, tip_radius_m=2e-3, ie=1e-4)
    fp = rig.scales.preload_n
    res = rig.run(sim.build_drive(rig.scales, "spring", ie=1e-4), start=(-0.01, 0.0))
    assert res.end_reason is sim.EndReason.LEFT_DOMAIN and not res.engine_trouble
    rows = slice(res.drive_start_index + (res.n - res.drive_start_index) // 3, res.n - res.n // 10)
    load = np.mean(res.normal_force_n[rows]) / fp  # the tip hops: the mean over the rows
    assert load == pytest.approx(1.0 / math.cos(math.radians(alpha)), rel=0.02)
    assert np.mean(res.drive_force_n[rows]) / fp == pytest.approx(mu * load, rel=0.02)
    assert (res.normal_force_n >= 0).all()
