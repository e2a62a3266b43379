"""The optional extras (``pip install 'spine-mj[EXTRA]'``), checked where a command needs one.

A command that needs an extra calls :func:`require` before it does any work or writes
anything, so a missing package is one ``Error:`` line naming what to install, not a
``ModuleNotFoundError`` traceback halfway through.
"""

from __future__ import annotations

import importlib.util

from spine_mj.errors import SpineInputError

__all__ = ["EXTRAS", "missing", "require"]

#: The modules each extra of pyproject.toml brings (import names).
EXTRAS = {
    "video": ("imageio", "imageio_ffmpeg"),
    "slurm": ("dask_jobqueue",),
    "gpu": ("mujoco_warp",),
    "bullet": ("pybullet",),
}


def missing(extra: str) -> list[str]:
    """The modules of ``extra`` that are not installed here."""
    return [m for m in EXTRAS[extra] if importlib.util.find_spec(m) is None]


def require(extra: str, what: str) -> None:
    """Refuse ``what`` (an option or command, for the message) when ``extra`` is missing."""
    gone = missing(extra)
    if gone:
        raise SpineInputError(
            f"{what} needs the optional extra '{extra}' ({', '.join(gone)} not installed): "
            f"pip install 'spine-mj[{extra}]'"
        )
