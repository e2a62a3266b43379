"""Digests of a sweep's inputs: what a store's resume and its case ids are keyed by.

:func:`digest` is the sha256 of canonical JSON (config hashes, case ids);
:func:`input_digests` covers what a config's text does not: the contents of its surface
files and its resolved presets.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from spine_mj import presets
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import to_jsonable


def input_digests(config) -> dict[str, str]:
    """sha256 of every input of ``config`` beyond its text: the contents of each surface
    file, and the resolved preset (generator, parameters, seed, [engagement] and other
    tables; the contents of a measured preset's file). Keyed ``file:<path>`` /
    ``preset:<name>``; a store resumes only while these are unchanged.

    Parameters
    ----------
    config : spine_mj.sweep.config.SweepConfig
        A parsed config (its ``surfaces``).

    Returns
    -------
    dict of str to str
    """
    out = {}
    for spec in config.surfaces:
        key = f"{spec.kind}:{spec.source}"
        if key not in out:
            out[key] = surface_digest(spec.kind, spec.source)
    return out


def surface_digest(kind: str, source: str) -> str:
    """sha256 of one surface input of :func:`input_digests`: a file's contents (``kind``
    ``"file"``, ``source`` its path) or a resolved preset (``"preset"``, its name)."""
    if kind == "file":
        return _file_digest(Path(source))
    preset = presets.load_preset(source)
    resolved = {
        "generator": preset.generator,
        "params": to_jsonable(preset.params),
        "seed": preset.seed,
        "extras": to_jsonable(preset.extras),
    }
    measured = preset.params.get("file") if preset.generator == "measured" else None
    if isinstance(measured, str) and Path(measured).is_file():
        resolved["file_sha256"] = _file_digest(Path(measured))
    return digest(resolved)


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError as exc:
        raise SpineInputError(f"surface file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    return h.hexdigest()


def digest(obj) -> str:
    """sha256 (hex) of ``obj`` as canonical JSON (sorted keys): config hashes and case ids."""
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()
