"""The one exception type spine_mj raises for bad input, and atomic file writing.

Every check of user input raises :class:`SpineInputError` with a message that names the
argument, what was expected and what arrived. The CLI turns it into one line on stderr and
exit code 2; library users can catch it as a ``ValueError``.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["SpineInputError", "atomic_output", "check_positive"]


class SpineInputError(ValueError):
    """Bad input: a malformed file or config, non-finite data, or nonsense parameters."""


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """``float(value)`` if it is a finite number > 0 (>= 0 with ``allow_zero``), else a
    :class:`SpineInputError` naming ``name``, the expectation and what arrived."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpineInputError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(v) and (v >= 0 if allow_zero else v > 0)):
        raise SpineInputError(
            f"{name} must be a finite number {'>= 0' if allow_zero else '> 0'}, got {value!r}"
        )
    return v


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it onto ``path`` only on success.

    Whatever goes wrong inside the block (an exception, a kill before the rename), no
    half-written file is left at ``path``: the rename is atomic on POSIX file systems.

    Parameters
    ----------
    path
        Final destination. Its parent directory is created if missing.
    suffix
        Suffix of the temporary file (some writers pick the format from it); defaults to
        the suffix of ``path``.
    """
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(
        prefix=f".{dest.name}.",
        suffix=suffix if suffix is not None else dest.suffix,
        dir=dest.parent,
    )
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, dest)
    finally:
        if tmp.exists():
            tmp.unlink()
