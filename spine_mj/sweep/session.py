"""One sweep session: :func:`run_sweep` runs (or resumes) a sweep into its store.

A session takes the store's lock, records itself in the manifest, skips the cases already
finished, runs the others on the chosen backend (:mod:`spine_mj.sweep.executors`),
writing each as it comes back, reports :class:`Progress`, and rebuilds ``runs.parquet``
at the end. Killed at any moment, the next session resumes where it stopped.
"""

from __future__ import annotations

import datetime
import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.compute as pc
from distributed import Client

from spine_mj.errors import SpineInputError
from spine_mj.sweep.analyses import quasistatic
from spine_mj.sweep.analyses.mujoco import case_rig
from spine_mj.sweep.cases import expand_cases, longest_first
from spine_mj.sweep.config import SweepConfig, _make_surface, load_config
from spine_mj.sweep.executors import DEFAULT_WORKER_WAIT_S, run_dask, run_here, run_processes
from spine_mj.sweep.preflight import check_cases
from spine_mj.sweep.store import (
    consolidate,
    corrupt_cases,
    finished_cases,
    git_commit,
    prepare_store,
    remove_temporaries,
    reopen_cases,
    store_encoded,
    store_lock,
    versions,
)
from spine_mj.workers import MAX_WORKERS_PER_CORE, check_workers  # noqa: F401 (re-exported)


