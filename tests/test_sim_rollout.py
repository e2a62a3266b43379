"""Batches: the pipelined native rollout equals one run at a time and the Python reference."""

from __future__ import annotations

import numpy as np
from sim_rigs import flat_rig

from spine_mj.sim import SpringDrive, StaticProbe


def test_batch_equals_one_at_a_time_and_python_reference():
    rig = flat_rig()
    drives = [
        SpringDrive(speed_m_s=0.01, duration_s=0.15),
        SpringDrive(speed_m_s=0.03, duration_s=0.15, stiffness_n_m=50.0),
        StaticProbe(rate_n_s=5 * rig.scales.preload_n),
    ]
    starts = [(-0.02, 0.0), (0.01, 0.013), (0.0, -0.01)]
    batch = rig.run_batch(drives, starts, nthread=2)
    for drive, start, b in zip(drives, starts, batch):
        one = rig.run(drive, start=start)
        ref = rig.run(drive, start=start, backend="python")
        for other in (one, ref):
            assert other.end_reason is b.end_reason and other.n == b.n
            np.testing.assert_allclose(other.position_m, b.position_m, rtol=0, atol=1e-12)
            np.testing.assert_allclose(other.drive_force_n, b.drive_force_n, rtol=1e-9, atol=1e-12)
