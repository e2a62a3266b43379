"""Identical metrics whatever runs the cases: one process, two workers, a Dask cluster."""

import json

import pandas as pd
from sweep_support import metrics_frame, write_config

from spine_mj import sweep

RANDOM_QS = """
[sweep]
name = "random"
seed = 11
[[surfaces]]
preset = "paper-random-convex"
n_seeds = 2
set = { n_peaks = 30 }
[starts]
random = 3
[grid]
mu = [2.0, 3.0]
trajectory = ["streamline", "ideal"]
dl = 0.05
"""


def test_same_metrics_with_one_or_two_workers_and_on_a_dask_cluster(tmp_path):
    from distributed import LocalCluster

    cfg = write_config(tmp_path, RANDOM_QS)
    sweep.run_sweep(cfg, tmp_path / "w1", workers=1)
    sweep.run_sweep(cfg, tmp_path / "w2", workers=2)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        summary = sweep.run_sweep(cfg, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert summary.workers is None and summary.run_cases == 8
    ref = metrics_frame(tmp_path / "w1")
    assert len(ref) == 24 and set(ref.status) == {"ok"}
    assert ref.self_locked.any() and not ref.self_locked.all()
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "w2"), ref)
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "dask"), ref)
    manifest = json.loads((tmp_path / "dask" / "manifest.json").read_text())
    assert manifest["sessions"][0]["scheduler"].startswith(("tcp://", "inproc://"))
