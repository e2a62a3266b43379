"""How many local worker processes a command may start: the one rule every command that
takes ``--workers`` checks before it does any work (sweeps, validation, reproduce)."""

from __future__ import annotations

import os

from spine_mj.errors import SpineInputError

__all__ = ["MAX_WORKERS_PER_CORE", "check_workers"]

#: Local worker processes allowed per core (more only cost memory: ~300 MB each).
MAX_WORKERS_PER_CORE = 4


def check_workers(workers) -> int:
    """``workers`` if it is an integer from 1 to :data:`MAX_WORKERS_PER_CORE` per core."""
    cores = os.cpu_count() or 1
    limit = MAX_WORKERS_PER_CORE * cores
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= limit:
        raise SpineInputError(
            f"--workers: must be an integer from 1 to {limit} ({MAX_WORKERS_PER_CORE} per core "
            f"on {cores} cores), got {workers!r}"
        )
    return workers
