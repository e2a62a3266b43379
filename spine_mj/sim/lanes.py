"""The worker lanes a batch of open-loop pieces is stepped on.

:class:`NativeLanes`: worker threads stepping pieces through
:func:`mujoco.rollout.rollout` (which releases the GIL), each on its own ``MjData`` whose
warm start the run goes on from; :class:`PythonLane`: the reference, every piece stepped
by :func:`python_steps` (a plain ``mj_step`` loop) on the calling thread. Both take pieces
with ``put`` and hand finished ones back with ``take``; :mod:`spine_mj.sim.rollout`
schedules the pieces and :mod:`spine_mj.sim.array` runs an array's on the same lanes.
"""

from __future__ import annotations

import queue
import threading


class NativeLanes:
    """Worker threads, each taking pieces from one queue and stepping them through
    :func:`mujoco.rollout.rollout` on its own ``MjData`` (whose warm start the run goes on
    from); :meth:`take` hands finished pieces back in the order they finished."""

    def __init__(self, nthread: int):
        import mujoco

        self.spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
        self.nthread = nthread
        self.local = threading.local()
        self.jobs: queue.SimpleQueue = queue.SimpleQueue()
        self.finished: list = []  # (ok, result or exception), under ``ready``
        self.ready = threading.Condition()
        self.wanted = 0  # take() waits for this many: the workers wake it once, not per piece
        self.cancelled = False
        self.threads = [threading.Thread(target=self._work, daemon=True) for _ in range(nthread)]
        for t in self.threads:
            t.start()

    def _work(self) -> None:
        while (job := self.jobs.get()) is not None:
            if not self.cancelled:
                fn, args = job
                try:
                    item = (True, fn(*args))
                except BaseException as exc:  # raised again by take(), on the calling thread
                    item = (False, exc)
                with self.ready:
                    self.finished.append(item)
                    if len(self.finished) == self.wanted or not item[0]:
                        self.ready.notify()

    def put(self, fn, args: tuple) -> None:
        """Queue ``fn(*args)``."""
        self.jobs.put((fn, args))

    def take(self, n: int) -> list:
        """At least ``n`` finished pieces (waiting for them) and any others finished by then."""
        with self.ready:
            self.wanted = n
            self.ready.wait_for(lambda: len(self.finished) >= n or not all(ok for ok, _ in self.finished))
            got, self.finished, self.wanted = self.finished, [], 0
        for ok, value in got:
            if not ok:
                raise value
        return [value for _, value in got]

    def step(self, model, init, warm, ctrl, state, sens):
        """Rows ``ctrl.shape[1]`` of one run from full physics state ``init`` and warm start
        ``warm`` into ``state`` and ``sens`` (each a C-contiguous view with a leading axis of
        one: the run as a batch of one, as rollout takes it); returns the warm start
        after the last row (a list) and ``"frozen"`` if MuJoCo warned (the rollout clears the
        warnings at its start, stops stepping at one and repeats the row), else None."""
        import mujoco
        from mujoco import rollout

        lane = getattr(self.local, "lane", None)
        if lane is None:  # the rig's models differ in the spring's stiffness only: one MjData fits all
            data = mujoco.MjData(model)
            # live views of the warnings and the warm start, read through memoryviews: after a
            # piece, the bindings' and numpy's code has left the cache, and reading
            # ``data.warning`` then costs ~100 us a piece against ~10 (measured)
            warned, warm_out = memoryview(data.warning.number), memoryview(data.qacc_warmstart)
            lane = self.local.lane = (data, rollout.Rollout(nthread=0), warned, warm_out)
        data, pool, warned, warm_out = lane
        pool.rollout(
            [model],
            [data],
            init,
            ctrl,
            control_spec=self.spec,
            skip_checks=True,
            nstep=ctrl.shape[1],
            initial_warmstart=warm,
            state=state,
            sensordata=sens,
        )
        return warm_out.tolist(), ("frozen" if any(warned) else None)

    def close(self) -> None:
        """Stop the workers (pieces still queued are dropped) and wait for them."""
        self.cancelled = True
        for _ in self.threads:
            self.jobs.put(None)
        for t in self.threads:
            t.join()


class PythonLane:
    """The reference backend: every piece stepped by :func:`python_steps` on the calling
    thread, when it is queued."""

    nthread = 1

    def __init__(self):
        self.finished: list = []

    def put(self, fn, args: tuple) -> None:
        self.finished.append(fn(*args))

    def take(self, n: int) -> list:
        got, self.finished = self.finished, []
        return got

    def step(self, model, init, warm, ctrl, state, sens):
        return python_steps(model, init[0], warm[0], ctrl[0], state[0], sens[0])

    def close(self) -> None:
        pass


def warning_total(d) -> int:
    """The number of MuJoCo warnings ``d`` (an ``MjData``) has seen (read as one array: a
    loop over the warning structs costs 100 us)."""
    return int(d.warning.number.sum())


def warning_text(d) -> str:
    """The names of the warnings ``d`` has seen, comma separated."""
    import mujoco

    names = [n for n in dir(mujoco.mjtWarning) if n.startswith("mjWARN_") and n != "mjWARN_NWARNING"]
    hit = [n for n in names if d.warning[int(getattr(mujoco.mjtWarning, n))].number > 0]
    return ", ".join(h.removeprefix("mjWARN_") for h in hit) or "unknown"


def python_steps(model, init, warm, ctrl, state, sens):
    """Reference for one run's piece of :func:`mujoco.rollout.rollout`: a plain ``mj_step``
    loop from full physics state ``init`` and warm start ``warm``, filling ``state``
    ``(nstep, nstate)`` and ``sens`` ``(nstep, nsensordata)``.

    Returns the warm start after the last step and ``(first step with a new MuJoCo warning,
    warning names)`` or None (the loop steps on after a warning).
    """
    import mujoco

    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    d = mujoco.MjData(model)
    mujoco.mj_setState(model, d, init, full)
    d.qacc_warmstart[:] = warm
    first_warn = None
    for i in range(ctrl.shape[0]):
        d.ctrl[:] = ctrl[i, : model.nu]
        d.mocap_pos[:] = ctrl[i, model.nu :].reshape(-1, 3)
        mujoco.mj_step(model, d)
        mujoco.mj_getState(model, d, state[i], full)
        sens[i] = d.sensordata
        if first_warn is None and warning_total(d):
            first_warn = (i, warning_text(d))
    return d.qacc_warmstart.copy(), first_warn
