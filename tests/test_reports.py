"""The sweep HTML report, the validation markdown report and the house style of figures."""

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from sweep_support import peak_config

from spine_mj import plotting
from spine_mj.cli import main
from spine_mj.sweep import report as sweep_report
from spine_mj.validate import (
    BoundaryCurve,
    BoundaryResult,
    LimitPath,
    QuasistaticLimitResult,
    SandpaperResult,
    StaticMapResult,
    StickSlipResult,
)
from spine_mj.validate import write_report as write_validation_report


@pytest.mark.parametrize(
    "value, text",
    [
        (3.6068453317776017, "3.61"),
        (1e-4, "0.0001"),
        (0.031622776602047833, "0.0316"),
        (123456.0, "1.23e+05"),
        (7, "7"),
        (float("nan"), "nan"),
        (None, "-"),
        (True, "yes"),
    ],
)
def test_sig_rounds_to_three_significant_digits(value, text):
    assert plotting.sig(value) == text


def test_length_unit_picks_um_or_mm_for_scans():
    assert plotting.length_unit(4e-4) == (1e6, "um")
    assert plotting.length_unit(5e-3) == (1e3, "mm")
    assert plotting.length_unit(2.0) == (1.0, "m")


def _links(text: str) -> list[str]:
    """Targets of markdown links/images and of HTML src/href attributes."""
    md = re.findall(r"!?\[[^\]]*\]\(([^)\s]+)\)", text)
    html = re.findall(r"(?:src|href)=\"([^\"]+)\"", text)
    return md + html


def _assert_links_resolve(text: str, base: Path) -> None:
    for target in _links(text):
        if target.startswith(("data:", "#", "http://", "https://")):
            continue
        assert (base / target).is_file(), f"link to a missing file: {target}"


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
    _assert_links_resolve(html, tmp_path)
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


def _validation_results():
    t = np.linspace(0, 1, 20)
    path = np.column_stack([np.linspace(-3, 5, 20), np.linspace(-2, -3, 20)])
    curve = BoundaryCurve(
        ie=[1e-4, 1.0],
        agreement=[0.9, 0.5],
        frechet=[0.05, 1.2],
        median_frechet=[0.04, 0.9],
        lateral=[0.01, 0.2],
        engine_trouble=[0.0, 0.5],
        runs_per_ie=10,
        frechet_kind="Frechet",
    )
    star = {"kind": "bracketed", "value": 0.01, "low": 1e-4, "high": 1.0, "ci_low": 1e-4, "ci_high": 1.0}
    star |= {"criterion": "outcome agreement >= 95 %", "ie_used": [1e-4, 1.0]}
    star["by_criterion"] = {"outcome": dict(star)}
    fam = {"runs": 10, "ok_runs": 9, "outcome_agreement": 0.9, "mean_frechet": 0.05, "median_frechet": 0.04}
    fam |= {"failed_runs": {"penetration": 1}, "reference_stalled": 2}
    return {
        "static": StaticMapResult(rows=[], per_engine={}, mu=1.0, static_kappa_max_rel_error=0.01),
        "limit": QuasistaticLimitResult(
            families={"single_peak_valley": fam | {"meets_target": False}},
            runs=[],
            variations={},
            paths={"paper-single-peak": [LimitPath(path, path, path, (-3.0, -2.0))]},
            lowest_ie=1e-4,
        ),
        "boundary": BoundaryResult(
            curves={"spring": curve},
            ie_star={"spring": star},
            skip_rate={"spring": [0.0, 0.5]},
            families=["x"],
        ),
        "stick": StickSlipResult(
            rows=[{"ie": 0.01, "stiffness_fp_per_lc": 2.0, "runs": 2}],
            traces={(0.01, 19.37): (t, np.sin(t))},
            surface="paper-random-concave#1",
        ),
        # every sandpaper run failed: no paths, so no figure and no link to one
        "sand": SandpaperResult(
            rows=[{"grit": "P36", "runs": 2, "failed_runs": 2, "failures": ["diverged"]}],
            paths={"P36": []},
            mu=0.5,
        ),
    }


def test_validation_report_links_only_written_figures_and_names_its_plan(tmp_path):
    result = {"plan": "quick", "static_kappa_max_rel_error": 0.01, "engine_settings": {"dt": 1e-3}}
    result["timings_s"] = {"static": 1.23456}
    path = write_validation_report(tmp_path, result, _validation_results().values())
    text = path.read_text()
    assert text.startswith("# Validation") and "(quick plan)" in text and "full plan" in text
    assert "{{" not in text and "{%" not in text
    _assert_links_resolve(text, tmp_path)
    assert "figures/boundary.png" in text and "figures/limit_paths.png" in text
    assert "sandpaper.png" not in text and not (tmp_path / "figures" / "sandpaper.png").exists()
    assert "9/10" in text  # agree / runs beside the agreement
    assert "penetration 1" in text  # the engine stops of a family, by kind
    assert "stalled (single_peak_valley 2 of 10)" in text  # and the model's own stops
    assert "the issue" not in text


def test_falls_note_splits_the_runs_at_the_lower_end_of_the_ie_star_bracket():
    from spine_mj.validate.report.quasistatic_limit import falls_note as _falls_note

    res = _validation_results()
    runs = [
        {"family": "single_peak_valley", "agree": True, "frechet": 0.01, "tip_peak_ie": 5e-5},
        {"family": "single_peak_valley", "agree": True, "frechet": 0.03, "tip_peak_ie": 1e-4},
        {"family": "single_peak_valley", "agree": False, "frechet": 0.5, "tip_peak_ie": 0.3},
    ]
    fam = dict(res["limit"].families["single_peak_valley"], slide_runs=1)
    limit = QuasistaticLimitResult({"single_peak_valley": fam}, runs, {}, {}, 1e-4)
    text = "\n".join(_falls_note(limit, res["boundary"]))
    row = next(line for line in text.splitlines() if line.startswith("| single_peak_valley"))
    # the bracket's lower end is 1e-4: the run at exactly 1e-4 is on the slow side
    assert [c.strip() for c in row.strip("|").split("|")] == [
        "single_peak_valley",
        "1/3",
        "0.0001 (5e-05-0.3)",
        "2/2, 0.02",
        "0/1, 0.5",
    ]
    no_star = BoundaryResult(curves={}, ie_star={}, skip_rate={}, families=[])
    assert _falls_note(limit, no_star) == []
