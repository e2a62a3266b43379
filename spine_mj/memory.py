"""The memory budget: a request that would need more is refused before it allocates.

The count limits (:data:`spine_mj.surfaces.MAX_GRID_POINTS`, the step limits) bound how many
things a request makes; this bounds the bytes an operation's arrays take together, so a
command fails with one line naming the size instead of driving the machine into swap or
the kernel's out-of-memory killer. The budget is :data:`DEFAULT_FRACTION` of the memory
available now (Linux's ``MemAvailable``: what can be had without swapping; the physical
memory where that cannot be read) unless the environment variable ``SPINE_MJ_MEMORY_BUDGET``
sets it (bytes, or a number with a suffix K, M, G or T in powers of 1024:
``SPINE_MJ_MEMORY_BUDGET=2G``). Half the physical memory (12 GiB on a 24 GiB machine) was
more than a laptop running a browser has free.

Work that can be cut into pieces (the path comparisons of :mod:`spine_mj.theory.agreement`) is
chunked by :data:`BLOCK_BYTES` instead, so it never comes near the budget.
"""

from __future__ import annotations

import math
import os
import re

from spine_mj.errors import SpineInputError

__all__ = ["BLOCK_BYTES", "DEFAULT_FRACTION", "ENV_VAR", "check_memory", "format_bytes", "memory_budget"]

#: Share of the machine's available memory one operation may take by default.
DEFAULT_FRACTION = 0.8
#: Environment variable that sets the budget.
ENV_VAR = "SPINE_MJ_MEMORY_BUDGET"
#: Temporaries of one block of chunked work (32 MiB): small against any budget, large
#: enough that numpy's per-call overhead is negligible.
BLOCK_BYTES = 2**25

_UNITS = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


def _physical_memory() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):  # not POSIX: assume a modest machine
        return 8 * 2**30


def _available_memory() -> int:
    """Bytes the machine can give now without swapping: ``MemAvailable`` of
    ``/proc/meminfo``, else the physical memory."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return _physical_memory()


def memory_budget() -> int:
    """Bytes one operation may allocate: ``SPINE_MJ_MEMORY_BUDGET`` if set, else
    :data:`DEFAULT_FRACTION` of the memory available now.

    Raises
    ------
    SpineInputError
        When the variable is set to something other than a positive size.
    """
    raw = os.environ.get(ENV_VAR, "").strip()
    if not raw:
        return int(DEFAULT_FRACTION * _available_memory())
    m = re.fullmatch(r"([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([KMGT]?)i?B?", raw, flags=re.IGNORECASE)
    value = float(m.group(1)) * _UNITS[m.group(2).upper()] if m else math.nan
    if not (math.isfinite(value) and value >= 1):
        raise SpineInputError(
            f"{ENV_VAR} must be a size in bytes, optionally with a suffix K, M, G or T (e.g. 2G), got {raw!r}"
        )
    return int(value)


def format_bytes(nbytes: float) -> str:
    """``nbytes`` in the largest unit that keeps it >= 1 (``1.5 GiB``)."""
    for unit in ("TiB", "GiB", "MiB", "KiB"):
        scale = _UNITS[unit[0]]
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes:.0f} B"


def check_memory(nbytes: float, *, where: str) -> None:
    """Refuse, before allocating, an operation whose arrays would take ``nbytes``.

    Raises
    ------
    SpineInputError
        Naming ``where``, the size needed and the budget, when ``nbytes`` exceeds
        :func:`memory_budget` (or is not finite).
    """
    budget = memory_budget()
    if not float(nbytes) <= budget:
        raise SpineInputError(
            f"{where} would need {format_bytes(float(nbytes))} of memory, more than the budget of "
            f"{format_bytes(budget)} ({ENV_VAR} sets it); use a smaller grid or a coarser spacing"
        )
