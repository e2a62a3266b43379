"""jsonio: every value the project writes becomes the same JSON, and a write is atomic."""

import enum
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.jsonio import to_jsonable, write_json


class Colour(enum.Enum):
    RED = "red"


@dataclass(frozen=True)
class Record:
    value: np.float64
    counts: np.ndarray
    colour: Colour


def test_numpy_values_become_plain_python_types():
    out = to_jsonable({"i": np.int32(3), "f": np.float32(0.5), "b": np.bool_(True), "a": np.arange(3)})
    assert out == {"i": 3, "f": 0.5, "b": True, "a": [0, 1, 2]}
    assert type(out["i"]) is int and type(out["f"]) is float and type(out["b"]) is bool


def test_non_finite_floats_become_null_and_strings():
    assert to_jsonable([math.nan, math.inf, -math.inf, np.float64("nan")]) == [None, "inf", "-inf", None]


def test_enums_paths_dataclasses_tuples_and_keys():
    rec = Record(value=np.float64(2.5), counts=np.array([[1, 2]]), colour=Colour.RED)
    out = to_jsonable({1: rec, "p": Path("a") / "b", "t": (1, (2, 3))})
    assert out == {"1": {"value": 2.5, "counts": [[1, 2]], "colour": "red"}, "p": "a/b", "t": [1, [2, 3]]}


def test_write_json_round_trips_and_is_strict_json(tmp_path):
    path = write_json(tmp_path / "out.json", {"x": np.array([1.0, np.inf]), "y": None})
    text = path.read_text()
    assert json.loads(text) == {"x": [1.0, "inf"], "y": None}
    assert text.endswith("\n") and "Infinity" not in text and "NaN" not in text


def test_write_json_leaves_the_old_file_when_the_destination_is_unusable(tmp_path):
    (tmp_path / "taken").mkdir()
    with pytest.raises(SpineInputError, match="taken"):
        write_json(tmp_path / "taken", {"a": 1})
    assert (tmp_path / "taken").is_dir() and not list((tmp_path / "taken").iterdir())
