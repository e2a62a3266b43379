"""Identical metrics whatever runs the cases: one process, two workers, a Dask cluster."""

import json

import pandas as pd
import pytest
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


def test_sweeps_run_together_store_what_each_alone_stores(tmp_path):
    """run_sweeps: two sweeps sharing one pool give each store the rows run_sweep gives it,
    and a sweep given twice (a case in both) runs its cases once and stores them in both."""
    from sweep_support import peak_config

    (tmp_path / "ca").mkdir()
    (tmp_path / "cb").mkdir()
    a = peak_config(tmp_path / "ca", nmu=3, ny=2, name="a")
    b = peak_config(tmp_path / "cb", nmu=2, ny=3, dl=0.03, name="b")
    sweep.run_sweep(a, tmp_path / "a_alone", workers=1)
    sweep.run_sweep(b, tmp_path / "b_alone", workers=1)
    summaries = sweep.run_sweeps([(a, tmp_path / "a"), (b, tmp_path / "b")], workers=2)
    assert [s.run_cases for s in summaries] == [3, 2]
    for name in ("a", "b"):
        pd.testing.assert_frame_equal(
            metrics_frame(tmp_path / name), metrics_frame(tmp_path / f"{name}_alone")
        )
    # resumed: nothing left to run
    again = sweep.run_sweeps([(a, tmp_path / "a"), (b, tmp_path / "b")], workers=2)
    assert [s.skipped_cases for s in again] == [3, 2] and [s.run_cases for s in again] == [0, 0]
    twice = sweep.run_sweeps([(a, tmp_path / "a1"), (a, tmp_path / "a2")], workers=1)
    assert [s.run_cases for s in twice] == [3, 3]
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "a1"), metrics_frame(tmp_path / "a2"))


def test_sweeps_run_together_need_their_own_folders(tmp_path):
    import pytest
    from sweep_support import peak_config

    from spine_mj.errors import SpineInputError

    a = peak_config(tmp_path, nmu=2, ny=1, name="a")
    with pytest.raises(SpineInputError, match="own out_dir"):
        sweep.run_sweeps([(a, tmp_path / "x"), (a, tmp_path / "x")])


def test_dask_log_lines_are_held_back_while_a_sweep_runs_on_a_scheduler():
    """The line distributed prints when its scheduler is gone ("distributed.client - ERROR -
    Failed to reconnect ...") would come before the sweep's own one-line error: inside
    run_dask the library's loggers pass nothing to their handlers, and their levels are
    restored after."""
    import logging

    from spine_mj.sweep.executors import _quiet_distributed

    seen = []

    class Keep(logging.Handler):
        def emit(self, record):
            seen.append(record.getMessage())

    keep = Keep()
    client_log, comm_log = logging.getLogger("distributed.client"), logging.getLogger("distributed.comm.tcp")
    client_log.addHandler(keep)
    logging.getLogger("distributed").addHandler(keep)
    level = client_log.level
    try:
        with _quiet_distributed():
            client_log.error("Failed to reconnect to scheduler after 30.00 seconds, closing client")
            comm_log.warning("closed")
        assert seen == [] and client_log.level == level
        client_log.error("after the sweep")
        assert seen and set(seen) == {"after the sweep"}
    finally:
        client_log.removeHandler(keep)
        logging.getLogger("distributed").removeHandler(keep)


def test_after_a_lost_scheduler_dask_stays_quiet():
    """The client's reconnect task is cancelled on its own loop after the client closes and
    logs a 30-line traceback: after SchedulerUnavailable the levels are not restored, so it
    cannot reach the user before the sweep's one Error line."""
    import logging

    from spine_mj.sweep.executors import SchedulerUnavailable, _quiet_distributed

    client_log = logging.getLogger("distributed.client")
    level = client_log.level
    try:
        with pytest.raises(SchedulerUnavailable), _quiet_distributed():
            raise SchedulerUnavailable("lost")
        assert not client_log.isEnabledFor(logging.ERROR)
        with pytest.raises(KeyError), _quiet_distributed():
            raise KeyError("another error restores them")
    finally:
        client_log.setLevel(level)


def _square_or_fail(x):
    if x == 3:
        raise ValueError("three is refused")
    return x * x


def test_map_processes_keeps_the_order_and_names_a_failure():
    from spine_mj.sweep.executors import map_processes

    assert map_processes(_square_or_fail, [5, 1, 4, 2], 2) == [25, 1, 16, 4]
    assert map_processes(_square_or_fail, [5, 1, 4, 2], 1) == [25, 1, 16, 4]
    with pytest.raises(RuntimeError, match="ValueError: three is refused"):
        map_processes(_square_or_fail, [1, 3, 2], 2)
