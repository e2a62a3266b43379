"""Local worker processes that die with their parent and whose deaths cost one case only.

:func:`run_pool` hands cases one at a time to worker processes over pipes and waits on
both the pipes and the processes. A worker that dies while running a case (a segfault, a
kill, the out-of-memory killer) has that case recorded ``failed`` with the cause, and a
new worker takes its place: the sweep goes on. Each worker exits by itself when the
process that started it dies, however it dies (``kill -9`` included): on Linux the kernel
sends it SIGKILL (``PR_SET_PDEATHSIG``), elsewhere a watchdog thread notices that its
parent changed. So a killed sweep leaves no worker behind to hold memory or the store.
"""

from __future__ import annotations

import collections
import ctypes
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from multiprocessing.connection import wait

#: Seconds between a worker's checks that its parent is alive (where prctl is missing).
WATCHDOG_PERIOD_S = 0.5
#: Workers that die before their first case, in a row, before the pool gives up.
MAX_STARTUP_DEATHS = 3
#: Seconds a worker may take to report ready (a fork takes milliseconds, a fork server's
#: first start its imports, ~1-2 s); one that takes longer is hung, is killed and counts
#: as a death before its first case.
STARTUP_TIMEOUT_S = 120.0


class WorkersCannotStart(RuntimeError):
    """Worker processes die or hang before their first case, :data:`MAX_STARTUP_DEATHS` in
    a row: something in the environment (memory, a broken install), not in a case."""


def die_with_parent(parent_pid: int | None) -> None:
    """Make this process exit when its parent dies (call first thing in a worker).

    ``parent_pid`` is the pid the parent had when it started this process (None: take
    ``os.getppid()`` now); a parent already gone ends this process at once.
    """
    if sys.platform.startswith("linux"):
        # the running program's own symbols (libc's among them): find_library would start a
        # subprocess, which a child forked from a threaded process must not
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
    expected = os.getppid() if parent_pid is None else parent_pid
    if os.getppid() != expected:
        os._exit(1)

    def watch():
        while os.getppid() == expected:
            time.sleep(WATCHDOG_PERIOD_S)
        os._exit(1)

    threading.Thread(target=watch, name="spine-mj-parent-watchdog", daemon=True).start()


def _worker_main(conn, parent_pid, work) -> None:
    """A worker's loop: ``work(case)`` for each case received until None or EOF."""
    die_with_parent(parent_pid)
    conn.send(("ready", None))
    while True:
        try:
            case = conn.recv()
        except (EOFError, OSError):
            return
        if case is None:
            return
        try:
            result = ("done", work(case))
        except Exception as exc:  # recorded as the case's failure; the worker goes on
            result = ("error", failure_text(exc))
        conn.send(result)


@dataclass(eq=False)
class _Worker:
    process: object
    conn: object
    case: object = None
    ready: bool = False
    started: float = field(default_factory=time.monotonic)


def failure_text(exc: BaseException) -> str:
    """How a worker reports the exception of a case."""
    return f"{type(exc).__name__}: {exc}"[:500]


def death_reason(exitcode: int | None) -> str:
    """Why a worker process ended, for the ``reason`` column of its case's runs."""
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        hint = " (killed, or out of memory)" if -exitcode == signal.SIGKILL else ""
        return f"WorkerDied: the worker process running this case was ended by {name}{hint}"
    return f"WorkerDied: the worker process running this case exited with code {exitcode}"


def run_pool(todo: list, n_workers: int, ctx, work, on_death, handle, *, parent_pid=None) -> None:
    """Run ``work(case)`` for every case of ``todo`` in ``n_workers`` processes of ``ctx``.

    Cases go to the workers in the order of ``todo``; none runs in this process, so no case
    can take the sweep down with it. ``handle`` gets each result in this process;
    ``on_death(case, reason)`` gives the result of a case whose worker died. ``parent_pid``:
    this process's pid where workers are its own children (fork), None where a fork server
    starts them.
    """
    queue = collections.deque(todo)
    workers: list[_Worker] = []
    state = {"startup_deaths": 0}
    try:
        while queue or any(w.case is not None for w in workers):
            busy = sum(w.case is not None for w in workers)
            while len(workers) < min(n_workers, busy + len(queue)):
                workers.append(_start(ctx, work, parent_pid))
            objs = [w.conn for w in workers] + [w.process.sentinel for w in workers]
            ready = set(wait(objs, timeout=1.0))
            for w in workers:
                if not w.ready and time.monotonic() - w.started > STARTUP_TIMEOUT_S:
                    w.process.kill()  # hung before its first case: its death is seen next
            for w in list(workers):
                if w.conn in ready or w.process.sentinel in ready:
                    _serve(w, workers, queue, state, handle, on_death)
    finally:
        _stop(workers)


def _start(ctx, work, parent_pid) -> _Worker:
    here, there = ctx.Pipe()
    proc = ctx.Process(target=_worker_main, args=(there, parent_pid, work), daemon=True)
    proc.start()
    there.close()
    return _Worker(process=proc, conn=here)


def _serve(w: _Worker, workers, queue, state, handle, on_death) -> None:
    """A worker's message (ready, or a finished case), or its death."""
    msg = None
    try:
        if w.conn.poll():
            msg = w.conn.recv()
    except (EOFError, OSError):
        msg = None
    if msg is None:
        w.process.join(0.05)
        if w.process.is_alive():
            return
        workers.remove(w)
        w.conn.close()
        if w.case is not None:
            handle(on_death(w.case, death_reason(w.process.exitcode)))
        elif not w.ready:
            state["startup_deaths"] += 1
            if state["startup_deaths"] >= MAX_STARTUP_DEATHS:
                raise WorkersCannotStart(
                    f"sweep worker processes die (or hang) before their first case "
                    f"({death_reason(w.process.exitcode)}); run with --workers 1 to see why"
                )
        return
    kind, payload = msg
    if kind == "ready":
        w.ready = True
        state["startup_deaths"] = 0
    else:
        case, w.case = w.case, None
        handle(payload if kind == "done" else on_death(case, payload))
    if queue:
        w.case = queue.popleft()
        w.conn.send(w.case)
    else:
        w.conn.send(None)
        workers.remove(w)
        w.process.join(5)


def _stop(workers: list[_Worker]) -> None:
    """End the workers still running (after an error or an interrupt in this process)."""
    for w in workers:
        if w.process.is_alive():
            w.process.kill()
    for w in workers:
        w.process.join(5)
        w.conn.close()
