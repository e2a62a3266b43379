"""One sweep session: :func:`run_sweep` runs (or resumes) a sweep into its store.

A session takes the store's lock, records itself in the manifest, skips the cases already
finished, runs the others on the chosen backend (:mod:`spine_mj.sweep.executors`),
writing each as it comes back, reports :class:`Progress`, and rebuilds ``runs.parquet``
at the end. Killed at any moment, the next session resumes where it stopped.
"""

from __future__ import annotations

import contextlib
import datetime
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.compute as pc

from spine_mj.errors import SpineInputError
from spine_mj.sweep.analyses import quasistatic
from spine_mj.sweep.analyses.engine import case_rig
from spine_mj.sweep.cases import case_count, check_cases_memory, expand_cases
from spine_mj.sweep.config import SweepConfig, _make_surface, load_config
from spine_mj.sweep.executors import DEFAULT_WORKER_WAIT_S, Backend
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
    workers, scheduler, worker_wait_s, notice
        Where the cases run (:class:`~spine_mj.sweep.executors.Backend`): ``workers`` local
        processes (default all cores; 1: this process), or the workers of the Dask
        ``scheduler`` (an address or a client), waiting ``worker_wait_s`` for the first and
        saying so through ``notice``.
    overwrite : bool
        Replace a store holding another config.
    retry_failed : bool
        Run again the finished cases that have a run with a status other than ``ok``.
    progress : callable, optional
        Called with a :class:`Progress` once after the skipped cases are counted and after
        every finished case.

    Returns
    -------
    SweepSummary

    Raises
    ------
    SpineInputError
        A bad config, store, worker count or scheduler address.
    WorkersCannotStart, SchedulerUnavailable
        Local worker processes died or hung before their first case; the Dask scheduler
        had no worker within ``worker_wait_s`` or was lost. The finished cases are kept: a
        re-run resumes.

    Examples
    --------
    A quasistatic sweep of two friction coefficients on the single valley, run twice: the
    second call finds every case finished and skips it (a killed sweep resumes this way).

    >>> import tempfile
    >>> from spine_mj import sweep
    >>> config = sweep.parse_config({
    ...     "sweep": {"name": "valley", "seed": 1, "analyses": ["quasistatic"]},
    ...     "surfaces": [{"preset": "paper-single-valley"}],
    ...     "starts": {"frame": "absolute", "x": [-3.0], "y": [-1.0, -4.0]},
    ...     "grid": {"mu": [0.6, 1.23]},
    ... })
    >>> out = tempfile.mkdtemp()
    >>> summary = sweep.run_sweep(config, out, workers=1)
    >>> summary.run_cases, summary.ok_runs
    (2, 4)
    >>> sweep.run_sweep(config, out, workers=1).skipped_cases
    2
    >>> runs = sweep.load_runs(out)
    >>> sorted(runs.groupby("mu")["self_locked"].sum().astype(int).tolist())
    [0, 1]
    """
    backend = Backend(workers, scheduler, worker_wait_s, notice)
    config, out_dir = _checked_inputs(config, out_dir)
    say = _preparing(config, notice)
    cases = _checked_cases(config, say)
    session = _session_record(backend)
    with backend.connected() as backend, _locked(out_dir):  # connected before anything is written
        if say is not None:
            say("writing the store's manifest")
        st = _open_store(config, cases, out_dir, session, overwrite=overwrite, retry_failed=retry_failed)
        return _run_stores([st], backend, progress)[0]


def _checked_inputs(config, out_dir) -> tuple[SweepConfig, Path]:
    """:func:`run_sweep`'s config (read if a path) and store folder, or SpineInputError
    naming the bad one."""
    if not isinstance(config, SweepConfig):
        config = load_config(config)
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise SpineInputError(f"--out {out_dir} exists and is not a folder")
    return config, out_dir


#: A sweep of at least this many cases says what it prepares (listing its cases takes
#: about 17 us each, checking one whose drive is distinct 130 us, CPU on a 2-core machine
#: loaded 5-12: 3 s here, 166 CPU-s for 999,999 cases), with a count every PROGRESS_EVERY_S.
PREPARE_NOTICE_CASES = 20_000


def _preparing(config: SweepConfig, notice) -> Callable[[str], None] | None:
    """``notice`` with the sweep's size in front, for a sweep of at least
    :data:`PREPARE_NOTICE_CASES` cases (None for a smaller one, or without ``notice``)."""
    n = case_count(config)
    if notice is None or n < PREPARE_NOTICE_CASES:
        return None
    return lambda text: notice(f"preparing {n:,} cases: {text}")


def _checked_cases(
    config: SweepConfig, say: Callable[[str], None] | None = None, *, afresh: bool = True
) -> list:
    """The cases of ``config``, read afresh (:func:`clear_caches`; ``afresh`` False: the
    caller cleared them once for several sweeps) and checked: an input error refuses the
    config, not every run. ``say`` hears of each step of a long one."""
    check_cases_memory(config)  # before the first notice: a refusal is one line
    if say is not None:
        say("listing them")
    listed = None if say is None else (lambda i, n: say(f"listed {i:,} of {n:,}"))
    cases = expand_cases(config, listed)
    if afresh:
        clear_caches()
    if say is not None:
        say("checking every one before the first runs")
    progress = None if say is None else (lambda i, n: say(f"checked {i:,} of {n:,}") if i < n else None)
    check_cases(cases, config.swept, progress)
    return cases


@contextlib.contextmanager
def _locked(out_dir: Path):
    """The store folder, created if missing, locked for this session (:func:`store_lock`)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    with store_lock(out_dir):
        yield


