"""The one exception type spine_mj raises for bad input, the check of a positive number, and
the argument parser of the analysis scripts that reports as the CLI does.

Every check of user input raises :class:`SpineInputError` with a message that names the
argument, what was expected and what arrived. The CLI turns it into one line on stderr and
exit code 2; library users can catch it as a ``ValueError``.
"""

from __future__ import annotations

import argparse
import math

__all__ = ["OneLineParser", "SpineInputError", "check_count", "check_positive"]


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


def check_count(name: str, value, *, least: int = 1, most: int | None = None) -> int:
    """``int(value)`` if it is a whole number (an integer, or a float without a fraction; not
    a bool) in ``[least, most]``, else a :class:`SpineInputError` naming ``name``, the
    expectation and what arrived (a string, NaN or 2.5 included: never ``int()``'s error)."""
    try:
        whole = not isinstance(value, (bool, str)) and type(value).__name__ not in ("bool", "bool_")
        whole = whole and math.isfinite(float(value)) and float(value) == int(value)
    except (TypeError, ValueError, OverflowError):
        whole = False
    span = f">= {least}" if most is None else f"in [{least}, {most}]"
    if not whole or not (least <= int(value) and (most is None or int(value) <= most)):
        raise SpineInputError(f"{name} must be a whole number {span}, got {value!r}")
    return int(value)


class OneLineParser(argparse.ArgumentParser):
    """An :class:`argparse.ArgumentParser` whose usage errors (a missing, unknown or
    malformed argument) are one ``Error:`` line and exit code 2, as the CLI's, instead of
    argparse's usage text."""

    def error(self, message):
        self.exit(2, f"Error: {message} (see --help)\n")
