"""The one exception type spine_mj raises for bad input, and the check of a positive number.

Every check of user input raises :class:`SpineInputError` with a message that names the
argument, what was expected and what arrived. The CLI turns it into one line on stderr and
exit code 2; library users can catch it as a ``ValueError``.
"""

from __future__ import annotations

import math

__all__ = ["SpineInputError", "check_positive"]


class SpineInputError(ValueError):
    """Bad input: a malformed file or config, non-finite data, or nonsense parameters.

    ``str(error)`` is one line for the user; ``details`` (optional) holds longer text,
    such as a reader's full report, that the CLI shows with ``--verbose``.
    """

    details: str | None = None


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
