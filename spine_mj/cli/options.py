"""Options that several commands share, written once (each takes its choices from the
library's name lists in :mod:`spine_mj.choices`, which load no numpy: ``spine-mj --help``
stays instant)."""

from __future__ import annotations

import click

from spine_mj.choices import FILL_METHODS

__all__ = ["fill_option"]


def fill_option(help_text: str):
    """``--fill``: how an instrument file's missing points are filled
    (:data:`~spine_mj.choices.FILL_METHODS`, default ``refuse``), as ``surface make`` and
    ``hold`` take it; ``help_text`` says what the command fills."""
    return click.option(
        "--fill", type=click.Choice(FILL_METHODS), default="refuse", show_default=True, help=help_text
    )
