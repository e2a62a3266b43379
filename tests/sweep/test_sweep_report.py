"""The sweep's HTML report: rendered without template leftovers, units and counts shown,
corrupt case files listed, quasistatic rows not repeated per drive value."""

import pytest
from click.testing import CliRunner
from report_links import assert_links_resolve
from sweep_support import peak_config

from spine_mj.cli import main
from spine_mj.sweep import report as sweep_report


@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("store")
    out = tmp / "out"
    res = CliRunner().invoke(
        main, ["sweep", str(peak_config(tmp, nmu=3, ny=2)), "--out", str(out), "--workers", "1"]
    )
    assert res.exit_code == 0, res.output
    return out


def test_sweep_report_renders_without_template_braces(small_store, tmp_path):
    html = sweep_report.write_report(small_store, tmp_path / "r.html").read_text()
    style = html[html.index("<style>") : html.index("</style>")]
    assert "{{" not in style and "}}" not in style and "table {" in style
    assert "{{" not in html and "{%" not in html
    assert_links_resolve(html, tmp_path)
    assert "data:image/png;base64," in html
    assert "max_kappa [1]" in html  # units in the headers
    assert "2/2" in html  # ok / runs beside the means
    assert "Corrupt case files" not in html


def test_sweep_report_lists_corrupt_cases(small_store, tmp_path, monkeypatch):
    real = sweep_report.store_status

    class WithCorrupt:
        def __init__(self, st):
            self._st = st
            self.corrupt_cases = ("case-0003 (<not parquet>)",)

        def __getattr__(self, name):
            return getattr(self._st, name)

    monkeypatch.setattr(sweep_report, "store_status", lambda d: WithCorrupt(real(d)))
    html = sweep_report.write_report(small_store, tmp_path / "r.html").read_text()
    assert "Corrupt case files" in html and "case-0003 (&lt;not parquet&gt;)" in html  # autoescaped


def test_quasistatic_rows_do_not_repeat_per_drive_value():
    import pandas as pd

    rows = []
    for ie in (0.01, 1.0):
        for start in (0, 1):
            rows.append(
                {
                    "analysis": "quasistatic",
                    "surface": "s",
                    "start": start,
                    "status": "ok",
                    "ie": ie,
                    "mu": 1.0,
                }
                | {"max_kappa": 1.0 + start, "case_id": f"c{ie}"}
            )
    sec = sweep_report._analysis_section("quasistatic", pd.DataFrame(rows), ["ie"])
    assert sec["dropped"] == ["ie"]
    assert [r["n"] for r in sec["rows"]] == [2]
