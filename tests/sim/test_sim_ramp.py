"""The force ramp with reset: slips at mu, resets, slides the set distance per cycle."""

from __future__ import annotations

import numpy as np
import pytest
from sim_rigs import MU, flat_rig

from spine_mj.sim import EndReason, RampDrive


def test_ramp_with_reset_slips_at_mu_and_ramps_again():
    rig = flat_rig()
    res = rig.run(RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2), start=(-0.04, 0.0))
    assert res.end_reason is EndReason.COMPLETED
    assert len(res.breakaway_kappas) >= 2
    np.testing.assert_allclose(res.breakaway_kappas, MU, rtol=0.05)
    kinds = [e.kind for e in res.events]
    assert "reset" in kinds and kinds.index("reset") > kinds.index("move_onset")
    assert res.speed_m_s == pytest.approx(rig.scales.char_length_m * 2)


def test_ramp_slides_the_set_distance_per_cycle():
    """The paper's algorithm: break away at kappa W, step dl, reset. Each cycle moves the
    tip at least slide_distance_m (and not runaway far), breaking away at mu W each time."""
    rig = flat_rig()
    slide = 0.05 * rig.scales.char_length_m
    res = rig.run(
        RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2, slide_distance_m=slide),
        start=(-0.04, 0.0),
    )
    resets = [e.index for e in res.events if e.kind == "reset"]
    assert len(resets) >= 2
    steps = np.diff(res.position_m[resets, 0])
    assert np.all(steps >= slide) and np.all(steps < 3 * slide)
    np.testing.assert_allclose(res.breakaway_kappas, MU, rtol=0.05)
    short = rig.run(
        RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2, slide_distance_m=0.0), start=(-0.04, 0.0)
    )
    short_resets = [e.index for e in short.events if e.kind == "reset"]
    assert np.diff(short.position_m[short_resets, 0]).max() < slide
