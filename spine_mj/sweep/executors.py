"""Where the cases of a sweep run: in this process, in local worker processes, or on Dask.

Every backend takes the cases to run and a ``handle`` callback, and calls it in this
process with each finished case encoded as Parquet bytes (:func:`spine_mj.sweep.store.
encode_case`); the caller writes the store, so workers never touch it. Workers receive
:class:`~spine_mj.sweep.cases.Case` objects and :func:`encoded_case` by qualified name
(pickled), so these must stay importable module-level names.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import dataclasses
import functools
import importlib
import logging
import math
import multiprocessing
import os
import re
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from distributed import Client, as_completed
from distributed.comm.core import CommClosedError

from spine_mj.errors import SpineInputError
from spine_mj.sweep.case_runs import failed_rows, run_case
from spine_mj.sweep.cases import Case, longest_first
from spine_mj.sweep.pool import run_pool
from spine_mj.sweep.registry import CASE_THREADS
from spine_mj.sweep.store import encode_case
from spine_mj.workers import check_workers


def encoded_case(case: Case) -> tuple:
    """Run ``case`` and encode its rows and paths for the store (what a worker sends back)."""
    return encode_case(case.case_id, *run_case(case))


def run_here(todo: list[Case], handle, *, threads: int = 1) -> None:
    """One worker: the cases run in this process, in order; each case's store files are
    encoded and written on a helper thread while the next case runs (pyarrow releases the
    GIL), and handled here in order as they complete. Each case's engine batch steps on
    ``threads`` threads (:data:`~spine_mj.sweep.registry.CASE_THREADS`)."""
    token = CASE_THREADS.set(max(1, int(threads)))
    try:
        with cf.ThreadPoolExecutor(max_workers=1) as writer:
            pending = None
            for case in todo:
                rows, traj = run_case(case)
                if pending is not None:
                    handle(pending.result())
                pending = writer.submit(encode_case, case.case_id, rows, traj)
            if pending is not None:
                handle(pending.result())
    finally:
        CASE_THREADS.reset(token)


def run_processes(todo: list, n_workers: int, handle, work=None, on_death=None) -> None:
    """``n_workers`` local worker processes, taking the cases in the order of ``todo``
    (``work(case)`` in a worker, by default :func:`encoded_case`; ``on_death(case, reason)``
    here for a case whose worker failed, by default :func:`dead_worker_case`)."""
    # one BLAS thread per worker process (idle BLAS threads spinning in every worker cost a
    # third of the throughput on 2 cores); the worker server reads these when it starts
    saved = {k: os.environ.get(k) for k in _ONE_THREAD}
    for k in _ONE_THREAD:
        os.environ.setdefault(k, "1")
    try:
        _run_pool(todo, n_workers, handle, work or encoded_case, on_death or dead_worker_case)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def map_processes(work: Callable, items, n_workers: int) -> list:
    """``[work(item) for item in items]`` on ``n_workers`` local worker processes (the
    sweeps' pool: :func:`run_processes`), in the order of ``items``; one worker or one item
    runs here. ``work`` must be a module-level function and the items and results
    picklable. Raises RuntimeError (after the other items finished) where an item's
    ``work`` raised or its worker died, naming why."""
    items = list(items)
    if n_workers <= 1 or len(items) <= 1:
        return [work(item) for item in items]
    got: dict[int, tuple] = {}
    run_processes(
        list(enumerate(items)),
        n_workers,
        lambda res: got.__setitem__(res[0], res[1:]),
        functools.partial(_indexed, work),
        lambda job, reason: (job[0], False, reason),
    )
    failed = [f"item {i}: {got[i][1]}" for i in sorted(got) if not got[i][0]]
    if failed:
        raise RuntimeError(f"{work.__name__} failed on {len(failed)} of {len(items)} items; " + failed[0])
    return [got[i][1] for i in range(len(items))]


def _indexed(work: Callable, job: tuple) -> tuple:
    """``(index, True, work(item))`` of ``job = (index, item)`` (a worker's task in
    :func:`map_processes`)."""
    return job[0], True, work(job[1])


_ONE_THREAD = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _run_pool(todo: list, n_workers: int, handle, work, on_death) -> None:
    if threading.active_count() == 1 and "fork" in multiprocessing.get_all_start_methods():
        # a single-threaded process forks safely, and its workers inherit every module it
        # has imported: no second start-up (about 1 s of imports on one core per pool)
        _preload_worker_modules()
        ctx, parent = multiprocessing.get_context("fork"), os.getpid()
    else:
        # with other threads alive a fork could copy a held lock: workers fork instead from
        # a server that has imported these once
        ctx, parent = multiprocessing.get_context("forkserver"), None
        ctx.set_forkserver_preload(list(_WORKER_MODULES))
    run_pool(todo, n_workers, ctx, work, on_death, handle, parent_pid=parent)


def dead_worker_case(case: Case, reason: str) -> tuple:
    """The store entry of a case whose worker process died: every run ``failed``."""
    return encode_case(case.case_id, failed_rows(case, reason), None)


#: What a worker imports before its first case (pandas: pyarrow imports it when it builds a
#: table; mujoco: spine_mj.sim imports it lazily).
_WORKER_MODULES = (
    "spine_mj.sweep",
    "spine_mj.theory.streamline",
    "spine_mj.sim",
    "pyarrow.parquet",
    "pandas",
    "mujoco",
    "mujoco.rollout",
)


def _preload_worker_modules() -> None:
    for name in _WORKER_MODULES:
        importlib.import_module(name)


#: Seconds a sweep waits for the first worker of a Dask scheduler that has none (the CLI's
#: ``--worker-wait``).
DEFAULT_WORKER_WAIT_S = 300.0


class SchedulerUnavailable(RuntimeError):
    """The Dask scheduler had no worker within the wait, or was lost mid-sweep: the
    environment, not a case (the finished cases are kept; a re-run resumes)."""


def run_dask(
    todo: list[Case],
    scheduler,
    handle,
    *,
    worker_wait_s: float = DEFAULT_WORKER_WAIT_S,
    notice: Callable[[str], None] | None = None,
) -> None:
    """The workers of a Dask scheduler (an address, or a connected ``distributed.Client``).

    Waits at most ``worker_wait_s`` for a first worker, saying so through ``notice``.

    Raises
    ------
    SchedulerUnavailable
        No worker within ``worker_wait_s``, or the scheduler lost while cases were running.
    """
    with _quiet_distributed():
        _run_dask(todo, scheduler, handle, worker_wait_s=worker_wait_s, notice=notice)


@contextlib.contextmanager
def _quiet_distributed():
    """Hold back Dask's own log lines while a sweep runs on its scheduler: a lost scheduler
    is one line of ours (:class:`SchedulerUnavailable`), not ``distributed.client - ERROR -
    Failed to reconnect`` before it; what a case raises reaches us through its future.

    After a lost scheduler the loggers stay quiet: the client's reconnect task is
    cancelled on its own event loop after the client is closed, and would log its
    30-line traceback just as the levels came back (3 of 3 tries, scheduler killed 10 s
    in)."""
    names = [
        "distributed",
        *(n for n in list(logging.root.manager.loggerDict) if n.startswith("distributed.")),
    ]
    loggers = [logging.getLogger(n) for n in names]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    except SchedulerUnavailable:
        raise
    except BaseException:
        _restore(loggers, levels)
        raise
    _restore(loggers, levels)


def _restore(loggers, levels) -> None:
    for lg, level in zip(loggers, levels, strict=True):
        lg.setLevel(level)


def _run_dask(todo, scheduler, handle, *, worker_wait_s, notice) -> None:
    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    address = client.scheduler.address
    done = 0
    try:
        _wait_for_workers(client, address, worker_wait_s, notice)
        futures = client.map(
            encoded_case,
            todo,
            pure=False,
            key=[f"spine-mj-case-{c.case_id}-{os.getpid()}-{time.monotonic_ns()}" for c in todo],
        )
        for fut in as_completed(futures):
            result = fut.result()
            fut.release()
            handle(result)
            done += 1
    except (cf.CancelledError, CommClosedError, OSError) as exc:
        raise SchedulerUnavailable(
            f"lost the Dask scheduler {address} after {done} of {len(todo)} cases "
            f"({type(exc).__name__}); the finished cases are kept: re-run the same command to "
            "resume, with a scheduler that is up or without --scheduler to finish here"
        ) from None
    finally:
        if own:
            client.close()


def _wait_for_workers(client, address: str, wait_s: float, notice) -> None:
    n = len(client.scheduler_info().get("workers", {}))
    say = notice or (lambda text: None)
    if n:
        say(f"scheduler {address}: {n} worker{'s' if n != 1 else ''}")
        return
    say(f"waiting for workers: scheduler {address} has 0; giving up after {wait_s:g} s (--worker-wait)")
    try:
        client.wait_for_workers(1, timeout=wait_s)
    except TimeoutError:
        raise SchedulerUnavailable(
            f"scheduler {address} still had no workers after {wait_s:g} s: start some "
            f"(dask worker {address}) and re-run, or wait longer with --worker-wait"
        ) from None
    n = len(client.scheduler_info().get("workers", {}))
    say(f"scheduler {address}: {n} worker{'s' if n != 1 else ''}")


@dataclass(frozen=True)
class Backend:
    """Where a sweep session's cases run: local worker processes, or the workers of a Dask
    scheduler (checked on creation; :func:`~spine_mj.sweep.run_sweep`'s keywords).

    Attributes
    ----------
    workers : int or None
        Local worker processes; None: all cores (``os.cpu_count()``). 1 runs in this
        process. Ignored when ``scheduler`` is given.
    scheduler : str or distributed.Client or None
        Address of a Dask distributed scheduler (``tcp://host:8786``) or a connected client:
        cases run on its workers (spine_mj installed, the config's surface files readable);
        results come back to this process, which writes the store (no shared file system).
    worker_wait_s : float
        With ``scheduler``: seconds to wait for its first worker before giving up.
    notice : callable or None
        Called with a line of text on what the sweep waits for (a scheduler's workers).
    """

    workers: int | None = None
    scheduler: str | Client | None = None
    worker_wait_s: float = DEFAULT_WORKER_WAIT_S
    notice: Callable[[str], None] | None = None

    def __post_init__(self):
        wait = self.worker_wait_s
        if not (math.isfinite(wait) and wait > 0):
            raise SpineInputError(f"--worker-wait must be a number of seconds > 0, got {wait!r}")
        if self.workers is not None:
            check_workers(self.workers)

    @property
    def n_workers(self) -> int | None:
        """Local worker processes (None with a scheduler)."""
        return None if self.scheduler is not None else (self.workers or os.cpu_count() or 1)

    def record(self) -> dict:
        """What a store's manifest records of the backend: workers and scheduler."""
        scheduler = self.scheduler
        return {
            "workers": self.n_workers,
            "scheduler": None if scheduler is None else str(getattr(scheduler, "scheduler", scheduler)),
        }

    @contextlib.contextmanager
    def connected(self) -> Iterator[Backend]:
        """This backend with its scheduler connected (a client made here is closed on exit);
        SpineInputError for a malformed or unreachable address, before anything is written."""
        if self.scheduler is None:
            yield self
            return
        client = connect(self.scheduler)
        try:
            yield dataclasses.replace(self, scheduler=client)
        finally:
            if client is not self.scheduler:
                client.close()

    def run(self, todo: list[Case], handle) -> None:
        """Run ``todo``, ``handle`` taking each finished case (longest first on processes and
        Dask; one case left runs here, its engine batch on the workers' threads)."""
        if not todo:
            return
        if self.scheduler is not None:
            run_dask(
                longest_first(todo),
                self.scheduler,
                handle,
                worker_wait_s=self.worker_wait_s,
                notice=self.notice,
            )
        elif self.n_workers == 1 or len(todo) == 1:
            run_here(todo, handle, threads=self.n_workers)
        else:
            run_processes(longest_first(todo), self.n_workers, handle)


_ADDRESS = re.compile(r"^((tcp|tls|ucx|ws|wss)://)?[A-Za-z0-9._-]+(:[0-9]{1,5})?$|^inproc://\S+$")

#: Seconds to wait for a Dask scheduler to answer.
CONNECT_TIMEOUT_S = 10


def connect(scheduler) -> Client:
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
