"""Killing a sweep: the main process alone (its workers exit, a resume starts at once), one
worker alone (its case is recorded failed, the sweep goes on)."""

import contextlib
import faulthandler
import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from sweep_support import peak_config

from spine_mj import sweep
from spine_mj.sweep.pool import run_pool

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")


def start_sweep(cfg, out, workers=2):
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "spine_mj.cli",
            "sweep",
            cfg,
            "--out",
            out,
            "--workers",
            str(workers),
            "--quiet",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def stop(proc):
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)


def children(pid):
    try:
        return {int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()}
    except FileNotFoundError:
        return set()


def alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return False
    return state != "Z"


def n_done(out):
    return len([p for p in (out / "runs").glob("*.parquet") if not p.name.startswith(".")])


def wait_for(cond, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(0.01)
    return False


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_killing_the_main_process_alone_ends_its_workers_and_a_resume_starts_at_once(tmp_path, sig):
    cfg = peak_config(tmp_path, nmu=60, ny=8, dl=0.01)
    out = tmp_path / "out"
    proc = start_sweep(cfg, out)
    try:
        assert wait_for(lambda: (out / "runs").is_dir() and n_done(out) >= 4 and len(children(proc.pid)) == 2)
        workers = children(proc.pid)
        os.kill(proc.pid, sig)  # the main process only, not its process group
        proc.wait(10)
        assert wait_for(lambda: not any(alive(w) for w in workers), timeout=5), "workers outlived the sweep"
    finally:
        stop(proc)
    assert n_done(out) < 60, "the sweep must be killed midway"
    # the store lock never waits: a lock still held by the killed sweep would raise here
    summary = sweep.run_sweep(cfg, out, workers=2)
    assert summary.skipped_cases >= 4 and summary.skipped_cases + summary.run_cases == 60
    runs = sweep.load_runs(out)
    assert len(runs) == 480 and runs.run_id.is_unique and set(runs.status) == {"ok"}


def test_killing_one_worker_fails_its_case_and_the_sweep_goes_on(tmp_path):
    cfg = peak_config(tmp_path, nmu=16, ny=8, dl=0.004)
    out = tmp_path / "out"
    proc = start_sweep(cfg, out)
    try:
        assert wait_for(lambda: (out / "runs").is_dir() and n_done(out) >= 2 and len(children(proc.pid)) == 2)
        os.kill(min(children(proc.pid)), signal.SIGKILL)
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        stop(proc)
    assert proc.returncode == 0, stderr
    assert "Traceback" not in stderr and "failed 8" in stdout
    runs = sweep.load_runs(out)
    assert len(runs) == 128 and runs.run_id.is_unique
    failed = runs[runs.status != "ok"]
    assert failed.case_id.nunique() == 1 and len(failed) == 8
    assert set(failed.status) == {"failed"}
    assert failed.reason.str.contains("SIGKILL").all()


TEST_PROCESS = os.getpid()


def crash_on_three(case):
    if case == 3 and os.getpid() != TEST_PROCESS:
        faulthandler.disable()  # no stack dump on stderr: the crash is the point
        os.kill(os.getpid(), signal.SIGSEGV)
    if case == 5:
        raise ValueError("five is bad")
    return ("ok", case, os.getpid())


def test_pool_records_a_segfault_and_an_exception_as_the_case_failure_and_finishes():
    results = []
    run_pool(
        list(range(8)),
        2,
        multiprocessing.get_context("fork"),
        crash_on_three,
        lambda case, reason: ("failed", case, reason),
        results.append,
        parent_pid=os.getpid(),
    )
    assert sorted(r[1] for r in results) == list(range(8))
    assert all(r[2] != TEST_PROCESS for r in results if r[0] == "ok"), "a case ran in the pool's own process"
    failed = {r[1]: r[2] for r in results if r[0] == "failed"}
    assert set(failed) == {3, 5}
    assert "SIGSEGV" in failed[3] and failed[5] == "ValueError: five is bad"


class _StartsInstead:
    """A multiprocessing context whose processes run ``target(*args)`` instead of the pool's
    worker loop: real processes that die or hang before their first case."""

    def __init__(self, target, args=()):
        self._ctx, self._target, self._args = multiprocessing.get_context("fork"), target, args

    def Pipe(self):
        return self._ctx.Pipe()

    def Process(self, *, target, args, daemon):
        return self._ctx.Process(target=self._target, args=self._args, daemon=daemon)


@pytest.mark.parametrize(
    ("start", "what"),
    [((os._exit, (3,)), "exited with code 3"), ((time.sleep, (600,)), "ended by SIGKILL")],
    ids=["dies", "hangs"],
)
def test_workers_that_die_or_hang_before_their_first_case_end_the_pool_with_the_cause(
    monkeypatch, start, what
):
    import spine_mj.sweep.pool as pool

    monkeypatch.setattr(pool, "STARTUP_TIMEOUT_S", 0.5)
    with pytest.raises(pool.WorkersCannotStart, match=f"die \\(or hang\\) before their first case .*{what}"):
        run_pool(
            list(range(4)), 2, _StartsInstead(*start), crash_on_three, None, None, parent_pid=os.getpid()
        )


def test_a_sweep_whose_workers_cannot_start_ends_in_one_line_and_resumes(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from spine_mj.cli import main
    from spine_mj.sweep import executors

    def dying_pool(todo, n_workers, handle, work, on_death):  # workers that exit before their first case
        run_pool(
            todo,
            n_workers,
            _StartsInstead(os._exit, (3,)),
            work,
            on_death,
            handle,
            parent_pid=os.getpid(),
        )

    cfg = peak_config(tmp_path, nmu=4, ny=2)
    out = tmp_path / "out"
    monkeypatch.setattr(executors, "_run_pool", dying_pool)
    result = CliRunner().invoke(main, ["sweep", str(cfg), "--out", str(out), "--workers", "2", "--quiet"])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == 1 and len(lines) == 1, result.output
    assert lines[0].startswith("Error: sweep worker processes die (or hang) before their first case")
    assert "a re-run resumes" in lines[0]
    monkeypatch.undo()
    summary = sweep.run_sweep(cfg, out, workers=2)
    assert summary.run_cases == 4 and set(sweep.load_runs(out).status) == {"ok"}
