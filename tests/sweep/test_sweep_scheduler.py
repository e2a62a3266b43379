"""A Dask scheduler that has no workers, or is lost mid-sweep: one line saying what happened
and how to resume, within a stated time (a real scheduler on loopback)."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest
from sweep_support import write_config

from spine_mj import sweep

QS = """
[sweep]
name = "sched"
[[surfaces]]
preset = "paper-random-convex"
n_seeds = {n}
set = {{ n_peaks = 20 }}
[starts]
random = 2
[grid]
mu = 2.0
dl = 0.05
"""


def test_a_scheduler_without_workers_is_given_up_after_the_stated_wait(tmp_path):
    from distributed import LocalCluster

    said = []
    cfg = write_config(tmp_path, QS.format(n=2))
    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        t0 = time.monotonic()
        with pytest.raises(sweep.SchedulerUnavailable, match=r"still had no workers after 1 s: start some"):
            sweep.run_sweep(
                cfg,
                tmp_path / "out",
                scheduler=cluster.scheduler_address,
                worker_wait_s=1,
                notice=said.append,
            )
        assert time.monotonic() - t0 < 30
    assert len(said) == 1 and "waiting for workers" in said[0] and "has 0" in said[0]
    assert "giving up after 1 s" in said[0]


def _start(args, tmp_path, name):
    log = open(tmp_path / f"{name}.log", "w")
    return subprocess.Popen([sys.executable, "-m", *args], stdout=log, stderr=subprocess.STDOUT)


def test_losing_the_scheduler_mid_sweep_is_one_error_and_a_resume_finishes(tmp_path, capfd):
    sched_file = tmp_path / "scheduler.json"
    scheduler = _start(
        [
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(sched_file),
        ],
        tmp_path,
        "scheduler",
    )
    worker = None
    try:
        deadline = time.monotonic() + 60
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(sched_file.read_text())["address"]
        worker = _start(
            [
                "distributed.cli.dask_worker",
                "--scheduler-file",
                str(sched_file),
                "--nworkers",
                "1",
                "--nthreads",
                "1",
                "--no-dashboard",
            ],
            tmp_path,
            "worker",
        )
        cfg = write_config(tmp_path, QS.format(n=40))

        def kill_after_first_case(p):
            if p.finished_cases >= 1 and scheduler.poll() is None:
                os.kill(scheduler.pid, signal.SIGKILL)

        with pytest.raises(
            sweep.SchedulerUnavailable, match=r"lost the Dask scheduler .* re-run the same command"
        ):
            sweep.run_sweep(
                cfg, tmp_path / "out", scheduler=address, worker_wait_s=60, progress=kill_after_first_case
            )
        # Dask's own "distributed.client - ERROR - Failed to reconnect" is held back: ours is the line
        assert "distributed." not in capfd.readouterr().err
    finally:
        for proc in (worker, scheduler):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait(timeout=30)
    summary = sweep.run_sweep(cfg, tmp_path / "out", workers=1)  # the resume, here
    assert summary.skipped_cases >= 1 and summary.total_cases == 40
    assert summary.status_counts == {"ok": 80}


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--worker-wait", "5"], "without --scheduler does not use --worker-wait"),
        (
            ["--scheduler", "tcp://127.0.0.1:1", "--worker-wait", "nan"],
            "--worker-wait must be a number of seconds > 0",
        ),
    ],
)
def test_worker_wait_is_refused_where_it_would_be_ignored_or_is_nonsense(tmp_path, extra, fragment):
    from click.testing import CliRunner

    from spine_mj.cli import main

    cfg = write_config(tmp_path, QS.format(n=1))
    result = CliRunner().invoke(main, ["sweep", str(cfg), "--out", str(tmp_path / "out"), *extra])
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip() and "%" not in line]
    assert lines[-1].startswith("Error: ") and fragment in lines[-1], result.output
    assert not (tmp_path / "out").exists()
