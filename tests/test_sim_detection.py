"""End reasons: every one is reachable and recorded."""

from __future__ import annotations

from sim_rigs import START, flat_rig, plane_rig

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
    res = rig.run(
        SpringDrive(speed_m_s=0.01, stiffness_n_m=1e9, duration_s=0.05),
        start=(0.0, 0.0),
        detection=Detection(kappa_cap=1e12),
    )
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
