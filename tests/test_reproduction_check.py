"""analysis/reproduction_check.py held to the CLI's standard: every bad input one `Error:`
line, exit 2, nothing written; a good one checked against the committed intervals."""

import copy
import importlib.util
import json
import math
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
COMMITTED = ROOT / "analysis" / "reports" / "validation-quick" / "validation.json"


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location(
        "reproduction_check", ROOT / "analysis" / "reproduction_check.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def committed() -> dict:
    return json.loads(COMMITTED.read_text())


def _one_error(capsys, rc, *fragments):
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert rc == 2 and out == "" and len(lines) == 1 and lines[0].startswith("Error: "), (rc, out, err)
    for f in fragments:
        assert f in lines[0], lines[0]


def _broken(committed, edit):
    doc = copy.deepcopy(committed)
    edit(doc)
    return doc


def _set(path, value):
    def edit(doc):
        *head, last = path
        for k in head:
            doc = doc[k]
        doc[last] = value

    return edit


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (_set(["limit_families", "fractal"], 3), "limit_families.fractal must be a JSON object, got int 3"),
        (
            _set(["limit_families", "fractal", "agreement_ci"], 7),
            "limit_families.fractal.agreement_ci must be a pair",
        ),
        (_set(["ie_star"], [0.1, 0.2]), "ie_star must be a JSON object, got list"),
        (
            _set(["limit_families", "fractal", "median_frechet"], math.nan),
            "median_frechet must be a finite number, got nan",
        ),
        (_set(["limit_families"], {}), "limit_families must hold at least one family, got none"),
        (
            _set(["limit_families", "fractal", "agreement_well_conditioned"], "high"),
            "must be a finite number, got 'high'",
        ),
    ],
)
def test_a_malformed_validation_is_one_error_line(script, committed, tmp_path, capsys, edit, fragment):
    bad = tmp_path / "validation.json"
    bad.write_text(json.dumps(_broken(committed, edit)))
    report = tmp_path / "report.md"
    _one_error(capsys, script.main([str(bad), "-o", str(report)]), str(bad), fragment)
    assert not report.exists()


def test_no_argument_an_unknown_option_and_an_unwritable_report(script, tmp_path, capsys):
    _one_error(capsys, script.main([]), "give the new run's validation.json")
    with pytest.raises(SystemExit) as stop:
        script.main([str(COMMITTED), "--bogus"])
    assert stop.value.code == 2
    _one_error(capsys, 2, "unrecognized arguments: --bogus")
    a_file = tmp_path / "a-file"
    a_file.write_text("")
    _one_error(capsys, script.main([str(COMMITTED), "-o", str(a_file / "report.md")]), "cannot write there")
    _one_error(capsys, script.main([str(COMMITTED), "-o", str(tmp_path)]), "is a folder")


def test_the_committed_run_reproduces_itself(script, committed, tmp_path, capsys):
    from spine_mj.validate.headlines import headline_numbers

    n = len(headline_numbers(committed))
    report = tmp_path / "sub" / "report.md"
    assert script.main([str(COMMITTED), "-o", str(report)]) == 0
    assert f"{n} of {n} inside the committed intervals" in report.read_text()
    assert f"{n} of {n}" in capsys.readouterr().out


def test_deeply_nested_json_is_one_error_line(script, tmp_path, capsys):
    deep = tmp_path / "validation.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    _one_error(capsys, script.main([str(deep)]), "nested too deep")
