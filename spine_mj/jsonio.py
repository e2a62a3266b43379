"""JSON output: one conversion of the project's values to JSON, and one atomic writer.

Every JSON file the project writes (validation results, sweep manifests, surface
metadata) goes through :func:`to_jsonable`, so a NumPy scalar, an array, a tuple, an enum,
a path or a dataclass is written the same way everywhere. Non-finite floats are not valid
JSON: NaN becomes ``null`` and an infinity the string ``"inf"`` / ``"-inf"``.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import math
import os
from pathlib import Path

import numpy as np

from spine_mj.atomic import atomic_output

__all__ = ["to_jsonable", "write_json"]


def to_jsonable(obj, *, nonfinite: bool = False):
    """``obj`` as plain JSON types (dict keys as strings); see the module docstring.
    ``nonfinite``: NaN and infinities kept as floats (for ``json.dumps(allow_nan=True)``:
    a value read back as it was computed, not a report's ``null``)."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v, nonfinite=nonfinite) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v, nonfinite=nonfinite) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist(), nonfinite=nonfinite)
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        if math.isfinite(v) or nonfinite:
            return v
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(obj, enum.Enum):
        return to_jsonable(obj.value, nonfinite=nonfinite)
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable(dataclasses.asdict(obj), nonfinite=nonfinite)
    if obj is None or isinstance(obj, str):
        return obj
    return str(obj)


def write_json(path: str | os.PathLike, obj, *, indent: int | None = 2) -> Path:
    """Write ``to_jsonable(obj)`` to ``path`` atomically (a complete file or none)."""
    path = Path(path)
    text = json.dumps(to_jsonable(obj), indent=indent, allow_nan=False)
    with atomic_output(path) as tmp:
        tmp.write_text(text + "\n")
    return path
