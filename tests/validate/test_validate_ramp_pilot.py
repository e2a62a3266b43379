"""Ramp-with-reset duration from a pilot run."""

import pytest

from spine_mj import validate
from spine_mj.surfaces import inclined_plane


def test_ramp_duration_covers_the_target_from_the_measured_slip_per_cycle():
    from spine_mj import sim

    rig = sim.Rig(inclined_plane(slope_deg=0.0, azimuth_deg=0.0), tip=sim.TipParams(mu_s=0.5))
    rp = validate.ramp_duration(rig, validate.PLANE_START, 1.0, target_lc=0.5, max_steps=4000)
    assert rp.ie_equivalent == pytest.approx(1.0, rel=1e-9)
    assert rp.slip_per_cycle_lc > 0 and rp.cycle_s > 0
    # three times the pilot's cycles over the target, plus one ramp to the self-lock cap
    lock_s = sim.Detection().kappa_cap * rig.scales.preload_n / rp.rate_n_s
    assert rp.required_s == pytest.approx(3 * rp.cycle_s * 0.5 / rp.slip_per_cycle_lc + lock_s, rel=1e-9)
    assert rp.duration_s == pytest.approx(min(rp.required_s, 4000 * rp.timestep_s), rel=1e-3)
    assert rp.capped == (rp.required_s > 4000 * rp.timestep_s)
    assert 0 < rp.coverage_expected <= 1