def _session_record(backend: Backend) -> dict:
    """What the manifest records of this session: start time, workers, scheduler, versions."""
    return {
        "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        **backend.record(),
        "versions": versions(),
        "git": git_commit(),
    }


def clear_caches() -> None:
    """Forget the surfaces and rigs this process built: a session reads its inputs afresh
    (a preset edited since an earlier session in this process is read again)."""
    _make_surface.cache_clear()
    quasistatic.clear_cache()
    case_rig.cache_clear()


@dataclass
class _Store:
    """One sweep's store while its cases run: what is left to do and what came back."""

    config: SweepConfig
    cases: list
    out_dir: Path
    todo: list
    skipped: int
    skipped_runs: int
    corrupt: list
    finished: int = 0
    ok: int = 0
    failed: int = 0

    def store(self, encoded) -> None:
        store_encoded(self.out_dir, encoded)
        statuses = encoded[1]
        ok = sum(1 for s in statuses if s == "ok")
        self.finished += 1
        self.ok += ok
        self.failed += len(statuses) - ok

    def summary(self, t0: float, n_workers) -> SweepSummary:
        cases = self.cases
        return SweepSummary(
            out_dir=self.out_dir,
            total_cases=len(cases),
            run_cases=self.finished,
            skipped_cases=self.skipped,
            total_runs=sum(c.starts.count for c in cases) * len(self.config.analyses),
            ok_runs=self.ok,
            failed_runs=self.failed,
            skipped_runs=self.skipped_runs,
            elapsed_s=time.perf_counter() - t0,
            workers=n_workers,
            status_counts=_status_counts(consolidate(self.out_dir)),
            rerun_corrupt=tuple(self.corrupt),
        )


def _open_store(config, cases, out_dir, session, *, overwrite, retry_failed) -> _Store:
    """Prepare the store (locked by the caller) and list the cases left to run."""
    prepare_store(config, cases, out_dir, overwrite=overwrite, session=session)
    remove_temporaries(out_dir)
    corrupt = corrupt_cases(out_dir)
    reopen_cases(out_dir, corrupt)  # unreadable: run again
    done = _done_cases(out_dir, retry_failed)
    todo = [c for c in cases if c.case_id not in done]
    skipped_runs = sum(c.starts.count for c in cases if c.case_id in done) * len(config.analyses)
    return _Store(config, cases, out_dir, todo, len(cases) - len(todo), skipped_runs, list(corrupt))