@dataclass(frozen=True)
class Progress:
    """Progress of a running sweep, passed to the ``progress`` callback after each case.

    Attributes
    ----------
    total_cases, finished_cases, skipped_cases : int
        ``finished_cases`` counts cases finished in this session and ``skipped_cases`` those
        found done in the store.
    ok_runs, failed_runs : int
        Runs finished in this session with status ``ok`` / any other status.
    elapsed_s : float
    case_id : str or None
        The case that just finished.
    """

    total_cases: int
    finished_cases: int
    skipped_cases: int
    ok_runs: int
    failed_runs: int
    elapsed_s: float
    case_id: str | None = None


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    out_dir : Path
    total_cases, run_cases, skipped_cases : int
    total_runs, ok_runs, failed_runs, skipped_runs : int
        Runs done now with status ok / other, and runs found finished in the store.
    elapsed_s : float
    workers : int or None
        Local worker processes (None for a Dask scheduler).
    status_counts : dict of str to int
        Whole store (including earlier sessions).
    rerun_corrupt : tuple of str
        Cases whose stored rows could not be read, run again in this session.
    """

    out_dir: Path
    total_cases: int
    run_cases: int
    skipped_cases: int
    total_runs: int
    ok_runs: int
    failed_runs: int
    skipped_runs: int
    elapsed_s: float
    workers: int | None
    status_counts: dict[str, int]
    rerun_corrupt: tuple[str, ...] = ()


def run_sweep(
    config: SweepConfig | str | os.PathLike,
    out_dir: str | os.PathLike,
    *,
    workers: int | None = None,
    scheduler=None,
    overwrite: bool = False,
    retry_failed: bool = False,
    progress: Callable[[Progress], None] | None = None,
    worker_wait_s: float = DEFAULT_WORKER_WAIT_S,
    notice: Callable[[str], None] | None = None,
) -> SweepSummary:
    """Run (or resume) a sweep into ``out_dir``.

    Parameters
    ----------
    config : SweepConfig or path
        A validated config, or the path of its TOML file.
    out_dir : path
        The result store (created if missing). If it holds a sweep of the same config, the
        finished cases are skipped; of another config, SpineInputError unless ``overwrite``.
    workers : int, optional
        Local worker processes; default all cores (``os.cpu_count()``). 1 runs in this
        process. Ignored when ``scheduler`` is given.
    scheduler : str or distributed.Client, optional
        Address of a Dask distributed scheduler (``tcp://host:8786``) or a connected client:
        cases run on its workers, which need spine_mj installed. Results come back to this
        process, which writes the store, so workers need no shared file system (surface
        files named in the config must be readable by them, though).
    overwrite : bool
        Replace a store holding another config.
    retry_failed : bool
        Run again the finished cases that have a run with a status other than ``ok``.
    progress : callable, optional
        Called with a :class:`Progress` once after the skipped cases are counted and after
        every finished case.
    worker_wait_s : float
        With ``scheduler``: seconds to wait for its first worker before giving up.
    notice : callable, optional
        Called with a line of text on what the sweep waits for (a scheduler's workers).

    Returns
    -------
    SweepSummary

    Raises
    ------
    SpineInputError
        A bad config, store, worker count or scheduler address.
    WorkersCannotStart
        Local worker processes die or hang before their first case (the finished cases
        are kept; a re-run resumes).
    SchedulerUnavailable
        The Dask scheduler had no worker within ``worker_wait_s`` or was lost (the
        finished cases are kept; a re-run resumes).
    """
    if not (math.isfinite(worker_wait_s) and worker_wait_s > 0):
        raise SpineInputError(f"--worker-wait must be a number of seconds > 0, got {worker_wait_s!r}")
    if not isinstance(config, SweepConfig):
        config = load_config(config)
    if workers is not None:
        check_workers(workers)
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise SpineInputError(f"--out {out_dir} exists and is not a folder")
    cases = expand_cases(config)
    n_workers = None if scheduler is not None else (workers or os.cpu_count() or 1)
    session = _session_record(n_workers, scheduler)
    clear_caches()
    check_cases(cases, config.swept)  # an input error refuses the config, not every run
    client = None if scheduler is None else connect(scheduler)  # before anything is written
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with store_lock(out_dir):
            return _run_locked(
                config,
                cases,
                out_dir,
                session,
                n_workers=n_workers,
                scheduler=client,
                overwrite=overwrite,
                retry_failed=retry_failed,
                progress=progress,
                worker_wait_s=worker_wait_s,
                notice=notice,
            )
    finally:
        if client is not None and client is not scheduler:
            client.close()


def _session_record(n_workers: int | None, scheduler) -> dict:
    """What the manifest records of this session: start time, workers, scheduler, versions."""
    return {
        "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "workers": n_workers,
        "scheduler": None if scheduler is None else str(getattr(scheduler, "scheduler", scheduler)),
        "versions": versions(),
        "git": git_commit(),
    }


def clear_caches() -> None:
    """Forget the surfaces and rigs this process built: a session reads its inputs afresh
    (a preset edited since an earlier session in this process is read again)."""
    _make_surface.cache_clear()
    quasistatic.clear_cache()
    case_rig.cache_clear()


_ADDRESS = re.compile(r"^((tcp|tls|ucx|ws|wss)://)?[A-Za-z0-9._-]+(:[0-9]{1,5})?$|^inproc://\S+$")


def connect(scheduler):
    """A client of the Dask scheduler ``scheduler`` (an address, or a connected client,
    returned as is); SpineInputError for a malformed or unreachable address."""
    if isinstance(scheduler, Client):
        return scheduler
    if not isinstance(scheduler, str) or not _ADDRESS.match(scheduler):
        raise SpineInputError(
            f"--scheduler: must be a Dask scheduler address like tcp://host:8786, got {scheduler!r}"
        )
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SpineInputError(f"--scheduler {scheduler}: cannot connect ({exc})") from None


#: Seconds to wait for a Dask scheduler to answer.
CONNECT_TIMEOUT_S = 10


def _run_locked(
    config,
    cases,
    out_dir,
    session,
    *,
    n_workers,
    scheduler,
    overwrite,
    retry_failed,
    progress,
    worker_wait_s=DEFAULT_WORKER_WAIT_S,
    notice=None,
) -> SweepSummary:
    prepare_store(config, cases, out_dir, overwrite=overwrite, session=session)
    remove_temporaries(out_dir)
    corrupt = corrupt_cases(out_dir)
    reopen_cases(out_dir, corrupt)  # unreadable: run again
    done = _done_cases(out_dir, retry_failed)
    todo = [c for c in cases if c.case_id not in done]
    skipped = len(cases) - len(todo)
    skipped_runs = sum(c.starts.count for c in cases if c.case_id in done) * len(config.analyses)
    t0 = time.perf_counter()
    counts = {"finished": 0, "ok": 0, "failed": 0}

    def report(case_id):
        if progress is not None:
            progress(
                Progress(
                    total_cases=len(cases),
                    finished_cases=counts["finished"],
                    skipped_cases=skipped,
                    ok_runs=counts["ok"],
                    failed_runs=counts["failed"],
                    elapsed_s=time.perf_counter() - t0,
                    case_id=case_id,
                )
            )

    def handle(encoded):
        store_encoded(out_dir, encoded)
        case_id, statuses = encoded[:2]
        ok = sum(1 for s in statuses if s == "ok")
        counts["finished"] += 1
        counts["ok"] += ok
        counts["failed"] += len(statuses) - ok
        report(case_id)

    report(None)
    if todo:
        if scheduler is not None:
            run_dask(longest_first(todo), scheduler, handle, worker_wait_s=worker_wait_s, notice=notice)
        elif n_workers == 1 or len(todo) == 1:
            # one case left: no processes to start; its engine batch gets the workers' threads
            run_here(todo, handle, threads=n_workers)
        else:
            run_processes(longest_first(todo), n_workers, handle)
    status_counts = _status_counts(consolidate(out_dir))
    return SweepSummary(
        out_dir=out_dir,
        total_cases=len(cases),
        run_cases=counts["finished"],
        skipped_cases=skipped,
        total_runs=sum(c.starts.count for c in cases) * len(config.analyses),
        ok_runs=counts["ok"],
        failed_runs=counts["failed"],
        skipped_runs=skipped_runs,
        elapsed_s=time.perf_counter() - t0,
        workers=n_workers,
        status_counts=status_counts,
        rerun_corrupt=tuple(corrupt),
    )


def _done_cases(out_dir: Path, retry_failed: bool) -> set[str]:
    """The finished cases to skip (with ``retry_failed``, those with a run not ``ok`` are
    taken out of the store and run again)."""
    done = finished_cases(out_dir)
    if retry_failed and done:
        table = consolidate(out_dir)
        bad = set(table.filter(pc.not_equal(table["status"], "ok"))["case_id"].to_pylist())
        reopen_cases(out_dir, bad)
        done -= bad
    return done


def _status_counts(table) -> dict[str, int]:
    """Runs by status in the run table."""
    if not table.num_rows:
        return {}
    vals, cnt = np.unique(np.asarray(table["status"].to_pylist(), dtype=str), return_counts=True)
    return {str(v): int(c) for v, c in zip(vals, cnt)}
