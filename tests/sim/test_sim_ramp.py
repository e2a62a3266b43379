"""The force ramp with reset: slips at mu, resets, slides the set distance per cycle."""

from __future__ import annotations

import numpy as np
import pytest
from sim_rigs import MU, flat_rig

from spine_mj.sim import EndReason, RampDrive, StaticProbe
from spine_mj.sim.results import breakaway_rows


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


def test_breakaway_is_read_at_the_last_stuck_row_before_each_onset():
    speed = np.array([0.0, 0.0, 5.0, 9.0, 0.0, 1.0, 7.0, 8.0, 9.0])
    # onsets at 3 (stuck at 0, 1) and 6 (stuck at 4); 8 follows 6 with no stuck row between:
    # the same slip going on
    np.testing.assert_array_equal(breakaway_rows(speed, [3, 6, 8], 0.5), [1, 4])
    assert breakaway_rows(speed + 1, [3], 0.5).size == 0


def test_ramp_breakaways_agree_with_the_static_probe_without_the_onset_lag():
    # at the onset (1e-3 v_c) the ramp has risen sqrt(2e-3 sqrt(I_e)) F_p past breakaway,
    # 1.4 % of F_p at I_e = 0.01; read at the last stuck row it is the probe's kappa
    rig = flat_rig()
    rate = 0.1 * rig.scales.preload_n / rig.scales.time_s
    res = rig.run(RampDrive(rate_n_s=rate), start=(-0.04, 0.0))
    probe = rig.run(StaticProbe(rate_n_s=rate), start=(-0.04, 0.0))
    assert len(res.breakaway_kappas) >= 2
    assert np.median(res.breakaway_kappas) == pytest.approx(probe.kappa_mj, rel=2e-3)
    np.testing.assert_allclose(res.breakaway_kappas, probe.kappa_mj, rtol=0.01)  # a cycle may catch
