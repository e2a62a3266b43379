"""The study runner: drives :func:`spine_mj.sweep.run_sweep` for the validation's studies.

Every study hands its sweep configs (dicts) to one :class:`StudyRunner`, which runs each
into its own resumable store under ``out/sweeps/<name>`` (a killed validation resumes
where it stopped) and reports :class:`ValidationProgress` to the caller's callback.
"""

from __future__ import annotations

import contextlib
import json
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from spine_mj import sweep
from spine_mj.atomic import atomic_output
from spine_mj.jsonio import to_jsonable
from spine_mj.sweep.digests import digest
from spine_mj.sweep.session import clear_caches

__all__ = ["StudyRunner", "ValidationProgress"]


@dataclass(frozen=True)
class ValidationProgress:
    """Progress of a validation, passed to the ``progress`` callback.

    Attributes
    ----------
    study : str
        ``static``, ``limit``, ``boundary``, ``stick_slip``, ``sandpaper``,
        ``fractal_lock``, ``stiffness_map`` or ``report``.
    step : str
        What runs now (a sweep name or a phase).
    finished_cases, total_cases : int
        Of the current sweep, or the parts of a phase that runs none
        (:meth:`StudyRunner.phase`).
    elapsed_s : float
        Since the validation started.
    """

    study: str
    step: str
    finished_cases: int
    total_cases: int
    elapsed_s: float


class StudyRunner:
    """Runs sweep configs (dicts) into ``out/sweeps/<name>`` and reports progress.

    Parameters
    ----------
    out_dir : Path
        The validation's output folder (absolute: the stores refer to files under it).
    workers : int or None
        Worker processes per sweep (None: all cores); a sweep of one case steps its engine
        batch on that many threads.
    progress : callable or None
        Called with :class:`ValidationProgress`.
    t0 : float
        ``time.perf_counter()`` at the start of the validation.

    Attributes
    ----------
    study : str
        The study now running; each study sets it before its first sweep.
    """

    def __init__(
        self,
        out_dir: Path,
        workers: int | None,
        progress: Callable[[ValidationProgress], None] | None,
        t0: float,
    ):
        self.out_dir = out_dir
        self.workers = workers
        self.progress = progress
        self.t0 = t0
        self.study = ""
        # the inputs read once, here: the studies' sweeps share the surfaces, their sizing and
        # dilation (the quick plan's quasistatic limit sized its 30 surfaces 60 times before
        # its cases ran, each case once more in its worker), and a forked worker inherits them
        clear_caches()

    @property
    def n_workers(self) -> int:
        """The worker processes a sweep of several cases runs on (``workers``, else every core)."""
        return self.workers or os.cpu_count() or 1

    @contextlib.contextmanager
    def phase(self, step: str, total: int = 1) -> Iterator[Callable[[], None]]:
        """A phase that runs no sweep (``step``), of ``total`` parts: reported at 0 as it
        starts, at every call of the ``tick`` it yields, and at ``total`` as it ends (a
        phase reported only as it started was left at 0 % by the CLI's bar)."""
        done = 0

        def tick() -> None:
            nonlocal done
            done = min(done + 1, total)
            self.report(step, done, total)

        self.report(step, 0, total)
        yield tick
        self.report(step, total, total)

    def report(self, step: str, done: int, total: int) -> None:
        """Report ``done`` of ``total`` parts of ``step``, a stage that runs no sweep."""
        if self.progress is not None:
            self.progress(ValidationProgress(self.study, step, done, total, time.perf_counter() - self.t0))

    def _sweep_progress(self, step: str) -> Callable:
        """A sweep's progress callback reporting its cases as ``step`` of this study."""

        def report(p) -> None:
            if self.progress is not None:
                done = p.finished_cases + p.skipped_cases
                elapsed = time.perf_counter() - self.t0
                self.progress(ValidationProgress(self.study, step, done, p.total_cases, elapsed))

        return report

    def __call__(self, doc: dict, name: str, *, workers: int | None = None):
        """Run the sweep config ``doc`` into ``out/sweeps/<name>`` (overwriting it).

        Returns
        -------
        (DataFrame, Path)
            The run table (:func:`spine_mj.sweep.load_runs`) and the store.
        """
        config = sweep.parse_config(doc, base_dir=self.out_dir)
        store = self.out_dir / "sweeps" / name

        # not capped at the case count: a sweep of one case steps its engine batch on the
        # workers' threads instead of starting processes
        w = workers or self.n_workers
        sweep.run_sweeps(
            [(config, store)], workers=w, overwrite=True, progress=self._sweep_progress(name), afresh=False
        )
        return sweep.load_runs(store), store

    def stored(self, name: str, inputs: dict, compute: Callable[[], Any]) -> Any:
        """``compute()``, kept in ``out/stored/<name>.json`` with the digest of ``inputs``
        (JSON: what it depends on) and read back instead of computed while that digest is
        unchanged: a stage that runs no sweep resumes as a sweep's store does (the full
        plan's arrays, 393 s, ran again on every resume). The value must be JSON (NaN and
        infinities kept); written atomically, so a killed write leaves none."""
        path = self.out_dir / "stored" / f"{name}.json"
        key = digest(to_jsonable(inputs, nonfinite=True))
        with contextlib.suppress(OSError, ValueError):
            doc = json.loads(path.read_text())
            if doc.get("inputs") == key:
                return doc["value"]
        value = compute()
        path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"inputs": key, "value": to_jsonable(value, nonfinite=True)}, allow_nan=True)
        with atomic_output(path) as tmp:
            tmp.write_text(text)
        return json.loads(text)["value"]

    def many(self, jobs, step: str):
        """Run the sweep configs of ``jobs`` (``(doc, name)`` pairs) together, their cases
        sharing the workers (:func:`spine_mj.sweep.run_sweeps`), each into
        ``out/sweeps/<name>``; progress is reported as one ``step``.

        Returns
        -------
        list of (DataFrame, Path)
            Per job, in order, as :meth:`__call__` returns.
        """
        configs = [sweep.parse_config(doc, base_dir=self.out_dir) for doc, _ in jobs]
        stores = [self.out_dir / "sweeps" / name for _, name in jobs]

        w = self.n_workers
        progress = self._sweep_progress(step)
        sweep.run_sweeps(
            list(zip(configs, stores)), workers=w, overwrite=True, progress=progress, afresh=False
        )
        return [(sweep.load_runs(store), store) for store in stores]
