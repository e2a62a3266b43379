"""The examples that ship with spine_mj, named ``example:NAME`` wherever a file is expected.

The README's examples read two measured scans (``plu-1.plu``, ``di-1.di``: from
SurfaceTopography's MIT-licensed test suite, see ``tests/data/README.md``, which ships
beside them) and the sweep configs of ``analysis/sweeps/``. A wheel has no repository, and
a user's shell is rarely at its root, so these files ship inside the package
(:mod:`spine_mj.resources`) and every file argument (a SURFACE, ``--from-file``, a sweep
CONFIG, a config's ``file = ...``) takes ``example:NAME`` for them: the examples run the
same from any folder, in a clone or from a wheel. ``spine-mj examples`` lists them.
"""

from __future__ import annotations

import os
from pathlib import Path

from spine_mj import resources
from spine_mj.errors import SpineInputError

__all__ = ["PREFIX", "list_examples", "resolve"]

#: How a file argument names a shipped example.
PREFIX = "example:"
_SUFFIXES = {"scan": (".plu", ".di"), "sweep": (".toml",)}


def list_examples() -> dict[str, tuple[str, Path]]:
    """Every shipped example: ``NAME -> (kind, path)``, kind ``"scan"`` or ``"sweep"``."""
    out = {}
    for kind, folder in resources.examples_dirs().items():
        for path in sorted(folder.iterdir()):
            if path.suffix in _SUFFIXES[kind]:
                out[path.name] = (kind, path)
    return out


def resolve(spec: str | os.PathLike) -> str | os.PathLike:
    """The path of ``example:NAME``; any other ``spec`` unchanged.

    Raises
    ------
    SpineInputError
        ``example:NAME`` with a NAME that is not shipped (the message lists the names).
    """
    if not (isinstance(spec, str) and spec.startswith(PREFIX)):
        return spec
    name = spec[len(PREFIX) :]
    found = list_examples()
    if name not in found:
        raise SpineInputError(
            f"{spec!r}: no such example; the examples are {', '.join(PREFIX + n for n in found)} "
            "(spine-mj examples)"
        )
    return str(found[name][1])