def _run_stores(stores: list[_Store], backend: Backend, progress) -> list[SweepSummary]:
    """Run the cases left in ``stores`` (locked by the caller) on ``backend``: a case found
    in two stores runs once and is stored in both; ``progress`` gets one :class:`Progress`
    over all of them, once before the first case and after each."""
    owners: dict[str, list[_Store]] = {}
    todo = []
    for st in stores:
        for case in st.todo:
            if case.case_id not in owners:
                todo.append(case)
            owners.setdefault(case.case_id, []).append(st)
    t0 = time.perf_counter()

    def report(case_id):
        if progress is not None:
            progress(
                Progress(
                    total_cases=sum(len(st.cases) for st in stores),
                    finished_cases=sum(st.finished for st in stores),
                    skipped_cases=sum(st.skipped for st in stores),
                    ok_runs=sum(st.ok for st in stores),
                    failed_runs=sum(st.failed for st in stores),
                    elapsed_s=time.perf_counter() - t0,
                    case_id=case_id,
                )
            )

    def handle(encoded):
        for st in owners[encoded[0]]:
            st.store(encoded)
        report(encoded[0])

    report(None)
    backend.run(todo, handle)
    return [st.summary(t0, backend.n_workers) for st in stores]


def run_sweeps(
    jobs: Sequence[tuple[SweepConfig, str | os.PathLike]],
    *,
    workers: int | None = None,
    overwrite: bool = False,
    progress: Callable[[Progress], None] | None = None,
    afresh: bool = True,
) -> list[SweepSummary]:
    """Run (or resume) several sweeps, their cases sharing one pool of local workers.

    Each ``(config, out_dir)`` is stored exactly as :func:`run_sweep` would store it (and
    resumes the same way); the cases of all of them are handed to the workers together,
    longest first, so one sweep's slow last case does not leave the other workers idle
    while the next sweep waits. A case found in two sweeps runs once and is stored in
    both. ``progress`` gets one :class:`Progress` over all the sweeps' cases.

    Parameters
    ----------
    jobs : sequence of (SweepConfig, path)
        Each sweep's config and result store.
    workers : int, optional
        Local worker processes (default: all cores).
    overwrite : bool
        Replace stores that hold another config.
    progress : callable, optional
        Called with a :class:`Progress` over all the sweeps' cases.
    afresh : bool
        Read the surfaces afresh, once for all the sweeps (:func:`clear_caches`: a preset or
        file edited since an earlier sweep in this process is read again); False keeps what
        this process built (surfaces, sizings, dilations, streamlines) for a caller whose
        inputs do not change under it (:class:`~spine_mj.validate.StudyRunner`).

    Returns
    -------
    list of SweepSummary
        One per job, in order.
    """
    backend = Backend(workers)
    configs = [c if isinstance(c, SweepConfig) else load_config(c) for c, _ in jobs]
    dirs = [Path(d) for _, d in jobs]
    if len({d.resolve() for d in dirs}) != len(dirs):
        raise SpineInputError("run_sweeps: every sweep needs its own out_dir")
    if afresh:  # once: the sweeps share the surfaces, their sizing and dilation
        clear_caches()
    expanded = [_checked_cases(c, afresh=False) for c in configs]
    session = _session_record(backend)
    with contextlib.ExitStack() as locks:
        stores = []
        for config, cases, d in zip(configs, expanded, dirs):
            locks.enter_context(_locked(d))
            stores.append(_open_store(config, cases, d, session, overwrite=overwrite, retry_failed=False))
        return _run_stores(stores, backend, progress)


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
