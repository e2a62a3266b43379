"""The study runner's store of a stage that runs no sweep (:meth:`StudyRunner.stored`)."""

import json
import math

from spine_mj.validate.study_runner import StudyRunner


def _runner(tmp_path):
    return StudyRunner(tmp_path, 1, None, 0.0)


def test_stored_computes_once_and_reads_the_value_back_with_its_nonfinite_floats(tmp_path):
    calls = []

    def compute():
        calls.append(1)
        return {"a": [1.5, math.nan, math.inf], "b": (2, None), "c": True}

    runner = _runner(tmp_path)
    first = runner.stored("piece", {"n": 3}, compute)
    second = _runner(tmp_path).stored("piece", {"n": 3}, compute)
    assert len(calls) == 1
    assert json.dumps(first) == json.dumps(second)
    a = second["a"]
    assert a[0] == 1.5 and math.isnan(a[1]) and a[2] == math.inf
    assert second["b"] == [2, None] and second["c"] is True


def test_stored_computes_again_when_its_inputs_change_or_the_file_is_damaged(tmp_path):
    runner = _runner(tmp_path)
    assert runner.stored("piece", {"n": 3}, lambda: 1) == 1
    assert runner.stored("piece", {"n": 4}, lambda: 2) == 2
    assert runner.stored("piece", {"n": 4}, lambda: 3) == 2
    (tmp_path / "stored" / "piece.json").write_text('{"inputs": ')  # a killed writer's half
    assert runner.stored("piece", {"n": 4}, lambda: 5) == 5
    assert [p.name for p in (tmp_path / "stored").iterdir()] == ["piece.json"]
